//! Scene files: one schema, written as TOML (`.toml`) or JSON (`.json`).
//!
//! ```toml
//! width = 256                 # optional, default 256
//! height = 256                # optional, default 256
//! ambient = 0.15              # optional, default 0.15
//! methods = ["hard-sv", "nsample"]   # optional, default: every method for the light shape
//!
//! [camera]
//! eye = [0, 2, 5]
//! target = [0, 0, 0]
//! up = [0, 1, 0]
//! vfov_deg = 45
//! near = 0.1                  # optional
//!
//! [light]
//! type = "rect"               # point | sphere | disk | rect | textured_rect
//! center = [0, 4, 0]
//! u = [0.5, 0, 0]             # rect, textured_rect: half-extent vectors
//! v = [0, 0, 0.5]
//! radius = 0.5                # sphere, disk
//! normal = [0, -1, 0]         # disk (used as written, not normalized)
//! texture = "fire.png"        # textured_rect, relative to the scene file, sRGB → linear
//!
//! # Several lights (Paper I §7): instead of [light], one [[lights]] table per light,
//! # each with the fields of [light]; errors name `lights[K].<field>`.
//!
//! [[meshes]]
//! mesh = "models/bunny.ply"   # relative to the scene file: .obj .ply .stl .gltf .glb
//! # obj = "models/bunny.obj"  # the older key, the same thing; give exactly one of the two
//! transform = [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]   # optional, column-major, affine
//! # or instead of transform, its parts (each optional; scaled, then rotated, then moved):
//! # scale = 2.0 or [sx, sy, sz]; rotate_deg = [x, y, z] (Euler angles in degrees about the
//! # world axes, X first, then Y, then Z); translate = [tx, ty, tz]
//! color = [0.8, 0.8, 0.8]     # optional, linear RGB albedo
//! receiver_only = true        # optional: casts no shadow in any method, may be open
//! # Repair (docs/mesh-repair.md; every repair is reported): all optional.
//! weld = true                 # merge corners at equal positions (default true)
//! weld_tolerance = 1e-6       # also within this fraction of the bounding-box diagonal (default 0)
//! open = "close"              # open parts: "close" (cap the holes), "shell" (two-sided
//!                             # surface) or "refuse"; default: close where every hole
//!                             # ear-clips, else shell
//!
//! [options.nsample]           # per-method options, checked later by each method
//! n = 256
//! ```
//!
//! A mesh file is read by [`read_mesh`] (format by extension, case-insensitive; what each
//! format accepts is in `docs/mesh-formats.md`), moved by its transform
//! ([`RawMesh::transformed`](super::mesh_io::RawMesh::transformed)) and repaired
//! ([`repair`], which welds its bit-identical corners); validation then requires it closed.
//! A load that takes longer than a second (a model of a million triangles) shows a progress
//! bar on a terminal's stderr, one step per mesh read, mesh repaired and the validation
//! ([`Progress::delayed`]).
//!
//! Unknown keys anywhere are errors (`deny_unknown_fields`), as are light fields that do not
//! belong to the chosen light type and missing ones that do (the error names `light.<field>`),
//! and a scene with both `light` and `lights`, with neither, or with more than
//! [`crate::limits::MAX_LIGHTS`] lights.
//! Option values must be scalars (integer, float, bool, string). Every error is one line
//! naming the file, and for syntax and schema errors the line and column.

use super::input_file::read_input_file;
use super::mesh_io::{check_transform, read_mesh, MeshFormat};
use super::repair::{repair, OpenTreatment, RepairOptions};
use super::validate::validate;
use super::{builtin, Camera, Light, LightShape, Mesh, OptionValue, RawOptions, RgbTexture, Scene};
use crate::error::InputError;
use crate::limits::MAX_LIGHTS;
use crate::progress::Progress;
use glam::{DMat4, DVec3, Mat4, Vec3};
use serde::de::{self, IgnoredAny, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer};
use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;
use std::time::Duration;

/// The syntax a scene file is written in; both share one schema.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// TOML (`.toml`).
    Toml,
    /// JSON (`.json`).
    Json,
}

impl Format {
    /// The format for a file name's extension (`.toml`, `.json`, case-insensitive).
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "toml" => Some(Format::Toml),
            "json" => Some(Format::Json),
            _ => None,
        }
    }
}

