//! `ssv`: the geometry-based soft shadow volume algorithm (Paper III, Assarsson &
//! Akenine-Möller, SIGGRAPH 2003) for rectangular, textured rectangular and spherical lights.
//!
//! * **Pass 1** (§3.2.1): the hard shadow quads from the light center
//!   ([`shadow_volume_triangles`], its submission order) add −1.0 (entering, front-facing) and
//!   +1.0 (leaving, back-facing) to a V-buffer cleared to 1.0, exactly as the stencil counts of
//!   `hard-sv` (z-pass; z-fail with caps when the eye is in shadow, chosen as `hard-sv` does).
//! * **Pass 2** (§3.2.2): one wedge per possible silhouette edge of the same edges, in the same
//!   order ([`SsvWedge`], §3.1; built around the sphere itself for a sphere light). For every
//!   pixel covered by the wedge's front-facing triangles, the receiver point `p` is tested
//!   against the wedge's four planes; inside, the signed coverage of the edge's semi-infinite
//!   hard shadow quad is added — positive when `p` is on the umbra side of the quad (the
//!   paper's "negative half space"). The sum over the silhouette is Green's theorem: exact for
//!   occluders without the single-silhouette or overlap artifacts (§5.3).
//! * **Coverage** (`coverage`): `exact` clips the projected quad against the light
//!   ([`edge_coverage_exact`](crate::light::coverage::edge_coverage_exact), §3.2.2; for a sphere [`sphere_edge_coverage_exact`](crate::light::coverage::sphere_edge_coverage_exact), below);
//!   `texture` looks the clipped projected edge up in the 4D coverage texture (§3.3) of
//!   `texture-n` (8…64, default 32) with `filter` (`nearest` (default; the paper: "for normal
//!   scenes, this filtering is not necessary"), `bilinear`, `quadrilinear`).
//! * **V-buffer** (`vbuffer`, [`crate::gpu::vbuffer`]): `f32` (default), `f16`, and `8bit`
//!   (§4.2): pass 1 goes to the 8-bit stencil ([`stencil_shadow`], wrap) and pass 2 to the
//!   saturating R (add) / G (subtract) channels; resolved as `1 − stencil + (R − G)/63`.
//! * **Textured lights** (§3.3, §4.1): the coverage texture is RGB (the light texture resampled
//!   to n×n), the V-buffer RGB f32, and the visibility RGB. `coverage = texture` is required
//!   and is the default for them; the 8-bit V-buffer is grey only ("only one component could be
//!   used", §4.2) and is rejected for textured lights.
//!
//! * **Shader precision** (`[options.gpu] shader`, [`crate::gpu::shader_float`]): pass 2's
//!   fragment program — the wedge's inside test (its four plane evaluations), the exact
//!   coverage of a rectangle (the clipping and area arithmetic,
//!   [`crate::light::coverage::shader_edge_coverage`]) and, with `coverage = texture`, the
//!   texture coordinates (the clipped projected edge) and the sign applied to the fetched
//!   value — runs in the chosen precision, and so does a sphere's coverage (the chord in the
//!   light space of the receiver, its `atan2` and sector area,
//!   [`crate::light::coverage::shader_sphere_edge_coverage`]); the texture unit's addressing
//!   and filtering stay as they are. The hard quads of pass 1 and the wedges (§3.1) are
//!   geometry built on the CPU and submitted as vertices, and stay f64.
//!
//! * **The receiver's horizon** (`horizon`, [`super::horizon_clip`]): `clip` limits the
//!   visibility to the fraction `f` of the light in front of the receiver's plane; `integrate`
//!   (rectangle lights, exact coverage, f32 or f16 V-buffer) integrates over the clipped light:
//!   a scale pass between pass 1 and pass 2 ([`HORIZON_SCALE`]) multiplies the V-buffer's
//!   `1 − count` by `f` and keeps `f` in a fraction buffer, each wedge fragment's coverage is
//!   clipped by the receiver's half-plane
//!   ([`EdgeCoverageProgram::at_in_front`](crate::light::coverage::EdgeCoverageProgram::at_in_front)),
//!   and the resolve clamps to `[0, f]` (`docs/horizon.md`, "`integrate`").
//!
//! Choices where the paper is silent:
//! * The receiver point of a pixel is the depth-buffer point ([`Frame::receivers`]), the same
//!   one `raycast` uses by default, so the error against the reference is the method's own.
//! * The eye in or near a wedge: the paper rasterizes front faces only. When the eye lies
//!   within the near-plane radius of a wedge (so front faces could be missing or clipped by the
//!   near plane), that wedge is drawn as a full-screen quad instead; the inside test still
//!   decides per pixel, so the result is the same, only more pixels are tested. Degenerate
//!   wedges ([`SsvWedge::new`] returns `None`) are handled the same way.
//! * Sphere lights (§5.3: pass 2 is "trivial to modify" for a sphere, "we do not use a
//!   precomputed coverage texture ... all computations can be done in the pixel shader"):
//!   pass 1 is unchanged (hard quads from the center); the wedges are built around the
//!   sphere (§3.1's bounding-sphere construction, [`WedgeLight::Sphere`]); the coverage is the
//!   signed fraction of the disk through the center facing `p` — the sphere as the `raycast`
//!   reference sees it — covered by the projected quad, computed exactly as sector minus
//!   triangle ([`sphere_edge_coverage_exact`](crate::light::coverage::sphere_edge_coverage_exact), the same arithmetic as `ssv-optimized`'s
//!   spherical shader, Paper IV §4.2.1), with the rectangle's sign convention and every
//!   V-buffer format. Following §5.3, there is no coverage texture for spheres:
//!   `coverage = "texture"` with a sphere light is an input error naming `options.ssv.coverage`
//!   (the 4D texture of §3.3 is indexed by the edge clipped to the rectangle).
//! * Final visibility: the resolved V-buffer clamped to [0, 1] (overlapping occluders can
//!   drive the Green's sum below 0, §5.3 "object overlap artifact"); background pixels are 1.
//!
//! Buffer dumps (`--dump-buffers`, [`super::dump`]): `vbuffer`, the V-buffer in its format
//! before the resolve, with its overflow events (f16: non-finite results; 8-bit: saturated
//! blends) and the pixels the resolve clamps; with the 8-bit V-buffer also `stencil`, the
//! umbra counts of pass 1.

