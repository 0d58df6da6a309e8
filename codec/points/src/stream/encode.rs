//! The point-stream encoder.

use vitrine_codec::entropy::RangeEncoder;
use vitrine_codec::{Error, Result};

use super::attr::{octahedral_encode, root_prediction, Attr};
use super::context::morton;
use super::format::{PointHeader, MAX_BITS, VERSION, VERSIONS};
use super::models::Models;
use super::neighbourhood::Neighbourhood;
use super::predict::{child_centre, parent_centre, Neighbours, AHEAD, BEHIND};
use crate::PointCloud;

/// How to encode.
#[derive(Clone, Debug)]
pub struct EncodeOptions {
    /// Position bits per axis (1..=20): the cloud's bounding cube split into
    /// 2^bits cells per axis.
    pub bits: u8,
    /// Octahedral bits per normal component (4..=15).
    pub normal_bits: u8,
    /// The first level holds at least this many points (or all of them).
    pub base_points: usize,
    /// Code the cloud's normals, when it has them.
    pub normals: bool,
    /// Code the cloud's colours, when it has them.
    pub colours: bool,
    /// Stream format version to write (1, 2 or 3; 2 and 3 code positions smaller).
    pub version: u8,
    /// Code new points' normals and colours against a prediction from the
    /// decoded neighbourhood (header flag bit 2, any version) instead of
    /// their parent's representative alone: 3–10 % smaller normals and
    /// 3–12 % smaller colours on the clouds measured, for 1.13–1.21× the
    /// WebAssembly decode time, which the bytes saved outweigh at 10 Mbit/s
    /// (session 34). Decoders before session 34 refuse such streams.
    pub predict_attributes: bool,
}

impl Default for EncodeOptions {
    fn default() -> Self {
        EncodeOptions {
            bits: 14,
            normal_bits: 11,
            base_points: 4096,
            normals: true,
            colours: true,
            version: VERSION,
            predict_attributes: true,
        }
    }
}

/// An encoded cloud and what the encoder knows about it.
#[derive(Clone, Debug)]
pub struct EncodedPoints {
    pub bytes: Vec<u8>,
    pub header: PointHeader,
    /// Byte range of each level chunk in `bytes` (the header precedes them).
    pub chunks: Vec<std::ops::Range<usize>>,
    /// Points after each level (cumulative).
    pub level_points: Vec<u32>,
    /// The input index of each point, in stream order.
    pub order: Vec<u32>,
    /// Quantized positions in stream order (what the decoder reproduces).
    pub quantized: Vec<[u32; 3]>,
    /// Octahedral normals in stream order, when coded.
    pub normals: Option<Vec<[u16; 2]>>,
}

/// Quantization of a cloud's positions: the bounding cube's corner and the
/// cell size for `bits` bits.
fn quantization(positions: &[[f32; 3]], bits: u8) -> ([f32; 3], f32) {
    let (min, max) = crate::grid::bounds(positions);
    let extent = (0..3).map(|a| max[a] - min[a]).fold(0f32, f32::max);
    let cells = ((1u32 << bits) - 1) as f32;
    let step = if extent > 0.0 { extent / cells } else { 1.0 };
    (min, step)
}

/// The level depths: the first where the cells reach `base_points` (or the
/// finest), then each depth that at least doubles the points of the last.
fn level_depths(cells: &[usize], base_points: usize) -> Vec<u8> {
    let finest = cells.len() - 1;
    let first = (0..=finest)
        .find(|&d| cells[d] >= base_points)
        .unwrap_or(finest);
    let mut depths = vec![first as u8];
    let mut last = cells[first];
    for (d, &c) in cells.iter().enumerate().skip(first + 1) {
        if c >= 2 * last || d == finest {
            depths.push(d as u8);
            last = c;
        }
    }
    depths
}

struct Cell {
    /// Coordinates at the current depth.
    at: [u32; 3],
    start: u32,
    end: u32,
    /// Parent's child count − 1.
    class: u8,
}

