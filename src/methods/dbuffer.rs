//! `dbuffer`: umbra and penumbra volumes rendered into a D-buffer (*Soft shadows with correct
//! boundaries from umbra and penumbra volumes*, CGI 2004) — the one method whose shadow
//! *boundaries* come from two silhouettes of the area light instead of one silhouette seen
//! from its center, for one circular disk light.
//!
//! # Passes
//!
//! 1. **Volumes** (§2.1, CPU): face classification against the whole disk, the umbra- and
//!    penumbra-volume silhouettes, their quads extruded through the tangent points of the
//!    circle, trimmed or closed with fans at the corners, and the silhouette faces that do not
//!    face c appended to the umbra volume (§3.3) — [`crate::geometry::umbra_penumbra`], every
//!    choice documented there.
//! 2. **D-buffer** (§2.2, §3): one RGBA render target of `map-size`² texels
//!    (`storage = f32|f16` per channel, [`RgbaTile`]) seen from the light center through the
//!    light view ([`crate::gpu::light_view`]; fitted around the scene, depth format `depth`),
//!    filled by three draws that each own some of its channels by colour masking
//!    ([`ColorMask`]) and clear the depth buffer before they start. Every vertex goes through
//!    the vertex program of §3.2, "the z-coordinate of the vertices is calculated as the
//!    distance between the vertex and c" ([`LightView::distance_clip_point`], over the range
//!    [0, [`DBufferRender::range`]]), and hands its distance |cX| to the fragment as a
//!    varying; the rasterizer interpolates both linearly across the triangle (depth in window
//!    space, varyings perspective-correctly, i.e. linearly in the triangle's plane), which is
//!    the paper's "linearly distributed values instead of spherically distributed values"
//!    artifact: on a plane the true distance is convex, so an interpolated one is too long
//!    inside large triangles (reproduced, pinned in the tests).
//!    * **R = |cx_o|** (`dbuffer-scene`): every mesh, back faces culled, depth LESS from 1:
//!      the nearest surface, a distance shadow map ("in the case where x is not placed in the
//!      umbra region |cx_o| and |cx| will be the same", §3.1, so receivers are drawn too).
//!      The paper gives no bias; without one the lit side of every occluder shadows itself
//!      wherever the texel's ray meets the surface farther than the receiver. We add the
//!      shadow maps' polygon offset ([`PolygonOffset`], `bias` units and `slope-bias`, as
//!      `penumbra-map`) to the fragment's depth and, in distance units (× range), to the
//!      stored distance.
//!    * **G = |cx_uv|, A = |cx_s|** (`dbuffer-umbra`): the umbra volume, both facings, depth
//!      GREATER from 0 — §4: "choose the geometry with the greatest distance from the light
//!      source. This can be done using depth test when rendering to the D-Buffer".
//!    * **B = |cx_pv|, A = |cx_s|** (`dbuffer-penumbra`): the penumbra volume, the same.
//!      The paper keeps one |cx_s| channel for both volumes ("generated simultaneously with
//!      |cx_uv| and |cx_pv|"); where a texel's ray crosses both volumes (overlapping
//!      occluders), the penumbra draw writes it last and the umbra branch reads the penumbra
//!      edge's |cx_s| — one of the overlap artifacts (such texels are counted,
//!      [`DBufferStats::shared_a_texels`]).
//!
//!    **|cx_s|** (eq. 2) is computed per vertex at its silhouette point e
//!    ([`crate::geometry::umbra_penumbra`], "Output"), as printed:
//!    `|cx_s| = (dir(c, x)·n)/(dir(c, e)·n)·dist(c, e)` with n the disk's normal. It is
//!    dist(c, e) on the silhouette itself; elsewhere it is not the distance along the ray to
//!    the silhouette's depth, h_e/(dir(c, x)·n), which the inverted ratio would give — the two
//!    differ to first order in the angle between the directions. The inverted ratio changed
//!    the RMSE vs `raycast` by at most 0.0017 on each of five disk scenes at 256² (measured
//!    during development, not kept as an option), so the printed one stays. A vertex whose
//!    ratio is not finite (e at the light's height) gets dist(c, e), counted.
//!
//!    **Distances** (`distances`): `interpolated` (default) is the paper's vertex program;
//!    `exact` computes, per fragment, the distance along the texel's ray from c to the
//!    triangle's plane and writes it as the fragment's depth too (for R, the polygon offset's
//!    slope is then the change of that distance to the next texel), to measure what the
//!    linear-interpolation artifact costs.
//!
//!    **Early Z** in the scene draw, with interpolated distances and `[options.gpu] hiz = on`
//!    (`early_z_applies`; `docs/architecture.md`, "Hierarchical Z").
//!
//!    Clear values: R = range (nothing nearer), G = B = A = 0 ("no volume on this ray"; every
//!    volume distance is positive).
//! 3. **Screen** (§4): per pixel, the visible triangle's point x at the pixel center
//!    ([`Frame::primary_ray_receivers`], as a forward pass's interpolated position), its
//!    light-view texel, read with nearest filtering (float textures of the NV30 generation had
//!    no filtering; [`LightView::nearest_texel`]), and the fragment program
//!    [`screen_program`]:
//!    * x is on the **umbra side** when the D-buffer's surface is nearer than x, |cx| > |cx_o|
//!      (x is in the hard shadow of c), else on the **penumbra side**. Eq. 3 prints its first
//!      (umbra-side) branch for |cx| < |cx_o|; with |cx_o| as §3.1 defines it that inequality
//!      holds nowhere on a visible receiver, so we read it as the shadow-map test it stands
//!      for (the umbra side is where the occluder lies between c and x);
//!    * umbra side: no umbra volume on the ray (G = 0) or x before it (|cx| < |cx_uv|):
//!      **umbra**, V = 0; else the first branch of eq. 3, t =
//!      |cx_s|(|cx| − |cx_uv|) / (2|cx_uv|·D) with D = |cx| − |cx_s| (printed:
//!      |cx_uv| − |cx_s|; below);
//!    * penumbra side: no penumbra volume (B = 0) or x before it (|cx| < |cx_pv|): **lit**,
//!      V = 1; else the second branch, t = 1 − |cx_s|(|cx| − |cx_pv|) / (2|cx_pv|·D), D =
//!      |cx| − |cx_s| (printed: |cx_pv| − |cx_s|);
//!    * V = 3t² − 2t³ (eq. 4, `falloff = smoothstep`) or √t (§6.2, `falloff = sqrt`).
//!
//!    **Eq. 3's denominator** (`eq3`). In the paper's 2D projection (Fig. 4), with
//!    depths h (silhouette), z_v (volume crossing) and z (x) along the ray, the line from x
//!    over the silhouette meets the light at (1 − 2t)·r from its center, which gives
//!    t = h(z − z_v) / (2 z_v (z − h)) on the umbra side (mirrored on the other): this is the
//!    printed eq. 3 with **(|cx| − |cx_s|)** where it prints (|cx_uv| − |cx_s|). The printed
//!    form agrees at the volume (t = 0, with the same slope: it is the linearization there) but
//!    contradicts the paper's own derivation of the second branch, "observing symmetry around
//!    c where t = ½": on the ray through the silhouette (|cx_uv| = |cx_s|) the printed t is
//!    s(d − s)/0, the corrected one ½ for every x. Rendered as printed, the rays through the
//!    silhouette faces of §3.3 (whose |cx_uv| and |cx_s| are the same distances) divide by 0,
//!    the inner penumbra next to c's hard-shadow line gets t > 1 (lit) and the outer penumbra
//!    next to it t < 0 (black): bright and black rings the paper's figures do not show
//!    (RMSE vs `raycast` 1.8–3.9 times the corrected formula's on the disk built-ins,
//!    `docs/dbuffer.md`). So `eq3 = corrected` is the default and `eq3 = printed` reproduces
//!    the printed arithmetic. With the corrected denominator t stays in [0, ½] on the umbra
//!    side and [½, 1] on the other whenever z ≥ z_v ≥ h.
//!    A denominator that is not positive (or a t that is not finite) is **degenerate**: t = ½
//!    (the corrected formula's value at the silhouette), counted. t outside [0, 1] is counted
//!    before it is clamped to [0, 1] (`saturate`), and those pixels are
//!    [`super::output::MethodStats::clamped_pixels`]; V of a clamped t is in [0, 1] up to the
//!    rounding of the falloff, and is saturated to [0, 1] as the fragment's colour output.
//!
//!    **Shader precision** (`[options.gpu] shader`, [`crate::gpu::shader_float`]): the screen
//!    pass's fragment program — §2.2: "the second render-pass renders the objects in screen
//!    space using a fragment program to calculate visibility. This fragment program uses the
//!    distances from the D-buffer by performing a texture look-up and calculates the
//!    visibility using the retrieved values" — runs in the chosen precision (the paper's
//!    QuadroFX 3000, §5, computes in fp32): |cx| from the interpolated receiver position
//!    ([`receiver_distance`]), the texel's four distances as the program reads them, the side
//!    and region comparisons, eq. 3's t ([`parameter_t`]), V(t) ([`Falloff::apply`]) and the
//!    saturation of V. What stays f64: the volumes (§2.1, built on the CPU), the vertex
//!    program of §3.2 (the distances |cX| and eq. 2's |cx_s| per vertex, as the vertex stage
//!    computes everything in this project), the rasterizer's interpolation of those
//!    distances into the D-buffer and its storage (`storage`, f32 or f16); and the D-buffer
//!    draws' own additions the paper has no fragment program for — the R channel's bias and
//!    the per-fragment `distances = exact` — which are measurement devices, not the method.
//!
//!    The stencil buffer of §6.2 ("used to avoid overwriting umbra regions") is not needed: the
//!    screen pass computes each pixel's V once, from the D-buffer, with nothing drawn over it.
//!
//! Buffer dumps (`--dump-buffers`, [`super::dump`]): `dbuffer`, the RGBA target at the map
//! size as stored (R |cx_o|, G |cx_uv|, B |cx_pv|, A |cx_s|), with its non-finite writes; and
//! `t`, per pixel eq. 3's t before the clamp (f64, NaN where the screen program computed none:
//! umbra, lit, degenerate, background), with the pixels whose t the clamp changed — the
//! method's `clamped_pixels`.
//!
//! # Several crossings (concave and overlapping occluders, §4 case 1)
//!
//! The D-buffer holds one distance per volume and texel: where the ray from c crosses a
//! volume's surface more than once — a concave occluder, whose silhouettes from the disk are
//! many loops (a real mesh: legs, horns, folds of the surface), or overlapping occluders —
//! §4 keeps the farthest crossing, and eq. 3 then measures the receiver against a crossing
//! that is not the one between it and the light (often one beyond the receiver, under the
//! floor, which makes the receiver umbra or lit: the hard shadow). The paper says the
//! artifact stays in the occluder's self-shadow; on real meshes it takes the floor's
//! penumbra too (Spot the cow, `scenes/real/spot-disk.toml`: `docs/dbuffer.md`, "Real
//! meshes"). Keeping instead the farthest crossing in front of the last surface of the ray
//! was tried and measured worse (mean |e| over whole-light receivers 0.0156 against 0.0142 at
//! 128²): with overlapping penumbrae no single crossing is right. So the condition is detected
//! and reported, not fixed: every volume draw counts the fragments each texel's ray meets
//! (its crossings) and records the mesh of the fragment the channel keeps; after the screen
//! pass, the receivers whose texel's ray crosses the volume their side reads (umbra side: the
//! umbra volume; penumbra side: the penumbra volume) more than once are counted per mesh
//! ([`DBufferRender::several_crossings`], in the stats), and each mesh with any gets a
//! warning naming it, the count and the remedies (`nsample`; `ssv` with the disk as a
//! sphere). 0 on `disk-block`, `disk-slab` and `disk-small-sphere` (convex occluders, one
//! crossing per ray); `disk-torus` and `disk-acute` (whose untrimmed quads cross, the "thin
//! occluders" finding) are warned.
//!
//! Lights: disks only (the paper's "one circular light source"); every other shape is rejected
//! by the registry. Several disk lights: one D-buffer each, averaged
//! ([`super::light_average`]). The paper's failure cases — concave and overlapping occluders,
//! no umbra (§4 case 2: V too low, √t better), acute silhouette corners — are measured and
//! pinned in `tests/suite/dbuffer.rs`; the findings are in `docs/dbuffer.md`.

