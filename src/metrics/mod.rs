//! Image error metrics: how far a method's visibility is from the reference
//! (`docs/architecture.md` "Layout": RMSE, max abs, % pixels off by more than 1/255), split by
//! the receiver's own horizon ([`horizon`]), and a diff mask for viewing.
//!
//! Differences are taken per channel in f64 (`f64::from(a) − f64::from(b)`, exact for f32
//! inputs) and accumulated sequentially in pixel order, channel order inside a pixel, so the
//! result does not depend on threads or scheduling.

use crate::visibility::Visibility;
use serde::{Deserialize, Serialize};

pub mod error_report;
pub mod horizon;

/// Error of one visibility buffer against another (usually: a method against `raycast`).
///
/// For RGB buffers every channel of every pixel is one sample of `rmse`, `max_abs` and
/// `mean_abs`; a pixel counts towards `pct_over_1_255` when **any** of its channels is off by
/// more than 1/255. A NaN difference (NaN on one side only, or with different bits) makes
/// `rmse`, `mean_abs` and `max_abs` NaN and counts as off, so it cannot hide.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ErrorStats {
    /// Root mean square of the differences.
    pub rmse: f64,
    /// Largest absolute difference.
    pub max_abs: f64,
    /// Mean absolute difference.
    pub mean_abs: f64,
    /// Percentage (0–100) of pixels with `|a − b| > 1/255` in some channel.
    pub pct_over_1_255: f64,
    /// Percentage (0–100) of pixels with `|a − b| > 4/255` in some channel.
    pub pct_over_4_255: f64,
    /// Number of pixels compared.
    pub pixels: u64,
}

/// The threshold of [`ErrorStats::pct_over_1_255`]: one step of an 8-bit display.
pub const ONE_8BIT_STEP: f64 = 1.0 / 255.0;

/// The signed difference of two samples in f64; 0 when their bits are equal (so two NaNs
/// with the same bits compare equal, like the goldens), NaN when exactly one is NaN or two
/// NaNs differ in bits.
fn sample_diff(a: f32, b: f32) -> f64 {
    if a.to_bits() == b.to_bits() {
        0.0
    } else if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        f64::from(a) - f64::from(b)
    }
}

/// The channels of pixel `i` of `a` and `b` and how many are used: one when both buffers
/// are gray, otherwise three (a gray buffer is replicated into RGB).
fn pixel_pairs(a: &Visibility, b: &Visibility, i: usize) -> ([f32; 3], [f32; 3], usize) {
    match (a, b) {
        (Visibility::Gray(ga), Visibility::Gray(gb)) => ([ga[i], 0.0, 0.0], [gb[i], 0.0, 0.0], 1),
        _ => (a.rgb(i), b.rgb(i), 3),
    }
}

/// Compares `a` with `b` (see [`ErrorStats`]). A gray buffer compared with an RGB one is
/// replicated into three channels. Empty buffers give all-zero stats.
///
/// # Panics
/// If the buffers have different pixel counts (a caller bug: both come from one render size).
pub fn compare(a: &Visibility, b: &Visibility) -> ErrorStats {
    compare_where(a, b, |_| true)
}

/// [`compare`] over the pixels `i` with `keep(i)` only (e.g. where penumbrae overlap);
/// `pixels` counts them.
///
/// # Panics
/// As [`compare`].
pub fn compare_where(a: &Visibility, b: &Visibility, keep: impl Fn(usize) -> bool) -> ErrorStats {
    assert_eq!(
        a.len(),
        b.len(),
        "compare: buffers of different sizes ({} vs {} pixels)",
        a.len(),
        b.len()
    );
    let mut n = 0usize;
    let mut sum_sq = 0.0f64;
    let mut sum_abs = 0.0f64;
    let mut max_abs = 0.0f64;
    let mut samples = 0u64;
    let mut over = 0u64;
    let mut over4 = 0u64;
    for i in (0..a.len()).filter(|i| keep(*i)) {
        n += 1;
        let (ca, cb, k) = pixel_pairs(a, b, i);
        let mut off = false;
        let mut off4 = false;
        for c in 0..k {
            let d = sample_diff(ca[c], cb[c]).abs();
            sum_sq += d * d;
            sum_abs += d;
            if d.is_nan() || d > max_abs {
                // Once NaN, `max_abs` stays NaN (`d > NaN` is false).
                if !max_abs.is_nan() {
                    max_abs = d;
                }
            }
            off |= d.is_nan() || d > ONE_8BIT_STEP;
            off4 |= d.is_nan() || d > 4.0 * ONE_8BIT_STEP;
            samples += 1;
        }
        over += u64::from(off);
        over4 += u64::from(off4);
    }
    if n == 0 {
        return ErrorStats {
            rmse: 0.0,
            max_abs: 0.0,
            mean_abs: 0.0,
            pct_over_1_255: 0.0,
            pct_over_4_255: 0.0,
            pixels: 0,
        };
    }
    ErrorStats {
        rmse: (sum_sq / samples as f64).sqrt(),
        max_abs,
        mean_abs: sum_abs / samples as f64,
        pct_over_1_255: 100.0 * over as f64 / n as f64,
        pct_over_4_255: 100.0 * over4 as f64 / n as f64,
        pixels: n as u64,
    }
}

