//! Binning and tile traversal (after Mesa's `lp_rast_tri.c`), and the parallel draw loop.
//!
//! Triangles are binned to the tiles they may cover ([`touched_tiles`]: the tiles of their
//! bounding box that no edge function trivially rejects), in submission order. Tiles run
//! in parallel (rayon); inside a tile, triangles are processed strictly in submission order and
//! samples in row-major order, so every buffer's final bits are independent of the number of
//! threads. Per tile, each edge function is evaluated at the tile's four corner samples: a
//! tile outside one edge is skipped, a tile inside all three is filled without per-sample
//! tests (edge functions are linear, so corners bound the whole tile).

use super::counters::{count, Counters};
use super::probe::{PassProbe, Tap};
use super::setup::RasterTriangle;
use super::tiling::{TileRect, Tiling};
use rayon::prelude::*;

/// One covered sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fragment {
    /// Pixel column.
    pub x: u32,
    /// Pixel row (0 at the top).
    pub y: u32,
    /// Index of the pixel inside its tile's storage.
    pub local: usize,
    /// Interpolated window depth (f32, unclamped).
    pub z: f32,
}

/// What a pass's tile test (`skip_tile` of [`draw`]) lets the draw loop rasterize of a
/// (tile, triangle) pair. A test returning `bool` means [`TileDraw::Skip`] for `true` and
/// [`TileDraw::Whole`] for `false`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TileDraw {
    /// Nothing: no fragment of the triangle in the tile could change a buffer.
    Skip,
    /// The whole tile.
    Whole,
    /// Only this rectangle of the tile (the hierarchical-Z tiles that did not reject the
    /// triangle, [`super::hiz`]): no fragment outside it could change a buffer.
    Within(TileRect),
}

impl From<bool> for TileDraw {
    fn from(skip: bool) -> Self {
        if skip {
            TileDraw::Skip
        } else {
            TileDraw::Whole
        }
    }
}

/// Per-tile lists of triangle indices, in submission order, stored one after the other
/// (compressed rows: tile t's list is `indices[starts[t]..starts[t + 1]]`), so that binning
/// makes two allocations however many tiles and triangles there are.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Bins {
    /// Where each tile's list starts in `indices`, with the total length appended.
    starts: Vec<u32>,
    /// Every tile's triangle indices, tile after tile.
    indices: Vec<u32>,
}

impl Bins {
    /// The triangles whose bounding box touches tile `t`, in submission order.
    pub fn tile(&self, t: usize) -> &[u32] {
        &self.indices[self.starts[t] as usize..self.starts[t + 1] as usize]
    }

    /// The number of (tile, triangle) pairs binned, over every tile.
    pub fn pair_count(&self) -> usize {
        self.indices.len()
    }
}

/// Tile rows one parallel binning task covers ([`bin`]).
const BIN_BAND_ROWS: u32 = 4;

/// Bin triangles to the tiles they may cover ([`touched_tiles`]): a counting sort (count per
/// tile, then place) per band of four tile rows, the bands in parallel, each scanning every
/// triangle. Concatenated in band order the lists are the same for any thread count.
pub fn bin(tiling: &Tiling, tris: &[RasterTriangle]) -> Bins {
    bin_to(tiling, tris.len(), |k, rows| {
        touched_tiles(tiling, &tris[k], rows)
    })
}

/// The tiles of the tile rows `rows` where triangle `t` may cover a sample, in increasing
/// index: in each tile row of its bounding box, the tile columns where no edge function is
/// negative at every sample (`touched_columns`). A tile it leaves out would have been
/// classified outside by [`rasterize_in_tile`], with no fragment, so binning to these tiles
/// instead of the whole bounding box changes no output bit, only the work: shadow-volume
/// quads are long slivers whose boxes span far more tiles than they touch (`ssv`'s hard quads
/// on `cube-of-spheres` 512²: 52 415 (tile, triangle) pairs where their boxes gave 491 404, and
/// the pass 10.9 → 6.5 ms with one thread; its wedge faces: 317 460 pairs, was 2 006 831).
pub fn touched_tiles<'a>(
    tiling: &'a Tiling,
    t: &'a RasterTriangle,
    rows: std::ops::Range<u32>,
) -> impl Iterator<Item = usize> + 'a {
    let [_, ty0, _, ty1] = tiling.tiles_of_box(t.bbox);
    let ty = ty0.max(rows.start)..(ty1 + 1).min(rows.end);
    ty.flat_map(move |ty| {
        touched_columns(tiling, t, ty).map(move |tx| (ty * tiling.tiles_x + tx) as usize)
    })
}

