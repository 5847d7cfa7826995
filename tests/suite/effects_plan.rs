//! Only the effects a scene calls for, proved by counters (issue 13, item 7;
//! `docs/architecture.md` "Only the effects a scene calls for" and "Counters"): every test
//! reads what the methods report — the per-pass `Counters` and the `MethodPlan` (pass names,
//! `BufferPlan`s, resolved settings) of `stats.json` — not option flags.
//!
//! Buffer kinds, derived from the `Counters` fields and the `BufferPlan` formats:
//!
//! | counter fields | buffer kind | `BufferPlan` that holds it |
//! |---|---|---|
//! | `depth_read_bytes`, `depth_write_bytes` | depth | format `D16`, `D24` or `D32F` (the scene depth, a shadow map, a light-view map's depth) |
//! | `stencil_read_bytes`, `stencil_write_bytes` | stencil | format starting with `S8` |
//! | `color_read_bytes`, `color_write_bytes` | colour / LI / V-buffer | any other format (`Li16`, `F32`, `Unorm8`, `2×RGBA8 …`, `f64x3`, …) |

use penumbra::frame::Frame;
use penumbra::gpu::counters::Counters;
use penumbra::methods::recorder::PassRecorder;
use penumbra::methods::{self, output::MethodOutput, pw2002, pw_restructured};
use penumbra::scene::procedural::box_mesh;
use penumbra::scene::{builtin, LightShape, Scene};
use serde_json::Value;

/// Image side of every render here: small, so that the file runs in seconds.
const SIZE: u32 = 32;

/// A built-in scene at [`SIZE`]².
fn small(name: &str) -> Scene {
    let mut s = builtin::load(name).expect("built-in scene");
    s.width = SIZE;
    s.height = SIZE;
    s
}

/// Every method `scene` supports, run on one frame.
fn run_all(scene: &Scene) -> Vec<(&'static str, MethodOutput)> {
    penumbra::scene::validate::validate(scene).unwrap_or_else(|e| panic!("{e}"));
    let frame = Frame::render(scene, penumbra::render::gpu_settings(scene).unwrap()).unwrap();
    methods::names()
        .filter(|m| methods::supports_scene(m, scene))
        .map(|m| {
            let out = methods::run(m, &frame).unwrap_or_else(|e| panic!("{m}: {e}"));
            (m, out)
        })
        .collect()
}

/// `method` alone on `scene`, which must be valid.
fn run_one(scene: &Scene, method: &str) -> MethodOutput {
    penumbra::scene::validate::validate(scene).unwrap_or_else(|e| panic!("{e}"));
    run_unvalidated(scene, method)
}

/// `method` alone on `scene`, not validated: for the bounds-only twin of a valid scene
/// ([`with_box`]), whose triangle-less mesh validation refuses.
fn run_unvalidated(scene: &Scene, method: &str) -> MethodOutput {
    let frame = Frame::render(scene, penumbra::render::gpu_settings(scene).unwrap()).unwrap();
    methods::run(method, &frame).unwrap_or_else(|e| panic!("{method}: {e}"))
}

/// The kind of buffer a `BufferPlan` format holds (module doc table).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Depth,
    Stencil,
    Color,
}

fn kind_of_format(format: &str) -> Kind {
    if matches!(format, "D16" | "D24" | "D32F") {
        Kind::Depth
    } else if format.starts_with("S8") {
        Kind::Stencil
    } else {
        Kind::Color
    }
}

/// The kinds of buffer whose bytes `c` counts (module doc table).
fn kinds_touched(c: &Counters) -> Vec<Kind> {
    let mut k = Vec::new();
    if c.depth_read_bytes + c.depth_write_bytes > 0 {
        k.push(Kind::Depth);
    }
    if c.stencil_read_bytes + c.stencil_write_bytes > 0 {
        k.push(Kind::Stencil);
    }
    if c.color_read_bytes + c.color_write_bytes > 0 {
        k.push(Kind::Color);
    }
    k
}

