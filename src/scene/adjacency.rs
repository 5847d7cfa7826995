//! Edge adjacency of a closed triangle mesh: every undirected edge and its two faces.
//!
//! Representation: [`Adjacency::edges`] lists each undirected edge once, in the order of its
//! first occurrence when the triangles are scanned in order with corners 0→1, 1→2, 2→0. The
//! triangle of that first occurrence is `faces[0]` and `v` keeps its direction, so `faces[0]`
//! holds the directed edge `v[0]→v[1]` and `faces[1]` the opposite one `v[1]→v[0]`.
//! [`Adjacency::triangle_edges`] maps each triangle back to its three edges.
//!
//! [`build`] accepts only closed, consistently wound two-manifold meshes (every edge has exactly
//! two triangles, used once in each direction) and rejects repeated indices in one triangle.
//! Geometrically degenerate triangles with three distinct indices (zero area, slivers) are
//! accepted: they are hard cases the shadow methods must handle, not bad input. Vertex
//! manifoldness (two fans touching at one vertex) is not checked; silhouette loops handle
//! vertices of any even degree (Paper V).

use crate::scene::Mesh;
use glam::Vec3;
use std::collections::HashMap;
use std::fmt;

/// One undirected edge of a closed mesh: `v` in the winding order of `faces[0]`
/// (`faces[0]` contains the directed edge `v[0]→v[1]`, `faces[1]` contains `v[1]→v[0]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Edge {
    /// The two vertex indices, in the direction `faces[0]` traverses the edge.
    pub v: [u32; 2],
    /// The two triangles sharing the edge; `faces[0]` is the first one in triangle order.
    pub faces: [u32; 2],
}

/// The edge adjacency of a closed two-manifold mesh.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Adjacency {
    /// Every undirected edge once, in order of first occurrence (see the module docs).
    pub edges: Vec<Edge>,
    /// Per triangle, its three edge indices (edges of corners (0,1), (1,2), (2,0)).
    pub triangle_edges: Vec<[u32; 3]>,
}

/// Why a mesh is not a closed, consistently wound two-manifold.
#[derive(Debug, Clone, PartialEq)]
pub enum AdjacencyError {
    /// The edge `a–b` has only one triangle.
    Open {
        /// First vertex index.
        a: u32,
        /// Second vertex index.
        b: u32,
        /// Position of `a`.
        pa: Vec3,
        /// Position of `b`.
        pb: Vec3,
    },
    /// The edge `a–b` has more than two triangles.
    NonManifold {
        /// First vertex index.
        a: u32,
        /// Second vertex index.
        b: u32,
        /// Position of `a`.
        pa: Vec3,
        /// Position of `b`.
        pb: Vec3,
        /// How many triangles share the edge.
        faces: usize,
    },
    /// Two triangles traverse the edge `a→b` in the same direction (one of them is flipped).
    Inconsistent {
        /// First vertex index.
        a: u32,
        /// Second vertex index.
        b: u32,
        /// Position of `a`.
        pa: Vec3,
        /// Position of `b`.
        pb: Vec3,
    },
    /// A triangle repeats a vertex index.
    Degenerate {
        /// Index of the triangle.
        triangle: u32,
        /// Its vertex indices.
        indices: [u32; 3],
    },
    /// A triangle refers to a vertex that does not exist.
    IndexOutOfRange {
        /// Index of the triangle.
        triangle: u32,
        /// The offending vertex index.
        index: u32,
        /// Number of vertices in the mesh.
        vertex_count: usize,
    },
    /// The mesh has more triangles or vertices than u32 indices can address.
    TooLarge {
        /// Number of triangles.
        triangles: usize,
    },
}

/// Formats a position compactly, e.g. `(0,1,0.5)`.
struct P(Vec3);

impl fmt::Display for P {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({},{},{})", self.0.x, self.0.y, self.0.z)
    }
}

