//! Quake II MD2 writer. [`write_md2`] writes an [`Md2`] field by field in
//! the usual section order (header, skins, texture coordinates, triangles,
//! frames, GL commands), regenerating the GL command list from the
//! triangles, so an MD2 this module wrote reads back
//! ([`Md2::parse`]) and re-writes byte-identical. [`write_mesh_md2`] writes
//! a plain mesh (a decoded level) as a one-frame, untextured MD2.

use std::io::Write;

use glam::Vec3;

use super::normal_table::nearest_normal;
use crate::import::md2::{
    quake_to_y_up, y_up_to_quake, Md2, Md2Frame, Md2Triangle, MD2_FRAME_HEADER_BYTES,
    MD2_HEADER_BYTES, MD2_MAGIC, MD2_MAX_FRAMES, MD2_MAX_SKINS, MD2_MAX_ST, MD2_MAX_TRIANGLES,
    MD2_MAX_VERTICES, MD2_SKIN_NAME_BYTES, MD2_VERSION,
};
use crate::{Error, IndexedMesh, Result};

/// Skin size written for a model without skin (texture coordinates are 0).
const BLANK_SKIN_SIDE: i32 = 8;

/// One 3-vertex triangle strip per triangle, then the terminating 0: the
/// simplest list every engine draws (SEEDS.md 003: "regenerate on write").
/// A strip vertex is `float s, float t, int32 vertex`; strips draw with
/// OpenGL's counter-clockwise-first convention, and Quake culls front
/// faces, so the triangle's clockwise corner order is kept as it is.
pub fn gl_commands(model: &Md2) -> Vec<i32> {
    let mut words = Vec::with_capacity(1 + 10 * model.triangles.len());
    let (w, h) = (model.skin_width as f32, model.skin_height as f32);
    for t in &model.triangles {
        words.push(3);
        for c in 0..3 {
            let [s, tt] = model.st[t.st[c] as usize];
            words.push((f32::from(s) / w).to_bits() as i32);
            words.push((f32::from(tt) / h).to_bits() as i32);
            words.push(i32::from(t.vertex[c]));
        }
    }
    words.push(0);
    words
}

fn check(model: &Md2) -> Result<()> {
    let n = model.vertex_count();
    let limits = [
        ("vertices", n, MD2_MAX_VERTICES),
        ("triangles", model.triangles.len(), MD2_MAX_TRIANGLES),
        ("frames", model.frames.len(), MD2_MAX_FRAMES),
        ("skins", model.skins.len(), MD2_MAX_SKINS),
        ("texture coordinates", model.st.len(), MD2_MAX_ST),
    ];
    for (what, count, limit) in limits {
        if count > limit {
            return Err(Error::Limit(format!(
                "MD2 holds at most {limit} {what}; this model has {count} (simplify it first: vitrine lod / vitrine simplify)"
            )));
        }
    }
    if model.frames.is_empty() {
        return Err(Error::Parameter("an MD2 model needs a frame".into()));
    }
    if let Some(k) = model.frames.iter().position(|f| f.vertices.len() != n) {
        return Err(Error::Parameter(format!(
            "MD2 frame {k} has {} vertices, frame 0 has {n}",
            model.frames[k].vertices.len()
        )));
    }
    for (k, t) in model.triangles.iter().enumerate() {
        if t.vertex.iter().any(|&v| v as usize >= n)
            || t.st.iter().any(|&s| s as usize >= model.st.len())
        {
            return Err(Error::Parameter(format!(
                "MD2 triangle {k} refers past the vertices or texture coordinates"
            )));
        }
    }
    if model.skin_width < 1 || model.skin_height < 1 {
        return Err(Error::Parameter("MD2 skin size must be positive".into()));
    }
    Ok(())
}

