//! Tighter penumbra wedges (Paper IV §4.1) for rectangular and spherical lights, and their split
//! into an inner and an outer half by the plane of the hard shadow quad (Paper IV §4.2 Fig. 2,
//! §4.4).
//!
//! # Construction
//! The edge vertex farther from the light center `c` is moved toward `c` to the other vertex's
//! distance (Paper III §3.1, kept by Paper IV §4.1), giving the adjusted edge `e0' e1'`. Each end
//! vertex `e` is the apex of the **end pyramid**: the light reflected through `e`, i.e. the rays
//! `e + λ(e − l_k)`, `λ ≥ 0`, over the light's corners `l_k`. Every ray from a light point through
//! a point `(1−t)·e0' + t·e1'` of the edge is a convex combination of rays of the two end pyramids,
//! so the **convex hull of the two end pyramids** contains the penumbra volume of the edge. Its
//! facets are exactly the wedge of §4.1: the front and back planes through the edge touching the
//! light, and at each end the outermost ("leftmost/rightmost") triangles of the end pyramid.
//! They are found by enumerating the candidate planes spanned by the generators (2 apexes and
//! the 2·k ray directions) and keeping those with every generator on one side.
//!
//! Choices where the paper is silent:
//! - **Spherical lights** (module section "Spheres" below). Paper IV §4.1 builds the wedge from
//!   "the two end pyramids that are formed by the reflection of the light source through the
//!   edge end points" and describes the swept circular cone of a sphere (its Fig. 1a), but
//!   gives the construction for rectangles only.
//! - **`bounding-sphere`.** Paper IV §4.1's baseline, "our previously presented method created
//!   wedges from bounding spheres surrounding the light source", is read as Paper III's wedge
//!   ([`SsvWedge`]: front and back planes tangent to the sphere, one side plane per end) of the
//!   light's bounding sphere: for a rectangle the sphere through its corners, for a sphere
//!   light the sphere itself ([`bounding_sphere_halfspaces`]).
//! - **Finite wedges.** Receivers lie inside the scene's bounding box, so a wedge is the
//!   intersection of its facet half-spaces with that box (slightly enlarged), built by clipping
//!   the box polyhedron plane by plane. Wedges are never drawn beyond the box; none of their
//!   pixels can hold a receiver point there.
//! - **Halves.** The wedge is cut by the plane of the hard shadow quad (through `c`, `e0`, `e1`).
//!   Both halves share one cut polygon (the "wedge center polygons" of Fig. 2) with bit-identical
//!   vertices, listed in opposite winding with the same fan, so the rasterizer gives both the
//!   same pixels and depths and every receiver point falls in exactly one half.
//!
//! # Spheres
//! For a sphere (center `c`, radius `r`) the end pyramid at an adjusted end point `e` becomes
//! the cone of the sphere reflected through `e`. Every ray from a point of the ball through `e`
//! crosses the plane of the sphere's silhouette circle seen from `e` inside that circle's disk
//! (the tangent cone from `e` is the cone over the disk), so the pyramid over a polygon
//! **circumscribing** that disk holds the cone ([`sphere_silhouette_polygon`]): a regular
//! `N`-gon, `N` = [`DEFAULT_SPHERE_SIDES`] (`ssv-optimized`'s `sphere-sides`). The convex hull
//! of the two end pyramids, each over its own end's polygon ([`hull_halfspaces`]; one corner
//! set for both ends would add the rays from the other end's polygon and be looser), encloses
//! the penumbra volume and is at most `1/cos(π/N)` wider (in the tangent of the angle seen
//! from the edge) than the hull of the two cones. It is then intersected with Paper III's
//! wedge of the sphere ([`paper3_halfspaces`]), which encloses the penumbra volume too, so the
//! result never exceeds Paper III's wedge: the hull's facets along the edge are replaced by
//! Paper III's front and back planes (the exact tangent planes through the edge; planes
//! through one line a small angle apart would only leave sliver faces), and each end is the
//! tighter of the polygon hull's facets and Paper III's side plane
//! ([`sphere_wedge_halfspaces`]).
//!
//! `N` trades fragments for triangles. Measured on `cube-of-spheres-sphere` at 256², fragments
//! shaded by the wedge pass (Paper III's wedges, `ssv`: 157,526; the bounding cube's hull
//! `ssv-optimized` used before: 237,973), triangles submitted and the pass's time (best of
//! three): N = 4: 142,463, 35,974, 0.056 s; 8: 134,160, 48,282, 0.070 s; 16: 131,305, 74,412,
//! 0.097 s; 32: 130,483, 126,482, 0.213 s. This rasterizer's time follows the triangles, so
//! the default is 8: 97% of the fragment saving of N = 32 for 38% of its triangles.
//!
//! A sphere narrower than [`MIN_SPHERE_WEDGE_ANGLE`] (10⁻³ rad) seen from the edge gets the
//! hull over its bounding cube's corners instead ([`thin_light_cube`]), in both `tight` and
//! `bounding-sphere`: every plane of so thin a wedge meets the hard-quad plane, which runs
//! through the same edge, within that angle, and the halves cut from the polygon or tangent
//! planes lost receivers on the edge itself (found by fuzzing), while the cube's hull splits
//! as before.

use super::ssv_wedge::{SsvWedge, WedgeLight};
use crate::gpu::shader_float::ShaderFloat;
use crate::gpu::shader_vec::SVec3;
use glam::{DVec3, Vec3};
use std::cmp::Ordering;

/// A half-space `normal · x ≤ offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfSpace {
    /// Outward normal (unit length).
    pub normal: DVec3,
    /// Plane offset.
    pub offset: f64,
}

impl HalfSpace {
    /// Signed distance of `x` (positive outside).
    pub fn distance(&self, x: DVec3) -> f64 {
        self.normal.dot(x) - self.offset
    }

    /// The complementary half-space.
    pub fn flipped(&self) -> Self {
        Self {
            normal: -self.normal,
            offset: -self.offset,
        }
    }
}

/// A closed convex polyhedron as a list of convex faces, each counter-clockwise seen from
/// outside.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ConvexPolyhedron {
    /// Faces.
    pub faces: Vec<Vec<DVec3>>,
}

/// The point where segment `p q` crosses the plane, computed from the endpoints in a canonical
/// (lexicographic) order so that the two faces sharing the segment get the same bits.
fn crossing(p: DVec3, q: DVec3, plane: &HalfSpace) -> DVec3 {
    let (a, b) = if (p.x, p.y, p.z) <= (q.x, q.y, q.z) {
        (p, q)
    } else {
        (q, p)
    };
    let (da, db) = (plane.distance(a), plane.distance(b));
    a + (b - a) * (da / (da - db))
}

impl ConvexPolyhedron {
    /// The axis-aligned box `[lo, hi]`.
    pub fn aabb(lo: DVec3, hi: DVec3) -> Self {
        let v = |i: usize| {
            DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        };
        let quads: [[usize; 4]; 6] = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        Self {
            faces: quads
                .iter()
                .map(|q| q.iter().map(|&i| v(i)).collect())
                .collect(),
        }
    }

    /// Whether the polyhedron has no faces (empty).
    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// All vertices (with repetitions).
    pub fn vertices(&self) -> impl Iterator<Item = &DVec3> {
        self.faces.iter().flatten()
    }

