//! Closed mesh generators for the built-in scenes: spheres, boxes, capped cylinders, tori,
//! prisms and two-sided quads, all closed two-manifolds with shared vertices and counter-clockwise
//! outward winding.
//!
//! Positions are computed in f64 and rounded once to f32 (as [`Mesh`] stores them), so the
//! only platform dependence is the last bit of f64 `sin`/`cos`, which the f32 rounding hides
//! except in astronomically rare ties.

use super::Mesh;
use glam::{DMat4, DVec3, Mat4, Vec3};
use std::f64::consts::PI;

/// Rounds an f64 point to the f32 position a mesh stores.
fn f32v(p: DVec3) -> Vec3 {
    p.as_vec3()
}

/// A UV sphere around `center`: a single vertex at each pole (+y and −y), `stacks` bands
/// of latitude (≥ 2) and `slices` meridians (≥ 3); `2·slices·(stacks−1)` triangles.
///
/// # Panics
/// If `stacks < 2` or `slices < 3` (a programming error: only code calls this).
pub fn uv_sphere(
    name: &str,
    center: Vec3,
    radius: f32,
    stacks: u32,
    slices: u32,
    color: [f32; 3],
) -> Mesh {
    let r = f64::from(radius);
    star_sphere(name, center, (stacks, slices), |_, _| r, color)
}

/// A bumpy sphere around the origin: [`uv_sphere`]'s mesh with the radius `1 + amplitude·sin(b·φ)·cos(b·θ)`
/// at polar angle φ and azimuth θ, `b = bumps`: a closed, star-shaped mesh whose every bump
/// has its own silhouette loop, so that silhouettes grow with the triangle count (the
/// workload of `experiment cost-growth`). `amplitude` < 1 keeps it star-shaped.
///
/// # Panics
/// As [`uv_sphere`], or if `amplitude` is not in [0, 1).
pub fn bumpy_sphere(
    name: &str,
    (stacks, slices): (u32, u32),
    (bumps, amplitude): (u32, f64),
    color: [f32; 3],
) -> Mesh {
    assert!(
        (0.0..1.0).contains(&amplitude),
        "bumpy_sphere needs amplitude in [0, 1)"
    );
    let b = f64::from(bumps);
    let radius = |phi: f64, theta: f64| 1.0 + amplitude * libm::sin(b * phi) * libm::cos(b * theta);
    star_sphere(name, Vec3::ZERO, (stacks, slices), radius, color)
}

