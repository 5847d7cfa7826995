//! `wedge-blending` (Forest, Barthe & Paulin 2006): one silhouette is the plain penumbra-wedge
//! sum, disjoint occluders are not corrected, overlapping ones are (and closer to the
//! reference than `ssv`), the 8-bit packing against the f32 variant, the float targets, the
//! blending order, thread-count independence, the buffer footprint and the option errors.

use glam::{DVec3, Vec3};
use penumbra::frame::{Frame, GpuSettings};
use penumbra::methods::recorder::PassRecorder;
use penumbra::methods::wedge_blending::{options, render, BlendingRender};
use penumbra::metrics::compare_where;
use penumbra::scene::procedural::{box_mesh, two_sided_quad};
use penumbra::scene::{builtin, Camera, Light, LightShape, OptionValue, Scene};
use penumbra::visibility::Visibility;

/// `scene` with `[options.wedge-blending]` set to `opts`.
fn with_options(mut scene: Scene, opts: &[(&str, &str)]) -> Scene {
    let table = scene.options.entry("wedge-blending".into()).or_default();
    for (k, v) in opts {
        table.insert(k.to_string(), OptionValue::Str(v.to_string()));
    }
    scene
}

/// Render `wedge-blending` with `opts` on `scene`.
fn blend(scene: &Scene, opts: &[(&str, &str)]) -> BlendingRender {
    let scene = with_options(scene.clone(), opts);
    let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
    let (s, _) = options(&frame).unwrap();
    render(&mut PassRecorder::new(&frame, "wedge-blending"), &s).unwrap()
}

/// The visibility of `method` on `scene`.
fn method(scene: &Scene, method: &str) -> Vec<f32> {
    let frame = Frame::render(scene, GpuSettings::default()).unwrap();
    match penumbra::methods::run(method, &frame).unwrap().visibility {
        Visibility::Gray(v) => v,
        Visibility::Rgb(_) => unreachable!("rect lights are gray"),
    }
}

fn sized(name: &str, size: u32) -> Scene {
    let mut s = builtin::load(name).unwrap();
    s.width = size;
    s.height = size;
    s
}

fn max_diff(a: &[f32], b: &[f32]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}

/// The bound of the f32 comparisons with `ssv`: both sum the same exact coverages (f64,
/// identical to 1e-12 apart from the local near plane), rounded to f32: `ssv` in one V-buffer
/// value, wedge-blending per part and then `1 − Σ/4`. A pixel meets at most a handful of
/// wedges, so the two f32 sums of terms in [−1, 1] differ by a few ulps of 1 (2⁻²⁴ each).
const F32_SUM_BOUND: f32 = 1e-5;

/// With a single occluding silhouette nothing is blended: the result is `ssv`'s (the plain
/// penumbra-wedge occlusion of Paper III) up to the f32 summation order.
#[test]
fn one_silhouette_gives_the_plain_penumbra_wedge_occlusion() {
    for name in ["single-quad", "forest-spheres-1"] {
        let scene = sized(name, 64);
        let r = blend(&scene, &[("packing", "f32")]);
        let ssv = method(&scene, "ssv");
        let d = max_diff(&r.visibility, &ssv);
        assert!(d <= F32_SUM_BOUND, "{name}: max |wb − ssv| = {d}");
        assert_eq!(r.counters.parts_corrected, 0, "{name}");
        assert!(
            r.counters.parts_copied > 100,
            "{name}: the occluder was drawn"
        );
    }
}

