//! Stratified point samples on an area light: the sample positions of the papers' reference
//! (`nsample`, "1024-sample shadows", Paper III §5.1) and of the ray-cast ground truth
//! (`raycast`, `docs/architecture.md` "Methods").
//!
//! # Representation
//!
//! `n = k×k` samples, one per stratum of a k×k grid over the parameter square `[-1,1]²`.
//! Stratum `(i, j)` covers `s ∈ [-1 + 2i/k, -1 + 2(i+1)/k]`, `t ∈ [-1 + 2j/k, -1 + 2(j+1)/k]`;
//! samples are returned in row-major stratum order, index `j·k + i` (`i` runs fastest).
//! Inside its stratum a sample sits at the stratum center ([`Pattern::Centered`]) or at a
//! hashed offset ([`Pattern::Jittered`]). The square is then mapped onto the light:
//!
//! - **Rect / TexturedRect** (Papers III, IV, Forest 2006): `center + s·u + t·v`.
//! - **Disk** (CGI 2004): Shirley–Chiu concentric mapping of `(s, t)` onto the unit disk,
//!   scaled by the radius, in the plane ⟂ `normal` spanned by the basis of [`orthonormal_basis`].
//! - **Sphere** (Papers I, II, IV §4.2.1): "the sphere seen from a point is the disk through
//!   its center perpendicular to the view direction" — the disk of the sphere's radius through
//!   the center whose normal points `toward` the receiver, sampled like a disk.
//! - **Point**: one sample at the center.
//!
//! # Weights
//!
//! Each sample carries an RGB weight; the weights of one sample set sum to 1 per channel (up to
//! f32 rounding). Uniform lights give every sample `1/n`. A textured light (Paper III §3.3:
//! every texel is a small light) gives each sample the texel under it, sampled *nearest*:
//! column `⌊(s+1)/2 · W⌋`, row `⌊(1−t)/2 · H⌋` (both clamped into the texture), so texel
//! (0,0) is at the corner `center − u + v` and columns run along `u`, as
//! [`crate::scene::LightShape::TexturedRect`] states. The texel values are normalised per
//! channel over the sample set; a channel whose sampled texels sum to 0 gets weight 0 on every
//! sample (that channel emits nothing, its visibility is reported as 0).
//!
//! # Determinism
//!
//! All arithmetic is done in f64 and each position is rounded to f32 once. The jitter is a pure
//! function of `(seed, stratum index)` (splitmix64), so no RNG state is shared between threads
//! and any subset of the samples can be computed independently. The Shirley–Chiu mapping uses
//! the platform's f64 `sin`/`cos` — deterministic on one machine kind, and the only place where
//! the bits may depend on the math library.

use crate::scene::{Light, LightShape, RgbTexture};
use glam::{DVec3, Vec3};

/// One point sample of an area light with its per-channel weight; the weights of a sample set
/// sum to 1 per channel (see the module doc, "Weights").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    /// The sample position in world space.
    pub position: Vec3,
    /// Per-channel (RGB) weight of the sample in [0, 1].
    pub weight: [f32; 3],
}

/// How the n samples are placed inside their strata (module doc, "Representation").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pattern {
    /// Every sample at its stratum center: the regular grid `nsample` uses (Paper III §5.1).
    Centered,
    /// Every sample at a uniformly distributed offset inside its stratum, hashed from
    /// `seed` and the stratum index with splitmix64 (used by `raycast` so that its estimate is
    /// independent of `nsample`'s grid).
    Jittered {
        /// The seed; the same seed gives the same samples, bit for bit.
        seed: u64,
    },
}

