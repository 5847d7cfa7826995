//! The code paths the fuzz targets exercise, written once and shared: each `fuzz_targets/*.rs`
//! includes this file with `#[path = "common.rs"] mod common;`, and
//! `tests/suite/fuzz_corpus_replay.rs` includes it the same way to replay every corpus and
//! regression input under `cargo test`. It depends only on `penumbra` and `std` (no
//! `arbitrary`), so the replay test needs no extra dependency.
//!
//! Every function takes raw fuzzer bytes and must not panic on any of them, except on the
//! `assert!`s written here, which state invariants the library promises (a panic there is a
//! bug the fuzzer found, not bad input).

use glam::{DVec2, DVec3, Vec3};
use penumbra::geometry::loops::{silhouette_loops, vertex_degrees};
use penumbra::geometry::penumbra_wedge::{
    build_wedges, cap_triangles, far_distance, li_amount, light_intensity, screen_wedge,
    wedge_triangles, WedgeOptions,
};
use penumbra::geometry::shadow_volume::{shadow_volume_triangles, Capping};
use penumbra::geometry::silhouette::{light_facing, possible_silhouettes};
use penumbra::geometry::ssv_wedge::{SsvWedge, WedgeLight, WedgeVertex};
use penumbra::geometry::tight_wedge::{
    adjusted_edge, bounding_planes, halves_from_planes, polyhedron_from_planes, wedge_clip_box,
    HalfSpace,
};
use penumbra::gpu::counters::Counters;
use penumbra::gpu::raster::{bin, draw, no_tile_culling};
use penumbra::gpu::setup::{setup_triangle, CullMode, RasterTriangle};
use penumbra::gpu::shader_float::Fp32;
use penumbra::gpu::tiling::Tiling;
use penumbra::gpu::transform::{ClipVertex, Projection};
use penumbra::light::coverage::{
    clip_to_light_cone, edge_coverage_exact, projected_edge_in_light, projected_edge_near_clipped,
    quad_side, segment_coverage, sphere_edge_coverage_exact, RectLight,
};
use penumbra::light::coverage_texture::{
    coverage_texture, CoverageFilter, CoverageTexture, CoverageTextureKey, MIN_N,
};
use penumbra::light::lookup_tables::TableFilter;
use penumbra::light::radial_parts::{edge_in_parts, NEAR_FRACTION, PART_COUNT};
use penumbra::methods::ssv_optimized::{CoverageMode, LightModel};
use penumbra::scene::adjacency;
use penumbra::scene::file::{parse_scene_str, Format};
use penumbra::scene::mesh_io::{parse_mesh, weld_identical, MeshFormat};
use penumbra::scene::validate::{light_shape_touches, validate, validate_light};
use penumbra::scene::{Camera, Light, LightShape, Mesh, RgbTexture, Scene};
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

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

/// The `obj` path: `parse_mesh` as OBJ on the raw bytes (sometimes with a mirroring transform,
/// which flips the winding), the bit-identical weld, then [`mesh_path`].
pub fn obj(data: &[u8]) {
    mesh_file(data, MeshFormat::Obj);
}

/// The `ply` path: `parse_mesh` as PLY (ASCII or binary, either byte order), then as [`obj`].
pub fn ply(data: &[u8]) {
    mesh_file(data, MeshFormat::Ply);
}

/// The `stl` path: `parse_mesh` as STL (ASCII or binary), then as [`obj`].
pub fn stl(data: &[u8]) {
    mesh_file(data, MeshFormat::Stl);
}

/// The `gltf` path: `parse_mesh` as glTF (JSON with `data:` buffers, or GLB; no directory, so an
/// external buffer is an error), then as [`obj`].
pub fn gltf(data: &[u8]) {
    mesh_file(data, MeshFormat::Gltf);
}

/// A mesh file of `format` in `data`: read (it may fail with an error, never panic; the
/// reader's promises are checked: indices in range, positions finite), sometimes mirrored,
/// welded, then [`mesh_path`].
fn mesh_file(data: &[u8], format: MeshFormat) {
    let h = fnv1a(data);
    let Ok(raw) = parse_mesh(data, format, "fuzz", None) else {
        return;
    };
    assert_eq!(raw.format, format);
    assert!(!raw.triangles.is_empty());
    assert!(raw.positions.iter().all(|p| p.is_finite()));
    assert!(raw
        .triangles
        .iter()
        .flatten()
        .all(|&i| (i as usize) < raw.positions.len()));
    let raw = if h & 1 == 1 {
        match raw.transformed(glam::Mat4::from_scale(glam::Vec3::new(-1.0, 1.0, 1.0))) {
            Ok(m) => m,
            Err(_) => return,
        }
    } else {
        raw
    };
    mesh_path(&weld_identical(raw, "fuzz", [0.8; 3]), h);
}

