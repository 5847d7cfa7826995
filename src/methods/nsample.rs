//! `nsample`: the papers' reference (Paper III §5.1, "1024-sample shadows") — the average of N
//! hard shadow-volume renders ([`super::hard_sv`]) from N stratified points on the light.
//!
//! Samples sit at the centers of a √N×√N grid of strata over the light
//! ([`Pattern::Centered`]); a sphere light is sampled on its disk facing the center of the
//! scene's mesh bounds (one fixed disk for all pixels, as a GPU multi-pass render must use);
//! a textured light weights each sample by its texel (RGB visibility). Per pixel, the weights of
//! the samples whose stencil count is 0 are summed in f64 in sample order, then rounded to f32.
//! Every stencil pass's memory traffic is counted, so the totals can be set against Paper III
//! §5.2 (585 MB for 1024 samples vs 6 MB for the soft shadow volume pass).
//!
//! The N passes are independent: up to [`MAX_CONCURRENT_SAMPLES`] of them (one per thread)
//! run at once, each parallel over tiles as well, and each batch is accumulated in sample
//! order, so the sums are those of one pass after another for any thread count (issue 13:
//! two threads against one, 512², n = 256, whole process: 1.99× with batches, 1.62× with one
//! pass at a time; farm-bench medians of 5).
//!
//! Buffer dump (`--dump-buffers`, [`super::dump`]): `accumulator`, per pixel (and channel for
//! a textured light) the f64 sum of the weights of the samples that saw the light — what the
//! visibility is rounded from (`clamp(sum, 0, 1)` to f32) — with the stencil's overflow
//! events summed over the sample passes. The per-sample stencils are not kept.
//!
//! Options: `n` (a perfect square, 1…4096, default 1024), `horizon`
//! ([`super::horizon_clip`]: with `clip` the averaged visibility is limited to the part of the
//! light in front of the receiver's plane; with `integrate` each sample is tested against
//! that plane, `n·(s − p) ≥ 0` in f64, a sample behind lights nothing and its weight goes to
//! a behind accumulator, and a pixel with samples behind is `f·lit/front`, the lit share of
//! the samples in front times the fraction `f` in front (`in_front_share`;
//! `docs/horizon.md`, "`integrate`")), and `mode`, `stencil`, `submission` as for
//! `hard-sv`; `mode = auto` chooses z-fail when the near plane is in the shadow of the
//! light center or of the shape's extreme points ([`crate::geometry::near_plane::representative_light_points`]).

use super::dump::{row_major, BufferDump, DumpValues, ElementFormat, EventMap};
use super::hard_sv::{
    stencil_event_kind, stencil_shadow, HardSvOptions, ShadowTest, StencilShadowSettings,
};
use super::horizon_clip::{clip_to_horizon, uses_receiver_normals, Horizon, IntegrableHorizonKeys};
use super::output::MethodOutput;
use crate::error::InputError;
use crate::frame::{Frame, BACKGROUND};
use crate::geometry::near_plane::representative_light_points;
use crate::gpu::counters::{count, Counters};
use crate::gpu::normal_buffer;
use crate::gpu::probe::{Overflow, PrimitiveKind, Raw};
use crate::light::horizon::shader_fraction_in_front;
use crate::light::sampling::{stratified, LightSample, Pattern};
use crate::methods::hard_sv::CountMode;
use crate::methods::output::BufferPlan;
use crate::methods::recorder::PassRecorder;
use crate::options::{option_table, OptionTable, OptionType};
use crate::scene::LightShape;
use crate::visibility::Visibility;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Default sample count (Paper III §5.1).
pub const DEFAULT_SAMPLES: u32 = 1024;

/// Most stencil passes rendered at once (one per thread, at most this many): each holds its
/// own stencil buffer until the batch is accumulated (1 byte per pixel, `memory`'s estimate).
pub const MAX_CONCURRENT_SAMPLES: usize = 8;

/// The point a sphere light's sampling disk faces: the center of the bounds of the meshes
/// within the light's influence ([`Frame::influence_bounds`]), so that a mesh whose shadow
/// reaches no receiver of the frame does not turn the disk.
pub fn sphere_disk_target(frame: &Frame) -> Vec3 {
    let (lo, hi) = frame.influence_bounds(false);
    (lo + hi) * 0.5
}

