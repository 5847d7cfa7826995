//! `pw2002`: soft shadows with penumbra wedges, Paper I (Akenine-Möller & Assarsson, EGWR
//! 2002) §4 `rasterizeWedge`, §4.1 construction ([`crate::geometry::penumbra_wedge`]), §4.2
//! interpolation, §5 (side-plane contributions cancel; front/back entries give 255/0).
//!
//! The LI buffer ([`crate::gpu::li_buffer`]) is cleared to 255. Every wedge face is submitted
//! (wedge by wedge, faces front, back, left, right, bottom, each polygon as a fan), back faces
//! are culled; each fragment of a front-facing wedge triangle that passes LESS against the
//! scene depth (Paper I §4 line 2, "visible fragment") does:
//! * `p = point(x, y, z)`: the pixel center un-projected at the stored depth
//!   ([`crate::gpu::transform::Projection::unproject`], f64);
//! * entry value `v_f = li_amount(s(p_f))` at the entry point p_f, the eye ray's intersection
//!   with the rasterized triangle's plane;
//! * `p_i`: p if it is inside the wedge, else the exit point p_b, found as the nearest plane the
//!   eye ray leaves through (Paper I §6); `v_i = li_amount(s(p_i))`;
//! * `addToLIBuffer(v_i − v_f)` (skipped when 0, so no write happens).
//!
//! Choice: Paper I writes `round(255·(s_i − s_f))`; we add `li_amount(s_i) − li_amount(s_f)`
//! ([`crate::geometry::penumbra_wedge::li_amount`]), within 1 of it, so that `pw2002` and
//! `pw-restructured` add literally the same integers. Background pixels (stored depth 1.0) have
//! no point; their p is never inside a wedge. Visibility = clamp(LI, 0, 255)/255.
//!
//! Options ([`Pw2002Options`]): `side-planes = compute|cancel` ([`SidePlanes`]: the §4
//! pseudocode, default, or the §5 shortcut — 255 on front planes, 0 on back and side planes;
//! pw2002 only), `hiz = off|on` (the hierarchical-Z unit, [`crate::gpu::hiz`], rejects a wedge
//! face for a tile when it lies at or behind every stored depth there: such fragments fail
//! the depth test and add nothing; off by default because Paper I ran without it; needs
//! `[options.gpu] hiz = on`; the same image either way), and, shared with `pw-restructured` ([`WedgeKeys`]), `li = 16|12|8` (bits),
//! `overflow = wrap|saturate`, `falloff = linear|smoothstep`
//! (s' = 3s² − 2s³, §4.2), `corner-wedges = on|off` (Fig. 7), `parallel-rule = on|off` (§8),
//! `lights = shared|separate` ([`MultiLight`]: several lights in one LI buffer with amounts
//! scaled by 255/n, Paper I §7, default; or one LI buffer per light, averaged).
//! The eye is assumed to be outside every shadow (Paper I §8); `pw-restructured` handles the
//! other case.
//!
//! * **Shader precision** (`[options.gpu] shader`, [`crate::gpu::shader_float`]): the fragment
//!   program of Paper I §4 `rasterizeWedge` — the entry point's plane evaluation, the inside
//!   test, the exit point, equations 1–3 at p_f and p_i and the scaling `255/n·s + 0.5` of the
//!   LI amounts ([`crate::geometry::penumbra_wedge`], "Shader precision") — runs in the chosen
//!   precision, with the point `p` and the eye ray's direction as inputs rounded to it; the
//!   floor to an integer and the LI buffer's integer arithmetic are exact. The wedges' construction
//!   (§4.1) is geometry built on the CPU and submitted as vertices, and stays f64, as does the
//!   un-projection of the pixel (the depth-buffer point, made by the rasterizer's
//!   interpolation before the program reads it).
//!
//! Buffer dump (`--dump-buffers`, [`super::dump`]): `li`, the LI buffer before the resolve, with
//! its wraps or saturations per pixel and the pixels the resolve clamps ([`li_dump`]).

