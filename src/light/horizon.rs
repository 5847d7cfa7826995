//! The receiver's own horizon (issue 28): the part of an area light in front of the plane
//! through a receiver point along its normal. None of the papers discusses it — their
//! visibility counts the shadow volumes of occluders' silhouettes, while a receiver whose own
//! tangent plane cuts the light sees only the part of the light in front of that plane (the
//! rest is hidden by the receiver's own surface, as the ray-cast reference finds).
//!
//! This is the project's geometry, in f64, for measuring (which pixels are *horizon
//! receivers*) and as the exact value the methods' `horizon = clip` arithmetic is tested
//! against:
//!
//! - a rectangle is clipped as a polygon: the signed distance to the plane is affine in the
//!   light's `(s, t) ∈ [-1, 1]²` parameters (`center + s·u + t·v`), so the fraction in front
//!   is the area of the unit square's part where it is ≥ 0, over 4;
//! - a disk's signed distance ranges over `d(center) ± radius·|n⊥|` (`n⊥`, the receiver
//!   normal's part in the disk's plane), so the part in front is a circular segment;
//! - a sphere is the disk through its center facing the receiver (Paper IV §4.2.1, the disk
//!   [`crate::light::sampling`] samples), a point light is all in front or all behind.
//!
//! Choice where the plane holds the whole light (a disk or rectangle in the receiver's own
//! plane, a point light on it): the light counts as in front (fraction 1), the same rule as a
//! point exactly on the plane of a clipped polygon — such a light sends no light to the
//! receiver anyway (its cosine is 0).

use crate::gpu::shader_float::ShaderFloat;
use crate::gpu::shader_vec::{SVec2, SVec3};
use crate::gpu::texture::{linear_taps, Wrap};
use crate::scene::{Light, LightShape};
use glam::{DVec3, Vec3};
use std::sync::OnceLock;

/// The fraction in `[0, 1]` of `light`'s area in front of (or on) the plane through `point`
/// with normal `normal` (module doc). `normal` need not be unit length but must not be zero.
pub fn fraction_in_front(light: &Light, point: Vec3, normal: Vec3) -> f64 {
    fraction_with::<f64>(
        light,
        SVec3::from_f64(point.as_dvec3()),
        SVec3::from_f64(normal.as_dvec3()),
        exact_segment,
    )
}

/// Whether the plane through `point` with normal `normal` cuts `light`: part of it is in
/// front and part behind (`0 < fraction_in_front < 1`). These are the *horizon receivers*.
pub fn plane_cuts_light(light: &Light, point: Vec3, normal: Vec3) -> bool {
    let f = fraction_in_front(light, point, normal);
    f > 0.0 && f < 1.0
}

/// [`fraction_in_front`] as a fragment program computes it (`horizon = clip`,
/// [`crate::methods::horizon_clip`]): every operation rounded to the shader precision `T`
/// ([`crate::gpu::shader_float`]), the light's parameters uniforms rounded to `T`, `point`
/// and `normal` as the program reads them (the depth-buffer point, the normal buffer's
/// value), and a disk's circular segment looked up in [`SegmentTable`] instead of computed
/// with `acos`. The same arithmetic as the f64 reference otherwise (one generic function:
/// at `T = f64` only the segment differs).
///
/// Its error against [`fraction_in_front`], for a unit normal and coordinates of magnitude at
/// most `m` and a light of half-extent `h` at distance at most `D` from the point: the plane
/// distances `d` carry a relative rounding of a few units of `ε = 2^−(mantissa bits + 1)` of
/// `m` (the subtraction `c − p`) and of `D` (the dot product), so the clipped line moves by
/// about `4ε·(m + D) / h` in the light's `[−1, 1]` parameters, and the fraction by at most half
/// that per unit of the line's length (≤ 2√2), plus the segment table's error for a disk
/// ([`SEGMENT_TABLE_MAX_ERROR`]): tested with these constants in
/// `tests::the_shader_fraction_is_within_its_precision_bound`.
pub fn shader_fraction_in_front<T: ShaderFloat>(light: &Light, point: DVec3, normal: DVec3) -> T {
    let table = SegmentTable::get();
    fraction_with::<T>(
        light,
        SVec3::from_f64(point),
        SVec3::from_f64(normal),
        |t| table.sample(t),
    )
}