option_table! {
    /// `[options.nsample]` (module doc): those of `hard-sv` and the sample count.
    pub struct NsampleOptions["nsample"] {
        ..shadow: HardSvOptions,
        ..horizon: IntegrableHorizonKeys,
        /// light samples: the centers of √n×√n strata (a perfect square)
        n: u32 [1..=4096] = DEFAULT_SAMPLES;
    }
}

/// `nsample`'s options, read and checked once ([`options`]).
#[derive(Debug, Clone)]
pub struct NsampleSettings {
    /// The light samples.
    pub samples: Vec<LightSample>,
    /// The stencil settings of each sample's hard shadow-volume pass.
    pub stencil: StencilShadowSettings,
    /// The `mode` as written.
    pub mode: CountMode,
    /// The receiver's own horizon (`horizon`, [`super::horizon_clip`]).
    pub horizon: Horizon,
}

/// Read and check `[options.nsample]`.
pub fn options(frame: &Frame) -> Result<NsampleSettings, InputError> {
    let scene = frame.scene;
    let o = NsampleOptions::read(scene)?;
    let settings = o
        .shadow
        .stencil_settings(frame, &representative_light_points(scene));
    let samples = stratified(
        scene.light(),
        o.n,
        Pattern::Centered,
        sphere_disk_target(frame),
    )
    .map_err(|e| scene.option_error(NsampleOptions::NAME, "n", e))?;
    Ok(NsampleSettings {
        samples,
        stencil: settings,
        mode: o.shadow.mode,
        horizon: o.horizon.into(),
    })
}

/// `horizon = integrate`'s receiver planes in tile order: per tile and sample, the receiver's
/// point and its normal as the normal buffer holds it ([`Frame::receiver_normals`]), `None`
/// for background and the tiles' padding. A light sample `s` is in front where
/// `n·(s − p) ≥ 0`, in f64 like the accumulation.
fn receiver_planes(frame: &Frame) -> Vec<Vec<Option<(DVec3, DVec3)>>> {
    let tiling = &frame.tiling;
    let (receivers, normals) = (frame.receivers(), frame.receiver_normals());
    (0..tiling.tile_count())
        .map(|t| {
            (0..tiling.tile_len())
                .map(|i| {
                    let [x, y] = tiling.position(t, i);
                    if x >= tiling.width || y >= tiling.height {
                        return None;
                    }
                    let k = (y * tiling.width + x) as usize;
                    receivers[k].map(|r| (r.point.as_dvec3(), normals[k]))
                })
                .collect()
        })
        .collect()
}

/// `horizon = integrate`'s value of a pixel some of whose samples lie behind its plane
/// (module doc), per channel: `f · lit / (total − behind)`, the lit samples' weight over the
/// weight of those in front times the fraction `f` of the light in front — the mean
/// visibility over the clipped light, estimated from the samples that fall on it, times its
/// area, so that a clipped light with nothing in front of it gives `f` itself rather than the
/// share of the sample grid the plane leaves (a staircase in the plane's position: up to a
/// row of √n samples, 1/√n of the light, at once). 0 where no sample is in front.
fn in_front_share(lit: [f64; 3], behind: [f64; 3], total: [f64; 3], f: f64) -> [f64; 3] {
    [0, 1, 2].map(|ch| {
        let front = total[ch] - behind[ch];
        if front > 0.0 {
            f * lit[ch] / front
        } else {
            0.0
        }
    })
}

/// `nsample`'s pinned golden renders ([`crate::methods::Method::goldens`]).
const GOLDENS: &[crate::methods::Golden] = &[
    crate::methods::Golden::new("cube-of-spheres"),
    crate::methods::Golden::new("single-quad"),
    crate::methods::Golden::new("cylinder"),
    crate::methods::Golden::new("eye-in-shadow"),
    crate::methods::Golden::new("two-lights"),
    // The references' options.
    crate::methods::Golden::variant("single-quad", "n16", &[("n", "16")]),
];

/// `nsample`'s configurations in the accuracy–time sweep ([`crate::methods::Method::sweep`]).
const SWEEP: &[crate::methods::OptionPairs] = &[
    &[("n", "4")],
    &[("n", "16")],
    &[("n", "64")],
    &[("n", "256")],
    &[("n", "1024")],
    &[("n", "64"), ("horizon", "clip")],
    &[("n", "64"), ("horizon", "integrate")],
];

