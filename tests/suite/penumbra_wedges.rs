//! Penumbra wedges (Paper I) and the restructured algorithm (Paper II): equality of the LI
//! buffers, z-fail, overflow, construction invariants and hard cases.

use glam::DVec3;
use penumbra::frame::{Frame, GpuSettings};
use penumbra::geometry::penumbra_wedge::{light_intensity, FaceKind, Plane, Wedge};
use penumbra::gpu::transform::ClipVertex;
use penumbra::methods::pw2002::{self, WedgeSettings};
use penumbra::methods::pw_restructured::{self, Culling, Passes, RestructuredSettings, WedgeTest};
use penumbra::scene::Scene;
use std::cmp::Ordering;
use std::collections::BTreeMap;

use crate::sphere_hard_cases;
use sphere_hard_cases::{gray, small, with_sphere};

fn wedge_settings(frame: &Frame) -> WedgeSettings {
    pw2002::options(frame).expect("settings")
}

fn li_pw2002(frame: &Frame, s: &WedgeSettings) -> Vec<i32> {
    let set = pw2002::frame_wedges(frame, s).expect("wedges");
    let (t, _) = pw2002::render_li(frame, &set, s);
    pw2002::li_row_major(frame, &t)
}

fn li_restructured(frame: &Frame, s: &RestructuredSettings) -> Vec<i32> {
    let set = pw2002::frame_wedges(frame, &s.wedge).expect("wedges");
    let t = pw_restructured::render_li(&mut PassRecorder::new(frame, "pw-restructured"), &set, s);
    pw2002::li_row_major(frame, &t)
}

fn restructured(
    w: WedgeSettings,
    test: WedgeTest,
    passes: Passes,
    culling: Culling,
) -> RestructuredSettings {
    RestructuredSettings {
        wedge: w,
        test,
        passes,
        culling,
    }
}

/// Pixels where the LI buffers of `pw2002` (side planes cancelling, Paper I §5) and
/// `pw-restructured` (z-pass) may differ: pixels whose eye ray grazes a line where two wedge
/// faces meet. There `pw2002` finds the exit plane analytically in f64 (Paper I §6) while
/// `pw-restructured` sees whether the snapped, fixed-point triangle of the neighbouring face
/// covers the pixel center; both are exact for their own representation but can disagree by
/// one umbra step. Everywhere else the two add the same integers (same wedges, same
/// `light_intensity`, same `li_amount`). The equality needs the same wedges in both: scenes
/// with degenerate wedges (Fig. 6), whose umbra `pw-restructured` draws with the outer-volume
/// quad instead, are excluded — `cube-of-spheres-sphere` has them (asserted below).
///
/// The one `pw-columns` pixel (64², pixel (4, 32): `pw2002` LI 0, `pw-restructured` 255,
/// `raycast` 1.0): its eye ray runs through wedge 101 of the loop, crosses the side plane
/// shared with wedge 100 at ray parameter 305.4964, and leaves wedge 100 through its front
/// plane at 305.5179 (wedge 101's front plane is at 305.5550): in f64 it passes 0.0011 pixel
/// from the projected front line the two wedges share (where both front planes and the side
/// plane meet), less than the rasterizer's vertex snapping of 1/256 pixel. The snapped
/// triangles put the pixel center on wedge 101's side of that line: `pw-restructured` counts
/// wedge 101's back-facing front face (+255, leaving the umbra); `pw2002` adds nothing: wedge
/// 100's entry face does not cover the pixel, and for wedge 101 its analytic f64 exit is the
/// left side plane (value 0 with `cancel`), not the front plane. Making them agree would mean
/// replacing the analytic exit search of Paper I §6 by the rasterizer's coverage test of the
/// exit faces, so the pixel is allowed rather than forced.
const GRAZING_PIXELS_ALLOWED: [(&str, usize); 2] = [("cylinder", 0), ("pw-columns", 1)];

/// Where `pw-restructured` and `pw2002` (`cancel`) build their umbra differently — the
/// outer-volume quad of degenerate wedges (Fig. 6) — their LI buffers differ, but only by
/// whole umbra steps: the penumbra contributions stay identical (64² `cube-of-spheres-sphere`:
/// 35 pixels differ, all by multiples of 255; see the light-spike note in `pw_restructured`).
#[test]
fn degenerate_wedges_change_only_whole_umbra_steps() {
    let scene = small("cube-of-spheres-sphere", 64);
    let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
    let mut w = wedge_settings(&frame);
    w.side_planes = pw2002::SidePlanes::Cancel;
    let a = li_pw2002(&frame, &w);
    let b = li_restructured(
        &frame,
        &restructured(w, WedgeTest::ZPass, Passes::Single, Culling::ZminZmax),
    );
    let diff: Vec<usize> = (0..a.len()).filter(|&i| a[i] != b[i]).collect();
    assert!(!diff.is_empty());
    for i in diff {
        assert_eq!((b[i] - a[i]) % 255, 0, "pixel {i}: {} vs {}", a[i], b[i]);
    }
}

