//! The catalog of pinned golden renders: every render the test suite compares bit for bit,
//! in one list, so that `penumbra golden --bless` re-blesses exactly what the tests check and a
//! method that stops supporting a scene fails the check instead of dropping out of it.
//!
//! A case is a scene (a built-in name, or a scene file under the crate root), a small size
//! (32–64 px, so the suite stays fast), one method, and the options that differ from its
//! defaults (the method's own and `[options.gpu]`). Its goldens live in
//! `golden/<scene>/<method>` for the defaults, `golden/<scene>/<method>-<variant>` otherwise
//! (the scene of a file is its file stem). Cases of the same scene, size and GPU options share
//! one rendered frame.
//!
//! Each method declares its own cases in its module ([`crate::methods::Method::goldens`]: the
//! foundation scenes it renders with its defaults, then the knobs that change what it
//! computes — coverage textures and their filters, V-buffer formats, LI formats and overflow,
//! the restructured passes and culling, z-fail, textured lights, the overlap approximation,
//! light splitting, the plane split, depth formats, tile sizes, shader precisions, the
//! wedge-blending, penumbra-map and dbuffer options); the catalog is their union in
//! [`crate::methods::ALL`] order.

use super::{bless, check};
use crate::frame::Frame;
use crate::methods::output::MethodOutput;
use crate::methods::{Golden, OptionPairs};
use crate::scene::{builtin, file, OptionValue, Scene};
use std::path::Path;

pub use crate::methods::GOLDEN_SIZE;

/// One pinned golden render: a method and one of its [`Golden`]s.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GoldenCase {
    /// A built-in scene name, or a scene file path relative to the crate root.
    pub scene: &'static str,
    /// Width and height in pixels.
    pub size: u32,
    /// The method.
    pub method: &'static str,
    /// Empty for the method's defaults, else the suffix of its golden directory.
    pub variant: &'static str,
    /// The method's options.
    pub options: OptionPairs,
    /// `[options.gpu]`.
    pub gpu: OptionPairs,
}

impl GoldenCase {
    /// Golden `g` of method `method`.
    pub fn of(method: &'static str, g: &Golden) -> Self {
        GoldenCase {
            scene: g.scene,
            size: g.size,
            method,
            variant: g.variant,
            options: g.options,
            gpu: g.gpu,
        }
    }

    /// The scene's directory under the golden root: the built-in name or the file stem.
    pub fn scene_dir(&self) -> &'static str {
        let name = self.scene.rsplit('/').next().unwrap_or(self.scene);
        name.split('.').next().unwrap_or(name)
    }

    /// The method's directory: `method` or `method-variant`.
    pub fn method_dir(&self) -> String {
        if self.variant.is_empty() {
            self.method.to_string()
        } else {
            format!("{}-{}", self.method, self.variant)
        }
    }
}

/// Every pinned render: the goldens of every method of [`crate::methods::ALL`], in its order
/// ([`crate::methods::Method::goldens`], declared in the method's module).
pub fn cases() -> Vec<GoldenCase> {
    crate::methods::ALL
        .iter()
        .flat_map(|m| m.goldens.iter().map(|g| GoldenCase::of(m.name, g)))
        .collect()
}

/// Load a case's scene at its size with its GPU options; `base` is the crate root (scene
/// files are relative to it).
fn load_scene(base: &Path, case: &GoldenCase) -> Result<Scene, String> {
    let mut scene = match builtin::load(case.scene) {
        Some(s) => s,
        None => file::load_scene_file(&base.join(case.scene)).map_err(|e| e.to_string())?,
    };
    scene.width = case.size;
    scene.height = case.size;
    scene.methods = None;
    set_options(&mut scene, "gpu", case.gpu);
    Ok(scene)
}

fn set_options(scene: &mut Scene, table: &str, options: OptionPairs) {
    if options.is_empty() {
        return;
    }
    let t = scene.options.entry(table.to_string()).or_default();
    for (k, v) in options {
        t.insert(k.to_string(), OptionValue::parse_cli(v));
    }
}

