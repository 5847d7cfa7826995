//! The HTML report (`penumbra report`, `penumbra::report`): the page of two scenes parses as
//! XML (roxmltree, a strict parser: the page is written as XHTML), every link and image refers
//! to a file that exists, every method table has one row per method that ran, a scene file
//! name with markup characters is shown escaped, the accuracy–time and tile-size results next
//! to the page are shown, a bad scene writes nothing, and with `--dump-buffers` every buffer
//! dump is linked (its viewable image, raw values, sidecar and event map, all existing files).
//! Small frames (32²), three methods, `raycast.samples=16`.

use penumbra::experiment::accuracy_time::{self, Configuration, Shard};
use penumbra::experiment::{cost_growth, sized, tile_size};
use penumbra::scene::{builtin, file};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A fresh, not yet existing directory under `CARGO_TARGET_TMPDIR`, unique per call.
fn fresh_dir(tag: &str) -> PathBuf {
    static N: AtomicUsize = AtomicUsize::new(0);
    let n = N.fetch_add(1, Ordering::Relaxed);
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("report-{tag}-{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn penumbra(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(args)
        .output()
        .expect("run penumbra")
}

/// `scenes/tetra-on-floor.toml` copied to `dir/NAME` with its models by absolute path.
fn weird_scene(dir: &Path, name: &str) -> PathBuf {
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/tetra-on-floor.toml"),
    )
    .unwrap()
    .replace("\"models/", &format!("\"{}/", models.display()));
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// `%XX` escapes of a link decoded (the page percent-encodes every byte but `A–Z a–z 0–9
/// -._~` and `/`).
fn percent_decoded(link: &str) -> String {
    let b = link.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            out.push(u8::from_str_radix(&link[i + 1..i + 3], 16).unwrap());
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).unwrap()
}

/// The page parsed strictly, with every `href`/`src` checked: a `#id` names an element of
/// the page, anything else is a relative path to an existing file under `dir`.
fn parse_and_check_links<'a>(dir: &Path, text: &'a str) -> roxmltree::Document<'a> {
    let options = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    };
    let doc = roxmltree::Document::parse_with_options(text, options)
        .unwrap_or_else(|e| panic!("the page is not well-formed XML: {e}"));
    let mut links = 0;
    for node in doc.descendants().filter(|n| n.is_element()) {
        for attr in ["href", "src"] {
            let Some(link) = node.attribute(attr) else {
                continue;
            };
            links += 1;
            if let Some(id) = link.strip_prefix('#') {
                assert!(
                    doc.descendants().any(|n| n.attribute("id") == Some(id)),
                    "no element with id {id}"
                );
                continue;
            }
            assert!(
                !link.contains("://") && !link.starts_with('/'),
                "not a relative link: {link}"
            );
            let path = dir.join(percent_decoded(link));
            assert!(
                path.is_file(),
                "{attr}={link:?}: {} is missing",
                path.display()
            );
        }
    }
    assert!(links > 0);
    doc
}

/// The text of an element and its descendants.
fn text_of(n: roxmltree::Node) -> String {
    n.descendants()
        .filter(|d| d.is_text())
        .filter_map(|d| d.text())
        .collect()
}

fn has_class(n: &roxmltree::Node, class: &str) -> bool {
    n.attribute("class")
        .is_some_and(|c| c.split(' ').any(|x| x == class))
}

/// The configurations of the small accuracy–time sweep written next to the page.
const TINY: &[Configuration] = &[("hard-sv", &[]), ("ssv", &[])];

