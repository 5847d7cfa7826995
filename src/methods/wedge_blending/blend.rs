//! The per-radial-part arithmetic of penumbra-wedges blending (Forest, Barthe & Paulin 2006):
//! what one silhouette vBuffer fragment holds (§3.1, §4.3), how each half-wedge fragment
//! updates it, and the blending function that folds it into the final vBuffer (§3.2), with the
//! center-of-gravity refinement the paper proposes in §6.
//!
//! # One part of one silhouette vBuffer pixel ([`PartState`])
//! * `occlusion`: the occluded fraction of the part. The shadow-volume pass initializes it to
//!   the silhouette's hard count from the light center ("coefficients one and zero are
//!   affected respectively to shaded and unshaded fragments", §2); every outer half-wedge
//!   fragment adds its edge's area beyond the edge, every inner one subtracts it (§3.1, §4.3).
//! * `rect`: the bounding rectangle of the occluded region. The hard pass sets it to the whole
//!   part where the center is shaded (the whole light is occluded there as far as the hard
//!   shadow knows), empty elsewhere; outer half-wedges grow it by the bounding box of their
//!   region (§4.3: "we first compute a rectangle that bounds the occluded light region defined
//!   by the outer-half-wedges").
//! * `max_edge`: the maximum X and Y (part-local, away from the center) of the inner
//!   half-wedges' clipped edges (§4.3, Fig. 10: "for the inner-half-wedges bounding rectangle
//!   adjustment, we need the maximum in X and Y of the silhouette edges"). `(0, 0)`: no inner
//!   edge reached the part.
//! * `centroid`: the center of gravity of the occluded region (§6, option).
//!
//! **The inner adjustment** ([`PartState::occluded_rect`]). The inner half-wedges bound the
//! *inner penumbra* (§2, Fig. 3): in the silhouette's hard shadow the center is occluded and
//! the occluded region of a part is the part minus the regions beyond the inner edges — it
//! runs from the center to those edges, and `[0, max X] × [0, max Y]` bounds it whenever the
//! silhouette's boundary crosses the part's whole angle (where the boundary leaves through the
//! part's outer border, the clipped edge ends on that border and the maximum is 1). So the
//! rectangle (the whole part, from the shadow-volume pass) is clipped on its far sides:
//! `right = min(right, max X)`, `top = min(top, max Y)`. Outside the hard shadow, the inner
//! half-wedges a fragment meets are those of the far side of the occluder, which bound the
//! outer rectangle the same way. The paper does not say when the adjustment is made; the
//! maximum is only complete after the last inner half-wedge, so it is applied when the
//! rectangle is read (by the blend pass), from the two stored values — the paper's storage.
//!
//! The maximum of the edges *in the part* does not bound the region when the region reaches
//! the part's border where no edge crosses it: in the hard shadow, a boundary that covers only
//! part of the part's angle (the rest of the part is occluded to its border); outside it, a
//! region that leaves the part through its outer border (the far edges are then outside the
//! part and the inner edges left in it are the sides). The clipped rectangle is then too
//! small, the overlap ε too small, and the blended occlusion too large. Such a rectangle is
//! often *smaller than the occluded area it must bound*, which is impossible for a bounding
//! rectangle, so the default (`adjust = checked`) keeps the unclipped rectangle where the
//! clipped one's area is below the part's occlusion (by more than 8-bit rounding explains,
//! [`AREA_CHECK_SLACK`]); `always` is the literal reading and
//! `never` skips the adjustment. Measured (`penumbra experiment wedge-blending`), RMSE vs
//! `raycast` at 256², f32: `cube-of-spheres` 0.0246 checked, 0.0270 always, 0.0263 never;
//! `forest-spheres` 0.0268 checked, 0.0290 always, 0.0286 never.
//!
//! # Blending (§3.2)
//! Per part, with `A` the occlusion and `B` the area of the (adjusted) rectangle of the final
//! (f) and silhouette (s) vBuffers, and β the area of the two rectangles' intersection:
//! `ε = (A_f/B_f)·(A_s/B_s)·β`, `A = A_f + A_s − ε`, rectangle = union. Choices:
//! * the ratios `A/B` are clamped to [0, 1] (an occluded area cannot exceed its bounding
//!   rectangle; quantization or a clamped sum can make it look so), and are 1 for an empty
//!   rectangle (then β = 0 and ε = 0 anyway);
//! * the result is limited to 1: a part cannot be more than fully occluded. Where a
//!   rectangle underestimates its region (the inner adjustment above, quantization) ε is too
//!   small and the sum would pass 1; the packed storage clamps it there anyway (PK4UB
//!   saturates), and the unpacked variant does the same so that the two differ only by
//!   quantization and the clamps inside the silhouette vBuffer;
//! * the dynamic branch of §4.3: ε is computed only where both occlusions are positive; where
//!   the final one is 0 the silhouette's part is copied; where the silhouette's is 0 nothing
//!   happens. A negative occlusion (a silhouette loop that bounds a hole, whose hard count from
//!   the center is −1) can only reach here unpacked (PK4UB clamps it to 0); it is added
//!   without ε so the Green sum over the loops stays exact, and the rectangle is left as is.
//!
//! # Shader precision
//! Every function here computes in the fragment program's scalar `S`, the shader precision
//! capped at fp32 ([`ShaderFloat::AtMostFp32`]; the method's module doc, "Shader
//! precision"): the stored f32 values are read as `S` ([`read`]), every operation rounds,
//! and results are stored as f32 ([`stored`], exact). Unions, intersections, clamps and
//! comparisons are exact in every format.
//!
//! # Center of gravity (§6, `centroid = on`)
//! §6 proposes to "weight the bounding rectangles intersection area" by the center of gravity
//! of the occluded area, stored as one of 256 positions per part. The paper gives no formula;
//! ours: each occluded region is modelled as a rectangle of its own area `A` with the shape of
//! its bounding rectangle (scaled by √(A/B)), centered at its center of gravity and moved inside
//! the bounding rectangle, and ε is the area where the two model rectangles overlap. Where an
//! occlusion fills its rectangle (A = B) this is β, as without the centroid. The centroid is
//! kept through the passes as a first moment: `occlusion · centroid` plus or minus the
//! region's moment, divided by the new occlusion; the blend combines the two centroids
//! weighted by their occlusions minus ε at the overlap's center.

