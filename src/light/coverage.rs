//! Exact coverage of a rectangular light by the projected semi-infinite hard shadow quad of one
//! silhouette edge, by clipping (Paper III §3.2.2, Figure 8).
//!
//! # What is computed
//!
//! For a silhouette edge `e0 e1` and the light center `c`, the *semi-infinite hard shadow quad*
//! `Q` is the part of the triangle cone `(c; e0, e1)` beyond the edge: `e0, e1` and the rays
//! `e_i + λ(e_i − c)`, `λ ≥ 0`. Seen from a receiver point `p`, `Q` is projected onto the
//! light; the **coverage** is the area of the light covered by that projection divided by the
//! light's area. Summed with signs over a closed silhouette loop and added to the hard shadow
//! count from the light center (pass 1), it gives the visible fraction of the light by Green's
//! theorem (Paper III §3.2, Figure 9).
//!
//! Only the part of `Q` strictly *between* `p` and the light plane can hide light from `p`, so
//! `Q` is first clipped to that slab; this also makes the result exact when the edge crosses
//! the plane through `p` parallel to the light (its projection then runs through infinity) or
//! lies behind `p`.
//!
//! # Representation
//!
//! Everything is done in f64 in the light's affine frame ([`RectLight`]): a point is
//! `c + s·u + t·v + h·n` with `n` the unit normal `u × v / |u × v|`, so the light is the square
//! `s, t ∈ [−1, 1]`, `h = 0`, whatever the angle between `u` and `v` (area ratios are affine
//! invariant). Points of `Q` are homogeneous 4-vectors `(s, t, h, w)` (the rays' ends are the
//! directions `(e_i − c, 0)`). The central projection from `p = (p_s, p_t, h_p)` onto `h = 0` is
//! the linear map `(s, t, h, w) ↦ (s·h_p − p_s·h, t·h_p − p_t·h, w·h_p − h)`, so all clipping —
//! the slab `0 ≤ h ≤ h_p·w` and the four light borders `|S| ≤ W`, `|T| ≤ W` — is done by
//! Sutherland–Hodgman on homogeneous coordinates before any division (the same technique
//! Paper IV §4.2.2 uses in its shader). The clipped polygon is convex; its area is the shoelace
//! formula on the dehomogenised vertices.
//!
//! # Shader precision
//!
//! The per-fragment computations ([`shader_edge_coverage`], [`shader_quad_side`],
//! [`shader_projected_edge_in_light`], and for spheres [`shader_sphere_edge_coverage`],
//! [`shader_clip_to_light_cone`], [`shader_sector_minus_triangle`],
//! [`shader_exact_sector_minus_triangle`]) are generic over the fragment program's scalar
//! ([`ShaderFloat`], `[options.gpu] shader`): the light frame (or the sphere's center and
//! radius), the edge and the receiver are rounded to it on input and every operation after
//! that is rounded. The f64 functions of the
//! same names without `shader_` are their f64 instances, used where the computation is not a
//! fragment program (the coverage texture's precomputation, tests).
//!
//! # Sign (Paper III §3.2.2, pseudo code lines 6–9)
//!
//! The paper adds the coverage when `p` is in the negative half space of `Q` (the side that
//! holds the umbra) and subtracts it otherwise. The functions here return the coverage signed
//! by the orientation of `(c, e0, e1, p)`: positive when `det(e0 − c, e1 − c, p − c) > 0`, i.e.
//! when `p` is on the side the normal `(e0 − c) × (e1 − c)` points to. A caller orders the edge so
//! that this normal points into its shadow volume and adds the result to its V-buffer.
//! (For a shadow quad `b, a, a∞, b∞` of [`crate::geometry::shadow_volume`], whose normal points
//! out of the volume, that is `e0 = b`, `e1 = a`.)
//!
//! [`projected_edge_in_light`] and [`segment_coverage`] split the same computation at the point
//! where the 4D coverage texture of Paper III §3.3 indexes it: the projected edge clipped to the
//! light square, and the coverage as a function of that clipped edge alone.
//!
//! # Sphere lights (Paper III §5.3, Paper IV §4.2.1)
//!
//! A sphere of center `c` and radius `r` is seen from a receiver `p` as the disk of radius `r`
//! through `c` perpendicular to `p − c` — the convention of the ray-cast reference
//! ([`crate::light::sampling`]). Everything above carries over with that disk as the light:
//! the same quad `Q`, projected from `p` onto the disk's plane after clipping to the slab
//! between `p` and that plane, signed by the same [`quad_side`]. The projection of `Q` is
//! bounded by the projected edge and the rays from `c` through its endpoints, so inside the
//! disk it is the part of the sector between those rays beyond the chord — *sector minus
//! triangle* (Paper IV §4.2.1, Fig. 5a; the same formula with the square is Paper IV
//! §4.2.2's rectangular shader). [`clip_to_light_cone`] gives the chord in the unit disk,
//! [`sector_minus_triangle`] the area and [`sphere_edge_coverage_exact`] the signed coverage.
//! Paper III §5.3 computes this in the shader, without a coverage texture.

use crate::gpu::shader_float::ShaderFloat;
use crate::gpu::shader_vec::{SVec2, SVec3, SVec4};
use crate::light::horizon::SquarePlane;
use crate::light::lookup_tables::AreaShape;
use crate::primitives::polygon_clip::{clip_polygon_into, clip_segment, clip_segment_marking};
use crate::scene::{Light, LightShape};
use arrayvec::ArrayVec;
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// A rectangular (parallelogram) light in f64 with its affine frame (module doc,
/// "Representation"): `center + s·u + t·v`, `s, t ∈ [−1, 1]` (Paper III §3.2.2: "a rectangular
/// light source L").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RectLight {
    /// The light center `c` (the point the hard shadow quads are built from).
    pub center: DVec3,
    /// Half-extent vector along `s`.
    pub u: DVec3,
    /// Half-extent vector along `t`.
    pub v: DVec3,
    /// Unit normal `u × v / |u × v|` (the `h` axis).
    pub normal: DVec3,
    /// Dual vector of `u`: `s = (x − c)·dual_u`.
    dual_u: DVec3,
    /// Dual vector of `v`: `t = (x − c)·dual_v`.
    dual_v: DVec3,
}

impl RectLight {
    /// The light `center + s·u + t·v`, `s, t ∈ [−1, 1]`. `u` and `v` must be non-parallel and
    /// non-zero (scene validation guarantees this for scene lights).
    pub fn new(center: DVec3, u: DVec3, v: DVec3) -> Self {
        let normal = u.cross(v).normalize();
        let dual_u = v.cross(normal) / u.dot(v.cross(normal));
        let dual_v = normal.cross(u) / v.dot(normal.cross(u));
        RectLight {
            center,
            u,
            v,
            normal,
            dual_u,
            dual_v,
        }
    }

    /// The rectangle of a `rect` or `textured_rect` scene light; `None` for other shapes.
    pub fn from_light(light: &Light) -> Option<Self> {
        match &light.shape {
            LightShape::Rect { u, v } | LightShape::TexturedRect { u, v, .. } => Some(
                RectLight::new(light.center.as_dvec3(), u.as_dvec3(), v.as_dvec3()),
            ),
            _ => None,
        }
    }

    /// The light-frame coordinates `(s, t, h)` of the world point `x`.
    pub fn local(&self, x: DVec3) -> DVec3 {
        self.shader_local::<f64>(x).to_f64()
    }

    /// [`RectLight::local`] in the shader precision `T` (module doc, "Shader precision").
    pub fn shader_local<T: ShaderFloat>(&self, x: DVec3) -> SVec3<T> {
        let d = SVec3::from_f64(x) - SVec3::from_f64(self.center);
        SVec3::new(
            d.dot(SVec3::from_f64(self.dual_u)),
            d.dot(SVec3::from_f64(self.dual_v)),
            d.dot(SVec3::from_f64(self.normal)),
        )
    }

    /// Light-frame units per world unit along `s` and `t`: `|dual_u|` and `|dual_v|`, the
    /// vectors [`RectLight::local`] takes dot products with. A world point `x` has its `s`
    /// and `t` known to about `ε·|x − c|` times these (the dual vectors are rounded), however
    /// small the coordinates themselves come out.
    pub fn local_scale(&self) -> DVec2 {
        DVec2::new(self.dual_u.length(), self.dual_v.length())
    }

    /// The world point at light-frame coordinates `(s, t, h)`.
    pub fn world(&self, local: DVec3) -> DVec3 {
        self.center + local.x * self.u + local.y * self.v + local.z * self.normal
    }

    /// The four corners, in order around the light: `(s, t)` = (−1, −1), (1, −1), (1, 1),
    /// (−1, 1).
    pub fn corners(&self) -> [DVec3; 4] {
        let c = self.center;
        [
            c - self.u - self.v,
            c + self.u - self.v,
            c + self.u + self.v,
            c - self.u + self.v,
        ]
    }

    /// The light's area `4·|u × v|`.
    pub fn area(&self) -> f64 {
        4.0 * self.u.cross(self.v).length()
    }
}

/// Signed exact coverage of `light` by the semi-infinite hard shadow quad of edge `e0 e1` seen
/// from `p` (Paper III §3.2.2): the covered area divided by the light area, in `[−1, 1]`,
/// positive when `det(e0 − c, e1 − c, p − c) > 0` (module doc, "Sign"). Zero when `p` lies in
/// the light's plane or in the plane of the quad.
pub fn edge_coverage_exact(light: &RectLight, p: DVec3, e0: DVec3, e1: DVec3) -> f64 {
    shader_edge_coverage::<f64>(light, p, e0, e1)
}

/// [`edge_coverage_exact`] in the shader precision `T` (module doc, "Shader precision"): the
/// fragment program of Paper III §3.2.2 ([`EdgeCoverageProgram`] for one edge at one point).
pub fn shader_edge_coverage<T: ShaderFloat>(
    light: &RectLight,
    p: DVec3,
    e0: DVec3,
    e1: DVec3,
) -> T {
    EdgeCoverageProgram::new(light, e0, e1).at(p)
}

/// The fragment program of [`shader_edge_coverage`] for one edge `e0 e1` (Paper III §3.2.2),
/// with what depends on the edge alone — the quad's normal and its vertices in the light's
/// frame — computed once, as a GPU program takes them as per-wedge constants, and the rest per
/// receiver by [`EdgeCoverageProgram::at`]. The same operations in the same order as computing
/// everything per receiver: the same bits (`ssv` on `cube-of-spheres` 512², one thread: 188 →
/// 177 ms).
#[derive(Debug, Clone)]
pub struct EdgeCoverageProgram<T> {
    light: RectLight,
    side: QuadSide<T>,
    /// The semi-infinite quad `e0, e1, e1∞, e0∞` in light coordinates `(s, t, h, w)`, clipped
    /// to the side of the light's plane of receivers below it (`[0]`, `h ≤ 0`) and above it
    /// (`[1]`, `h ≥ 0`): the first slab clip ([`ProjectionFromPoint::slab_planes`]) depends on
    /// the receiver only through that side, so both outcomes are per-wedge constants, computed
    /// by the same operations as per receiver (the same bits; `ssv` on `cube-of-spheres`
    /// 512², one thread, warm: 115 → 113 ms, near the noise).
    quad_beyond_light_plane: [QuadPart<T>; 2],
}

