//! Shared by the round-trip and property tests: the lossless check.

use vitrine_codec::{Decoder, IndexedMesh, Quantization};

fn canonical(t: [u32; 3]) -> [u32; 3] {
    let i = (0..3).min_by_key(|&i| t[i]).expect("three corners");
    [t[i], t[(i + 1) % 3], t[(i + 2) % 3]]
}

/// The first way the decoder's final level differs from the quantized input
/// (positions, oriented triangles up to the stream's renumbering, colours),
/// or `None` when it is exactly the input.
pub fn final_level_mismatch(
    mesh: &IndexedMesh,
    bits: u8,
    d: &Decoder,
    order: &[u32],
) -> Option<String> {
    if order.len() != mesh.positions.len() {
        return Some(format!(
            "{} vertices decoded, {} in the input",
            order.len(),
            mesh.positions.len()
        ));
    }
    let q = Quantization::for_positions(&mesh.positions, bits).expect("finite input");
    for (i, &v) in order.iter().enumerate() {
        if d.quantized_positions()[i] != q.quantize(mesh.positions[v as usize]) {
            return Some(format!("vertex {i}"));
        }
    }
    let mut expected: Vec<[u32; 3]> = mesh.triangles.iter().map(|&t| canonical(t)).collect();
    let mut got: Vec<[u32; 3]> = d
        .indices()
        .chunks_exact(3)
        .map(|t| {
            canonical([
                order[t[0] as usize],
                order[t[1] as usize],
                order[t[2] as usize],
            ])
        })
        .collect();
    expected.sort_unstable();
    got.sort_unstable();
    if got != expected {
        return Some("triangles differ (set or orientation)".into());
    }
    match (&mesh.colors, d.colours()) {
        (Some(colours), Some(decoded)) => {
            for (i, &v) in order.iter().enumerate() {
                if decoded[3 * i..3 * i + 3] != colours[v as usize] {
                    return Some(format!("colour {i}"));
                }
            }
            None
        }
        (None, None) => None,
        (Some(_), None) => Some("stream lost the colour".into()),
        (None, Some(_)) => Some("stream invented colour".into()),
    }
}
