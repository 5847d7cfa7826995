//! The hierarchical-Z unit (`[options.gpu] hiz = on|off`, `docs/architecture.md`
//! "Hierarchical Z"): what a pass may learn about a whole screen tile before it rasterizes a
//! triangle there, so that it can reject the (tile, triangle) pair when no fragment of the
//! triangle could change any buffer in that tile. Rejection never changes an output bit; it
//! only removes work, which the counters show (`tiles_culled_hiz`, fewer fragments and depth
//! reads) and prices (`hiz_read_bytes`).
//!
//! Two kinds of per-tile bounds:
//! * **zmin/zmax of the scene depth**, per HiZ tile ([`HizBounds`](super::buffers::HizBounds),
//!   [`HizBounds::depth_outcome`](super::buffers::HizBounds::depth_outcome)): when the
//!   triangle's depth range lies wholly on one side of the bounds of every HiZ tile under it,
//!   every fragment has the same depth-test outcome, and a pass whose fragments do nothing on
//!   that outcome skips the tile (the hardware's hierarchical Z, Paper II §4 for Paper I's
//!   passes).
//! * **Receiver bounds** ([`TileReceiverBounds`]): the box of the receiver points the tile's
//!   fragment programs read (the world position a wedge's inside test and coverage take). A
//!   wedge whose inside test fails at every point of that box — one of its planes rejects the
//!   box ([`plane_rejects_box`]), in the fragment program's own arithmetic — shades nothing
//!   there. This is the same reduction as zmin/zmax, taken over the position buffer instead of
//!   the depth buffer (Paper IV §4.2 keeps positions in a texture); a tile without receivers
//!   (all background) rejects every wedge. A coarse level over blocks of [`BLOCK_TILES`]²
//!   tiles is read first ([`TileReceiverBounds::kept_tiles`]).
//!
//! **HiZ tiles** (`[options.gpu] hiz-tile-size`, default 8×8): the square one zmin/zmax
//! covers, independent of the raster tile but at most it — each raster tile holds its HiZ
//! tiles and keeps their bounds as it writes depth, in parallel with the other tiles. Each
//! HiZ tile a triangle's pixel box overlaps in a raster tile
//! ([`DepthTile::hiz_draw`](super::buffers::DepthTile::hiz_draw)) is read, counted, and
//! rejects the triangle or keeps it; the pair is rasterized over the rectangle of those
//! that keep it ([`TileDraw`](super::raster::TileDraw)), skipped when none does.
//!
//! **Early Z** ([`DepthTile::early_z`](super::buffers::DepthTile::early_z)):
//! in the scene pass, which writes depth under LESS, the same zmax rejects a triangle at or
//! behind it before traversal; the writes keep the bounds as they lower the depths
//! (`docs/architecture.md`, "Hierarchical Z").
//!
//! The receiver box is used rather than the tile's frustum between zmin and zmax because the
//! receiver points are not always on the depth buffer's surface (`Frame::receivers` moves a
//! point onto its triangle's plane where the depth format cannot hold it, and `ssv-optimized`
//! may round positions to binary16): the box of the points actually read is the bound that
//! holds for every fragment.

use super::counters::{count, Counters};
use super::shader_float::FloatFormat;
use super::tiling::Tiling;
use glam::DVec3;
use rayon::prelude::*;

/// The probe's note for a triangle the zmin/zmax test rejected for the probed pixel's tile
/// (`Frame::hiz_depth_draw`).
pub const HIZ_CULLED: &str =
    "culled for the tile by the hierarchical Z (zmin/zmax): no fragment could change a buffer";

/// Per screen tile, the axis-aligned box of the receiver points its fragment programs read
/// (module doc), `None` for a tile with no receiver; and the same per block of
/// [`BLOCK_TILES`]² tiles, the union of its tiles' boxes: the coarse level of a two-level
/// pyramid, which [`TileReceiverBounds::kept_tiles`] reads first.
#[derive(Debug, Clone, PartialEq)]
pub struct TileReceiverBounds {
    boxes: Vec<Option<[DVec3; 2]>>,
    blocks: Vec<Option<[DVec3; 2]>>,
    tiles_x: u32,
    blocks_x: u32,
}