/// The semi-infinite quad of an [`EdgeCoverageProgram`] clipped to one side of the light's
/// plane: one Sutherland–Hodgman step on 4 vertices returns at most 6 ([`Polygon`]).
type QuadPart<T> = ArrayVec<SVec4<T>, 6>;

impl<T: ShaderFloat> EdgeCoverageProgram<T> {
    /// The program for edge `e0 e1` under `light`.
    pub fn new(light: &RectLight, e0: DVec3, e1: DVec3) -> Self {
        let (zero, one) = (T::zero(), T::one());
        // The local coordinates of e_i are also the ray directions e_i − c (the frame is
        // centered at c), so the rays' ends at infinity are the same vectors with w = 0.
        let l0 = light.shader_local::<T>(e0);
        let l1 = light.shader_local::<T>(e1);
        let quad = [
            l0.extend(one),
            l1.extend(one),
            l1.extend(zero),
            l0.extend(zero),
        ];
        let beyond = |flip: T| {
            let mut part = QuadPart::new();
            clip_beyond_light_plane_into(&quad, flip, |x| part.push(x));
            part
        };
        EdgeCoverageProgram {
            light: *light,
            side: QuadSide::new(light.center, e0, e1),
            quad_beyond_light_plane: [beyond(-one), beyond(one)],
        }
    }

    /// The signed coverage at the receiver `p` ([`edge_coverage_exact`]).
    pub fn at(&self, p: DVec3) -> T {
        self.covered(p, square_fraction)
    }

    /// The signed coverage at the receiver `p` of the part of the light in front of its own
    /// plane `plane` (`horizon = integrate`, [`crate::methods::ssv`]): the projected quad
    /// clipped to the light square as by [`EdgeCoverageProgram::at`], then by the half-plane
    /// `plane ≥ 0` (Sutherland–Hodgman, [`clip_polygon_into`]), its area over the **whole**
    /// light's (so that the sum over a silhouette composes with the fraction in front,
    /// `docs/horizon.md`). A caller whose plane has every corner of the light in front calls
    /// [`EdgeCoverageProgram::at`], which this equals there up to the clip's rounding.
    pub fn at_in_front(&self, p: DVec3, plane: &SquarePlane<T>) -> T {
        self.covered(p, |clipped| {
            let mut front: ArrayVec<SVec2<T>, IN_FRONT_CAPACITY> = ArrayVec::new();
            clip_polygon_into(clipped, |q| plane.at(q), |q| q, |q| front.push(q));
            square_fraction(&front)
        })
    }

    /// The sign of `p`'s side of the quad times `area` of the projected quad clipped to the
    /// light square (0 where `p` is in the quad's or the light's plane).
    fn covered(&self, p: DVec3, area: impl FnOnce(&[SVec2<T>]) -> T) -> T {
        let zero = T::zero();
        let sign = self.side.at(p);
        if sign == zero {
            return zero;
        }
        let Some(projection) = ProjectionFromPoint::<T>::new(&self.light, p) else {
            return zero;
        };
        // The polygons live in buffers of this frame, filled in place: a polygon collected
        // and returned by value is copied whole (profiled: 10 % of the wedge pass in
        // `memmove`).
        let half = &self.quad_beyond_light_plane[usize::from(projection.flip > zero)];
        let mut in_slab = Polygon::new();
        projection.clip_to_receiver_level_into(half, &mut in_slab);
        let mut clipped = Polygon::new();
        clip_to_light_into(in_slab.iter().map(|x| projection.apply(*x)), &mut clipped);
        sign * area(&clipped)
    }
}

/// `+1`, `−1` or `0`: the sign of `det(e0 − c, e1 − c, p − c)` for the light center `c`
/// (module doc, "Sign"), the side of the quad's plane `p` is on.
pub fn quad_side(c: DVec3, p: DVec3, e0: DVec3, e1: DVec3) -> f64 {
    shader_quad_side::<f64>(c, p, e0, e1)
}

/// [`quad_side`] in the shader precision `T` (module doc, "Shader precision").
pub fn shader_quad_side<T: ShaderFloat>(c: DVec3, p: DVec3, e0: DVec3, e1: DVec3) -> T {
    QuadSide::new(c, e0, e1).at(p)
}

/// [`shader_quad_side`] for one quad: its normal `(e0 − c) × (e1 − c)` computed once.
#[derive(Debug, Clone, Copy)]
struct QuadSide<T> {
    c: SVec3<T>,
    normal: SVec3<T>,
}

impl<T: ShaderFloat> QuadSide<T> {
    fn new(c: DVec3, e0: DVec3, e1: DVec3) -> Self {
        let c = SVec3::<T>::from_f64(c);
        let (e0, e1) = (SVec3::from_f64(e0), SVec3::from_f64(e1));
        QuadSide {
            c,
            normal: (e0 - c).cross(e1 - c),
        }
    }

    /// The side of `p`: `+1`, `−1` or `0`.
    fn at(&self, p: DVec3) -> T {
        let d = self.normal.dot(SVec3::from_f64(p) - self.c);
        let zero = T::zero();
        if d > zero {
            T::one()
        } else if d < zero {
            -T::one()
        } else {
            zero
        }
    }
}

/// The edge `e0 e1` projected from `p` onto the light and clipped to the light square, in light
/// coordinates `(s, t) ∈ [−1, 1]²` — the 4-tuple `(x1, y1, x2, y2)` that indexes the 4D
/// coverage texture (Paper III §3.3, Figure 8 right). The endpoints keep the edge's direction
/// (`e0` side first). Only the part of the edge between `p` and the light plane is projected
/// (module doc). `None` when nothing of the edge projects into the light.
pub fn projected_edge_in_light(
    light: &RectLight,
    p: DVec3,
    e0: DVec3,
    e1: DVec3,
) -> Option<[DVec2; 2]> {
    shader_projected_edge_in_light::<f64>(light, p, e0, e1).map(|e| e.map(SVec2::to_f64))
}

/// [`projected_edge_in_light`] in the shader precision `T` (module doc, "Shader precision"):
/// the texture coordinates Paper III §3.3's fragment program computes for the coverage
/// texture.
pub fn shader_projected_edge_in_light<T: ShaderFloat>(
    light: &RectLight,
    p: DVec3,
    e0: DVec3,
    e1: DVec3,
) -> Option<[SVec2<T>; 2]> {
    let one = T::one();
    let projection = ProjectionFromPoint::<T>::new(light, p)?;
    let seg = [
        light.shader_local::<T>(e0).extend(one),
        light.shader_local::<T>(e1).extend(one),
    ];
    let mut a = seg[0];
    let mut b = seg[1];
    for (k, plane) in projection.slab_planes().into_iter().enumerate() {
        clip_segment_marking(
            &mut a,
            &mut b,
            |x| plane.dot(x),
            |x| projection.onto_slab_plane(k, x),
        )?;
    }
    let mut a = BorderPoint::new(projection.apply(a));
    let mut b = BorderPoint::new(projection.apply(b));
    for k in 0..LIGHT_BORDERS {
        clip_segment_marking(&mut a, &mut b, |x| light_border(k, x.x), |x| x.on_border(k))?;
    }
    Some([in_light_square(a)?, in_light_square(b)?])
}

/// The light coordinates `(S/W, T/W)` of a homogeneous point clipped to the light square: a
/// coordinate of a point on a border ([`BorderPoint`]) is that border's ±1 exactly, the others
/// are clamped to `[−1, 1]`; `None` for a point with `W ≤ 0` (a direction at infinity, left
/// by a clip to the light square only as the zero vector, or from rounding) and for one on
/// two opposite borders. A NaN `W` gives NaN coordinates, not `None`, so that it shows in the
/// coverage. One rule for the projected edge's two ends and the clipped polygon's vertices.
/// The point lies in the square, but where its `W` is at the rounding of
/// the coordinates it was interpolated from, dividing puts it anywhere (found by fuzzing: a
/// receiver 6·10⁻⁹ from an edge lying at its own level, so that the whole projected edge is at
/// infinity and its clipped ends have `W` ≈ 2·10⁻¹⁶, gave s = −1.118); the clamp and the snap
/// remove only that rounding, and keep texture coordinates in the texture.
fn in_light_square<T: ShaderFloat>(x: BorderPoint<T>) -> Option<SVec2<T>> {
    let one = T::one();
    if x.x.z <= T::zero() {
        return None;
    }
    let on = |k: usize| x.on & (1 << k) != 0;
    let snap = |q: T, plus: usize, minus: usize| match (on(plus), on(minus)) {
        (true, true) => None,
        (true, false) => Some(one),
        (false, true) => Some(-one),
        (false, false) => Some(q.clamp(-one, one)),
    };
    let q = x.x.truncate() / x.x.z;
    Some(SVec2::new(snap(q.x, 0, 1)?, snap(q.y, 2, 3)?))
}

/// A homogeneous light-plane point `(S, T, W)` with the set of light borders it lies on (bit
/// `k`: the `k`-th functional of [`light_border`]), so that dehomogenising can put it on them
/// exactly ([`in_light_square`]). A point a clip creates lies on the border it was clipped
/// to, and a point interpolated between two points lies on every border both lie on (the
/// borders are linear functionals). Found by fuzzing: a rectangle 2·10⁻⁶ of its length wide
/// and skewed, an edge whose projection halves it, and the corners of the covered half
/// interpolated between points at infinity (`W` ≈ 10⁻¹⁰ from coordinates of size 8): they
/// came out at t = ±0.99999 instead of ±1, and the coverage's antisymmetry was off by
/// 2.3·10⁻⁶ (`fuzz/regressions/coverage/rect-5e5-to-1-skewed-light-antisymmetry-2.3e-6.bin`).
#[derive(Debug, Clone, Copy)]
struct BorderPoint<T> {
    x: SVec3<T>,
    /// Bit `k` set: the point lies on border `k`.
    on: u8,
}

impl<T: ShaderFloat> BorderPoint<T> {
    /// The point `x` on the borders whose functionals are exactly 0 at it (a direction at
    /// infinity along `T`, `(0, T, 0)`, lies on both `s` borders).
    fn new(x: SVec3<T>) -> Self {
        let on = (0..LIGHT_BORDERS)
            .filter(|&k| light_border(k, x) == T::zero())
            .fold(0, |on, k| on | 1 << k);
        BorderPoint { x, on }
    }

    /// The same point, marked as lying on border `k` (a clip to that border created it).
    fn on_border(self, k: usize) -> Self {
        BorderPoint {
            on: self.on | 1 << k,
            ..self
        }
    }
}

impl<T: ShaderFloat> std::ops::Add for BorderPoint<T> {
    type Output = Self;
    fn add(self, other: Self) -> Self {
        BorderPoint {
            x: self.x + other.x,
            on: self.on & other.on,
        }
    }
}

impl<T: ShaderFloat> std::ops::Sub for BorderPoint<T> {
    type Output = Self;
    fn sub(self, other: Self) -> Self {
        BorderPoint {
            x: self.x - other.x,
            on: self.on & other.on,
        }
    }
}

impl<T: ShaderFloat> std::ops::Mul<T> for BorderPoint<T> {
    type Output = Self;
    fn mul(self, k: T) -> Self {
        BorderPoint {
            x: self.x * k,
            on: self.on,
        }
    }
}

