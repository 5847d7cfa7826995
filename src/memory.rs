//! The memory a render needs, estimated before anything is allocated, and the limit it must
//! fit in (`--max-memory`, by default half of the machine's memory), so that a large image is
//! refused with a clear error instead of aborting on a failed allocation.
//!
//! The estimate is per pixel and per method: a method's peak while it runs (the scene pass's
//! buffers, its own emulated buffers and scratch, its encoded outputs), plus what every
//! finished method keeps until the outputs are written (its visibility, shaded image and raw
//! images). The per-method peaks were measured (peak resident memory at 512² and 1024², the
//! difference per pixel, then rounded up by at least 10%), so the estimate is an upper
//! estimate for the built-in scenes, not a bound for every scene. Meshes add their own
//! memory, which does not grow with the image: loading (the file's vertices before welding,
//! repairs, adjacency), silhouettes, volumes and wedges, a ray-cast BVH. That is a figure per
//! triangle and method, measured by `experiment cost-growth` at 512²: what the peak held beyond
//! the per-pixel figures, the largest over bumpy spheres of 0.33 M and 1.3 M triangles and the
//! scanned `ogre` and `nefertiti`, rounded up by at least 25 %. It ranges from 192 bytes a
//! triangle for `ssv` to 608 for `raycast` (its BVH and triangle copies) and 848 for
//! `pw-restructured`, whose wedges follow the silhouette edges, which a scan has far more of
//! per triangle than the spheres (671 bytes a triangle on `ogre` against 238 on the 1.3 M
//! sphere). Without it the estimate was below the measured peak at 16 of 30 points of the
//! first run, with the sphere-only figures at 4 of 100 of the second
//! (`docs/performance.md` "How cost grows").

use crate::error::InputError;
use crate::methods::Method;
use crate::scene::Scene;

/// Memory a render needs whatever its size: the program, the built-in scenes, thread stacks.
pub const FIXED_BYTES: u64 = 64 << 20;

/// What a finished method keeps per pixel until the outputs are written: RGB f32 visibility
/// (12 bytes), the shaded image (12), raw 8-bit images and their share of the table.
pub const KEPT_BYTES_PER_PIXEL: u64 = 32;

/// What each extra light adds per pixel while a method runs once per light: that light's
/// visibility (up to RGB f32) and raw images, kept until they are averaged.
pub const PER_LIGHT_BYTES_PER_PIXEL: u64 = 16;

/// What a finished method's buffer dumps keep per pixel until the outputs are written, with
/// `--dump-buffers` (`methods::dump`): measured at 512² and 1024² on `cube-of-spheres` with
/// `hard-sv`, `ssv`, `ssv-optimized` and `wedge-blending`, 129 bytes per pixel for the four
/// (raw values, event records, clamp flags), rounded up per method. Light-view maps count at
/// their default size, the image's larger side squared.
pub const DUMP_BYTES_PER_PIXEL: u64 = 48;

/// A method's figure of its registry entry (`figure`: [`Method::bytes_per_pixel`] or
/// [`Method::bytes_per_triangle`]); an unknown name (names are checked before) counts as the
/// largest of any method.
fn method_figure(method: &str, figure: fn(&Method) -> u64) -> u64 {
    match crate::methods::find(method) {
        Some(m) => figure(m),
        None => crate::methods::ALL.iter().map(figure).max().unwrap_or(0),
    }
}

/// A method's peak memory per pixel while it runs (module doc: measured, rounded up), as its
/// registry entry gives it ([`Method::bytes_per_pixel`]).
pub fn method_bytes_per_pixel(method: &str) -> u64 {
    method_figure(method, |m| m.bytes_per_pixel)
}

/// A method's peak memory per triangle of the scene (module doc), as its registry entry gives
/// it ([`Method::bytes_per_triangle`]).
pub fn method_bytes_per_triangle(method: &str) -> u64 {
    method_figure(method, |m| m.bytes_per_triangle)
}

/// Estimated bytes to render `scene` with `methods` and, with `dump_buffers`, keep their
/// buffer dumps ([`DUMP_BYTES_PER_PIXEL`] each).
pub fn estimate_dumping(scene: &Scene, methods: &[String], dump_buffers: bool) -> u64 {
    let side = u64::from(scene.width.max(scene.height));
    let dumps = if dump_buffers {
        DUMP_BYTES_PER_PIXEL * side * side * methods.len() as u64
    } else {
        0
    };
    estimate(scene, methods) + dumps
}

