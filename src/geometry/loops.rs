//! Splitting silhouette edges into closed loops (Paper V: the degree of a silhouette vertex is
//! always even — 2, 4, 6 and 8 occur — so loops are found by following edge orientation).
//!
//! Every oriented silhouette edge a→b is continued by an unused edge starting at b. At a vertex
//! of degree > 2 there are several candidates; Paper V does not say which to take. We take the
//! unused outgoing edge with the smallest index (deterministic, independent of hashing order).
//! Because in-degree equals out-degree at every vertex, the walk always returns to its start.

use super::silhouette::SilhouetteEdge;
use std::collections::BTreeMap;

/// Closed loops of silhouette edges, as lists of indices into `edges`, in walk order.
/// Returns `Err` naming a vertex whose in-degree differs from its out-degree (an inconsistent
/// silhouette, which cannot happen for facing computed once per triangle on a closed mesh).
pub fn silhouette_loops(edges: &[SilhouetteEdge]) -> Result<Vec<Vec<usize>>, String> {
    let mut outgoing: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
    let mut balance: BTreeMap<u32, i64> = BTreeMap::new();
    for (k, e) in edges.iter().enumerate() {
        outgoing.entry(e.va).or_default().push(k);
        *balance.entry(e.va).or_default() += 1;
        *balance.entry(e.vb).or_default() -= 1;
    }
    if let Some((v, b)) = balance.iter().find(|(_, b)| **b != 0) {
        return Err(format!(
            "silhouette vertex {v} has in/out degree imbalance {b}"
        ));
    }
    let mut used = vec![false; edges.len()];
    let mut loops = Vec::new();
    for start in 0..edges.len() {
        if used[start] {
            continue;
        }
        let mut lp = vec![start];
        used[start] = true;
        let mut at = edges[start].vb;
        while at != edges[start].va {
            let next = outgoing[&at].iter().copied().find(|&k| !used[k]);
            match next {
                Some(k) => {
                    used[k] = true;
                    lp.push(k);
                    at = edges[k].vb;
                }
                None => return Err(format!("silhouette walk stuck at vertex {at}")),
            }
        }
        loops.push(lp);
    }
    Ok(loops)
}

/// Degree (number of silhouette edges touching it) of every silhouette vertex, by vertex index.
pub fn vertex_degrees(edges: &[SilhouetteEdge]) -> BTreeMap<u32, u32> {
    let mut d = BTreeMap::new();
    for e in edges {
        *d.entry(e.va).or_default() += 1;
        *d.entry(e.vb).or_default() += 1;
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn e(va: u32, vb: u32) -> SilhouetteEdge {
        SilhouetteEdge {
            edge: 0,
            va,
            vb,
            a: Vec3::ZERO,
            b: Vec3::ZERO,
        }
    }

    #[test]
    fn simple_loop() {
        let l = silhouette_loops(&[e(0, 1), e(1, 2), e(2, 0)]).unwrap();
        assert_eq!(l, vec![vec![0, 1, 2]]);
    }

    #[test]
    fn degree_four_vertex_gives_two_loops() {
        // Figure-eight through vertex 0: 0→1→2→0 and 0→3→4→0.
        let edges = [e(0, 1), e(1, 2), e(2, 0), e(0, 3), e(3, 4), e(4, 0)];
        let l = silhouette_loops(&edges).unwrap();
        let total: usize = l.iter().map(|x| x.len()).sum();
        assert_eq!(total, 6);
        assert_eq!(vertex_degrees(&edges)[&0], 4);
        for lp in &l {
            assert_eq!(edges[lp[0]].va, edges[*lp.last().unwrap()].vb);
        }
    }

    #[test]
    fn imbalance_is_reported() {
        assert!(silhouette_loops(&[e(0, 1), e(1, 2)]).is_err());
    }
}
