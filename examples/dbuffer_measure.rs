//! `dbuffer` (CGI 2004) measured against `raycast` on the disk-light built-ins, and its cost
//! per pass at the paper's resolutions (Table 1: 300², 600², 1k²).
//!
//! ```sh
//! cargo run --release --example dbuffer_measure [SIZE] > docs/dbuffer-measurements.txt
//! ```
//!
//! 1. Error vs `raycast` (1024 samples) at SIZE² (default 256) on every disk built-in:
//!    `dbuffer` with its defaults and each variant (`falloff = sqrt`, `eq3 = printed`,
//!    `distances = exact`, `storage = f16`), `hard-sv`, and — with the disk replaced by a
//!    sphere of the same radius, the only light they take — `pw2002`, `ssv` and
//!    `penumbra-map`.
//! 2. The boundary-classification table on every scene: the fraction of
//!    receiver pixels each method puts in the umbra (v = 0), the penumbra and the lit region
//!    (v = 1), up to [`CLASS_TOLERANCE`], the fraction classified as `raycast` classifies them,
//!    and the fractions that swap lit and penumbra (the outer boundary) and umbra and penumbra
//!    (the inner one) — over every receiver pixel and over the floor's alone (the occluders'
//!    own faces carry the self-shadowing artifacts).
//! 3. Time per pass of `dbuffer` (median of 5 runs, all threads) on `disk-small-sphere`
//!    (224-triangle occluder), `disk-block` and `disk-torus` (5760) at 300², 600² and 1024²,
//!    with the D-buffer's fragment and byte counts.
//!
//! Times are informational (wall clock on a shared machine); errors, classes and counters are
//! deterministic.

use penumbra::frame::{Frame, GpuSettings};
use penumbra::methods::dbuffer;
use penumbra::metrics::{compare, ClassTable, ShadowClass};
use penumbra::scene::{builtin, LightShape, OptionValue, Scene};
use penumbra::visibility::Visibility;

/// The tolerance of the shadow classes: visibility 0 and 1 up to f32 rounding — each method's
/// own classification (pw2002's LI is k/255, dbuffer's V is 0 or 1 exactly outside its
/// penumbra region), and `raycast`'s up to its sampling (a point that sees less than about one
/// of its 1024 samples' strata is umbra to it).
const CLASS_TOLERANCE: f64 = 1e-6;

/// The disk-light built-ins.
const SCENES: [&str; 5] = [
    "disk-block",
    "disk-slab",
    "disk-small-sphere",
    "disk-acute",
    "disk-torus",
];

/// The `dbuffer` variants measured: a label and the options that differ from the defaults.
const VARIANTS: [(&str, &[(&str, &str)]); 5] = [
    ("dbuffer", &[]),
    ("dbuffer falloff=sqrt", &[("falloff", "sqrt")]),
    ("dbuffer eq3=printed", &[("eq3", "printed")]),
    ("dbuffer distances=exact", &[("distances", "exact")]),
    ("dbuffer storage=f16", &[("storage", "f16")]),
];

fn sized(name: &str, size: u32) -> Scene {
    let mut s = builtin::load(name).expect("built-in scene");
    s.width = size;
    s.height = size;
    s
}

fn run(scene: &Scene, method: &str) -> Visibility {
    let frame = Frame::render(scene, GpuSettings::default()).expect("frame");
    penumbra::methods::run(method, &frame)
        .expect("method")
        .visibility
}

fn with_options(scene: &Scene, options: &[(&str, &str)]) -> Scene {
    let mut s = scene.clone();
    let table = s.options.entry("dbuffer".into()).or_default();
    for (k, v) in options {
        table.insert(k.to_string(), OptionValue::Str(v.to_string()));
    }
    s
}

fn as_sphere(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    if let LightShape::Disk { radius, .. } = s.lights[0].shape {
        s.lights[0].shape = LightShape::Sphere { radius };
    }
    s
}

