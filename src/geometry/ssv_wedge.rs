//! Robust penumbra wedges of the soft shadow volume algorithm (Paper III §3.1, Figure 5) for a
//! rectangular or a spherical light ([`WedgeLight`]).
//!
//! For a silhouette edge `e0 e1` and a light with center `c`:
//!
//! 1. The vertex nearer to `c` is the wedge's top vertex `A`; the other one is moved toward `c`
//!    to the same distance, giving `B` (Figure 5a). `A B` is the wedge's top edge; the original
//!    edge is still the one the coverage is computed from.
//! 2. Front and back planes contain the line `A B` and are rotated about it until they barely
//!    touch the light (Figure 5b): around the axis `A B`, the light's four corners span an
//!    angular sector (the light is convex, so its corners bound it); the two planes through the
//!    axis and the extreme corners bound the reflected sector, which is the wedge's cross-section.
//! 3. The right plane contains `B` and the direction `k = (A − B) × (c − B)` perpendicular to
//!    both the top edge and the direction to the light center, rotated about that axis until
//!    it barely touches the light (Figure 5c): in the plane ⟂ `k` through `B`, spanned by the
//!    outward edge direction `t` and the light direction `g`, it passes through the reflection
//!    of the corner with the largest angle from `t`. The left plane is the same construction at
//!    `A` with `t` pointing the other way.
//!
//! For a **sphere** (the paper's own construction: Paper III §3.1 "barely touch the light
//! source", Paper IV §4.1 "our previously presented method created wedges from bounding
//! spheres") steps 2 and 3 use the sphere instead of the corners: seen along the axis, the
//! sphere is a disk of its radius around the projected center, and the planes are its two
//! tangents through the axis. The wedge then holds every point that sees part of the sphere
//! through the edge, hence every point whose coverage of the facing disk
//! ([`crate::light::coverage::sphere_edge_coverage_exact`]) the edge changes: that disk lies in
//! the sphere.
//!
//! The wedge is the intersection of the four inner half spaces (Figure 5d); its faces are the
//! front and back quads and the left and right triangles, each extended to infinity away from
//! the light (vertices at w = 0, as the shadow volume quads, [`super::shadow_volume`]). Every
//! wedge is built from its own edge only ("wedges independent of each other", §3.1).
//!
//! # Degenerate wedges (a choice the paper leaves open)
//!
//! When the light's corners (or the sphere) span half a turn or more around the top edge or
//! around a side axis (the edge is very close to a large light, or the line of the edge passes
//! through the light), no four planes bound the penumbra volume as above. [`SsvWedge::new`]
//! then returns `None` and the caller treats the whole space as inside the wedge — correct,
//! because the coverage it then computes for every pixel is exactly 0 outside the real
//! penumbra volume (Paper III §3.2.2 and [`crate::light::coverage`]), only slower.

use crate::gpu::hiz::{plane_rejects_box, InsideTestRounding};
use crate::gpu::shader_float::ShaderFloat;
use crate::gpu::shader_vec::SVec3;
use crate::gpu::transform::{ClipVertex, Projection};
use crate::light::coverage::RectLight;
use crate::scene::{Light, LightShape};
use glam::{DVec2, DVec3};

/// The light a wedge is built around (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WedgeLight {
    /// A rectangle: the wedge touches its four corners.
    Rect(RectLight),
    /// A sphere: the wedge's planes are tangent to it.
    Sphere {
        /// Center.
        center: DVec3,
        /// Radius.
        radius: f64,
    },
}

impl WedgeLight {
    /// The light of a `rect`, `textured_rect` or `sphere` scene light; `None` for other shapes.
    pub fn from_light(light: &Light) -> Option<Self> {
        match light.shape {
            LightShape::Sphere { radius } => Some(WedgeLight::Sphere {
                center: light.center.as_dvec3(),
                radius: radius as f64,
            }),
            _ => RectLight::from_light(light).map(WedgeLight::Rect),
        }
    }

    /// The light center `c`.
    pub fn center(&self) -> DVec3 {
        match self {
            WedgeLight::Rect(l) => l.center,
            WedgeLight::Sphere { center, .. } => *center,
        }
    }

    /// The light seen in the plane through `o` spanned by the orthonormal `x`, `y` (projected
    /// along `x × y`): its two points of smallest and largest angle around `o` measured from
    /// `x`, when it spans less than half a turn and does not contain `o`.
    fn angular_extremes(&self, o: DVec3, x: DVec3, y: DVec3) -> Option<(DVec2, DVec2)> {
        let local = |q: DVec3| DVec2::new((q - o).dot(x), (q - o).dot(y));
        match self {
            WedgeLight::Rect(l) => angular_extremes(l.corners().map(local)),
            WedgeLight::Sphere { center, radius } => {
                let (lo, hi) = tangent_angles(local(*center), *radius)?;
                Some((DVec2::from_angle(lo), DVec2::from_angle(hi)))
            }
        }
    }
}

