//! What the simplifier benches share: loading a scan as every import is
//! repaired (or the generated plate), and the quadric-error peer
//! (`scripts/peer_quadric.py`, fast-simplification) on the very same mesh.
//! Included by each bench with `#[path = "support/mod.rs"] mod support;`.

#![allow(dead_code)] // each bench uses its own share of it

use std::process::Command;

use vitrine_codec::IndexedMesh;
use vitrine_mesh::export::write_ply;
use vitrine_mesh::import::{import_path, ImportOptions};
use vitrine_mesh::repair::{prepare, RepairOptions};
use vitrine_quality::metrics::hausdorff;

/// Area samples per mesh for Hausdorff (plus the vertices).
pub const SAMPLES: usize = 200_000;

pub type Failure = Box<dyn std::error::Error>;

/// A scan from a file, repaired as every import is; or `plate`, the
/// generated genus-3 plate (flat faces, sharp edges:
/// `vitrine_samples::plate_with_tunnels(3, 6)`).
pub fn load(path: &str) -> Result<IndexedMesh, Failure> {
    if path == "plate" {
        return Ok(vitrine_samples::plate_with_tunnels(3, 6));
    }
    let mesh = import_path(path.as_ref(), &ImportOptions::default())?;
    Ok(prepare(mesh, &RepairOptions::default())?.0)
}

/// The file name of `path` (or `plate`).
pub fn name(path: &str) -> &str {
    std::path::Path::new(path)
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or(path)
}

/// The peer `script` on `mesh` keeping `fraction` of its faces: its faces,
/// Hausdorff over the diagonal against `mesh`, seconds (its own timing).
pub fn peer(script: &str, mesh: &IndexedMesh, fraction: f64) -> Result<(usize, f64, f64), Failure> {
    let dir = tempfile_dir()?;
    let (input, output) = (dir.join("in.ply"), dir.join("out.ply"));
    let geometry = IndexedMesh {
        colors: None,
        ..mesh.clone()
    };
    write_ply(
        &geometry,
        &mut std::io::BufWriter::new(std::fs::File::create(&input)?),
    )?;
    let run = Command::new("python3")
        .arg(script)
        .arg(&input)
        .arg(&output)
        .arg(fraction.to_string())
        .output()?;
    if !run.status.success() {
        return Err(String::from_utf8_lossy(&run.stderr).into_owned().into());
    }
    let ms: f64 = String::from_utf8_lossy(&run.stdout).trim().parse()?;
    let simplified = import_path(&output, &ImportOptions::default())?;
    let h = hausdorff(mesh, &simplified, SAMPLES).relative();
    std::fs::remove_dir_all(&dir)?;
    Ok((simplified.triangles.len(), h, ms / 1000.0))
}

/// A fresh directory for one peer run.
fn tempfile_dir() -> std::io::Result<std::path::PathBuf> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static RUN: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "vitrine-peer-{}-{}",
        std::process::id(),
        RUN.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}

/// Hausdorff over the diagonal below which a simplification lost nothing
/// (f32 positions of a unit-scale model round at about 1e-7).
const NOTHING: f64 = 1e-6;

/// `ours / quadric`, said plainly where quadric loses nothing (then ours
/// is given as it is).
pub fn ratio(ours: f64, quadric: f64) -> String {
    match (ours < NOTHING, quadric < NOTHING) {
        (true, true) => "both 0".into(),
        (false, true) => format!("quadric 0, ours {ours:.5}"),
        _ => format!("{:.2}", ours / quadric),
    }
}
