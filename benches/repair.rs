//! Criterion benchmarks of mesh repair at scale (issue 27, item 4): a UV sphere of 998 000
//! triangles (500 stacks × 1000 slices) written as STL writes it, every triangle with its
//! own three corners (2 994 000 positions).
//!
//! Functions (group `sphere-1m`):
//!
//! * `parse-obj`: [`parse_mesh`] of the same sphere as OBJ text with shared vertices (tobj,
//!   the OBJ welding of bit-identical positions);
//! * `repair`: [`repair`] of the STL soup (weld 2 994 000 corners into 499 002 vertices, clean,
//!   orient, look for non-manifold and boundary edges);
//! * `validate`: [`validate`] of a scene holding the repaired sphere, split into its checks:
//!   `adjacency` ([`adjacency::build`]), `point-touches` ([`point_touches`]: the light centre
//!   against every triangle) and `light-shape-touches` ([`light_shape_touches`]).
//!
//! Run with `cargo bench --bench repair` (`-- --quick --noplot` for one short pass). Budget: flat
//! sampling, 10 samples, 3 s of measurement.

use criterion::{black_box, criterion_group, criterion_main, Criterion, SamplingMode};
use glam::Vec3;
use penumbra::scene::adjacency;
use penumbra::scene::mesh_io::{parse_mesh, MeshFormat};
use penumbra::scene::procedural::uv_sphere;
use penumbra::scene::repair::{repair, RepairOptions};
use penumbra::scene::validate::{light_shape_touches, point_touches, validate};
use penumbra::scene::{builtin, Mesh};
use std::fmt::Write;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let sphere = uv_sphere("sphere", Vec3::new(0.0, 1.0, 0.0), 0.5, 500, 1000, [0.8; 3]);
    let soup: Vec<Vec3> = sphere
        .triangles
        .iter()
        .flat_map(|t| t.map(|i| sphere.positions[i as usize]))
        .collect();
    let corners: Vec<[u32; 3]> = (0..sphere.triangles.len() as u32)
        .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
        .collect();
    let mut obj = String::new();
    for p in &sphere.positions {
        let _ = writeln!(obj, "v {} {} {}", p.x, p.y, p.z);
    }
    for t in &sphere.triangles {
        let _ = writeln!(obj, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    let options = RepairOptions::default();
    let (positions, triangles, _) = repair(soup.clone(), corners.clone(), &options).unwrap();
    let mut scene = builtin::load("cube-of-spheres").unwrap();
    let repaired = Mesh {
        positions,
        triangles,
        ..sphere.clone()
    };
    scene.meshes = vec![repaired.clone()];
    validate(&scene).unwrap();
    let light = scene.light().clone();

    let mut g = c.benchmark_group("sphere-1m");
    g.sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_millis(500));
    g.bench_function("parse-obj", |b| {
        b.iter(|| {
            parse_mesh(
                black_box(obj.as_bytes()),
                MeshFormat::Obj,
                "sphere.obj",
                None,
            )
            .unwrap()
        })
    });
    g.bench_function("repair", |b| {
        b.iter(|| repair(black_box(soup.clone()), corners.clone(), &options).unwrap())
    });
    g.bench_function("validate", |b| {
        b.iter(|| validate(black_box(&scene)).unwrap())
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