/// Tiles per side of a block of [`TileReceiverBounds`]' coarse level (4×4 tiles, 32×32
/// pixels with the default 8×8 tile).
pub const BLOCK_TILES: u32 = 4;

/// The index of the block holding tile `(tx, ty)` in a row of `blocks_x` blocks.
fn block_index(blocks_x: u32, tx: u32, ty: u32) -> usize {
    ((ty / BLOCK_TILES) * blocks_x + tx / BLOCK_TILES) as usize
}

/// The union of two optional boxes.
fn union(a: Option<[DVec3; 2]>, b: Option<[DVec3; 2]>) -> Option<[DVec3; 2]> {
    match (a, b) {
        (Some([lo, hi]), Some([l, h])) => Some([lo.min(l), hi.max(h)]),
        (a, None) => a,
        (None, b) => b,
    }
}

impl TileReceiverBounds {
    /// Bytes one read of a tile's (or a block's) bounds costs: six f32 (the receiver points
    /// are f32 or narrower).
    pub const READ_BYTES: u64 = 24;

    /// The bounds of the points `point(x, y)` (the receiver of pixel (x, y), `None` for
    /// background) over every tile of `tiling`, and over its blocks.
    pub fn new(tiling: &Tiling, point: impl Fn(u32, u32) -> Option<DVec3> + Sync) -> Self {
        let boxes: Vec<Option<[DVec3; 2]>> = (0..tiling.tile_count())
            .into_par_iter()
            .map(|t| {
                let r = tiling.rect(t);
                let mut bounds = None;
                for y in r.y0..r.y1 {
                    for x in r.x0..r.x1 {
                        bounds = union(bounds, point(x, y).map(|p| [p, p]));
                    }
                }
                bounds
            })
            .collect();
        let blocks_x = tiling.tiles_x.div_ceil(BLOCK_TILES);
        let mut blocks = vec![None; (blocks_x * tiling.tiles_y.div_ceil(BLOCK_TILES)) as usize];
        for (t, b) in boxes.iter().enumerate() {
            let k = block_index(
                blocks_x,
                t as u32 % tiling.tiles_x,
                t as u32 / tiling.tiles_x,
            );
            blocks[k] = union(blocks[k], *b);
        }
        TileReceiverBounds {
            boxes,
            blocks,
            tiles_x: tiling.tiles_x,
            blocks_x,
        }
    }

    /// The box `[lo, hi]` of tile `t`'s receivers, `None` when it has none.
    pub fn tile(&self, t: usize) -> Option<[DVec3; 2]> {
        self.boxes[t]
    }

    /// The tiles of the rectangle of tiles `[tx0, tx1] × [ty0, ty1]` (inclusive) where a
    /// primitive whose inside test `rejects` a box may shade a receiver, in increasing index:
    /// each block the rectangle meets is read once and, where its box is rejected or empty,
    /// so are all its tiles; otherwise each of its tiles in the rectangle is read and kept
    /// unless its own box is rejected or empty. A tile inside a rejected block's box would be
    /// rejected by itself too when `rejects` is monotone (a box rejected has every box inside
    /// it rejected, as [`plane_rejects_box`]'s are): the kept tiles are those a per-tile test
    /// keeps, found with fewer reads. Each read is counted in `c`
    /// ([`TileReceiverBounds::READ_BYTES`]).
    pub fn kept_tiles(
        &self,
        [tx0, ty0, tx1, ty1]: [u32; 4],
        rejects: impl Fn([DVec3; 2]) -> bool,
        c: &mut Counters,
    ) -> Vec<u32> {
        let (bx0, bx1) = (tx0 / BLOCK_TILES, tx1 / BLOCK_TILES);
        let mut block_kept = vec![false; (bx1 - bx0 + 1) as usize];
        let mut kept = Vec::new();
        for ty in ty0..=ty1 {
            if ty == ty0 || ty % BLOCK_TILES == 0 {
                for (bx, k) in (bx0..=bx1).zip(&mut block_kept) {
                    count!(c.hiz_read_bytes += Self::READ_BYTES);
                    *k = self.blocks[block_index(self.blocks_x, bx * BLOCK_TILES, ty)]
                        .is_some_and(|b| !rejects(b));
                }
            }
            for tx in tx0..=tx1 {
                if !block_kept[(tx / BLOCK_TILES - bx0) as usize] {
                    continue;
                }
                let t = ty * self.tiles_x + tx;
                count!(c.hiz_read_bytes += Self::READ_BYTES);
                if self.boxes[t as usize].is_some_and(|b| !rejects(b)) {
                    kept.push(t);
                }
            }
        }
        kept
    }
}

