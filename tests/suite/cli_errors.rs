//! The command line on bad input (`docs/cli.md` "Errors and exit codes",
//! `docs/architecture.md` "Bad input"): every bad scene file and bad argument gets exactly one
//! line on stderr naming the file and the problem, exit status 2, and no output at all — the
//! `--out` directory is not created, and an existing one is left untouched. Plus the good path: one small render writes every documented file and a
//! `stats.json` with the documented keys, and `penumbra list` prints the built-in scenes and the
//! methods one per line.
//!
//! Runs the built binary (`CARGO_BIN_EXE_penumbra`) at 32×32 with `hard-sv`, so each case
//! takes milliseconds.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The crate root (the binary runs there, so relative scene paths match the docs' examples).
fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh, not yet existing output directory under `CARGO_TARGET_TMPDIR`, unique per call.
fn fresh_out(tag: &str) -> PathBuf {
    static N: AtomicUsize = AtomicUsize::new(0);
    let n = N.fetch_add(1, Ordering::Relaxed);
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cli_errors-{tag}-{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Runs `penumbra ARGS` in the crate root.
fn penumbra(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("cannot run the penumbra binary")
}

/// `penumbra render ARGS --out DIR` with `DIR` fresh; returns the output and `DIR`.
fn render(tag: &str, args: &[&str]) -> (Output, PathBuf) {
    let out = fresh_out(tag);
    let mut all = vec!["render"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--out", out.to_str().expect("UTF-8 temp path")]);
    (penumbra(&all), out)
}

/// Asserts the run failed as bad input must: status 2, one line on stderr that names `file`
/// and contains at least one of `keywords`, nothing on stdout, and no `out` directory.
fn assert_bad_input(what: &str, (output, out): &(Output, PathBuf), file: &str, keywords: &[&str]) {
    let stderr = String::from_utf8_lossy(&output.stderr);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(
        output.status.code(),
        Some(2),
        "{what}: exit status {:?}, stderr {stderr:?}",
        output.status
    );
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{what}: stderr is not one line: {stderr:?}");
    assert!(
        lines[0].contains(file),
        "{what}: stderr does not name {file:?}: {stderr:?}"
    );
    assert!(
        keywords.iter().any(|k| lines[0].contains(k)),
        "{what}: stderr names none of {keywords:?}: {stderr:?}"
    );
    assert!(!stderr.contains("panicked"), "{what}: panic: {stderr:?}");
    assert!(stdout.is_empty(), "{what}: printed on stdout: {stdout:?}");
    assert!(
        !out.exists(),
        "{what}: wrote partial output into {}",
        out.display()
    );
}

/// Arguments of the small render every bad-file case uses.
const SMALL: &[&str] = &["--width", "32", "--height", "32", "--methods", "hard-sv"];

/// One case per file in `scenes/bad/`: which problem its error line must mention. A new bad
/// file without an entry here fails [`every_bad_scene_file_is_rejected`].
const BAD_FILES: &[(&str, &[&str])] = &[
    ("malformed.toml", &["line"]),
    (
        "missing-obj.toml",
        &["missing", "not found", "No such file", "cannot read"],
    ),
    ("open-mesh.toml", &["open"]),
    ("nan-vertex.toml", &["NaN", "nan", "finite"]),
    ("nan-light.toml", &["NaN", "nan", "finite"]),
    ("zero-light.toml", &["zero"]),
    ("unknown-method.toml", &["unknown method"]),
    (
        "camera-inside-mesh.toml",
        &["camera inside geometry", "near plane"],
    ),
    (
        "penumbra-map-frustum.toml",
        &["one light frustum cannot cover the scene"],
    ),
    ("light-overlaps-mesh.toml", &["light intersects geometry"]),
    ("top-level-array.json", &["not an array"]),
    (
        "dbuffer-frustum.toml",
        &["one light frustum cannot cover the scene"],
    ),
];

/// Files whose problem is in their own method list or in a method that list names, which
/// `--methods` would replace: they run with their own list.
const OWN_METHODS: &[&str] = &[
    "unknown-method.toml",
    "penumbra-map-frustum.toml",
    "dbuffer-frustum.toml",
];

#[test]
fn every_bad_scene_file_is_rejected() {
    let mut files: Vec<String> = std::fs::read_dir(root().join("scenes/bad"))
        .expect("scenes/bad")
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml" || e == "json"))
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    files.sort();
    let mut known: Vec<String> = BAD_FILES.iter().map(|(f, _)| f.to_string()).collect();
    known.sort();
    assert_eq!(files, known, "scenes/bad/ and BAD_FILES disagree");

    for (name, keywords) in BAD_FILES {
        let path = format!("scenes/bad/{name}");
        let args: Vec<&str> = if OWN_METHODS.contains(name) {
            vec![path.as_str(), "--width", "32", "--height", "32"]
        } else {
            [&[path.as_str()], SMALL].concat()
        };
        assert_bad_input(name, &render(name, &args), name, keywords);
    }
}

#[test]
fn bad_input_leaves_an_existing_out_dir_untouched() {
    let out = fresh_out("existing");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("keep.txt"), "mine").unwrap();
    let o = out.to_str().unwrap();
    let output = penumbra(&[
        "render",
        "scenes/bad/open-mesh.toml",
        "--width",
        "32",
        "--height",
        "32",
        "--methods",
        "hard-sv",
        "--out",
        o,
    ]);
    assert_eq!(output.status.code(), Some(2));
    assert_eq!(entries(&out), ["keep.txt"]);
    std::fs::remove_dir_all(&out).unwrap();
}

/// The names in directory `dir`, sorted.
fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn unknown_scene_name_or_path() {
    assert_bad_input(
        "unknown built-in",
        &render("nosuch", &[&["no-such-scene"], SMALL].concat()),
        "no-such-scene",
        &["not a built-in", "not found", "No such file"],
    );
    assert_bad_input(
        "missing file",
        &render("nofile", &[&["scenes/no-such-file.toml"], SMALL].concat()),
        "scenes/no-such-file.toml",
        &["not a built-in", "not found", "No such file"],
    );
    assert_bad_input(
        "not a scene file",
        &render("readme", &[&["README.md"], SMALL].concat()),
        "README.md",
        &["extension"],
    );
}

#[test]
fn bad_options_and_methods() {
    let scene = "single-quad";
    let small = ["--width", "32", "--height", "32"];
    // (what, arguments, what the error line names: the scene or the `--opt` argument, keywords)
    let cases: &[(&str, &[&str], &str, &[&str])] = &[
        (
            "unknown option",
            &["--methods", "nsample", "--opt", "nsample.bogus=1"],
            "--opt nsample.bogus=1",
            &["unknown option bogus for nsample; valid: mode, stencil, submission, horizon, n"],
        ),
        (
            "not a perfect square",
            &["--methods", "nsample", "--opt", "nsample.n=1000"],
            "--opt nsample.n=1000",
            &["perfect square"],
        ),
        (
            "option of a method not rendered",
            &["--methods", "hard-sv", "--opt", "nsample.n=1000"],
            "--opt nsample.n=1000",
            &["perfect square"],
        ),
        (
            "unknown key of a method not rendered",
            &["--methods", "hard-sv", "--opt", "ssv.bogus=1"],
            "--opt ssv.bogus=1",
            &["unknown option bogus for ssv"],
        ),
        (
            "tile size",
            &["--methods", "hard-sv", "--opt", "gpu.tile-size=3"],
            "--opt gpu.tile-size=3",
            &["invalid value 3; expected a power of two in 2..=256"],
        ),
        (
            "snake-case key",
            &["--methods", "hard-sv", "--opt", "gpu.tile_size=16"],
            "--opt gpu.tile_size=16",
            &["unknown option tile_size for gpu; did you mean tile-size? valid: tile-size, depth"],
        ),
        (
            "unknown method",
            &["--methods", "nosuch"],
            scene,
            &["unknown method"],
        ),
        (
            "a method listed twice",
            &["--methods", "hard-sv,hard-sv"],
            scene,
            &["method \"hard-sv\" is listed twice"],
        ),
        (
            "unknown option table",
            &["--methods", "hard-sv", "--opt", "bogus.x=1"],
            "--opt bogus.x=1",
            &["unknown method \"bogus\"; known: gpu, raycast, nsample"],
        ),
        (
            "option without a value",
            &["--methods", "hard-sv", "--opt", "hard-sv"],
            "--opt hard-sv",
            &["METHOD.KEY=VALUE"],
        ),
        (
            "hard-sv option",
            &["--methods", "hard-sv", "--opt", "hard-sv.bogus=1"],
            "--opt hard-sv.bogus=1",
            &["unknown option"],
        ),
        (
            "hard-sv value",
            &["--methods", "hard-sv", "--opt", "hard-sv.mode=z-fail"],
            "--opt hard-sv.mode=z-fail",
            &["invalid value \"z-fail\"; expected one of auto, zpass, zfail"],
        ),
        (
            "unknown key of a method that cannot render the light",
            &["--methods", "hard-sv", "--opt", "pw2002.bogus=1"],
            "--opt pw2002.bogus=1",
            &["unknown option bogus for pw2002"],
        ),
        (
            "bad value of a method that cannot render the light",
            &["--methods", "hard-sv", "--opt", "pw2002.li=9"],
            "--opt pw2002.li=9",
            &["invalid value 9; expected one of 16, 12, 8"],
        ),
        (
            "known key of a method that cannot render the light",
            &["--methods", "hard-sv", "--opt", "pw2002.li=8"],
            "--opt pw2002.li=8",
            &["method pw2002 does not support rect lights"],
        ),
        (
            "ssv filter with exact coverage",
            &["--methods", "ssv", "--opt", "ssv.filter=bilinear"],
            "--opt ssv.filter=bilinear",
            &["coverage = \"texture\""],
        ),
        (
            "ssv texture-n with exact coverage",
            &[
                "--methods",
                "ssv",
                "--opt",
                "ssv.coverage=exact",
                "--opt",
                "ssv.texture-n=16",
            ],
            "--opt ssv.texture-n=16",
            &["coverage = \"texture\""],
        ),
        (
            "wedge-blending packing",
            &[
                "--methods",
                "wedge-blending",
                "--opt",
                "wedge-blending.packing=4bit",
            ],
            "--opt wedge-blending.packing=4bit",
            &["expected one of 8bit, f32"],
        ),
        (
            "wedge-blending target without packing",
            &[
                "--methods",
                "wedge-blending",
                "--opt",
                "wedge-blending.packing=f32",
                "--opt",
                "wedge-blending.target=flush-denormals",
            ],
            "--opt wedge-blending.target=flush-denormals",
            &["8bit"],
        ),
        (
            "penumbra maps need a sphere light",
            &["--methods", "penumbra-map"],
            scene,
            &["method penumbra-map does not support rect lights"],
        ),
        (
            "the D-buffer needs a disk light",
            &["--methods", "dbuffer"],
            scene,
            &["method dbuffer does not support rect lights"],
        ),
    ];
    for (what, args, file, keywords) in cases {
        let all: Vec<&str> = [&[scene][..], &small, args].concat();
        assert_bad_input(what, &render(what, &all), file, keywords);
    }
    // dbuffer's own options, on a disk-light scene.
    let disk_cases: &[(&str, &[&str], &[&str])] = &[
        (
            "dbuffer eq3",
            &["--opt", "dbuffer.eq3=exact"],
            &["--opt dbuffer.eq3=exact: invalid value \"exact\"; expected one of corrected, printed"],
        ),
        (
            "dbuffer storage",
            &["--opt", "dbuffer.storage=unorm8"],
            &["expected one of f32, f16"],
        ),
        (
            "dbuffer map size",
            &["--opt", "dbuffer.map-size=4"],
            &["--opt dbuffer.map-size=4: invalid value 4; expected an integer in 8..=4096"],
        ),
        (
            "dbuffer map size, snake case",
            &["--opt", "dbuffer.map_size=64"],
            &["unknown option map_size for dbuffer; did you mean map-size? valid: map-size, depth"],
        ),
    ];
    for (what, args, keywords) in disk_cases {
        let all: Vec<&str> =
            [&["disk-block"][..], &small, &["--methods", "dbuffer"], args].concat();
        assert_bad_input(what, &render(what, &all), "--opt dbuffer.", keywords);
    }
    for size in ["0", "100000"] {
        assert_bad_input(
            "image size",
            &render(
                "size",
                &[
                    scene,
                    "--width",
                    size,
                    "--height",
                    "32",
                    "--methods",
                    "hard-sv",
                ],
            ),
            scene,
            &["width"],
        );
    }
}

/// An option written in a scene file: its errors name the file and `options.METHOD.KEY`; the
/// same option from `--opt` names the argument instead, and `--opt` overrides the file.
#[test]
fn scene_file_option_errors_name_the_file_and_the_key() {
    let dir = fresh_out("option-file");
    std::fs::create_dir_all(&dir).unwrap();
    let base = std::fs::read_to_string(root().join("scenes/tetra-on-floor.toml")).unwrap();
    let write = |name: &str, table: &str| {
        let path = dir.join(name);
        let models = root().join("scenes/models");
        let text = base.replace("\"models/", &format!("\"{}/", models.display()));
        std::fs::write(&path, format!("{text}\n{table}\n")).unwrap();
        path
    };
    let bad_value = write("li.toml", "[options.hard-sv]\nmode = \"z-fail\"");
    let file = bad_value.to_str().unwrap();
    assert_bad_input(
        "bad value in the file",
        &render("file-value", &[&[file][..], SMALL].concat()),
        &format!("{file}: options.hard-sv.mode: "),
        &["invalid value \"z-fail\"; expected one of auto, zpass, zfail"],
    );
    // The same key from the command line overrides the file's value: a good one renders.
    let (ok, out) = render(
        "file-value-overridden",
        &[&[file][..], SMALL, &["--opt", "hard-sv.mode=zfail"]].concat(),
    );
    assert_eq!(ok.status.code(), Some(0), "{ok:?}");
    assert!(out.join("hard-sv/stats.json").is_file());
    let snake = write("snake.toml", "[options.gpu]\ntile_size = 16");
    let file = snake.to_str().unwrap();
    assert_bad_input(
        "snake-case key in the file",
        &render("file-snake", &[&[file][..], SMALL].concat()),
        &format!("{file}: options.gpu.tile_size: "),
        &["did you mean tile-size?"],
    );
    let table = write("table.toml", "[options.hardsv]\nmode = \"zfail\"");
    let file = table.to_str().unwrap();
    assert_bad_input(
        "unknown table in the file",
        &render("file-table", &[&[file][..], SMALL].concat()),
        &format!("{file}: options.hardsv: "),
        &["unknown method \"hardsv\"; known: gpu, raycast, nsample, hard-sv"],
    );
}

/// Values written naturally are read alike from a scene file and from `--opt`: `li = 12`,
/// `li = "12"`, `--opt pw2002.li=12`, and a number key written as an integer.
#[test]
fn natural_spellings_render() {
    let small = ["--width", "16", "--height", "16"];
    for opts in [
        &[
            "--opt",
            "pw2002.li=12",
            "--opt",
            "pw2002.side-planes=cancel",
        ][..],
        &[
            "--opt",
            "penumbra-map.bias=4",
            "--opt",
            "penumbra-map.slope-bias=2.5",
        ][..],
        &["--opt", "gpu.tile-size=16", "--opt", "gpu.depth=d32f"][..],
    ] {
        let methods = ["--methods", "pw2002,penumbra-map"];
        let (output, out) = render(
            "natural",
            &[&["cube-of-spheres-sphere"][..], &small, &methods, opts].concat(),
        );
        assert_eq!(output.status.code(), Some(0), "{opts:?}: {output:?}");
        assert!(out.join("pw2002/stats.json").is_file(), "{opts:?}");
    }
}

/// A path with a line break in it (found by the `scene_json` fuzzer) still gives one line:
/// the break is printed escaped.
#[test]
fn newline_in_a_quoted_path_stays_on_one_line() {
    let dir = fresh_out("newline-scene");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("newline.toml");
    std::fs::write(
        &scene,
        "[camera]\neye = [0, 2, 5]\ntarget = [0, 0, 0]\nup = [0, 1, 0]\nvfov_deg = 45\n\
         [light]\ntype = \"point\"\ncenter = [0, 4, 0]\n\
         [[meshes]]\nobj = \"models/no\\nsuch.obj\"\n",
    )
    .unwrap();
    let run = render("newline", &[&[scene.to_str().unwrap()], SMALL].concat());
    assert_bad_input("newline in path", &run, "newline.toml", &["no\\nsuch.obj"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Argument syntax errors are clap's (usage text on several lines), but they still exit with
/// status 2 and write nothing.
#[test]
fn argument_syntax_errors_exit_2_without_output() {
    for args in [
        &["single-quad", "--width", "abc"][..],
        &["single-quad", "--no-such-flag"],
    ] {
        let (output, out) = render("syntax", args);
        assert_eq!(output.status.code(), Some(2), "{args:?}");
        assert!(!out.exists(), "{args:?}: wrote {}", out.display());
    }
}

#[test]
fn small_render_writes_every_documented_output() {
    let (output, out) = render(
        "ok",
        &[
            "single-quad",
            "--width",
            "32",
            "--height",
            "32",
            "--methods",
            "hard-sv",
        ],
    );
    assert_eq!(
        output.status.code(),
        Some(0),
        "stderr: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let dir = out.join("hard-sv");
    let mut documented = [
        "image.png",
        "visibility.png",
        "visibility.exr",
        "visibility.pfm",
        "stats.json",
        "stencil.png",
    ];
    for f in documented {
        let len = std::fs::metadata(dir.join(f))
            .unwrap_or_else(|e| panic!("{f}: {e}"))
            .len();
        assert!(len > 0, "{f} is empty");
    }
    // Nothing else: buffer dumps beyond the stencil only with --dump-buffers.
    documented.sort();
    assert_eq!(entries(&dir), documented);
    let stats: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("stats.json")).unwrap()).unwrap();
    assert_eq!(stats["scene"], "single-quad");
    assert_eq!(
        stats["version"],
        concat!("penumbra ", env!("CARGO_PKG_VERSION"))
    );
    assert!(
        stats["plan"]["settings"].is_object(),
        "the options in force"
    );
    for key in [
        "method",
        "width",
        "height",
        "wall_seconds",
        "plan",
        "passes",
    ] {
        assert!(
            stats.get(key).is_some(),
            "stats.json lacks {key:?}: {stats}"
        );
    }
    assert_eq!(stats["method"], "hard-sv");
    assert!(stats["error"].is_null(), "no reference ran: {stats}");
    assert!(stats["error_note"]
        .as_str()
        .unwrap()
        .contains("add raycast"));
    assert!(!dir.join("error.png").exists());
    assert_eq!(stats["width"], 32);
    assert_eq!(stats["height"], 32);
    let passes = stats["passes"].as_array().expect("passes is an array");
    assert!(!passes.is_empty());
    for p in passes {
        for key in ["name", "wall_seconds", "counters"] {
            assert!(p.get(key).is_some(), "pass lacks {key:?}: {p}");
        }
        assert!(p["counters"].is_object(), "{p}");
    }
    // Beside the method folders: the memory the render was estimated to need and what it
    // took (the process's own high-water mark, read on Linux), which must not exceed it.
    let record: penumbra::memory::MemoryRecord =
        serde_json::from_slice(&std::fs::read(out.join(penumbra::memory::RECORD_FILE)).unwrap())
            .unwrap();
    let scene = penumbra::scene::builtin::load("single-quad").unwrap();
    let scene = penumbra::experiment::sized(scene, 32);
    assert_eq!(
        record.estimate_bytes,
        penumbra::memory::estimate(&scene, &["hard-sv".to_string()])
    );
    if cfg!(target_os = "linux") {
        let peak = record.peak_resident_bytes.expect("VmHWM is read on Linux");
        assert!(
            peak > 1 << 20 && peak <= record.estimate_bytes,
            "{record:?}"
        );
    }
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn list_prints_scenes_and_methods_one_per_line() {
    let output = penumbra(&["list"]);
    assert_eq!(output.status.code(), Some(0));
    let stdout = String::from_utf8(output.stdout).unwrap();
    let lines: Vec<&str> = stdout.lines().collect();
    for name in penumbra::scene::builtin::names() {
        assert!(lines.contains(name), "list lacks scene {name}: {stdout}");
    }
    for m in penumbra::methods::names() {
        assert!(lines.contains(&m), "list lacks method {m}: {stdout}");
    }
}

/// A fresh directory holding `scene.toml` whose mesh is `obj` (relative to it) under a point
/// light; returns the directory and the scene path.
fn scene_with_obj(tag: &str, obj: &str) -> (PathBuf, PathBuf) {
    let dir = fresh_out(tag);
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("scene.toml");
    std::fs::write(
        &scene,
        format!(
            "[camera]\neye = [0, 2, 5]\ntarget = [0, 0, 0]\nup = [0, 1, 0]\nvfov_deg = 45\n\
             [light]\ntype = \"point\"\ncenter = [0, 4, 0]\n[[meshes]]\nobj = \"{obj}\"\n"
        ),
    )
    .unwrap();
    (dir, scene)
}

/// An OBJ that is a device, a symlink to one, or a FIFO is refused before it is opened (one
/// rule for every input file): it would never end, or block forever.
#[cfg(unix)]
#[test]
fn special_files_as_inputs_are_refused() {
    let (dir, scene) = scene_with_obj("devzero", "zero.obj");
    std::os::unix::fs::symlink("/dev/zero", dir.join("zero.obj")).unwrap();
    let run = render("devzero", &[&[scene.to_str().unwrap()], SMALL].concat());
    assert_bad_input(
        "/dev/zero OBJ",
        &run,
        "zero.obj",
        &["is a character device"],
    );

    let (dir2, scene2) = scene_with_obj("fifo", "pipe.obj");
    let made = Command::new("mkfifo")
        .arg(dir2.join("pipe.obj"))
        .status()
        .expect("mkfifo");
    assert!(made.success());
    let run = render("fifo", &[&[scene2.to_str().unwrap()], SMALL].concat());
    assert_bad_input("FIFO OBJ", &run, "pipe.obj", &["is a FIFO"]);

    let run = render("dir-scene", &[&["scenes/bad"], SMALL].concat());
    assert_bad_input(
        "directory as scene",
        &run,
        "scenes/bad",
        &["is a directory"],
    );
    for d in [dir, dir2] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

/// A very long path in a scene file is shortened in the message, which says so.
#[test]
fn long_paths_are_shortened() {
    let long = format!("{}.obj", "d/".repeat(500_000));
    let (dir, scene) = scene_with_obj("long", &long);
    let run = render("long", &[&[scene.to_str().unwrap()], SMALL].concat());
    assert_bad_input("long path", &run, "scene.toml", &["characters, shortened]"]);
    assert!(run.0.stderr.len() < 4000, "{} bytes", run.0.stderr.len());
    std::fs::remove_dir_all(dir).unwrap();
}

/// `--dump-buffers` acts on render, report and the default run; elsewhere it is refused as
/// bad input, and with a bad option it writes nothing, like any bad input.
#[test]
fn dump_buffers_where_it_cannot_act_and_with_bad_input() {
    for args in [
        &["list", "--dump-buffers"][..],
        &["golden", "--dump-buffers"],
        &[
            "experiment",
            "tile-size",
            "cube-of-spheres-sphere",
            "--dump-buffers",
        ],
    ] {
        let o = penumbra(args);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.contains("--dump-buffers"), "{args:?}: {stderr}");
        assert!(o.stdout.is_empty(), "{args:?}");
    }
    let bad = render(
        "dump-bad",
        &["single-quad", "--dump-buffers", "--opt", "ssv.vbuffer=f64"],
    );
    assert_bad_input(
        "--dump-buffers with a bad option",
        &bad,
        "--opt ssv.vbuffer=f64",
        &["vbuffer"],
    );
}

#[test]
fn thread_count_is_bounded() {
    for n in ["0", "20000"] {
        let (output, out) = render("threads", &["single-quad", "--threads", n]);
        assert_bad_input(
            "--threads",
            &(output, out),
            &format!("--threads: {n}"),
            &["expected 1..=1024 worker threads"],
        );
    }
}

/// An image too large for the memory limit is refused before anything is allocated, naming
/// the size, the estimate and the limit.
#[test]
fn memory_limit_refuses_large_images() {
    let big = [
        "single-quad",
        "--width",
        "4096",
        "--height",
        "4096",
        "--methods",
        "hard-sv",
        "--max-memory",
        "1G",
    ];
    let run = render("memory", &big);
    assert_bad_input(
        "memory limit",
        &run,
        "single-quad",
        &[
            "4096×4096 with hard-sv needs an estimated 1728.0 MiB, more than the memory limit \
           of 1024.0 MiB (--max-memory)",
        ],
    );
    let run = render("memory-arg", &["single-quad", "--max-memory", "lots"]);
    assert_bad_input(
        "bad --max-memory",
        &run,
        "--max-memory",
        &["expected bytes"],
    );
    let (output, out) = render(
        "memory-ok",
        &[&["single-quad", "--max-memory", "200M"], SMALL].concat(),
    );
    assert_eq!(output.status.code(), Some(0), "{output:?}");
    std::fs::remove_dir_all(out).unwrap();
}

/// A file where a method's folder should be: the error names it, and no method's output of
/// this run is left behind (the outputs are staged and moved into place together).
#[test]
fn output_write_errors_name_the_path_and_leave_nothing() {
    let out = fresh_out("blocked");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("hard-sv"), "in the way").unwrap();
    let mut args: Vec<&str> = "render single-quad --width 32 --height 32 \
                               --methods raycast,hard-sv --opt raycast.samples=4 --out"
        .split_whitespace()
        .collect();
    args.push(out.to_str().unwrap());
    let output = penumbra(&args);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert_eq!(
        stderr.trim_end(),
        format!(
            "penumbra: {}: cannot write outputs: exists and is not a directory",
            out.join("hard-sv").display()
        )
    );
    assert_eq!(entries(&out), ["hard-sv"]);
    std::fs::remove_dir_all(&out).unwrap();
}

/// Coordinates far from the origin render, with one warning line on stderr naming the
/// rounding and the scene's size.
#[test]
fn far_coordinates_warn_on_stderr() {
    let dir = fresh_out("far");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("far.toml");
    let models = root().join("scenes/models");
    std::fs::write(
        &scene,
        format!(
            "[camera]\neye = [40000, 2.5, 4]\ntarget = [40000, 0.4, 0]\nup = [0, 1, 0]\n\
             vfov_deg = 45\n[light]\ntype = \"point\"\ncenter = [40000.5, 3.5, 0.3]\n\
             [[meshes]]\nobj = \"{0}/cube.obj\"\n\
             transform = [6,0,0,0, 0,0.1,0,0, 0,0,6,0, 40000,-0.05,0,1]\n\
             [[meshes]]\nobj = \"{0}/tetra.obj\"\n\
             transform = [1,0,0,0, 0,1,0,0, 0,0,1,0, 40000,0.6,0,1]\n",
            models.display()
        ),
    )
    .unwrap();
    let (output, out) = render("far-out", &[&[scene.to_str().unwrap()], SMALL].concat());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(0), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("far.toml: warning: coordinates up to 40003 are stored as f32")
            && stderr.contains("warned above 1e-4"),
        "{stderr}"
    );
    std::fs::remove_dir_all(out).unwrap();
    std::fs::remove_dir_all(dir).unwrap();
}

/// With the reference in the run, every other method writes `error.png` (the signed error
/// map, as big as the image) and its error in `stats.json`, whole image and penumbra only;
/// the reference writes its noise floor. The numbers are the table's.
#[test]
fn a_run_with_the_reference_writes_error_maps_and_metrics() {
    let (output, out) = render(
        "errors",
        &[
            "single-quad",
            "--width",
            "32",
            "--height",
            "32",
            "--methods",
            "raycast,hard-sv",
        ],
    );
    assert_eq!(output.status.code(), Some(0));
    let stats = |m: &str| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(out.join(m).join("stats.json")).unwrap()).unwrap()
    };
    let hard = stats("hard-sv");
    let e = &hard["error"];
    assert_eq!(e["reference"], "raycast");
    assert_eq!(e["pixels"], 32 * 32);
    let penumbra = e["penumbra_only"]["pixels"].as_u64().unwrap();
    assert!(penumbra > 0 && penumbra < 32 * 32, "{e}");
    // A hard shadow is wrong only in the penumbra, so its penumbra-only error is larger.
    assert!(
        e["penumbra_only"]["mean_abs"].as_f64() > e["mean_abs"].as_f64(),
        "{e}"
    );
    let table = String::from_utf8_lossy(&output.stdout);
    let row = table.lines().find(|l| l.starts_with("hard-sv")).unwrap();
    assert!(
        row.contains(&format!("{:.5}", e["rmse"].as_f64().unwrap())),
        "{row} vs {e}"
    );
    let png = image::open(out.join("hard-sv").join("error.png")).unwrap();
    assert_eq!((png.width(), png.height()), (32, 32));
    let reference = stats("raycast");
    assert!(reference["error"].is_null());
    assert!(reference["reference_noise_floor"]["pixels"].as_u64() == Some(32 * 32));
    assert!(!out.join("raycast").join("error.png").exists());
    std::fs::remove_dir_all(&out).unwrap();
}

/// `stats.json`'s error holds the split by the receiver's horizon (issue 28): on
/// `cube-of-spheres` the spheres' terminators are horizon receivers and the floor sees the
/// whole light; the three classes count exactly the pixels that show a surface, the percentage
/// and the share follow from the counts and means, and the table prints the same numbers.
#[test]
fn stats_json_splits_the_error_into_whole_light_and_horizon_receivers() {
    let (output, out) = render(
        "horizon-split",
        &[
            "cube-of-spheres",
            "--width",
            "32",
            "--height",
            "32",
            "--methods",
            "raycast,hard-sv",
        ],
    );
    assert_eq!(output.status.code(), Some(0));
    let stats: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("hard-sv/stats.json")).unwrap()).unwrap();
    let e = &stats["error"];
    let split = &e["horizon_split"];
    let count = |class: &str| split[class]["pixels"].as_u64().unwrap();
    let (whole, horizon, away) = (count("whole_light"), count("horizon"), count("facing_away"));
    // The pixels that show a surface, counted from the scene pass.
    let scene = penumbra::experiment::sized(
        penumbra::scene::builtin::load("cube-of-spheres").unwrap(),
        32,
    );
    let frame =
        penumbra::frame::Frame::render(&scene, penumbra::render::gpu_settings(&scene).unwrap())
            .unwrap();
    let surface = frame.receivers().iter().filter(|r| r.is_some()).count() as u64;
    assert_eq!(whole + horizon + away, surface, "{split}");
    assert!(horizon > 0 && whole > horizon, "{split}");
    let pixels = e["pixels"].as_u64().unwrap();
    assert_eq!(
        split["horizon_pct"].as_f64().unwrap(),
        100.0 * horizon as f64 / pixels as f64
    );
    let mean = |v: &serde_json::Value| v["mean_abs"].as_f64().unwrap();
    let share = mean(&split["horizon"]) * horizon as f64 / (mean(e) * pixels as f64);
    assert_eq!(split["horizon_share"].as_f64().unwrap(), share);
    // A hard shadow errs on the spheres' terminators far more than on the floor.
    assert!(
        mean(&split["horizon"]) > mean(&split["whole_light"]),
        "{split}"
    );
    let table = String::from_utf8_lossy(&output.stdout);
    let row = table.lines().find(|l| l.starts_with("hard-sv")).unwrap();
    for v in [mean(&split["whole_light"]), mean(&split["horizon"])] {
        assert!(row.contains(&format!("{v:.5}")), "{row} vs {split}");
    }
    std::fs::remove_dir_all(&out).unwrap();
}

