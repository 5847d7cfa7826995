//! `horizon = integrate` (issue 28 item 4, `docs/horizon.md`): `nsample` and `ssv` integrate
//! their visibility over the light clipped by the receiver's tangent plane. On spheres standing
//! on a floor at 64² (`cube-of-spheres`): the horizon error against `raycast` is lower than
//! `clip`'s by a stated factor (the measured values pinned); every pixel whose fraction in
//! front is exactly 1 keeps its bits; every other pixel keeps within the bounds the method's
//! arithmetic implies; the receiver-normal buffer and the extra passes are counted; and the
//! methods and configurations without the integral refuse the value.

use crate::common::{assert_horizon_gains, mean_abs_over, HorizonGain};
use penumbra::frame::{Frame, GpuSettings};
use penumbra::gpu::normal_buffer::BYTES_PER_PIXEL;
use penumbra::light::horizon::{plane_cuts_light, shader_fraction_in_front, SquarePlane};
use penumbra::light::sampling::{stratified, Pattern};
use penumbra::methods::output::MethodOutput;
use penumbra::methods::{self, nsample, ssv};
use penumbra::scene::{builtin, Scene};

/// Light samples of `nsample` here.
const N: u32 = 64;

/// `cube-of-spheres` (27 spheres on a floor under a rectangle) at 64², `nsample` at n = 64.
fn scene() -> Scene {
    let mut s = builtin::load("cube-of-spheres").unwrap();
    s.resize(Some(64), Some(64));
    s.set_cli_option(&format!("nsample.n={N}")).unwrap();
    s
}

/// `method` on `frame` with `horizon = mode`.
fn run(frame: &Frame, method: &str, mode: &str) -> MethodOutput {
    let mut s = frame.scene.clone();
    s.set_cli_option(&format!("{method}.horizon={mode}"))
        .unwrap();
    methods::run(method, &frame.lit_by(&s)).unwrap()
}

/// The plan entries named `name`.
fn buffers(o: &MethodOutput, name: &str) -> usize {
    o.stats.plan["buffers"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|b| b["name"] == name)
        .count()
}

/// The counters of pass `name`.
fn pass(o: &MethodOutput, name: &str) -> penumbra::gpu::counters::Counters {
    o.stats
        .passes
        .iter()
        .find(|p| p.name == name)
        .unwrap_or_else(|| panic!("pass {name}"))
        .counters
}

/// Per method: the factor `integrate` must lower `clip`'s horizon error by (the check), and
/// the measured mean |e| on the horizon receivers with `clip` and `integrate` (pins: 1.21×,
/// 1.30×; at 128² and n = 256 the gains are larger, docs/horizon.md).
const PINS: &[(&str, f64, f64, f64)] = &[
    ("nsample", 1.15, 0.0077, 0.0064),
    ("ssv", 1.25, 0.0532, 0.0410),
];

#[test]
fn integrate_lowers_the_horizon_error_below_clip_and_keeps_whole_light_pixels() {
    let s = scene();
    let frame = Frame::render(&s, GpuSettings::default()).unwrap();
    let light = s.light();
    let receivers = frame.receivers();
    let normals = frame.receiver_normals();
    let horizon: Vec<bool> = receivers
        .iter()
        .map(|r| r.is_some_and(|r| plane_cuts_light(light, r.point, r.normal)))
        .collect();
    assert!(horizon.iter().filter(|h| **h).count() >= 40);
    // The fraction in front as the fragment program computes it (f64, the default shader).
    let fraction: Vec<Option<f64>> = receivers
        .iter()
        .enumerate()
        .map(|(i, r)| r.map(|r| shader_fraction_in_front(light, r.point.as_dvec3(), normals[i])))
        .collect();
    let reference = methods::run("raycast", &frame).unwrap().visibility;
    let mut errors = Vec::new();
    for &(method, factor, pin_clip, pin_integrate) in PINS {
        let (off, clip, integrate) = (
            run(&frame, method, "off"),
            run(&frame, method, "clip"),
            run(&frame, method, "integrate"),
        );
        let (o, v) = (&off.visibility, &integrate.visibility);
        let (mut kept, mut changed) = (0, 0);
        for (i, f) in fraction.iter().enumerate() {
            let (a, b) = (o.gray(i), v.gray(i));
            match f {
                None => assert_eq!(a.to_bits(), b.to_bits(), "{method}: background {i}"),
                Some(f) if *f == 1.0 => {
                    assert_eq!(a.to_bits(), b.to_bits(), "{method}: whole-light pixel {i}");
                    kept += 1;
                }
                Some(f) => {
                    changed += usize::from(a != b);
                    // `ssv`: the visible part of the clipped light is clamped to [0, f].
                    if method == "ssv" {
                        assert!((0.0..=*f as f32).contains(&b), "{i}: {b} not in [0, {f}]");
                    }
                }
            }
        }
        assert!(
            kept > 1000 && changed >= 10,
            "{method}: {kept} kept, {changed} changed"
        );
        let e = |x: &MethodOutput| mean_abs_over(&x.visibility, &reference, &horizon);
        errors.push(HorizonGain {
            method,
            factor,
            before: e(&clip),
            after: e(&integrate),
            pin_before: pin_clip,
            pin_after: pin_integrate,
        });
        assert_eq!(
            integrate.stats.plan["settings"]["horizon"]["mode"],
            "integrate"
        );
        // The normal buffer, written by the scene pass, is counted with integrate only.
        assert_eq!(
            (
                buffers(&off, "receiver normals"),
                buffers(&integrate, "receiver normals")
            ),
            (0, 1)
        );
        let mut written = frame.pass.counters;
        written.color_write_bytes += frame.pass.counters.depth_passed * u64::from(BYTES_PER_PIXEL);
        assert_eq!(integrate.stats.passes[0].counters, written, "{method}");
        assert!(integrate
            .stats
            .passes
            .iter()
            .all(|p| p.name != methods::horizon_clip::PASS));
    }
    assert_horizon_gains(&errors, ("clip", "integrate"));
}

