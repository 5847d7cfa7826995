//! Umbra and penumbra volumes of a circular disk light (CGI 2004, "Soft shadows with correct
//! boundaries from umbra and penumbra volumes", §2.1 and §3.3): the geometry the `dbuffer`
//! method renders into its D-buffer ([`crate::methods::dbuffer`]).
//!
//! Notation: c the disk's center, n_c its unit normal, r its radius; a face Φ of a mesh has the
//! outward normal n = (b − a) × (c − a) of its triangle (a, b, c) and faces a point p when
//! n · (p − a) > 0 (a face seen edge-on does not face p, as in [`super::silhouette`]).
//! Everything is computed in f64 from the f32 mesh positions.
//!
//! # Silhouettes for a disk (§2.1, eq. 1)
//!
//! Per face, the disk point most in front of its plane, p_near, and the one most behind it,
//! p_far: "if p_near is in the negative half-space of Φ, so is every other point on the disk.
//! Similarly if p_far is in the positive half-space, then every other point is too."
//! Eq. 1 as printed, p_near = c + r((n × n_c) × n_c) and p_far = c − r((n × n_c) × n_c),
//! contradicts that sentence: (n × n_c) × n_c = −n_⊥ (the vector triple product; n_⊥ is the
//! part of n in the light plane), so the printed p_near is the point *behind* the plane, and
//! for unit n its length r|n_⊥| is off the rim unless n lies in the light plane. The text's
//! property needs the rim points ±r·n̂_⊥, so we take the text: with
//! w = normalize((n × n_c) × n_c), **p_near = c − r·w, p_far = c + r·w** (both c when n ∥ n_c,
//! where every disk point is equally far from the plane). [`Disk::extremes`]; the unit test
//! checks the property against the whole rim.
//!
//! Faces are **none-frontfacing** when p_near does not face them (no disk point does),
//! **all-frontfacing** when p_far faces them (every disk point does), else **silhouette faces**
//! ([`FaceClass`]). An edge is on the **umbra-volume silhouette** when exactly one of its two
//! faces is none-frontfacing, on the **penumbra-volume silhouette** when exactly one is
//! all-frontfacing ([`volume_edges`]); an edge between an all- and a none-frontfacing face is on
//! both. Each such edge is oriented a → b as it appears (counter-clockwise from outside) in its
//! *front* face: the face that is not none-frontfacing for the umbra, the all-frontfacing face
//! for the penumbra — so the front face lies on the same side for every point the volume is
//! extruded from, and the edges form closed loops ([`super::loops`]) as the silhouettes from a
//! point do.
//!
//! # Extrusion points (§2.1, Fig. 3b)
//!
//! The two planes through an edge v1 v2 tangent to the circle touch it where the tangents from
//! a, the point where the edge's line meets the light plane, touch it
//! (a = (cv1·n_c)/(v2v1·n_c)·v1v2 + v1, the paper's formula). We compute a homogeneously, A =
//! (v1 − c)(n_c·(v2 − v1)) − (v2 − v1)(n_c·(v1 − c)) with weight W = n_c·(v2 − v1), so that
//! a − c = A/W, and take the tangent points of the circle from A: with (X, Y) the light-plane
//! coordinates of A, L = |(X, Y)| and q = rW/L (r over the distance of a from c),
//! `t± = c + (rq/L)(X, Y) ± r√(1 − q²)(−Y, X)/L` ([`Disk::tangent_points`]).
//!
//! * **The edge parallel to the light plane** (the paper defers to its reference): W = 0 puts a
//!   at infinity, and the same formula gives its limit, t± = c ± r·ŵ with ŵ the in-plane unit
//!   vector perpendicular to the edge — the two planes through the edge parallel to it that
//!   touch the circle. No special branch; the flat occluders of the built-in disk scenes have
//!   such edges everywhere (tested against the general case for a nearly parallel edge).
//! * **a inside the circle** "never occurs for a silhouette edge in a closed two-manifold
//!   mesh": a lies on both face planes, and a plane through an interior point of the disk has
//!   disk points strictly on both sides, so neither face could be all- or none-frontfacing.
//!   This is checked, not trusted: an edge whose q exceeds 1 by more than [`TANGENT_SLACK`] is
//!   counted ([`VolumeStats::a_inside_circle`]) and gets no quad; the tests assert the count
//!   is 0 on every hard case. Within the slack (rounding of a tangent plane) q is taken as 1.
//! * An edge lying in the light plane (A = 0, W = 0) has no tangent plane but the light plane
//!   itself; it is counted ([`VolumeStats::degenerate_edges`]) and gets no quad.
//!
//! **Which tangent point is p_u and which p_p.** The paper describes the edge that is on both
//! silhouettes, "not a general case". We use the construction's own meaning: the volume quad
//! through the edge is the shadow-volume quad of the light point where the edge is the
//! silhouette (its front face faces the point and its other face does not) that is extreme —
//! the smallest shadow (umbra, the intersection of the shadow volumes) or the largest
//! (penumbra, their union). When exactly one tangent point makes the edge a silhouette (one
//! face is a silhouette face, whose plane cuts the disk between the two tangent points), it is
//! the one. When both do (an all-/none-frontfacing edge), the quad plane M_t = (b − a) ×
//! (t − a) has the volume on its negative side; the umbra takes the t whose other tangent
//! point t′ is inside it (M_t·(t′ − a) < 0: every other disk point's shadow extends beyond
//! the plane), the penumbra the t whose t′ is outside. When rounding leaves neither (a face
//! plane through a tangent point), the same rule decides.
//!
//! **Extrusion.** A quad is the region of the plane through a → b and its extrusion point
//! between its two sides, the rays from a and from b away from the extrusion point (or the
//! seams that replace them at trimmed corners, below), up to the sphere of radius `bound`
//! around c — a sphere that holds every mesh vertex, so every receiver lies between the
//! silhouette and the quad's far edge, and the quads are no longer than the scene needs (their
//! distance values are interpolated linearly, §3.2, so the error grows with their length). It
//! is the triangles (a, b, f_b), (a, f_b, f_a), f the points where the sides leave the sphere,
//! or the triangle (a, b, P) when the two sides meet at P inside it.
//!
//! # Corners (§2.1: trimming and closing)
//!
//! At the vertex v between consecutive edges e1 = a1 → v and e2 = v → b2 of a loop, with
//! extrusion points p1, p2 and quad planes M1, M2 (outward normals, as above), the corner is
//! **convex** when e2 turns into Q1's half-space (M1·(b2 − v) < 0: the volume is locally the
//! intersection of the two half-spaces) and **reflex** otherwise (locally their union). Seen in
//! a cross-section behind the corner, Q1 and Q2 are two rays that start where v's extrusions
//! through p1 and p2 land; whether they cross depends on where the far edge of Q2 at v,
//! v − p2, lies relative to Q1's plane:
//!
//! * the quads **converge** when it points out of Q1's half-space at a convex corner
//!   (M1·(v − p2) > 0), or into it at a reflex one: they intersect along a line through v and
//!   are **trimmed** there ("the extruded quads of the umbra volume need to be trimmed as they
//!   will otherwise intersect"): the **seam**, the common line of the two planes from v away
//!   from the light (direction ±M1 × M2), becomes the end side of Q1 and the start side of Q2,
//!   so each keeps the part on its own side of it (inside the other's half-space at a convex
//!   corner, outside at a reflex one) and both share the seam's two vertices bit for bit: no
//!   crack between them for a ray to pass through;
//! * otherwise they **diverge** and the gap is closed by a fan of triangles (v, f(p(θ_k)),
//!   f(p(θ_k+1))) with p(θ) the rim point at angle θ, interpolating from p1 to p2 along the
//!   shorter arc in ⌈|Δθ|·`fan-segments`/2π⌉ steps ("in the case of a circular light source,
//!   it is preferable to extrude more triangles using interpolation between pp for each of the
//!   two adjacent edges"). The ends are p1 and p2 themselves, so the fan meets both quads.
//!
//! At a convex corner this trims the umbra (the intersection of shadows whose corner moves
//! with the light point is bounded by the two extreme edges' planes, which cross) and closes
//! the penumbra (their union is bounded by a cone piece from v between them), as the paper
//! describes for convex occluders; at a reflex corner the roles swap (the penumbra quads cross,
//! the umbra needs the cone piece). The paper names only the first case; we apply the one rule
//! at every corner and count each kind ([`VolumeStats`]) (the zigzag silhouettes of
//! `disk-torus` have both kinds all along). Intersections between quads that are not
//! neighbours in their loop are not trimmed: §4 handles them with the depth test ("it is much
//! easier to use depth test to ensure storing of proper distances"), and that is the paper's
//! no-umbra artifact — also where a short edge separates two long ones, as the vertical edges
//! of a thin slab whose sides are silhouette faces (measured in `tests/suite/dbuffer.rs`).
//!
//! # Silhouette faces (§3.3)
//!
//! Between the two silhouettes lie the silhouette faces; a ray from c through one that faces
//! away from c meets neither volume (Fig. 6's gap). "The straight-forward solution to this
//! problem is to render the silhouette faces as a part of the umbra volume", and the category
//! of Fig. 6 is the one whose plane has c in its negative half-space: those faces (not facing
//! c) are appended to the umbra volume. Silhouette faces that face c are seen from c as part
//! of the occluder and leave no gap.
//!
//! # Output
//!
//! [`build_volumes`] returns the triangles of both volumes in submission order: mesh by mesh
//! in file order, loop by loop ([`super::loops::silhouette_loops`]), edge by edge in walk
//! order: the edge's quad, then the fan of the corner at its end; for the umbra, then the
//! mesh's silhouette faces not facing c, in triangle order. Every vertex carries its
//! **silhouette point** e: the vertex itself for points on a silhouette edge and for
//! silhouette faces, the edge end whose side it ends for far points (a seam's far point: the
//! corner vertex), the middle of the edge for the meeting point P of a quad's two sides —
//! which is what eq. 2's "dist(c, e)" and "dir(c, e)" are evaluated at in the vertex program.

