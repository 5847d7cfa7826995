//! The light occlusion geometry of penumbra-wedges blending (Forest, Barthe & Paulin 2006,
//! §3.1 Fig. 6, §4.2, §4.3): a rectangular light split into four radial parts, and per part the
//! area and the bounding rectangle of the light region one silhouette edge occludes.
//!
//! # The radial split (§3.1, Fig. 6)
//! The light square `[−1, 1]²` (light space of §4.2, [`RectLight`]) is cut by the two axes
//! through its center into four quadrants, numbered counter-clockwise from `s ≥ 0, t ≥ 0`
//! ([`PART_SIGNS`]). The paper only says "dividing the light area in four parts using a radial
//! subdivision" and that "the occlusion area is now integrated independently from the center
//! and per radial part". The quadrants are the radial subdivision for which both hold
//! exactly: every part has the light center as a corner, so the integration from the center
//! of Paper III (hard shadow from the center, then per edge the signed area beyond the edge as
//! seen from the center) is valid per part unchanged — for any region R of the light, the
//! signed areas of R beyond each projected edge sum to ∫_R (w(x) − w(c)) over the winding
//! number w of the projected silhouette, and the hard pass adds w(c) — and every part is an
//! axis-aligned square, so the §4.2 clip "in 2D to the light borders" by saturation applies to
//! a part as it does to the light, and a part's bounding rectangle of the occluded region is
//! axis-aligned in light space as the rectangles of Fig. 10 are.
//!
//! Each part has **part-local coordinates** `(x, y) = (σ_s·s, σ_t·t)` in `[0, 1]²`, the light
//! center at `(0, 0)` and the light's outer corner at `(1, 1)`: the mirror images of one
//! another, so one rule serves all four ("the maximum in X and Y of the occluding edges",
//! §4.3 Fig. 10, is the maximum away from the center), and the packed 8-bit rectangle
//! coordinates of §4.3 span a whole part (255 steps over half the light's side).
//!
//! # One edge at one receiver (§4.2, §4.3)
//! [`edge_in_parts`]: the edge is clipped to the local near plane and projected onto the light
//! plane ([`projected_edge_near_clipped`], Fig. 9), clipped in 2D to the light borders by
//! saturation and the edge's line equation ([`clip_by_saturation`]: "we use the instruction
//! MOV_SSAT to clip the x and y to the [−1..1] range and we compute their corresponding y and
//! x coordinates using the linear equations of the edges"), then clipped the same way to each
//! radial part ("we first clip the edge in the radial part; a dynamic branching is used to
//! avoid computation when the edge does not intersect the current radial part"). In the part,
//! the occluded region of the edge is the part of the square beyond the clipped edge as seen
//! from the center ([`RegionBeyondEdge`]): its area is the occluded light percentage of the
//! part (the sector-minus-triangle of Paper IV §4.2.2, computed exactly as a polygon here), and
//! its bounding box is what §4.3 combines into the part's bounding rectangle.
//!
//! The projection, the clipping and the regions are f64 (module doc of
//! [`crate::methods::wedge_blending`], "Shader precision"); the rectangles are f32 because
//! they are what the vBuffers store, and their arithmetic ([`BoundingRect::area`],
//! [`BoundingRect::center`], [`RegionBeyondEdge::bounds`]) is the blending program's, in its
//! scalar.

use super::coverage::{projected_edge_near_clipped, RectLight};
use crate::gpu::shader_float::ShaderFloat;
use crate::gpu::shader_vec::SVec2;
use glam::{DVec2, DVec3};

/// Number of radial parts (§3.1).
pub const PART_COUNT: usize = 4;

/// The signs `(σ_s, σ_t)` of the light coordinates in each part, counter-clockwise from the
/// `s ≥ 0, t ≥ 0` quadrant (module doc).
pub const PART_SIGNS: [[f64; 2]; PART_COUNT] = [[1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0], [1.0, -1.0]];

/// The local near plane of §4.2 (Fig. 9) as a fraction of the receiver's distance from the
/// light plane ([`projected_edge_near_clipped`]): 2⁻²⁰ drops only edge points within about a
/// millionth of that distance of the receiver's level.
pub const NEAR_FRACTION: f64 = 1.0 / (1u64 << 20) as f64;