/// Estimated bytes to render `scene` with `methods` (module doc).
pub fn estimate(scene: &Scene, methods: &[String]) -> u64 {
    let pixels = u64::from(scene.width) * u64::from(scene.height);
    let extra_lights = scene.lights.len().saturating_sub(1) as u64;
    let peak = methods
        .iter()
        .map(|m| method_bytes_per_pixel(m) + extra_lights * PER_LIGHT_BYTES_PER_PIXEL)
        .max()
        .unwrap_or(0);
    let kept = KEPT_BYTES_PER_PIXEL * methods.len() as u64;
    let triangles: u64 = scene.meshes.iter().map(|m| m.triangles.len() as u64).sum();
    let per_triangle = methods
        .iter()
        .map(|m| method_bytes_per_triangle(m))
        .max()
        .unwrap_or(0);
    FIXED_BYTES + pixels * (peak + kept) + triangles * per_triangle
}

/// The file `render` writes beside the method folders: what the render was estimated to need
/// and what it took ([`MemoryRecord`]).
pub const RECORD_FILE: &str = "memory.json";

/// A render's memory, as `render` writes it to [`RECORD_FILE`] after its outputs: the
/// estimate it was checked against, the limit, and the process's measured peak, so that the
/// estimate can be checked against the truth (`experiment cost-growth`).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MemoryRecord {
    /// [`estimate_dumping`] of the scene as rendered.
    pub estimate_bytes: u64,
    /// The limit it was checked against; `None` for no limit.
    pub limit_bytes: Option<u64>,
    /// The process's peak resident memory when the outputs were written
    /// ([`peak_resident_bytes`]); `None` where it cannot be read.
    pub peak_resident_bytes: Option<u64>,
}

/// This process's peak resident memory so far: `VmHWM` of `/proc/self/status` (the high-water
/// mark of this program's own address space: a fresh one from `exec`, so the parent that
/// started it does not count, as it can in `wait4`'s `ru_maxrss`, which keeps the high-water
/// mark of the address space replaced by `exec`). `None` where it cannot be
/// read (systems other than Linux).
pub fn peak_resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let kib = status.lines().find_map(|l| l.strip_prefix("VmHWM:"))?;
    let kib: u64 = kib.trim().trim_end_matches("kB").trim().parse().ok()?;
    Some(kib * 1024)
}

/// The machine's memory in bytes as this process may use it: the smaller of the physical
/// memory (`MemTotal` in `/proc/meminfo`) and the cgroup's memory limit, if any. `None` where
/// neither can be read (systems other than Linux).
pub fn machine_memory() -> Option<u64> {
    let total = std::fs::read_to_string("/proc/meminfo").ok().and_then(|s| {
        let kib = s.lines().find_map(|l| l.strip_prefix("MemTotal:"))?;
        kib.trim().trim_end_matches("kB").trim().parse::<u64>().ok()
    });
    let total = total.map(|kib| kib * 1024);
    let cgroup = [
        "/sys/fs/cgroup/memory.max",
        "/sys/fs/cgroup/memory/memory.limit_in_bytes",
    ]
    .iter()
    .find_map(|p| std::fs::read_to_string(p).ok()?.trim().parse::<u64>().ok());
    match (total, cgroup) {
        (Some(t), Some(c)) => Some(t.min(c)),
        (t, c) => t.or(c),
    }
}

/// The default `--max-memory`: half of [`machine_memory`], `None` (no limit) where that is
/// unknown.
pub fn default_limit() -> Option<u64> {
    machine_memory().map(|m| m / 2)
}

/// Parses a `--max-memory` value: a number of bytes, optionally with the suffix `K`, `M`,
/// `G` or `T` (powers of 1024; `KiB`, `MiB`, … and `KB`, `MB`, … mean the same).
pub fn parse_size(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let digits = t
        .find(|c: char| !c.is_ascii_digit() && c != '.')
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(digits);
    let shift = match unit.trim().to_ascii_uppercase().as_str() {
        "" | "B" => 0,
        "K" | "KB" | "KIB" => 10,
        "M" | "MB" | "MIB" => 20,
        "G" | "GB" | "GIB" => 30,
        "T" | "TB" | "TIB" => 40,
        _ => {
            return Err(format!(
                "{text:?}: expected bytes, e.g. 8G, 512M or 1000000"
            ))
        }
    };
    let value: f64 = number
        .parse()
        .map_err(|_| format!("{text:?}: expected bytes, e.g. 8G, 512M or 1000000"))?;
    let bytes = value * (1u64 << shift) as f64;
    if !(bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!("{text:?}: expected at least 1 byte"));
    }
    Ok(bytes as u64)
}