use super::dump::{color_values, row_major, BufferDump, DumpValues, ElementFormat};
use super::dump::{EventKind, EventMap};
use super::horizon_clip::{clip_to_horizon, Horizon, HorizonKeys};
use super::output::MethodOutput;
use super::penumbra_map::ShadowMapKeys;
use crate::error::InputError;
use crate::frame::Frame;
use crate::geometry::umbra_penumbra::{
    build_volumes, Disk, Extrusion, VolumeStats, VolumeVertex, Volumes,
};
use crate::gpu::buffers::{alloc_tiles, DepthTile};
use crate::gpu::color::{ColorFormat, ColorMask, RgbaTile};
use crate::gpu::counters::{count, Counters};
use crate::gpu::depth::DepthFunc;
use crate::gpu::depth::{DepthFormat, DepthState, PolygonOffset};
use crate::gpu::light_view::LightView;
use crate::gpu::probe::{Overflow, PassProbe, PrimitiveKind, ProbeEvent, Raw, Tap};
use crate::gpu::raster::{bin, draw, Fragment, TileDraw};
use crate::gpu::setup::{setup_all_barycentric, CullMode};
use crate::gpu::shader_float::ShaderFloat;
use crate::gpu::shader_vec::SVec3;
use crate::gpu::texture::Filter;
use crate::gpu::transform::ClipVertex;
use crate::methods::output::BufferPlan;
use crate::methods::precision_spec::PrecisionSpec;
use crate::methods::recorder::PassRecorder;
use crate::options::{option_names, option_table, OptionTable};
use crate::pass::PassStats;
use crate::scene::LightShape;
use crate::visibility::Visibility;
use glam::DVec3;
use serde::Serialize;

/// The default number of corner-fan triangles per full circle (`fan-segments`).
pub const DEFAULT_FAN_SEGMENTS: u32 = 32;
/// Relative margin of the sphere the volumes reach beyond the farthest mesh vertex, and of the
/// distance range beyond that sphere.
pub const BOUND_MARGIN: f64 = 0.01;

/// V(t): 3t² − 2t³ (smoothstep, §4 eq. 4) or √t (§6.2, for small occluders).
pub use super::Falloff;

/// Eq. 3's denominator (module doc, pass 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Eq3 {
    /// (|cx| − |cx_s|): t = ½ at c's hard-shadow boundary, as §4 states.
    Corrected,
    /// (|cx_uv| − |cx_s|), as printed.
    Printed,
}

/// How the D-buffer's fragments get their distances (module doc, pass 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Distances {
    /// The vertex distances interpolated across the triangle (the paper's).
    Interpolated,
    /// The distance along the texel's ray from c to the triangle's plane, computed per
    /// fragment and written as its depth too (removes the "spherically distributed values"
    /// artifact; |cx_s| stays interpolated).
    Exact,
}

/// The settings of one `dbuffer` render (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DBufferSettings {
    /// Edge of the D-buffer in texels.
    pub map_size: u32,
    /// Depth format of the D-buffer's depth buffer.
    pub depth: DepthFormat,
    /// Storage format of the four distance channels (f32 or f16).
    pub storage: ColorFormat,
    /// The R channel's bias.
    pub offset: PolygonOffset,
    /// V(t).
    pub falloff: Falloff,
    /// Eq. 3's denominator.
    pub eq3: Eq3,
    /// Corner-fan triangles per full circle.
    pub fan_segments: u32,
    /// How fragments get their distances.
    pub distances: Distances,
    /// The receiver's own horizon (`horizon`, [`super::horizon_clip`]), read with the other
    /// options; `stats.json` shows it under its own `"horizon"`.
    #[serde(skip)]
    pub horizon: Horizon,
}

option_names!(Eq3 {
    Corrected = "corrected",
    Printed = "printed",
});

option_names!(Distances {
    Interpolated = "interpolated",
    Exact = "exact",
});

option_table! {
    /// `[options.dbuffer]` (module doc): the D-buffer's shadow-map keys, as `penumbra-map`'s,
    /// and the method's own.
    pub struct DBufferOptions["dbuffer"] {
        ..maps: ShadowMapKeys,
        ..horizon: HorizonKeys,
        /// storage of the four distance channels
        storage: ColorFormat [&[ColorFormat::F32, ColorFormat::F16]] = ColorFormat::F32;
        /// V(t): 3t² − 2t³ (CGI 2004 eq. 4) or √t (§6.2, for occluders smaller than the light)
        falloff: Falloff [&[Falloff::Smoothstep, Falloff::Sqrt]] = Falloff::Smoothstep;
        /// eq. 3's denominator: (|cx| − |cx_s|), t = ½ at the light center's shadow line, or as printed
        eq3: Eq3 = Eq3::Corrected;
        /// corner-fan triangles per full circle of the volumes
        fan_segments: u32 [4..=1024] = DEFAULT_FAN_SEGMENTS;
        /// the D-buffer's distances: the vertex distances interpolated (the paper's), or per fragment
        distances: Distances = Distances::Interpolated;
    }
}

