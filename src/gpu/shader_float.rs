//! The fragment programs' scalar: arithmetic rounded to the shader precision of the emulated
//! GPU (`[options.gpu] shader`, issue 11).
//!
//! A fragment program written against [`ShaderFloat`] reads the same at every precision; the
//! method picks the type once per pass with [`with_shader_float!`](crate::with_shader_float)
//! from [`ShaderPrecision`]. Every operation — `+ − × ÷`, `sqrt`, the conversion from f64
//! (constants, uniforms, interpolated inputs), and the transcendental calls (computed with the
//! `libm` crate in f64, then rounded) — returns its exact (or f64) result rounded to the
//! format: round to nearest, ties to even, at the format's mantissa width, then the exponent
//! range enforced. `abs`, `min`, `max`, `clamp`, `floor`, `signum`, negation and comparisons are
//! exact in every format and need no rounding. Computing an operation in f64 and rounding once
//! to a narrower format gives the correctly rounded result for `+ − × ÷ sqrt` whenever f64 has
//! at least 2p + 2 significand bits for the target's p (Figueroa, "When is double rounding
//! innocuous?", SIGNUM 1995): p = 24, 17 and 11 here, against f64's 53.
//!
//! # The formats
//!
//! | name | sign / exponent / mantissa bits | bias | normal exponents | denormals | overflow | largest finite |
//! |---|---|---|---|---|---|---|
//! | `f64` | 1 / 11 / 52 | 1023 | −1022…1023 | kept | ±∞ | ≈ 1.80·10³⁰⁸ |
//! | `fp32` | 1 / 8 / 23 | 127 | −126…127 | kept | ±∞ | (2 − 2⁻²³)·2¹²⁷ ≈ 3.40·10³⁸ |
//! | `fp24` | 1 / 7 / 16 | 63 | −62…63 | flushed to ±0 | ±∞ | (2 − 2⁻¹⁶)·2⁶³ ≈ 1.84·10¹⁹ |
//! | `fp16` | 1 / 5 / 10 | 15 | −14…15 | kept | ±∞ | 65504 |
//!
//! * **`f64`** is the identity: the default precision's scalar [`ShaderF64`] (and `f64`'s own
//!   [`ShaderFloat`] implementation, the uncounted reference arithmetic of tests and CPU stages)
//!   is plain f64 arithmetic, so the default leaves every output bit-identical to the code
//!   before shader precision existed. Every fragment-program scalar counts its operations
//!   ([`super::shader_ops`]); `f64` does not.
//! * **`fp32`**: IEEE 754 binary32, as NV3x's (GeForce FX) and G70's (GeForce 7800) `float`
//!   (Paper III's Cg shaders; Forest et al. 2006). Denormals are kept, so the arithmetic equals
//!   Rust's `f32` bit for bit (a property test checks it).
//! * **`fp24`**: the ATI R300 (Radeon 9700 Pro) "full precision" format: 1 sign, 7 exponent and
//!   16 (+1 implicit) mantissa bits (Paper IV §5 tested on an ATI 9700 Pro; the format as listed
//!   by Wikipedia "Minifloat": "The Radeon R300 and R420 GPUs used an fp24 floating-point
//!   format with 7 bits of exponent and 16 bits (+1 implicit) of mantissa"; DirectX 9's pixel
//!   shader 2.0 full precision requires at least this, "s16e7"). The sources give neither the
//!   bias nor the special values; the choice here is IEEE-like: bias 63, exponent field 0 is
//!   zero (no denormals: a result below 2⁻⁶² after rounding is flushed to a zero of its sign,
//!   which is what hardware without denormal support does), field 127 holds ±∞ (overflow
//!   rounds to ±∞ as IEEE does; R300 may have clamped instead — the sources are silent, and
//!   no fragment program here produces values near 10¹⁹, so the choice does not show).
//! * **`fp16`**: IEEE 754 binary16, NVIDIA's `half` of NV3x and G70 (Cg's `half`; the same
//!   format as OpenEXR's `half` and the `NV_half_float` OpenGL extension, whose format
//!   definition includes the denormals 2⁻¹⁴·m/1024). Denormals are kept, as that definition
//!   gives them; whether NV3x's arithmetic units flushed half denormals in results is not
//!   documented, and keeping them matches the `half` crate (checked in the tests).
//!
//! Rounding is applied to the exact result with an unbounded exponent first, then the range
//! rules: a result at or above the largest finite value plus half an ulp becomes ±∞; with
//! denormals kept the rounding is on the denormal grid (2^(emin − mantissa bits)); with
//! denormals flushed, a rounded result below the smallest normal becomes ±0. NaN stays NaN.
//!
//! # Generic, not runtime-dispatched
//!
//! The fragment code is generic over [`ShaderFloat`] and monomorphized per format (four copies
//! of each converted pass, chosen once per pass by [`with_shader_float!`](crate::with_shader_float)).
//! The alternative, one runtime type that looks up its format and branches on it in every
//! operation, was measured on the same code — `ssv`'s exact edge coverage
//! ([`crate::light::coverage::shader_edge_coverage`]) on 1000 fixed pseudo-random receivers and
//! edges at f64, criterion benchmark `benches/shader_float.rs` (`cargo bench --bench
//! shader_float`), on the shared 2-core machine: median 299 µs for the generic f64 instance
//! (plain f64 code) against 778 µs for the runtime-dispatched type (its format in an atomic
//! read per operation) — 2.6× slower at the default precision. The cost of the generic choice
//! is compile time and code size, paid only in the converted passes.

