//! `ssv-optimized`: the optimized soft shadow volume algorithm of Paper IV (Assarsson,
//! Dougherty, Mounier, Akenine-Möller, Graphics Hardware 2003).
//!
//! Per light (or per piece of a split light, §5.2):
//! 1. **Pass 1** (Paper III §3.2.1, Paper IV §4.2): the hard shadow quads from the light center
//!    ([`crate::geometry::shadow_volume`]) blend a full value into the split V-buffer
//!    ([`crate::gpu::split_blend`], §4.3): the additive buffer where the V-buffer would be
//!    incremented, the subtractive one where it would be decremented. The V-buffer starts at 1.0
//!    (the additive buffer is cleared to the split of the full value). z-fail (with caps) is
//!    chosen like `hard-sv` does when the eye is in shadow.
//! 2. **Pass 2** (§4.2, §4.4): every silhouette edge's wedge ([`crate::geometry::tight_wedge`],
//!    §4.1) is cut by the hard-quad plane into an inner and an outer half, and **each half is
//!    rendered separately with stencil and depth tests** (§4.4): its front faces set the stencil
//!    to the half's reference where the receiver lies behind them (depth LESS), then its back
//!    faces run the shader where the stencil equals the reference and the receiver lies in front
//!    of them (depth GEQUAL). The shader computes the coverage of the light by the projected
//!    hard shadow quad and blends it through the split table into the additive buffer (inner half)
//!    or the subtractive one (outer half). `split = "plane"` instead renders the whole wedge and
//!    classifies the receiver by the hard-quad plane equation in f32 in the shader — the
//!    approach §4.4 abandoned for its precision errors near the plane.
//! 3. **Resolve**: `V = (add − sub) / full`, clamped to [0, 1].
//!
//! Coverage (the shaders of §4.2): **rectangular lights** (§4.2.2) — the edge is clipped to the
//! light in homogeneous coordinates and projected ([`coverage::projected_edge_in_light`]); the
//! coverage is the light's area between the rays from the light center through the clipped
//! endpoints (area table at the two atan2 angles) minus the triangle (center, p0, p1).
//! **Spherical lights** (§4.2.1) — light space with the receiver at the origin, the light center
//! at z = 1 and radius 1; the edge is clipped to the cone x² + y² = z² (0 < z ≤ 1: between
//! the receiver and the facing disk, [`coverage::clip_to_light_cone`]), projected to z = 1,
//! and the same sector-minus-triangle on the unit disk ([`coverage::sector_minus_triangle`]).
//! `coverage = "tables"` uses the paper's tables ([`crate::light::lookup_tables`]); `"exact"`
//! uses f64 `atan2` and the exact sector area for the sphere, and exact clipping
//! ([`coverage::edge_coverage_exact`]) for the rectangle.
//!
//! Wedges (`wedge`, §4.1, [`LightModel::wedge_halfspaces`]): `tight` (default) is the convex
//! hull of the two end pyramids — over the rectangle's corners, or for a sphere over the
//! `sphere-sides`-gons (3…64, default 8) circumscribing its silhouette disks seen from the end
//! points, cut by Paper III's planes ([`tight_wedge`], "Spheres"); `bounding-sphere` is the
//! paper's baseline, Paper III's wedge of the light's bounding sphere (the sphere through a
//! rectangle's corners; a sphere light itself). On `cube-of-spheres-sphere` at 256² the tight
//! wedges shade 134,160 fragments where Paper III's (`ssv`) shade 157,526; on `cube-of-spheres`
//! 157,733 where `ssv` shades 235,902 and `bounding-sphere` 311,655.
//!
//! Options ([`SsvOptimizedOptions`]): `coverage = tables|exact`, `filter = bilinear|nearest`
//! (area table), `split = stencil|plane`, `wedge = tight|bounding-sphere`, `sphere-sides`
//! (sphere lights with `wedge = tight` only), `overlap = off|loops`, `light-split = 1…4`,
//! `reserved-bits = 1…7` (default 5), `mode = auto|zpass|zfail`, `position = depth|f16`.
//!
//! Shader precision (`[options.gpu] shader`, [`crate::gpu::shader_float`]): the pixel shaders
//! of §4.2 run in the chosen precision — the inside test of a half that crosses the near plane
//! ([`ConvexPolyhedron::shader_contains`]), the clipping and projection of the edge
//! ([`coverage::shader_projected_edge_in_light`], [`coverage::shader_clip_to_light_cone`]), the
//! exact coverage ([`coverage::shader_edge_coverage`], [`AreaShape::shader_sector_fraction`]),
//! with the tables the texture coordinates (the cube-map direction, the area table's
//! `(θ + π)/2π`, the split table's `1023·c`, [`AreaTable::shader_sector_fraction`],
//! [`SplitTable::shader_index`]) and the sector-minus-triangle arithmetic; the texture unit's
//! addressing and filtering and the tables' contents stay as they are. `split = "plane"`'s
//! plane equation runs in f32 at the default precision (the paper's hardware, whose errors
//! near the plane §4.4 reports) and in the shader precision otherwise. The shadow volumes and
//! wedges stay f64: "the test program first generates shadow volumes and wedge geometry on the
//! CPU" (§4.2).
//!
//! Improvements (§5): `overlap = "loops"` renders every silhouette loop
//! ([`crate::geometry::loops::silhouette_loops`]) into its own V-buffer and combines the loops'
//! coverages `c = max(c_A, c_B) + ½·min(c_A, c_B)` (eq. 1), folded over the loops in order;
//! `light-split = k` splits a rectangular light into k×k equal pieces, each with its own
//! silhouettes, and averages their visibilities (§5.2).
//!
//! Choices where the paper is silent or ambiguous:
//! - §4.4 names `GL_GREATER` for the front faces and `GL_LESS` for the back faces but describes
//!   the opposite comparisons ("only passing for fragments with points farther away than the
//!   front-facing triangles"); with our LESS-is-closer depth we implement the description:
//!   front faces LESS, back faces GEQUAL (so a receiver exactly on the shared cut polygon belongs
//!   to exactly one half).
//! - The stencil is not reset per half: each half uses its own reference 1…255 and the stencil
//!   is cleared (counted) every 255 halves.
//! - A half that reaches in front of the near plane (or contains the eye) cannot use the
//!   front-face stencil test; its back faces are drawn without it and the shader tests the
//!   receiver against the half's face planes.
//! - Which half goes to which buffer: §4.3 says "back half → additive, front half →
//!   subtractive"; §3 says the inner half (toward the umbra) adds. We use inner → additive.
//! - Receiver points (`position`): by default the depth-buffer points in f64, like every method
//!   here; `position = "f16"` reads them from the paper's "16 bit per channel float texture"
//!   of world positions (§4.2), each coordinate rounded to binary16 (IEEE half: 11
//!   significant bits, so a point 2 units from the origin moves by up to 2⁻¹⁰). Measured on
//!   256² renders against `depth` (f64 shaders): 237 pixels of `cube-of-spheres` and 217 of
//!   `cube-of-spheres-sphere` move by more than 1/255 (largest 0.40 and 0.39, mean 1.5·10⁻⁴
//!   and 1.4·10⁻⁴), nearly all (200 and 191) on the spheres themselves, where the receiver
//!   lies close to the silhouette edges whose wedges it is tested against.
//! - The overlap approximation renders each loop's quads z-pass (per-loop caps do not exist);
//!   it is refused when the eye is in shadow. Light splitting is for rectangular lights only.
//!
//! Buffer dumps (`--dump-buffers`, [`super::dump`]): `vbuffer-add` and `vbuffer-sub`, the two
//! RGBA8 split buffers before the resolve (carry bits included), each with its saturated
//! channels per pixel and the receiver pixels whose resolved value the clamp changed; one
//! pair per rendered group, named `-loop<l>` with `overlap = loops` and `-piece<k>` with
//! `light_split` > 1. The stencil only marks wedge halves and is not dumped.

