//! Thread-count independence of the penumbra-wedge methods, including the three-pass variant
//! (their goldens are in the catalog of `penumbra::golden::cases`).

use penumbra::frame::{Frame, GpuSettings};
use penumbra::scene::{builtin, OptionValue};

const METHODS: [&str; 2] = ["pw2002", "pw-restructured"];

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