/// The plan's buffers as (name, format, bytes per sample).
fn buffers(out: &MethodOutput) -> Vec<(String, String, u64)> {
    out.stats.plan["buffers"]
        .as_array()
        .expect("plan.buffers")
        .iter()
        .map(|b| {
            (
                b["name"].as_str().unwrap().to_string(),
                b["format"].as_str().unwrap().to_string(),
                b["bytes_per_sample"].as_u64().unwrap(),
            )
        })
        .collect()
}

/// The plan's pass names.
fn plan_passes(out: &MethodOutput) -> Vec<String> {
    out.stats.plan["passes"]
        .as_array()
        .expect("plan.passes")
        .iter()
        .map(|p| p.as_str().unwrap().to_string())
        .collect()
}

/// Every pass name the method reports, from the plan and from the counted passes.
fn all_pass_names(out: &MethodOutput) -> Vec<String> {
    let mut names = plan_passes(out);
    names.extend(out.stats.passes.iter().map(|p| p.name.clone()));
    names
}

/// The z-fail decision as the plan reports it after option parsing and `mode = auto`:
/// `settings.resolved.test` ("ZPass"/"ZFail") or `settings.resolved.zfail` (ssv-optimized);
/// `None` for a method that does not count shadow-volume boundaries.
fn resolved_zfail(out: &MethodOutput) -> Option<bool> {
    let r = &out.stats.plan["settings"]["resolved"];
    match (&r["test"], &r["zfail"]) {
        (Value::String(t), _) => Some(match t.as_str() {
            "ZPass" => false,
            "ZFail" => true,
            other => panic!("{}: unknown test {other}", out.stats.method),
        }),
        (_, Value::Bool(z)) => Some(*z),
        _ => None,
    }
}

/// Methods whose `mode` option chooses z-pass or z-fail.
const COUNTING_METHODS: &[&str] = &[
    "nsample",
    "hard-sv",
    "pw-restructured",
    "ssv-optimized",
    "ssv",
    "wedge-blending",
];

/// Counters summed over every pass but the shared scene-depth pass.
fn shadow_passes(out: &MethodOutput) -> Counters {
    let mut c = Counters::default();
    for p in out.stats.passes.iter().skip(1) {
        c += p.counters;
    }
    c
}

/// A name or format that says the buffer is part of a soft-shadow method: a wedge, V-buffer or
/// light-intensity buffer.
fn is_soft_shadow_buffer(name: &str, format: &str) -> bool {
    let n = name.to_lowercase();
    n.contains("wedge")
        || n.contains("vbuffer")
        || n.contains("v-buffer")
        || n == "li"
        || n.contains("penumbra")
        || format.starts_with("Li")
}

