//! What a frame would cost on the GPUs the methods were designed for (issue 29 item 2;
//! `docs/gpu-model.md` has the equations, the profiles with their sources and the
//! assumptions): a roofline per pass over the work the emulator counted.
//!
//! Per pass, from its [`Counters`] ([`PassWork::from_counters`]) and a [`GpuProfile`] at clock
//! `f`:
//!
//! ```text
//! t = overhead + max( setup   = triangles submitted / setup rate,
//!                     raster  = fragments rasterized / (z/stencil-only rate · f),
//!                     shade   = (fragment-program slots + transcendentals · their slots)
//!                               / (pipes · ALU ops per pipe · f),
//!                     rop     = fragments passing the depth test / (ROP rate · f),
//!                               ROP rate = colour ROPs if the pass writes colour, else the
//!                               z/stencil-only rate,
//!                     hiz     = hierarchical-Z tile tests / (tests per clock · f),
//!                     memory  = (depth+stencil bytes / z compression + other bytes)
//!                               / (bandwidth · efficiency) )
//! ```
//!
//! and the frame is the sum over its passes. Each figure is a range (a published value is a
//! range of one point), so each pass gets a **low** estimate (every figure at its fast end) and
//! a **high** one (every figure at its slow end), and the **bound**: the term that is largest
//! with every figure at the geometric middle of its range. A pass with no GPU work (no
//! triangle, fragment or byte: the CPU stages, e.g. silhouette extraction and the ray tracer's
//! rays) costs nothing here and is bound by `cpu`: the model prices the GPU only.
//!
//! What it leaves out, on purpose (`docs/gpu-model.md` "Limits"): the CPU and driver, the
//! bus transfer of vertices built on the CPU each frame, caches (every counted byte goes to
//! DRAM), and the overlap of consecutive passes.

pub mod profile;
pub mod sli;

pub use profile::{profiles, GpuModel, GpuProfile, DEFAULT_PROFILE};

use crate::gpu::counters::Counters;
use crate::pass::PassStats;
use profile::Assumptions;

/// The work of one pass the model prices, from its counters.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PassWork {
    /// Triangles handed to setup.
    pub triangles: u64,
    /// Fragments the rasterizer produced.
    pub fragments_rasterized: u64,
    /// Fragment-program instruction slots executed: ALU slots and texture fetches
    /// ([`crate::gpu::shader_ops`]).
    pub shader_slots: u64,
    /// Fragment-program transcendental functions, each priced at the assumed
    /// `transcendental_slots`.
    pub shader_transcendentals: u64,
    /// Fragments that reached the ROPs (passed the depth test).
    pub rop_fragments: u64,
    /// Whether the pass writes colour (else its ROPs run at the z/stencil-only rate).
    pub writes_color: bool,
    /// Depth and stencil bytes read and written.
    pub depth_stencil_bytes: u64,
    /// Colour, texture and hierarchical-Z bytes read and written.
    pub other_bytes: u64,
    /// Hierarchical-Z tile tests.
    pub hiz_tests: u64,
    /// How many times the pass ran (its counters are the runs' sum; each run pays the fixed
    /// overhead).
    pub runs: u64,
}

impl PassWork {
    /// The work `c` counted over `runs` runs of a pass.
    pub fn from_counters(c: &Counters, runs: u64) -> Self {
        PassWork {
            triangles: c.triangles_submitted,
            fragments_rasterized: c.fragments_rasterized,
            shader_slots: c.shader_alu_ops + c.shader_fetches,
            shader_transcendentals: c.shader_transcendentals,
            rop_fragments: c.depth_passed,
            writes_color: c.color_write_bytes > 0,
            depth_stencil_bytes: c.depth_read_bytes
                + c.depth_write_bytes
                + c.stencil_read_bytes
                + c.stencil_write_bytes,
            other_bytes: c.color_read_bytes + c.color_write_bytes + c.hiz_read_bytes,
            hiz_tests: c.tiles_visited,
            runs,
        }
    }

    fn is_gpu_work(&self) -> bool {
        self.triangles + self.fragments_rasterized + self.depth_stencil_bytes + self.other_bytes > 0
    }
}

/// A term of the per-pass maximum (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Term {
    /// Triangle setup.
    Setup,
    /// Rasterization.
    Raster,
    /// Fragment-program arithmetic.
    Shade,
    /// Raster operations (depth, stencil and colour writes).
    Rop,
    /// Hierarchical-Z tile tests.
    Hiz,
    /// DRAM traffic.
    Memory,
    /// No GPU work: a CPU stage the model does not price.
    Cpu,
}

