//! Criterion benchmarks of loading a 10⁶-triangle model (issue 27, item 4: "loads, is repaired
//! and validated in under 1 s per million triangles"): a UV sphere of 998 000 triangles (500
//! stacks × 1000 slices, 499 002 vertices) written once as OBJ text and once as binary
//! little-endian PLY (shared vertices), and as the STL-like soup of its 2 994 000 corners.
//!
//! Groups and functions:
//!
//! * `load-obj`, `load-ply`: `load` is the whole load, [`load_scene_file`] of a scene holding
//!   only that mesh (read, parse, repair, validate, as `penumbra render` does); then its steps
//!   one by one: `parse` ([`read_mesh`]), `repair` ([`repair`] of the parsed mesh) and
//!   `validate` ([`validate`] of the scene holding the repaired mesh);
//! * `soup`: `repair` of the STL soup (weld 2 994 000 corners into 499 002 vertices, clean,
//!   orient, look for non-manifold and boundary edges), and the parts of validation: `adjacency`
//!   ([`adjacency::build`]), `point-touches` ([`point_touches`]: the light centre against every
//!   triangle) and `light-shape-touches` ([`light_shape_touches`]).
//!
//! The files and their scenes are written under the system's temporary directory
//! (`penumbra-bench-repair/`, kept, so that a render of `sphere-obj.toml` can be measured
//! with `/usr/bin/time -v`). Run with `cargo bench --bench repair` (`-- --quick --noplot` for
//! one short pass). Budget: flat sampling, 10 samples, 3 s of measurement.

use criterion::{black_box, criterion_group, criterion_main, Criterion, SamplingMode};
use glam::Vec3;
use penumbra::scene::adjacency;
use penumbra::scene::file::load_scene_file;
use penumbra::scene::mesh_io::read_mesh;
use penumbra::scene::procedural::uv_sphere;
use penumbra::scene::repair::{repair, RepairOptions};
use penumbra::scene::validate::{light_shape_touches, point_touches, validate};
use penumbra::scene::Mesh;
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The sphere as OBJ text (one `v` line per vertex, one `f` line per triangle).
fn obj_text(m: &Mesh) -> Vec<u8> {
    let mut obj = String::new();
    for p in &m.positions {
        let _ = writeln!(obj, "v {} {} {}", p.x, p.y, p.z);
    }
    for t in &m.triangles {
        let _ = writeln!(obj, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    obj.into_bytes()
}

/// The sphere as binary little-endian PLY (float x y z; uchar-counted int lists).
fn ply_bytes(m: &Mesh) -> Vec<u8> {
    let header = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\n\
         property float y\nproperty float z\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        m.positions.len(),
        m.triangles.len()
    );
    let mut out = header.into_bytes();
    for p in &m.positions {
        for c in p.to_array() {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in &m.triangles {
        out.push(3);
        for i in t {
            out.extend_from_slice(&(*i as i32).to_le_bytes());
        }
    }
    out
}

/// A scene of `mesh_file` under a small sphere light above it, seen from the side.
fn scene_text(mesh_file: &str) -> String {
    format!(
        r#"width = 64
height = 64
methods = ["hard-sv"]
[camera]
eye = [0.0, 1.5, 3.0]
target = [0.0, 1.0, 0.0]
up = [0, 1, 0]
vfov_deg = 45
[light]
type = "sphere"
center = [0.3, 3.0, 0.2]
radius = 0.2
[[meshes]]
mesh = "{mesh_file}"
"#
    )
}

/// Writes `bytes` to `dir/name` and returns the path.
fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    path
}

fn bench(c: &mut Criterion) {
    let sphere = uv_sphere("sphere", Vec3::new(0.0, 1.0, 0.0), 0.5, 500, 1000, [0.8; 3]);
    let dir = std::env::temp_dir().join("penumbra-bench-repair");
    std::fs::create_dir_all(&dir).unwrap();
    let obj = write(&dir, "sphere.obj", &obj_text(&sphere));
    let ply = write(&dir, "sphere.ply", &ply_bytes(&sphere));
    let options = RepairOptions::default();

    for (group, mesh_path, scene_name) in [
        ("load-obj", &obj, "sphere-obj.toml"),
        ("load-ply", &ply, "sphere-ply.toml"),
    ] {
        let file_name = mesh_path.file_name().unwrap().to_str().unwrap();
        let scene_path = write(&dir, scene_name, scene_text(file_name).as_bytes());
        let scene = load_scene_file(&scene_path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(scene.meshes[0].triangles.len(), sphere.triangles.len());
        let display = mesh_path.display().to_string();
        let raw = read_mesh(mesh_path, &display).unwrap();

        let mut g = c.benchmark_group(group);
        g.sampling_mode(SamplingMode::Flat)
            .sample_size(10)
            .measurement_time(Duration::from_secs(3))
            .warm_up_time(Duration::from_millis(500));
        g.bench_function("load", |b| {
            b.iter(|| load_scene_file(black_box(&scene_path)).unwrap())
        });
        g.bench_function("parse", |b| {
            b.iter(|| read_mesh(black_box(mesh_path), &display).unwrap())
        });
        g.bench_function("repair", |b| {
            b.iter(|| {
                repair(
                    black_box(raw.positions.clone()),
                    raw.triangles.clone(),
                    &options,
                )
                .unwrap()
            })
        });
        g.bench_function("validate", |b| {
            b.iter(|| validate(black_box(&scene)).unwrap())
        });
        g.finish();
    }

    let soup: Vec<Vec3> = sphere
        .triangles
        .iter()
        .flat_map(|t| t.map(|i| sphere.positions[i as usize]))
        .collect();
    let corners: Vec<[u32; 3]> = (0..sphere.triangles.len() as u32)
        .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
        .collect();
    let scene = load_scene_file(&dir.join("sphere-obj.toml")).unwrap();
    let repaired = scene.meshes[0].clone();
    let light = scene.light().clone();
    let mut g = c.benchmark_group("soup");
    g.sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_millis(500));
    g.bench_function("repair", |b| {
        b.iter(|| repair(black_box(soup.clone()), corners.clone(), &options).unwrap())
    });
    g.bench_function("adjacency", |b| {
        b.iter(|| adjacency::build(black_box(&repaired)).unwrap())
    });
    g.bench_function("point-touches", |b| {
        b.iter(|| point_touches(black_box(&repaired), light.center))
    });
    g.bench_function("light-shape-touches", |b| {
        b.iter(|| light_shape_touches(black_box(&repaired), &light))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
