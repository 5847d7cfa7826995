//! Typed per-tile buffers (`docs/architecture.md` "Buffers", "Counters",
//! "Hierarchical Z"). Every access
//! goes through these types, which add the bytes moved to the caller's [`Counters`].
//!
//! Storage is tile-major (see [`super::tiling`]): one value per sample of a T×T tile.

use super::counters::{count, Counters};
use super::depth::{DepthFormat, DepthFunc, DepthState};
use super::probe::{Overflow, ProbeEvent, Raw};
use super::raster::{Fragment, TileDraw};
use super::setup::RasterTriangle;
use super::stencil::{StencilOp, StencilState};
use super::tiling::{TileRect, Tiling};

/// The hierarchical-Z bounds of one HiZ tile: a square of the raster tile's samples whose edge
/// is `[options.gpu] hiz-tile-size` ([`super::hiz`], "HiZ tiles").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HizBounds {
    /// Smallest stored value over the HiZ tile's pixels inside the image: built by
    /// [`DepthTile::build_hiz`] and kept exact by every depth write of
    /// [`DepthTile::test_and_write`] under `Less` (such writes only lower values).
    pub zmin: u32,
    /// Largest stored value over the HiZ tile's pixels inside the image: built by
    /// [`DepthTile::build_hiz`]; during a pass that writes under `Less`, an upper bound that
    /// [`DepthTile::early_z`] tightens when it must and [`DepthTile::finish_hiz`]
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
    /// How many samples hold `zmax` (the HiZ tile's pixels inside the image, or every sample
    /// of a tile cleared without its rectangle, [`DepthTile::cleared`]); 0 once `Less` writes
    /// have replaced every one of them, `zmax` then being only an upper bound.
    at_zmax: u32,
}

impl HizBounds {
    /// The bounds of `samples` samples all holding `z` in `format`.
    fn uniform(format: DepthFormat, z: u32, samples: u32) -> Self {
        let threshold = format.first_quantized_at_least(z);
        HizBounds {
            zmin: z,
            zmax: z,
            behind_from: threshold,
            in_front_below: threshold,
            at_zmax: samples,
        }
    }

    /// The outcome every fragment of `tri` in this HiZ tile has under the depth test `func`,
    /// when the bounds decide it for all of them ([`super::hiz`]): `Some(false)` when none
    /// can pass, `Some(true)` when all pass, `None` when it depends on the sample. A
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
    /// ([`HizBounds::depth_outcome`]).
    fn behind(&self, near: f32) -> bool {
        near > 0.0 && near >= self.behind_from
    }
}

/// The depth samples of one raster tile, plus the hierarchical-Z bounds of each of its HiZ
/// tiles ([`HizBounds`]; one HiZ tile per raster tile when both edges are equal, the default).
#[derive(Debug, Clone, PartialEq)]
pub struct DepthTile {
    /// Storage format.
    pub format: DepthFormat,
    /// Stored values (see [`DepthFormat::quantize`]).
    pub values: Vec<u32>,
    /// The bounds of the HiZ tiles, row-major inside the raster tile (padding included: a
    /// HiZ tile wholly outside the image holds no sample and is never consulted).
    hiz: Vec<HizBounds>,
    /// The coarse level: the union of the bounds of the HiZ tiles holding samples, built with
    /// them ([`DepthTile::build_hiz`], [`DepthTile::finish_hiz`]) and read first where a
    /// raster tile holds several HiZ tiles ([`DepthTile::hiz_draw`]). Not kept by the
    /// writes: early Z reads the HiZ tiles only.
    coarse: HizBounds,
    /// How the raster tile is cut into HiZ tiles.
    grid: HizGrid,
}

/// How a raster tile is cut into HiZ tiles: both edges powers of two, the HiZ tile's at most
/// the raster tile's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct HizGrid {
    /// log₂ of the raster tile's edge.
    tile_shift: u32,
    /// log₂ of the HiZ tile's edge, at most `tile_shift`.
    hiz_shift: u32,
}

