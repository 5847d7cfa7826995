//! `horizon = off | clip` measured (`docs/horizon.md`): for each method that has the key, its
//! mean |e| against `raycast` on the *horizon receivers* (whose tangent plane cuts the light,
//! [`plane_cuts_light`]) and on the receivers that see the whole light, with `off`, with
//! `clip` (`min(v, f)`, what the methods do), with the product `v·f` (the candidate
//! `clip` was chosen over, computed here from `off` and the same fragment program's `f`), and
//! with `integrate` where the method has it (`nsample`, `ssv` under a rectangle).
//! The reference's own noise on each class is the mean |e| between two `raycast` seeds.
//!
//! The *lower-only floor* is the mean over the horizon receivers of `max(0, truth − off)`:
//! the part of `off`'s error where it is too dark. A correction that can only lower a value —
//! `clip` and `v·f` — leaves that part as it is, so its horizon error cannot go below the
//! floor, and `off / floor` bounds the factor such a correction can reach (if it is under 3,
//! the 3× is out of reach of `clip` on that scene, whatever the fraction in front).
//! `clip`'s own horizon error is split the same way into its too-dark and its too-bright part
//! (`mean max(0, clip − truth)`: light in front of the plane that something else hides and
//! the method misses).
//! The last two columns name the horizon pixel where `off` is farthest below the truth and the
//! one where `clip` is farthest above it (`x,y`, the method's value → `raycast`'s), the ones to
//! hand to `penumbra probe`.
//!
//! `cargo run --release --example horizon_measure [SIZE] [SCENE…]` (default 256,
//! `cube-of-spheres` and `scenes/real/*.toml`; a scene is a built-in name or a file).

use penumbra::frame::Frame;
use penumbra::gpu::shader_float::ShaderFloat;
use penumbra::light::horizon::{fraction_in_front, plane_cuts_light, shader_fraction_in_front};
use penumbra::methods;
use penumbra::scene::file::load_scene_file;
use penumbra::scene::{builtin, Scene};
use penumbra::visibility::Visibility;
use std::path::Path;

/// The methods with the `horizon` key, their options for this measurement, and whether they
/// have `horizon = integrate`.
const METHODS: &[(&str, &[&str], bool)] = &[
    ("nsample", &["nsample.n=256"], true),
    ("ssv", &[], true),
    ("ssv-optimized", &[], false),
    ("penumbra-map", &[], false),
    ("pw2002", &[], false),
    ("pw-restructured", &[], false),
    ("wedge-blending", &[], false),
    ("dbuffer", &[], false),
];

/// Mean of `term(i)` over the pixels `mask` selects.
fn mean_over(mask: &[bool], term: impl Fn(usize) -> f32) -> f64 {
    let (sum, n) = (0..mask.len())
        .filter(|&i| mask[i])
        .fold((0.0, 0usize), |(s, n), i| (s + f64::from(term(i)), n + 1));
    sum / n.max(1) as f64
}

/// Mean |a − b| over the pixels `mask` selects.
fn mean_abs(a: &Visibility, b: &Visibility, mask: &[bool]) -> f64 {
    mean_over(mask, |i| (a.gray(i) - b.gray(i)).abs())
}

/// Mean of `max(0, b − a)` over the pixels `mask` selects: where `a` is darker than `b`.
fn mean_too_dark(a: &Visibility, b: &Visibility, mask: &[bool]) -> f64 {
    mean_over(mask, |i| (b.gray(i) - a.gray(i)).max(0.0))
}