/// Two long bars in one plane parallel to the light, side by side with a gap: from every
/// floor point their projections onto the light are the bars scaled about the same center
/// (the floor, the bars and the light are parallel), so the occluded regions never intersect.
fn two_bars() -> Scene {
    let bar = |name: &str, x0: f32, x1: f32| {
        two_sided_quad(
            name,
            [
                Vec3::new(x0, 1.0, 1.0),
                Vec3::new(x1, 1.0, 1.0),
                Vec3::new(x1, 1.0, -1.0),
                Vec3::new(x0, 1.0, -1.0),
            ],
            [0.8, 0.4, 0.3],
        )
    };
    Scene {
        source: "two-bars".into(),
        width: 96,
        height: 96,
        camera: Camera {
            eye: DVec3::new(0.0, 4.0, 3.0),
            target: DVec3::ZERO,
            up: DVec3::Y,
            vfov_deg: 60.0,
            near: None,
        },
        lights: vec![Light {
            center: Vec3::new(0.0, 3.0, 0.0),
            shape: LightShape::Rect {
                u: Vec3::new(0.5, 0.0, 0.0),
                v: Vec3::new(0.0, 0.0, 0.5),
            },
        }],
        meshes: vec![
            box_mesh(
                "floor",
                Vec3::new(-3.0, -0.1, -3.0),
                Vec3::new(3.0, 0.0, 3.0),
                [0.8; 3],
            ),
            bar("left", -0.15, -0.05),
            bar("right", 0.05, 0.15),
        ],
        methods: None,
        options: Default::default(),
        cli_options: Default::default(),
        ambient: 0.15,
    }
}

/// Disjoint occluded regions are not corrected: wherever both bars occlude a part of the
/// light, their rectangles do not intersect (ε = 0), and the result is `ssv`'s.
#[test]
fn disjoint_occluders_are_not_corrected() {
    let scene = two_bars();
    let ssv = method(&scene, "ssv");
    for packing in ["f32", "8bit"] {
        let r = blend(&scene, &[("packing", packing)]);
        assert!(
            r.counters.parts_blended > 50,
            "{packing}: both bars occlude the same parts at {} parts",
            r.counters.parts_blended
        );
        assert_eq!(r.counters.parts_corrected, 0, "{packing}");
        if packing == "f32" {
            // Unlike `ssv`, a half-wedge's front faces are depth tested (Fig. 8): a receiver
            // within one depth step behind a face is rejected with its coverage, which is
            // close to 0 there (the face is the wedge's boundary). Pinned: two such pixels at
            // the outer boundary of the right bar's wedge, 2.6·10⁻⁵ each.
            let off: Vec<f32> = r
                .visibility
                .iter()
                .zip(&ssv)
                .map(|(a, b)| (a - b).abs())
                .filter(|d| *d > F32_SUM_BOUND)
                .collect();
            assert!(
                off.len() <= 2,
                "{} pixels where f32 wedge-blending ≠ ssv",
                off.len()
            );
            assert!(off.iter().all(|d| *d < 1e-4), "{off:?}");
        }
    }
}

/// Where penumbrae of different silhouettes overlap (the raw image `penumbrae` ≥ 2), the
/// blending is closer to the reference than `ssv`'s plain sum (Forest et al. §5.1's claim, on
/// the paper's own scene), and it changes nothing where they do not overlap by more than
/// `ssv` errs there.
#[test]
fn blending_beats_the_plain_sum_where_penumbrae_overlap() {
    let scene = sized("forest-spheres", 96);
    let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
    let reference = penumbra::methods::run("raycast", &frame)
        .unwrap()
        .visibility;
    let ssv = penumbra::methods::run("ssv", &frame).unwrap().visibility;
    for packing in ["8bit", "f32"] {
        let r = blend(&scene, &[("packing", packing)]);
        let overlap = |i: usize| r.penumbrae[i] >= 2;
        let wb = Visibility::Gray(r.visibility.clone());
        let e_wb = compare_where(&wb, &reference, overlap);
        let e_ssv = compare_where(&ssv, &reference, overlap);
        assert!(e_wb.pixels > 500, "{} overlap pixels", e_wb.pixels);
        assert!(
            e_wb.mean_abs < 0.5 * e_ssv.mean_abs && e_wb.rmse < 0.5 * e_ssv.rmse,
            "{packing}: wedge-blending {e_wb:?} vs ssv {e_ssv:?}"
        );
        assert!(r.counters.parts_corrected > 1000);
    }
}

