//! The stream's header and chunk framing (see `FORMAT.md`).

use vitrine_codec::{Error, Result};

/// First bytes of every point stream.
pub const MAGIC: [u8; 4] = *b"VPTS";
/// The format version [`encode`](super::encode) writes by default. Version
/// 2 codes positions 8 % smaller (0.86× Draco's bytes on 300 k lucy samples
/// against 0.94×) but decodes 2.5–3× slower (0.13–0.23 s against
/// 0.05–0.08 s for those points, native, on a shared 2-core machine; 6–10×
/// before the neighbour lists of session 29): at 10 Mbit/s the 37 kB it
/// saves take 30 ms to fetch and its decoding costs 90–150 ms more, so it is written
/// only when asked for ([`EncodeOptions::version`](super::EncodeOptions))
/// until it decodes within 1.5× of version 1 (issue 42). Version 3 codes
/// positions another 4 % smaller (0.82× Draco's bytes on those points) and
/// decodes in about twice version 2's time (session 32): also only when
/// asked for.
pub const VERSION: u8 = 1;
/// The format versions this crate reads and can write (they differ only in
/// how child masks are coded, see `FORMAT.md`).
pub const VERSIONS: std::ops::RangeInclusive<u8> = 1..=3;

/// Header flag: points carry normals.
pub(crate) const FLAG_NORMALS: u8 = 1;
/// Header flag: points carry colours.
pub(crate) const FLAG_COLOURS: u8 = 2;
/// Header flag: new points' attributes are predicted from the decoded
/// neighbourhood (`FORMAT.md` "Predicted attributes"), any version.
pub(crate) const FLAG_PREDICTED: u8 = 4;

/// Most position bits per axis (the octree depth): 3 × 20 bits fit the u64
/// Morton keys.
pub(crate) const MAX_BITS: u8 = 20;

/// Fixed header bytes before the level depths.
const FIXED: usize = 4 + 1 + 1 + 1 + 1 + 24 + 12 + 4 + 4 + 1;
/// Bytes of a chunk's framing: payload length and cumulative point count.
pub(crate) const CHUNK_FRAME: usize = 8;

/// What the header says.
#[derive(Clone, Debug, PartialEq)]
pub struct PointHeader {
    /// Format version (1, 2 or 3).
    pub version: u8,
    /// Position bits per axis; the octree has this depth.
    pub bits: u8,
    /// Octahedral bits per normal component (0: no normals).
    pub normal_bits: u8,
    pub has_colours: bool,
    /// New points' attributes are coded against a prediction from the
    /// decoded neighbourhood (flag bit 2), not their parent's alone.
    pub predicted_attributes: bool,
    /// Added to every dequantized position.
    pub origin: [f64; 3],
    /// Dequantized position = `min + q · step` (then `origin` added).
    pub min: [f32; 3],
    pub step: f32,
    /// Points in the whole stream.
    pub points: u32,
    /// The octree depth each level ends at (increasing, the last = `bits`).
    pub level_depths: Vec<u8>,
}

impl PointHeader {
    pub fn has_normals(&self) -> bool {
        self.normal_bits > 0
    }

    pub fn levels(&self) -> usize {
        self.level_depths.len()
    }

    /// Serialized length in bytes.
    pub fn len(&self) -> usize {
        FIXED + self.level_depths.len()
    }

    pub fn is_empty(&self) -> bool {
        false
    }

    pub(crate) fn write(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&MAGIC);
        out.push(self.version);
        let flags = if self.has_normals() { FLAG_NORMALS } else { 0 }
            | if self.has_colours { FLAG_COLOURS } else { 0 }
            | if self.predicted_attributes {
                FLAG_PREDICTED
            } else {
                0
            };
        out.push(flags);
        out.push(self.bits);
        out.push(self.normal_bits);
        for v in self.origin {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in self.min {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&self.step.to_le_bytes());
        out.extend_from_slice(&self.points.to_le_bytes());
        out.push(self.level_depths.len() as u8);
        out.extend_from_slice(&self.level_depths);
    }

