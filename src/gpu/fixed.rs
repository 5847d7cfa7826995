//! Fixed-point window coordinates (`docs/architecture.md` "Rasterization").
//!
//! Window x and y are snapped to [`SUBPIXEL_BITS`] = 8 fractional bits, rounding half to even,
//! after subtracting the 0.5 pixel-center offset, so that the sample of pixel i sits exactly at
//! the integer `i << 8`. Snapping happens in OpenGL orientation (y up); the flip to image rows
//! (row 0 at the top) is then the exact integer map `Y_img = (H−1)·256 − Y_gl`.

use crate::limits::{FIXED_ONE, SUBPIXEL_BITS};

/// A window coordinate in 24.8 fixed point with the pixel-center offset removed:
/// pixel i's sample is at `Fixed8(i << 8)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Fixed8(pub i64);

impl Fixed8 {
    /// Snap an f32 window coordinate: `round_half_even((x − 0.5) · 256)`.
    /// The subtraction is done in f32 like the hardware does; scaling by 256 is exact.
    pub fn snap(x_window: f32) -> Fixed8 {
        let shifted = (x_window - 0.5) * (FIXED_ONE as f32);
        Fixed8(shifted.round_ties_even() as i64)
    }

    /// The image-space coordinate for GL-space fixed `y` in an image of `height` rows.
    pub fn flip_y(self, height: u32) -> Fixed8 {
        Fixed8(((height as i64 - 1) << SUBPIXEL_BITS) - self.0)
    }

    /// Index of the first pixel whose sample is ≥ this coordinate.
    pub fn ceil_pixel(self) -> i64 {
        (self.0 + FIXED_ONE - 1).div_euclid(FIXED_ONE)
    }

    /// Index of the last pixel whose sample is ≤ this coordinate.
    pub fn floor_pixel(self) -> i64 {
        self.0.div_euclid(FIXED_ONE)
    }

    /// The value in pixels as f64 (exact).
    pub fn to_f64(self) -> f64 {
        self.0 as f64 / FIXED_ONE as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_centers_are_integers() {
        assert_eq!(Fixed8::snap(0.5), Fixed8(0));
        assert_eq!(Fixed8::snap(3.5), Fixed8(3 * 256));
    }

    #[test]
    fn snapping_rounds_half_to_even() {
        // 0.5 + 0.5/256 → 0.5 units → 0; 0.5 + 1.5/256 → 1.5 units → 2.
        assert_eq!(Fixed8::snap(0.5 + 0.5 / 256.0), Fixed8(0));
        assert_eq!(Fixed8::snap(0.5 + 1.5 / 256.0), Fixed8(2));
        assert_eq!(Fixed8::snap(0.5 - 0.5 / 256.0), Fixed8(0));
    }

    #[test]
    fn flip_maps_gl_rows_to_image_rows() {
        // GL row 0 (bottom) is image row H−1.
        assert_eq!(Fixed8(0).flip_y(4), Fixed8(3 * 256));
        assert_eq!(Fixed8(3 * 256).flip_y(4), Fixed8(0));
    }

    /// The first pixel whose sample `i·256` is ≥ the coordinate, and the last one ≤ it, on
    /// both sides of every sample and of 0 (`div_euclid`, not truncation, below 0).
    #[test]
    fn pixel_ranges_on_both_sides_of_each_sample() {
        for i in -3i64..=3 {
            let sample = Fixed8(i * 256);
            assert_eq!(sample.ceil_pixel(), i);
            assert_eq!(sample.floor_pixel(), i);
            assert_eq!(Fixed8(i * 256 + 1).ceil_pixel(), i + 1);
            assert_eq!(Fixed8(i * 256 + 1).floor_pixel(), i);
            assert_eq!(Fixed8(i * 256 - 1).ceil_pixel(), i);
            assert_eq!(Fixed8(i * 256 - 1).floor_pixel(), i - 1);
        }
    }

    /// The value in pixels, exactly: 24.8 fixed point over 256.
    #[test]
    fn to_f64_is_the_value_over_256() {
        assert_eq!(Fixed8(384).to_f64(), 1.5);
        assert_eq!(Fixed8(-1).to_f64(), -1.0 / 256.0);
        assert_eq!(Fixed8(0).to_f64(), 0.0);
    }

    #[test]
    fn pixel_ranges() {
        assert_eq!(Fixed8(1).ceil_pixel(), 1);
        assert_eq!(Fixed8(256).ceil_pixel(), 1);
        assert_eq!(Fixed8(-1).floor_pixel(), -1);
        assert_eq!(Fixed8(255).floor_pixel(), 0);
    }
}
