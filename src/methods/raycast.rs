//! `raycast`: the ground truth by definition (`docs/architecture.md` "Methods"; issue 2,
//! `raycast`).
//!
//! For every pixel, the fraction of the light visible from the pixel's receiver point,
//! estimated with stratified shadow rays: `samples` jittered samples from
//! [`sampling::stratified`] ([`Pattern::Jittered`], so that the estimate is independent of the
//! centered grid `nsample` uses, Paper III §5.1). Sphere lights are sampled as the disk through
//! their center facing the receiver (Paper IV §4.2.1); textured lights (Paper III §3.3) give one
//! visibility per RGB channel, every other light one gray value.
//!
//! # The visibility of one receiver
//!
//! With sample weights `w_ic` (per channel c, see [`sampling`]) and `B` the set of blocked
//! samples, `V_c = Σ_{i∉B} w_ic / Σ_i w_ic`, both sums accumulated in f64 in sample order and
//! the quotient rounded to f32 once. Dividing by the total (rather than trusting the f32
//! weights to sum to 1) makes a fully lit point exactly 1 and a fully shadowed one exactly 0.
//! A channel with no emission (all its weights 0) reports 0.
//!
//! # Shadow rays
//!
//! The ray from the receiver `p` to the sample `s` starts at `o = p + δ·n`, with `n` the
//! receiver's camera-side normal and `δ = `[`ORIGIN_OFFSET`]` × D + `[`ORIGIN_OFFSET_ULPS`]
//! `× ε_f32 ×` the largest coordinate magnitude of the meshes, `D` the length (f32) of the
//! diagonal of [`Scene::mesh_bounds`] (receivers are mesh points: a light far away changes
//! neither their extent nor their rounding — measured with the light's center in the bounds,
//! a point light 10⁶ units up lifted every ray origin 100 units, above the occluder), so that a receiver read back from a quantized depth buffer does
//! not shadow itself, and neither does one whose f32 coordinates far from the origin are
//! rounded by more than the first term (a scene 3·10⁴ units out rounds receivers by ~0.002,
//! more than 10⁻⁴ of a 10-unit scene). The ray is blocked when it hits any triangle at a parameter
//! `t ∈ (ε·min(1, D/L), 1 − ε)` of the segment `o + t·(s − o)` of length `L`,
//! `ε = `[`SEGMENT_EPSILON`]: hits closer to the origin than `ε·min(L, D)` do not count (a
//! relative start `ε·L` ignored the first unit of every ray to a light 10⁶ away, and the whole
//! scene for a light at 10³⁰), and the far end keeps a light that lies on a surface from
//! being blocked by that surface.
//!
//! # Self-occlusion
//!
//! A light sample at or below the receiver's tangent plane (`n·(s − p) ≤ 0`) is blocked by the
//! receiver's own surface: the meshes are closed, so the solid lies locally below that plane.
//! Without this rule the normal offset would lift a receiver on a facet facing away from (part
//! of) the light out of its own object's shadow — near terminators of faceted spheres, rays
//! from the offset origin graze past the object and report light that the surface point cannot
//! see, while every shadow-volume method (the receiver is inside its own object's volume)
//! correctly reports shadow. Measured on `cube-of-spheres` with a point light at 256²: 147 of
//! the 159 pixels where `raycast` and `hard-sv` disagreed were such receivers.
//!
//! Each ray–triangle test is Möller–Trumbore in f64 on the f32 vertices, edges and vertices
//! inclusive (a ray through a shared edge of a closed mesh cannot leak), no back-face culling.
//! It is a pure function of the ray and the triangle, and a ray is blocked if *any* triangle
//! blocks it. Everything below only decides which triangles are tested; it never changes the
//! answer, so the result depends neither on the BVH's shape nor on its traversal order.
//!
//! # Acceleration (exact)
//!
//! Everything here only decides *which* triangles a ray is tested against, never the answer;
//! a test checks that it gives the same bits as testing every ray through the whole tree.
//!
//! 1. A bounding volume hierarchy is built once per scene by [`ShadowRayCaster::new`] with
//!    the `bvh` crate (0.10: binned SAH, one triangle per leaf, deterministic) and flattened
//!    into a depth-first array of glam boxes. (The crate's own iterator follows a ray to
//!    infinity, past the light, and its strict box test `t_far > t_near` skips the flat box
//!    of an axis-aligned triangle; the flattened any-hit traversal, clipped to `t ∈ [0, 1]`,
//!    avoids both.)
//! 2. Per receiver, the *shaft* (Haines & Wallace, "Shaft Culling for Efficient Ray-Traced
//!    Radiosity", 1991) — the convex hull of the ray origin and a quadrilateral containing
//!    every light sample ([`sampling::bounding_quad`]) — collects from the tree the triangles
//!    whose boxes it may meet: no other triangle can block any of the receiver's rays. None:
//!    the receiver sees every sample.
//! 3. Each candidate is clipped to the depths a blocking hit can have (`> ε·h/2`, `h` the
//!    distance of the light plane from the origin), projected from the origin onto the light
//!    plane and binned by its bounding box into a 16×16 grid over the quadrilateral. A ray
//!    blocked by a triangle crosses the light plane inside that triangle's projection, so
//!    each ray is tested only against the triangles of the cell its crossing point falls in
//!    (plus those covering the whole grid), with the exact test above.
//!
//! 4. Each ray first tests the triangle that blocked the receiver's previous ray (the strata
//!    run in order, so neighbouring samples are mostly blocked by the same triangle).
//!
//! Point lights, degenerate shafts (the origin in the light's plane) and sample counts below
//! [`BINNED_MIN_SAMPLES`] (where the set-up costs more than it saves) trace the rays through
//! the whole tree instead:
//!
//! 5. In *packets* of 16 rays from one origin (from [`PACKET_MIN_SAMPLES`] samples; fewer go
//!    one by one with step 4): the traversal carries per node the rays whose segment may meet
//!    its box, four rays' slab tests to one SIMD operation ([`glam::Vec4`]: the same f32
//!    products as a single ray's test), and a ray leaves the packet when a triangle blocks it.
//!    Where every ray's direction has the same sign on an axis, the slab's entry face is known
//!    and the min/max of the two products need not be taken (the same values). The rays of a
//!    receiver head for one light, so they share most of their path through the tree: on
//!    `forest-spheres` at 16 samples a packet visited 74 nodes on average (counted), 4.6 a
//!    ray. The tree is built in parallel (`Bvh::build_par`, the same tree as the serial
//!    build: the splits do not depend on the threads).
//!
//! Conservativeness: with `D` the diagonal of the bounds of the meshes and the whole light and
//! `M` the largest coordinate magnitude in them, every triangle's box is padded by
//! `pad = `[`BOX_PADDING`]` × D + 4·ε_f32 × M`, and the shaft is widened by `pad` too. The f32
//! rounding of the ray origin, of the sample positions and of the slab parameters moves a
//! ray by at most a few ulps of M (plus ~1e-7 D), far less than the padding, so a box that
//! holds a blocking triangle is never culled; a ray parallel to a slab that grazes a padded
//! face exactly (where `0·∞` gives NaN and the box may be rejected) cannot touch a triangle,
//! which lies at least `pad` inside. The bins are widened by `BIN_MARGIN × (D + M)`,
//! which covers the f64 rounding of the projections; the clip depth `ε·h/2` keeps half of
//! `ε` to spare.
//!
//! # Determinism
//!
//! Pixels are independent and computed in parallel with rayon; each pixel's sum runs in sample
//! order, so the output bits do not depend on the number of threads. Every pixel uses the same
//! jitter (a pure function of `seed` and the stratum), hence the error of the estimate is
//! correlated between neighbouring pixels rather than noisy.

use super::output::MethodOutput;
use super::recorder::PassRecorder;
use crate::error::InputError;
use crate::frame::Frame;
use crate::gpu::probe::{PassProbe, PrimitiveKind};
use crate::light::sampling::{self, LightSample, Pattern};
use crate::options::{option_names, option_table, OptionTable, OptionType};
use crate::primitives::ray_triangle::segment_crosses_triangle;
use crate::scene::{Light, LightShape, Scene};
use crate::visibility::Visibility;
use bvh::aabb::{Aabb, Bounded};
use bvh::bounding_hierarchy::{BHShape, BoundingHierarchy};
use bvh::bvh::{Bvh, BvhNode};
use glam::{DVec3, Vec3, Vec4};
use rayon::prelude::*;

/// Ray-origin offset along the receiver normal, relative to the scene diagonal (module doc,
/// "Shadow rays"): 10⁻⁴, twice the tolerance within which [`Frame::receivers`] snaps a
/// depth-buffer receiver onto its triangle's plane, so that a snapped receiver is never below
/// the point its shadow rays start from — by construction, not by a test.
pub const ORIGIN_OFFSET: f64 = 2.0 * crate::frame::RECEIVER_PLANE_TOLERANCE;

/// The part of the ray-origin offset that scales with the coordinates' magnitude, in f32 ulps
/// (module doc, "Shadow rays"): receivers are f32 points, rounded by half an ulp.
pub const ORIGIN_OFFSET_ULPS: f64 = 2.0;

/// `ε` of the open parameter interval `(ε·min(1, D/L), 1 − ε)` of the shadow segment in which
/// a hit blocks it (module doc, "Shadow rays").
pub const SEGMENT_EPSILON: f64 = 1e-6;

/// Fewest light samples per receiver for which the shaft and the light-plane binning
/// (module doc, "Acceleration", 2–3) are used; fewer samples go through the whole tree in
/// packets (5), which then costs less than the per-receiver set-up. Measured on 2026-12-04
/// at 256² with one thread, the `raycast` pass, binned vs packets (s), with a mutation run
/// on the other core:
///
/// | samples | `cube-of-spheres` | `forest-spheres` | `spot` |
/// |---|---|---|---|
/// | 16 | 0.165 / 0.045 | 0.623 / 0.071 | 0.113 / 0.085 |
/// | 36 | 0.194 / 0.095 | 0.671 / 0.125 | 0.129 / 0.116 |
/// | 64 | 0.208 / 0.142 | 0.725 / 0.203 | 0.157 / 0.205 |
/// | 100 | 0.249 / 0.208 | 0.753 / 0.300 | 0.184 / 0.281 |
/// | 144 | 0.310 / 0.291 | 0.861 / 0.415 | 0.201 / 0.382 |
/// | 256 | 0.357 / 0.458 | 0.988 / 0.642 | 0.263 / 0.597 |
/// | 1024 | 0.772 / 1.613 | 1.564 / 2.025 | 0.562 / 2.101 |
///
/// The crossing lies near 45 samples on the real model, 150 on the cube and 450 on the
/// forest (where a receiver's shaft holds many spheres); 100 loses at most 1.5× on either
/// side. Either path gives the same bits. (Before the packets, with one ray at a time, the
/// threshold was 40.)
pub const BINNED_MIN_SAMPLES: usize = 100;

