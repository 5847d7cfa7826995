//! Scene loading end to end: every shipped scene file loads and validates, every built-in
//! scene validates, and every file in `scenes/bad/` fails with the expected one-line error
//! naming the file and the problem.

use penumbra::scene::file::{load_scene_file, resolve};
use penumbra::scene::validate::validate;
use penumbra::scene::{builtin, LightShape};
use std::path::{Path, PathBuf};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

/// The `.toml` and `.json` files directly in `dir`, sorted.
fn scene_files(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            matches!(
                p.extension().and_then(|e| e.to_str()),
                Some("toml" | "json")
            )
        })
        .collect();
    files.sort();
    files
}

#[test]
fn every_scene_file_loads() {
    let files = scene_files(&scenes_dir());
    assert!(
        files.len() >= 3,
        "expected at least 3 scene files, found {files:?}"
    );
    let mut json = 0;
    for path in &files {
        let scene = load_scene_file(path).unwrap_or_else(|e| panic!("{e}"));
        validate(&scene).unwrap();
        assert_eq!(scene.source, path.display().to_string());
        assert!(
            scene.meshes.len() >= 2,
            "{}: a floor and an occluder",
            path.display()
        );
        json += usize::from(path.extension().unwrap() == "json");
        // resolve() accepts the same path.
        assert_eq!(resolve(path.to_str().unwrap()).unwrap(), scene);
    }
    assert!(json >= 1, "at least one JSON scene");
}

#[test]
fn shipped_scenes_cover_light_types() {
    let mut kinds: Vec<&str> = scene_files(&scenes_dir())
        .iter()
        .map(|p| load_scene_file(p).unwrap().light().shape.type_name())
        .collect();
    kinds.sort();
    kinds.dedup();
    for k in ["rect", "sphere", "disk", "textured_rect"] {
        assert!(
            kinds.contains(&k),
            "no shipped scene with a {k} light: {kinds:?}"
        );
    }
}

#[test]
fn every_builtin_validates() {
    assert!(builtin::names().contains(&builtin::DEFAULT));
    for &name in builtin::names() {
        let scene = builtin::load(name).unwrap();
        validate(&scene).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(resolve(name).unwrap(), scene);
    }
    let err = resolve("no-such-scene").unwrap_err().to_string();
    for &name in builtin::names() {
        assert!(err.contains(name), "{err}");
    }
}

/// Loads `scenes/bad/NAME` and returns the error as the CLI prints it.
fn bad(name: &str) -> String {
    let path = scenes_dir().join("bad").join(name);
    let err = load_scene_file(&path).expect_err(name).to_string();
    assert!(!err.contains('\n'), "error must be one line: {err}");
    assert!(
        err.starts_with(&path.display().to_string()),
        "error must name the file: {err}"
    );
    err
}

fn assert_contains(err: &str, parts: &[&str]) {
    for p in parts {
        assert!(err.contains(p), "expected {p:?} in: {err}");
    }
}

#[test]
fn malformed_toml() {
    assert_contains(
        &bad("malformed.toml"),
        &["malformed.toml: line 7, column 1: invalid array; expected `]`"],
    );
}

#[test]
fn missing_obj() {
    assert_contains(
        &bad("missing-obj.toml"),
        &[
            "missing-obj.toml: meshes[1] (",
            "models/does-not-exist.obj): cannot read OBJ file: ",
        ],
    );
}

#[test]
fn open_mesh() {
    assert_contains(
        &bad("open-mesh.toml"),
        &[
            "open-mesh.toml: meshes[1] (",
            "open-box.obj): open mesh: edge ",
            "has only one triangle",
        ],
    );
}

#[test]
fn nan_vertex() {
    assert_contains(
        &bad("nan-vertex.toml"),
        &[
            "nan-vertex.toml: meshes[1] (",
            "models/nan-vertex.obj): OBJ parse error at line 5: vertex 4 is not finite: \
             (0, NaN, 0) (line reads \"v 0 nan 0\")",
        ],
    );
}

#[test]
fn nan_light() {
    assert_contains(
        &bad("nan-light.toml"),
        &["nan-light.toml: light.center: (0.5, NaN, 0.3) is not finite"],
    );
}

