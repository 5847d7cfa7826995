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

use crate::scene::{Light, LightShape};
use glam::{DVec2, DVec3, Vec3};

/// The fraction in `[0, 1]` of `light`'s area in front of (or on) the plane through `point`
/// with normal `normal` (module doc). `normal` need not be unit length but must not be zero.
pub fn fraction_in_front(light: &Light, point: Vec3, normal: Vec3) -> f64 {
    let n = normal.as_dvec3();
    let p = point.as_dvec3();
    let c = light.center.as_dvec3();
    let d0 = n.dot(c - p);
    match &light.shape {
        LightShape::Point => f64::from(u8::from(d0 >= 0.0)),
        LightShape::Rect { u, v } | LightShape::TexturedRect { u, v, .. } => {
            square_fraction_in_front(d0, n.dot(u.as_dvec3()), n.dot(v.as_dvec3()))
        }
        LightShape::Disk { radius, normal: dn } => {
            disk_fraction_in_front(d0, f64::from(*radius), n, dn.as_dvec3())
        }
        LightShape::Sphere { radius } => {
            let toward = p - c;
            let facing = if toward.length_squared() > 0.0 {
                toward
            } else {
                DVec3::Z
            };
            disk_fraction_in_front(d0, f64::from(*radius), n, facing)
        }
    }
}

/// Whether the plane through `point` with normal `normal` cuts `light`: part of it is in
/// front and part behind (`0 < fraction_in_front < 1`). These are the *horizon receivers*.
pub fn plane_cuts_light(light: &Light, point: Vec3, normal: Vec3) -> bool {
    let f = fraction_in_front(light, point, normal);
    f > 0.0 && f < 1.0
}

/// The fraction of the square `[-1, 1]²` where `d0 + s·ds + t·dt ≥ 0`: the square clipped by
/// the half-plane (Sutherland–Hodgman, one edge), its area by the shoelace formula, over 4.
fn square_fraction_in_front(d0: f64, ds: f64, dt: f64) -> f64 {
    let corners = [
        DVec2::new(-1.0, -1.0),
        DVec2::new(1.0, -1.0),
        DVec2::new(1.0, 1.0),
        DVec2::new(-1.0, 1.0),
    ];
    let d = |q: DVec2| d0 + q.x * ds + q.y * dt;
    let mut clipped: Vec<DVec2> = Vec::with_capacity(5);
    for (i, &a) in corners.iter().enumerate() {
        let b = corners[(i + 1) % 4];
        let (da, db) = (d(a), d(b));
        if da >= 0.0 {
            clipped.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            clipped.push(a + (b - a) * (da / (da - db)));
        }
    }
    let twice_area: f64 = (0..clipped.len())
        .map(|i| clipped[i].perp_dot(clipped[(i + 1) % clipped.len()]))
        .sum();
    (twice_area / 8.0).clamp(0.0, 1.0)
}

/// The fraction of a disk (center at signed distance `d0` from the receiver's plane, `radius`,
/// facing `disk_normal`) in front of the plane of normal `n`: the circular segment cut at
/// `t = d0 / (radius·|n⊥|)`, of area fraction `1 − (acos t − t·√(1 − t²)) / π`.
fn disk_fraction_in_front(d0: f64, radius: f64, n: DVec3, disk_normal: DVec3) -> f64 {
    let dn = disk_normal.normalize();
    let reach = radius * (n - dn * n.dot(dn)).length();
    if reach <= 0.0 {
        return f64::from(u8::from(d0 >= 0.0));
    }
    let t = (d0 / reach).clamp(-1.0, 1.0);
    (1.0 - (libm::acos(t) - t * libm::sqrt(1.0 - t * t)) / std::f64::consts::PI).clamp(0.0, 1.0)
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
        let f = square_fraction_in_front(-1.5, 1.0, 1.0);
        assert!((f - 0.125 / 4.0).abs() < 1e-15, "{f}");
        // The complement (≤ 1.5) is the rest.
        let g = square_fraction_in_front(1.5, -1.0, -1.0);
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
