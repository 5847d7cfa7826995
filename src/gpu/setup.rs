//! Triangle setup (after Mesa's `lp_setup_tri.c`): clip, project to the viewport, snap to
//! fixed point, compute the facing, the exact i64 edge functions with the fill-rule bias, the
//! bounding box and the depth plane. Traversal lives in [`super::raster`].
//!
//! Fill rule (`docs/architecture.md` "Rasterization"; OpenGL's, as Mesa's llvmpipe implements it):
//! a sample exactly on an edge belongs to the triangle for which that edge is a **left** edge (the
//! interior lies toward +x); on a horizontal edge, to the triangle for which it is a **bottom**
//! edge (the interior lies toward smaller image y, i.e. above it as displayed with row 0 at the
//! top). Zero-area triangles are dropped. Facing is the sign of the fixed-point area:
//! counter-clockwise in OpenGL window coordinates (y up) is front-facing.
//!
//! Depth: the window depths z_w (f32) of the three vertices define a plane over the snapped
//! positions; it is evaluated at each sample in f64 and rounded once to f32
//! ([`RasterTriangle::depth_at`]). This is the only place interpolated depth is computed.
//!
//! Attributes (varyings): a triangle set up with [`setup_all_barycentric`] also gets the
//! perspective-correct barycentric coordinates of each sample with respect to the submitted
//! triangle ([`RasterTriangle::barycentric_at`]): 1/w and b_k/w of the three (clipped)
//! vertices are planes over the snapped positions like the depth ([`ScreenPlane`]), evaluated
//! in f64 at the sample, and `b_k = (b_k/w) / (1/w)`. An attribute is then
//! `Σ b_k · a_k` ([`RasterTriangle::interpolate`]), in f64 and not rounded — the fragment
//! programs of this crate compute in f64. Triangles set up without them pay nothing.

use super::clip::{clip_triangle, clip_triangle_barycentric, fully_inside};
use super::counters::{count, Counters};
use super::depth::{DepthFormat, PolygonOffset};
use super::fixed::Fixed8;
use super::tiling::Tiling;
use super::transform::{viewport, ClipVertex};
use crate::limits::{FIXED_ONE, WINDOW_LIMIT};
use rayon::prelude::*;

/// Which facing to discard before rasterization.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum CullMode {
    /// Rasterize both facings.
    None,
    /// Discard back-facing triangles.
    Back,
    /// Discard front-facing triangles.
    Front,
}

/// An edge function `E(i, j) = a·i + b·j + c` at the sample of pixel (i, j), with the fill-rule
/// bias folded into `c`: the sample is covered iff `E ≥ 0` for all three edges.
/// `a` and `b` are already multiplied by one pixel (256 fixed-point units).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EdgeFunction {
    /// Step per pixel in x.
    pub a: i64,
    /// Step per pixel in y.
    pub b: i64,
    /// Value at pixel (0, 0), bias included.
    pub c: i64,
}

impl EdgeFunction {
    /// The biased edge value at the sample of pixel (i, j).
    #[inline]
    pub fn at(&self, i: i64, j: i64) -> i64 {
        self.a * i + self.b * j + self.c
    }
}

/// A value that is affine over the image: `v(i, j) = v0 + sx·(i − x0) + sy·(j − y0)` at the
/// sample of pixel (i, j), defined by its values at three snapped vertex positions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScreenPlane {
    /// Origin x, y (pixels, image space) and the value there.
    origin: [f64; 3],
    /// Slopes per pixel in x and y.
    slope: [f64; 2],
}

impl ScreenPlane {
    /// The plane through `(x_k, y_k, v_k)` for the three vertices (positions in pixels).
    pub fn through(p: [(f64, f64); 3], v: [f64; 3]) -> Self {
        let [(x0, y0), (x1, y1), (x2, y2)] = p;
        let det = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
        let dvdx = ((v[1] - v[0]) * (y2 - y0) - (v[2] - v[0]) * (y1 - y0)) / det;
        let dvdy = ((x1 - x0) * (v[2] - v[0]) - (x2 - x0) * (v[1] - v[0])) / det;
        Self {
            origin: [x0, y0, v[0]],
            slope: [dvdx, dvdy],
        }
    }