use super::dump::{li_values, row_major, BufferDump, ElementFormat, EventKind, EventMap};
use super::horizon_clip::{clip_to_horizon, Horizon, HorizonKeys};
use super::output::MethodOutput;
use super::Falloff;
use crate::error::InputError;
use crate::frame::{setup_all, Frame, BACKGROUND};
use crate::geometry::near_plane::{eye_in_shadow, representative_light_points};
use crate::geometry::penumbra_wedge::{
    build_wedges, far_distance, li_amount, shader_li_amount, shader_light_intensity, wedge_radius,
    wedge_triangles, FaceKind, WedgeOptions, WedgeSet,
};
use crate::gpu::buffers::alloc_tiles;
use crate::gpu::counters::count;
use crate::gpu::depth::{DepthFunc, DepthState};
use crate::gpu::li_buffer::{li_clamped, li_visibility, LiFormat, LiOverflow, LiTile, LI_CLEAR};
use crate::gpu::probe::{PrimitiveKind, ProbeEvent, Raw, Tap};
use crate::gpu::raster::{bin, draw, TileDraw};
use crate::gpu::setup::{CullMode, RasterTriangle};
use crate::gpu::shader_float::ShaderFloat;
use crate::gpu::shader_vec::SVec3;
use crate::methods::output::BufferPlan;
use crate::methods::precision_spec::{NarrowFormat, OverflowKnobs, PrecisionSpec, StackLight};
use crate::methods::recorder::PassRecorder;
use crate::options::{option_names, option_table, OptionTable, Switch};
use crate::scene::{LightShape, Scene};
use crate::visibility::Visibility;

/// How `pw2002` values the points where an eye ray enters or leaves a wedge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum SidePlanes {
    /// Paper I §4 pseudocode: s is computed at the entry point p_f and at the exit point p_b.
    /// Where a neighbour's wedge does not continue across a shared side plane (degenerate
    /// wedges, Fig. 6), the ray keeps the intensity of the point where it left.
    Compute,
    /// Paper I §5 optimization (and what Paper II §3 builds on): 255 on the front plane, 0 on
    /// the back plane, 0 on side planes because neighbours cancel. This is what
    /// `pw-restructured` computes, so the two agree bit for bit in this mode.
    Cancel,
}

/// How the penumbra-wedge methods render a scene with several lights.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum MultiLight {
    /// Paper I §7: every light's wedges add amounts scaled by 255/n into one LI buffer,
    /// clamped once at the end. Where shadows of one light overlap (two occluders of the same
    /// light), that light's umbra is subtracted twice and eats into the other lights' share.
    SharedLi,
    /// One LI buffer per light, each clamped to [0, 255], visibilities averaged
    /// ([`super::light_average`]): n times the LI memory and passes, no cross-light error.
    PerLight,
}

/// Settings shared by both penumbra-wedge methods.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct WedgeSettings {
    /// LI buffer format.
    pub li: LiFormat,
    /// LI overflow behaviour.
    pub overflow: LiOverflow,
    /// Smoothstep falloff s' = 3s² − 2s³.
    pub smooth: bool,
    /// Values at entry and exit points (pw2002 only; Paper I §4 vs §5).
    pub side_planes: SidePlanes,
    /// Whether the hierarchical-Z unit rejects wedge faces behind every receiver of a tile
    /// (pw2002 only: `[options.pw2002] hiz`, with `[options.gpu] hiz` on; Paper I ran
    /// without it).
    pub hiz_culling: bool,
    /// Number of lights n (LI amounts scaled by 255/n, Paper I §7).
    pub lights: u32,
    /// Several lights in one LI buffer or one per light.
    pub multi_light: MultiLight,
    /// Wedge construction options of the first light; [`frame_wedges`] builds every light's
    /// wedges with these flags and that light's center, radius and far distance.
    pub wedge: WedgeOptions,
    /// The receiver's own horizon (`horizon`, [`super::horizon_clip`]), applied after the
    /// resolve; shown in `stats.json` under its own `"horizon"`, not here.
    #[serde(skip)]
    pub horizon: Horizon,
}

