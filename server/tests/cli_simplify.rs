//! `vitrine encode --guard features` and `vitrine simplify` as a user runs
//! them: the built binary on a generated sample written to a temporary
//! folder, its files checked with the library.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use vitrine_codec::{decode, EncodeOptions, Encoder, IndexedMesh, Limits, Quantization};
use vitrine_mesh::import::{import_path, ImportOptions};
use vitrine_mesh::repair::{check_manifold, prepare, RepairOptions};
use vitrine_simplify::{
    search_feature_guard, FeatureGuard, FeatureThreshold, DEFAULT_CONNECTIVITY_BUDGET,
};

fn vitrine(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vitrine"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("vitrine runs")
}

/// Runs `vitrine` and returns its stdout and stderr; it must succeed.
fn succeeds(args: &[&str]) -> (String, String) {
    let out = vitrine(args);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    );
    assert!(out.status.success(), "vitrine {args:?} failed: {stderr}");
    (stdout, stderr)
}

/// Runs `vitrine` and returns its stderr; it must fail.
fn fails(args: &[&str]) -> String {
    let out = vitrine(args);
    assert!(!out.status.success(), "vitrine {args:?} succeeded");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The genus-3 plate (5504 vertices, sharp edges for the feature guard) as
/// a PLY file in `dir`.
fn plate(dir: &Path) -> PathBuf {
    let path = dir.join("plate.ply");
    let mesh = vitrine_samples::plate_with_tunnels(3, 9);
    let file = std::fs::File::create(&path).unwrap();
    vitrine_mesh::export::write_ply(&mesh, &mut std::io::BufWriter::new(file)).unwrap();
    path
}

fn read(path: &Path) -> IndexedMesh {
    import_path(path, &ImportOptions::default()).expect("reads back")
}

/// The file as the commands see it: imported and repaired.
fn repaired(path: &Path) -> IndexedMesh {
    prepare(read(path), &RepairOptions::default()).unwrap().0
}

fn text(path: &Path) -> &str {
    path.to_str().expect("a UTF-8 temporary path")
}

#[test]
fn encode_without_a_guard_is_the_plain_stream() {
    let dir = tempfile::tempdir().unwrap();
    let (input, output) = (plate(dir.path()), dir.path().join("plain.vtr"));
    succeeds(&["encode", text(&input), "-o", text(&output)]);
    let plain = vitrine_codec::encode(&repaired(&input), &EncodeOptions::default()).unwrap();
    assert!(std::fs::read(&output).unwrap() == plain.bytes);
}

#[test]
fn encode_with_the_feature_guard_is_guarded_and_lossless() {
    let dir = tempfile::tempdir().unwrap();
    let (input, output) = (plate(dir.path()), dir.path().join("guarded.vtr"));
    // A fixed setting: the library's default guard.
    let (_, stderr) = succeeds(&[
        "encode",
        text(&input),
        "--guard",
        "features",
        "--feature-setting",
        "0.3:0.3",
        "-o",
        text(&output),
    ]);
    assert!(stderr.contains("feature guard: threshold"), "{stderr}");
    assert!(stderr.contains("share 0.3, relief gate 0.3"), "{stderr}");
    let bytes = std::fs::read(&output).unwrap();
    let mesh = repaired(&input);
    let options = EncodeOptions::default();
    let plain = vitrine_codec::encode(&mesh, &options).unwrap();
    assert!(
        bytes != plain.bytes,
        "the guard changed nothing on the plate"
    );

    let q = Quantization::for_positions(&mesh.positions, options.quantization_bits).unwrap();
    let guard = FeatureGuard::new(&mesh, &q, FeatureThreshold::MeanPlusTwoSigma);
    let expected = Encoder::new(options.clone())
        .guard(&guard)
        .encode(&mesh)
        .unwrap();
    assert!(bytes == expected.bytes, "not the library's guarded stream");
    let decoder = decode(&bytes, None, Limits::default()).unwrap();
    assert_eq!(decoder.to_mesh().vertex_count(), mesh.vertex_count());
    let mismatch =
        vitrine_samples::final_level_mismatch(&mesh, 12, &decoder, &expected.vertex_order);
    assert_eq!(mismatch, None);

    let decoded = dir.path().join("decoded.ply");
    succeeds(&["decode", text(&output), "-o", text(&decoded)]);
    assert_eq!(read(&decoded).vertex_count(), mesh.vertex_count());

    // The default searches: the stream is the library's search's, guarded
    // by the setting it kept or, when it declined, the plain one.
    let searched = dir.path().join("searched.vtr");
    let (_, stderr) = succeeds(&[
        "encode",
        text(&input),
        "--guard",
        "features",
        "-o",
        text(&searched),
    ]);
    let (guard, search) =
        search_feature_guard(&mesh, &options, &guard, DEFAULT_CONNECTIVITY_BUDGET).unwrap();
    let expected = match (&guard, search.choice()) {
        (Some(g), Some((s, _))) => {
            assert!(stderr.contains(&s.to_string()), "{stderr}");
            assert!(stderr.contains("searched: features' distance"), "{stderr}");
            Encoder::new(options).guard(g).encode(&mesh).unwrap()
        }
        _ => {
            assert!(stderr.contains("declined"), "{stderr}");
            plain
        }
    };
    assert!(std::fs::read(&searched).unwrap() == expected.bytes);
}

#[test]
fn a_feature_threshold_needs_the_feature_guard() {
    let dir = tempfile::tempdir().unwrap();
    let input = plate(dir.path());
    let out = dir.path().join("x.vtr");
    let stderr = fails(&[
        "encode",
        text(&input),
        "--feature-threshold",
        "20",
        "-o",
        text(&out),
    ]);
    assert!(
        stderr.contains("--feature-threshold needs --guard features"),
        "{stderr}"
    );
    let stderr = fails(&[
        "encode",
        text(&input),
        "--guard",
        "features",
        "--feature-threshold",
        "sharp",
    ]);
    assert!(stderr.contains("feature threshold must be"), "{stderr}");
    for bad in ["1.5", "0.3:x", "most"] {
        let stderr = fails(&[
            "encode",
            text(&input),
            "--guard",
            "features",
            "--feature-setting",
            bad,
            "-o",
            text(&out),
        ]);
        assert!(
            stderr.contains("feature setting must be"),
            "{bad}: {stderr}"
        );
    }
    let stderr = fails(&[
        "encode",
        text(&input),
        "--feature-setting",
        "auto",
        "-o",
        text(&out),
    ]);
    assert!(
        stderr.contains("--feature-setting needs --guard features"),
        "{stderr}"
    );
    assert!(!out.exists());
}

#[test]
fn ingest_records_the_feature_guard_in_the_compression_options() {
    let dir = tempfile::tempdir().unwrap();
    let input = plate(dir.path());
    let db = format!("sqlite:{}", text(&dir.path().join("vitrine.db")));
    let (_, log) = succeeds(&[
        "ingest",
        text(&input),
        "--db",
        &db,
        "--slug",
        "plate",
        "--title",
        "Plate",
        "--guard",
        "features",
        "--feature-threshold",
        "p90",
    ]);
    assert!(log.contains("feature guard"), "{log}");
    let options: serde_json::Value = serde_json::from_str(&stored_options(&db)).unwrap();
    assert_eq!(options["guards"], serde_json::json!(["features"]));
    assert_eq!(options["feature_threshold"], "p90");
    assert_eq!(options["feature_setting"], "auto");
}

/// The options JSON of the one compression in the database at `url`.
fn stored_options(url: &str) -> String {
    let runtime = tokio::runtime::Runtime::new().unwrap();
    runtime.block_on(async {
        let pool = sqlx::SqlitePool::connect(url).await.unwrap();
        sqlx::query_scalar("SELECT options FROM compression")
            .fetch_one(&pool)
            .await
            .unwrap()
    })
}

#[test]
fn simplify_reaches_the_target_vertex_count_with_every_collapse() {
    let dir = tempfile::tempdir().unwrap();
    let input = plate(dir.path());
    for (collapse, file) in [
        ("edge", "e.ply"),
        ("half-edge", "h.obj"),
        ("triangle", "t.glb"),
    ] {
        let output = dir.path().join(file);
        let (stdout, _) = succeeds(&[
            "simplify",
            text(&input),
            "--method",
            "normal-deviation",
            "--collapse",
            collapse,
            "--target-vertices",
            "1001",
            "--hausdorff-samples",
            "20000",
            "-o",
            text(&output),
        ]);
        assert!(stdout.contains("→ 1001 vertices"), "{collapse}: {stdout}");
        let mesh = read(&output);
        assert_eq!(mesh.vertex_count(), 1001, "{collapse}");
        check_manifold(&mesh).unwrap_or_else(|e| panic!("{collapse}: {e}"));
    }
}

#[test]
fn simplify_reports_as_json() {
    let dir = tempfile::tempdir().unwrap();
    let (input, output) = (plate(dir.path()), dir.path().join("quarter.ply"));
    let (stdout, _) = succeeds(&[
        "simplify",
        text(&input),
        "--method",
        "normal-deviation",
        "--target-fraction",
        "0.25",
        "--hausdorff-samples",
        "20000",
        "--json",
        "-o",
        text(&output),
    ]);
    let report: serde_json::Value = serde_json::from_str(&stdout).expect("JSON on stdout");
    assert_eq!(report["method"], "normal-deviation");
    assert_eq!(report["collapse"], "edge");
    assert_eq!(report["placement"], "quadric");
    assert_eq!(report["input"]["vertices"], 5504);
    assert_eq!(report["output"]["vertices"], 1376);
    assert_eq!(report["stopped"], "target");
    assert!(report["passes"].as_u64().unwrap() > 0);
    let hausdorff = report["hausdorff"].as_f64().unwrap();
    assert!(hausdorff > 0.0 && hausdorff < 0.1, "{hausdorff}");
    assert!(report["seconds"].as_f64().unwrap() >= 0.0);
    assert_eq!(read(&output).vertex_count(), 1376);
}

#[test]
fn features_go_last_unless_kept() {
    // The genus plate at 5 %: its feature vertices (the tunnels' rims)
    // stop the seed's rule short; the default lets them go last.
    let dir = tempfile::tempdir().unwrap();
    let input = plate(dir.path());
    let run = |extra: &[&str]| {
        let output = dir.path().join("out.ply");
        let mut args = vec![
            "simplify",
            text(&input),
            "--method",
            "normal-deviation",
            "--target-fraction",
            "0.05",
            "--hausdorff-samples",
            "5000",
            "--json",
            "-o",
            text(&output),
        ];
        args.extend_from_slice(extra);
        let (stdout, _) = succeeds(&args);
        serde_json::from_str::<serde_json::Value>(&stdout).expect("JSON on stdout")
    };
    let kept = run(&["--features", "keep", "--placement", "seed"]);
    assert_eq!(kept["stopped"], "no-candidate", "{kept}");
    assert!(kept["output"]["vertices"].as_u64().unwrap() > 275);
    assert_eq!(kept["placement"], "seed");
    let last = run(&[]);
    assert_eq!(last["stopped"], "target", "{last}");
    assert_eq!(last["output"]["vertices"], 275);
    let (first, end) = (
        last["feature_threshold_degrees"].as_f64().unwrap(),
        last["final_feature_threshold_degrees"].as_f64().unwrap(),
    );
    assert!(end > first, "{first} → {end}");
}

#[test]
fn simplify_refuses_bad_arguments() {
    let dir = tempfile::tempdir().unwrap();
    let input = plate(dir.path());
    let ply = dir.path().join("out.ply");
    let simplify = |rest: &[&str], output: &Path| {
        let mut args = vec!["simplify", text(&input), "--method", "normal-deviation"];
        args.extend_from_slice(rest);
        args.extend_from_slice(&["-o", text(output)]);
        fails(&args)
    };
    let both = simplify(
        &["--target-vertices", "100", "--target-fraction", "0.5"],
        &ply,
    );
    assert!(both.contains("cannot be used with"), "{both}");
    let neither = simplify(&[], &ply);
    assert!(neither.contains("--target-vertices"), "{neither}");
    for fraction in ["0", "1.5", "-0.2", "half"] {
        let e = simplify(&[&format!("--target-fraction={fraction}")], &ply);
        assert!(
            e.contains("must be a number within (0, 1]"),
            "{fraction}: {e}"
        );
    }
    let stl = dir.path().join("out.stl");
    let e = simplify(&["--target-fraction", "0.5"], &stl);
    assert!(e.contains("must end in .ply, .obj, .glb or .md2"), "{e}");
    assert!(!ply.exists() && !stl.exists());
}

/// The genus-3 plate's χ, components and border loops, and whether every
/// vertex of `out` is one of `input`'s, bit for bit.
fn same_topology_and_vertices(input: &IndexedMesh, out: &IndexedMesh) {
    use std::collections::HashSet;
    let counts = |m: &IndexedMesh| {
        let s = vitrine_geodesic_surface(m);
        let used = (0..s.vertex_count() as u32)
            .filter(|&v| !s.faces_of(v).is_empty())
            .count() as i64;
        let chi = used - (s.edge_ids() / 2) as i64 + m.triangles.len() as i64;
        (chi, s.components().0, s.boundary_loops().len())
    };
    assert_eq!(counts(out), counts(input));
    let bits: HashSet<[u32; 3]> = input
        .positions
        .iter()
        .map(|p| p.map(f32::to_bits))
        .collect();
    assert!(out
        .positions
        .iter()
        .all(|p| bits.contains(&p.map(f32::to_bits))));
}

fn vitrine_geodesic_surface(mesh: &IndexedMesh) -> vitrine_geodesic::Surface {
    vitrine_geodesic::Surface::new(mesh).expect("a manifold")
}

/// `vitrine simplify --method voronoi` with `flags`, its JSON report.
fn voronoi_report(input: &Path, output: &Path, flags: &[&str]) -> serde_json::Value {
    let mut args = vec!["simplify", text(input), "--method", "voronoi"];
    args.extend_from_slice(flags);
    args.extend(["--hausdorff-samples", "20000", "--json", "-o", text(output)]);
    let (stdout, _) = succeeds(&args);
    serde_json::from_str(&stdout).expect("JSON on stdout")
}

#[test]
fn simplify_by_voronoi_keeps_the_plates_topology_in_every_configuration() {
    let dir = tempfile::tempdir().unwrap();
    let input = plate(dir.path());
    let original = repaired(&input);
    for (distance, order) in [
        ("dijkstra", "incremental"),
        ("fmm", "farthest"),
        ("fmm", "curvature"),
    ] {
        let output = dir.path().join(format!("{distance}-{order}.ply"));
        let flags = ["--distance", distance, "--order", order, "--radius", "0.05"];
        let report = voronoi_report(&input, &output, &flags);
        assert_eq!(report["method"], "voronoi");
        assert_eq!(report["stopped"], "radius");
        assert_eq!(report["voronoi"]["distance"], distance);
        assert_eq!(report["voronoi"]["order"], order);
        assert_eq!(report["voronoi"]["radius"], 0.05);
        let mesh = read(&output);
        check_manifold(&mesh).unwrap_or_else(|e| panic!("{distance} {order}: {e}"));
        assert!(
            mesh.face_count() * 4 < original.face_count(),
            "{}",
            mesh.face_count()
        );
        assert_eq!(report["output"]["faces"], mesh.face_count());
        same_topology_and_vertices(&original, &mesh);
    }
}

#[test]
fn simplify_by_voronoi_with_quadric_placement_keeps_the_plate_exact() {
    let dir = tempfile::tempdir().unwrap();
    let input = plate(dir.path());
    let output = dir.path().join("quadric.ply");
    let flags = ["--voronoi-placement", "quadric", "--radius", "0.05"];
    let report = voronoi_report(&input, &output, &flags);
    assert_eq!(report["voronoi"]["placement"], "quadric");
    check_manifold(&read(&output)).unwrap();
    // Flat faces and sharp edges: each cell's quadric minimum lies on the
    // plate, so nothing moves off it.
    let h = report["hausdorff"].as_f64().unwrap();
    assert!(h < 1e-6, "{report}");
}

#[test]
fn simplify_by_voronoi_with_adaptive_spacing_keeps_topology_and_vertices() {
    let dir = tempfile::tempdir().unwrap();
    let input = plate(dir.path());
    let original = repaired(&input);
    let output = dir.path().join("adaptive.ply");
    let flags = ["--voronoi-spacing", "adaptive", "--radius", "0.05"];
    let report = voronoi_report(&input, &output, &flags);
    assert_eq!(report["voronoi"]["spacing"], "adaptive");
    assert_eq!(report["voronoi"]["placement"], "sites");
    let mesh = read(&output);
    check_manifold(&mesh).unwrap();
    same_topology_and_vertices(&original, &mesh);
    // The plate's faces are flat and its edges kept: nothing is lost.
    let h = report["hausdorff"].as_f64().unwrap();
    assert!(h < 1e-6, "{report}");
    let output = dir.path().join("uniform.ply");
    let flags = ["--voronoi-spacing", "uniform", "--radius", "0.05"];
    assert_eq!(
        voronoi_report(&input, &output, &flags)["voronoi"]["spacing"],
        "uniform"
    );
}

#[test]
fn simplify_by_voronoi_to_a_vertex_target_or_fraction() {
    let dir = tempfile::tempdir().unwrap();
    let input = plate(dir.path());
    let output = dir.path().join("v.obj");
    // The plate is a lattice, so its vertex count moves in steps with r; with
    // its creases covered first no radius gives 263–394 vertices. The seed's
    // cover (`--sharp-degrees 0`, `--voronoi-spacing uniform`) has steps fine
    // enough for the search here (adaptive spacing's: 245 for 275), and the
    // creases' own case follows.
    let (stdout, _) = succeeds(&[
        "simplify",
        text(&input),
        "--method",
        "voronoi",
        "--sharp-degrees",
        "0",
        "--voronoi-spacing",
        "uniform",
        "--target-vertices",
        "300",
        "--hausdorff-samples",
        "20000",
        "-o",
        text(&output),
    ]);
    assert!(
        stdout.contains("voronoi (dijkstra distance, farthest order"),
        "{stdout}"
    );
    let got = read(&output).vertex_count();
    assert!(got.abs_diff(300) <= 30, "{got}");
    // A fraction is a vertex target of that share of the input (5504).
    let (stdout, _) = succeeds(&[
        "simplify",
        text(&input),
        "--method",
        "voronoi",
        "--sharp-degrees",
        "0",
        "--voronoi-spacing",
        "uniform",
        "--target-fraction",
        "0.05",
        "--hausdorff-samples",
        "20000",
        "--json",
        "-o",
        text(&output),
    ]);
    let report: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let got = report["output"]["vertices"].as_u64().unwrap();
    assert!(got.abs_diff(275) <= 28, "{got}");
    assert!(matches!(
        report["stopped"].as_str(),
        Some("target" | "nearest")
    ));
    // Creases first (the default): the nearest step to 300, and the plate's
    // edges kept exactly (all its faces are flat).
    let (stdout, _) = succeeds(&[
        "simplify",
        text(&input),
        "--method",
        "voronoi",
        "--target-vertices",
        "300",
        "--hausdorff-samples",
        "20000",
        "--json",
        "-o",
        text(&output),
    ]);
    let report: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let got = report["output"]["vertices"].as_u64().unwrap();
    assert!((262..=395).contains(&got), "{got}");
    let h = report["hausdorff"].as_f64().unwrap();
    assert!(h < 1e-4, "{h}");
}

#[test]
fn simplify_by_voronoi_refuses_bad_arguments_and_input() {
    let dir = tempfile::tempdir().unwrap();
    let input = plate(dir.path());
    let out = dir.path().join("out.ply");
    let base = |rest: &[&str]| {
        let mut args = vec!["simplify", text(&input), "-o", text(&out)];
        args.extend_from_slice(rest);
        fails(&args)
    };
    let e = base(&[
        "--method",
        "voronoi",
        "--radius",
        "0.05",
        "--target-vertices",
        "10",
    ]);
    assert!(e.contains("cannot be used with"), "{e}");
    let e = base(&["--method", "voronoi", "--radius", "0"]);
    assert!(e.contains("must be a number within (0, 10]"), "{e}");
    let e = base(&[
        "--method",
        "voronoi",
        "--radius",
        "0.1",
        "--distance",
        "euclid",
    ]);
    assert!(e.contains("invalid value 'euclid'"), "{e}");
    let e = base(&["--method", "normal-deviation", "--radius", "0.1"]);
    assert!(
        e.contains("--radius applies to --method voronoi only"),
        "{e}"
    );
    let empty = dir.path().join("empty.ply");
    std::fs::write(
        &empty,
        "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n",
    )
    .unwrap();
    let e = fails(&[
        "simplify",
        text(&empty),
        "--method",
        "voronoi",
        "--radius",
        "0.1",
        "-o",
        text(&out),
    ]);
    assert!(!e.contains("panicked"), "{e}");
    assert!(!out.exists());
}
