//! Writing a method's outputs to disk (`docs/architecture.md` "The flow of one frame", issue 2
//! "Outputs").
//!
//! One method's results go to `DIR/METHOD/`:
//!
//! | file | contents |
//! |---|---|
//! | `image.png` | the shaded image, linear RGB → 8-bit sRGB ([`linear_to_srgb8`]) |
//! | `visibility.png` | 16-bit PNG, `round(v·65535)`: grayscale for [`Visibility::Gray`], RGB for [`Visibility::Rgb`] |
//! | `visibility.exr` | OpenEXR, RGB f32 (gray replicated into the three channels) |
//! | `visibility.pfm` | PFM with the exact f32 bits (`Pf` gray / `PF` RGB) — what goldens compare |
//! | `<name>.png`, `<name>.bin`, … | each buffer dump ([`dump`]): in every run the raw file of the dumps a method always hands back (`hard-sv`'s `stencil.png`, `wedge-blending`'s `penumbrae.png`, 8-bit grayscale, values as stored); with `--dump-buffers` every dump with its sidecar, viewable image and event map |
//! | `error.png` | when the reference ran: the signed error against it, on the fixed scale of [`error_colour`](crate::metrics::error_report::error_colour) (white 0, red too bright, blue too dark) |
//! | `stats.json` | [`MethodStats`](crate::methods::output::MethodStats) as pretty-printed JSON (its `"meshes"`: each mesh's name, triangle count and repairs), plus `"error"`: the [`ErrorReport`] against the reference (whole image and penumbra only), or null with `"error_note"` when no reference ran; the reference itself has `"reference_noise_floor"` |
//!
//! **No partial output** (`docs/architecture.md` "Bad input"): a run's method folders are
//! written into a hidden staging folder inside the output directory and moved into place only
//! once every method's files were encoded and written ([`write_method_dirs`]); single files are
//! written to a hidden temporary name and renamed ([`write_files_all_or_nothing`]). Every I/O
//! error names the path it happened at.
//!
//! All images are row-major with row 0 at the top, like [`Visibility`].

pub mod dump;

use crate::methods::output::MethodOutput;
use crate::metrics::error_report::ErrorReport;
use crate::metrics::ErrorStats;
use crate::visibility::Visibility;
use image::codecs::openexr::OpenExrEncoder;
use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};
use std::io::{self, Cursor};
use std::path::{Path, PathBuf};

/// Converts one linear-light value to an 8-bit sRGB code with the sRGB OETF
/// (IEC 61966-2-1): `12.92·x` for `x ≤ 0.0031308`, else `1.055·x^(1/2.4) − 0.055`.
///
/// The input is clamped to [0, 1] first (NaN maps to 0). The curve is evaluated in f64 and the
/// code is `round_half_even(255·y)`: ties go to the even code, the same rounding rule the
/// emulated GPU uses for its quantizations. `powf` comes from the platform's libm, so this is
/// used only for viewing images (the shaded `image.png`, diff panels), never for goldens.
pub fn linear_to_srgb8(x: f32) -> u8 {
    let x = if x.is_nan() {
        0.0
    } else {
        f64::from(x.clamp(0.0, 1.0))
    };
    let y = if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * libm::pow(x, 1.0 / 2.4) - 0.055
    };
    (y * 255.0).round_ties_even().clamp(0.0, 255.0) as u8
}

/// Quantizes a visibility value to 16 bits: `round_half_even(clamp(v, 0, 1)·65535)`, NaN → 0.
pub fn visibility_to_u16(v: f32) -> u16 {
    let v = if v.is_nan() {
        0.0
    } else {
        f64::from(v.clamp(0.0, 1.0))
    };
    (v * 65535.0).round_ties_even() as u16
}

/// Maps a visibility buffer to displayable 8-bit sRGB pixels (each channel through
/// [`linear_to_srgb8`]; gray is replicated), e.g. for side-by-side comparisons.
pub fn visibility_to_srgb8(vis: &Visibility) -> Vec<[u8; 3]> {
    (0..vis.len())
        .map(|i| vis.rgb(i).map(linear_to_srgb8))
        .collect()
}

/// The shaded image's file name in a method's folder.
pub const IMAGE_FILE: &str = "image.png";

/// The signed error map's file name in a method's folder (written when the reference ran).
pub const ERROR_FILE: &str = "error.png";

fn invalid(msg: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, msg)
}

fn image_err(what: &str, e: image::ImageError) -> io::Error {
    io::Error::other(format!("encoding {what}: {e}"))
}

fn pixel_count(width: u32, height: u32) -> io::Result<usize> {
    usize::try_from(u64::from(width) * u64::from(height))
        .map_err(|_| invalid(format!("image size {width}x{height} too large")))
}

fn check_len(what: &str, len: usize, width: u32, height: u32) -> io::Result<()> {
    let n = pixel_count(width, height)?;
    if len != n {
        return Err(invalid(format!(
            "{what} has {len} pixels, expected {width}x{height} = {n}"
        )));
    }
    Ok(())
}

fn encode_png(
    what: &str,
    bytes: &[u8],
    width: u32,
    height: u32,
    color: ExtendedColorType,
) -> io::Result<Vec<u8>> {
    let mut out = Vec::new();
    PngEncoder::new(&mut out)
        .write_image(bytes, width, height, color)
        .map_err(|e| image_err(what, e))?;
    Ok(out)
}

