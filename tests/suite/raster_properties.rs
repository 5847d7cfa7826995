//! Rasterizer properties (`docs/architecture.md` "Tests"): a quad split into two triangles covers
//! every pixel of its interior exactly once — no gaps, no double hits — for random quads, both
//! diagonals, random tile sizes, including vertices off screen and at sub-pixel positions; the
//! single-pixel coverage query agrees with the traversal; binning keeps exactly the tiles where
//! no edge function is negative at every sample, so every tile with a covered sample; the
//! hierarchical-Z unit leaves out no fragment whose depth test could change a buffer.

use penumbra::gpu::buffers::DepthTile;
use penumbra::gpu::counters::Counters;
use penumbra::gpu::depth::{DepthFormat, DepthFunc};
use penumbra::gpu::raster::{
    bin, draw, no_tile_culling, rasterize_in_tile, touched_tile_count, touched_tiles, touches_tile,
    TileDraw,
};
use penumbra::gpu::setup::RasterTriangle;
use penumbra::gpu::setup::{setup_triangle, CullMode};
use penumbra::gpu::tiling::Tiling;
use penumbra::gpu::transform::ClipVertex;
use proptest::prelude::*;

const W: u32 = 48;
const H: u32 = 40;

fn hits(tris: &[[ClipVertex; 3]], tile: u32) -> Vec<u32> {
    let tiling = Tiling::new(W, H, tile).unwrap();
    let mut setup = Vec::new();
    let mut c = Counters::default();
    for (k, t) in tris.iter().enumerate() {
        setup_triangle(t, k as u32, CullMode::None, W, H, &mut setup, &mut c);
    }
    let bins = bin(&tiling, &setup);
    let mut tiles: Vec<Vec<u32>> = (0..tiling.tile_count())
        .map(|_| vec![0; tiling.tile_len()])
        .collect();
    draw(
        &tiling,
        &mut tiles,
        &setup,
        &bins,
        None,
        no_tile_culling,
        |_, t, _, f, _, _| t[f.local] += 1,
    );
    let flat: Vec<u32> = tiles.into_iter().flatten().collect();
    tiling.to_row_major(&flat)
}

/// How close to an outer edge of the quad (in pixels) a sample may be classified either way:
/// the rasterizer snaps vertices to 1/256 pixel (`gpu::fixed`), which moves each by at most
/// 1/512 in x and y, so an edge by at most √2/512 ≈ 0.003 pixel where the sample lies
/// between its ends, a few times that beside a vertex; the f32 viewport transform adds
/// ~10⁻⁵ pixel. 1/64 pixel is five times the snapping and a sixty-fourth of a one-pixel shift:
/// an edge moved by a pixel puts the samples of a strip of width 1 − 2/64 on the wrong side
/// (`shifted_reference_fails`).
const EDGE_BAND_PX: f64 = 1.0 / 64.0;

/// Whether the sample of pixel (i, j) is strictly inside the convex quad `q` (in NDC, GL y
/// up) moved by `shift` pixels (x right, y down), `None` within [`EDGE_BAND_PX`] of an edge.
fn strictly_inside_shifted(q: &[[f32; 2]; 4], i: u32, j: u32, shift: [f64; 2]) -> Option<bool> {
    // In pixels, rows down from the top: the sample of pixel (i, j) is at (i + ½, j + ½).
    let px = |v: [f32; 2]| {
        [
            (v[0] as f64 + 1.0) / 2.0 * W as f64 + shift[0],
            (1.0 - v[1] as f64) / 2.0 * H as f64 + shift[1],
        ]
    };
    let (x, y) = (i as f64 + 0.5, j as f64 + 0.5);
    let mut sign = 0.0;
    let mut near_edge = false;
    for k in 0..4 {
        let [ax, ay] = px(q[k]);
        let [bx, by] = px(q[(k + 1) % 4]);
        let e = (bx - ax) * (y - ay) - (by - ay) * (x - ax);
        let len = libm::hypot(bx - ax, by - ay);
        if (e / len).abs() < EDGE_BAND_PX {
            near_edge = true; // within snapping distance of an outer edge: either answer is fine
        }
        if sign == 0.0 {
            sign = e.signum();
        } else if e.signum() != sign {
            return if near_edge { None } else { Some(false) };
        }
    }
    if near_edge {
        None
    } else {
        Some(true)
    }
}

/// [`strictly_inside_shifted`] with the quad where it is.
fn strictly_inside(q: &[[f32; 2]; 4], i: u32, j: u32) -> Option<bool> {
    strictly_inside_shifted(q, i, j, [0.0, 0.0])
}

