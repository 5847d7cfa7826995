//! The 4D coverage texture of Paper III §3.3 (Figure 10): the coverage of a rectangular light
//! as a function `f(x1, y1, x2, y2)` of the projected, clipped edge, discretized and stored as
//! an 8-bit 2D texture of n×n sub-textures of n×n texels.
//!
//! # Representation
//!
//! The light square `[−1, 1]²` (light coordinates of [`crate::light::coverage`]) is discretized
//! into n×n *texel positions* on a regular grid that includes the border:
//! `s_i = −1 + 2i/(n − 1)`, `i = 0 … n − 1` (same for `t`). (The paper says "discretized into
//! n×n texel positions"; putting the outermost positions on the border is our choice: the
//! clipped endpoints of most projected edges lie on the border, where a grid of cell centers
//! would need extrapolation.) Sub-texture `(a, b)` holds the first endpoint at `(s_a, t_b)`,
//! its texel `(i, j)` the second endpoint at `(s_i, t_j)`; the sub-textures are tiled into one
//! `n² × n²` texture, big-texture column `a·n + i`, row `b·n + j`. Each texel stores
//! `round(255·f)` with `f` = [`segment_coverage`](crate::light::coverage::segment_coverage) computed by exact clipping (n = 32: 1024×1024
//! bytes, 1 MB). The texture does not depend on the light's size or aspect: area ratios are
//! affine invariant, so one texture per `n` serves every rectangular light.
//!
//! **Textured lights** (§3.3): the light's RGB texture is first resampled to n×n texels (nearest,
//! at the texel-cell centers, with the convention of [`crate::light::sampling`]: texel (0,0) at
//! the corner `center − u + v`). Each coverage texel then stores, per channel, the light-texture
//! weighted area of the same region — the sum over light cells of `area(region ∩ cell) ·
//! colour` — divided by that channel's total over the whole light, rounded to 8 bits: three
//! bytes per texel, 3 MB at n = 32. A channel that emits nothing stores 0.
//!
//! # Lookup (§3.3)
//!
//! The clipped endpoints are mapped to grid coordinates `g = (s + 1)/2 · (n − 1)`.
//! [`CoverageFilter::Nearest`] rounds both endpoints to the nearest position (half away from
//! zero); [`CoverageFilter::Bilinear`] rounds the first and filters the second bilinearly inside
//! its sub-texture; [`CoverageFilter::Quadrilinear`] filters the first endpoint bilinearly over
//! the four nearest sub-textures, each looked up bilinearly ("quadlinear filtering"). Weights
//! and sums are f64 on the texel values / 255.
//!
//! # Cache
//!
//! A texture is computed once per shape key — `n` and, for textured lights, the resampled
//! light texture — and kept for the life of the process ([`coverage_texture`]); a video
//! sequence that shows the same frame again re-uses its texture. It is also kept on disk
//! across processes ([`crate::light::texture_cache`], keyed by the exact inputs and a
//! fingerprint of this computation's source). The computation is a pure function of the key
//! (texels computed in parallel, each independently), so neither cache can change any bit.

use crate::light::coverage::{polygon_area, segment_region};
use crate::light::texture_cache;
use crate::progress::Progress;
use crate::scene::RgbTexture;
use glam::DVec2;
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::Path;
use std::sync::{Arc, Mutex, OnceLock};

/// Smallest selectable `n`.
pub const MIN_N: u32 = 8;
/// Largest selectable `n`.
pub const MAX_N: u32 = 64;
/// The paper's `n` (§3.3: "In practice, we use n = 32").
pub const DEFAULT_N: u32 = 32;

/// How the coverage texture is sampled (module doc, "Lookup").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum CoverageFilter {
    /// Nearest position for both endpoints.
    Nearest,
    /// Nearest sub-texture, bilinear inside it.
    Bilinear,
    /// Bilinear over the four nearest sub-textures, each bilinear.
    Quadrilinear,
}

/// What a coverage texture is computed for (module doc, "Cache").
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct CoverageTextureKey {
    /// Texel positions per side of the light.
    pub n: u32,
    /// The light texture resampled to n×n (row-major, row 0 at `t = +1`), as f32 bits; `None`
    /// for a uniform light.
    pub light_texels: Option<Vec<[u32; 3]>>,
}

