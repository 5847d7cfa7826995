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
pub mod light_average;
pub mod nsample;
pub mod output;
pub mod penumbra_map;
pub mod pw2002;
pub mod pw_restructured;
pub mod raycast;
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
use crate::options::{option_names, option_table, KeyDoc, OptionTable, OptionType};
use crate::plan::{BufferPlan, MethodPlan};
use crate::scene::{LightShape, Scene};
use output::{MethodOutput, MethodStats, PassStats, Visibility};
use std::time::Instant;

/// Every method penumbra implements, in the order the default run shows them.
pub const ALL: &[&str] = &[
    "raycast",
    "nsample",
    "hard-sv",
    "pw2002",
    "pw-restructured",
    "ssv-optimized",
    "ssv",
    "wedge-blending",
    "penumbra-map",
    "dbuffer",
];

/// The reference every other method's error is measured against.
pub const REFERENCE: &str = "raycast";

/// The paper `method` reproduces, in a few words (`../shared/papers/README.md`; Papers I–V
/// are those of Assarsson's thesis), for captions; an empty string for an unknown name.
pub fn paper(method: &str) -> &'static str {
    match method {
        "raycast" => "reference: shadow rays per pixel",
        "nsample" => "Paper III §5.1: N hard shadows",
        "hard-sv" => "Paper I §3, II §5: hard shadow volumes",
        "pw2002" => "Paper I: penumbra wedges, EGWR 2002",
        "pw-restructured" => "Paper II: restructured penumbra wedges",
        "ssv-optimized" => "Paper IV: optimized soft shadow volumes, GH 2003",
        "ssv" => "Paper III: soft shadow volumes, SIGGRAPH 2003",
        "wedge-blending" => "Forest et al., GH 2006: penumbra-wedges blending",
        "penumbra-map" => "Wyman & Hansen, EGSR 2003: penumbra maps",
        "dbuffer" => "CGI 2004: umbra and penumbra volumes, D-buffer",
        _ => "",
    }
}

/// Methods that render every light of a scene in one pass structure: Paper I §7 scales the
/// LI amounts by 255/n into one LI buffer (also used by Paper II's restructured algorithm).
/// Every other method runs once per light ([`light_average`]).
pub const RENDERS_SEVERAL_LIGHTS: &[&str] = &["pw2002", "pw-restructured"];

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

/// Whether `method` can render a light of this shape.
pub fn supports(method: &str, shape: &LightShape) -> bool {
    match method {
        // hard-sv uses the light center; nsample and raycast sample any shape.
        "hard-sv" | "nsample" | "raycast" => {
            let _ = shape;
            true
        }
        // Penumbra wedges are built for spherical lights only (Paper I §4); penumbra maps
        // use spherical lights (Wyman & Hansen §4).
        "pw2002" | "pw-restructured" | "penumbra-map" => {
            matches!(shape, LightShape::Sphere { .. })
        }
        // Paper IV §4.2: the rectangular and the spherical shader.
        "ssv-optimized" => matches!(shape, LightShape::Rect { .. } | LightShape::Sphere { .. }),
        // Paper III §3.2.2, §3.3: rectangular and textured rectangular lights; §5.3: spheres.
        "ssv" => matches!(
            shape,
            LightShape::Rect { .. } | LightShape::TexturedRect { .. } | LightShape::Sphere { .. }
        ),
        // Forest et al. 2006 §4.2: rectangular lights, in light space [−1, 1]².
        "wedge-blending" => matches!(shape, LightShape::Rect { .. }),
        // CGI 2004 §2: "the light source is approximated by a circular disk".
        "dbuffer" => matches!(shape, LightShape::Disk { .. }),
        _ => false,
    }
}

/// The methods to run for `scene`: its `methods` list (validated), else every method that
/// supports its light shape.
pub fn selected(scene: &Scene) -> Result<Vec<String>, InputError> {
    match &scene.methods {
        None => Ok(ALL
            .iter()
            .filter(|m| supports_scene(m, scene))
            .map(|m| m.to_string())
            .collect()),
        Some(list) => {
            for m in list {
                check_method(m, scene)?;
            }
            Ok(list.clone())
        }
    }
}

