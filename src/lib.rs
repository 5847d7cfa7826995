//! penumbra — a deterministic, tile-based CPU rasterizer that reproduces the classic
//! real-time soft-shadow algorithms with each paper's exact buffer arithmetic.
//!
//! The crate is layered; dependency arrows point down:
//!
//! ```text
//! cli (main.rs) ─► report ─► render ─► methods ─► gpu, geometry, light ─► scene ─► limits
//!       │             │         └────► output, metrics
//!       └► progress   └────► experiment (results read back for the page)
//! ```
//!
//! See `../shared/DESIGN.md` for the bit-exactness contract the [`gpu`] module implements.

pub mod error;
pub mod experiment;
pub mod frame;
pub mod geometry;
pub mod golden;
pub mod gpu;
pub mod light;
pub mod limits;
pub mod memory;
pub mod methods;
pub mod metrics;
pub mod output;
pub mod plan;
pub mod progress;
pub mod render;
pub mod report;
pub mod scene;
