//! What the emulated fragment programs execute, counted (issue 29 item 1; `docs/gpu-model.md`
//! "Fragment-program work"): the work the GPU cost model's shade term prices.
//!
//! Every operation of a fragment program goes through its scalar, a [`ShaderFloat`](super::shader_float::ShaderFloat) chosen by
//! [`with_shader_float!`](crate::with_shader_float) (the default precision's scalar is
//! [`ShaderF64`](super::shader_float::ShaderF64), plain f64 arithmetic that counts). Each
//! operation adds its instruction count to a thread-local tally ([`alu`], [`transcendental`]),
//! each texture sample to a fetch tally ([`fetch`]). The tallies are read only around one
//! program invocation — [`measure`], which the rasterizer's [`draw`](super::raster::draw) and
//! the screen passes' [`shade_receivers`](crate::methods::shade_receivers) wrap around every
//! fragment they hand to a program — and the difference is added to that tile's or row's
//! [`Counters`]: the sum over a pass is an integer sum over its fragments, so the counts are
//! as deterministic as the images, for any thread count. Operations outside an invocation
//! (setup on the CPU, reference computations, tests) go to the same tally but are never read.
//!
//! # What one operation costs, in instructions
//!
//! The counts are instruction slots of a DirectX 9 / `ARB_fragment_program`-class ISA (the
//! papers' GPUs), not f64 operations:
//!
//! | operation | slots | why |
//! |---|---|---|
//! | `+ − ×`, `min`, `max`, `floor`, a comparison (`<`, `==`, …) | 1 | `ADD`, `MUL` (a `MAD` fuses a pair; counted as two, an upper bound), `MIN`, `MAX`, `FLR`, `SLT`/`SGE`/`CMP` |
//! | `÷` | 2 | no divide instruction: `RCP` then `MUL` |
//! | `sqrt` | 2 | `RSQ` then `RCP` (or `MUL` by the operand) |
//! | `clamp` | 2 | `MIN`, `MAX` (clamping to [0, 1] would be a free `_SAT`; not distinguished) |
//! | `round`, `signum`, `rem_euclid` | 2, 2, 3 | `ADD`+`FLR`; two `CMP`; `MUL`+`FRC`+`MUL` |
//! | negation, `abs` | 0 | source modifiers on NV3x and R300 |
//! | `atan2`, `acos`, `tan` | 1 transcendental | no such instruction: the compiler expands each into a polynomial; the model prices it as an assumption with a range |
//! | a texture sample | 1 fetch | `TEX` / `TXP` (a bilinear sample is one fetch) |
//!
//! A *discard* is counted by the method where its program kills the fragment
//! (`Counters::shader_discards`).

use super::counters::{count, Counters};
use std::cell::Cell;

thread_local! {
    /// This thread's running tallies: ALU slots, transcendental calls, texture fetches.
    static TALLY: Cell<[u64; 3]> = const { Cell::new([0; 3]) };
}

#[inline(always)]
fn add(k: usize, n: u64) {
    if cfg!(feature = "counters") {
        TALLY.with(|t| {
            let mut v = t.get();
            v[k] = v[k].wrapping_add(n);
            t.set(v);
        });
    }
}

/// `n` ALU instruction slots executed (module doc, the table).
#[inline(always)]
pub fn alu(n: u64) {
    add(0, n);
}

/// A vector instruction of `slots` slots that its scalar `T` operations counted as
/// `scalar` slots (a `DP3` is one slot, its three products and two sums five): the tally
/// is lowered by the difference. Nothing for an uncounted `T`.
#[inline(always)]
pub fn vector<T: super::shader_float::ShaderFloat>(scalar: u64, slots: u64) {
    if T::COUNTED {
        add(0, slots.wrapping_sub(scalar));
    }
}

/// One transcendental function executed (`atan2`, `acos`, `tan`).
#[inline(always)]
pub fn transcendental() {
    add(1, 1);
}

/// One texture sample executed.
#[inline(always)]
pub fn fetch() {
    add(2, 1);
}

/// Runs one fragment-program invocation `program` and adds what it executed to `c`:
/// `shader_alu_ops`, `shader_transcendentals`, `shader_fetches`, and the most slots
/// (ALU + fetches) of one invocation in `shader_max_slots`. `program` must not hand work to
/// other threads (a fragment program never does): what it executes is read from this
/// thread's tally.
#[inline]
pub fn measure<R>(c: &mut Counters, program: impl FnOnce(&mut Counters) -> R) -> R {
    if !cfg!(feature = "counters") {
        return program(c);
    }
    let before = TALLY.with(Cell::get);
    let r = program(c);
    let after = TALLY.with(Cell::get);
    let [alu, tr, fe] = [0, 1, 2].map(|k| after[k].wrapping_sub(before[k]));
    count!(c.shader_alu_ops += alu);
    count!(c.shader_transcendentals += tr);
    count!(c.shader_fetches += fe);
    count!(c.shader_max_slots = c.shader_max_slots.max(alu + fe));
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::shader_float::{Fp16, Fp24, Fp32, ShaderF64, ShaderFloat};

    /// A known program counts the slots of the module doc's table, in every format, and only
    /// inside [`measure`]; the maximum is over invocations, the rest sums.
    #[test]
    fn a_known_program_counts_its_slots() {
        fn program<T: ShaderFloat>() -> T {
            let (a, b) = (T::from_f64(2.0), T::from_f64(3.0));
            // + × ÷ sqrt min, a comparison, a negation and an abs: 1 + 1 + 2 + 2 + 1 + 1 = 8.
            let s = (a + b * a / b).sqrt().min(-a.abs());
            if s < a {
                s
            } else {
                a.atan2(b)
            }
        }
        fn check<T: ShaderFloat>() {
            let mut c = Counters::default();
            program::<T>(); // outside: not counted
            measure(&mut c, |_| program::<T>());
            measure(&mut c, |_| {
                fetch();
                T::from_f64(1.0).atan2(T::one())
            });
            assert_eq!(c.shader_alu_ops, 8, "{:?}", T::PRECISION);
            assert_eq!(c.shader_transcendentals, 1);
            assert_eq!(c.shader_fetches, 1);
            assert_eq!(c.shader_max_slots, 8);
        }
        check::<ShaderF64>();
        check::<Fp32>();
        check::<Fp24>();
        check::<Fp16>();
    }
}
