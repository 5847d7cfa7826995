//! Typed per-tile buffers (`docs/architecture.md` "Buffers", "Counters",
//! "Hierarchical Z"). Every access
//! goes through these types, which add the bytes moved to the caller's [`Counters`].
//!
//! Storage is tile-major (see [`super::tiling`]): one value per sample of a T×T tile.

use super::counters::{count, Counters};
use super::depth::{DepthFormat, DepthFunc, DepthState};
use super::probe::{Overflow, ProbeEvent, Raw};
use super::raster::Fragment;
use super::setup::RasterTriangle;
use super::stencil::{StencilOp, StencilState};
use super::tiling::Tiling;

/// The depth samples of one tile, plus its hierarchical-Z bounds.
#[derive(Debug, Clone, PartialEq)]
pub struct DepthTile {
    /// Storage format.
    pub format: DepthFormat,
    /// Stored values (see [`DepthFormat::quantize`]).
    pub values: Vec<u32>,
    /// Smallest stored value over the tile's pixels inside the image (valid after
    /// [`DepthTile::build_hiz`]).
    pub zmin: u32,
    /// Largest stored value over the tile's pixels inside the image.
    pub zmax: u32,
    /// The smallest window depth that quantizes to `zmax` or more
    /// ([`DepthFormat::first_quantized_at_least`]):
    /// a fragment at or beyond it is behind every stored sample. Kept with `zmax` so that the
    /// hierarchical-Z test compares the triangle's f32 depth range without quantizing it.
    behind_from: f32,
    /// The smallest window depth that quantizes to `zmin` or more: a fragment before it is in
    /// front of every stored sample.
    in_front_below: f32,
}

impl DepthTile {
    /// A tile of `len` samples cleared to depth 1.0.
    pub fn cleared(format: DepthFormat, len: usize) -> Self {
        Self::cleared_to(format, 1.0, len)
    }

    /// A tile of `len` samples cleared to window depth `z_w` (`glClearDepth`, quantized as a
    /// fragment's depth is).
    pub fn cleared_to(format: DepthFormat, z_w: f32, len: usize) -> Self {
        let z = format.quantize(z_w);
        let threshold = format.first_quantized_at_least(z);
        Self {
            format,
            values: vec![z; len],
            zmin: z,
            zmax: z,
            behind_from: threshold,
            in_front_below: threshold,
        }
    }

    /// Read sample `i` (counted).
    #[inline]
    pub fn read(&self, i: usize, c: &mut Counters) -> u32 {
        count!(c.depth_read_bytes += self.format.bytes());
        self.values[i]
    }

    /// Write sample `i` (counted).
    #[inline]
    pub fn write(&mut self, i: usize, v: u32, c: &mut Counters) {
        count!(c.depth_write_bytes += self.format.bytes());
        self.values[i] = v;
    }

