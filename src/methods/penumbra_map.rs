//! `penumbra-map`: penumbra maps (Wyman & Hansen, "Penumbra Maps: Approximate Soft Shadows in
//! Real-Time", EGSR 2003), the one image-space method: a shadow map for the umbra and a second
//! map holding the penumbra intensity on the surfaces the shadow map sees.
//!
//! Three passes on the emulated GPU, all through the same fixed-point rasterizer, fill rule
//! and depth rules as every other pass ([`crate::gpu::light_view`]):
//!
//! 1. **Shadow map** (§3 "the first pass renders a standard shadow map from the viewpoint of a
//!    point light source at the approximate center of the light"): the scene from the light
//!    center into a `map-size`² depth target (`depth`, default the frame's format, D24), back
//!    faces culled. The depth bias is a polygon offset ([`PolygonOffset`],
//!    `glPolygonOffset(slope-bias, bias)`): `bias` in units of the format's resolvable
//!    difference (one D24 or D16 step, default 4) and `slope-bias`, the slope-scaled factor
//!    (default 1). The paper's "larger bias" (§5) compensates for shadows of simplified models
//!    cast onto full models; here both are the same mesh, and what the method needs is the
//!    slope-scaled part: the fitted light view is not perpendicular to any floor, so a
//!    receiver half a texel from the texel center differs in depth by up to the surface's
//!    depth slope m, so half of a tilted lit surface shadows itself without a slope term
//!    (tested). Measured at 256², RMSE vs `raycast` on `cube-of-spheres-sphere` / `pw-columns`
//!    / `pw-fractal` / `pw-2002`: 0.535 / 0.548 / 0.346 / 0.577 without slope bias (1000
//!    units instead: 0.389 / 0.535 / 0.341 / 0.540), 0.278 / 0.262 / 0.181 / 0.299 with
//!    factor 0.5, 0.173 / 0.138 / 0.149 / 0.185 with 1 (default), 0.174 / 0.155 / 0.168 /
//!    0.185 with 2 (light leaks grow); 0, 4 or 64 units change nothing visible at D24.
//!    `bias-stage` chooses where the offset applies: `render` (default) offsets the shadow
//!    map as it is drawn, so pass 2 reads the offset depths too — near an occluder's own
//!    silhouette, where its surface is seen edge-on and the slope term is large, the offset
//!    pushes the surface behind the silhouette, a cone's fragments pass line (4) there and
//!    darken a few lit texels; `lookup` keeps the shadow map exact and moves the receiver
//!    toward the light in the screen pass's test by the offset its own triangle has in the
//!    light view ([`LightView::depth_slopes`]) — fewer dark specks but more light leaks on
//!    steep receivers, whose own slope is large. Measured at 256² (pixels `raycast` sees
//!    fully lit, ≥ 0.99, that come out below 0.5 / pixels `raycast` sees dark, ≤ 0.01, that
//!    come out above 0.5) on the same four scenes: render 72/26, 283/261, 197/361, 180/16;
//!    lookup 49/45, 268/322, 140/815, 166/888 (RMSE 0.173, 0.141, 0.173, 0.217).
//! 2. **Penumbra map** (§3): the silhouette from the light center (possible silhouette edges
//!    and their loops), a cone per silhouette vertex and an outer sheet per silhouette edge
//!    ([`crate::geometry::penumbra_cones`]; `cone-segments` triangles per cone), drawn into a
//!    map with a colour channel (`storage = unorm8|f16|f32`, [`ColorFormat`]; unorm8 as a
//!    p-buffer of 2003 held it) cleared to white and a depth channel (the light view's format)
//!    cleared to 1.0, both facings, in the order of
//!    [`crate::geometry::penumbra_cones::cones_and_sheets`]. The fragment program, line by
//!    line as the paper's pseudocode:
//!    * (1)–(3) `Z_P` = the shadow map at the fragment's own window coordinates (same
//!      resolution and matrices, so the same texel), `Z_F` = the fragment's interpolated
//!      window depth (f32);
//!    * (4) discard if `Z_F > Z_P` (the cone or sheet lies behind the surface);
//!    * (5)–(6) `Z_P′`, `Z_F′`: both converted to view depths by the projection's one rule
//!      ([`crate::gpu::transform::Projection::view_depth`]);
//!    * `Z_v`: constant on cones; on sheets interpolated perspective-correctly by the
//!      rasterizer ([`crate::gpu::setup::RasterTriangle::interpolate`]);
//!    * (7) `I = (Z_F′ − Z_v)/(Z_P′ − Z_v)`; (8) `I′ = 3I² − 2I³` (`falloff = smoothstep`,
//!      default, the Bernstein interpolant of §3) or `I′ = I` (`falloff = linear`);
//!    * (9)–(10) `I′` to the colour channel and to the depth channel, depth test LESS with
//!      writes: where cones and sheets overlap, the darkest wins (§3, Fig. 6).
//!
//!    Choices where the pseudocode divides by zero or leaves [0, 1] (each counted in
//!    [`ProgramStats`], asserted in the tests): a fragment is also discarded when
//!    `Z_P′ ≤ Z_v` — the surface is not beyond the silhouette vertex, so it is not in that
//!    vertex's penumbra (at a cone's tip on the occluder the paper's I is 0/0) — and when
//!    `Z_F′ < Z_v` — the fragment lies in front of its silhouette point, which only rounding
//!    can produce (at the sheet's silhouette edge, where the interpolated `Z_v` and the
//!    rasterized depth meet). After these, `0 ≤ Z_F′ − Z_v ≤ Z_P′ − Z_v` with a positive
//!    denominator, so `I` is in [0, 1] by construction; the count of `I` outside [0, 1]
//!    (before any falloff or storage clamp) is kept to prove it (at f64; in a narrower
//!    shader precision the rounded `I` and `I′` can leave [0, 1] by an ulp, counted the same).
//!
//!    **Shader precision** (`[options.gpu] shader`, [`crate::gpu::shader_float`]): lines
//!    (3)–(8) run in the chosen precision (the paper's ATI Radeon 9700 PRO, §5 "Results",
//!    computes in fp24): `Z_F`, `Z_P` and `Z_v` as the program reads them, the comparison of
//!    line (4) and the two discard tests on those values, `ConvertToWorldSpace` of lines
//!    (5)–(6) ([`Projection::shader_view_depth`](crate::gpu::transform::Projection::shader_view_depth)),
//!    `I` ([`penumbra_intensity`]) and the falloff ([`Falloff::apply`]). What stays f64: the
//!    silhouette, the cones and sheets and their per-vertex `Z_v` (§3: "We compute Z_vi on
//!    the CPU on a per-vertex basis"), the rasterizer's interpolation of `Z_F` and `Z_v`, and
//!    the storage of `I′` (the colour format and the depth channel's quantization).
//! 3. **Screen** (§3 "for each pixel rendered from the camera's viewpoint, a comparison with the
//!    depth in the shadow map determines if the pixel is completely shadowed. If not fully
//!    shadowed, a lookup into the penumbra map gives an approximation of the light"): the
//!    paper's third pass is a forward pass whose fragment program gets the light-space
//!    position interpolated from the vertices, i.e. the point of the visible triangle at the
//!    pixel center ([`Frame::primary_ray_receivers`]; the depth-buffer point would add the
//!    camera's depth quantization, hundreds of light-map depth steps, to every comparison).
//!    Its window position in the light view ([`LightView::window`], f32), the shadow-map test
//!    at the nearest texel (`quantize(z) > stored` → umbra, visibility 0; the comparison is
//!    always nearest: the umbra is the hard shadow) and otherwise the penumbra map sampled
//!    with `filter` (`nearest`, default, as the paper, or `bilinear`), clamped to the edge.
//!    Values outside [0, 1] before the final clamp are counted ([`ScreenStats`]). In the
//!    shader precision: the subtraction of `bias-stage = lookup`'s offset from the receiver's
//!    light-view depth (fragment arithmetic); the shadow-map comparison of quantized depths
//!    and the penumbra-map lookup with its filter are the texture unit's and stay as they
//!    are, as does the receiver's light-view position (the vertex stage's, interpolated).
//!
//! Buffer dumps (`--dump-buffers`, [`super::dump`]), at the map size: `shadow-map`, the depth
//! target of pass 1 as stored, and `penumbra-map`, the colour channel of pass 2 with its
//! overflow events (unorm8: clamped writes; f16/f32: non-finite results). The penumbra map's
//! depth channel holds the same intensities as depths (the LESS test's copy) and is not
//! dumped.
//!
//! Lights: spheres only (the paper's, §4); every other shape is rejected by the registry.
//! Several lights: one shadow map and one penumbra map per light (§3, last paragraph), run once
//! per light and averaged ([`super::light_average`]).
//!
//! The paper's limits follow from the construction and are measured in
//! `tests/suite/penumbra_map.rs`: the penumbra is outer only (inside the hard shadow nothing is lit),
//! the umbra does not shrink as the light grows (§4.1), shadows harden where occluder and
//! receiver touch, and the shadow map's resolution shows as aliasing. Against `raycast` the
//! method is less accurate than the plain hard shadow (`hard-sv`) on every sphere-light
//! built-in (256², RMSE: `cube-of-spheres-sphere` 0.173 vs 0.124, `pw-columns` 0.138 vs
//! 0.072, `pw-fractal` 0.149 vs 0.083): the whole 0 → 1 transition is put in the outer half
//! of the penumbra, where the true visibility only rises from about 0.5, and I is linear in
//! depth along the cone, not across the penumbra (halfway across a sheet from a silhouette at
//! view depth 2 to a receiver at 3, I = 0.4 and I′ = 0.35; `raycast` there is about 0.8).