use super::dump::{
    receiver_pixels, row_major, BufferDump, DumpValues, ElementFormat, EventKind, EventMap,
};
use super::horizon_clip::{clip_to_horizon, Horizon, HorizonKeys};
use super::output::MethodOutput;
use crate::error::InputError;
use crate::frame::{Frame, BACKGROUND};
use crate::geometry::loops::silhouette_loops;
use crate::geometry::shadow_volume::{shadow_volume_triangles, silhouette_quad, Capping};
use crate::geometry::silhouette::{light_facing, possible_silhouettes};
use crate::geometry::tight_wedge::{
    self, halves_from_planes, polyhedron_from_planes, wedge_clip_box, ConvexPolyhedron, HalfSpace,
    DEFAULT_SPHERE_SIDES,
};
use crate::gpu::buffers::{alloc_tiles, StencilTile};
use crate::gpu::counters::{count, Counters};
use crate::gpu::depth::{DepthFunc, DepthState};
use crate::gpu::probe::{Overflow, PrimitiveKind, ProbeEvent, Raw};
use crate::gpu::raster::{bin, draw, TileDraw};
use crate::gpu::setup::setup_all_culled;
use crate::gpu::setup::{CullMode, RasterTriangle};
use crate::gpu::shader_float::{ShaderFloat, FP16};
use crate::gpu::shader_vec::{SVec2, SVec3};
use crate::gpu::split_blend::{SplitBlend, SplitFormat, SplitTarget, SplitVTile};
use crate::gpu::stencil::{StencilFace, StencilFunc, StencilOp, StencilState};
use crate::gpu::transform::ClipVertex;
use crate::light::coverage::{self, RectLight};
use crate::light::lookup_tables::{AreaShape, AreaTable, Atan2CubeMap, SplitTable, TableFilter};
use crate::methods::hard_sv::CountMode;
use crate::methods::output::BufferPlan;
use crate::methods::precision_spec::{NarrowFormat, OverflowKnobs, PrecisionSpec, StackLight};
use crate::methods::recorder::PassRecorder;
use crate::options::{option_names, option_table, OptionTable};
use crate::scene::LightShape;
use crate::visibility::Visibility;
use glam::{DVec2, DVec3, Vec3};

/// How the shaders compute coverage.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum CoverageMode {
    /// The paper's lookup tables (atan2 cube map, area table) with the given area filter.
    Tables(TableFilter),
    /// Exact arithmetic.
    Exact,
}

/// How a receiver is assigned to the inner or outer wedge half.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum HalfSplit {
    /// Each half rendered separately with stencil and depth tests (§4.4).
    Stencil,
    /// The whole wedge rendered; the hard-quad plane equation in f32 in the shader.
    Plane,
}

/// All settings of one `ssv-optimized` run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Settings {
    /// Coverage computation.
    pub coverage: CoverageMode,
    /// Inner/outer split.
    pub split: HalfSplit,
    /// Overlap approximation per silhouette loop (§5.1).
    pub overlap: bool,
    /// The light is split into k×k pieces (§5.2).
    pub light_split: u32,
    /// The split V-buffer layout (§4.3).
    pub format: SplitFormat,
    /// Use z-fail (with caps) for pass 1.
    pub zfail: bool,
    /// Tighter wedges (§4.1); `false`: Paper III's wedges of the light's bounding sphere
    /// ([`LightModel::wedge_halfspaces`]).
    pub tight_wedges: bool,
    /// Sides of the polygons circumscribing a sphere's silhouette disks in its tight wedges
    /// ([`tight_wedge::sphere_wedge_halfspaces`]).
    pub sphere_sides: usize,
    /// Where the wedge shaders read the receiver point from (module doc, "Shader precision").
    pub position: PositionBuffer,
    /// The receiver's own horizon (`horizon`, [`super::horizon_clip`]), read with the other
    /// options; `stats.json` shows it under its own `"horizon"`.
    #[serde(skip)]
    pub horizon: Horizon,
}

/// A light (or a piece of one) as the shaders see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LightModel {
    /// A rectangle.
    Rect(RectLight),
    /// A sphere.
    Sphere {
        /// Center.
        center: DVec3,
        /// Radius.
        radius: f64,
    },
}

impl LightModel {
    /// The model of a scene light; `None` for shapes `ssv-optimized` does not support.
    pub fn from_shape(center: Vec3, shape: &LightShape) -> Option<Self> {
        match shape {
            LightShape::Rect { u, v } => Some(LightModel::Rect(RectLight::new(
                center.as_dvec3(),
                u.as_dvec3(),
                v.as_dvec3(),
            ))),
            LightShape::Sphere { radius } => Some(LightModel::Sphere {
                center: center.as_dvec3(),
                radius: *radius as f64,
            }),
            _ => None,
        }
    }

    /// The light center (the point silhouettes and hard quads are built from).
    pub fn center(&self) -> DVec3 {
        match self {
            LightModel::Rect(r) => r.center,
            LightModel::Sphere { center, .. } => *center,
        }
    }

    /// The light's bounding sphere: the sphere itself, or for a rectangle the sphere around
    /// its center through its farthest corner (radius the half-diagonal `max(|u + v|, |u − v|)`).
    pub fn bounding_sphere(&self) -> (DVec3, f64) {
        match self {
            LightModel::Rect(r) => (r.center, (r.u + r.v).length().max((r.u - r.v).length())),
            LightModel::Sphere { center, radius } => (*center, *radius),
        }
    }

