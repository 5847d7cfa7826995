//! Replays every fuzz input kept in the repository — the seed corpora `fuzz/corpus/TARGET/` and the
//! crashes found and fixed, `fuzz/regressions/TARGET/` — through the same code the cargo-fuzz
//! targets run (`fuzz/fuzz_targets/common.rs`, included here), so `cargo test` catches a regression
//! without nightly or cargo-fuzz (`docs/architecture.md` "Tests": fuzz corpora and every crash
//! found are replayed by `cargo test`).
//!
//! Each input runs under `catch_unwind`; a test fails listing every input that panicked.

#[path = "../../fuzz/fuzz_targets/common.rs"]
#[allow(dead_code)] // `fuzz_scene_dir` serves the cargo-fuzz binaries; replay uses its own dirs
mod common;

use penumbra::scene::file::Format;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

/// The `fuzz/` directory of this crate.
fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz")
}

/// The input files of `target`: its corpus (which must not be empty) and its regressions
/// (which may not exist yet), sorted, hidden files skipped.
fn inputs(target: &str) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for kind in ["corpus", "regressions"] {
        let dir = fuzz_dir().join(kind).join(target);
        let Ok(entries) = std::fs::read_dir(&dir) else {
            assert_ne!(kind, "corpus", "missing seed corpus {}", dir.display());
            continue;
        };
        let before = files.len();
        files.extend(
            entries
                .map(|e| e.expect("readable corpus directory").path())
                .filter(|p| p.is_file())
                .filter(|p| {
                    !p.file_name()
                        .and_then(|n| n.to_str())
                        .is_some_and(|n| n.starts_with('.'))
                }),
        );
        assert!(
            kind != "corpus" || files.len() > before,
            "empty seed corpus {}",
            dir.display()
        );
    }
    files.sort();
    files
}

/// Runs `run` on every input of `target` and fails naming each input that panicked.
fn replay(target: &str, run: impl Fn(&[u8])) {
    let files = inputs(target);
    let failed: Vec<String> = files
        .iter()
        .filter(|path| {
            let data = std::fs::read(path).expect("readable corpus file");
            catch_unwind(AssertUnwindSafe(|| run(&data))).is_err()
        })
        .map(|p| p.display().to_string())
        .collect();
    assert!(
        failed.is_empty(),
        "{target}: {} of {} inputs panicked:\n{}",
        failed.len(),
        files.len(),
        failed.join("\n")
    );
}

/// A fresh scene directory for one test (removed again when dropped).
struct SceneDir {
    /// Root of the temporary tree.
    root: PathBuf,
    /// The directory scenes are parsed against (`root/scenes`).
    base: PathBuf,
}

impl SceneDir {
    /// Creates and fills `CARGO_TARGET_TMPDIR/fuzz-replay-NAME-PID`.
    fn new(name: &str) -> Self {
        let root = Path::new(env!("CARGO_TARGET_TMPDIR"))
            .join(format!("fuzz-replay-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        let base = common::populate_scene_dir(&root).expect("cannot create scene directory");
        Self { root, base }
    }
}

impl Drop for SceneDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.root);
    }
}

/// `scene_toml`: every TOML input parses or fails with a one-line error, without panicking.
#[test]
fn scene_toml_corpus() {
    let dir = SceneDir::new("toml");
    replay("scene_toml", |d| common::scene(d, Format::Toml, &dir.base));
}

/// `scene_json`: every JSON input parses or fails with a one-line error, without panicking.
#[test]
fn scene_json_corpus() {
    let dir = SceneDir::new("json");
    replay("scene_json", |d| common::scene(d, Format::Json, &dir.base));
}

/// `obj`: OBJ parsing, adjacency, silhouettes, loops, shadow volumes and their rasterization.
#[test]
fn obj_corpus() {
    replay("obj", common::obj);
}

/// `ply`: PLY reading (ASCII, both binary byte orders), then the `obj` path's geometry.
#[test]
fn ply_corpus() {
    replay("ply", common::ply);
}

/// `stl`: STL reading (ASCII, binary), then the `obj` path's geometry.
#[test]
fn stl_corpus() {
    replay("stl", common::stl);
}

/// `gltf`: glTF and GLB reading (no external buffers), then the `obj` path's geometry.
#[test]
fn gltf_corpus() {
    replay("gltf", common::gltf);
}

/// `raster`: setup, binning and traversal of arbitrary clip-space triangles.
#[test]
fn raster_corpus() {
    replay("raster", common::raster);
}

/// `pw_wedges`: Paper I/II wedges of validated meshes under a sphere light, light intensities,
/// and the wedges' rasterization.
#[test]
fn pw_wedges_corpus() {
    replay("pw_wedges", common::pw_wedges);
}

/// `ssv_wedge`: Paper III wedges hold the penumbra and all coverage of their edge.
#[test]
fn ssv_wedge_corpus() {
    replay("ssv_wedge", common::ssv_wedge);
}

/// `tight_wedge`: Paper IV tight wedges, their halves and polyhedron splits.
#[test]
fn tight_wedge_corpus() {
    replay("tight_wedge", common::tight_wedge);
}

/// `coverage`: exact, projected, radial-part, texture and table coverage of one edge.
#[test]
fn coverage_corpus() {
    replay("coverage", common::coverage);
}

/// The shipped scenes really reach validation in the fuzz scene directory (so the seed
/// corpus exercises more than "cannot read OBJ"): the shipped good scenes parse.
#[test]
fn shipped_scenes_parse_in_the_fuzz_directory() {
    let dir = SceneDir::new("shipped");
    for name in ["tetra-on-floor.toml", "stars.toml", "fire.toml"] {
        let text = std::fs::read_to_string(fuzz_dir().join("corpus/scene_toml").join(name))
            .expect("seed scene");
        penumbra::scene::file::parse_scene_str(&text, Format::Toml, name, &dir.base)
            .unwrap_or_else(|e| panic!("{e}"));
    }
    let text = std::fs::read_to_string(fuzz_dir().join("corpus/scene_json/torus.json"))
        .expect("seed scene");
    penumbra::scene::file::parse_scene_str(&text, Format::Json, "torus.json", &dir.base)
        .unwrap_or_else(|e| panic!("{e}"));
}
