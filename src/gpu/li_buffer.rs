//! The light-intensity (LI) buffer of the penumbra-wedge algorithms (Paper I §4, Paper II §2,
//! §6.1): "just a stencil buffer with more precision", cleared to 255 (fully lit), to which
//! wedges add signed integer amounts, clamped to [0, 255] at the end and resolved to
//! visibility = clamp(LI, 0, 255) / 255.
//!
//! Formats ([`LiFormat`]):
//! * `Li16`: signed 16-bit, [−32768, 32767] — Paper I's buffer. Paper II §2: "at least 127
//!   shadow volumes can have overlapping regions without causing overflow".
//! * `Li12`: signed 12-bit, [−2048, 2047] (Paper I §4: "for certain scenes, a 12-bit buffer may
//!   be sufficient"), stored in an `i16`.
//! * `Li8`: an 8-bit stencil buffer, unsigned [0, 255] (Paper I §4: "another implementation
//!   could use an 8-bit stencil buffer"; stencil buffers are unsigned, so the cleared value
//!   255 fits but a single umbra entry already reaches the bottom of the range).
//!
//! Overflow ([`LiOverflow`]): `Wrap` keeps the low bits (two's complement modulo 2^bits,
//! re-centred into the format's range), `Saturate` clamps to the format's range. Every add
//! whose exact result leaves the range is one overflow event in [`Counters::overflow_events`].
//! Each add is a read-modify-write of one sample: its bytes (2 for `Li16`/`Li12`, 1 for `Li8`)
//! are counted as colour/LI read and write traffic.

use super::buffers::{overflow_record, record_overflow};
use super::counters::{count, Counters};
use super::probe::{Overflow, ProbeEvent, Raw};

/// Storage format of the LI buffer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum LiFormat {
    /// Signed 16-bit.
    Li16,
    /// Signed 12-bit.
    Li12,
    /// Unsigned 8-bit (an 8-bit stencil buffer).
    Li8,
}

impl LiFormat {
    /// Smallest storable value.
    pub fn min(self) -> i32 {
        match self {
            LiFormat::Li16 => i16::MIN as i32,
            LiFormat::Li12 => -2048,
            LiFormat::Li8 => 0,
        }
    }

    /// Largest storable value.
    pub fn max(self) -> i32 {
        match self {
            LiFormat::Li16 => i16::MAX as i32,
            LiFormat::Li12 => 2047,
            LiFormat::Li8 => 255,
        }
    }

    /// Bytes per sample as counted in the traffic counters.
    pub fn bytes(self) -> u64 {
        match self {
            LiFormat::Li16 | LiFormat::Li12 => 2,
            LiFormat::Li8 => 1,
        }
    }

    /// Bits of storage.
    pub fn bits(self) -> u32 {
        match self {
            LiFormat::Li16 => 16,
            LiFormat::Li12 => 12,
            LiFormat::Li8 => 8,
        }
    }
}

/// What an add does when its result leaves the format's range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum LiOverflow {
    /// Modulo 2^bits, back into the range.
    Wrap,
    /// Clamp to the range.
    Saturate,
}

/// The value LI buffers are cleared to: fully lit (Paper I §4).
pub const LI_CLEAR: i32 = 255;

/// `stored + delta` in `format` with `overflow` behaviour; returns the new value and whether
/// the exact sum left the range.
#[inline]
pub fn li_add(format: LiFormat, overflow: LiOverflow, stored: i32, delta: i32) -> (i32, bool) {
    let exact = stored + delta;
    let (lo, hi) = (format.min(), format.max());
    if (lo..=hi).contains(&exact) {
        return (exact, false);
    }
    let v = match overflow {
        LiOverflow::Saturate => exact.clamp(lo, hi),
        LiOverflow::Wrap => {
            let m = 1i64 << format.bits();
            (((exact as i64 - lo as i64).rem_euclid(m)) + lo as i64) as i32
        }
    };
    (v, true)
}

/// The final resolve of one LI value (Paper I §4): clamp to [0, 255], divide by 255.
#[inline]
pub fn li_visibility(li: i32) -> f32 {
    li.clamp(0, 255) as f32 / 255.0
}

/// Whether [`li_visibility`] clamps `li` (it lies outside [0, 255]).
pub fn li_clamped(li: i32) -> bool {
    !(0..=255).contains(&li)
}

/// The LI samples of one tile. Values are kept as `i32` but always lie in the format's range.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LiTile {
    /// Storage format.
    pub format: LiFormat,
    /// Overflow behaviour.
    pub overflow: LiOverflow,
    /// Stored values.
    pub values: Vec<i32>,
    /// Overflow events per sample, kept only for a buffer dump ([`overflow_record`]; empty
    /// otherwise).
    pub overflows: Vec<u32>,
}

