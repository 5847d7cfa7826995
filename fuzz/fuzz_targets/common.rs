//! The code paths the fuzz targets exercise, written once and shared: each `fuzz_targets/*.rs`
//! includes this file with `#[path = "common.rs"] mod common;`, and
//! `tests/fuzz_corpus_replay.rs` includes it the same way to replay every corpus and
//! regression input under `cargo test`. It depends only on `penumbra` and `std` (no
//! `arbitrary`), so the replay test needs no extra dependency.
//!
//! Every function takes raw fuzzer bytes and must not panic on any of them, except on the
//! `assert!`s written here, which state invariants the library promises (a panic there is a
//! bug the fuzzer found, not bad input).

use penumbra::geometry::adjacency;
use penumbra::geometry::loops::{silhouette_loops, vertex_degrees};
use penumbra::geometry::shadow_volume::{shadow_volume_triangles, Capping};
use penumbra::geometry::silhouette::{light_facing, possible_silhouettes};
use penumbra::gpu::counters::Counters;
use penumbra::gpu::raster::{bin, draw, no_tile_culling};
use penumbra::gpu::setup::{setup_triangle, CullMode, RasterTriangle};
use penumbra::gpu::tiling::Tiling;
use penumbra::gpu::transform::{ClipVertex, Projection};
use penumbra::scene::file::{parse_scene_str, Format};
use penumbra::scene::obj::parse_obj;
use penumbra::scene::Camera;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Image edge (pixels) every raster check uses: 32×32, as the fuzz brief fixes.
pub const SIZE: u32 = 32;

/// Most triangles one raster input is decoded into (keeps each run well under a millisecond).
const MAX_TRIANGLES: u32 = 256;

/// The files a fuzzed scene can refer to, relative to the scene directory's parent: the
/// shipped models (as `models/...` from `scenes/` and as `../models/...` from `scenes/bad/`
/// alike), the bad-input models and the texture. Embedded so the fuzz binaries and the replay
/// test carry them wherever they run.
const SCENE_FILES: &[(&str, &[u8])] = &[
    (
        "scenes/models/cube.obj",
        include_bytes!("../../scenes/models/cube.obj"),
    ),
    (
        "scenes/models/star.obj",
        include_bytes!("../../scenes/models/star.obj"),
    ),
    (
        "scenes/models/tetra.obj",
        include_bytes!("../../scenes/models/tetra.obj"),
    ),
    (
        "scenes/models/torus.obj",
        include_bytes!("../../scenes/models/torus.obj"),
    ),
    (
        "scenes/models/nan-vertex.obj",
        include_bytes!("../../scenes/bad/models/nan-vertex.obj"),
    ),
    (
        "scenes/models/open-box.obj",
        include_bytes!("../../scenes/bad/models/open-box.obj"),
    ),
    (
        "scenes/textures/fire.png",
        include_bytes!("../../scenes/textures/fire.png"),
    ),
    (
        "models/cube.obj",
        include_bytes!("../../scenes/models/cube.obj"),
    ),
];

/// Writes [`SCENE_FILES`] under `root` and returns the directory fuzzed scenes are parsed
/// against (`root/scenes`): `models/cube.obj`, `textures/fire.png` and `../models/cube.obj`
/// all resolve there, so the shipped scene files get past loading to validation.
pub fn populate_scene_dir(root: &Path) -> std::io::Result<PathBuf> {
    for (rel, bytes) in SCENE_FILES {
        let path = root.join(rel);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent)?;
        }
        std::fs::write(path, bytes)?;
    }
    Ok(root.join("scenes"))
}

/// Whether scene text may name a path that reads forever or blocks (`/dev/zero`,
/// `/dev/stdin`, `/proc/...`), or hide one behind a `\u` escape. Such inputs are skipped:
/// a scene may name any file its user can read, and reading a device is the user's choice, not
/// a parser bug, but it would stall the fuzzer.
fn names_special_file(text: &str) -> bool {
    ["dev", "proc", "sys", "\\u", "\\U"]
        .iter()
        .any(|s| text.contains(s))
}

/// The `scene_toml` / `scene_json` path: `parse_scene_str` on the input as UTF-8 (other
/// inputs are skipped) with OBJ and texture paths relative to `base_dir`. Any result is fine;
/// an error must be one line naming the source.
pub fn scene(data: &[u8], format: Format, base_dir: &Path) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if names_special_file(text) {
        return;
    }
    let source = match format {
        Format::Toml => "fuzz.toml",
        Format::Json => "fuzz.json",
    };
    match parse_scene_str(text, format, source, base_dir) {
        Ok(scene) => {
            assert!(scene.width >= 1 && scene.height >= 1);
            assert!(scene.lights.iter().all(|l| l.center.is_finite()));
        }
        Err(e) => {
            let msg = e.to_string();
            assert!(!msg.contains(['\n', '\r']), "multi-line error: {msg:?}");
            assert_eq!(e.file, source);
        }
    }
}