fn load(name: &str) -> Result<Scene, String> {
    match builtin::load(name) {
        Some(s) => Ok(s),
        None => load_scene_file(Path::new(name)).map_err(|e| e.to_string()),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let size: u32 = args.first().and_then(|a| a.parse().ok()).unwrap_or(256);
    let mut scenes: Vec<String> = args.iter().skip(1).cloned().collect();
    if scenes.is_empty() {
        scenes.push("cube-of-spheres".into());
        let mut real: Vec<String> = std::fs::read_dir("scenes/real")
            .expect("scenes/real")
            .filter_map(|e| e.ok().map(|e| e.path().display().to_string()))
            .filter(|p| p.ends_with(".toml"))
            .collect();
        real.sort();
        scenes.extend(real);
    }
    println!(
        "| scene | light | method | horizon px | whole-light px | off: horizon | clip: horizon | v·f: horizon | integrate: horizon | lower-only floor: horizon | clip too bright: horizon | off / clip | off / floor | off / integrate | off: whole | clip: whole | v·f: whole | integrate: whole | raycast noise: horizon / whole | darkest below truth: x,y off→truth | brightest above truth: x,y clip→truth |"
    );
    println!(
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for name in scenes {
        let mut scene = match load(&name) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("{name}: skipped: {e}");
                continue;
            }
        };
        scene.resize(Some(size), Some(size));
        let gpu = penumbra::render::gpu_settings(&scene).expect("gpu options");
        let frame = Frame::render(&scene, gpu).expect("scene renders");
        let light = scene.light().clone();
        let receivers = frame.receivers();
        let fraction: Vec<Option<f64>> = receivers
            .iter()
            .map(|r| r.map(|r| fraction_in_front(&light, r.point, r.normal)))
            .collect();
        let horizon: Vec<bool> = receivers
            .iter()
            .map(|r| r.is_some_and(|r| plane_cuts_light(&light, r.point, r.normal)))
            .collect();
        let whole: Vec<bool> = fraction.iter().map(|f| *f == Some(1.0)).collect();
        let reference = methods::run("raycast", &frame).expect("raycast").visibility;
        let mut reseeded = scene.clone();
        reseeded.set_cli_option("raycast.seed=1").unwrap();
        let noise = methods::run("raycast", &frame.lit_by(&reseeded))
            .expect("raycast")
            .visibility;
        let normals = frame.receiver_normals();
        for (method, opts, integrates) in METHODS {
            if !methods::supports_scene(method, &scene) {
                continue;
            }
            let with = |extra: Option<&str>| {
                let mut s = scene.clone();
                for o in opts.iter().copied().chain(extra) {
                    s.set_cli_option(o).unwrap();
                }
                s
            };
            let (off_scene, clip_scene) =
                (with(None), with(Some(&format!("{method}.horizon=clip"))));
            let off = methods::run(method, &frame.lit_by(&off_scene))
                .expect("off")
                .visibility;
            let clip = methods::run(method, &frame.lit_by(&clip_scene))
                .expect("clip")
                .visibility;
            // Where the method has no integral over the clipped light (or not for this light:
            // `ssv` under a sphere), a dash.
            let integrate = integrates
                .then(|| {
                    let s = with(Some(&format!("{method}.horizon=integrate")));
                    methods::run(method, &frame.lit_by(&s)).ok()
                })
                .flatten()
                .map(|o| o.visibility);
            let product = Visibility::Gray(
                (0..off.len())
                    .map(|i| match receivers[i] {
                        None => off.gray(i),
                        Some(r) => {
                            let f = shader_fraction_in_front::<f64>(
                                &light,
                                r.point.as_dvec3(),
                                normals[i],
                            );
                            (f64::from(off.gray(i)) * f.to_f64()) as f32
                        }
                    })
                    .collect(),
            );
            let e = |v: &Visibility, m: &[bool]| mean_abs(v, &reference, m);
            let dash = || "–".to_string();
            let (e_off, e_clip) = (e(&off, &horizon), e(&clip, &horizon));
            let floor = mean_too_dark(&off, &reference, &horizon);
            let clip_bright = mean_too_dark(&reference, &clip, &horizon);
            // The horizon pixel where `v` exceeds the truth most (`sign` −1: falls below it).
            let extreme = |v: &Visibility, sign: f32| {
                (0..v.len())
                    .filter(|&i| horizon[i])
                    .max_by(|&i, &j| {
                        let by = |k: usize| sign * (v.gray(k) - reference.gray(k));
                        by(i).total_cmp(&by(j)).then(j.cmp(&i))
                    })
                    .map_or_else(dash, |i| {
                        format!(
                            "{},{} {:.3}→{:.3}",
                            i as u32 % size,
                            i as u32 / size,
                            v.gray(i),
                            reference.gray(i)
                        )
                    })
            };
            let (darkest, brightest) = (extreme(&off, -1.0), extreme(&clip, 1.0));
            let integrated =
                |f: &dyn Fn(&Visibility) -> String| integrate.as_ref().map_or_else(dash, f);
            println!(
                "| {} | {} | {method} | {} | {} | {e_off:.4} | {e_clip:.4} | {:.4} | {} | {floor:.4} | {clip_bright:.4} | {:.1}× | {:.1}× | {} | {:.4} | {:.4} | {:.4} | {} | {:.4} / {:.4} | {darkest} | {brightest} |",
                Path::new(&name).file_stem().unwrap().to_string_lossy(),
                light.shape.type_name(),
                horizon.iter().filter(|h| **h).count(),
                whole.iter().filter(|h| **h).count(),
                e(&product, &horizon),
                integrated(&|v| format!("{:.4}", e(v, &horizon))),
                e_off / e_clip,
                e_off / floor,
                integrated(&|v| format!("{:.1}×", e_off / e(v, &horizon))),
                e(&off, &whole),
                e(&clip, &whole),
                e(&product, &whole),
                integrated(&|v| format!("{:.4}", e(v, &whole))),
                mean_abs(&noise, &reference, &horizon),
                mean_abs(&noise, &reference, &whole),
            );
        }
    }
}
