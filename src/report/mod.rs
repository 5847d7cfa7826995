//! The HTML report (issue 14 item 5): one self-contained page, `DIR/index.html`, showing the
//! runs of one or more scenes — per scene the reference and every method's image in a
//! labelled grid (each linking to its error map and raw buffers), the error/time/traffic
//! table, the frame plans, and the accuracy–time Pareto plot and the tile-size experiment
//! where their outputs lie next to the page, and the peers' side-by-side timings
//! (`scripts/peers/run.py`, issue 32) where its `peers.json` does.
//!
//! The page is built from the runs in memory ([`crate::render::MethodRun`]) and the names of
//! the files [`crate::render::write_runs`] wrote; nothing is read back but the experiments'
//! results. Every link is a relative path to a file the run or an experiment wrote, so the
//! folder can be moved or archived as a whole; nothing is loaded from the network and there
//! is no script (the error-map toggle is a CSS checkbox). The page is well-formed XHTML
//! ([`html::Html`] escapes every text and closes every element), so scene names from user
//! files cannot break it.
//!
//! | module | part of the page |
//! |---|---|
//! | [`gallery`] | the image grid and the error-map legend |
//! | [`table`] | the table and the notes under it |
//! | [`plan`] | the frame plans in a collapsible `<details>` |
//! | [`experiments`] | the accuracy–time and tile-size results found next to the page |
//! | [`peers`] | the peers' results (Mitsuba 3, llvmpipe) found next to the page |
//! | [`html`] | escaping, links, the element builder |

pub mod experiments;
pub mod gallery;
pub mod html;
pub mod peers;
pub mod plan;
pub mod table;

use crate::render::{scene_title, MethodRun};
use crate::scene::Scene;
use html::Html;
use std::path::{Path, PathBuf};

/// The page's file name inside the report directory.
pub const INDEX_FILE: &str = "index.html";

/// One scene's results as the report shows them.
#[derive(Debug, Clone)]
pub struct SceneRuns<'a> {
    /// The scene as rendered (after any size or method overrides).
    pub scene: &'a Scene,
    /// Its runs, in run order ([`crate::render::render_scene`]).
    pub runs: &'a [MethodRun],
    /// The files each run wrote into its method folder, in run order
    /// ([`crate::render::write_runs`]).
    pub files: &'a [Vec<String>],
    /// The folder holding the scene's method folders, relative to the report's directory
    /// (empty when they are in it).
    pub dir: PathBuf,
}

impl SceneRuns<'_> {
    /// The link to `file` of method `method`, relative to the report's directory.
    fn link(&self, method: &str, file: &str) -> String {
        html::url(&self.dir.join(method).join(file))
    }
}