#[test]
fn zero_light() {
    assert_contains(
        &bad("zero-light.toml"),
        &["zero-light.toml: light.u: is the zero vector (zero-size light)"],
    );
}

#[test]
fn unknown_method_loads_and_is_left_to_the_registry() {
    let scene = load_scene_file(&scenes_dir().join("bad/unknown-method.toml")).unwrap();
    assert_eq!(scene.methods, Some(vec!["no-such-method".to_string()]));
    assert!(matches!(scene.light().shape, LightShape::Rect { .. }));
}

#[test]
fn unknown_extension() {
    let err = load_scene_file(&scenes_dir().join("models/cube.obj"))
        .unwrap_err()
        .to_string();
    assert_contains(&err, &["cube.obj: unknown scene file extension"]);
}

#[test]
fn light_overlapping_a_mesh() {
    assert_contains(
        &bad("light-overlaps-mesh.toml"),
        &[
            "light-overlaps-mesh.toml: light: light intersects geometry: the sphere light around \
             (0, 1.7, 0) overlaps meshes[1] (",
            "tetra.obj): its triangle ",
        ],
    );
}

#[test]
fn top_level_json_array() {
    assert_contains(
        &bad("top-level-array.json"),
        &[
            "top-level-array.json: the top level must be a JSON object ({...}) holding the \
           scene, not an array",
        ],
    );
}

#[test]
fn a_directory_is_not_a_scene_file() {
    let dir = scenes_dir().join("bad");
    let err = resolve(dir.to_str().unwrap()).unwrap_err().to_string();
    assert_eq!(
        err,
        format!(
            "{}: cannot read scene file: is a directory, not a file",
            dir.display()
        )
    );
}

/// A scene in a fresh temporary folder: a floor (the unit cube flattened) and one mesh from
/// `obj` (an absolute path) with the extra mesh keys `keys`, lit by a rectangle from above.
fn repair_scene(obj: &Path, keys: &str, size: u32, methods: &str) -> PathBuf {
    repair_scene_lit(obj, keys, size, methods, RECT_LIGHT)
}

/// The light of [`repair_scene`]: a rectangle above the floor.
const RECT_LIGHT: &str =
    "type = \"rect\"\ncenter = [0.5, 3.5, 0.3]\nu = [0.4, 0, 0]\nv = [0, 0, 0.4]";
/// A sphere light where [`RECT_LIGHT`] is, for the methods of Papers I, II and Wyman & Hansen.
const SPHERE_LIGHT: &str = "type = \"sphere\"\ncenter = [0.5, 3.5, 0.3]\nradius = 0.3";
/// A disk light facing down where [`RECT_LIGHT`] is, for the D-buffer (CGI 2004).
const DISK_LIGHT: &str =
    "type = \"disk\"\ncenter = [0.5, 3.5, 0.3]\nradius = 0.3\nnormal = [0, -1, 0]";

