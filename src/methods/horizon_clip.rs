//! `horizon = off | clip | integrate`, a key of every soft method's option table (issue 28,
//! item 4): the receiver's own horizon, which none of the papers models. `integrate` exists
//! only in the tables of `nsample` and `ssv` ([`IntegrableHorizonKeys`]), which integrate
//! over the light clipped by the receiver's plane themselves (`docs/horizon.md`,
//! "`integrate`"); [`clip_to_horizon`] then leaves their visibility as it is.
//!
//! A receiver whose tangent plane cuts an area light sees only the part of the light in front
//! of that plane; the papers' methods count only the occluders' silhouette volumes, so on these
//! pixels (the *horizon receivers*, [`crate::light::horizon::plane_cuts_light`]) every soft
//! method errs 10–40× more than elsewhere (`docs/horizon.md`). With `horizon = clip` the
//! method's visibility `v` of each pixel is limited to the fraction `f` of the light in front
//! of the receiver's plane:
//!
//! * `f` is computed by a fragment program at the method's shader precision
//!   ([`crate::light::horizon::shader_fraction_in_front`]) from the depth-buffer receiver
//!   point and the **receiver-normal buffer** the scene pass writes as a second render target
//!   ([`Frame::receiver_normals`], RGBA16F, [`crate::gpu::normal_buffer`]). Only a run with
//!   `clip` counts that buffer: its memory (a plan entry) and the scene pass's writes to it
//!   (8 bytes per fragment passing the depth test, added to the scene pass), and the clip
//!   pass's read of it (8 bytes per receiver).
//! * **How `v` and `f` combine** — `min(v, f)`, chosen over `v·f` by measurement
//!   (`docs/horizon.md`, "Combining"): most horizon receivers lie on the terminator of the
//!   occluder that shades them, where the method's volumes already darken the part of the
//!   light behind the plane, so the product counts that part twice. `min` is also exact in
//!   every format (a comparison): where `f = 1` (every receiver that sees the whole light) the
//!   method's value is kept bit for bit.
//!
//! Adopting it is one key and one call (`docs/horizon.md`, "Adopting it in a method"): the
//! method's option table includes `..horizon: HorizonKeys`, and its `run` passes its final
//! visibility through [`clip_to_horizon`] before `rec.finish`, putting the returned summary
//! under `"horizon"` in its settings.

use super::recorder::PassRecorder;
use super::shade_receivers;
use crate::frame::Frame;
use crate::gpu::counters::{count, Counters};
use crate::gpu::normal_buffer;
use crate::gpu::shader_float::ShaderFloat;
use crate::light::horizon::shader_fraction_in_front;
use crate::methods::output::BufferPlan;
use crate::options::{option_names, option_table, OptionType};
use crate::visibility::Visibility;

option_names! {
    /// What a soft method does about the receiver's own horizon (the `horizon` key; module
    /// doc).
    pub enum Horizon {
        /// The paper's arithmetic: only the occluders' volumes count.
        Off = "off",
        /// The visibility limited to the part of the light in front of the receiver's plane.
        Clip = "clip",
        /// The method's own integral taken over the light clipped by the receiver's plane
        /// (only the methods whose table is [`IntegrableHorizonKeys`]).
        Integrate = "integrate",
    }
}

option_table! {
    /// The `horizon` key, declared once: every soft method's table includes it
    /// (`..horizon: HorizonKeys`), or [`IntegrableHorizonKeys`] for a method that also
    /// integrates over the clipped light.
    pub struct HorizonKeys {
        /// the receiver's own horizon (docs/horizon.md): off, the paper's arithmetic, or clip, the visibility limited to the part of the light in front of the receiver's tangent plane (a fragment program at the shader precision, reading the scene pass's receiver-normal buffer)
        horizon: Horizon [&[Horizon::Off, Horizon::Clip]] = Horizon::Off;
    }
}

option_table! {
    /// The `horizon` key of a method whose own coverage integral can run over the light
    /// clipped by the receiver's plane (`nsample`, `ssv`): [`HorizonKeys`]' values and
    /// `integrate`. Declared per method rather than refused at run time, so that every other
    /// method's table rejects `integrate` when it is read and `docs/options.md` lists it only
    /// where it exists (`docs/horizon.md`, "`integrate`").
    pub struct IntegrableHorizonKeys {
        /// the receiver's own horizon (docs/horizon.md): off, the paper's arithmetic; clip, the visibility limited to the part of the light in front of the receiver's tangent plane; or integrate, the method's own integral over the light clipped by that plane (reading the scene pass's receiver-normal buffer)
        horizon: Horizon = Horizon::Off;
    }
}

impl From<HorizonKeys> for Horizon {
    fn from(keys: HorizonKeys) -> Self {
        keys.horizon
    }
}