/// A point light (`overlap-stress` cut down to 4 quads): the methods that take it (raycast,
/// nsample, hard-sv) allocate no wedge, V-buffer or LI buffer, run no wedge or penumbra pass,
/// and their passes move no colour/LI/V-buffer byte — only depth and stencil traffic, and
/// `nsample`'s accumulator: its one sample adds to it (a read and a write of 24 B) at every
/// receiver it lights, the receivers whose visibility is 1.
#[test]
fn a_point_light_allocates_no_soft_shadow_buffer_and_moves_no_colour_byte() {
    let mut s = builtin::overlap_stack(4, LightShape::Point);
    s.width = SIZE;
    s.height = SIZE;
    let runs = run_all(&s);
    let frame = Frame::render(&s, penumbra::render::gpu_settings(&s).unwrap()).unwrap();
    let lit_receivers = |v: &penumbra::visibility::Visibility| {
        (0..frame.pixel_count())
            .filter(|&i| frame.prim_ids()[i] != penumbra::frame::BACKGROUND && v.gray(i) == 1.0)
            .count() as u64
    };
    let names: Vec<&str> = runs.iter().map(|(m, _)| *m).collect();
    assert_eq!(names, ["raycast", "nsample", "hard-sv"]);
    for (m, out) in &runs {
        for (name, format, _) in buffers(out) {
            assert!(
                !is_soft_shadow_buffer(&name, &format),
                "{m}: point light, plan lists {name} ({format})"
            );
        }
        for p in all_pass_names(out) {
            let p = p.to_lowercase();
            assert!(
                !p.contains("wedge") && !p.contains("penumbra"),
                "{m}: point light runs pass {p}"
            );
        }
        let accumulator = if *m == "nsample" {
            24 * lit_receivers(&out.visibility)
        } else {
            0
        };
        let mut colour = (0, 0);
        for p in &out.stats.passes {
            colour.0 += p.counters.color_read_bytes;
            colour.1 += p.counters.color_write_bytes;
        }
        assert_eq!(
            colour,
            (accumulator, accumulator),
            "{m}: colour/LI/V-buffer bytes under a point light"
        );
    }
    let nsample = &runs.iter().find(|(m, _)| *m == "nsample").unwrap().1;
    assert!(lit_receivers(&nsample.visibility) > 0);
    // The shadow is there: hard-sv's volume pass wrote the stencil.
    let hard = &runs.iter().find(|(m, _)| *m == "hard-sv").unwrap().1;
    assert!(shadow_passes(hard).stencil_write_bytes > 0);
}

/// A point light has one sample point, so N hard shadows of it are N copies of one: `nsample`
/// runs its stencil pass once (the plan's `n` is 1) and submits exactly the volume triangles
/// `hard-sv` does.
#[test]
fn nsample_renders_a_point_light_once() {
    let mut s = builtin::overlap_stack(4, LightShape::Point);
    s.width = SIZE;
    s.height = SIZE;
    let out = run_one(&s, "nsample");
    assert_eq!(out.stats.plan["settings"]["n"], 1);
    let runs: Vec<u64> = out.stats.passes.iter().skip(1).map(|p| p.runs).collect();
    assert_eq!(runs, [1]);
    let hard = run_one(&s, "hard-sv");
    assert_eq!(
        shadow_passes(&out).triangles_submitted,
        shadow_passes(&hard).triangles_submitted
    );
}

/// A lit eye (`cube-of-spheres`, `cube-of-spheres-sphere`): every counting method resolves
/// `mode = auto` to z-pass and names no z-fail pass; forcing `mode = zfail` adds the caps,
/// so the same method then submits strictly more triangles in its shadow passes (the caps
/// are the only difference: z-pass draws none).
#[test]
fn a_lit_eye_counts_zpass_and_submits_no_caps() {
    for scene in ["cube-of-spheres", "cube-of-spheres-sphere"] {
        let s = small(scene);
        for (m, out) in run_all(&s) {
            for p in all_pass_names(&out) {
                assert!(!p.contains("zfail"), "{scene} {m}: pass {p}");
            }
            if !COUNTING_METHODS.contains(&m) {
                continue;
            }
            assert_eq!(resolved_zfail(&out), Some(false), "{scene} {m}");
            let mut forced = s.clone();
            forced.set_cli_option(&format!("{m}.mode=zfail")).unwrap();
            let zfail = run_one(&forced, m);
            assert_eq!(resolved_zfail(&zfail), Some(true), "{scene} {m} forced");
            let (zp, zf) = (
                shadow_passes(&out).triangles_submitted,
                shadow_passes(&zfail).triangles_submitted,
            );
            eprintln!("{scene} {m}: triangles submitted z-pass {zp}, z-fail {zf}");
            assert!(zf > zp, "{scene} {m}: z-fail {zf} ≤ z-pass {zp}: no caps?");
        }
    }
}

/// The eye in shadow (`eye-in-shadow`): every counting method resolves `mode = auto` to
/// z-fail.
#[test]
fn the_eye_in_shadow_counts_zfail() {
    let s = small("eye-in-shadow");
    let mut counted = 0;
    for (m, out) in run_all(&s) {
        if let Some(z) = resolved_zfail(&out) {
            assert!(z, "eye-in-shadow {m}: z-pass chosen");
            counted += 1;
        }
    }
    // hard-sv, nsample, ssv-optimized, ssv, wedge-blending (rect light).
    assert_eq!(counted, 5);
}