/// Encodes a cloud (at least one point, finite) as a progressive stream.
pub fn encode(cloud: &PointCloud, opts: &EncodeOptions) -> Result<EncodedPoints> {
    cloud.validate()?;
    let n = cloud.len();
    if n == 0 {
        return Err(Error::Parameter(
            "point stream: the cloud has no points".into(),
        ));
    }
    let n32 = u32::try_from(n).map_err(|_| Error::Limit("more than 2^32 − 1 points".into()))?;
    if !(1..=MAX_BITS).contains(&opts.bits) {
        return Err(Error::Parameter(format!(
            "position bits {} outside 1..=20",
            opts.bits
        )));
    }
    let normals = cloud.normals.as_ref().filter(|_| opts.normals);
    let colours = cloud.colours.as_ref().filter(|_| opts.colours);
    if normals.is_some() && !(4..=15).contains(&opts.normal_bits) {
        return Err(Error::Parameter(format!(
            "normal bits {} outside 4..=15",
            opts.normal_bits
        )));
    }
    if !VERSIONS.contains(&opts.version) {
        return Err(Error::Parameter(format!(
            "point stream version {} (this encoder writes {} to {})",
            opts.version,
            VERSIONS.start(),
            VERSIONS.end()
        )));
    }
    let bits = opts.bits;
    let normal_bits = if normals.is_some() {
        opts.normal_bits
    } else {
        0
    };
    let (min, step) = quantization(&cloud.positions, bits);
    let qmax = (1u32 << bits) - 1;
    let quant: Vec<[u32; 3]> = cloud
        .positions
        .iter()
        .map(|p| [0, 1, 2].map(|a| (((p[a] - min[a]) / step).round().max(0.0) as u32).min(qmax)))
        .collect();
    let attrs: Vec<Attr> = (0..n)
        .map(|i| Attr {
            normal: normals.map_or([0; 2], |v| octahedral_encode(v[i], normal_bits)),
            colour: colours.map_or([0; 3], |v| v[i]),
        })
        .collect();
    let mut sorted: Vec<(u64, u32)> = quant
        .iter()
        .enumerate()
        .map(|(i, q)| (morton(*q), i as u32))
        .collect();
    radsort::sort_by_key(&mut sorted, |s| s.0); // stable: ties keep input order
    let b = u32::from(bits);
    let cells_at: Vec<usize> = (0..=b)
        .map(|d| {
            let shift = 3 * (b - d);
            1 + sorted
                .windows(2)
                .filter(|w| w[0].0 >> shift != w[1].0 >> shift)
                .count()
        })
        .collect();
    let header = PointHeader {
        version: opts.version,
        bits,
        normal_bits,
        has_colours: colours.is_some(),
        predicted_attributes: opts.predict_attributes && (normals.is_some() || colours.is_some()),
        origin: cloud.origin,
        min,
        step,
        points: n32,
        level_depths: level_depths(&cells_at, opts.base_points.max(1)),
    };
    let mut bytes = Vec::new();
    header.write(&mut bytes);
    let mut models = Models::new(normals.is_some(), colours.is_some());
    let mut order: Vec<u32> = Vec::with_capacity(n);
    let mut neighbourhood = if header.version >= 3 {
        Neighbourhood::wide()
    } else {
        Neighbourhood::default()
    };
    let mut cells = vec![Cell {
        at: [0; 3],
        start: 0,
        end: n32,
        class: 7,
    }];
    let mut chunks = Vec::new();
    let mut level_points = Vec::new();
    let mut depth = 0u32;
    for (level, &last) in header.level_depths.iter().enumerate() {
        let mut enc = RangeEncoder::new();
        if level == 0 {
            let root = sorted[0].1;
            order.push(root);
            models.encode_attr(&mut enc, attrs[root as usize], root_prediction(normal_bits));
        }
        while depth < u32::from(last) {
            let shift = 3 * (b - depth - 1);
            let mut next: Vec<Cell> = Vec::with_capacity(cells.len() * 2);
            if header.version >= 2 {
                neighbourhood.start_depth(depth, depth + 1 == b);
            }
            for (i, cell) in cells.iter().enumerate() {
                let parent_rep = sorted[cell.start as usize].1;
                let mut mask = 0u8;
                let mut children = [(0u32, 0u32); 8];
                let mut s = cell.start;
                while s < cell.end {
                    let k = ((sorted[s as usize].0 >> shift) & 7) as usize;
                    let mut e = s + 1;
                    while e < cell.end && ((sorted[e as usize].0 >> shift) & 7) as usize == k {
                        e += 1;
                    }
                    mask |= 1 << k;
                    children[k] = (s, e);
                    s = e;
                }
                if header.version >= 3 {
                    let around = neighbourhood.around(cell.at);
                    models.masks_v3.encode(&mut enc, &around, cell.class, mask);
                    neighbourhood.record(mask);
                } else if header.version >= 2 {
                    let around = neighbourhood.around(cell.at);
                    models.encode_mask_v2(&mut enc, &around, cell.class, mask);
                    neighbourhood.record(mask);
                } else {
                    models.encode_mask(&mut enc, cell.class, mask);
                }
                let class = (mask.count_ones() - 1) as u8;
                let mut first = true;
                for (k, &(s, e)) in children.iter().enumerate() {
                    if mask & (1 << k) == 0 {
                        continue;
                    }
                    let k = k as u32;
                    let at = [0, 1, 2].map(|a| cell.at[a] * 2 + ((k >> a) & 1));
                    if !first {
                        let rep = sorted[s as usize].1;
                        order.push(rep);
                        let (a, p) = (attrs[rep as usize], attrs[parent_rep as usize]);
                        if header.predicted_attributes {
                            let attr_of = |c: &Cell| attrs[sorted[c.start as usize].1 as usize];
                            let mut near =
                                Neighbours::new(at, normals.is_some(), colours.is_some());
                            let behind = next.iter().rev().take(BEHIND);
                            let ahead = cells[i + 1..].iter().take(AHEAD);
                            near.offer(
                                behind
                                    .map(|c| (child_centre(c.at), attr_of(c)))
                                    .chain(ahead.map(|c| (parent_centre(c.at), attr_of(c)))),
                            );
                            let prediction = near.predict(p);
                            models.encode_predicted(&mut enc, a, &prediction);
                        } else {
                            models.encode_attr(&mut enc, a, p);
                        }
                    }
                    first = false;
                    next.push(Cell {
                        at,
                        start: s,
                        end: e,
                        class,
                    });
                }
            }
            cells = next;
            depth += 1;
        }
        if depth == b {
            for cell in &cells {
                let rep = sorted[cell.start as usize].1;
                models.encode_duplicates(&mut enc, cell.end - cell.start - 1);
                for &(_, i) in &sorted[cell.start as usize + 1..cell.end as usize] {
                    order.push(i);
                    models.encode_attr(&mut enc, attrs[i as usize], attrs[rep as usize]);
                }
            }
        }
        let payload = enc.finish();
        let start = bytes.len();
        bytes.extend_from_slice(&(payload.len() as u32).to_le_bytes());
        bytes.extend_from_slice(&(order.len() as u32).to_le_bytes());
        bytes.extend_from_slice(&payload);
        chunks.push(start..bytes.len());
        level_points.push(order.len() as u32);
    }
    debug_assert_eq!(order.len(), n);
    let quantized = order.iter().map(|&i| quant[i as usize]).collect();
    let normals = normals.map(|_| order.iter().map(|&i| attrs[i as usize].normal).collect());
    Ok(EncodedPoints {
        bytes,
        header,
        chunks,
        level_points,
        order,
        quantized,
        normals,
    })
}
