//! `vitrine study` as a curator runs it (issue 17): open a study, print
//! invitations, import answers gathered on paper, report, apply the level
//! (which the manifest then shows), export the same CSV back.

use std::fmt::Write as _;
use std::process::{Command, Output};

fn vitrine(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vitrine"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .env("RUST_LOG", "warn")
        .output()
        .expect("vitrine runs")
}

fn succeeds(args: &[&str]) -> String {
    let out = vitrine(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "vitrine {args:?} failed: {stderr}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn fails(args: &[&str]) -> String {
    let out = vitrine(args);
    assert!(!out.status.success(), "vitrine {args:?} succeeded");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// `participants` sessions over levels `0..=last`: participant k finds every
/// level from `good(k)` on sufficient; the control step (a no-transition
/// step after step 2) answered "none", except by `fooled`.
fn answers(last: u32, good: impl Fn(usize) -> u32, participants: usize, fooled: usize) -> String {
    let mut csv =
        String::from("participant,step,from_level,to_level,control,improvement,sufficient\n");
    for k in 0..participants {
        let mut step = 1;
        for b in 1..=last {
            let yes = if b >= good(k) { "yes" } else { "no" };
            writeln!(csv, "p{k:02},{step},{},{b},false,a-little,{yes}", b - 1).unwrap();
            step += 1;
            if b == 2 {
                let improvement = if k == fooled { "improved" } else { "none" };
                writeln!(csv, "p{k:02},{step},2,2,true,{improvement},{yes}").unwrap();
                step += 1;
            }
        }
    }
    csv
}

#[tokio::test]
async fn curator_runs_a_study_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    let db = format!("sqlite:{}", path("vitrine.db"));
    succeeds(&[
        "sample",
        "sphere",
        "--kilo-vertices",
        "5",
        "-o",
        &path("bust.ply"),
    ]);
    succeeds(&[
        "ingest",
        &path("bust.ply"),
        "--db",
        &db,
        "--slug",
        "bust",
        "--title",
        "Bust",
    ]);
    let target = ["--db", db.as_str(), "--slug", "bust"];
    let with = |action: &str, extra: &[&str]| -> Vec<String> {
        let mut args = vec!["study".to_owned(), action.to_owned()];
        args.extend(target.iter().map(|s| s.to_string()));
        args.extend(extra.iter().map(|s| s.to_string()));
        args
    };
    let run = |args: Vec<String>| succeeds(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let refused = |args: Vec<String>| fails(&args.iter().map(String::as_str).collect::<Vec<_>>());

    // Reporting before any study says how to open one.
    assert!(refused(with("report", &[])).contains("has no study"));
    let created = run(with("create", &["--seconds", "0.5"]));
    assert!(created.contains("is open"), "{created}");
    assert!(refused(with("create", &[])).contains("open already"));
    let links = run(with(
        "invite",
        &["--count", "3", "--base-url", "https://museum.example/"],
    ));
    let links: Vec<&str> = links.lines().collect();
    assert_eq!(links.len(), 3);
    for link in &links {
        let token = link
            .strip_prefix("https://museum.example/study/bust?invitation=inv_")
            .unwrap_or_else(|| panic!("{link}"));
        assert_eq!(token.len(), 64);
    }

    // The model's levels decide which answers are valid.
    let store = vitrine::storage::connect(&db, &Default::default()).unwrap();
    let record = store.model_by_slug("bust").await.unwrap().unwrap();
    let last = record.batch_count();
    assert!(last >= 4);
    // 12 participants: 10 good from last - 1, one from last - 2, one fooled
    // by the control step. p90 of the 11 valid is last - 1.
    let csv = answers(last, |k| if k == 3 { last - 2 } else { last - 1 }, 12, 5);
    std::fs::write(path("paper.csv"), &csv).unwrap();

    // A malformed file names its line and stores nothing.
    let bad = csv.replacen(",a-little,", ",somewhat,", 1);
    std::fs::write(path("bad.csv"), &bad).unwrap();
    let e = refused(with("import", &[&path("bad.csv")]));
    assert!(e.contains("line 2") && e.contains("improvement"), "{e}");
    let imported = run(with("import", &[&path("paper.csv")]));
    assert!(imported.contains("imported 12 participants"), "{imported}");
    // The same file again conflicts, and nothing of it is stored twice.
    let e = refused(with("import", &[&path("paper.csv")]));
    assert!(e.contains("already"), "{e}");

    let report: serde_json::Value =
        serde_json::from_str(&run(with("report", &["--json"]))).unwrap();
    assert_eq!(report["valid_sessions"], 11);
    assert_eq!(report["excluded_sessions"], 1);
    assert_eq!(report["excluded"][0]["participant"], "p05");
    assert_eq!(report["excluded"][0]["reason"], "control-improvement");
    assert_eq!(report["good_enough_level"], last - 1);
    let top = report["levels"].as_array().unwrap().last().unwrap();
    assert_eq!(
        (top["level"].as_u64(), top["sufficient"].as_u64()),
        (Some(u64::from(last)), Some(11))
    );

    // --apply refuses below the minimum unless forced; then the manifest's
    // good-enough level is the study's.
    let e = refused(with("report", &["--apply", "--min-participants", "20"]));
    assert!(e.contains("fewer than --min-participants 20"), "{e}");
    run(with("report", &["--apply"]));
    let record = store.model_by_slug("bust").await.unwrap().unwrap();
    assert_eq!(record.good_enough_level, Some(last - 1));

    // Export gives the imported file back, byte for byte.
    run(with(
        "export",
        &["-o", &path("out.csv"), "--views", &path("views.csv")],
    ));
    assert_eq!(std::fs::read_to_string(path("out.csv")).unwrap(), csv);
    let views = std::fs::read_to_string(path("views.csv")).unwrap();
    assert_eq!(views.trim(), "participant,at_ms,step,state,kind,data");
}
