//! The `penumbra` command line: `render`, `report`, `probe`, `list`, `experiment`, `golden`.
//! With no arguments it renders the built-in default scene with every available method into
//! `out/cube-of-spheres/` and its companions into `out/NAME/`, prints the error/time tables,
//! and writes the HTML
//! report `out/index.html`. Bad input prints one line naming the file and the problem and exits with code 2,
//! before any output is written.

use clap::{Parser, Subcommand};
use penumbra::error::InputError;
use penumbra::limits::MAX_THREADS;
use penumbra::memory;
use penumbra::methods::DefaultRun;
use penumbra::progress::Progress;
use penumbra::render::MethodRun;
use penumbra::report::SceneRuns;
use penumbra::scene::{builtin, file, validate, Scene};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser, Debug)]
#[command(
    name = "penumbra",
    version,
    about = "Deterministic soft-shadow algorithms on an emulated GPU"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Option<Cmd>,
    /// Worker threads, 1 to 1024 (default: all cores). Results are bit-identical for any count.
    #[arg(long, global = true)]
    threads: Option<usize>,
    /// Also write every buffer each method resolved its visibility from, as raw values, a
    /// viewable PNG and an overflow/clamp map (render, report and the default run; see
    /// docs/buffer-dumps.md).
    #[arg(long, global = true)]
    dump_buffers: bool,
}

#[derive(Subcommand, Debug)]
enum Cmd {
    /// Render a scene (file or built-in name) with its methods and print the error/time table.
    Render(RenderArgs),
    /// Render scenes like `render` and write an HTML page showing them all, DIR/index.html.
    Report(ReportArgs),
    /// Explain one pixel: every pass's contribution to it with one method, then the reference.
    Probe(ProbeArgs),
    /// Write a scene's meshes, camera, light, raycast's light samples and hard-sv's shadow
    /// volume as JSON, for renderers outside the crate (docs/cli.md).
    ExportScene(ExportArgs),
    /// Print the built-in scenes and the methods, one per line.
    List {
        /// Print instead every option table's keys: values, default and meaning.
        #[arg(long)]
        options: bool,
        /// With --options: print the listing as Markdown, the page docs/options.md.
        #[arg(long, requires = "options")]
        markdown: bool,
        /// Print instead the GPU profiles of the cost model, every figure with its source or
        /// assumption (docs/gpu-model.md); choose one with --opt gpu.model=NAME.
        #[arg(long, conflicts_with = "options")]
        gpus: bool,
    },
    /// Run an experiment, or merge the shards of an accuracy–time sweep.
    #[command(subcommand)]
    Experiment(ExperimentCmd),
    /// Check (or with --bless rewrite) the golden outputs under golden/.
    Golden {
        /// Rewrite the goldens instead of checking them.
        #[arg(long)]
        bless: bool,
        /// Golden root directory.
        #[arg(long, default_value = "golden")]
        root: PathBuf,
    },
}