use super::loops::silhouette_loops;
use super::silhouette::SilhouetteEdge;
use crate::light::sampling::orthonormal_basis;
use crate::scene::adjacency::Adjacency;
use crate::scene::Mesh;
use glam::{DVec2, DVec3, Vec3};
use serde::Serialize;
use std::f64::consts::{PI, TAU};

/// How far beyond 1 the tangent parameter q = r/|a − c| may be and still be taken as a tangent
/// plane (rounding of a face plane that touches the rim).
pub const TANGENT_SLACK: f64 = 1e-9;

/// The circular disk light of the paper: center, unit normal, radius and an orthonormal basis
/// of its plane ([`orthonormal_basis`], the basis the samplers use).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Disk {
    /// Center c.
    pub center: DVec3,
    /// Unit normal n_c.
    pub normal: DVec3,
    /// Radius r.
    pub radius: f64,
    /// Orthonormal basis of the light plane.
    pub basis: [DVec3; 2],
}

/// The classification of a face with respect to the whole disk (§2.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum FaceClass {
    /// Every disk point faces it.
    AllFront,
    /// No disk point faces it.
    NoneFront,
    /// Some disk points face it and some do not.
    Silhouette,
}

/// The two tangent points of the circle seen from the point a of an edge's line (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tangents {
    /// The two points, and whether the edge is parallel to the light plane (a at infinity).
    Points {
        /// t+ and t−.
        points: [DVec3; 2],
        /// W = 0.
        parallel: bool,
    },
    /// a lies inside the circle: no tangent plane.
    Inside,
    /// The edge lies in the light plane.
    Degenerate,
}

