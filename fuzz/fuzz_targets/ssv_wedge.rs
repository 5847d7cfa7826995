//! Fuzzes Paper III's penumbra wedge of one edge under a rectangle or a sphere light, and
//! checks that it holds the edge's penumbra and all of its coverage (see
//! [`common::ssv_wedge`]). It must never panic.
#![no_main]

#[path = "common.rs"]
#[allow(dead_code)]
mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    common::ssv_wedge(data);
});