impl CoverageTextureKey {
    /// The key of a uniform rectangular light.
    pub fn uniform(n: u32) -> Self {
        CoverageTextureKey {
            n,
            light_texels: None,
        }
    }

    /// The key of a textured light: its texture resampled to n×n (module doc).
    pub fn textured(n: u32, texture: &RgbTexture) -> Self {
        let mut texels = Vec::with_capacity((n * n) as usize);
        for row in 0..n {
            for col in 0..n {
                let tx = (((col as f64 + 0.5) / n as f64 * texture.width as f64) as u32)
                    .min(texture.width - 1);
                let ty = (((row as f64 + 0.5) / n as f64 * texture.height as f64) as u32)
                    .min(texture.height - 1);
                let c = texture.texels[(ty * texture.width + tx) as usize];
                texels.push(c.map(f32::to_bits));
            }
        }
        CoverageTextureKey {
            n,
            light_texels: Some(texels),
        }
    }
}

/// A computed 4D coverage texture (module doc, "Representation").
#[derive(Debug, Clone, PartialEq)]
pub struct CoverageTexture {
    /// Texel positions per side.
    pub n: u32,
    /// 1 (uniform light) or 3 (RGB) channels per texel.
    pub channels: u32,
    /// The `n² × n²` texture, row-major, `channels` bytes per texel.
    pub texels: Vec<u8>,
}

impl CoverageTexture {
    /// Compute the texture for `key` (module doc). `key.n` must be in `MIN_N..=MAX_N`.
    pub fn compute(key: &CoverageTextureKey) -> CoverageTexture {
        Self::compute_with_progress(key, None)
    }

    /// [`Self::compute`], advancing `progress` by one per row of the big texture (n² rows).
    fn compute_with_progress(
        key: &CoverageTextureKey,
        progress: Option<&Progress>,
    ) -> CoverageTexture {
        let n = key.n as usize;
        assert!((MIN_N as usize..=MAX_N as usize).contains(&n));
        let side = n * n;
        let weights = key.light_texels.as_ref().map(|t| LightWeights::new(n, t));
        let channels = if weights.is_some() { 3 } else { 1 };
        let texels: Vec<u8> = (0..side)
            .into_par_iter()
            .flat_map_iter(|row| {
                let (b, j) = (row / n, row % n);
                let weights = &weights;
                if let Some(p) = progress {
                    p.advance(1);
                }
                (0..side).flat_map(move |col| {
                    let (a, i) = (col / n, col % n);
                    let region = segment_region(grid_point(n, a, b), grid_point(n, i, j));
                    let values: Vec<f64> = match weights {
                        None => vec![polygon_area(&region) / 4.0],
                        Some(w) => w.coverage(&region).to_vec(),
                    };
                    values.into_iter().map(|f| (f * 255.0).round() as u8)
                })
            })
            .collect();
        CoverageTexture {
            n: key.n,
            channels,
            texels,
        }
    }

    /// Bytes of storage (n = 32: 1 MB grey, 3 MB RGB).
    pub fn bytes(&self) -> usize {
        self.texels.len()
    }

    /// The coverage of the clipped edge `p1 → p2` (light coordinates in `[−1, 1]²`) per
    /// channel, looked up with `filter` (module doc, "Lookup"); unsigned. Grey textures
    /// replicate their channel.
    pub fn lookup(&self, p1: DVec2, p2: DVec2, filter: CoverageFilter) -> [f64; 3] {
        let g1 = self.grid(p1);
        let g2 = self.grid(p2);
        // What the fragment program executes (crate::gpu::shader_ops): one fetch for the
        // nearest and bilinear filters; the quadrilinear filter is four bilinear fetches
        // blended by the program (a MUL and three MADs).
        match filter {
            CoverageFilter::Nearest | CoverageFilter::Bilinear => crate::gpu::shader_ops::fetch(),
            CoverageFilter::Quadrilinear => {
                (0..4).for_each(|_| crate::gpu::shader_ops::fetch());
                crate::gpu::shader_ops::alu(4);
            }
        }
        match filter {
            CoverageFilter::Nearest => self.texel(nearest(g1), nearest(g2)),
            CoverageFilter::Bilinear => self.bilinear_second(nearest(g1), g2),
            CoverageFilter::Quadrilinear => {
                let mut sum = [0.0; 3];
                for (first, w) in self.bilinear_taps(g1) {
                    let v = self.bilinear_second(first, g2);
                    for k in 0..3 {
                        sum[k] += w * v[k];
                    }
                }
                sum
            }
        }
    }