/// `nsample`: where some samples lie behind a pixel's plane, its visibility is `f·lit/front`
/// — the weight `lit` of the samples whose stencil count is 0 and that are in front, over the
/// weight `front` of those in front, times the fraction `f` of the light in front — and
/// elsewhere `off`'s bits. With `off`'s `v` (every lit sample, in front or not) and every
/// weight 1/n under a rectangle, `v − (1 − front) ≤ lit ≤ min(v, front)`, so the value lies
/// between `f·(v − (1 − front))/front` and `f·min(v, front)/front ≤ f`, and a pixel every
/// sample lights gets `f` itself. The accumulation reads the normal buffer at every receiver
/// in every sample pass, besides the accumulators it adds to (each read where it is written).
#[test]
fn nsample_integrate_is_the_lit_share_of_the_samples_in_front_times_the_fraction() {
    let s = scene();
    let frame = Frame::render(&s, GpuSettings::default()).unwrap();
    let samples = stratified(
        s.light(),
        N,
        Pattern::Centered,
        nsample::sphere_disk_target(&frame),
    )
    .unwrap();
    let (off, integrate) = (
        run(&frame, "nsample", "off"),
        run(&frame, "nsample", "integrate"),
    );
    let normals = frame.receiver_normals();
    let slack = 1e-6;
    let mut lowered = 0;
    for (i, r) in frame.receivers().iter().enumerate() {
        let Some(r) = r else { continue };
        let front = samples
            .iter()
            .filter(|x| normals[i].dot(x.position.as_dvec3() - r.point.as_dvec3()) >= 0.0)
            .count() as f64
            / f64::from(N);
        let (a, b) = (
            f64::from(off.visibility.gray(i)),
            f64::from(integrate.visibility.gray(i)),
        );
        if front == 1.0 {
            assert_eq!(a.to_bits(), b.to_bits(), "{i}");
            continue;
        }
        let f: f64 = shader_fraction_in_front(s.light(), r.point.as_dvec3(), normals[i]);
        let (low, high) = if front > 0.0 {
            (f * (a - (1.0 - front)) / front, f * a.min(front) / front)
        } else {
            (0.0, 0.0)
        };
        assert!(
            b >= low - slack && b <= high + slack,
            "{i}: {b} not in [{low}, {high}]"
        );
        if a == 1.0 {
            assert!(
                (b - f).abs() <= slack,
                "{i}: every sample lights it: {b} vs {f}"
            );
        }
        lowered += usize::from(b < a);
    }
    assert!(lowered >= 10, "{lowered}");
    let receivers = frame.receivers().iter().flatten().count() as u64;
    let name = &off.stats.passes[1].name;
    let (i, o) = (pass(&integrate, name), pass(&off, name));
    // The accumulators are read where they are written (24 B each); what integrate reads
    // beyond that is the normal at every receiver in every sample pass.
    assert_eq!(
        i.color_read_bytes - i.color_write_bytes,
        u64::from(N) * receivers * u64::from(BYTES_PER_PIXEL)
    );
    assert_eq!(o.color_read_bytes, o.color_write_bytes);
    assert!(o.color_write_bytes > 0 && o.color_write_bytes % 24 == 0);
}

