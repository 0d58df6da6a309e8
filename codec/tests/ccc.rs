//! The cubic cell complex: colour through the shared texture at every level,
//! the decimation guard, lossless geometry, and bad textures refused.

mod common;

use glam::Vec3;
use vitrine_codec::ccc::{self, CccOptions, CellComplex, ColourSource};
use vitrine_codec::samples;
use vitrine_codec::{
    decode, encode, EncodeOptions, IndexedMesh, Limits, Quantization, StreamIndex,
};

fn painted_torus() -> IndexedMesh {
    let mut mesh = samples::torus(120, 60, 1.0, 0.35);
    samples::add_noise(&mut mesh, 0.004, 7);
    samples::paint(&mut mesh);
    mesh
}

fn encode_ccc(mesh: &IndexedMesh) -> (vitrine_codec::Encoded, ccc::TextureMapping) {
    ccc::encode_with_ccc(
        mesh,
        &EncodeOptions::default(),
        ColourSource::PerVertex(mesh),
        &CccOptions::default(),
        |_| {},
    )
    .expect("encodes")
}

/// Mean and 95th-percentile colour error (0–255) of the complex at the
/// input's vertices, against the vertices' own colours.
fn colour_error(mesh: &IndexedMesh, complex: &CellComplex) -> (f64, f64) {
    let q = Quantization::for_positions(&mesh.positions, 12).unwrap();
    let colours = mesh.colors.as_ref().unwrap();
    let mut errors: Vec<f64> = mesh
        .positions
        .iter()
        .zip(colours)
        .map(|(&p, c)| {
            let at = complex.colour_at(Vec3::from(q.dequantize(q.quantize(p))));
            (0..3)
                .map(|k| (at[k] as f64 * 255.0 - c[k] as f64).abs())
                .sum::<f64>()
                / 3.0
        })
        .collect();
    errors.sort_by(f64::total_cmp);
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    (mean, errors[errors.len() * 95 / 100])
}

#[test]
fn texture_gives_the_vertex_colours_back() {
    let mesh = painted_torus();
    let (_, mapping) = encode_ccc(&mesh);
    let p = &mapping.parameters;
    let full = CellComplex::from_images(p, &mapping.cell_png, &mapping.colour_jpeg).unwrap();
    let low = CellComplex::from_images(p, &mapping.cell_png, &mapping.colour_low_jpeg).unwrap();
    let (mean, p95) = colour_error(&mesh, &full);
    let (low_mean, _) = colour_error(&mesh, &low);
    eprintln!(
        "cells {} tiles {} tile {} atlas {}x{}; error full mean {mean:.2} p95 {p95:.2}, low mean {low_mean:.2}; ambiguous {}/{}",
        p.cells, p.atlas.tiles, p.tile_size, p.atlas.width, p.atlas.height,
        mapping.report.ambiguous_texels, mapping.report.covered_texels
    );
    assert!(
        mean < 6.0 && p95 < 20.0,
        "full texture: mean {mean}, p95 {p95}"
    );
    assert!(low_mean < 20.0, "low-res texture: mean {low_mean}");
    assert!(
        low_mean > mean,
        "the low-resolution atlas should be the coarser one"
    );
    assert!(mapping.report.ambiguous_texels * 100 < mapping.report.covered_texels);
}

#[test]
fn every_level_stays_inside_the_cells() {
    let mesh = painted_torus();
    let q = Quantization::for_positions(&mesh.positions, 12).unwrap();
    let (mapping, guard) = ccc::build(
        &mesh,
        &q,
        ColourSource::PerVertex(&mesh),
        &CccOptions::default(),
    )
    .unwrap();
    let geometry = IndexedMesh {
        colors: None,
        ..mesh.clone()
    };
    let encoded =
        vitrine_codec::encode_guarded(&geometry, &EncodeOptions::default(), Some(&guard), |_| {})
            .unwrap();
    let index = StreamIndex::parse(&encoded.bytes).unwrap();
    assert!(index.header.levels.len() >= 4, "a few levels to check");
    for level in 0..index.header.levels.len() {
        let d = decode(&encoded.bytes, Some(level), Limits::default()).unwrap();
        for t in d.indices().chunks_exact(3) {
            let tri = [0, 1, 2].map(|k| d.quantized_positions()[t[k] as usize]);
            assert!(
                guard.triangle_in_cells(tri),
                "level {level}: a face leaves the complex"
            );
        }
    }
    // And the stream is the same one `encode_with_ccc` writes.
    let (again, mapping2) = encode_ccc(&mesh);
    assert_eq!(again.bytes, encoded.bytes);
    assert_eq!(mapping2.cell_png, mapping.cell_png);
}

#[test]
fn ccc_stream_is_lossless_and_carries_no_vertex_colour() {
    let mesh = painted_torus();
    let (encoded, _) = encode_ccc(&mesh);
    let d = decode(&encoded.bytes, None, Limits::default()).unwrap();
    assert!(d.colours().is_none());
    let geometry = IndexedMesh {
        colors: None,
        ..mesh.clone()
    };
    assert_eq!(
        common::final_level_mismatch(&geometry, 12, &d, &encoded.vertex_order),
        None
    );
    // The guard costs little connectivity.
    let plain = encode(&geometry, &EncodeOptions::default()).unwrap();
    let overhead = encoded.bytes.len() as f64 / plain.bytes.len() as f64 - 1.0;
    eprintln!(
        "ccc stream {} B, unguarded {} B ({:+.2} %)",
        encoded.bytes.len(),
        plain.bytes.len(),
        overhead * 100.0
    );
    // A thin tube is a hard case (coarse chords leave it); real scans stay under 1 % (BENCHMARKS.md).
    assert!(overhead < 0.08, "guard overhead {overhead}");
}

#[test]
fn corrupt_or_mismatched_textures_are_errors() {
    let mesh = painted_torus();
    let (_, m) = encode_ccc(&mesh);
    let p = &m.parameters;
    assert!(
        CellComplex::from_images(p, &m.cell_png[..m.cell_png.len() / 2], &m.colour_jpeg).is_err()
    );
    assert!(CellComplex::from_images(p, &m.cell_png, b"not a jpeg").is_err());
    let mut wrong = p.clone();
    wrong.cells += 1_000_000;
    assert!(CellComplex::from_images(&wrong, &m.cell_png, &m.colour_jpeg).is_err());
    let mut wrong = p.clone();
    wrong.atlas.tiles = 1;
    assert!(CellComplex::from_images(&wrong, &m.cell_png, &m.colour_jpeg).is_err());
    // A cell size that would need more cubes than the cell texture can number.
    let q = Quantization::for_positions(&mesh.positions, 12).unwrap();
    let tiny = CccOptions {
        cell_size: Some(1e-4),
        ..CccOptions::default()
    };
    assert!(ccc::build(&mesh, &q, ColourSource::PerVertex(&mesh), &tiny).is_err());
    let bad = CccOptions {
        cell_size: Some(f32::NAN),
        ..CccOptions::default()
    };
    assert!(ccc::build(&mesh, &q, ColourSource::PerVertex(&mesh), &bad).is_err());
    // No colour to build from.
    let grey = IndexedMesh {
        colors: None,
        ..mesh.clone()
    };
    assert!(ccc::build(
        &grey,
        &q,
        ColourSource::PerVertex(&grey),
        &CccOptions::default()
    )
    .is_err());
}
