//! Penumbra wedges for a spherical light (Paper I §4.1, §4.2, §8; Paper II §3–§5).
//!
//! # Construction (Paper I §4.1)
//! Silhouette edges are found from the light center c and walked into closed loops
//! ([`super::loops::silhouette_loops`]), which gives each edge its two neighbours. For an edge
//! a→b (oriented as in its light-facing triangle) with shadow-volume-quad normal `n` (pointing
//! out of the hard shadow volume), the points `f = c − r·n` and `b' = c + r·n` define the
//! **front** plane (through the edge and f) and the **back** plane (through the edge and b').
//! Adjacent wedges share one **side** plane: it contains the intersection line of their two
//! front planes and that of their two back planes. Each side plane carries a **ray direction**:
//! the average of the two quad normals projected into the side plane and normalized (§4.1).
//!
//! Choices where the paper is silent (tested in `tests/suite/penumbra_wedges.rs`):
//! * **Finite wedges.** Each wedge is closed by a **bottom** plane (Paper II §5: "if the wedge
//!   planes are of finite length, a capping bottom plane of the wedge must be added") through
//!   the far points `P_v = v + far·d_v` of its two front lines `d_v` (the front–front
//!   intersection lines, shared by neighbours), containing the quad normal. `far` is chosen by
//!   the caller beyond every receiver and the eye ([`far_distance`]), so the bottom never cuts
//!   a visible point out of a wedge, and the front faces of a loop meet exactly at the `P_v`:
//!   front faces plus the occluder's light-facing triangles plus the far cap through the `P_v`
//!   close the outer soft shadow volume (needed by z-fail, Paper II §5).
//! * **Wedge = intersection of its five half-spaces.** Faces are found by enumerating plane
//!   triples. When the side planes cross (large lights or far from the edge: Paper I Fig. 6)
//!   this automatically yields the degenerate wedge the paper draws on the right of Fig. 6: the
//!   back face shrinks to the triangle up to the crossing point, and the side faces meet
//!   beyond it.
//! * **Degenerate side planes.** When the two front (or back) planes are nearly parallel
//!   (collinear neighbouring edges), their intersection line is ill-defined; the side plane is
//!   then the plane through the vertex spanned by the light ray `v − c` and the averaged quad
//!   normal.
//! * **Every wedge bounded and closed.** Where the paper's side plane leaves a neighbouring
//!   wedge empty or not bounded by its bottom plane (back planes nearly parallel, a plane that
//!   does not separate the two edges, or a corner wedge next to an edge close to the light
//!   ray, Paper I §8), the side planes next to that wedge are replaced, first by the plane
//!   through the front–front line and the light ray, then by the degenerate-case plane above,
//!   until every wedge is a bounded polyhedron closed by its faces (`side_plane`). A
//!   front–front line more than [`FRONT_LINE_CONE`] angular radii of the light off the light
//!   ray through its vertex (nearly parallel front planes) is not used at all: the
//!   degenerate-case plane is taken directly.
//! * **Acute corners (Fig. 7).** At a convex silhouette corner whose quad normals turn by more
//!   than 90° (interior angle below 90°), `ceil(turn / 18°) − 1` extra wedges are inserted, with
//!   zero-length edges at the vertex and quad normals interpolated (slerp) between the two
//!   edges' normals — 6 extra wedges for the 60° corner of an equilateral triangle, as in Fig. 7.
//! * **Near-parallel edges (§8).** An edge within [`PARALLEL_SIN`] (sine of the angle) of the
//!   direction of the light ray through it is removed, and its two neighbours are shortened or
//!   lengthened to meet at the removed edge's midpoint ("remove such edges, and shorten &
//!   connect its neighbors"). The rule is optional so that a test can show what happens
//!   without it. The moved vertices no longer lie on the top caps' boundary, so the rule also
//!   adds patch triangles to the top caps that keep the outer soft shadow volume closed.
//!
//! # Folds (the zigzag the papers cannot handle)
//! The thesis's introduction (Fig. 5b) names the silhouettes Papers I and II cannot build
//! wedges for: "silhouette edges \[that\] form a zigzag pattern along the direction to the light
//! source". Seen from the light center such a loop turns back on itself: at a cusp the quad
//! normals of consecutive edges are nearly opposite. The possible silhouettes of finely
//! tessellated real meshes do this wherever the surface is seen at a grazing angle (Spot the
//! cow in `scenes/real/spot-sphere.toml`: 116 folds, every one a turn of more than 150°; the
//! built-in spheres, boxes and columns: none). There the corner wedges of Fig. 7 sweep half a turn around the
//! cusp vertex and the neighbouring wedges overlap instead of partitioning the penumbra, so an
//! eye ray enters a wedge through its back face (s = 0) without having crossed that loop's
//! front faces (−255) and the loop *adds* light: bright streaks and specks inside the umbra.
//! [`silhouette_folds`] counts the folds per mesh ([`WedgeSet::folds`]): corners turning by
//! more than [`FOLD_TURN`], or by more than 90° at a reflex corner (which gets no corner
//! wedges). `pw2002` and `pw-restructured` warn with the count (the condition is the papers',
//! not fixed here).
//!
//! # Light intensity (Paper I §4.2, equations 1–3)
//! [`light_intensity`]: s_l and s_r from the front/back distances along the left and right side
//! directions, interpolated with the distances to the side planes along the edge direction;
//! optionally the smoothstep s' = 3s² − 2s³. [`li_amount`] is the one place 255·s is rounded,
//! shared by `pw2002` and `pw-restructured` so that both produce the same LI values.
//!
//! # Shader precision
//! What the fragment programs of Paper I §4 and Paper II §3 compute per pixel — a plane's value
//! ([`Plane::shader_eval`], [`Plane::shader_distance_along`]), the inside test
//! ([`Wedge::shader_contains`]), the exit point of the eye ray ([`Wedge::shader_exit`]),
//! equations 1–3 ([`shader_light_intensity`]) and the scaling of s to an LI amount
//! ([`shader_li_amount`]) — is generic over the fragment program's scalar
//! ([`crate::gpu::shader_float::ShaderFloat`], `[options.gpu] shader`): the wedge's planes and
//! directions are uniforms rounded to it, the point an input rounded to it, every operation
//! rounded. The functions without `shader_` are their f64 instances; the construction above is
//! CPU work (Paper I §4.1) and stays f64.

use super::loops::silhouette_loops;
use super::silhouette::{light_facing, possible_silhouettes};
use crate::gpu::shader_float::ShaderFloat;
use crate::gpu::shader_vec::SVec3;
use crate::gpu::transform::{ClipVertex, Projection};
use crate::scene::adjacency::Adjacency;
use crate::scene::{Mesh, Scene};
use glam::{DMat3, DVec3, DVec4};