const TERMS: [Term; 6] = [
    Term::Setup,
    Term::Raster,
    Term::Shade,
    Term::Rop,
    Term::Hiz,
    Term::Memory,
];

/// Which end of every figure's range an evaluation takes.
#[derive(Debug, Clone, Copy, PartialEq)]
enum End {
    /// The fast end: the highest rate, the lowest overhead.
    Fast,
    /// The slow end.
    Slow,
    /// The geometric middle.
    Middle,
}

/// A rate figure (higher is faster) at `end`.
fn rate(f: &profile::Figure, end: End) -> f64 {
    let (low, high) = f.range();
    match end {
        End::Fast => high,
        End::Slow => low,
        End::Middle => (low * high).sqrt(),
    }
}

/// A cost figure (higher is slower) at `end`.
fn cost(f: &profile::Figure, end: End) -> f64 {
    let (low, high) = f.range();
    match end {
        End::Fast => low,
        End::Slow => high,
        End::Middle => (low * high).sqrt(),
    }
}

/// The six terms of `w` in seconds, in [`TERMS`] order, and the overhead.
fn terms(g: &GpuProfile, a: &Assumptions, w: &PassWork, end: End) -> ([f64; 6], f64) {
    let clock = rate(&g.core_clock_mhz, end) * 1e6;
    let per_clock = |count: u64, per: f64| count as f64 / (per * clock);
    let rop_rate = if w.writes_color {
        rate(&g.rops, end)
    } else {
        rate(&g.zstencil_per_clock, end)
    };
    let bytes = w.depth_stencil_bytes as f64 / rate(&a.z_compression, end) + w.other_bytes as f64;
    let t = [
        w.triangles as f64 / (rate(&g.triangle_setup_mtris, end) * 1e6),
        per_clock(w.fragments_rasterized, rate(&g.zstencil_per_clock, end)),
        per_clock(
            w.shader_slots,
            rate(&g.pixel_pipes, end) * rate(&g.alu_ops_per_pipe_per_clock, end),
        ) + per_clock(
            w.shader_transcendentals,
            rate(&g.pixel_pipes, end) * rate(&g.alu_ops_per_pipe_per_clock, end)
                / cost(&a.transcendental_slots, end),
        ),
        per_clock(w.rop_fragments, rop_rate),
        per_clock(w.hiz_tests, rate(&a.hiz_tests_per_clock, end)),
        bytes / (rate(&g.memory_bandwidth_gbs, end) * 1e9 * rate(&a.memory_efficiency, end)),
    ];
    (t, w.runs as f64 * cost(&a.pass_overhead_us, end) * 1e-6)
}

fn seconds(g: &GpuProfile, a: &Assumptions, w: &PassWork, end: End) -> f64 {
    let (t, overhead) = terms(g, a, w, end);
    overhead + t.iter().copied().fold(0.0, f64::max)
}

/// A low and a high estimate, seconds.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Seconds {
    /// Every figure at its fast end.
    pub low: f64,
    /// Every figure at the geometric middle of its range: the point estimate the modeled
    /// accuracy–time Pareto fronts use.
    pub mid: f64,
    /// Every figure at its slow end.
    pub high: f64,
}

/// The modeled time of one pass.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PassEstimate {
    /// The pass name.
    pub name: String,
    /// Every figure at its fast end, seconds.
    pub low: f64,
    /// Every figure at the geometric middle of its range, seconds.
    pub mid: f64,
    /// Every figure at its slow end, seconds.
    pub high: f64,
    /// The term that bounds it with every figure at the middle of its range.
    pub bound: Term,
    /// What its fragment program executed per fragment shaded (`None` for a pass that ran
    /// none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub program: Option<ProgramWork>,
}

/// A pass's fragment-program work per fragment shaded ([`crate::gpu::shader_ops`]): what
/// `docs/gpu-model.md` compares with the papers' instruction counts.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ProgramWork {
    /// Instruction slots (ALU + fetches) over fragments shaded.
    pub mean_slots: f64,
    /// The most slots one invocation executed.
    pub max_slots: u64,
    /// Texture fetches over fragments shaded.
    pub mean_fetches: f64,
    /// Transcendental functions over fragments shaded.
    pub mean_transcendentals: f64,
}

impl ProgramWork {
    /// The per-fragment work of a pass that counted `c`; `None` if no program ran.
    pub fn from_counters(c: &Counters) -> Option<Self> {
        let slots = c.shader_alu_ops + c.shader_fetches;
        if c.fragments_shaded == 0 || slots + c.shader_transcendentals == 0 {
            return None;
        }
        let per = |n: u64| n as f64 / c.fragments_shaded as f64;
        Some(ProgramWork {
            mean_slots: per(slots),
            max_slots: c.shader_max_slots,
            mean_fetches: per(c.shader_fetches),
            mean_transcendentals: per(c.shader_transcendentals),
        })
    }
}

