//! The option tables as users see them: `penumbra list --options` is generated from the
//! tables' declarations, `docs/options.md` is exactly its Markdown form (`list --options
//! --markdown`, so the two cannot drift), no page (README, CONTRIBUTING, docs/) spells a key
//! in snake case, `render --help` points to the listing, and the default the listing prints
//! for every key reads back as that default. Also the pages' relative links: each points to a
//! file of the repository and, with `#anchor`, to one of its headings.

use penumbra::frame::GpuOptions;
use penumbra::methods::raycast::RaycastOptions;
use penumbra::methods::{self, dbuffer, hard_sv, nsample, penumbra_map, pw2002, pw_restructured};
use penumbra::methods::{ssv, ssv_optimized, wedge_blending};
use penumbra::options::{listing, markdown, DefaultValue, OptionTable};
use penumbra::scene::{builtin, OptionValue};
use std::collections::BTreeSet;
use std::fmt::Debug;
use std::path::Path;
use std::process::Command;

/// `penumbra ARGS`' stdout, which must succeed.
fn penumbra(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(args)
        .output()
        .expect("cannot run the penumbra binary");
    assert_eq!(out.status.code(), Some(0), "penumbra {args:?}: {out:?}");
    String::from_utf8(out.stdout).expect("UTF-8")
}

/// The crate root: README.md, docs/ and CONTRIBUTING.md are read from there.
fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The hand-written and generated Markdown pages users read: README.md, CONTRIBUTING.md and
/// every `docs/*.md`, as (path relative to the root, text), sorted by path.
fn pages() -> Vec<(String, String)> {
    let mut names = vec!["README.md".to_string(), "CONTRIBUTING.md".to_string()];
    for entry in std::fs::read_dir(root().join("docs")).expect("docs/") {
        let name = entry.expect("docs/ entry").file_name();
        let name = name.to_str().expect("UTF-8 file name");
        if name.ends_with(".md") {
            names.push(format!("docs/{name}"));
        }
    }
    names.sort();
    names
        .into_iter()
        .map(|n| {
            let text =
                std::fs::read_to_string(root().join(&n)).unwrap_or_else(|e| panic!("{n}: {e}"));
            (n, text)
        })
        .collect()
}

/// The (table, key) pairs a listing names: `[options.TABLE]` headers and `  KEY = …` lines.
fn keys_of(listing: &str) -> BTreeSet<(String, String)> {
    let mut table = String::new();
    let mut keys = BTreeSet::new();
    for line in listing.lines() {
        if let Some(name) = line.strip_prefix("[options.") {
            table = name.trim_end_matches(']').to_string();
        } else if let Some((key, _)) = line.strip_prefix("  ").and_then(|l| l.split_once(" = ")) {
            if !key.starts_with(' ') {
                keys.insert((table.clone(), key.to_string()));
            }
        }
    }
    keys
}

#[test]
fn the_listing_has_every_table_and_is_what_the_program_prints() {
    let printed = penumbra(&["list", "--options"]);
    assert_eq!(printed, listing(&methods::option_docs()));
    // Every table, every key: at least one key per table and the tables the registry has.
    let code = keys_of(&printed);
    let tables: BTreeSet<&str> = code.iter().map(|(t, _)| t.as_str()).collect();
    let expected: BTreeSet<&str> = ["gpu"].into_iter().chain(methods::names()).collect();
    assert_eq!(tables, expected);
    let declared: usize = methods::option_docs().iter().map(|(_, k)| k.len()).sum();
    assert_eq!(code.len(), declared, "a key is listed twice or not at all");
}

/// The command that regenerates docs/options.md, as the failure message says it.
const REGENERATE: &str = "cargo run --release -- list --options --markdown > docs/options.md";

#[test]
fn docs_options_md_is_what_the_code_generates() {
    let printed = penumbra(&["list", "--options", "--markdown"]);
    assert_eq!(printed, markdown(&methods::option_docs()));
    let page = std::fs::read_to_string(root().join("docs/options.md")).expect("docs/options.md");
    assert!(
        page == printed,
        "docs/options.md is not what the code generates: run `{REGENERATE}` and commit it"
    );
    // The page names every key of every table, each in its table's section.
    for (table, keys) in methods::option_docs() {
        let section = page
            .split_once(&format!("\n## `[options.{table}]`\n"))
            .unwrap_or_else(|| panic!("docs/options.md has no section [options.{table}]"))
            .1;
        let section = section.split_once("\n## ").map_or(section, |(s, _)| s);
        for k in keys {
            assert!(
                section.contains(&format!("\n| `{}` | ", k.key)),
                "docs/options.md [options.{table}] lacks {}",
                k.key
            );
        }
    }
}