/// Whether triangle `t` may cover a sample of tile `tile` ([`touched_tiles`]): the same test
/// as `touched_columns`, each edge evaluated at the tile's corner where it is largest, with
/// no division (unit-tested equal).
pub fn touches_tile(tiling: &Tiling, t: &RasterTriangle, tile: usize) -> bool {
    let (tx, ty) = (tile as u32 % tiling.tiles_x, tile as u32 / tiling.tiles_x);
    let [tx0, ty0, tx1, ty1] = tiling.tiles_of_box(t.bbox);
    if !(tx0..=tx1).contains(&tx) || !(ty0..=ty1).contains(&ty) {
        return false;
    }
    let (y0, y1) = tile_rows_in_box(tiling, t, ty);
    let x0 = (tx * tiling.tile) as i64;
    let x1 = x0 + tiling.tile as i64 - 1;
    t.edges
        .iter()
        .all(|e| (e.a * x0).max(e.a * x1) + (e.b * y0).max(e.b * y1) + e.c >= 0)
}

/// The rows of tile row `ty` inside triangle `t`'s bounding box, first and last.
fn tile_rows_in_box(tiling: &Tiling, t: &RasterTriangle, ty: u32) -> (i64, i64) {
    let [_, by0, _, by1] = t.bbox;
    let y0 = (ty * tiling.tile).max(by0) as i64;
    let y1 = ((ty + 1) * tiling.tile - 1).min(by1) as i64;
    (y0, y1)
}

/// The number of tiles triangle `t` may cover ([`touched_tiles`]).
pub fn touched_tile_count(tiling: &Tiling, t: &RasterTriangle) -> usize {
    let [_, ty0, _, ty1] = tiling.tiles_of_box(t.bbox);
    (ty0..=ty1)
        .map(|ty| touched_columns(tiling, t, ty).len())
        .sum()
}

/// The tile columns of tile row `ty`, within triangle `t`'s bounding box, where each edge
/// function is non-negative at some sample of the tile (its rows inside the box): an edge
/// `a·i + b·j + c` is largest over a tile at the tile's last column when `a > 0` and at its
/// first when `a < 0`, so each edge keeps a half-line of columns, found with two floor
/// divisions per tile row (Mesa's `lp_setup_tri.c` trivially rejects a tile by the same
/// corner). Conservative: a column kept may hold no covered sample (each edge is tested on
/// its own), which [`rasterize_in_tile`] then finds.
fn touched_columns(tiling: &Tiling, t: &RasterTriangle, ty: u32) -> std::ops::Range<u32> {
    let [tx0, _, tx1, _] = tiling.tiles_of_box(t.bbox);
    let size = tiling.tile as i64;
    // The tile edge is a power of two: a floor division by it is a shift.
    let shift = tiling.tile.trailing_zeros();
    let (mut lo, mut hi) = (tx0 as i64, tx1 as i64);
    let (y0, y1) = tile_rows_in_box(tiling, t, ty);
    for e in &t.edges {
        // The edge's largest value over the rows y0..=y1, less its column term.
        let rest = (e.b * y0).max(e.b * y1) + e.c;
        match e.a.cmp(&0) {
            // a·(tx·T + T − 1) + rest ≥ 0 ⟺ tx·T + T − 1 ≥ ⌈−rest / a⌉.
            std::cmp::Ordering::Greater => {
                let first_x = -rest.div_euclid(e.a);
                lo = lo.max(-((size - 1 - first_x) >> shift));
            }
            // a·tx·T + rest ≥ 0 ⟺ tx·T ≤ ⌊rest / −a⌋.
            std::cmp::Ordering::Less => {
                hi = hi.min(rest.div_euclid(-e.a) >> shift);
            }
            std::cmp::Ordering::Equal if rest < 0 => return 0..0,
            std::cmp::Ordering::Equal => {}
        }
    }
    if lo > hi {
        return 0..0;
    }
    lo as u32..hi as u32 + 1
}

