//! `experiment cost-growth` (issue 32, item 3; `docs/performance.md` "How cost grows"): every
//! method's time and peak memory against the occluder's triangle count and against the image
//! size, and the memory estimate ([`crate::memory`]) against the measured peak at every point,
//! since a render above `--max-memory` is refused on that estimate and it must not
//! under-estimate.
//!
//! The workloads:
//! - **bumpy spheres** ([`bumpy_sphere`]): closed, star-shaped, with a bump every 30° in both
//!   angles, so that every bump has its own silhouette loop and the silhouettes grow with the
//!   triangle count, as on a scanned mesh (a smooth sphere's silhouette grows only with the
//!   square root of it); one per target count of `--triangles`;
//! - **the user's meshes** (`--mesh FILE`, any format a scene can read), scaled and moved to
//!   the same place.
//!
//! Each stands on a floor under a light of the first shape the method renders of rectangle,
//! sphere and disk (the same size and place for all three), and is rendered at the base size
//! (`--size`) and, for the first workload, at every size of `--sizes`. Every point is one
//! `penumbra render` process per run, one method, `--threads` threads: its time is the sum of
//! the method's passes (`stats.json`), its peak the process's own high-water mark and its
//! estimate what the render was checked against, both from the render's `memory.json`
//! ([`crate::memory::MemoryRecord`]). A separate process per point is what makes the peak the
//! point's own.
//!
//! The outputs: `cost-growth.csv`, `cost-growth.json`, `summary.md` (tables of time and peak
//! per method against triangles and against pixels, the growth exponent between the smallest
//! and the largest point, and every point where the peak exceeded the estimate), and log–log
//! plots `cost-triangles`, `cost-pixels` and `memory-estimate` (`.png` and `.svg`).

use crate::error::InputError;
use crate::experiment::plotting::{chart_on, draw_legend, png_and_svg, Plot, PALETTE};
use crate::experiment::spread;
use crate::memory::{fmt_bytes, MemoryRecord, RECORD_FILE};
use crate::methods;
use crate::scene::mesh_io::read_mesh;
use crate::scene::procedural::{box_mesh, bumpy_sphere};
use crate::scene::{LightShape, Mesh};
use glam::Vec3;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// Where the experiment writes by default.
pub const DEFAULT_OUT: &str = "out/cost-growth";
/// The CSV file: one line per point.
pub const CSV_FILE: &str = "cost-growth.csv";
/// The JSON file: the plan and every point.
pub const JSON_FILE: &str = "cost-growth.json";
/// The tables and findings.
pub const SUMMARY_FILE: &str = "summary.md";
/// The plots' file stems (each written as `.png` and `.svg`).
pub const PLOTS: [&str; 3] = ["cost-triangles", "cost-pixels", "memory-estimate"];

/// The default target triangle counts of the bumpy spheres (issue 32: 20 k → 330 k → 1.3 M).
pub const DEFAULT_TRIANGLES: [u32; 3] = [20_000, 330_000, 1_300_000];
/// The default image sides of the size series (issue 32: 256² → 2048²).
pub const DEFAULT_SIZES: [u32; 4] = [256, 512, 1024, 2048];
/// The default image side of the triangle series.
pub const DEFAULT_SIZE: u32 = 512;

/// Bumps per half turn of the bumpy spheres (a bump every 30°).
const BUMPS: u32 = 6;
/// The bumps' height, relative to the radius.
const BUMP_AMPLITUDE: f64 = 0.12;

/// What to measure.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Plan {
    /// The bumpy spheres' target triangle counts.
    pub triangles: Vec<u32>,
    /// The user's meshes.
    pub meshes: Vec<PathBuf>,
    /// The image side of the triangle series.
    pub size: u32,
    /// The image sides of the size series (on the first workload).
    pub sizes: Vec<u32>,
    /// The methods (default: all).
    pub methods: Vec<String>,
    /// Processes per point (the time is their median, the peak their largest).
    pub runs: usize,
    /// `--threads` of each render.
    pub threads: usize,
    /// `--opt METHOD.KEY=VALUE` of each render (a method's keys reach only its renders).
    pub opts: Vec<String>,
}