#[derive(Subcommand, Debug)]
enum ExperimentCmd {
    /// Paper II §7: pw-restructured's memory traffic per tile size (sphere light).
    TileSize {
        /// Scene file or built-in name (sphere light).
        scene: String,
        /// Output directory for the CSV file, plot and summary.
        #[arg(long, default_value = penumbra::experiment::DEFAULT_OUT)]
        out: PathBuf,
    },
    /// Forest et al. 2006: error and time of the overlap correction (default scenes
    /// cube-of-spheres and forest-spheres).
    WedgeBlending {
        /// Scene file or built-in name (one rect light).
        scene: Option<String>,
        /// Output directory for the CSV files and summary.
        #[arg(long, default_value = penumbra::experiment::DEFAULT_OUT)]
        out: PathBuf,
        /// Image side (errors at SIZE², times at SIZE² and (2·SIZE)²).
        #[arg(long, default_value_t = 256)]
        size: u32,
    },
    /// Error against a 1024-sample raycast reference and time of every method and knob
    /// setting that applies to each scene, with a Pareto plot per scene.
    AccuracyTime {
        /// Scene files or built-in names.
        #[arg(required = true)]
        scenes: Vec<String>,
        /// Output directory.
        #[arg(long, default_value = penumbra::experiment::accuracy_time::DEFAULT_OUT)]
        out: PathBuf,
        /// Render at SIZE×SIZE instead of each scene's own size.
        #[arg(long)]
        size: Option<u32>,
        /// Measure only slice I of N (1-based, e.g. 2/4): the items k with k mod N = I − 1.
        #[arg(long)]
        shard: Option<String>,
        /// Timed runs per configuration (their median, min and max are reported).
        #[arg(long, default_value_t = penumbra::experiment::accuracy_time::TIMING_RUNS)]
        runs: usize,
        /// Also model each configuration's time on GPU profile NAME (repeatable; default the
        /// default profile): a modeled-time column, Pareto front and plot per profile
        /// (docs/gpu-model.md; `penumbra list --gpus` lists them).
        #[arg(long = "gpu", value_name = "NAME")]
        gpus: Vec<String>,
    },
    /// Issue 11: error added by each shader precision and buffer format, overflow of each
    /// buffer format over stacks of N = 1…512 quads, the papers' precision claims checked
    /// (default scenes cube-of-spheres, cube-of-spheres-sphere and disk-block).
    Precision {
        /// Scene files or built-in names.
        scenes: Vec<String>,
        /// Output directory.
        #[arg(long, default_value = penumbra::experiment::precision::DEFAULT_OUT)]
        out: PathBuf,
        /// Image side of the shader-precision and storage-format renders.
        #[arg(long, default_value_t = penumbra::experiment::precision::DEFAULT_SIZE)]
        size: u32,
    },
    /// Issue 32: every method's time and peak memory against the occluder's triangle count
    /// (bumpy spheres, and the meshes of --mesh) and against the image size, and the memory
    /// estimate against the measured peak (docs/performance.md "How cost grows").
    CostGrowth {
        /// Target triangle counts of the bumpy spheres, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = penumbra::experiment::cost_growth::DEFAULT_TRIANGLES)]
        triangles: Vec<u32>,
        /// A mesh file (OBJ, PLY, STL, glTF) to measure too (repeatable).
        #[arg(long = "mesh", value_name = "FILE")]
        meshes: Vec<PathBuf>,
        /// Image side of the triangle series.
        #[arg(long, default_value_t = penumbra::experiment::cost_growth::DEFAULT_SIZE)]
        size: u32,
        /// Image sides of the size series (on the first workload), comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = penumbra::experiment::cost_growth::DEFAULT_SIZES)]
        sizes: Vec<u32>,
        /// Comma-separated methods (default: every method).
        #[arg(long, value_delimiter = ',')]
        methods: Option<Vec<String>>,
        /// Processes per point (the median time, the largest peak).
        #[arg(long, default_value_t = 3)]
        runs: usize,
        /// Threads of each render (default: all cores).
        #[arg(long = "render-threads")]
        render_threads: Option<usize>,
        /// A method option for its renders, METHOD.KEY=VALUE (repeatable), e.g.
        /// raycast.samples=16.
        #[arg(long = "opt", value_name = "METHOD.KEY=VALUE")]
        opts: Vec<String>,
        /// Output directory.
        #[arg(long, default_value = penumbra::experiment::cost_growth::DEFAULT_OUT)]
        out: PathBuf,
    },
    /// Join the outputs of accuracy-time shards into what an unsharded run writes.
    Merge {
        /// The shards' output directories.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Output directory.
        #[arg(long, default_value = penumbra::experiment::accuracy_time::DEFAULT_OUT)]
        out: PathBuf,
    },
}