impl Disk {
    /// The disk of `radius` around `center` facing along `normal` (normalized in f64).
    pub fn new(center: Vec3, normal: Vec3, radius: f32) -> Self {
        let normal = normal.as_dvec3().normalize();
        let (b1, b2) = orthonormal_basis(normal);
        Self {
            center: center.as_dvec3(),
            normal,
            radius: f64::from(radius),
            basis: [b1, b2],
        }
    }

    /// `[p_near, p_far]` of a face with normal `n` (module doc: eq. 1 read as its text says).
    pub fn extremes(&self, n: DVec3) -> [DVec3; 2] {
        let w = n.cross(self.normal).cross(self.normal);
        match w.try_normalize() {
            Some(w) => [self.center - self.radius * w, self.center + self.radius * w],
            None => [self.center; 2],
        }
    }

    /// The class of the triangle `tri` (module doc).
    pub fn classify(&self, tri: [DVec3; 3]) -> FaceClass {
        let [a, b, c] = tri;
        let n = (b - a).cross(c - a);
        let [near, far] = self.extremes(n);
        if !faces(n, a, near) {
            FaceClass::NoneFront
        } else if faces(n, a, far) {
            FaceClass::AllFront
        } else {
            FaceClass::Silhouette
        }
    }

    /// The rim point at angle `theta` in the plane basis.
    pub fn rim_point(&self, theta: f64) -> DVec3 {
        let (s, c) = libm::sincos(theta);
        self.center + self.radius * (c * self.basis[0] + s * self.basis[1])
    }

    /// The angle of (the projection of) `p` around the center in the plane basis.
    pub fn angle_of(&self, p: DVec3) -> f64 {
        let d = p - self.center;
        libm::atan2(d.dot(self.basis[1]), d.dot(self.basis[0]))
    }

    /// The tangent points of the circle from the point where the line through `v1` and `v2`
    /// meets the light plane (module doc, "Extrusion points").
    pub fn tangent_points(&self, v1: DVec3, v2: DVec3) -> Tangents {
        let (c, nc, r) = (self.center, self.normal, self.radius);
        let d = v2 - v1;
        let w = nc.dot(d);
        let a = (v1 - c) * w - d * nc.dot(v1 - c);
        let xy = DVec2::new(a.dot(self.basis[0]), a.dot(self.basis[1]));
        let l = xy.length();
        if l == 0.0 {
            return if w == 0.0 {
                Tangents::Degenerate
            } else {
                Tangents::Inside
            };
        }
        let q = r * w / l;
        if q.abs() > 1.0 + TANGENT_SLACK {
            return Tangents::Inside;
        }
        let q = q.clamp(-1.0, 1.0);
        let foot = xy * (r * q / l);
        let off = DVec2::new(-xy.y, xy.x) * (r * (1.0 - q * q).sqrt() / l);
        let to_world = |p: DVec2| c + p.x * self.basis[0] + p.y * self.basis[1];
        Tangents::Points {
            points: [to_world(foot + off), to_world(foot - off)],
            parallel: w == 0.0,
        }
    }
}

/// Whether a face with normal `n` through `a` faces the point `p`.
fn faces(n: DVec3, a: DVec3, p: DVec3) -> bool {
    n.dot(p - a) > 0.0
}

/// The corners of triangle `t` of `mesh` in f64.
fn corners(mesh: &Mesh, t: usize) -> [DVec3; 3] {
    mesh.triangles[t].map(|i| mesh.positions[i as usize].as_dvec3())
}

/// The class of every triangle of `mesh` for `disk`.
pub fn classify_faces(mesh: &Mesh, disk: &Disk) -> Vec<FaceClass> {
    (0..mesh.triangles.len())
        .map(|t| disk.classify(corners(mesh, t)))
        .collect()
}

/// Which of the two volumes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Volume {
    /// The umbra volume: the intersection of the shadow volumes of every disk point.
    Umbra,
    /// The penumbra volume: their union.
    Penumbra,
}