/// The V-buffer of `ssv` (Paper III §3.3): one f32 channel (4 bytes) under an untextured
/// rectangle, RGB (3 × f32 = 12 bytes) under a textured one (`scenes/fire.toml`), and the
/// passes' colour bytes scale with it.
#[test]
fn an_untextured_light_gets_a_one_channel_vbuffer() {
    let vbuffer = |out: &MethodOutput| -> (String, u64) {
        let b = buffers(out);
        let v: Vec<_> = b.iter().filter(|(n, _, _)| n.contains("vbuffer")).collect();
        assert_eq!(v.len(), 1, "one V-buffer: {b:?}");
        (v[0].1.clone(), v[0].2)
    };
    let plain = run_one(&small("single-quad"), "ssv");
    assert_eq!(vbuffer(&plain).1, 4, "{:?}", vbuffer(&plain));
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/fire.toml");
    let mut fire = penumbra::scene::file::resolve(path).unwrap();
    assert!(matches!(
        fire.lights[0].shape,
        LightShape::TexturedRect { .. }
    ));
    fire.width = SIZE;
    fire.height = SIZE;
    let textured = run_one(&fire, "ssv");
    assert_eq!(vbuffer(&textured).1, 12, "{:?}", vbuffer(&textured));
    // Every colour byte a pass of the textured run moves is a whole RGB sample.
    for p in textured.stats.passes.iter().skip(1) {
        assert_eq!(p.counters.color_write_bytes % 12, 0, "{}", p.name);
        assert_eq!(p.counters.color_read_bytes % 12, 0, "{}", p.name);
    }
    for p in plain.stats.passes.iter().skip(1) {
        assert!(
            p.counters.color_write_bytes > 0,
            "{}: the V-buffer is written",
            p.name
        );
    }
}

/// `pw-restructured` (Paper II §4): with `culling = off` no tile is culled and no tile
/// zmin/zmax is read (the counters' `hiz_read_bytes`, in units of the depth format), and the
/// plan lists no zmin/zmax buffer; with the default `zmin-zmax` tiles are culled on
/// `cube-of-spheres-sphere`, each culled tile after a zmin/zmax read, with fewer fragments and
/// the same image.
#[test]
fn pw_restructured_culls_tiles_only_with_culling_on() {
    let on = small("cube-of-spheres-sphere");
    let mut off = on.clone();
    off.set_cli_option("pw-restructured.culling=off").unwrap();
    let tile_reads = |scene: &Scene| -> u64 {
        let frame = Frame::render(scene, penumbra::render::gpu_settings(scene).unwrap()).unwrap();
        let (s, _) = pw_restructured::read_settings(&frame).unwrap();
        let set = pw2002::frame_wedges(&frame, &s.wedge).unwrap();
        let mut rec = PassRecorder::new(&frame, "pw-restructured");
        pw_restructured::render_li(&mut rec, &set, &s);
        let out = rec.finish(
            penumbra::visibility::Visibility::Gray(vec![]),
            Default::default(),
        );
        let bytes: u64 = out.stats.passes[1..]
            .iter()
            .map(|p| p.counters.hiz_read_bytes)
            .sum();
        bytes / frame.gpu.depth.bytes()
    };
    let (reads_on, reads_off) = (tile_reads(&on), tile_reads(&off));
    let on = run_one(&on, "pw-restructured");
    let off = run_one(&off, "pw-restructured");
    assert_eq!(on.stats.plan["settings"]["resolved"]["culling"], "ZminZmax");
    assert_eq!(off.stats.plan["settings"]["resolved"]["culling"], "Off");
    let (c_on, c_off) = (shadow_passes(&on), shadow_passes(&off));
    eprintln!(
        "tiles culled: on {}, off {}; tile zmin/zmax reads: on {reads_on}, off {reads_off}",
        c_on.tiles_culled_hiz, c_off.tiles_culled_hiz
    );
    assert_eq!((c_off.tiles_culled_hiz, reads_off), (0, 0));
    assert!(c_on.tiles_culled_hiz > 0);
    assert!(reads_on >= c_on.tiles_culled_hiz);
    // Culling skips fragments whose depth test would fail: fewer fragments, same LI.
    assert!(c_on.fragments_rasterized < c_off.fragments_rasterized);
    assert_eq!(on.visibility, off.visibility);
    for (name, _, _) in buffers(&off) {
        let n = name.to_lowercase();
        assert!(
            !n.contains("zmin") && !n.contains("zmax"),
            "culling off lists {name}"
        );
    }
}