/// On a mesh as a file reader makes it: `adjacency::build`; if the mesh is closed, the
/// light-facing triangles, possible silhouettes, silhouette loops and both kinds of shadow
/// volume from a light point derived from `h` (the input's hash), then those volumes through
/// setup, binning and traversal with a fixed camera at 32×32.
///
/// The light is one of: a point in [−4, 4)³, a mesh vertex (light on the surface) or the
/// centre of the mesh bounds (usually inside the mesh).
fn mesh_path(mesh: &Mesh, h: u64) {
    let Ok(adj) = adjacency::build(mesh) else {
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

    let facing = light_facing(mesh, light);
    assert_eq!(facing.len(), mesh.triangles.len());
    let sil = possible_silhouettes(mesh, &adj, &facing);
    // Paper V: facing decided once per triangle gives even degree at every silhouette vertex,
    // so the edges always split into closed loops that use each edge once.
    assert!(vertex_degrees(&sil).values().all(|d| d % 2 == 0));
    let loops = silhouette_loops(&sil).unwrap_or_else(|e| panic!("silhouette loops: {e}"));
    assert_eq!(loops.iter().map(Vec::len).sum::<usize>(), sil.len());

    let proj = Projection::new(&fixed_camera(), SIZE, SIZE, 0.1);
    let open = shadow_volume_triangles(&[(mesh, &adj)], light, &proj, Capping::Open);
    assert_eq!(open.len(), 2 * sil.len());
    let capped = shadow_volume_triangles(&[(mesh, &adj)], light, &proj, Capping::Capped);
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
        None,
        no_tile_culling,
        |t, storage: &mut Vec<u32>, _tri, f, _c, _tap| {
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

// ---------------------------------------------------------------------------------------------
// Wedge construction and coverage (targets `pw_wedges`, `ssv_wedge`, `tight_wedge`, `coverage`).
//
// What they are fed is what scene validation lets through: every number a finite f32 (as a
// scene stores it; validation refuses NaN and infinities), lights that `validate_light` accepts
// (radius > 0; rectangle sides non-zero and not parallel), receivers finite in f32 (they are
// points of the scene's meshes). Edges are any two finite points, coincident ones and edges
// whose line passes through the light center included (a mesh may repeat a position under two
// indices). An edge that touches or crosses the light cannot come from a validated scene
// (validation refuses meshes that touch a light): such edges still must not panic anything,
// but the properties that rely on it (wedges hold the penumbra and all coverage) are checked
// only for edges apart from the light, decided by validation's own rule
// (`light_shape_touches`). The `pw_wedges` target builds whole meshes and runs the full scene
// validation instead.
// ---------------------------------------------------------------------------------------------

/// How far (relative to the far distance) a Paper I wedge's face vertex may lie off its plane
/// or outside another: the construction keeps vertices within 10⁻⁷ of every plane and snaps
/// them by up to 10⁻⁶ to shared points (`penumbra_wedge`'s face tolerance).
const FACE_SLACK: f64 = 1e-5;

/// Most receiver points one geometry input is decoded into.
const MAX_RECEIVERS: u8 = 8;

/// How far an area fraction computed in f64 from points clipped to the light may exceed 1:
/// each clipped coordinate may overshoot the border by rounding.
const UNIT_SLACK: f64 = 1e-12;

/// How far two f64 computations of one coverage (the same edge clipped another way or in the
/// other direction) may differ by rounding, on top of [`ROUNDING_GROWTH`] × the machine epsilon
/// × the condition of the projection ([`rect_condition`], [`sphere_condition`]): a
/// millionth, far below one step of the finest V-buffer that is not f32 (f16, 2⁻¹¹) and above
/// what clipping near the disk's rim or a double root loses in well-conditioned cases
/// (1.3·10⁻⁹ seen).
const COVERAGE_TOL: f64 = 1e-6;

/// How many machine epsilons of rounding, times the condition of the projection, two
/// computations of one coverage may differ by: a few roundings per clip step, four clip steps
/// and a sum of areas.
const ROUNDING_GROWTH: f64 = 256.0;

/// Margin (relative to the largest coordinate involved) within which a point counts as on a
/// wedge's boundary, where plane distances computed in f64 may have either sign: 10× the
/// tolerance within which `wedge_halfspaces` accepts a plane generators lie outside of.
const REL_MARGIN: f64 = 1e-8;

/// Narrowest light (radians, seen from the edge's far end) whose wedges are checked to hold
/// the penumbra and all coverage. Narrower, the penumbra is thinner than 10⁻¹⁰ of its distance,
/// far below the f32 spacing of any receiver, and Paper IV's construction can lose the part of
/// the wedge near the edge (fuzz/README.md, "Findings": a light 1.5·10⁻¹² rad wide).
const MIN_LIGHT_ANGLE: f64 = 1e-10;

/// Smallest sine of the angle between the hard shadow quad's plane and the direction from the
/// light center to the receiver for which two ways of computing the coverage are compared.
/// Closer to the plane, the signed coverage jumps by 1 across it (the quad's projection runs
/// through the light center), and [`edge_coverage_exact`]'s homogeneous clipping, whose two
/// vertices at infinity point in nearly opposite directions there, loses up to a quarter of
/// the light (fuzz/README.md, "Findings").
const MIN_QUAD_PLANE_SINE: f64 = 1e-6;

impl Bytes<'_> {
    /// The next two bytes as a little-endian i16.
    fn i16(&mut self) -> i16 {
        i16::from_le_bytes(self.array())
    }

    /// A finite `f32` in one of four encodings chosen by the low bits of a mode byte:
    /// 0 → a signed byte / 4 (a coarse grid, so coincident points, parallel edges and points
    /// on planes are common); 1 → i16 / 1024; 2 → i16 · 2^(mode/4 − 40) (from 2⁻⁴⁰ to 2³⁸);
    /// 3 → raw little-endian bits (the whole f32 range, subnormals included), a non-finite
    /// value read as 0.
    fn finite_f32(&mut self) -> f32 {
        let mode = self.u8();
        match mode & 3 {
            0 => f32::from(self.u8() as i8) / 4.0,
            1 => f32::from(self.i16()) / 1024.0,
            2 => f32::from(self.i16()) * pow2(i32::from(mode >> 2) - 40),
            _ => {
                let x = f32::from_le_bytes(self.array());
                if x.is_finite() {
                    x
                } else {
                    0.0
                }
            }
        }
    }

    /// A point of three [`Bytes::finite_f32`].
    fn vec3(&mut self) -> Vec3 {
        Vec3::new(self.finite_f32(), self.finite_f32(), self.finite_f32())
    }

    /// A fraction in [0, 1]: one byte / 255.
    fn fraction(&mut self) -> f64 {
        f64::from(self.u8()) / 255.0
    }

    /// A fraction in [−1, 1]: one signed byte / 127 (−128 read as −1).
    fn signed_fraction(&mut self) -> f64 {
        (f64::from(self.u8() as i8) / 127.0).max(-1.0)
    }
}

/// 2^e as an `f32` for e in −126..=127, built from its bits (exact).
fn pow2(e: i32) -> f32 {
    f32::from_bits(((e + 127) as u32) << 23)
}

/// A light from the input: the center, then a sphere's radius (its magnitude) or a rectangle's
/// half-extents `u`, `v`; `None` when [`validate_light`] refuses it, since no such light
/// reaches a method.
fn decode_light(r: &mut Bytes, sphere: bool) -> Option<Light> {
    let center = r.vec3();
    let shape = if sphere {
        LightShape::Sphere {
            radius: r.finite_f32().abs(),
        }
    } else {
        LightShape::Rect {
            u: r.vec3(),
            v: r.vec3(),
        }
    };
    let light = Light { center, shape };
    validate_light(&light).ok().map(|()| light)
}

/// A point of `light` from the input: `c + s·u + t·v` with s, t ∈ [−1, 1] on a rectangle, the
/// center plus the radius times a vector of the unit ball in a sphere.
fn light_point(r: &mut Bytes, light: &WedgeLight) -> DVec3 {
    match light {
        WedgeLight::Rect(l) => {
            let (s, t) = (r.signed_fraction(), r.signed_fraction());
            l.center + l.u * s + l.v * t
        }
        WedgeLight::Sphere { center, radius } => {
            let d = DVec3::new(
                r.signed_fraction(),
                r.signed_fraction(),
                r.signed_fraction(),
            );
            *center + d / d.length().max(1.0) * *radius
        }
    }
}

/// A receiver point and whether it was built in the edge's penumbra volume.
struct Receiver {
    /// The point.
    p: DVec3,
    /// Whether `p` is on a ray from a light point through a point of the edge, beyond the edge
    /// (every penumbra wedge of the edge must hold it).
    penumbra: bool,
}

/// Up to [`MAX_RECEIVERS`] receiver points, each either any point ([`Bytes::vec3`]) or a point
/// `e + λ(e − l)` of the penumbra volume of the edge `e0 e1` (`e` on the edge, `l` a point of
/// the light, λ ∈ [0, 2⁹]). Points that are not finite in f32 are left out: receivers are
/// points of the scene's meshes.
fn receivers(r: &mut Bytes, light: &WedgeLight, e0: DVec3, e1: DVec3) -> Vec<Receiver> {
    let n = r.u8() % (MAX_RECEIVERS + 1);
    let mut out = Vec::new();
    for _ in 0..n {
        let rcv = if r.u8() & 1 == 0 {
            Receiver {
                p: r.vec3().as_dvec3(),
                penumbra: false,
            }
        } else {
            let e = e0.lerp(e1, r.fraction());
            let l = light_point(r, light);
            let lambda = r.fraction() * f64::from(pow2(i32::from(r.u8() & 15) - 6));
            Receiver {
                p: e + (e - l) * lambda,
                penumbra: true,
            }
        };
        if rcv.p.as_vec3().is_finite() {
            out.push(rcv);
        }
    }
    out
}

/// The largest absolute coordinate of `points` (0 for none): the scale of the rounding errors
/// of plane distances computed from them.
fn magnitude<'a>(points: impl IntoIterator<Item = &'a DVec3>) -> f64 {
    points
        .into_iter()
        .map(|p| p.abs().max_element())
        .fold(0.0, f64::max)
}

/// The largest absolute coordinate of a point of `light`.
fn light_magnitude(light: &WedgeLight) -> f64 {
    match light {
        WedgeLight::Rect(l) => magnitude(&l.corners()),
        WedgeLight::Sphere { center, radius } => magnitude([center]) + radius,
    }
}

/// The sine of the angle between the plane through the light center `c` and the edge `e0 e1`
/// (the hard shadow quad's plane) and the direction from `c` to `p`; 0 when the plane or the
/// direction is undefined.
fn quad_plane_sine(c: DVec3, p: DVec3, e0: DVec3, e1: DVec3) -> f64 {
    let n = (e0 - c).cross(e1 - c);
    let d = p - c;
    let s = n.dot(d).abs() / (n.length() * d.length());
    if s.is_finite() {
        s
    } else {
        0.0
    }
}

/// How much projecting the edge `e0 e1` from `p` onto the rectangle `l` amplifies rounding:
/// [`edge_coverage_exact`] clips homogeneous light-plane points whose coordinates for an end
/// `e` are `S = s_e·h_p − s_p·h_e` (T likewise) and `W = h_p − h_e` (its ray: `W = −h_e`; where
/// the slab cuts the ray: `W = 0`), each computed with an error of ε times the size of its
/// terms, and interpolates between them, which carries that error over to the smallest of
/// them. That is the largest terms over the smallest such coordinate (|S, T| or |W|, or `h_p`,
/// the slab's thickness), among them the two points where the slab cuts the edge:
/// - where it crosses the light's plane, `(s₀·h_p, t₀·h_p, h_p)`, whose quad side runs from the
///   light center through `(s₀, t₀)` (found by fuzzing: an edge crossing the plane 10⁻¹⁴ of the
///   light's size from its center got coverage −0.3755 one way and 0.3746 the other);
/// - where it crosses `p`'s level, `(h_p·(s_x − s_p), h_p·(t_x − t_p), 0)`, the direction from
///   `p` to the edge's point `x` there, which the border clips follow: a difference of light
///   coordinates of the size of `p`'s (found by fuzzing: a receiver on the edge, λ = 0, whose
///   `x` was `p` itself to rounding, gave a projected point at t = −2; a receiver 0.8 from `x`
///   and 5.5·10⁵ from the center of a light as large, its border 1.4·10⁻¹⁰ off).
///
/// Infinite (or NaN) when `p` or an end is in the light's plane, an end is at `p`'s level or
/// projects onto the light center, or the edge crosses the light's plane at its center or
/// `p`'s level at `p`.
fn rect_condition(l: &RectLight, p: DVec3, e0: DVec3, e1: DVec3) -> f64 {
    // A point's s and t carry the light frame's own rounding, ε·|x − c|·|dual| (found by
    // fuzzing: a rectangle 1.5·10²⁶ across, whose dual vectors' rounding put 10⁻¹⁸ of error
    // into light coordinates of size 10⁻²⁵): their sizes count at least that large.
    let scale = l.local_scale();
    let size = |x: DVec3, lx: DVec3| {
        let frame = (x - l.center).length() * scale;
        lx.x.abs().max(frame.x) + lx.y.abs().max(frame.y)
    };
    let lp = l.local(p);
    let p_size = size(p, lp);
    let (mut terms, mut smallest) = (0.0f64, f64::INFINITY);
    let mut projected = [DVec2::ZERO; 2];
    for (i, e) in [e0, e1].into_iter().enumerate() {
        let le = l.local(e);
        let s = le.x * lp.z - lp.x * le.z;
        let t = le.y * lp.z - lp.y * le.z;
        projected[i] = DVec2::new(s, t);
        terms = terms
            .max(size(e, le) * lp.z.abs() + p_size * le.z.abs())
            .max(lp.z.abs() + le.z.abs());
        smallest = smallest
            .min(s.abs().max(t.abs()))
            .min((lp.z - le.z).abs())
            .min(le.z.abs())
            .min(lp.z.abs());
    }
    // How far the projected edge's line passes from the light center (in S, T units): where
    // it runs through the center, the quad's region flips between the two half-lights (p
    // crosses the quad's plane as seen in the light's frame). Found by fuzzing: the
    // 1.5·10²⁶ light above, the line 10⁻²⁵ of the light from its center.
    let [a, b] = projected;
    smallest = smallest.min(a.perp_dot(b).abs() / a.length().max(b.length()));
    let (l0, l1) = (l.local(e0), l.local(e1));
    // The edge's points at the light's plane (height 0) and at p's level, relative to the
    // center and to p.
    for (level, from) in [(0.0, DVec3::ZERO), (lp.z, lp)] {
        if (l0.z - level) * (l1.z - level) < 0.0 {
            let x = l0.lerp(l1, (level - l0.z) / (l1.z - l0.z)) - from;
            smallest = smallest.min(x.x.abs().max(x.y.abs()) * lp.z.abs());
        }
    }
    terms / smallest
}

/// 1 / the sine of the angle the edge `e0 e1` subtends at `p` (`|e0 − p|·|e1 − p| / |(e0 − p) ×
/// (e1 − p)|`): how nearly `p` sees the edge end-on, its line running through `p`. Infinite
/// (or NaN) when `p` is on the edge's line.
fn end_on(p: DVec3, e0: DVec3, e1: DVec3) -> f64 {
    let (a, b) = (e0 - p, e1 - p);
    a.length() * b.length() / a.cross(b).length()
}

/// How much the light space of [`clip_to_light_cone`] amplifies rounding for the edge `e0 e1`
/// seen from `p` by the sphere (`center`, `radius`): an end's offset from the center in radii,
/// over its height above `p`'s level as a fraction of the light's (the projection divides by
/// it), and 1 / the sine of the angle the edge subtends at `p` (seen end-on, the edge's line
/// runs through the cone's apex and the cone's quadratic degenerates). Infinite when an end is
/// at `p`'s level or `p` is on the edge's line.
fn sphere_condition(center: DVec3, radius: f64, p: DVec3, e0: DVec3, e1: DVec3) -> f64 {
    sphere_end_factor(center, radius, p, e0, e1).max(end_on(p, e0, e1))
}

/// The largest of [`sphere_condition`]'s per-end factors (at least 1): an end's offset from the
/// center in radii over its height above `p`'s level as a fraction of the light's.
fn sphere_end_factor(center: DVec3, radius: f64, p: DVec3, e0: DVec3, e1: DVec3) -> f64 {
    [e0, e1]
        .iter()
        .map(|e| (1.0 + (*e - center).length() / radius) / height_fraction(center, p, *e).abs())
        .fold(1.0, f64::max)
}

/// The height of `e` above `p` toward the light center, as a fraction of the center's (0 at
/// `p`'s level, 1 in the facing disk's plane): the light space's z of [`clip_to_light_cone`].
fn height_fraction(center: DVec3, p: DVec3, e: DVec3) -> f64 {
    let w = center - p;
    let dist = w.length();
    (e - p).dot(w) / dist / dist
}

/// 1 / the smallest height fraction at which [`clip_to_light_cone`]'s chord can end next to the
/// cone's apex `p`: an edge end's ([`height_fraction`]), or the edge's line passing `p`, within
/// about 1 / [`end_on`] of it. At least 1.
fn apex_factor(center: DVec3, p: DVec3, e0: DVec3, e1: DVec3) -> f64 {
    [e0, e1]
        .iter()
        .map(|e| 1.0 / height_fraction(center, p, *e).abs())
        .fold(end_on(p, e0, e1).max(1.0), f64::max)
}

/// How much [`clip_to_light_cone`] amplifies rounding in its chord's ends: the product of
/// [`sphere_condition`]'s two kinds of factor, not their maximum. The light-space coordinates
/// carry errors of ε × an end's factor (its offset in radii over its height fraction); the
/// chord's ends are roots of the cone's quadratic in those coordinates, and where the edge's
/// line passes the cone's apex (`p`) at a small angle the two roots close in on a double root,
/// moving by the coordinate error times the end-on factor (1 / the sine of the angle the edge
/// subtends at `p`). Found by fuzzing: a receiver 1.4·10⁻⁴ of the edge's length beside it
/// (end-on 1524, ends 101 and 156) got chord ends 4.8·10⁻⁵ outside the disk, above the square
/// root of the maximum's rounding (9·10⁻⁶) and below the product's (1.2·10⁻⁴); the same in a
/// scene 2¹²⁶ times larger (radius 0.085 instead of 10⁻³⁹), as f64 scaling by a power of two
/// is exact: rounding in the geometry, not subnormals.
fn sphere_chord_condition(center: DVec3, radius: f64, p: DVec3, e0: DVec3, e1: DVec3) -> f64 {
    end_on(p, e0, e1).max(1.0) * sphere_end_factor(center, radius, p, e0, e1)
}

/// [`rect_condition`] or [`sphere_condition`] for `light`.
fn condition(light: &WedgeLight, p: DVec3, e0: DVec3, e1: DVec3) -> f64 {
    match light {
        WedgeLight::Rect(l) => rect_condition(l, p, e0, e1),
        WedgeLight::Sphere { center, radius } => sphere_condition(*center, *radius, p, e0, e1),
    }
}

/// Largest projection condition for which results are compared at all: beyond it (ε·cond
/// above 2·10⁻⁶) rounding may leave nothing of the answer.
const MAX_CONDITION: f64 = 1e10;

/// The rounding error of a light-space coordinate or coverage computed through a projection
/// of condition `cond`; infinite beyond [`MAX_CONDITION`] (or for a NaN condition).
fn rounding(cond: f64) -> f64 {
    if cond <= MAX_CONDITION {
        ROUNDING_GROWTH * f64::EPSILON * cond
    } else {
        f64::INFINITY
    }
}

/// The tolerance between two computations of one coverage with projection condition `cond`.
fn coverage_tol(cond: f64) -> f64 {
    COVERAGE_TOL + rounding(cond)
}

/// Whether `n` is finite and of unit length (to rounding).
fn is_unit(n: DVec3) -> bool {
    n.is_finite() && (n.length() - 1.0).abs() <= 1e-12
}

/// The exact signed coverage of `light` by the hard shadow quad of `e0 e1` seen from `p`
/// ([`edge_coverage_exact`] for a rectangle, [`sphere_edge_coverage_exact`] for a sphere).
fn exact_coverage(light: &WedgeLight, p: DVec3, e0: DVec3, e1: DVec3) -> f64 {
    match light {
        WedgeLight::Rect(l) => edge_coverage_exact(l, p, e0, e1),
        WedgeLight::Sphere { center, radius } => {
            sphere_edge_coverage_exact(*center, *radius, p, e0, e1)
        }
    }
}

/// The light, edge and receivers every edge target starts from: a selector byte (bit 0: a
/// sphere, else a rectangle; the other bits are the target's), the light ([`decode_light`]),
/// the edge's two end points and the receivers ([`receivers`]).
struct EdgeInput {
    /// The selector byte.
    select: u8,
    /// The scene light.
    light: Light,
    /// The same light in f64 ([`WedgeLight::from_light`]).
    shape: WedgeLight,
    /// The edge.
    e0: DVec3,
    /// The edge's other end.
    e1: DVec3,
    /// Whether the edge is apart from the light, as every edge of a validated scene is
    /// (`light_shape_touches` on the edge as a degenerate triangle).
    apart: bool,
    /// Receiver points.
    receivers: Vec<Receiver>,
}

impl EdgeInput {
    /// Decodes the input (see the type); `None` when the light is refused.
    fn decode(r: &mut Bytes) -> Option<Self> {
        let select = r.u8();
        let light = decode_light(r, select & 1 == 1)?;
        let shape = WedgeLight::from_light(&light).expect("a rect or sphere light");
        let ends = [r.vec3(), r.vec3()];
        let edge = Mesh {
            name: "edge".into(),
            positions: ends.to_vec(),
            triangles: vec![[0, 1, 1]],
            color: [0.8; 3],
            receiver_only: false,
            repairs: Default::default(),
        };
        let apart = light_shape_touches(&edge, &light).is_none();
        let [e0, e1] = ends.map(|e| e.as_dvec3());
        let receivers = receivers(r, &shape, e0, e1);
        Some(EdgeInput {
            select,
            light,
            shape,
            e0,
            e1,
            apart,
            receivers,
        })
    }

    /// The largest absolute coordinate of the light, the edge and `p`.
    fn magnitude(&self, p: DVec3) -> f64 {
        light_magnitude(&self.shape).max(magnitude([&self.e0, &self.e1, &p]))
    }

    /// The margin within which a point of magnitude up to `m` counts as on the boundary of a
    /// wedge of the edge: [`REL_MARGIN`] of `m`, plus what rounding can move the wedge's planes
    /// by (fuzz/README.md, "Findings"):
    /// - both papers' wedges turn about the adjusted edge ([`adjusted_edge`]), whose moved end
    ///   is computed from the light center with an error of ε·(|c| + d_far); over the adjusted
    ///   edge's length that turns the wedge by up to ε·(|c| + d_far)/length (a light 10³⁸ away
    ///   turns a zero-length edge into a 31-unit one);
    /// - a wedge is about as thin as the light's angular size α seen from the edge, and planes
    ///   and faces found from points that close together (cross products of generators, Newell
    ///   normals of sliver faces of a clipped polyhedron) are off by ε/α (a light 10⁻¹⁰ rad wide
    ///   gave faces misplaced by 10⁻⁷);
    /// - Paper III's wedge is built in a frame around the edge whose axis to the light center
    ///   is the center's offset from the edge's line, found from an end of the edge with an
    ///   error of ε·d_far: off by ε·d_far / (the center's distance from the line) (an edge
    ///   whose line passed 5·10⁻¹⁰ from the center of a light 7·10⁴ away got a wedge turned
    ///   by 90°).
    ///
    /// Infinite for an edge that adjusts to a point, and for a light narrower than
    /// [`MIN_LIGHT_ANGLE`] seen from the edge.
    fn wedge_margin(&self, m: f64) -> f64 {
        let c = self.shape.center();
        let [a, b] = adjusted_edge(c, self.e0, self.e1);
        let d_far = (self.e0 - c).length().max((self.e1 - c).length());
        let turn = (magnitude([&c]) + d_far) / (b - a).length();
        let angle = self.light_radius() / d_far;
        let line = (c - self.e0)
            .cross((self.e1 - self.e0).normalize_or_zero())
            .length();
        let rounding = 64.0 * f64::EPSILON * (turn + 1.0 / angle + d_far / line);
        if rounding.is_finite() && angle >= MIN_LIGHT_ANGLE {
            m * (REL_MARGIN + rounding)
        } else {
            f64::INFINITY
        }
    }

    /// The radius of the light's bounding sphere around its center.
    fn light_radius(&self) -> f64 {
        match self.shape {
            WedgeLight::Rect(l) => (l.u + l.v).length().max((l.u - l.v).length()),
            WedgeLight::Sphere { radius, .. } => radius,
        }
    }
}

/// The `coverage` path: for a rectangle or a sphere light, an edge and receivers (see
/// [`EdgeInput`]), every coverage function of `light::coverage` and `light::radial_parts`, the
/// coverage texture lookups and `ssv-optimized`'s coverage in each of its modes, with the
/// properties in [`rect_coverage`] and [`sphere_coverage`].
pub fn coverage(data: &[u8]) {
    let mut r = Bytes(data);
    let Some(input) = EdgeInput::decode(&mut r) else {
        return;
    };
    let (e0, e1) = (input.e0, input.e1);
    let model = LightModel::from_shape(input.light.center, &input.light.shape)
        .expect("a rect or sphere light");
    for rcv in &input.receivers {
        let p = rcv.p;
        match input.shape {
            WedgeLight::Rect(l) => rect_coverage(&l, p, e0, e1, input.apart),
            WedgeLight::Sphere { center, radius } => {
                sphere_coverage(center, radius, p, e0, e1, input.apart)
            }
        }
        for mode in [
            CoverageMode::Exact,
            CoverageMode::Tables(TableFilter::Nearest),
            CoverageMode::Tables(TableFilter::Bilinear),
        ] {
            let c = model.coverage(p, e0, e1, mode);
            assert!((0.0..=1.0).contains(&c), "{mode:?}: coverage {c}");
        }
    }
}

/// Checks the coverage of the rectangle `l` by the edge `e0 e1` seen from `p`:
/// - [`edge_coverage_exact`] is finite, in [−1, 1], signed as [`quad_side`], and, with `p` off
///   the quad's plane ([`MIN_QUAD_PLANE_SINE`]), negated (to rounding, [`coverage_tol`]) when
///   the edge is reversed;
/// - [`projected_edge_in_light`] gives points in the light square (to rounding) whose
///   [`segment_coverage`] and coverage-texture lookups (every filter, grey and RGB) are in
///   [0, 1]; where the edge lies strictly between the light's plane and `p` (Paper III §3.3:
///   the texture's function is the coverage there) and `p` is off the quad's plane
///   ([`MIN_QUAD_PLANE_SINE`]), `segment_coverage` is the exact coverage's magnitude, and the
///   exact coverage is 0 when nothing projects into the light;
/// - [`edge_in_parts`] gives regions in their part with areas in [0, 1], and where the edge
///   lies strictly between the light's plane and the local near plane (so neither clips it)
///   and `p` is off the quad's plane, the four areas sum to 4 × the exact coverage's
///   magnitude;
/// - [`projected_edge_near_clipped`] is finite.
///
/// The comparisons between computations (antisymmetry, segment against exact coverage, the
/// parts' sum) need an edge `apart` from the light, as every edge of a validated scene is
/// (`scene::validate` refuses geometry that touches an area light): an edge through the light
/// itself has no well-defined coverage there (found by fuzzing: an edge crossing a rectangle
/// 4.7·10⁻¹⁰ from its center, coverage 0.4999975 one way and −0.5002615 the other). The range
/// checks hold for every edge.
fn rect_coverage(l: &RectLight, p: DVec3, e0: DVec3, e1: DVec3, apart: bool) {
    let at = || format!("p {p}, edge {e0} {e1}, light {l:?}");
    let c = edge_coverage_exact(l, p, e0, e1);
    assert!(
        c.is_finite() && c.abs() <= 1.0 + UNIT_SLACK,
        "coverage {c}: {}",
        at()
    );
    let side = quad_side(l.center, p, e0, e1);
    assert!(
        c == 0.0 || c.signum() == side,
        "coverage {c}, side {side}: {}",
        at()
    );
    let off_plane = apart && quad_plane_sine(l.center, p, e0, e1) >= MIN_QUAD_PLANE_SINE;
    let cond = rect_condition(l, p, e0, e1);
    let tol = coverage_tol(cond);
    let reversed = edge_coverage_exact(l, p, e1, e0);
    assert!(
        !off_plane || (c + reversed).abs() <= tol,
        "coverage {c}, reversed {reversed}: {}",
        at()
    );
    // Heights of the edge's ends as fractions of p's (0 in the light's plane, 1 at p's level).
    let hp = l.local(p).z;
    let between = |top: f64| {
        off_plane
            && [e0, e1].iter().all(|e| {
                let h = l.local(*e).z / hp;
                h > 0.0 && h < top
            })
    };
    match projected_edge_in_light(l, p, e0, e1) {
        Some([a, b]) => {
            for q in [a, b] {
                assert!(
                    q.is_finite() && q.abs().max_element() <= 1.0 + UNIT_SLACK + rounding(cond),
                    "projected point {q} outside the light: {}",
                    at()
                );
            }
            let f = segment_coverage(a, b);
            assert!((0.0..=1.0 + UNIT_SLACK).contains(&f), "{f}: {}", at());
            if between(1.0) {
                assert!(
                    (f - c.abs()).abs() <= tol,
                    "segment coverage {f}, exact {c}: {}",
                    at()
                );
            }
            for texture in coverage_textures() {
                for filter in [
                    CoverageFilter::Nearest,
                    CoverageFilter::Bilinear,
                    CoverageFilter::Quadrilinear,
                ] {
                    let v = texture.lookup(a, b, filter);
                    assert!(
                        v.iter().all(|x| (0.0..=1.0 + UNIT_SLACK).contains(x)),
                        "{filter:?} lookup {v:?} of ({a}, {b})"
                    );
                }
            }
        }
        None => {
            if between(1.0) {
                assert!(c.abs() <= tol, "no projection, coverage {c}: {}", at());
            }
        }
    }
    let mut total = 0.0;
    for region in edge_in_parts::<f64>(l, p, e0, e1).iter().flatten() {
        let b = region.bounds::<Fp32>();
        assert!(
            region.area.is_finite()
                && (0.0..=1.0 + UNIT_SLACK).contains(&region.area)
                && region.moment.is_finite()
                && region
                    .chord
                    .iter()
                    .all(|q| q.cmpge(DVec2::ZERO).all() && q.cmple(DVec2::ONE).all())
                && !b.is_empty()
                && b.left >= 0.0
                && b.bottom >= 0.0
                && b.right <= 1.0
                && b.top <= 1.0,
            "region {region:?}: {}",
            at()
        );
        total += region.area;
    }
    if between(1.0 - NEAR_FRACTION) {
        let parts = total / PART_COUNT as f64;
        assert!(
            (parts - c.abs()).abs() <= tol,
            "parts {parts}, exact {c}: {}",
            at()
        );
    }
    for near in [0.0, NEAR_FRACTION] {
        if let Some([a, b]) = projected_edge_near_clipped(l, p, e0, e1, near) {
            assert!(a.is_finite() && b.is_finite(), "{a} {b}: {}", at());
        }
    }
}

/// Checks the coverage of the disk the sphere (`center`, `radius`) shows `p` by the edge
/// `e0 e1`: [`sphere_edge_coverage_exact`] is finite, in [−1, 1], signed as [`quad_side`] and,
/// with `p` off the quad's plane, negated (to rounding) when the edge is reversed;
/// [`clip_to_light_cone`]'s chord lies in the unit disk (to the square root of the rounding of
/// [`sphere_chord_condition`]: its ends are roots of a quadratic, double where the edge's line
/// touches the cone; plus the rounding of [`apex_factor`]²: a chord end at a height fraction δ
/// above `p`, the cone's apex, is a root of the cone's quadratic, whose coefficients are of the
/// light's size (the clip's parameter starts near the center) while the cone there is δ wide:
/// off by ε/δ, which the projection divides by the height, δ again: ε/δ²; measured 2·ε·end_on²
/// where the edge's line passes p (end-on factors 8·10²…8·10⁶). Found by fuzzing: a receiver
/// 3·10⁻⁸ from the line of an edge 1.7·10³⁸ long, chord end 1.006 from the center, the coverage
/// right to 10⁻⁶; an edge end 1.5·10⁻⁸ of the light's distance above `p`, chord end 1.015).
///
/// As for [`rect_coverage`], the antisymmetry needs an edge `apart` from the light.
fn sphere_coverage(center: DVec3, radius: f64, p: DVec3, e0: DVec3, e1: DVec3, apart: bool) {
    let at = || format!("p {p}, edge {e0} {e1}, sphere {center} r {radius}");
    let c = sphere_edge_coverage_exact(center, radius, p, e0, e1);
    assert!(
        c.is_finite() && c.abs() <= 1.0 + UNIT_SLACK,
        "coverage {c}: {}",
        at()
    );
    let side = quad_side(center, p, e0, e1);
    assert!(
        c == 0.0 || c.signum() == side,
        "coverage {c}, side {side}: {}",
        at()
    );
    let off_plane = apart && quad_plane_sine(center, p, e0, e1) >= MIN_QUAD_PLANE_SINE;
    let cond = sphere_condition(center, radius, p, e0, e1);
    let tol = coverage_tol(cond);
    let reversed = sphere_edge_coverage_exact(center, radius, p, e1, e0);
    assert!(
        !off_plane || (c + reversed).abs() <= tol,
        "coverage {c}, reversed {reversed}: {}",
        at()
    );
    if let Some([a, b]) = clip_to_light_cone(center, radius, p, e0, e1) {
        let chord = rounding(sphere_chord_condition(center, radius, p, e0, e1));
        let apex = rounding(apex_factor(center, p, e0, e1) * apex_factor(center, p, e0, e1));
        for q in [a, b] {
            assert!(
                q.is_finite() && q.length() <= 1.0 + UNIT_SLACK + chord + chord.sqrt() + apex,
                "chord point {q} outside the disk: {}",
                at()
            );
        }
    }
}

/// The coverage textures the lookups are checked on, n = [`MIN_N`]: the grey one and the RGB
/// one of a fixed 2×2 light texture (computed once per process).
fn coverage_textures() -> &'static [Arc<CoverageTexture>; 2] {
    static TEXTURES: OnceLock<[Arc<CoverageTexture>; 2]> = OnceLock::new();
    TEXTURES.get_or_init(|| {
        let light = RgbTexture {
            width: 2,
            height: 2,
            texels: vec![
                [1.0, 0.5, 0.25],
                [0.2, 1.0, 0.7],
                [0.9, 0.1, 1.0],
                [0.5, 0.5, 0.5],
            ],
            source: "fuzz".into(),
        };
        [
            coverage_texture(&CoverageTextureKey::uniform(MIN_N)),
            coverage_texture(&CoverageTextureKey::textured(MIN_N, &light)),
        ]
    })
}