/// Encodes 8-bit RGB pixels (row 0 at the top) as a PNG file in memory.
pub fn encode_rgb8_png(pixels: &[[u8; 3]], width: u32, height: u32) -> io::Result<Vec<u8>> {
    check_len("RGB image", pixels.len(), width, height)?;
    let bytes: Vec<u8> = pixels.iter().flatten().copied().collect();
    encode_png("RGB PNG", &bytes, width, height, ExtendedColorType::Rgb8)
}

/// Encodes 8-bit grayscale values (row 0 at the top) as a PNG file in memory.
pub fn encode_gray8_png(values: &[u8], width: u32, height: u32) -> io::Result<Vec<u8>> {
    check_len("gray image", values.len(), width, height)?;
    encode_png("gray PNG", values, width, height, ExtendedColorType::L8)
}

/// Decodes a PNG holding an 8-bit grayscale image into `(width, height, values)`; any other
/// colour type or bit depth is an error (raw images are stored exactly, never converted).
pub fn decode_gray8_png(bytes: &[u8]) -> Result<(u32, u32, Vec<u8>), String> {
    let img = image::load_from_memory_with_format(bytes, image::ImageFormat::Png)
        .map_err(|e| format!("decoding PNG: {e}"))?;
    match img {
        image::DynamicImage::ImageLuma8(g) => Ok((g.width(), g.height(), g.into_raw())),
        other => Err(format!(
            "expected an 8-bit grayscale PNG, found {:?}",
            other.color()
        )),
    }
}

/// Encodes visibility as a 16-bit PNG ([`visibility_to_u16`]): grayscale for
/// [`Visibility::Gray`], RGB for [`Visibility::Rgb`].
pub fn encode_visibility_png16(vis: &Visibility, width: u32, height: u32) -> io::Result<Vec<u8>> {
    check_len("visibility", vis.len(), width, height)?;
    // `PngEncoder` takes 16-bit samples in native byte order and swaps them itself.
    let (samples, color): (Vec<u16>, _) = match vis {
        Visibility::Gray(v) => (
            v.iter().map(|&x| visibility_to_u16(x)).collect(),
            ExtendedColorType::L16,
        ),
        Visibility::Rgb(v) => (
            v.iter().flat_map(|p| p.map(visibility_to_u16)).collect(),
            ExtendedColorType::Rgb16,
        ),
    };
    let bytes: Vec<u8> = samples.iter().flat_map(|s| s.to_ne_bytes()).collect();
    encode_png("16-bit visibility PNG", &bytes, width, height, color)
}

/// Encodes visibility as an OpenEXR file (RGB, 32-bit float channels; gray is replicated)
/// with `image`'s OpenEXR encoder.
pub fn encode_visibility_exr(vis: &Visibility, width: u32, height: u32) -> io::Result<Vec<u8>> {
    check_len("visibility", vis.len(), width, height)?;
    let bytes: Vec<u8> = (0..vis.len())
        .flat_map(|i| vis.rgb(i))
        .flat_map(f32::to_ne_bytes)
        .collect();
    let mut out = Cursor::new(Vec::new());
    OpenExrEncoder::new(&mut out)
        .write_image(&bytes, width, height, ExtendedColorType::Rgb32F)
        .map_err(|e| image_err("visibility EXR", e))?;
    Ok(out.into_inner())
}

/// Encodes visibility as a Portable Float Map with the exact f32 bits.
///
/// The format: the header `Pf` (one channel, [`Visibility::Gray`]) or `PF` (three channels,
/// [`Visibility::Rgb`]), then `WIDTH HEIGHT`, then the scale `-1.0` (negative means
/// little-endian; its magnitude is unused here), each on its own line; then the raw samples,
/// rows **bottom to top** as the format requires, each row left to right.
///
/// # Panics
/// If `vis.len() != width·height`.
pub fn encode_pfm(vis: &Visibility, width: u32, height: u32) -> Vec<u8> {
    let w = width as usize;
    let h = height as usize;
    assert_eq!(
        vis.len(),
        w * h,
        "visibility has {} pixels, expected {width}x{height}",
        vis.len()
    );
    let (tag, channels) = match vis {
        Visibility::Gray(_) => ("Pf", 1),
        Visibility::Rgb(_) => ("PF", 3),
    };
    let header = format!("{tag}\n{width} {height}\n-1.0\n");
    let mut out = Vec::with_capacity(header.len() + w * h * channels * 4);
    out.extend_from_slice(header.as_bytes());
    for y in (0..h).rev() {
        let row = y * w..(y + 1) * w;
        match vis {
            Visibility::Gray(v) => {
                for x in &v[row] {
                    out.extend_from_slice(&x.to_le_bytes());
                }
            }
            Visibility::Rgb(v) => {
                for p in &v[row] {
                    for c in p {
                        out.extend_from_slice(&c.to_le_bytes());
                    }
                }
            }
        }
    }
    out
}