/// What `render` and `report` may change in a scene before rendering it.
#[derive(clap::Args, Debug, Default)]
struct SceneOverrides {
    /// Comma-separated methods (default: the scene's list, else every method its light supports).
    #[arg(long, value_delimiter = ',')]
    methods: Option<Vec<String>>,
    /// Override the image width (alone, the height follows the scene's aspect ratio).
    #[arg(long)]
    width: Option<u32>,
    /// Override the image height (alone, the width follows the scene's aspect ratio).
    #[arg(long)]
    height: Option<u32>,
    /// A method option, METHOD.KEY=VALUE (repeatable), e.g. nsample.n=256 or gpu.tile-size=16;
    /// `penumbra list --options` lists every key with its values and default.
    #[arg(long = "opt")]
    opts: Vec<String>,
    /// The GPU profile whose modeled time the table and stats.json show (`gpu_model`); the
    /// same as --opt gpu.model=NAME. `penumbra list --gpus` lists them.
    #[arg(long)]
    gpu: Option<String>,
    /// Refuse a render whose estimated memory exceeds this many bytes (suffix K, M, G, T:
    /// powers of 1024). Default: half of the machine's memory.
    #[arg(long)]
    max_memory: Option<String>,
}

#[derive(clap::Args, Debug)]
struct RenderArgs {
    /// Scene file (.toml/.json) or built-in scene name.
    #[arg(default_value = builtin::DEFAULT)]
    scene: String,
    #[command(flatten)]
    overrides: SceneOverrides,
    /// Output directory: DIR/METHOD/…. Default: out/SCENE (SCENE: the built-in name or the
    /// scene file's stem).
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(clap::Args, Debug)]
struct ReportArgs {
    /// Scene files (.toml/.json) or built-in scene names.
    #[arg(required = true)]
    scenes: Vec<String>,
    #[command(flatten)]
    overrides: SceneOverrides,
    /// Output directory: DIR/index.html and DIR/SCENE/METHOD/….
    #[arg(long, default_value = penumbra::render::DEFAULT_OUT)]
    out: PathBuf,
}

#[derive(clap::Args, Debug)]
struct ExportArgs {
    /// Scene file (.toml/.json) or built-in scene name.
    scene: String,
    #[command(flatten)]
    overrides: SceneOverrides,
    /// The JSON file to write.
    #[arg(long)]
    out: PathBuf,
}

#[derive(clap::Args, Debug)]
struct ProbeArgs {
    /// Scene file (.toml/.json) or built-in scene name.
    scene: String,
    /// The method whose passes are traced.
    #[arg(long)]
    method: String,
    /// The pixel, X,Y (column and row, row 0 at the top).
    #[arg(long)]
    pixel: String,
    /// Print the report as JSON instead of the listing.
    #[arg(long)]
    json: bool,
    /// List the events of every light sample (nsample, raycast), not only of the first few.
    #[arg(long)]
    verbose: bool,
    #[command(flatten)]
    overrides: SceneOverrides,
}

fn apply_overrides(scene: &mut Scene, a: &SceneOverrides) -> Result<(), InputError> {
    if let Some(m) = &a.methods {
        scene.methods = Some(m.clone());
    }
    scene.resize(a.width, a.height);
    for o in &a.opts {
        scene.set_cli_option(o)?;
    }
    if let Some(g) = &a.gpu {
        scene.set_cli_option(&format!("gpu.model={g}"))?;
    }
    validate::validate(scene)?;
    penumbra::methods::check_option_tables(scene)
}

/// The memory limit `a` sets (`--max-memory`, else the default) and where it comes from.
fn memory_limit(a: &SceneOverrides) -> Result<(Option<u64>, &'static str), InputError> {
    Ok(match &a.max_memory {
        Some(text) => (
            Some(
                memory::parse_size(text)
                    .map_err(|m| InputError::at("--max-memory", text.as_str(), m))?,
            ),
            "--max-memory",
        ),
        None => (
            memory::default_limit(),
            "the default, half of the machine's memory; set it with --max-memory",
        ),
    })
}

