//! Writes the raw bytes of what the importer reads from each file named on
//! the command line (positions, colours, triangles, and the textured
//! surface's positions, UVs, triangles and image), for `sha256sum`: a
//! refactoring of an importer must leave them bit-identical.
//!
//! `cargo run -p vitrine-mesh --example import_dump -- FILE... | sha256sum`

use std::io::Write;
use std::path::Path;

use vitrine_mesh::import::{import_path_textured, ImportOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut out = std::io::stdout().lock();
    for arg in std::env::args().skip(1) {
        let got = import_path_textured(Path::new(&arg), &ImportOptions::default())?;
        let m = &got.mesh;
        let f32s = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        let u32s = |v: &[u32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        out.write_all(&f32s(m.positions.as_flattened()))?;
        out.write_all(m.colors.as_deref().unwrap_or(&[]).as_flattened())?;
        out.write_all(&u32s(m.triangles.as_flattened()))?;
        if let Some(t) = &got.texture {
            out.write_all(&f32s(t.positions.as_flattened()))?;
            out.write_all(&f32s(t.uvs.as_flattened()))?;
            out.write_all(&u32s(t.triangles.as_flattened()))?;
            out.write_all(t.image.as_raw())?;
        }
        for w in &got.warnings {
            out.write_all(w.as_bytes())?;
        }
    }
    Ok(())
}