/// Sine of the smallest angle an edge may make with the light ray through its first vertex
/// before the near-parallel rule removes it (≈ 1.15°).
pub const PARALLEL_SIN: f64 = 0.02;

/// Interior angle below which a convex corner gets extra wedges: the quad normals turn by more
/// than this (90°).
pub const ACUTE_TURN: f64 = std::f64::consts::FRAC_PI_2;

/// The turn of the quad normals (150°) beyond which a silhouette corner is a fold, convex or
/// not ([`silhouette_folds`]): the loop seen from the light runs out and back within an
/// interior angle below 30°.
pub const FOLD_TURN: f64 = 5.0 * std::f64::consts::PI / 6.0;

/// Angular step of the extra wedges at an acute corner (18°).
pub const EXTRA_WEDGE_STEP: f64 = std::f64::consts::PI / 10.0;

/// Relative tolerance for plane membership during face enumeration (times the far distance).
const FACE_TOL: f64 = 1e-7;

/// How far the front–front line of a side plane may leave the light ray through its vertex,
/// in angular radii of the light seen from the vertex, before the side plane falls back to the
/// plane through the light ray and the averaged quad normal (see `side_plane`). The paper's
/// lines stay within 1.27 radii on `cylinder` and `pw-columns`, 2.14 on `pw-2002` and 3.05 on
/// `cube-of-spheres-sphere` (large light, Fig. 6); nearly parallel front planes next to corner
/// wedges of `pw-fractal` gave 8 and 11 (and 80° off the ray next to a wedge that was not
/// closed), spreading those wedges' penumbra far from the light's actual penumbra.
pub const FRONT_LINE_CONE: f64 = 4.0;

/// Cross products shorter than this are treated as degenerate (parallel planes).
const DEGENERATE: f64 = 1e-6;

/// A plane `n·x + d = 0` with unit normal `n`; the wedge's inside is `n·x + d ≤ 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// Outward unit normal.
    pub n: DVec3,
    /// Offset.
    pub d: f64,
}

impl Plane {
    /// The plane through `p` with outward normal `n` (normalized here).
    pub fn through(p: DVec3, n: DVec3) -> Self {
        let n = n.normalize();
        Self { n, d: -n.dot(p) }
    }

    /// Signed distance of `p` (positive outside).
    #[inline]
    pub fn eval(&self, p: DVec3) -> f64 {
        self.shader_eval(SVec3::<f64>::from_f64(p))
    }

    /// [`Plane::eval`] by a fragment program in the shader precision `T` (module doc, "Shader
    /// precision"): the plane rounded to `T`, every operation rounded.
    #[inline]
    pub fn shader_eval<T: ShaderFloat>(&self, p: SVec3<T>) -> T {
        SVec3::from_f64(self.n).dot(p) + T::from_f64(self.d)
    }

    /// Distance from `p` to the plane along the line through `p` with direction `dir` (either
    /// way): the "positive intersection distance" of Paper I §4.2. Parallel lines give a huge
    /// finite distance.
    #[inline]
    pub fn distance_along(&self, p: DVec3, dir: DVec3) -> f64 {
        self.shader_distance_along(SVec3::<f64>::from_f64(p), SVec3::from_f64(dir))
    }

    /// [`Plane::distance_along`] in the shader precision `T`. The floor 10⁻¹² of `|n·dir|`
    /// is a constant rounded to `T` (0 in fp16, where a parallel line then gives an infinite
    /// or NaN distance, as it would on the GPU).
    #[inline]
    pub fn shader_distance_along<T: ShaderFloat>(&self, p: SVec3<T>, dir: SVec3<T>) -> T {
        let den = SVec3::from_f64(self.n)
            .dot(dir)
            .abs()
            .max(T::from_f64(1e-12));
        (self.shader_eval(p) / den).abs()
    }

    fn flipped(self) -> Self {
        Self {
            n: -self.n,
            d: -self.d,
        }
    }
}

/// Which plane of a wedge a face lies in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum FaceKind {
    /// Front plane (through f = c − r·n): the lit side.
    Front,
    /// Back plane (through c + r·n): the umbra side.
    Back,
    /// Side plane shared with the previous wedge of the loop.
    Left,
    /// Side plane shared with the next wedge of the loop.
    Right,
    /// Far capping plane.
    Bottom,
}

/// The order planes are stored and faces submitted in.
pub const FACE_ORDER: [FaceKind; 5] = [
    FaceKind::Front,
    FaceKind::Back,
    FaceKind::Left,
    FaceKind::Right,
    FaceKind::Bottom,
];

/// One penumbra wedge.
#[derive(Debug, Clone, PartialEq)]
pub struct Wedge {
    /// Edge start (equal to `b` for an extra corner wedge).
    pub a: DVec3,
    /// Edge end.
    pub b: DVec3,
    /// Unit edge direction (for a corner wedge, the tangent of its virtual edge).
    pub dir: DVec3,
    /// Unit normal of the hard shadow-volume quad, pointing out of the volume.
    pub n: DVec3,
    /// True for an extra wedge at an acute corner (Fig. 7).
    pub extra: bool,
    /// Planes in [`FACE_ORDER`]: front, back, left, right, bottom.
    pub planes: [Plane; 5],
    /// Ray direction in the left side plane (§4.2).
    pub left_dir: DVec3,
    /// Ray direction in the right side plane.
    pub right_dir: DVec3,
    /// Far points of the left and right front lines (`P_a`, `P_b`).
    pub far_front: [DVec3; 2],
    /// Face polygons (counter-clockwise seen from outside), in [`FACE_ORDER`]; a plane that
    /// does not bound the wedge has no face.
    pub faces: Vec<(FaceKind, Vec<DVec3>)>,
}

impl Wedge {
    /// The plane of `kind`.
    pub fn plane(&self, kind: FaceKind) -> &Plane {
        &self.planes[FACE_ORDER.iter().position(|k| *k == kind).unwrap_or(0)]
    }

    /// The front plane's part of the outer soft shadow volume, `(b, a, P_a, P_b)` as two
    /// triangles, wound outward like a shadow-volume quad. Consecutive quads share their far
    /// lines, so with the top and bottom caps they close the volume even where the wedge itself
    /// is degenerate (Fig. 6) and the quad self-intersects.
    pub fn umbra_front_quad(&self) -> [[DVec3; 3]; 2] {
        let [pa, pb] = self.far_front;
        [[self.b, self.a, pa], [self.b, pa, pb]]
    }

