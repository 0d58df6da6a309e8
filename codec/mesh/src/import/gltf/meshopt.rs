//! `EXT_meshopt_compression`: buffer views whose bytes are stored
//! meshoptimizer-encoded in another buffer, decoded with the `meshopt` crate
//! (the reference C++ decoder, which is safe on malformed input) before the
//! document is validated.
//!
//! Each compressed view's extension names the encoded bytes (`buffer`,
//! `byteOffset`, `byteLength`) and what they decode to: `count` elements of
//! `byteStride` bytes, as vertex attributes (`ATTRIBUTES`, with an optional
//! `OCTAHEDRAL`, `QUATERNION`, `EXPONENTIAL` or `COLOR` filter), a triangle
//! list (`TRIANGLES`) or an index sequence (`INDICES`). The decoded bytes
//! become a buffer of their own, and the view is pointed at it, so every
//! accessor reads them through the ordinary checked path. The view's own
//! (fallback) buffer is never read.
//!
//! A declared `count` is believed only as far as the import limits and the
//! encoded bytes allow: at most `max_vertices` attribute elements or
//! `3 · max_faces` indices, and at most [`MAX_EXPANSION`] decoded bytes per
//! encoded byte (meshoptimizer's codecs spend at least a fixed share of a bit
//! per decoded byte), refused before anything is allocated.

use gltf::json::{self, Value};

use super::buffers::Buffers;
use crate::import::ImportOptions;
use crate::{Error, Result};

const NAME: &str = "EXT_meshopt_compression";

/// Most decoded bytes per encoded byte believed before decoding. The vertex
/// codec's densest case (version 1: a byte column that never changes) costs
/// 2 bits per block of 256 bytes, 1:1024; index streams decode at most 12
/// bytes per encoded byte. Twice the densest case, plus a small stream's
/// fixed overhead (`+ 256` below), is what a real file can need.
const MAX_EXPANSION: u64 = 2048;

/// How the decoded elements are laid out.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Mode {
    Attributes,
    Triangles,
    Indices,
}

/// The filter applied to decoded attributes.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Filter {
    None,
    Octahedral,
    Quaternion,
    Exponential,
    Color,
}

/// One compressed view's extension object, checked.
#[derive(Debug)]
struct Compressed {
    buffer: usize,
    offset: usize,
    length: usize,
    stride: usize,
    count: usize,
    mode: Mode,
    filter: Filter,
}

/// Decodes every compressed buffer view of `root` into a buffer of its own
/// (appended to `root.buffers` and preloaded in `buffers`).
pub(super) fn decode_views(
    root: &mut json::Root,
    buffers: &mut Buffers<'_>,
    opts: &ImportOptions,
) -> Result<()> {
    let what = buffers.what;
    for v in 0..root.buffer_views.len() {
        let Some(ext) = extension(&root.buffer_views[v]) else {
            continue;
        };
        let c = parse(ext, v, root.buffers.len(), what)?;
        let source = &root.buffers[c.buffer];
        buffers.load_json(c.buffer, source)?;
        let encoded = buffers
            .get(c.buffer)
            .get(c.offset..)
            .and_then(|rest| rest.get(..c.length))
            .ok_or_else(|| {
                Error::input(
                    what,
                    format!(
                        "buffer view {v}: {NAME} bytes run past the end of buffer {}",
                        c.buffer
                    ),
                )
            })?;
        let decoded_len = (c.count as u64) * (c.stride as u64);
        let max_count = match c.mode {
            Mode::Attributes => opts.max_vertices,
            Mode::Triangles | Mode::Indices => opts.max_faces.saturating_mul(3),
        };
        if c.count > max_count || decoded_len > MAX_EXPANSION * (c.length as u64 + 256) {
            return Err(Error::input(
                what,
                format!(
                    "buffer view {v}: {NAME} declares {} elements of {} bytes from {} encoded bytes, more than such a stream can hold",
                    c.count, c.stride, c.length
                ),
            ));
        }
        let decoded = decode(&c, encoded)
            .map_err(|e| Error::input(what, format!("buffer view {v}: {NAME}: {e}")))?;
        let index = root.buffers.len();
        let mut buffer = root.buffers[c.buffer].clone();
        buffer.uri = None;
        buffer.extensions = None;
        buffer.byte_length = decoded.len().into();
        root.buffers.push(buffer);
        buffers.preload(index, decoded);
        let view = &mut root.buffer_views[v];
        view.buffer = json::Index::new(index as u32);
        view.byte_offset = None;
        view.byte_length = (c.count * c.stride).into();
        view.extensions = None;
    }
    // The fallback buffers hold nothing (or data nobody reads any more).
    for buffer in &mut root.buffers {
        if let Some(ext) = buffer.extensions.as_mut() {
            ext.others.remove(NAME);
        }
    }
    Ok(())
}

