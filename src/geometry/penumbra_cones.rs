//! The cones and sheets of a penumbra map (Wyman & Hansen, EGSR 2003, §3 and Fig. 4, after
//! Haines 2001), built from the silhouette as seen from the light center.
//!
//! Notation: L the light center, k the light view's unit axis, Z(p) = (p − L)·k the view depth
//! of a point, Z_far the view depth of the light's far plane, L_r the light radius.
//!
//! * **Silhouette** ([`silhouettes`]): the possible silhouette edges of every mesh from L
//!   ([`super::silhouette`]) split into loops ([`super::loops`], Paper V). V is the set of
//!   vertices of those edges, E the edges.
//! * **Cone** of a silhouette vertex v (§3 bullet 3): tip at v, base on the far plane: the
//!   circle of radius `C_r = (Z_far − Z_v)·L_r / Z_v` in the far plane, centered where the ray
//!   from L through v meets it (the cone's axis is that ray, so from L the cone projects to a
//!   disk around v). The paper leaves the base plane's orientation to "the far plane"; we take
//!   the circle in the far plane (perpendicular to k), so C_r is measured there, as the
//!   formula's similar triangles along k do. The circle is cut into `segments` equal arcs,
//!   starting on the plane's first basis vector ([`DVec3::any_orthonormal_pair`] of k); cone
//!   triangle i is (v, b_i, b_{i+1}). Every vertex of a cone carries Z_v.
//! * **Sheet** of a silhouette edge a→b (§3 bullet 4): the quad joining the two cones on the
//!   outer side of the edge — the side away from the edge's light-facing triangle; inner
//!   sheets would lie over the occluder, where the penumbra pass discards them anyway (§3: the
//!   penumbra lies outside the hard shadow). Its far side is the outer common tangent of the
//!   two cones' base circles: with c_a, c_b the circles' centers, d̂ the unit direction
//!   c_a → c_b and m the unit vector of the far plane perpendicular to it on the outer side,
//!   the tangent's outward normal is `n̂ = ((C_ra − C_rb)/|c_b − c_a|)·d̂ + √(1 − (…)²)·m` and
//!   the quad is (a, b, c_b + C_rb·n̂, c_a + C_ra·n̂). Its two far-side edges from a and b are
//!   generators of the cones, so the sheet is tangent to both. Every sheet vertex carries the
//!   Z_v of its edge end (Z_a at a and its far point, Z_b at b and its far point); the
//!   rasterizer interpolates in between (§3: "for sheets we use the rasterizer to interpolate
//!   between the Z_vi values of the two adjacent cones").
//! * **Planarity** (§3: "depending on the cone radii, this quad may be non-planar. We subdivide
//!   extremely non-planar quads"): the test is the twist of the quad (a, b, B, A), the angle
//!   between the normals of its triangles (a, b, B) and (a, B, A) ([`quad_twist_deg`]). With
//!   the cone bases in one far plane the twist is zero: along the edge's line the base circles'
//!   centers and radii are affine functions of 1/Z (central projection of a line; C_r =
//!   L_r·(Z_far/Z − 1)), so their outer tangent is a line that meets the edge's line where it
//!   crosses the far plane (radius 0), and two intersecting lines are coplanar. So no quad
//!   needs subdividing; the largest twist is measured and reported
//!   ([`PenumbraGeometry::max_sheet_twist_deg`]: 1.2e−6° on every sphere-light built-in, the
//!   resolution of the angle itself, acos of a cosine one ulp below 1) — the paper's
//!   non-planar quads must come from a construction whose bases are not in one plane.
//! * An edge whose circles have no outer common tangent — one circle contains the other, as
//!   when the edge lies (almost) along a light ray — gets no sheet: the larger cone covers it
//!   (counted in [`PenumbraGeometry::skipped_sheets`]).
//!
//! Submission order: mesh by mesh in file order, loop by loop, edge by edge in walk order: the
//! cone of the edge's start vertex (the first time the vertex is met in its mesh), then the
//! edge's sheet.