impl HizGrid {
    /// log₂ of the number of HiZ tiles per row.
    fn per_row_shift(self) -> u32 {
        self.tile_shift - self.hiz_shift
    }

    /// Number of HiZ tiles (padding included).
    fn count(self) -> usize {
        1 << (2 * self.per_row_shift())
    }

    /// The column and row of HiZ tile `k` in the tile.
    fn coords(self, k: usize) -> (u32, u32) {
        let k = k as u32;
        (
            k & ((1 << self.per_row_shift()) - 1),
            k >> self.per_row_shift(),
        )
    }

    /// The HiZ tile at column `kx` and row `ky` of the tile.
    fn index_of(self, kx: u32, ky: u32) -> usize {
        ((ky << self.per_row_shift()) + kx) as usize
    }

    /// The pixel rectangle of HiZ tile `k` of tile `t` of `tiling`, clipped to the image
    /// (empty for a HiZ tile in the padding).
    fn rect(self, tiling: &Tiling, t: usize, k: usize) -> TileRect {
        let r = tiling.rect(t);
        let (kx, ky) = self.coords(k);
        let (x0, y0) = (r.x0 + (kx << self.hiz_shift), r.y0 + (ky << self.hiz_shift));
        let edge = 1 << self.hiz_shift;
        TileRect {
            x0: x0.min(r.x1),
            y0: y0.min(r.y1),
            x1: (x0 + edge).min(r.x1),
            y1: (y0 + edge).min(r.y1),
        }
    }

    /// The HiZ tile holding sample `i` of the tile.
    #[inline]
    fn index(self, i: usize) -> usize {
        let i = i as u32;
        let (y, x) = (i >> self.tile_shift, i & ((1 << self.tile_shift) - 1));
        self.index_of(x >> self.hiz_shift, y >> self.hiz_shift)
    }

    /// The HiZ tiles of tile `t` of `tiling` that the inclusive pixel box `bbox` (a
    /// triangle's, [`RasterTriangle::bbox`]) overlaps, in row-major order. A box that misses
    /// the tile is clamped into it: the triangle then has no fragment there, and any HiZ
    /// tile's decision holds for none.
    fn under(
        self,
        tiling: &Tiling,
        t: usize,
        [x0, y0, x1, y1]: [u32; 4],
    ) -> impl Iterator<Item = usize> + Clone {
        let span = |lo: u32, hi: u32, r0: u32, r1: u32| {
            let at = |v: u32| (v.clamp(r0, r1 - 1) - r0) >> self.hiz_shift;
            at(lo)..=at(hi)
        };
        let r = tiling.rect(t);
        let (xs, ys) = (span(x0, x1, r.x0, r.x1), span(y0, y1, r.y0, r.y1));
        ys.flat_map(move |ky| xs.clone().map(move |kx| self.index_of(kx, ky)))
    }

    /// What the draw loop rasterizes of a triangle with pixel box `bbox` in tile `t` of
    /// `tiling` when `rejects(k)` tells whether HiZ tile `k` rejects it, asked of every HiZ
    /// tile under the box in row-major order ([`KeptHizTiles`]). With one HiZ tile per raster
    /// tile (the default) that tile decides alone, without the box (profiled: the general
    /// path took 12 % of `hard-sv` on `cube-of-spheres` 512², one thread).
    fn draw(
        self,
        tiling: &Tiling,
        t: usize,
        bbox: [u32; 4],
        mut rejects: impl FnMut(usize) -> bool,
    ) -> TileDraw {
        if self.count() == 1 {
            return rejects(0).into();
        }
        let mut kept = KeptHizTiles::new(self);
        for k in self.under(tiling, t, bbox) {
            kept.add(k, rejects(k));
        }
        kept.draw(tiling, t)
    }
}

