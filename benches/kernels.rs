//! Criterion benchmarks of the kernels under the methods, on the built-in `forest-spheres`
//! (20 532 triangles, Forest et al. 2006 Fig. 1) at 256×256, all in the group
//! `forest-spheres-256`:
//!
//! * `setup/transform`: every vertex of the scene to clip space ([`Projection::clip_point`])
//!   and the clip-space triangles assembled in submission order, as the scene pass does;
//! * `setup/setup-all`: clipping, projection, snapping and edge-function set-up of those
//!   triangles ([`setup_all`], back faces culled as in the scene pass);
//! * `traversal/bin`: binning the set-up triangles to tiles ([`bin`]);
//! * `traversal/draw`: every binned (tile, triangle) pair traversed ([`rasterize_in_tile`]
//!   through [`draw`], tiles in parallel as every pass runs them), each fragment counted and
//!   passed through [`black_box`];
//! * `traversal/rasterize-serial`: the same traversal on one thread without bins: each
//!   triangle, in submission order, over every tile its bounding box touches;
//! * `coverage/exact`: the exact coverage of the rectangular light by an edge's hard shadow
//!   quad ([`edge_coverage_exact`], Paper III §3.2.2: projection, clipping and area) for 4096
//!   fixed pseudo-random (receiver, edge) pairs;
//! * `coverage/table-lookup`: the 4D coverage texture (Paper III §3.3, n = [`DEFAULT_N`], the
//!   `ssv` default) looked up ([`CoverageTexture::lookup`], nearest, the `ssv` default) at the
//!   same edges' projected, clipped end points, computed outside the timed loop;
//! * `coverage/table-with-projection`: `ssv`'s whole texture path per fragment — the projected,
//!   clipped edge ([`projected_edge_in_light`]), its side ([`quad_side`]) and the lookup — on
//!   the same 4096 pairs, the fair comparison with `coverage/exact`;
//! * `silhouette/adjacency`: the edge adjacency of every caster mesh ([`adjacency::build`]);
//! * `silhouette/possible-edges`: the light-facing triangles and possible silhouette edges of
//!   every caster mesh from the light center ([`light_facing`], [`possible_silhouettes`]);
//! * `silhouette/loops`: those edges split into closed loops ([`silhouette_loops`], Paper V),
//!   as the penumbra wedges of Paper I need;
//! * `wedges/ssv`: `ssv`'s wedge of every possible silhouette edge around the rectangle
//!   ([`SsvWedge::new`], Paper III §3.1), the edges extracted outside the timed loop;
//! * `wedges/pw2002`: `pw2002`'s whole wedge construction ([`pw2002::options`] and
//!   [`pw2002::frame_wedges`], Paper I: silhouettes, loops, the near-parallel rule, corner
//!   wedges, planes, faces and caps) with the rectangle swapped for a sphere of radius its
//!   half extent at the same center, as `benches/pipeline.rs` lights the sphere-only methods.
//!
//! The coverage inputs come from a fixed 64-bit generator (SplitMix64), so every run times the
//! same cases. Each case is a receiver point on the floor under the light and an edge whose end
//! points lie between it and the light, on the segments from the receiver to two points of the
//! light's plane spread over 1.5× the light (so that some ends are clipped by the light's
//! border); cases whose edge projects outside the light are skipped, so both methods see only
//! edges that cover part of the light.
//!
//! Run with `cargo bench --bench kernels`, a subset with criterion's name filter, e.g.
//! `cargo bench --bench kernels -- coverage/`. Criterion writes its HTML report to
//! `target/criterion/report/index.html`. The file took 75 s on a shared two-core machine.

mod common;

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use glam::{DVec2, DVec3};
use penumbra::frame::{Frame, GpuSettings};
use penumbra::geometry::loops::silhouette_loops;
use penumbra::geometry::silhouette::{light_facing, possible_silhouettes, SilhouetteEdge};
use penumbra::geometry::ssv_wedge::{SsvWedge, WedgeLight};
use penumbra::gpu::raster::{bin, draw, no_tile_culling, rasterize_in_tile};
use penumbra::gpu::setup::{setup_all, CullMode, RasterTriangle};
use penumbra::gpu::tiling::Tiling;
use penumbra::gpu::transform::{ClipVertex, Projection};
use penumbra::light::coverage::{
    edge_coverage_exact, projected_edge_in_light, quad_side, RectLight,
};
use penumbra::light::coverage_texture::{
    coverage_texture, CoverageFilter, CoverageTexture, CoverageTextureKey, DEFAULT_N,
};
use penumbra::methods::pw2002;
use penumbra::scene::adjacency;
use penumbra::scene::{builtin, LightShape, Scene};

/// The scene every kernel runs on.
const SCENE: &str = "forest-spheres";
/// Its image width and height in pixels.
const SIZE: u32 = 256;
/// Receiver–edge pairs per iteration of the coverage benchmarks.
const COVERAGE_CASES: usize = 4096;
/// The coverage texture's lookup filter (the `ssv` default).
const FILTER: CoverageFilter = CoverageFilter::Nearest;