impl fmt::Display for AdjacencyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            AdjacencyError::Open { a, b, pa, pb } => {
                write!(f, "open mesh: edge {a}–{b} ({}–{}) has only one triangle", P(pa), P(pb))
            }
            AdjacencyError::NonManifold { a, b, pa, pb, faces } => write!(
                f,
                "non-manifold mesh: edge {a}–{b} ({}–{}) has {faces} triangles",
                P(pa),
                P(pb)
            ),
            AdjacencyError::Inconsistent { a, b, pa, pb } => write!(
                f,
                "inconsistent winding: edge {a}→{b} ({}–{}) is traversed in the same direction \
                 by two triangles (a triangle is flipped)",
                P(pa),
                P(pb)
            ),
            AdjacencyError::Degenerate { triangle, indices: [i, j, k] } => write!(
                f,
                "degenerate triangle {triangle}: vertex indices {i}, {j}, {k} repeat a vertex"
            ),
            AdjacencyError::IndexOutOfRange { triangle, index, vertex_count } => write!(
                f,
                "triangle {triangle} refers to vertex {index} but the mesh has {vertex_count} vertices"
            ),
            AdjacencyError::TooLarge { triangles } => {
                write!(f, "mesh too large: {triangles} triangles exceed u32 indexing")
            }
        }
    }
}

impl std::error::Error for AdjacencyError {}

/// Per-edge bookkeeping while scanning.
struct Scan {
    /// Number of triangles using the edge.
    count: usize,
    /// Set when a second triangle used the edge in the direction of the first.
    same_direction: bool,
}

