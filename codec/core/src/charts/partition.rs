//! Cutting a mesh into charts: spatially compact groups of faces whose fine
//! layers decode independently.
//!
//! Faces are sorted along the Morton curve of their centroids and cut into
//! equal runs. A chart must be a manifold on its own, so a vertex where one
//! chart's faces meet in two separate fans (a bow tie, common where a Morton
//! run brushes itself) is mended by handing the smaller fan to the chart
//! next to it, until no vertex has one.

use crate::halfedge::{face, Connectivity, NONE};
use crate::{Error, Result};

/// Rounds of bow-tie mending before giving up on a cut.
const MENDING_ROUNDS: usize = 32;

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
    for _ in 0..MENDING_ROUNDS {
        if !mend_bow_ties(conn, &mut labels) {
            return Ok(labels);
        }
    }
    Err(Error::Unsupported(format!(
        "could not cut the mesh into {charts} manifold charts"
    )))
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

    #[test]
    fn morton_interleaves_bits() {
        assert_eq!(morton([1, 0, 0]), 1);
        assert_eq!(morton([0, 1, 0]), 2);
        assert_eq!(morton([0, 0, 1]), 4);
        assert_eq!(morton([3, 0, 0]), 0b1001);
        assert_eq!(morton([1 << 20, 0, 0]), 1 << 60);
    }
}