/// One measured point: a method on a workload at one image size.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Point {
    /// The workload's name (`bumpy-TRIANGLES`, or the mesh file's stem).
    pub workload: String,
    /// Whether the workload is a generated bumpy sphere (else a user's mesh).
    pub bumpy: bool,
    /// The occluder's triangles as rendered (after repairs).
    pub triangles: usize,
    /// What the repairs made of the occluder (`stats.json`'s `meshes[].became`).
    pub became: String,
    /// Image side (square images).
    pub size: u32,
    /// The method.
    pub method: String,
    /// The light's shape (`rect`, `sphere`, `disk`).
    pub light: &'static str,
    /// Median, min and max over the runs of the method's passes, seconds.
    pub seconds: [f64; 3],
    /// Median over the runs of the whole process (loading, rendering, writing), seconds.
    pub process_seconds: f64,
    /// The largest peak resident memory of the runs, bytes; `None` where it cannot be read.
    pub peak_bytes: Option<u64>,
    /// The memory estimate the render was checked against, bytes.
    pub estimate_bytes: u64,
}

impl Point {
    /// Whether the measured peak exceeded the estimate.
    pub fn under_estimated(&self) -> bool {
        self.peak_bytes.is_some_and(|p| p > self.estimate_bytes)
    }
}

/// The light shapes tried for a method, in order, with their names.
fn light_shapes() -> [(&'static str, LightShape); 3] {
    [
        (
            "rect",
            LightShape::Rect {
                u: Vec3::new(0.35, 0.0, 0.0),
                v: Vec3::new(0.0, 0.0, 0.35),
            },
        ),
        ("sphere", LightShape::Sphere { radius: 0.35 }),
        (
            "disk",
            LightShape::Disk {
                radius: 0.35,
                normal: Vec3::NEG_Y,
            },
        ),
    ]
}

/// The light's center, for every shape.
const LIGHT_CENTER: [f32; 3] = [0.8, 4.2, 0.6];

/// The `[light]` table of light shape `name` ([`light_shapes`]) in a scene file.
fn light_toml(name: &str) -> String {
    let [x, y, z] = LIGHT_CENTER;
    let shape = light_shapes()
        .into_iter()
        .find(|(n, _)| *n == name)
        .map(|(_, s)| s);
    let fields = match shape {
        Some(LightShape::Rect { u, v }) => {
            format!(
                "type = \"rect\"\nu = [{}, {}, {}]\nv = [{}, {}, {}]",
                u.x, u.y, u.z, v.x, v.y, v.z
            )
        }
        Some(LightShape::Sphere { radius }) => format!("type = \"sphere\"\nradius = {radius}"),
        Some(LightShape::Disk { radius, normal }) => format!(
            "type = \"disk\"\nradius = {radius}\nnormal = [{}, {}, {}]",
            normal.x, normal.y, normal.z
        ),
        _ => unreachable!("light_shapes has rect, sphere and disk"),
    };
    format!("{fields}\ncenter = [{x}, {y}, {z}]\n")
}

/// The first light shape `method` renders, or an error naming the method.
fn light_for(method: &str) -> Result<&'static str, InputError> {
    let m = methods::find(method).ok_or_else(|| {
        InputError::at(
            "--methods",
            method,
            format!(
                "unknown method; expected one of {}",
                methods::names().collect::<Vec<_>>().join(", ")
            ),
        )
    })?;
    light_shapes()
        .into_iter()
        .find(|(_, shape)| (m.supports)(shape))
        .map(|(name, _)| name)
        .ok_or_else(|| {
            InputError::at(
                "--methods",
                method,
                "renders none of rect, sphere, disk lights",
            )
        })
}