use super::dump::{row_major, BufferDump, ElementFormat, EventKind, EventMap, VBufferDump};
use super::hard_sv::stencil_dump;
use super::hard_sv::{shadow_test, stencil_row_major, stencil_shadow, ShadowTest, StencilOverflow};
use super::hard_sv::{StencilShadowSettings, Submission};
use super::horizon_clip::{clip_to_horizon, uses_receiver_normals, Horizon, IntegrableHorizonKeys};
use super::output::MethodOutput;
use crate::error::InputError;
use crate::frame::{setup_all, Frame, Receiver, FULL_SCREEN};
use crate::geometry::shadow_volume::{
    shadow_volume_parts, shadow_volume_triangles, volume_event, Capping,
};
use crate::geometry::silhouette::{light_facing, possible_silhouettes};
use crate::geometry::ssv_wedge::{SsvWedge, WedgeLight};
use crate::gpu::counters::{count, Counters};
use crate::gpu::depth::{DepthFunc, DepthState};
use crate::gpu::hiz::InsideTestRounding;
use crate::gpu::normal_buffer;
use crate::gpu::probe::{PrimitiveKind, Tap};
use crate::gpu::raster::{bin, bin_to, draw, touched_tile_count, touches_tile};
use crate::gpu::setup::{setup_triangle, CullMode, RasterTriangle};
use crate::gpu::shader_float::ShaderFloat;
use crate::gpu::transform::ClipVertex;
use crate::gpu::vbuffer::{
    add_probed, VBuffer8Tile, VBufferF16Tile, VBufferF32Tile, VBufferFormat, VBufferRgbTile,
    VBufferTile,
};
use crate::light::coverage::{
    shader_projected_edge_in_light, shader_quad_side, shader_sphere_edge_coverage,
    EdgeCoverageProgram,
};
use crate::light::coverage_texture::{
    coverage_texture, CoverageFilter, CoverageTexture, CoverageTextureKey, DEFAULT_N, MAX_N, MIN_N,
};
use crate::light::horizon::SquarePlane;
use crate::methods::hard_sv::CountMode;
use crate::methods::output::BufferPlan;
use crate::methods::precision_spec::{NarrowFormat, OverflowKnobs, PrecisionSpec, StackLight};
use crate::methods::recorder::PassRecorder;
use crate::options::{option_names, option_table, OptionTable, OptionType};
use crate::scene::{Light, LightShape};
use crate::visibility::Visibility;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::Arc;

/// How the coverage of an edge is computed (module doc, "Coverage").
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum CoverageMode {
    /// Exact clipping (§3.2.2).
    Exact,
    /// The 4D coverage texture of `n` with `filter` (§3.3).
    Texture {
        /// Texel positions per light side.
        n: u32,
        /// Lookup filter.
        filter: CoverageFilter,
    },
}

/// The settings of one `ssv` render.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct SsvSettings {
    /// Coverage computation.
    pub coverage: CoverageMode,
    /// V-buffer format (RGB f32 for textured lights).
    pub vbuffer: VBufferFormat,
    /// z-pass or z-fail for pass 1.
    pub test: ShadowTest,
    /// The receiver's own horizon (module doc, "The receiver's horizon"); with `integrate`
    /// the visibility is integrated over the light clipped by the receiver's tangent plane.
    /// `stats.json` shows it under its own `"horizon"`.
    #[serde(skip)]
    pub horizon: Horizon,
}

option_names! {
    /// How `ssv` computes coverage (`[options.ssv] coverage`; module doc, "Coverage").
    pub enum CoverageKind {
        /// Exact clipping (§3.2.2).
        Exact = "exact",
        /// The 4D coverage texture (§3.3).
        Texture = "texture",
    }
}

option_names!(CoverageFilter {
    Nearest = "nearest",
    Bilinear = "bilinear",
    Quadrilinear = "quadrilinear",
});

option_names! {
    /// The V-buffer `ssv` renders into (`[options.ssv] vbuffer`; module doc, "V-buffer").
    pub enum VBufferKind {
        /// f32 (RGB f32 for a textured light).
        F32 = "f32",
        /// f16.
        F16 = "f16",
        /// The 8-bit stencil and R/G channels of §4.2.
        Bit8 = "8bit",
    }
}

option_table! {
    /// `[options.ssv]` (module doc).
    pub struct SsvOptions["ssv"] {
        ..horizon: IntegrableHorizonKeys,
        /// count pass 1 z-pass or z-fail; auto: z-fail when the near plane is in the light center's shadow
        mode: CountMode = CountMode::Auto;
        /// coverage of an edge: exact clipping (Paper III §3.2.2) or the 4D coverage texture (§3.3; rectangle lights)
        coverage: Option<CoverageKind> = None, scene "texture for a textured light, else exact";
        /// texel positions per light side of the coverage texture (coverage = texture only)
        texture_n: u32 [MIN_N..=MAX_N] = DEFAULT_N;
        /// lookup filter of the coverage texture (coverage = texture only)
        filter: CoverageFilter = CoverageFilter::Nearest;
        /// V-buffer format: f32, f16, or the 8-bit stencil and channels of Paper III §4.2 (textured lights: f32)
        vbuffer: VBufferKind = VBufferKind::F32;
    }
}