/// The edge `e0 e1` projected from `p` onto the light plane, in light coordinates `(s, t)`,
/// *not* clipped to the light square: the edge is clipped to the slab between the light plane
/// and a **local near plane** parallel to it at `(1 − near_fraction)` of `p`'s distance from the
/// light (Forest et al. 2006 §4.2, Fig. 9, after Lengyel: a point of the edge that does not
/// lie between `p` and the light plane "cannot be projected onto the area light plane"; the
/// near plane keeps the projection finite). The endpoints keep the edge's direction. `None`
/// when nothing of the edge lies in the slab, `p` is in the light plane, or an end's
/// projection is not finite (it overflowed).
///
/// With `near_fraction = 0` this is the projection [`projected_edge_in_light`] clips; a
/// positive fraction drops the part of the edge within `near_fraction·h_p` of `p`'s level,
/// whose projection lies farther than `d / near_fraction` from the projection of `p` (`d` the
/// edge's distance from `p` across the light normal), i.e. outside the light unless the edge
/// passes that close to `p`.
pub fn projected_edge_near_clipped(
    light: &RectLight,
    p: DVec3,
    e0: DVec3,
    e1: DVec3,
    near_fraction: f64,
) -> Option<[DVec2; 2]> {
    let projection = ProjectionFromPoint::<f64>::new(light, p)?;
    let mut a = light.shader_local::<f64>(e0).extend(1.0);
    let mut b = light.shader_local::<f64>(e1).extend(1.0);
    let [far, _] = projection.slab_planes();
    let near = SVec4::new(
        0.0,
        0.0,
        -projection.flip,
        projection.p.z * (1.0 - near_fraction),
    );
    for plane in [far, near] {
        clip_segment(&mut a, &mut b, |x| plane.dot(x))?;
    }
    let (a, b) = (projection.apply(a), projection.apply(b));
    if a.z <= 0.0 || b.z <= 0.0 {
        return None;
    }
    let (a, b) = ((a.truncate() / a.z).to_f64(), (b.truncate() / b.z).to_f64());
    (a.is_finite() && b.is_finite()).then_some([a, b])
}

/// Unsigned coverage of the light square by the region beyond the segment `a b` (light
/// coordinates inside `[−1, 1]²`) within the cone from the light center `(0, 0)` through it:
/// the quad `a, b, b∞, a∞` clipped to the square, area / 4 (Paper III §3.3: the function
/// `f(x1, y1, x2, y2)` the coverage texture stores). For a clipped projected edge from
/// [`projected_edge_in_light`] this equals the magnitude of [`edge_coverage_exact`] whenever the
/// edge lies entirely between `p` and the light plane. At most 1 (rounding clamped: found
/// by fuzzing, a segment whose end was 2·10⁻¹⁴ from the center, so that its ray's direction at
/// infinity was as short, gave 1.7·10¹³).
pub fn segment_coverage(a: DVec2, b: DVec2) -> f64 {
    let region: Vec<SVec2<f64>> = segment_region(a, b)
        .iter()
        .map(|v| SVec2::from_f64(*v))
        .collect();
    square_fraction(&region)
}

/// The region whose area [`segment_coverage`] measures, as a convex polygon in light
/// coordinates: the quad `a, b, b∞, a∞` clipped to the light square `[−1, 1]²` (Paper III
/// §3.3; textured lights weight it by the light texture).
///
/// When the line through `a` and `b` passes through the center the quad degenerates (the
/// receiver lies in the plane of the hard shadow quad) and the region is empty, as
/// [`edge_coverage_exact`] is 0 there. "Through the center" means within the rounding of
/// `a × b` (`|a × b| ≤ 16 ε |a| |b|`), not only exactly: for endpoints nearly opposite each
/// other a cross product of rounding noise decides which way the edge `b∞ a∞` at infinity
/// goes around, and the clipped quad came out on the wrong side or self-intersecting (a region
/// of area 5.5 > 4 for `a × b ≈ 10⁻¹⁷`; 1 812 texels of the n = 32 texture held values
/// anywhere in 0…1.37 for edges through the center, which the grid's rounding made non-zero).
pub fn segment_region(a: DVec2, b: DVec2) -> Vec<DVec2> {
    if a.perp_dot(b).abs() <= THROUGH_CENTER_ROUNDING * a.length() * b.length() {
        return Vec::new();
    }
    let quad = [a.extend(1.0), b.extend(1.0), b.extend(0.0), a.extend(0.0)].map(SVec3::from_f64);
    let mut clipped = Polygon::new();
    clip_to_light_into::<f64>(quad, &mut clipped);
    clipped.into_iter().map(SVec2::to_f64).collect()
}

/// `|a × b| / (|a| |b|)` at or below which a segment's line counts as passing through the light
/// center ([`segment_region`]): a few roundings of the cross product.
const THROUGH_CENTER_ROUNDING: f64 = 16.0 * f64::EPSILON;

/// Unsigned area of a simple polygon (shoelace formula).
pub fn polygon_area(poly: &[DVec2]) -> f64 {
    let poly: Vec<SVec2<f64>> = poly.iter().map(|v| SVec2::from_f64(*v)).collect();
    shader_polygon_area(&poly)
}

/// [`polygon_area`] in the shader precision `T`.
fn shader_polygon_area<T: ShaderFloat>(poly: &[SVec2<T>]) -> T {
    let Some(&last) = poly.last() else {
        return T::zero();
    };
    let mut twice_area = T::zero();
    // The edges in order, the closing one last, without a division per vertex.
    for w in poly.windows(2) {
        twice_area = twice_area + w[0].perp_dot(w[1]);
    }
    twice_area = twice_area + last.perp_dot(poly[0]);
    (T::from_f64(0.5) * twice_area).abs()
}

/// Signed exact coverage of the disk that the sphere light (`center`, `radius`) shows to `p` by
/// the semi-infinite hard shadow quad of edge `e0 e1` (module doc, "Sphere lights"; Paper III
/// §5.3): the covered area divided by the disk's area, in `[−1, 1]`, with the sign of
/// [`quad_side`] as [`edge_coverage_exact`] for a rectangle. Zero when `p` is in the plane of
/// the quad or inside the sphere.
pub fn sphere_edge_coverage_exact(
    center: DVec3,
    radius: f64,
    p: DVec3,
    e0: DVec3,
    e1: DVec3,
) -> f64 {
    shader_sphere_edge_coverage::<f64>(center, radius, p, e0, e1)
}

/// [`sphere_edge_coverage_exact`] in the shader precision `T` (module doc, "Shader
/// precision"): the fragment program of Paper III §5.3 and Paper IV §4.2.1's spherical shader
/// with exact arithmetic (its `atan2` and sector area rounded to `T`).
pub fn shader_sphere_edge_coverage<T: ShaderFloat>(
    center: DVec3,
    radius: f64,
    p: DVec3,
    e0: DVec3,
    e1: DVec3,
) -> T {
    let sign = shader_quad_side::<T>(center, p, e0, e1);
    if sign == T::zero() {
        return T::zero();
    }
    match shader_clip_to_light_cone::<T>(center, radius, p, e0, e1) {
        Some([a, b]) => sign * shader_exact_sector_minus_triangle(a, b, AreaShape::Disk),
        None => T::zero(),
    }
}

/// The edge `e0 e1` in the light space of receiver `p` (Paper IV §4.2.1: `p` at the origin,
/// the light center at z = 1, the radius 1), clipped to the cone x² + y² ≤ z² over the facing
/// disk and to the slab 0 < z ≤ 1 between `p` and the disk's plane, and projected to z = 1:
/// the chord of the unit disk that bounds the projected quad (module doc, "Sphere lights").
/// Clipping the edge rather than the quad to the slab is enough: the quad runs from the edge
/// away from the center, which lies in the plane z = 1, so beyond a point with z ≤ 1 it stays
/// at z ≤ 1, and its part that reaches z ≤ 0 projects onto the rest of the sector beyond the
/// chord. `None` when nothing of the edge is left (or `p` is inside the light).
pub fn clip_to_light_cone(
    center: DVec3,
    radius: f64,
    p: DVec3,
    e0: DVec3,
    e1: DVec3,
) -> Option<[DVec2; 2]> {
    shader_clip_to_light_cone::<f64>(center, radius, p, e0, e1).map(|c| c.map(SVec2::to_f64))
}

/// [`clip_to_light_cone`] in the shader precision `T` (module doc, "Shader precision"): the
/// light center, radius, receiver and edge rounded to `T` on input, every operation rounded.
pub fn shader_clip_to_light_cone<T: ShaderFloat>(
    center: DVec3,
    radius: f64,
    p: DVec3,
    e0: DVec3,
    e1: DVec3,
) -> Option<[SVec2<T>; 2]> {
    let (zero, one) = (T::zero(), T::one());
    let center = SVec3::<T>::from_f64(center);
    let radius = T::from_f64(radius);
    let w = center - SVec3::from_f64(p);
    let dist = w.length();
    if dist <= radius || !dist.is_finite() {
        return None;
    }
    let z = w / dist;
    let x = z.any_orthonormal_vector();
    let y = z.cross(x);
    // Light-space coordinates of e as (x, y, u) with z = 1 + u: u = (e − c)·z / dist is the
    // depth beyond the disk's plane. They come from e's offset to the light center, since
    // (e − p)·x = (e − c)·x and (e − p)·z = (e − c)·z + dist (x, y ⟂ z = (c − p)/dist), and u is
    // kept apart from the 1. Both matter when p is far from a light that is near the edge
    // (found by fuzzing): the offset from p loses the edge to rounding (a radius-10⁻³⁹ light
    // and an edge 10⁻³⁸ away seen from 1 unit gave half the light covered where the edge hides
    // none of it), and z rounds to 1 on both sides of the disk's plane (a receiver 4·10³⁷ away
    // saw an edge end behind the light as in front of it).
    let to_light = |e: DVec3| {
        let d = SVec3::from_f64(e) - center;
        SVec3::new(d.dot(x) / radius, d.dot(y) / radius, d.dot(z) / dist)
    };
    // The edge is parametrized as o + s·d, s ∈ [lo, hi], from o, its point nearest the light
    // center (found by fuzzing). A point q0 + d·t carries an error of ε·(|q0| + |d·t|) and
    // the cone's quadratic has coefficients as large as |q0|² and |d|², so the chord, at most
    // a few radii from the center, was lost to rounding when the parameter started at an end
    // far from it: from the far end of an edge reaching 10⁶ radii away (coverage 0.261 one
    // way, 0 the other), and from either end of an edge crossing the cone in the middle of
    // 2·10⁸ radii. `o` is found from the end nearer the center, with an error of ε times that
    // end's distance, and the quadratic in s has coefficients |o|² and |d|², whose roots are
    // as accurate as the chord's own coordinates.
    let (q0, q1) = (to_light(e0), to_light(e1));
    let from_e1 = q1.dot(q1) < q0.dot(q0);
    let (near, d) = if from_e1 {
        (q1, q0 - q1)
    } else {
        (q0, q1 - q0)
    };
    // NaN for coincident ends: then o is that point (and lo ≤ hi keeps both candidates).
    let foot = -near.dot(d) / d.dot(d);
    let foot = if foot.to_f64().is_nan() {
        zero
    } else {
        foot.clamp(zero, one)
    };
    let o = near + d * foot;
    let (lo, hi) = (-foot, one - foot);
    let zo = one + o.z;
    let g = |s: T| {
        let q = o + d * s;
        let zq = one + q.z;
        q.x * q.x + q.y * q.y - zq * zq
    };
    // Breakpoints: roots of g (the cone) and of z = 0 and z = 1 (u = −1, u = 0) in (lo, hi).
    let qa = d.x * d.x + d.y * d.y - d.z * d.z;
    let qb = o.x * d.x + o.y * d.y - zo * d.z;
    let qc = o.x * o.x + o.y * o.y - zo * zo;
    // At most 6 candidates (lo, hi, two cone roots, z = 0, z = 1): a fixed array, since this
    // runs per fragment. NaN candidates fail the range test and are left out.
    let mut buf = [zero; 6];
    let mut len = 0;
    let mut push = |s: T| {
        if lo <= s && s <= hi {
            buf[len] = s;
            len += 1;
        }
    };
    push(lo);
    push(hi);
    if qa.abs() > T::from_f64(1e-300) {
        let disc = qb * qb - qa * qc;
        if disc >= zero {
            let s = disc.sqrt();
            let r = -(qb + qb.signum() * s);
            if r != zero {
                push(r / qa);
                push(qc / r);
            } else {
                // qb = 0 and a double root: at s = 0 (the line touches the cone at o).
                push(zero);
            }
        }
    } else if qb != zero {
        push(-qc / (T::from_f64(2.0) * qb));
    }
    if d.z != zero {
        push(-zo / d.z);
        push(-o.z / d.z);
    }
    let ss = &mut buf[..len];
    ss.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let mut span: Option<(T, T)> = None;
    for k in 0..ss.len() - 1 {
        let (s0, s1) = (ss[k], ss[k + 1]);
        let m = T::from_f64(0.5) * (s0 + s1);
        let um = (o + d * m).z;
        if s1 > s0 && g(m) <= zero && um > -one && um <= zero {
            span = Some(match span {
                None => (s0, s1),
                Some((first, _)) => (first, s1),
            });
        }
    }
    let (s0, s1) = span?;
    // A point of the chord lies in the unit disk: it is inside the cone. Where the edge passes
    // next to the cone's apex `p` its projection divides by a height at the rounding of the
    // coordinates (found by fuzzing: a receiver 10⁻⁶ from the line of an edge that ends next
    // to it gave a chord point 1.063 from the center), so a point outside is moved onto the
    // rim along its ray: only rounding is removed, and the sector and triangle stay those of
    // points of the disk. The coverage there is ill-posed anyway: `p` is then on the quad's
    // plane.
    let project = |s: T| {
        let q = o + d * s;
        let zq = one + q.z;
        let r = SVec2::new(q.x / zq, q.y / zq);
        let r2 = r.dot(r);
        if r2 > one {
            r / r2.sqrt()
        } else {
            r
        }
    };
    // The chord keeps the edge's direction.
    let (a, b) = (project(s0), project(s1));
    let (a, b) = if from_e1 { (b, a) } else { (a, b) };
    (a.is_finite() && b.is_finite()).then_some([a, b])
}