/// The shadow region a visibility value puts a pixel in, up to a tolerance τ (CGI 2004's
/// claim is about these boundaries): umbra when v ≤ τ, lit when v ≥ 1 − τ, penumbra between.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum ShadowClass {
    /// v ≤ τ.
    Umbra,
    /// τ < v < 1 − τ.
    Penumbra,
    /// v ≥ 1 − τ.
    Lit,
}

impl ShadowClass {
    /// The three classes in table order.
    pub const ALL: [ShadowClass; 3] = [ShadowClass::Umbra, ShadowClass::Penumbra, ShadowClass::Lit];

    /// The class of visibility `v` with tolerance `tol` (a NaN is penumbra: neither end).
    pub fn of(v: f32, tol: f64) -> Self {
        let v = f64::from(v);
        if v <= tol {
            ShadowClass::Umbra
        } else if v >= 1.0 - tol {
            ShadowClass::Lit
        } else {
            ShadowClass::Penumbra
        }
    }
}

/// How a method's shadow regions compare with the reference's, pixel by pixel:
/// `counts[r][m]` pixels are of class `ShadowClass::ALL[r]` in the reference and
/// `ShadowClass::ALL[m]` in the method (gray values; RGB averaged).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct ClassTable {
    /// Pixel counts, reference class × method class.
    pub counts: [[u64; 3]; 3],
}

impl ClassTable {
    /// The table of `method` against `reference` over the pixels `i` with `keep(i)`, with
    /// tolerance `tol` ([`ShadowClass::of`]).
    ///
    /// # Panics
    /// If the buffers have different pixel counts (as [`compare`]).
    pub fn of(
        reference: &Visibility,
        method: &Visibility,
        tol: f64,
        keep: impl Fn(usize) -> bool,
    ) -> Self {
        assert_eq!(
            reference.len(),
            method.len(),
            "ClassTable: buffers of different sizes"
        );
        let mut t = Self::default();
        let index = |c: ShadowClass| ShadowClass::ALL.iter().position(|x| *x == c).unwrap_or(1);
        for i in (0..reference.len()).filter(|i| keep(*i)) {
            let r = index(ShadowClass::of(reference.gray(i), tol));
            let m = index(ShadowClass::of(method.gray(i), tol));
            t.counts[r][m] += 1;
        }
        t
    }

    /// Pixels counted.
    pub fn pixels(&self) -> u64 {
        self.counts.iter().flatten().sum()
    }

    /// Pixels of class `c` in the reference (`reference = true`) or in the method.
    pub fn total(&self, c: ShadowClass, reference: bool) -> u64 {
        let k = ShadowClass::ALL.iter().position(|x| *x == c).unwrap_or(1);
        (0..3)
            .map(|j| {
                if reference {
                    self.counts[k][j]
                } else {
                    self.counts[j][k]
                }
            })
            .sum()
    }

    /// The fraction of pixels classified as the reference classifies them (1 when empty).
    pub fn agreement(&self) -> f64 {
        let same: u64 = (0..3).map(|k| self.counts[k][k]).sum();
        match self.pixels() {
            0 => 1.0,
            n => same as f64 / n as f64,
        }
    }
}

/// Smallest red intensity of a differing pixel in [`diff_mask`], so that even a one-ulp
/// difference is visible against the black of equal pixels.
pub const DIFF_MIN_RED: u8 = 64;

/// Red intensity for an absolute difference `d` (≥ 0, or NaN): `DIFF_MIN_RED` plus the rest
/// of the range in proportion to `min(d, 1)`, rounded half to even; NaN → 255.
pub fn diff_red(d: f64) -> u8 {
    if d.is_nan() {
        return 255;
    }
    let span = f64::from(255 - DIFF_MIN_RED);
    let r = f64::from(DIFF_MIN_RED) + (d.min(1.0) * span).round_ties_even();
    r.clamp(f64::from(DIFF_MIN_RED), 255.0) as u8
}