option_names!(LiFormat {
    Li16 = "16",
    Li12 = "12",
    Li8 = "8",
});

option_names!(LiOverflow {
    Wrap = "wrap",
    Saturate = "saturate",
});

option_names!(SidePlanes {
    Compute = "compute",
    Cancel = "cancel",
});

option_names!(MultiLight {
    SharedLi = "shared",
    PerLight = "separate",
});

option_table! {
    /// The keys both penumbra-wedge methods read (module doc).
    pub struct WedgeKeys {
        /// LI buffer: signed 16 or 12 bits, or an unsigned 8-bit stencil buffer
        li: LiFormat = LiFormat::Li16;
        /// LI values past the format's range: wrap around or saturate
        overflow: LiOverflow = LiOverflow::Wrap;
        /// light intensity across a wedge: s, or s' = 3s² − 2s³ (Paper I §4.2)
        falloff: Falloff [&[Falloff::Linear, Falloff::Smoothstep]] = Falloff::Linear;
        /// the extra wedges at silhouette corners (Paper I Fig. 7)
        corner_wedges: Switch = Switch::On;
        /// the rule for silhouette edges parallel to the light direction (Paper I §8)
        parallel_rule: Switch = Switch::On;
        /// several lights: one LI buffer with amounts scaled by 255/n (Paper I §7), or one per light, averaged
        lights: MultiLight = MultiLight::SharedLi;
    }
}

impl WedgeKeys {
    /// The wedge settings these keys and the method's `horizon` keys ask for on `frame` (every
    /// light must be a sphere).
    pub fn settings(
        &self,
        frame: &Frame,
        horizon: HorizonKeys,
    ) -> Result<WedgeSettings, InputError> {
        let lights = sphere_lights(frame.scene)?;
        Ok(WedgeSettings {
            li: self.li,
            overflow: self.overflow,
            smooth: self.falloff == Falloff::Smoothstep,
            side_planes: SidePlanes::Compute,
            hiz_culling: false,
            lights: lights.len() as u32,
            multi_light: self.lights,
            wedge: WedgeOptions {
                extra_corner_wedges: self.corner_wedges.is_on(),
                parallel_rule: self.parallel_rule.is_on(),
                ..lights[0]
            },
            horizon: horizon.into(),
        })
    }
}

option_table! {
    /// `[options.pw2002]` (module doc).
    pub struct Pw2002Options["pw2002"] {
        ..wedges: WedgeKeys,
        ..horizon: HorizonKeys,
        /// values at a wedge's entry and exit points: computed (Paper I §4) or 255/0 with side planes cancelling (§5)
        side_planes: SidePlanes = SidePlanes::Compute;
        /// the hierarchical-Z unit's zmax rejection of wedge faces behind every receiver of a tile (needs [options.gpu] hiz = on; Paper I ran without it; the same image either way)
        hiz: Switch = Switch::Off;
    }
}

/// Center, radius and far distance of every light of `scene` (all must be spheres), as wedge
/// options with the default construction flags.
fn sphere_lights(scene: &Scene) -> Result<Vec<WedgeOptions>, InputError> {
    scene
        .lights
        .iter()
        .enumerate()
        .map(|(k, l)| match l.shape {
            LightShape::Sphere { radius } => Ok(WedgeOptions {
                center: l.center.as_dvec3(),
                radius: wedge_radius(radius as f64, far_distance(scene, l.center.as_dvec3())),
                far: far_distance(scene, l.center.as_dvec3()),
                extra_corner_wedges: true,
                parallel_rule: true,
            }),
            _ => Err(InputError::at(
                &scene.source,
                scene.light_object(k, "light"),
                "penumbra wedges need a sphere light",
            )),
        })
        .collect()
}

