//! The experiments' results that lie next to the page: an accuracy–time sweep
//! ([`crate::experiment::accuracy_time`]: `accuracy-time.json` and the scenes' Pareto plots),
//! a tile-size sweep ([`crate::experiment::tile_size`]: its plot and CSV), the precision
//! experiment ([`crate::experiment::precision`]: its two plots and summary) and the cost-growth
//! experiment ([`crate::experiment::cost_growth`]: its three plots, summary and CSV). Each is
//! looked for in the report's directory itself and where its command writes by default
//! relative to the default output directory (`experiment/accuracy-time/`, `experiment/`,
//! `experiment/precision/` and `cost-growth/`, so that the default run's `out/index.html`
//! finds them). The page shows a scene's Pareto plot and Pareto-optimal configurations in the
//! scene's section, the tile-size, precision and cost-growth plots once at the end.

use super::html::{url, Html};
use crate::experiment::accuracy_time::{
    self, axis_label, fmt_g, pareto_rows, plot_files, Sweep, TimeAxis,
};
use crate::experiment::{cost_growth, precision, tile_size};
use std::path::{Path, PathBuf};

/// The folders, relative to the report's directory, where an experiment writing by default
/// to `default_out` may have left its results: the report's directory and `default_out`
/// taken relative to the default output directory.
fn candidates(default_out: &str) -> [PathBuf; 2] {
    let default = Path::new(default_out);
    let rel = default
        .strip_prefix(crate::render::DEFAULT_OUT)
        .unwrap_or(default);
    [PathBuf::new(), rel.to_path_buf()]
}

/// What was found next to the page.
#[derive(Debug)]
pub struct Found {
    /// The report's directory.
    root: PathBuf,
    /// An accuracy–time sweep: its folder relative to the report's directory, and its results.
    accuracy: Option<(PathBuf, Sweep)>,
    /// The tile-size experiment's folder relative to the report's directory.
    pub tile_size: Option<PathBuf>,
    /// The precision experiment's folder relative to the report's directory.
    pub precision: Option<PathBuf>,
    /// The cost-growth experiment's folder relative to the report's directory.
    pub cost_growth: Option<PathBuf>,
    /// Results found but unreadable, one sentence each (shown at the top of the page).
    pub problems: Vec<String>,
}

impl Found {
    /// Looks for the experiments' results around the report directory `dir`.
    pub fn look(dir: &Path) -> Self {
        let mut found = Found {
            root: dir.to_path_buf(),
            accuracy: None,
            tile_size: None,
            precision: None,
            cost_growth: None,
            problems: Vec::new(),
        };
        for rel in candidates(accuracy_time::DEFAULT_OUT) {
            let at = dir.join(&rel);
            if found.accuracy.is_some() || !at.join(accuracy_time::JSON_FILE).is_file() {
                continue;
            }
            match accuracy_time::read(&at) {
                Ok(sweep) => found.accuracy = Some((rel, sweep)),
                Err(e) => found.problems.push(format!("not shown: {e}")),
            }
        }
        found.tile_size = candidates(crate::experiment::DEFAULT_OUT)
            .into_iter()
            .find(|rel| dir.join(rel).join(tile_size::SVG_FILE).is_file());
        found.precision = candidates(precision::DEFAULT_OUT)
            .into_iter()
            .find(|rel| dir.join(rel).join(precision::SUMMARY_FILE).is_file());
        found.cost_growth = candidates(cost_growth::DEFAULT_OUT)
            .into_iter()
            .find(|rel| dir.join(rel).join(cost_growth::JSON_FILE).is_file());
        found
    }

    /// The accuracy–time part of the section of scene `source` (the scene's name as the
    /// sweep records it), if the sweep measured that scene: per time axis (CPU time, then each
    /// GPU profile's modeled time) the Pareto plot (PNG, linking to the SVG) and the
    /// Pareto-optimal configurations, fastest first.
    pub fn accuracy_time(&self, h: &mut Html, source: &str) {
        let Some((rel, sweep)) = &self.accuracy else {
            return;
        };
        let Some(first) = sweep.rows.iter().find(|r| r.item.scene == source) else {
            return;
        };
        h.element("h3", &[], "Accuracy against time");
        h.open("p", &[]);
        let shard = if sweep.shard == accuracy_time::Shard::WHOLE {
            String::new()
        } else {
            format!(", shard {} only", sweep.shard)
        };
        h.text(&format!(
            "From the accuracy–time experiment ({}{shard}): every configuration at {}×{}, \
             error against {}, time of the method alone (median of its timed runs). ",
            rel.join(accuracy_time::JSON_FILE).display(),
            first.item.width,
            first.item.height,
            sweep.reference
        ));
        let summary = rel.join(accuracy_time::SUMMARY_FILE);
        if self.root.join(&summary).is_file() {
            h.element("a", &[("href", &url(&summary))], "Its full table.");
        }
        h.close();
        for axis in TimeAxis::all(sweep) {
            let label = axis_label(sweep, axis);
            h.element("h4", &[], &format!("Against {label}"));
            let [png, svg] = plot_files(sweep, source, axis).map(|f| rel.join(f));
            let exists = |p: &PathBuf| self.root.join(p).is_file();
            let shown = [&png, &svg].into_iter().find(|p| exists(p));
            let linked = [&svg, &png].into_iter().find(|p| exists(p));
            if let (Some(shown), Some(linked)) = (shown, linked) {
                h.open("div", &[("class", "pareto")]);
                h.open("a", &[("href", &url(linked))]);
                let alt =
                    format!("RMSE against {label} on {source}, log–log, with the Pareto front");
                h.void("img", &[("src", &url(shown)), ("alt", &alt)]);
                h.close().close();
            }
            h.element(
                "p",
                &[],
                "Pareto-optimal (no other configuration is both at least as fast and at least \
                 as accurate), fastest first, numbered as in the plot:",
            );
            h.open("ol", &[("class", "front")]);
            for (n, r) in pareto_rows(sweep, source, axis) {
                h.element(
                    "li",
                    &[],
                    &format!(
                        "#{n} {} {}: {} ms, RMSE {:.5}",
                        r.item.method,
                        r.item.knobs,
                        fmt_g(1e3 * axis.seconds(r)),
                        r.error.rmse
                    ),
                );
            }
            h.close();
        }
    }

