//! Goldens of `wedge-blending` beyond the foundation cases (which pin the packed default on
//! `cube-of-spheres`, `single-quad` and `eye-in-shadow`): the unpacked variant and the knobs
//! that change the arithmetic, on the paper's scene `forest-spheres` and on `cube-of-spheres`,
//! 64×64, bit for bit (see `penumbra::golden::check`). Each variant is stored under
//! `golden/<scene>/wedge-blending-<variant>/`.

use penumbra::frame::{Frame, GpuSettings};
use penumbra::scene::{builtin, OptionValue};
use std::path::Path;

/// `[options.wedge-blending]` of one case.
type Options = &'static [(&'static str, &'static str)];

/// (scene, variant name, options).
const CASES: &[(&str, &str, Options)] = &[
    ("forest-spheres", "packed", &[]),
    ("forest-spheres", "f32", &[("packing", "f32")]),
    ("cube-of-spheres", "f32", &[("packing", "f32")]),
    ("cube-of-spheres", "centroid", &[("centroid", "on")]),
    ("cube-of-spheres", "adjust-always", &[("adjust", "always")]),
    ("cube-of-spheres", "reverse", &[("order", "reverse")]),
    (
        "cube-of-spheres",
        "flush-denormals",
        &[("target", "flush-denormals")],
    ),
];

#[test]
fn wedge_blending_goldens_match() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("golden");
    let bless = std::env::var(penumbra::golden::BLESS_ENV).is_ok_and(|v| v == "1");
    let mut failures = Vec::new();
    for (name, variant, opts) in CASES {
        let mut scene = builtin::load(name).unwrap();
        scene.width = 64;
        scene.height = 64;
        let table = scene.options.entry("wedge-blending".into()).or_default();
        for (k, v) in *opts {
            table.insert(k.to_string(), OptionValue::Str(v.to_string()));
        }
        let frame = Frame::render(&scene, GpuSettings::default()).unwrap();
        let out = penumbra::methods::run("wedge-blending", &frame).unwrap();
        let dir = format!("wedge-blending-{variant}");
        let result = if bless {
            penumbra::golden::bless(&root, name, &dir, &out).map(drop)
        } else {
            penumbra::golden::check(&root, name, &dir, 64, 64, &out)
        };
        if let Err(e) = result {
            failures.push(format!("{name}/{dir}: {e}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
