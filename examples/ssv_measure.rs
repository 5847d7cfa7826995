//! `ssv` (Paper III) measured against `raycast`, and its shadow-pass bandwidth next to
//! `nsample` at N = 256 and 1024 on the same frame (Paper III §5.2: 6.0 MB vs 146 MB vs
//! 585 MB, depth and V-buffer/stencil accesses only).
//!
//! `cargo run --release --example ssv_measure [SIZE] [SCENE…]` (default 256,
//! `cube-of-spheres single-quad`); `cargo run --release --example ssv_measure textures` times
//! the coverage-texture precomputation instead (grey n = 8…64, RGB n = 32). Times are informational (wall clock, all threads); counters
//! are deterministic. The scene depth pass is excluded from every method's bytes.

use penumbra::frame::{Frame, GpuSettings};
use penumbra::gpu::counters::Counters;
use penumbra::gpu::vbuffer::VBufferFormat;
use penumbra::light::coverage_texture::{CoverageFilter, CoverageTexture, CoverageTextureKey};
use penumbra::methods::hard_sv::ShadowTest;
use penumbra::methods::recorder::PassRecorder;
use penumbra::methods::ssv::{render, CoverageMode, SsvSettings};
use penumbra::methods::{self};
use penumbra::metrics::compare;
use penumbra::scene::{builtin, OptionValue, RgbTexture};
use std::time::Instant;

fn mb(bytes: u64) -> f64 {
    bytes as f64 / 1e6
}

/// Time the coverage-texture precomputation (Paper III §3.3: "less than 3 minutes" for n = 32
/// on a Pentium 4 1.7 GHz, naive implementation).
fn time_textures() {
    for n in [8, 16, 32, 64] {
        let t = Instant::now();
        let tex = CoverageTexture::compute(&CoverageTextureKey::uniform(n));
        println!(
            "grey n = {n}: {} bytes in {:.2} s",
            tex.bytes(),
            t.elapsed().as_secs_f64()
        );
    }
    let light = RgbTexture {
        width: 2,
        height: 1,
        texels: vec![[1.0, 0.3, 0.0], [0.0, 0.3, 1.0]],
        source: "two colours".into(),
    };
    let t = Instant::now();
    let tex = CoverageTexture::compute(&CoverageTextureKey::textured(32, &light));
    println!(
        "RGB n = 32: {} bytes in {:.2} s",
        tex.bytes(),
        t.elapsed().as_secs_f64()
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("textures") {
        time_textures();
        return;
    }
    let size: u32 = args.first().and_then(|a| a.parse().ok()).unwrap_or(256);
    let scenes: Vec<String> = if args.len() > 1 {
        args[1..].to_vec()
    } else {
        vec!["cube-of-spheres".into(), "single-quad".into()]
    };
    for name in scenes {
        let mut scene = builtin::load(&name).expect("a built-in scene");
        scene.width = size;
        scene.height = size;
        let frame = Frame::render(&scene, GpuSettings::default()).expect("scene renders");
        let t = Instant::now();
        let reference = methods::run("raycast", &frame).expect("raycast");
        println!(
            "\n{name} at {size}×{size}: raycast ({} s)",
            t.elapsed().as_secs_f32()
        );
        println!(
            "| variant | rmse | max abs | mean abs | time s | shadow-pass MB (depth + V/stencil) | overflow events |"
        );
        println!("|---|---|---|---|---|---|---|");
        let texture = |n, filter| CoverageMode::Texture { n, filter };
        let variants: Vec<(String, CoverageMode, VBufferFormat)> = vec![
            ("exact, f32".into(), CoverageMode::Exact, VBufferFormat::F32),
            ("exact, f16".into(), CoverageMode::Exact, VBufferFormat::F16),
            (
                "exact, 8-bit".into(),
                CoverageMode::Exact,
                VBufferFormat::Split8,
            ),
            (
                "texture n=8 nearest".into(),
                texture(8, CoverageFilter::Nearest),
                VBufferFormat::F32,
            ),
            (
                "texture n=16 nearest".into(),
                texture(16, CoverageFilter::Nearest),
                VBufferFormat::F32,
            ),
            (
                "texture n=32 nearest".into(),
                texture(32, CoverageFilter::Nearest),
                VBufferFormat::F32,
            ),
            (
                "texture n=32 bilinear".into(),
                texture(32, CoverageFilter::Bilinear),
                VBufferFormat::F32,
            ),
            (
                "texture n=32 quadrilinear".into(),
                texture(32, CoverageFilter::Quadrilinear),
                VBufferFormat::F32,
            ),
            (
                "texture n=64 nearest".into(),
                texture(64, CoverageFilter::Nearest),
                VBufferFormat::F32,
            ),
        ];
        let mut ssv_bytes = 0;
        for (label, coverage, vbuffer) in variants {
            let settings = SsvSettings {
                coverage,
                vbuffer,
                test: ShadowTest::ZPass,
                horizon: penumbra::methods::horizon_clip::Horizon::Off,
            };
            // Warm the coverage-texture cache so the time is the render's (§3.3: the texture
            // is computed once per light shape).
            render(&mut PassRecorder::new(&frame, "ssv"), &settings);
            let t = Instant::now();
            let mut rec = PassRecorder::new(&frame, "ssv");
            let r = render(&mut rec, &settings);
            let secs = t.elapsed().as_secs_f64();
            let out = rec.finish(r.visibility, serde_json::Value::Null);
            let e = compare(&out.visibility, &reference.visibility);
            // The two passes after the scene pass.
            let mut c = Counters::default();
            for p in out.stats.passes.iter().skip(1) {
                c += p.counters;
            }
            if label == "exact, f32" {
                ssv_bytes = c.total_bytes();
            }
            println!(
                "| ssv {label} | {:.5} | {:.4} | {:.5} | {secs:.3} | {:.2} | {} |",
                e.rmse,
                e.max_abs,
                e.mean_abs,
                mb(c.total_bytes()),
                c.overflow_events
            );
        }
        for n in [256i64, 1024] {
            let mut s = scene.clone();
            s.options
                .entry("nsample".into())
                .or_default()
                .insert("n".into(), OptionValue::Int(n));
            let f = Frame::render(&s, GpuSettings::default()).expect("scene renders");
            let out = methods::run("nsample", &f).expect("nsample");
            let mut c = Counters::default();
            for p in out.stats.passes.iter().skip(1) {
                c += p.counters;
            }
            let e = compare(&out.visibility, &reference.visibility);
            println!(
                "| nsample N={n} | {:.5} | {:.4} | {:.5} | {:.3} | {:.2} (×{:.1} ssv) | {} |",
                e.rmse,
                e.max_abs,
                e.mean_abs,
                out.stats.wall_seconds,
                mb(c.total_bytes()),
                c.total_bytes() as f64 / ssv_bytes as f64,
                c.overflow_events
            );
        }
    }
}
