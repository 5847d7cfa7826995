//! Golden outputs: the bit-exact regression loop (`docs/architecture.md` "Tests"; after vello's
//! sparse tests and resvg).
//!
//! # Layout
//!
//! ```text
//! golden/<scene>/<method>/visibility.pfm     the visibility buffer, exact f32 bits
//! golden/<scene>/<method>/<raw>.png          each 8-bit buffer dump a method always hands
//!                                            back, e.g. hard-sv's stencil.png
//! golden/<scene>/<method>/counters.json      every integer counter of stats.json: totals,
//!                                            per pass (name, runs, counters), clamped_pixels
//! ```
//!
//! `<method>` is the method name, or `<method>-<variant>` for a render with other options
//! ([`cases`] holds the catalog of pinned renders).
//!
//! Files are compared on their **decoded values** — f32 bits of the PFM, u8 values of the
//! PNG — never on the compressed bytes, so a different PNG encoder version cannot fail a test
//! and a `-0.0` vs `0.0` or a 1-ulp change cannot pass one.
//!
//! # The loop
//!
//! - Missing golden file: [`check`] fails naming it and writes what the method produced to the
//!   failure directory below (`target/golden-failures/<scene>/<method>/`), never to the golden
//!   root: a new case gets its goldens only through `penumbra golden --bless`.
//! - Mismatch: [`check`] writes `target/golden-failures/<scene>/<method>/actual.pfm` and
//!   `expected_diff_actual.png` (expected | diff mask | actual, visibility shown as sRGB gray;
//!   for raw images `actual_<raw>.png` and `expected_diff_actual_<raw>.png`) and fails naming
//!   the first differing pixel, both values with their bits, the number of differing pixels
//!   and the paths. `target/` is the sibling of the golden root (`<crate>/golden` →
//!   `<crate>/target`).
//! - Re-blessing is explicit and only on the command line: the CLI's `golden --bless` calls
//!   [`bless`]; nothing in `cargo test` (no environment variable) writes a golden. Goldens are
//!   never loosened silently: there is no tolerance.

use crate::methods::dump::{BufferDump, DumpValues};
use crate::methods::output::MethodOutput;
use crate::metrics::{diff_mask, diff_mask_u8};
use crate::output::dump::raw_file_name;
use crate::output::{
    decode_gray8_png, encode_gray8_png, encode_pfm, encode_side_by_side_png, read_pfm,
    visibility_to_srgb8, write_files_all_or_nothing,
};
use crate::visibility::Visibility;
use std::path::{Path, PathBuf};

pub mod cases;

pub use cases::{run_cases, GoldenCase, GOLDEN_SIZE};

/// The file name of the visibility golden.
pub const VISIBILITY_FILE: &str = "visibility.pfm";

/// The file name of the counters golden.
pub const COUNTERS_FILE: &str = "counters.json";

/// The integer counters of a method's stats that a golden pins (times excluded), as pretty
/// JSON: `clamped_pixels`, `totals`, and per pass its name, runs and counters.
pub fn counters_json(out: &MethodOutput) -> Vec<u8> {
    let passes: Vec<serde_json::Value> = out
        .stats
        .passes
        .iter()
        .map(|p| serde_json::json!({ "name": p.name, "runs": p.runs, "counters": p.counters }))
        .collect();
    let v = serde_json::json!({
        "clamped_pixels": out.stats.clamped_pixels,
        "totals": out.stats.totals,
        "passes": passes,
    });
    let mut text = serde_json::to_string_pretty(&v).unwrap_or_default();
    text.push('\n');
    text.into_bytes()
}

/// Where the goldens of one scene and method live: `root/scene/method`.
pub fn golden_dir(root: &Path, scene: &str, method: &str) -> PathBuf {
    root.join(scene).join(method)
}

/// Where failures of one scene and method are written:
/// `<parent of root>/target/golden-failures/scene/method`.
pub fn failure_dir(root: &Path, scene: &str, method: &str) -> PathBuf {
    failures_root(root).join(scene).join(method)
}

fn failures_root(root: &Path) -> PathBuf {
    let parent = match root.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    parent.join("target").join("golden-failures")
}

