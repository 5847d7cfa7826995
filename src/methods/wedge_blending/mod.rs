//! `wedge-blending`: realistic soft shadows by penumbra-wedges blending (Forest, Barthe &
//! Paulin, Graphics Hardware 2006) for rectangular lights, in light space where the light is
//! `[−1, 1]²` (§4.2).
//!
//! The penumbra-wedge methods add every silhouette's occlusion into one buffer, so where two
//! silhouettes occlude the same part of the light it is counted twice (§3, Fig. 5). Forest et
//! al. keep, per fragment and per radial part of the light, a bounding rectangle of the
//! occluded region, and subtract an estimate of the overlap when a silhouette is blended into
//! the result. Per silhouette, three passes (§4):
//!
//! 1. **Shadow volume** (§4.1): the silhouette's hard shadow quads from the light center into
//!    an 8-bit stencil (two-sided, wrap; z-pass, or z-fail with caps when the eye is in shadow,
//!    decided like `ssv`); then every shaded pixel's silhouette vBuffer is initialized to the
//!    count in all four radial parts with the whole part as rectangle ([`PartState::hard`]).
//! 2. **Penumbra wedges** (§4.2, §4.3): every edge's wedge (the tight wedge of a rectangular
//!    light, [`crate::geometry::tight_wedge`]) split by the hard shadow quad's plane into an
//!    inner and an outer half; the outer halves of all edges are drawn first, then the inner
//!    halves ("First, we compute a rectangle that bounds the occluded light region defined by
//!    the outer-half-wedges. Then we rasterize the inner-half-wedges"), each in edge order.
//!    A half-wedge's front faces are rasterized; per fragment, in this order, each counted
//!    when it rejects: the **depth test** of the face against the scene depth (a receiver in
//!    front of the half-wedge is outside it); the **outside bounding planes** of the half
//!    (its wedge planes other than the quad's, [`bounding_planes`]) tested in viewport space
//!    against the pixel's footprint (Fig. 7, [`WindowPlane::footprint_outside`]); and the
//!    **side of the hard quad** the receiver is on — "the wrong side of the shadow-volume
//!    quadrilateral" of Fig. 8 — one test for both halves (`HardQuad::side`): where the quad
//!    covers the pixel it is the shadow-volume pass's own depth test of the quad against the
//!    receiver (the quad in front of the receiver puts it on the other side of the plane from
//!    the eye), so the half a receiver falls in agrees with its stencil count bit for bit;
//!    elsewhere the exact sign `ssv` uses ([`quad_side`]) — the coverage is continuous across
//!    the plane outside the quad. Where the two disagree, the shader evaluates the edge at the
//!    receiver mirrored across the plane, onto the side the stencil counted. (With the plane's
//!    sign everywhere, as `ssv` does, a receiver within one depth step of a quad is counted in
//!    the hard shadow by the stencil and on the lit side by the half-wedges, or the reverse,
//!    and half the light is added or lost: single pixels off by 0.2–0.5 along hard-shadow
//!    boundaries on `forest-spheres`.) The face of a
//!    half that lies in the quad's plane is drawn without the depth test, which would decide
//!    the same question a second time with the face's own depths. A receiver on the quad's
//!    plane belongs to neither half (its coverage is 0).
//!    The shader then projects the edge with the local near
//!    plane, clips it to the light and to each radial part
//!    ([`edge_in_parts`]) and, per part the edge reaches, adds (outer) or subtracts (inner)
//!    the occluded area and updates the rectangle or the maximum X and Y
//!    ([`PartState::add_outer`], [`PartState::add_inner`]).
//! 3. **Blend** (§3.2, §4.3): where the silhouette vBuffer holds anything, each part is
//!    blended into the final vBuffer ([`blend::blend_part`]: ε = (A_f/B_f)(A_s/B_s)β only
//!    where both occlusions are positive, the paper's dynamic branch). Then the silhouette
//!    vBuffer and the stencil are cleared.
//!
//! Finally the visibility is `1 − (Σ parts' occlusion)/4` (the parts are the four equal
//! quarters of the light), clamped to [0, 1]; the unclamped value is kept and the pixels the
//! clamp changed are counted (`clamped_pixels`).
//!
//! Storage (`packing`, [`vbuffer`]): `8bit` — the paper's two 32-bit scalars per part packed
//! with PK4UB into two RGBA32F targets per vBuffer, quantized and clamped at every write,
//! through a `target` that keeps every bit (`raw`), flushes denormals
//! (`flush-denormals`) or canonicalizes NaNs (`canonical-nans`); `f32` — the same algorithm
//! unpacked. `centroid = on` adds the center of gravity of §6. `adjust` says how the inner
//! rectangle adjustment of Fig. 10 applies (default `checked`; [`blend`] module doc). `order = reverse` blends the
//! silhouettes in the opposite order (the result depends on it). `silhouettes = loops`
//! (default; the and the paper's "silhouette": one connected silhouette loop from the
//! light center, [`silhouette_loops`]) or `meshes` (all loops of one mesh in one silhouette
//! vBuffer).
//!
//! **Shader precision** (`[options.gpu] shader`, [`crate::gpu::shader_float`]). Forest et al.
//! ran ARB/NV fragment programs on a GeForce 7800 GTX (§5.1, §5.2), whose `float` is fp32.
//! * The half-wedge program's region of each radial part — the polygon beyond the clipped
//!   chord, its area, first moment and bounding box ([`RegionBeyondEdge::in_shader`](crate::light::radial_parts::RegionBeyondEdge::in_shader))
//!   — runs in the chosen precision `T`.
//! * The vBuffer arithmetic — the half-wedge updates ([`PartState::add_outer`],
//!   [`PartState::add_inner`]: occlusion, centroid, maximum X and Y), the rectangles' areas
//!   and the inner adjustment's check, ε and the blend ([`blend::blend_part`]) and the
//!   resolve `1 − Σ/4` — runs in `T` capped at fp32
//!   ([`ShaderFloat::AtMostFp32`]): it was
//!   f32 arithmetic before shader precision existed (the vBuffers' values are f32), so the
//!   default f64 keeps its bits and equals `fp32` there, while `fp24` and `fp16` round every
//!   operation as everywhere else. Its operands are the stored values (f32 unpacked; the 8-bit
//!   values PK4UB unpacks, exact) and its results are stored as f32 (exact: the scalar is at
//!   most fp32), then packed; PK4UB's quantization is the instruction's and is exact.
//! * Still f64: the shadow-volume pass and the wedges (CPU geometry, §4.1–§4.2); the
//!   per-fragment tests before the program's arithmetic — the outside bounding planes in
//!   viewport space (Fig. 7) and the side of the hard quad (its depth test is the
//!   rasterizer's, its plane sign `ssv`'s [`quad_side`]) — and the edge's projection with the
//!   local near plane and its clipping by saturation ([`edge_in_parts`]): the projection is
//!   [`crate::light::coverage`]'s and is converted with the rest of that module; the clip's
//!   validity test has an absolute tolerance (10⁻¹² of the coordinates) that needs a bound per
//!   format before it can run narrower.
//!
//! Choices where the paper is silent:
//! * **Order.** Meshes in scene order, within a mesh its loops in the order
//!   [`silhouette_loops`] finds them (by their first edge in adjacency order); within a
//!   silhouette, edges in loop order.
//! * **Shadow volume of a loop.** The volume of a mesh with one loop is the mesh's own (its
//!   silhouette quads, and for z-fail its light-facing triangles as front cap and its other
//!   triangles at infinity as back cap, exactly as `hard-sv` and `ssv` draw them). A loop of a
//!   mesh with several loops has its quads (z-pass) but no caps of its own: closing it with a
//!   fan over the loop was tried and misclassifies receivers wherever the fan leaves the mesh
//!   (on `scenes/hard/torus-hole-rect.toml`, RMSE 0.056 against 0.0074 z-pass), so **with
//!   z-fail a mesh with several loops is one silhouette** (its own closed volume), as with
//!   `silhouettes = meshes`.
//! * **Holes.** A loop around a hole of its mesh (a torus seen from above) has the hard count
//!   −1 from the center where it is alone. Unpacked, it is added without ε ([`blend`]) and the
//!   Green sum over the loops is exact; packed, PK4UB clamps it to 0 and the hole stays as
//!   dark as the rest of the mesh's shadow (`torus-hole-rect`: RMSE 0.237 packed, 0.0073
//!   unpacked, 0.0075 with `silhouettes = meshes`, `ssv` 0.0074) — the per-loop silhouettes
//!   of the paper cannot represent a hole in 8 bits. This is detected at run time: the
//!   initialization counts the negative hard counts it reads (`negative_counts`), per mesh
//!   the loops that had some ([`BlendingRender::hole_loops`]), and with `packing = 8bit` the
//!   method warns (`stats.json` and the terminal) naming the mesh and the remedies
//!   (`packing = f32`, `silhouettes = meshes`).
//! * **Only where the silhouette was drawn.** Per tile, a flag records whether any fragment of
//!   the silhouette reached it; the initialization, blend and clear passes visit only those
//!   tiles (a tile-level fast clear: the GPU of the paper would clear and blend the whole
//!   screen, which changes only the traffic counts, not the result).
//! * **Penumbra overlap map.** The raw image `penumbrae` counts, per pixel, the silhouettes
//!   whose occlusion (mean over the parts) lies strictly between 0.5/255 and 1 − 0.5/255
//!   there: where two or more overlap is where the blending matters.
//! * Receiver points are the depth-buffer points (f32), as `ssv`'s, so that one silhouette
//!   gives `ssv`'s result and the error against `raycast` is the method's own.
//!
//! Buffer dumps ([`super::dump`]): `penumbrae` (always, `penumbrae.png`); with
//! `--dump-buffers` the final vBuffer before the resolve — packed: `final-rects` and
//! `final-occlusion`, the raw `PK4UB` words of its two RGBA32F targets; unpacked:
//! `final-parts` ([`VBufferStorage::final_dumps`]) — whose last dump carries the event map of
//! the blend pass's writes (per pixel: `PK4UB` clamps, special float patterns among the
//! pixel's words) and the pixels the final clamp changed; and `stencil-sum`, per pixel the sum
//! over the silhouettes of the signed stencil count the initialization read (the stencil is
//! cleared after each silhouette, so no single state of it is left), with the stencil's wraps
//! over all silhouettes. The silhouette vBuffer is cleared after each silhouette and is not
//! dumped.

