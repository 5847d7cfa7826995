//! `ssv` (Paper III) with a sphere light (§5.3): the wedges around the sphere (§3.1) and the
//! exact coverage of the facing disk ([`sphere_edge_coverage_exact`]).
//!
//! Tolerance of the planar-occluder test (derivation). `ssv` with exact coverage is exact for a
//! single planar occluder (Paper III §5.3: neither the single-silhouette nor the overlap
//! artifact applies), up to f32 accumulation of a handful of terms (< 1e-5); both methods see
//! the sphere as the same facing disk and evaluate the same depth-buffer receiver point, so the
//! difference is the reference's sampling error. `raycast` maps k×k jittered strata (k = 32)
//! onto the disk with the Shirley–Chiu concentric map, one sample of weight 1/k² each, so an
//! edge crossing the disk misclassifies at most the strata its chord passes through. Count
//! them in the square: inside the sector |φ| ≤ π/4 the inverse map is s = r, t = (4/π)·r·φ, so
//! |ds| + |dt| ≤ 2|dr| + (4/π)·r|dφ| ≤ √(4 + 16/π²)·dℓ ≈ 2.371·dℓ along the chord (the other
//! sectors by symmetry). A chord of the unit disk has length ≤ 2, so its preimage crosses at
//! most 2.371·2/(2/k) = 2.371·k grid lines on monotone pieces, plus one more per monotone
//! piece of s and of t (≤ 2 each in each of the ≤ 3 sectors a line meets: 12): at most
//! 2.371·k + 13 strata, an error ≤ (2.371·k + 13)/k² = 0.0868 per crossing edge. An edge
//! crosses the disk when it meets F, the set where the rays from the receiver to the disk
//! cross the occluder's plane y = 1. F is convex, and for every receiver of the scene (floor
//! and floor slab, |x|, |z| ≤ 3, y ≤ 0; the occluder's own top sees its edges edge-on, coverage
//! 0) its diameter is < 1 (≤ 0.7, at the floor's corners, where the disk of radius 0.5 three
//! above is tilted by 55°), while opposite sides of the 1×1 occluder are 1 apart: at most two
//! (adjacent) edges cross, so max |e| ≤ 2·0.0868 = 0.174. Jitter errors are unbiased, so the
//! mean is far smaller; as for the rectangle (`tests/suite/soft_shadow_volumes.rs`) we require
//! mean ≤ 1/(2k). Measured: 64² max 0.0081, mean 0.00027; 256² max 0.0106, mean 0.00025.

use crate::common;
use crate::independent_coverage::{
    clip_convex, disk_coverage_by_grid, polygon_signed_area, DISK_GRID_BOUND,
};
use common::{gray, K};
use glam::{DVec2, DVec3, Vec3};
use penumbra::frame::{Frame, GpuSettings};
use penumbra::geometry::ssv_wedge::{SsvWedge, WedgeLight};
use penumbra::gpu::vbuffer::VBufferFormat;
use penumbra::light::coverage::sphere_edge_coverage_exact;
use penumbra::methods::hard_sv::ShadowTest;
use penumbra::methods::output::MethodOutput;
use penumbra::methods::recorder::PassRecorder;
use penumbra::methods::ssv::{read_settings, CoverageMode, SsvSettings};
use penumbra::render::render_scene;
use penumbra::scene::procedural::two_sided_quad;
use penumbra::scene::{builtin, LightShape, OptionValue, Scene};
use proptest::prelude::*;

/// `ssv`'s two passes on `frame` with `s`, through a recorder of their own.
fn render(frame: &Frame, s: &SsvSettings) -> MethodOutput {
    let mut rec = PassRecorder::new(frame, "ssv");
    let r = penumbra::methods::ssv::render(&mut rec, s);
    rec.finish(r.visibility, serde_json::Value::Null)
}

/// `single-quad` at 64² with its 1×1 rectangle replaced by a sphere of radius 0.5 (same
/// center, 3 above the floor, 2 above the quad).
fn sphere_quad() -> Scene {
    let mut s = builtin::load("single-quad").unwrap();
    s.width = 64;
    s.height = 64;
    s.lights[0].shape = LightShape::Sphere { radius: 0.5 };
    s
}

