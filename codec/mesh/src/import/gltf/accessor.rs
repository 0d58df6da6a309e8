//! Checked views of accessor bytes: every element of an accessor is proved
//! to lie inside its buffer view before any is read.
//!
//! A sparse accessor is read through its base (its buffer view, or zeros
//! when it has none, as the specification says) and a sorted list of the
//! substituted elements, looked up by binary search: nothing is allocated
//! but that list, whose length the index bytes present bound.

use gltf::accessor::sparse::IndexType;
use gltf::accessor::DataType;

use super::buffers::Buffers;
use crate::{Error, Result};

/// A checked view of one accessor's bytes.
pub(super) struct Accessor<'b> {
    /// The base bytes (empty without a buffer view: all zeros).
    pub(super) data: &'b [u8],
    pub(super) start: usize,
    pub(super) stride: usize,
    pub(super) count: usize,
    pub(super) ty: DataType,
    pub(super) dims: usize,
    pub(super) normalized: bool,
    /// Without a buffer view every base value is zero.
    based: bool,
    sparse: Option<Sparse<'b>>,
}

/// The substituted elements of a sparse accessor.
struct Sparse<'b> {
    /// Strictly increasing element numbers, each below the accessor's count.
    indices: Vec<u32>,
    /// Their values, tightly packed, in the same order.
    values: &'b [u8],
}

/// Component `b` (`ty.size()` bytes) as a number.
#[inline]
fn component(ty: DataType, b: &[u8]) -> f64 {
    match ty {
        DataType::I8 => b[0] as i8 as f64,
        DataType::U8 => b[0] as f64,
        DataType::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
        DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
        DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
    }
}

impl Accessor<'_> {
    #[inline]
    pub(super) fn raw(&self, i: usize, j: usize) -> f64 {
        let size = self.ty.size();
        if let Some(s) = &self.sparse {
            if let Some(k) = u32::try_from(i)
                .ok()
                .and_then(|i| s.indices.binary_search(&i).ok())
            {
                // In range: checked by `sparse` for every k < indices.len().
                let p = (k * self.dims + j) * size;
                return component(self.ty, &s.values[p..p + size]);
            }
        }
        if !self.based {
            return 0.0;
        }
        let p = self.start + i * self.stride + j * size;
        // In range: checked by `open` for every i < count, j < dims.
        component(self.ty, &self.data[p..p + size])
    }

    /// The value as the spec means it: normalized integers map to 0–1 or −1–1.
    #[inline]
    pub(super) fn value(&self, i: usize, j: usize) -> f64 {
        let v = self.raw(i, j);
        if !self.normalized {
            return v;
        }
        match self.ty {
            DataType::I8 => (v / 127.0).max(-1.0),
            DataType::U8 => v / 255.0,
            DataType::I16 => (v / 32767.0).max(-1.0),
            DataType::U16 => v / 65535.0,
            DataType::U32 => v / 4294967295.0,
            DataType::F32 => v,
        }
    }

    #[inline]
    pub(super) fn index(&self, i: usize) -> u64 {
        match self.ty {
            DataType::F32 => u64::MAX,
            _ => self.raw(i, 0) as u64,
        }
    }
}

/// Loads the buffers an accessor reads: its buffer view's and, when it is
/// sparse, those of its indices and values.
pub(super) fn load(acc: &gltf::Accessor<'_>, buffers: &mut Buffers<'_>) -> Result<()> {
    if let Some(view) = acc.view() {
        buffers.load(&view.buffer())?;
    }
    if let Some(sparse) = acc.sparse() {
        buffers.load(&sparse.indices().view().buffer())?;
        buffers.load(&sparse.values().view().buffer())?;
    }
    Ok(())
}

/// `len` bytes from `offset` into buffer view `view`, checked.
fn view_bytes<'b>(
    view: &gltf::buffer::View<'_>,
    offset: usize,
    len: Option<usize>,
    buffers: &'b Buffers<'_>,
) -> std::result::Result<&'b [u8], String> {
    let data = buffers.get(view.buffer().index());
    let view_end = view
        .offset()
        .checked_add(view.length())
        .filter(|&e| e <= data.len())
        .ok_or_else(|| {
            format!(
                "buffer view {} ends past its buffer ({} bytes)",
                view.index(),
                data.len()
            )
        })?;
    let start = view.offset().checked_add(offset);
    let end = start.zip(len).and_then(|(s, l)| s.checked_add(l));
    match (start, end) {
        (Some(start), Some(end)) if end <= view_end => Ok(&data[start..end]),
        _ => Err(format!("runs past the end of buffer view {}", view.index())),
    }
}