/// A 64-bit FNV-1a hash, to derive parameters (light position, transform) from the input
/// deterministically without consuming bytes the OBJ parser sees.
fn fnv1a(data: &[u8]) -> u64 {
    data.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The fixed camera of the `obj` target: at (0, 2, 5) looking at the origin, 45° vertical.
fn fixed_camera() -> Camera {
    Camera {
        eye: glam::DVec3::new(0.0, 2.0, 5.0),
        target: glam::DVec3::ZERO,
        up: glam::DVec3::Y,
        vfov_deg: 45.0,
        near: Some(0.1),
    }
}

/// The `obj` path: `parse_obj` on the raw bytes (sometimes with a mirroring transform, which
/// flips winding); if it parses, `adjacency::build`; if the mesh is closed, the light-facing
/// triangles, possible silhouettes, silhouette loops and both kinds of shadow volume from a
/// light point derived from the input, then those volumes through setup, binning and
/// traversal with a fixed camera at 32×32.
///
/// The light is one of: a point in [−4, 4)³, a mesh vertex (light on the surface) or the
/// centre of the mesh bounds (usually inside the mesh).
pub fn obj(data: &[u8]) {
    let h = fnv1a(data);
    let transform = (h & 1 == 1).then(|| glam::Mat4::from_scale(glam::Vec3::new(-1.0, 1.0, 1.0)));
    let Ok(mesh) = parse_obj(data, "fuzz.obj", transform, [0.8; 3]) else {
        return;
    };
    assert!(mesh.positions.iter().all(|p| p.is_finite()));
    assert!(mesh
        .triangles
        .iter()
        .flatten()
        .all(|&i| (i as usize) < mesh.positions.len()));
    let Ok(adj) = adjacency::build(&mesh) else {
        return;
    };
    assert_eq!(adj.triangle_edges.len(), mesh.triangles.len());

    let coord = |shift: u32| ((h >> shift) & 0xffff) as f32 / 8192.0 - 4.0;
    let light = match (h >> 56) & 3 {
        0 if !mesh.positions.is_empty() => {
            mesh.positions[((h >> 8) % mesh.positions.len() as u64) as usize]
        }
        1 if !mesh.positions.is_empty() => {
            let lo = mesh
                .positions
                .iter()
                .fold(mesh.positions[0], |a, p| a.min(*p));
            let hi = mesh
                .positions
                .iter()
                .fold(mesh.positions[0], |a, p| a.max(*p));
            (lo + hi) * 0.5
        }
        _ => glam::Vec3::new(coord(8), coord(24), coord(40)),
    };

    let facing = light_facing(&mesh, light);
    assert_eq!(facing.len(), mesh.triangles.len());
    let sil = possible_silhouettes(&mesh, &adj, &facing);
    // Paper V: facing decided once per triangle gives even degree at every silhouette vertex,
    // so the edges always split into closed loops that use each edge once.
    assert!(vertex_degrees(&sil).values().all(|d| d % 2 == 0));
    let loops = silhouette_loops(&sil).unwrap_or_else(|e| panic!("silhouette loops: {e}"));
    assert_eq!(loops.iter().map(Vec::len).sum::<usize>(), sil.len());

    let proj = Projection::new(&fixed_camera(), SIZE, SIZE, 0.1);
    let open = shadow_volume_triangles(&[(&mesh, &adj)], light, &proj, Capping::Open);
    assert_eq!(open.len(), 2 * sil.len());
    let capped = shadow_volume_triangles(&[(&mesh, &adj)], light, &proj, Capping::Capped);
    assert_eq!(capped.len(), 2 * sil.len() + mesh.triangles.len());
    rasterize(&capped, CullMode::None, 8);
}

/// A cursor over fuzzer bytes that reads zeros past the end.
struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    /// The next byte (0 past the end).
    fn u8(&mut self) -> u8 {
        match self.0.split_first() {
            Some((&b, rest)) => {
                self.0 = rest;
                b
            }
            None => 0,
        }
    }

    /// The next `N` bytes (zero-padded past the end).
    fn array<const N: usize>(&mut self) -> [u8; N] {
        std::array::from_fn(|_| self.u8())
    }
}