/// The fraction of `light` in front of the plane through `p` with normal `n`, in the
/// arithmetic of `T`, a disk's circular segment of cut `t ∈ [−1, 1]` given by `segment`
/// (module doc).
fn fraction_with<T: ShaderFloat>(
    light: &Light,
    p: SVec3<T>,
    n: SVec3<T>,
    segment: impl Fn(T) -> T,
) -> T {
    let uniform = |v: Vec3| SVec3::<T>::from_f64(v.as_dvec3());
    let c = uniform(light.center);
    let d0 = n.dot(c - p);
    match &light.shape {
        LightShape::Point => in_front_or_not(d0),
        LightShape::Rect { u, v } | LightShape::TexturedRect { u, v, .. } => SquarePlane {
            d0,
            ds: n.dot(uniform(*u)),
            dt: n.dot(uniform(*v)),
        }
        .fraction(),
        LightShape::Disk { radius, normal: dn } => disk_fraction_in_front(
            d0,
            T::from_f64(f64::from(*radius)),
            n,
            uniform(*dn),
            segment,
        ),
        LightShape::Sphere { radius } => {
            let toward = p - c;
            let facing = if toward.dot(toward) > T::zero() {
                toward
            } else {
                SVec3::from_f64(DVec3::Z)
            };
            disk_fraction_in_front(d0, T::from_f64(f64::from(*radius)), n, facing, segment)
        }
    }
}

/// The receiver's plane over a rectangle light's parameters: the signed distance
/// `d(s, t) = d0 + s·ds + t·dt` of the light's point `center + s·u + t·v`, `(s, t) ∈ [−1, 1]²`,
/// in the arithmetic of `T` (`d0 = n·(c − p)`, `ds = n·u`, `dt = n·v`: the operations of
/// [`shader_fraction_in_front`], so [`SquarePlane::fraction`] is its value bit for bit). What
/// `horizon = integrate` clips `ssv`'s coverage polygons with
/// ([`crate::light::coverage::EdgeCoverageProgram::at_in_front`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SquarePlane<T> {
    /// The distance at the light's center.
    pub d0: T,
    /// Its change per unit of `s`.
    pub ds: T,
    /// Its change per unit of `t`.
    pub dt: T,
}

impl<T: ShaderFloat> SquarePlane<T> {
    /// The plane through `point` with normal `normal` (as the fragment program reads them:
    /// the depth-buffer point, the normal buffer's value) over a rectangle `light`; `None` for
    /// the other shapes.
    pub fn of(light: &Light, point: DVec3, normal: DVec3) -> Option<Self> {
        let (LightShape::Rect { u, v } | LightShape::TexturedRect { u, v, .. }) = &light.shape
        else {
            return None;
        };
        let uniform = |v: Vec3| SVec3::<T>::from_f64(v.as_dvec3());
        let (p, n) = (SVec3::<T>::from_f64(point), SVec3::<T>::from_f64(normal));
        Some(SquarePlane {
            d0: n.dot(uniform(light.center) - p),
            ds: n.dot(uniform(*u)),
            dt: n.dot(uniform(*v)),
        })
    }

    /// The signed distance at `(s, t)`, `d0 + s·ds + t·dt` in that order.
    pub fn at(&self, q: SVec2<T>) -> T {
        self.d0 + q.x * self.ds + q.y * self.dt
    }

    /// How many of the light's four corners are in front of (or on) the plane: 4, the whole
    /// light ([`SquarePlane::fraction`] exactly 1), 0, none of it (exactly 0).
    pub fn corners_in_front(&self) -> usize {
        square_corners::<T>()
            .into_iter()
            .filter(|&q| self.at(q) >= T::zero())
            .count()
    }

