//! A scene's table: the rows and notes of the text table ([`crate::render::table_rows`],
//! [`crate::render::table_notes`]) plus what only the page has room for — the error over the
//! reference's penumbra, the modeled GPU time ([`crate::gpu_model`]), the split by the receiver's horizon (mean |e| over whole-light and
//! horizon receivers, their share of the image and of the error; [`crate::metrics::horizon`]),
//! the clamp and overflow counters, and the plan's resolved settings
//! (z-pass or z-fail, formats; [`super::plan::settings_summary`]). One row per method that
//! ran; the reference's row holds its own noise floor.

use super::html::Html;
use super::plan::settings_summary;
use super::SceneRuns;
use crate::metrics::horizon::HorizonSplit;
use crate::metrics::ErrorStats;
use crate::render::{table_notes, table_rows};

/// The column heads, in order.
const HEADS: [&str; 15] = [
    "method",
    "time [s]",
    "GPU model [ms] (a model)",
    "RMSE",
    "penumbra RMSE",
    "max |e|",
    "% > 1/255",
    "whole-light mean |e|",
    "horizon mean |e|",
    "% horizon pixels",
    "horizon share of error",
    "MB traffic",
    "clamped pixels",
    "overflow events",
    "plan",
];

/// The table and its notes for `s`.
pub fn table(h: &mut Html, s: &SceneRuns) {
    h.open("table", &[("class", "methods")]);
    h.open("thead", &[]).open("tr", &[]);
    for head in HEADS {
        let class = if head == "method" || head == "plan" {
            "name"
        } else {
            "num"
        };
        h.element("th", &[("class", class)], head);
    }
    h.close().close();
    h.open("tbody", &[]);
    let dash = "—".to_string();
    let stat = |e: Option<&ErrorStats>, f: fn(&ErrorStats) -> String| e.map_or(dash.clone(), f);
    for row in table_rows(s.runs) {
        let stats = &row.run.output.stats;
        let (class, name) = if row.is_reference() {
            ("reference", format!("{} (its noise floor)", row.run.method))
        } else {
            ("method", row.run.method.clone())
        };
        let split = |f: fn(&HorizonSplit) -> String| row.horizon.map_or(dash.clone(), f);
        h.open("tr", &[("class", class)]);
        h.element("td", &[("class", "name")], &name);
        let cells = [
            format!("{:.3}", row.seconds()),
            row.gpu_model_ms(),
            stat(row.error, |e| format!("{:.5}", e.rmse)),
            stat(row.penumbra_error, |e| format!("{:.5}", e.rmse)),
            stat(row.error, |e| format!("{:.4}", e.max_abs)),
            stat(row.error, |e| format!("{:.3}", e.pct_over_1_255)),
            split(|h| format!("{:.5}", h.whole_light.mean_abs)),
            split(|h| format!("{:.5}", h.horizon.mean_abs)),
            split(|h| format!("{:.2}", h.horizon_pct)),
            split(|h| format!("{:.3}", h.horizon_share)),
            format!("{:.2}", row.traffic_mb),
            stats.clamped_pixels.to_string(),
            stats.totals.overflow_events.to_string(),
        ];
        for c in &cells {
            h.element("td", &[], c);
        }
        h.element("td", &[("class", "text")], &settings_summary(&stats.plan));
        h.close();
    }
    h.close().close();
    let notes = table_notes(s.scene, s.runs);
    if !notes.is_empty() {
        h.open("ul", &[("class", "notes")]);
        for n in &notes {
            h.element("li", &[], n);
        }
        h.close();
    }
}