/// `s` as one plain path component (not empty, no separator, not starting with `.`), or an
/// error naming `what`.
fn check_component(what: &str, s: &str) -> Result<(), String> {
    if s.is_empty() || s.starts_with('.') || s.contains(['/', '\\']) {
        return Err(format!(
            "golden: {what} name {s:?} is not a plain directory name"
        ));
    }
    Ok(())
}

/// The 8-bit values of a single-channel 8-bit dump (the only dumps a golden pins: those of a
/// normal run), or why not.
fn gray8_values(d: &BufferDump) -> Result<&[u8], String> {
    match &d.values {
        DumpValues::U8(v) if d.format.channels() == 1 => Ok(v),
        _ => Err(format!(
            "golden: buffer dump {:?} is not a single-channel 8-bit buffer",
            d.name
        )),
    }
}

/// The golden files of one output, `(file name, bytes)`: [`VISIBILITY_FILE`], then one PNG
/// per buffer dump in output order.
fn golden_files(
    out: &MethodOutput,
    width: u32,
    height: u32,
) -> Result<Vec<(String, Vec<u8>)>, String> {
    let n = width as usize * height as usize;
    if out.visibility.len() != n {
        return Err(format!(
            "golden: visibility has {} pixels, expected {width}x{height} = {n}",
            out.visibility.len()
        ));
    }
    let mut files = vec![
        (
            VISIBILITY_FILE.to_string(),
            encode_pfm(&out.visibility, width, height),
        ),
        (COUNTERS_FILE.to_string(), counters_json(out)),
    ];
    for d in &out.dumps {
        let name = raw_file_name(d).map_err(|e| format!("golden: {e}"))?;
        if files.iter().any(|(f, _)| *f == name) {
            return Err(format!("golden: two outputs named {name}"));
        }
        let png = encode_gray8_png(gray8_values(d)?, d.width, d.height)
            .map_err(|e| format!("golden: buffer dump {:?}: {e}", d.name))?;
        files.push((name, png));
    }
    Ok(files)
}

/// Golden-like files already in `dir` (`*.pfm`, `*.png`, `*.json`), sorted; empty if `dir` is
/// missing.
fn existing_golden_files(dir: &Path) -> Result<Vec<String>, String> {
    let rd = match std::fs::read_dir(dir) {
        Ok(rd) => rd,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(format!("golden: reading {}: {e}", dir.display())),
    };
    let mut names = Vec::new();
    for entry in rd {
        let entry = entry.map_err(|e| format!("golden: reading {}: {e}", dir.display()))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let golden_like = [".pfm", ".png", ".json"].iter().any(|x| name.ends_with(x));
        if !name.starts_with('.') && golden_like {
            names.push(name);
        }
    }
    names.sort();
    Ok(names)
}

/// Rewrites the goldens of `scene`/`method` under `root` from `out` and returns the paths
/// it changed: files whose bytes differ or that did not exist are written (nothing else), and
/// removed stale files are listed too. The size is taken from `out.stats.width`/`height` (and must match the buffers).
/// Golden files of that method that `out` no longer produces (`*.pfm`, `*.png`, `*.json`) are
/// removed.
pub fn bless(
    root: &Path,
    scene: &str,
    method: &str,
    out: &MethodOutput,
) -> Result<Vec<PathBuf>, String> {
    let (width, height) = (out.stats.width, out.stats.height);
    check_component("scene", scene)?;
    check_component("method", method)?;
    let dir = golden_dir(root, scene, method);
    let files = golden_files(out, width, height)?;
    let stale: Vec<String> = existing_golden_files(&dir)?
        .into_iter()
        .filter(|name| !files.iter().any(|(f, _)| f == name))
        .collect();
    let changed: Vec<(String, Vec<u8>)> = files
        .into_iter()
        .filter(|(name, bytes)| std::fs::read(dir.join(name)).ok().as_ref() != Some(bytes))
        .collect();
    if !changed.is_empty() {
        write_files_all_or_nothing(&dir, &changed)
            .map_err(|e| format!("golden: writing {}: {e}", dir.display()))?;
    }
    for name in &stale {
        let p = dir.join(name);
        std::fs::remove_file(&p)
            .map_err(|e| format!("golden: removing stale {}: {e}", p.display()))?;
    }
    Ok(changed
        .into_iter()
        .map(|(f, _)| f)
        .chain(stale)
        .map(|f| dir.join(f))
        .collect())
}