use crate::gpu::shader_float::ShaderFloat;
use crate::light::radial_parts::{read, stored, BoundingRect, RegionBeyondEdge};

/// One radial part of a vBuffer pixel (module doc).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PartState {
    /// Occluded fraction of the part (may leave [0, 1] unpacked).
    pub occlusion: f32,
    /// Bounding rectangle of the occluded region, part-local coordinates.
    pub rect: BoundingRect,
    /// Maximum X and Y of the inner half-wedges' clipped edges; `[0, 0]`: none.
    pub max_edge: [f32; 2],
    /// Center of gravity of the occluded region (part-local; meaningful where occlusion > 0).
    pub centroid: [f32; 2],
}

/// What the blending function did with one part ([`blend_part`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BlendCase {
    /// The silhouette's occlusion is 0: nothing to do.
    Skipped,
    /// The final occlusion was 0: the silhouette's part was copied.
    Copied,
    /// Both positive: ε computed and subtracted (§3.2).
    Blended,
    /// One of them negative (unpacked only): added without ε.
    Accumulated,
}

impl PartState {
    /// A cleared part: nothing occluded, empty rectangle.
    pub const CLEARED: PartState = PartState {
        occlusion: 0.0,
        rect: BoundingRect::EMPTY,
        max_edge: [0.0, 0.0],
        centroid: [0.0, 0.0],
    };

