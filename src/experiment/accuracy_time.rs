//! What accuracy costs in time (issue 14, item 4): `penumbra experiment accuracy-time SCENE...`
//! renders every scene with every configuration of [`configurations`] that applies to it,
//! times each and measures its error against a high-sample reference, and draws error against
//! time with the Pareto front. `penumbra experiment merge DIR...` joins the outputs of shards.
//!
//! **The list.** For each scene in the order given, every configuration of the table in
//! table order whose method supports the scene's lights ([`methods::supports_scene`]) and
//! whose options the method accepts on that scene ([`methods::check_options`]; e.g.
//! `ssv-optimized`'s `light-split` is for rectangular lights only, `overlap = loops` refuses
//! z-fail). A configuration the method refuses is listed under `skipped` with the reason. The
//! knobs are set on top of the scene's own `[options.METHOD]` table; the scene's `methods`
//! list is ignored. Item `k` of this (scene × configuration) list is the sweep's `k`-th row.
//!
//! **The reference** is [`REFERENCE`] (`raycast` with 1024 samples per pixel, its default
//! seed), rendered once per scene. Its own sampling noise (the same settings with the next
//! seed, [`methods::raycast::reference_noise_floor`]) is reported next to it and drawn in the plot:
//! differences of that size are the reference's, not a method's. `raycast` with 1024 samples
//! is not in the default table: with the reference's seed its error is 0 by construction.
//!
//! **A measurement** of one configuration: one untimed render gives its error
//! ([`error_report`]: whole-image RMSE, mean and max |e|, % of pixels off by more than 1/255
//! and 4/255, the same over the reference's penumbra, and split into whole-light and horizon
//! receivers, [`crate::metrics::horizon`]) and warms the process-wide caches
//! (coverage textures, lookup tables), then `runs` timed renders (default [`TIMING_RUNS`])
//! give the median, min and max. The timed renders are interleaved: round 1 renders every
//! configuration of the shard once, then round 2, …, so a slow phase of the machine affects
//! all alike. A time is the method's own (`methods::run`); the scene pass, shared by all
//! methods, is rendered once per scene and excluded. Renders are deterministic, so every
//! column but the times is the same on every run and machine.
//!
//! **Modeled GPU time** (issue 29 item 4; [`crate::gpu_model`], `docs/gpu-model.md`): the
//! untimed render's passes priced on each profile of the run's list (`--gpu NAME`,
//! repeatable; default [`crate::gpu_model::DEFAULT_PROFILE`]) — the whole frame on that GPU,
//! the scene pass included, since a GPU renders it too; low, middle and high estimates
//! ([`Modeled`]). It is deterministic, so it is the same on every run and in every shard. A
//! method with no GPU pass besides the scene pass (`raycast`, a CPU ray tracer) is not
//! modeled: pricing only its scene pass would put it at the fast end of every front. Each
//! profile gets its own Pareto front on (middle estimate, RMSE) and its own plot, beside the
//! CPU-time one.
//!
//! **Shards.** `--shard I/N` (1-based: `1/4` … `4/4`) measures item `k` of the list when
//! `k mod N = I − 1` — round-robin slices, so that the costly configurations (e.g. `nsample`
//! with 1024 samples) spread over the shards. Every shard builds the whole list (a scene pass
//! per scene) and renders the reference of each scene it measures. A shard writes its rows
//! (`accuracy-time.csv`, `.json`, `summary.md`) but no plots; [`merge`] checks that the
//! shards are the `N` disjoint slices of one list and writes what an unsharded run writes.
//!
//! **Outputs** ([`write()`]): `accuracy-time.csv` and `accuracy-time.json` (one row per scene ×
//! configuration), `summary.md` (the table and the Pareto-optimal configurations per scene,
//! also printed), and per scene `SCENE-pareto.png` and `.svg`: RMSE against median time,
//! log–log, one colour per method, one numbered marker per knob setting, the Pareto front as
//! a step line ([`pareto_front`]); and per profile `SCENE-pareto-gpu-ID.png` and `.svg`: RMSE
//! against modeled time, the low–high range of each estimate as a bar.

pub mod plot;

use super::configured;
use super::spread;
use crate::error::InputError;
use crate::frame::Frame;
use crate::gpu_model::{GpuModel, Seconds};
use crate::methods;
use crate::metrics::error_report::error_report;
use crate::metrics::horizon::{receiver_classes, HorizonSplit};
use crate::metrics::ErrorStats;
use crate::render::gpu_settings;
use crate::scene::Scene;
use crate::visibility::Visibility;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// A method and its knob settings, `(method, &[(key, value), ...])`: one line of the sweep
/// table. Keys and values are written as `--opt METHOD.KEY=VALUE` takes them.
pub type Configuration = (&'static str, &'static [(&'static str, &'static str)]);