    /// Cut by `plane`: returns (the part inside, the part outside, the cut polygon oriented
    /// as an outward face of the inside part). The outside part carries the same cut polygon
    /// reversed with the same first vertex.
    pub fn split(&self, plane: &HalfSpace) -> (Self, Self, Vec<DVec3>) {
        let mut inside = Vec::new();
        let mut outside = Vec::new();
        let mut cut_points: Vec<DVec3> = Vec::new();
        for face in &self.faces {
            let mut fin = Vec::new();
            let mut fout = Vec::new();
            for k in 0..face.len() {
                let p = face[k];
                let q = face[(k + 1) % face.len()];
                let (dp, dq) = (plane.distance(p), plane.distance(q));
                if dp <= 0.0 {
                    fin.push(p);
                }
                if dp >= 0.0 {
                    fout.push(p);
                }
                if dp == 0.0 {
                    cut_points.push(p);
                }
                if (dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0) {
                    let x = crossing(p, q, plane);
                    fin.push(x);
                    fout.push(x);
                    cut_points.push(x);
                }
            }
            if fin.len() >= 3 && face.iter().any(|p| plane.distance(*p) < 0.0) {
                inside.push(fin);
            }
            if fout.len() >= 3 && face.iter().any(|p| plane.distance(*p) > 0.0) {
                outside.push(fout);
            }
        }
        let cut = order_in_plane(cut_points, plane.normal);
        let mut inside = Self { faces: inside };
        let mut outside = Self { faces: outside };
        if cut.len() >= 3 {
            if !inside.is_empty() {
                inside.faces.push(cut.clone());
            }
            if !outside.is_empty() {
                let mut rev = vec![cut[0]];
                rev.extend(cut[1..].iter().rev());
                outside.faces.push(rev);
            }
        }
        (inside, outside, cut)
    }

    /// Clip to the half-space (keep the inside).
    pub fn clip(&self, plane: &HalfSpace) -> Self {
        self.split(plane).0
    }

    /// Whether `x` is inside or on every face plane (within `eps`). Faces of no width — the
    /// slivers clipping leaves where a cutting plane runs along an edge or through a vertex,
    /// whose vertices coincide or line up to rounding — have no meaningful plane and are
    /// skipped: a face counts when its width, its Newell normal (twice its area) over half its
    /// perimeter, exceeds [`MIN_FACE_WIDTH`] of the polyhedron's size. A polyhedron with no
    /// face that counts is flat (a sliver part of a split, found by fuzzing) and contains
    /// nothing.
    pub fn contains(&self, x: DVec3, eps: f64) -> bool {
        self.shader_contains::<f64>(x, eps)
    }

    /// [`ConvexPolyhedron::contains`] evaluated by a fragment program in the shader precision
    /// `T` (`[options.gpu] shader`, [`crate::gpu::shader_float`]): which faces count, their
    /// normals, points and tolerances are uniforms computed in f64; `x`, rounded to `T`, is
    /// tested against each plane with every operation rounded.
    pub fn shader_contains<T: ShaderFloat>(&self, x: DVec3, eps: f64) -> bool {
        let x = SVec3::<T>::from_f64(x);
        let Some(origin) = self.vertices().next().copied() else {
            return false;
        };
        let size = self
            .vertices()
            .map(|v| (*v - origin).length())
            .fold(0.0, f64::max);
        let mut counted = false;
        for f in &self.faces {
            let n = newell_normal(f);
            let half_perimeter = 0.5
                * (0..f.len())
                    .map(|k| (f[(k + 1) % f.len()] - f[k]).length())
                    .sum::<f64>();
            // NaN widths (NaN vertices) count, so their NaN distance makes x outside.
            if n.length() <= MIN_FACE_WIDTH * size * half_perimeter {
                continue;
            }
            // A NaN distance is unordered, so it counts as outside.
            let distance = SVec3::from_f64(n).dot(x - SVec3::from_f64(f[0]));
            let inside = distance.partial_cmp(&T::from_f64(eps * n.length()));
            if !matches!(
                inside,
                Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)
            ) {
                return false;
            }
            counted = true;
        }
        counted
    }
}

/// Narrowest face, relative to its polyhedron's size, whose plane [`ConvexPolyhedron::contains`]
/// tests: 10⁻⁹, the tolerance within which this module counts a point as on a plane
/// ([`wedge_halfspaces`]' facet test, [`bounding_planes`]). A face's plane is found from its
/// vertices, so vertex errors δ tilt it by about δ / its width and move it by δ·size / width
/// across the polyhedron; a face narrower than that tolerance lines up to within it and has no
/// plane worth testing. Found by fuzzing: splitting a 10⁻⁶ rad thin wedge by the hard shadow
/// quad's plane, which runs along the wedge's edge, cut it at crossings of edges lying in the
/// plane to rounding and left a triangle 3·10⁻⁴ wide and 3·10⁷ long (10⁻¹¹ of the size, but above
/// the 10⁻¹² area test used before) whose rounded plane cut off the edge's own end by 424
/// units, so that end was in neither half.
pub const MIN_FACE_WIDTH: f64 = 1e-9;