    /// The part after the silhouette's shadow-volume pass with signed count `count` from the
    /// light center: occlusion = count; the whole part as rectangle where shaded.
    pub fn hard(count: i32) -> PartState {
        if count == 0 {
            return PartState::CLEARED;
        }
        PartState {
            occlusion: count as f32,
            rect: if count > 0 {
                BoundingRect::FULL
            } else {
                BoundingRect::EMPTY
            },
            max_edge: [0.0, 0.0],
            centroid: [0.5, 0.5],
        }
    }

    /// Move the center of gravity for a change of `delta_area` with first moment
    /// `delta_moment` (module doc, "Center of gravity").
    fn shift_centroid<S: ShaderFloat>(&mut self, delta_area: S, delta_moment: [S; 2]) {
        let occlusion = read::<S>(self.occlusion);
        let total = occlusion + delta_area;
        if total > S::zero() {
            let m = occlusion.max(S::zero());
            self.centroid = [0, 1].map(|k| {
                let c = (m * read(self.centroid[k]) + delta_moment[k]) / total;
                stored(c.clamp(S::zero(), S::one()))
            });
        }
    }

    /// An outer half-wedge fragment (§4.3): add the region's area, grow the rectangle; in the
    /// program's scalar `S` (module doc, "Shader precision").
    pub fn add_outer<S: ShaderFloat>(&mut self, r: &RegionBeyondEdge) {
        let area = S::from_f64(r.area);
        self.shift_centroid(area, [S::from_f64(r.moment.x), S::from_f64(r.moment.y)]);
        self.occlusion = stored(read::<S>(self.occlusion) + area);
        self.rect = self.rect.union(&r.bounds::<S>());
    }

    /// An inner half-wedge fragment (§4.3): subtract the region's area, raise the maximum X
    /// and Y of the occluding edges; in the program's scalar `S`.
    pub fn add_inner<S: ShaderFloat>(&mut self, r: &RegionBeyondEdge) {
        let area = S::from_f64(r.area);
        let moment = [-S::from_f64(r.moment.x), -S::from_f64(r.moment.y)];
        self.shift_centroid(-area, moment);
        self.occlusion = stored(read::<S>(self.occlusion) - area);
        for (k, m) in self.max_edge.iter_mut().enumerate() {
            let ends = r.chord.map(|q| S::from_f64(q[k]));
            *m = stored(read::<S>(*m).max(ends[0]).max(ends[1]));
        }
    }

    /// The rectangle with the inner adjustment of Fig. 10 applied as `adjust` says (module
    /// doc, "The inner adjustment"), its area check in the program's scalar `S`.
    pub fn occluded_rect<S: ShaderFloat>(&self, adjust: InnerAdjust) -> BoundingRect {
        let [mx, my] = self.max_edge;
        if (mx == 0.0 && my == 0.0) || adjust == InnerAdjust::Never {
            return self.rect;
        }
        let clipped = BoundingRect {
            right: self.rect.right.min(mx),
            top: self.rect.top.min(my),
            ..self.rect
        };
        let slack = read::<S>(self.occlusion) - read(AREA_CHECK_SLACK);
        if adjust == InnerAdjust::Checked && clipped.area::<S>() < slack {
            return self.rect;
        }
        clipped
    }
}

/// How much smaller than the occlusion an adjusted rectangle's area may be before `checked`
/// rejects it: what 8-bit storage can explain (each of the four coordinates rounded by half a
/// step changes the area of a rectangle inside the unit part by at most 2/255, the occlusion
/// by half a step); a rectangle that fits its region exactly must pass in either storage.
pub const AREA_CHECK_SLACK: f32 = 2.5 / 255.0;

/// How the inner adjustment of Fig. 10 is applied (module doc, "The inner adjustment").
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum InnerAdjust {
    /// Wherever an inner half-wedge reached the part, unless the adjusted rectangle is
    /// smaller than the occluded area it must bound.
    Checked,
    /// Wherever an inner half-wedge reached the part (the literal reading).
    Always,
    /// Never: the rectangle of the shadow-volume pass and the outer half-wedges.
    Never,
}