    /// Whether the wedge's front face is exactly [`Wedge::umbra_front_quad`] (same vertices):
    /// false for degenerate wedges whose side planes cross (Fig. 6).
    pub fn front_face_is_quad(&self) -> bool {
        let mut quad = vec![self.a, self.b, self.far_front[0], self.far_front[1]];
        quad.dedup();
        self.faces.iter().any(|(k, poly)| {
            *k == FaceKind::Front
                && poly.len() == quad.len()
                && quad.iter().all(|q| poly.contains(q))
        })
    }

    /// Whether `p` lies inside (or on) all five planes.
    #[inline]
    pub fn contains(&self, p: DVec3) -> bool {
        self.shader_contains(SVec3::<f64>::from_f64(p))
    }

    /// [`Wedge::contains`] by a fragment program in the shader precision `T` (module doc,
    /// "Shader precision").
    #[inline]
    pub fn shader_contains<T: ShaderFloat>(&self, p: SVec3<T>) -> bool {
        self.planes.iter().all(|pl| pl.shader_eval(p) <= T::zero())
    }

    /// The plane through which the ray `origin + t·dir` leaves the wedge, and the ray
    /// parameter there: among the planes the ray moves outward through (`n·dir > 0`), the one it
    /// reaches first (Paper I §6: "the exit point is found by computing the intersection of the
    /// ray with all back facing planes, and picking the closest").
    pub fn exit(&self, origin: DVec3, dir: DVec3) -> Option<(FaceKind, f64)> {
        self.shader_exit(SVec3::<f64>::from_f64(origin), SVec3::from_f64(dir))
    }

    /// [`Wedge::exit`] by a fragment program in the shader precision `T` (module doc, "Shader
    /// precision").
    pub fn shader_exit<T: ShaderFloat>(
        &self,
        origin: SVec3<T>,
        dir: SVec3<T>,
    ) -> Option<(FaceKind, T)> {
        let mut best: Option<(FaceKind, T)> = None;
        for (pl, kind) in self.planes.iter().zip(FACE_ORDER) {
            let den = SVec3::from_f64(pl.n).dot(dir);
            if den > T::zero() {
                let t = -pl.shader_eval(origin) / den;
                if best.is_none_or(|(_, bt)| t < bt) {
                    best = Some((kind, t));
                }
            }
        }
        best
    }
}

/// The smallest light radius the wedge construction uses, relative to the distance from the
/// light to the farthest scene point (a quarter of [`far_distance`]); see [`wedge_radius`].
pub const MIN_RELATIVE_RADIUS: f64 = 1e-5;

/// The radius the wedges of a sphere light of `radius` are built with: `radius`, or
/// [`MIN_RELATIVE_RADIUS`] of the light's distance to the farthest scene point if that is
/// larger. Wedges of a smaller light are thinner than the arithmetic resolves — the front and
/// back planes of an edge within ~10⁻⁶ rad of each other and of the light ray, so the side
/// planes built from their intersection lines are rounding noise: a radius of 10⁻⁶ over a
/// 1-unit box blackened 62% of the floor (RMSE 0.79 against `raycast`), 10⁻³⁰ as well —
/// while the penumbra of such a light is far below a pixel at any image size, so widening it
/// changes no visible result.
pub fn wedge_radius(radius: f64, far: f64) -> f64 {
    radius.max(MIN_RELATIVE_RADIUS * far / FAR_FACTOR)
}

/// Options of the wedge construction.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct WedgeOptions {
    /// Light center.
    pub center: DVec3,
    /// Light radius.
    pub radius: f64,
    /// Distance of the far points from their vertices.
    pub far: f64,
    /// Insert extra wedges at acute convex corners (Fig. 7).
    pub extra_corner_wedges: bool,
    /// Apply the near-parallel-edge rule (§8).
    pub parallel_rule: bool,
}

/// All wedges of a scene plus the caps that close the outer soft shadow volume.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct WedgeSet {
    /// Wedges, mesh by mesh, loop by loop, in walk order.
    pub wedges: Vec<Wedge>,
    /// Top caps: the light-facing triangles of every mesh (outward = toward the light), plus
    /// the patches that join them to loops shortened by the near-parallel rule (§8).
    pub top_caps: Vec<[DVec3; 3]>,
    /// Bottom caps: fans over the far points `P_v` of every loop, facing away from the light.
    pub bottom_caps: Vec<[DVec3; 3]>,
    /// Silhouette edges removed by the near-parallel rule.
    pub removed_parallel: usize,
    /// Extra corner wedges inserted.
    pub extra_wedges: usize,
    /// Wedges still not bounded and closed by their faces with the most robust side planes
    /// (0 on every built-in scene; reported in the stats so that a scene where the
    /// construction fails is visible).
    pub open_wedges: usize,
    /// Per set appended ([`WedgeSet::append`], one per light): the index of its first wedge,
    /// top cap and bottom cap.
    pub appended_at: Vec<[usize; 3]>,
    /// The silhouette folds of each mesh that has any ([`silhouette_folds`], module doc,
    /// "Folds"): the mesh's name and its count, in mesh order (one entry per light and mesh).
    pub folds: Vec<(String, usize)>,
}

impl WedgeSet {
    /// Append `other`'s wedges and caps after this set's (several lights, Paper I §7: the
    /// wedges of every light are submitted in light order).
    pub fn append(&mut self, other: WedgeSet) {
        self.appended_at.push([
            self.wedges.len(),
            self.top_caps.len(),
            self.bottom_caps.len(),
        ]);
        self.wedges.extend(other.wedges);
        self.top_caps.extend(other.top_caps);
        self.bottom_caps.extend(other.bottom_caps);
        self.removed_parallel += other.removed_parallel;
        self.extra_wedges += other.extra_wedges;
        self.open_wedges += other.open_wedges;
        self.folds.extend(other.folds);
    }

    /// The total of [`WedgeSet::folds`].
    pub fn fold_count(&self) -> usize {
        self.folds.iter().map(|(_, n)| n).sum()
    }

    /// The light (the set appended, in order) of wedge `wi`; `None` for a set built at once.
    pub fn light_of_wedge(&self, wi: usize) -> Option<u32> {
        self.appended(0, wi)
    }

    /// The light of cap `ci` in [`cap_triangles`] order (top caps, then bottom caps).
    pub fn light_of_cap(&self, ci: usize) -> Option<u32> {
        match ci.checked_sub(self.top_caps.len()) {
            None => self.appended(1, ci),
            Some(b) => self.appended(2, b),
        }
    }

    fn appended(&self, column: usize, index: usize) -> Option<u32> {
        let k = self
            .appended_at
            .iter()
            .filter(|a| a[column] <= index)
            .count();
        k.checked_sub(1).map(|k| k as u32)
    }
}

