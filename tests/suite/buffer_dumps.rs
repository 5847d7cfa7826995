//! Buffer dumps (`--dump-buffers`, issue 14 item 2; `docs/buffer-dumps.md`): every method's
//! dumps decode back to the values its resolve read — resolving the dumped raw values with the
//! method's own rule gives its visibility bit for bit — its event maps agree with the
//! counters the renderer keeps (`overflow_events`) and with `clamped_pixels`, asking for dumps
//! changes no visibility bit and no counter, and the files decode back to the dumps.

use penumbra::frame::BACKGROUND;
use penumbra::gpu::li_buffer::li_visibility;
use penumbra::gpu::pack4ub::FloatTarget;
use penumbra::gpu::split_blend::SplitVTile;
use penumbra::gpu::vbuffer::{VBuffer8Tile, VBufferTile};
use penumbra::methods::dump::{BufferDump, DumpValues, ElementFormat, EventKind};
use penumbra::methods::output::MethodOutput;
use penumbra::methods::wedge_blending::vbuffer::{Packed8, VBufferStorage};
use penumbra::methods::Falloff;
use penumbra::render::{render_scene_dumping, MethodRun};
use penumbra::scene::{file, OptionValue, Scene};
use penumbra::visibility::Visibility;

/// `name` (built-in or file) at `width` (aspect kept) with `methods` and `opts`
/// (`METHOD.KEY=VALUE`).
fn scene(name: &str, width: u32, methods: &[&str], opts: &[&str]) -> Scene {
    let mut s = file::resolve(name).unwrap();
    s.resize(Some(width), None);
    s.methods = Some(methods.iter().map(|m| m.to_string()).collect());
    for o in opts {
        let (lhs, v) = o.split_once('=').unwrap();
        let (m, k) = lhs.split_once('.').unwrap();
        s.options
            .entry(m.into())
            .or_default()
            .insert(k.into(), OptionValue::parse_cli(v));
    }
    s
}

fn render(s: &Scene, dump: bool) -> Vec<MethodRun> {
    render_scene_dumping(s, dump, |_| {}).unwrap()
}

fn output<'a>(runs: &'a [MethodRun], method: &str) -> &'a MethodOutput {
    &runs.iter().find(|r| r.method == method).unwrap().output
}

fn dump<'a>(out: &'a MethodOutput, name: &str) -> &'a BufferDump {
    out.dumps
        .iter()
        .find(|d| d.name == name)
        .unwrap_or_else(|| panic!("no dump {name}"))
}

fn gray(v: &Visibility) -> &[f32] {
    match v {
        Visibility::Gray(v) => v,
        Visibility::Rgb(_) => panic!("expected gray"),
    }
}

/// Row-major: whether each pixel shows geometry (the resolve runs there; background is 1).
fn receivers(s: &Scene) -> Vec<bool> {
    let frame =
        penumbra::frame::Frame::render(s, penumbra::render::gpu_settings(s).unwrap()).unwrap();
    frame.prim_ids().iter().map(|&p| p != BACKGROUND).collect()
}

/// Asserts `visibility` equals `resolve(i)` bit for bit at every receiver pixel and is 1
/// elsewhere.
fn assert_resolves(label: &str, s: &Scene, vis: &[f32], resolve: impl Fn(usize) -> f32) {
    for (i, r) in receivers(s).into_iter().enumerate() {
        let want = if r { resolve(i) } else { 1.0 };
        assert_eq!(
            vis[i].to_bits(),
            want.to_bits(),
            "{label}: pixel {i}: visibility {} but the dump resolves to {want}",
            vis[i]
        );
    }
}

/// The total overflow events of every kind in a dump's event map.
fn events(d: &BufferDump) -> u64 {
    d.events
        .as_ref()
        .unwrap()
        .totals()
        .iter()
        .map(|(_, n)| n)
        .sum()
}

fn clamps(d: &BufferDump) -> u64 {
    d.events.as_ref().unwrap().clamped_pixels()
}

fn u8s(d: &BufferDump) -> &[u8] {
    match &d.values {
        DumpValues::U8(v) => v,
        other => panic!("{}: expected u8, got {:?}", d.name, other.storage()),
    }
}