/// The rounding margin [`plane_rejects_box`] allows for a fragment program's inside test in
/// one format, computed once per pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InsideTestRounding {
    /// Bound on the relative error of the evaluation, times its terms' size:
    /// `8·(u + 2⁻⁵³)`.
    relative: f64,
    /// Bound on its absolute error from flushed or denormal results: `16·min_normal`.
    absolute: f64,
    /// Terms' size from which the program could overflow: `max_finite / 16`.
    limit: f64,
}

impl InsideTestRounding {
    /// The margin for programs computing in `format`.
    pub fn new(format: FloatFormat) -> Self {
        let u = libm::ldexp(1.0, -(format.mantissa_bits + 1));
        InsideTestRounding {
            relative: 8.0 * (u + libm::ldexp(1.0, -53)),
            absolute: 16.0 * format.min_normal(),
            limit: format.max_finite() / 16.0,
        }
    }
}

/// Whether the inside test `normal·(p − origin) ≥ 0`, evaluated by a fragment program in the
/// format of `rounding` (inputs rounded to it, every operation rounded:
/// [`super::shader_float`]), fails at every point `p` of the box `[lo, hi]`.
///
/// Conservative: the largest exact value over the box (at its corner furthest along the
/// normal) must be below minus a bound on the rounding of the evaluation, `8·(u + 2⁻⁵³)·S +
/// 16·min_normal` with `u` the format's unit roundoff and `S = Σ|nᵢ|·(max(|loᵢ|, |hiᵢ|) +
/// |originᵢ|)` — the evaluation rounds p, origin, normal, the difference, the product and two
/// sums, at most 5 relative errors per term (γ₅ < 8u), plus the same for the f64 evaluation
/// here, plus a flushed or denormal result per operation. Where `S` comes near the format's
/// largest finite value (the program could overflow), it never rejects.
pub fn plane_rejects_box(
    normal: DVec3,
    origin: DVec3,
    [lo, hi]: [DVec3; 2],
    rounding: &InsideTestRounding,
) -> bool {
    let far = DVec3::select(normal.cmpge(DVec3::ZERO), hi, lo);
    let largest = normal.dot(far - origin);
    let scale = normal.abs().dot(lo.abs().max(hi.abs()) + origin.abs());
    if scale.is_nan() || scale >= rounding.limit {
        return false;
    }
    largest + rounding.relative * scale + rounding.absolute < 0.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::shader_float::{Fp16, Fp24, Fp32};
    use crate::gpu::shader_float::{ShaderFloat, F64, FP16, FP24, FP32};
    use crate::gpu::shader_vec::SVec3;

    /// An inside test `(normal, origin, p)` in some precision.
    type InsideTest = fn(DVec3, DVec3, DVec3) -> bool;

    /// The inside test as the fragment programs compute it, in `T`.
    fn inside<T: ShaderFloat>(n: DVec3, o: DVec3, p: DVec3) -> bool {
        SVec3::<T>::from_f64(n).dot(SVec3::from_f64(p) - SVec3::from_f64(o)) >= T::zero()
    }

    /// A box the plane rejects is one where every point fails the shader's own test: checked
    /// on a grid of points of boxes placed just beyond the plane, at every precision, and a
    /// box straddling the plane is never rejected.
    #[test]
    fn a_rejected_box_fails_the_shader_test_everywhere() {
        let n = DVec3::new(0.48, -0.6, 0.64);
        let o = DVec3::new(3.25, -1.5, 7.0);
        let mut rejected = [0; 4];
        for k in 0..200 {
            let gap = 1e-6 * libm::pow(1.2, k as f64);
            let lo = o - n * (gap + 0.5) - DVec3::splat(0.25);
            let hi = o - n * (gap + 0.5) + DVec3::splat(0.25);
            // The box's farthest corner along n is 0.25·Σ|nᵢ| = 0.43 past its center.
            let cases: [(FloatFormat, InsideTest); 4] = [
                (F64, inside::<f64>),
                (FP32, inside::<Fp32>),
                (FP24, inside::<Fp24>),
                (FP16, inside::<Fp16>),
            ];
            for (j, (format, test)) in cases.into_iter().enumerate() {
                if !plane_rejects_box(n, o, [lo, hi], &InsideTestRounding::new(format)) {
                    continue;
                }
                rejected[j] += 1;
                for i in 0..=4 {
                    for jj in 0..=4 {
                        for kk in 0..=4 {
                            let f = DVec3::new(i as f64, jj as f64, kk as f64) / 4.0;
                            let p = lo + (hi - lo) * f;
                            assert!(!test(n, o, p), "{format:?}: {p} inside, gap {gap}");
                        }
                    }
                }
            }
            let straddling = [o - DVec3::splat(0.01), o + DVec3::splat(0.01)];
            for format in [FP16, F64] {
                let r = InsideTestRounding::new(format);
                assert!(!plane_rejects_box(n, o, straddling, &r));
            }
        }
        // Every precision rejects the far boxes, and the wider formats reject nearer ones.
        assert!(rejected.iter().all(|&r| r > 0), "{rejected:?}");
        assert!(
            rejected[0] >= rejected[1] && rejected[1] >= rejected[2] && rejected[2] >= rejected[3]
        );
    }

    /// The margin is the documented bound, `8·(u + 2⁻⁵³)·S + 16·min_normal`, no more and no
    /// less. Binary16 (u = 2⁻¹¹, min_normal = 2⁻¹⁴) with `S = 2`: the normal (1, 1, 0)
    /// through (0, q, 0) and a one-point box at (−g, q, 0) give `largest = −g` and
    /// `S = g + 2q`; with `g = 2·(2⁻⁸ + 2⁻⁵⁰) + 2⁻¹⁰` and `2q = 2 − g` (both exact in f64) the
    /// sum is exactly 0, which does not reject (the test is strict), and a relative change of
    /// g by ±2⁻³⁰ crosses the bound.
    #[test]
    fn the_margin_is_the_documented_bound() {
        let rounding = InsideTestRounding::new(FP16);
        let n = DVec3::new(1.0, 1.0, 0.0);
        let rejects_at = |g: f64| {
            let q = (2.0 - g) / 2.0;
            let p = DVec3::new(-g, q, 0.0);
            plane_rejects_box(n, DVec3::new(0.0, q, 0.0), [p, p], &rounding)
        };
        let g = 2.0 * (libm::ldexp(1.0, -8) + libm::ldexp(1.0, -50)) + libm::ldexp(1.0, -10);
        assert_eq!((2.0 - g) / 2.0 * 2.0 + g, 2.0);
        assert!(!rejects_at(g), "the bound itself is kept");
        assert!(!rejects_at(g * (1.0 - libm::ldexp(1.0, -30))));
        assert!(rejects_at(g * (1.0 + libm::ldexp(1.0, -30))));
    }

    /// Beyond the format's range the program may overflow: never rejected.
    #[test]
    fn boxes_beyond_the_format_range_are_kept() {
        let n = DVec3::X;
        let far = [DVec3::new(-1e6, 0.0, 0.0), DVec3::new(-9e5, 1.0, 1.0)];
        let at = |format| plane_rejects_box(n, DVec3::ZERO, far, &InsideTestRounding::new(format));
        assert!(!at(FP16));
        assert!(at(FP32));
    }

    /// The two-level decision keeps exactly the tiles the per-tile test keeps, in increasing
    /// order, and reads fewer bounds where whole blocks are rejected.
    #[test]
    fn kept_tiles_are_the_tiles_the_per_tile_test_keeps() {
        let tiling = Tiling::new(100, 72, 8).unwrap();
        // Receivers on a tilted floor, none in a hole.
        let b = TileReceiverBounds::new(&tiling, |x, y| {
            let hole = (30..50).contains(&x) && (10..40).contains(&y);
            (!hole).then(|| DVec3::new(x as f64, 0.1 * y as f64, y as f64))
        });
        let rounding = InsideTestRounding::new(FP32);
        for (n, o) in [
            (DVec3::new(1.0, 0.0, 0.0), DVec3::new(60.5, 0.0, 0.0)),
            (DVec3::new(-0.6, 0.0, 0.8), DVec3::new(20.0, 0.0, 30.0)),
            (DVec3::new(0.0, 1.0, 0.0), DVec3::new(0.0, -1.0, 0.0)),
        ] {
            let rejects = |bx: [DVec3; 2]| plane_rejects_box(n, o, bx, &rounding);
            for rect in [[0, 0, 12, 8], [3, 1, 9, 6], [5, 5, 5, 5]] {
                let [tx0, ty0, tx1, ty1] = rect;
                let mut c = Counters::default();
                let kept = b.kept_tiles(rect, rejects, &mut c);
                let want: Vec<u32> = (0..tiling.tile_count() as u32)
                    .filter(|&t| {
                        let (tx, ty) = (t % tiling.tiles_x, t / tiling.tiles_x);
                        (tx0..=tx1).contains(&tx) && (ty0..=ty1).contains(&ty)
                    })
                    .filter(|&t| b.tile(t as usize).is_some_and(|bx| !rejects(bx)))
                    .collect();
                assert_eq!(kept, want, "plane {n} through {o}, tiles {rect:?}");
                let tiles_in_rect = ((tx1 - tx0 + 1) * (ty1 - ty0 + 1)) as u64;
                let per_tile = tiles_in_rect * TileReceiverBounds::READ_BYTES;
                if rect == [0, 0, 12, 8] && n.x == 1.0 {
                    assert!(c.hiz_read_bytes < per_tile, "{} reads", c.hiz_read_bytes);
                }
            }
        }
    }

    /// Each block holds its own 4×4 tiles and no others: with receivers at their pixel's
    /// (x, y) and the plane y = 40 (inside above it), the tile rows 0–4 (pixels 0–39) are
    /// rejected, so the first block row (tile rows 0–3) is rejected as a whole and its tiles
    /// are never read. Reads, by hand, on the 13×9 tiles of 100×72 pixels: 4 blocks at each
    /// of the tile rows 0, 4 and 8, and the 13 tiles of each of the rows 4–8.
    #[test]
    fn a_rejected_block_row_costs_one_read_per_block() {
        let tiling = Tiling::new(100, 72, 8).unwrap();
        let b = TileReceiverBounds::new(&tiling, |x, y| Some(DVec3::new(x as f64, y as f64, 0.0)));
        let rounding = InsideTestRounding::new(FP32);
        let rejects = |bx| plane_rejects_box(DVec3::Y, DVec3::new(0.0, 40.0, 0.0), bx, &rounding);
        let mut c = Counters::default();
        let kept = b.kept_tiles([0, 0, 12, 8], rejects, &mut c);
        assert_eq!(kept, (5 * 13..9 * 13).collect::<Vec<u32>>());
        assert_eq!(
            c.hiz_read_bytes,
            (3 * 4 + 5 * 13) * TileReceiverBounds::READ_BYTES
        );
    }

    #[test]
    fn bounds_cover_the_tile_receivers_and_skip_empty_tiles() {
        let tiling = Tiling::new(12, 8, 8).unwrap();
        let b = TileReceiverBounds::new(&tiling, |x, y| {
            (x < 8 && (x + y) % 3 == 0).then(|| DVec3::new(x as f64, -(y as f64), 1.0))
        });
        // Tile 0 holds x, y ∈ 0..8; (7, 5) and (6, 6) are its receivers with the largest x, y.
        assert_eq!(
            b.tile(0),
            Some([DVec3::new(0.0, -7.0, 1.0), DVec3::new(7.0, 0.0, 1.0)])
        );
        assert_eq!(b.tile(1), None);
    }
}
