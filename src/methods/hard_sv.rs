//! `hard-sv`: hard shadow volumes from the light center (Paper I §3; Paper II §5; Everitt &
//! Kilgard's z-fail with an infinite far plane), counted in an 8-bit stencil buffer.
//!
//! * z-pass: stencil cleared to 0; front-facing shadow-volume triangles whose fragment passes
//!   LESS against the scene depth increment, back-facing ones decrement.
//! * z-fail: front and back caps added ([`Capping::Capped`]); back-facing triangles whose
//!   fragment *fails* LESS increment, front-facing ones decrement.
//! * `stencil = "wrap"` uses INCR_WRAP/DECR_WRAP, `"saturate"` uses INCR/DECR: with more than 255
//!   overlapping volumes, wrap brings a count of 256 back to 0 (lit), saturate sticks at 255,
//!   and saturating decrements that clamp at 0 before their increment arrive leave counts > 0.
//! * `submission = "two-sided"` (default): one pass, two-sided stencil, primitives in the order
//!   of [`crate::geometry::shadow_volume`]. `"two-pass"`: the incrementing facing is drawn first
//!   (culling the other), then the decrementing one — the classic order that keeps saturating
//!   counts from clamping at 0.
//!
//! A pixel is lit (visibility 1) when its stencil count is 0; background pixels are lit.
//!
//! Buffer dump ([`super::dump`]): `stencil`, the final counts (always, as `stencil.png`), with
//! its wraps or clamps per pixel under `--dump-buffers`.

use super::dump::{row_major, BufferDump, DumpValues, ElementFormat, EventKind, EventMap};
use super::output::MethodOutput;
use crate::error::InputError;
use crate::frame::{setup_all, Frame, BACKGROUND};
use crate::geometry::shadow_volume::{
    shadow_volume_parts, shadow_volume_triangles, volume_event, Capping,
};
use crate::gpu::buffers::{alloc_tiles, StencilTile};
use crate::gpu::counters::{count, Counters};
use crate::gpu::depth::{DepthFunc, DepthState};
use crate::gpu::probe::Raw;
use crate::gpu::raster::{bin, draw};
use crate::gpu::setup::CullMode;
use crate::gpu::stencil::{StencilFace, StencilOp, StencilState};
use crate::methods::output::BufferPlan;
use crate::methods::precision_spec::{OverflowKnobs, PrecisionSpec, StackLight};
use crate::methods::recorder::PassRecorder;
use crate::options::{option_names, option_table, OptionTable, OptionType};
use crate::visibility::Visibility;
use glam::Vec3;

option_names! {
    /// The `mode` option of the methods that count shadow-volume boundaries: z-pass, z-fail, or
    /// `auto`, decided from the frame ([`CountMode::zfail`]).
    pub enum CountMode {
        /// z-fail when the near plane is in shadow ([`crate::geometry::near_plane::eye_in_shadow`]), else z-pass.
        Auto = "auto",
        /// Count between the eye and the receiver.
        ZPass = "zpass",
        /// Count between the receiver and infinity (caps needed).
        ZFail = "zfail",
    }
}

impl CountMode {
    /// Whether to count z-fail: as asked, or with `Auto` when the near plane at distance `near`
    /// is in the shadow of one of `lights` ([`crate::geometry::near_plane::eye_in_shadow`]).
    pub fn zfail(self, scene: &crate::scene::Scene, near: f64, lights: &[Vec3]) -> bool {
        match self {
            CountMode::ZPass => false,
            CountMode::ZFail => true,
            CountMode::Auto => crate::geometry::near_plane::eye_in_shadow(scene, near, lights),
        }
    }
}

/// Counting direction of the stencil passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum ShadowTest {
    /// Count volume boundaries between the eye and the receiver.
    ZPass,
    /// Count volume boundaries between the receiver and infinity (caps needed).
    ZFail,
}

impl ShadowTest {
    /// The outcome of the LESS depth test on which a volume face counts nothing — z-pass counts
    /// where it passes, z-fail where it fails — so a tile where every fragment has it can be
    /// skipped ([`Frame::hiz_depth_draw`]).
    pub fn idle_outcome(self) -> bool {
        self == ShadowTest::ZFail
    }
}

/// Stencil overflow behaviour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum StencilOverflow {
    /// INCR_WRAP / DECR_WRAP.
    Wrap,
    /// INCR / DECR (saturate).
    Saturate,
}