use super::loops::{silhouette_loops, vertex_degrees};
use super::silhouette::{light_facing, possible_silhouettes, SilhouetteEdge};
use crate::scene::adjacency::Adjacency;
use crate::scene::Mesh;
use glam::{DVec3, Vec3};
use std::collections::BTreeSet;

/// The silhouette of one mesh from the light center.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshSilhouette {
    /// Possible silhouette edges, oriented along their light-facing triangle.
    pub edges: Vec<SilhouetteEdge>,
    /// Loops as indices into `edges`, in walk order.
    pub loops: Vec<Vec<usize>>,
    /// The largest number of silhouette edges at one vertex (0 without silhouette).
    pub max_vertex_degree: u32,
}

/// The silhouettes of `meshes` from the light center `light`. Errors name the mesh index of an
/// inconsistent silhouette (impossible for closed meshes, which validation guarantees).
pub fn silhouettes(
    meshes: &[(&Mesh, &Adjacency)],
    light: Vec3,
) -> Result<Vec<MeshSilhouette>, (usize, String)> {
    meshes
        .iter()
        .enumerate()
        .map(|(i, (mesh, adj))| {
            let facing = light_facing(mesh, light);
            let edges = possible_silhouettes(mesh, adj, &facing);
            let loops = silhouette_loops(&edges).map_err(|e| (i, e))?;
            let max_vertex_degree = vertex_degrees(&edges).values().copied().max().unwrap_or(0);
            Ok(MeshSilhouette {
                edges,
                loops,
                max_vertex_degree,
            })
        })
        .collect()
}

/// The light as the cones and sheets see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConeLight {
    /// Light center L.
    pub center: DVec3,
    /// Unit view axis k.
    pub axis: DVec3,
    /// View depth of the far plane, Z_far.
    pub far: f64,
    /// Light radius L_r.
    pub radius: f64,
}

impl ConeLight {
    /// View depth Z(p).
    pub fn depth(&self, p: DVec3) -> f64 {
        (p - self.center).dot(self.axis)
    }

    /// The point where the ray from the light center through `p` meets the far plane.
    pub fn on_far_plane(&self, p: DVec3) -> DVec3 {
        self.center + (p - self.center) * (self.far / self.depth(p))
    }

    /// The cone radius at the far plane of a point at view depth `z`:
    /// `C_r = (Z_far − z)·L_r / z` (§3).
    pub fn cone_radius(&self, z: f64) -> f64 {
        (self.far - z) * self.radius / z
    }
}

/// Which silhouette element a penumbra triangle belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConeOrSheet {
    /// The cone of a silhouette vertex.
    Cone,
    /// The sheet of a silhouette edge.
    Sheet,
}

/// One triangle of a cone or sheet, with Z_v at each corner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PenumbraTriangle {
    /// World-space corners.
    pub corners: [DVec3; 3],
    /// Z_v at each corner (the view depth of the silhouette point the corner belongs to).
    pub z_v: [f64; 3],
    /// Cone or sheet.
    pub kind: ConeOrSheet,
}

/// Every cone and sheet of a light, in submission order (module doc).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PenumbraGeometry {
    /// The triangles.
    pub triangles: Vec<PenumbraTriangle>,
    /// Number of cones (silhouette vertices).
    pub cones: usize,
    /// Number of sheets (silhouette edges with a sheet).
    pub sheets: usize,
    /// Largest sheet twist ([`quad_twist_deg`]), in degrees.
    pub max_sheet_twist_deg: f64,
    /// Silhouette edges without an outer common tangent, hence without a sheet.
    pub skipped_sheets: usize,
}

