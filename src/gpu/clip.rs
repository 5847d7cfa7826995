//! Homogeneous clipping (`docs/architecture.md` "Projection": homogeneous clipping handles w = 0,
//! far clipping stays on).
//!
//! Triangles are clipped in clip space against six planes: near `z + w ≥ 0`, far `w − z ≥ 0`
//! (points at infinity have z = w and stay inside), and a guard band
//! `|x|, |y| ≤ GUARD_BAND·w` instead of the viewport sides, like hardware guard-band clipping:
//! edges that cross the viewport are never moved, while vertices at infinity (w = 0, which lie
//! outside every guard plane unless x = y = 0) become finite.
//!
//! Watertightness: an intersection point is always computed from the edge's inside vertex
//! toward its outside vertex, in f64, then rounded to f32. Two triangles sharing an edge
//! therefore get bit-identical new vertices on it. The clipped polygon is fanned from its first
//! vertex. Vertices that end with w ≤ 0 (only the degenerate direction x = y = 0, z = w = 0
//! can) cause the polygon to be dropped.
//!
//! Attributes: [`clip_triangle_barycentric`] also carries each output vertex's barycentric
//! coordinates with respect to the submitted triangle (linear in clip space, so a new vertex
//! gets the f64 interpolation of its edge's barycentrics with the same parameter, not
//! rounded); setup turns them into perspective-correct barycentrics per sample
//! ([`super::setup`]).

use super::transform::ClipVertex;
use crate::limits::GUARD_BAND;

/// A vertex the clipper can cut edges at: its clip-space position and whatever it carries.
pub trait ClipPoint: Copy {
    /// The clip-space position.
    fn clip(&self) -> ClipVertex;
    /// The point at parameter `t` from `inside` toward `outside` whose position is `at`.
    fn between(inside: &Self, outside: &Self, t: f64, at: ClipVertex) -> Self;
}

impl ClipPoint for ClipVertex {
    fn clip(&self) -> ClipVertex {
        *self
    }
    fn between(_: &Self, _: &Self, _: f64, at: ClipVertex) -> Self {
        at
    }
}

/// A clip vertex with its barycentric coordinates in the submitted triangle.
pub type BarycentricVertex = (ClipVertex, [f64; 3]);

impl ClipPoint for BarycentricVertex {
    fn clip(&self) -> ClipVertex {
        self.0
    }
    fn between(inside: &Self, outside: &Self, t: f64, at: ClipVertex) -> Self {
        let (a, b) = (inside.1, outside.1);
        (at, std::array::from_fn(|k| a[k] + t * (b[k] - a[k])))
    }
}

/// Signed distances of a vertex to the six clip planes (inside ≥ 0).
#[inline]
fn plane_distance(plane: usize, v: &[f64; 4]) -> f64 {
    let [x, y, z, w] = *v;
    match plane {
        0 => z + w,              // near
        1 => w - z,              // far
        2 => x + GUARD_BAND * w, // left guard band
        3 => GUARD_BAND * w - x, // right guard band
        4 => y + GUARD_BAND * w, // bottom guard band
        _ => GUARD_BAND * w - y, // top guard band
    }
}

fn to_f64(v: ClipVertex) -> [f64; 4] {
    v.0.map(|c| c as f64)
}

/// Whether all three vertices are inside all planes (the fast path: no clipping needed).
pub fn fully_inside(tri: &[ClipVertex; 3]) -> bool {
    tri.iter().all(|v| {
        let v = to_f64(*v);
        (0..6).all(|p| plane_distance(p, &v) >= 0.0) && v[3] > 0.0
    })
}

/// Clip a triangle; returns the clipped convex polygon (0, or 3 to 9 vertices), in order.
pub fn clip_triangle(tri: &[ClipVertex; 3]) -> Vec<ClipVertex> {
    clip_polygon(tri.to_vec())
}

/// [`clip_triangle`] with each output vertex's barycentric coordinates in `tri` (module doc).
pub fn clip_triangle_barycentric(tri: &[ClipVertex; 3]) -> Vec<BarycentricVertex> {
    let unit = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    clip_polygon((0..3).map(|k| (tri[k], unit[k])).collect())
}