#[test]
fn large_light_over_small_spheres_gives_degenerate_wedges() {
    let scene = small("cube-of-spheres-sphere", 32);
    let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
    let set = pw2002::frame_wedges(&frame, &wedge_settings(&frame)).unwrap();
    let degenerate = set
        .wedges
        .iter()
        .filter(|x| !x.front_face_is_quad())
        .count();
    assert!(degenerate > 0 && degenerate < set.wedges.len());
}

/// Absolute checks of the wedges `frame_wedges` builds, derived by hand (the bit-for-bit
/// agreement below is differential: both methods share `frame_wedges` and
/// `light_intensity`). `single-quad` under a sphere light of radius 0.3 at (0, 3, 0): seen
/// from the light center the 1×1 two-sided quad at y = 1 has four silhouette edges, its
/// border (each border edge joins a face towards the light and one away; the diagonals join
/// faces of one side), and so has the floor box (x, z ∈ [−3, 3], y ∈ [−0.1, 0]): its top
/// face is lit and its sides face away, so its top edges at y = 0. No corner is acute, so
/// there are exactly 8 wedges and no extra corner wedge (Paper I Fig. 7).
///
/// Planes (Paper I §4.1, the module's "Construction"): the front plane holds the edge and
/// `f = c − r·n`, the back plane the edge and `b' = c + r·n`, `n` the unit normal of the plane
/// through the edge and `c`. In the cross-section across the edge, `c` at the origin and the
/// edge's line at distance `D`, `f` is `r` from `c` perpendicular to the line's direction
/// from `c`, so the line through the edge and `f` lies `r·D/√(D² + r²)` from `c` — just inside
/// the sphere's tangent (`r`) for `D ≫ r`. By hand: `D² = 2² + ½² = 4.25` for the quad's
/// edges (0.2969), `3² + 3² = 18` for the floor's (0.29925). Both planes contain the edge's
/// ends, and they are different planes. Equations 1–3
/// themselves are checked on a hand-built wedge (`equations_1_to_3_on_hand_computed_points`).
#[test]
fn pw2002_front_and_back_planes_of_one_quad_by_hand() {
    let scene = with_sphere(small("single-quad", 32), 0.3);
    let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
    let w = wedge_settings(&frame);
    let set = pw2002::frame_wedges(&frame, &w).unwrap();
    assert_eq!(set.wedges.len(), 8, "one wedge per silhouette edge");
    let (c, r) = (w.wedge.center, w.wedge.radius);
    assert_eq!(c, DVec3::new(0.0, 3.0, 0.0));
    assert_eq!(r, f64::from(0.3f32), "the wedge radius is the light's here");
    for wedge in &set.wedges {
        assert!(!wedge.extra);
        // The edge is a border edge of the quad (y = 1, on x = ±½ or z = ±½) or of the floor's
        // top (y = 0, on x = ±3 or z = ±3).
        let half = if wedge.a.y == 1.0 { 0.5 } else { 3.0 };
        for e in [wedge.a, wedge.b] {
            assert_eq!(e.y, if half == 0.5 { 1.0 } else { 0.0 }, "{e}");
            assert_eq!(e.x.abs().max(e.z.abs()), half, "{e}");
        }
        let (front, back) = (wedge.plane(FaceKind::Front), wedge.plane(FaceKind::Back));
        for plane in [front, back] {
            for e in [wedge.a, wedge.b] {
                assert!(plane.eval(e).abs() < 1e-12, "{plane:?} misses {e}");
            }
            let d = plane.eval(c).abs();
            let dd = if half == 0.5 { 4.25 } else { 18.0 };
            let expected = r * libm::sqrt(dd) / libm::sqrt(dd + r * r);
            assert!(
                (d - expected).abs() < 1e-12,
                "{plane:?}: {d} from the light center, not {expected}"
            );
        }
        assert!(front.n.dot(back.n).abs() < 1.0 - 1e-3, "{front:?} {back:?}");
    }
}

#[test]
fn pw2002_and_restructured_agree_bit_for_bit_with_the_eye_outside_shadow() {
    for (name, allowed) in GRAZING_PIXELS_ALLOWED {
        let scene = small(name, 64);
        let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
        // Paper II §3 rests on the side-plane contributions cancelling (Paper I §5).
        let mut w = wedge_settings(&frame);
        w.side_planes = pw2002::SidePlanes::Cancel;
        let set = pw2002::frame_wedges(&frame, &w).unwrap();
        assert!(set.wedges.iter().all(|x| x.front_face_is_quad()), "{name}");
        let a = li_pw2002(&frame, &w);
        for passes in [Passes::Single, Passes::Three] {
            for culling in [Culling::Off, Culling::Zmax, Culling::ZminZmax] {
                let b =
                    li_restructured(&frame, &restructured(w, WedgeTest::ZPass, passes, culling));
                let diff: Vec<usize> = (0..a.len()).filter(|&i| a[i] != b[i]).collect();
                assert!(
                    diff.len() <= allowed,
                    "{name} {passes:?} {culling:?}: {} pixels differ, first {:?}",
                    diff.len(),
                    diff.first().map(|&i| (i, a[i], b[i]))
                );
            }
        }
    }
}