#[test]
fn asking_for_dumps_changes_no_visibility_bit_and_no_counter() {
    for name in ["cube-of-spheres", "cube-of-spheres-sphere", "disk-block"] {
        let mut s = scene(name, 40, &[], &["nsample.n=16", "raycast.samples=64"]);
        let methods: Vec<String> = penumbra::methods::names()
            .filter(|m| penumbra::methods::supports_scene(m, &s))
            .map(|m| m.to_string())
            .collect();
        s.methods = Some(methods);
        let (plain, dumped) = (render(&s, false), render(&s, true));
        for (a, b) in plain.iter().zip(&dumped) {
            let m = a.method.as_str();
            let bits = |v: &Visibility| {
                (0..v.len())
                    .map(|i| v.rgb(i).map(f32::to_bits))
                    .collect::<Vec<_>>()
            };
            assert_eq!(
                bits(&a.output.visibility),
                bits(&b.output.visibility),
                "{name} {m}"
            );
            assert_eq!(a.output.stats.totals, b.output.stats.totals, "{name} {m}");
            assert_eq!(
                a.output.stats.clamped_pixels, b.output.stats.clamped_pixels,
                "{name} {m}"
            );
            // A normal run keeps the dumps of its ordinary outputs only, without events.
            let kept: Vec<&str> = a.output.dumps.iter().map(|d| d.name.as_str()).collect();
            let expected: &[&str] = match m {
                "hard-sv" => &["stencil"],
                "wedge-blending" => &["penumbrae"],
                _ => &[],
            };
            assert_eq!(kept, expected, "{name} {m}");
            assert!(
                a.output.dumps.iter().all(|d| d.events.is_none()),
                "{name} {m}"
            );
            // With dumps every emulated-GPU method hands back at least one, raycast none.
            assert_eq!(b.output.dumps.is_empty(), m == "raycast", "{name} {m}");
            for d in &b.output.dumps {
                assert_eq!(
                    d.values.len(),
                    d.pixels() * d.format.channels() as usize,
                    "{name} {m} {}",
                    d.name
                );
            }
        }
    }
}

#[test]
fn hard_sv_stencil_is_zero_exactly_where_lit_and_its_events_are_the_counters() {
    // 256 stacked plates: the 8-bit stencil wraps (or saturates) at every receiver under them.
    for (mode, kind) in [("wrap", EventKind::Wrap), ("saturate", EventKind::Saturate)] {
        let opt = format!("hard-sv.stencil={mode}");
        let s = scene("scenes/hard/stack-256-rect.toml", 64, &["hard-sv"], &[&opt]);
        let runs = render(&s, true);
        let out = output(&runs, "hard-sv");
        let d = dump(out, "stencil");
        assert_eq!(d.format, ElementFormat::Stencil8);
        let st = u8s(d);
        assert_resolves(mode, &s, gray(&out.visibility), |i| {
            (st[i] == 0) as u8 as f32
        });
        let ev = d.events.as_ref().unwrap();
        assert_eq!(ev.overflows[0].0, kind);
        assert!(events(d) > 0, "{mode}: 256 volumes overflow 8 bits");
        assert_eq!(events(d), out.stats.totals.overflow_events, "{mode}");
    }
}

#[test]
fn li_buffer_resolves_to_the_visibility_bit_for_bit() {
    for (method, opts) in [
        ("pw2002", vec!["pw2002.li=16"]),
        ("pw2002", vec!["pw2002.li=8"]),
        ("pw2002", vec!["pw2002.li=12", "pw2002.overflow=saturate"]),
        ("pw-restructured", vec![]),
        ("pw-restructured", vec!["pw-restructured.li=8"]),
    ] {
        let s = scene("cube-of-spheres-sphere", 64, &[method], &opts);
        let runs = render(&s, true);
        let out = output(&runs, method);
        let d = dump(out, "li");
        let li: Vec<i32> = match &d.values {
            DumpValues::I16(v) => v.iter().map(|&x| x.into()).collect(),
            DumpValues::U8(v) => v.iter().map(|&x| x.into()).collect(),
            v => panic!("LI stored as {:?}", v.storage()),
        };
        let label = format!("{method} {opts:?}");
        assert_resolves(&label, &s, gray(&out.visibility), |i| li_visibility(li[i]));
        assert_eq!(clamps(d), out.stats.clamped_pixels, "{label}");
        // The LI adds are the only overflows of these passes.
        assert_eq!(events(d), out.stats.totals.overflow_events, "{label}");
        if opts.contains(&"pw2002.li=8") || opts.contains(&"pw-restructured.li=8") {
            // An 8-bit LI buffer cleared to 255 cannot hold one umbra entry of −255 and the
            // +255 that leaves it: every umbra pixel overflows.
            assert!(events(d) > 0, "{label}");
        }
    }
}

