//! The one convex-polygon clip of the crate: Sutherland & Hodgman's reentrant polygon clipping
//! ("Reentrant Polygon Clipping", CACM 1974), one half-space at a time, generic over the vertex
//! type and over the scalar (f64, or a shader precision of `gpu::shader_float`, whose every
//! operation rounds), so the fragment programs of `light::coverage` round each step as a GPU
//! would while the scene checks and the near-plane geometry clip in f64 with the same rule.
//!
//! The rule: a vertex with signed distance `dist ≥ 0` is kept (the boundary is inside); an
//! edge whose ends lie on opposite sides gets the new vertex `a + (b − a)·(dₐ / (dₐ − d_b))`.
//! A point or a segment passed as a polygon clips as one (an empty result: nothing is inside).

use glam::DVec2;
use std::ops::{Add, Div, Mul, Sub};

/// A scalar the clip computes with: comparable, with subtraction and division, and `0` as
/// its default (f64 and every shader precision).
pub trait ClipScalar:
    Copy + PartialOrd + Sub<Output = Self> + Div<Output = Self> + Default
{
}

impl<T: Copy + PartialOrd + Sub<Output = T> + Div<Output = T> + Default> ClipScalar for T {}

/// A vertex the clip interpolates: copied, subtracted, added and scaled by its scalar `T`
/// (a point or a point with attributes, in f64 or a shader precision).
pub trait ClipVertex<T>:
    Copy + Sub<Output = Self> + Add<Output = Self> + Mul<T, Output = Self>
{
}

impl<T, V: Copy + Sub<Output = V> + Add<Output = V> + Mul<T, Output = V>> ClipVertex<T> for V {}

/// Where the edge `a b`, at signed distances `da` and `db` of opposite signs, crosses
/// `dist = 0`: the module's one interpolation rule.
#[inline]
fn crossing<V: ClipVertex<T>, T: ClipScalar>(a: V, b: V, da: T, db: T) -> V {
    a + (b - a) * (da / (da - db))
}

/// One Sutherland–Hodgman step: keep the part of `poly` where `dist ≥ 0`.
pub fn clip_polygon<V, T, F>(poly: &[V], dist: F) -> Vec<V>
where
    V: ClipVertex<T>,
    T: ClipScalar,
    F: Fn(V) -> T,
{
    let mut out = Vec::with_capacity(poly.len() + 2);
    clip_polygon_into(poly, dist, |x| x, |x| out.push(x));
    out
}

/// [`clip_polygon`], handing the result's vertices in order to `emit`, and each vertex the
/// clip creates through `cut` first.
pub fn clip_polygon_into<V, T, F, M>(poly: &[V], dist: F, cut: M, mut emit: impl FnMut(V))
where
    V: ClipVertex<T>,
    T: ClipScalar,
    F: Fn(V) -> T,
    M: Fn(V) -> V,
{
    let zero = T::default();
    let Some(&first) = poly.first() else {
        return;
    };
    // Each vertex's distance is evaluated once and carried to the next edge.
    let d_first = dist(first);
    let (mut a, mut da) = (first, d_first);
    for i in 1..=poly.len() {
        let (b, db) = match poly.get(i) {
            Some(&b) => (b, dist(b)),
            None => (first, d_first),
        };
        if da >= zero {
            emit(a);
        }
        if (da >= zero) != (db >= zero) {
            emit(cut(crossing(a, b, da, db)));
        }
        (a, da) = (b, db);
    }
}

/// Clip the segment `a b` to `dist ≥ 0` in place; `None` when nothing is left.
pub fn clip_segment<V, T, F>(a: &mut V, b: &mut V, dist: F) -> Option<()>
where
    V: ClipVertex<T>,
    T: ClipScalar,
    F: Fn(V) -> T,
{
    clip_segment_marking(a, b, dist, |x| x)
}

