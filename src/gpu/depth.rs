//! Depth formats, depth quantization and the depth test (DESIGN.md "Depth").
//!
//! * D24 unorm (default): `D24 = round_half_even(f32(z_w · 16777215))`, z_w clamped to [0, 1]
//!   first (OpenGL clamps interpolated depth to the depth range).
//! * D32F: the clamped f32 z_w itself; stored as its bit pattern, compared as f32.
//!
//! Both are stored as `u32`; for non-negative f32 the bit patterns order like the values, so
//! one integer comparison serves both formats.

use crate::limits::D24_MAX;

/// The depth buffer's storage format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum DepthFormat {
    /// 24-bit unsigned normalized (3 bytes per sample).
    D24,
    /// 32-bit float (4 bytes per sample).
    D32F,
}

impl DepthFormat {
    /// Bytes one sample occupies (used by the traffic counters).
    pub fn bytes(self) -> u64 {
        match self {
            DepthFormat::D24 => 3,
            DepthFormat::D32F => 4,
        }
    }

    /// The stored value of window depth `z_w` (clamped to [0, 1]).
    pub fn quantize(self, z_w: f32) -> u32 {
        let z = z_w.clamp(0.0, 1.0);
        match self {
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
            DepthFormat::D24 => stored as f64 / D24_MAX as f64,
            DepthFormat::D32F => f32::from_bits(stored) as f64,
        }
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