    /// The facet half-spaces of the wedge of edge `e0 e1` (clipped to the scene box and split
    /// by [`crate::geometry::tight_wedge::halves_from_planes`]):
    /// - `tight`, rectangle: Paper IV §4.1, the hull of the end pyramids over the four corners
    ///   ([`tight_wedge::wedge_halfspaces`]);
    /// - `tight`, sphere: Paper IV §4.1 for a sphere, the hull of the end pyramids over the
    ///   `sphere_sides`-gons (option `sphere-sides`) circumscribing the silhouette disks seen from the end points,
    ///   intersected with Paper III's wedge of the sphere
    ///   ([`tight_wedge::sphere_wedge_halfspaces`]);
    /// - not `tight` (`wedge = bounding-sphere`): Paper III's wedge of the light's bounding
    ///   sphere ([`LightModel::bounding_sphere`], [`tight_wedge::bounding_sphere_halfspaces`])
    ///   — "our previously presented method created wedges from bounding spheres surrounding
    ///   the light source" (Paper IV §4.1); for a sphere light, Paper III's wedge of the sphere.
    ///
    /// A sphere narrower than 10⁻³ rad seen from the edge gets the hull over its bounding
    /// cube in both cases ([`tight_wedge::thin_light_cube`]).
    pub fn wedge_halfspaces(
        &self,
        tight: bool,
        sphere_sides: usize,
        e0: DVec3,
        e1: DVec3,
    ) -> Vec<HalfSpace> {
        match self {
            LightModel::Rect(r) if tight => {
                tight_wedge::wedge_halfspaces(r.center, &r.corners(), e0, e1)
            }
            LightModel::Sphere { center, radius } if tight => {
                tight_wedge::sphere_wedge_halfspaces(*center, *radius, sphere_sides, e0, e1)
            }
            _ => {
                let (center, radius) = self.bounding_sphere();
                tight_wedge::bounding_sphere_halfspaces(center, radius, e0, e1)
            }
        }
    }

    /// The k×k pieces of a rectangle (§5.2), row by row; a sphere only for k = 1.
    pub fn pieces(&self, k: u32) -> Option<Vec<LightModel>> {
        match self {
            _ if k == 1 => Some(vec![*self]),
            LightModel::Rect(r) => {
                let kf = k as f64;
                let mut out = Vec::new();
                for j in 0..k {
                    for i in 0..k {
                        let s = (2 * i + 1) as f64 / kf - 1.0;
                        let t = (2 * j + 1) as f64 / kf - 1.0;
                        out.push(LightModel::Rect(RectLight::new(
                            r.center + r.u * s + r.v * t,
                            r.u / kf,
                            r.v / kf,
                        )));
                    }
                }
                Some(out)
            }
            LightModel::Sphere { .. } => None,
        }
    }

    /// Unsigned coverage of the light by the projected hard shadow quad of edge `e0 e1` seen
    /// from `p` (Paper IV §4.2.1, §4.2.2), in [0, 1].
    pub fn coverage(&self, p: DVec3, e0: DVec3, e1: DVec3, mode: CoverageMode) -> f64 {
        self.shader_coverage::<f64>(p, e0, e1, mode)
    }

    /// [`LightModel::coverage`] computed by the shaders in the shader precision `T` (module
    /// doc, "Shader precision").
    pub fn shader_coverage<T: ShaderFloat>(
        &self,
        p: DVec3,
        e0: DVec3,
        e1: DVec3,
        mode: CoverageMode,
    ) -> T {
        match (self, mode) {
            (LightModel::Rect(r), CoverageMode::Exact) => {
                coverage::shader_edge_coverage::<T>(r, p, e0, e1)
                    .abs()
                    .min(T::one())
            }
            (LightModel::Rect(r), CoverageMode::Tables(_)) => {
                match coverage::shader_projected_edge_in_light::<T>(r, p, e0, e1) {
                    Some([a, b]) => shader_sector_minus_triangle(a, b, AreaShape::Square, mode),
                    None => T::zero(),
                }
            }
            (LightModel::Sphere { center, radius }, _) => {
                match coverage::shader_clip_to_light_cone::<T>(*center, *radius, p, e0, e1) {
                    Some([a, b]) => shader_sector_minus_triangle(a, b, AreaShape::Disk, mode),
                    None => T::zero(),
                }
            }
        }
    }
}

/// The shaders' coverage of §4.2.2 Fig. 6a and §4.2.1 Fig. 5a: the clipped, projected edge
/// `a b` through [`coverage::sector_minus_triangle`], with the sector from the paper's tables
/// (atan2 cube map, area table) or exact ([`coverage::exact_sector_minus_triangle`]).
pub fn sector_minus_triangle(a: DVec2, b: DVec2, shape: AreaShape, mode: CoverageMode) -> f64 {
    shader_sector_minus_triangle(SVec2::from_f64(a), SVec2::from_f64(b), shape, mode)
}

/// [`sector_minus_triangle`] in the shader precision `T` (module doc, "Shader precision"):
/// the atan2 cube map is looked up with the direction `(x, y, 0)` of `a` and `b` in `T` and
/// its angle read as a `T`; the area table's texture coordinates are computed in `T`
/// ([`AreaTable::shader_sector_fraction`]).
pub fn shader_sector_minus_triangle<T: ShaderFloat>(
    a: SVec2<T>,
    b: SVec2<T>,
    shape: AreaShape,
    mode: CoverageMode,
) -> T {
    match mode {
        CoverageMode::Exact => coverage::shader_exact_sector_minus_triangle(a, b, shape),
        CoverageMode::Tables(filter) => {
            let map = Atan2CubeMap::get();
            let angle = |v: SVec2<T>| T::from_f64(map.atan2(v.y.to_f64(), v.x.to_f64()));
            let sector = AreaTable::get(shape).shader_sector_fraction(angle(a), angle(b), filter);
            coverage::shader_sector_minus_triangle(a, b, shape, sector)
        }
    }
}

option_names! {
    /// How the shaders compute coverage (`[options.ssv-optimized] coverage`).
    pub enum CoverageKind {
        /// The paper's lookup tables.
        Tables = "tables",
        /// Exact arithmetic.
        Exact = "exact",
    }
}

/// Where the wedge shaders read each pixel's world position (`[options.ssv-optimized]
/// position`; Paper IV §4.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum PositionBuffer {
    /// The pixel center un-projected at its stored depth, in f64 (every method's receiver).
    Depth,
    /// Paper IV §4.2's 16-bit float RGB texture of world positions: each coordinate of the
    /// un-projected point rounded to binary16.
    F16,
}

option_names!(PositionBuffer {
    Depth = "depth",
    F16 = "f16",
});

option_names!(HalfSplit {
    Stencil = "stencil",
    Plane = "plane",
});

option_names! {
    /// The overlap approximation (`[options.ssv-optimized] overlap`, §5.1).
    pub enum Overlap {
        /// One V-buffer for all silhouettes.
        Off = "off",
        /// One V-buffer per silhouette loop, combined by eq. 1.
        Loops = "loops",
    }
}

option_names! {
    /// The wedges (`[options.ssv-optimized] wedge`, §4.1).
    pub enum WedgeShape {
        /// The hull of the end pyramids.
        Tight = "tight",
        /// Paper III's wedge of the light's bounding sphere.
        BoundingSphere = "bounding-sphere",
    }
}