use super::dump::{
    color_values, depth_values, row_major, BufferDump, ElementFormat, EventKind, EventMap,
};
use super::horizon_clip::{clip_to_horizon, Horizon, HorizonKeys};
use super::output::MethodOutput;
use crate::error::InputError;
use crate::frame::Frame;
use crate::geometry::penumbra_cones::{
    cones_and_sheets, silhouettes, ConeLight, ConeOrSheet, PenumbraGeometry,
};
use crate::gpu::buffers::{alloc_tiles, DepthTile};
use crate::gpu::color::{ColorFormat, ColorTile};
use crate::gpu::counters::{count, Counters};
use crate::gpu::depth::{DepthFormat, DepthState, PolygonOffset};
use crate::gpu::light_view::LightView;
use crate::gpu::probe::{Overflow, PassProbe, PrimitiveKind, ProbeEvent, Raw, Tap};
use crate::gpu::raster::{bin, draw, no_tile_culling, Fragment};
use crate::gpu::setup::{setup_all_barycentric, CullMode};
use crate::gpu::shader_float::ShaderFloat;
use crate::gpu::texture::Filter;
use crate::methods::output::BufferPlan;
use crate::methods::precision_spec::PrecisionSpec;
use crate::methods::recorder::PassRecorder;
use crate::options::{option_names, option_table, OptionTable};
use crate::pass::PassStats;
use crate::scene::{LightShape, Scene};
use crate::visibility::Visibility;
use serde::Serialize;

/// The default polygon-offset units of the shadow map (`bias`): resolvable-difference steps.
pub const DEFAULT_BIAS_UNITS: f64 = 4.0;
/// The default slope-scaled polygon-offset factor of the shadow map (`slope-bias`).
pub const DEFAULT_SLOPE_BIAS: f64 = 1.0;
/// The largest `map-size` of `penumbra-map` and `dbuffer` ([`ShadowMapKeys`]): the three map
/// buffers of `penumbra-map` (shadow map, penumbra colour and depth) of 4096² texels take
/// 200 MB as stored, the RGBA f32 D-buffer 256 MB; the papers' maps are 1024².
pub const MAX_MAP_SIZE: u32 = 4096;
/// The default number of triangles per cone (`cone-segments`).
pub const DEFAULT_CONE_SEGMENTS: u32 = 16;

