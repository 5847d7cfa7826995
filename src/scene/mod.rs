//! Scenes: the validated, in-memory description of one frame — image size, camera, lights,
//! closed meshes in world space, the methods to run and their options.
//!
//! A scene holds one light or several (Paper I §7, Fig. 16: "multiply the light intensities
//! by 255/n, where n is the number of lights"). Visibility with n lights is the mean of the
//! per-light visibilities; the penumbra-wedge methods compute it in one LI buffer with
//! amounts scaled by 255/n, every other method renders each light on its own
//! ([`Scene::with_only_light`]) and averages ([`crate::methods::run`]).
//!
//! Files are TOML or JSON with one schema ([`mod@file`]); built-in scenes are generated in code
//! ([`builtin`]); mesh files (OBJ, PLY, STL, glTF) are read by [`mesh_io`] and repaired,
//! every repair counted ([`repair`]). Everything that reaches a
//! [`Scene`] has been validated ([`validate`]): finite numbers, non-degenerate light and
//! camera, closed two-manifold meshes.

pub mod adjacency;
pub mod builtin;
pub mod file;
pub mod input_file;
pub mod mesh_io;
pub mod procedural;
pub mod repair;
pub mod validate;

use crate::error::InputError;
use glam::{DVec3, Vec3};
use std::collections::BTreeMap;

/// The camera (`docs/architecture.md` "Coordinates"): right-handed world, view matrix as gluLookAt,
/// `vfov_deg` the full vertical angle. Kept in f64; clip coordinates are rounded to f32 once.
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// Eye position in world space.
    pub eye: DVec3,
    /// Point the camera looks at.
    pub target: DVec3,
    /// Up vector (need not be orthogonal to the view direction, must not be parallel to it).
    pub up: DVec3,
    /// Full vertical field of view in degrees, in (0, 180).
    pub vfov_deg: f64,
    /// Near-plane distance; `None` picks the default derived from the scene bounds and the
    /// nearest geometry in view (see [`crate::gpu::transform::default_near`]).
    pub near: Option<f64>,
}

impl Camera {
    /// tan of half the horizontal and half the vertical field of view of a `width`×`height`
    /// image: the view pyramid's half extents at distance 1 (the projection's 1/f and a/f).
    pub fn view_half_tangents(&self, width: u32, height: u32) -> (f64, f64) {
        let tan_y = libm::tan(self.vfov_deg.to_radians() * 0.5);
        (tan_y * width as f64 / height as f64, tan_y)
    }
}

/// An RGB texture with linear f32 texels in [0, 1], row 0 at the top (used by textured lights).
#[derive(Debug, Clone, PartialEq)]
pub struct RgbTexture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major texels, `width * height` entries.
    pub texels: Vec<[f32; 3]>,
    /// Where the texture came from (file path or a description), for messages and stats.
    pub source: String,
}

/// The shape of the area light (`docs/architecture.md` "Methods": which method supports which
/// shape).
#[derive(Debug, Clone, PartialEq)]
pub enum LightShape {
    /// A point light at the light center (hard shadows only).
    Point,
    /// A sphere of `radius` (Papers I, II, IV §4.2.1).
    Sphere {
        /// The radius.
        radius: f32,
    },
    /// A one-sided circular disk of `radius` facing along `normal` (CGI 2004).
    Disk {
        /// The radius.
        radius: f32,
        /// The unit normal the disk emits along.
        normal: Vec3,
    },
    /// A rectangle spanned by the half-extent vectors `u` and `v` (Papers III, IV; Forest 2006).
    Rect {
        /// Half-extent along the first side.
        u: Vec3,
        /// Half-extent along the second side.
        v: Vec3,
    },
    /// A rectangle like [`LightShape::Rect`] whose emission is an RGB texture (Paper III §3.3);
    /// texel (0,0) is at `center − u + v` (top-left), texel columns run along `u`.
    TexturedRect {
        /// Half-extent along the first side (texel columns).
        u: Vec3,
        /// Half-extent along the second side (texel rows, downward from `center + v`).
        v: Vec3,
        /// The emission.
        texture: RgbTexture,
    },
}