/// Decodes a Portable Float Map into `(width, height, visibility)`, row 0 at the top.
///
/// Accepts `Pf` (→ [`Visibility::Gray`]) and `PF` (→ [`Visibility::Rgb`]), header tokens
/// separated by any ASCII whitespace, a negative scale (little-endian samples) or a positive
/// one (big-endian samples), and exactly one whitespace byte before the samples. The samples'
/// bits are kept as they are (no scaling, NaN payloads preserved). Trailing bytes are an
/// error, as is a truncated file.
pub fn read_pfm(bytes: &[u8]) -> Result<(u32, u32, Visibility), String> {
    // Header: four whitespace-separated tokens, the last followed by one whitespace byte.
    let mut pos = 0;
    let mut tokens = Vec::with_capacity(4);
    while tokens.len() < 4 {
        while pos < bytes.len() && bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while pos < bytes.len() && !bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        if start == pos {
            return Err("PFM: truncated header".to_string());
        }
        if pos - start > 32 {
            return Err("PFM: header token too long".to_string());
        }
        tokens.push(String::from_utf8_lossy(&bytes[start..pos]).into_owned());
    }
    if pos >= bytes.len() {
        // Zero-size images have no samples but still need the whitespace after the scale.
        return Err("PFM: missing whitespace after the scale".to_string());
    }
    pos += 1;
    let channels = match tokens[0].as_str() {
        "Pf" => 1,
        "PF" => 3,
        t => {
            return Err(format!(
                "PFM: unknown magic {t:?} (expected \"Pf\" or \"PF\")"
            ))
        }
    };
    let width: u32 = tokens[1]
        .parse()
        .map_err(|_| format!("PFM: bad width {:?}", tokens[1]))?;
    let height: u32 = tokens[2]
        .parse()
        .map_err(|_| format!("PFM: bad height {:?}", tokens[2]))?;
    let scale: f64 = tokens[3]
        .parse()
        .map_err(|_| format!("PFM: bad scale {:?}", tokens[3]))?;
    if !scale.is_finite() || scale == 0.0 {
        return Err(format!(
            "PFM: scale must be finite and non-zero, got {scale}"
        ));
    }
    let little = scale < 0.0;
    let w = width as usize;
    let h = height as usize;
    let expected = (w as u128) * (h as u128) * (channels as u128) * 4;
    let data = &bytes[pos..];
    if data.len() as u128 != expected {
        return Err(format!(
            "PFM: {width}x{height} with {channels} channel(s) needs {expected} bytes of samples, found {}",
            data.len()
        ));
    }
    let sample = |i: usize| {
        let b = [
            data[4 * i],
            data[4 * i + 1],
            data[4 * i + 2],
            data[4 * i + 3],
        ];
        if little {
            f32::from_le_bytes(b)
        } else {
            f32::from_be_bytes(b)
        }
    };
    // File row r (from the bottom) is image row h − 1 − r.
    let vis = if channels == 1 {
        let mut v = vec![0.0f32; w * h];
        for y in 0..h {
            let r = h - 1 - y;
            for x in 0..w {
                v[y * w + x] = sample(r * w + x);
            }
        }
        Visibility::Gray(v)
    } else {
        let mut v = vec![[0.0f32; 3]; w * h];
        for y in 0..h {
            let r = h - 1 - y;
            for x in 0..w {
                let s = 3 * (r * w + x);
                v[y * w + x] = [sample(s), sample(s + 1), sample(s + 2)];
            }
        }
        Visibility::Rgb(v)
    };
    Ok((width, height, vis))
}

/// The I/O error `e` of `doing` at `path`, with the path (shortened if very long,
/// [`crate::error::shortened`]) in its message: `PATH: doing: cause`.
pub fn error_at(path: &Path, doing: &str, e: io::Error) -> io::Error {
    let shown = path.display().to_string();
    io::Error::new(
        e.kind(),
        format!("{}: {doing}: {e}", crate::error::shortened(&shown)),
    )
}

/// Writes `bytes` to a new file at `path` and syncs it; errors name the path.
fn write_new_file(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut f = std::fs::File::create(path).map_err(|e| error_at(path, "cannot create", e))?;
    io::Write::write_all(&mut f, bytes).map_err(|e| error_at(path, "cannot write", e))?;
    f.sync_all().map_err(|e| error_at(path, "cannot write", e))
}

/// `dir` created with its missing parents; returns the outermost directory this created (to
/// remove on failure), `None` if `dir` existed.
fn create_dirs(dir: &Path) -> io::Result<Option<PathBuf>> {
    let mut outermost = None;
    let mut p = Some(dir);
    while let Some(d) = p.filter(|d| !d.as_os_str().is_empty() && !d.exists()) {
        outermost = Some(d.to_path_buf());
        p = d.parent();
    }
    std::fs::create_dir_all(dir).map_err(|e| error_at(dir, "cannot create directory", e))?;
    Ok(outermost)
}

