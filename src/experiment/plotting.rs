//! What every experiment plot shares: the embedded font and drawing one chart into both a PNG
//! and an SVG ([`png_and_svg`]), with `plotters`. Text uses DejaVu Sans, embedded (its
//! licence is in `src/experiment/font/LICENSE`), so no system font library is needed.

use plotters::coord::Shift;
use plotters::prelude::*;
use std::sync::OnceLock;

/// The embedded font (DejaVu Sans 2.37).
const FONT: &[u8] = include_bytes!("font/DejaVuSans.ttf");

/// Registers the embedded font (DejaVu Sans) as plotters' `sans-serif` once per process. Every plot of this crate
/// calls it (also the legends of buffer dumps, [`crate::output::dump`]); a program that draws
/// with plotters through another crate (the benchmarks' criterion HTML reports) calls it
/// first, since no system font is looked up.
pub fn register_font() -> Result<(), String> {
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
            .map_err(|_| "the embedded font cannot be read".to_string())
    })
    .clone()
}

/// The colours of every plot's series, in order (Tableau 10).
pub const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(127, 127, 127),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(23, 190, 207),
    RGBColor(188, 189, 34),
    RGBColor(227, 119, 194),
];

/// A plot that can draw itself on any plotters backend.
pub trait Plot {
    /// Draws the whole plot on `area`.
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), String>;
}

/// Draws `plot` at `width`×`height` once into an RGB buffer, encoded as PNG with the crate's
/// own encoder, and once into an SVG string: `(png bytes, svg text)`.
pub fn png_and_svg(
    plot: &impl Plot,
    (width, height): (u32, u32),
) -> Result<(Vec<u8>, String), String> {
    register_font()?;
    let mut rgb = vec![0u8; width as usize * height as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        plot.draw(&root)?;
        root.present().map_err(|e| e.to_string())?;
    }
    let pixels: Vec<[u8; 3]> = rgb.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let png = crate::output::encode_rgb8_png(&pixels, width, height).map_err(|e| e.to_string())?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        plot.draw(&root)?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok((png, svg))
}
