//! A museum's own words (`[ui.strings.<language>]` in the configuration
//! file) reach every page of the viewer as one JSON script element, which
//! no text can end; a site that gives none carries none.

use crate::harness::{ingest_sample, test_config, Backend, TestDb, TestServer};
use vitrine::UiStrings;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_page_carries_the_museums_own_words() {
    let db = TestDb::new(Backend::Sqlite).await.unwrap();
    ingest_sample(&*db.storage, "vase", "open").await;
    let web = tempfile::tempdir().unwrap();
    std::fs::write(
        web.path().join("index.html"),
        "<!doctype html>\n<html>\n<head><title>Vitrine</title></head><body></body></html>\n",
    )
    .unwrap();
    let file: toml::Table =
        "[ui.strings.en]\n\"gallery.intro\" = \"Stories from the collection </script>\"\n\
         [ui.strings.pt]\n\"page.allModels\" = \"← Todas as histórias\"\n"
            .parse()
            .unwrap();
    let mut config = test_config();
    config.web_dir = web.path().to_owned();
    config.ui_strings = UiStrings::from_toml(&file["ui"]).unwrap();
    let server = TestServer::start(db.storage.clone(), config).await;
    let expected = "<script type=\"application/json\" id=\"vitrine-ui-strings\">\
         {\"en\":{\"gallery.intro\":\"Stories from the collection \\u003c/script>\"},\
         \"pt\":{\"page.allModels\":\"← Todas as histórias\"}}</script>\n</head>";
    for path in [
        "/",
        "/m/vase",
        "/embed/vase",
        "/study/vase",
        "/admin",
        "/m/nothing",
    ] {
        let body = reqwest::get(server.url(path))
            .await
            .unwrap()
            .text()
            .await
            .unwrap();
        assert!(body.contains(expected), "{path}: {body}");
        assert!(!body.contains("collection </script>"), "{path}: {body}");
    }
    server.shut_down().await;

    // Without any, the page is the build's.
    let mut config = test_config();
    config.web_dir = web.path().to_owned();
    let server = TestServer::start(db.storage.clone(), config).await;
    let body = reqwest::get(server.url("/"))
        .await
        .unwrap()
        .text()
        .await
        .unwrap();
    assert!(!body.contains("vitrine-ui-strings"), "{body}");
    server.shut_down().await;
}
