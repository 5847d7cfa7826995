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
//! The catalog covers every method on the foundation scenes ([`FOUNDATION`]) and the knobs
//! that change what a method computes ([`VARIANTS`]): coverage textures and their filters,
//! V-buffer formats, LI formats and overflow, the restructured passes and culling, z-fail,
//! textured lights, the overlap approximation, light splitting, the plane split, depth
//! formats, tile sizes, shader precisions, and the wedge-blending and penumbra-map options.

use super::{bless, check};
use crate::frame::Frame;
use crate::methods::output::MethodOutput;
use crate::scene::{builtin, file, OptionValue, Scene};
use std::path::Path;

/// The default golden image side (`docs/architecture.md` "Goldens are rendered small").
pub const GOLDEN_SIZE: u32 = 64;

/// Options as `(key, value)` pairs, values written as on the command line (`--opt`).
pub type CaseOptions = &'static [(&'static str, &'static str)];

/// One pinned golden render.
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
    pub options: CaseOptions,
    /// `[options.gpu]`.
    pub gpu: CaseOptions,
}

impl GoldenCase {
    const fn new(scene: &'static str, method: &'static str) -> Self {
        GoldenCase {
            scene,
            size: GOLDEN_SIZE,
            method,
            variant: "",
            options: &[],
            gpu: &[],
        }
    }

    const fn variant(
        scene: &'static str,
        method: &'static str,
        variant: &'static str,
        options: CaseOptions,
    ) -> Self {
        GoldenCase {
            variant,
            options,
            ..GoldenCase::new(scene, method)
        }
    }

    const fn sized(self, size: u32) -> Self {
        GoldenCase { size, ..self }
    }

