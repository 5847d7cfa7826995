//! The on-disk cache of coverage textures ([`crate::light::coverage_texture`]): a texture is
//! computed once per machine, not once per process. Building the n = 32 RGB texture of a
//! textured light takes seconds and n = 64 much longer; a cached one loads in milliseconds.
//!
//! # Where
//! `$PENUMBRA_CACHE_DIR` when set (set it empty to turn the disk cache off), else
//! `penumbra/` under the platform cache directory (`$XDG_CACHE_HOME` or `~/.cache` on Linux,
//! `~/Library/Caches` on macOS, the local app-data folder on Windows). No directory, no
//! cache: textures are then computed as before.
//!
//! # What a file holds
//! `coverage-n{n}-{grey|rgb}-{fingerprint:08x}.bin`: the magic `PNBRCT01`, then the whole key
//! (length-prefixed), the texels (length-prefixed), and a CRC-32 of everything before it. The
//! key is the exact input of the computation: a fingerprint of the source of the modules that
//! compute a texture (so a changed computation never reads a file an older build wrote), `n`,
//! and the light texture's f32 bits for textured lights.
//!
//! # Safety
//! A file is used only if its magic, lengths, checksum and entire key match; anything else
//! (a truncated, corrupt or foreign file, an unreadable directory) counts as a miss: the
//! texture is computed and the file written again. Writers never expose a partial file: each
//! writes a temporary file with a name unique to the process and the call, then renames it over
//! the final name (atomic within a directory), so concurrent writers of one key leave one
//! complete file and readers see the old or the new one. A failed write only costs the next
//! process the computation; it never changes a result.

use crate::light::coverage_texture::{CoverageTexture, CoverageTextureKey};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;

/// First bytes of every cache file (format version 01).
const MAGIC: &[u8; 8] = b"PNBRCT01";

/// The source of the computation a cached texture depends on (module doc, "What a file
/// holds").
const COMPUTATION_SOURCE: [&[u8]; 2] = [
    include_bytes!("coverage_texture.rs"),
    include_bytes!("coverage.rs"),
];

/// CRC-32 of [`COMPUTATION_SOURCE`], computed once.
fn source_fingerprint() -> u32 {
    static FP: OnceLock<u32> = OnceLock::new();
    *FP.get_or_init(|| {
        let mut h = crc32fast::Hasher::new();
        for s in COMPUTATION_SOURCE {
            h.update(s);
        }
        h.finalize()
    })
}

/// The cache directory (module doc, "Where"), or `None` when there is none or it is off.
pub fn cache_dir() -> Option<PathBuf> {
    match std::env::var_os("PENUMBRA_CACHE_DIR") {
        Some(d) if d.is_empty() => None,
        Some(d) => Some(PathBuf::from(d)),
        None => dirs::cache_dir().map(|d| d.join("penumbra")),
    }
}

/// The exact input of a texture as bytes (module doc).
fn key_bytes(key: &CoverageTextureKey) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend_from_slice(&source_fingerprint().to_le_bytes());
    b.extend_from_slice(&key.n.to_le_bytes());
    match &key.light_texels {
        None => b.push(0),
        Some(texels) => {
            b.push(1);
            for t in texels {
                for c in t {
                    b.extend_from_slice(&c.to_le_bytes());
                }
            }
        }
    }
    b
}

/// The file of `key` in `dir`.
pub fn file_of(dir: &Path, key: &CoverageTextureKey) -> PathBuf {
    let kind = if key.light_texels.is_some() {
        "rgb"
    } else {
        "grey"
    };
    let fp = crc32fast::hash(&key_bytes(key));
    dir.join(format!("coverage-n{}-{kind}-{fp:08x}.bin", key.n))
}

/// The cached texture of `key` in `dir`, if a valid file holds it (module doc, "Safety").
pub fn load(dir: &Path, key: &CoverageTextureKey) -> Option<CoverageTexture> {
    let bytes = std::fs::read(file_of(dir, key)).ok()?;
    let body_len = bytes.len().checked_sub(4)?;
    let (body, crc) = bytes.split_at(body_len);
    if crc32fast::hash(body).to_le_bytes() != crc {
        return None;
    }
    let rest = body.strip_prefix(MAGIC.as_slice())?;
    let (stored_key, rest) = length_prefixed(rest)?;
    if stored_key != key_bytes(key).as_slice() {
        return None;
    }
    let (texels, rest) = length_prefixed(rest)?;
    let channels: u32 = if key.light_texels.is_some() { 3 } else { 1 };
    let expected = (key.n as usize).pow(4) * channels as usize;
    (rest.is_empty() && texels.len() == expected).then(|| CoverageTexture {
        n: key.n,
        channels,
        texels: texels.to_vec(),
    })
}

/// Splits a `u64` little-endian length and that many bytes off `b`.
fn length_prefixed(b: &[u8]) -> Option<(&[u8], &[u8])> {
    let (len, rest) = b.split_first_chunk::<8>()?;
    let len = usize::try_from(u64::from_le_bytes(*len)).ok()?;
    (rest.len() >= len).then(|| rest.split_at(len))
}