/// SplitMix64 (Steele, Lea & Flood 2014): a fixed, portable pseudo-random sequence.
struct SplitMix64(u64);

impl SplitMix64 {
    /// The next 64 random bits.
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A uniform number in `[lo, hi)` (53 random bits).
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let unit = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * unit
    }
}

/// One coverage input: a receiver point, an edge above it, and the edge projected from the
/// receiver onto the light and clipped to it (the texture's coordinates).
struct CoverageCase {
    /// Receiver point (on the floor).
    p: DVec3,
    /// Edge start.
    e0: DVec3,
    /// Edge end.
    e1: DVec3,
    /// [`projected_edge_in_light`] of the above, in light coordinates.
    projected: [DVec2; 2],
}

/// [`COVERAGE_CASES`] cases under `light` (module doc), the same on every run.
fn coverage_cases(light: &RectLight) -> Vec<CoverageCase> {
    let mut rng = SplitMix64(0x5eed_c0ff_ee15_4a6e);
    let mut cases = Vec::with_capacity(COVERAGE_CASES);
    while cases.len() < COVERAGE_CASES {
        let p = DVec3::new(rng.uniform(-1.5, 1.5), 0.0, rng.uniform(-1.5, 1.5));
        let mut end = || {
            let on_light = light.world(DVec3::new(
                rng.uniform(-1.5, 1.5),
                rng.uniform(-1.5, 1.5),
                0.0,
            ));
            p + rng.uniform(0.15, 0.85) * (on_light - p)
        };
        let (e0, e1) = (end(), end());
        if let Some(projected) = projected_edge_in_light(light, p, e0, e1) {
            cases.push(CoverageCase {
                p,
                e0,
                e1,
                projected,
            });
        }
    }
    cases
}

/// The clip-space triangles of every mesh of `scene` in submission order (mesh by mesh,
/// triangle by triangle, as [`Frame::render`] submits them).
fn clip_triangles(scene: &Scene, proj: &Projection) -> Vec<[ClipVertex; 3]> {
    let mut prims = Vec::new();
    for m in &scene.meshes {
        let clip: Vec<ClipVertex> = m.positions.iter().map(|p| proj.clip_point(*p)).collect();
        prims.extend(m.triangles.iter().map(|t| t.map(|i| clip[i as usize])));
    }
    prims
}

/// Every fragment of `tris`, one triangle after the other over the tiles its bounding box
/// touches, on the calling thread; returns the number of fragments.
fn rasterize_serial(tiling: &Tiling, tris: &[RasterTriangle]) -> u64 {
    let mut fragments = 0;
    for t in tris {
        let [x0, y0, x1, y1] = t.bbox;
        for ty in y0 / tiling.tile..=y1 / tiling.tile {
            for tx in x0 / tiling.tile..=x1 / tiling.tile {
                let rect = tiling.rect((ty * tiling.tiles_x + tx) as usize);
                let (_, n) = rasterize_in_tile(tiling, t, &rect, |f| {
                    black_box(f);
                });
                fragments += n;
            }
        }
    }
    fragments
}

/// `scene` (one rectangular light) with the rectangle swapped for a sphere of radius its half
/// extent along `u`, at the same center.
fn sphere_lit(scene: &Scene) -> Scene {
    let mut out = scene.clone();
    let LightShape::Rect { u, .. } = scene.light().shape else {
        panic!("{} has no rectangular light", scene.source);
    };
    out.lights[0].shape = LightShape::Sphere { radius: u.length() };
    out
}

/// The possible silhouette edges of every caster mesh of `frame` from its light center.
fn silhouettes(frame: &Frame) -> Vec<Vec<SilhouetteEdge>> {
    let center = frame.scene.light().center;
    frame
        .caster_meshes()
        .into_iter()
        .map(|(mesh, adj)| possible_silhouettes(mesh, adj, &light_facing(mesh, center)))
        .collect()
}

/// Registers the triangle set-up and traversal benchmarks on `frame`'s scene.
fn setup_and_traversal(c: &mut Criterion, frame: &Frame) {
    let mut group = c.benchmark_group(format!("{SCENE}-{SIZE}"));
    let (scene, proj, tiling) = (frame.scene, &frame.proj, &frame.tiling);
    group.bench_function("setup/transform", |b| {
        b.iter(|| clip_triangles(black_box(scene), proj))
    });
    let prims = clip_triangles(scene, proj);
    group.bench_function("setup/setup-all", |b| {
        b.iter(|| setup_all(black_box(&prims), CullMode::Back, tiling))
    });
    let (tris, _) = setup_all(&prims, CullMode::Back, tiling);
    group.bench_function("traversal/bin", |b| {
        b.iter(|| bin(tiling, black_box(&tris)))
    });
    let bins = bin(tiling, &tris);
    group.bench_function("traversal/draw", |b| {
        b.iter(|| {
            let mut counts = vec![0u64; tiling.tile_count()];
            draw(
                tiling,
                &mut counts,
                &tris,
                &bins,
                None,
                no_tile_culling,
                |_, n, _, f, _, _| {
                    black_box(f);
                    *n += 1;
                },
            );
            counts.iter().sum::<u64>()
        })
    });
    group.bench_function("traversal/rasterize-serial", |b| {
        b.iter(|| rasterize_serial(tiling, black_box(&tris)))
    });
    group.finish();
}

