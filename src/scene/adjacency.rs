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
//!
//! Design choice (issue 27, scale): edges are found through the crate's one edge table
//! (`EdgeTable`: half-edges grouped by a counting sort on their lower vertex, no hashing, no
//! sort of all half-edges), which mesh repair ([`super::repair`]) uses for every step that
//! walks edges; a mesh of a million triangles is checked in one linear pass over it.

use crate::scene::Mesh;
use glam::Vec3;
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

/// Builds the edge adjacency of `mesh`, or says why it is not a closed, consistently wound
/// two-manifold. Checks run triangle by triangle for index errors, then edge by edge in edge
/// order, so the reported edge is deterministic: the first problematic edge in edge order.
///
/// The edges come from an `EdgeTable` (half-edges grouped by a counting sort, no hashing),
/// numbered by their first half-edge: a linear pass, no allocation per triangle or edge.
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

    let table = EdgeTable::new(&mesh.triangles);
    // Per half-edge, the other half-edge of its edge. The problem of an edge that has not
    // exactly two half-edges, or two running the same way, is kept for the edge whose first
    // half-edge comes first (the first problem in edge order).
    let mut partner = vec![u32::MAX; 3 * n];
    let mut problem: Option<(u32, usize)> = None;
    for g in table.groups() {
        let first = g.h(0);
        if g.len() != 2 || table.same_direction(&g) {
            if problem.is_none_or(|(h, _)| first < h) {
                problem = Some((first, g.len()));
            }
            continue;
        }
        partner[first as usize] = g.h(1);
        partner[g.h(1) as usize] = first;
    }
    if let Some((h, faces)) = problem {
        let [a, b] = table.ends(h);
        let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
        return Err(match faces {
            1 => AdjacencyError::Open { a, b, pa, pb },
            2 => AdjacencyError::Inconsistent { a, b, pa, pb },
            faces => AdjacencyError::NonManifold {
                a,
                b,
                pa,
                pb,
                faces,
            },
        });
    }
    // Edges numbered in order of their first half-edge (triangle order, corners 0→1, 1→2,
    // 2→0): a half-edge whose partner comes later opens an edge, the other one joins it.
    let mut edges: Vec<Edge> = Vec::with_capacity(3 * n / 2);
    let mut triangle_edges = vec![[0u32; 3]; n];
    for h in 0..3 * n as u32 {
        let p = partner[h as usize];
        let (t, k) = ((h / 3) as usize, (h % 3) as usize);
        triangle_edges[t][k] = if p > h {
            edges.push(Edge {
                v: table.ends(h),
                faces: [h / 3, p / 3],
            });
            (edges.len() - 1) as u32
        } else {
            triangle_edges[(p / 3) as usize][(p % 3) as usize]
        };
    }
    Ok(Adjacency {
        edges,
        triangle_edges,
    })
}

/// The undirected edges of a triangle list: every half-edge (triangle·3 + corner, the edge
/// from corner k to corner k+1) grouped by its undirected edge, the groups in order of
/// (lower vertex, higher vertex) and each group's half-edges in triangle order, so the result
/// depends on the triangles alone (no hashing, no thread count).
///
/// Built by a counting sort on the lower vertex (one bucket per vertex), then a sort of each
/// bucket by the higher vertex: linear in the triangle count but for the buckets' sorts,
/// which hold a vertex's edges towards higher vertices. The one edge table of the crate:
/// [`build`] here and every step of mesh repair ([`super::repair`]) that walks edges use it.
pub(crate) struct EdgeTable<'a> {
    tris: &'a [[u32; 3]],
    /// Per vertex `v`, `entries[start[v]..start[v + 1]]` are the half-edges whose lower end
    /// is `v`.
    start: Vec<u32>,
    /// (higher end, half-edge), sorted within each vertex's bucket.
    entries: Vec<(u32, u32)>,
}

impl<'a> EdgeTable<'a> {
    /// The edge table of `tris` (every index below `u32::MAX`, at most `u32::MAX / 3`
    /// triangles).
    pub(crate) fn new(tris: &'a [[u32; 3]]) -> Self {
        let vertices = tris.iter().flatten().max().map_or(0, |&m| m as usize + 1);
        let (start, entries) = bucket_sort(vertices, 3 * tris.len(), |h| {
            let (t, k) = (tris[h / 3], h % 3);
            let (a, b) = (t[k], t[(k + 1) % 3]);
            (a.min(b), (a.max(b), h as u32))
        });
        EdgeTable {
            tris,
            start,
            entries,
        }
    }

