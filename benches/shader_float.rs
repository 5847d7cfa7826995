//! Generic or runtime-dispatched shader scalar (`penumbra::gpu::shader_float` module doc):
//! `ssv`'s exact edge coverage ([`shader_edge_coverage`]) over fixed pseudo-random receivers
//! and edges, at f64, computed by the monomorphized `f64` instance and by a runtime-dispatched
//! scalar that reads its precision from a global and branches on it in every operation.
//! Run with `cargo bench --bench shader_float`.

use criterion::{criterion_group, criterion_main, Criterion};
use glam::DVec3;
use penumbra::gpu::shader_float::{ShaderFloat, ShaderPrecision, FP16, FP24, FP32};
use penumbra::light::coverage::{shader_edge_coverage, RectLight};
use std::ops::{Add, Div, Mul, Neg, Sub};
use std::sync::atomic::{AtomicU8, Ordering};

/// The runtime-selected precision (0 = f64).
static PRECISION: AtomicU8 = AtomicU8::new(0);

/// A scalar whose format is chosen at run time.
#[derive(Debug, Clone, Copy, Default, PartialEq, PartialOrd)]
struct Dyn(f64);

fn round(x: f64) -> f64 {
    match PRECISION.load(Ordering::Relaxed) {
        0 => x,
        1 => FP32.round(x),
        2 => FP24.round(x),
        _ => FP16.round(x),
    }
}

impl ShaderFloat for Dyn {
    const PRECISION: ShaderPrecision = ShaderPrecision::F64;
    type AtMostFp32 = penumbra::gpu::shader_float::Fp32;
    fn from_f64(x: f64) -> Self {
        Dyn(round(x))
    }
    fn to_f64(self) -> f64 {
        self.0
    }
}

macro_rules! op {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for Dyn {
            type Output = Dyn;
            fn $f(self, o: Dyn) -> Dyn {
                Dyn(round(self.0 $op o.0))
            }
        }
    };
}
op!(Add, add, +);
op!(Sub, sub, -);
op!(Mul, mul, *);
op!(Div, div, /);

impl Neg for Dyn {
    type Output = Dyn;
    fn neg(self) -> Dyn {
        Dyn(-self.0)
    }
}

fn inputs() -> Vec<[DVec3; 3]> {
    let mut s = 0x2545_f491_4f6c_dd1du64;
    let mut r = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    (0..1000)
        .map(|_| {
            let p = DVec3::new(r(), r(), -2.0 + 0.5 * r());
            let e0 = DVec3::new(r(), r(), -1.0);
            let e1 = DVec3::new(r(), r(), -1.0 + 0.2 * r());
            [p, e0, e1]
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let light = RectLight::new(DVec3::ZERO, DVec3::X * 0.5, DVec3::Y * 0.5);
    let cases = inputs();
    let mut g = c.benchmark_group("edge-coverage-1000");
    g.bench_function("generic-f64", |b| {
        b.iter(|| {
            cases
                .iter()
                .map(|[p, e0, e1]| shader_edge_coverage::<f64>(&light, *p, *e0, *e1))
                .sum::<f64>()
        })
    });
    g.bench_function("runtime-dispatched-f64", |b| {
        PRECISION.store(0, Ordering::Relaxed);
        b.iter(|| {
            cases
                .iter()
                .map(|[p, e0, e1]| shader_edge_coverage::<Dyn>(&light, *p, *e0, *e1).0)
                .sum::<f64>()
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().without_plots();
    targets = bench
}
criterion_main!(benches);