/// Bin `count` primitives: primitive `k` goes to the tiles `tiles(k, rows)` names among the
/// tile rows `rows`, in increasing index (a primitive's bounding-box tiles for [`bin`], fewer
/// where a pass has already rejected some). The same counting sort and bands as [`bin`].
pub fn bin_to<I>(
    tiling: &Tiling,
    count: usize,
    tiles: impl Fn(usize, std::ops::Range<u32>) -> I + Sync,
) -> Bins
where
    I: Iterator<Item = usize>,
{
    let bands: Vec<(Vec<u32>, Vec<u32>)> = (0..tiling.tiles_y.div_ceil(BIN_BAND_ROWS))
        .into_par_iter()
        .map(|band| {
            let rows = band * BIN_BAND_ROWS..((band + 1) * BIN_BAND_ROWS).min(tiling.tiles_y);
            bin_band(tiling, count, |k| tiles(k, rows.clone()), rows.clone())
        })
        .collect();
    let mut starts = Vec::with_capacity(tiling.tile_count() + 1);
    let mut indices = Vec::with_capacity(bands.iter().map(|(_, i)| i.len()).sum());
    for (band_starts, band_indices) in bands {
        let base = indices.len() as u32;
        starts.extend(
            band_starts[..band_starts.len() - 1]
                .iter()
                .map(|s| base + s),
        );
        indices.extend(band_indices);
    }
    starts.push(indices.len() as u32);
    Bins { starts, indices }
}

/// The bins of the tile rows `rows`: each tile's start in the band's indices (with the band's
/// total appended), and the indices. `touched(k)` names primitive k's tiles in the band.
fn bin_band<I>(
    tiling: &Tiling,
    count: usize,
    touched: impl Fn(usize) -> I,
    rows: std::ops::Range<u32>,
) -> (Vec<u32>, Vec<u32>)
where
    I: Iterator<Item = usize>,
{
    let first = (rows.start * tiling.tiles_x) as usize;
    let tiles = ((rows.end - rows.start) * tiling.tiles_x) as usize;
    let mut starts = vec![0u32; tiles + 1];
    // The (primitive, tile) pairs, found once: `touched` costs divisions per tile row
    // (`touched_columns`), where the second pass of the sort once asked again (13 % of an
    // `nsample` frame).
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    for k in 0..count {
        for t in touched(k) {
            starts[t - first + 1] += 1;
            pairs.push((k as u32, (t - first) as u32));
        }
    }
    for k in 1..starts.len() {
        starts[k] += starts[k - 1];
    }
    let mut next = starts.clone();
    let mut indices = vec![0u32; pairs.len()];
    for (k, t) in pairs {
        indices[next[t as usize] as usize] = k;
        next[t as usize] += 1;
    }
    (starts, indices)
}

/// How a triangle relates to a tile.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TileCoverage {
    Outside,
    Partial,
    Full,
}

fn classify(t: &RasterTriangle, r: &TileRect) -> TileCoverage {
    let corners = [
        (r.x0 as i64, r.y0 as i64),
        (r.x1 as i64 - 1, r.y0 as i64),
        (r.x0 as i64, r.y1 as i64 - 1),
        (r.x1 as i64 - 1, r.y1 as i64 - 1),
    ];
    let mut full = true;
    for e in &t.edges {
        let vals = corners.map(|(i, j)| e.at(i, j));
        if vals.iter().all(|&v| v < 0) {
            return TileCoverage::Outside;
        }
        if vals.iter().any(|&v| v < 0) {
            full = false;
        }
    }
    if full {
        TileCoverage::Full
    } else {
        TileCoverage::Partial
    }
}