/// Read the `ssv` options (module doc) for `frame`, and the `mode` as written.
pub fn read_settings(frame: &Frame) -> Result<(SsvSettings, CountMode), InputError> {
    let scene = frame.scene;
    let textured = matches!(scene.light().shape, LightShape::TexturedRect { .. });
    let o = SsvOptions::read(scene)?;
    let coverage = o.coverage.unwrap_or(if textured {
        CoverageKind::Texture
    } else {
        CoverageKind::Exact
    });
    let vbuffer = match o.vbuffer {
        VBufferKind::F32 if textured => VBufferFormat::RgbF32,
        VBufferKind::F32 => VBufferFormat::F32,
        VBufferKind::F16 => VBufferFormat::F16,
        VBufferKind::Bit8 => VBufferFormat::Split8,
    };
    let bad = |key: &str, msg: &str| scene.option_error(SsvOptions::NAME, key, msg);
    if textured && coverage == CoverageKind::Exact {
        return Err(bad(
            "coverage",
            "textured lights need coverage = \"texture\" (the RGB coverage texture, Paper III §3.3)",
        ));
    }
    if matches!(scene.light().shape, LightShape::Sphere { .. }) && coverage == CoverageKind::Texture
    {
        return Err(bad(
            "coverage",
            "sphere lights need coverage = \"exact\" (Paper III §5.3: no coverage texture for \
             spheres; the 4D texture of §3.3 is defined over a rectangle)",
        ));
    }
    let texture_key = ["texture-n", "filter"]
        .into_iter()
        .find(|k| SsvOptions::is_written(scene, k));
    if let (Some(key), CoverageKind::Exact) = (texture_key, coverage) {
        return Err(bad(
            key,
            "only used with coverage = \"texture\"; coverage is \"exact\" (the default for \
             rectangle and sphere lights), which has no coverage texture to size or filter",
        ));
    }
    if textured && vbuffer != VBufferFormat::RgbF32 {
        return Err(bad(
            "vbuffer",
            "textured lights need the RGB f32 V-buffer (vbuffer = \"f32\"); f16 and 8bit are grey",
        ));
    }
    let horizon = Horizon::from(o.horizon);
    if horizon == Horizon::Integrate {
        let refused = if matches!(scene.light().shape, LightShape::Sphere { .. }) {
            Some(
                "is not implemented for sphere lights: the clipped light would be a circular \
                 segment cut by each edge's sector (use horizon = \"clip\")",
            )
        } else if textured {
            Some(
                "is not implemented for textured lights: their coverage is the RGB coverage \
                 texture (Paper III §3.3), indexed by the edge clipped to the whole light",
            )
        } else if coverage == CoverageKind::Texture {
            Some(
                "needs coverage = \"exact\": the coverage texture (Paper III §3.3) is indexed by \
                 the edge clipped to the whole light, not by the receiver's plane",
            )
        } else if vbuffer == VBufferFormat::Split8 {
            Some(
                "needs a float V-buffer (vbuffer = \"f32\" or \"f16\"): the 8-bit version \
                 keeps pass 1 in the stencil, which its horizon pass cannot scale",
            )
        } else {
            None
        };
        if let Some(why) = refused {
            return Err(bad("horizon", &format!("horizon = \"integrate\" {why}")));
        }
    }
    let coverage = match coverage {
        CoverageKind::Exact => CoverageMode::Exact,
        CoverageKind::Texture => CoverageMode::Texture {
            n: o.texture_n,
            filter: o.filter,
        },
    };
    Ok((
        SsvSettings {
            coverage,
            vbuffer,
            test: shadow_test(o.mode, frame, &[scene.light().center]),
            horizon,
        },
        o.mode,
    ))
}

/// One silhouette edge with its wedge: the edge oriented so that the coverage sign convention
/// of [`crate::light::coverage`] gives "+ on the umbra side", and `None` for a wedge drawn
/// full-screen (module doc).
struct EdgeWedge {
    e0: DVec3,
    e1: DVec3,
    wedge: Option<SsvWedge>,
}

/// Everything pass 2 needs per fragment.
struct CoverageSource<'a, T> {
    light: WedgeLight,
    /// Under a rectangle with exact coverage, the fragment program of each edge's coverage
    /// with its per-edge terms computed once (indexed as the edges), else empty.
    programs: Vec<EdgeCoverageProgram<T>>,
    mode: CoverageMode,
    texture: Option<Arc<CoverageTexture>>,
    receivers: &'a [Option<Receiver>],
    width: u32,
    /// With `horizon = integrate`, the light and the receiver-normal buffer the program
    /// reads each fragment's plane from.
    horizon: Option<(&'a Light, &'a [DVec3])>,
}

impl<T: ShaderFloat> CoverageSource<'_, T> {
    /// The signed per-channel coverage of edge `k`, `w`, at `p`, the receiver of pixel `i`
    /// (module doc), computed in the shader precision `T` (module doc, "Shader precision");
    /// with `horizon = integrate`, of the part of the light in front of the receiver's plane
    /// (a light wholly in front takes the default program, wholly behind covers nothing).
    fn coverage(&self, k: usize, w: &EdgeWedge, p: DVec3, i: usize) -> [f32; 3] {
        let light = match self.light {
            WedgeLight::Rect(light) => light,
            WedgeLight::Sphere { center, radius } => {
                let c = shader_sphere_edge_coverage::<T>(center, radius, p, w.e0, w.e1);
                return [c.to_f64() as f32; 3];
            }
        };
        match (self.mode, &self.texture) {
            (CoverageMode::Texture { filter, .. }, Some(t)) => {
                let Some([a, b]) = shader_projected_edge_in_light::<T>(&light, p, w.e0, w.e1)
                else {
                    return [0.0; 3];
                };
                let s = shader_quad_side::<T>(light.center, p, w.e0, w.e1);
                t.lookup(a.to_f64(), b.to_f64(), filter)
                    .map(|v| (s * T::from_f64(v)).to_f64() as f32)
            }
            _ => {
                let program = &self.programs[k];
                let plane = self
                    .horizon
                    .and_then(|(light, normals)| SquarePlane::<T>::of(light, p, normals[i]));
                let c = match plane {
                    Some(plane) => match plane.corners_in_front() {
                        4 => program.at(p),
                        0 => T::zero(),
                        _ => program.at_in_front(p, &plane),
                    },
                    None => program.at(p),
                };
                [c.to_f64() as f32; 3]
            }
        }
    }
}

/// The probe's note for a wedge the hierarchical Z rejected for the probed pixel's tile.
const WEDGE_CULLED: &str = "culled for the tile by the hierarchical Z: the wedge's inside test \
     fails at every receiver of the tile (its receiver bounds), or the tile has none";