/// Writes `files` (name, bytes) into `dir` with no partial output: `dir` is created if
/// needed, every file is first written to a hidden temporary name in `dir`
/// (`.NAME.tmp-PID`) and synced, and only when all writes succeeded are they renamed to their
/// final names (a rename within one directory replaces the target atomically). On an error
/// before the renames, the temporary files (and the directories this created) are removed and
/// no final file is touched. Errors name the path.
pub fn write_files_all_or_nothing(dir: &Path, files: &[(String, Vec<u8>)]) -> io::Result<()> {
    let created = create_dirs(dir)?;
    let pid = std::process::id();
    let mut temps: Vec<(PathBuf, PathBuf)> = Vec::with_capacity(files.len());
    let result = files.iter().try_for_each(|(name, bytes)| {
        let tmp = dir.join(format!(".{name}.tmp-{pid}"));
        temps.push((tmp.clone(), dir.join(name)));
        write_new_file(&tmp, bytes)
    });
    if let Err(e) = result {
        for (tmp, _) in &temps {
            let _ = std::fs::remove_file(tmp);
        }
        if let Some(d) = created {
            let _ = std::fs::remove_dir_all(d);
        }
        return Err(e);
    }
    for (tmp, fin) in &temps {
        std::fs::rename(tmp, fin).map_err(|e| error_at(fin, "cannot move into place", e))?;
    }
    Ok(())
}

/// Writes one folder per method, `dir/NAME/` for each of `names`, all or nothing: every
/// target must be absent or a directory (checked first); the folders are written into a
/// hidden staging folder `dir/.penumbra-staging-PID/` with the files `encode(i)` returns for
/// method `i`, and only when every method's files were encoded and written are they moved into
/// place, each replacing the folder of the same name as a whole. On any error nothing of this
/// run is left: the staging folder, and `dir` itself if this call created it, are removed,
/// and the folders already moved are moved back. Every error names its path. Returns the
/// names of the files written into each folder, in the order of `names`.
pub fn write_method_dirs(
    dir: &Path,
    names: &[&str],
    encode: impl Fn(usize) -> io::Result<Vec<(String, Vec<u8>)>>,
) -> io::Result<Vec<Vec<String>>> {
    for name in names {
        if name.is_empty() || name.contains(['/', '\\']) || name.starts_with('.') {
            return Err(invalid(format!(
                "method name {name:?} is not a plain directory name"
            )));
        }
    }
    for target in std::iter::once(dir.to_path_buf()).chain(names.iter().map(|n| dir.join(n))) {
        match std::fs::symlink_metadata(&target) {
            Ok(m) if !m.is_dir() => {
                return Err(error_at(
                    &target,
                    "cannot write outputs",
                    io::Error::new(
                        io::ErrorKind::AlreadyExists,
                        "exists and is not a directory",
                    ),
                ))
            }
            _ => {}
        }
    }
    let created = create_dirs(dir)?;
    let staging = dir.join(format!(".penumbra-staging-{}", std::process::id()));
    let cleanup = |staging: &Path| {
        let _ = std::fs::remove_dir_all(staging);
        if let Some(d) = &created {
            let _ = std::fs::remove_dir_all(d);
        }
    };
    let staged = (|| -> io::Result<Vec<Vec<String>>> {
        std::fs::create_dir(&staging)
            .map_err(|e| error_at(&staging, "cannot create directory", e))?;
        let mut written = Vec::with_capacity(names.len());
        for (i, name) in names.iter().enumerate() {
            let files = encode(i)?;
            let method_dir = staging.join(name);
            std::fs::create_dir(&method_dir)
                .map_err(|e| error_at(&method_dir, "cannot create directory", e))?;
            for (file, bytes) in &files {
                write_new_file(&method_dir.join(file), bytes)?;
            }
            written.push(files.into_iter().map(|(file, _)| file).collect());
        }
        Ok(written)
    })();
    let written = match staged {
        Ok(written) => written,
        Err(e) => {
            cleanup(&staging);
            return Err(e);
        }
    };
    // Move into place: an existing folder is first moved aside into the staging folder.
    let mut moved: Vec<(PathBuf, PathBuf, Option<PathBuf>)> = Vec::new();
    for name in names {
        let (new, target) = (staging.join(name), dir.join(name));
        let aside = staging.join(format!(".old-{name}"));
        let result = (|| -> io::Result<Option<PathBuf>> {
            let old = if target.exists() {
                std::fs::rename(&target, &aside)
                    .map_err(|e| error_at(&target, "cannot replace", e))?;
                Some(aside.clone())
            } else {
                None
            };
            if let Err(e) = std::fs::rename(&new, &target) {
                if let Some(o) = &old {
                    let _ = std::fs::rename(o, &target);
                }
                return Err(error_at(&target, "cannot move into place", e));
            }
            Ok(old)
        })();
        match result {
            Ok(old) => moved.push((new, target, old)),
            Err(e) => {
                for (new, target, old) in moved.iter().rev() {
                    let _ = std::fs::rename(target, new);
                    if let Some(o) = old {
                        let _ = std::fs::rename(o, target);
                    }
                }
                cleanup(&staging);
                return Err(e);
            }
        }
    }
    std::fs::remove_dir_all(&staging)
        .map_err(|e| error_at(&staging, "outputs written, but cannot remove", e))?;
    Ok(written)
}