    const fn gpu(self, gpu: CaseOptions) -> Self {
        GoldenCase { gpu, ..self }
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

/// Every method on the foundation scenes (explicit, so that a method that stops supporting
/// one fails instead of disappearing).
pub const FOUNDATION: &[(&str, &[&str])] = &[
    // dbuffer (CGI 2004) on every disk-light built-in.
    ("disk-block", &["dbuffer"]),
    ("disk-slab", &["dbuffer"]),
    ("disk-small-sphere", &["dbuffer"]),
    ("disk-acute", &["dbuffer"]),
    ("disk-torus", &["dbuffer"]),
    (
        "cube-of-spheres",
        &[
            "raycast",
            "nsample",
            "hard-sv",
            "ssv-optimized",
            "ssv",
            "wedge-blending",
        ],
    ),
    (
        "single-quad",
        &[
            "raycast",
            "nsample",
            "hard-sv",
            "ssv-optimized",
            "ssv",
            "wedge-blending",
        ],
    ),
    (
        "cylinder",
        &[
            "raycast",
            "nsample",
            "hard-sv",
            "pw2002",
            "pw-restructured",
            "ssv-optimized",
            "ssv",
            "penumbra-map",
        ],
    ),
    (
        "eye-in-shadow",
        &[
            "raycast",
            "nsample",
            "hard-sv",
            "ssv-optimized",
            "ssv",
            "wedge-blending",
        ],
    ),
    (
        "two-lights",
        &[
            "raycast",
            "nsample",
            "hard-sv",
            "pw2002",
            "pw-restructured",
            "ssv-optimized",
            "ssv",
            "penumbra-map",
        ],
    ),
    (
        "cube-of-spheres-sphere",
        &["pw2002", "pw-restructured", "penumbra-map"],
    ),
    ("pw-columns", &["pw2002", "pw-restructured", "penumbra-map"]),
    ("pw-fractal", &["pw2002", "pw-restructured", "penumbra-map"]),
    ("pw-2002", &["pw2002", "pw-restructured", "penumbra-map"]),
    // Real models (scenes/models/README): the open hand, closed by repair on load (one hole
    // capped); Bob, genus 1 (a hole loop for the wedge methods); the scorpion's thin legs
    // under a sphere light; Spot under a disk light.
    (
        "scenes/real/hand.toml",
        &["hard-sv", "ssv", "ssv-optimized", "wedge-blending"],
    ),
    (
        "scenes/real/bob.toml",
        &["hard-sv", "ssv", "ssv-optimized", "wedge-blending"],
    ),
    (
        "scenes/real/scorpion.toml",
        &[
            "hard-sv",
            "pw2002",
            "pw-restructured",
            "ssv",
            "penumbra-map",
        ],
    ),
    ("scenes/real/spot-disk.toml", &["dbuffer"]),
];

/// The knobs (module doc).
pub const VARIANTS: &[GoldenCase] = &[
    // ssv: coverage texture and filters, V-buffer formats, z-fail, a textured light.
    GoldenCase::variant(
        "single-quad",
        "ssv",
        "texture-nearest",
        &[("coverage", "texture")],
    ),
    GoldenCase::variant(
        "single-quad",
        "ssv",
        "texture-bilinear",
        &[("coverage", "texture"), ("filter", "bilinear")],
    ),
    GoldenCase::variant(
        "single-quad",
        "ssv",
        "texture-quadrilinear",
        &[("coverage", "texture"), ("filter", "quadrilinear")],
    ),
    GoldenCase::variant("cube-of-spheres", "ssv", "f16", &[("vbuffer", "f16")]),
    GoldenCase::variant("cube-of-spheres", "ssv", "8bit", &[("vbuffer", "8bit")]),
    GoldenCase::variant("single-quad", "ssv", "zfail", &[("mode", "zfail")]),
    GoldenCase::new("scenes/fire.toml", "ssv").sized(32),
    GoldenCase::new("scenes/fire.toml", "raycast").sized(32),
    // ssv-optimized: overlap approximation, light split, plane split, exact coverage, filter,
    // bounding-sphere wedges, a sphere's tight wedges over squares.
    GoldenCase::variant(
        "cube-of-spheres",
        "ssv-optimized",
        "overlap",
        &[("overlap", "loops")],
    ),
    GoldenCase::variant(
        "single-quad",
        "ssv-optimized",
        "split2",
        &[("light-split", "2")],
    ),
    GoldenCase::variant(
        "single-quad",
        "ssv-optimized",
        "plane",
        &[("split", "plane")],
    ),
    GoldenCase::variant(
        "cube-of-spheres",
        "ssv-optimized",
        "exact",
        &[("coverage", "exact")],
    ),
    GoldenCase::variant(
        "cube-of-spheres",
        "ssv-optimized",
        "nearest",
        &[("filter", "nearest")],
    ),
    GoldenCase::variant(
        "cylinder",
        "ssv-optimized",
        "bounding-sphere",
        &[("wedge", "bounding-sphere")],
    ),
    GoldenCase::variant(
        "cylinder",
        "ssv-optimized",
        "sides4",
        &[("sphere-sides", "4")],
    ),
    // pw2002 / pw-restructured: LI formats and overflow, falloff, corner wedges, the parallel
    // rule, side planes, several lights, three passes, culling, z-fail with the eye in shadow.
    GoldenCase::variant("pw-2002", "pw2002", "li12", &[("li", "12")]),
    GoldenCase::variant("pw-2002", "pw2002", "li8", &[("li", "8")]),
    GoldenCase::variant("pw-2002", "pw2002", "saturate", &[("overflow", "saturate")]),
    GoldenCase::variant(
        "pw-2002",
        "pw2002",
        "smoothstep",
        &[("falloff", "smoothstep")],
    ),
    GoldenCase::variant(
        "pw-columns",
        "pw2002",
        "no-corners",
        &[("corner-wedges", "off")],
    ),
    GoldenCase::variant(
        "cylinder",
        "pw2002",
        "no-parallel-rule",
        &[("parallel-rule", "off")],
    ),
    GoldenCase::variant(
        "pw-columns",
        "pw2002",
        "cancel",
        &[("side-planes", "cancel")],
    ),
    GoldenCase::variant(
        "two-lights",
        "pw2002",
        "separate",
        &[("lights", "separate")],
    ),
    GoldenCase::variant(
        "pw-2002",
        "pw-restructured",
        "three",
        &[("passes", "three")],
    ),
    GoldenCase::variant(
        "pw-columns",
        "pw-restructured",
        "zmax",
        &[("culling", "zmax")],
    ),
    GoldenCase::variant(
        "pw-columns",
        "pw-restructured",
        "no-culling",
        &[("culling", "off")],
    ),
    GoldenCase::new("scenes/hard/eye-in-shadow-sphere.toml", "pw-restructured"),
    GoldenCase::new("scenes/hard/eye-in-shadow-sphere.toml", "pw2002"),
    GoldenCase::new("scenes/hard/eye-in-shadow-sphere.toml", "raycast"),
    // hard-sv: stencil overflow and submission order where 300 volumes overlap.
    GoldenCase::new("overlap-stress", "hard-sv").sized(32),
    GoldenCase::variant(
        "overlap-stress",
        "hard-sv",
        "saturate",
        &[("stencil", "saturate")],
    )
    .sized(32),
    GoldenCase::variant(
        "overlap-stress",
        "hard-sv",
        "saturate-two-pass",
        &[("stencil", "saturate"), ("submission", "two-pass")],
    )
    .sized(32),
    // The references' options.
    GoldenCase::variant("single-quad", "nsample", "n16", &[("n", "16")]),
    GoldenCase::variant(
        "single-quad",
        "raycast",
        "primary-ray",
        &[("receiver", "primary-ray")],
    ),
    // Pipeline settings: depth formats and tile sizes (the output must not depend on the tile
    // size; these goldens equal the default ones where it does not).
    GoldenCase::variant("cube-of-spheres", "hard-sv", "d32f", &[]).gpu(&[("depth", "d32f")]),
    GoldenCase::variant("cube-of-spheres", "hard-sv", "d16", &[]).gpu(&[("depth", "d16")]),
    GoldenCase::variant("cube-of-spheres", "ssv", "d32f", &[]).gpu(&[("depth", "d32f")]),
    GoldenCase::variant("cube-of-spheres", "ssv", "tile16", &[]).gpu(&[("tile-size", "16")]),
    GoldenCase::variant("cube-of-spheres", "ssv", "tile2", &[]).gpu(&[("tile-size", "2")]),
    // HiZ tiles finer than the raster tile: the image of the default golden, other counters.
    GoldenCase::variant("cube-of-spheres", "hard-sv", "tile16-hiz4", &[])
        .gpu(&[("tile-size", "16"), ("hiz-tile-size", "4")]),
    // Shader precision (issue 11): ssv's fragment program in ATI R300 fp24 and in fp16.
    GoldenCase::variant("cube-of-spheres", "ssv", "shader-fp24", &[]).gpu(&[("shader", "fp24")]),
    GoldenCase::variant("cube-of-spheres", "ssv", "shader-fp16", &[]).gpu(&[("shader", "fp16")]),
    // pw2002's (Paper I, a sphere light) and ssv-optimized's (Paper IV) fragment programs in
    // fp24 and fp16, and ssv-optimized's 16-bit float position buffer (Paper IV §4.2).
    GoldenCase::variant("cube-of-spheres-sphere", "pw2002", "shader-fp24", &[])
        .gpu(&[("shader", "fp24")]),
    GoldenCase::variant("cube-of-spheres-sphere", "pw2002", "shader-fp16", &[])
        .gpu(&[("shader", "fp16")]),
    GoldenCase::variant("cube-of-spheres", "ssv-optimized", "shader-fp24", &[])
        .gpu(&[("shader", "fp24")]),
    GoldenCase::variant("cube-of-spheres", "ssv-optimized", "shader-fp16", &[])
        .gpu(&[("shader", "fp16")]),
    GoldenCase::variant(
        "cube-of-spheres",
        "ssv-optimized",
        "position-f16",
        &[("position", "f16")],
    ),
    // penumbra-map's pass-2 program (Z′ conversions, I, falloff) and dbuffer's screen program
    // (|cx|, t, V) in fp24 and fp16.
    GoldenCase::variant("cube-of-spheres-sphere", "penumbra-map", "shader-fp24", &[])
        .gpu(&[("shader", "fp24")]),
    GoldenCase::variant("cube-of-spheres-sphere", "penumbra-map", "shader-fp16", &[])
        .gpu(&[("shader", "fp16")]),
    GoldenCase::variant("disk-block", "dbuffer", "shader-fp24", &[]).gpu(&[("shader", "fp24")]),
    GoldenCase::variant("disk-block", "dbuffer", "shader-fp16", &[]).gpu(&[("shader", "fp16")]),
    // wedge-blending's regions in the shader precision, its vBuffer arithmetic capped at fp32.
    GoldenCase::variant("cube-of-spheres", "wedge-blending", "shader-fp24", &[])
        .gpu(&[("shader", "fp24")]),
    GoldenCase::variant("cube-of-spheres", "wedge-blending", "shader-fp16", &[])
        .gpu(&[("shader", "fp16")]),
    GoldenCase::variant("cube-of-spheres", "wedge-blending", "tile32", &[])
        .gpu(&[("tile-size", "32")]),
    // wedge-blending (Forest et al. 2006): packing, knobs, float targets, order.
    GoldenCase::variant("forest-spheres", "wedge-blending", "packed", &[]),
    GoldenCase::variant(
        "forest-spheres",
        "wedge-blending",
        "f32",
        &[("packing", "f32")],
    ),
    GoldenCase::variant(
        "cube-of-spheres",
        "wedge-blending",
        "f32",
        &[("packing", "f32")],
    ),
    GoldenCase::variant(
        "cube-of-spheres",
        "wedge-blending",
        "centroid",
        &[("centroid", "on")],
    ),
    GoldenCase::variant(
        "cube-of-spheres",
        "wedge-blending",
        "adjust-always",
        &[("adjust", "always")],
    ),
    GoldenCase::variant(
        "cube-of-spheres",
        "wedge-blending",
        "reverse",
        &[("order", "reverse")],
    ),
    GoldenCase::variant(
        "cube-of-spheres",
        "wedge-blending",
        "flush-denormals",
        &[("target", "flush-denormals")],
    ),
    GoldenCase::variant(
        "cube-of-spheres",
        "wedge-blending",
        "canonical-nans",
        &[("target", "canonical-nans")],
    ),
    GoldenCase::variant(
        "cube-of-spheres",
        "wedge-blending",
        "meshes-zfail",
        &[("silhouettes", "meshes"), ("mode", "zfail")],
    ),
    // dbuffer (CGI 2004): the falloff of §6.2, f16 distance channels, eq. 3 as printed.
    GoldenCase::variant("disk-block", "dbuffer", "sqrt", &[("falloff", "sqrt")]),
    GoldenCase::variant("disk-block", "dbuffer", "f16", &[("storage", "f16")]),
    GoldenCase::variant("disk-block", "dbuffer", "printed", &[("eq3", "printed")]),
    GoldenCase::variant(
        "disk-small-sphere",
        "dbuffer",
        "sqrt",
        &[("falloff", "sqrt")],
    ),
    GoldenCase::variant("disk-small-sphere", "dbuffer", "f16", &[("storage", "f16")]),
    GoldenCase::variant(
        "disk-small-sphere",
        "dbuffer",
        "printed",
        &[("eq3", "printed")],
    ),
    // penumbra-map (Wyman & Hansen 2003): map sizes and storage formats.
    GoldenCase::variant(
        "pw-columns",
        "penumbra-map",
        "map32-unorm8",
        &[("map-size", "32"), ("storage", "unorm8")],
    ),
    GoldenCase::variant(
        "pw-columns",
        "penumbra-map",
        "map32-f32",
        &[("map-size", "32"), ("storage", "f32")],
    ),
    GoldenCase::variant(
        "pw-columns",
        "penumbra-map",
        "map128-unorm8",
        &[("map-size", "128"), ("storage", "unorm8")],
    ),
    GoldenCase::variant(
        "pw-columns",
        "penumbra-map",
        "map128-f32",
        &[("map-size", "128"), ("storage", "f32")],
    ),
];

/// Every pinned render: [`FOUNDATION`] then [`VARIANTS`].
pub fn cases() -> Vec<GoldenCase> {
    FOUNDATION
        .iter()
        .flat_map(|(scene, methods)| methods.iter().map(|m| GoldenCase::new(scene, m)))
        .chain(VARIANTS.iter().copied())
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

fn set_options(scene: &mut Scene, table: &str, options: CaseOptions) {
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
            GoldenCase::new("scenes/hard/eye-in-shadow-sphere.toml", "pw2002").scene_dir(),
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