/// Fewest light samples per receiver for which the rays go through the tree in packets
/// (module doc, "Acceleration", 5) rather than one by one: one SIMD group of four (not
/// measured below 16 samples; a point light's single ray goes alone).
pub const PACKET_MIN_SAMPLES: usize = 4;

/// Padding of every triangle's BVH box and of every shaft, relative to the scene diagonal
/// (module doc, "Acceleration").
pub const BOX_PADDING: f64 = 1e-5;

/// The default number of light samples per pixel (issue 2: 1024, the papers' reference count,
/// Paper III §5.1).
pub const DEFAULT_SAMPLES: u32 = 1024;

pub use crate::frame::Receiver;

/// Which disk a sphere light is seen as.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SphereDisk {
    /// The disk through the center facing each receiver (Paper IV §4.2.1; what the wedge
    /// methods' coverage uses): the default.
    FacingReceiver,
    /// One disk for all receivers, facing this point (what `nsample` must use: one set of
    /// light samples per frame, facing the center of the bounds of the meshes within the light's influence).
    Facing(Vec3),
}

/// Options of the `raycast` method (issue 2, `raycast`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RaycastSettings {
    /// Light samples per receiver: a perfect square k×k ([`sampling::stratified`]); default
    /// [`DEFAULT_SAMPLES`].
    pub samples: u32,
    /// Seed of the jitter ([`Pattern::Jittered`]); default 0.
    pub seed: u64,
    /// The disk a sphere light is seen as.
    pub sphere_disk: SphereDisk,
}

impl Default for RaycastSettings {
    fn default() -> Self {
        Self {
            samples: DEFAULT_SAMPLES,
            seed: 0,
            sphere_disk: SphereDisk::FacingReceiver,
        }
    }
}

impl RaycastSettings {
    /// Checks the settings: `samples` must be a perfect square ≥ 1. Option parsing calls this,
    /// so that [`ShadowRayCaster::visibility`] never sees an invalid count.
    pub fn validate(&self) -> Result<(), String> {
        let k = self.samples.isqrt();
        if self.samples == 0 || k * k != self.samples {
            return Err(format!(
                "raycast.samples must be a perfect square k×k ≥ 1 (e.g. 256, 1024), got {}",
                self.samples
            ));
        }
        Ok(())
    }
}

/// One triangle in f64 for the exact Möller–Trumbore test: a vertex and the two edges from it.
#[derive(Debug, Clone, Copy)]
struct Triangle {
    v0: DVec3,
    e1: DVec3,
    e2: DVec3,
}

impl Triangle {
    /// True when the segment `o + t·d` hits the triangle at `t ∈ (t_start, 1 − ε)`
    /// ([`segment_crosses_triangle`]: Möller & Trumbore 1997, f64, edges inclusive, both
    /// sides).
    #[inline]
    fn blocks(&self, o: DVec3, d: DVec3, t_start: f64) -> bool {
        segment_crosses_triangle(
            o,
            d,
            self.v0,
            self.e1,
            self.e2,
            t_start,
            1.0 - SEGMENT_EPSILON,
        )
    }
}

/// The primitive handed to the `bvh` crate: one triangle's padded box and its index.
#[derive(Debug, Clone)]
struct BoxedTriangle {
    aabb: Aabb<f32, 3>,
    triangle: usize,
    node_index: usize,
}

impl Bounded<f32, 3> for BoxedTriangle {
    fn aabb(&self) -> Aabb<f32, 3> {
        self.aabb
    }
}

impl BHShape<f32, 3> for BoxedTriangle {
    fn set_bh_node_index(&mut self, index: usize) {
        self.node_index = index;
    }

    fn bh_node_index(&self) -> usize {
        self.node_index
    }
}

/// One node of the flattened BVH, in depth-first order: an inner node's first child is the
/// next node, its second child is at `index`; a leaf holds one triangle.
#[derive(Debug, Clone, Copy)]
struct FlatNode {
    lo: Vec3,
    hi: Vec3,
    /// Leaf: the triangle index; inner node: the index of the second child.
    index: u32,
    leaf: bool,
}

/// Flattens the crate's tree below `node` (whose box is `aabb`) into `out`, depth first;
/// returns the depth of the subtree (a leaf has depth 0).
fn flatten(
    bvh: &Bvh<f32, 3>,
    shapes: &[BoxedTriangle],
    node: usize,
    aabb: &Aabb<f32, 3>,
    out: &mut Vec<FlatNode>,
) -> usize {
    let lo = Vec3::new(aabb.min.x, aabb.min.y, aabb.min.z);
    let hi = Vec3::new(aabb.max.x, aabb.max.y, aabb.max.z);
    let at = out.len();
    match &bvh.nodes[node] {
        BvhNode::Leaf { shape_index, .. } => {
            let index = shapes[*shape_index].triangle as u32;
            out.push(FlatNode {
                lo,
                hi,
                index,
                leaf: true,
            });
            0
        }
        BvhNode::Node {
            child_l_index,
            child_l_aabb,
            child_r_index,
            child_r_aabb,
            ..
        } => {
            out.push(FlatNode {
                lo,
                hi,
                index: 0,
                leaf: false,
            });
            let left = flatten(bvh, shapes, *child_l_index, child_l_aabb, out);
            out[at].index = out.len() as u32;
            let right = flatten(bvh, shapes, *child_r_index, child_r_aabb, out);
            1 + left.max(right)
        }
    }
}

/// The convex hull of a ray origin and a light quadrilateral, widened by the padding
/// (module doc, "Acceleration"): its bounding box and its five face planes `n·x ≤ d`
/// (unit `n`): four through the origin and a quadrilateral edge, one through the
/// quadrilateral.
struct Shaft {
    lo: DVec3,
    hi: DVec3,
    planes: [(DVec3, f64); 5],
}

impl Shaft {
    /// The shaft from `o` to `quad`, or `None` when it is degenerate (the origin in the plane
    /// of the quadrilateral or on the line of one of its edges).
    fn new(o: DVec3, quad: &[DVec3; 4], pad: f64) -> Option<Self> {
        let centroid = (quad[0] + quad[1] + quad[2] + quad[3]) * 0.25;
        let inner = (centroid + o) * 0.5;
        let plane = |a: DVec3, b: DVec3, c: DVec3| -> Option<(DVec3, f64)> {
            let n = (b - a).cross(c - a).try_normalize()?;
            // Orient the plane so that a point strictly inside the hull is inside it.
            let n = if n.dot(inner - a) > 0.0 { -n } else { n };
            let d = n.dot(a);
            (n.dot(inner) < d).then_some((n, d + pad))
        };
        let mut planes = [(DVec3::ZERO, 0.0); 5];
        for i in 0..4 {
            planes[i] = plane(o, quad[i], quad[(i + 1) % 4])?;
        }
        planes[4] = plane(quad[0], quad[1], quad[3])?;
        let lo = quad.iter().fold(o, |m, q| m.min(*q)) - pad;
        let hi = quad.iter().fold(o, |m, q| m.max(*q)) + pad;
        Some(Self { lo, hi, planes })
    }

    /// Whether the box `[lo, hi]` may meet the shaft: false when a face plane of the shaft or
    /// of the shaft's bounding box separates them (then they are disjoint).
    #[inline]
    fn may_meet(&self, lo: Vec3, hi: Vec3) -> bool {
        let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
        if lo.cmpgt(self.hi).any() || hi.cmplt(self.lo).any() {
            return false;
        }
        self.planes
            .iter()
            .all(|&(n, d)| n.dot(DVec3::select(n.cmpge(DVec3::ZERO), lo, hi)) <= d)
    }
}

/// The plane of a light quadrilateral `c ± U ± V` with coordinates `(a, b)`, `x = c + a·U +
/// b·V` (the quadrilateral is `[-1,1]²`), computed with the dual basis so that `U` and `V`
/// need not be orthogonal.
struct LightPlane {
    center: DVec3,
    normal: DVec3,
    dual_u: DVec3,
    dual_v: DVec3,
    /// The binning margin in plane coordinates: [`BIN_MARGIN`] × the scene scale, mapped
    /// through the dual basis.
    margin: f64,
}

impl LightPlane {
    /// The plane of `quad` (corners `c−U−V, c+U−V, c+U+V, c−U+V`), `None` if it is degenerate;
    /// `scale` is the scene's size plus its distance from the origin.
    fn new(quad: &[DVec3; 4], scale: f64) -> Option<Self> {
        let center = (quad[0] + quad[1] + quad[2] + quad[3]) * 0.25;
        let u = (quad[1] - quad[0]) * 0.5;
        let v = (quad[3] - quad[0]) * 0.5;
        let normal = u.cross(v).try_normalize()?;
        let (uu, uv, vv) = (u.dot(u), u.dot(v), v.dot(v));
        let det = uu * vv - uv * uv;
        if det.is_nan() || det <= 0.0 {
            return None;
        }
        let dual_u = (vv * u - uv * v) / det;
        let dual_v = (uu * v - uv * u) / det;
        let margin = BIN_MARGIN * scale * dual_u.length().max(dual_v.length());
        Some(Self {
            center,
            normal,
            dual_u,
            dual_v,
            margin,
        })
    }

    /// `(a, b)` of a point of the plane.
    #[inline]
    fn coords(&self, x: DVec3) -> (f64, f64) {
        let d = x - self.center;
        (d.dot(self.dual_u), d.dot(self.dual_v))
    }
}

/// Cells per side of the light-plane grid the candidate triangles are binned into (module
/// doc, "Acceleration"); at most the sample grid's side.
const GRID: usize = 16;

