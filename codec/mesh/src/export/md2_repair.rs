//! An MD2 model repaired as every other import is (issue 45: `vitrine lod`
//! read MD2 files as they came, and a real model with one non-manifold
//! edge or a degenerate face failed): the same repair as
//! [`crate::repair::prepare`], done on the connectivity, with every frame
//! and every corner's texture coordinate carried along by its trace.

use super::md2::{gl_commands, set_normal_indices};
use crate::import::md2::{Md2, Md2Frame, Md2Triangle};
use crate::repair::{prepare_traced, RepairOptions, RepairReport};
use crate::{Error, IndexedMesh, Result};

impl Md2 {
    /// The model with degenerate and duplicate triangles dropped, faces
    /// oriented alike and non-manifold edges and vertices split (a split
    /// vertex is copied in every frame). Vertices are never welded by
    /// position: two that coincide in one frame may part in another.
    pub fn repaired(&self) -> Result<(Md2, RepairReport)> {
        let first = self.frame(0)?;
        let ccw = self.mesh_triangles();
        let mesh = IndexedMesh {
            positions: first.positions(),
            colors: None,
            triangles: ccw.clone(),
        };
        let options = RepairOptions {
            weld: false,
            ..RepairOptions::default()
        };
        let (out, report, trace) = prepare_traced(mesh, &options)?;
        if out.positions.len() > u16::MAX as usize {
            return Err(Error::Unsupported(format!(
                "the repaired MD2 model has {} vertices, more than an MD2 file can index",
                out.positions.len()
            )));
        }
        let triangles = out
            .triangles
            .iter()
            .zip(&trace.face_origin)
            .map(|(t, &f)| {
                let input = &self.triangles[f as usize];
                // The input's corners counter-clockwise, as `ccw` has them.
                let (vertices, st) = (ccw[f as usize], [input.st[0], input.st[2], input.st[1]]);
                let corner_st = |v: u32| {
                    let origin = trace.vertex_origin[v as usize];
                    let k = vertices.iter().position(|&w| w == origin);
                    k.map(|k| st[k])
                };
                let s = [corner_st(t[0]), corner_st(t[1]), corner_st(t[2])];
                let [Some(a), Some(b), Some(c)] = s else {
                    return Err(Error::Unsupported(
                        "the repair moved a corner off its triangle".into(),
                    ));
                };
                // Back to MD2's clockwise corners.
                Ok(Md2Triangle {
                    vertex: [t[0], t[2], t[1]].map(|v| v as u16),
                    st: [a, c, b],
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let mut model = Md2 {
            skin_width: self.skin_width,
            skin_height: self.skin_height,
            skins: self.skins.clone(),
            st: self.st.clone(),
            triangles,
            frames: Vec::with_capacity(self.frames.len()),
            gl_commands: Vec::new(),
        };
        for f in &self.frames {
            let mut frame = Md2Frame {
                scale: f.scale,
                translate: f.translate,
                name: f.name,
                vertices: trace
                    .vertex_origin
                    .iter()
                    .map(|&v| f.vertices[v as usize])
                    .collect(),
            };
            set_normal_indices(&mut frame, &out.triangles);
            model.frames.push(frame);
        }
        model.gl_commands = gl_commands(&model);
        Ok((model, report))
    }
}
