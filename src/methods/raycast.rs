//! `raycast`: the ground truth by definition (DESIGN.md "Methods"; issue 2, `raycast`).
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
//! receiver's camera-side normal and `δ = `[`ORIGIN_OFFSET`]` × ` the scene diagonal (of
//! [`Scene::bounds`]), so that a receiver read back from a quantized depth buffer does not
//! shadow itself. It is blocked when it hits any triangle at a parameter `t ∈ (ε, 1 − ε)` of
//! the segment `o + t·(s − o)`, `ε = `[`SEGMENT_EPSILON`]` (the far end keeps a light that lies
//! on a surface from being blocked by that surface).
//!
//! Each ray–triangle test is Möller–Trumbore in f64 on the f32 vertices, edges and vertices
//! inclusive (a ray through a shared edge of a closed mesh cannot leak), no back-face culling.
//! It is a pure function of the ray and the triangle, and a ray is blocked if *any* triangle
//! blocks it, so the result does not depend on the order in which the BVH offers candidates.
//!
//! # Acceleration
//!
//! A bounding volume hierarchy is built once per scene by [`ShadowRayCaster::new`] with the
//! `bvh` crate (0.10: binned SAH, one leaf per triangle, deterministic). Its tree is then
//! flattened into a depth-first array of glam boxes ([`FlatNode`]) that shadow rays traverse
//! any-hit with early exit, clipped to the segment `t ∈ [0, 1]`: the crate's own traversal
//! iterator follows the ray to infinity (past the light), goes through nalgebra, and its
//! strict box test (`t_far > t_near`) skips the flat box of an axis-aligned triangle; the
//! flattened traversal is about 4× faster here and has none of those problems.
//!
//! Every triangle's box is padded by [`BOX_PADDING`]` × ` the scene diagonal, which keeps the
//! f32 box tests conservative with respect to the exact f64 triangle test: the f32 rounding
//! of the origin and of the slab parameters moves a box by about 1e-7 of the scene size, far
//! less than the padding, and a ray parallel to a slab that grazes a padded face exactly
//! (where `0·∞` gives NaN and the box is rejected) cannot touch a triangle, which lies at
//! least the padding inside. A box the exact test needs is therefore never culled, and the
//! blocked/unblocked answer of every ray is the exact one.
//!
//! There is no per-pixel shortcut: every sample of every pixel is traced.
//!
//! # Determinism
//!
//! Pixels are independent and computed in parallel with rayon; each pixel's sum runs in sample
//! order, so the output bits do not depend on the number of threads. Every pixel uses the same
//! jitter (a pure function of `seed` and the stratum), hence the error of the estimate is
//! correlated between neighbouring pixels rather than noisy.

use crate::light::sampling::{self, LightSample, Pattern};
use crate::methods::output::Visibility;
use crate::scene::{Light, LightShape, Scene};
use bvh::aabb::{Aabb, Bounded};
use bvh::bounding_hierarchy::BHShape;
use bvh::bvh::{Bvh, BvhNode};
use glam::{DVec3, Vec3};
use nalgebra::Point3;
use rayon::prelude::*;

/// Receiver-origin offset along the normal, relative to the scene diagonal (module doc,
/// "Shadow rays").
pub const ORIGIN_OFFSET: f64 = 1e-4;

/// The open parameter interval `(ε, 1 − ε)` of the shadow segment in which a hit blocks it.
pub const SEGMENT_EPSILON: f64 = 1e-6;

/// Padding of every triangle's BVH box, relative to the scene diagonal (module doc,
/// "Acceleration").
pub const BOX_PADDING: f32 = 1e-5;

/// The default number of light samples per pixel (issue 2: 1024, the papers' reference count,
/// Paper III §5.1).
pub const DEFAULT_SAMPLES: u32 = 1024;

/// A receiver point seen at one pixel: the point whose light visibility is wanted, and its
/// surface normal (unit, facing the camera side). By default the rasterized methods' own
/// depth-buffer point (issue 2, `raycast`), so a method's error is the method's alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Receiver {
    /// The receiver point in world space.
    pub point: Vec3,
    /// Unit surface normal on the camera side; the shadow-ray origin is offset along it.
    pub normal: Vec3,
}

/// Options of the `raycast` method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RaycastSettings {
    /// Light samples per receiver: a perfect square k×k ([`sampling::stratified`]); default
    /// [`DEFAULT_SAMPLES`].
    pub samples: u32,
    /// Seed of the jitter ([`Pattern::Jittered`]).
    pub seed: u64,
}