/// The `ssv_wedge` path: Paper III's wedge ([`SsvWedge::new`]) of the edge under a rectangle or
/// a sphere light (see [`EdgeInput`]). When it is built: its planes and vertices are finite
/// with unit normals and directions; and for an edge apart from the light, it holds every
/// penumbra receiver (within the rounding margin) and outside it (beyond the margin) the
/// edge's exact coverage is 0 (to rounding, [`coverage_tol`]) — what `ssv` relies on when it
/// adds coverage only inside wedges (Paper III §3.2.2).
pub fn ssv_wedge(data: &[u8]) {
    let mut r = Bytes(data);
    let Some(input) = EdgeInput::decode(&mut r) else {
        return;
    };
    let (e0, e1) = (input.e0, input.e1);
    let Some(w) = SsvWedge::new(&input.shape, e0, e1) else {
        return;
    };
    let at = || format!("edge {e0} {e1}, light {:?}", input.shape);
    assert!(
        w.top.iter().all(|p| p.is_finite())
            && w.planes
                .iter()
                .all(|h| h.origin.is_finite() && is_unit(h.normal)),
        "wedge {w:?}: {}",
        at()
    );
    for v in w.triangles.iter().flatten() {
        let ok = match v {
            WedgeVertex::Point(p) => p.is_finite(),
            WedgeVertex::Direction(d) => is_unit(*d),
        };
        assert!(ok, "vertex {v:?}: {}", at());
    }
    if !input.apart {
        return;
    }
    for rcv in &input.receivers {
        let margin = input.wedge_margin(input.magnitude(rcv.p));
        if rcv.penumbra {
            assert!(
                w.contains_within(rcv.p, margin),
                "penumbra point {} outside the wedge {w:?}: {}",
                rcv.p,
                at()
            );
        }
        if !w.contains_within(rcv.p, margin) {
            let c = exact_coverage(&input.shape, rcv.p, e0, e1);
            assert!(
                c.abs() <= coverage_tol(condition(&input.shape, rcv.p, e0, e1)),
                "coverage {c} at {} outside the wedge: {}",
                rcv.p,
                at()
            );
        }
    }
}