/// Binning margin in world units relative to the scene scale (module doc, "Acceleration"):
/// projecting a vertex near the clip depth `ε·h/2` magnifies its f64 rounding (≈ 1e-16 of
/// the scale) by up to `2/ε = 2e6`; 1e-7 leaves a factor of more than 100 to spare.
const BIN_MARGIN: f64 = 1e-7;

/// Per-thread buffers reused from receiver to receiver (their contents never outlive one
/// receiver, so the results do not depend on which thread ran which pixel).
#[derive(Default)]
struct Scratch {
    stack: Vec<u32>,
    candidates: Vec<u32>,
    /// Per binned candidate: triangle index and its cell range `i0, i1, j0, j1`.
    binned: Vec<(u32, [u16; 4])>,
    /// Triangles whose projection covers the whole grid (tested for every sample).
    global: Vec<u32>,
    /// Compressed cell lists: cell `c` holds `cell_items[cell_start[c]..cell_start[c + 1]]`.
    cell_start: Vec<u32>,
    cell_items: Vec<u32>,
    /// Per sample: lit or not.
    lit: Vec<bool>,
    /// The nodes still to visit of [`ShadowRayCaster::trace_packets`], with their lanes.
    packet_stack: Vec<(u32, PacketMask)>,
}

/// The grid cell of light-plane coordinate `x` on a grid of `g` cells over `[-1, 1]`
/// (clamped, monotone in `x`).
#[inline]
fn cell_of(x: f64, g: usize) -> usize {
    // `as usize` truncates (= floor for the non-negative values that reach it), saturates
    // and maps NaN to 0, all without a libm call.
    let c = (x + 1.0) * 0.5 * g as f64;
    if c > 0.0 {
        (c as usize).min(g - 1)
    } else {
        0
    }
}

/// Casts shadow rays against all triangles of a scene; builds the BVH once per scene
/// (module doc, "Acceleration").
pub struct ShadowRayCaster {
    triangles: Vec<Triangle>,
    nodes: Vec<FlatNode>,
    /// Depth of the tree (a single leaf has depth 0).
    depth: usize,
    /// `δ` of the module doc: the ray-origin offset in world units.
    origin_offset: f64,
    /// `D` of the module doc: the diagonal of the meshes' bounds.
    mesh_diagonal: f64,
    /// The box and shaft padding in world units.
    pad: f64,
    /// The scene's diagonal plus its largest coordinate magnitude (scale of rounding errors).
    scale: f64,
}

impl ShadowRayCaster {
    /// Collects the triangles of every mesh of `scene` that casts shadows (not the
    /// receiver-only ones) and builds the BVH over them.
    pub fn new(scene: &Scene) -> Self {
        let (mesh_lo, mesh_hi) = scene.mesh_bounds();
        // δ uses the diagonal of the meshes' bounds as an f32 length.
        let mesh_diagonal = f64::from((mesh_hi - mesh_lo).length());
        let mesh_diagonal = if mesh_diagonal.is_finite() && mesh_diagonal > 0.0 {
            mesh_diagonal
        } else {
            1.0
        };
        let mesh_magnitude = f64::from(mesh_lo.abs().max(mesh_hi.abs()).max_element());
        // Padding and margins use the bounds of meshes and the whole light.
        let (mut lo, mut hi) = (mesh_lo.as_dvec3(), mesh_hi.as_dvec3());
        for l in &scene.lights {
            lo = lo.min(l.center.as_dvec3());
            hi = hi.max(l.center.as_dvec3());
        }
        for q in sampling::bounding_quad(scene.light(), scene.light().center)
            .into_iter()
            .flatten()
        {
            lo = lo.min(q);
            hi = hi.max(q);
        }
        let diagonal = (hi - lo).length();
        let diagonal = if diagonal.is_finite() && diagonal > 0.0 {
            diagonal
        } else {
            1.0
        };
        let magnitude = lo.abs().max(hi.abs()).max_element();
        let pad = BOX_PADDING * diagonal + 4.0 * f64::from(f32::EPSILON) * magnitude;
        let mut triangles = Vec::new();
        let mut shapes = Vec::new();
        // Receiver-only meshes cast no shadow here either (methods stay comparable).
        for mesh in scene.meshes.iter().filter(|m| !m.receiver_only) {
            for tri in &mesh.triangles {
                let [a, b, c] = tri.map(|i| mesh.positions[i as usize].as_dvec3());
                // f32 rounding moves the box by half an ulp, far less than `pad`.
                let lo = (a.min(b).min(c) - pad).as_vec3();
                let hi = (a.max(b).max(c) + pad).as_vec3();
                shapes.push(BoxedTriangle {
                    // bvh's points are nalgebra's; built from arrays so that this crate
                    // does not name nalgebra (bvh 0.10 depends on it regardless).
                    aabb: Aabb::with_bounds(lo.to_array().into(), hi.to_array().into()),
                    triangle: triangles.len(),
                    node_index: 0,
                });
                triangles.push(Triangle {
                    v0: a,
                    e1: b - a,
                    e2: c - a,
                });
            }
        }
        let mut nodes = Vec::with_capacity(2 * shapes.len());
        let mut depth = 0;
        if !shapes.is_empty() {
            let root_box = shapes.iter().fold(Aabb::empty(), |b, s| b.join(&s.aabb));
            let bvh = Bvh::build_par(&mut shapes);
            depth = flatten(&bvh, &shapes, 0, &root_box, &mut nodes);
        }
        Self {
            triangles,
            nodes,
            depth,
            origin_offset: ORIGIN_OFFSET * mesh_diagonal
                + ORIGIN_OFFSET_ULPS * f64::from(f32::EPSILON) * mesh_magnitude,
            mesh_diagonal,
            pad,
            scale: diagonal + magnitude,
        }
    }

    /// The start `ε·min(1, D/L)` of the blocking interval of the segment `d` of length `L`
    /// (module doc, "Shadow rays").
    #[inline]
    fn segment_start(&self, d: DVec3) -> f64 {
        SEGMENT_EPSILON * (self.mesh_diagonal / d.length()).min(1.0)
    }

    /// Number of triangles the caster tests against.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Fraction of the light visible from `r` (module doc, "The visibility of one receiver"):
    /// per RGB channel for textured lights, equal channels for every other light.
    ///
    /// # Panics
    ///
    /// If `settings.samples` is not a perfect square (checked by [`RaycastSettings::validate`]
    /// when the options are parsed).
    pub fn visibility(&self, light: &Light, r: &Receiver, settings: &RaycastSettings) -> [f32; 3] {
        let samples = light_samples(light, r.point, settings);
        let quad = sampling::bounding_quad(light, r.point);
        self.visibility_of_samples(r, &samples, quad.as_ref(), &mut Scratch::default())
    }

    /// The visibility of `r` for an explicit sample set contained in `quad` (shared by
    /// [`Self::visibility`] and [`raycast_visibility`], which computes the sample set once
    /// when it does not depend on the receiver). `quad = None` traces every ray through the
    /// whole tree.
    fn visibility_of_samples(
        &self,
        r: &Receiver,
        samples: &[LightSample],
        quad: Option<&[DVec3; 4]>,
        scratch: &mut Scratch,
    ) -> [f32; 3] {
        let origin = r.point.as_dvec3() + self.origin_offset * r.normal.as_dvec3();
        scratch.lit.clear();
        scratch.lit.resize(samples.len(), true);
        // Below the threshold, or where the shaft does not apply, each ray through the tree.
        let binned = |scratch: &mut Scratch| {
            samples.len() >= BINNED_MIN_SAMPLES && self.trace_binned(origin, samples, quad, scratch)
        };
        if !self.nodes.is_empty() && !binned(scratch) {
            if samples.len() >= PACKET_MIN_SAMPLES {
                self.trace_packets(origin, samples, scratch);
            } else {
                self.trace_each(origin, samples, scratch);
            }
        }
        // The receiver's own surface hides every sample at or below its tangent plane (module
        // doc, "Self-occlusion").
        let (p, n) = (r.point.as_dvec3(), r.normal.as_dvec3());
        for (s, lit) in samples.iter().zip(scratch.lit.iter_mut()) {
            if n.dot(s.position.as_dvec3() - p) <= 0.0 {
                *lit = false;
            }
        }
        let mut visible = [0.0f64; 3];
        let mut total = [0.0f64; 3];
        for (s, &lit) in samples.iter().zip(&scratch.lit) {
            for c in 0..3 {
                let w = f64::from(s.weight[c]);
                total[c] += w;
                if lit {
                    visible[c] += w;
                }
            }
        }
        std::array::from_fn(|c| {
            if total[c] > 0.0 {
                (visible[c] / total[c]) as f32
            } else {
                0.0
            }
        })
    }

    /// The receiver's rays through the whole tree in packets of [`PACKET`] (module doc,
    /// "Acceleration", 5): each node's box is tested against every live ray of the packet
    /// at once, the same slab test as [`Self::blocker`] lane by lane, and a ray leaves the
    /// packet when a triangle blocks it.
    fn trace_packets(&self, origin: DVec3, samples: &[LightSample], scratch: &mut Scratch) {
        for (k, chunk) in samples.chunks(PACKET).enumerate() {
            let mut rays = RayPacket {
                origin,
                o: origin.as_vec3(),
                inv: [[Vec4::ZERO; GROUPS]; 3],
                d: [DVec3::ZERO; PACKET],
                t_start: [0.0; PACKET],
                live: 0,
                groups: chunk.len().div_ceil(4),
                ascending: [None; 3],
            };
            let mut signs: [Option<bool>; 3] = [None; 3];
            for (i, s) in chunk.iter().enumerate() {
                let d = s.position.as_dvec3() - origin;
                // A zero segment is never blocked ([`Self::blocker`]): it stays out.
                if d == DVec3::ZERO {
                    continue;
                }
                let inv = d.as_vec3().recip();
                let (g, lane) = (i / 4, i % 4);
                rays.inv[0][g][lane] = inv.x;
                rays.inv[1][g][lane] = inv.y;
                rays.inv[2][g][lane] = inv.z;
                rays.d[i] = d;
                rays.t_start[i] = self.segment_start(d);
                for (axis, v) in inv.to_array().into_iter().enumerate() {
                    let sign = (v.is_finite() && v != 0.0).then_some(v > 0.0);
                    signs[axis] = match signs[axis] {
                        _ if rays.live == 0 => sign,
                        same if same == sign => same,
                        _ => None,
                    };
                }
                rays.live |= 1 << i;
            }
            rays.ascending = signs;
            let blocked = self.packet_blocked(&rays, &mut scratch.packet_stack);
            for (i, lit) in scratch.lit[k * PACKET..][..chunk.len()]
                .iter_mut()
                .enumerate()
            {
                if blocked & (1 << i) != 0 {
                    *lit = false;
                }
            }
        }
    }

