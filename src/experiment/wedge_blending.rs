//! Does penumbra-wedges blending (Forest, Barthe & Paulin 2006) fix the overlap artifact of
//! the wedge methods, and what does it cost? `penumbra experiment wedge-blending`.
//!
//! For each overlap scene (default: `cube-of-spheres` and `forest-spheres`, the paper's Fig. 1
//! situation) at `size`² (default 256):
//! 1. **Error vs `raycast`** (1024 samples, the receiver the rasterized methods see) of `ssv`,
//!    `ssv-optimized` with and without `overlap = loops`, `wedge-blending` packed and
//!    unpacked, with and without the centroid, the other knobs, and `nsample` with 16 and
//!    64 samples (the sampling peers at comparable time): mean |e|, RMSE, max |e|,
//!    % > 4/255 over the whole image and over the **overlap pixels** — where the
//!    penumbrae of two or more silhouettes overlap, read from the frame's own wedge
//!    coverage (the raw image `penumbrae` of the unpacked `wedge-blending` render, ≥ 2).
//! 2. **Order**: the unpacked render with the silhouettes in reverse order against the
//!    forward one.
//! 3. **One pixel step by step**: the overlap pixel where packed `wedge-blending` errs most
//!    among receivers that see the whole light in front of their tangent plane and lie on no
//!    mesh blended there (elsewhere the receiver's own surface hides light, which no wedge
//!    method models — `ssv` errs as much there), with every silhouette's radial parts,
//!    rectangles and ε, from the render's probe trace ([`blend_steps`]).
//! 4. **Time**: the median of [`TIMING_RUNS`] interleaved runs of `ssv`, `ssv-optimized` and
//!    `wedge-blending` (packed, unpacked) at `size`² and 2·`size`², and the ratios to `ssv`.
//!
//! Then the **cost series** of Fig. 12: `forest-spheres-1`, `-4`, `-9` and `forest-spheres`
//! (1, 4, 9, 27 spheres of 760 triangles), median times of the same methods at `size`².
//! `pw2002` (Paper I) is for sphere lights only; on these rectangular-light scenes the plain
//! penumbra wedges are `ssv` (Paper III) and `ssv-optimized` (Paper IV).
//!
//! Outputs: `wedge_blending_errors.csv`, `wedge_blending_times.csv` and the summary the
//! command prints (also `summary.md`). Errors and counters are deterministic; times are
//! informational and depend on the machine.

use super::{configured, sized};
use crate::error::InputError;
use crate::frame::{Frame, GpuSettings};
use crate::geometry::near_plane::segment_hits_mesh;
use crate::gpu::probe;
use crate::light::coverage::RectLight;
use crate::light::radial_parts::{PART_COUNT, PART_SIGNS};
use crate::methods::recorder::PassRecorder;
use crate::methods::wedge_blending::{self, blend_steps, BlendStep};
use crate::metrics::{compare_where, ErrorStats};
use crate::scene::{builtin, Scene};
use crate::visibility::Visibility;
use glam::DVec3;
use std::fmt::Write as _;
use std::path::Path;

/// Timed runs per configuration; the reported time is their median. Rounds interleave the
/// methods so that a slow phase of the machine affects all of them alike.
pub const TIMING_RUNS: usize = 5;

/// How many of the worst overlap pixels are probed to find one off the occluders.
const PROBE_CANDIDATES: usize = 64;

/// The default overlap scenes.
pub const SCENES: [&str; 2] = ["cube-of-spheres", "forest-spheres"];

/// The cost series of Fig. 12.
pub const COST_SERIES: [&str; 4] = [
    "forest-spheres-1",
    "forest-spheres-4",
    "forest-spheres-9",
    "forest-spheres",
];

/// One configuration of a method.
#[derive(Debug, Clone, PartialEq)]
pub struct Variant {
    /// Row label.
    pub label: &'static str,
    /// Method name.
    pub method: &'static str,
    /// Its options.
    pub options: &'static [(&'static str, &'static str)],
}

