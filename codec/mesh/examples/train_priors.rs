//! Trains the connectivity priors (`codec/core/src/priors/table.rs`) on meshes:
//! `cargo run --release -p vitrine-mesh --example train_priors -- mesh… > table.rs`
//! (`scripts/train-priors.sh` runs it on the Stanford dragon from npm).
use vitrine_codec::{encode, EncodeOptions, GateStatistics};
use vitrine_mesh::import::{import_path, ImportOptions};
use vitrine_mesh::repair::{prepare, RepairOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() {
        return Err("usage: train_priors mesh… > codec/core/src/priors/table.rs".into());
    }
    let mut statistics = GateStatistics::default();
    for path in &paths {
        let mesh = import_path(path.as_ref(), &ImportOptions::default())?;
        let (mesh, _) = prepare(mesh, &RepairOptions::default())?;
        let stream = encode(&mesh, &EncodeOptions::default())?.bytes;
        statistics.add_stream(&stream)?;
        eprintln!("{path}: {} vertices", mesh.positions.len());
    }
    print!("{}", statistics.table_source());
    Ok(())
}