    /// The lanes of `rays.live` that some triangle blocks: depth-first traversal of the whole
    /// tree carrying, per node, the lanes whose segment may meet its box.
    fn packet_blocked(&self, rays: &RayPacket, stack: &mut Vec<(u32, PacketMask)>) -> PacketMask {
        let mut blocked: PacketMask = 0;
        stack.clear();
        stack.push((0, rays.live));
        while let Some((at, lanes)) = stack.pop() {
            let lanes = lanes & !blocked;
            if lanes == 0 {
                continue;
            }
            let node = &self.nodes[at as usize];
            let lanes = lanes & rays.meet(node.lo, node.hi, lanes);
            if lanes == 0 {
                continue;
            }
            if node.leaf {
                let hit = self.lanes_blocked_by(node.index, rays, lanes);
                if hit != 0 {
                    blocked |= hit;
                    if blocked == rays.live {
                        break;
                    }
                }
            } else {
                stack.push((node.index, lanes));
                stack.push((at + 1, lanes));
            }
        }
        blocked
    }

    /// The lanes of `lanes` whose segment triangle `ti` blocks (the exact test).
    #[inline]
    fn lanes_blocked_by(&self, ti: u32, rays: &RayPacket, lanes: PacketMask) -> PacketMask {
        let triangle = &self.triangles[ti as usize];
        let mut hit: PacketMask = 0;
        let mut rest = lanes;
        while rest != 0 {
            let i = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            if triangle.blocks(rays.origin, rays.d[i], rays.t_start[i]) {
                hit |= 1 << i;
            }
        }
        hit
    }

    /// Every ray through the whole tree (point lights, degenerate shafts, and the reference
    /// the binned path is tested against).
    fn trace_each(&self, origin: DVec3, samples: &[LightSample], scratch: &mut Scratch) {
        scratch.stack.resize(self.depth + 2, 0);
        let mut last_blocker: Option<u32> = None;
        for (s, lit) in samples.iter().zip(scratch.lit.iter_mut()) {
            let target = s.position.as_dvec3();
            let d = target - origin;
            let blocks =
                |ti: u32| self.triangles[ti as usize].blocks(origin, d, self.segment_start(d));
            let search = || self.blocker(origin, target, &mut scratch.stack);
            *lit = !blocked_after(&mut last_blocker, blocks, search);
        }
    }

    /// The per-receiver path of the module doc ("Acceleration"): shaft candidates binned by
    /// their projection on the light plane, each ray tested against its cell's triangles.
    /// Returns false (and leaves `scratch.lit` alone) when it does not apply.
    fn trace_binned(
        &self,
        origin: DVec3,
        samples: &[LightSample],
        quad: Option<&[DVec3; 4]>,
        scratch: &mut Scratch,
    ) -> bool {
        let Some(quad) = quad else { return false };
        let (Some(shaft), Some(plane)) = (
            Shaft::new(origin, quad, self.pad),
            LightPlane::new(quad, self.scale),
        ) else {
            return false;
        };
        // Signed distance of the light plane from the origin along the plane normal; every
        // ray point at parameter t lies at t·h.
        let h = plane.normal.dot(plane.center - origin);
        if h.abs() <= self.pad {
            return false;
        }
        let (n, h) = if h > 0.0 {
            (plane.normal, h)
        } else {
            (-plane.normal, -h)
        };
        self.shaft_candidates(&shaft, scratch);
        if scratch.candidates.is_empty() {
            return true;
        }
        let g = GRID.min(samples.len().isqrt()).max(1);
        // A hit at t > ε·min(1, D/L) lies at depth > ε·h·min(1, D/L), and L is at most the
        // distance to the farthest corner of the quad around the samples; half of that keeps
        // rounding on the safe side.
        let longest = quad
            .iter()
            .map(|c| (*c - origin).length())
            .fold(0.0, f64::max);
        let near = 0.5 * SEGMENT_EPSILON * h * (self.mesh_diagonal / longest).min(1.0);
        let far = h * (1.0 + 1e-6) + self.pad;
        scratch.binned.clear();
        scratch.global.clear();
        for &ti in &scratch.candidates {
            let t = &self.triangles[ti as usize];
            let v = [t.v0, t.v0 + t.e1, t.v0 + t.e2];
            let q = v.map(|x| n.dot(x - origin));
            if q.iter().all(|&x| x < near) || q.iter().all(|&x| x > far) {
                continue; // entirely behind the rays' start or beyond the light plane
            }
            // Clip to depth ≥ near (Sutherland–Hodgman, one plane) and project from the
            // origin onto the light plane.
            let (mut a0, mut a1, mut b0, mut b1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
            let mut project = |x: DVec3, qx: f64| {
                let (a, b) = plane.coords(origin + (x - origin) * (h / qx));
                (a0, a1, b0, b1) = (a0.min(a), a1.max(a), b0.min(b), b1.max(b));
            };
            for i in 0..3 {
                let (x, y, qx, qy) = (v[i], v[(i + 1) % 3], q[i], q[(i + 1) % 3]);
                if qx >= near {
                    project(x, qx);
                }
                if (qx >= near) != (qy >= near) {
                    let s = (near - qx) / (qy - qx);
                    project(x + (y - x) * s, near);
                }
            }
            let range = [
                cell_of(a0 - plane.margin, g),
                cell_of(a1 + plane.margin, g),
                cell_of(b0 - plane.margin, g),
                cell_of(b1 + plane.margin, g),
            ];
            if !(a0 <= a1 && b0 <= b1) || range == [0, g - 1, 0, g - 1] {
                scratch.global.push(ti); // NaN-safe: anything odd is tested for every ray
            } else {
                scratch.binned.push((ti, range.map(|x| x as u16)));
            }
        }
        // Compressed cell lists (counting sort by cell, candidates in BVH order).
        let cells = g * g;
        scratch.cell_start.clear();
        scratch.cell_start.resize(cells + 1, 0);
        for (_, [i0, i1, j0, j1]) in &scratch.binned {
            for j in *j0..=*j1 {
                for i in *i0..=*i1 {
                    scratch.cell_start[j as usize * g + i as usize + 1] += 1;
                }
            }
        }
        for c in 0..cells {
            scratch.cell_start[c + 1] += scratch.cell_start[c];
        }
        scratch.cell_items.clear();
        scratch
            .cell_items
            .resize(scratch.cell_start[cells] as usize, 0);
        let mut fill = scratch.cell_start.clone();
        for &(ti, [i0, i1, j0, j1]) in &scratch.binned {
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let c = j as usize * g + i as usize;
                    scratch.cell_items[fill[c] as usize] = ti;
                    fill[c] += 1;
                }
            }
        }
        // Each ray: the plane point it passes through gives its cell.
        let mut last_blocker: Option<u32> = None;
        for (s, lit) in samples.iter().zip(scratch.lit.iter_mut()) {
            let target = s.position.as_dvec3();
            let d = target - origin;
            let qs = n.dot(d);
            if qs.is_nan() || qs <= 0.0 {
                // Cannot happen for a sample on the light plane; trace it fully if it does.
                scratch.stack.resize(self.depth + 2, 0);
                *lit = !self.blocked(origin, target, &mut scratch.stack);
                continue;
            }
            let t_start = self.segment_start(d);
            let (a, b) = plane.coords(origin + d * (h / qs));
            let c = cell_of(b, g) * g + cell_of(a, g);
            let cell = &scratch.cell_items
                [scratch.cell_start[c] as usize..scratch.cell_start[c + 1] as usize];
            let blocks = |ti: u32| self.triangles[ti as usize].blocks(origin, d, t_start);
            let search = || {
                scratch
                    .global
                    .iter()
                    .chain(cell)
                    .copied()
                    .find(|&ti| blocks(ti))
            };
            *lit = !blocked_after(&mut last_blocker, blocks, search);
        }
        true
    }

    /// The triangles in leaves whose boxes may meet `shaft`, in depth-first order.
    fn shaft_candidates(&self, shaft: &Shaft, scratch: &mut Scratch) {
        scratch.candidates.clear();
        scratch.stack.clear();
        scratch.stack.push(0);
        while let Some(at) = scratch.stack.pop() {
            let node = &self.nodes[at as usize];
            if !shaft.may_meet(node.lo, node.hi) {
                continue;
            }
            if node.leaf {
                scratch.candidates.push(node.index);
            } else {
                scratch.stack.push(node.index);
                scratch.stack.push(at + 1);
            }
        }
    }

    /// True when the segment from `origin` to `target` is blocked by any triangle:
    /// depth-first any-hit traversal of the whole tree, boxes clipped to `t ∈ [0, 1]`;
    /// `stack` holds at least the tree's depth + 1 entries.
    fn blocked(&self, origin: DVec3, target: DVec3, stack: &mut [u32]) -> bool {
        self.blocker(origin, target, stack).is_some()
    }

    /// [`ShadowRayCaster::blocked`], naming the first blocking triangle found.
    fn blocker(&self, origin: DVec3, target: DVec3, stack: &mut [u32]) -> Option<u32> {
        let d = target - origin;
        if d == DVec3::ZERO || self.nodes.is_empty() {
            return None;
        }
        let t_start = self.segment_start(d);
        let o = origin.as_vec3();
        let inv = d.as_vec3().recip();
        stack[0] = 0;
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let at = stack[top];
            let node = &self.nodes[at as usize];
            let t0 = (node.lo - o) * inv;
            let t1 = (node.hi - o) * inv;
            // Plain compare-and-select (one `minss`/`maxss` each; `f32::min`/`max` add a NaN
            // check around every one, 20 % of the traversal): a NaN, from a ray parallel to a
            // slab that lies exactly on a padded face (0·∞), may keep or reject the box, and
            // either is right (module doc, "Acceleration").
            let near = max_f32(
                max_f32(min_f32(t0.x, t1.x), min_f32(t0.y, t1.y)),
                max_f32(min_f32(t0.z, t1.z), 0.0),
            );
            let far = min_f32(
                min_f32(max_f32(t0.x, t1.x), max_f32(t0.y, t1.y)),
                min_f32(max_f32(t0.z, t1.z), 1.0),
            );
            if near > far {
                continue;
            }
            if node.leaf {
                if self.triangles[node.index as usize].blocks(origin, d, t_start) {
                    return Some(node.index);
                }
            } else {
                stack[top] = node.index;
                stack[top + 1] = at + 1;
                top += 2;
            }
        }
        None
    }
}

