//! `vitrine lod MESH --levels 100,80,60,40,20 -o OUT.glb`: Melax's collapses
//! run once (seed 003), every level a prefix of them with exactly
//! ⌊n·p/100⌋ vertices: one GLB with `MSFT_lod` and coverage hints, one GLB
//! per level with `--split`, or one MD2 per level with `--format md2`. An
//! MD2 input keeps its frames (morph targets and a LINEAR animation in GLB,
//! every frame in MD2) and its texture coordinates (seams thin out only
//! along themselves), after the same repair as every other import.
//!
//! GLB levels carry what the model has: its texture (an MD2's skin, a
//! scan's base colour texture) as an embedded PNG with `TEXCOORD_0`, and
//! its per-vertex colour as `COLOR_0`. Melax keeps a subset of the model's
//! vertices and every corner keeps one of its vertex's texture
//! coordinates, so each attribute carries over per kept vertex; a GLB
//! vertex is a (vertex, texture coordinate) pair, two where a seam runs.

use super::simplify::MelaxCostKind;
use anyhow::{bail, Context};
use clap::{Args, ValueEnum};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use vitrine_mesh::export::{
    corner_vertices, mesh_to_md2, write_lod_glb, write_md2, LevelCorners, LodGlb,
};
use vitrine_mesh::import::md2::{Md2, Md2Triangle};
use vitrine_mesh::import::{ImportOptions, MeshFormat as InputFormat};
use vitrine_simplify::melax::{
    compact, melax_chain, MelaxChain, MelaxCost, MelaxLevel, MelaxModel,
};

use crate::source::{describe_repair, load_coloured_mesh};

mod texture;
use texture::{md2_texture, weld, Texture};

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
    /// The crease term of Melax's collapse cost.
    #[arg(long, value_enum, default_value_t = MelaxCostKind::Sine)]
    pub melax_cost: MelaxCostKind,
}

/// The model to cut into levels.
enum Source {
    Md2 {
        model: Md2,
        frames: Vec<Vec<[f32; 3]>>,
        triangles: Vec<[u32; 3]>,
        corner_uvs: Vec<[u32; 3]>,
        /// The skin, when one is found beside the file.
        texture: Option<Texture>,
    },
    /// A scan with a base colour texture: its textured surface welded by
    /// position, each corner's texture coordinate id the surface vertex.
    Textured {
        positions: Vec<[f32; 3]>,
        triangles: Vec<[u32; 3]>,
        corner_uvs: Vec<[u32; 3]>,
        texture: Texture,
        /// The repaired mesh, should Melax refuse the welded surface.
        fallback: vitrine_codec::IndexedMesh,
    },
    Mesh(vitrine_codec::IndexedMesh),
}

fn load(path: &Path) -> anyhow::Result<Source> {
    if InputFormat::from_path(path) == Some(InputFormat::Md2) {
        let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
        let model = Md2::parse(&bytes, &ImportOptions::default())
            .with_context(|| format!("reading {}", path.display()))?;
        // Repaired as every other import is, its frames and texture
        // coordinates carried along.
        let (model, repair) = model
            .repaired()
            .with_context(|| format!("repairing {}", path.display()))?;
        if let Some(text) = describe_repair(&repair) {
            eprintln!("repair: {text}");
        }
        let frames = model.frames.iter().map(|f| f.positions()).collect();
        let triangles = model.mesh_triangles();
        // The same corner swap as the triangles (clockwise to counter-clockwise).
        let corner_uvs = model
            .triangles
            .iter()
            .map(|t| [t.st[0], t.st[2], t.st[1]].map(u32::from))
            .collect();
        let texture = md2_texture(path, &model)?;
        return Ok(Source::Md2 {
            model,
            frames,
            triangles,
            corner_uvs,
            texture,
        });
    }
    let source = load_coloured_mesh(path)?;
    if let Some(text) = describe_repair(&source.repair) {
        eprintln!("repair: {text}");
    }
    if let Some(surface) = source.texture {
        let (positions, triangles, corner_uvs) = weld(&surface);
        return Ok(Source::Textured {
            texture: Texture {
                uvs: surface.uvs.clone(),
                surface,
            },
            positions,
            triangles,
            corner_uvs,
            fallback: source.mesh,
        });
    }
    Ok(Source::Mesh(source.mesh))
}

