//! The emulated GPU pipeline (DESIGN.md "The emulated GPU: the bit-exactness contract").

pub mod counters;