/// Whether a ray is blocked, testing first `last`, the triangle that blocked the receiver's
/// previous ray (module doc, "Acceleration", 4: neighbouring samples are mostly blocked by the
/// same triangle; a ray is blocked if any triangle blocks it, so the order changes no answer),
/// then what `search` finds; `last` becomes this ray's blocker when it has one.
fn blocked_after(
    last: &mut Option<u32>,
    blocks: impl Fn(u32) -> bool,
    search: impl FnOnce() -> Option<u32>,
) -> bool {
    let blocker = match *last {
        Some(ti) if blocks(ti) => Some(ti),
        _ => search(),
    };
    *last = blocker.or(*last);
    blocker.is_some()
}

/// Rays per packet of [`ShadowRayCaster::trace_packets`]: one bit each in a [`PacketMask`].
const PACKET: usize = 16;

/// One bit per lane of a [`RayPacket`].
type PacketMask = u16;

/// SIMD groups of four lanes in a [`RayPacket`].
const GROUPS: usize = PACKET / 4;

/// Up to [`PACKET`] segments from one origin, lane by lane: the f32 inverse direction of the
/// slab test (per axis and four lanes to a [`Vec4`], so that four lanes take one SIMD
/// operation) and the f64 direction and start of the exact triangle test.
struct RayPacket {
    origin: DVec3,
    o: Vec3,
    inv: [[Vec4; GROUPS]; 3],
    d: [DVec3; PACKET],
    t_start: [f64; PACKET],
    /// The lanes that hold a ray.
    live: PacketMask,
    /// The groups that hold a ray (the first ones).
    groups: usize,
    /// Per axis, whether every lane's inverse direction is finite and positive (`Some(true)`)
    /// or finite and negative (`Some(false)`); `None` when the lanes differ ([`slab`]).
    ascending: [Option<bool>; 3],
}

impl RayPacket {
    /// The lanes whose segment `t ∈ [0, 1]` may meet the box `lo..hi`: [`ShadowRayCaster::
    /// blocker`]'s slab test with the same f32 products, four lanes at a time (lanes without
    /// a ray are computed too, and masked by the caller). `Vec4::min`/`max` may treat a NaN
    /// differently from [`min_f32`]/[`max_f32`]; either keeps or rejects a box only where a
    /// ray grazes a padded face exactly, and either is right (module doc, "Acceleration").
    #[inline]
    fn meet(&self, lo: Vec3, hi: Vec3, lanes: PacketMask) -> PacketMask {
        let (lo, hi) = (lo - self.o, hi - self.o);
        let mut missed = 0u32;
        for g in (0..self.groups).filter(|g| (lanes >> (4 * g)) & 0xF != 0) {
            let (x_in, x_out) = slab(self.inv[0][g], lo.x, hi.x, self.ascending[0]);
            let (y_in, y_out) = slab(self.inv[1][g], lo.y, hi.y, self.ascending[1]);
            let (z_in, z_out) = slab(self.inv[2][g], lo.z, hi.z, self.ascending[2]);
            let near = x_in.max(y_in).max(z_in.max(Vec4::ZERO));
            let far = x_out.min(y_out).min(z_out.min(Vec4::ONE));
            missed |= near.cmpgt(far).bitmask() << (4 * g);
        }
        !(missed as PacketMask)
    }
}

/// The parameters at which four lanes' segments enter and leave the slab `lo..hi` of one
/// axis (relative to the origin), from their inverse directions `inv`. With one finite sign
/// for every lane (`ascending`), the entry face is known and the two products are the
/// entry and exit already — the same values `min`/`max` give (a product is monotone in the
/// face, and so is its f32 rounding), half the operations; otherwise `min`/`max` sort them.
#[inline]
fn slab(inv: Vec4, lo: f32, hi: f32, ascending: Option<bool>) -> (Vec4, Vec4) {
    match ascending {
        Some(true) => (inv * lo, inv * hi),
        Some(false) => (inv * hi, inv * lo),
        None => {
            let (a, b) = (inv * lo, inv * hi);
            (a.min(b), a.max(b))
        }
    }
}

/// `a < b ? a : b` (the second operand when either is NaN): one `minss`.
#[inline]
fn min_f32(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

/// `a > b ? a : b` (the second operand when either is NaN): one `maxss`.
#[inline]
fn max_f32(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// The jittered samples of `light` seen from `toward`, panicking on an invalid count.
fn light_samples(light: &Light, toward: Vec3, settings: &RaycastSettings) -> Vec<LightSample> {
    sampling::stratified(
        light,
        settings.samples,
        Pattern::Jittered {
            seed: settings.seed,
        },
        toward,
    )
    .unwrap_or_else(|e| panic!("raycast: {e}"))
}

/// The ray-cast ground truth for one frame: per pixel (row-major, row 0 at the top) the
/// visibility of the scene's light from that pixel's receiver; `None` (background) gives
/// visibility 1. Computed in parallel with rayon, bit-identical for any thread count.
/// Returns [`Visibility::Rgb`] for a textured light and [`Visibility::Gray`] otherwise.
///
/// # Panics
///
/// If `settings.samples` is not a perfect square (see [`RaycastSettings::validate`]).
/// With a probe, every shadow ray's verdict and the resolve are recorded at the pixel `probe`
/// watches (the pass's tiling is the image's; [`crate::gpu::probe`]).
pub fn raycast_visibility(
    scene: &Scene,
    receivers: &[Option<Receiver>],
    settings: &RaycastSettings,
    probe: Option<&PassProbe>,
) -> Visibility {
    let watched = probe.map(|p| {
        let [x, y] = p.probe().pixel();
        (p, (y * scene.width + x) as usize)
    });
    let caster = ShadowRayCaster::new(scene);
    let light = scene.light();
    // Only sphere lights seen as the disk facing each receiver depend on the receiver; sample
    // the others once.
    let shared = match (&light.shape, settings.sphere_disk) {
        (LightShape::Sphere { .. }, SphereDisk::FacingReceiver) => None,
        (_, SphereDisk::Facing(toward)) => Some((
            light_samples(light, toward, settings),
            sampling::bounding_quad(light, toward),
        )),
        (_, SphereDisk::FacingReceiver) => Some((
            light_samples(light, light.center, settings),
            sampling::bounding_quad(light, light.center),
        )),
    };
    let pixel = |scratch: &mut Scratch, (i, r): (usize, &Option<Receiver>)| -> [f32; 3] {
        let own;
        let (v, samples) = match (r, &shared) {
            (None, _) => ([1.0; 3], &[][..]),
            (Some(r), Some((samples, quad))) => (
                caster.visibility_of_samples(r, samples, quad.as_ref(), scratch),
                &samples[..],
            ),
            (Some(r), None) => {
                own = light_samples(light, r.point, settings);
                let quad = sampling::bounding_quad(light, r.point);
                let v = caster.visibility_of_samples(r, &own, quad.as_ref(), scratch);
                (v, &own[..])
            }
        };
        if let Some((p, _)) = watched.filter(|(_, w)| *w == i) {
            p.record(|tap| {
                for (k, (s, lit)) in samples.iter().zip(&scratch.lit).enumerate() {
                    let q = s.position;
                    tap.push(
                        tap.event()
                            .sample(k as u32)
                            .primitive(
                                PrimitiveKind::LightSample,
                                k as u32,
                                format!("at ({}, {}, {})", q.x, q.y, q.z),
                                None,
                            )
                            .value("lit", *lit as u8 as f64)
                            .value("weight", f64::from(s.weight[0]))
                            .note(if *lit {
                                "the ray reaches the light"
                            } else {
                                "blocked"
                            }),
                    );
                }
                let channels = match light.shape {
                    LightShape::TexturedRect { .. } => 3,
                    _ => 1,
                };
                tap.event()
                    .resolve(&v[..channels], false)
                    .note(if r.is_none() {
                        "background: lit"
                    } else {
                        "the lit samples' share of the total weight"
                    })
            });
        }
        v
    };
    match light.shape {
        LightShape::TexturedRect { .. } => Visibility::Rgb(
            receivers
                .par_iter()
                .enumerate()
                .map_init(Scratch::default, pixel)
                .collect(),
        ),
        _ => Visibility::Gray(
            receivers
                .par_iter()
                .enumerate()
                .map_init(Scratch::default, |s, r| pixel(s, r)[0])
                .collect(),
        ),
    }
}

/// `raycast`'s pinned golden renders ([`crate::methods::Method::goldens`]).
const GOLDENS: &[crate::methods::Golden] = &[
    crate::methods::Golden::new("cube-of-spheres"),
    crate::methods::Golden::new("single-quad"),
    crate::methods::Golden::new("cylinder"),
    crate::methods::Golden::new("eye-in-shadow"),
    crate::methods::Golden::new("two-lights"),
    crate::methods::Golden::new("scenes/fire.toml").sized(32),
    crate::methods::Golden::new("scenes/hard/eye-in-shadow-sphere.toml"),
    crate::methods::Golden::variant("single-quad", "primary-ray", &[("receiver", "primary-ray")]),
];

/// `raycast`'s configurations in the accuracy–time sweep ([`crate::methods::Method::sweep`]).
const SWEEP: &[crate::methods::OptionPairs] = &[
    &[("samples", "4")],
    &[("samples", "16")],
    &[("samples", "64")],
    &[("samples", "256")],
];

/// `raycast` in the registry ([`super::ALL`]).
pub const METHOD: super::Method = super::Method {
    name: "raycast",
    paper: "reference: shadow rays per pixel",
    // Shadow rays sample any light shape.
    supports: |_| true,
    lights: super::SeveralLights::PerLight,
    options: super::OptionTableSpec::of::<RaycastOptions>(),
    // Measured again by `experiment cost-growth` (2026-12-07): 120 bytes a pixel between 1024²
    // and 2048² with the 32 every method keeps, so 88 of its own; it was 72, below the peak at
    // 2048² (501.5 MiB against an estimate of 491.5).
    bytes_per_pixel: 104,
    bytes_per_triangle: 608,
    default_run: super::DefaultRun::EveryScene,
    sums_per_silhouette_edge: false,
    table_note: |_| None,
    check: |frame| raycast_options(frame).map(drop),
    run,
    goldens: GOLDENS,
    sweep: SWEEP,
    precision: crate::methods::precision_spec::PrecisionSpec::NO_SHADER_ARITHMETIC,
};

/// `raycast` (the ground truth by definition): per pixel, the fraction of the light visible
/// from the receiver point, with `samples` jittered stratified samples (default 1024, a perfect
/// square) and `seed`. A sphere light is the disk facing each receiver (`sphere =
/// facing-receiver`, the papers' definition) or, with `sphere = fixed-disk`, `nsample`'s one
/// disk facing the center of the bounds of the meshes within the light's influence, so the two references can be compared on one
/// definition. `receiver = "depth-buffer"` (default) uses the depth-buffer point the
/// rasterized methods see; `"primary-ray"` the exact hit of the ray through the pixel center
/// with the visible triangle's plane.
fn run(frame: &Frame) -> Result<MethodOutput, InputError> {
    // The frame's scene pass writes the depth buffer whatever the receivers are read from.
    let mut rec = PassRecorder::new(frame, "raycast");
    let scene = frame.scene;
    let (settings, receiver) = raycast_options(frame)?;
    let visibility = rec.pass("raycast", |pass| {
        let primary;
        let receivers = if receiver == ReceiverPoint::PrimaryRay {
            primary = frame.primary_ray_receivers();
            &primary[..]
        } else {
            frame.receivers()
        };
        raycast_visibility(scene, receivers, &settings, pass.probe().as_ref())
    });
    let snapped = frame.snapped_receivers();
    if snapped > 0 && receiver == ReceiverPoint::DepthBuffer {
        rec.warn(format!(
            "{snapped} pixels: the depth buffer cannot hold the surface there (a near plane too \
             close for the depth format?); their receivers, for every method, are the exact \
             hits of the pixel rays with the visible triangles"
        ));
    }
    Ok(rec.finish(
        visibility,
        serde_json::json!({
            "samples": settings.samples,
            "seed": settings.seed,
            "pattern": "jittered",
            "receiver": receiver.written(),
            "sphere": match settings.sphere_disk {
                SphereDisk::FacingReceiver => "the disk facing each receiver".to_string(),
                SphereDisk::Facing(p) => format!("one disk facing ({}, {}, {})", p.x, p.y, p.z),
            },
        }),
    ))
}

/// The reference's own sampling noise (issue 15: the "% > 1/255" column is dominated by it for
/// exact methods): `raycast` evaluated again with the next seed (`seed + 1`, every other
/// setting the same) and compared with `reference`, its run with `seed`. Only pixels that can
/// differ are evaluated again — those whose 3×3 neighbourhood holds a reference value strictly
/// between 0 and 1 (a penumbra and its one-pixel border); elsewhere every sample of the run
/// saw the light, or none did, and the second run is taken to agree (so the result is a lower
/// bound, and costs a fraction of the reference's time). Several lights are averaged like the
/// reference ([`super::light_average`]).
pub fn reference_noise_floor(
    frame: &Frame,
    reference: &Visibility,
) -> Result<crate::metrics::ErrorStats, InputError> {
    let (w, h) = (frame.scene.width as usize, frame.scene.height as usize);
    let fractional = |i: usize| reference.rgb(i).iter().any(|&v| v > 0.0 && v < 1.0);
    let again: Vec<bool> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            (y.saturating_sub(1)..(y + 2).min(h))
                .any(|yy| (x.saturating_sub(1)..(x + 2).min(w)).any(|xx| fractional(yy * w + xx)))
        })
        .collect();
    let second = raycast_where(frame, &again, 1)?;
    let merged = match (reference, &second) {
        (Visibility::Gray(r), Visibility::Gray(s)) => Visibility::Gray(
            (0..r.len())
                .map(|i| if again[i] { s[i] } else { r[i] })
                .collect(),
        ),
        _ => Visibility::Rgb(
            (0..reference.len())
                .map(|i| {
                    if again[i] {
                        second.rgb(i)
                    } else {
                        reference.rgb(i)
                    }
                })
                .collect(),
        ),
    };
    Ok(crate::metrics::compare(&merged, reference))
}

