//! `vitrine sample cloud` and `vitrine ingest` of a point cloud, as a user
//! runs them (issue 21): a PLY without faces is stored as a point stream,
//! and `--kind mesh` on it fails with a message that says what it is.

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