impl LightShape {
    /// The name used in scene files (`type = "..."`).
    pub fn type_name(&self) -> &'static str {
        match self {
            LightShape::Point => "point",
            LightShape::Sphere { .. } => "sphere",
            LightShape::Disk { .. } => "disk",
            LightShape::Rect { .. } => "rect",
            LightShape::TexturedRect { .. } => "textured_rect",
        }
    }
}

/// The area light: a shape around `center`. Hard shadows always use `center`.
#[derive(Debug, Clone, PartialEq)]
pub struct Light {
    /// The light center in world space.
    pub center: Vec3,
    /// The shape and its size.
    pub shape: LightShape,
}

impl Light {
    /// The axis-aligned box (min, max) of every point of the light, in f64: the center of a
    /// point light, a rectangle's corners, a disk's rim (`center ± radius·√(1 − n_k²)` along
    /// axis k, for its unit normal `n`), a sphere's `center ± radius`.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let c = self.center.as_dvec3();
        let half = match &self.shape {
            LightShape::Point => DVec3::ZERO,
            LightShape::Sphere { radius } => DVec3::splat(f64::from(*radius)),
            LightShape::Disk { radius, normal } => {
                let n = normal.as_dvec3().normalize_or_zero();
                let r = f64::from(*radius);
                let rim = |nk: f64| (1.0 - nk * nk).max(0.0).sqrt() * r;
                DVec3::new(rim(n.x), rim(n.y), rim(n.z))
            }
            LightShape::Rect { u, v } | LightShape::TexturedRect { u, v, .. } => {
                u.as_dvec3().abs() + v.as_dvec3().abs()
            }
        };
        (c - half, c + half)
    }
}

/// A closed, two-manifold triangle mesh in world space (transform already applied).
/// Triangles are counter-clockwise seen from outside (outward normals by the right-hand rule).
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// A name for messages: the mesh file's path or the built-in part's name.
    pub name: String,
    /// Vertex positions, world space, f32 as a GPU would hold them.
    pub positions: Vec<Vec3>,
    /// Triangles as indices into `positions`; shared vertices are shared indices.
    pub triangles: Vec<[u32; 3]>,
    /// Diffuse albedo in linear RGB, used only for the shaded image.
    pub color: [f32; 3],
    /// A receiver only (`receiver_only = true`): it receives shadows but casts none in any
    /// method (`raycast` included, so that methods stay comparable), and it may be open (a
    /// floor plane): it is exempt from the closed-mesh check.
    pub receiver_only: bool,
    /// What [`repair::repair`] changed to make the file's triangles this mesh (nothing for a
    /// built-in mesh); reported on the terminal, in the table notes and in `stats.json`.
    pub repairs: repair::MeshRepairs,
}

/// Raw per-method options as written in `[options.METHOD]` or with `--opt METHOD.KEY=VALUE`.
/// Values are kept as strings/numbers/bools; each method reads its own table into its typed
/// options ([`crate::options::OptionTable::read`]).
pub type RawOptions = BTreeMap<String, BTreeMap<String, OptionValue>>;

/// One option value as written by the user.
#[derive(Debug, Clone, PartialEq)]
pub enum OptionValue {
    /// `true` / `false`.
    Bool(bool),
    /// An integer.
    Int(i64),
    /// A float.
    Float(f64),
    /// A string (also every `--opt` value that is not a number or bool).
    Str(String),
}

impl OptionValue {
    /// A value written on the command line (`--opt METHOD.KEY=VALUE`): a bool, else an
    /// integer, else a float, else a string.
    pub fn parse_cli(v: &str) -> OptionValue {
        if let Ok(b) = v.parse::<bool>() {
            OptionValue::Bool(b)
        } else if let Ok(i) = v.parse::<i64>() {
            OptionValue::Int(i)
        } else if let Ok(f) = v.parse::<f64>() {
            OptionValue::Float(f)
        } else {
            OptionValue::Str(v.to_string())
        }
    }

    /// The value's text, which is what an option reads ([`crate::options`]), so that a scene
    /// file and `--opt` agree: a string as written, a number or bool as the command line
    /// writes it; a float keeps its point (`4.0`), so an integer key refuses it.
    pub fn text(&self) -> String {
        match self {
            OptionValue::Str(s) => s.clone(),
            other => other.to_string(),
        }
    }
}