/// How the penumbra intensity falls off across the penumbra (§3): `I′ = 3I² − 2I³`
/// (smoothstep, Parker et al.'s approximation of the spherical light's falloff) or `I′ = I`
/// (linear).
pub use super::Falloff;

/// Where the shadow-map bias is applied (module doc, pass 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum BiasStage {
    /// In the screen pass's shadow-map test: the receiver's depth is moved toward the light
    /// by the offset its own triangle would get from `glPolygonOffset` in the light view.
    /// The shadow map holds the surfaces' depths, so pass 2 sees them unbiased.
    Lookup,
    /// `glPolygonOffset` while rendering the shadow map: both the test and pass 2 read the
    /// offset depths.
    Render,
}

/// The settings of one `penumbra-map` render (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PenumbraMapSettings {
    /// Edge of the shadow and penumbra maps in texels.
    pub map_size: u32,
    /// Depth format of the shadow map and of the penumbra map's depth channel.
    pub depth: DepthFormat,
    /// The shadow-map bias: `bias` (units) and `slope-bias` (factor).
    pub offset: PolygonOffset,
    /// Where the bias is applied.
    pub bias_stage: BiasStage,
    /// Triangles per cone.
    pub cone_segments: u32,
    /// Intensity falloff.
    pub falloff: Falloff,
    /// Storage format of the penumbra map's colour channel.
    pub storage: ColorFormat,
    /// Filter of the penumbra-map lookup in the screen pass.
    pub filter: Filter,
    /// The receiver's own horizon (`horizon`, [`super::horizon_clip`]), read with the other
    /// options; `stats.json` shows it under its own `"horizon"`.
    #[serde(skip)]
    pub horizon: Horizon,
}

option_names!(BiasStage {
    Render = "render",
    Lookup = "lookup",
});

option_table! {
    /// The keys of a shadow map rendered from the light: `penumbra-map`'s, and `dbuffer`'s
    /// D-buffer (its nearest-surface channel is a distance shadow map).
    pub struct ShadowMapKeys {
        /// edge of the maps rendered from the light, in texels
        map_size: Option<u32> [8..=MAX_MAP_SIZE] = None,
            scene format!("the image's larger side, at most {MAX_MAP_SIZE}");
        /// depth format of the maps rendered from the light
        depth: Option<DepthFormat> = None, scene "the frame's, [options.gpu] depth";
        /// polygon-offset units of the shadow-map depth, in resolvable steps of its depth format
        bias: f64 [0.0..=16_777_215.0] = DEFAULT_BIAS_UNITS;
        /// slope-scaled polygon-offset factor of the shadow-map depth (glPolygonOffset's factor)
        slope_bias: f64 [0.0..=1000.0] = DEFAULT_SLOPE_BIAS;
    }
}

impl ShadowMapKeys {
    /// The edge of the maps: `map-size`, by default the image's larger side (at most
    /// [`MAX_MAP_SIZE`]).
    pub fn map_edge(&self, scene: &Scene) -> u32 {
        self.map_size
            .unwrap_or(scene.width.max(scene.height).min(MAX_MAP_SIZE))
    }

    /// The depth format of the maps: `depth`, by default the frame's.
    pub fn depth_format(&self, frame: &Frame) -> DepthFormat {
        self.depth.unwrap_or(frame.gpu.depth)
    }

    /// The shadow map's polygon offset, `glPolygonOffset(slope-bias, bias)`.
    pub fn offset(&self) -> PolygonOffset {
        PolygonOffset {
            factor: self.slope_bias,
            units: self.bias,
        }
    }
}

option_table! {
    /// `[options.penumbra-map]` (module doc).
    pub struct PenumbraMapOptions["penumbra-map"] {
        ..maps: ShadowMapKeys,
        ..horizon: HorizonKeys,
        /// where the bias applies: drawing the shadow map, or the screen pass's shadow test
        bias_stage: BiasStage = BiasStage::Render;
        /// triangles per cone at a silhouette vertex
        cone_segments: u32 [3..=1024] = DEFAULT_CONE_SEGMENTS;
        /// I′ = 3I² − 2I³ (Wyman & Hansen §3, the Bernstein interpolant) or I′ = I
        falloff: Falloff [&[Falloff::Smoothstep, Falloff::Linear]] = Falloff::Smoothstep;
        /// storage of the penumbra map's colour channel
        storage: ColorFormat = ColorFormat::Unorm8;
        /// filter of the penumbra-map lookup in the screen pass
        filter: Filter = Filter::Nearest;
    }
}

/// Read and check `[options.penumbra-map]` (module doc) for `frame`.
pub fn read_settings(frame: &Frame) -> Result<PenumbraMapSettings, InputError> {
    let o = PenumbraMapOptions::read(frame.scene)?;
    Ok(PenumbraMapSettings {
        map_size: o.maps.map_edge(frame.scene),
        depth: o.maps.depth_format(frame),
        offset: o.maps.offset(),
        bias_stage: o.bias_stage,
        cone_segments: o.cone_segments,
        falloff: o.falloff,
        storage: o.storage,
        filter: o.filter,
        horizon: o.horizon.into(),
    })
}

/// What the penumbra-map fragment program did (module doc, pass 2).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct ProgramStats {
    /// Fragments that ran the program.
    pub fragments: u64,
    /// Discarded by line (4): `Z_F > Z_P`.
    pub discarded_behind_surface: u64,
    /// Discarded because `Z_P′ ≤ Z_v` (the surface is not beyond the silhouette point).
    pub discarded_surface_not_beyond_silhouette: u64,
    /// Discarded because `Z_F′ < Z_v` (the fragment is in front of its silhouette point).
    pub discarded_in_front_of_silhouette: u64,
    /// Fragments whose `I` was not a number in [0, 1] (before the falloff and the storage).
    pub intensity_out_of_range: u64,
    /// Fragments that passed the LESS test and were written.
    pub written: u64,
}