/// The wedges of every mesh of the frame's scene, light by light (Paper I §7: all lights'
/// wedges go into one LI buffer, in light order, each with amounts scaled by 255/n).
pub fn frame_wedges(frame: &Frame, s: &WedgeSettings) -> Result<WedgeSet, InputError> {
    let scene = frame.scene;
    let meshes = frame.caster_meshes();
    let mut all = WedgeSet::default();
    for light in sphere_lights(scene)? {
        let opts = WedgeOptions {
            extra_corner_wedges: s.wedge.extra_corner_wedges,
            parallel_rule: s.wedge.parallel_rule,
            ..light
        };
        let set =
            build_wedges(&meshes, &opts).map_err(|e| InputError::at(&scene.source, "meshes", e))?;
        all.append(set);
    }
    Ok(all)
}

/// Row-major LI values of a tiled LI buffer.
pub fn li_row_major(frame: &Frame, tiles: &[LiTile]) -> Vec<i32> {
    row_major(&frame.tiling, tiles, |t| &t.values)
}

/// Resolve LI values to visibility (background pixels are lit), and mark the receiver pixels
/// whose LI value the resolve clamps (outside [0, 255]: overlapping shadows of Paper I §7's
/// approximation, or an LI format's wrap).
pub fn resolve(frame: &Frame, li: &[i32]) -> (Visibility, Vec<bool>) {
    let prims = frame.prim_ids();
    let mut clamped = vec![false; li.len()];
    let v: Vec<f32> = li
        .iter()
        .zip(prims)
        .zip(&mut clamped)
        .map(|((v, p), c)| {
            if *p == BACKGROUND {
                return 1.0;
            }
            *c = li_clamped(*v);
            li_visibility(*v)
        })
        .collect();
    frame.probe_record("resolve", |tap, i| {
        let background = prims[i] == BACKGROUND;
        tap.event()
            .read("li", Raw::Int(li[i]))
            .resolve(&[v[i]], !background && li_clamped(li[i]))
            .note(if background {
                "background: lit"
            } else {
                "clamp(LI, 0, 255) / 255"
            })
    });
    (Visibility::Gray(v), clamped)
}

/// The dump of the LI buffer `li` (row-major, from `tiles`) in the format of `s`, with its
/// overflow events per pixel and the pixels the resolve `clamped` (`paper` cites the sections).
pub fn li_dump(
    frame: &Frame,
    s: &WedgeSettings,
    tiles: &[LiTile],
    li: &[i32],
    clamped: Vec<bool>,
    paper: &str,
) -> BufferDump {
    let kind = match s.overflow {
        LiOverflow::Wrap => EventKind::Wrap,
        LiOverflow::Saturate => EventKind::Saturate,
    };
    BufferDump::new(
        "li",
        &format!(
            "the light-intensity (LI) buffer before the resolve ({paper}): cleared to 255, \
             signed amounts added per wedge and umbra; visibility = clamp(LI, 0, 255)/255"
        ),
        (frame.scene.width, frame.scene.height),
        ElementFormat::Li(s.li),
        li_values(s.li, li),
    )
    .with_events(EventMap::new(
        kind,
        row_major(&frame.tiling, tiles, |t| &t.overflows),
        clamped,
    ))
}

/// The LI buffer of `pw2002` (tile-major) and its counters, the fragment program in the
/// frame's shader precision.
pub fn render_li(
    frame: &Frame,
    set: &WedgeSet,
    s: &WedgeSettings,
) -> (Vec<LiTile>, crate::gpu::counters::Counters) {
    crate::with_shader_float!(frame.gpu.shader, T => render_li_with::<T>(frame, set, s))
}