/// The analytic coverage of Paper IV §4.2.2 Fig. 6a and §4.2.1 Fig. 5a: with `sector` the
/// fraction of the light (`shape`, centered at the origin) between the rays through `a` and `b`
/// (along the minor arc), the fraction beyond the chord `a b`: `sector` minus the triangle
/// (origin, a, b) over the light's area, clamped to [0, 1]. `a` and `b` lie in the light.
pub fn sector_minus_triangle(a: DVec2, b: DVec2, shape: AreaShape, sector: f64) -> f64 {
    shader_sector_minus_triangle(SVec2::from_f64(a), SVec2::from_f64(b), shape, sector)
}

/// [`sector_minus_triangle`] in the shader precision `T` (module doc, "Shader precision").
pub fn shader_sector_minus_triangle<T: ShaderFloat>(
    a: SVec2<T>,
    b: SVec2<T>,
    shape: AreaShape,
    sector: T,
) -> T {
    let total = T::from_f64(match shape {
        AreaShape::Square => 4.0,
        AreaShape::Disk => PI,
    });
    let triangle = T::from_f64(0.5) * a.perp_dot(b).abs() / total;
    (sector - triangle).clamp(T::zero(), T::one())
}

/// [`sector_minus_triangle`] with the exact sector: f64 `atan2` of the two points and
/// [`AreaShape::sector_fraction`].
pub fn exact_sector_minus_triangle(a: DVec2, b: DVec2, shape: AreaShape) -> f64 {
    shader_exact_sector_minus_triangle(SVec2::from_f64(a), SVec2::from_f64(b), shape)
}

/// [`exact_sector_minus_triangle`] in the shader precision `T` (module doc, "Shader
/// precision"): `atan2` and [`AreaShape::shader_sector_fraction`] rounded to `T`.
pub fn shader_exact_sector_minus_triangle<T: ShaderFloat>(
    a: SVec2<T>,
    b: SVec2<T>,
    shape: AreaShape,
) -> T {
    let sector = shape.shader_sector_fraction(a.y.atan2(a.x), b.y.atan2(b.x));
    shader_sector_minus_triangle(a, b, shape, sector)
}

/// The central projection from a receiver point onto the light plane in the light frame
/// (module doc, "Representation"), with `h_p > 0` (the frame is flipped for points below the
/// light plane), in the shader precision `T`.
struct ProjectionFromPoint<T> {
    /// `(p_s, p_t, h_p)` with `h_p > 0`.
    p: SVec3<T>,
    /// `−1` when the `h` axis was flipped so that `h_p > 0`, else `1`.
    flip: T,
}

impl<T: ShaderFloat> ProjectionFromPoint<T> {
    fn new(light: &RectLight, p: DVec3) -> Option<Self> {
        let lp = light.shader_local::<T>(p);
        if lp.z == T::zero() || !lp.is_finite() {
            return None;
        }
        let flip = lp.z.signum();
        Some(ProjectionFromPoint {
            p: SVec3::new(lp.x, lp.y, lp.z * flip),
            flip,
        })
    }

    /// The slab planes `h ≥ 0` and `h_p·w − h ≥ 0` as functionals on `(s, t, h, w)` with `h`
    /// already in the caller's (unflipped) frame.
    fn slab_planes(&self) -> [SVec4<T>; 2] {
        let zero = T::zero();
        [
            light_plane_side(self.flip),
            SVec4::new(zero, zero, -self.flip, self.p.z),
        ]
    }

    /// Clip `poly`, already clipped to the first slab plane ([`clip_beyond_light_plane_into`]
    /// with this projection's `flip`), to the second, `p`'s level, into `out` (cleared
    /// first): together, the clip to the slab between the light's plane and `p`'s level.
    fn clip_to_receiver_level_into(&self, poly: &[SVec4<T>], out: &mut Polygon<SVec4<T>>) {
        let [_, level] = self.slab_planes();
        out.clear();
        clip_polygon_into(
            poly,
            |x| level.dot(x),
            |x| self.onto_slab_plane(1, x),
            |x| out.push(x),
        );
    }

    /// The point `x`, which a clip to slab plane `k` ([`ProjectionFromPoint::slab_planes`])
    /// created, put on that plane exactly: `h = 0` in the light's plane, `h = h_p·w` (flipped
    /// back) at `p`'s level, so that [`ProjectionFromPoint::apply`] gives it `W = 0` exactly —
    /// a direction. Interpolated, its `h` carries rounding of the size of the coordinates it
    /// came from, and where the light is large (its `s, t` small) that residue outweighs the
    /// direction's `S, T` (found by fuzzing: a rectangle 1.5·10²⁶ across, a vertex at `p`'s
    /// level with `W` = 1.8·10⁻¹⁵ beside `S` = −1.3·10⁻²⁴, which turned a half-light
    /// coverage of −0.5 into 1.5·10⁻⁹ in one edge direction).
    ///
    /// At `p`'s level `w` is first recomputed from `h` as `h/h_p` (flipped back): a point cut
    /// from the ray through an edge end has that end's exact `h` but a `w` interpolated from 1
    /// to 0, as `1 − λ` with an absolute error of ε, which is relative error ε/w; found by
    /// fuzzing: a light 10⁻⁵ across seen from 8.75 away, w = 1.1·10⁻⁶ carrying 10⁻¹⁰ of
    /// relative error, and p's light coordinates 2.6·10⁶ turned that into directions off by
    /// 10⁻⁹ and coverages 1.8·10⁻⁵ apart in the two edge directions.
    fn onto_slab_plane(&self, k: usize, x: SVec4<T>) -> SVec4<T> {
        if k == 0 {
            return onto_light_plane(x);
        }
        let w = x.z * self.flip / self.p.z;
        SVec4::new(x.x, x.y, w * self.p.z * self.flip, w)
    }

    /// `(s, t, h, w) ↦ (S, T, W)`: homogeneous light-plane coordinates of the projection.
    fn apply(&self, x: SVec4<T>) -> SVec3<T> {
        let h = x.z * self.flip;
        SVec3::new(
            x.x * self.p.z - self.p.x * h,
            x.y * self.p.z - self.p.y * h,
            x.w * self.p.z - h,
        )
    }
}

/// The first slab plane of a receiver on side `flip` of the light's plane, `flip·h ≥ 0`, as
/// a functional on `(s, t, h, w)` ([`ProjectionFromPoint::slab_planes`]).
fn light_plane_side<T: ShaderFloat>(flip: T) -> SVec4<T> {
    let zero = T::zero();
    SVec4::new(zero, zero, flip, zero)
}

/// A point a clip to the light's plane created, put on it exactly: `h = 0`
/// ([`ProjectionFromPoint::onto_slab_plane`]).
fn onto_light_plane<T: ShaderFloat>(x: SVec4<T>) -> SVec4<T> {
    SVec4::new(x.x, x.y, T::zero(), x.w)
}

/// Clip `poly` to the side `flip` of the light's plane (the first slab plane of a receiver
/// on that side), handing the result's vertices to `emit`.
fn clip_beyond_light_plane_into<T: ShaderFloat>(
    poly: &[SVec4<T>],
    flip: T,
    emit: impl FnMut(SVec4<T>),
) {
    let plane = light_plane_side(flip);
    clip_polygon_into(poly, |x| plane.dot(x), onto_light_plane, emit);
}

/// The number of light borders ([`light_border`]).
const LIGHT_BORDERS: usize = 4;

/// The light border `k` of the four `W − S ≥ 0`, `W + S ≥ 0`, `W − T ≥ 0`, `W + T ≥ 0` on
/// homogeneous light-plane coordinates `(S, T, W)`: its functional at `x`. A `match` the
/// compiler folds in an unrolled loop, where an array of function pointers was called
/// indirectly (`ssv` on `cube-of-spheres` 512², one thread: 177 → 168 ms).
fn light_border<T: ShaderFloat>(k: usize, x: SVec3<T>) -> T {
    match k {
        0 => x.z - x.x,
        1 => x.z + x.x,
        2 => x.z - x.y,
        _ => x.z + x.y,
    }
}

/// The area of a polygon clipped to the light square over the square's (4 in light
/// coordinates), unsigned, at most 1: the polygon lies in the square, but where its vertices'
/// `W` were tiny beside their rounding (a receiver 10⁻⁹ above the light's plane and 10 to the
/// side of it) dividing by them can put vertices outside it (found by fuzzing: a coverage of
/// −1.64).
fn square_fraction<T: ShaderFloat>(clipped: &[SVec2<T>]) -> T {
    (shader_polygon_area(clipped) / T::from_f64(4.0)).min(T::one())
}