fn clip_polygon<V: ClipPoint>(mut poly: Vec<V>) -> Vec<V> {
    for plane in 0..6 {
        if poly.is_empty() {
            break;
        }
        let d: Vec<f64> = poly
            .iter()
            .map(|v| plane_distance(plane, &to_f64(v.clip())))
            .collect();
        if d.iter().all(|&x| x >= 0.0) {
            continue;
        }
        let mut out = Vec::with_capacity(poly.len() + 1);
        for i in 0..poly.len() {
            let j = (i + 1) % poly.len();
            let (a, b) = (poly[i], poly[j]);
            let (da, db) = (d[i], d[j]);
            if da >= 0.0 {
                out.push(a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                out.push(if da >= 0.0 {
                    intersect(&a, da, &b, db)
                } else {
                    intersect(&b, db, &a, da)
                });
            }
        }
        poly = out;
    }
    if poly.len() < 3 || poly.iter().any(|v| v.clip().0[3] <= 0.0) {
        return Vec::new();
    }
    poly
}

/// The point where the edge from `inside` (distance `di` ≥ 0) to `outside` (`do_` < 0) crosses
/// the plane, computed from the inside vertex so shared edges clip identically.
fn intersect<V: ClipPoint>(inside: &V, di: f64, outside: &V, do_: f64) -> V {
    let t = di / (di - do_);
    let a = to_f64(inside.clip());
    let b = to_f64(outside.clip());
    let at = ClipVertex(std::array::from_fn(|k| (a[k] + t * (b[k] - a[k])) as f32));
    V::between(inside, outside, t, at)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inside_triangle_is_unchanged() {
        let t = [
            ClipVertex([0.0, 0.0, 0.0, 1.0]),
            ClipVertex([0.5, 0.0, 0.0, 1.0]),
            ClipVertex([0.0, 0.5, 0.0, 1.0]),
        ];
        assert!(fully_inside(&t));
        assert_eq!(clip_triangle(&t), t.to_vec());
    }

    #[test]
    fn vertex_at_infinity_becomes_finite() {
        let t = [
            ClipVertex([0.0, 0.0, 0.0, 1.0]),
            ClipVertex([0.5, 0.0, 0.0, 1.0]),
            ClipVertex([1.0, 0.2, 1.0, 0.0]),
        ];
        let p = clip_triangle(&t);
        assert!(p.len() >= 3);
        for v in &p {
            assert!(v.0[3] > 0.0);
            assert!(v.0[0].abs() <= GUARD_BAND as f32 * v.0[3] * 1.0001);
        }
    }

    #[test]
    fn behind_near_plane_is_dropped() {
        let t = [
            ClipVertex([0.0, 0.0, -2.0, 1.0]),
            ClipVertex([0.5, 0.0, -2.0, 1.0]),
            ClipVertex([0.0, 0.5, -2.0, 1.0]),
        ];
        assert!(clip_triangle(&t).is_empty());
    }

    #[test]
    fn barycentrics_follow_the_clipped_vertices() {
        // One vertex behind the near plane: two new vertices on its edges.
        let t = [
            ClipVertex([0.0, 0.0, 0.0, 1.0]),
            ClipVertex([0.5, 0.0, -3.0, 1.0]),
            ClipVertex([0.0, 0.5, 0.0, 1.0]),
        ];
        let plain = clip_triangle(&t);
        let with = clip_triangle_barycentric(&t);
        assert_eq!(plain, with.iter().map(|v| v.0).collect::<Vec<_>>());
        for (v, b) in &with {
            assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-15);
            // The barycentric combination of the input reproduces the position (to f32).
            for k in 0..4 {
                let x: f64 = (0..3).map(|i| b[i] * t[i].0[k] as f64).sum();
                assert!((x - v.0[k] as f64).abs() < 1e-6, "{v:?} {b:?}");
            }
        }
    }

    #[test]
    fn shared_edge_clips_identically_from_both_sides() {
        let a = ClipVertex([0.1, 0.1, -3.0, 1.0]);
        let b = ClipVertex([0.3, -0.2, 0.5, 1.0]);
        let t1 = [a, b, ClipVertex([0.9, 0.9, 0.5, 1.0])];
        let t2 = [b, a, ClipVertex([-0.9, -0.9, 0.5, 1.0])];
        let p1 = clip_triangle(&t1);
        let p2 = clip_triangle(&t2);
        // The only vertices both polygons share are b and the clipped point on edge a–b.
        let common: Vec<_> = p1.iter().filter(|v| p2.contains(v)).collect();
        assert_eq!(common.len(), 2, "{p1:?} {p2:?}");
        assert!(common.contains(&&b));
    }

    /// The six signed distances of one vertex, worked out by hand from the planes of the
    /// module doc (G = 4): near z + w, far w − z, guard bands x + G·w, G·w − x, y + G·w,
    /// G·w − y.
    #[test]
    fn each_plane_distance_is_its_plane() {
        assert_eq!(GUARD_BAND, 4.0);
        let v = [1.0, 2.0, 3.0, 5.0];
        let d: Vec<f64> = (0..6).map(|p| plane_distance(p, &v)).collect();
        assert_eq!(d, [8.0, 2.0, 21.0, 19.0, 22.0, 18.0]);
    }

    /// A vertex on every plane at once is the degenerate direction w = 0: not inside (w must
    /// be positive), and a triangle that keeps it is dropped; one vertex past a guard band
    /// makes the triangle not fully inside.
    #[test]
    fn a_vertex_with_w_zero_is_never_inside_and_drops_its_triangle() {
        let t = [
            ClipVertex([0.0, 0.0, 0.0, 0.0]),
            ClipVertex([0.5, 0.0, 0.0, 1.0]),
            ClipVertex([0.0, 0.5, 0.0, 1.0]),
        ];
        assert!(!fully_inside(&t));
        assert!(clip_triangle(&t).is_empty());
        let past = [t[1], t[2], ClipVertex([4.5, 0.0, 0.0, 1.0])];
        assert!(!fully_inside(&past));
        assert!(fully_inside(&[
            t[1],
            t[2],
            ClipVertex([4.0, 0.0, 0.0, 1.0])
        ]));
    }

    /// A new vertex is computed from the edge's inside vertex (module doc, "Watertightness"):
    /// `a + t·(b − a)`, `t = d_a / (d_a − d_b)`, in f64 and rounded once. The sweep uses edges
    /// whose x nearly cancels where they cross the near plane (x_b ≈ x_a·(1 − n), t = 1/n), so
    /// that the f64 rounding of `t` survives the rounding to f32 and, on a third of them, the
    /// same point computed from the outside vertex differs in its bits: the rule is observable.
    #[test]
    fn new_vertices_are_computed_from_the_inside_vertex() {
        let from = |p: ClipVertex, q: ClipVertex| {
            let (p, q) = (to_f64(p), to_f64(q));
            let (dp, dq) = (plane_distance(0, &p), plane_distance(0, &q));
            let t = dp / (dp - dq);
            ClipVertex(std::array::from_fn(|i| (p[i] + t * (q[i] - p[i])) as f32))
        };
        let (mut edges, mut differ) = (0, 0);
        for n in 2..=40 {
            for s in [0.1f64, 0.3, 0.7, 1.3] {
                let xb = s * (1.0 - n as f64);
                if xb.abs() > GUARD_BAND {
                    continue;
                }
                let a = ClipVertex([s as f32, 0.25, 0.0, 1.0]);
                let b = ClipVertex([xb as f32, 0.25, -(n as f32), 1.0]);
                let c = ClipVertex([0.5, 0.9, 0.5, 1.0]);
                // a and c are inside, b is behind the near plane: the new vertices lie on a–b
                // and b–c, each from its inside end.
                let poly = clip_triangle(&[a, b, c]);
                assert_eq!(poly, vec![a, from(a, b), from(c, b), c], "n {n} s {s}");
                edges += 1;
                differ += usize::from(from(a, b) != from(b, a));
            }
        }
        assert_eq!(edges, 60);
        assert!(
            differ >= 10,
            "{differ} of {edges} edges tell the two ends apart"
        );
    }
}