/// A distance beyond every point of the scene and the eye as seen from the light center `c`
/// (4× the largest such distance), used to place the far ends of wedges.
pub fn far_distance(scene: &Scene, c: DVec3) -> f64 {
    let (lo, hi) = scene.bounds();
    let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
    let mut r = (scene.camera.eye - c).length();
    for i in 0..8 {
        let p = DVec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        r = r.max((p - c).length());
    }
    FAR_FACTOR * r.max(1e-3)
}

/// How much farther than the farthest scene point [`far_distance`] puts the far points.
const FAR_FACTOR: f64 = 4.0;

/// The quad normal of edge a→b from light center c: out of the hard shadow volume.
pub fn quad_normal(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    (a - c).cross(b - a).normalize_or_zero()
}

/// Whether edge a→b is within [`PARALLEL_SIN`] of the light ray through a.
pub fn nearly_parallel(a: DVec3, b: DVec3, c: DVec3) -> bool {
    let e = (b - a).normalize_or_zero();
    let l = (a - c).normalize_or_zero();
    e.cross(l).length() < PARALLEL_SIN
}

/// Remove near-parallel edges of a closed loop of vertex positions, joining the neighbours at
/// the removed edge's midpoint (Paper I §8); returns the removed count.
///
/// The wedges then start at the new loop while the top caps (the light-facing triangles) end
/// at the mesh's silhouette, so each removal also pushes to `patches` the triangles that carry
/// the top cap from the old loop to the new one (Paper II §5: the caps and front planes must
/// close the soft shadow volume exactly, else z-fail counts leak). Replacing `x→p→q→y` by
/// `x→m→y` (m the midpoint of p, q) adds `(x, m, p)`, `(m, y, q)` and the zero-area
/// `(p, m, q)`: their boundary is `x→m→y` minus `x→p→q→y`, every edge shared with exactly the
/// same vertices, so the rasterized surface stays watertight even where the snapped `p, m, q`
/// are not collinear.
fn apply_parallel_rule(lp: &mut Vec<DVec3>, c: DVec3, patches: &mut Vec<[DVec3; 3]>) -> usize {
    let mut removed = 0;
    while lp.len() >= 3 {
        let m = lp.len();
        let Some(i) = (0..m).find(|&i| nearly_parallel(lp[i], lp[(i + 1) % m], c)) else {
            break;
        };
        let j = (i + 1) % m;
        let (x, p, q, y) = (lp[(i + m - 1) % m], lp[i], lp[j], lp[(j + 1) % m]);
        let mid = (p + q) * 0.5;
        patches.extend([[x, mid, p], [mid, y, q], [p, mid, q]]);
        lp[i] = mid;
        lp.remove(j);
        removed += 1;
    }
    removed
}

/// An edge of the wedge loop before planes are built.
#[derive(Debug, Clone, Copy)]
struct LoopEdge {
    a: DVec3,
    b: DVec3,
    dir: DVec3,
    n: DVec3,
    extra: bool,
}

/// The normals of the front and back planes of edge `e` (module doc, "Construction"): the
/// edge direction crossed with the offset of `f` (of `b'`) from the edge's start, or from its
/// end where that offset is parallel to the edge in f64. Such an edge runs from a vertex so far
/// away that the light's offset from it vanishes in rounding (found by fuzzing: an edge from a
/// vertex 10¹⁷ away got NaN front and back planes). Measuring from the end nearer the light
/// throughout would also keep such planes accurate, but moves two-lights/pw2002 by one LI step
/// at 89 pixels, so it is not done here (fuzz/README.md, "Findings").
fn front_back(e: &LoopEdge, c: DVec3, r: f64) -> (DVec3, DVec3) {
    let normal = |x: DVec3| {
        e.dir
            .cross(x - e.a)
            .try_normalize()
            .or_else(|| e.dir.cross(x - e.b).try_normalize())
            .unwrap_or(DVec3::ZERO)
    };
    let f = c - e.n * r;
    let bp = c + e.n * r;
    let mut nf = normal(f);
    if nf.dot(e.n) < 0.0 {
        nf = -nf;
    }
    let mut nb = normal(bp);
    if nb.dot(e.n) > 0.0 {
        nb = -nb;
    }
    (nf, nb)
}

/// How close to a half turn (radians) two quad normals may be before [`slerp`] stops using the
/// great circle through them: there the slerp formula divides a vanishing sum by a vanishing
/// sine (0/0 at the half turn itself, NaN normals and wedges without faces before this rule,
/// found by fuzzing: a silhouette that runs out to a spike and straight back).
const HALF_TURN_TOL: f64 = 1e-6;

/// The unit vector `t` of the way from the unit vector `p` to the unit vector `q` along the
/// great circle through them (spherical linear interpolation). When `p` and `q` are opposite
/// within [`HALF_TURN_TOL`], no great circle is defined by them: the arc then turns from `p`
/// toward `via` (the incoming edge's direction, perpendicular to `p`), the side the short arc
/// takes at every other convex corner (`q · via > 0`), so the corner wedges sweep around the
/// outside of the corner.
fn slerp(p: DVec3, q: DVec3, t: f64, via: DVec3) -> DVec3 {
    let ang = libm::acos(p.dot(q).clamp(-1.0, 1.0));
    if ang < 1e-9 {
        return p;
    }
    if std::f64::consts::PI - ang < HALF_TURN_TOL {
        let u = (via - p * p.dot(via))
            .try_normalize()
            .unwrap_or_else(|| p.any_orthonormal_vector());
        let (sin, cos) = libm::sincos(t * ang);
        return p * cos + u * sin;
    }
    ((p * libm::sin((1.0 - t) * ang) + q * libm::sin(t * ang)) / libm::sin(ang)).normalize()
}

/// Number of extra wedges at the corner between edges with quad normals n1 → n2 (`dir1` is the
/// incoming edge direction): 0 unless convex and acute.
pub fn extra_wedge_count(n1: DVec3, n2: DVec3, dir1: DVec3) -> usize {
    let turn = libm::acos(n1.dot(n2).clamp(-1.0, 1.0));
    let convex = n2.dot(dir1) > 0.0;
    if !convex || turn <= ACUTE_TURN {
        return 0;
    }
    ((turn / EXTRA_WEDGE_STEP).ceil() as usize).saturating_sub(1)
}