/// The configurations of part 1 (module doc), in table order.
pub const VARIANTS: &[Variant] = &[
    Variant {
        label: "ssv",
        method: "ssv",
        options: &[],
    },
    Variant {
        label: "ssv-optimized",
        method: "ssv-optimized",
        options: &[],
    },
    Variant {
        label: "ssv-optimized overlap=loops",
        method: "ssv-optimized",
        options: &[("overlap", "loops")],
    },
    Variant {
        label: "wedge-blending 8bit",
        method: "wedge-blending",
        options: &[],
    },
    Variant {
        label: "wedge-blending f32",
        method: "wedge-blending",
        options: &[("packing", "f32")],
    },
    Variant {
        label: "wedge-blending 8bit centroid",
        method: "wedge-blending",
        options: &[("centroid", "on")],
    },
    Variant {
        label: "wedge-blending f32 centroid",
        method: "wedge-blending",
        options: &[("packing", "f32"), ("centroid", "on")],
    },
    Variant {
        label: "wedge-blending f32 adjust=always",
        method: "wedge-blending",
        options: &[("packing", "f32"), ("adjust", "always")],
    },
    Variant {
        label: "wedge-blending f32 adjust=never",
        method: "wedge-blending",
        options: &[("packing", "f32"), ("adjust", "never")],
    },
    Variant {
        label: "wedge-blending f32 silhouettes=meshes",
        method: "wedge-blending",
        options: &[("packing", "f32"), ("silhouettes", "meshes")],
    },
    Variant {
        label: "wedge-blending 8bit flush-denormals",
        method: "wedge-blending",
        options: &[("target", "flush-denormals")],
    },
    Variant {
        label: "wedge-blending 8bit canonical-nans",
        method: "wedge-blending",
        options: &[("target", "canonical-nans")],
    },
    Variant {
        label: "nsample n=16",
        method: "nsample",
        options: &[("n", "16")],
    },
    Variant {
        label: "nsample n=64",
        method: "nsample",
        options: &[("n", "64")],
    },
];

/// The configurations timed in part 4 and in the cost series.
pub const TIMED: [&str; 4] = [
    "ssv",
    "ssv-optimized",
    "wedge-blending 8bit",
    "wedge-blending f32",
];

/// Error of one variant on one scene.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ErrorRow {
    /// Scene name.
    pub scene: String,
    /// Variant label.
    pub variant: &'static str,
    /// Over every pixel.
    pub all: ErrorStats,
    /// Over the overlap pixels.
    pub overlap: ErrorStats,
    /// The method's wall time of this (single) run, informational.
    pub seconds: f64,
}

/// Median time of one variant on one scene at one size.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TimeRow {
    /// Scene name.
    pub scene: String,
    /// Image side.
    pub size: u32,
    /// Scene triangles.
    pub triangles: usize,
    /// Variant label.
    pub variant: &'static str,
    /// Median wall seconds of [`TIMING_RUNS`] runs.
    pub seconds: f64,
}

/// One pixel traced step by step (module doc, part 3).
#[derive(Debug, Clone)]
pub struct Probe {
    /// (column, row).
    pub pixel: (u32, u32),
    /// The reference visibility there.
    pub reference: f32,
    /// The packed wedge-blending visibility there.
    pub packed: f32,
    /// Every blend step with what the receiver really sees ([`ProbeTruth`]).
    pub steps: Vec<(BlendStep, ProbeTruth)>,
}

/// Everything the experiment measured on one overlap scene.
#[derive(Debug, Clone)]
pub struct SceneReport {
    /// Scene name.
    pub scene: String,
    /// Error rows, [`VARIANTS`] order.
    pub errors: Vec<ErrorRow>,
    /// Overlap pixels.
    pub overlap_pixels: usize,
    /// Forward against reverse order (unpacked): max |Δ|, mean |Δ|, pixels with |Δ| > 1/255.
    pub order: (f64, f64, usize),
    /// The probed pixel (module doc, part 3).
    pub probe: Option<Probe>,
    /// The packed render's method counters.
    pub counters: wedge_blending::BlendingCounters,
}

fn variant(label: &str) -> &'static Variant {
    VARIANTS
        .iter()
        .find(|v| v.label == label)
        .expect("a listed variant")
}

/// Run `v` on `frame`'s geometry (the scene pass is shared).
fn run_variant(
    frame: &Frame,
    v: &Variant,
) -> Result<crate::methods::output::MethodOutput, InputError> {
    let scene = configured(frame.scene, v.method, v.options);
    crate::methods::run(v.method, &frame.lit_by(&scene))
}

fn gray(v: &Visibility) -> Vec<f32> {
    (0..v.len()).map(|i| v.gray(i)).collect()
}

/// Whether the experiment can measure `scene`: one light that `wedge-blending` renders (a
/// rectangle); the error names the scene.
pub fn check_scene(scene: &Scene) -> Result<(), InputError> {
    if crate::methods::supports_scene(wedge_blending::METHOD.name, scene) && !scene.is_multi_light()
    {
        Ok(())
    } else {
        Err(InputError::at(
            &scene.source,
            "light",
            "the wedge-blending experiment needs one rect light",
        ))
    }
}