/// Encodes every output file of one method in memory: `(file name, bytes)` in a fixed order
/// (see the module table); each buffer dump's raw file, and with `dump_buffers` every file of
/// every dump ([`dump::dump_files`]). Nothing is written; errors (wrong buffer sizes, a dump
/// name that is not a plain file stem or collides with another output) come out here.
/// `stats.json` names `scene` (the built-in name or the scene file) and this program's version;
/// the options in force are its plan's `settings`.
pub fn encode_method_outputs(
    out: &MethodOutput,
    shaded: &[[f32; 3]],
    (width, height): (u32, u32),
    scene: &str,
    comparison: &Comparison,
    dump_buffers: bool,
) -> io::Result<Vec<(String, Vec<u8>)>> {
    check_len("shaded image", shaded.len(), width, height)?;
    check_len("visibility", out.visibility.len(), width, height)?;
    let srgb: Vec<[u8; 3]> = shaded.iter().map(|p| p.map(linear_to_srgb8)).collect();
    let mut files = vec![
        (
            IMAGE_FILE.to_string(),
            encode_rgb8_png(&srgb, width, height)?,
        ),
        (
            "visibility.png".to_string(),
            encode_visibility_png16(&out.visibility, width, height)?,
        ),
        (
            "visibility.exr".to_string(),
            encode_visibility_exr(&out.visibility, width, height)?,
        ),
        (
            "visibility.pfm".to_string(),
            encode_pfm(&out.visibility, width, height),
        ),
    ];
    for d in &out.dumps {
        for (name, bytes) in dump::dump_files(d, dump_buffers)? {
            if files.iter().any(|(n, _)| *n == name) || name == "stats.json" {
                return Err(invalid(format!(
                    "buffer dump {:?}: {name} collides with another output file",
                    d.name
                )));
            }
            files.push((name, bytes));
        }
    }
    let encoding = |e: serde_json::Error| io::Error::other(format!("encoding stats.json: {e}"));
    let mut stats = serde_json::to_value(&out.stats).map_err(encoding)?;
    stats["scene"] = scene.into();
    stats["version"] = concat!("penumbra ", env!("CARGO_PKG_VERSION")).into();
    let error = match comparison {
        Comparison::NoReference => {
            stats["error_note"] = "no reference in this run: add raycast to the methods".into();
            serde_json::Value::Null
        }
        Comparison::Reference { noise_floor } => {
            stats["reference_noise_floor"] = serde_json::to_value(noise_floor).map_err(encoding)?;
            serde_json::Value::Null
        }
        Comparison::Against { report, reference } => {
            check_len("reference", reference.len(), width, height)?;
            let map = crate::metrics::error_report::signed_error_map(&out.visibility, reference);
            files.push((
                ERROR_FILE.to_string(),
                encode_rgb8_png(&map, width, height)?,
            ));
            serde_json::to_value(report).map_err(encoding)?
        }
    };
    stats["error"] = error;
    let mut json = serde_json::to_vec_pretty(&stats).map_err(encoding)?;
    json.push(b'\n');
    files.push(("stats.json".to_string(), json));
    Ok(files)
}

/// What a run knows about a method's error, for `stats.json` and `error.png` (module table).
#[derive(Debug, Clone)]
pub enum Comparison<'a> {
    /// No reference ran: `"error": null` and an `"error_note"` saying so.
    NoReference,
    /// This method is the reference: `"error": null` and `"reference_noise_floor"`, the
    /// reference against itself with the next seed
    /// ([`reference_noise_floor`](crate::methods::raycast::reference_noise_floor)).
    Reference {
        /// Its noise floor, when it was measured.
        noise_floor: Option<ErrorStats>,
    },
    /// Compared with the reference: `"error"` holds the report, `error.png` the signed map.
    Against {
        /// The metrics.
        report: &'a ErrorReport,
        /// The reference's visibility.
        reference: &'a Visibility,
    },
}

/// Writes all outputs of one method to `dir/METHOD/` (see the module table): `image.png`
/// from `shaded` (linear RGB, `width·height` pixels, row 0 at the top), `visibility.png`,
/// `visibility.exr`, `visibility.pfm`, the raw file of each buffer dump, and `stats.json`
/// (without a reference: [`Comparison::NoReference`]).
///
/// The folder appears only once every file was encoded and written ([`write_method_dirs`]).
pub fn write_method_outputs(
    dir: &Path,
    (scene, method): (&str, &str),
    out: &MethodOutput,
    shaded: &[[f32; 3]],
    (width, height): (u32, u32),
) -> io::Result<()> {
    write_method_dirs(dir, &[method], |_| {
        encode_method_outputs(
            out,
            shaded,
            (width, height),
            scene,
            &Comparison::NoReference,
            false,
        )
    })
    .map(|_| ())
}

/// Width in pixels of the separator between the panels of [`write_side_by_side_png`].
pub const PANEL_GAP: u32 = 2;

/// Colour of the separator between panels: a mid gray, so that black (e.g. an all-equal diff
/// mask) and white panels both stand apart from it.
pub const PANEL_GAP_COLOR: [u8; 3] = [128, 128, 128];