    /// Parses and checks a header at the start of `bytes`.
    pub fn parse(bytes: &[u8]) -> Result<PointHeader> {
        let err = |d: &str| Error::input("point stream", d);
        if bytes.len() < 5 {
            return Err(err("truncated header"));
        }
        if bytes[..4] != MAGIC {
            return Err(err("not a point stream (bad magic)"));
        }
        let version = bytes[4];
        if !VERSIONS.contains(&version) {
            return Err(Error::input(
                "point stream",
                format!(
                    "version {version} (this decoder reads {} to {})",
                    VERSIONS.start(),
                    VERSIONS.end()
                ),
            ));
        }
        if bytes.len() < FIXED {
            return Err(err("truncated header"));
        }
        let flags = bytes[5];
        if flags & !(FLAG_NORMALS | FLAG_COLOURS | FLAG_PREDICTED) != 0 {
            return Err(err("unknown header flags"));
        }
        let bits = bytes[6];
        let normal_bits = bytes[7];
        if !(1..=MAX_BITS).contains(&bits) {
            return Err(err("position bits outside 1..=20"));
        }
        if (flags & FLAG_NORMALS != 0) != (normal_bits != 0)
            || (normal_bits != 0 && !(4..=15).contains(&normal_bits))
        {
            return Err(err("normal bits outside 4..=15 or disagree with the flags"));
        }
        let f64_at = |o: usize| f64::from_le_bytes(bytes[o..o + 8].try_into().unwrap_or([0; 8]));
        let f32_at = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap_or([0; 4]));
        let origin = [f64_at(8), f64_at(16), f64_at(24)];
        let min = [f32_at(32), f32_at(36), f32_at(40)];
        let step = f32_at(44);
        let points = u32::from_le_bytes(bytes[48..52].try_into().unwrap_or([0; 4]));
        let n_levels = usize::from(bytes[52]);
        let finite = origin.iter().all(|v| v.is_finite()) && min.iter().all(|v| v.is_finite());
        if !(finite && step.is_finite() && step > 0.0) {
            return Err(err("non-finite origin, minimum or step"));
        }
        if points == 0 {
            return Err(err("no points"));
        }
        if n_levels == 0 || bytes.len() < FIXED + n_levels {
            return Err(err("truncated header (level depths)"));
        }
        let level_depths = bytes[FIXED..FIXED + n_levels].to_vec();
        let increasing = level_depths.windows(2).all(|w| w[0] < w[1]);
        if !increasing || level_depths.last() != Some(&bits) {
            return Err(err(
                "level depths must increase and end at the position bits",
            ));
        }
        Ok(PointHeader {
            version,
            bits,
            normal_bits,
            has_colours: flags & FLAG_COLOURS != 0,
            predicted_attributes: flags & FLAG_PREDICTED != 0,
            origin,
            min,
            step,
            points,
            level_depths,
        })
    }
}

/// One chunk's framing: (payload, cumulative point count, chunk length).
pub(crate) fn read_chunk(bytes: &[u8]) -> Result<(&[u8], u32, usize)> {
    if bytes.len() < CHUNK_FRAME {
        return Err(Error::input(
            "point stream",
            "truncated level chunk (framing)",
        ));
    }
    let len = u32::from_le_bytes(bytes[0..4].try_into().unwrap_or([0; 4])) as usize;
    let count = u32::from_le_bytes(bytes[4..8].try_into().unwrap_or([0; 4]));
    let end = CHUNK_FRAME
        .checked_add(len)
        .filter(|&e| e <= bytes.len())
        .ok_or_else(|| Error::input("point stream", "truncated level chunk"))?;
    Ok((&bytes[CHUNK_FRAME..end], count, end))
}

/// Splits a whole stream into its header and its level chunks (byte
/// ranges), as storage keeps them; checks the framing, not the payloads.
pub fn split(bytes: &[u8]) -> Result<(PointHeader, Vec<std::ops::Range<usize>>)> {
    let header = PointHeader::parse(bytes)?;
    let mut at = header.len();
    let mut chunks = Vec::with_capacity(header.levels());
    for _ in 0..header.levels() {
        let (_, _, len) = read_chunk(&bytes[at..])?;
        chunks.push(at..at + len);
        at += len;
    }
    if at != bytes.len() {
        return Err(Error::input("point stream", "bytes after the last level"));
    }
    Ok((header, chunks))
}