/// Default image edge in pixels.
const DEFAULT_SIZE: u32 = 256;
/// Default ambient term.
const DEFAULT_AMBIENT: f64 = 0.15;
/// Default mesh albedo.
const DEFAULT_COLOR: [f64; 3] = [0.8, 0.8, 0.8];

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a scene table")]
struct SceneDef {
    width: Option<u32>,
    height: Option<u32>,
    ambient: Option<f64>,
    methods: Option<Vec<String>>,
    camera: CameraDef,
    light: Option<LightDef>,
    lights: Option<Vec<LightDef>>,
    meshes: Vec<MeshDef>,
    #[serde(default)]
    options: BTreeMap<String, BTreeMap<String, RawValue>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a camera table")]
struct CameraDef {
    eye: Three,
    target: Three,
    up: Three,
    vfov_deg: f64,
    near: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a light table")]
struct LightDef {
    #[serde(rename = "type")]
    kind: String,
    center: Three,
    u: Option<Three>,
    v: Option<Three>,
    radius: Option<f64>,
    normal: Option<Three>,
    texture: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a mesh table")]
struct MeshDef {
    mesh: Option<String>,
    obj: Option<String>,
    transform: Option<Vec<f64>>,
    scale: Option<Scale>,
    rotate_deg: Option<Three>,
    translate: Option<Three>,
    color: Option<Three>,
    receiver_only: Option<bool>,
    weld: Option<bool>,
    weld_tolerance: Option<f64>,
    open: Option<String>,
}

/// `scale`: one number for all three axes, or three numbers.
#[derive(Deserialize, Clone, Copy)]
#[serde(untagged, expecting = "a number or three numbers")]
enum Scale {
    Uniform(f64),
    PerAxis(Three),
}

/// Exactly three numbers (a point, a vector or an RGB colour): a list of any other length is
/// an error, not truncated (serde's fixed-size arrays let TOML drop the extra values).
#[derive(Clone, Copy)]
struct Three([f64; 3]);

impl<'de> Deserialize<'de> for Three {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = Vec::<f64>::deserialize(d)?;
        <[f64; 3]>::try_from(v.as_slice())
            .map(Three)
            .map_err(|_| de::Error::invalid_length(v.len(), &"exactly 3 numbers"))
    }
}

/// An option value as written; arrays and tables are kept only to be reported as errors.
enum RawValue {
    Scalar(OptionValue),
    Array,
    Table,
}

impl<'de> Deserialize<'de> for RawValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RawValue;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("an integer, float, bool or string")
            }
            fn visit_bool<E: de::Error>(self, b: bool) -> Result<RawValue, E> {
                Ok(RawValue::Scalar(OptionValue::Bool(b)))
            }
            fn visit_i64<E: de::Error>(self, i: i64) -> Result<RawValue, E> {
                Ok(RawValue::Scalar(OptionValue::Int(i)))
            }
            fn visit_u64<E: de::Error>(self, u: u64) -> Result<RawValue, E> {
                i64::try_from(u)
                    .map(|i| RawValue::Scalar(OptionValue::Int(i)))
                    .map_err(|_| E::custom(format!("integer {u} is too large")))
            }
            fn visit_f64<E: de::Error>(self, x: f64) -> Result<RawValue, E> {
                Ok(RawValue::Scalar(OptionValue::Float(x)))
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<RawValue, E> {
                Ok(RawValue::Scalar(OptionValue::Str(s.to_string())))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<RawValue, A::Error> {
                while seq.next_element::<IgnoredAny>()?.is_some() {}
                Ok(RawValue::Array)
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<RawValue, A::Error> {
                while map.next_entry::<IgnoredAny, IgnoredAny>()?.is_some() {}
                Ok(RawValue::Table)
            }
        }
        d.deserialize_any(V)
    }
}

/// Loads, builds and validates the scene file at `path` (format from its extension; OBJ and
/// texture paths relative to its directory). The scene's `source` is `path` as given.
pub fn load_scene_file(path: &Path) -> Result<Scene, InputError> {
    let source = path.display().to_string();
    let bytes = read_input_file(path)
        .map_err(|m| InputError::new(&source, format!("cannot read scene file: {m}")))?;
    let format = Format::from_path(path).ok_or_else(|| {
        InputError::new(
            &source,
            "unknown scene file extension (expected .toml or .json)",
        )
    })?;
    let text = String::from_utf8(bytes).map_err(|e| {
        let (line, col) = line_col_of_bytes(e.as_bytes(), e.utf8_error().valid_up_to());
        InputError::new(
            &source,
            format!("line {line}, column {col}: not UTF-8 text"),
        )
    })?;
    let base_dir = path.parent().unwrap_or(Path::new(""));
    parse_scene_str(&text, format, &source, base_dir)
}

/// Parses scene text in `format`, loads its OBJs and texture relative to `base_dir`, and
/// validates the result; errors name `source_name`. Never panics on any input (fuzzed).
pub fn parse_scene_str(
    text: &str,
    format: Format,
    source_name: &str,
    base_dir: &Path,
) -> Result<Scene, InputError> {
    if format == Format::Json && text.trim_start().starts_with('[') {
        // serde would read an array as the scene's fields in order.
        return Err(InputError::new(
            source_name,
            "the top level must be a JSON object ({...}) holding the scene, not an array",
        ));
    }
    let def: SceneDef = match format {
        Format::Toml => toml::from_str(text).map_err(|e| toml_error(source_name, text, &e))?,
        Format::Json => serde_json::from_str(text).map_err(|e| json_error(source_name, &e))?,
    };
    // Two steps per mesh (read, repair) and validation; drawn once loading takes a second.
    let progress = Progress::delayed(
        2 * def.meshes.len() + 1,
        &format!("loading {source_name}"),
        LOAD_PROGRESS_DELAY,
    );
    let scene = build(def, source_name, base_dir, &progress)?;
    progress.start("validating");
    validate(&scene)?;
    progress.finish();
    Ok(scene)
}

/// A built-in scene name or a scene file path. Built-in names take precedence; an existing
/// path is loaded as a scene file (a directory or special file gets the error of
/// [`read_input_file`]); an argument that is neither gives an error listing the built-in scenes.
pub fn resolve(arg: &str) -> Result<Scene, InputError> {
    if let Some(scene) = builtin::load(arg) {
        return Ok(scene);
    }
    let path = Path::new(arg);
    if std::fs::metadata(path).is_ok() {
        return load_scene_file(path);
    }
    Err(InputError::new(
        arg,
        format!(
            "not a built-in scene or an existing scene file (built-in scenes: {})",
            builtin::names().join(", ")
        ),
    ))
}

/// One line from a TOML error: "line L, column C: message".
fn toml_error(source: &str, text: &str, e: &toml::de::Error) -> InputError {
    let msg = one_line(e.message());
    match e.span() {
        Some(span) => {
            let (line, col) = line_col(text, span.start);
            InputError::new(source, format!("line {line}, column {col}: {msg}"))
        }
        None => InputError::new(source, msg),
    }
}

/// One line from a serde_json error: "line L, column C: message".
fn json_error(source: &str, e: &serde_json::Error) -> InputError {
    let full = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let msg = one_line(full.strip_suffix(&suffix).unwrap_or(&full));
    if e.line() == 0 {
        InputError::new(source, msg)
    } else {
        InputError::new(
            source,
            format!("line {}, column {}: {msg}", e.line(), e.column()),
        )
    }
}

/// Joins the lines of a multi-line message with "; ".
fn one_line(s: &str) -> String {
    s.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}

/// 1-based line and column (in bytes) of byte offset `at` in `bytes`, which need not be text.
fn line_col_of_bytes(bytes: &[u8], at: usize) -> (usize, usize) {
    let before = &bytes[..at.min(bytes.len())];
    let line = before.iter().filter(|b| **b == b'\n').count() + 1;
    let col = before.iter().rev().take_while(|b| **b != b'\n').count() + 1;
    (line, col)
}

/// 1-based line and column (in characters) of byte offset `at` in `text`.
fn line_col(text: &str, at: usize) -> (usize, usize) {
    let mut at = at.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().unwrap_or("").chars().count() + 1;
    (line, col)
}

fn v3(a: Three) -> Vec3 {
    DVec3::from_array(a.0).as_vec3()
}

/// How long loading a scene runs before its progress bar appears (issue 27: "a progress bar
/// when loading takes longer than a second").
const LOAD_PROGRESS_DELAY: Duration = Duration::from_secs(1);

/// Turns the parsed definition into a scene: light fields per type, meshes (each a step of
/// `progress`), options.
fn build(
    def: SceneDef,
    source: &str,
    base_dir: &Path,
    progress: &Progress,
) -> Result<Scene, InputError> {
    let at = |object: &str, message: String| InputError::at(source, object, message);
    let camera = Camera {
        eye: DVec3::from_array(def.camera.eye.0),
        target: DVec3::from_array(def.camera.target.0),
        up: DVec3::from_array(def.camera.up.0),
        vfov_deg: def.camera.vfov_deg,
        near: def.camera.near,
    };
    let lights = build_lights(def.light, def.lights, source, base_dir)?;

    let mut meshes = Vec::with_capacity(def.meshes.len());
    for (i, m) in def.meshes.iter().enumerate() {
        meshes.push(build_mesh(m, i, source, base_dir, progress)?);
    }

    let mut options = RawOptions::new();
    for (method, table) in def.options {
        let mut out = BTreeMap::new();
        for (key, value) in table {
            match value {
                RawValue::Scalar(v) => {
                    out.insert(key, v);
                }
                RawValue::Array | RawValue::Table => {
                    return Err(at(
                        &format!("options.{method}.{key}"),
                        "must be a single integer, float, bool or string".into(),
                    ));
                }
            }
        }
        options.insert(method, out);
    }

    Ok(Scene {
        source: source.to_string(),
        width: def.width.unwrap_or(DEFAULT_SIZE),
        height: def.height.unwrap_or(DEFAULT_SIZE),
        camera,
        lights,
        meshes,
        methods: def.methods,
        options,
        cli_options: Default::default(),
        ambient: def.ambient.unwrap_or(DEFAULT_AMBIENT) as f32,
    })
}

/// The light types and the fields each one takes besides `type` and `center`.
const LIGHT_FIELDS: [(&str, &[&str]); 5] = [
    ("point", &[]),
    ("sphere", &["radius"]),
    ("disk", &["radius", "normal"]),
    ("rect", &["u", "v"]),
    ("textured_rect", &["u", "v", "texture"]),
];

/// The scene's lights from `light` (one) or `lights` (one or more), exactly one of the two.
fn build_lights(
    light: Option<LightDef>,
    lights: Option<Vec<LightDef>>,
    source: &str,
    base_dir: &Path,
) -> Result<Vec<Light>, InputError> {
    match (light, lights) {
        (Some(l), None) => Ok(vec![build_light(l, "light", source, base_dir)?]),
        (None, Some(list)) => {
            if list.is_empty() || list.len() > MAX_LIGHTS {
                return Err(InputError::at(
                    source,
                    "lights",
                    format!("has {} lights, needs 1..={MAX_LIGHTS}", list.len()),
                ));
            }
            list.into_iter()
                .enumerate()
                .map(|(k, l)| build_light(l, &format!("lights[{k}]"), source, base_dir))
                .collect()
        }
        (Some(_), Some(_)) => Err(InputError::at(
            source,
            "lights",
            "give either [light] or [[lights]], not both".to_string(),
        )),
        (None, None) => Err(InputError::at(
            source,
            "light",
            "missing: a scene needs [light] (or [[lights]] for several lights)".to_string(),
        )),
    }
}

/// One light; `object` names it in errors (`light` or `lights[K]`).
fn build_light(
    l: LightDef,
    object: &str,
    source: &str,
    base_dir: &Path,
) -> Result<Light, InputError> {
    let at =
        |field: &str, message: String| InputError::at(source, format!("{object}.{field}"), message);
    let Some(&(kind, fields)) = LIGHT_FIELDS.iter().find(|(k, _)| *k == l.kind) else {
        let kinds: Vec<&str> = LIGHT_FIELDS.iter().map(|(k, _)| *k).collect();
        return Err(at(
            "type",
            format!(
                "unknown light type {:?} (expected one of {})",
                l.kind,
                kinds.join(", ")
            ),
        ));
    };
    let present = [
        ("u", l.u.is_some()),
        ("v", l.v.is_some()),
        ("radius", l.radius.is_some()),
        ("normal", l.normal.is_some()),
        ("texture", l.texture.is_some()),
    ];
    let takes = if fields.is_empty() {
        "only center".to_string()
    } else {
        fields.join(", ")
    };
    for (name, is) in present {
        if is && !fields.contains(&name) {
            return Err(at(
                name,
                format!("not used by a \"{kind}\" light (it takes {takes})"),
            ));
        }
        if !is && fields.contains(&name) {
            return Err(at(
                name,
                format!("missing: a \"{kind}\" light needs {takes}"),
            ));
        }
    }
    // Every field the type needs is present (checked above).
    let u = l.u.map(v3).unwrap_or_default();
    let v = l.v.map(v3).unwrap_or_default();
    let radius = l.radius.unwrap_or_default() as f32;
    let shape = match kind {
        "point" => LightShape::Point,
        "sphere" => LightShape::Sphere { radius },
        "disk" => LightShape::Disk {
            radius,
            normal: l.normal.map(v3).unwrap_or_default(),
        },
        "rect" => LightShape::Rect { u, v },
        _ => {
            let rel = l.texture.unwrap_or_default();
            let texture = load_texture(&base_dir.join(&rel)).map_err(|m| at("texture", m))?;
            LightShape::TexturedRect { u, v, texture }
        }
    };
    Ok(Light {
        center: v3(l.center),
        shape,
    })
}

/// The matrix of a mesh's `scale`, `rotate_deg` and `translate` (each optional): T · R · S,
/// so the mesh is scaled first, then rotated, then moved. `rotate_deg = [x, y, z]` are Euler
/// angles in degrees about the world axes, applied X first, then Y, then Z
/// (R = R_z · R_y · R_x), each counter-clockwise looking down its axis toward the origin
/// (right-handed). Computed in f64, rounded to f32 once, as a written `transform` is.
fn transform_from_parts(m: &MeshDef) -> Mat4 {
    let scale = match m.scale {
        None => DVec3::ONE,
        Some(Scale::Uniform(k)) => DVec3::splat(k),
        Some(Scale::PerAxis(k)) => DVec3::from_array(k.0),
    };
    let [x, y, z] = m.rotate_deg.map_or([0.0; 3], |r| r.0.map(f64::to_radians));
    let rotation =
        DMat4::from_rotation_z(z) * DMat4::from_rotation_y(y) * DMat4::from_rotation_x(x);
    let translation = m.translate.map_or(DVec3::ZERO, |t| DVec3::from_array(t.0));
    let mat = DMat4::from_translation(translation) * rotation * DMat4::from_scale(scale);
    Mat4::from_cols_array(&mat.to_cols_array().map(|x| x as f32))
}

/// Mesh `i` of the scene: its file read, moved and repaired (two steps of `progress`).
fn build_mesh(
    m: &MeshDef,
    i: usize,
    source: &str,
    base_dir: &Path,
    progress: &Progress,
) -> Result<Mesh, InputError> {
    let at = |field: &str, message: String| {
        InputError::at(source, format!("meshes[{i}]{field}"), message)
    };
    let parts = m.scale.is_some() || m.rotate_deg.is_some() || m.translate.is_some();
    let transform = match &m.transform {
        Some(_) if parts => {
            return Err(at(
                "",
                "has `transform` and `scale`/`rotate_deg`/`translate`: give either the matrix \
                 or its parts"
                    .into(),
            ))
        }
        None if !parts => None,
        None => {
            let mat = transform_from_parts(m);
            let field = ".scale/.rotate_deg/.translate";
            check_transform(&mat).map_err(|e| at(field, e))?;
            Some(mat)
        }
        Some(t) => {
            let arr: [f64; 16] = t.as_slice().try_into().map_err(|_| {
                at(
                    ".transform",
                    format!(
                        "has {} numbers, needs 16 (a column-major 4×4 matrix)",
                        t.len()
                    ),
                )
            })?;
            let mat = Mat4::from_cols_array(&arr.map(|x| x as f32));
            check_transform(&mat).map_err(|e| at(".transform", e))?;
            Some(mat)
        }
    };
    let color = m.color.map_or(DEFAULT_COLOR, |c| c.0).map(|c| c as f32);
    let file = match (&m.mesh, &m.obj) {
        (Some(f), None) | (None, Some(f)) => f,
        (Some(_), Some(_)) => {
            return Err(at(
                "",
                "has both `mesh` and `obj`: give the mesh file once (`mesh`; `obj` is its \
                 older name)"
                    .into(),
            ))
        }
        (None, None) => {
            return Err(at(
                "",
                "has no mesh file: give `mesh = \"path\"` (.obj .ply .stl .gltf .glb)".into(),
            ))
        }
    };
    let path = base_dir.join(file);
    let display = path.display().to_string();
    let mut options = repair_options(m).map_err(|(field, e)| at(field, e))?;
    let object = format!("meshes[{i}] ({display})");
    let in_mesh = |message: String| InputError::at(source, &object, message);
    progress.start(&format!("reading meshes[{i}]"));
    let mut raw = read_mesh(&path, &display).map_err(|e| in_mesh(e.message))?;
    if let Some(t) = transform {
        raw = raw.transformed(t).map_err(in_mesh)?;
    }
    // Repair's weld is the only one: bit-identical corners numbered by first appearance (as
    // the OBJ loader always did, so closed models keep their vertex order and every golden
    // its bits), then within the tolerance. The positions an OBJ repeats (exporters write a
    // group's shared `v` lines again) are one vertex in the file, so joining them is no
    // repair; STL's, PLY's and glTF's repeated corners are reported.
    options.count_identical_welds = raw.format != MeshFormat::Obj;
    progress.start(&format!("repairing meshes[{i}]"));
    let (positions, triangles, repairs) =
        repair(raw.positions, raw.triangles, &options).map_err(in_mesh)?;
    let mesh = Mesh {
        name: display.clone(),
        positions,
        triangles,
        color,
        receiver_only: options.receiver_only,
        repairs,
    };
    Ok(mesh)
}

/// The repair options of a mesh table (`weld`, `weld_tolerance`, `open`, `receiver_only`);
/// the error names the field (`.open`, …).
fn repair_options(m: &MeshDef) -> Result<RepairOptions, (&'static str, String)> {
    let weld_tolerance = m.weld_tolerance.unwrap_or(0.0);
    if !(weld_tolerance.is_finite() && weld_tolerance >= 0.0) {
        return Err((
            ".weld_tolerance",
            format!("{weld_tolerance} must be a finite number ≥ 0 (a fraction of the mesh's bounding-box diagonal)"),
        ));
    }
    let open = match m.open.as_deref() {
        None => None,
        Some(name) => Some(OpenTreatment::from_name(name).ok_or_else(|| {
            (
                ".open",
                format!("unknown treatment {name:?} (expected \"close\", \"shell\" or \"refuse\")"),
            )
        })?),
    };
    Ok(RepairOptions {
        weld: m.weld.unwrap_or(true),
        weld_tolerance,
        open,
        receiver_only: m.receiver_only.unwrap_or(false),
        // Set by the mesh's format (build_mesh).
        count_identical_welds: true,
    })
}

/// Loads an image as linear RGB in [0, 1]: 8- and 16-bit images are sRGB-decoded, float
/// images (EXR) are taken as linear. Alpha is ignored.
fn load_texture(path: &Path) -> Result<RgbTexture, String> {
    let name = path.display().to_string();
    let bytes = read_input_file(path).map_err(|m| format!("cannot open {name}: {m}"))?;
    let img = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("cannot open {name}: {e}"))?
        .decode()
        .map_err(|e| format!("cannot decode {name}: {e}"))?;
    let (width, height) = (img.width(), img.height());
    let float = matches!(
        img.color(),
        image::ColorType::Rgb32F | image::ColorType::Rgba32F
    );
    let texels = if float {
        img.to_rgb32f().pixels().map(|p| p.0).collect()
    } else {
        img.to_rgb16()
            .pixels()
            .map(|p| p.0.map(|c| srgb_to_linear(f64::from(c) / 65535.0) as f32))
            .collect()
    };
    Ok(RgbTexture {
        width,
        height,
        texels,
        source: name,
    })
}