/// What the screen pass found (module doc, pass 3).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct ScreenStats {
    /// Receiver pixels shaded.
    pub receivers: u64,
    /// Pixels in the umbra (failed the shadow-map test).
    pub umbra: u64,
    /// Pixels outside the umbra with a penumbra-map value below 1.
    pub penumbra: u64,
    /// Receivers not in front of the light (w ≤ 0 in the light view): lit, no lookup.
    pub behind_light: u64,
    /// Values outside [0, 1] (or not a number) before the final clamp.
    pub out_of_range: u64,
}

field_sum!(ProgramStats {
    fragments,
    discarded_behind_surface,
    discarded_surface_not_beyond_silhouette,
    discarded_in_front_of_silhouette,
    intensity_out_of_range,
    written
});
field_sum!(ScreenStats {
    receivers,
    umbra,
    penumbra,
    behind_light,
    out_of_range
});

/// Per-tile storage of the penumbra map.
struct PenumbraTile {
    color: ColorTile,
    depth: DepthTile,
    stats: ProgramStats,
}

/// The result of the three passes.
#[derive(Debug, Clone)]
pub struct PenumbraMapRender {
    /// Visibility per pixel, row-major, clamped to [0, 1]; background 1.
    pub visibility: Visibility,
    /// The light view the maps were rendered in.
    pub view: LightView,
    /// The shadow map, tile-major in `view.tiling`.
    pub shadow_map: Vec<DepthTile>,
    /// The penumbra map's colour channel, tile-major in `view.tiling`.
    pub penumbra_map: Vec<ColorTile>,
    /// The cones and sheets.
    pub geometry: PenumbraGeometry,
    /// Silhouette edges, loops and the largest vertex degree over all meshes.
    pub silhouette: (usize, usize, u32),
    /// What the fragment program did.
    pub program: ProgramStats,
    /// What the screen pass found.
    pub screen: ScreenStats,
    /// The passes after the scene pass: shadow map, silhouettes, penumbra map, screen.
    pub passes: Vec<PassStats>,
}

/// Render `penumbra-map` with `s` on `frame` (one sphere light), its passes recorded by a
/// recorder of its own ([`PenumbraMapRender::passes`]).
pub fn render(frame: &Frame, s: &PenumbraMapSettings) -> Result<PenumbraMapRender, InputError> {
    let (r, passes) = PassRecorder::record_alone(frame, METHOD.name, |rec| render_with(rec, s))?;
    Ok(PenumbraMapRender { passes, ..r })
}

/// [`render`], its passes run through `rec` (`passes` left empty).
pub fn render_with(
    rec: &mut PassRecorder,
    s: &PenumbraMapSettings,
) -> Result<PenumbraMapRender, InputError> {
    let frame = rec.frame();
    let scene = frame.scene;
    let light = scene.light();
    let LightShape::Sphere { radius } = light.shape else {
        return Err(InputError::at(
            &scene.source,
            scene.light_object(0, "light"),
            "penumbra maps need a sphere light",
        ));
    };
    let view = super::fit_light_view(frame, "penumbra-map", s.map_size, s.depth, "penumbra maps")?;

    // A probe watches the texels the screen pass reads for its pixel.
    let texels = frame.probe.as_ref().and_then(|p| {
        let [x, y] = p.pixel();
        let r = frame.primary_ray_receiver((y * scene.width + x) as usize)?;
        let [wx, wy, _] = view.window(r.point)?;
        Some((p, view.texels_read(wx, wy, s.filter)))
    });
    let map_probe = |name: &str| {
        texels
            .as_ref()
            .map(|(p, t)| p.pass_at(name, &view.tiling, t, true))
    };

    // Pass 1: the shadow map.
    let render_offset = match s.bias_stage {
        BiasStage::Render => s.offset,
        BiasStage::Lookup => PolygonOffset::NONE,
    };
    let shadow_map = rec.pass("shadow-map", |pass| {
        let probe = map_probe("shadow-map");
        let hiz_tile = frame.gpu.hiz_tile();
        let (map, c) = view.render_depth(scene, render_offset, hiz_tile, probe.as_ref());
        pass.count(c);
        map
    });

    // The silhouette from the light center (CPU; the paper's 30 %).
    let meshes = frame.caster_meshes();
    let sils = rec
        .pass("silhouettes", |_| silhouettes(&meshes, light.center))
        .map_err(|(i, e)| InputError::at(&scene.source, frame.caster_object(i), e))?;

    // Pass 2: cones and sheets into the penumbra map.
    let (geometry, color, program) = rec.pass("penumbra-map", |pass| {
        let mesh_refs: Vec<_> = meshes.iter().map(|(m, _)| *m).collect();
        let geometry = cones_and_sheets(
            &mesh_refs,
            &sils,
            &cone_light(&view, radius),
            s.cone_segments,
        );
        let probe = map_probe("penumbra-map");
        let (color, program, c) = crate::with_shader_float!(frame.gpu.shader, T => {
            render_penumbra_map::<T>(
                &view,
                &shadow_map,
                &geometry,
                s,
                frame.dump_buffers,
                probe.as_ref(),
            )
        });
        pass.count(c);
        (geometry, color, program)
    });

    // Pass 3: the screen.
    let (visibility, screen) = rec.pass("screen", |pass| {
        let (visibility, screen, c) = crate::with_shader_float!(frame.gpu.shader, T => {
            screen_pass::<T>(frame, &view, &shadow_map, &color, s)
        });
        pass.count(c);
        (visibility, screen)
    });

    let silhouette = (
        sils.iter().map(|m| m.edges.len()).sum(),
        sils.iter().map(|m| m.loops.len()).sum(),
        sils.iter().map(|m| m.max_vertex_degree).max().unwrap_or(0),
    );
    Ok(PenumbraMapRender {
        visibility,
        view,
        shadow_map,
        penumbra_map: color,
        geometry,
        silhouette,
        program,
        screen,
        passes: Vec::new(),
    })
}

