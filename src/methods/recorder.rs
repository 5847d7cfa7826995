//! The pass recorder: the one object a method's passes run through (issue 30, item 2;
//! `docs/architecture.md` "Passes").
//!
//! A method used to time each pass with its own `Instant`, sum the counters by hand, write a
//! [`PassStats`] literal per pass, list its buffers in a [`BufferPlan`] vector written apart
//! from the code that allocates them, and reach into the frame for the probe and the dump
//! flag. A [`PassRecorder`] holds all of that for one method run:
//!
//! * [`PassRecorder::pass`] runs one pass: it times it, hands the body a [`Pass`] that sums the
//!   pass's counters and owns its probe hook, and records the [`PassStats`] in execution order
//!   (the frame's scene pass first, as every method starts from it);
//! * [`PassRecorder::allocate`] allocates a buffer and records its [`BufferPlan`] in the same
//!   call, so the plan in `stats.json` is the list of what was allocated, in allocation order;
//!   [`PassRecorder::uses`] records a buffer the emulated GPU keeps on its own (the
//!   hierarchical Z's tile summaries);
//! * [`PassRecorder::dump`] keeps a buffer dump only when the frame asks for dumps, and
//!   [`PassRecorder::output`] keeps one of the method's ordinary outputs always;
//! * [`PassRecorder::finish`] builds the [`MethodOutput`]: the plan (the recorded passes and
//!   buffers, and the method's settings), the stats (totals summed over the passes) and the
//!   dumps.
//!
//! The plan's pass list is the recorded passes by name, with `×N` after a pass that ran N
//! times (`nsample`'s per-sample stencil pass).

use super::dump::BufferDump;
use super::output::{BufferPlan, MethodOutput, MethodPlan, MethodStats};
use crate::frame::Frame;
use crate::gpu::counters::Counters;
use crate::gpu::probe::{PassProbe, ProbeEvent, Tap};
use crate::pass::PassStats;
use crate::visibility::Visibility;
use std::time::Instant;

/// Records one method run on one frame (module doc).
pub struct PassRecorder<'f, 's> {
    frame: &'f Frame<'s>,
    method: &'static str,
    start: Instant,
    passes: Vec<PassStats>,
    buffers: Vec<BufferPlan>,
    dumps: Vec<BufferDump>,
    clamped_pixels: u64,
    warnings: Vec<String>,
}

/// One running pass (module doc): its counters, its probe hook and its dump hook.
pub struct Pass<'f, 's> {
    frame: &'f Frame<'s>,
    name: String,
    counters: Counters,
    runs: u64,
    dumps: Vec<BufferDump>,
    clamped_pixels: u64,
}

impl<'f, 's> Pass<'f, 's> {
    /// Add `c` to the pass's counters.
    pub fn count(&mut self, c: Counters) {
        self.counters += c;
    }

    /// Record that the pass ran `runs` times in all (its counters and time are the sum over
    /// the runs; `stats.json` and the plan show the count).
    pub fn set_runs(&mut self, runs: u64) {
        self.runs = runs;
    }

    /// The probe's view of this pass, when a probe is attached ([`crate::gpu::probe`]).
    pub fn probe(&self) -> Option<PassProbe<'f>> {
        self.frame.probe_pass(&self.name)
    }

    /// Record one event named `name` at the probed pixel ([`Frame::probe_record`]).
    pub fn record(&self, name: &str, event: impl FnOnce(Tap, usize) -> ProbeEvent) {
        self.frame.probe_record(name, event)
    }

    /// Keep the buffer dump `make` builds, when the frame asks for dumps; `make` is not called
    /// otherwise. The recorder hands the dumps back in the order the passes kept them.
    pub fn dump(&mut self, make: impl FnOnce() -> BufferDump) {
        if self.frame.dump_buffers {
            self.dumps.push(make());
        }
    }

    /// Add `n` pixels whose value the pass's resolve clamped into [0, 1] (what it computed
    /// there was outside).
    pub fn clamped(&mut self, n: u64) {
        self.clamped_pixels += n;
    }
}

impl<'f, 's> PassRecorder<'f, 's> {
    /// A recorder for `method` on `frame`, started now, holding the frame's scene pass and
    /// its depth buffer.
    pub fn new(frame: &'f Frame<'s>, method: &'static str) -> Self {
        Self {
            frame,
            method,
            start: Instant::now(),
            passes: vec![frame.pass.clone()],
            buffers: vec![BufferPlan::depth(&frame.gpu)],
            dumps: Vec::new(),
            clamped_pixels: 0,
            warnings: Vec::new(),
        }
    }

    /// The frame the method runs on.
    pub fn frame(&self) -> &'f Frame<'s> {
        self.frame
    }

    /// Run pass `name`: time `body`, hand it the [`Pass`] that sums its counters and owns its
    /// probe hook, and record its [`PassStats`] after the passes before it.
    pub fn pass<R>(&mut self, name: &str, body: impl FnOnce(&mut Pass<'f, 's>) -> R) -> R {
        let start = Instant::now();
        let mut pass = Pass {
            frame: self.frame,
            name: name.to_string(),
            counters: Counters::default(),
            runs: 1,
            dumps: Vec::new(),
            clamped_pixels: 0,
        };
        let out = body(&mut pass);
        self.dumps.append(&mut pass.dumps);
        self.clamped_pixels += pass.clamped_pixels;
        self.passes.push(PassStats {
            name: pass.name,
            wall_seconds: start.elapsed().as_secs_f64(),
            runs: pass.runs,
            counters: pass.counters,
        });
        out
    }