/// With culling on, `pw-restructured` reads a per-tile zmin/zmax (Paper II §4): its plan
/// lists it (a finding of this test, fixed: the plan had listed only depth and LI).
#[test]
fn pw_restructured_lists_its_tile_zmin_zmax_buffer_when_culling() {
    // Measured before the fix (cube-of-spheres-sphere, 32²): tiles_culled_hiz = 4407 in pass
    // `wedges-single-pass` after 8143 tile zmin/zmax reads; plan buffers = [depth (D24),
    // li (Li16)]. The number of reads is computed by `pw_restructured::render_li` and still
    // dropped by `run` (a counter for it would change every golden's counters).
    let out = run_one(&small("cube-of-spheres-sphere"), "pw-restructured");
    assert!(shadow_passes(&out).tiles_culled_hiz > 0);
    let b = buffers(&out);
    assert!(
        b.iter()
            .any(|(n, _, _)| n.to_lowercase().contains("zmin") || n.to_lowercase().contains("zmax")),
        "{b:?}"
    );
}

/// `scene` with a closed box added, `lo`, `hi` its corners; with `triangles = false` only its
/// vertices (no triangle): the scene then has the same bounds — which set the default near
/// plane, `nsample`'s sphere-disk orientation and the wedge clip box — without the box's
/// geometry.
fn with_box(mut s: Scene, lo: [f32; 3], hi: [f32; 3], triangles: bool) -> Scene {
    let mut b = box_mesh(
        "outside",
        glam::Vec3::from_array(lo),
        glam::Vec3::from_array(hi),
        [0.5, 0.5, 0.5],
    );
    if !triangles {
        b.triangles.clear();
    }
    s.meshes.push(b);
    s
}

/// What a method reports about its wedges or silhouettes, from its plan settings (the keys
/// the methods write), as (key, value) pairs.
fn wedge_counts(out: &MethodOutput) -> Vec<(&'static str, Value)> {
    let s = &out.stats.plan["settings"];
    [
        ("wedges", &s["wedges"]),
        ("half_wedges", &s["counters"]["half_wedges"]),
        ("silhouettes", &s["counters"]["silhouettes"]),
    ]
    .into_iter()
    .filter(|(_, v)| !v.is_null())
    .map(|(k, v)| (k, v.clone()))
    .collect()
}

/// Per shadow pass: (name, triangles submitted, fragments rasterized).
fn pass_work(out: &MethodOutput) -> Vec<(String, u64, u64)> {
    out.stats
        .passes
        .iter()
        .skip(1)
        .map(|p| {
            (
                p.name.clone(),
                p.counters.triangles_submitted,
                p.counters.fragments_rasterized,
            )
        })
        .collect()
}

/// A case of the "outside the light's influence" tests.
struct OutsideCase {
    /// The scene with the box's vertices only (same bounds, no box geometry).
    bounds_only: Scene,
    /// The scene with the box.
    with_box: Scene,
    /// The methods compared: every method the scene supports but `raycast` (no volumes) and
    /// `penumbra-map` (see [`outside_cases`]).
    methods: Vec<&'static str>,
}

