//! Measures every method on the built-in `cube-of-spheres` scene at 512×512: `raycast` (the
//! reference, default 1024 samples), `nsample` with `n = 1024` and `hard-sv`.
//!
//! Prints, per method, its wall time and a JSON table of its passes (name, wall seconds, runs
//! and all counters) and totals, then the error table of [`penumbra::render::table`].
//!
//! ```sh
//! cargo run --release --example measure > docs/measurements-512.txt
//! ```
//!
//! Times are informational (they depend on the machine and its load); counters and errors are
//! deterministic.

use penumbra::render::{render_scene, table};
use penumbra::scene::{builtin, OptionValue};
use serde_json::json;
use std::process::ExitCode;

/// The measured scene.
const SCENE: &str = "cube-of-spheres";
/// Image width and height in pixels.
const SIZE: u32 = 512;
/// `nsample`'s sample count (the papers' 1024-sample reference).
const NSAMPLE_N: i64 = 1024;

/// Renders the scene with every method and prints the per-method stats and the error table.
fn main() -> ExitCode {
    let mut scene = builtin::load(SCENE).expect("built-in scene cube-of-spheres");
    scene.width = SIZE;
    scene.height = SIZE;
    scene.methods = Some(vec!["raycast".into(), "nsample".into(), "hard-sv".into()]);
    scene
        .options
        .entry("nsample".into())
        .or_default()
        .insert("n".into(), OptionValue::Int(NSAMPLE_N));

    let threads = rayon::current_num_threads();
    println!("{SCENE} at {SIZE}×{SIZE}, nsample.n = {NSAMPLE_N}, {threads} rayon threads");
    let runs = match render_scene(&scene) {
        Ok(runs) => runs,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::from(2);
        }
    };

    for run in &runs {
        let stats = &run.output.stats;
        println!();
        println!("== {}: {:.3} s", run.method, stats.wall_seconds);
        let table = json!({
            "method": stats.method,
            "wall_seconds": stats.wall_seconds,
            "passes": stats.passes,
            "totals": stats.totals,
            "total_bytes": stats.totals.total_bytes(),
        });
        println!(
            "{}",
            serde_json::to_string_pretty(&table).expect("stats serialize to JSON")
        );
    }
    println!();
    print!("{}", table(&scene, &runs));
    ExitCode::SUCCESS
}