/// Bytes as MiB (or GiB from 10 GiB on) with one decimal, for messages.
pub fn fmt_bytes(bytes: u64) -> String {
    let mib = bytes as f64 / (1u64 << 20) as f64;
    if mib >= 10240.0 {
        format!("{:.1} GiB", mib / 1024.0)
    } else {
        format!("{mib:.1} MiB")
    }
}

/// Refuses a render of `scene` with `methods` (and their buffer dumps with `dump_buffers`)
/// whose [`estimate_dumping`] exceeds `limit` (no check when `limit` is `None`), naming the
/// image size, the estimate and the limit; `limit_origin` says where the limit came from
/// (`--max-memory` or the default).
pub fn check_fits(
    scene: &Scene,
    (methods, dump_buffers): (&[String], bool),
    limit: Option<u64>,
    limit_origin: &str,
) -> Result<(), InputError> {
    let Some(limit) = limit else {
        return Ok(());
    };
    let need = estimate_dumping(scene, methods, dump_buffers);
    if need <= limit {
        return Ok(());
    }
    Err(InputError::at(
        &scene.source,
        "width×height",
        format!(
            "{}×{} with {} needs an estimated {}, more than the memory limit of {} ({limit_origin})",
            scene.width,
            scene.height,
            methods.join(", "),
            fmt_bytes(need),
            fmt_bytes(limit),
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse() {
        assert_eq!(parse_size("1000"), Ok(1000));
        assert_eq!(parse_size("8G"), Ok(8 << 30));
        assert_eq!(parse_size("512MiB"), Ok(512 << 20));
        assert_eq!(parse_size("1.5k"), Ok(1536));
        assert!(parse_size("0").is_err());
        assert!(parse_size("8X").is_err());
        assert!(parse_size("").is_err());
        assert!(parse_size("-5").is_err());
    }

    #[test]
    fn estimate_grows_with_pixels_and_methods() {
        let mut s = crate::scene::builtin::load("single-quad").unwrap();
        s.width = 1024;
        s.height = 1024;
        let one = vec!["hard-sv".to_string()];
        let triangles: u64 = s.meshes.iter().map(|m| m.triangles.len() as u64).sum();
        assert!(triangles > 0);
        let meshes = |bytes: u64| triangles * bytes;
        assert_eq!(
            estimate(&s, &one),
            FIXED_BYTES + (1 << 20) * (72 + 32) + meshes(208)
        );
        let two = vec!["hard-sv".to_string(), "ssv".to_string()];
        assert_eq!(
            estimate(&s, &two),
            // hard-sv's 208 bytes a triangle, the larger of the two (ssv: 192).
            FIXED_BYTES + (1 << 20) * (160 + 64) + meshes(208)
        );
        // A mesh's memory grows with its triangles, by the largest figure of the methods.
        let mut big = s.clone();
        big.meshes.push(crate::scene::procedural::bumpy_sphere(
            "b",
            (101, 202),
            (6, 0.1),
            [1.0; 3],
        ));
        let more = 4 * 101 * 100;
        assert_eq!(estimate(&big, &two) - estimate(&s, &two), more * 208);
        let raycast = vec!["raycast".to_string()];
        assert_eq!(
            estimate(&big, &raycast) - estimate(&s, &raycast),
            more * 608
        );
        let e = check_fits(&s, (&one, false), Some(100 << 20), "--max-memory")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "single-quad: width×height: 1024×1024 with hard-sv needs an estimated 168.0 MiB, \
             more than the memory limit of 100.0 MiB (--max-memory)"
        );
        check_fits(&s, (&one, false), Some(200 << 20), "--max-memory").unwrap();
        check_fits(&s, (&one, false), None, "default").unwrap();
        // Dumps add their bytes per pixel per method.
        assert_eq!(
            estimate_dumping(&s, &two, true),
            estimate(&s, &two) + (1 << 20) * 2 * DUMP_BYTES_PER_PIXEL
        );
        assert!(check_fits(&s, (&one, true), Some(200 << 20), "--max-memory").is_err());
    }

    #[test]
    fn machine_memory_is_read_on_linux() {
        if cfg!(target_os = "linux") {
            let m = machine_memory().unwrap();
            assert!(m >= 64 << 20, "{m}");
            assert_eq!(default_limit(), Some(m / 2));
        }
    }
}