/// A silhouette edge of one volume: oriented along its front face (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumeEdge {
    /// The edge, `va → vb` counter-clockwise in the front face.
    pub edge: SilhouetteEdge,
    /// The front face (not none-frontfacing for the umbra, all-frontfacing for the penumbra).
    pub front: u32,
    /// The other face.
    pub back: u32,
}

/// The silhouette edges of `volume` in adjacency edge order (module doc).
pub fn volume_edges(
    mesh: &Mesh,
    adj: &Adjacency,
    classes: &[FaceClass],
    volume: Volume,
) -> Vec<VolumeEdge> {
    let member = |f: u32| match volume {
        Volume::Umbra => classes[f as usize] == FaceClass::NoneFront,
        Volume::Penumbra => classes[f as usize] == FaceClass::AllFront,
    };
    adj.edges
        .iter()
        .enumerate()
        .filter(|(_, e)| member(e.faces[0]) != member(e.faces[1]))
        .map(|(k, e)| {
            // The umbra's front face is the non-member, the penumbra's the member.
            let first_is_front = member(e.faces[0]) == (volume == Volume::Penumbra);
            let (front, back, va, vb) = if first_is_front {
                (e.faces[0], e.faces[1], e.v[0], e.v[1])
            } else {
                (e.faces[1], e.faces[0], e.v[1], e.v[0])
            };
            VolumeEdge {
                edge: SilhouetteEdge {
                    edge: k as u32,
                    va,
                    vb,
                    a: mesh.positions[va as usize],
                    b: mesh.positions[vb as usize],
                },
                front,
                back,
            }
        })
        .collect()
}

/// A vertex of a volume triangle: its position and its silhouette point (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumeVertex {
    /// World position.
    pub position: DVec3,
    /// The silhouette point eq. 2 is evaluated at.
    pub silhouette: DVec3,
}

/// A vertex on a silhouette (its own silhouette point).
fn on_silhouette(p: DVec3) -> VolumeVertex {
    VolumeVertex {
        position: p,
        silhouette: p,
    }
}

/// What building the volumes of one scene found (module doc), summed over meshes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct VolumeStats {
    /// All-frontfacing faces.
    pub all_front_faces: u64,
    /// None-frontfacing faces.
    pub none_front_faces: u64,
    /// Silhouette faces.
    pub silhouette_faces: u64,
    /// Silhouette faces not facing c, rendered as part of the umbra volume (§3.3).
    pub silhouette_faces_rendered: u64,
    /// Umbra-volume silhouette edges.
    pub umbra_edges: u64,
    /// Penumbra-volume silhouette edges.
    pub penumbra_edges: u64,
    /// Loops of the two silhouettes.
    pub loops: u64,
    /// Edges parallel to the light plane (a at infinity).
    pub parallel_edges: u64,
    /// Edges whose a falls inside the circle (never, for closed meshes: module doc).
    pub a_inside_circle: u64,
    /// Edges lying in the light plane (no quad).
    pub degenerate_edges: u64,
    /// Edges for which exactly one tangent point makes the edge a silhouette.
    pub one_candidate: u64,
    /// Edges for which both do.
    pub two_candidates: u64,
    /// Edges for which rounding left neither.
    pub no_candidate: u64,
    /// Corners whose quads were trimmed, at convex corners.
    pub trimmed_convex: u64,
    /// Corners whose quads were trimmed, at reflex corners.
    pub trimmed_reflex: u64,
    /// Corners closed with a fan, at convex corners.
    pub fanned_convex: u64,
    /// Corners closed with a fan, at reflex corners.
    pub fanned_reflex: u64,
    /// Umbra-volume triangles.
    pub umbra_triangles: u64,
    /// Penumbra-volume triangles.
    pub penumbra_triangles: u64,
}

/// The two volumes of a scene (module doc, "Output").
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Volumes {
    /// Umbra-volume triangles (quads, corner fans, silhouette faces), in submission order.
    pub umbra: Vec<[VolumeVertex; 3]>,
    /// Penumbra-volume triangles (quads, corner fans), in submission order.
    pub penumbra: Vec<[VolumeVertex; 3]>,
    /// Per mesh (in the order given), the end of its triangles in `umbra` and in `penumbra`:
    /// mesh i's are `ends[i - 1]..ends[i]` (from 0 for the first).
    pub mesh_ends: Vec<[usize; 2]>,
    /// What was found.
    pub stats: VolumeStats,
}

impl Volumes {
    /// The index of the mesh (in the order given to [`build_volumes`]) whose volume triangle
    /// `prim` is, in the umbra volume (`umbra`) or the penumbra volume.
    pub fn mesh_of(&self, umbra: bool, prim: usize) -> usize {
        let k = usize::from(!umbra);
        self.mesh_ends.partition_point(|e| e[k] <= prim)
    }
}

/// The extrusion of one volume edge a → b: its tangent point and the directions of the quad's
/// two sides, from a and from b (the rays away from the tangent point, or a corner's seam).
#[derive(Debug, Clone, Copy)]
struct Quad {
    /// The extrusion point p_u or p_p.
    point: DVec3,
    /// The side from a.
    start: DVec3,
    /// The side from b.
    end: DVec3,
}

