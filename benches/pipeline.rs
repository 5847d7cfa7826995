//! Criterion benchmarks of the rendering pipeline: every method of [`penumbra::methods::ALL`]
//! at 256×256 and 512×512 on the built-in `cube-of-spheres` (4548 triangles) and on the
//! heavier `forest-spheres` (20 532 triangles, Forest et al. 2006 Fig. 1), both under their
//! rectangular light.
//!
//! Each scene and size is one benchmark group named `SCENE-SIZE` (`cube-of-spheres-256`,
//! `cube-of-spheres-512`, `forest-spheres-256`, `forest-spheres-512`) with these functions:
//!
//! * `scene-depth`: the shared first pass of every frame ([`Frame::render`]: adjacency, the
//!   depth pass and hierarchical Z);
//! * `hard-sv/zpass`, `hard-sv/zfail`: one hard shadow-volume stencil pass from the light
//!   center ([`stencil_shadow`]) against a frame rendered once up front;
//! * one function per method of [`penumbra::methods::ALL`], named after it: the method with
//!   its defaults (but `raycast.samples = 16` and `nsample.n = 16`) on the first of these
//!   frames whose light it supports — the scene's rectangle; a sphere of radius the
//!   rectangle's half extent at the same center (for `cube-of-spheres` that is the built-in
//!   `cube-of-spheres-sphere`); a disk of that radius at the same center facing straight down
//!   onto the floor (the construction of the built-in disk scenes, `disk_down` in
//!   `src/scene/builtin.rs`). A method added to the registry is benchmarked without editing
//!   this file.
//!
//! `forest-spheres-256` also has `raycast-samples1024`: the reference with 1024 samples, the
//! sample count the issue compares with 16 on that scene.
//!
//! The method benchmarks run [`penumbra::methods::run`] on a prebuilt frame (the sphere- and
//! disk-lit frames share the rect frame's scene pass, [`Frame::lit_by`]), so they exclude the
//! depth pass (measured on its own) and the shading of the image.
//!
//! Run everything with `cargo bench --bench pipeline`; criterion's name filter runs a subset,
//! e.g. `cargo bench --bench pipeline -- forest-spheres-256` (one group),
//! `cargo bench --bench pipeline -- /ssv$` (`ssv` in every group) or
//! `cargo bench --bench pipeline -- --list` (the names only). `cargo test` does not build or
//! run this target. Criterion writes its HTML report to `target/criterion/report/index.html`.
//!
//! Budget: flat sampling, 10 samples, 2 s of measurement after 0.5 s of warm-up per
//! benchmark (a benchmark whose iteration takes longer than 0.2 s runs 10 iterations, one per
//! sample; criterion then warns that it could not complete 10 samples in 2 s, which is
//! expected). The whole file took 410 s (about 7 minutes) on a shared two-core machine.

mod common;

use criterion::{black_box, criterion_group, criterion_main, Criterion, SamplingMode};
use glam::Vec3;
use penumbra::frame::{Frame, GpuSettings};
use penumbra::methods::hard_sv::{
    stencil_shadow, ShadowTest, StencilOverflow, StencilShadowSettings, Submission,
};
use penumbra::scene::{builtin, LightShape, OptionValue, Scene};

/// The benchmarked built-in scenes, both under a rectangular light.
const SCENES: &[&str] = &["cube-of-spheres", "forest-spheres"];
/// Image widths (and heights) in pixels.
const SIZES: &[u32] = &[256, 512];

/// The lights a method benchmark's frame can have, in the order a method's first supported
/// one is chosen: the scene's rectangle, a sphere of radius its half extent at the same
/// center, a downward-facing disk of that radius (the frames of [`variants`], in this order).
const LIGHTS: [&str; 3] = ["rect", "sphere", "disk"];

/// The scene and size whose group also times `raycast` at 1024 samples.
const RAYCAST_1024_AT: (&str, u32) = ("forest-spheres", 256);

/// The built-in scene `name` at `size`×`size` with `nsample.n = 16` and
/// `raycast.samples = 16`.
fn sized(name: &str, size: u32) -> Scene {
    let mut scene = builtin::load(name).expect("built-in scene");
    scene.resize(Some(size), Some(size));
    set_option(&mut scene, "nsample", "n", OptionValue::Int(16));
    set_option(&mut scene, "raycast", "samples", OptionValue::Int(16));
    scene
}

