//! Fuzzes triangle setup, binning and traversal with arbitrary clip-space triangles, finite
//! or not, on a 32×32 image (see [`common::raster`]). It must never panic.
#![no_main]

#[path = "common.rs"]
#[allow(dead_code)]
mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    common::raster(data);
});