pub mod blend;
pub mod vbuffer;

use super::dump::{row_major, BufferDump, DumpValues, ElementFormat, EventKind, EventMap};
use super::hard_sv::{shadow_test, volume_stencil_state, ShadowTest, StencilOverflow};
use super::horizon_clip::{clip_to_horizon, Horizon, HorizonKeys};
use super::output::MethodOutput;
use crate::error::InputError;
use crate::frame::{setup_all, Frame, FULL_SCREEN};
use crate::geometry::loops::silhouette_loops;
use crate::geometry::shadow_volume::{shadow_volume_triangles, silhouette_quad, Capping};
use crate::geometry::silhouette::{light_facing, possible_silhouettes};
use crate::geometry::tight_wedge::{
    bounding_planes, quad_inner_halfspace, wedge_clip_box, wedge_halves_and_planes,
};
use crate::gpu::buffers::{alloc_tiles, overflow_record, record_overflow, StencilTile};
use crate::gpu::counters::{count, Counters};
use crate::gpu::depth::{DepthFunc, DepthState};
use crate::gpu::pack4ub::{FloatTarget, StoreEvents};
use crate::gpu::probe::{Overflow, PrimitiveKind, ProbeEvent, Raw, Tap};
use crate::gpu::raster::{bin, draw, TileDraw};
use crate::gpu::setup::{setup_triangle, CullMode, RasterTriangle};
use crate::gpu::shader_float::ShaderFloat;
use crate::gpu::tiling::Tiling;
use crate::gpu::transform::{ClipVertex, WindowPlane};
use crate::light::coverage::{quad_side, RectLight};
use crate::light::radial_parts::{edge_in_parts, read, stored, PART_COUNT};
use crate::methods::hard_sv::CountMode;
use crate::methods::output::BufferPlan;
use crate::methods::precision_spec::{NarrowFormat, OverflowKnobs, PrecisionSpec, StackLight};
use crate::methods::recorder::PassRecorder;
use crate::options::{option_names, option_table, OptionTable, OptionType, Switch};

use crate::scene::LightShape;
use crate::visibility::Visibility;
use blend::{blend_part, BlendCase, InnerAdjust, PartState, Rules};
use glam::DVec3;
use rayon::prelude::*;

use vbuffer::{Packed8, PixelParts, UnpackedF32, VBufferStorage};

/// How the vBuffers store a pixel (module doc, [`vbuffer`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Packing {
    /// PK4UB-packed 8-bit values in two RGBA32F targets (§4.3).
    Bit8,
    /// Unpacked f32 values.
    F32,
}

/// What one silhouette vBuffer holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Grouping {
    /// One connected silhouette loop.
    Loops,
    /// All loops of one mesh.
    Meshes,
}

/// All settings of one `wedge-blending` render.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Settings {
    /// vBuffer storage.
    pub packing: Packing,
    /// How the RGBA32F targets store packed patterns (8-bit packing only).
    pub target: FloatTarget,
    /// Center of gravity per part (§6).
    pub centroid: bool,
    /// How the inner adjustment of Fig. 10 applies ([`blend`] module doc).
    pub adjust: InnerAdjust,
    /// Blend the silhouettes in reverse order.
    pub reverse: bool,
    /// Silhouette grouping.
    pub grouping: Grouping,
    /// z-pass or z-fail for the shadow-volume passes.
    pub test: ShadowTest,
    /// The receiver's own horizon (`horizon`, [`crate::methods::horizon_clip`]), read with the other
    /// options; `stats.json` shows it under its own `"horizon"`.
    #[serde(skip)]
    pub horizon: Horizon,
}

option_names!(Packing {
    Bit8 = "8bit",
    F32 = "f32",
});

option_names!(FloatTarget {
    Raw = "raw",
    FlushDenormals = "flush-denormals",
    CanonicalNans = "canonical-nans",
});

option_names!(InnerAdjust {
    Checked = "checked",
    Always = "always",
    Never = "never",
});

option_names!(Grouping {
    Loops = "loops",
    Meshes = "meshes",
});

option_names! {
    /// The order the silhouettes are blended in (`[options.wedge-blending] order`).
    pub enum Order {
        /// Meshes in scene order, loops in the order they are found (module doc).
        Forward = "forward",
        /// The opposite.
        Reverse = "reverse",
    }
}

option_table! {
    /// `[options.wedge-blending]` (module doc).
    pub struct WedgeBlendingOptions["wedge-blending"] {
        ..horizon: HorizonKeys,
        /// vBuffer storage: PK4UB-packed 8-bit values in two RGBA32F targets (Forest et al. §4.3), or f32
        packing: Packing = Packing::Bit8;
        /// how the RGBA32F targets store packed patterns (packing = 8bit only)
        target: FloatTarget = FloatTarget::Raw;
        /// the center of gravity per radial part (Forest et al. §6)
        centroid: Switch = Switch::Off;
        /// when the inner rectangle adjustment of Forest et al. Fig. 10 applies
        adjust: InnerAdjust = InnerAdjust::Checked;
        /// the order the silhouettes are blended in (the result depends on it)
        order: Order = Order::Forward;
        /// one silhouette vBuffer per silhouette loop, or per mesh
        silhouettes: Grouping = Grouping::Loops;
        /// count the shadow volumes z-pass or z-fail; auto: z-fail when the near plane is in the light center's shadow
        mode: CountMode = CountMode::Auto;
    }
}