    /// The fraction of the light in front of the plane ([`shader_fraction_in_front`]): the
    /// square clipped by the half-plane (Sutherland–Hodgman, one edge), its area by the
    /// shoelace formula, over 4. With every corner in front the polygon is the square itself
    /// and the area is exactly 1 in every format (the corners' cross products are ±2).
    pub fn fraction(&self) -> T {
        let corners = square_corners::<T>();
        let (zero, one) = (T::zero(), T::one());
        // A half-plane cuts a quadrilateral into at most five corners: a fixed array, no
        // allocation in the per-pixel program.
        let mut clipped = [corners[0]; 5];
        let mut n = 0;
        for (i, &a) in corners.iter().enumerate() {
            let b = corners[(i + 1) % 4];
            let (da, db) = (self.at(a), self.at(b));
            if da >= zero {
                clipped[n] = a;
                n += 1;
            }
            if (da >= zero) != (db >= zero) {
                clipped[n] = a + (b - a) * (da / (da - db));
                n += 1;
            }
        }
        let twice_area = (0..n)
            .map(|i| clipped[i].perp_dot(clipped[(i + 1) % n]))
            .fold(zero, |sum, x| sum + x);
        (twice_area / T::from_f64(8.0)).clamp(zero, one)
    }
}

/// The corners of the light's parameter square `[−1, 1]²`, counterclockwise from `(−1, −1)`.
fn square_corners<T: ShaderFloat>() -> [SVec2<T>; 4] {
    let one = T::one();
    [
        SVec2::new(-one, -one),
        SVec2::new(one, -one),
        SVec2::new(one, one),
        SVec2::new(-one, one),
    ]
}

/// 1 when the signed distance `d` is ≥ 0, else 0.
fn in_front_or_not<T: ShaderFloat>(d: T) -> T {
    if d >= T::zero() {
        T::one()
    } else {
        T::zero()
    }
}

/// The fraction of a disk (center at signed distance `d0` from the receiver's plane, `radius`,
/// facing `disk_normal`) in front of the plane of normal `n`: the circular segment cut at
/// `t = d0 / (radius·|n⊥|)`, its area fraction given by `segment` (for the reference
/// [`exact_segment`]).
fn disk_fraction_in_front<T: ShaderFloat>(
    d0: T,
    radius: T,
    n: SVec3<T>,
    disk_normal: SVec3<T>,
    segment: impl Fn(T) -> T,
) -> T {
    let dn = disk_normal * (T::one() / disk_normal.length());
    let reach = radius * (n - dn * n.dot(dn)).length();
    if reach <= T::zero() {
        return in_front_or_not(d0);
    }
    let one = T::one();
    segment((d0 / reach).clamp(-one, one))
}

/// The area fraction of the unit disk on the far side of the chord at signed distance `−t`
/// from its center (the part in front of a plane the center is `t` in front of),
/// `1 − (acos t − t·√(1 − t²)) / π`: 0 at `t = −1`, ½ at 0, 1 at 1. In f64.
fn exact_segment(t: f64) -> f64 {
    (1.0 - (libm::acos(t) - t * libm::sqrt(1.0 - t * t)) / std::f64::consts::PI).clamp(0.0, 1.0)
}

/// The largest error of [`SegmentTable::sample`] against the exact segment at f64 (its doc).
pub const SEGMENT_TABLE_MAX_ERROR: f64 = 7e-5;

/// Texels of [`SegmentTable`].
pub const SEGMENT_TABLE_SIZE: usize = 256;