/// Sets the option `method.key = value` on `scene`.
fn set_option(scene: &mut Scene, method: &str, key: &str, value: OptionValue) {
    scene
        .options
        .entry(method.to_string())
        .or_default()
        .insert(key.to_string(), value);
}

/// `scene` (one rectangular light) with that light's shape replaced by `shape(r)`, `r` the
/// rectangle's half extent along `u`.
fn relit(scene: &Scene, shape: impl Fn(f32) -> LightShape) -> Scene {
    let mut out = scene.clone();
    let LightShape::Rect { u, .. } = scene.light().shape else {
        panic!("{} has no rectangular light", scene.source);
    };
    out.lights[0].shape = shape(u.length());
    out
}

/// The scenes of [`LIGHTS`], in its order, for the rect-lit `scene`.
fn variants(scene: &Scene) -> Vec<Scene> {
    vec![
        scene.clone(),
        relit(scene, |radius| LightShape::Sphere { radius }),
        relit(scene, |radius| LightShape::Disk {
            radius,
            normal: Vec3::NEG_Y,
        }),
    ]
}

/// Stencil settings for one hard-shadow pass with the given counting direction (wrap,
/// two-sided: the `hard-sv` defaults).
fn stencil_settings(test: ShadowTest) -> StencilShadowSettings {
    StencilShadowSettings {
        test,
        overflow: StencilOverflow::Wrap,
        submission: Submission::TwoSided,
    }
}

/// Registers every benchmark of one scene at one size: the group `SCENE-SIZE`.
fn scene_at(c: &mut Criterion, name: &str, size: u32) {
    let scene = sized(name, size);
    let lit = variants(&scene);
    let frame = Frame::render(&scene, GpuSettings::default()).expect("scene pass");
    let frames: Vec<Frame> = lit.iter().map(|s| frame.lit_by(s)).collect();

    // One method iteration takes tens to hundreds of milliseconds: flat sampling runs the same
    // small number of iterations per sample instead of criterion's linear ramp, which would
    // need 55 iterations for 10 samples.
    let mut group = c.benchmark_group(format!("{name}-{size}"));
    group.sampling_mode(SamplingMode::Flat);

    group.bench_function("scene-depth", |b| {
        b.iter(|| Frame::render(black_box(&scene), GpuSettings::default()).expect("scene pass"))
    });
    let center = scene.light().center;
    for (id, test) in [
        ("hard-sv/zpass", ShadowTest::ZPass),
        ("hard-sv/zfail", ShadowTest::ZFail),
    ] {
        let settings = stencil_settings(test);
        group.bench_function(id, |b| {
            b.iter(|| stencil_shadow(black_box(&frame), black_box(center), &settings))
        });
    }
    // Every method of the registry, on the first frame whose light it supports.
    for m in penumbra::methods::ALL {
        let Some(frame) = frames.iter().find(|f| (m.supports)(&f.scene.light().shape)) else {
            panic!("{} supports none of the lights {LIGHTS:?}", m.name);
        };
        group.bench_function(m.name, |b| {
            b.iter(|| penumbra::methods::run(black_box(m.name), black_box(frame)).expect(m.name))
        });
    }
    if (name, size) == RAYCAST_1024_AT {
        let mut many = scene.clone();
        set_option(&mut many, "raycast", "samples", OptionValue::Int(1024));
        let frame = frame.lit_by(&many);
        group.bench_function("raycast-samples1024", |b| {
            b.iter(|| penumbra::methods::run("raycast", black_box(&frame)).expect("raycast"))
        });
    }
    group.finish();
}

/// Registers every benchmark of this file: [`scene_at`] for every scene of [`SCENES`] at every
/// size of [`SIZES`].
fn pipeline(c: &mut Criterion) {
    for name in SCENES {
        for &size in SIZES {
            scene_at(c, name, size);
        }
    }
}

criterion_group! {
    name = benches;
    config = common::config();
    targets = pipeline
}
criterion_main!(benches);