/// Writes `model`, with its GL commands regenerated ([`gl_commands`]).
pub fn write_md2(model: &Md2, w: &mut impl Write) -> Result<()> {
    check(model)?;
    let n = model.vertex_count();
    let glcmds = gl_commands(model);
    let frame_size = MD2_FRAME_HEADER_BYTES + 4 * n;
    let ofs_skins = MD2_HEADER_BYTES;
    let ofs_st = ofs_skins + MD2_SKIN_NAME_BYTES * model.skins.len();
    let ofs_tris = ofs_st + 4 * model.st.len();
    let ofs_frames = ofs_tris + 12 * model.triangles.len();
    let ofs_glcmds = ofs_frames + frame_size * model.frames.len();
    let ofs_end = ofs_glcmds + 4 * glcmds.len();
    let mut out = Vec::with_capacity(ofs_end);
    out.extend_from_slice(&MD2_MAGIC);
    let fields = [
        MD2_VERSION as usize,
        model.skin_width as usize,
        model.skin_height as usize,
        frame_size,
        model.skins.len(),
        n,
        model.st.len(),
        model.triangles.len(),
        glcmds.len(),
        model.frames.len(),
        ofs_skins,
        ofs_st,
        ofs_tris,
        ofs_frames,
        ofs_glcmds,
        ofs_end,
    ];
    for f in fields {
        // Every field is bounded by the limits checked above.
        out.extend_from_slice(&(f as i32).to_le_bytes());
    }
    for s in &model.skins {
        out.extend_from_slice(s);
    }
    for st in &model.st {
        out.extend_from_slice(&st[0].to_le_bytes());
        out.extend_from_slice(&st[1].to_le_bytes());
    }
    for t in &model.triangles {
        for v in t.vertex.iter().chain(&t.st) {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    for f in &model.frames {
        for x in f.scale.iter().chain(&f.translate) {
            out.extend_from_slice(&x.to_le_bytes());
        }
        out.extend_from_slice(&f.name);
        for v in &f.vertices {
            out.extend_from_slice(v);
        }
    }
    for c in &glcmds {
        out.extend_from_slice(&c.to_le_bytes());
    }
    debug_assert_eq!(out.len(), ofs_end);
    w.write_all(&out)?;
    Ok(())
}

/// A frame quantized from Y-up positions: per axis `scale = (max − min) / 255`,
/// `translate = min`, each coordinate rounded to the nearest step; normal
/// indices from the triangles (counter-clockwise, as the importers give them).
pub fn quantize_frame(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    name: &str,
) -> Result<Md2Frame> {
    if let Some(v) = positions
        .iter()
        .position(|p| p.iter().any(|x| !x.is_finite()))
    {
        return Err(Error::Parameter(format!("vertex {v} is not finite")));
    }
    let quake: Vec<[f32; 3]> = positions.iter().map(|&p| y_up_to_quake(p)).collect();
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in &quake {
        for k in 0..3 {
            min[k] = min[k].min(p[k]);
            max[k] = max[k].max(p[k]);
        }
    }
    if quake.is_empty() {
        (min, max) = ([0.0; 3], [0.0; 3]);
    }
    let scale: [f32; 3] = std::array::from_fn(|k| (max[k] - min[k]) / 255.0);
    let vertices: Vec<[u8; 4]> = quake
        .iter()
        .map(|p| {
            let b: [u8; 3] = std::array::from_fn(|k| {
                if scale[k] > 0.0 {
                    ((p[k] - min[k]) / scale[k]).round().clamp(0.0, 255.0) as u8
                } else {
                    0
                }
            });
            [b[0], b[1], b[2], 0]
        })
        .collect();
    let mut frame = Md2Frame {
        scale,
        translate: min,
        name: frame_name(name),
        vertices,
    };
    set_normal_indices(&mut frame, triangles);
    Ok(frame)
}

/// A frame name, NUL-padded to 16 bytes (cut at 15).
pub fn frame_name(name: &str) -> [u8; 16] {
    let mut out = [0u8; 16];
    for (o, b) in out.iter_mut().zip(name.bytes().take(15)) {
        *o = b;
    }
    out
}

/// Each vertex's normal index: the table entry nearest its area-weighted
/// normal over `triangles` (counter-clockwise, Y-up) in the frame's
/// decoded positions.
pub fn set_normal_indices(frame: &mut Md2Frame, triangles: &[[u32; 3]]) {
    let p: Vec<Vec3> = (0..frame.vertices.len())
        .map(|i| Vec3::from(quake_to_y_up(frame.quake_position(i))))
        .collect();
    let mut normals = vec![Vec3::ZERO; p.len()];
    for &[a, b, c] in triangles {
        let (a, b, c) = (a as usize, b as usize, c as usize);
        if a.max(b).max(c) >= p.len() {
            continue;
        }
        let n = (p[b] - p[a]).cross(p[c] - p[a]);
        for v in [a, b, c] {
            normals[v] += n;
        }
    }
    for (v, n) in frame.vertices.iter_mut().zip(normals) {
        v[3] = nearest_normal(y_up_to_quake(n.normalize_or_zero().to_array()));
    }
}

/// A mesh as an MD2 model: one frame named `frame`, no skin, every corner
/// at texture coordinate (0, 0). Positions are quantized to bytes (see
/// [`quantize_frame`]): the MD2 is an approximation of the mesh.
pub fn mesh_to_md2(mesh: &IndexedMesh) -> Result<Md2> {
    let n = mesh.positions.len();
    if n > MD2_MAX_VERTICES || mesh.triangles.len() > MD2_MAX_TRIANGLES {
        return Err(Error::Limit(format!(
            "MD2 holds at most {MD2_MAX_VERTICES} vertices and {MD2_MAX_TRIANGLES} triangles; \
             this mesh has {n} and {} (take a coarser level or simplify it first)",
            mesh.triangles.len()
        )));
    }
    if let Some(f) = mesh
        .triangles
        .iter()
        .position(|t| t.iter().any(|&v| v as usize >= n))
    {
        return Err(Error::Parameter(format!(
            "triangle {f} refers past the {n} vertices"
        )));
    }
    let frame = quantize_frame(&mesh.positions, &mesh.triangles, "frame0")?;
    Ok(Md2 {
        skin_width: BLANK_SKIN_SIDE,
        skin_height: BLANK_SKIN_SIDE,
        skins: Vec::new(),
        st: vec![[0, 0]],
        triangles: mesh
            .triangles
            .iter()
            // Back to MD2's clockwise order (the importer swaps the same corners).
            .map(|t| Md2Triangle {
                vertex: [t[0], t[2], t[1]].map(|v| v as u16),
                st: [0; 3],
            })
            .collect(),
        frames: vec![frame],
        gl_commands: Vec::new(),
    })
}

/// [`mesh_to_md2`] then [`write_md2`].
pub fn write_mesh_md2(mesh: &IndexedMesh, w: &mut impl Write) -> Result<()> {
    write_md2(&mesh_to_md2(mesh)?, w)
}

/// A skin name as MD2 stores it (NUL-padded to 64 bytes, cut at 63).
pub fn skin_name(name: &str) -> [u8; MD2_SKIN_NAME_BYTES] {
    let mut out = [0u8; MD2_SKIN_NAME_BYTES];
    for (o, b) in out
        .iter_mut()
        .zip(name.bytes().take(MD2_SKIN_NAME_BYTES - 1))
    {
        *o = b;
    }
    out
}

impl Md2 {
    /// The model with only `triangles` (indices into this model's vertices
    /// and texture coordinates): unused vertices and texture coordinates
    /// dropped, the rest renumbered in their order, every frame's packed
    /// vertices kept bit for bit and its normal indices recomputed. A level
    /// of detail made by collapses that never move a vertex.
    pub fn with_triangles(&self, triangles: &[Md2Triangle]) -> Md2 {
        let n = self.vertex_count();
        let mut vmap = vec![u16::MAX; n];
        let mut smap = vec![u16::MAX; self.st.len()];
        for t in triangles {
            for c in 0..3 {
                vmap[t.vertex[c] as usize] = 0;
                smap[t.st[c] as usize] = 0;
            }
        }
        let renumber = |map: &mut [u16]| {
            for (next, m) in map.iter_mut().filter(|m| **m == 0).enumerate() {
                *m = next as u16;
            }
        };
        renumber(&mut vmap);
        renumber(&mut smap);
        let kept_v: Vec<usize> = (0..n).filter(|&v| vmap[v] != u16::MAX).collect();
        let triangles: Vec<Md2Triangle> = triangles
            .iter()
            .map(|t| Md2Triangle {
                vertex: t.vertex.map(|v| vmap[v as usize]),
                st: t.st.map(|s| smap[s as usize]),
            })
            .collect();
        let mut out = Md2 {
            skin_width: self.skin_width,
            skin_height: self.skin_height,
            skins: self.skins.clone(),
            st: (0..self.st.len())
                .filter(|&s| smap[s] != u16::MAX)
                .map(|s| self.st[s])
                .collect(),
            triangles,
            frames: Vec::with_capacity(self.frames.len()),
            gl_commands: Vec::new(),
        };
        let ccw = out.mesh_triangles();
        for f in &self.frames {
            let mut frame = Md2Frame {
                scale: f.scale,
                translate: f.translate,
                name: f.name,
                vertices: kept_v.iter().map(|&v| f.vertices[v]).collect(),
            };
            set_normal_indices(&mut frame, &ccw);
            out.frames.push(frame);
        }
        out.gl_commands = gl_commands(&out);
        out
    }
}
