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

use std::fmt::Write as _;
use std::path::PathBuf;

use vitrine_codec::{decode, encode, EncodeOptions, IndexedMesh, Limits};
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

/// FNV-1a, 64 bits.
fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
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
fn fnv1a64_reference_values() {
    assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
    assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
    assert_eq!(fnv1a64(b"foobar"), 0x8594_4171_f739_67e8);
}

#[test]
fn encoder_output_matches_golden_values() {
    let mut actual = String::from(HEADER);
    let mut found = Vec::new();
    for (name, mesh) in meshes() {
        let encoded = encode(&mesh, &EncodeOptions::default()).unwrap();
        // A golden stream must at least decode to the mesh's size.
        let d = decode(&encoded.bytes, None, Limits::default()).unwrap();
        assert_eq!(d.vertex_count(), mesh.positions.len(), "{name}");
        let (len, hash) = (encoded.bytes.len(), fnv1a64(&encoded.bytes));
        writeln!(actual, "{name} {len} {hash:016x}").unwrap();
        found.push((name, len, hash));
    }
    if std::env::var("VITRINE_BLESS").is_ok_and(|v| v == "1") {
        std::fs::write(golden_path(), &actual).unwrap();
        eprintln!("re-recorded {}", golden_path().display());
        return;
    }
    let recorded = std::fs::read_to_string(golden_path())
        .expect("tests/golden.txt (record it with VITRINE_BLESS=1)");
    let mut expected = Vec::new();
    for line in recorded
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
    {
        let f: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(f.len(), 3, "malformed golden.txt line {line:?}");
        let len: usize = f[1]
            .parse()
            .unwrap_or_else(|_| panic!("bad length in {line:?}"));
        let hash = u64::from_str_radix(f[2], 16).unwrap_or_else(|_| panic!("bad hash in {line:?}"));
        expected.push((f[0], len, hash));
    }
    let mut diffs = Vec::new();
    for &(name, len, hash) in &found {
        match expected.iter().find(|e| e.0 == name) {
            None => diffs.push(format!("{name}: not in golden.txt")),
            Some(&(_, l, h)) if (l, h) != (len, hash) => diffs.push(format!(
                "{name}: recorded {l} bytes {h:016x}, now {len} bytes {hash:016x}"
            )),
            Some(_) => {}
        }
    }
    for (name, ..) in &expected {
        if !found.iter().any(|f| f.0 == *name) {
            diffs.push(format!("{name}: in golden.txt but no longer encoded"));
        }
    }
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
