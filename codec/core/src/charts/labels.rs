//! Chart labels of the level where charts begin, one per face in canonical
//! order, range-coded with the label of a neighbouring face already coded
//! as context: a chart is a connected patch, so a face's label is its
//! neighbour's everywhere but along the cut.

use crate::entropy::{RangeDecoder, RangeEncoder, SymbolModel};
use crate::halfedge::{face, Connectivity, NONE};
use crate::{Error, Result};

/// One model per context label.
fn models(charts: usize) -> Vec<SymbolModel> {
    (0..charts).map(|_| SymbolModel::new(charts)).collect()
}

/// The context of face `f`: the label of its first neighbour (across its
/// edges in order) labelled already, else the previous face's (else 0).
fn context(conn: &Connectivity, labels: &[u32], f: usize) -> usize {
    (0..3)
        .map(|k| conn.twin[3 * f + k])
        .filter(|&t| t != NONE)
        .map(|t| labels[face(t) as usize])
        .find(|&l| l != NONE)
        .or_else(|| f.checked_sub(1).map(|p| labels[p]))
        .map_or(0, |l| l as usize)
}

fn adjacency(faces: &[[u32; 3]], vertex_count: usize) -> Result<Connectivity> {
    Connectivity::from_triangles(vertex_count, faces)
        .map_err(|e| Error::stream(format!("the level where charts begin: {e}")))
}

/// `faces` in canonical order (a manifold on `vertex_count` vertices),
/// `labels` each below `charts` (2..=64).
pub(crate) fn encode_labels(
    faces: &[[u32; 3]],
    vertex_count: usize,
    labels: &[u32],
    charts: usize,
) -> Result<Vec<u8>> {
    let conn = adjacency(faces, vertex_count)?;
    let mut models = models(charts);
    let mut coder = RangeEncoder::with_capacity(labels.len() / 16 + 16);
    let mut known = vec![NONE; labels.len()];
    for (f, &label) in labels.iter().enumerate() {
        let c = context(&conn, &known, f);
        coder.encode_symbol(&mut models[c], label as usize);
        known[f] = label;
    }
    Ok(coder.finish())
}

/// The labels of the faces of `adjacency` (the level where charts begin,
/// in canonical order: [`super::canonical_level`]).
pub(crate) fn decode_labels(
    bytes: &[u8],
    adjacency: &Connectivity,
    charts: usize,
) -> Result<Vec<u32>> {
    if !(2..=super::MAX_CHARTS).contains(&charts) {
        return Err(Error::stream(format!("{charts} charts is out of range")));
    }
    let mut models = models(charts);
    let mut coder = RangeDecoder::new(bytes);
    let faces = adjacency.origin.len() / 3;
    let mut labels = vec![NONE; faces];
    for f in 0..faces {
        let c = context(adjacency, &labels, f);
        labels[f] = coder.decode_symbol(&mut models[c]) as u32;
    }
    coder.check_overrun()?;
    Ok(labels)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip of quads, `n` long, as canonical faces.
    fn strip(n: u32) -> Vec<[u32; 3]> {
        let mut faces = Vec::new();
        for i in 0..n {
            let (a, b, c, d) = (i, i + 1, n + 1 + i, n + 2 + i);
            faces.push([a, b, d]);
            faces.push([a, d, c]);
        }
        let vertices = 2 * n as usize + 2;
        let (faces, _) = super::super::canonical_faces(&faces, vertices, &vec![0; faces.len()]);
        faces
    }

    #[test]
    fn labels_round_trip_and_patches_cost_little() {
        let n = 5000;
        let faces = strip(n);
        // Seven patches along the strip.
        let labels: Vec<u32> = faces.iter().map(|t| (t[0] * 7 / (n + 1)).min(6)).collect();
        let bytes = encode_labels(&faces, 2 * n as usize + 2, &labels, 7).unwrap();
        assert!(bytes.len() < 200, "{} bytes for 7 patches", bytes.len());
        let conn = adjacency(&faces, 2 * n as usize + 2).unwrap();
        let decoded = decode_labels(&bytes, &conn, 7).unwrap();
        assert_eq!(decoded, labels);
        // Truncated: an overrun, never a panic.
        assert!(decode_labels(&bytes[..bytes.len() / 2], &conn, 7).is_err());
        assert!(decode_labels(&bytes, &conn, 65).is_err());
    }
}
