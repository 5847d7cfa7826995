//! The image grid of a scene: the reference and every method's shaded image, captioned with
//! the method, its paper, its time and its error, each linking to its error map; under each,
//! links to every other file the method wrote, then its buffer dumps in bold, each linking
//! to its viewable image where it was written (`--dump-buffers`) or else its raw file, with
//! its raw values and event map beside it. A checkbox swaps the shaded images for the error
//! maps (CSS only).

use super::html::Html;
use super::SceneRuns;
use crate::metrics::error_report::error_colour;
use crate::output::dump::{events_view_file_name, raw_file_name, view_file_name};
use crate::output::{ERROR_FILE as ERROR_MAP, IMAGE_FILE as IMAGE};
use crate::render::table_rows;

/// A CSS colour of [`error_colour`].
fn css_colour(e: f64) -> String {
    let [r, g, b] = error_colour(e);
    format!("rgb({r},{g},{b})")
}

/// The error maps' colour scale: a bar from −1 (blue) through 0 (white) to +1 (red), its
/// position proportional to √|e| like the colour strength, so it is exact with three stops.
pub fn legend(h: &mut Html) {
    h.text("Error maps: ");
    let style = format!(
        "background: linear-gradient(to right, {}, {}, {})",
        css_colour(-1.0),
        css_colour(0.0),
        css_colour(1.0)
    );
    h.element("span", &[("class", "legend"), ("style", &style)], "");
    h.text(&format!(
        " the signed error against {}: blue where a method is too dark, red where too bright, \
         −1 … 0 … +1 with strength √|e| (1/255 a faint tint, 1/4 half way), the same scale in \
         every run.",
        crate::methods::REFERENCE
    ));
}

/// The grid of scene `index` (its checkbox's id is derived from it).
pub fn grid(h: &mut Html, s: &SceneRuns, index: usize) {
    let toggle = format!("errors-{}", index + 1);
    h.void(
        "input",
        &[("type", "checkbox"), ("id", &toggle), ("class", "toggle")],
    );
    h.element(
        "label",
        &[("for", &toggle)],
        " show the error maps instead of the images",
    );
    h.open("div", &[("class", "grid")]);
    for (row, files) in table_rows(s.runs).iter().zip(s.files) {
        let run = row.run;
        let method = run.method.as_str();
        let has_error_map = files.iter().any(|f| f == ERROR_MAP);
        let class = if row.is_reference() {
            "reference"
        } else {
            "method"
        };
        h.open("figure", &[("class", class)]);
        let target = if has_error_map { ERROR_MAP } else { IMAGE };
        h.open("a", &[("href", &s.link(method, target))]);
        let alt = format!("{method}: shaded image");
        let swap = if has_error_map { "swap" } else { "" };
        let (w, hh) = (s.scene.width.to_string(), s.scene.height.to_string());
        h.void(
            "img",
            &[
                ("src", &s.link(method, IMAGE)),
                ("alt", &alt),
                ("class", swap),
                ("width", &w),
                ("height", &hh),
            ],
        );
        if has_error_map {
            let alt = format!("{method}: signed error against the reference");
            h.void(
                "img",
                &[
                    ("src", &s.link(method, ERROR_MAP)),
                    ("alt", &alt),
                    ("class", "err"),
                    ("width", &w),
                    ("height", &hh),
                ],
            );
        }
        h.close();
        h.open("figcaption", &[]);
        h.element("strong", &[], method);
        h.element("span", &[("class", "paper")], crate::methods::paper(method));
        let error = match row.error {
            Some(e) if row.is_reference() => format!(" · its noise RMSE {:.5}", e.rmse),
            Some(e) => format!(" · RMSE {:.5}", e.rmse),
            None => String::new(),
        };
        h.text(&format!("{:.3} s{error}", row.seconds()));
        h.void("br", &[]);
        let dump_prefixes: Vec<String> = run
            .output
            .dumps
            .iter()
            .map(|d| format!("{}.", d.name))
            .collect();
        let of_a_dump = |f: &str| dump_prefixes.iter().any(|p| f.starts_with(p.as_str()));
        h.open("span", &[("class", "files")]);
        for file in files.iter().filter(|f| *f != IMAGE && !of_a_dump(f)) {
            h.element(
                "a",
                &[("href", &s.link(method, file)), ("class", "file")],
                file,
            );
            h.text(" ");
        }
        h.close();
        let written = |f: &String| files.contains(f);
        let dumps: Vec<_> = run
            .output
            .dumps
            .iter()
            .filter_map(|d| Some((d, raw_file_name(d).ok().filter(written)?)))
            .collect();
        if !dumps.is_empty() {
            h.open("span", &[("class", "files buffers")]);
            h.text("buffers: ");
            for (d, raw) in dumps {
                let view = Some(view_file_name(d)).filter(written);
                let main = view.as_ref().unwrap_or(&raw);
                let title = format!(
                    "{} ({}×{}): {}",
                    d.format.name(),
                    d.width,
                    d.height,
                    d.about
                );
                h.element(
                    "a",
                    &[
                        ("href", &s.link(method, main)),
                        ("class", "buffer"),
                        ("title", &title),
                    ],
                    &d.name,
                );
                if view.is_some() {
                    h.text(" (");
                    h.element("a", &[("href", &s.link(method, &raw))], "raw");
                    let json = format!("{}.json", d.name);
                    if written(&json) {
                        h.text(", ");
                        h.element("a", &[("href", &s.link(method, &json))], "json");
                    }
                    let events = events_view_file_name(d);
                    if written(&events) {
                        h.text(", ");
                        h.element("a", &[("href", &s.link(method, &events))], "events");
                    }
                    h.text(")");
                }
                h.text(" ");
            }
            h.close();
        }
        h.close();
        h.close();
    }
    h.close();
}
