//! Mesh repair: a raw triangle soup (positions and index triples, as a file reader produces
//! it) becomes the closed, consistently wound two-manifold every shadow method needs, and
//! every change is counted ([`MeshRepairs`]) so that it is reported, never silent.
//!
//! The steps, in order (`docs/mesh-repair.md` says why each works as it does):
//!
//! 1. **Weld** ([`RepairOptions::weld`]): corners at bit-identical positions (−0 = +0), or
//!    within [`RepairOptions::weld_tolerance`] × the bounding-box diagonal (a sorted grid and
//!    union-find, so the result depends on neither thread count nor hashing), become the
//!    vertex of their first occurrence; vertices no triangle uses are dropped. Vertices keep
//!    the order of their first occurrence, so a mesh that needs nothing stays bit-identical.
//!    This is the only weld of the load path: a file's corners reach it as the file holds
//!    them. A welded vertex stores −0 as +0 (chosen: the two are one position, and the mesh
//!    loader always stored it so, which keeps every file scene bit-identical); with
//!    `weld = false` positions stay as written.
//! 2. **Clean**: triangles that repeat a vertex (after welding) and exact duplicates (the same
//!    three vertices in the same rotation) are dropped. A face and its reverse are kept: the
//!    pair is a two-sided flat part (closed on its own, volume 0). A zero-area triangle with
//!    three distinct vertices is kept: it fills a T-junction of a closed surface, dropping it
//!    would open the mesh, and the edge adjacency and every method accept it.
//! 3. **Orient**: per part (triangles joined by edges with exactly two triangles), a
//!    breadth-first walk from the part's first triangle makes neighbours agree; the winding
//!    held by more of the part's triangles wins (a tie keeps the first triangle's).
//! 4. **Non-manifold edges** (three or more triangles) and edges the walk could not make
//!    agree (a Möbius band) are cut: around a non-manifold edge the triangles are sorted by
//!    angle and each one traversing `b→a` is paired with the next one counter-clockwise about
//!    `a→b` if that one traverses `a→b` (the two bound one solid wedge); triangles left
//!    without a partner become boundary. The edge's vertices are duplicated per sheet (corner
//!    classes of a union-find over the uncut edges). Two triangles at one angle make the
//!    pairing undefined: that is an error naming the edge.
//! 5. **Open parts** (an edge with one triangle), per [`OpenTreatment`]: capped (boundary loops
//!    found by walking the fan at each vertex, so loops touching at a vertex separate; each
//!    simple loop ear-clipped in its best-fit plane, else fanned around a new centre vertex),
//!    made a zero-thickness two-sided shell, or refused.
//! 6. Every closed part whose signed volume is negative is turned right side out (the rule
//!    of [`super::validate`], shared through [`super::validate::inside_out_volume`]).
//!
//! A receiver-only mesh casts nothing and may stay open: it gets steps 1 and 2 only.

use super::adjacency::{bucket_sort, EdgeTable};
use super::validate::inside_out_volume;
use super::{Mesh, Scene};
use glam::{DVec2, DVec3, Vec3};
use serde::Serialize;

/// What to do with a part of a mesh that has boundary edges (scene key `open`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OpenTreatment {
    /// `open = "close"`: cap every hole (ear clipping in the loop's best-fit plane, else a
    /// fan around a new centre vertex), so the part becomes a closed solid.
    Close,
    /// `open = "shell"`: keep the surface as it is, as a closed two-sided shell of volume 0
    /// (each triangle and a reversed copy, glued along the boundary).
    Shell,
    /// `open = "refuse"`: an open mesh is an error naming a boundary edge.
    Refuse,
}

impl OpenTreatment {
    /// The treatment named by a scene file's `open` value, `None` for an unknown name.
    pub fn from_name(name: &str) -> Option<OpenTreatment> {
        match name {
            "close" => Some(OpenTreatment::Close),
            "shell" => Some(OpenTreatment::Shell),
            "refuse" => Some(OpenTreatment::Refuse),
            _ => None,
        }
    }
}

/// How [`repair`] treats one mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RepairOptions {
    /// Weld corners at equal positions (scene key `weld`, default true).
    pub weld: bool,
    /// Also weld corners within this fraction of the bounding-box diagonal (scene key
    /// `weld_tolerance`, default 0: bit-identical positions only, −0 = +0).
    pub weld_tolerance: f64,
    /// The treatment of open parts; `None` (the default) closes each open part whose holes
    /// all ear-clip in their best-fit planes and makes every other open part a shell.
    pub open: Option<OpenTreatment>,
    /// A receiver-only mesh: weld and clean only, it may stay open and unoriented.
    pub receiver_only: bool,
    /// Whether corners at bit-identical positions count in
    /// [`MeshRepairs::corners_welded`] (default true). False for OBJ, whose exporters write
    /// the positions a group shares with another group again (one `v` line per group), so
    /// joining them is reading the file, not repairing it (and OBJ loading never reported
    /// it); welds within the tolerance count either way.
    pub count_identical_welds: bool,
}

impl Default for RepairOptions {
    fn default() -> Self {
        RepairOptions {
            weld: true,
            weld_tolerance: 0.0,
            open: None,
            receiver_only: false,
            count_identical_welds: true,
        }
    }
}

/// Every change [`repair`] made to one mesh (in `stats.json`'s `"meshes"`, and summed up in
/// one line by [`MeshRepairs::summary`]).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct MeshRepairs {
    /// Corners merged into an earlier vertex at the same position (or within the tolerance).
    pub corners_welded: u64,
    /// Vertices no triangle uses, dropped.
    pub unused_vertices_dropped: u64,
    /// Triangles that repeat a vertex after welding, dropped.
    pub degenerate_dropped: u64,
    /// Exact duplicate triangles (same vertices, same rotation), dropped.
    pub duplicates_dropped: u64,
    /// Triangles whose winding was reversed to agree with their part's majority.
    pub faces_flipped: u64,
    /// Closed parts whose every triangle was reversed because their volume was negative.
    pub parts_turned_inside_out: u64,
    /// Edges cut because more than two triangles met there (or their windings could not
    /// agree), split into separate sheets.
    pub nonmanifold_edges_split: u64,
    /// Vertices duplicated to separate those sheets.
    pub vertices_split: u64,
    /// Edges with a single triangle, before the open treatment.
    pub boundary_edges: u64,
    /// Holes capped (`open = "close"`).
    pub holes_closed: u64,
    /// Triangles added by those caps.
    pub cap_triangles: u64,
    /// Of the holes capped, those fanned around a new centre vertex (not ear-clippable).
    pub holes_fanned: u64,
    /// Open parts made two-sided shells (`open = "shell"`).
    pub parts_shelled: u64,
    /// Triangles added as the shells' reversed copies.
    pub shell_triangles: u64,
    /// Edges with both ends on the boundary split at their midpoint before the shell's copy
    /// (so that no edge of the shell has four triangles).
    pub shell_edges_split: u64,
    /// What the mesh became: `closed`, `closed (N holes capped)`, `two-sided shell`, both
    /// joined by `and`, or `receiver only (may stay open)`.
    pub became: String,
}

