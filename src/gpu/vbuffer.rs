//! V-buffers: the per-pixel visibility storage of the soft shadow volume algorithm
//! (Paper III §3, §4.1, §4.2), one typed tile storage per format, every access counted.
//!
//! A V-buffer accumulates signed contributions — the ±1.0 of the hard shadow quads (pass 1,
//! Paper III §3.2.1) and the signed coverages of the wedges (pass 2, §3.2.2) — in submission
//! order within a tile (`docs/architecture.md` "Determinism"). The formats:
//!
//! - [`VBufferF32Tile`]: one f32 per pixel, cleared to 1.0 (§4.1, the default). Each
//!   accumulation reads and writes the pixel (the GeForce FX read-as-texture + write of §4.1):
//!   4 bytes read, 4 bytes written.
//! - [`VBufferF16Tile`]: one IEEE binary16 (`half::f16`) per pixel, cleared to 1.0 (§4.1: "if
//!   a 16-bit floating point texture capability is available, it is likely that those would
//!   suffice"). Each accumulation is `f16(f32(stored) + delta)`, rounded to nearest even once;
//!   2 bytes read, 2 written; a result that is not finite counts an overflow event.
//! - [`VBufferRgbTile`]: three f32 per pixel (textured and coloured lights, §3.3, §4.1),
//!   cleared to 1.0; 12 bytes read, 12 written.
//! - [`VBuffer8Tile`]: the 8-bit version of §4.2, an RGBA8 frame buffer of which two channels
//!   are used. Only pass 2 goes here (the umbra of pass 1 is counted in the stencil buffer);
//!   both channels are cleared to 0. A contribution `δ` is quantized to 6 bits,
//!   `q = round(|δ|·63)` (64 levels 0…63, [`VBUFFER8_FULL`] = 63 is a full contribution,
//!   rounding half away from zero), and added with OpenGL's saturating additive blending
//!   `min(255, dst + q)` to R when `δ > 0`, to G when `δ < 0` (the subtractive part stored as
//!   positive values). The two upper bits hold up to 255/63 ≈ 4.05 full contributions: the
//!   fifth full contribution that piles up in one channel saturates (an overflow event) and
//!   the pixel's resolve is wrong from then on. Resolved by subtraction, `(R − G)/63`.
//!   Each blend reads and writes the 4-byte RGBA8 pixel.
//!
//! [`VBufferTile::resolve`] returns what the buffer holds as a visibility sum per channel
//! (grey formats replicate their one channel); for [`VBuffer8Tile`] that is the penumbra sum
//! only, which the method merges with its stencil umbra.

use super::buffers::{overflow_record, record_overflow};
use super::counters::{count, Counters};
use super::probe::{Overflow, ProbeEvent, Raw, Tap};
use half::f16;

/// The storage formats of a V-buffer (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum VBufferFormat {
    /// One f32 per pixel (Paper III §4.1).
    F32,
    /// One binary16 per pixel.
    F16,
    /// Three f32 per pixel (textured lights).
    RgbF32,
    /// Two saturating 8-bit channels, 6 value bits + 2 overflow bits (Paper III §4.2).
    Split8,
}

impl VBufferFormat {
    /// What the overflow events an accumulation counts are: saturation for the 8-bit version,
    /// a result that is not finite for the float formats.
    pub fn overflow(self) -> Overflow {
        match self {
            VBufferFormat::Split8 => Overflow::Saturate,
            _ => Overflow::NonFinite,
        }
    }

    /// Bytes per pixel as stored (the 8-bit version occupies an RGBA8 pixel).
    pub fn bytes(self) -> u32 {
        match self {
            VBufferFormat::F32 => 4,
            VBufferFormat::F16 => 2,
            VBufferFormat::RgbF32 => 12,
            VBufferFormat::Split8 => 4,
        }
    }
}

/// A V-buffer's per-tile storage (module doc).
pub trait VBufferTile: Send + Sync {
    /// The format this storage implements.
    const FORMAT: VBufferFormat;
    /// A tile of `len` pixels, cleared (1.0 for the float formats, 0 in both channels for the
    /// 8-bit version).
    fn cleared(len: usize) -> Self;
    /// Accumulate the per-channel contribution `delta` into pixel `i` (counted; grey formats
    /// use `delta[0]`).
    fn add(&mut self, i: usize, delta: [f32; 3], c: &mut Counters);
    /// The accumulated value of pixel `i` per channel (module doc; not counted: the final
    /// read-back).
    fn resolve(&self, i: usize) -> [f32; 3];
    /// Record overflow events per sample from now on, for a buffer dump
    /// ([`overflow_record`]); formats that count none record nothing.
    fn record_overflows(&mut self) {}
    /// The overflow events per sample recorded since [`VBufferTile::record_overflows`]
    /// (empty when nothing was recorded).
    fn overflows(&self) -> &[u32] {
        &[]
    }
    /// Pixel `i` as stored, for probes ([`super::probe`]; not counted).
    fn raw(&self, i: usize) -> Raw;
}