/// Checks `out` (a `width×height` render of `scene` by `method`) against the goldens under
/// `root` (usually `<crate>/golden`), bit for bit on decoded values. See the module docs for
/// what happens when a golden is missing or differs.
///
/// Stale failure files of this scene and method are removed first, so
/// `target/golden-failures` only shows current failures.
pub fn check(
    root: &Path,
    scene: &str,
    method: &str,
    width: u32,
    height: u32,
    out: &MethodOutput,
) -> Result<(), String> {
    check_against(
        root,
        &failures_root(root),
        scene,
        method,
        width,
        height,
        out,
    )
}

/// [`check`] with the failures under `failures_root/scene/method`: compares, and writes there
/// what differs or has no golden.
fn check_against(
    root: &Path,
    failures_root: &Path,
    scene: &str,
    method: &str,
    width: u32,
    height: u32,
    out: &MethodOutput,
) -> Result<(), String> {
    check_component("scene", scene)?;
    check_component("method", method)?;
    let dir = golden_dir(root, scene, method);
    let fail_dir = failures_root.join(scene).join(method);
    match std::fs::remove_dir_all(&fail_dir) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(format!("golden: clearing {}: {e}", fail_dir.display())),
    }
    let files = golden_files(out, width, height)?;

    let mut problems: Vec<String> = Vec::new();
    let mut missing: Vec<String> = Vec::new();
    let mut failure_files: Vec<(String, Vec<u8>)> = Vec::new();
    let what = format!("{scene}/{method}");

    for (name, bytes) in &files {
        let path = dir.join(name);
        let expected = match std::fs::read(&path) {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                missing.push(format!(
                    "golden missing: {} (what the method produced: {})",
                    path.display(),
                    fail_dir.join(name).display()
                ));
                failure_files.push((name.clone(), bytes.clone()));
                continue;
            }
            Err(e) => {
                problems.push(format!("golden {what}: reading {}: {e}", path.display()));
                continue;
            }
        };
        let result = if name == VISIBILITY_FILE {
            compare_visibility(&expected, &out.visibility, width, height)
        } else if name == COUNTERS_FILE {
            compare_counters(&expected, bytes)
        } else {
            let d = out
                .dumps
                .iter()
                .find(|d| format!("{}.png", d.name) == *name)
                .expect("every golden file but the PFM and the counters comes from a dump");
            match gray8_values(d) {
                Ok(values) => compare_raw(&expected, values, d.width, d.height),
                Err(e) => Err(Mismatch {
                    summary: e,
                    panels: None,
                }),
            }
        };
        match result {
            Ok(()) => {}
            Err(mismatch) => {
                let (actual_name, panel_name) = match name.as_str() {
                    VISIBILITY_FILE => (
                        "actual.pfm".to_string(),
                        "expected_diff_actual.png".to_string(),
                    ),
                    _ => (
                        format!("actual_{name}"),
                        format!("expected_diff_actual_{name}"),
                    ),
                };
                let mut msg = format!(
                    "golden mismatch {what} {name}: {}\n  expected: {}\n  actual:   {}",
                    mismatch.summary,
                    path.display(),
                    fail_dir.join(&actual_name).display()
                );
                failure_files.push((actual_name, bytes.clone()));
                if let Some(panels) = mismatch.panels {
                    match encode_side_by_side_png(width, height, &panels) {
                        Ok(png) => {
                            msg.push_str(&format!(
                                "\n  images:   {} (expected | diff | actual)",
                                fail_dir.join(&panel_name).display()
                            ));
                            failure_files.push((panel_name, png));
                        }
                        Err(e) => msg.push_str(&format!("\n  (no diff image: {e})")),
                    }
                }
                problems.push(msg);
            }
        }
    }

    for stale in existing_golden_files(&dir)? {
        if !files.iter().any(|(f, _)| *f == stale) {
            problems.push(format!(
                "golden {what}: {} exists but the method no longer produces {stale}",
                dir.join(&stale).display()
            ));
        }
    }

    if !failure_files.is_empty() {
        if let Err(e) = write_files_all_or_nothing(&fail_dir, &failure_files) {
            problems.push(format!(
                "golden {what}: could not write failure files to {}: {e}",
                fail_dir.display()
            ));
        }
    }
    problems.extend(missing);

    if problems.is_empty() {
        Ok(())
    } else {
        problems.push(
            "  if the change is intended: `cargo run --release -- golden --bless`, review the \
             diff of golden/ and commit it"
                .into(),
        );
        Err(problems.join("\n"))
    }
}