/// `single-quad` (rect light at y = 3 facing down) with a box above the light (y 3.4–3.7:
/// behind it, no point of the light sees it), and `cube-of-spheres-sphere` (sphere light
/// r 0.5 at y = 4) with a box at y 4.6–4.9 beside it: every ray from the light through the
/// box climbs, so its volume and wedges stay above y = 4.6, above every receiver and outside
/// the view (the camera at y = 3 looks down; every ray of its frustum descends).
/// `penumbra-map` is left out: with the box its light frustum cannot cover the scene (the box
/// is behind the light center) and it refuses the scene with an error.
fn outside_cases() -> Vec<OutsideCase> {
    let quad = small("single-quad");
    let (ql, qh) = ([-0.3, 3.4, -0.3], [0.3, 3.7, 0.3]);
    let sph = small("cube-of-spheres-sphere");
    let (sl, sh) = ([1.5, 4.6, -1.8], [1.8, 4.9, -1.5]);
    [(quad, ql, qh), (sph, sl, sh)]
        .into_iter()
        .map(|(scene, lo, hi)| OutsideCase {
            methods: methods::names()
                .filter(|m| methods::supports_scene(m, &scene))
                .filter(|m| !["raycast", "penumbra-map"].contains(m))
                .collect(),
            bounds_only: with_box(scene.clone(), lo, hi, false),
            with_box: with_box(scene, lo, hi, true),
        })
        .collect()
}

/// A mesh wholly outside the light's influence changes no visibility value and rasterizes no
/// shadow-volume or wedge fragment: every shadow pass rasterizes exactly as many fragments as
/// in the scene with the same bounds and no box.
#[test]
fn a_mesh_outside_the_lights_influence_rasterizes_no_shadow_fragment() {
    for case in outside_cases() {
        let scene = &case.with_box.source;
        for m in case.methods.iter().copied() {
            let a = run_unvalidated(&case.bounds_only, m);
            let b = run_one(&case.with_box, m);
            let fa: Vec<_> = pass_work(&a).into_iter().map(|(n, _, f)| (n, f)).collect();
            let fb: Vec<_> = pass_work(&b).into_iter().map(|(n, _, f)| (n, f)).collect();
            assert_eq!(fa, fb, "{scene} {m}: fragments per pass");
            assert_eq!(a.visibility, b.visibility, "{scene} {m}");
        }
    }
}

/// A mesh wholly outside the light's influence submits no shadow-volume or wedge triangle
/// and produces no wedge (a finding of this test, fixed: `Frame::caster_meshes` leaves out
/// the casters `Frame::within_light_influence` separates from the light and the receivers).
#[test]
fn a_mesh_outside_the_lights_influence_produces_no_wedge_or_volume() {
    // Measured before the fix at 32² (bounds-only scene → scene with the box; triangles
    // submitted per shadow pass; the fragments were equal, see the test above):
    // single-quad, box behind the light: hard-sv 16 → 24; nsample 16384 → 27072; ssv-optimized
    // 392 → 560; ssv wedges 8 → 12, ssv-hard-quads 16 → 24, ssv-wedges 48 → 72;
    // wedge-blending silhouettes 2 → 3, half wedges 16 → 24, wb-shadow-volumes 16 → 24,
    // wb-half-wedges 188 → 268.
    // cube-of-spheres-sphere, box above the light: hard-sv 768 → 780; nsample 804824 →
    // 817112; pw2002 wedges 384 → 390 (2980 → 3028 triangles); pw-restructured wedges
    // 384 → 390 (3028 → 3076); ssv-optimized 43460 → 44278; ssv wedges 384 → 390
    // (ssv-hard-quads 768 → 780, ssv-wedges 2304 → 2340).
    let mut bad = Vec::new();
    for case in outside_cases() {
        let scene = &case.with_box.source;
        for m in case.methods.iter().copied() {
            let a = run_unvalidated(&case.bounds_only, m);
            let b = run_one(&case.with_box, m);
            let (wa, wb) = (wedge_counts(&a), wedge_counts(&b));
            let (pa, pb) = (pass_work(&a), pass_work(&b));
            eprintln!("{scene} {m}: wedges {wa:?} → {wb:?}; passes {pa:?} → {pb:?}");
            let ta: Vec<_> = pa.iter().map(|(n, t, _)| (n, t)).collect();
            let tb: Vec<_> = pb.iter().map(|(n, t, _)| (n, t)).collect();
            if wa != wb || ta != tb {
                bad.push(format!("{scene} {m}"));
            }
        }
    }
    assert!(bad.is_empty(), "extra volumes/wedges: {bad:?}");
}