use penumbra::gpu::li_buffer::{LiFormat, LiOverflow};
use penumbra::methods::recorder::PassRecorder;
use penumbra::scene::LightShape;

fn mean_abs(a: &[f32], b: &[f32]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs() as f64)
        .sum::<f64>()
        / a.len() as f64
}

#[test]
fn zfail_is_right_in_eye_in_shadow_and_zpass_is_not() {
    let scene = with_sphere(small("eye-in-shadow", 40), 0.3);
    let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
    let (auto, _) = pw_restructured::read_settings(&frame).unwrap();
    assert_eq!(auto.test, WedgeTest::ZFail, "the plan must pick z-fail");
    let reference = gray(
        &penumbra::methods::run("raycast", &frame)
            .unwrap()
            .visibility,
    );
    let err = |test| {
        let s = RestructuredSettings { test, ..auto };
        let li = li_restructured(&frame, &s);
        let v = gray(&pw2002::resolve(&frame, &li).0);
        mean_abs(&v, &reference)
    };
    let (zfail, zpass) = (err(WedgeTest::ZFail), err(WedgeTest::ZPass));
    eprintln!("eye-in-shadow 40²: mean |Δ| vs raycast: z-fail {zfail}, z-pass {zpass}");
    // PIN (measured 0.0043 at 40², then margin; not derived): z-fail's mean error. pw-restructured
    // approximates the penumbra (Paper I's wedges), so no bound on it follows from the
    // arithmetic alone; the derived part of this test is the comparison with z-pass below.
    assert!(zfail < 0.03, "pin: z-fail mean error {zfail}");
    assert!(
        zpass > 5.0 * zfail && zpass > 0.1,
        "z-pass {zpass} vs z-fail {zfail}"
    );
    // pw2002 has no z-fail (Paper I): its result here is the z-pass one, and it says so.
    let warned = |frame: &Frame| {
        penumbra::methods::run("pw2002", frame)
            .unwrap()
            .stats
            .warnings
            .iter()
            .any(|w| w.contains("eye is in shadow"))
    };
    assert!(warned(&frame));
    let cylinder = small("cylinder", 16);
    let lit = Frame::render(&cylinder, GpuSettings::default()).unwrap();
    assert!(!warned(&lit));
}

/// Floor + the lowest `k` quads of `overlap-stress` under a small sphere light; returns the LI
/// value at a floor pixel that lies inside all k umbrae.
fn stacked_li(k: usize, li: LiFormat, overflow: LiOverflow) -> i32 {
    let mut scene = with_sphere(small("overlap-stress", 24), 0.02);
    scene.meshes.truncate(1 + k);
    let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
    let recv = frame.receivers();
    let px = recv
        .iter()
        .position(|r| {
            r.is_some_and(|r| {
                r.point.y.abs() < 1e-3
                    && r.point.x.abs() < 0.3
                    && r.point.z > 0.62
                    && r.point.z < 0.72
            })
        })
        .expect("a floor pixel in the common umbra");
    let mut w = wedge_settings(&frame);
    w.li = li;
    w.overflow = overflow;
    li_pw2002(&frame, &w)[px]
}

#[test]
fn overflow_first_wrong_pixel_is_pinned() {
    use LiFormat::*;
    use LiOverflow::*;
    // 16-bit: 129 overlapping umbrae fit (255 − 129·255 = −32640), the 130th wraps.
    assert_eq!(stacked_li(129, Li16, Wrap), -32640);
    assert_eq!(stacked_li(130, Li16, Wrap), 32641); // wrong: resolves to fully lit
    assert_eq!(stacked_li(130, Li16, Saturate), -32768); // still dark: saturation at the bottom is harmless here
                                                         // 8-bit stencil (unsigned): one umbra fits, the second wraps to 1.
    assert_eq!(stacked_li(1, Li8, Wrap), 0);
    assert_eq!(stacked_li(2, Li8, Wrap), 1);
    assert_eq!(stacked_li(2, Li8, Saturate), 0);
    // 12-bit: 9 fit (255 − 9·255 = −2040), the 10th wraps (−2295 + 4096).
    assert_eq!(stacked_li(9, Li12, Wrap), -2040);
    assert_eq!(stacked_li(10, Li12, Wrap), 1801);
    assert_eq!(stacked_li(10, Li12, Saturate), -2048);
}

