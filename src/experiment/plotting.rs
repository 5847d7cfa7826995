//! What every experiment plot shares: the palette and drawing one chart into both a PNG and an
//! SVG ([`png_and_svg`]), with `plotters`, in the embedded font ([`crate::drawing`]).

use crate::drawing::register_font;
use plotters::coord::Shift;
use plotters::prelude::*;

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

/// The chart every experiment plot starts from: a white `root` with `caption` on top, the
/// common margin and an x label area of 44 pixels, `y_label_area` pixels for the y labels.
pub fn chart_on<'a, 'b, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, Shift>,
    caption: &str,
    y_label_area: u32,
) -> Result<ChartBuilder<'a, 'b, DB>, String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let mut chart = ChartBuilder::on(root);
    chart
        .caption(caption, ("sans-serif", 20))
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(y_label_area);
    Ok(chart)
}

/// Draws `chart`'s legend at `position` in the style of every experiment plot.
pub fn draw_legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 11))
        .draw()
        .map_err(|e| e.to_string())
}
