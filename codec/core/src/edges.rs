//! Half-edges grouped by undirected edge, for pairing twins
//! (the codec's half-edge structure) and for repairing meshes (`vitrine-mesh`'s
//! `repair`).
//!
//! Half-edge `3f + k` runs from corner `k` of face `f` to corner `k + 1`.
//! They are bucketed by their edge's lower vertex with a counting sort (two
//! streaming passes; a hash map or a global sort by edge key costs a cache
//! miss or several passes per half-edge on multi-million-vertex scans), then
//! each bucket, a handful of half-edges, is sorted by the upper vertex. Each
//! entry carries that upper vertex beside its half-edge (`upper << 32 | h`),
//! so sorting and splitting a bucket read no face. Keys are unique and
//! half-edges ascend with their faces, so edges come in (lower, upper) order
//! and each edge's half-edges in face order: what depends on that order,
//! such as which edge an error names, is the same on any machine.

use std::convert::Infallible;

const NEXT: [usize; 3] = [1, 2, 0];

pub struct Edges {
    offsets: Vec<u32>,
    items: Vec<u64>,
}

impl Edges {
    /// Groups the half-edges of `tris`, whose corners are below `nv`, and
    /// whose half-edges number fewer than 2³².
    pub fn build(tris: &[[u32; 3]], nv: usize) -> Edges {
        let mut offsets = vec![0u32; nv + 1];
        for t in tris {
            for k in 0..3 {
                offsets[t[k].min(t[NEXT[k]]) as usize + 1] += 1;
            }
        }
        for v in 0..nv {
            offsets[v + 1] += offsets[v];
        }
        let mut cursor = offsets.clone();
        let mut items = vec![0u64; tris.len() * 3];
        for (f, t) in tris.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[NEXT[k]]);
                let lower = a.min(b) as usize;
                items[cursor[lower] as usize] = (a.max(b) as u64) << 32 | (3 * f + k) as u64;
                cursor[lower] += 1;
            }
        }
        drop(cursor);
        for v in 0..nv {
            let bucket = &mut items[offsets[v] as usize..offsets[v + 1] as usize];
            if bucket.len() > 1 {
                bucket.sort_unstable();
            }
        }
        Edges { offsets, items }
    }

    /// Calls `f` with the half-edges of every undirected edge until it
    /// returns an error.
    pub fn try_for_each<E>(&self, mut f: impl FnMut(&[u32]) -> Result<(), E>) -> Result<(), E> {
        let mut edge: Vec<u32> = Vec::new();
        for w in self.offsets.windows(2) {
            let bucket = &self.items[w[0] as usize..w[1] as usize];
            for run in bucket.chunk_by(|a, b| a >> 32 == b >> 32) {
                edge.clear();
                edge.extend(run.iter().map(|&item| item as u32));
                f(&edge)?;
            }
        }
        Ok(())
    }

    /// Calls `f` with the half-edges of every undirected edge.
    pub fn for_each(&self, mut f: impl FnMut(&[u32])) {
        let all = self.try_for_each(|edge| {
            f(edge);
            Ok::<(), Infallible>(())
        });
        match all {
            Ok(()) => {}
            Err(never) => match never {},
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edges_come_in_order_with_their_half_edges_in_face_order() {
        // Two triangles sharing edge 1–2, and a third face on it.
        let tris = [[0, 1, 2], [2, 1, 3], [1, 2, 4]];
        let mut seen = Vec::new();
        Edges::build(&tris, 5).for_each(|edge| seen.push(edge.to_vec()));
        // Lower vertex 0: edges 0–1 (h0), 0–2 (h2); 1: 1–2 (h1, h3, h6), 1–3 (h4), 1–4 (h8); 2: 2–3 (h5), 2–4 (h7).
        assert_eq!(
            seen,
            vec![
                vec![0],
                vec![2],
                vec![1, 3, 6],
                vec![4],
                vec![8],
                vec![5],
                vec![7]
            ]
        );
        let mut visited = 0;
        let stopped = Edges::build(&tris, 5).try_for_each(|edge| {
            visited += 1;
            if edge.len() > 2 {
                Err(edge.to_vec())
            } else {
                Ok(())
            }
        });
        assert_eq!(stopped, Err(vec![1, 3, 6]));
        assert_eq!(visited, 3);
    }
}
