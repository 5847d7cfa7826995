//! Memory-traffic and work counters (`docs/architecture.md` "Counters"; Paper II §7 counts depth
//! reads and stencil/LI writes per tile size, Paper III §5.2 counts depth and V-buffer/stencil
//! bytes).
//!
//! Every buffer access goes through the typed buffers in [`super::buffers`], which add to a
//! tile-local `Counters`; tiles' counters are summed after a pass. Integer sums do not depend
//! on the order tiles finish in, so counters are as deterministic as the images.
//! Every count goes through the crate-private macro `count!`. Counting is on in every normal
//! build (the cargo feature `counters`, a default feature): one integer add per access into a
//! tile-local struct that lives in L1. Built with `--no-default-features`, every count compiles to
//! nothing and every counter reads 0 — a build that exists only to measure what counting
//! costs (`docs/architecture.md` "Counters"); its goldens, tests and traffic columns are
//! meaningless.

use serde::Serialize;
use std::ops::AddAssign;

/// Adds to a counter: `count!(c.depth_read_bytes += n)`. With the cargo feature `counters`
/// off the statement is type-checked but never runs (module doc).
macro_rules! count {
    ($($add:tt)+) => {
        if cfg!(feature = "counters") {
            $($add)+;
        }
    };
}
pub(crate) use count;

/// Counters of one pass (or of a whole frame, once summed). Bytes are counted at the
/// storage size of the emulated format (D24 = 3 bytes, stencil = 1, LI16 = 2, …).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Counters {
    /// Triangles submitted to setup.
    pub triangles_submitted: u64,
    /// Triangles dropped by setup: zero area, culled by facing, or clipped away entirely.
    pub triangles_dropped: u64,
    /// Triangles produced by clipping that reached rasterization.
    pub triangles_rasterized: u64,
    /// (triangle, tile) pairs visited by traversal.
    pub tiles_visited: u64,
    /// (tile, triangle) pairs rejected by the hierarchical-Z unit before any fragment was
    /// made: a zmin/zmax test, or a wedge's planes against the tile's receiver bounds
    /// ([`crate::gpu::hiz::TileReceiverBounds`]).
    pub tiles_culled_hiz: u64,
    /// Samples that passed the coverage test (fragments generated).
    pub fragments_rasterized: u64,
    /// Fragments that ran a fragment shader (method-specific per-pixel work).
    pub fragments_shaded: u64,
    /// Fragments that passed the depth test.
    pub depth_passed: u64,
    /// Depth-buffer reads, in bytes.
    pub depth_read_bytes: u64,
    /// Depth-buffer writes, in bytes.
    pub depth_write_bytes: u64,
    /// Stencil-buffer reads, in bytes.
    pub stencil_read_bytes: u64,
    /// Stencil-buffer writes, in bytes.
    pub stencil_write_bytes: u64,
    /// Colour/LI/V-buffer reads, in bytes (blending reads the destination).
    pub color_read_bytes: u64,
    /// Colour/LI/V-buffer writes, in bytes.
    pub color_write_bytes: u64,
    /// Hierarchical-Z reads (a tile's zmin/zmax, or its receiver bounds), in bytes at the
    /// storage size of the values read.
    pub hiz_read_bytes: u64,
    /// Writes whose value over- or underflowed the storage format (wrapped or saturated).
    pub overflow_events: u64,
    /// Fragment-program ALU instruction slots executed ([`super::shader_ops`], its table).
    pub shader_alu_ops: u64,
    /// Fragment-program transcendental functions executed (`atan2`, `acos`, `tan`: no
    /// instruction of the papers' GPUs; the cost model prices each as an assumption).
    pub shader_transcendentals: u64,
    /// Fragment-program texture samples.
    pub shader_fetches: u64,
    /// Fragments a fragment program killed (discarded) before they wrote.
    pub shader_discards: u64,
    /// The most instruction slots (ALU + fetches) one fragment-program invocation executed:
    /// a maximum, not a sum, when counters are added.
    pub shader_max_slots: u64,
}

impl Counters {
    /// Total buffer traffic in bytes (depth + stencil + colour, reads and writes, and the
    /// hierarchical-Z reads).
    pub fn total_bytes(&self) -> u64 {
        self.hiz_read_bytes
            + self.depth_read_bytes
            + self.depth_write_bytes
            + self.stencil_read_bytes
            + self.stencil_write_bytes
            + self.color_read_bytes
            + self.color_write_bytes
    }

    /// [`Counters::total_bytes`] in MB (10⁶ bytes), as tables show it.
    pub fn total_mb(&self) -> f64 {
        self.total_bytes() as f64 / 1e6
    }
}

impl AddAssign for Counters {
    fn add_assign(&mut self, o: Counters) {
        self.triangles_submitted += o.triangles_submitted;
        self.triangles_dropped += o.triangles_dropped;
        self.triangles_rasterized += o.triangles_rasterized;
        self.tiles_visited += o.tiles_visited;
        self.tiles_culled_hiz += o.tiles_culled_hiz;
        self.fragments_rasterized += o.fragments_rasterized;
        self.fragments_shaded += o.fragments_shaded;
        self.depth_passed += o.depth_passed;
        self.depth_read_bytes += o.depth_read_bytes;
        self.depth_write_bytes += o.depth_write_bytes;
        self.stencil_read_bytes += o.stencil_read_bytes;
        self.stencil_write_bytes += o.stencil_write_bytes;
        self.color_read_bytes += o.color_read_bytes;
        self.color_write_bytes += o.color_write_bytes;
        self.hiz_read_bytes += o.hiz_read_bytes;
        self.overflow_events += o.overflow_events;
        self.shader_alu_ops += o.shader_alu_ops;
        self.shader_transcendentals += o.shader_transcendentals;
        self.shader_fetches += o.shader_fetches;
        self.shader_discards += o.shader_discards;
        self.shader_max_slots = self.shader_max_slots.max(o.shader_max_slots);
    }
}
