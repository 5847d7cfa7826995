//! Rendering one scene with a set of methods: the frame's scene pass, every method, the shaded
//! images, the error table against the reference — all in memory, so that a bad option stops
//! the run before any file is written (`docs/architecture.md` "Bad input": no partial
//! outputs).

use crate::error::InputError;
use crate::frame::{Frame, GpuOptions, GpuSettings, BACKGROUND};
use crate::methods::{self, output::MethodOutput};
use crate::metrics::error_report::{error_report, ErrorReport};
use crate::metrics::horizon::{receiver_classes, HorizonSplit};
use crate::metrics::ErrorStats;
use crate::options::OptionTable;
use crate::output::Comparison;
use crate::scene::{OptionValue, Scene};
use crate::visibility::Visibility;
use std::path::Path;

/// Where `render`, `report` and the default run write by default.
pub const DEFAULT_OUT: &str = "out";

/// Colour of pixels where no geometry was drawn (linear RGB).
pub const BACKGROUND_COLOR: [f32; 3] = [0.02, 0.02, 0.03];

/// One method's result within a render.
#[derive(Debug, Clone)]
pub struct MethodRun {
    /// Method name.
    pub method: String,
    /// Its output.
    pub output: MethodOutput,
    /// The shaded image, linear RGB, row-major.
    pub shaded: Vec<[f32; 3]>,
    /// Error against the reference (whole image, the reference's penumbra, and split by the
    /// receiver's horizon), when the reference ran and this is not it.
    pub error: Option<ErrorReport>,
    /// For the reference: its own sampling noise, the reference against itself with the next
    /// seed ([`methods::raycast::reference_noise_floor`]).
    pub noise_floor: Option<ErrorStats>,
    /// For the scene's best method (lowest RMSE among those with a `horizon` key the scene
    /// leaves at its default `off`): its error rerun with `horizon = clip` on the same frame
    /// (issue 28: shown next to `off` under the table and in the report).
    pub horizon_clip: Option<ErrorReport>,
}

/// The pipeline settings `[options.gpu]` of `scene` asks for ([`GpuOptions`]).
pub fn gpu_settings(scene: &Scene) -> Result<GpuSettings, InputError> {
    Ok(GpuOptions::read(scene)?.settings())
}

/// The shaded image (`docs/architecture.md` "The flow of one frame"): `albedo · (ambient +
/// visibility · max(0, n·l))` with l toward the light center (a point light there), per RGB channel
/// of the visibility. With several lights the diffuse term is the mean of `max(0, n·l_k)` over the
/// lights: a method's visibility is already the mean over the lights (Paper I §7), so per-light
/// terms cannot be weighted separately.
pub fn shade(frame: &Frame, vis: &Visibility) -> Vec<[f32; 3]> {
    let receivers = frame.receivers();
    let prims = frame.prim_ids();
    let ambient = frame.scene.ambient;
    let lights = &frame.scene.lights;
    let n = lights.len() as f32;
    receivers
        .iter()
        .zip(prims)
        .enumerate()
        .map(|(i, (r, prim))| match r {
            Some(r) if *prim != BACKGROUND => {
                let (mi, _) = frame.prim_owner[*prim as usize];
                let albedo = frame.scene.meshes[mi as usize].color;
                let diffuse = lights
                    .iter()
                    .map(|l| {
                        r.normal
                            .dot((l.center - r.point).normalize_or_zero())
                            .max(0.0)
                    })
                    .sum::<f32>()
                    / n;
                let v = vis.rgb(i);
                std::array::from_fn(|c| (albedo[c] * (ambient + v[c] * diffuse)).clamp(0.0, 1.0))
            }
            _ => BACKGROUND_COLOR,
        })
        .collect()
}

/// Render `scene` with its selected methods. The reference runs first when selected; every
/// other method's error is measured against it.
pub fn render_scene(scene: &Scene) -> Result<Vec<MethodRun>, InputError> {
    render_scene_with(scene, |_| {})
}

