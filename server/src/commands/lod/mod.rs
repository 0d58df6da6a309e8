//! `vitrine lod MESH --levels 100,80,60,40,20 -o OUT.glb`: Melax's collapses
//! run once (seed 003), every level a prefix of them with exactly
//! ⌊n·p/100⌋ vertices: one GLB with `MSFT_lod` and coverage hints, one GLB
//! per level with `--split`, or one MD2 per level with `--format md2`. An
//! MD2 input keeps its frames (morph targets and a LINEAR animation in GLB,
//! every frame in MD2) and its texture coordinates (seams never collapse).

use anyhow::{bail, Context};
use clap::{Args, ValueEnum};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use vitrine_mesh::export::{mesh_to_md2, write_lod_glb, write_md2, LodGlb};
use vitrine_mesh::import::md2::{Md2, Md2Triangle};
use vitrine_mesh::import::{ImportOptions, MeshFormat as InputFormat};
use vitrine_simplify::melax::{compact, melax_chain, MelaxLevel, MelaxModel};

use crate::source::{describe_repair, load_coloured_mesh};

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LodFormat {
    Glb,
    Md2,
}

#[derive(Args, Debug)]
pub struct LodArgs {
    /// Input mesh: .ply, .obj, .off, .gltf, .glb or .md2 (all its frames).
    pub input: PathBuf,
    /// Output file; with --split or --format md2, each level goes to
    /// OUT-<percent>.<ext> beside it.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Level sizes in percent of the vertices, finest first.
    #[arg(long, value_delimiter = ',', default_value = "100,80,60,40,20",
          value_parser = clap::value_parser!(u32).range(1..=100))]
    pub levels: Vec<u32>,
    /// One file per level instead of one GLB with MSFT_lod.
    #[arg(long)]
    pub split: bool,
    #[arg(long, value_enum, default_value_t = LodFormat::Glb)]
    pub format: LodFormat,
    /// Animation key frames per second (MD2 frames in GLB; Quake II: 10).
    #[arg(long, default_value_t = 10.0)]
    pub fps: f32,
}

/// The model to cut into levels.
enum Source {
    Md2 {
        model: Md2,
        frames: Vec<Vec<[f32; 3]>>,
        triangles: Vec<[u32; 3]>,
        corner_uvs: Vec<[u32; 3]>,
    },
    Mesh(vitrine_codec::IndexedMesh),
}

fn load(path: &Path) -> anyhow::Result<Source> {
    if InputFormat::from_path(path) == Some(InputFormat::Md2) {
        let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
        let model = Md2::parse(&bytes, &ImportOptions::default())
            .with_context(|| format!("reading {}", path.display()))?;
        let frames = model.frames.iter().map(|f| f.positions()).collect();
        let triangles = model.mesh_triangles();
        // The same corner swap as the triangles (clockwise to counter-clockwise).
        let corner_uvs = model
            .triangles
            .iter()
            .map(|t| [t.st[0], t.st[2], t.st[1]].map(u32::from))
            .collect();
        return Ok(Source::Md2 {
            model,
            frames,
            triangles,
            corner_uvs,
        });
    }
    let source = load_coloured_mesh(path)?;
    if let Some(text) = describe_repair(&source.repair) {
        eprintln!("repair: {text}");
    }
    Ok(Source::Mesh(source.mesh))
}

pub fn run(args: LodArgs) -> anyhow::Result<()> {
    if args.levels.is_empty() {
        bail!("--levels needs at least one percentage");
    }
    let source = load(&args.input)?;
    let (frames, triangles, corner_uvs) = match &source {
        Source::Md2 {
            frames,
            triangles,
            corner_uvs,
            ..
        } => (
            frames.clone(),
            triangles.as_slice(),
            Some(corner_uvs.as_slice()),
        ),
        Source::Mesh(m) => (vec![m.positions.clone()], m.triangles.as_slice(), None),
    };
    let started = std::time::Instant::now();
    let chain = melax_chain(&MelaxModel {
        triangles,
        frames: &frames,
        corner_uvs,
    })
    .with_context(|| format!("simplifying {}", args.input.display()))?;
    let levels: Vec<MelaxLevel> = args
        .levels
        .iter()
        .map(|&p| chain.level(chain.percent(p)))
        .collect::<Result<_, _>>()?;
    eprintln!(
        "melax: {} vertices, {} collapses in {:.2} s; levels {}",
        chain.vertices,
        chain.collapses.len(),
        started.elapsed().as_secs_f64(),
        levels
            .iter()
            .zip(&args.levels)
            .map(|(l, p)| format!(
                "{p} % = {} vertices, {} faces",
                l.vertices,
                l.triangles.len()
            ))
            .collect::<Vec<_>>()
            .join("; ")
    );
    match args.format {
        LodFormat::Glb if !args.split => {
            let all: Vec<Vec<[u32; 3]>> = levels.iter().map(|l| l.triangles.clone()).collect();
            write_glb(&args.output, &frames, &all, args.fps)?;
        }
        LodFormat::Glb => {
            for (level, p) in levels.iter().zip(&args.levels) {
                let out = level_path(&args.output, *p, "glb");
                write_glb(
                    &out,
                    &frames,
                    std::slice::from_ref(&level.triangles),
                    args.fps,
                )?;
            }
        }
        LodFormat::Md2 => {
            for (level, p) in levels.iter().zip(&args.levels) {
                let out = level_path(&args.output, *p, "md2");
                let model = level_md2(&source, level)?;
                write_file(&out, |w| Ok(write_md2(&model, w)?))?;
            }
        }
    }
    Ok(())
}

/// OUT-<percent>.<ext>.
fn level_path(output: &Path, percent: u32, ext: &str) -> PathBuf {
    let stem = output
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "level".into());
    output.with_file_name(format!("{stem}-{percent}.{ext}"))
}

fn write_file(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<std::fs::File>) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let file =
        std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?;
    let mut w = BufWriter::new(file);
    write(&mut w)?;
    w.flush()
        .with_context(|| format!("writing {}", path.display()))?;
    eprintln!("{}", path.display());
    Ok(())
}

fn write_glb(
    path: &Path,
    frames: &[Vec<[f32; 3]>],
    levels: &[Vec<[u32; 3]>],
    fps: f32,
) -> anyhow::Result<()> {
    write_file(path, |w| {
        Ok(write_lod_glb(
            &LodGlb {
                frames,
                levels,
                fps,
            },
            w,
        )?)
    })
}

/// A level as an MD2: an MD2 input keeps its frames, packed vertices and
/// texture coordinates; any other mesh is quantized into one frame.
fn level_md2(source: &Source, level: &MelaxLevel) -> anyhow::Result<Md2> {
    match source {
        Source::Md2 { model, .. } => {
            let uvs = level.corner_uvs.as_deref().unwrap_or_default();
            let triangles: Vec<Md2Triangle> = level
                .triangles
                .iter()
                .zip(uvs)
                .map(|(t, s)| Md2Triangle {
                    // Back to MD2's clockwise corner order.
                    vertex: [t[0], t[2], t[1]].map(|v| v as u16),
                    st: [s[0], s[2], s[1]].map(|v| v as u16),
                })
                .collect();
            Ok(model.with_triangles(&triangles))
        }
        Source::Mesh(mesh) => Ok(mesh_to_md2(&compact(mesh, &level.triangles).0)?),
    }
}
