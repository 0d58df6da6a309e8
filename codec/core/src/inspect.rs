//! Per-level byte breakdown of a stream, read from section lengths only.

use crate::decoder::read_pass;
use crate::format::{ChunkHeader, Reader, BASE_TAG, BATCH_TAG, NESTED_VERSION, PARTED_TAG};
use crate::gates::PassKind;
use crate::{Result, StreamIndex};

/// Where the bytes of one level went.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LevelBreakdown {
    pub vertices: u32,
    pub faces: u32,
    /// Whole chunk, framing included.
    pub bytes: u32,
    pub connectivity: u32,
    pub geometry: u32,
    pub colour: u32,
    /// Chunk header, seeds and section lengths.
    pub overhead: u32,
}

/// One entry per level; entry 0 is the base mesh (all its payload counted as geometry
/// and connectivity together under `geometry`).
pub fn breakdown(stream: &[u8]) -> Result<Vec<LevelBreakdown>> {
    let index = StreamIndex::parse(stream)?;
    let levels = &index.header.levels;
    let base_chunk = &stream[index.header.byte_len()..index.base.end];
    let (_, base_payload) = ChunkHeader::parse(base_chunk, &[BASE_TAG])?;
    let mut out = vec![LevelBreakdown {
        vertices: levels[0].vertices,
        faces: levels[0].faces,
        bytes: levels[0].bytes,
        geometry: base_payload.len() as u32,
        overhead: levels[0].bytes - base_payload.len() as u32,
        ..Default::default()
    }];
    let mut cut = false;
    let nested = index.header.version >= NESTED_VERSION;
    let mut phase = None;
    for (k, range) in index.batches.iter().enumerate() {
        let (chunk, payload) =
            ChunkHeader::parse(&stream[range.clone()], &[BATCH_TAG, PARTED_TAG])?;
        let mut b = LevelBreakdown {
            vertices: levels[k + 1].vertices,
            faces: levels[k + 1].faces,
            bytes: levels[k + 1].bytes,
            ..Default::default()
        };
        let mut r = Reader::new(payload);
        if nested {
            // The deferred-precision byte (0 in every stream written today).
            r.u8()?;
        }
        if chunk.tag == PARTED_TAG && nested {
            let this = r.varint()?;
            let charts = r.varint()?;
            if phase != Some(this) {
                // The labels or the split count as connectivity.
                b.connectivity += r.section()?.len() as u32;
                phase = Some(this);
            }
            for _ in 0..charts {
                let part = r.section()?;
                if !part.is_empty() {
                    add_passes(&mut Reader::new(part), &mut b)?;
                }
            }
        } else if chunk.tag == PARTED_TAG {
            let charts = r.varint()?;
            if !cut {
                // The chart labels count as connectivity.
                b.connectivity += r.section()?.len() as u32;
                cut = true;
            }
            for _ in 0..charts {
                let part = r.section()?;
                if !part.is_empty() {
                    add_passes(&mut Reader::new(part), &mut b)?;
                }
            }
        } else {
            add_passes(&mut r, &mut b)?;
        }
        b.overhead = b.bytes - b.connectivity - b.geometry - b.colour;
        out.push(b);
    }
    Ok(out)
}

/// Adds a batch's (or a chart part's) two passes' section sizes to `b`.
fn add_passes(r: &mut Reader<'_>, b: &mut LevelBreakdown) -> Result<()> {
    for kind in [PassKind::Cleaning, PassKind::Decimating] {
        let pass = read_pass(r, kind)?;
        b.connectivity += pass.connectivity.len() as u32;
        b.geometry += pass.geometry.len() as u32;
        b.colour += pass.colour.len() as u32;
    }
    Ok(())
}