/// The configurations swept by default: every method of [`crate::methods::ALL`] in its
/// order, each with its own list ([`crate::methods::Method::sweep`], declared in the method's
/// module next to its goldens). Every value is one the method's option reader accepts
/// (tested):
/// - `hard-sv`, `penumbra-map`: their defaults;
/// - `nsample`: N = 4 … 1024 light samples; `raycast`: 4 … 256 samples per pixel — the
///   sampling baselines a user would otherwise pick;
/// - `pw2002`, `pw-restructured`: the LI buffer at 16, 12 and 8 bits;
/// - `ssv`: exact coverage with the V-buffer in f32, f16 and 8 bits; the coverage texture at
///   n = 8 … 64 with each of its filters (f32 V-buffer);
/// - `ssv-optimized`: its defaults (area tables, bilinear, the 12-bit value split over two
///   RGBA8 buffers), the nearest filter, exact coverage, the light split k = 2 … 4 (k = 1 is
///   the default) and the overlap approximation;
/// - `wedge-blending`: packed (8-bit, the default) and unpacked (f32), the centroid, the
///   inner-rectangle adjustment always / never, silhouettes grouped per mesh;
/// - `penumbra-map`: its defaults (the 8-bit map, the p-buffer of its time) and an f32 map;
/// - `dbuffer`: its defaults (smoothstep, f32 channels, interpolated distances, the corrected
///   eq. 3), √t, f16 channels, exact distances and eq. 3 as printed;
/// - every soft method once with `horizon = clip` (the receiver's own horizon, issue 28;
///   `nsample` at n = 64, `pw2002` and `pw-restructured` with the 16-bit LI buffer, `ssv` with
///   exact coverage and the f32 V-buffer, the others at their defaults).
pub fn configurations() -> Vec<Configuration> {
    crate::methods::ALL
        .iter()
        .flat_map(|m| m.sweep.iter().map(|knobs| (m.name, *knobs)))
        .collect()
}

/// The reference every configuration is measured against: `raycast` with 1024 jittered
/// stratified samples per pixel (and the scene's other `raycast` options, e.g. its seed).
pub const REFERENCE: Configuration = (crate::methods::REFERENCE, &[("samples", "1024")]);

/// Timed renders per configuration by default; the reported time is their median.
pub const TIMING_RUNS: usize = 5;

/// Where the experiment writes by default.
pub const DEFAULT_OUT: &str = "out/experiment/accuracy-time";

/// The JSON file a run writes and [`merge`] reads.
pub const JSON_FILE: &str = "accuracy-time.json";

/// The CSV file a run writes.
pub const CSV_FILE: &str = "accuracy-time.csv";

/// The table and Pareto-optimal configurations ([`summary`]) as a file.
pub const SUMMARY_FILE: &str = "summary.md";

