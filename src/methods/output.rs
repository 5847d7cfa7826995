//! What every method hands back: a visibility buffer in [0, 1] (`docs/architecture.md` "Methods":
//! all methods are compared on the same footing), its buffers for inspection
//! ([`super::dump`]), and the stats that go into `stats.json`.

use super::dump::BufferDump;
use crate::gpu::counters::Counters;
use serde::Serialize;

/// Per-pixel visibility of the light, row 0 at the top, row-major.
#[derive(Debug, Clone, PartialEq)]
pub enum Visibility {
    /// One value per pixel in [0, 1].
    Gray(Vec<f32>),
    /// One value per pixel and RGB channel in [0, 1] (textured/coloured lights).
    Rgb(Vec<[f32; 3]>),
}

impl Visibility {
    /// Number of pixels.
    pub fn len(&self) -> usize {
        match self {
            Visibility::Gray(v) => v.len(),
            Visibility::Rgb(v) => v.len(),
        }
    }

    /// True when there are no pixels.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The visibility of pixel `i` as RGB (gray replicated).
    pub fn rgb(&self, i: usize) -> [f32; 3] {
        match self {
            Visibility::Gray(v) => [v[i]; 3],
            Visibility::Rgb(v) => v[i],
        }
    }

    /// The visibility of pixel `i` per stored channel: one value for gray, three for RGB.
    pub fn channels(&self, i: usize) -> Vec<f32> {
        match self {
            Visibility::Gray(v) => vec![v[i]],
            Visibility::Rgb(v) => v[i].to_vec(),
        }
    }

    /// The visibility of pixel `i` as one value (RGB averaged with equal weights).
    pub fn gray(&self, i: usize) -> f32 {
        match self {
            Visibility::Gray(v) => v[i],
            Visibility::Rgb(v) => (v[i][0] + v[i][1] + v[i][2]) / 3.0,
        }
    }
}

/// Time and counters of one pass.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PassStats {
    /// The pass name, e.g. `scene-depth`, `shadow-volume-zpass`, `sample-17` (summed per kind).
    pub name: String,
    /// Wall-clock seconds the pass took (informational; never decides a test).
    pub wall_seconds: f64,
    /// How many times the pass ran (e.g. N for the per-sample passes of `nsample`).
    pub runs: u64,
    /// Counters summed over all tiles and runs.
    pub counters: Counters,
}

impl PassStats {
    /// The stats of one run of pass `name` that started at `start` with `counters`.
    pub fn since(name: &str, start: std::time::Instant, counters: Counters) -> Self {
        Self {
            name: name.into(),
            wall_seconds: start.elapsed().as_secs_f64(),
            runs: 1,
            counters,
        }
    }
}

/// Everything `stats.json` holds for one method.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MethodStats {
    /// The method name.
    pub method: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Wall-clock seconds of the whole method (informational).
    pub wall_seconds: f64,
    /// The frame plan: passes and buffers used, as JSON.
    pub plan: serde_json::Value,
    /// Per-pass time and counters, in execution order.
    pub passes: Vec<PassStats>,
    /// Counters summed over all passes.
    pub totals: Counters,
    /// What the user must know about this result (e.g. a paper's limit the scene runs into),
    /// one sentence each; printed under the table.
    pub warnings: Vec<String>,
    /// Pixels whose value the method's final resolve had to clamp into [0, 1] (what it
    /// computed there was outside); 0 for methods whose result cannot leave [0, 1]. Summed over
    /// the lights of a scene with several lights.
    pub clamped_pixels: u64,
    /// Each mesh of the scene: its name, triangle count and what repair changed
    /// ([`crate::scene::repair::MeshReport`]), so that a result names the geometry it saw.
    pub meshes: Vec<crate::scene::repair::MeshReport>,
}

/// The result of running one method on one scene.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodOutput {
    /// Visibility in [0, 1].
    pub visibility: Visibility,
    /// The method's buffers as it resolved them ([`super::dump`]): those of its ordinary
    /// outputs (e.g. `hard-sv`'s stencil) always, every other one only when the frame asks
    /// for dumps ([`crate::frame::Frame::dump_buffers`]).
    pub dumps: Vec<BufferDump>,
    /// Stats for `stats.json`.
    pub stats: MethodStats,
}
