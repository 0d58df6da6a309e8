//! `vitrine-dev bench`: bits per vertex, speed and peak memory on a set of meshes,
//! optionally beside Google Draco, as a markdown table for BENCHMARKS.md.
//!
//! Each mesh runs in a child process (`vitrine-dev bench-one`) so its peak
//! resident memory is its own.

use anyhow::{bail, Context};
use clap::Args;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;
use vitrine_codec::{breakdown, decode, encode, EncodeOptions, IndexedMesh, Limits};
use vitrine_mesh::export::write_ply;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Mesh files or folders of meshes.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    #[arg(short = 'q', long, default_value_t = 12)]
    pub bits: u8,
    /// Timed runs per mesh; the median is reported.
    #[arg(long, default_value_t = 5)]
    pub runs: usize,
    /// Run Google Draco on the same meshes through this script (peer_draco.py).
    #[arg(long)]
    pub draco: Option<PathBuf>,
    /// Also write the table to this markdown file.
    #[arg(long)]
    pub markdown: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct BenchOneArgs {
    pub input: PathBuf,
    #[arg(short = 'q', long, default_value_t = 12)]
    pub bits: u8,
    #[arg(long, default_value_t = 5)]
    pub runs: usize,
    /// Also write the mesh as encoded (positions and triangles, after
    /// import and repair) to this binary PLY, for a peer coder to read.
    #[arg(long)]
    pub write_mesh: Option<PathBuf>,
}

#[derive(Serialize, Deserialize, Debug)]
pub struct BenchResult {
    pub name: String,
    pub vertices: usize,
    pub faces: usize,
    pub colour: bool,
    pub levels: usize,
    pub base_vertices: u32,
    pub bytes: usize,
    pub connectivity_bpv: f64,
    pub geometry_bpv: f64,
    pub colour_bpv: f64,
    pub base_bpv: f64,
    pub total_bpv: f64,
    pub encode_ms: f64,
    pub decode_ms: f64,
    pub peak_rss_mib: f64,
}

/// Runs `f` `runs` times (at least once): the median time in milliseconds,
/// and the last result (dropped outside the timing).
fn timed<T>(runs: usize, mut f: impl FnMut() -> anyhow::Result<T>) -> anyhow::Result<(f64, T)> {
    let mut ms = Vec::new();
    let mut last = None;
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        let value = f()?;
        ms.push(t.elapsed().as_secs_f64() * 1e3);
        last = Some(value);
    }
    Ok((median(ms), last.expect("at least one run")))
}

/// The mesh as encoded, without its colour, as a binary PLY for the peer coder.
fn write_geometry(mesh: &IndexedMesh, path: &Path) -> anyhow::Result<()> {
    let geometry = IndexedMesh {
        colors: None,
        ..mesh.clone()
    };
    let mut file = std::io::BufWriter::new(std::fs::File::create(path)?);
    write_ply(&geometry, &mut file)?;
    file.flush()?;
    Ok(())
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Peak resident set size of this process (Linux `VmHWM`), in MiB.
fn peak_rss_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kib| kib / 1024.0)
}

pub fn run_one(args: BenchOneArgs) -> anyhow::Result<()> {
    println!("{}", serde_json::to_string(&measure(&args)?)?);
    Ok(())
}

/// Encodes and decodes one mesh `args.runs` times; sizes, median speeds and
/// this process's peak memory.
fn measure(args: &BenchOneArgs) -> anyhow::Result<BenchResult> {
    let (mesh, _) = crate::source::load_mesh(&args.input)?;
    if let Some(path) = &args.write_mesh {
        write_geometry(&mesh, path)?;
    }
    let options = EncodeOptions {
        quantization_bits: args.bits,
        // Speeds are per core: code the passes on the encoding thread.
        pipelined: false,
        ..EncodeOptions::default()
    };
    let (encode_ms, encoded) = timed(args.runs, || Ok(encode(&mesh, &options)?))?;
    let (decode_ms, _) = timed(args.runs, || {
        let d = decode(&encoded.bytes, None, Limits::default())?;
        std::hint::black_box(d.indices().len());
        Ok(d)
    })?;
    let levels = breakdown(&encoded.bytes)?;
    let n = mesh.positions.len() as f64;
    let per_vertex = |f: fn(&vitrine_codec::LevelBreakdown) -> u32| {
        levels[1..].iter().map(f).sum::<u32>() as f64 * 8.0 / n
    };
    let result = BenchResult {
        name: args
            .input
            .file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        vertices: mesh.positions.len(),
        faces: mesh.triangles.len(),
        colour: mesh.colors.is_some(),
        levels: encoded.header.batch_count(),
        base_vertices: encoded.header.levels[0].vertices,
        bytes: encoded.bytes.len(),
        connectivity_bpv: per_vertex(|l| l.connectivity + l.overhead),
        geometry_bpv: per_vertex(|l| l.geometry),
        colour_bpv: per_vertex(|l| l.colour),
        base_bpv: (levels[0].bytes as usize + encoded.header.byte_len()) as f64 * 8.0 / n,
        total_bpv: encoded.bytes.len() as f64 * 8.0 / n,
        encode_ms,
        decode_ms,
        peak_rss_mib: peak_rss_mib(),
    };
    Ok(result)
}

