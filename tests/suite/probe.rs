//! `penumbra probe` (issue 14 item 3, `docs/architecture.md` "Probing one pixel"): for every
//! method on a small built-in scene, the probe's trace ends in the rendered pixel's value bit
//! for bit, every buffer's value before an event is its value after the one before, and
//! attaching a probe changes no output bit and no counter. The stacked plates of
//! `scenes/hard/stack-256-*.toml` show the stencil wrap and the split V-buffer's saturation at
//! a pixel under all 256 plates. Bad `probe` arguments exit with status 2.

use penumbra::frame::Frame;
use penumbra::gpu::probe::{check_chains, Overflow, Probe, ProbeEvent};
use penumbra::methods::dump::DumpValues;
use penumbra::methods::{self, output::MethodOutput};
use penumbra::render::checked_frame;
use penumbra::scene::{builtin, file, OptionValue, Scene};
use std::process::Command;
use std::sync::Arc;

/// Built-in `name` at `size`², with `options` (METHOD, KEY, VALUE) set.
fn scene(name: &str, size: u32, options: &[(&str, &str, OptionValue)]) -> Scene {
    let mut s = builtin::load(name).expect("a built-in scene");
    s.resize(Some(size), Some(size));
    for (m, k, v) in options {
        s.options
            .entry(m.to_string())
            .or_default()
            .insert(k.to_string(), v.clone());
    }
    s
}

/// The first receiver pixel (row-major) where `out` is strictly between 0 and 1 — a penumbra
/// pixel, whose trace has contributions — else the first receiver pixel.
fn penumbra_pixel(frame: &Frame, out: &MethodOutput) -> usize {
    let receiver = |i: &usize| frame.receivers()[*i].is_some();
    let all = 0..frame.pixel_count();
    all.clone()
        .filter(receiver)
        .find(|&i| (0.0..1.0).contains(&out.visibility.gray(i)) && out.visibility.gray(i) > 0.0)
        .or_else(|| all.clone().find(receiver))
        .expect("a receiver pixel")
}

/// The visibility bits of a method output (every channel of every pixel).
fn bits(out: &MethodOutput) -> Vec<u32> {
    (0..out.visibility.len())
        .flat_map(|i| out.visibility.rgb(i).map(f32::to_bits))
        .collect()
}

/// Renders `method` on `scene` without and then with a probe at a penumbra pixel; checks
/// that the outputs are the same bits and counters, that the trace ends in the pixel's value
/// and that every buffer chains. Returns the pixel and the events.
fn probe_and_check(scene: &Scene, method: &str) -> (usize, Vec<ProbeEvent>) {
    let mut frame = checked_frame(scene).unwrap();
    let plain = methods::run(method, &frame).unwrap();
    let i = penumbra_pixel(&frame, &plain);
    let (x, y) = (i as u32 % scene.width, i as u32 / scene.width);
    let probe = Arc::new(Probe::new(x, y));
    frame.probe = Some(probe.clone());
    let probed = methods::run(method, &frame).unwrap();
    let label = format!("{method} on {} at ({x}, {y})", scene.source);
    assert_eq!(
        bits(&plain),
        bits(&probed),
        "{label}: probing changed the image"
    );
    assert_eq!(
        plain.stats.totals, probed.stats.totals,
        "{label}: probing changed the counters"
    );
    assert_eq!(plain.dumps, probed.dumps, "{label}: buffer dumps");
    let events = probe.events();
    assert!(events.len() >= 2, "{label}: {} events", events.len());
    let last = events
        .iter()
        .rev()
        .find_map(|e| e.resolve.as_ref())
        .unwrap_or_else(|| panic!("{label}: no resolve in the trace"));
    let want: Vec<u32> = probed
        .visibility
        .channels(i)
        .iter()
        .map(|v| v.to_bits())
        .collect();
    let got: Vec<u32> = last.visibility.iter().map(|v| v.to_bits()).collect();
    assert_eq!(got, want, "{label}: the trace's resolve is not the pixel");
    assert_eq!(check_chains(&events), Ok(()), "{label}");
    (i, events)
}