/// The `tight_wedge` path: Paper IV's tight wedge of the edge (see [`EdgeInput`]; selector bit
/// 1: `wedge = tight`, else `bounding-sphere`, as `ssv-optimized`'s `wedge` option; bits 2–7
/// pick a sphere's `sphere-sides`, 3…64; [`LightModel::wedge_halfspaces`]) clipped to the box
/// of a scene holding the light, the edge and the receivers ([`wedge_clip_box`]): the wedge's
/// half-spaces, [`polyhedron_from_planes`], [`halves_from_planes`], [`bounding_planes`], and
/// [`ConvexPolyhedron::split`] by a plane from the input. Checked:
/// - planes have finite unit normals, polyhedra finite vertices and faces of ≥ 3 vertices,
///   bounding planes are among the wedge's planes;
/// - for an edge apart from the light, inside the box (beyond the margin): every penumbra
///   receiver is in the whole wedge and, when the hard shadow quad has a plane (the edge's line
///   misses the light center; else both halves are empty and so is the coverage), in one of
///   its halves; outside the wedge or both halves the edge's exact coverage is 0 to rounding
///   (an empty wedge included: `ssv-optimized` and `wedge-blending` then draw nothing for the
///   edge);
/// - for an edge apart from the light whose quad has a plane, a point well inside the inner
///   (outer) half is on the umbra (lit) side of the hard shadow quad ([`quad_side`] ≤ 0, ≥ 0);
/// - the split's parts lie on their side of the plane, share the cut polygon as described, and
///   a point well inside the wedge is in one of them.
pub fn tight_wedge(data: &[u8]) {
    let mut r = Bytes(data);
    let Some(input) = EdgeInput::decode(&mut r) else {
        return;
    };
    let (a, b) = (input.e0, input.e1);
    let (cut_normal, cut_point) = (r.vec3().as_dvec3(), r.vec3().as_dvec3());
    let model = LightModel::from_shape(input.light.center, &input.light.shape)
        .expect("a rect or sphere light");
    let tight = input.select & 2 != 0;
    let sides = 3 + usize::from(input.select >> 2) % 62;
    let c = model.center();
    let mut positions = vec![a.as_vec3(), b.as_vec3()];
    positions.extend(input.receivers.iter().map(|rcv| rcv.p.as_vec3()));
    let scene = Scene {
        source: "fuzz".into(),
        width: SIZE,
        height: SIZE,
        camera: fixed_camera(),
        lights: vec![input.light.clone()],
        meshes: vec![Mesh {
            name: "fuzz".into(),
            positions,
            triangles: Vec::new(),
            color: [0.8; 3],
            receiver_only: false,
            repairs: Default::default(),
        }],
        methods: None,
        options: Default::default(),
        cli_options: Default::default(),
        ambient: 0.0,
    };
    let (lo, hi) = wedge_clip_box(scene.bounds());
    let at =
        || format!("edge {a} {b}, light {model:?}, tight {tight}, {sides} sides, box {lo} {hi}");

    let planes = model.wedge_halfspaces(tight, sides, a, b);
    for h in &planes {
        assert!(
            is_unit(h.normal) && h.offset.is_finite(),
            "plane {h:?}: {}",
            at()
        );
    }
    let whole = polyhedron_from_planes(&planes, lo, hi);
    let [inner, outer] = halves_from_planes(&planes, c, a, b, lo, hi);
    for poly in [&whole, &inner, &outer] {
        assert!(
            poly.faces
                .iter()
                .all(|f| f.len() >= 3 && f.iter().all(|v| v.is_finite())),
            "polyhedron {poly:?}: {}",
            at()
        );
    }
    for half in [&inner, &outer] {
        for h in bounding_planes(half, &planes) {
            assert!(planes.contains(&h), "bounding plane {h:?}: {}", at());
        }
    }
    let (bound_center, bound_radius) = model.bounding_sphere();
    let box_magnitude = magnitude([&lo, &hi]).max(bound_center.abs().max_element() + bound_radius);
    let margin = REL_MARGIN * box_magnitude;
    let wedge_margin = input.wedge_margin(box_magnitude);
    let quad_plane = (a - c).cross(b - c) != DVec3::ZERO;
    for rcv in &input.receivers {
        let p = rcv.p;
        let side = quad_side(c, p, a, b);
        if !input.apart || !quad_plane {
            continue;
        }
        if inner.contains(p, -margin) {
            assert!(
                side <= 0.0,
                "{p} well inside the inner half, side {side}: {}",
                at()
            );
        }
        if outer.contains(p, -margin) {
            assert!(
                side >= 0.0,
                "{p} well inside the outer half, side {side}: {}",
                at()
            );
        }
        let inside_box = p.cmpge(lo + wedge_margin).all() && p.cmple(hi - wedge_margin).all();
        if !inside_box {
            continue;
        }
        let in_halves = inner.contains(p, wedge_margin) || outer.contains(p, wedge_margin);
        if rcv.penumbra {
            assert!(
                whole.contains(p, wedge_margin),
                "penumbra point {p} outside the wedge {whole:?}: {}",
                at()
            );
            assert!(
                in_halves || !quad_plane,
                "penumbra point {p} outside both halves: {}",
                at()
            );
        }
        if !whole.contains(p, wedge_margin) || !in_halves {
            let cov = exact_coverage(&input.shape, p, a, b);
            assert!(
                cov.abs() <= coverage_tol(condition(&input.shape, p, a, b)),
                "coverage {cov} at {p} outside the wedge or its halves: {}",
                at()
            );
        }
    }
    if let Some(n) = cut_normal.try_normalize() {
        let plane = HalfSpace {
            normal: n,
            offset: n.dot(cut_point),
        };
        let (inside, outside, cut) = whole.split(&plane);
        let m = REL_MARGIN * box_magnitude.max(plane.offset.abs());
        assert!(
            inside.vertices().all(|v| plane.distance(*v) <= m)
                && outside.vertices().all(|v| plane.distance(*v) >= -m),
            "split of {whole:?} by {plane:?}: {}",
            at()
        );
        if cut.len() >= 3 && !inside.is_empty() && !outside.is_empty() {
            let last_out = outside.faces.last().expect("not empty");
            assert!(
                inside.faces.last() == Some(&cut)
                    && last_out.len() == cut.len()
                    && last_out[0] == cut[0]
                    && last_out[1..].iter().eq(cut[1..].iter().rev()),
                "cut {cut:?} not shared: {}",
                at()
            );
        }
        for rcv in &input.receivers {
            if whole.contains(rcv.p, -margin) {
                assert!(
                    inside.contains(rcv.p, m) || outside.contains(rcv.p, m),
                    "{} inside the wedge but in neither part of the split by {plane:?}: {}",
                    rcv.p,
                    at()
                );
            }
        }
    }
}