/// Why the penumbra-map fragment program discards a fragment (module doc, pass 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Discard {
    /// Line (4): `Z_F > Z_P`, the cone or sheet lies behind the surface.
    BehindSurface,
    /// `Z_P′ ≤ Z_v`: the surface is not beyond the silhouette point.
    SurfaceNotBeyondSilhouette,
    /// `Z_F′ < Z_v`: the fragment lies in front of its silhouette point (rounding only).
    InFrontOfSilhouette,
}

/// Lines (3)–(7) of the penumbra-map fragment program (module doc, pass 2): the intensity
/// `I` of a fragment at interpolated window depth `z_f` over a shadow-map surface at window
/// depth `z_p`, for the silhouette point at view depth `z_v`, depths converted by `proj`.
///
/// Computed in the shader precision `T` (module doc, "Shader precision"): the three inputs
/// are rounded to `T` as the program reads them, the comparisons are made on the rounded
/// values and every operation of the depth conversion and of `I` is rounded.
pub fn penumbra_intensity<T: ShaderFloat>(
    z_f: f32,
    z_p: f64,
    z_v: f64,
    proj: &crate::gpu::transform::Projection,
) -> Result<T, Discard> {
    let (z_f, z_p, z_v) = (T::from_f64(z_f as f64), T::from_f64(z_p), T::from_f64(z_v));
    if z_f > z_p {
        return Err(Discard::BehindSurface);
    }
    let (z_p, z_f) = (proj.shader_view_depth(z_p), proj.shader_view_depth(z_f));
    if z_p <= z_v {
        return Err(Discard::SurfaceNotBeyondSilhouette);
    }
    if z_f < z_v {
        return Err(Discard::InFrontOfSilhouette);
    }
    Ok((z_f - z_v) / (z_p - z_v))
}

/// The light of radius `radius` as the cones and sheets see it from `view`: its center, the
/// view axis and the far plane.
pub fn cone_light(view: &LightView, radius: f32) -> ConeLight {
    ConeLight {
        center: view.center,
        axis: view.axis,
        far: view.proj.far,
        radius: radius as f64,
    }
}

/// Pass 2 (module doc): draw the cones and sheets of `geometry` over `shadow_map` (both in
/// `view`) into a penumbra map; returns its colour tiles (recording their overflow events per
/// sample when `record`, for a buffer dump), the program's stats and the pass counters. The
/// fragment program computes in the shader precision `T` (module doc, "Shader precision").
/// With a probe, the clears and every fragment at the texels `probe` watches are recorded
/// ([`crate::gpu::probe`]).
pub fn render_penumbra_map<T: ShaderFloat>(
    view: &LightView,
    shadow_map: &[DepthTile],
    geometry: &PenumbraGeometry,
    s: &PenumbraMapSettings,
    record: bool,
    probe: Option<&PassProbe>,
) -> (Vec<ColorTile>, ProgramStats, Counters) {
    let prims: Vec<_> = geometry
        .triangles
        .iter()
        .map(|t| t.corners.map(|p| view.clip_point(p)))
        .collect();
    let (tris, mut counters) = setup_all_barycentric(&prims, CullMode::None, &view.tiling);
    let bins = bin(&view.tiling, &tris);
    let mut tiles = alloc_tiles(&view.tiling, |_, len| PenumbraTile {
        color: ColorTile::cleared(s.storage, 1.0, len).recording(record),
        depth: DepthTile::cleared(view.depth, len),
        stats: ProgramStats::default(),
    });
    let less = DepthState::LESS_WRITE;
    let format = view.depth;
    if let Some(p) = probe {
        let cleared = &tiles[0];
        p.record_each(|tap| tap.event().clear("colour", color_raw(&cleared.color, 0)));
        p.record_each(|tap| {
            tap.event()
                .clear("depth", Raw::Depth(cleared.depth.values[0]))
        });
    }
    counters += draw(
        &view.tiling,
        &mut tiles,
        &tris,
        &bins,
        probe,
        no_tile_culling,
        |t, tile, tri, f, c, tap| {
            let PenumbraTile {
                color,
                depth,
                stats: st,
            } = tile;
            count!(c.fragments_shaded += 1);
            st.fragments += 1;
            let z_p = shadow_map[t].read(f.local, c);
            let triangle = &geometry.triangles[tri.prim as usize];
            let z_v = tri
                .interpolate(f.x, f.y, triangle.z_v)
                .expect("penumbra triangles are set up with barycentrics");
            // The watched fragment's event, built only there.
            let event = |tap: Tap| {
                let kind = match triangle.kind {
                    ConeOrSheet::Cone => PrimitiveKind::Cone,
                    ConeOrSheet::Sheet => PrimitiveKind::Sheet,
                };
                tap.event()
                    .primitive(kind, tri.prim, "", Some(tri.front_facing))
                    .value("Z_F", f.z as f64)
                    .value("Z_P", format.to_window(z_p))
                    .value("Z_v", z_v)
            };
            let i = match penumbra_intensity::<T>(f.z, format.to_window(z_p), z_v, &view.proj) {
                Ok(i) => i,
                Err(why) => {
                    count!(c.shader_discards += 1);
                    match why {
                        Discard::BehindSurface => st.discarded_behind_surface += 1,
                        Discard::SurfaceNotBeyondSilhouette => {
                            st.discarded_surface_not_beyond_silhouette += 1
                        }
                        Discard::InFrontOfSilhouette => st.discarded_in_front_of_silhouette += 1,
                    }
                    if let Some(tap) = tap {
                        tap.push(event(tap).note(format!("discarded: {why:?}")));
                    }
                    return;
                }
            };
            let (i, falloff) = (i.to_f64(), s.falloff.apply(i).to_f64());
            if !(0.0..=1.0).contains(&i) {
                st.intensity_out_of_range += 1;
            }
            // (9)–(10): colour and depth, LESS: the darkest wins.
            let out = Fragment {
                z: falloff as f32,
                ..f
            };
            let before = tap.map(|_| {
                let colour = color_raw(color, f.local);
                (depth.values[f.local], colour, c.overflow_events)
            });
            let written = depth.test_and_write(&less, &out, c);
            if written {
                color.write(f.local, falloff, c);
                st.written += 1;
            }
            if let (Some(tap), Some((depth_before, colour_before, overflows))) = (tap, before) {
                let z = format.quantize(out.z);
                let e = event(tap).value("I", i).value("I'", falloff).depth(
                    format,
                    less.func,
                    z,
                    depth_before,
                    written,
                );
                let depth_after = Raw::Depth(depth.values[f.local]);
                let e = e.write(
                    "depth",
                    Raw::Depth(depth_before),
                    depth_after,
                    Overflow::Clamp,
                    0,
                );
                tap.push(e.note("(10): I' as depth, LESS: the darkest wins"));
                let e = tap.event().write(
                    "colour",
                    colour_before,
                    color_raw(color, f.local),
                    s.storage.overflow(),
                    c.overflow_events - overflows,
                );
                tap.push(e.note(if written {
                    "(9): I' written"
                } else {
                    "not written"
                }));
            }
        },
    );
    let mut program = ProgramStats::default();
    let mut color = Vec::with_capacity(tiles.len());
    for t in tiles {
        program += t.stats;
        color.push(t.color);
    }
    (color, program, counters)
}