/// The hard cases, before the resolve's clamp: the LI values stay in [0, 255] (the resolve
/// clamps nothing, `clamped_pixels` = 0) wherever the eye is lit and one convex occluder
/// casts the shadow — Paper I's sum of one silhouette's wedges over a full umbra step — and
/// leave it where the papers say they do: where shadows of different occluders overlap
/// (Paper I §7's 255/n sum, boxes of `pw-2002`, landscape folds of `pw-fractal`, columns,
/// two lights), and with the eye in shadow for `pw2002`, which has no z-fail (Paper II §5
/// adds it): 404 of 1024 pixels clamped there. The counts are pins measured at 32².
#[test]
fn hard_cases_clamp_only_where_the_papers_say() {
    // [pw2002, pw-restructured] per scene of `sphere_hard_cases::scenes`, in its order.
    let pinned: [[u64; 2]; 9] = [
        [0, 0],   // no umbra (light radius 1.5): one convex occluder
        [404, 0], // eye in shadow: pw2002 has no z-fail
        [53, 39], // pw-2002: overlapping boxes
        [27, 20], // pw-fractal: folds overlap
        [9, 9],   // pw-columns: overlapping column shadows
        [77, 69], // two lights in one LI buffer: both umbrae give 255 − 2·128 = −1
        [1, 0],   // acute corners: pw2002's corner wedges overlap at one pixel
        [0, 0],   // near-parallel edges: one convex occluder
        [0, 0],   // far from the origin: one convex occluder
    ];
    let scenes = sphere_hard_cases::scenes(32);
    assert_eq!(scenes.len(), pinned.len());
    for (scene, pin) in scenes.iter().zip(pinned) {
        let frame = Frame::render(scene, GpuSettings::default()).unwrap();
        for (m, expected) in ["pw2002", "pw-restructured"].into_iter().zip(pin) {
            let out = penumbra::methods::run(m, &frame).unwrap();
            assert!(gray(&out.visibility).iter().all(|x| x.is_finite()));
            assert_eq!(
                out.stats.clamped_pixels, expected,
                "{} {m}: pixels the resolve clamped",
                scene.source
            );
        }
    }
}

#[test]
fn wedge_faces_are_closed_and_contain_their_edge() {
    let scene = small("pw-columns", 32);
    let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
    let w = wedge_settings(&frame);
    let set = pw2002::frame_wedges(&frame, &w).unwrap();
    assert!(!set.wedges.is_empty());
    // The plane checks that ran (a side ray can leave the wedge before reaching a plane).
    let mut checked = [0usize; 2];
    for wedge in &set.wedges {
        // The edge midpoint lies on the front and back planes; a point just beyond the edge
        // along the light ray is inside.
        let mid = (wedge.a + wedge.b) * 0.5;
        let beyond = mid + (mid - w.wedge.center).normalize() * 0.01;
        assert!(
            wedge.contains(beyond),
            "point beyond the edge must be inside"
        );
        assert!(wedge.faces.len() >= 4);
        // Full light at the front plane, none at the back plane (equations 1–3): move from the
        // inside point along the left side direction onto each plane.
        for (k, (kind, expected)) in [(FaceKind::Front, 1.0), (FaceKind::Back, 0.0)]
            .into_iter()
            .enumerate()
        {
            let plane = wedge.plane(kind);
            let d = wedge.left_dir
                * -plane.eval(beyond).signum()
                * plane.n.dot(wedge.left_dir).signum();
            let on = beyond + d * plane.distance_along(beyond, wedge.left_dir);
            if !wedge.planes[2..].iter().all(|pl| pl.eval(on) <= 1e-9) {
                continue; // the side ray leaves the wedge through a side before the plane
            }
            let s = light_intensity(wedge, on, false);
            assert!((s - expected).abs() < 1e-9, "{kind:?}: s = {s}");
            checked[k] += 1;
        }
    }
    // PIN (measured: 148 wedges, both checks ran on all 148; a change in the wedges or in the
    // side rays changes it): how many of the front and back plane checks ran, so that the
    // `continue` above cannot skip them all.
    eprintln!(
        "{} wedges, front/back checks run {checked:?}",
        set.wedges.len()
    );
    assert_eq!(
        (set.wedges.len(), checked),
        (148, [148, 148]),
        "pin: wedges, checks run"
    );
}

/// A wedge built by hand: front plane z = 0, back plane z = 1 + x/2, left plane x = 0, right
/// plane x = 2 (outward normals), edge direction x, left side direction z and right side
/// direction (0.2, 0, 1) normalized.
fn hand_wedge() -> Wedge {
    let front = Plane::through(DVec3::ZERO, DVec3::new(0.0, 0.0, -1.0));
    let back = Plane::through(DVec3::new(0.0, 0.0, 1.0), DVec3::new(-0.5, 0.0, 1.0));
    let left = Plane::through(DVec3::ZERO, DVec3::new(-1.0, 0.0, 0.0));
    let right = Plane::through(DVec3::new(2.0, 0.0, 0.0), DVec3::X);
    let bottom = Plane::through(DVec3::new(0.0, -10.0, 0.0), DVec3::NEG_Y);
    Wedge {
        a: DVec3::ZERO,
        b: DVec3::new(2.0, 0.0, 0.0),
        dir: DVec3::X,
        n: DVec3::Y,
        extra: false,
        planes: [front, back, left, right, bottom],
        left_dir: DVec3::Z,
        right_dir: DVec3::new(0.2, 0.0, 1.0).normalize(),
        far_front: [DVec3::ZERO; 2],
        faces: Vec::new(),
    }
}