/// Read and check `[options.wedge-blending]` ([`WedgeBlendingOptions`]), and the `mode` as
/// written.
pub fn options(frame: &Frame) -> Result<(Settings, CountMode), InputError> {
    let scene = frame.scene;
    let o = WedgeBlendingOptions::read(scene)?;
    if o.packing == Packing::F32 && o.target != FloatTarget::Raw {
        return Err(scene.option_error(
            WedgeBlendingOptions::NAME,
            "target",
            format!(
                "target = \"{}\" describes how RGBA32F targets store packed 8-bit values; it \
                 needs packing = \"8bit\"",
                o.target.written()
            ),
        ));
    }
    if !matches!(scene.light().shape, LightShape::Rect { .. }) {
        return Err(InputError::at(
            &scene.source,
            "light",
            "wedge-blending supports rect lights (Forest et al. 2006 §4.2)",
        ));
    }
    Ok((
        Settings {
            packing: o.packing,
            target: o.target,
            centroid: o.centroid.is_on(),
            adjust: o.adjust,
            reverse: o.order == Order::Reverse,
            grouping: o.silhouettes,
            test: shadow_test(o.mode, frame, &[scene.light().center]),
            horizon: o.horizon.into(),
        },
        o.mode,
    ))
}

/// One silhouette: its edges `a → b` (oriented as in their light-facing triangles) and its
/// hard shadow volume (quads, plus caps for z-fail) in submission order.
#[derive(Debug, Clone)]
pub struct Silhouette {
    /// Index of the mesh it belongs to.
    pub mesh: usize,
    /// Its edges, in loop order.
    pub edges: Vec<[DVec3; 2]>,
    /// Its shadow-volume triangles in clip space.
    pub volume: Vec<[ClipVertex; 3]>,
}

/// The silhouettes of `frame`'s scene from the light center, in blending order (module doc).
pub fn silhouettes(frame: &Frame, s: &Settings) -> Result<Vec<Silhouette>, InputError> {
    let c = frame.scene.light().center;
    let proj = &frame.proj;
    let capping = match s.test {
        ShadowTest::ZPass => Capping::Open,
        ShadowTest::ZFail => Capping::Capped,
    };
    let mut out = Vec::new();
    for (k, (mesh, adj)) in frame.caster_meshes().into_iter().enumerate() {
        let mi = frame.caster_mesh_index(k);
        let facing = light_facing(mesh, c);
        let edges = possible_silhouettes(mesh, adj, &facing);
        let loops = silhouette_loops(&edges)
            .map_err(|e| InputError::at(&frame.scene.source, frame.caster_object(k), e))?;
        let edge_of = |k: usize| [edges[k].a.as_dvec3(), edges[k].b.as_dvec3()];
        // z-fail needs closed volumes: a loop is closed by its mesh's caps only when it is
        // the mesh's only loop (module doc).
        let whole_mesh =
            s.grouping == Grouping::Meshes || (capping == Capping::Capped && loops.len() > 1);
        if whole_mesh && !edges.is_empty() {
            out.push(Silhouette {
                mesh: mi,
                edges: loops.iter().flatten().map(|&k| edge_of(k)).collect(),
                volume: shadow_volume_triangles(&[(mesh, adj)], c, proj, capping),
            });
            continue;
        }
        for l in &loops {
            out.push(Silhouette {
                mesh: mi,
                edges: l.iter().map(|&k| edge_of(k)).collect(),
                volume: if loops.len() == 1 {
                    shadow_volume_triangles(&[(mesh, adj)], c, proj, capping)
                } else {
                    l.iter()
                        .flat_map(|&k| silhouette_quad(proj, c, edges[k].a, edges[k].b))
                        .collect()
                },
            });
        }
    }
    if s.reverse {
        out.reverse();
    }
    Ok(out)
}

/// Work and rejection counts of the method (module doc), next to the traffic [`Counters`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct BlendingCounters {
    /// Silhouettes processed.
    pub silhouettes: u64,
    /// Half-wedges drawn, and how many of them full-screen (eye within reach).
    pub half_wedges: u64,
    /// Half-wedges drawn as a full-screen quad.
    pub half_wedges_full_screen: u64,
    /// Half-wedge fragments rejected by the depth test (Fig. 8). With the hierarchical Z on,
    /// the fragments of faces it skipped in a tile are not rasterized and not counted.
    pub rejected_depth: u64,
    /// Rejected by the outside bounding planes in viewport space (Fig. 7).
    pub rejected_outside_planes: u64,
    /// Rejected for lying on the other side of the hard quad (or on its plane).
    pub rejected_quad_side: u64,
    /// Fragments that passed every test but whose edge reaches no part of the light.
    pub missed_light: u64,
    /// (fragment, part) updates: the dynamic branch of §4.3 taken.
    pub part_updates: u64,
    /// Pixels where the blend pass read the final vBuffer.
    pub blended_pixels: u64,
    /// Parts copied into an empty final part.
    pub parts_copied: u64,
    /// Parts blended with ε (both occlusions positive).
    pub parts_blended: u64,
    /// Of those, parts where ε > 0 (an overlap was corrected).
    pub parts_corrected: u64,
    /// Parts added without ε (a negative occlusion, unpacked only).
    pub parts_accumulated: u64,
    /// Blended parts whose occlusion exceeded 1 and was limited to it ([`blend_part`]).
    pub parts_limited: u64,
    /// Occlusion values PK4UB clamped to [0, 1] at a write.
    pub packing_clamps: u64,
    /// Pixels where the initialization read a negative hard count: inside a silhouette loop
    /// around a hole of its mesh where that loop is alone (module doc, "Holes"). Unpacked
    /// they are kept; the 8-bit packing clamps them to 0 ([`BlendingRender::hole_loops`]).
    pub negative_counts: u64,
    /// Special float patterns written to the RGBA32F targets.
    pub stores: StoreEvents,
    /// Pixels whose resolved visibility was outside [0, 1] before the final clamp.
    pub clamped_pixels: u64,
}

impl std::ops::AddAssign for BlendingCounters {
    fn add_assign(&mut self, o: Self) {
        self.silhouettes += o.silhouettes;
        self.half_wedges += o.half_wedges;
        self.half_wedges_full_screen += o.half_wedges_full_screen;
        self.rejected_depth += o.rejected_depth;
        self.rejected_outside_planes += o.rejected_outside_planes;
        self.rejected_quad_side += o.rejected_quad_side;
        self.missed_light += o.missed_light;
        self.part_updates += o.part_updates;
        self.blended_pixels += o.blended_pixels;
        self.parts_copied += o.parts_copied;
        self.parts_blended += o.parts_blended;
        self.parts_corrected += o.parts_corrected;
        self.parts_accumulated += o.parts_accumulated;
        self.parts_limited += o.parts_limited;
        self.packing_clamps += o.packing_clamps;
        self.negative_counts += o.negative_counts;
        self.stores += o.stores;
        self.clamped_pixels += o.clamped_pixels;
    }
}

/// The passes of the method, in the order they first run and `stats.json` lists them.
pub const PASS_NAMES: [&str; 5] = [
    "wb-shadow-volumes",
    "wb-init",
    "wb-half-wedges",
    "wb-blend",
    "wb-resolve",
];

/// The result of one render.
#[derive(Debug, Clone)]
pub struct BlendingRender {
    /// Visibility per pixel, row-major, clamped to [0, 1]; background 1.
    pub visibility: Vec<f32>,
    /// The visibility before the final clamp (background 1).
    pub unclamped: Vec<f32>,
    /// Per pixel, the number of silhouettes in whose penumbra it lies (module doc).
    pub penumbrae: Vec<u8>,
    /// Method counters.
    pub counters: BlendingCounters,
    /// The buffer dumps of `--dump-buffers` (module doc), empty otherwise.
    pub dumps: Vec<BufferDump>,
    /// Per mesh with any, its silhouette loops around holes (module doc, "Holes"), in mesh
    /// order.
    pub hole_loops: Vec<HoleLoops>,
}

