//! One module per soft-shadow method; each cites its paper section. This module is the
//! registry: method names, which light shapes each supports, and dispatch — including scenes
//! with several lights: the penumbra-wedge methods render them in one LI buffer (Paper I §7),
//! every other method once per light ([`light_average`]).

/// `AddAssign` as the field-wise sum, for the per-tile and per-row tallies of a method's
/// fragment programs (`field_sum!(Stats { a, b })`).
macro_rules! field_sum {
    ($t:ty { $($f:ident),* }) => {
        impl std::ops::AddAssign for $t {
            fn add_assign(&mut self, o: Self) {
                $(self.$f += o.$f;)*
            }
        }
    };
}

pub mod dbuffer;
pub mod dump;
pub mod hard_sv;
pub mod horizon_clip;
pub mod light_average;
pub mod nsample;
pub mod output;
pub mod penumbra_map;
pub mod precision_spec;
pub mod pw2002;
pub mod pw_restructured;
pub mod raycast;
pub mod recorder;
pub mod ssv;
pub mod ssv_optimized;
pub mod wedge_blending;

use crate::error::InputError;
use crate::frame::{Frame, GpuOptions};
use crate::gpu::color::ColorFormat;
use crate::gpu::counters::Counters;
use crate::gpu::depth::DepthFormat;
use crate::gpu::light_view::{LightView, MAX_LIGHT_VIEW_HALF_ANGLE_DEG};
use crate::gpu::probe::{PassProbe, Tap};
use crate::gpu::shader_float::ShaderFloat;
use crate::gpu::texture::Filter;
use crate::gpu::tiling::Tiling;
use crate::options::{option_names, KeyDoc, OptionTable};
use crate::scene::{LightShape, Scene};
use output::MethodOutput;

/// One method as the rest of the crate knows it (`docs/architecture.md` "How to add a
/// method"): each method's module declares one (`METHOD`) and [`ALL`] lists them, so that the
/// CLI, the memory estimate, the option listing, the goldens, the experiments and the report
/// ask the list instead of matching on names.
#[derive(Clone, Copy)]
pub struct Method {
    /// The name scene files, `--methods`, `--opt METHOD.KEY` and the output folders use.
    pub name: &'static str,
    /// The paper it reproduces, in a few words (`docs/papers.md`; Papers I–V are those of
    /// Assarsson's thesis), for captions.
    pub paper: &'static str,
    /// Whether it can render a light of this shape.
    pub supports: fn(&LightShape) -> bool,
    /// How it renders a scene with several lights.
    pub lights: SeveralLights,
    /// Its option table `[options.NAME]`.
    pub options: OptionTableSpec,
    /// Its peak memory per pixel while it runs, in bytes ([`crate::memory`]: measured, then
    /// rounded up by at least 10 %).
    pub bytes_per_pixel: u64,
    /// Its peak memory per triangle of the scene, loading included, in bytes
    /// ([`crate::memory`]: the largest of what bumpy spheres of 0.33 M and 1.3 M triangles
    /// and the scanned `ogre` (124 k) and `nefertiti` (100 k) took beyond the per-pixel
    /// figures, rounded up by at least 25 %).
    pub bytes_per_triangle: u64,
    /// Which of the default run's scenes it renders.
    pub default_run: DefaultRun,
    /// Whether it sums a coverage or light amount per silhouette edge (the wedge and V-buffer
    /// methods), so that a mesh kept as a two-sided shell (`open = "shell"`,
    /// `docs/mesh-repair.md`), whose every silhouette edge has a twin on the other sheet, is
    /// counted twice: [`run`] then warns.
    pub sums_per_silhouette_edge: bool,
    /// A note under the render table when it ran on `scene` (what a reader of its row must
    /// know about the scene), or `None`.
    pub table_note: fn(&Scene) -> Option<&'static str>,
    /// Check its options against a rendered frame without running it (what needs the frame:
    /// a sample count the light's shape cannot take, an option that cannot act with the
    /// others, …): for one light, or for every light with [`SeveralLights::OnePass`].
    pub check: fn(&Frame) -> Result<(), InputError>,
    /// Run it on a rendered frame: of one light, or of every light with
    /// [`SeveralLights::OnePass`].
    pub run: fn(&Frame) -> Result<MethodOutput, InputError>,
    /// Its pinned golden renders ([`crate::golden::cases`]): the foundation scenes it renders
    /// with its defaults (explicit, so that a method that stops supporting one fails instead
    /// of disappearing), then the knobs that change what it computes.
    pub goldens: &'static [Golden],
    /// Its configurations in the accuracy–time sweep
    /// ([`crate::experiment::accuracy_time::configurations`]).
    pub sweep: &'static [OptionPairs],
    /// What the precision experiment measures of it ([`crate::experiment::precision`]).
    pub precision: precision_spec::PrecisionSpec,
}

