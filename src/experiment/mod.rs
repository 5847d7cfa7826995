//! Experiments that sweep a parameter and report counters (DESIGN.md "report/": sweeps,
//! CSV, plots).

pub mod tile_size;
pub mod wedge_blending;