    /// The value at the sample of pixel (i, j), in f64.
    #[inline]
    pub fn at(&self, i: u32, j: u32) -> f64 {
        let dx = i as f64 - self.origin[0];
        let dy = j as f64 - self.origin[1];
        self.origin[2] + self.slope[0] * dx + self.slope[1] * dy
    }

    /// The largest absolute slope per pixel, max(|∂v/∂x|, |∂v/∂y|).
    pub fn max_slope(&self) -> f64 {
        self.slope[0].abs().max(self.slope[1].abs())
    }
}

/// The planes of 1/w and b_k/w of a raster triangle (module doc, "Attributes").
#[derive(Debug, Clone, PartialEq)]
pub struct PerspectivePlanes {
    inv_w: ScreenPlane,
    b_over_w: [ScreenPlane; 3],
}

/// A triangle ready for traversal: everything that does not depend on the pixel.
#[derive(Debug, Clone, PartialEq)]
pub struct RasterTriangle {
    /// Index of the primitive this came from, in submission order.
    pub prim: u32,
    /// True if counter-clockwise in OpenGL window coordinates.
    pub front_facing: bool,
    /// The three edge functions (interior where all are ≥ 0).
    pub edges: [EdgeFunction; 3],
    /// Inclusive pixel bounding box, clamped to the image: x0, y0, x1, y1.
    pub bbox: [u32; 4],
    /// The window-depth plane.
    depth: ScreenPlane,
    /// Smallest and largest vertex window depth (clamped to [0, 1]) — the triangle's depth range
    /// for hierarchical-Z tests.
    pub z_range: [f32; 2],
    /// Perspective-correct barycentrics, when set up with [`setup_all_barycentric`].
    perspective: Option<Box<PerspectivePlanes>>,
}

impl RasterTriangle {
    /// Whether the sample of pixel (i, j) is covered: inside the bounding box and on the
    /// inner side of all three edge functions (fill rule included) — exactly the samples
    /// [`super::raster::rasterize_in_tile`] visits.
    pub fn covers(&self, i: u32, j: u32) -> bool {
        let [x0, y0, x1, y1] = self.bbox;
        (x0..=x1).contains(&i)
            && (y0..=y1).contains(&j)
            && self.edges.iter().all(|e| e.at(i as i64, j as i64) >= 0)
    }

    /// Interpolated window depth at the sample of pixel (i, j): the plane evaluated in f64,
    /// rounded once to f32 (not yet clamped; the depth format clamps).
    #[inline]
    pub fn depth_at(&self, i: u32, j: u32) -> f32 {
        self.depth.at(i, j) as f32
    }

    /// The largest window-depth slope per pixel, max(|∂z/∂x|, |∂z/∂y|) (the `m` of
    /// [`super::depth::PolygonOffset`]).
    pub fn max_depth_slope(&self) -> f64 {
        self.depth.max_slope()
    }

    /// The window depth a fragment of this triangle at interpolated depth `z` is tested and
    /// stored with under polygon `offset` in `format` (the triangle's slope and largest vertex
    /// depth: [`PolygonOffset::apply`]).
    pub fn offset_depth(&self, offset: PolygonOffset, format: DepthFormat, z: f32) -> f32 {
        offset.apply(format, z, self.max_depth_slope(), self.z_range[1])
    }

    /// A lower bound of [`RasterTriangle::offset_depth`] over the triangle's fragments, for
    /// early Z: the offset adds one amount per triangle in f64 and rounds, which keeps the
    /// order of depths, so its nearest vertex depth's offset depth bounds them all; 0 (no
    /// bound) for a triangle reaching in front of the near plane, whose nearest vertex depth
    /// was clamped to 0.
    pub fn nearest_offset_depth(&self, offset: PolygonOffset, format: DepthFormat) -> f32 {
        if self.z_range[0] > 0.0 {
            self.offset_depth(offset, format, self.z_range[0])
        } else {
            0.0
        }
    }

    /// The perspective-correct barycentric coordinates of the sample of pixel (i, j) with
    /// respect to the submitted triangle's vertices (module doc, "Attributes"); `None` for a
    /// triangle set up without them ([`setup_triangle`]).
    #[inline]
    pub fn barycentric_at(&self, i: u32, j: u32) -> Option<[f64; 3]> {
        let p = self.perspective.as_deref()?;
        let q = p.inv_w.at(i, j);
        Some(p.b_over_w.map(|b| b.at(i, j) / q))
    }