/// The 8-bit packing against the f32 variant on a single silhouette: every stored value is
/// rounded to the nearest 255th at each write, so a part's occlusion is off by at most half a
/// step per write — the shadow-volume initialization, one fragment per edge of the silhouette
/// (a pixel lies in one half of each edge's wedge at most), and the copy into the final
/// vBuffer — and the visibility, their mean, by no more. The measured difference is pinned
/// below that bound.
#[test]
fn packed_occlusion_is_within_its_rounding_of_the_f32_one() {
    let scene = sized("forest-spheres-1", 64);
    let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
    let (settings, _) = options(&frame).unwrap();
    let edges = penumbra::methods::wedge_blending::silhouettes(&frame, &settings)
        .unwrap()
        .iter()
        .map(|s| s.edges.len())
        .max()
        .unwrap();
    let f = blend(&scene, &[("packing", "f32")]);
    let p = blend(&scene, &[("packing", "8bit")]);
    let writes_per_part = (1 + edges + 1) as f32;
    let bound = writes_per_part * 0.5 / 255.0 + F32_SUM_BOUND;
    let d = max_diff(&f.visibility, &p.visibility);
    assert!(
        d <= bound,
        "max |8bit − f32| = {d} > {bound} ({edges} edges)"
    );
    // Pin: rounding errors do not pile up in practice (a pixel meets few wedges).
    assert!(d > 0.0 && d <= 4.0 / 255.0, "max |8bit − f32| = {d}");
}

/// The packed patterns that are not ordinary floats (`gpu::pack4ub`): an umbra's occlusion
/// scalar `(255, 0, 0, 0)` is a denormal, a rectangle in the far half of a part with right =
/// 1 a NaN. A raw target keeps them; a flushing or NaN-canonicalizing target corrupts them
/// and the image changes.
#[test]
fn float_targets_that_alter_packed_patterns_change_the_image() {
    let scene = sized("cube-of-spheres", 64);
    let raw = blend(&scene, &[]);
    assert!(raw.counters.stores.denormal > 0 && raw.counters.stores.nan > 0);
    assert_eq!(raw.counters.stores.altered, 0);
    for target in ["flush-denormals", "canonical-nans"] {
        let r = blend(&scene, &[("target", target)]);
        assert!(r.counters.stores.altered > 0, "{target}");
        assert!(max_diff(&r.visibility, &raw.visibility) > 0.1, "{target}");
    }
}

/// The result depends on the blending order where three or more silhouettes overlap
/// (ε depends on the merged rectangle), and not at all with one occluder.
#[test]
fn blending_order_matters_only_where_silhouettes_overlap() {
    let one = sized("single-quad", 48);
    let f = blend(&one, &[("packing", "f32")]);
    let r = blend(&one, &[("packing", "f32"), ("order", "reverse")]);
    assert_eq!(f.visibility, r.visibility);
    let many = sized("cube-of-spheres", 64);
    let f = blend(&many, &[("packing", "f32")]);
    let r = blend(&many, &[("packing", "f32"), ("order", "reverse")]);
    assert!(max_diff(&f.visibility, &r.visibility) > 1.0 / 255.0);
}

/// Before the final clamp, every pixel's visibility is already in [0, 1] on closed occluders
/// without holes: packed, PK4UB clamps each part; unpacked, the blend limits each part to 1
/// and a loop's Green sum is ≥ 0 — once the half-wedge a receiver falls in agrees with its
/// stencil count (`HardQuad::side`; before that rule, a receiver within a depth step of a hard
/// quad got a negative sum, one pixel each on `cube-of-spheres` and `forest-spheres` at 64²).
#[test]
fn nothing_to_clamp_on_closed_occluders_without_holes() {
    for name in ["cube-of-spheres", "eye-in-shadow", "forest-spheres"] {
        let scene = sized(name, 64);
        for packing in ["8bit", "f32"] {
            let r = blend(&scene, &[("packing", packing)]);
            let outside = r
                .unclamped
                .iter()
                .filter(|v| !(0.0..=1.0).contains(*v) || !v.is_finite())
                .count() as u64;
            assert_eq!(outside, 0, "{name} {packing}");
            assert_eq!(r.counters.clamped_pixels, 0, "{name} {packing}");
        }
    }
}

