//! Fuzzes the OBJ path: `parse_mesh` as OBJ on arbitrary bytes, then the welded mesh through
//! adjacency, silhouettes, loops, shadow volumes and their rasterization (see [`common::obj`]).
//! It must never panic.
#![no_main]

#[path = "common.rs"]
#[allow(dead_code)]
mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    common::obj(data);
});
