//! The one ray–triangle intersection of the crate: Möller & Trumbore's test ("Fast, Minimum
//! Storage Ray/Triangle Intersection", 1997) in f64, both sides (no back-face culling).
//!
//! Its rules, chosen once for every caller (module doc of [`super`]):
//! - **Parallel**: a line with `det = 0` exactly misses (no threshold: a threshold would make
//!   thin triangles of large scenes transparent; a caller that wants one applies it to
//!   [`LineHit::det`], as the scene checks do).
//! - **Edges**: inclusive at `tolerance = 0` — a point on a shared edge of a closed mesh hits
//!   both triangles, so a ray through it cannot leak. A positive tolerance widens the triangle
//!   by that much in barycentric coordinates (the scene checks flag such grazing hits as
//!   ambiguous).
//! - **The parameter range** is the caller's: the test returns `t` for the whole line.
//! - **NaN**: a NaN `u` misses; every other comparison lets NaN through to `t`, which then
//!   fails any range test a caller makes.

use glam::DVec3;

/// Where a line meets a triangle ([`line_triangle`]): the point is `o + t·d`
/// = `v0 + u·e1 + v·e2`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineHit {
    /// Barycentric coordinate along `e1`.
    pub u: f64,
    /// Barycentric coordinate along `e2`.
    pub v: f64,
    /// The line's parameter.
    pub t: f64,
    /// The determinant `e1 · (d × e2)`: its magnitude over `|e1|·|e2|·|d|` is the sine of the
    /// angle between the line and the triangle's plane.
    pub det: f64,
}

/// Where the line `o + t·d` meets the triangle `v0 + u·e1 + v·e2` (`u ≥ −tolerance`,
/// `v ≥ −tolerance`, `u + v ≤ 1 + tolerance`), or `None` when it is parallel to the plane or
/// passes outside (module doc for the rules).
#[inline]
pub fn line_triangle(
    o: DVec3,
    d: DVec3,
    v0: DVec3,
    e1: DVec3,
    e2: DVec3,
    tolerance: f64,
) -> Option<LineHit> {
    let pvec = d.cross(e2);
    let det = e1.dot(pvec);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let tvec = o - v0;
    let u = tvec.dot(pvec) * inv;
    if !(-tolerance..=1.0 + tolerance).contains(&u) {
        return None;
    }
    let qvec = tvec.cross(e1);
    let v = d.dot(qvec) * inv;
    if v < -tolerance || u + v > 1.0 + tolerance {
        return None;
    }
    let t = e2.dot(qvec) * inv;
    Some(LineHit { u, v, t, det })
}

/// Whether the open segment `p + t·d`, `t ∈ (t_start, t_end)`, crosses the triangle
/// `v0 + u·e1 + v·e2` (edges inclusive).
#[inline]
pub fn segment_crosses_triangle(
    p: DVec3,
    d: DVec3,
    v0: DVec3,
    e1: DVec3,
    e2: DVec3,
    t_start: f64,
    t_end: f64,
) -> bool {
    line_triangle(p, d, v0, e1, e2, 0.0).is_some_and(|h| h.t > t_start && h.t < t_end)
}

#[cfg(test)]
mod tests {
    use super::*;

    const V0: DVec3 = DVec3::ZERO;
    const E1: DVec3 = DVec3::X;
    const E2: DVec3 = DVec3::Y;

    /// A line down the z axis through (x, y) of the unit right triangle in z = 0, from z = 1.
    fn down(x: f64, y: f64, tolerance: f64) -> Option<LineHit> {
        line_triangle(DVec3::new(x, y, 1.0), -DVec3::Z, V0, E1, E2, tolerance)
    }

    /// The hit's coordinates are the point's: u = x, v = y, t = the distance travelled, from
    /// either side (no culling).
    #[test]
    fn the_hit_gives_the_points_coordinates_from_both_sides() {
        let h = down(0.25, 0.5, 0.0).unwrap();
        assert_eq!((h.u, h.v, h.t), (0.25, 0.5, 1.0));
        let below = line_triangle(DVec3::new(0.25, 0.5, -2.0), DVec3::Z, V0, E1, E2, 0.0);
        assert_eq!(below.map(|h| h.t), Some(2.0));
    }

    /// Edges and vertices are inclusive at tolerance 0; beyond them the line misses unless the
    /// tolerance covers the distance.
    #[test]
    fn edges_are_inclusive_and_the_tolerance_widens_the_triangle() {
        for (x, y) in [(0.0, 0.5), (0.5, 0.0), (0.5, 0.5), (0.0, 0.0), (1.0, 0.0)] {
            assert!(down(x, y, 0.0).is_some(), "({x}, {y})");
        }
        for (x, y) in [(-1e-9, 0.5), (0.5, -1e-9), (0.5, 0.5 + 1e-9)] {
            assert!(down(x, y, 0.0).is_none(), "({x}, {y})");
            assert!(down(x, y, 1e-8).is_some(), "({x}, {y})");
        }
    }

    /// A line in the triangle's plane (det = 0) misses; a NaN origin never hits a range.
    #[test]
    fn parallel_lines_miss_and_nan_fails_every_range() {
        assert!(line_triangle(DVec3::new(0.2, 0.2, 0.0), DVec3::X, V0, E1, E2, 0.0).is_none());
        let nan = DVec3::new(f64::NAN, 0.2, 1.0);
        assert!(!segment_crosses_triangle(
            nan,
            -DVec3::Z,
            V0,
            E1,
            E2,
            0.0,
            1.0
        ));
    }

    /// The segment test is open at both ends.
    #[test]
    fn the_segment_is_open() {
        let p = DVec3::new(0.25, 0.25, 1.0);
        let d = -DVec3::Z * 2.0; // reaches the plane at t = 0.5
        assert!(segment_crosses_triangle(p, d, V0, E1, E2, 0.0, 1.0));
        assert!(!segment_crosses_triangle(p, d, V0, E1, E2, 0.5, 1.0));
        assert!(!segment_crosses_triangle(p, d, V0, E1, E2, 0.0, 0.5));
    }
}