#[test]
fn vbuffers_resolve_to_the_visibility_bit_for_bit() {
    for vbuffer in ["f32", "f16", "8bit"] {
        let opt = format!("ssv.vbuffer={vbuffer}");
        let s = scene("cube-of-spheres", 64, &["ssv"], &[&opt]);
        let runs = render(&s, true);
        let out = output(&runs, "ssv");
        let vis = gray(&out.visibility);
        let d = dump(out, "vbuffer");
        let resolve: Box<dyn Fn(usize) -> f32> = match &d.values {
            DumpValues::F32(v) => Box::new(move |i| v[i].clamp(0.0, 1.0)),
            DumpValues::F16(v) => Box::new(move |i| v[i].to_f32().clamp(0.0, 1.0)),
            DumpValues::U8(rg) => {
                let st = u8s(dump(out, "stencil"));
                let tile = VBuffer8Tile {
                    add: rg.iter().step_by(2).copied().collect(),
                    sub: rg.iter().skip(1).step_by(2).copied().collect(),
                    overflows: Vec::new(),
                };
                Box::new(move |i| (tile.resolve(i)[0] + (1.0 - st[i] as f32)).clamp(0.0, 1.0))
            }
            v => panic!("V-buffer stored as {:?}", v.storage()),
        };
        assert_resolves(vbuffer, &s, vis, resolve);
        let d = dump(out, "vbuffer");
        assert_eq!(clamps(d), out.stats.clamped_pixels, "{vbuffer}");
        let stencil_events = out
            .dumps
            .iter()
            .find(|d| d.name == "stencil")
            .map_or(0, events);
        assert_eq!(
            events(d) + stencil_events,
            out.stats.totals.overflow_events,
            "{vbuffer}"
        );
    }
}

#[test]
fn split_buffers_resolve_to_the_visibility_bit_for_bit() {
    for bits in ["5", "2", "1"] {
        let opt = format!("ssv-optimized.reserved-bits={bits}");
        let s = scene("cube-of-spheres", 64, &["ssv-optimized"], &[&opt]);
        let runs = render(&s, true);
        let out = output(&runs, "ssv-optimized");
        let (add, sub) = (dump(out, "vbuffer-add"), dump(out, "vbuffer-sub"));
        let ElementFormat::SplitRgba8(format) = add.format else {
            panic!("{:?}", add.format)
        };
        assert_eq!(format.reserved_bits.to_string(), bits);
        let px = |d: &BufferDump| -> Vec<[u8; 4]> {
            u8s(d)
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect()
        };
        let tile = SplitVTile {
            add: px(add),
            sub: px(sub),
            saturations: [Vec::new(), Vec::new()],
        };
        assert_resolves(bits, &s, gray(&out.visibility), |i| {
            tile.resolve(format, i).clamp(0.0, 1.0) as f32
        });
        assert_eq!(
            clamps(add),
            out.stats.clamped_pixels,
            "reserved bits {bits}"
        );
        assert_eq!(
            clamps(sub),
            out.stats.clamped_pixels,
            "reserved bits {bits}"
        );
        // The saturating blends are the method's only overflow events.
        assert_eq!(
            events(add) + events(sub),
            out.stats.totals.overflow_events,
            "reserved bits {bits}"
        );
        if bits == "1" {
            // 7 value bits per channel hold ⌊255/127⌋ = 2 full values: the 27 spheres'
            // overlapping quads saturate.
            assert!(events(add) + events(sub) > 0);
        }
    }
}