/// Check that `method` is a known method that can render every light of `scene`.
pub fn check_method(method: &str, scene: &Scene) -> Result<(), InputError> {
    if !ALL.contains(&method) {
        return Err(InputError::at(
            &scene.source,
            "methods",
            format!("unknown method {method:?}; known: {}", ALL.join(", ")),
        ));
    }
    match unsupported_light(method, scene) {
        Some(why) => Err(InputError::at(&scene.source, "methods", why)),
        None => Ok(()),
    }
}

/// An option table as the registry holds it: its name, its keys documented, and its check
/// (the table read from a scene, [`OptionTable::read`]).
type Table = (
    &'static str,
    fn() -> Vec<KeyDoc>,
    fn(&Scene) -> Result<(), InputError>,
);

/// The registry entry of table `O`.
fn table<O: OptionTable>() -> Table {
    (O::NAME, O::keys, |scene| O::read(scene).map(drop))
}

/// Every option table: `gpu`, then the methods in [`ALL`] order.
fn tables() -> [Table; 11] {
    [
        table::<GpuOptions>(),
        table::<RaycastOptions>(),
        table::<nsample::NsampleOptions>(),
        table::<hard_sv::HardSvOptions>(),
        table::<pw2002::Pw2002Options>(),
        table::<pw_restructured::PwRestructuredOptions>(),
        table::<ssv_optimized::SsvOptimizedOptions>(),
        table::<ssv::SsvOptions>(),
        table::<wedge_blending::WedgeBlendingOptions>(),
        table::<penumbra_map::PenumbraMapOptions>(),
        table::<dbuffer::DBufferOptions>(),
    ]
}

/// Every option table's name and keys, documented: `gpu`, then the methods in [`ALL`] order
/// (what `penumbra list --options` prints, [`crate::options::listing`]).
pub fn option_docs() -> Vec<(&'static str, Vec<KeyDoc>)> {
    tables()
        .iter()
        .map(|(name, keys, _)| (*name, keys()))
        .collect()
}