/// `penumbra golden` outside the repository refuses (exit 2, one line naming the directory)
/// and writes nothing where it was run: before, `--bless` wrote a whole golden tree into the
/// current directory and then failed.
#[test]
fn golden_outside_the_repository_refuses_and_writes_nothing() {
    let dir = fresh_out("golden-elsewhere");
    std::fs::create_dir_all(&dir).unwrap();
    for args in [&["golden"][..], &["golden", "--bless"][..]] {
        let output = Command::new(env!("CARGO_BIN_EXE_penumbra"))
            .args(args)
            .current_dir(&dir)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(
            stderr.contains("golden: not the golden directory of a penumbra repository"),
            "{stderr}"
        );
        assert!(
            entries(&dir).is_empty(),
            "{args:?} wrote {:?}",
            entries(&dir)
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--width` alone keeps the scene's aspect ratio (the height follows), as users expect.
#[test]
fn width_alone_keeps_the_aspect_ratio() {
    let scene = penumbra::scene::builtin::load("cube-of-spheres").unwrap();
    let (output, out) = render(
        "aspect",
        &["cube-of-spheres", "--width", "40", "--methods", "hard-sv"],
    );
    assert_eq!(output.status.code(), Some(0));
    let stats: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("hard-sv/stats.json")).unwrap()).unwrap();
    let expected = (40.0 * f64::from(scene.height) / f64::from(scene.width)).round();
    assert_eq!(stats["width"], 40);
    assert_eq!(stats["height"].as_f64(), Some(expected));
    std::fs::remove_dir_all(&out).unwrap();
}

/// Without `--out`, `render` writes `out/SCENE/METHOD/` in the current directory: SCENE is the
/// built-in name or the scene file's stem, so two scenes never share a folder.
#[test]
fn render_without_out_writes_out_scene_method() {
    let dir = fresh_out("default-layout");
    std::fs::create_dir_all(&dir).unwrap();
    let scene_file = root().join("scenes/receiver-only-floor.toml");
    for scene in ["single-quad", scene_file.to_str().unwrap()] {
        let output = Command::new(env!("CARGO_BIN_EXE_penumbra"))
            .args(["render", scene, "--methods", "hard-sv", "--width", "16"])
            .current_dir(&dir)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(0), "{stderr}");
    }
    for folder in ["single-quad", "receiver-only-floor"] {
        let image = dir.join("out").join(folder).join("hard-sv/image.png");
        assert!(image.is_file(), "{} missing", image.display());
    }
    assert_eq!(
        entries(&dir.join("out")).len(),
        2,
        "{:?}",
        entries(&dir.join("out"))
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