/// The circular-segment area of a disk cut by the receiver's plane, as a fragment program of
/// `horizon = clip` reads it: a 1D texture of [`SEGMENT_TABLE_SIZE`] 16-bit unorm texels
/// (512 bytes), linearly filtered, clamped to the edge.
///
/// Choice — a table rather than a polynomial: the segment fraction `g(t)` has a `(1 − t)^{3/2}`
/// singularity at both ends (its slope `(2/π)·√(1 − t²)` has an infinite derivative there), so
/// a low-degree polynomial in `t` is poor exactly where the horizon pixels sit, and `acos` was
/// no instruction of the papers' GPUs (NV3x, R300); one texture fetch was. Texel `i` holds
/// `g(t_i)` at `t_i = −1 + 2i/(N − 1)`, so the texel centers include both ends: `t = ±1` reads
/// exactly 0 and 1 (a disk wholly in front gives exactly 1, the method's value unchanged).
/// Its error ([`SEGMENT_TABLE_MAX_ERROR`]): the rounding to 16 bits, ≤ ½·2⁻¹⁶ ≈ 7.6·10⁻⁶, plus
/// the linear interpolation's, largest on the end intervals where `1 − g ≈ (4√2 / 3π)·u^{3/2}`
/// (`u = 1 − t`; the segment's area is `(4√2/3)·u^{3/2}` to first order): the chord of
/// `u^{3/2}` over `[0, h]` is off by at most `(4/27)·h^{3/2}`, so ≤ `0.600·(4/27)·h^{3/2}` ≈
/// 6.2·10⁻⁵ for `h = 2/255`; in the interior `h²/8·max|g″|` is smaller. In all ≤ 7·10⁻⁵
/// (tested: `tests::the_segment_table_is_within_its_bound`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SegmentTable {
    /// The texels, `round(g(t_i)·65535)`.
    pub texels: Vec<u16>,
}