use super::shader_ops;
use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// The precision of the fragment programs (`[options.gpu] shader`; module doc, "The formats").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum ShaderPrecision {
    /// f64: the project's reference arithmetic (default).
    F64,
    /// IEEE binary32 (NV3x / G70 `float`).
    Fp32,
    /// ATI R300 24-bit float (s16e7).
    Fp24,
    /// IEEE binary16 (NV3x / G70 `half`).
    Fp16,
}

/// How a format treats results below its smallest normal number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Denormals {
    /// Gradual underflow on the denormal grid (IEEE).
    Kept,
    /// Flushed to a zero of the result's sign.
    Flushed,
}

/// A binary floating-point format (module doc, "The formats").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FloatFormat {
    /// Stored mantissa bits (the precision is one more, the implicit bit).
    pub mantissa_bits: i32,
    /// Exponent of the smallest normal number.
    pub min_exp: i32,
    /// Exponent of the largest finite number.
    pub max_exp: i32,
    /// Results below the smallest normal number.
    pub denormals: Denormals,
}

/// IEEE binary64, the `f64` precision (its arithmetic is plain f64; the format describes its
/// rounding for error bounds such as [`super::hiz::plane_rejects_box`]'s).
pub const F64: FloatFormat = FloatFormat {
    mantissa_bits: 52,
    min_exp: -1022,
    max_exp: 1023,
    denormals: Denormals::Kept,
};

/// IEEE binary32.
pub const FP32: FloatFormat = FloatFormat {
    mantissa_bits: 23,
    min_exp: -126,
    max_exp: 127,
    denormals: Denormals::Kept,
};

/// ATI R300's 24-bit float: 7 exponent bits, bias 63, no denormals (module doc).
pub const FP24: FloatFormat = FloatFormat {
    mantissa_bits: 16,
    min_exp: -62,
    max_exp: 63,
    denormals: Denormals::Flushed,
};

/// IEEE binary16 (`half`).
pub const FP16: FloatFormat = FloatFormat {
    mantissa_bits: 10,
    min_exp: -14,
    max_exp: 15,
    denormals: Denormals::Kept,
};

impl ShaderPrecision {
    /// The format this precision rounds to.
    pub fn format(self) -> FloatFormat {
        match self {
            ShaderPrecision::F64 => F64,
            ShaderPrecision::Fp32 => FP32,
            ShaderPrecision::Fp24 => FP24,
            ShaderPrecision::Fp16 => FP16,
        }
    }
}

impl FloatFormat {
    /// The largest finite value, `(2 − 2^−mantissa_bits)·2^max_exp`.
    pub fn max_finite(&self) -> f64 {
        libm::ldexp(2.0 - libm::ldexp(1.0, -self.mantissa_bits), self.max_exp)
    }