/// The style sheet: a grid of figures, compact tables, the error-map toggle. No `<` or `&`,
/// so that it is valid XML text.
const STYLE: &str = "
body { font: 14px/1.4 system-ui, sans-serif; margin: 1.5em; color: #222; max-width: 1600px; }
h1 { margin: 0 0 .2em; } h2 { margin-top: 1.6em; border-bottom: 1px solid #ccc; }
.grid { display: grid; grid-template-columns: repeat(auto-fill, minmax(170px, 1fr)); gap: 12px; }
figure { margin: 0; background: #f6f6f6; padding: 6px; border-radius: 4px; }
figure img { width: 100%; height: auto; image-rendering: pixelated; display: block; }
figure.reference { outline: 2px solid #555; }
figcaption { font-size: 12px; margin-top: 4px; }
figcaption .paper { color: #666; display: block; }
figcaption .files a { margin-right: .5em; }
figcaption .files a.buffer { font-weight: bold; }
figcaption .buffers { display: block; }
img.err { display: none; }
.toggle:checked ~ .grid img.swap { display: none; }
.toggle:checked ~ .grid img.err { display: block; }
.legend { display: inline-block; width: 240px; height: 12px; vertical-align: middle; border: 1px solid #999; }
table { border-collapse: collapse; margin: .8em 0; font-size: 13px; }
th, td { border: 1px solid #ccc; padding: 2px 6px; text-align: right; }
th { background: #eee; } td.name, th.name, td.text { text-align: left; }
tr.reference td { background: #f4f4fb; }
.notes { font-size: 12px; color: #444; }
pre { font-size: 11px; background: #f6f6f6; padding: 4px; overflow-x: auto; }
details { margin: .6em 0; } summary { cursor: pointer; font-weight: bold; }
.pareto img { max-width: 1000px; width: 100%; }
";

/// The page for `scenes`, whose report directory is `dir` (where the experiments' results are
/// looked for, [`experiments::Found`]).
pub fn page(dir: &Path, scenes: &[SceneRuns]) -> String {
    let found = experiments::Found::look(dir);
    let (peer_results, peer_problems) = peers::look(dir);
    let mut h = Html::new();
    h.raw("<!DOCTYPE html>\n");
    h.open(
        "html",
        &[("xmlns", "http://www.w3.org/1999/xhtml"), ("lang", "en")],
    );
    h.open("head", &[]);
    h.void("meta", &[("charset", "utf-8")]);
    h.element("title", &[], "penumbra report");
    h.open("style", &[]).raw(STYLE).close();
    h.close();
    h.open("body", &[]);
    h.element("h1", &[], "penumbra report");
    h.open("p", &[]).text(&format!(
        "{} scene{} rendered by penumbra {}; every method against the reference, {}. ",
        scenes.len(),
        if scenes.len() == 1 { "" } else { "s" },
        env!("CARGO_PKG_VERSION"),
        crate::methods::REFERENCE
    ));
    gallery::legend(&mut h);
    h.close();
    h.open("ul", &[]);
    for (i, s) in scenes.iter().enumerate() {
        h.open("li", &[]);
        h.element(
            "a",
            &[("href", &format!("#{}", section_id(i)))],
            &s.scene.source,
        );
        h.close();
    }
    if found.tile_size.is_some() {
        h.open("li", &[]);
        h.element("a", &[("href", "#tile-size")], "tile-size experiment");
        h.close();
    }
    if found.precision.is_some() {
        h.open("li", &[]);
        h.element("a", &[("href", "#precision")], "precision experiment");
        h.close();
    }
    if found.cost_growth.is_some() {
        h.open("li", &[]);
        h.element("a", &[("href", "#cost-growth")], "cost-growth experiment");
        h.close();
    }
    for (i, (rel, _)) in peer_results.iter().enumerate() {
        h.open("li", &[]);
        let text = format!("peers ({})", rel.join(peers::JSON_FILE).display());
        h.element("a", &[("href", &format!("#peers-{}", i + 1))], &text);
        h.close();
    }
    h.close();
    for note in found.problems.iter().chain(&peer_problems) {
        h.element("p", &[("class", "notes")], note);
    }
    for (i, s) in scenes.iter().enumerate() {
        h.open("section", &[("id", &section_id(i))]);
        h.element("h2", &[], &scene_title(s.scene));
        gallery::grid(&mut h, s, i);
        table::table(&mut h, s);
        plan::details(&mut h, s);
        found.accuracy_time(&mut h, &s.scene.source);
        h.close();
    }
    found.tile_size(&mut h);
    found.precision(&mut h);
    found.cost_growth(&mut h);
    for (i, (rel, p)) in peer_results.iter().enumerate() {
        peers::section(&mut h, dir, rel, p, &format!("peers-{}", i + 1));
    }
    h.close().close();
    h.finish()
}

/// The id of the `i`-th scene's section (scene names are not ids: they may hold anything).
fn section_id(i: usize) -> String {
    format!("scene-{}", i + 1)
}

/// Writes the page for `scenes` to `dir/index.html` ([`page`]; written to a temporary name
/// and renamed, [`crate::output::write_files_all_or_nothing`]) and returns its path.
pub fn write(dir: &Path, scenes: &[SceneRuns]) -> std::io::Result<PathBuf> {
    let page = page(dir, scenes);
    crate::output::write_files_all_or_nothing(dir, &[(INDEX_FILE.into(), page.into_bytes())])?;
    Ok(dir.join(INDEX_FILE))
}