/// The silhouette loops of one mesh that bound a hole: the initialization read a negative
/// hard count from the light center inside them (module doc, "Holes").
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct HoleLoops {
    /// Index of the mesh in the scene.
    pub mesh: usize,
    /// Its silhouettes (loops) with a negative count somewhere.
    pub loops: u64,
    /// The pixels where those counts were read, summed over the loops.
    pub pixels: u64,
}

/// One silhouette blended at a probed pixel, decoded from the probe's trace ([`blend_steps`]):
/// the values the blend pass read and wrote there.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BlendStep {
    /// Index of the silhouette in blending order.
    pub silhouette: usize,
    /// The mesh it belongs to.
    pub mesh: usize,
    /// The silhouette vBuffer's parts after the half-wedges (as unpacked).
    pub silhouette_parts: PixelParts,
    /// The final vBuffer's parts before the blend.
    pub before: PixelParts,
    /// And after.
    pub after: PixelParts,
    /// ε per part (0 where the part was not blended).
    pub eps: [f32; PART_COUNT],
}

/// The blend steps of a probe's `events` of a render with settings `s` (the `wb-blend` pass's
/// read of the silhouette vBuffer and write of the final vBuffer, unpacked by the storage the
/// render used), in blending order.
pub fn blend_steps(events: &[ProbeEvent], s: &Settings) -> Vec<BlendStep> {
    match s.packing {
        Packing::Bit8 => decode_steps(
            events,
            &Packed8 {
                target: s.target,
                centroid: s.centroid,
            },
        ),
        Packing::F32 => decode_steps(
            events,
            &UnpackedF32 {
                centroid: s.centroid,
            },
        ),
    }
}

fn decode_steps<S: VBufferStorage>(events: &[ProbeEvent], storage: &S) -> Vec<BlendStep> {
    let load = |raw: &Raw| storage.decode_raw(raw).map(|px| storage.load(&px));
    let mut silhouette = None;
    let mut steps = Vec::new();
    for e in events.iter().filter(|e| e.pass == PASS_NAMES[3]) {
        let Some(b) = &e.buffer else { continue };
        match (b.buffer.as_str(), &b.before) {
            ("silhouette-vbuffer", Some(_)) => silhouette = load(&b.after),
            ("final-vbuffer", Some(before)) => {
                let (Some(sp), Some(before), Some(after), Some(p)) =
                    (silhouette, load(before), load(&b.after), &e.primitive)
                else {
                    continue;
                };
                let value = |name: &str| e.values.iter().find(|v| v.name == name).map(|v| v.value);
                steps.push(BlendStep {
                    silhouette: p.index as usize,
                    mesh: value("mesh").unwrap_or(0.0) as usize,
                    silhouette_parts: sp,
                    before,
                    after,
                    eps: std::array::from_fn(|k| value(&format!("eps{k}")).unwrap_or(0.0) as f32),
                });
            }
            _ => {}
        }
    }
    steps
}

/// Per-tile storage.
struct BlendTile<P> {
    stencil: StencilTile,
    silhouette: Vec<P>,
    last: Vec<P>,
    penumbrae: Vec<u8>,
    /// Whether the current silhouette reached the tile.
    dirty: bool,
    counters: BlendingCounters,
    /// For a dump: per sample the sum of the stencil counts the initialization read, and the
    /// `PK4UB` clamps and special float patterns of the final vBuffer's writes (empty
    /// otherwise, [`overflow_record`]).
    stencil_sum: Vec<i32>,
    final_events: [Vec<u32>; 2],
}

/// One half-wedge to draw.
struct HalfJob {
    /// Index of the edge in the silhouette.
    edge: usize,
    /// The inner (umbra side) half.
    inner: bool,
    /// Its outside bounding planes in window coordinates.
    planes: Vec<WindowPlane>,
    /// Drawn as a full-screen quad (no depth test of its faces).
    full_screen: bool,
}

/// The hard shadow quad of one silhouette edge as the shadow-volume pass rasterized it, for
/// the "wrong side of the shadow-volume quadrilateral" test of Fig. 8 (module doc).
struct HardQuad {
    /// Its raster triangles (the same vertices, setup and fill rule as the stencil pass).
    tris: Vec<RasterTriangle>,
    /// The side of its plane the eye is on ([`quad_side`]'s sign).
    eye_side: f64,
    /// The light center and the edge `a → b`.
    c: DVec3,
    edge: [DVec3; 2],
}

impl HardQuad {
    fn new(frame: &Frame, a: DVec3, b: DVec3) -> Self {
        let c = frame.scene.light().center;
        let mut tris = Vec::new();
        let mut ignored = Counters::default();
        for (k, t) in silhouette_quad(&frame.proj, c, a.as_vec3(), b.as_vec3())
            .iter()
            .enumerate()
        {
            let (w, h) = (frame.tiling.width, frame.tiling.height);
            setup_triangle(t, k as u32, CullMode::None, w, h, &mut tris, &mut ignored);
        }
        let c = c.as_dvec3();
        HardQuad {
            tris,
            eye_side: quad_side(c, frame.scene.camera.eye, b, a),
            c,
            edge: [a, b],
        }
    }

    /// The side of the quad receiver `p` (seen at pixel (`x`, `y`) with stored depth
    /// `stored`) is on, `ssv`'s sign ([`quad_side`]: positive on the umbra side), and the point
    /// the shader evaluates the edge at. Where the quad covers the pixel the side is decided by
    /// the shadow-volume pass's own depth test — the quad in front of the receiver puts it on
    /// the other side of the plane from the eye — so that the half a receiver falls in always
    /// agrees with its stencil count; elsewhere (and with the eye in the plane) by the sign of
    /// the plane equation in f64. Where the depth test and the plane equation disagree (the
    /// receiver is within a depth step of the plane), the shader evaluates the edge at the
    /// receiver mirrored across the plane (moved off it by 10⁻⁹ of its distance from the
    /// light center if it lies in it), so that the region it adds or subtracts is the one of
    /// the side the stencil counted: otherwise it would take the region beyond the edge of the
    /// other side — its complement within the light — and be off by up to the whole light.
    fn side(&self, x: u32, y: u32, stored: u32, p: DVec3, frame: &Frame) -> (f64, DVec3) {
        let [a, b] = self.edge;
        let exact = quad_side(self.c, p, b, a);
        if self.eye_side == 0.0 {
            return (exact, p);
        }
        let Some(t) = self.tris.iter().find(|t| t.covers(x, y)) else {
            return (exact, p);
        };
        let z = frame.gpu.depth.quantize(t.depth_at(x, y));
        let side = if DepthFunc::Less.test(z, stored) {
            -self.eye_side
        } else {
            self.eye_side
        };
        if side == exact {
            return (side, p);
        }
        // The unit normal pointing to the umbra side (positive quad_side).
        let n = (b - self.c).cross(a - self.c).normalize();
        let d = n.dot(p - self.c);
        let offset = if d == 0.0 {
            side * 1e-9 * (p - self.c).length()
        } else {
            -2.0 * d
        };
        (side, p + n * offset)
    }
}

/// What a submitted half-wedge triangle is.
#[derive(Debug, Clone, Copy)]
struct PrimRole {
    /// Index of its [`HalfJob`].
    job: u32,
    /// Facing culled.
    cull: CullMode,
    /// Whether its fragments are depth tested against the scene.
    depth_tested: bool,
}

/// Render `wedge-blending` on `frame` with settings `s`. A probe attached to the frame records
/// every pass at its pixel ([`crate::gpu::probe`]; the blend steps: [`blend_steps`]).
pub fn render(rec: &mut PassRecorder, s: &Settings) -> Result<BlendingRender, InputError> {
    let frame = rec.frame();
    let silhouettes = silhouettes(frame, s)?;
    let packed = Packed8 {
        target: s.target,
        centroid: s.centroid,
    };
    let unpacked = UnpackedF32 {
        centroid: s.centroid,
    };
    // The vBuffer programs' scalar: the shader precision, at most fp32 (module doc).
    Ok(
        crate::with_shader_float!(frame.gpu.shader, T => match s.packing {
            Packing::Bit8 => render_with::<_, T>(
                rec,
                s,
                &silhouettes,
                &packed,
            ),
            Packing::F32 => render_with::<_, T>(
                rec,
                s,
                &silhouettes,
                &unpacked,
            ),
        }),
    )
}