/// The folds of a closed loop of vertex positions seen from the light center `c` (module doc,
/// "Folds"): the corners where the loop turns back on itself — quad normals more than
/// [`FOLD_TURN`] apart at any corner (a cusp: the silhouette runs out and back), or more than
/// 90° apart at a reflex corner (`n2 · dir1 < 0`, which gets no corner wedges). Edges without
/// a quad normal or direction (zero length, or along the light ray) are skipped, as the wedge
/// construction skips them.
pub fn silhouette_folds(lp: &[DVec3], c: DVec3) -> usize {
    let m = lp.len();
    let edges: Vec<(DVec3, DVec3)> = (0..m)
        .map(|i| {
            let (a, b) = (lp[i], lp[(i + 1) % m]);
            ((b - a).normalize_or_zero(), quad_normal(a, b, c))
        })
        .filter(|(d, n)| *d != DVec3::ZERO && *n != DVec3::ZERO)
        .collect();
    let k = edges.len();
    if k < 2 {
        return 0;
    }
    let cusp = libm::cos(FOLD_TURN);
    (0..k)
        .filter(|&i| {
            let (d1, n1) = edges[i];
            let (_, n2) = edges[(i + 1) % k];
            let cos = n1.dot(n2);
            cos < cusp || (cos < 0.0 && n2.dot(d1) < 0.0)
        })
        .count()
}

/// Build the wedges of one loop of vertex positions (edge i = v_i → v_{i+1}).
fn loop_wedges(lp: &[DVec3], o: &WedgeOptions, set: &mut WedgeSet) {
    let c = o.center;
    let m = lp.len();
    let base: Vec<LoopEdge> = (0..m)
        .map(|i| {
            let (a, b) = (lp[i], lp[(i + 1) % m]);
            LoopEdge {
                a,
                b,
                dir: (b - a).normalize_or_zero(),
                n: quad_normal(a, b, c),
                extra: false,
            }
        })
        .filter(|e| e.n != DVec3::ZERO && e.dir != DVec3::ZERO)
        .collect();
    let mut edges = Vec::new();
    for (i, e) in base.iter().enumerate() {
        edges.push(*e);
        let next = &base[(i + 1) % base.len()];
        if o.extra_corner_wedges {
            let k = extra_wedge_count(e.n, next.n, e.dir);
            for j in 1..=k {
                let n = slerp(e.n, next.n, j as f64 / (k + 1) as f64, e.dir);
                let v = e.b;
                let dir = n.cross(v - c).normalize_or_zero();
                // An interpolated normal along the light ray through v gives no edge
                // direction, and its wedge no front and back planes: left out, as the
                // loop's own edges with a zero direction or normal are (found by fuzzing: a
                // half turn at a vertex 2·10²⁴ away, whose incoming edge, the direction the
                // turn takes, runs along the ray to rounding; NaN planes before).
                if dir == DVec3::ZERO {
                    continue;
                }
                edges.push(LoopEdge {
                    a: v,
                    b: v,
                    dir,
                    n,
                    extra: true,
                });
                set.extra_wedges += 1;
            }
        }
    }
    let k = edges.len();
    if k < 2 {
        return;
    }
    let fb: Vec<(DVec3, DVec3)> = edges.iter().map(|e| front_back(e, c, o.radius)).collect();
    // Side plane j sits between edge j and edge j+1 at vertex edges[j].b. Paper I §4.1 first;
    // both side planes of a wedge that is not bounded and closed step down one `SideLevel`,
    // until every wedge is closed or its side planes are at the last level (see `side_plane`).
    let mut level = vec![SideLevel::Paper; k];
    let (sides, wedges) = loop {
        let sides: Vec<Side> = (0..k)
            .map(|j| side_plane(&edges, &fb, j, o, level[j]))
            .collect();
        let wedges: Vec<Wedge> = (0..k)
            .map(|j| make_wedge(&edges[j], fb[j], &sides[(j + k - 1) % k], &sides[j], o))
            .collect();
        let mut changed = false;
        for (j, w) in wedges.iter().enumerate() {
            if !is_closed(w) {
                for s in [(j + k - 1) % k, j] {
                    changed |= level[s] != SideLevel::Ray;
                    level[s] = level[s].next();
                }
            }
        }
        if !changed {
            break (sides, wedges);
        }
    };
    set.open_wedges += wedges.iter().filter(|w| !is_closed(w)).count();
    set.wedges.extend(wedges);
    // Far cap: reverse loop order so shared edges P_a→P_b of the front faces are traversed
    // oppositely (outward, away from the light).
    for i in 1..k.saturating_sub(1) {
        set.bottom_caps
            .push([sides[0].far, sides[i + 1].far, sides[i].far]);
    }
}

/// A side plane shared by two neighbouring wedges, with its ray direction (§4.2) and the far
/// point `P_v` of its front line.
struct Side {
    plane: Plane,
    ray: DVec3,
    far: DVec3,
}

/// How a side plane is built (see [`side_plane`]), from the paper's construction to the most
/// robust fallback.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SideLevel {
    /// Paper I §4.1: through the front–front and the back–back intersection lines.
    Paper,
    /// Through the front–front intersection line and the light ray through the vertex.
    FrontLine,
    /// Through the light ray through the vertex and the averaged quad normal.
    Ray,
}

impl SideLevel {
    fn next(self) -> Self {
        match self {
            SideLevel::Paper => SideLevel::FrontLine,
            _ => SideLevel::Ray,
        }
    }
}

