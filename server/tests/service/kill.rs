//! Ingest atomicity: an ingest killed with SIGKILL inside its transaction
//! leaves nothing visible, and the slug can be ingested afterwards.
//!
//! The ingest runs in a child process: this test binary re-run on the
//! ignored `kill::child_ingest` alone, which calls the same `run_ingest` as
//! `vitrine ingest`.

use super::harness::{ingest_sample, sample_mesh, TestDb};
use clap::Parser;
use std::io::Write;
use std::process::Stdio;
use std::time::Duration;
use tokio::io::{AsyncBufReadExt, BufReader};
use vitrine::IngestArgs;

const CHILD_ENV: &str = "VITRINE_TEST_CHILD_INGEST";

#[derive(Parser)]
struct IngestCli {
    #[command(flatten)]
    args: IngestArgs,
}

/// The child half, run only by [`killed_ingest_leaves_nothing`] (ignored
/// otherwise, so it is never counted as a test that passed).
#[tokio::test]
#[ignore = "the child process of kill::killed_ingest_leaves_nothing"]
async fn child_ingest() {
    let spec = std::env::var(CHILD_ENV)
        .unwrap_or_else(|_| panic!("{CHILD_ENV} is set by the parent test"));
    let (db, mesh) = spec.split_once('\t').expect("url<TAB>path");
    let cli = IngestCli::parse_from([
        "ingest", mesh, "--db", db, "--slug", "killed", "--title", "Killed",
    ]);
    vitrine::run_ingest(cli.args).await.expect("child ingest");
}

fn write_off(path: &std::path::Path) {
    let mesh = sample_mesh();
    let mut out = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    writeln!(
        out,
        "OFF\n{} {} 0",
        mesh.positions.len(),
        mesh.triangles.len()
    )
    .unwrap();
    for p in &mesh.positions {
        writeln!(out, "{} {} {}", p[0], p[1], p[2]).unwrap();
    }
    for t in &mesh.triangles {
        writeln!(out, "3 {} {} {}", t[0], t[1], t[2]).unwrap();
    }
}

pub async fn killed_ingest_leaves_nothing(db: TestDb) {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("sample.off");
    write_off(&mesh);
    let mut child = tokio::process::Command::new(std::env::current_exe().unwrap())
        .args([
            "--ignored",
            "--exact",
            "kill::child_ingest",
            "--nocapture",
            "--test-threads=1",
        ])
        .env(CHILD_ENV, format!("{}\t{}", db.url, mesh.display()))
        .env("VITRINE_TEST_PAUSE_BEFORE_COMMIT_MS", "120000")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .kill_on_drop(true)
        .spawn()
        .expect("spawn child ingest");
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    let paused = tokio::time::timeout(Duration::from_secs(120), async {
        while let Ok(Some(line)) = lines.next_line().await {
            if line.contains("pausing") && line.contains("before commit") {
                return true;
            }
        }
        false
    })
    .await;
    assert_eq!(paused, Ok(true), "the child never reached its commit");

    // Every row is written but not committed: nothing shows.
    assert!(db.storage.model_by_slug("killed").await.unwrap().is_none());
    assert!(db.storage.list_models().await.unwrap().is_empty());

    child.start_kill().unwrap();
    let status = child.wait().await.unwrap();
    assert!(!status.success());
    assert!(db.storage.model_by_slug("killed").await.unwrap().is_none());
    assert!(db.storage.list_models().await.unwrap().is_empty());

    // The slug is free: the same ingest now succeeds as version 1.
    let report = ingest_sample(&*db.storage, "killed", "exhibition").await;
    assert_eq!(report.stored.version, 1);
    assert_eq!(db.storage.list_models().await.unwrap().len(), 1);
}
