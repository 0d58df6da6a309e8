//! Evaluates the cubic cell complex on a mesh file: guard overhead against
//! unguarded AD, texture sizes, ambiguity and build time, for a few cell sizes.
//!
//!     cargo run --release -p vitrine-colour --example ccc_eval -- MESH [CUBES_ON_LONGEST...]

use std::time::Instant;

use vitrine_codec::{breakdown, encode, EncodeOptions, Encoder, IndexedMesh, Quantization};
use vitrine_colour::ccc::{self, CccOptions, ColourSource};
use vitrine_mesh::import::{import_path_textured, ImportOptions};
use vitrine_mesh::repair::{prepare, RepairOptions};

fn connectivity_bits(stream: &[u8], vertices: usize) -> (f64, usize, u32) {
    let levels = breakdown(stream).expect("own stream");
    let bits: u64 = levels.iter().map(|l| l.connectivity as u64 * 8).sum();
    (
        bits as f64 / vertices as f64,
        levels.len(),
        levels[0].vertices,
    )
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = std::path::Path::new(&args[0]);
    let imported = import_path_textured(path, &ImportOptions::default()).expect("imports");
    let textured = imported.texture;
    let (mut mesh, _) = prepare(imported.mesh, &RepairOptions::default()).expect("repairs");
    if textured.is_none() && mesh.colors.is_none() {
        vitrine_samples::paint(&mut mesh);
    }
    let source = match &textured {
        Some(t) => ColourSource::Texture(t),
        None => ColourSource::PerVertex(&mesh),
    };
    let options = EncodeOptions::default();
    let geometry = IndexedMesh {
        colors: None,
        ..mesh.clone()
    };
    let plain = encode(&geometry, &options).unwrap();
    let (pc, pl, pb) = connectivity_bits(&plain.bytes, mesh.positions.len());
    println!(
        "{}: {} vertices, texture {:?}; unguarded: conn {pc:.3} b/v, {pl} levels, base {pb}",
        path.display(),
        mesh.positions.len(),
        textured
            .as_ref()
            .map(|t| (t.image.width(), t.image.height()))
    );
    let q = Quantization::for_positions(&mesh.positions, 12).unwrap();
    let lo = q.min;
    let extent = (1u32 << 12) as f32 * q.step;
    let mut sizes: Vec<Option<f32>> = args[1..]
        .iter()
        .map(|a| Some(extent / a.parse::<f32>().unwrap()))
        .collect();
    if sizes.is_empty() {
        sizes.push(None);
    }
    let _ = lo;
    for cell_size in sizes {
        let t = Instant::now();
        let (m, guard) = ccc::build(
            &mesh,
            &q,
            source,
            &CccOptions {
                cell_size,
                ..CccOptions::default()
            },
        )
        .unwrap();
        let build = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let guarded = Encoder::new(options.clone())
            .guard(&guard)
            .encode(&geometry)
            .unwrap();
        let enc = t.elapsed().as_secs_f64();
        let (gc, gl, gb) = connectivity_bits(&guarded.bytes, mesh.positions.len());
        if let Some(colours) = mesh.colors.as_ref().filter(|_| textured.is_none()) {
            let complex =
                ccc::CellComplex::from_images(&m.parameters, &m.cell_png, &m.colour_jpeg).unwrap();
            let mut errors: Vec<f64> = mesh
                .positions
                .iter()
                .zip(colours)
                .map(|(&p, c)| {
                    let at = complex.colour_at(q.dequantize(q.quantize(p)).into());
                    (0..3)
                        .map(|k| (at[k] as f64 * 255.0 - c[k] as f64).abs())
                        .sum::<f64>()
                        / 3.0
                })
                .collect();
            errors.sort_by(f64::total_cmp);
            let n = errors.len();
            println!(
                "colour error at the vertices (mean abs per channel): mean {:.2}, median {:.2}, p90 {:.2}, p99 {:.2}",
                errors.iter().sum::<f64>() / n as f64,
                errors[n / 2],
                errors[n * 9 / 10],
                errors[n * 99 / 100]
            );
        }
        let r = &m.report;
        let p = &m.parameters;
        println!(
            "cell {:.4} dims {:?} cells {} tile {} atlas {}x{}: conn {gc:.3} b/v ({:+.2} %), {gl} levels, base {gb}; total {:+.2} %; ambiguous {:.3} %; cell png {} B, jpeg {} B, low {} B; build {build:.2} s, encode {enc:.2} s",
            p.cell_size, p.dims, p.cells, p.tile_size, p.atlas.width, p.atlas.height,
            (gc / pc - 1.0) * 100.0,
            (guarded.bytes.len() as f64 / plain.bytes.len() as f64 - 1.0) * 100.0,
            r.ambiguous_texels as f64 / r.covered_texels.max(1) as f64 * 100.0,
            r.cell_texture_bytes, r.colour_texture_bytes, r.colour_texture_low_bytes
        );
    }
}