fn extension(view: &json::buffer::View) -> Option<&Value> {
    view.extensions.as_ref()?.others.get(NAME)
}

fn parse(ext: &Value, v: usize, buffers: usize, what: &'static str) -> Result<Compressed> {
    let bad = |detail: String| Error::input(what, format!("buffer view {v}: {NAME}: {detail}"));
    let field = |name: &str, default: Option<u64>| -> Result<usize> {
        match ext.get(name) {
            Some(value) => value
                .as_u64()
                .and_then(|n| usize::try_from(n).ok())
                .ok_or_else(|| bad(format!("{name} must be a non-negative integer"))),
            None => default
                .map(|d| d as usize)
                .ok_or_else(|| bad(format!("{name} is missing"))),
        }
    };
    let buffer = field("buffer", None)?;
    if buffer >= buffers {
        return Err(bad(format!(
            "buffer {buffer} does not exist ({buffers} buffers)"
        )));
    }
    let mode = match ext.get("mode").and_then(Value::as_str) {
        Some("ATTRIBUTES") => Mode::Attributes,
        Some("TRIANGLES") => Mode::Triangles,
        Some("INDICES") => Mode::Indices,
        other => return Err(bad(format!("unknown mode {other:?}"))),
    };
    let filter = match ext.get("filter").and_then(Value::as_str) {
        None | Some("NONE") => Filter::None,
        Some("OCTAHEDRAL") => Filter::Octahedral,
        Some("QUATERNION") => Filter::Quaternion,
        Some("EXPONENTIAL") => Filter::Exponential,
        Some("COLOR") => Filter::Color,
        Some(other) => return Err(bad(format!("unknown filter {other:?}"))),
    };
    let c = Compressed {
        buffer,
        offset: field("byteOffset", Some(0))?,
        length: field("byteLength", None)?,
        stride: field("byteStride", None)?,
        count: field("count", None)?,
        mode,
        filter,
    };
    let stride_ok = match (c.mode, c.filter) {
        (Mode::Attributes, Filter::None) => {
            c.stride.is_multiple_of(4) && (4..=256).contains(&c.stride)
        }
        (Mode::Attributes, Filter::Octahedral | Filter::Color) => c.stride == 4 || c.stride == 8,
        (Mode::Attributes, Filter::Quaternion) => c.stride == 8,
        (Mode::Attributes, Filter::Exponential) => {
            c.stride.is_multiple_of(4) && (4..=256).contains(&c.stride)
        }
        (Mode::Triangles | Mode::Indices, Filter::None) => c.stride == 2 || c.stride == 4,
        _ => return Err(bad(format!("filter {:?} is for attributes only", c.filter))),
    };
    if !stride_ok {
        return Err(bad(format!(
            "byteStride {} is not allowed for {:?} with filter {:?}",
            c.stride, c.mode, c.filter
        )));
    }
    if c.mode == Mode::Triangles && !c.count.is_multiple_of(3) {
        return Err(bad(format!(
            "TRIANGLES count {} is not a multiple of 3",
            c.count
        )));
    }
    Ok(c)
}

/// One decoded element of `N` bytes: `meshopt` decodes into a `Vec<T>` whose
/// element size is the stride, and `[u8; N]` has no `Default` above 32.
#[derive(Clone, Copy)]
struct Row<const N: usize>([u8; N]);

impl<const N: usize> Default for Row<N> {
    fn default() -> Self {
        Row([0; N])
    }
}

fn rows<const N: usize>(encoded: &[u8], count: usize) -> std::result::Result<Vec<u8>, String> {
    let rows =
        meshopt::decode_vertex_buffer::<Row<N>>(encoded, count).map_err(|e| e.to_string())?;
    Ok(rows.iter().flat_map(|r| r.0).collect())
}