/// `ssv`: the scale pass shades every receiver once, reading its normal and the V-buffer and
/// writing the V-buffer and the fraction buffer; the wedge pass shades the same fragments as
/// `off`, each reading the normal, and its resolve reads the fraction buffer. With `f16` the
/// same pass runs on the 2-byte V-buffer.
#[test]
fn ssv_integrate_counts_its_scale_pass_and_its_reads() {
    let s = scene();
    let frame = Frame::render(&s, GpuSettings::default()).unwrap();
    let receivers = frame.receivers().iter().flatten().count() as u64;
    let (off, integrate) = (run(&frame, "ssv", "off"), run(&frame, "ssv", "integrate"));
    assert_eq!(buffers(&integrate, "horizon fraction"), 1);
    let scale = pass(&integrate, ssv::HORIZON_SCALE);
    let normal = u64::from(BYTES_PER_PIXEL);
    assert_eq!(
        (
            scale.fragments_shaded,
            scale.color_read_bytes,
            scale.color_write_bytes
        ),
        (receivers, receivers * (normal + 4), receivers * (4 + 4))
    );
    let (w_off, w_int) = (pass(&off, "ssv-wedges"), pass(&integrate, "ssv-wedges"));
    assert_eq!(w_off.fragments_shaded, w_int.fragments_shaded);
    assert_eq!(
        w_int.color_read_bytes - w_off.color_read_bytes,
        w_off.fragments_shaded * normal + receivers * 4
    );
    let mut half = s.clone();
    half.set_cli_option("ssv.vbuffer=f16").unwrap();
    let f16 = run(&frame.lit_by(&half), "ssv", "integrate");
    let scale = pass(&f16, ssv::HORIZON_SCALE);
    assert_eq!(scale.color_write_bytes, receivers * (2 + 4));
    let e = (0..f16.visibility.len())
        .map(|i| (f16.visibility.gray(i) - integrate.visibility.gray(i)).abs())
        .fold(0.0f32, f32::max);
    // f16's 11 significant bits on values up to 1, summed over a few wedges.
    assert!(e < 0.01, "{e}");
}

/// Each fragment program's plane is the clip's: the fraction the scale pass multiplies by is
/// [`shader_fraction_in_front`] bit for bit ([`SquarePlane::fraction`]).
#[test]
fn the_horizon_plane_gives_the_clip_fraction_bit_for_bit() {
    let s = scene();
    let frame = Frame::render(&s, GpuSettings::default()).unwrap();
    let normals = frame.receiver_normals();
    for (i, r) in frame.receivers().iter().enumerate() {
        let Some(r) = r else { continue };
        let p = r.point.as_dvec3();
        let plane = SquarePlane::<f64>::of(s.light(), p, normals[i]).unwrap();
        let f: f64 = shader_fraction_in_front(s.light(), p, normals[i]);
        assert_eq!(plane.fraction().to_bits(), f.to_bits());
        match plane.corners_in_front() {
            4 => assert_eq!(f, 1.0),
            0 => assert_eq!(f, 0.0),
            _ => {}
        }
    }
}

/// `integrate` is refused where there is no integral to clip: methods without it (their
/// table's values are `off` and `clip`), and `ssv` with a sphere light, the coverage texture
/// or the 8-bit V-buffer.
#[test]
fn integrate_is_refused_where_it_does_not_exist() {
    let s = scene();
    for method in ["ssv-optimized", "penumbra-map", "wedge-blending"] {
        let mut t = s.clone();
        let err = t
            .set_cli_option(&format!("{method}.horizon=integrate"))
            .map_err(|e| e.to_string())
            .and_then(|()| {
                let frame = Frame::render(&t, GpuSettings::default()).map_err(|e| e.to_string())?;
                methods::run(method, &frame)
                    .map(drop)
                    .map_err(|e| e.to_string())
            })
            .expect_err(method);
        assert!(
            err.contains("horizon") && err.contains("clip"),
            "{method}: {err}"
        );
    }
    let refused = |scene: Scene, extra: &str, why: &str| {
        let mut t = scene;
        t.set_cli_option("ssv.horizon=integrate").unwrap();
        if !extra.is_empty() {
            t.set_cli_option(extra).unwrap();
        }
        let frame = Frame::render(&t, GpuSettings::default()).unwrap();
        let err = methods::run("ssv", &frame)
            .map(drop)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("horizon") && err.contains(why),
            "{extra}: {err}"
        );
    };
    refused(s.clone(), "ssv.coverage=texture", "coverage");
    refused(s.clone(), "ssv.vbuffer=8bit", "float V-buffer");
    let mut sphere = builtin::load("cube-of-spheres-sphere").unwrap();
    sphere.resize(Some(32), Some(32));
    refused(sphere, "", "sphere");
}