/// `nsample` in the registry ([`crate::methods::ALL`]).
pub const METHOD: crate::methods::Method = crate::methods::Method {
    name: "nsample",
    paper: "Paper III §5.1: N hard shadows",
    // Stratified samples of any shape.
    supports: |_| true,
    lights: crate::methods::SeveralLights::PerLight,
    options: crate::methods::OptionTableSpec::of::<NsampleOptions>(),
    // Up to `MAX_CONCURRENT_SAMPLES` stencil passes at once, each with its own stencil and
    // scratch: 92 bytes per pixel on one thread, 185 on eight (n = 16, `cube-of-spheres`,
    // 512² and 1024²).
    bytes_per_pixel: 208,
    bytes_per_triangle: 240,
    default_run: crate::methods::DefaultRun::FirstSceneOnly,
    sums_per_silhouette_edge: false,
    table_note: |scene| {
        let sphere = |l: &crate::scene::Light| matches!(l.shape, LightShape::Sphere { .. });
        scene.lights.iter().any(sphere).then_some(
            "note: a sphere light is the disk facing each receiver for raycast (unless \
             raycast.sphere = fixed-disk) and the wedge methods, but one disk facing the \
             center of the bounds of the meshes within the light's influence for nsample",
        )
    },
    check: |frame| options(frame).map(drop),
    run,
    goldens: GOLDENS,
    sweep: SWEEP,
    precision: crate::methods::precision_spec::PrecisionSpec::NO_SHADER_ARITHMETIC,
};

/// Bytes of one accumulator pixel (f64x3), read and written where a sample adds to it.
const ACCUMULATOR_BYTES: u32 = 24;

/// What one sample's accumulation does on the GPU (Paper III §5.1's accumulation of the N hard
/// shadows): a screen pass over the receivers with the stencil test `EQUAL 0` — one stencil
/// byte read per receiver — that adds the sample's weight to the accumulator by blending, a
/// read and a write of it, where the test passes (and, with `horizon = integrate`, to the
/// behind accumulator where the sample is behind the receiver's plane). Background pixels are
/// not counted: their value is replaced by 1 at the resolve.
#[derive(Debug, Default, Clone, Copy)]
struct AccumulateWork {
    /// Receivers whose stencil the pass tests.
    receivers: u64,
    /// Receivers whose accumulator (or behind accumulator) the pass reads and writes.
    updates: u64,
}

impl AccumulateWork {
    fn add(&mut self, receiver: bool, updated: bool) {
        self.receivers += u64::from(receiver);
        self.updates += u64::from(receiver && updated);
    }

    fn merged(self, other: Self) -> Self {
        Self {
            receivers: self.receivers + other.receivers,
            updates: self.updates + other.updates,
        }
    }

    fn counters(self) -> Counters {
        let mut c = Counters::default();
        count!(c.stencil_read_bytes += self.receivers);
        count!(c.color_read_bytes += self.updates * u64::from(ACCUMULATOR_BYTES));
        count!(c.color_write_bytes += self.updates * u64::from(ACCUMULATOR_BYTES));
        c
    }
}

