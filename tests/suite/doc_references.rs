//! Prose references to a section of a document (issue 31): comments and docs cite a section as
//! the document's path followed by the section's heading in double quotes, e.g. the
//! `Layout` section of `docs/architecture.md` (written with the path in backticks or not, on
//! one line or with the quoted heading on the next comment line). Nothing but this test checks
//! them, so a renamed or removed heading left them pointing nowhere.
//!
//! Choice: a reference holds when the file exists and has a Markdown heading (`#` to `######`)
//! whose text is the quoted section or starts with it (`"Passes"` for "Passes: the
//! recorder"), as a reader finds it by the heading's first words.

use std::path::{Path, PathBuf};

/// Where references are looked for: directories (walked) and single files, from the crate root.
const ROOTS: [&str; 6] = [
    "src",
    "tests",
    "benches",
    "docs",
    "README.md",
    "CONTRIBUTING.md",
];

/// One reference: where it is, the document and the section it names.
#[derive(Debug)]
struct Reference {
    place: String,
    document: String,
    section: String,
}

/// The `.rs` and `.md` files under `path` (itself, if a file), sorted.
fn text_files(path: &Path, out: &mut Vec<PathBuf>) {
    if path.is_dir() {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(path)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        entries.sort();
        for e in entries {
            text_files(&e, out);
        }
    } else if path.extension().is_some_and(|e| e == "rs" || e == "md") {
        out.push(path.to_path_buf());
    }
}

/// Whether `c` can be part of a document path.
fn path_char(c: u8) -> bool {
    c.is_ascii_alphanumeric() || matches!(c, b'_' | b'-' | b'.' | b'/')
}

/// The references in `text` (of the file `name`): a `docs/…​.md` path, an optional closing
/// backtick, at least one blank — across a line break also the next line's comment marker
/// (`//!`, `///`, `//`) — and a double-quoted section on the same or the next line.
fn references(name: &str, text: &str) -> Vec<Reference> {
    let bytes = text.as_bytes();
    let mut found = Vec::new();
    let mut from = 0;
    while let Some(k) = text[from..].find("docs/") {
        let start = from + k;
        from = start + 5;
        // A path starts here, not inside a longer one (`src/docs/…`).
        if start > 0 && path_char(bytes[start - 1]) && bytes[start - 1] != b'.' {
            continue;
        }
        let mut end = start;
        while end < bytes.len() && path_char(bytes[end]) {
            end += 1;
        }
        let document = text[start..end].trim_end_matches('.');
        if !document.ends_with(".md") {
            continue;
        }
        let mut i = start + document.len();
        if bytes.get(i) == Some(&b'`') {
            i += 1;
        }
        let (mut lines, blank_from) = (0, i);
        while i < bytes.len() {
            match bytes[i] {
                b' ' | b'\t' => i += 1,
                b'\n' if lines == 0 => {
                    lines += 1;
                    i += 1;
                    while i < bytes.len() && matches!(bytes[i], b' ' | b'\t') {
                        i += 1;
                    }
                    for marker in ["//!", "///", "//"] {
                        if text[i..].starts_with(marker) {
                            i += marker.len();
                            break;
                        }
                    }
                }
                _ => break,
            }
        }
        // At least one blank before the quote: `"docs/x.md", "y"` is two strings, not a
        // reference.
        if i == blank_from || bytes.get(i) != Some(&b'"') {
            continue;
        }
        let Some(close) = text[i + 1..].find(['"', '\n']) else {
            continue;
        };
        if bytes[i + 1 + close] != b'"' {
            continue;
        }
        let line = text[..start].matches('\n').count() + 1;
        found.push(Reference {
            place: format!("{name}:{line}"),
            document: document.to_string(),
            section: text[i + 1..i + 1 + close].to_string(),
        });
    }
    found
}

/// The heading texts of the Markdown file at `path`, or `None` when it does not exist.
fn headings(path: &Path) -> Option<Vec<String>> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut in_code = false;
    let mut out = Vec::new();
    for line in text.lines() {
        if line.starts_with("```") {
            in_code = !in_code;
        }
        let hashes = line.bytes().take_while(|&b| b == b'#').count();
        if !in_code && (1..=6).contains(&hashes) && line[hashes..].starts_with(' ') {
            out.push(line[hashes..].trim().to_string());
        }
    }
    Some(out)
}

/// The broken references among `refs` under the crate root `root`, one message each.
fn broken(root: &Path, refs: &[Reference]) -> Vec<String> {
    refs.iter()
        .filter_map(|r| match headings(&root.join(&r.document)) {
            None => Some(format!("{}: {} does not exist", r.place, r.document)),
            Some(h) if !h.iter().any(|h| h.starts_with(&r.section)) => Some(format!(
                "{}: {} has no heading \"{}\"",
                r.place, r.document, r.section
            )),
            Some(_) => None,
        })
        .collect()
}

#[test]
fn every_section_reference_names_a_heading_of_an_existing_document() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for r in ROOTS {
        text_files(&root.join(r), &mut files);
    }
    let mut refs = Vec::new();
    for f in &files {
        let name = f.strip_prefix(root).unwrap().display().to_string();
        refs.extend(references(&name, &std::fs::read_to_string(f).unwrap()));
    }
    eprintln!("{} section references in {} files", refs.len(), files.len());
    // Not vacuous: the count of the issue (about 35) was found when this test was written.
    assert!(refs.len() >= 35, "only {} references found", refs.len());
    let bad = broken(root, &refs);
    assert!(bad.is_empty(), "stale references:\n{}", bad.join("\n"));
}

/// The scanner finds the forms in use and the checker rejects what it should: a reference on
/// one line with and without backticks, one split across two comment lines, a missing file, a
/// missing heading; and a heading's first words are enough.
#[test]
fn the_scanner_finds_every_form_and_the_checker_names_the_place() {
    let q = '"';
    let text = format!(
        "a (`docs/architecture.md` {q}Layout{q}) b\n\
         c docs/architecture.md {q}Passes{q}\n\
         //! (`docs/architecture.md`\n//! {q}Tests{q})\n\
         docs/nowhere.md {q}Layout{q}\n\
         `docs/architecture.md` {q}No such heading{q}\n\
         `docs/architecture.md` is cited without a section\n\
         (\"docs/architecture.md{q}, {q}Layout{q}) are two strings\n"
    );
    let refs = references("x.rs", &text);
    let got: Vec<(&str, &str, &str)> = refs
        .iter()
        .map(|r| (r.place.as_str(), r.document.as_str(), r.section.as_str()))
        .collect();
    assert_eq!(
        got,
        [
            ("x.rs:1", "docs/architecture.md", "Layout"),
            ("x.rs:2", "docs/architecture.md", "Passes"),
            ("x.rs:3", "docs/architecture.md", "Tests"),
            ("x.rs:5", "docs/nowhere.md", "Layout"),
            ("x.rs:6", "docs/architecture.md", "No such heading"),
        ]
    );
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    assert_eq!(
        broken(root, &refs),
        [
            "x.rs:5: docs/nowhere.md does not exist".to_string(),
            format!("x.rs:6: docs/architecture.md has no heading {q}No such heading{q}"),
        ]
    );
}
