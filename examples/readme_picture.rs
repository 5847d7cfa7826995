//! Builds the README picture `docs/cube-of-spheres.png`: the shaded images of `raycast`,
//! `nsample` and `hard-sv` side by side (left to right), from a render's output directory.
//!
//! ```sh
//! cargo run --release -- render cube-of-spheres --width 256 --height 256 --out /tmp/readme-out
//! cargo run --release --example readme_picture -- /tmp/readme-out docs/cube-of-spheres.png
//! ```
//!
//! Both arguments are optional and default to the paths above. The panels are joined with
//! [`penumbra::output::write_side_by_side_png`].

use penumbra::output::write_side_by_side_png;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The methods shown, left to right.
const METHODS: [&str; 3] = ["raycast", "nsample", "hard-sv"];
/// Default render output directory.
const DEFAULT_IN: &str = "/tmp/readme-out";
/// Default picture path.
const DEFAULT_OUT: &str = "docs/cube-of-spheres.png";

/// Reads `dir/METHOD/image.png` as 8-bit RGB pixels, row-major, with its size.
fn read_panel(dir: &Path, method: &str) -> Result<(u32, u32, Vec<[u8; 3]>), String> {
    let path = dir.join(method).join("image.png");
    let img = image::open(&path)
        .map_err(|e| format!("{}: {e}", path.display()))?
        .into_rgb8();
    let (w, h) = img.dimensions();
    let pixels = img.pixels().map(|p| p.0).collect();
    Ok((w, h, pixels))
}

/// Reads the three panels, checks they have one size, and writes the side-by-side PNG.
fn run(input: &Path, output: &Path) -> Result<(), String> {
    let mut size = None;
    let mut panels = Vec::new();
    for method in METHODS {
        let (w, h, pixels) = read_panel(input, method)?;
        match size {
            None => size = Some((w, h)),
            Some(s) if s != (w, h) => {
                return Err(format!(
                    "{method}/image.png is {w}×{h}, the first panel is {}×{}",
                    s.0, s.1
                ))
            }
            Some(_) => {}
        }
        panels.push(pixels);
    }
    let (w, h) = size.expect("at least one panel");
    write_side_by_side_png(output, w, h, &panels).map_err(|e| format!("{}: {e}", output.display()))
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
