//! The few constants the emulated GPU derives everything else from (after Mesa's
//! `lp_limits.h`): sub-pixel precision, tile sizes, depth formats and the guard band.

/// Fractional bits of the fixed-point window coordinates (`docs/architecture.md` "Rasterization": 8
/// sub-pixel bits).
pub const SUBPIXEL_BITS: u32 = 8;
/// One pixel in fixed-point units.
pub const FIXED_ONE: i64 = 1 << SUBPIXEL_BITS;
/// Default tile edge in pixels (`docs/architecture.md` "Rasterization": 8×8).
pub const DEFAULT_TILE_SIZE: u32 = 8;
/// Default edge of a hierarchical-Z tile in pixels (`docs/architecture.md` "Hierarchical Z":
/// 8×8, independent of the raster tile, at most it).
pub const DEFAULT_HIZ_TILE_SIZE: u32 = 8;
/// Smallest tile edge the tile sweep allows (Paper II §7: 2×2).
pub const MIN_TILE_SIZE: u32 = 2;
/// Largest tile edge the tile sweep allows (Paper II §7: 256×256).
pub const MAX_TILE_SIZE: u32 = 256;
/// Largest accepted image edge in pixels: keeps every fixed-point edge function product
/// well inside i64 (coordinates < 2^(14+3+8) after the guard band, products < 2^52).
pub const MAX_IMAGE_SIZE: u32 = 16384;
/// Guard band: clip-space x and y are clipped to |x| ≤ GUARD_BAND·w, so that primitives
/// reaching infinity (w = 0) become finite without moving any edge that crosses the viewport.
pub const GUARD_BAND: f64 = 4.0;
/// Largest D16 value, 2^16 − 1.
pub const D16_MAX: u32 = (1 << 16) - 1;
/// Largest D24 value, 2^24 − 1.
pub const D24_MAX: u32 = (1 << 24) - 1;
/// Largest |window coordinate| in pixels a vertex may have after clipping: 2^20. The guard
/// band keeps real vertices below (GUARD_BAND + 1)/2 · MAX_IMAGE_SIZE ≈ 41,000 px; with
/// 8 sub-pixel bits, coordinates stay below 2^28 and edge-function products below 2^58.
pub const WINDOW_LIMIT: f32 = 1_048_576.0;
/// Largest number of lights in a scene: Paper I §7 scales light intensities by 255/n, so
/// with more than 255 lights a fully visible light would add less than one LI unit.
pub const MAX_LIGHTS: usize = 255;
/// Largest input file (scene file, OBJ, texture) in bytes, 512 MiB: every input is read whole
/// into memory, so a bound keeps a mistaken path (a disk image, say) from exhausting memory.
pub const MAX_INPUT_FILE_BYTES: u64 = 512 << 20;
/// Largest `--threads`: far above any core count the renders scale to, far below the
/// thousands of threads that exhaust a machine's process limits.
pub const MAX_THREADS: usize = 1024;
/// Smallest accepted `camera.vfov_deg`, 0.1°: at [`MAX_IMAGE_SIZE`] rows a pixel then still
/// spans about two f32 steps (2⁻²⁴ relative) of the distance it is seen at; narrower views
/// put several pixels into one representable coordinate and the methods stop agreeing.
pub const MIN_VFOV_DEG: f64 = 0.1;
/// Smallest width of a rectangular light relative to its length: its narrower height
/// `|u × v| / max(|u|, |v|)` over `max(|u|, |v|)` (the sine of the angle between `u` and `v`
/// times the shorter side over the longer). f32 keeps 2⁻²⁴ ≈ 6·10⁻⁸ of a coordinate, so the
/// corners `c ± u ± v` of a thinner light round onto a segment, and the coverage code's light
/// frame mixes the two sides' scales (found by fuzzing: a light 10³⁴ long and 60 wide got
/// coverage −0.036 for an edge one way and 0 the other). 10⁻⁶ is 16 times that rounding, the
/// bound the check for parallel sides already used.
pub const MIN_RECT_LIGHT_WIDTH: f64 = 1e-6;