/// The name of pass 1.
const HARD_QUADS: &str = "ssv-hard-quads";

/// What the two passes hand back besides what they recorded.
pub struct SsvRender {
    /// Visibility per pixel, row-major, clamped to [0, 1]; background 1.
    pub visibility: Visibility,
    /// Number of wedges, and how many of them were drawn full-screen.
    pub wedges: (usize, usize),
}

/// Render `ssv` with `settings` on the recorder's frame (the light must be a rectangle or a
/// sphere, with exact coverage for a sphere: [`read_settings`] checks both). The passes, the
/// buffers, the pixels the resolve clamps and the dumps (module doc) go to `rec`.
pub fn render(rec: &mut PassRecorder, settings: &SsvSettings) -> SsvRender {
    crate::with_shader_float!(rec.frame().gpu.shader, T => match settings.vbuffer {
        VBufferFormat::F32 => {
            render_with::<VBufferF32Tile, T>(rec, settings, Some(VBufferF32Tile::scale))
        }
        VBufferFormat::F16 => {
            render_with::<VBufferF16Tile, T>(rec, settings, Some(VBufferF16Tile::scale))
        }
        VBufferFormat::RgbF32 => render_with::<VBufferRgbTile, T>(rec, settings, None),
        VBufferFormat::Split8 => render_with::<VBuffer8Tile, T>(rec, settings, None),
    })
}

/// A V-buffer format's multiplication of a pixel by a factor (`horizon = integrate`'s
/// scale pass; the grey float formats).
type Scale<V> = fn(&mut V, usize, f32, &mut Counters);