#[test]
fn deterministic_for_any_thread_count() {
    let scene = sized("cube-of-spheres", 48);
    for opts in [
        &[][..],
        &[("packing", "f32"), ("centroid", "on")][..],
        &[("silhouettes", "meshes"), ("mode", "zfail")][..],
    ] {
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let r = blend(&scene, opts);
                (r.visibility, r.penumbrae, r.counters)
            })
        };
        assert_eq!(run(1), run(3), "{opts:?}");
    }
}

/// z-fail with the loops' fan caps gives z-pass's result where the eye is lit, and with the
/// meshes' own caps too.
#[test]
fn zfail_caps_agree_with_zpass_when_the_eye_is_lit() {
    let scene = sized("cube-of-spheres", 48);
    let zpass = blend(&scene, &[("mode", "zpass")]).visibility;
    for grouping in ["loops", "meshes"] {
        let zfail = blend(&scene, &[("mode", "zfail"), ("silhouettes", grouping)]).visibility;
        let differ = zpass.iter().zip(&zfail).filter(|(a, b)| a != b).count();
        // Shadow-volume counts differ only where a quad and the receiver share a depth step.
        assert!(differ <= 3, "{grouping}: {differ} pixels differ");
    }
}

/// A hole: the torus of `scenes/hard/torus-hole-rect.toml` has two silhouette loops from the
/// light center, the rim and the hole (hard count −1 where the hole loop is alone). Unpacked,
/// the hole loop is added without ε and the result is `ssv`'s Green sum; grouped by mesh, too
/// (up to the packing); packed per loop, PK4UB clamps the −1 to 0 and the hole's light is
/// lost — the finding is pinned: the hole's pixels go dark.
#[test]
fn a_hole_loop_needs_signed_storage_or_one_silhouette_per_mesh() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/hard/torus-hole-rect.toml"
    );
    let mut scene = penumbra::scene::file::resolve(path).unwrap();
    scene.width = 64;
    scene.height = 64;
    let ssv = method(&scene, "ssv");
    let f32_loops = blend(&scene, &[("packing", "f32")]);
    assert!(
        f32_loops.counters.parts_accumulated > 0,
        "the hole loop is negative"
    );
    let d = max_diff(&f32_loops.visibility, &ssv);
    eprintln!("f32 loops vs ssv: {d}");
    assert!(d <= 1e-4, "{d}");
    let meshes = blend(&scene, &[("silhouettes", "meshes")]);
    let steps = 8.0 / 255.0;
    let close = |v: &[f32]| {
        v.iter()
            .zip(&ssv)
            .filter(|(a, b)| (*a - *b).abs() > steps)
            .count()
    };
    assert!(
        close(&meshes.visibility) <= 4,
        "{}",
        close(&meshes.visibility)
    );
    let packed_loops = blend(&scene, &[]);
    let dark = packed_loops
        .visibility
        .iter()
        .zip(&ssv)
        .filter(|(a, b)| **b > 0.5 && **a < 0.1)
        .count();
    assert!(dark > 20, "{dark} lit hole pixels went dark");
}