/// Pass 3 (module doc): visibility per pixel, the screen stats, the counters; the fragment
/// program's bias subtraction (`bias-stage = lookup`) in the shader precision `T`.
fn screen_pass<T: ShaderFloat>(
    frame: &Frame,
    view: &LightView,
    shadow_map: &[DepthTile],
    penumbra_map: &[ColorTile],
    s: &PenumbraMapSettings,
) -> (Visibility, ScreenStats, Counters) {
    let receivers = frame.primary_ray_receivers();
    let prims = frame.prim_ids();
    let slopes = match s.bias_stage {
        BiasStage::Lookup => view.depth_slopes(frame.scene),
        BiasStage::Render => Vec::new(),
    };
    let width = frame.scene.width as usize;
    let depth_bytes = view.depth.bytes();
    let taps = match s.filter {
        Filter::Nearest => 1,
        Filter::Bilinear => 4,
    };
    let probe = frame.probe_pass("screen");
    let (values, stats, counters) = super::shade_receivers(
        &receivers,
        width,
        probe.as_ref(),
        |i, r, st: &mut ScreenStats, c, tap| {
            let record = |e: Option<ProbeEvent>, v: f32, clamped: bool, why: &str| {
                if let (Some(tap), Some(e)) = (tap, e) {
                    tap.push(e.resolve(&[v], clamped).note(why));
                }
            };
            let event = tap.map(|tap| tap.event());
            let Some(r) = r else {
                record(event, 1.0, false, "background: lit");
                return 1.0;
            };
            st.receivers += 1;
            count!(c.fragments_shaded += 1);
            let Some([x, y, z]) = view.window(r.point) else {
                st.behind_light += 1;
                record(event, 1.0, false, "behind the light: lit");
                return 1.0;
            };
            count!(c.depth_read_bytes += depth_bytes);
            let z = match slopes.get(prims[i] as usize) {
                Some(&(m, z_max)) => {
                    let amount = T::from_f64(s.offset.amount(view.depth, m, z_max));
                    (T::from_f64(z as f64) - amount).to_f64() as f32
                }
                None => z,
            };
            let event = event.map(|e| {
                let (t, l) = view.nearest_texel(x, y);
                let e = e
                    .value("x", x as f64)
                    .value("y", y as f64)
                    .value("z", z as f64);
                e.value(
                    "shadow-map depth",
                    view.depth.to_window(shadow_map[t].values[l]),
                )
            });
            if !view.lit(shadow_map, [x, y, z]) {
                st.umbra += 1;
                record(event, 0.0, false, "behind the shadow map's surface: umbra");
                return 0.0;
            }
            count!(c.color_read_bytes += taps * s.storage.bytes());
            let v = view.sample(x, y, s.filter, |t, l| penumbra_map[t].value(l) as f64);
            if !(0.0..=1.0).contains(&v) {
                st.out_of_range += 1;
            }
            st.penumbra += (v < 1.0) as u64;
            let vis = v.clamp(0.0, 1.0) as f32;
            let event = event.map(|e| e.value("penumbra map", v));
            record(
                event,
                vis,
                vis as f64 != v,
                "lit by the shadow map: the penumbra map's value",
            );
            vis
        },
    );
    (Visibility::Gray(values), stats, counters)
}

/// A colour sample as stored, for probes ([`crate::gpu::probe`]).
fn color_raw(tile: &ColorTile, i: usize) -> Raw {
    let stored = tile.values[i];
    match tile.format {
        ColorFormat::Unorm8 => Raw::U8(stored as u8),
        ColorFormat::F16 => Raw::F16(stored as u16),
        ColorFormat::F32 => Raw::F32(stored),
    }
}

/// `penumbra-map`'s pinned golden renders ([`crate::methods::Method::goldens`]).
const GOLDENS: &[crate::methods::Golden] = &[
    crate::methods::Golden::new("cylinder"),
    crate::methods::Golden::new("two-lights"),
    crate::methods::Golden::new("cube-of-spheres-sphere"),
    crate::methods::Golden::new("pw-columns"),
    crate::methods::Golden::new("pw-fractal"),
    crate::methods::Golden::new("pw-2002"),
    crate::methods::Golden::new("scenes/real/scorpion.toml"),
    // penumbra-map's pass-2 program (Z′ conversions, I, falloff) and dbuffer's screen program
    // (|cx|, t, V) in fp24 and fp16.
    crate::methods::Golden::variant("cube-of-spheres-sphere", "shader-fp24", &[])
        .gpu(&[("shader", "fp24")]),
    crate::methods::Golden::variant("cube-of-spheres-sphere", "shader-fp16", &[])
        .gpu(&[("shader", "fp16")]),
    // penumbra-map (Wyman & Hansen 2003): map sizes and storage formats.
    crate::methods::Golden::variant(
        "pw-columns",
        "map32-unorm8",
        &[("map-size", "32"), ("storage", "unorm8")],
    ),
    crate::methods::Golden::variant(
        "pw-columns",
        "map32-f32",
        &[("map-size", "32"), ("storage", "f32")],
    ),
    crate::methods::Golden::variant(
        "pw-columns",
        "map128-unorm8",
        &[("map-size", "128"), ("storage", "unorm8")],
    ),
    crate::methods::Golden::variant(
        "pw-columns",
        "map128-f32",
        &[("map-size", "128"), ("storage", "f32")],
    ),
];

