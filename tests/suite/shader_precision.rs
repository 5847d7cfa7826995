//! Shader precision (`[options.gpu] shader`, issue 11) in the fragment programs of `pw2002`,
//! `pw-restructured`, `ssv-optimized` and `ssv`'s sphere path: fp24 and fp16 change what each
//! method computes on `cube-of-spheres(-sphere)` (the default f64 is pinned bit for bit by the
//! goldens), and the rounded plane evaluations and LI amounts stay within the error bounds of
//! floating-point arithmetic (Higham, *Accuracy and Stability of Numerical Algorithms*, §3.1:
//! a value through k roundings of unit roundoff u carries a relative error of at most
//! γ_k = k·u / (1 − k·u)).

use glam::DVec3;
use penumbra::geometry::penumbra_wedge::{li_amount, shader_li_amount, Plane};
use penumbra::gpu::shader_float::{FloatFormat, Fp16, Fp24, Fp32, ShaderFloat, FP16, FP24, FP32};
use penumbra::gpu::shader_vec::SVec3;
use penumbra::render::render_scene;
use penumbra::scene::builtin;
use penumbra::visibility::Visibility;

/// The visibility of `method` on the built-in `scene` at `size`² with `opts` (`--opt` form).
fn visibility(scene: &str, method: &str, size: u32, opts: &[&str]) -> Vec<f32> {
    let mut s = builtin::load(scene).unwrap();
    s.resize(Some(size), Some(size));
    s.methods = Some(vec![method.into()]);
    for o in opts {
        s.set_cli_option(o).unwrap();
    }
    let runs = render_scene(&s).unwrap();
    match &runs
        .iter()
        .find(|r| r.method == method)
        .unwrap()
        .output
        .visibility
    {
        Visibility::Gray(v) => v.clone(),
        Visibility::Rgb(v) => v.iter().map(|c| c[0]).collect(),
    }
}

/// Pixels whose visibility differs.
fn changed(a: &[f32], b: &[f32]) -> usize {
    a.iter().zip(b).filter(|(x, y)| x != y).count()
}

/// Every converted fragment program computes something else at fp24 and at fp16 than at f64:
/// the precision reaches the method's output.
#[test]
fn fp24_and_fp16_change_every_converted_method() {
    for (scene, method) in [
        ("cube-of-spheres-sphere", "pw2002"),
        ("cube-of-spheres-sphere", "pw-restructured"),
        ("cube-of-spheres", "ssv-optimized"),
        ("cube-of-spheres-sphere", "ssv-optimized"),
        ("cube-of-spheres-sphere", "ssv"),
    ] {
        let f64v = visibility(scene, method, 96, &[]);
        let fp24 = visibility(scene, method, 96, &["gpu.shader=fp24"]);
        let fp16 = visibility(scene, method, 96, &["gpu.shader=fp16"]);
        let (n24, n16) = (changed(&f64v, &fp24), changed(&f64v, &fp16));
        eprintln!("{scene} {method}: fp24 changes {n24} pixels, fp16 {n16}");
        assert!(n24 > 0, "{scene} {method}: fp24 equals f64");
        assert!(n16 > 0, "{scene} {method}: fp16 equals f64");
    }
}

/// `ssv-optimized`'s 16-bit float position buffer (Paper IV §4.2) moves the receivers and so
/// the shadow; `position = depth` is the default.
#[test]
fn position_buffer_f16_changes_ssv_optimized_and_depth_is_the_default() {
    let scene = "cube-of-spheres";
    let default = visibility(scene, "ssv-optimized", 64, &[]);
    let depth = visibility(
        scene,
        "ssv-optimized",
        64,
        &["ssv-optimized.position=depth"],
    );
    let f16 = visibility(scene, "ssv-optimized", 64, &["ssv-optimized.position=f16"]);
    assert_eq!(changed(&default, &depth), 0);
    assert!(changed(&default, &f16) > 0);
}