#[test]
fn markdown_escapes_the_bar_in_cells() {
    // dbuffer's eq3 meaning writes |cx| and ssv's filter values are `a | b | c`: each `|`
    // inside a cell is `\|`, so every key's row has exactly the table's five separators.
    let page = markdown(&methods::option_docs());
    let rows: Vec<&str> = page.lines().filter(|l| l.starts_with("| `")).collect();
    let declared: usize = methods::option_docs().iter().map(|(_, k)| k.len()).sum();
    assert_eq!(rows.len(), declared);
    for row in rows {
        let unescaped = row.replace("\\|", "");
        assert_eq!(unescaped.matches('|').count(), 5, "{row}");
    }
    assert!(
        page.contains("(\\|cx\\| − \\|cx_s\\|)"),
        "dbuffer eq3's meaning"
    );
}

#[test]
fn keys_are_kebab_case_unique_and_documented() {
    for (table, keys) in methods::option_docs() {
        let mut seen = BTreeSet::new();
        for k in &keys {
            assert!(
                !k.key.is_empty()
                    && k.key
                        .chars()
                        .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'),
                "[options.{table}] {}: not kebab-case",
                k.key
            );
            assert!(seen.insert(&k.key), "[options.{table}] {} twice", k.key);
            assert!(
                !k.meaning.is_empty(),
                "[options.{table}] {}: no meaning",
                k.key
            );
            let (DefaultValue::Written(d) | DefaultValue::FromScene(d)) = &k.default;
            assert!(!d.is_empty(), "[options.{table}] {}: no default", k.key);
        }
    }
}

/// A paragraph may write a key's old snake-case spelling only to say what it is now: beside
/// the kebab-case key (docs/accuracy-time.md on its plots' labels).
#[test]
fn no_page_spells_a_key_in_snake_case_but_beside_its_name() {
    let pages = pages();
    for (table, keys) in methods::option_docs() {
        for k in keys.iter().filter(|k| k.key.contains('-')) {
            let snake = k.key.replace('-', "_");
            for written in [
                format!("`{snake}`"),
                format!("{snake} ="),
                format!("{snake}="),
            ] {
                for (name, text) in &pages {
                    for paragraph in text.split("\n\n") {
                        assert!(
                            !paragraph.contains(&written) || paragraph.contains(&k.key),
                            "{name} writes {written:?}; [options.{table}] spells it {}",
                            k.key
                        );
                    }
                }
            }
        }
    }
}

/// Pages that other branches add, linked before they are merged: a link to one of these may
/// point to a missing file. Once a file exists, the test fails until it is removed here.
const ARRIVING: &[&str] = &[];

/// The lines of a Markdown text outside fenced code blocks.
fn prose_lines(text: &str) -> Vec<&str> {
    let mut lines = Vec::new();
    let mut in_code = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_code = !in_code;
        } else if !in_code {
            lines.push(line);
        }
    }
    lines
}

/// The anchors of a Markdown text's headings, as GitHub makes them: the heading's text in
/// lower case, letters, digits, `-` and `_` kept, spaces made `-`, everything else dropped.
fn anchors(text: &str) -> BTreeSet<String> {
    prose_lines(text)
        .into_iter()
        .filter_map(|l| {
            l.trim_start_matches('#')
                .strip_prefix(' ')
                .filter(|_| l.starts_with('#'))
        })
        .map(|heading| {
            heading
                .trim()
                .to_lowercase()
                .chars()
                .filter_map(|c| match c {
                    ' ' => Some('-'),
                    '-' | '_' => Some(c),
                    c if c.is_alphanumeric() => Some(c),
                    _ => None,
                })
                .collect()
        })
        .collect()
}

/// The targets of the inline links `](TARGET)` of a Markdown text, outside code blocks.
fn link_targets(text: &str) -> Vec<String> {
    let mut targets = Vec::new();
    for line in prose_lines(text) {
        let mut rest = line;
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let Some(end) = after.find(')') else { break };
            targets.push(after[..end].to_string());
            rest = &after[end..];
        }
    }
    targets
}

