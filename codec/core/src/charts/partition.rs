//! Cutting a mesh into charts: spatially compact groups of faces whose fine
//! layers decode independently.
//!
//! Faces are sorted along the Morton curve of their centroids and cut into
//! equal runs; each chart is then regrown breadth first from the face
//! nearest its centroid, which shortens the ragged borders of Morton runs
//! (the cut is what charts cost most), the smallest chart so far claiming
//! next, which keeps the charts equal (the largest sets how long a pool of
//! decoders takes). A chart must be a manifold on its own, so a vertex where one
//! chart's faces meet in two separate fans (a bow tie, common where a Morton
//! run brushes itself) is mended by handing the smaller fan to the chart
//! next to it, until no vertex has one.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

use crate::halfedge::{face, Connectivity, NONE};
use crate::{Error, Result};

/// Rounds of bow-tie mending before giving up on a cut.
const MENDING_ROUNDS: usize = 32;

/// Faces a chart claims in one turn while the charts regrow.
const GROWTH_STEP: usize = 64;

/// A chart label for every face of `conn`, `charts` runs of the Morton curve
/// (fewer when the mesh has fewer faces), every chart a manifold.
pub(crate) fn partition(
    conn: &Connectivity,
    positions: &[[i32; 3]],
    charts: usize,
) -> Result<Vec<u32>> {
    let faces = conn.face_count_slots();
    let charts = charts.clamp(1, faces.max(1));
    let mut keyed: Vec<(u64, u32)> = (0..faces as u32)
        .map(|f| {
            let mut c = [0i64; 3];
            for k in 0..3 {
                let p = positions[conn.origin[3 * f as usize + k] as usize];
                for (axis, value) in c.iter_mut().enumerate() {
                    *value += i64::from(p[axis]);
                }
            }
            (morton(c.map(|v| (v / 3) as u32)), f)
        })
        .collect();
    keyed.sort_unstable();
    let mut labels = vec![0u32; faces];
    for (i, &(_, f)) in keyed.iter().enumerate() {
        labels[f as usize] = (i * charts / faces) as u32;
    }
    drop(keyed);
    grow_from_centres(conn, positions, &mut labels, charts);
    for _ in 0..MENDING_ROUNDS {
        if !mend_bow_ties(conn, &mut labels) {
            return Ok(labels);
        }
    }
    Err(Error::Unsupported(format!(
        "could not cut the mesh into {charts} manifold charts"
    )))
}

/// Regrows the charts from one face each, the face nearest its chart's
/// centroid, breadth first across edges: Morton runs have ragged borders,
/// and every cut vertex is kept out of the fine layers, so shorter cuts
/// make smaller streams. The smallest chart grows next, [`GROWTH_STEP`]
/// faces at a time. A face no seed reaches (another component) keeps its
/// run's label.
fn grow_from_centres(
    conn: &Connectivity,
    positions: &[[i32; 3]],
    labels: &mut [u32],
    charts: usize,
) {
    let centroid = |f: usize| -> [f64; 3] {
        let mut c = [0.0; 3];
        for k in 0..3 {
            let p = positions[conn.origin[3 * f + k] as usize];
            for (sum, &v) in c.iter_mut().zip(&p) {
                *sum += f64::from(v) / 3.0;
            }
        }
        c
    };
    let mut sums = vec![([0.0f64; 3], 0usize); charts];
    for (f, &l) in labels.iter().enumerate() {
        let c = centroid(f);
        let s = &mut sums[l as usize];
        for (sum, v) in s.0.iter_mut().zip(c) {
            *sum += v;
        }
        s.1 += 1;
    }
    let mut seeds = vec![(f64::MAX, NONE); charts];
    for (f, &l) in labels.iter().enumerate() {
        let (sum, n) = sums[l as usize];
        let c = centroid(f);
        let d: f64 = (0..3).map(|a| (c[a] - sum[a] / n as f64).powi(2)).sum();
        if d < seeds[l as usize].0 {
            seeds[l as usize] = (d, f as u32);
        }
    }
    let mut grown = vec![NONE; labels.len()];
    // Each chart grows breadth first from its seed, and the chart with the
    // fewest faces so far claims the next ones, so the charts end about
    // equal: a chart's fine layers are one pool member's work, and the
    // largest chart sets when the level is done.
    let mut queues = vec![VecDeque::new(); charts];
    let mut sizes = vec![0usize; charts];
    let mut smallest = BinaryHeap::new();
    for (k, &(_, f)) in seeds.iter().enumerate() {
        if f != NONE {
            grown[f as usize] = k as u32;
            queues[k].push_back(f);
            sizes[k] = 1;
            smallest.push(Reverse((1, k)));
        }
    }
    while let Some(Reverse((_, k))) = smallest.pop() {
        let claimed = sizes[k];
        while sizes[k] < claimed + GROWTH_STEP {
            let Some(f) = queues[k].pop_front() else {
                break;
            };
            for h in 3 * f..3 * f + 3 {
                let t = conn.twin[h as usize];
                if t != NONE && grown[face(t) as usize] == NONE {
                    grown[face(t) as usize] = k as u32;
                    queues[k].push_back(face(t));
                    sizes[k] += 1;
                }
            }
        }
        if !queues[k].is_empty() {
            smallest.push(Reverse((sizes[k], k)));
        }
    }
    for (l, g) in labels.iter_mut().zip(grown) {
        if g != NONE {
            *l = g;
        }
    }
}

