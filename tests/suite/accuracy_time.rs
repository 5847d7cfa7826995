//! The accuracy–time experiment (`penumbra::experiment::accuracy_time`): sharded sweeps merge
//! into the unsharded one, the Pareto front, the reference against itself, `nsample`'s
//! convergence, the default table's option values, and bad `--shard` / `merge` input on the
//! command line. Small frames (32² and 48²), short configuration lists and one timed run:
//! timing decides nothing here.

use penumbra::experiment::accuracy_time::{self, merge, pareto_front, Configuration, Shard, Sweep};
use penumbra::experiment::{configured, sized};
use penumbra::frame::Frame;
use penumbra::gpu_model::GpuModel;
use penumbra::scene::{builtin, Scene};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A fresh, not yet existing directory under `CARGO_TARGET_TMPDIR`, unique per call.
fn fresh_dir(tag: &str) -> PathBuf {
    static N: AtomicUsize = AtomicUsize::new(0);
    let n = N.fetch_add(1, Ordering::Relaxed);
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("accuracy_time-{tag}-{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn scene(name: &str, size: u32) -> Scene {
    sized(builtin::load(name).expect("a built-in scene"), size)
}

/// A tiny list: on `single-quad` (rect light) and `cylinder` (sphere light) it has items of
/// both scenes, methods that support only one of the lights, and a configuration the method
/// refuses on the sphere (`light-split`).
const TINY: &[Configuration] = &[
    ("hard-sv", &[]),
    ("nsample", &[("n", "4")]),
    ("raycast", &[("samples", "16")]),
    ("pw2002", &[("li", "8")]),
    ("ssv", &[("coverage", "exact"), ("vbuffer", "f16")]),
    ("ssv-optimized", &[("light-split", "2")]),
    ("wedge-blending", &[("packing", "f32")]),
];

/// `sweep` without what depends on the clock: the times and the Pareto flags set to 0/false.
fn without_times(mut sweep: Sweep) -> Sweep {
    for r in &mut sweep.references {
        r.seconds = 0.0;
    }
    for r in &mut sweep.rows {
        (r.median_seconds, r.min_seconds, r.max_seconds) = (0.0, 0.0, 0.0);
        r.pareto = false;
    }
    sweep
}

/// The CSV without its timing columns (median, min, max seconds) and the Pareto flag (the
/// modeled times and their fronts stay: they depend on no clock).
fn csv_without_times(csv: &str) -> Vec<String> {
    let first = csv.lines().next().unwrap_or_default().to_string();
    let header: Vec<&str> = first.split(',').collect();
    let timing = |name: &str| name.ends_with("_seconds") || name == "pareto";
    csv.lines()
        .map(|line| {
            line.split(',')
                .zip(&header)
                .filter(|(_, h)| !timing(h))
                .map(|(v, _)| v)
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect()
}

#[test]
fn four_shards_merged_equal_the_unsharded_sweep() {
    let scenes = [scene("single-quad", 32), scene("cylinder", 32)];
    let whole = accuracy_time::run(&scenes, TINY, 1, Shard::WHOLE, &[GpuModel::default()]).unwrap();
    // The list: rect-light methods on single-quad, sphere-light ones on cylinder, the light
    // split refused on the sphere.
    let on = |s: &str| whole.items.iter().filter(|i| i.scene == s).count();
    assert_eq!(
        (on("single-quad"), on("cylinder")),
        (6, 5),
        "{:?}",
        whole.items
    );
    assert_eq!(whole.skipped.len(), 1, "{:?}", whole.skipped);
    assert_eq!(whole.skipped[0].method, "ssv-optimized");
    assert_eq!(whole.rows.len(), whole.items.len());
    assert_eq!(whole.references.len(), 2);

    // Four shards, each written and read back as a separate run would, then merged.
    let mut shards = Vec::new();
    for i in 1..=4 {
        let shard = Shard { index: i, count: 4 };
        let part = accuracy_time::run(&scenes, TINY, 1, shard, &[GpuModel::default()]).unwrap();
        assert!(part.rows.iter().all(|r| shard.holds(r.index)));
        let dir = fresh_dir(&format!("shard{i}"));
        accuracy_time::write(&part, &dir).unwrap();
        assert!(
            !dir.join("single-quad-pareto.png").exists(),
            "a shard draws no plots"
        );
        let back = accuracy_time::read(&dir).unwrap();
        assert_eq!(back, part, "JSON round trip of shard {shard}");
        shards.push((dir.display().to_string(), back));
    }
    let merged = merge(&shards).unwrap();
    assert_eq!(without_times(merged.clone()), without_times(whole.clone()));

    // Modeled times: every row on the default profile; only the CPU ray tracer is not
    // modeled, and the profile's front holds only modeled rows.
    assert_eq!(
        whole.gpus,
        vec![penumbra::gpu_model::DEFAULT_PROFILE.to_string()]
    );
    for r in &whole.rows {
        assert_eq!(r.modeled.len(), 1);
        match r.modeled[0].seconds {
            None => assert_eq!(r.item.method, "raycast", "{r:?}"),
            Some(t) => {
                assert_ne!(r.item.method, "raycast");
                assert!(0.0 < t.low && t.low <= t.mid && t.mid <= t.high, "{r:?}");
            }
        }
        assert!(!r.modeled[0].pareto || r.modeled[0].seconds.is_some());
    }
    for s in ["single-quad", "cylinder"] {
        let axis = accuracy_time::TimeAxis::Gpu(0);
        assert!(
            !accuracy_time::pareto_rows(&whole, s, axis).is_empty(),
            "{s}"
        );
    }

    // The written outputs agree too, but for the timing columns; plots for both scenes.
    let (a, b) = (fresh_dir("whole"), fresh_dir("merged"));
    accuracy_time::write(&whole, &a).unwrap();
    accuracy_time::write(&merged, &b).unwrap();
    let csv = |d: &Path| std::fs::read_to_string(d.join(accuracy_time::CSV_FILE)).unwrap();
    assert_eq!(csv_without_times(&csv(&a)), csv_without_times(&csv(&b)));
    assert_eq!(csv(&a).lines().count(), 1 + whole.rows.len());
    for dir in [&a, &b] {
        for stem in ["single-quad", "cylinder"] {
            let png = std::fs::read(dir.join(format!("{stem}-pareto.png"))).unwrap();
            assert_eq!(&png[1..4], b"PNG");
            let svg = std::fs::read_to_string(dir.join(format!("{stem}-pareto.svg"))).unwrap();
            assert!(svg.starts_with("<svg") && svg.contains("Pareto front"));
            let gpu = penumbra::gpu_model::DEFAULT_PROFILE;
            let svg = dir.join(format!("{stem}-pareto-gpu-{gpu}.svg"));
            let svg = std::fs::read_to_string(svg).unwrap();
            assert!(svg.contains("modeled GPU time") && svg.contains("not modeled"));
        }
    }

    // Not the slices of one list: a shard twice, one missing, another list.
    let err = |s: &[(String, Sweep)]| merge(s).unwrap_err().to_string();
    let twice = [shards[0].clone(), shards[0].clone()];
    assert!(err(&twice).contains("overlap"), "{}", err(&twice));
    assert!(err(&shards[..3]).contains("shards missing: 4/4"));
    let mut other = shards.clone();
    other[2].1.items.pop();
    assert!(
        err(&other).contains("GPU profiles differ"),
        "{}",
        err(&other)
    );
}

#[test]
fn the_pareto_front_of_hand_made_points() {
    // (time, error)
    let points = [
        (1.0, 0.5),  // 0: fastest → on the front
        (2.0, 0.6),  // 1: slower and worse than 0
        (2.0, 0.2),  // 2: on the front
        (3.0, 0.2),  // 3: as accurate as 2 but slower
        (4.0, 0.05), // 4: on the front
        (4.0, 0.05), // 5: identical to 4: both stay
        (5.0, 0.01), // 6: most accurate → on the front
        (0.5, f64::NAN),
        (6.0, 0.3), // 8: dominated
    ];
    assert_eq!(pareto_front(&points), vec![0, 2, 4, 5, 6]);
    assert_eq!(pareto_front(&[]), Vec::<usize>::new());
    assert_eq!(pareto_front(&[(1.0, 1.0)]), vec![0]);
    // The front is sorted by time whatever the input order.
    assert_eq!(pareto_front(&[(3.0, 0.1), (1.0, 0.9)]), vec![1, 0]);
}

/// The sweep renders the reference's configuration with the reference's own settings (the
/// same bits: error 0), and the seed reaches it: with another seed the reference differs from
/// itself, by no more than jittered stratification allows. With k×k strata (k = 32) only the
/// strata a shadow edge crosses can change between seeds, each by 1/k²; single-quad's square
/// occluder is aligned with its square light, so an edge crosses one column of k strata and at
/// most two edges cross the light at a pixel: |e| ≤ 2·k/k² = 2/32.
#[test]
fn the_reference_differs_from_itself_only_by_its_seed() {
    let scenes = [scene("single-quad", 32)];
    let cfg: &[Configuration] = &[
        accuracy_time::REFERENCE,
        ("raycast", &[("samples", "1024"), ("seed", "1")]),
    ];
    let sweep = accuracy_time::run(&scenes, cfg, 1, Shard::WHOLE, &[GpuModel::default()]).unwrap();
    let row = &sweep.rows[0];
    assert_eq!(
        (row.item.method.as_str(), row.item.knobs.as_str()),
        ("raycast", "samples=1024")
    );
    assert_eq!(row.error.rmse, 0.0);
    assert_eq!(row.error.max_abs, 0.0);
    assert!(row.penumbra.pixels > 0, "single-quad has a penumbra");
    let other = &sweep.rows[1];
    assert_eq!(other.item.knobs, "samples=1024 seed=1");
    eprintln!("reference, seed 1 against seed 0: {:?}", other.error);
    assert!(other.error.max_abs > 0.0, "the seed changes the jitter");
    assert!(other.error.max_abs <= 2.0 / 32.0, "{:?}", other.error);
}

/// `nsample` converges on `single-quad` as N grows. With k×k strata (N = k²) sampled at their
/// centers, an occluder edge parallel to a light axis (single-quad's square occluder is
/// parallel to its square light and aligned with it) cuts one column of k strata, all at the
/// same fraction f, so a pixel's error is (1/k)·([f > ½] − f): at most 1/(2k) per crossing edge
/// (two at most), with RMS (1/k)/√12 over a penumbra where f is uniform — the RMSE halves each
/// time N quadruples. The reference (k = 32 jittered) adds at most 1/32 per edge, and the
/// rasterized hard shadows a few samples (2/N). So, at every pixel,
/// |e| ≤ 2·(1/(2k) + 1/32) + 2/N; the penumbra RMSE must stay within 1.25·(1/k)/√12 (corners,
/// where two edges cross, and the reference's noise add a little) and fall by at least a
/// quarter (0.75, against the 0.5 of the derivation) per quadrupling of N.
#[test]
fn nsample_converges_on_single_quad() {
    let scenes = [scene("single-quad", 48)];
    let cfg: &[Configuration] = &[
        ("nsample", &[("n", "4")]),
        ("nsample", &[("n", "16")]),
        ("nsample", &[("n", "64")]),
        ("nsample", &[("n", "256")]),
    ];
    let sweep = accuracy_time::run(&scenes, cfg, 1, Shard::WHOLE, &[GpuModel::default()]).unwrap();
    let mut previous: Option<f64> = None;
    for (row, n) in sweep.rows.iter().zip([4.0f64, 16.0, 64.0, 256.0]) {
        let k = n.sqrt();
        let bound = 2.0 * (1.0 / (2.0 * k) + 1.0 / 32.0) + 2.0 / n;
        eprintln!(
            "nsample n={n}: max |e| {} (bound {bound}), RMSE {}, penumbra RMSE {}",
            row.error.max_abs, row.error.rmse, row.penumbra.rmse
        );
        assert!(row.error.max_abs <= bound, "n={n}: {:?}", row.error);
        let rms_bound = 1.25 / (k * 12f64.sqrt());
        assert!(
            row.penumbra.rmse <= rms_bound,
            "n={n}: penumbra RMSE {} > {rms_bound}",
            row.penumbra.rmse
        );
        if let Some(p) = previous {
            assert!(
                row.penumbra.rmse <= 0.75 * p,
                "n={n}: penumbra RMSE {} vs {p} at n/4",
                row.penumbra.rmse
            );
        }
        previous = Some(row.penumbra.rmse);
    }
}

/// Every configuration of the default table is accepted by its method's option reader on a
/// built-in scene (a rect, a sphere or a disk light), so a misspelt key or value cannot hide
/// among the skipped ones; on `single-quad` none is skipped.
#[test]
fn every_default_configuration_is_accepted_somewhere() {
    let scenes = [
        scene("single-quad", 16),
        scene("cylinder", 16),
        scene("disk-block", 16),
    ];
    let frames: Vec<Frame> = scenes
        .iter()
        .map(|s| Frame::render(s, penumbra::render::gpu_settings(s).unwrap()).unwrap())
        .collect();
    for (method, knobs) in accuracy_time::configurations() {
        let accepted: Vec<bool> = scenes
            .iter()
            .zip(&frames)
            .map(|(s, f)| {
                penumbra::methods::supports_scene(method, s)
                    && penumbra::methods::check_options(
                        method,
                        &f.lit_by(&configured(s, method, knobs)),
                    )
                    .is_ok()
            })
            .collect();
        assert!(
            accepted.contains(&true),
            "{method} {knobs:?} is refused everywhere"
        );
        let rect_light = penumbra::methods::supports_scene(method, &scenes[0]);
        assert_eq!(accepted[0], rect_light, "{method} {knobs:?} on single-quad");
    }
}

#[test]
fn shard_specs() {
    assert_eq!(Shard::parse("2/4").unwrap(), Shard { index: 2, count: 4 });
    assert_eq!(Shard::parse("1/1").unwrap(), Shard::WHOLE);
    for bad in ["0/4", "5/4", "1/0", "2", "a/4", "2/b", "-1/4", ""] {
        assert!(Shard::parse(bad).is_err(), "{bad:?} accepted");
    }
    // Round-robin slices: every item in exactly one shard.
    for k in 0..20 {
        let owners = (1..=3)
            .filter(|&i| Shard { index: i, count: 3 }.holds(k))
            .count();
        assert_eq!(owners, 1);
    }
}

/// Runs the built binary with `args` in the crate root.
fn penumbra(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cannot run the penumbra binary")
}

/// Asserts exit status 2, one line on stderr containing every one of `words`, no output
/// directory.
fn assert_exit_2(output: &std::process::Output, words: &[&str], out: &Path) {
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "stderr {stderr:?}");
    assert_eq!(stderr.lines().count(), 1, "{stderr:?}");
    for w in words {
        assert!(stderr.contains(w), "{w:?} not in {stderr:?}");
    }
    assert!(!out.exists(), "wrote {}", out.display());
}

/// Runs a 16² one-run sweep of `single-quad` into `out` with the arguments `extra`.
fn tiny_sweep(extra: &[&str], out: &Path) -> std::process::Output {
    let o = out.to_str().unwrap();
    let mut args = vec![
        "experiment",
        "accuracy-time",
        "single-quad",
        "--size",
        "16",
        "--runs",
        "1",
        "--out",
        o,
    ];
    args.extend(extra);
    penumbra(&args)
}

#[test]
fn bad_shard_specs_and_merges_exit_2() {
    for spec in ["5/4", "0/4", "1/0", "x/4", "3"] {
        let out = fresh_dir("cli-bad-shard");
        let output = tiny_sweep(&["--shard", spec], &out);
        assert_exit_2(&output, &["--shard", spec, "1 ≤ I ≤ N"], &out);
    }
    // GPU profiles: an unknown one, one given twice.
    let unknown = ["--gpu", "voodoo2", "unknown GPU profile", "radeon-9700-pro"];
    let twice = ["--gpu", "geforce3", "given twice"];
    for (args, words) in [
        (&["--gpu", "voodoo2"][..], &unknown[..]),
        (&["--gpu", "geforce3", "--gpu", "geforce3"][..], &twice[..]),
    ] {
        let out = fresh_dir("cli-bad-gpu");
        assert_exit_2(&tiny_sweep(args, &out), words, &out);
    }
    // Merging: a shard given twice; a directory without results.
    let scenes = [scene("single-quad", 16)];
    let cfg: &[Configuration] = &[("hard-sv", &[]), ("ssv", &[])];
    let dir = fresh_dir("cli-shard");
    let part = accuracy_time::run(
        &scenes,
        cfg,
        1,
        Shard { index: 1, count: 2 },
        &[GpuModel::default()],
    )
    .unwrap();
    accuracy_time::write(&part, &dir).unwrap();
    let d = dir.to_str().unwrap();
    let out = fresh_dir("cli-merge");
    let o = out.to_str().unwrap();
    assert_exit_2(
        &penumbra(&["experiment", "merge", d, d, "--out", o]),
        &["shard 1/2", "overlap"],
        &out,
    );
    assert_exit_2(
        &penumbra(&["experiment", "merge", d, "--out", o]),
        &["shards missing: 2/2"],
        &out,
    );
    let empty = fresh_dir("cli-empty");
    std::fs::create_dir_all(&empty).unwrap();
    assert_exit_2(
        &penumbra(&["experiment", "merge", empty.to_str().unwrap(), "--out", o]),
        &["accuracy-time.json", "cannot read"],
        &out,
    );
}