/// Light coordinates `(s, t)` in the part-local coordinates of part `k` (module doc).
pub fn to_part(k: usize, st: DVec2) -> DVec2 {
    DVec2::new(PART_SIGNS[k][0] * st.x, PART_SIGNS[k][1] * st.y)
}

/// An axis-aligned rectangle in part-local coordinates, f32 as the vBuffers store it.
/// Empty when `left > right` or `bottom > top` ([`BoundingRect::EMPTY`]); a rectangle of zero
/// width or height is not empty.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct BoundingRect {
    /// Smallest x.
    pub left: f32,
    /// Smallest y.
    pub bottom: f32,
    /// Largest x.
    pub right: f32,
    /// Largest y.
    pub top: f32,
}

impl BoundingRect {
    /// The empty rectangle (what a cleared vBuffer holds).
    pub const EMPTY: BoundingRect = BoundingRect {
        left: 1.0,
        bottom: 1.0,
        right: 0.0,
        top: 0.0,
    };

    /// The whole part `[0, 1]²`.
    pub const FULL: BoundingRect = BoundingRect {
        left: 0.0,
        bottom: 0.0,
        right: 1.0,
        top: 1.0,
    };

    /// Whether the rectangle holds no point.
    pub fn is_empty(&self) -> bool {
        self.left > self.right || self.bottom > self.top
    }

    /// The area (0 for an empty rectangle), computed in the fragment program's scalar `S`
    /// (at most fp32, [`ShaderFloat::AtMostFp32`]).
    pub fn area<S: ShaderFloat>(&self) -> S {
        if self.is_empty() {
            return S::zero();
        }
        let [l, b, r, t] = [self.left, self.bottom, self.right, self.top].map(read::<S>);
        (r - l) * (t - b)
    }

    /// The smallest rectangle holding both ("combine it with the bounding rectangle computed
    /// previously", §3.1; "the combination of the silhouette and the final vBuffer bounding
    /// rectangle", §3.2).
    pub fn union(&self, o: &BoundingRect) -> BoundingRect {
        if self.is_empty() {
            return *o;
        }
        if o.is_empty() {
            return *self;
        }
        BoundingRect {
            left: self.left.min(o.left),
            bottom: self.bottom.min(o.bottom),
            right: self.right.max(o.right),
            top: self.top.max(o.top),
        }
    }

    /// The intersection (possibly empty).
    pub fn intersection(&self, o: &BoundingRect) -> BoundingRect {
        if self.is_empty() || o.is_empty() {
            return BoundingRect::EMPTY;
        }
        BoundingRect {
            left: self.left.max(o.left),
            bottom: self.bottom.max(o.bottom),
            right: self.right.min(o.right),
            top: self.top.min(o.top),
        }
    }

    /// The center, computed in `S` as [`BoundingRect::area`].
    pub fn center<S: ShaderFloat>(&self) -> [S; 2] {
        let half = S::from_f64(0.5);
        [
            half * (read::<S>(self.left) + read(self.right)),
            half * (read::<S>(self.bottom) + read(self.top)),
        ]
    }
}

/// A stored f32 value as a fragment program computing in `S` reads it.
pub fn read<S: ShaderFloat>(x: f32) -> S {
    S::from_f64(x as f64)
}

/// A value of `S` as an f32 field stores it: exact when `S` is at most fp32
/// ([`ShaderFloat::AtMostFp32`]).
pub fn stored<S: ShaderFloat>(x: S) -> f32 {
    x.to_f64() as f32
}

/// The occluded region one edge gives in one part: the part of the square beyond the clipped
/// edge as seen from the light center (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RegionBeyondEdge {
    /// The edge clipped to the part, part-local coordinates.
    pub chord: [DVec2; 2],
    /// The region's area as a fraction of the part (the part's area is 1 in part-local units).
    pub area: f64,
    /// Its bounding box, lower-left and upper-right corners ([`RegionBeyondEdge::bounds`]).
    pub extent: [DVec2; 2],
    /// Its first moment `∫ (x, y) dA` (the center of gravity times the area, §6).
    pub moment: DVec2,
}