/// A probe event naming the half-wedge (or full-screen quad) of job `job` (index `k`) of
/// silhouette `si` whose triangle `tri` the watched fragment belongs to.
fn half_wedge_event(
    tap: Tap,
    job: &HalfJob,
    k: u32,
    tri: &RasterTriangle,
    si: usize,
) -> ProbeEvent {
    let half = if job.inner { "inner" } else { "outer" };
    let detail = format!("{half} half of edge {} of silhouette {si}", job.edge);
    let kind = if job.full_screen {
        PrimitiveKind::FullScreen
    } else {
        PrimitiveKind::HalfWedge
    };
    tap.event()
        .primitive(kind, k, detail, Some(tri.front_facing))
}

/// Visit the pixels of tile `t` inside the image: (tile-local index, row-major index).
fn tile_pixels(tiling: &Tiling, t: usize, mut visit: impl FnMut(usize, usize)) {
    let r = tiling.rect(t);
    for y in r.y0..r.y1 {
        for x in r.x0..r.x1 {
            visit(tiling.local(x, y), (y * tiling.width + x) as usize);
        }
    }
}

/// Run `pass` on every tile the current silhouette reached (in parallel; the tile's pixels
/// in order), with the tile index and a counter set each; returns the counters summed.
fn on_dirty_tiles<P: Send>(
    tiles: &mut [BlendTile<P>],
    pass: impl Fn(usize, &mut BlendTile<P>, &mut Counters) + Sync,
) -> Counters {
    tiles
        .par_iter_mut()
        .enumerate()
        .map(|(t, tile)| {
            let mut cnt = Counters::default();
            if tile.dirty {
                pass(t, tile, &mut cnt);
            }
            cnt
        })
        .reduce(Counters::default, |mut a, b| {
            a += b;
            a
        })
}