/// Writes `mesh` as an OBJ file (positions and triangles; 1-based indices).
fn write_obj(mesh: &Mesh, path: &Path) -> std::io::Result<()> {
    use std::io::Write as _;
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(
        w,
        "# {} ({} triangles), written by penumbra experiment cost-growth",
        mesh.name,
        mesh.triangles.len()
    )?;
    for p in &mesh.positions {
        writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
    }
    for t in &mesh.triangles {
        writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    w.flush()
}

/// `stacks` of the bumpy sphere with about `target` triangles (slices = 2·stacks, so
/// `4·stacks·(stacks − 1)` triangles).
fn stacks_for(target: u32) -> u32 {
    ((f64::from(target) / 4.0).sqrt().round() as u32).max(3)
}

/// A scene file placing the mesh file `mesh` (scaled by `scale`, moved by `translate`) on the
/// floor `floor` under the light `light`, `size`² pixels.
fn scene_toml(mesh: &Path, floor: &Path, light: &str, placement: (f32, Vec3), size: u32) -> String {
    let (scale, t) = placement;
    let path = |p: &Path| {
        p.display()
            .to_string()
            .replace('\\', "\\\\")
            .replace('"', "\\\"")
    };
    format!(
        "# written by penumbra experiment cost-growth\nwidth = {size}\nheight = {size}\nambient = 0.1\n\n\
         [camera]\neye = [0.0, 3.4, 4.4]\ntarget = [0.0, 0.7, 0.0]\nup = [0, 1, 0]\nvfov_deg = 45\n\n\
         [light]\n{}\n\
         [[meshes]]\nobj = \"{}\"\nreceiver_only = true\n\n\
         [[meshes]]\nobj = \"{}\"\nscale = {scale}\ntranslate = [{}, {}, {}]\ncolor = [0.8, 0.75, 0.7]\n",
        light_toml(light),
        path(floor),
        path(mesh),
        t.x,
        t.y,
        t.z,
    )
}

/// A workload ready to render: its name, mesh file, placement and rendered triangle count.
struct Workload {
    name: String,
    bumpy: bool,
    mesh: PathBuf,
    placement: (f32, Vec3),
    triangles: usize,
}

/// Reads `mesh` and places it: its bounding box's largest side scaled to 1.6, centred over
/// the origin, its lowest point 0.2 above the floor. Its triangle count is the file's until a
/// render says how many it rendered (after repairs).
fn place((name, bumpy): (String, bool), mesh: PathBuf) -> Result<Workload, InputError> {
    let display = mesh.display().to_string();
    let raw = read_mesh(&mesh, &display)?;
    let (lo, hi) = raw.positions.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let side = (hi - lo).max_element();
    if !(side > 0.0 && side.is_finite()) {
        return Err(InputError::new(display, "the mesh has no extent"));
    }
    let scale = 1.6 / side;
    let centre = (lo + hi) * 0.5 * scale;
    let translate = Vec3::new(-centre.x, 0.2 - lo.y * scale, -centre.z);
    Ok(Workload {
        name,
        bumpy,
        mesh,
        placement: (scale, translate),
        triangles: raw.triangles.len(),
    })
}

/// What one render process measured.
struct Measured {
    /// The method's passes, seconds.
    seconds: f64,
    /// The whole process, seconds.
    process: f64,
    /// Its memory record.
    record: MemoryRecord,
    /// The occluder's triangles as rendered, and what its repairs made of it (`stats.json`'s
    /// `meshes`).
    occluder: (usize, String),
}

/// One render process.
fn render_once(
    (exe, plan): (&Path, &Plan),
    scene: &Path,
    method: &str,
    out: &Path,
) -> Result<Measured, InputError> {
    let _ = std::fs::remove_dir_all(out);
    let start = std::time::Instant::now();
    let threads = plan.threads.to_string();
    let prefix = format!("{method}.");
    let mut cmd = Command::new(exe);
    cmd.arg("render")
        .arg(scene)
        .args(["--methods", method, "--threads", &threads]);
    for o in plan
        .opts
        .iter()
        .filter(|o| o.starts_with(&prefix) || o.starts_with("gpu."))
    {
        cmd.args(["--opt", o]);
    }
    let output = cmd
        .arg("--out")
        .arg(out)
        .stdin(Stdio::null())
        .output()
        .map_err(|e| InputError::new(exe.display().to_string(), format!("cannot run: {e}")))?;
    let process = start.elapsed().as_secs_f64();
    if !output.status.success() {
        return Err(InputError::new(
            scene.display().to_string(),
            format!(
                "`penumbra render --methods {method}` failed ({}): {}",
                output.status,
                String::from_utf8_lossy(&output.stderr).trim()
            ),
        ));
    }
    let read = |p: PathBuf| -> Result<serde_json::Value, InputError> {
        let text = std::fs::read_to_string(&p)
            .map_err(|e| InputError::new(p.display().to_string(), e.to_string()))?;
        serde_json::from_str(&text)
            .map_err(|e| InputError::new(p.display().to_string(), e.to_string()))
    };
    let stats = read(out.join(method).join("stats.json"))?;
    let seconds = stats["passes"]
        .as_array()
        .map(|ps| ps.iter().filter_map(|p| p["wall_seconds"].as_f64()).sum())
        .unwrap_or(f64::NAN);
    let record: MemoryRecord = serde_json::from_value(read(out.join(RECORD_FILE))?)
        .map_err(|e| InputError::new(out.join(RECORD_FILE).display().to_string(), e.to_string()))?;
    let occluder =
        stats["meshes"]
            .as_array()
            .and_then(|ms| ms.get(1))
            .map_or((0, String::new()), |m| {
                let triangles = m["triangles"].as_u64().unwrap_or(0) as usize;
                (triangles, m["became"].as_str().unwrap_or("").to_string())
            });
    Ok(Measured {
        seconds,
        process,
        record,
        occluder,
    })
}

/// Runs the plan with the `penumbra` binary `exe`, writing meshes and scenes into
/// `out/work/`; `progress` is told each point before it runs. An unknown method or an option
/// for none of the methods is refused before anything is written; a mesh file that cannot be
/// read, or a render that fails, stops the run with the render's own message.
pub fn run(
    plan: &Plan,
    exe: &Path,
    out: &Path,
    mut progress: impl FnMut(&str),
) -> Result<Vec<Point>, InputError> {
    let work = out.join("work");
    let io = |p: &Path, e: std::io::Error| InputError::new(p.display().to_string(), e.to_string());
    let lights: Vec<(&String, &'static str)> = plan
        .methods
        .iter()
        .map(|m| Ok((m, light_for(m)?)))
        .collect::<Result<_, InputError>>()?;
    for o in &plan.opts {
        let target = o.split_once('.').map_or("", |(m, _)| m);
        if target != "gpu" && !plan.methods.iter().any(|m| m == target) {
            return Err(InputError::at(
                "--opt",
                o,
                "expected METHOD.KEY=VALUE for a method of --methods, or gpu.KEY=VALUE",
            ));
        }
    }
    std::fs::create_dir_all(&work).map_err(|e| io(&work, e))?;
    let floor = work.join("floor.obj");
    let floor_mesh = box_mesh(
        "floor",
        Vec3::new(-4.0, -0.1, -4.0),
        Vec3::new(4.0, 0.0, 4.0),
        [0.8; 3],
    );
    write_obj(&floor_mesh, &floor).map_err(|e| io(&floor, e))?;
    let mut workloads = Vec::new();
    for &target in &plan.triangles {
        let stacks = stacks_for(target);
        let name = format!("bumpy-{}", 4 * stacks * (stacks - 1));
        let mesh = bumpy_sphere(
            &name,
            (stacks, 2 * stacks),
            (BUMPS, BUMP_AMPLITUDE),
            [0.8; 3],
        );
        let path = work.join(format!("{name}.obj"));
        write_obj(&mesh, &path).map_err(|e| io(&path, e))?;
        drop(mesh);
        workloads.push(place((name, true), path)?);
    }
    for mesh in &plan.meshes {
        let stem = mesh
            .file_stem()
            .map_or("mesh".into(), |s| s.to_string_lossy().into_owned());
        let mesh = std::path::absolute(mesh).map_err(|e| io(mesh, e))?;
        workloads.push(place((stem, false), mesh)?);
    }
    let mut jobs: Vec<(usize, u32)> = (0..workloads.len()).map(|w| (w, plan.size)).collect();
    if !workloads.is_empty() {
        jobs.extend(
            plan.sizes
                .iter()
                .filter(|&&s| s != plan.size)
                .map(|&s| (0, s)),
        );
    }
    let mut points = Vec::new();
    for &(w, size) in &jobs {
        let wl = &workloads[w];
        for &(method, light) in &lights {
            progress(&format!("{} {}² {method}", wl.name, size));
            let scene = work.join(format!("{}-{light}-{size}.toml", wl.name));
            std::fs::write(
                &scene,
                scene_toml(&wl.mesh, &floor, light, wl.placement, size),
            )
            .map_err(|e| io(&scene, e))?;
            let dir = work.join("render");
            let mut times = Vec::new();
            let mut processes = Vec::new();
            let mut peak: Option<u64> = None;
            let mut estimate = 0;
            let mut occluder = (wl.triangles, String::new());
            for _ in 0..plan.runs.max(1) {
                let m = render_once((exe, plan), &scene, method, &dir)?;
                times.push(m.seconds);
                processes.push(m.process);
                peak = peak.max(m.record.peak_resident_bytes);
                estimate = m.record.estimate_bytes;
                occluder = m.occluder;
            }
            points.push(Point {
                workload: wl.name.clone(),
                bumpy: wl.bumpy,
                triangles: occluder.0,
                became: occluder.1,
                size,
                method: method.clone(),
                light,
                seconds: {
                    let (median, min, max) = spread(times);
                    [median, min, max]
                },
                process_seconds: spread(processes).0,
                peak_bytes: peak,
                estimate_bytes: estimate,
            });
        }
    }
    let _ = std::fs::remove_dir_all(work.join("render"));
    Ok(points)
}

/// The CSV of `points`.
pub fn csv(points: &[Point]) -> String {
    let mut s = String::from(
        "workload,triangles,size,method,light,seconds_median,seconds_min,seconds_max,process_seconds,peak_bytes,estimate_bytes\n",
    );
    for p in points {
        let peak = p.peak_bytes.map_or(String::new(), |b| b.to_string());
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{peak},{}",
            p.workload,
            p.triangles,
            p.size,
            p.method,
            p.light,
            p.seconds[0],
            p.seconds[1],
            p.seconds[2],
            p.process_seconds,
            p.estimate_bytes
        );
    }
    s
}

/// Bytes in a MiB.
const MIB: f64 = 1048576.0;

/// A point's pixels (square images).
fn pixels(p: &Point) -> f64 {
    f64::from(p.size) * f64::from(p.size)
}

/// The exponent `k` of `cost ∝ work^k` between two points (`None` for equal work or a cost
/// that is not positive).
pub fn growth_exponent((w0, c0): (f64, f64), (w1, c1): (f64, f64)) -> Option<f64> {
    (w1 != w0 && c0 > 0.0 && c1 > 0.0).then(|| libm::log(c1 / c0) / libm::log(w1 / w0))
}

/// The points of one series: the triangle series (every workload at `plan.size`, by
/// triangles) or the size series (the first workload, by pixels), per method.
fn series<'a>(plan: &Plan, points: &'a [Point], by_pixels: bool) -> Vec<(&'a str, Vec<&'a Point>)> {
    let first = points.first().map(|p| p.workload.as_str());
    plan.methods
        .iter()
        .filter_map(|m| {
            let mut ps: Vec<&Point> = points
                .iter()
                .filter(|p| &p.method == m)
                .filter(|p| {
                    if by_pixels {
                        Some(p.workload.as_str()) == first
                    } else {
                        p.size == plan.size
                    }
                })
                .collect();
            ps.sort_by_key(|p| {
                if by_pixels {
                    p.size as usize
                } else {
                    p.triangles
                }
            });
            let name = ps.first()?.method.as_str();
            Some((name, ps))
        })
        .collect()
}

