//! Point-cloud importers: PLY (the vertex element; faces, if any, ignored)
//! through `vitrine-mesh`'s PLY reader, and LAS/LAZ through the `las` crate.

use std::path::Path;

use vitrine_codec::{Error, Result};
use vitrine_mesh::import::{import_ply_points, ImportOptions};

use crate::PointCloud;

/// The point-cloud file formats this module reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PointFormat {
    Ply,
    /// ASPRS LAS, and LAZ (its compressed form).
    Las,
}

impl PointFormat {
    /// The format a file name's extension stands for (case-insensitive).
    pub fn from_path(p: &Path) -> Option<Self> {
        let ext = p.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "ply" => Some(PointFormat::Ply),
            "las" | "laz" => Some(PointFormat::Las),
            _ => None,
        }
    }

    /// Guesses the format from the first bytes of a file.
    pub fn sniff(bytes: &[u8]) -> Option<Self> {
        if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r") {
            Some(PointFormat::Ply)
        } else if bytes.starts_with(b"LASF") {
            Some(PointFormat::Las)
        } else {
            None
        }
    }
}

/// Reads a point cloud from a file's bytes (format sniffed). `max_points`
/// bounds what a header may declare.
pub fn import_bytes(bytes: &[u8], max_points: usize) -> Result<PointCloud> {
    match PointFormat::sniff(bytes) {
        Some(PointFormat::Ply) => ply(bytes, max_points),
        Some(PointFormat::Las) => las(bytes.to_vec(), max_points),
        None => Err(Error::input(
            "point cloud file",
            "neither PLY (\"ply\") nor LAS/LAZ (\"LASF\")",
        )),
    }
}

/// Reads a point cloud from a file.
pub fn import_path(path: &Path, max_points: usize) -> Result<PointCloud> {
    let bytes = std::fs::read(path).map_err(|e| {
        Error::Io(std::io::Error::new(
            e.kind(),
            format!("{}: {e}", path.display()),
        ))
    })?;
    import_bytes(&bytes, max_points)
}

fn ply(bytes: &[u8], max_points: usize) -> Result<PointCloud> {
    let opts = ImportOptions {
        max_vertices: max_points,
        ..ImportOptions::default()
    };
    let p = import_ply_points(bytes, &opts)?;
    let normals = p.normals.map(|v| v.into_iter().map(unit_or_z).collect());
    Ok(PointCloud {
        origin: [0.0; 3],
        positions: p.positions,
        normals,
        colours: p.colors,
    })
}

/// A file's normal made unit length; a zero one becomes +z.
fn unit_or_z(n: [f32; 3]) -> [f32; 3] {
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if l > 0.0 && l.is_finite() {
        n.map(|v| v / l)
    } else {
        [0.0, 0.0, 1.0]
    }
}

const LAS: &str = "LAS file";

fn las(bytes: Vec<u8>, max_points: usize) -> Result<PointCloud> {
    let len = bytes.len() as u64;
    let mut reader =
        las::Reader::new(std::io::Cursor::new(bytes)).map_err(|e| Error::input(LAS, e))?;
    let header = reader.header();
    let declared = header.number_of_points();
    let record = u64::from(header.point_format().len());
    let compressed = header.point_format().is_compressed;
    // Uncompressed records must fit in the file; LAZ is bounded by the limit
    // alone (and its decoder reads what is there, not what is claimed).
    if !compressed && declared.saturating_mul(record) > len {
        return Err(Error::input(
            LAS,
            format!("declares {declared} points of {record} bytes but has {len} bytes"),
        ));
    }
    if declared > max_points as u64 {
        return Err(Error::Limit(format!(
            "{LAS} declares {declared} points, more than the limit of {max_points}"
        )));
    }
    let bounds = header.bounds();
    let origin = [bounds.min.x, bounds.min.y, bounds.min.z];
    let has_colour = header.point_format().has_color;
    let mut cloud = PointCloud {
        origin,
        positions: Vec::with_capacity(declared.min(len / 20 + 1) as usize),
        normals: None,
        colours: None,
    };
    let mut wide: Option<Vec<[u16; 3]>> = has_colour.then(Vec::new);
    for (i, point) in reader.points().enumerate() {
        if i >= max_points {
            return Err(Error::Limit(format!(
                "{LAS}: more than {max_points} points"
            )));
        }
        let point = point.map_err(|e| Error::input(LAS, format!("point {i}: {e}")))?;
        let p = [
            point.x - origin[0],
            point.y - origin[1],
            point.z - origin[2],
        ];
        if !p.iter().all(|v| v.is_finite()) {
            return Err(Error::input(LAS, format!("point {i} is not finite")));
        }
        cloud.positions.push(p.map(|v| v as f32));
        if let Some(c) = wide.as_mut() {
            let col = point.color.unwrap_or_default();
            // LAS colours are 16-bit; files written by 8-bit tools leave the
            // high byte zero, which `to_u8` below would turn black.
            c.push([col.red, col.green, col.blue]);
        }
    }
    if cloud.positions.is_empty() {
        return Err(Error::input(LAS, "contains no points"));
    }
    cloud.colours = wide.map(to_u8);
    Ok(cloud)
}

/// LAS 16-bit colour to 8 bits: full-range files are scaled, files whose
/// values all fit in 8 bits (written by 8-bit tools) are kept as they are.
fn to_u8(c: Vec<[u16; 3]>) -> Vec<[u8; 3]> {
    let eight_bit = c.iter().flatten().all(|&v| v <= 255);
    c.into_iter()
        .map(|v| v.map(|x| if eight_bit { x as u8 } else { (x >> 8) as u8 }))
        .collect()
}