/// [`render_li`] with the fragment program in the precision `T` (module doc, "Shader
/// precision").
fn render_li_with<T: ShaderFloat>(
    frame: &Frame,
    set: &WedgeSet,
    s: &WedgeSettings,
) -> (Vec<LiTile>, crate::gpu::counters::Counters) {
    let tris = wedge_triangles(set, &frame.proj);
    let prims: Vec<_> = tris.iter().map(|t| t.clip).collect();
    let tiling = &frame.tiling;
    let (rt, mut counters) = setup_all(&prims, CullMode::Back, tiling);
    let bins = bin(tiling, &rt);
    let mut li = alloc_tiles(tiling, |_, len| {
        LiTile::cleared(s.li, s.overflow, len).recording(frame.dump_buffers)
    });
    frame.probe_record("wedges", |tap, _| {
        tap.event().clear("li", Raw::Int(LI_CLEAR))
    });
    let probe = frame.probe_pass("wedges");
    let depth_state = DepthState {
        func: DepthFunc::Less,
        write: false,
    };
    let eye = frame.scene.camera.eye;
    let eye_uniform = SVec3::<T>::from_f64(eye);
    let full = li_amount(1.0, s.lights);
    let far = frame.gpu.depth.far();
    counters += draw(
        tiling,
        &mut li,
        &rt,
        &bins,
        probe.as_ref(),
        |t, _, tri, c| {
            // A fragment failing the depth test does nothing (below).
            if !s.hiz_culling {
                return TileDraw::Whole;
            }
            let idle = (depth_state.func, false);
            frame.hiz_depth_draw(t, tri, idle, c, probe.as_ref(), |tap| {
                let wt = &tris[tri.prim as usize];
                match (wt.wedge, wt.kind) {
                    (Some(wi), Some(kind)) => wedge_primitive(tap.event(), set, wi, kind, tri),
                    _ => tap.event(),
                }
            })
        },
        |t, tile, tri, f, c, tap| {
            let depth = &frame.tiles[t].depth;
            let (pass, z) = depth.test(&depth_state, &f, c);
            // The watched fragment's event, built only there.
            let event = |tap: Tap| {
                let wt = &tris[tri.prim as usize];
                let e = tap.event();
                let e = match (wt.wedge, wt.kind) {
                    (Some(wi), Some(kind)) => wedge_primitive(e, set, wi, kind, tri),
                    _ => e,
                };
                depth.record_test(e, depth_state.func, f.local, z, pass)
            };
            if !pass {
                if let Some(tap) = tap {
                    tap.push(event(tap).note("depth test failed: not a visible fragment"));
                }
                return;
            }
            count!(c.depth_passed += 1);
            count!(c.fragments_shaded += 1);
            let wt = &tris[tri.prim as usize];
            let (Some(wi), Some(kind)) = (wt.wedge, wt.kind) else {
                return;
            };
            let w = &set.wedges[wi as usize];
            // The eye ray: the eye a uniform, its direction an interpolated input.
            let dir = SVec3::<T>::from_f64(frame.proj.unproject(f.x, f.y, 0.5) - eye);
            let eye = eye_uniform;
            // The value at a wedge boundary point: 255 on the front plane and 0 on the back plane
            // (equation 1 with t_f = 0 or t_b = 0, the identity §5 uses); on a side plane §5
            // (`cancel`) uses 0, the §4 pseudocode (`compute`) evaluates s at the point itself.
            // Evaluating the front and back planes numerically instead fails for wedges
            // thinner than the arithmetic (a light of radius 1e-6 or less): t_f + t_b vanishes
            // and s is noise or the 0/0 fallback, so the umbra step is lost or doubled.
            let boundary = |k: FaceKind, t: T| match (k, s.side_planes) {
                (FaceKind::Front, _) => full,
                (FaceKind::Back, _) | (_, SidePlanes::Cancel) => 0,
                (_, SidePlanes::Compute) => {
                    shader_li_amount(shader_light_intensity(w, eye + dir * t, s.smooth), s.lights)
                }
            };
            let entry = w.plane(kind);
            let v_f = boundary(
                kind,
                -entry.shader_eval(eye) / SVec3::from_f64(entry.n).dot(dir),
            );
            let stored = depth.values[f.local];
            let p = SVec3::<T>::from_f64(frame.proj.unproject(
                f.x,
                f.y,
                frame.gpu.depth.to_window(stored),
            ));
            let inside = stored != far && w.shader_contains(p);
            let v_i = if inside {
                shader_li_amount(shader_light_intensity(w, p, s.smooth), s.lights)
            } else {
                w.shader_exit(eye, dir).map_or(0, |(k, t)| boundary(k, t))
            };
            let delta = v_i - v_f;
            let added = (delta != 0).then(|| tile.add(f.local, delta, c));
            if let Some(tap) = tap {
                let e = event(tap)
                    .value("v_f", v_f as f64)
                    .value("v_i", v_i as f64)
                    .value("delta", delta as f64)
                    .note(if inside {
                        "p inside the wedge: v_i at p"
                    } else {
                        "p outside the wedge: v_i at the exit point"
                    });
                tap.push(match added {
                    Some(a) => tile.record_add(e, a),
                    None => e.read("li", Raw::Int(tile.values[f.local])),
                });
            }
        },
    );
    (li, counters)
}