/// The angles (from the x axis, `lo < hi`) of the two tangents from the origin to the disk of
/// `radius` around `m`: `atan2(m) ∓ asin(radius/|m|)`; `None` when the origin is not outside
/// the disk.
fn tangent_angles(m: DVec2, radius: f64) -> Option<(f64, f64)> {
    let d = m.length();
    if d.is_nan() || d <= radius {
        return None;
    }
    let half = libm::asin(radius / d);
    let phi = libm::atan2(m.y, m.x);
    Some((phi - half, phi + half))
}

/// A wedge vertex: a finite point or a direction at infinity (w = 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WedgeVertex {
    /// A finite world-space point.
    Point(DVec3),
    /// A world-space direction, the vertex at infinity (w = 0).
    Direction(DVec3),
}

impl WedgeVertex {
    /// Clip coordinates (points as [`Projection::clip_point`], directions as
    /// [`Projection::clip_direction`]).
    pub fn clip(&self, proj: &Projection) -> ClipVertex {
        match self {
            WedgeVertex::Point(p) => proj.clip_point(p.as_vec3()),
            WedgeVertex::Direction(d) => proj.clip_direction(*d),
        }
    }
}

/// A plane `normal · (x − origin) ≥ 0` for the inside, `normal` of unit length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfSpace {
    /// A point of the plane.
    pub origin: DVec3,
    /// Unit normal pointing into the wedge.
    pub normal: DVec3,
}

impl HalfSpace {
    /// Signed distance of `x` to the plane, positive inside.
    pub fn distance(&self, x: DVec3) -> f64 {
        self.normal.dot(x - self.origin)
    }
}

/// A penumbra wedge of Paper III §3.1 (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct SsvWedge {
    /// The top edge: `A` (the edge vertex nearer the light center) and the adjusted `B`.
    pub top: [DVec3; 2],
    /// Front, back, left, right planes, normals pointing inside.
    pub planes: [HalfSpace; 4],
    /// The six faces as triangles, wound counter-clockwise seen from outside (front-facing
    /// when seen from outside the wedge).
    pub triangles: [[WedgeVertex; 3]; 6],
}

impl SsvWedge {
    /// The wedge of edge `e0 e1` under `light` (module doc); `None` when it is degenerate
    /// (module doc, "Degenerate wedges").
    pub fn new(light: &WedgeLight, e0: DVec3, e1: DVec3) -> Option<SsvWedge> {
        let c = light.center();
        let (near, far) = if (e0 - c).length() <= (e1 - c).length() {
            (e0, e1)
        } else {
            (e1, e0)
        };
        let a = near;
        let b = c + (far - c) * ((a - c).length() / (far - c).length());
        let d = (b - a).try_normalize()?;
        // Front and back planes: the corners' sector around the axis A B (step 2).
        let r0 = reject(c - a, d).try_normalize()?;
        let r1 = d.cross(r0);
        let (q_min, q_max) = light.angular_extremes(a, r0, r1)?;
        let front = HalfSpace {
            origin: a,
            normal: (r1 * q_max.x - r0 * q_max.y).try_normalize()?,
        };
        let back = HalfSpace {
            origin: a,
            normal: (r0 * q_min.y - r1 * q_min.x).try_normalize()?,
        };
        // Side planes (step 3).
        let right = side_plane(b, b - a, light)?;
        let left = side_plane(a, a - b, light)?;
        let away = (a - c).normalize() + (b - c).normalize();
        let edge_dir = |p: &HalfSpace, q: &HalfSpace| -> Option<DVec3> {
            let l = p.normal.cross(q.normal).try_normalize()?;
            Some(if l.dot(away) < 0.0 { -l } else { l })
        };
        let fl = edge_dir(&front, &left)?;
        let fr = edge_dir(&front, &right)?;
        let bl = edge_dir(&back, &left)?;
        let br = edge_dir(&back, &right)?;
        let scale = (b - a).length().max(1e-6);
        let faces: [(Vec<(DVec3, WedgeVertex)>, &HalfSpace); 4] = [
            (
                vec![pt(a), pt(b), dir(b, fr, scale), dir(a, fl, scale)],
                &front,
            ),
            (
                vec![pt(a), pt(b), dir(b, br, scale), dir(a, bl, scale)],
                &back,
            ),
            (vec![pt(a), dir(a, fl, scale), dir(a, bl, scale)], &left),
            (vec![pt(b), dir(b, fr, scale), dir(b, br, scale)], &right),
        ];
        let mut triangles = Vec::with_capacity(6);
        for (poly, plane) in faces {
            let n = (poly[1].0 - poly[0].0).cross(poly[2].0 - poly[0].0);
            let mut v: Vec<WedgeVertex> = poly.iter().map(|x| x.1).collect();
            if n.dot(plane.normal) > 0.0 {
                v.reverse();
            }
            for k in 1..v.len() - 1 {
                triangles.push([v[0], v[k], v[k + 1]]);
            }
        }
        Some(SsvWedge {
            top: [a, b],
            planes: [front, back, left, right],
            triangles: triangles.try_into().ok()?,
        })
    }