impl std::fmt::Debug for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name)
    }
}

impl PartialEq for Method {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name
    }
}

/// Options as `(key, value)` pairs, values written as on the command line (`--opt
/// METHOD.KEY=VALUE`).
pub type OptionPairs = &'static [(&'static str, &'static str)];

/// The default golden image side (`docs/architecture.md` "Goldens are rendered small").
pub const GOLDEN_SIZE: u32 = 64;

/// One pinned golden render of a method ([`Method::goldens`], [`crate::golden::cases`]): a
/// scene (a built-in name, or a scene file under the crate root), a small size, and the
/// options that differ from the defaults. Its goldens live in `golden/<scene>/<method>` for
/// the defaults, `golden/<scene>/<method>-<variant>` otherwise.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Golden {
    /// A built-in scene name, or a scene file path relative to the crate root.
    pub scene: &'static str,
    /// Width and height in pixels.
    pub size: u32,
    /// Empty for the method's defaults, else the suffix of its golden directory.
    pub variant: &'static str,
    /// The method's options.
    pub options: OptionPairs,
    /// `[options.gpu]`.
    pub gpu: OptionPairs,
}

impl Golden {
    /// The method's defaults on `scene` at [`GOLDEN_SIZE`].
    pub const fn new(scene: &'static str) -> Self {
        Golden {
            scene,
            size: GOLDEN_SIZE,
            variant: "",
            options: &[],
            gpu: &[],
        }
    }

    /// The method with `options` on `scene`, in the golden directory suffixed `variant`.
    pub const fn variant(scene: &'static str, variant: &'static str, options: OptionPairs) -> Self {
        Golden {
            variant,
            options,
            ..Golden::new(scene)
        }
    }

    /// At `size`×`size`.
    pub const fn sized(self, size: u32) -> Self {
        Golden { size, ..self }
    }

    /// With `[options.gpu]` set to `gpu`.
    pub const fn gpu(self, gpu: OptionPairs) -> Self {
        Golden { gpu, ..self }
    }
}

/// How a method renders a scene with several lights.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeveralLights {
    /// Every light in one pass structure: Paper I §7 scales the LI amounts by 255/n into one
    /// LI buffer (also used by Paper II's restructured algorithm).
    OnePass,
    /// Once per light on the same frame, the visibilities averaged in light order
    /// ([`light_average`]).
    PerLight,
}

/// Which of the default run's scenes (`cargo run --release` with no arguments) a method
/// renders.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DefaultRun {
    /// Every scene whose lights it supports.
    EveryScene,
    /// Only the first, `cube-of-spheres` (`nsample`, the slowest: its companions are
    /// rendered without it).
    FirstSceneOnly,
}

/// What the registry knows of an option table: its name, its keys documented, and its check
/// (the table read from a scene, [`OptionTable::read`]).
#[derive(Clone, Copy)]
pub struct OptionTableSpec {
    /// The table's name: a method, or `gpu`.
    pub name: &'static str,
    /// Its keys, documented ([`OptionTable::keys`]).
    pub keys: fn() -> Vec<KeyDoc>,
    /// Reads the table from a scene and drops it: the first bad key or value is an error.
    pub check: fn(&Scene) -> Result<(), InputError>,
}

impl OptionTableSpec {
    /// The entry of table `O`.
    pub const fn of<O: OptionTable>() -> Self {
        Self {
            name: O::NAME,
            keys: O::keys,
            check: O::check,
        }
    }
}

