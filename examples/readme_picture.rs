//! Builds the README picture `docs/cube-of-spheres.png`: the shaded images of the reference
//! (`raycast`), the sampling baseline (`nsample`), the hard shadow (`hard-sv`) and the wedge
//! methods (`ssv`, `ssv-optimized`, `wedge-blending`), each labelled with its name, its time
//! and its RMSE against the reference, read from a render's output directory.
//!
//! ```sh
//! cargo run --release -- render cube-of-spheres --width 256 --height 256 --out /tmp/readme-out
//! cargo run --release --example readme_picture -- /tmp/readme-out docs/cube-of-spheres.png
//! ```
//!
//! Both arguments are optional and default to the paths above. The grid is drawn by
//! [`penumbra::experiment::panels::labelled_grid_png`].

use penumbra::experiment::panels::{labelled_grid_png, Panel};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The methods shown, left to right, top to bottom, with what each is.
const METHODS: [(&str, &str); 6] = [
    ("raycast", "reference, 1024 rays"),
    ("nsample", "1024 hard shadows"),
    ("hard-sv", "hard shadow"),
    ("ssv", "Paper III"),
    ("ssv-optimized", "Paper IV"),
    ("wedge-blending", "Forest et al. 2006"),
];
/// Panels per row.
const COLUMNS: u32 = 3;
/// Default render output directory.
const DEFAULT_IN: &str = "/tmp/readme-out";
/// Default picture path.
const DEFAULT_OUT: &str = "docs/cube-of-spheres.png";

/// Reads `dir/METHOD/image.png` as 8-bit RGB pixels and its caption from
/// `dir/METHOD/stats.json` (wall time; RMSE against the reference when it ran).
fn read_panel(dir: &Path, method: &str, what: &str) -> Result<((u32, u32), Panel), String> {
    let path = dir.join(method).join("image.png");
    let img = image::open(&path)
        .map_err(|e| format!("{}: {e}", path.display()))?
        .into_rgb8();
    let stats_path = dir.join(method).join("stats.json");
    let text = std::fs::read_to_string(&stats_path)
        .map_err(|e| format!("{}: {e}", stats_path.display()))?;
    let stats: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", stats_path.display()))?;
    let ms = stats["wall_seconds"].as_f64().unwrap_or(f64::NAN) * 1000.0;
    let caption = match stats["error"]["rmse"].as_f64() {
        Some(rmse) => format!("{ms:.0} ms · RMSE {rmse:.4}"),
        None => format!("{ms:.0} ms"),
    };
    Ok((
        img.dimensions(),
        Panel {
            pixels: img.pixels().map(|p| p.0).collect(),
            title: format!("{method} ({what})"),
            caption,
        },
    ))
}

/// Reads the panels, checks they have one size, and writes the labelled grid.
fn run(input: &Path, output: &Path) -> Result<(), String> {
    let mut size = None;
    let mut panels = Vec::new();
    for (method, what) in METHODS {
        let (dims, panel) = read_panel(input, method, what)?;
        match size {
            None => size = Some(dims),
            Some(s) if s != dims => {
                return Err(format!(
                    "{method}/image.png is {}×{}, the first panel is {}×{}",
                    dims.0, dims.1, s.0, s.1
                ))
            }
            Some(_) => {}
        }
        panels.push(panel);
    }
    let png = labelled_grid_png(&panels, size.expect("at least one panel"), COLUMNS)?;
    std::fs::write(output, png).map_err(|e| format!("{}: {e}", output.display()))
}

/// `readme_picture [INPUT_DIR] [OUTPUT_PNG]`.
fn main() -> ExitCode {
    let mut args = std::env::args_os().skip(1);
    let input = args
        .next()
        .map_or_else(|| PathBuf::from(DEFAULT_IN), PathBuf::from);
    let output = args
        .next()
        .map_or_else(|| PathBuf::from(DEFAULT_OUT), PathBuf::from);
    match run(&input, &output) {
        Ok(()) => {
            println!("wrote {}", output.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("readme_picture: {e}");
            ExitCode::FAILURE
        }
    }
}
