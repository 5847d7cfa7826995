//! Light coverage computed without `penumbra::light::coverage`, for the tests that check it
//! (issue 31: a range check after a clamp cannot fail; an assertion against a second algorithm
//! can). The library clips the semi-infinite hard shadow quad of an edge in homogeneous light
//! coordinates and measures the polygon; here a grid of points on the light is tested one by
//! one for whether the segment from the receiver to the point crosses the quad, and polygons
//! are clipped and measured by code written here (Sutherland–Hodgman, shoelace).
//!
//! Grid bound. The points of the light hidden by the quad form a convex set: the quad `Q` is
//! convex, the set of points behind `Q` seen from `p` is the cone from `p` over `Q` cut by
//! `Q`'s plane (convex), and it meets the light's plane (and the square, or the disk) in a
//! convex set. With one sample at the center of each of the `N × N` cells of the light's
//! bounding square, only the cells the set's boundary passes through can be counted wrongly,
//! each by at most its own area. A closed convex curve crosses each of the `N − 1` inner grid
//! lines of either direction at most twice, so it enters at most `4(N − 1) + 1 < 4N` cells:
//! the hidden area is off by less than `4N` cell areas.

use glam::{DVec2, DVec3};

/// Samples per side of the grid.
pub const GRID: usize = 512;

/// The bound of the module doc for a rectangular light: `4N` cells of `1/N²` of the light.
pub const RECT_GRID_BOUND: f64 = 4.0 / GRID as f64;

/// The bound of the module doc for a disk: `4N` cells of `(2r/N)²` over the disk's `π r²`.
pub const DISK_GRID_BOUND: f64 = 16.0 / (std::f64::consts::PI * GRID as f64);

/// Whether the segment from `p` to `q` crosses the semi-infinite quad of edge `e0 e1` away
/// from the light center `c`: `{c + a(e0 − c) + b(e1 − c) : a, b ≥ 0, a + b ≥ 1}` (Paper III
/// §3.2.2, the quad `e0, e1, e1∞, e0∞`). `n = (e0 − c) × (e1 − c)`; the crossing point `x`
/// solves `x − c = a u + b w` by `a = ((x − c) × w)·n / |n|²`, `b = (u × (x − c))·n / |n|²`.
fn segment_crosses_quad(c: DVec3, p: DVec3, q: DVec3, e0: DVec3, e1: DVec3) -> bool {
    let (u, w) = (e0 - c, e1 - c);
    let n = u.cross(w);
    let (dp, dq) = (n.dot(p - c), n.dot(q - c));
    if dp == 0.0 || dp * dq >= 0.0 {
        return false;
    }
    let x = p + (q - p) * (dp / (dp - dq));
    let r = x - c;
    let nn = n.length_squared();
    let a = r.cross(w).dot(n) / nn;
    let b = u.cross(r).dot(n) / nn;
    a >= 0.0 && b >= 0.0 && a + b >= 1.0
}

/// `+1`, `−1` or `0`: the side of the quad's plane `p` is on, `det(e0 − c, e1 − c, p − c)`
/// (the sign convention of `edge_coverage_exact`).
fn side(c: DVec3, p: DVec3, e0: DVec3, e1: DVec3) -> f64 {
    let d = (e0 - c).cross(e1 - c).dot(p - c);
    if d > 0.0 {
        1.0
    } else if d < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// The signed coverage of the parallelogram light `center + s·u + t·v` (`s, t ∈ [−1, 1]`) by
/// the quad of edge `e0 e1` seen from `p`, counted on the grid: within [`RECT_GRID_BOUND`] of
/// the exact value.
pub fn rect_coverage_by_grid(
    center: DVec3,
    u: DVec3,
    v: DVec3,
    p: DVec3,
    e0: DVec3,
    e1: DVec3,
) -> f64 {
    let mut hidden = 0usize;
    for i in 0..GRID {
        let s = -1.0 + (2 * i + 1) as f64 / GRID as f64;
        for j in 0..GRID {
            let t = -1.0 + (2 * j + 1) as f64 / GRID as f64;
            let q = center + u * s + v * t;
            hidden += segment_crosses_quad(center, p, q, e0, e1) as usize;
        }
    }
    side(center, p, e0, e1) * hidden as f64 / (GRID * GRID) as f64
}

/// The signed coverage of the disk of radius `r` through `center` perpendicular to
/// `p − center` (the disk a sphere light shows to `p`) by the quad of edge `e0 e1`, counted
/// on the grid over the disk's bounding square: within [`DISK_GRID_BOUND`] of the exact value.
pub fn disk_coverage_by_grid(center: DVec3, r: f64, p: DVec3, e0: DVec3, e1: DVec3) -> f64 {
    let n = (p - center).normalize();
    let x = n.any_orthonormal_vector();
    let y = n.cross(x);
    let cell = 2.0 * r / GRID as f64;
    let mut hidden = 0usize;
    for i in 0..GRID {
        let s = -r + (i as f64 + 0.5) * cell;
        for j in 0..GRID {
            let t = -r + (j as f64 + 0.5) * cell;
            if s * s + t * t > r * r {
                continue;
            }
            let q = center + x * s + y * t;
            hidden += segment_crosses_quad(center, p, q, e0, e1) as usize;
        }
    }
    let area = std::f64::consts::PI * r * r;
    side(center, p, e0, e1) * hidden as f64 * cell * cell / area
}

/// Signed area of a simple polygon (counter-clockwise positive; shoelace formula).
pub fn polygon_signed_area(poly: &[DVec2]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| poly[i].perp_dot(poly[(i + 1) % n]))
        .sum::<f64>()
        * 0.5
}

/// The part of the convex counter-clockwise polygon `poly` inside the convex
/// counter-clockwise polygon `clip` (Sutherland–Hodgman).
pub fn clip_convex(poly: &[DVec2], clip: &[DVec2]) -> Vec<DVec2> {
    let mut out = poly.to_vec();
    for k in 0..clip.len() {
        let (a, b) = (clip[k], clip[(k + 1) % clip.len()]);
        let side = |q: DVec2| (b - a).perp_dot(q - a);
        let input = std::mem::take(&mut out);
        for i in 0..input.len() {
            let (p, q) = (input[i], input[(i + 1) % input.len()]);
            let (sp, sq) = (side(p), side(q));
            if sp >= 0.0 {
                out.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                out.push(p + (q - p) * (sp / (sp - sq)));
            }
        }
    }
    out
}

/// The square `[−1, 1]²`, counter-clockwise.
pub const UNIT_SQUARE: [DVec2; 4] = [
    DVec2::new(-1.0, -1.0),
    DVec2::new(1.0, -1.0),
    DVec2::new(1.0, 1.0),
    DVec2::new(-1.0, 1.0),
];