/// The pixels of the split quad `q` (diagonal 0, tiles of 8) whose coverage contradicts
/// [`strictly_inside_shifted`] by `shift`.
fn contradicted_pixels(q: &[[f32; 2]; 4], shift: [f64; 2]) -> usize {
    let v: Vec<ClipVertex> = q
        .iter()
        .map(|p| ClipVertex([p[0], p[1], 0.0, 1.0]))
        .collect();
    let counts = hits(&[[v[0], v[1], v[2]], [v[0], v[2], v[3]]], 8);
    let mut wrong = 0;
    for j in 0..H {
        for i in 0..W {
            let n = counts[(j * W + i) as usize];
            if let Some(inside) = strictly_inside_shifted(q, i, j, shift) {
                wrong += usize::from((n == 1) != inside);
            }
        }
    }
    wrong
}

/// The coverage property is sharp: the rasterizer's coverage of a quad agrees with the
/// reference where it is and contradicts it on many pixels when the reference is moved by one
/// pixel (a rasterizer with a systematic one-pixel offset would fail
/// `split_quad_covers_each_pixel_once`) — and by a quarter pixel too. Each edge of the quad
/// spans ≥ 10 rows or columns, so a shift across it misclassifies ≥ 10 samples per edge.
#[test]
fn shifted_reference_fails() {
    let q = [[-0.5, -0.6], [0.55, -0.45], [0.4, 0.5], [-0.45, 0.62]];
    assert_eq!(contradicted_pixels(&q, [0.0, 0.0]), 0);
    for shift in [
        [1.0, 0.0],
        [-1.0, 0.0],
        [0.0, 1.0],
        [0.0, -1.0],
        [0.25, 0.25],
    ] {
        let wrong = contradicted_pixels(&q, shift);
        eprintln!("reference shifted by {shift:?} px: {wrong} pixels contradicted");
        assert!(
            wrong >= 10,
            "shift {shift:?}: only {wrong} pixels contradicted"
        );
    }
}

fn convex_quad() -> impl Strategy<Value = [[f32; 2]; 4]> {
    // A random convex quad: four angles around a center, radii varying, possibly off screen.
    (
        -0.8f32..0.8,
        -0.8f32..0.8,
        0.2f32..1.6,
        prop::array::uniform4(0.0f32..1.0),
        prop::array::uniform4(0.6f32..1.0),
    )
        .prop_map(|(cx, cy, r, jit, rad)| {
            let mut q = [[0.0; 2]; 4];
            for k in 0..4 {
                let ang = (k as f32 + jit[k] * 0.8) * std::f32::consts::FRAC_PI_2;
                q[k] = [
                    cx + r * rad[k] * libm::cosf(ang),
                    cy + r * rad[k] * libm::sinf(ang),
                ];
            }
            q
        })
}

/// Three vertices in NDC: a random triangle, or a sliver (the third vertex within `thin` of
/// the segment between the first two), possibly off screen.
fn triangle_or_sliver() -> impl Strategy<Value = [[f32; 2]; 3]> {
    (
        prop::array::uniform2(-1.5f32..1.5),
        prop::array::uniform2(-1.5f32..1.5),
        prop::array::uniform2(-1.5f32..1.5),
        0.0f32..1.0,
        prop::option::of(-0.05f32..0.05),
    )
        .prop_map(|(a, b, c, along, thin)| match thin {
            None => [a, b, c],
            Some(off) => {
                let d = [b[0] - a[0], b[1] - a[1]];
                let m = [a[0] + along * d[0], a[1] + along * d[1]];
                [a, b, [m[0] - off * d[1], m[1] + off * d[0]]]
            }
        })
}

