//! The Pareto plot of one scene on one time axis ([`pareto_plot`]): RMSE against median CPU
//! time per frame, or against a GPU profile's modeled time (the middle estimate, with its
//! low–high range as a horizontal bar), both axes logarithmic. Each method has one colour ([`method_colour`]), each knob setting of a
//! method one marker shape, and every point carries its row number (`#` of the summary
//! table), which the panel on the right spells out; the Pareto front is the step line through
//! the Pareto-optimal configurations (after each one, the best error attainable until the
//! next is as fast), and the reference's own noise is a dashed line. A configuration whose
//! RMSE is 0 (the reference itself, when listed) is drawn on the bottom edge; one without a
//! time on the axis (a CPU-only method, not modeled) is left out of the chart and marked
//! "not modeled" in the key.
//!
//! Drawn with `plotters` once per backend ([`crate::experiment::plotting`]).

use super::{axis_label, pareto_front, Row, Sweep, TimeAxis};
use crate::experiment::plotting::{png_and_svg, Plot, PALETTE};
use crate::methods;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Size of the plots in pixels: the chart on the left, the key on the right.
pub const WIDTH: u32 = 1400;
/// Smallest height of the plots; a long key makes them taller.
pub const MIN_HEIGHT: u32 = 820;
/// Width of the chart part.
const CHART_WIDTH: u32 = 900;
/// Height of one line of the key.
const KEY_LINE: i32 = 18;
/// Distinct marker shapes (circles, triangle, squares, cross, diamonds); knob settings beyond them repeat the shapes.
pub const MARKERS: usize = 8;

/// The colour of `method` (Tableau 10, by its position in [`methods::ALL`]).
pub fn method_colour(method: &str) -> RGBColor {
    let k = methods::names()
        .position(|m| m == method)
        .unwrap_or(PALETTE.len() - 1);
    PALETTE[k % PALETTE.len()]
}

/// Draws marker `kind` (mod [`MARKERS`]) in `colour` centred at pixel `at` of `area`: filled
/// and open circle, filled triangle, filled and open square, cross, filled and open diamond.
fn marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    at: (i32, i32),
    kind: usize,
    colour: RGBColor,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let filled = colour.filled();
    let open = colour.stroke_width(2);
    let base = EmptyElement::at(at);
    let diamond = vec![(0, -6), (6, 0), (0, 6), (-6, 0)];
    match kind % MARKERS {
        0 => area.draw(&(base + Circle::new((0, 0), 5, filled))),
        1 => area.draw(&(base + Circle::new((0, 0), 5, open))),
        2 => area.draw(&(base + TriangleMarker::new((0, 0), 6, filled))),
        3 => area.draw(&(base + Rectangle::new([(-4, -4), (4, 4)], filled))),
        4 => area.draw(&(base + Rectangle::new([(-4, -4), (4, 4)], open))),
        5 => area.draw(&(base + Cross::new((0, 0), 5, open))),
        6 => area.draw(&(base + Polygon::new(diamond, filled))),
        _ => {
            let mut closed = diamond;
            closed.push(closed[0]);
            area.draw(&(base + PathElement::new(closed, open)))
        }
    }
}

/// One point of the plot.
struct Point<'r> {
    /// Its row number within the scene (1-based, the summary's `#`).
    number: usize,
    /// Marker shape: the knob setting's position among its method's rows.
    kind: usize,
    /// The row.
    row: &'r Row,
}