fn exact(vbuffer: VBufferFormat) -> SsvSettings {
    SsvSettings {
        coverage: CoverageMode::Exact,
        vbuffer,
        test: ShadowTest::ZPass,
        horizon: penumbra::methods::horizon_clip::Horizon::Off,
    }
}

fn ssv_visibility(scene: &Scene, settings: &SsvSettings) -> Vec<f32> {
    let frame = Frame::render(scene, GpuSettings::default()).unwrap();
    gray(&render(&frame, settings).visibility)
}

#[test]
fn ssv_exact_matches_raycast_on_single_quad_under_a_sphere() {
    common::assert_ssv_agrees_with_raycast(
        sphere_quad(),
        2.0 * (2.371 * K + 13.0) / (K * K) + 1e-5,
        "single-quad, sphere light, 64²",
    );
}

/// The occluder of the sphere scene cut in two along x = `cut` (two closed two-sided quads
/// sharing the cut edge).
fn cut_in_two(cut: f32) -> Scene {
    let mut s = sphere_quad();
    let quad = s.meshes.pop().unwrap();
    let y = quad.positions[0].y;
    let c = quad.color;
    let piece = |x0: f32, x1: f32| {
        [
            Vec3::new(x0, y, 0.5),
            Vec3::new(x1, y, 0.5),
            Vec3::new(x1, y, -0.5),
            Vec3::new(x0, y, -0.5),
        ]
    };
    s.meshes.push(two_sided_quad("left", piece(-0.5, cut), c));
    s.meshes.push(two_sided_quad("right", piece(cut, 0.5), c));
    s
}

#[test]
fn cutting_the_occluder_in_two_does_not_change_the_sphere_shadow() {
    let a = ssv_visibility(&sphere_quad(), &exact(VBufferFormat::F32));
    let b = ssv_visibility(&cut_in_two(0.125), &exact(VBufferFormat::F32));
    // The two wedges of the shared edge are the same wedge (built from the same top edge) and
    // their coverages are exact negatives; the two collinear halves of a side cover exactly
    // what the whole side covers (sector minus triangle is additive along a chord); the hard
    // quads cancel exactly. Only f32 rounding of these sums remains, a few ulps of 1.
    let max = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0f32, f32::max);
    eprintln!("sphere: whole vs cut in two: max |Δ| = {max:e}");
    assert!(max <= 4.0 * f32::EPSILON, "max |Δ| = {max}");
}

/// Sphere-light hard cases, every V-buffer format: values finite, and before the resolve's
/// clamp in [0, 1] (`clamped_pixels` = 0) except where Paper III §5.3's object-overlap
/// artifact drives the sum below 0 — on `cube-of-spheres-sphere` (pinned: 159 pixels with the
/// float V-buffers, 157 with the 8-bit one at 48²):
/// * `cylinder`, `cube-of-spheres-sphere`: faceted occluders (single-silhouette and overlap
///   artifacts, Paper III §5.3);
/// * `eye-in-shadow` with a sphere: the eye in the hard shadow volume (z-fail) and in wedges;
/// * the sphere lowered to 0.01 above the quad (edges almost touching the light: degenerate,
///   full-screen wedges);
/// * a sphere so large (radius 1.9, 0.05 above the quad) that the quad has no umbra.
#[test]
fn sphere_hard_cases_stay_in_unit_interval() {
    let mut scenes = Vec::new();
    for name in ["cylinder", "cube-of-spheres-sphere", "eye-in-shadow"] {
        let mut s = builtin::load(name).unwrap();
        s.width = 48;
        s.height = 48;
        if name == "eye-in-shadow" {
            s.lights[0].shape = LightShape::Sphere { radius: 0.3 };
        }
        scenes.push(s);
    }
    for (height, radius) in [(1.51, 0.5), (2.95, 1.9)] {
        let mut s = sphere_quad();
        s.lights[0].center.y = height;
        s.lights[0].shape = LightShape::Sphere { radius };
        scenes.push(s);
    }
    for s in &scenes {
        let frame = Frame::render(s, GpuSettings::default()).unwrap();
        let (settings, _) = read_settings(&frame).unwrap();
        for vbuffer in [
            VBufferFormat::F32,
            VBufferFormat::F16,
            VBufferFormat::Split8,
        ] {
            let r = render(
                &frame,
                &SsvSettings {
                    vbuffer,
                    ..settings
                },
            );
            let v = gray(&r.visibility);
            assert!(v.iter().all(|x| x.is_finite()), "{} {vbuffer:?}", s.source);
            let pinned = match (s.source.as_str(), vbuffer) {
                ("cube-of-spheres-sphere", VBufferFormat::Split8) => 157,
                ("cube-of-spheres-sphere", _) => 159,
                _ => 0,
            };
            assert_eq!(r.stats.clamped_pixels, pinned, "{} {vbuffer:?}", s.source);
        }
    }
    // The large light leaves no umbra on the floor under the quad.
    let large = scenes.last().unwrap();
    let v = ssv_visibility(large, &exact(VBufferFormat::F32));
    assert!(v.iter().all(|x| *x > 0.0), "no umbra expected");
}