/// Read and check `[options.dbuffer]` (module doc) for `frame`.
pub fn read_settings(frame: &Frame) -> Result<DBufferSettings, InputError> {
    let o = DBufferOptions::read(frame.scene)?;
    Ok(DBufferSettings {
        map_size: o.maps.map_edge(frame.scene),
        depth: o.maps.depth_format(frame),
        storage: o.storage,
        offset: o.maps.offset(),
        falloff: o.falloff,
        eq3: o.eq3,
        fan_segments: o.fan_segments,
        distances: o.distances,
        horizon: o.horizon.into(),
    })
}

/// Eq. 2 at a vertex `x` with silhouette point `e` for the disk normal `n` seen from `c`:
/// `(dir(c, x)·n)/(dir(c, e)·n)·dist(c, e)` (module doc); `None` when it is not finite.
pub fn silhouette_distance(c: DVec3, n: DVec3, x: DVec3, e: DVec3) -> Option<f64> {
    let dist = (e - c).length();
    let s = (x - c).normalize().dot(n) / (e - c).normalize().dot(n) * dist;
    s.is_finite().then_some(s)
}

/// |cx| of the screen pass's receiver `x` (the interpolated position) from the light center
/// `c` (a uniform), as the fragment program computes it in the shader precision `T`.
pub fn receiver_distance<T: ShaderFloat>(x: DVec3, c: DVec3) -> T {
    (SVec3::<T>::from_f64(x) - SVec3::from_f64(c)).length()
}

/// Which side of c's hard shadow x is on (module doc, pass 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Side {
    /// |cx| > |cx_o|: the first branch of eq. 3, with |cx_uv|.
    Umbra,
    /// Otherwise: the second branch, with |cx_pv|.
    Penumbra,
}

/// Eq. 3: t of a receiver at distance `d` from c, with the volume distance `v` (|cx_uv| on the
/// umbra side, |cx_pv| on the other) and `s` = |cx_s|; `None` when degenerate (module doc).
/// Computed in the shader precision `T` (module doc, "Shader precision"), every operation
/// rounded; the degeneracy test is on the rounded denominator and quotient.
pub fn parameter_t<T: ShaderFloat>(eq: Eq3, side: Side, d: T, v: T, s: T) -> Option<T> {
    let den = T::from_f64(2.0)
        * v
        * match eq {
            Eq3::Corrected => d - s,
            Eq3::Printed => v - s,
        };
    let q = s * (d - v) / den;
    if !(den > T::zero() && q.is_finite()) {
        return None;
    }
    Some(match side {
        Side::Umbra => q,
        Side::Penumbra => T::one() - q,
    })
}

/// The region the screen pass puts a receiver in (module doc, pass 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Region {
    /// V = 0.
    Umbra,
    /// The first branch of eq. 3.
    InnerPenumbra,
    /// The second branch of eq. 3.
    OuterPenumbra,
    /// V = 1.
    Lit,
}

/// What the screen program computed for one receiver.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Shade {
    /// The region.
    pub region: Region,
    /// t before the clamp (`None` outside the penumbra regions and where degenerate).
    pub t: Option<f64>,
    /// Whether eq. 3 was degenerate (t = ½ used).
    pub degenerate: bool,
    /// The visibility: V of t clamped to [0, 1], saturated to [0, 1] as the fragment's colour
    /// output (module doc, "Shader precision").
    pub v: f64,
}

impl Shade {
    /// Whether the clamp of t to [0, 1] changed it (the method's clamped pixels).
    pub fn clamped(&self) -> bool {
        self.t.is_some_and(|t| !(0.0..=1.0).contains(&t))
    }
}

/// The fragment program of the screen pass (module doc, pass 3): the receiver at distance `d`
/// from c over the D-buffer texel `[|cx_o|, |cx_uv|, |cx_pv|, |cx_s|]`, computed in the
/// shader precision `T` (module doc, "Shader precision"): `d` and the texel's channels are
/// read as `T`, every comparison is on those values and every operation of t and V(t) is
/// rounded.
pub fn screen_program<T: ShaderFloat>(d: T, texel: [f32; 4], s: &DBufferSettings) -> Shade {
    let [o, uv, pv, cs] = texel.map(|x| T::from_f64(x as f64));
    let (side, v) = if d > o {
        (Side::Umbra, uv)
    } else {
        (Side::Penumbra, pv)
    };
    if v <= T::zero() || d < v {
        let (region, v) = match side {
            Side::Umbra => (Region::Umbra, 0.0),
            Side::Penumbra => (Region::Lit, 1.0),
        };
        return Shade {
            region,
            t: None,
            degenerate: false,
            v,
        };
    }
    let region = match side {
        Side::Umbra => Region::InnerPenumbra,
        Side::Penumbra => Region::OuterPenumbra,
    };
    let t = parameter_t(s.eq3, side, d, v, cs);
    let (zero, one) = (T::zero(), T::one());
    let clamped = t.unwrap_or(T::from_f64(0.5)).clamp(zero, one);
    Shade {
        region,
        t: t.map(T::to_f64),
        degenerate: t.is_none(),
        v: s.falloff.apply(clamped).clamp(zero, one).to_f64(),
    }
}

/// What the D-buffer draws did (module doc, pass 2).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct DBufferStats {
    /// Fragments of the scene draw.
    pub scene_fragments: u64,
    /// Of them, written (R).
    pub r_writes: u64,
    /// Fragments of the umbra-volume draw.
    pub umbra_fragments: u64,
    /// Of them, written (G and A).
    pub g_writes: u64,
    /// Fragments of the penumbra-volume draw.
    pub penumbra_fragments: u64,
    /// Of them, written (B and A).
    pub b_writes: u64,
    /// Writes of the shared A channel (both volume draws).
    pub a_writes: u64,
    /// Volume vertices whose eq. 2 ratio was not finite (dist(c, e) used).
    pub s_not_finite: u64,
    /// Texels holding both an umbra and a penumbra distance: their A is the penumbra draw's.
    pub shared_a_texels: u64,
}

/// What the screen pass found (module doc, pass 3).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct ScreenStats {
    /// Receiver pixels shaded.
    pub receivers: u64,
    /// Receivers not in front of the light (w ≤ 0 in the light view): lit, no lookup.
    pub behind_light: u64,
    /// Umbra (V = 0).
    pub umbra: u64,
    /// Umbra because the ray has no umbra-volume distance (G = 0).
    pub umbra_without_volume: u64,
    /// First branch of eq. 3.
    pub inner_penumbra: u64,
    /// Second branch of eq. 3.
    pub outer_penumbra: u64,
    /// Lit (V = 1).
    pub lit: u64,
    /// Degenerate eq. 3 (t = ½ used).
    pub degenerate_t: u64,
    /// t outside [0, 1] before the clamp (the clamped pixels).
    pub t_out_of_range: u64,
}

field_sum!(DBufferStats {
    scene_fragments,
    r_writes,
    umbra_fragments,
    g_writes,
    penumbra_fragments,
    b_writes,
    a_writes,
    s_not_finite,
    shared_a_texels
});
field_sum!(ScreenStats {
    receivers,
    behind_light,
    umbra,
    umbra_without_volume,
    inner_penumbra,
    outer_penumbra,
    lit,
    degenerate_t,
    t_out_of_range
});

/// Per-tile storage of the D-buffer.
struct DTile {
    color: RgbaTile,
    depth: DepthTile,
    stats: DBufferStats,
    /// Per texel and volume (umbra, penumbra), the fragments its ray met: how often the ray
    /// crosses the volume's surface (module doc, "Several crossings").
    crossings: Vec<[u32; 2]>,
    /// Per texel and volume, the volume triangle whose fragment the channel holds.
    farthest_prim: Vec<[u32; 2]>,
}

/// The result of the passes.
#[derive(Debug, Clone)]
pub struct DBufferRender {
    /// Visibility per pixel, row-major; background 1.
    pub visibility: Visibility,
    /// The light view the D-buffer was rendered in.
    pub view: LightView,
    /// The distance range [0, range] of the D-buffer's depth.
    pub range: f64,
    /// The D-buffer (R = |cx_o|, G = |cx_uv|, B = |cx_pv|, A = |cx_s|), tile-major in
    /// `view.tiling`.
    pub dbuffer: Vec<RgbaTile>,
    /// What building the volumes found.
    pub volumes: VolumeStats,
    /// What the D-buffer draws did.
    pub program: DBufferStats,
    /// What the screen pass found.
    pub screen: ScreenStats,
    /// Per pixel (row-major), what the screen program computed; `None` for background and
    /// receivers behind the light.
    pub shades: Vec<Option<Shade>>,
    /// Per caster mesh ([`Frame::caster_meshes`] order), the receiver pixels whose texel's ray
    /// crosses the volume they read more than once, that mesh's fragment held
    /// (module doc, "Several crossings").
    pub several_crossings: Vec<u64>,
    /// The passes after the scene pass: volumes, the three D-buffer draws, screen.
    pub passes: Vec<PassStats>,
}