    /// The perspective-correct interpolation of the per-vertex `values` (in the submitted
    /// vertex order) at the sample of pixel (i, j): `Σ b_k · values[k]` in f64; `None` for a
    /// triangle set up without barycentrics.
    #[inline]
    pub fn interpolate(&self, i: u32, j: u32, values: [f64; 3]) -> Option<f64> {
        let b = self.barycentric_at(i, j)?;
        Some(b[0] * values[0] + b[1] * values[1] + b[2] * values[2])
    }
}

/// The target and state of triangle setup.
#[derive(Debug, Clone, Copy)]
struct SetupState {
    cull: CullMode,
    width: u32,
    height: u32,
    barycentric: bool,
}

/// Clip, project, snap and set up one triangle of clip-space vertices; pushes 0 or more
/// raster triangles (clipping may fan a polygon) onto `out`.
pub fn setup_triangle(
    tri: &[ClipVertex; 3],
    prim: u32,
    cull: CullMode,
    width: u32,
    height: u32,
    out: &mut Vec<RasterTriangle>,
    counters: &mut Counters,
) {
    let state = SetupState {
        cull,
        width,
        height,
        barycentric: false,
    };
    setup_with(tri, prim, state, out, counters);
}

const UNIT_BARYCENTRICS: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn setup_with(
    tri: &[ClipVertex; 3],
    prim: u32,
    state: SetupState,
    out: &mut Vec<RasterTriangle>,
    counters: &mut Counters,
) {
    count!(counters.triangles_submitted += 1);
    let before = out.len();
    if fully_inside(tri) {
        let v = [0, 1, 2].map(|k| (tri[k], UNIT_BARYCENTRICS[k]));
        setup_clipped(&v, prim, state, out);
    } else if state.barycentric {
        let poly = clip_triangle_barycentric(tri);
        for k in 1..poly.len().saturating_sub(1) {
            setup_clipped(&[poly[0], poly[k], poly[k + 1]], prim, state, out);
        }
    } else {
        let poly = clip_triangle(tri);
        for k in 1..poly.len().saturating_sub(1) {
            let v = [poly[0], poly[k], poly[k + 1]];
            setup_clipped(&v.map(|c| (c, [0.0; 3])), prim, state, out);
        }
    }
    let made = (out.len() - before) as u64;
    count!(counters.triangles_rasterized += made);
    if made == 0 {
        count!(counters.triangles_dropped += 1);
    }
}

/// Set up every primitive (in parallel, order kept) and return the raster triangles in
/// submission order with the setup counters.
pub fn setup_all(
    prims: &[[ClipVertex; 3]],
    cull: CullMode,
    tiling: &Tiling,
) -> (Vec<RasterTriangle>, Counters) {
    setup_all_with(prims, tiling, |_| cull, false)
}

/// [`setup_all`] with a face culling per submitted triangle, `cull(k)` for `prims[k]`: one
/// submission of several draw calls that cull differently (a half-wedge's front faces, then
/// its back faces), in their order.
pub fn setup_all_culled(
    prims: &[[ClipVertex; 3]],
    cull: impl Fn(usize) -> CullMode + Sync,
    tiling: &Tiling,
) -> (Vec<RasterTriangle>, Counters) {
    setup_all_with(prims, tiling, cull, false)
}

/// [`setup_all`] that also sets up perspective-correct barycentrics, so that fragments can
/// interpolate per-vertex attributes ([`RasterTriangle::interpolate`]).
pub fn setup_all_barycentric(
    prims: &[[ClipVertex; 3]],
    cull: CullMode,
    tiling: &Tiling,
) -> (Vec<RasterTriangle>, Counters) {
    setup_all_with(prims, tiling, |_| cull, true)
}

/// Submitted triangles one parallel task sets up: large enough that a task's set-up is not
/// lost in scheduling and allocation (one vector per task, not per triangle), small enough
/// that two threads share a few thousand triangles evenly.
const SETUP_CHUNK: usize = 256;

