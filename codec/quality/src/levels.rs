//! Quality of every level of a stream against the original: the curves the
//! thesis compares colour modes with (Hausdorff, Roy colour RMSE,
//! Lindstrom–Turk image RMSE), computed by the codec so the CLI, the
//! database and benchmarks all use the same numbers.

use serde::{Deserialize, Serialize};

use vitrine_colour::ccc::CellComplex;
use vitrine_mesh::import::TexturedSurface;

use crate::metrics::{
    self, ConstantColour, ImageReference, RenderOptions, SurfaceShader, VertexColours,
};
use crate::TextureShader;
use vitrine_codec::{Decoder, IndexedMesh, Limits, Result, StreamIndex};

/// Metrics of one level.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LevelQuality {
    pub level: usize,
    pub vertices: usize,
    pub faces: usize,
    /// Symmetric Hausdorff distance over the bounding-box diagonal.
    pub hausdorff: f64,
    /// Roy et al. colour RMSE (0–255), when both sides have colour.
    pub roy_rmse: Option<f64>,
    /// Lindstrom–Turk luma RMSE (0–255) over 24 views.
    pub image_rmse: f64,
}

/// The original a stream is measured against.
pub struct Original<'a> {
    /// The full-resolution mesh, with per-vertex colour when it has colour
    /// (sampled from the texture for a textured scan).
    pub mesh: &'a IndexedMesh,
    /// The photographic texture, rendered through its UVs for the image metric.
    pub texture: Option<&'a TexturedSurface>,
}

/// Knobs for [`stream_quality`].
#[derive(Clone, Copy, Debug)]
pub struct QualityOptions {
    pub image_size: u32,
    pub hausdorff_samples: usize,
}

impl Default for QualityOptions {
    fn default() -> Self {
        QualityOptions {
            image_size: 512,
            hausdorff_samples: 200_000,
        }
    }
}

/// Measures each level of `stream` against `original`. Colour at a level is
/// the stream's own per-vertex colour, or the cell complex's lookup when
/// `complex` is given, or clay grey.
pub fn stream_quality(
    stream: &[u8],
    complex: Option<&CellComplex>,
    original: &Original<'_>,
    options: &QualityOptions,
) -> Result<Vec<LevelQuality>> {
    let index = StreamIndex::parse(stream)?;
    let reference_mesh;
    let texture_shader;
    let vertex_shader;
    let (ref_mesh, ref_shader): (&IndexedMesh, &dyn SurfaceShader) =
        match (original.texture, VertexColours::new(original.mesh)) {
            (Some(t), _) => {
                reference_mesh = t.as_mesh();
                texture_shader = TextureShader(t);
                (&reference_mesh, &texture_shader)
            }
            (None, Some(v)) => {
                vertex_shader = v;
                (original.mesh, &vertex_shader)
            }
            (None, None) => (original.mesh, &ConstantColour::CLAY),
        };
    let reference = ImageReference::new(
        ref_mesh,
        ref_shader,
        &RenderOptions::square(options.image_size),
    );
    let distances = metrics::HausdorffReference::new(original.mesh, options.hausdorff_samples);
    let mut decoder = Decoder::new(&stream[index.base.clone()], Limits::default())?;
    let mut out = Vec::with_capacity(index.batches.len() + 1);
    for level in 0..=index.batches.len() {
        if level > 0 {
            decoder.apply_batch(&stream[index.batches[level - 1].clone()])?;
        }
        let mut mesh = decoder.to_mesh();
        if let Some(c) = complex {
            mesh.colors = Some(
                mesh.positions
                    .iter()
                    .map(|&p| {
                        c.colour_at(p.into())
                            .map(|v| (v * 255.0).round().clamp(0.0, 255.0) as u8)
                    })
                    .collect(),
            );
        }
        let h = distances.distance_to(&mesh);
        let roy = metrics::roy_colour_rmse(original.mesh, &mesh).ok();
        let vertex;
        let shader: &dyn SurfaceShader = match complex {
            Some(c) => c,
            None => match VertexColours::new(&mesh) {
                Some(v) => {
                    vertex = v;
                    &vertex
                }
                None => &ConstantColour::CLAY,
            },
        };
        let image = reference.rmse(&mesh, shader);
        out.push(LevelQuality {
            level,
            vertices: mesh.positions.len(),
            faces: mesh.triangles.len(),
            hausdorff: h.relative(),
            roy_rmse: roy,
            image_rmse: image,
        });
    }
    Ok(out)
}