/// The scene pass of `scene` with `[options.gpu]`, after every method's options were checked,
/// also of methods not rendered now, so that a bad option stops a run before any method runs
/// (the table names are [`methods::check_option_tables`]'s, which callers run first).
pub fn checked_frame(scene: &Scene) -> Result<Frame<'_>, InputError> {
    let frame = Frame::render(scene, gpu_settings(scene)?)?;
    for method in scene.options.keys().filter(|k| k.as_str() != "gpu") {
        methods::check_options(method, &frame)?;
    }
    Ok(frame)
}

/// The methods [`render_scene`] runs on `scene`, in the order it runs them: the reference
/// first when selected, then the others in their selected order.
pub fn render_order(scene: &Scene) -> Result<Vec<String>, InputError> {
    let selected = methods::selected(scene)?;
    let (mut order, others): (Vec<String>, Vec<String>) = selected
        .into_iter()
        .partition(|m| m.as_str() == methods::REFERENCE);
    order.extend(others);
    Ok(order)
}

/// [`render_scene`], calling `starting(method)` before each method runs (e.g. to advance a
/// progress bar).
pub fn render_scene_with(
    scene: &Scene,
    starting: impl FnMut(&str),
) -> Result<Vec<MethodRun>, InputError> {
    render_scene_dumping(scene, false, starting)
}

/// [`render_scene_with`]; with `dump_buffers` every method also hands back every buffer it
/// resolved, with its event map (`--dump-buffers`, [`crate::methods::dump`]).
pub fn render_scene_dumping(
    scene: &Scene,
    dump_buffers: bool,
    mut starting: impl FnMut(&str),
) -> Result<Vec<MethodRun>, InputError> {
    methods::check_option_tables(scene)?;
    let order = render_order(scene)?;
    let frame = checked_frame(scene)?.dumping(dump_buffers);
    let classes = receiver_classes(&frame.scene.lights, frame.receivers());
    let mut runs: Vec<MethodRun> = Vec::new();
    for m in &order {
        starting(m);
        let output = methods::run(m, &frame)?;
        let shaded = shade(&frame, &output.visibility);
        let error = runs
            .iter()
            .find(|r| r.method == methods::REFERENCE)
            .filter(|_| m != methods::REFERENCE)
            .map(|r| {
                error_report(
                    &output.visibility,
                    &r.output.visibility,
                    methods::REFERENCE,
                    &classes,
                )
            });
        let noise_floor = if m == methods::REFERENCE {
            Some(methods::raycast::reference_noise_floor(
                &frame,
                &output.visibility,
            )?)
        } else {
            None
        };
        runs.push(MethodRun {
            method: m.clone(),
            output,
            shaded,
            error,
            noise_floor,
            horizon_clip: None,
        });
    }
    if let Some(best) = best_with_horizon_key(scene, &runs) {
        let reference = runs
            .iter()
            .find(|r| r.method == methods::REFERENCE)
            .map(|r| &r.output.visibility)
            .expect("a run with an error has the reference");
        let mut clipped = scene.clone();
        clipped
            .options
            .entry(runs[best].method.clone())
            .or_default()
            .insert("horizon".into(), OptionValue::Str("clip".into()));
        let out = methods::run(&runs[best].method, &frame.lit_by(&clipped))?;
        runs[best].horizon_clip = Some(error_report(
            &out.visibility,
            reference,
            methods::REFERENCE,
            &classes,
        ));
    }
    Ok(runs)
}

