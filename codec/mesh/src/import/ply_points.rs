//! PLY as a point cloud: the vertex element of a PLY file (faces, if any, are
//! skipped) with its positions, optional normals (`nx ny nz`) and optional
//! colour (`red green blue`, integer 0–255 / 0–65535 or float 0–1).
//!
//! A child of the mesh PLY reader, so that it shares its header parser, its
//! ascii and binary sources and its limits; the mesh path is unchanged (it
//! still refuses a PLY without faces).

use super::{
    check_counts, read_with, skip, skip_records, Header, Kind, Payload, Records, Source, WHAT,
};
use crate::import::ImportOptions;
use crate::{Error, Result};

/// The points of a PLY file, as read (nothing estimated or cleaned).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlyPoints {
    pub positions: Vec<[f32; 3]>,
    /// Per point, as in the file (not renormalised), when it has all three of `nx ny nz`.
    pub normals: Option<Vec<[f32; 3]>>,
    /// Per point, 8-bit sRGB, when it has all three colour channels.
    pub colors: Option<Vec<[u8; 3]>>,
}

/// What the point reader does with one vertex property.
#[derive(Clone, Copy)]
enum Slot {
    Coord(usize),
    Normal(usize),
    Colour(usize),
    Skip,
}

/// Reads the vertex element of a PLY file as points. Refused: a file without
/// a vertex element or without scalar `x y z`, no vertices, more vertices than
/// `opts.max_vertices` or than the bytes can hold, non-finite values.
pub fn import_ply_points(bytes: &[u8], opts: &ImportOptions) -> Result<PlyPoints> {
    read_with(bytes, PointsPayload(opts))
}

/// The point reader's payload: the vertex element only.
struct PointsPayload<'a>(&'a ImportOptions);

impl Payload for PointsPayload<'_> {
    type Output = PlyPoints;
    fn read<S: Source>(
        self,
        header: &Header,
        src: &mut S,
        payload_len: usize,
    ) -> Result<PlyPoints> {
        read_points(header, src, payload_len, self.0)
    }
}

fn read_points<S: Source>(
    header: &Header,
    src: &mut S,
    payload_len: usize,
    opts: &ImportOptions,
) -> Result<PlyPoints> {
    let vertex_pos = header
        .elements
        .iter()
        .position(|e| e.name == "vertex")
        .ok_or_else(|| Error::input(WHAT, "has no \"vertex\" element"))?;
    let counts = check_counts(header, payload_len, opts)?;
    // Elements before the vertices are skipped; nothing after them is read.
    for (element, &count) in header.elements.iter().zip(&counts).take(vertex_pos) {
        if !element.props.is_empty() {
            skip_records(Records { element, count }, src)?;
        }
    }
    let records = Records {
        element: &header.elements[vertex_pos],
        count: counts[vertex_pos],
    };
    if records.count == 0 {
        return Err(Error::input(WHAT, "contains no vertices"));
    }
    let slots = slots(records)?;
    let has = |f: fn(Slot) -> Option<usize>| (0..3).all(|a| slots.iter().any(|&s| f(s) == Some(a)));
    let has_normals = has(|s| match s {
        Slot::Normal(a) => Some(a),
        _ => None,
    });
    let has_colour = has(|s| match s {
        Slot::Colour(a) => Some(a),
        _ => None,
    });
    let n = records.count;
    let mut out = PlyPoints {
        positions: Vec::with_capacity(n),
        normals: has_normals.then(|| Vec::with_capacity(n)),
        colors: has_colour.then(|| Vec::with_capacity(n)),
    };
    for i in 0..n {
        let (mut p, mut nrm, mut c) = ([0f32; 3], [0f32; 3], [0u8; 3]);
        for (prop, &slot) in records.element.props.iter().zip(&slots) {
            let fail = |src: &S, f| records.fail(i, src, f);
            match (slot, prop.kind) {
                (Slot::Coord(a), Kind::Scalar(t)) => {
                    p[a] = src.coord(t).map_err(|f| fail(src, f))?
                }
                (Slot::Normal(a), Kind::Scalar(t)) => {
                    nrm[a] = src.coord(t).map_err(|f| fail(src, f))?
                }
                (Slot::Colour(a), Kind::Scalar(t)) => {
                    c[a] = super::colour_u8(src.real(t).map_err(|f| fail(src, f))?, t)
                }
                (_, kind) => skip(src, kind).map_err(|f| fail(src, f))?,
            }
        }
        if !p.iter().chain(&nrm).all(|v| v.is_finite()) {
            return Err(Error::input(
                WHAT,
                format!(
                    "vertex {i} ({}) has a non-finite position or normal",
                    src.location()
                ),
            ));
        }
        out.positions.push(p);
        if let Some(v) = out.normals.as_mut() {
            v.push(nrm);
        }
        if let Some(v) = out.colors.as_mut() {
            v.push(c);
        }
    }
    Ok(out)
}

/// The slot of each vertex property; refused without scalar `x`, `y`, `z`.
fn slots(records: Records<'_>) -> Result<Vec<Slot>> {
    let slots: Vec<Slot> = records
        .element
        .props
        .iter()
        .map(|p| match (p.name.as_str(), p.kind) {
            (name, Kind::Scalar(_)) => match name {
                "x" => Slot::Coord(0),
                "y" => Slot::Coord(1),
                "z" => Slot::Coord(2),
                "nx" => Slot::Normal(0),
                "ny" => Slot::Normal(1),
                "nz" => Slot::Normal(2),
                other => super::colour_channel(other).map_or(Slot::Skip, Slot::Colour),
            },
            _ => Slot::Skip,
        })
        .collect();
    for (axis, name) in ["x", "y", "z"].iter().enumerate() {
        if !slots
            .iter()
            .any(|s| matches!(s, Slot::Coord(a) if *a == axis))
        {
            return Err(Error::input(
                WHAT,
                format!("vertex element has no scalar \"{name}\" property"),
            ));
        }
    }
    Ok(slots)
}