/// Visit the covered samples of triangle `t` inside tile rectangle `r`, in row-major order.
/// Returns (whether the tile was visited, number of fragments generated).
pub fn rasterize_in_tile(
    tiling: &Tiling,
    t: &RasterTriangle,
    r: &TileRect,
    mut visit: impl FnMut(Fragment),
) -> (bool, u64) {
    let [bx0, by0, bx1, by1] = t.bbox;
    let x0 = r.x0.max(bx0);
    let y0 = r.y0.max(by0);
    let x1 = r.x1.min(bx1 + 1);
    let y1 = r.y1.min(by1 + 1);
    let sub = TileRect { x0, y0, x1, y1 };
    if sub.is_empty() {
        return (false, 0);
    }
    let coverage = classify(t, &sub);
    if coverage == TileCoverage::Outside {
        return (true, 0);
    }
    let mut n = 0u64;
    let [e0, e1, e2] = t.edges;
    for y in y0..y1 {
        let j = y as i64;
        let mut v0 = e0.at(x0 as i64, j);
        let mut v1 = e1.at(x0 as i64, j);
        let mut v2 = e2.at(x0 as i64, j);
        for x in x0..x1 {
            if coverage == TileCoverage::Full || (v0 | v1 | v2) >= 0 {
                n += 1;
                visit(Fragment {
                    x,
                    y,
                    local: tiling.local(x, y),
                    z: t.depth_at(x, y),
                });
            }
            v0 += e0.a;
            v1 += e1.a;
            v2 += e2.a;
        }
    }
    (true, n)
}

/// Run `fragment` for every covered sample of every triangle, tiles in parallel, triangles in
/// submission order within a tile. `tiles[t]` is the method's per-tile storage for tile t.
/// `skip_tile(t, storage, tri)` may reject a (tile, triangle) pair before traversal, or limit
/// it to part of the tile ([`TileDraw`]; used for hierarchical-Z culling; count the rejection
/// in the counters it is given). It gets the
/// tile's storage mutably, so that a pass writing depth can bring the tile's bounds up to date
/// before it decides (early Z in a pass that writes depth).
/// `fragment` gets a [`Tap`] for the fragments of the samples `probe` watches
/// ([`super::probe`]) and `None` for every other one: the tile index is compared with the
/// watched tiles once per tile; only in a watched tile is each fragment's sample compared.
/// Every fragment handed to `fragment` is one fragment-program invocation whose operations
/// are counted ([`super::shader_ops::measure`]). Returns the counters summed over tiles.
pub fn draw<T, S, D, F>(
    tiling: &Tiling,
    tiles: &mut [T],
    tris: &[RasterTriangle],
    bins: &Bins,
    probe: Option<&PassProbe>,
    skip_tile: S,
    fragment: F,
) -> Counters
where
    T: Send,
    S: Fn(usize, &mut T, &RasterTriangle, &mut Counters) -> D + Sync,
    D: Into<TileDraw>,
    F: Fn(usize, &mut T, &RasterTriangle, Fragment, &mut Counters, Option<Tap>) + Sync,
{
    assert_eq!(tiles.len(), tiling.tile_count());
    tiles
        .par_iter_mut()
        .enumerate()
        // One tile per task: the work per tile is very uneven (a shadow's tiles hold most of a
        // wedge pass's fragments), and rayon's adaptive split left runs of hundreds of tiles
        // that one thread finished alone (`ssv`'s wedge draw on `cube-of-spheres` 512²: one
        // thread 100.4 ms, two threads 54.2 → 50.7 ms).
        .with_max_len(1)
        .map(|(t, storage)| {
            let mut c = Counters::default();
            let rect = tiling.rect(t);
            let watched = probe.filter(|p| p.watches_tile(t));
            for &k in bins.tile(t) {
                let tri = &tris[k as usize];
                let within = match skip_tile(t, &mut *storage, tri, &mut c).into() {
                    TileDraw::Skip => continue,
                    TileDraw::Whole => rect,
                    TileDraw::Within(part) => part,
                };
                let (visited, n) = rasterize_in_tile(tiling, tri, &within, |f| {
                    let tap = watched.and_then(|p| p.tap(t, f.local));
                    super::shader_ops::measure(&mut c, |c| fragment(t, storage, tri, f, c, tap))
                });
                count!(c.tiles_visited += visited as u64);
                count!(c.fragments_rasterized += n);
            }
            c
        })
        .reduce(Counters::default, |mut a, b| {
            a += b;
            a
        })
}

/// A `skip_tile` that never skips.
pub fn no_tile_culling<T>(_: usize, _: &mut T, _: &RasterTriangle, _: &mut Counters) -> bool {
    false
}