/// The summary: both series as tables (time and peak per point, the growth exponent of the
/// time from the first to the last point — of the bumpy spheres, against triangles), then the
/// estimate against the peak.
pub fn summary(plan: &Plan, points: &[Point]) -> String {
    let mut s = String::from("# How cost grows with the work\n\n");
    let _ = writeln!(
        s,
        "One `penumbra render` process per point and run ({} run(s), the median time; the largest peak), {} thread(s). \
         Time: the method's passes (stats.json). Peak: the process's resident high-water mark; estimate: what `--max-memory` is checked against (memory.json).\n",
        plan.runs, plan.threads
    );
    for (by_pixels, title) in [
        (false, format!("Against triangles, {0}×{0}", plan.size)),
        (true, "Against image size".to_string()),
    ] {
        let table = series(plan, points, by_pixels);
        let Some((_, first)) = table.first() else {
            continue;
        };
        if first.len() < 2 && by_pixels {
            continue;
        }
        let _ = writeln!(s, "## {title}\n");
        let heads: Vec<String> = first
            .iter()
            .map(|p| {
                if by_pixels {
                    format!("{}²", p.size)
                } else {
                    let repaired = if p.became.is_empty() || p.became == "closed" {
                        String::new()
                    } else {
                        format!(", {}", p.became)
                    };
                    format!("{} ({} tris{repaired})", p.workload, p.triangles)
                }
            })
            .collect();
        let _ = writeln!(s, "| method | light | {} | exponent |", heads.join(" | "));
        let _ = writeln!(s, "|---|---|{}---|", "---|".repeat(heads.len()));
        for (method, ps) in &table {
            let cells: Vec<String> = ps
                .iter()
                .map(|p| {
                    let peak = p.peak_bytes.map_or("–".into(), fmt_bytes);
                    format!("{:.3} s, {peak}", p.seconds[0])
                })
                .collect();
            let work = |p: &Point| {
                if by_pixels {
                    pixels(p)
                } else {
                    p.triangles as f64
                }
            };
            // Against triangles, the exponent runs over the bumpy spheres only (one family).
            let fit: Vec<&Point> = ps
                .iter()
                .copied()
                .filter(|p| by_pixels || p.bumpy)
                .collect();
            let exponent = match (fit.first(), fit.last()) {
                (Some(a), Some(b)) => {
                    growth_exponent((work(a), a.seconds[0]), (work(b), b.seconds[0]))
                        .map_or("–".into(), |k| format!("{k:.2}"))
                }
                _ => "–".into(),
            };
            let light = ps.first().map_or("", |p| p.light);
            let _ = writeln!(
                s,
                "| {method} | {light} | {} | {exponent} |",
                cells.join(" | ")
            );
        }
        s.push('\n');
    }
    let _ = writeln!(s, "## The memory estimate against the peak\n");
    let under: Vec<&Point> = points.iter().filter(|p| p.under_estimated()).collect();
    let measured = points.iter().filter(|p| p.peak_bytes.is_some()).count();
    if measured == 0 {
        let _ = writeln!(
            s,
            "The peak could not be read on this system (no `/proc/self/status`)."
        );
    } else if under.is_empty() {
        let worst = points
            .iter()
            .filter_map(|p| Some(p.estimate_bytes as f64 / p.peak_bytes? as f64))
            .fold(f64::INFINITY, f64::min);
        let _ = writeln!(s, "The estimate is above the measured peak at all {measured} points (estimate / peak ≥ {worst:.2}).");
    } else {
        let _ = writeln!(
            s,
            "**The estimate is below the measured peak at {} of {measured} points:**\n",
            under.len()
        );
        let _ = writeln!(
            s,
            "| workload | triangles | size | method | peak | estimate |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|");
        for p in under {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} |",
                p.workload,
                p.triangles,
                p.size,
                p.method,
                p.peak_bytes.map_or("–".into(), fmt_bytes),
                fmt_bytes(p.estimate_bytes)
            );
        }
    }
    s
}

