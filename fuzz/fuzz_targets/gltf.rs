//! Fuzzes the glTF path: `parse_mesh` as glTF or GLB on arbitrary bytes, then the welded
//! mesh through the `obj` path's geometry (see [`common::gltf`]). It must never panic.
#![no_main]

#[path = "common.rs"]
#[allow(dead_code)]
mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    common::gltf(data);
});
