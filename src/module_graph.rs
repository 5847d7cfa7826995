//! The dependency graph of the crate's top-level modules points down (`docs/architecture.md`
//! "Layout"): a test reads every source file, takes each `crate::MODULE` path written in code
//! (comment lines, where rustdoc links may point anywhere, and the `#[cfg(test)] mod tests`
//! blocks at the end of a file are not dependencies) as an edge from the file's top-level
//! module to MODULE, and fails on a cycle, naming the modules and the files of every edge in it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Top-level module name → the source files it is made of.
fn top_level_modules(src: &Path) -> BTreeMap<String, Vec<PathBuf>> {
    let mut modules = BTreeMap::new();
    for entry in std::fs::read_dir(src).expect("src/ is readable") {
        let path = entry.expect("a directory entry").path();
        let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
        if name == "main" || name == "lib" {
            continue;
        }
        if path.is_dir() {
            let mut files = Vec::new();
            collect_rust_files(&path, &mut files);
            modules.insert(name.to_string(), files);
        } else if path.extension().is_some_and(|e| e == "rs") {
            modules.insert(name.to_string(), vec![path.clone()]);
        }
    }
    modules
}

fn collect_rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("a readable module directory") {
        let path = entry.expect("a directory entry").path();
        if path.is_dir() {
            collect_rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The code of a source file that counts as dependencies: without comment lines and without
/// its trailing unit-test module.
fn code_of(text: &str) -> String {
    let end = text.find("#[cfg(test)]\nmod tests").unwrap_or(text.len());
    text[..end]
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The module names `code` reaches as `crate::NAME`.
fn crate_paths(code: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    for (i, _) in code.match_indices("crate::") {
        // Not the tail of a longer identifier (`penumbra_crate::` and the like).
        let before = code[..i].chars().next_back();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let name: String = code[i + "crate::".len()..]
            .chars()
            .take_while(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || *c == '_')
            .collect();
        if !name.is_empty() {
            found.insert(name);
        }
    }
    found
}

/// Edge (from, to) → the files of `from` that use `to`.
type Edges = BTreeMap<(String, String), BTreeSet<String>>;

fn module_edges(src: &Path) -> (BTreeSet<String>, Edges) {
    let modules = top_level_modules(src);
    let names: BTreeSet<String> = modules.keys().cloned().collect();
    let mut edges = Edges::new();
    for (from, files) in &modules {
        for file in files {
            let text = std::fs::read_to_string(file).expect("a readable source file");
            for to in crate_paths(&code_of(&text)) {
                if names.contains(&to) && &to != from {
                    let shown = file.strip_prefix(src).unwrap_or(file).display().to_string();
                    edges.entry((from.clone(), to)).or_default().insert(shown);
                }
            }
        }
    }
    (names, edges)
}

/// The strongly connected components of more than one module (Tarjan), each sorted.
fn cycles(names: &BTreeSet<String>, edges: &Edges) -> Vec<Vec<String>> {
    struct Walk<'a> {
        next: BTreeMap<&'a str, Vec<&'a str>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on_stack: BTreeSet<&'a str>,
        found: Vec<Vec<String>>,
    }
    impl<'a> Walk<'a> {
        fn visit(&mut self, v: &'a str) {
            let i = self.index.len();
            self.index.insert(v, i);
            self.low.insert(v, i);
            self.stack.push(v);
            self.on_stack.insert(v);
            for w in self.next.get(v).cloned().unwrap_or_default() {
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let lw = self.low[w];
                    let lv = self.low.get_mut(v).expect("visited");
                    *lv = (*lv).min(lw);
                } else if self.on_stack.contains(w) {
                    let iw = self.index[w];
                    let lv = self.low.get_mut(v).expect("visited");
                    *lv = (*lv).min(iw);
                }
            }
            if self.low[v] == self.index[v] {
                let mut component = Vec::new();
                while let Some(w) = self.stack.pop() {
                    self.on_stack.remove(w);
                    component.push(w.to_string());
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    component.sort();
                    self.found.push(component);
                }
            }
        }
    }
    let mut next: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
    for (from, to) in edges.keys() {
        next.entry(from.as_str()).or_default().push(to.as_str());
    }
    let mut walk = Walk {
        next,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        found: Vec::new(),
    };
    for v in names {
        if !walk.index.contains_key(v.as_str()) {
            walk.visit(v);
        }
    }
    walk.found
}

#[test]
fn top_level_modules_have_no_cycle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let (names, edges) = module_edges(&src);
    assert!(names.len() > 10 && names.contains("gpu") && names.contains("methods"));
    let found = cycles(&names, &edges);
    let report: Vec<String> = found
        .iter()
        .map(|c| {
            let inside: Vec<String> = edges
                .iter()
                .filter(|((a, b), _)| c.contains(a) && c.contains(b))
                .map(|((a, b), files)| {
                    format!(
                        "  {a} -> {b} ({})",
                        Vec::from_iter(files.iter().cloned()).join(", ")
                    )
                })
                .collect();
            format!("cycle between {}:\n{}", c.join(", "), inside.join("\n"))
        })
        .collect();
    assert!(found.is_empty(), "{}", report.join("\n"));
}

/// The checker itself finds a cycle, and ignores comments, test modules and longer names.
#[test]
fn the_checker_finds_a_cycle_and_ignores_comments() {
    assert_eq!(
        crate_paths("use crate::gpu::x; let a = my_crate::scene::y; crate::limits::Z"),
        BTreeSet::from(["gpu".to_string(), "limits".to_string()])
    );
    let code = code_of(
        "use crate::a;\n/// [`crate::b`]\n  // crate::c\n#[cfg(test)]\nmod tests { use crate::d; }",
    );
    assert_eq!(crate_paths(&code), BTreeSet::from(["a".to_string()]));
    let names: BTreeSet<String> = ["a", "b", "c", "d"].map(String::from).into();
    let edge = |a: &str, b: &str| ((a.to_string(), b.to_string()), BTreeSet::new());
    let edges: Edges = [
        edge("a", "b"),
        edge("b", "c"),
        edge("c", "a"),
        edge("c", "d"),
    ]
    .into();
    assert_eq!(cycles(&names, &edges), vec![vec!["a", "b", "c"]]);
    let edges: Edges = [edge("a", "b"), edge("b", "c"), edge("a", "c")].into();
    assert!(cycles(&names, &edges).is_empty());
}