/// The tiles binning must keep, by brute force: those where each edge function is
/// non-negative at some sample of the tile's columns and of its rows inside the triangle's
/// bounding box (`raster::touched_tiles`).
fn tiles_by_brute_force(tiling: &Tiling, t: &RasterTriangle) -> Vec<usize> {
    let [_, by0, _, by1] = t.bbox;
    (0..tiling.tile_count())
        .filter(|&k| {
            let r = tiling.rect(k);
            let [bx0, _, bx1, _] = t.bbox;
            let in_box_tiles = r.x0 <= bx1 && r.x0 + tiling.tile > bx0 && r.y0 <= by1 && r.y1 > by0;
            let rows = r.y0.max(by0)..(r.y0 + tiling.tile).min(by1 + 1);
            let cols = r.x0..r.x0 + tiling.tile;
            in_box_tiles
                && t.edges.iter().all(|e| {
                    rows.clone()
                        .any(|j| cols.clone().any(|i| e.at(i as i64, j as i64) >= 0))
                })
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Binning keeps exactly the tiles of the brute-force rule, so every tile with a covered
    /// sample (no fragment is lost: the bound comes from the coverage itself), and the three
    /// forms of the rule (the tile list, the one-tile query, the count) agree.
    #[test]
    fn binning_keeps_exactly_the_tiles_no_edge_rejects(v in triangle_or_sliver(), w in 0.5f32..3.0, tile_log in 1u32..6) {
        let tiling = Tiling::new(W, H, 1 << tile_log).unwrap();
        let tri = v.map(|p| ClipVertex([p[0] * w, p[1] * w, 0.0, w]));
        let mut setup = Vec::new();
        let mut c = Counters::default();
        setup_triangle(&tri, 0, CullMode::None, W, H, &mut setup, &mut c);
        let Some(t) = setup.first() else {
            return Ok(());
        };
        let kept: Vec<usize> = touched_tiles(&tiling, t, 0..tiling.tiles_y).collect();
        prop_assert_eq!(&kept, &tiles_by_brute_force(&tiling, t));
        prop_assert_eq!(kept.len(), touched_tile_count(&tiling, t));
        for k in 0..tiling.tile_count() {
            prop_assert_eq!(touches_tile(&tiling, t, k), kept.contains(&k), "tile {}", k);
            let r = tiling.rect(k);
            let covered = (r.y0..r.y1).any(|j| (r.x0..r.x1).any(|i| t.covers(i, j)));
            prop_assert!(!covered || kept.contains(&k), "tile {} has a covered sample", k);
        }
    }
}

#[test]
fn binning_leaves_out_the_tiles_a_sliver_only_boxes() {
    // A diagonal sliver across the whole image: its box is every tile; it touches a band.
    let tiling = Tiling::new(W, H, 4).unwrap();
    let tri = [[-1.0, -1.0], [1.0, 1.0], [0.98, 1.0]]
        .map(|p: [f32; 2]| ClipVertex([p[0], p[1], 0.0, 1.0]));
    let mut setup = Vec::new();
    let mut c = Counters::default();
    setup_triangle(&tri, 0, CullMode::None, W, H, &mut setup, &mut c);
    let kept = touched_tile_count(&tiling, &setup[0]);
    // The diagonal of a 12×10-tile image crosses at most 12 + 10 − 1 tiles; the sliver is
    // under a tile wide, so it touches at most twice that.
    assert!(
        kept <= 2 * (12 + 10 - 1),
        "{kept} of {} tiles",
        tiling.tile_count()
    );
    assert!(kept >= 12, "{kept}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn split_quad_covers_each_pixel_once(q in convex_quad(), diag in 0usize..2, tile_log in 1u32..6, w in 0.5f32..3.0) {
        let v: Vec<ClipVertex> = q.iter().map(|p| ClipVertex([p[0] * w, p[1] * w, 0.0, w])).collect();
        let tris = if diag == 0 {
            [[v[0], v[1], v[2]], [v[0], v[2], v[3]]]
        } else {
            [[v[0], v[1], v[3]], [v[1], v[2], v[3]]]
        };
        let counts = hits(&tris, 1 << tile_log);
        for j in 0..H {
            for i in 0..W {
                let n = counts[(j * W + i) as usize];
                prop_assert!(n <= 1, "pixel ({i},{j}) hit {n} times");
                if let Some(inside) = strictly_inside(&q, i, j) {
                    prop_assert_eq!(n == 1, inside, "pixel ({},{}) coverage {} inside {}", i, j, n, inside);
                }
            }
        }
    }

    /// `RasterTriangle::covers` (the single-pixel query) is exactly the set of samples the
    /// tile traversal visits.
    #[test]
    fn single_pixel_coverage_matches_traversal(q in convex_quad(), w in 0.5f32..3.0) {
        let v: Vec<ClipVertex> = q.iter().map(|p| ClipVertex([p[0] * w, p[1] * w, 0.0, w])).collect();
        let tri = [v[0], v[1], v[2]];
        let counts = hits(&[tri], 8);
        let mut setup = Vec::new();
        let mut c = Counters::default();
        setup_triangle(&tri, 0, CullMode::None, W, H, &mut setup, &mut c);
        for j in 0..H {
            for i in 0..W {
                let covered = setup.iter().filter(|t| t.covers(i, j)).count() as u32;
                prop_assert_eq!(covered, counts[(j * W + i) as usize], "pixel ({},{})", i, j);
            }
        }
    }

    #[test]
    fn coverage_does_not_depend_on_tile_size(q in convex_quad(), a in 1u32..9, b in 1u32..9) {
        let v: Vec<ClipVertex> = q.iter().map(|p| ClipVertex([p[0], p[1], 0.0, 1.0])).collect();
        let tris = [[v[0], v[1], v[2]], [v[0], v[2], v[3]]];
        prop_assert_eq!(hits(&tris, 1 << a), hits(&tris, 1 << b));
    }
}

#[test]
fn triangle_fan_around_a_vertex_is_watertight() {
    // 12 triangles sharing a center vertex at a pixel sample: every covered pixel exactly once.
    let c = [0.03125f32, -0.05];
    let mut tris = Vec::new();
    for k in 0..12 {
        let a0 = k as f32 / 12.0 * std::f32::consts::TAU;
        let a1 = (k + 1) as f32 / 12.0 * std::f32::consts::TAU;
        let p = |a: f32| {
            ClipVertex([
                c[0] + 0.9 * libm::cosf(a),
                c[1] + 0.9 * libm::sinf(a),
                0.0,
                1.0,
            ])
        };
        tris.push([ClipVertex([c[0], c[1], 0.0, 1.0]), p(a0), p(a1)]);
    }
    let counts = hits(&tris, 8);
    assert!(counts.iter().all(|&n| n <= 1));
    assert!(counts.iter().filter(|&&n| n == 1).count() > 500);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// The hierarchical-Z unit never leaves out a fragment that could change a buffer: on a
    /// random depth surface (a plane with noise, D24) and a random triangle, for LESS and
    /// GEQUAL and either idle outcome, every covered sample of every tile whose depth test
    /// outcome differs from the idle one lies in what `DepthTile::hiz_draw` lets the draw loop
    /// rasterize (the bound is the depth test itself, sample by sample), at every HiZ tile
    /// size up to the raster tile.
    #[test]
    fn hiz_draws_every_fragment_whose_outcome_is_not_idle(
        v in triangle_or_sliver(),
        zs in prop::array::uniform3(-0.95f32..0.95),
        w in 0.5f32..3.0,
        tile_log in 2u32..6,
        hiz_log in 1u32..6,
        surface in (0.05f32..0.95, -0.01f32..0.01, -0.01f32..0.01, 0.0f32..0.05, any::<u32>()),
    ) {
        let tiling = Tiling::new(W, H, 1 << tile_log).unwrap();
        let format = DepthFormat::D24;
        let (base, dx, dy, noise, seed) = surface;
        let mut state = seed | 1;
        let mut tiles: Vec<DepthTile> = (0..tiling.tile_count())
            .map(|t| DepthTile::cleared_in(format, &tiling, t, 1 << hiz_log))
            .collect();
        for y in 0..H {
            for x in 0..W {
                state ^= state << 13;
                state ^= state >> 17;
                state ^= state << 5;
                let jitter = noise * (state as f32 / u32::MAX as f32);
                let z = (base + dx * x as f32 + dy * y as f32 + jitter).clamp(0.0, 1.0);
                tiles[tiling.tile_of(x, y)].values[tiling.local(x, y)] = format.quantize(z);
            }
        }
        for (t, tile) in tiles.iter_mut().enumerate() {
            tile.build_hiz(&tiling, t);
        }
        let tri: [ClipVertex; 3] =
            std::array::from_fn(|k| ClipVertex([v[k][0] * w, v[k][1] * w, zs[k] * w, w]));
        let mut setup = Vec::new();
        let mut c = Counters::default();
        setup_triangle(&tri, 0, CullMode::None, W, H, &mut setup, &mut c);
        let Some(tri) = setup.first() else {
            return Ok(());
        };
        let mut missed = Vec::new();
        for t in touched_tiles(&tiling, tri, 0..tiling.tiles_y) {
            let depth = &tiles[t];
            for (func, idle) in [DepthFunc::Less, DepthFunc::GEqual]
                .into_iter()
                .flat_map(|f| [(f, false), (f, true)])
            {
                let drawn = depth.hiz_draw(&tiling, t, (func, idle), tri, &mut c);
                rasterize_in_tile(&tiling, tri, &tiling.rect(t), |f| {
                    let outcome = func.test(format.quantize(f.z), depth.values[f.local]);
                    let inside = match drawn {
                        TileDraw::Skip => false,
                        TileDraw::Whole => true,
                        TileDraw::Within(r) => r.contains(f.x, f.y),
                    };
                    if outcome != idle && !inside {
                        missed.push((t, func, idle, f.x, f.y));
                    }
                });
            }
        }
        prop_assert!(missed.is_empty(), "{missed:?}");
    }
}
