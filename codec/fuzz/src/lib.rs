//! Shared by the fuzz targets: budgets, sample streams and the invariants a
//! successful result must satisfy.

use std::sync::OnceLock;

use vitrine_mesh::import::ImportOptions;
use vitrine_samples::{icosphere, paint, torus};
use vitrine_codec::{encode, BatchChunk, Decoder, EncodeOptions, IndexedMesh, Limits, StreamIndex};

/// Small budgets, so that a hostile input that is merely big is refused
/// quickly and the fuzzer spends its time on malformed ones.
pub const LIMITS: Limits = Limits {
    max_vertices: 1 << 16,
    max_faces: 1 << 17,
    max_batches: 64,
};

pub fn import_options() -> ImportOptions {
    ImportOptions {
        max_vertices: 1 << 16,
        max_faces: 1 << 17,
        ..ImportOptions::default()
    }
}

/// Generated meshes to build valid streams from: one without colour, one with.
pub fn sample_meshes() -> Vec<IndexedMesh> {
    let mut painted = torus(16, 8, 1.0, 0.4);
    paint(&mut painted);
    vec![icosphere(2), painted]
}

/// Encoded [`sample_meshes`], each with at least two batches.
pub fn sample_streams() -> &'static [Vec<u8>] {
    static S: OnceLock<Vec<Vec<u8>>> = OnceLock::new();
    S.get_or_init(|| {
        sample_meshes()
            .iter()
            .map(|m| {
                let options = EncodeOptions {
                    min_base_vertices: 8,
                    ..Default::default()
                };
                encode(m, &options).expect("sample mesh encodes").bytes
            })
            .collect()
    })
}

/// Panics unless batch 1 of every sample stream, its payload re-wrapped by
/// [`BatchChunk::with_payload`], is the same chunk and decodes: the
/// structured batch target would otherwise fuzz only the header parser.
/// Checked once per process.
pub fn wrapped_batches_decode() {
    static CHECKED: OnceLock<()> = OnceLock::new();
    CHECKED.get_or_init(|| {
        for stream in sample_streams() {
            let index = StreamIndex::parse(stream).expect("sample stream");
            let real = &stream[index.batches[0].clone()];
            let chunk = BatchChunk::parse(real).expect("sample batch");
            let wrapped = chunk.with_payload(chunk.payload).expect("small payload");
            assert_eq!(wrapped, real, "the chunk writer rebuilds the real chunk");
            let mut d = Decoder::new(&stream[index.base.clone()], LIMITS).expect("sample base");
            d.apply_batch(&wrapped).expect("an unmodified wrapped payload decodes");
        }
    });
}

/// What holds for any decoder that returned `Ok`, whatever its input.
pub fn check_decoder(d: &Decoder) {
    let n = d.vertex_count();
    assert_eq!(d.indices().len(), 3 * d.face_count());
    assert!(
        d.indices().iter().all(|&i| (i as usize) < n),
        "index out of range"
    );
    assert_eq!(d.positions().len(), 3 * n);
    assert_eq!(d.quantized_positions().len(), n);
    if let Some(c) = d.colours() {
        assert_eq!(c.len(), 3 * n);
    }
    assert!(n <= LIMITS.max_vertices as usize && d.face_count() <= LIMITS.max_faces as usize);
    assert_eq!(n, d.header().levels[d.level()].vertices as usize);
}

/// What holds for any mesh an importer returned.
pub fn check_import(m: &IndexedMesh) {
    let opts = import_options();
    let n = m.positions.len();
    assert!(n > 0 && !m.triangles.is_empty());
    assert!(n <= opts.max_vertices && m.triangles.len() <= opts.max_faces);
    assert!(m.positions.iter().flatten().all(|v| v.is_finite()));
    assert!(m.triangles.iter().flatten().all(|&i| (i as usize) < n));
    if let Some(c) = &m.colors {
        assert_eq!(c.len(), n);
    }
}

/// Each undirected edge on at most two faces, each half-edge on one.
pub fn assert_edge_manifold(indices: &[u32]) {
    let mut directed: Vec<(u32, u32)> = indices
        .chunks_exact(3)
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .collect();
    directed.sort_unstable();
    if let Some(w) = directed.windows(2).find(|w| w[0] == w[1]) {
        panic!("half-edge {:?} appears twice", w[0]);
    }
    let mut undirected: Vec<(u32, u32)> = directed
        .iter()
        .map(|&(a, b)| (a.min(b), a.max(b)))
        .collect();
    undirected.sort_unstable();
    if let Some(w) = undirected.windows(3).find(|w| w[0] == w[2]) {
        panic!("edge {:?} has more than two faces", w[0]);
    }
}
