//! The record of one pass of the emulated GPU: its name, how many times it ran, its wall time
//! and its counters summed over tiles and runs ([`crate::gpu::counters`]), as `stats.json`
//! lists it. Below the frame (whose scene pass is one) and the methods.

use crate::gpu::counters::Counters;
use serde::Serialize;

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