/// How shadow-volume triangles are submitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Submission {
    /// One pass with two-sided stencil.
    TwoSided,
    /// Incrementing facing first, then decrementing facing.
    TwoPass,
}

/// Settings of one hard-shadow stencil render.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct StencilShadowSettings {
    /// z-pass or z-fail.
    pub test: ShadowTest,
    /// Wrap or saturate.
    pub overflow: StencilOverflow,
    /// Submission order.
    pub submission: Submission,
}

option_names!(StencilOverflow {
    Wrap = "wrap",
    Saturate = "saturate",
});

option_names!(Submission {
    TwoSided = "two-sided",
    TwoPass = "two-pass",
});

option_table! {
    /// `[options.hard-sv]` (module doc); `nsample` has these keys too.
    pub struct HardSvOptions["hard-sv"] {
        /// count z-pass or z-fail; auto: z-fail when the near plane is in the light's shadow
        mode: CountMode = CountMode::Auto;
        /// stencil overflow: INCR_WRAP/DECR_WRAP or saturating INCR/DECR
        stencil: StencilOverflow = StencilOverflow::Wrap;
        /// one two-sided stencil pass, or the incrementing facing first, then the other
        submission: Submission = Submission::TwoSided;
    }
}

impl HardSvOptions {
    /// The stencil settings these options ask for on `frame`: with `mode = auto`, z-fail when
    /// the eye (or any point of the near plane) is in the shadow of one of `lights`.
    pub fn stencil_settings(&self, frame: &Frame, lights: &[Vec3]) -> StencilShadowSettings {
        StencilShadowSettings {
            test: shadow_test(self.mode, frame, lights),
            overflow: self.stencil,
            submission: self.submission,
        }
    }
}

/// The counting direction `mode` asks for on `frame` ([`CountMode::zfail`] with `lights`).
pub fn shadow_test(mode: CountMode, frame: &Frame, lights: &[Vec3]) -> ShadowTest {
    if mode.zfail(frame.scene, frame.proj.near, lights) {
        ShadowTest::ZFail
    } else {
        ShadowTest::ZPass
    }
}

/// The two-sided stencil state that counts shadow-volume boundaries (module doc): z-pass
/// increments on front faces passing the depth test and decrements on back faces; z-fail
/// increments on back faces failing it and decrements on front faces; wrapping or saturating.
pub fn volume_stencil_state(test: ShadowTest, overflow: StencilOverflow) -> StencilState {
    let (incr, decr) = match overflow {
        StencilOverflow::Wrap => (StencilOp::IncrWrap, StencilOp::DecrWrap),
        StencilOverflow::Saturate => (StencilOp::Incr, StencilOp::Decr),
    };
    let keep = StencilOp::Keep;
    // (front face, back face) ops for (depth fail, depth pass).
    match test {
        ShadowTest::ZPass => StencilState {
            front: StencilFace::always(keep, incr),
            back: StencilFace::always(keep, decr),
        },
        ShadowTest::ZFail => StencilState {
            front: StencilFace::always(decr, keep),
            back: StencilFace::always(incr, keep),
        },
    }
}

/// The name of the stencil pass of shadow-volume test `test`.
pub fn shadow_volume_pass(test: ShadowTest) -> &'static str {
    match test {
        ShadowTest::ZPass => "shadow-volume-zpass",
        ShadowTest::ZFail => "shadow-volume-zfail",
    }
}