#[test]
fn a_report_of_two_scenes_links_existing_files_and_shows_every_method() {
    let root = fresh_dir("two");
    let name = "a<b & c>'\".toml";
    let weird = weird_scene(&root.join("scenes"), name);
    let weird_arg = weird.to_str().unwrap();
    let out = root.join("out");
    // Experiments' results where their commands write by default, relative to the out dir.
    let scenes = [
        sized(builtin::load("single-quad").unwrap(), 32),
        sized(file::resolve(weird_arg).unwrap(), 32),
    ];
    let sweep = accuracy_time::run(
        &scenes,
        TINY,
        1,
        Shard::WHOLE,
        &[penumbra::gpu_model::GpuModel::default()],
    )
    .unwrap();
    accuracy_time::write(&sweep, &out.join("experiment/accuracy-time")).unwrap();
    let pw = sized(builtin::load("pw-2002").unwrap(), 32);
    let summary = tile_size::run(&pw, &out.join("experiment")).unwrap();
    // The tile-size experiment writes its summary next to its CSV, and its plot as SVG and PNG.
    let written = std::fs::read_to_string(out.join("experiment").join(tile_size::SUMMARY_FILE));
    assert_eq!(written.unwrap(), summary);
    assert!(out.join("experiment").join(tile_size::PNG_FILE).is_file());
    // A cost-growth result (two points written as the experiment writes them; the experiment
    // itself is run by tests/suite/cost_growth.rs).
    let plan = cost_growth::Plan {
        triangles: vec![288, 1088],
        meshes: Vec::new(),
        size: 32,
        sizes: vec![32],
        methods: vec!["hard-sv".into()],
        runs: 1,
        threads: 1,
        opts: Vec::new(),
    };
    let point = |triangles: usize, seconds: f64| cost_growth::Point {
        workload: format!("bumpy-{triangles}"),
        bumpy: true,
        triangles,
        became: "closed".into(),
        size: 32,
        method: "hard-sv".into(),
        light: "rect",
        seconds: [seconds; 3],
        process_seconds: 2.0 * seconds,
        peak_bytes: Some(20 << 20),
        estimate_bytes: 70 << 20,
    };
    let points = [point(288, 0.01), point(1088, 0.02)];
    cost_growth::write(&plan, &points, &out.join("cost-growth")).unwrap();

    let o = penumbra(&[
        "report",
        "single-quad",
        weird_arg,
        "--width",
        "32",
        "--height",
        "32",
        "--methods",
        "raycast,hard-sv,ssv",
        "--opt",
        "raycast.samples=16",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stdout}\n{stderr}");
    // Not on a terminal: no progress bar.
    assert!(stderr.is_empty(), "stderr: {stderr}");
    let index = out.join("index.html");
    assert!(
        stdout.contains(&format!("report: {}", index.display())),
        "{stdout}"
    );
    let text = std::fs::read_to_string(&index).unwrap();
    let doc = parse_and_check_links(&out, &text);

    // The scene name is escaped in the markup and reads back as it is.
    assert!(text.contains("a&lt;b &amp; c&gt;&#39;&quot;.toml"));
    assert!(!text.contains(name));
    let headings: Vec<String> = doc
        .descendants()
        .filter(|n| n.has_tag_name("h2"))
        .map(text_of)
        .collect();
    assert!(headings.iter().any(|h| h.starts_with("single-quad (32×32")));
    assert!(headings.iter().any(|h| h.contains(name)), "{headings:?}");

    // One table per scene, one row per method that ran, in run order.
    let tables: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("table") && has_class(n, "methods"))
        .collect();
    assert_eq!(tables.len(), 2);
    for t in &tables {
        let rows: Vec<String> = t
            .descendants()
            .filter(|n| n.has_tag_name("tbody"))
            .flat_map(|b| b.children().filter(|r| r.has_tag_name("tr")))
            .map(|r| text_of(r.children().find(|c| c.is_element()).unwrap()))
            .collect();
        assert_eq!(rows, ["raycast (its noise floor)", "hard-sv", "ssv"]);
    }
    // Every method of every scene in the grid, with its error map and hard-sv's stencil.
    let figures = doc
        .descendants()
        .filter(|n| n.has_tag_name("figure"))
        .count();
    assert_eq!(figures, 6);
    let srcs: Vec<&str> = doc
        .descendants()
        .filter_map(|n| n.attribute("src"))
        .collect();
    let hrefs: Vec<&str> = doc
        .descendants()
        .filter_map(|n| n.attribute("href"))
        .collect();
    assert!(srcs.contains(&"single-quad/ssv/error.png"), "{srcs:?}");
    assert!(hrefs.contains(&"single-quad/hard-sv/stencil.png"));
    assert!(hrefs.contains(&"single-quad/hard-sv/stats.json"));
    // The accuracy–time results of both scenes, on CPU time and modeled GPU time; the
    // tile-size plot once.
    let fronts = doc
        .descendants()
        .filter(|n| n.has_tag_name("ol") && has_class(n, "front"))
        .count();
    assert_eq!(fronts, 4);
    assert!(srcs.contains(&"experiment/accuracy-time/single-quad-pareto.png"));
    let gpu_plot = format!(
        "experiment/accuracy-time/single-quad-pareto-gpu-{}.png",
        penumbra::gpu_model::DEFAULT_PROFILE
    );
    assert!(srcs.contains(&gpu_plot.as_str()), "{srcs:?}");
    assert!(srcs.contains(&"experiment/tile_size.svg"));
    for stem in cost_growth::PLOTS {
        let png = format!("cost-growth/{stem}.png");
        assert!(srcs.contains(&png.as_str()), "{srcs:?}");
    }
    assert!(hrefs.contains(&"cost-growth/summary.md"), "{hrefs:?}");
    // The frame plans, collapsed.
    assert_eq!(
        doc.descendants()
            .filter(|n| n.has_tag_name("details"))
            .count(),
        2
    );
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn without_a_reference_the_page_says_so_and_links_only_what_was_written() {
    let dir = fresh_dir("no-reference");
    let mut scene = sized(builtin::load("single-quad").unwrap(), 32);
    scene.methods = Some(vec!["hard-sv".into()]);
    let runs = penumbra::render::render_scene(&scene).unwrap();
    let files = penumbra::render::write_runs(&dir.join("q"), &scene, &runs, false).unwrap();
    assert!(!files[0].iter().any(|f| f == "error.png"));
    let page = penumbra::report::write(
        &dir,
        &[penumbra::report::SceneRuns {
            scene: &scene,
            runs: &runs,
            files: &files,
            dir: "q".into(),
        }],
    )
    .unwrap();
    let text = std::fs::read_to_string(page).unwrap();
    let doc = parse_and_check_links(&dir, &text);
    assert!(text.contains("no reference in this run"));
    let cells: Vec<String> = doc
        .descendants()
        .filter(|n| n.has_tag_name("td"))
        .take(4)
        .map(text_of)
        .collect();
    assert_eq!(cells[0], "hard-sv");
    assert!(
        cells[2].contains('–'),
        "the modeled GPU time, low–high: {}",
        cells[2]
    );
    assert_eq!(cells[3], "—");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn with_dump_buffers_every_dump_is_linked_with_its_files() {
    let dir = fresh_dir("dumps");
    let o = penumbra(&[
        "report",
        "single-quad",
        "--dump-buffers",
        "--methods",
        "raycast,hard-sv,ssv,wedge-blending",
        "--width",
        "32",
        "--height",
        "32",
        "--opt",
        "raycast.samples=16",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(dir.join("index.html")).unwrap();
    let doc = parse_and_check_links(&dir, &text);
    let buffers: Vec<(String, &str)> = doc
        .descendants()
        .filter(|n| n.has_tag_name("a") && has_class(n, "buffer"))
        .map(|n| (text_of(n), n.attribute("href").unwrap()))
        .collect();
    // Every dump of every method, linking to its viewable image.
    for (method, name) in [
        ("hard-sv", "stencil"),
        ("ssv", "vbuffer"),
        ("wedge-blending", "penumbrae"),
        ("wedge-blending", "final-occlusion"),
        ("wedge-blending", "stencil-sum"),
    ] {
        let href = format!("single-quad/{method}/{name}.view.png");
        assert!(
            buffers.iter().any(|(t, h)| t == name && *h == href),
            "{method} {name}: {buffers:?}"
        );
    }
    assert!(!buffers.iter().any(|(_, h)| h.contains("/raycast/")));
    // Beside each: its raw values, its sidecar and (where it has one) its event map.
    let hrefs: Vec<&str> = doc
        .descendants()
        .filter_map(|n| n.attribute("href"))
        .collect();
    for f in [
        "hard-sv/stencil.png",
        "hard-sv/stencil.json",
        "hard-sv/stencil.events.png",
        "ssv/vbuffer.bin",
        "ssv/vbuffer.events.png",
        "wedge-blending/final-rects.bin",
    ] {
        assert!(hrefs.contains(&format!("single-quad/{f}").as_str()), "{f}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_bad_scene_exits_2_and_writes_nothing() {
    let dir = fresh_dir("bad");
    let out = dir.join("out");
    let bad = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bad/malformed.toml");
    for second in [bad.to_str().unwrap(), "no-such-scene"] {
        let o = penumbra(&[
            "report",
            "single-quad",
            second,
            "--width",
            "32",
            "--height",
            "32",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{second}");
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(!out.exists(), "{second}: {} was written", out.display());
    }
    // With buffer dumps asked for, the same: the bad scene is found before anything renders.
    let o = penumbra(&[
        "report",
        "single-quad",
        bad.to_str().unwrap(),
        "--dump-buffers",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!out.exists());
}