/// Why one golden file did not match: a one-line summary and, when sizes agree, the
/// expected | diff | actual panels.
struct Mismatch {
    summary: String,
    panels: Option<Vec<Vec<[u8; 3]>>>,
}

fn fmt_pixel(v: &Visibility, i: usize) -> String {
    match v {
        Visibility::Gray(g) => format!("{:?} (0x{:08x})", g[i], g[i].to_bits()),
        Visibility::Rgb(c) => {
            let [r, g, b] = c[i];
            format!(
                "[{r:?}, {g:?}, {b:?}] (0x{:08x}, 0x{:08x}, 0x{:08x})",
                r.to_bits(),
                g.to_bits(),
                b.to_bits()
            )
        }
    }
}

fn kind(v: &Visibility) -> &'static str {
    match v {
        Visibility::Gray(_) => "gray (Pf)",
        Visibility::Rgb(_) => "RGB (PF)",
    }
}

/// True when pixel `i` has the same bits in both buffers (both gray, or both RGB).
fn same_bits(a: &Visibility, b: &Visibility, i: usize) -> bool {
    match (a, b) {
        (Visibility::Gray(x), Visibility::Gray(y)) => x[i].to_bits() == y[i].to_bits(),
        (Visibility::Rgb(x), Visibility::Rgb(y)) => {
            (0..3).all(|c| x[i][c].to_bits() == y[i][c].to_bits())
        }
        _ => false,
    }
}

/// The decoded golden, or the mismatch saying it does not decode or has another size.
fn decoded<T>(
    golden: Result<(u32, u32, T), String>,
    width: u32,
    height: u32,
) -> Result<T, Mismatch> {
    let (ew, eh, values) = golden.map_err(|e| Mismatch {
        summary: format!("the golden does not decode: {e}"),
        panels: None,
    })?;
    if (ew, eh) != (width, height) {
        return Err(Mismatch {
            summary: format!("size differs: expected {ew}x{eh}, actual {width}x{height}"),
            panels: None,
        });
    }
    Ok(values)
}

fn compare_visibility(
    expected_bytes: &[u8],
    actual: &Visibility,
    width: u32,
    height: u32,
) -> Result<(), Mismatch> {
    let expected = decoded(read_pfm(expected_bytes), width, height)?;
    let w = width as usize;
    let n = w * height as usize;
    let differing: Vec<usize> = (0..n)
        .filter(|&i| !same_bits(&expected, actual, i))
        .collect();
    let Some(&first) = differing.first() else {
        return Ok(());
    };
    let kinds = if kind(&expected) != kind(actual) {
        format!("expected {}, actual {}; ", kind(&expected), kind(actual))
    } else {
        String::new()
    };
    let summary = format!(
        "{kinds}{} of {n} pixels differ; first at (x={}, y={}): expected {}, actual {}",
        differing.len(),
        first % w,
        first / w,
        fmt_pixel(&expected, first),
        fmt_pixel(actual, first),
    );
    let panels = vec![
        visibility_to_srgb8(&expected),
        diff_mask(&expected, actual, width, height),
        visibility_to_srgb8(actual),
    ];
    Err(Mismatch {
        summary,
        panels: Some(panels),
    })
}