/// `penumbra-map`'s configurations in the accuracy–time sweep ([`crate::methods::Method::sweep`]).
const SWEEP: &[crate::methods::OptionPairs] = &[&[], &[("storage", "f32")], &[("horizon", "clip")]];

/// What the precision experiment measures of it ([`crate::experiment::precision`]): its fragment programs only.
const PRECISION: PrecisionSpec = PrecisionSpec {
    shader_arithmetic: true,
    storage: &[],
    overflow: &[],
};

/// `penumbra-map` in the registry ([`crate::methods::ALL`]).
pub const METHOD: crate::methods::Method = crate::methods::Method {
    name: "penumbra-map",
    paper: "Wyman & Hansen, EGSR 2003: penumbra maps",
    // Penumbra maps use spherical lights (Wyman & Hansen §4).
    supports: |s| matches!(s, LightShape::Sphere { .. }),
    lights: crate::methods::SeveralLights::PerLight,
    options: crate::methods::OptionTableSpec::of::<PenumbraMapOptions>(),
    // Not measured: the largest method's figure (wedge-blending's).
    bytes_per_pixel: 384,
    bytes_per_triangle: 240,
    default_run: crate::methods::DefaultRun::EveryScene,
    sums_per_silhouette_edge: false,
    table_note: |_| None,
    check: |frame| read_settings(frame).map(drop),
    run,
    goldens: GOLDENS,
    sweep: SWEEP,
    precision: PRECISION,
};

/// Run `penumbra-map` on a rendered frame (one light: [`super::run`] averages several).
pub fn run(frame: &Frame) -> Result<MethodOutput, InputError> {
    let mut rec = PassRecorder::new(frame, METHOD.name);
    let s = read_settings(frame)?;
    let n = s.map_size;
    rec.uses(BufferPlan::depth_target(
        format!("shadow-map {n}x{n}"),
        s.depth,
    ));
    rec.uses(BufferPlan::color_target(
        format!("penumbra-map colour {n}x{n}"),
        s.storage,
        1,
    ));
    rec.uses(BufferPlan::depth_target(
        format!("penumbra-map depth {n}x{n}"),
        s.depth,
    ));
    if let Some(hiz_tile) = frame.gpu.hiz_tile() {
        rec.uses(BufferPlan::hiz_zmin_zmax_of(
            "shadow map",
            s.depth,
            hiz_tile,
        ));
    }
    let r = render_with(&mut rec, &s)?;
    rec.dump_all(|| map_dumps(&r, &s));
    let (visibility, horizon) = clip_to_horizon(&mut rec, s.horizon, r.visibility);
    let settings = serde_json::json!({
        "settings": s,
        "light_view": {
            "axis": r.view.axis.to_array(),
            "near": r.view.proj.near,
            "far": r.view.proj.far,
        },
        "silhouette_edges": r.silhouette.0,
        "silhouette_loops": r.silhouette.1,
        "max_silhouette_vertex_degree": r.silhouette.2,
        "cones": r.geometry.cones,
        "sheets": r.geometry.sheets,
        "skipped_sheets": r.geometry.skipped_sheets,
        "max_sheet_twist_deg": r.geometry.max_sheet_twist_deg,
        "penumbra_triangles": r.geometry.triangles.len(),
        "program": r.program,
        "screen": r.screen,
        "horizon": horizon,
        "gpu": frame.gpu,
    });
    Ok(rec.finish(visibility, settings))
}