/// The HiZ tile edge of early Z in the D-buffer's scene draw (`docs/architecture.md`,
/// "Hierarchical Z"), `None` where it does not apply: with the unit off, and with `distances =
/// exact`, where a fragment's depth is the distance along its texel's ray to the triangle's
/// plane and its offset uses that distance's slope per fragment — neither bounded by the
/// vertex depths (the nearest point of a triangle to the light can lie inside it). With the
/// paper's interpolated distances a fragment's depth is the rasterizer's, between the vertex
/// depths, offset as the shadow map's ([`crate::gpu::setup::RasterTriangle::offset_depth`]):
/// the bound the shadow map's early Z uses holds.
fn early_z_applies(gpu: &crate::frame::GpuSettings, distances: Distances) -> Option<u32> {
    gpu.hiz_tile()
        .filter(|_| distances == Distances::Interpolated)
}

/// One D-buffer draw (module doc, pass 2).
#[derive(Debug, Clone, Copy)]
enum DrawKind {
    /// The scene into R, LESS, with the R bias, with early Z when `early_z`
    /// ([`early_z_applies`]): a triangle is rejected in the HiZ tiles of a tile where its
    /// nearest offset depth is at or behind every stored depth.
    Scene {
        offset: PolygonOffset,
        early_z: bool,
    },
    /// A volume into the channels of the mask, GREATER.
    Volume(ColorMask),
}

/// The triangles of one D-buffer draw: clip coordinates, per-vertex `[distance, |cx_s|]`
/// (the vertex program's outputs) and the world plane `(unit normal, offset)` of each.
#[derive(Debug, Clone, Default)]
struct DrawInput {
    prims: Vec<[ClipVertex; 3]>,
    values: Vec<[[f64; 2]; 3]>,
    planes: Vec<(DVec3, f64)>,
}

impl DrawInput {
    /// Append the triangle with world corners `w`, clip corners and vertex values.
    fn push(&mut self, w: [DVec3; 3], clip: [ClipVertex; 3], values: [[f64; 2]; 3]) {
        let n = (w[1] - w[0]).cross(w[2] - w[0]).normalize_or_zero();
        self.prims.push(clip);
        self.values.push(values);
        self.planes.push((n, n.dot(w[0])));
    }
}

/// The distance from c along the ray through the center of texel (x, y) of `view` to the
/// plane `(n, k)`; `None` when the ray does not meet it in front of c.
fn ray_distance(view: &LightView, x: u32, y: u32, (n, k): (DVec3, f64)) -> Option<f64> {
    let c = view.center;
    let dir = (view.proj.unproject(x, y, 0.5) - c).normalize();
    let d = (k - n.dot(c)) / n.dot(dir);
    (d.is_finite() && d > 0.0).then_some(d)
}

/// A D-buffer texel as stored, for probes ([`crate::gpu::probe`]).
fn texel_raw(tile: &RgbaTile, i: usize) -> Raw {
    let c = tile.values[i];
    Raw::Channels(match tile.format {
        ColorFormat::F16 => c.iter().map(|v| Raw::F16(*v as u16)).collect(),
        _ => c.iter().map(|v| Raw::F32(*v)).collect(),
    })
}

/// Run one D-buffer draw of `input` into `tiles` (module doc, pass 2), recording at the texel
/// `probe` watches. A volume draw counts, per texel, the fragments its ray meets and records
/// the triangle of the fragment the channel holds.
fn draw_dbuffer(
    view: &LightView,
    range: f64,
    distances: Distances,
    tiles: &mut [DTile],
    input: &DrawInput,
    kind: DrawKind,
    probe: Option<&PassProbe>,
) -> Counters {
    let cull = match kind {
        DrawKind::Scene { .. } => CullMode::Back,
        DrawKind::Volume(_) => CullMode::None,
    };
    let (tris, mut counters) = setup_all_barycentric(&input.prims, cull, &view.tiling);
    let bins = bin(&view.tiling, &tris);
    let format = view.depth;
    counters += draw(
        &view.tiling,
        tiles,
        &tris,
        &bins,
        probe,
        |t, tile, tri, c| match kind {
            DrawKind::Scene {
                offset,
                early_z: true,
            } => {
                let near = tri.nearest_offset_depth(offset, format);
                tile.depth.early_z(&view.tiling, t, tri.bbox, near, c)
            }
            _ => TileDraw::Whole,
        },
        |_, tile, tri, f, c, tap| {
            let before = tap.map(|_| {
                let (depth, texel) = (tile.depth.values[f.local], texel_raw(&tile.color, f.local));
                (depth, texel, c.overflow_events)
            });
            count!(c.fragments_shaded += 1);
            let prim = tri.prim as usize;
            let v = input.values[prim];
            let at = |k: usize| {
                tri.interpolate(f.x, f.y, v.map(|x| x[k]))
                    .expect("D-buffer triangles are set up with barycentrics")
            };
            let (d, f) = match distances {
                Distances::Interpolated => (at(0), f),
                Distances::Exact => match ray_distance(view, f.x, f.y, input.planes[prim]) {
                    Some(d) => (
                        d,
                        Fragment {
                            z: (d / range) as f32,
                            ..f
                        },
                    ),
                    None => (at(0), f),
                },
            };
            match kind {
                DrawKind::Scene { offset, .. } => {
                    tile.stats.scene_fragments += 1;
                    let m = match distances {
                        Distances::Interpolated => tri.max_depth_slope(),
                        // The slope of the depth this fragment writes: the exact distance's
                        // change to the next texel in x and in y.
                        Distances::Exact => [(1, 0), (0, 1)]
                            .map(|(dx, dy)| {
                                let plane = input.planes[prim];
                                ray_distance(view, f.x + dx, f.y + dy, plane)
                                    .map_or(0.0, |n| (n - d).abs() / range)
                            })
                            .into_iter()
                            .fold(0.0, f64::max),
                    };
                    let z_max = tri.z_range[1];
                    let z = offset.apply(format, f.z, m, z_max);
                    let pass =
                        tile.depth
                            .test_and_write(&DepthState::LESS_WRITE, &Fragment { z, ..f }, c);
                    if pass {
                        let r = d + range * offset.amount(format, m, z_max);
                        let mask = ColorMask([true, false, false, false]);
                        tile.color
                            .write_masked(f.local, [r, 0.0, 0.0, 0.0], mask, c);
                        tile.stats.r_writes += 1;
                    }
                    if let (Some(tap), Some(b)) = (tap, &before) {
                        let e = tap.event().primitive(
                            PrimitiveKind::SceneTriangle,
                            tri.prim,
                            "",
                            Some(tri.front_facing),
                        );
                        let z = format.quantize(z);
                        let e = e.depth(format, DepthFunc::Less, z, b.0, pass);
                        record_dbuffer_write(tap, e.value("|cx|", d), tile, f.local, b, c);
                    }
                }
                DrawKind::Volume(mask) => {
                    let umbra = mask.0[1];
                    if umbra {
                        tile.stats.umbra_fragments += 1;
                    } else {
                        tile.stats.penumbra_fragments += 1;
                    }
                    let k = usize::from(!umbra);
                    tile.crossings[f.local][k] += 1;
                    let pass = tile.depth.test_and_write(&DepthState::GREATER_WRITE, &f, c);
                    if pass {
                        tile.farthest_prim[f.local][k] = tri.prim;
                        tile.color
                            .write_masked(f.local, [0.0, d, d, at(1)], mask, c);
                        if umbra {
                            tile.stats.g_writes += 1;
                        } else {
                            tile.stats.b_writes += 1;
                        }
                        tile.stats.a_writes += 1;
                    }
                    if let (Some(tap), Some(b)) = (tap, &before) {
                        let kind = if umbra {
                            PrimitiveKind::UmbraVolume
                        } else {
                            PrimitiveKind::PenumbraVolume
                        };
                        let e = tap
                            .event()
                            .primitive(kind, tri.prim, "", Some(tri.front_facing));
                        let z = format.quantize(f.z);
                        let e = e.depth(format, DepthFunc::Greater, z, b.0, pass);
                        let e = e.value("|cx|", d).value("|cx_s|", at(1));
                        record_dbuffer_write(tap, e, tile, f.local, b, c);
                    }
                }
            }
        },
    );
    counters
}

