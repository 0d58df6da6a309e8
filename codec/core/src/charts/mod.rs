//! Chart-parallel streams (format 5).
//!
//! The encoder cuts the mesh into charts ([`partition`]) and runs the fine
//! layers inside each chart, with the chart's cut edges as borders (AD01
//! never removes a border vertex, so cut vertices stay until the charts have
//! thinned out). What the charts leave is simplified by ordinary global
//! layers down to the base mesh. A decoder applies the base and the global
//! batches as in format 4, then cuts the level they make into the same
//! charts (the labels travel in the first parted batch) and decodes each
//! chart's part of every later batch on its own: on as many threads as it
//! has, and to the same bytes whatever the number.
//!
//! Both sides agree on the charts' vertex numbering through the level where
//! charts begin: its faces in canonical order ([`canonical_faces`]), each
//! chart's vertices in order of first appearance there ([`cut`]).

pub(crate) mod encode;
mod labels;
mod partition;

pub(crate) use labels::{decode_labels, encode_labels};

use crate::halfedge::NONE;

/// At most this many charts: a label is one symbol of a 64-symbol model.
pub const MAX_CHARTS: usize = 64;

/// A face rotated so its smallest vertex id comes first (orientation kept).
fn canonical(t: [u32; 3]) -> [u32; 3] {
    let i = if t[0] <= t[1] && t[0] <= t[2] {
        0
    } else if t[1] <= t[2] {
        1
    } else {
        2
    };
    [t[i], t[(i + 1) % 3], t[(i + 2) % 3]]
}

/// The faces of the level where charts begin in the order both sides label
/// them, with `tag` (a label, or the face's index elsewhere) carried along:
/// each face rotated to its smallest vertex, then sorted.
pub(crate) fn canonical_faces(
    triangles: impl Iterator<Item = [u32; 3]>,
    tags: impl Iterator<Item = u32>,
) -> (Vec<[u32; 3]>, Vec<u32>) {
    let mut faces: Vec<([u32; 3], u32)> = triangles.map(canonical).zip(tags).collect();
    faces.sort_unstable();
    faces.into_iter().unzip()
}

/// One chart cut out of the level where charts begin.
#[derive(Debug, Default, PartialEq)]
pub(crate) struct Cut {
    /// The level's id of each chart vertex, by first appearance.
    pub global: Vec<u32>,
    /// The chart's faces in chart ids, in canonical order.
    pub triangles: Vec<[u32; 3]>,
}

/// Cuts `faces` (canonical order, ids below `vertex_count`) into `charts`
/// charts by their `labels` (each below `charts`).
pub(crate) fn cut(
    faces: &[[u32; 3]],
    labels: &[u32],
    charts: usize,
    vertex_count: usize,
) -> Vec<Cut> {
    let mut cuts: Vec<Cut> = (0..charts).map(|_| Cut::default()).collect();
    let mut local = vec![NONE; vertex_count];
    // Charts in turn, so `local` serves each and is cleared after it.
    let mut by_chart: Vec<Vec<u32>> = vec![Vec::new(); charts];
    for (f, &label) in labels.iter().enumerate() {
        by_chart[label as usize].push(f as u32);
    }
    for (chart, faces_of) in cuts.iter_mut().zip(&by_chart) {
        chart.triangles.reserve(faces_of.len());
        for &f in faces_of {
            let t = faces[f as usize].map(|v| {
                let slot = &mut local[v as usize];
                if *slot == NONE {
                    *slot = chart.global.len() as u32;
                    chart.global.push(v);
                }
                *slot
            });
            chart.triangles.push(t);
        }
        for &v in &chart.global {
            local[v as usize] = NONE;
        }
    }
    cuts
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn canonical_keeps_orientation() {
        assert_eq!(canonical([5, 2, 9]), [2, 9, 5]);
        assert_eq!(canonical([9, 5, 2]), [2, 9, 5]);
        assert_eq!(canonical([2, 9, 5]), [2, 9, 5]);
    }

    #[test]
    fn cut_numbers_each_chart_by_first_appearance() {
        // Two quads sharing the edge 1–4: chart 0 the left, chart 1 the right.
        let faces = [[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]];
        let (faces, labels) = canonical_faces(faces.into_iter(), [0, 0, 1, 1].into_iter());
        let cuts = cut(&faces, &labels, 2, 6);
        assert_eq!(cuts[0].global, vec![0, 1, 4, 3]);
        assert_eq!(cuts[0].triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(cuts[1].global, vec![1, 2, 5, 4]);
        assert_eq!(cuts[1].triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }
}