/// Decodes one clip-space vertex coordinate set in the encoding selected by a triangle's
/// header byte `h`: bit 7 → raw little-endian f32 bits (NaN, ±inf, subnormals reachable);
/// else bit 6 → x, y, z = i16/8192 (±4, around the viewport) with w = 1; else all four
/// = i16/1024 (±32, w of either sign).
fn vertex(r: &mut Bytes, h: u8) -> ClipVertex {
    let small = |r: &mut Bytes, scale: f32| i16::from_le_bytes(r.array()) as f32 / scale;
    ClipVertex(if h & 0x80 != 0 {
        std::array::from_fn(|_| f32::from_le_bytes(r.array()))
    } else if h & 0x40 != 0 {
        [small(r, 8192.0), small(r, 8192.0), small(r, 8192.0), 1.0]
    } else {
        std::array::from_fn(|_| small(r, 1024.0))
    })
}

/// The `raster` path: arbitrary clip-space triangles through `setup_triangle`, `bin` and
/// `draw` on a 32×32 image. Byte 0 picks the tile size (2…32); then per triangle a header
/// byte (bits 0–1 cull mode, bits 6–7 vertex encoding, see [`vertex`]) and its three
/// vertices. Must not panic for finite or non-finite coordinates.
pub fn raster(data: &[u8]) {
    let mut r = Bytes(data);
    let tile = 2u32 << (r.u8() % 5);
    let mut tris = Vec::new();
    let mut prim = 0;
    while !r.0.is_empty() && prim < MAX_TRIANGLES {
        let h = r.u8();
        let cull = match h & 3 {
            1 => CullMode::Back,
            2 => CullMode::Front,
            _ => CullMode::None,
        };
        let tri: [ClipVertex; 3] = std::array::from_fn(|_| vertex(&mut r, h));
        tris.push((tri, cull));
        prim += 1;
    }
    let mut setup = Vec::new();
    let mut counters = Counters::default();
    for (k, (tri, cull)) in tris.iter().enumerate() {
        setup_triangle(tri, k as u32, *cull, SIZE, SIZE, &mut setup, &mut counters);
    }
    assert_eq!(counters.triangles_submitted, tris.len() as u64);
    draw_checked(&setup, tile);
}

/// Sets up `tris` with one cull mode and draws them (see [`draw_checked`]).
fn rasterize(tris: &[[ClipVertex; 3]], cull: CullMode, tile: u32) {
    let mut setup = Vec::new();
    let mut counters = Counters::default();
    for (k, tri) in tris.iter().enumerate() {
        setup_triangle(tri, k as u32, cull, SIZE, SIZE, &mut setup, &mut counters);
    }
    draw_checked(&setup, tile);
}

/// Bins and draws set-up triangles on a `SIZE`×`SIZE` image with `tile`-pixel tiles, counting
/// fragments per pixel, and checks that every fragment lies in the image and in the tile that
/// drew it, and that the counters agree with the fragments seen.
fn draw_checked(setup: &[RasterTriangle], tile: u32) {
    for t in setup {
        let [x0, y0, x1, y1] = t.bbox;
        assert!(
            x0 <= x1 && y0 <= y1 && x1 < SIZE && y1 < SIZE,
            "{:?}",
            t.bbox
        );
    }
    let tiling = Tiling::new(SIZE, SIZE, tile).expect("tile size is a power of two in 2..=32");
    let bins = bin(&tiling, setup);
    let mut tiles: Vec<Vec<u32>> = (0..tiling.tile_count())
        .map(|_| vec![0; tiling.tile_len()])
        .collect();
    let counters = draw(
        &tiling,
        &mut tiles,
        setup,
        &bins,
        no_tile_culling,
        |t, storage: &mut Vec<u32>, _tri, f, _c| {
            assert!(f.x < SIZE && f.y < SIZE, "fragment ({}, {})", f.x, f.y);
            assert_eq!(tiling.tile_of(f.x, f.y), t);
            assert_eq!(tiling.local(f.x, f.y), f.local);
            storage[f.local] += 1;
        },
    );
    let seen: u64 = tiles.iter().flatten().map(|&n| n as u64).sum();
    assert_eq!(counters.fragments_rasterized, seen);
}

/// The fuzz targets' scene directory, made once per process under the system temp directory.
pub fn fuzz_scene_dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let root = std::env::temp_dir().join(format!("penumbra-fuzz-{}", std::process::id()));
        populate_scene_dir(&root).expect("cannot create the fuzz scene directory")
    })
}
