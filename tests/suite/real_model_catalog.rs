//! The real-model catalog (issue 28, item 2): every `scenes/real-catalog/*.toml` — eight real
//! meshes (`scenes/models/README`: bob, fish, goathead, hand, scorpion, spider, spot, wingnut),
//! each on a floor under a rectangle, a sphere and a disk light — read from the directory in
//! sorted order, rendered at [`SIZE`]² with every method that supports the light.
//!
//! For every (scene, method) the row printed (`cargo test --test suite real_model_catalog::
//! -- --nocapture`) holds the mean |e| against `raycast` over the **whole-light receivers**
//! and over the **horizon receivers** (the library's classification,
//! `penumbra::metrics::horizon`: the receiver's tangent plane cuts the light), the horizon
//! receivers' share of the method's error, and `clamped_pixels`. The bound is on the
//! whole-light error: on horizon receivers every method errs (the papers do not treat the
//! receiver's own plane; issue 28), so those numbers are printed, not bounded.
//!
//! A bound is [`Bound::Correct`] when it follows from the math or a paper: `nsample`'s
//! sampling error, and soft shadow methods that must beat the hard shadow (a fraction of
//! `hard-sv`'s whole-light error on the same scene: [`Bound::VsHard`]). A [`Bound::Pin`] is the
//! code's measured output when the entry was written — a regression fence, not a claim that
//! the output is right; its `why` says what is wrong. Pins name issue 28 where a method is
//! known to fail on real meshes (pw2002 and pw-restructured on sphere lights, dbuffer on disk
//! lights): another change fixes or flags those, and the pins are then tightened.
//! `wedge-blending`'s default 8-bit packing, which fails on meshes with a hole (issue 28),
//! stays within its `Correct` bound here (on `bob-rect`, genus 1: whole-light mean |e|
//! 0.0007 at 64², hard-sv 0.011; the issue measured its failure on another placement and
//! light), so it needs no pin. A
//! scene or method without an entry fails the test with a message naming it and its measured
//! error. And issue 28's rule is checked on every scene: a method whose whole-light error is
//! above `hard-sv`'s there must carry a warning (`penumbra-map` aside: it darkens outward by
//! design) — pw2002 and pw-restructured warn about the folds of the silhouette, dbuffer about
//! receivers whose ray crosses its volumes more than once.
//!
//! **The reference** is `raycast` with its default [`REFERENCE_SAMPLES`] = 1024 jittered
//! stratified samples. Its own noise — the same reference with the next seed — is measured on
//! every scene and must stay below [`NOISE_MAX`] over the whole-light receivers (measured: at
//! most 0.00102, on the hand, whose wide penumbrae cover most of the floor; 0.0005 or less
//! elsewhere), under a third of the tightest `Correct` bound (0.004), so an error over a bound
//! is the method's, not the reference's. With 256 samples the noise was 3× larger (0.0030 on
//! the hand), too close to that bound. `nsample` runs with n = 256 (the table).
//!
//! **Runtime**: 40–47 s of wall time (12 s of CPU time) for the 24 scenes at 64² (two
//! references per scene, for the noise, and every method) with the test profile (opt-level 3)
//! on the 2-core machine shared with three other builds (load 8), measured when the test was
//! written; with 256 reference samples it took 21 s.
//! Findings: `docs/real-models.md`.

use penumbra::experiment::configured;
use penumbra::frame::Frame;
use penumbra::methods;
use penumbra::metrics::error_report::error_report;
use penumbra::metrics::horizon::receiver_classes;
use penumbra::scene::Scene;
use std::path::{Path, PathBuf};

/// The image size of every scene (the files ask for 256², what docs/real-models.md measures
/// with the CLI).
const SIZE: u32 = 64;

/// Light samples of the reference here (module doc).
const REFERENCE_SAMPLES: &str = "1024";

/// Light samples of `nsample` here.
const NSAMPLE_N: &str = "256";