#[test]
fn every_relative_link_of_the_pages_points_to_a_file_and_heading() {
    let mut broken = Vec::new();
    for (name, text) in pages() {
        let dir = Path::new(&name).parent().expect("a page's directory");
        for target in link_targets(&text) {
            if target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            let (file, anchor) = target.split_once('#').unwrap_or((&target, ""));
            if file.is_empty() {
                if !anchors(&text).contains(anchor) {
                    broken.push(format!("{name}: ({target}): no such heading"));
                }
                continue;
            }
            let path = dir.join(file);
            let normal: String = path
                .components()
                .fold(Vec::<&str>::new(), |mut parts, c| {
                    match c {
                        std::path::Component::ParentDir => {
                            parts.pop();
                        }
                        std::path::Component::Normal(p) => parts.push(p.to_str().expect("UTF-8")),
                        _ => {}
                    }
                    parts
                })
                .join("/");
            if ARRIVING.contains(&normal.as_str()) {
                continue;
            }
            match std::fs::read_to_string(root().join(&normal)) {
                Err(_) if !root().join(&normal).exists() => {
                    broken.push(format!("{name}: ({target}) -> {normal}: no such file"));
                }
                Ok(linked) if !anchor.is_empty() && !anchors(&linked).contains(anchor) => {
                    broken.push(format!("{name}: ({target}): no such heading in {normal}"));
                }
                _ => {}
            }
        }
    }
    assert!(broken.is_empty(), "broken links: {broken:#?}");
    for arriving in ARRIVING {
        assert!(
            !root().join(arriving).exists(),
            "{arriving} exists now: remove it from ARRIVING in tests/suite/options.rs"
        );
    }
}

#[test]
fn link_targets_and_anchors_read_markdown_outside_code() {
    let text = "see [a](a.md) and [b](../b.md#x)\n```\n[c](c.md)\n# Not\n```\n![d](d.png)\n\
                ## The GPU: `[options.gpu]`\n### Errors and exit_codes\n#hashtag";
    assert_eq!(link_targets(text), ["a.md", "../b.md#x", "d.png"]);
    let expected: BTreeSet<String> = ["the-gpu-optionsgpu", "errors-and-exit_codes"]
        .map(String::from)
        .into();
    assert_eq!(anchors(text), expected);
}

#[test]
fn render_help_points_to_the_listing() {
    let help = penumbra(&["render", "--help"]);
    assert!(help.contains("penumbra list --options"), "{help}");
}

/// Every printed default of table `O`, set as the scene file writes it (a string) and as
/// `--opt` does, reads back as the default; returns the table's name.
fn printed_defaults_read_back<O: OptionTable + PartialEq + Debug>() -> &'static str {
    for key in O::keys() {
        let DefaultValue::Written(text) = &key.default else {
            continue;
        };
        for value in [OptionValue::Str(text.clone()), OptionValue::parse_cli(text)] {
            let mut scene = builtin::load("single-quad").unwrap();
            scene
                .options
                .entry(O::NAME.into())
                .or_default()
                .insert(key.key.clone(), value.clone());
            let read = O::read(&scene).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(
                read,
                O::default(),
                "[options.{}] {} = {value}",
                O::NAME,
                key.key
            );
        }
    }
    O::NAME
}

#[test]
fn every_printed_default_reads_back_as_the_default() {
    let checked = [
        printed_defaults_read_back::<GpuOptions>(),
        printed_defaults_read_back::<RaycastOptions>(),
        printed_defaults_read_back::<nsample::NsampleOptions>(),
        printed_defaults_read_back::<hard_sv::HardSvOptions>(),
        printed_defaults_read_back::<pw2002::Pw2002Options>(),
        printed_defaults_read_back::<pw_restructured::PwRestructuredOptions>(),
        printed_defaults_read_back::<ssv_optimized::SsvOptimizedOptions>(),
        printed_defaults_read_back::<ssv::SsvOptions>(),
        printed_defaults_read_back::<wedge_blending::WedgeBlendingOptions>(),
        printed_defaults_read_back::<penumbra_map::PenumbraMapOptions>(),
        printed_defaults_read_back::<dbuffer::DBufferOptions>(),
    ];
    let all: Vec<&str> = methods::option_docs().iter().map(|(n, _)| *n).collect();
    assert_eq!(checked.to_vec(), all, "a table is not checked here");
}
