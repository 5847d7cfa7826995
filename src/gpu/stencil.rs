//! The 8-bit stencil unit (`docs/architecture.md` "Stencil"): two-sided state, every OpenGL op,
//! reference value and masks exactly as `glStencilFuncSeparate` / `glStencilOpSeparate` /
//! `glStencilMaskSeparate` define them.
//!
//! With saturating ops the result depends on the order fragments arrive in; the rasterizer
//! keeps submission order inside each tile, so the order is part of each method's contract.

/// A stencil operation (`glStencilOp`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum StencilOp {
    /// Keep the stored value.
    Keep,
    /// Set to 0.
    Zero,
    /// Set to the reference value.
    Replace,
    /// Increment, clamping at 255 (`GL_INCR`).
    Incr,
    /// Decrement, clamping at 0 (`GL_DECR`).
    Decr,
    /// Increment modulo 256 (`GL_INCR_WRAP`).
    IncrWrap,
    /// Decrement modulo 256 (`GL_DECR_WRAP`).
    DecrWrap,
    /// Bitwise invert.
    Invert,
}

impl StencilOp {
    /// The new value before the write mask is applied, and whether it over/underflowed
    /// (a clamp for `Incr`/`Decr`, a wrap for the wrapping ops).
    #[inline]
    pub fn apply(self, stored: u8, reference: u8) -> (u8, bool) {
        match self {
            StencilOp::Keep => (stored, false),
            StencilOp::Zero => (0, false),
            StencilOp::Replace => (reference, false),
            StencilOp::Incr => (stored.saturating_add(1), stored == u8::MAX),
            StencilOp::Decr => (stored.saturating_sub(1), stored == 0),
            StencilOp::IncrWrap => (stored.wrapping_add(1), stored == u8::MAX),
            StencilOp::DecrWrap => (stored.wrapping_sub(1), stored == 0),
            StencilOp::Invert => (!stored, false),
        }
    }

    /// Whether the op wraps modulo 256 on over/underflow (else it saturates).
    pub fn wraps(self) -> bool {
        matches!(self, StencilOp::IncrWrap | StencilOp::DecrWrap)
    }
}

/// The stencil comparison (`glStencilFunc`): `(ref & mask) FUNC (stored & mask)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum StencilFunc {
    /// Never passes.
    Never,
    /// ref < stored.
    Less,
    /// ref ≤ stored.
    LEqual,
    /// ref > stored.
    Greater,
    /// ref ≥ stored.
    GEqual,
    /// ref == stored.
    Equal,
    /// ref != stored.
    NotEqual,
    /// Always passes.
    Always,
}

impl StencilFunc {
    /// Evaluate on masked values.
    #[inline]
    pub fn test(self, reference: u8, stored: u8, mask: u8) -> bool {
        let (r, s) = (reference & mask, stored & mask);
        match self {
            StencilFunc::Never => false,
            StencilFunc::Less => r < s,
            StencilFunc::LEqual => r <= s,
            StencilFunc::Greater => r > s,
            StencilFunc::GEqual => r >= s,
            StencilFunc::Equal => r == s,
            StencilFunc::NotEqual => r != s,
            StencilFunc::Always => true,
        }
    }
}

/// The stencil state of one face.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct StencilFace {
    /// Comparison function.
    pub func: StencilFunc,
    /// Reference value.
    pub reference: u8,
    /// Mask applied to both sides of the comparison.
    pub read_mask: u8,
    /// Bits the ops may change.
    pub write_mask: u8,
    /// Op when the stencil test fails.
    pub stencil_fail: StencilOp,
    /// Op when the stencil test passes and the depth test fails.
    pub depth_fail: StencilOp,
    /// Op when both pass.
    pub depth_pass: StencilOp,
}

impl StencilFace {
    /// ALWAYS-pass state with the given depth-fail and depth-pass ops (what shadow volumes use).
    pub fn always(depth_fail: StencilOp, depth_pass: StencilOp) -> Self {
        Self {
            func: StencilFunc::Always,
            reference: 0,
            read_mask: 0xFF,
            write_mask: 0xFF,
            stencil_fail: StencilOp::Keep,
            depth_fail,
            depth_pass,
        }
    }

    /// The op a fragment with the given test outcomes runs.
    #[inline]
    pub fn op(&self, stencil_pass: bool, depth_pass: bool) -> StencilOp {
        if !stencil_pass {
            self.stencil_fail
        } else if !depth_pass {
            self.depth_fail
        } else {
            self.depth_pass
        }
    }

    /// The stored value after a fragment with the given test outcomes, and whether the op
    /// over/underflowed. `None` means the value is unchanged (no write happens).
    #[inline]
    pub fn update(&self, stored: u8, stencil_pass: bool, depth_pass: bool) -> Option<(u8, bool)> {
        let op = self.op(stencil_pass, depth_pass);
        if op == StencilOp::Keep || self.write_mask == 0 {
            return None;
        }
        let (v, overflow) = op.apply(stored, self.reference);
        Some((
            (stored & !self.write_mask) | (v & self.write_mask),
            overflow,
        ))
    }
}

/// Two-sided stencil state (`GL_STENCIL_TEST` with separate front and back state).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct StencilState {
    /// State for front-facing primitives.
    pub front: StencilFace,
    /// State for back-facing primitives.
    pub back: StencilFace,
}