/// [`clip_segment`], passing an end the clip moves through `cut`.
pub fn clip_segment_marking<V, T, F, M>(a: &mut V, b: &mut V, dist: F, cut: M) -> Option<()>
where
    V: ClipVertex<T>,
    T: ClipScalar,
    F: Fn(V) -> T,
    M: Fn(V) -> V,
{
    let zero = T::default();
    let (da, db) = (dist(*a), dist(*b));
    match (da >= zero, db >= zero) {
        (true, true) => Some(()),
        (false, false) => None,
        (true, false) => {
            *b = cut(crossing(*a, *b, da, db));
            Some(())
        }
        (false, true) => {
            *a = cut(crossing(*a, *b, da, db));
            Some(())
        }
    }
}

/// The part of a convex polygon inside the axis-aligned box `[lo, hi]` (Sutherland–Hodgman).
pub fn clip_polygon_to_box(poly: &[DVec2], lo: DVec2, hi: DVec2) -> Vec<DVec2> {
    let mut out = clip_polygon(poly, |p: DVec2| p.x - lo.x);
    out = clip_polygon(&out, |p: DVec2| hi.x - p.x);
    out = clip_polygon(&out, |p: DVec2| p.y - lo.y);
    clip_polygon(&out, |p: DVec2| hi.y - p.y)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The box keeps what is inside, boundary included, and clips a triangle poking out to
    /// the exact crossing points.
    #[test]
    fn the_box_clip_keeps_the_inside_and_cuts_at_the_crossings() {
        let (lo, hi) = (DVec2::splat(-1.0), DVec2::splat(1.0));
        let tri = [
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(0.0, 1.0),
        ];
        let out = clip_polygon_to_box(&tri, lo, hi);
        assert!(out.contains(&DVec2::new(1.0, 0.0)), "{out:?}");
        assert!(out.contains(&DVec2::new(1.0, 0.5)), "{out:?}");
        assert!(out.iter().all(|p| p.x <= 1.0 && p.y <= 1.0), "{out:?}");
        assert_eq!(
            clip_polygon_to_box(&[DVec2::new(1.0, 1.0)], lo, hi).len(),
            1
        );
        assert!(clip_polygon_to_box(&[DVec2::new(1.5, 0.0)], lo, hi).is_empty());
        let segment = [DVec2::new(2.0, 0.0), DVec2::new(0.0, 0.5)];
        assert!(!clip_polygon_to_box(&segment, lo, hi).is_empty());
    }

    /// A segment clipped to a half-space: moved to the crossing, or gone.
    #[test]
    fn a_segment_is_cut_at_the_plane_or_dropped() {
        let (mut a, mut b) = (DVec2::new(-1.0, 0.0), DVec2::new(3.0, 0.0));
        assert!(clip_segment(&mut a, &mut b, |p: DVec2| p.x).is_some());
        assert_eq!((a, b), (DVec2::new(0.0, 0.0), DVec2::new(3.0, 0.0)));
        let (mut a, mut b) = (DVec2::new(-1.0, 0.0), DVec2::new(-3.0, 0.0));
        assert!(clip_segment(&mut a, &mut b, |p: DVec2| p.x).is_none());
    }

    /// The light-shape check's cases (`scene::validate`): points, segments and triangles
    /// against the square [−1, 1]².
    #[test]
    fn points_segments_and_triangles_against_the_unit_square() {
        let meets = |p: &[[f64; 2]]| {
            let p: Vec<DVec2> = p.iter().map(|&q| DVec2::from(q)).collect();
            !clip_polygon_to_box(&p, DVec2::splat(-1.0), DVec2::ONE).is_empty()
        };
        assert!(!meets(&[[2.0, 0.0], [3.0, 5.0]]));
        assert!(meets(&[[2.0, 0.0], [0.0, 0.5]]));
        assert!(meets(&[[0.5, 0.5]]));
        assert!(!meets(&[[1.5, 0.5]]));
        assert!(
            meets(&[[-9.0, -9.0], [9.0, -9.0], [0.0, 9.0]]),
            "a triangle around it"
        );
        assert!(!meets(&[[2.0, 2.0], [3.0, 2.0], [2.0, 3.0]]));
    }
}
