//! The container: header, level table, base chunk and one chunk per refinement batch.
//! `codec/core/FORMAT.md` documents the layout byte by byte.

use crate::quantize::Quantization;
use crate::{Error, Result};
use std::ops::Range;

pub const MAGIC: [u8; 4] = *b"VTRN";
/// The plain stream: every batch refines the whole mesh.
pub const VERSION: u8 = 4;
/// The chart-parallel stream: after its global batches, every batch is cut
/// into one part per chart, each decoded on its own (`charts` module).
pub const CHARTED_VERSION: u8 = 5;
/// The nested-chart stream: phases of parted batches, each phase's charts
/// splitting the previous phase's (`charts::nested`); every batch payload
/// starts with a deferred-precision byte.
pub const NESTED_VERSION: u8 = 6;
pub(crate) const HEADER_FIXED: usize = 40;
pub(crate) const LEVEL_ENTRY: usize = 12;
pub(crate) const BASE_TAG: u8 = b'M';
pub(crate) const BATCH_TAG: u8 = b'L';
/// A batch of a charted stream, in one part per chart.
pub(crate) const PARTED_TAG: u8 = b'P';
pub(crate) const FLAG_COLOUR: u8 = 1;

/// Vertex, face and byte counts after one level (the base mesh is level 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LevelInfo {
    pub vertices: u32,
    pub faces: u32,
    /// Size of the chunk that produces this level (base chunk for level 0).
    pub bytes: u32,
}

/// Everything a server needs to list a stream's levels, read without decoding.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    pub version: u8,
    pub has_colour: bool,
    pub quantization: Quantization,
    /// `levels[0]` is the base mesh, `levels[k]` the mesh after batch `k`.
    pub levels: Vec<LevelInfo>,
}

impl Header {
    pub fn byte_len(&self) -> usize {
        HEADER_FIXED + LEVEL_ENTRY * (self.levels.len() - 1)
    }

    /// Number of refinement batches.
    pub fn batch_count(&self) -> usize {
        self.levels.len() - 1
    }

    pub fn final_level(&self) -> LevelInfo {
        *self
            .levels
            .last()
            .expect("a header always has the base level")
    }

    pub(crate) fn write(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&MAGIC);
        out.push(self.version);
        out.push(if self.has_colour { FLAG_COLOUR } else { 0 });
        out.push(self.quantization.bits);
        out.push(0);
        for k in 0..3 {
            out.extend_from_slice(&self.quantization.min[k].to_le_bytes());
        }
        out.extend_from_slice(&self.quantization.step.to_le_bytes());
        out.extend_from_slice(&(self.batch_count() as u32).to_le_bytes());
        for level in &self.levels {
            out.extend_from_slice(&level.vertices.to_le_bytes());
            out.extend_from_slice(&level.faces.to_le_bytes());
            out.extend_from_slice(&level.bytes.to_le_bytes());
        }
    }

    /// Parses the header at the start of `bytes` (the rest may be absent).
    pub fn parse(bytes: &[u8]) -> Result<Header> {
        let mut r = Reader::new(bytes);
        if r.take(4)? != MAGIC {
            return Err(Error::stream("not a Vitrine stream (bad magic)"));
        }
        let version = r.u8()?;
        if !(VERSION..=NESTED_VERSION).contains(&version) {
            return Err(Error::stream(format!(
                "unsupported version {version} (this build reads {VERSION} to {NESTED_VERSION})"
            )));
        }
        let flags = r.u8()?;
        if flags & !FLAG_COLOUR != 0 {
            return Err(Error::stream(format!("unknown flags {flags:#x}")));
        }
        let bits = r.u8()?;
        if !(Quantization::MIN_BITS..=Quantization::MAX_BITS).contains(&bits) {
            return Err(Error::stream(format!(
                "quantization of {bits} bits is out of range"
            )));
        }
        r.u8()?;
        let min = [r.f32()?, r.f32()?, r.f32()?];
        let step = r.f32()?;
        if !(min.iter().all(|v| v.is_finite()) && step.is_finite() && step > 0.0) {
            return Err(Error::stream("bounding box or step is not finite"));
        }
        let batches = r.u32()? as usize;
        // Each level entry takes 12 bytes: refuse counts the input cannot hold.
        if batches > r.remaining() / LEVEL_ENTRY {
            return Err(Error::stream(format!(
                "header declares {batches} batches but is truncated"
            )));
        }
        let mut levels = Vec::with_capacity(batches + 1);
        for _ in 0..=batches {
            levels.push(LevelInfo {
                vertices: r.u32()?,
                faces: r.u32()?,
                bytes: r.u32()?,
            });
        }
        for pair in levels.windows(2) {
            if pair[1].vertices <= pair[0].vertices || pair[1].faces < pair[0].faces {
                return Err(Error::stream("level table does not grow"));
            }
            // A refinement adds two faces per vertex.
            let added = (pair[1].vertices - pair[0].vertices) as u64;
            if (pair[1].faces - pair[0].faces) as u64 != 2 * added {
                return Err(Error::stream(
                    "level table adds faces other than two per vertex",
                ));
            }
        }
        Ok(Header {
            version,
            has_colour: flags & FLAG_COLOUR != 0,
            quantization: Quantization { bits, min, step },
            levels,
        })
    }
}

/// Byte ranges of each part of a complete stream.
#[derive(Clone, Debug)]
pub struct StreamIndex {
    pub header: Header,
    /// Header plus base chunk: what [`crate::Decoder::new`] takes.
    pub base: Range<usize>,
    /// One range per refinement batch, in application order.
    pub batches: Vec<Range<usize>>,
}

