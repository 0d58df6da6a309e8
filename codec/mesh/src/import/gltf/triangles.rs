//! A primitive's triangles (`TRIANGLES`, `TRIANGLE_STRIP`, `TRIANGLE_FAN`,
//! indexed or not), every vertex index checked, appended to the combined
//! mesh.

use gltf::accessor::DataType;
use gltf::mesh::Mode;

use super::super::push_triangle;
use super::accessor::open;
use super::primitive::{Combined, Placed, Reading};
use crate::{Error, Result};

impl Combined {
    /// Appends the primitive's triangles, through its indices when it has
    /// them.
    pub(super) fn push_triangles(
        &mut self,
        r: &Reading<'_, '_>,
        mode: Mode,
        acc: Option<&gltf::Accessor<'_>>,
        placed: &Placed,
    ) -> Result<()> {
        let indices = match acc {
            Some(acc) => {
                let ix = open(acc, r.buffers, r.what)?;
                if ix.dims != 1 || ix.ty == DataType::F32 {
                    return Err(Error::input(
                        r.what,
                        format!("{}: indices must be unsigned integer scalars", placed.ctx),
                    ));
                }
                Some(ix)
            }
            None => None,
        };
        let count = indices.as_ref().map_or(placed.n, |ix| ix.count);
        let at = |i: usize| indices.as_ref().map_or(i as u64, |ix| ix.index(i));
        let emit = |t: [u64; 3], k: usize| self.add_triangle(r, placed, t, k);
        for_each_triangle(mode, count, at, emit)
    }

    /// Appends triangle `k` of the primitive, `t` in its own vertex numbers.
    fn add_triangle(
        &mut self,
        r: &Reading<'_, '_>,
        placed: &Placed,
        t: [u64; 3],
        k: usize,
    ) -> Result<()> {
        let n = placed.n;
        for &v in &t {
            if v >= n as u64 {
                return Err(Error::input(
                    r.what,
                    format!(
                        "{}: triangle {k} has vertex index {v} out of range ({n} vertices)",
                        placed.ctx
                    ),
                ));
            }
        }
        let [a, b, c] = t.map(|v| (v as usize + placed.base) as u32);
        let t = if placed.flip { [a, c, b] } else { [a, b, c] };
        push_triangle(&mut self.triangles, t, r.what, r.opts.max_faces)
    }
}

/// Calls `emit(triangle, k)` for each triangle of a `TRIANGLES`,
/// `TRIANGLE_STRIP` or `TRIANGLE_FAN` primitive with `count` vertex
/// references, `at(i)` being reference `i`. Degenerate strip triangles
/// (stitching) are dropped.
fn for_each_triangle(
    mode: Mode,
    count: usize,
    at: impl Fn(usize) -> u64,
    mut emit: impl FnMut([u64; 3], usize) -> Result<()>,
) -> Result<()> {
    match mode {
        Mode::Triangles => {
            for k in 0..count / 3 {
                emit([at(3 * k), at(3 * k + 1), at(3 * k + 2)], k)?;
            }
        }
        Mode::TriangleStrip => {
            for k in 0..count.saturating_sub(2) {
                let t = if k % 2 == 0 {
                    [at(k), at(k + 1), at(k + 2)]
                } else {
                    [at(k + 1), at(k), at(k + 2)]
                };
                if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                    emit(t, k)?;
                }
            }
        }
        _ => {
            for k in 0..count.saturating_sub(2) {
                emit([at(0), at(k + 1), at(k + 2)], k)?;
            }
        }
    }
    Ok(())
}
