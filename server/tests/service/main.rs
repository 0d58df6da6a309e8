//! Service tests. The shared suite runs on SQLite and on PostgreSQL
//! (`VITRINE_TEST_POSTGRES`, default `postgres://postgres@127.0.0.1:5432/postgres`;
//! skipped with a note when unreachable, a failure when `CI` is set).

mod broken;
mod caps;
mod colour;
mod curation;
mod curators;
mod download;
mod fast_path;
mod harness;
mod http;
mod iiif;
mod kill;
mod nested_parts;
mod parts;
mod points;
mod proxy;
mod publishing;
mod quality;
mod slow;
mod spec;
mod story;
mod study;
mod texts;
mod tours;
mod uploads;
mod viewer;

use harness::{Backend, TestDb};
use std::future::Future;

async fn on(
    backend: Backend,
    test: impl FnOnce(TestDb) -> std::pin::Pin<Box<dyn Future<Output = ()> + Send>>,
) {
    if let Some(db) = TestDb::new(backend).await {
        test(db).await;
    }
}

macro_rules! on_both_backends {
    ($($module:ident :: $name:ident),* $(,)?) => {
        mod sqlite {
            $(
                #[tokio::test(flavor = "multi_thread", worker_threads = 2)]
                async fn $name() {
                    super::on(super::Backend::Sqlite, |db| Box::pin(crate::$module::$name(db))).await;
                }
            )*
        }
        mod postgres {
            $(
                #[tokio::test(flavor = "multi_thread", worker_threads = 2)]
                async fn $name() {
                    super::on(super::Backend::Postgres, |db| Box::pin(crate::$module::$name(db))).await;
                }
            )*
        }
    };
}

on_both_backends!(
    story::storage_round_trip,
    story::manifest_and_payloads_match_codec,
    story::etags_and_not_modified,
    story::stale_stream_format_is_refused,
    caps::caps_by_audience_and_device,
    fast_path::fast_path_answers_as_the_router,
    caps::load_caps_fall_and_recover,
    caps::bad_ids_and_slugs,
    http::end_to_end,
    http::load_cap_under_real_load,
    http::database_outage_and_recovery,
    http::shedding_and_body_limit,
    http::admission_in_a_surge,
    http::graceful_shutdown,
    kill::killed_ingest_leaves_nothing,
    colour::ccc_mapping_stored_and_served,
    colour::restricted_textures_need_a_token,
    colour::inconsistent_mappings_are_refused,
    colour::ccc_ingest_from_vertex_colour,
    quality::quality_curve_stored_and_served,
    spec::responses_match_openapi,
    study::scripted_participants,
    study::bad_study_requests,
    download::glb_download_of_a_level,
    publishing::rights_served_and_carried,
    publishing::rights_and_placement_through_uploads,
    publishing::oembed_for_pasted_links,
    texts::texts_in_the_visitors_language,
    texts::annotations_in_several_languages,
    publishing::crawlers_find_public_models,
    curators::annotations_and_scopes,
    iiif::manifests_for_public_models,
    iiif::annotations_round_trip,
    tours::tours_stored_versioned_and_in_the_manifest,
    uploads::uploads_as_jobs,
    curation::curation_in_manifest_and_thumbnail,
    points::points_streamed_under_caps,
    points::cloud_uploads,
    parts::parts_served_under_caps,
    nested_parts::nested_parts_served_under_caps,
);

/// `server/openapi.json` is the served description, committed for reviewers
/// to read and diff; `UPDATE_OPENAPI=1` rewrites it.
#[test]
fn committed_openapi_is_current() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("openapi.json");
    let served = vitrine::service::openapi_json();
    if std::env::var_os("UPDATE_OPENAPI").is_some() {
        std::fs::write(&path, &served).expect("write server/openapi.json");
        return;
    }
    let committed = std::fs::read(&path).unwrap_or_default();
    assert!(
        committed == served,
        "server/openapi.json is not what the service serves: \
         UPDATE_OPENAPI=1 cargo test -p vitrine --test service committed_openapi_is_current"
    );
}