/// Every method penumbra implements, in the order the default run shows them: the one list
/// (adding a method = its module and one line here).
pub const ALL: &[Method] = &[
    raycast::METHOD,
    nsample::METHOD,
    hard_sv::METHOD,
    pw2002::METHOD,
    pw_restructured::METHOD,
    ssv_optimized::METHOD,
    ssv::METHOD,
    wedge_blending::METHOD,
    penumbra_map::METHOD,
    dbuffer::METHOD,
];

/// The reference every other method's error is measured against.
pub const REFERENCE: &str = raycast::METHOD.name;

/// The names of [`ALL`], in its order.
pub fn names() -> impl Iterator<Item = &'static str> {
    ALL.iter().map(|m| m.name)
}

/// The method called `name`, if there is one.
pub fn find(name: &str) -> Option<&'static Method> {
    ALL.iter().find(|m| m.name == name)
}

/// The paper `method` reproduces, in a few words ([`Method::paper`]), for captions; an empty
/// string for an unknown name.
pub fn paper(method: &str) -> &'static str {
    find(method).map_or("", |m| m.paper)
}

/// Whether `method` can render every light of `scene`.
pub fn supports_scene(method: &str, scene: &Scene) -> bool {
    scene.lights.iter().all(|l| supports(method, &l.shape))
}

/// The first light of `scene` that `method` cannot render, as a message.
fn unsupported_light(method: &str, scene: &Scene) -> Option<String> {
    scene
        .lights
        .iter()
        .find(|l| !supports(method, &l.shape))
        .map(|l| {
            format!(
                "method {method} does not support {} lights",
                l.shape.type_name()
            )
        })
}

/// Whether `method` can render a light of this shape ([`Method::supports`]); false for an
/// unknown name.
pub fn supports(method: &str, shape: &LightShape) -> bool {
    find(method).is_some_and(|m| (m.supports)(shape))
}

/// The methods to run for `scene`: its `methods` list (validated), else every method that
/// supports its light shape.
pub fn selected(scene: &Scene) -> Result<Vec<String>, InputError> {
    match &scene.methods {
        None => Ok(names()
            .filter(|m| supports_scene(m, scene))
            .map(|m| m.to_string())
            .collect()),
        Some(list) => {
            for (k, m) in list.iter().enumerate() {
                check_method(m, scene)?;
                if list[..k].contains(m) {
                    return Err(InputError::at(
                        &scene.source,
                        "methods",
                        format!("method {m:?} is listed twice (each method renders once)"),
                    ));
                }
            }
            Ok(list.clone())
        }
    }
}

/// Check that `method` is a known method that can render every light of `scene`.
pub fn check_method(method: &str, scene: &Scene) -> Result<(), InputError> {
    if find(method).is_none() {
        let known: Vec<&str> = names().collect();
        return Err(InputError::at(
            &scene.source,
            "methods",
            format!("unknown method {method:?}; known: {}", known.join(", ")),
        ));
    }
    match unsupported_light(method, scene) {
        Some(why) => Err(InputError::at(&scene.source, "methods", why)),
        None => Ok(()),
    }
}

/// Every option table: `gpu`, then the methods' in [`ALL`] order.
fn tables() -> impl Iterator<Item = OptionTableSpec> {
    std::iter::once(OptionTableSpec::of::<GpuOptions>()).chain(ALL.iter().map(|m| m.options))
}

/// Every option table's name and keys, documented: `gpu`, then the methods in [`ALL`] order
/// (what `penumbra list --options` prints, [`crate::options::listing`]).
pub fn option_docs() -> Vec<(&'static str, Vec<KeyDoc>)> {
    tables().map(|t| (t.name, (t.keys)())).collect()
}

