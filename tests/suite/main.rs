//! The integration tests, in one test binary (issue 30 item 6). Each module was its own
//! `tests/*.rs` binary until every one of them, linking the whole crate at the test profile's
//! opt-level 3, made `cargo test` spend most of its time building 28 executables; now the crate
//! is linked into one. A module holds the tests of one topic (its doc says which); run one with
//! `cargo test --test suite MODULE::`, e.g. `cargo test --test suite golden::`.
//!
//! The modules share one process and run in parallel, so no test may change what is global to
//! the process: no `std::env::set_var`, no `set_current_dir` (the tests that run the binary
//! give it a `current_dir`), no `rayon::ThreadPoolBuilder::build_global` (the thread-count
//! tests build their own pools and `install` them), no panic hook, and no fixed output path
//! (temporary directories are named by module, process id and a per-module counter). A test
//! that needs a process of its own goes in its own `tests/NAME.rs`, with the reason in its doc.
//!
//! proptest keeps the seeds of past failures in `tests/proptest-regressions/MODULE.txt`: its
//! default (`FileFailurePersistence::SourceParallel`) walks up from a module's file to the
//! directory holding `main.rs` and uses `proptest-regressions/` beside that directory.

// Helpers shared by several modules.
mod common;
mod independent_coverage;
mod sphere_hard_cases;

mod accuracy_time;
mod buffer_dumps;
mod cli_errors;
mod cost_growth;
mod dbuffer;
mod doc_references;
mod effects_plan;
mod fuzz_corpus_replay;
mod golden;
mod gpu_model;
mod hard_case_catalog;
mod hard_shadow_volumes;
mod hiz;
mod horizon_clip;
mod horizon_integrate;
mod multi_light;
mod optimized_ssv;
mod options;
mod penumbra_map;
mod penumbra_wedges;
mod penumbra_wedges_threads;
mod probe;
mod raster_properties;
mod real_model_catalog;
mod receiver_only;
mod reference_agreement;
mod report;
mod scene_loading;
mod shader_precision;
mod shader_precision_maps;
mod soft_shadow_volumes;
mod ssv_sphere;
mod wedge_blending;
mod wedge_continuity;
