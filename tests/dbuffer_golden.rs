//! Goldens of `dbuffer` on the disk-light built-ins, 64×64, bit for bit (see
//! `penumbra::golden::check`): the defaults (`falloff = smoothstep`, `storage = f32`) on every
//! disk scene, and on `disk-block` and `disk-small-sphere` the variants `falloff = sqrt`,
//! `storage = f16` and `eq3 = printed`, so that a change of the volumes, of the D-buffer's
//! draws and their channel formats, or of the screen program shows.

use penumbra::frame::{Frame, GpuSettings};
use penumbra::scene::{builtin, OptionValue, Scene};
use std::path::Path;

fn scene(name: &str, options: &[(&str, &str)]) -> Scene {
    let mut s = builtin::load(name).unwrap();
    s.width = 64;
    s.height = 64;
    let table = s.options.entry("dbuffer".into()).or_default();
    for (k, v) in options {
        table.insert(k.to_string(), OptionValue::Str(v.to_string()));
    }
    s
}

#[test]
fn dbuffer_goldens_match() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("golden");
    let mut cases: Vec<(&str, String, Scene)> = [
        "disk-block",
        "disk-slab",
        "disk-small-sphere",
        "disk-acute",
        "disk-torus",
    ]
    .into_iter()
    .map(|n| (n, "dbuffer".to_string(), scene(n, &[])))
    .collect();
    for name in ["disk-block", "disk-small-sphere"] {
        for (dir, key, value) in [
            ("dbuffer-sqrt", "falloff", "sqrt"),
            ("dbuffer-f16", "storage", "f16"),
            ("dbuffer-printed", "eq3", "printed"),
        ] {
            cases.push((name, dir.to_string(), scene(name, &[(key, value)])));
        }
    }
    let mut failures = Vec::new();
    for (name, dir, s) in &cases {
        let frame = Frame::render(s, GpuSettings::default()).unwrap();
        let out = penumbra::methods::run("dbuffer", &frame).unwrap();
        if let Err(e) = penumbra::golden::check(&root, name, dir, 64, 64, &out) {
            failures.push(format!("{name}/{dir}: {e}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
