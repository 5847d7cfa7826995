//! One module per soft-shadow method; each cites its paper section. This module is the
//! registry: method names, which light shapes each supports, and dispatch.

pub mod hard_sv;
pub mod nsample;
pub mod options;
pub mod output;
pub mod pw2002;
pub mod pw_restructured;
pub mod raycast;
pub mod ssv;
pub mod ssv_optimized;

use crate::error::InputError;
use crate::frame::Frame;
use crate::gpu::counters::Counters;
use crate::plan::MethodPlan;
use crate::scene::{LightShape, Scene};
use output::{MethodOutput, MethodStats, PassStats};
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
];

/// The reference every other method's error is measured against.
pub const REFERENCE: &str = "raycast";

/// Whether `method` can render a light of this shape.
pub fn supports(method: &str, shape: &LightShape) -> bool {
    match method {
        // hard-sv uses the light center; nsample and raycast sample any shape.
        "hard-sv" | "nsample" | "raycast" => {
            let _ = shape;
            true
        }
        // Penumbra wedges are built for spherical lights only (Paper I §4).
        "pw2002" | "pw-restructured" => matches!(shape, LightShape::Sphere { .. }),
        // Paper IV §4.2: the rectangular and the spherical shader.
        "ssv-optimized" => matches!(shape, LightShape::Rect { .. } | LightShape::Sphere { .. }),
        // Paper III §3.2.2, §3.3: rectangular and textured rectangular lights.
        "ssv" => matches!(
            shape,
            LightShape::Rect { .. } | LightShape::TexturedRect { .. }
        ),
        _ => false,
    }
}

/// The methods to run for `scene`: its `methods` list (validated), else every method that
/// supports its light shape.
pub fn selected(scene: &Scene) -> Result<Vec<String>, InputError> {
    match &scene.methods {
        None => Ok(ALL
            .iter()
            .filter(|m| supports(m, &scene.light.shape))
            .map(|m| m.to_string())
            .collect()),
        Some(list) => {
            for m in list {
                if !ALL.contains(&m.as_str()) {
                    return Err(InputError::at(
                        &scene.source,
                        "methods",
                        format!("unknown method {m:?}; known: {}", ALL.join(", ")),
                    ));
                }
                if !supports(m, &scene.light.shape) {
                    return Err(InputError::at(
                        &scene.source,
                        "methods",
                        format!(
                            "method {m} does not support {} lights",
                            scene.light.shape.type_name()
                        ),
                    ));
                }
            }
            Ok(list.clone())
        }
    }
}

/// Check that every `[options.X]` table names a known method (or `gpu`).
pub fn check_option_tables(scene: &Scene) -> Result<(), InputError> {
    for k in scene.options.keys() {
        if k != "gpu" && !ALL.contains(&k.as_str()) {
            return Err(InputError::at(
                &scene.source,
                format!("options.{k}"),
                format!("unknown method {k:?}; known: gpu, {}", ALL.join(", ")),
            ));
        }
    }
    Ok(())
}

/// Run one method on a rendered frame.
pub fn run(method: &str, frame: &Frame) -> Result<MethodOutput, InputError> {
    match method {
        "hard-sv" => hard_sv::run(frame),
        "nsample" => nsample::run(frame),
        "raycast" => run_raycast(frame),
        "ssv-optimized" => ssv_optimized::run(frame),
        "ssv" => ssv::run(frame),
        "pw2002" => pw2002::run(frame),
        "pw-restructured" => pw_restructured::run(frame),
        _ => Err(InputError::at(
            &frame.scene.source,
            "methods",
            format!("unknown method {method:?}"),
        )),
    }
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
    }
}

/// `raycast` (the ground truth by definition): per pixel, the fraction of the light visible
/// from the receiver point, with `samples` jittered stratified samples (default 1024, a perfect
/// square) and `seed`. `receiver = "depth-buffer"` (default) uses the depth-buffer point the
/// rasterized methods see; `"primary-ray"` the exact hit of the ray through the pixel center
/// with the visible triangle's plane.
fn run_raycast(frame: &Frame) -> Result<MethodOutput, InputError> {
    let start = Instant::now();
    let scene = frame.scene;
    let (settings, receiver) = raycast_options(scene)?;
    let pass_start = Instant::now();
    let primary;
    let receivers = if receiver == "primary-ray" {
        primary = frame.primary_ray_receivers();
        &primary[..]
    } else {
        frame.receivers()
    };
    let visibility = raycast::raycast_visibility(scene, receivers, &settings);
    let pass = PassStats {
        name: "raycast".into(),
        wall_seconds: pass_start.elapsed().as_secs_f64(),
        runs: 1,
        counters: Counters::default(),
    };
    let plan = MethodPlan {
        method: "raycast".into(),
        passes: vec![frame.pass.name.clone(), "raycast".into()],
        buffers: vec![],
        settings: serde_json::json!({ "samples": settings.samples, "seed": settings.seed, "pattern": "jittered", "receiver": receiver }),
    };
    let passes = vec![frame.pass.clone(), pass];
    Ok(MethodOutput {
        visibility,
        raw_images: vec![],
        stats: method_stats("raycast", frame, start, &plan, passes),
    })
}

/// Read and check `[options.raycast]`: the settings and the receiver choice.
fn raycast_options(scene: &Scene) -> Result<(raycast::RaycastSettings, &'static str), InputError> {
    let mut r = options::OptionReader::new(scene, "raycast");
    let settings = raycast::RaycastSettings {
        samples: r.uint("samples", raycast::DEFAULT_SAMPLES as u64, 1..=65536)? as u32,
        seed: r.uint("seed", 0, 0..=u64::MAX >> 1)?,
    };
    settings
        .validate()
        .map_err(|e| InputError::at(&scene.source, "options.raycast.samples", e))?;
    let receiver = r.choice("receiver", &["depth-buffer", "primary-ray"], "depth-buffer")?;
    r.finish()?;
    Ok((settings, receiver))
}

/// Parse and check `method`'s options without running it, so that a bad option is reported
/// even for a method this run does not render. Methods that do not support the scene's light
/// shape are not checked (their options cannot be interpreted for this light).
pub fn check_options(method: &str, frame: &Frame) -> Result<(), InputError> {
    if !supports(method, &frame.scene.light.shape) {
        return Ok(());
    }
    match method {
        "hard-sv" => hard_sv::options(frame).map(drop),
        "nsample" => nsample::options(frame).map(drop),
        "raycast" => raycast_options(frame.scene).map(drop),
        "pw2002" => pw2002::options(frame).map(drop),
        "pw-restructured" => pw_restructured::read_settings(frame).map(drop),
        "ssv" => ssv::read_settings(frame).map(drop),
        "ssv-optimized" => ssv_optimized::options(frame).map(drop),
        _ => Err(InputError::at(
            &frame.scene.source,
            "methods",
            format!("unknown method {method:?}"),
        )),
    }
}
