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

/// Pixels whose visibility differs, and the largest difference.
fn changes(a: &[f32], b: &[f32]) -> (usize, f32) {
    a.iter().zip(b).fold((0, 0.0f32), |(n, m), (x, y)| {
        ((x != y) as usize + n, m.max((x - y).abs()))
    })
}

/// `method` on `scene`: the default precision is f64, and fp24 and fp16 each change the
/// visibility of some pixel (the fragment program computes in them).
fn narrower_formats_change(scene: &Scene, method: &str) {
    assert_eq!(GpuSettings::default().shader, ShaderPrecision::F64);
    let f64v = visibility(scene, method, ShaderPrecision::F64);
    for p in [ShaderPrecision::Fp24, ShaderPrecision::Fp16] {
        let v = visibility(scene, method, p);
        let (n, max) = changes(&f64v, &v);
        eprintln!("{method} {p:?}: {n} pixels changed, max |Δ| {max}");
        assert!(n > 0, "{method}: {p:?} changed nothing");
        assert!(v.iter().all(|x| (0.0..=1.0).contains(x)), "{method} {p:?}");
    }
}

#[test]
fn penumbra_map_fp24_and_fp16_change_the_visibility() {
    narrower_formats_change(&small("cube-of-spheres-sphere", 64), "penumbra-map");
}

#[test]
fn dbuffer_fp24_and_fp16_change_the_visibility() {
    narrower_formats_change(&small("disk-block", 64), "dbuffer");
}

#[test]
fn wedge_blending_fp24_and_fp16_change_the_visibility() {
    narrower_formats_change(&small("cube-of-spheres", 64), "wedge-blending");
}