/// Render the cases of one scene, size and GPU options (all of `group` must share them) on
/// one frame. A case whose method does not support the scene is an error: the catalog
/// expects it to run.
pub fn render_group(
    base: &Path,
    group: &[GoldenCase],
) -> Result<Vec<(GoldenCase, MethodOutput)>, String> {
    let Some(first) = group.first() else {
        return Ok(Vec::new());
    };
    let scene = load_scene(base, first)?;
    let gpu = crate::render::gpu_settings(&scene).map_err(|e| e.to_string())?;
    let frame = Frame::render(&scene, gpu).map_err(|e| e.to_string())?;
    let mut out = Vec::new();
    for case in group {
        if !crate::methods::supports_scene(case.method, &scene) {
            return Err(format!(
                "golden case {}/{}: {} did not run (it does not support the scene's lights)",
                case.scene_dir(),
                case.method_dir(),
                case.method
            ));
        }
        let mut s = scene.clone();
        set_options(&mut s, case.method, case.options);
        let output = crate::methods::run(case.method, &frame.lit_by(&s)).map_err(|e| {
            format!(
                "golden case {}/{}: {e}",
                case.scene_dir(),
                case.method_dir()
            )
        })?;
        out.push((*case, output));
    }
    Ok(out)
}

/// The catalog grouped by (scene, size, GPU options), in catalog order of first appearance.
pub fn groups() -> Vec<Vec<GoldenCase>> {
    let mut groups: Vec<Vec<GoldenCase>> = Vec::new();
    for case in cases() {
        let key = |c: &GoldenCase| (c.scene, c.size, c.gpu);
        match groups.iter_mut().find(|g| key(&g[0]) == key(&case)) {
            Some(g) => g.push(case),
            None => groups.push(vec![case]),
        }
    }
    groups
}

/// Check (or with `bless_all`, rewrite) every golden of the catalog under `root` (scene files
/// are read relative to `root`'s parent, the crate root). Returns a report, one line per case;
/// fails with every mismatch listed.
pub fn run_cases(root: &Path, bless_all: bool) -> Result<String, String> {
    let base = match root.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let mut report = String::new();
    let mut failures = Vec::new();
    let (mut cases_changed, mut files_changed) = (0, 0);
    for group in groups() {
        let rendered = match render_group(&base, &group) {
            Ok(r) => r,
            Err(e) => {
                failures.push(e);
                continue;
            }
        };
        for (case, output) in rendered {
            let (scene, method) = (case.scene_dir(), case.method_dir());
            let result = if bless_all {
                bless(root, scene, &method, &output).map(|changed| {
                    if changed.is_empty() {
                        "unchanged".to_string()
                    } else {
                        cases_changed += 1;
                        files_changed += changed.len();
                        let names: Vec<String> = changed
                            .iter()
                            .filter_map(|p| p.file_name().map(|f| f.to_string_lossy().into()))
                            .collect();
                        format!("re-blessed ({})", names.join(", "))
                    }
                })
            } else {
                check(root, scene, &method, case.size, case.size, &output).map(|()| "ok".into())
            };
            match result {
                Ok(verb) => report += &format!("{verb} {scene}/{method}\n"),
                Err(e) => failures.push(format!("{scene}/{method}: {e}")),
            }
        }
    }
    if bless_all {
        report += &match files_changed {
            0 => "nothing changed\n".to_string(),
            n => format!("{n} files re-blessed in {cases_changed} goldens\n"),
        };
    }
    if failures.is_empty() {
        Ok(report)
    } else {
        Err(failures.join("\n"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn case_directories_are_unique_and_plain() {
        let mut dirs: Vec<String> = cases()
            .iter()
            .map(|c| format!("{}/{}", c.scene_dir(), c.method_dir()))
            .collect();
        let n = dirs.len();
        dirs.sort();
        dirs.dedup();
        assert_eq!(dirs.len(), n, "two cases share a golden directory");
        assert_eq!(
            GoldenCase::of(
                "pw2002",
                &Golden::new("scenes/hard/eye-in-shadow-sphere.toml")
            )
            .scene_dir(),
            "eye-in-shadow-sphere"
        );
    }

    #[test]
    fn every_method_has_a_golden() {
        let all = cases();
        for m in crate::methods::names() {
            assert!(all.iter().any(|c| c.method == m), "{m} has no golden case");
        }
    }
}