impl From<IntegrableHorizonKeys> for Horizon {
    fn from(keys: IntegrableHorizonKeys) -> Self {
        keys.horizon
    }
}

/// The name of the clip pass in the plan.
pub const PASS: &str = "horizon-clip";

/// `visibility`, a method's final per-pixel visibility on the recorder's frame, with the
/// method's `horizon` key applied (module doc): unchanged with `off`, and with `integrate`,
/// where the method has integrated over the clipped light itself; with `clip`, each
/// receiver's channels limited to `min(v, f)`, the pass and the normal buffer recorded on
/// `rec`. Returns the visibility and what the method's settings show under `"horizon"`: the
/// mode and, with `clip`, how many receivers the plane limited.
pub fn clip_to_horizon(
    rec: &mut PassRecorder,
    horizon: impl Into<Horizon>,
    visibility: Visibility,
) -> (Visibility, serde_json::Value) {
    match horizon.into() {
        mode @ (Horizon::Off | Horizon::Integrate) => {
            (visibility, serde_json::json!({ "mode": mode.written() }))
        }
        Horizon::Clip => {
            let (v, limited) = crate::with_shader_float!(
                rec.frame().gpu.shader,
                T => clip_with::<T>(rec, visibility)
            );
            (
                v,
                serde_json::json!({ "mode": Horizon::Clip.written(), "limited_pixels": limited }),
            )
        }
    }
}

/// Record the receiver-normal buffer for a run that reads it (`clip`, and `integrate` in
/// the methods that have it): its plan entry and the scene pass's writes to it, 8 bytes per
/// fragment passing the scene pass's depth test (module doc). The reads are the reading
/// passes' own to count.
pub fn uses_receiver_normals(rec: &mut PassRecorder) {
    let frame = rec.frame();
    rec.uses(BufferPlan {
        name: "receiver normals".into(),
        format: normal_buffer::FORMAT.into(),
        bytes_per_sample: normal_buffer::BYTES_PER_PIXEL,
    });
    let mut writes = Counters::default();
    count!(
        writes.color_write_bytes +=
            frame.pass.counters.depth_passed * u64::from(normal_buffer::BYTES_PER_PIXEL)
    );
    rec.count_in_scene_pass(writes);
}

/// `min(v, f)` of a channel `v` and the fraction `f` (module doc): `v`'s own bits unless `f`
/// is smaller.
fn limit<T: ShaderFloat>(v: f32, f: T) -> f32 {
    if f.to_f64() < f64::from(v) {
        f.to_f64() as f32
    } else {
        v
    }
}

/// [`clip_to_horizon`] with `clip`, the fragment program in `T`: the visibility and the
/// number of receivers it lowered.
fn clip_with<T: ShaderFloat>(rec: &mut PassRecorder, visibility: Visibility) -> (Visibility, u64) {
    let frame: &Frame = rec.frame();
    let lights = &frame.scene.lights;
    let share = T::from_f64(1.0 / lights.len() as f64);
    let normals = frame.receiver_normals();
    uses_receiver_normals(rec);
    rec.pass(PASS, |pass| {
        let probe = pass.probe();
        let (rgb, limited, c) = shade_receivers(
            frame.receivers(),
            frame.scene.width as usize,
            probe.as_ref(),
            |i, r, limited: &mut u64, c, tap| {
                let v = visibility.rgb(i);
                let Some(r) = r else {
                    return v;
                };
                count!(c.fragments_shaded += 1);
                count!(c.color_read_bytes += u64::from(normal_buffer::BYTES_PER_PIXEL));
                // Several lights in one pass (Paper I §7's equal shares, `pw2002` and
                // `pw-restructured`): the mean of their fractions, the part of all the light
                // in front; one light: its fraction, bit for bit.
                let fraction = |l| shader_fraction_in_front::<T>(l, r.point.as_dvec3(), normals[i]);
                let f = match lights.as_slice() {
                    [one] => fraction(one),
                    many => {
                        many.iter().fold(T::zero(), |sum, l| sum + fraction(l)) * share
                    }
                };
                let out = v.map(|x| limit(x, f));
                *limited += u64::from(out != v);
                if let Some(tap) = tap {
                    let e = tap
                        .event()
                        .value("fraction_in_front", f.to_f64())
                        .resolve(&out[..visibility.channels(i).len()], false)
                        .note("min(visibility, fraction of the light in front of the receiver's plane)");
                    tap.push(e);
                }
                out
            },
        );
        pass.count(c);
        let v = match visibility {
            Visibility::Gray(_) => Visibility::Gray(rgb.iter().map(|v| v[0]).collect()),
            Visibility::Rgb(_) => Visibility::Rgb(rgb),
        };
        (v, limited)
    })
}
