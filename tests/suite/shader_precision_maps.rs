//! Shader precision (issue 11, `[options.gpu] shader`) of `penumbra-map`, `dbuffer` and
//! `wedge-blending` (the wedge methods: `tests/suite/shader_precision.rs`): every converted method's fragment
//! programs compute in the chosen format, so a narrower format changes the visibility of a
//! small render of the method's usual scene, and the default (f64) is what the method
//! computes with no `[options.gpu]` at all. The bounds of the single operations are derived
//! in the methods' unit tests (`penumbra_map`: I; `dbuffer`: t); the measured added error per
//! method and precision is in the closing note.

use penumbra::frame::{Frame, GpuSettings};
use penumbra::gpu::shader_float::ShaderPrecision;
use penumbra::scene::{builtin, Scene};
use penumbra::visibility::Visibility;

/// The built-in scene `name` at `size`×`size`.
fn small(name: &str, size: u32) -> Scene {
    let mut s = builtin::load(name).expect("built-in scene");
    s.width = size;
    s.height = size;
    s
}

/// The visibility `method` computes on `scene` with the fragment programs in `shader`.
fn visibility(scene: &Scene, method: &str, shader: ShaderPrecision) -> Vec<f32> {
    let gpu = GpuSettings {
        shader,
        ..GpuSettings::default()
    };
    let frame = Frame::render(scene, gpu).unwrap();
    match penumbra::methods::run(method, &frame).unwrap().visibility {
        Visibility::Gray(v) => v,
        Visibility::Rgb(_) => panic!("gray expected"),
    }
}

/// Pixels whose visibility differs, and the largest difference — NaN if either holds a NaN
/// (`f32::max` would drop it).
fn changes(a: &[f32], b: &[f32]) -> (usize, f32) {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).fold((0, 0.0f32), |(n, m), (x, y)| {
        let d = (x - y).abs();
        let m = if d.is_nan() || m.is_nan() {
            f32::NAN
        } else {
            m.max(d)
        };
        ((x != y) as usize + n, m)
    })
}

/// `method` on `scene`: the default precision is f64, and fp24 and fp16 each change the
/// visibility of some pixel (the fragment program computes in them), by at most the pins
/// `[fp24, fp16]` of `max_change`.
///
/// The visibility is clamped to [0, 1] when it is resolved, so a range check of it could not
/// fail, and the unclamped sums are not reachable from the public API: what is checked is
/// the change from f64 (NaN fails), against PINS (measured, then ~20% margin; not derived —
/// the single operations' bounds are derived in the methods' unit tests, module doc).
fn narrower_formats_change(scene: &Scene, method: &str, max_change: [f32; 2]) {
    assert_eq!(GpuSettings::default().shader, ShaderPrecision::F64);
    let f64v = visibility(scene, method, ShaderPrecision::F64);
    for (p, pin) in [ShaderPrecision::Fp24, ShaderPrecision::Fp16]
        .into_iter()
        .zip(max_change)
    {
        let v = visibility(scene, method, p);
        let (n, max) = changes(&f64v, &v);
        eprintln!("{method} {p:?}: {n} pixels changed, max |Δ| {max}");
        assert!(n > 0, "{method}: {p:?} changed nothing");
        assert!(max <= pin, "pin: {method} {p:?}: max |Δ| {max} > {pin}");
    }
}

/// PINS `[fp24, fp16]` of the largest change from f64 (measured at 64², then ~20% margin):
/// 1/255 and 3/255 — one and three steps of the 8-bit maps.
const PIN_PENUMBRA_MAP: [f32; 2] = [0.0048, 0.0142];

/// PINS `[fp24, fp16]` (measured 3.9·10⁻⁵ and 0.5; where fp16 moves a pixel by 0.5 is not
/// investigated).
const PIN_DBUFFER: [f32; 2] = [5e-5, 0.6];

/// PINS `[fp24, fp16]` (measured 0.00098 and 0.120).
const PIN_WEDGE_BLENDING: [f32; 2] = [0.0012, 0.144];

#[test]
fn penumbra_map_fp24_and_fp16_change_the_visibility() {
    narrower_formats_change(
        &small("cube-of-spheres-sphere", 64),
        "penumbra-map",
        PIN_PENUMBRA_MAP,
    );
}

#[test]
fn dbuffer_fp24_and_fp16_change_the_visibility() {
    narrower_formats_change(&small("disk-block", 64), "dbuffer", PIN_DBUFFER);
}

#[test]
fn wedge_blending_fp24_and_fp16_change_the_visibility() {
    narrower_formats_change(
        &small("cube-of-spheres", 64),
        "wedge-blending",
        PIN_WEDGE_BLENDING,
    );
}