/// Run `nsample` on a rendered frame.
pub fn run(frame: &Frame) -> Result<MethodOutput, InputError> {
    let mut rec = PassRecorder::new(frame, "nsample");
    let scene = frame.scene;
    let NsampleSettings {
        samples,
        stencil: settings,
        mode,
        horizon,
    } = options(frame)?;
    let colored = matches!(scene.light().shape, LightShape::TexturedRect { .. });
    let planes = (horizon == Horizon::Integrate).then(|| {
        uses_receiver_normals(&mut rec);
        receiver_planes(frame)
    });

    let tiling = &frame.tiling;
    rec.uses(BufferPlan::stencil8());
    // An f64x3 accumulator per tile, zeroed, and its plan entry.
    let accumulator = |name: &str| BufferPlan {
        name: name.into(),
        format: "f64x3".into(),
        bytes_per_sample: ACCUMULATOR_BYTES,
    };
    let zeroed = || -> Vec<Vec<[f64; 3]>> {
        (0..tiling.tile_count())
            .map(|_| vec![[0.0; 3]; tiling.tile_len()])
            .collect()
    };
    let mut acc = rec.allocate(accumulator("accumulator"), zeroed);
    // `horizon = integrate`: the weight of the samples behind each receiver's plane.
    let mut behind: Vec<Vec<[f64; 3]>> = match planes {
        Some(_) => rec.allocate(accumulator("behind accumulator"), zeroed),
        None => vec![Vec::new(); tiling.tile_count()],
    };
    rec.uses_hiz_depth();
    let mut overflows = vec![
        0u32;
        if frame.dump_buffers {
            frame.pixel_count()
        } else {
            0
        }
    ];
    let pass_name = match settings.test {
        ShadowTest::ZPass => "sample-shadow-volume-zpass",
        ShadowTest::ZFail => "sample-shadow-volume-zfail",
    };
    let f64_bits = |px: &[f64; 3]| Raw::Channels(px.map(|v| Raw::F64(v.to_bits())).to_vec());
    frame.probe_record("accumulate", |tap, _| {
        tap.event().clear("accumulator", f64_bits(&[0.0; 3]))
    });
    // The N stencil passes are independent: a batch of them runs at once (each is itself
    // parallel over tiles), then the batch is accumulated in sample order, so the f64 sums and
    // every output bit are those of one pass after another, for any thread count. A probe
    // records events in the order the passes apply them: one sample at a time then.
    let batch = if frame.probe.is_some() {
        1
    } else {
        rayon::current_num_threads().clamp(1, MAX_CONCURRENT_SAMPLES)
    };
    let scoped = |k: usize| {
        frame
            .probe
            .as_ref()
            .map(|p| p.enter(move |sc| sc.sample = Some(k as u32)))
    };
    // `horizon = integrate`: each sample's accumulation reads the receiver's normal at every
    // receiver (its point is the depth buffer's, which the stencil pass reads already).
    let normal_reads = planes.as_ref().map(|planes| {
        let receivers = planes.iter().flatten().flatten().count() as u64;
        let mut reads = Counters::default();
        count!(reads.color_read_bytes += receivers * u64::from(normal_buffer::BYTES_PER_PIXEL));
        reads
    });
    rec.pass(pass_name, |pass| {
        pass.set_runs(samples.len() as u64);
        for (b, chunk) in samples.chunks(batch).enumerate() {
            let rendered: Vec<_> = chunk
                .par_iter()
                .enumerate()
                .map(|(j, s)| {
                    let _scope = scoped(b * batch + j);
                    stencil_shadow(frame, s.position, &settings)
                })
                .collect();
            for (j, (s, (stencil, c))) in chunk.iter().zip(rendered).enumerate() {
                let k = b * batch + j;
                let _scope = scoped(k);
                pass.count(c);
                if let Some(reads) = normal_reads {
                    pass.count(reads);
                }
                if frame.dump_buffers {
                    let sample = row_major(tiling, &stencil, |t| &t.overflows);
                    overflows.iter_mut().zip(sample).for_each(|(a, b)| *a += b);
                }
                let w = s.weight.map(f64::from);
                let at = s.position.as_dvec3();
                // `horizon = integrate`: a sample behind the receiver's plane lights nothing;
                // its weight goes to the behind accumulator.
                let in_front = |t: usize, i: usize| {
                    planes
                        .as_ref()
                        .is_none_or(|planes| planes[t][i].is_none_or(|(p, n)| n.dot(at - p) >= 0.0))
                };
                // Adds the sample's weight where it lights the pixel (or, behind the plane, to
                // the behind accumulator); whether an accumulator was read and written.
                let add = |px: &mut [f64; 3], back: &mut [[f64; 3]], i: usize, v: u8, front| {
                    let sum = match (front, v == 0) {
                        (true, true) => Some(px),
                        (true, false) => None,
                        (false, _) => Some(&mut back[i]),
                    };
                    let updated = sum.is_some();
                    if let Some(sum) = sum {
                        for ch in 0..3 {
                            sum[ch] += w[ch];
                        }
                    }
                    updated
                };
                let probe = frame.probe_pass("accumulate");
                let accumulated: AccumulateWork = acc
                    .par_iter_mut()
                    .zip(behind.par_iter_mut())
                    .zip(&stencil)
                    .enumerate()
                    .map(|(t, ((a, back), st))| {
                        let receiver = |i: usize| frame.tiles[t].prim[i] != BACKGROUND;
                        let mut work = AccumulateWork::default();
                        match probe.as_ref().filter(|p| p.watches_tile(t)) {
                            None => {
                                for (i, (px, v)) in a.iter_mut().zip(&st.values).enumerate() {
                                    let updated = add(px, back, i, *v, in_front(t, i));
                                    work.add(receiver(i), updated);
                                }
                            }
                            Some(p) => {
                                for (i, (px, v)) in a.iter_mut().zip(&st.values).enumerate() {
                                    let before = *px;
                                    let front = in_front(t, i);
                                    let updated = add(px, back, i, *v, front);
                                    work.add(receiver(i), updated);
                                    if let Some(tap) = p.tap(t, i) {
                                        let e = tap
                                            .event()
                                            .primitive(
                                                PrimitiveKind::LightSample,
                                                k as u32,
                                                "",
                                                None,
                                            )
                                            .value("lit", (*v == 0 && front) as u8 as f64)
                                            .value("in_front", front as u8 as f64)
                                            .value("weight", w[0]);
                                        tap.push(e.read("stencil", Raw::U8(*v)));
                                        let e = tap.event().write(
                                            "accumulator",
                                            f64_bits(&before),
                                            f64_bits(px),
                                            Overflow::NonFinite,
                                            0,
                                        );
                                        tap.push(e.note(match (*v == 0, front) {
                                            (true, true) => {
                                                "stencil 0: the sample lights the pixel"
                                            }
                                            (true, false) => {
                                                "stencil 0, but the sample is behind the \
                                                 receiver's plane (horizon = integrate)"
                                            }
                                            (false, _) => "stencil ≠ 0: in the sample's shadow",
                                        }));
                                    }
                                }
                            }
                        }
                        work
                    })
                    .reduce(AccumulateWork::default, AccumulateWork::merged);
                pass.count(accumulated.counters());
            }
        }
    });
    let flat: Vec<[f64; 3]> = acc.into_iter().flatten().collect();
    let rows = tiling.to_row_major(&flat);
    let prims = frame.prim_ids();
    // `horizon = integrate`: where some samples fell behind the plane, the lit ones' share of
    // those in front, times the fraction of the light in front (module doc).
    let resolved: Option<Vec<[f64; 3]>> = planes.as_ref().map(|_| {
        let back = tiling.to_row_major(&behind.concat());
        let total = samples.iter().fold([0.0f64; 3], |sum, s| {
            [0, 1, 2].map(|ch| sum[ch] + f64::from(s.weight[ch]))
        });
        let (receivers, normals) = (frame.receivers(), frame.receiver_normals());
        (0..rows.len())
            .map(|i| match receivers[i] {
                Some(r) if back[i] != [0.0; 3] => {
                    let f: f64 =
                        shader_fraction_in_front(scene.light(), r.point.as_dvec3(), normals[i]);
                    in_front_share(rows[i], back[i], total, f)
                }
                _ => rows[i],
            })
            .collect()
    });
    let values = resolved.as_deref().unwrap_or(&rows);
    let to_f32 = |p: &[f64; 3]| p.map(|x| x.clamp(0.0, 1.0) as f32);
    let visibility = if colored {
        Visibility::Rgb(
            values
                .iter()
                .zip(prims)
                .map(|(p, id)| {
                    if *id == BACKGROUND {
                        [1.0; 3]
                    } else {
                        to_f32(p)
                    }
                })
                .collect(),
        )
    } else {
        Visibility::Gray(
            values
                .iter()
                .zip(prims)
                .map(|(p, id)| if *id == BACKGROUND { 1.0 } else { to_f32(p)[0] })
                .collect(),
        )
    };
    frame.probe_record("resolve", |tap, i| {
        tap.event()
            .read("accumulator", f64_bits(&rows[i]))
            .resolve(&visibility.channels(i), rows[i].iter().any(|v| *v > 1.0))
            .note(if prims[i] == BACKGROUND {
                "background: lit"
            } else if values[i] != rows[i] {
                "horizon = integrate: the fraction in front times the lit samples' weight over \
                 the weight of those in front, clamped to [0, 1], as f32"
            } else {
                "the lit samples' weights, clamped to [0, 1], as f32"
            })
    });
    let (visibility, horizon) = clip_to_horizon(&mut rec, horizon, visibility);
    rec.dump(|| {
        let channels = if colored { 3 } else { 1 };
        let sums = rows.iter().flat_map(|p| p[..channels].to_vec()).collect();
        BufferDump::new(
            "accumulator",
            "per pixel the f64 sum, in sample order, of the weights of the light samples whose \
             stencil count was 0 (Paper III §5.1); visibility = f32(clamp(sum, 0, 1)), \
             background 1",
            (scene.width, scene.height),
            ElementFormat::SumF64(channels as u32),
            DumpValues::F64(sums),
        )
        .with_events(EventMap::new(
            stencil_event_kind(settings.overflow),
            overflows,
            Vec::new(),
        ))
    });
    Ok(rec.finish(
        visibility,
        serde_json::json!({ "n": samples.len(), "pattern": "centered", "mode": mode.written(), "resolved": settings, "colored": colored, "horizon": horizon, "gpu": frame.gpu }),
    ))
}