/// Writes panels of `w×h` 8-bit sRGB pixels (row 0 at the top) side by side, left to right,
/// separated by [`PANEL_GAP`] columns of [`PANEL_GAP_COLOR`], as one RGB PNG at `path`.
/// Used for golden failures (expected | diff mask | actual) and the `compare` command.
///
/// The parent directory is created if needed; the file is written to a temporary name and
/// renamed into place. An error if any panel does not have `w·h` pixels.
pub fn write_side_by_side_png(
    path: &Path,
    w: u32,
    h: u32,
    panels: &[Vec<[u8; 3]>],
) -> io::Result<()> {
    let bytes = encode_side_by_side_png(w, h, panels)?;
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| invalid(format!("{} has no file name", path.display())))?
        .to_string_lossy()
        .into_owned();
    write_files_all_or_nothing(&dir, &[(name, bytes)])
}

/// Encodes the side-by-side image of [`write_side_by_side_png`] in memory.
pub fn encode_side_by_side_png(w: u32, h: u32, panels: &[Vec<[u8; 3]>]) -> io::Result<Vec<u8>> {
    let n = pixel_count(w, h)?;
    for (i, p) in panels.iter().enumerate() {
        if p.len() != n {
            return Err(invalid(format!(
                "panel {i} has {} pixels, expected {w}x{h} = {n}",
                p.len()
            )));
        }
    }
    let count = panels.len() as u64;
    let total_w = count * u64::from(w) + count.saturating_sub(1) * u64::from(PANEL_GAP);
    let total_w = u32::try_from(total_w)
        .map_err(|_| invalid(format!("{count} panels of width {w} are too wide")))?;
    let (w, h) = (w as usize, h as usize);
    let mut pixels = Vec::with_capacity(total_w as usize * h);
    for y in 0..h {
        for (i, p) in panels.iter().enumerate() {
            if i > 0 {
                pixels.extend(std::iter::repeat_n(PANEL_GAP_COLOR, PANEL_GAP as usize));
            }
            pixels.extend_from_slice(&p[y * w..(y + 1) * w]);
        }
    }
    encode_rgb8_png(&pixels, total_w, h as u32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::counters::Counters;
    use crate::methods::dump::{BufferDump, DumpValues, ElementFormat};
    use crate::methods::output::MethodStats;

    fn temp_dir(tag: &str) -> PathBuf {
        use std::sync::atomic::{AtomicU32, Ordering};
        static N: AtomicU32 = AtomicU32::new(0);
        let d = std::env::temp_dir().join(format!(
            "penumbra-output-{tag}-{}-{}",
            std::process::id(),
            N.fetch_add(1, Ordering::Relaxed)
        ));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    fn sample_output(vis: Visibility) -> MethodOutput {
        MethodOutput {
            dumps: vec![BufferDump::new(
                "stencil",
                "test",
                match vis.len() as u32 {
                    n if n % 3 == 0 => (3, n / 3),
                    n => (n, 1),
                },
                ElementFormat::Stencil8,
                DumpValues::U8((0..vis.len() as u32).map(|i| (i * 37) as u8).collect()),
            )],
            visibility: vis,
            stats: MethodStats {
                method: "hard-sv".into(),
                width: 3,
                height: 2,
                wall_seconds: 0.25,
                plan: serde_json::json!({"passes": ["scene-depth"]}),
                passes: vec![],
                totals: Counters::default(),
                warnings: vec![],
                clamped_pixels: 0,
                meshes: vec![],
                gpu_model: crate::gpu_model::estimate(
                    crate::gpu_model::GpuModel::default().profile(),
                    &[],
                ),
            },
        }
    }

    #[test]
    fn srgb_endpoints_and_curve() {
        assert_eq!(linear_to_srgb8(0.0), 0);
        assert_eq!(linear_to_srgb8(1.0), 255);
        assert_eq!(linear_to_srgb8(-3.0), 0);
        assert_eq!(linear_to_srgb8(7.0), 255);
        assert_eq!(linear_to_srgb8(f32::NAN), 0);
        assert_eq!(linear_to_srgb8(f32::INFINITY), 255);
        // Middle gray: 0.5 linear is 0.7354 sRGB → 187.5… → 188.
        assert_eq!(linear_to_srgb8(0.5), 188);
        // 0.18 linear → 0.4614 → 117.66 → 118.
        assert_eq!(linear_to_srgb8(0.18), 118);
        // Linear segment: 0.001 → 12.92e-3·255 = 3.29 → 3.
        assert_eq!(linear_to_srgb8(0.001), 3);
        // Monotonic.
        let mut prev = 0;
        for i in 0..=10_000 {
            let c = linear_to_srgb8(i as f32 / 10_000.0);
            assert!(c >= prev);
            prev = c;
        }
    }

    #[test]
    fn u16_quantization() {
        assert_eq!(visibility_to_u16(0.0), 0);
        assert_eq!(visibility_to_u16(1.0), 65535);
        assert_eq!(visibility_to_u16(0.5), 32768); // 32767.5 ties to even
        assert_eq!(visibility_to_u16(f32::NAN), 0);
        assert_eq!(visibility_to_u16(2.0), 65535);
        assert_eq!(visibility_to_u16(-1.0), 0);
    }

    #[test]
    fn pfm_round_trip_gray_and_rgb_exact_bits() {
        let gray: Vec<f32> = vec![
            0.0,
            -0.0,
            1.0,
            f32::from_bits(1),
            0.1,
            f32::from_bits(0x7fc0_1234),
        ];
        let vis = Visibility::Gray(gray.clone());
        let bytes = encode_pfm(&vis, 3, 2);
        assert!(bytes.starts_with(b"Pf\n3 2\n-1.0\n"));
        let (w, h, back) = read_pfm(&bytes).unwrap();
        assert_eq!((w, h), (3, 2));
        let Visibility::Gray(back) = back else {
            panic!("expected gray")
        };
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back), bits(&gray));

        let rgb: Vec<[f32; 3]> = (0..6).map(|i| [i as f32, 0.5 / i as f32, -1.0]).collect();
        let vis = Visibility::Rgb(rgb.clone());
        let bytes = encode_pfm(&vis, 2, 3);
        assert!(bytes.starts_with(b"PF\n2 3\n-1.0\n"));
        let (w, h, back) = read_pfm(&bytes).unwrap();
        assert_eq!((w, h), (2, 3));
        assert_eq!(back, Visibility::Rgb(rgb));
    }

    #[test]
    fn pfm_rows_are_bottom_to_top() {
        // Image row 0 (top) = [1, 2], row 1 = [3, 4]; the file stores row 1 first.
        let bytes = encode_pfm(&Visibility::Gray(vec![1.0, 2.0, 3.0, 4.0]), 2, 2);
        let data = &bytes[bytes.len() - 16..];
        let first = f32::from_le_bytes(data[0..4].try_into().unwrap());
        assert_eq!(first, 3.0);
    }

    #[test]
    fn pfm_big_endian_and_errors() {
        let mut bytes = b"Pf 2 1 1.0\n".to_vec();
        bytes.extend_from_slice(&0.25f32.to_be_bytes());
        bytes.extend_from_slice(&0.75f32.to_be_bytes());
        let (_, _, v) = read_pfm(&bytes).unwrap();
        assert_eq!(v, Visibility::Gray(vec![0.25, 0.75]));

        assert!(read_pfm(b"").is_err());
        assert!(read_pfm(b"P6\n1 1\n-1.0\n\0\0\0\0").is_err());
        assert!(read_pfm(b"Pf\n1 1\n-1.0\n\0\0\0").is_err());
        assert!(read_pfm(b"Pf\n1 1\n-1.0\n\0\0\0\0\0").is_err());
        assert!(read_pfm(b"Pf\nx 1\n-1.0\n\0\0\0\0").is_err());
        assert!(read_pfm(b"Pf\n1 1\n0\n\0\0\0\0").is_err());
        assert!(read_pfm(b"Pf\n4294967295 4294967295\n-1.0\n").is_err());
        assert!(read_pfm(b"Pf\n0 0\n-1.0").is_err());
        assert!(read_pfm(b"Pf\n0 0\n-1.0\n").is_ok());
    }

    #[test]
    fn writes_every_file_and_they_decode() {
        let dir = temp_dir("write");
        let vis = Visibility::Gray(vec![0.0, 0.25, 0.5, 0.75, 1.0, 0.125]);
        let out = sample_output(vis.clone());
        let shaded = vec![[0.5f32, 0.25, 1.0]; 6];
        write_method_outputs(&dir, ("test", "hard-sv"), &out, &shaded, (3, 2)).unwrap();
        let m = dir.join("hard-sv");
        let mut names: Vec<String> = std::fs::read_dir(&m)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(
            names,
            [
                "image.png",
                "stats.json",
                "stencil.png",
                "visibility.exr",
                "visibility.pfm",
                "visibility.png"
            ]
        );

        let img = image::open(m.join("image.png")).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (3, 2));
        assert_eq!(img.get_pixel(0, 0).0, [188, 137, 255]);

        let v16 = image::open(m.join("visibility.png")).unwrap();
        let image::DynamicImage::ImageLuma16(v16) = v16 else {
            panic!("expected 16-bit gray")
        };
        assert_eq!(v16.into_raw(), vec![0, 16384, 32768, 49151, 65535, 8192]);

        let exr = image::open(m.join("visibility.exr")).unwrap().to_rgb32f();
        assert_eq!(exr.dimensions(), (3, 2));
        assert_eq!(exr.get_pixel(1, 0).0, [0.25; 3]);
        assert_eq!(exr.get_pixel(2, 1).0, [0.125; 3]);

        let (w, h, back) = read_pfm(&std::fs::read(m.join("visibility.pfm")).unwrap()).unwrap();
        assert_eq!((w, h, back), (3, 2, vis));

        let (w, h, st) = decode_gray8_png(&std::fs::read(m.join("stencil.png")).unwrap()).unwrap();
        assert_eq!((w, h), (3, 2));
        assert_eq!(DumpValues::U8(st), out.dumps[0].values);

        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(m.join("stats.json")).unwrap()).unwrap();
        assert_eq!(json["method"], "hard-sv");
        assert_eq!(json["width"], 3);
        assert_eq!(json["totals"]["overflow_events"], 0);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn rgb_visibility_writes_rgb16_and_pf() {
        let dir = temp_dir("rgb");
        let vis = Visibility::Rgb(vec![[0.0, 0.5, 1.0], [1.0, 0.0, 0.25]]);
        let mut out = sample_output(vis.clone());
        out.dumps.clear();
        write_method_outputs(&dir, ("test", "ssv"), &out, &[[0.0; 3]; 2], (2, 1)).unwrap();
        let m = dir.join("ssv");
        let image::DynamicImage::ImageRgb16(v16) = image::open(m.join("visibility.png")).unwrap()
        else {
            panic!("expected 16-bit RGB")
        };
        assert_eq!(v16.into_raw(), vec![0, 32768, 65535, 65535, 0, 16384]);
        let pfm = std::fs::read(m.join("visibility.pfm")).unwrap();
        assert!(pfm.starts_with(b"PF\n"));
        assert_eq!(read_pfm(&pfm).unwrap().2, vis);
        let exr = image::open(m.join("visibility.exr")).unwrap().to_rgb32f();
        assert_eq!(exr.get_pixel(1, 0).0, [1.0, 0.0, 0.25]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_sizes_write_nothing() {
        let dir = temp_dir("bad");
        let mut out = sample_output(Visibility::Gray(vec![0.0; 6]));
        // A dump of the wrong size: encoding fails before any file exists.
        out.dumps[0].values = DumpValues::U8(vec![0; 5]);
        let err = write_method_outputs(&dir, ("test", "hard-sv"), &out, &[[0.0; 3]; 6], (3, 2))
            .unwrap_err();
        assert!(err.to_string().contains("stencil"), "{err}");
        assert!(!dir.exists());
        let out = sample_output(Visibility::Gray(vec![0.0; 6]));
        assert!(
            write_method_outputs(&dir, ("test", "hard-sv"), &out, &[[0.0; 3]; 5], (3, 2)).is_err()
        );
        assert!(
            write_method_outputs(&dir, ("test", "../x"), &out, &[[0.0; 3]; 6], (3, 2)).is_err()
        );
        let mut out2 = out.clone();
        out2.dumps[0].name = "../evil".into();
        assert!(
            write_method_outputs(&dir, ("test", "hard-sv"), &out2, &[[0.0; 3]; 6], (3, 2)).is_err()
        );
        out2.dumps[0].name = "visibility".into();
        assert!(
            write_method_outputs(&dir, ("test", "hard-sv"), &out2, &[[0.0; 3]; 6], (3, 2)).is_err()
        );
        assert!(!dir.exists());
    }

    #[test]
    fn a_failing_method_leaves_nothing_behind() {
        let out = sample_output(Visibility::Gray(vec![0.5; 6]));
        let good = |_: usize| {
            encode_method_outputs(
                &out,
                &[[0.0; 3]; 6],
                (3, 2),
                "test",
                &Comparison::NoReference,
                false,
            )
        };
        // A new output directory: not created at all.
        let dir = temp_dir("fail").join("new");
        let fail_second = |i: usize| {
            if i == 1 {
                Err(io::Error::other("disk full"))
            } else {
                good(i)
            }
        };
        let e = write_method_dirs(&dir, &["hard-sv", "ssv"], fail_second).unwrap_err();
        assert_eq!(e.to_string(), "disk full");
        assert!(!dir.parent().unwrap().exists());
        // An existing output directory with an older run: left exactly as it was.
        write_method_dirs(&dir, &["hard-sv"], good).unwrap();
        std::fs::write(dir.join("hard-sv").join("mine.txt"), "x").unwrap();
        write_method_dirs(&dir, &["hard-sv", "ssv"], fail_second).unwrap_err();
        let listing = |d: &Path| {
            let mut v: Vec<String> = std::fs::read_dir(d)
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect();
            v.sort();
            v
        };
        assert_eq!(listing(&dir), ["hard-sv"]);
        assert!(listing(&dir.join("hard-sv")).contains(&"mine.txt".to_string()));
        // Success replaces the method folder as a whole.
        write_method_dirs(&dir, &["hard-sv", "ssv"], good).unwrap();
        assert_eq!(listing(&dir), ["hard-sv", "ssv"]);
        assert!(!listing(&dir.join("hard-sv")).contains(&"mine.txt".to_string()));
        // A file where a method folder should be: refused before anything is written.
        std::fs::remove_dir_all(dir.join("ssv")).unwrap();
        std::fs::write(dir.join("ssv"), "a file").unwrap();
        std::fs::remove_dir_all(dir.join("hard-sv")).unwrap();
        let e = write_method_dirs(&dir, &["hard-sv", "ssv"], good).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{}: cannot write outputs: exists and is not a directory",
                dir.join("ssv").display()
            )
        );
        assert_eq!(listing(&dir), ["ssv"]);
        std::fs::remove_dir_all(dir.parent().unwrap()).unwrap();
    }

    #[test]
    fn side_by_side_layout() {
        let dir = temp_dir("sbs");
        let path = dir.join("sub").join("cmp.png");
        let a = vec![[255, 0, 0]; 4];
        let b = vec![[0, 0, 255]; 4];
        write_side_by_side_png(&path, 2, 2, &[a, b]).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (2 + PANEL_GAP + 2, 2));
        assert_eq!(img.get_pixel(0, 1).0, [255, 0, 0]);
        assert_eq!(img.get_pixel(2, 0).0, PANEL_GAP_COLOR);
        assert_eq!(img.get_pixel(2 + PANEL_GAP, 1).0, [0, 0, 255]);
        assert!(write_side_by_side_png(&path, 2, 2, &[vec![[0; 3]; 3]]).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