/// Check every `[options.X]` table of `scene` before anything is rendered: X must be `gpu` or a
/// method, every key and value must read ([`OptionTable::read`]) — also for a method this run
/// does not render —, and a method whose table sets a key must be able to render the scene's
/// lights (else its options could never act). The checks that need the rendered frame follow
/// in [`check_options`].
pub fn check_option_tables(scene: &Scene) -> Result<(), InputError> {
    for (name, written) in &scene.options {
        let first_key = written.keys().next();
        let Some(table) = tables().find(|t| t.name == name) else {
            let known: Vec<&str> = tables().map(|t| t.name).collect();
            let message = format!("unknown method {name:?}; known: {}", known.join(", "));
            return Err(match first_key {
                Some(key) if scene.cli_options.contains_key(&(name.clone(), key.clone())) => {
                    scene.option_error(name, key, message)
                }
                _ => InputError::at(&scene.source, format!("options.{name}"), message),
            });
        };
        (table.check)(scene)?;
        if name == GpuOptions::NAME {
            continue;
        }
        if let (Some(why), Some(key)) = (unsupported_light(name, scene), first_key) {
            return Err(scene.option_error(
                name,
                key,
                format!("{why}, so options for it cannot act on this scene"),
            ));
        }
    }
    Ok(())
}

/// The method called `method`, or an error naming the scene's `methods`.
fn known(method: &str, frame: &Frame) -> Result<&'static Method, InputError> {
    find(method).ok_or_else(|| {
        InputError::at(
            &frame.scene.source,
            "methods",
            format!("unknown method {method:?}"),
        )
    })
}

/// Run one method on a rendered frame: directly for a single light or a method that renders
/// every light in one pass ([`SeveralLights::OnePass`]), else once per light, averaged
/// ([`light_average`]).
pub fn run(method: &str, frame: &Frame) -> Result<MethodOutput, InputError> {
    let m = known(method, frame)?;
    let mut out = if frame.scene.is_multi_light() && m.lights == SeveralLights::PerLight {
        light_average::run(m.name, frame, |_, f| (m.run)(f))?
    } else {
        (m.run)(frame)?
    };
    if m.sums_per_silhouette_edge {
        out.stats.warnings.extend(shell_warnings(frame.scene));
    }
    Ok(out)
}

/// One warning per shadow-casting mesh kept (partly) as a two-sided shell, for a method that
/// sums per silhouette edge ([`Method::sums_per_silhouette_edge`]): its coverage is summed
/// twice there (`docs/mesh-repair.md`, "Measured on a real open model": `ssv` on the hand,
/// mean error 0.054 as a shell against 0.0014 closed).
fn shell_warnings(scene: &Scene) -> Vec<String> {
    scene
        .meshes
        .iter()
        .enumerate()
        .filter(|(_, mesh)| !mesh.receiver_only && mesh.repairs.parts_shelled > 0)
        .map(|(i, mesh)| {
            format!(
                "meshes[{i}] ({}) has {} open part(s) kept as a two-sided shell: every \
                 silhouette edge there has a twin on the other sheet, so this method sums its \
                 coverage twice (the overlap artifact); open = \"close\" caps the holes instead",
                mesh.name, mesh.repairs.parts_shelled
            )
        })
        .collect()
}

/// How a visibility parameter in [0, 1] becomes a visibility: each method accepts the falloffs
/// its paper names (`penumbra-map`: smoothstep or linear; `dbuffer`: smoothstep or √t).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Falloff {
    /// 3x² − 2x³, the Bernstein interpolant of Parker et al. (Wyman & Hansen §3, CGI 2004
    /// eq. 4).
    Smoothstep,
    /// x.
    Linear,
    /// √x (CGI 2004 §6.2, for occluders smaller than the light).
    Sqrt,
}

impl Falloff {
    /// The falloff of `x`, computed by the fragment program in the shader precision `T`
    /// (`[options.gpu] shader`, [`crate::gpu::shader_float`]; plain f64 arithmetic at
    /// `T = f64`): the constants 3 and 2 are exact in every format, each product and the
    /// difference rounded.
    pub fn apply<T: ShaderFloat>(self, x: T) -> T {
        match self {
            Falloff::Smoothstep => {
                let (three, two) = (T::from_f64(3.0), T::from_f64(2.0));
                three * x * x - two * x * x * x
            }
            Falloff::Linear => x,
            Falloff::Sqrt => x.sqrt(),
        }
    }
}

option_names!(Falloff {
    Smoothstep = "smoothstep",
    Linear = "linear",
    Sqrt = "sqrt",
});

option_names!(ColorFormat {
    Unorm8 = "unorm8",
    F16 = "f16",
    F32 = "f32",
});

