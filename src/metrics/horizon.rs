//! The error split by the receiver's own horizon (issue 28, "The horizon, measured
//! everywhere"): every pixel with a receiver is a *horizon receiver* when its tangent plane
//! cuts some light, a *whole-light receiver* when every light is entirely in front of that
//! plane, and *facing away* otherwise ([`ReceiverClass`]); [`HorizonSplit`] is a method's
//! error over each class, next to the whole-image numbers of
//! [`ErrorReport`](super::error_report::ErrorReport).
//!
//! The geometry is [`crate::light::horizon`]'s (the fraction of a light in front of a plane,
//! in f64); this module only sorts pixels by it, so that `stats.json`, the tables, the report,
//! the accuracy–time sweep and the tests all count the same pixels.
//!
//! Choice — the third class: a receiver with no light cut and some light entirely behind its
//! plane (with one light: the light is behind it) is neither a horizon receiver nor one that
//! sees the whole light. It is reported separately as [`ReceiverClass::FacingAway`] rather
//! than with the whole-light receivers: such a light sends it no direct light (its cosine is
//! ≤ 0 everywhere on the light), so the shaded image hides its visibility, and mixing those
//! pixels in would dilute the whole-light error the way background pixels dilute the
//! whole-image error. Background pixels (no receiver) are in no class.

use super::{compare_where, ErrorStats};
use crate::frame::Receiver;
use crate::light::horizon::fraction_in_front;
use crate::scene::Light;
use crate::visibility::Visibility;
use serde::{Deserialize, Serialize};

/// What the lights are to a receiver's tangent plane (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ReceiverClass {
    /// Every light is entirely in front of (or on) the plane.
    WholeLight,
    /// The plane cuts at least one light: part of it is behind the receiver's own surface.
    Horizon,
    /// No light is cut and at least one is entirely behind the plane.
    FacingAway,
}

impl ReceiverClass {
    /// The class of the receiver at `point` with normal `normal` under `lights`
    /// ([`fraction_in_front`] of each light: some strictly between 0 and 1 → horizon; all 1 →
    /// whole light; else facing away).
    pub fn of(lights: &[Light], point: glam::Vec3, normal: glam::Vec3) -> Self {
        let (mut cut, mut all_in_front) = (false, true);
        for l in lights {
            let f = fraction_in_front(l, point, normal);
            cut |= f > 0.0 && f < 1.0;
            all_in_front &= f == 1.0;
        }
        if cut {
            ReceiverClass::Horizon
        } else if all_in_front {
            ReceiverClass::WholeLight
        } else {
            ReceiverClass::FacingAway
        }
    }
}

/// The class of every pixel's receiver (row-major, like [`crate::frame::Frame::receivers`]);
/// `None` where no geometry was drawn.
pub fn receiver_classes(
    lights: &[Light],
    receivers: &[Option<Receiver>],
) -> Vec<Option<ReceiverClass>> {
    receivers
        .iter()
        .map(|r| r.map(|r| ReceiverClass::of(lights, r.point, r.normal)))
        .collect()
}

/// A method's error split by [`ReceiverClass`], as `stats.json` holds it under
/// `"error"."horizon_split"`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HorizonSplit {
    /// Over the whole-light receivers.
    pub whole_light: ErrorStats,
    /// Over the horizon receivers.
    pub horizon: ErrorStats,
    /// Over the receivers facing away from every light not cut (module doc).
    pub facing_away: ErrorStats,
    /// The horizon receivers as a percentage (0–100) of the image's pixels, background
    /// included (the denominator of the whole-image numbers).
    pub horizon_pct: f64,
    /// The horizon receivers' part (0–1) of the method's total absolute error over the image:
    /// Σ|e| over them / Σ|e| over every pixel; 0 when the method is exact, NaN when an error
    /// is NaN.
    pub horizon_share: f64,
}