/// The choices of the blending function.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Rules {
    /// Where the inner adjustment applies.
    pub adjust: InnerAdjust,
    /// Weight the overlap by the centers of gravity (§6).
    pub centroid: bool,
}

/// `A/B` clamped to [0, 1]; 1 for an empty or zero-area rectangle (module doc).
fn fill_ratio<S: ShaderFloat>(occlusion: S, rect: &BoundingRect) -> S {
    let b = rect.area::<S>();
    if b > S::zero() {
        (occlusion / b).clamp(S::zero(), S::one())
    } else {
        S::one()
    }
}

/// The rectangle of area `occlusion` with the shape of `rect`, centered at `centroid` and
/// moved inside `rect` (module doc, "Center of gravity").
fn compact_rect<S: ShaderFloat>(
    occlusion: S,
    rect: &BoundingRect,
    centroid: [f32; 2],
) -> BoundingRect {
    let k = fill_ratio(occlusion, rect).sqrt();
    let half_of = S::from_f64(0.5);
    let [left, bottom, right, top] = [rect.left, rect.bottom, rect.right, rect.top].map(read::<S>);
    let half = [half_of * k * (right - left), half_of * k * (top - bottom)];
    let lo = [left, bottom];
    let hi = [right, top];
    let c: [S; 2] = std::array::from_fn(|i| {
        let (a, b) = (lo[i] + half[i], hi[i] - half[i]);
        if a <= b {
            read::<S>(centroid[i]).clamp(a, b)
        } else {
            half_of * (lo[i] + hi[i])
        }
    });
    BoundingRect {
        left: stored(c[0] - half[0]),
        bottom: stored(c[1] - half[1]),
        right: stored(c[0] + half[0]),
        top: stored(c[1] + half[1]),
    }
}

/// The effective overlapped area ε of two occluded regions (module doc, "Blending"):
/// `(A_f/B_f)·(A_s/B_s)·β`, or with `centroid` the overlap of the two compact model
/// rectangles, in the program's scalar `S` (module doc, "Shader precision"). Returns ε and
/// the center of the overlap.
pub fn overlap_estimate<S: ShaderFloat>(f: &PartState, s: &PartState, rules: Rules) -> (S, [S; 2]) {
    let (rf, rs) = (
        f.occluded_rect::<S>(rules.adjust),
        s.occluded_rect::<S>(rules.adjust),
    );
    let (af, a_s) = (read::<S>(f.occlusion), read::<S>(s.occlusion));
    if rules.centroid {
        let mf = compact_rect(af, &rf, f.centroid);
        let ms = compact_rect(a_s, &rs, s.centroid);
        let overlap = mf.intersection(&ms);
        return (overlap.area(), overlap.center());
    }
    let overlap = rf.intersection(&rs);
    let eps = fill_ratio(af, &rf) * fill_ratio(a_s, &rs) * overlap.area();
    (eps, overlap.center())
}

/// What [`blend_part`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlendOutcome {
    /// Which branch ran.
    pub case: BlendCase,
    /// ε (0 unless [`BlendCase::Blended`]).
    pub eps: f32,
    /// Whether the result exceeded 1 and was limited to it.
    pub limited: bool,
}

/// Blend one part of a silhouette vBuffer pixel `s` into the final vBuffer's `f` (§3.2,
/// module doc). The result's occlusion is limited to 1 (a part cannot be more than fully
/// occluded; the packed storage would clamp it anyway, this makes the unpacked variant do the
/// same so that the two differ only by quantization and the silhouette vBuffer's clamps).
///
/// The arithmetic is the fragment program's, in its scalar `S` (module doc, "Shader
/// precision"); the operands are the stored f32 values and the result is stored as f32.
pub fn blend_part<S: ShaderFloat>(
    f: &PartState,
    s: &PartState,
    rules: Rules,
) -> (PartState, BlendOutcome) {
    let (mut out, case, eps) = blend_unlimited::<S>(f, s, rules);
    let limited = out.occlusion > 1.0;
    out.occlusion = out.occlusion.min(1.0);
    (out, BlendOutcome { case, eps, limited })
}

