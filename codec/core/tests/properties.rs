//! Property tests: random small meshes survive repair → encode → decode.
//!
//! Each case builds a mesh from a generated sphere, torus or plate with a
//! random subset of its faces removed (leaving holes, islands and pinched
//! vertices for repair to split), random noise, maybe random colours, a
//! random quantization and a random base target. After `repair::prepare`:
//! every level the decoder produces is a valid manifold, and the final level
//! is exactly the quantized repaired mesh.

use proptest::prelude::*;
use vitrine_codec::{encode, BaseTarget, Decoder, EncodeOptions, IndexedMesh, Limits, StreamIndex};
use vitrine_mesh::repair::{check_manifold, prepare, RepairOptions};
use vitrine_samples::{add_noise, compact, icosphere, plate_with_tunnels, torus};

#[derive(Clone, Debug)]
enum Shape {
    Sphere(u32),
    Torus(u32, u32),
    Plate(u32, u32),
}

#[derive(Clone, Debug)]
struct Case {
    shape: Shape,
    /// Out of 256: the chance that a face is dropped.
    drop: u32,
    seed: u64,
    noise: f32,
    colour: bool,
    bits: u8,
    base: BaseTarget,
    min_base: u32,
    guard: bool,
}

fn shape() -> impl Strategy<Value = Shape> {
    prop_oneof![
        (0u32..=3).prop_map(Shape::Sphere),
        (3u32..=40, 3u32..=16).prop_map(|(r, s)| Shape::Torus(r, s)),
        (1u32..=2, 1u32..=3).prop_map(|(g, c)| Shape::Plate(g, c)),
    ]
}

fn case() -> impl Strategy<Value = Case> {
    (
        shape(),
        prop_oneof![Just(0u32), 0u32..32, 32u32..128],
        any::<u64>(),
        prop_oneof![Just(0.0f32), 0.0f32..0.05],
        any::<bool>(),
        8u8..=16,
        prop_oneof![
            (4u32..200).prop_map(BaseTarget::Vertices),
            (0.0f32..0.5).prop_map(BaseTarget::Fraction)
        ],
        prop_oneof![Just(4u32), 4u32..64],
        any::<bool>(),
    )
        .prop_map(
            |(shape, drop, seed, noise, colour, bits, base, min_base, guard)| Case {
                shape,
                drop,
                seed,
                noise,
                colour,
                bits,
                base,
                min_base,
                guard,
            },
        )
}

fn next(state: &mut u64) -> u64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    *state >> 33
}

fn build(c: &Case) -> IndexedMesh {
    let mut mesh = match c.shape {
        Shape::Sphere(levels) => icosphere(levels),
        Shape::Torus(rings, sides) => torus(rings, sides, 1.0, 0.35),
        Shape::Plate(genus, cells) => plate_with_tunnels(genus, cells),
    };
    let mut state = c.seed;
    mesh.triangles
        .retain(|_| next(&mut state) % 256 >= c.drop as u64);
    let mut mesh = compact(mesh);
    add_noise(&mut mesh, c.noise, c.seed);
    if c.colour {
        mesh.colors = Some(
            (0..mesh.positions.len())
                .map(|_| {
                    let v = next(&mut state);
                    [v as u8, (v >> 8) as u8, (v >> 16) as u8]
                })
                .collect(),
        );
    }
    mesh
}

/// Each undirected edge on at most two faces, each half-edge on one.
fn edge_manifold(indices: &[u32]) -> Result<(), String> {
    let mut directed: Vec<(u32, u32)> = indices
        .chunks_exact(3)
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .collect();
    directed.sort_unstable();
    if let Some(w) = directed.windows(2).find(|w| w[0] == w[1]) {
        return Err(format!("half-edge {:?} appears twice", w[0]));
    }
    let mut undirected: Vec<(u32, u32)> = directed
        .iter()
        .map(|&(a, b)| (a.min(b), a.max(b)))
        .collect();
    undirected.sort_unstable();
    match undirected.windows(3).find(|w| w[0] == w[2]) {
        Some(w) => Err(format!("edge {:?} has more than two faces", w[0])),
        None => Ok(()),
    }
}

fn check(c: &Case) -> Result<(), TestCaseError> {
    let soup = build(c);
    prop_assume!(!soup.triangles.is_empty());
    let mesh = match prepare(soup, &RepairOptions::default()) {
        Ok((mesh, _)) => mesh,
        Err(e) => {
            prop_assert!(
                e.to_string().contains("no triangles left"),
                "prepare: {}",
                e
            );
            return Ok(());
        }
    };
    check_manifold(&mesh).map_err(|e| TestCaseError::fail(format!("prepare output: {e}")))?;
    let options = EncodeOptions {
        quantization_bits: c.bits,
        base: c.base,
        min_base_vertices: c.min_base,
        geometric_guard: c.guard,
        ..Default::default()
    };
    let encoded =
        encode(&mesh, &options).map_err(|e| TestCaseError::fail(format!("encode: {e}")))?;

    let bytes = &encoded.bytes;
    let index =
        StreamIndex::parse(bytes).map_err(|e| TestCaseError::fail(format!("index: {e}")))?;
    let mut d = Decoder::new(&bytes[index.base.clone()], Limits::default())
        .map_err(|e| TestCaseError::fail(format!("base: {e}")))?;
    for k in 0..=index.batches.len() {
        if k > 0 {
            d.apply_batch(&bytes[index.batches[k - 1].clone()])
                .map_err(|e| TestCaseError::fail(format!("batch {k}: {e}")))?;
        }
        let level = index.header.levels[k];
        prop_assert_eq!(d.vertex_count(), level.vertices as usize, "level {}", k);
        prop_assert_eq!(d.face_count(), level.faces as usize, "level {}", k);
        prop_assert!(
            d.indices().iter().all(|&v| (v as usize) < d.vertex_count()),
            "level {}",
            k
        );
        edge_manifold(d.indices()).map_err(|e| TestCaseError::fail(format!("level {k}: {e}")))?;
        check_manifold(&d.to_mesh()).map_err(|e| TestCaseError::fail(format!("level {k}: {e}")))?;
    }
    prop_assert!(d.is_complete());

    // The final level is the quantized input, vertex for vertex.
    let mismatch = vitrine_samples::final_level_mismatch(&mesh, c.bits, &d, &encoded.vertex_order);
    prop_assert!(mismatch.is_none(), "final level differs: {:?}", mismatch);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]
    #[test]
    fn prepared_meshes_round_trip_through_every_level(c in case()) {
        check(&c)?;
    }
}