/// The scene argument `arg` with the overrides applied, validated, and checked against the
/// memory limit (with its buffer dumps when `dump_buffers`); prints the f32-rounding warning
/// if it applies. Nothing is rendered yet.
fn prepare(
    arg: &str,
    a: &SceneOverrides,
    dump_buffers: bool,
) -> Result<Scene, Box<dyn std::error::Error>> {
    let mut scene = file::resolve(arg)?;
    apply_overrides(&mut scene, a)?;
    let (limit, origin) = memory_limit(a)?;
    let methods = penumbra::methods::selected(&scene)?;
    memory::check_fits(&scene, (&methods, dump_buffers), limit, origin)?;
    if let Some(w) = validate::f32_rounding_warning(&scene) {
        eprintln!("penumbra: {w}");
    }
    for line in penumbra::scene::repair::repair_notes(&scene) {
        eprintln!(
            "penumbra: {}: warning: {line}",
            penumbra::error::shortened(&scene.source)
        );
    }
    Ok(scene)
}

/// Renders `scene` with a progress bar on a terminal (one step per method), with every
/// buffer dump when `dump_buffers`.
fn render_scene(scene: &Scene, dump_buffers: bool) -> Result<Vec<MethodRun>, InputError> {
    let progress = Progress::new(penumbra::render::render_order(scene)?.len(), &scene.source);
    let runs = penumbra::render::render_scene_dumping(scene, dump_buffers, |m| progress.start(m));
    progress.finish();
    runs
}

/// A rendered scene with the files its runs wrote.
struct Rendered {
    scene: Scene,
    runs: Vec<MethodRun>,
    files: Vec<Vec<String>>,
}

/// Writes `scene`'s runs into `out/METHOD/` (`out` = the scene's folder; every buffer dump's
/// files with `dump_buffers`) and prints its table and the outputs written.
fn write_and_print(
    out: &Path,
    scene: Scene,
    runs: Vec<MethodRun>,
    dump_buffers: bool,
) -> Result<Rendered, Box<dyn std::error::Error>> {
    let files = penumbra::render::write_runs(out, &scene, &runs, dump_buffers)?;
    print!("{}", penumbra::render::table(&scene, &runs));
    let error_png = if runs
        .iter()
        .any(|r| r.method == penumbra::methods::REFERENCE)
    {
        "error.png, "
    } else {
        ""
    };
    println!(
        "outputs: {}/METHOD/{{image.png, visibility.png, visibility.exr, visibility.pfm, {error_png}stats.json}}",
        out.display()
    );
    if dump_buffers {
        println!(
            "buffer dumps: {}/METHOD/NAME.{{bin or png, json, view.png, events.bin, events.png}} (docs/buffer-dumps.md)",
            out.display()
        );
    }
    Ok(Rendered { scene, runs, files })
}

fn render(a: &RenderArgs, dump_buffers: bool) -> Result<Rendered, Box<dyn std::error::Error>> {
    let scene = prepare(&a.scene, &a.overrides, dump_buffers)?;
    let out = a.out.clone().unwrap_or_else(|| {
        Path::new(penumbra::render::DEFAULT_OUT).join(scene_dir_name(&scene.source))
    });
    let runs = render_scene(&scene, dump_buffers)?;
    let methods = penumbra::methods::selected(&scene)?;
    let estimate_bytes = memory::estimate_dumping(&scene, &methods, dump_buffers);
    let rendered = write_and_print(&out, scene, runs, dump_buffers)?;
    let record = memory::MemoryRecord {
        estimate_bytes,
        limit_bytes: memory_limit(&a.overrides)?.0,
        peak_resident_bytes: memory::peak_resident_bytes(),
    };
    std::fs::write(
        out.join(memory::RECORD_FILE),
        serde_json::to_string_pretty(&record)? + "\n",
    )?;
    Ok(rendered)
}

