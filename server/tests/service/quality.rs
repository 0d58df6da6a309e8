//! Quality curves (issue #5): measured at ingest, stored in the level rows,
//! offered in the manifest as `quality`.

use super::harness::{sample_mesh, test_config, TestDb};
use super::story::get;
use serde_json::Value;
use vitrine::ingest::{ingest_mesh, IngestOptions, ModelMeta};
use vitrine::{app, AppState};
use vitrine_colour::ColourMode;
use vitrine_quality::QualityOptions;

/// Small enough for a debug build: the curve's shape, not its precision, is tested.
fn quick() -> QualityOptions {
    QualityOptions {
        image_size: 96,
        hausdorff_samples: 20_000,
    }
}

/// The painted torus ingested with quality in per-vertex and in cell-complex
/// colour, and once without: the manifest has one point per level, vertices
/// increasing, the image error falling to the last level, the Hausdorff
/// distance vanishing there (the stream is lossless at its quantization), and
/// no `quality` at all for the model that was not measured.
pub async fn quality_curve_stored_and_served(db: TestDb) {
    let s = &*db.storage;
    for (slug, colour) in [("q-vertex", ColourMode::Vertex), ("q-ccc", ColourMode::Ccc)] {
        let options = IngestOptions {
            colour: Some(colour),
            quality: Some(quick()),
            ..IngestOptions::default()
        };
        let report = ingest_mesh(s, sample_mesh(), ModelMeta::new(slug, slug), &options)
            .await
            .expect("ingest with quality");
        let measured = report.quality.expect("quality report");
        assert_eq!(measured.levels.len(), report.levels);
        eprintln!(
            "{slug}: {} levels measured in {} ms",
            report.levels,
            measured.time.as_millis()
        );
    }
    ingest_mesh(
        s,
        sample_mesh(),
        ModelMeta::new("q-none", "q-none"),
        &IngestOptions::default(),
    )
    .await
    .unwrap();

    let app = app(AppState::new(db.storage.clone(), test_config()));
    for slug in ["q-vertex", "q-ccc"] {
        let m = get(&app, &format!("/api/models/{slug}"), &[]).await.json();
        let levels = m["levels"].as_array().unwrap();
        let curve = m["quality"].as_array().unwrap_or_else(|| panic!("{m}"));
        assert_eq!(curve.len(), levels.len(), "one point per level: {m}");
        assert!(curve.len() >= 3, "{m}");
        let number =
            |v: &Value, key: &str| v[key].as_f64().unwrap_or_else(|| panic!("{key} in {v}"));
        for (k, (point, level)) in curve.iter().zip(levels).enumerate() {
            assert_eq!(point["level"], k, "{point}");
            assert_eq!(point["vertices"], level["vertices"], "{point}");
            // The level rows carry the same numbers.
            assert_eq!(level["hausdorff"], point["hausdorff"], "{level}");
            assert_eq!(level["rmse"], point["image_rmse"], "{level}");
            assert!(number(point, "image_rmse").is_finite() && number(point, "image_rmse") >= 0.0);
            let roy = number(point, "roy_rmse"); // both sides have colour
            assert!((0.0..=255.0).contains(&roy), "{point}");
            let keys: Vec<_> = point.as_object().unwrap().keys().cloned().collect();
            assert_eq!(
                keys.len(),
                5,
                "level, vertices, hausdorff, roy_rmse, image_rmse: {point}"
            );
        }
        for pair in curve.windows(2) {
            assert!(
                number(&pair[0], "vertices") < number(&pair[1], "vertices"),
                "vertices increase: {pair:?}"
            );
        }
        let (first, last) = (&curve[0], &curve[curve.len() - 1]);
        assert!(
            number(last, "image_rmse") < number(first, "image_rmse"),
            "{slug}: image RMSE falls from the base to the last level: {first} → {last}"
        );
        assert!(
            number(first, "hausdorff") > number(last, "hausdorff"),
            "{slug}: {first} → {last}"
        );
        assert!(
            number(last, "hausdorff") <= 1e-3,
            "{slug}: the last level is the original up to quantization: {last}"
        );
    }
    let m = get(&app, "/api/models/q-none", &[]).await.json();
    assert!(m.get("quality").is_none(), "not measured, not offered: {m}");
    // The sampled Hausdorff distance is measured by default (issue 22).
    assert!(m["levels"][0]["hausdorff"].is_number(), "{m}");
}