/// A mesh that casts no shadow on anything (the sphere case of [`outside_cases`]) does not
/// change the work of the other casters' volumes (a finding of this test, fixed: `nsample`'s
/// sphere disk, `ssv-optimized`'s wedge clip box and the light view of `penumbra-map` are
/// taken from the meshes within the light's influence, `Frame::influence_bounds`).
#[test]
fn a_mesh_outside_the_lights_influence_leaves_the_other_volumes_alone() {
    // Measured before the fix at 32², cube-of-spheres-sphere → with the box at y 4.6–4.9 (fragments
    // rasterized in the shadow pass): nsample 4410302 → 4411223 (its sphere's sample disk
    // faces the center of the meshes' bounds, `nsample::sphere_disk_target`, which the box
    // moves), ssv-optimized 58772 → 58960 (the wedges are clipped to the scene bounds,
    // `tight_wedge::wedge_clip_box`); with the box at y 8.6–8.9: 4412481 and 60228.
    // penumbra-map refuses the scene with the box (light frustum 83.1° > 80°).
    let case = outside_cases().pop().unwrap();
    let without = small("cube-of-spheres-sphere");
    let mut bad = Vec::new();
    for m in ["nsample", "ssv-optimized", "penumbra-map"] {
        let a = run_one(&without, m);
        let frame = Frame::render(
            &case.with_box,
            penumbra::render::gpu_settings(&case.with_box).unwrap(),
        )
        .unwrap();
        let Ok(b) = methods::run(m, &frame) else {
            bad.push(format!("{m}: error"));
            continue;
        };
        let fa: Vec<_> = pass_work(&a).into_iter().map(|(n, _, f)| (n, f)).collect();
        let fb: Vec<_> = pass_work(&b).into_iter().map(|(n, _, f)| (n, f)).collect();
        eprintln!("{m}: {fa:?} → {fb:?}");
        if fa != fb {
            bad.push(format!("{m}: {fa:?} → {fb:?}"));
        }
    }
    assert!(bad.is_empty(), "{bad:?}");
}

/// A method's passes touch no buffer its plan does not list: on `cube-of-spheres`,
/// `cube-of-spheres-sphere` and `disk-block` (so every method runs), for every method and
/// pass, each buffer kind the pass's counters show bytes for (module doc table) is the kind of
/// a buffer in the plan; and each pass the method counted is named in the plan. Every
/// method, `raycast` included (its plan lists the depth buffer it reads since
/// [`raycast_lists_the_depth_buffer_it_reads`] was fixed); the methods checked are counted.
#[test]
fn passes_touch_only_buffers_their_plan_lists() {
    let mut checked = std::collections::BTreeSet::new();
    for scene in ["cube-of-spheres", "cube-of-spheres-sphere", "disk-block"] {
        let s = small(scene);
        for (m, out) in run_all(&s) {
            checked.insert(m.to_string());
            let listed: Vec<Kind> = buffers(&out)
                .iter()
                .map(|(_, f, _)| kind_of_format(f))
                .collect();
            let plan = plan_passes(&out);
            for p in &out.stats.passes {
                assert!(
                    plan.iter().any(|n| n.starts_with(&p.name)),
                    "{scene} {m}: pass {} not in the plan {plan:?}",
                    p.name
                );
                for k in kinds_touched(&p.counters) {
                    assert!(
                        listed.contains(&k),
                        "{scene} {m}: pass {} touches a {k:?} buffer; plan lists {:?}",
                        p.name,
                        buffers(&out)
                    );
                }
            }
        }
    }
    let registry: std::collections::BTreeSet<String> =
        penumbra::methods::names().map(String::from).collect();
    assert_eq!(checked, registry, "every method was checked");
}