/// Hands the smaller fan of every bow tie to its neighbouring chart; whether
/// any was found.
fn mend_bow_ties(conn: &Connectivity, labels: &mut [u32]) -> bool {
    // A face starts a run of its chart around vertex v when the face before
    // it (clockwise, across its edge leaving v) is missing or in another chart.
    let label_of = |h: u32| labels[face(h) as usize];
    let mut starts: Vec<(u32, u32, u32)> = Vec::new();
    for h in 0..conn.origin.len() as u32 {
        if !conn.face_alive(face(h)) {
            continue;
        }
        let before = conn.twin[h as usize];
        if before == NONE || label_of(before) != label_of(h) {
            starts.push((conn.origin[h as usize], label_of(h), h));
        }
    }
    starts.sort_unstable();
    let mut found = false;
    let mut mended = None;
    let mut i = 0;
    while i < starts.len() {
        let (v, k, _) = starts[i];
        let mut j = i;
        while j < starts.len() && starts[j].0 == v && starts[j].1 == k {
            j += 1;
        }
        // One chart's runs per vertex and round: mending two charts that
        // alternate around a vertex at once would only swap them.
        if j - i > 1 && mended != Some(v) {
            mended = Some(v);
            found = true;
            // Every run of chart k around v but the longest goes to the chart before it.
            let runs: Vec<Vec<u32>> = starts[i..j]
                .iter()
                .map(|&(_, _, h)| run_from(conn, labels, h))
                .collect();
            let longest = (0..runs.len()).max_by_key(|&r| runs[r].len()).unwrap_or(0);
            for (r, run) in runs.iter().enumerate() {
                if r == longest {
                    continue;
                }
                let before = conn.twin[starts[i + r].2 as usize];
                let after = conn.rotate_ccw(*run.last().unwrap_or(&starts[i + r].2));
                let to = [before, after]
                    .into_iter()
                    .find(|&g| g != NONE && labels[face(g) as usize] != k)
                    .map(|g| labels[face(g) as usize]);
                if let Some(to) = to {
                    for &h in run {
                        labels[face(h) as usize] = to;
                    }
                }
            }
        }
        i = j;
    }
    found
}

/// The outgoing half-edges of one run of a chart around a vertex,
/// counter-clockwise from the run's first face.
fn run_from(conn: &Connectivity, labels: &[u32], start: u32) -> Vec<u32> {
    let k = labels[face(start) as usize];
    let mut run = vec![start];
    let mut h = conn.rotate_ccw(start);
    while h != NONE && h != start && labels[face(h) as usize] == k {
        run.push(h);
        h = conn.rotate_ccw(h);
    }
    run
}

/// Interleaves the low 21 bits of each coordinate into a 63-bit Morton key.
/// Four shifts and masks per axis: not worth a dependency.
fn morton(p: [u32; 3]) -> u64 {
    fn spread(x: u32) -> u64 {
        let mut x = u64::from(x) & 0x1f_ffff;
        x = (x | x << 32) & 0x1f_0000_0000_ffff;
        x = (x | x << 16) & 0x1f_0000_ff00_00ff;
        x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
        x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
        x = (x | x << 2) & 0x1249_2492_4924_9249;
        x
    }
    spread(p[0]) | spread(p[1]) << 1 | spread(p[2]) << 2
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest chart's faces over an equal share, for `charts` charts.
    fn imbalance(mesh: &crate::IndexedMesh, charts: usize) -> f64 {
        let conn = Connectivity::from_triangles(mesh.positions.len(), &mesh.triangles).unwrap();
        let quantized: Vec<[i32; 3]> = mesh
            .positions
            .iter()
            .map(|p| p.map(|x| ((x + 4.0) * 1000.0) as i32))
            .collect();
        let labels = partition(&conn, &quantized, charts).unwrap();
        let mut sizes = vec![0usize; charts];
        for &l in &labels {
            sizes[l as usize] += 1;
        }
        let most = *sizes.iter().max().unwrap();
        most as f64 * charts as f64 / labels.len() as f64
    }

    #[test]
    fn charts_come_out_about_equal() {
        use crate::samples::{grid, icosphere, torus};
        // A chart's fine layers are one decoding member's work: the largest
        // chart sets the pace. Regrown by hop count alone, the largest took
        // up to 1.52 shares here (9 of these 12 cases over 1.10; igea's
        // largest of 4 charts ended with 1.19 shares of the final vertices);
        // grown smallest chart first, at most 1.08.
        for (name, mesh) in [
            ("grid", grid(100)),
            ("torus", torus(120, 60, 1.0, 0.3)),
            ("icosphere", icosphere(5)),
        ] {
            for charts in [2, 3, 4, 8] {
                let ratio = imbalance(&mesh, charts);
                assert!(
                    ratio < 1.10,
                    "{name}, {charts} charts: largest {ratio:.3} of a share"
                );
            }
        }
    }

    #[test]
    fn morton_interleaves_bits() {
        assert_eq!(morton([1, 0, 0]), 1);
        assert_eq!(morton([0, 1, 0]), 2);
        assert_eq!(morton([0, 0, 1]), 4);
        assert_eq!(morton([3, 0, 0]), 0b1001);
        assert_eq!(morton([1 << 20, 0, 0]), 1 << 60);
    }
}