/// A small deterministic generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// 0, or a magnitude in [0.01, 10) with a random sign (no product of two such values
    /// underflows fp16's normal range, none overflows it).
    fn component(&mut self) -> f64 {
        if self.next() < 0.1 {
            return 0.0;
        }
        let m = 0.01 * libm::pow(1000.0, self.next());
        if self.next() < 0.5 {
            -m
        } else {
            m
        }
    }

    fn vector(&mut self) -> DVec3 {
        DVec3::new(self.component(), self.component(), self.component())
    }
}

/// γ_k = k·u / (1 − k·u) with u the unit roundoff of `f`.
fn gamma(k: f64, f: FloatFormat) -> f64 {
    let u = libm::ldexp(1.0, -(f.mantissa_bits + 1));
    k * u / (1.0 - k * u)
}

/// A wedge plane evaluated by a fragment program, `((n_x·p_x + n_y·p_y) + n_z·p_z) + d` with
/// `n`, `p`, `d` rounded to the format on input, differs from the exact value by at most
/// γ_6·(Σ|n_i·p_i| + |d|) + 3·(smallest normal): each product term passes through 6
/// roundings (its two inputs, the product, three additions), `d` through 2, and a sum that
/// falls below the smallest normal (products here cannot) loses less than that in fp24 (which
/// flushes) and nothing in fp32 or fp16 (whose denormal sums are exact). So a point farther
/// than the bound from every plane is classified as f64 classifies it — the inside test of
/// `pw2002`'s and `pw-restructured`'s wedges ([`Plane::shader_eval`]).
#[test]
fn plane_evaluation_error_within_the_rounding_bound() {
    fn check<T: ShaderFloat>(f: FloatFormat) -> usize {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut differing = 0;
        for _ in 0..200_000 {
            let n = rng.vector();
            let plane = Plane {
                n,
                d: rng.component(),
            };
            let p = rng.vector();
            // The f64 value, itself within γ_4 at u = 2⁻⁵³ (< 4ε) of the exact one.
            let exact = plane.eval(p);
            let got = plane.shader_eval(SVec3::<T>::from_f64(p)).to_f64();
            let magnitude = (n.x * p.x).abs() + (n.y * p.y).abs() + (n.z * p.z).abs();
            let bound = (gamma(6.0, f) + 4.0 * f64::EPSILON) * (magnitude + plane.d.abs())
                + 3.0 * f.min_normal();
            assert!(
                (got - exact).abs() <= bound,
                "{:?}: n {n} p {p} d {}: {got} vs {exact}, bound {bound}",
                T::PRECISION,
                plane.d
            );
            differing += (got != exact) as usize;
        }
        differing
    }
    // The rounding is really there (the bound is not vacuous).
    assert!(check::<Fp32>(FP32) > 0);
    assert!(check::<Fp24>(FP24) > 0);
    assert!(check::<Fp16>(FP16) > 0);
}

/// The LI amount `floor(255/n·s + 0.5)` with the scaling in the shader precision differs from
/// f64's by at most 1: the argument of the floor, at most 255.5, passes through 4 roundings
/// (s, ×255, ÷n, +0.5), so it is off by at most γ_4·255.5 ≈ 0.5 in fp16 (γ_4 ≈ 0.00196) —
/// and two reals less than 1 apart have floors at most 1 apart. At fp16 the amounts do differ
/// (255·s has an ulp of 1/8 above 128).
#[test]
fn li_amount_within_one_of_f64() {
    fn max_diff<T: ShaderFloat>() -> (i32, usize) {
        let mut worst = 0;
        let mut differing = 0;
        for lights in 1..=4 {
            for k in 0..=100_000 {
                let s = k as f64 / 100_000.0;
                let d = (shader_li_amount(T::from_f64(s), lights) - li_amount(s, lights)).abs();
                worst = worst.max(d);
                differing += (d != 0) as usize;
            }
        }
        (worst, differing)
    }
    assert!(gamma(4.0, FP16) * 255.5 < 1.0);
    for (worst, _) in [max_diff::<Fp32>(), max_diff::<Fp24>(), max_diff::<Fp16>()] {
        assert!(worst <= 1, "{worst}");
    }
    assert!(max_diff::<Fp16>().1 > 0, "fp16 changes some amounts");
}