/// Render the hard shadow volumes of every mesh from light point `light` into a fresh 8-bit
/// stencil buffer (tile-major) against the frame's depth buffer. Returns the stencil tiles and
/// the counters (setup + rasterization). The tiles record their overflow events per sample
/// when the frame asks for buffer dumps ([`Frame::dump_buffers`]). A probe attached to the
/// frame records the clear and every fragment at its pixel ([`crate::gpu::probe`]).
pub fn stencil_shadow(
    frame: &Frame,
    light: Vec3,
    s: &StencilShadowSettings,
) -> (Vec<StencilTile>, Counters) {
    let capping = match s.test {
        ShadowTest::ZPass => Capping::Open,
        ShadowTest::ZFail => Capping::Capped,
    };
    let meshes = frame.caster_meshes();
    let prims = shadow_volume_triangles(&meshes, light, &frame.proj, capping);
    let parts = frame
        .probe
        .as_ref()
        .map(|_| shadow_volume_parts(&meshes, light, &frame.proj, capping));
    let state = volume_stencil_state(s.test, s.overflow);
    let depth = DepthState {
        func: DepthFunc::Less,
        write: false,
    };
    let passes: Vec<(CullMode, &str)> = match (s.submission, s.test) {
        (Submission::TwoSided, _) => vec![(CullMode::None, "")],
        // z-pass increments on front faces: draw them first (cull back), then the back faces.
        (Submission::TwoPass, ShadowTest::ZPass) => vec![
            (CullMode::Back, "/front-faces"),
            (CullMode::Front, "/back-faces"),
        ],
        // z-fail increments on back faces: draw them first (cull front).
        (Submission::TwoPass, ShadowTest::ZFail) => vec![
            (CullMode::Front, "/back-faces"),
            (CullMode::Back, "/front-faces"),
        ],
    };
    let tiling = &frame.tiling;
    let name = shadow_volume_pass(s.test);
    let mut stencil = alloc_tiles(tiling, |_, len| {
        StencilTile::cleared(0, len).recording(frame.dump_buffers)
    });
    frame.probe_record(name, |tap, _| tap.event().clear("stencil", Raw::U8(0)));
    let mut counters = Counters::default();
    for (cull, suffix) in passes {
        let (tris, c) = setup_all(&prims, cull, tiling);
        counters += c;
        let bins = bin(tiling, &tris);
        let probe = frame.probe_pass(&format!("{name}{suffix}"));
        counters += draw(
            tiling,
            &mut stencil,
            &tris,
            &bins,
            probe.as_ref(),
            |t, _, tri, c| {
                let idle = (depth.func, s.test.idle_outcome());
                frame.hiz_depth_draw(t, tri, idle, c, probe.as_ref(), |tap| {
                    volume_event(tap.event(), parts.as_deref(), tri)
                })
            },
            |t, st, tri, f, c, tap| {
                let (pass, z) = frame.tiles[t].depth.test(&depth, &f, c);
                count!(c.depth_passed += pass as u64);
                let update = st.apply(&state, tri.front_facing, &f, pass, c);
                if let Some(tap) = tap {
                    let e = volume_event(tap.event(), parts.as_deref(), tri);
                    let e = frame.tiles[t]
                        .depth
                        .record_test(e, depth.func, f.local, z, pass);
                    tap.push(update.record(e, "stencil"));
                }
            },
        );
    }
    (stencil, counters)
}

/// Row-major stencil values.
pub fn stencil_row_major(frame: &Frame, tiles: &[StencilTile]) -> Vec<u8> {
    row_major(&frame.tiling, tiles, |t| &t.values)
}

/// The kind of overflow event a stencil with `overflow` ops makes.
pub fn stencil_event_kind(overflow: StencilOverflow) -> EventKind {
    match overflow {
        StencilOverflow::Wrap => EventKind::Wrap,
        StencilOverflow::Saturate => EventKind::Saturate,
    }
}

/// The dump of a hard-shadow stencil (`stencil` of `tiles`, row-major `values`) described by
/// `about`, with its overflow events of `kind` when they were recorded.
pub fn stencil_dump(
    frame: &Frame,
    name: &str,
    about: &str,
    tiles: &[StencilTile],
    values: Vec<u8>,
    kind: EventKind,
) -> BufferDump {
    let dump = BufferDump::new(
        name,
        about,
        (frame.scene.width, frame.scene.height),
        ElementFormat::Stencil8,
        DumpValues::U8(values),
    );
    if frame.dump_buffers {
        let overflows = row_major(&frame.tiling, tiles, |t| &t.overflows);
        dump.with_events(EventMap::new(kind, overflows, Vec::new()))
    } else {
        dump
    }
}