    /// The triangles the table was built from.
    pub(crate) fn tris(&self) -> &'a [[u32; 3]] {
        self.tris
    }

    /// The table without its triangles, to be given the same triangles again after some of
    /// them were turned ([`EdgeTable::turned`]).
    pub(crate) fn into_buckets(self) -> EdgeBuckets {
        EdgeBuckets {
            start: self.start,
            entries: self.entries,
        }
    }

    /// The table of `tris`, the triangles `buckets` was built from with every triangle `t`
    /// where `turned[t]` reversed by swapping its corners 1 and 2: the same edges, and the
    /// half-edges of a turned triangle renumbered (corner 0's edge is now its corner 2's and
    /// the other way round, corner 1's stays). The order within each edge is triangle order,
    /// which turning does not change, so nothing is sorted again.
    pub(crate) fn turned(
        tris: &'a [[u32; 3]],
        buckets: EdgeBuckets,
        turned: &[bool],
    ) -> EdgeTable<'a> {
        let EdgeBuckets { start, mut entries } = buckets;
        for (_, h) in &mut entries {
            if turned[(*h / 3) as usize] && *h % 3 != 1 {
                *h = *h / 3 * 3 + 2 - *h % 3;
            }
        }
        EdgeTable {
            tris,
            start,
            entries,
        }
    }

    /// The half-edges of each undirected edge, edges in (lower, higher) vertex order.
    pub(crate) fn groups(&self) -> impl Iterator<Item = Group<'_>> + '_ {
        self.start.windows(2).flat_map(move |w| {
            self.entries[w[0] as usize..w[1] as usize]
                .chunk_by(|x, y| x.0 == y.0)
                .map(Group)
        })
    }

    /// The half-edges of the undirected edge `a–b`, in triangle order.
    pub(crate) fn of(&self, a: u32, b: u32) -> impl Iterator<Item = u32> + '_ {
        let (lo, hi) = (a.min(b) as usize, a.max(b));
        let bucket = match self.start.get(lo..lo + 2) {
            Some(&[s, e]) => &self.entries[s as usize..e as usize],
            _ => &[],
        };
        let first = bucket.partition_point(|&(x, _)| x < hi);
        bucket[first..]
            .iter()
            .take_while(move |&&(x, _)| x == hi)
            .map(|&(_, h)| h)
    }

    /// The ends of half-edge `h`, in its triangle's direction.
    pub(crate) fn ends(&self, h: u32) -> [u32; 2] {
        let t = self.tris[(h / 3) as usize];
        let k = (h % 3) as usize;
        [t[k], t[(k + 1) % 3]]
    }

    /// Whether the two half-edges of a two-triangle edge run the same way.
    pub(crate) fn same_direction(&self, g: &Group) -> bool {
        g.len() == 2 && self.ends(g.h(0)) == self.ends(g.h(1))
    }
}

/// Items `0..n` sorted without hashing or comparing across buckets: `item(i)` is `(bucket,
/// value)` with `bucket < buckets`; a counting sort puts each value in its bucket, then each
/// bucket is sorted. Returns, per bucket `b`, the start of its values (`start[b]..start[b +
/// 1]`), and the values. Linear in `n` but for the buckets' own sorts; the result depends on
/// the items alone (values that compare equal are equal). `item` is called twice per item;
/// `n` must fit in u32. The sort behind [`EdgeTable`], also used by mesh repair (welding,
/// duplicate triangles).
pub(crate) fn bucket_sort<T: Copy + Ord + Default>(
    buckets: usize,
    n: usize,
    item: impl Fn(usize) -> (u32, T),
) -> (Vec<u32>, Vec<T>) {
    let mut start = vec![0u32; buckets + 1];
    for i in 0..n {
        start[item(i).0 as usize + 1] += 1;
    }
    for b in 0..buckets {
        start[b + 1] += start[b];
    }
    let mut fill: Vec<u32> = start[..buckets].to_vec();
    let mut values = vec![T::default(); n];
    for i in 0..n {
        let (b, v) = item(i);
        values[fill[b as usize] as usize] = v;
        fill[b as usize] += 1;
    }
    for b in 0..buckets {
        values[start[b] as usize..start[b + 1] as usize].sort_unstable();
    }
    (start, values)
}

/// An [`EdgeTable`] without the triangles it was built from ([`EdgeTable::into_buckets`]).
pub(crate) struct EdgeBuckets {
    start: Vec<u32>,
    entries: Vec<(u32, u32)>,
}

/// The half-edges of one undirected edge (a run of an [`EdgeTable`] bucket).
pub(crate) struct Group<'a>(&'a [(u32, u32)]);

