//! Golden streams: the exact bytes the encoder writes for a fixed set of
//! generated meshes, recorded in `golden.txt` as `name length fnv1a64`.
//!
//! A mismatch means the stream format or the encoder's output changed. That
//! may be intended (a better encoder), but every stream already stored by a
//! server was written by the old one: if the decoder can no longer read
//! them, `FORMAT.md`'s version (and `VERSION`) must be bumped. Once the
//! change is understood, re-record the values with
//!
//! ```sh
//! VITRINE_BLESS=1 cargo test -p vitrine-codec --test golden
//! ```

use std::path::PathBuf;

use vitrine_codec::{decode, encode, Charts, EncodeOptions, IndexedMesh, Limits};
use vitrine_samples::golden::{check_or_bless, GoldenEntry};
use vitrine_samples::{add_noise, icosphere, paint, plate_with_tunnels, torus};

fn meshes() -> Vec<(&'static str, IndexedMesh)> {
    let mut painted = torus(60, 24, 1.0, 0.35);
    add_noise(&mut painted, 0.004, 9);
    paint(&mut painted);
    vec![
        ("icosphere-4", icosphere(4)),
        ("torus-60x24", torus(60, 24, 1.0, 0.3)),
        ("painted-noisy-torus-60x24", painted),
        ("plate-genus-2", plate_with_tunnels(2, 6)),
    ]
}

fn golden_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden.txt")
}

const HEADER: &str = "\
# Golden encoder output: `name length fnv1a64-hex` per generated mesh (see tests/golden.rs).
# A change means the stream format or the encoder's output changed: consider FORMAT.md's
# version, then re-record with `VITRINE_BLESS=1 cargo test -p vitrine-codec --test golden`.
";

#[test]
fn encoder_output_matches_golden_values() {
    let mut found = Vec::new();
    for (name, mesh) in meshes() {
        let encoded = encode(&mesh, &EncodeOptions::default()).unwrap();
        // A golden stream must at least decode to the mesh's size.
        let d = decode(&encoded.bytes, None, Limits::default()).unwrap();
        assert_eq!(d.vertex_count(), mesh.positions.len(), "{name}");
        found.push(GoldenEntry::of(name, &encoded.bytes));
    }
    // Charted (format 5) and nested (format 6) streams of a larger scan-like torus.
    let mut scan = torus(120, 48, 1.0, 0.35);
    add_noise(&mut scan, 0.003, 5);
    paint(&mut scan);
    for (name, charts, version) in [
        ("charted-4-painted-noisy-torus-120x48", Charts::Count(4), 5),
        (
            "nested-2x2x2-painted-noisy-torus-120x48",
            Charts::NestedShape {
                top: 2,
                fanout: 2,
                phases: 2,
            },
            6,
        ),
    ] {
        let options = EncodeOptions {
            charts,
            ..EncodeOptions::default()
        };
        let encoded = encode(&scan, &options).unwrap();
        assert_eq!(encoded.header.version, version, "{name}");
        let d = decode(&encoded.bytes, None, Limits::default()).unwrap();
        assert_eq!(d.vertex_count(), scan.positions.len(), "{name}");
        found.push(GoldenEntry::of(name, &encoded.bytes));
    }
    let diffs = check_or_bless(&golden_path(), HEADER, &found);
    assert!(
        diffs.is_empty(),
        "encoder output changed:\n  {}\nIf intended, consider FORMAT.md's version and re-record with \
         VITRINE_BLESS=1 cargo test -p vitrine-codec --test golden",
        diffs.join("\n  ")
    );
}

/// Coding passes on a second thread must not change a byte.
#[test]
fn pipelined_and_in_place_coding_write_the_same_stream() {
    for (name, mesh) in meshes() {
        let write = |pipelined| {
            let options = EncodeOptions {
                pipelined,
                ..EncodeOptions::default()
            };
            encode(&mesh, &options).unwrap().bytes
        };
        assert_eq!(write(true), write(false), "{name}");
    }
}
