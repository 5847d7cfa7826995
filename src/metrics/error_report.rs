//! What a run writes about a method's error against the reference (issue 14, "Error maps and
//! metrics in every run"): the metrics over the whole image, over the reference's penumbra and
//! split by the receiver's own horizon (issue 28; [`ErrorReport`], in `stats.json`), and the signed error as a picture ([`signed_error_map`],
//! `error.png`) on one fixed scale, so that two runs can be compared by eye.

use super::horizon::{horizon_split, HorizonSplit, ReceiverClass};
use super::{compare, compare_where, ErrorStats};
use crate::visibility::Visibility;
use serde::Serialize;

/// A method's error against the reference, as `stats.json` holds it under `"error"`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ErrorReport {
    /// The reference method's name.
    pub reference: String,
    /// Over every pixel.
    #[serde(flatten)]
    pub all: ErrorStats,
    /// Over the reference's penumbra only: the pixels where some channel of the reference is
    /// strictly between 0 and 1 (elsewhere most methods are exact, and whole-image numbers
    /// are diluted by the lit and umbra areas).
    pub penumbra_only: ErrorStats,
    /// Over the whole-light receivers, the horizon receivers and those facing away
    /// ([`super::horizon`]).
    pub horizon_split: HorizonSplit,
}

/// The error of `method` against `reference` (named `reference_name`), see [`ErrorReport`];
/// `classes` holds each pixel's [`ReceiverClass`]
/// ([`receiver_classes`](super::horizon::receiver_classes)).
///
/// # Panics
/// If the buffers and `classes` have different pixel counts.
pub fn error_report(
    method: &Visibility,
    reference: &Visibility,
    reference_name: &str,
    classes: &[Option<ReceiverClass>],
) -> ErrorReport {
    ErrorReport {
        reference: reference_name.into(),
        all: compare(method, reference),
        penumbra_only: compare_where(method, reference, |i| in_penumbra(reference, i)),
        horizon_split: horizon_split(method, reference, classes),
    }
}

/// Whether some channel of pixel `i` of the reference is strictly between 0 and 1.
pub fn in_penumbra(reference: &Visibility, i: usize) -> bool {
    reference.rgb(i).iter().any(|&v| v > 0.0 && v < 1.0)
}

/// The colour of a signed error `e = method − reference` in `error.png`: white at 0, towards
/// red where the method is too bright (too much light), towards blue where it is too dark;
/// the strength is `√min(|e|, 1)`, so one 8-bit step (1/255) is already a visible tint
/// (6 %), 1/16 is a quarter of the way, 1/4 half way and a full error saturated. NaN is green.
/// The scale is fixed: the same colour means the same error in every run.
pub fn error_colour(e: f64) -> [u8; 3] {
    if e.is_nan() {
        return [0, 255, 0];
    }
    let fade = (255.0 * (1.0 - e.abs().min(1.0).sqrt())).round_ties_even() as u8;
    if e > 0.0 {
        [255, fade, fade]
    } else {
        [fade, fade, 255]
    }
}

/// The signed error of `method` against `reference` per pixel ([`error_colour`]); for RGB
/// buffers the channel with the largest |e| decides (its sign kept). Row-major, like the
/// buffers.
///
/// # Panics
/// If the buffers have different pixel counts.
pub fn signed_error_map(method: &Visibility, reference: &Visibility) -> Vec<[u8; 3]> {
    assert_eq!(
        method.len(),
        reference.len(),
        "signed_error_map: sizes differ"
    );
    (0..method.len())
        .map(|i| {
            let (m, r) = (method.rgb(i), reference.rgb(i));
            let mut worst = 0.0f64;
            for c in 0..3 {
                let e = f64::from(m[c]) - f64::from(r[c]);
                if e.is_nan() || e.abs() > worst.abs() {
                    worst = e;
                    if e.is_nan() {
                        break;
                    }
                }
            }
            error_colour(worst)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_is_fixed_and_signed() {
        assert_eq!(error_colour(0.0), [255, 255, 255]);
        assert_eq!(error_colour(1.0), [255, 0, 0]);
        assert_eq!(error_colour(-1.0), [0, 0, 255]);
        assert_eq!(error_colour(-7.0), [0, 0, 255]);
        assert_eq!(error_colour(0.25), [255, 128, 128]);
        // One 8-bit step is visible: 255·(1 − √(1/255)) = 239.03.
        assert_eq!(error_colour(1.0 / 255.0), [255, 239, 239]);
        assert_eq!(error_colour(f64::NAN), [0, 255, 0]);
    }

    #[test]
    fn penumbra_only_counts_the_reference_penumbra() {
        let reference = Visibility::Gray(vec![0.0, 0.5, 1.0, 0.25]);
        let method = Visibility::Gray(vec![0.5, 0.5, 1.0, 0.0]);
        // Pixels 0 and 1 are whole-light receivers, 2 a horizon receiver, 3 background.
        use crate::metrics::horizon::ReceiverClass::{Horizon, WholeLight};
        let classes = [Some(WholeLight), Some(WholeLight), Some(Horizon), None];
        let r = error_report(&method, &reference, "raycast", &classes);
        assert_eq!(r.all.pixels, 4);
        assert_eq!(r.penumbra_only.pixels, 2);
        assert_eq!(r.penumbra_only.max_abs, 0.25);
        assert_eq!(r.all.max_abs, 0.5);
        let json = serde_json::to_value(&r).unwrap();
        assert_eq!(json["reference"], "raycast");
        assert_eq!(json["rmse"], r.all.rmse);
        assert_eq!(json["penumbra_only"]["pixels"], 2);
        assert_eq!(json["horizon_split"]["whole_light"]["pixels"], 2);
        assert_eq!(json["horizon_split"]["whole_light"]["mean_abs"], 0.25);
        assert_eq!(json["horizon_split"]["horizon"]["mean_abs"], 0.0);
        assert_eq!(json["horizon_split"]["horizon_pct"], 25.0);
        let map = signed_error_map(&method, &reference);
        assert_eq!(map[0][0], 255); // too bright: red
        assert_eq!(map[1], [255, 255, 255]);
        assert_eq!(map[3][2], 255); // too dark: blue
        assert!(map[3][0] < 255);
        let rgb = Visibility::Rgb(vec![[0.5, 0.5, 0.9]]);
        let rgb_ref = Visibility::Rgb(vec![[0.5, 0.6, 0.5]]);
        // The blue channel's +0.4 outweighs green's −0.1.
        assert_eq!(
            signed_error_map(&rgb, &rgb_ref)[0],
            error_colour(f64::from(0.9f32) - 0.5)
        );
    }
}