/// Check every `[options.X]` table of `scene` before anything is rendered: X must be `gpu` or a
/// method, every key and value must read ([`OptionTable::read`]) — also for a method this run
/// does not render —, and a method whose table sets a key must be able to render the scene's
/// lights (else its options could never act). The checks that need the rendered frame follow
/// in [`check_options`].
pub fn check_option_tables(scene: &Scene) -> Result<(), InputError> {
    let tables = tables();
    for (name, written) in &scene.options {
        let first_key = written.keys().next();
        let Some((_, _, read)) = tables.iter().find(|t| t.0 == name) else {
            let known: Vec<&str> = tables.iter().map(|t| t.0).collect();
            let message = format!("unknown method {name:?}; known: {}", known.join(", "));
            return Err(match first_key {
                Some(key) if scene.cli_options.contains_key(&(name.clone(), key.clone())) => {
                    scene.option_error(name, key, message)
                }
                _ => InputError::at(&scene.source, format!("options.{name}"), message),
            });
        };
        read(scene)?;
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

/// Run one method on a rendered frame: directly for a single light or a method in
/// [`RENDERS_SEVERAL_LIGHTS`], else once per light, averaged ([`light_average`]).
pub fn run(method: &str, frame: &Frame) -> Result<MethodOutput, InputError> {
    if frame.scene.is_multi_light() && !RENDERS_SEVERAL_LIGHTS.contains(&method) {
        return light_average::run(method, frame, run_one_light);
    }
    run_one_light(method, frame)
}

/// Run one method on a frame whose scene has one light (or on any frame for a method in
/// [`RENDERS_SEVERAL_LIGHTS`]).
fn run_one_light(method: &str, frame: &Frame) -> Result<MethodOutput, InputError> {
    match method {
        "hard-sv" => hard_sv::run(frame),
        "nsample" => nsample::run(frame),
        "raycast" => run_raycast(frame),
        "ssv-optimized" => ssv_optimized::run(frame),
        "ssv" => ssv::run(frame),
        "pw2002" => pw2002::run(frame),
        "pw-restructured" => pw_restructured::run(frame),
        "wedge-blending" => wedge_blending::run(frame),
        "penumbra-map" => penumbra_map::run(frame),
        "dbuffer" => dbuffer::run(frame),
        _ => Err(InputError::at(
            &frame.scene.source,
            "methods",
            format!("unknown method {method:?}"),
        )),
    }
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
    LightView::fit(scene, scene.light().center, tiling, depth).map_err(|u| {
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

/// A screen pass: the fragment program `program(pixel, receiver, stats, counters)` run on the
/// receiver of every pixel (`None` for background), rows in parallel, each row's tallies summed
/// in row order (integer sums: independent of the thread count). Returns the program's outputs
/// in row-major order, the summed stats and the summed counters.
pub fn shade_receivers<T, S>(
    receivers: &[Option<crate::frame::Receiver>],
    width: usize,
    program: impl Fn(usize, Option<&crate::frame::Receiver>, &mut S, &mut Counters) -> T + Sync,
) -> (Vec<T>, S, Counters)
where
    T: Send,
    S: Default + std::ops::AddAssign + Send,
{
    shade_receivers_probed(receivers, width, None, |i, r, st, c, _| {
        program(i, r, st, c)
    })
}

/// [`shade_receivers`] with a probe ([`crate::gpu::probe`]): `program` gets a [`Tap`] for the
/// pixel `probe` watches and `None` for every other one (the row is compared once per row).
pub fn shade_receivers_probed<T, S>(
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
                    program(row * width + k, r.as_ref(), &mut st, &mut c, tap)
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

/// [`MethodStats`] of a method that started at `start` and ran `passes` after the frame's
/// scene pass: the plan lists the scene pass and them, with `buffers` and `settings`.
pub fn stats_after_scene_pass(
    method: &str,
    frame: &Frame,
    start: Instant,
    passes: &[PassStats],
    buffers: Vec<BufferPlan>,
    settings: serde_json::Value,
) -> MethodStats {
    let mut all = vec![frame.pass.clone()];
    all.extend(passes.iter().cloned());
    let plan = MethodPlan {
        method: method.into(),
        passes: all.iter().map(|p| p.name.clone()).collect(),
        buffers,
        settings,
    };
    method_stats(method, frame, start, &plan, all)
}

/// Assemble [`MethodStats`] for a method that started at `start` (totals summed over passes).
pub fn method_stats(
    method: &str,
    frame: &Frame,
    start: Instant,
    plan: &MethodPlan,
    passes: Vec<PassStats>,
) -> MethodStats {
    let mut totals = Counters::default();
    for p in &passes {
        totals += p.counters;
    }
    MethodStats {
        method: method.into(),
        width: frame.scene.width,
        height: frame.scene.height,
        wall_seconds: start.elapsed().as_secs_f64(),
        plan: serde_json::to_value(plan).unwrap_or(serde_json::Value::Null),
        passes,
        totals,
        warnings: Vec::new(),
        clamped_pixels: 0,
        meshes: frame
            .scene
            .meshes
            .iter()
            .map(crate::scene::repair::MeshReport::of)
            .collect(),
    }
}

/// `raycast` (the ground truth by definition): per pixel, the fraction of the light visible
/// from the receiver point, with `samples` jittered stratified samples (default 1024, a perfect
/// square) and `seed`. A sphere light is the disk facing each receiver (`sphere =
/// facing-receiver`, the papers' definition) or, with `sphere = fixed-disk`, `nsample`'s one
/// disk facing the center of the mesh bounds, so the two references can be compared on one
/// definition. `receiver = "depth-buffer"` (default) uses the depth-buffer point the
/// rasterized methods see; `"primary-ray"` the exact hit of the ray through the pixel center
/// with the visible triangle's plane.
fn run_raycast(frame: &Frame) -> Result<MethodOutput, InputError> {
    let start = Instant::now();
    let scene = frame.scene;
    let (settings, receiver) = raycast_options(scene)?;
    let pass_start = Instant::now();
    let primary;
    let receivers = if receiver == ReceiverPoint::PrimaryRay {
        primary = frame.primary_ray_receivers();
        &primary[..]
    } else {
        frame.receivers()
    };
    let probe = frame.probe_pass("raycast");
    let visibility =
        raycast::raycast_visibility_probed(scene, receivers, &settings, probe.as_ref());
    let pass = PassStats {
        name: "raycast".into(),
        wall_seconds: pass_start.elapsed().as_secs_f64(),
        runs: 1,
        counters: Counters::default(),
    };
    let plan = MethodPlan {
        method: "raycast".into(),
        passes: vec![frame.pass.name.clone(), "raycast".into()],
        // The frame's scene pass writes the depth buffer whatever the receivers are read from.
        buffers: vec![BufferPlan::depth(&frame.gpu)],
        settings: serde_json::json!({
            "samples": settings.samples,
            "seed": settings.seed,
            "pattern": "jittered",
            "receiver": receiver.written(),
            "sphere": match settings.sphere_disk {
                raycast::SphereDisk::FacingReceiver => "the disk facing each receiver".to_string(),
                raycast::SphereDisk::Facing(p) => format!("one disk facing ({}, {}, {})", p.x, p.y, p.z),
            },
        }),
    };
    let passes = vec![frame.pass.clone(), pass];
    let mut stats = method_stats("raycast", frame, start, &plan, passes);
    let snapped = frame.snapped_receivers();
    if snapped > 0 && receiver == ReceiverPoint::DepthBuffer {
        stats.warnings.push(format!(
            "{snapped} pixels: the depth buffer cannot hold the surface there (a near plane too \
             close for the depth format?); their receivers, for every method, are the exact \
             hits of the pixel rays with the visible triangles"
        ));
    }
    Ok(MethodOutput {
        visibility,
        dumps: vec![],
        stats,
    })
}

/// The reference's own sampling noise (issue 15: the "% > 1/255" column is dominated by it for
/// exact methods): `raycast` evaluated again with the next seed (`seed + 1`, every other
/// setting the same) and compared with `reference`, its run with `seed`. Only pixels that can
/// differ are evaluated again — those whose 3×3 neighbourhood holds a reference value strictly
/// between 0 and 1 (a penumbra and its one-pixel border); elsewhere every sample of the run
/// saw the light, or none did, and the second run is taken to agree (so the result is a lower
/// bound, and costs a fraction of the reference's time). Several lights are averaged like the
/// reference ([`light_average`]).
pub fn reference_noise_floor(
    frame: &Frame,
    reference: &Visibility,
) -> Result<crate::metrics::ErrorStats, InputError> {
    let (w, h) = (frame.scene.width as usize, frame.scene.height as usize);
    let fractional = |i: usize| reference.rgb(i).iter().any(|&v| v > 0.0 && v < 1.0);
    let again: Vec<bool> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            (y.saturating_sub(1)..(y + 2).min(h))
                .any(|yy| (x.saturating_sub(1)..(x + 2).min(w)).any(|xx| fractional(yy * w + xx)))
        })
        .collect();
    let second = raycast_where(frame, &again, 1)?;
    let merged = match (reference, &second) {
        (Visibility::Gray(r), Visibility::Gray(s)) => Visibility::Gray(
            (0..r.len())
                .map(|i| if again[i] { s[i] } else { r[i] })
                .collect(),
        ),
        _ => Visibility::Rgb(
            (0..reference.len())
                .map(|i| {
                    if again[i] {
                        second.rgb(i)
                    } else {
                        reference.rgb(i)
                    }
                })
                .collect(),
        ),
    };
    Ok(crate::metrics::compare(&merged, reference))
}

option_names! {
    /// How `raycast` sees a sphere light (`[options.raycast] sphere`).
    pub enum SphereAs {
        /// The disk through the center facing each receiver (the papers' definition).
        FacingReceiver = "facing-receiver",
        /// `nsample`'s one disk, facing the center of the mesh bounds.
        FixedDisk = "fixed-disk",
    }
}

option_names! {
    /// Which point of a pixel `raycast` computes the visibility of (`[options.raycast] receiver`).
    pub enum ReceiverPoint {
        /// The pixel center un-projected at its stored depth, the point the rasterized methods see.
        DepthBuffer = "depth-buffer",
        /// The exact hit of the ray through the pixel center with the visible triangle's plane.
        PrimaryRay = "primary-ray",
    }
}

option_table! {
    /// `[options.raycast]`: the reference's samples and definitions.
    pub struct RaycastOptions["raycast"] {
        /// light samples per pixel, jittered in √n×√n strata (a perfect square)
        samples: u32 [1..=65536] = raycast::DEFAULT_SAMPLES;
        /// seed of the jitter
        seed: u64 [0..=u64::MAX >> 1] = 0;
        /// the pixel's point: the depth buffer's (what the rasterized methods see) or the pixel ray's exact hit
        receiver: ReceiverPoint = ReceiverPoint::DepthBuffer;
        /// a sphere light as the disk facing each receiver (the papers'), or as nsample's one disk facing the center of the mesh bounds
        sphere: SphereAs = SphereAs::FacingReceiver;
    }
}

/// `raycast` with its options but the seed advanced by `seed_offset`, evaluated only at the
/// pixels where `mask` (row-major) is true (1 elsewhere); several lights averaged like the
/// reference ([`light_average`]).
pub fn raycast_where(
    frame: &Frame,
    mask: &[bool],
    seed_offset: u64,
) -> Result<Visibility, InputError> {
    let one_light = |f: &Frame| -> Result<Visibility, InputError> {
        let (mut settings, receiver) = raycast_options(f.scene)?;
        settings.seed = settings.seed.wrapping_add(seed_offset);
        let all = if receiver == ReceiverPoint::PrimaryRay {
            f.primary_ray_receivers()
        } else {
            f.receivers().to_vec()
        };
        let some: Vec<_> = all
            .iter()
            .zip(mask)
            .map(|(r, &a)| r.filter(|_| a))
            .collect();
        Ok(raycast::raycast_visibility(f.scene, &some, &settings))
    };
    if frame.scene.is_multi_light() {
        let mut per_light = Vec::new();
        for k in 0..frame.scene.lights.len() {
            let scene = frame.scene.with_only_light(k);
            per_light.push(one_light(&frame.lit_by(&scene))?);
        }
        Ok(light_average::average(per_light.iter()))
    } else {
        one_light(frame)
    }
}

/// The light samples per pixel of the reference (`[options.raycast]`'s `samples`).
pub fn reference_samples(scene: &Scene) -> Result<u32, InputError> {
    Ok(raycast_options(scene)?.0.samples)
}

/// Read and check `[options.raycast]`: the settings and the receiver choice.
fn raycast_options(scene: &Scene) -> Result<(raycast::RaycastSettings, ReceiverPoint), InputError> {
    let o = RaycastOptions::read(scene)?;
    let settings = raycast::RaycastSettings {
        samples: o.samples,
        seed: o.seed,
        sphere_disk: match o.sphere {
            SphereAs::FixedDisk => raycast::SphereDisk::Facing(nsample::sphere_disk_target(scene)),
            SphereAs::FacingReceiver => raycast::SphereDisk::FacingReceiver,
        },
    };
    settings
        .validate()
        .map_err(|e| scene.option_error(RaycastOptions::NAME, "samples", e))?;
    Ok((settings, o.receiver))
}

/// Check `method`'s options against the rendered `frame` without running it (what needs the
/// frame: a sample count the light's shape cannot take, an option that cannot act with the
/// others, …), so that a bad option is reported even for a method this run does not render.
/// A method that runs once per light is checked for each light. A method that cannot render
/// the scene's lights is skipped: [`check_option_tables`] refused any key of its table.
pub fn check_options(method: &str, frame: &Frame) -> Result<(), InputError> {
    if unsupported_light(method, frame.scene).is_some() {
        return Ok(());
    }
    if frame.scene.is_multi_light() && !RENDERS_SEVERAL_LIGHTS.contains(&method) {
        for k in 0..frame.scene.lights.len() {
            let scene = frame.scene.with_only_light(k);
            check_options_one_light(method, &frame.lit_by(&scene))?;
        }
        return Ok(());
    }
    check_options_one_light(method, frame)
}

/// [`check_options`] for a frame with one light (or a method in [`RENDERS_SEVERAL_LIGHTS`]).
fn check_options_one_light(method: &str, frame: &Frame) -> Result<(), InputError> {
    match method {
        "hard-sv" => hard_sv::HardSvOptions::read(frame.scene).map(drop),
        "nsample" => nsample::options(frame).map(drop),
        "raycast" => raycast_options(frame.scene).map(drop),
        "pw2002" => pw2002::options(frame).map(drop),
        "pw-restructured" => pw_restructured::read_settings(frame).map(drop),
        "ssv" => ssv::read_settings(frame).map(drop),
        "ssv-optimized" => ssv_optimized::options(frame).map(drop),
        "wedge-blending" => wedge_blending::options(frame).map(drop),
        "penumbra-map" => penumbra_map::read_settings(frame).map(drop),
        "dbuffer" => dbuffer::read_settings(frame).map(drop),
        _ => Err(InputError::at(
            &frame.scene.source,
            "methods",
            format!("unknown method {method:?}"),
        )),
    }
}
