//! Fuzzes `parse_scene_str` on arbitrary UTF-8 as JSON scene text, with OBJ and texture
//! paths resolved in a temporary directory holding the shipped models (see
//! [`common::scene`]). It must never panic.
#![no_main]

#[path = "common.rs"]
#[allow(dead_code)]
mod common;

use libfuzzer_sys::fuzz_target;
use penumbra::scene::file::Format;
use std::path::PathBuf;
use std::sync::OnceLock;

/// The scene directory, made once per process under the system temp directory.
fn base_dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let root = std::env::temp_dir().join(format!("penumbra-fuzz-{}", std::process::id()));
        common::populate_scene_dir(&root).expect("cannot create the fuzz scene directory")
    })
}

fuzz_target!(|data: &[u8]| {
    common::scene(data, Format::Json, base_dir());
});