/// `n` stratified samples on `light` (module doc). `n` must be a perfect square `k×k` with
/// `k ≥ 1` (an error string otherwise), except for a point light, which always yields its
/// center with weight 1 and ignores `n`. `toward` is only used by sphere lights: the point the
/// sphere is seen from (Paper IV §4.2.1).
///
/// Stratum `(i, j)` (index `j·k + i`) maps to `s` along `u`, `t` along `v` for rectangles;
/// disks and spheres use the Shirley–Chiu concentric map of the same square.
pub fn stratified(
    light: &Light,
    n: u32,
    pattern: Pattern,
    toward: Vec3,
) -> Result<Vec<LightSample>, String> {
    if let LightShape::Point = light.shape {
        return Ok(vec![LightSample {
            position: light.center,
            weight: [1.0; 3],
        }]);
    }
    let k = grid_side(n)?;
    let center = light.center.as_dvec3();
    let squares = square_samples(k, pattern);
    let uniform = [1.0 / f64::from(n) as f32; 3];
    let samples = match &light.shape {
        LightShape::Point => unreachable!("handled above"),
        LightShape::Rect { u, v } => {
            let (u, v) = (u.as_dvec3(), v.as_dvec3());
            squares
                .iter()
                .map(|&(s, t)| LightSample {
                    position: rect_point(center, u, v, s, t),
                    weight: uniform,
                })
                .collect()
        }
        LightShape::TexturedRect { u, v, texture } => {
            let (u, v) = (u.as_dvec3(), v.as_dvec3());
            let texels: Vec<[f32; 3]> = squares
                .iter()
                .map(|&(s, t)| nearest_texel(texture, s, t))
                .collect();
            let weights = normalised_weights(&texels);
            squares
                .iter()
                .zip(weights)
                .map(|(&(s, t), weight)| LightSample {
                    position: rect_point(center, u, v, s, t),
                    weight,
                })
                .collect()
        }
        LightShape::Disk { radius, normal } => disk_samples(
            center,
            f64::from(*radius),
            normal.as_dvec3(),
            &squares,
            uniform,
        ),
        LightShape::Sphere { radius } => disk_samples(
            center,
            f64::from(*radius),
            sphere_disk_normal(center, toward),
            &squares,
            uniform,
        ),
    };
    Ok(samples)
}

/// A convex quadrilateral, corners in order around it, that contains every sample
/// [`stratified`] returns for `light` seen from `toward` (up to the f32 rounding of the sample
/// positions); `None` for a point light. Rectangles give their own corners, disks and spheres
/// the square circumscribing their (facing) disk in the basis of [`orthonormal_basis`]. The
/// ray-cast reference culls with the convex hull of a receiver and this quadrilateral.
pub fn bounding_quad(light: &Light, toward: Vec3) -> Option<[DVec3; 4]> {
    let center = light.center.as_dvec3();
    let (u, v) = match &light.shape {
        LightShape::Point => return None,
        LightShape::Rect { u, v } | LightShape::TexturedRect { u, v, .. } => {
            (u.as_dvec3(), v.as_dvec3())
        }
        LightShape::Disk { radius, normal } => {
            let (b1, b2) = orthonormal_basis(normal.as_dvec3());
            (f64::from(*radius) * b1, f64::from(*radius) * b2)
        }
        LightShape::Sphere { radius } => {
            let (b1, b2) = orthonormal_basis(sphere_disk_normal(center, toward));
            (f64::from(*radius) * b1, f64::from(*radius) * b2)
        }
    };
    Some([
        center - u - v,
        center + u - v,
        center + u + v,
        center - u + v,
    ])
}

/// The normal of the disk that stands for a sphere light seen from `toward` (Paper IV
/// §4.2.1: the disk through the center perpendicular to the view direction). A point exactly
/// at the center has no view direction; +Z is used then.
fn sphere_disk_normal(center: DVec3, toward: Vec3) -> DVec3 {
    let view = toward.as_dvec3() - center;
    if view.length_squared() > 0.0 {
        view
    } else {
        DVec3::Z
    }
}

/// `k` with `k·k = n`, `k ≥ 1`, or an error naming `n`.
fn grid_side(n: u32) -> Result<u32, String> {
    let k = n.isqrt();
    if n == 0 || k * k != n {
        return Err(format!(
            "the number of light samples must be a perfect square k×k ≥ 1, got {n}"
        ));
    }
    Ok(k)
}