/// Paper I §4.2 equations 1–3 on hand-computed points of [`hand_wedge`]. At p = (0.5, 0, 0.25):
/// along the left direction z, t_lf = 0.25 and t_lb = (1 + 0.25) − 0.25 = 1, so
/// s_l = 1/1.25 = 0.8 (eq. 2); along the right direction r = (0.2, 0, 1)/k, k = √1.04, the
/// front plane is 0.25·k away and the back plane, whose normal is (−0.5, 0, 1)/√1.25, is
/// (1/√1.25)/((−0.1 + 1)/(k·√1.25)) = k/0.9 away, so s_r = (1/0.9)/(0.25 + 1/0.9) = 40/49;
/// along the edge direction x, t_l = 0.5 and t_r = 1.5, so (eq. 3)
/// s = (1.5·0.8 + 0.5·40/49)/2 = 0.6 + 10/49. On the front plane s = 1, on the back 0, and
/// with the smooth falloff 3s² − 2s³.
#[test]
fn equations_1_to_3_on_hand_computed_points() {
    let w = hand_wedge();
    let p = DVec3::new(0.5, 0.0, 0.25);
    let s = light_intensity(&w, p, false);
    let expected = 0.6 + 10.0 / 49.0;
    assert!((s - expected).abs() < 1e-12, "s = {s}, expected {expected}");
    let smooth = light_intensity(&w, p, true);
    assert!((smooth - expected * expected * (3.0 - 2.0 * expected)).abs() < 1e-12);
    // On the front plane (z = 0) and the back plane (z = 1 + x/2).
    assert!((light_intensity(&w, DVec3::new(0.7, 0.0, 0.0), false) - 1.0).abs() < 1e-12);
    assert!(light_intensity(&w, DVec3::new(0.4, 0.0, 1.2), false).abs() < 1e-12);
    // On the left plane only the left side value counts: t_lf = 0.5, t_lb = 1 − 0.5 → 0.5.
    assert!((light_intensity(&w, DVec3::new(0.0, 0.0, 0.5), false) - 0.5).abs() < 1e-12);
}

/// The light center of `frame`'s scene.
fn light_center(frame: &Frame) -> DVec3 {
    frame.scene.light().center.as_dvec3()
}

/// C0 continuity across adjacent wedges (Paper I §4.2: "since the side directions are shared
/// between adjacent wedges, this equation gives C0 light intensity continuity"): on the side
/// plane two consecutive wedges of a loop share, both give the same intensity, for points
/// sampled on that plane between the front and back planes of both. Tolerance 1e-9 (the
/// planes are built in f64 from the same vertices).
#[test]
fn adjacent_wedges_agree_on_their_shared_side_plane() {
    for name in ["cylinder", "pw-columns", "cube-of-spheres-sphere"] {
        let scene = small(name, 32);
        let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
        let set = pw2002::frame_wedges(&frame, &wedge_settings(&frame)).unwrap();
        let mut pairs = 0;
        let mut samples = 0;
        for k in &set.wedges {
            let right = k.plane(FaceKind::Right);
            for l in set
                .wedges
                .iter()
                .filter(|l| l.a == k.b && !l.extra && !k.extra)
            {
                let left = l.plane(FaceKind::Left);
                let same = (right.n + left.n).length() < 1e-12 && (right.d + left.d).abs() < 1e-12;
                if !same {
                    continue;
                }
                pairs += 1;
                // In the side plane: away from the light along the ray through the shared
                // vertex (projected into the plane), and across the penumbra along the side
                // direction.
                let ray = (k.b - light_center(&frame)).normalize();
                let along = (ray - right.n * right.n.dot(ray)).normalize();
                for i in 1..8 {
                    for j in -6..=6 {
                        let t = i as f64 * 0.1;
                        let q = k.b + along * t + k.right_dir * (j as f64 * 0.01 * t);
                        let between = |w: &Wedge| {
                            w.plane(FaceKind::Front).eval(q) < 0.0
                                && w.plane(FaceKind::Back).eval(q) < 0.0
                        };
                        if !(between(k) && between(l)) {
                            continue;
                        }
                        samples += 1;
                        let (sk, sl) = (light_intensity(k, q, false), light_intensity(l, q, false));
                        assert!((sk - sl).abs() < 1e-9, "{name}: {sk} vs {sl} at {q}");
                    }
                }
            }
        }
        assert!(
            pairs > 5 && samples > 20,
            "{name}: {pairs} pairs, {samples} samples"
        );
    }
}

fn parallel_corner_box(size: u32) -> Scene {
    let mut scene = small("eye-in-shadow", size);
    scene.meshes.truncate(1);
    scene.meshes.push(penumbra::scene::procedural::box_mesh(
        "box",
        glam::Vec3::new(0.0, 0.2, 2.0),
        glam::Vec3::new(0.5, 0.8, 2.5),
        [0.5; 3],
    ));
    scene.lights[0].center = glam::Vec3::new(-0.01, 4.0, 2.01);
    scene.lights[0].shape = LightShape::Sphere { radius: 0.2 };
    scene
}