/// The modeled time of a frame (a method's passes): `stats.json`'s `gpu_model`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FrameEstimate {
    /// The profile's id.
    pub gpu: String,
    /// The sum over the passes.
    pub seconds: Seconds,
    /// Per pass, in execution order.
    pub passes: Vec<PassEstimate>,
}

/// The modeled time of `w` on `g` with the shared assumptions `a`.
pub fn estimate_pass(g: &GpuProfile, a: &Assumptions, name: &str, w: &PassWork) -> PassEstimate {
    if !w.is_gpu_work() {
        return PassEstimate {
            name: name.into(),
            low: 0.0,
            mid: 0.0,
            high: 0.0,
            bound: Term::Cpu,
            program: None,
        };
    }
    let (mid, _) = terms(g, a, w, End::Middle);
    let k = (0..TERMS.len())
        .max_by(|&i, &j| mid[i].total_cmp(&mid[j]))
        .unwrap_or(0);
    PassEstimate {
        name: name.into(),
        low: seconds(g, a, w, End::Fast),
        mid: seconds(g, a, w, End::Middle),
        high: seconds(g, a, w, End::Slow),
        bound: TERMS[k],
        program: None,
    }
}

/// The modeled time of the passes `passes` (a method's, in execution order; a pass that ran
/// N times counts its summed work and N overheads, as N runs of it would) on the profile `gpu`
/// with the built-in assumptions.
pub fn estimate(gpu: &GpuProfile, passes: &[PassStats]) -> FrameEstimate {
    let a = &profiles().assumptions;
    let passes: Vec<PassEstimate> = passes
        .iter()
        .map(|p| PassEstimate {
            program: ProgramWork::from_counters(&p.counters),
            ..estimate_pass(
                gpu,
                a,
                &p.name,
                &PassWork::from_counters(&p.counters, p.runs),
            )
        })
        .collect();
    FrameEstimate::summed(gpu.id.clone(), passes)
}

impl FrameEstimate {
    /// The frame of `passes` on the GPU named `gpu`: its seconds the sums over the passes.
    pub fn summed(gpu: String, passes: Vec<PassEstimate>) -> Self {
        FrameEstimate {
            gpu,
            seconds: Seconds {
                low: passes.iter().map(|p| p.low).sum(),
                mid: passes.iter().map(|p| p.mid).sum(),
                high: passes.iter().map(|p| p.high).sum(),
            },
            passes,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gpu() -> &'static GpuProfile {
        profiles().get("geforce-6800-ultra").unwrap()
    }

    fn a() -> &'static Assumptions {
        &profiles().assumptions
    }

    fn work() -> PassWork {
        PassWork {
            triangles: 10_000,
            fragments_rasterized: 200_000,
            shader_slots: 2_000_000,
            shader_transcendentals: 20_000,
            rop_fragments: 150_000,
            writes_color: true,
            depth_stencil_bytes: 1_600_000,
            other_bytes: 600_000,
            hiz_tests: 20_000,
            runs: 1,
        }
    }

    /// Every counter, raised, never lowers either estimate (each term is increasing in its
    /// count and the maximum and the sum keep that).
    #[test]
    fn the_model_is_monotonic_in_every_counter() {
        type Bump = fn(&mut PassWork);
        let bumps: [(&str, Bump); 9] = [
            ("triangles", |w| w.triangles *= 50),
            ("fragments", |w| w.fragments_rasterized *= 50),
            ("shader slots", |w| w.shader_slots *= 50),
            ("transcendentals", |w| w.shader_transcendentals *= 50),
            ("rop fragments", |w| w.rop_fragments *= 50),
            ("depth bytes", |w| w.depth_stencil_bytes *= 50),
            ("other bytes", |w| w.other_bytes *= 50),
            ("hiz tests", |w| w.hiz_tests *= 50),
            ("colour writes", |w| w.writes_color = true),
        ];
        for g in &profiles().gpu {
            for base in [
                work(),
                PassWork {
                    writes_color: false,
                    ..work()
                },
            ] {
                let e0 = estimate_pass(g, a(), "p", &base);
                for (what, bump) in bumps {
                    let mut w = base;
                    bump(&mut w);
                    let e = estimate_pass(g, a(), "p", &w);
                    assert!(
                        e.low >= e0.low && e.mid >= e0.mid && e.high >= e0.high,
                        "{}: {what}",
                        g.id
                    );
                }
            }
            let e = estimate_pass(g, a(), "p", &work());
            assert!(
                0.0 < e.low && e.low <= e.mid && e.mid <= e.high,
                "{}: {e:?}",
                g.id
            );
        }
    }