/// Writes the report page for `rendered` scenes, whose method folders are `dirs` (relative to
/// `out`), and prints its path.
fn write_report(
    out: &Path,
    rendered: &[Rendered],
    dirs: &[PathBuf],
) -> Result<(), Box<dyn std::error::Error>> {
    let scenes: Vec<SceneRuns> = rendered
        .iter()
        .zip(dirs)
        .map(|(r, dir)| SceneRuns {
            scene: &r.scene,
            runs: &r.runs,
            files: &r.files,
            dir: dir.clone(),
        })
        .collect();
    let path = penumbra::report::write(out, &scenes)?;
    println!("report: {}", path.display());
    Ok(())
}

/// `report`: every scene is loaded and checked, then rendered, before anything is written, so
/// a bad scene or option leaves no output. Each scene's methods go to `out/SCENE/METHOD/`
/// (SCENE: the name's file stem, made unique), then the page to `out/index.html`.
fn report(a: &ReportArgs, dump_buffers: bool) -> Result<(), Box<dyn std::error::Error>> {
    let scenes = a
        .scenes
        .iter()
        .map(|arg| prepare(arg, &a.overrides, dump_buffers))
        .collect::<Result<Vec<_>, _>>()?;
    let runs = scenes
        .iter()
        .map(|s| render_scene(s, dump_buffers))
        .collect::<Result<Vec<_>, _>>()?;
    let mut dirs: Vec<PathBuf> = Vec::new();
    let mut rendered = Vec::new();
    for (scene, runs) in scenes.into_iter().zip(runs) {
        let stem = scene_dir_name(&scene.source);
        let dir = (1..)
            .map(|k| match k {
                1 => PathBuf::from(&stem),
                k => PathBuf::from(format!("{stem}-{k}")),
            })
            .find(|d| !dirs.contains(d))
            .expect("some suffix is free");
        rendered.push(write_and_print(
            &a.out.join(&dir),
            scene,
            runs,
            dump_buffers,
        )?);
        dirs.push(dir);
    }
    write_report(&a.out, &rendered, &dirs)
}

/// The folder a scene's methods are written to under the output directory: the built-in
/// name or the scene file's stem, reduced to `[A-Za-z0-9_-]`.
fn scene_dir_name(source: &str) -> String {
    penumbra::experiment::accuracy_time::plot_stem(source)
}

/// `probe`: the report of one pixel, as a listing or JSON; nothing is written.
fn probe(a: ProbeArgs) -> Result<(), Box<dyn std::error::Error>> {
    if a.overrides.methods.is_some() {
        return Err(InputError::at(
            "--methods",
            "probe",
            "probe traces one method: give it as --method METHOD",
        )
        .into());
    }
    let bad_pixel = || InputError::at("--pixel", a.pixel.as_str(), "expected X,Y, e.g. 30,41");
    let (x, y) = a.pixel.split_once(',').ok_or_else(bad_pixel)?;
    let pixel = [x, y].map(|v| v.trim().parse::<u32>());
    let [Ok(x), Ok(y)] = pixel else {
        return Err(bad_pixel().into());
    };
    let overrides = SceneOverrides {
        methods: Some(vec![a.method.clone()]),
        ..a.overrides
    };
    let scene = prepare(&a.scene, &overrides, false)?;
    let report = penumbra::probe::probe_pixel(&scene, &a.method, [x, y], a.verbose)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", report.text());
    }
    Ok(())
}

/// `export-scene`: the scene's export document ([`penumbra::export`]) written to `--out`.
fn export_scene(a: &ExportArgs) -> Result<(), Box<dyn std::error::Error>> {
    let mut scene = file::resolve(&a.scene)?;
    apply_overrides(&mut scene, &a.overrides)?;
    let doc = penumbra::export::export_scene(&scene)?;
    std::fs::write(&a.out, serde_json::to_vec(&doc)?)
        .map_err(|e| format!("{}: cannot write: {e}", a.out.display()))?;
    println!("export: {}", a.out.display());
    Ok(())
}