fn mesh_files(inputs: &[PathBuf]) -> anyhow::Result<Vec<PathBuf>> {
    let is_mesh = |p: &Path| {
        matches!(
            p.extension()
                .and_then(|e| e.to_str())
                .map(str::to_ascii_lowercase)
                .as_deref(),
            Some("ply" | "obj" | "off" | "gltf" | "glb")
        )
    };
    let mut out = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let mut entries: Vec<PathBuf> = std::fs::read_dir(input)?
                .filter_map(|e| Some(e.ok()?.path()))
                .collect();
            entries.sort();
            for e in entries {
                if e.is_dir() {
                    out.extend(mesh_files(&[e])?);
                } else if is_mesh(&e) {
                    out.push(e);
                }
            }
        } else {
            out.push(input.clone());
        }
    }
    Ok(out)
}

/// Draco's bits per vertex and decode speed per mesh, keyed by the name of
/// the file `files` holds (each written by `bench-one --write-mesh` as
/// `<mesh file name>.ply`, so the key is the original name).
fn run_draco(script: &Path, files: &[PathBuf], bits: u8) -> anyhow::Result<DracoRows> {
    let out = Command::new("python3")
        .arg(script)
        .arg("--bits")
        .arg(bits.to_string())
        .args(files)
        .output()
        .context("running python3 for Draco")?;
    if !out.status.success() {
        bail!(
            "Draco script failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    Ok(draco_rows(&String::from_utf8_lossy(&out.stdout)))
}

/// Parses `peer_draco.py`'s tab-separated rows (after its header line).
fn draco_rows(table: &str) -> DracoRows {
    let mut map = HashMap::new();
    for line in table.lines().skip(1) {
        let cols: Vec<&str> = line.split('\t').collect();
        if cols.len() >= 9 {
            let written = Path::new(cols[0])
                .file_name()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            let name = written.strip_suffix(".ply").unwrap_or(&written).to_owned();
            map.insert(
                name,
                (
                    cols[5].parse().unwrap_or(f64::NAN),
                    cols[8].parse().unwrap_or(f64::NAN),
                ),
            );
        }
    }
    map
}

pub fn run(args: BenchArgs) -> anyhow::Result<()> {
    let files = mesh_files(&args.inputs)?;
    let exe = std::env::current_exe()?;
    // Draco is given the very meshes we encode (welded, repaired, without
    // unused vertices), so both sizes count the same vertices and faces.
    let peer_meshes = match &args.draco {
        Some(_) => Some(tempfile::tempdir().context("a folder for Draco's meshes")?),
        None => None,
    };
    let mut results = Vec::new();
    let mut written = Vec::new();
    for file in &files {
        eprintln!("bench {}", file.display());
        let mut one = Command::new(&exe);
        one.arg("bench-one").arg(file).args([
            "--bits",
            &args.bits.to_string(),
            "--runs",
            &args.runs.to_string(),
        ]);
        let peer_mesh = peer_meshes.as_ref().and_then(|dir| {
            let name = file.file_name()?.to_string_lossy().into_owned();
            Some(dir.path().join(format!("{name}.ply")))
        });
        if let Some(path) = &peer_mesh {
            one.arg("--write-mesh").arg(path);
        }
        let out = one.output()?;
        if !out.status.success() {
            eprintln!("  skipped: {}", String::from_utf8_lossy(&out.stderr).trim());
            continue;
        }
        results.push(serde_json::from_slice::<BenchResult>(&out.stdout)?);
        written.extend(peer_mesh);
    }
    let draco = match &args.draco {
        Some(script) if !written.is_empty() => Some(run_draco(script, &written, args.bits)?),
        _ => None,
    };
    let table = markdown(&results, draco.as_ref(), args.bits, args.runs);
    println!("{table}");
    if let Some(path) = &args.markdown {
        std::fs::write(path, &table)?;
    }
    Ok(())
}

/// Draco's bits per vertex and decode speed, by mesh file name.
type DracoRows = HashMap<String, (f64, f64)>;

fn markdown(results: &[BenchResult], draco: Option<&DracoRows>, bits: u8, runs: usize) -> String {
    let mut s = format!(
        "{bits}-bit quantization; speeds are the median of {runs} runs on one core; bits per vertex (b/v) over the final vertex count.\n\n"
    );
    s += &table_header(draco.is_some());
    let mut sums = [0.0; 3];
    for r in results {
        s += &table_row(r, draco);
        sums[0] += r.connectivity_bpv;
        sums[1] += r.total_bpv;
        sums[2] += 1.0;
    }
    if sums[2] > 0.0 {
        s += &format!(
            "\nMean connectivity {:.2} b/v, mean total {:.2} b/v over {} meshes.\n",
            sums[0] / sums[2],
            sums[1] / sums[2],
            sums[2]
        );
    }
    s
}

fn table_header(with_draco: bool) -> String {
    let mut s = String::from(
        "| mesh | vertices | levels | base v | conn b/v | geom b/v | colour b/v | base b/v | total b/v |",
    );
    if with_draco {
        s += " Draco b/v | ours / Draco (no colour) |";
    }
    s += " encode Mv/s | decode Mv/s |";
    if with_draco {
        s += " Draco decode Mv/s |";
    }
    s += " peak MiB |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|";
    if with_draco {
        s += "---:|---:|";
    }
    s += "---:|---:|";
    if with_draco {
        s += "---:|";
    }
    s += "---:|\n";
    s
}

fn table_row(r: &BenchResult, draco: Option<&DracoRows>) -> String {
    let mv = |ms: f64| r.vertices as f64 / ms / 1e3;
    let mut s = format!(
        "| {} | {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |",
        r.name,
        r.vertices,
        r.levels,
        r.base_vertices,
        r.connectivity_bpv,
        r.geometry_bpv,
        r.colour_bpv,
        r.base_bpv,
        r.total_bpv
    );
    let peer = draco.and_then(|d| d.get(&r.name));
    if draco.is_some() {
        match peer {
            // Draco codes positions only: compare without our colour bits.
            Some((bpv, _)) => {
                s += &format!(" {bpv:.2} | {:.3} |", (r.total_bpv - r.colour_bpv) / bpv)
            }
            None => s += " – | – |",
        }
    }
    s += &format!(" {:.2} | {:.2} |", mv(r.encode_ms), mv(r.decode_ms));
    if draco.is_some() {
        match peer {
            Some((_, speed)) => s += &format!(" {speed:.2} |"),
            None => s += " – |",
        }
    }
    s += &format!(" {:.0} |\n", r.peak_rss_mib);
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use vitrine_mesh::import::{import_path, ImportOptions};
    use vitrine_samples as samples;

    /// Draco must be handed the mesh we encode, not the file: an OBJ whose
    /// seams duplicate vertices is welded by our import, so the file holds
    /// more vertices than either coder should count.
    #[test]
    fn the_peer_gets_the_mesh_as_encoded() {
        let dir = tempfile::tempdir().unwrap();
        let mut torus = samples::torus(24, 12, 1.0, 0.3);
        samples::paint(&mut torus);
        // Every face gets corners of its own: 3 vertices per face in the file.
        let unwelded = IndexedMesh {
            positions: torus
                .triangles
                .iter()
                .flat_map(|t| t.map(|v| torus.positions[v as usize]))
                .collect(),
            triangles: (0..torus.triangles.len() as u32)
                .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
                .collect(),
            colors: None,
        };
        let input = dir.path().join("seams.obj");
        let mut file = std::fs::File::create(&input).unwrap();
        vitrine_mesh::export::write_obj(&unwelded, &mut file).unwrap();
        drop(file);
        let written = dir.path().join("seams.obj.ply");
        let result = measure(&BenchOneArgs {
            input: input.clone(),
            bits: 12,
            runs: 1,
            write_mesh: Some(written.clone()),
        })
        .unwrap();
        let peer = import_path(&written, &ImportOptions::default()).unwrap();
        let (encoded, _) = crate::source::load_mesh(&input).unwrap();
        assert_eq!(result.vertices, torus.positions.len());
        assert_eq!(peer.positions.len(), result.vertices);
        assert_eq!(peer.triangles.len(), result.faces);
        assert_eq!(peer.positions, encoded.positions);
        assert_eq!(peer.triangles, encoded.triangles);
        assert!(peer.colors.is_none(), "Draco is compared on positions only");
    }

    #[test]
    fn draco_rows_are_keyed_by_the_original_file_name() {
        let table = "mesh\tvertices\tfaces\tbits\tbytes\tbpv\tencode_ms\tdecode_ms\tdecode_Mv_s\n\
                     bunny.ply.ply\t34834\t69451\t12\t52729\t12.11\t80.0\t9.5\t3.67\n\
                     /tmp/x/suzanne.obj.ply\t508\t968\t12\t1930\t30.30\t1.0\t0.2\t2.65\n\
                     short\trow\n";
        let rows = draco_rows(table);
        assert_eq!(rows.len(), 2);
        assert_eq!(rows["bunny.ply"], (12.11, 3.67));
        assert_eq!(rows["suzanne.obj"], (30.30, 2.65));
    }
}