/// Every method's visibility on `name`: label and buffer, `raycast` first.
fn results(name: &str, size: u32) -> Vec<(String, Visibility)> {
    let scene = sized(name, size);
    let mut out = vec![("raycast".to_string(), run(&scene, "raycast"))];
    for (label, options) in VARIANTS {
        out.push((label.into(), run(&with_options(&scene, options), "dbuffer")));
    }
    out.push(("hard-sv".into(), run(&scene, "hard-sv")));
    let sphere = as_sphere(&scene);
    for m in ["pw2002", "ssv", "penumbra-map"] {
        out.push((format!("{m} (sphere)"), run(&sphere, m)));
    }
    out
}

fn main() {
    let size: u32 = std::env::args()
        .nth(1)
        .map(|s| s.parse().expect("SIZE"))
        .unwrap_or(256);
    println!("# dbuffer (CGI 2004) vs raycast (1024 samples), {size}x{size}\n");
    for name in SCENES {
        let res = results(name, size);
        let frame_scene = sized(name, size);
        let frame = Frame::render(&frame_scene, GpuSettings::default()).expect("frame");
        let receiver = |i: usize| frame.prim_ids()[i] != penumbra::frame::BACKGROUND;
        let floor = |i: usize| receiver(i) && frame.prim_owner[frame.prim_ids()[i] as usize].0 == 0;
        println!("## {name}\n");
        println!(
            "| method | RMSE | mean abs | % > 1/255 | umbra | penumbra | lit | same class as raycast | lit↔penumbra | umbra↔penumbra | floor: same class | floor: lit↔penumbra | floor: umbra↔penumbra |"
        );
        println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
        let reference = &res[0].1;
        for (label, v) in &res {
            let e = compare(v, reference);
            let t = ClassTable::of(reference, v, CLASS_TOLERANCE, receiver);
            let n = t.pixels() as f64;
            let frac = |c| t.total(c, false) as f64 / n;
            let swap = |t: &ClassTable, a: usize, b: usize| {
                (t.counts[a][b] + t.counts[b][a]) as f64 / t.pixels() as f64
            };
            let f = ClassTable::of(reference, v, CLASS_TOLERANCE, floor);
            println!(
                "| {label} | {:.4} | {:.4} | {:.2} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} |",
                e.rmse,
                e.mean_abs,
                e.pct_over_1_255,
                frac(ShadowClass::Umbra),
                frac(ShadowClass::Penumbra),
                frac(ShadowClass::Lit),
                t.agreement(),
                swap(&t, 1, 2),
                swap(&t, 0, 1),
                f.agreement(),
                swap(&f, 1, 2),
                swap(&f, 0, 1)
            );
        }
        println!();
    }
    println!("# dbuffer time per pass (median of 5 runs, seconds) and D-buffer traffic\n");
    println!("| scene | triangles | size | volumes | dbuffer-scene | dbuffer-umbra | dbuffer-penumbra | screen | D-buffer fragments | D-buffer MB written |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for name in ["disk-small-sphere", "disk-block", "disk-torus"] {
        for size in [300, 600, 1024] {
            let scene = sized(name, size);
            let triangles: usize = scene.meshes.iter().map(|m| m.triangles.len()).sum();
            let frame = Frame::render(&scene, GpuSettings::default()).expect("frame");
            let s = dbuffer::read_settings(&frame).expect("settings");
            let mut times: Vec<Vec<f64>> = vec![Vec::new(); 5];
            let mut last = None;
            for _ in 0..5 {
                let r = dbuffer::render(&frame, &s).expect("dbuffer");
                for (k, p) in r.passes.iter().enumerate() {
                    times[k].push(p.wall_seconds);
                }
                last = Some(r);
            }
            let r = last.expect("five runs");
            let median = |v: &mut Vec<f64>| {
                v.sort_by(f64::total_cmp);
                v[v.len() / 2]
            };
            let med: Vec<f64> = times.iter_mut().map(median).collect();
            let draws = &r.passes[1..4];
            let fragments: u64 = draws.iter().map(|p| p.counters.fragments_rasterized).sum();
            let written: u64 = draws
                .iter()
                .map(|p| p.counters.color_write_bytes + p.counters.depth_write_bytes)
                .sum();
            println!(
                "| {name} | {triangles} | {size}² | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {fragments} | {:.2} |",
                med[0],
                med[1],
                med[2],
                med[3],
                med[4],
                written as f64 / 1e6
            );
        }
    }
}