/// Build the cones and sheets of the silhouettes `sils` of `meshes` (module doc), `segments`
/// triangles per cone.
pub fn cones_and_sheets(
    meshes: &[&Mesh],
    sils: &[MeshSilhouette],
    light: &ConeLight,
    segments: u32,
) -> PenumbraGeometry {
    let mut g = PenumbraGeometry::default();
    let (e1, e2) = light.axis.any_orthonormal_pair();
    for (mesh, sil) in meshes.iter().zip(sils) {
        let mut coned = BTreeSet::new();
        for lp in &sil.loops {
            for &k in lp {
                let e = &sil.edges[k];
                if coned.insert(e.va) {
                    push_cone(
                        &mut g,
                        light,
                        mesh.positions[e.va as usize],
                        segments,
                        [e1, e2],
                    );
                }
                push_sheet(&mut g, light, e.a.as_dvec3(), e.b.as_dvec3());
            }
        }
    }
    g
}

fn push_cone(
    g: &mut PenumbraGeometry,
    light: &ConeLight,
    v: Vec3,
    segments: u32,
    basis: [DVec3; 2],
) {
    let tip = v.as_dvec3();
    let z = light.depth(tip);
    let center = light.on_far_plane(tip);
    let r = light.cone_radius(z);
    let base = |i: u32| {
        let a = std::f64::consts::TAU * (i % segments) as f64 / segments as f64;
        center + (basis[0] * libm::cos(a) + basis[1] * libm::sin(a)) * r
    };
    for i in 0..segments {
        g.triangles.push(PenumbraTriangle {
            corners: [tip, base(i), base(i + 1)],
            z_v: [z; 3],
            kind: ConeOrSheet::Cone,
        });
    }
    g.cones += 1;
}

/// The angle between the normals of the two triangles (p, q, Q) and (p, Q, P) of the quad
/// (p, q, Q, P), in degrees (0 for a planar convex quad).
pub fn quad_twist_deg(p: DVec3, q: DVec3, big_q: DVec3, big_p: DVec3) -> f64 {
    let n1 = (q - p).cross(big_q - p);
    let n2 = (big_q - p).cross(big_p - p);
    n1.angle_between(n2).to_degrees()
}