/// Same bits with 1 and 3 worker threads, in every V-buffer format.
#[test]
fn sphere_ssv_is_deterministic_for_any_thread_count() {
    let s = sphere_quad();
    for vbuffer in [
        VBufferFormat::F32,
        VBufferFormat::F16,
        VBufferFormat::Split8,
    ] {
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| ssv_visibility(&s, &exact(vbuffer)))
        };
        let (one, three) = (run(1), run(3));
        assert!(
            one.iter()
                .zip(&three)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{vbuffer:?}"
        );
    }
}

/// `coverage = "texture"` is defined over a rectangle only (Paper III §5.3: no coverage texture
/// for spheres): an input error naming the option.
#[test]
fn coverage_texture_with_a_sphere_is_an_input_error() {
    let mut s = sphere_quad();
    s.methods = Some(vec!["ssv".into()]);
    s.options
        .entry("ssv".into())
        .or_default()
        .insert("coverage".into(), OptionValue::Str("texture".into()));
    let Err(e) = render_scene(&s) else {
        panic!("an input error expected");
    };
    let e = e.to_string();
    assert!(e.contains("options.ssv.coverage"), "{e}");
}

/// The facing disk of a sphere at the origin seen from `p`: an orthonormal basis of its plane.
fn disk_basis(p: DVec3) -> (DVec3, DVec3, DVec3) {
    let n = p.normalize();
    let x = n.any_orthonormal_vector();
    (x, n.cross(x), n)
}

