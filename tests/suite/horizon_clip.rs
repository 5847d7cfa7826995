//! `horizon = clip` (issue 28 item 4, `docs/horizon.md`): on spheres standing on a floor at
//! 64² (`cube-of-spheres`), for every method with the key, `clip` lowers the error against
//! `raycast` on the horizon receivers (the spheres' terminators, where their tangent plane cuts
//! the light) by a stated factor per method (the measured values are pinned), keeps every pixel whose fraction in
//! front is exactly 1 bit for bit, changes a pixel only to that fraction, and is counted: the
//! normal buffer's plan entry, the scene pass's writes to it and the clip pass's reads.

use crate::common::{assert_horizon_gains, mean_abs_over, HorizonGain};
use penumbra::frame::{Frame, GpuSettings};
use penumbra::gpu::normal_buffer::BYTES_PER_PIXEL;
use penumbra::light::horizon::{plane_cuts_light, shader_fraction_in_front};
use penumbra::methods::{self, horizon_clip};
use penumbra::scene::{builtin, Scene};

/// `cube-of-spheres` (27 spheres on a floor under a rectangle) at 64², or its sphere-light
/// twin `cube-of-spheres-sphere` (for `penumbra-map`).
fn scene(sphere_light: bool) -> Scene {
    let mut s = builtin::load(if sphere_light {
        "cube-of-spheres-sphere"
    } else {
        "cube-of-spheres"
    })
    .unwrap();
    s.resize(Some(64), Some(64));
    s.set_cli_option("nsample.n=64").unwrap();
    s
}

/// Per method: whether it runs under the sphere light, the factor `clip` must lower the
/// horizon error by (the check), and the measured mean |e| on the horizon receivers, off and
/// clip (pins: 1.37×, 1.88×, 1.78×, 1.24×).
const PINS: &[(&str, bool, f64, f64, f64)] = &[
    ("nsample", false, 1.3, 0.0106, 0.0077),
    ("ssv", false, 1.5, 0.1001, 0.0532),
    ("ssv-optimized", false, 1.5, 0.0946, 0.0533),
    ("penumbra-map", true, 1.2, 0.2448, 0.1975),
];

#[test]
fn clip_lowers_the_horizon_error_and_keeps_whole_light_pixels() {
    let mut errors = Vec::new();
    for &(method, sphere_light, factor, pin_off, pin_clip) in PINS {
        let s = scene(sphere_light);
        let frame = Frame::render(&s, GpuSettings::default()).unwrap();
        let light = s.light();
        let receivers = frame.receivers();
        let horizon: Vec<bool> = receivers
            .iter()
            .map(|r| r.is_some_and(|r| plane_cuts_light(light, r.point, r.normal)))
            .collect();
        let count = horizon.iter().filter(|h| **h).count();
        assert!(count >= 40, "{method}: {count} horizon receivers");
        let reference = methods::run("raycast", &frame).unwrap().visibility;
        let off = methods::run(method, &frame).unwrap();
        let mut clipped = s.clone();
        clipped
            .set_cli_option(&format!("{method}.horizon=clip"))
            .unwrap();
        let clip = methods::run(method, &frame.lit_by(&clipped)).unwrap();
        let (e_off, e_clip) = (
            mean_abs_over(&off.visibility, &reference, &horizon),
            mean_abs_over(&clip.visibility, &reference, &horizon),
        );
        errors.push(HorizonGain {
            method,
            factor,
            before: e_off,
            after: e_clip,
            pin_before: pin_off,
            pin_after: pin_clip,
        });
        // Pixel by pixel: a fraction of exactly 1 keeps the bits, any change is to the
        // fraction, and only downward.
        let normals = frame.receiver_normals();
        let (mut kept, mut lowered) = (0, 0);
        for (i, r) in receivers.iter().enumerate() {
            let (a, b) = (off.visibility.gray(i), clip.visibility.gray(i));
            let Some(r) = r else {
                assert_eq!(a.to_bits(), b.to_bits());
                continue;
            };
            let f: f64 = shader_fraction_in_front(light, r.point.as_dvec3(), normals[i]);
            if f == 1.0 {
                assert_eq!(a.to_bits(), b.to_bits(), "{method}: pixel {i}");
                kept += 1;
            } else if a.to_bits() != b.to_bits() {
                assert_eq!((b, f64::from(b) < f64::from(a)), (f as f32, true));
                lowered += 1;
            }
        }
        assert!(
            kept > 1000 && lowered > 0,
            "{method}: {kept} kept, {lowered} lowered"
        );
        let settings = &clip.stats.plan["settings"]["horizon"];
        assert_eq!(settings["mode"], "clip");
        assert_eq!(settings["limited_pixels"], lowered);
        assert_eq!(off.stats.plan["settings"]["horizon"]["mode"], "off");
        // Counted only with clip: the buffer, the scene pass's writes, the clip pass's reads.
        let buffers = |o: &methods::output::MethodOutput| {
            o.stats.plan["buffers"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|b| b["name"] == "receiver normals")
                .count()
        };
        assert_eq!((buffers(&off), buffers(&clip)), (0, 1), "{method}");
        assert_eq!(off.stats.passes[0].counters, frame.pass.counters);
        let mut written = frame.pass.counters;
        written.color_write_bytes += frame.pass.counters.depth_passed * u64::from(BYTES_PER_PIXEL);
        assert_eq!(clip.stats.passes[0].counters, written, "{method}");
        let pass = clip
            .stats
            .passes
            .iter()
            .find(|p| p.name == horizon_clip::PASS)
            .expect("the clip pass");
        let receivers_drawn = receivers.iter().flatten().count() as u64;
        assert_eq!(
            (
                pass.counters.fragments_shaded,
                pass.counters.color_read_bytes
            ),
            (
                receivers_drawn,
                receivers_drawn * u64::from(BYTES_PER_PIXEL)
            )
        );
        assert!(off
            .stats
            .passes
            .iter()
            .all(|p| p.name != horizon_clip::PASS));
    }
    // The horizon error lower by each method's factor (the 3× is reached on real
    // models by ssv and ssv-optimized, not on this scene at 64²; docs/horizon.md), and the
    // measured values pinned.
    assert_horizon_gains(&errors, ("off", "clip"));
}