/// The vertex decoder for a stride known only at run time.
fn vertex_rows(
    encoded: &[u8],
    count: usize,
    stride: usize,
) -> std::result::Result<Vec<u8>, String> {
    macro_rules! by_stride {
        ($($n:literal)*) => {
            match stride {
                $($n => rows::<$n>(encoded, count),)*
                _ => Err(format!("byteStride {stride}")),
            }
        };
    }
    by_stride!(4 8 12 16 20 24 28 32 36 40 44 48 52 56 60 64 68 72 76 80 84 88 92 96 100
        104 108 112 116 120 124 128 132 136 140 144 148 152 156 160 164 168 172 176 180 184
        188 192 196 200 204 208 212 216 220 224 228 232 236 240 244 248 252 256)
}

fn decode(c: &Compressed, encoded: &[u8]) -> std::result::Result<Vec<u8>, String> {
    match c.mode {
        Mode::Attributes => {
            let mut bytes = vertex_rows(encoded, c.count, c.stride)?;
            apply_filter(c.filter, c.stride, &mut bytes);
            Ok(bytes)
        }
        Mode::Triangles | Mode::Indices => {
            let triangles = c.mode == Mode::Triangles;
            if c.stride == 2 {
                let indices: Vec<u16> = if triangles {
                    meshopt::decode_index_buffer(encoded, c.count)
                } else {
                    meshopt::decode_index_sequence(encoded, c.count)
                }
                .map_err(|e| e.to_string())?;
                Ok(indices.iter().flat_map(|i| i.to_le_bytes()).collect())
            } else {
                let indices: Vec<u32> = if triangles {
                    meshopt::decode_index_buffer(encoded, c.count)
                } else {
                    meshopt::decode_index_sequence(encoded, c.count)
                }
                .map_err(|e| e.to_string())?;
                Ok(indices.iter().flat_map(|i| i.to_le_bytes()).collect())
            }
        }
    }
}

/// The filters work on typed elements; the bytes are converted there and
/// back (little-endian, as glTF stores them).
fn apply_filter(filter: Filter, stride: usize, bytes: &mut [u8]) {
    match (filter, stride) {
        (Filter::None, _) => {}
        (Filter::Octahedral, 4) => {
            let mut data = i8_rows(bytes);
            meshopt::decode_filter_oct(&mut data);
            write_i8_rows(&data, bytes);
        }
        (Filter::Color, 4) => {
            let mut data = i8_rows(bytes);
            meshopt::decode_filter_color(&mut data);
            write_i8_rows(&data, bytes);
        }
        (Filter::Octahedral, _) => {
            let mut data = i16_rows(bytes);
            meshopt::decode_filter_oct(&mut data);
            write_i16_rows(&data, bytes);
        }
        (Filter::Color, _) => {
            let mut data = i16_rows(bytes);
            meshopt::decode_filter_color(&mut data);
            write_i16_rows(&data, bytes);
        }
        (Filter::Quaternion, _) => {
            let mut data = i16_rows(bytes);
            meshopt::decode_filter_quat(&mut data);
            write_i16_rows(&data, bytes);
        }
        (Filter::Exponential, _) => {
            // Each 32-bit component decodes on its own, so one component
            // per element gives the same values as the stride's width.
            let mut data: Vec<[u32; 1]> = bytes
                .chunks_exact(4)
                .map(|b| [u32::from_le_bytes([b[0], b[1], b[2], b[3]])])
                .collect();
            meshopt::decode_filter_exp(&mut data);
            for (out, v) in bytes.chunks_exact_mut(4).zip(&data) {
                out.copy_from_slice(&v[0].to_le_bytes());
            }
        }
    }
}

fn i8_rows(bytes: &[u8]) -> Vec<[i8; 4]> {
    bytes
        .chunks_exact(4)
        .map(|b| [b[0] as i8, b[1] as i8, b[2] as i8, b[3] as i8])
        .collect()
}

fn write_i8_rows(data: &[[i8; 4]], bytes: &mut [u8]) {
    for (out, row) in bytes.chunks_exact_mut(4).zip(data) {
        for (o, v) in out.iter_mut().zip(row) {
            *o = *v as u8;
        }
    }
}

fn i16_rows(bytes: &[u8]) -> Vec<[i16; 4]> {
    bytes
        .chunks_exact(8)
        .map(|b| {
            let c = |k: usize| i16::from_le_bytes([b[2 * k], b[2 * k + 1]]);
            [c(0), c(1), c(2), c(3)]
        })
        .collect()
}

fn write_i16_rows(data: &[[i16; 4]], bytes: &mut [u8]) {
    for (out, row) in bytes.chunks_exact_mut(8).zip(data) {
        for (k, v) in row.iter().enumerate() {
            out[2 * k..2 * k + 2].copy_from_slice(&v.to_le_bytes());
        }
    }
}