impl RegionBeyondEdge {
    /// The region beyond the chord `a b` of the part `[0, 1]²` (both points in the part), or
    /// `None` when the chord's line passes through the center (the receiver is in the plane of
    /// the edge's hard shadow quad: nothing is covered, as [`super::coverage`]'s exact
    /// coverage is 0 there).
    pub fn new(a: DVec2, b: DVec2) -> Option<Self> {
        Self::in_shader::<f64>(a, b)
    }

    /// [`RegionBeyondEdge::new`] computed by the half-wedge fragment program in the shader
    /// precision `T` (`[options.gpu] shader`): the chord's ends rounded to `T`, every
    /// operation of the polygon, its area, first moment and bounding box rounded; the fields
    /// hold the `T` values exactly.
    pub fn in_shader<T: ShaderFloat>(a: DVec2, b: DVec2) -> Option<Self> {
        let (a, b) = (SVec2::<T>::from_f64(a), SVec2::from_f64(b));
        let (zero, one) = (T::zero(), T::one());
        let cross = a.perp_dot(b);
        if cross == zero || !cross.is_finite() {
            return None;
        }
        // The ray from the center through q leaves the part where its larger coordinate is 1.
        let exit = |q: SVec2<T>| q / q.x.max(q.y);
        let corner = SVec2::new(one, one);
        let corner_between = a.perp_dot(corner) * cross > zero && corner.perp_dot(b) * cross > zero;
        let mut poly = [SVec2::new(zero, zero); 5];
        let mut n = 0;
        for q in [a, b, exit(b)] {
            poly[n] = q;
            n += 1;
        }
        if corner_between {
            poly[n] = corner;
            n += 1;
        }
        poly[n] = exit(a);
        n += 1;
        let poly = &poly[..n];
        let mut twice_area = zero;
        let mut moment6 = SVec2::new(zero, zero);
        for i in 0..n {
            let (p, q) = (poly[i], poly[(i + 1) % n]);
            let c = p.perp_dot(q);
            twice_area = twice_area + c;
            moment6 = moment6 + (p + q) * c;
        }
        let sign = twice_area.signum();
        let (lo, hi) = poly.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), q| (lo.min(q.to_f64()), hi.max(q.to_f64())),
        );
        Some(RegionBeyondEdge {
            chord: [a.to_f64(), b.to_f64()],
            area: (T::from_f64(0.5) * twice_area * sign).to_f64(),
            extent: [lo, hi],
            moment: (moment6 * (sign / T::from_f64(6.0))).to_f64(),
        })
    }
}

impl RegionBeyondEdge {
    /// Its bounding box as a fragment program computing in `S` (at most fp32,
    /// [`ShaderFloat::AtMostFp32`]) holds it: each corner rounded to `S`, stored as f32.
    pub fn bounds<S: ShaderFloat>(&self) -> BoundingRect {
        let [lo, hi] = self.extent;
        let at = |x: f64| stored(S::from_f64(x));
        BoundingRect {
            left: at(lo.x),
            bottom: at(lo.y),
            right: at(hi.x),
            top: at(hi.y),
        }
    }
}

/// The segment `a b` clipped to the box `[lo, hi]` the way §4.2 describes for the light
/// borders: each endpoint's x is saturated to the box and its y recomputed from the line
/// equation, then its y saturated and its x recomputed (a coordinate is recomputed only where
/// the saturation changed the other); the endpoints keep their order. `None`
/// when the segment misses the box (a recomputed point is off the box or off the line: the
/// "dynamic branch" of §4.3) or is left with zero length.
pub fn clip_by_saturation(a: DVec2, b: DVec2, lo: DVec2, hi: DVec2) -> Option<[DVec2; 2]> {
    let d = b - a;
    // A coordinate is recomputed from the line only where saturation moved the other one, so
    // a point inside the box keeps its bits.
    let saturate = |q: DVec2| {
        let x = q.x.clamp(lo.x, hi.x);
        let y = if x != q.x && d.x != 0.0 {
            a.y + (x - a.x) * (d.y / d.x)
        } else {
            q.y
        };
        let ys = y.clamp(lo.y, hi.y);
        let x = if ys != y && d.y != 0.0 {
            a.x + (ys - a.y) * (d.x / d.y)
        } else {
            x
        };
        DVec2::new(x, ys)
    };
    let scale = 1.0 + a.abs().max_element().max(b.abs().max_element());
    let tol = 1e-12 * scale;
    let valid = |q: DVec2| {
        let in_box = q.cmpge(lo - tol).all() && q.cmple(hi + tol).all();
        let on_line = d.perp_dot(q - a).abs() <= tol * d.length();
        in_box && on_line
    };
    let (ca, cb) = (saturate(a), saturate(b));
    if !valid(ca) || !valid(cb) {
        return None;
    }
    let (ca, cb) = (ca.clamp(lo, hi), cb.clamp(lo, hi));
    (ca != cb).then_some([ca, cb])
}

