//! Penumbra wedges (Paper I) and the restructured algorithm (Paper II): equality of the LI
//! buffers, z-fail, overflow, construction invariants and hard cases.

use penumbra::frame::{Frame, GpuSettings};
use penumbra::methods::pw2002::{self, WedgeSettings};
use penumbra::methods::pw_restructured::{self, Culling, Passes, RestructuredSettings, WedgeTest};
use penumbra::scene::{builtin, Scene};

fn small(name: &str, size: u32) -> Scene {
    let mut s = builtin::load(name).expect("built-in scene");
    s.width = size;
    s.height = size;
    s
}

fn wedge_settings(frame: &Frame) -> WedgeSettings {
    let mut r = penumbra::methods::options::OptionReader::new(frame.scene, "pw2002");
    pw2002::read_wedge_settings(&mut r, frame).expect("settings")
}

fn li_pw2002(frame: &Frame, s: &WedgeSettings) -> Vec<i32> {
    let set = pw2002::frame_wedges(frame, s).expect("wedges");
    let (t, _) = pw2002::render_li(frame, &set, s);
    pw2002::li_row_major(frame, &t)
}

fn li_restructured(frame: &Frame, s: &RestructuredSettings) -> Vec<i32> {
    let set = pw2002::frame_wedges(frame, &s.wedge).expect("wedges");
    let (t, _, _) = pw_restructured::render_li(frame, &set, s);
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
/// faces meet. There `pw2002` finds the exit plane analytically in f64 while
/// `pw-restructured` sees whether the snapped, fixed-point triangle of the neighbouring face
/// covers the pixel center; both are exact for their own representation but can disagree by
/// one umbra step. Everywhere else the two add the same integers (same wedges, same
/// `light_intensity`, same `li_amount`). The equality needs the same wedges in both: scenes
/// with degenerate wedges (Fig. 6), whose umbra `pw-restructured` draws with the outer-volume
/// quad instead, are excluded — `cube-of-spheres-sphere` has them (asserted below).
const GRAZING_PIXELS_ALLOWED: [(&str, usize); 2] = [("cylinder", 0), ("pw-columns", 1)];

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
use penumbra::methods::output::Visibility;
use penumbra::scene::LightShape;

fn gray(v: &Visibility) -> Vec<f32> {
    match v {
        Visibility::Gray(g) => g.clone(),
        Visibility::Rgb(_) => panic!("gray expected"),
    }
}

fn mean_abs(a: &[f32], b: &[f32]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs() as f64)
        .sum::<f64>()
        / a.len() as f64
}

fn with_sphere(mut s: Scene, r: f32) -> Scene {
    s.lights[0].shape = LightShape::Sphere { radius: r };
    s
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
        let v = gray(&pw2002::resolve(&frame, &li));
        mean_abs(&v, &reference)
    };
    let (zfail, zpass) = (err(WedgeTest::ZFail), err(WedgeTest::ZPass));
    assert!(zfail < 0.03, "z-fail mean error {zfail}");
    assert!(
        zpass > 5.0 * zfail && zpass > 0.1,
        "z-pass {zpass} vs z-fail {zfail}"
    );
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

/// Hard cases of DESIGN.md that apply to spheres: a light so large there is no umbra, an
/// occluder touching the receiver, silhouette edges nearly parallel to the light direction,
/// acute corners, eye in shadow, geometry far from the origin.
fn hard_cases() -> Vec<Scene> {
    let mut v = vec![
        with_sphere(small("single-quad", 32), 1.5),   // no umbra
        with_sphere(small("eye-in-shadow", 32), 0.3), // eye inside shadow
        small("pw-2002", 32),                         // overlapping boxes
        small("pw-fractal", 32),                      // zigzag silhouettes, high vertex degrees
        small("pw-columns", 32),                      // contact: columns stand on the floor
    ];
    // Edges nearly parallel to the light: the cylinder's vertical edges under a light almost
    // straight above its rim.
    let mut s = small("cylinder", 32);
    s.lights[0].center = glam::Vec3::new(0.35, 3.2, 0.0);
    v.push(s);
    // Far from the origin (depth precision).
    let mut s = small("cylinder", 32);
    let off = glam::Vec3::new(1000.0, 0.0, -1000.0);
    for m in &mut s.meshes {
        for p in &mut m.positions {
            *p += off;
        }
    }
    s.lights[0].center += off;
    s.camera.eye += off.as_dvec3();
    s.camera.target += off.as_dvec3();
    v.push(s);
    v
}

#[test]
fn hard_cases_give_finite_visibility_in_range() {
    for scene in hard_cases() {
        let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
        for m in ["pw2002", "pw-restructured"] {
            let v = gray(&penumbra::methods::run(m, &frame).unwrap().visibility);
            assert!(
                v.iter().all(|x| x.is_finite() && (0.0..=1.0).contains(x)),
                "{} {m}",
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
        // Full light at the front plane, none at the back plane (equations 1-3).
        let s = penumbra::geometry::penumbra_wedge::light_intensity(wedge, beyond, false);
        assert!((0.0..=1.0).contains(&s));
    }
}

#[test]
fn near_parallel_rule_removes_edges_and_without_it_wedges_degenerate() {
    use penumbra::geometry::penumbra_wedge::nearly_parallel;
    // A box whose vertical edges point straight at the light: light directly above a corner.
    let mut scene = small("eye-in-shadow", 32);
    scene.meshes.truncate(1);
    scene.meshes.push(penumbra::scene::procedural::box_mesh(
        "box",
        glam::Vec3::new(0.0, 0.2, 2.0),
        glam::Vec3::new(0.5, 0.8, 2.5),
        [0.5; 3],
    ));
    scene.lights[0].center = glam::Vec3::new(-0.01, 4.0, 2.01);
    scene.lights[0].shape = LightShape::Sphere { radius: 0.2 };
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