    fn grid(&self, p: DVec2) -> DVec2 {
        let m = (self.n - 1) as f64;
        ((p + DVec2::ONE) * 0.5 * m).clamp(DVec2::ZERO, DVec2::splat(m))
    }

    /// The four grid positions around `g` with their bilinear weights, in a fixed order.
    fn bilinear_taps(&self, g: DVec2) -> [([usize; 2], f64); 4] {
        let last = self.n as usize - 2;
        let x0 = (g.x.floor() as usize).min(last);
        let y0 = (g.y.floor() as usize).min(last);
        let fx = g.x - x0 as f64;
        let fy = g.y - y0 as f64;
        [
            ([x0, y0], (1.0 - fx) * (1.0 - fy)),
            ([x0 + 1, y0], fx * (1.0 - fy)),
            ([x0, y0 + 1], (1.0 - fx) * fy),
            ([x0 + 1, y0 + 1], fx * fy),
        ]
    }

    fn bilinear_second(&self, first: [usize; 2], g2: DVec2) -> [f64; 3] {
        let mut sum = [0.0; 3];
        for (second, w) in self.bilinear_taps(g2) {
            let v = self.texel(first, second);
            for k in 0..3 {
                sum[k] += w * v[k];
            }
        }
        sum
    }

    fn texel(&self, first: [usize; 2], second: [usize; 2]) -> [f64; 3] {
        let n = self.n as usize;
        let row = first[1] * n + second[1];
        let col = first[0] * n + second[0];
        let ch = self.channels as usize;
        let at = (row * n * n + col) * ch;
        let v = |k: usize| self.texels[at + k.min(ch - 1)] as f64 / 255.0;
        [v(0), v(1), v(2)]
    }
}

/// An upper bound on `|lookup(p1, p2, filter) − segment_coverage(p1, p2)|` for a **uniform**
/// light with `n` texel positions per side, derived from the grid alone (no measurement), or
/// `None` where no bound holds.
///
/// Derivation. A lookup reads texels whose endpoints `a′, b′` lie within `r₁` of `a = p1` and
/// `r₂` of `b = p2`: `r = h/√2` for a rounded endpoint and `r = h√2` for a bilinearly filtered
/// one (a corner of its grid cell), with the spacing `h = 2/(n − 1)`. Filtering is a convex
/// combination of such texels, so it suffices to bound one texel. Each texel stores
/// `segment_coverage(a′, b′)` rounded to 8 bits (error ≤ ½/255). The region of
/// [`segment_coverage`](crate::light::coverage::segment_coverage) is the part of the light
/// square beyond the segment inside the cone from the center through its endpoints, so the
/// symmetric difference of the regions of `a b` and `a′ b′` lies in
/// - the two sectors between the rays through `a, a′` and through `b, b′`: inside the square
///   (radius ≤ √2) each has area ≤ ½·2·Δθ, with `Δθ ≤ asin(r/|p|)`;
/// - the part between the two segments, inside the stadium `a b ⊕ disk(max r)`:
///   area ≤ 2·max r·|a b| + π·(max r)².
///
/// Coverage is area / 4. This holds only while `a′ b′` keeps the orientation of `a b` (else
/// the region switches to the other side of the center: the jump of module doc "Lookup",
/// where filtered lookups blend both sides). `|a′×b′ − a×b| ≤ r₁|b| + r₂|a| + r₁r₂`, so the
/// bound is returned only where `|a×b|` exceeds that (which also gives `|a| > r₁`,
/// `|b| > r₂`).
pub fn lookup_error_bound(n: u32, filter: CoverageFilter, p1: DVec2, p2: DVec2) -> Option<f64> {
    let h = 2.0 / (n as f64 - 1.0);
    let rounded = h * std::f64::consts::FRAC_1_SQRT_2;
    let filtered = h * std::f64::consts::SQRT_2;
    let (r1, r2) = match filter {
        CoverageFilter::Nearest => (rounded, rounded),
        CoverageFilter::Bilinear => (rounded, filtered),
        CoverageFilter::Quadrilinear => (filtered, filtered),
    };
    let (la, lb) = (p1.length(), p2.length());
    if p1.perp_dot(p2).abs() <= r1 * lb + r2 * la + r1 * r2 {
        return None;
    }
    let sectors = libm::asin(r1 / la) + libm::asin(r2 / lb);
    let r = r1.max(r2);
    let between = 2.0 * r * (p2 - p1).length() + std::f64::consts::PI * r * r;
    Some(0.5 / 255.0 + (sectors + between) / 4.0)
}