/// Builds the edge adjacency of `mesh`, or says why it is not a closed, consistently wound
/// two-manifold. Checks run triangle by triangle for index errors, then edge by edge in edge
/// order, so the reported edge is deterministic: the first problematic edge in edge order.
pub fn build(mesh: &Mesh) -> Result<Adjacency, AdjacencyError> {
    let n = mesh.triangles.len();
    // Each edge index and 3 × triangle count must fit in u32.
    if n > (u32::MAX / 3) as usize {
        return Err(AdjacencyError::TooLarge { triangles: n });
    }
    let vertex_count = mesh.positions.len();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &i in tri {
            if i as usize >= vertex_count {
                return Err(AdjacencyError::IndexOutOfRange {
                    triangle: t as u32,
                    index: i,
                    vertex_count,
                });
            }
        }
        if tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0] {
            return Err(AdjacencyError::Degenerate {
                triangle: t as u32,
                indices: *tri,
            });
        }
    }

    let mut lookup: HashMap<(u32, u32), u32> = HashMap::with_capacity(n * 3 / 2 + 1);
    let mut edges: Vec<Edge> = Vec::with_capacity(n * 3 / 2 + 1);
    let mut scan: Vec<Scan> = Vec::with_capacity(n * 3 / 2 + 1);
    let mut triangle_edges = Vec::with_capacity(n);
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let t = t as u32;
        let mut te = [0u32; 3];
        for (k, slot) in te.iter_mut().enumerate() {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let key = (a.min(b), a.max(b));
            let e = *lookup.entry(key).or_insert_with(|| {
                edges.push(Edge {
                    v: [a, b],
                    faces: [t, u32::MAX],
                });
                scan.push(Scan {
                    count: 0,
                    same_direction: false,
                });
                (edges.len() - 1) as u32
            });
            let s = &mut scan[e as usize];
            s.count += 1;
            if s.count == 2 {
                edges[e as usize].faces[1] = t;
                if edges[e as usize].v == [a, b] {
                    s.same_direction = true;
                }
            }
            *slot = e;
        }
        triangle_edges.push(te);
    }

    let pos = |i: u32| mesh.positions[i as usize];
    for (e, s) in edges.iter().zip(&scan) {
        let [a, b] = e.v;
        let (pa, pb) = (pos(a), pos(b));
        if s.count == 1 {
            return Err(AdjacencyError::Open { a, b, pa, pb });
        }
        if s.count > 2 {
            return Err(AdjacencyError::NonManifold {
                a,
                b,
                pa,
                pb,
                faces: s.count,
            });
        }
        if s.same_direction {
            return Err(AdjacencyError::Inconsistent { a, b, pa, pb });
        }
    }
    Ok(Adjacency {
        edges,
        triangle_edges,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube, 8 vertices, 12 outward CCW triangles.
    fn cube() -> Mesh {
        let positions = (0..8)
            .map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32))
            .collect();
        let quads: [[u32; 4]; 6] = [
            [0, 2, 3, 1], // z = 0, normal −z
            [4, 5, 7, 6], // z = 1, normal +z
            [0, 1, 5, 4], // y = 0, normal −y
            [2, 6, 7, 3], // y = 1, normal +y
            [0, 4, 6, 2], // x = 0, normal −x
            [1, 3, 7, 5], // x = 1, normal +x
        ];
        let triangles = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        Mesh {
            name: "cube".into(),
            positions,
            triangles,
            color: [1.0; 3],
            receiver_only: false,
            repairs: Default::default(),
        }
    }

    #[test]
    fn cube_is_closed() {
        let m = cube();
        let adj = build(&m).unwrap();
        assert_eq!(m.triangles.len(), 12);
        assert_eq!(adj.edges.len(), 18);
        assert_eq!(adj.triangle_edges.len(), 12);
        for (i, e) in adj.edges.iter().enumerate() {
            let [a, b] = e.v;
            let t0 = m.triangles[e.faces[0] as usize];
            let t1 = m.triangles[e.faces[1] as usize];
            let has =
                |t: [u32; 3], x: u32, y: u32| (0..3).any(|k| t[k] == x && t[(k + 1) % 3] == y);
            assert!(has(t0, a, b) && has(t1, b, a));
            assert!(e.faces[0] < e.faces[1]);
            assert!(adj.triangle_edges[e.faces[0] as usize].contains(&(i as u32)));
            assert!(adj.triangle_edges[e.faces[1] as usize].contains(&(i as u32)));
        }
        // First edge is triangle 0's corners 0→1.
        assert_eq!(adj.edges[0].v, [0, 2]);
        assert_eq!(adj.triangle_edges[0], [0, 1, 2]);
    }

    #[test]
    fn open_box_names_an_edge() {
        let mut m = cube();
        m.triangles.truncate(10); // drop the x = 1 face
        let err = build(&m).unwrap_err();
        assert!(matches!(err, AdjacencyError::Open { .. }), "{err}");
        let msg = err.to_string();
        assert!(msg.starts_with("open mesh: edge "), "{msg}");
        assert!(msg.contains("has only one triangle"), "{msg}");
        // The first open edge in edge order is 1–3 of the z = 0 face: (1,0,0)–(1,1,0).
        assert!(msg.contains("(1,1,0)") && msg.contains("(1,0,0)"), "{msg}");
    }

    #[test]
    fn three_triangles_on_one_edge() {
        let mut m = cube();
        // A fin hanging from edge 0–1 with its own closed-up partner would still be 3+ faces.
        m.positions.push(Vec3::new(0.5, -1.0, 0.5));
        m.triangles.push([1, 0, 8]);
        let err = build(&m).unwrap_err();
        match err {
            AdjacencyError::NonManifold { a, b, faces, .. } => {
                assert_eq!((a.min(b), a.max(b)), (0, 1));
                assert_eq!(faces, 3);
            }
            e => panic!("expected NonManifold, got {e}"),
        }
        assert!(err.to_string().contains("has 3 triangles"));
    }

    #[test]
    fn flipped_triangle_is_inconsistent() {
        let mut m = cube();
        let t = &mut m.triangles[5];
        t.swap(1, 2);
        let err = build(&m).unwrap_err();
        assert!(matches!(err, AdjacencyError::Inconsistent { .. }), "{err}");
        assert!(err.to_string().starts_with("inconsistent winding"));
    }

    #[test]
    fn repeated_index_is_degenerate() {
        let mut m = cube();
        m.triangles[3] = [2, 2, 5];
        let err = build(&m).unwrap_err();
        assert_eq!(
            err,
            AdjacencyError::Degenerate {
                triangle: 3,
                indices: [2, 2, 5]
            }
        );
        assert!(err.to_string().contains("degenerate triangle 3"));
    }

    #[test]
    fn index_out_of_range() {
        let mut m = cube();
        m.triangles[0][1] = 99;
        assert!(matches!(
            build(&m),
            Err(AdjacencyError::IndexOutOfRange {
                triangle: 0,
                index: 99,
                ..
            })
        ));
    }
}