impl Default for RaycastSettings {
    fn default() -> Self {
        Self {
            samples: DEFAULT_SAMPLES,
            seed: 0,
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
    /// True when the segment `o + t·d` hits the triangle at `t ∈ (ε, 1 − ε)`
    /// (Möller & Trumbore 1997, f64, edges inclusive, both sides).
    #[inline]
    fn blocks(&self, o: DVec3, d: DVec3) -> bool {
        let pvec = d.cross(self.e2);
        let det = self.e1.dot(pvec);
        if det == 0.0 {
            return false;
        }
        let inv = 1.0 / det;
        let tvec = o - self.v0;
        let u = tvec.dot(pvec) * inv;
        if !(0.0..=1.0).contains(&u) {
            return false;
        }
        let qvec = tvec.cross(self.e1);
        let v = d.dot(qvec) * inv;
        if v < 0.0 || u + v > 1.0 {
            return false;
        }
        let t = self.e2.dot(qvec) * inv;
        t > SEGMENT_EPSILON && t < 1.0 - SEGMENT_EPSILON
    }
}

/// The BVH primitive: one triangle's padded box and its index.
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
/// next node, its second child is at `second`; a leaf holds one triangle.
#[derive(Debug, Clone, Copy)]
struct FlatNode {
    lo: Vec3,
    hi: Vec3,
    /// Leaf: the triangle index; inner node: the index of the second child.
    index: u32,
    leaf: bool,
}

/// Flattens the crate's tree below `node` (whose box is `aabb`) into `out`, depth first;
/// returns the depth of the subtree.
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
            out.push(FlatNode {
                lo,
                hi,
                index: shapes[*shape_index].triangle as u32,
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

/// Casts shadow rays against all triangles of a scene; builds the BVH once per scene
/// (module doc, "Acceleration").
pub struct ShadowRayCaster {
    triangles: Vec<Triangle>,
    nodes: Vec<FlatNode>,
    /// Depth of the tree (a single leaf has depth 0).
    depth: usize,
    /// `δ` of the module doc: the receiver-origin offset in world units.
    origin_offset: f64,
}

impl ShadowRayCaster {
    /// Collects the triangles of every mesh of `scene` and builds the BVH over them.
    pub fn new(scene: &Scene) -> Self {
        let (lo, hi) = scene.bounds();
        let diagonal = f64::from((hi - lo).length());
        let diagonal = if diagonal.is_finite() && diagonal > 0.0 {
            diagonal
        } else {
            1.0
        };
        let pad = BOX_PADDING * diagonal as f32;
        let mut triangles = Vec::new();
        let mut shapes = Vec::new();
        for mesh in &scene.meshes {
            for tri in &mesh.triangles {
                let [a, b, c] = tri.map(|i| mesh.positions[i as usize]);
                let (lo, hi) = (a.min(b).min(c) - pad, a.max(b).max(c) + pad);
                shapes.push(BoxedTriangle {
                    aabb: Aabb::with_bounds(
                        Point3::new(lo.x, lo.y, lo.z),
                        Point3::new(hi.x, hi.y, hi.z),
                    ),
                    triangle: triangles.len(),
                    node_index: 0,
                });
                let v0 = a.as_dvec3();
                triangles.push(Triangle {
                    v0,
                    e1: b.as_dvec3() - v0,
                    e2: c.as_dvec3() - v0,
                });
            }
        }
        let mut nodes = Vec::with_capacity(2 * shapes.len());
        let mut depth = 0;
        if !shapes.is_empty() {
            let root_box = shapes.iter().fold(Aabb::empty(), |b, s| b.join(&s.aabb));
            let bvh = Bvh::build(&mut shapes);
            depth = flatten(&bvh, &shapes, 0, &root_box, &mut nodes);
        }
        Self {
            triangles,
            nodes,
            depth,
            origin_offset: ORIGIN_OFFSET * diagonal,
        }
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
        self.visibility_of_samples(r, &samples)
    }

    /// True when the shadow segment from `origin` to `target` is blocked by any triangle.
    fn blocked(&self, origin: DVec3, target: DVec3) -> bool {
        let d = target - origin;
        if self.nodes.is_empty() || d == DVec3::ZERO {
            return false;
        }
        // A depth-first traversal holds at most one pending sibling per level.
        if self.depth < 64 {
            self.any_hit(origin, d, &mut [0; 64])
        } else {
            self.any_hit(origin, d, &mut vec![0; self.depth + 1])
        }
    }

    /// Depth-first any-hit traversal of the flattened BVH from `origin` along `d`, boxes
    /// clipped to the segment `t ∈ [0, 1]`; `stack` has room for the tree's depth.
    #[inline]
    fn any_hit(&self, origin: DVec3, d: DVec3, stack: &mut [u32]) -> bool {
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
            // f32::min/max ignore a NaN operand (see the module doc, "Acceleration").
            let near =
                t0.x.min(t1.x)
                    .max(t0.y.min(t1.y))
                    .max(t0.z.min(t1.z))
                    .max(0.0);
            let far =
                t0.x.max(t1.x)
                    .min(t0.y.max(t1.y))
                    .min(t0.z.max(t1.z))
                    .min(1.0);
            if near > far {
                continue;
            }
            if node.leaf {
                if self.triangles[node.index as usize].blocks(origin, d) {
                    return true;
                }
            } else {
                stack[top] = node.index;
                stack[top + 1] = at + 1;
                top += 2;
            }
        }
        false
    }

    /// The visibility of `r` for an explicit sample set (shared by [`Self::visibility`] and
    /// [`raycast_visibility`], which computes the sample set once when it does not depend on
    /// the receiver).
    fn visibility_of_samples(&self, r: &Receiver, samples: &[LightSample]) -> [f32; 3] {
        let origin = r.point.as_dvec3() + self.origin_offset * r.normal.as_dvec3();
        let mut visible = [0.0f64; 3];
        let mut total = [0.0f64; 3];
        for s in samples {
            let w = s.weight.map(f64::from);
            for c in 0..3 {
                total[c] += w[c];
            }
            if self.triangles.is_empty() || !self.blocked(origin, s.position.as_dvec3()) {
                for c in 0..3 {
                    visible[c] += w[c];
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
pub fn raycast_visibility(
    scene: &Scene,
    receivers: &[Option<Receiver>],
    settings: &RaycastSettings,
) -> Visibility {
    let caster = ShadowRayCaster::new(scene);
    let light = &scene.light;
    // Only sphere lights depend on the receiver (the facing disk); sample the others once.
    let shared = match light.shape {
        LightShape::Sphere { .. } => None,
        _ => Some(light_samples(light, light.center, settings)),
    };
    let pixel = |r: &Option<Receiver>| -> [f32; 3] {
        match r {
            None => [1.0; 3],
            Some(r) => match &shared {
                Some(samples) => caster.visibility_of_samples(r, samples),
                None => caster.visibility(light, r, settings),
            },
        }
    };
    match light.shape {
        LightShape::TexturedRect { .. } => {
            Visibility::Rgb(receivers.par_iter().map(pixel).collect())
        }
        _ => Visibility::Gray(receivers.par_iter().map(|r| pixel(r)[0]).collect()),
    }
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
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
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
            light,
            meshes,
            methods: None,
            options: Default::default(),
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
        let v = caster.visibility(&s.light, &ON_FLOOR, &RaycastSettings::default());
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
            ShadowRayCaster::new(&s).visibility(&s.light, &ON_FLOOR, &RaycastSettings::default());
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
                &s.light,
                &ON_FLOOR,
                &RaycastSettings::default(),
            );
            assert_eq!(v, [0.0; 3], "{:?}", s.light.shape);
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
            let settings = RaycastSettings { samples, seed };
            let v = caster.visibility(&s.light, &ON_FLOOR, &settings);
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
            ShadowRayCaster::new(&s).visibility(&s.light, &ON_FLOOR, &RaycastSettings::default());
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
            ShadowRayCaster::new(&s).visibility(&s.light, &ON_FLOOR, &RaycastSettings::default());
        // Red is hidden, blue fully visible, green emits nothing (reported as 0).
        assert_eq!(v, [0.0, 0.0, 1.0]);
        let out = raycast_visibility(&s, &[Some(ON_FLOOR), None], &RaycastSettings::default());
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
            };
            let run = |threads| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(|| raycast_visibility(&s, &receivers, &settings))
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

    #[test]
    fn settings_validation() {
        assert!(RaycastSettings::default().validate().is_ok());
        assert!(RaycastSettings {
            samples: 1000,
            seed: 0
        }
        .validate()
        .is_err());
        assert!(RaycastSettings {
            samples: 0,
            seed: 0
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
        let t = std::time::Instant::now();
        let caster = ShadowRayCaster::new(&s);
        let build = t.elapsed();
        let v = raycast_visibility(&s, &receivers, &RaycastSettings::default());
        let total = t.elapsed();
        let mean: f64 = (0..v.len()).map(|i| f64::from(v.gray(i))).sum::<f64>() / v.len() as f64;
        println!(
            "{} triangles, BVH build {:?}, 256×256×1024 rays in {:?} on {} threads, mean visibility {mean:.4}",
            caster.triangle_count(),
            build,
            total,
            rayon::current_num_threads()
        );
    }
}