/// Parts 1–3 of the module doc on `scene`.
pub fn measure_scene(scene: &Scene) -> Result<SceneReport, InputError> {
    let frame = Frame::render(scene, GpuSettings::default())?;
    let reference = crate::methods::run(crate::methods::REFERENCE, &frame)?.visibility;
    let f32_variant = variant("wedge-blending f32");
    let unpacked = wedge_blending::options(&frame.lit_by(&configured(
        scene,
        f32_variant.method,
        f32_variant.options,
    )))?
    .0;
    let mask_render = wedge_blending::render(
        &mut PassRecorder::new(&frame, wedge_blending::METHOD.name),
        &unpacked,
    )?;
    let overlap: Vec<bool> = mask_render.penumbrae.iter().map(|n| *n >= 2).collect();
    let mut errors = Vec::new();
    let mut packed = None;
    for v in VARIANTS {
        let out = run_variant(&frame, v)?;
        if v.label == "wedge-blending 8bit" {
            packed = Some(gray(&out.visibility));
        }
        errors.push(ErrorRow {
            scene: scene.source.clone(),
            variant: v.label,
            all: compare_where(&out.visibility, &reference, |_| true),
            overlap: compare_where(&out.visibility, &reference, |i| overlap[i]),
            seconds: out.stats.wall_seconds,
        });
    }
    let packed = packed.expect("the packed variant is listed");
    let reversed = wedge_blending::Settings {
        reverse: true,
        ..unpacked
    };
    let rev = wedge_blending::render(
        &mut PassRecorder::new(&frame, wedge_blending::METHOD.name),
        &reversed,
    )?
    .visibility;
    let diffs: Vec<f64> = rev
        .iter()
        .zip(&mask_render.visibility)
        .map(|(a, b)| (f64::from(*a) - f64::from(*b)).abs())
        .collect();
    let order = (
        diffs.iter().copied().fold(0.0, f64::max),
        diffs.iter().sum::<f64>() / diffs.len().max(1) as f64,
        diffs.iter().filter(|d| **d > 1.0 / 255.0).count(),
    );
    let reference = gray(&reference);
    let packed_settings = wedge_blending::options(&frame)?.0;
    let counters = wedge_blending::render(
        &mut PassRecorder::new(&frame, wedge_blending::METHOD.name),
        &packed_settings,
    )?
    .counters;
    // The probe: overlap pixels by decreasing error (ties by index) among receivers that see
    // the whole light in front of their tangent plane (elsewhere the receiver's own surface
    // hides part of the light, which no wedge method models, ssv as little); the first whose
    // receiver is not on a mesh blended there, among the PROBE_CANDIDATES worst.
    let corners = RectLight::from_light(scene.light())
        .map(|l| l.corners())
        .unwrap_or_default();
    let receivers = frame.receivers();
    let faces_whole_light = |i: usize| {
        receivers[i].is_some_and(|r| {
            let (p, n) = (r.point.as_dvec3(), r.normal.as_dvec3());
            corners.iter().all(|c| n.dot(*c - p) > 0.0)
        })
    };
    let mut candidates: Vec<usize> = (0..packed.len())
        .filter(|i| overlap[*i] && faces_whole_light(*i))
        .collect();
    let error = |i: usize| (packed[i] - reference[i]).abs();
    candidates.sort_by(|a, b| error(*b).total_cmp(&error(*a)).then(a.cmp(b)));
    let mut probe = None;
    for &i in candidates.iter().take(PROBE_CANDIDATES) {
        let xy = ((i as u32) % scene.width, (i as u32) / scene.width);
        let receiver_mesh = frame.prim_owner[frame.prim_ids()[i] as usize].0 as usize;
        let mut probed = frame.lit_by(scene);
        let recorder = std::sync::Arc::new(probe::Probe::new(xy.0, xy.1));
        probed.probe = Some(recorder.clone());
        wedge_blending::render(
            &mut PassRecorder::new(&probed, wedge_blending::METHOD.name),
            &packed_settings,
        )?;
        let trace = blend_steps(&recorder.events(), &packed_settings);
        if trace.iter().all(|st| st.mesh != receiver_mesh) {
            let p = receivers[i].expect("an overlap pixel has a receiver").point;
            let truths = probe_truths(scene, p.as_dvec3(), &trace);
            probe = Some(Probe {
                pixel: xy,
                reference: reference[i],
                packed: packed[i],
                steps: trace.into_iter().zip(truths).collect(),
            });
            break;
        }
    }
    Ok(SceneReport {
        scene: scene.source.clone(),
        errors,
        overlap_pixels: overlap.iter().filter(|o| **o).count(),
        order,
        probe,
        counters,
    })
}