/// A `w×h` RGB mask of where `a` and `b` differ: black where every channel is equal bit for
/// bit, otherwise red ([`diff_red`] of the largest absolute channel difference; at least
/// [`DIFF_MIN_RED`], so `0.0` vs `-0.0` or a 1-ulp difference shows). Gray vs RGB compares
/// the gray buffer replicated.
///
/// # Panics
/// If either buffer does not have `w·h` pixels.
pub fn diff_mask(a: &Visibility, b: &Visibility, w: u32, h: u32) -> Vec<[u8; 3]> {
    let n = w as usize * h as usize;
    assert_eq!(a.len(), n, "diff_mask: first buffer is not {w}x{h}");
    assert_eq!(b.len(), n, "diff_mask: second buffer is not {w}x{h}");
    (0..n)
        .map(|i| {
            let (ca, cb, k) = pixel_pairs(a, b, i);
            let mut equal = true;
            let mut worst = 0.0f64;
            for c in 0..k {
                if ca[c].to_bits() != cb[c].to_bits() {
                    equal = false;
                    let d = sample_diff(ca[c], cb[c]).abs();
                    if d.is_nan() || worst.is_nan() {
                        worst = f64::NAN;
                    } else {
                        worst = worst.max(d);
                    }
                }
            }
            if equal {
                [0, 0, 0]
            } else {
                [diff_red(worst), 0, 0]
            }
        })
        .collect()
}

