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

/// `round(|δ|·63)` as a 6-bit level (module doc), `|δ|` clamped to 1. A NaN is level 0, the
/// lower bound, as `pack4ub::unorm8` and Direct3D 10's float-to-unorm conversion make it
/// (OpenGL leaves it undefined): `f32::min` would have made it a full contribution, 63.
pub fn quantize6(delta: f32) -> u8 {
    if delta.is_nan() {
        return 0;
    }
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
    use crate::gpu::probe::{BufferChange, Probe};
    use crate::gpu::tiling::Tiling;

    /// The float formats as the module doc states them: cleared to 1.0, each accumulation and
    /// each scale reading and writing the format's bytes (`VBufferFormat::bytes`), f32 exact,
    /// binary16 rounded to nearest once per access, RGB per channel.
    #[test]
    fn float_formats_clear_to_one_accumulate_and_count_their_bytes() {
        let mut c = Counters::default();
        let mut t = VBufferF32Tile::cleared(3);
        assert_eq!(
            (0..3).map(|i| t.resolve(i)).collect::<Vec<_>>(),
            [[1.0; 3]; 3]
        );
        t.add(1, [0.25, 9.0, 9.0], &mut c);
        t.add(1, [-0.75, 9.0, 9.0], &mut c);
        assert_eq!([t.resolve(0), t.resolve(1)], [[1.0; 3], [0.5; 3]]);
        t.scale(1, 0.5, &mut c);
        assert_eq!(t.raw(1), Raw::f32(0.25));
        let bytes = u64::from(VBufferFormat::F32.bytes());
        assert_eq!(bytes, 4);
        assert_eq!(
            (c.color_read_bytes, c.color_write_bytes),
            (3 * bytes, 3 * bytes)
        );

        let mut c = Counters::default();
        let mut t = VBufferF16Tile::cleared(2);
        assert_eq!(t.resolve(1), [1.0; 3]);
        // Half an ulp of binary16 in [1, 2) is 2⁻¹¹ ≈ 0.00049: 0.0007 rounds up to one ulp.
        t.add(1, [0.5, 0.0, 0.0], &mut c);
        t.add(1, [0.0007, 0.0, 0.0], &mut c);
        assert_eq!(t.resolve(1), [1.5 + 1.0 / 1024.0; 3]);
        assert_eq!(
            t.raw(1),
            Raw::F16(f16::from_f32(1.5 + 1.0 / 1024.0).to_bits())
        );
        // (1 + 2⁻¹⁰)·(1 − 2⁻¹¹) = 1 + 2⁻¹¹ − 2⁻²¹, just under half-way: rounds down to 1.
        t.add(0, [1.0 / 1024.0, 0.0, 0.0], &mut c);
        t.scale(0, 1.0 - 1.0 / 2048.0, &mut c);
        assert_eq!(t.resolve(0), [1.0; 3]);
        let bytes = u64::from(VBufferFormat::F16.bytes());
        assert_eq!(bytes, 2);
        assert_eq!(
            (c.color_read_bytes, c.color_write_bytes),
            (4 * bytes, 4 * bytes)
        );
        assert_eq!(c.overflow_events, 0);

        let mut c = Counters::default();
        let mut t = VBufferRgbTile::cleared(2);
        t.add(1, [0.25, -0.5, 2.0], &mut c);
        assert_eq!([t.resolve(0), t.resolve(1)], [[1.0; 3], [1.25, 0.5, 3.0]]);
        assert_eq!(
            t.raw(1),
            Raw::Channels(vec![Raw::f32(1.25), Raw::f32(0.5), Raw::f32(3.0)])
        );
        let bytes = u64::from(VBufferFormat::RgbF32.bytes());
        assert_eq!(bytes, 12);
        assert_eq!((c.color_read_bytes, c.color_write_bytes), (bytes, bytes));
        assert!([
            VBufferFormat::F32,
            VBufferFormat::F16,
            VBufferFormat::RgbF32
        ]
        .iter()
        .all(|f| f.overflow() == Overflow::NonFinite));
        assert_eq!(VBufferFormat::Split8.overflow(), Overflow::Saturate);
    }

    /// A binary16 result that is not finite is an overflow event, counted always and recorded
    /// per sample only once [`VBufferTile::record_overflows`] asked for it; the largest finite
    /// value is not one.
    #[test]
    fn f16_counts_and_records_results_that_are_not_finite() {
        let mut c = Counters::default();
        let mut t = VBufferF16Tile::cleared(3);
        t.add(2, [70000.0, 0.0, 0.0], &mut c);
        assert_eq!(c.overflow_events, 1);
        assert!(t.overflows().is_empty());
        t.record_overflows();
        assert_eq!(t.overflows(), [0, 0, 0]);
        t.add(0, [65503.0, 0.0, 0.0], &mut c);
        assert_eq!(t.resolve(0), [65504.0; 3]);
        t.add(1, [f32::INFINITY, 0.0, 0.0], &mut c);
        t.add(1, [1.0, 0.0, 0.0], &mut c);
        assert_eq!(c.overflow_events, 3);
        assert_eq!(t.overflows(), [0, 2, 0]);
        assert!(VBufferF32Tile::cleared(1).overflows().is_empty());
    }

    /// `round(|δ|·63)`: every level from its exact value and ± a quarter level, half-way up,
    /// both signs, clamped above 1, NaN to 0 (never a full contribution).
    #[test]
    fn quantize6_rounds_to_the_nearest_of_64_levels() {
        for k in 0..=63u8 {
            let level = f32::from(k) / 63.0;
            for d in [level, level + 0.24 / 63.0, level - 0.24 / 63.0] {
                if (0.0..=1.0).contains(&d) {
                    assert_eq!((quantize6(d), quantize6(-d)), (k, k), "{d}");
                }
            }
        }
        assert_eq!(quantize6(0.5 / 63.0 + 1e-6), 1);
        assert_eq!(quantize6(0.5 / 63.0 - 1e-6), 0);
        assert_eq!(
            (quantize6(1.5), quantize6(-7.0), quantize6(f32::INFINITY)),
            (63, 63, 63)
        );
        assert_eq!(quantize6(f32::NAN), 0);
    }

    /// Paper III §4.2's two channels: a positive contribution blends into R, a negative one
    /// into G, both read and write the RGBA8 pixel (4 bytes), a contribution that quantizes to
    /// level 0 is no blend at all, and the resolve is `(R − G)/63`. G saturates like R.
    #[test]
    fn split8_adds_positive_to_r_negative_to_g_and_resolves_their_difference() {
        let mut c = Counters::default();
        let mut t = VBuffer8Tile::cleared(2);
        assert_eq!(t.resolve(1), [0.0; 3]);
        t.add(1, [1.0, 0.0, 0.0], &mut c);
        t.add(1, [1.0, 0.0, 0.0], &mut c);
        t.add(1, [-0.5, 0.0, 0.0], &mut c);
        assert_eq!(t.raw(1), Raw::Rg8([126, 32]));
        assert_eq!(t.resolve(1), [(126.0 - 32.0) / 63.0; 3]);
        assert_eq!((c.color_read_bytes, c.color_write_bytes), (12, 12));
        assert_eq!(u64::from(VBufferFormat::Split8.bytes()), 4);
        t.add(1, [0.007, 0.0, 0.0], &mut c);
        t.add(1, [-0.007, 0.0, 0.0], &mut c);
        assert_eq!(t.raw(1), Raw::Rg8([126, 32]));
        assert_eq!((c.color_read_bytes, c.color_write_bytes), (12, 12));
        assert_eq!(t.raw(0), Raw::Rg8([0, 0]));
        t.record_overflows();
        for _ in 0..5 {
            t.add(0, [-1.0, 0.0, 0.0], &mut c);
        }
        assert_eq!(t.raw(0), Raw::Rg8([0, 255]));
        assert_eq!(t.resolve(0), [-255.0 / 63.0; 3]);
        assert_eq!(c.overflow_events, 1);
        assert_eq!(t.overflows(), [1, 0]);
    }

    /// [`add_probed`] is [`VBufferTile::add`] with or without a tap, and with one records the
    /// write at the tap: the stored value before and after and this write's overflow events
    /// of the format's kind (none when there were none).
    #[test]
    fn add_probed_records_the_write_and_its_overflows() {
        let tiling = Tiling::new(8, 8, 8).unwrap();
        let probe = Probe::new(3, 2);
        let pass = probe.pass("p", &tiling);
        let tap = pass.tap_at(3, 2);
        let mut c = Counters::default();
        let mut t = VBuffer8Tile::cleared(64);
        let i = tiling.local(3, 2);
        // An untapped pixel saturated first: the tap counts this write's events only.
        for _ in 0..5 {
            add_probed(&mut t, 5, [1.0; 3], &mut c, None, |tap| tap.event());
        }
        assert_eq!((t.raw(5), c.overflow_events), (Raw::Rg8([255, 0]), 1));
        assert!(probe.events().is_empty());
        for _ in 0..5 {
            add_probed(&mut t, i, [1.0; 3], &mut c, tap, |tap| tap.event());
        }
        assert_eq!(c.overflow_events, 2);
        let writes: Vec<BufferChange> = probe
            .events()
            .into_iter()
            .filter_map(|e| e.buffer)
            .collect();
        assert_eq!(writes.len(), 5);
        let write = |before: [u8; 2], after: [u8; 2], overflow| BufferChange {
            buffer: "vbuffer".into(),
            before: Some(Raw::Rg8(before)),
            after: Raw::Rg8(after),
            overflow,
        };
        assert_eq!(writes[0], write([0, 0], [63, 0], None));
        assert_eq!(writes[3], write([189, 0], [252, 0], None));
        assert_eq!(
            writes[4],
            write([252, 0], [255, 0], Some((Overflow::Saturate, 1)))
        );
    }

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