fn compare_raw(
    expected_bytes: &[u8],
    actual: &[u8],
    width: u32,
    height: u32,
) -> Result<(), Mismatch> {
    let expected = decoded(decode_gray8_png(expected_bytes), width, height)?;
    if actual.len() != expected.len() {
        return Err(Mismatch {
            summary: format!(
                "{} values produced for the golden's {}×{} = {}",
                actual.len(),
                width,
                height,
                expected.len()
            ),
            panels: None,
        });
    }
    let w = width as usize;
    let differing = expected.iter().zip(actual).filter(|(a, b)| a != b).count();
    let Some(first) = expected.iter().zip(actual).position(|(a, b)| a != b) else {
        return Ok(());
    };
    let summary = format!(
        "{differing} of {} pixels differ; first at (x={}, y={}): expected {}, actual {}",
        expected.len(),
        first % w,
        first / w,
        expected[first],
        actual[first],
    );
    let gray = |v: &[u8]| v.iter().map(|&x| [x; 3]).collect::<Vec<_>>();
    let panels = vec![
        gray(&expected),
        diff_mask_u8(&expected, actual, width, height),
        gray(actual),
    ];
    Err(Mismatch {
        summary,
        panels: Some(panels),
    })
}

/// Compares the counters JSON: equal values, or the first differing counter by its path.
fn compare_counters(expected_bytes: &[u8], actual_bytes: &[u8]) -> Result<(), Mismatch> {
    let parse = |b: &[u8]| serde_json::from_slice::<serde_json::Value>(b);
    let (expected, actual) = match (parse(expected_bytes), parse(actual_bytes)) {
        (Ok(e), Ok(a)) => (e, a),
        (Err(e), _) | (_, Err(e)) => {
            return Err(Mismatch {
                summary: format!("unreadable counters JSON: {e}"),
                panels: None,
            })
        }
    };
    match first_difference(&expected, &actual, String::new()) {
        None => Ok(()),
        Some((path, e, a)) => Err(Mismatch {
            summary: format!("counter {path}: expected {e}, actual {a}"),
            panels: None,
        }),
    }
}

/// The first place where two JSON values differ: (path, expected, actual).
fn first_difference(
    e: &serde_json::Value,
    a: &serde_json::Value,
    path: String,
) -> Option<(String, String, String)> {
    use serde_json::Value;
    match (e, a) {
        (Value::Object(eo), Value::Object(ao)) => {
            let mut keys: Vec<&String> = eo.keys().chain(ao.keys()).collect();
            keys.sort();
            keys.dedup();
            keys.into_iter().find_map(|k| {
                let p = format!("{path}.{k}");
                match (eo.get(k), ao.get(k)) {
                    (Some(x), Some(y)) => first_difference(x, y, p),
                    (x, y) => Some((p, fmt_json(x), fmt_json(y))),
                }
            })
        }
        (Value::Array(ea), Value::Array(aa)) if ea.len() == aa.len() => ea
            .iter()
            .zip(aa)
            .enumerate()
            .find_map(|(i, (x, y))| first_difference(x, y, format!("{path}[{i}]"))),
        _ if e == a => None,
        _ => Some((path, e.to_string(), a.to_string())),
    }
}