/// A scene argument, loaded and validated, its option tables checked.
fn load_scene(arg: &str) -> Result<Scene, InputError> {
    let scene = file::resolve(arg)?;
    validate::validate(&scene)?;
    penumbra::methods::check_option_tables(&scene)?;
    Ok(scene)
}

fn experiment(cmd: ExperimentCmd) -> Result<(), Box<dyn std::error::Error>> {
    use penumbra::experiment::{accuracy_time, precision, sized, tile_size, wedge_blending};
    let size_range = |size: u32| {
        if (16..=2048).contains(&size) {
            Ok(size)
        } else {
            Err(InputError::at(
                "--size",
                size.to_string(),
                "expected 16…2048",
            ))
        }
    };
    match cmd {
        ExperimentCmd::TileSize { scene, out } => {
            print!("{}", tile_size::run(&load_scene(&scene)?, &out)?);
            println!(
                "outputs: {0}/{1}, {0}/{2}, {0}/{3}, {0}/{4}",
                out.display(),
                tile_size::CSV_FILE,
                tile_size::SVG_FILE,
                tile_size::PNG_FILE,
                tile_size::SUMMARY_FILE
            );
        }
        ExperimentCmd::WedgeBlending { scene, out, size } => {
            let scenes = match scene {
                Some(s) => vec![load_scene(&s)?],
                None => wedge_blending::SCENES
                    .iter()
                    .map(|n| builtin::load(n).ok_or("missing built-in scene"))
                    .collect::<Result<_, _>>()?,
            };
            for s in &scenes {
                wedge_blending::check_scene(s)?;
            }
            print!("{}", wedge_blending::run(&scenes, size_range(size)?, &out)?);
            println!(
                "outputs: {0}/wedge_blending_errors.csv, {0}/wedge_blending_times.csv, {0}/summary.md",
                out.display()
            );
        }
        ExperimentCmd::AccuracyTime {
            scenes,
            out,
            size,
            shard,
            runs,
            gpus,
        } => {
            let gpus = if gpus.is_empty() {
                vec![penumbra::gpu_model::GpuModel::default()]
            } else {
                gpus.iter()
                    .map(|g| {
                        use penumbra::options::OptionType;
                        type Gpu = penumbra::gpu_model::GpuModel;
                        Gpu::named(g).ok_or_else(|| {
                            let expected = Gpu::accepted(&Gpu::everything()).expected();
                            InputError::at("--gpu", g, format!("unknown GPU profile; {expected}"))
                        })
                    })
                    .collect::<Result<Vec<_>, _>>()?
            };
            let shard = match shard {
                Some(spec) => accuracy_time::Shard::parse(&spec)?,
                None => accuracy_time::Shard::WHOLE,
            };
            let size = size.map(size_range).transpose()?;
            let mut loaded = Vec::new();
            for arg in &scenes {
                let scene = load_scene(arg)?;
                let scene = match size {
                    Some(n) => sized(scene, n),
                    None => scene,
                };
                // The sweep keeps one method's output at a time.
                for m in penumbra::methods::names() {
                    memory::check_fits(
                        &scene,
                        (&[m.to_string()], false),
                        memory::default_limit(),
                        "half of the machine's memory",
                    )?;
                }
                loaded.push(scene);
            }
            let sweep = accuracy_time::run(
                &loaded,
                &accuracy_time::configurations(),
                runs,
                shard,
                &gpus,
            )?;
            accuracy_time::write(&sweep, &out)?;
            print!("{}", accuracy_time::summary(&sweep));
            print_accuracy_outputs(&sweep, &out);
        }
        ExperimentCmd::Precision { scenes, out, size } => {
            let names: Vec<String> = if scenes.is_empty() {
                precision::SCENES.iter().map(|s| s.to_string()).collect()
            } else {
                scenes
            };
            let loaded = names
                .iter()
                .map(|n| load_scene(n))
                .collect::<Result<Vec<_>, _>>()?;
            let (study, maps) = precision::study(&loaded, size_range(size)?)?;
            precision::write(&study, &maps, &out)?;
            print!("{}", precision::summary(&study));
            println!(
                "outputs: {0}/{1}, {0}/{2}, {0}/{3}, {0}/precision.json, CSV files and maps/",
                out.display(),
                precision::SUMMARY_FILE,
                precision::SHADER_PNG,
                precision::OVERFLOW_PNG
            );
        }
        ExperimentCmd::CostGrowth {
            triangles,
            meshes,
            size,
            sizes,
            methods,
            runs,
            render_threads,
            opts,
            out,
        } => {
            use penumbra::experiment::cost_growth;
            for &t in &triangles {
                if !(24..=20_000_000).contains(&t) {
                    return Err(InputError::at(
                        "--triangles",
                        t.to_string(),
                        "expected 24…20000000",
                    )
                    .into());
                }
            }
            if runs == 0 {
                return Err(InputError::at("--runs", "0", "expected at least 1").into());
            }
            let threads = render_threads
                .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
            if !(1..=MAX_THREADS).contains(&threads) {
                return Err(InputError::at(
                    "--render-threads",
                    threads.to_string(),
                    format!("expected 1…{MAX_THREADS}"),
                )
                .into());
            }
            let plan = cost_growth::Plan {
                triangles,
                meshes,
                size: size_range(size)?,
                sizes: sizes
                    .into_iter()
                    .map(size_range)
                    .collect::<Result<_, _>>()?,
                methods: methods
                    .unwrap_or_else(|| penumbra::methods::names().map(String::from).collect()),
                runs,
                threads,
                opts,
            };
            let exe = std::env::current_exe()?;
            let points = cost_growth::run(&plan, &exe, &out, |p| eprintln!("cost-growth: {p}"))?;
            cost_growth::write(&plan, &points, &out)?;
            print!("{}", cost_growth::summary(&plan, &points));
            println!(
                "outputs: {0}/{{{1}, {2}, {3}}}, {0}/{{{4}}}.{{png,svg}}",
                out.display(),
                cost_growth::CSV_FILE,
                cost_growth::JSON_FILE,
                cost_growth::SUMMARY_FILE,
                cost_growth::PLOTS.join(", ")
            );
        }
        ExperimentCmd::Merge { dirs, out } => {
            let shards = dirs
                .iter()
                .map(|d| Ok((d.display().to_string(), accuracy_time::read(d)?)))
                .collect::<Result<Vec<_>, InputError>>()?;
            let sweep = accuracy_time::merge(&shards)?;
            accuracy_time::write(&sweep, &out)?;
            print!("{}", accuracy_time::summary(&sweep));
            print_accuracy_outputs(&sweep, &out);
        }
    }
    Ok(())
}