/// A probe's record of the primitive of fragment `tri`, a triangle of wedge `wi`'s `kind` face
/// (with its light when the scene has several).
pub fn wedge_primitive(
    e: ProbeEvent,
    set: &WedgeSet,
    wi: u32,
    kind: FaceKind,
    tri: &RasterTriangle,
) -> ProbeEvent {
    let e = e.primitive(
        PrimitiveKind::Wedge,
        wi,
        format!("{kind:?} face, triangle {}", tri.prim),
        Some(tri.front_facing),
    );
    match set.light_of_wedge(wi as usize) {
        Some(l) if set.appended_at.len() > 1 => e.light(l),
        _ => e,
    }
}

/// Read and check `[options.pw2002]`.
pub fn options(frame: &Frame) -> Result<WedgeSettings, InputError> {
    let o = Pw2002Options::read(frame.scene)?;
    Ok(WedgeSettings {
        side_planes: o.side_planes,
        hiz_culling: o.hiz.is_on() && frame.gpu.hiz,
        ..o.wedges.settings(frame, o.horizon)?
    })
}

/// `pw2002`'s pinned golden renders ([`crate::methods::Method::goldens`]).
const GOLDENS: &[crate::methods::Golden] = &[
    crate::methods::Golden::new("cylinder"),
    crate::methods::Golden::new("two-lights"),
    crate::methods::Golden::new("cube-of-spheres-sphere"),
    crate::methods::Golden::new("pw-columns"),
    crate::methods::Golden::new("pw-fractal"),
    crate::methods::Golden::new("pw-2002"),
    crate::methods::Golden::new("scenes/real/scorpion.toml"),
    // pw2002 / pw-restructured: LI formats and overflow, falloff, corner wedges, the parallel
    // rule, side planes, several lights, three passes, culling, z-fail with the eye in shadow.
    crate::methods::Golden::variant("pw-2002", "li12", &[("li", "12")]),
    crate::methods::Golden::variant("pw-2002", "li8", &[("li", "8")]),
    crate::methods::Golden::variant("pw-2002", "saturate", &[("overflow", "saturate")]),
    crate::methods::Golden::variant("pw-2002", "smoothstep", &[("falloff", "smoothstep")]),
    crate::methods::Golden::variant("pw-columns", "no-corners", &[("corner-wedges", "off")]),
    crate::methods::Golden::variant("cylinder", "no-parallel-rule", &[("parallel-rule", "off")]),
    crate::methods::Golden::variant("pw-columns", "cancel", &[("side-planes", "cancel")]),
    crate::methods::Golden::variant("two-lights", "separate", &[("lights", "separate")]),
    crate::methods::Golden::new("scenes/hard/eye-in-shadow-sphere.toml"),
    // pw2002's (Paper I, a sphere light) and ssv-optimized's (Paper IV) fragment programs in
    // fp24 and fp16, and ssv-optimized's 16-bit float position buffer (Paper IV §4.2).
    crate::methods::Golden::variant("cube-of-spheres-sphere", "shader-fp24", &[])
        .gpu(&[("shader", "fp24")]),
    crate::methods::Golden::variant("cube-of-spheres-sphere", "shader-fp16", &[])
        .gpu(&[("shader", "fp16")]),
];