/// The side plane between edge j and edge j+1 at their common vertex v.
///
/// Paper I §4.1: the plane through the intersection line of the two front planes and that of
/// the two back planes, far point `P_v` on the front–front line. Paper I §8 warns that this
/// "side plane construction will not be robust" for edges nearly along the light ray, and it
/// fails in two ways the paper does not list: where the two back planes are nearly parallel
/// or the plane does not separate the two edges (`pw-2002`: short edges at right-angled box
/// corners), and where a corner wedge (Fig. 7) meets an edge close to the light ray, whose
/// front plane is tilted almost onto the corner wedge's, so that the front–front line runs far
/// off the light ray (`pw-fractal`). The wedges next to such a plane are then empty or not
/// bounded by their bottom plane. `loop_wedges` therefore steps the side planes next to a
/// wedge that is not bounded and closed ([`is_closed`]) down this list until it is (the first
/// two need a front–front line within [`FRONT_LINE_CONE`] of the light ray, else the last is
/// taken):
/// * [`SideLevel::FrontLine`]: the plane through the front–front line and the light ray
///   `v − c`; the front faces still meet on the front–front line, so they stay the quads
///   `(b, a, P_a, P_b)` of the outer soft shadow volume.
/// * [`SideLevel::Ray`] (also used when the paper's lines are degenerate): the plane through
///   v spanned by the light ray and the averaged quad normal, the limit of the paper's plane
///   for a point light (both lines become the light ray). It separates the two edges and is
///   never close to a front or back plane, so the wedges on both sides are bounded. `P_v` lies
///   on the bisector of the two front lines in the plane, shared by both wedges, so the outer
///   soft shadow volume stays closed through it.
///
/// Both wedges use the same plane, so the C⁰ continuity of §4.2 is kept.
fn side_plane(
    edges: &[LoopEdge],
    fb: &[(DVec3, DVec3)],
    j: usize,
    o: &WedgeOptions,
    level: SideLevel,
) -> Side {
    let c = o.center;
    let k = edges.len();
    let (e1, e2) = (&edges[j], &edges[(j + 1) % k]);
    let v = e1.b;
    let (nf1, nb1) = fb[j];
    let (nf2, nb2) = fb[(j + 1) % k];
    let df = nf1.cross(nf2);
    let db = nb1.cross(nb2);
    // Opposite quad normals (a silhouette spike, within HALF_TURN_TOL of a half turn) have no
    // average: their sum is rounding noise, which gave a side plane through the light ray with
    // a zero normal (NaN, found by fuzzing). The first edge's normal makes the side plane
    // perpendicular to the edge at the spike's tip.
    let sum = e1.n + e2.n;
    let navg = if sum.length() > HALF_TURN_TOL {
        sum.normalize()
    } else {
        e1.n
    };
    let away = |l: DVec3| {
        let l = l.normalize_or_zero();
        if l.dot(v - c) < 0.0 {
            -l
        } else {
            l
        }
    };
    let ray = (v - c).normalize_or_zero();
    let paper = df.cross(db);
    let front_ray = away(df).cross(ray);
    let near_ray = away(df).dot(ray)
        >= libm::cos(
            (FRONT_LINE_CONE * libm::asin((o.radius / (v - c).length()).min(1.0)))
                .min(std::f64::consts::FRAC_PI_2),
        );
    let (normal, line) = if level == SideLevel::Paper
        && near_ray
        && df.length() > DEGENERATE
        && db.length() > DEGENERATE
        && paper.length() > DEGENERATE * DEGENERATE
    {
        (paper.normalize(), away(df))
    } else if level != SideLevel::Ray
        && near_ray
        && df.length() > DEGENERATE
        && front_ray.length() > DEGENERATE
    {
        (front_ray.normalize(), away(df))
    } else {
        // navg is perpendicular to the light ray where both edges end at v; where edges were
        // dropped between them (zero length or along the ray) it need not be, and a plane
        // through the ray is still needed.
        let normal = ray
            .cross(navg)
            .try_normalize()
            .or_else(|| ray.cross(e1.n).try_normalize())
            .unwrap_or_else(|| ray.any_orthonormal_vector());
        (
            normal,
            away(away(normal.cross(nf1)) + away(normal.cross(nf2))),
        )
    };
    let normal = if normal.dot(e1.dir + e2.dir) < 0.0 {
        -normal
    } else {
        normal
    };
    Side {
        plane: Plane::through(v, normal),
        ray: (navg - normal * navg.dot(normal)).normalize_or_zero(),
        far: v + line * o.far,
    }
}

/// The wedge of edge `e` between side planes `prev` (left) and `next` (right), closed by the
/// bottom plane through the far points.
fn make_wedge(
    e: &LoopEdge,
    fb: (DVec3, DVec3),
    prev: &Side,
    next: &Side,
    o: &WedgeOptions,
) -> Wedge {
    let (nf, nb) = fb;
    let (pa, pb) = (prev.far, next.far);
    let mut zn = (pb - pa).cross(e.n);
    if zn.length() < DEGENERATE {
        zn = ((pa + pb) * 0.5 - o.center).normalize_or_zero();
    }
    let mut bottom = Plane::through(pa, zn);
    if bottom.eval(e.a) > 0.0 {
        bottom = bottom.flipped();
    }
    let planes = [
        Plane::through(e.a, nf),
        Plane::through(e.a, nb),
        prev.plane.flipped(),
        next.plane,
        bottom,
    ];
    let faces = wedge_faces(&planes, &[e.a, e.b, pa, pb], o.far);
    Wedge {
        a: e.a,
        b: e.b,
        dir: e.dir,
        n: e.n,
        extra: e.extra,
        planes,
        left_dir: prev.ray,
        right_dir: next.ray,
        far_front: [pa, pb],
        faces,
    }
}

/// Whether a wedge is a bounded region with at least four faces: no direction d has
/// `n·d ≤ 0` for all five plane normals. Such a direction, if any, is an edge direction of the
/// recession cone, which lies on two of the planes: `±(n_i × n_j)`.
fn is_closed(w: &Wedge) -> bool {
    if w.faces.len() < 4 {
        return false;
    }
    let p = &w.planes;
    for i in 0..5 {
        for j in i + 1..5 {
            let d = p[i].n.cross(p[j].n);
            if d.length() < DEGENERATE {
                continue;
            }
            let d = d.normalize();
            for d in [d, -d] {
                if p.iter().all(|pl| pl.n.dot(d) <= DEGENERATE) {
                    return false;
                }
            }
        }
    }
    true
}

/// The faces of the intersection of five half-spaces, by vertex enumeration. Vertices within
/// tolerance of a canonical point (edge ends, far points) are snapped to it so that neighbouring
/// wedges share their vertices exactly.
fn wedge_faces(planes: &[Plane; 5], canon: &[DVec3], far: f64) -> Vec<(FaceKind, Vec<DVec3>)> {
    let tol = FACE_TOL * far;
    let mut verts: Vec<DVec3> = Vec::new();
    for i in 0..5 {
        for j in i + 1..5 {
            for k in j + 1..5 {
                let (p, q, r) = (planes[i], planes[j], planes[k]);
                let m = DMat3::from_cols(p.n, q.n, r.n).transpose();
                let det = m.determinant();
                if det.abs() < 1e-12 {
                    continue;
                }
                let x = m.inverse() * DVec3::new(-p.d, -q.d, -r.d);
                if !x.is_finite() || planes.iter().any(|pl| pl.eval(x) > tol) {
                    continue;
                }
                let x = canon
                    .iter()
                    .copied()
                    .find(|cp| (*cp - x).length() <= tol * 10.0)
                    .unwrap_or(x);
                if !verts.iter().any(|v| (*v - x).length() <= tol * 10.0) {
                    verts.push(x);
                }
            }
        }
    }
    let mut faces = Vec::new();
    for (pl, kind) in planes.iter().zip(FACE_ORDER) {
        let on: Vec<DVec3> = verts
            .iter()
            .copied()
            .filter(|v| pl.eval(*v).abs() <= tol * 10.0)
            .collect();
        if on.len() < 3 {
            continue;
        }
        let centroid = on.iter().copied().sum::<DVec3>() / on.len() as f64;
        let u = pl.n.any_orthonormal_vector();
        let w = pl.n.cross(u);
        let mut sorted = on;
        sorted.sort_by(|x, y| {
            let ax = libm::atan2((*x - centroid).dot(w), (*x - centroid).dot(u));
            let ay = libm::atan2((*y - centroid).dot(w), (*y - centroid).dot(u));
            ax.total_cmp(&ay)
        });
        faces.push((kind, sorted));
    }
    faces
}

