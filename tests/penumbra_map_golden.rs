//! Goldens of `penumbra-map` on the sphere-light built-ins (the foundation golden cases hold
//! `cylinder` and `two-lights`), 64×64, bit for bit (see `penumbra::golden::check`): the
//! default settings on `cube-of-spheres-sphere` and the Paper II scene analogues, and
//! `pw-columns` at two map sizes (32² and 128²: coarser and finer than the image) in two
//! storage formats (unorm8, the default, and f32), so that a change of the light view, the
//! rasterization of the cones and sheets, the darkest-wins depth channel or the colour
//! quantization shows.

use penumbra::frame::{Frame, GpuSettings};
use penumbra::scene::{builtin, OptionValue, Scene};
use std::path::Path;

fn scene(name: &str, options: &[(&str, OptionValue)]) -> Scene {
    let mut s = builtin::load(name).unwrap();
    s.width = 64;
    s.height = 64;
    let table = s.options.entry("penumbra-map".into()).or_default();
    for (k, v) in options {
        table.insert(k.to_string(), v.clone());
    }
    s
}

#[test]
fn penumbra_map_goldens_match() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("golden");
    let mut cases: Vec<(&str, String, Scene)> = [
        "cube-of-spheres-sphere",
        "pw-columns",
        "pw-fractal",
        "pw-2002",
    ]
    .into_iter()
    .map(|n| (n, "penumbra-map".to_string(), scene(n, &[])))
    .collect();
    for map_size in [32, 128] {
        for storage in ["unorm8", "f32"] {
            let options = [
                ("map_size", OptionValue::Int(map_size)),
                ("storage", OptionValue::Str(storage.into())),
            ];
            cases.push((
                "pw-columns",
                format!("penumbra-map-map{map_size}-{storage}"),
                scene("pw-columns", &options),
            ));
        }
    }
    let mut failures = Vec::new();
    for (name, dir, s) in &cases {
        let frame = Frame::render(s, GpuSettings::default()).unwrap();
        let out = penumbra::methods::run("penumbra-map", &frame).unwrap();
        if let Err(e) = penumbra::golden::check(&root, name, dir, 64, 64, &out) {
            failures.push(format!("{name}/{dir}: {e}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
