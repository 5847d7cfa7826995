//! Several lights for methods that render one light at a time: the method runs once per light
//! on the same frame lit by that light alone ([`Scene::with_only_light`],
//! [`Frame::lit_by`]), and the visibilities are averaged — the definition Paper I §7 gives
//! for n lights ("multiply the light intensities by 255/n"), which the penumbra-wedge methods
//! instead compute natively in one LI buffer.
//!
//! Arithmetic: per pixel and channel, the per-light values are summed in f32 in light order
//! and the sum is divided by n once (fixed order: independent of threads). A gray and an RGB
//! result average to RGB (gray replicated). Stats: the scene pass appears once; every pass of
//! light k is named `light<k>/<pass>`; buffer dumps are named `<name>-light<k>`; the plan lists
//! the per-light plans (their buffers are allocated once per light, in turn).

use super::output::MethodOutput;
use crate::error::InputError;
use crate::frame::Frame;
use crate::methods::recorder::PassRecorder;
use crate::scene::Scene;
use crate::visibility::Visibility;

/// Run `method` (through `run_one`, the single-light dispatch) once per light of `frame`'s
/// scene and average the visibilities.
pub fn run(
    method: &'static str,
    frame: &Frame,
    run_one: impl Fn(&str, &Frame) -> Result<MethodOutput, InputError>,
) -> Result<MethodOutput, InputError> {
    let mut rec = PassRecorder::new(frame, method);
    let lights = frame.scene.lights.len();
    let mut outputs = Vec::with_capacity(lights);
    for k in 0..lights {
        let scene: Scene = frame.scene.with_only_light(k);
        let _scope = frame
            .probe
            .as_ref()
            .map(|p| p.enter(|s| s.light = Some(k as u32)));
        outputs.push(run_one(method, &frame.lit_by(&scene))?);
    }
    let visibility = average(outputs.iter().map(|o| &o.visibility));
    frame.probe_record("average-lights", |tap, i| {
        outputs
            .iter()
            .enumerate()
            .fold(tap.event(), |e, (k, o)| {
                e.value(&format!("light {k}"), o.visibility.gray(i) as f64)
            })
            .resolve(&visibility.channels(i), false)
            .note(format!("mean of the {lights} lights' visibilities"))
    });
    let mut plans = Vec::new();
    for (k, out) in outputs.into_iter().enumerate() {
        rec.clamped(out.stats.clamped_pixels);
        for w in &out.stats.warnings {
            rec.warn(format!("light {k}: {w}"));
        }
        for mut p in out.stats.passes {
            if p.name != frame.pass.name {
                p.name = format!("light{k}/{}", p.name);
                rec.record_pass(p);
            }
        }
        for mut d in out.dumps {
            d.name = format!("{}-light{k}", d.name);
            d.about = format!("light {k} alone: {}", d.about);
            rec.output(d);
        }
        plans.push(out.stats.plan);
    }
    Ok(rec.finish(
        visibility,
        serde_json::json!({
            "lights": lights,
            "combine": "mean of per-light visibilities (f32 sum in light order, / n)",
            "per_light": plans,
        }),
    ))
}

/// The mean of the visibilities, per pixel and channel: f32 sum in order, divided by n once.
pub fn average<'a>(all: impl Iterator<Item = &'a Visibility> + Clone) -> Visibility {
    let n = all.clone().count() as f32;
    let rgb = all.clone().any(|v| matches!(v, Visibility::Rgb(_)));
    let len = all.clone().next().map_or(0, Visibility::len);
    if rgb {
        Visibility::Rgb(
            (0..len)
                .map(|i| {
                    let mut sum = [0.0f32; 3];
                    for v in all.clone() {
                        let c = v.rgb(i);
                        for ch in 0..3 {
                            sum[ch] += c[ch];
                        }
                    }
                    sum.map(|s| s / n)
                })
                .collect(),
        )
    } else {
        Visibility::Gray(
            (0..len)
                .map(|i| all.clone().map(|v| v.gray(i)).sum::<f32>() / n)
                .collect(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn average_is_the_ordered_mean() {
        let a = Visibility::Gray(vec![0.0, 1.0, 0.25]);
        let b = Visibility::Gray(vec![1.0, 1.0, 0.5]);
        assert_eq!(
            average([&a, &b].into_iter()),
            Visibility::Gray(vec![0.5, 1.0, 0.375])
        );
        let c = Visibility::Rgb(vec![[1.0, 0.0, 0.5]; 3]);
        assert_eq!(
            average([&a, &c].into_iter()),
            Visibility::Rgb(vec![
                [0.5, 0.0, 0.25],
                [1.0, 0.5, 0.75],
                [0.625, 0.125, 0.375]
            ])
        );
        // One light: unchanged.
        assert_eq!(average([&a].into_iter()), a);
    }
}
