//! Single-channel colour render targets (the red channel of a p-buffer, Wyman & Hansen §5)
//! in the storage formats a map can be measured in, every access counted.
//!
//! * [`ColorFormat::Unorm8`]: 8-bit unsigned normalized, as a p-buffer of 2003 held colour:
//!   `round_half_even(clamp(v, 0, 1) · 255)` (OpenGL converts to fixed point with a clamp; a
//!   clamped write counts an overflow event).
//! * [`ColorFormat::F16`]: IEEE binary16 (`half::f16`), `v` rounded to nearest even once;
//!   a result that is not finite counts an overflow event.
//! * [`ColorFormat::F32`]: `v` rounded to f32.
//!
//! Values are stored as `u32` (the unorm value or the float's bits).
//!
//! Targets with four channels ([`RgbaTile`], the D-buffer of CGI 2004 §3) store each channel
//! in the same format and write only the channels a [`ColorMask`] enables (`glColorMask`), so
//! one target can be filled by several draws that each own some of its channels.

use super::buffers::{overflow_record, record_overflow};
use super::counters::{count, Counters};
use super::probe::Overflow;
use half::f16;

/// The storage format of a colour target (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum ColorFormat {
    /// 8-bit unsigned normalized.
    Unorm8,
    /// 16-bit float.
    F16,
    /// 32-bit float.
    F32,
}

impl ColorFormat {
    /// Bytes one sample occupies.
    pub fn bytes(self) -> u64 {
        match self {
            ColorFormat::Unorm8 => 1,
            ColorFormat::F16 => 2,
            ColorFormat::F32 => 4,
        }
    }

    /// The stored value of `v` and whether the conversion saturated or overflowed.
    pub fn encode(self, v: f64) -> (u32, bool) {
        match self {
            ColorFormat::Unorm8 => {
                let c = v.clamp(0.0, 1.0);
                ((c * 255.0).round_ties_even() as u32, c != v)
            }
            ColorFormat::F16 => {
                let h = f16::from_f64(v);
                (h.to_bits() as u32, !h.is_finite())
            }
            ColorFormat::F32 => {
                let x = v as f32;
                (x.to_bits(), !x.is_finite())
            }
        }
    }

    /// What the overflow events a write counts are: a clamp for unorm8, a result that is not
    /// finite for the float formats.
    pub fn overflow(self) -> Overflow {
        match self {
            ColorFormat::Unorm8 => Overflow::Clamp,
            _ => Overflow::NonFinite,
        }
    }

    /// The value a stored sample stands for.
    pub fn decode(self, stored: u32) -> f32 {
        match self {
            ColorFormat::Unorm8 => stored as f32 / 255.0,
            ColorFormat::F16 => f16::from_bits(stored as u16).to_f32(),
            ColorFormat::F32 => f32::from_bits(stored),
        }
    }
}

/// The colour samples of one tile.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ColorTile {
    /// Storage format.
    pub format: ColorFormat,
    /// Stored values ([`ColorFormat::encode`]).
    pub values: Vec<u32>,
    /// Overflow events per sample, kept only for a buffer dump ([`overflow_record`]; empty
    /// otherwise).
    pub overflows: Vec<u32>,
}

impl ColorTile {
    /// A tile of `len` samples cleared to `value` (the clear is not counted).
    pub fn cleared(format: ColorFormat, value: f64, len: usize) -> Self {
        Self {
            format,
            values: vec![format.encode(value).0; len],
            overflows: Vec::new(),
        }
    }

    /// This tile, recording its overflow events per sample when `on` ([`overflow_record`]).
    pub fn recording(mut self, on: bool) -> Self {
        self.overflows = overflow_record(on, self.values.len());
        self
    }

    /// Write `v` to sample `i` (counted; a saturated or overflowed conversion counts an
    /// overflow event).
    #[inline]
    pub fn write(&mut self, i: usize, v: f64, c: &mut Counters) {
        let (stored, overflow) = self.format.encode(v);
        count!(c.color_write_bytes += self.format.bytes());
        count!(c.overflow_events += overflow as u64);
        record_overflow(&mut self.overflows, i, overflow as u32);
        self.values[i] = stored;
    }

