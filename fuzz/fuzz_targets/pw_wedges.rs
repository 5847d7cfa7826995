//! Fuzzes Paper I/II penumbra wedge construction and light intensity on closed meshes under a
//! sphere light, in scenes that pass validation (see [`common::pw_wedges`]). It must never
//! panic.
#![no_main]

#[path = "common.rs"]
#[allow(dead_code)]
mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    common::pw_wedges(data);
});