/// Newell's normal of a polygon (unnormalized, outward for a counter-clockwise face).
fn newell_normal(f: &[DVec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for k in 0..f.len() {
        let (a, b) = (f[k], f[(k + 1) % f.len()]);
        n += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    n
}

/// The order of `f64::partial_cmp`, with NaN after every number and equal to NaN: a total
/// preorder, so a sort cannot panic whatever reaches it, and for NaN-free values exactly
/// `partial_cmp` (−0 and +0 stay equal and keep their order in a stable sort), so results do
/// not change where there is no NaN. (`total_cmp` would order −0 before +0, which moves the
/// first vertex of a cut polygon and with it the rasterized bits.) No NaN reaches the sorts
/// from a validated scene — its numbers are finite f32, so distances and crossings computed
/// from them in f64 are finite, and the `tight_wedge` fuzz target checks that every vertex is —
/// but a sort must not be where a broken guarantee turns into a panic.
fn float_order(a: f64, b: f64) -> Ordering {
    a.partial_cmp(&b)
        .unwrap_or_else(|| a.is_nan().cmp(&b.is_nan()))
}

/// Lexicographic [`float_order`] on `(x, y, z)`.
fn point_order(a: &DVec3, b: &DVec3) -> Ordering {
    float_order(a.x, b.x)
        .then_with(|| float_order(a.y, b.y))
        .then_with(|| float_order(a.z, b.z))
}

/// Deduplicate coplanar points and order them counter-clockwise around `normal`.
fn order_in_plane(mut pts: Vec<DVec3>, normal: DVec3) -> Vec<DVec3> {
    pts.sort_by(point_order);
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let center = pts.iter().copied().sum::<DVec3>() / pts.len() as f64;
    let t = normal.any_orthonormal_vector();
    let b = normal.cross(t);
    let mut keyed: Vec<(f64, DVec3)> = pts
        .into_iter()
        .map(|p| {
            let d = p - center;
            (libm::atan2(d.dot(b), d.dot(t)), p)
        })
        .collect();
    keyed.sort_by(|x, y| float_order(x.0, y.0));
    keyed.into_iter().map(|(_, p)| p).collect()
}

/// The edge `e0 e1` with its farther vertex moved toward `center` to the nearer vertex's
/// distance (Paper III §3.1, Paper IV §4.1).
pub fn adjusted_edge(center: DVec3, e0: DVec3, e1: DVec3) -> [DVec3; 2] {
    let (d0, d1) = ((e0 - center).length(), (e1 - center).length());
    if d0 > d1 {
        [center + (e0 - center) * (d1 / d0), e1]
    } else {
        [e0, center + (e1 - center) * (d0 / d1)]
    }
}

/// Smallest sine of the angle between the two vectors whose cross product is a candidate facet
/// normal in [`wedge_halfspaces`]: the normal of nearly parallel vectors is off by about
/// ε / sine, which must stay well below the 10⁻⁹ tolerance of the facet test.
pub const MIN_CANDIDATE_SINE: f64 = 1e-6;

/// The facet half-spaces of the convex hull of the two end pyramids of edge `e0 e1` for a
/// light with the given corners (module doc, "Construction"). `center` is the light center
/// (for the edge adjustment, and a point of the light whose rays through the apexes lie inside
/// the pyramids, [`hull_halfspaces`]). May be fewer than needed to bound the wedge when the
/// edge crosses the light (the wedge is then everything on one side, §4.1). Candidate planes
/// that rounding leaves undetermined are left out — spanned by nearly parallel generators
/// (sine below `MIN_CANDIDATE_SINE`, 10⁻⁶), with every generator within the relative 10⁻⁹
/// tolerance of the plane (the edge in the light's plane, or a light too small seen from the
/// edge), or with generators on both sides of it beyond the normal's rounding (a diagonal of
/// a thin light) — so the wedge may be larger than the hull but cuts into it by no more than
/// that tolerance.
pub fn wedge_halfspaces(center: DVec3, corners: &[DVec3], e0: DVec3, e1: DVec3) -> Vec<HalfSpace> {
    hull_halfspaces(center, adjusted_edge(center, e0, e1), [corners, corners])
}

/// The facet half-spaces of the convex hull of the end pyramids with apexes `apex[i]` over the
/// corners `corners[i]` (rays `apex[i] + λ(apex[i] − l)`, `l ∈ corners[i]`, `λ ≥ 0`):
/// [`wedge_halfspaces`] with a corner set per end (a sphere's circumscribed polygons,
/// [`sphere_wedge_halfspaces`]). The same tolerances apply.
///
/// `center` is a point inside the light (its center), so the ray from it through each apex
/// lies inside that apex's pyramid; a facet must have those rays on its inner side as well as
/// the corners' rays. The corners' rays alone cannot tell a facet's side when the light is
/// seen nearly edge-on from both apexes (found by fuzzing: a rectangle 9·10¹² wide, 0.19 below
/// an edge parallel to it): every corner ray then lies within the tolerance of the plane
/// parallel to the light through an apex, rising above it by the apex's height over the
/// corner's distance (2·10⁻¹⁴), and the other apex alone put the plane through the higher one
/// on the wrong side, cutting the wedge, which holds the whole half-space above the light
/// there, down to a slab as thick as the apexes' heights differ (1.4·10⁻³), which clipping to
/// a scene box of 10³⁸ then lost. The center's ray rises by that height over its own length
/// (10⁻² here), far beyond the tolerance, and rules the plane out.
pub fn hull_halfspaces(center: DVec3, apex: [DVec3; 2], corners: [&[DVec3]; 2]) -> Vec<HalfSpace> {
    let dirs: Vec<DVec3> = apex
        .iter()
        .zip(corners)
        .flat_map(|(a, ls)| ls.iter().map(move |l| *a - *l))
        .collect();
    // The rays from the center through the apexes, each measured against its own length.
    let center_rays = apex.map(|a| (a - center).normalize_or_zero());
    let scale = dirs
        .iter()
        .map(|d| d.length())
        .fold(0.0, f64::max)
        .max(1e-300);
    // Each candidate normal u × v with |u|·|v|, to tell how well it is determined.
    let mut candidates = Vec::new();
    let edge = apex[1] - apex[0];
    for d in &dirs {
        candidates.push((edge.cross(*d), edge.length() * d.length()));
    }
    for i in 0..dirs.len() {
        for j in i + 1..dirs.len() {
            candidates.push((dirs[i].cross(dirs[j]), dirs[i].length() * dirs[j].length()));
        }
    }
    let edge_len = edge.length();
    let mut out: Vec<HalfSpace> = Vec::new();
    for (n, lengths) in candidates {
        let len = n.length();
        // Nearly parallel u and v give a normal off by about ε / sin(u, v): beyond
        // MIN_CANDIDATE_SINE that error could exceed eps and let a plane through the hull
        // (found by fuzzing: a light 5·10⁻⁹ rad wide seen from the edge got an empty wedge).
        if len <= 1e-12 * scale * scale.max(edge_len) || len <= MIN_CANDIDATE_SINE * lengths {
            continue;
        }
        let n = n / len;
        // Generators on a facet are on its computed plane to within the normal's error, about
        // ε / sin(u, v) relative: the tolerance of the facet test (at most 10⁻⁹). A looser one
        // lets near-facets cut into a hull thinner than it (found by fuzzing: two such planes
        // of opposite sides left nothing of the wedge of a light 3·10⁻¹⁰ rad wide).
        let eps = (64.0 * f64::EPSILON * lengths / len).min(1e-9);
        // Directions on both sides of the plane beyond a few roundings of the normal (not
        // eps) rule it out: a facet has every generator on one side up to that rounding, while
        // the plane through an apex and a diagonal of a thin light has the other two corners'
        // rays on either side by the light's thickness, which can be below eps (found by
        // fuzzing: a rectangle 6·10⁻⁵ by 1.6·10⁻¹⁰ rad seen from the edge, eps 2.4·10⁻¹⁰; the
        // two diagonal planes through each apex bounded the wedge to the edge's own length
        // along the light at every distance). Leaving a plane out only makes the wedge larger.
        let straddle = (4.0 * f64::EPSILON * lengths / len).min(eps);
        // The generators' signed distances along n, as the range [lo, hi] of the values:
        // the directions' part (the corners' rays over the longest, the center's rays over
        // their own length) does not depend on the apex, and directions on both sides rule
        // the candidate out for both apexes (then it stops early).
        let mut dir_range = (f64::INFINITY, f64::NEG_INFINITY);
        let mut nan = false;
        let corner_values = dirs.iter().map(|d| n.dot(*d) / scale);
        for v in corner_values.chain(center_rays.iter().map(|r| n.dot(*r))) {
            nan |= v.is_nan();
            dir_range = (dir_range.0.min(v), dir_range.1.max(v));
            if dir_range.0 < -straddle && dir_range.1 > straddle {
                break;
            }
        }
        // A NaN value satisfies none of the tests below (each needs every value compared true).
        if nan || (dir_range.0 < -straddle && dir_range.1 > straddle) {
            continue;
        }
        for a in apex {
            // The apexes' side is measured against the edge's length: against the light's
            // distance, a plane could cut off a whole apex within the tolerance when the light
            // is 10⁹ edge lengths away (found by fuzzing: an empty wedge).
            let mut range = dir_range;
            for p in apex {
                let v = n.dot(p - a) / edge_len.max(f64::MIN_POSITIVE);
                nan |= v.is_nan();
                range = (range.0.min(v), range.1.max(v));
            }
            if nan {
                break;
            }
            // A plane every generator lies on within eps separates nothing it can be sure of:
            // the generators may lie on both sides (a light whose angular size seen from the
            // edge is below eps). Keeping it, and the same plane found again with the opposite
            // normal, cut the wedge to nothing (found by fuzzing: a light of radius 0.003 at
            // 10⁹ from the edge lost its whole penumbra). Leaving it out can only make the
            // wedge larger.
            if range.0 >= -eps && range.1 <= eps {
                continue;
            }
            let sign = if range.1 <= eps {
                1.0
            } else if range.0 >= -eps {
                -1.0
            } else {
                continue;
            };
            let h = HalfSpace {
                normal: n * sign,
                offset: (n * sign).dot(a),
            };
            if !out.iter().any(|o| nearly_parallel(o, &h)) {
                out.push(h);
            }
        }
    }
    // Two facets with opposite normals would hold both pyramids in a slab, which pyramids
    // opening across it cannot fit: every ray then lies on the plane within the tolerance, on
    // a side the facet test cannot tell, and both are left out (found by fuzzing: a rectangle
    // 7·10¹³ long and 60 wide 1.8·10⁹ from the edge, whose corners' rays lie 6·10⁻¹³ of their
    // length off one plane while the rays from its middle spread 2.4·10⁻⁸ rad across it, got a
    // slab 0.25 thick between the apexes' levels, which clipping to a 10³⁸ box lost).
    let opposed: Vec<bool> = out
        .iter()
        .map(|h| out.iter().any(|o| nearly_antiparallel(o, h)))
        .collect();
    out.into_iter()
        .zip(opposed)
        .filter_map(|(h, opposed)| (!opposed).then_some(h))
        .collect()
}

/// Whether two half-spaces' outward normals are opposite within 10⁻⁹ rad, the largest
/// tolerance of [`hull_halfspaces`]' facet test.
fn nearly_antiparallel(a: &HalfSpace, b: &HalfSpace) -> bool {
    a.normal.dot(b.normal) < 0.0 && a.normal.cross(b.normal).length() <= 1e-9
}

/// Whether two half-spaces' outward normals are within 1.4·10⁻⁶ rad (`n·n' > 1 − 10⁻¹²`). Two
/// supporting planes of one convex set with normals that close are the same plane to within
/// that angle over the set; keeping both leaves a sliver face between them whose Newell normal
/// is off by about ε/angle, enough to put the edge itself outside the wedge (found by fuzzing:
/// a sphere 1.8·10⁻⁴ wide, 8 units from the edge, whose two end polygons gave front planes
/// 8·10⁻⁸ rad apart through the same edge, and Paper III's front plane 5·10⁻⁷ rad from them).
/// The later one is left out, which can only make the wedge larger, by at most that angle.
fn nearly_parallel(a: &HalfSpace, b: &HalfSpace) -> bool {
    a.normal.dot(b.normal) > 1.0 - 1e-12
}

/// Default number of sides of the polygons circumscribing a sphere's silhouette disks
/// ([`sphere_wedge_halfspaces`], module doc "Spheres"): the end pyramids are at most
/// `1/cos(π/8)` ≈ 1.082 times as wide (in the tangent of the half angle) as the end cones.
pub const DEFAULT_SPHERE_SIDES: usize = 8;

/// The corners of the regular `sides`-gon circumscribing the silhouette disk of the sphere
/// (`center`, `radius`) seen from `apex` (module doc, "Spheres"): the disk of the tangent
/// points, at distance `(d² − r²)/d` from `apex` toward the center, of radius `r·√(d² − r²)/d`
/// (`d = |center − apex|`). Every ray from a point of the ball through `apex` crosses that
/// disk's plane inside the disk, hence inside the polygon, so the pyramid over the polygon
/// reflected through `apex` holds the reflected cone of the sphere. `None` when `apex` is not
/// outside the sphere (no cone: the wedge is the whole space) or `sides < 3`. The polygon's
/// first vertex is in the direction `u.any_orthonormal_vector()` from the disk's center,
/// `u` the unit direction from `apex` to `center`.
pub fn sphere_silhouette_polygon(
    center: DVec3,
    radius: f64,
    apex: DVec3,
    sides: usize,
) -> Option<Vec<DVec3>> {
    let to_center = center - apex;
    let d = to_center.length();
    if sides < 3 || d.is_nan() || d <= radius {
        return None;
    }
    let u = to_center / d;
    let along = (d - radius) * (d + radius) / d;
    let disk = (radius / d) * ((d - radius) * (d + radius)).sqrt();
    let half = std::f64::consts::PI / sides as f64;
    let vertex_radius = disk / libm::cos(half);
    let m = apex + u * along;
    let b1 = u.any_orthonormal_vector();
    let b2 = u.cross(b1);
    Some(
        (0..sides)
            .map(|k| {
                let t = 2.0 * half * k as f64;
                m + (b1 * libm::cos(t) + b2 * libm::sin(t)) * vertex_radius
            })
            .collect(),
    )
}

/// Paper IV §4.1's tight wedge of edge `e0 e1` for a **sphere** light (module doc, "Spheres"):
/// Paper III's front and back planes (tangent to the sphere through the adjusted edge,
/// [`paper3_halfspaces`]), the facet half-spaces of the convex hull of the two end pyramids
/// over the `sides`-gons circumscribing the sphere's silhouette disks seen from the adjusted
/// end points ([`sphere_silhouette_polygon`], [`hull_halfspaces`]) except its facets along the
/// edge (normal within `MIN_SIDE_FACET_SINE`, 0.05, of perpendicular to it: its own front and back,
/// looser than Paper III's, and the facets between them and the ends, within the wedge's angle
/// of Paper III's), then Paper III's two side planes unless nearly parallel to a plane already
/// kept. Every one of these holds the penumbra volume, so the wedge does, and it is never
/// larger than Paper III's wedge. The hull alone when Paper III's wedge has no planes; the
/// bounding cube's hull for a sphere narrower than [`MIN_SPHERE_WEDGE_ANGLE`]
/// ([`thin_light_cube`]); empty (the whole space) when an end point is not outside the
/// sphere.
pub fn sphere_wedge_halfspaces(
    center: DVec3,
    radius: f64,
    sides: usize,
    e0: DVec3,
    e1: DVec3,
) -> Vec<HalfSpace> {
    let apex = adjusted_edge(center, e0, e1);
    if let Some(cube) = thin_light_cube(center, radius, apex[0]) {
        return wedge_halfspaces(center, &cube, e0, e1);
    }
    let polygon = |a: DVec3| sphere_silhouette_polygon(center, radius, a, sides);
    let (Some(p0), Some(p1)) = (polygon(apex[0]), polygon(apex[1])) else {
        return Vec::new();
    };
    let hull = hull_halfspaces(center, apex, [&p0, &p1]);
    let paper3 = paper3_halfspaces(&WedgeLight::Sphere { center, radius }, e0, e1);
    if paper3.is_empty() {
        return hull;
    }
    // The hull's facets along the edge (its front and back, tangent to the polygons, and those
    // next to them) give way to Paper III's front and back planes (tangent to the sphere):
    // planes through one line, or one end, a small angle apart cut the box into sliver faces
    // whose rounding put the edge itself 10⁻⁶ outside the wedge or its halves (found by
    // fuzzing, at 3, 11 and 64 sides).
    let along = (apex[1] - apex[0]).normalize_or_zero();
    let side = |h: &HalfSpace| h.normal.dot(along).abs() >= MIN_SIDE_FACET_SINE;
    let mut planes: Vec<HalfSpace> = paper3[..2].to_vec();
    planes.extend(hull.into_iter().filter(side));
    for h in &paper3[2..] {
        if !planes.iter().any(|o| nearly_parallel(o, h)) {
            planes.push(*h);
        }
    }
    planes
}

/// Smallest sine of the angle between a hull facet of a sphere's tight wedge and the edge for
/// [`sphere_wedge_halfspaces`] to keep it: facets closer to the edge's direction run along the
/// wedge's front or back, within the wedge's angle of Paper III's front and back planes.
const MIN_SIDE_FACET_SINE: f64 = 0.05;

/// Narrowest sphere (its radius over its distance from the adjusted edge) that gets the
/// wedges of [`sphere_wedge_halfspaces`] and [`bounding_sphere_halfspaces`]; a narrower one
/// gets the hull over the 8 corners of its bounding cube ([`thin_light_cube`]).
pub const MIN_SPHERE_WEDGE_ANGLE: f64 = 1e-3;

/// The 8 corners of the cube around the sphere when it is narrower than
/// [`MIN_SPHERE_WEDGE_ANGLE`] seen from the adjusted end point `apex` (else `None`). Every
/// plane of a wedge that thin is within that angle of the hard-quad plane, which runs through
/// the same edge: Paper III's tangent planes and the polygons' facets then meet it and each
/// other so obliquely that the halves cut from the wedge lost receivers on the edge itself
/// (by 10⁻⁶ of the scene for a sphere 10⁻⁵ rad wide; found by fuzzing), while the cube's hull
/// (the construction `ssv-optimized` used for every sphere before) splits cleanly. The cube's
/// wedge is at most `√3` times as wide, here less than 2·10⁻³ rad: a few pixels at most.
pub fn thin_light_cube(center: DVec3, radius: f64, apex: DVec3) -> Option<Vec<DVec3>> {
    if radius > MIN_SPHERE_WEDGE_ANGLE * (apex - center).length() {
        return None;
    }
    Some(
        (0..8)
            .map(|i| {
                let s = |b: usize| if i & b == 0 { -radius } else { radius };
                center + DVec3::new(s(1), s(2), s(4))
            })
            .collect(),
    )
}

/// Paper III's wedge of the sphere (`center`, `radius`) for edge `e0 e1`
/// ([`paper3_halfspaces`]): `ssv-optimized`'s `wedge = bounding-sphere`, "our previously
/// presented method created wedges from bounding spheres surrounding the light source" (Paper
/// IV §4.1) — except for a sphere narrower than [`MIN_SPHERE_WEDGE_ANGLE`], which gets the
/// hull over its bounding cube ([`thin_light_cube`]).
pub fn bounding_sphere_halfspaces(
    center: DVec3,
    radius: f64,
    e0: DVec3,
    e1: DVec3,
) -> Vec<HalfSpace> {
    let apex = adjusted_edge(center, e0, e1);
    match thin_light_cube(center, radius, apex[0]) {
        Some(cube) => wedge_halfspaces(center, &cube, e0, e1),
        None => paper3_halfspaces(&WedgeLight::Sphere { center, radius }, e0, e1),
    }
}

/// The four planes (front, back, left, right) of Paper III's wedge of edge `e0 e1`
/// ([`SsvWedge`], §3.1) as outward half-spaces; empty when that wedge is degenerate (Paper
/// III's whole space, [`SsvWedge::new`] returns `None`). With a sphere around a light this is
/// "the previously presented method \[that\] created wedges from bounding spheres" of Paper IV
/// §4.1 ([`bounding_sphere_halfspaces`]).
pub fn paper3_halfspaces(light: &WedgeLight, e0: DVec3, e1: DVec3) -> Vec<HalfSpace> {
    SsvWedge::new(light, e0, e1).map_or_else(Vec::new, |w| {
        w.planes
            .iter()
            .map(|h| HalfSpace {
                normal: -h.normal,
                offset: -h.normal.dot(h.origin),
            })
            .collect()
    })
}

/// The plane of the hard shadow quad of the silhouette edge `a → b` (oriented as in its
/// light-facing triangle, [`super::silhouette::SilhouetteEdge`]) from light point `c`, as the
/// half-space of the **inner** wedge half (the umbra side): `n = (a − c) × (b − c)` points out
/// of the shadow volume (the light-facing triangle (a, b, x), counter-clockwise from outside
/// and facing c, has `det(a − c, b − c, x − c) < 0`: the tetrahedron (c, a, b, x) is an odd
/// permutation of the positively oriented (a, b, x, c)).
pub fn quad_inner_halfspace(c: DVec3, a: DVec3, b: DVec3) -> HalfSpace {
    let n = (a - c).cross(b - c);
    let n = n / n.length().max(1e-300);
    HalfSpace {
        normal: n,
        offset: n.dot(c),
    }
}

/// The box wedges are clipped to (module doc, "Finite wedges"): the scene's bounds (`bounds`:
/// [`crate::scene::Scene::bounds`], or [`crate::frame::Frame::influence_bounds`] without the
/// meshes whose shadow reaches no receiver) enlarged by 1% of their diagonal plus 10⁻³. The
/// diagonal is the f32 one the goldens pin, or the f64 one where that overflows: a scene may
/// span more than the f32 range (found by fuzzing: an infinite box, whose clipped wedges had
/// infinite and NaN vertices).
pub fn wedge_clip_box(bounds: (Vec3, Vec3)) -> (DVec3, DVec3) {
    let (lo, hi) = bounds;
    let diagonal = (hi - lo).length();
    let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
    let diagonal = if diagonal.is_finite() {
        diagonal as f64
    } else {
        (hi - lo).length()
    };
    let margin = diagonal * 0.01 + 1e-3;
    (lo - margin, hi + margin)
}

/// The inner (umbra side) and outer halves of the wedge of silhouette edge `a → b` for a light
/// with center `c` and the given corners, clipped to the box `[lo, hi]`, and the wedge's facet
/// half-spaces ([`wedge_halfspaces`]) they were cut from.
pub fn wedge_halves_and_planes(
    c: DVec3,
    corners: &[DVec3],
    a: DVec3,
    b: DVec3,
    lo: DVec3,
    hi: DVec3,
) -> ([ConvexPolyhedron; 2], Vec<HalfSpace>) {
    let planes = wedge_halfspaces(c, corners, a, b);
    (halves_from_planes(&planes, c, a, b, lo, hi), planes)
}

/// The inner (umbra side) and outer halves of the wedge with the facet half-spaces `planes` of
/// silhouette edge `a → b` for a light with center `c`, clipped to the box `[lo, hi]`
/// ([`polyhedron_from_planes`], split by [`quad_inner_halfspace`]).
pub fn halves_from_planes(
    planes: &[HalfSpace],
    c: DVec3,
    a: DVec3,
    b: DVec3,
    lo: DVec3,
    hi: DVec3,
) -> [ConvexPolyhedron; 2] {
    let wedge = polyhedron_from_planes(planes, lo, hi);
    if wedge.is_empty() {
        return [wedge.clone(), wedge];
    }
    let (inner, outer, _) = wedge.split(&quad_inner_halfspace(c, a, b));
    [inner, outer]
}

/// The box `[lo, hi]` clipped by every half-space of `planes`, in order (empty as soon as a
/// clip leaves nothing).
pub fn polyhedron_from_planes(planes: &[HalfSpace], lo: DVec3, hi: DVec3) -> ConvexPolyhedron {
    let mut wedge = ConvexPolyhedron::aabb(lo, hi);
    for h in planes {
        wedge = wedge.clip(h);
        if wedge.is_empty() {
            break;
        }
    }
    wedge
}

/// The planes among `planes` that bound `half`: those holding at least three of its vertices
/// (within 10⁻⁹ of the polyhedron's size) — the "outside bounding planes" of a half-wedge
/// (Forest et al. 2006 §4.2, after Lengyel), without the planes of the clip box and the cut.
pub fn bounding_planes(half: &ConvexPolyhedron, planes: &[HalfSpace]) -> Vec<HalfSpace> {
    let size = half
        .vertices()
        .map(|v| v.abs().max_element())
        .fold(1.0, f64::max);
    planes
        .iter()
        .filter(|h| {
            let mut on: Vec<DVec3> = half
                .vertices()
                .filter(|v| h.distance(**v).abs() <= 1e-9 * size)
                .copied()
                .collect();
            on.sort_by(point_order);
            on.dedup();
            on.len() >= 3
        })
        .copied()
        .collect()
}

/// The whole wedge (not split), clipped to the box.
pub fn whole_wedge(
    c: DVec3,
    corners: &[DVec3],
    a: DVec3,
    b: DVec3,
    lo: DVec3,
    hi: DVec3,
) -> ConvexPolyhedron {
    polyhedron_from_planes(&wedge_halfspaces(c, corners, a, b), lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(c: DVec3, h: f64) -> Vec<DVec3> {
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .iter()
            .map(|(s, t)| c + DVec3::new(s * h, 0.0, t * h))
            .collect()
    }

    #[test]
    fn wedge_contains_every_light_ray_through_the_edge() {
        let c = DVec3::new(0.0, 3.0, 0.0);
        let corners = square(c, 0.5);
        let (a, b) = (DVec3::new(-0.4, 1.0, 0.3), DVec3::new(0.5, 1.3, 0.2));
        let w = whole_wedge(c, &corners, a, b, DVec3::splat(-5.0), DVec3::splat(5.0));
        for i in 0..=8 {
            for j in 0..=8 {
                for k in 0..=8 {
                    let l = c + DVec3::new(i as f64 / 8.0 - 0.5, 0.0, j as f64 / 8.0 - 0.5);
                    let e = a.lerp(b, k as f64 / 8.0);
                    let x = e + (e - l) * 1.5;
                    assert!(w.contains(x, 1e-9), "{x}");
                }
            }
        }
        // A point straight below the middle of the edge far from the penumbra is outside.
        assert!(!w.contains(DVec3::new(3.0, -1.0, 3.0), 1e-9));
    }

    #[test]
    fn halves_partition_the_wedge_and_share_the_cut() {
        let c = DVec3::new(0.0, 3.0, 0.0);
        let corners = square(c, 0.5);
        let (a, b) = (DVec3::new(-0.5, 1.0, 0.0), DVec3::new(0.5, 1.0, 0.0));
        let [inner, outer] =
            wedge_halves_and_planes(c, &corners, a, b, DVec3::splat(-4.0), DVec3::splat(4.0)).0;
        let ic = inner.faces.last().unwrap();
        let oc = outer.faces.last().unwrap();
        assert_eq!(ic[0], oc[0]);
        assert_eq!(ic[1], oc[oc.len() - 1]);
        // Light-facing triangle (a, b, x) with x toward −z seen... pick the inner side by the
        // rule: det(a − c, b − c, x − c) < 0 for points of the shadow volume.
        let probe_in = DVec3::new(0.0, 0.0, 0.05);
        let probe_out = DVec3::new(0.0, 0.0, -0.05);
        let n = (a - c).cross(b - c);
        let (pin, pout) = if n.dot(probe_in - c) < 0.0 {
            (probe_in, probe_out)
        } else {
            (probe_out, probe_in)
        };
        assert!(inner.contains(pin, 1e-12) && !inner.contains(pout, 1e-12));
        assert!(outer.contains(pout, 1e-12) && !outer.contains(pin, 1e-12));
    }

    /// A NaN vertex (no validated scene makes one, but nothing may panic on it) is sorted after
    /// every number instead of panicking a sort: splitting and bounding-plane selection finish.
    #[test]
    fn nan_vertices_do_not_panic_the_sorts() {
        let mut poly = ConvexPolyhedron::aabb(DVec3::splat(-1.0), DVec3::ONE);
        poly.faces[0][1] = DVec3::new(f64::NAN, 0.0, 0.0);
        poly.faces[2][0] = DVec3::new(0.0, f64::NAN, 1.0);
        let plane = HalfSpace {
            normal: DVec3::X,
            offset: 0.0,
        };
        let (inside, outside, _) = poly.split(&plane);
        assert!(!inside.is_empty() && !outside.is_empty());
        let ordered = order_in_plane(
            vec![
                DVec3::new(f64::NAN, 0.0, 0.0),
                DVec3::X,
                DVec3::Y,
                DVec3::ONE,
            ],
            DVec3::Z,
        );
        assert_eq!(ordered.len(), 4);
        let face_plane = HalfSpace {
            normal: DVec3::X,
            offset: 1.0,
        };
        assert_eq!(
            bounding_planes(&poly, &[plane, face_plane]),
            vec![face_plane]
        );
        assert_eq!(float_order(f64::NAN, 1.0), Ordering::Greater);
        assert_eq!(float_order(-0.0, 0.0), Ordering::Equal);
    }

    /// A polyhedron whose faces all have no area (a split leaves one on the far side of a plane
    /// that grazes a face: its vertices line up to rounding) contains nothing; before, with
    /// every face skipped, it contained every point.
    #[test]
    fn polyhedron_of_slivers_contains_nothing() {
        let line = vec![DVec3::ZERO, DVec3::Z, DVec3::Z * 2.0];
        let mut back = line.clone();
        back.reverse();
        let slivers = ConvexPolyhedron {
            faces: vec![line, back],
        };
        assert!(!slivers.contains(DVec3::new(-5.0, 0.5, 0.5), 1e-9));
        assert!(!slivers.contains(DVec3::Z, 1e-9));
        let cube = ConvexPolyhedron::aabb(DVec3::ZERO, DVec3::ONE);
        assert!(cube.contains(DVec3::splat(0.5), 0.0));
    }

    /// A light too small for the facet tolerance seen from the edge (0.003 wide, 1.2·10⁹
    /// away: 2.5·10⁻¹² rad) still gets a wedge that holds the edge and its penumbra: candidate
    /// planes that every generator lies on within the tolerance no longer cut it to nothing.
    #[test]
    fn wedge_of_a_light_below_the_facet_tolerance_is_not_empty() {
        let c = DVec3::new(0.0, 0.75, 1_185_546_240.0);
        let h = 0.0029296875;
        let corners: Vec<DVec3> = (0..8)
            .map(|i| {
                let s = |b: usize| if i & b == 0 { -h } else { h };
                c + DVec3::new(s(1), s(2), s(4))
            })
            .collect();
        let a = DVec3::new(0.0, 0.75, -7.25);
        let b = DVec3::new(2.7939677238464355e-9, 14_614_528_000.0, 0.75);
        let (lo, hi) = (
            DVec3::new(-146_625_361.921, -146_625_361.921, -146_625_369.171),
            DVec3::new(146_625_362.671, 14_761_153_361.921, 1_332_171_601.921),
        );
        let w = whole_wedge(c, &corners, a, b, lo, hi);
        let penumbra = DVec3::new(
            1.183327506570255e-9,
            6_189_682_447.491177,
            -3.8617647058823525,
        );
        for x in [a, a.lerp(b, 0.5), penumbra] {
            assert!(w.contains(x, 1e-3), "{x}");
        }
    }

    /// An edge end on the hard shadow quad's plane (a penumbra receiver at the edge itself)
    /// is in one of the halves of a wedge 10⁻⁶ rad thin, 5·10⁷ from the light (found by
    /// fuzzing): the split along the wedge's edge leaves sliver triangles (3·10⁻⁴ wide, 3·10⁷
    /// long) whose rounded planes cut the end off both halves by over 40 units.
    #[test]
    fn edge_end_on_the_split_plane_is_in_a_half() {
        let (u, v) = (
            DVec3::splat(28.0),
            DVec3::new(28.0, -9.313225746154785e-10, 2.0),
        );
        let r = (u + v).length().max((u - v).length());
        let corners: Vec<DVec3> = (0..8)
            .map(|i| {
                let s = |b: usize| if i & b == 0 { -r } else { r };
                DVec3::new(s(1), s(2), s(4))
            })
            .collect();
        let a = DVec3::new(0.0, -47374336.0, -47374336.0);
        let b = DVec3::new(-47374336.0, -47190016.0, -4096.0);
        let (lo, hi) = (
            DVec3::new(-48194883.601, -48194883.601, -48194883.601),
            DVec3::new(820548.101, 820560.601, 820547.601),
        );
        let [inner, outer] = wedge_halves_and_planes(DVec3::ZERO, &corners, a, b, lo, hi).0;
        let whole = whole_wedge(DVec3::ZERO, &corners, a, b, lo, hi);
        for x in [b, a.lerp(b, 0.5)] {
            assert!(whole.contains(x, 1.0), "{x}");
            assert!(inner.contains(x, 1.0) || outer.contains(x, 1.0), "{x}");
        }
    }

    /// Points of the sphere (center `c`, radius `r`): a latitude-longitude grid of its
    /// surface, poles included, and its center.
    fn sphere_points(c: DVec3, r: f64) -> Vec<DVec3> {
        let mut out = vec![c];
        for i in 0..=12 {
            let theta = std::f64::consts::PI * i as f64 / 12.0;
            for j in 0..24 {
                let phi = std::f64::consts::TAU * j as f64 / 24.0;
                out.push(
                    c + DVec3::new(
                        libm::sin(theta) * libm::cos(phi),
                        libm::cos(theta),
                        libm::sin(theta) * libm::sin(phi),
                    ) * r,
                );
            }
        }
        out
    }

    /// The circumscribed polygon holds the silhouette disk: every ray from a point of the
    /// sphere through the apex, reflected, crosses the polygon's plane inside the polygon.
    #[test]
    fn silhouette_polygon_holds_every_ray_through_the_apex() {
        let (c, r) = (DVec3::new(0.3, 3.0, -0.2), 0.6);
        let apex = DVec3::new(-0.4, 1.1, 0.5);
        for sides in [3, 8, 16] {
            let poly = sphere_silhouette_polygon(c, r, apex, sides).unwrap();
            let n = (c - apex).normalize();
            let m = poly.iter().copied().sum::<DVec3>() / sides as f64;
            for l in sphere_points(c, r) {
                // The ray from l through the apex, met where it crosses the plane on l's side.
                let d = apex - l;
                let t = n.dot(m - apex) / n.dot(-d);
                let x = apex - d * t;
                // Inside every side of the polygon (counter-clockwise around n or not).
                let inside = (0..sides).all(|k| {
                    let (p, q) = (poly[k], poly[(k + 1) % sides]);
                    let s = (q - p).cross(x - p).dot(n);
                    let orient = (poly[1] - poly[0]).cross(poly[2] - poly[1]).dot(n);
                    s * orient.signum() >= -1e-12
                });
                assert!(inside, "{sides} sides: {l} crosses the plane at {x}");
            }
        }
        assert!(sphere_silhouette_polygon(c, r, c + DVec3::X * 0.5, 8).is_none());
        assert!(sphere_silhouette_polygon(c, r, apex, 2).is_none());
    }

    /// Paper IV §4.1 for a sphere: the wedge holds every ray from a point of the sphere through
    /// a point of the edge (beyond the edge), for an edge whose far vertex is adjusted; it lies
    /// within Paper III's wedge, and is tighter than the hull over the bounding cube's corners.
    #[test]
    fn sphere_wedge_contains_every_ray_and_lies_in_paper_iii() {
        let (c, r) = (DVec3::new(0.0, 3.0, 0.0), 0.5);
        let (lo, hi) = (DVec3::splat(-5.0), DVec3::splat(5.0));
        let light = WedgeLight::Sphere {
            center: c,
            radius: r,
        };
        let cube: Vec<DVec3> = (0..8)
            .map(|i| {
                let s = |b: usize| if i & b == 0 { -r } else { r };
                c + DVec3::new(s(1), s(2), s(4))
            })
            .collect();
        for (a, b) in [
            (DVec3::new(-0.4, 1.0, 0.3), DVec3::new(0.5, 1.3, 0.2)),
            (DVec3::new(-0.6, 1.5, -0.5), DVec3::new(0.4, 0.8, 0.6)),
        ] {
            for sides in [3, DEFAULT_SPHERE_SIDES, 16] {
                let planes = sphere_wedge_halfspaces(c, r, sides, a, b);
                let w = polyhedron_from_planes(&planes, lo, hi);
                for l in sphere_points(c, r) {
                    for k in 0..=8 {
                        let e = a.lerp(b, k as f64 / 8.0);
                        for lambda in [0.0, 0.3, 1.0, 2.0] {
                            let x = e + (e - l) * lambda;
                            assert!(w.contains(x, 1e-9), "{sides} sides: {x}");
                        }
                    }
                }
            }
            // Grid points: inside the tight wedge ⇒ inside Paper III's; fewer than the cube's.
            let paper3 = SsvWedge::new(&light, a, b).unwrap();
            let tight = polyhedron_from_planes(
                &sphere_wedge_halfspaces(c, r, DEFAULT_SPHERE_SIDES, a, b),
                lo,
                hi,
            );
            let cube_wedge = whole_wedge(c, &cube, a, b, lo, hi);
            let (mut n_tight, mut n_paper3, mut n_cube) = (0, 0, 0);
            for i in 0..40 {
                for j in 0..20 {
                    for k in 0..40 {
                        let x = DVec3::new(i as f64, j as f64, k as f64) * 0.1
                            - DVec3::new(2.0, 1.0, 2.0);
                        if tight.contains(x, 0.0) {
                            n_tight += 1;
                            assert!(paper3.contains_within(x, 1e-9), "{x}");
                        }
                        n_paper3 += paper3.contains(x) as u32;
                        n_cube += cube_wedge.contains(x, 0.0) as u32;
                    }
                }
            }
            assert!(
                n_tight <= n_paper3 && n_tight < n_cube,
                "{n_tight} {n_paper3} {n_cube}"
            );
        }
    }

    /// A light 2·10¹³ by 2·10⁹ seen nearly edge-on from an edge 0.19 above it (found by
    /// fuzzing): its corners' rays rise 10⁻¹⁴ of their length above the light's plane, within
    /// the facet test's tolerance (10⁻¹⁰ for normals from rays 10⁻⁴ rad apart, across the
    /// light's short side), but the penumbra fills the half-space above the light there. Every
    /// point on a ray from a light point through the edge, here the rays from the light's
    /// middle straight up through the edge and from beside it, must be inside every facet
    /// (up to the tolerance, 10⁻⁹ of its distance); the plane through the higher apex parallel
    /// to the light (y ≤ 0.1996) left them outside by their height above it (0.19 at λ = 1).
    #[test]
    fn light_seen_edge_on_keeps_the_half_space_above_it() {
        let c = DVec3::ZERO;
        let (u, v) = (DVec3::new(1e13, 0.0, 0.0), DVec3::new(0.0, 0.0, 1e9));
        let corners = [c - u - v, c + u - v, c + u + v, c - u + v];
        let (a, b) = (DVec3::new(-1.0, 0.19, 0.0), DVec3::new(1.0, 0.2, 0.0));
        let planes = wedge_halfspaces(c, &corners, a, b);
        for (edge_point, light_point) in [
            (DVec3::new(0.0, 0.195, 0.0), c),
            (a, DVec3::new(-3.0, 0.0, 2.0)),
            (b, DVec3::new(1e6, 0.0, -1e6)),
        ] {
            for lambda in [1.0, 4.0, 1e3] {
                let p = edge_point + (edge_point - light_point) * lambda;
                for h in &planes {
                    assert!(
                        h.distance(p) <= 1e-9 * p.length(),
                        "{p} outside {h:?} by {}",
                        h.distance(p)
                    );
                }
            }
        }
    }

    /// A rectangle 1.7·10⁷ long and 60 thick seen from 2.7·10¹¹ (6·10⁻⁵ by 1.6·10⁻¹⁰ rad; found
    /// by fuzzing): the planes through an apex and a diagonal of the light have the other two
    /// corners' rays on either side, but only 1.6·10⁻¹⁰ of their length off, within the facet
    /// tolerance for normals from rays 6·10⁻⁵ rad apart (2.4·10⁻¹⁰). Kept as facets, the two
    /// diagonal planes through each apex, each within that tolerance of the penumbra, bounded
    /// the wedge together to the edge's own x range at every distance, where the penumbra fans
    /// out along the light's length (3·10⁹ at 10¹⁴). Every point on a ray from a light point
    /// through the edge must be in the wedge clipped to a box holding them (within 10⁻⁸ of the
    /// box, the fuzz target's margin).
    #[test]
    fn diagonal_planes_of_a_thin_light_are_not_facets() {
        let c = DVec3::new(0.0, 0.0, 2.7e11);
        let (u, v) = (DVec3::new(1.5, 21.0, 21.0), DVec3::new(-8.4e6, 0.0, 21.0));
        let corners = [c - u - v, c + u - v, c + u + v, c - u + v];
        let (a, b) = (
            DVec3::new(-0.25, 0.0, -26.5),
            DVec3::new(-6200.0, -1e-3, 10.0),
        );
        let planes = wedge_halfspaces(c, &corners, a, b);
        let size = 1e15;
        let whole = polyhedron_from_planes(&planes, DVec3::splat(-size), DVec3::splat(size));
        for light_point in corners.iter().chain([&c]) {
            for edge_point in [a, b, (a + b) * 0.5] {
                let p = edge_point + (edge_point - *light_point) * 400.0;
                assert!(whole.contains(p, 1e-8 * size), "{p} outside {whole:?}");
            }
        }
    }

    /// A rectangle 7·10¹³ long and 60 wide whose middle passes 1.8·10⁹ from the edge (found
    /// by fuzzing): its corners' rays lie within 6·10⁻¹³ of their length of one plane, within
    /// the facet tolerance, so that plane was kept through one apex and, opposite, through the
    /// other, a slab 0.25 thick, while the rays from the light's middle spread 2.4·10⁻⁸ rad
    /// across it. Every point on a ray from a light point through the edge must be inside every
    /// facet (up to the tolerance, 10⁻⁹ of its distance).
    #[test]
    fn long_thin_light_does_not_make_a_slab() {
        let c = DVec3::new(-2.75, -14.5576171875, 274408144896.0);
        let u = DVec3::new(1.4423828125, 21.3330078125, 21.3330078125);
        let v = DVec3::new(-227532603392.0, 0.0, 35183845703680.0);
        let corners = [c - u - v, c + u - v, c + u + v, c - u + v];
        let (a, b) = (
            DVec3::new(0.0, 0.0, -0.125),
            DVec3::new(-14.5615234375, -0.25, 10.6884765625),
        );
        let planes = wedge_halfspaces(c, &corners, a, b);
        // The light's points nearest the edge: its middle line where it crosses z = 0.
        let t = -c.z / v.z;
        for light_point in [c + v * t + u, c + v * t - u, c + v * t, c] {
            for edge_point in [a, b, (a + b) * 0.5] {
                for lambda in [1.0, 1e3] {
                    let p = edge_point + (edge_point - light_point) * lambda;
                    for h in &planes {
                        assert!(
                            h.distance(p) <= 1e-9 * (p - edge_point).length(),
                            "{p} outside {h:?} by {}",
                            h.distance(p)
                        );
                    }
                }
            }
        }
    }

    /// A sphere narrower than 10⁻³ rad seen from the edge gets its bounding cube's hull, in
    /// both constructions; a wider one does not.
    #[test]
    fn thin_spheres_get_the_bounding_cube() {
        let (a, b) = (DVec3::new(-0.4, 1.0, 0.3), DVec3::new(0.5, 1.3, 0.2));
        let c = DVec3::new(0.0, 3.0, 0.0);
        let r = 0.9e-3 * (adjusted_edge(c, a, b)[0] - c).length();
        let cube = thin_light_cube(c, r, adjusted_edge(c, a, b)[0]).unwrap();
        let hull = wedge_halfspaces(c, &cube, a, b);
        assert_eq!(sphere_wedge_halfspaces(c, r, 8, a, b), hull);
        assert_eq!(bounding_sphere_halfspaces(c, r, a, b), hull);
        assert!(thin_light_cube(c, 0.5, a).is_none());
        let light = WedgeLight::Sphere {
            center: c,
            radius: 0.5,
        };
        assert_eq!(
            bounding_sphere_halfspaces(c, 0.5, a, b),
            paper3_halfspaces(&light, a, b)
        );
    }

    #[test]
    fn adjusted_edge_is_equidistant() {
        let c = DVec3::ZERO;
        let [p, q] = adjusted_edge(c, DVec3::new(3.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0));
        assert!((p.length() - q.length()).abs() < 1e-15);
    }
}
