//! Golden point streams: the exact bytes the encoder writes for generated
//! clouds, recorded in `golden.txt` as `name length fnv1a64`.
//!
//! A mismatch means the point-stream format or the encoder's output
//! changed; streams already stored must still decode, or `FORMAT.md`'s
//! version (and `VERSION`) must be bumped. Re-record with
//!
//! ```sh
//! VITRINE_BLESS=1 cargo test -p vitrine-points --test golden
//! ```

use std::fmt::Write as _;
use std::path::PathBuf;

use vitrine_points::stream::{decode, encode, EncodeOptions, Limits};
use vitrine_points::testing::{cube, sphere};
use vitrine_points::PointCloud;

fn clouds() -> Vec<(&'static str, PointCloud, EncodeOptions)> {
    let (pos, nrm) = sphere(5000, [0.0; 3], 1.0, 42);
    let colours = pos
        .iter()
        .map(|p| p.map(|v| (v * 100.0 + 128.0) as u8))
        .collect();
    let painted = PointCloud {
        origin: [10.0, 20.0, 30.0],
        positions: pos,
        normals: Some(nrm),
        colours: Some(colours),
    };
    let (cube_pos, _) = cube(8000, 1.0, 7);
    // Version 1 streams must stay byte for byte what they were; these
    // record the parent-only attribute coding (the default before session 34).
    let small = EncodeOptions {
        base_points: 256,
        version: 1,
        predict_attributes: false,
        ..Default::default()
    };
    let small_v2 = EncodeOptions {
        version: 2,
        ..small.clone()
    };
    let small_v3 = EncodeOptions {
        version: 3,
        ..small.clone()
    };
    let cube = PointCloud::from_positions(cube_pos);
    vec![
        (
            "sphere-5000-normals-colours-14bit",
            painted.clone(),
            small.clone(),
        ),
        (
            "cube-8000-positions-11bit",
            cube.clone(),
            EncodeOptions { bits: 11, ..small },
        ),
        (
            "v2-sphere-5000-normals-colours-14bit",
            painted.clone(),
            small_v2.clone(),
        ),
        (
            "v2-cube-8000-positions-11bit",
            cube.clone(),
            EncodeOptions {
                bits: 11,
                ..small_v2
            },
        ),
        (
            "v3-sphere-5000-normals-colours-14bit",
            painted.clone(),
            small_v3.clone(),
        ),
        // Attributes predicted from the neighbourhood (flag bit 2).
        (
            "predicted-sphere-5000-normals-colours-14bit",
            painted.clone(),
            EncodeOptions {
                predict_attributes: true,
                ..small.clone()
            },
        ),
        (
            "v3-predicted-sphere-5000-normals-colours-14bit",
            painted,
            EncodeOptions {
                predict_attributes: true,
                ..small_v3.clone()
            },
        ),
        (
            "v3-cube-8000-positions-11bit",
            cube,
            EncodeOptions {
                bits: 11,
                ..small_v3
            },
        ),
    ]
}

fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

const HEADER: &str = "\
# Golden point-stream output: `name length fnv1a64-hex` (see tests/golden.rs).
# Re-record with `VITRINE_BLESS=1 cargo test -p vitrine-points --test golden`.
";

#[test]
fn point_stream_matches_golden_values() {
    let mut actual = String::from(HEADER);
    for (name, cloud, opts) in clouds() {
        let enc = encode(&cloud, &opts).unwrap();
        // The recorded bytes also decode back to the encoder's points.
        let d = decode(&enc.bytes, None, Limits::default()).unwrap();
        assert_eq!(d.quantized(), &enc.quantized[..], "{name}");
        writeln!(
            actual,
            "{name} {} {:016x}",
            enc.bytes.len(),
            fnv1a64(&enc.bytes)
        )
        .unwrap();
    }
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden.txt");
    if std::env::var_os("VITRINE_BLESS").is_some() {
        std::fs::write(&path, &actual).unwrap();
        return;
    }
    let recorded = std::fs::read_to_string(&path).expect("tests/golden.txt (bless to create)");
    assert_eq!(
        actual, recorded,
        "point stream output changed; see tests/golden.rs"
    );
}