/// Build every wedge of `meshes` for a sphere light (center and radius in `o`): silhouettes from
/// the center, loops, the near-parallel rule, extra corner wedges, planes, faces and caps.
pub fn build_wedges(meshes: &[(&Mesh, &Adjacency)], o: &WedgeOptions) -> Result<WedgeSet, String> {
    let mut set = WedgeSet::default();
    let c32 = o.center.as_vec3();
    for (mesh, adj) in meshes {
        let facing = light_facing(mesh, c32);
        for (t, f) in mesh.triangles.iter().zip(&facing) {
            if *f {
                set.top_caps
                    .push(t.map(|i| mesh.positions[i as usize].as_dvec3()));
            }
        }
        let sil = possible_silhouettes(mesh, adj, &facing);
        let mut folds = 0;
        for lp in silhouette_loops(&sil).map_err(|e| format!("mesh {}: {e}", mesh.name))? {
            let mut pts: Vec<DVec3> = lp.iter().map(|&k| sil[k].a.as_dvec3()).collect();
            if o.parallel_rule {
                set.removed_parallel += apply_parallel_rule(&mut pts, o.center, &mut set.top_caps);
            }
            if pts.len() >= 2 {
                folds += silhouette_folds(&pts, o.center);
                loop_wedges(&pts, o, &mut set);
            }
        }
        if folds > 0 {
            set.folds.push((mesh.name.clone(), folds));
        }
    }
    Ok(set)
}

/// Paper I §4.2, equations 1–3: the light intensity s ∈ [0, 1] at a point `p` inside wedge `w`
/// (1 on the front plane, 0 on the back plane), optionally smoothed to 3s² − 2s³.
pub fn light_intensity(w: &Wedge, p: DVec3, smooth: bool) -> f64 {
    shader_light_intensity(w, SVec3::<f64>::from_f64(p), smooth)
}

/// [`light_intensity`] by a fragment program in the shader precision `T` (module doc, "Shader
/// precision"): the wedge's planes and ray directions rounded to `T`, every operation rounded.
pub fn shader_light_intensity<T: ShaderFloat>(w: &Wedge, p: SVec3<T>, smooth: bool) -> T {
    let (zero, one, half) = (T::zero(), T::one(), T::from_f64(0.5));
    let [front, back, left, right, _] = &w.planes;
    let side = |d: DVec3| {
        let d = SVec3::from_f64(d);
        let tf = front.shader_distance_along(p, d);
        let tb = back.shader_distance_along(p, d);
        if tf + tb > zero {
            tb / (tf + tb)
        } else {
            half
        }
    };
    let sl = side(w.left_dir);
    let sr = side(w.right_dir);
    let dir = SVec3::from_f64(w.dir);
    let tl = left.shader_distance_along(p, dir);
    let tr = right.shader_distance_along(p, dir);
    let s = if tl + tr > zero {
        (tr * sl + tl * sr) / (tr + tl)
    } else {
        half * (sl + sr)
    };
    let s = if s.is_finite() {
        s.clamp(zero, one)
    } else {
        zero
    };
    if smooth {
        s * s * (T::from_f64(3.0) - T::from_f64(2.0) * s)
    } else {
        s
    }
}

/// The LI amount of intensity `s` with `lights` lights: `round(255/n · s)`, rounding half up
/// (`floor(x + 0.5)`). Paper I adds `round(255·(s_i − s_f))`; both penumbra-wedge methods here
/// add `li_amount(s_i) − li_amount(s_f)` instead, which differs by at most 1 and makes integer
/// sums independent of how contributions are grouped into passes (Paper I §7 for 255/n).
#[inline]
pub fn li_amount(s: f64, lights: u32) -> i32 {
    shader_li_amount(s, lights)
}

/// [`li_amount`] with the scaling `255/n · s + 0.5` computed by the fragment program in the
/// shader precision `T` (module doc, "Shader precision"); the floor is the conversion to the
/// LI buffer's integers (exact).
#[inline]
pub fn shader_li_amount<T: ShaderFloat>(s: T, lights: u32) -> i32 {
    let scaled = s * T::from_f64(255.0) / T::from_f64(lights.max(1) as f64) + T::from_f64(0.5);
    scaled.floor().to_f64() as i32
}

/// A triangle of wedge geometry to submit, with what it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WedgeTriangle {
    /// Clip-space vertices (world positions rounded to f32 first, as a vertex stage sees them).
    pub clip: [ClipVertex; 3],
    /// Wedge index, or `None` for a cap triangle.
    pub wedge: Option<u32>,
    /// Face kind (`None` for caps).
    pub kind: Option<FaceKind>,
}

fn clip_of(proj: &Projection, p: DVec3) -> ClipVertex {
    proj.clip_point(p.as_vec3())
}

/// The faces of every wedge as fan-triangulated clip-space triangles, wedge by wedge, faces in
/// [`FACE_ORDER`] (the submission order of both penumbra-wedge methods).
pub fn wedge_triangles(set: &WedgeSet, proj: &Projection) -> Vec<WedgeTriangle> {
    let mut out = Vec::new();
    for (wi, w) in set.wedges.iter().enumerate() {
        for (kind, poly) in &w.faces {
            for i in 1..poly.len() - 1 {
                out.push(WedgeTriangle {
                    clip: [poly[0], poly[i], poly[i + 1]].map(|p| clip_of(proj, p)),
                    wedge: Some(wi as u32),
                    kind: Some(*kind),
                });
            }
        }
    }
    out
}

/// The cap triangles (top caps, then bottom caps) in clip space.
pub fn cap_triangles(set: &WedgeSet, proj: &Projection) -> Vec<WedgeTriangle> {
    set.top_caps
        .iter()
        .chain(&set.bottom_caps)
        .map(|t| WedgeTriangle {
            clip: t.map(|p| clip_of(proj, p)),
            wedge: None,
            kind: None,
        })
        .collect()
}