/// The cached texture for `key` (module doc, "Cache"): from this process's cache, else from
/// the disk cache ([`crate::light::texture_cache`]), else computed — with a progress bar on a
/// terminal — and stored in both.
pub fn coverage_texture(key: &CoverageTextureKey) -> Arc<CoverageTexture> {
    static CACHE: OnceLock<Mutex<HashMap<CoverageTextureKey, Arc<CoverageTexture>>>> =
        OnceLock::new();
    let cache = CACHE.get_or_init(|| Mutex::new(HashMap::new()));
    if let Some(t) = cache.lock().unwrap_or_else(|e| e.into_inner()).get(key) {
        return t.clone();
    }
    // Loaded or computed outside the lock (it takes a while); a concurrent computation of the
    // same key yields the same bits, and the first one stored wins.
    let t = Arc::new(load_or_compute(key, texture_cache::cache_dir().as_deref()));
    cache
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .entry(key.clone())
        .or_insert(t)
        .clone()
}

/// The texture of `key` from the disk cache in `dir`, or computed and stored there (a failed
/// store is ignored: it only costs the next process the computation). `dir = None`: computed.
pub fn load_or_compute(key: &CoverageTextureKey, dir: Option<&Path>) -> CoverageTexture {
    if let Some(t) = dir.and_then(|d| texture_cache::load(d, key)) {
        return t;
    }
    let kind = if key.light_texels.is_some() {
        "RGB"
    } else {
        "grey"
    };
    let rows = (key.n as usize).pow(2);
    let progress = Progress::new(rows, &format!("coverage texture n = {} ({kind})", key.n));
    let t = CoverageTexture::compute_with_progress(key, Some(&progress));
    progress.finish();
    if let Some(d) = dir {
        let _ = texture_cache::store(d, key, &t);
    }
    t
}

/// Grid position `(s_a, t_b)` (module doc).
fn grid_point(n: usize, a: usize, b: usize) -> DVec2 {
    let m = (n - 1) as f64;
    DVec2::new(-1.0 + 2.0 * a as f64 / m, -1.0 + 2.0 * b as f64 / m)
}

fn nearest(g: DVec2) -> [usize; 2] {
    [g.x.round() as usize, g.y.round() as usize]
}

/// The resampled light texture as per-cell weights (module doc, "Textured lights").
struct LightWeights {
    n: usize,
    /// Row-major, row 0 at `t = +1`.
    colour: Vec<[f64; 3]>,
    /// Row-major, `n + 1` entries per row: `prefix[row·(n+1) + k]` is the colour integrated
    /// along the row from `s = −1` to the left side of column `k` (per unit height).
    prefix: Vec<[f64; 3]>,
    /// Per channel: the sum of colour × cell area over the light.
    total: [f64; 3],
}