    /// Run pass `name` once more: a pass a method runs once per silhouette, between its other
    /// passes (`wedge-blending`). Like [`Self::pass`] the first time; later runs add their
    /// time and counters to that entry and count one more run.
    pub fn pass_again<R>(&mut self, name: &str, body: impl FnOnce(&mut Pass<'f, 's>) -> R) -> R {
        let earlier = self.passes.iter().skip(1).position(|p| p.name == name);
        let out = self.pass(name, body);
        if let Some(k) = earlier {
            let run = self.passes.pop().expect("the pass just recorded");
            let entry = &mut self.passes[k + 1];
            entry.wall_seconds += run.wall_seconds;
            entry.runs += run.runs;
            entry.counters += run.counters;
        }
        out
    }

    /// Run `body` with a recorder of its own for `method` on `frame`, and hand back its result
    /// with the passes it recorded after the frame's scene pass (a method's typed `render`,
    /// which the tests read, over its `render_with`).
    pub fn record_alone<R, E>(
        frame: &'f Frame<'s>,
        method: &'static str,
        body: impl FnOnce(&mut Self) -> Result<R, E>,
    ) -> Result<(R, Vec<PassStats>), E> {
        let mut rec = Self::new(frame, method);
        let r = body(&mut rec)?;
        Ok((r, rec.passes.split_off(1)))
    }

    /// Record a pass that was run elsewhere and handed back its stats (a building block shared
    /// by methods, or a method run inside another one), after the passes before it.
    pub fn record_pass(&mut self, stats: PassStats) {
        self.passes.push(stats);
    }

    /// Add `c` to the frame's scene pass, the first pass recorded: the work of a render target
    /// the scene pass writes only for this method (the receiver normals of `horizon = clip`,
    /// [`crate::methods::horizon_clip`]), counted only in the runs that read it.
    pub fn count_in_scene_pass(&mut self, c: Counters) {
        self.passes[0].counters += c;
    }

    /// Allocate a buffer with `alloc` and record `plan` for it, in allocation order.
    pub fn allocate<B>(&mut self, plan: BufferPlan, alloc: impl FnOnce() -> B) -> B {
        self.buffers.push(plan);
        alloc()
    }

    /// Record a buffer the emulated GPU keeps on its own for the method's passes (the
    /// hierarchical Z's per-tile summaries, a shared building block's target).
    pub fn uses(&mut self, plan: BufferPlan) {
        self.buffers.push(plan);
    }

    /// Record the hierarchical Z's per-tile zmin/zmax of the scene depth
    /// ([`BufferPlan::hiz_zmin_zmax`]) when the frame's GPU has the unit on.
    pub fn uses_hiz_depth(&mut self) {
        if self.frame.gpu.hiz {
            self.uses(BufferPlan::hiz_zmin_zmax(&self.frame.gpu));
        }
    }

    /// The bytes of the buffers recorded so far at the frame's pixel count.
    pub fn buffer_bytes(&self) -> u64 {
        let pixels = self.frame.pixel_count() as u64;
        self.buffers
            .iter()
            .map(|b| b.bytes_per_sample as u64 * pixels)
            .sum()
    }

    /// Whether the frame asks for every buffer the method resolved (`--dump-buffers`).
    pub fn dumping(&self) -> bool {
        self.frame.dump_buffers
    }

    /// Keep the buffer dump `make` builds, when the frame asks for dumps; `make` is not called
    /// otherwise.
    pub fn dump(&mut self, make: impl FnOnce() -> BufferDump) {
        if self.frame.dump_buffers {
            self.dumps.push(make());
        }
    }

    /// Keep the buffer dumps `make` builds, when the frame asks for dumps ([`Self::dump`]).
    pub fn dump_all(&mut self, make: impl FnOnce() -> Vec<BufferDump>) {
        if self.frame.dump_buffers {
            self.dumps.extend(make());
        }
    }

    /// Keep `dump`, one of the method's ordinary outputs (always handed back).
    pub fn output(&mut self, dump: BufferDump) {
        self.dumps.push(dump);
    }

    /// Add `n` pixels whose value the final resolve clamped into [0, 1].
    pub fn clamped(&mut self, n: u64) {
        self.clamped_pixels += n;
    }

    /// Add a warning for the user (`stats.json` and under the table).
    pub fn warn(&mut self, warning: String) {
        self.warnings.push(warning);
    }

    /// The method's output: `visibility`, the dumps kept, and the stats with the plan of the
    /// recorded passes and buffers and `settings`.
    pub fn finish(self, visibility: Visibility, settings: serde_json::Value) -> MethodOutput {
        let plan = MethodPlan {
            method: self.method.into(),
            passes: self
                .passes
                .iter()
                .map(|p| match p.runs {
                    1 => p.name.clone(),
                    n => format!("{} ×{n}", p.name),
                })
                .collect(),
            buffers: self.buffers,
            settings,
        };
        let mut totals = Counters::default();
        for p in &self.passes {
            totals += p.counters;
        }
        let gpu_model = crate::gpu_model::estimate(self.frame.gpu.model.profile(), &self.passes);
        let stats = MethodStats {
            gpu_model,
            method: self.method.into(),
            width: self.frame.scene.width,
            height: self.frame.scene.height,
            wall_seconds: self.start.elapsed().as_secs_f64(),
            plan: serde_json::to_value(&plan).unwrap_or(serde_json::Value::Null),
            passes: self.passes,
            totals,
            warnings: self.warnings,
            clamped_pixels: self.clamped_pixels,
            meshes: self
                .frame
                .scene
                .meshes
                .iter()
                .map(crate::scene::repair::MeshReport::of)
                .collect(),
        };
        MethodOutput {
            visibility,
            dumps: self.dumps,
            stats,
        }
    }
}