option_names! {
    /// How `raycast` sees a sphere light (`[options.raycast] sphere`).
    pub enum SphereAs {
        /// The disk through the center facing each receiver (the papers' definition).
        FacingReceiver = "facing-receiver",
        /// `nsample`'s one disk, facing the center of the bounds of the meshes within the light's influence.
        FixedDisk = "fixed-disk",
    }
}

option_names! {
    /// Which point of a pixel `raycast` computes the visibility of (`[options.raycast] receiver`).
    pub enum ReceiverPoint {
        /// The pixel center un-projected at its stored depth, the point the rasterized methods see.
        DepthBuffer = "depth-buffer",
        /// The exact hit of the ray through the pixel center with the visible triangle's plane.
        PrimaryRay = "primary-ray",
    }
}

option_table! {
    /// `[options.raycast]`: the reference's samples and definitions.
    pub struct RaycastOptions["raycast"] {
        /// light samples per pixel, jittered in √n×√n strata (a perfect square)
        samples: u32 [1..=65536] = DEFAULT_SAMPLES;
        /// seed of the jitter
        seed: u64 [0..=u64::MAX >> 1] = 0;
        /// the pixel's point: the depth buffer's (what the rasterized methods see) or the pixel ray's exact hit
        receiver: ReceiverPoint = ReceiverPoint::DepthBuffer;
        /// a sphere light as the disk facing each receiver (the papers'), or as nsample's one disk facing the center of the bounds of the meshes within the light's influence
        sphere: SphereAs = SphereAs::FacingReceiver;
    }
}

/// `raycast` with its options but the seed advanced by `seed_offset`, evaluated only at the
/// pixels where `mask` (row-major) is true (1 elsewhere); several lights averaged like the
/// reference ([`super::light_average`]).
pub fn raycast_where(
    frame: &Frame,
    mask: &[bool],
    seed_offset: u64,
) -> Result<Visibility, InputError> {
    let one_light = |f: &Frame| -> Result<Visibility, InputError> {
        let (mut settings, receiver) = raycast_options(f)?;
        settings.seed = settings.seed.wrapping_add(seed_offset);
        let all = if receiver == ReceiverPoint::PrimaryRay {
            f.primary_ray_receivers()
        } else {
            f.receivers().to_vec()
        };
        let some: Vec<_> = all
            .iter()
            .zip(mask)
            .map(|(r, &a)| r.filter(|_| a))
            .collect();
        Ok(raycast_visibility(f.scene, &some, &settings, None))
    };
    if frame.scene.is_multi_light() {
        let mut per_light = Vec::new();
        for k in 0..frame.scene.lights.len() {
            let scene = frame.scene.with_only_light(k);
            per_light.push(one_light(&frame.lit_by(&scene))?);
        }
        Ok(super::light_average::average(per_light.iter()))
    } else {
        one_light(frame)
    }
}

/// The light samples per pixel of the reference (`[options.raycast]`'s `samples`).
pub fn reference_samples(frame: &Frame) -> Result<u32, InputError> {
    Ok(raycast_options(frame)?.0.samples)
}

