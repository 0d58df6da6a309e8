//! Golden colour output: the exact bytes a generated *textured* mesh gives
//! through every colour mode — the texel sampling into vertex colours, the
//! cubic cell complex's cell map and atlases, and the streams — so colour
//! sampling cannot drift unseen (the codec's own goldens cover geometry and
//! per-vertex colour only). Re-record an intended change with
//!
//! ```sh
//! VITRINE_BLESS=1 cargo test -p vitrine-colour --test golden
//! ```

mod common;

use std::path::PathBuf;

use vitrine_codec::{EncodeOptions, Encoder};
use vitrine_colour::ccc::CccOptions;
use vitrine_colour::{encode_coloured, vertex_colours_from_texture, ColourMode};
use vitrine_samples::golden::{check_or_bless, GoldenEntry};

const HEADER: &str = "\
# Golden colour output of the generated textured torus (see tests/golden.rs):
# `name length fnv1a64-hex`. Re-record with `VITRINE_BLESS=1 cargo test -p vitrine-colour --test golden`.
";

#[test]
fn textured_mesh_output_matches_golden_values() {
    let (mesh, surface) = common::textured_torus();
    let sampled: Vec<u8> = vertex_colours_from_texture(&mesh, &surface)
        .into_iter()
        .flatten()
        .collect();
    let mut found = vec![GoldenEntry::of("textured-torus-vertex-colours", &sampled)];
    for mode in [
        ColourMode::Ccc,
        ColourMode::Vertex,
        ColourMode::VertexMetric,
    ] {
        let (encoded, mapping) = encode_coloured(
            &mesh,
            Some(&surface),
            mode,
            &CccOptions::default(),
            Encoder::new(EncodeOptions::default()),
        )
        .unwrap();
        found.push(GoldenEntry::of(
            &format!("textured-torus-{mode}-stream"),
            &encoded.bytes,
        ));
        if let Some(m) = mapping {
            found.push(GoldenEntry::of("textured-torus-ccc-cells", &m.cell_png));
            found.push(GoldenEntry::of("textured-torus-ccc-atlas", &m.colour_jpeg));
            found.push(GoldenEntry::of(
                "textured-torus-ccc-atlas-low",
                &m.colour_low_jpeg,
            ));
        }
    }
    // Sampling really reads the texture: both of its paints are there.
    assert!(sampled.chunks(3).any(|c| c[0] > 200 && c[2] < 60));
    assert!(sampled.chunks(3).any(|c| c[0] < 50 && c[2] > 110));
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden.txt");
    let diffs = check_or_bless(&path, HEADER, &found);
    assert!(
        diffs.is_empty(),
        "colour output changed:\n  {}\nIf intended, re-record with \
         VITRINE_BLESS=1 cargo test -p vitrine-colour --test golden",
        diffs.join("\n  ")
    );
}