/// The substitutions of a sparse accessor of `count` elements of `elem`
/// bytes.
fn sparse<'b>(
    acc: &gltf::Accessor<'_>,
    s: &gltf::accessor::sparse::Sparse<'_>,
    elem: usize,
    buffers: &'b Buffers<'_>,
    what: &'static str,
) -> Result<Sparse<'b>> {
    let ai = acc.index();
    let bad = |detail: String| Error::input(what, format!("accessor {ai}: sparse {detail}"));
    let n = s.count();
    let (index_ty, index_size) = match s.indices().index_type() {
        IndexType::U8 => (DataType::U8, 1),
        IndexType::U16 => (DataType::U16, 2),
        IndexType::U32 => (DataType::U32, 4),
    };
    let iv = s.indices().view();
    let index_bytes = view_bytes(
        &iv,
        s.indices().offset(),
        n.checked_mul(index_size),
        buffers,
    )
    .map_err(|e| bad(format!("indices: {n} indices {e}")))?;
    let vv = s.values().view();
    let values = view_bytes(&vv, s.values().offset(), n.checked_mul(elem), buffers)
        .map_err(|e| bad(format!("values: {n} values {e}")))?;
    // `n` is now backed by `n * index_size` bytes that are present.
    let mut indices = Vec::with_capacity(n);
    for (k, b) in index_bytes.chunks_exact(index_size).enumerate() {
        let i = component(index_ty, b) as u32;
        if i as usize >= acc.count() {
            return Err(bad(format!(
                "index {k} is {i}, past the accessor's {} elements",
                acc.count()
            )));
        }
        if indices.last().is_some_and(|&last| i <= last) {
            return Err(bad(format!(
                "indices must increase strictly (index {k} is {i})"
            )));
        }
        indices.push(i);
    }
    Ok(Sparse { indices, values })
}

pub(super) fn open<'b>(
    acc: &gltf::Accessor<'_>,
    buffers: &'b Buffers<'_>,
    what: &'static str,
) -> Result<Accessor<'b>> {
    let ai = acc.index();
    let ty = acc.data_type();
    let dims = acc.dimensions().multiplicity();
    let elem = ty.size() * dims;
    let count = acc.count();
    let sparse = acc
        .sparse()
        .map(|s| sparse(acc, &s, elem, buffers, what))
        .transpose()?;
    let Some(view) = acc.view() else {
        if sparse.is_none() {
            return Err(Error::Unsupported(format!(
                "{what}: accessor {ai} has no bufferView (and is not sparse)"
            )));
        }
        return Ok(Accessor {
            data: &[],
            start: 0,
            stride: elem,
            count,
            ty,
            dims,
            normalized: acc.normalized(),
            based: false,
            sparse,
        });
    };
    let stride = view.stride().unwrap_or(elem);
    if stride < elem {
        return Err(Error::input(
            what,
            format!(
                "accessor {ai}: byteStride {stride} is smaller than its element ({elem} bytes)"
            ),
        ));
    }
    let data = buffers.get(view.buffer().index());
    let bad = |detail: String| Error::input(what, format!("accessor {ai}: {detail}"));
    let view_end = view
        .offset()
        .checked_add(view.length())
        .filter(|&e| e <= data.len())
        .ok_or_else(|| {
            bad(format!(
                "buffer view {} ends past its buffer ({} bytes)",
                view.index(),
                data.len()
            ))
        })?;
    let start = view.offset().checked_add(acc.offset());
    let end = match count {
        0 => start,
        n => start
            .and_then(|s| s.checked_add(stride.checked_mul(n - 1)?))
            .and_then(|s| s.checked_add(elem)),
    };
    match (start, end) {
        (Some(start), Some(end)) if end <= view_end => Ok(Accessor {
            data: &data[..view_end],
            start,
            stride,
            count,
            ty,
            dims,
            normalized: acc.normalized(),
            based: true,
            sparse,
        }),
        _ => Err(bad(format!(
            "{count} elements run past the end of buffer view {}",
            view.index()
        ))),
    }
}
