//! Hard shadow volumes (Paper I §3; Paper II §5; Everitt & Kilgard's robust z-fail with an
//! infinite far plane).
//!
//! For a light point L, each possible silhouette edge a→b (oriented as in its light-facing
//! triangle) gives the shadow quad `b, a, a∞, b∞` with `x∞ = (x − L, 0)` at w = 0, wound so its
//! normal points out of the volume. Caps (z-fail only): the light-facing triangles as they
//! are (front cap) and the light-back-facing triangles projected to infinity with their
//! winding kept (back cap); both are then outward-facing too.
//!
//! Submission order (part of the contract, it matters with saturating stencil ops): meshes in
//! scene order; per mesh the front cap (triangle order), then the quads (adjacency edge order,
//! two triangles each: `(b, a, a∞)`, `(b, a∞, b∞)`), then the back cap (triangle order).

use super::silhouette::{away_from_light, light_facing, possible_silhouettes};
use crate::gpu::probe::{PrimitiveKind, ProbeEvent};
use crate::gpu::setup::RasterTriangle;
use crate::gpu::transform::{ClipVertex, Projection};
use crate::scene::adjacency::Adjacency;
use crate::scene::Mesh;
use glam::Vec3;

/// Which primitives a shadow volume is built from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Capping {
    /// Quads only (z-pass).
    Open,
    /// Quads plus front and back caps (z-fail).
    Capped,
}

/// The two triangles `(b, a, a∞)`, `(b, a∞, b∞)` of the shadow quad of silhouette edge a → b
/// from the clip coordinates of its ends (`near = [a, b]`) and of their extrusions to infinity
/// (`far = [a∞, b∞]`): the winding that makes the quad's normal point out of the volume.
pub fn quad_triangles(near: [ClipVertex; 2], far: [ClipVertex; 2]) -> [[ClipVertex; 3]; 2] {
    let ([a, b], [fa, fb]) = (near, far);
    [[b, a, fa], [b, fa, fb]]
}

/// The shadow quad of one silhouette edge a → b from light point `light`, exactly as
/// [`shadow_volume_triangles`] builds it for the same edge (same vertex transforms).
pub fn silhouette_quad(proj: &Projection, light: Vec3, a: Vec3, b: Vec3) -> [[ClipVertex; 3]; 2] {
    let far = |x: Vec3| proj.clip_direction(away_from_light(x, light));
    quad_triangles([proj.clip_point(a), proj.clip_point(b)], [far(a), far(b)])
}

/// What one shadow-volume triangle is (for probes, [`crate::gpu::probe`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum VolumePart {
    /// Front-cap triangle `triangle` of the mesh.
    FrontCap {
        /// Index of the mesh in the meshes given.
        mesh: usize,
        /// The mesh's triangle.
        triangle: usize,
    },
    /// Triangle `half` (0 or 1) of the quad of the mesh's possible silhouette edge `edge`
    /// (its index in [`possible_silhouettes`] order).
    Quad {
        /// Index of the mesh in the meshes given.
        mesh: usize,
        /// The silhouette edge.
        edge: usize,
        /// Which of the quad's two triangles.
        half: usize,
    },
    /// Back-cap triangle `triangle` of the mesh, at infinity.
    BackCap {
        /// Index of the mesh in the meshes given.
        mesh: usize,
        /// The mesh's triangle.
        triangle: usize,
    },
}

/// The probe event `e` naming the volume triangle `tri` ([`VolumePart::describe`] of its
/// primitive in `parts`, the parts of the submitted volume; `None` when no probe asked for
/// them, and `e` is returned as it is).
pub fn volume_event(
    e: ProbeEvent,
    parts: Option<&[VolumePart]>,
    tri: &RasterTriangle,
) -> ProbeEvent {
    match parts {
        Some(parts) => {
            let (kind, detail) = parts[tri.prim as usize].describe();
            e.primitive(kind, tri.prim, detail, Some(tri.front_facing))
        }
        None => e,
    }
}

impl VolumePart {
    /// The primitive a probe names for the triangle ([`crate::gpu::probe`]): its kind and what
    /// it belongs to.
    pub fn describe(&self) -> (PrimitiveKind, String) {
        match *self {
            VolumePart::FrontCap { mesh, triangle } => (
                PrimitiveKind::FrontCap,
                format!("triangle {triangle} of caster {mesh}"),
            ),
            VolumePart::Quad { mesh, edge, half } => (
                PrimitiveKind::ShadowQuad,
                format!("edge {edge} of caster {mesh}, half {half}"),
            ),
            VolumePart::BackCap { mesh, triangle } => (
                PrimitiveKind::BackCap,
                format!("triangle {triangle} of caster {mesh}"),
            ),
        }
    }
}

/// The clip-space triangles of the shadow volumes of `meshes` from light point `light`,
/// in submission order.
pub fn shadow_volume_triangles(
    meshes: &[(&Mesh, &Adjacency)],
    light: Vec3,
    proj: &Projection,
    capping: Capping,
) -> Vec<[ClipVertex; 3]> {
    let mut out = Vec::new();
    each_volume_triangle(meshes, light, proj, capping, |t, _| out.push(t));
    out
}

/// What each triangle of [`shadow_volume_triangles`] (same arguments) is, in the same order.
pub fn shadow_volume_parts(
    meshes: &[(&Mesh, &Adjacency)],
    light: Vec3,
    proj: &Projection,
    capping: Capping,
) -> Vec<VolumePart> {
    let mut out = Vec::new();
    each_volume_triangle(meshes, light, proj, capping, |_, part| out.push(part));
    out
}

/// Every shadow-volume triangle in submission order (module doc) with what it is.
fn each_volume_triangle(
    meshes: &[(&Mesh, &Adjacency)],
    light: Vec3,
    proj: &Projection,
    capping: Capping,
    mut emit: impl FnMut([ClipVertex; 3], VolumePart),
) {
    for (mi, (mesh, adj)) in meshes.iter().enumerate() {
        let facing = light_facing(mesh, light);
        let near: Vec<ClipVertex> = mesh.positions.iter().map(|p| proj.clip_point(*p)).collect();
        let far: Vec<ClipVertex> = mesh
            .positions
            .iter()
            .map(|p| proj.clip_direction(away_from_light(*p, light)))
            .collect();
        if capping == Capping::Capped {
            for (ti, (t, f)) in mesh.triangles.iter().zip(&facing).enumerate() {
                if *f {
                    let part = VolumePart::FrontCap {
                        mesh: mi,
                        triangle: ti,
                    };
                    emit(t.map(|i| near[i as usize]), part);
                }
            }
        }
        for (ei, e) in possible_silhouettes(mesh, adj, &facing).iter().enumerate() {
            let (a, b) = (e.va as usize, e.vb as usize);
            let quad = quad_triangles([near[a], near[b]], [far[a], far[b]]);
            for (half, t) in quad.into_iter().enumerate() {
                let part = VolumePart::Quad {
                    mesh: mi,
                    edge: ei,
                    half,
                };
                emit(t, part);
            }
        }
        if capping == Capping::Capped {
            for (ti, (t, f)) in mesh.triangles.iter().zip(&facing).enumerate() {
                if !*f {
                    let part = VolumePart::BackCap {
                        mesh: mi,
                        triangle: ti,
                    };
                    emit(t.map(|i| far[i as usize]), part);
                }
            }
        }
    }
}