proptest! {
    /// Green's theorem over a closed silhouette loop with a sphere (Paper III §3.2, Figure 9):
    /// a convex polygon between the receiver and the sphere. The hard count from the center
    /// plus the loop's coverages gives 1 − area(projection ∩ facing disk)/area(disk), checked
    /// against an independent clipping of a 4096-gon disk (relative area error < 1e-6).
    #[test]
    fn closed_loop_gives_the_visible_fraction_of_the_disk(
        p in (-0.3..0.3f64, -0.3..0.3f64, 2.0..4.0f64),
        h_frac in 0.3..0.8f64,
        sides in 3usize..9,
        phase in 0.0..1.0f64,
        offset in (-0.5..0.5f64, -0.5..0.5f64),
        radius in 0.05..2.0f64,
        light_radius in 0.1..0.3f64,
    ) {
        let pw = DVec3::new(p.0, p.1, p.2);
        let h = p.2 * h_frac;
        // Counter-clockwise seen from p (above): det(a, b, p) > 0 on the umbra side.
        let world: Vec<DVec3> = (0..sides)
            .map(|k| {
                let a = (k as f64 + phase) / sides as f64 * std::f64::consts::TAU;
                DVec3::new(offset.0 + radius * libm::cos(a), offset.1 + radius * libm::sin(a), h)
            })
            .collect();
        let mut sum = 0.0;
        for k in 0..sides {
            sum += sphere_edge_coverage_exact(
                DVec3::ZERO, light_radius, pw, world[k], world[(k + 1) % sides],
            );
        }
        // Independent check: project the vertices from p onto the disk's plane, clip.
        let (bx, by, n) = disk_basis(pw);
        let projected: Vec<DVec2> = world
            .iter()
            .map(|q| {
                let x = pw + (*q - pw) * (pw.dot(n) / (pw - *q).dot(n));
                DVec2::new(x.dot(bx), x.dot(by))
            })
            .collect();
        let ccw = polygon_signed_area(&projected) > 0.0;
        let projected: Vec<DVec2> = if ccw {
            projected
        } else {
            projected.into_iter().rev().collect()
        };
        let disk: Vec<DVec2> = (0..4096)
            .map(|k| DVec2::from_angle(k as f64 / 4096.0 * std::f64::consts::TAU) * light_radius)
            .collect();
        let disk_area = polygon_signed_area(&disk);
        let covered = polygon_signed_area(&clip_convex(&disk, &projected)) / disk_area;
        let center_hidden = projected
            .iter()
            .zip(projected.iter().cycle().skip(1))
            .all(|(a, b)| a.perp_dot(*b) > 0.0);
        let visibility = 1.0 - center_hidden as u8 as f64 + sum;
        prop_assert!(
            (visibility - (1.0 - covered)).abs() < 1e-6,
            "{visibility} vs {}", 1.0 - covered
        );
    }

    /// The wedge around the sphere encloses the penumbra volume of its edge (Paper III §3.1):
    /// wherever the edge's coverage of the facing disk is not zero, the receiver is inside.
    #[test]
    fn sphere_wedge_contains_every_point_with_coverage(
        p in (-3.0..3.0f64, -3.0..3.0f64, -4.0..4.0f64),
        e0 in (-2.0..2.0f64, -2.0..2.0f64, -3.0..3.0f64),
        e1 in (-2.0..2.0f64, -2.0..2.0f64, -3.0..3.0f64),
        radius in 0.1..0.6f64,
    ) {
        let (pw, a, b) = (DVec3::from(p), DVec3::from(e0), DVec3::from(e1));
        // Geometry does not intersect the light: the edge and p stay outside the sphere.
        let d = b - a;
        let t = if d.length_squared() > 0.0 {
            (-a.dot(d) / d.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let closest = (a + d * t).length();
        prop_assume!(closest > radius && pw.length() > radius);
        let c = sphere_edge_coverage_exact(DVec3::ZERO, radius, pw, a, b);
        let light = WedgeLight::Sphere { center: DVec3::ZERO, radius };
        if let Some(w) = SsvWedge::new(&light, a, b) {
            prop_assert!(c.abs() < 1e-9 || w.contains(pw), "coverage {c} outside the wedge");
        }
    }

    /// The signed coverage of any edge is the fraction of the facing disk the edge's quad
    /// hides, counted on a grid of the disk by segment–quad crossings (an algorithm of the
    /// test's own, `independent_coverage`): within its derived bound 16/(πN), so a value
    /// beyond the disk or NaN fails. A receiver inside the sphere gets 0 (the function's doc).
    #[test]
    fn sphere_coverage_is_the_hidden_fraction_of_the_disk(
        p in (-3.0..3.0f64, -3.0..3.0f64, -4.0..4.0f64),
        e0 in (-3.0..3.0f64, -3.0..3.0f64, -4.0..4.0f64),
        e1 in (-3.0..3.0f64, -3.0..3.0f64, -4.0..4.0f64),
    ) {
        let (pw, a, b) = (DVec3::from(p), DVec3::from(e0), DVec3::from(e1));
        let c = sphere_edge_coverage_exact(DVec3::ZERO, 0.4, pw, a, b);
        let expected = if pw.length() <= 0.4 {
            0.0
        } else {
            disk_coverage_by_grid(DVec3::ZERO, 0.4, pw, a, b)
        };
        prop_assert!(
            (c - expected).abs() <= DISK_GRID_BOUND,
            "{c} vs grid {expected} (bound {DISK_GRID_BOUND})"
        );
    }
}