#[test]
fn every_method_traces_its_pixel_without_changing_its_output() {
    let int = |v| OptionValue::Int(v);
    let text = |v: &str| OptionValue::Str(v.into());
    let rect = scene("single-quad", 32, &[("nsample", "n", int(16))]);
    let sphere = scene("cube-of-spheres-sphere", 48, &[]);
    let disk = scene("disk-block", 48, &[]);
    let cases: Vec<(Scene, &str)> = vec![
        (rect.clone(), "raycast"),
        (rect.clone(), "nsample"),
        (rect.clone(), "hard-sv"),
        (rect.clone(), "ssv"),
        (rect.clone(), "ssv-optimized"),
        (rect.clone(), "wedge-blending"),
        (sphere.clone(), "pw2002"),
        (sphere.clone(), "pw-restructured"),
        (sphere.clone(), "penumbra-map"),
        (disk, "dbuffer"),
        // Variants whose passes record through other code.
        (
            scene(
                "single-quad",
                32,
                &[("hard-sv", "submission", text("two-pass"))],
            ),
            "hard-sv",
        ),
        (
            scene("single-quad", 32, &[("ssv", "vbuffer", text("8bit"))]),
            "ssv",
        ),
        (
            scene(
                "cube-of-spheres",
                32,
                &[("ssv-optimized", "overlap", text("loops"))],
            ),
            "ssv-optimized",
        ),
        (
            scene(
                "single-quad",
                32,
                &[("ssv-optimized", "light-split", int(2))],
            ),
            "ssv-optimized",
        ),
        (
            scene(
                "cube-of-spheres",
                32,
                &[("wedge-blending", "packing", text("f32"))],
            ),
            "wedge-blending",
        ),
        (
            scene(
                "cube-of-spheres-sphere",
                32,
                &[("pw-restructured", "passes", text("three"))],
            ),
            "pw-restructured",
        ),
        (
            scene(
                "cube-of-spheres-sphere",
                32,
                &[("penumbra-map", "filter", text("bilinear"))],
            ),
            "penumbra-map",
        ),
    ];
    for (s, m) in &cases {
        let (_, events) = probe_and_check(s, m);
        // Every rasterizing method records primitives with the passes that drew them.
        if *m != "raycast" {
            assert!(
                events
                    .iter()
                    .any(|e| e.primitive.is_some() && e.buffer.is_some()),
                "{m}: no fragment wrote a buffer at the pixel"
            );
        }
    }
}

/// Several lights: the per-light methods and the penumbra wedges' shared LI buffer both name
/// the light of every event that belongs to one.
#[test]
fn events_carry_the_light_index() {
    let s = scene("two-lights", 48, &[("nsample", "n", OptionValue::Int(4))]);
    // Methods run once per light: every pass of each light, and the average.
    for m in ["hard-sv", "nsample"] {
        let (_, events) = probe_and_check(&s, m);
        for k in [0, 1] {
            assert!(
                events.iter().any(|e| e.scope.light == Some(k)),
                "{m}: no event of light {k}"
            );
        }
        assert_eq!(events.last().unwrap().pass, "average-lights", "{m}");
    }
    // One LI buffer for both lights (Paper I §7): each wedge fragment names its wedge's light;
    // some penumbra pixel has wedges of both.
    let mut frame = checked_frame(&s).unwrap();
    let out = methods::run("pw2002", &frame).unwrap();
    let penumbra: Vec<usize> = (0..frame.pixel_count())
        .filter(|&i| out.visibility.gray(i) > 0.0 && out.visibility.gray(i) < 1.0)
        .collect();
    let mut both = false;
    for &i in penumbra.iter().step_by(penumbra.len().div_ceil(40).max(1)) {
        let probe = Arc::new(Probe::new(i as u32 % s.width, i as u32 / s.width));
        frame.probe = Some(probe.clone());
        methods::run("pw2002", &frame).unwrap();
        let wedges: Vec<_> = probe
            .events()
            .into_iter()
            .filter(|e| e.primitive.is_some())
            .collect();
        assert!(wedges.iter().all(|e| e.scope.light.is_some()));
        both |= [0, 1]
            .iter()
            .all(|k| wedges.iter().any(|e| e.scope.light == Some(*k)));
    }
    assert!(both, "no penumbra pixel drawn by wedges of both lights");
}

/// The pixel of `scene` (row-major) where `hard-sv` with a saturating stencil counts 255: under
/// every one of the 256 plates.
fn under_all_plates(scene: &Scene) -> (u32, u32) {
    let mut s = scene.clone();
    s.options
        .entry("hard-sv".into())
        .or_default()
        .insert("stencil".into(), OptionValue::Str("saturate".into()));
    let frame = checked_frame(&s).unwrap();
    let out = methods::run("hard-sv", &frame).unwrap();
    let DumpValues::U8(stencil) = &out.dumps[0].values else {
        panic!("hard-sv's stencil dump is 8-bit");
    };
    let i = stencil
        .iter()
        .position(|v| *v == 255)
        .expect("a pixel under all 256 plates");
    (i as u32 % s.width, i as u32 / s.width)
}

#[test]
fn stacked_plates_show_the_stencil_wrap_and_the_split_saturation() {
    let scene = file::resolve("scenes/hard/stack-256-rect.toml").unwrap();
    let (x, y) = under_all_plates(&scene);
    let overflow = |events: &[ProbeEvent], kind: Overflow| {
        events
            .iter()
            .filter_map(|e| e.buffer.as_ref()?.overflow)
            .filter(|(k, _)| *k == kind)
            .map(|(_, n)| n)
            .sum::<u64>()
    };
    // hard-sv wraps: 256 increments take the count back to 0 once, and the pixel reads lit.
    let r = penumbra::probe::probe_pixel(&scene, "hard-sv", [x, y], true).unwrap();
    assert!(r.chain_break.is_none(), "{:?}", r.chain_break);
    assert!(overflow(&r.events, Overflow::Wrap) >= 1, "no stencil wrap");
    assert_eq!(r.visibility, vec![1.0], "the wrapped count reads lit");
    assert_eq!(r.reference, vec![0.0], "under 256 opaque plates");
    // ssv-optimized: pass 1 blends one full value per plate into the subtractive buffer;
    // each 8-bit channel holds ⌊255/7⌋ = 36 full values of the default 3-bit split
    // (Paper IV §4.3), so 256 plates saturate it.
    let r = penumbra::probe::probe_pixel(&scene, "ssv-optimized", [x, y], true).unwrap();
    assert!(r.chain_break.is_none(), "{:?}", r.chain_break);
    assert!(
        overflow(&r.events, Overflow::Saturate) >= 4,
        "no saturated split channel"
    );
}

