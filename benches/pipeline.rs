//! Criterion benchmarks of the rendering pipeline on the built-in `cube-of-spheres` scene at
//! 256×256:
//!
//! * `scene-depth`: the shared first pass of every frame ([`Frame::render`]: adjacency, the
//!   depth pass and hierarchical Z);
//! * `hard-sv/zpass`, `hard-sv/zfail`: one hard shadow-volume stencil pass from the light
//!   center ([`stencil_shadow`]) against a frame rendered once up front;
//! * `method/nsample-n16`: the `nsample` method with `n = 16` (16 stencil passes and their
//!   accumulation) on that frame;
//! * `method/raycast-samples16`: the `raycast` reference with `samples = 16` on that frame;
//! * `method/ssv`, `method/wedge-blending-8bit`, `method/wedge-blending-f32`: the soft shadow
//!   volumes of Paper III and penumbra-wedges blending (Forest et al. 2006, packed and
//!   unpacked) side by side on that frame;
//! * `method/hard-sv`, `method/ssv-optimized`: the remaining methods that take the rectangular
//!   light, on that frame, so that every method of [`penumbra::methods::ALL`] is timed;
//! * `method/pw2002`, `method/pw-restructured`, `method/penumbra-map`: the methods that take
//!   only spherical lights, on `cube-of-spheres-sphere` (the same occluders under a sphere
//!   light) at 256×256;
//! * `method/dbuffer`: the D-buffer (CGI 2004), which takes only disk lights, on `disk-block`
//!   at 256×256.
//!
//! The method benchmarks run [`penumbra::methods::run`] on a prebuilt frame, so they exclude
//! the depth pass (measured on its own) and the shading of the image.
//!
//! Sample counts and measurement times are kept small so that `cargo bench --bench pipeline`
//! finishes well within three minutes on a shared two-core machine. Run with
//! `cargo bench --bench pipeline`; `cargo test` does not build or run this target. Criterion
//! writes its HTML report to `target/criterion/report/index.html`.

use criterion::{black_box, criterion_group, criterion_main, Criterion, SamplingMode};
use penumbra::frame::{Frame, GpuSettings};
use penumbra::methods::hard_sv::{
    stencil_shadow, ShadowTest, StencilOverflow, StencilShadowSettings, Submission,
};
use penumbra::scene::{builtin, OptionValue, Scene};
use std::time::Duration;

/// The benchmarked scene.
const SCENE: &str = "cube-of-spheres";
/// Image width and height in pixels.
const SIZE: u32 = 256;

/// The methods timed on [`SCENE`] besides those with options of their own (`nsample`,
/// `raycast`, `wedge-blending`), which take the rectangular light.
const RECT_METHODS: &[&str] = &["hard-sv", "ssv-optimized", "ssv"];
/// The methods that take only spherical lights, timed on [`SPHERE_SCENE`].
const SPHERE_METHODS: &[&str] = &["pw2002", "pw-restructured", "penumbra-map"];
/// [`SCENE`]'s occluders under a sphere light.
const SPHERE_SCENE: &str = "cube-of-spheres-sphere";
/// The methods that take only disk lights, timed on [`DISK_SCENE`].
const DISK_METHODS: &[&str] = &["dbuffer"];
/// The built-in scene of the D-buffer paper's Fig. 1/7.
const DISK_SCENE: &str = "disk-block";

/// The built-in scene `name` at [`SIZE`]×[`SIZE`].
fn sized(name: &str) -> Scene {
    let mut scene = builtin::load(name).expect("built-in scene");
    scene.width = SIZE;
    scene.height = SIZE;
    scene
}

/// `cube-of-spheres` at [`SIZE`]×[`SIZE`] with `nsample.n = 16` and `raycast.samples = 16`.
fn scene() -> Scene {
    let mut scene = sized(SCENE);
    set_option(&mut scene, "nsample", "n", 16);
    set_option(&mut scene, "raycast", "samples", 16);
    scene
}

/// Sets the integer option `method.key = value` on `scene`.
fn set_option(scene: &mut Scene, method: &str, key: &str, value: i64) {
    scene
        .options
        .entry(method.to_string())
        .or_default()
        .insert(key.to_string(), OptionValue::Int(value));
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

/// Registers every benchmark of this file.
fn pipeline(c: &mut Criterion) {
    let scene = scene();

    c.bench_function("scene-depth", |b| {
        b.iter(|| Frame::render(black_box(&scene), GpuSettings::default()).expect("scene pass"))
    });

    let frame = Frame::render(&scene, GpuSettings::default()).expect("scene pass");
    let center = scene.light().center;
    for (name, test) in [
        ("hard-sv/zpass", ShadowTest::ZPass),
        ("hard-sv/zfail", ShadowTest::ZFail),
    ] {
        let settings = stencil_settings(test);
        c.bench_function(name, |b| {
            b.iter(|| stencil_shadow(black_box(&frame), black_box(center), &settings))
        });
    }

    // One iteration of these takes a few hundred milliseconds: flat sampling runs the same
    // small number of iterations per sample instead of criterion's linear ramp, which would
    // need 55 iterations for 10 samples.
    let mut group = c.benchmark_group("method");
    group.sampling_mode(SamplingMode::Flat);
    group.measurement_time(Duration::from_secs(5));
    let named = [
        ("nsample-n16", "nsample"),
        ("raycast-samples16", "raycast"),
        ("wedge-blending-8bit", "wedge-blending"),
    ];
    for method in penumbra::methods::ALL {
        let timed = named.iter().any(|(_, m)| m == method)
            || [RECT_METHODS, SPHERE_METHODS, DISK_METHODS]
                .iter()
                .any(|list| list.contains(method));
        assert!(timed, "method {method} has no benchmark");
    }
    let plain = RECT_METHODS.iter().map(|m| (*m, *m));
    for (name, method) in named.into_iter().chain(plain) {
        group.bench_function(name, |b| {
            b.iter(|| penumbra::methods::run(black_box(method), black_box(&frame)).expect(method))
        });
    }
    let mut unpacked = scene.clone();
    unpacked
        .options
        .entry("wedge-blending".into())
        .or_default()
        .insert("packing".into(), OptionValue::Str("f32".into()));
    let unpacked_frame = frame.lit_by(&unpacked);
    group.bench_function("wedge-blending-f32", |b| {
        b.iter(|| {
            penumbra::methods::run("wedge-blending", black_box(&unpacked_frame))
                .expect("wedge-blending")
        })
    });
    for (scene_name, methods) in [(SPHERE_SCENE, SPHERE_METHODS), (DISK_SCENE, DISK_METHODS)] {
        let scene = sized(scene_name);
        let frame = Frame::render(&scene, GpuSettings::default()).expect("scene pass");
        for method in methods {
            group.bench_function(*method, |b| {
                b.iter(|| {
                    penumbra::methods::run(black_box(method), black_box(&frame)).expect(method)
                })
            });
        }
    }
    group.finish();
}

/// Small samples and short measurement windows: the whole file runs in well under three
/// minutes, at the price of wider confidence intervals. The HTML report
/// (`target/criterion/report/index.html`) is drawn by plotters with the crate's embedded
/// font.
fn config() -> Criterion {
    penumbra::experiment::plotting::register_font().expect("the embedded font");
    Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3))
}

criterion_group! {
    name = benches;
    config = config();
    targets = pipeline
}
criterion_main!(benches);