impl std::fmt::Display for OptionValue {
    /// As a message shows it: a string quoted, a float with its point (`4.0`).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OptionValue::Bool(b) => write!(f, "{b}"),
            OptionValue::Int(i) => write!(f, "{i}"),
            OptionValue::Float(x) => write!(f, "{x:?}"),
            OptionValue::Str(s) => write!(f, "{s:?}"),
        }
    }
}

/// A validated scene, ready to render.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The scene file path or the built-in scene's name (used in every error message).
    pub source: String,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The camera.
    pub camera: Camera,
    /// The lights, at least one and at most [`crate::limits::MAX_LIGHTS`].
    pub lights: Vec<Light>,
    /// The shadow-casting and receiving meshes (every mesh does both).
    pub meshes: Vec<Mesh>,
    /// Methods to run; `None` = every method that supports the light shape.
    pub methods: Option<Vec<String>>,
    /// Per-method options, not yet validated against each method's keys.
    pub options: RawOptions,
    /// The `--opt METHOD.KEY=VALUE` argument that set each option `(METHOD, KEY)` from the
    /// command line ([`Scene::set_cli_option`]), so that an error about it names the argument.
    pub cli_options: BTreeMap<(String, String), String>,
    /// Ambient term of the shaded image, in [0, 1].
    pub ambient: f32,
}

impl Scene {
    /// Set the image size from `width` and/or `height`: one given alone keeps the scene's
    /// aspect ratio (the other side rounded to the nearest pixel, at least 1), both replace
    /// both, neither changes nothing.
    pub fn resize(&mut self, width: Option<u32>, height: Option<u32>) {
        let scaled = |side: u32, from: u32, to: u32| -> u32 {
            let exact = u64::from(side) * u64::from(to);
            let rounded = (2 * exact + u64::from(from)) / (2 * u64::from(from).max(1));
            rounded.clamp(1, u64::from(u32::MAX)) as u32
        };
        let (w0, h0) = (self.width, self.height);
        (self.width, self.height) = match (width, height) {
            (Some(w), Some(h)) => (w, h),
            (Some(w), None) => (w, scaled(h0, w0, w)),
            (None, Some(h)) => (scaled(w0, h0, h), h),
            (None, None) => (w0, h0),
        };
    }

    /// Sets an option from a command-line argument `METHOD.KEY=VALUE` (`--opt`), over the
    /// scene file's value; the value is read as [`OptionValue::parse_cli`] reads it.
    pub fn set_cli_option(&mut self, arg: &str) -> Result<(), InputError> {
        let bad = || InputError::new(format!("--opt {arg}"), "expected METHOD.KEY=VALUE");
        let (lhs, value) = arg.split_once('=').ok_or_else(bad)?;
        let (method, key) = lhs.split_once('.').ok_or_else(bad)?;
        if method.is_empty() || key.is_empty() {
            return Err(bad());
        }
        self.options
            .entry(method.to_string())
            .or_default()
            .insert(key.to_string(), OptionValue::parse_cli(value));
        self.cli_options
            .insert((method.to_string(), key.to_string()), arg.to_string());
        Ok(())
    }

    /// An error about option `key` of table `method`, naming where it was written: the
    /// `--opt` argument that set it, else `options.METHOD.KEY` of the scene file (also for a
    /// default the method cannot use).
    pub fn option_error(&self, method: &str, key: &str, message: impl Into<String>) -> InputError {
        match self.cli_options.get(&(method.to_string(), key.to_string())) {
            Some(arg) => InputError::new(format!("--opt {arg}"), message),
            None => InputError::at(&self.source, format!("options.{method}.{key}"), message),
        }
    }

    /// The light of a single-light scene. Methods that render one light at a time only ever
    /// see single-light scenes ([`Scene::with_only_light`]); for a multi-light scene this is
    /// the first light.
    pub fn light(&self) -> &Light {
        &self.lights[0]
    }

    /// Whether the scene has more than one light.
    pub fn is_multi_light(&self) -> bool {
        self.lights.len() > 1
    }

    /// The name of light `k`'s field `object` (written `light` or `light.FIELD`) in messages:
    /// unchanged for a single-light scene, `lights[K]` / `lights[K].FIELD` when the scene has
    /// several lights.
    pub fn light_object(&self, k: usize, object: &str) -> String {
        if self.is_multi_light() {
            format!(
                "lights[{k}]{}",
                object.strip_prefix("light").unwrap_or(object)
            )
        } else {
            object.to_string()
        }
    }