/// The mesh of [`uv_sphere`] with the radius a function of the polar angle φ and the azimuth θ
/// (the poles at θ = 0).
fn star_sphere(
    name: &str,
    center: Vec3,
    (stacks, slices): (u32, u32),
    radius: impl Fn(f64, f64) -> f64,
    color: [f32; 3],
) -> Mesh {
    assert!(
        stacks >= 2 && slices >= 3,
        "uv_sphere needs stacks ≥ 2 and slices ≥ 3"
    );
    let c = center.as_dvec3();
    let mut positions = vec![f32v(c + DVec3::new(0.0, radius(0.0, 0.0), 0.0))];
    for i in 1..stacks {
        let phi = PI * f64::from(i) / f64::from(stacks);
        let (sp, cp) = libm::sincos(phi);
        for j in 0..slices {
            let theta = 2.0 * PI * f64::from(j) / f64::from(slices);
            let (st, ct) = libm::sincos(theta);
            let r = radius(phi, theta);
            positions.push(f32v(c + r * DVec3::new(sp * ct, cp, -sp * st)));
        }
    }
    let south = positions.len() as u32;
    positions.push(f32v(c - DVec3::new(0.0, radius(PI, 0.0), 0.0)));

    // Ring i (1-based) vertex j is 1 + (i−1)·slices + j. θ runs counter-clockwise seen from +y.
    let ring = |i: u32, j: u32| 1 + (i - 1) * slices + (j % slices);
    let mut triangles = Vec::with_capacity((2 * slices * (stacks - 1)) as usize);
    for j in 0..slices {
        triangles.push([0, ring(1, j), ring(1, j + 1)]);
    }
    for i in 1..stacks - 1 {
        for j in 0..slices {
            let (a, b) = (ring(i, j), ring(i, j + 1));
            let (c, d) = (ring(i + 1, j), ring(i + 1, j + 1));
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
    }
    for j in 0..slices {
        triangles.push([south, ring(stacks - 1, j + 1), ring(stacks - 1, j)]);
    }
    Mesh {
        name: name.to_string(),
        positions,
        triangles,
        color,
        receiver_only: false,
        repairs: Default::default(),
    }
}

/// An axis-aligned box from `min` to `max`: 8 vertices, 12 triangles.
pub fn box_mesh(name: &str, min: Vec3, max: Vec3, color: [f32; 3]) -> Mesh {
    // Vertex i has x = max.x if bit 0, y = max.y if bit 1, z = max.z if bit 2.
    let positions = (0..8u32)
        .map(|i| {
            Vec3::new(
                if i & 1 != 0 { max.x } else { min.x },
                if i & 2 != 0 { max.y } else { min.y },
                if i & 4 != 0 { max.z } else { min.z },
            )
        })
        .collect();
    let quads: [[u32; 4]; 6] = [
        [0, 2, 3, 1], // −z
        [4, 5, 7, 6], // +z
        [0, 1, 5, 4], // −y
        [2, 6, 7, 3], // +y
        [0, 4, 6, 2], // −x
        [1, 3, 7, 5], // +x
    ];
    let triangles = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    Mesh {
        name: name.to_string(),
        positions,
        triangles,
        color,
        receiver_only: false,
        repairs: Default::default(),
    }
}

/// A capped cylinder with axis +y from `base_center` up to `base_center + height·y`:
/// `segments` (≥ 3) vertices per rim and one centre vertex per cap (fans), `4·segments`
/// triangles.
///
/// # Panics
/// If `segments < 3`.
pub fn cylinder(
    name: &str,
    base_center: Vec3,
    radius: f32,
    height: f32,
    segments: u32,
    color: [f32; 3],
) -> Mesh {
    assert!(segments >= 3, "cylinder needs at least 3 segments");
    let c = base_center.as_dvec3();
    let (r, h) = (f64::from(radius), f64::from(height));
    let mut positions = Vec::with_capacity(2 * segments as usize + 2);
    for level in [0.0, h] {
        for j in 0..segments {
            let theta = 2.0 * PI * f64::from(j) / f64::from(segments);
            let (st, ct) = libm::sincos(theta);
            positions.push(f32v(c + DVec3::new(r * ct, level, -r * st)));
        }
    }
    let bottom = 2 * segments;
    let top = bottom + 1;
    positions.push(f32v(c));
    positions.push(f32v(c + DVec3::new(0.0, h, 0.0)));
    let b = |j: u32| j % segments;
    let t = |j: u32| segments + j % segments;
    let mut triangles = Vec::with_capacity(4 * segments as usize);
    for j in 0..segments {
        triangles.push([b(j), b(j + 1), t(j + 1)]);
        triangles.push([b(j), t(j + 1), t(j)]);
        triangles.push([top, t(j), t(j + 1)]);
        triangles.push([bottom, b(j + 1), b(j)]);
    }
    Mesh {
        name: name.to_string(),
        positions,
        triangles,
        color,
        receiver_only: false,
        repairs: Default::default(),
    }
}

/// A torus around the +y axis through `center`: `rings` (≥ 3) segments around the axis at
/// major radius `major`, `sides` (≥ 3) around the tube of radius `minor`; `2·rings·sides`
/// triangles (genus 1: V − E + F = 0).
///
/// # Panics
/// If `rings < 3` or `sides < 3`.
pub fn torus(
    name: &str,
    center: Vec3,
    major: f32,
    minor: f32,
    [rings, sides]: [u32; 2],
    color: [f32; 3],
) -> Mesh {
    assert!(
        rings >= 3 && sides >= 3,
        "torus needs at least 3×3 segments"
    );
    let c = center.as_dvec3();
    let (big, small) = (f64::from(major), f64::from(minor));
    let mut positions = Vec::with_capacity((rings * sides) as usize);
    for i in 0..rings {
        let (su, cu) = libm::sincos(2.0 * PI * f64::from(i) / f64::from(rings));
        for j in 0..sides {
            let (sv, cv) = libm::sincos(2.0 * PI * f64::from(j) / f64::from(sides));
            let r = big + small * cv;
            positions.push(f32v(c + DVec3::new(r * cu, small * sv, -r * su)));
        }
    }
    let at = |i: u32, j: u32| (i % rings) * sides + j % sides;
    let mut triangles = Vec::with_capacity(2 * (rings * sides) as usize);
    for i in 0..rings {
        for j in 0..sides {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    Mesh {
        name: name.to_string(),
        positions,
        triangles,
        color,
        receiver_only: false,
        repairs: Default::default(),
    }
}

/// A prism: the convex polygon `base` (x, z points in order around it, either direction)
/// extruded from y = `y[0]` to `y[1]`; `2·(n − 2) + 2·n` triangles for n corners, wound
/// outward.
///
/// # Panics
/// If `base` has fewer than 3 corners.
pub fn prism(name: &str, base: &[[f32; 2]], y: [f32; 2], color: [f32; 3]) -> Mesh {
    let n = base.len() as u32;
    assert!(n >= 3, "a prism needs at least 3 base corners");
    let mut positions: Vec<Vec3> = Vec::with_capacity(2 * base.len());
    for level in y {
        positions.extend(base.iter().map(|[x, z]| Vec3::new(*x, level, *z)));
    }
    let mut triangles = Vec::with_capacity(4 * base.len() - 4);
    for k in 1..n - 1 {
        triangles.push([0, k + 1, k]);
        triangles.push([n, n + k, n + k + 1]);
    }
    for k in 0..n {
        let k1 = (k + 1) % n;
        triangles.push([k, k1, n + k1]);
        triangles.push([k, n + k1, n + k]);
    }
    // Orient every triangle away from the centroid (the prism is convex).
    let p: Vec<DVec3> = positions.iter().map(|v| v.as_dvec3()).collect();
    let centroid = p.iter().sum::<DVec3>() / p.len() as f64;
    for t in &mut triangles {
        let [a, b, c] = t.map(|i| p[i as usize]);
        if (b - a).cross(c - a).dot((a + b + c) / 3.0 - centroid) < 0.0 {
            t.swap(1, 2);
        }
    }
    Mesh {
        name: name.to_string(),
        positions,
        triangles,
        color,
        receiver_only: false,
        repairs: Default::default(),
    }
}

/// A closed two-sided quadrilateral (a planar occluder of zero thickness): the 4 `corners`
/// (in order around the quad; the front faces the side from which they appear
/// counter-clockwise), front triangles (0,1,2), (0,2,3) on diagonal 0–2 and back triangles
/// (1,0,3), (1,3,2) on diagonal 1–3, so every edge — the four sides and both diagonals — has
/// exactly two triangles, traversed once in each direction.
pub fn two_sided_quad(name: &str, corners: [Vec3; 4], color: [f32; 3]) -> Mesh {
    Mesh {
        name: name.to_string(),
        positions: corners.to_vec(),
        triangles: vec![[0, 1, 2], [0, 2, 3], [1, 0, 3], [1, 3, 2]],
        color,
        receiver_only: false,
        repairs: Default::default(),
    }
}

/// `mesh` with every vertex transformed by `m` (point, w = 1), computed in f64 and rounded
/// once to f32. A transform with negative determinant (a reflection) would turn the mesh
/// inside out, so the winding of every triangle is then flipped to stay outward.
/// The last row of `m` is assumed to be (0,0,0,1); it is ignored.
pub fn transformed(mesh: &Mesh, m: Mat4) -> Mesh {
    let md = m.as_dmat4();
    let positions = mesh
        .positions
        .iter()
        .map(|p| transform_point(&md, *p))
        .collect();
    let triangles = if md.determinant() < 0.0 {
        mesh.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect()
    } else {
        mesh.triangles.clone()
    };
    Mesh {
        name: mesh.name.clone(),
        positions,
        triangles,
        color: mesh.color,
        receiver_only: mesh.receiver_only,
        repairs: mesh.repairs.clone(),
    }
}

/// Transforms a point (w = 1) by an affine f64 matrix and rounds to f32.
pub(crate) fn transform_point(m: &DMat4, p: Vec3) -> Vec3 {
    f32v(m.transform_point3(p.as_dvec3()))
}

/// Six times the signed volume of a closed mesh (positive for outward winding), in f64.
pub fn signed_volume6(mesh: &Mesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3());
            a.dot(b.cross(c))
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::adjacency;

    const C: [f32; 3] = [0.5; 3];

    fn check_closed_outward(m: &Mesh, volume: f64, tol: f64) {
        let adj = adjacency::build(m).unwrap_or_else(|e| panic!("{}: {e}", m.name));
        assert_eq!(adj.edges.len() * 2, m.triangles.len() * 3);
        // Euler characteristic of a sphere: V − E + F = 2.
        assert_eq!(
            m.positions.len() as i64 - adj.edges.len() as i64 + m.triangles.len() as i64,
            2
        );
        let v = signed_volume6(m) / 6.0;
        assert!(
            (v - volume).abs() <= tol * volume.abs().max(1e-9),
            "{}: volume {v} vs {volume}",
            m.name
        );
        assert!(volume == 0.0 || v > 0.0);
    }

    #[test]
    fn sphere_closed_outward() {
        let m = uv_sphere("s", Vec3::new(1.0, 2.0, 3.0), 0.5, 8, 12, C);
        assert_eq!(m.triangles.len(), 2 * 12 * 7);
        assert_eq!(m.positions.len(), 12 * 7 + 2);
        // Inscribed polyhedron: volume a bit below 4/3 π r³.
        let full = 4.0 / 3.0 * PI * 0.125;
        let v = signed_volume6(&m) / 6.0;
        assert!(v > 0.8 * full && v < full, "{v} vs {full}");
        check_closed_outward(&m, v, 1e-12);
        // The smallest sphere: a triangular bipyramid, volume 2 · (1/3) · (3√3/4) · 1.
        let tiny = uv_sphere("s2", Vec3::ZERO, 1.0, 2, 3, C);
        check_closed_outward(&tiny, 3f64.sqrt() / 2.0, 1e-6);
    }

    /// The bumpy sphere is closed and outward, with the volume of its radius function:
    /// (2π/3)·(2 + (3a²/2)·(1 + 1/(4b² − 1))) (the odd powers of cos(bθ) integrate to 0),
    /// within the inscribed mesh's 1 %.
    #[test]
    fn bumpy_sphere_closed_outward() {
        let (a, b) = (0.1, 6.0);
        let m = bumpy_sphere("bumpy", (96, 192), (6, a), C);
        assert_eq!(m.triangles.len(), 2 * 192 * 95);
        let volume = 2.0 * PI / 3.0 * (2.0 + 1.5 * a * a * (1.0 + 1.0 / (4.0 * b * b - 1.0)));
        check_closed_outward(&m, volume, 0.01);
    }

    #[test]
    fn box_closed_outward() {
        let m = box_mesh("b", Vec3::new(-1.0, 0.0, 2.0), Vec3::new(1.0, 0.5, 5.0), C);
        assert_eq!(m.triangles.len(), 12);
        check_closed_outward(&m, 2.0 * 0.5 * 3.0, 1e-9);
    }

    #[test]
    fn cylinder_closed_outward() {
        let m = cylinder("c", Vec3::new(0.0, 1.0, 0.0), 0.5, 2.0, 24, C);
        assert_eq!(m.triangles.len(), 96);
        // Inscribed 24-gon prism: area = n/2 r² sin(2π/n).
        let area = 12.0 * 0.25 * libm::sin(2.0 * PI / 24.0);
        check_closed_outward(&m, area * 2.0, 1e-6);
        // Every side face points away from the axis.
        for t in &m.triangles[..] {
            let [a, b, c] = t.map(|i| m.positions[i as usize].as_dvec3());
            let n = (b - a).cross(c - a);
            let centroid = (a + b + c) / 3.0 - DVec3::new(0.0, 1.0, 0.0);
            if n.y.abs() < 1e-9 {
                assert!(n.dot(DVec3::new(centroid.x, 0.0, centroid.z)) > 0.0);
            }
        }
    }

    #[test]
    fn torus_closed_outward() {
        let m = torus("t", Vec3::new(0.0, 1.0, 0.0), 0.5, 0.15, [60, 48], C);
        assert_eq!(m.triangles.len(), 5760);
        let adj = adjacency::build(&m).unwrap();
        assert_eq!(
            m.positions.len() as i64 - adj.edges.len() as i64 + m.triangles.len() as i64,
            0
        );
        // Pappus: 2π²·R·r², the inscribed polyhedron slightly less.
        let full = 2.0 * PI * PI * 0.5 * 0.15 * 0.15;
        let v = signed_volume6(&m) / 6.0;
        assert!(v > 0.98 * full && v < full, "{v} vs {full}");
    }

    #[test]
    fn prism_closed_outward() {
        let base = [[0.9, 0.0], [-0.7, 0.2], [-0.7, -0.2]];
        let m = prism("p", &base, [1.0, 1.5], C);
        assert_eq!(m.triangles.len(), 8);
        check_closed_outward(&m, 0.5 * 1.6 * 0.4 * 0.5, 1e-6);
        let reversed: Vec<[f32; 2]> = base.iter().rev().copied().collect();
        check_closed_outward(&prism("q", &reversed, [1.0, 1.5], C), 0.16, 1e-6);
    }

    #[test]
    fn two_sided_quad_closed_flat() {
        let corners = [
            Vec3::new(-1.0, 1.0, 1.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, 1.0, -1.0),
            Vec3::new(-1.0, 1.0, -1.0),
        ];
        let m = two_sided_quad("q", corners, C);
        let adj = adjacency::build(&m).unwrap();
        assert_eq!(adj.edges.len(), 6);
        assert_eq!(signed_volume6(&m), 0.0);
        // Front faces +y for these corners.
        let [a, b, c] = m.triangles[0].map(|i| m.positions[i as usize]);
        assert!((b - a).cross(c - a).y > 0.0);
    }

    #[test]
    fn transformed_keeps_outward() {
        let m = box_mesh("b", Vec3::ZERO, Vec3::ONE, C);
        let moved = transformed(
            &m,
            Mat4::from_translation(Vec3::new(3.0, 0.0, 0.0)) * Mat4::from_scale(Vec3::splat(2.0)),
        );
        check_closed_outward(&moved, 8.0, 1e-9);
        assert_eq!(moved.positions[7], Vec3::new(5.0, 2.0, 2.0));
        let mirrored = transformed(&m, Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)));
        check_closed_outward(&mirrored, 1.0, 1e-9);
        let s = uv_sphere("s", Vec3::ZERO, 1.0, 6, 8, C);
        let rot = transformed(
            &s,
            Mat4::from_rotation_z(1.0) * Mat4::from_scale(Vec3::new(1.0, -2.0, 1.0)),
        );
        assert!(signed_volume6(&rot) > 0.0);
        adjacency::build(&rot).unwrap();
    }
}
