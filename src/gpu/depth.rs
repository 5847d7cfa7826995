//! Depth formats, depth quantization and the depth test (`docs/architecture.md` "Depth").
//!
//! * D24 unorm (default): `D24 = round_half_even(f32(z_w · 16777215))`, z_w clamped to [0, 1]
//!   first (OpenGL clamps interpolated depth to the depth range).
//! * D16 unorm: `D16 = round_half_even(f32(z_w · 65535))`, the same rule at 16 bits (the depth
//!   format of many shadow maps of the era; selectable for the depth-format study).
//! * D32F: the clamped f32 z_w itself; stored as its bit pattern, compared as f32.
//!
//! All are stored as `u32`; for non-negative f32 the bit patterns order like the values, so
//! one integer comparison serves every format.
//!
//! Polygon offset ([`PolygonOffset`], `glPolygonOffset(factor, units)`) is the depth bias of
//! shadow maps: `o = m·factor + r·units`, added to the fragment's window depth before the
//! format clamps and quantizes it.

use crate::limits::{D16_MAX, D24_MAX};

/// The depth buffer's storage format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum DepthFormat {
    /// 16-bit unsigned normalized (2 bytes per sample).
    D16,
    /// 24-bit unsigned normalized (3 bytes per sample).
    D24,
    /// 32-bit float (4 bytes per sample).
    D32F,
}

impl DepthFormat {
    /// Bytes one sample occupies (used by the traffic counters).
    pub fn bytes(self) -> u64 {
        match self {
            DepthFormat::D16 => 2,
            DepthFormat::D24 => 3,
            DepthFormat::D32F => 4,
        }
    }

    /// The stored value of window depth `z_w` (clamped to [0, 1]).
    pub fn quantize(self, z_w: f32) -> u32 {
        let z = z_w.clamp(0.0, 1.0);
        match self {
            DepthFormat::D16 => (z * D16_MAX as f32).round_ties_even() as u32,
            DepthFormat::D24 => (z * D24_MAX as f32).round_ties_even() as u32,
            DepthFormat::D32F => z.to_bits(),
        }
    }

    /// The smallest window depth in [0, 1] that quantizes to `q` or more, `+∞` when none does:
    /// for every finite `z ≥ 0`, `quantize(z) >= q` ⇔ `z >= first_quantized_at_least(q)`
    /// (quantizing is monotone over the ordered bit patterns of the non-negative f32). The
    /// hierarchical-Z unit compares a triangle's f32 depth range with these thresholds instead
    /// of quantizing it per tile ([`super::buffers::HizBounds::depth_outcome`]). A binary
    /// search over the bit patterns between the window depths of `q − 1` and `q` (the whole
    /// of [0, 1] where rounding put either on the wrong side): a few steps, not thirty.
    ///
    /// Why that bracket always holds, `quantize(window(q − 1)) < q ≤ quantize(window(q))`
    /// with `window(c)` the f32 nearest `c / M`: for the unorm formats the f32 is within half
    /// an ulp, at most 2⁻²⁵ in [½, 1) and less below, so `window(c)·M` is within
    /// 2⁻²⁵·(2²⁴ − 1) < ½ of `c`, and the f32 product (exact integers above 2²³, a grid of ½
    /// or finer below, with the error shrinking as fast) rounds back to `c`; for D32F
    /// `window(c)` is `c`'s own bits. The test
    /// `every_code_is_bracketed_by_its_own_window_depths` checks every D16 and D24 code.
    pub fn first_quantized_at_least(self, q: u32) -> f32 {
        let at = |bits: u32| self.quantize(f32::from_bits(bits));
        let one = 1.0f32.to_bits();
        if at(one) < q {
            return f32::INFINITY;
        }
        if at(0) >= q {
            return 0.0;
        }
        // q ≥ 1 here. Invariant: at(lo) < q ≤ at(hi).
        let near = |code: u32| (self.to_window(code) as f32).to_bits().min(one);
        let (mut lo, mut hi) = (near(q - 1), near(q));
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            if at(mid) >= q {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        f32::from_bits(hi)
    }

    /// The stored value of the clear depth 1.0.
    pub fn far(self) -> u32 {
        self.quantize(1.0)
    }

    /// The window depth a stored value stands for.
    pub fn to_window(self, stored: u32) -> f64 {
        match self {
            DepthFormat::D16 => stored as f64 / D16_MAX as f64,
            DepthFormat::D24 => stored as f64 / D24_MAX as f64,
            DepthFormat::D32F => f32::from_bits(stored) as f64,
        }
    }

    /// The minimum resolvable difference `r` of `glPolygonOffset` for a primitive whose
    /// largest window depth is `z_max`: one step of the unorm formats; for D32F
    /// `2^(e − 23)`, e the binary exponent of `z_max` (OpenGL 4.6 §14.6.5), with the smallest
    /// normal exponent for `z_max` ≤ 0 or subnormal.
    pub fn resolvable_difference(self, z_max: f32) -> f64 {
        match self {
            DepthFormat::D16 => 1.0 / D16_MAX as f64,
            DepthFormat::D24 => 1.0 / D24_MAX as f64,
            DepthFormat::D32F => {
                let z = z_max.clamp(f32::MIN_POSITIVE, 1.0);
                let e = ((z.to_bits() >> 23) & 0xff) as i32 - 127;
                libm::ldexp(1.0, e - 23)
            }
        }
    }
}

/// `glPolygonOffset(factor, units)`: a primitive's fragments are moved back by
/// `o = m·factor + r·units`, with m = max(|∂z/∂x|, |∂z/∂y|) the largest window-depth slope of
/// the primitive per pixel (OpenGL allows the maximum as an approximation of the gradient
/// length; we use it) and r the format's [`DepthFormat::resolvable_difference`]. The offset is
/// computed in f64, added to the fragment's interpolated f32 depth and rounded once to f32,
/// before the format clamps and quantizes it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PolygonOffset {
    /// Slope-scaled part: multiples of the primitive's largest depth slope.
    pub factor: f64,
    /// Constant part: multiples of the format's minimum resolvable difference.
    pub units: f64,
}