fn render_with<V: VBufferDump, T: ShaderFloat>(
    rec: &mut PassRecorder,
    settings: &SsvSettings,
    scale: Option<Scale<V>>,
) -> SsvRender {
    let frame = rec.frame();
    let scene = frame.scene;
    let tiling = &frame.tiling;
    let light = WedgeLight::from_light(scene.light()).expect("ssv supports rects and spheres");
    let center = scene.light().center;
    if V::FORMAT == VBufferFormat::Split8 {
        rec.uses(BufferPlan::stencil8());
    }
    let vbuffer_plan = BufferPlan {
        name: "vbuffer".into(),
        format: format!("{:?}", settings.vbuffer),
        bytes_per_sample: settings.vbuffer.bytes(),
    };
    let mut vbuf: Vec<V> = rec.allocate(vbuffer_plan, || {
        (0..tiling.tile_count())
            .map(|_| V::cleared(tiling.tile_len()))
            .collect()
    });
    if frame.gpu.hiz {
        // Pass 1 (hard quads or the 8-bit version's stencil) and the wedges.
        rec.uses_hiz_depth();
        rec.uses(BufferPlan::hiz_receiver_bounds(&frame.gpu));
    }
    if rec.dumping() {
        vbuf.iter_mut().for_each(V::record_overflows);
    }
    frame.probe_record("clear", |tap, _| {
        tap.event().clear("vbuffer", vbuf[0].raw(0))
    });

    // Pass 1: hard shadow quads, ±1 (float V-buffers) or the stencil (8-bit version).
    let stencil = if V::FORMAT == VBufferFormat::Split8 {
        let s = StencilShadowSettings {
            test: settings.test,
            overflow: StencilOverflow::Wrap,
            submission: Submission::TwoSided,
        };
        Some(rec.pass(HARD_QUADS, |pass| {
            let (tiles, c) = stencil_shadow(frame, center, &s);
            pass.count(c);
            let values = stencil_row_major(frame, &tiles);
            pass.dump(|| {
                stencil_dump(
                    frame,
                    "stencil",
                    "pass 1 of the 8-bit V-buffer (Paper III §4.2): the stencil counts of the \
                     hard shadow quads from the light center (wrap); the resolve adds 1 − count",
                    &tiles,
                    values.clone(),
                    EventKind::Wrap,
                )
            });
            values
        }))
    } else {
        rec.pass(HARD_QUADS, |pass| {
            pass.count(hard_quads_pass(frame, settings.test, &mut vbuf))
        });
        None
    };

    // `horizon = integrate`: pass 1's count weighted by the fraction in front.
    let fractions = (settings.horizon == Horizon::Integrate).then(|| {
        let scale = scale.expect("read_settings refuses integrate without a grey float V-buffer");
        horizon_scale_pass::<V, T>(rec, &mut vbuf, scale)
    });

    // Pass 2: wedges.
    rec.pass("ssv-wedges", |pass| {
        let edges = edge_wedges(frame, &light);
        let eye_radius = frame.near_plane_radius();
        let eye = scene.camera.eye;
        let mut prims: Vec<[ClipVertex; 3]> = Vec::new();
        let mut owner: Vec<u32> = Vec::new();
        let mut full_screen = 0;
        let mut tris: Vec<RasterTriangle> = Vec::new();
        let mut pass2 = Counters::default();
        for (k, ew) in edges.iter().enumerate() {
            let (faces, cull): (Vec<[ClipVertex; 3]>, CullMode) = match &ew.wedge {
                Some(w) if !w.contains_within(eye, eye_radius) => (
                    w.triangles
                        .iter()
                        .map(|t| t.map(|v| v.clip(&frame.proj)))
                        .collect(),
                    CullMode::Back,
                ),
                _ => {
                    full_screen += 1;
                    (FULL_SCREEN.to_vec(), CullMode::None)
                }
            };
            for f in faces {
                setup_triangle(
                    &f,
                    prims.len() as u32,
                    cull,
                    tiling.width,
                    tiling.height,
                    &mut tris,
                    &mut pass2,
                );
                prims.push(f);
                owner.push(k as u32);
            }
        }
        let receivers = frame.receivers();
        let texture = match settings.coverage {
            CoverageMode::Exact => None,
            CoverageMode::Texture { n, .. } => {
                Some(coverage_texture(&match &scene.light().shape {
                    LightShape::TexturedRect { texture, .. } => {
                        CoverageTextureKey::textured(n, texture)
                    }
                    _ => CoverageTextureKey::uniform(n),
                }))
            }
        };
        let programs = match (light, settings.coverage) {
            (WedgeLight::Rect(rect), CoverageMode::Exact) => edges
                .iter()
                .map(|w| EdgeCoverageProgram::<T>::new(&rect, w.e0, w.e1))
                .collect(),
            _ => Vec::new(),
        };
        let source = CoverageSource {
            light,
            programs,
            mode: settings.coverage,
            texture,
            receivers,
            width: scene.width,
            horizon: fractions
                .is_some()
                .then(|| (scene.light(), frame.receiver_normals())),
        };
        let probe = pass.probe();
        // The watched fragment's event, built only there.
        let event = |tap: Tap, tri: &RasterTriangle| {
            let k = owner[tri.prim as usize];
            let (kind, how) = match edges[k as usize].wedge {
                Some(_) => (PrimitiveKind::Wedge, "face"),
                None => (PrimitiveKind::FullScreen, "full-screen"),
            };
            let detail = format!("of silhouette edge {k}, {how} triangle {}", tri.prim);
            tap.event()
                .primitive(kind, k, detail, Some(tri.front_facing))
        };
        // The hierarchical-Z unit's decision per wedge: the tiles where it may shade.
        let kept = frame.gpu.hiz.then(|| {
            let rounding = InsideTestRounding::new(T::PRECISION.format());
            let (kept, c) = wedge_kept_tiles(frame, &edges, &owner, &tris, &rounding);
            pass2 += c;
            kept
        });
        let is_kept = |kept: &[Vec<u32>], t: usize, tri: &RasterTriangle| {
            kept[owner[tri.prim as usize] as usize]
                .binary_search(&(t as u32))
                .is_ok()
        };
        // Each face is binned only to its wedge's kept tiles that it touches (each pair decided
        // in the binning's bands: deciding once per face and collecting the lists measured
        // slower), and the tiles it touches that were not binned are counted as culled: the
        // touched pairs less the binned ones, where counting each face's kept tiles again was a
        // serial loop of 6 ms of a 105 ms pass on two threads (`cube-of-spheres` 512²). With a
        // probe, every face is binned to the tiles it touches and rejected tile by tile, in
        // submission order, so that the watched samples record the rejection where it happens
        // (the same pairs, the same counts).
        let bins = match (&kept, &probe) {
            (Some(kept), None) => {
                let bins = bin_to(tiling, tris.len(), |i, rows| {
                    let tri = &tris[i];
                    let list = &kept[owner[tri.prim as usize] as usize];
                    let (first, end) = (rows.start * tiling.tiles_x, rows.end * tiling.tiles_x);
                    let from = list.partition_point(|&t| t < first);
                    let to = list.partition_point(|&t| t < end);
                    list[from..to]
                        .iter()
                        .map(|&t| t as usize)
                        .filter(move |&t| touches_tile(tiling, tri, t))
                });
                count!(
                    pass2.tiles_culled_hiz += (tris
                        .par_iter()
                        .map(|tri| touched_tile_count(tiling, tri))
                        .sum::<usize>()
                        - bins.pair_count()) as u64
                );
                bins
            }
            _ => bin(tiling, &tris),
        };
        let binned_kept = probe.is_none();
        pass2 += draw(
            tiling,
            &mut vbuf,
            &tris,
            &bins,
            probe.as_ref(),
            |t, _, tri, c| {
                let Some(kept) = &kept else {
                    return false;
                };
                if binned_kept {
                    return false;
                }
                let culled = !is_kept(kept, t, tri);
                count!(c.tiles_culled_hiz += culled as u64);
                if let (true, Some(probe)) = (culled, &probe) {
                    probe.record_culled(t, tri, None, WEDGE_CULLED, |tap| event(tap, tri));
                }
                culled
            },
            |t, vb, tri, f, c, tap| {
                frame.tiles[t].depth.read(f.local, c);
                let k = owner[tri.prim as usize];
                let ew = &edges[k as usize];
                let event = |tap: Tap| event(tap, tri);
                let stop = |why: &str| {
                    if let Some(tap) = tap {
                        tap.push(event(tap).note(why));
                    }
                };
                let Some(rcv) = source.receivers[(f.y * source.width + f.x) as usize] else {
                    return stop("background: no receiver");
                };
                let p = rcv.point.as_dvec3();
                if ew
                    .wedge
                    .as_ref()
                    .is_some_and(|w| !w.shader_contains::<T>(p))
                {
                    count!(c.shader_discards += 1);
                    return stop("receiver outside the wedge: discarded");
                }
                count!(c.fragments_shaded += 1);
                if source.horizon.is_some() {
                    count!(c.color_read_bytes += u64::from(normal_buffer::BYTES_PER_PIXEL));
                }
                let i = (f.y * source.width + f.x) as usize;
                let coverage = source.coverage(k as usize, ew, p, i);
                add_probed(vb, f.local, coverage, c, tap, |tap| {
                    event(tap).value("coverage", coverage[0] as f64)
                });
            },
        );

        // Resolve: pixels in parallel, each on its own (the same bits for any thread count).
        let (rgb, clamped): (Vec<[f32; 3]>, Vec<bool>) = (0..receivers.len())
            .into_par_iter()
            .map(|i| {
                if receivers[i].is_none() {
                    return ([1.0; 3], false);
                }
                let [x, y] = [i as u32 % tiling.width, i as u32 / tiling.width];
                let v = vbuf[tiling.tile_of(x, y)].resolve(tiling.local(x, y));
                let umbra = stencil.as_ref().map_or(0.0, |s| 1.0 - s[i] as f32);
                let unclamped = v.map(|x| x + umbra);
                // With `horizon = integrate` the visible part of the clipped light is at most
                // the fraction in front (1 where the whole light is).
                let top = fractions.as_ref().map_or(1.0, |f| f[i]);
                let clamped = unclamped.iter().any(|x| !(0.0..=top).contains(x));
                (unclamped.map(|x| x.clamp(0.0, top)), clamped)
            })
            .unzip();
        if fractions.is_some() {
            // The resolve's read of the fraction buffer, at every receiver.
            let read = receivers.iter().flatten().count() as u64 * u64::from(FRACTION_BYTES);
            count!(pass2.color_read_bytes += read);
        }
        pass.clamped(clamped.iter().filter(|&&c| c).count() as u64);
        pass.count(pass2);
        pass.dump(|| {
            let overflows = || row_major(tiling, &vbuf, |t| t.overflows());
            let events = match V::FORMAT {
                VBufferFormat::F16 => {
                    EventMap::new(EventKind::NonFinite, overflows(), clamped.clone())
                }
                VBufferFormat::Split8 => {
                    EventMap::new(EventKind::Saturate, overflows(), clamped.clone())
                }
                _ => EventMap::clamps(clamped.clone()),
            };
            BufferDump::new(
                "vbuffer",
                "the V-buffer before the resolve (Paper III §3.2, §4): cleared to 1, the hard \
                 quads' ±1 (pass 1, float formats) and the wedges' signed coverages (pass 2) \
                 added; visibility = clamp(V, 0, 1), for the 8-bit version (R − G)/63 + 1 − \
                 stencil",
                (scene.width, scene.height),
                ElementFormat::VBuffer(V::FORMAT),
                V::dump_values(tiling, &vbuf),
            )
            .with_events(events)
        });
        let visibility = if V::FORMAT == VBufferFormat::RgbF32 {
            Visibility::Rgb(rgb)
        } else {
            Visibility::Gray(rgb.iter().map(|v| v[0]).collect())
        };
        frame.probe_record("resolve", |tap, i| {
            let [x, y] = [i as u32 % tiling.width, i as u32 / tiling.width];
            let e = tap.event().read(
                "vbuffer",
                vbuf[tiling.tile_of(x, y)].raw(tiling.local(x, y)),
            );
            let e = match &stencil {
                Some(s) => e.value("stencil", s[i] as f64),
                None => e,
            };
            e.resolve(&visibility.channels(i), clamped[i]).note(
                match (receivers[i].is_none(), &stencil) {
                    (true, _) => "background: lit",
                    (false, Some(_)) => "1 − stencil + (R − G)/63, clamped to [0, 1]",
                    (false, None) => "the V-buffer clamped to [0, 1]",
                },
            )
        });
        SsvRender {
            visibility,
            wedges: (edges.len(), full_screen),
        }
    })
}