/// The HiZ tiles of one (raster tile, triangle) pair that keep the triangle, gathered into
/// what the draw loop rasterizes ([`TileDraw`]).
#[derive(Debug)]
struct KeptHizTiles {
    grid: HizGrid,
    /// The first and the last HiZ tile, in both directions, of those that keep the triangle:
    /// `[kx0, ky0, kx1, ky1]` in HiZ tiles.
    kept: Option<[u32; 4]>,
    /// Whether some HiZ tile rejected it.
    rejected_some: bool,
}

impl KeptHizTiles {
    fn new(grid: HizGrid) -> Self {
        KeptHizTiles {
            grid,
            kept: None,
            rejected_some: false,
        }
    }

    /// Add HiZ tile `k`, which `rejected` the triangle or kept it.
    fn add(&mut self, k: usize, rejected: bool) {
        if rejected {
            self.rejected_some = true;
            return;
        }
        let (kx, ky) = self.grid.coords(k);
        self.kept = Some(match self.kept {
            None => [kx, ky, kx, ky],
            Some([x0, y0, x1, y1]) => [x0.min(kx), y0.min(ky), x1.max(kx), y1.max(ky)],
        });
    }

    /// Nothing when every HiZ tile rejected the triangle, the whole tile when none did, else
    /// the smallest rectangle of tile `t` of `tiling` holding those that kept it.
    fn draw(self, tiling: &Tiling, t: usize) -> TileDraw {
        match self.kept {
            None => TileDraw::Skip,
            Some(_) if !self.rejected_some => TileDraw::Whole,
            Some([x0, y0, x1, y1]) => {
                let at = |kx: u32, ky: u32| self.grid.rect(tiling, t, self.grid.index_of(kx, ky));
                TileDraw::Within(at(x0, y0).union(&at(x1, y1)))
            }
        }
    }
}

impl DepthTile {
    /// A tile of `len` samples (a square power of two) cleared to depth 1.0, one HiZ tile.
    pub fn cleared(format: DepthFormat, len: usize) -> Self {
        Self::cleared_to(format, 1.0, len)
    }

    /// A tile of `len` samples cleared to window depth `z_w` (`glClearDepth`, quantized as a
    /// fragment's depth is), one HiZ tile.
    pub fn cleared_to(format: DepthFormat, z_w: f32, len: usize) -> Self {
        let z = format.quantize(z_w);
        let tile_shift = len.trailing_zeros() / 2;
        Self {
            format,
            values: vec![z; len],
            hiz: vec![HizBounds::uniform(format, z, len as u32)],
            coarse: HizBounds::uniform(format, z, len as u32),
            grid: HizGrid {
                tile_shift,
                hiz_shift: tile_shift,
            },
        }
    }

    /// Tile `t` of `tiling` cleared to depth 1.0, with HiZ tiles of edge `hiz_tile` (taken as
    /// the raster tile's edge when larger, [`crate::frame::GpuSettings::hiz_tile_size`]) and
    /// their bounds over their pixels inside the image (what [`DepthTile::build_hiz`] would
    /// give, without reading it): the start of a pass with early Z
    /// ([`DepthTile::early_z`]).
    pub fn cleared_in(format: DepthFormat, tiling: &Tiling, t: usize, hiz_tile: u32) -> Self {
        let mut tile = Self::cleared(format, tiling.tile_len());
        tile.grid.hiz_shift = hiz_tile.min(tiling.tile).trailing_zeros();
        let (z, grid) = (tile.values[0], tile.grid);
        tile.hiz = (0..grid.count())
            .map(|k| HizBounds::uniform(format, z, grid.rect(tiling, t, k).area()))
            .collect();
        tile.coarse = HizBounds::uniform(format, z, tiling.rect(t).area());
        tile
    }

    /// The bounds of the whole raster tile: the coarse level, the union of its HiZ tiles'
    /// (those holding samples), as of the last [`DepthTile::build_hiz`] or
    /// [`DepthTile::finish_hiz`] — for a test made per raster tile (`pw-restructured`, Paper
    /// II §4).
    pub fn tile_bounds(&self) -> HizBounds {
        self.coarse
    }