/// Registers the exact-versus-table coverage benchmarks under `frame`'s rectangular light.
fn coverage(c: &mut Criterion, frame: &Frame) {
    let light = RectLight::from_light(frame.scene.light()).expect("a rectangular light");
    let cases = coverage_cases(&light);
    let texture: std::sync::Arc<CoverageTexture> =
        coverage_texture(&CoverageTextureKey::uniform(DEFAULT_N));
    report_agreement(&light, &texture, &cases);
    let mut group = c.benchmark_group(format!("{SCENE}-{SIZE}"));
    group.bench_function("coverage/exact", |b| {
        b.iter(|| {
            black_box(&cases)
                .iter()
                .map(|k| edge_coverage_exact(&light, k.p, k.e0, k.e1))
                .sum::<f64>()
        })
    });
    group.bench_function("coverage/table-lookup", |b| {
        b.iter(|| {
            black_box(&cases)
                .iter()
                .map(|k| texture.lookup(k.projected[0], k.projected[1], FILTER)[0])
                .sum::<f64>()
        })
    });
    group.bench_function("coverage/table-with-projection", |b| {
        b.iter(|| {
            black_box(&cases)
                .iter()
                .map(|k| match projected_edge_in_light(&light, k.p, k.e0, k.e1) {
                    Some([q0, q1]) => {
                        quad_side(light.center, k.p, k.e0, k.e1) * texture.lookup(q0, q1, FILTER)[0]
                    }
                    None => 0.0,
                })
                .sum::<f64>()
        })
    });
    group.finish();
}

/// Prints, once, how many cases cover part of the light and how far the table is from the
/// exact coverage on them (the inputs are meaningful when most coverages are non-zero).
fn report_agreement(light: &RectLight, texture: &CoverageTexture, cases: &[CoverageCase]) {
    let mut nonzero = 0;
    let mut error = 0.0;
    for k in cases {
        let exact = edge_coverage_exact(light, k.p, k.e0, k.e1);
        let table = quad_side(light.center, k.p, k.e0, k.e1)
            * texture.lookup(k.projected[0], k.projected[1], FILTER)[0];
        nonzero += usize::from(exact != 0.0);
        error += (exact - table).abs();
    }
    assert!(
        2 * nonzero > cases.len(),
        "most coverage cases must cover the light"
    );
    eprintln!(
        "coverage inputs: {} cases, {nonzero} with non-zero exact coverage, mean |exact − table| \
         = {:.5} (n = {DEFAULT_N}, {FILTER:?})",
        cases.len(),
        error / cases.len() as f64
    );
}

/// Registers the silhouette and wedge construction benchmarks on `frame` (rectangular light)
/// and on `sphere_frame` (the same occluders under a sphere).
fn wedges(c: &mut Criterion, frame: &Frame, sphere_frame: &Frame) {
    let mut group = c.benchmark_group(format!("{SCENE}-{SIZE}"));
    let meshes = frame.caster_meshes();
    group.bench_function("silhouette/adjacency", |b| {
        b.iter(|| {
            meshes
                .iter()
                .map(|(mesh, _)| adjacency::build(black_box(mesh)).expect("closed mesh"))
                .collect::<Vec<_>>()
        })
    });
    group.bench_function("silhouette/possible-edges", |b| {
        b.iter(|| silhouettes(black_box(frame)))
    });
    let edges = silhouettes(frame);
    group.bench_function("silhouette/loops", |b| {
        b.iter(|| {
            black_box(&edges)
                .iter()
                .map(|e| silhouette_loops(e).expect("consistent silhouette"))
                .collect::<Vec<_>>()
        })
    });
    let light = WedgeLight::from_light(frame.scene.light()).expect("a rectangular light");
    group.bench_function("wedges/ssv", |b| {
        b.iter(|| {
            black_box(&edges)
                .iter()
                .flatten()
                .map(|e| SsvWedge::new(&light, e.b.as_dvec3(), e.a.as_dvec3()))
                .collect::<Vec<_>>()
        })
    });
    group.bench_function("wedges/pw2002", |b| {
        b.iter(|| {
            let frame = black_box(sphere_frame);
            let settings = pw2002::options(frame).expect("pw2002 options");
            pw2002::frame_wedges(frame, &settings).expect("pw2002 wedges")
        })
    });
    group.finish();
}

/// Registers every benchmark of this file.
fn kernels(c: &mut Criterion) {
    let mut scene = builtin::load(SCENE).expect("built-in scene");
    scene.resize(Some(SIZE), Some(SIZE));
    let frame = Frame::render(&scene, GpuSettings::default()).expect("scene pass");
    let sphere = sphere_lit(&scene);
    let sphere_frame = frame.lit_by(&sphere);
    setup_and_traversal(c, &frame);
    coverage(c, &frame);
    wedges(c, &frame, &sphere_frame);
}

criterion_group! {
    name = benches;
    config = common::config();
    targets = kernels
}
criterion_main!(benches);