impl StencilState {
    /// The face state for a fragment of the given facing.
    #[inline]
    pub fn face(&self, front_facing: bool) -> &StencilFace {
        if front_facing {
            &self.front
        } else {
            &self.back
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn saturating_and_wrapping_ops() {
        assert_eq!(StencilOp::Incr.apply(255, 0), (255, true));
        assert_eq!(StencilOp::IncrWrap.apply(255, 0), (0, true));
        assert_eq!(StencilOp::Decr.apply(0, 0), (0, true));
        assert_eq!(StencilOp::DecrWrap.apply(0, 0), (255, true));
        assert_eq!(StencilOp::Invert.apply(0x0F, 0), (0xF0, false));
        assert_eq!(StencilOp::Replace.apply(3, 9), (9, false));
    }

    #[test]
    fn write_mask_keeps_unmasked_bits() {
        let mut f = StencilFace::always(StencilOp::Keep, StencilOp::Replace);
        f.reference = 0xFF;
        f.write_mask = 0x0F;
        assert_eq!(f.update(0xA0, true, true), Some((0xAF, false)));
    }

    const OPS: [StencilOp; 8] = [
        StencilOp::Keep,
        StencilOp::Zero,
        StencilOp::Replace,
        StencilOp::Incr,
        StencilOp::Decr,
        StencilOp::IncrWrap,
        StencilOp::DecrWrap,
        StencilOp::Invert,
    ];

    /// Every op on every stored value, against the GL specification's definitions written
    /// in i32 arithmetic (OpenGL 4.6 §17.3.5, Table 17.3): the value and the overflow flag.
    #[test]
    fn every_op_on_every_value_is_the_specification() {
        for op in OPS {
            for stored in 0..=255i32 {
                let reference = 0x5Ai32;
                let (value, overflow) = match op {
                    StencilOp::Keep => (stored, false),
                    StencilOp::Zero => (0, false),
                    StencilOp::Replace => (reference, false),
                    StencilOp::Incr => ((stored + 1).min(255), stored == 255),
                    StencilOp::Decr => ((stored - 1).max(0), stored == 0),
                    StencilOp::IncrWrap => ((stored + 1).rem_euclid(256), stored == 255),
                    StencilOp::DecrWrap => ((stored - 1).rem_euclid(256), stored == 0),
                    StencilOp::Invert => (255 - stored, false),
                };
                assert_eq!(
                    op.apply(stored as u8, reference as u8),
                    (value as u8, overflow),
                    "{op:?} on {stored}"
                );
            }
            assert_eq!(
                op.wraps(),
                matches!(op, StencilOp::IncrWrap | StencilOp::DecrWrap),
                "{op:?}"
            );
        }
    }

    /// Every function on every (reference, stored) pair under three masks, against the
    /// comparison of the masked values as integers.
    #[test]
    fn every_func_compares_the_masked_values() {
        type Spec = fn(i32, i32) -> bool;
        let funcs: [(StencilFunc, Spec); 8] = [
            (StencilFunc::Never, |_, _| false),
            (StencilFunc::Less, |r, s| r < s),
            (StencilFunc::LEqual, |r, s| r <= s),
            (StencilFunc::Greater, |r, s| r > s),
            (StencilFunc::GEqual, |r, s| r >= s),
            (StencilFunc::Equal, |r, s| r == s),
            (StencilFunc::NotEqual, |r, s| r != s),
            (StencilFunc::Always, |_, _| true),
        ];
        for (func, spec) in funcs {
            for mask in [0xFFu8, 0x0F, 0x00] {
                for r in 0..=255u8 {
                    for st in (0..=255u8).step_by(7) {
                        let want = spec(i32::from(r & mask), i32::from(st & mask));
                        assert_eq!(func.test(r, st, mask), want, "{func:?} {r} {st} {mask:#x}");
                    }
                }
            }
        }
    }

    /// The op chosen for each outcome of the two tests (glStencilOp's sfail, dpfail, dppass),
    /// and what `update` writes: nothing for KEEP or a zero write mask.
    #[test]
    fn the_outcomes_choose_the_op_and_update_writes_through_the_mask() {
        let f = StencilFace {
            func: StencilFunc::Always,
            reference: 7,
            read_mask: 0xFF,
            write_mask: 0xFF,
            stencil_fail: StencilOp::Zero,
            depth_fail: StencilOp::Incr,
            depth_pass: StencilOp::Invert,
        };
        assert_eq!(f.op(false, false), StencilOp::Zero);
        assert_eq!(f.op(false, true), StencilOp::Zero);
        assert_eq!(f.op(true, false), StencilOp::Incr);
        assert_eq!(f.op(true, true), StencilOp::Invert);
        assert_eq!(f.update(9, false, true), Some((0, false)));
        assert_eq!(f.update(9, true, false), Some((10, false)));
        assert_eq!(f.update(255, true, false), Some((255, true)));
        assert_eq!(f.update(0x0F, true, true), Some((0xF0, false)));
        let masked = StencilFace { write_mask: 0, ..f };
        assert_eq!(masked.update(9, true, true), None);
        let keep = StencilFace::always(StencilOp::Keep, StencilOp::Keep);
        assert_eq!(keep.update(9, true, true), None);
        assert_eq!(
            (
                keep.func,
                keep.read_mask,
                keep.write_mask,
                keep.stencil_fail
            ),
            (StencilFunc::Always, 0xFF, 0xFF, StencilOp::Keep)
        );
        let two_sided = StencilState {
            front: f,
            back: keep,
        };
        assert_eq!(*two_sided.face(true), f);
        assert_eq!(*two_sided.face(false), keep);
    }

    #[test]
    fn func_uses_read_mask() {
        assert!(StencilFunc::Equal.test(0x12, 0x32, 0x0F));
        assert!(!StencilFunc::Equal.test(0x12, 0x32, 0xFF));
    }
}