/// The hole is detected at run time (issue 28): the packed default warns, naming the mesh, the
/// loop count and the remedies; the unpacked storage and one silhouette per mesh hold the hole
/// and do not warn; a scene of convex occluders has no hole loop and does not warn.
#[test]
fn a_hole_loop_under_the_8bit_packing_is_warned_about() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/hard/torus-hole-rect.toml"
    );
    let mut torus = penumbra::scene::file::resolve(path).unwrap();
    torus.width = 64;
    torus.height = 64;
    let warnings = |scene: &Scene, opts: &[(&str, &str)]| {
        let scene = with_options(scene.clone(), opts);
        let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
        let out = penumbra::methods::run("wedge-blending", &frame).unwrap();
        out.stats.warnings
    };
    let packed = blend(&torus, &[]);
    // One mesh, the torus (not the floor); some of its loops (the hole's; not every loop: the rim's count is +1) read
    // −1 where they are alone.
    assert_eq!(packed.hole_loops.len(), 1, "{:?}", packed.hole_loops);
    assert!(torus.meshes[packed.hole_loops[0].mesh]
        .name
        .contains("torus"));
    let loops = packed.hole_loops[0].loops;
    assert!(
        loops >= 1 && loops < packed.counters.silhouettes,
        "{loops} of {}",
        packed.counters.silhouettes
    );
    assert_eq!(packed.hole_loops[0].pixels, packed.counters.negative_counts);
    assert!(packed.counters.negative_counts > 20);
    let w = warnings(&torus, &[]);
    assert_eq!(w.len(), 1, "{w:?}");
    let count = format!("{loops} silhouette loop(s) around a hole");
    for needle in [count.as_str(), "packing = \"f32\"", "torus"] {
        assert!(w[0].contains(needle), "{needle:?} not in {:?}", w[0]);
    }
    // Unpacked, the same negative counts are read and kept: no warning.
    assert_eq!(
        blend(&torus, &[("packing", "f32")])
            .counters
            .negative_counts,
        packed.counters.negative_counts
    );
    assert!(warnings(&torus, &[("packing", "f32")]).is_empty());
    // One silhouette per mesh: the rim's +1 and the hole's −1 sum in one stencil, no
    // negative count is read.
    assert_eq!(
        blend(&torus, &[("silhouettes", "meshes")])
            .counters
            .negative_counts,
        0
    );
    assert!(warnings(&torus, &[("silhouettes", "meshes")]).is_empty());
    let spheres = sized("cube-of-spheres", 48);
    assert_eq!(blend(&spheres, &[]).counters.negative_counts, 0);
    assert!(warnings(&spheres, &[]).is_empty());
}

/// The plan's buffers: depth, stencil and two vBuffers of two RGBA32F targets each — 48 MiB
/// at the paper's 1024×768 for the two vBuffers, as Forest et al. §4.3 says.
#[test]
fn buffer_footprint_is_the_papers() {
    let scene = sized("single-quad", 32);
    let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
    let out = penumbra::methods::run("wedge-blending", &frame).unwrap();
    let buffers = out.stats.plan["buffers"].as_array().unwrap().clone();
    let vbuffer_bytes: u64 = buffers
        .iter()
        .filter(|b| b["name"].as_str().unwrap().ends_with("vbuffer"))
        .map(|b| b["bytes_per_sample"].as_u64().unwrap())
        .sum();
    assert_eq!(vbuffer_bytes * 1024 * 768, 48 * 1024 * 1024);
    let names: Vec<&str> = out.stats.passes.iter().map(|p| p.name.as_str()).collect();
    for pass in ["wb-shadow-volumes", "wb-half-wedges", "wb-blend"] {
        assert!(names.contains(&pass), "{names:?}");
    }
}

#[test]
fn bad_options_are_input_errors() {
    let scene = sized("single-quad", 16);
    let cases: [(&[(&str, &str)], &str); 3] = [
        (&[("packing", "4bit")], "options.wedge-blending.packing"),
        (
            &[("packing", "f32"), ("target", "flush-denormals")],
            "options.wedge-blending.target",
        ),
        (
            &[("radial_parts", "8")],
            "options.wedge-blending.radial_parts",
        ),
    ];
    for (opts, key) in cases {
        let s = with_options(scene.clone(), opts);
        let frame = Frame::render(&s, GpuSettings::default()).unwrap();
        let e = options(&frame).unwrap_err().to_string();
        assert!(e.contains(key), "{e}");
    }
    let mut sphere = scene.clone();
    sphere.lights[0].shape = LightShape::Sphere { radius: 0.3 };
    let frame = Frame::render(&sphere, GpuSettings::default()).unwrap();
    assert!(options(&frame).unwrap_err().to_string().contains("rect"));
}