impl PolygonOffset {
    /// No offset.
    pub const NONE: PolygonOffset = PolygonOffset {
        factor: 0.0,
        units: 0.0,
    };

    /// No offset, a positive one and a negative one: the offsets the early-Z tests of the
    /// passes drawn from the light try (a bound on fragment depths must hold for each).
    #[cfg(test)]
    pub(crate) const EARLY_Z_TEST_CASES: [PolygonOffset; 3] = [
        PolygonOffset::NONE,
        PolygonOffset {
            factor: 2.0,
            units: 4.0,
        },
        PolygonOffset {
            factor: -1.5,
            units: -64.0,
        },
    ];

    /// The offset `o = m·factor + r·units` of a primitive with largest depth slope
    /// `max_slope` and largest vertex depth `z_max`, stored as `format` (a slope that is not
    /// finite — a primitive seen edge-on — counts as 0).
    pub fn amount(self, format: DepthFormat, max_slope: f64, z_max: f32) -> f64 {
        let m = if max_slope.is_finite() {
            max_slope
        } else {
            0.0
        };
        m * self.factor + format.resolvable_difference(z_max) * self.units
    }

    /// The offset window depth of a fragment at interpolated depth `z` of a primitive with
    /// largest depth slope `max_slope` and largest vertex depth `z_max`, stored as `format`.
    pub fn apply(self, format: DepthFormat, z: f32, max_slope: f64, z_max: f32) -> f32 {
        if self == Self::NONE {
            return z;
        }
        (z as f64 + self.amount(format, max_slope, z_max)) as f32
    }
}

/// The depth comparison function, `fragment FUNC stored` as in `glDepthFunc`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum DepthFunc {
    /// Never passes.
    Never,
    /// Passes if fragment < stored.
    Less,
    /// Passes if fragment ≤ stored.
    LEqual,
    /// Passes if fragment == stored.
    Equal,
    /// Passes if fragment > stored.
    Greater,
    /// Passes if fragment ≥ stored.
    GEqual,
    /// Always passes.
    Always,
}

impl DepthFunc {
    /// Evaluate the test on stored values of the same format.
    #[inline]
    pub fn test(self, fragment: u32, stored: u32) -> bool {
        match self {
            DepthFunc::Never => false,
            DepthFunc::Less => fragment < stored,
            DepthFunc::LEqual => fragment <= stored,
            DepthFunc::Equal => fragment == stored,
            DepthFunc::Greater => fragment > stored,
            DepthFunc::GEqual => fragment >= stored,
            DepthFunc::Always => true,
        }
    }
}

