//! The receiver-normal buffer: the second render target of the scene pass, the unit normal of
//! the surface each pixel shows, as the fragment programs of `horizon = clip` read it
//! ([`crate::methods::horizon_clip`], issue 28).
//!
//! Format choice — **RGBA16F** (three fp16 components and an unused alpha, 8 bytes per
//! pixel): the papers' GPUs (NV3x, R300) render to 64-bit half-float targets but have no
//! 48-bit RGB16F one, and have no signed 8-bit render targets at all. Against RGBA8 SNORM
//! (4 bytes, each component on the grid k/127) the cost is 4 bytes per pixel; the gain is the
//! precision the horizon needs: the plane's distance to the light moves by the normal's error
//! times the light's distance, so a component error of 1/254 (8-bit, about 0.2°) at a light
//! five of its half-extents away moves the cut by ~0.02 of the light — as large as the
//! horizon error `clip` is meant to remove — while fp16's relative 2⁻¹¹ moves it by ~0.002.
//! Each component is rounded to fp16 (to nearest, ties to even,
//! [`crate::gpu::shader_float::FP16`]); the stored vector is not re-normalized, as a GPU
//! writing `normalize(n)` to a half target does not.

use crate::gpu::shader_float::FP16;
use glam::{DVec3, Vec3};

/// The buffer's format, as the plan lists it.
pub const FORMAT: &str = "RGBA16F";

/// Bytes per pixel (RGBA16F; module doc).
pub const BYTES_PER_PIXEL: u32 = 8;

/// The unit normal `n` as the buffer stores it: each component rounded to fp16.
pub fn quantize(n: Vec3) -> DVec3 {
    let n = n.as_dvec3();
    DVec3::new(FP16.round(n.x), FP16.round(n.y), FP16.round(n.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// fp16 holds ±1, 0 and ½ exactly, and rounds 1/3 to 0x3555 = 1365/4096 (11 significant
    /// bits: 1/3 = 0.0101…₂, the 12th bit and the rest below half).
    #[test]
    fn components_round_to_half_floats() {
        assert_eq!(
            quantize(Vec3::new(1.0, 0.0, -0.5)),
            DVec3::new(1.0, 0.0, -0.5)
        );
        let third = quantize(Vec3::splat(1.0 / 3.0));
        assert_eq!(third.x, 1365.0 / 4096.0);
        assert_eq!(third.x, f64::from(half::f16::from_f32(1.0 / 3.0).to_f32()));
    }
}
