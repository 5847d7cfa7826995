//! Fuzzes `parse_scene_str` on arbitrary UTF-8 as TOML scene text, with OBJ and texture
//! paths resolved in a temporary directory holding the shipped models (see
//! [`common::scene`]). It must never panic.
#![no_main]

#[path = "common.rs"]
#[allow(dead_code)]
mod common;

use libfuzzer_sys::fuzz_target;
use penumbra::scene::file::Format;

fuzz_target!(|data: &[u8]| {
    common::scene(data, Format::Toml, common::fuzz_scene_dir());
});