    /// The smallest positive normal value, `2^min_exp`.
    pub fn min_normal(&self) -> f64 {
        libm::ldexp(1.0, self.min_exp)
    }

    /// `x` rounded to this format (module doc): to nearest, ties to even, at the mantissa
    /// width; beyond the largest finite value ±∞; below the smallest normal on the denormal
    /// grid or flushed to ±0. NaN, infinities and zeros are returned as they are.
    #[inline]
    pub fn round(&self, x: f64) -> f64 {
        if x == 0.0 || !x.is_finite() {
            return x;
        }
        // fp32 is IEEE binary32 with denormals: the conversion to f32 rounds exactly as the
        // grid below does (to nearest even, denormals on their grid, ±∞ past the largest
        // finite value; tested), with one instruction instead of `ilogb`, two `ldexp` and a
        // software `rint` (a third of `wedge-blending`, whose vBuffer arithmetic is fp32).
        if *self == FP32 {
            return x as f32 as f64;
        }
        self.round_on_grid(x)
    }

    /// [`FloatFormat::round`] of a finite non-zero `x` by scaling to the format's grid.
    fn round_on_grid(&self, x: f64) -> f64 {
        let e = libm::ilogb(x);
        let quantum_exp = match self.denormals {
            Denormals::Kept => e.max(self.min_exp) - self.mantissa_bits,
            // Far below the smallest normal: no rounding can reach it (and the scaling below
            // could overflow).
            Denormals::Flushed if e < self.min_exp - 1 => return libm::copysign(0.0, x),
            Denormals::Flushed => e - self.mantissa_bits,
        };
        // Both scalings are by powers of two within f64's range: exact.
        let r = libm::ldexp(libm::ldexp(x, -quantum_exp).round_ties_even(), quantum_exp);
        if r.abs() > self.max_finite() {
            libm::copysign(f64::INFINITY, x)
        } else if self.denormals == Denormals::Flushed && r.abs() < self.min_normal() {
            libm::copysign(0.0, x)
        } else {
            r
        }
    }
}