#[test]
fn near_parallel_rule_removes_edges_and_without_it_wedges_degenerate() {
    use penumbra::geometry::penumbra_wedge::nearly_parallel;
    let scene = parallel_corner_box(32);
    let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
    let mut w = wedge_settings(&frame);
    let with_rule = pw2002::frame_wedges(&frame, &w).unwrap();
    w.wedge.parallel_rule = false;
    let without = pw2002::frame_wedges(&frame, &w).unwrap();
    assert!(with_rule.removed_parallel >= 1);
    assert_eq!(without.removed_parallel, 0);
    // Without the rule the vertical edge, almost along the light ray, gets a wedge whose
    // front and back planes are spanned by nearly parallel vectors, and the shadow changes.
    let c = w.wedge.center;
    assert!(without
        .wedges
        .iter()
        .any(|x| !x.extra && nearly_parallel(x.a, x.b, c)));
    assert!(with_rule
        .wedges
        .iter()
        .all(|x| x.extra || !nearly_parallel(x.a, x.b, c)));
    let on = li_pw2002(&frame, &wedge_settings(&frame));
    let off = li_pw2002(&frame, &w);
    assert_ne!(on, off);
}

/// The umbra surface `pw-restructured` rasterizes in z-fail (Paper II §5: top caps, front
/// planes — the outer-volume quad for degenerate wedges — and bottom caps) as clip-space
/// triangles, exactly as submitted.
fn zfail_umbra_surface(
    frame: &Frame,
    set: &penumbra::geometry::penumbra_wedge::WedgeSet,
) -> Vec<[ClipVertex; 3]> {
    use penumbra::geometry::penumbra_wedge::{cap_triangles, wedge_triangles, FaceKind};
    let mut tris: Vec<[ClipVertex; 3]> = cap_triangles(set, &frame.proj)
        .iter()
        .map(|t| t.clip)
        .collect();
    for t in wedge_triangles(set, &frame.proj) {
        let w = &set.wedges[t.wedge.unwrap() as usize];
        if t.kind == Some(FaceKind::Front) && w.front_face_is_quad() {
            tris.push(t.clip);
        }
    }
    for w in set.wedges.iter().filter(|w| !w.front_face_is_quad()) {
        tris.extend(
            w.umbra_front_quad()
                .map(|t| t.map(|p| frame.proj.clip_point(p.as_vec3()))),
        );
    }
    tris
}

/// Directed edges of the closed polygons `polys` not cancelled by the same edge in the
/// opposite direction (vertices compared by their bits through `K`): none for a closed,
/// consistently oriented surface.
fn unmatched_edges<K: Ord + Copy>(polys: impl Iterator<Item = Vec<K>>) -> usize {
    let mut count: BTreeMap<(K, K), i32> = BTreeMap::new();
    for poly in polys {
        for i in 0..poly.len() {
            let (u, v) = (poly[i], poly[(i + 1) % poly.len()]);
            match u.cmp(&v) {
                Ordering::Less => *count.entry((u, v)).or_default() += 1,
                Ordering::Greater => *count.entry((v, u)).or_default() -= 1,
                Ordering::Equal => {}
            }
        }
    }
    count.values().filter(|c| **c != 0).count()
}

/// Directed edges of `tris` not cancelled by the reverse edge (bit-identical clip-space
/// vertices).
fn open_edges(tris: &[[ClipVertex; 3]]) -> usize {
    unmatched_edges(
        tris.iter()
            .map(|t| t.iter().map(|v| v.0.map(f32::to_bits)).collect()),
    )
}

/// Paper II §5: z-fail needs the umbra surface (top caps, front planes, bottom caps) closed.
/// The near-parallel rule (Paper I §8) moves loop vertices to midpoints, off the top caps'
/// boundary; without the patch triangles it adds to the top caps the surface has holes there
/// (z-fail then differs from z-pass at 114 pixels of a 64² render of `parallel_corner_box`,
/// LI off by up to 255, in streaks).
#[test]
fn zfail_umbra_surface_is_closed_also_where_the_parallel_rule_moves_vertices() {
    let mut scenes: Vec<Scene> = ["cylinder", "pw-columns", "pw-2002", "pw-fractal"]
        .iter()
        .map(|n| small(n, 32))
        .collect();
    scenes.push(small("cube-of-spheres-sphere", 32));
    scenes.push(parallel_corner_box(32));
    for scene in scenes {
        let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
        let set = pw2002::frame_wedges(&frame, &wedge_settings(&frame)).unwrap();
        assert_eq!(
            open_edges(&zfail_umbra_surface(&frame, &set)),
            0,
            "{}: {} edges removed by the parallel rule",
            scene.source,
            set.removed_parallel
        );
    }
}