/// [`blend_part`] before the limit.
fn blend_unlimited<S: ShaderFloat>(
    f: &PartState,
    s: &PartState,
    rules: Rules,
) -> (PartState, BlendCase, f32) {
    if s.occlusion == 0.0 {
        return (*f, BlendCase::Skipped, 0.0);
    }
    let rs = s.occluded_rect::<S>(rules.adjust);
    if f.occlusion == 0.0 {
        let copy = PartState {
            occlusion: s.occlusion,
            rect: rs,
            max_edge: [0.0, 0.0],
            centroid: s.centroid,
        };
        return (copy, BlendCase::Copied, 0.0);
    }
    let (af, a_s) = (read::<S>(f.occlusion), read::<S>(s.occlusion));
    if f.occlusion < 0.0 || s.occlusion < 0.0 {
        let sum = PartState {
            occlusion: stored(af + a_s),
            ..*f
        };
        return (sum, BlendCase::Accumulated, 0.0);
    }
    let (eps, at) = overlap_estimate::<S>(f, s, rules);
    let occlusion = af + a_s - eps;
    let out = PartState {
        occlusion: stored(occlusion),
        rect: f.occluded_rect::<S>(rules.adjust).union(&rs),
        max_edge: [0.0, 0.0],
        centroid: if occlusion > S::zero() {
            [0, 1].map(|k| {
                let moment = af * read(f.centroid[k]) + a_s * read(s.centroid[k]) - eps * at[k];
                stored((moment / occlusion).clamp(S::zero(), S::one()))
            })
        } else {
            f.centroid
        },
    };
    (out, BlendCase::Blended, stored(eps))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::shader_float::Fp32;

    const PLAIN: Rules = Rules {
        adjust: InnerAdjust::Checked,
        centroid: false,
    };
    const CENTROID: Rules = Rules {
        adjust: InnerAdjust::Checked,
        centroid: true,
    };

    fn part(occlusion: f32, rect: BoundingRect) -> PartState {
        PartState {
            occlusion,
            rect,
            max_edge: [0.0, 0.0],
            centroid: rect.center::<Fp32>().map(stored),
        }
    }

    /// ε in fp32, fp24 and fp16 against f64 for operands exact in every format (rectangle
    /// coordinates multiples of 1/8, occlusions multiples of 1/64): first-order error analysis
    /// with unit roundoff u. Each area B = (r − l)(t − b) has exact differences and one
    /// rounded product (u); each ratio A/B rounds once more (2u; the clamp to [0, 1] does not
    /// increase an error); β's area is one product (u); ε's two products round once each (2u):
    /// |ε_S − ε| ≤ 7u·ε. The factor 1.01 covers the second-order terms (7u ≤ 0.35 %). fp16
    /// must differ somewhere (the blend does compute in `S`).
    #[test]
    fn epsilon_in_each_precision_is_within_the_rounding_bound() {
        use crate::gpu::shader_float::{Fp16, Fp24, FP16, FP24, FP32};
        fn check<S: ShaderFloat>(mantissa_bits: i32) -> usize {
            let u = libm::ldexp(1.0, -(mantissa_bits + 1));
            let rects = [
                r(0.0, 0.0, 1.0, 1.0),
                r(0.125, 0.25, 0.875, 0.625),
                r(0.375, 0.0, 1.0, 0.75),
                r(0.0, 0.5, 0.625, 1.0),
            ];
            let mut differ = 0;
            for (rf, rs) in rects.iter().flat_map(|a| rects.iter().map(move |b| (a, b))) {
                for af in [0.046875, 0.203125, 0.328125] {
                    for a_s in [0.078125, 0.140625, 0.421875] {
                        let (f, s) = (part(af, *rf), part(a_s, *rs));
                        let exact = overlap_estimate::<f64>(&f, &s, PLAIN).0;
                        let eps = overlap_estimate::<S>(&f, &s, PLAIN).0.to_f64();
                        let err = (eps - exact).abs();
                        assert!(
                            err <= 1.01 * 7.0 * u * exact,
                            "{f:?} {s:?}: {eps} vs {exact}"
                        );
                        differ += (err > 0.0) as usize;
                    }
                }
            }
            differ
        }
        check::<Fp32>(FP32.mantissa_bits);
        check::<Fp24>(FP24.mantissa_bits);
        assert!(check::<Fp16>(FP16.mantissa_bits) > 0, "fp16 changed no ε");
    }

    fn r(left: f32, bottom: f32, right: f32, top: f32) -> BoundingRect {
        BoundingRect {
            left,
            bottom,
            right,
            top,
        }
    }

    #[test]
    fn disjoint_rectangles_are_not_corrected() {
        let f = part(0.1, r(0.0, 0.0, 0.4, 0.5));
        let s = part(0.2, r(0.5, 0.0, 1.0, 0.5));
        let (out, o) = blend_part::<Fp32>(&f, &s, PLAIN);
        assert_eq!(o.case, BlendCase::Blended);
        assert_eq!(o.eps, 0.0);
        assert_eq!(out.occlusion, 0.1 + 0.2);
        assert_eq!(out.rect, r(0.0, 0.0, 1.0, 0.5));
    }

    #[test]
    fn nested_rectangles() {
        // Final: 0.2 in [0,1]×[0,0.5] (B = 0.5); silhouette: 0.04 filling [0.2,0.4]×[0.1,0.3].
        let f = part(0.2, r(0.0, 0.0, 1.0, 0.5));
        let s = part(0.04, r(0.2, 0.1, 0.4, 0.3));
        let (out, BlendOutcome { eps, .. }) = blend_part::<Fp32>(&f, &s, PLAIN);
        // ε = (0.2/0.5)·(0.04/0.04)·0.04 = 0.016.
        assert!((eps - 0.016).abs() < 1e-7, "{eps}");
        assert!((out.occlusion - (0.24 - 0.016)).abs() < 1e-7);
        assert_eq!(out.rect, f.rect);
    }

    #[test]
    fn identical_rectangles() {
        let rect = r(0.25, 0.25, 0.75, 0.75);
        let f = part(0.125, rect);
        let s = part(0.25, rect);
        let (out, BlendOutcome { eps, .. }) = blend_part::<Fp32>(&f, &s, PLAIN);
        // ε = 0.5·1·0.25.
        assert!((eps - 0.125).abs() < 1e-7);
        assert!((out.occlusion - 0.25).abs() < 1e-7);
    }

    #[test]
    fn a_full_occluder_absorbs_the_other() {
        // An umbra (whole part) over any penumbra gives the whole part.
        let f = part(0.3, r(0.1, 0.2, 0.9, 0.8));
        let s = PartState::hard(1);
        let (out, o) = blend_part::<Fp32>(&f, &s, PLAIN);
        assert!((out.occlusion - 1.0).abs() < 1e-6);
        assert!(!o.limited);
        let (out, _) = blend_part::<Fp32>(&s, &f, PLAIN);
        assert!((out.occlusion - 1.0).abs() < 1e-6);
    }

    #[test]
    fn dynamic_branch_cases() {
        let f = part(0.3, r(0.1, 0.2, 0.9, 0.8));
        assert_eq!(
            blend_part::<Fp32>(&f, &PartState::CLEARED, PLAIN).1.case,
            BlendCase::Skipped
        );
        let (copy, o) = blend_part::<Fp32>(&PartState::CLEARED, &f, PLAIN);
        assert_eq!(o.case, BlendCase::Copied);
        assert_eq!(copy.occlusion, 0.3);
        let hole = PartState::hard(-1);
        let (sum, o) = blend_part::<Fp32>(&PartState::hard(1), &hole, PLAIN);
        assert_eq!(
            (o.case, o.eps, sum.occlusion),
            (BlendCase::Accumulated, 0.0, 0.0)
        );
        // An underestimated rectangle (occlusion larger than its area) limits at 1.
        let small = PartState {
            occlusion: 0.9,
            ..part(0.9, r(0.0, 0.0, 1.0, 0.7))
        };
        let (out, o) = blend_part::<Fp32>(&PartState::hard(1), &small, PLAIN);
        assert!(o.limited);
        assert_eq!(out.occlusion, 1.0);
    }

    #[test]
    fn inner_maximum_clips_the_far_sides() {
        let mut s = PartState::hard(1);
        // An inner edge from (0.5, 0) to (0, 0.4): the part minus the triangle stays.
        let region =
            RegionBeyondEdge::new(glam::DVec2::new(0.5, 0.0), glam::DVec2::new(0.0, 0.4)).unwrap();
        s.add_inner::<Fp32>(&region);
        assert!((s.occlusion - 0.1).abs() < 1e-7);
        assert_eq!(
            s.occluded_rect::<Fp32>(InnerAdjust::Checked),
            r(0.0, 0.0, 0.5, 0.4)
        );
        assert_eq!(
            s.occluded_rect::<Fp32>(InnerAdjust::Never),
            BoundingRect::FULL
        );
        // The centroid of the remaining triangle (1/3 of (0.5, 0.4)).
        assert!((s.centroid[0] - 0.5 / 3.0).abs() < 1e-5, "{:?}", s.centroid);
        assert!((s.centroid[1] - 0.4 / 3.0).abs() < 1e-5);
    }

    #[test]
    fn an_adjusted_rectangle_smaller_than_its_area_is_not_used() {
        // Hard shadow; two inner edges cut a notch into the right side of the part, from
        // (1, 0.3) in to (0.8, 0.5) and out to (1, 0.7): the occluded region still reaches
        // the top border, but the edges' maximum Y is 0.7.
        let mut s = PartState::hard(1);
        let bite =
            RegionBeyondEdge::new(glam::DVec2::new(1.0, 0.3), glam::DVec2::new(0.8, 0.5)).unwrap();
        let bite2 =
            RegionBeyondEdge::new(glam::DVec2::new(0.8, 0.5), glam::DVec2::new(1.0, 0.7)).unwrap();
        s.add_inner::<Fp32>(&bite);
        s.add_inner::<Fp32>(&bite2);
        // Occluded: the whole part but a small notch; max edge (1, 0.7).
        assert!(s.occlusion > 0.9);
        let clipped = BoundingRect {
            top: 0.7,
            ..BoundingRect::FULL
        };
        assert_eq!(s.occluded_rect::<Fp32>(InnerAdjust::Always), clipped);
        assert_eq!(
            s.occluded_rect::<Fp32>(InnerAdjust::Checked),
            BoundingRect::FULL
        );
    }

    #[test]
    fn centroid_model_separates_concentrated_occluders() {
        // Two thin occluders in opposite corners of the same rectangle: the plain estimate
        // assumes spread-out occlusion and subtracts; the centroid model sees no overlap.
        let rect = r(0.0, 0.0, 1.0, 1.0);
        let f = PartState {
            centroid: [0.1, 0.1],
            ..part(0.04, rect)
        };
        let s = PartState {
            centroid: [0.9, 0.9],
            ..part(0.04, rect)
        };
        let plain = overlap_estimate::<Fp32>(&f, &s, PLAIN).0.to_f64();
        let centroid = overlap_estimate::<Fp32>(&f, &s, CENTROID).0.to_f64();
        assert!((plain - 0.0016).abs() < 1e-7);
        assert_eq!(centroid, 0.0);
        // Same place: the centroid model subtracts the whole smaller occlusion.
        let s = PartState {
            centroid: [0.1, 0.1],
            ..s
        };
        let same = overlap_estimate::<Fp32>(&f, &s, CENTROID).0.to_f64();
        assert!((same - 0.04).abs() < 1e-6, "{same}");
    }
}
