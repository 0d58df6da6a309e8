//! `vitrine sample cloud` and `vitrine ingest` of a point cloud, as a user
//! runs them (issue 21): a PLY without faces is stored as a point stream,
//! and `--kind mesh` on it fails with a message that says what it is; a
//! LAZ file (georeferenced, without normals) is one too.

use std::path::Path;
use std::process::{Command, Output};

fn vitrine(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vitrine"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("vitrine runs")
}

fn text(path: &Path) -> &str {
    path.to_str().expect("a UTF-8 temporary path")
}

#[test]
fn faceless_ply_is_ingested_as_points() {
    let dir = tempfile::tempdir().unwrap();
    let ply = dir.path().join("cube.ply");
    let db = format!("sqlite:{}", dir.path().join("v.db").display());
    let out = vitrine(&[
        "sample",
        "cloud",
        "-o",
        text(&ply),
        "--kilo-vertices",
        "5",
        "--colour",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let head = std::fs::read(&ply).unwrap();
    let header = String::from_utf8_lossy(&head[..head.len().min(400)]).into_owned();
    assert!(header.contains("element vertex 5000"), "{header}");
    assert!(!header.contains("element face"), "{header}");

    let ingest = |slug: &str, extra: &[&str]| {
        let mut args = vec![
            "ingest",
            text(&ply),
            "--db",
            &db,
            "--slug",
            slug,
            "--title",
            "Cube",
        ];
        args.extend_from_slice(extra);
        vitrine(&args)
    };
    let out = ingest("cube", &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("point cloud"), "{stdout}");
    assert!(stdout.contains("→ 5000 points"), "{stdout}");

    let out = ingest("forced", &["--kind", "mesh"]);
    assert!(!out.status.success(), "--kind mesh on a cloud must fail");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("is a point cloud (no faces)") && stderr.contains("--kind points"),
        "not a clear error: {stderr}"
    );

    // The model list shows the cloud as points, and nothing else.
    let out = vitrine(&["models", "--db", &db]);
    let listed = String::from_utf8_lossy(&out.stdout);
    let line = listed.lines().find(|l| l.starts_with("cube")).unwrap_or("");
    assert!(line.contains(" points "), "{listed}");
    assert!(!listed.contains("forced"), "{listed}");
}

/// A LAZ file of `n` points on a gently sloping 40-wide grid, far from the
/// origin as georeferenced scans are, with colour and without normals.
fn laz_bytes(n: usize) -> Vec<u8> {
    let mut b = las::Builder::from((1, 2));
    b.point_format = las::point::Format::new(2).unwrap();
    b.point_format.is_compressed = true;
    let t = |offset| las::Transform {
        scale: 0.001,
        offset,
    };
    b.transforms = las::Vector {
        x: t(500_000.0),
        y: t(4_000_000.0),
        z: t(0.0),
    };
    let header = b.into_header().unwrap();
    let mut w = las::Writer::new(std::io::Cursor::new(Vec::new()), header).unwrap();
    for i in 0..n {
        let (col, row) = ((i % 40) as f64, (i / 40) as f64);
        w.write_point(las::Point {
            x: 500_000.0 + col * 0.05,
            y: 4_000_000.0 + row * 0.05,
            z: 12.5 + 0.01 * col,
            color: Some(las::Color::new((i * 257) as u16, 65535, 0)),
            ..Default::default()
        })
        .unwrap();
    }
    w.close().unwrap();
    w.into_inner().unwrap().into_inner()
}

#[test]
fn laz_is_ingested_as_points_with_estimated_normals() {
    let dir = tempfile::tempdir().unwrap();
    let laz = dir.path().join("site.laz");
    std::fs::write(&laz, laz_bytes(2000)).unwrap();
    let db = format!("sqlite:{}", dir.path().join("v.db").display());
    let out = vitrine(&[
        "ingest",
        text(&laz),
        "--db",
        &db,
        "--slug",
        "site",
        "--title",
        "Site",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("point cloud"), "{stdout}");
    assert!(stdout.contains("→ 2000 points"), "{stdout}");
    assert!(stdout.contains("normals estimated"), "{stdout}");
}