/// With the eye lit and the umbra surface closed, z-pass and z-fail count the same umbra
/// crossings; on `parallel_corner_box` (where the near-parallel rule fires) they also agree on
/// every penumbra contribution, so the LI buffers are equal bit for bit.
///
/// They are not equal everywhere on the lit-eye built-ins (default `pw-restructured` settings;
/// 64²: 1 pixel of `cylinder`, 1 of `pw-2002`, 1 of `pw-fractal`, 2 of
/// `cube-of-spheres-sphere`, none of `pw-columns`; 256²: `cylinder` 1, `pw-2002` 3,
/// `pw-fractal` 29, `cube-of-spheres-sphere` 11, `pw-columns` 3). Every one of these 47
/// pixels has its receiver point (un-projected stored depth) within one D24 step (the world
/// distance from stored depth d to d + 1 along the pixel's ray) of the boundary of some wedge
/// (the largest of its five signed plane distances is below one step in magnitude), against 0
/// to 6 of 300 sampled receiver pixels per scene; single pixels traced show the cause:
/// * **Depth ties.** The receiver point p lies within about one D24 step of a wedge face,
///   where the depth test of the rasterized face (its interpolated f32 depth, quantized,
///   against the stored depth) and the world-space inside test of the penumbra (at the
///   un-projected stored depth, f64) disagree about which side of the face p is on; z-pass
///   tests the faces in front of p and z-fail those behind it, so they resolve the tie from
///   opposite sides. `cylinder` 64² pixel (14, 33): p at ray parameter 318.0756 lies in
///   wedge 18 just past the side plane it shares with wedge 19 (318.0635); the entry face's
///   fragment quantizes to the stored depth and fails LESS, so z-pass (like `pw2002`) adds
///   the penumbra of neither wedge (LI 0, `raycast` 0.84) while z-fail adds wedge 18's
///   (LI 194). `pw-fractal` 256² pixel (178, 112): p lies in wedge 357 0.0022 before it leaves
///   through its front plane (372.3636 against 372.3658); z-pass adds the penumbra (+255,
///   s = 1) and, because the front face's fragment passes LESS, also the umbra exit (+255),
///   z-fail neither.
///
/// A second cause is fixed: wedges not bounded by their bottom plane or empty (5 corner wedges
/// of `pw-fractal`, 4 wedges of `pw-2002`), whose faces did not enclose the points the inside
/// test accepts; their side planes now fall back to planes through the light ray
/// (`every_wedge_is_bounded_and_closed_by_its_faces`). Before that fix the counts were 64²:
/// `pw-fractal` 2; 256²: `pw-2002` 8, `pw-fractal` 43; the others unchanged.
#[test]
fn zpass_and_zfail_agree_where_the_parallel_rule_fires() {
    let scene = parallel_corner_box(64);
    let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
    let w = wedge_settings(&frame);
    assert!(pw2002::frame_wedges(&frame, &w).unwrap().removed_parallel >= 1);
    for passes in [Passes::Single, Passes::Three] {
        let li = |test| li_restructured(&frame, &restructured(w, test, passes, Culling::ZminZmax));
        let (a, b) = (li(WedgeTest::ZPass), li(WedgeTest::ZFail));
        let diff = (0..a.len()).filter(|&i| a[i] != b[i]).count();
        assert_eq!(diff, 0, "{passes:?}: {diff} pixels differ");
    }
}

/// Solid angle of triangle (a, b, c) seen from the origin (Van Oosterom & Strackee 1983),
/// signed positive when the triangle is counter-clockwise seen from outside a surface that
/// encloses the origin.
fn solid_angle(a: glam::DVec3, b: glam::DVec3, c: glam::DVec3) -> f64 {
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let num = a.dot(b.cross(c));
    let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * libm::atan2(num, den)
}

/// The winding number of the face polygons of `w` around `p`: 1 inside, 0 outside for a closed,
/// outward-oriented polyhedron; fractional if the faces leave holes.
fn face_winding(w: &penumbra::geometry::penumbra_wedge::Wedge, p: glam::DVec3) -> f64 {
    let mut total = 0.0;
    for (_, poly) in &w.faces {
        for i in 1..poly.len() - 1 {
            total += solid_angle(poly[0] - p, poly[i] - p, poly[i + 1] - p);
        }
    }
    total / (4.0 * std::f64::consts::PI)
}

/// Directed face edges of `w` not matched by the reverse edge of another face (bit-identical
/// vertices): none when the faces close a polyhedron.
fn open_face_edges(w: &penumbra::geometry::penumbra_wedge::Wedge) -> usize {
    unmatched_edges(w.faces.iter().map(|(_, poly)| {
        poly.iter()
            .map(|v| v.to_array().map(f64::to_bits))
            .collect()
    }))
}

