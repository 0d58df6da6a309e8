//! The point-stream decoder: a header, then one level chunk at a time.

use vitrine_codec::entropy::RangeDecoder;
use vitrine_codec::{Error, Result};

use super::attr::{octahedral_decode, root_prediction, Attr};
use super::format::{read_chunk, PointHeader};
use super::models::Models;
use super::neighbourhood::Neighbourhood;
use super::predict::{child_centre, parent_centre, Neighbours, AHEAD, BEHIND};
use crate::PointCloud;

/// Budgets for decoding untrusted streams.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Most points a stream may declare.
    pub max_points: u32,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_points: 50_000_000,
        }
    }
}

fn corrupt(detail: &str) -> Error {
    Error::input("point stream", detail)
}

#[derive(Clone, Copy)]
struct Cell {
    /// Cell coordinates at the current depth.
    at: [u32; 3],
    /// Its representative point.
    rep: u32,
    /// Parent's child count − 1.
    class: u8,
    /// The representative's attributes (a copy: predictions read the
    /// cells near in coding order, not points scattered over `attrs`).
    attr: Attr,
}

/// Decodes a stream level by level; after each level it holds every point
/// so far (positions are cell centres until the finest level).
pub struct PointDecoder {
    header: PointHeader,
    models: Models,
    neighbourhood: Neighbourhood,
    level: usize,
    depth: u8,
    cells: Vec<Cell>,
    attrs: Vec<Attr>,
    /// Quantized positions of the points (cell corners before the finest level).
    quantized: Vec<[u32; 3]>,
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    colours: Vec<[u8; 3]>,
    failed: bool,
}

impl std::fmt::Debug for PointDecoder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PointDecoder")
            .field("header", &self.header)
            .field("level", &self.level)
            .field("points", &self.positions.len())
            .finish_non_exhaustive()
    }
}

impl PointDecoder {
    /// Starts on a stream's header (`bytes` may continue past it).
    pub fn new(bytes: &[u8], limits: Limits) -> Result<Self> {
        let header = PointHeader::parse(bytes)?;
        if header.points > limits.max_points {
            return Err(Error::Limit(format!(
                "point stream declares {} points, more than the limit of {}",
                header.points, limits.max_points
            )));
        }
        let models = Models::new(header.has_normals(), header.has_colours);
        let neighbourhood = if header.version >= 3 {
            Neighbourhood::wide()
        } else {
            Neighbourhood::default()
        };
        Ok(PointDecoder {
            header,
            models,
            neighbourhood,
            level: 0,
            depth: 0,
            cells: Vec::new(),
            attrs: Vec::new(),
            quantized: Vec::new(),
            positions: Vec::new(),
            normals: Vec::new(),
            colours: Vec::new(),
            failed: false,
        })
    }

    pub fn header(&self) -> &PointHeader {
        &self.header
    }

    /// Levels decoded so far.
    pub fn level(&self) -> usize {
        self.level
    }

    pub fn is_complete(&self) -> bool {
        self.level == self.header.levels()
    }

    pub fn point_count(&self) -> usize {
        self.positions.len()
    }

    /// Dequantized positions (relative to the header's origin).
    pub fn positions(&self) -> &[[f32; 3]] {
        &self.positions
    }

    /// Quantized positions; exact once [`is_complete`](Self::is_complete),
    /// before that the corner of each point's cell at the current depth.
    pub fn quantized(&self) -> &[[u32; 3]] {
        &self.quantized
    }

    pub fn normals(&self) -> Option<&[[f32; 3]]> {
        self.header.has_normals().then_some(&self.normals[..])
    }

    /// Octahedral normal codes, when the stream has normals.
    pub fn normal_codes(&self) -> Option<Vec<[u16; 2]>> {
        self.header
            .has_normals()
            .then(|| self.attrs.iter().map(|a| a.normal).collect())
    }

    pub fn colours(&self) -> Option<&[[u8; 3]]> {
        self.header.has_colours.then_some(&self.colours[..])
    }

    /// The points so far as a cloud.
    pub fn to_cloud(&self) -> PointCloud {
        PointCloud {
            origin: self.header.origin,
            positions: self.positions.clone(),
            normals: self.normals().map(<[_]>::to_vec),
            colours: self.colours().map(<[_]>::to_vec),
        }
    }

    /// Decodes the next level from `chunk` (exactly one chunk, framing
    /// included). After an error the decoder refuses further levels.
    pub fn apply_level(&mut self, chunk: &[u8]) -> Result<()> {
        if self.failed {
            return Err(corrupt("an earlier level failed to decode"));
        }
        if self.is_complete() {
            return Err(corrupt("more level chunks than the header declares"));
        }
        let r = self.apply(chunk);
        if r.is_err() {
            self.failed = true;
        }
        r
    }

    fn new_point(&mut self, a: Attr) -> Result<u32> {
        if self.attrs.len() >= self.header.points as usize {
            return Err(corrupt("more points than the header declares"));
        }
        self.attrs.push(a);
        Ok((self.attrs.len() - 1) as u32)
    }