/// The occluded region of every radial part for the silhouette edge `e0 e1` seen from the
/// receiver `p` (module doc), `None` for the parts the edge does not reach. The unsigned area
/// of each region is the part's occluded light percentage from this edge; whether it is added
/// (outer half-wedge) or subtracted (inner) is the caller's.
///
/// The region of each part is computed in the shader precision `T`
/// ([`RegionBeyondEdge::in_shader`]); the projection and the clipping are f64 (module doc).
pub fn edge_in_parts<T: ShaderFloat>(
    light: &RectLight,
    p: DVec3,
    e0: DVec3,
    e1: DVec3,
) -> [Option<RegionBeyondEdge>; PART_COUNT] {
    let mut out = [None; PART_COUNT];
    let Some([a, b]) = projected_edge_near_clipped(light, p, e0, e1, NEAR_FRACTION) else {
        return out;
    };
    let Some([a, b]) = clip_by_saturation(a, b, DVec2::splat(-1.0), DVec2::ONE) else {
        return out;
    };
    for (k, slot) in out.iter_mut().enumerate() {
        *slot = clip_by_saturation(to_part(k, a), to_part(k, b), DVec2::ZERO, DVec2::ONE)
            .and_then(|[ca, cb]| RegionBeyondEdge::in_shader::<T>(ca, cb));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::shader_float::Fp32;
    use crate::light::coverage::edge_coverage_exact;
    use proptest::prelude::*;

    #[test]
    fn region_beyond_a_chord_across_the_part() {
        // The chord from (0.5, 0) to (0, 0.5): the part minus the triangle (0,0),(0.5,0),(0,0.5).
        let r = RegionBeyondEdge::new(DVec2::new(0.5, 0.0), DVec2::new(0.0, 0.5)).unwrap();
        assert!((r.area - 0.875).abs() < 1e-15, "{}", r.area);
        assert_eq!(r.bounds::<Fp32>(), BoundingRect::FULL);
        // Reversing the chord does not change the region.
        let s = RegionBeyondEdge::new(DVec2::new(0.0, 0.5), DVec2::new(0.5, 0.0)).unwrap();
        assert!((s.area - r.area).abs() < 1e-15);
        // Centroid of the part (1/2, 1/2) minus the triangle's (1/6, 1/6) weighted by 1/8.
        let expected = (DVec2::splat(0.5) - DVec2::splat(1.0 / 6.0) * 0.125) / 0.875;
        assert!((r.moment / r.area - expected).length() < 1e-14);
    }

    #[test]
    fn region_beyond_a_short_chord_is_its_sector_part() {
        // Chord from (0.5, 0.1) to (0.5, 0.3) (vertical, x = 0.5): rays to (1, 0.2) and
        // (1, 0.6); the region is the trapezoid between x = 0.5 and x = 1.
        let r = RegionBeyondEdge::new(DVec2::new(0.5, 0.1), DVec2::new(0.5, 0.3)).unwrap();
        let expected = 0.5 * (0.2 + 0.4) * 0.5;
        assert!((r.area - expected).abs() < 1e-15);
        assert_eq!(r.bounds::<Fp32>().left, 0.5);
        assert_eq!(r.bounds::<Fp32>().right, 1.0);
        assert_eq!(r.bounds::<Fp32>().bottom, 0.1);
        assert!((r.bounds::<Fp32>().top - 0.6).abs() < 1e-7);
        assert!(RegionBeyondEdge::new(DVec2::new(0.2, 0.2), DVec2::new(0.4, 0.4)).is_none());
    }

    #[test]
    fn saturation_clip_matches_the_box() {
        let lo = DVec2::splat(-1.0);
        let hi = DVec2::ONE;
        // Crossing from left to right.
        let [a, b] =
            clip_by_saturation(DVec2::new(-3.0, 0.0), DVec2::new(3.0, 0.6), lo, hi).unwrap();
        assert!((a - DVec2::new(-1.0, 0.2)).length() < 1e-15);
        assert!((b - DVec2::new(1.0, 0.4)).length() < 1e-15);
        // Entering through the top after x saturation.
        let [a, _] =
            clip_by_saturation(DVec2::new(-2.0, 3.0), DVec2::new(0.0, -1.0), lo, hi).unwrap();
        assert!((a - DVec2::new(-1.0, 1.0)).length() < 1e-15, "{a}");
        // Missing the box: line passes by a corner; horizontal and vertical lines outside.
        assert!(clip_by_saturation(DVec2::new(-3.0, 0.0), DVec2::new(0.0, 3.0), lo, hi).is_none());
        assert!(clip_by_saturation(DVec2::new(-3.0, 2.0), DVec2::new(3.0, 2.0), lo, hi).is_none());
        assert!(clip_by_saturation(DVec2::new(2.0, -3.0), DVec2::new(2.0, 3.0), lo, hi).is_none());
        // Both endpoints beyond the same border: nothing left.
        assert!(clip_by_saturation(DVec2::new(2.0, 0.0), DVec2::new(3.0, 0.5), lo, hi).is_none());
        // Inside: unchanged.
        let (p, q) = (DVec2::new(0.1, 0.2), DVec2::new(-0.3, 0.9));
        assert_eq!(clip_by_saturation(p, q, lo, hi), Some([p, q]));
    }

    fn light() -> RectLight {
        RectLight::new(
            DVec3::new(0.2, 3.0, -0.1),
            DVec3::new(0.6, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 0.4),
        )
    }

    proptest! {
        /// The four parts' areas sum to the exact coverage of the whole light (Paper III
        /// §3.2.2's clipping), for edges anywhere between the receiver and the light.
        #[test]
        fn parts_sum_to_the_exact_coverage(
            p in (-2.0f64..2.0, -1.0f64..0.5, -2.0f64..2.0),
            e0 in (-1.5f64..1.5, 0.6f64..2.8, -1.5f64..1.5),
            e1 in (-1.5f64..1.5, 0.6f64..2.8, -1.5f64..1.5),
        ) {
            let l = light();
            let (p, e0, e1) = (DVec3::from(p), DVec3::from(e0), DVec3::from(e1));
            let exact = edge_coverage_exact(&l, p, e0, e1).abs();
            let parts: f64 = edge_in_parts::<f64>(&l, p, e0, e1)
                .iter()
                .flatten()
                .map(|r| r.area)
                .sum::<f64>() / PART_COUNT as f64;
            prop_assert!((parts - exact).abs() < 1e-9, "parts {} exact {}", parts, exact);
        }

        /// A region lies in its bounding box, and the box in the part.
        #[test]
        fn region_is_inside_its_bounds(
            a in (0.0f64..=1.0, 0.0f64..=1.0),
            b in (0.0f64..=1.0, 0.0f64..=1.0),
        ) {
            let (a, b) = (DVec2::from(a), DVec2::from(b));
            if let Some(r) = RegionBeyondEdge::new(a, b) {
                let bx = r.bounds::<Fp32>();
                prop_assert!(bx.left >= 0.0 && bx.bottom >= 0.0 && bx.right <= 1.0 && bx.top <= 1.0);
                prop_assert!(r.area <= bx.area::<Fp32>().to_f64() + 1e-6);
                let c = r.moment / r.area.max(1e-300);
                if r.area > 1e-9 {
                    prop_assert!(c.x >= bx.left as f64 - 1e-6 && c.x <= bx.right as f64 + 1e-6);
                    prop_assert!(c.y >= bx.bottom as f64 - 1e-6 && c.y <= bx.top as f64 + 1e-6);
                }
            }
        }
    }
}