/// A fragment program's scalar (module doc): arithmetic rounded to one format.
///
/// The default methods compute in f64 with the `libm` crate and round with
/// [`ShaderFloat::from_f64`]; the f64 implementation is therefore plain f64 arithmetic.
pub trait ShaderFloat:
    Copy
    + Default
    + Debug
    + PartialEq
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Send
    + Sync
    + 'static
{
    /// The precision this type computes in.
    const PRECISION: ShaderPrecision;

    /// Whether its operations are counted ([`shader_ops`]): the fragment programs' scalars
    /// are, `f64` (the uncounted reference arithmetic) is not.
    const COUNTED: bool = true;

    /// This format, or fp32 where this one is wider (f64): the scalar of a fragment program
    /// whose arithmetic was fp32 before shader precision existed — `wedge-blending`'s vBuffer
    /// arithmetic ([`crate::methods::wedge_blending::blend`]), whose values are the f32 the
    /// vBuffers store, and `ssv-optimized`'s plane-equation split (Paper IV §4.4) — so that the
    /// default keeps its bits and the narrower formats round as every other program does.
    /// Every value of it is an exact f32.
    type AtMostFp32: ShaderFloat;

    /// `x` rounded to the format (a constant, a uniform or an interpolated input).
    fn from_f64(x: f64) -> Self;

    /// The value as f64 (exact).
    fn to_f64(self) -> f64;

    /// Zero.
    fn zero() -> Self {
        Self::from_f64(0.0)
    }

    /// One.
    fn one() -> Self {
        Self::from_f64(1.0)
    }

    /// Square root, rounded.
    fn sqrt(self) -> Self {
        if Self::COUNTED {
            shader_ops::alu(2);
        }
        Self::from_f64(libm::sqrt(self.to_f64()))
    }

    /// `atan2(self, x)` (`libm`), rounded.
    fn atan2(self, x: Self) -> Self {
        if Self::COUNTED {
            shader_ops::transcendental();
        }
        Self::from_f64(libm::atan2(self.to_f64(), x.to_f64()))
    }

    /// `acos` (`libm`), rounded.
    fn acos(self) -> Self {
        if Self::COUNTED {
            shader_ops::transcendental();
        }
        Self::from_f64(libm::acos(self.to_f64()))
    }

    /// `tan` (`libm`), rounded.
    fn tan(self) -> Self {
        if Self::COUNTED {
            shader_ops::transcendental();
        }
        Self::from_f64(libm::tan(self.to_f64()))
    }

    /// The nearest integer, halves away from zero (f64 `round`; exact).
    fn round(self) -> Self {
        if Self::COUNTED {
            shader_ops::alu(2);
        }
        Self::from_f64(self.to_f64().round())
    }

    /// The least non-negative remainder of `self` by `rhs` (f64 `rem_euclid`): the remainder
    /// `self mod rhs` is exact in every format, and the one addition of `|rhs|` to a negative
    /// remainder is rounded once (module doc: double rounding is innocuous for `+`).
    fn rem_euclid(self, rhs: Self) -> Self {
        if Self::COUNTED {
            shader_ops::alu(3);
        }
        Self::from_f64(self.to_f64().rem_euclid(rhs.to_f64()))
    }

    /// Absolute value (exact).
    fn abs(self) -> Self {
        Self::from_f64(self.to_f64().abs())
    }

    /// The smaller of the two; NaN when either is NaN (issue 31: f64 `min` returns the other
    /// operand, which would turn a NaN coverage into a valid-looking 0 or 1 — a NaN must stay
    /// visible; the GL specs leave `min` of a NaN undefined, so this is the choice).
    fn min(self, other: Self) -> Self {
        if Self::COUNTED {
            shader_ops::alu(1);
        }
        let (a, b) = (self.to_f64(), other.to_f64());
        Self::from_f64(if a.is_nan() || b.is_nan() {
            f64::NAN
        } else {
            a.min(b)
        })
    }

    /// The larger of the two; NaN when either is NaN (as [`ShaderFloat::min`]).
    fn max(self, other: Self) -> Self {
        if Self::COUNTED {
            shader_ops::alu(1);
        }
        let (a, b) = (self.to_f64(), other.to_f64());
        Self::from_f64(if a.is_nan() || b.is_nan() {
            f64::NAN
        } else {
            a.max(b)
        })
    }

    /// `self` clamped to `[lo, hi]` (f64 `clamp`: NaN stays NaN).
    fn clamp(self, lo: Self, hi: Self) -> Self {
        if Self::COUNTED {
            shader_ops::alu(2);
        }
        Self::from_f64(self.to_f64().clamp(lo.to_f64(), hi.to_f64()))
    }

    /// Largest integer not above `self` (exact).
    fn floor(self) -> Self {
        if Self::COUNTED {
            shader_ops::alu(1);
        }
        Self::from_f64(libm::floor(self.to_f64()))
    }

    /// `1`, `−1` (by the sign bit, as f64 `signum`), or NaN.
    fn signum(self) -> Self {
        if Self::COUNTED {
            shader_ops::alu(2);
        }
        Self::from_f64(self.to_f64().signum())
    }

    /// Whether the value is neither infinite nor NaN.
    fn is_finite(self) -> bool {
        if Self::COUNTED {
            shader_ops::alu(1);
        }
        self.to_f64().is_finite()
    }
}

impl ShaderFloat for f64 {
    const PRECISION: ShaderPrecision = ShaderPrecision::F64;
    const COUNTED: bool = false;
    type AtMostFp32 = Fp32;

    fn from_f64(x: f64) -> Self {
        x
    }

    fn to_f64(self) -> f64 {
        self
    }
}