/// Record a D-buffer fragment's writes (module doc, pass 2): the depth buffer, then the
/// texel, from their values `before` (depth, texel, overflow count) to what `tile` holds now.
fn record_dbuffer_write(
    tap: Tap,
    e: ProbeEvent,
    tile: &DTile,
    i: usize,
    before: &(u32, Raw, u64),
    c: &Counters,
) {
    let after = Raw::Depth(tile.depth.values[i]);
    tap.push(e.write("depth", Raw::Depth(before.0), after, Overflow::Clamp, 0));
    let e = tap.event().write(
        "dbuffer",
        before.1.clone(),
        texel_raw(&tile.color, i),
        tile.color.format.overflow(),
        c.overflow_events - before.2,
    );
    tap.push(e.note("(R |cx_o|, G |cx_uv|, B |cx_pv|, A |cx_s|)"));
}

/// The D-buffer draw of the volume triangles `tris`: the vertex program of §3.2 with eq. 2;
/// counts the vertices whose ratio is not finite.
fn volume_input(
    view: &LightView,
    range: f64,
    disk: &Disk,
    tris: &[[VolumeVertex; 3]],
    not_finite: &mut u64,
) -> DrawInput {
    let c = disk.center;
    let mut input = DrawInput::default();
    for t in tris {
        let values = t.map(|x| {
            let s = silhouette_distance(c, disk.normal, x.position, x.silhouette);
            *not_finite += s.is_none() as u64;
            [
                (x.position - c).length(),
                s.unwrap_or((x.silhouette - c).length()),
            ]
        });
        let clip = t.map(|x| view.distance_clip_point(x.position, range));
        input.push(t.map(|x| x.position), clip, values);
    }
    input
}

/// Render `dbuffer` with `s` on `frame` (one disk light), its passes recorded by a recorder
/// of its own ([`DBufferRender::passes`]).
pub fn render(frame: &Frame, s: &DBufferSettings) -> Result<DBufferRender, InputError> {
    let (r, passes) = PassRecorder::record_alone(frame, METHOD.name, |rec| render_with(rec, s))?;
    Ok(DBufferRender { passes, ..r })
}

/// [`render`], its passes run through `rec` (`passes` left empty).
pub fn render_with(
    rec: &mut PassRecorder,
    s: &DBufferSettings,
) -> Result<DBufferRender, InputError> {
    let frame = rec.frame();
    let scene = frame.scene;
    let light = scene.light();
    let LightShape::Disk { radius, normal } = light.shape else {
        return Err(InputError::at(
            &scene.source,
            scene.light_object(0, "light"),
            "the D-buffer method needs a disk light",
        ));
    };
    let view = super::fit_light_view(frame, "dbuffer", s.map_size, s.depth, "D-buffers")?;
    let disk = Disk::new(light.center, normal, radius);
    let c = disk.center;
    let farthest = scene
        .meshes
        .iter()
        .flat_map(|m| &m.positions)
        .map(|p| (p.as_dvec3() - c).length())
        .fold(0.0, f64::max);
    let bound = farthest * (1.0 + BOUND_MARGIN);
    let range = bound * (1.0 + BOUND_MARGIN);

    // Pass 1: the volumes (CPU).
    let meshes = frame.caster_meshes();
    let ex = Extrusion {
        bound,
        fan_segments: s.fan_segments,
    };
    let volumes = rec
        .pass("volumes", |_| build_volumes(&meshes, &disk, &ex))
        .map_err(|(i, e)| InputError::at(&scene.source, frame.caster_object(i), e))?;

    // Pass 2: the D-buffer, three draws; a probe watches the texel the screen pass reads for
    // its pixel.
    let early_z = early_z_applies(&frame.gpu, s.distances);
    let hiz_tile = early_z.unwrap_or(view.tiling.tile);
    let mut tiles = alloc_tiles(&view.tiling, |t, len| DTile {
        color: RgbaTile::cleared(s.storage, [range, 0.0, 0.0, 0.0], len)
            .recording(frame.dump_buffers),
        depth: DepthTile::cleared_in(view.depth, &view.tiling, t, hiz_tile),
        stats: DBufferStats::default(),
        crossings: vec![[0; 2]; len],
        farthest_prim: vec![[0; 2]; len],
    });
    let texel = frame.probe.as_ref().and_then(|p| {
        let [x, y] = p.pixel();
        let r = frame.primary_ray_receiver((y * scene.width + x) as usize)?;
        let [wx, wy, _] = view.window(r.point)?;
        Some((p, view.texels_read(wx, wy, Filter::Nearest)))
    });
    let map_probe = |name: &str| {
        texel
            .as_ref()
            .map(|(p, t)| p.pass_at(name, &view.tiling, t, true))
    };
    if let Some(p) = map_probe("dbuffer-clear") {
        p.record_each(|tap| tap.event().clear("dbuffer", texel_raw(&tiles[0].color, 0)));
        p.record_each(|tap| {
            tap.event()
                .clear("depth", Raw::Depth(tiles[0].depth.values[0]))
        });
    }
    rec.pass("dbuffer-scene", |pass| {
        let mut scene_input = DrawInput::default();
        for (m, _) in &meshes {
            let world: Vec<DVec3> = m.positions.iter().map(|p| p.as_dvec3()).collect();
            let clip: Vec<ClipVertex> = world
                .iter()
                .map(|p| view.distance_clip_point(*p, range))
                .collect();
            for tri in &m.triangles {
                let k = tri.map(|i| i as usize);
                let w = k.map(|i| world[i]);
                scene_input.push(w, k.map(|i| clip[i]), w.map(|p| [(p - c).length(), 0.0]));
            }
        }
        pass.count(draw_dbuffer(
            &view,
            range,
            s.distances,
            &mut tiles,
            &scene_input,
            DrawKind::Scene {
                offset: s.offset,
                early_z: early_z.is_some(),
            },
            map_probe("dbuffer-scene").as_ref(),
        ));
    });
    let mut not_finite = 0;
    let mut volume_pass = |name: &str, tris: &[[VolumeVertex; 3]], mask: [bool; 4]| {
        rec.pass(name, |pass| {
            for tile in tiles.iter_mut() {
                tile.depth = DepthTile::cleared_to(view.depth, 0.0, tile.depth.values.len());
            }
            let probe = map_probe(name);
            if let Some(p) = &probe {
                p.record_each(|tap| {
                    tap.event()
                        .clear("depth", Raw::Depth(tiles[0].depth.values[0]))
                });
            }
            let input = volume_input(&view, range, &disk, tris, &mut not_finite);
            let kind = DrawKind::Volume(ColorMask(mask));
            pass.count(draw_dbuffer(
                &view,
                range,
                s.distances,
                &mut tiles,
                &input,
                kind,
                probe.as_ref(),
            ));
        })
    };
    volume_pass("dbuffer-umbra", &volumes.umbra, [false, true, false, true]);
    volume_pass(
        "dbuffer-penumbra",
        &volumes.penumbra,
        [false, false, true, true],
    );
    let mut program = DBufferStats {
        s_not_finite: not_finite,
        ..Default::default()
    };
    let mut dbuffer = Vec::with_capacity(tiles.len());
    let mut crossings = Vec::with_capacity(tiles.len());
    for tile in tiles {
        program += tile.stats;
        program.shared_a_texels += tile
            .color
            .values
            .iter()
            .filter(|v| v[1] != 0 && v[2] != 0)
            .count() as u64;
        dbuffer.push(tile.color);
        crossings.push((tile.crossings, tile.farthest_prim));
    }

    // Pass 3: the screen.
    let (visibility, shades, screen) = rec.pass("screen", |pass| {
        let (visibility, shades, screen, c) = crate::with_shader_float!(frame.gpu.shader, T => {
            screen_pass::<T>(frame, &view, &dbuffer, c, s)
        });
        pass.count(c);
        (visibility, shades, screen)
    });
    let several_crossings = several_crossings(frame, &view, &crossings, &shades, &volumes);

    Ok(DBufferRender {
        visibility,
        view,
        range,
        dbuffer,
        volumes: volumes.stats,
        program,
        screen,
        shades,
        several_crossings,
        passes: Vec::new(),
    })
}

/// Per tile of the D-buffer, per texel and volume (umbra, penumbra): the fragments its ray met
/// and the volume triangle whose fragment the channel holds.
type TexelCrossings = (Vec<[u32; 2]>, Vec<[u32; 2]>);