/// Draws the plot of `scene` onto `root`.
fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    sweep: &Sweep,
    scene: &str,
    axis: TimeAxis,
) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let rows: Vec<&Row> = sweep
        .rows
        .iter()
        .filter(|r| r.item.scene == scene)
        .collect();
    let points: Vec<Point> = rows
        .iter()
        .enumerate()
        .map(|(n, r)| Point {
            number: n + 1,
            kind: rows[..n]
                .iter()
                .filter(|o| o.item.method == r.item.method)
                .count(),
            row: r,
        })
        .collect();
    let noise = sweep
        .references
        .iter()
        .find(|r| r.scene == scene)
        .map(|r| r.noise_floor.rmse)
        .filter(|e| *e > 0.0);
    let positive = |e: f64| (e > 0.0 && e.is_finite()).then_some(e);
    let errors: Vec<f64> = rows
        .iter()
        .filter_map(|r| positive(r.error.rmse))
        .chain(noise)
        .collect();
    let y_lo = errors.iter().copied().fold(f64::INFINITY, f64::min) / 2.0;
    let y_hi = errors.iter().copied().fold(0.0, f64::max) * 2.0;
    let (y_lo, y_hi) = if errors.is_empty() {
        (1e-6, 1.0)
    } else {
        (y_lo, y_hi.max(10.0 * y_lo))
    };
    // The time range of every point, for the axis limits: its bar where it has one.
    let bar = |r: &Row| match axis {
        TimeAxis::Cpu => (r.median_seconds, r.median_seconds),
        TimeAxis::Gpu(k) => r
            .modeled
            .get(k)
            .and_then(|m| m.seconds)
            .map_or((f64::NAN, f64::NAN), |t| (t.low, t.high)),
    };
    let times: Vec<f64> = rows
        .iter()
        .flat_map(|r| [bar(r).0, bar(r).1])
        .filter_map(positive)
        .collect();
    let t_lo = times.iter().copied().fold(f64::INFINITY, f64::min) / 1.5;
    let t_hi = times.iter().copied().fold(0.0, f64::max) * 1.5;
    let (t_lo, t_hi) = if times.is_empty() {
        (1e-6, 1.0)
    } else {
        (t_lo, t_hi.max(10.0 * t_lo))
    };
    let at = |r: &Row| (axis.seconds(r).max(t_lo), r.error.rmse.max(y_lo));
    let drawn = |r: &Row| positive(axis.seconds(r)).is_some();

    root.fill(&WHITE).map_err(err)?;
    let (left, right) = root.split_horizontally(CHART_WIDTH);
    let (w, h) = (rows[0].item.width, rows[0].item.height);
    let mut chart = ChartBuilder::on(&left)
        .caption(
            format!("{scene} {w}×{h}: error vs {}", axis_label(sweep, axis)),
            ("sans-serif", 24),
        )
        .margin(16)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d((t_lo..t_hi).log_scale(), (y_lo..y_hi).log_scale())
        .map_err(err)?;
    let tick = |v: &f64| format!("{v:.0e}");
    chart
        .configure_mesh()
        .x_desc(match axis {
            TimeAxis::Cpu => format!(
                "CPU time per frame [s], median of {} runs (log)",
                rows[0].runs
            ),
            TimeAxis::Gpu(k) => format!(
                "modeled GPU time per frame on {} [s], middle (bar: low–high), a model (log)",
                sweep.gpus[k]
            ),
        })
        .y_desc(format!("RMSE vs {} (log)", sweep.reference))
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    if let Some(e) = noise {
        chart
            .draw_series(DashedLineSeries::new(
                [(t_lo, e), (t_hi, e)],
                6,
                4,
                RGBColor(120, 120, 120).stroke_width(1),
            ))
            .map_err(err)?;
    }
    let coords: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (axis.seconds(r), r.error.rmse))
        .collect();
    let front = pareto_front(&coords);
    let mut step = Vec::new();
    for (j, &i) in front.iter().enumerate() {
        let p = at(rows[i]);
        if j > 0 {
            step.push((p.0, step.last().map_or(p.1, |q: &(f64, f64)| q.1)));
        }
        step.push(p);
    }
    chart
        .draw_series(LineSeries::new(step, BLACK.stroke_width(2)))
        .map_err(err)?;
    // Markers and numbers in pixels of `root` (the chart maps a point to backend pixels, and
    // `root` starts at the backend's origin).
    for p in points.iter().filter(|p| drawn(p.row)) {
        let colour = method_colour(&p.row.item.method);
        let (lo, hi) = bar(p.row);
        if lo < hi {
            chart
                .draw_series(LineSeries::new(
                    [(lo, at(p.row).1), (hi, at(p.row).1)],
                    colour.stroke_width(1),
                ))
                .map_err(err)?;
        }
        let (x, y) = chart.backend_coord(&at(p.row));
        marker(root, (x, y), p.kind, colour).map_err(err)?;
        root.draw(&Text::new(
            p.number.to_string(),
            (x + 6, y - 16),
            ("sans-serif", 12).into_font().color(&colour),
        ))
        .map_err(err)?;
    }

    // The key: one line per configuration, then the lines' meaning.
    let text = |s: String, x: i32, y: i32, size: u32| Text::new(s, (x, y), ("sans-serif", size));
    right
        .draw(&text(
            "#  method  knobs  (★ Pareto-optimal)".into(),
            10,
            20,
            15,
        ))
        .map_err(err)?;
    for (n, p) in points.iter().enumerate() {
        let y = 48 + KEY_LINE * n as i32;
        let colour = method_colour(&p.row.item.method);
        marker(&right, (18, y), p.kind, colour).map_err(err)?;
        let star = if !drawn(p.row) {
            " (not modeled)"
        } else if axis.pareto(p.row) {
            " ★"
        } else {
            ""
        };
        right
            .draw(&text(
                format!(
                    "{}  {}  {}{star}",
                    p.number, p.row.item.method, p.row.item.knobs
                ),
                32,
                y - 7,
                13,
            ))
            .map_err(err)?;
    }
    let y = 48 + KEY_LINE * points.len() as i32 + 10;
    right
        .draw(&PathElement::new(
            vec![(8, y), (28, y)],
            BLACK.stroke_width(2),
        ))
        .map_err(err)?;
    right
        .draw(&text("Pareto front".into(), 32, y - 7, 13))
        .map_err(err)?;
    if noise.is_some() {
        let y = y + KEY_LINE;
        right
            .draw(&PathElement::new(
                vec![(8, y), (28, y)],
                RGBColor(120, 120, 120).stroke_width(1),
            ))
            .map_err(err)?;
        right
            .draw(&text(
                "the reference's own noise (seed + 1)".into(),
                32,
                y - 7,
                13,
            ))
            .map_err(err)?;
    }
    root.present().map_err(err)
}

/// The plot's height for `lines` key lines.
fn height(lines: usize) -> u32 {
    MIN_HEIGHT.max(48 + KEY_LINE as u32 * (lines as u32 + 4))
}

/// The Pareto plot of `scene` on `axis` (module doc) as PNG bytes and SVG text.
pub fn pareto_plot(
    sweep: &Sweep,
    scene: &str,
    axis: TimeAxis,
) -> Result<(Vec<u8>, String), String> {
    let lines = sweep.rows.iter().filter(|r| r.item.scene == scene).count();
    if lines == 0 {
        return Err(format!("no rows of scene {scene} to plot"));
    }
    png_and_svg(&ParetoPlot { sweep, scene, axis }, (WIDTH, height(lines)))
}

/// [`draw`] as a [`Plot`].
struct ParetoPlot<'a> {
    sweep: &'a Sweep,
    scene: &'a str,
    axis: TimeAxis,
}

impl Plot for ParetoPlot<'_> {
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), String> {
        draw(area, self.sweep, self.scene, self.axis)
    }
}
