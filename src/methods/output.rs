//! What every method hands back: a visibility buffer in [0, 1] (`docs/architecture.md` "Methods":
//! all methods are compared on the same footing), its buffers for inspection
//! ([`super::dump`]), and the stats that go into `stats.json`.

use super::dump::BufferDump;
use crate::gpu::counters::Counters;
use crate::pass::PassStats;
use crate::visibility::Visibility;
use serde::Serialize;

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
    /// The passes' modeled time on the GPU profile `[options.gpu] model` ([`crate::gpu_model`]):
    /// a model, not a measurement.
    pub gpu_model: crate::gpu_model::FrameEstimate,
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

/// One buffer a pass uses.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BufferPlan {
    /// Buffer name.
    pub name: String,
    /// Storage format, e.g. `D24`, `S8`, `f64x3 accumulator`.
    pub format: String,
    /// Bytes per sample.
    pub bytes_per_sample: u32,
}

impl BufferPlan {
    /// The hierarchical-Z unit's per-tile zmin and zmax of the scene depth
    /// ([`crate::gpu::hiz`]): two values in the depth format per tile, as whole bytes per
    /// sample rounded up.
    pub fn hiz_zmin_zmax(gpu: &crate::frame::GpuSettings) -> Self {
        Self::zmin_zmax("", gpu.depth, gpu.hiz_tile_size)
    }

    /// [`BufferPlan::hiz_zmin_zmax`] of a depth target seen from the light (`target`, e.g.
    /// "shadow map": its early Z, [`crate::gpu::light_view::LightView::render_depth`]),
    /// in its `depth` format with HiZ tiles of edge `hiz_tile`.
    pub fn hiz_zmin_zmax_of(
        target: &str,
        depth: crate::gpu::depth::DepthFormat,
        hiz_tile: u32,
    ) -> Self {
        Self::zmin_zmax(&format!(" of the {target}"), depth, hiz_tile)
    }

    fn zmin_zmax(of: &str, depth: crate::gpu::depth::DepthFormat, hiz_tile: u32) -> Self {
        Self {
            name: format!("tile zmin/zmax{of} (2 per {hiz_tile}×{hiz_tile} HiZ tile)"),
            format: format!("{depth:?}"),
            bytes_per_sample: (2 * depth.bytes() as u32).div_ceil(hiz_tile * hiz_tile),
        }
    }

    /// The hierarchical-Z unit's per-tile stencil summary (`ssv-optimized`: the last half
    /// that marked the tile, [`crate::gpu::hiz`]): one byte per tile, as whole bytes per
    /// sample rounded up.
    pub fn hiz_stencil_summary(gpu: &crate::frame::GpuSettings) -> Self {
        Self {
            name: format!("tile stencil summary (1 per {0}×{0} tile)", gpu.tile_size),
            format: "u8".into(),
            bytes_per_sample: 1u32.div_ceil(gpu.tile_size * gpu.tile_size),
        }
    }

    /// The hierarchical-Z unit's per-tile receiver bounds ([`crate::gpu::hiz::TileReceiverBounds`]):
    /// six f32 per tile and per block of tiles, as whole bytes per sample rounded up.
    pub fn hiz_receiver_bounds(gpu: &crate::frame::GpuSettings) -> Self {
        let tile_len = gpu.tile_size * gpu.tile_size;
        Self {
            name: format!(
                "tile receiver bounds (6 per {0}×{0} tile and per {1}×{1} tiles)",
                gpu.tile_size,
                crate::gpu::hiz::BLOCK_TILES
            ),
            format: "f32x6".into(),
            bytes_per_sample: (crate::gpu::hiz::TileReceiverBounds::READ_BYTES as u32)
                .div_ceil(tile_len),
        }
    }

    /// The frame's scene depth buffer, in the format the frame uses.
    pub fn depth(gpu: &crate::frame::GpuSettings) -> Self {
        Self {
            name: "depth".into(),
            format: format!("{:?}", gpu.depth),
            bytes_per_sample: gpu.depth.bytes() as u32,
        }
    }

    /// A depth target named `name` (a shadow map, a map's depth channel) in `format`.
    pub fn depth_target(name: String, format: crate::gpu::depth::DepthFormat) -> Self {
        Self {
            name,
            format: format!("{format:?}"),
            bytes_per_sample: format.bytes() as u32,
        }
    }

    /// A colour target named `name` with `channels` channels, each in `format`.
    pub fn color_target(
        name: String,
        format: crate::gpu::color::ColorFormat,
        channels: u32,
    ) -> Self {
        Self {
            name,
            format: format!("{format:?}"),
            bytes_per_sample: channels * format.bytes() as u32,
        }
    }

    /// An 8-bit stencil buffer.
    pub fn stencil8() -> Self {
        Self {
            name: "stencil".into(),
            format: "S8".into(),
            bytes_per_sample: 1,
        }
    }
}

/// What one method will do for this frame.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MethodPlan {
    /// Method name.
    pub method: String,
    /// Pass names in execution order.
    pub passes: Vec<String>,
    /// Buffers allocated.
    pub buffers: Vec<BufferPlan>,
    /// Method settings after option parsing and automatic decisions.
    pub settings: serde_json::Value,
}
