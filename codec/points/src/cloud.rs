//! The point cloud type shared by the importers, the stream and the splats.

use vitrine_codec::{Error, Result};

/// Points with optional per-point normals and colours.
///
/// Positions are `f32` relative to `origin` (`f64`): georeferenced scans
/// (LAS) have coordinates in the millions of metres, where `f32` would lose
/// millimetres; relative to the cloud's own corner it keeps them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointCloud {
    /// Added to every position to get the file's coordinates.
    pub origin: [f64; 3],
    pub positions: Vec<[f32; 3]>,
    /// Unit normals, one per point.
    pub normals: Option<Vec<[f32; 3]>>,
    /// 8-bit sRGB colour, one per point.
    pub colours: Option<Vec<[u8; 3]>>,
}

impl PointCloud {
    /// A cloud of positions only, at origin zero.
    pub fn from_positions(positions: Vec<[f32; 3]>) -> Self {
        PointCloud {
            positions,
            ..Default::default()
        }
    }

    pub fn len(&self) -> usize {
        self.positions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Err unless positions and normals are finite and the attribute arrays
    /// have one entry per point.
    pub fn validate(&self) -> Result<()> {
        let n = self.positions.len();
        if self.normals.as_ref().is_some_and(|v| v.len() != n)
            || self.colours.as_ref().is_some_and(|v| v.len() != n)
        {
            return Err(Error::Parameter(
                "point cloud: normals/colours do not have one entry per point".into(),
            ));
        }
        let finite = |v: &[[f32; 3]]| v.iter().flatten().all(|x| x.is_finite());
        if !finite(&self.positions) || self.normals.as_deref().is_some_and(|v| !finite(v)) {
            return Err(Error::Parameter(
                "point cloud: non-finite position or normal".into(),
            ));
        }
        Ok(())
    }
}
