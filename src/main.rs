//! The `penumbra` command line: `render`, `list`, `golden`. With no arguments it renders the
//! built-in default scene with every available method into `out/` and prints the error/time
//! table. Bad input prints one line naming the file and the problem and exits with code 2,
//! before any output is written.

use clap::{Parser, Subcommand};
use penumbra::error::InputError;
use penumbra::limits::MAX_THREADS;
use penumbra::memory;
use penumbra::scene::{builtin, file, validate, OptionValue, Scene};
use std::path::PathBuf;
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
}

#[derive(Subcommand, Debug)]
enum Cmd {
    /// Render a scene (file or built-in name) with its methods and print the error/time table.
    Render(RenderArgs),
    /// Print the built-in scenes and the methods, one per line.
    List,
    /// Run an experiment: `tile-size SCENE` (Paper II §7, sphere light) or
    /// `wedge-blending [SCENE]` (Forest et al. 2006: error and time of the overlap
    /// correction; default scenes cube-of-spheres and forest-spheres).
    Experiment {
        /// The experiment: `tile-size` or `wedge-blending`.
        #[arg(value_parser = ["tile-size", "wedge-blending"])]
        name: String,
        /// Scene file or built-in name (required for tile-size).
        scene: Option<String>,
        /// Output directory for the CSV files, plots and summary.
        #[arg(long, default_value = "out/experiment")]
        out: PathBuf,
        /// Image side for wedge-blending (errors at SIZE², times at SIZE² and (2·SIZE)²).
        #[arg(long, default_value_t = 256)]
        size: u32,
    },
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

#[derive(clap::Args, Debug)]
struct RenderArgs {
    /// Scene file (.toml/.json) or built-in scene name.
    #[arg(default_value = builtin::DEFAULT)]
    scene: String,
    /// Comma-separated methods (default: the scene's list, else every method its light supports).
    #[arg(long, value_delimiter = ',')]
    methods: Option<Vec<String>>,
    /// Override the image width.
    #[arg(long)]
    width: Option<u32>,
    /// Override the image height.
    #[arg(long)]
    height: Option<u32>,
    /// Output directory.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// A method option, METHOD.KEY=VALUE (repeatable), e.g. nsample.n=256 or gpu.tile_size=16.
    #[arg(long = "opt")]
    opts: Vec<String>,
    /// Refuse a render whose estimated memory exceeds this many bytes (suffix K, M, G, T:
    /// powers of 1024). Default: half of the machine's memory.
    #[arg(long)]
    max_memory: Option<String>,
}

fn apply_overrides(scene: &mut Scene, a: &RenderArgs) -> Result<(), InputError> {
    if let Some(m) = &a.methods {
        scene.methods = Some(m.clone());
    }
    if let Some(w) = a.width {
        scene.width = w;
    }
    if let Some(h) = a.height {
        scene.height = h;
    }
    for o in &a.opts {
        let bad = || InputError::at("--opt", o.as_str(), "expected METHOD.KEY=VALUE");
        let (lhs, value) = o.split_once('=').ok_or_else(bad)?;
        let (method, key) = lhs.split_once('.').ok_or_else(bad)?;
        if method.is_empty() || key.is_empty() {
            return Err(bad());
        }
        scene
            .options
            .entry(method.to_string())
            .or_default()
            .insert(key.to_string(), OptionValue::parse_cli(value));
    }
    validate::validate(scene)
}

fn render(a: &RenderArgs) -> Result<(), Box<dyn std::error::Error>> {
    let mut scene = file::resolve(&a.scene)?;
    apply_overrides(&mut scene, a)?;
    let (limit, origin) = match &a.max_memory {
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
    };
    memory::check_fits(&scene, &penumbra::methods::selected(&scene)?, limit, origin)?;
    if let Some(w) = validate::f32_rounding_warning(&scene) {
        eprintln!("penumbra: {w}");
    }
    let runs = penumbra::render::render_scene(&scene)?;
    penumbra::render::write_runs(&a.out, &scene, &runs)?;
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
        a.out.display()
    );
    Ok(())
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
    match cli.cmd {
        // The default scene, then its companions so that the methods its rectangular light
        // cannot run appear in a table too: the sphere-light twin (penumbra wedges,
        // penumbra maps) and a disk-light scene (the D-buffer). The companions skip nsample,
        // the slowest method, to keep the default run short; raycast is every table's
        // reference.
        None => {
            render(&RenderArgs {
                scene: builtin::DEFAULT.into(),
                methods: None,
                width: None,
                height: None,
                out: "out".into(),
                opts: vec![],
                max_memory: None,
            })?;
            for name in builtin::DEFAULT_COMPANIONS {
                let scene = builtin::load(name).ok_or("missing built-in companion scene")?;
                let methods = penumbra::methods::ALL
                    .iter()
                    .filter(|m| **m != "nsample" && penumbra::methods::supports_scene(m, &scene))
                    .map(|m| m.to_string())
                    .collect();
                render(&RenderArgs {
                    scene: name.to_string(),
                    methods: Some(methods),
                    width: None,
                    height: None,
                    out: format!("out/{name}").into(),
                    opts: vec![],
                    max_memory: None,
                })?;
            }
            Ok(())
        }
        Some(Cmd::Experiment {
            name,
            scene,
            out,
            size,
        }) => {
            let scene = scene.map(|s| file::resolve(&s)).transpose()?;
            if let Some(s) = &scene {
                validate::validate(s)?;
            }
            if name == "wedge-blending" {
                let scenes = match scene {
                    Some(s) => vec![s],
                    None => penumbra::experiment::wedge_blending::SCENES
                        .iter()
                        .map(|n| builtin::load(n).ok_or("missing built-in scene"))
                        .collect::<Result<_, _>>()?,
                };
                if let Some(bad) = scenes.iter().find(|s| {
                    !penumbra::methods::supports_scene("wedge-blending", s) || s.is_multi_light()
                }) {
                    return Err(InputError::at(
                        &bad.source,
                        "light",
                        "the wedge-blending experiment needs one rect light",
                    )
                    .into());
                }
                if !(16..=2048).contains(&size) {
                    return Err(InputError::at("--size", "size", "expected 16…2048").into());
                }
                print!(
                    "{}",
                    penumbra::experiment::wedge_blending::run(&scenes, size, &out)?
                );
                println!(
                    "outputs: {0}/wedge_blending_errors.csv, {0}/wedge_blending_times.csv, {0}/summary.md",
                    out.display()
                );
                return Ok(());
            }
            let scene = scene.ok_or_else(|| {
                InputError::at(
                    "experiment",
                    "scene",
                    "tile-size needs a SCENE (sphere light)",
                )
            })?;
            print!("{}", penumbra::experiment::tile_size::run(&scene, &out)?);
            println!(
                "outputs: {0}/tile_size.csv, {0}/tile_size.svg",
                out.display()
            );
            Ok(())
        }
        Some(Cmd::Render(a)) => render(&a),
        Some(Cmd::List) => {
            println!("# built-in scenes");
            for n in builtin::names() {
                println!("{n}");
            }
            println!("# methods");
            for m in penumbra::methods::ALL {
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