option_table! {
    /// `[options.ssv-optimized]` (module doc).
    pub struct SsvOptimizedOptions["ssv-optimized"] {
        ..horizon: HorizonKeys,
        /// coverage in the shaders: the paper's lookup tables (Paper IV §4.2) or exact arithmetic
        coverage: CoverageKind = CoverageKind::Tables;
        /// filter of the area table (coverage = tables)
        filter: TableFilter = TableFilter::Bilinear;
        /// wedge halves: rendered apart with stencil and depth tests (Paper IV §4.4), or split by the hard-quad plane in the shader
        split: HalfSplit = HalfSplit::Stencil;
        /// the overlap approximation: one V-buffer per silhouette loop, combined by eq. 1 (Paper IV §5.1)
        overlap: Overlap = Overlap::Off;
        /// wedges: the tight hull of the end pyramids (Paper IV §4.1), or Paper III's wedge of the light's bounding sphere
        wedge: WedgeShape = WedgeShape::Tight;
        /// sides of the polygons around a sphere light's silhouette disks (sphere lights with wedge = tight only)
        sphere_sides: u32 [3..=64] = DEFAULT_SPHERE_SIDES as u32;
        /// a rectangle light split into k×k pieces, each with its own silhouettes (Paper IV §5.2)
        light_split: u32 [1..=4] = 1;
        /// carry bits per channel of the split V-buffer (Paper IV §4.3)
        reserved_bits: u32 [1..=7] = 5;
        /// count pass 1 z-pass or z-fail; auto: z-fail when the near plane is in the shadow of a light center
        mode: CountMode = CountMode::Auto;
        /// receiver positions the wedge shaders read: un-projected from the depth buffer, or a 16-bit float RGB position buffer (Paper IV §4.2)
        position: PositionBuffer = PositionBuffer::Depth;
    }
}

/// Read and check `[options.ssv-optimized]` (module doc).
pub fn options(frame: &Frame) -> Result<Settings, InputError> {
    let scene = frame.scene;
    let o = SsvOptimizedOptions::read(scene)?;
    let bad = |key: &str, msg: &str| scene.option_error(SsvOptimizedOptions::NAME, key, msg);
    let coverage = match o.coverage {
        CoverageKind::Exact => CoverageMode::Exact,
        CoverageKind::Tables => CoverageMode::Tables(o.filter),
    };
    let tight_wedges = o.wedge == WedgeShape::Tight;
    let format = SplitFormat::new(o.reserved_bits).map_err(|e| bad("reserved-bits", &e))?;
    let model = LightModel::from_shape(frame.scene.light().center, &frame.scene.light().shape)
        .ok_or_else(|| {
            InputError::at(
                &frame.scene.source,
                "light",
                "ssv-optimized supports rect and sphere lights",
            )
        })?;
    if SsvOptimizedOptions::is_written(scene, "sphere-sides")
        && !(tight_wedges && matches!(model, LightModel::Sphere { .. }))
    {
        return Err(bad(
            "sphere-sides",
            "sphere-sides shapes the tight wedges of a sphere light only (wedge = tight)",
        ));
    }
    let pieces = model.pieces(o.light_split).ok_or_else(|| {
        bad(
            "light-split",
            "light splitting (Paper IV §5.2) is for rectangular lights",
        )
    })?;
    let centers: Vec<Vec3> = pieces.iter().map(|p| p.center().as_vec3()).collect();
    let zfail = o.mode.zfail(scene, frame.proj.near, &centers);
    let overlap = o.overlap == Overlap::Loops;
    if overlap && zfail {
        return Err(bad(
            "overlap",
            "the overlap approximation renders each silhouette loop z-pass; the eye is in shadow \
             (or mode = zfail)",
        ));
    }
    Ok(Settings {
        coverage,
        split: o.split,
        overlap,
        light_split: o.light_split,
        format,
        zfail,
        tight_wedges,
        sphere_sides: o.sphere_sides as usize,
        position: o.position,
        horizon: o.horizon.into(),
    })
}

/// What a submitted triangle does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Role {
    /// A pass-1 hard shadow volume triangle.
    Quad,
    /// A face of wedge half `h`: front faces mark the stencil.
    Mark(u32),
    /// A face of wedge half `h`: back faces shade where the stencil is marked.
    Shade(u32),
    /// A face of wedge half `h`: back faces shade, inside test in the shader (near plane).
    ShadeTested(u32),
}

/// One wedge (half) to shade.
struct HalfJob {
    /// Silhouette edge, oriented as in its light-facing triangle.
    edge: [DVec3; 2],
    /// Target buffer, or `None` to classify by the plane equation in the shader.
    target: Option<SplitTarget>,
    /// Stencil reference.
    reference: u8,
    /// The polyhedron (for the shader's inside test when the stencil cannot be used).
    shape: ConvexPolyhedron,
    /// Index of the silhouette edge in the group (for probes).
    edge_index: usize,
}

/// Per-tile storage of the method.
struct OptTile {
    v: SplitVTile,
    stencil: StencilTile,
    /// The hierarchical-Z unit's stencil summary of the tile ([`STENCIL_CULLED`]): 1 + the
    /// index of the last half whose front faces wrote its reference into a sample of the tile
    /// since the last stencil clear, 0 for none.
    marked: u32,
}

/// The probe's note for a half's back face rejected for the probed pixel's tile by the
/// hierarchical-Z unit's stencil summary. Within one stencil clear each half has its own
/// reference and only its front faces write it, drawn just before its back faces: a tile
/// where they wrote no sample holds the reference nowhere, so every back-face fragment there
/// would fail the stencil test and do nothing (the summary is the tile's last marking half,
/// one read per (tile, face), counted as one byte of `hiz_read_bytes`; keeping it is not
/// counted, as the zmin/zmax reduction is not).
const STENCIL_CULLED: &str = "culled for the tile by the hierarchical Z (stencil summary): \
     the half's front faces marked no sample of the tile, so none holds its reference";

/// Halves per stencil clear (references 1…255).
const HALVES_PER_CLEAR: usize = 255;

/// The silhouette edges (a, b) of every mesh from light point `c`, and their loops.
fn silhouettes(frame: &Frame, c: Vec3) -> Result<Vec<Vec<[DVec3; 2]>>, InputError> {
    let mut loops = Vec::new();
    for (k, (mesh, adj)) in frame.caster_meshes().into_iter().enumerate() {
        let facing = light_facing(mesh, c);
        let edges = possible_silhouettes(mesh, adj, &facing);
        let mesh_loops = silhouette_loops(&edges)
            .map_err(|e| InputError::at(&frame.scene.source, frame.caster_object(k), e))?;
        for l in mesh_loops {
            loops.push(
                l.iter()
                    .map(|&k| [edges[k].a.as_dvec3(), edges[k].b.as_dvec3()])
                    .collect(),
            );
        }
    }
    Ok(loops)
}

/// What one group rendered: the resolved, clamped visibility per pixel (row-major), the
/// counters, per pixel whether the clamp changed the value, and its buffer dumps (when the
/// frame asks for them).
type GroupResult = (Vec<f32>, Counters, Vec<bool>, Vec<BufferDump>);