/// `pw2002`'s configurations in the accuracy–time sweep ([`crate::methods::Method::sweep`]).
const SWEEP: &[crate::methods::OptionPairs] = &[
    &[("li", "16")],
    &[("li", "12")],
    &[("li", "8")],
    &[("li", "16"), ("horizon", "clip")],
];

/// What the precision experiment measures of it ([`crate::experiment::precision`]): Paper I's LI buffers.
const PRECISION: PrecisionSpec = PrecisionSpec {
    shader_arithmetic: true,
    storage: &[
        NarrowFormat::of("li", "12", "16"),
        NarrowFormat::of("li", "8", "16"),
    ],
    overflow: &[
        OverflowKnobs::of(StackLight::Sphere, &[("li", "16"), ("overflow", "wrap")]),
        OverflowKnobs::of(
            StackLight::Sphere,
            &[("li", "16"), ("overflow", "saturate")],
        ),
        OverflowKnobs::of(StackLight::Sphere, &[("li", "12"), ("overflow", "wrap")]),
        OverflowKnobs::of(
            StackLight::Sphere,
            &[("li", "12"), ("overflow", "saturate")],
        ),
        OverflowKnobs::of(StackLight::Sphere, &[("li", "8"), ("overflow", "wrap")]),
        OverflowKnobs::of(StackLight::Sphere, &[("li", "8"), ("overflow", "saturate")]),
    ],
};

/// `pw2002` in the registry ([`crate::methods::ALL`]).
pub const METHOD: crate::methods::Method = crate::methods::Method {
    name: "pw2002",
    paper: "Paper I: penumbra wedges, EGWR 2002",
    // Penumbra wedges are built for spherical lights only (Paper I §4).
    supports: |s| matches!(s, LightShape::Sphere { .. }),
    lights: crate::methods::SeveralLights::OnePass,
    options: crate::methods::OptionTableSpec::of::<Pw2002Options>(),
    bytes_per_pixel: 88,
    bytes_per_triangle: 656,
    default_run: crate::methods::DefaultRun::EveryScene,
    sums_per_silhouette_edge: true,
    table_note: |_| None,
    check: |frame| options(frame).map(drop),
    run,
    goldens: GOLDENS,
    sweep: SWEEP,
    precision: PRECISION,
};

/// Run `pw2002` on a rendered frame.
pub fn run(frame: &Frame) -> Result<MethodOutput, InputError> {
    let s = options(frame)?;
    if s.multi_light == MultiLight::PerLight && frame.scene.is_multi_light() {
        return super::light_average::run("pw2002", frame, |_, f| run(f));
    }
    let mut rec = PassRecorder::new(frame, "pw2002");
    rec.uses(li_buffer_plan(s.li));
    if s.hiz_culling {
        rec.uses_hiz_depth();
    }
    let (set, tiles) = rec.pass("wedges", |pass| {
        let set = frame_wedges(frame, &s)?;
        let (tiles, counters) = render_li(frame, &set, &s);
        pass.count(counters);
        Ok::<_, InputError>((set, tiles))
    })?;
    let li = li_row_major(frame, &tiles);
    let (visibility, clamped) = resolve(frame, &li);
    rec.clamped(clamped.iter().filter(|&&c| c).count() as u64);
    let lights = representative_light_points(frame.scene);
    if eye_in_shadow(frame.scene, frame.proj.near, &lights) {
        rec.warn(
            "the eye is in shadow: Paper I counts wedges z-pass only, so this result is wrong \
             where the eye's shadow volumes are (pw-restructured has Paper II's z-fail)"
                .into(),
        );
    }
    for w in fold_warnings(&set) {
        rec.warn(w);
    }
    rec.dump(|| li_dump(frame, &s, &tiles, &li, clamped, "Paper I §4"));
    let (visibility, horizon) = clip_to_horizon(&mut rec, s.horizon, visibility);
    Ok(rec.finish(
        visibility,
        serde_json::json!({
            "horizon": horizon,
            "settings": s,
            "wedges": set.wedges.len(),
            "extra_corner_wedges": set.extra_wedges,
            "removed_parallel_edges": set.removed_parallel,
            "open_wedges": set.open_wedges,
            "silhouette_folds": set.fold_count(),
            "gpu": frame.gpu,
        }),
    ))
}