#[test]
fn wedge_blending_final_vbuffer_resolves_to_the_visibility_bit_for_bit() {
    for packing in ["8bit", "f32"] {
        let opt = format!("wedge-blending.packing={packing}");
        let s = scene("cube-of-spheres", 64, &["wedge-blending"], &[&opt]);
        let runs = render(&s, true);
        let out = output(&runs, "wedge-blending");
        let vis = gray(&out.visibility);
        let occlusion: Vec<f32> = if packing == "8bit" {
            let words = |name| match &dump(out, name).values {
                DumpValues::U32(v) => v.clone(),
                v => panic!("{name} stored as {:?}", v.storage()),
            };
            let (rects, occ) = (words("final-rects"), words("final-occlusion"));
            let storage = Packed8 {
                target: FloatTarget::Raw,
                centroid: false,
            };
            (0..vis.len())
                .map(|i| {
                    let mut px = [0u32; 8];
                    px[..4].copy_from_slice(&rects[4 * i..4 * i + 4]);
                    px[4..].copy_from_slice(&occ[4 * i..4 * i + 4]);
                    storage.load(&px).iter().map(|p| p.occlusion).sum::<f32>()
                })
                .collect()
        } else {
            let DumpValues::F32(v) = &dump(out, "final-parts").values else {
                panic!("parts stored as f32")
            };
            v.chunks_exact(20)
                .map(|p| (0..4).map(|k| p[5 * k]).sum::<f32>())
                .collect()
        };
        // The resolve: the four parts are equal quarters of the light.
        assert_resolves(packing, &s, vis, |i| {
            (1.0 - occlusion[i] * 0.25).clamp(0.0, 1.0)
        });
        let last = out
            .dumps
            .iter()
            .rev()
            .find(|d| d.name.starts_with("final-"))
            .unwrap();
        assert_eq!(clamps(last), out.stats.clamped_pixels, "{packing}");
        // The stencil sum: every silhouette's count is at most the 27 spheres; the per-loop
        // stencil passes wrap transiently (a decrement before its increment) and those wraps
        // are the method's only overflow events.
        let sums = match &dump(out, "stencil-sum").values {
            DumpValues::I32(v) => v.clone(),
            v => panic!("stencil sum stored as {:?}", v.storage()),
        };
        assert_eq!(
            events(dump(out, "stencil-sum")),
            out.stats.totals.overflow_events,
            "{packing}"
        );
        assert!(sums.iter().all(|&c| (0..=27).contains(&c)), "{packing}");
        assert!(
            sums.iter().zip(vis).any(|(&c, &v)| c > 0 && v == 0.0),
            "{packing}: an umbra has a positive hard count"
        );
    }
}

#[test]
fn dbuffer_t_resolves_to_the_visibility_and_its_clamps_are_the_clamped_pixels() {
    for eq3 in ["corrected", "printed"] {
        let opt = format!("dbuffer.eq3={eq3}");
        let s = scene(
            "disk-block",
            64,
            &["dbuffer"],
            &[&opt, "dbuffer.map-size=48"],
        );
        let runs = render(&s, true);
        let out = output(&runs, "dbuffer");
        let vis = gray(&out.visibility);
        let t = dump(out, "t");
        let DumpValues::F64(tv) = &t.values else {
            panic!("t stored as f64")
        };
        let with_t = tv.iter().filter(|t| t.is_finite()).count();
        assert!(with_t > 50, "{eq3}: a penumbra");
        for (i, t) in tv.iter().enumerate().filter(|(_, t)| t.is_finite()) {
            let v = Falloff::Smoothstep.apply(t.clamp(0.0, 1.0)) as f32;
            assert_eq!(vis[i].to_bits(), v.to_bits(), "{eq3}: pixel {i}, t {t}");
        }
        assert_eq!(clamps(t), out.stats.clamped_pixels, "{eq3}");
        if eq3 == "printed" {
            // The printed eq. 3 leaves [0, 1] next to c's hard-shadow line (module doc).
            assert!(clamps(t) > 0);
        }
        let d = dump(out, "dbuffer");
        assert_eq!((d.width, d.height), (48, 48), "the map has its own size");
        assert_eq!(d.format.channels(), 4);
        assert_eq!(events(d), out.stats.totals.overflow_events);
    }
}