    /// The union of the bounds of the HiZ tiles of tile `t` of `tiling` that hold samples.
    fn union_of_hiz_tiles(&self, tiling: &Tiling, t: usize) -> HizBounds {
        let union = |a: HizBounds, b: HizBounds| {
            let lo = if a.zmin <= b.zmin { a } else { b };
            let hi = if a.zmax >= b.zmax { a } else { b };
            HizBounds {
                zmin: lo.zmin,
                zmax: hi.zmax,
                behind_from: hi.behind_from,
                in_front_below: lo.in_front_below,
                at_zmax: [a, b]
                    .iter()
                    .filter(|x| x.zmax == hi.zmax)
                    .map(|x| x.at_zmax)
                    .sum(),
            }
        };
        let r = tiling.rect(t);
        let holding = self.grid.under(tiling, t, [r.x0, r.y0, r.x1 - 1, r.y1 - 1]);
        holding
            .map(|k| self.hiz[k])
            .reduce(union)
            .unwrap_or(self.hiz[0])
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

    /// Compute each HiZ tile's zmin/zmax over its pixels inside the image of tile `t`, with
    /// both thresholds and the coarse level, by a full reduction (Paper II §4's bounds: the
    /// scene depth is final after the scene pass; wedges and shadow volumes never write
    /// depth). The pipeline does not call it: the scene pass keeps the bounds as it writes and
    /// [`DepthTile::finish_hiz`] completes them, unit-tested equal to this. It gives bounds to
    /// depth values written directly (tests).
    pub fn build_hiz(&mut self, tiling: &Tiling, t: usize) {
        for k in 0..self.grid.count() {
            if !self.grid.rect(tiling, t, k).is_empty() {
                self.hiz[k].zmin = self.scan(tiling, t, k);
                self.hiz[k].in_front_below = self.format.first_quantized_at_least(self.hiz[k].zmin);
            }
        }
        self.coarse = self.union_of_hiz_tiles(tiling, t);
    }

    /// Set HiZ tile `k`'s zmax to the largest stored value over its pixels inside the image
    /// of tile `t`, with the count of those holding it and its threshold (uncounted: the
    /// unit's own reduction); returns the smallest.
    fn scan(&mut self, tiling: &Tiling, t: usize, k: usize) -> u32 {
        let r = self.grid.rect(tiling, t, k);
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
        let b = &mut self.hiz[k];
        b.at_zmax = at_hi.sum();
        if hi != b.zmax {
            b.zmax = hi;
            b.behind_from = self.format.first_quantized_at_least(hi);
        }
        lo
    }

    /// Early Z, in a pass that tests `Less` and writes depth into tiles started with
    /// [`DepthTile::cleared_in`] (module [`super::hiz`], "Early Z"), asked before each
    /// triangle the pass draws in tile `t` of `tiling`: where in the tile a triangle with
    /// pixel box `bbox`, whose fragment depths are all `near` or more (the depths it is tested
    /// with), may pass the test at some sample. A HiZ tile under the box rejects it when it is
    /// at or behind every sample there — what [`HizBounds::depth_outcome`] decides as
    /// `Some(false)` for `Less` — and the triangle is drawn only over the HiZ tiles that keep
    /// it ([`TileDraw`]).
    ///
    /// The writes keep zmin exact and zmax an upper bound with the count of the samples that
    /// hold it ([`DepthTile::test_and_write`]). When a HiZ tile's zmax does not reject the
    /// triangle but no sample holds it any more, it is made exact again by a reduction over
    /// the HiZ tile — unless the triangle is in front of every sample (quantized `near` below
    /// zmin), which no bound could reject. Each zmax read (one value per HiZ tile) and a
    /// rejection of the whole pair are counted in `c`; the reduction is not, as
    /// [`DepthTile::build_hiz`]'s is not.
    pub fn early_z(
        &mut self,
        tiling: &Tiling,
        t: usize,
        bbox: [u32; 4],
        near: f32,
        c: &mut Counters,
    ) -> TileDraw {
        let draw = self.grid.draw(tiling, t, bbox, |k| {
            count!(c.hiz_read_bytes += self.format.bytes());
            let b = self.hiz[k];
            let rescan = b.at_zmax == 0 && self.format.quantize(near) >= b.zmin;
            b.behind(near) || {
                if rescan {
                    self.scan(tiling, t, k);
                }
                rescan && self.hiz[k].behind(near)
            }
        });
        count!(c.tiles_culled_hiz += (draw == TileDraw::Skip) as u64);
        draw
    }

    /// The end of a pass with early Z ([`DepthTile::early_z`]) on tile `t` of
    /// `tiling`: each HiZ tile's zmax made exact where no sample holds it any more, and both
    /// thresholds computed — what [`DepthTile::build_hiz`] gives.
    pub fn finish_hiz(&mut self, tiling: &Tiling, t: usize) {
        for k in 0..self.grid.count() {
            if self.grid.rect(tiling, t, k).is_empty() {
                continue;
            }
            if self.hiz[k].at_zmax == 0 {
                self.scan(tiling, t, k);
            }
            self.hiz[k].in_front_below = self.format.first_quantized_at_least(self.hiz[k].zmin);
        }
        self.coarse = self.union_of_hiz_tiles(tiling, t);
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
    /// passed. A write under `Less` keeps its HiZ tile's bounds: zmin exact, zmax an upper
    /// bound with the count of the samples holding it ([`DepthTile::early_z`]).
    #[inline]
    pub fn test_and_write(&mut self, state: &DepthState, f: &Fragment, c: &mut Counters) -> bool {
        let (pass, z, stored) = self.test_read(state, f, c);
        if pass {
            count!(c.depth_passed += 1);
            if state.write {
                if state.func == DepthFunc::Less {
                    // z < stored ≤ zmax: the sample no longer holds zmax if it did.
                    let k = self.grid.index(f.local);
                    let b = &mut self.hiz[k];
                    b.zmin = b.zmin.min(z);
                    b.at_zmax -= (stored == b.zmax) as u32;
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

    /// Where in tile `t` of `tiling` a fragment of `tri` may have a depth-test outcome under
    /// `func` other than `idle` (the outcome on which the pass's fragments do nothing): the
    /// HiZ tiles under its box whose bounds decide `idle` for every fragment
    /// ([`HizBounds::depth_outcome`]) reject it, and it is drawn only over the others
    /// ([`TileDraw`]). Where the raster tile holds several HiZ tiles, the coarse level
    /// ([`DepthTile::tile_bounds`]) is read first and a pair it rejects is skipped; otherwise
    /// every HiZ tile under the box is read. Each read (two values,
    /// [`DepthTile::hiz_read_bytes`]) is counted in `c`.
    pub fn hiz_draw(
        &self,
        tiling: &Tiling,
        t: usize,
        (func, idle): (DepthFunc, bool),
        tri: &RasterTriangle,
        c: &mut Counters,
    ) -> TileDraw {
        // The coarse level first, where the raster tile holds several HiZ tiles: a pair it
        // rejects, every HiZ tile would (their bounds lie inside it), for one read.
        if self.grid.count() > 1 {
            count!(c.hiz_read_bytes += self.hiz_read_bytes());
            if self.coarse.depth_outcome(func, tri) == Some(idle) {
                return TileDraw::Skip;
            }
        }
        self.grid.draw(tiling, t, tri.bbox, |k| {
            count!(c.hiz_read_bytes += self.hiz_read_bytes());
            self.hiz[k].depth_outcome(func, tri) == Some(idle)
        })
    }

    /// Bytes one hierarchical-Z read of a HiZ tile's zmin and zmax costs (two values in the
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A 21×13 image (tiles cut by both borders) with pseudo-random D24 depths: each tile
    /// started with [`DepthTile::cleared_in`] and its pixels written, for HiZ tiles of edge
    /// `hiz` inside 8×8 raster tiles.
    fn filled(hiz: u32) -> (Tiling, Vec<DepthTile>) {
        let tiling = Tiling::new(21, 13, 8).unwrap();
        let mut state = 0x2545_f491_u32;
        let mut tiles = alloc_tiles(&tiling, |t, _| {
            DepthTile::cleared_in(DepthFormat::D24, &tiling, t, hiz)
        });
        for y in 0..tiling.height {
            for x in 0..tiling.width {
                state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                tiles[tiling.tile_of(x, y)].values[tiling.local(x, y)] = state >> 8;
            }
        }
        for (t, tile) in tiles.iter_mut().enumerate() {
            tile.build_hiz(&tiling, t);
        }
        (tiling, tiles)
    }

    /// The HiZ tile of pixel (x, y) of tile `t`, from the geometry alone.
    fn hiz_tile_of(tiling: &Tiling, t: usize, hiz: u32, (x, y): (u32, u32)) -> usize {
        let r = tiling.rect(t);
        (((y - r.y0) / hiz) * (tiling.tile / hiz) + (x - r.x0) / hiz) as usize
    }

    /// Every HiZ tile's zmin and zmax are the smallest and largest depth of the image pixels
    /// it covers, the tile's bounds are their union, and a write finds its HiZ tile.
    #[test]
    fn hiz_tiles_hold_the_extremes_of_their_pixels() {
        for hiz in [2, 4, 8, 16] {
            let (tiling, tiles) = filled(hiz);
            let edge = hiz.min(tiling.tile);
            for (t, tile) in tiles.iter().enumerate() {
                let r = tiling.rect(t);
                let mut want = vec![None; tile.grid.count()];
                for y in r.y0..r.y1 {
                    for x in r.x0..r.x1 {
                        let k = hiz_tile_of(&tiling, t, edge, (x, y));
                        assert_eq!(tile.grid.index(tiling.local(x, y)), k);
                        let v = tile.values[tiling.local(x, y)];
                        let [lo, hi] = want[k].unwrap_or([v, v]);
                        want[k] = Some([lo.min(v), hi.max(v)]);
                    }
                }
                for (k, w) in want.iter().enumerate() {
                    assert_eq!(w.is_none(), tile.grid.rect(&tiling, t, k).is_empty());
                    if let Some([lo, hi]) = *w {
                        let b = tile.hiz[k];
                        assert_eq!([b.zmin, b.zmax], [lo, hi], "hiz {hiz}, tile {t}, {k}");
                    }
                }
                let all = want.iter().flatten();
                let lo = all.clone().map(|w| w[0]).min().unwrap();
                let hi = all.map(|w| w[1]).max().unwrap();
                let union = tile.tile_bounds();
                assert_eq!([union.zmin, union.zmax], [lo, hi], "hiz {hiz}, tile {t}");
            }
        }
    }

    /// The HiZ tiles under a pixel box are those holding a pixel of the box in the tile.
    #[test]
    fn hiz_under_lists_the_hiz_tiles_a_box_overlaps() {
        for hiz in [2, 4, 8] {
            let (tiling, tiles) = filled(hiz);
            for bbox in [[0, 0, 20, 12], [3, 2, 9, 5], [7, 7, 8, 8], [17, 9, 20, 12]] {
                for (t, tile) in tiles.iter().enumerate() {
                    let r = tiling.rect(t);
                    let mut want: Vec<usize> = (bbox[1].max(r.y0)..=bbox[3].min(r.y1 - 1))
                        .flat_map(|y| {
                            (bbox[0].max(r.x0)..=bbox[2].min(r.x1 - 1))
                                .map(move |x| hiz_tile_of(&tiling, t, hiz, (x, y)))
                        })
                        .collect();
                    want.sort();
                    want.dedup();
                    if want.is_empty() {
                        continue; // the box misses the tile: no triangle of it is drawn there
                    }
                    let got: Vec<usize> = tile.grid.under(&tiling, t, bbox).collect();
                    assert_eq!(got, want, "hiz {hiz}, box {bbox:?}, tile {t}");
                }
            }
        }
    }
}
