//! The split V-buffer of Paper IV §4.3 ("Frame Buffer Blending"): a coverage value spread over
//! the four 8-bit channels of an RGBA8 frame buffer, the upper bits of every channel reserved
//! for carries, accumulated with OpenGL's saturating 8-bit additive blending.
//!
//! Representation. With `r` reserved bits per channel (Paper IV: 5, "more than 16 levels of
//! overlap occur" on complex models), each channel carries `b = 8 − r` value bits and a value
//! has `4·b` bits (12 with `r = 5`). A value `v` is written as the channels
//! `(v >> 3b) & m, (v >> 2b) & m, (v >> b) & m, v & m` with `m = 2^b − 1` (R holds the most
//! significant bits). Blending adds channel-wise and saturates at 255 (OpenGL
//! `GL_FUNC_ADD`, `GL_ONE, GL_ONE` on an unsigned normalized 8-bit buffer). Reconstruction
//! after the pass reads all 8 bits of every channel, carries included:
//! `R·2^3b + G·2^2b + B·2^b + A`. It is exact as long as no channel saturated: with every
//! contribution at full value (all channels = m), that is `⌊255 / m⌋` contributions
//! (36 for `r = 5`); the paper's "n bits allow up to 2^n levels of overlap" is the guaranteed
//! bound for arbitrary values.
//!
//! Two such buffers form the V-buffer (Paper IV §4.3): an additive one and a subtractive one;
//! the method resolves `(add − sub) / full` after the pass.
//!
//! The coverage-to-channels conversion is the 1024-entry split table of
//! [`crate::light::lookup_tables::SplitTable`].

use super::buffers::{overflow_record, record_overflow};
use super::counters::{count, Counters};
use super::probe::{Overflow, ProbeEvent, Raw};

/// The channel layout of a split value: how many upper bits of each 8-bit channel are reserved
/// for carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct SplitFormat {
    /// Reserved (carry) bits per channel, 1…7.
    pub reserved_bits: u32,
}

impl Default for SplitFormat {
    /// Paper IV §4.3: 5 reserved bits, 3 value bits per channel, 12-bit values.
    fn default() -> Self {
        Self { reserved_bits: 5 }
    }
}

impl SplitFormat {
    /// A format with `reserved_bits` carry bits per channel (1…7).
    pub fn new(reserved_bits: u32) -> Result<Self, String> {
        if (1..=7).contains(&reserved_bits) {
            Ok(Self { reserved_bits })
        } else {
            Err(format!("reserved bits must be 1…7, got {reserved_bits}"))
        }
    }

    /// Value bits per channel.
    pub fn channel_bits(self) -> u32 {
        8 - self.reserved_bits
    }

    /// Bits of a whole value (four channels).
    pub fn value_bits(self) -> u32 {
        4 * self.channel_bits()
    }

    /// The largest value, which stands for coverage 1.0.
    pub fn full(self) -> u32 {
        (1u32 << self.value_bits()) - 1
    }

    /// Split `v` (≤ [`SplitFormat::full`]) over R, G, B, A.
    pub fn split(self, v: u32) -> [u8; 4] {
        debug_assert!(v <= self.full());
        let b = self.channel_bits();
        let m = (1u32 << b) - 1;
        [3, 2, 1, 0].map(|k| ((v >> (k * b)) & m) as u8)
    }

    /// Reconstruct the accumulated value of a pixel, carries included.
    pub fn reconstruct(self, rgba: [u8; 4]) -> u64 {
        let b = self.channel_bits();
        rgba.iter().fold(0u64, |acc, &c| (acc << b) + c as u64)
    }
}

/// Saturating 8-bit additive blend of one channel; the flag tells whether it saturated.
#[inline]
pub fn blend_add_u8(dst: u8, src: u8) -> (u8, bool) {
    let s = dst as u16 + src as u16;
    if s > 255 {
        (255, true)
    } else {
        (s as u8, false)
    }
}

/// One tile of a split V-buffer: an additive and a subtractive RGBA8 buffer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SplitVTile {
    /// Additive buffer, one RGBA8 pixel per sample.
    pub add: Vec<[u8; 4]>,
    /// Subtractive buffer.
    pub sub: Vec<[u8; 4]>,
    /// Saturated channels per sample of the additive and the subtractive buffer, kept only for
    /// a buffer dump ([`overflow_record`]; empty otherwise).
    pub saturations: [Vec<u32>; 2],
}