/// The `(s, t)` ∈ `[-1,1]²` of every stratum in row-major order (index `j·k + i`).
fn square_samples(k: u32, pattern: Pattern) -> Vec<(f64, f64)> {
    let kf = f64::from(k);
    let mut out = Vec::with_capacity((k * k) as usize);
    for j in 0..k {
        for i in 0..k {
            let (a, b) = match pattern {
                Pattern::Centered => (0.5, 0.5),
                Pattern::Jittered { seed } => jitter(seed, u64::from(j * k + i)),
            };
            let s = -1.0 + 2.0 * (f64::from(i) + a) / kf;
            let t = -1.0 + 2.0 * (f64::from(j) + b) / kf;
            out.push((s, t));
        }
    }
    out
}

/// splitmix64 (Steele, Lea & Flood 2014): one step of the generator as a 64-bit mixer.
pub(crate) fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The two offsets in [0,1) of stratum `index` for `seed`: 53-bit uniforms from two chained
/// splitmix64 hashes of `seed` and the index.
fn jitter(seed: u64, index: u64) -> (f64, f64) {
    let h1 = splitmix64(seed ^ splitmix64(index));
    let h2 = splitmix64(h1);
    let unit = |h: u64| (h >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
    (unit(h1), unit(h2))
}

/// `center + s·u + t·v`, rounded to f32 once.
fn rect_point(center: DVec3, u: DVec3, v: DVec3, s: f64, t: f64) -> Vec3 {
    (center + s * u + t * v).as_vec3()
}

/// The texel under `(s, t)`, nearest sampling: texel (0,0) at `s = −1, t = +1` (the corner
/// `center − u + v`), columns along `u`, rows downwards along `−v`.
fn nearest_texel(texture: &RgbTexture, s: f64, t: f64) -> [f32; 3] {
    let (w, h) = (texture.width, texture.height);
    if w == 0 || h == 0 {
        return [0.0; 3];
    }
    let col = (((s + 1.0) * 0.5 * f64::from(w)).floor().max(0.0) as u32).min(w - 1);
    let row = (((1.0 - t) * 0.5 * f64::from(h)).floor().max(0.0) as u32).min(h - 1);
    texture.texels[(row * w + col) as usize]
}

/// Per-channel weights `texel / Σ texels` (f64 sum in sample order); a channel whose sum is
/// not positive gets 0 everywhere.
fn normalised_weights(texels: &[[f32; 3]]) -> Vec<[f32; 3]> {
    let mut sums = [0.0f64; 3];
    for t in texels {
        for c in 0..3 {
            sums[c] += f64::from(t[c].max(0.0));
        }
    }
    texels
        .iter()
        .map(|t| {
            let mut w = [0.0f32; 3];
            for c in 0..3 {
                if sums[c] > 0.0 {
                    w[c] = (f64::from(t[c].max(0.0)) / sums[c]) as f32;
                }
            }
            w
        })
        .collect()
}

/// Shirley & Chiu, "A Low Distortion Map Between Disk and Square" (JGT 1997), in the form of
/// Shirley's 2011 note: maps `[-1,1]²` onto the unit disk, stratum boundaries to curves that
/// keep the strata of equal area.
fn concentric_disk(s: f64, t: f64) -> (f64, f64) {
    use std::f64::consts::FRAC_PI_4;
    if s == 0.0 && t == 0.0 {
        return (0.0, 0.0);
    }
    let (r, phi) = if s.abs() > t.abs() {
        (s, FRAC_PI_4 * (t / s))
    } else {
        (t, 2.0 * FRAC_PI_4 - FRAC_PI_4 * (s / t))
    };
    (r * libm::cos(phi), r * libm::sin(phi))
}

/// A right-handed orthonormal basis `(b1, b2)` with `b1 × b2 = n̂` for the direction `n`
/// (normalised here), after Duff, Burgess, Christensen, Hery, Kensler, Liani & Villemin,
/// "Building an Orthonormal Basis, Revisited" (JCGT 2017): branch-free except for the sign of
/// `n.z`, continuous everywhere else, and a pure function of `n`, so every disk and sphere
/// light gets the same basis on every run.
pub fn orthonormal_basis(n: DVec3) -> (DVec3, DVec3) {
    let n = n.normalize();
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let b1 = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let b2 = DVec3::new(b, sign + n.y * n.y * a, -n.y);
    (b1, b2)
}

/// Samples of the disk of `radius` around `center` in the plane ⟂ `normal`.
fn disk_samples(
    center: DVec3,
    radius: f64,
    normal: DVec3,
    squares: &[(f64, f64)],
    weight: [f32; 3],
) -> Vec<LightSample> {
    let (b1, b2) = orthonormal_basis(normal);
    squares
        .iter()
        .map(|&(s, t)| {
            let (x, y) = concentric_disk(s, t);
            let position = (center + radius * (x * b1 + y * b2)).as_vec3();
            LightSample { position, weight }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect_light() -> Light {
        Light {
            center: Vec3::new(1.0, 5.0, -2.0),
            shape: LightShape::Rect {
                u: Vec3::new(0.5, 0.0, 0.0),
                v: Vec3::new(0.0, 0.0, 0.25),
            },
        }
    }

    fn weight_sums(samples: &[LightSample]) -> [f64; 3] {
        let mut s = [0.0; 3];
        for x in samples {
            for (sum, w) in s.iter_mut().zip(x.weight) {
                *sum += f64::from(w);
            }
        }
        s
    }

    /// (s, t) of a rect sample, for orthogonal u, v.
    fn rect_coords(light: &Light, p: Vec3) -> (f64, f64) {
        let (LightShape::Rect { u, v } | LightShape::TexturedRect { u, v, .. }) = &light.shape
        else {
            panic!("not a rect")
        };
        let d = (p - light.center).as_dvec3();
        (
            d.dot(u.as_dvec3()) / u.as_dvec3().length_squared(),
            d.dot(v.as_dvec3()) / v.as_dvec3().length_squared(),
        )
    }

    #[test]
    fn counts_and_errors() {
        let l = rect_light();
        for n in [1, 4, 16, 64, 256, 1024] {
            assert_eq!(
                stratified(&l, n, Pattern::Centered, Vec3::ZERO)
                    .unwrap()
                    .len(),
                n as usize
            );
        }
        for n in [0, 2, 3, 1000] {
            let e = stratified(&l, n, Pattern::Centered, Vec3::ZERO).unwrap_err();
            assert!(e.contains("perfect square"), "{e}");
        }
        let p = Light {
            center: Vec3::ONE,
            shape: LightShape::Point,
        };
        let s = stratified(&p, 7, Pattern::Jittered { seed: 3 }, Vec3::ZERO).unwrap();
        assert_eq!(
            s,
            vec![LightSample {
                position: Vec3::ONE,
                weight: [1.0; 3]
            }]
        );
    }

    #[test]
    fn rect_samples_inside_and_weights_sum_to_one() {
        let l = rect_light();
        for pattern in [Pattern::Centered, Pattern::Jittered { seed: 42 }] {
            let s = stratified(&l, 256, pattern, Vec3::ZERO).unwrap();
            for c in weight_sums(&s) {
                assert!((c - 1.0).abs() < 1e-6, "{c}");
            }
            for (idx, x) in s.iter().enumerate() {
                let (ss, tt) = rect_coords(&l, x.position);
                assert!(
                    ss.abs() <= 1.0 + 1e-6 && tt.abs() <= 1.0 + 1e-6,
                    "{ss} {tt}"
                );
                // The sample lies in its own stratum (i along u, j along v).
                let (i, j) = ((idx % 16) as f64, (idx / 16) as f64);
                let lo_s = -1.0 + 2.0 * i / 16.0;
                let lo_t = -1.0 + 2.0 * j / 16.0;
                assert!(
                    ss >= lo_s - 1e-6 && ss <= lo_s + 0.125 + 1e-6,
                    "{idx}: s {ss}"
                );
                assert!(
                    tt >= lo_t - 1e-6 && tt <= lo_t + 0.125 + 1e-6,
                    "{idx}: t {tt}"
                );
            }
        }
        // Centered 2×2: exactly the four quarter centers.
        let s = stratified(&l, 4, Pattern::Centered, Vec3::ZERO).unwrap();
        let st: Vec<_> = s.iter().map(|x| rect_coords(&l, x.position)).collect();
        assert_eq!(st, vec![(-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5)]);
    }

    #[test]
    fn disk_and_sphere_samples_in_plane_and_radius() {
        let normal = Vec3::new(0.3, -1.0, 0.2).normalize();
        let disk = Light {
            center: Vec3::new(0.0, 4.0, 1.0),
            shape: LightShape::Disk {
                radius: 0.7,
                normal,
            },
        };
        let toward = Vec3::new(2.0, -3.0, 0.5);
        let sphere = Light {
            center: Vec3::new(0.0, 4.0, 1.0),
            shape: LightShape::Sphere { radius: 0.7 },
        };
        let sphere_normal = (toward - sphere.center).normalize();
        for (light, n) in [(&disk, normal), (&sphere, sphere_normal)] {
            for pattern in [Pattern::Centered, Pattern::Jittered { seed: 7 }] {
                let s = stratified(light, 1024, pattern, toward).unwrap();
                assert_eq!(s.len(), 1024);
                for c in weight_sums(&s) {
                    assert!((c - 1.0).abs() < 1e-6);
                }
                let mut max_r = 0.0f32;
                for x in &s {
                    let d = x.position - light.center;
                    assert!(d.length() <= 0.7 * (1.0 + 1e-5), "{}", d.length());
                    assert!(d.dot(n).abs() < 1e-5, "off plane by {}", d.dot(n));
                    max_r = max_r.max(d.length());
                }
                assert!(max_r > 0.65, "samples should reach the rim, max {max_r}");
            }
        }
    }

    #[test]
    fn bounding_quad_contains_every_sample() {
        let toward = Vec3::new(2.0, -3.0, 0.5);
        let lights = [
            rect_light(),
            Light {
                center: Vec3::new(0.0, 4.0, 1.0),
                shape: LightShape::Disk {
                    radius: 0.7,
                    normal: Vec3::new(0.3, -1.0, 0.2).normalize(),
                },
            },
            Light {
                center: Vec3::new(0.0, 4.0, 1.0),
                shape: LightShape::Sphere { radius: 0.7 },
            },
        ];
        for light in &lights {
            let q = bounding_quad(light, toward).unwrap();
            // The quad's inward edge normals within its plane.
            let n = (q[1] - q[0]).cross(q[3] - q[0]);
            for x in stratified(light, 256, Pattern::Jittered { seed: 4 }, toward).unwrap() {
                let p = x.position.as_dvec3();
                assert!((p - q[0]).dot(n.normalize()).abs() < 1e-5);
                for i in 0..4 {
                    let (a, b) = (q[i], q[(i + 1) % 4]);
                    let inward = n.cross(b - a);
                    assert!((p - a).dot(inward.normalize()) > -1e-5, "{:?}", light.shape);
                }
            }
        }
        let point = Light {
            center: Vec3::ONE,
            shape: LightShape::Point,
        };
        assert_eq!(bounding_quad(&point, Vec3::ZERO), None);
    }

    #[test]
    fn concentric_map_preserves_stratum_areas() {
        // Equal-area strata: the mean squared radius of a fine grid is 1/2 (uniform disk).
        let s = square_samples(64, Pattern::Centered);
        let mean_r2: f64 = s
            .iter()
            .map(|&(a, b)| {
                let (x, y) = concentric_disk(a, b);
                x * x + y * y
            })
            .sum::<f64>()
            / s.len() as f64;
        assert!((mean_r2 - 0.5).abs() < 1e-3, "{mean_r2}");
    }

    #[test]
    fn basis_is_orthonormal_and_right_handed() {
        for n in [
            DVec3::Z,
            -DVec3::Z,
            DVec3::X,
            DVec3::new(1.0, 2.0, -3.0),
            DVec3::new(0.0, 1e-9, -1.0),
        ] {
            let (b1, b2) = orthonormal_basis(n);
            let nn = n.normalize();
            assert!((b1.length() - 1.0).abs() < 1e-12 && (b2.length() - 1.0).abs() < 1e-12);
            assert!(
                b1.dot(b2).abs() < 1e-12 && b1.dot(nn).abs() < 1e-12 && b2.dot(nn).abs() < 1e-12
            );
            assert!((b1.cross(b2) - nn).length() < 1e-12);
        }
    }

    #[test]
    fn textured_weights_follow_the_texture() {
        // 2×2 texture: top row (texel row 0, at +v) red, green; bottom row blue, black.
        let texture = RgbTexture {
            width: 2,
            height: 2,
            texels: vec![
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [0.0, 0.0, 0.0],
            ],
            source: "test".into(),
        };
        let light = Light {
            center: Vec3::ZERO,
            shape: LightShape::TexturedRect {
                u: Vec3::X,
                v: Vec3::Y,
                texture,
            },
        };
        let s = stratified(&light, 16, Pattern::Jittered { seed: 1 }, Vec3::ZERO).unwrap();
        let sums = weight_sums(&s);
        for c in sums {
            assert!((c - 1.0).abs() < 1e-6, "{sums:?}");
        }
        for x in &s {
            let p = x.position;
            // 4 of the 16 samples fall in each quadrant: weight 1/4 in its channel.
            let expect = match (p.x > 0.0, p.y > 0.0) {
                (false, true) => [0.25, 0.0, 0.0],
                (true, true) => [0.0, 0.25, 0.0],
                (false, false) => [0.0, 0.0, 0.25],
                (true, false) => [0.0, 0.0, 0.0],
            };
            assert_eq!(x.weight, expect, "at {p}");
        }
        // A black texture: every channel sums to 0, so every weight is 0.
        let LightShape::TexturedRect { u, v, texture } = &light.shape else {
            unreachable!()
        };
        let mut black = texture.clone();
        black.texels = vec![[0.0; 3]; 4];
        let dark = Light {
            center: Vec3::ZERO,
            shape: LightShape::TexturedRect {
                u: *u,
                v: *v,
                texture: black,
            },
        };
        let s = stratified(&dark, 4, Pattern::Centered, Vec3::ZERO).unwrap();
        assert!(s.iter().all(|x| x.weight == [0.0; 3]));
    }

    #[test]
    fn deterministic_and_seed_dependent() {
        let l = rect_light();
        let a = stratified(&l, 64, Pattern::Jittered { seed: 9 }, Vec3::ZERO).unwrap();
        let b = stratified(&l, 64, Pattern::Jittered { seed: 9 }, Vec3::ZERO).unwrap();
        let c = stratified(&l, 64, Pattern::Jittered { seed: 10 }, Vec3::ZERO).unwrap();
        assert_eq!(a, b);
        assert_ne!(a, c);
        // The jitter of stratum 0 for seed 0 is a fixed value: it must never change silently.
        let two53 = (1u64 << 53) as f64;
        assert_eq!(
            jitter(0, 0),
            (5876733520225071.0 / two53, 1249383295688599.0 / two53)
        );
        // Same samples computed in parallel: identical bits.
        use rayon::prelude::*;
        let par: Vec<_> = (0..8u64)
            .into_par_iter()
            .map(|_| stratified(&l, 64, Pattern::Jittered { seed: 9 }, Vec3::ZERO).unwrap())
            .collect();
        assert!(par.iter().all(|p| *p == a));
    }
}
