//! The peers' results next to the page (issue 32): what `scripts/peers/run.py` wrote —
//! `peers.json` and `peers.md`, penumbra's passes side by side with Mitsuba 3 (Embree) and
//! Mesa's llvmpipe on one scene. They are looked for in the report's directory itself and in
//! each folder of `peers/` inside it (the script's default output, `out/peers/SCENE/`, so that
//! the default run's `out/index.html` finds them). The page shows each as a table of every
//! peer's passes (median, min and max seconds, runs, error against `raycast`), the rows of
//! issue 32 with their ratios, and a link to `peers.md`. The script is a benchmark run by hand;
//! nothing here runs it, and a report without its files has no peers section.

use super::html::{url, Html};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The script's JSON file.
pub const JSON_FILE: &str = "peers.json";
/// The script's Markdown table.
pub const MD_FILE: &str = "peers.md";
/// The folder of the report's directory whose subfolders are also searched.
pub const SUBDIR: &str = "peers";

/// Median, min and max of a pass's timed runs, in seconds.
#[derive(Debug, Clone, Deserialize, PartialEq)]
pub struct Seconds {
    /// Median.
    pub median: f64,
    /// Fastest run.
    pub min: f64,
    /// Slowest run.
    pub max: f64,
}

/// One timed pass of a peer.
#[derive(Debug, Clone, Deserialize, PartialEq)]
pub struct PeerPass {
    /// What was timed.
    pub name: String,
    /// Its times.
    pub seconds: Seconds,
    /// How many runs were timed.
    pub runs: u32,
    /// The pass's own error against `raycast`, where the script gives one.
    #[serde(default)]
    pub error: Option<String>,
}

/// One peer (penumbra itself, Mitsuba, llvmpipe) and its errors against `raycast`.
#[derive(Debug, Clone, Deserialize, PartialEq)]
pub struct Peer {
    /// The peer's name.
    pub name: String,
    /// Its timed passes.
    pub passes: Vec<PeerPass>,
    /// Its errors: what was compared, and the number.
    pub error: BTreeMap<String, f64>,
}

/// One row of issue 32's table: penumbra's median against a peer's.
#[derive(Debug, Clone, Deserialize, PartialEq)]
pub struct Row {
    /// What is compared.
    pub row: String,
    /// penumbra's median seconds.
    pub penumbra: f64,
    /// The peer's median seconds.
    pub peer: f64,
    /// `penumbra / peer`.
    pub ratio: f64,
    /// The goal for the ratio (met when `ratio ≤ goal`).
    pub goal: f64,
    /// The goal as the issue writes it.
    pub goal_text: String,
}

/// The contents of `peers.json`.
#[derive(Debug, Clone, Deserialize, PartialEq)]
pub struct Peers {
    /// The scene as given to the script.
    pub scene: String,
    /// The penumbra options given to the script (`--opt`), applied to every render.
    #[serde(default)]
    pub options: Vec<String>,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Timed runs per pass.
    pub runs: u32,
    /// The machine and the peers' versions.
    pub machine: String,
    /// Every peer.
    pub peers: Vec<Peer>,
    /// Issue 32's rows.
    #[serde(default)]
    pub rows: Vec<Row>,
}

/// The peers' results found around the report's directory `dir`: per result its folder
/// relative to `dir` and its contents, in folder order, and one sentence per file that could
/// not be read.
pub fn look(dir: &Path) -> (Vec<(PathBuf, Peers)>, Vec<String>) {
    let mut folders = vec![PathBuf::new()];
    if let Ok(entries) = std::fs::read_dir(dir.join(SUBDIR)) {
        let mut subs: Vec<PathBuf> = entries
            .filter_map(Result::ok)
            .filter(|e| e.path().is_dir())
            .map(|e| Path::new(SUBDIR).join(e.file_name()))
            .collect();
        subs.sort();
        folders.extend(subs);
    }
    let mut found = Vec::new();
    let mut problems = Vec::new();
    for rel in folders {
        let file = dir.join(&rel).join(JSON_FILE);
        if !file.is_file() {
            continue;
        }
        let parsed = std::fs::read_to_string(&file)
            .map_err(|e| e.to_string())
            .and_then(|text| serde_json::from_str::<Peers>(&text).map_err(|e| e.to_string()));
        match parsed {
            Ok(p) => found.push((rel, p)),
            Err(e) => problems.push(format!("not shown: {}: {e}", file.display())),
        }
    }
    (found, problems)
}

/// Seconds with three significant digits.
fn secs(s: f64) -> String {
    crate::experiment::accuracy_time::fmt_g(s)
}