    /// Whether `p` is inside the wedge (Paper III §3.2.2 pseudo code line 4): inside all four
    /// planes (points on a plane count as inside).
    pub fn contains(&self, p: DVec3) -> bool {
        self.shader_contains::<f64>(p)
    }

    /// [`SsvWedge::contains`] evaluated by a fragment program in the shader precision `T`
    /// (`[options.gpu] shader`): the planes and `p` rounded to `T`, every operation rounded.
    pub fn shader_contains<T: ShaderFloat>(&self, p: DVec3) -> bool {
        let p = SVec3::<T>::from_f64(p);
        self.planes
            .iter()
            .all(|h| SVec3::from_f64(h.normal).dot(p - SVec3::from_f64(h.origin)) >= T::zero())
    }

    /// Whether [`SsvWedge::shader_contains`] in the format of `rounding` fails at every point of the
    /// box `[lo, hi]`: one of the four planes rejects the whole box, with a margin for the
    /// program's rounding ([`plane_rejects_box`]). The hierarchical-Z unit's test of a wedge
    /// against a tile's receiver bounds ([`crate::gpu::hiz`]).
    pub fn rejects_box(&self, bounds: [DVec3; 2], rounding: &InsideTestRounding) -> bool {
        self.planes
            .iter()
            .any(|h| plane_rejects_box(h.normal, h.origin, bounds, rounding))
    }

    /// Whether `p` is within distance `r` of the inside of every plane (a conservative test
    /// for "`p` is near or inside the wedge").
    pub fn contains_within(&self, p: DVec3, r: f64) -> bool {
        self.planes.iter().all(|h| h.distance(p) >= -r)
    }
}

fn pt(p: DVec3) -> (DVec3, WedgeVertex) {
    (p, WedgeVertex::Point(p))
}

/// A vertex at infinity in direction `d` from `origin`, with a finite stand-in at `origin +
/// scale·d` for the winding test.
fn dir(origin: DVec3, d: DVec3, scale: f64) -> (DVec3, WedgeVertex) {
    (origin + d * scale, WedgeVertex::Direction(d))
}

/// `x` minus its component along the unit vector `d`.
fn reject(x: DVec3, d: DVec3) -> DVec3 {
    x - d * x.dot(d)
}

/// The corners with the smallest and largest angle around the origin measured from the
/// positive x axis, when they span less than half a turn (and none is at the origin).
fn angular_extremes(q: [DVec2; 4]) -> Option<(DVec2, DVec2)> {
    let ang: Vec<f64> = q.iter().map(|p| libm::atan2(p.y, p.x)).collect();
    let (mut lo, mut hi) = (0, 0);
    for i in 1..4 {
        if ang[i] < ang[lo] {
            lo = i;
        }
        if ang[i] > ang[hi] {
            hi = i;
        }
    }
    let spans_half_turn = ang[hi] - ang[lo] >= std::f64::consts::PI;
    if spans_half_turn || q.contains(&DVec2::ZERO) {
        return None;
    }
    Some((q[lo], q[hi]))
}

/// The side plane through `at` (module doc, step 3); `outward` points from the other top
/// vertex to `at`. The whole light must lie on the light side (angles from `t` in (0, π)).
fn side_plane(at: DVec3, outward: DVec3, light: &WedgeLight) -> Option<HalfSpace> {
    let t = outward.try_normalize()?;
    let g = reject(light.center() - at, t).try_normalize()?;
    let q = match light {
        WedgeLight::Rect(l) => {
            let mut best: Option<DVec2> = None;
            for q in l.corners() {
                let p = DVec2::new((q - at).dot(t), (q - at).dot(g));
                if p.y <= 0.0 {
                    return None;
                }
                // Largest angle from t in (0, π): p is counter-clockwise of the best so far.
                if best.is_none_or(|b| b.perp_dot(p) > 0.0) {
                    best = Some(p);
                }
            }
            best?
        }
        WedgeLight::Sphere { center, radius } => {
            let m = DVec2::new((*center - at).dot(t), (*center - at).dot(g));
            let (lo, hi) = tangent_angles(m, *radius)?;
            if lo <= 0.0 || hi >= std::f64::consts::PI {
                return None;
            }
            DVec2::from_angle(hi)
        }
    };
    Some(HalfSpace {
        origin: at,
        normal: (g * q.x - t * q.y).try_normalize()?,
    })
}