/// The error of `method` against `reference` over each class of `classes` (one per pixel,
/// [`receiver_classes`]), see [`HorizonSplit`].
///
/// # Panics
/// If the buffers and `classes` have different pixel counts (a caller bug: all come from one
/// render size).
pub fn horizon_split(
    method: &Visibility,
    reference: &Visibility,
    classes: &[Option<ReceiverClass>],
) -> HorizonSplit {
    assert_eq!(
        classes.len(),
        method.len(),
        "horizon_split: {} classes for {} pixels",
        classes.len(),
        method.len()
    );
    let over = |c: ReceiverClass| compare_where(method, reference, |i| classes[i] == Some(c));
    let all = compare_where(method, reference, |_| true);
    let horizon = over(ReceiverClass::Horizon);
    // Σ|e| = mean |e| · samples, and every pixel of one comparison has the same channel count.
    let total = all.mean_abs * all.pixels as f64;
    let horizon_share = if total == 0.0 {
        0.0
    } else {
        horizon.mean_abs * horizon.pixels as f64 / total
    };
    HorizonSplit {
        whole_light: over(ReceiverClass::WholeLight),
        horizon,
        facing_away: over(ReceiverClass::FacingAway),
        horizon_pct: if all.pixels == 0 {
            0.0
        } else {
            100.0 * horizon.pixels as f64 / all.pixels as f64
        },
        horizon_share,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::LightShape;
    use glam::Vec3;

    /// A 2 × 2 rectangle at height 2 over the origin, facing down.
    fn rect() -> Light {
        Light {
            center: Vec3::new(0.0, 2.0, 0.0),
            shape: LightShape::Rect {
                u: Vec3::X,
                v: Vec3::Z,
            },
        }
    }

    #[test]
    fn floor_wall_and_ceiling_receivers_are_whole_light_horizon_and_facing_away() {
        let lights = [rect()];
        // A floor sees the whole light; a wall x = 0 (normal +x) halves it; a ceiling (normal
        // −y) has it entirely behind.
        assert_eq!(
            ReceiverClass::of(&lights, Vec3::ZERO, Vec3::Y),
            ReceiverClass::WholeLight
        );
        assert_eq!(
            ReceiverClass::of(&lights, Vec3::ZERO, Vec3::X),
            ReceiverClass::Horizon
        );
        assert_eq!(
            ReceiverClass::of(&lights, Vec3::ZERO, -Vec3::Y),
            ReceiverClass::FacingAway
        );
        // A wall x = 1.5 (normal +x) has the light (x ∈ [−1, 1]) entirely behind it; the same
        // wall facing −x has it entirely in front.
        assert_eq!(
            ReceiverClass::of(&lights, Vec3::new(1.5, 0.0, 0.0), Vec3::X),
            ReceiverClass::FacingAway
        );
        assert_eq!(
            ReceiverClass::of(&lights, Vec3::new(1.5, 0.0, 0.0), -Vec3::X),
            ReceiverClass::WholeLight
        );
    }

    #[test]
    fn with_two_lights_one_cut_makes_a_horizon_receiver_and_one_behind_facing_away() {
        // The second light is the first moved to x = 3: the wall x = 1.5 (normal +x) has the
        // first entirely behind and the second entirely in front; at x = 3 it halves the second.
        let mut second = rect();
        second.center.x = 3.0;
        let lights = [rect(), second];
        assert_eq!(
            ReceiverClass::of(&lights, Vec3::new(1.5, 0.0, 0.0), Vec3::X),
            ReceiverClass::FacingAway
        );
        assert_eq!(
            ReceiverClass::of(&lights, Vec3::new(3.0, 0.0, 0.0), Vec3::X),
            ReceiverClass::Horizon
        );
        assert_eq!(
            ReceiverClass::of(&lights, Vec3::ZERO, Vec3::Y),
            ReceiverClass::WholeLight
        );
    }

    #[test]
    fn the_split_counts_each_class_and_the_horizon_share_of_the_error() {
        let lights = [rect()];
        let floor = Some(Receiver {
            point: Vec3::ZERO,
            normal: Vec3::Y,
        });
        let wall = Some(Receiver {
            point: Vec3::ZERO,
            normal: Vec3::X,
        });
        let ceiling = Some(Receiver {
            point: Vec3::ZERO,
            normal: -Vec3::Y,
        });
        // Pixels: floor, floor, wall, ceiling, background.
        let classes = receiver_classes(&lights, &[floor, floor, wall, ceiling, None]);
        use ReceiverClass::*;
        assert_eq!(
            classes,
            [
                Some(WholeLight),
                Some(WholeLight),
                Some(Horizon),
                Some(FacingAway),
                None
            ]
        );
        let reference = Visibility::Gray(vec![1.0, 0.5, 0.5, 0.0, 1.0]);
        let method = Visibility::Gray(vec![1.0, 0.25, 1.0, 0.0, 1.0]);
        let s = horizon_split(&method, &reference, &classes);
        // Whole light: |e| = 0 and 0.25 over 2 pixels; horizon: 0.5 over 1; facing away: 0.
        assert_eq!(s.whole_light.pixels, 2);
        assert_eq!(s.whole_light.mean_abs, 0.125);
        assert_eq!(s.horizon.pixels, 1);
        assert_eq!(s.horizon.mean_abs, 0.5);
        assert_eq!(s.facing_away.pixels, 1);
        assert_eq!(s.facing_away.mean_abs, 0.0);
        // 1 of 5 pixels; 0.5 of the total 0.75.
        assert_eq!(s.horizon_pct, 20.0);
        assert!(
            (s.horizon_share - 2.0 / 3.0).abs() < 1e-15,
            "{}",
            s.horizon_share
        );
        // An exact method has no share.
        assert_eq!(
            horizon_split(&reference, &reference, &classes).horizon_share,
            0.0
        );
        let json = serde_json::to_value(s).unwrap();
        assert_eq!(json["horizon"]["pixels"], 1);
        assert_eq!(json["whole_light"]["mean_abs"], 0.125);
    }
}