fn render_with<S: VBufferStorage, T: ShaderFloat>(
    rec: &mut PassRecorder,
    s: &Settings,
    silhouettes: &[Silhouette],
    storage: &S,
) -> BlendingRender {
    let frame = rec.frame();
    let tiling = &frame.tiling;
    let light = RectLight::from_light(frame.scene.light()).expect("options checked a rect light");
    let c = light.center;
    let corners = light.corners();
    let (lo, hi) = wedge_clip_box(frame.influence_bounds(true));
    let receivers = frame.receivers();
    let eye = frame.scene.camera.eye;
    let eye_radius = frame.near_plane_radius();
    let (sil_bytes, fin_bytes) = (storage.silhouette_bytes(), storage.final_bytes());
    let cleared = storage.cleared();
    let dumping = frame.dump_buffers;
    let mut tiles = alloc_tiles(tiling, |_, len| BlendTile {
        stencil: StencilTile::cleared(0, len).recording(dumping),
        silhouette: vec![cleared; len],
        last: vec![cleared; len],
        penumbrae: vec![0; len],
        dirty: false,
        counters: BlendingCounters::default(),
        stencil_sum: if dumping { vec![0; len] } else { Vec::new() },
        final_events: [overflow_record(dumping, len), overflow_record(dumping, len)],
    });
    frame.probe_record("clear", |tap, _| tap.event().clear("stencil", Raw::U8(0)));
    for buffer in ["silhouette-vbuffer", "final-vbuffer"] {
        frame.probe_record("clear", |tap, _| {
            tap.event().clear(buffer, storage.raw(&cleared))
        });
    }
    let probes: Vec<_> = PASS_NAMES.iter().map(|p| frame.probe_pass(p)).collect();
    // The silhouette a probe's events name.
    let silhouette_primitive = |e: ProbeEvent, si: usize| {
        e.primitive(
            PrimitiveKind::Silhouette,
            si as u32,
            format!("of mesh {}", silhouettes[si].mesh),
            None,
        )
        .value("mesh", silhouettes[si].mesh as f64)
    };
    let mut counters = BlendingCounters::default();
    let less = DepthState {
        func: DepthFunc::Less,
        write: false,
    };
    let stencil_state = volume_stencil_state(s.test, StencilOverflow::Wrap);
    let rules = Rules {
        adjust: s.adjust,
        centroid: s.centroid,
    };

    // The negative counts the initialization has read so far, and per mesh the loops that
    // had some (silhouettes come mesh by mesh; reversed, in reverse mesh order).
    let mut negative_seen = 0;
    let mut hole_loops: Vec<HoleLoops> = Vec::new();
    for (si, sil) in silhouettes.iter().enumerate() {
        counters.silhouettes += 1;
        // Pass 1: the shadow volume into the stencil.
        rec.pass_again(PASS_NAMES[0], |pass| {
            let (tris, mut c1) = setup_all(&sil.volume, CullMode::None, tiling);
            let bins = bin(tiling, &tris);
            c1 += draw(
                tiling,
                &mut tiles,
                &tris,
                &bins,
                probes[0].as_ref(),
                // The hierarchical-Z unit skips a tile where every fragment of the volume face
                // would count nothing ([`Frame::hiz_depth_draw`]); such a tile is not marked
                // as drawn, and a tile the silhouette left alone is skipped by the later passes
                // without changing the result (module doc, "Only where the silhouette was drawn").
                |t, _, tri, cnt| {
                    let idle = (less.func, s.test.idle_outcome());
                    frame.hiz_depth_draw(t, tri, idle, cnt, probes[0].as_ref(), |tap| {
                        tap.event().primitive(
                            PrimitiveKind::VolumeTriangle,
                            tri.prim,
                            format!("of silhouette {si}"),
                            Some(tri.front_facing),
                        )
                    })
                },
                |t, tile, tri, f, cnt, tap| {
                    let (pass, z) = frame.tiles[t].depth.test(&less, &f, cnt);
                    count!(cnt.depth_passed += pass as u64);
                    let update =
                        tile.stencil
                            .apply(&stencil_state, tri.front_facing, &f, pass, cnt);
                    tile.dirty = true;
                    if let Some(tap) = tap {
                        let e = tap.event().primitive(
                            PrimitiveKind::VolumeTriangle,
                            tri.prim,
                            format!("of silhouette {si}"),
                            Some(tri.front_facing),
                        );
                        let e = frame.tiles[t]
                            .depth
                            .record_test(e, less.func, f.local, z, pass);
                        tap.push(update.record(e, "stencil"));
                    }
                },
            );
            pass.count(c1);
        });

        // Initialization: shaded pixels get the hard count in every part.
        rec.pass_again(PASS_NAMES[1], |pass| {
            pass.count(on_dirty_tiles(&mut tiles, |t, tile, cnt| {
                let watched = probes[1].as_ref().filter(|p| p.watches_tile(t));
                tile_pixels(tiling, t, |i, _| {
                    count!(cnt.stencil_read_bytes += 1);
                    let count = tile.stencil.values[i] as i8 as i32;
                    if let Some(sum) = tile.stencil_sum.get_mut(i) {
                        *sum += count;
                    }
                    let before = tile.silhouette[i];
                    let mut clamps = 0;
                    tile.counters.negative_counts += u64::from(count < 0);
                    if count != 0 {
                        let (px, c) = storage.store(
                            &[PartState::hard(count); PART_COUNT],
                            &mut tile.counters.stores,
                        );
                        clamps = c;
                        tile.silhouette[i] = px;
                        tile.counters.packing_clamps += clamps;
                        count!(cnt.color_write_bytes += sil_bytes);
                    }
                    if let Some(tap) = watched.and_then(|p| p.tap(t, i)) {
                        let e = silhouette_primitive(tap.event(), si).value("count", count as f64);
                        let e = e.read("stencil", Raw::U8(tile.stencil.values[i]));
                        if count == 0 {
                            return tap.push(e.note("count 0: nothing stored"));
                        }
                        tap.push(e);
                        let e = silhouette_primitive(tap.event(), si).write(
                            "silhouette-vbuffer",
                            storage.raw(&before),
                            storage.raw(&tile.silhouette[i]),
                            Overflow::Clamp,
                            clamps,
                        );
                        tap.push(
                            e.note("every part: occlusion = count, the whole part as rectangle"),
                        );
                    }
                });
            }));
        });
        let negative: u64 = tiles.iter().map(|t| t.counters.negative_counts).sum();
        if negative > negative_seen {
            match hole_loops.last_mut() {
                Some(h) if h.mesh == sil.mesh => {
                    h.loops += 1;
                    h.pixels += negative - negative_seen;
                }
                _ => hole_loops.push(HoleLoops {
                    mesh: sil.mesh,
                    loops: 1,
                    pixels: negative - negative_seen,
                }),
            }
            negative_seen = negative;
        }

        // Pass 2: outer halves of every edge, then inner halves.
        rec.pass_again(PASS_NAMES[2], |pass| {
            let mut jobs: Vec<HalfJob> = Vec::new();
            let mut prims: Vec<[ClipVertex; 3]> = Vec::new();
            let mut roles: Vec<PrimRole> = Vec::new();
            let mut halves = Vec::with_capacity(sil.edges.len());
            let mut quads = Vec::with_capacity(sil.edges.len());
            for [a, b] in &sil.edges {
                halves.push(wedge_halves_and_planes(c, &corners, *a, *b, lo, hi));
                quads.push(HardQuad::new(frame, *a, *b));
            }
            for inner in [false, true] {
                for (k, (pair, planes)) in halves.iter().enumerate() {
                    let [a, b] = sil.edges[k];
                    let cut = quad_inner_halfspace(c, a, b);
                    let half = &pair[if inner { 0 } else { 1 }];
                    if half.is_empty() {
                        continue;
                    }
                    let full_screen = half.contains(eye, eye_radius);
                    let job = jobs.len() as u32;
                    jobs.push(HalfJob {
                        edge: k,
                        inner,
                        planes: bounding_planes(half, planes)
                            .iter()
                            .map(|h| frame.proj.window_plane(h.normal, h.offset))
                            .collect(),
                        full_screen,
                    });
                    if full_screen {
                        for f in FULL_SCREEN {
                            prims.push(f);
                            roles.push(PrimRole {
                                job,
                                cull: CullMode::None,
                                depth_tested: false,
                            });
                        }
                        continue;
                    }
                    let size = half
                        .vertices()
                        .map(|v| v.abs().max_element())
                        .fold(1.0, f64::max);
                    for face in &half.faces {
                        // The face in the hard quad's plane is not depth tested (module doc).
                        let on_quad = face.iter().all(|v| cut.distance(*v).abs() <= 1e-9 * size);
                        for i in 1..face.len() - 1 {
                            prims.push(
                                [face[0], face[i], face[i + 1]]
                                    .map(|x| frame.proj.clip_point(x.as_vec3())),
                            );
                            roles.push(PrimRole {
                                job,
                                cull: CullMode::Back,
                                depth_tested: !on_quad,
                            });
                        }
                    }
                }
            }
            counters.half_wedges += jobs.len() as u64;
            counters.half_wedges_full_screen +=
                jobs.iter().filter(|j| j.full_screen).count() as u64;
            let mut c2 = Counters::default();
            let mut tris: Vec<RasterTriangle> = Vec::new();
            for (k, p) in prims.iter().enumerate() {
                setup_triangle(
                    p,
                    k as u32,
                    roles[k].cull,
                    tiling.width,
                    tiling.height,
                    &mut tris,
                    &mut c2,
                );
            }
            let bins = bin(tiling, &tris);
            c2 += draw(
                tiling,
                &mut tiles,
                &tris,
                &bins,
                probes[2].as_ref(),
                // The hierarchical-Z unit skips a depth-tested face in a tile where LESS fails at
                // every sample ([`Frame::hiz_depth_draw`], idle outcome `false`): there the
                // fragment program below returns at the depth test, having counted the fragment
                // in `rejected_depth` and written no buffer — neither the silhouette vBuffer nor
                // the tile's `dirty` flag, which only a shaded fragment sets. Faces drawn without
                // the depth test (the face in the hard quad's plane, full-screen quads) are never
                // skipped: their fragments do not depend on the scene depth's outcome.
                |t, _, tri, cnt| {
                    let role = roles[tri.prim as usize];
                    if !role.depth_tested {
                        return TileDraw::Whole;
                    }
                    frame.hiz_depth_draw(
                        t,
                        tri,
                        (less.func, false),
                        cnt,
                        probes[2].as_ref(),
                        |tap| half_wedge_event(tap, &jobs[role.job as usize], role.job, tri, si),
                    )
                },
                |t, tile, tri, f, cnt, tap| {
                    let role = roles[tri.prim as usize];
                    let job = &jobs[role.job as usize];
                    let depth = &frame.tiles[t].depth;
                    // The watched fragment's event, built only there: what it saw up to where it
                    // stopped.
                    let record = |build: &dyn Fn(ProbeEvent) -> ProbeEvent| {
                        if let Some(tap) = tap {
                            tap.push(build(half_wedge_event(tap, job, role.job, tri, si)));
                        }
                    };
                    let (stored, test) = if !role.depth_tested {
                        (depth.read(f.local, cnt), None)
                    } else {
                        let (pass, z) = depth.test(&less, &f, cnt);
                        if !pass {
                            tile.counters.rejected_depth += 1;
                            return record(&|e| {
                                depth
                                    .record_test(e, less.func, f.local, z, pass)
                                    .note("depth test failed: the receiver is in front")
                            });
                        }
                        count!(cnt.depth_passed += 1);
                        (depth.values[f.local], Some(z))
                    };
                    let seen = |e: ProbeEvent| match test {
                        Some(z) => depth.record_test(e, less.func, f.local, z, true),
                        None => e,
                    };
                    let Some(rcv) = receivers[(f.y * tiling.width + f.x) as usize] else {
                        return record(&|e| seen(e).note("background"));
                    };
                    let z_w = frame.gpu.depth.to_window(stored);
                    if job
                        .planes
                        .iter()
                        .any(|pl| pl.footprint_outside(f.x, f.y, z_w))
                    {
                        tile.counters.rejected_outside_planes += 1;
                        count!(cnt.shader_discards += 1);
                        return record(&|e| seen(e).note("outside a bounding plane (Fig. 7)"));
                    }
                    let [a, b] = sil.edges[job.edge];
                    let (side, p) =
                        quads[job.edge].side(f.x, f.y, stored, rcv.point.as_dvec3(), frame);
                    if side == 0.0 || (side > 0.0) != job.inner {
                        tile.counters.rejected_quad_side += 1;
                        count!(cnt.shader_discards += 1);
                        return record(&|e| {
                            seen(e).note("the other side of the hard quad (Fig. 8)")
                        });
                    }
                    count!(cnt.fragments_shaded += 1);
                    tile.dirty = true;
                    let regions = edge_in_parts::<T>(&light, p, a, b);
                    if regions.iter().all(Option::is_none) {
                        tile.counters.missed_light += 1;
                        return record(&|e| seen(e).note("the edge reaches no part of the light"));
                    }
                    count!(cnt.color_read_bytes += sil_bytes);
                    let before = tile.silhouette[f.local];
                    let mut parts = storage.load(&before);
                    for (part, region) in parts.iter_mut().zip(&regions) {
                        let Some(r) = region else { continue };
                        tile.counters.part_updates += 1;
                        if job.inner {
                            part.add_inner::<T::AtMostFp32>(r);
                        } else {
                            part.add_outer::<T::AtMostFp32>(r);
                        }
                    }
                    let (px, clamps) = storage.store(&parts, &mut tile.counters.stores);
                    tile.silhouette[f.local] = px;
                    tile.counters.packing_clamps += clamps;
                    count!(cnt.color_write_bytes += sil_bytes);
                    record(&|e| {
                        let areas = regions
                            .iter()
                            .enumerate()
                            .filter_map(|(k, r)| Some((k, r.as_ref()?)));
                        let e =
                            areas.fold(seen(e), |e, (k, r)| e.value(&format!("area{k}"), r.area));
                        let e = e.write(
                            "silhouette-vbuffer",
                            storage.raw(&before),
                            storage.raw(&px),
                            Overflow::Clamp,
                            clamps,
                        );
                        e.note(if job.inner {
                            "inner: the regions' areas subtracted, max X/Y raised"
                        } else {
                            "outer: the regions' areas added, rectangles grown"
                        })
                    });
                },
            );
            pass.count(c2);
        });

        // Pass 3: blend into the final vBuffer, then clear the silhouette vBuffer and stencil.
        rec.pass_again(PASS_NAMES[3], |pass| {
            pass.count(on_dirty_tiles(&mut tiles, |t, tile, cnt| {
                let watched = probes[3].as_ref().filter(|p| p.watches_tile(t));
                tile_pixels(tiling, t, |i, _| {
                    count!(cnt.color_read_bytes += sil_bytes);
                    let sp = storage.load(&tile.silhouette[i]);
                    let tap = watched.and_then(|p| p.tap(t, i));
                    if let Some(tap) = tap {
                        let e = silhouette_primitive(tap.event(), si);
                        tap.push(e.read("silhouette-vbuffer", storage.raw(&tile.silhouette[i])));
                    }
                    if sp.iter().all(|p| p.occlusion == 0.0) {
                        return;
                    }
                    let mean = sp.iter().map(|p| p.occlusion).sum::<f32>() / PART_COUNT as f32;
                    if mean > 0.5 / 255.0 && mean < 1.0 - 0.5 / 255.0 {
                        tile.penumbrae[i] = tile.penumbrae[i].saturating_add(1);
                    }
                    tile.counters.blended_pixels += 1;
                    count!(cnt.color_read_bytes += fin_bytes);
                    let mut fp = storage.load(&tile.last[i]);
                    let mut eps = [0.0; PART_COUNT];
                    for (k, (f, sp)) in fp.iter_mut().zip(&sp).enumerate() {
                        let (out, o) = blend_part::<T::AtMostFp32>(f, sp, rules);
                        *f = out;
                        eps[k] = o.eps;
                        let k = &mut tile.counters;
                        k.parts_limited += o.limited as u64;
                        match o.case {
                            BlendCase::Skipped => {}
                            BlendCase::Copied => k.parts_copied += 1,
                            BlendCase::Blended => {
                                k.parts_blended += 1;
                                k.parts_corrected += (o.eps > 0.0) as u64;
                            }
                            BlendCase::Accumulated => k.parts_accumulated += 1,
                        }
                    }
                    let special = |e: &StoreEvents| e.denormal + e.nan + e.infinite;
                    let before_store = special(&tile.counters.stores);
                    let (px, clamps) = storage.store(&fp, &mut tile.counters.stores);
                    let specials = special(&tile.counters.stores) - before_store;
                    record_overflow(&mut tile.final_events[0], i, clamps as u32);
                    record_overflow(&mut tile.final_events[1], i, specials as u32);
                    if let Some(tap) = tap {
                        let e = eps
                            .iter()
                            .enumerate()
                            .fold(silhouette_primitive(tap.event(), si), |e, (k, x)| {
                                e.value(&format!("eps{k}"), *x as f64)
                            });
                        let e = e.write(
                            "final-vbuffer",
                            storage.raw(&tile.last[i]),
                            storage.raw(&px),
                            Overflow::Clamp,
                            clamps,
                        );
                        tap.push(e.note("A = A_f + A_s − ε per part (§3.2)"));
                    }
                    tile.last[i] = px;
                    tile.counters.packing_clamps += clamps;
                    count!(cnt.color_write_bytes += fin_bytes);
                });
                let pixels = tiling.rect(t).area() as u64;
                tile.silhouette.fill(cleared);
                tile.stencil.values.fill(0);
                count!(cnt.color_write_bytes += pixels * sil_bytes);
                count!(cnt.stencil_write_bytes += pixels);
                tile.dirty = false;
                if let Some(p) = watched {
                    p.record(|tap| tap.event().clear("stencil", Raw::U8(0)));
                    p.record(|tap| {
                        tap.event()
                            .clear("silhouette-vbuffer", storage.raw(&cleared))
                    });
                }
            }));
        });
    }

    // Resolve.
    let (unclamped, penumbrae, visibility, clamped) = rec.pass(PASS_NAMES[4], |pass| {
        let n = frame.pixel_count();
        let mut unclamped = vec![1.0f32; n];
        let mut penumbrae = vec![0u8; n];
        let mut resolve = Counters::default();
        for (t, tile) in tiles.iter_mut().enumerate() {
            counters += tile.counters;
            tile_pixels(tiling, t, |i, g| {
                penumbrae[g] = tile.penumbrae[i];
                if receivers[g].is_none() {
                    return;
                }
                count!(resolve.color_read_bytes += fin_bytes);
                let parts = storage.load(&tile.last[i]);
                let sum = parts.iter().fold(T::AtMostFp32::zero(), |sum, p| {
                    sum + read::<T::AtMostFp32>(p.occlusion)
                });
                let quarter = T::AtMostFp32::from_f64(0.25);
                unclamped[g] = stored(T::AtMostFp32::one() - sum * quarter);
            });
        }
        let visibility: Vec<f32> = unclamped.iter().map(|v| v.clamp(0.0, 1.0)).collect();
        let clamped: Vec<bool> = unclamped
            .iter()
            .zip(&visibility)
            .map(|(u, v)| u != v)
            .collect();
        counters.clamped_pixels = clamped.iter().filter(|&&c| c).count() as u64;
        pass.count(resolve);
        (unclamped, penumbrae, visibility, clamped)
    });
    if let Some(p) = &probes[4] {
        let [x, y] = p.probe().pixel();
        let (g, t) = ((y * tiling.width + x) as usize, tiling.tile_of(x, y));
        p.record(|tap| {
            tap.event()
                .read(
                    "final-vbuffer",
                    storage.raw(&tiles[t].last[tiling.local(x, y)]),
                )
                .value("unclamped", unclamped[g] as f64)
                .resolve(&[visibility[g]], unclamped[g] != visibility[g])
                .note(if receivers[g].is_none() {
                    "background: lit"
                } else {
                    "1 − (Σ parts' occlusion)/4, clamped to [0, 1]"
                })
        });
    }
    let dumps = if dumping {
        blending_dumps(frame, storage, &tiles, clamped)
    } else {
        Vec::new()
    };
    BlendingRender {
        visibility,
        unclamped,
        penumbrae,
        counters,
        dumps,
        hole_loops,
    }
}

