//! `vitrine sample`: writes a generated mesh, for demos and tests that must
//! not depend on third-party scans.

use anyhow::Context;
use clap::{Args, ValueEnum};
use std::io::BufWriter;
use std::path::PathBuf;
use vitrine_codec::IndexedMesh;
use vitrine_samples::{add_noise, icosphere, paint, plate_with_tunnels, torus};

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum SampleKind {
    /// Genus-1 torus, valence 6 everywhere.
    Torus,
    /// Subdivided icosahedron.
    Sphere,
    /// Plate with three tunnels (genus 3), sharp edges.
    Plate,
}

#[derive(Args, Debug)]
pub struct SampleArgs {
    #[arg(value_enum)]
    pub kind: SampleKind,
    /// Output PLY file.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Detail: roughly the number of vertices in thousands.
    #[arg(long, default_value_t = 50)]
    pub kilo_vertices: u32,
    /// Paint a procedural colour pattern on the vertices.
    #[arg(long)]
    pub colour: bool,
    /// Displace vertices by this fraction of the size, like scanner noise.
    #[arg(long, default_value_t = 0.0)]
    pub noise: f32,
}

pub fn generate(args: &SampleArgs) -> IndexedMesh {
    let target = args.kilo_vertices.max(1) as f64 * 1000.0;
    let mut mesh = match args.kind {
        SampleKind::Torus => {
            let sides = ((target / 2.5).sqrt()).round().max(8.0) as u32;
            torus((sides as f64 * 2.5) as u32, sides, 1.0, 0.35)
        }
        SampleKind::Sphere => {
            let levels = ((target / 10.0).log(4.0)).round().clamp(1.0, 9.0) as u32;
            icosphere(levels)
        }
        SampleKind::Plate => {
            let cells = (target / 60.0).sqrt().round().max(2.0) as u32;
            plate_with_tunnels(3, cells)
        }
    };
    if args.noise > 0.0 {
        add_noise(&mut mesh, args.noise, 1);
    }
    if args.colour {
        paint(&mut mesh);
    }
    mesh
}

pub fn run(args: SampleArgs) -> anyhow::Result<()> {
    let mesh = generate(&args);
    let file = std::fs::File::create(&args.output)
        .with_context(|| format!("creating {}", args.output.display()))?;
    vitrine_mesh::export::write_ply(&mesh, &mut BufWriter::new(file))?;
    eprintln!(
        "{}: {} vertices, {} faces",
        args.output.display(),
        mesh.positions.len(),
        mesh.triangles.len()
    );
    Ok(())
}