/// Writes `texture` as the cached texture of `key` into `dir` (created if missing): a
/// temporary file, then a rename (module doc, "Safety"). Errors are returned for the caller
/// to ignore or report; no partial file is ever left under the final name.
pub fn store(
    dir: &Path,
    key: &CoverageTextureKey,
    texture: &CoverageTexture,
) -> std::io::Result<()> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    std::fs::create_dir_all(dir)?;
    let target = file_of(dir, key);
    let key = key_bytes(key);
    let mut body = Vec::with_capacity(MAGIC.len() + 16 + key.len() + texture.texels.len() + 4);
    body.extend_from_slice(MAGIC);
    body.extend_from_slice(&(key.len() as u64).to_le_bytes());
    body.extend_from_slice(&key);
    body.extend_from_slice(&(texture.texels.len() as u64).to_le_bytes());
    body.extend_from_slice(&texture.texels);
    let crc = crc32fast::hash(&body);
    body.extend_from_slice(&crc.to_le_bytes());
    let tmp = dir.join(format!(
        ".{}.tmp-{}-{}",
        target
            .file_name()
            .map_or("coverage".into(), |n| n.to_string_lossy()),
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let written = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(&body)?;
        f.sync_all()?;
        std::fs::rename(&tmp, &target)
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::coverage_texture::load_or_compute;
    use crate::scene::RgbTexture;

    fn temp_dir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!(
            "penumbra-texture-cache-{tag}-{}",
            std::process::id()
        ));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    fn textured_key() -> CoverageTextureKey {
        let texture = RgbTexture {
            width: 2,
            height: 1,
            texels: vec![[1.0, 0.5, 0.0], [0.25, 1.0, 2.0]],
            source: "test".into(),
        };
        CoverageTextureKey::textured(8, &texture)
    }

    /// A stored texture loads back bit for bit, for a grey and an RGB key, and the two keys
    /// use different files.
    #[test]
    fn round_trip() {
        let dir = temp_dir("round-trip");
        for key in [CoverageTextureKey::uniform(8), textured_key()] {
            assert_eq!(load(&dir, &key), None);
            let t = CoverageTexture::compute(&key);
            store(&dir, &key, &t).unwrap();
            assert_eq!(load(&dir, &key), Some(t));
        }
        assert_ne!(
            file_of(&dir, &CoverageTextureKey::uniform(8)),
            file_of(&dir, &textured_key())
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Every kind of damage is a miss, and `load_or_compute` then returns the computed texture
    /// and repairs the file.
    #[test]
    fn corrupt_truncated_or_foreign_files_are_misses() {
        let dir = temp_dir("corrupt");
        let key = CoverageTextureKey::uniform(8);
        let fresh = CoverageTexture::compute(&key);
        store(&dir, &key, &fresh).unwrap();
        let path = file_of(&dir, &key);
        let good = std::fs::read(&path).unwrap();
        let mut flipped = good.clone();
        flipped[good.len() / 2] ^= 0x10;
        let other_key = {
            let other = CoverageTextureKey::uniform(9);
            store(&dir, &other, &CoverageTexture::compute(&other)).unwrap();
            std::fs::read(file_of(&dir, &other)).unwrap()
        };
        for damaged in [
            flipped,
            good[..good.len() - 1].to_vec(),
            good[..10].to_vec(),
            Vec::new(),
            other_key,
        ] {
            std::fs::write(&path, &damaged).unwrap();
            assert_eq!(load(&dir, &key), None);
            assert_eq!(load_or_compute(&key, Some(&dir)), fresh);
            assert_eq!(std::fs::read(&path).unwrap(), good, "file repaired");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Writers of one key at the same time leave one complete, valid file and no temporary
    /// files.
    #[test]
    fn concurrent_writers_leave_one_valid_file() {
        let dir = temp_dir("concurrent");
        let key = textured_key();
        let t = CoverageTexture::compute(&key);
        std::thread::scope(|s| {
            for _ in 0..8 {
                s.spawn(|| store(&dir, &key, &t).unwrap());
            }
        });
        assert_eq!(load(&dir, &key), Some(t));
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 1, "{names:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A directory that cannot be created is no cache, not an error: the texture is computed.
    #[test]
    fn an_unusable_directory_still_gives_the_texture() {
        let dir = temp_dir("unusable");
        std::fs::create_dir_all(dir.parent().unwrap()).unwrap();
        std::fs::write(&dir, b"a file, not a directory").unwrap();
        let key = CoverageTextureKey::uniform(8);
        assert!(store(&dir, &key, &CoverageTexture::compute(&key)).is_err());
        assert_eq!(
            load_or_compute(&key, Some(&dir)),
            CoverageTexture::compute(&key)
        );
        std::fs::remove_file(&dir).unwrap();
    }
}