/// The Melax model of a source: frames, triangles, corner texture ids.
fn model_of(source: &Source) -> MelaxModelOwned<'_> {
    match source {
        Source::Md2 {
            frames,
            triangles,
            corner_uvs,
            ..
        } => (frames.clone(), triangles, Some(corner_uvs)),
        Source::Textured {
            positions,
            triangles,
            corner_uvs,
            ..
        } => (vec![positions.clone()], triangles, Some(corner_uvs)),
        Source::Mesh(m) => (vec![m.positions.clone()], &m.triangles, None),
    }
}

type MelaxModelOwned<'s> = (Vec<Vec<[f32; 3]>>, &'s [[u32; 3]], Option<&'s [[u32; 3]]>);

fn chain_of(source: &Source, cost: MelaxCost) -> vitrine_codec::Result<MelaxChain> {
    let (frames, triangles, corner_uvs) = model_of(source);
    melax_chain(&MelaxModel {
        triangles,
        frames: &frames,
        corner_uvs,
        cost,
    })
}

pub fn run(args: LodArgs) -> anyhow::Result<()> {
    if args.levels.is_empty() {
        bail!("--levels needs at least one percentage");
    }
    let mut source = load(&args.input)?;
    let started = std::time::Instant::now();
    let chain = match (chain_of(&source, args.melax_cost.into()), source) {
        (Ok(chain), s) => {
            source = s;
            Ok(chain)
        }
        // Melax needs an oriented manifold: a textured surface that is not
        // one after the weld is cut from the repaired mesh, untextured.
        (Err(e), Source::Textured { fallback, .. }) => {
            eprintln!("warning: the levels leave the texture out: {e}");
            source = Source::Mesh(fallback);
            chain_of(&source, args.melax_cost.into())
        }
        (Err(e), s) => {
            source = s;
            Err(e)
        }
    }
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
            write_glb(&args.output, &source, &levels, args.fps)?;
        }
        LodFormat::Glb => {
            for (level, p) in levels.iter().zip(&args.levels) {
                let out = level_path(&args.output, *p, "glb");
                write_glb(&out, &source, std::slice::from_ref(level), args.fps)?;
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

/// Writes `levels` of `source` as one GLB, with the source's texture and
/// texture coordinates (one GLB vertex per vertex and coordinate pair the
/// levels use) or its vertex colours.
fn write_glb(path: &Path, source: &Source, levels: &[MelaxLevel], fps: f32) -> anyhow::Result<()> {
    let (frames, _, _) = model_of(source);
    let texture = match source {
        Source::Md2 { texture, .. } => texture.as_ref(),
        Source::Textured { texture, .. } => Some(texture),
        Source::Mesh(_) => None,
    };
    let corners: Option<Vec<LevelCorners<'_>>> = levels
        .iter()
        .map(|l| Some((l.triangles.as_slice(), l.corner_uvs.as_deref()?)))
        .collect();
    if let (Some(texture), Some(corners)) = (texture, corners) {
        let split = corner_vertices(&corners)?;
        let frames: Vec<Vec<[f32; 3]>> = frames
            .iter()
            .map(|f| split.vertex.iter().map(|&v| f[v as usize]).collect())
            .collect();
        let uvs = split
            .uv
            .iter()
            .map(|&id| texture.uvs.get(id as usize).copied())
            .collect::<Option<Vec<_>>>()
            .context("a texture coordinate id past the model's coordinates")?;
        return write_file(path, |w| {
            Ok(write_lod_glb(
                &LodGlb {
                    frames: &frames,
                    levels: &split.levels,
                    fps,
                    uvs: Some(&uvs),
                    texture: Some(&texture.surface.image),
                    colors: None,
                },
                w,
            )?)
        });
    }
    let colors = match source {
        Source::Mesh(m) => m.colors.as_deref(),
        _ => None,
    };
    let triangles: Vec<Vec<[u32; 3]>> = levels.iter().map(|l| l.triangles.clone()).collect();
    write_file(path, |w| {
        Ok(write_lod_glb(
            &LodGlb {
                frames: &frames,
                levels: &triangles,
                fps,
                uvs: None,
                texture: None,
                colors,
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
        // The levels index the welded surface's positions.
        Source::Textured { positions, .. } => {
            let welded = vitrine_codec::IndexedMesh {
                positions: positions.clone(),
                colors: None,
                triangles: Vec::new(),
            };
            Ok(mesh_to_md2(&compact(&welded, &level.triangles).0)?)
        }
        Source::Mesh(mesh) => Ok(mesh_to_md2(&compact(mesh, &level.triangles).0)?),
    }
}