/// The dumps of the shadow map and the penumbra map (module doc).
fn map_dumps(r: &PenumbraMapRender, s: &PenumbraMapSettings) -> Vec<BufferDump> {
    let tiling = &r.view.tiling;
    let size = (r.view.size(), r.view.size());
    let shadow = BufferDump::new(
        "shadow-map",
        "the shadow map from the light center (Wyman & Hansen §3, pass 1): the nearest depth \
         per texel of the fitted light view, as stored (polygon offset included with \
         bias_stage = render); a receiver deeper than its texel is in the umbra",
        size,
        ElementFormat::Depth(r.view.depth),
        depth_values(
            r.view.depth,
            row_major(tiling, &r.shadow_map, |t| &t.values).into_iter(),
        ),
    );
    let kind = match s.storage {
        ColorFormat::Unorm8 => EventKind::Saturate,
        _ => EventKind::NonFinite,
    };
    let penumbra = BufferDump::new(
        "penumbra-map",
        "the penumbra map (Wyman & Hansen §3, pass 2): per texel the darkest intensity I′ of \
         the cones and sheets over the shadow map's surface, 1 where none reached; the screen \
         pass reads it where a receiver is not in the umbra",
        size,
        ElementFormat::Color(s.storage, 1),
        color_values(
            s.storage,
            row_major(tiling, &r.penumbra_map, |t| &t.values).into_iter(),
        ),
    )
    .with_events(EventMap::new(
        kind,
        row_major(tiling, &r.penumbra_map, |t| &t.overflows),
        Vec::new(),
    ));
    vec![shadow, penumbra]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::transform::Projection;
    use glam::DVec3;

    fn proj() -> Projection {
        Projection::frustum(
            DVec3::ZERO,
            DVec3::NEG_Z,
            DVec3::Y,
            [-1.0, 1.0, -1.0, 1.0],
            1.0,
            10.0,
            [64, 64],
        )
    }

    /// The window depth of view depth `d` (f64, the projection's own mapping).
    fn window(p: &Projection, d: f64) -> f64 {
        p.window_depth(DVec3::new(0.0, 0.0, -d)).unwrap()
    }

    #[test]
    fn intensity_is_the_depth_ratio_of_equation_1() {
        let p = proj();
        // Silhouette at 2, fragment at 3, surface at 6: I = (3 − 2)/(6 − 2).
        let i =
            penumbra_intensity::<f64>(window(&p, 3.0) as f32, window(&p, 6.0), 2.0, &p).unwrap();
        assert!((i - 0.25).abs() < 1e-6, "{i}");
        // Line (4): the fragment behind the surface.
        assert_eq!(
            penumbra_intensity::<f64>(window(&p, 7.0) as f32, window(&p, 6.0), 2.0, &p),
            Err(Discard::BehindSurface)
        );
    }

    #[test]
    fn degenerate_denominators_and_rounding_are_discarded_not_divided() {
        let p = proj();
        let z = window(&p, 2.0);
        let tip = p.view_depth(z as f32 as f64);
        // The cone's tip on the occluder itself: Z_F′ = Z_P′ = Z_v, the paper's I is 0/0.
        assert_eq!(
            penumbra_intensity::<f64>(z as f32, z as f32 as f64, tip, &p),
            Err(Discard::SurfaceNotBeyondSilhouette)
        );
        // A fragment rounded in front of its silhouette point over a surface beyond it.
        assert_eq!(
            penumbra_intensity::<f64>(z as f32, window(&p, 5.0), tip * (1.0 + 1e-9), &p),
            Err(Discard::InFrontOfSilhouette)
        );
        // At the silhouette point over a surface beyond it: I = 0, the darkest.
        assert_eq!(
            penumbra_intensity::<f64>(z as f32, window(&p, 5.0), tip, &p),
            Ok(0.0)
        );
    }

    /// First-order bound on |I_T − I| (module doc, "Shader precision") for inputs exact in
    /// `T` (window depths on the fp16 grid, an integer `Z_v`; `proj` has n = 1, f = 10, so
    /// `f·n` and `f − n` are exact) with unit roundoff `u`. `Z′ = f·n/(f − z·(f − n))`: the
    /// product `z·(f − n)` (relative u) enters the difference `D = f − z·(f − n)` as an
    /// absolute error `u·z·(f − n)`, the difference and the quotient round once each, so
    /// `Z′` is off by `Z′·u·(z·(f − n)/D + 2)`. `N = Z_F′ − Z_v` and `M = Z_P′ − Z_v` add that
    /// and their own rounding; `I = N/M` adds `u·I`. Relative errors below 5 % make the
    /// second-order terms a fraction 0.05 of the first-order ones, covered by the factor 1.05.
    fn intensity_bound(p: &Projection, z_f: f64, z_p: f64, z_v: f64, u: f64) -> f64 {
        let (n, f) = (p.near, p.far);
        let conversion = |z: f64| u * (z * (f - n) / (f - z * (f - n)) + 2.0);
        let (zf, zp) = (p.view_depth(z_f), p.view_depth(z_p));
        let (num, den) = (zf - z_v, zp - z_v);
        let e_num = zf * conversion(z_f) + u * num;
        let e_den = zp * conversion(z_p) + u * den;
        let i = num / den;
        1.05 * (e_num / den + i * e_den / den + i * u)
    }

    /// Pass 2's `I` in fp32, fp24 and fp16 against f64, within [`intensity_bound`]; fp16
    /// must differ somewhere (the program does compute at `T`).
    #[test]
    fn intensity_in_each_precision_is_within_the_rounding_bound() {
        use crate::gpu::shader_float::{Fp16, Fp24, Fp32, ShaderFloat, FP16, FP24, FP32};
        fn check<T: ShaderFloat>(p: &Projection, mantissa_bits: i32) -> (usize, f64) {
            let u = libm::ldexp(1.0, -(mantissa_bits + 1));
            let grid = [0.5, 0.75, 0.875, 0.90625, 0.96875, 0.9951171875];
            let (mut differ, mut worst) = (0, 0.0f64);
            for z_f in grid {
                for z_p in grid {
                    for z_v in [1.0, 1.5, 2.0, 3.0] {
                        let Ok(exact) = penumbra_intensity::<f64>(z_f as f32, z_p, z_v, p) else {
                            continue;
                        };
                        let i = penumbra_intensity::<T>(z_f as f32, z_p, z_v, p)
                            .unwrap_or_else(|d| panic!("{z_f} {z_p} {z_v}: {d:?}"))
                            .to_f64();
                        let bound = intensity_bound(p, z_f, z_p, z_v, u);
                        let err = (i - exact).abs();
                        assert!(err <= bound, "{z_f} {z_p} {z_v}: |{i} − {exact}| > {bound}");
                        differ += (err > 0.0) as usize;
                        worst = worst.max(err / bound.max(f64::MIN_POSITIVE));
                    }
                }
            }
            (differ, worst)
        }
        let p = proj();
        assert_eq!((p.near, p.far), (1.0, 10.0));
        let (_, w32) = check::<Fp32>(&p, FP32.mantissa_bits);
        let (_, w24) = check::<Fp24>(&p, FP24.mantissa_bits);
        let (d16, w16) = check::<Fp16>(&p, FP16.mantissa_bits);
        assert!(d16 > 0, "fp16 changed no I");
        eprintln!("worst error / bound: fp32 {w32:.3}, fp24 {w24:.3}, fp16 {w16:.3}");
    }

    #[test]
    fn smoothstep_is_the_bernstein_interpolant() {
        for (i, e) in [(0.0, 0.0), (0.5, 0.5), (1.0, 1.0), (0.25, 0.15625)] {
            assert_eq!(Falloff::Smoothstep.apply(i), e);
            assert_eq!(Falloff::Linear.apply(i), i);
        }
    }
}