impl SegmentTable {
    /// The table, built once per process (deterministic: f64, in texel order).
    pub fn get() -> &'static Self {
        static TABLE: OnceLock<SegmentTable> = OnceLock::new();
        TABLE.get_or_init(|| {
            let last = (SEGMENT_TABLE_SIZE - 1) as f64;
            SegmentTable {
                texels: (0..SEGMENT_TABLE_SIZE)
                    .map(|i| {
                        let t = -1.0 + 2.0 * i as f64 / last;
                        (exact_segment(t) * 65535.0).round() as u16
                    })
                    .collect(),
            }
        })
    }

    /// Storage size in bytes.
    pub fn bytes(&self) -> usize {
        self.texels.len() * 2
    }

    /// The segment fraction at the cut `t ∈ [−1, 1]`: the texture coordinate
    /// `(t + 1)·(N − 1)/2 + 0.5` computed in `T`, the fetch and the linear filter by the
    /// texture unit ([`crate::gpu::texture`]), the filtered value rounded to `T`.
    pub fn sample<T: ShaderFloat>(&self, t: T) -> T {
        let half_span = T::from_f64((SEGMENT_TABLE_SIZE - 1) as f64 / 2.0);
        let x = (t + T::one()) * half_span + T::from_f64(0.5);
        let ([i, j], f) = linear_taps(x.to_f64(), SEGMENT_TABLE_SIZE as u32, Wrap::ClampToEdge);
        crate::gpu::shader_ops::fetch();
        let texel = |k: u32| f64::from(self.texels[k as usize]) / 65535.0;
        T::from_f64(texel(i) * (1.0 - f) + texel(j) * f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect() -> Light {
        Light {
            center: Vec3::new(0.0, 2.0, 0.0),
            shape: LightShape::Rect {
                u: Vec3::new(1.0, 0.0, 0.0),
                v: Vec3::new(0.0, 0.0, 1.0),
            },
        }
    }

    use crate::gpu::shader_float::{Fp16, Fp24, Fp32, FP16, FP24, FP32};

    /// The segment table against the exact segment on a fine grid, within the bound its doc
    /// derives ([`SEGMENT_TABLE_MAX_ERROR`]), and exact at both ends.
    #[test]
    fn the_segment_table_is_within_its_bound() {
        let table = SegmentTable::get();
        assert_eq!(table.bytes(), 512);
        assert_eq!(table.sample(1.0f64), 1.0);
        assert_eq!(table.sample(-1.0f64), 0.0);
        let worst = (0..=20_000)
            .map(|k| -1.0 + k as f64 / 10_000.0)
            .map(|t| (table.sample(t) - exact_segment(t)).abs())
            .fold(0.0, f64::max);
        assert!(worst <= SEGMENT_TABLE_MAX_ERROR, "{worst}");
        // The bound is not loose: the end intervals come close to it.
        assert!(worst >= 0.75 * SEGMENT_TABLE_MAX_ERROR, "{worst}");
    }

    /// Constructed receivers whose fraction every format computes exactly: the plane distances
    /// are small dyadic numbers, so the clipped square's corners and area are exact.
    #[test]
    fn the_shader_fraction_is_exact_on_dyadic_receivers() {
        fn check<T: ShaderFloat>() {
            let at = |x: f64, n: DVec3| {
                shader_fraction_in_front::<T>(&rect(), DVec3::new(x, 0.0, 0.0), n).to_f64()
            };
            assert_eq!(at(0.0, DVec3::X), 0.5, "{:?}", T::PRECISION);
            assert_eq!(at(0.5, DVec3::X), 0.25);
            assert_eq!(at(-0.5, DVec3::X), 0.75);
            assert_eq!(at(0.0, DVec3::Y), 1.0);
            assert_eq!(at(0.0, -DVec3::Y), 0.0);
            // The corner triangle of legs 0.5 (1/32), with the plane s + t = 1.5 through the
            // light's plane (x + z = 1.5, normal (1, 0, 1)/… not unit: still exact).
            let f = shader_fraction_in_front::<T>(
                &rect(),
                DVec3::new(0.75, 2.0, 0.75),
                DVec3::new(1.0, 0.0, 1.0),
            );
            assert_eq!(f.to_f64(), 1.0 / 32.0);
        }
        check::<f64>();
        check::<Fp32>();
        check::<Fp24>();
        check::<Fp16>();
    }

    /// At f64 the shader's rectangle is the reference bit for bit (one generic function), and
    /// its disk differs only by the segment table.
    #[test]
    fn at_f64_the_shader_is_the_reference_but_for_the_table() {
        let disk = Light {
            center: Vec3::new(0.0, 2.0, 0.0),
            shape: LightShape::Disk {
                radius: 1.0,
                normal: -Vec3::Y,
            },
        };
        for k in 0..200 {
            let p = Vec3::new(k as f32 / 50.0 - 2.0, 1.5 + k as f32 / 400.0, 0.3);
            let n = Vec3::new(1.0, 0.2 - k as f32 / 500.0, 0.1).normalize();
            let s: f64 = shader_fraction_in_front(&rect(), p.as_dvec3(), n.as_dvec3());
            assert_eq!(s.to_bits(), fraction_in_front(&rect(), p, n).to_bits());
            let d: f64 = shader_fraction_in_front(&disk, p.as_dvec3(), n.as_dvec3());
            assert!((d - fraction_in_front(&disk, p, n)).abs() <= SEGMENT_TABLE_MAX_ERROR);
        }
    }

    /// The precision bound of [`shader_fraction_in_front`]'s doc, at fp32, fp24 and fp16, on
    /// 3000 pseudo-random receivers near each light shape (fixed LCG): the error against the
    /// f64 reference is at most `K·ε·(m + D)/g` plus the table's error for a disk, with
    /// `ε = 2^−(mantissa bits + 1)`, `m` the largest coordinate, `D` the point's distance to
    /// the light's center and `g` the plane's gradient over the light's parameters (`|∇d|`
    /// over `[−1, 1]²`; for a disk its reach `radius·|n⊥|`): the plane distance carries about
    /// `4ε(m + D)` of rounding, the fraction moves by at most `(2√2/4)/g` per unit of distance
    /// (the cut's length over the square's area; `(2/π)/g` for a disk), and `K = 4` covers
    /// both with a factor of 2 for the clipping and area arithmetic.
    #[test]
    fn the_shader_fraction_is_within_its_precision_bound() {
        fn worst<T: ShaderFloat>(eps: f64) -> f64 {
            let lights = [
                rect(),
                Light {
                    center: Vec3::new(0.3, 2.5, -0.2),
                    shape: LightShape::Disk {
                        radius: 0.7,
                        normal: Vec3::new(0.2, -1.0, 0.1).normalize(),
                    },
                },
                Light {
                    center: Vec3::new(-0.4, 3.0, 0.5),
                    shape: LightShape::Sphere { radius: 0.5 },
                },
            ];
            let mut state = 12345u64;
            let mut next = || {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
            };
            let mut worst = 0.0f64;
            for light in &lights {
                for _ in 0..1000 {
                    let p = Vec3::new(
                        (2.0 * next()) as f32,
                        (1.0 + next()) as f32,
                        (2.0 * next()) as f32,
                    );
                    let n = crate::gpu::normal_buffer::quantize(
                        Vec3::new(next() as f32, next() as f32, next() as f32).normalize(),
                    );
                    let reference = fraction_in_front(light, p, n.as_vec3());
                    let shader: T = shader_fraction_in_front(light, p.as_dvec3(), n);
                    let c = light.center.as_dvec3();
                    let pd = p.as_dvec3();
                    let m = c.abs().max_element().max(pd.abs().max_element());
                    let dist = (c - pd).length();
                    let (g, slope, table) = match light.shape {
                        LightShape::Rect { u, v } => (
                            libm::hypot(n.dot(u.as_dvec3()), n.dot(v.as_dvec3())),
                            2f64.sqrt() / 2.0,
                            0.0,
                        ),
                        LightShape::Disk { radius, normal } => {
                            let dn = normal.as_dvec3();
                            (
                                f64::from(radius) * (n - dn * n.dot(dn)).length(),
                                2.0 / std::f64::consts::PI,
                                SEGMENT_TABLE_MAX_ERROR,
                            )
                        }
                        LightShape::Sphere { radius } => {
                            let dn = (pd - c).normalize();
                            (
                                f64::from(radius) * (n - dn * n.dot(dn)).length(),
                                2.0 / std::f64::consts::PI,
                                SEGMENT_TABLE_MAX_ERROR,
                            )
                        }
                        _ => unreachable!(),
                    };
                    let bound = 4.0 * 4.0 * eps * (m + dist) * slope / g + table + 4.0 * eps;
                    let err = (shader.to_f64() - reference).abs();
                    worst = worst.max(err / bound);
                }
            }
            worst
        }
        let eps =
            |f: crate::gpu::shader_float::FloatFormat| libm::ldexp(1.0, -(f.mantissa_bits + 1));
        for (name, w) in [
            ("fp32", worst::<Fp32>(eps(FP32))),
            ("fp24", worst::<Fp24>(eps(FP24))),
            ("fp16", worst::<Fp16>(eps(FP16))),
        ] {
            assert!(w <= 1.0, "{name}: error / bound = {w}");
        }
    }

    #[test]
    fn a_floor_under_a_rectangle_sees_all_of_it_and_a_ceiling_none() {
        assert_eq!(fraction_in_front(&rect(), Vec3::ZERO, Vec3::Y), 1.0);
        assert_eq!(fraction_in_front(&rect(), Vec3::ZERO, -Vec3::Y), 0.0);
        assert!(!plane_cuts_light(&rect(), Vec3::ZERO, Vec3::Y));
    }

    #[test]
    fn a_wall_through_the_rectangles_middle_sees_half_and_an_offset_wall_a_quarter() {
        // The plane x = 0 halves the light; x = 0.5 (normal +x) keeps s ∈ [0.5, 1]: 1/4.
        let at = |x: f32| fraction_in_front(&rect(), Vec3::new(x, 2.0, 0.0), Vec3::X);
        assert_eq!(at(0.0), 0.5);
        assert_eq!(at(0.5), 0.25);
        assert_eq!(at(-0.5), 0.75);
        assert!(plane_cuts_light(&rect(), Vec3::new(0.5, 0.0, 0.0), Vec3::X));
    }

    #[test]
    fn a_diagonal_plane_through_a_corner_cuts_a_triangle_of_one_eighth() {
        // s + t ≥ 1.5 ⇔ the corner triangle of legs 0.5: area 0.125 of the square's 4 → 1/32.
        let plane = |d0, ds, dt| SquarePlane::<f64> { d0, ds, dt };
        let f = plane(-1.5, 1.0, 1.0).fraction();
        assert!((f - 0.125 / 4.0).abs() < 1e-15, "{f}");
        // The complement (≤ 1.5) is the rest.
        let g = plane(1.5, -1.0, -1.0).fraction();
        assert!((g - (1.0 - 0.125 / 4.0)).abs() < 1e-15, "{g}");
    }

    #[test]
    fn a_disk_is_cut_into_circular_segments() {
        let disk = Light {
            center: Vec3::new(0.0, 2.0, 0.0),
            shape: LightShape::Disk {
                radius: 1.0,
                normal: -Vec3::Y,
            },
        };
        // A vertical plane through the center: half. The plane x = 0.5 (normal +x) keeps the
        // segment of height 0.5, of area acos(0.5) − 0.5·√0.75 = π/3 − √3/4, over π.
        let half = fraction_in_front(&disk, Vec3::new(0.0, 0.0, 0.0), Vec3::X);
        assert!((half - 0.5).abs() < 1e-15, "{half}");
        let seg = fraction_in_front(&disk, Vec3::new(0.5, 0.0, 0.0), Vec3::X);
        let expected = (std::f64::consts::PI / 3.0 - 3f64.sqrt() / 4.0) / std::f64::consts::PI;
        assert!((seg - expected).abs() < 1e-12, "{seg} vs {expected}");
        // A plane parallel to the disk: all or nothing.
        assert_eq!(fraction_in_front(&disk, Vec3::ZERO, Vec3::Y), 1.0);
        assert_eq!(fraction_in_front(&disk, Vec3::ZERO, -Vec3::Y), 0.0);
    }

    #[test]
    fn a_sphere_is_its_disk_facing_the_receiver() {
        let sphere = Light {
            center: Vec3::new(0.0, 2.0, 0.0),
            shape: LightShape::Sphere { radius: 1.0 },
        };
        // Receiver straight below: the facing disk is horizontal, a floor sees all of it even
        // though the floor plane y = 1.5 cuts the ball.
        assert_eq!(
            fraction_in_front(&sphere, Vec3::new(0.0, 1.5, 0.0), Vec3::Y),
            1.0
        );
        // A wall x = 0.5 under it cuts the facing disk like the disk case.
        let seg = fraction_in_front(&sphere, Vec3::new(0.5, 0.0, 0.0), Vec3::X);
        let expected = (std::f64::consts::PI / 3.0 - 3f64.sqrt() / 4.0) / std::f64::consts::PI;
        // The facing disk tilts by the receiver's offset: its reach along x is
        // radius·√(1 − n_d.x²) = 2/√4.25, so t = −0.5·√4.25/2: a thinner segment.
        let t: f64 = -0.5 * 4.25f64.sqrt() / 2.0;
        let tilted = 1.0 - (libm::acos(t) - t * libm::sqrt(1.0 - t * t)) / std::f64::consts::PI;
        assert!((seg - tilted).abs() < 1e-12, "{seg} vs {tilted}");
        assert!(seg < expected);
    }

    #[test]
    fn a_point_light_is_never_cut() {
        let point = Light {
            center: Vec3::new(0.0, 2.0, 0.0),
            shape: LightShape::Point,
        };
        assert_eq!(fraction_in_front(&point, Vec3::ZERO, Vec3::Y), 1.0);
        assert_eq!(fraction_in_front(&point, Vec3::ZERO, -Vec3::Y), 0.0);
        assert!(!plane_cuts_light(&point, Vec3::new(0.0, 2.0, 0.0), Vec3::X));
    }
}