    /// The value of sample `i` (not counted: reads of a finished map are counted by the pass
    /// that samples it).
    #[inline]
    pub fn value(&self, i: usize) -> f32 {
        self.format.decode(self.values[i])
    }
}

/// `glColorMask(r, g, b, a)`: which channels of an RGBA target a draw writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct ColorMask(pub [bool; 4]);

/// The RGBA samples of one tile, every channel in one format.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RgbaTile {
    /// Storage format of every channel.
    pub format: ColorFormat,
    /// Stored values per sample and channel ([`ColorFormat::encode`]).
    pub values: Vec<[u32; 4]>,
    /// Overflow events per sample (all channels), kept only for a buffer dump
    /// ([`overflow_record`]; empty otherwise).
    pub overflows: Vec<u32>,
}

impl RgbaTile {
    /// A tile of `len` samples cleared to `value` (the clear is not counted).
    pub fn cleared(format: ColorFormat, value: [f64; 4], len: usize) -> Self {
        Self {
            format,
            values: vec![value.map(|v| format.encode(v).0); len],
            overflows: Vec::new(),
        }
    }

    /// This tile, recording its overflow events per sample when `on` ([`overflow_record`]).
    pub fn recording(mut self, on: bool) -> Self {
        self.overflows = overflow_record(on, self.values.len());
        self
    }

    /// Write the channels of `v` that `mask` enables to sample `i` (each counted; a
    /// saturated or overflowed conversion counts an overflow event).
    #[inline]
    pub fn write_masked(&mut self, i: usize, v: [f64; 4], mask: ColorMask, c: &mut Counters) {
        for ((value, on), slot) in v.iter().zip(mask.0).zip(&mut self.values[i]) {
            if on {
                let (stored, overflow) = self.format.encode(*value);
                count!(c.color_write_bytes += self.format.bytes());
                count!(c.overflow_events += overflow as u64);
                record_overflow(&mut self.overflows, i, overflow as u32);
                *slot = stored;
            }
        }
    }

    /// The four values of sample `i` (not counted: reads of a finished target are counted by
    /// the pass that samples it).
    #[inline]
    pub fn texel(&self, i: usize) -> [f32; 4] {
        self.values[i].map(|v| self.format.decode(v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_round_and_flag_overflow() {
        use ColorFormat::*;
        assert_eq!(Unorm8.encode(1.0), (255, false));
        assert_eq!(Unorm8.encode(0.5), (128, false)); // 127.5 → even
        assert_eq!(Unorm8.encode(1.5 / 255.0), (2, false));
        assert_eq!(Unorm8.encode(-0.1), (0, true));
        assert_eq!(Unorm8.encode(1.1), (255, true));
        assert_eq!(Unorm8.decode(255), 1.0);
        assert_eq!(F16.decode(F16.encode(0.1).0), f16::from_f64(0.1).to_f32());
        assert!(F16.encode(1e6).1);
        assert_eq!(F32.decode(F32.encode(0.1).0), 0.1f32);
        assert!(!F32.encode(-0.25).1);
    }

    #[test]
    fn writes_are_counted() {
        let mut t = ColorTile::cleared(ColorFormat::F16, 1.0, 4);
        let mut c = Counters::default();
        t.write(2, 0.25, &mut c);
        assert_eq!(t.value(2), 0.25);
        assert_eq!(t.value(0), 1.0);
        assert_eq!((c.color_write_bytes, c.overflow_events), (2, 0));
    }

    #[test]
    fn masked_writes_touch_only_their_channels() {
        let mut t = RgbaTile::cleared(ColorFormat::F16, [9.0, 0.0, 0.0, 0.0], 2);
        let mut c = Counters::default();
        t.write_masked(
            1,
            [1.0, 2.5, 3.0, 4.0],
            ColorMask([false, true, false, true]),
            &mut c,
        );
        assert_eq!(t.texel(1), [9.0, 2.5, 0.0, 4.0]);
        assert_eq!(t.texel(0), [9.0, 0.0, 0.0, 0.0]);
        assert_eq!((c.color_write_bytes, c.overflow_events), (4, 0));
        t.write_masked(0, [1e6; 4], ColorMask([true; 4]), &mut c);
        assert_eq!(c.overflow_events, 4);
    }
}
