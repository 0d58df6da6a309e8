//! Bit-exact round trips on generated meshes: every level decodes to a
//! manifold, and the final level is exactly the quantized input.

use vitrine_codec::{decode, encode, EncodeOptions, IndexedMesh, Limits, StreamIndex};
use vitrine_samples::{add_noise, icosphere, merge, paint, plate_with_tunnels, punch_holes, torus};

/// Encodes, decodes level by level, and compares the final level with the input.
fn assert_round_trip(mesh: &IndexedMesh, options: &EncodeOptions) -> usize {
    let encoded = encode(mesh, options).expect("encode");
    let again = encode(mesh, options).unwrap();
    assert_eq!(encoded.bytes, again.bytes, "encoding is deterministic");

    let index = StreamIndex::parse(&encoded.bytes).unwrap();
    let mut decoder =
        vitrine_codec::Decoder::new(&encoded.bytes[index.base.clone()], Limits::default()).unwrap();
    for (k, range) in index.batches.iter().enumerate() {
        decoder
            .apply_batch(&encoded.bytes[range.clone()])
            .unwrap_or_else(|e| panic!("batch {k}: {e}"));
        let level = index.header.levels[k + 1];
        assert_eq!(decoder.vertex_count(), level.vertices as usize);
        assert_eq!(decoder.face_count(), level.faces as usize);
    }
    assert!(decoder.is_complete());

    let order = &encoded.vertex_order;
    if let Some(diff) =
        vitrine_samples::final_level_mismatch(mesh, options.quantization_bits, &decoder, order)
    {
        panic!("final level differs from the quantized input: {diff}");
    }
    // A fresh decode of the whole stream gives the same buffers.
    let whole = decode(&encoded.bytes, None, Limits::default()).unwrap();
    assert_eq!(whole.indices(), decoder.indices());
    encoded.bytes.len()
}

fn layers(mesh: &IndexedMesh) -> usize {
    encode(mesh, &EncodeOptions::default())
        .unwrap()
        .header
        .batch_count()
}

#[test]
fn icosphere_round_trips() {
    let mesh = icosphere(5);
    assert_round_trip(&mesh, &EncodeOptions::default());
    assert!(
        layers(&mesh) >= 3,
        "a regular sphere decimates over several layers"
    );
}

#[test]
fn torus_round_trips() {
    assert_round_trip(&torus(120, 48, 1.0, 0.3), &EncodeOptions::default());
}

#[test]
fn genus_two_and_three_round_trip() {
    for genus in 2..=3 {
        assert_round_trip(&plate_with_tunnels(genus, 12), &EncodeOptions::default());
    }
}

#[test]
fn holes_round_trip() {
    let sphere = icosphere(4);
    let holed = punch_holes(
        &sphere,
        &[[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.3, 0.95]],
        0.35,
    );
    assert!(holed.triangles.len() < sphere.triangles.len());
    assert_round_trip(&holed, &EncodeOptions::default());
}

#[test]
fn several_components_round_trip() {
    let parts = [
        icosphere(3),
        torus(40, 16, 1.0, 0.4),
        icosphere(1),
        plate_with_tunnels(1, 6),
    ];
    assert_round_trip(&merge(&parts, 3.0), &EncodeOptions::default());
}

#[test]
fn noisy_coloured_surface_round_trips() {
    let mut mesh = torus(160, 60, 1.0, 0.35);
    add_noise(&mut mesh, 0.004, 9);
    paint(&mut mesh);
    assert_round_trip(&mesh, &EncodeOptions::default());
}

#[test]
fn every_quantization_round_trips() {
    let mut mesh = icosphere(3);
    add_noise(&mut mesh, 0.01, 3);
    for bits in [8, 10, 12, 14, 16] {
        let options = EncodeOptions {
            quantization_bits: bits,
            ..Default::default()
        };
        assert_round_trip(&mesh, &options);
    }
}

#[test]
fn geometric_guard_off_round_trips() {
    let mut mesh = plate_with_tunnels(2, 8);
    add_noise(&mut mesh, 0.02, 5);
    assert_round_trip(
        &mesh,
        &EncodeOptions {
            geometric_guard: false,
            ..Default::default()
        },
    );
}