impl LightWeights {
    fn new(n: usize, texels: &[[u32; 3]]) -> Self {
        let colour: Vec<[f64; 3]> = texels
            .iter()
            .map(|c| c.map(|b| f32::from_bits(b) as f64))
            .collect();
        let step = 2.0 / n as f64;
        let cell = step * step;
        let mut total = [0.0; 3];
        for c in &colour {
            for k in 0..3 {
                total[k] += c[k] * cell;
            }
        }
        let mut prefix = Vec::with_capacity(n * (n + 1));
        for row in 0..n {
            let mut run = [0.0; 3];
            prefix.push(run);
            for col in 0..n {
                for k in 0..3 {
                    run[k] += colour[row * n + col][k] * step;
                }
                prefix.push(run);
            }
        }
        LightWeights {
            n,
            colour,
            prefix,
            total,
        }
    }

    /// Per channel, the colour-weighted area of the convex `region` (inside the light square)
    /// over the light's total.
    ///
    /// Green's theorem: with `C(s, t) = ∫_{−1}^{s} colour(σ, t) dσ` (piecewise linear in `s`
    /// along a row, from the row's prefix sums), `∬_R colour dA = ∮_{∂R} C dt`. Each boundary
    /// edge is split where it crosses a row or column line; on every piece `C` is linear in
    /// the parameter, so the trapezoid rule integrates it exactly. The cost per region is
    /// linear in `n` (the cells its boundary crosses), where clipping the region against every
    /// cell it covers was quadratic — `texture-n = 64` for a textured light took over 400 s
    /// that way and takes seconds now.
    fn coverage(&self, region: &[DVec2]) -> [f64; 3] {
        let mut out = [0.0; 3];
        if region.len() < 3 {
            return out;
        }
        let mut sum = [0.0; 3];
        let mut cuts = Vec::with_capacity(2 * self.n + 2);
        for i in 0..region.len() {
            let piece =
                self.boundary_integral(region[i], region[(i + 1) % region.len()], &mut cuts);
            for k in 0..3 {
                sum[k] += piece[k];
            }
        }
        // A clockwise region integrates to minus its weight.
        let orientation = (0..region.len())
            .map(|i| region[i].perp_dot(region[(i + 1) % region.len()]))
            .sum::<f64>()
            .signum();
        for k in 0..3 {
            if self.total[k] > 0.0 {
                out[k] = (orientation * sum[k] / self.total[k]).clamp(0.0, 1.0);
            }
        }
        out
    }