option_names!(Filter {
    Nearest = "nearest",
    Bilinear = "bilinear",
});

/// The light view of `frame`'s (only) light for `method`: a `map_size`² target of format
/// `depth` fitted around the scene ([`LightView::fit`]). Errors name the option `map-size`
/// ([`Scene::option_error`]) for a size the tiling rejects, and the light, the farthest vertex and its angle when one
/// frustum cannot cover the scene (`who` names the maps in the message, e.g. "penumbra maps").
pub fn fit_light_view(
    frame: &Frame,
    method: &str,
    map_size: u32,
    depth: DepthFormat,
    who: &str,
) -> Result<LightView, InputError> {
    let scene = frame.scene;
    let tiling = Tiling::new(map_size, map_size, frame.tiling.tile)
        .map_err(|e| scene.option_error(method, "map-size", e))?;
    LightView::fit(scene, scene.light().center, tiling, depth, |mi| {
        frame.within_light_influence(mi)
    })
    .map_err(|u| {
        let m = &scene.meshes[u.mesh];
        InputError::at(
            &scene.source,
            scene.light_object(0, "light"),
            format!(
                "one light frustum cannot cover the scene: vertex {} ({}, {}, {}) of meshes[{}] \
                 ({}) is {:.1}° from the light's view axis (limit {MAX_LIGHT_VIEW_HALF_ANGLE_DEG}°); \
                 {who} need every receiver in front of the light center",
                u.vertex, u.position.x, u.position.y, u.position.z, u.mesh, m.name, u.angle_deg
            ),
        )
    })
}

/// A screen pass: the fragment program `program(pixel, receiver, stats, counters, tap)` run
/// on the receiver of every pixel (`None` for background), rows in parallel, each row's
/// tallies summed in row order (integer sums: independent of the thread count). `program` gets
/// a [`Tap`] for the pixel `probe` watches ([`crate::gpu::probe`]) and `None` for every other
/// one (the row is compared once per row). Returns the program's outputs in row-major order,
/// the summed stats and the summed counters.
pub fn shade_receivers<T, S>(
    receivers: &[Option<crate::frame::Receiver>],
    width: usize,
    probe: Option<&PassProbe>,
    program: impl Fn(usize, Option<&crate::frame::Receiver>, &mut S, &mut Counters, Option<Tap>) -> T
        + Sync,
) -> (Vec<T>, S, Counters)
where
    T: Send,
    S: Default + std::ops::AddAssign + Send,
{
    use rayon::prelude::*;
    let rows: Vec<(Vec<T>, S, Counters)> = receivers
        .par_chunks(width)
        .enumerate()
        .map(|(row, pixels)| {
            let mut st = S::default();
            let mut c = Counters::default();
            let watched = probe.filter(|p| p.watches_row(row as u32));
            let out = pixels
                .iter()
                .enumerate()
                .map(|(k, r)| {
                    let tap = watched.and_then(|p| p.tap_at(k as u32, row as u32));
                    crate::gpu::shader_ops::measure(&mut c, |c| {
                        program(row * width + k, r.as_ref(), &mut st, c, tap)
                    })
                })
                .collect();
            (out, st, c)
        })
        .collect();
    let mut out = Vec::with_capacity(receivers.len());
    let mut stats = S::default();
    let mut counters = Counters::default();
    for (o, st, c) in rows {
        out.extend(o);
        stats += st;
        counters += c;
    }
    (out, stats, counters)
}

/// Check `method`'s options against the rendered `frame` without running it
/// ([`Method::check`]), so that a bad option is reported even for a method this run does not
/// render. A method that runs once per light is checked for each light. A method that cannot
/// render the scene's lights is skipped: [`check_option_tables`] refused any key of its table.
pub fn check_options(method: &str, frame: &Frame) -> Result<(), InputError> {
    if unsupported_light(method, frame.scene).is_some() {
        return Ok(());
    }
    let m = known(method, frame)?;
    if frame.scene.is_multi_light() && m.lights == SeveralLights::PerLight {
        for k in 0..frame.scene.lights.len() {
            let scene = frame.scene.with_only_light(k);
            (m.check)(&frame.lit_by(&scene))?;
        }
        return Ok(());
    }
    (m.check)(frame)
}