/// Read and check `[options.raycast]` of `frame`'s scene: the settings and the receiver
/// choice (`sphere = fixed-disk` faces `nsample`'s disk, [`super::nsample::sphere_disk_target`]).
fn raycast_options(frame: &Frame) -> Result<(RaycastSettings, ReceiverPoint), InputError> {
    let scene = frame.scene;
    let o = RaycastOptions::read(scene)?;
    let settings = RaycastSettings {
        samples: o.samples,
        seed: o.seed,
        sphere_disk: match o.sphere {
            SphereAs::FixedDisk => SphereDisk::Facing(super::nsample::sphere_disk_target(frame)),
            SphereAs::FacingReceiver => SphereDisk::FacingReceiver,
        },
    };
    settings
        .validate()
        .map_err(|e| scene.option_error(RaycastOptions::NAME, "samples", e))?;
    Ok((settings, o.receiver))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Camera, Mesh, RgbTexture};

    /// A closed axis-aligned box, 12 outward counter-clockwise triangles.
    fn cube(name: &str, lo: Vec3, hi: Vec3) -> Mesh {
        let positions = (0..8)
            .map(|i| {
                Vec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                )
            })
            .collect();
        let quads = [
            [0, 4, 6, 2], // -x
            [1, 3, 7, 5], // +x
            [0, 1, 5, 4], // -y
            [2, 6, 7, 3], // +y
            [0, 2, 3, 1], // -z
            [4, 5, 7, 6], // +z
        ];
        let triangles = quads
            .iter()
            .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
            .collect();
        Mesh {
            name: name.into(),
            positions,
            triangles,
            color: [0.8; 3],
            receiver_only: false,
            repairs: Default::default(),
        }
    }

    /// A closed UV sphere with `stacks × slices` quads (poles as triangle fans).
    fn sphere(name: &str, center: Vec3, radius: f32, stacks: u32, slices: u32) -> Mesh {
        let mut positions = vec![center + Vec3::Y * radius];
        for i in 1..stacks {
            let theta = std::f32::consts::PI * i as f32 / stacks as f32;
            for j in 0..slices {
                let phi = std::f32::consts::TAU * j as f32 / slices as f32;
                let dir = Vec3::new(
                    libm::sinf(theta) * libm::cosf(phi),
                    libm::cosf(theta),
                    libm::sinf(theta) * libm::sinf(phi),
                );
                positions.push(center + dir * radius);
            }
        }
        positions.push(center - Vec3::Y * radius);
        let bottom = positions.len() as u32 - 1;
        let ring = |i: u32, j: u32| 1 + (i - 1) * slices + j % slices;
        let mut triangles = Vec::new();
        for j in 0..slices {
            triangles.push([0, ring(1, j + 1), ring(1, j)]);
            triangles.push([bottom, ring(stacks - 1, j), ring(stacks - 1, j + 1)]);
        }
        for i in 1..stacks - 1 {
            for j in 0..slices {
                let (a, b, c, d) = (
                    ring(i, j),
                    ring(i, j + 1),
                    ring(i + 1, j + 1),
                    ring(i + 1, j),
                );
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            }
        }
        Mesh {
            name: name.into(),
            positions,
            triangles,
            color: [0.8; 3],
            receiver_only: false,
            repairs: Default::default(),
        }
    }

    fn scene(light: Light, meshes: Vec<Mesh>) -> Scene {
        Scene {
            source: "test".into(),
            width: 1,
            height: 1,
            camera: Camera {
                eye: DVec3::new(0.0, 3.0, 8.0),
                target: DVec3::ZERO,
                up: DVec3::Y,
                vfov_deg: 45.0,
                near: None,
            },
            lights: vec![light],
            meshes,
            methods: None,
            options: Default::default(),
            cli_options: Default::default(),
            ambient: 0.1,
        }
    }

    /// A 2×2 rect light at height 4 facing down, a floor with its top at y = 0.
    fn rect_light() -> Light {
        Light {
            center: Vec3::new(0.0, 4.0, 0.0),
            shape: LightShape::Rect {
                u: Vec3::X,
                v: Vec3::Z,
            },
        }
    }

    fn floor() -> Mesh {
        cube(
            "floor",
            Vec3::new(-5.0, -1.0, -5.0),
            Vec3::new(5.0, 0.0, 5.0),
        )
    }

    const ON_FLOOR: Receiver = Receiver {
        point: Vec3::ZERO,
        normal: Vec3::Y,
    };

    #[test]
    fn fully_lit_point_sees_all_of_the_light() {
        let s = scene(
            rect_light(),
            vec![floor(), cube("aside", Vec3::splat(2.0), Vec3::splat(3.0))],
        );
        let caster = ShadowRayCaster::new(&s);
        assert_eq!(caster.triangle_count(), 24);
        let v = caster.visibility(s.light(), &ON_FLOOR, &RaycastSettings::default());
        assert_eq!(v, [1.0; 3]);
    }

    #[test]
    fn point_under_a_big_occluder_is_dark() {
        let s = scene(
            rect_light(),
            vec![
                floor(),
                cube("roof", Vec3::new(-3.0, 2.0, -3.0), Vec3::new(3.0, 2.5, 3.0)),
            ],
        );
        let v =
            ShadowRayCaster::new(&s).visibility(s.light(), &ON_FLOOR, &RaycastSettings::default());
        assert_eq!(v, [0.0; 3]);
        // Same for a disk, a sphere and a point light.
        for shape in [
            LightShape::Disk {
                radius: 1.0,
                normal: -Vec3::Y,
            },
            LightShape::Sphere { radius: 1.0 },
            LightShape::Point,
        ] {
            let light = Light {
                center: Vec3::new(0.0, 4.0, 0.0),
                shape,
            };
            let s = scene(light, s.meshes.clone());
            let v = ShadowRayCaster::new(&s).visibility(
                s.light(),
                &ON_FLOOR,
                &RaycastSettings::default(),
            );
            assert_eq!(v, [0.0; 3], "{:?}", s.light().shape);
        }
    }

    #[test]
    fn partial_occluder_within_the_stratification_bound() {
        // A thin slab at y ∈ [2, 2.001] covering x ≥ 0.15 seen from the origin hides the part
        // s ≥ 0.3 of the light (s along u): visible fraction 0.65. A straight edge along v
        // crosses one column of k strata, so the jittered estimate errs by at most k/n = 1/k;
        // the slab's thickness moves the edge by 0.15·(1 − 2/2.001)·2 < 2e-4.
        let slab = cube(
            "slab",
            Vec3::new(0.15, 2.0, -5.0),
            Vec3::new(5.0, 2.001, 5.0),
        );
        let s = scene(rect_light(), vec![floor(), slab]);
        let caster = ShadowRayCaster::new(&s);
        for (samples, seed) in [(1024, 0), (1024, 77), (256, 3)] {
            let settings = RaycastSettings {
                samples,
                seed,
                ..Default::default()
            };
            let v = caster.visibility(s.light(), &ON_FLOOR, &settings);
            let k = f64::from(samples).sqrt();
            assert!(
                (f64::from(v[0]) - 0.65).abs() <= 1.0 / k + 2e-4,
                "{samples}: {v:?}"
            );
            assert!(v[0] == v[1] && v[1] == v[2]);
        }
        // Half of the light (x ≥ 0 ⇒ s ≥ 0): the edge is a stratum boundary, so exactly 0.5.
        let half = cube(
            "half",
            Vec3::new(0.0, 2.0, -5.0),
            Vec3::new(5.0, 2.001, 5.0),
        );
        let s = scene(rect_light(), vec![floor(), half]);
        let v =
            ShadowRayCaster::new(&s).visibility(s.light(), &ON_FLOOR, &RaycastSettings::default());
        assert_eq!(v, [0.5; 3]);
    }

    #[test]
    fn textured_light_per_channel() {
        // Texel columns run along u: the left texel (s < 0) is blue, the right one (s > 0) red.
        let texture = RgbTexture {
            width: 2,
            height: 1,
            texels: vec![[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]],
            source: "test".into(),
        };
        let light = Light {
            center: Vec3::new(0.0, 4.0, 0.0),
            shape: LightShape::TexturedRect {
                u: Vec3::X,
                v: Vec3::Z,
                texture,
            },
        };
        let half = cube(
            "half",
            Vec3::new(0.0, 2.0, -5.0),
            Vec3::new(5.0, 2.001, 5.0),
        );
        let s = scene(light, vec![floor(), half]);
        let v =
            ShadowRayCaster::new(&s).visibility(s.light(), &ON_FLOOR, &RaycastSettings::default());
        // Red is hidden, blue fully visible, green emits nothing (reported as 0).
        assert_eq!(v, [0.0, 0.0, 1.0]);
        let out = raycast_visibility(
            &s,
            &[Some(ON_FLOOR), None],
            &RaycastSettings::default(),
            None,
        );
        assert_eq!(out, Visibility::Rgb(vec![[0.0, 0.0, 1.0], [1.0; 3]]));
    }

    #[test]
    fn frame_is_identical_for_any_thread_count() {
        let meshes = vec![
            floor(),
            sphere("ball", Vec3::new(0.2, 1.5, -0.1), 0.6, 8, 12),
        ];
        for light in [
            rect_light(),
            Light {
                center: Vec3::new(0.0, 4.0, 0.0),
                shape: LightShape::Sphere { radius: 0.8 },
            },
        ] {
            let s = scene(light, meshes.clone());
            let receivers: Vec<Option<Receiver>> = (0..32 * 32)
                .map(|i| {
                    let (x, z) = ((i % 32) as f32 / 8.0 - 2.0, (i / 32) as f32 / 8.0 - 2.0);
                    (i % 7 != 0).then_some(Receiver {
                        point: Vec3::new(x, 0.0, z),
                        normal: Vec3::Y,
                    })
                })
                .collect();
            let settings = RaycastSettings {
                samples: 64,
                seed: 5,
                ..Default::default()
            };
            let run = |threads| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(|| raycast_visibility(&s, &receivers, &settings, None))
            };
            let one = run(1);
            assert_eq!(one, run(3));
            let Visibility::Gray(v) = &one else {
                panic!("gray expected")
            };
            assert!(v.iter().all(|x| (0.0..=1.0).contains(x)));
            assert!(
                v.iter().any(|&x| x < 0.5),
                "the ball should shadow some receivers"
            );
            assert!(
                v.iter().enumerate().all(|(i, &x)| i % 7 != 0 || x == 1.0),
                "background is 1"
            );
        }
    }

    /// Receivers on the floor and on the ball's surface (normals outward), a few per row.
    fn floor_and_ball_receivers(center: Vec3, radius: f32) -> Vec<Receiver> {
        let mut out = Vec::new();
        for i in 0..24 * 24 {
            let (x, z) = ((i % 24) as f32 / 6.0 - 2.0, (i / 24) as f32 / 6.0 - 2.0);
            out.push(Receiver {
                point: Vec3::new(x, 0.0, z),
                normal: Vec3::Y,
            });
        }
        for i in 0..64 {
            let (a, b) = (i as f32 * 0.7, libm::sinf(i as f32 * 0.37));
            let n = Vec3::new(
                libm::cosf(a) * (1.0 - b * b).sqrt(),
                b,
                libm::sinf(a) * (1.0 - b * b).sqrt(),
            );
            out.push(Receiver {
                point: center + n * radius,
                normal: n,
            });
        }
        out
    }

    #[test]
    fn binned_tracing_gives_the_bits_of_tracing_every_ray() {
        let center = Vec3::new(0.2, 1.5, -0.1);
        let meshes = vec![
            floor(),
            sphere("ball", center, 0.6, 8, 12),
            cube("post", Vec3::new(-1.2, 0.0, 0.4), Vec3::new(-0.9, 2.2, 0.7)),
        ];
        let texture = RgbTexture {
            width: 3,
            height: 2,
            texels: vec![
                [1.0, 0.5, 0.0],
                [0.0, 1.0, 0.2],
                [0.3, 0.3, 0.3],
                [0.0, 0.0, 1.0],
                [1.0, 1.0, 1.0],
                [0.5, 0.0, 0.5],
            ],
            source: "test".into(),
        };
        let lights = [
            rect_light(),
            // A skewed, tilted rectangle: u and v are not orthogonal.
            Light {
                center: Vec3::new(0.5, 3.5, 0.2),
                shape: LightShape::Rect {
                    u: Vec3::new(1.0, 0.2, 0.0),
                    v: Vec3::new(0.6, 0.1, 0.9),
                },
            },
            Light {
                center: Vec3::new(-0.3, 3.8, 0.1),
                shape: LightShape::TexturedRect {
                    u: Vec3::X * 0.8,
                    v: Vec3::Z * 1.3,
                    texture,
                },
            },
            Light {
                center: Vec3::new(0.3, 4.0, -0.2),
                shape: LightShape::Disk {
                    radius: 1.2,
                    normal: Vec3::new(0.1, -1.0, 0.2),
                },
            },
            Light {
                center: Vec3::new(0.0, 4.0, 0.0),
                shape: LightShape::Sphere { radius: 0.9 },
            },
        ];
        let mut receivers = floor_and_ball_receivers(center, 0.6);
        // On the post's faces: a vertical wall, lit from above at a grazing angle.
        for i in 0..40 {
            let (y, z) = (0.05 + i as f32 * 0.05, 0.42 + (i % 7) as f32 * 0.04);
            receivers.push(Receiver {
                point: Vec3::new(-0.9, y, z),
                normal: Vec3::X,
            });
            receivers.push(Receiver {
                point: Vec3::new(-1.2, y, z),
                normal: -Vec3::X,
            });
        }
        let settings = RaycastSettings {
            samples: 256,
            seed: 11,
            ..Default::default()
        };
        let mut empty_total = 0;
        for light in lights {
            let s = scene(light, meshes.clone());
            let caster = ShadowRayCaster::new(&s);
            let (mut partial, mut empty, mut binned) = (0, 0, 0);
            for r in &receivers {
                let samples = light_samples(s.light(), r.point, &settings);
                let quad = sampling::bounding_quad(s.light(), r.point).unwrap();
                let o = r.point.as_dvec3() + caster.origin_offset * r.normal.as_dvec3();
                let mut fast = Scratch {
                    lit: vec![true; samples.len()],
                    ..Default::default()
                };
                if !caster.trace_binned(o, &samples, Some(&quad), &mut fast) {
                    continue;
                }
                binned += 1;
                empty += usize::from(fast.candidates.is_empty());
                let mut full = Scratch {
                    lit: vec![true; samples.len()],
                    ..Default::default()
                };
                caster.trace_each(o, &samples, &mut full);
                assert_eq!(fast.lit, full.lit, "{:?} at {:?}", s.light().shape, r.point);
                let lit = full.lit.iter().filter(|&&l| l).count();
                partial += usize::from(lit > 0 && lit < samples.len());
                assert_eq!(
                    caster.visibility(s.light(), r, &settings),
                    caster.visibility_of_samples(r, &samples, None, &mut Scratch::default())
                );
            }
            assert!(
                binned > receivers.len() * 9 / 10,
                "{binned} of {}",
                receivers.len()
            );
            assert!(partial > 20, "the scene should have penumbrae ({partial})");
            empty_total += empty;
        }
        assert!(empty_total > 0, "some shafts should hold no box");
    }

    #[test]
    fn bvh_traversal_agrees_with_testing_every_triangle() {
        let center = Vec3::new(0.2, 1.5, -0.1);
        let s = scene(
            rect_light(),
            vec![floor(), sphere("ball", center, 0.6, 8, 12)],
        );
        let caster = ShadowRayCaster::new(&s);
        let mut stack = vec![0u32; caster.depth + 2];
        let mut blocked = 0;
        for (i, r) in floor_and_ball_receivers(center, 0.6).iter().enumerate() {
            let o = r.point.as_dvec3() + caster.origin_offset * r.normal.as_dvec3();
            for j in 0..16 {
                let (a, b) = (jitter_pair(i, j), jitter_pair(j, i));
                let target = DVec3::new(2.0 * a - 1.0, 4.0, 2.0 * b - 1.0);
                let d = target - o;
                let brute = caster
                    .triangles
                    .iter()
                    .any(|t| t.blocks(o, d, caster.segment_start(d)));
                assert_eq!(caster.blocked(o, target, &mut stack), brute);
                blocked += usize::from(brute);
            }
        }
        assert!(blocked > 100, "{blocked}");
        // Axis-parallel rays along a flat (axis-aligned) face and through shared edges.
        for x in [-0.5, 0.0, 0.25] {
            let o = DVec3::new(x, -0.5, 0.0);
            for target in [
                DVec3::new(x, 0.5, 0.0),
                DVec3::new(x, 0.5, 0.3),
                DVec3::new(5.0, 0.5, 5.0),
            ] {
                let d = target - o;
                let brute = caster
                    .triangles
                    .iter()
                    .any(|t| t.blocks(o, d, caster.segment_start(d)));
                assert!(brute, "{o} → {target} crosses the floor top");
                assert!(caster.blocked(o, target, &mut stack));
            }
        }
    }

    /// The packets give each ray the answer of the exact test against every triangle: rays
    /// of mixed and of one sign per axis, axis-parallel rays (an infinite inverse), a zero
    /// segment, packets of 1 to 16 lanes and one of two chunks.
    #[test]
    fn packets_agree_with_testing_every_triangle() {
        let center = Vec3::new(0.2, 1.5, -0.1);
        let s = scene(
            rect_light(),
            vec![floor(), sphere("ball", center, 0.6, 8, 12)],
        );
        let caster = ShadowRayCaster::new(&s);
        let brute = |o: DVec3, target: DVec3| {
            let d = target - o;
            d != DVec3::ZERO
                && caster
                    .triangles
                    .iter()
                    .any(|t| t.blocks(o, d, caster.segment_start(d)))
        };
        let sample = |position: DVec3| LightSample {
            position: position.as_vec3(),
            weight: [1.0; 3],
        };
        let mut scratch = Scratch::default();
        // The number of blocked rays of the packet, after checking each.
        let mut check = |o: DVec3, samples: &[LightSample]| {
            scratch.lit.clear();
            scratch.lit.resize(samples.len(), true);
            caster.trace_packets(o, samples, &mut scratch);
            for (s, &l) in samples.iter().zip(&scratch.lit) {
                assert_eq!(l, !brute(o, s.position.as_dvec3()), "{o} → {}", s.position);
            }
            scratch.lit.iter().filter(|&&l| !l).count()
        };
        let (mut blocked, mut rays, mut packets) = (0, 0, 0);
        for (i, r) in floor_and_ball_receivers(center, 0.6).iter().enumerate() {
            let o = r.point.as_dvec3() + caster.origin_offset * r.normal.as_dvec3();
            let n = 1 + i % 20; // 1..=20 lanes: partial groups, and two chunks past 16.
            let samples: Vec<LightSample> = (0..n)
                .map(|j| {
                    let (a, b) = (jitter_pair(i, j), jitter_pair(j, i));
                    sample(DVec3::new(2.0 * a - 1.0, 4.0, 2.0 * b - 1.0))
                })
                .collect();
            blocked += check(o, &samples);
            (rays, packets) = (rays + n, packets + 1);
        }
        assert!(
            blocked > 100 && rays - blocked > 100 && packets > 100,
            "{blocked} of {rays} rays blocked, {packets} packets"
        );
        // Axis-parallel rays along and through the floor's top face, a zero segment, and a
        // packet whose x directions are all positive (one sign per axis).
        for x in [-0.5f64, 0.0, 0.25] {
            let o = DVec3::new(x, -0.5, 0.0);
            let targets = [
                DVec3::new(x, 0.5, 0.0),
                DVec3::new(x, 0.5, 0.3),
                DVec3::new(5.0, 0.5, 5.0),
                o,
                DVec3::new(x + 1.0, 0.5, 0.2),
            ];
            // The first three cross the floor's top; the zero segment is never blocked.
            assert!(check(o, &targets.map(sample)) >= 3, "from {o}");
        }
    }

    /// A deterministic value in [0,1) for the pair (i, j).
    fn jitter_pair(i: usize, j: usize) -> f64 {
        ((i * 7919 + j * 104729) % 1000) as f64 / 1000.0
    }

    #[test]
    fn settings_validation() {
        assert!(RaycastSettings::default().validate().is_ok());
        assert!(RaycastSettings {
            samples: 1000,
            ..Default::default()
        }
        .validate()
        .is_err());
        assert!(RaycastSettings {
            samples: 0,
            ..Default::default()
        }
        .validate()
        .is_err());
    }

    /// The performance case of issue 2: 256×256 receivers × 1024 samples on ~3000 triangles.
    /// Run with `cargo test --lib raycast -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn bench_256x256_1024_samples_3000_triangles() {
        // 3×3×3 spheres of 112 triangles (8 stacks × 8 slices) = 3024, plus a 12-triangle floor.
        let mut meshes = vec![cube(
            "floor",
            Vec3::new(-4.0, -1.0, -4.0),
            Vec3::new(4.0, 0.0, 4.0),
        )];
        for i in 0..27 {
            let c = Vec3::new(
                (i % 3) as f32 - 1.0,
                1.0 + (i / 9) as f32,
                ((i / 3) % 3) as f32 - 1.0,
            ) * 0.8;
            meshes.push(sphere(&format!("s{i}"), c, 0.35, 8, 8));
        }
        let light = Light {
            center: Vec3::new(0.5, 5.0, 0.3),
            shape: LightShape::Rect {
                u: Vec3::X * 1.5,
                v: Vec3::Z * 1.5,
            },
        };
        let s = scene(light, meshes);
        let receivers: Vec<Option<Receiver>> = (0..256 * 256)
            .map(|i| {
                let (x, z) = (
                    (i % 256) as f32 / 256.0 * 6.0 - 3.0,
                    (i / 256) as f32 / 256.0 * 6.0 - 3.0,
                );
                Some(Receiver {
                    point: Vec3::new(x, 0.0, z),
                    normal: Vec3::Y,
                })
            })
            .collect();
        let cpu = || -> f64 {
            // utime + stime of the process, in clock ticks (100 Hz) — fields 14 and 15.
            let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
            let rest = stat.rsplit(')').next().unwrap_or("");
            let f: Vec<f64> = rest
                .split_whitespace()
                .map(|x| x.parse().unwrap_or(0.0))
                .collect();
            (f.get(11).unwrap_or(&0.0) + f.get(12).unwrap_or(&0.0)) / 100.0
        };
        let cpu0 = cpu();
        let t = std::time::Instant::now();
        let caster = ShadowRayCaster::new(&s);
        let build = t.elapsed();
        let v = raycast_visibility(&s, &receivers, &RaycastSettings::default(), None);
        let total = t.elapsed();
        let mean: f64 = (0..v.len()).map(|i| f64::from(v.gray(i))).sum::<f64>() / v.len() as f64;
        println!(
            "{} triangles, BVH build {:?}, 256×256×1024 rays in {:?} wall, {:.2} s CPU, on {} threads, mean visibility {mean:.4}",
            caster.triangle_count(),
            build,
            total,
            cpu() - cpu0,
            rayon::current_num_threads()
        );
    }
}