/// The `pw_wedges` path: Paper I/II penumbra wedges ([`build_wedges`]) of a closed mesh under a
/// sphere light, in a scene that passes [`validate`] as every rendered scene does. Input: a
/// flags byte (bit 0 extra corner wedges, bit 1 the near-parallel rule), the light's center and
/// radius, a ring size k ∈ 3..=12 and k + 2 vertices: a bipyramid over the ring (any positions,
/// so silhouettes of any shape, coincident vertices and self-intersections included; the
/// winding that validation accepts as outward, if either); then receivers, each any point or a
/// point near wedge w: along its edge, away from the light and across its quad normal.
/// Checked: the construction succeeds; planes have finite unit normals, faces ≥ 3 finite
/// vertices, rays, far points and caps are finite; every face vertex lies on its face's plane
/// and inside the other planes within [`FACE_SLACK`] of the far distance; the light intensity of every receiver in
/// every wedge is in [0, 1] (equations 1–3, plain and smoothed) and its LI amount in 0..=255;
/// the screen depth range of every wedge is in [0, 1]; and the wedges' and caps' triangles go
/// through setup, binning and traversal as in [`obj`].
pub fn pw_wedges(data: &[u8]) {
    let mut r = Bytes(data);
    let flags = r.u8();
    let center = r.vec3();
    let radius = r.finite_f32().abs();
    let k = 3 + u32::from(r.u8() % 10);
    let positions: Vec<Vec3> = (0..k + 2).map(|_| r.vec3()).collect();
    let mut triangles = Vec::new();
    for i in 0..k {
        let j = (i + 1) % k;
        triangles.push([k, i, j]);
        triangles.push([k + 1, j, i]);
    }
    let mut scene = Scene {
        source: "fuzz".into(),
        width: SIZE,
        height: SIZE,
        camera: fixed_camera(),
        lights: vec![Light {
            center,
            shape: LightShape::Sphere { radius },
        }],
        meshes: vec![Mesh {
            name: "fuzz".into(),
            positions,
            triangles,
            color: [0.8; 3],
            receiver_only: false,
            repairs: Default::default(),
        }],
        methods: None,
        options: Default::default(),
        cli_options: Default::default(),
        ambient: 0.0,
    };
    if validate(&scene).is_err() {
        for t in &mut scene.meshes[0].triangles {
            t.swap(1, 2);
        }
        if validate(&scene).is_err() {
            return;
        }
    }
    let mesh = &scene.meshes[0];
    let adj = adjacency::build(mesh).expect("a validated mesh");
    let c = center.as_dvec3();
    let opts = WedgeOptions {
        center: c,
        radius: f64::from(radius),
        far: far_distance(&scene, c),
        extra_corner_wedges: flags & 1 != 0,
        parallel_rule: flags & 2 != 0,
    };
    let set = build_wedges(&[(mesh, &adj)], &opts).unwrap_or_else(|e| panic!("build_wedges: {e}"));
    let at = || format!("mesh {:?}, light {c} r {radius}, {opts:?}", mesh.positions);
    assert!(
        set.open_wedges <= set.wedges.len() && set.extra_wedges <= set.wedges.len(),
        "{} open, {} extra of {}: {}",
        set.open_wedges,
        set.extra_wedges,
        set.wedges.len(),
        at()
    );
    let slack = FACE_SLACK * opts.far;
    for (i, w) in set.wedges.iter().enumerate() {
        let on_boundary = w.faces.iter().all(|(kind, f)| {
            f.iter().all(|v| {
                w.plane(*kind).eval(*v).abs() <= slack
                    && w.planes.iter().all(|pl| pl.eval(*v) <= slack)
            })
        });
        assert!(
            on_boundary,
            "wedge {i} {w:?}: a face vertex off the boundary: {}",
            at()
        );
        assert!(
            w.planes.iter().all(|pl| is_unit(pl.n) && pl.d.is_finite())
                && w.left_dir.is_finite()
                && w.right_dir.is_finite()
                && w.far_front.iter().all(|p| p.is_finite())
                && w.faces
                    .iter()
                    .all(|(_, f)| f.len() >= 3 && f.iter().all(|v| v.is_finite())),
            "wedge {i} {w:?}: {}",
            at()
        );
    }
    assert!(
        set.top_caps
            .iter()
            .chain(&set.bottom_caps)
            .flatten()
            .all(|p| p.is_finite()),
        "caps: {}",
        at()
    );

    let mut points = Vec::new();
    for _ in 0..r.u8() % (MAX_RECEIVERS + 1) {
        let near = r.u8() & 1 == 1 && !set.wedges.is_empty();
        points.push(if near {
            let w = &set.wedges[usize::from(r.u8()) % set.wedges.len()];
            let on_edge = w.a.lerp(w.b, r.fraction());
            let away = (w.far_front[0] + w.far_front[1]) * 0.5 - on_edge;
            on_edge + away * r.fraction() + w.n * (away.length() * 0.25 * r.signed_fraction())
        } else {
            r.vec3().as_dvec3()
        });
    }
    for p in &points {
        for w in &set.wedges {
            for smooth in [false, true] {
                let s = light_intensity(w, *p, smooth);
                let li = li_amount(s, 1);
                assert!(
                    (0.0..=1.0).contains(&s) && (0..=255).contains(&li),
                    "intensity {s} (LI {li}) at {p} in {w:?}: {}",
                    at()
                );
            }
        }
    }

    let proj = Projection::new(&fixed_camera(), SIZE, SIZE, 0.1);
    for w in &set.wedges {
        let [z0, z1] = screen_wedge(w, &proj).z_range;
        assert!(
            (0.0..=1.0).contains(&z0) && (0.0..=1.0).contains(&z1) && z0 <= z1,
            "depth range {z0} {z1}: {}",
            at()
        );
    }
    let tris: Vec<[ClipVertex; 3]> = wedge_triangles(&set, &proj)
        .iter()
        .chain(&cap_triangles(&set, &proj))
        .map(|t| t.clip)
        .collect();
    rasterize(&tris, CullMode::None, 8);
}