/// What one [`SplitVTile::blend`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SplitBlend {
    /// The buffer blended into.
    pub target: SplitTarget,
    /// Its pixel before.
    pub before: [u8; 4],
    /// And after.
    pub after: [u8; 4],
    /// Channels that saturated at 255.
    pub saturated: u64,
}

impl SplitBlend {
    /// The buffer's name in a probe ([`super::probe`]).
    pub fn buffer(target: SplitTarget) -> &'static str {
        match target {
            SplitTarget::Add => "v-add",
            SplitTarget::Sub => "v-sub",
        }
    }

    /// A probe's record of this blend: the write of the target buffer.
    pub fn record(&self, e: ProbeEvent) -> ProbeEvent {
        e.write(
            Self::buffer(self.target),
            Raw::Rgba8(self.before),
            Raw::Rgba8(self.after),
            Overflow::Saturate,
            self.saturated,
        )
    }
}

/// Which of the two buffers a contribution goes to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SplitTarget {
    /// The additive buffer.
    Add,
    /// The subtractive buffer.
    Sub,
}

impl SplitVTile {
    /// A tile of `len` samples cleared to `add_clear` in the additive buffer and 0 in the
    /// subtractive one (the V-buffer is cleared to 1.0: `add_clear = format.split(full)`).
    pub fn cleared(add_clear: [u8; 4], len: usize) -> Self {
        Self {
            add: vec![add_clear; len],
            sub: vec![[0; 4]; len],
            saturations: [Vec::new(), Vec::new()],
        }
    }

    /// This tile, recording its saturations per sample when `on` ([`overflow_record`]).
    pub fn recording(mut self, on: bool) -> Self {
        let len = self.add.len();
        self.saturations = [overflow_record(on, len), overflow_record(on, len)];
        self
    }

    /// Blend the split value `src` into sample `i` of `target`: read the destination (4 bytes),
    /// add with saturation, write (4 bytes). Every saturated channel counts one overflow event.
    /// Returns the pixel before and after and the number of saturated channels.
    #[inline]
    pub fn blend(
        &mut self,
        target: SplitTarget,
        i: usize,
        src: [u8; 4],
        c: &mut Counters,
    ) -> SplitBlend {
        let (buf, record) = match target {
            SplitTarget::Add => (&mut self.add, &mut self.saturations[0]),
            SplitTarget::Sub => (&mut self.sub, &mut self.saturations[1]),
        };
        count!(c.color_read_bytes += 4);
        count!(c.color_write_bytes += 4);
        let dst = &mut buf[i];
        let before = *dst;
        let mut saturated = 0;
        for k in 0..4 {
            let (v, sat) = blend_add_u8(dst[k], src[k]);
            dst[k] = v;
            saturated += sat as u64;
        }
        count!(c.overflow_events += saturated);
        record_overflow(record, i, saturated as u32);
        SplitBlend {
            target,
            before,
            after: *dst,
            saturated,
        }
    }