/// The name of `horizon = integrate`'s pass between pass 1 and pass 2.
pub const HORIZON_SCALE: &str = "ssv-horizon-scale";

/// Bytes per pixel of `horizon = integrate`'s fraction buffer (R32F).
const FRACTION_BYTES: u32 = 4;

/// `horizon = integrate`'s pass between pass 1 and pass 2 (module doc, "The receiver's
/// horizon"): at every receiver, the fraction `f` of the light in front of its tangent plane
/// (the fragment program of `horizon = clip`, in `T`, from the receiver-normal buffer)
/// multiplies the V-buffer, which holds pass 1's `1 − count` there, and is written to the
/// fraction buffer the resolve clamps with. Returns the fractions row-major, 1 for background.
fn horizon_scale_pass<V: VBufferTile, T: ShaderFloat>(
    rec: &mut PassRecorder,
    vbuf: &mut [V],
    scale: Scale<V>,
) -> Vec<f32> {
    let frame = rec.frame();
    uses_receiver_normals(rec);
    rec.uses(BufferPlan {
        name: "horizon fraction".into(),
        format: "R32F".into(),
        bytes_per_sample: FRACTION_BYTES,
    });
    let light = frame.scene.light();
    let (receivers, normals) = (frame.receivers(), frame.receiver_normals());
    let tiling = &frame.tiling;
    rec.pass(HORIZON_SCALE, |pass| {
        let probe = pass.probe();
        let per_tile: Vec<(Vec<(usize, f32)>, Counters)> = vbuf
            .par_iter_mut()
            .enumerate()
            .map(|(t, vb)| {
                let watched = probe.as_ref().filter(|p| p.watches_tile(t));
                let mut c = Counters::default();
                let mut out = Vec::new();
                for i in 0..tiling.tile_len() {
                    let [x, y] = tiling.position(t, i);
                    if x >= tiling.width || y >= tiling.height {
                        continue;
                    }
                    let k = (y * tiling.width + x) as usize;
                    let Some(r) = receivers[k] else {
                        continue;
                    };
                    count!(c.fragments_shaded += 1);
                    count!(c.color_read_bytes += u64::from(normal_buffer::BYTES_PER_PIXEL));
                    count!(c.color_write_bytes += u64::from(FRACTION_BYTES));
                    let f = SquarePlane::<T>::of(light, r.point.as_dvec3(), normals[k])
                        .expect("read_settings refuses integrate but under a rectangle")
                        .fraction()
                        .to_f64() as f32;
                    match watched.and_then(|p| p.tap(t, i)) {
                        None => scale(vb, i, f, &mut c),
                        Some(tap) => {
                            let before = vb.raw(i);
                            scale(vb, i, f, &mut c);
                            let e = tap
                                .event()
                                .value("fraction_in_front", f64::from(f))
                                .write("vbuffer", before, vb.raw(i), V::FORMAT.overflow(), 0)
                                .note(
                                    "pass 1's 1 − count times the fraction of the light in \
                                     front of the receiver's plane (horizon = integrate)",
                                );
                            tap.push(e);
                        }
                    }
                    out.push((k, f));
                }
                (out, c)
            })
            .collect();
        let mut fractions = vec![1.0; receivers.len()];
        let mut counters = Counters::default();
        for (out, c) in per_tile {
            counters += c;
            for (k, f) in out {
                fractions[k] = f;
            }
        }
        pass.count(counters);
        fractions
    })
}