/// The knobs of a configuration as one string: `key=value` pairs separated by spaces, in
/// table order, or `default` when there are none.
pub fn knobs_label(knobs: &[(&str, &str)]) -> String {
    if knobs.is_empty() {
        return "default".into();
    }
    knobs
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Which slice of the list a run measures: items `k` with `k mod count = index − 1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// 1-based shard number, `1..=count`.
    pub index: usize,
    /// Number of shards.
    pub count: usize,
}

impl Shard {
    /// The whole list (`1/1`).
    pub const WHOLE: Shard = Shard { index: 1, count: 1 };

    /// Reads `I/N` with `1 ≤ I ≤ N` (1-based), as `--shard` takes it.
    pub fn parse(spec: &str) -> Result<Shard, InputError> {
        let bad = |why: &str| {
            InputError::at(
                "--shard",
                spec,
                format!("{why}; expected I/N with 1 ≤ I ≤ N (1-based), e.g. 2/4"),
            )
        };
        let (i, n) = spec.split_once('/').ok_or_else(|| bad("no '/'"))?;
        let i: usize = i.trim().parse().map_err(|_| bad("I is not a number"))?;
        let n: usize = n.trim().parse().map_err(|_| bad("N is not a number"))?;
        if n == 0 {
            return Err(bad("N must be at least 1"));
        }
        if !(1..=n).contains(&i) {
            return Err(bad("I is out of range"));
        }
        Ok(Shard { index: i, count: n })
    }

    /// Whether item `k` (0-based) of the list belongs to this shard.
    pub fn holds(&self, k: usize) -> bool {
        k % self.count == self.index - 1
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// One entry of the (scene × configuration) list.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Item {
    /// The scene (built-in name or file path).
    pub scene: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The method.
    pub method: String,
    /// Its knobs ([`knobs_label`]).
    pub knobs: String,
}

/// A configuration that applies to a scene's light shape but that the method refuses on it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Skipped {
    /// The scene.
    pub scene: String,
    /// The method.
    pub method: String,
    /// Its knobs ([`knobs_label`]).
    pub knobs: String,
    /// The method's option error.
    pub reason: String,
}

/// The reference of one scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Reference {
    /// The scene.
    pub scene: String,
    /// Wall seconds of its one render (informational).
    pub seconds: f64,
    /// Its own sampling noise: the reference against itself with the next seed
    /// ([`methods::raycast::reference_noise_floor`]).
    pub noise_floor: ErrorStats,
}

/// The modeled time of one item on one GPU profile (module doc).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Modeled {
    /// The profile's id.
    pub gpu: String,
    /// The whole frame's modeled seconds; `None` for a method with no GPU pass besides the
    /// scene pass.
    pub seconds: Option<Seconds>,
    /// Whether it is on its scene's Pareto front of (middle estimate, RMSE) on this profile.
    pub pareto: bool,
}

/// The measurement of one item.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// Its position in the whole list (0-based).
    pub index: usize,
    /// What was measured.
    #[serde(flatten)]
    pub item: Item,
    /// Median wall seconds of the timed renders.
    pub median_seconds: f64,
    /// Fastest timed render.
    pub min_seconds: f64,
    /// Slowest timed render.
    pub max_seconds: f64,
    /// Number of timed renders.
    pub runs: usize,
    /// Error against the reference over the whole image.
    pub error: ErrorStats,
    /// Error over the reference's penumbra (pixels strictly between 0 and 1).
    pub penumbra: ErrorStats,
    /// Error over the whole-light and the horizon receivers ([`crate::metrics::horizon`]).
    pub horizon: HorizonSplit,
    /// Whether it is on its scene's Pareto front of (median time, RMSE) ([`pareto_front`];
    /// depends on the times).
    pub pareto: bool,
    /// Its modeled time on each profile of [`Sweep::gpus`], in that order.
    #[serde(default)]
    pub modeled: Vec<Modeled>,
}

/// What a run (or a merge) produced; `accuracy-time.json` holds it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sweep {
    /// The slice measured ([`Shard::WHOLE`] for an unsharded run or a merge).
    pub shard: Shard,
    /// The reference configuration, `method knobs`.
    pub reference: String,
    /// The GPU profiles every row's time is modeled on ([`Modeled`]).
    #[serde(default)]
    pub gpus: Vec<String>,
    /// The whole (scene × configuration) list, whatever the shard.
    pub items: Vec<Item>,
    /// Configurations the methods refused, per scene.
    pub skipped: Vec<Skipped>,
    /// The reference of every scene measured, in scene order.
    pub references: Vec<Reference>,
    /// The rows measured, in list order.
    pub rows: Vec<Row>,
}

/// The file-name stem of a scene's plots: the built-in name or the file's stem, with every
/// character other than ASCII letters, digits, `-` and `_` replaced by `-`.
pub fn plot_stem(scene: &str) -> String {
    let stem = Path::new(scene)
        .file_stem()
        .map_or(scene.into(), |s| s.to_string_lossy());
    stem.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '-'
            }
        })
        .collect()
}

/// The indices of the Pareto-optimal points among `points` = (time, error): those that no
/// other point dominates, where `q` dominates `p` when `q` is at least as fast and at least as
/// accurate and strictly better in one of the two (so of two identical points both stay). A
/// point with a NaN coordinate is never on the front and dominates nothing. Sorted by time,
/// then error, then index: along the front the error decreases as the time grows.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let dominates =
        |q: (f64, f64), p: (f64, f64)| q.0 <= p.0 && q.1 <= p.1 && (q.0 < p.0 || q.1 < p.1);
    let mut front: Vec<usize> = (0..points.len())
        .filter(|&i| {
            let p = points[i];
            !p.0.is_nan() && !p.1.is_nan() && !points.iter().any(|&q| dominates(q, p))
        })
        .collect();
    front.sort_by(|&a, &b| {
        let (p, q) = (points[a], points[b]);
        p.0.total_cmp(&q.0)
            .then(p.1.total_cmp(&q.1))
            .then(a.cmp(&b))
    });
    front
}

/// A time axis of the sweep: the measured CPU time, or the modeled time on the `k`-th profile
/// of [`Sweep::gpus`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeAxis {
    /// Median wall seconds of the timed renders.
    Cpu,
    /// The middle modeled estimate on profile `k`.
    Gpu(usize),
}

impl TimeAxis {
    /// The time of `row` on this axis (NaN for a row not modeled, which is never on a front).
    pub fn seconds(self, row: &Row) -> f64 {
        match self {
            TimeAxis::Cpu => row.median_seconds,
            TimeAxis::Gpu(k) => row
                .modeled
                .get(k)
                .and_then(|m| m.seconds)
                .map_or(f64::NAN, |s| s.mid),
        }
    }

    /// Whether `row` is on its scene's front on this axis.
    pub fn pareto(self, row: &Row) -> bool {
        match self {
            TimeAxis::Cpu => row.pareto,
            TimeAxis::Gpu(k) => row.modeled.get(k).is_some_and(|m| m.pareto),
        }
    }

    fn set_pareto(self, row: &mut Row, on: bool) {
        match self {
            TimeAxis::Cpu => row.pareto = on,
            TimeAxis::Gpu(k) => {
                if let Some(m) = row.modeled.get_mut(k) {
                    m.pareto = on;
                }
            }
        }
    }

    /// Every axis of `sweep`: CPU time, then each profile.
    pub fn all(sweep: &Sweep) -> Vec<TimeAxis> {
        Self::of(sweep.gpus.len())
    }

    /// CPU time, then the modeled time on each of `gpus` profiles.
    fn of(gpus: usize) -> Vec<TimeAxis> {
        std::iter::once(TimeAxis::Cpu)
            .chain((0..gpus).map(TimeAxis::Gpu))
            .collect()
    }
}

/// Sets the Pareto flags of every row, per scene, on (time, RMSE) for each of the `gpus + 1`
/// time axes.
fn mark_pareto(rows: &mut [Row], gpus: usize) {
    let mut scenes: Vec<String> = rows.iter().map(|r| r.item.scene.clone()).collect();
    scenes.dedup();
    for axis in TimeAxis::of(gpus) {
        for scene in &scenes {
            let idx: Vec<usize> = (0..rows.len())
                .filter(|&i| &rows[i].item.scene == scene)
                .collect();
            let points: Vec<(f64, f64)> = idx
                .iter()
                .map(|&i| (axis.seconds(&rows[i]), rows[i].error.rmse))
                .collect();
            let front = pareto_front(&points);
            for (j, &i) in idx.iter().enumerate() {
                axis.set_pareto(&mut rows[i], front.contains(&j));
            }
        }
    }
}

/// The modeled time of a method's output on `gpu`: `None` when no pass besides the first (the
/// frame's scene pass) has GPU work.
fn modeled_seconds(gpu: GpuModel, out: &methods::output::MethodOutput) -> Option<Seconds> {
    let e = crate::gpu_model::estimate(gpu.profile(), &out.stats.passes);
    let on_gpu = e.passes.iter().skip(1).any(|p| p.high > 0.0);
    on_gpu.then_some(e.seconds)
}

/// Measures the `shard` of the list of `scenes` × `configurations` (module doc) with `runs`
/// timed renders per item (at least 1), each item's time also modeled on every profile of
/// `gpus` (distinct). Scenes are rendered at their own size; their plot names
/// ([`plot_stem`]) must differ.
pub fn run(
    scenes: &[Scene],
    configurations: &[Configuration],
    runs: usize,
    shard: Shard,
    gpus: &[GpuModel],
) -> Result<Sweep, InputError> {
    for (i, g) in gpus.iter().enumerate() {
        if gpus[..i].contains(g) {
            return Err(InputError::at(
                "--gpu",
                &g.profile().id,
                "given twice: each profile is modeled once",
            ));
        }
    }
    if runs == 0 {
        return Err(InputError::at(
            "--runs",
            "0",
            "expected at least 1 timed run",
        ));
    }
    for (i, s) in scenes.iter().enumerate() {
        if let Some(t) = scenes[..i]
            .iter()
            .find(|t| plot_stem(&t.source) == plot_stem(&s.source))
        {
            return Err(InputError::at(
                &s.source,
                "scene",
                format!(
                    "given twice, or its plots would overwrite those of {} (both are named {})",
                    t.source,
                    plot_stem(&s.source)
                ),
            ));
        }
    }
    let frames = scenes
        .iter()
        .map(|s| {
            methods::check_option_tables(s)?;
            Frame::render(s, gpu_settings(s)?)
        })
        .collect::<Result<Vec<_>, _>>()?;
    // The whole list, with each item's configured scene.
    let mut items = Vec::new();
    let mut item_scenes: Vec<(usize, &str, Scene)> = Vec::new();
    let mut skipped = Vec::new();
    for (si, scene) in scenes.iter().enumerate() {
        for &(method, knobs) in configurations {
            if !methods::supports_scene(method, scene) {
                continue;
            }
            let s = configured(scene, method, knobs);
            match methods::check_options(method, &frames[si].lit_by(&s)) {
                Ok(()) => {
                    items.push(Item {
                        scene: scene.source.clone(),
                        width: scene.width,
                        height: scene.height,
                        method: method.into(),
                        knobs: knobs_label(knobs),
                    });
                    item_scenes.push((si, method, s));
                }
                Err(e) => skipped.push(Skipped {
                    scene: scene.source.clone(),
                    method: method.into(),
                    knobs: knobs_label(knobs),
                    reason: e.message,
                }),
            }
        }
    }
    let mine: Vec<usize> = (0..items.len()).filter(|&k| shard.holds(k)).collect();
    // The reference of every scene this shard measures.
    let mut references = Vec::new();
    let mut reference_vis: Vec<Option<Visibility>> = vec![None; scenes.len()];
    for (si, scene) in scenes.iter().enumerate() {
        if !mine.iter().any(|&k| item_scenes[k].0 == si) {
            continue;
        }
        let s = configured(scene, REFERENCE.0, REFERENCE.1);
        let frame = frames[si].lit_by(&s);
        let start = Instant::now();
        let vis = methods::run(REFERENCE.0, &frame)?.visibility;
        let seconds = start.elapsed().as_secs_f64();
        references.push(Reference {
            scene: scene.source.clone(),
            seconds,
            noise_floor: methods::raycast::reference_noise_floor(&frame, &vis)?,
        });
        reference_vis[si] = Some(vis);
    }
    // The untimed render of each item: its error.
    let item_frames: Vec<Frame> = mine
        .iter()
        .map(|&k| frames[item_scenes[k].0].lit_by(&item_scenes[k].2))
        .collect();
    let classes: Vec<_> = frames
        .iter()
        .map(|f| receiver_classes(&f.scene.lights, f.receivers()))
        .collect();
    let mut errors = Vec::new();
    let mut modeled = Vec::new();
    for (j, &k) in mine.iter().enumerate() {
        let (si, method, _) = &item_scenes[k];
        let out = methods::run(method, &item_frames[j])?;
        let reference = reference_vis[*si].as_ref().expect("rendered above");
        errors.push(error_report(
            &out.visibility,
            reference,
            REFERENCE.0,
            &classes[*si],
        ));
        modeled.push(
            gpus.iter()
                .map(|&g| Modeled {
                    gpu: g.profile().id.clone(),
                    seconds: modeled_seconds(g, &out),
                    pareto: false,
                })
                .collect::<Vec<_>>(),
        );
    }
    // The timed renders, interleaved.
    let mut times: Vec<Vec<f64>> = vec![Vec::with_capacity(runs); mine.len()];
    for _ in 0..runs {
        for (j, &k) in mine.iter().enumerate() {
            let start = Instant::now();
            methods::run(item_scenes[k].1, &item_frames[j])?;
            times[j].push(start.elapsed().as_secs_f64());
        }
    }
    let mut rows: Vec<Row> = mine
        .iter()
        .zip(errors)
        .zip(times)
        .zip(modeled)
        .map(|(((&k, e), t), modeled)| {
            let (median_seconds, min_seconds, max_seconds) = spread(t);
            Row {
                index: k,
                item: items[k].clone(),
                median_seconds,
                min_seconds,
                max_seconds,
                runs,
                error: e.all,
                penumbra: e.penumbra_only,
                horizon: e.horizon_split,
                pareto: false,
                modeled,
            }
        })
        .collect();
    mark_pareto(&mut rows, gpus.len());
    Ok(Sweep {
        shard,
        reference: format!("{} {}", REFERENCE.0, knobs_label(REFERENCE.1)),
        gpus: gpus.iter().map(|g| g.profile().id.clone()).collect(),
        items,
        skipped,
        references,
        rows,
    })
}

/// Reads the `accuracy-time.json` a run wrote into `dir`.
pub fn read(dir: &Path) -> Result<Sweep, InputError> {
    let path = dir.join(JSON_FILE);
    let shown = path.display().to_string();
    let bytes = crate::scene::input_file::read_input_file(&path)
        .map_err(|e| InputError::new(&shown, format!("cannot read the shard's results: {e}")))?;
    serde_json::from_slice(&bytes)
        .map_err(|e| InputError::new(&shown, format!("not an accuracy-time result: {e}")))
}

/// Joins the sweeps of shards, each given with the name to use in messages (its directory):
/// they must be the `N` disjoint slices `1/N … N/N` of one list (same items, skipped
/// configurations and reference), each holding exactly its rows, and their references of a
/// scene must agree. The result is what an unsharded run gives, but for the times.
pub fn merge(shards: &[(String, Sweep)]) -> Result<Sweep, InputError> {
    let Some((first_name, first)) = shards.first() else {
        return Err(InputError::new("merge", "no shard directories given"));
    };
    let count = first.shard.count;
    let mut seen: Vec<Option<&str>> = vec![None; count];
    for (name, s) in shards {
        if s.items != first.items
            || s.skipped != first.skipped
            || s.reference != first.reference
            || s.gpus != first.gpus
        {
            return Err(InputError::new(
                name,
                format!(
                    "not a slice of the same sweep as {first_name}: the (scene × configuration) \
                     list or the GPU profiles differ"
                ),
            ));
        }
        if s.shard.count != count || !(1..=count).contains(&s.shard.index) {
            return Err(InputError::new(
                name,
                format!(
                    "shard {} is not one of {count} shards like {first_name} ({})",
                    s.shard, first.shard
                ),
            ));
        }
        if let Some(other) = seen[s.shard.index - 1].replace(name) {
            return Err(InputError::new(
                name,
                format!("shard {} is also in {other}: the slices overlap", s.shard),
            ));
        }
        let expected: Vec<usize> = (0..first.items.len())
            .filter(|&k| s.shard.holds(k))
            .collect();
        let held: Vec<usize> = s.rows.iter().map(|r| r.index).collect();
        if held != expected || s.rows.iter().any(|r| r.item != first.items[r.index]) {
            return Err(InputError::new(
                name,
                format!("its rows are not those of shard {}", s.shard),
            ));
        }
    }
    let missing: Vec<String> = (0..count)
        .filter(|&i| seen[i].is_none())
        .map(|i| format!("{}/{count}", i + 1))
        .collect();
    if !missing.is_empty() {
        return Err(InputError::new(
            "merge",
            format!("shards missing: {}", missing.join(", ")),
        ));
    }
    let mut rows: Vec<Row> = shards
        .iter()
        .flat_map(|(_, s)| s.rows.iter().cloned())
        .collect();
    rows.sort_by_key(|r| r.index);
    mark_pareto(&mut rows, first.gpus.len());
    let mut references: Vec<Reference> = Vec::new();
    for item in &first.items {
        if references.iter().any(|r| r.scene == item.scene) {
            continue;
        }
        let mut found = shards
            .iter()
            .flat_map(|(name, s)| s.references.iter().map(move |r| (name, r)))
            .filter(|(_, r)| r.scene == item.scene);
        if let Some((_, r)) = found.next() {
            if let Some((name, _)) = found.find(|(_, o)| o.noise_floor != r.noise_floor) {
                return Err(InputError::new(
                    name,
                    format!("its reference of {} differs from another shard's", r.scene),
                ));
            }
            references.push(r.clone());
        }
    }
    Ok(Sweep {
        shard: Shard::WHOLE,
        reference: first.reference.clone(),
        gpus: first.gpus.clone(),
        items: first.items.clone(),
        skipped: first.skipped.clone(),
        references,
        rows,
    })
}

/// A CSV field: quoted (with inner quotes doubled) when it holds a comma, quote or newline.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.into()
    }
}

/// The header of `accuracy-time.csv` up to its modeled-time columns ([`csv_header`]).
pub const CSV_HEADER: &str = "scene,width,height,method,knobs,median_seconds,min_seconds,\
max_seconds,runs,rmse,mean_abs,max_abs,pct_over_1_255,pct_over_4_255,pixels,penumbra_rmse,\
penumbra_mean_abs,penumbra_max_abs,penumbra_pct_over_1_255,penumbra_pct_over_4_255,\
penumbra_pixels,whole_light_mean_abs,whole_light_pixels,horizon_mean_abs,horizon_pixels,\
horizon_pct,horizon_share,pareto";

/// The header of `accuracy-time.csv` for the profiles `gpus`: [`CSV_HEADER`], then per
/// profile `gpu_ID_low`, `gpu_ID_mid`, `gpu_ID_high` (modeled seconds, empty for a row not
/// modeled) and `gpu_ID_pareto`.
pub fn csv_header(gpus: &[String]) -> String {
    let mut h = CSV_HEADER.to_string();
    for g in gpus {
        let _ = write!(h, ",gpu_{g}_low,gpu_{g}_mid,gpu_{g}_high,gpu_{g}_pareto");
    }
    h
}

/// `accuracy-time.csv`: [`csv_header`], then one line per row (floats written exactly, as
/// Rust's shortest round-trip form).
pub fn csv(sweep: &Sweep) -> String {
    let mut s = format!("{}\n", csv_header(&sweep.gpus));
    for r in &sweep.rows {
        let e = |st: &ErrorStats| {
            format!(
                "{},{},{},{},{},{}",
                st.rmse, st.mean_abs, st.max_abs, st.pct_over_1_255, st.pct_over_4_255, st.pixels
            )
        };
        let _ = write!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            csv_field(&r.item.scene),
            r.item.width,
            r.item.height,
            csv_field(&r.item.method),
            csv_field(&r.item.knobs),
            r.median_seconds,
            r.min_seconds,
            r.max_seconds,
            r.runs,
            e(&r.error),
            e(&r.penumbra),
            r.horizon.whole_light.mean_abs,
            r.horizon.whole_light.pixels,
            r.horizon.horizon.mean_abs,
            r.horizon.horizon.pixels,
            r.horizon.horizon_pct,
            r.horizon.horizon_share,
            r.pareto
        );
        for m in &r.modeled {
            let _ = match m.seconds {
                Some(t) => write!(s, ",{},{},{},{}", t.low, t.mid, t.high, m.pareto),
                None => write!(s, ",,,,{}", m.pareto),
            };
        }
        s.push('\n');
    }
    s
}

/// The scenes of `sweep`'s rows, in list order.
fn row_scenes(sweep: &Sweep) -> Vec<&str> {
    let mut scenes: Vec<&str> = Vec::new();
    for r in &sweep.rows {
        if !scenes.contains(&r.item.scene.as_str()) {
            scenes.push(&r.item.scene);
        }
    }
    scenes
}

/// The Pareto-optimal rows of `scene` on `axis`, fastest first, each with its number in the
/// scene's table (1-based, the number of its marker in the plot).
pub fn pareto_rows<'a>(sweep: &'a Sweep, scene: &str, axis: TimeAxis) -> Vec<(usize, &'a Row)> {
    let mut front: Vec<(usize, &Row)> = sweep
        .rows
        .iter()
        .filter(|r| r.item.scene == scene)
        .enumerate()
        .filter(|(_, r)| axis.pareto(r))
        .map(|(n, r)| (n + 1, r))
        .collect();
    front.sort_by(|a, b| axis.seconds(a.1).total_cmp(&axis.seconds(b.1)));
    front
}

/// The file names of `scene`'s Pareto plot on `axis`, PNG and SVG ([`plot_stem`]):
/// `STEM-pareto` for CPU time, `STEM-pareto-gpu-ID` for a profile's modeled time.
pub fn plot_files(sweep: &Sweep, scene: &str, axis: TimeAxis) -> [String; 2] {
    let stem = match axis {
        TimeAxis::Cpu => format!("{}-pareto", plot_stem(scene)),
        TimeAxis::Gpu(k) => format!("{}-pareto-gpu-{}", plot_stem(scene), sweep.gpus[k]),
    };
    [format!("{stem}.png"), format!("{stem}.svg")]
}

/// How `axis` is named in tables and plots.
pub fn axis_label(sweep: &Sweep, axis: TimeAxis) -> String {
    match axis {
        TimeAxis::Cpu => "CPU time (measured)".into(),
        TimeAxis::Gpu(k) => format!("modeled time on {} (a model)", sweep.gpus[k]),
    }
}

/// A row's modeled time on profile `k` for a table: `mid (low–high)` in ms, or `—`.
fn modeled_ms(row: &Row, k: usize) -> String {
    match row.modeled.get(k).and_then(|m| m.seconds) {
        Some(t) => format!(
            "{} ({}–{})",
            fmt_g(1e3 * t.mid),
            fmt_g(1e3 * t.low),
            fmt_g(1e3 * t.high)
        ),
        None => "—".into(),
    }
}

/// The table and the Pareto-optimal configurations of every scene (what the command prints
/// and `summary.md` holds).
pub fn summary(sweep: &Sweep) -> String {
    let mut s = format!(
        "# accuracy–time, shard {}: error against {} and time per frame (the method alone, \
         scene pass excluded; median of the timed runs, min–max) on {} threads\n",
        sweep.shard,
        sweep.reference,
        rayon::current_num_threads()
    );
    for scene in row_scenes(sweep) {
        let rows: Vec<&Row> = sweep
            .rows
            .iter()
            .filter(|r| r.item.scene == scene)
            .collect();
        let (w, h) = (rows[0].item.width, rows[0].item.height);
        let _ = writeln!(s, "\n## {scene} ({w}×{h})\n");
        if let Some(r) = sweep.references.iter().find(|r| r.scene == scene) {
            let _ = writeln!(
                s,
                "Reference: {} s; its own noise (seed + 1): RMSE {:.5}, max |e| {:.4}, {:.2} % \
                 > 1/255.\n",
                fmt_g(r.seconds),
                r.noise_floor.rmse,
                r.noise_floor.max_abs,
                r.noise_floor.pct_over_1_255
            );
        }
        let gpu_heads: String = sweep
            .gpus
            .iter()
            .map(|g| format!(" {g} model [ms] | Pareto |"))
            .collect();
        let _ = writeln!(
            s,
            "| # | method | knobs | median [ms] | min–max [ms] | RMSE | max \\|e\\| | % > 1/255 | \
             penumbra RMSE | whole-light mean \\|e\\| | horizon mean \\|e\\| | horizon share | \
             Pareto |{gpu_heads}"
        );
        let _ = writeln!(
            s,
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|{}",
            "---|---|".repeat(sweep.gpus.len())
        );
        for (n, r) in rows.iter().enumerate() {
            let gpu_cells: String = (0..sweep.gpus.len())
                .map(|k| {
                    let star = if TimeAxis::Gpu(k).pareto(r) {
                        "★"
                    } else {
                        ""
                    };
                    format!(" {} | {star} |", modeled_ms(r, k))
                })
                .collect();
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {}–{} | {:.5} | {:.4} | {:.2} | {:.5} | {:.5} | {:.5} | {:.3} \
                 | {} |{gpu_cells}",
                n + 1,
                r.item.method,
                r.item.knobs,
                fmt_g(1e3 * r.median_seconds),
                fmt_g(1e3 * r.min_seconds),
                fmt_g(1e3 * r.max_seconds),
                r.error.rmse,
                r.error.max_abs,
                r.error.pct_over_1_255,
                r.penumbra.rmse,
                r.horizon.whole_light.mean_abs,
                r.horizon.horizon.mean_abs,
                r.horizon.horizon_share,
                if r.pareto { "★" } else { "" }
            );
        }
        for axis in TimeAxis::all(sweep) {
            let _ = writeln!(
                s,
                "\nPareto-optimal on {scene} in {}, fastest first:",
                axis_label(sweep, axis)
            );
            for (n, r) in pareto_rows(sweep, scene, axis) {
                let _ = writeln!(
                    s,
                    "- #{} {} {}: {} ms, RMSE {:.5}",
                    n,
                    r.item.method,
                    r.item.knobs,
                    fmt_g(1e3 * axis.seconds(r)),
                    r.error.rmse
                );
            }
        }
        if !sweep.gpus.is_empty() {
            let _ = writeln!(
                s,
                "\nModeled times are the whole frame (scene pass included) priced by the GPU \
                 cost model (docs/gpu-model.md), middle estimate (low–high); — = a CPU-only \
                 method the model does not price."
            );
        }
    }
    let _ = writeln!(
        s,
        "\n{} of {} configurations measured in this run.",
        sweep.rows.len(),
        sweep.items.len()
    );
    for k in &sweep.skipped {
        let _ = writeln!(
            s,
            "skipped on {}: {} {}: {}",
            k.scene, k.method, k.knobs, k.reason
        );
    }
    s
}

/// `x` with 3 significant digits (no exponent between 0.001 and 10⁶).
pub fn fmt_g(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let digits = (2 - libm::log10(x.abs()).floor() as i32).max(0) as usize;
    format!("{x:.digits$}")
}

/// Writes `sweep`'s outputs into `out` (module doc): the CSV, the JSON and `summary.md`, and
/// for a whole sweep ([`Shard::WHOLE`]) the Pareto plots of every scene and time axis — all or nothing
/// ([`crate::output::write_files_all_or_nothing`]).
pub fn write(sweep: &Sweep, out: &Path) -> std::io::Result<()> {
    let json = serde_json::to_string_pretty(sweep).map_err(std::io::Error::other)?;
    let mut files = vec![
        (CSV_FILE.to_string(), csv(sweep).into_bytes()),
        (JSON_FILE.to_string(), json.into_bytes()),
        (SUMMARY_FILE.to_string(), summary(sweep).into_bytes()),
    ];
    if sweep.shard == Shard::WHOLE {
        for scene in row_scenes(sweep) {
            for axis in TimeAxis::all(sweep) {
                let (png, svg) =
                    plot::pareto_plot(sweep, scene, axis).map_err(std::io::Error::other)?;
                let [png_file, svg_file] = plot_files(sweep, scene, axis);
                files.push((png_file, png));
                files.push((svg_file, svg.into_bytes()));
            }
        }
    }
    crate::output::write_files_all_or_nothing(out, &files)
}