impl MeshRepairs {
    /// One line naming every repair, e.g. "welded 380 corners, dropped 56 degenerate
    /// triangles, closed 3 holes with 41 triangles"; `None` when nothing was repaired.
    pub fn summary(&self) -> Option<String> {
        let mut parts = Vec::new();
        let mut say = |n: u64, one: &str, many: &str| match n {
            0 => {}
            1 => parts.push(one.replace('#', "1")),
            n => parts.push(many.replace('#', &n.to_string())),
        };
        say(self.corners_welded, "welded # corner", "welded # corners");
        say(
            self.unused_vertices_dropped,
            "dropped # unused vertex",
            "dropped # unused vertices",
        );
        say(
            self.degenerate_dropped,
            "dropped # degenerate triangle",
            "dropped # degenerate triangles",
        );
        say(
            self.duplicates_dropped,
            "dropped # duplicate triangle",
            "dropped # duplicate triangles",
        );
        say(
            self.faces_flipped,
            "flipped # triangle to agree with its neighbours",
            "flipped # triangles to agree with their neighbours",
        );
        say(
            self.parts_turned_inside_out,
            "turned # inside-out part right side out",
            "turned # inside-out parts right side out",
        );
        if self.nonmanifold_edges_split > 0 {
            parts.push(format!(
                "split {} non-manifold edge{} ({} vertices duplicated)",
                self.nonmanifold_edges_split,
                plural(self.nonmanifold_edges_split),
                self.vertices_split
            ));
        }
        if self.holes_closed > 0 {
            let fanned = if self.holes_fanned > 0 {
                format!(
                    ", {} of them fanned around a centre vertex",
                    self.holes_fanned
                )
            } else {
                String::new()
            };
            parts.push(format!(
                "closed {} hole{} with {} triangles{fanned}",
                self.holes_closed,
                plural(self.holes_closed),
                self.cap_triangles
            ));
        }
        if self.parts_shelled > 0 {
            parts.push(format!(
                "made {} open part{} a two-sided shell ({} triangles added, {} edges split)",
                self.parts_shelled,
                plural(self.parts_shelled),
                self.shell_triangles,
                self.shell_edges_split
            ));
        }
        (!parts.is_empty()).then(|| parts.join(", "))
    }
}

fn plural(n: u64) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}

/// One mesh as `stats.json`'s `"meshes"` lists it: its name, its triangle count as rendered
/// and every repair ([`MeshRepairs`]'s fields, flattened into the object).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct MeshReport {
    /// The mesh's name (its file or built-in part).
    pub name: String,
    /// Triangles as rendered (after repair).
    pub triangles: u64,
    /// What repair changed.
    #[serde(flatten)]
    pub repairs: MeshRepairs,
}

impl MeshReport {
    /// The report of `mesh`.
    pub fn of(mesh: &Mesh) -> MeshReport {
        MeshReport {
            name: mesh.name.clone(),
            triangles: mesh.triangles.len() as u64,
            repairs: mesh.repairs.clone(),
        }
    }
}

/// One line per repaired mesh of `scene`, `meshes[I] (NAME): SUMMARY` (the terminal prints
/// each as a warning, and so do the table notes), none for a scene that needed no repair.
pub fn repair_notes(scene: &Scene) -> Vec<String> {
    scene
        .meshes
        .iter()
        .enumerate()
        .filter_map(|(i, m)| {
            let s = m.repairs.summary()?;
            Some(format!("meshes[{i}] ({}): {s}", m.name))
        })
        .collect()
}

/// Loops longer than this are fanned around a centre vertex instead of ear-clipped (ear
/// clipping and its simplicity test are quadratic to cubic in the loop length).
pub const MAX_EAR_CLIP_LOOP: usize = 256;

/// What [`repair`] returns: the positions and triangles to render, and what was changed.
pub type Repaired = (Vec<Vec3>, Vec<[u32; 3]>, MeshRepairs);

/// Repairs one mesh (module docs): returns the positions and triangles to render and what
/// was changed. Errors (one sentence, without the mesh's name, which the caller adds): an
/// index out of range, a non-finite position, no triangle left, a non-manifold edge whose
/// sheets are undefined, an open mesh with `open = "refuse"`.
pub fn repair(
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    options: &RepairOptions,
) -> Result<Repaired, String> {
    let mut r = MeshRepairs::default();
    if positions.len() >= u32::MAX as usize || triangles.len() > (u32::MAX / 3) as usize {
        return Err(format!(
            "mesh too large: {} vertices and {} triangles exceed u32 indexing",
            positions.len(),
            triangles.len()
        ));
    }
    if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
        let p = positions[i];
        return Err(format!(
            "vertex {i} is not finite: ({}, {}, {})",
            p.x, p.y, p.z
        ));
    }
    for (t, tri) in triangles.iter().enumerate() {
        if let Some(&i) = tri.iter().find(|&&i| i as usize >= positions.len()) {
            return Err(format!(
                "triangle {t} refers to vertex {i} but the mesh has {} vertices",
                positions.len()
            ));
        }
    }

    // 1. Weld, 2. clean, then drop unused vertices.
    let (canon, identical) = if options.weld {
        weld_map(&positions, options.weld_tolerance)
    } else {
        ((0..positions.len() as u32).collect(), 0)
    };
    r.corners_welded = canon
        .iter()
        .enumerate()
        .filter(|&(i, &c)| c as usize != i)
        .count() as u64;
    if !options.count_identical_welds {
        r.corners_welded -= identical;
    }
    let mut tris: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| t.map(|i| canon[i as usize]))
        .collect();
    let before = tris.len();
    tris.retain(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0]);
    r.degenerate_dropped = (before - tris.len()) as u64;
    r.duplicates_dropped = drop_duplicates(&mut tris, positions.len());
    let (mut pos, dropped) = compact(&positions, &canon, &mut tris, options.weld);
    r.unused_vertices_dropped = dropped;
    if tris.is_empty() {
        return Err("no triangle is left after dropping degenerate ones".into());
    }
    if options.receiver_only {
        r.became = "receiver only (may stay open)".into();
        return Ok((pos, tris, r));
    }

    // 3. Orient each part by its majority.
    let edges = EdgeTable::new(&tris);
    let (flips, conflicts) = orient(&edges);
    let crowded = edges.groups().any(|g| g.len() > 2);
    let buckets = edges.into_buckets();
    for (t, &f) in tris.iter_mut().zip(&flips) {
        if f {
            t.swap(1, 2);
        }
    }
    r.faces_flipped = flips.iter().filter(|&&f| f).count() as u64;

    // 4. Cut non-manifold and conflicting edges into sheets.
    let cuts = crowded || !conflicts.is_empty();
    if cuts {
        let (cut, split) = split_sheets(&mut pos, &mut tris, conflicts)?;
        r.nonmanifold_edges_split = cut;
        r.vertices_split = split;
    }

    // 5. Open parts (the edge table of step 3 serves unless sheets were cut).
    let edges = if cuts {
        EdgeTable::new(&tris)
    } else {
        EdgeTable::turned(&tris, buckets, &flips)
    };
    if let Some(e) = edges
        .groups()
        .find(|g| g.len() > 2 || edges.same_direction(g))
    {
        let [a, b] = edges.ends(e.h(0));
        return Err(format!(
            "edge {} – {} still has {} triangles after splitting its sheets: the sheets \
             meeting there are not separable (a non-orientable surface or fans touching only \
             along this edge); separate them in a modelling tool",
            fmt_p(pos[a as usize]),
            fmt_p(pos[b as usize]),
            e.len()
        ));
    }
    let part = parts(&tris, &edges);
    let boundary: Vec<u32> = edges
        .groups()
        .filter(|g| g.len() == 1)
        .map(|g| g.h(0))
        .collect();
    r.boundary_edges = boundary.len() as u64;
    let mut open_part = vec![false; tris.len()];
    for &h in &boundary {
        open_part[part[(h / 3) as usize] as usize] = true;
    }
    if let (Some(OpenTreatment::Refuse), Some(&h)) = (options.open, boundary.first()) {
        let [a, b] = edges.ends(h);
        return Err(format!(
            "open mesh: edge {} – {} has only one triangle ({} boundary edges in all); set \
             open = \"close\" to cap the holes or open = \"shell\" to render the surface \
             two-sided",
            fmt_p(pos[a as usize]),
            fmt_p(pos[b as usize]),
            boundary.len()
        ));
    }
    let mut part_of: Vec<u32> = part.clone();
    let mut shelled = vec![false; tris.len()];
    let mut capped_holes = 0;
    if !boundary.is_empty() {
        let loops = boundary_loops(&edges, &boundary);
        // Caps per part: all of a part's loops, planned before anything is added.
        let mut caps: Vec<(u32, Cap)> = loops
            .iter()
            .map(|lp| {
                let p = part[(lp.first_half_edge / 3) as usize];
                (p, plan_cap(&pos, &edges, &lp.vertices))
            })
            .collect();
        fan_shared_diagonals(&mut caps);
        for (p, cap) in &caps {
            let fall_back = options.open.is_none() && matches!(cap, Cap::Fan);
            if fall_back || options.open == Some(OpenTreatment::Shell) {
                shelled[*p as usize] = true;
            }
        }
        for ((p, cap), lp) in caps.into_iter().zip(&loops) {
            if shelled[p as usize] {
                continue;
            }
            r.holes_closed += 1;
            capped_holes += 1;
            let added = match cap {
                Cap::Ears { triangles, .. } => triangles,
                Cap::Fan => {
                    r.holes_fanned += 1;
                    fan_cap(&mut pos, &lp.vertices)
                }
            };
            r.cap_triangles += added.len() as u64;
            part_of.extend(std::iter::repeat_n(p, added.len()));
            tris.extend(added);
        }
        r.parts_shelled = (0..open_part.len())
            .filter(|&p| open_part[p] && shelled[p])
            .count() as u64;
        if r.parts_shelled > 0 {
            let (split_edges, added) = make_shells(&mut pos, &mut tris, &mut part_of, &shelled);
            r.shell_edges_split = split_edges;
            r.shell_triangles = added;
        }
    }

    // 6. Closed parts right side out (shells have volume 0 and are left as they are).
    // Each closed part's triangles in triangle order (shelled parts' in a last bucket, unused).
    let part_count = open_part.len();
    let (start, members) = bucket_sort(part_count + 1, part_of.len(), |t| {
        let p = part_of[t];
        let bucket = if shelled[p as usize] {
            part_count as u32
        } else {
            p
        };
        (bucket, t as u32)
    });
    let mut own: Vec<[u32; 3]> = Vec::new();
    for p in 0..part_count {
        let list = &members[start[p] as usize..start[p + 1] as usize];
        if list.is_empty() {
            continue;
        }
        own.clear();
        own.extend(list.iter().map(|&t| tris[t as usize]));
        if inside_out_volume(&pos, &own).is_some() {
            r.parts_turned_inside_out += 1;
            for &t in list {
                tris[t as usize].swap(1, 2);
            }
        }
    }
    r.became = match (capped_holes, r.parts_shelled) {
        (0, 0) => "closed".to_string(),
        (h, 0) => format!("closed ({h} hole{} capped)", plural(h)),
        (0, _) => "two-sided shell".to_string(),
        (h, _) => format!("closed ({h} hole{} capped) and two-sided shell", plural(h)),
    };
    Ok((pos, tris, r))
}