/// Depth state of a draw: test function and write mask.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct DepthState {
    /// The comparison.
    pub func: DepthFunc,
    /// Whether passing fragments write their depth.
    pub write: bool,
}

impl DepthState {
    /// LESS with depth writes: the ordinary nearest-surface (or smallest-value) pass.
    pub const LESS_WRITE: DepthState = DepthState {
        func: DepthFunc::Less,
        write: true,
    };

    /// GREATER with depth writes, on a target cleared to 0: the farthest surface (or largest
    /// value) wins.
    pub const GREATER_WRITE: DepthState = DepthState {
        func: DepthFunc::Greater,
        write: true,
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The offsets the early-Z tests try are what their doc promises — none, a positive and a
    /// negative one in both parts — so that a bound on fragment depths is tried on each side
    /// (a negative offset moves fragments towards the viewer, where a bound can fail first).
    #[test]
    fn the_early_z_test_cases_are_none_a_positive_and_a_negative_offset() {
        let [none, positive, negative] = PolygonOffset::EARLY_Z_TEST_CASES;
        assert_eq!(none, PolygonOffset::NONE);
        assert!(
            positive.factor > 0.0 && positive.units > 0.0,
            "{positive:?}"
        );
        assert!(
            negative.factor < 0.0 && negative.units < 0.0,
            "{negative:?}"
        );
    }

    /// Each threshold is the first depth of its code: it quantizes to `q` or more and the f32
    /// just below it to less — for every D16 code and every 97th D24 code.
    #[test]
    fn each_threshold_is_the_first_depth_of_its_code() {
        let codes = [
            (DepthFormat::D16, (0..=D16_MAX + 1).collect::<Vec<_>>()),
            (DepthFormat::D24, (0..=D24_MAX + 1).step_by(97).collect()),
        ];
        for (format, codes) in codes {
            for q in codes {
                let t = format.first_quantized_at_least(q);
                if q > format.far() {
                    assert_eq!(t, f32::INFINITY, "{format:?} {q}");
                    continue;
                }
                assert!(format.quantize(t) >= q, "{format:?} {q}: {t:e}");
                if t > 0.0 {
                    let below = f32::from_bits(t.to_bits() - 1);
                    assert!(format.quantize(below) < q, "{format:?} {q}: {below:e}");
                }
            }
        }
    }

    /// The search bracket of [`DepthFormat::first_quantized_at_least`] holds for every code:
    /// the window depth of `q − 1` quantizes below `q` and that of `q` to `q` itself (the
    /// rounding argument of its doc), every D16 and every D24 code, and D32F around 0, ½ and 1.
    #[test]
    fn every_code_is_bracketed_by_its_own_window_depths() {
        let window = |format: DepthFormat, code: u32| format.to_window(code) as f32;
        let d32: Vec<u32> = [0.0f32, 0.5, 1.0]
            .iter()
            .flat_map(|z| {
                let b = z.to_bits();
                b.saturating_sub(1000).max(1)..=(b + 1000).min(1.0f32.to_bits())
            })
            .collect();
        let codes = [
            (DepthFormat::D16, (1..=D16_MAX).collect::<Vec<_>>()),
            (DepthFormat::D24, (1..=D24_MAX).collect()),
            (DepthFormat::D32F, d32),
        ];
        for (format, codes) in codes {
            for q in codes {
                assert!(format.quantize(window(format, q - 1)) < q, "{format:?} {q}");
                assert_eq!(format.quantize(window(format, q)), q, "{format:?} {q}");
            }
        }
    }

    /// The thresholds decide `quantize(z) >= q` exactly as quantizing does, for every format,
    /// at and around every threshold and over a sweep of depths.
    #[test]
    fn thresholds_agree_with_quantizing() {
        for format in [DepthFormat::D16, DepthFormat::D24, DepthFormat::D32F] {
            let stored: Vec<u32> = [0.0f32, 1e-30, 1e-7, 0.25, 0.5, 0.7, 0.999_999, 1.0]
                .iter()
                .flat_map(|&z| {
                    let q = format.quantize(z);
                    [q.saturating_sub(1), q, q + 1]
                })
                .chain([format.far() + 1, 0, 1])
                .collect();
            for &q in &stored {
                let t = format.first_quantized_at_least(q);
                let mut probes: Vec<f32> = (0..=1000).map(|k| k as f32 / 1000.0).collect();
                if t.is_finite() {
                    probes.extend([
                        t,
                        f32::from_bits(t.to_bits().saturating_sub(1)),
                        f32::from_bits(t.to_bits() + 1),
                    ]);
                }
                probes.extend([1.5, 1e-45]);
                for z in probes {
                    assert_eq!(
                        format.quantize(z) >= q,
                        z >= t,
                        "{format:?} q {q} z {z:e} t {t:e}"
                    );
                }
            }
        }
    }

    #[test]
    fn d24_endpoints_and_rounding() {
        assert_eq!(DepthFormat::D24.quantize(0.0), 0);
        assert_eq!(DepthFormat::D24.quantize(1.0), D24_MAX);
        assert_eq!(DepthFormat::D24.quantize(2.0), D24_MAX);
        assert_eq!(DepthFormat::D24.quantize(-1.0), 0);
        assert_eq!(DepthFormat::D24.quantize(0.5), 8388608); // 8388607.5 in f32 is 8388608
    }

    #[test]
    fn d16_endpoints_and_rounding() {
        let f = DepthFormat::D16;
        assert_eq!(f.quantize(0.0), 0);
        assert_eq!(f.quantize(1.0), D16_MAX);
        assert_eq!(f.quantize(1.5), D16_MAX);
        // 0.5·65535 = 32767.5 exactly: ties to even.
        assert_eq!(f.quantize(0.5), 32768);
        assert_eq!(f.quantize(1.5 / 65535.0), 2);
        assert_eq!(f.to_window(D16_MAX), 1.0);
        assert_eq!(f.bytes(), 2);
    }

    #[test]
    fn polygon_offset_moves_depth_by_slope_and_units() {
        let o = PolygonOffset {
            factor: 2.0,
            units: 3.0,
        };
        let z = o.apply(DepthFormat::D24, 0.25, 1e-4, 0.3);
        let expected = (0.25f64 + 2e-4 + 3.0 / D24_MAX as f64) as f32;
        assert_eq!(z, expected);
        assert_eq!(
            PolygonOffset::NONE.apply(DepthFormat::D16, 0.7, 1.0, 1.0),
            0.7
        );
        // One D16 unit moves the stored value by one step.
        let one = PolygonOffset {
            factor: 0.0,
            units: 1.0,
        };
        let f = DepthFormat::D16;
        assert_eq!(
            f.quantize(one.apply(f, 0.25, 0.0, 0.5)),
            f.quantize(0.25) + 1
        );
        // D32F: r = 2^(e − 23) of the largest depth, e = −1 for z in [0.5, 1).
        assert_eq!(
            DepthFormat::D32F.resolvable_difference(0.75),
            libm::ldexp(1.0, -24)
        );
    }

    #[test]
    fn d32f_orders_like_values() {
        let f = DepthFormat::D32F;
        assert!(f.quantize(0.25) < f.quantize(0.5));
        assert_eq!(f.to_window(f.quantize(0.75)), 0.75);
    }

    /// Every function on every pair of stored values below, above and equal, and at the
    /// ends of the range, against the GL specification's table (the fragment's depth compared
    /// with the stored one): each of the seven tells `<`, `=` and `>` apart as the table says.
    #[test]
    fn every_func_is_the_specification_on_less_equal_and_greater() {
        use std::cmp::Ordering::{self, Equal, Greater, Less};
        type Expected = fn(Ordering) -> bool;
        let table: [(DepthFunc, Expected); 7] = [
            (DepthFunc::Never, |_| false),
            (DepthFunc::Less, |o| o == Less),
            (DepthFunc::LEqual, |o| o != Greater),
            (DepthFunc::Equal, |o| o == Equal),
            (DepthFunc::Greater, |o| o == Greater),
            (DepthFunc::GEqual, |o| o != Less),
            (DepthFunc::Always, |_| true),
        ];
        let values = [0, 1, 2, 0x00ff_ffff, u32::MAX - 1, u32::MAX];
        for (func, expected) in table {
            for fragment in values {
                for stored in values {
                    assert_eq!(
                        func.test(fragment, stored),
                        expected(fragment.cmp(&stored)),
                        "{func:?} {fragment} {stored}"
                    );
                }
            }
        }
    }
}