/// The index of the run with the lowest whole-image RMSE against the reference among the
/// methods whose option table has the `horizon` key and whose scene leaves it unset (the
/// method [`MethodRun::horizon_clip`] is measured for), if any.
fn best_with_horizon_key(scene: &Scene, runs: &[MethodRun]) -> Option<usize> {
    let docs = methods::option_docs();
    let has_key = |m: &str| {
        docs.iter()
            .any(|(t, keys)| *t == m && keys.iter().any(|k| k.key == "horizon"))
    };
    runs.iter()
        .enumerate()
        .filter(|(_, r)| has_key(&r.method))
        .filter(|(_, r)| {
            !scene
                .options
                .get(&r.method)
                .is_some_and(|t| t.contains_key("horizon"))
        })
        .filter_map(|(i, r)| Some((i, r.error.as_ref()?.all.rmse)))
        .filter(|(_, e)| e.is_finite())
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// Write every run's files under `dir/METHOD/`, all or nothing: the method folders appear
/// only once every method's files were written ([`crate::output::write_method_dirs`]). When
/// the reference ran, every other method also gets `error.png` and its error (whole image and
/// penumbra only) in `stats.json` ([`Comparison`]). Every buffer dump's raw file is written;
/// with `dump_buffers` also its sidecar, viewable image and event map
/// ([`crate::output::dump`]). Returns the names of the files written into each method's
/// folder, in the order of `runs`.
pub fn write_runs(
    dir: &Path,
    scene: &Scene,
    runs: &[MethodRun],
    dump_buffers: bool,
) -> std::io::Result<Vec<Vec<String>>> {
    let names: Vec<&str> = runs.iter().map(|r| r.method.as_str()).collect();
    let reference = runs.iter().find(|r| r.method == methods::REFERENCE);
    crate::output::write_method_dirs(dir, &names, |i| {
        let r = &runs[i];
        let comparison = match (reference, &r.error) {
            (None, _) => Comparison::NoReference,
            (Some(reference), Some(report)) => Comparison::Against {
                report,
                reference: &reference.output.visibility,
            },
            (Some(_), None) => Comparison::Reference {
                noise_floor: r.noise_floor,
            },
        };
        crate::output::encode_method_outputs(
            &r.output,
            &r.shaded,
            (scene.width, scene.height),
            &scene.source,
            &comparison,
            dump_buffers,
        )
    })
}

/// One row of a run's table: what [`table`] prints and the HTML report
/// ([`crate::report`]) shows.
#[derive(Debug, Clone, Copy)]
pub struct TableRow<'a> {
    /// The method's run.
    pub run: &'a MethodRun,
    /// Its error against the reference over the whole image or, for the reference itself,
    /// its noise floor; `None` when no reference ran.
    pub error: Option<&'a ErrorStats>,
    /// Its error over the reference's penumbra (not for the reference itself).
    pub penumbra_error: Option<&'a ErrorStats>,
    /// Its error over whole-light and horizon receivers (not for the reference itself;
    /// [`crate::metrics::horizon`]).
    pub horizon: Option<&'a HorizonSplit>,
    /// Buffer traffic of the whole method, in MB (10⁶ bytes).
    pub traffic_mb: f64,
}

impl TableRow<'_> {
    /// The method's wall time in seconds.
    pub fn seconds(&self) -> f64 {
        self.run.output.stats.wall_seconds
    }

    /// The modeled GPU time of the method's passes, low–high in ms (`stats.json`'s
    /// `gpu_model`; a model, not a measurement: [`crate::gpu_model`]).
    pub fn gpu_model_ms(&self) -> String {
        let g = &self.run.output.stats.gpu_model.seconds;
        format!("{:.3}–{:.3}", g.low * 1e3, g.high * 1e3)
    }

    /// Whether this is the reference's row (its error columns hold its noise floor).
    pub fn is_reference(&self) -> bool {
        self.run.method == methods::REFERENCE
    }
}

/// The rows of the table, one per run in run order.
pub fn table_rows(runs: &[MethodRun]) -> Vec<TableRow<'_>> {
    runs.iter()
        .map(|r| TableRow {
            run: r,
            error: r.error.as_ref().map(|e| &e.all).or(r.noise_floor.as_ref()),
            penumbra_error: r.error.as_ref().map(|e| &e.penumbra_only),
            horizon: r.error.as_ref().map(|e| &e.horizon_split),
            traffic_mb: r.output.stats.totals.total_mb(),
        })
        .collect()
}

