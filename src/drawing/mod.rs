//! What every picture this crate draws with `plotters` shares: the embedded font. Text uses
//! DejaVu Sans, embedded (its licence is in `src/drawing/font/LICENSE`), so no system font
//! library is needed. It sits below both the outputs (the legends of buffer dumps,
//! [`crate::output::dump`]) and the experiments' plots ([`crate::experiment::plotting`]), which
//! both draw text.

use plotters::style::FontStyle;
use std::sync::OnceLock;

/// The embedded font (DejaVu Sans 2.37).
const FONT: &[u8] = include_bytes!("font/DejaVuSans.ttf");

/// Registers the embedded font (DejaVu Sans) as plotters' `sans-serif` once per process. Every
/// plot of this crate calls it; a program that draws with plotters through another crate (the
/// benchmarks' criterion HTML reports) calls it first, since no system font is looked up.
pub fn register_font() -> Result<(), String> {
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
            .map_err(|_| "the embedded font cannot be read".to_string())
    })
    .clone()
}