/// Clip a homogeneous polygon `(S, T, W)` to the light square and dehomogenise it into the
/// square ([`in_light_square`], [`BorderPoint`]; vertices with `W = 0` left by the clip are
/// the zero vector and are dropped). Found by fuzzing: a vertex at p's level, a direction with
/// `W` at the rounding of the clip (−10⁻¹³ one way, 8.6·10⁻¹⁴ the other), left a vertex at
/// t = −1.0000083 in one edge direction only, and the coverage's antisymmetry off by 2·10⁻⁶.
/// The result is written into `out` (cleared first).
fn clip_to_light_into<T: ShaderFloat>(
    poly: impl IntoIterator<Item = SVec3<T>>,
    out: &mut Polygon<SVec2<T>>,
) {
    out.clear();
    let mut a: Polygon<BorderPoint<T>> = Polygon::new();
    a.extend(poly.into_iter().map(BorderPoint::new));
    let mut b = Polygon::new();
    // Each clip writes the other buffer; swapping the references moves no vertices.
    let (mut src, mut dst) = (&mut a, &mut b);
    for k in 0..LIGHT_BORDERS {
        // Wholly inside the border (the common case): the clip would copy it unchanged.
        if src.iter().all(|x| light_border(k, x.x) >= T::zero()) {
            continue;
        }
        dst.clear();
        clip_polygon_into(
            src,
            |x| light_border(k, x.x),
            |x| x.on_border(k),
            |x| dst.push(x),
        );
        if dst.is_empty() {
            return;
        }
        std::mem::swap(&mut src, &mut dst);
    }
    out.extend(src.iter().copied().filter_map(in_light_square));
}

/// A clipped polygon of the fragment programs, on the stack in a buffer that never
/// overflows: one Sutherland–Hodgman step keeps `k` of a polygon's `n` vertices and adds one
/// per edge that changes side, at most `min(2k, 2(n − k), n)` of them, so it returns at most
/// `⌊3n/2⌋` vertices whatever the rounding (alternating sides is the worst). The quad's 4
/// vertices through the two slab planes and the four light borders: 4 → 6 → 9 → 13 → 19 → 28
/// → 42. A fixed buffer, where a growable one checked at every access whether it had moved to
/// the heap (`ssv` on `cube-of-spheres` 512², one thread: 156 → 144 ms).
type Polygon<V> = ArrayVec<V, POLYGON_CAPACITY>;

/// The most vertices a fragment program's clipped polygon can have ([`Polygon`]).
const POLYGON_CAPACITY: usize = 42;

