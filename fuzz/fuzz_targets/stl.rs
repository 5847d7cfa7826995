//! Fuzzes the STL path: `parse_mesh` as STL (ASCII or binary) on arbitrary bytes, then the welded
//! mesh through the `obj` path's geometry (see [`common::stl`]). It must never panic.
#![no_main]

#[path = "common.rs"]
#[allow(dead_code)]
mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    common::stl(data);
});