impl StreamIndex {
    pub fn parse(bytes: &[u8]) -> Result<StreamIndex> {
        let header = Header::parse(bytes)?;
        let mut at = header.byte_len();
        let mut ranges = Vec::with_capacity(header.levels.len());
        for level in &header.levels {
            let end = at
                .checked_add(level.bytes as usize)
                .filter(|&e| e <= bytes.len())
                .ok_or_else(|| Error::stream("stream is shorter than its level table says"))?;
            ranges.push(at..end);
            at = end;
        }
        let base = 0..ranges[0].end;
        ranges.remove(0);
        Ok(StreamIndex {
            header,
            base,
            batches: ranges,
        })
    }
}

/// Fixed fields at the start of a base or batch chunk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ChunkHeader {
    pub tag: u8,
    /// The stream's version, repeated in every chunk.
    pub version: u8,
    pub level: u16,
    pub vertices_before: u32,
    pub vertices_after: u32,
    pub faces_after: u32,
    pub payload_len: u32,
}

impl ChunkHeader {
    pub(crate) fn write(&self, out: &mut Vec<u8>) {
        out.push(self.tag);
        out.push(self.version);
        for v in [
            self.level as u32,
            self.vertices_before,
            self.vertices_after,
            self.faces_after,
            self.payload_len,
        ] {
            write_varint(out, v);
        }
    }

    /// Splits a chunk into its header and payload, checking the payload is
    /// all there; `tags` are the kinds of chunk expected here.
    pub(crate) fn parse<'b>(bytes: &'b [u8], tags: &[u8]) -> Result<(ChunkHeader, &'b [u8])> {
        let mut r = Reader::new(bytes);
        let tag = r.u8()?;
        if !tags.contains(&tag) {
            return Err(Error::stream(format!(
                "expected a {} chunk, found tag {tag:#x}",
                if tags.contains(&BASE_TAG) {
                    "base"
                } else {
                    "batch"
                }
            )));
        }
        let version = r.u8()?;
        if !(VERSION..=NESTED_VERSION).contains(&version) {
            return Err(Error::stream("chunk version mismatch"));
        }
        let h = ChunkHeader {
            tag,
            version,
            level: u16::try_from(r.varint()?)
                .map_err(|_| Error::stream("chunk level exceeds 65535"))?,
            vertices_before: r.varint()?,
            vertices_after: r.varint()?,
            faces_after: r.varint()?,
            payload_len: r.varint()?,
        };
        let payload = r.take(h.payload_len as usize)?;
        Ok((h, payload))
    }
}

/// One refinement batch's chunk (FORMAT.md, "Chunks"), split into its
/// header and payload: for tools that build batches piece by piece, such as
/// the fuzz target that wraps fuzzed payloads in a real batch's header.
#[derive(Clone, Copy, Debug)]
pub struct BatchChunk<'a> {
    header: ChunkHeader,
    pub payload: &'a [u8],
}

impl<'a> BatchChunk<'a> {
    /// Parses a batch chunk, as [`StreamIndex::batches`] delimits one.
    pub fn parse(chunk: &'a [u8]) -> Result<Self> {
        let (header, payload) = ChunkHeader::parse(chunk, &[BATCH_TAG, PARTED_TAG])?;
        Ok(BatchChunk { header, payload })
    }

    /// The same chunk (level and counts) around another payload, written by
    /// the encoder's own chunk writer.
    pub fn with_payload(&self, payload: &[u8]) -> Result<Vec<u8>> {
        let payload_len = u32::try_from(payload.len())
            .map_err(|_| Error::Limit("a payload over 4 GiB".into()))?;
        let mut out = Vec::with_capacity(payload.len() + 24);
        ChunkHeader {
            payload_len,
            ..self.header
        }
        .write(&mut out);
        out.extend_from_slice(payload);
        Ok(out)
    }
}

/// A bounds-checked little-endian cursor: every read past the end is an error.
#[derive(Clone)]
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        Reader { bytes, at: 0 }
    }

    pub(crate) fn remaining(&self) -> usize {
        self.bytes.len() - self.at
    }

    pub(crate) fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        if n > self.remaining() {
            return Err(Error::stream(format!(
                "truncated: needs {n} more bytes at offset {}, has {}",
                self.at,
                self.remaining()
            )));
        }
        let s = &self.bytes[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }

    pub(crate) fn u8(&mut self) -> Result<u8> {
        Ok(self.take(1)?[0])
    }

    pub(crate) fn u32(&mut self) -> Result<u32> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }

    pub(crate) fn f32(&mut self) -> Result<f32> {
        Ok(f32::from_bits(self.u32()?))
    }

    /// LEB128 unsigned varint of at most 32 bits.
    pub(crate) fn varint(&mut self) -> Result<u32> {
        let mut value = 0u64;
        for shift in (0..35).step_by(7) {
            let b = self.u8()?;
            value |= ((b & 0x7f) as u64) << shift;
            if b & 0x80 == 0 {
                return u32::try_from(value).map_err(|_| Error::stream("varint exceeds 32 bits"));
            }
        }
        Err(Error::stream("varint longer than 5 bytes"))
    }

    /// A varint-length-prefixed byte slice.
    pub(crate) fn section(&mut self) -> Result<&'a [u8]> {
        let n = self.varint()? as usize;
        self.take(n)
    }
}

pub(crate) fn write_varint(out: &mut Vec<u8>, mut v: u32) {
    while v >= 0x80 {
        out.push((v as u8 & 0x7f) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

pub(crate) fn write_section(out: &mut Vec<u8>, bytes: &[u8]) {
    write_varint(out, bytes.len() as u32);
    out.extend_from_slice(bytes);
}