/// The files an accuracy-time run or merge wrote.
fn print_accuracy_outputs(
    sweep: &penumbra::experiment::accuracy_time::Sweep,
    out: &std::path::Path,
) {
    use penumbra::experiment::accuracy_time::{CSV_FILE, JSON_FILE, SUMMARY_FILE};
    let plots = if sweep.shard == penumbra::experiment::accuracy_time::Shard::WHOLE {
        ", SCENE-pareto.{png,svg}, SCENE-pareto-gpu-ID.{png,svg}"
    } else {
        " (a shard: plots come from `experiment merge`)"
    };
    println!(
        "outputs: {}/{{{CSV_FILE}, {JSON_FILE}, {SUMMARY_FILE}}}{plots}",
        out.display()
    );
}

fn run(cli: Cli) -> Result<(), Box<dyn std::error::Error>> {
    if let Some(n) = cli.threads {
        let bad = |why: String| InputError::at("--threads", n.to_string(), why);
        if !(1..=MAX_THREADS).contains(&n) {
            return Err(bad(format!("expected 1..={MAX_THREADS} worker threads")).into());
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| bad(format!("cannot start {n} worker threads: {e}")))?;
    }
    let dumps = cli.dump_buffers;
    if dumps
        && matches!(
            cli.cmd,
            Some(
                Cmd::List { .. }
                    | Cmd::Probe(_)
                    | Cmd::ExportScene(_)
                    | Cmd::Experiment(_)
                    | Cmd::Golden { .. }
            )
        )
    {
        return Err(InputError::new(
            "--dump-buffers",
            "only render, report and the default run (no command) write buffer dumps",
        )
        .into());
    }
    match cli.cmd {
        // The default scene, then its companions so that the methods its rectangular light
        // cannot run appear in a table too: the sphere-light twin (penumbra wedges,
        // penumbra maps) and a disk-light scene (the D-buffer). The companions skip nsample,
        // the slowest method, to keep the default run short; raycast is every table's
        // reference.
        None => {
            let out = PathBuf::from(penumbra::render::DEFAULT_OUT);
            let mut rendered = vec![render(
                &RenderArgs {
                    scene: builtin::DEFAULT.into(),
                    overrides: SceneOverrides::default(),
                    out: Some(out.join(builtin::DEFAULT)),
                },
                dumps,
            )?];
            let mut dirs = vec![PathBuf::from(builtin::DEFAULT)];
            for name in builtin::DEFAULT_COMPANIONS {
                let scene = builtin::load(name).ok_or("missing built-in companion scene")?;
                let methods = penumbra::methods::ALL
                    .iter()
                    .filter(|m| {
                        m.default_run == DefaultRun::EveryScene
                            && penumbra::methods::supports_scene(m.name, &scene)
                    })
                    .map(|m| m.name.to_string())
                    .collect();
                rendered.push(render(
                    &RenderArgs {
                        scene: name.to_string(),
                        overrides: SceneOverrides {
                            methods: Some(methods),
                            ..SceneOverrides::default()
                        },
                        out: Some(out.join(name)),
                    },
                    dumps,
                )?);
                dirs.push(PathBuf::from(name));
            }
            write_report(&out, &rendered, &dirs)
        }
        Some(Cmd::Experiment(e)) => experiment(e),
        Some(Cmd::Render(a)) => render(&a, dumps).map(|_| ()),
        Some(Cmd::Report(a)) => report(&a, dumps),
        Some(Cmd::Probe(a)) => probe(a),
        Some(Cmd::ExportScene(a)) => export_scene(&a),
        Some(Cmd::List { gpus: true, .. }) => {
            print!("{}", penumbra::gpu_model::profile::listing());
            Ok(())
        }
        Some(Cmd::List {
            options: true,
            markdown,
            ..
        }) => {
            let tables = penumbra::methods::option_docs();
            if markdown {
                print!("{}", penumbra::options::markdown(&tables));
            } else {
                print!("{}", penumbra::options::listing(&tables));
            }
            Ok(())
        }
        Some(Cmd::List { options: false, .. }) => {
            println!("# built-in scenes");
            for n in builtin::names() {
                println!("{n}");
            }
            println!("# methods");
            for m in penumbra::methods::names() {
                println!("{m}");
            }
            Ok(())
        }
        Some(Cmd::Golden { bless, root }) => {
            // Outside the repository there is nothing to check, and blessing would write a
            // whole golden tree into the current directory.
            if !root.join("..").join("scenes").is_dir() || !root.is_dir() {
                return Err(InputError::new(
                    root.display().to_string(),
                    "not the golden directory of a penumbra repository (golden/ next to \
                     scenes/): run `penumbra golden` from the repository's root, or pass \
                     --root PATH/TO/golden",
                )
                .into());
            }
            let report = penumbra::golden::run_cases(&root, bless)?;
            print!("{report}");
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("penumbra: {e}");
            if e.downcast_ref::<InputError>().is_some() {
                ExitCode::from(2)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}