/// Every real scan in `../shared/data/meshes` round-trips bit-exactly (skipped when absent).
#[test]
fn shared_meshes_round_trip() {
    use vitrine_mesh::import::{import_path, ImportOptions};
    use vitrine_mesh::repair::{prepare, RepairOptions};
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/meshes");
    if !dir.is_dir() {
        eprintln!("skipped: {} is absent", dir.display());
        return;
    }
    let mut files = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            for inner in std::fs::read_dir(&path).unwrap() {
                files.push(inner.unwrap().path());
            }
        } else {
            files.push(path);
        }
    }
    let mut tested = 0;
    for path in files {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        if !matches!(ext.as_str(), "ply" | "obj" | "off" | "gltf" | "glb") {
            continue;
        }
        let mesh = import_path(&path, &ImportOptions::default()).unwrap();
        let (mesh, _) = prepare(mesh, &RepairOptions::default()).unwrap();
        let bytes = assert_round_trip(&mesh, &EncodeOptions::default());
        eprintln!(
            "{}: {} vertices, {} bytes",
            path.display(),
            mesh.positions.len(),
            bytes
        );
        tested += 1;
    }
    assert!(tested >= 10, "expected the shared meshes, found {tested}");
}

/// A batch's payload re-wrapped by the public chunk writer is the same chunk,
/// byte for byte, and decodes (the batch fuzz target relies on it); a
/// different payload length is written into the header.
#[test]
fn batch_chunks_rewrap_to_the_same_bytes() {
    let mesh = torus(40, 16, 1.0, 0.3);
    let stream = encode(&mesh, &EncodeOptions::default()).unwrap().bytes;
    let index = StreamIndex::parse(&stream).unwrap();
    let mut d =
        vitrine_codec::Decoder::new(&stream[index.base.clone()], Limits::default()).unwrap();
    for range in &index.batches {
        let real = &stream[range.clone()];
        let chunk = vitrine_codec::BatchChunk::parse(real).unwrap();
        let wrapped = chunk.with_payload(chunk.payload).unwrap();
        assert_eq!(wrapped, real);
        d.apply_batch(&wrapped).unwrap();
    }
    assert_eq!(d.vertex_count(), mesh.positions.len());
    let first = vitrine_codec::BatchChunk::parse(&stream[index.batches[0].clone()]).unwrap();
    let longer = first.with_payload(&[0; 300]).unwrap();
    let parsed = vitrine_codec::BatchChunk::parse(&longer).unwrap();
    assert_eq!(parsed.payload, &[0; 300][..]);
    assert!(vitrine_codec::BatchChunk::parse(&longer[..longer.len() - 1]).is_err());
}

/// Guards compose: a patch is decimated only when every guard allows it, so
/// two guards give the bytes one guard testing both would give, and a guard
/// that allows everything changes nothing.
#[test]
fn guards_compose_as_a_conjunction() {
    use vitrine_codec::{CandidatePatch, Encoder, PatchGuard};
    /// Refuses the patches centred in one slab of x (quantized, 0–4095).
    struct Slab(i32, i32);
    impl PatchGuard for Slab {
        fn allows(&self, p: &CandidatePatch<'_>) -> bool {
            !(self.0..self.1).contains(&p.centre[0])
        }
    }
    struct Both;
    impl PatchGuard for Both {
        fn allows(&self, p: &CandidatePatch<'_>) -> bool {
            Slab(0, 1000).allows(p) && Slab(3000, 4096).allows(p)
        }
    }
    struct Anything;
    impl PatchGuard for Anything {
        fn allows(&self, _: &CandidatePatch<'_>) -> bool {
            true
        }
    }
    let mut mesh = torus(48, 16, 1.0, 0.3);
    add_noise(&mut mesh, 0.003, 5);
    let options = EncodeOptions::default();
    let bytes = |guards: &[&dyn PatchGuard]| {
        let mut encoder = Encoder::new(options.clone());
        for g in guards {
            encoder = encoder.guard(*g);
        }
        encoder.encode(&mesh).unwrap().bytes
    };
    let composed = bytes(&[&Slab(0, 1000), &Slab(3000, 4096)]);
    assert_eq!(composed, bytes(&[&Both]));
    assert_ne!(
        composed,
        bytes(&[&Slab(0, 1000)]),
        "the second guard refuses patches"
    );
    assert_ne!(
        composed,
        bytes(&[&Slab(3000, 4096)]),
        "the first guard refuses patches"
    );
    assert_eq!(
        bytes(&[&Anything, &Anything]),
        encode(&mesh, &options).unwrap().bytes
    );
    let d = decode(&composed, None, Limits::default()).unwrap();
    assert_eq!(d.vertex_count(), mesh.positions.len());
}