/// The peers section, with the element id `id`, of one result found in folder `rel` of the
/// report's directory `root`.
pub fn section(h: &mut Html, root: &Path, rel: &Path, p: &Peers, id: &str) {
    h.open("section", &[("id", id), ("class", "peers")]);
    h.element(
        "h2",
        &[],
        &format!(
            "Peers: {} at {}×{}{}",
            p.scene,
            p.width,
            p.height,
            p.options
                .iter()
                .map(|o| format!(", {o}"))
                .collect::<String>()
        ),
    );
    h.open("p", &[]);
    h.text(&format!(
        "From scripts/peers/run.py ({}): medians of {} runs, {}. ",
        rel.join(JSON_FILE).display(),
        p.runs,
        p.machine
    ));
    let md = rel.join(MD_FILE);
    if root.join(&md).is_file() {
        h.element("a", &[("href", &url(&md))], MD_FILE);
    }
    h.close();
    h.open("table", &[]);
    h.head_row(&[
        ("name", "peer"),
        ("name", "pass"),
        ("", "median s"),
        ("", "min s"),
        ("", "max s"),
        ("", "runs"),
        ("", "error vs raycast"),
    ]);
    for peer in &p.peers {
        for pass in &peer.passes {
            h.open("tr", &[]);
            h.element("td", &[("class", "name")], &peer.name);
            h.element("td", &[("class", "name")], &pass.name);
            for s in [pass.seconds.median, pass.seconds.min, pass.seconds.max] {
                h.element("td", &[], &secs(s));
            }
            h.element("td", &[], &pass.runs.to_string());
            h.element("td", &[], pass.error.as_deref().unwrap_or(""));
            h.close();
        }
    }
    h.close();
    if !p.rows.is_empty() {
        h.open("table", &[]);
        h.head_row(&[
            ("name", "issue 32 row"),
            ("", "penumbra s"),
            ("", "peer s"),
            ("", "penumbra / peer"),
            ("", "goal"),
            ("", "met"),
        ]);
        for r in &p.rows {
            h.open("tr", &[]);
            h.element("td", &[("class", "name")], &r.row);
            h.element("td", &[], &secs(r.penumbra));
            h.element("td", &[], &secs(r.peer));
            h.element("td", &[], &format!("{:.2}×", r.ratio));
            h.element("td", &[], &r.goal_text);
            h.element("td", &[], if r.ratio <= r.goal { "yes" } else { "no" });
            h.close();
        }
        h.close();
    }
    h.open("ul", &[("class", "notes")]);
    for peer in &p.peers {
        for (what, e) in &peer.error {
            h.element("li", &[], &format!("{}, {what}: {e}", peer.name));
        }
    }
    h.close();
    h.close();
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `peers.json` as `scripts/peers/run.py` writes it, cut down to a pass per peer.
    const FIXTURE: &str = include_str!("peers_fixture.json");

    fn folder(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("penumbra-peers-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("temp dir");
        d
    }

    /// The fixture is found both in the report's directory and under `peers/SCENE/`, and
    /// its section shows every pass, the ratio, whether the goal was met and the link.
    #[test]
    fn fixture_is_found_and_shown() {
        let dir = folder("found");
        std::fs::write(dir.join(JSON_FILE), FIXTURE).expect("write");
        std::fs::write(dir.join(MD_FILE), "# Peers\n").expect("write");
        let sub = dir.join(SUBDIR).join("cube-of-spheres");
        std::fs::create_dir_all(&sub).expect("sub");
        std::fs::write(sub.join(JSON_FILE), FIXTURE).expect("write");
        let (found, problems) = look(&dir);
        assert!(problems.is_empty(), "{problems:?}");
        assert_eq!(found.len(), 2);
        assert_eq!(found[0].0, PathBuf::new());
        assert_eq!(found[1].0, Path::new("peers/cube-of-spheres"));
        let p = &found[0].1;
        assert_eq!(p.scene, "cube-of-spheres");
        assert_eq!(p.peers.len(), 3);
        assert_eq!(p.peers[1].passes[0].seconds.median, 0.0251);

        let mut h = Html::new();
        section(&mut h, &dir, &found[0].0, p, "peers-1");
        let page = h.finish();
        for want in [
            "Peers: cube-of-spheres at 256×256, hard-sv.mode=zfail",
            "mitsuba-embree",
            "llvmpipe",
            "shadow rays, 16 samples",
            "0.0251",
            "4.18×",
            "<td>no</td>",
            "<td>yes</td>",
            "href=\"peers.md\"",
        ] {
            assert!(page.contains(want), "missing {want:?} in {page}");
        }
        // Without its peers.md the section has no link.
        let mut h = Html::new();
        section(&mut h, &dir, &found[1].0, &found[1].1, "peers-2");
        assert!(!h.finish().contains("peers.md\""));
        std::fs::remove_dir_all(&dir).expect("clean up");
    }

    /// A broken peers.json is named among the problems, not shown, and no file: nothing.
    #[test]
    fn broken_or_missing_files() {
        let dir = folder("broken");
        assert_eq!(look(&dir), (vec![], vec![]));
        std::fs::write(dir.join(JSON_FILE), "{\"scene\": 3}").expect("write");
        let (found, problems) = look(&dir);
        assert!(found.is_empty());
        assert_eq!(problems.len(), 1);
        assert!(problems[0].contains(JSON_FILE), "{}", problems[0]);
        std::fs::remove_dir_all(&dir).expect("clean up");
    }
}