/// The largest mean |e| over whole-light receivers the reference may show against itself with
/// the next seed (module doc).
const NOISE_MAX: f64 = 0.0012;

/// The bound on a method's mean |e| over whole-light receivers.
#[derive(Debug, Clone, Copy)]
enum Bound {
    /// Follows from the math or a paper: at most `max`.
    Correct { max: f64, why: &'static str },
    /// Follows from a paper: at most `factor` × `hard-sv`'s on the same scene.
    VsHard { factor: f64, why: &'static str },
    /// The code's measured output, pinned (a fence against regressions).
    Pin { max: f64, why: &'static str },
}

impl Bound {
    /// The bound's value on a scene where `hard-sv`'s whole-light mean |e| is `hard`.
    fn max(&self, hard: f64) -> f64 {
        match *self {
            Bound::Correct { max, .. } | Bound::Pin { max, .. } => max,
            Bound::VsHard { factor, .. } => factor * hard,
        }
    }

    fn describe(&self, hard: f64) -> String {
        match *self {
            Bound::Correct { max, why } => format!("correct ≤ {max}: {why}"),
            Bound::VsHard { factor, why } => {
                format!("correct ≤ {factor} × hard-sv = {:.5}: {why}", factor * hard)
            }
            Bound::Pin { max, why } => format!("PIN ≤ {max}: {why}"),
        }
    }
}

use Bound::{Correct, Pin, VsHard};

/// `nsample` with n = 256 stratum centers: each hard shadow is the reference's function for
/// its sample point, and the average's error at a pixel is at most the strata a silhouette
/// edge crosses over n, ≈ 1/(2·√n) = 0.031 per edge; averaged over the whole-light receivers,
/// most of which no penumbra crosses, it is far less.
const NSAMPLE: Bound = Correct {
    max: 0.004,
    why: "n = 256 hard shadows: stratified sampling error ≤ 1/(2√n) per crossing edge",
};

/// The soft shadow volume (Paper III, and its optimized form, Paper IV) integrates the
/// light's coverage exactly per silhouette edge; only where wedges of neighbouring edges of a
/// real mesh overlap (Paper III §5.3) or where the silhouette from the light center is not the
/// one from every light point does it differ. It must be far better than the hard shadow.
const SSV: Bound = VsHard {
    factor: 0.5,
    why: "exact coverage per silhouette edge (Paper III §3); overlap errors only (§5.3)",
};

/// Wedge blending (Forest et al.) blends exact per-loop coverages; a soft method must not be
/// worse than the hard shadow on receivers that see the whole light (issue 28).
const WEDGE_BLENDING: Bound = VsHard {
    factor: 1.0,
    why: "per-loop exact coverage blended (Forest et al. §4): no worse than the hard shadow",
};

/// Why `hard-sv` is pinned: it is the baseline every soft method is measured against.
const HARD: &str = "the hard shadow from the light center has no penumbra";

/// Why the penumbra wedges are pinned (issue 28, item 1, being fixed in parallel: tighten
/// these pins once it lands).
const PW: &str = "issue 28: penumbra wedges fail on real meshes (wrong regions and streaks on \
the floor, clamped pixels), worse than the hard shadow on goathead, hand, scorpion and spot; \
Paper I/II's linear-in-angle falloff and summed wedges";

/// Why the penumbra map is pinned: its design.
const PMAP: &str = "penumbra map: outer penumbra only, umbra = the hard shadow (Wyman & Hansen); \
it darkens outward, so it is worse than the hard shadow by design";

/// Why the D-buffer is pinned (issue 28, item 1, being fixed in parallel: tighten these pins
/// once it lands).
const DBUF: &str = "issue 28: the D-buffer loses the soft penumbra on real meshes (the hard \
shadow with noise), worse than the hard shadow on bob, fish, scorpion, spider and spot";

/// (scene file stem, or `*-LIGHT` for every model under that light, method, bound). The
/// first entry matching a (scene, method) applies: specific entries go first. A pin's `max`
/// is the measured value plus 2 %, rounded up to 4 significant digits, so that an unrelated
/// change of the rasterization by a few ulps does not trip it while a regression does.
#[rustfmt::skip]
const TABLE: &[(&str, &str, Bound)] = &[
    ("bob-disk", "hard-sv", Pin { max: 0.009545, why: HARD }), // measured 0.0093578 (hard-sv 0.00936)
    ("bob-disk", "dbuffer", Pin { max: 0.01501, why: DBUF }), // measured 0.014708 (hard-sv 0.00936)
    ("bob-rect", "hard-sv", Pin { max: 0.01096, why: HARD }), // measured 0.01074 (hard-sv 0.01074)
    ("bob-sphere", "hard-sv", Pin { max: 0.01031, why: HARD }), // measured 0.010101 (hard-sv 0.01010)
    ("bob-sphere", "pw2002", Pin { max: 0.006220, why: PW }), // measured 0.0060976 (hard-sv 0.01010)
    ("bob-sphere", "pw-restructured", Pin { max: 0.003570, why: PW }), // measured 0.0034992 (hard-sv 0.01010)
    ("bob-sphere", "penumbra-map", Pin { max: 0.03216, why: PMAP }), // measured 0.031525 (hard-sv 0.01010)
    ("fish-disk", "hard-sv", Pin { max: 0.004385, why: HARD }), // measured 0.0042982 (hard-sv 0.00430)
    ("fish-disk", "dbuffer", Pin { max: 0.01126, why: DBUF }), // measured 0.011031 (hard-sv 0.00430)
    ("fish-rect", "hard-sv", Pin { max: 0.005053, why: HARD }), // measured 0.0049535 (hard-sv 0.00495)
    ("fish-sphere", "hard-sv", Pin { max: 0.004841, why: HARD }), // measured 0.0047456 (hard-sv 0.00475)
    ("fish-sphere", "pw2002", Pin { max: 0.002643, why: PW }), // measured 0.0025911 (hard-sv 0.00475)
    ("fish-sphere", "pw-restructured", Pin { max: 0.001852, why: PW }), // measured 0.0018152 (hard-sv 0.00475)
    ("fish-sphere", "penumbra-map", Pin { max: 0.01515, why: PMAP }), // measured 0.014849 (hard-sv 0.00475)
    ("goathead-disk", "hard-sv", Pin { max: 0.04447, why: HARD }), // measured 0.043597 (hard-sv 0.04360)
    ("goathead-disk", "dbuffer", Pin { max: 0.04212, why: DBUF }), // measured 0.041285 (hard-sv 0.04360)
    ("goathead-rect", "hard-sv", Pin { max: 0.05039, why: HARD }), // measured 0.049393 (hard-sv 0.04939)
    ("goathead-sphere", "hard-sv", Pin { max: 0.04818, why: HARD }), // measured 0.047234 (hard-sv 0.04723)
    ("goathead-sphere", "pw2002", Pin { max: 0.04950, why: PW }), // measured 0.048526 (hard-sv 0.04723)
    ("goathead-sphere", "pw-restructured", Pin { max: 0.02696, why: PW }), // measured 0.026425 (hard-sv 0.04723)
    ("goathead-sphere", "penumbra-map", Pin { max: 0.07325, why: PMAP }), // measured 0.071805 (hard-sv 0.04723)
    ("hand-disk", "hard-sv", Pin { max: 0.09364, why: HARD }), // measured 0.091796 (hard-sv 0.09180)
    ("hand-disk", "dbuffer", Pin { max: 0.07932, why: DBUF }), // measured 0.07776 (hard-sv 0.09180)
    ("hand-rect", "hard-sv", Pin { max: 0.1028, why: HARD }), // measured 0.10073 (hard-sv 0.10073)
    ("hand-sphere", "hard-sv", Pin { max: 0.09946, why: HARD }), // measured 0.097507 (hard-sv 0.09751)
    ("hand-sphere", "pw2002", Pin { max: 0.1608, why: PW }), // measured 0.15758 (hard-sv 0.09751)
    ("hand-sphere", "pw-restructured", Pin { max: 0.1028, why: PW }), // measured 0.10073 (hard-sv 0.09751)
    ("hand-sphere", "penumbra-map", Pin { max: 0.1666, why: PMAP }), // measured 0.16325 (hard-sv 0.09751)
    ("scorpion-disk", "hard-sv", Pin { max: 0.01455, why: HARD }), // measured 0.01426 (hard-sv 0.01426)
    ("scorpion-disk", "dbuffer", Pin { max: 0.03169, why: DBUF }), // measured 0.03106 (hard-sv 0.01426)
    ("scorpion-rect", "hard-sv", Pin { max: 0.01678, why: HARD }), // measured 0.016445 (hard-sv 0.01644)
    ("scorpion-sphere", "hard-sv", Pin { max: 0.01637, why: HARD }), // measured 0.016045 (hard-sv 0.01605)
    ("scorpion-sphere", "pw2002", Pin { max: 0.02072, why: PW }), // measured 0.020314 (hard-sv 0.01605)
    ("scorpion-sphere", "pw-restructured", Pin { max: 0.01327, why: PW }), // measured 0.013005 (hard-sv 0.01605)
    ("scorpion-sphere", "penumbra-map", Pin { max: 0.05697, why: PMAP }), // measured 0.055844 (hard-sv 0.01605)
    ("spider-disk", "hard-sv", Pin { max: 0.01959, why: HARD }), // measured 0.019204 (hard-sv 0.01920)
    ("spider-disk", "dbuffer", Pin { max: 0.02202, why: DBUF }), // measured 0.021587 (hard-sv 0.01920)
    ("spider-rect", "hard-sv", Pin { max: 0.02142, why: HARD }), // measured 0.020996 (hard-sv 0.02100)
    ("spider-sphere", "hard-sv", Pin { max: 0.02004, why: HARD }), // measured 0.019639 (hard-sv 0.01964)
    ("spider-sphere", "pw2002", Pin { max: 0.01216, why: PW }), // measured 0.011921 (hard-sv 0.01964)
    ("spider-sphere", "pw-restructured", Pin { max: 0.007585, why: PW }), // measured 0.0074355 (hard-sv 0.01964)
    ("spider-sphere", "penumbra-map", Pin { max: 0.04185, why: PMAP }), // measured 0.041025 (hard-sv 0.01964)
    ("spot-disk", "hard-sv", Pin { max: 0.01250, why: HARD }), // measured 0.012249 (hard-sv 0.01225)
    ("spot-disk", "dbuffer", Pin { max: 0.02034, why: DBUF }), // measured 0.019941 (hard-sv 0.01225)
    ("spot-rect", "hard-sv", Pin { max: 0.01441, why: HARD }), // measured 0.014121 (hard-sv 0.01412)
    ("spot-sphere", "hard-sv", Pin { max: 0.01438, why: HARD }), // measured 0.01409 (hard-sv 0.01409)
    ("spot-sphere", "pw2002", Pin { max: 0.01883, why: PW }), // measured 0.018453 (hard-sv 0.01409)
    ("spot-sphere", "pw-restructured", Pin { max: 0.01044, why: PW }), // measured 0.01023 (hard-sv 0.01409)
    ("spot-sphere", "penumbra-map", Pin { max: 0.03254, why: PMAP }), // measured 0.031893 (hard-sv 0.01409)
    ("wingnut-disk", "hard-sv", Pin { max: 0.02618, why: HARD }), // measured 0.025658 (hard-sv 0.02566)
    ("wingnut-disk", "dbuffer", Pin { max: 0.01988, why: DBUF }), // measured 0.019484 (hard-sv 0.02566)
    ("wingnut-rect", "hard-sv", Pin { max: 0.03014, why: HARD }), // measured 0.029541 (hard-sv 0.02954)
    ("wingnut-sphere", "hard-sv", Pin { max: 0.02950, why: HARD }), // measured 0.028915 (hard-sv 0.02892)
    ("wingnut-sphere", "pw2002", Pin { max: 0.008485, why: PW }), // measured 0.0083178 (hard-sv 0.02892)
    ("wingnut-sphere", "pw-restructured", Pin { max: 0.006357, why: PW }), // measured 0.0062322 (hard-sv 0.02892)
    ("wingnut-sphere", "penumbra-map", Pin { max: 0.04913, why: PMAP }), // measured 0.048158 (hard-sv 0.02892)
    ("*-rect", "nsample", NSAMPLE),
    ("*-sphere", "nsample", NSAMPLE),
    ("*-disk", "nsample", NSAMPLE),
    ("*-rect", "ssv", SSV),
    ("*-sphere", "ssv", SSV),
    ("*-rect", "ssv-optimized", SSV),
    ("*-sphere", "ssv-optimized", SSV),
    ("*-rect", "wedge-blending", WEDGE_BLENDING),
];

fn catalog_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/real-catalog")
}

fn scene_files() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(catalog_dir())
        .expect("scenes/real-catalog")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    v
}

fn stem(p: &Path) -> String {
    p.file_stem().unwrap().to_string_lossy().into_owned()
}

/// Whether a [`TABLE`] scene pattern matches the scene `name`.
fn matches(pattern: &str, name: &str) -> bool {
    match pattern.strip_prefix('*') {
        Some(suffix) => name.ends_with(suffix),
        None => pattern == name,
    }
}

/// One measured row.
struct Row {
    scene: String,
    method: String,
    whole_light: f64,
    horizon: f64,
    horizon_share: f64,
    clamped: u64,
    warnings: usize,
}

/// Renders `scene` with `method` (the test's sample counts set) on `frame`'s scene pass.
fn run(frame: &Frame, scene: &Scene, method: &str) -> penumbra::MethodOutput {
    let knobs: &[(&str, &str)] = match method {
        "raycast" => &[("samples", REFERENCE_SAMPLES)],
        "nsample" => &[("n", NSAMPLE_N)],
        _ => &[],
    };
    let s = configured(scene, method, knobs);
    methods::run(method, &frame.lit_by(&s)).unwrap_or_else(|e| panic!("{method}: {e}"))
}

#[test]
fn every_real_model_renders_with_every_method_within_its_bound() {
    let files = scene_files();
    assert_eq!(
        files.len(),
        24,
        "8 models × 3 lights in scenes/real-catalog"
    );
    let mut failures = Vec::new();
    let mut rows: Vec<Row> = Vec::new();
    let mut seen = Vec::new();
    for path in &files {
        let name = stem(path);
        let mut scene = penumbra::scene::file::load_scene_file(path)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        scene.width = SIZE;
        scene.height = SIZE;
        let gpu = penumbra::render::gpu_settings(&scene).unwrap();
        let frame = Frame::render(&scene, gpu).unwrap_or_else(|e| panic!("{name}: {e}"));
        let classes = receiver_classes(&scene.lights, frame.receivers());
        let reference = run(&frame, &scene, methods::REFERENCE).visibility;
        // The reference's own noise: the next seed.
        let next = configured(
            &scene,
            "raycast",
            &[("samples", REFERENCE_SAMPLES), ("seed", "1")],
        );
        let noisy = methods::run("raycast", &frame.lit_by(&next))
            .unwrap()
            .visibility;
        let noise = error_report(&noisy, &reference, "raycast", &classes).horizon_split;
        rows.push(Row {
            scene: name.clone(),
            method: "(raycast seed 1)".into(),
            whole_light: noise.whole_light.mean_abs,
            horizon: noise.horizon.mean_abs,
            horizon_share: noise.horizon_share,
            clamped: 0,
            warnings: 0,
        });
        if noise.whole_light.mean_abs > NOISE_MAX {
            failures.push(format!(
                "{name}: the reference's own noise {:.5} > {NOISE_MAX} over whole-light \
                 receivers: raise REFERENCE_SAMPLES",
                noise.whole_light.mean_abs
            ));
        }
        let mut hard = f64::NAN;
        for m in methods::names() {
            if m == methods::REFERENCE || !methods::supports_scene(m, &scene) {
                continue;
            }
            let out = run(&frame, &scene, m);
            let split =
                error_report(&out.visibility, &reference, "raycast", &classes).horizon_split;
            if m == "hard-sv" {
                hard = split.whole_light.mean_abs;
            }
            rows.push(Row {
                scene: name.clone(),
                method: m.to_string(),
                whole_light: split.whole_light.mean_abs,
                horizon: split.horizon.mean_abs,
                horizon_share: split.horizon_share,
                clamped: out.stats.clamped_pixels,
                warnings: out.stats.warnings.len(),
            });
        }
        assert!(hard.is_finite(), "{name}: hard-sv runs on every light");
        // Issue 28's rule: no method is silently worse than the hard shadow on receivers that
        // see the whole light — where one is, it warns (penumbra-map aside: it darkens
        // outward by design, Wyman & Hansen).
        for row in rows.iter().filter(|r| {
            r.scene == name
                && !r.method.starts_with('(')
                && r.method != "hard-sv"
                && r.method != "penumbra-map"
        }) {
            if row.whole_light > hard && row.warnings == 0 {
                failures.push(format!(
                    "{name} {}: whole-light mean |e| {:.5} > hard-sv's {hard:.5} and no warning",
                    row.method, row.whole_light
                ));
            }
        }
        for row in rows
            .iter()
            .filter(|r| r.scene == name && !r.method.starts_with('('))
        {
            seen.push((name.clone(), row.method.clone()));
            let entry = TABLE
                .iter()
                .find(|(s, m, _)| matches(s, &name) && *m == row.method);
            match entry {
                None => failures.push(format!(
                    "{name} {}: no entry in TABLE (whole-light mean |e| {:.7}, hard-sv {hard:.5}): \
                     add one to tests/suite/real_model_catalog.rs — Correct if the bound \
                     follows from the math or a paper, else Pin with the reason",
                    row.method, row.whole_light
                )),
                Some((_, _, b)) if row.whole_light.is_nan() || row.whole_light > b.max(hard) => {
                    failures.push(format!(
                        "{name} {}: whole-light mean |e| {:.5} > {}",
                        row.method,
                        row.whole_light,
                        b.describe(hard)
                    ))
                }
                _ => {}
            }
        }
    }
    eprintln!(
        "{:<20} {:<18} {:>10} {:>10} {:>8} {:>8} {:>5}  bound",
        "scene", "method", "whole |e|", "horizon|e|", "h.share", "clamped", "warn"
    );
    for r in &rows {
        let hard = rows
            .iter()
            .find(|h| h.scene == r.scene && h.method == "hard-sv")
            .map_or(f64::NAN, |h| h.whole_light);
        let kind = TABLE
            .iter()
            .find(|(s, m, _)| matches(s, &r.scene) && *m == r.method)
            .map_or(String::new(), |e| e.2.describe(hard));
        eprintln!(
            "{:<20} {:<18} {:>10.5} {:>10.5} {:>8.3} {:>8} {:>5}  {kind}",
            r.scene, r.method, r.whole_light, r.horizon, r.horizon_share, r.clamped, r.warnings
        );
    }
    for (s, m, _) in TABLE {
        if !seen.iter().any(|(ss, mm)| matches(s, ss) && mm == m) {
            failures.push(format!(
                "TABLE entry ({s}, {m}) matches no scene and method"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
