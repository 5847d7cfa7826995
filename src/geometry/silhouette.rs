//! Possible silhouette edges as seen from a point on the light (Paper I §3, Paper V §1):
//! an edge whose two triangles face the light point differently.
//!
//! Facing is decided once per triangle, in f64, as the sign of `n · (L − a)` with
//! `n = (b − a) × (c − a)`; a triangle exactly edge-on (zero) counts as back-facing. Because
//! each triangle's facing is computed once and shared by its three edges, the silhouette is
//! always consistent: every silhouette vertex has even degree (Paper V).

use crate::scene::adjacency::Adjacency;
use crate::scene::Mesh;
use glam::{DVec3, Vec3};

/// Whether each triangle of `mesh` faces the point `light`.
pub fn light_facing(mesh: &Mesh, light: Vec3) -> Vec<bool> {
    let l = light.as_dvec3();
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3());
            (b - a).cross(c - a).dot(l - a) > 0.0
        })
        .collect()
}

/// A possible silhouette edge, oriented as it appears in its light-facing triangle
/// (counter-clockwise seen from outside), so the light-facing side is on its left as seen
/// from the light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SilhouetteEdge {
    /// Index of the edge in the mesh's [`Adjacency`].
    pub edge: u32,
    /// Start vertex index.
    pub va: u32,
    /// End vertex index.
    pub vb: u32,
    /// Start position.
    pub a: Vec3,
    /// End position.
    pub b: Vec3,
}

/// The possible silhouette edges of `mesh` from the light point with the given triangle
/// facing, in adjacency edge order.
pub fn possible_silhouettes(mesh: &Mesh, adj: &Adjacency, facing: &[bool]) -> Vec<SilhouetteEdge> {
    adj.edges
        .iter()
        .enumerate()
        .filter_map(|(k, e)| {
            let f0 = facing[e.faces[0] as usize];
            let f1 = facing[e.faces[1] as usize];
            if f0 == f1 {
                return None;
            }
            // faces[0] holds v[0]→v[1]; orient along the light-facing triangle.
            let (va, vb) = if f0 {
                (e.v[0], e.v[1])
            } else {
                (e.v[1], e.v[0])
            };
            Some(SilhouetteEdge {
                edge: k as u32,
                va,
                vb,
                a: mesh.positions[va as usize],
                b: mesh.positions[vb as usize],
            })
        })
        .collect()
}

/// Direction from the light point to `p`, in f64 (the extrusion direction of shadow quads).
pub fn away_from_light(p: Vec3, light: Vec3) -> DVec3 {
    p.as_dvec3() - light.as_dvec3()
}