/// A wedge's screen-space setup for tile culling (Paper II §4): its planes in normalized device
/// coordinates and its window-depth range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScreenWedge {
    /// Plane coefficients over (x_ndc, y_ndc, z_ndc, 1); positive = outside, valid for points in
    /// front of the eye.
    pub planes: [DVec4; 5],
    /// Smallest and largest window depth of the wedge's vertices ([0, 1] if any vertex is not in
    /// front of the eye).
    pub z_range: [f64; 2],
}

/// Precompute the screen-space plane equations and depth range of a wedge (once per frame).
pub fn screen_wedge(w: &Wedge, proj: &Projection) -> ScreenWedge {
    let inv_t = proj.inv_view_proj.transpose();
    let planes = w.planes.map(|pl| inv_t * pl.n.extend(pl.d));
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    let mut behind = false;
    for (_, poly) in &w.faces {
        for p in poly {
            match proj.window_depth(*p) {
                None => behind = true,
                Some(z) => {
                    lo = lo.min(z);
                    hi = hi.max(z);
                }
            }
        }
    }
    let z_range = if behind || lo > hi {
        [0.0, 1.0]
    } else {
        [lo.clamp(0.0, 1.0), hi.clamp(0.0, 1.0)]
    };
    ScreenWedge { planes, z_range }
}

impl ScreenWedge {
    /// The n/p-vertex test (Paper II §4, Fig. 6): true when the screen-space box
    /// `[x0,x1]×[y0,y1]` (pixel edges, row 0 at the top) × `[z0,z1]` (window depth) lies
    /// entirely outside one wedge plane. Only the box vertex nearest to the inside of each plane
    /// (its n-vertex) is tested.
    pub fn box_outside(&self, px: [f64; 2], py: [f64; 2], z: [f64; 2], w: f64, h: f64) -> bool {
        let xs = px.map(|x| x / w * 2.0 - 1.0);
        let ys = py.map(|y| 1.0 - y / h * 2.0);
        let zs = z.map(|z| z * 2.0 - 1.0);
        let (xlo, xhi) = (xs[0].min(xs[1]), xs[0].max(xs[1]));
        let (ylo, yhi) = (ys[0].min(ys[1]), ys[0].max(ys[1]));
        let (zlo, zhi) = (zs[0].min(zs[1]), zs[0].max(zs[1]));
        self.planes.iter().any(|q| {
            let x = if q.x > 0.0 { xlo } else { xhi };
            let y = if q.y > 0.0 { ylo } else { yhi };
            let zz = if q.z > 0.0 { zlo } else { zhi };
            q.x * x + q.y * y + q.z * zz + q.w > 0.0
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Loops in the plane z = 0 under a light at (0, 0, 10), counter-clockwise seen from it
    /// (the orientation of silhouette loops: quad normals point out of the loop). The angles
    /// below are those of the plane figures; the perspective from c moves them by well under a
    /// degree, far from the thresholds (90° and 150°).
    #[test]
    fn folds_are_cusps_and_sharp_reflex_corners() {
        let c = DVec3::new(0.0, 0.0, 10.0);
        let lp = |pts: &[(f64, f64)]| -> Vec<DVec3> {
            pts.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect()
        };
        let h = libm::sqrt(3.0) / 2.0;
        // Equilateral triangle: three convex corners turning by 120° (Fig. 7's acute corners,
        // which get corner wedges), no fold.
        assert_eq!(
            silhouette_folds(&lp(&[(0.0, 0.0), (1.0, 0.0), (0.5, h)]), c),
            0
        );
        // A spike: the corner at (4, 0) has an interior angle of atan(1/8) = 7.1° (a turn of
        // 172.9° > 150°: a fold); (0, 0.5) turns by 97.1° and (0, 0) by 90°, both convex.
        assert_eq!(
            silhouette_folds(&lp(&[(0.0, 0.0), (4.0, 0.0), (0.0, 0.5)]), c),
            1
        );
        // A dart: the cusps at (4, −2) and (4, 2) (7.1° interior, turns of 172.9°) and the
        // reflex corner at (1, 0) (turning back by 112.6° > 90°) are folds; the convex corner
        // at (0, 0) turns by 126.9° < 150° and is not.
        let dart = lp(&[(0.0, 0.0), (4.0, -2.0), (1.0, 0.0), (4.0, 2.0)]);
        assert_eq!(silhouette_folds(&dart, c), 3);
        // Reversed, (0, 0) becomes the reflex corner (126.9° > 90°: a fold) and (1, 0) a
        // convex one turning by 112.6° (not): three again.
        let reversed: Vec<DVec3> = dart.iter().rev().copied().collect();
        assert_eq!(silhouette_folds(&reversed, c), 3);
    }

    /// Opposite quad normals (a silhouette spike) have no great circle: the corner normals turn
    /// from the first toward the incoming edge direction, finite and of unit length (the slerp
    /// formula gave NaN at t = ½).
    #[test]
    fn slerp_of_opposite_normals_turns_toward_the_edge() {
        let (n, dir) = (DVec3::Z, DVec3::X);
        for k in 0..=10 {
            let t = k as f64 / 10.0;
            let m = slerp(n, -n, t, dir);
            let expected = DVec3::new(
                libm::sin(t * std::f64::consts::PI),
                0.0,
                libm::cos(t * std::f64::consts::PI),
            );
            assert!((m - expected).length() < 1e-15, "t {t}: {m}");
        }
        // Short of the half turn the great circle is used as before.
        let q = DVec3::new(0.6, 0.0, -0.8);
        assert!((slerp(n, q, 1.0, dir) - q).length() < 1e-15);
    }

    #[test]
    fn extra_wedges_for_sixty_degree_corner() {
        // Equilateral triangle corner: the outward normal turns by 120° (convex).
        let n1 = DVec3::new(0.0, -1.0, 0.0);
        let (sn, cs) = libm::sincos(120f64.to_radians());
        let n2 = DVec3::new(sn, -cs, 0.0);
        let dir1 = DVec3::X;
        assert!((libm::acos(n1.dot(n2)).to_degrees() - 120.0).abs() < 1e-9);
        assert_eq!(extra_wedge_count(n1, n2, dir1), 6);
        // Concave corner (normal turns the other way): none.
        assert_eq!(extra_wedge_count(n1, DVec3::new(-n2.x, n2.y, 0.0), dir1), 0);
    }

    #[test]
    fn li_amount_rounds_half_up_and_scales_per_light() {
        assert_eq!(li_amount(1.0, 1), 255);
        assert_eq!(li_amount(0.5, 1), 128);
        assert_eq!(li_amount(1.0, 2), 128);
        assert_eq!(li_amount(0.0, 1), 0);
    }
}