/// The dumps of `--dump-buffers` (module doc) from the tiles after the resolve.
fn blending_dumps<S: VBufferStorage>(
    frame: &Frame,
    storage: &S,
    tiles: &[BlendTile<S::Pixel>],
    clamped: Vec<bool>,
) -> Vec<BufferDump> {
    let tiling = &frame.tiling;
    let size = (frame.scene.width, frame.scene.height);
    let n = frame.pixel_count();
    let mut last = vec![storage.cleared(); n];
    let mut sums = vec![0i32; n];
    let mut events = [vec![0u32; n], vec![0u32; n]];
    for (t, tile) in tiles.iter().enumerate() {
        tile_pixels(tiling, t, |i, g| {
            last[g] = tile.last[i];
            sums[g] = tile.stencil_sum[i];
            for (e, record) in events.iter_mut().zip(&tile.final_events) {
                e[g] = record[i];
            }
        });
    }
    let mut dumps = storage.final_dumps(&last, size);
    let [clamps, specials] = events;
    if let Some(d) = dumps.pop() {
        dumps.push(d.with_events(EventMap {
            overflows: vec![
                (EventKind::Saturate, clamps),
                (EventKind::SpecialFloat, specials),
            ],
            clamped,
        }));
    }
    let stencil = BufferDump::new(
        "stencil-sum",
        "per pixel, the sum over the silhouettes of the signed 8-bit stencil count of each \
         silhouette's shadow volume as the initialization pass read it (§4.1; the stencil is \
         cleared after each silhouette)",
        size,
        ElementFormat::CountI32,
        DumpValues::I32(sums),
    )
    .with_events(EventMap::new(
        EventKind::Wrap,
        row_major(tiling, tiles, |t| &t.stencil.overflows),
        Vec::new(),
    ));
    dumps.push(stencil);
    dumps
}

