//! penumbra — a deterministic, tile-based CPU rasterizer that reproduces the classic
//! real-time soft-shadow algorithms with each paper's exact buffer arithmetic.
//!
//! The crate is layered; dependency arrows point down, floor by floor (a module uses only
//! modules on floors below its own; the test in `src/module_graph.rs` fails on a cycle):
//!
//! ```text
//! cli (main.rs)
//!   report · probe · golden       the HTML page, one pixel explained, the bit-exact goldens
//!   experiment                    sweeps: tile size, wedge blending, accuracy–time, precision
//!   render · memory               one scene with its methods, in memory; the memory estimate
//!   output                        the files of a run, all or nothing
//!   methods                       one module per paper, the registry
//!   frame · metrics               the scene depth pass; image error against the reference
//!   geometry                      silhouettes, volumes, wedges, cones; the z-fail decision
//!   light                         coverage of a light, samples, lookup tables
//!   gpu · pass · options          the emulated pipeline; a pass's record; option tables
//!   scene                         the scene, its meshes and their adjacency, validation
//!   error · limits · visibility · drawing · progress
//! ```
//!
//! # Example
//!
//! Render a built-in scene at 32×32 and run one soft-shadow method on it:
//!
//! ```
//! use penumbra::frame::{Frame, GpuSettings};
//! use penumbra::methods;
//! use penumbra::visibility::Visibility;
//! use penumbra::scene::builtin;
//!
//! // A square occluder above a floor under a rectangular light (`penumbra list` names them all).
//! let mut scene = builtin::load("single-quad").expect("a built-in scene");
//! scene.resize(Some(32), Some(32));
//!
//! // The shared first pass: scene depth (D24, 8×8 tiles), the visible triangle per pixel and
//! // the hierarchical Z that every method reads.
//! let frame = Frame::render(&scene, GpuSettings::default())?;
//!
//! // Paper III's soft shadow volumes on that frame; any name of `methods::ALL` works.
//! let out = methods::run("ssv", &frame)?;
//! let Visibility::Gray(v) = &out.visibility else {
//!     unreachable!("a single-colour light gives one value per pixel")
//! };
//! assert_eq!(v.len(), 32 * 32); // row-major, row 0 at the top
//! assert!(v.iter().all(|x| (0.0..=1.0).contains(x)));
//! assert!(v.contains(&1.0) && v.iter().any(|&x| x < 1.0)); // lit and shadowed pixels
//!
//! // What the passes cost on the emulated GPU, as `stats.json` reports it.
//! assert!(out.stats.totals.total_bytes() > 0);
//! # Ok::<(), penumbra::error::InputError>(())
//! ```
//!
//! Documentation beyond the API: `docs/architecture.md` (the flow of one frame, the
//! bit-exactness contract the [`gpu`] module implements, the tests, and where each paper lives
//! in the code) and `docs/papers.md` (the full reference of every paper cited as "Paper III
//! §3.2.2" and so on).

#![forbid(unsafe_code)]
#![warn(missing_docs)]

// The library's API (issue 30, item 4): what a user needs to load a scene, render its methods
// and read the results, re-exported here; `examples/library.rs` uses only these. The modules
// below stay public for the project's own tests, benches, fuzz targets and experiments, which
// reach the emulated GPU's internals (`docs/architecture.md` "The public API").
pub use error::InputError;
pub use gpu::counters::Counters;
pub use methods::dump::BufferDump;
pub use methods::output::{BufferPlan, MethodOutput, MethodPlan, MethodStats};
pub use metrics::error_report::ErrorReport;
pub use metrics::ErrorStats;
pub use pass::PassStats;
pub use render::{render_scene, render_scene_dumping, MethodRun};
pub use scene::file::{load_scene_file, parse_scene_str, resolve as load_scene, Format};
pub use scene::Scene;
pub use visibility::Visibility;

/// The names of every method, in the registry's order ([`methods::ALL`]): what
/// [`Scene::methods`] may list.
pub fn method_names() -> impl Iterator<Item = &'static str> {
    methods::names()
}

pub mod drawing;
pub mod error;
pub mod experiment;
pub mod export;
pub mod frame;
pub mod geometry;
pub mod golden;
pub mod gpu;
pub mod gpu_model;
pub mod light;
pub mod limits;
pub mod memory;
pub mod methods;
pub mod metrics;
#[cfg(test)]
mod module_graph;
pub mod options;
pub mod output;
pub mod pass;
pub mod primitives;
pub mod probe;
pub mod progress;
pub mod render;
pub mod report;
pub mod scene;
pub mod visibility;