impl LiTile {
    /// A tile of `len` samples cleared to [`LI_CLEAR`] (which every format can hold).
    pub fn cleared(format: LiFormat, overflow: LiOverflow, len: usize) -> Self {
        Self {
            format,
            overflow,
            values: vec![LI_CLEAR; len],
            overflows: Vec::new(),
        }
    }

    /// This tile, recording its overflow events per sample when `on` ([`overflow_record`]).
    pub fn recording(mut self, on: bool) -> Self {
        self.overflows = overflow_record(on, self.values.len());
        self
    }

    /// `addToLIBuffer(delta)` at sample `i` (Paper I §4 line 10): a counted read-modify-write;
    /// overflow events are counted. Returns the values before and after and whether it
    /// overflowed.
    #[inline]
    pub fn add(&mut self, i: usize, delta: i32, c: &mut Counters) -> (i32, i32, bool) {
        let b = self.format.bytes();
        count!(c.color_read_bytes += b);
        count!(c.color_write_bytes += b);
        let before = self.values[i];
        let (v, overflowed) = li_add(self.format, self.overflow, before, delta);
        count!(c.overflow_events += overflowed as u64);
        record_overflow(&mut self.overflows, i, overflowed as u32);
        self.values[i] = v;
        (before, v, overflowed)
    }

    /// A probe's record ([`super::probe`]) of an [`LiTile::add`] that returned `added`.
    pub fn record_add(
        &self,
        e: ProbeEvent,
        (before, after, overflowed): (i32, i32, bool),
    ) -> ProbeEvent {
        let kind = match self.overflow {
            LiOverflow::Wrap => Overflow::Wrap,
            LiOverflow::Saturate => Overflow::Saturate,
        };
        e.write(
            "li",
            Raw::Int(before),
            Raw::Int(after),
            kind,
            overflowed as u64,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sixteen_bit_wraps_and_saturates() {
        let f = LiFormat::Li16;
        assert_eq!(li_add(f, LiOverflow::Wrap, -32640, -255), (32641, true));
        assert_eq!(
            li_add(f, LiOverflow::Saturate, -32640, -255),
            (-32768, true)
        );
        assert_eq!(li_add(f, LiOverflow::Wrap, 255, -255), (0, false));
    }

    #[test]
    fn twelve_and_eight_bit_ranges() {
        assert_eq!(
            li_add(LiFormat::Li12, LiOverflow::Wrap, -2040, -255),
            (1801, true)
        );
        assert_eq!(li_add(LiFormat::Li8, LiOverflow::Wrap, 0, -255), (1, true));
        assert_eq!(
            li_add(LiFormat::Li8, LiOverflow::Saturate, 0, -255),
            (0, true)
        );
        assert_eq!(
            li_add(LiFormat::Li8, LiOverflow::Saturate, 255, 10),
            (255, true)
        );
    }

    #[test]
    fn tile_counts_bytes_and_overflows() {
        let mut t = LiTile::cleared(LiFormat::Li8, LiOverflow::Saturate, 4);
        let mut c = Counters::default();
        t.add(1, -255, &mut c);
        t.add(1, -255, &mut c);
        assert_eq!(t.values, vec![255, 0, 255, 255]);
        assert_eq!(c.overflow_events, 1);
        assert_eq!(c.color_write_bytes, 2);
        assert_eq!(c.color_read_bytes, 2);
        assert_eq!(li_visibility(-5), 0.0);
        assert_eq!(li_visibility(300), 1.0);
    }

    /// Bytes per sample are the storage bits rounded up to whole bytes (a 12-bit LI value
    /// lives in a 16-bit word), and a tile's traffic counts them per read and write.
    #[test]
    fn each_format_counts_its_bytes() {
        for format in [LiFormat::Li16, LiFormat::Li12, LiFormat::Li8] {
            assert_eq!(
                format.bytes(),
                u64::from(format.bits().div_ceil(8)),
                "{format:?}"
            );
            let mut t = LiTile::cleared(format, LiOverflow::Wrap, 2);
            let mut c = Counters::default();
            t.add(0, -1, &mut c);
            assert_eq!(c.color_read_bytes, format.bytes());
            assert_eq!(c.color_write_bytes, format.bytes());
        }
        assert_eq!(LiFormat::Li16.bytes(), 2);
    }

    /// The resolve clamps exactly the values outside [0, 255] (Paper I §4), and
    /// [`li_clamped`] says so for each of them.
    #[test]
    fn clamped_is_outside_the_resolve_range() {
        for li in [-40000, -256, -1, 0, 1, 128, 254, 255, 256, 511, 40000] {
            let unclamped = li as f32 / 255.0;
            let clamped = li_visibility(li) != unclamped;
            assert_eq!(li_clamped(li), clamped, "{li}");
            assert_eq!(li_clamped(li), !(0..=255).contains(&li), "{li}");
        }
    }
}