/// Light samples per part side for [`ProbeTruth`] (32² = 1024 per part).
pub const TRUTH_GRID: usize = 32;

/// What the probed receiver really sees, per radial part, at one blend step: measured by
/// testing segments from the receiver to a grid of [`TRUTH_GRID`]² points per part against the
/// meshes themselves.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ProbeTruth {
    /// Fraction of the part hidden by this step's mesh alone (what A_s estimates).
    pub alone: [f64; PART_COUNT],
    /// Fraction hidden both by it and by the meshes blended before (what ε estimates).
    pub overlap: [f64; PART_COUNT],
    /// Fraction hidden by it or by the meshes blended before (what the final occlusion after
    /// the step estimates).
    pub union: [f64; PART_COUNT],
}

/// The [`ProbeTruth`] of every step of `trace` at receiver `p`.
fn probe_truths(scene: &Scene, p: DVec3, trace: &[BlendStep]) -> Vec<ProbeTruth> {
    let Some(light) = RectLight::from_light(scene.light()) else {
        return Vec::new();
    };
    let g = TRUTH_GRID;
    let samples: Vec<Vec<DVec3>> = (0..PART_COUNT)
        .map(|k| {
            let [ss, st] = PART_SIGNS[k];
            (0..g * g)
                .map(|n| {
                    let s = ss * ((n % g) as f64 + 0.5) / g as f64;
                    let t = st * ((n / g) as f64 + 0.5) / g as f64;
                    light.center + light.u * s + light.v * t
                })
                .collect()
        })
        .collect();
    let mut before = vec![vec![false; g * g]; PART_COUNT];
    trace
        .iter()
        .map(|step| {
            let mesh = &scene.meshes[step.mesh];
            let mut truth = ProbeTruth {
                alone: [0.0; PART_COUNT],
                overlap: [0.0; PART_COUNT],
                union: [0.0; PART_COUNT],
            };
            for k in 0..PART_COUNT {
                for (n, q) in samples[k].iter().enumerate() {
                    let hit = segment_hits_mesh(mesh, p, *q);
                    truth.alone[k] += hit as u8 as f64;
                    truth.overlap[k] += (hit && before[k][n]) as u8 as f64;
                    before[k][n] |= hit;
                    truth.union[k] += before[k][n] as u8 as f64;
                }
                let n = (g * g) as f64;
                truth.alone[k] /= n;
                truth.overlap[k] /= n;
                truth.union[k] /= n;
            }
            truth
        })
        .collect()
}

/// Median of the [`TIMED`] variants' wall times on `scene` (interleaved rounds).
pub fn time_scene(scene: &Scene) -> Result<Vec<TimeRow>, InputError> {
    let frame = Frame::render(scene, GpuSettings::default())?;
    let mut samples: Vec<Vec<f64>> = vec![Vec::new(); TIMED.len()];
    for _ in 0..TIMING_RUNS {
        for (k, label) in TIMED.iter().enumerate() {
            let out = run_variant(&frame, variant(label))?;
            samples[k].push(out.stats.wall_seconds);
        }
    }
    let triangles = scene.meshes.iter().map(|m| m.triangles.len()).sum();
    Ok(TIMED
        .iter()
        .zip(samples)
        .map(|(label, mut s)| {
            s.sort_by(f64::total_cmp);
            TimeRow {
                scene: scene.source.clone(),
                size: scene.width,
                triangles,
                variant: variant(label).label,
                seconds: s[s.len() / 2],
            }
        })
        .collect())
}

fn stats_cells(e: &ErrorStats) -> String {
    format!(
        "{:.5} | {:.5} | {:.4} | {:.2}",
        e.mean_abs, e.rmse, e.max_abs, e.pct_over_4_255
    )
}

