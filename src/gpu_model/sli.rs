//! Several GPUs on one frame (issue 29 item 2; `docs/gpu-model.md` "SLI"): NVIDIA's SLI, as
//! Forest, Barthe & Paulin 2006 §5.2 ran it — two GeForce 7800 GTX "configured either in the
//! Alternate Frame Rendering SLI mode or with no SLI".
//!
//! - **Alternate-frame rendering** (AFR): each of `k` GPUs renders every `k`-th frame whole.
//!   A frame takes as long as on one GPU, but frames finish `k` times as often: the *frame
//!   interval*, what a frame rate measures, is the one-GPU frame time over `k`.
//! - **Split-frame rendering** (SFR): each GPU renders a `1/k` band of the screen. Every GPU
//!   sets up every triangle (the driver cannot know which band a triangle falls in before
//!   setup) and pays every pass's overhead; the per-pixel work — fragments, fragment
//!   programs, ROP operations, hierarchical-Z tests, bytes — is divided among them, evenly
//!   (the balance the driver's load balancing aims at: the best case).
//!
//! Neither mode prices what the model leaves out for one GPU (the CPU, the driver, the bus),
//! nor the inter-GPU transfer of SFR's bands or AFR's render-to-texture dependencies.

use super::{estimate_pass, profiles, FrameEstimate, GpuProfile, PassEstimate, PassWork};
use crate::pass::PassStats;

/// How `gpus` GPUs share a frame (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SliMode {
    /// Alternate-frame rendering: whole frames in turn.
    AlternateFrame,
    /// Split-frame rendering: a band of the screen each.
    SplitFrame,
}

/// The share of one pass's work one of `gpus` GPUs does in split-frame rendering: every
/// triangle and every run, and `1/gpus` of every per-pixel count, rounded up.
pub fn split_frame_share(w: &PassWork, gpus: u64) -> PassWork {
    let share = |n: u64| n.div_ceil(gpus.max(1));
    PassWork {
        fragments_rasterized: share(w.fragments_rasterized),
        shader_slots: share(w.shader_slots),
        shader_transcendentals: share(w.shader_transcendentals),
        rop_fragments: share(w.rop_fragments),
        depth_stencil_bytes: share(w.depth_stencil_bytes),
        other_bytes: share(w.other_bytes),
        hiz_tests: share(w.hiz_tests),
        ..*w
    }
}

/// The modeled frame interval of `passes` on `gpus` GPUs of profile `gpu` sharing each frame
/// by `mode` (module doc), with the built-in assumptions. One GPU gives the frame time of
/// [`super::estimate`] in either mode.
pub fn estimate_sli(
    gpu: &GpuProfile,
    passes: &[PassStats],
    mode: SliMode,
    gpus: u32,
) -> FrameEstimate {
    let k = u64::from(gpus.max(1));
    let a = &profiles().assumptions;
    let passes: Vec<PassEstimate> = passes
        .iter()
        .map(|p| {
            let whole = PassWork::from_counters(&p.counters, p.runs);
            let e = match mode {
                SliMode::AlternateFrame => estimate_pass(gpu, a, &p.name, &whole),
                SliMode::SplitFrame => {
                    estimate_pass(gpu, a, &p.name, &split_frame_share(&whole, k))
                }
            };
            match mode {
                SliMode::AlternateFrame => PassEstimate {
                    low: e.low / k as f64,
                    mid: e.mid / k as f64,
                    high: e.high / k as f64,
                    ..e
                },
                SliMode::SplitFrame => e,
            }
        })
        .collect();
    FrameEstimate::summed(format!("{} ×{k} ({mode:?})", gpu.id), passes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::counters::Counters;
    use crate::gpu_model::estimate;

    fn pass(name: &str, c: Counters) -> PassStats {
        PassStats {
            name: name.into(),
            wall_seconds: 0.0,
            runs: 1,
            counters: c,
        }
    }

    /// A setup-bound pass and a pixel-bound one, on every profile: one GPU is the one-GPU
    /// estimate in both modes; AFR halves the interval of both passes; SFR halves the pixel-
    /// bound pass's terms (not its overhead) and leaves the setup-bound one as it was.
    #[test]
    fn afr_divides_the_interval_and_sfr_only_the_pixel_work() {
        let geometry = Counters {
            triangles_submitted: 50_000_000,
            fragments_rasterized: 10,
            ..Default::default()
        };
        let pixels = Counters {
            triangles_submitted: 10,
            fragments_rasterized: 400_000_000,
            depth_passed: 400_000_000,
            depth_read_bytes: 1_600_000_000,
            shader_alu_ops: 4_000_000_000,
            color_write_bytes: 1_600_000_000,
            fragments_shaded: 400_000_000,
            ..Default::default()
        };
        let a = &profiles().assumptions;
        for g in &profiles().gpu {
            let passes = [pass("geometry", geometry), pass("pixels", pixels)];
            let one = estimate(g, &passes);
            for mode in [SliMode::AlternateFrame, SliMode::SplitFrame] {
                let e = estimate_sli(g, &passes, mode, 1);
                assert_eq!(e.seconds, one.seconds, "{}: {mode:?}", g.id);
            }
            let afr = estimate_sli(g, &passes, SliMode::AlternateFrame, 2);
            assert_eq!(afr.seconds.low, one.seconds.low / 2.0, "{}", g.id);
            assert_eq!(afr.seconds.high, one.seconds.high / 2.0, "{}", g.id);
            let sfr = estimate_sli(g, &passes, SliMode::SplitFrame, 2);
            assert_eq!(
                sfr.passes[0].low, one.passes[0].low,
                "{}: setup-bound",
                g.id
            );
            let (overhead_low, overhead_high) = a.pass_overhead_us.range();
            let half = |t: f64, o: f64| o * 1e-6 + (t - o * 1e-6) / 2.0;
            let rel = |x: f64, y: f64| ((x - y) / y).abs();
            assert!(
                rel(sfr.passes[1].low, half(one.passes[1].low, overhead_low)) < 1e-9,
                "{}: {} vs {}",
                g.id,
                sfr.passes[1].low,
                one.passes[1].low
            );
            assert!(rel(sfr.passes[1].high, half(one.passes[1].high, overhead_high)) < 1e-9);
        }
    }
}