    fn apply(&mut self, chunk: &[u8]) -> Result<()> {
        let (payload, count, len) = read_chunk(chunk)?;
        if len != chunk.len() {
            return Err(corrupt("bytes after the level chunk"));
        }
        if count > self.header.points || (count as usize) < self.attrs.len() {
            return Err(corrupt("level point count out of range"));
        }
        let mut dec = RangeDecoder::new(payload);
        let nb = self.header.normal_bits;
        let normal_max = if nb == 0 {
            0
        } else {
            ((1u32 << nb) - 1) as u16
        };
        let bad_attr = || corrupt("attribute residual out of range");
        if self.level == 0 {
            let a = self
                .models
                .decode_attr(&mut dec, root_prediction(nb), normal_max)
                .ok_or_else(bad_attr)?;
            let rep = self.new_point(a)?;
            self.cells.push(Cell {
                at: [0; 3],
                rep,
                class: 7,
                attr: a,
            });
        }
        let last = self.header.level_depths[self.level];
        while self.depth < last {
            let cells = std::mem::take(&mut self.cells);
            let mut next: Vec<Cell> = Vec::with_capacity(cells.len().min(count as usize));
            let v2 = self.header.version >= 2;
            if v2 {
                let depth = u32::from(self.depth);
                self.neighbourhood
                    .start_depth(depth, depth + 1 == u32::from(self.header.bits));
            }
            for (i, cell) in cells.iter().enumerate() {
                dec.check_overrun()?;
                let mask = if self.header.version >= 3 {
                    let around = self.neighbourhood.around(cell.at);
                    let mask = self.models.masks_v3.decode(&mut dec, &around, cell.class);
                    self.neighbourhood.record(mask);
                    mask
                } else if v2 {
                    let around = self.neighbourhood.around(cell.at);
                    let mask = self.models.decode_mask_v2(&mut dec, &around, cell.class);
                    self.neighbourhood.record(mask);
                    mask
                } else {
                    self.models.decode_mask(&mut dec, cell.class)
                };
                let class = (mask.count_ones() - 1) as u8;
                let mut first = true;
                for k in 0..8u32 {
                    if mask & (1 << k) == 0 {
                        continue;
                    }
                    let at = [0, 1, 2].map(|a| cell.at[a] * 2 + ((k >> a) & 1));
                    let (rep, attr) = if first {
                        (cell.rep, cell.attr)
                    } else {
                        let a = if self.header.predicted_attributes {
                            let h = &self.header;
                            let mut near = Neighbours::new(at, h.has_normals(), h.has_colours);
                            let behind = next.iter().rev().take(BEHIND);
                            let ahead = cells[i + 1..].iter().take(AHEAD);
                            near.offer(
                                behind
                                    .map(|c| (child_centre(c.at), c.attr))
                                    .chain(ahead.map(|c| (parent_centre(c.at), c.attr))),
                            );
                            let prediction = near.predict(cell.attr);
                            self.models
                                .decode_predicted(&mut dec, &prediction, normal_max)
                        } else {
                            self.models.decode_attr(&mut dec, cell.attr, normal_max)
                        };
                        let a = a.ok_or_else(bad_attr)?;
                        (self.new_point(a)?, a)
                    };
                    first = false;
                    next.push(Cell {
                        at,
                        rep,
                        class,
                        attr,
                    });
                }
            }
            self.cells = next;
            self.depth += 1;
        }
        // Points are the cells' representatives, in id order.
        let side = 1u32 << (self.header.bits - self.depth);
        self.quantized.resize(self.attrs.len(), [0; 3]);
        for cell in &self.cells {
            self.quantized[cell.rep as usize] = cell.at.map(|v| v * side);
        }
        if self.depth == self.header.bits {
            for i in 0..self.cells.len() {
                dec.check_overrun()?;
                let extra = self.models.decode_duplicates(&mut dec);
                let cell = self.cells[i];
                if u64::from(extra) > u64::from(self.header.points) - self.attrs.len() as u64 {
                    return Err(corrupt("more points than the header declares"));
                }
                for _ in 0..extra {
                    let a = self
                        .models
                        .decode_attr(&mut dec, cell.attr, normal_max)
                        .ok_or_else(bad_attr)?;
                    self.new_point(a)?;
                    self.quantized.push(cell.at);
                }
            }
        }
        dec.check_overrun()?;
        if self.attrs.len() != count as usize {
            return Err(corrupt(
                "level decodes to a different point count than it declares",
            ));
        }
        self.level += 1;
        if self.is_complete() && self.attrs.len() != self.header.points as usize {
            return Err(corrupt("stream decodes to fewer points than it declares"));
        }
        self.refresh(side);
        Ok(())
    }

    /// Recomputes the float outputs for the points decoded so far.
    fn refresh(&mut self, side: u32) {
        let h = &self.header;
        let centre = (side - 1) as f32 * 0.5;
        self.positions.clear();
        self.positions.extend(
            self.quantized
                .iter()
                .map(|q| [0, 1, 2].map(|a| h.min[a] + (q[a] as f32 + centre) * h.step)),
        );
        let done = self.normals.len();
        if h.has_normals() {
            let nb = h.normal_bits;
            let new = self.attrs[done..]
                .iter()
                .map(|a| octahedral_decode(a.normal, nb));
            self.normals.extend(new);
        }
        if h.has_colours {
            let done = self.colours.len();
            let new = self.attrs[done..].iter().map(|a| a.colour);
            self.colours.extend(new);
        }
    }
}

/// Decodes the header and up to `max_levels` level chunks (all when
/// `None`) of a stream; `bytes` may stop after any whole chunk.
pub fn decode(bytes: &[u8], max_levels: Option<usize>, limits: Limits) -> Result<PointDecoder> {
    let mut d = PointDecoder::new(bytes, limits)?;
    let mut at = d.header().len();
    let want = max_levels.unwrap_or(usize::MAX).min(d.header().levels());
    while d.level() < want && at < bytes.len() {
        let (_, _, len) = read_chunk(&bytes[at..])?;
        d.apply_level(&bytes[at..at + len])?;
        at += len;
    }
    if max_levels.is_none() && !d.is_complete() {
        return Err(corrupt("truncated: the stream ends before its last level"));
    }
    Ok(d)
}

/// Convenience alias for what [`decode`] returns.
pub type DecodedPoints = PointDecoder;
