//! The mesh files `decode` and `simplify` write, chosen by the output's
//! extension, and checked before any work is done.

use anyhow::{bail, Context};
use std::io::{BufWriter, Write};
use std::path::Path;
use vitrine_codec::IndexedMesh;
use vitrine_mesh::export::{write_glb, write_mesh_md2, write_obj, write_ply};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    Ply,
    Obj,
    Glb,
    /// Quake II MD2: one frame, positions quantized to bytes, at most 2,048
    /// vertices and 4,096 triangles.
    Md2,
}

impl MeshFormat {
    /// The format `path`'s extension names: .ply, .obj, .glb or .md2 (any case).
    pub fn from_path(path: &Path) -> anyhow::Result<MeshFormat> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        Ok(match extension.as_deref() {
            Some("ply") => MeshFormat::Ply,
            Some("obj") => MeshFormat::Obj,
            Some("glb") => MeshFormat::Glb,
            Some("md2") => MeshFormat::Md2,
            _ => bail!(
                "output {} must end in .ply, .obj, .glb or .md2",
                path.display()
            ),
        })
    }

    pub fn write(self, mesh: &IndexedMesh, path: &Path) -> anyhow::Result<()> {
        let file =
            std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?;
        let mut w = BufWriter::new(file);
        match self {
            MeshFormat::Ply => write_ply(mesh, &mut w)?,
            MeshFormat::Obj => write_obj(mesh, &mut w)?,
            MeshFormat::Glb => write_glb(mesh, &mut w)?,
            MeshFormat::Md2 => write_mesh_md2(mesh, &mut w)?,
        }
        w.flush()
            .with_context(|| format!("writing {}", path.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_extension_picks_the_format_in_any_case() {
        let format = |p: &str| MeshFormat::from_path(Path::new(p));
        assert_eq!(format("a/b.ply").unwrap(), MeshFormat::Ply);
        assert_eq!(format("b.OBJ").unwrap(), MeshFormat::Obj);
        assert_eq!(format("b.Glb").unwrap(), MeshFormat::Glb);
        assert_eq!(format("level.md2").unwrap(), MeshFormat::Md2);
        for bad in ["b.stl", "b", "b.ply.gz"] {
            let e = format(bad).unwrap_err().to_string();
            assert!(
                e.contains("must end in .ply, .obj, .glb or .md2"),
                "{bad}: {e}"
            );
        }
    }
}
