//! Fuzzes the coverage of a rectangle or a sphere light by one edge's hard shadow quad: exact
//! clipping, projected edges, radial parts, coverage texture lookups and `ssv-optimized`'s
//! modes (see [`common::coverage`]). It must never panic.
#![no_main]

#[path = "common.rs"]
#[allow(dead_code)]
mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    common::coverage(data);
});
