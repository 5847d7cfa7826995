//! Four 8-bit values packed into the bits of one 32-bit float register, as NV_fragment_program
//! (and NV_fragment_program2, the instruction set of Forest, Barthe & Paulin 2006 §5.1) offers
//! with `PK4UB` / `UP4UB`, and the RGBA32F render-target channels such a packed scalar is
//! stored in (Forest 2006 §4.3, Fig. 11: "we can pack top, bottom, left and right coordinates
//! of the bounding rectangle in a single 32-bits scalar").
//!
//! # The instructions
//! * [`pk4ub`] (`PK4UB`): each of the four components is clamped to [0, 1], multiplied by 255
//!   and rounded to the nearest integer; the bytes are packed `x | y << 8 | z << 16 | w << 24`
//!   and the 32-bit pattern is the raw bits of a float register. The extension specifications
//!   say "rounded to the nearest integer" without a tie rule; we implement
//!   `floor(255·c + 0.5)` in f32 (ties upward, the formula of GLSL's `packUnorm4x8` and WGSL's
//!   `pack4x8unorm`). A tie needs `255·c` to be exactly k + ½ in f32, so the rule only matters
//!   for those inputs, and the unit tests pin it.
//! * [`up4ub`] (`UP4UB`): the inverse: byte `k` of the pattern becomes `k / 255` in f32.
//!   Unpacking then packing gives back every byte exactly (tested for all 256 values of every
//!   byte position, and by proptest for whole words).
//!
//! # Which patterns are not ordinary floats
//! The pattern is read as an IEEE binary32 by the render target. Its exponent field is bits
//! 23…30: the low seven bits of byte `w` and the top bit of byte `z`
//! ([`classify`]):
//! * **NaN or infinity** when `w & 0x7F == 0x7F` (w = 127 or 255) and `z ≥ 128`: infinity for
//!   the single mantissa-zero pattern of each sign (`z = 128`, `y = x = 0`), NaN otherwise.
//! * **Denormal** when `w & 0x7F == 0` (w = 0 or 128) and `z < 128`, unless the remaining 23
//!   bits are all zero (then it is ±0).
//!
//! A target that keeps the bits ([`FloatTarget::Raw`], what the NVIDIA hardware of the paper
//! did with a plain move into an RGBA32F buffer) stores every pattern. A target that flushes
//! denormals to zero ([`FloatTarget::FlushDenormals`]) or replaces every NaN by one canonical
//! quiet NaN ([`FloatTarget::CanonicalNans`]) corrupts the packed values of such patterns;
//! [`FloatTarget::store`] emulates each, and [`StoreEvents`] counts the patterns written so a
//! report can say how many pixels a less forgiving GPU would corrupt.

/// `PK4UB`: clamp each component to [0, 1], scale by 255, round (ties upward, module doc) and
/// pack as `x | y << 8 | z << 16 | w << 24`.
pub fn pk4ub(v: [f32; 4]) -> u32 {
    v.iter()
        .enumerate()
        .fold(0u32, |bits, (k, c)| bits | (unorm8(*c) as u32) << (8 * k))
}

/// The byte `PK4UB` makes of one component: `floor(255·clamp(c, 0, 1) + 0.5)` in f32; NaN
/// becomes 0 (the clamp of NV_fragment_program maps NaN to the lower bound).
pub fn unorm8(c: f32) -> u8 {
    let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
    // `255·c + 0.5` lies in [0.5, 255.5], where the conversion's truncation is the floor (a
    // libm `floorf` call on x86-64 without SSE4.1).
    (c * 255.0 + 0.5) as u8
}

/// `UP4UB`: byte k of `bits` (k = 0 the lowest) divided by 255, in f32.
pub fn up4ub(bits: u32) -> [f32; 4] {
    std::array::from_fn(|k| ((bits >> (8 * k)) & 0xFF) as f32 / 255.0)
}

/// What kind of binary32 value a 32-bit pattern is (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum FloatClass {
    /// +0 or −0.
    Zero,
    /// A normal number.
    Normal,
    /// A denormal (subnormal) number: exponent field 0, mantissa not 0.
    Denormal,
    /// ±infinity.
    Infinite,
    /// Not a number.
    Nan,
}

