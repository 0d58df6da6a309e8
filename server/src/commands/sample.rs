//! `vitrine sample`: writes a generated mesh or point cloud, for demos and
//! tests that must not depend on third-party scans.

use anyhow::Context;
use clap::{Args, ValueEnum};
use std::io::{BufWriter, Write};
use std::path::PathBuf;
use vitrine_codec::IndexedMesh;
use vitrine_points::PointCloud;
use vitrine_samples::{add_noise, icosphere, paint, plate_with_tunnels, torus};

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum SampleKind {
    /// Genus-1 torus, valence 6 everywhere.
    Torus,
    /// Subdivided icosahedron.
    Sphere,
    /// Plate with three tunnels (genus 3), sharp edges.
    Plate,
    /// A point cloud (a PLY without faces): points at random on a cube's
    /// surface, with their normals (colour by face with --colour).
    Cloud,
}

#[derive(Args, Debug)]
pub struct SampleArgs {
    #[arg(value_enum)]
    pub kind: SampleKind,
    /// Output PLY file.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Detail: roughly the number of vertices (a cloud's points) in thousands.
    #[arg(long, default_value_t = 50)]
    pub kilo_vertices: u32,
    /// Paint a procedural colour pattern on the vertices.
    #[arg(long)]
    pub colour: bool,
    /// Displace vertices (points) by this fraction of the size, like scanner noise.
    #[arg(long, default_value_t = 0.0)]
    pub noise: f32,
}

/// The mesh `args` describe; `None` for a [`SampleKind::Cloud`] (see [`cloud`]).
pub fn generate(args: &SampleArgs) -> Option<IndexedMesh> {
    let target = args.kilo_vertices.max(1) as f64 * 1000.0;
    let mut mesh = match args.kind {
        SampleKind::Cloud => return None,
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
    Some(mesh)
}

/// `points` points at random on the surface of the cube [−1, 1]³ (seeded,
/// so the same every time), with their outward normals; with `colour`, each
/// face its own colour; with `noise`, moved along the normal by up to that
/// fraction of the cube's side.
pub fn cloud(points: usize, colour: bool, noise: f32) -> PointCloud {
    let (mut positions, normals) = vitrine_points::testing::cube(points, 1.0, 0x5EED);
    let mut state = 0xC0FFEE_u64;
    if noise > 0.0 {
        for (p, n) in positions.iter_mut().zip(&normals) {
            let d = (vitrine_points::testing::unit(&mut state) * 2.0 - 1.0) * noise * 2.0;
            *p = [0, 1, 2].map(|a| p[a] + d * n[a]);
        }
    }
    let colours = colour.then(|| {
        normals
            .iter()
            .map(|n| {
                let face = n.iter().position(|v| *v != 0.0).unwrap_or(0);
                let positive = n[face] > 0.0;
                let mut c = [60u8; 3];
                c[face] = if positive { 230 } else { 150 };
                c
            })
            .collect()
    });
    PointCloud {
        origin: [0.0; 3],
        positions,
        normals: Some(normals),
        colours,
    }
}

/// Writes `cloud` as a binary PLY with a vertex element only (positions,
/// normals and colours as it has them) and no faces.
pub fn write_cloud_ply(cloud: &PointCloud, w: &mut impl Write) -> std::io::Result<()> {
    let mut header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment vitrine sample cloud\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\n",
        cloud.len()
    );
    if cloud.normals.is_some() {
        header += "property float nx\nproperty float ny\nproperty float nz\n";
    }
    if cloud.colours.is_some() {
        header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    }
    header += "end_header\n";
    w.write_all(header.as_bytes())?;
    for (i, p) in cloud.positions.iter().enumerate() {
        let mut record = Vec::with_capacity(27);
        // Positions relative to the origin, as the cloud keeps them.
        for v in p {
            record.extend_from_slice(&v.to_le_bytes());
        }
        if let Some(n) = &cloud.normals {
            for v in n[i] {
                record.extend_from_slice(&v.to_le_bytes());
            }
        }
        if let Some(c) = &cloud.colours {
            record.extend_from_slice(&c[i]);
        }
        w.write_all(&record)?;
    }
    w.flush()
}

pub fn run(args: SampleArgs) -> anyhow::Result<()> {
    let Some(mesh) = generate(&args) else {
        let points = args.kilo_vertices.max(1) as usize * 1000;
        let cloud = cloud(points, args.colour, args.noise);
        let file = std::fs::File::create(&args.output)
            .with_context(|| format!("creating {}", args.output.display()))?;
        write_cloud_ply(&cloud, &mut BufWriter::new(file))
            .with_context(|| format!("writing {}", args.output.display()))?;
        eprintln!(
            "{}: {} points, no faces",
            args.output.display(),
            cloud.len()
        );
        return Ok(());
    };
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