fn push_sheet(g: &mut PenumbraGeometry, light: &ConeLight, a: DVec3, b: DVec3) {
    let (c_a, c_b) = (light.on_far_plane(a), light.on_far_plane(b));
    let (z_a, z_b) = (light.depth(a), light.depth(b));
    let (r_a, r_b) = (light.cone_radius(z_a), light.cone_radius(z_b));
    let along = c_b - c_a;
    let len = along.length();
    let cos = (r_a - r_b) / len;
    // Not `cos.abs() < 1` (NaN for coincident centers, or nested circles): no tangent.
    if cos.is_nan() || cos.abs() >= 1.0 {
        g.skipped_sheets += 1;
        return;
    }
    let outward = (a - light.center).cross(b - light.center);
    let mut m = light.axis.cross(along).normalize();
    if m.dot(outward) < 0.0 {
        m = -m;
    }
    let n = along / len * cos + m * (1.0 - cos * cos).sqrt();
    let (big_a, big_b) = (c_a + n * r_a, c_b + n * r_b);
    g.sheets += 1;
    g.max_sheet_twist_deg = g
        .max_sheet_twist_deg
        .max(quad_twist_deg(a, b, big_b, big_a));
    g.triangles.push(PenumbraTriangle {
        corners: [a, b, big_b],
        z_v: [z_a, z_b, z_b],
        kind: ConeOrSheet::Sheet,
    });
    g.triangles.push(PenumbraTriangle {
        corners: [a, big_b, big_a],
        z_v: [z_a, z_b, z_a],
        kind: ConeOrSheet::Sheet,
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::adjacency;
    use crate::scene::procedural::box_mesh;

    fn light() -> ConeLight {
        ConeLight {
            center: DVec3::new(0.0, 3.0, 0.0),
            axis: DVec3::NEG_Y,
            far: 4.0,
            radius: 0.5,
        }
    }

    #[test]
    fn cone_radius_is_the_similar_triangles_of_fig_4() {
        let l = light();
        // A vertex at depth 2 (y = 1): C_r = (4 − 2)·0.5/2 = 0.5.
        assert_eq!(l.cone_radius(2.0), 0.5);
        let mut g = PenumbraGeometry::default();
        let (e1, e2) = l.axis.any_orthonormal_pair();
        push_cone(&mut g, &l, Vec3::new(0.25, 1.0, 0.0), 8, [e1, e2]);
        assert_eq!(g.triangles.len(), 8);
        // Base centered on the far plane (y = −1) where the ray through the tip meets it.
        let center = DVec3::new(0.5, -1.0, 0.0);
        for t in &g.triangles {
            assert_eq!(t.z_v, [2.0; 3]);
            for b in &t.corners[1..] {
                assert!((b.y + 1.0).abs() < 1e-12);
                assert!(((*b - center).length() - 0.5).abs() < 1e-12, "{b:?}");
            }
        }
    }

    #[test]
    fn box_sheets_are_planar_outside_the_silhouette_and_tangent_to_both_cones() {
        // A box under the light: its silhouette is the top face's outline (seen from above,
        // the side faces are edge-on or back-facing).
        let mesh = box_mesh(
            "box",
            Vec3::new(-0.5, 0.8, -0.3),
            Vec3::new(0.4, 1.0, 0.5),
            [0.5; 3],
        );
        let adj = adjacency::build(&mesh).unwrap();
        let l = light();
        let sils = silhouettes(&[(&mesh, &adj)], l.center.as_vec3()).unwrap();
        assert_eq!(sils[0].max_vertex_degree, 2);
        let g = cones_and_sheets(&[&mesh], &sils, &l, 16);
        assert_eq!(g.cones, sils[0].edges.len());
        assert_eq!(g.sheets, sils[0].edges.len());
        assert_eq!(g.skipped_sheets, 0);
        assert!(g.max_sheet_twist_deg < 1e-9, "{}", g.max_sheet_twist_deg);
        let box_center = DVec3::new(-0.05, 0.9, 0.1);
        let sheets: Vec<_> = g
            .triangles
            .iter()
            .filter(|t| t.kind == ConeOrSheet::Sheet)
            .collect();
        assert_eq!(sheets.len(), 2 * g.sheets);
        for t in sheets.chunks(2) {
            let [a, b, big_b] = t[0].corners;
            let big_a = t[1].corners[2];
            for (p, far) in [(a, big_a), (b, big_b)] {
                // On the far plane (y = −1), on the p cone's base circle, offset away from
                // the box.
                let c = l.on_far_plane(p);
                assert!((far.y + 1.0).abs() < 1e-12);
                assert!(((far - c).length() - l.cone_radius(l.depth(p))).abs() < 1e-12);
                assert!((far - c).dot(p - box_center) > 0.0, "{t:?}");
            }
            // Tangent to both base circles: the far line's distance to each center is its radius.
            let dir = (big_b - big_a).normalize();
            for (p, far) in [(a, big_a), (b, big_b)] {
                let c = l.on_far_plane(p);
                let off = (c - far) - dir * (c - far).dot(dir);
                assert!((off.length() - l.cone_radius(l.depth(p))).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn steep_edges_give_planar_sheets_and_nested_circles_give_none() {
        let l = ConeLight {
            radius: 1.0,
            ..light()
        };
        // An edge climbing steeply in depth: very different cone radii, still planar.
        let mut g = PenumbraGeometry::default();
        push_sheet(
            &mut g,
            &l,
            DVec3::new(-0.5, 1.5, 0.2),
            DVec3::new(0.5, 0.2, 0.2),
        );
        assert_eq!(g.sheets, 1);
        assert!(g.max_sheet_twist_deg < 1e-9, "{}", g.max_sheet_twist_deg);
        assert_eq!(g.triangles[0].z_v, [1.5, 2.8, 2.8]);
        // An edge along a light ray: one base circle inside the other, no sheet.
        let mut g = PenumbraGeometry::default();
        push_sheet(
            &mut g,
            &l,
            DVec3::new(0.1, 2.0, 0.1),
            DVec3::new(0.2, 1.0, 0.2),
        );
        assert_eq!((g.sheets, g.skipped_sheets), (0, 1));
        assert!(g.triangles.is_empty());
    }
}