/// `hard-sv`'s pinned golden renders ([`crate::methods::Method::goldens`]).
const GOLDENS: &[crate::methods::Golden] = &[
    crate::methods::Golden::new("cube-of-spheres"),
    crate::methods::Golden::new("single-quad"),
    crate::methods::Golden::new("cylinder"),
    crate::methods::Golden::new("eye-in-shadow"),
    crate::methods::Golden::new("two-lights"),
    // Real models (scenes/models/README): the open hand, closed by repair on load (one hole
    // capped); Bob, genus 1 (a hole loop for the wedge methods); the scorpion's thin legs
    // under a sphere light; Spot under a disk light.
    crate::methods::Golden::new("scenes/real/hand.toml"),
    crate::methods::Golden::new("scenes/real/bob.toml"),
    crate::methods::Golden::new("scenes/real/scorpion.toml"),
    // hard-sv: stencil overflow and submission order where 300 volumes overlap.
    crate::methods::Golden::new("overlap-stress").sized(32),
    crate::methods::Golden::variant("overlap-stress", "saturate", &[("stencil", "saturate")])
        .sized(32),
    crate::methods::Golden::variant(
        "overlap-stress",
        "saturate-two-pass",
        &[("stencil", "saturate"), ("submission", "two-pass")],
    )
    .sized(32),
    // Pipeline settings: depth formats and tile sizes (the output must not depend on the tile
    // size; these goldens equal the default ones where it does not).
    crate::methods::Golden::variant("cube-of-spheres", "d32f", &[]).gpu(&[("depth", "d32f")]),
    crate::methods::Golden::variant("cube-of-spheres", "d16", &[]).gpu(&[("depth", "d16")]),
    // HiZ tiles finer than the raster tile: the image of the default golden, other counters.
    crate::methods::Golden::variant("cube-of-spheres", "tile16-hiz4", &[])
        .gpu(&[("tile-size", "16"), ("hiz-tile-size", "4")]),
];

/// `hard-sv`'s configurations in the accuracy–time sweep ([`crate::methods::Method::sweep`]).
const SWEEP: &[crate::methods::OptionPairs] = &[&[]];

/// What the precision experiment measures of it ([`crate::experiment::precision`]): the 8-bit stencil wrapping and saturating (every stencil pass of the other methods is the same buffer).
const PRECISION: PrecisionSpec = PrecisionSpec {
    shader_arithmetic: false,
    storage: &[],
    overflow: &[
        OverflowKnobs::of(StackLight::Point, &[("stencil", "wrap")]),
        OverflowKnobs::of(StackLight::Point, &[("stencil", "saturate")]),
    ],
};

/// `hard-sv` in the registry ([`crate::methods::ALL`]).
pub const METHOD: crate::methods::Method = crate::methods::Method {
    name: "hard-sv",
    paper: "Paper I §3, II §5: hard shadow volumes",
    // The light center of any shape.
    supports: |_| true,
    lights: crate::methods::SeveralLights::PerLight,
    options: crate::methods::OptionTableSpec::of::<HardSvOptions>(),
    bytes_per_pixel: 72,
    bytes_per_triangle: 208,
    default_run: crate::methods::DefaultRun::EveryScene,
    sums_per_silhouette_edge: false,
    table_note: |_| None,
    check: |frame| HardSvOptions::read(frame.scene).map(drop),
    run,
    goldens: GOLDENS,
    sweep: SWEEP,
    precision: PRECISION,
};

/// Run `hard-sv` on a rendered frame.
pub fn run(frame: &Frame) -> Result<MethodOutput, InputError> {
    let mut rec = PassRecorder::new(frame, "hard-sv");
    let center = frame.scene.light().center;
    let options = HardSvOptions::read(frame.scene)?;
    let settings = options.stencil_settings(frame, &[center]);
    rec.uses(BufferPlan::stencil8());
    rec.uses_hiz_depth();
    let tiles = rec.pass(shadow_volume_pass(settings.test), |pass| {
        let (tiles, counters) = stencil_shadow(frame, center, &settings);
        pass.count(counters);
        tiles
    });
    let stencil = stencil_row_major(frame, &tiles);
    let prims = frame.prim_ids();
    let vis: Vec<f32> = stencil
        .iter()
        .zip(prims)
        .map(|(s, p)| {
            if *p == BACKGROUND || *s == 0 {
                1.0
            } else {
                0.0
            }
        })
        .collect();
    frame.probe_record("resolve", |tap, i| {
        tap.event()
            .read("stencil", Raw::U8(stencil[i]))
            .resolve(&[vis[i]], false)
            .note(if prims[i] == BACKGROUND {
                "background: lit"
            } else {
                "lit where the stencil count is 0, else shadowed"
            })
    });
    rec.output(stencil_dump(
        frame,
        "stencil",
        "the 8-bit stencil counts of the hard shadow volumes from the light center (Paper I §3; \
         z-pass, or z-fail with caps, Paper II §5) as the resolve read them: lit where 0",
        &tiles,
        stencil,
        stencil_event_kind(settings.overflow),
    ));
    Ok(rec.finish(
        Visibility::Gray(vis),
        serde_json::json!({ "mode": options.mode.written(), "resolved": settings, "gpu": frame.gpu }),
    ))
}