fn setup_all_with(
    prims: &[[ClipVertex; 3]],
    tiling: &Tiling,
    cull: impl Fn(usize) -> CullMode + Sync,
    barycentric: bool,
) -> (Vec<RasterTriangle>, Counters) {
    let state = |k: usize| SetupState {
        cull: cull(k),
        width: tiling.width,
        height: tiling.height,
        barycentric,
    };
    // Chunks of submitted triangles set up in parallel, each into one vector: concatenated
    // in chunk order, the triangles keep submission order for any thread count.
    let parts: Vec<(Vec<RasterTriangle>, Counters)> = prims
        .par_chunks(SETUP_CHUNK)
        .enumerate()
        .map(|(chunk, ps)| {
            let mut out = Vec::with_capacity(ps.len());
            let mut c = Counters::default();
            for (k, p) in ps.iter().enumerate() {
                let k = chunk * SETUP_CHUNK + k;
                setup_with(p, k as u32, state(k), &mut out, &mut c);
            }
            (out, c)
        })
        .collect();
    let mut tris = Vec::with_capacity(prims.len());
    let mut counters = Counters::default();
    for (t, c) in parts {
        tris.extend(t);
        counters += c;
    }
    (tris, counters)
}

/// Snapped image-space position (fixed point) and window depth of a clipped vertex, or `None`
/// when the window position is not finite or lies beyond [`WINDOW_LIMIT`] pixels — possible
/// only for degenerate clip input (w within rounding error of 0 after clipping), never for a
/// vertex inside the guard band. Such triangles are dropped, which keeps every edge-function
/// product inside i64.
fn window_vertex(v: ClipVertex, width: u32, height: u32) -> Option<(i64, i64, f32)> {
    let [xw, yw, zw] = viewport(v, width, height);
    let inside = |c: f32| c.is_finite() && c.abs() <= WINDOW_LIMIT;
    if !(inside(xw) && inside(yw) && zw.is_finite()) {
        return None;
    }
    let x = Fixed8::snap(xw);
    let y = Fixed8::snap(yw).flip_y(height);
    Some((x.0, y.0, zw))
}

/// Set up one clipped triangle whose vertices carry their barycentrics in the submitted
/// triangle (ignored unless `state.barycentric`).
fn setup_clipped(
    tri: &[(ClipVertex, [f64; 3]); 3],
    prim: u32,
    state: SetupState,
    out: &mut Vec<RasterTriangle>,
) {
    let SetupState {
        cull,
        width,
        height,
        barycentric,
    } = state;
    let [Some(a), Some(b), Some(c)] = tri.map(|c| window_vertex(c.0, width, height)) else {
        return;
    };
    let mut v = [a, b, c];
    let mut carried = *tri;
    // Image-space signed area ×2 (y down). Counter-clockwise in GL (y up) = negative here.
    let area = (v[1].0 - v[0].0) * (v[2].1 - v[0].1) - (v[1].1 - v[0].1) * (v[2].0 - v[0].0);
    if area == 0 {
        return;
    }
    let front_facing = area < 0;
    match cull {
        CullMode::Back if !front_facing => return,
        CullMode::Front if front_facing => return,
        _ => {}
    }
    if area < 0 {
        v.swap(1, 2); // make the image-space area positive: interior where every E > 0
        carried.swap(1, 2);
    }
    let edges = [(0, 1), (1, 2), (2, 0)].map(|(p, q)| edge_function(v[p], v[q]));

    let min_x = v.iter().map(|p| p.0).min().unwrap_or(0);
    let max_x = v.iter().map(|p| p.0).max().unwrap_or(0);
    let min_y = v.iter().map(|p| p.1).min().unwrap_or(0);
    let max_y = v.iter().map(|p| p.1).max().unwrap_or(0);
    let x0 = Fixed8(min_x).ceil_pixel().max(0);
    let y0 = Fixed8(min_y).ceil_pixel().max(0);
    let x1 = Fixed8(max_x).floor_pixel().min(width as i64 - 1);
    let y1 = Fixed8(max_y).floor_pixel().min(height as i64 - 1);
    if x0 > x1 || y0 > y1 {
        return;
    }

    let pos = v.map(|p| (p.0 as f64 / FIXED_ONE as f64, p.1 as f64 / FIXED_ONE as f64));
    let depth = ScreenPlane::through(pos, v.map(|p| p.2 as f64));
    let zs = [v[0].2, v[1].2, v[2].2].map(|z| z.clamp(0.0, 1.0));
    let perspective = barycentric.then(|| {
        let inv_w = carried.map(|c| 1.0 / c.0 .0[3] as f64);
        Box::new(PerspectivePlanes {
            inv_w: ScreenPlane::through(pos, inv_w),
            b_over_w: std::array::from_fn(|k| {
                ScreenPlane::through(pos, std::array::from_fn(|i| carried[i].1[k] * inv_w[i]))
            }),
        })
    });

    out.push(RasterTriangle {
        prim,
        front_facing,
        edges,
        bbox: [x0 as u32, y0 as u32, x1 as u32, y1 as u32],
        depth,
        z_range: [zs[0].min(zs[1]).min(zs[2]), zs[0].max(zs[1]).max(zs[2])],
        perspective,
    });
}