/// The hierarchical-Z unit's decision for every wedge (`crate::gpu::hiz`, "Receiver
/// bounds"): the tiles, among those its faces' boxes touch, where its inside test may pass at
/// some receiver ([`crate::gpu::hiz::TileReceiverBounds::kept_tiles`]: one of the wedge's planes rejects the
/// receiver box of a block or a tile, or it has no receivers; a full-screen wedge has no
/// inside test and is rejected only where there are no receivers). The wedges are decided in
/// parallel, each on its own; the reads are counted in the returned counters.
fn wedge_kept_tiles(
    frame: &Frame,
    edges: &[EdgeWedge],
    owner: &[u32],
    tris: &[RasterTriangle],
    rounding: &InsideTestRounding,
) -> (Vec<Vec<u32>>, Counters) {
    let tiling = &frame.tiling;
    let mut rects: Vec<Option<[u32; 4]>> = vec![None; edges.len()];
    for tri in tris {
        let [x0, y0, x1, y1] = tiling.tiles_of_box(tri.bbox);
        let r = &mut rects[owner[tri.prim as usize] as usize];
        *r = Some(match *r {
            None => [x0, y0, x1, y1],
            Some([a, b, c, d]) => [a.min(x0), b.min(y0), c.max(x1), d.max(y1)],
        });
    }
    let bounds = frame.receiver_bounds();
    let per_wedge: Vec<(Vec<u32>, Counters)> = rects
        .par_iter()
        .zip(edges)
        .map(|(rect, ew)| {
            let mut c = Counters::default();
            let rejects = |b: [DVec3; 2]| {
                ew.wedge
                    .as_ref()
                    .is_some_and(|w| w.rejects_box(b, rounding))
            };
            let kept = rect.map_or_else(Vec::new, |r| bounds.kept_tiles(r, rejects, &mut c));
            (kept, c)
        })
        .collect();
    let mut total = Counters::default();
    let kept = per_wedge
        .into_iter()
        .map(|(kept, c)| {
            total += c;
            kept
        })
        .collect();
    (kept, total)
}

/// The possible silhouette edges of every mesh from the light center, in the submission order
/// of [`shadow_volume_triangles`], with their wedges. A silhouette edge `a → b` (oriented along
/// its light-facing triangle) has the shadow quad `b, a, a∞` whose normal points out of the
/// volume, so `e0 = b`, `e1 = a` puts the umbra on the positive side of
/// [`crate::light::coverage`]'s sign.
fn edge_wedges(frame: &Frame, light: &WedgeLight) -> Vec<EdgeWedge> {
    let center = frame.scene.light().center;
    let mut out = Vec::new();
    for (mesh, adj) in frame.caster_meshes() {
        let facing = light_facing(mesh, center);
        for e in possible_silhouettes(mesh, adj, &facing) {
            let (e0, e1) = (e.b.as_dvec3(), e.a.as_dvec3());
            out.push(EdgeWedge {
                e0,
                e1,
                wedge: SsvWedge::new(light, e0, e1),
            });
        }
    }
    out
}

/// Pass 1 into a float V-buffer: hard shadow quads from the light center, −1 entering, +1
/// leaving (§3.2.1), z-pass or z-fail with caps, one pass with both facings in the order of
/// [`shadow_volume_triangles`].
fn hard_quads_pass<V: VBufferTile>(frame: &Frame, test: ShadowTest, vbuf: &mut [V]) -> Counters {
    let capping = match test {
        ShadowTest::ZPass => Capping::Open,
        ShadowTest::ZFail => Capping::Capped,
    };
    let meshes = frame.caster_meshes();
    let center = frame.scene.light().center;
    let prims = shadow_volume_triangles(&meshes, center, &frame.proj, capping);
    let parts = frame
        .probe
        .as_ref()
        .map(|_| shadow_volume_parts(&meshes, center, &frame.proj, capping));
    let (tris, mut counters) = setup_all(&prims, CullMode::None, &frame.tiling);
    let bins = bin(&frame.tiling, &tris);
    let depth = DepthState {
        func: DepthFunc::Less,
        write: false,
    };
    let probe = frame.probe_pass(HARD_QUADS);
    counters += draw(
        &frame.tiling,
        vbuf,
        &tris,
        &bins,
        probe.as_ref(),
        |t, _, tri, c| {
            let idle = (depth.func, test.idle_outcome());
            frame.hiz_depth_draw(t, tri, idle, c, probe.as_ref(), |tap| {
                volume_event(tap.event(), parts.as_deref(), tri)
            })
        },
        |t, vb, tri, f, c, tap| {
            let (pass, z) = frame.tiles[t].depth.test(&depth, &f, c);
            count!(c.depth_passed += pass as u64);
            // The watched fragment's event, built only there.
            let event = |tap: Tap| {
                let e = volume_event(tap.event(), parts.as_deref(), tri);
                frame.tiles[t]
                    .depth
                    .record_test(e, depth.func, f.local, z, pass)
            };
            let delta = match (test, pass, tri.front_facing) {
                (ShadowTest::ZPass, true, true) | (ShadowTest::ZFail, false, false) => -1.0,
                (ShadowTest::ZPass, true, false) | (ShadowTest::ZFail, false, true) => 1.0,
                _ => {
                    if let Some(tap) = tap {
                        tap.push(event(tap).read("vbuffer", vb.raw(f.local)).note("no count"));
                    }
                    return;
                }
            };
            add_probed(vb, f.local, [delta; 3], c, tap, |tap| {
                event(tap).value("delta", delta as f64)
            });
        },
    );
    counters
}