/// [`VBufferTile::add`] that, for the watched fragment's `tap`, records `event` with the write
/// of the V-buffer there, before and after, and its overflow events ([`super::probe`]).
#[inline]
pub fn add_probed<V: VBufferTile>(
    vb: &mut V,
    i: usize,
    delta: [f32; 3],
    c: &mut Counters,
    tap: Option<Tap>,
    event: impl FnOnce(Tap) -> ProbeEvent,
) {
    let Some(tap) = tap else {
        return vb.add(i, delta, c);
    };
    let (before, overflows) = (vb.raw(i), c.overflow_events);
    vb.add(i, delta, c);
    let kind = V::FORMAT.overflow();
    let after = vb.raw(i);
    let overflows = c.overflow_events - overflows;
    tap.push(event(tap).write("vbuffer", before, after, kind, overflows));
}

/// One f32 per pixel (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct VBufferF32Tile {
    /// Stored values.
    pub values: Vec<f32>,
}

impl VBufferTile for VBufferF32Tile {
    const FORMAT: VBufferFormat = VBufferFormat::F32;
    fn cleared(len: usize) -> Self {
        Self {
            values: vec![1.0; len],
        }
    }
    #[inline]
    fn add(&mut self, i: usize, delta: [f32; 3], c: &mut Counters) {
        count!(c.color_read_bytes += 4);
        count!(c.color_write_bytes += 4);
        self.values[i] += delta[0];
    }
    fn resolve(&self, i: usize) -> [f32; 3] {
        [self.values[i]; 3]
    }
    fn raw(&self, i: usize) -> Raw {
        Raw::f32(self.values[i])
    }
}

impl VBufferF32Tile {
    /// Multiply pixel `i` by `k` (`ssv`'s `horizon = integrate` pass, between pass 1 and
    /// pass 2): read as a texture and written, like an accumulation (4 bytes each way).
    pub fn scale(&mut self, i: usize, k: f32, c: &mut Counters) {
        count!(c.color_read_bytes += 4);
        count!(c.color_write_bytes += 4);
        self.values[i] *= k;
    }
}

/// One binary16 per pixel (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct VBufferF16Tile {
    /// Stored values.
    pub values: Vec<f16>,
    /// Non-finite results per sample, kept only for a buffer dump ([`overflow_record`]).
    pub overflows: Vec<u32>,
}

impl VBufferTile for VBufferF16Tile {
    const FORMAT: VBufferFormat = VBufferFormat::F16;
    fn cleared(len: usize) -> Self {
        Self {
            values: vec![f16::ONE; len],
            overflows: Vec::new(),
        }
    }
    #[inline]
    fn add(&mut self, i: usize, delta: [f32; 3], c: &mut Counters) {
        count!(c.color_read_bytes += 2);
        count!(c.color_write_bytes += 2);
        let v = f16::from_f32(self.values[i].to_f32() + delta[0]);
        count!(c.overflow_events += !v.is_finite() as u64);
        record_overflow(&mut self.overflows, i, !v.is_finite() as u32);
        self.values[i] = v;
    }
    fn resolve(&self, i: usize) -> [f32; 3] {
        [self.values[i].to_f32(); 3]
    }
    fn record_overflows(&mut self) {
        self.overflows = overflow_record(true, self.values.len());
    }
    fn overflows(&self) -> &[u32] {
        &self.overflows
    }
    fn raw(&self, i: usize) -> Raw {
        Raw::F16(self.values[i].to_bits())
    }
}

impl VBufferF16Tile {
    /// Multiply pixel `i` by `k`, `f16(f32(stored)·k)` rounded once (as
    /// [`VBufferF32Tile::scale`]; 2 bytes each way). `|k| ≤ 1` in its use: never an overflow.
    pub fn scale(&mut self, i: usize, k: f32, c: &mut Counters) {
        count!(c.color_read_bytes += 2);
        count!(c.color_write_bytes += 2);
        self.values[i] = f16::from_f32(self.values[i].to_f32() * k);
    }
}

