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
    /// Smallest stored value over the tile's pixels inside the image: built by
    /// [`DepthTile::build_hiz`] and kept exact by every depth write of
    /// [`DepthTile::test_and_write`] under `Less` (such writes only lower values).
    pub zmin: u32,
    /// Largest stored value over the tile's pixels inside the image: built by
    /// [`DepthTile::build_hiz`]; during a pass that writes under `Less`, an upper bound that
    /// [`DepthTile::early_z_rejects`] tightens when it must and [`DepthTile::finish_hiz`]
    /// makes exact again.
    pub zmax: u32,
    /// The smallest window depth that quantizes to `zmax` or more
    /// ([`DepthFormat::first_quantized_at_least`]):
    /// a fragment at or beyond it is behind every stored sample. Kept with `zmax` so that the
    /// hierarchical-Z test compares the triangle's f32 depth range without quantizing it.
    behind_from: f32,
    /// The smallest window depth that quantizes to `zmin` or more: a fragment before it is in
    /// front of every stored sample (computed with the bounds, not kept by the writes).
    in_front_below: f32,
    /// How many samples hold `zmax` (the tile's pixels inside the image, or every sample of a
    /// tile cleared without its rectangle, [`DepthTile::cleared`]); 0 once `Less` writes
    /// have replaced every one of them, `zmax` then being only an upper bound.
    at_zmax: u32,
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
            at_zmax: len as u32,
        }
    }

    /// Tile `t` of `tiling` cleared to depth 1.0, its bounds over its pixels inside the image
    /// (what [`DepthTile::build_hiz`] would give, without reading it): the start of a pass
    /// with early Z ([`DepthTile::early_z_rejects`]).
    pub fn cleared_in(format: DepthFormat, tiling: &Tiling, t: usize) -> Self {
        let r = tiling.rect(t);
        Self {
            at_zmax: (r.x1 - r.x0) * (r.y1 - r.y0),
            ..Self::cleared(format, tiling.tile_len())
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
    /// built once after the scene pass; wedges and shadow volumes never write depth), with
    /// both thresholds.
    pub fn build_hiz(&mut self, tiling: &Tiling, t: usize) {
        self.zmin = self.scan(tiling, t);
        self.in_front_below = self.format.first_quantized_at_least(self.zmin);
    }

    /// Set zmax to the largest stored value over the pixels of tile `t` inside the image,
    /// with the count of those holding it and its threshold (uncounted: the unit's own
    /// reduction); returns the smallest.
    fn scan(&mut self, tiling: &Tiling, t: usize) -> u32 {
        let r = tiling.rect(t);
        let width = (r.x1 - r.x0) as usize;
        let rows = (r.y0..r.y1).map(|y| tiling.local(r.x0, y));
        let (mut lo, mut hi) = (u32::MAX, 0);
        for start in rows.clone() {
            for &v in &self.values[start..start + width] {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        let at_hi = rows.map(|start| {
            let row = &self.values[start..start + width];
            row.iter().filter(|&&v| v == hi).count() as u32
        });
        self.at_zmax = at_hi.sum();
        if hi != self.zmax {
            self.zmax = hi;
            self.behind_from = self.format.first_quantized_at_least(hi);
        }
        lo
    }

    /// Early Z, in a pass that tests `Less` and writes depth into tiles started with
    /// [`DepthTile::cleared_in`] (module [`super::hiz`], "Early Z"), asked before each
    /// triangle the pass draws in tile `t` of `tiling`: whether every fragment of a triangle
    /// whose fragment depths are all `near` or more (the depths it is tested with) fails the
    /// test at every sample — what [`DepthTile::depth_outcome`] decides as `Some(false)` for
    /// `Less` — so that it need not be drawn there.
    ///
    /// The writes keep zmin exact and zmax an upper bound with the count of the samples that
    /// hold it ([`DepthTile::test_and_write`]). When zmax does not reject the triangle but no
    /// sample holds it any more, it is made exact again by a reduction over the tile — unless
    /// the triangle is in front of every sample (quantized `near` below zmin), which no bound
    /// could reject. The zmax read (one value) and the rejection are counted in `c`; the
    /// reduction is not, as [`DepthTile::build_hiz`]'s is not.
    pub fn early_z_rejects(
        &mut self,
        tiling: &Tiling,
        t: usize,
        near: f32,
        c: &mut Counters,
    ) -> bool {
        count!(c.hiz_read_bytes += self.format.bytes());
        let mut culled = self.behind(near);
        if !culled && self.at_zmax == 0 && self.format.quantize(near) >= self.zmin {
            self.scan(tiling, t);
            culled = self.behind(near);
        }
        count!(c.tiles_culled_hiz += culled as u64);
        culled
    }

    /// The end of a pass with early Z ([`DepthTile::early_z_rejects`]) on tile `t` of
    /// `tiling`: zmax made exact where no sample holds it any more, and both thresholds
    /// computed — what [`DepthTile::build_hiz`] gives.
    pub fn finish_hiz(&mut self, tiling: &Tiling, t: usize) {
        if self.at_zmax == 0 {
            self.scan(tiling, t);
        }
        self.in_front_below = self.format.first_quantized_at_least(self.zmin);
    }

    /// The depth test of fragment `f` against this tile (reads the stored value, counted).
    /// Returns (passed, quantized fragment depth).
    #[inline]
    pub fn test(&self, state: &DepthState, f: &Fragment, c: &mut Counters) -> (bool, u32) {
        let (pass, z, _) = self.test_read(state, f, c);
        (pass, z)
    }

    /// [`DepthTile::test`], also returning the stored value it read.
    #[inline]
    fn test_read(&self, state: &DepthState, f: &Fragment, c: &mut Counters) -> (bool, u32, u32) {
        let z = self.format.quantize(f.z);
        let stored = self.read(f.local, c);
        (state.func.test(z, stored), z, stored)
    }

    /// The depth test of fragment `f` followed, when it passes and `state.write` is set, by the
    /// write of its quantized depth (all counted, `depth_passed` included). Returns whether it
    /// passed. A write under `Less` keeps the tile's bounds: zmin exact, zmax an upper bound
    /// with the count of the samples holding it ([`DepthTile::early_z_rejects`]).
    #[inline]
    pub fn test_and_write(&mut self, state: &DepthState, f: &Fragment, c: &mut Counters) -> bool {
        let (pass, z, stored) = self.test_read(state, f, c);
        if pass {
            count!(c.depth_passed += 1);
            if state.write {
                if state.func == DepthFunc::Less {
                    // z < stored ≤ zmax: the sample no longer holds zmax if it did.
                    self.zmin = self.zmin.min(z);
                    self.at_zmax -= (stored == self.zmax) as u32;
                }
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
        let behind = self.behind(near);
        let in_front = far < self.in_front_below;
        match func {
            DepthFunc::Less if behind => Some(false),
            DepthFunc::Less if in_front => Some(true),
            DepthFunc::GEqual if behind => Some(true),
            DepthFunc::GEqual if in_front => Some(false),
            _ => None,
        }
    }

    /// Whether every fragment at window depth `near` or beyond quantizes to `zmax` or more:
    /// at or behind every stored sample. Undecided (false) for a `near` that is not positive
    /// ([`DepthTile::depth_outcome`]).
    fn behind(&self, near: f32) -> bool {
        near > 0.0 && near >= self.behind_from
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