    /// A pass built to stress one unit is bound by that unit, for each term in turn, and its
    /// time is then that term plus the overhead (the arithmetic of the module doc).
    #[test]
    fn a_constructed_pass_is_bound_by_each_term_in_turn() {
        let g = gpu();
        let small = PassWork {
            triangles: 1,
            fragments_rasterized: 1,
            shader_slots: 1,
            shader_transcendentals: 0,
            rop_fragments: 1,
            writes_color: true,
            depth_stencil_bytes: 1,
            other_bytes: 1,
            hiz_tests: 1,
            runs: 1,
        };
        let big = 1_000_000_000;
        let cases: [(Term, PassWork); 7] = [
            (
                Term::Setup,
                PassWork {
                    triangles: big,
                    ..small
                },
            ),
            (
                Term::Raster,
                PassWork {
                    fragments_rasterized: big,
                    ..small
                },
            ),
            (
                Term::Shade,
                PassWork {
                    shader_slots: 100 * big,
                    ..small
                },
            ),
            (
                Term::Shade,
                PassWork {
                    shader_transcendentals: 10 * big,
                    ..small
                },
            ),
            (
                Term::Rop,
                PassWork {
                    rop_fragments: big,
                    ..small
                },
            ),
            (
                Term::Hiz,
                PassWork {
                    hiz_tests: big,
                    ..small
                },
            ),
            (
                Term::Memory,
                PassWork {
                    other_bytes: 100 * big,
                    ..small
                },
            ),
        ];
        for (term, w) in cases {
            let e = estimate_pass(g, a(), "p", &w);
            assert_eq!(e.bound, term, "{w:?}");
        }
        // Setup-bound at the slow end: 10⁹ triangles at 200 M/s is 5 s, plus 50 µs.
        let e = estimate_pass(g, a(), "p", &cases[0].1);
        assert!((e.high - (5.0 + 50e-6)).abs() < 1e-9, "{e:?}");
        // Memory-bound at the fast end: 10¹¹ bytes at 35.2 GB/s × 0.85.
        let e = estimate_pass(g, a(), "p", &cases[6].1);
        let want = 1e11 / (35.2e9 * 0.85) + 5e-6;
        assert!((e.low - want).abs() < 1e-9 * want, "{e:?}");
    }

    /// A pass that ran N times pays N overheads (5–50 µs each) on top of its summed work.
    #[test]
    fn each_run_of_a_pass_pays_the_overhead() {
        let one = PassWork { runs: 1, ..work() };
        let many = PassWork {
            runs: 1024,
            ..work()
        };
        let (e1, en) = (
            estimate_pass(gpu(), a(), "p", &one),
            estimate_pass(gpu(), a(), "p", &many),
        );
        assert!(
            (en.low - e1.low - 1023.0 * 5e-6).abs() < 1e-12,
            "{e1:?} {en:?}"
        );
        assert!(
            (en.high - e1.high - 1023.0 * 50e-6).abs() < 1e-12,
            "{e1:?} {en:?}"
        );
    }

    /// A pass with no GPU work is a CPU stage: no time, bound `cpu`.
    #[test]
    fn a_pass_without_gpu_work_costs_nothing_and_says_cpu() {
        let e = estimate_pass(gpu(), a(), "silhouettes", &PassWork::default());
        assert_eq!((e.low, e.high, e.bound), (0.0, 0.0, Term::Cpu));
    }

    /// Z/stencil-only fragments run at twice the colour rate on NV40 and at the same rate on
    /// R300 (the profiles' published figures).
    #[test]
    fn stencil_only_passes_fill_twice_as_fast_on_nv40_not_on_r300() {
        let fill = |id: &str, writes_color: bool| {
            let g = profiles().get(id).unwrap();
            let w = PassWork {
                rop_fragments: 1_000_000_000,
                writes_color,
                ..PassWork::default()
            };
            let (t, _) = terms(g, a(), &w, End::Middle);
            t[3]
        };
        let nv40 = fill("geforce-6800-ultra", true) / fill("geforce-6800-ultra", false);
        assert!((nv40 - 2.0).abs() < 1e-12, "{nv40}");
        let r300 = fill("radeon-9700-pro", true) / fill("radeon-9700-pro", false);
        assert!((r300 - 1.0).abs() < 1e-12, "{r300}");
    }
}
