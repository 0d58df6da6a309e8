//! The per-vertex colour RMSE of Roy, Foufou and Truchetet (2004).

use super::kdtree::KdTree;
use super::parallel_map;
use glam::DVec3;
use vitrine_codec::IndexedMesh;

const CHUNK: usize = 4096;

/// Why [`roy_colour_rmse`] could not compare two meshes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ColourError {
    #[error("the original mesh has no per-vertex colour")]
    OriginalHasNoColour,
    #[error("the approximation has no per-vertex colour")]
    ApproximationHasNoColour,
    #[error("a mesh has {colours} colours for {vertices} vertices")]
    ColourCountMismatch { colours: usize, vertices: usize },
    #[error("the approximation has no vertices")]
    EmptyApproximation,
}

/// The colour RMSE of Roy, Foufou and Truchetet, "Mesh comparison using
/// attribute deviation metric" (Int. J. Image and Graphics 4(1), 2004), as
/// the thesis uses it: every vertex of `original` is matched to the nearest
/// vertex (Euclidean distance in space) of `approx`, and the colour error is
///
/// `sqrt( Σ_v |c_original(v) − c_approx(nearest(v))|² / n )`
///
/// where `|·|` is the Euclidean distance between the two sRGB colours in 0–255
/// units per channel (no conversion to L\*a\*b\*), so the result lies in
/// `0..=441.7` (`255·√3`). Equally near vertices (duplicated positions) are
/// resolved in favour of the closest colour. All vertices count, whether or
/// not a triangle uses them. An original without vertices gives 0.
pub fn roy_colour_rmse(original: &IndexedMesh, approx: &IndexedMesh) -> Result<f64, ColourError> {
    let oc = colours(original).ok_or(ColourError::OriginalHasNoColour)??;
    let ac = colours(approx).ok_or(ColourError::ApproximationHasNoColour)??;
    if original.positions.is_empty() {
        return Ok(0.0);
    }
    if approx.positions.is_empty() {
        return Err(ColourError::EmptyApproximation);
    }
    let tree = KdTree::new(
        approx
            .positions
            .iter()
            .map(|p| DVec3::from(p.map(f64::from))),
    );
    let n = original.positions.len();
    let sums = parallel_map(n.div_ceil(CHUNK), |chunk| {
        let range = chunk * CHUNK..((chunk + 1) * CHUNK).min(n);
        let mut sum = 0u64;
        for v in range {
            let q = DVec3::from(original.positions[v].map(f64::from));
            let c = oc[v];
            let nearest = tree
                .nearest(q, |i| distance_squared(c, ac[i as usize]))
                .expect("the approximation has vertices");
            sum += distance_squared(c, ac[nearest as usize]);
        }
        sum
    });
    let total: u64 = sums.iter().sum();
    Ok((total as f64 / n as f64).sqrt())
}

fn colours(mesh: &IndexedMesh) -> Option<Result<&[[u8; 3]], ColourError>> {
    let c = mesh.colors.as_deref()?;
    Some(if c.len() == mesh.positions.len() {
        Ok(c)
    } else {
        Err(ColourError::ColourCountMismatch {
            colours: c.len(),
            vertices: mesh.positions.len(),
        })
    })
}

fn distance_squared(a: [u8; 3], b: [u8; 3]) -> u64 {
    (0..3)
        .map(|k| (i64::from(a[k]) - i64::from(b[k])).pow(2) as u64)
        .sum()
}