/// Render one group (pass 1 quads + the wedges of `edges`) for light piece `light` into a
/// fresh split V-buffer ([`GroupResult`]), the shaders in the precision `T` (module doc,
/// "Shader precision").
fn render_group<T: ShaderFloat>(
    frame: &Frame,
    light: &LightModel,
    quads: Vec<[ClipVertex; 3]>,
    edges: &[[DVec3; 2]],
    s: &Settings,
    receivers: &[Vec<Option<DVec3>>],
) -> GroupResult {
    let tiling = &frame.tiling;
    let format = s.format;
    let table = SplitTable::get(format);
    let full = format.split(format.full());
    let mut tiles = alloc_tiles(tiling, |_, len| OptTile {
        v: SplitVTile::cleared(full, len).recording(frame.dump_buffers),
        stencil: StencilTile::cleared(0, len),
        marked: 0,
    });
    frame.probe_record("clear", |tap, _| {
        tap.event()
            .clear(SplitBlend::buffer(SplitTarget::Add), Raw::Rgba8(full))
    });
    frame.probe_record("clear", |tap, _| {
        tap.event()
            .clear(SplitBlend::buffer(SplitTarget::Sub), Raw::Rgba8([0; 4]))
    });
    frame.probe_record("clear", |tap, _| tap.event().clear("stencil", Raw::U8(0)));
    let (lo, hi) = wedge_clip_box(frame.influence_bounds(true));
    let c = light.center();

    // Wedge halves in edge order (inner, then outer).
    let mut jobs: Vec<HalfJob> = Vec::new();
    for (edge_index, e) in edges.iter().enumerate() {
        match s.split {
            HalfSplit::Stencil => {
                let planes = light.wedge_halfspaces(s.tight_wedges, s.sphere_sides, e[0], e[1]);
                let [inner, outer] = halves_from_planes(&planes, c, e[0], e[1], lo, hi);
                for (shape, target) in [(inner, SplitTarget::Add), (outer, SplitTarget::Sub)] {
                    if !shape.is_empty() {
                        jobs.push(HalfJob {
                            edge: *e,
                            target: Some(target),
                            reference: 0,
                            shape,
                            edge_index,
                        });
                    }
                }
            }
            HalfSplit::Plane => {
                let planes = light.wedge_halfspaces(s.tight_wedges, s.sphere_sides, e[0], e[1]);
                let shape = polyhedron_from_planes(&planes, lo, hi);
                if !shape.is_empty() {
                    jobs.push(HalfJob {
                        edge: *e,
                        target: None,
                        reference: 0,
                        shape,
                        edge_index,
                    });
                }
            }
        }
    }
    for (k, j) in jobs.iter_mut().enumerate() {
        j.reference = (k % HALVES_PER_CLEAR) as u8 + 1;
    }

    let mut counters = Counters::default();
    let chunks: Vec<&[HalfJob]> = if jobs.is_empty() {
        vec![&[]]
    } else {
        jobs.chunks(HALVES_PER_CLEAR).collect()
    };
    for (ci, chunk) in chunks.iter().enumerate() {
        let base = ci * HALVES_PER_CLEAR;
        let mut prims: Vec<[ClipVertex; 3]> = Vec::new();
        let mut roles: Vec<Role> = Vec::new();
        if ci == 0 {
            roles.extend(std::iter::repeat_n(Role::Quad, quads.len()));
            prims.extend(quads.iter().copied());
        } else {
            // Clear the stencil for the next 255 references (counted as written bytes).
            for t in tiles.iter_mut() {
                t.stencil.values.fill(0);
                t.marked = 0;
            }
            count!(counters.stencil_write_bytes += frame.pixel_count() as u64);
            frame.probe_record("stencil-clear", |tap, _| {
                tap.event().clear("stencil", Raw::U8(0))
            });
        }
        for (k, j) in chunk.iter().enumerate() {
            let h = (base + k) as u32;
            let tris: Vec<[ClipVertex; 3]> = j
                .shape
                .faces
                .iter()
                .flat_map(|f| {
                    (1..f.len() - 1).map(move |i| {
                        [f[0], f[i], f[i + 1]].map(|x| frame.proj.clip_point(x.as_vec3()))
                    })
                })
                .collect();
            let near_crossing = tris
                .iter()
                .flatten()
                .any(|v| v.0[3] <= 0.0 || v.0[2] < -v.0[3]);
            if near_crossing {
                roles.extend(std::iter::repeat_n(Role::ShadeTested(h), tris.len()));
                prims.extend(tris);
            } else {
                roles.extend(std::iter::repeat_n(Role::Mark(h), tris.len()));
                prims.extend(tris.iter().copied());
                roles.extend(std::iter::repeat_n(Role::Shade(h), tris.len()));
                prims.extend(tris);
            }
        }
        // Each half is two draw calls (§4.4): its front faces with back faces culled, then
        // its back faces with front faces culled; the quads draw both facings.
        let (tris, c_setup) = setup_all_culled(
            &prims,
            |k| match roles[k] {
                Role::Quad => CullMode::None,
                Role::Mark(_) => CullMode::Back,
                Role::Shade(_) | Role::ShadeTested(_) => CullMode::Front,
            },
            tiling,
        );
        counters += c_setup;
        let bins = bin(tiling, &tris);
        let less = DepthState {
            func: DepthFunc::Less,
            write: false,
        };
        let gequal = DepthState {
            func: DepthFunc::GEqual,
            write: false,
        };
        let zfail = s.zfail;
        let probe = frame.probe_pass("soft-shadow-volumes");
        // The primitive a probe names: a hard-quad triangle or a face of wedge half `h`.
        let primitive = |e: ProbeEvent, tri: &RasterTriangle| match roles[tri.prim as usize] {
            Role::Quad => e.primitive(
                PrimitiveKind::ShadowQuad,
                tri.prim,
                "",
                Some(tri.front_facing),
            ),
            Role::Mark(h) | Role::Shade(h) | Role::ShadeTested(h) => {
                let job = &jobs[h as usize];
                let half = match job.target {
                    Some(SplitTarget::Add) => "inner half",
                    Some(SplitTarget::Sub) => "outer half",
                    None => "whole wedge",
                };
                let detail = format!("{half} of silhouette edge {}", job.edge_index);
                e.primitive(PrimitiveKind::HalfWedge, h, detail, Some(tri.front_facing))
            }
        };
        counters += draw(
            tiling,
            &mut tiles,
            &tris,
            &bins,
            probe.as_ref(),
            |t, st, tri, cnt| {
                if let (true, Role::Shade(h)) = (frame.gpu.hiz, roles[tri.prim as usize]) {
                    count!(cnt.hiz_read_bytes += 1);
                    if st.marked != h + 1 {
                        count!(cnt.tiles_culled_hiz += 1);
                        if let Some(probe) = &probe {
                            probe.record_culled(t, tri, None, STENCIL_CULLED, |tap| {
                                primitive(tap.event(), tri)
                            });
                        }
                        return TileDraw::Skip;
                    }
                }
                // The depth-test outcome on which the role's fragment does nothing: a quad
                // counts on a pass (z-pass) or a fail (z-fail); a front face marks the stencil
                // only where LESS passes; a back face shades only where GEQUAL passes.
                let (func, idle) = match roles[tri.prim as usize] {
                    Role::Quad => (less.func, zfail),
                    Role::Mark(_) => (less.func, false),
                    Role::Shade(_) | Role::ShadeTested(_) => (gequal.func, false),
                };
                frame.hiz_depth_draw(t, tri, (func, idle), cnt, probe.as_ref(), |tap| {
                    primitive(tap.event(), tri)
                })
            },
            |t, st, tri, f, cnt, tap| match roles[tri.prim as usize] {
                Role::Quad => {
                    let (pass, z) = frame.tiles[t].depth.test(&less, &f, cnt);
                    count!(cnt.depth_passed += pass as u64);
                    // z-pass: front faces passing decrement, back faces increment.
                    // z-fail: back faces failing decrement, front faces failing increment.
                    let target = match (zfail, pass, tri.front_facing) {
                        (false, true, true) | (true, false, false) => Some(SplitTarget::Sub),
                        (false, true, false) | (true, false, true) => Some(SplitTarget::Add),
                        _ => None,
                    };
                    let blend = target.map(|target| st.v.blend(target, f.local, full, cnt));
                    if let Some(tap) = tap {
                        let e = primitive(tap.event(), tri);
                        let e = frame.tiles[t]
                            .depth
                            .record_test(e, less.func, f.local, z, pass);
                        tap.push(match blend {
                            Some(b) => b.record(e.value("split value", format.full() as f64)),
                            None => e.note("no count"),
                        });
                    }
                }
                Role::Mark(h) => {
                    let job = &jobs[h as usize];
                    let (pass, z) = frame.tiles[t].depth.test(&less, &f, cnt);
                    let face = StencilFace {
                        func: StencilFunc::Always,
                        reference: job.reference,
                        read_mask: 0xFF,
                        write_mask: 0xFF,
                        stencil_fail: StencilOp::Keep,
                        depth_fail: StencilOp::Keep,
                        depth_pass: StencilOp::Replace,
                    };
                    let state = StencilState {
                        front: face,
                        back: face,
                    };
                    let update = st.stencil.apply(&state, true, &f, pass, cnt);
                    if pass {
                        st.marked = h + 1;
                    }
                    if let Some(tap) = tap {
                        let e = primitive(tap.event(), tri);
                        let e = frame.tiles[t]
                            .depth
                            .record_test(e, less.func, f.local, z, pass);
                        let e = e.value("reference", job.reference as f64);
                        tap.push(update.record(e, "stencil"));
                    }
                }
                Role::Shade(h) | Role::ShadeTested(h) => {
                    let job = &jobs[h as usize];
                    let tested = matches!(roles[tri.prim as usize], Role::ShadeTested(_));
                    // The watched fragment's event, built only there: what it saw up to
                    // where it stopped.
                    let record = |build: &dyn Fn(ProbeEvent) -> ProbeEvent| {
                        if let Some(tap) = tap {
                            tap.push(build(primitive(tap.event(), tri)));
                        }
                    };
                    let stored = (!tested).then(|| {
                        count!(cnt.stencil_read_bytes += 1);
                        st.stencil.values[f.local]
                    });
                    let seen_stencil = |e: ProbeEvent| match stored {
                        Some(v) => e
                            .value("reference", job.reference as f64)
                            .value("stencil", v as f64),
                        None => e,
                    };
                    if stored.is_some_and(|v| v != job.reference) {
                        return record(&|e| {
                            seen_stencil(e).note("stencil ≠ reference: not in this half")
                        });
                    }
                    let (pass, z) = frame.tiles[t].depth.test(&gequal, &f, cnt);
                    let seen_depth = |e: ProbeEvent| {
                        let depth = &frame.tiles[t].depth;
                        depth.record_test(seen_stencil(e), gequal.func, f.local, z, pass)
                    };
                    if !pass {
                        return record(&|e| seen_depth(e).note("receiver behind the back face"));
                    }
                    count!(cnt.depth_passed += 1);
                    let Some(p) = receivers[t][f.local] else {
                        return record(&|e| seen_depth(e).note("background"));
                    };
                    if tested && !job.shape.shader_contains::<T>(p, 0.0) {
                        count!(cnt.shader_discards += 1);
                        return record(&|e| {
                            seen_depth(e).note("receiver outside the half (shader test)")
                        });
                    }
                    count!(cnt.fragments_shaded += 1);
                    let target = job.target.unwrap_or_else(|| {
                        plane_split_target::<T::AtMostFp32>(light.center(), &job.edge, p)
                    });
                    let cov = light.shader_coverage::<T>(p, job.edge[0], job.edge[1], s.coverage);
                    let split = table.shader_lookup(cov);
                    let cov = cov.to_f64();
                    let blend = st.v.blend(target, f.local, split, cnt);
                    record(&|e| {
                        let e = seen_depth(e)
                            .value("coverage", cov)
                            .value("split value", format.reconstruct(split) as f64);
                        blend.record(e)
                    });
                }
            },
        );
    }
    let flat: Vec<f64> = tiles
        .iter()
        .flat_map(|t| (0..t.v.add.len()).map(|i| t.v.resolve(format, i)))
        .collect();
    let values = tiling.to_row_major(&flat);
    let clamped: Vec<bool> = values.iter().map(|v| !(0.0..=1.0).contains(v)).collect();
    let vis: Vec<f32> = values.iter().map(|v| v.clamp(0.0, 1.0) as f32).collect();
    frame.probe_record("resolve-group", |tap, i| {
        let [x, y] = [i as u32 % tiling.width, i as u32 / tiling.width];
        let (tile, local) = (&tiles[tiling.tile_of(x, y)].v, tiling.local(x, y));
        tap.push(tap.event().read(
            SplitBlend::buffer(SplitTarget::Add),
            Raw::Rgba8(tile.add[local]),
        ));
        tap.event()
            .read(
                SplitBlend::buffer(SplitTarget::Sub),
                Raw::Rgba8(tile.sub[local]),
            )
            .value("V", values[i])
            .resolve(&[vis[i]], clamped[i])
            .note("(add − sub)/full, clamped to [0, 1]")
    });
    let dumps = if frame.dump_buffers {
        split_dumps(frame, s, &tiles, &clamped)
    } else {
        Vec::new()
    };
    (vis, counters, clamped, dumps)
}