/// The class of the binary32 pattern `bits`.
pub fn classify(bits: u32) -> FloatClass {
    let exponent = (bits >> 23) & 0xFF;
    let mantissa = bits & 0x7F_FFFF;
    match (exponent, mantissa) {
        (0, 0) => FloatClass::Zero,
        (0, _) => FloatClass::Denormal,
        (0xFF, 0) => FloatClass::Infinite,
        (0xFF, _) => FloatClass::Nan,
        _ => FloatClass::Normal,
    }
}

/// The quiet NaN a NaN-canonicalizing target stores for every NaN (sign and payload lost).
pub const CANONICAL_NAN: u32 = 0x7FC0_0000;

/// How an RGBA32F render-target channel stores a 32-bit pattern (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum FloatTarget {
    /// Every bit is kept (the paper's hardware).
    Raw,
    /// Denormals are stored as zero of the same sign.
    FlushDenormals,
    /// Every NaN is stored as [`CANONICAL_NAN`].
    CanonicalNans,
}

/// How many packed patterns of each special class were written (counted at every store,
/// whatever the target does with them).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct StoreEvents {
    /// Patterns that are denormals as floats.
    pub denormal: u64,
    /// Patterns that are NaN as floats.
    pub nan: u64,
    /// Patterns that are infinities as floats.
    pub infinite: u64,
    /// Patterns the target changed (corrupted the packed bytes of).
    pub altered: u64,
}

impl std::ops::AddAssign for StoreEvents {
    fn add_assign(&mut self, o: Self) {
        self.denormal += o.denormal;
        self.nan += o.nan;
        self.infinite += o.infinite;
        self.altered += o.altered;
    }
}