/// The summary of one scene (parts 1–3).
pub fn scene_summary(r: &SceneReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "\n## {} — error vs raycast ({} overlap pixels: ≥ 2 silhouettes' penumbrae)\n",
        r.scene, r.overlap_pixels
    );
    let _ = writeln!(
        s,
        "| variant | all: mean | RMSE | max | % > 4/255 | overlap: mean | RMSE | max | % > 4/255 | time [s] |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    for e in &r.errors {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.3} |",
            e.variant,
            stats_cells(&e.all),
            stats_cells(&e.overlap),
            e.seconds
        );
    }
    let find = |l: &str| r.errors.iter().find(|e| e.variant == l);
    if let (Some(ssv), Some(wb8), Some(wb32)) = (
        find("ssv"),
        find("wedge-blending 8bit"),
        find("wedge-blending f32"),
    ) {
        let beats =
            wb8.overlap.rmse < ssv.overlap.rmse && wb8.overlap.mean_abs < ssv.overlap.mean_abs;
        let _ = writeln!(
            s,
            "\nOverlap pixels: wedge-blending (8bit) RMSE {:.5} vs ssv {:.5} ({:.0}% less), mean \
             |e| {:.5} vs {:.5}; unpacked {:.5}. The paper's claim (\"significantly reduces the \
             overlapping error\") {} here.",
            wb8.overlap.rmse,
            ssv.overlap.rmse,
            100.0 * (1.0 - wb8.overlap.rmse / ssv.overlap.rmse),
            wb8.overlap.mean_abs,
            ssv.overlap.mean_abs,
            wb32.overlap.rmse,
            if beats { "holds" } else { "does NOT hold" }
        );
    }
    let _ = writeln!(
        s,
        "Order: reversing the silhouettes (unpacked) changes the visibility by at most {:.4} \
         (mean {:.6}); {} pixels by more than 1/255.",
        r.order.0, r.order.1, r.order.2
    );
    let c = &r.counters;
    let _ = writeln!(
        s,
        "Packed render: {} silhouettes, {} half-wedges; fragments rejected by depth {}, \
         outside planes {}, quad side {}; {} part updates; parts copied {}, blended {} \
         (ε > 0 in {}), limited to 1 {}; packing clamps {}; patterns written: {} denormal, \
         {} NaN, {} infinite.",
        c.silhouettes,
        c.half_wedges,
        c.rejected_depth,
        c.rejected_outside_planes,
        c.rejected_quad_side,
        c.part_updates,
        c.parts_copied,
        c.parts_blended,
        c.parts_corrected,
        c.parts_limited,
        c.packing_clamps,
        c.stores.denormal,
        c.stores.nan,
        c.stores.infinite
    );
    if let Some(Probe {
        pixel: (x, y),
        reference,
        packed,
        steps,
    }) = &r.probe
    {
        let _ = writeln!(
            s,
            "\nThe overlap pixel where packed wedge-blending errs most among receivers that see \
             the whole light above their tangent plane and lie on no mesh blended there: \
             ({x}, {y}), raycast {reference:.4}, wedge-blending {packed:.4}. Per silhouette blended there, per part \
             (part-local coordinates): the silhouette's occlusion A_s, rectangle [l, b, r, t] \
             and max X/Y of its inner edges; the final occlusion before → after, ε.\n"
        );
        let _ = writeln!(
            s,
            "In parentheses, what the receiver really sees ({TRUTH_GRID}² light samples per \
             part, segments tested against the meshes): the part hidden by this mesh alone, \
             the overlap with the meshes blended before, and their union.\n"
        );
        let _ = writeln!(s, "```");
        for (st, truth) in steps {
            let _ = writeln!(s, "silhouette {} (mesh {})", st.silhouette, st.mesh);
            for k in 0..st.eps.len() {
                let p = &st.silhouette_parts[k];
                if p.occlusion == 0.0 {
                    continue;
                }
                let r = p.rect;
                let _ = writeln!(
                    s,
                    "  part {k}: A_s {:.3} ({:.3}) rect [{:.3}, {:.3}, {:.3}, {:.3}] max ({:.3}, {:.3}) | ε {:.3} ({:.3}) | A_f {:.3} → {:.3} ({:.3})",
                    p.occlusion,
                    truth.alone[k],
                    r.left,
                    r.bottom,
                    r.right,
                    r.top,
                    p.max_edge[0],
                    p.max_edge[1],
                    st.eps[k],
                    truth.overlap[k],
                    st.before[k].occlusion,
                    st.after[k].occlusion,
                    truth.union[k]
                );
            }
        }
        let _ = writeln!(s, "```");
    }
    s
}