#[test]
fn penumbra_map_dumps_have_the_map_size_and_its_events_are_the_counters() {
    let s = scene(
        "cube-of-spheres-sphere",
        64,
        &["penumbra-map"],
        &["penumbra-map.map-size=40"],
    );
    let runs = render(&s, true);
    let out = output(&runs, "penumbra-map");
    let (sm, pm) = (dump(out, "shadow-map"), dump(out, "penumbra-map"));
    assert_eq!((sm.width, sm.height, pm.width, pm.height), (40, 40, 40, 40));
    assert!(matches!(sm.format, ElementFormat::Depth(_)));
    // D24 values: every texel is a 24-bit unorm, some covered by the scene (< 1.0).
    let DumpValues::U32(depth) = &sm.values else {
        panic!("D24 stored as u32")
    };
    assert!(depth.iter().all(|&z| z <= 0xFF_FFFF));
    assert!(depth.iter().any(|&z| z < 0xFF_FFFF));
    // The penumbra map: intensities in [0, 1], some strictly inside (a penumbra).
    let i: Vec<f64> = (0..pm.pixels()).map(|k| pm.values.get(k)).collect();
    assert!(i.iter().all(|v| (0.0..=255.0).contains(v)));
    assert!(i.iter().any(|&v| v > 0.0 && v < 255.0));
    assert_eq!(events(pm), out.stats.totals.overflow_events);
}

#[test]
fn nsample_accumulator_rounds_to_the_visibility() {
    let s = scene("cube-of-spheres", 48, &["nsample"], &["nsample.n=16"]);
    let runs = render(&s, true);
    let out = output(&runs, "nsample");
    let d = dump(out, "accumulator");
    let DumpValues::F64(sums) = &d.values else {
        panic!("accumulator stored as f64")
    };
    assert_resolves("nsample", &s, gray(&out.visibility), |i| {
        sums[i].clamp(0.0, 1.0) as f32
    });
    assert_eq!(events(d), out.stats.totals.overflow_events);
}

#[test]
fn several_lights_dump_each_light_or_the_shared_li_buffer() {
    let s = scene("two-lights", 48, &["hard-sv", "pw2002"], &[]);
    let runs = render(&s, true);
    let names = |m| -> Vec<String> {
        output(&runs, m)
            .dumps
            .iter()
            .map(|d| d.name.clone())
            .collect()
    };
    assert_eq!(names("hard-sv"), ["stencil-light0", "stencil-light1"]);
    // Paper I §7: both lights in one LI buffer.
    assert_eq!(names("pw2002"), ["li"]);
    let out = output(&runs, "hard-sv");
    let total: u64 = out.dumps.iter().map(events).sum();
    assert_eq!(total, out.stats.totals.overflow_events);
}

#[test]
fn written_files_decode_back_to_the_dumps() {
    let s = scene(
        "cube-of-spheres-sphere",
        40,
        &["hard-sv", "pw2002", "ssv", "penumbra-map"],
        &["ssv.vbuffer=f16"],
    );
    let runs = render(&s, true);
    let dir = std::env::temp_dir().join(format!("penumbra-dumps-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let files = penumbra::render::write_runs(&dir, &s, &runs, true).unwrap();
    for (run, written) in runs.iter().zip(&files) {
        for d in &run.output.dumps {
            let m = dir.join(&run.method);
            let meta: serde_json::Value =
                serde_json::from_slice(&std::fs::read(m.join(format!("{}.json", d.name))).unwrap())
                    .unwrap();
            let raw = meta["raw"].as_str().unwrap();
            assert!(written.iter().any(|f| f == raw));
            let bytes = std::fs::read(m.join(raw)).unwrap();
            let decoded = if raw.ends_with(".png") {
                let (w, h, v) = penumbra::output::decode_gray8_png(&bytes).unwrap();
                assert_eq!((w, h), (d.width, d.height));
                v
            } else {
                bytes
            };
            // Shape and dtype as the sidecar says; the bytes are the values, little-endian.
            let shape: Vec<u64> = meta["shape"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_u64().unwrap())
                .collect();
            let size: u64 = meta["dtype"].as_str().unwrap()[2..].parse().unwrap();
            assert_eq!(shape.iter().product::<u64>() * size, decoded.len() as u64);
            assert_eq!(decoded, d.values.le_bytes(), "{} {}", run.method, d.name);
            for f in ["view", "events"] {
                if let Some(view) = meta[f].as_str().or(meta[f]["view"].as_str()) {
                    let img = image::open(m.join(view)).unwrap();
                    assert!(img.width() >= d.width && img.height() > d.height);
                }
            }
            let has_events = d.events.is_some();
            assert_eq!(meta["events"].is_object(), has_events, "{}", d.name);
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