/// The dumps of a group's two split buffers (module doc): the raw RGBA8 pixels, the
/// saturated channels, and the receiver pixels among `clamped`.
fn split_dumps(
    frame: &Frame,
    s: &Settings,
    tiles: &[OptTile],
    clamped: &[bool],
) -> Vec<BufferDump> {
    let tiling = &frame.tiling;
    let clamped: Vec<bool> = clamped
        .iter()
        .zip(receiver_pixels(frame))
        .map(|(c, r)| *c && r)
        .collect();
    [
        ("vbuffer-add", 0, "additive"),
        ("vbuffer-sub", 1, "subtractive"),
    ]
    .into_iter()
    .map(|(name, k, which)| {
        let pixels = row_major(tiling, tiles, |t| if k == 0 { &t.v.add } else { &t.v.sub });
        BufferDump::new(
            name,
            &format!(
                "the {which} RGBA8 buffer of the split V-buffer (Paper IV §4.3): the value \
                     over R, G, B, A, {} carry bits per channel, blended with saturation; \
                     visibility = clamp((add − sub)/{}, 0, 1)",
                s.format.reserved_bits,
                s.format.full()
            ),
            (frame.scene.width, frame.scene.height),
            ElementFormat::SplitRgba8(s.format),
            DumpValues::U8(pixels.concat()),
        )
        .with_events(EventMap::new(
            EventKind::Saturate,
            row_major(tiling, tiles, |t| &t.v.saturations[k]),
            clamped.clone(),
        ))
    })
    .collect()
}