/// Three f32 per pixel (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct VBufferRgbTile {
    /// Stored values.
    pub values: Vec<[f32; 3]>,
}

impl VBufferTile for VBufferRgbTile {
    const FORMAT: VBufferFormat = VBufferFormat::RgbF32;
    fn cleared(len: usize) -> Self {
        Self {
            values: vec![[1.0; 3]; len],
        }
    }
    #[inline]
    fn add(&mut self, i: usize, delta: [f32; 3], c: &mut Counters) {
        count!(c.color_read_bytes += 12);
        count!(c.color_write_bytes += 12);
        for (v, d) in self.values[i].iter_mut().zip(delta) {
            *v += d;
        }
    }
    fn resolve(&self, i: usize) -> [f32; 3] {
        self.values[i]
    }
    fn raw(&self, i: usize) -> Raw {
        Raw::Channels(self.values[i].map(Raw::f32).to_vec())
    }
}

/// A full contribution (coverage 1.0) in the 8-bit V-buffer: 6 bits, levels 0…63.
pub const VBUFFER8_FULL: u8 = 63;

/// The 8-bit V-buffer of Paper III §4.2: additive R, subtractive G (module doc).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct VBuffer8Tile {
    /// The red channel: additive contributions.
    pub add: Vec<u8>,
    /// The green channel: subtractive contributions, stored as positive values.
    pub sub: Vec<u8>,
    /// Saturations per sample, kept only for a buffer dump ([`overflow_record`]).
    pub overflows: Vec<u32>,
}

/// `round(|δ|·63)` as a 6-bit level (module doc).
pub fn quantize6(delta: f32) -> u8 {
    (delta.abs().min(1.0) * VBUFFER8_FULL as f32).round() as u8
}

impl VBufferTile for VBuffer8Tile {
    const FORMAT: VBufferFormat = VBufferFormat::Split8;
    fn cleared(len: usize) -> Self {
        Self {
            add: vec![0; len],
            sub: vec![0; len],
            overflows: Vec::new(),
        }
    }
    #[inline]
    fn add(&mut self, i: usize, delta: [f32; 3], c: &mut Counters) {
        let q = quantize6(delta[0]);
        if q == 0 {
            return;
        }
        count!(c.color_read_bytes += 4);
        count!(c.color_write_bytes += 4);
        let channel = if delta[0] > 0.0 {
            &mut self.add[i]
        } else {
            &mut self.sub[i]
        };
        let (sum, overflow) = match channel.checked_add(q) {
            Some(s) => (s, false),
            None => (u8::MAX, true),
        };
        count!(c.overflow_events += overflow as u64);
        *channel = sum;
        record_overflow(&mut self.overflows, i, overflow as u32);
    }
    fn resolve(&self, i: usize) -> [f32; 3] {
        [(self.add[i] as f32 - self.sub[i] as f32) / VBUFFER8_FULL as f32; 3]
    }
    fn record_overflows(&mut self) {
        self.overflows = overflow_record(true, self.add.len());
    }
    fn overflows(&self) -> &[u32] {
        &self.overflows
    }
    fn raw(&self, i: usize) -> Raw {
        Raw::Rg8([self.add[i], self.sub[i]])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split8_saturates_on_the_fifth_full_contribution() {
        let mut t = VBuffer8Tile::cleared(1);
        let mut c = Counters::default();
        for k in 1..=4 {
            t.add(0, [1.0; 3], &mut c);
            assert_eq!(t.resolve(0)[0], k as f32);
        }
        assert_eq!(c.overflow_events, 0);
        t.add(0, [1.0; 3], &mut c);
        assert_eq!(t.add[0], 255);
        assert_eq!(t.resolve(0)[0], 255.0 / 63.0);
        assert_eq!(c.overflow_events, 1);
    }

    #[test]
    fn f16_rounds_each_accumulation() {
        let mut t = VBufferF16Tile::cleared(1);
        let mut c = Counters::default();
        t.add(0, [1e-4; 3], &mut c);
        // 1 + 1e-4 is below half an ulp of 1.0 in binary16 (2^-11): it rounds back to 1.
        assert_eq!(t.resolve(0)[0], 1.0);
        assert_eq!(c.color_write_bytes, 2);
    }
}