/// `wedge-blending`'s pinned golden renders ([`crate::methods::Method::goldens`]).
const GOLDENS: &[crate::methods::Golden] = &[
    crate::methods::Golden::new("cube-of-spheres"),
    crate::methods::Golden::new("single-quad"),
    crate::methods::Golden::new("eye-in-shadow"),
    crate::methods::Golden::new("scenes/real/hand.toml"),
    crate::methods::Golden::new("scenes/real/bob.toml"),
    // wedge-blending's regions in the shader precision, its vBuffer arithmetic capped at fp32.
    crate::methods::Golden::variant("cube-of-spheres", "shader-fp24", &[])
        .gpu(&[("shader", "fp24")]),
    crate::methods::Golden::variant("cube-of-spheres", "shader-fp16", &[])
        .gpu(&[("shader", "fp16")]),
    crate::methods::Golden::variant("cube-of-spheres", "tile32", &[]).gpu(&[("tile-size", "32")]),
    // wedge-blending (Forest et al. 2006): packing, knobs, float targets, order.
    crate::methods::Golden::variant("forest-spheres", "packed", &[]),
    crate::methods::Golden::variant("forest-spheres", "f32", &[("packing", "f32")]),
    crate::methods::Golden::variant("cube-of-spheres", "f32", &[("packing", "f32")]),
    crate::methods::Golden::variant("cube-of-spheres", "centroid", &[("centroid", "on")]),
    crate::methods::Golden::variant("cube-of-spheres", "adjust-always", &[("adjust", "always")]),
    crate::methods::Golden::variant("cube-of-spheres", "reverse", &[("order", "reverse")]),
    crate::methods::Golden::variant(
        "cube-of-spheres",
        "flush-denormals",
        &[("target", "flush-denormals")],
    ),
    crate::methods::Golden::variant(
        "cube-of-spheres",
        "canonical-nans",
        &[("target", "canonical-nans")],
    ),
    crate::methods::Golden::variant(
        "cube-of-spheres",
        "meshes-zfail",
        &[("silhouettes", "meshes"), ("mode", "zfail")],
    ),
];

/// `wedge-blending`'s configurations in the accuracy–time sweep ([`crate::methods::Method::sweep`]).
const SWEEP: &[crate::methods::OptionPairs] = &[
    &[],
    &[("packing", "f32")],
    &[("centroid", "on")],
    &[("packing", "f32"), ("centroid", "on")],
    &[("adjust", "always")],
    &[("adjust", "never")],
    &[("silhouettes", "meshes")],
    &[("horizon", "clip")],
];

/// What the precision experiment measures of it ([`crate::experiment::precision`]): Paper V's packed vBuffer.
const PRECISION: PrecisionSpec = PrecisionSpec {
    shader_arithmetic: true,
    storage: &[NarrowFormat::of("packing", "8bit", "f32")],
    overflow: &[OverflowKnobs::of(StackLight::Rect, &[("packing", "8bit")])],
};

/// `wedge-blending` in the registry ([`crate::methods::ALL`]).
pub const METHOD: crate::methods::Method = crate::methods::Method {
    name: "wedge-blending",
    paper: "Forest et al., GH 2006: penumbra-wedges blending",
    // Forest et al. 2006 §4.2: rectangular lights, in light space [−1, 1]².
    supports: |s| matches!(s, LightShape::Rect { .. }),
    lights: crate::methods::SeveralLights::PerLight,
    options: crate::methods::OptionTableSpec::of::<WedgeBlendingOptions>(),
    // Sized for packing = f32 (two RGBA32F targets per vBuffer; 8bit needs about a third).
    bytes_per_pixel: 384,
    bytes_per_triangle: 224,
    default_run: crate::methods::DefaultRun::EveryScene,
    sums_per_silhouette_edge: true,
    table_note: |_| None,
    check: |frame| options(frame).map(drop),
    run,
    goldens: GOLDENS,
    sweep: SWEEP,
    precision: PRECISION,
};

/// The warning for a mesh whose hole loops the 8-bit packing cannot hold (module doc,
/// "Holes"; the costs measured in `docs/wedge-blending.md`).
fn hole_warning(frame: &Frame, h: &HoleLoops) -> String {
    let name = frame
        .scene
        .meshes
        .get(h.mesh)
        .map_or("?", |m| m.name.as_str());
    format!(
        "mesh {name}: {} silhouette loop(s) around a hole (hard count −1 on {} \
         pixels); the paper's 8-bit packing (PK4UB) clamps a negative count to 0, so the light \
         through the hole is lost (scenes/hard/torus-hole-rect.toml: RMSE 0.237 against \
         0.0073 unpacked); use [options.wedge-blending] packing = \"f32\" or silhouettes = \
         \"meshes\"",
        h.loops, h.pixels
    )
}

/// Run `wedge-blending` on a rendered frame.
pub fn run(frame: &Frame) -> Result<MethodOutput, InputError> {
    let mut rec = PassRecorder::new(frame, "wedge-blending");
    let (s, mode) = options(frame)?;
    let (sil_bytes, fin_bytes, format) = match s.packing {
        Packing::Bit8 => {
            let st = Packed8 {
                target: s.target,
                centroid: s.centroid,
            };
            (st.silhouette_bytes(), st.final_bytes(), st.describe())
        }
        Packing::F32 => {
            let st = UnpackedF32 {
                centroid: s.centroid,
            };
            (st.silhouette_bytes(), st.final_bytes(), st.describe())
        }
    };
    rec.uses(BufferPlan::stencil8());
    rec.uses(BufferPlan {
        name: "silhouette-vbuffer".into(),
        format: format.clone(),
        bytes_per_sample: sil_bytes as u32,
    });
    rec.uses(BufferPlan {
        name: "final-vbuffer".into(),
        format,
        bytes_per_sample: fin_bytes as u32,
    });
    rec.uses_hiz_depth();
    let footprint = rec.buffer_bytes();
    // The passes of each silhouette run through the recorder, summed per pass ([`render`]).
    let r = render(&mut rec, &s)?;
    rec.clamped(r.counters.clamped_pixels);
    if s.packing == Packing::Bit8 {
        for h in &r.hole_loops {
            rec.warn(hole_warning(frame, h));
        }
    }
    rec.output(BufferDump::new(
        "penumbrae",
        "per pixel, the number of silhouettes whose occlusion (mean over the radial parts) \
         lies strictly between 0.5/255 and 1 − 0.5/255 there: where two or more overlap, the \
         blending of Forest et al. §3.2 matters",
        (frame.scene.width, frame.scene.height),
        ElementFormat::Count8,
        DumpValues::U8(r.penumbrae),
    ));
    r.dumps.into_iter().for_each(|d| rec.output(d));
    let (visibility, horizon) =
        clip_to_horizon(&mut rec, s.horizon, Visibility::Gray(r.visibility));
    Ok(rec.finish(
        visibility,
        serde_json::json!({
            "mode": mode.written(),
            "horizon": horizon,
            "resolved": s,
            "gpu": frame.gpu,
            "buffer_bytes": footprint,
            "counters": r.counters,
        }),
    ))
}