    /// The tile-size section, if its results were found.
    pub fn tile_size(&self, h: &mut Html) {
        let Some(rel) = &self.tile_size else {
            return;
        };
        h.open("section", &[("id", "tile-size")]);
        h.element(
            "h2",
            &[],
            "Tile size: pw-restructured's memory accesses (Paper II §7)",
        );
        h.open("p", &[]);
        h.text(&format!(
            "From the tile-size experiment ({}; its scene is named in the plot). ",
            rel.join(tile_size::SVG_FILE).display()
        ));
        let csv = rel.join(tile_size::CSV_FILE);
        if self.root.join(&csv).is_file() {
            h.element("a", &[("href", &url(&csv))], tile_size::CSV_FILE);
        }
        h.close();
        let svg = url(&rel.join(tile_size::SVG_FILE));
        h.void(
            "img",
            &[
                ("src", &svg),
                ("alt", "memory accesses per tile size, one line per variant"),
            ],
        );
        h.close();
    }

    /// The precision section (issue 11), if its results were found: the two plots and a
    /// link to the summary with the papers' claims.
    pub fn precision(&self, h: &mut Html) {
        let Some(rel) = &self.precision else {
            return;
        };
        h.open("section", &[("id", "precision")]);
        h.element(
            "h2",
            &[],
            "Precision: shader arithmetic, buffer formats and overflow",
        );
        h.open("p", &[]);
        h.text("From the precision experiment: ");
        let summary = rel.join(precision::SUMMARY_FILE);
        h.element("a", &[("href", &url(&summary))], precision::SUMMARY_FILE);
        h.text(" has every table and the papers' claims checked.");
        h.close();
        for (file, alt) in [
            (
                precision::SHADER_PNG,
                "mean error against f64 per shader precision, one line per method and scene",
            ),
            (
                precision::OVERFLOW_PNG,
                "corrupted pixels per stack size, one line per buffer format",
            ),
        ] {
            let at = rel.join(file);
            if self.root.join(&at).is_file() {
                h.void("img", &[("src", &url(&at)), ("alt", alt)]);
            }
        }
        h.close();
    }

    /// The cost-growth section, if its results were found: a link to its tables and its three
    /// plots (time against triangles, time against pixels, peak against the estimate).
    pub fn cost_growth(&self, h: &mut Html) {
        let Some(rel) = &self.cost_growth else {
            return;
        };
        h.open("section", &[("id", "cost-growth")]);
        h.element(
            "h2",
            &[],
            "Cost growth: time and peak memory against triangles and image size",
        );
        h.open("p", &[]);
        h.text("From experiment cost-growth: ");
        let summary = rel.join(cost_growth::SUMMARY_FILE);
        if self.root.join(&summary).is_file() {
            h.element("a", &[("href", &url(&summary))], cost_growth::SUMMARY_FILE);
            h.text(" has the tables and every point where the peak exceeded the estimate; ");
        }
        let csv = rel.join(cost_growth::CSV_FILE);
        if self.root.join(&csv).is_file() {
            h.element("a", &[("href", &url(&csv))], cost_growth::CSV_FILE);
            h.text(" every point.");
        }
        h.close();
        let alts = [
            "method time against the occluder's triangles, log–log, one line per method",
            "method time against the image's pixels, log–log, one line per method",
            "measured peak memory against the estimate, log–log, with the diagonal",
        ];
        for (stem, alt) in cost_growth::PLOTS.iter().zip(alts) {
            let png = rel.join(format!("{stem}.png"));
            if self.root.join(&png).is_file() {
                h.open("div", &[("class", "pareto")]);
                h.void("img", &[("src", &url(&png)), ("alt", alt)]);
                h.close();
            }
        }
        h.close();
    }
}
