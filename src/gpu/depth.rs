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

    #[test]
    fn funcs() {
        assert!(DepthFunc::Less.test(1, 2) && !DepthFunc::Less.test(2, 2));
        assert!(DepthFunc::LEqual.test(2, 2));
        assert!(DepthFunc::GEqual.test(2, 2) && !DepthFunc::Greater.test(2, 2));
        assert!(!DepthFunc::Never.test(0, 1) && DepthFunc::Always.test(5, 1));
    }
}