    /// Compute zmin/zmax over the pixels of tile `t` that lie inside the image (Paper II §4:
    /// built once after the scene pass; wedges and shadow volumes never write depth).
    pub fn build_hiz(&mut self, tiling: &Tiling, t: usize) {
        let r = tiling.rect(t);
        let mut lo = u32::MAX;
        let mut hi = 0;
        for y in r.y0..r.y1 {
            for x in r.x0..r.x1 {
                let v = self.values[tiling.local(x, y)];
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        self.zmin = lo;
        self.zmax = hi;
        self.behind_from = self.format.first_quantized_at_least(hi);
        self.in_front_below = self.format.first_quantized_at_least(lo);
    }

    /// The depth test of fragment `f` against this tile (reads the stored value, counted).
    /// Returns (passed, quantized fragment depth).
    #[inline]
    pub fn test(&self, state: &DepthState, f: &Fragment, c: &mut Counters) -> (bool, u32) {
        let z = self.format.quantize(f.z);
        let stored = self.read(f.local, c);
        (state.func.test(z, stored), z)
    }

    /// The depth test of fragment `f` followed, when it passes and `state.write` is set, by the
    /// write of its quantized depth (all counted, `depth_passed` included). Returns whether it
    /// passed.
    #[inline]
    pub fn test_and_write(&mut self, state: &DepthState, f: &Fragment, c: &mut Counters) -> bool {
        let (pass, z) = self.test(state, f, c);
        if pass {
            count!(c.depth_passed += 1);
            if state.write {
                self.write(f.local, z, c);
            }
        }
        pass
    }

    /// A probe's record ([`super::probe`]) of a depth test with `func` of the quantized fragment
    /// depth `z` against sample `i`, which `pass`ed or not (the stored value read again,
    /// uncounted).
    pub fn record_test(
        &self,
        e: ProbeEvent,
        func: DepthFunc,
        i: usize,
        z: u32,
        pass: bool,
    ) -> ProbeEvent {
        e.depth(self.format, func, z, self.values[i], pass)
    }

    /// The outcome every fragment of `tri` in this tile has under the depth test `func`, when
    /// the tile's zmin/zmax decide it for all of them ([`super::hiz`]): `Some(false)` when
    /// none can pass, `Some(true)` when all pass, `None` when it depends on the sample. A
    /// fragment's depth is the triangle's depth plane at a covered sample, between its vertex
    /// depths ([`RasterTriangle::z_range`]), and quantizing is monotone. A triangle reaching
    /// depth 0 is left undecided (a fragment depth of −0.0 quantizes out of order in D32F).
    /// Only `Less` and `GEqual` are decided; other functions give `None`.
    pub fn depth_outcome(&self, func: DepthFunc, tri: &RasterTriangle) -> Option<bool> {
        let [near, far] = tri.z_range;
        if near.is_nan() || far.is_nan() || near <= 0.0 {
            return None;
        }
        // Every fragment at or behind every stored sample (quantize(near) >= zmax) / in front
        // of every one (quantize(far) < zmin), decided on the unquantized depths.
        let behind = near >= self.behind_from;
        let in_front = far < self.in_front_below;
        match func {
            DepthFunc::Less if behind => Some(false),
            DepthFunc::Less if in_front => Some(true),
            DepthFunc::GEqual if behind => Some(true),
            DepthFunc::GEqual if in_front => Some(false),
            _ => None,
        }
    }

    /// Bytes one hierarchical-Z read of this tile's zmin and zmax costs (two values in the
    /// depth format; [`Counters::hiz_read_bytes`]).
    pub fn hiz_read_bytes(&self) -> u64 {
        2 * self.format.bytes()
    }
}

/// A per-sample record of overflow events for a buffer dump (`methods::dump`): `len` zeros
/// when `on`, else empty — a record that records nothing and costs nothing (a normal run).
pub fn overflow_record(on: bool, len: usize) -> Vec<u32> {
    if on {
        vec![0; len]
    } else {
        Vec::new()
    }
}

/// Count `n` overflow events at sample `i` of `record` when it is kept ([`overflow_record`]);
/// called where the event happens, next to [`Counters::overflow_events`].
#[inline]
pub fn record_overflow(record: &mut [u32], i: usize, n: u32) {
    if n > 0 {
        if let Some(c) = record.get_mut(i) {
            *c += n;
        }
    }
}

/// The 8-bit stencil samples of one tile.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StencilTile {
    /// Stored values.
    pub values: Vec<u8>,
    /// Overflow events (clamps and wraps) per sample, kept only for a buffer dump
    /// ([`overflow_record`]; empty otherwise).
    pub overflows: Vec<u32>,
}

impl StencilTile {
    /// A tile of `len` samples cleared to `value`.
    pub fn cleared(value: u8, len: usize) -> Self {
        Self {
            values: vec![value; len],
            overflows: Vec::new(),
        }
    }

    /// This tile, recording its overflow events per sample when `on` ([`overflow_record`]).
    pub fn recording(mut self, on: bool) -> Self {
        self.overflows = overflow_record(on, self.values.len());
        self
    }

    /// Apply the stencil state to fragment `f` of a triangle with the given facing, given the
    /// depth-test outcome. Reads and (when the value changes or an op writes) writes are
    /// counted; clamps and wraps are counted as overflow events. Returns what happened.
    #[inline]
    pub fn apply(
        &mut self,
        state: &StencilState,
        front_facing: bool,
        f: &Fragment,
        depth_pass: bool,
        c: &mut Counters,
    ) -> StencilUpdate {
        let face = state.face(front_facing);
        count!(c.stencil_read_bytes += 1);
        let stored = self.values[f.local];
        let stencil_pass = face.func.test(face.reference, stored, face.read_mask);
        let mut update = StencilUpdate {
            before: stored,
            after: stored,
            stencil_pass,
            op: face.op(stencil_pass, depth_pass),
            overflow: false,
        };
        if let Some((v, overflow)) = face.update(stored, stencil_pass, depth_pass) {
            count!(c.stencil_write_bytes += 1);
            count!(c.overflow_events += overflow as u64);
            record_overflow(&mut self.overflows, f.local, overflow as u32);
            self.values[f.local] = v;
            (update.after, update.overflow) = (v, overflow);
        }
        update
    }
}

/// What [`StencilTile::apply`] did to one sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StencilUpdate {
    /// The stored value before.
    pub before: u8,
    /// And after.
    pub after: u8,
    /// Whether the stencil test passed.
    pub stencil_pass: bool,
    /// The op that ran.
    pub op: StencilOp,
    /// Whether it over- or underflowed (wrapped or saturated).
    pub overflow: bool,
}

impl StencilUpdate {
    /// The probe's record of this update ([`super::probe`]): a write of `buffer`.
    pub fn record(&self, e: ProbeEvent, buffer: &str) -> ProbeEvent {
        let kind = if self.op.wraps() {
            Overflow::Wrap
        } else {
            Overflow::Saturate
        };
        e.write(
            buffer,
            Raw::U8(self.before),
            Raw::U8(self.after),
            kind,
            self.overflow as u64,
        )
        .note(format!("stencil {:?}", self.op))
    }
}

/// Allocate one tile-storage value per tile with `make(tile_index, samples_per_tile)`.
pub fn alloc_tiles<T>(tiling: &Tiling, make: impl Fn(usize, usize) -> T) -> Vec<T> {
    (0..tiling.tile_count())
        .map(|t| make(t, tiling.tile_len()))
        .collect()
}