fn fmt_json(v: Option<&serde_json::Value>) -> String {
    v.map_or("(missing)".to_string(), |v| v.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::counters::Counters;
    use crate::methods::dump::ElementFormat;
    use crate::methods::output::MethodStats;

    /// A fresh `<tmp>/penumbra-golden-…/golden` root and its failures root.
    fn roots(tag: &str) -> (PathBuf, PathBuf, PathBuf) {
        use std::sync::atomic::{AtomicU32, Ordering};
        static N: AtomicU32 = AtomicU32::new(0);
        let base = std::env::temp_dir().join(format!(
            "penumbra-golden-{tag}-{}-{}",
            std::process::id(),
            N.fetch_add(1, Ordering::Relaxed)
        ));
        let _ = std::fs::remove_dir_all(&base);
        let root = base.join("golden");
        let fails = failures_root(&root);
        (base, root, fails)
    }

    fn output(vis: Vec<f32>, stencil: Option<Vec<u8>>) -> MethodOutput {
        MethodOutput {
            visibility: Visibility::Gray(vis),
            dumps: stencil
                .map(|values| {
                    let n = values.len() as u32;
                    vec![BufferDump::new(
                        "stencil",
                        "test",
                        if n == 6 { (3, 2) } else { (n, 1) },
                        ElementFormat::Stencil8,
                        DumpValues::U8(values),
                    )]
                })
                .unwrap_or_default(),
            stats: MethodStats {
                method: "hard-sv".into(),
                width: 3,
                height: 2,
                wall_seconds: 0.0,
                plan: serde_json::Value::Null,
                passes: vec![],
                totals: Counters::default(),
                warnings: vec![],
                clamped_pixels: 0,
                meshes: vec![],
                gpu_model: crate::gpu_model::estimate(
                    crate::gpu_model::GpuModel::default().profile(),
                    &[],
                ),
            },
        }
    }

    fn base_out() -> MethodOutput {
        output(
            vec![0.0, 0.25, 0.5, 0.75, 1.0, 0.125],
            Some(vec![0, 1, 2, 3, 4, 5]),
        )
    }

    fn run(root: &Path, fails: &Path, out: &MethodOutput) -> Result<(), String> {
        check_against(root, fails, "scene", "hard-sv", 3, 2, out)
    }

    #[test]
    fn failures_go_next_to_the_golden_root() {
        assert_eq!(
            failure_dir(Path::new("/c/golden"), "s", "m"),
            Path::new("/c/target/golden-failures/s/m")
        );
    }

    #[test]
    fn missing_fails_every_time_and_writes_only_failures() {
        let (base, root, fails) = roots("missing");
        let out = base_out();
        for _ in 0..2 {
            let err = run(&root, &fails, &out).unwrap_err();
            assert!(err.contains("golden missing:"), "{err}");
            assert!(err.contains("golden --bless"), "{err}");
            assert!(
                err.contains("visibility.pfm") && err.contains("stencil.png"),
                "{err}"
            );
            assert!(!root.join("scene/hard-sv").exists());
            assert!(fails.join("scene/hard-sv/visibility.pfm").exists());
            assert!(fails.join("scene/hard-sv/stencil.png").exists());
        }
        bless(&root, "scene", "hard-sv", &out).unwrap();
        run(&root, &fails, &out).unwrap();
        assert!(!fails.join("scene/hard-sv").exists());
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn one_ulp_mismatch_names_pixel_and_writes_failures() {
        let (base, root, fails) = roots("ulp");
        let out = base_out();
        bless(&root, "scene", "hard-sv", &out).unwrap();
        let mut bad = out.clone();
        let Visibility::Gray(v) = &mut bad.visibility else {
            unreachable!()
        };
        v[4] = f32::from_bits(v[4].to_bits() - 1);
        v[5] = 0.5;
        let err = run(&root, &fails, &bad).unwrap_err();
        assert!(err.contains("2 of 6 pixels differ"), "{err}");
        assert!(err.contains("first at (x=1, y=1)"), "{err}");
        assert!(
            err.contains("0x3f800000") && err.contains("0x3f7fffff"),
            "{err}"
        );
        let fd = fails.join("scene/hard-sv");
        assert!(
            err.contains(&fd.join("actual.pfm").display().to_string()),
            "{err}"
        );
        let actual = read_pfm(&std::fs::read(fd.join("actual.pfm")).unwrap()).unwrap();
        assert_eq!(actual.2, bad.visibility);
        let img = image::open(fd.join("expected_diff_actual.png"))
            .unwrap()
            .to_rgb8();
        let gap = crate::output::PANEL_GAP;
        assert_eq!(img.dimensions(), (9 + 2 * gap, 2));
        // Diff panel: black where equal, red where different.
        assert_eq!(img.get_pixel(3 + gap, 0).0, [0, 0, 0]);
        assert!(img.get_pixel(3 + gap + 1, 1).0[0] >= crate::metrics::DIFF_MIN_RED);
        // The stencil still matches, so there is no stencil failure.
        assert!(!err.contains("stencil"), "{err}");
        // Fixing the output clears the failure directory on the next check.
        run(&root, &fails, &out).unwrap();
        assert!(!fd.exists());
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn raw_image_mismatch() {
        let (base, root, fails) = roots("raw");
        let out = base_out();
        bless(&root, "scene", "hard-sv", &out).unwrap();
        let mut bad = out.clone();
        let DumpValues::U8(v) = &mut bad.dumps[0].values else {
            unreachable!()
        };
        v[2] = 255;
        let err = run(&root, &fails, &bad).unwrap_err();
        assert!(err.contains("stencil.png"), "{err}");
        assert!(
            err.contains("1 of 6 pixels differ; first at (x=2, y=0): expected 2, actual 255"),
            "{err}"
        );
        let fd = fails.join("scene/hard-sv");
        assert!(fd.join("actual_stencil.png").exists());
        assert!(fd.join("expected_diff_actual_stencil.png").exists());
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn size_kind_and_stale_files_fail() {
        let (base, root, fails) = roots("size");
        let out = base_out();
        bless(&root, "scene", "hard-sv", &out).unwrap();
        // A different size.
        let small = output(vec![0.0; 2], Some(vec![0; 2]));
        let err = check_against(&root, &fails, "scene", "hard-sv", 2, 1, &small).unwrap_err();
        assert!(
            err.contains("size differs: expected 3x2, actual 2x1"),
            "{err}"
        );
        // Gray golden vs RGB output.
        let mut rgb = out.clone();
        rgb.visibility = Visibility::Rgb((0..6).map(|i| [out.visibility.gray(i); 3]).collect());
        let err = run(&root, &fails, &rgb).unwrap_err();
        assert!(err.contains("expected gray (Pf), actual RGB (PF)"), "{err}");
        // The method stopped producing the stencil.
        let no_raw = output(vec![0.0, 0.25, 0.5, 0.75, 1.0, 0.125], None);
        let err = run(&root, &fails, &no_raw).unwrap_err();
        assert!(err.contains("no longer produces stencil.png"), "{err}");
        // Blessing removes the stale golden.
        bless(&root, "scene", "hard-sv", &no_raw).unwrap();
        assert!(!root.join("scene/hard-sv/stencil.png").exists());
        run(&root, &fails, &no_raw).unwrap();
        std::fs::remove_dir_all(&base).unwrap();
    }

    /// `bless` writes and reports only what changed, so `golden --bless` can say "nothing
    /// changed" or name the re-blessed files.
    #[test]
    fn bless_reports_only_changed_files() {
        let (base, root, _) = roots("changed");
        let out = base_out();
        let dir = root.join("scene/hard-sv");
        let first = bless(&root, "scene", "hard-sv", &out).unwrap();
        assert_eq!(first.len(), 3, "{first:?}");
        assert!(bless(&root, "scene", "hard-sv", &out).unwrap().is_empty());
        let mut one_pixel = out.clone();
        let DumpValues::U8(v) = &mut one_pixel.dumps[0].values else {
            unreachable!()
        };
        v[2] = 255;
        assert_eq!(
            bless(&root, "scene", "hard-sv", &one_pixel).unwrap(),
            vec![dir.join("stencil.png")]
        );
        let no_raw = output(vec![0.0, 0.25, 0.5, 0.75, 1.0, 0.125], None);
        assert_eq!(
            bless(&root, "scene", "hard-sv", &no_raw).unwrap(),
            vec![dir.join("stencil.png")],
            "the removed stale file is a change"
        );
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn nan_bits_compare_exactly() {
        let (base, root, fails) = roots("nan");
        let out = output(vec![f32::NAN, 0.0, 0.0, 0.0, 0.0, 0.0], None);
        bless(&root, "scene", "hard-sv", &out).unwrap();
        run(&root, &fails, &out).unwrap();
        let other = output(
            vec![f32::from_bits(0x7fc0_0001), 0.0, 0.0, 0.0, 0.0, 0.0],
            None,
        );
        assert!(run(&root, &fails, &other).is_err());
        // -0.0 vs 0.0 differs in bits, so it fails too.
        let neg = output(vec![f32::NAN, -0.0, 0.0, 0.0, 0.0, 0.0], None);
        let err = run(&root, &fails, &neg).unwrap_err();
        assert!(err.contains("first at (x=1, y=0)"), "{err}");
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn bad_names_and_sizes_are_errors() {
        let (base, root, fails) = roots("names");
        let out = base_out();
        assert!(check_against(&root, &fails, "../x", "m", 3, 2, &out).is_err());
        assert!(check_against(&root, &fails, "s", "", 3, 2, &out).is_err());
        assert!(check_against(&root, &fails, "s", "m", 4, 2, &out).is_err());
        assert!(!base.exists());
    }
}