/// A scalar type whose every operation rounds to `$format` (module doc).
macro_rules! rounded_float {
    ($(#[$meta:meta])* $name:ident, $round:expr, $precision:expr, $at_most_fp32:ty) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, Default)]
        pub struct $name(f64);

        impl ShaderFloat for $name {
            const PRECISION: ShaderPrecision = $precision;
            type AtMostFp32 = $at_most_fp32;

            #[inline]
            fn from_f64(x: f64) -> Self {
                let round: fn(f64) -> f64 = $round;
                $name(round(x))
            }

            fn to_f64(self) -> f64 {
                self.0
            }
        }

        impl Add for $name {
            type Output = Self;
            fn add(self, rhs: Self) -> Self {
                shader_ops::alu(1);
                Self::from_f64(self.0 + rhs.0)
            }
        }

        impl Sub for $name {
            type Output = Self;
            fn sub(self, rhs: Self) -> Self {
                shader_ops::alu(1);
                Self::from_f64(self.0 - rhs.0)
            }
        }

        impl Mul for $name {
            type Output = Self;
            fn mul(self, rhs: Self) -> Self {
                shader_ops::alu(1);
                Self::from_f64(self.0 * rhs.0)
            }
        }

        impl Div for $name {
            type Output = Self;
            fn div(self, rhs: Self) -> Self {
                shader_ops::alu(2);
                Self::from_f64(self.0 / rhs.0)
            }
        }

        impl Neg for $name {
            type Output = Self;
            fn neg(self) -> Self {
                $name(-self.0)
            }
        }

        /// A comparison is one instruction (`SLT`, `SGE`, `CMP`; [`shader_ops`]).
        impl PartialEq for $name {
            fn eq(&self, other: &Self) -> bool {
                shader_ops::alu(1);
                self.0 == other.0
            }
        }

        impl PartialOrd for $name {
            fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
                shader_ops::alu(1);
                self.0.partial_cmp(&other.0)
            }
        }
    };
}

rounded_float!(
    /// The default precision's scalar in a fragment program: plain f64 arithmetic (the same
    /// bits as `f64`'s [`ShaderFloat`]), every operation counted ([`shader_ops`]). `f64`
    /// itself stays the uncounted reference arithmetic of the tests and the CPU stages.
    ShaderF64,
    |x| x,
    ShaderPrecision::F64,
    Fp32
);
rounded_float!(
    /// IEEE binary32 arithmetic ([`FP32`]).
    Fp32,
    |x| FP32.round(x),
    ShaderPrecision::Fp32,
    Self
);
rounded_float!(
    /// ATI R300 24-bit float arithmetic ([`FP24`]).
    Fp24,
    |x| FP24.round(x),
    ShaderPrecision::Fp24,
    Self
);
rounded_float!(
    /// IEEE binary16 arithmetic ([`FP16`]).
    Fp16,
    |x| FP16.round(x),
    ShaderPrecision::Fp16,
    Self
);

