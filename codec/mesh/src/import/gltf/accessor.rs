//! Checked views of accessor bytes: every element of an accessor is proved
//! to lie inside its buffer view before any is read.

use gltf::accessor::DataType;

use super::buffers::Buffers;
use crate::{Error, Result};

/// A checked view of one accessor's bytes.
pub(super) struct Accessor<'b> {
    pub(super) data: &'b [u8],
    pub(super) start: usize,
    pub(super) stride: usize,
    pub(super) count: usize,
    pub(super) ty: DataType,
    pub(super) dims: usize,
    pub(super) normalized: bool,
}

impl Accessor<'_> {
    #[inline]
    pub(super) fn raw(&self, i: usize, j: usize) -> f64 {
        let p = self.start + i * self.stride + j * self.ty.size();
        // In range: checked by `open` for every i < count, j < dims.
        let b = &self.data[p..p + self.ty.size()];
        match self.ty {
            DataType::I8 => b[0] as i8 as f64,
            DataType::U8 => b[0] as f64,
            DataType::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        }
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

pub(super) fn open<'b>(
    acc: &gltf::Accessor<'_>,
    buffers: &'b Buffers<'_>,
    what: &'static str,
) -> Result<Accessor<'b>> {
    let ai = acc.index();
    if acc.sparse().is_some() {
        return Err(Error::Unsupported(format!(
            "{what}: accessor {ai} is sparse"
        )));
    }
    let view = acc
        .view()
        .ok_or_else(|| Error::Unsupported(format!("{what}: accessor {ai} has no bufferView")))?;
    let ty = acc.data_type();
    let dims = acc.dimensions().multiplicity();
    let elem = ty.size() * dims;
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
    let count = acc.count();
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
        }),
        _ => Err(bad(format!(
            "{count} elements run past the end of buffer view {}",
            view.index()
        ))),
    }
}