/// Writes the CSV, JSON, summary and plots into `out`.
pub fn write(plan: &Plan, points: &[Point], out: &Path) -> Result<(), InputError> {
    let io = |p: PathBuf, e: String| InputError::new(p.display().to_string(), e);
    std::fs::create_dir_all(out).map_err(|e| io(out.to_path_buf(), e.to_string()))?;
    let json = serde_json::json!({ "plan": plan, "points": points });
    let files = [
        (CSV_FILE, csv(points)),
        (
            JSON_FILE,
            serde_json::to_string_pretty(&json).unwrap_or_default() + "\n",
        ),
        (SUMMARY_FILE, summary(plan, points)),
    ];
    for (name, text) in files {
        std::fs::write(out.join(name), text).map_err(|e| io(out.join(name), e.to_string()))?;
    }
    for (k, stem) in PLOTS.iter().enumerate() {
        let plot = GrowthPlot {
            plan,
            points,
            kind: k,
        };
        let (png, svg) = png_and_svg(&plot, (900, 560)).map_err(|e| io(out.join(stem), e))?;
        for (ext, bytes) in [("png", png), ("svg", svg.into_bytes())] {
            let p = out.join(format!("{stem}.{ext}"));
            std::fs::write(&p, bytes).map_err(|e| io(p.clone(), e.to_string()))?;
        }
    }
    Ok(())
}

