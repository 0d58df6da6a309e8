//! The cubic cell complex: colour through the shared texture at every level,
//! the decimation guard, lossless geometry, and bad textures refused.

use glam::Vec3;
use vitrine_codec::{
    decode, encode, EncodeOptions, IndexedMesh, Limits, Quantization, StreamIndex,
};
use vitrine_colour::ccc::{self, CccOptions, CellComplex, ColourSource};
use vitrine_samples as samples;

mod common;
use common::textured_torus;

fn painted_torus() -> IndexedMesh {
    let mut mesh = samples::torus(120, 60, 1.0, 0.35);
    samples::add_noise(&mut mesh, 0.004, 7);
    samples::paint(&mut mesh);
    mesh
}

fn encode_ccc(mesh: &IndexedMesh) -> (vitrine_codec::Encoded, ccc::TextureMapping) {
    ccc::encode_with_ccc(
        mesh,
        ColourSource::PerVertex(mesh),
        &CccOptions::default(),
        vitrine_codec::Encoder::new(EncodeOptions::default()),
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
fn the_complex_is_the_same_whatever_the_number_of_threads() {
    // Its cells are rendered, and its triangles swept (14,400 of them: two
    // tasks), on every core: the images must not depend on how many.
    let mesh = painted_torus();
    let q = Quantization::for_positions(&mesh.positions, 12).unwrap();
    let build = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let source = ColourSource::PerVertex(&mesh);
        pool.install(|| ccc::build(&mesh, &q, source, &CccOptions::default()))
            .expect("builds")
            .0
    };
    let one = build(1);
    assert!(one.report.cells > 100, "{:?}", one.report);
    for threads in [2, 5] {
        let several = build(threads);
        assert_eq!(several.report, one.report, "{threads} threads");
        assert!(several.cell_png == one.cell_png, "{threads} threads");
        assert!(several.colour_jpeg == one.colour_jpeg, "{threads} threads");
        assert!(
            several.colour_low_jpeg == one.colour_low_jpeg,
            "{threads} threads"
        );
    }
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
    let encoded = vitrine_codec::Encoder::new(EncodeOptions::default())
        .guard(&guard)
        .encode(&geometry)
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
        vitrine_samples::final_level_mismatch(&geometry, 12, &d, &encoded.vertex_order),
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
    // So small that the cube counts would overflow: still a clear error.
    let absurd = CccOptions {
        cell_size: Some(1e-30),
        ..CccOptions::default()
    };
    assert!(ccc::build(&mesh, &q, ColourSource::PerVertex(&mesh), &absurd).is_err());
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

#[test]
fn every_level_shows_the_painted_texture() {
    use vitrine_colour::{encode_coloured, ColourMode};
    use vitrine_quality::metrics::{render, views, Frame, Lighting, RenderOptions};
    use vitrine_quality::TextureShader;
    let (mesh, surface) = textured_torus();
    let (encoded, mapping) = encode_coloured(
        &mesh,
        Some(&surface),
        ColourMode::Ccc,
        &CccOptions::default(),
        vitrine_codec::Encoder::new(EncodeOptions::default()),
    )
    .unwrap();
    let m = mapping.unwrap();
    let complex = CellComplex::from_images(&m.parameters, &m.cell_png, &m.colour_jpeg).unwrap();
    let reference = surface.as_mesh();
    let (centre, radius) = views::bounding_sphere(&reference);
    let cameras = views::rhombicuboctahedron(centre, radius);
    // Unlit: the albedo alone, so coarse normals do not count against colour.
    let options = RenderOptions {
        lighting: Lighting::headlight(1.0),
        ..RenderOptions::square(192)
    };
    let index = StreamIndex::parse(&encoded.bytes).unwrap();
    let mut decoder =
        vitrine_codec::Decoder::new(&encoded.bytes[index.base.clone()], Limits::default()).unwrap();
    for level in 0..=index.batches.len() {
        if level > 0 {
            decoder
                .apply_batch(&encoded.bytes[index.batches[level - 1].clone()])
                .unwrap();
        }
        let level_mesh = decoder.to_mesh();
        let (mut sum, mut n, mut foreign) = (0.0f64, 0usize, 0usize);
        for camera in [&cameras[0], &cameras[9], &cameras[17]] {
            let want = render(&reference, &TextureShader(&surface), camera, &options);
            let got = render(&level_mesh, &complex, camera, &options);
            if let Ok(dir) = std::env::var("VITRINE_SNAPSHOTS") {
                want.write_png(format!("{dir}/torus-reference.png"))
                    .unwrap();
                got.write_png(format!("{dir}/torus-level{level}.png"))
                    .unwrap();
            }
            // The painted palette: colour bins (16 levels a channel) the reference shows.
            let bin = |c: [u8; 3]| c.map(|v| (v / 16) as i32);
            let mut palette = std::collections::HashSet::new();
            for (i, c) in want.rgb.iter().enumerate() {
                if want.triangle[i] != Frame::BACKGROUND {
                    palette.insert(bin(*c));
                }
            }
            let painted = |c: [u8; 3]| {
                let b = bin(c);
                (-1..=1).any(|x| {
                    (-1..=1).any(|y| {
                        (-1..=1).any(|z| palette.contains(&[b[0] + x, b[1] + y, b[2] + z]))
                    })
                })
            };
            for i in 0..want.rgb.len() {
                if got.triangle[i] == Frame::BACKGROUND {
                    continue;
                }
                foreign += usize::from(!painted(got.rgb[i]));
                // Where both show the surface, the same colour (the coarse surface
                // sits elsewhere than the fine one, so this only tightens with level).
                if want.triangle[i] != Frame::BACKGROUND {
                    sum += (0..3)
                        .map(|k| (want.rgb[i][k] as f64 - got.rgb[i][k] as f64).abs())
                        .sum::<f64>()
                        / 3.0;
                    n += 1;
                }
            }
        }
        let mean = sum / n as f64;
        let foreign = foreign as f64 / n as f64;
        eprintln!(
            "level {level}: {} vertices, mean pixel difference {mean:.1}, {:.2} % pixels off the painted palette",
            level_mesh.positions.len(),
            foreign * 100.0
        );
        // Every level shows the painted colours, not blends of them...
        assert!(
            foreign < 0.03,
            "level {level}: {:.1} % of pixels are not painted colours",
            foreign * 100.0
        );
        // ...in about the right places, converging to the photograph.
        assert!(
            mean < 40.0,
            "level {level}: mean colour difference {mean:.1}"
        );
        if level == index.batches.len() {
            assert!(mean < 4.0, "final level: mean colour difference {mean:.1}");
        }
    }
}

#[test]
fn every_mode_is_lossless() {
    use vitrine_colour::{encode_coloured, ColourMode};
    let mesh = painted_torus();
    for mode in ColourMode::ALL {
        let (encoded, mapping) = encode_coloured(
            &mesh,
            None,
            mode,
            &CccOptions::default(),
            vitrine_codec::Encoder::new(EncodeOptions::default()),
        )
        .unwrap();
        assert_eq!(mapping.is_some(), mode == ColourMode::Ccc);
        let d = decode(&encoded.bytes, None, Limits::default()).unwrap();
        let expected = match mode {
            ColourMode::Vertex | ColourMode::VertexMetric => mesh.clone(),
            _ => IndexedMesh {
                colors: None,
                ..mesh.clone()
            },
        };
        assert_eq!(
            vitrine_samples::final_level_mismatch(&expected, 12, &d, &encoded.vertex_order),
            None,
            "{mode}"
        );
    }
    // The colour metric refuses some decimations on a painted mesh.
    let plain = encode_coloured(
        &mesh,
        None,
        ColourMode::Vertex,
        &CccOptions::default(),
        vitrine_codec::Encoder::new(EncodeOptions::default()),
    )
    .unwrap()
    .0;
    let metric = encode_coloured(
        &mesh,
        None,
        ColourMode::VertexMetric,
        &CccOptions::default(),
        vitrine_codec::Encoder::new(EncodeOptions::default()),
    )
    .unwrap()
    .0;
    assert_ne!(plain.bytes, metric.bytes);
}
