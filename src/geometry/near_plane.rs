//! Whether the eye or the near plane lies in a hard shadow volume — the z-fail decision
//! (`docs/architecture.md` "Only the effects a scene calls for": detected, not asked) — and
//! the exact f64 segment–mesh tests it is made of, which tests also use as hard-shadow ground
//! truth.

use crate::primitives::polygon_clip::clip_polygon;
use crate::primitives::ray_triangle::segment_crosses_triangle;
use crate::scene::{LightShape, Scene};
use glam::{DVec3, Vec3};

/// Grid of near-plane points tested for shadow (per side).
const NEAR_GRID: u32 = 9;

/// The light points whose hard shadow volumes a method renders, for the z-fail decision: for
/// every light, its center plus the extreme points of its shape (rectangle corners; four rim
/// points of a disk or of a sphere's silhouette disk in every axis plane). The union of their
/// shadows bounds the shadow of any point of the lights only approximately; a user can force
/// z-fail.
pub fn representative_light_points(scene: &Scene) -> Vec<Vec3> {
    let mut pts = Vec::new();
    for light in &scene.lights {
        let c = light.center;
        pts.push(c);
        match &light.shape {
            LightShape::Point => {}
            LightShape::Rect { u, v } | LightShape::TexturedRect { u, v, .. } => {
                for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                    pts.push(c + *u * su + *v * sv);
                }
            }
            LightShape::Disk { radius, normal } => {
                let n = normal.normalize();
                let a = n.any_orthonormal_vector();
                let b = n.cross(a);
                for d in [a, -a, b, -b] {
                    pts.push(c + d * *radius);
                }
            }
            LightShape::Sphere { radius } => {
                for d in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
                    pts.push(c + d * *radius);
                }
            }
        }
    }
    pts
}

/// The eye and a 9×9 grid on the near-plane rectangle at distance `near` (its corners and
/// edges included), in world space: the points where the near plane can meet a shadow volume
/// ([`eye_in_shadow`]) or geometry ([`crate::frame::Frame::render`]).
pub fn near_plane_points(scene: &Scene, near: f64) -> Vec<DVec3> {
    let at = near_plane_map(scene, near);
    let mut pts = vec![scene.camera.eye];
    for i in 0..NEAR_GRID {
        for j in 0..NEAR_GRID {
            let s = i as f64 / (NEAR_GRID - 1) as f64 * 2.0 - 1.0;
            let t = j as f64 / (NEAR_GRID - 1) as f64 * 2.0 - 1.0;
            pts.push(at(s, t));
        }
    }
    pts
}

/// The point of the near-plane rectangle at distance `near` with coordinates (s, t) ∈ [−1, 1]²
/// (s to the right, t up), in world space.
fn near_plane_map(scene: &Scene, near: f64) -> impl Fn(f64, f64) -> DVec3 {
    let cam = &scene.camera;
    let fwd = (cam.target - cam.eye).normalize();
    let right = fwd.cross(cam.up).normalize();
    let up = right.cross(fwd);
    let (tan_x, tan_y) = cam.view_half_tangents(scene.width, scene.height);
    let (center, right, up) = (
        cam.eye + fwd * near,
        right * (near * tan_x),
        up * (near * tan_y),
    );
    move |s, t| center + right * s + up * t
}

/// Whether the eye or the near-plane rectangle lies (partly) in the hard shadow of any of
/// `lights`: then z-pass counts are wrong (the near plane clips a shadow volume) and z-fail is
/// needed. The [`near_plane_points`] are tested with the exact f64 segment–triangle test, and
/// the whole rectangle with [`near_rect_meets_shadow`]: a shadow volume thinner than the grid's
/// spacing can cross the near plane between its points (`scenes/hard/near-plane-cuts-volume-
/// rect.toml`: a bar's volume crosses it in a strip 0.05 of its height; z-pass was chosen and
/// 384 of 4096 pixels of `hard-sv` were wrong).
pub fn eye_in_shadow(scene: &Scene, near: f64, lights: &[Vec3]) -> bool {
    let points = near_plane_points(scene, near);
    let rect = near_rect(scene, near);
    let lights: Vec<DVec3> = lights.iter().map(|l| l.as_dvec3()).collect();
    let tris = casters_meeting_hull_box(scene, points.iter().chain(&rect).chain(&lights));
    points.iter().any(|p| {
        lights.iter().any(|l| {
            tris.iter().any(|[a, b, c]| {
                segment_crosses_triangle(*p, *l - *p, *a, *b - *a, *c - *a, 0.0, 1.0)
            })
        })
    }) || rect_meets_shadow(&rect, &tris, &lights)
}

/// The triangles of the meshes that cast shadows whose bounding box meets the bounding box of
/// `points` (widened by 10⁻⁹ of its size for rounding), as f64 world triangles. Every segment
/// between two of the points, and every point of the points' convex hull, lies in that box, so
/// the other triangles can neither block such a segment nor put part of the hull in shadow:
/// [`eye_in_shadow`] tests the near plane against these only (on `forest-spheres`, 20 532
/// triangles, most of them far from the eye–light pyramid).
fn casters_meeting_hull_box<'a>(
    scene: &Scene,
    points: impl Iterator<Item = &'a DVec3>,
) -> Vec<[DVec3; 3]> {
    let (lo, hi) = points.fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let pad = (hi - lo).max_element() * 1e-9;
    let (lo, hi) = (lo - pad, hi + pad);
    let meets = |a: DVec3, b: DVec3| a.cmple(hi).all() && b.cmpge(lo).all();
    scene
        .meshes
        .iter()
        .filter(|m| !m.receiver_only)
        .flat_map(|m| {
            m.triangles
                .iter()
                .map(|t| t.map(|i| m.positions[i as usize].as_dvec3()))
        })
        .filter(|[a, b, c]| meets(a.min(*b).min(*c), a.max(*b).max(*c)))
        .collect()
}

