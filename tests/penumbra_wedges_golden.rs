//! Goldens of the penumbra-wedge methods on the sphere-light built-ins (the foundation golden
//! cases hold only one sphere-light scene, `cylinder`): `cube-of-spheres-sphere` and the
//! Paper II scene analogues, 64×64, bit for bit (see `penumbra::golden::check`), plus a
//! thread-count independence check of both methods including the three-pass variant.

use penumbra::frame::{Frame, GpuSettings};
use penumbra::scene::{builtin, OptionValue};
use std::path::Path;

const SCENES: [&str; 4] = [
    "cube-of-spheres-sphere",
    "pw-columns",
    "pw-fractal",
    "pw-2002",
];
const METHODS: [&str; 2] = ["pw2002", "pw-restructured"];

#[test]
fn penumbra_wedge_goldens_match() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("golden");
    let mut failures = Vec::new();
    for name in SCENES {
        let mut scene = builtin::load(name).unwrap();
        scene.width = 64;
        scene.height = 64;
        let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
        for m in METHODS {
            let out = penumbra::methods::run(m, &frame).unwrap();
            if let Err(e) = penumbra::golden::check(&root, name, m, 64, 64, &out) {
                failures.push(format!("{name}/{m}: {e}"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn penumbra_wedges_do_not_depend_on_thread_count() {
    let mut scene = builtin::load("pw-2002").unwrap();
    scene.width = 48;
    scene.height = 48;
    scene
        .options
        .entry("pw-restructured".into())
        .or_default()
        .insert("passes".into(), OptionValue::Str("three".into()));
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
            METHODS.map(|m| penumbra::methods::run(m, &frame).unwrap().visibility)
        })
    };
    assert_eq!(run(1), run(3));
}