/// One warning per mesh whose silhouette seen from the light center folds back on itself
/// ([`crate::geometry::penumbra_wedge::silhouette_folds`]): the zigzag that Papers I and II
/// cannot build wedges for (the thesis's introduction, Fig. 5b: "zigzag patterns along the
/// direction to the light source cannot be handled with the wedge generation method in I and
/// II"). Their wedges overlap instead of partitioning the penumbra, so an eye ray adds a
/// wedge's light without the umbra step that should cancel it — light streaks and specks
/// inside the umbra (measured in `docs/methods.md`, "pw2002"). Shared by `pw-restructured`.
pub fn fold_warnings(set: &WedgeSet) -> Vec<String> {
    set.folds
        .iter()
        .map(|(mesh, n)| {
            format!(
                "mesh `{mesh}`: its silhouette seen from the light center folds back on itself \
                 at {n} corners (a zigzag along the light direction, which Paper I's and \
                 Paper II's wedges cannot represent); the wedges there overlap and add light \
                 inside the umbra, so this result can be worse than hard-sv — ssv or \
                 ssv-optimized (Paper III's wedges with per-wedge coverage) handle such \
                 silhouettes"
            )
        })
        .collect()
}

/// The plan entry of the LI buffer in format `li`.
pub fn li_buffer_plan(li: LiFormat) -> BufferPlan {
    BufferPlan {
        name: "li".into(),
        format: format!("{li:?}"),
        bytes_per_sample: li.bytes() as u32,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The warnings of `method` on `scene` at 48², and its wedges' fold count.
    fn warnings_at_48(mut scene: Scene, method: &str) -> (Vec<String>, usize) {
        scene.resize(Some(48), Some(48));
        let frame = Frame::render(&scene, crate::frame::GpuSettings::default()).unwrap();
        let folds = frame_wedges(&frame, &options(&frame).unwrap())
            .unwrap()
            .fold_count();
        let out = crate::methods::run(method, &frame).unwrap();
        (out.stats.warnings, folds)
    }

    /// Spot the cow under a sphere light (`scenes/real/spot-sphere.toml`) has a zigzag
    /// silhouette and both penumbra-wedge methods say so, naming the mesh and the count; the
    /// tessellated spheres of `cube-of-spheres-sphere` (convex loops) do not fold.
    #[test]
    fn folds_are_warned_on_a_real_model_and_not_on_spheres() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/real/spot-sphere.toml");
        for method in ["pw2002", "pw-restructured"] {
            let scene = crate::scene::file::load_scene_file(&path).unwrap();
            let (warnings, folds) = warnings_at_48(scene, method);
            assert_eq!(folds, 116, "module doc of penumbra_wedge, \"Folds\"");
            assert_eq!(warnings.len(), 1, "{warnings:?}");
            assert!(warnings[0].contains("spot.obj"), "{}", warnings[0]);
            assert!(warnings[0].contains("at 116 corners"), "{}", warnings[0]);
            assert!(warnings[0].contains("ssv"), "{}", warnings[0]);
            let spheres = crate::scene::builtin::load("cube-of-spheres-sphere").unwrap();
            assert_eq!(warnings_at_48(spheres, method), (Vec::new(), 0));
        }
    }
}