/// Evaluate `$body` with the type name `$t` bound to the [`ShaderFloat`] of `$precision` (a
/// [`ShaderPrecision`]): `with_shader_float!(frame.gpu.shader, T => pass::<T>(frame))`.
#[macro_export]
macro_rules! with_shader_float {
    ($precision:expr, $t:ident => $body:expr) => {
        match $precision {
            $crate::gpu::shader_float::ShaderPrecision::F64 => {
                type $t = $crate::gpu::shader_float::ShaderF64;
                $body
            }
            $crate::gpu::shader_float::ShaderPrecision::Fp32 => {
                type $t = $crate::gpu::shader_float::Fp32;
                $body
            }
            $crate::gpu::shader_float::ShaderPrecision::Fp24 => {
                type $t = $crate::gpu::shader_float::Fp24;
                $body
            }
            $crate::gpu::shader_float::ShaderPrecision::Fp16 => {
                type $t = $crate::gpu::shader_float::Fp16;
                $body
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A NaN operand of `min`, `max` and `clamp` gives NaN in every format, on either side: it
    /// never becomes the other operand (a NaN coverage must not read as 0 or full coverage).
    #[test]
    fn min_max_and_clamp_keep_a_nan() {
        fn check<T: ShaderFloat>() {
            let (nan, one) = (T::from_f64(f64::NAN), T::one());
            for v in [
                nan.min(one),
                one.min(nan),
                nan.max(one),
                one.max(nan),
                nan.clamp(T::zero(), one),
            ] {
                assert!(v.to_f64().is_nan(), "{v:?}");
            }
            assert_eq!(one.min(T::zero()).to_f64(), 0.0);
            assert_eq!(one.max(T::zero()).to_f64(), 1.0);
        }
        check::<f64>();
        check::<Fp32>();
        check::<Fp24>();
        check::<Fp16>();
    }

    /// fp32's fast path gives the bits of rounding on the grid: random doubles over the whole
    /// range, the denormal range, the overflow boundary and ties.
    #[test]
    fn fp32_conversion_rounds_as_the_grid_does() {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let max = FP32.max_finite();
        let half_ulp_max = libm::ldexp(1.0, 127 - 24);
        let mut cases = vec![
            max,
            max + half_ulp_max,
            max + half_ulp_max * 0.999,
            -(max + half_ulp_max),
            f64::MAX,
            f64::MIN_POSITIVE,
            libm::ldexp(1.0, -149),
            libm::ldexp(1.0, -150),
            libm::ldexp(1.5, -150),
            libm::ldexp(1.0, -151),
            1.0 + libm::ldexp(1.0, -24),
            1.0 + libm::ldexp(3.0, -24),
        ];
        for _ in 0..200_000 {
            let bits = next();
            cases.push(f64::from_bits(bits));
            // Near the f32 range, and in its denormals.
            let m = f64::from_bits(bits >> 12 | 0x3FF0_0000_0000_0000);
            cases.push(
                libm::ldexp(m, (next() % 300) as i32 - 160)
                    * if bits & 1 == 0 { 1.0 } else { -1.0 },
            );
        }
        for x in cases {
            if x == 0.0 || !x.is_finite() {
                continue;
            }
            assert_eq!(
                FP32.round(x).to_bits(),
                FP32.round_on_grid(x).to_bits(),
                "{x:e}"
            );
        }
    }
    use proptest::prelude::*;

    fn b<T: ShaderFloat>(x: f64) -> f64 {
        T::from_f64(x).to_f64()
    }

    #[test]
    fn ties_round_to_even() {
        // 1 + 2^-24 lies halfway between 1 and 1 + 2^-23 in fp32: the even one is 1.
        assert_eq!(b::<Fp32>(1.0 + libm::ldexp(1.0, -24)), 1.0);
        // 1 + 3·2^-24 lies halfway between 1 + 2^-23 (odd) and 1 + 2^-22 (even).
        assert_eq!(
            b::<Fp32>(1.0 + 3.0 * libm::ldexp(1.0, -24)),
            1.0 + libm::ldexp(1.0, -22)
        );
        // fp24: ulp at 1 is 2^-16.
        assert_eq!(b::<Fp24>(1.0 + libm::ldexp(1.0, -17)), 1.0);
        assert_eq!(
            b::<Fp24>(1.0 + 3.0 * libm::ldexp(1.0, -17)),
            1.0 + libm::ldexp(1.0, -15)
        );
        // fp16: ulp at 1 is 2^-10; 2049 lies between 2048 and 2050 (ulp 2): 2048 is even.
        assert_eq!(b::<Fp16>(1.0 + libm::ldexp(1.0, -11)), 1.0);
        assert_eq!(b::<Fp16>(2049.0), 2048.0);
        assert_eq!(b::<Fp16>(2051.0), 2052.0);
        // Just above a tie rounds up.
        assert_eq!(b::<Fp16>(2049.0 + 1e-9), 2050.0);
    }

    #[test]
    fn largest_finite_and_overflow_to_infinity() {
        assert_eq!(FP32.max_finite(), f32::MAX as f64);
        assert_eq!(FP16.max_finite(), 65504.0);
        assert_eq!(
            FP24.max_finite(),
            (2.0 - libm::ldexp(1.0, -16)) * libm::ldexp(1.0, 63)
        );
        for (f, max, ulp_exp) in [
            (FP32, FP32.max_finite(), 127 - 23),
            (FP24, FP24.max_finite(), 63 - 16),
            (FP16, 65504.0, 15 - 10),
        ] {
            let half_ulp = libm::ldexp(1.0, ulp_exp - 1);
            assert_eq!(f.round(max), max);
            // Below the halfway point to 2^(emax+1): stays at max; at it: the tie rounds to
            // the even 2^(emax+1), which overflows.
            assert_eq!(f.round(max + half_ulp * 0.99), max);
            assert_eq!(f.round(max + half_ulp), f64::INFINITY);
            assert_eq!(f.round(-(max + half_ulp)), f64::NEG_INFINITY);
        }
        assert_eq!(b::<Fp16>(65519.0), 65504.0);
        assert_eq!(b::<Fp16>(65520.0), f64::INFINITY);
        let big = Fp16::from_f64(300.0);
        assert_eq!((big * big).to_f64(), f64::INFINITY);
        let big = Fp24::from_f64(libm::ldexp(1.0, 40));
        assert_eq!((big * big).to_f64(), f64::INFINITY);
        assert_eq!(
            (Fp32::from_f64(1e30) * Fp32::from_f64(1e30)).to_f64(),
            f64::INFINITY
        );
    }

    #[test]
    fn fp24_exponent_range_and_flushed_denormals() {
        // Smallest normal 2^-62 is kept; below it everything is flushed, keeping the sign.
        let min = libm::ldexp(1.0, -62);
        assert_eq!(FP24.min_normal(), min);
        assert_eq!(b::<Fp24>(min), min);
        assert_eq!(b::<Fp24>(min * 0.75), 0.0);
        assert!(b::<Fp24>(-min * 0.75).is_sign_negative());
        assert_eq!(b::<Fp24>(-min * 0.75), 0.0);
        // Just below 2^-62 but rounding up to it at 17 bits: kept as the normal 2^-62.
        assert_eq!(b::<Fp24>(min * (1.0 - libm::ldexp(1.0, -20))), min);
        // A product underflowing the range flushes; the same product in fp32 does not.
        let small = Fp24::from_f64(libm::ldexp(1.0, -40));
        assert_eq!((small * small).to_f64(), 0.0);
        assert_eq!(
            b::<Fp32>(libm::ldexp(1.0, -80)),
            libm::ldexp(1.0, -80),
            "2^-80 is a normal fp32"
        );
        // Largest exponent: 2^63 is finite, 2^64 is not.
        assert_eq!(b::<Fp24>(libm::ldexp(1.0, 63)), libm::ldexp(1.0, 63));
        assert_eq!(b::<Fp24>(libm::ldexp(1.0, 64)), f64::INFINITY);
        assert_eq!(b::<Fp24>(1e-300), 0.0);
    }

    #[test]
    fn fp16_keeps_denormals_on_their_grid() {
        let tiny = libm::ldexp(1.0, -24); // smallest fp16 denormal
        assert_eq!(b::<Fp16>(tiny), tiny);
        assert_eq!(
            b::<Fp16>(tiny * 0.5),
            0.0,
            "a tie with 0 rounds to the even 0"
        );
        assert_eq!(b::<Fp16>(tiny * 0.51), tiny);
        assert_eq!(b::<Fp16>(tiny * 1.5), 2.0 * tiny, "tie to the even 2·2^-24");
        assert_eq!(b::<Fp16>(3.3 * tiny), 3.0 * tiny);
        // fp32 keeps its denormals too.
        let d = f32::from_bits(1) as f64;
        assert_eq!(b::<Fp32>(d), d);
    }

    #[test]
    fn one_third_in_each_format() {
        let one_third = |t: f64| (t - 1.0 / 3.0).abs();
        let (f32v, f24v, f16v) = (
            (Fp32::one() / Fp32::from_f64(3.0)).to_f64(),
            (Fp24::one() / Fp24::from_f64(3.0)).to_f64(),
            (Fp16::one() / Fp16::from_f64(3.0)).to_f64(),
        );
        // 1/3 = 0.010101…₂: truncated after p significant bits, the next bit decides.
        assert_eq!(f32v, (1.0f32 / 3.0f32) as f64);
        // fp24: 17 significant bits 1.0101010101010101₂·2^-2 (next bit 0: rounds down).
        assert_eq!(f24v, 87381.0 * libm::ldexp(1.0, -18));
        // fp16: 11 significant bits 1.0101010101₂·2^-2 (next bit 0: rounds down).
        assert_eq!(f16v, 1365.0 * libm::ldexp(1.0, -12));
        assert!(one_third(f24v) <= libm::ldexp(1.0, -2 - 17));
        assert!(one_third(f16v) <= libm::ldexp(1.0, -2 - 11));
        assert_eq!(
            (f64::one() / f64::from_f64(3.0)).to_bits(),
            (1.0f64 / 3.0).to_bits()
        );
    }

    #[test]
    fn f64_is_the_identity() {
        for x in [0.1, -1e-310, 1e300, f64::MAX, f64::MIN_POSITIVE] {
            assert_eq!(f64::from_f64(x).to_bits(), x.to_bits());
        }
        assert_eq!(f64::from_f64(2.0).sqrt(), libm::sqrt(2.0));
    }

    #[test]
    fn fp16_conversion_matches_the_half_crate() {
        // Every fp16 value, the midpoints between neighbours and the f32 values either side of
        // them: rounding to fp16 here must agree with the `half` crate. Its f32 → f16 is used:
        // its f64 → f16 drops the low 32 mantissa bits before rounding, so a value just above
        // a tie by less than that rounds as the tie there (2^-25·(1 + 10^-12) gives 0, the
        // correctly rounded result is 2^-24).
        for bits in 0u16..=0xffff {
            let h = half::f16::from_bits(bits);
            if h.is_nan() {
                continue;
            }
            let x = h.to_f64();
            assert_eq!(b::<Fp16>(x).to_bits(), x.to_bits(), "{bits:#x}");
            let next = half::f16::from_bits(bits.wrapping_add(1));
            if next.is_nan() || next.is_infinite() || bits == 0x7fff || bits == 0xffff {
                continue;
            }
            // Exact in f32: neighbours differ in the 12th significant bit at most.
            let mid = (0.5 * (x + next.to_f64())) as f32;
            assert_eq!(mid as f64, 0.5 * (x + next.to_f64()));
            for m in [
                mid,
                f32::from_bits(mid.to_bits() + 1),
                f32::from_bits(mid.to_bits().saturating_sub(1)),
            ] {
                let want = half::f16::from_f32(m).to_f64();
                assert_eq!(
                    b::<Fp16>(m as f64).to_bits(),
                    want.to_bits(),
                    "{m} after {bits:#x}"
                );
            }
        }
    }

    fn f32_value() -> impl Strategy<Value = f32> {
        prop_oneof![
            any::<u32>().prop_map(f32::from_bits),
            (-1e3f32..1e3f32),
            (-1.0f32..1.0f32),
        ]
    }

    fn same(a: f64, b: f32) -> bool {
        (a.is_nan() && b.is_nan()) || a.to_bits() == (b as f64).to_bits()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4000))]
        /// fp32 is Rust's f32 arithmetic, bit for bit, on every operation.
        #[test]
        fn fp32_equals_rust_f32(x in f32_value(), y in f32_value(), z in any::<u64>()) {
            let (a, c) = (Fp32::from_f64(x as f64), Fp32::from_f64(y as f64));
            prop_assert!(same(a.to_f64(), x));
            prop_assert!(same((a + c).to_f64(), x + y));
            prop_assert!(same((a - c).to_f64(), x - y));
            prop_assert!(same((a * c).to_f64(), x * y));
            prop_assert!(same((a / c).to_f64(), x / y));
            prop_assert!(same((-a).to_f64(), -x));
            prop_assert!(same(a.sqrt().to_f64(), x.sqrt()));
            prop_assert!(same(a.abs().to_f64(), x.abs()));
            // min and max keep a NaN operand (f32's give the other one; ShaderFloat::min).
            let nan_or = |v: f32| if x.is_nan() || y.is_nan() { f32::NAN } else { v };
            prop_assert!(same(a.min(c).to_f64(), nan_or(x.min(y))));
            prop_assert!(same(a.max(c).to_f64(), nan_or(x.max(y))));
            prop_assert!(same(a.floor().to_f64(), x.floor()));
            prop_assert_eq!(a < c, x < y);
            prop_assert_eq!(a == c, x == y);
            // Conversion from any f64 is Rust's `as f32`.
            let w = f64::from_bits(z);
            prop_assert!(same(Fp32::from_f64(w).to_f64(), w as f32));
        }
    }
}