impl Group<'_> {
    /// How many triangles use the edge.
    pub(crate) fn len(&self) -> usize {
        self.0.len()
    }

    /// The `i`-th half-edge, in triangle order.
    pub(crate) fn h(&self, i: usize) -> u32 {
        self.0[i].1
    }

    /// All its half-edges, in triangle order.
    pub(crate) fn all(&self) -> Vec<u32> {
        self.0.iter().map(|&(_, h)| h).collect()
    }
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

    /// The adjacency of a closed mesh by the definition of the module docs, found by linear
    /// search (quadratic, for small meshes): edges in order of first occurrence.
    fn by_search(m: &Mesh) -> Adjacency {
        let mut edges: Vec<Edge> = Vec::new();
        let mut triangle_edges = Vec::new();
        for (t, tri) in m.triangles.iter().enumerate() {
            let mut te = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                te[k] = match edges.iter().position(|e| e.v == [b, a]) {
                    Some(e) => {
                        edges[e].faces[1] = t as u32;
                        e as u32
                    }
                    None => {
                        edges.push(Edge {
                            v: [a, b],
                            faces: [t as u32, u32::MAX],
                        });
                        (edges.len() - 1) as u32
                    }
                };
            }
            triangle_edges.push(te);
        }
        Adjacency {
            edges,
            triangle_edges,
        }
    }

    #[test]
    fn edges_are_numbered_by_first_occurrence() {
        let sphere = crate::scene::procedural::uv_sphere("s", Vec3::ZERO, 1.0, 7, 9, [1.0; 3]);
        for m in [cube(), sphere] {
            let adj = build(&m).unwrap();
            assert_eq!(adj, by_search(&m), "{}", m.name);
            assert_eq!(adj.edges.len(), m.triangles.len() * 3 / 2);
        }
    }

    #[test]
    fn the_first_bad_edge_in_edge_order_is_reported() {
        // The cube's +x face missing (open edges 1–3, 5–7, 1–5, 3–7, first seen at half-edges
        // 4 (3→1 in triangle 1), 7, 13, 22) and a two-triangle fin on edge 4–6 (four triangles
        // there, first seen at half-edge 11): the open edge 1–3 comes first, named 3→1.
        let mut m = cube();
        m.triangles.truncate(10);
        m.positions.push(Vec3::new(-1.0, 0.5, 0.5));
        m.triangles.push([4, 6, 8]);
        m.triangles.push([6, 4, 8]);
        match build(&m).unwrap_err() {
            AdjacencyError::Open { a, b, .. } => assert_eq!([a, b], [3, 1]),
            e => panic!("expected the open edge 3→1, got {e}"),
        }
        // A third triangle on edge 0–2 (half-edge 0, triangle 0's first) comes first of all.
        m.triangles.push([0, 2, 8]);
        match build(&m).unwrap_err() {
            AdjacencyError::NonManifold { a, b, faces, .. } => {
                assert_eq!(([a, b], faces), ([0, 2], 3))
            }
            e => panic!("expected the non-manifold edge 0–2, got {e}"),
        }
    }

    #[test]
    fn edge_table_groups_and_lookups() {
        let m = cube();
        let table = EdgeTable::new(&m.triangles);
        let groups: Vec<Vec<u32>> = table.groups().map(|g| g.all()).collect();
        assert_eq!(groups.len(), 18);
        // Every half-edge once; each edge's two half-edges in triangle order, opposite ways.
        let mut all: Vec<u32> = groups.iter().flatten().copied().collect();
        all.sort_unstable();
        assert_eq!(all, (0..36).collect::<Vec<u32>>());
        for g in &groups {
            assert_eq!(g.len(), 2);
            assert!(g[0] < g[1]);
            let [a, b] = table.ends(g[0]);
            assert_eq!(table.ends(g[1]), [b, a]);
            assert_eq!(table.of(b, a).collect::<Vec<_>>(), *g);
        }
        // Groups in (lower, higher) vertex order: the first is 0–1, the last 6–7.
        let ends = |g: &Vec<u32>| {
            let [a, b] = table.ends(g[0]);
            [a.min(b), a.max(b)]
        };
        assert_eq!(ends(&groups[0]), [0, 1]);
        assert_eq!(ends(&groups[17]), [6, 7]);
        assert_eq!(table.of(0, 7).count(), 0);
        assert_eq!(table.of(40, 41).count(), 0);
    }

    #[test]
    fn a_turned_table_is_the_table_of_the_turned_triangles() {
        let m = cube();
        let turned: Vec<bool> = (0..12).map(|t| t % 3 == 1).collect();
        let mut tris = m.triangles.clone();
        for (t, &f) in tris.iter_mut().zip(&turned) {
            if f {
                t.swap(1, 2);
            }
        }
        let buckets = EdgeTable::new(&m.triangles).into_buckets();
        let reused = EdgeTable::turned(&tris, buckets, &turned);
        let fresh = EdgeTable::new(&tris);
        let list = |t: &EdgeTable| t.groups().map(|g| g.all()).collect::<Vec<_>>();
        assert_eq!(list(&reused), list(&fresh));
        assert_ne!(list(&fresh), list(&EdgeTable::new(&m.triangles)));
    }
}