/// A position as `(x, y, z)` for messages.
fn fmt_p(p: Vec3) -> String {
    format!("({}, {}, {})", p.x, p.y, p.z)
}

/// Per vertex, the vertex it welds into: the first (lowest-index) vertex at the same
/// position (bits of `p + 0`, so −0 = +0), or with `tolerance > 0` the lowest index of its
/// class of points chained within `tolerance × diagonal` of each other; and how many
/// vertices are welded for being at a bit-identical position.
pub(crate) fn weld_map(positions: &[Vec3], tolerance: f64) -> (Vec<u32>, u64) {
    let n = positions.len();
    let mut canon: Vec<u32> = (0..n as u32).collect();
    // Equal positions meet in one bucket of a fixed hash of their bits (a hash only places
    // them: collisions cost time, not correctness), sorted there by bits and index.
    let bits = |i: usize| (positions[i] + Vec3::ZERO).to_array().map(f32::to_bits);
    let log_buckets = (n / 4).max(1).next_power_of_two().trailing_zeros();
    let (start, order) = bucket_sort(1 << log_buckets, n, |i| {
        let [x, y, z] = bits(i).map(u64::from);
        let h = x.wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ y.wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
            ^ z.wrapping_mul(0x1656_67B1_9E37_79F9);
        ((h >> 32 >> (32 - log_buckets)) as u32, (bits(i), i as u32))
    });
    let mut identical = 0;
    for w in start.windows(2) {
        let bucket = &order[w[0] as usize..w[1] as usize];
        for k in 1..bucket.len() {
            if bucket[k].0 == bucket[k - 1].0 {
                canon[bucket[k].1 as usize] = canon[bucket[k - 1].1 as usize];
                identical += 1;
            }
        }
    }
    if tolerance <= 0.0 || n == 0 {
        return (canon, identical);
    }
    let (lo, hi) = positions
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.as_dvec3()), hi.max(p.as_dvec3()))
        });
    let h = tolerance * (hi - lo).length();
    if h <= 0.0 {
        return (canon, identical);
    }
    // Cells of edge h: points within h of each other are in neighbouring cells.
    let cell = |p: Vec3| ((p.as_dvec3() - lo) / h).floor().as_i64vec3().to_array();
    let mut grid: Vec<([i64; 3], u32)> = positions
        .iter()
        .enumerate()
        .map(|(i, p)| (cell(*p), i as u32))
        .collect();
    grid.sort_unstable();
    let mut parent = canon;
    for (i, p) in positions.iter().enumerate() {
        let c = cell(*p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let key = [c[0] + dx, c[1] + dy, c[2] + dz];
                    let start = grid.partition_point(|(k, _)| *k < key);
                    for &(k, j) in &grid[start..] {
                        if k != key {
                            break;
                        }
                        if j as usize > i
                            && positions[j as usize].as_dvec3().distance(p.as_dvec3()) <= h
                        {
                            union_min(&mut parent, i as u32, j);
                        }
                    }
                }
            }
        }
    }
    let canon = (0..n as u32).map(|i| find(&mut parent, i)).collect();
    (canon, identical)
}

/// Union-find root with path halving.
fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let up = parent[parent[x as usize] as usize];
        parent[x as usize] = up;
        x = up;
    }
    x
}

/// Joins the classes of `a` and `b`; the root is the smaller index (so a class's root is its
/// lowest member, whatever the order of the unions).
fn union_min(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        let (keep, join) = (ra.min(rb), ra.max(rb));
        parent[join as usize] = keep;
    }
}