/// The most vertices of a [`Polygon`] clipped once more, by the receiver's plane
/// ([`EdgeCoverageProgram::at_in_front`]): `⌊3n/2⌋` of [`POLYGON_CAPACITY`].
const IN_FRONT_CAPACITY: usize = POLYGON_CAPACITY * 3 / 2;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::polygon_clip::{clip_polygon, clip_polygon_to_box};

    /// [`Polygon`]'s capacity is the bound of its doc: a clip step that alternates sides at
    /// every vertex returns `⌊3n/2⌋` vertices, no clip of random polygons returns more, and six
    /// steps from the quad's 4 vertices reach [`POLYGON_CAPACITY`].
    #[test]
    fn a_clip_step_returns_at_most_three_halves_of_its_vertices() {
        let step = |n: usize| 3 * n / 2;
        assert_eq!((0..6).fold(4, |n, _| step(n)), POLYGON_CAPACITY);
        // Coordinates in −3…4 from the top bits of a multiplicative hash of a counter.
        let mut k = 0u64;
        let mut next = || {
            k += 1;
            k.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 61
        };
        for n in 1..=30 {
            let alternating: Vec<DVec2> = (0..n)
                .map(|i| DVec2::new(i as f64, if i % 2 == 0 { 1.0 } else { -1.0 }))
                .collect();
            let kept = clip_polygon(&alternating, |p: DVec2| p.y).len();
            assert_eq!(kept, step(n), "n = {n}");
            for _ in 0..200 {
                let poly: Vec<DVec2> = (0..n)
                    .map(|_| DVec2::new(next() as f64 - 3.0, next() as f64 - 3.0))
                    .collect();
                assert!(clip_polygon(&poly, |p: DVec2| p.y).len() <= step(n));
            }
        }
    }

    /// The light's affine frame by hand for a skewed rectangle `u = (2, 0, 0)`, `v = (1, 3, 0)`
    /// at `c = (1, 2, 3)`: `n = (0, 0, 1)`, the dual vectors `v × n / (u·(v × n)) =
    /// (3, −1, 0)/6` and `n × u / (v·(n × u)) = (0, 2, 0)/6`, the area `4·|u × v| = 24`, the
    /// corners in their documented order, and `local` the inverse of `world`.
    #[test]
    fn the_light_frame_of_a_skewed_rectangle_by_hand() {
        let c = DVec3::new(1.0, 2.0, 3.0);
        let (u, v) = (DVec3::new(2.0, 0.0, 0.0), DVec3::new(1.0, 3.0, 0.0));
        let l = RectLight::new(c, u, v);
        assert_eq!(l.normal, DVec3::Z);
        assert_eq!(l.area(), 24.0);
        let scale = l.local_scale();
        assert!(
            (scale - DVec2::new(10f64.sqrt() / 6.0, 1.0 / 3.0)).length() < 1e-15,
            "{scale}"
        );
        assert_eq!(
            l.corners(),
            [
                DVec3::new(-2.0, -1.0, 3.0),
                DVec3::new(2.0, -1.0, 3.0),
                DVec3::new(4.0, 5.0, 3.0),
                DVec3::new(0.0, 5.0, 3.0),
            ]
        );
        let local = DVec3::new(0.25, -0.5, 2.0);
        // c + 0.25·u − 0.5·v + 2·n.
        let world = DVec3::new(1.0, 0.5, 5.0);
        assert_eq!(l.world(local), world);
        assert!(
            (l.local(world) - local).length() < 1e-15,
            "{}",
            l.local(world)
        );
        let rect = Light {
            center: c.as_vec3(),
            shape: LightShape::Rect {
                u: u.as_vec3(),
                v: v.as_vec3(),
            },
        };
        assert_eq!(RectLight::from_light(&rect), Some(l));
        let sphere = Light {
            center: c.as_vec3(),
            shape: LightShape::Sphere { radius: 1.0 },
        };
        assert_eq!(RectLight::from_light(&sphere), None);
    }

    /// [`in_light_square`] by hand: `(S/W, T/W)` inside the square, clamped outside it, a
    /// coordinate on a marked border exactly that border's ±1 whatever the division gives,
    /// `None` on two opposite borders and for `W` = 0 (a direction, even marked on one border
    /// only), −0 and < 0; a NaN `W` gives NaN coordinates, not `None` or a value in the square.
    #[test]
    fn in_light_square_divides_clamps_snaps_and_drops_directions() {
        let at = |s: f64, t: f64, w: f64, on: u8| {
            in_light_square(BorderPoint {
                x: SVec3::new(s, t, w),
                on,
            })
            .map(SVec2::to_f64)
        };
        let d = |s, t| Some(DVec2::new(s, t));
        assert_eq!(at(1.0, -3.0, 4.0, 0), d(0.25, -0.75));
        assert_eq!(at(5.0, -6.0, 4.0, 0), d(1.0, -1.0));
        assert_eq!(at(-5.0, 6.0, 4.0, 0), d(-1.0, 1.0));
        // Marked borders: 0 is s = 1, 1 is s = −1, 2 is t = 1, 3 is t = −1.
        assert_eq!(at(3.9, 1.0, 4.0, 0b0001), d(1.0, 0.25));
        assert_eq!(at(-3.9, 1.0, 4.0, 0b0010), d(-1.0, 0.25));
        assert_eq!(at(1.0, 3.9, 4.0, 0b0100), d(0.25, 1.0));
        assert_eq!(at(1.0, -3.9, 4.0, 0b1000), d(0.25, -1.0));
        assert_eq!(at(3.9, -3.9, 4.0, 0b1001), d(1.0, -1.0));
        assert_eq!(at(0.0, 1.0, 4.0, 0b0011), None);
        assert_eq!(at(1.0, 0.0, 4.0, 0b1100), None);
        for (s, t, w) in [(1.0, 0.0, 0.0), (0.0, 0.0, -0.0), (-1.0, 0.0, -2.0)] {
            assert_eq!(at(s, t, w, 0b0001), None, "({s}, {t}, {w})");
            assert_eq!(at(s, t, w, 0), None, "({s}, {t}, {w})");
        }
        let nan = at(1.0, 1.0, f64::NAN, 0).expect("a NaN W is not dropped");
        assert!(nan.x.is_nan() && nan.y.is_nan(), "{nan}");
    }

    /// [`quad_side`] is the sign of `det(e0 − c, e1 − c, p − c)`, computed here in integers:
    /// on 4000 random points of the lattice {−2, …, 2}³, where the determinant is exact in
    /// f64 and often 0 (both signs and 0 required to occur).
    #[test]
    fn quad_side_is_the_sign_of_the_determinant() {
        let mut k = 0u64;
        let mut point = || {
            let mut coord = || {
                k += 1;
                (crate::light::sampling::splitmix64(k) % 5) as i64 - 2
            };
            [coord(), coord(), coord()]
        };
        let det = |a: [i64; 3], b: [i64; 3], d: [i64; 3]| {
            a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0])
                + a[2] * (b[0] * d[1] - b[1] * d[0])
        };
        let f = |x: [i64; 3]| DVec3::new(x[0] as f64, x[1] as f64, x[2] as f64);
        let mut seen = [0; 3];
        for _ in 0..4000 {
            let (c, e0, e1, p) = (point(), point(), point(), point());
            let minus = |a: [i64; 3]| [a[0] - c[0], a[1] - c[1], a[2] - c[2]];
            let want = det(minus(e0), minus(e1), minus(p)).signum();
            seen[(want + 1) as usize] += 1;
            assert_eq!(
                quad_side(f(c), f(p), f(e0), f(e1)),
                want as f64,
                "c {c:?} p {p:?} e0 {e0:?} e1 {e1:?}"
            );
        }
        assert!(seen.iter().all(|&n| n > 100), "{seen:?}");
    }

    /// [`projected_edge_near_clipped`] by hand under the unit light from `p = (0.3, −0.2, 4)`:
    /// an edge from `h = −1` to `h = 3.8` is cut at the light's plane (`h = 0`) and at the near
    /// plane `(1 − 0.1)·4 = 3.6`, and each cut point `x` projects from `p` to
    /// `(x·h_p − p·h)/(h_p − h)` in `(s, t)`, in the edge's direction. The same edge mirrored
    /// below the light (`p` and the edge at −h) projects to the same points. Nothing is left of
    /// an edge wholly beyond the light's plane, or of one wholly within the near fraction of
    /// `p`'s level, and a receiver in the light's plane projects nothing.
    #[test]
    fn near_clipped_edge_is_cut_at_both_planes_and_projected_by_hand() {
        let l = unit_light();
        let p = DVec3::new(0.3, -0.2, 4.0);
        let (e0, e1) = (DVec3::new(-0.5, 0.4, -1.0), DVec3::new(1.9, -0.8, 3.8));
        let at_h = |h: f64| e0 + (e1 - e0) * ((h - e0.z) / (e1.z - e0.z));
        let project = |x: DVec3| ((x * p.z - p * x.z) / (p.z - x.z)).truncate();
        let (a, b) = (project(at_h(0.0)), project(at_h(3.6)));
        let mirror = |x: DVec3| DVec3::new(x.x, x.y, -x.z);
        for (p, e0, e1) in [(p, e0, e1), (mirror(p), mirror(e0), mirror(e1))] {
            let [qa, qb] = projected_edge_near_clipped(&l, p, e0, e1, 0.1).unwrap();
            assert!(
                (qa - a).length() < 1e-12 && (qb - b).length() < 1e-12,
                "{qa} {qb}"
            );
            let [qb, qa] = projected_edge_near_clipped(&l, p, e1, e0, 0.1).unwrap();
            assert!(
                (qa - a).length() < 1e-12 && (qb - b).length() < 1e-12,
                "{qa} {qb}"
            );
        }
        let beyond = (DVec3::new(0.0, 0.0, -1.0), DVec3::new(1.0, 0.0, -0.5));
        assert_eq!(
            projected_edge_near_clipped(&l, p, beyond.0, beyond.1, 0.1),
            None
        );
        let near = (DVec3::new(0.0, 0.0, 3.7), DVec3::new(1.0, 0.0, 3.9));
        assert_eq!(
            projected_edge_near_clipped(&l, p, near.0, near.1, 0.1),
            None
        );
        assert!(projected_edge_near_clipped(&l, p, near.0, near.1, 0.0).is_some());
        let level = DVec3::new(0.3, -0.2, 0.0);
        assert_eq!(projected_edge_near_clipped(&l, level, e0, e1, 0.1), None);
        // An end whose projection overflows (S = 4·10³⁰⁸ = ∞), either way round.
        let huge = (DVec3::new(1e308, 0.0, 1.0), DVec3::new(0.0, 0.0, 2.0));
        assert_eq!(
            projected_edge_near_clipped(&l, p, huge.0, huge.1, 0.1),
            None
        );
        assert_eq!(
            projected_edge_near_clipped(&l, p, huge.1, huge.0, 0.1),
            None
        );
    }

    /// [`projected_edge_near_clipped`] without a near plane, of edges that cross `p`'s level:
    /// a point of the edge just below that level projects from `p` far out along the
    /// direction from `p` to the point (`p + (x − p)·h_p/(h_p − h)`), so the projected end at
    /// the level lies on that side of `p`'s own projection, never on the other — where a point
    /// just *above* the level projects, which the clip's rounding leaves with `W < 0` (a
    /// projection through the receiver's level, dropped). 3000 random edges; the end is
    /// checked wherever the projection is `Some` (at least 100 times).
    #[test]
    fn edge_through_the_receivers_level_projects_out_on_its_own_side() {
        let l = unit_light();
        let mut unit = uniform_sequence();
        let mut checked = 0;
        for _ in 0..3000 {
            let p = DVec3::new(2.0 * unit() - 1.0, 2.0 * unit() - 1.0, 1.0 + 4.0 * unit());
            let (h0, h1) = (p.z * (0.1 + 0.8 * unit()), p.z * (1.1 + unit()));
            let mut around = |h: f64| DVec3::new(4.0 * unit() - 2.0, 4.0 * unit() - 2.0, h);
            let (e0, e1) = (around(h0), around(h1));
            let at_level = e0 + (e1 - e0) * ((p.z - e0.z) / (e1.z - e0.z));
            let out = (at_level - p).truncate();
            if out.length() < 1e-3 {
                continue;
            }
            if let Some([_, end]) = projected_edge_near_clipped(&l, p, e0, e1, 0.0) {
                checked += 1;
                assert!(
                    (end - p.truncate()).dot(out) > 0.0,
                    "p {p} e0 {e0} e1 {e1}: end {end}"
                );
            }
        }
        assert!(checked >= 100, "{checked}");
    }

    /// A fixed sequence of uniform numbers in [0, 1): splitmix64 of 1, 2, 3, … to 53 bits.
    fn uniform_sequence() -> impl FnMut() -> f64 {
        let mut k = 0u64;
        move || {
            k += 1;
            (crate::light::sampling::splitmix64(k) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn unit_light() -> RectLight {
        RectLight::new(DVec3::ZERO, DVec3::X, DVec3::Y)
    }

    /// `horizon = integrate`'s identity (`docs/horizon.md`): for a flat square occluder
    /// between a receiver and the light, pass 1's `1 − count` weighted by the fraction `f` of
    /// the light in front of the receiver's plane, plus the coverages of its four edges over
    /// the clipped light ([`EdgeCoverageProgram::at_in_front`]), is the visible part of the
    /// clipped light over the whole light's area — `f` less the occluder's projection clipped
    /// to the square and the half-plane, computed here independently (the projected polygon
    /// clipped with [`clip_polygon`]) — with the light's center in the shadow (count 1) and
    /// out of it (count 0). Without the plane ([`EdgeCoverageProgram::at`]) the same sum is
    /// Paper III's `1 − count + Σ`.
    #[test]
    fn horizon_clipped_edge_coverages_sum_to_the_visible_part_of_the_clipped_light() {
        let l = unit_light();
        let scene_light = Light {
            center: glam::Vec3::ZERO,
            shape: LightShape::Rect {
                u: glam::Vec3::X,
                v: glam::Vec3::Y,
            },
        };
        let p = DVec3::new(0.3, -0.2, 3.0);
        // The plane d = (s − 0.3) + 0.5·(t + 0.2) − 0.1·3 = s + t/2 − 1/2 over the light.
        let n = DVec3::new(1.0, 0.5, 0.1);
        let plane = SquarePlane::<f64>::of(&scene_light, p, n).unwrap();
        assert_eq!(plane.corners_in_front(), 2);
        let f = plane.fraction();
        for (shift, count) in [(0.0, 1.0), (0.5, 0.0)] {
            // A square of half-size 0.4 at height 1.5, counterclockwise seen from p; its
            // projection from p onto the light's plane is the square scaled by 2 about p.
            let corners: Vec<DVec3> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .iter()
                .map(|&(a, b)| DVec3::new(0.1 + shift + 0.4 * a, 0.1 + 0.4 * b, 1.5))
                .collect();
            let projected: Vec<DVec2> = corners
                .iter()
                .map(|o| (p + (*o - p) * 2.0).truncate())
                .collect();
            let in_light = clip_polygon_to_box(&projected, DVec2::splat(-1.0), DVec2::splat(1.0));
            let in_front = clip_polygon(&in_light, |q: DVec2| plane.at(SVec2::new(q.x, q.y)));
            let edges = || (0..4).map(|j| (corners[j], corners[(j + 1) % 4]));
            let whole: f64 = edges()
                .map(|(a, b)| EdgeCoverageProgram::<f64>::new(&l, a, b).at(p))
                .sum();
            let clipped: f64 = edges()
                .map(|(a, b)| EdgeCoverageProgram::<f64>::new(&l, a, b).at_in_front(p, &plane))
                .sum();
            let v = 1.0 - count + whole;
            let expected = 1.0 - polygon_area(&in_light) / 4.0;
            assert!((v - expected).abs() < 1e-12, "{shift}: {v} vs {expected}");
            let v = f * (1.0 - count) + clipped;
            let expected = f - polygon_area(&in_front) / 4.0;
            assert!((v - expected).abs() < 1e-12, "{shift}: {v} vs {expected}");
            // The plane does take something off: the occluder's shadow reaches behind it.
            assert!(
                polygon_area(&in_front) < polygon_area(&in_light) - 0.1,
                "{shift}"
            );
        }
        assert!(f > 0.2 && f < 0.8, "{f}");
    }

    #[test]
    fn edge_projecting_to_a_strip_covers_the_strip() {
        // An edge at height 1 along x = 0.25, seen from (0, 0, 2): it projects onto x = 0.5,
        // and the region beyond it covers the strip x ∈ [0.5, 1] of the light: 1/4.
        let l = unit_light();
        let p = DVec3::new(0.0, 0.0, 2.0);
        let e0 = DVec3::new(0.25, -10.0, 1.0);
        let e1 = DVec3::new(0.25, 10.0, 1.0);
        let c = edge_coverage_exact(&l, p, e0, e1);
        assert!((c.abs() - 0.25).abs() < 1e-12, "{c}");
        assert_eq!(edge_coverage_exact(&l, p, e1, e0), -c);
    }

    /// The fuzz finding [`BorderPoint`] fixes: a skewed rectangle 2·10⁻⁶ of its length wide
    /// (`s` spans ±3.1·10⁶ world units, `t` ±8.5), and an edge crossing `p`'s level whose
    /// projection runs through the whole square along `t`, 10⁻⁶ from its middle: the quad covers
    /// the side `s` below that line, `½ + (s(−1) + s(1))/4` of the light, where `s(t)` is the
    /// line through the projections of two points of the edge between the light and `p`. Before
    /// the fix the corners (−1, ±1) came out at t = ±0.99999 one way round and the two
    /// directions differed by 2.3·10⁻⁶.
    #[test]
    fn thin_skewed_light_halved_by_an_edge_keeps_its_corners() {
        let l = RectLight::new(
            DVec3::new(0.25, 3.0, 0.75),
            DVec3::new(0.0, 3145728.0, 0.0),
            DVec3::new(6.25, -5.75, 0.0),
        );
        let p = DVec3::new(-15.196115436540616, -6.661371913947409, -6.660914982462424);
        let e0 = DVec3::new(-17.068359375, -8.5341796875, -8.5341796875);
        let e1 = DVec3::new(-8.5341796875, -0.0009765625, 1.2489267343781473e-38);
        let lp = l.local(p);
        let project = |x: DVec3| {
            let lx = l.local(x);
            assert!(lx.z > 0.0 && lx.z < lp.z, "{x} not between the light and p");
            (lp + (lx - lp) * (lp.z / (lp.z - lx.z))).truncate()
        };
        let (a, b) = (project(e1), project(e1.lerp(e0, 0.5)));
        let s_at = |t: f64| a.x + (b.x - a.x) * (t - a.y) / (b.y - a.y);
        let expected = 0.5 + (s_at(-1.0) + s_at(1.0)) / 4.0;
        let c = edge_coverage_exact(&l, p, e0, e1);
        let reversed = edge_coverage_exact(&l, p, e1, e0);
        assert!((c.abs() - expected).abs() < 1e-12, "{c} vs {expected}");
        assert!((c + reversed).abs() < 1e-12, "{c} vs {reversed}");
    }

    /// The fuzz finding [`ProjectionFromPoint::onto_slab_plane`] fixes: a rectangle
    /// 1.5·10²⁶ across, so that light coordinates `s` are of size 10⁻²⁵, and an edge whose
    /// projection halves it; the quad's vertex where the ray through `e1` leaves the slab at
    /// `p`'s level is a direction (`W = 0`), but interpolated it had `W` = 1.8·10⁻¹⁵, which
    /// outweighed its `S` = −1.3·10⁻²⁴ and made the coverage 1.5·10⁻⁹ instead of ½ in one edge
    /// direction.
    #[test]
    fn huge_light_vertex_at_the_receivers_level_stays_a_direction() {
        let l = RectLight::new(
            DVec3::new(26.75, 0.015625, 0.0),
            DVec3::new(-1.0, 26.75, 1.5474113062823904e26),
            DVec3::new(16.1279296875, 6.067004998634556e24, 26.25),
        );
        let p = DVec3::new(0.0, 0.0, 4.75);
        let e0 = DVec3::new(12.25, -4.3900599175968137e24, -26.0);
        let e1 = DVec3::new(12.5, 4.3900599175968137e24, 0.5);
        let c = edge_coverage_exact(&l, p, e0, e1);
        let reversed = edge_coverage_exact(&l, p, e1, e0);
        assert!((c.abs() - 0.5).abs() < 1e-12, "{c}");
        assert!((c + reversed).abs() < 1e-12, "{c} vs {reversed}");
    }

    /// The fuzz finding the `w = h/h_p` of [`ProjectionFromPoint::onto_slab_plane`] fixes: a
    /// skewed light 10⁻⁵ across seen from 8.75 away (p's light coordinates 2.6·10⁶) and an
    /// edge 6.5·10⁻⁹ long next to the light; the rays from the center through its ends reach
    /// p's level at w ≈ 1.1·10⁻⁶, near p. With w interpolated the two edge directions gave
    /// −0.145796 and 0.145778.
    #[test]
    fn tiny_light_rays_reaching_the_receivers_level_keep_their_w() {
        let x = 1.0052695870399475e-5;
        let l = RectLight::new(
            DVec3::new(1.511366173271439e-13, x, x),
            DVec3::new(x, 8.37724655866623e-6, x),
            DVec3::splat(x),
        );
        let p = DVec3::new(8.75, 8.843688195366776e-18, 8.843688195366776e-18);
        let e0 = DVec3::splat(x);
        let e1 = DVec3::new(x, x, 1.0046176612377167e-5);
        let c = edge_coverage_exact(&l, p, e0, e1);
        let reversed = edge_coverage_exact(&l, p, e1, e0);
        assert!((c + reversed).abs() < 1e-12, "{c} vs {reversed}");
    }

    #[test]
    fn sphere_edge_covers_the_circular_segment_and_nothing_behind_the_disk() {
        // A sphere of radius 0.5 at the origin seen from p = (0, 0, 3): the facing disk lies in
        // z = 0. A long edge along x at y = 0.125, z = 1.5 projects (scale 2) onto the chord
        // y = 0.25 = r/2: the segment beyond it is (acos ½ − ½·√¾)/π of the disk. The same
        // edge at z = −1 (beyond the disk's plane, inside the cone from p widened past it)
        // hides nothing.
        let p = DVec3::new(0.0, 0.0, 3.0);
        let edge = |z: f64| (DVec3::new(-5.0, 0.125, z), DVec3::new(5.0, 0.125, z));
        let (e0, e1) = edge(1.5);
        let c = sphere_edge_coverage_exact(DVec3::ZERO, 0.5, p, e0, e1);
        let expected = (libm::acos(0.5f64) - 0.5 * 0.75f64.sqrt()) / PI;
        assert!((c.abs() - expected).abs() < 1e-12, "{c} vs {expected}");
        let reversed = sphere_edge_coverage_exact(DVec3::ZERO, 0.5, p, e1, e0);
        assert!((reversed + c).abs() < 1e-15, "{reversed} vs {c}");
        let (e0, e1) = edge(-1.0);
        assert_eq!(sphere_edge_coverage_exact(DVec3::ZERO, 0.5, p, e0, e1), 0.0);
        assert_eq!(clip_to_light_cone(DVec3::ZERO, 0.5, p, e0, e1), None);
    }

    /// A sphere of radius 1 at the origin seen from p = (0, 0, −10): an edge along x at
    /// y = 0.3, z = −5 (half-way) projects onto the chord at 0.6 radii from the center, and the
    /// region beyond it is (acos 0.6 − 0.6·0.8)/π of the disk whatever the edge's length, since
    /// its part outside the cone hides nothing. Found by fuzzing: a clip started from an end
    /// far from the cone lost the chord to rounding (a fuzzed edge reaching 10⁶ radii away got
    /// coverage 0 one way and 0.261 the other; here one end 10⁶ away was off by 10⁻⁸ and both
    /// ends 10⁸ away gave 0).
    #[test]
    fn sphere_coverage_does_not_depend_on_how_far_the_edge_reaches() {
        let p = DVec3::new(0.0, 0.0, -10.0);
        let expected = (libm::acos(0.6f64) - 0.6 * 0.8) / PI;
        let at = |x: f64| DVec3::new(x, 0.3, -5.0);
        for (x0, x1) in [
            (-10.0, 10.0),
            (-10.0, 1e6),
            (-10.0, 1e12),
            (-1e8, 1e8),
            (-1e12, 1e15),
        ] {
            for (e0, e1) in [(at(x0), at(x1)), (at(x1), at(x0))] {
                let c = sphere_edge_coverage_exact(DVec3::ZERO, 1.0, p, e0, e1);
                assert!(
                    (c.abs() - expected).abs() < 1e-12,
                    "edge {e0} {e1}: {c} vs {expected}"
                );
            }
        }
    }

    /// A projected edge whose line runs through the light's center to rounding, one end
    /// 2·10⁻¹⁴ from it (found by fuzzing: a receiver on the edge, so in the quad's plane): the
    /// ray through that end has a direction as short, and clipping the region beyond the
    /// segment gave 1.7·10¹³ of the light.
    ///
    /// The region, derived by hand: with `a = (−η, −1)`, `b = (−η, ε)` (`η ≈ 1.4·10⁻¹⁷`,
    /// `ε ≈ 2.2·10⁻¹⁴`) the quad `a, b, b∞, a∞` is `{αa + βb : α, β ≥ 0, α + β ≥ 1}`: the
    /// points left of `x = −η` inside the cone between the ray along `a` (straight down, to
    /// `η`) and the ray along `b` (up, leaning left by `η/ε ≈ 6.6·10⁻⁴`). In the square that is
    /// the left half (area 2) less the sliver between the ray along `b` and the `+y` axis
    /// (`½·η/ε`) and strips of width `≤ η`: a fraction `(2 − ½ η/ε)/4 ± η` (exact rational
    /// arithmetic on the same vertices gives 0.49991807479119554). Rounding: the clip of the
    /// edge from `b` (W = 1) to `b∞` (W = 0) at the border T = W solves `1 − λ = ε`, a
    /// difference of two numbers near 1, so the sliver's width is off by a relative `u/ε`
    /// (`u = 2⁻⁵³`: 5·10⁻³) per rounding; two allowed. Measured 2.0·10⁻⁷ (0.25% of the
    /// sliver). Checked on the region's own area — before [`square_fraction`]'s clamp — so a
    /// value above the light, a wrong one below it, or NaN fails.
    #[test]
    fn segment_through_the_center_covers_its_half_square_less_a_sliver() {
        let a = DVec2::new(-1.4153545364093077e-17, -1.0);
        let b = DVec2::new(-1.415354536409308e-17, 2.1595223208207936e-14);
        let (eta, eps) = (-b.x, b.y);
        let sliver = 0.5 * eta / eps / 4.0;
        let expected = 0.5 - sliver;
        let tolerance = 2.0 * (0.5 * f64::EPSILON / eps) * sliver + 1e-15;
        for (a, b) in [(a, b), (b, a)] {
            let unclamped = polygon_area(&segment_region(a, b)) / 4.0;
            assert!(
                (unclamped - expected).abs() <= tolerance,
                "{a} {b}: region {unclamped} vs {expected} (tolerance {tolerance})"
            );
            assert_eq!(segment_coverage(a, b), unclamped, "{a} {b}");
        }
    }

    /// A receiver 6·10⁻⁹ from an edge that lies at its own level to 3·10⁻⁸ (found by fuzzing,
    /// `fuzz/regressions/coverage/rect-receiver-6e-9-from-edge-at-its-level-projected-at-infinity.bin`):
    /// the projected edge is at infinity, its clipped ends had W ≈ 2·10⁻¹⁶ and divided to
    /// s = −1.118. Every projected point lies in the light square.
    #[test]
    fn edge_at_the_receivers_level_projects_into_the_square() {
        let l = RectLight::new(
            DVec3::new(0.0, 3.0, 0.0),
            DVec3::new(0.5, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 0.5),
        );
        let p = DVec3::new(
            -0.8117647057946991,
            -5.807754967142554e-9,
            0.040808823529411765,
        );
        let e0 = DVec3::new(-1.0, 5.868143310234427e-39, 0.0);
        let e1 = DVec3::new(4.656612873077393e-10, -3.085369826294482e-8, 0.216796875);
        for (a, b) in [(e0, e1), (e1, e0)] {
            let [q0, q1] = projected_edge_in_light(&l, p, a, b).expect("the edge projects");
            for q in [q0, q1] {
                assert!(q.abs().max_element() <= 1.0, "{q}");
            }
        }
    }

    /// The chord [`clip_to_light_cone`] should give, computed independently: the set of edge
    /// parameters `t` whose point lies in the slab between `p` and the disk's plane and
    /// projects from `p` into the disk is an interval (a line meets the convex cone and the slab
    /// in one), found by sampling `t` for a point inside and bisecting each way on that
    /// predicate, with the projection done by dividing directly. Returns the projections of
    /// the interval's ends in the edge's direction and a tolerance: `10⁻⁹` plus the
    /// projection's slope times the bisection's `10⁻¹⁵`; `None` when no sample is inside.
    fn chord_by_bisection(
        c: DVec3,
        radius: f64,
        p: DVec3,
        e0: DVec3,
        e1: DVec3,
    ) -> Option<([DVec2; 2], f64)> {
        let dist = (c - p).length();
        let z = (c - p) / dist;
        let x = z.any_orthonormal_vector();
        let y = z.cross(x);
        let at = |t: f64| {
            let w = e0 + (e1 - e0) * t - p;
            let depth = w.dot(z) / dist;
            (depth > 0.0 && depth <= 1.0).then(|| DVec2::new(w.dot(x), w.dot(y)) / (radius * depth))
        };
        let inside = |t: f64| at(t).is_some_and(|q| q.length_squared() <= 1.0);
        let seed = (0..=4096).map(|i| i as f64 / 4096.0).find(|&t| inside(t))?;
        let bisect = |mut good: f64, mut bad: f64| {
            if inside(bad) {
                return bad;
            }
            while (good - bad).abs() > 1e-15 {
                let mid = 0.5 * (good + bad);
                if inside(mid) {
                    good = mid;
                } else {
                    bad = mid;
                }
            }
            good
        };
        let (t0, t1) = (bisect(seed, 0.0), bisect(seed, 1.0));
        let slope = |t: f64| {
            let h = 1e-7;
            let (lo, hi) = ((t - h).max(t0), (t + h).min(t1));
            if hi > lo {
                Some((at(hi)? - at(lo)?).length() / (hi - lo))
            } else {
                Some(0.0)
            }
        };
        let tol = 1e-9 + 1e-15 * (slope(t0)? + slope(t1)?) * 4.0;
        Some(([at(t0)?, at(t1)?], tol))
    }

    /// [`clip_to_light_cone`] against [`chord_by_bisection`] ([`assert_same_chord`]). An edge the sampling
    /// finds outside everywhere must get no chord or one shorter than its step could see.
    /// Returns whether there was a chord.
    fn check_chord(what: &str, c: DVec3, radius: f64, p: DVec3, e0: DVec3, e1: DVec3) -> bool {
        let chord = clip_to_light_cone(c, radius, p, e0, e1);
        let Some(([pa, pb], tol)) = chord_by_bisection(c, radius, p, e0, e1) else {
            if let Some([a, b]) = chord {
                assert!((a - b).length() < 1e-2, "{what}: chord {a} {b}, none seen");
            }
            return false;
        };
        let got = chord.unwrap_or_else(|| panic!("{what}: no chord, {pa} {pb} expected"));
        assert_same_chord(what, got, [pa, pb], tol);
        true
    }

    /// Chord `[a, b]` is `want` to `tol` in what a basis of the disk's plane does not change:
    /// `|a|`, `|b|`, `a·b`, `a × b`.
    fn assert_same_chord(what: &str, [a, b]: [DVec2; 2], [pa, pb]: [DVec2; 2], tol: f64) {
        for (name, got, want) in [
            ("|a|", a.length(), pa.length()),
            ("|b|", b.length(), pb.length()),
            ("a·b", a.dot(b), pa.dot(pb)),
            ("a×b", a.perp_dot(b), pa.perp_dot(pb)),
        ] {
            assert!(
                (got - want).abs() <= tol,
                "{what}: {name} {got} vs {want} (tolerance {tol}; chord {a} {b})"
            );
        }
    }

    /// The chord of an edge reaching 10⁶ radii from the light is found in binary32 from
    /// either end, because the parameter starts at the end nearer the light (the fuzzing find
    /// of [`shader_clip_to_light_cone`]'s comment): started from the far end, the nearest point
    /// carries an error of ε·10⁶ radii ≈ 0.06. The unit disk at the origin seen from
    /// `p = (0, 0, −2)`; the edge at `z = −1`, half way, so that it projects doubled: `y = 0.3`,
    /// `x` from −0.5 to 10⁶, whose part in the disk runs to `x = √0.91`. Compared through the
    /// invariants of [`assert_same_chord`] (the disk's basis is any), to 10⁻⁵ — 160 ulps of binary32
    /// at 1, none at the far end's scale.
    #[test]
    fn sphere_chord_of_an_edge_a_million_radii_long_from_either_end() {
        use crate::gpu::shader_float::Fp32;
        let (c, p) = (DVec3::ZERO, DVec3::new(0.0, 0.0, -2.0));
        let (near, far) = (DVec3::new(-0.25, 0.15, -1.0), DVec3::new(5e5, 0.15, -1.0));
        let (a, b) = (DVec2::new(-0.5, 0.3), DVec2::new(0.91f64.sqrt(), 0.3));
        for (e0, e1, want) in [(near, far, [a, b]), (far, near, [b, a])] {
            let got = shader_clip_to_light_cone::<Fp32>(c, 1.0, p, e0, e1)
                .expect("a chord")
                .map(SVec2::to_f64);
            assert_same_chord(&format!("from {e0}"), got, want, 1e-5);
        }
    }

    /// The chord of [`clip_to_light_cone`] is the projected edge inside the disk
    /// ([`check_chord`]) on 3000 random edges around random spheres, at least 1000 of which
    /// have one.
    #[test]
    fn sphere_chord_is_the_projected_edge_inside_the_disk() {
        let mut unit = uniform_sequence();
        let mut chords = 0;
        for case in 0..3000 {
            let mut vec3 =
                |scale: f64| DVec3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5) * 2.0 * scale;
            let c = vec3(2.0);
            let p = vec3(6.0);
            let (e0, e1) = (p + (c - p) * vec3(1.0).x.abs() * 1.2, p + (c - p) * 0.7);
            let (e0, e1) = (e0 + vec3(1.5), e1 + vec3(1.5));
            let radius = 0.2 + 1.3 * unit();
            if (c - p).length() <= radius * 1.01 {
                continue;
            }
            chords += usize::from(check_chord(&format!("case {case}"), c, radius, p, e0, e1));
        }
        assert!(chords >= 1000, "{chords} edges with a chord");
    }

    /// The branches of [`clip_to_light_cone`] random edges do not reach, from `p` at the
    /// origin under the sphere of radius 1 at `(0, 0, 2)` (every light-space coordinate below is
    /// exact): an edge in the disk's plane (its chord is the edge inside the disk, since the
    /// slab includes that plane: `|a| = |b| = 1`, `|a × b| = 2·½·√¾`), an edge along the
    /// direction of a generator of the cone (the quadratic's leading coefficient is exactly 0:
    /// one root), an edge at `p`'s level (not in the slab), and receivers inside the sphere and
    /// on it (no chord).
    #[test]
    fn sphere_chord_in_the_disks_plane_along_a_generator_and_from_inside() {
        let (c, r, p) = (DVec3::new(0.0, 0.0, 2.0), 1.0, DVec3::ZERO);
        let in_plane = (DVec3::new(-3.0, 0.5, 2.0), DVec3::new(3.0, 0.5, 2.0));
        assert!(check_chord(
            "in the disk's plane",
            c,
            r,
            p,
            in_plane.0,
            in_plane.1
        ));
        let [a, b] = clip_to_light_cone(c, r, p, in_plane.0, in_plane.1).unwrap();
        assert!((a.length() - 1.0).abs() < 1e-15 && (b.length() - 1.0).abs() < 1e-15);
        assert!(
            (a.perp_dot(b).abs() - 0.75f64.sqrt()).abs() < 1e-15,
            "{a} {b}"
        );
        // In light space d = (Δ·x, Δ·y, Δ·z/2) for Δ = (3, 4, 10)/8: d_x² + d_y² = d_z².
        let e0 = DVec3::new(0.25, 0.0, 1.0);
        let generator = (e0, e0 + DVec3::new(0.375, 0.5, 1.25));
        assert!(check_chord(
            "along a generator",
            c,
            r,
            p,
            generator.0,
            generator.1
        ));
        let back = (generator.1, generator.0);
        assert!(check_chord(
            "along a generator, reversed",
            c,
            r,
            p,
            back.0,
            back.1
        ));
        let level = (DVec3::new(-3.0, 0.5, 0.0), DVec3::new(3.0, 0.5, 0.0));
        assert_eq!(clip_to_light_cone(c, r, p, level.0, level.1), None);
        for inside in [DVec3::new(0.5, 0.0, 1.5), DVec3::new(0.0, 0.0, 1.0)] {
            assert_eq!(
                clip_to_light_cone(c, r, inside, in_plane.0, in_plane.1),
                None
            );
        }
    }

    /// A receiver 10⁻⁶ from the line of an edge that ends 0.0014 from it, under a sphere of
    /// radius 13.3 (found by fuzzing,
    /// `fuzz/regressions/coverage/sphere-receiver-1e-6-from-edge-line-end-next-to-it-chord-1.063.bin`):
    /// a chord end next to the cone's apex came out 1.063 from the disk's center. Every chord
    /// point lies in the unit disk.
    #[test]
    fn chord_next_to_the_apex_stays_in_the_disk() {
        let c = DVec3::new(11.0, 0.0, 13.3017578125);
        let p = DVec3::new(0.0, 0.0, 0.0009765625);
        let e0 = DVec3::new(13.3017578125, 6.3427723944187164e-6, 13.3017578125);
        let e1 = DVec3::new(-0.0009765625, 0.0, 6.750632906005194e-7);
        for (a, b) in [(e0, e1), (e1, e0)] {
            let [q0, q1] = clip_to_light_cone(c, 13.3017578125, p, a, b).expect("a chord");
            for q in [q0, q1] {
                assert!(q.length() <= 1.0, "{q}");
            }
        }
    }

    /// A rectangle light 1.5·10¹⁰ across seen from 1558 beyond its plane, an edge whose
    /// projection runs nearly through its center (found by fuzzing,
    /// `fuzz/regressions/coverage/rect-1.5e10-light-edge-projects-through-center-antisymmetry-2e-6.bin`):
    /// the clipped region kept a vertex 8.3·10⁻⁶ outside the square in one edge direction only
    /// (coverage −0.49999905 one way, 0.50000112 the other). Reversing the edge negates the
    /// coverage to within 10⁻⁹ (the region's vertices are exact to about that).
    #[test]
    fn huge_light_coverage_is_antisymmetric() {
        let l = RectLight::new(
            DVec3::new(0.0, 0.76171875, -7.25),
            DVec3::new(2.7939677238464355e-9, 14614528000.0, 0.75),
            DVec3::new(1419771904.0, 0.75, 14614528000.0),
        );
        let p = DVec3::new(26.75, 0.0, 16384.0);
        let e0 = DVec3::new(0.75, -14417920000.0, 26.75);
        let e1 = DVec3::new(0.0, 16384.0, 0.0);
        let (c, r) = (
            edge_coverage_exact(&l, p, e0, e1),
            edge_coverage_exact(&l, p, e1, e0),
        );
        assert!((c + r).abs() < 1e-9, "{c} {r}");
    }

    #[test]
    fn projected_edge_matches_segment_coverage() {
        let l = unit_light();
        let p = DVec3::new(0.3, -0.2, 3.0);
        let e0 = DVec3::new(0.5, -0.4, 1.0);
        let e1 = DVec3::new(-0.2, 0.6, 1.2);
        let [a, b] = projected_edge_in_light(&l, p, e0, e1).unwrap();
        let exact = edge_coverage_exact(&l, p, e0, e1);
        assert!((segment_coverage(a, b) - exact.abs()).abs() < 1e-12);
    }

    /// An edge through the light center from nearly opposite endpoints: the region beyond it
    /// is the half-square beyond its line — or empty when [`segment_region`]'s rounding rule
    /// takes the line through the center — whatever the rounding of `a × b`. Before that rule,
    /// `a × b ≈ 10⁻¹⁷` gave a self-intersecting region of area 5.5.
    ///
    /// Bound, derived: with `|a| = 0.7` and `b = −a + off·a⊥` the line passes `d ≤ 0.35·off`
    /// from the center, so the region differs from a half-square by a strip of width `d` and
    /// length ≤ 2√2 and by the cone's missing angle (`≤ off`) over a radius ≤ √2: at most
    /// `(2√2·0.35 + 1)·off < 2·off` of area, `off/2` of the light; checked with `off`. The rule
    /// empties the region only when `|a × b| = 0.49·off ≤ 16ε·0.49`, i.e. `off ≤ 16ε < 2⁻⁴⁵`.
    /// The region's area is checked before [`square_fraction`]'s clamp, so NaN fails too.
    #[test]
    fn segments_through_the_center_never_cover_more_than_the_light() {
        let a = DVec2::new(-0.09999999999999998, 0.7666666666666666);
        let b = DVec2::new(0.10000000000000009, -0.7666666666666666);
        assert!(a.perp_dot(b) != 0.0);
        assert_eq!(segment_coverage(a, b), 0.0);
        for k in 0..2000 {
            let t = k as f64 * 0.00314;
            let a = DVec2::new(libm::cos(t), libm::sin(t)) * 0.7;
            for e in 1..20 {
                let off = libm::ldexp(1.0, -3 * e);
                let b = -a + a.perp() * off;
                let unclamped = polygon_area(&segment_region(a, b)) / 4.0;
                if unclamped == 0.0 {
                    assert!(off < libm::ldexp(1.0, -45), "{a} {b}: empty at off {off}");
                } else {
                    assert!((unclamped - 0.5).abs() <= off, "{a} {b}: {unclamped}");
                }
                assert_eq!(segment_coverage(a, b), unclamped, "{a} {b}");
            }
        }
    }
}
