//! Arbitrary triangle soup → `repair::prepare`; when that succeeds the mesh
//! must be a manifold that encodes, decodes to a manifold at every level,
//! and comes back exactly (at its quantization).
#![no_main]

use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use vitrine_mesh::repair::{check_manifold, prepare, RepairOptions};
use vitrine_codec::{
    encode, BaseTarget, Decoder, EncodeOptions, IndexedMesh, Limits, Quantization, StreamIndex,
};
use vitrine_codec_fuzz::assert_edge_manifold;

#[derive(Arbitrary, Debug)]
struct Soup {
    /// Coordinates on a coarse grid, so that welding has work to do.
    positions: Vec<[u8; 3]>,
    triangles: Vec<[u16; 3]>,
    colour: bool,
    weld: bool,
    bits: u8,
    base: u8,
    guard: bool,
}

fn canonical(t: [u32; 3]) -> [u32; 3] {
    let i = (0..3).min_by_key(|&i| t[i]).unwrap();
    [t[i], t[(i + 1) % 3], t[(i + 2) % 3]]
}

fuzz_target!(|soup: Soup| {
    let nv = soup.positions.len();
    if nv == 0 || nv > 4096 || soup.triangles.len() > 8192 {
        return;
    }
    let mesh = IndexedMesh {
        positions: soup
            .positions
            .iter()
            .map(|p| p.map(|c| c as f32 / 16.0))
            .collect(),
        colors: soup
            .colour
            .then(|| soup.positions.iter().map(|p| [p[1], p[2], p[0]]).collect()),
        triangles: soup
            .triangles
            .iter()
            .map(|t| t.map(|v| (v as usize % nv) as u32))
            .collect(),
    };
    let opts = RepairOptions {
        weld: soup.weld,
        split_non_manifold: true,
    };
    let Ok((mesh, _report)) = prepare(mesh, &opts) else {
        return;
    };
    if let Err(e) = check_manifold(&mesh) {
        panic!("prepare returned a mesh check_manifold refuses: {e}");
    }

    let options = EncodeOptions {
        quantization_bits: 8 + soup.bits % 9,
        base: BaseTarget::Vertices(soup.base as u32 % 64),
        min_base_vertices: 4,
        geometric_guard: soup.guard,
        ..Default::default()
    };
    let encoded = match encode(&mesh, &options) {
        Ok(e) => e,
        Err(e) => panic!("a prepared mesh does not encode: {e}"),
    };
    let bytes = &encoded.bytes;
    let index = StreamIndex::parse(bytes).expect("own stream parses");
    let mut d =
        Decoder::new(&bytes[index.base.clone()], Limits::default()).expect("own base decodes");
    assert_edge_manifold(d.indices());
    for (k, range) in index.batches.iter().enumerate() {
        if let Err(e) = d.apply_batch(&bytes[range.clone()]) {
            panic!("own batch {} fails: {e}", k + 1);
        }
        assert_edge_manifold(d.indices());
        assert_eq!(d.face_count(), index.header.levels[k + 1].faces as usize);
    }
    assert!(d.is_complete());

    let q = Quantization::for_positions(&mesh.positions, options.quantization_bits).unwrap();
    let order = &encoded.vertex_order;
    assert_eq!(order.len(), mesh.positions.len());
    for (i, &v) in order.iter().enumerate() {
        assert_eq!(
            d.quantized_positions()[i],
            q.quantize(mesh.positions[v as usize]),
            "vertex {i}"
        );
    }
    let mut expected: Vec<_> = mesh.triangles.iter().map(|&t| canonical(t)).collect();
    let mut got: Vec<_> = d
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
    assert_eq!(got, expected, "same triangles, same orientation");
    if let Some(colours) = &mesh.colors {
        let decoded = d.colours().expect("stream keeps colour");
        for (i, &v) in order.iter().enumerate() {
            assert_eq!(
                &decoded[3 * i..3 * i + 3],
                &colours[v as usize],
                "colour {i}"
            );
        }
    }
});