/// The plane-equation split (§4.4's first approach): the sign of the hard-quad plane equation
/// evaluated at the receiver by the shader in the precision `S`; inner (≤ 0, see
/// [`crate::geometry::tight_wedge::quad_inner_halfspace`]) adds. [`render_group`] evaluates it
/// in the shader precision capped at fp32 ([`ShaderFloat::AtMostFp32`]): f32 at the default,
/// the precision whose errors near the plane §4.4 reports.
fn plane_split_target<S: ShaderFloat>(c: DVec3, e: &[DVec3; 2], p: DVec3) -> SplitTarget {
    let c = SVec3::<S>::from_f64(c);
    let (a, b, p) = (
        SVec3::from_f64(e[0]),
        SVec3::from_f64(e[1]),
        SVec3::from_f64(p),
    );
    let n = (a - c).cross(b - c);
    if n.dot(p - c) <= S::zero() {
        SplitTarget::Add
    } else {
        SplitTarget::Sub
    }
}

/// The receiver point of every sample, tile-major (`None` for background), as the wedge
/// shaders read it (`position`, module doc): the pixel center un-projected at its stored
/// depth, in f64, or that point stored in the 16-bit float RGB position buffer of Paper IV
/// §4.2 (each coordinate rounded to binary16, [`FP16`]).
fn receiver_tiles(frame: &Frame, position: PositionBuffer) -> Vec<Vec<Option<DVec3>>> {
    let tiling = &frame.tiling;
    let stored = |p: DVec3| match position {
        PositionBuffer::Depth => p,
        PositionBuffer::F16 => DVec3::new(FP16.round(p.x), FP16.round(p.y), FP16.round(p.z)),
    };
    (0..tiling.tile_count())
        .map(|t| {
            let r = tiling.rect(t);
            let mut out = vec![None; tiling.tile_len()];
            for y in r.y0..r.y1 {
                for x in r.x0..r.x1 {
                    let i = tiling.local(x, y);
                    if frame.tiles[t].prim[i] != BACKGROUND {
                        let z = frame.gpu.depth.to_window(frame.tiles[t].depth.values[i]);
                        out[i] = Some(stored(frame.proj.unproject(x, y, z)));
                    }
                }
            }
            out
        })
        .collect()
}

/// The visibility of one light piece (row-major, clamped) with the settings' overlap mode, the
/// counters, per pixel whether a clamp changed a value, and the buffer dumps of its groups;
/// the shaders in the precision `T`.
fn piece_visibility<T: ShaderFloat>(
    frame: &Frame,
    light: &LightModel,
    s: &Settings,
    receivers: &[Vec<Option<DVec3>>],
) -> Result<GroupResult, InputError> {
    let c = light.center().as_vec3();
    let loops = silhouettes(frame, c)?;
    if !s.overlap {
        let meshes = frame.caster_meshes();
        let capping = if s.zfail {
            Capping::Capped
        } else {
            Capping::Open
        };
        let quads = shadow_volume_triangles(&meshes, c, &frame.proj, capping);
        let edges: Vec<[DVec3; 2]> = loops.into_iter().flatten().collect();
        return Ok(render_group::<T>(frame, light, quads, &edges, s, receivers));
    }
    // §5.1: per loop, coverage c_l = 1 − V_l, combined c = max + ½·min, folded in loop order.
    let mut covered = vec![0.0f32; frame.pixel_count()];
    let mut clamped = vec![false; frame.pixel_count()];
    let mut counters = Counters::default();
    let mut dumps = Vec::new();
    frame.probe_record("overlap", |tap, _| {
        tap.event().clear("coverage", Raw::f32(0.0))
    });
    for (k, l) in loops.iter().enumerate() {
        let quads: Vec<[ClipVertex; 3]> = l
            .iter()
            .flat_map(|e| silhouette_quad(&frame.proj, c, e[0].as_vec3(), e[1].as_vec3()))
            .collect();
        let scope = frame
            .probe
            .as_ref()
            .map(|p| p.enter(|sc| sc.group = Some(k as u32)));
        let (v, cnt, cl, group_dumps) = render_group::<T>(frame, light, quads, l, s, receivers);
        drop(scope);
        dumps.extend(group_dumps.into_iter().map(|mut d| {
            d.name = format!("{}-loop{k}", d.name);
            d.about = format!("silhouette loop {k} alone (§5.1): {}", d.about);
            d
        }));
        counters += cnt;
        let before = frame.probe.as_ref().map(|_| covered.clone());
        for (acc, v) in covered.iter_mut().zip(&v) {
            *acc = overlap_combine(*acc, 1.0 - v);
        }
        frame.probe_record("overlap", |tap, i| {
            let before = before.as_ref().map_or(0.0, |b| b[i]);
            tap.event()
                .value("loop", k as f64)
                .value("loop coverage", (1.0 - v[i]) as f64)
                .write(
                    "coverage",
                    Raw::f32(before),
                    Raw::f32(covered[i]),
                    Overflow::Clamp,
                    0,
                )
                .note("c = max(c_A, c_B) + ½·min(c_A, c_B) (§5.1 eq. 1)")
        });
        for (a, b) in clamped.iter_mut().zip(cl) {
            *a |= b;
        }
    }
    for (a, c) in clamped.iter_mut().zip(&covered) {
        *a |= *c > 1.0;
    }
    Ok((
        covered.iter().map(|c| 1.0 - c.min(1.0)).collect(),
        counters,
        clamped,
        dumps,
    ))
}

/// Paper IV §5.1 eq. 1: `c = max(c_A, c_B) + ½·min(c_A, c_B)`.
pub fn overlap_combine(a: f32, b: f32) -> f32 {
    a.max(b) + 0.5 * a.min(b)
}