/// The sRGB electro-optical transfer function (IEC 61966-2-1), in f64.
fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        libm::pow((c + 0.055) / 1.055, 2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A directory with a closed tetrahedron and a floor box, for parsing tests.
    fn fixture() -> std::path::PathBuf {
        // One directory per call: tests run in parallel and must not see half-written files.
        static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let dir =
            std::env::temp_dir().join(format!("penumbra-scene-file-{}-{n}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("tet.obj"),
            "v 0 1 0\nv 0 2 0\nv 1 1 0\nv 0 1 1\nf 1 3 4\nf 1 2 3\nf 1 4 2\nf 2 4 3\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("floor.obj"),
            "v -2 -0.1 -2\nv 2 -0.1 -2\nv -2 0 -2\nv 2 0 -2\nv -2 -0.1 2\nv 2 -0.1 2\nv -2 0 2\nv 2 0 2\n\
             f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n",
        )
        .unwrap();
        dir
    }

    const GOOD: &str = r#"
width = 64
methods = ["hard-sv"]
[camera]
eye = [0, 2, 5]
target = [0, 0, 0]
up = [0, 1, 0]
vfov_deg = 45
[light]
type = "rect"
center = [0, 4, 0]
u = [0.5, 0, 0]
v = [0, 0, 0.5]
[[meshes]]
obj = "floor.obj"
[[meshes]]
obj = "tet.obj"
color = [1, 0, 0]
transform = [1,0,0,0, 0,1,0,0, 0,0,1,0, 0.5,0,0,1]
[options.nsample]
n = 256
jitter = true
name = "x"
f = 0.5
"#;

    fn toml_in(dir: &Path, text: &str) -> Result<Scene, InputError> {
        parse_scene_str(text, Format::Toml, "s.toml", dir)
    }

    fn toml(text: &str) -> Result<Scene, InputError> {
        toml_in(&fixture(), text)
    }

    /// `scale`, `rotate_deg` and `translate` give the matrix T · R_z · R_y · R_x · S: the
    /// tetrahedron's vertex (1, 1, 0) scaled by 2 is (2, 2, 0), turned 90° about Y (x → −z)
    /// (0, 2, −2), moved by (1, 2, 3) (1, 4, 1); scale per axis and alone; errors name the mesh.
    #[test]
    fn transform_parts_scale_then_rotate_then_translate() {
        let with =
            |parts: &str| GOOD.replace("transform = [1,0,0,0, 0,1,0,0, 0,0,1,0, 0.5,0,0,1]", parts);
        let near = |s: &Scene, p: Vec3| {
            s.meshes[1]
                .positions
                .iter()
                .any(|q| (*q - p).length() < 1e-6)
        };
        let s = toml(&with(
            "scale = 2\nrotate_deg = [0, 90, 0]\ntranslate = [1, 2, 3]",
        ))
        .unwrap();
        assert!(
            near(&s, Vec3::new(1.0, 4.0, 1.0)),
            "{:?}",
            s.meshes[1].positions
        );
        // X first, then Y: (0, 1, 0) turned 90° about X is (0, 0, 1), then about Y (1, 0, 0).
        let s = toml(&with("rotate_deg = [90, 90, 0]")).unwrap();
        assert!(
            near(&s, Vec3::new(1.0, 0.0, 0.0)),
            "{:?}",
            s.meshes[1].positions
        );
        let s = toml(&with("scale = [1, 1.5, 1]")).unwrap();
        assert!(near(&s, Vec3::new(0.0, 3.0, 0.0)));
        let err = toml(&with(
            "transform = [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]\nscale = 2",
        ))
        .unwrap_err()
        .to_string();
        assert!(
            err.contains("meshes[1]: has `transform` and `scale`"),
            "{err}"
        );
        let err = toml(&with("scale = 0")).unwrap_err().to_string();
        assert!(
            err.contains("meshes[1].scale/.rotate_deg/.translate: is singular"),
            "{err}"
        );
        let err = toml(&with("scale = \"big\"")).unwrap_err().to_string();
        assert!(err.contains("a number or three numbers"), "{err}");
    }

    #[test]
    fn good_toml() {
        let s = toml(GOOD).unwrap();
        assert_eq!((s.width, s.height), (64, 256));
        assert_eq!(s.ambient, 0.15);
        assert_eq!(s.methods, Some(vec!["hard-sv".to_string()]));
        assert_eq!(s.meshes.len(), 2);
        assert_eq!(s.meshes[1].color, [1.0, 0.0, 0.0]);
        assert!(s.meshes[1].positions.contains(&Vec3::new(1.5, 1.0, 0.0)));
        assert_eq!(s.meshes[0].color, [0.8, 0.8, 0.8]);
        let o = &s.options["nsample"];
        assert_eq!(o["n"], OptionValue::Int(256));
        assert_eq!(o["jitter"], OptionValue::Bool(true));
        assert_eq!(o["name"], OptionValue::Str("x".into()));
        assert_eq!(o["f"], OptionValue::Float(0.5));
        assert_eq!(
            s.light().shape,
            LightShape::Rect {
                u: Vec3::X * 0.5,
                v: Vec3::Z * 0.5
            }
        );
    }

    #[test]
    fn json_same_schema() {
        let json = r#"{"width": 64, "methods": ["hard-sv"],
            "camera": {"eye": [0, 2, 5], "target": [0, 0, 0], "up": [0, 1, 0], "vfov_deg": 45},
            "light": {"type": "rect", "center": [0, 4, 0], "u": [0.5, 0, 0], "v": [0, 0, 0.5]},
            "meshes": [{"obj": "floor.obj"}, {"obj": "tet.obj", "color": [1, 0, 0],
                "transform": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0.5,0,0,1]}],
            "options": {"nsample": {"n": 256, "jitter": true, "name": "x", "f": 0.5}}}"#;
        let dir = fixture();
        let s = parse_scene_str(json, Format::Json, "s.toml", &dir).unwrap();
        assert_eq!(s, toml_in(&dir, GOOD).unwrap());
    }

    fn err(text: &str) -> String {
        toml(text).unwrap_err().to_string()
    }

    #[test]
    fn syntax_and_schema_errors() {
        let e = err("width = \n");
        assert!(e.starts_with("s.toml: line 1, column "), "{e}");
        assert!(!e.contains('\n'));
        let e = err(&GOOD.replace("width = 64", "widht = 64"));
        assert!(
            e.starts_with("s.toml: line 2, column 1: unknown field `widht`"),
            "{e}"
        );
        let e = err(&GOOD.replace("vfov_deg = 45", "vfov_deg = \"wide\""));
        assert!(e.contains("line 8") && e.contains("invalid type"), "{e}");
        let e = parse_scene_str(
            "{\"width\": 5,\n \"x\": 1}",
            Format::Json,
            "s.json",
            Path::new("."),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("s.json: line 2, column ") && e.contains(": unknown field `x`"),
            "{e}"
        );
    }

    #[test]
    fn lists_of_three_take_exactly_three_numbers() {
        let e = err(&GOOD.replace("color = [1, 0, 0]", "color = [1, 0, 0, 0.5]"));
        assert!(
            e.starts_with("s.toml: line 18, column ")
                && e.contains("invalid length 4, expected exactly 3 numbers"),
            "{e}"
        );
        let e = err(&GOOD.replace("eye = [0, 2, 5]", "eye = [0, 2]"));
        assert!(
            e.contains("invalid length 2, expected exactly 3 numbers"),
            "{e}"
        );
        let json = r#"{"camera": {"eye": [0, 2, 5, 1], "target": [0, 0, 0], "up": [0, 1, 0],
            "vfov_deg": 45}, "light": {"type": "point", "center": [0, 4, 0]}, "meshes": []}"#;
        let e = parse_scene_str(json, Format::Json, "s.json", Path::new("."))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("invalid length 4, expected exactly 3 numbers"),
            "{e}"
        );
    }

    #[test]
    fn messages_name_no_internal_types() {
        let e = parse_scene_str(" [1, 2]", Format::Json, "s.json", Path::new("."))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "s.json: the top level must be a JSON object ({...}) holding the scene, not an array"
        );
        let e = parse_scene_str("{\"camera\": 5}", Format::Json, "s.json", Path::new("."))
            .unwrap_err()
            .to_string();
        assert!(
            e.ends_with("invalid type: integer `5`, expected a camera table"),
            "{e}"
        );
        let e = err("camera = 5\n");
        assert!(
            e.contains("expected a camera table") && !e.contains("Def"),
            "{e}"
        );
    }

    #[test]
    fn light_fields() {
        let e = err(&GOOD.replace("type = \"rect\"", "type = \"sphere\""));
        assert_eq!(
            e,
            "s.toml: light.u: not used by a \"sphere\" light (it takes radius)"
        );
        let e = err(&GOOD.replace("v = [0, 0, 0.5]", ""));
        assert_eq!(e, "s.toml: light.v: missing: a \"rect\" light needs u, v");
        let e = err(&GOOD.replace("type = \"rect\"", "type = \"square\""));
        assert!(
            e.starts_with("s.toml: light.type: unknown light type \"square\""),
            "{e}"
        );
        let e = err(&GOOD.replace("u = [0.5, 0, 0]", "u = [0, 0, 0]"));
        assert!(e.contains("light.u: is the zero vector"), "{e}");
        let e = err(&GOOD.replace(
            "type = \"rect\"",
            "type = \"textured_rect\"\ntexture = \"no.png\"",
        ));
        assert!(e.starts_with("s.toml: light.texture: cannot open "), "{e}");
    }

    /// `GOOD` with its `[light]` replaced by `[[lights]]` tables of the given bodies.
    fn with_lights(bodies: &[&str]) -> String {
        let tables: String = bodies
            .iter()
            .map(|b| format!("[[lights]]\n{b}\n"))
            .collect();
        GOOD.replace(
            "[light]\ntype = \"rect\"\ncenter = [0, 4, 0]\nu = [0.5, 0, 0]\nv = [0, 0, 0.5]\n",
            &tables,
        )
    }

    #[test]
    fn several_lights() {
        let rect = "type = \"rect\"\ncenter = [0, 4, 0]\nu = [0.5, 0, 0]\nv = [0, 0, 0.5]";
        let sphere = "type = \"sphere\"\ncenter = [1, 4, 0]\nradius = 0.25";
        let s = toml(&with_lights(&[rect, sphere])).unwrap();
        assert_eq!(s.lights.len(), 2);
        assert!(s.is_multi_light());
        assert_eq!(s.lights[1].shape, LightShape::Sphere { radius: 0.25 });
        assert_eq!(s.lights[1].center, Vec3::new(1.0, 4.0, 0.0));
        // One [[lights]] table is the same scene as [light].
        let dir = fixture();
        assert_eq!(
            toml_in(&dir, &with_lights(&[rect])).unwrap(),
            toml_in(&dir, GOOD).unwrap()
        );
        let only = s.with_only_light(1);
        assert_eq!(only.lights, vec![s.lights[1].clone()]);
        assert_eq!(only.meshes, s.meshes);

        let e = err(&with_lights(&[
            rect,
            "type = \"sphere\"\ncenter = [1, 4, 0]",
        ]));
        assert_eq!(
            e,
            "s.toml: lights[1].radius: missing: a \"sphere\" light needs radius"
        );
        let e = err(&with_lights(&[
            rect,
            "type = \"sphere\"\ncenter = [1, 4, 0]\nradius = 0",
        ]));
        assert!(e.starts_with("s.toml: lights[1].radius: "), "{e}");
        let e = err(&format!("{GOOD}\n[[lights]]\n{sphere}\n"));
        assert_eq!(
            e,
            "s.toml: lights: give either [light] or [[lights]], not both"
        );
        let e = err(&with_lights(&[]));
        assert_eq!(
            e,
            "s.toml: light: missing: a scene needs [light] (or [[lights]] for several lights)"
        );
        let json = r#"{"camera": {"eye": [0, 2, 5], "target": [0, 0, 0], "up": [0, 1, 0], "vfov_deg": 45},
            "lights": [], "meshes": [{"obj": "floor.obj"}]}"#;
        let e = parse_scene_str(json, Format::Json, "s.json", &fixture())
            .unwrap_err()
            .to_string();
        assert_eq!(e, "s.json: lights: has 0 lights, needs 1..=255");
        let many: Vec<&str> = vec![sphere; MAX_LIGHTS + 1];
        let e = err(&with_lights(&many));
        assert_eq!(e, "s.toml: lights: has 256 lights, needs 1..=255");
    }

    /// `mesh = "…"` reads any format (here an STL copy of the tetrahedron); `obj` and `mesh`
    /// are the same key; both or neither is an error naming the mesh.
    #[test]
    fn mesh_key() {
        let dir = fixture();
        let corners = [
            [0, 1, 0],
            [1, 1, 0],
            [0, 1, 1],
            [0, 1, 0],
            [0, 2, 0],
            [1, 1, 0],
        ];
        let mut stl = String::from("solid tet\n");
        for tri in [&corners[..3], &corners[3..]] {
            stl += "facet normal 0 0 0\nouter loop\n";
            for c in tri {
                stl += &format!("vertex {} {} {}\n", c[0], c[1], c[2]);
            }
            stl += "endloop\nendfacet\n";
        }
        for tri in [
            [[0, 1, 0], [0, 1, 1], [0, 2, 0]],
            [[0, 2, 0], [0, 1, 1], [1, 1, 0]],
        ] {
            stl += "facet normal 0 0 0\nouter loop\n";
            for c in tri {
                stl += &format!("vertex {} {} {}\n", c[0], c[1], c[2]);
            }
            stl += "endloop\nendfacet\n";
        }
        stl += "endsolid tet\n";
        std::fs::write(dir.join("tet.STL"), stl).unwrap();
        let by_obj = parse_scene_str(GOOD, Format::Toml, "s.toml", &dir).unwrap();
        let by_mesh = GOOD.replace("obj = \"tet.obj\"", "mesh = \"tet.STL\"");
        let s = parse_scene_str(&by_mesh, Format::Toml, "s.toml", &dir).unwrap();
        assert_eq!(s.meshes[1].positions, by_obj.meshes[1].positions);
        assert_eq!(s.meshes[1].triangles, by_obj.meshes[1].triangles);
        let both = GOOD.replace("obj = \"tet.obj\"", "obj = \"tet.obj\"\nmesh = \"tet.obj\"");
        assert_eq!(
            parse_scene_str(&both, Format::Toml, "s.toml", &dir)
                .unwrap_err()
                .to_string(),
            "s.toml: meshes[1]: has both `mesh` and `obj`: give the mesh file once (`mesh`; \
             `obj` is its older name)"
        );
        let neither = GOOD.replace("obj = \"tet.obj\"", "receiver_only = false");
        assert_eq!(
            parse_scene_str(&neither, Format::Toml, "s.toml", &dir)
                .unwrap_err()
                .to_string(),
            "s.toml: meshes[1]: has no mesh file: give `mesh = \"path\"` (.obj .ply .stl .gltf \
             .glb)"
        );
        let unknown = GOOD.replace("obj = \"tet.obj\"", "mesh = \"tet.3ds\"");
        let e = parse_scene_str(&unknown, Format::Toml, "s.toml", &dir)
            .unwrap_err()
            .to_string();
        assert!(e.contains("tet.3ds): unknown mesh file extension"), "{e}");
    }

    #[test]
    fn mesh_and_option_errors() {
        let e = err(&GOOD.replace("obj = \"tet.obj\"", "obj = \"nope.obj\""));
        assert!(
            e.starts_with("s.toml: meshes[1] (") && e.contains("nope.obj): cannot read OBJ file: "),
            "{e}"
        );
        let e = err(&GOOD.replace("0.5,0,0,1]", "0.5,0,0]"));
        assert_eq!(
            e,
            "s.toml: meshes[1].transform: has 15 numbers, needs 16 (a column-major 4×4 matrix)"
        );
        let e = err(&GOOD.replace("n = 256", "n = [1, 2]"));
        assert_eq!(
            e,
            "s.toml: options.nsample.n: must be a single integer, float, bool or string"
        );
        let e = err(&GOOD.replace("n = 256", "n = { a = 1 }"));
        assert!(e.contains("options.nsample.n"), "{e}");
        let e = err(&GOOD.replace("[camera]", "ambient = nan\n[camera]"));
        assert!(e.contains("ambient"), "{e}");
    }

    /// The repair keys: bad values name `meshes[I].open` / `.weld_tolerance`; an open mesh
    /// is capped by default and refused with `open = "refuse"`.
    #[test]
    fn repair_keys() {
        let dir = fixture();
        std::fs::write(
            dir.join("open.obj"),
            "v 0 1 0\nv 0 2 0\nv 1 1 0\nv 0 1 1\nf 1 3 4\nf 1 2 3\nf 1 4 2\n",
        )
        .unwrap();
        let with =
            |keys: &str| GOOD.replace("obj = \"tet.obj\"", &format!("obj = \"open.obj\"\n{keys}"));
        let s = toml_in(&dir, &with("")).unwrap();
        assert_eq!(s.meshes[1].repairs.holes_closed, 1);
        assert_eq!(s.meshes[1].triangles.len(), 4);
        let e = toml_in(&dir, &with("open = \"refuse\""))
            .unwrap_err()
            .to_string();
        assert!(e.contains("open.obj): open mesh: edge "), "{e}");
        let e = toml_in(&dir, &with("open = \"seal\""))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "s.toml: meshes[1].open: unknown treatment \"seal\" (expected \"close\", \"shell\" \
             or \"refuse\")"
        );
        let e = toml_in(&dir, &with("weld_tolerance = -1.0"))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("s.toml: meshes[1].weld_tolerance: -1 must be"),
            "{e}"
        );
    }

    #[test]
    fn texture_light() {
        let dir = fixture();
        let mut img = image::RgbImage::new(2, 1);
        img.put_pixel(0, 0, image::Rgb([255, 0, 128]));
        img.put_pixel(1, 0, image::Rgb([10, 20, 30]));
        img.save(dir.join("t.png")).unwrap();
        let s = toml_in(
            &dir,
            &GOOD.replace(
                "type = \"rect\"",
                "type = \"textured_rect\"\ntexture = \"t.png\"",
            ),
        )
        .unwrap();
        let LightShape::TexturedRect { texture, .. } = &s.light().shape else {
            panic!()
        };
        assert_eq!((texture.width, texture.height), (2, 1));
        assert_eq!(texture.texels[0][0], 1.0);
        assert_eq!(texture.texels[0][1], 0.0);
        assert!((texture.texels[0][2] - 0.2158605).abs() < 1e-6);
        assert!((texture.texels[1][0] - 10.0 / 255.0 / 12.92).abs() < 1e-7);
    }

    #[test]
    fn resolve_names_and_paths() {
        assert_eq!(resolve("single-quad").unwrap().source, "single-quad");
        let e = resolve("no-such-thing").unwrap_err().to_string();
        assert!(
            e.starts_with("no-such-thing: not a built-in scene") && e.contains("cube-of-spheres"),
            "{e}"
        );
        let dir = fixture();
        std::fs::write(dir.join("s.yaml"), "x").unwrap();
        let p = dir.join("s.yaml");
        let e = resolve(p.to_str().unwrap()).unwrap_err();
        assert!(e.message.contains("unknown scene file extension"));
    }

    #[test]
    fn line_col_counts_chars() {
        assert_eq!(line_col("ab\ncé\nx", 6), (2, 3));
        assert_eq!(line_col("", 5), (1, 1));
    }
}