/// Drops every later copy of a triangle (the same vertices in the same rotation, every index
/// below `vertices`); returns how many. The triangles, each turned to start at its lowest
/// vertex, are bucketed by that vertex (a counting sort) and each bucket sorted by the other
/// two and the triangle index, so copies meet in index order.
fn drop_duplicates(tris: &mut Vec<[u32; 3]>, vertices: usize) -> u64 {
    let rotated = |t: &[u32; 3]| {
        let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
        [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
    };
    let (start, keys) = bucket_sort(vertices, tris.len(), |i| {
        let [a, b, c] = rotated(&tris[i]);
        (a, ([b, c], i as u32))
    });
    let mut keep = vec![true; tris.len()];
    for w in start.windows(2) {
        let bucket = &keys[w[0] as usize..w[1] as usize];
        for k in 1..bucket.len() {
            if bucket[k].0 == bucket[k - 1].0 {
                keep[bucket[k].1 as usize] = false;
            }
        }
    }
    let before = tris.len();
    let mut k = keep.iter();
    tris.retain(|_| *k.next().unwrap_or(&true));
    (before - tris.len()) as u64
}

/// The used vertices renumbered in their original order (triangles rewritten), each stored
/// as `p + 0` (−0 as +0) when `welded`; returns the new positions and how many unused
/// vertices (other than welded-away ones) were dropped.
pub(crate) fn compact(
    positions: &[Vec3],
    canon: &[u32],
    tris: &mut [[u32; 3]],
    welded: bool,
) -> (Vec<Vec3>, u64) {
    let mut new_index = vec![u32::MAX; positions.len()];
    for t in tris.iter() {
        for &i in t {
            new_index[i as usize] = 0;
        }
    }
    let mut pos = Vec::with_capacity(positions.len());
    let mut unused = 0;
    for (i, slot) in new_index.iter_mut().enumerate() {
        if *slot == 0 {
            *slot = pos.len() as u32;
            pos.push(if welded {
                positions[i] + Vec3::ZERO
            } else {
                positions[i]
            });
        } else if canon[i] as usize == i {
            unused += 1;
        }
    }
    for t in tris.iter_mut() {
        *t = t.map(|i| new_index[i as usize]);
    }
    (pos, unused)
}

fn key(a: u32, b: u32) -> u64 {
    (u64::from(a.min(b)) << 32) | u64::from(a.max(b))
}

/// Per triangle whether to flip it so that each part (joined by two-triangle edges) agrees
/// with its majority, and the two-triangle edges that still disagree afterwards (a part
/// that cannot be oriented), as the vertex pairs of their ends.
fn orient(edges: &EdgeTable) -> (Vec<bool>, Vec<[u32; 2]>) {
    let n = edges.tris().len();
    // Per triangle its neighbours across two-triangle edges: (neighbour, same direction).
    let mut neighbours: Vec<[(u32, bool); 3]> = vec![[(u32::MAX, false); 3]; n];
    let mut pairs = Vec::new();
    for g in edges.groups().filter(|g| g.len() == 2) {
        let (h0, h1) = (g.h(0), g.h(1));
        let same = edges.same_direction(&g);
        // Half-edge h is corner h % 3 of triangle h / 3: one slot per corner.
        neighbours[(h0 / 3) as usize][(h0 % 3) as usize] = (h1 / 3, same);
        neighbours[(h1 / 3) as usize][(h1 % 3) as usize] = (h0 / 3, same);
        pairs.push([h0, h1]);
    }
    let mut state: Vec<Option<bool>> = vec![None; n];
    let mut queue = std::collections::VecDeque::new();
    let mut members = Vec::new();
    for seed in 0..n {
        if state[seed].is_some() {
            continue;
        }
        state[seed] = Some(false);
        queue.push_back(seed as u32);
        members.clear();
        members.push(seed as u32);
        while let Some(t) = queue.pop_front() {
            let s = state[t as usize].unwrap_or(false);
            for &(u, same) in &neighbours[t as usize] {
                if u != u32::MAX && state[u as usize].is_none() {
                    state[u as usize] = Some(s ^ same);
                    members.push(u);
                    queue.push_back(u);
                }
            }
        }
        let flipped = members
            .iter()
            .filter(|&&t| state[t as usize] == Some(true))
            .count();
        if 2 * flipped > members.len() {
            for &t in &members {
                state[t as usize] = state[t as usize].map(|s| !s);
            }
        }
    }
    let flips: Vec<bool> = state.iter().map(|s| s.unwrap_or(false)).collect();
    let conflicts = pairs
        .into_iter()
        .filter(|[h0, h1]| {
            let same = edges.ends(*h0) == edges.ends(*h1);
            same ^ flips[(h0 / 3) as usize] ^ flips[(h1 / 3) as usize]
        })
        .map(|[h0, _]| edges.ends(h0))
        .collect();
    (flips, conflicts)
}

/// Cuts every edge with three or more triangles, and the `conflicts` (two-triangle edges
/// whose windings disagree), into separate sheets (module docs, step 4): triangles paired
/// by angle stay joined, the cut edges' vertices are duplicated per class of corners joined
/// across the uncut edges and the pairs. Returns (edges cut, vertices added).
fn split_sheets(
    pos: &mut Vec<Vec3>,
    tris: &mut [[u32; 3]],
    conflicts: Vec<[u32; 2]>,
) -> Result<(u64, u64), String> {
    let edges = EdgeTable::new(tris);
    let crowded: Vec<Vec<u32>> = edges
        .groups()
        .filter(|g| g.len() > 2)
        .map(|g| g.all())
        .collect();
    if crowded.is_empty() && conflicts.is_empty() {
        return Ok((0, 0));
    }
    // Half-edge pairs that stay joined: every consistent two-triangle edge, and the pairs
    // found around each crowded edge.
    let mut joined: Vec<[u32; 2]> = edges
        .groups()
        .filter(|g| g.len() == 2 && !edges.same_direction(g))
        .map(|g| [g.h(0), g.h(1)])
        .collect();
    let mut cut_vertices = Vec::new();
    for g in &crowded {
        joined.extend(pair_by_angle(pos, &edges, g).unwrap_or_default());
        cut_vertices.extend(edges.ends(g[0]));
    }
    for ends in &conflicts {
        cut_vertices.extend(ends);
    }
    cut_vertices.sort_unstable();
    cut_vertices.dedup();
    // Corner classes: corner c = triangle·3 + k; a half-edge h starts at corner h and ends at
    // the next corner of its triangle.
    let next = |c: u32| (c / 3) * 3 + (c % 3 + 1) % 3;
    let mut parent: Vec<u32> = (0..tris.len() as u32 * 3).collect();
    for [h0, h1] in joined {
        // h0 runs a→b, h1 runs b→a: start of h0 meets end of h1 and vice versa.
        union_min(&mut parent, h0, next(h1));
        union_min(&mut parent, next(h0), h1);
    }
    let mut is_cut = vec![false; pos.len()];
    for &v in &cut_vertices {
        is_cut[v as usize] = true;
    }
    // Per cut vertex, its classes in order of their lowest corner: the first keeps the vertex.
    let mut classes: Vec<(u32, u32, u32)> = Vec::new(); // (vertex, root, corner)
    for c in 0..tris.len() as u32 * 3 {
        let v = tris[(c / 3) as usize][(c % 3) as usize];
        if is_cut[v as usize] {
            classes.push((v, find(&mut parent, c), c));
        }
    }
    classes.sort_unstable();
    let mut added = 0;
    let mut w = 0;
    while w < classes.len() {
        let v = classes[w].0;
        let end = w + classes[w..].iter().take_while(|x| x.0 == v).count();
        // Roots are lowest corners (union_min), so sorting by root orders classes by corner.
        let mut first_root = None;
        let mut k = w;
        while k < end {
            let root = classes[k].1;
            let run = classes[k..end].iter().take_while(|x| x.1 == root).count();
            if first_root.is_some() {
                let new = pos.len() as u32;
                pos.push(pos[v as usize]);
                added += 1;
                for &(_, _, c) in &classes[k..k + run] {
                    tris[(c / 3) as usize][(c % 3) as usize] = new;
                }
            }
            first_root.get_or_insert(root);
            k += run;
        }
        w = end;
    }
    Ok(((crowded.len() + conflicts.len()) as u64, added))
}

/// The pairs of half-edges around the crowded edge `g` that bound one solid wedge: sorted by
/// the angle of their third vertex about the edge, a triangle traversing `b→a` followed
/// (counter-clockwise about `a→b`) by one traversing `a→b`. `None` when two triangles lie
/// at one angle (or one has no angle: zero area), where the order is undefined: then no two
/// of them are joined, every triangle keeps the edge as a boundary edge of its own sheet, and
/// the open treatment (close, shell) applies to it — the mesh renders, with the cut counted.
fn pair_by_angle(pos: &[Vec3], edges: &EdgeTable, g: &[u32]) -> Option<Vec<[u32; 2]>> {
    let [a, b] = edges.ends(g[0]);
    let (pa, pb) = (pos[a as usize].as_dvec3(), pos[b as usize].as_dvec3());
    let d = pb - pa;
    let perp = |h: u32| {
        let t = edges.tris()[(h / 3) as usize];
        let third = t[((h % 3 + 2) % 3) as usize];
        let w = pos[third as usize].as_dvec3() - pa;
        w - d * (w.dot(d) / d.length_squared())
    };
    let u = perp(g[0]);
    let v = d.cross(u);
    let mut around: Vec<(f64, u32)> = Vec::with_capacity(g.len());
    for &h in g {
        let w = perp(h);
        if w == DVec3::ZERO || u == DVec3::ZERO {
            // One of them has zero area: it has no angle about the edge.
            return None;
        }
        around.push((libm::atan2(w.dot(v), w.dot(u)), h));
    }
    around.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    if around.windows(2).any(|w| w[0].0 == w[1].0) {
        // Two of them lie in one plane on the same side: their order is undefined.
        return None;
    }
    let forward = |h: u32| edges.ends(h) == [a, b];
    let n = around.len();
    let mut used = vec![false; n];
    let mut pairs = Vec::new();
    for i in 0..n {
        let j = (i + 1) % n;
        let (hi, hj) = (around[i].1, around[j].1);
        if !used[i] && !used[j] && !forward(hi) && forward(hj) {
            used[i] = true;
            used[j] = true;
            pairs.push([hj, hi]);
        }
    }
    Some(pairs)
}

/// Per triangle, the part it belongs to: the lowest triangle index of its class joined
/// across edges with exactly two triangles.
fn parts(tris: &[[u32; 3]], edges: &EdgeTable) -> Vec<u32> {
    let mut parent: Vec<u32> = (0..tris.len() as u32).collect();
    for g in edges.groups().filter(|g| g.len() == 2) {
        union_min(&mut parent, g.h(0) / 3, g.h(1) / 3);
    }
    (0..tris.len() as u32)
        .map(|t| find(&mut parent, t))
        .collect()
}

/// One hole: its vertices in the direction of the boundary half-edges, and the first of them.
struct BoundaryLoop {
    vertices: Vec<u32>,
    first_half_edge: u32,
}

/// The simple boundary loops. Each boundary half-edge a→b is followed by the boundary
/// half-edge leaving b in the same gap of b's fan (walking from its triangle across the
/// edges at b), so loops that touch at a vertex separate; a loop that still visits a vertex
/// twice is split there into simple loops. Loops start at their lowest half-edge.
fn boundary_loops(edges: &EdgeTable, boundary: &[u32]) -> Vec<BoundaryLoop> {
    let is_boundary = |h: u32| {
        let [a, b] = edges.ends(h);
        edges.of(a, b).count() == 1
    };
    let successor = |h: u32| {
        // The half-edge leaving b in h's triangle, then across to the neighbour until a
        // boundary one.
        let mut out = (h / 3) * 3 + (h % 3 + 1) % 3;
        loop {
            if is_boundary(out) {
                return out;
            }
            let [b, c] = edges.ends(out);
            let twin = edges.of(b, c).find(|&x| x != out).unwrap_or(out);
            // The twin runs c→b; the half-edge leaving b in its triangle is the next one.
            out = (twin / 3) * 3 + (twin % 3 + 1) % 3;
        }
    };
    let mut used = vec![false; edges.tris().len() * 3];
    let mut loops = Vec::new();
    for &start in boundary {
        if used[start as usize] {
            continue;
        }
        let mut walk = Vec::new();
        let mut h = start;
        while !used[h as usize] {
            used[h as usize] = true;
            walk.push(h);
            h = successor(h);
        }
        // Split at repeated vertices into simple loops (a stack of the open walk).
        let mut stack: Vec<u32> = Vec::new();
        let mut at: std::collections::BTreeMap<u32, usize> = Default::default();
        for &h in &walk {
            let v = edges.ends(h)[0];
            if let Some(&k) = at.get(&v) {
                let sub: Vec<u32> = stack.split_off(k);
                for s in &sub {
                    at.remove(&edges.ends(*s)[0]);
                }
                loops.push(loop_of(edges, sub));
            }
            at.insert(v, stack.len());
            stack.push(h);
        }
        loops.push(loop_of(edges, stack));
    }
    loops
}

fn loop_of(edges: &EdgeTable, half_edges: Vec<u32>) -> BoundaryLoop {
    BoundaryLoop {
        vertices: half_edges.iter().map(|&h| edges.ends(h)[0]).collect(),
        first_half_edge: half_edges[0],
    }
}

/// How one hole is capped.
enum Cap {
    /// By ear-clipped triangles of the loop's own vertices.
    Ears {
        /// The cap's triangles.
        triangles: Vec<[u32; 3]>,
        /// The keys of its diagonals (edges that are not sides of the loop), sorted.
        diagonals: Vec<u64>,
    },
    /// By a fan around a new centre vertex (the loop is long, not simple in its best-fit
    /// plane, or a diagonal of its ears is already an edge).
    Fan,
}

/// Plans the cap of the loop `lp` (vertices in boundary direction; the cap runs the other
/// way): ear clipping of its projection onto the plane of its Newell normal when that is a
/// simple polygon and no diagonal is an existing edge, else [`Cap::Fan`].
fn plan_cap(pos: &[Vec3], edges: &EdgeTable, lp: &[u32]) -> Cap {
    let cap: Vec<u32> = lp.iter().rev().copied().collect();
    let k = cap.len();
    if k > MAX_EAR_CLIP_LOOP {
        return Cap::Fan;
    }
    let p: Vec<DVec3> = cap.iter().map(|&i| pos[i as usize].as_dvec3()).collect();
    let centre = p.iter().sum::<DVec3>() / k as f64;
    let mut n = DVec3::ZERO;
    for i in 0..k {
        let (a, b) = (p[i] - centre, p[(i + 1) % k] - centre);
        n += a.cross(b);
    }
    if n == DVec3::ZERO {
        return Cap::Fan;
    }
    let n = n.normalize();
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    let q: Vec<DVec2> = p
        .iter()
        .map(|x| DVec2::new((*x - centre).dot(u), (*x - centre).dot(v)))
        .collect();
    if !is_simple(&q) {
        return Cap::Fan;
    }
    let Some(ears) = ear_clip(&q) else {
        return Cap::Fan;
    };
    let list: Vec<[u32; 3]> = ears.iter().map(|e| e.map(|i| cap[i])).collect();
    // A diagonal (an ear edge that is not a loop edge) must not be an edge already.
    let diagonals = diagonals(&list, &cap);
    let new = diagonals
        .iter()
        .all(|&d| edges.of((d >> 32) as u32, d as u32).next().is_none());
    if new {
        Cap::Ears {
            triangles: list,
            diagonals,
        }
    } else {
        Cap::Fan
    }
}

/// The keys of the diagonals of the ear-clipped cap `list` of the loop `cap` (each diagonal
/// once, sorted).
fn diagonals(list: &[[u32; 3]], cap: &[u32]) -> Vec<u64> {
    let k = cap.len();
    let mut sides: Vec<u64> = (0..k).map(|i| key(cap[i], cap[(i + 1) % k])).collect();
    sides.sort_unstable();
    let mut out: Vec<u64> = list
        .iter()
        .flat_map(|t| (0..3).map(move |kk| key(t[kk], t[(kk + 1) % 3])))
        .filter(|d| sides.binary_search(d).is_err())
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// Caps whose ear-clipped diagonals coincide with another cap's diagonal (two holes sharing
/// two vertices) would put four triangles on that edge: both are fanned instead.
fn fan_shared_diagonals(caps: &mut [(u32, Cap)]) {
    let mut all: Vec<(u64, usize)> = Vec::new();
    for (i, (_, cap)) in caps.iter().enumerate() {
        if let Cap::Ears { diagonals, .. } = cap {
            all.extend(diagonals.iter().map(|&d| (d, i)));
        }
    }
    all.sort_unstable();
    for w in all.windows(2) {
        if w[0].0 == w[1].0 {
            caps[w[0].1].1 = Cap::Fan;
            caps[w[1].1].1 = Cap::Fan;
        }
    }
}

/// Whether the closed 2D polygon `q` has no two non-adjacent sides that touch, and no two
/// corners at one point.
fn is_simple(q: &[DVec2]) -> bool {
    let k = q.len();
    for i in 0..k {
        for j in i + 1..k {
            if q[i] == q[j] {
                return false;
            }
            let adjacent = j == i + 1 || (i == 0 && j == k - 1);
            if !adjacent && segments_touch(q[i], q[(i + 1) % k], q[j], q[(j + 1) % k]) {
                return false;
            }
        }
    }
    true
}

/// Twice the signed area of the 2D triangle (a, b, c): positive counter-clockwise.
fn orient2(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

/// Whether the closed segments ab and cd share a point.
fn segments_touch(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let (d1, d2) = (orient2(a, b, c), orient2(a, b, d));
    let (d3, d4) = (orient2(c, d, a), orient2(c, d, b));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let within = |p: DVec2, q: DVec2, r: DVec2| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    (d1 == 0.0 && within(a, b, c))
        || (d2 == 0.0 && within(a, b, d))
        || (d3 == 0.0 && within(c, d, a))
        || (d4 == 0.0 && within(c, d, b))
}

/// Ear clipping of the simple counter-clockwise polygon `q`: triangles of corner indices,
/// counter-clockwise; `None` when at some point no ear is left (a clockwise polygon, or a
/// corner of zero angle).
fn ear_clip(q: &[DVec2]) -> Option<Vec<[usize; 3]>> {
    let mut rest: Vec<usize> = (0..q.len()).collect();
    let mut out = Vec::with_capacity(q.len().saturating_sub(2));
    while rest.len() > 3 {
        let m = rest.len();
        let ear = (0..m).find(|&i| {
            let (a, b, c) = (rest[(i + m - 1) % m], rest[i], rest[(i + 1) % m]);
            orient2(q[a], q[b], q[c]) > 0.0
                && rest.iter().all(|&x| {
                    x == a
                        || x == b
                        || x == c
                        || !(orient2(q[a], q[b], q[x]) >= 0.0
                            && orient2(q[b], q[c], q[x]) >= 0.0
                            && orient2(q[c], q[a], q[x]) >= 0.0)
                })
        })?;
        out.push([rest[(ear + m - 1) % m], rest[ear], rest[(ear + 1) % m]]);
        rest.remove(ear);
    }
    (orient2(q[rest[0]], q[rest[1]], q[rest[2]]) > 0.0).then(|| {
        out.push([rest[0], rest[1], rest[2]]);
        out
    })
}

/// The cap of the loop `lp` as a fan around a new vertex at the mean of its corners (added
/// to `pos`): one triangle per loop edge, each running that edge the other way.
fn fan_cap(pos: &mut Vec<Vec3>, lp: &[u32]) -> Vec<[u32; 3]> {
    let centre = lp
        .iter()
        .map(|&i| pos[i as usize].as_dvec3())
        .sum::<DVec3>()
        / lp.len() as f64;
    let m = pos.len() as u32;
    pos.push(centre.as_vec3());
    let k = lp.len();
    (0..k).map(|i| [m, lp[(i + 1) % k], lp[i]]).collect()
}

/// Makes every part marked in `shelled` a closed two-sided shell (module docs, step 5):
/// interior edges of those parts with both ends on the boundary are split at their midpoint
/// (in the front, before the copy), then each triangle gets a reversed copy whose interior
/// vertices are duplicates and whose boundary vertices are shared. Returns (edges split,
/// triangles added); `part_of` grows with the new triangles.
fn make_shells(
    pos: &mut Vec<Vec3>,
    tris: &mut Vec<[u32; 3]>,
    part_of: &mut Vec<u32>,
    shelled: &[bool],
) -> (u64, u64) {
    let in_shell = |part_of: &[u32], t: usize| shelled[part_of[t] as usize];
    let edges = EdgeTable::new(tris);
    let mut on_boundary = vec![false; pos.len()];
    for g in edges.groups().filter(|g| g.len() == 1) {
        if in_shell(part_of, (g.h(0) / 3) as usize) {
            for v in edges.ends(g.h(0)) {
                on_boundary[v as usize] = true;
            }
        }
    }
    // Midpoints of the interior edges with both ends on the boundary, in key order.
    let mut midpoint: Vec<(u64, u32)> = Vec::new();
    for g in edges.groups().filter(|g| g.len() == 2) {
        let [a, b] = edges.ends(g.h(0));
        if in_shell(part_of, (g.h(0) / 3) as usize)
            && on_boundary[a as usize]
            && on_boundary[b as usize]
        {
            let m = (pos[a as usize].as_dvec3() + pos[b as usize].as_dvec3()) * 0.5;
            midpoint.push((key(a, b), pos.len() as u32));
            pos.push(m.as_vec3());
        }
    }
    let split = midpoint.len() as u64;
    let mid = |a: u32, b: u32| {
        midpoint
            .binary_search_by_key(&key(a, b), |x| x.0)
            .ok()
            .map(|i| midpoint[i].1)
    };
    let n = tris.len();
    let mut front: Vec<[u32; 3]> = Vec::with_capacity(n);
    let mut front_part: Vec<u32> = Vec::with_capacity(n);
    for t in 0..n {
        let tri = tris[t];
        let pieces = if in_shell(part_of, t) {
            subdivide(
                tri,
                [
                    mid(tri[0], tri[1]),
                    mid(tri[1], tri[2]),
                    mid(tri[2], tri[0]),
                ],
            )
        } else {
            vec![tri]
        };
        front_part.extend(std::iter::repeat_n(part_of[t], pieces.len()));
        front.extend(pieces);
    }
    // The reversed copies: interior vertices duplicated in increasing index order.
    let mut copy = vec![u32::MAX; pos.len()];
    for (t, tri) in front.iter().enumerate() {
        if shelled[front_part[t] as usize] {
            for &v in tri {
                if !on_boundary.get(v as usize).copied().unwrap_or(false) {
                    copy[v as usize] = 0;
                }
            }
        }
    }
    for v in 0..copy.len() {
        if copy[v] == 0 {
            copy[v] = pos.len() as u32;
            pos.push(pos[v]);
        }
    }
    let mut added = 0;
    let m = front.len();
    for t in 0..m {
        if shelled[front_part[t] as usize] {
            let back = front[t].map(|v| {
                if copy[v as usize] == u32::MAX {
                    v
                } else {
                    copy[v as usize]
                }
            });
            front.push([back[0], back[2], back[1]]);
            front_part.push(front_part[t]);
            added += 1;
        }
    }
    *tris = front;
    *part_of = front_part;
    (split, added)
}

/// The triangle `t` with the edges that have a midpoint (`mid[k]` on edge k→k+1) split,
/// wound as `t`.
fn subdivide(t: [u32; 3], mid: [Option<u32>; 3]) -> Vec<[u32; 3]> {
    // Rotate so the split edges come first: then the cases are 0, 1 (edge 0), 2 (edges 0,
    // 1) and 3.
    let count = mid.iter().filter(|m| m.is_some()).count();
    let r = (0..3)
        .find(|&r| (0..count).all(|k| mid[(r + k) % 3].is_some()))
        .unwrap_or(0);
    let [a, b, c] = [t[r], t[(r + 1) % 3], t[(r + 2) % 3]];
    let [m0, m1, m2] = [mid[r], mid[(r + 1) % 3], mid[(r + 2) % 3]];
    match (m0, m1, m2) {
        (Some(ab), Some(bc), Some(ca)) => vec![[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]],
        (Some(ab), Some(bc), None) => vec![[ab, b, bc], [a, ab, bc], [a, bc, c]],
        (Some(ab), None, None) => vec![[a, ab, c], [ab, b, c]],
        _ => vec![t],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::adjacency;
    use crate::scene::procedural::{box_mesh, signed_volume6};

    /// The unit cube of [`box_mesh`]: 8 vertices, 12 outward triangles (quad k is triangles
    /// 2k, 2k+1; quad 5 is the +x face).
    fn cube() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let m = box_mesh("cube", Vec3::ZERO, Vec3::ONE, [1.0; 3]);
        (m.positions, m.triangles)
    }

    fn mesh(positions: &[Vec3], triangles: &[[u32; 3]]) -> Mesh {
        Mesh {
            name: "test".into(),
            positions: positions.to_vec(),
            triangles: triangles.to_vec(),
            color: [1.0; 3],
            receiver_only: false,
            repairs: MeshRepairs::default(),
        }
    }

    fn run(
        positions: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
        options: RepairOptions,
    ) -> (Vec<Vec3>, Vec<[u32; 3]>, MeshRepairs) {
        repair(positions, triangles, &options).unwrap()
    }

    /// Closed (the adjacency builds) and six times its volume.
    fn closed_volume6(p: &[Vec3], t: &[[u32; 3]]) -> f64 {
        let m = mesh(p, t);
        adjacency::build(&m).unwrap();
        signed_volume6(&m)
    }

    /// Every triangle with its own three corners, as STL writes them.
    fn stl(p: &[Vec3], t: &[[u32; 3]]) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let positions: Vec<Vec3> = t.iter().flat_map(|t| t.map(|i| p[i as usize])).collect();
        let triangles = (0..t.len() as u32)
            .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
            .collect();
        (positions, triangles)
    }

    #[test]
    fn stl_cube_welds_36_corners_into_8() {
        let (p, t) = cube();
        let (sp, st) = stl(&p, &t);
        assert_eq!(sp.len(), 36);
        let (p2, t2, r) = run(sp, st, RepairOptions::default());
        assert_eq!(p2.len(), 8);
        assert_eq!(t2.len(), 12);
        assert_eq!(r.corners_welded, 28);
        assert_eq!(closed_volume6(&p2, &t2), 6.0);
        assert_eq!(r.summary().as_deref(), Some("welded 28 corners"));
        assert_eq!(r.became, "closed");
    }

    #[test]
    fn degenerate_and_duplicate_triangles_are_dropped() {
        let (p, mut t) = cube();
        let clean = t.clone();
        t.insert(4, [0, 0, 5]);
        let [a, b, c] = t[2];
        t.push([b, c, a]); // triangle 2 again, rotated
        let (p2, t2, r) = run(p.clone(), t, RepairOptions::default());
        assert_eq!((r.degenerate_dropped, r.duplicates_dropped), (1, 1));
        assert_eq!((p2, t2), (p, clean));
        assert_eq!(
            r.summary().as_deref(),
            Some("dropped 1 degenerate triangle, dropped 1 duplicate triangle")
        );
    }

    #[test]
    fn a_face_and_its_reverse_are_kept_as_a_closed_two_sided_part() {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let (p2, t2, r) = run(p, vec![[0, 1, 2], [0, 2, 1]], RepairOptions::default());
        assert_eq!(t2, vec![[0, 1, 2], [0, 2, 1]]);
        assert_eq!(closed_volume6(&p2, &t2), 0.0);
        assert_eq!(r.summary(), None);
    }

    #[test]
    fn one_flipped_face_is_flipped_back() {
        let (p, mut t) = cube();
        let clean = t.clone();
        t[5].swap(1, 2);
        let (p2, t2, r) = run(p, t, RepairOptions::default());
        assert_eq!(r.faces_flipped, 1);
        assert_eq!(r.parts_turned_inside_out, 0);
        assert_eq!(t2, clean);
        assert_eq!(closed_volume6(&p2, &t2), 6.0);
    }

    #[test]
    fn an_inside_out_cube_is_turned_right_side_out() {
        let (p, mut t) = cube();
        let clean = t.clone();
        for x in &mut t {
            x.swap(1, 2);
        }
        let (_, t2, r) = run(p, t, RepairOptions::default());
        assert_eq!((r.faces_flipped, r.parts_turned_inside_out), (0, 1));
        assert_eq!(t2, clean);
        assert_eq!(
            r.summary().as_deref(),
            Some("turned 1 inside-out part right side out")
        );
    }

    /// The cube without its +x face (triangles 10 and 11): the hole's loop is the square
    /// 1, 3, 7, 5 at x = 1.
    fn open_box() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let (p, mut t) = cube();
        t.truncate(10);
        (p, t)
    }

    #[test]
    fn close_caps_the_hole_with_the_cubes_volume() {
        for open in [None, Some(OpenTreatment::Close)] {
            let (p, t) = open_box();
            let options = RepairOptions {
                open,
                ..Default::default()
            };
            let (p2, t2, r) = run(p, t, options);
            assert_eq!(r.boundary_edges, 4);
            assert_eq!((r.holes_closed, r.cap_triangles, r.holes_fanned), (1, 2, 0));
            assert_eq!(p2.len(), 8, "ear clipping adds no vertex");
            assert_eq!(closed_volume6(&p2, &t2), 6.0);
            assert_eq!(r.became, "closed (1 hole capped)");
            assert_eq!(
                r.summary().as_deref(),
                Some("closed 1 hole with 2 triangles")
            );
        }
    }

    #[test]
    fn shell_makes_a_closed_two_sided_surface_of_volume_0() {
        let (p, t) = open_box();
        let options = RepairOptions {
            open: Some(OpenTreatment::Shell),
            ..Default::default()
        };
        let (p2, t2, r) = run(p, t, options);
        // The interior vertices 0, 2, 4, 6 get copies; no interior edge joins two boundary
        // vertices (the box's diagonals each have an interior end).
        assert_eq!(p2.len(), 12);
        assert_eq!(t2.len(), 20);
        assert_eq!(
            (r.parts_shelled, r.shell_triangles, r.shell_edges_split),
            (1, 10, 0)
        );
        assert_eq!(closed_volume6(&p2, &t2), 0.0);
        assert_eq!(r.became, "two-sided shell");
    }

    #[test]
    fn shell_of_a_quad_splits_its_diagonal() {
        // Two triangles on diagonal 0–2, all four corners on the boundary: the diagonal is
        // split at its midpoint (4 front triangles), the midpoint copied (4 back ones).
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let options = RepairOptions {
            open: Some(OpenTreatment::Shell),
            ..Default::default()
        };
        let (p2, t2, r) = run(p, vec![[0, 1, 2], [0, 2, 3]], options);
        assert_eq!(r.shell_edges_split, 1);
        assert_eq!((p2.len(), t2.len(), r.shell_triangles), (6, 8, 4));
        assert_eq!(p2[4], Vec3::new(0.5, 0.5, 0.0));
        assert_eq!(closed_volume6(&p2, &t2), 0.0);
    }

    #[test]
    fn refuse_names_a_boundary_edge() {
        let (p, t) = open_box();
        let options = RepairOptions {
            open: Some(OpenTreatment::Refuse),
            ..Default::default()
        };
        let e = repair(p, t, &options).unwrap_err();
        assert!(
            e.starts_with(
                "open mesh: edge (1, 1, 0) – (1, 0, 0) has only one triangle (4 boundary edges \
                 in all); set open = \"close\" to cap the holes"
            ),
            "{e}"
        );
    }

    #[test]
    fn two_cubes_on_one_edge_are_split_into_two_closed_cubes() {
        // Cube B is cube A moved by (1, 1, 0): they share the edge x = y = 1 (4 triangles).
        let (p, t) = cube();
        let mut positions = p.clone();
        positions.extend(p.iter().map(|v| *v + Vec3::new(1.0, 1.0, 0.0)));
        let mut triangles = t.clone();
        triangles.extend(t.iter().map(|x| x.map(|i| i + 8)));
        let (p2, t2, r) = run(positions, triangles, RepairOptions::default());
        assert_eq!(r.corners_welded, 2);
        assert_eq!((r.nonmanifold_edges_split, r.vertices_split), (1, 2));
        assert_eq!((p2.len(), t2.len()), (16, 24));
        assert_eq!(r.faces_flipped, 0);
        assert_eq!(closed_volume6(&p2, &t2), 12.0);
        assert_eq!(
            r.summary().as_deref(),
            Some("welded 2 corners, split 1 non-manifold edge (2 vertices duplicated)")
        );
    }

    /// Three triangles on edge 0–1, two of them on the same side in one plane: their order
    /// about the edge is undefined, so none is joined to another across it; each keeps its own
    /// copy of the edge (2 vertices duplicated for each triangle beyond the first), the edge
    /// counts as split, and the three open triangles are then closed (a single triangle's
    /// hole is capped by its reverse) into a mesh the closed-mesh check accepts.
    #[test]
    fn coplanar_triangles_on_a_non_manifold_edge_are_cut_apart() {
        let p = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(0.5, 2.0, 0.0),
            Vec3::Z,
        ];
        let (p2, t2, r) = run(
            p,
            vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
            RepairOptions::default(),
        );
        assert_eq!((r.nonmanifold_edges_split, r.vertices_split), (1, 4));
        assert_eq!(r.boundary_edges, 9);
        assert_eq!((r.holes_closed, r.cap_triangles), (3, 3));
        assert_eq!((p2.len(), t2.len()), (9, 6));
        let mesh = crate::scene::Mesh {
            name: "cut".into(),
            positions: p2,
            triangles: t2,
            color: [0.5; 3],
            receiver_only: false,
            repairs: r,
        };
        crate::scene::adjacency::build(&mesh).unwrap();
    }

    #[test]
    fn tolerance_welds_near_corners_and_zero_tolerance_does_not() {
        let (p, t) = cube();
        let (mut sp, st) = stl(&p, &t);
        // The last copy of corner (1, 1, 1) one f32 step (1.19e-7) away in x (the first
        // copy's position is the one kept).
        let k = sp.iter().rposition(|v| *v == Vec3::ONE).unwrap();
        sp[k].x = f32::from_bits(1.0f32.to_bits() + 1);
        let near = RepairOptions {
            weld_tolerance: 1e-6,
            ..Default::default()
        };
        let (p2, t2, r) = run(sp.clone(), st.clone(), near);
        assert_eq!((r.corners_welded, p2.len()), (28, 8));
        assert_eq!(closed_volume6(&p2, &t2), 6.0);
        let (_, _, r) = run(sp, st, RepairOptions::default());
        assert_eq!(r.corners_welded, 27);
        assert_eq!(
            r.boundary_edges, 4,
            "the lone corner's triangle opens a crack"
        );
    }

    /// Two triangles of a square with copied corners, positions in this order: (1,1,0),
    /// (−0,0,0), (1,0,0), (0,0,0), (1,1,0), (0,1,0); as a receiver-only mesh (weld and clean
    /// only, so the open square stays as it is).
    fn square_with_minus_zero() -> (Vec<Vec3>, Vec<[u32; 3]>, RepairOptions) {
        let p = vec![
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let options = RepairOptions {
            receiver_only: true,
            ..Default::default()
        };
        (p, vec![[1, 2, 0], [3, 4, 5]], options)
    }

    #[test]
    fn welded_vertices_keep_first_appearance_order_and_store_plus_zero() {
        let (p, t, options) = square_with_minus_zero();
        let (p2, t2, r) = run(p.clone(), t.clone(), options);
        let bits = |v: &[Vec3]| -> Vec<[u32; 3]> {
            v.iter().map(|x| x.to_array().map(f32::to_bits)).collect()
        };
        let expected = [p[0], Vec3::ZERO, p[2], p[5]];
        assert_eq!(bits(&p2), bits(&expected), "−0 is stored as +0");
        assert_eq!(t2, vec![[1, 2, 0], [1, 0, 3]]);
        assert_eq!(r.corners_welded, 2);
        // Without welding the positions stay as written, −0 included.
        let off = RepairOptions {
            weld: false,
            ..options
        };
        let (p3, t3, r) = run(p.clone(), t.clone(), off);
        assert_eq!(bits(&p3), bits(&p));
        assert_eq!(p3[1].x.to_bits(), 0x8000_0000);
        assert_eq!((t3, r.corners_welded), (t, 0));
    }

    #[test]
    fn identical_welds_can_go_uncounted() {
        let (p, t, options) = square_with_minus_zero();
        let shared = RepairOptions {
            count_identical_welds: false,
            ..options
        };
        let counted = run(p.clone(), t.clone(), options);
        let uncounted = run(p, t, shared);
        assert_eq!((counted.0, counted.1), (uncounted.0, uncounted.1));
        assert_eq!(
            (counted.2.corners_welded, uncounted.2.corners_welded),
            (2, 0)
        );
        // Welds within the tolerance still count: the STL cube with one corner of 28 welded
        // corners moved one f32 step, 27 of them identical.
        let (cp, ct) = cube();
        let (mut sp, st) = stl(&cp, &ct);
        let k = sp.iter().rposition(|v| *v == Vec3::ONE).unwrap();
        sp[k].x = f32::from_bits(1.0f32.to_bits() + 1);
        let near = RepairOptions {
            weld_tolerance: 1e-6,
            count_identical_welds: false,
            ..Default::default()
        };
        let (p2, _, r) = run(sp, st, near);
        assert_eq!((r.corners_welded, p2.len()), (1, 8));
    }

    #[test]
    fn welding_off_keeps_every_triangle_apart() {
        let (p, t) = cube();
        let (sp, st) = stl(&p, &t);
        let off = RepairOptions {
            weld: false,
            ..Default::default()
        };
        let (p2, t2, r) = run(sp.clone(), st.clone(), off);
        assert_eq!(r.corners_welded, 0);
        assert_eq!(r.boundary_edges, 36);
        // Each lone triangle's hole is capped by its reverse: 12 flat closed parts.
        assert_eq!((r.holes_closed, r.cap_triangles), (12, 12));
        assert_eq!((p2.len(), t2.len()), (36, 24));
        let refuse = RepairOptions {
            open: Some(OpenTreatment::Refuse),
            ..off
        };
        assert!(repair(sp, st, &refuse)
            .unwrap_err()
            .starts_with("open mesh: "));
    }

    #[test]
    fn receiver_only_meshes_are_welded_and_cleaned_but_stay_open() {
        let (p, t) = open_box();
        let (sp, st) = stl(&p, &t);
        let options = RepairOptions {
            receiver_only: true,
            ..Default::default()
        };
        let (p2, t2, r) = run(sp, st, options);
        assert_eq!((p2.len(), t2.len(), r.corners_welded), (p.len(), 10, 22));
        assert_eq!(r.boundary_edges, 0, "not looked for");
        assert_eq!(r.became, "receiver only (may stay open)");
    }

    #[test]
    fn bad_input_is_an_error() {
        let e = repair(vec![Vec3::ZERO; 3], vec![[0, 1, 3]], &Default::default()).unwrap_err();
        assert_eq!(
            e,
            "triangle 0 refers to vertex 3 but the mesh has 3 vertices"
        );
        let e = repair(vec![Vec3::NAN; 3], vec![[0, 1, 2]], &Default::default()).unwrap_err();
        assert_eq!(e, "vertex 0 is not finite: (NaN, NaN, NaN)");
        let e = repair(vec![Vec3::ZERO; 3], vec![[0, 1, 2]], &Default::default()).unwrap_err();
        assert_eq!(e, "no triangle is left after dropping degenerate ones");
    }

    /// Every built-in mesh is closed already: repair returns its positions (bit for bit) and
    /// triangles in the same order, and reports nothing.
    #[test]
    fn built_in_meshes_are_unchanged() {
        for name in crate::scene::builtin::names() {
            let scene = crate::scene::builtin::load(name).unwrap();
            for m in &scene.meshes {
                let options = RepairOptions {
                    receiver_only: m.receiver_only,
                    ..Default::default()
                };
                let (p, t, r) = run(m.positions.clone(), m.triangles.clone(), options);
                let bits = |v: &[Vec3]| -> Vec<[u32; 3]> {
                    v.iter().map(|x| x.to_array().map(f32::to_bits)).collect()
                };
                assert_eq!(bits(&p), bits(&m.positions), "{name}: {}", m.name);
                assert_eq!(t, m.triangles, "{name}: {}", m.name);
                assert_eq!(r.summary(), None, "{name}: {}: {r:?}", m.name);
            }
        }
    }
}