/// The four corners of the near-plane rectangle at distance `near`, in order around it.
fn near_rect(scene: &Scene, near: f64) -> [DVec3; 4] {
    let at = near_plane_map(scene, near);
    [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(s, t)| at(s, t))
}

/// Whether a part of the near-plane rectangle of positive area lies in the hard shadow of one
/// of `lights` (exact up to f64 rounding): for every light point and triangle, the rectangle
/// is clipped (Sutherland–Hodgman) to the triangle's shadow frustum — beyond the triangle's
/// plane and inside the three planes through the light point and its edges — and whatever is
/// left with an area above 10⁻¹² of the rectangle's counts. A triangle whose plane holds the
/// light point casts no volume.
pub fn near_rect_meets_shadow(scene: &Scene, near: f64, lights: &[Vec3]) -> bool {
    let rect = near_rect(scene, near);
    let lights: Vec<DVec3> = lights.iter().map(|l| l.as_dvec3()).collect();
    let tris = casters_meeting_hull_box(scene, rect.iter().chain(&lights));
    rect_meets_shadow(&rect, &tris, &lights)
}

/// [`near_rect_meets_shadow`] for the rectangle `rect` and the triangles `tris`.
fn rect_meets_shadow(rect: &[DVec3; 4], tris: &[[DVec3; 3]], lights: &[DVec3]) -> bool {
    let area = |poly: &[DVec3]| -> f64 {
        (1..poly.len().saturating_sub(1))
            .map(|i| (poly[i] - poly[0]).cross(poly[i + 1] - poly[0]))
            .sum::<DVec3>()
            .length()
            * 0.5
    };
    let min_area = area(rect) * 1e-12;
    lights.iter().any(|&l| {
        tris.iter().any(|&[a, b, c]| {
            let n = (b - a).cross(c - a);
            let side = n.dot(l - a);
            if side == 0.0 || !side.is_finite() {
                return false;
            }
            // Half-spaces {p : h.dot(p) + d ≥ 0}.
            let mut planes = vec![(-n * side.signum(), n.dot(a) * side.signum())];
            for (p, q, r) in [(a, b, c), (b, c, a), (c, a, b)] {
                let e = (p - l).cross(q - l);
                let s = e.dot(r - l).signum();
                planes.push((e * s, -e.dot(l) * s));
            }
            let mut poly = rect.to_vec();
            for (h, d) in planes {
                poly = clip_polygon(&poly, |p: DVec3| h.dot(p) + d);
                if poly.len() < 3 {
                    return false;
                }
            }
            area(&poly) > min_area
        })
    })
}

/// Whether the open segment p→q crosses a triangle of a mesh that casts shadows (not a
/// receiver-only one; exact f64 test, used for the z-fail decision and as hard-shadow ground
/// truth in tests).
pub fn segment_blocked(scene: &Scene, p: DVec3, q: DVec3) -> bool {
    scene
        .meshes
        .iter()
        .filter(|m| !m.receiver_only)
        .any(|m| segment_hits_mesh(m, p, q))
}

/// Whether the open segment p→q crosses a triangle of `mesh` (exact f64 test).
pub fn segment_hits_mesh(mesh: &crate::scene::Mesh, p: DVec3, q: DVec3) -> bool {
    let d = q - p;
    mesh.triangles.iter().any(|t| {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3());
        segment_crosses_triangle(p, d, a, b - a, c - a, 0.0, 1.0)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `scenes/hard/near-plane-cuts-volume-rect.toml`: a bar's shadow volume crosses the near
    /// plane in a strip between two rows of the 9×9 grid, the eye lit. The grid alone misses it
    /// (z-pass was chosen: 384 pixels of `hard-sv` wrong); the exact rectangle test finds it,
    /// and finds nothing with the near plane moved to 0.1 (the rectangle then lies outside the
    /// volume).
    #[test]
    fn the_near_plane_cutting_a_thin_volume_between_grid_points_is_found() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenes/hard/near-plane-cuts-volume-rect.toml"
        );
        let scene = crate::scene::file::resolve(path).unwrap();
        let near = scene.camera.near.unwrap();
        let lights = representative_light_points(&scene);
        let grid = near_plane_points(&scene, near).iter().any(|p| {
            lights
                .iter()
                .any(|l| segment_blocked(&scene, *p, l.as_dvec3()))
        });
        assert!(!grid, "the grid misses the strip");
        assert!(near_rect_meets_shadow(&scene, near, &lights));
        assert!(eye_in_shadow(&scene, near, &lights));
        assert!(!near_rect_meets_shadow(&scene, 0.1, &lights));
        assert!(!eye_in_shadow(&scene, 0.1, &lights));
    }
}