    /// The resolved value of sample `i` after the pass: `(add − sub) / full` (not clamped).
    pub fn resolve(&self, format: SplitFormat, i: usize) -> f64 {
        let a = format.reconstruct(self.add[i]) as f64;
        let s = format.reconstruct(self.sub[i]) as f64;
        (a - s) / format.full() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_and_reconstruct_round_trip_for_every_value() {
        for r in 1..=7 {
            let f = SplitFormat::new(r).unwrap();
            let step = (f.full() / 4096).max(1) as usize;
            for v in (0..=f.full()).step_by(step) {
                assert_eq!(f.reconstruct(f.split(v)), v as u64);
            }
        }
        assert_eq!(SplitFormat::default().full(), 4095);
        assert_eq!(SplitFormat::default().split(4095), [7, 7, 7, 7]);
        assert_eq!(SplitFormat::default().split(0o1234), [1, 2, 3, 4]);
    }

    #[test]
    fn carries_accumulate_in_the_reserved_bits() {
        let f = SplitFormat::default();
        let mut t = SplitVTile::cleared([0; 4], 1);
        let mut c = Counters::default();
        for _ in 0..10 {
            t.blend(SplitTarget::Add, 0, f.split(0o7654), &mut c);
        }
        assert_eq!(f.reconstruct(t.add[0]), 10 * 0o7654);
        assert_eq!(c.overflow_events, 0);
        assert_eq!(c.color_read_bytes, 40);
    }

    /// OpenGL's saturating add on an unsigned normalized 8-bit channel, for every pair: the
    /// sum where it fits in 8 bits (255 included, which does not saturate), 255 and the flag
    /// above.
    #[test]
    fn blend_add_u8_saturates_exactly_above_255() {
        for dst in 0..=255u8 {
            for src in 0..=255u8 {
                let sum = u32::from(dst) + u32::from(src);
                let want = (sum.min(255) as u8, sum > 255);
                assert_eq!(blend_add_u8(dst, src), want, "{dst} + {src}");
            }
        }
    }

    /// Each saturated channel is one overflow event, counted and recorded at its sample of its
    /// buffer; the other sample and the other buffer record nothing. Four bytes are read and
    /// four written per blend.
    #[test]
    fn saturated_channels_are_counted_and_recorded_per_sample_and_buffer() {
        let mut t = SplitVTile::cleared([250, 0, 250, 0], 2).recording(true);
        let mut c = Counters::default();
        let add = t.blend(SplitTarget::Add, 1, [10, 10, 5, 10], &mut c);
        assert_eq!(add.before, [250, 0, 250, 0]);
        assert_eq!(add.after, [255, 10, 255, 10]);
        assert_eq!(add.saturated, 1);
        assert_eq!(t.add[1], [255, 10, 255, 10]);
        assert_eq!(t.add[0], [250, 0, 250, 0]);
        let first = t.blend(SplitTarget::Sub, 0, [255, 0, 0, 1], &mut c);
        assert_eq!((first.target, first.saturated), (SplitTarget::Sub, 0));
        let second = t.blend(SplitTarget::Sub, 0, [1, 0, 0, 255], &mut c);
        assert_eq!(second.after, [255, 0, 0, 255]);
        assert_eq!(second.saturated, 2);
        assert_eq!(t.saturations, [vec![0, 1], vec![2, 0]]);
        assert_eq!(c.overflow_events, 3);
        assert_eq!((c.color_read_bytes, c.color_write_bytes), (12, 12));
        // Without recording nothing is kept, and the counter still counts.
        let mut quiet = SplitVTile::cleared([255; 4], 1);
        quiet.blend(SplitTarget::Add, 0, [1; 4], &mut c);
        assert_eq!(quiet.saturations, [Vec::<u32>::new(), Vec::new()]);
        assert_eq!(c.overflow_events, 7);
    }

    /// The resolve is `(add − sub) / full` without a clamp: cleared to 1, the subtractive
    /// buffer at twice full gives exactly −1, and one more unit in the additive one
    /// (`[7, 7, 7, 8]` = 4096 with 3-bit channels) moves it by 1/4095.
    #[test]
    fn resolve_subtracts_the_subtractive_buffer_unclamped() {
        let f = SplitFormat::default();
        let mut t = SplitVTile::cleared(f.split(f.full()), 1);
        let mut c = Counters::default();
        assert_eq!(t.resolve(f, 0), 1.0);
        for _ in 0..2 {
            t.blend(SplitTarget::Sub, 0, f.split(f.full()), &mut c);
        }
        assert_eq!(t.resolve(f, 0), -1.0);
        t.blend(SplitTarget::Add, 0, f.split(1), &mut c);
        assert_eq!(t.add[0], [7, 7, 7, 8]);
        assert_eq!(t.resolve(f, 0), (4096.0 - 8190.0) / 4095.0);
    }

    /// The probe's names of the two buffers, distinct; `ssv-optimized`'s clears, blends and
    /// resolve all take them from here.
    #[test]
    fn each_target_has_its_own_buffer_name() {
        assert_eq!(SplitBlend::buffer(SplitTarget::Add), "v-add");
        assert_eq!(SplitBlend::buffer(SplitTarget::Sub), "v-sub");
    }

    #[test]
    fn reserved_bits_out_of_range_are_rejected() {
        assert!(SplitFormat::new(0).is_err());
        assert!(SplitFormat::new(8).is_err());
    }
}