/// `raycast` (receiver = depth buffer) reads the scene depth buffer its `scene-depth` pass
/// writes: its plan lists it (a finding of this test, fixed: the plan listed no buffer).
#[test]
fn raycast_lists_the_depth_buffer_it_reads() {
    // Measured before the fix (cube-of-spheres, 32²): pass scene-depth depth_read_bytes 2376,
    // depth_write_bytes 2376; plan buffers = [].
    let out = run_one(&small("cube-of-spheres"), "raycast");
    let c = out.stats.passes[0].counters;
    assert!(c.depth_write_bytes > 0);
    assert!(
        buffers(&out)
            .iter()
            .any(|(_, f, _)| kind_of_format(f) == Kind::Depth),
        "{:?}",
        buffers(&out)
    );
}

/// Every buffer a plan lists is touched by one of the method's passes (the counters show
/// bytes of its kind): nothing is allocated that the frame does not use.
#[test]
fn plans_list_no_buffer_their_passes_leave_untouched() {
    let mut bad = Vec::new();
    for scene in ["cube-of-spheres", "cube-of-spheres-sphere", "disk-block"] {
        let s = small(scene);
        for (m, out) in run_all(&s) {
            let mut total = Counters::default();
            for p in &out.stats.passes {
                total += p.counters;
            }
            let touched = kinds_touched(&total);
            for (name, format, _) in buffers(&out) {
                if !touched.contains(&kind_of_format(&format)) {
                    bad.push(format!("{scene} {m}: {name} ({format})"));
                }
            }
        }
    }
    assert!(bad.is_empty(), "{bad:#?}");
}

/// `nsample` sums its N hard shadows in an accumulation buffer (Paper III §5.1; f64x3, 24 B
/// per pixel in its plan), and its sample passes count that traffic (a finding of this test,
/// fixed: no counter counted it). Each sample's accumulation is a screen pass over the
/// receivers with the stencil test `EQUAL 0`: one stencil byte read per receiver, and a read
/// and a write of 24 B where the sample lights it. So, summed over the N samples, the colour
/// bytes read equal those written, 24 × Σ over the samples of the receivers lit, which is
/// 24 × the sum over the receivers of `visibility · N` (every weight 1/N under a rectangle,
/// N a power of two: the sums are exact).
#[test]
fn nsample_counts_its_accumulator_traffic() {
    // Measured before the fix (cube-of-spheres, 32², n = 1024): color_read_bytes =
    // color_write_bytes = 0 in every pass; plan buffers depth (D24), stencil (S8), accumulator
    // (f64x3, 24).
    let s = small("cube-of-spheres");
    let out = run_one(&s, "nsample");
    let c = shadow_passes(&out);
    let n = out.stats.plan["settings"]["n"].as_u64().unwrap();
    let frame = Frame::render(&s, penumbra::render::gpu_settings(&s).unwrap()).unwrap();
    let receivers: Vec<usize> = (0..frame.pixel_count())
        .filter(|&i| frame.prim_ids()[i] != penumbra::frame::BACKGROUND)
        .collect();
    // Lit samples per receiver: visibility · n, an integer up to the f64 sum's rounding.
    let lit: u64 = receivers
        .iter()
        .map(|&i| (f64::from(out.visibility.gray(i)) * n as f64).round() as u64)
        .sum();
    assert!(lit > 0 && lit < n * receivers.len() as u64, "{lit}");
    assert_eq!(c.color_read_bytes, c.color_write_bytes, "{c:?}");
    assert_eq!(c.color_read_bytes, 24 * lit, "{c:?}");
}
