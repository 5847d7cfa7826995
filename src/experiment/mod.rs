//! Experiments that sweep a parameter and report counters (`docs/architecture.md`
//! "Experiments and reports": sweeps, CSV, summaries, plots).

pub mod accuracy_time;
pub mod cost_growth;
pub mod panels;
pub mod plotting;
pub mod precision;
pub mod tile_size;
pub mod wedge_blending;

use crate::scene::{OptionValue, Scene};

/// Where `experiment tile-size` and `experiment wedge-blending` write by default.
pub const DEFAULT_OUT: &str = "out/experiment";

/// `scene` with `method`'s options `knobs` set on top of its own `[options.METHOD]` table,
/// each value read as `--opt METHOD.KEY=VALUE` reads it ([`OptionValue::parse_cli`]).
pub fn configured(scene: &Scene, method: &str, knobs: &[(&str, &str)]) -> Scene {
    let mut s = scene.clone();
    let table = s.options.entry(method.to_string()).or_default();
    for (k, v) in knobs {
        table.insert(k.to_string(), OptionValue::parse_cli(v));
    }
    s
}

/// `scene` rendered at `size`×`size` pixels.
pub fn sized(mut scene: Scene, size: u32) -> Scene {
    scene.width = size;
    scene.height = size;
    scene
}

/// Median, min and max of `samples` (at least one; the median of an even count is the upper
/// middle one).
pub fn spread(mut samples: Vec<f64>) -> (f64, f64, f64) {
    samples.sort_by(f64::total_cmp);
    (
        samples[samples.len() / 2],
        samples[0],
        samples[samples.len() - 1],
    )
}