/// [`repair_scene`] under `light` (the TOML keys of the `[light]` table).
fn repair_scene_lit(obj: &Path, keys: &str, size: u32, methods: &str, light: &str) -> PathBuf {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("penumbra-repair-{}-{n}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cube = scenes_dir().join("models/cube.obj");
    let text = format!(
        r#"width = {size}
height = {size}
{methods}
[camera]
eye = [0.0, 2.5, 4.0]
target = [0.0, 0.4, 0.0]
up = [0, 1, 0]
vfov_deg = 45
[light]
{light}
[[meshes]]
obj = {cube:?}
transform = [6, 0, 0, 0,   0, 0.1, 0, 0,   0, 0, 6, 0,   0, -0.05, 0, 1]
[[meshes]]
obj = {obj:?}
{keys}
"#
    );
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// The real spider model (assimp's test model, corners duplicated per group, holes, some
/// flipped faces) loads with its repairs counted and named, and renders.
#[test]
fn a_real_model_is_repaired_and_reported() {
    let spider = scenes_dir().join("models/spider.obj");
    let keys = "scale = 0.01\ntranslate = [0, 0.45, 0]";
    let path = repair_scene(&spider, keys, 32, "methods = [\"hard-sv\", \"ssv\"]");
    let scene = load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
    let r = &scene.meshes[1].repairs;
    let notes = penumbra::scene::repair::repair_notes(&scene);
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert_eq!(
        notes[0],
        format!(
            "meshes[1] ({}): {}",
            spider.display(),
            "dropped 56 degenerate triangles, flipped 4 triangles to agree with their \
             neighbours, closed 6 holes with 60 triangles"
        )
    );
    assert_eq!(scene.meshes[0].repairs.summary(), None);
    // tobj's welding (scene/obj.rs) already joined the corners; 72 boundary edges in 6 loops.
    assert_eq!(r.degenerate_dropped, 56);
    assert_eq!(r.boundary_edges, 72);
    assert_eq!(r.became, "closed (6 holes capped)");
    let runs = penumbra::render::render_scene(&scene).unwrap();
    assert_eq!(runs.len(), 2);
    for run in &runs {
        let stats = &run.output.stats;
        assert_eq!(stats.meshes.len(), 2);
        assert_eq!(stats.meshes[1].repairs, *r);
        assert_eq!(
            stats.meshes[1].triangles,
            scene.meshes[1].triangles.len() as u64
        );
    }
    let notes = penumbra::render::table_notes(&scene, &runs);
    assert!(notes.contains(&format!(
        "warning: {}",
        penumbra::scene::repair::repair_notes(&scene)[0]
    )));
}

/// The mean |visibility − raycast| of each method of a 48×48 render of `path`, with every
/// value finite and in [0, 1].
fn errors_against_raycast(path: &Path) -> Vec<(String, f64)> {
    let scene = load_scene_file(path).unwrap_or_else(|e| panic!("{e}"));
    let runs = penumbra::render::render_scene(&scene).unwrap();
    let mut out = Vec::new();
    for run in &runs {
        let values: Vec<f32> = match &run.output.visibility {
            penumbra::visibility::Visibility::Gray(v) => v.clone(),
            penumbra::visibility::Visibility::Rgb(v) => v.iter().flatten().copied().collect(),
        };
        assert!(
            values
                .iter()
                .all(|v| v.is_finite() && (0.0..=1.0).contains(v)),
            "{}: {}",
            path.display(),
            run.method
        );
        if let Some(e) = &run.error {
            out.push((run.method.clone(), e.all.mean_abs));
        }
    }
    out
}

/// A box without its top face, rendered by every method, under a rectangle, a sphere and a
/// disk light: capped (`open = "close"`) it is the closed box again, so each method's mean
/// error against raycast matches its error on the closed box within 0.002 (what a different
/// triangulation of the cap can move); as a two-sided shell (`open = "shell"`) the methods
/// see a surface that folds at the rim, and each one's mean error stays within 0.05 of its
/// error on the closed box (the V-buffer methods' overlap where the shell folds,
/// docs/mesh-repair.md). Every method of the registry runs under one of the lights.
#[test]
fn a_mesh_with_a_hole_renders_with_every_method() {
    let open_box = scenes_dir().join("bad/models/open-box.obj");
    let closed_box = scenes_dir().join("models/cube.obj");
    let mut seen: Vec<String> = vec![penumbra::methods::REFERENCE.into()];
    for light in [RECT_LIGHT, SPHERE_LIGHT, DISK_LIGHT] {
        // Both span [−0.4, 0.4] × [0.4, 1.2] × [−0.4, 0.4] (cube.obj is centred,
        // open-box.obj spans [0, 1]³).
        let place = "scale = 0.8\ntranslate = [0, 0.8, 0]";
        let closed = errors_against_raycast(&repair_scene_lit(&closed_box, place, 48, "", light));
        let place = "scale = 0.8\ntranslate = [-0.4, 0.4, -0.4]";
        seen.extend(closed.iter().map(|(m, _)| m.clone()));
        for (open, bound) in [("close", 0.002), ("shell", 0.05)] {
            let keys = format!("{place}\nopen = \"{open}\"");
            let repaired =
                errors_against_raycast(&repair_scene_lit(&open_box, &keys, 48, "", light));
            assert_eq!(repaired.len(), closed.len());
            for ((m, e), (m0, e0)) in repaired.iter().zip(&closed) {
                assert_eq!(m, m0);
                assert!(
                    (e - e0).abs() <= bound,
                    "{light}: open = {open}: {m}: mean error {e} vs {e0} on the closed box"
                );
            }
        }
    }
    for m in penumbra::methods::names() {
        assert!(
            seen.iter().any(|s| s == m),
            "{m} ran under none of the lights"
        );
    }
}

/// A closed unit cube as PLY (binary), STL (binary: every facet its own corners, welded
/// bit-identically into 8 vertices) and GLB, each named with `mesh = "..."` in a 32×32 scene,
/// loads into the same mesh as the OBJ cube and renders with `hard-sv` to the same image.
#[test]
fn mesh_formats_render_like_the_obj() {
    let dir = scenes_dir();
    let scene_with = |file: &str| {
        let text = format!(
            r#"width = 32
height = 32
methods = ["hard-sv"]
[camera]
eye = [0.0, 2.5, 4.0]
target = [0.0, 0.4, 0.0]
up = [0, 1, 0]
vfov_deg = 45
[light]
type = "point"
center = [0.5, 3.5, 0.3]
[[meshes]]
mesh = "models/cube.obj"
transform = [6, 0, 0, 0,   0, 0.1, 0, 0,   0, 0, 6, 0,   0, -0.05, 0, 1]
[[meshes]]
mesh = "models/{file}"
translate = [0, 0.6, 0]
rotate_deg = [0, 30, 0]
"#
        );
        penumbra::scene::file::parse_scene_str(
            &text,
            penumbra::scene::file::Format::Toml,
            file,
            &dir,
        )
        .unwrap_or_else(|e| panic!("{e}"))
    };
    let obj = scene_with("cube.obj");
    assert_eq!(obj.meshes[1].positions.len(), 8);
    assert_eq!(obj.meshes[1].triangles.len(), 12);
    let obj_runs = penumbra::render::render_scene(&obj).unwrap();
    for file in ["cube.ply", "cube.stl", "cube.glb"] {
        let s = scene_with(file);
        // The same triangles in the same order, each turned to start at its lowest corner
        // (which keeps its winding): vertex numbering differs (OBJ numbers by first use).
        let corners = |m: &penumbra::scene::Mesh| -> Vec<[[u32; 3]; 3]> {
            m.triangles
                .iter()
                .map(|t| {
                    let c = t.map(|i| m.positions[i as usize].to_array().map(f32::to_bits));
                    let k = (0..3).min_by_key(|&k| c[k]).unwrap();
                    [c[k], c[(k + 1) % 3], c[(k + 2) % 3]]
                })
                .collect()
        };
        let (a, b) = (&s.meshes[1], &obj.meshes[1]);
        assert_eq!(a.positions.len(), 8, "{file}");
        assert_eq!(corners(a), corners(b), "{file}");
        let runs = penumbra::render::render_scene(&s).unwrap();
        assert_eq!(runs.len(), 1);
        assert_eq!(runs[0].method, "hard-sv");
        assert_eq!(runs[0].shaded, obj_runs[0].shaded, "{file}");
    }
}

/// A mesh kept as a two-sided shell is warned about by the methods that sum per silhouette
/// edge (their coverage is summed twice there) and only by them; capped, by none.
#[test]
fn a_shell_is_warned_about_by_the_methods_that_sum_per_silhouette_edge() {
    let open_box = scenes_dir().join("bad/models/open-box.obj");
    for (open, warned) in [("shell", true), ("close", false)] {
        let keys = format!("scale = 0.8\ntranslate = [-0.4, 0.4, -0.4]\nopen = \"{open}\"");
        let path = repair_scene(
            &open_box,
            &keys,
            16,
            "methods = [\"hard-sv\", \"nsample\", \"ssv\", \"wedge-blending\"]",
        );
        let scene = load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
        for run in penumbra::render::render_scene(&scene).unwrap() {
            let sums = penumbra::methods::find(&run.method)
                .unwrap()
                .sums_per_silhouette_edge;
            let shell_warning = run
                .output
                .stats
                .warnings
                .iter()
                .any(|w| w.contains("kept as a two-sided shell"));
            assert_eq!(shell_warning, warned && sums, "{open}: {}", run.method);
        }
    }
    assert!(
        penumbra::methods::find("ssv")
            .unwrap()
            .sums_per_silhouette_edge
    );
    assert!(
        !penumbra::methods::find("hard-sv")
            .unwrap()
            .sums_per_silhouette_edge
    );
}
