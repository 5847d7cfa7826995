//! Fuzzes Paper IV's tight wedge of one edge, its halves and convex polyhedron clipping, and
//! checks that the wedge holds the edge's penumbra and all of its coverage (see
//! [`common::tight_wedge`]). It must never panic.
#![no_main]

#[path = "common.rs"]
#[allow(dead_code)]
mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    common::tight_wedge(data);
});