/// The settings of the extrusion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extrusion {
    /// Radius of the sphere around c that the quads reach (module doc, "Extrusion").
    pub bound: f64,
    /// Fan triangles per full circle at diverging corners.
    pub fan_segments: u32,
}

impl Extrusion {
    /// The point where the ray from `x` along `dir` leaves the sphere of radius
    /// [`Extrusion::bound`] around `center` (`x` itself if it is not inside or `dir` is 0).
    pub fn far(&self, center: DVec3, x: DVec3, dir: DVec3) -> DVec3 {
        let Some(u) = dir.try_normalize() else {
            return x;
        };
        let m = x - center;
        let b = m.dot(u);
        let disc = b * b - (m.length_squared() - self.bound * self.bound);
        let s = -b + disc.max(0.0).sqrt();
        x + u * s.max(0.0)
    }
}

/// Choose the extrusion point of `e` for `volume` among the tangent points (module doc).
fn extrusion_point(
    mesh: &Mesh,
    e: &VolumeEdge,
    t: [DVec3; 2],
    volume: Volume,
    stats: &mut VolumeStats,
) -> DVec3 {
    let normal = |f: u32| {
        let [a, b, c] = corners(mesh, f as usize);
        ((b - a).cross(c - a), a)
    };
    let (nf, af) = normal(e.front);
    let (nb, ab) = normal(e.back);
    let silhouette_at = |p: DVec3| faces(nf, af, p) && !faces(nb, ab, p);
    let (a, b) = (e.edge.a.as_dvec3(), e.edge.b.as_dvec3());
    match [silhouette_at(t[0]), silhouette_at(t[1])] {
        [true, false] => {
            stats.one_candidate += 1;
            t[0]
        }
        [false, true] => {
            stats.one_candidate += 1;
            t[1]
        }
        both_or_none => {
            if both_or_none[0] {
                stats.two_candidates += 1;
            } else {
                stats.no_candidate += 1;
            }
            // M_t0 · (t1 − a): where t1 lies relative to the quad plane through t0.
            let s = (b - a).cross(t[0] - a).dot(t[1] - a);
            let t0_is_it = match volume {
                Volume::Umbra => s < 0.0,
                Volume::Penumbra => s > 0.0,
            };
            if t0_is_it {
                t[0]
            } else {
                t[1]
            }
        }
    }
}

/// The outward normal of the quad plane through edge a → b and extrusion point p.
fn quad_normal(a: DVec3, b: DVec3, p: DVec3) -> DVec3 {
    (b - a).cross(p - a)
}

/// The silhouettes of one volume of one mesh, extruded, trimmed and closed, appended to `out`.
fn extrude_volume(
    mesh: &Mesh,
    edges: &[VolumeEdge],
    disk: &Disk,
    ex: &Extrusion,
    volume: Volume,
    stats: &mut VolumeStats,
    out: &mut Vec<[VolumeVertex; 3]>,
) -> Result<(), String> {
    let loops = silhouette_loops(&edges.iter().map(|e| e.edge).collect::<Vec<_>>())?;
    stats.loops += loops.len() as u64;
    let c = disk.center;
    let mut quads: Vec<Option<Quad>> = edges
        .iter()
        .map(|e| {
            let (a, b) = (e.edge.a.as_dvec3(), e.edge.b.as_dvec3());
            match disk.tangent_points(a, b) {
                Tangents::Points { points, parallel } => {
                    stats.parallel_edges += parallel as u64;
                    let p = extrusion_point(mesh, e, points, volume, stats);
                    Some(Quad {
                        point: p,
                        start: a - p,
                        end: b - p,
                    })
                }
                Tangents::Inside => {
                    stats.a_inside_circle += 1;
                    None
                }
                Tangents::Degenerate => {
                    stats.degenerate_edges += 1;
                    None
                }
            }
        })
        .collect();
    // Corners: seams replace the sides of converging quads, fans close diverging ones.
    let mut fans: Vec<Vec<[VolumeVertex; 3]>> = vec![Vec::new(); edges.len()];
    for lp in &loops {
        for k in 0..lp.len() {
            let (i1, i2) = (lp[k], lp[(k + 1) % lp.len()]);
            let (Some(q1), Some(q2)) = (quads[i1], quads[i2]) else {
                continue;
            };
            let a1 = edges[i1].edge.a.as_dvec3();
            let v = edges[i1].edge.b.as_dvec3();
            let b2 = edges[i2].edge.b.as_dvec3();
            let (m1, m2) = (quad_normal(a1, v, q1.point), quad_normal(v, b2, q2.point));
            let convex = m1.dot(b2 - v) < 0.0;
            // Q2's far edge at v outside Q1's half-space: the quads meet at a convex corner
            // and part at a reflex one (module doc, "Corners").
            if (m1.dot(v - q2.point) > 0.0) == convex {
                // The seam: the planes' common line through v, away from the light.
                let Some(mut seam) = m1.cross(m2).try_normalize() else {
                    continue;
                };
                if seam.dot(q1.end + q2.start) < 0.0 {
                    seam = -seam;
                }
                if convex {
                    stats.trimmed_convex += 1;
                } else {
                    stats.trimmed_reflex += 1;
                }
                if let Some(q) = &mut quads[i1] {
                    q.end = seam;
                }
                if let Some(q) = &mut quads[i2] {
                    q.start = seam;
                }
            } else {
                let fan = corner_fan(disk, ex, v, q1.point, q2.point);
                if !fan.is_empty() {
                    if convex {
                        stats.fanned_convex += 1;
                    } else {
                        stats.fanned_reflex += 1;
                    }
                }
                fans[i1] = fan;
            }
        }
    }
    for lp in &loops {
        for &i in lp {
            if let Some(q) = &quads[i] {
                let e = &edges[i].edge;
                out.extend(quad_triangles(c, ex, e.a.as_dvec3(), e.b.as_dvec3(), q));
            }
            out.extend_from_slice(&fans[i]);
        }
    }
    Ok(())
}