/// Like [`diff_mask`] for 8-bit buffers (raw images such as the stencil): black where equal,
/// else red ∝ `|a − b| / 255`, at least [`DIFF_MIN_RED`].
///
/// # Panics
/// If either buffer does not have `w·h` values.
pub fn diff_mask_u8(a: &[u8], b: &[u8], w: u32, h: u32) -> Vec<[u8; 3]> {
    let n = w as usize * h as usize;
    assert_eq!(a.len(), n, "diff_mask_u8: first buffer is not {w}x{h}");
    assert_eq!(b.len(), n, "diff_mask_u8: second buffer is not {w}x{h}");
    a.iter()
        .zip(b)
        .map(|(&x, &y)| {
            if x == y {
                [0, 0, 0]
            } else {
                [diff_red(f64::from(x.abs_diff(y)) / 255.0), 0, 0]
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn class_table_counts_reference_against_method() {
        use super::*;
        let r = Visibility::Gray(vec![0.0, 0.5, 1.0, 0.002, 0.999]);
        let m = Visibility::Gray(vec![0.0, 0.0, 1.0, 0.1, 1.0]);
        let t = ClassTable::of(&r, &m, 1.0 / 255.0, |_| true);
        // Umbra: pixels 0, 3 (0.002 ≤ 1/255); lit: 2, 4; penumbra: 1.
        assert_eq!(t.counts, [[1, 1, 0], [1, 0, 0], [0, 0, 2]]);
        assert_eq!(t.pixels(), 5);
        assert_eq!(t.total(ShadowClass::Umbra, true), 2);
        assert_eq!(t.total(ShadowClass::Umbra, false), 2);
        assert!((t.agreement() - 0.6).abs() < 1e-12);
        assert_eq!(ClassTable::of(&r, &m, 0.01, |i| i != 1).agreement(), 0.75);
    }

    use super::*;

    fn gray(v: &[f32]) -> Visibility {
        Visibility::Gray(v.to_vec())
    }

    #[test]
    fn identical_is_zero() {
        let a = gray(&[0.0, 0.5, 1.0, 0.25]);
        let s = compare(&a, &a);
        assert_eq!(
            s,
            ErrorStats {
                rmse: 0.0,
                max_abs: 0.0,
                mean_abs: 0.0,
                pct_over_1_255: 0.0,
                pct_over_4_255: 0.0,
                pixels: 4
            }
        );
    }

    #[test]
    fn known_values_gray() {
        let a = gray(&[0.0, 0.5, 1.0, 0.25]);
        let b = gray(&[0.5, 0.5, 0.75, 0.25]);
        let s = compare(&a, &b);
        assert_eq!(s.pixels, 4);
        assert_eq!(s.max_abs, 0.5);
        assert_eq!(s.mean_abs, 0.75 / 4.0);
        assert_eq!(s.rmse, ((0.25 + 0.0625) / 4.0f64).sqrt());
        assert_eq!(s.pct_over_1_255, 50.0);
        assert_eq!(s.pct_over_4_255, 50.0);
    }

    #[test]
    fn masked_comparison_counts_only_kept_pixels() {
        let a = gray(&[0.0, 0.5, 1.0, 0.25]);
        let b = gray(&[0.5, 0.5, 0.99, 0.25]);
        let s = compare_where(&a, &b, |i| i >= 1);
        assert_eq!(s.pixels, 3);
        assert!((s.max_abs - 0.01).abs() < 1e-6);
        // 0.01 is over 1/255 but not over 4/255.
        assert!((s.pct_over_1_255 - 100.0 / 3.0).abs() < 1e-9);
        assert_eq!(s.pct_over_4_255, 0.0);
    }

    #[test]
    fn threshold_is_strict() {
        // A difference of exactly 1/255 (as near as f32 allows, below it) is not "over".
        let b = 0.5f32;
        let a_small = b + 0.5 / 255.0;
        let a_big = b + 2.0 / 255.0;
        let s = compare(&gray(&[a_small, a_big]), &gray(&[b, b]));
        assert_eq!(s.pct_over_1_255, 50.0);
    }

    #[test]
    fn rgb_counts_every_channel() {
        let a = Visibility::Rgb(vec![[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]);
        let b = Visibility::Rgb(vec![[0.0, 0.0, 0.6], [1.0, 1.0, 1.0]]);
        let s = compare(&a, &b);
        assert_eq!(s.pixels, 2);
        assert_eq!(s.max_abs, f64::from(0.6f32));
        assert_eq!(s.mean_abs, f64::from(0.6f32) / 6.0);
        assert_eq!(s.pct_over_1_255, 50.0);
        // Gray vs RGB: the gray is replicated.
        let g = gray(&[0.0, 1.0]);
        assert_eq!(compare(&g, &b), s);
    }

    #[test]
    fn nan_is_not_hidden() {
        let s = compare(&gray(&[0.0, f32::NAN, 0.0]), &gray(&[0.0, 0.0, 1.0]));
        assert!(s.rmse.is_nan() && s.mean_abs.is_nan() && s.max_abs.is_nan());
        assert!((s.pct_over_1_255 - 200.0 / 3.0).abs() < 1e-12);
        // Same-bits NaN is equal.
        let s = compare(&gray(&[f32::NAN]), &gray(&[f32::NAN]));
        assert_eq!(s.rmse, 0.0);
    }

    #[test]
    fn empty() {
        let s = compare(&gray(&[]), &gray(&[]));
        assert_eq!(s.pixels, 0);
        assert_eq!(s.rmse, 0.0);
    }

    #[test]
    #[should_panic]
    fn size_mismatch_panics() {
        compare(&gray(&[0.0]), &gray(&[0.0, 1.0]));
    }

    #[test]
    fn deterministic_order_matches_sequential_sum() {
        let a: Vec<f32> = (0..1000)
            .map(|i| libm::sinf(i as f32 * 0.37).abs())
            .collect();
        let b: Vec<f32> = (0..1000)
            .map(|i| libm::cosf(i as f32 * 0.11).abs())
            .collect();
        let mut sq = 0.0f64;
        for (x, y) in a.iter().zip(&b) {
            let d = f64::from(*x) - f64::from(*y);
            sq += d * d;
        }
        let s = compare(&gray(&a), &gray(&b));
        assert_eq!(s.rmse.to_bits(), (sq / 1000.0).sqrt().to_bits());
    }

    #[test]
    fn mask_shows_tiny_differences() {
        let a = gray(&[0.5, 0.5, 0.0, 0.0, 1.0, f32::NAN]);
        let b = gray(&[
            0.5,
            f32::from_bits(0.5f32.to_bits() + 1),
            -0.0,
            1.0,
            0.0,
            0.0,
        ]);
        let m = diff_mask(&a, &b, 3, 2);
        assert_eq!(m[0], [0, 0, 0]);
        assert_eq!(m[1], [DIFF_MIN_RED, 0, 0]);
        assert_eq!(m[2], [DIFF_MIN_RED, 0, 0]);
        assert_eq!(m[3], [255, 0, 0]);
        assert_eq!(m[4], [255, 0, 0]);
        assert_eq!(m[5], [255, 0, 0]);
        let half = diff_mask(&gray(&[0.5]), &gray(&[0.0]), 1, 1)[0][0];
        assert!(half > DIFF_MIN_RED && half < 255);
    }

    #[test]
    fn mask_rgb_and_u8() {
        let a = Visibility::Rgb(vec![[0.0, 0.0, 0.0], [0.2, 0.2, 0.2]]);
        let b = Visibility::Rgb(vec![[0.0, 0.0, 0.0], [0.2, 0.2, 0.3]]);
        let m = diff_mask(&a, &b, 2, 1);
        assert_eq!(m[0], [0, 0, 0]);
        assert!(m[1][0] >= DIFF_MIN_RED);
        let m = diff_mask_u8(&[0, 1, 255], &[0, 2, 0], 3, 1);
        assert_eq!(m, vec![[0, 0, 0], [DIFF_MIN_RED + 1, 0, 0], [255, 0, 0]]);
    }
}