/// `ssv`'s pinned golden renders ([`crate::methods::Method::goldens`]).
const GOLDENS: &[crate::methods::Golden] = &[
    crate::methods::Golden::new("cube-of-spheres"),
    crate::methods::Golden::new("single-quad"),
    crate::methods::Golden::new("cylinder"),
    crate::methods::Golden::new("eye-in-shadow"),
    crate::methods::Golden::new("two-lights"),
    crate::methods::Golden::new("scenes/real/hand.toml"),
    crate::methods::Golden::new("scenes/real/bob.toml"),
    crate::methods::Golden::new("scenes/real/scorpion.toml"),
    // ssv: coverage texture and filters, V-buffer formats, z-fail, a textured light.
    crate::methods::Golden::variant("single-quad", "texture-nearest", &[("coverage", "texture")]),
    crate::methods::Golden::variant(
        "single-quad",
        "texture-bilinear",
        &[("coverage", "texture"), ("filter", "bilinear")],
    ),
    crate::methods::Golden::variant(
        "single-quad",
        "texture-quadrilinear",
        &[("coverage", "texture"), ("filter", "quadrilinear")],
    ),
    crate::methods::Golden::variant("cube-of-spheres", "f16", &[("vbuffer", "f16")]),
    crate::methods::Golden::variant("cube-of-spheres", "8bit", &[("vbuffer", "8bit")]),
    crate::methods::Golden::variant("single-quad", "zfail", &[("mode", "zfail")]),
    crate::methods::Golden::new("scenes/fire.toml").sized(32),
    crate::methods::Golden::variant("cube-of-spheres", "d32f", &[]).gpu(&[("depth", "d32f")]),
    crate::methods::Golden::variant("cube-of-spheres", "tile16", &[]).gpu(&[("tile-size", "16")]),
    crate::methods::Golden::variant("cube-of-spheres", "tile2", &[]).gpu(&[("tile-size", "2")]),
    // Shader precision (issue 11): ssv's fragment program in ATI R300 fp24 and in fp16.
    crate::methods::Golden::variant("cube-of-spheres", "shader-fp24", &[])
        .gpu(&[("shader", "fp24")]),
    crate::methods::Golden::variant("cube-of-spheres", "shader-fp16", &[])
        .gpu(&[("shader", "fp16")]),
];

/// `ssv`'s configurations in the accuracy–time sweep ([`crate::methods::Method::sweep`]).
const SWEEP: &[crate::methods::OptionPairs] = &[
    &[("coverage", "exact"), ("vbuffer", "f32")],
    &[("coverage", "exact"), ("vbuffer", "f16")],
    &[("coverage", "exact"), ("vbuffer", "8bit")],
    &[
        ("coverage", "texture"),
        ("texture-n", "8"),
        ("filter", "nearest"),
    ],
    &[
        ("coverage", "texture"),
        ("texture-n", "16"),
        ("filter", "nearest"),
    ],
    &[
        ("coverage", "texture"),
        ("texture-n", "32"),
        ("filter", "nearest"),
    ],
    &[
        ("coverage", "texture"),
        ("texture-n", "64"),
        ("filter", "nearest"),
    ],
    &[
        ("coverage", "texture"),
        ("texture-n", "8"),
        ("filter", "bilinear"),
    ],
    &[
        ("coverage", "texture"),
        ("texture-n", "16"),
        ("filter", "bilinear"),
    ],
    &[
        ("coverage", "texture"),
        ("texture-n", "32"),
        ("filter", "bilinear"),
    ],
    &[
        ("coverage", "texture"),
        ("texture-n", "64"),
        ("filter", "bilinear"),
    ],
    &[
        ("coverage", "texture"),
        ("texture-n", "8"),
        ("filter", "quadrilinear"),
    ],
    &[
        ("coverage", "texture"),
        ("texture-n", "16"),
        ("filter", "quadrilinear"),
    ],
    &[
        ("coverage", "texture"),
        ("texture-n", "32"),
        ("filter", "quadrilinear"),
    ],
    &[
        ("coverage", "texture"),
        ("texture-n", "64"),
        ("filter", "quadrilinear"),
    ],
    &[
        ("coverage", "exact"),
        ("vbuffer", "f32"),
        ("horizon", "clip"),
    ],
    &[
        ("coverage", "exact"),
        ("vbuffer", "f32"),
        ("horizon", "integrate"),
    ],
];

/// What the precision experiment measures of it ([`crate::experiment::precision`]): Paper III's V-buffers.
const PRECISION: PrecisionSpec = PrecisionSpec {
    shader_arithmetic: true,
    storage: &[
        NarrowFormat::of("vbuffer", "f16", "f32"),
        NarrowFormat::of("vbuffer", "8bit", "f32"),
    ],
    overflow: &[
        OverflowKnobs::of(StackLight::Rect, &[("vbuffer", "f32")]),
        OverflowKnobs::of(StackLight::Rect, &[("vbuffer", "f16")]),
        OverflowKnobs::of(StackLight::Rect, &[("vbuffer", "8bit")]),
    ],
};

/// `ssv` in the registry ([`crate::methods::ALL`]).
pub const METHOD: crate::methods::Method = crate::methods::Method {
    name: "ssv",
    paper: "Paper III: soft shadow volumes, SIGGRAPH 2003",
    // Paper III §3.2.2, §3.3: rectangular and textured rectangular lights; §5.3: spheres.
    supports: |s| {
        matches!(
            s,
            LightShape::Rect { .. } | LightShape::TexturedRect { .. } | LightShape::Sphere { .. }
        )
    },
    lights: crate::methods::SeveralLights::PerLight,
    options: crate::methods::OptionTableSpec::of::<SsvOptions>(),
    bytes_per_pixel: 160,
    bytes_per_triangle: 192,
    default_run: crate::methods::DefaultRun::EveryScene,
    sums_per_silhouette_edge: true,
    table_note: |_| None,
    check: |frame| read_settings(frame).map(drop),
    run,
    goldens: GOLDENS,
    sweep: SWEEP,
    precision: PRECISION,
};

/// Run `ssv` on a rendered frame.
pub fn run(frame: &Frame) -> Result<MethodOutput, InputError> {
    let mut rec = PassRecorder::new(frame, "ssv");
    let (settings, mode) = read_settings(frame)?;
    let r = render(&mut rec, &settings);
    let (visibility, horizon) = clip_to_horizon(&mut rec, settings.horizon, r.visibility);
    Ok(rec.finish(
        visibility,
        serde_json::json!({
            "mode": mode.written(),
            "horizon": horizon,
            "resolved": settings,
            "wedges": r.wedges.0,
            "wedges_full_screen": r.wedges.1,
            "gpu": frame.gpu,
        }),
    ))
}