/// `penumbra probe ARGS` in the crate root.
fn penumbra(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(["probe"].iter().chain(args))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cannot run the penumbra binary")
}

#[test]
fn listing_and_json_describe_the_same_trace() {
    let args = ["single-quad", "--method", "hard-sv", "--pixel", "20,40"];
    let args: Vec<&str> = args.iter().chain(&["--width", "64"]).copied().collect();
    let text = penumbra(&args);
    assert_eq!(text.status.code(), Some(0));
    let text = String::from_utf8(text.stdout).unwrap();
    let json_args: Vec<&str> = args.iter().chain(&["--json"]).copied().collect();
    let json = penumbra(&json_args);
    assert_eq!(json.status.code(), Some(0));
    let report: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let events = report["events"].as_array().unwrap();
    // One line per event after the two header lines, then the result lines.
    let lines: Vec<&str> = text.lines().collect();
    for (k, e) in events.iter().enumerate() {
        let line = lines[2 + k];
        assert!(line.starts_with(&format!("{k} ")), "{line}");
        assert!(line.contains(e["pass"].as_str().unwrap()), "{line}");
    }
    assert_eq!(report["pixel"], serde_json::json!([20, 40]));
    assert!(report["chain_break"].is_null());
    assert!(text.contains("reference (raycast, 1024 samples)"));
}

#[test]
fn bad_probe_arguments_exit_2() {
    let cases: [(&[&str], &str); 5] = [
        (
            &[
                "single-quad",
                "--method",
                "hard-sv",
                "--pixel",
                "64,3",
                "--width",
                "64",
            ],
            "--pixel: 64,3: outside the 64×64 image",
        ),
        (
            &["single-quad", "--method", "hard-sv", "--pixel", "3"],
            "--pixel: 3: expected X,Y",
        ),
        (
            &["single-quad", "--method", "shadow-maps", "--pixel", "3,3"],
            "unknown method \"shadow-maps\"",
        ),
        (
            &["single-quad", "--method", "pw2002", "--pixel", "3,3"],
            "method pw2002 does not support rect lights",
        ),
        (
            &[
                "single-quad",
                "--method",
                "ssv",
                "--pixel",
                "3,3",
                "--methods",
                "ssv",
            ],
            "--methods",
        ),
    ];
    for (args, message) in cases {
        let out = penumbra(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
}

/// HiZ tiles finer than the raster tile (`gpu.hiz-tile-size = 4` in 32×32 tiles): a volume
/// triangle rejected by the HiZ tiles under part of a raster tile is recorded as culled at
/// the watched samples it covers there, though it is drawn in the rest of the tile. At each
/// pixel of a grid, the probe records at least the rejections of 32×32 HiZ tiles (a finer
/// HiZ tile rejects whatever the coarser one holding it rejects), more at some, and probing
/// changes no bit or counter.
#[test]
fn finer_hiz_tiles_record_rejections_inside_a_raster_tile() {
    let culled_notes = |hiz: i64, x: u32, y: u32| {
        let s = scene(
            "cube-of-spheres",
            64,
            &[
                ("gpu", "tile-size", OptionValue::Int(32)),
                ("gpu", "hiz-tile-size", OptionValue::Int(hiz)),
            ],
        );
        let mut frame = checked_frame(&s).unwrap();
        let plain = methods::run("hard-sv", &frame).unwrap();
        let probe = Arc::new(Probe::new(x, y));
        frame.probe = Some(probe.clone());
        let probed = methods::run("hard-sv", &frame).unwrap();
        assert_eq!(bits(&plain), bits(&probed), "({x}, {y})");
        assert_eq!(plain.stats.totals, probed.stats.totals, "({x}, {y})");
        let events = probe.events();
        assert_eq!(check_chains(&events), Ok(()), "({x}, {y})");
        events
            .iter()
            .filter(|e| e.note == penumbra::gpu::hiz::HIZ_CULLED)
            .count()
    };
    let mut more = 0;
    for y in (2..64).step_by(6) {
        for x in (1..64).step_by(6) {
            let (fine, coarse) = (culled_notes(4, x, y), culled_notes(32, x, y));
            assert!(fine >= coarse, "({x}, {y}): {fine} < {coarse}");
            more += (fine > coarse) as u32;
        }
    }
    assert!(more > 0, "no pixel shows a rejection inside a raster tile");
}
