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
    let (t, _) = pw_restructured::render_li(frame, &set, s);
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

#[test]
fn pw2002_and_restructured_agree_bit_for_bit_with_the_eye_outside_shadow() {
    for name in ["cylinder"] {
        let scene = small(name, 96);
        let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
        let w = wedge_settings(&frame);
        let a = li_pw2002(&frame, &w);
        for passes in [Passes::Single, Passes::Three] {
            for culling in [Culling::Off, Culling::Zmax, Culling::ZminZmax] {
                let b =
                    li_restructured(&frame, &restructured(w, WedgeTest::ZPass, passes, culling));
                let diff: Vec<usize> = (0..a.len()).filter(|&i| a[i] != b[i]).collect();
                assert!(
                    diff.is_empty(),
                    "{name} {passes:?} {culling:?}: {} pixels differ, first {:?}",
                    diff.len(),
                    diff.first().map(|&i| (i, a[i], b[i]))
                );
            }
        }
    }
}