    /// A copy of this scene lit by light `k` alone (same camera, meshes, methods, options).
    pub fn with_only_light(&self, k: usize) -> Scene {
        Scene {
            lights: vec![self.lights[k].clone()],
            ..self.clone()
        }
    }

    /// Axis-aligned bounds (min, max) of all mesh vertices: the extent of every receiver and
    /// occluder, the scale of their rounding errors (a light far away does not change it).
    /// A scene without meshes (refused by validation) gives the light center's point.
    pub fn mesh_bounds(&self) -> (Vec3, Vec3) {
        self.bounds_of(false, |_| true)
    }

    /// Axis-aligned bounds (min, max) of all mesh vertices and every light center.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds_of(true, |_| true)
    }

    /// Axis-aligned bounds (min, max) of the vertices of the meshes `mesh` accepts (by index)
    /// and, with `lights`, of every light center; the first light's center where there is no
    /// point.
    pub fn bounds_of(&self, lights: bool, mesh: impl Fn(usize) -> bool) -> (Vec3, Vec3) {
        let centers = self.lights.iter().map(|l| &l.center).filter(|_| lights);
        let vertices = self
            .meshes
            .iter()
            .enumerate()
            .filter(|(k, _)| mesh(*k))
            .flat_map(|(_, m)| m.positions.iter());
        let mut points = centers.chain(vertices);
        let first = points.next().copied().unwrap_or(self.light().center);
        points.fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
    }
}

#[cfg(test)]
mod tests {
    use super::{Light, LightShape};
    use glam::{DVec3, Vec3};

    /// A light's box holds its extreme points: a disk's rim reaches `radius·√(1 − n_k²)` along
    /// axis k (a disk facing +y is flat in y; one tilted 45° in x–y reaches `r/√2` in x and y).
    #[test]
    fn a_lights_box_is_the_box_of_its_points() {
        let at = |shape| Light {
            center: Vec3::new(1.0, 2.0, 3.0),
            shape,
        };
        let disk = |normal| LightShape::Disk {
            radius: 2.0,
            normal,
        };
        let half = |l: Light| {
            let (lo, hi) = l.bounds();
            assert_eq!(lo + hi, 2.0 * l.center.as_dvec3());
            (hi - lo) / 2.0
        };
        assert_eq!(half(at(disk(Vec3::Y))), DVec3::new(2.0, 0.0, 2.0));
        let tilted = half(at(disk(Vec3::new(1.0, 1.0, 0.0).normalize())));
        assert!((tilted - DVec3::new(2f64.sqrt(), 2f64.sqrt(), 2.0)).length() < 1e-6);
        assert_eq!(
            half(at(LightShape::Sphere { radius: 0.5 })),
            DVec3::splat(0.5)
        );
        let rect = LightShape::Rect {
            u: Vec3::new(1.0, 0.0, 1.0),
            v: Vec3::new(0.0, 0.0, -0.5),
        };
        assert_eq!(half(at(rect)), DVec3::new(1.0, 0.0, 1.5));
        assert_eq!(half(at(LightShape::Point)), DVec3::ZERO);
    }

    /// `--width` or `--height` alone keeps the aspect ratio; both replace both.
    #[test]
    fn resize_keeps_the_aspect_ratio_when_one_side_is_given() {
        let mut s = super::builtin::load("single-quad").unwrap();
        (s.width, s.height) = (320, 240);
        s.resize(Some(64), None);
        assert_eq!((s.width, s.height), (64, 48));
        s.resize(None, Some(100));
        assert_eq!((s.width, s.height), (133, 100), "133.33 rounds down");
        s.resize(Some(2), None);
        assert_eq!((s.width, s.height), (2, 2), "1.5 rounds up");
        s.resize(Some(1), None);
        assert_eq!((s.width, s.height), (1, 1), "never 0");
        s.resize(Some(30), Some(10));
        assert_eq!((s.width, s.height), (30, 10));
        s.resize(None, None);
        assert_eq!((s.width, s.height), (30, 10));
    }
}