/// The time table (part 4 and the cost series).
pub fn time_summary(title: &str, rows: &[TimeRow]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "\n## {title}\n");
    let _ = writeln!(
        s,
        "| scene | size | triangles | variant | median [s] | ÷ ssv |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    for r in rows {
        let ssv = rows
            .iter()
            .find(|o| o.scene == r.scene && o.size == r.size && o.variant == "ssv")
            .map_or(f64::NAN, |o| o.seconds);
        let _ = writeln!(
            s,
            "| {} | {}² | {} | {} | {:.4} | {:.2} |",
            r.scene,
            r.size,
            r.triangles,
            r.variant,
            r.seconds,
            r.seconds / ssv
        );
    }
    s
}

fn errors_csv(reports: &[SceneReport]) -> String {
    let mut s = String::from(
        "scene,variant,region,mean_abs,rmse,max_abs,pct_over_4_255,pct_over_1_255,pixels,seconds\n",
    );
    for r in reports {
        for e in &r.errors {
            for (region, st) in [("all", &e.all), ("overlap", &e.overlap)] {
                let _ = writeln!(
                    s,
                    "{},{},{region},{},{},{},{},{},{},{}",
                    e.scene,
                    e.variant,
                    st.mean_abs,
                    st.rmse,
                    st.max_abs,
                    st.pct_over_4_255,
                    st.pct_over_1_255,
                    st.pixels,
                    e.seconds
                );
            }
        }
    }
    s
}

fn times_csv(rows: &[TimeRow]) -> String {
    let mut s = String::from("scene,size,triangles,variant,median_seconds\n");
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{},{},{}",
            r.scene, r.size, r.triangles, r.variant, r.seconds
        );
    }
    s
}

/// The whole experiment on `scenes` (module doc) at `size`; writes the CSVs and `summary.md`
/// under `out` and returns the summary.
pub fn run(scenes: &[Scene], size: u32, out: &Path) -> Result<String, Box<dyn std::error::Error>> {
    let mut summary = format!(
        "# wedge-blending (Forest, Barthe & Paulin 2006) at {size}², reference raycast (1024 \
         samples); times are medians of {TIMING_RUNS} interleaved runs on {} threads\n",
        rayon::current_num_threads()
    );
    let mut reports = Vec::new();
    let mut times = Vec::new();
    for scene in scenes {
        let r = measure_scene(&sized(scene.clone(), size))?;
        summary += &scene_summary(&r);
        reports.push(r);
        for s in [size, 2 * size] {
            times.extend(time_scene(&sized(scene.clone(), s))?);
        }
    }
    summary += &time_summary("Time per frame (method only, scene pass excluded)", &times);
    let mut series = Vec::new();
    for name in COST_SERIES {
        let scene = builtin::load(name).expect("a built-in scene");
        series.extend(time_scene(&sized(scene, size))?);
    }
    summary += &time_summary(
        "Cost series (Fig. 12): 1, 4, 9, 27 spheres of 760 triangles",
        &series,
    );
    std::fs::create_dir_all(out)?;
    std::fs::write(out.join("wedge_blending_errors.csv"), errors_csv(&reports))?;
    times.extend(series);
    std::fs::write(out.join("wedge_blending_times.csv"), times_csv(&times))?;
    std::fs::write(out.join("summary.md"), &summary)?;
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The measurement's invariants on a small frame: every variant ran on every pixel, the
    /// overlap pixels are a subset, the probe is an overlap pixel and its trace ends in the
    /// value the packed render gives there.
    #[test]
    fn scene_measurement_is_consistent() {
        let scene = sized(builtin::load("cube-of-spheres").unwrap(), 40);
        let r = measure_scene(&scene).unwrap();
        assert_eq!(r.errors.len(), VARIANTS.len());
        assert!(r.overlap_pixels > 0);
        for e in &r.errors {
            assert_eq!(e.all.pixels, 1600);
            assert_eq!(e.overlap.pixels, r.overlap_pixels as u64);
            assert!(e.all.rmse.is_finite());
        }
        let probe = r.probe.clone().expect("a probe off the occluders");
        let (x, y) = probe.pixel;
        assert!(x < 40 && y < 40 && !probe.steps.is_empty());
        let (last, truth) = probe.steps.last().unwrap();
        assert!(truth.union.iter().all(|u| (0.0..=1.0).contains(u)));
        let occluded: f32 = last.after.iter().map(|p| p.occlusion).sum::<f32>() * 0.25;
        assert_eq!((1.0 - occluded).clamp(0.0, 1.0), probe.packed);
        let text = scene_summary(&r);
        assert!(
            text.contains("overlap pixels") && text.contains("ε"),
            "{text}"
        );
        assert_eq!(errors_csv(&[r]).lines().count(), 1 + 2 * VARIANTS.len());
    }
}