/// The triangles of the (trimmed) quad of edge a → b (module doc, "Corners"): the region
/// between its two sides up to the bounding sphere — the triangle (a, b, P) when the sides
/// meet at P inside the sphere, else (a, b, f_b), (a, f_b, f_a) with f the sides' exits.
fn quad_triangles(
    c: DVec3,
    ex: &Extrusion,
    a: DVec3,
    b: DVec3,
    q: &Quad,
) -> Vec<[VolumeVertex; 3]> {
    let (va, vb) = (on_silhouette(a), on_silhouette(b));
    let den = q.start.cross(q.end).length_squared();
    // a + λ·start = b + μ·end, solved in the plane of the quad.
    if den > 0.0 {
        let w = b - a;
        let cross = q.start.cross(q.end);
        let lambda = w.cross(q.end).dot(cross) / den;
        let mu = w.cross(q.start).dot(cross) / den;
        let p = a + q.start * lambda;
        if lambda > 0.0 && mu > 0.0 && (p - c).length() < ex.bound {
            let apex = VolumeVertex {
                position: p,
                silhouette: (a + b) * 0.5,
            };
            return vec![[va, vb, apex]];
        }
    }
    let far = |x: DVec3, dir: DVec3| VolumeVertex {
        position: ex.far(c, x, dir),
        silhouette: x,
    };
    let (fa, fb) = (far(a, q.start), far(b, q.end));
    vec![[va, vb, fb], [va, fb, fa]]
}

/// The fan closing a diverging corner at `v` from extrusion point `p1` to `p2` (module doc).
fn corner_fan(
    disk: &Disk,
    ex: &Extrusion,
    v: DVec3,
    p1: DVec3,
    p2: DVec3,
) -> Vec<[VolumeVertex; 3]> {
    let (t1, t2) = (disk.angle_of(p1), disk.angle_of(p2));
    let delta = (t2 - t1 + PI).rem_euclid(TAU) - PI;
    let steps = (delta.abs() * f64::from(ex.fan_segments) / TAU).ceil() as usize;
    if steps == 0 {
        return Vec::new();
    }
    let point = |k: usize| match k {
        0 => p1,
        k if k == steps => p2,
        k => disk.rim_point(t1 + delta * k as f64 / steps as f64),
    };
    let far = |p: DVec3| VolumeVertex {
        position: ex.far(disk.center, v, v - p),
        silhouette: v,
    };
    (0..steps)
        .map(|k| [on_silhouette(v), far(point(k)), far(point(k + 1))])
        .collect()
}