/// Every wedge of every sphere-light built-in is a bounded convex region whose face polygons
/// close it (Paper I §4.1: front, back, two side planes; Paper II §5: the bottom plane caps it):
/// every face edge is matched by the reverse edge of another face, and `contains` agrees with
/// the faces' winding number at sample points (the edge's light rays near and far, the
/// vertex centroid, and points scattered around the wedge), so the faces the methods rasterize
/// enclose exactly the points whose penumbra they add. With one light, every front line also
/// leaves its vertex within `FRONT_LINE_CONE` angular radii of the light ray (Paper I §8:
/// nearly parallel front planes do not define a side plane).
#[test]
fn every_wedge_is_bounded_and_closed_by_its_faces() {
    use penumbra::geometry::penumbra_wedge::FRONT_LINE_CONE;
    let mut failures = Vec::new();
    for name in [
        "cylinder",
        "cube-of-spheres-sphere",
        "pw-columns",
        "pw-fractal",
        "pw-2002",
        "two-lights",
    ] {
        let scene = small(name, 32);
        let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
        let ws = wedge_settings(&frame);
        let set = pw2002::frame_wedges(&frame, &ws).unwrap();
        if set.open_wedges != 0 {
            failures.push(format!("{name}: {} open wedges reported", set.open_wedges));
        }
        if scene.lights.len() == 1 {
            let (c, r) = (ws.wedge.center, ws.wedge.radius);
            for (i, w) in set.wedges.iter().enumerate() {
                let u = w.b - c;
                let cone = FRONT_LINE_CONE * libm::asin(r / u.length());
                let off = libm::acos((w.far_front[1] - w.b).normalize().dot(u.normalize()));
                if off > cone * (1.0 + 1e-9) {
                    failures.push(format!(
                        "{name} wedge {i}: front line {off} rad off the ray"
                    ));
                }
            }
        }
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for (i, w) in set.wedges.iter().enumerate() {
            let open = open_face_edges(w);
            if w.faces.len() < 4 || open > 0 {
                failures.push(format!(
                    "{name} wedge {i} (extra {}): {} faces, {open} open edges",
                    w.extra,
                    w.faces.len()
                ));
                continue;
            }
            let verts: Vec<glam::DVec3> = w.faces.iter().flat_map(|f| f.1.clone()).collect();
            let centroid = verts.iter().copied().sum::<glam::DVec3>() / verts.len() as f64;
            // Along the light rays through the edge: toward the far points of the front lines.
            let mid = (w.a + w.b) * 0.5;
            let far_mid = (w.far_front[0] + w.far_front[1]) * 0.5;
            let (ray, far) = ((far_mid - mid).normalize(), (far_mid - mid).length());
            let mut samples = vec![centroid];
            for t in [0.01, 0.1, 1.0, 0.25 * far, 0.9 * far, 2.0 * far, 10.0 * far] {
                samples.push(mid + ray * t);
                samples.push(mid + (ray + w.n * 0.2) * t);
                samples.push(mid + (ray - w.n * 0.2) * t);
            }
            for _ in 0..200 {
                let d = glam::DVec3::new(rnd(), rnd(), rnd());
                samples.push(centroid + d * (rnd().abs() * 3.0 * far));
            }
            for p in samples {
                // Points on a plane (within rounding) may go either way.
                if w.planes.iter().any(|pl| pl.eval(p).abs() < 1e-9 * far) {
                    continue;
                }
                let winding = face_winding(w, p);
                let inside = winding > 0.5;
                if (winding - winding.round()).abs() > 1e-6 || inside != w.contains(p) {
                    failures.push(format!(
                        "{name} wedge {i}: contains({p:?}) = {}, face winding {winding}",
                        w.contains(p)
                    ));
                    break;
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// Tiny sphere lights (`scenes/hard/tiny-sphere-light.toml`, radius 1e-6, and the same scene
/// at 1e-30): the wedges are built with at least `MIN_RELATIVE_RADIUS` of the light's distance,
/// so both penumbra-wedge methods give the hard shadow the reference sees (mean error below
/// 1/255; before, pw2002 had 0.62). And a light under the floor
/// (`scenes/hard/light-below-floor.toml`): the eye is in the floor's shadow, pw-restructured's
/// z-fail agrees with the reference, pw2002 (no z-fail) warns.
#[test]
fn tiny_lights_and_a_light_below_the_floor() {
    let load = |name: &str| {
        penumbra::scene::file::resolve(&format!(
            "{}/scenes/hard/{name}",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap()
    };
    let mean_error = |scene: &Scene, m: &str| {
        let frame = Frame::render(scene, GpuSettings::default()).unwrap();
        let reference = gray(
            &penumbra::methods::run("raycast", &frame)
                .unwrap()
                .visibility,
        );
        let out = penumbra::methods::run(m, &frame).unwrap();
        (
            mean_abs(&gray(&out.visibility), &reference),
            out.stats.warnings,
        )
    };
    let mut tiny = load("tiny-sphere-light.toml");
    for radius in [1e-6f32, 1e-30] {
        tiny.lights[0].shape = penumbra::scene::LightShape::Sphere { radius };
        for m in ["pw2002", "pw-restructured"] {
            let (e, _) = mean_error(&tiny, m);
            assert!(e < 1.0 / 255.0, "radius {radius} {m}: mean error {e}");
        }
    }
    let below = load("light-below-floor.toml");
    let (e, _) = mean_error(&below, "pw-restructured");
    assert!(e < 1.0 / 255.0, "pw-restructured mean error {e}");
    let (_, warnings) = mean_error(&below, "pw2002");
    assert!(warnings.iter().any(|w| w.contains("eye is in shadow")));
}
