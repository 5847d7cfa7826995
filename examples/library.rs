//! penumbra as a library, through the crate-root API only (`src/lib.rs`, "The library's
//! API"): load a scene (a built-in name or a scene file), choose methods, render them against
//! the ray-cast reference, and read each method's visibility, error, passes and buffers.
//!
//! ```sh
//! cargo run --release --example library                       # cube-of-spheres, 96×96
//! cargo run --release --example library -- scenes/real/bob.toml ssv hard-sv
//! ```
//!
//! The first argument is the scene (default `cube-of-spheres`), the others the methods
//! (default `hard-sv`, `ssv` and `wedge-blending`); `raycast`, the reference, is always added
//! so that every method has an error. A bad argument prints the library's error, exit code 2.

use std::process::ExitCode;

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn run() -> Result<(), penumbra::InputError> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut scene = penumbra::load_scene(args.first().map_or("cube-of-spheres", String::as_str))?;
    scene.resize(Some(96), Some(96));
    let mut methods = vec!["raycast".to_string()];
    match args.get(1..) {
        Some(chosen) if !chosen.is_empty() => methods.extend(chosen.iter().cloned()),
        _ => methods.extend(["hard-sv", "ssv", "wedge-blending"].map(String::from)),
    }
    if let Some(unknown) = methods
        .iter()
        .find(|m| !penumbra::method_names().any(|n| n == m.as_str()))
    {
        let known: Vec<&str> = penumbra::method_names().collect();
        return Err(penumbra::InputError::new(
            unknown.as_str(),
            format!("unknown method (known: {})", known.join(", ")),
        ));
    }
    scene.methods = Some(methods);

    let runs = penumbra::render_scene(&scene)?;
    println!("{}: {}×{}", scene.source, scene.width, scene.height);
    for run in &runs {
        let stats = &run.output.stats;
        let shadowed = (0..run.output.visibility.len())
            .filter(|&i| run.output.visibility.gray(i) < 1.0)
            .count();
        let error = run.error.as_ref().map_or("reference".to_string(), |e| {
            format!(
                "mean |e| {:.4} (penumbra {:.4})",
                e.all.mean_abs, e.penumbra_only.mean_abs
            )
        });
        println!(
            "{:>15}  {:>6} shadowed px  {:>9} fragments shaded  {error}",
            run.method, shadowed, stats.totals.fragments_shaded
        );
        for pass in &stats.passes {
            println!(
                "{:>17}{} ×{}: {} triangles rasterized",
                "", pass.name, pass.runs, pass.counters.triangles_rasterized
            );
        }
        for warning in &stats.warnings {
            println!("{:>17}warning: {warning}", "");
        }
    }
    Ok(())
}
