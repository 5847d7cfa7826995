//! Triangle setup (after Mesa's `lp_setup_tri.c`): clip, project to the viewport, snap to
//! fixed point, compute the facing, the exact i64 edge functions with the fill-rule bias, the
//! bounding box and the depth plane. Traversal lives in [`super::raster`].
//!
//! Fill rule (DESIGN.md, measured on llvmpipe): a sample exactly on an edge belongs to the
//! triangle for which that edge is a **left** edge (the interior lies toward +x); on a
//! horizontal edge, to the triangle for which it is a **bottom** edge (the interior lies toward
//! smaller image y, i.e. above it as displayed with row 0 at the top). Zero-area triangles are
//! dropped. Facing is the sign of the fixed-point area: counter-clockwise in OpenGL window
//! coordinates (y up) is front-facing.
//!
//! Depth: the window depths z_w (f32) of the three vertices define a plane over the snapped
//! positions; it is evaluated at each sample in f64 and rounded once to f32
//! ([`RasterTriangle::depth_at`]). This is the only place interpolated depth is computed.

use super::clip::{clip_triangle, fully_inside};
use super::counters::Counters;
use super::fixed::Fixed8;
use super::transform::{viewport, ClipVertex};
use crate::limits::{FIXED_ONE, WINDOW_LIMIT};

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
    /// Depth plane origin (pixels, image space) and value: x, y, z.
    z_origin: [f64; 3],
    /// Depth plane slopes per pixel in x and y.
    z_slope: [f64; 2],
    /// Smallest and largest vertex window depth (clamped to [0, 1]) — the triangle's depth range
    /// for hierarchical-Z tests.
    pub z_range: [f32; 2],
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
        let dx = i as f64 - self.z_origin[0];
        let dy = j as f64 - self.z_origin[1];
        (self.z_origin[2] + self.z_slope[0] * dx + self.z_slope[1] * dy) as f32
    }
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
    counters.triangles_submitted += 1;
    let before = out.len();
    if fully_inside(tri) {
        setup_clipped(tri, prim, cull, width, height, out);
    } else {
        let poly = clip_triangle(tri);
        for k in 1..poly.len().saturating_sub(1) {
            setup_clipped(
                &[poly[0], poly[k], poly[k + 1]],
                prim,
                cull,
                width,
                height,
                out,
            );
        }
    }
    let made = (out.len() - before) as u64;
    counters.triangles_rasterized += made;
    if made == 0 {
        counters.triangles_dropped += 1;
    }
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

fn setup_clipped(
    tri: &[ClipVertex; 3],
    prim: u32,
    cull: CullMode,
    width: u32,
    height: u32,
    out: &mut Vec<RasterTriangle>,
) {
    let [Some(a), Some(b), Some(c)] = tri.map(|c| window_vertex(c, width, height)) else {
        return;
    };
    let mut v = [a, b, c];
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

    let px = |p: (i64, i64, f32)| {
        (
            p.0 as f64 / FIXED_ONE as f64,
            p.1 as f64 / FIXED_ONE as f64,
            p.2 as f64,
        )
    };
    let (x0f, y0f, z0) = px(v[0]);
    let (x1f, y1f, z1) = px(v[1]);
    let (x2f, y2f, z2) = px(v[2]);
    let det = (x1f - x0f) * (y2f - y0f) - (x2f - x0f) * (y1f - y0f);
    let dzdx = ((z1 - z0) * (y2f - y0f) - (z2 - z0) * (y1f - y0f)) / det;
    let dzdy = ((x1f - x0f) * (z2 - z0) - (x2f - x0f) * (z1 - z0)) / det;
    let zs = [v[0].2, v[1].2, v[2].2].map(|z| z.clamp(0.0, 1.0));

    out.push(RasterTriangle {
        prim,
        front_facing,
        edges,
        bbox: [x0 as u32, y0 as u32, x1 as u32, y1 as u32],
        z_origin: [x0f, y0f, z0],
        z_slope: [dzdx, dzdy],
        z_range: [zs[0].min(zs[1]).min(zs[2]), zs[0].max(zs[1]).max(zs[2])],
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