/// Per caster mesh (of `volumes`), the receiver pixels whose texel's ray crosses the volume
/// their side of the shadow reads (the umbra volume on the umbra side, the penumbra volume on
/// the other) more than once (module doc, "Several crossings"), counted for the mesh whose
/// fragment the channel holds. Counted from the screen pass's shades, after it: a measurement
/// of the frame, not part of the method.
fn several_crossings(
    frame: &Frame,
    view: &LightView,
    crossings: &[TexelCrossings],
    shades: &[Option<Shade>],
    volumes: &Volumes,
) -> Vec<u64> {
    let mut found = vec![0; volumes.mesh_ends.len()];
    for (r, shade) in frame.primary_ray_receivers().iter().zip(shades) {
        let (Some(r), Some(shade)) = (r, shade) else {
            continue;
        };
        let Some([x, y, _]) = view.window(r.point) else {
            continue;
        };
        let k = match shade.region {
            Region::Umbra | Region::InnerPenumbra => 0,
            Region::Lit | Region::OuterPenumbra => 1,
        };
        let (tile, local) = view.nearest_texel(x, y);
        let (counts, prims) = &crossings[tile];
        if counts[local][k] > 1 {
            found[volumes.mesh_of(k == 0, prims[local][k] as usize)] += 1;
        }
    }
    found
}

/// Pass 3 (module doc): visibility per pixel, the shades, the screen stats, the counters; the
/// fragment program in the shader precision `T`.
fn screen_pass<T: ShaderFloat>(
    frame: &Frame,
    view: &LightView,
    dbuffer: &[RgbaTile],
    c: DVec3,
    s: &DBufferSettings,
) -> (Visibility, Vec<Option<Shade>>, ScreenStats, Counters) {
    let receivers = frame.primary_ray_receivers();
    let width = frame.scene.width as usize;
    let texel_bytes = 4 * s.storage.bytes();
    let probe = frame.probe_pass("screen");
    let (pixels, stats, counters) = super::shade_receivers(
        &receivers,
        width,
        probe.as_ref(),
        |_, r, st: &mut ScreenStats, cn, tap| {
            let record = |v: f32, note: &str| {
                if let Some(tap) = tap {
                    tap.push(tap.event().resolve(&[v], false).note(note));
                }
            };
            let Some(r) = r else {
                record(1.0, "background: lit");
                return (1.0, None);
            };
            st.receivers += 1;
            count!(cn.fragments_shaded += 1);
            let Some([x, y, _]) = view.window(r.point) else {
                st.behind_light += 1;
                record(1.0, "behind the light: lit");
                return (1.0, None);
            };
            let (tile, local) = view.nearest_texel(x, y);
            count!(cn.color_read_bytes += texel_bytes);
            let texel = dbuffer[tile].texel(local);
            let d = receiver_distance::<T>(r.point.as_dvec3(), c);
            let shade = screen_program(d, texel, s);
            let d = d.to_f64();
            if let Some(tap) = tap {
                let [tx, ty] = view.tiling.position(tile, local);
                let e = ["R", "G", "B", "A"]
                    .iter()
                    .zip(texel)
                    .fold(tap.event(), |e, (n, v)| e.value(n, v as f64))
                    .value("|cx|", d)
                    .value("texel x", tx as f64)
                    .value("texel y", ty as f64);
                let e = match shade.t {
                    Some(t) => e.value("t", t),
                    None => e,
                };
                let clamped = shade.clamped();
                let note = format!(
                    "{:?}{}",
                    shade.region,
                    if shade.degenerate {
                        ", degenerate: t = ½"
                    } else {
                        ""
                    }
                );
                tap.push(e.resolve(&[shade.v as f32], clamped).note(note));
            }
            match shade.region {
                Region::Umbra => {
                    st.umbra += 1;
                    st.umbra_without_volume += (texel[1] <= 0.0) as u64;
                }
                Region::InnerPenumbra => st.inner_penumbra += 1,
                Region::OuterPenumbra => st.outer_penumbra += 1,
                Region::Lit => st.lit += 1,
            }
            st.degenerate_t += shade.degenerate as u64;
            st.t_out_of_range += shade.clamped() as u64;
            (shade.v as f32, Some(shade))
        },
    );
    let (values, shades) = pixels.into_iter().unzip();
    (Visibility::Gray(values), shades, stats, counters)
}

/// `dbuffer`'s pinned golden renders ([`crate::methods::Method::goldens`]).
const GOLDENS: &[crate::methods::Golden] = &[
    // dbuffer (CGI 2004) on every disk-light built-in.
    crate::methods::Golden::new("disk-block"),
    crate::methods::Golden::new("disk-slab"),
    crate::methods::Golden::new("disk-small-sphere"),
    crate::methods::Golden::new("disk-acute"),
    crate::methods::Golden::new("disk-torus"),
    crate::methods::Golden::new("scenes/real/spot-disk.toml"),
    crate::methods::Golden::variant("disk-block", "shader-fp24", &[]).gpu(&[("shader", "fp24")]),
    crate::methods::Golden::variant("disk-block", "shader-fp16", &[]).gpu(&[("shader", "fp16")]),
    // dbuffer (CGI 2004): the falloff of §6.2, f16 distance channels, eq. 3 as printed.
    crate::methods::Golden::variant("disk-block", "sqrt", &[("falloff", "sqrt")]),
    crate::methods::Golden::variant("disk-block", "f16", &[("storage", "f16")]),
    crate::methods::Golden::variant("disk-block", "printed", &[("eq3", "printed")]),
    crate::methods::Golden::variant("disk-small-sphere", "sqrt", &[("falloff", "sqrt")]),
    crate::methods::Golden::variant("disk-small-sphere", "f16", &[("storage", "f16")]),
    crate::methods::Golden::variant("disk-small-sphere", "printed", &[("eq3", "printed")]),
];

/// `dbuffer`'s configurations in the accuracy–time sweep ([`crate::methods::Method::sweep`]).
const SWEEP: &[crate::methods::OptionPairs] = &[
    &[],
    &[("falloff", "sqrt")],
    &[("storage", "f16")],
    &[("distances", "exact")],
    &[("eq3", "printed")],
    &[("horizon", "clip")],
];

/// What the precision experiment measures of it ([`crate::experiment::precision`]): its fragment programs only.
const PRECISION: PrecisionSpec = PrecisionSpec {
    shader_arithmetic: true,
    storage: &[],
    overflow: &[],
};

/// `dbuffer` in the registry ([`crate::methods::ALL`]).
pub const METHOD: crate::methods::Method = crate::methods::Method {
    name: "dbuffer",
    paper: "CGI 2004: umbra and penumbra volumes, D-buffer",
    // CGI 2004 §2: "the light source is approximated by a circular disk".
    supports: |s| matches!(s, LightShape::Disk { .. }),
    lights: crate::methods::SeveralLights::PerLight,
    options: crate::methods::OptionTableSpec::of::<DBufferOptions>(),
    // Not measured: the largest method's figure (wedge-blending's).
    bytes_per_pixel: 384,
    bytes_per_triangle: 384,
    default_run: crate::methods::DefaultRun::EveryScene,
    sums_per_silhouette_edge: false,
    table_note: |_| None,
    check: |frame| read_settings(frame).map(drop),
    run,
    goldens: GOLDENS,
    sweep: SWEEP,
    precision: PRECISION,
};

/// Run `dbuffer` on a rendered frame (one light: [`super::run`] averages several).
pub fn run(frame: &Frame) -> Result<MethodOutput, InputError> {
    let mut rec = PassRecorder::new(frame, METHOD.name);
    let s = read_settings(frame)?;
    let n = s.map_size;
    rec.uses(BufferPlan::color_target(
        format!("D-buffer RGBA {n}x{n} (R |cx_o|, G |cx_uv|, B |cx_pv|, A |cx_s|)"),
        s.storage,
        4,
    ));
    rec.uses(BufferPlan::depth_target(
        format!("D-buffer depth {n}x{n}"),
        s.depth,
    ));
    if let Some(hiz_tile) = early_z_applies(&frame.gpu, s.distances) {
        rec.uses(BufferPlan::hiz_zmin_zmax_of(
            "D-buffer depth",
            s.depth,
            hiz_tile,
        ));
    }
    let r = render_with(&mut rec, &s)?;
    rec.clamped(r.screen.t_out_of_range);
    for (k, n) in r.several_crossings.iter().enumerate() {
        if *n > 0 {
            rec.warn(several_crossings_warning(&frame.caster_object(k), *n));
        }
    }
    rec.dump_all(|| dbuffer_dumps(frame, &r, &s));
    let (visibility, horizon) = clip_to_horizon(&mut rec, s.horizon, r.visibility);
    let settings = serde_json::json!({
        "horizon": horizon,
        "settings": s,
        "light_view": {
            "axis": r.view.axis.to_array(),
            "distance_range": r.range,
        },
        "volumes": r.volumes,
        "dbuffer": r.program,
        "channel_writes": {
            "R": r.program.r_writes,
            "G": r.program.g_writes,
            "B": r.program.b_writes,
            "A": r.program.a_writes,
        },
        "screen": r.screen,
        "several_crossings": r.several_crossings,
        "gpu": frame.gpu,
    });
    Ok(rec.finish(visibility, settings))
}