/// The edge function of directed edge p→q for a triangle with positive image-space area,
/// `E(s) = (p.y − q.y)·s.x + (q.x − p.x)·s.y + (p.x·q.y − p.y·q.x)`, positive inside, with the
/// fill-rule bias: samples with E = 0 are kept only on left edges (q.y < p.y: the interior is
/// toward +x) and on bottom edges (q.y = p.y and q.x < p.x: the interior is toward −y).
fn edge_function(p: (i64, i64, f32), q: (i64, i64, f32)) -> EdgeFunction {
    let (px, py, qx, qy) = (p.0, p.1, q.0, q.1);
    let a = py - qy;
    let b = qx - px;
    let c = px * qy - py * qx;
    let dy = qy - py;
    let dx = qx - px;
    let owns_ties = dy < 0 || (dy == 0 && dx < 0);
    let bias = if owns_ties { 0 } else { -1 };
    EdgeFunction {
        a: a * FIXED_ONE,
        b: b * FIXED_ONE,
        c: c + bias,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ndc(x: f32, y: f32) -> ClipVertex {
        ClipVertex([x, y, 0.0, 1.0])
    }

    fn covered(t: &RasterTriangle, i: u32, j: u32) -> bool {
        t.edges.iter().all(|e| e.at(i as i64, j as i64) >= 0)
    }

    #[test]
    fn ccw_in_gl_is_front_facing() {
        let mut out = Vec::new();
        let mut c = Counters::default();
        setup_triangle(
            &[ndc(-1.0, -1.0), ndc(1.0, -1.0), ndc(-1.0, 1.0)],
            0,
            CullMode::None,
            8,
            8,
            &mut out,
            &mut c,
        );
        assert!(out[0].front_facing);
        setup_triangle(
            &[ndc(-1.0, -1.0), ndc(-1.0, 1.0), ndc(1.0, -1.0)],
            1,
            CullMode::None,
            8,
            8,
            &mut out,
            &mut c,
        );
        assert!(!out[1].front_facing);
        setup_triangle(
            &[ndc(-1.0, -1.0), ndc(-1.0, 1.0), ndc(1.0, -1.0)],
            2,
            CullMode::Back,
            8,
            8,
            &mut out,
            &mut c,
        );
        assert_eq!(out.len(), 2);
    }

    #[test]
    fn vertical_edge_through_samples_goes_to_the_right_triangle() {
        // Split x = 4.5 (window) runs through the samples of column 4.
        // GL x = 4.5 ↔ NDC 4.5/4 − 1 = 0.125 for W = 8.
        let mut out = Vec::new();
        let mut c = Counters::default();
        let left = [ndc(-1.0, -1.0), ndc(0.125, -1.0), ndc(0.125, 1.0)];
        let right = [ndc(0.125, -1.0), ndc(1.0, -1.0), ndc(0.125, 1.0)];
        setup_triangle(&left, 0, CullMode::None, 8, 8, &mut out, &mut c);
        setup_triangle(&right, 1, CullMode::None, 8, 8, &mut out, &mut c);
        // Column 4, a row inside both triangles' y range: owned by the triangle on its right.
        assert!(!covered(&out[0], 4, 7));
        assert!(covered(&out[1], 4, 7));
    }

    #[test]
    fn horizontal_edge_through_samples_goes_to_the_triangle_above() {
        // Horizontal split at GL y = 4.5, i.e. image row 3's sample (H = 8: row 3 ↔ GL row 4).
        let mut out = Vec::new();
        let mut c = Counters::default();
        let below = [ndc(-1.0, -1.0), ndc(1.0, -1.0), ndc(-1.0, 0.125)]; // GL lower half
        let above = [ndc(-1.0, 0.125), ndc(1.0, -1.0), ndc(1.0, 0.125)];
        let top = [ndc(-1.0, 0.125), ndc(1.0, 0.125), ndc(-1.0, 1.0)];
        setup_triangle(&below, 0, CullMode::None, 8, 8, &mut out, &mut c);
        setup_triangle(&above, 1, CullMode::None, 8, 8, &mut out, &mut c);
        setup_triangle(&top, 2, CullMode::None, 8, 8, &mut out, &mut c);
        // Image row 3 pixel 0: on the horizontal edge between `below` (GL under, image below)
        // and `top` (image above): belongs to the triangle for which it is a bottom edge: `top`.
        assert!(covered(&out[2], 0, 3));
        assert!(!covered(&out[0], 0, 3));
    }

    #[test]
    fn perspective_barycentrics_reproduce_world_positions() {
        use crate::gpu::transform::Projection;
        use crate::scene::Camera;
        use glam::{DVec3, Vec3};
        // A triangle receding in depth, one vertex behind the near plane (clipped), seen by
        // a perspective camera: at every covered sample, the barycentric combination of the
        // world vertices lies on the eye ray through the sample.
        let cam = Camera {
            eye: DVec3::new(0.0, 1.0, 3.0),
            target: DVec3::ZERO,
            up: DVec3::Y,
            vfov_deg: 60.0,
            near: Some(0.5),
        };
        let p = Projection::new(&cam, 32, 32, 0.5);
        let world = [
            Vec3::new(-2.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.5),
            Vec3::new(0.0, 0.0, 3.4),
        ];
        let tri = world.map(|w| p.clip_point(w));
        let tiling = Tiling::new(32, 32, 8).unwrap();
        let (out, mut c) = setup_all_barycentric(&[tri], CullMode::None, &tiling);
        assert!(out.len() >= 2, "clipped into a fan");
        let mut checked = 0;
        for t in &out {
            for j in t.bbox[1]..=t.bbox[3] {
                for i in t.bbox[0]..=t.bbox[2] {
                    if !covered(t, i, j) {
                        continue;
                    }
                    let b = t.barycentric_at(i, j).unwrap();
                    assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-9);
                    let x: DVec3 = (0..3).map(|k| world[k].as_dvec3() * b[k]).sum();
                    let ray = (p.unproject(i, j, 0.5) - cam.eye).normalize();
                    let along = (x - cam.eye).dot(ray);
                    let off = (x - cam.eye) - ray * along;
                    // Vertices are snapped to 1/256 pixel: allow that much of a pixel's
                    // footprint at the point's distance.
                    let pixel = 2.0 * libm::tan((30f64).to_radians()) * along / 32.0;
                    assert!(off.length() < pixel / 256.0, "({i}, {j}): {off:?}");
                    let y = t.interpolate(i, j, [1.0, 2.0, 3.0]).unwrap();
                    assert!((y - (b[0] + 2.0 * b[1] + 3.0 * b[2])).abs() < 1e-15);
                    checked += 1;
                }
            }
        }
        assert!(checked > 50, "{checked}");
        // Without barycentrics: none.
        let mut plain = Vec::new();
        setup_triangle(&tri, 0, CullMode::None, 32, 32, &mut plain, &mut c);
        assert_eq!(plain[0].barycentric_at(5, 5), None);
        assert_eq!(plain[0].depth_at(5, 5), out[0].depth_at(5, 5));
    }

    #[test]
    #[allow(clippy::excessive_precision)] // the fuzzer's exact input
    fn degenerate_tiny_w_after_clipping_is_dropped_not_overflowed() {
        // Found by the `raster` fuzz target: w ≈ 1e-39 leaves x/w ≈ 1e23 after clipping.
        let mut out = Vec::new();
        let mut c = Counters::default();
        let tri = [
            ClipVertex([0.0, 0.0, -2.0, 0.0]),
            ClipVertex([1.0000075, 0.0, 0.5, 2.204052e-39]),
            ClipVertex([-2.0, 5.831554e-39, 5.7856363e-39, 2.2779508e-41]),
        ];
        setup_triangle(&tri, 0, CullMode::None, 32, 32, &mut out, &mut c);
        assert!(out.iter().all(|t| t.bbox[2] < 32 && t.bbox[3] < 32));
    }
}