impl FloatTarget {
    /// The bits this target holds after `bits` is written to it; the special classes of the
    /// written pattern and whether it was altered are added to `events`.
    pub fn store(self, bits: u32, events: &mut StoreEvents) -> u32 {
        let class = classify(bits);
        events.denormal += (class == FloatClass::Denormal) as u64;
        events.nan += (class == FloatClass::Nan) as u64;
        events.infinite += (class == FloatClass::Infinite) as u64;
        let stored = match (self, class) {
            (FloatTarget::FlushDenormals, FloatClass::Denormal) => bits & 0x8000_0000,
            (FloatTarget::CanonicalNans, FloatClass::Nan) => CANONICAL_NAN,
            _ => bits,
        };
        events.altered += (stored != bits) as u64;
        stored
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The truncating conversion is the formula's floor on a grid of 2²⁴ + 1 components over
    /// [0, 1] and at every tie `(k + ½)/255`.
    #[test]
    fn unorm8_is_the_floor_formula() {
        let floor_formula = |c: f32| (c * 255.0 + 0.5).floor() as u8;
        let grid = (0..=1u32 << 24).map(|k| k as f32 / (1u32 << 24) as f32);
        let ties = (0..255).map(|k| (k as f32 + 0.5) / 255.0);
        for c in grid.chain(ties) {
            assert_eq!(unorm8(c), floor_formula(c), "{c:e}");
        }
    }
    use proptest::prelude::*;

    #[test]
    fn every_byte_of_every_position_round_trips() {
        for pos in 0..4 {
            for b in 0..=255u32 {
                let bits = b << (8 * pos);
                assert_eq!(pk4ub(up4ub(bits)), bits, "byte {b} at position {pos}");
            }
        }
    }

    #[test]
    fn packing_clamps_and_rounds_to_nearest_with_ties_up() {
        assert_eq!(unorm8(-0.5), 0);
        assert_eq!(unorm8(2.0), 255);
        assert_eq!(unorm8(f32::NAN), 0);
        // 0.5·255 = 127.5 exactly in f32: the tie goes up.
        assert_eq!(unorm8(0.5), 128);
        // Just below and above a half step.
        assert_eq!(unorm8(1.49 / 255.0), 1);
        assert_eq!(unorm8(1.51 / 255.0), 2);
        assert_eq!(pk4ub([1.0, 0.0, 0.0, 0.0]), 0x0000_00FF);
        assert_eq!(pk4ub([0.0, 0.0, 0.0, 1.0]), 0xFF00_0000);
    }

    #[test]
    fn special_patterns_are_where_the_exponent_says() {
        // w = 255, z = 255: exponent all ones, mantissa non-zero.
        assert_eq!(classify(pk4ub([0.0, 0.0, 1.0, 1.0])), FloatClass::Nan);
        // w = 127, z = 128, y = x = 0: +infinity.
        assert_eq!(classify(0x7F80_0000), FloatClass::Infinite);
        // w = 0, z < 128, something in x: a denormal.
        assert_eq!(classify(pk4ub([1.0, 0.0, 0.0, 0.0])), FloatClass::Denormal);
        assert_eq!(classify(0), FloatClass::Zero);
        assert_eq!(classify(0x8000_0000), FloatClass::Zero);
        // Exhaustive over the two bytes that hold the exponent (x and y do not matter for
        // the exponent; x = 1 keeps the mantissa non-zero).
        for w in 0..=255u32 {
            for z in 0..=255u32 {
                let bits = w << 24 | z << 16 | 1;
                let expected = if w & 0x7F == 0x7F && z >= 128 {
                    FloatClass::Nan
                } else if w & 0x7F == 0 && z < 128 {
                    FloatClass::Denormal
                } else {
                    FloatClass::Normal
                };
                assert_eq!(classify(bits), expected, "w {w} z {z}");
            }
        }
    }

    #[test]
    fn targets_keep_flush_or_canonicalize() {
        let denormal = pk4ub([1.0, 0.0, 0.0, 0.0]);
        let nan = pk4ub([0.0, 0.0, 1.0, 1.0]);
        let normal = pk4ub([0.0, 0.0, 0.0, 0.5]);
        let mut e = StoreEvents::default();
        for bits in [denormal, nan, normal] {
            assert_eq!(FloatTarget::Raw.store(bits, &mut e), bits);
        }
        assert_eq!((e.denormal, e.nan, e.altered), (1, 1, 0));
        let mut e = StoreEvents::default();
        assert_eq!(FloatTarget::FlushDenormals.store(denormal, &mut e), 0);
        assert_eq!(FloatTarget::FlushDenormals.store(nan, &mut e), nan);
        assert_eq!(e.altered, 1);
        let mut e = StoreEvents::default();
        assert_eq!(FloatTarget::CanonicalNans.store(nan, &mut e), CANONICAL_NAN);
        assert_eq!(FloatTarget::CanonicalNans.store(denormal, &mut e), denormal);
        assert_eq!(e.altered, 1);
    }

    /// Every store counts the written pattern's class, infinities included; flushing keeps a
    /// denormal's sign; events add field by field.
    #[test]
    fn stores_count_every_class_and_events_add_up() {
        let mut e = StoreEvents::default();
        let negative_denormal = 0x8000_0001;
        assert_eq!(
            FloatTarget::FlushDenormals.store(negative_denormal, &mut e),
            0x8000_0000
        );
        for bits in [0x7F80_0000, 0xFF80_0000, 0x7FC0_0001, 0x3F80_0000] {
            assert_eq!(FloatTarget::FlushDenormals.store(bits, &mut e), bits);
        }
        assert_eq!(
            e,
            StoreEvents {
                denormal: 1,
                nan: 1,
                infinite: 2,
                altered: 1
            }
        );
        let mut sum = StoreEvents {
            denormal: 1,
            nan: 2,
            infinite: 3,
            altered: 4,
        };
        sum += StoreEvents {
            denormal: 10,
            nan: 20,
            infinite: 30,
            altered: 40,
        };
        assert_eq!(
            sum,
            StoreEvents {
                denormal: 11,
                nan: 22,
                infinite: 33,
                altered: 44
            }
        );
    }

    proptest! {
        #[test]
        fn whole_words_round_trip(bits in any::<u32>()) {
            prop_assert_eq!(pk4ub(up4ub(bits)), bits);
        }

        #[test]
        fn packing_is_within_half_a_step(v in proptest::array::uniform4(0.0f32..=1.0)) {
            let back = up4ub(pk4ub(v));
            for k in 0..4 {
                prop_assert!((back[k] - v[k]).abs() <= 0.5 / 255.0 + 1e-7);
            }
        }
    }
}