/// The umbra and penumbra volumes of `meshes` for `disk` (module doc). Errors name the mesh
/// index of an inconsistent silhouette (impossible for closed meshes, which validation
/// guarantees).
pub fn build_volumes(
    meshes: &[(&Mesh, &Adjacency)],
    disk: &Disk,
    ex: &Extrusion,
) -> Result<Volumes, (usize, String)> {
    let mut v = Volumes::default();
    for (i, (mesh, adj)) in meshes.iter().enumerate() {
        let classes = classify_faces(mesh, disk);
        let st = &mut v.stats;
        for c in &classes {
            match c {
                FaceClass::AllFront => st.all_front_faces += 1,
                FaceClass::NoneFront => st.none_front_faces += 1,
                FaceClass::Silhouette => st.silhouette_faces += 1,
            }
        }
        let umbra = volume_edges(mesh, adj, &classes, Volume::Umbra);
        let penumbra = volume_edges(mesh, adj, &classes, Volume::Penumbra);
        st.umbra_edges += umbra.len() as u64;
        st.penumbra_edges += penumbra.len() as u64;
        extrude_volume(mesh, &umbra, disk, ex, Volume::Umbra, st, &mut v.umbra)
            .map_err(|e| (i, e))?;
        extrude_volume(
            mesh,
            &penumbra,
            disk,
            ex,
            Volume::Penumbra,
            st,
            &mut v.penumbra,
        )
        .map_err(|e| (i, e))?;
        for (t, class) in classes.iter().enumerate() {
            let tri = corners(mesh, t);
            let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
            if *class == FaceClass::Silhouette && !faces(n, tri[0], disk.center) {
                st.silhouette_faces_rendered += 1;
                v.umbra.push(tri.map(on_silhouette));
            }
        }
        v.mesh_ends.push([v.umbra.len(), v.penumbra.len()]);
    }
    v.stats.umbra_triangles = v.umbra.len() as u64;
    v.stats.penumbra_triangles = v.penumbra.len() as u64;
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::adjacency;
    use crate::scene::procedural::box_mesh;

    fn disk(r: f32) -> Disk {
        Disk::new(Vec3::new(0.0, 4.0, 0.0), Vec3::NEG_Y, r)
    }

    /// The signed distance of the rim point at angle θ from the plane of `n` through `a`.
    fn rim_side(d: &Disk, n: DVec3, a: DVec3, k: usize) -> f64 {
        n.dot(d.rim_point(TAU * k as f64 / 720.0) - a)
    }

    #[test]
    fn p_near_and_p_far_bound_the_whole_rim() {
        let d = Disk::new(Vec3::new(0.3, 2.0, -1.0), Vec3::new(0.2, -1.0, 0.4), 0.7);
        for n in [
            DVec3::new(1.0, 0.3, -0.2),
            DVec3::new(-0.1, 1.0, 0.05),
            DVec3::new(0.0, 0.0, 1.0),
            d.normal,
        ] {
            let n = n.normalize();
            let a = DVec3::new(0.1, 1.0, 0.2);
            let [near, far] = d.extremes(n);
            assert!((near - d.center).length() <= d.radius * (1.0 + 1e-12));
            for k in 0..720 {
                let s = rim_side(&d, n, a, k);
                assert!(s <= n.dot(near - a) + 1e-12, "{n:?} {k}");
                assert!(s >= n.dot(far - a) - 1e-12, "{n:?} {k}");
            }
        }
        // The printed eq. 1a is the point behind the plane, off the rim: not the extreme.
        let n = DVec3::new(1.0, 1.0, 0.0).normalize();
        let printed = d.center + d.radius * n.cross(d.normal).cross(d.normal);
        assert!(n.dot(printed - d.center) < 0.0);
        assert!((printed - d.center).length() < d.radius * 0.99);
    }

    #[test]
    fn classification_of_a_box_under_a_large_disk() {
        // Box x ∈ [0.6, 1.4] under a disk of radius 1.5 at height 4: top all-frontfacing,
        // bottom none-frontfacing, every side a silhouette face (the rim reaches past it).
        let m = box_mesh(
            "b",
            Vec3::new(0.6, 0.6, -0.4),
            Vec3::new(1.4, 1.6, 0.4),
            [0.5; 3],
        );
        let classes = classify_faces(&m, &disk(1.5));
        for (t, c) in classes.iter().enumerate() {
            let [a, b, cc] = corners(&m, t);
            let n = (b - a).cross(cc - a).normalize();
            let expected = match n.y {
                y if y > 0.5 => FaceClass::AllFront,
                y if y < -0.5 => FaceClass::NoneFront,
                _ => FaceClass::Silhouette,
            };
            assert_eq!(*c, expected, "{n:?}");
        }
        // A small disk straight above: the sides are none-frontfacing, the silhouettes meet.
        let small = classify_faces(&m, &Disk::new(Vec3::new(1.0, 4.0, 0.0), Vec3::NEG_Y, 0.2));
        assert!(!small.contains(&FaceClass::Silhouette));
    }

    #[test]
    fn tangent_planes_touch_the_circle_and_the_parallel_edge_is_the_limit() {
        let d = disk(0.5);
        let tangent_plane_side = |v1: DVec3, v2: DVec3, t: DVec3| {
            let n = (v2 - v1).cross(t - v1).normalize();
            let sides: Vec<f64> = (0..720).map(|k| rim_side(&d, n, v1, k)).collect();
            let (lo, hi) = sides
                .iter()
                .fold((f64::MAX, f64::MIN), |(l, h), s| (l.min(*s), h.max(*s)));
            // All of the rim on one side, touching at t.
            assert!(lo > -1e-5 || hi < 1e-5, "{lo} {hi}");
            assert!(n.dot(t - v1).abs() < 1e-12);
            assert!(((t - d.center).length() - d.radius).abs() < 1e-12);
        };
        let (v1, v2) = (DVec3::new(1.0, 1.0, -0.5), DVec3::new(1.2, 1.4, 0.5));
        let Tangents::Points { points, parallel } = d.tangent_points(v1, v2) else {
            panic!()
        };
        assert!(!parallel);
        for t in points {
            tangent_plane_side(v1, v2, t);
        }
        // Parallel to the light plane: t = c ± r·ŵ, ŵ ⟂ the edge in the plane.
        let (p1, p2) = (DVec3::new(1.0, 1.0, -0.5), DVec3::new(1.0, 1.0, 0.5));
        let Tangents::Points { points, parallel } = d.tangent_points(p1, p2) else {
            panic!()
        };
        assert!(parallel);
        for t in points {
            tangent_plane_side(p1, p2, t);
            assert!((t - d.center).dot(DVec3::Z).abs() < 1e-12);
        }
        // The limit: a nearly parallel edge gives nearly the same points.
        let tilt = DVec3::new(0.0, 1e-7, 0.0);
        let Tangents::Points { points: near, .. } = d.tangent_points(p1, p2 + tilt) else {
            panic!()
        };
        let close = |a: DVec3, b: DVec3| (a - b).length() < 1e-5;
        assert!(
            (close(near[0], points[0]) && close(near[1], points[1]))
                || (close(near[0], points[1]) && close(near[1], points[0]))
        );
        // An edge line through the disk and one in the light plane.
        assert_eq!(
            d.tangent_points(DVec3::new(0.1, 1.0, 0.0), DVec3::new(0.1, 2.0, 0.1)),
            Tangents::Inside
        );
        assert_eq!(
            d.tangent_points(DVec3::new(2.0, 4.0, 0.0), DVec3::new(2.0, 4.0, 1.0)),
            Tangents::Degenerate
        );
    }

    /// The box of [`classification_of_a_box_under_a_large_disk`] and its volumes.
    fn box_volumes(r: f32) -> (Mesh, Volumes) {
        let m = box_mesh(
            "b",
            Vec3::new(0.6, 0.6, -0.4),
            Vec3::new(1.4, 1.6, 0.4),
            [0.5; 3],
        );
        let adj = adjacency::build(&m).unwrap();
        let ex = Extrusion {
            bound: 8.0,
            fan_segments: 32,
        };
        let v = build_volumes(&[(&m, &adj)], &disk(r), &ex).unwrap();
        (m, v)
    }

    #[test]
    fn box_volumes_follow_the_two_silhouettes() {
        let (_, v) = box_volumes(1.5);
        let s = v.stats;
        // Umbra silhouette: the bottom square (bottom vs sides); penumbra: the top square.
        assert_eq!((s.umbra_edges, s.penumbra_edges, s.loops), (4, 4, 2));
        assert_eq!(s.parallel_edges, 8);
        assert_eq!(s.a_inside_circle + s.degenerate_edges + s.no_candidate, 0);
        // Every edge has a silhouette face on one side: one tangent point qualifies.
        assert_eq!(s.one_candidate, 8);
        // Convex square loops: the umbra trims its four corners, the penumbra fans them.
        assert_eq!((s.trimmed_convex, s.fanned_convex), (4, 4));
        assert_eq!(s.trimmed_reflex + s.fanned_reflex, 0);
        // c (x = 0, z = 0) is in front of the −x side only: the +x and ±z sides are the
        // silhouette faces of Fig. 6 (3 sides, 6 triangles).
        assert_eq!(s.silhouette_faces, 8);
        assert_eq!(s.silhouette_faces_rendered, 6);
        for t in v.umbra.iter().chain(&v.penumbra) {
            for x in t {
                assert!((x.position - DVec3::new(0.0, 4.0, 0.0)).length() <= 8.0 + 1e-9);
            }
        }
    }

    /// An edge on both silhouettes (2D cross-section): the umbra plane passes through the rim
    /// point on the edge's free side, the penumbra plane through the opposite one, exactly.
    #[test]
    fn umbra_and_penumbra_planes_bound_the_shadows_of_every_disk_point() {
        // A box wider than the disk, whose every silhouette edge is on both silhouettes.
        let m = box_mesh(
            "w",
            Vec3::new(-2.0, 1.0, -2.0),
            Vec3::new(2.0, 1.2, 2.0),
            [0.5; 3],
        );
        let adj = adjacency::build(&m).unwrap();
        let d = Disk::new(Vec3::new(0.5, 4.0, 0.2), Vec3::NEG_Y, 0.6);
        let ex = Extrusion {
            bound: 20.0,
            fan_segments: 32,
        };
        let v = build_volumes(&[(&m, &adj)], &d, &ex).unwrap();
        assert_eq!(v.stats.two_candidates, 8);
        // On the floor y = 0 below the +x side: the umbra boundary is where the last rim point
        // disappears, the penumbra boundary where the first does.
        let floor_x = |tris: &[[VolumeVertex; 3]]| {
            let mut xs = Vec::new();
            for t in tris {
                // Intersect the triangle with the line y = 0, z = 0.2 (in its plane).
                let [a, b, c] = t.map(|x| x.position);
                let n = (b - a).cross(c - a);
                if n.normalize().x.abs() < 0.5 {
                    continue;
                }
                let p = DVec3::new(0.0, 0.0, 0.2);
                let x = (n.dot(a) - n.y * p.y - n.z * p.z) / n.x;
                xs.push(x);
            }
            xs
        };
        // Exact: edge x = 2 at y = 1.2; umbra through the rim point x = 0.5 + 0.6 (the near
        // end), penumbra through x = 0.5 − 0.6; light height 4.
        let h = 1.2 / (4.0 - 1.2);
        let umbra = 2.0 + (2.0 - 1.1) * h;
        let penumbra = 2.0 + (2.0 + 0.1) * h;
        let ux = floor_x(&v.umbra);
        let px = floor_x(&v.penumbra);
        // (The box's f32 height 1.2 is 5e-8 off.)
        assert!(
            ux.iter().any(|x| (x - umbra).abs() < 1e-6),
            "{ux:?} vs {umbra}"
        );
        assert!(
            px.iter().any(|x| (x - penumbra).abs() < 1e-6),
            "{px:?} vs {penumbra}"
        );
        // Trimming leaves no degenerate triangle.
        for t in v.umbra.iter().chain(&v.penumbra) {
            let [a, b, c] = t.map(|x| x.position);
            assert!((b - a).cross(c - a).length() > 1e-9, "{t:?}");
        }
    }
}