/// A method's points in a plot, each with whether it is a bumpy sphere.
type MethodPoints<'a> = (&'a str, Vec<((f64, f64), bool)>);

/// One of the three plots: time against triangles (0), time against pixels (1), peak against
/// estimate (2); every axis logarithmic, one colour per method.
struct GrowthPlot<'a> {
    plan: &'a Plan,
    points: &'a [Point],
    kind: usize,
}

impl Plot for GrowthPlot<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        // Per method, its points and whether each is a bumpy sphere (the line runs through
        // those; a user's mesh is a triangle marker).
        let lines: Vec<MethodPoints> = if self.kind == 2 {
            self.plan
                .methods
                .iter()
                .map(|m| {
                    let xy = self
                        .points
                        .iter()
                        .filter(|p| &p.method == m)
                        .filter_map(|p| {
                            let xy = (p.estimate_bytes as f64 / MIB, p.peak_bytes? as f64 / MIB);
                            Some((xy, p.bumpy))
                        })
                        .collect();
                    (m.as_str(), xy)
                })
                .collect()
        } else {
            series(self.plan, self.points, self.kind == 1)
                .into_iter()
                .map(|(m, ps)| {
                    let xy = ps
                        .iter()
                        .map(|p| {
                            let x = if self.kind == 1 {
                                pixels(p)
                            } else {
                                p.triangles as f64
                            };
                            ((x, p.seconds[0].max(1e-4)), p.bumpy)
                        })
                        .collect();
                    (m, xy)
                })
                .collect()
        };
        let all = lines.iter().flat_map(|(_, xy)| xy.iter().map(|&(p, _)| p));
        let (mut x0, mut x1, mut y0, mut y1) = all.fold(
            (f64::MAX, 0.0f64, f64::MAX, 0.0f64),
            |(a, b, c, d), (x, y)| (a.min(x), b.max(x), c.min(y), d.max(y)),
        );
        if self.kind == 2 {
            (x0, y0) = (x0.min(y0), x0.min(y0));
            (x1, y1) = (x1.max(y1), x1.max(y1));
        }
        if x1 <= 0.0 || y1 <= 0.0 {
            (x0, x1, y0, y1) = (1.0, 10.0, 1.0, 10.0);
        }
        let (caption, xd, yd) = match self.kind {
            0 => (
                format!("time against triangles, {0}×{0}", self.plan.size),
                "occluder triangles (log; circles: bumpy spheres, triangles: --mesh files)",
                "method time [s] (log)",
            ),
            1 => (
                "time against image size".to_string(),
                "pixels (log)",
                "method time [s] (log)",
            ),
            _ => (
                "measured peak against the estimate".to_string(),
                "estimate [MiB] (log)",
                "peak resident [MiB] (log)",
            ),
        };
        let mut chart = chart_on(root, &caption, 70)?
            .build_cartesian_2d(
                (x0 / 1.3..x1 * 1.3).log_scale(),
                (y0 / 1.3..y1 * 1.3).log_scale(),
            )
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(xd)
            .y_desc(yd)
            .x_label_formatter(&|v: &f64| crate::experiment::accuracy_time::fmt_g(*v))
            .y_label_formatter(&|v: &f64| crate::experiment::accuracy_time::fmt_g(*v))
            .draw()
            .map_err(err)?;
        if self.kind == 2 {
            let diag = [(x0 / 1.3, x0 / 1.3), (x1 * 1.3, x1 * 1.3)];
            chart
                .draw_series(LineSeries::new(diag, BLACK.stroke_width(1)))
                .map_err(err)?
                .label("peak = estimate")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], BLACK));
        }
        for (k, (method, xy)) in lines.iter().enumerate() {
            let colour = PALETTE[k % PALETTE.len()];
            let bumpy = xy.iter().filter(|(_, b)| *b).map(|&(p, _)| p);
            if self.kind != 2 {
                chart
                    .draw_series(LineSeries::new(bumpy.clone(), colour.stroke_width(2)))
                    .map_err(err)?;
            }
            let meshes = xy.iter().filter(|(_, b)| !*b).map(|&(p, _)| p);
            chart
                .draw_series(meshes.map(|p| TriangleMarker::new(p, 5, colour.filled())))
                .map_err(err)?;
            chart
                .draw_series(bumpy.map(|p| Circle::new(p, 3, colour.filled())))
                .map_err(err)?
                .label(*method)
                .legend(move |(x, y)| Circle::new((x + 8, y), 4, colour.filled()));
        }
        let position = if self.kind == 2 {
            SeriesLabelPosition::UpperLeft
        } else {
            SeriesLabelPosition::LowerRight
        };
        draw_legend(&mut chart, position)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exponent of a power law is recovered from two of its points, and work that did not
    /// change or a cost that is not positive has none.
    #[test]
    fn growth_exponent_of_power_laws() {
        for k in [0.5, 1.0, 1.5, 2.0] {
            let cost = |w: f64| 3.0 * libm::pow(w, k);
            let e = growth_exponent((20e3, cost(20e3)), (1.3e6, cost(1.3e6))).unwrap();
            assert!((e - k).abs() < 1e-12, "{k}: {e}");
        }
        assert_eq!(growth_exponent((5.0, 1.0), (5.0, 2.0)), None);
        assert_eq!(growth_exponent((5.0, 0.0), (50.0, 2.0)), None);
    }

    /// The bumpy spheres' triangle counts land within 1 % of each default target.
    #[test]
    fn stacks_hit_the_target_triangle_counts() {
        for target in DEFAULT_TRIANGLES {
            let s = stacks_for(target);
            let tris = 4 * s * (s - 1);
            let off = (f64::from(tris) / f64::from(target) - 1.0).abs();
            assert!(off < 0.01, "{target}: {tris}");
        }
    }

    /// Each method gets the first light shape it renders: the rectangle where it can, the
    /// sphere for the methods of Papers I, II and the penumbra map, the disk for CGI 2004's.
    #[test]
    fn each_method_gets_a_light_it_renders() {
        for m in methods::names() {
            let light = light_for(m).unwrap();
            let shape = light_shapes()
                .into_iter()
                .find(|(n, _)| *n == light)
                .unwrap()
                .1;
            assert!((methods::find(m).unwrap().supports)(&shape), "{m}");
        }
        assert_eq!(light_for("ssv").unwrap(), "rect");
        assert_eq!(light_for("pw2002").unwrap(), "sphere");
        assert_eq!(light_for("dbuffer").unwrap(), "disk");
        assert!(light_for("no-such-method").is_err());
    }
}