    /// `∫ C dt` along the segment `p → q` (see [`Self::coverage`]); `cuts` is scratch space.
    fn boundary_integral(&self, p: DVec2, q: DVec2, cuts: &mut Vec<f64>) -> [f64; 3] {
        let mut sum = [0.0; 3];
        let d = q - p;
        if d.y == 0.0 {
            return sum;
        }
        let n = self.n;
        let step = 2.0 / n as f64;
        // Parameters in (0, 1) where the segment crosses a grid line.
        cuts.clear();
        cuts.push(0.0);
        for (from, delta) in [(p.x, d.x), (p.y, d.y)] {
            if delta == 0.0 {
                continue;
            }
            let (lo, hi) = (from.min(from + delta), from.max(from + delta));
            let first = ((lo + 1.0) / step).floor().max(0.0) as usize + 1;
            let last = (((hi + 1.0) / step).ceil().max(0.0) as usize).min(n);
            for k in first..last {
                let u = (-1.0 + step * k as f64 - from) / delta;
                if u > 0.0 && u < 1.0 {
                    cuts.push(u);
                }
            }
        }
        cuts.push(1.0);
        cuts.sort_by(f64::total_cmp);
        for w in cuts.windows(2) {
            let (u0, u1) = (w[0], w[1]);
            if u1 <= u0 {
                continue;
            }
            // The cell of the piece, from its midpoint.
            let mid = p + d * (0.5 * (u0 + u1));
            let col = (((mid.x + 1.0) / step).floor().max(0.0) as usize).min(n - 1);
            let row = n - 1 - (((mid.y + 1.0) / step).floor().max(0.0) as usize).min(n - 1);
            let left = -1.0 + step * col as f64;
            let base = self.prefix[row * (n + 1) + col];
            let c = self.colour[row * n + col];
            let (x0, x1) = (p.x + d.x * u0, p.x + d.x * u1);
            let dt = d.y * (u1 - u0);
            for k in 0..3 {
                let c0 = base[k] + (x0 - left) * c[k];
                let c1 = base[k] + (x1 - left) * c[k];
                sum[k] += 0.5 * (c0 + c1) * dt;
            }
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::polygon_clip::clip_polygon_to_box;

    /// The colour-weighted area of `region` by clipping it against every light cell — the
    /// direct definition, against which the Green's-theorem sum is checked.
    fn coverage_by_cells(w: &LightWeights, region: &[DVec2]) -> [f64; 3] {
        let step = 2.0 / w.n as f64;
        let mut sum = [0.0; 3];
        for row in 0..w.n {
            let top = 1.0 - step * row as f64;
            for col in 0..w.n {
                let left = -1.0 + step * col as f64;
                let cell = clip_polygon_to_box(
                    region,
                    DVec2::new(left, top - step),
                    DVec2::new(left + step, top),
                );
                if cell.len() >= 3 {
                    let area = polygon_area(&cell);
                    for (s, c) in sum.iter_mut().zip(w.colour[row * w.n + col]) {
                        *s += area * c;
                    }
                }
            }
        }
        std::array::from_fn(|k| {
            if w.total[k] > 0.0 {
                (sum[k] / w.total[k]).min(1.0)
            } else {
                0.0
            }
        })
    }

    /// Green's theorem along the region's boundary equals clipping it against every cell,
    /// for regions of every kind the texture stores (both orientations, corners of the square,
    /// endpoints on grid lines) and a light texture with a dark channel and a zero texel.
    #[test]
    fn boundary_integral_equals_the_cell_by_cell_area() {
        for n in [8usize, 13, 32] {
            let texels: Vec<[u32; 3]> = (0..n * n)
                .map(|i| {
                    let r = ((i * 37 + 11) % 17) as f32 / 16.0;
                    let g = if i % 5 == 0 {
                        0.0
                    } else {
                        ((i * 7) % 13) as f32 / 12.0
                    };
                    [r.to_bits(), g.to_bits(), 0.25f32.to_bits()]
                })
                .collect();
            let w = LightWeights::new(n, &texels);
            let mut checked = 0;
            for a in 0..9 {
                for b in 0..9 {
                    for (i, j) in [(0, 3), (5, 8), (8, 1), (2, 2), (7, 0)] {
                        let p = grid_point(9, a, b) * 0.999 + DVec2::new(0.0003, -0.0007);
                        let q = grid_point(9, i, j);
                        for (p, q) in [(p, q), (q, p)] {
                            let region = segment_region(p, q);
                            let fast = w.coverage(&region);
                            let slow = coverage_by_cells(&w, &region);
                            for k in 0..3 {
                                assert!(
                                    (fast[k] - slow[k]).abs() < 1e-12,
                                    "n {n} {p} {q} ch {k}: {} vs {}",
                                    fast[k],
                                    slow[k]
                                );
                            }
                            checked += usize::from(region.len() >= 3);
                        }
                    }
                }
            }
            assert!(checked > 600, "{checked}");
        }
    }

    #[test]
    fn white_textured_light_matches_the_grey_texture() {
        let white = RgbTexture {
            width: 3,
            height: 2,
            texels: vec![[1.0; 3]; 6],
            source: "white".into(),
        };
        let grey = CoverageTexture::compute(&CoverageTextureKey::uniform(8));
        let rgb = CoverageTexture::compute(&CoverageTextureKey::textured(8, &white));
        assert_eq!(rgb.bytes(), 3 * grey.bytes());
        let n = 8;
        for (i, g) in grey.texels.iter().enumerate() {
            let (row, col) = (i / (n * n), i % (n * n));
            let a = grid_point(n, col / n, row / n);
            let b = grid_point(n, col % n, row % n);
            if a.perp_dot(b).abs() < 1e-9 {
                // The line through the center: the stored function jumps there (module doc of
                // `coverage`), so either side's value is a valid rounding of it.
                continue;
            }
            for k in 0..3 {
                // Summed per light cell instead of once: f64 rounding may move a value that
                // sits on a rounding boundary by one 8-bit step.
                assert!(rgb.texels[3 * i + k].abs_diff(*g) <= 1, "texel {i}");
            }
        }
    }
}