/// `ssv-optimized`'s pinned golden renders ([`crate::methods::Method::goldens`]).
const GOLDENS: &[crate::methods::Golden] = &[
    crate::methods::Golden::new("cube-of-spheres"),
    crate::methods::Golden::new("single-quad"),
    crate::methods::Golden::new("cylinder"),
    crate::methods::Golden::new("eye-in-shadow"),
    crate::methods::Golden::new("two-lights"),
    crate::methods::Golden::new("scenes/real/hand.toml"),
    crate::methods::Golden::new("scenes/real/bob.toml"),
    // ssv-optimized: overlap approximation, light split, plane split, exact coverage, filter,
    // bounding-sphere wedges, a sphere's tight wedges over squares.
    crate::methods::Golden::variant("cube-of-spheres", "overlap", &[("overlap", "loops")]),
    crate::methods::Golden::variant("single-quad", "split2", &[("light-split", "2")]),
    crate::methods::Golden::variant("single-quad", "plane", &[("split", "plane")]),
    crate::methods::Golden::variant("cube-of-spheres", "exact", &[("coverage", "exact")]),
    crate::methods::Golden::variant("cube-of-spheres", "nearest", &[("filter", "nearest")]),
    crate::methods::Golden::variant(
        "cylinder",
        "bounding-sphere",
        &[("wedge", "bounding-sphere")],
    ),
    crate::methods::Golden::variant("cylinder", "sides4", &[("sphere-sides", "4")]),
    crate::methods::Golden::variant("cube-of-spheres", "shader-fp24", &[])
        .gpu(&[("shader", "fp24")]),
    crate::methods::Golden::variant("cube-of-spheres", "shader-fp16", &[])
        .gpu(&[("shader", "fp16")]),
    crate::methods::Golden::variant("cube-of-spheres", "position-f16", &[("position", "f16")]),
];

/// `ssv-optimized`'s configurations in the accuracy–time sweep ([`crate::methods::Method::sweep`]).
const SWEEP: &[crate::methods::OptionPairs] = &[
    &[],
    &[("filter", "nearest")],
    &[("coverage", "exact")],
    &[("light-split", "2")],
    &[("light-split", "3")],
    &[("light-split", "4")],
    &[("overlap", "loops")],
    &[("horizon", "clip")],
];

/// What the precision experiment measures of it ([`crate::experiment::precision`]): Paper IV's split V-buffer with 1…7 carry bits and its f16 position buffer.
const PRECISION: PrecisionSpec = PrecisionSpec {
    shader_arithmetic: true,
    storage: &[
        NarrowFormat::of("reserved-bits", "3", "5"),
        NarrowFormat::of("reserved-bits", "7", "5"),
        NarrowFormat::of("position", "f16", "depth"),
    ],
    overflow: &[
        OverflowKnobs::of(StackLight::Rect, &[("reserved-bits", "1")]),
        OverflowKnobs::of(StackLight::Rect, &[("reserved-bits", "3")]),
        OverflowKnobs::of(StackLight::Rect, &[("reserved-bits", "5")]),
        OverflowKnobs::of(StackLight::Rect, &[("reserved-bits", "7")]),
    ],
};

/// `ssv-optimized` in the registry ([`crate::methods::ALL`]).
pub const METHOD: crate::methods::Method = crate::methods::Method {
    name: "ssv-optimized",
    paper: "Paper IV: optimized soft shadow volumes, GH 2003",
    // Paper IV §4.2: the rectangular and the spherical shader.
    supports: |s| matches!(s, LightShape::Rect { .. } | LightShape::Sphere { .. }),
    lights: crate::methods::SeveralLights::PerLight,
    options: crate::methods::OptionTableSpec::of::<SsvOptimizedOptions>(),
    bytes_per_pixel: 96,
    bytes_per_triangle: 208,
    default_run: crate::methods::DefaultRun::EveryScene,
    sums_per_silhouette_edge: true,
    table_note: |_| None,
    check: |frame| options(frame).map(drop),
    run,
    goldens: GOLDENS,
    sweep: SWEEP,
    precision: PRECISION,
};

/// Run `ssv-optimized` on a rendered frame.
pub fn run(frame: &Frame) -> Result<MethodOutput, InputError> {
    let mut rec = PassRecorder::new(frame, "ssv-optimized");
    let s = options(frame)?;
    let model = LightModel::from_shape(frame.scene.light().center, &frame.scene.light().shape)
        .expect("options checked the shape");
    let pieces = model
        .pieces(s.light_split)
        .expect("options checked the split");
    rec.uses(BufferPlan::stencil8());
    rec.uses(BufferPlan {
        name: "v-buffer".into(),
        format: format!(
            "2×RGBA8 split {}-bit ({} carry bits per channel)",
            s.format.value_bits(),
            s.format.reserved_bits
        ),
        bytes_per_sample: 8,
    });
    if s.position == PositionBuffer::F16 {
        rec.uses(BufferPlan {
            name: "position".into(),
            format: "RGB16F (world positions, Paper IV §4.2)".into(),
            bytes_per_sample: 6,
        });
    }
    rec.uses_hiz_depth();
    if frame.gpu.hiz {
        rec.uses(BufferPlan::hiz_stencil_summary(&frame.gpu));
    }
    let prims = frame.prim_ids();
    let vis = rec.pass("soft-shadow-volumes", |pass| {
        pass.set_runs(pieces.len() as u64);
        let receivers = receiver_tiles(frame, s.position);
        let mut sum = vec![0.0f32; frame.pixel_count()];
        let mut clamped = vec![false; frame.pixel_count()];
        for (k, piece) in pieces.iter().enumerate() {
            let scope = frame
                .probe
                .as_ref()
                .filter(|_| pieces.len() > 1)
                .map(|p| p.enter(|sc| sc.piece = Some(k as u32)));
            // The shader precision is chosen once per piece's pass.
            let (v, c, cl, piece_dumps) = crate::with_shader_float!(frame.gpu.shader, T => {
                piece_visibility::<T>(frame, piece, &s, &receivers)
            })?;
            drop(scope);
            pass.record("pieces", |tap, i| {
                tap.event()
                    .value("piece", k as f64)
                    .value("visibility", v[i] as f64)
            });
            for mut d in piece_dumps {
                if pieces.len() > 1 {
                    d.name = format!("{}-piece{k}", d.name);
                    d.about = format!("light piece {k} alone (§5.2): {}", d.about);
                }
                pass.dump(|| d);
            }
            pass.count(c);
            for (acc, v) in sum.iter_mut().zip(&v) {
                *acc += v;
            }
            for (a, b) in clamped.iter_mut().zip(cl) {
                *a |= b;
            }
        }
        let n = pieces.len() as f32;
        let vis: Vec<f32> = sum
            .iter()
            .zip(prims)
            .map(|(v, p)| {
                if *p == BACKGROUND {
                    1.0
                } else {
                    (v / n).clamp(0.0, 1.0)
                }
            })
            .collect();
        pass.record("resolve", |tap, i| {
            tap.event()
                .resolve(&[vis[i]], clamped[i] && prims[i] != BACKGROUND)
                .note(if prims[i] == BACKGROUND {
                    "background: lit".to_string()
                } else {
                    format!("mean of {} light piece(s), clamped to [0, 1]", pieces.len())
                })
        });
        pass.clamped(
            clamped
                .iter()
                .zip(prims)
                .filter(|(c, p)| **c && **p != BACKGROUND)
                .count() as u64,
        );
        Ok::<_, InputError>(vis)
    })?;
    let (visibility, horizon) = clip_to_horizon(&mut rec, s.horizon, Visibility::Gray(vis));
    Ok(rec.finish(
        visibility,
        serde_json::json!({ "resolved": s, "horizon": horizon, "gpu": frame.gpu }),
    ))
}
