//! The WebAssembly point session, driven natively: level-by-level decoding
//! matches the library's decoder bit for bit, a truncated chunk is an error
//! that stops the session, and splats run on a prefix and on the whole.

use vitrine_points::stream::{decode, encode, split, EncodeOptions, Limits};
use vitrine_points::testing::cube;
use vitrine_points::PointCloud;
use vitrine_wasm::points::PointsSession;

fn stream(normals: bool) -> Vec<u8> {
    let (pos, nrm) = cube(20_000, 1.0, 4);
    let cloud = PointCloud {
        normals: normals.then_some(nrm),
        ..PointCloud::from_positions(pos)
    };
    let opts = EncodeOptions {
        base_points: 1000,
        ..Default::default()
    };
    encode(&cloud, &opts).unwrap().bytes
}

#[test]
fn points_session_decodes_levels_and_runs_splats() {
    for normals in [true, false] {
        let bytes = stream(normals);
        let (header, chunks) = split(&bytes).unwrap();
        let mut s = PointsSession::new(&bytes[..header.len()]).unwrap();
        let mut prefix_ids = None;
        for (k, c) in chunks.iter().enumerate() {
            s.apply(&bytes[c.clone()]).unwrap();
            let want = decode(&bytes, Some(k + 1), Limits::default()).unwrap();
            assert_eq!(s.decoder().quantized(), want.quantized());
            if k == 0 {
                let n = s.decoder().point_count();
                let splats = s.run_splats(0.9).unwrap();
                assert_eq!(splats.radii.len(), n);
                prefix_ids = Some(splats.surface_ids.clone());
            }
        }
        assert!(s.decoder().is_complete());
        let n = s.decoder().point_count();
        assert_eq!(n, 20_000);
        let splats = s.run_splats(0.9).unwrap();
        assert_eq!(splats.clipping.clip.len(), n);
        // A cube's six faces: six large surfaces, on the prefix and the whole.
        for ids in [prefix_ids.unwrap(), splats.surface_ids.clone()] {
            let mut count = std::collections::HashMap::new();
            for id in ids {
                *count.entry(id).or_insert(0usize) += 1;
            }
            let mut sizes: Vec<usize> = count.into_values().collect();
            sizes.sort_unstable_by(|a, b| b.cmp(a));
            let six: usize = sizes.iter().take(6).sum();
            assert!(
                sizes.len() >= 6 && six as f64 >= 0.95 * sizes.iter().sum::<usize>() as f64,
                "{sizes:?}"
            );
        }
        // Edge splats clip.
        assert!(splats.clipping.planes.len() >= 4 * 100);
    }
}

#[test]
fn points_session_truncated_chunk_is_an_error() {
    let bytes = stream(true);
    let (header, chunks) = split(&bytes).unwrap();
    let mut s = PointsSession::new(&bytes[..header.len()]).unwrap();
    s.apply(&bytes[chunks[0].clone()]).unwrap();
    let c = chunks[1].clone();
    let e = s.apply(&bytes[c.start..c.end - 10]).unwrap_err();
    assert!(e.to_string().contains("truncated"), "{e}");
    // The session refuses to go on rather than show a wrong cloud.
    assert!(s.apply(&bytes[chunks[1].clone()]).is_err());
    assert!(PointsSession::new(b"VPTX").is_err());
}