/// The sentences under the table, one per line: a missing reference, what the reference's
/// row holds, every method's warnings, and how a sphere light is sampled.
pub fn table_notes(scene: &Scene, runs: &[MethodRun]) -> Vec<String> {
    let mut notes = Vec::new();
    if let Some(r) = runs.first() {
        let gpu = &r.output.stats.gpu_model.gpu;
        notes.push(format!(
            "note: \"GPU model\" is a model, not a measurement: the passes' counted work priced \
             on the {gpu} profile, low–high (docs/gpu-model.md; other GPUs: penumbra list \
             --gpus, --opt gpu.model=NAME)"
        ));
    }
    if !runs.iter().any(|r| r.method == methods::REFERENCE) {
        notes.push(format!(
            "no reference in this run, so no error columns: add {} to the methods",
            methods::REFERENCE
        ));
    }
    if runs.iter().any(|r| r.noise_floor.is_some()) {
        notes.push(format!(
            "{}'s row: its own sampling noise, seed s against seed s + 1 at the penumbra pixels \
             and their neighbours — differences of this size are the reference's, not the \
             method's",
            methods::REFERENCE
        ));
    }
    for line in crate::scene::repair::repair_notes(scene) {
        notes.push(format!("warning: {line}"));
    }
    for r in runs {
        for w in &r.output.stats.warnings {
            notes.push(format!("warning: {}: {w}", r.method));
        }
    }
    for r in runs {
        if let (Some(off), Some(clip)) = (&r.error, &r.horizon_clip) {
            let (a, b) = (&off.horizon_split, &clip.horizon_split);
            notes.push(format!(
                "horizon = clip on the best method here, {}: horizon receivers' mean |e| \
                 {:.5} → {:.5}, whole-light {:.5} → {:.5}, RMSE {:.5} → {:.5} (default off, \
                 the papers' arithmetic; docs/horizon.md)",
                r.method,
                a.horizon.mean_abs,
                b.horizon.mean_abs,
                a.whole_light.mean_abs,
                b.whole_light.mean_abs,
                off.all.rmse,
                clip.all.rmse
            ));
        }
    }
    for m in crate::methods::ALL {
        if runs.iter().any(|r| r.method == m.name) {
            notes.extend((m.table_note)(scene).map(String::from));
        }
    }
    notes
}

/// The scene's title line: its name, size, lights and reference.
pub fn scene_title(scene: &Scene) -> String {
    let shapes: Vec<&str> = scene.lights.iter().map(|l| l.shape.type_name()).collect();
    format!(
        "{} ({}×{}, {} light{}, reference: {})",
        scene.source,
        scene.width,
        scene.height,
        shapes.join(" + "),
        if shapes.len() > 1 { "s" } else { "" },
        methods::REFERENCE
    )
}

/// The table the default run prints: time and error vs the reference per method
/// ([`table_rows`]), the mean |e| over whole-light and horizon receivers, the horizon
/// receivers' share of the image and of the method's error ([`HorizonSplit`]), then the notes
/// ([`table_notes`]).
pub fn table(scene: &Scene, runs: &[MethodRun]) -> String {
    let mut s = format!("scene {}\n", scene_title(scene));
    s += &format!(
        "{:<18} {:>10} {:>15} {:>10} {:>10} {:>10} {:>12} {:>12} {:>12} {:>12} {:>10} {:>10}\n",
        "method",
        "time [s]",
        "GPU model [ms]",
        "RMSE",
        "mean |e|",
        "max |e|",
        "% > 1/255",
        "MB traffic",
        "whole |e|",
        "horizon |e|",
        "% horizon",
        "h. share"
    );
    for row in table_rows(runs) {
        let (m, t, mb) = (&row.run.method, row.seconds(), row.traffic_mb);
        let gpu = row.gpu_model_ms();
        match row.error {
            Some(e) => {
                s += &format!(
                    "{:<18} {:>10.3} {:>15} {:>10.5} {:>10.5} {:>10.5} {:>12.3} {:>12.2}",
                    m, t, gpu, e.rmse, e.mean_abs, e.max_abs, e.pct_over_1_255, mb
                )
            }
            None => {
                s += &format!(
                    "{:<18} {:>10.3} {:>15} {:>10} {:>10} {:>10} {:>12} {:>12.2}",
                    m, t, gpu, "—", "—", "—", "—", mb
                )
            }
        }
        match row.horizon {
            Some(h) => {
                s += &format!(
                    " {:>12.5} {:>12.5} {:>10.2} {:>10.3}\n",
                    h.whole_light.mean_abs, h.horizon.mean_abs, h.horizon_pct, h.horizon_share
                )
            }
            None => s += &format!(" {:>12} {:>12} {:>10} {:>10}\n", "—", "—", "—", "—"),
        }
    }
    for note in table_notes(scene, runs) {
        s += &note;
        s.push('\n');
    }
    s
}