/// The warning for `n` receiver pixels whose texel's ray crosses a volume of the mesh `object`
/// more than once (module doc, "Several crossings").
pub fn several_crossings_warning(object: &str, n: u64) -> String {
    format!(
        "{object}: at {n} receiver pixels the ray from the light center crosses this mesh's \
         umbra or penumbra volume more than once (a concave or overlapping occluder, CGI 2004 \
         §4 case 1); the D-buffer keeps only the farthest crossing, so there the penumbra is \
         lost or wrong and this result can be worse than hard-sv — nsample (any light) or ssv \
         with the disk as a sphere light of its radius handle such occluders"
    )
}

/// The dumps of the D-buffer and of t (module doc).
fn dbuffer_dumps(frame: &Frame, r: &DBufferRender, s: &DBufferSettings) -> Vec<BufferDump> {
    let tiling = &r.view.tiling;
    let texels = row_major(tiling, &r.dbuffer, |t| &t.values);
    let dbuffer = BufferDump::new(
        "dbuffer",
        &format!(
            "the D-buffer (CGI 2004 §2.2, §3) seen from the light center: per texel R = |cx_o| \
             (nearest surface), G = |cx_uv| and B = |cx_pv| (farthest umbra- and penumbra-volume \
             distance, 0 = none), A = |cx_s| (eq. 2), distances over [0, {}]",
            r.range
        ),
        (r.view.size(), r.view.size()),
        ElementFormat::Color(s.storage, 4),
        color_values(s.storage, texels.into_iter().flatten()),
    )
    .with_channels(&["R |cx_o|", "G |cx_uv|", "B |cx_pv|", "A |cx_s|"])
    .with_events(EventMap::new(
        EventKind::NonFinite,
        row_major(tiling, &r.dbuffer, |t| &t.overflows),
        Vec::new(),
    ));
    let t: Vec<f64> = r
        .shades
        .iter()
        .map(|sh| sh.and_then(|sh| sh.t).unwrap_or(f64::NAN))
        .collect();
    let clamped = r
        .shades
        .iter()
        .map(|sh| sh.is_some_and(|sh| sh.clamped()))
        .collect();
    let t = BufferDump::new(
        "t",
        "per pixel, the penumbra parameter t of eq. 3 (CGI 2004 §4) before the clamp to [0, 1] \
         that V = falloff(t) applies; NaN where the screen program computed none (umbra, lit, \
         degenerate, background)",
        (frame.scene.width, frame.scene.height),
        ElementFormat::ScalarF64,
        DumpValues::F64(t),
    )
    .with_events(EventMap::clamps(clamped));
    vec![dbuffer, t]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `dbuffer`'s warnings on `scene` at 48².
    fn warnings_at_48(mut scene: crate::scene::Scene) -> Vec<String> {
        scene.resize(Some(48), Some(48));
        let frame = Frame::render(&scene, crate::frame::GpuSettings::default()).unwrap();
        run(&frame).unwrap().stats.warnings
    }

    /// The concave real mesh (Spot the cow under a disk light) makes rays cross its volumes
    /// more than once and the method says so, naming the mesh, the count (the same as its
    /// stats) and the remedy; the convex block of the paper's Fig. 1/7 does not.
    #[test]
    fn several_crossings_are_warned_on_a_real_model_and_not_on_the_block() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/real/spot-disk.toml");
        let mut scene = crate::scene::file::load_scene_file(&path).unwrap();
        scene.resize(Some(48), Some(48));
        let frame = Frame::render(&scene, crate::frame::GpuSettings::default()).unwrap();
        let r = render(&frame, &read_settings(&frame).unwrap()).unwrap();
        assert_eq!(r.several_crossings.len(), 2, "floor and cow");
        assert_eq!(r.several_crossings[0], 0, "the floor box is convex");
        let n = r.several_crossings[1];
        assert!(n > 0);
        let expected = several_crossings_warning(&frame.caster_object(1), n);
        assert!(expected.contains("spot.obj") && expected.contains("nsample"));
        assert_eq!(run(&frame).unwrap().stats.warnings, vec![expected]);
        let block = crate::scene::builtin::load("disk-block").unwrap();
        assert_eq!(warnings_at_48(block), Vec::<String>::new());
    }

    /// The visible fraction of the 2D light [−1, 1] (radius 1 at depth 0) from x = (X, z)
    /// behind an occluder covering lateral positions ≤ σ at depth h, as the fraction t of the
    /// light's diameter (assumption 1 in 2D).
    fn exact_2d(sigma: f64, h: f64, x: f64, z: f64) -> f64 {
        // The line from x over the silhouette (σ, h) meets the light at ℓ.
        let l = (sigma * z - x * h) / (z - h);
        ((1.0 - l) / 2.0).clamp(0.0, 1.0)
    }

    /// The depth at which the ray from c = (0, 0) through (x, z) crosses the line from the
    /// light point (p, 0) through the silhouette (σ, h).
    fn crossing(sigma: f64, h: f64, p: f64, x: f64, z: f64) -> f64 {
        // Ray: lateral = u·depth, u = x/z; line: lateral = p + (σ − p)·depth/h.
        let u = x / z;
        p / (u - (sigma - p) / h)
    }

    /// Early Z in the D-buffer's scene draw (interpolated distances) changes no texel of the
    /// D-buffer and no output bit: unit on and off, HiZ tiles of 8 and 2, in D16, D24 and D32F,
    /// with no offset and with a positive and a negative one, on disk scenes and on scenes of
    /// intersecting meshes under a disk light, drawn in file order and reversed (nearer
    /// meshes first, where it rejects); with exact distances it stays off. The counters show
    /// it at work, and a bound taken at the farthest vertex instead fails it.
    #[test]
    fn early_z_in_the_scene_draw_changes_no_texel() {
        use crate::gpu::color::RgbaTile;
        let offsets = PolygonOffset::EARLY_Z_TEST_CASES;
        let (mut culled, mut saved) = (0, 0);
        // The disk scenes, and scenes with intersecting meshes under a disk light of the same
        // center (where a triangle can lie partly in front of a tile's depths).
        for name in [
            "disk-block",
            "disk-torus",
            "disk-small-sphere",
            "pw-fractal",
            "forest-spheres",
        ] {
            let mut scene = crate::scene::builtin::load(name).unwrap();
            scene.resize(Some(48), Some(48));
            let light = &mut scene.lights[0];
            if !matches!(light.shape, LightShape::Disk { .. }) {
                // Facing the origin, which the built-in scenes are around.
                let normal = -light.center.normalize();
                light.shape = LightShape::Disk {
                    radius: 0.3,
                    normal,
                };
            }
            for reversed in [false, true] {
                if reversed {
                    scene.meshes.reverse();
                }
                for depth in [DepthFormat::D16, DepthFormat::D24, DepthFormat::D32F] {
                    for offset in offsets {
                        let run = |hiz: bool, hiz_tile_size: u32, distances: Distances| {
                            let gpu = crate::frame::GpuSettings {
                                hiz,
                                hiz_tile_size,
                                ..Default::default()
                            };
                            let frame = Frame::render(&scene, gpu).unwrap();
                            let s = DBufferSettings {
                                depth,
                                offset,
                                distances,
                                ..read_settings(&frame).unwrap()
                            };
                            render(&frame, &s).unwrap()
                        };
                        let texels = |r: &DBufferRender| -> Vec<[u32; 4]> {
                            r.dbuffer
                                .iter()
                                .flat_map(|t: &RgbaTile| t.values.clone())
                                .collect()
                        };
                        let at = format!("{name} reversed {reversed} {depth:?} {offset:?}");
                        let off = run(false, 8, Distances::Interpolated);
                        for hiz_tile in [8, 2] {
                            let on = run(true, hiz_tile, Distances::Interpolated);
                            assert!(texels(&on) == texels(&off), "{at}, HiZ {hiz_tile}");
                            assert_eq!(on.visibility, off.visibility, "{at}");
                            let (c_on, c_off) = (on.passes[1].counters, off.passes[1].counters);
                            assert_eq!(c_off.tiles_culled_hiz, 0);
                            assert!(c_on.fragments_rasterized <= c_off.fragments_rasterized);
                            culled += c_on.tiles_culled_hiz;
                            saved += c_off.fragments_rasterized - c_on.fragments_rasterized;
                        }
                        let exact = run(true, 8, Distances::Exact);
                        assert_eq!(exact.passes[1].counters.hiz_read_bytes, 0, "{at}");
                    }
                }
            }
        }
        assert!(
            culled > 0 && saved > 0,
            "{culled} pairs rejected, {saved} fragments saved"
        );
    }

    #[test]
    fn corrected_equation_3_is_the_2d_visible_fraction_and_printed_is_its_linearization() {
        // Occluder lateral ≤ 1 at depth 2: the hard shadow of c is lateral < z/2, the umbra
        // lateral < 1 (the line from the light end +1 over the silhouette), the penumbra
        // lateral < z − 1 (from the end −1).
        let (sigma, h) = (1.0, 2.0);
        // Inner penumbra: the ray crosses the umbra line (from the light end +1) at z_uv.
        for (x, z) in [(2.0, 5.0), (2.4, 5.0), (1.3, 3.0), (1.1, 3.9)] {
            let zuv = crossing(sigma, h, 1.0, x, z);
            assert!(zuv > h && zuv < z, "{x} {z} {zuv}");
            let scale = (x * x + z * z).sqrt() / z; // distances along the ray ∝ depths
            let [d, v, s] = [z, zuv, h].map(|k| k * scale);
            let exact = parameter_t(Eq3::Corrected, Side::Umbra, d, v, s).unwrap();
            assert!((exact - exact_2d(sigma, h, x, z)).abs() < 1e-12, "{x} {z}");
            assert!((0.0..=0.5).contains(&exact));
            let printed = parameter_t(Eq3::Printed, Side::Umbra, d, v, s).unwrap();
            assert!(printed >= exact, "{printed} {exact}");
            // Same value (0) and slope at the volume: a step ε off it differs by O(ε²).
            let eps = 1e-6 * v;
            let e = parameter_t(Eq3::Corrected, Side::Umbra, v + eps, v, s).unwrap();
            let p = parameter_t(Eq3::Printed, Side::Umbra, v + eps, v, s).unwrap();
            assert!(e > 0.0 && (e - p).abs() < 1e-4 * e, "{e} {p}");
        }
        // Outer penumbra: mirrored, crossing the penumbra line from the light end −1.
        for (x, z) in [(3.0, 5.0), (3.9, 5.0), (1.7, 3.0)] {
            let zpv = crossing(sigma, h, -1.0, x, z);
            assert!(zpv > h && zpv < z, "{zpv}");
            let exact = parameter_t(Eq3::Corrected, Side::Penumbra, z, zpv, h).unwrap();
            assert!((exact - exact_2d(sigma, h, x, z)).abs() < 1e-12);
            assert!((0.5..=1.0).contains(&exact));
        }
    }

    #[test]
    fn degenerate_denominators_are_not_divided() {
        for eq in [Eq3::Printed, Eq3::Corrected] {
            // |cx_uv| = |cx_s| (a silhouette face): printed divides by 0.
            let t = parameter_t(eq, Side::Umbra, 3.0, 2.0, 2.0);
            match eq {
                Eq3::Printed => assert_eq!(t, None),
                Eq3::Corrected => assert_eq!(t, Some(0.5)),
            }
            assert_eq!(parameter_t(eq, Side::Umbra, 3.0, 0.0, 1.0), None);
        }
        // §4's "symmetry around c where t = ½": on the ray through the silhouette
        // (|cx_uv| = |cx_s|) the corrected t is ½ wherever x is, on both sides.
        for d in [2.5, 4.0, 9.0] {
            assert_eq!(
                parameter_t(Eq3::Corrected, Side::Umbra, d, 2.0, 2.0),
                Some(0.5)
            );
            assert_eq!(
                parameter_t(Eq3::Corrected, Side::Penumbra, d, 2.0, 2.0),
                Some(0.5)
            );
        }
    }

    /// Eq. 3's t in fp32, fp24 and fp16 against f64 for inputs exact in every format
    /// (multiples of 1/8 below 16): first-order error analysis with unit roundoff u. In
    /// `q = s·(d − v)/(2v·(d − s))` the differences, the two products (2v is exact) and the
    /// quotient round once each: |q_T − q| ≤ 5u·q; the penumbra side's `1 − q` adds u·|1 − q|.
    /// The factor 1.01 covers the second-order terms (5u ≤ 0.25 %). fp16 must differ
    /// somewhere.
    #[test]
    fn t_in_each_precision_is_within_the_rounding_bound() {
        use crate::gpu::shader_float::{Fp16, Fp24, Fp32, ShaderFloat, FP16, FP24, FP32};
        fn check<T: ShaderFloat>(mantissa_bits: i32) -> usize {
            let u = libm::ldexp(1.0, -(mantissa_bits + 1));
            let at = |x: f64| T::from_f64(x);
            let mut differ = 0;
            for d in [3.0, 4.125, 5.375, 7.875, 11.625] {
                for v in [1.5, 2.25, 2.875, 3.125] {
                    for s in [0.625, 1.125, 1.375, 2.0] {
                        for side in [Side::Umbra, Side::Penumbra] {
                            if !(d > v && v >= s) {
                                continue;
                            }
                            let exact = parameter_t(Eq3::Corrected, side, d, v, s).unwrap();
                            let t = parameter_t(Eq3::Corrected, side, at(d), at(v), at(s))
                                .unwrap()
                                .to_f64();
                            let q = s * (d - v) / (2.0 * v * (d - s));
                            let bound = 1.01
                                * match side {
                                    Side::Umbra => 5.0 * u * q,
                                    Side::Penumbra => 5.0 * u * q + u * (1.0 - q),
                                };
                            let err = (t - exact).abs();
                            assert!(err <= bound, "{d} {v} {s} {side:?}: {t} vs {exact}");
                            differ += (err > 0.0) as usize;
                        }
                    }
                }
            }
            differ
        }
        check::<Fp32>(FP32.mantissa_bits);
        check::<Fp24>(FP24.mantissa_bits);
        assert!(check::<Fp16>(FP16.mantissa_bits) > 0, "fp16 changed no t");
    }

    #[test]
    fn screen_program_regions() {
        let s = DBufferSettings {
            map_size: 8,
            depth: DepthFormat::D24,
            storage: ColorFormat::F32,
            offset: PolygonOffset::NONE,
            falloff: Falloff::Smoothstep,
            eq3: Eq3::Corrected,
            fan_segments: 32,
            distances: Distances::Interpolated,
            horizon: Horizon::Off,
        };
        // (|cx|, texel, region, V range): nothing nearer and no penumbra volume, before the
        // penumbra volume, beyond it; behind an occluder before the umbra volume's end, without
        // an umbra volume, beyond it.
        let cases: [(f64, [f32; 4], Region, [f64; 2]); 6] = [
            (5.0, [5.0, 0.0, 0.0, 0.0], Region::Lit, [1.0, 1.0]),
            (3.0, [3.0, 0.0, 4.0, 2.0], Region::Lit, [1.0, 1.0]),
            (5.0, [5.0, 0.0, 4.0, 2.0], Region::OuterPenumbra, [0.5, 1.0]),
            (3.0, [2.0, 4.0, 0.0, 2.0], Region::Umbra, [0.0, 0.0]),
            (3.0, [2.0, 0.0, 0.0, 0.0], Region::Umbra, [0.0, 0.0]),
            (5.0, [2.0, 4.0, 0.0, 2.0], Region::InnerPenumbra, [0.0, 0.5]),
        ];
        for (d, texel, region, [lo, hi]) in cases {
            let shade = screen_program(d, texel, &s);
            assert_eq!(shade.region, region, "{d} {texel:?}");
            assert!((lo..=hi).contains(&shade.v), "{d} {texel:?}: {}", shade.v);
        }
        let inner = screen_program(5.0, [2.0, 4.0, 0.0, 2.0], &s);
        // √t is brighter than smoothstep for t < ½.
        let sqrt = DBufferSettings {
            falloff: Falloff::Sqrt,
            ..s
        };
        assert!(screen_program(5.0, [2.0, 4.0, 0.0, 2.0], &sqrt).v > inner.v);
    }

    #[test]
    fn equation_2_is_the_silhouette_distance_on_the_silhouette() {
        let (c, n) = (DVec3::new(0.0, 4.0, 0.0), DVec3::NEG_Y);
        let e = DVec3::new(1.0, 2.0, 0.5);
        let s = silhouette_distance(c, n, e, e).unwrap();
        assert!((s - (e - c).length()).abs() < 1e-12);
        // Elsewhere, as printed: cos(x)/cos(e)·dist (the plane through e parallel to the
        // light would be at 2/cos(x) along the ray).
        let x = DVec3::new(3.0, -1.0, 0.0);
        let (cx, ce) = ((x - c).normalize().dot(n), (e - c).normalize().dot(n));
        let printed = silhouette_distance(c, n, x, e).unwrap();
        assert!((printed - cx / ce * (e - c).length()).abs() < 1e-12);
        // At the light's height the ratio is not finite.
        assert_eq!(
            silhouette_distance(c, n, x, DVec3::new(1.0, 4.0, 0.0)),
            None
        );
    }
}
