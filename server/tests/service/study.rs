//! The quality study over real HTTP (issue 17): scripted participants run
//! whole sessions; every session stores exactly its steps' answers; the
//! control-step exclusion holds; each bad input gets its status and stores
//! nothing.

use super::harness::{ingest_sample, test_config, TestDb, TestServer};
use reqwest::StatusCode;
use serde_json::{json, Value};
use std::sync::Arc;
use std::time::Duration;
use vitrine::storage::{for_analysis, now_ms, sha256_hex, Storage};
use vitrine::study::plan::default_transitions;
use vitrine::study::{new_invitation, report};

/// T for the tests: short, but the server's clock still enforces 2·T.
const STATE_MS: u64 = 120;
/// T where a test needs a request to land *before* 2·T has passed: long
/// enough that a loaded CI machine (PostgreSQL, parallel tests) cannot
/// overshoot it between two requests.
const SLOW_STATE_MS: u64 = 1_500;

struct Study {
    id: i64,
    invitations: Vec<String>,
}

async fn open_study(
    storage: &Arc<dyn Storage>,
    slug: &str,
    invitations: usize,
    state_ms: u64,
) -> Study {
    let record = storage.model_by_slug(slug).await.unwrap().unwrap();
    let vertices: Vec<u32> = record.levels.iter().map(|l| l.vertices).collect();
    let transitions = default_transitions(&vertices);
    assert!(transitions.len() >= 3, "the sample needs a few transitions");
    let id = storage
        .create_study(record.model_id, &transitions, state_ms)
        .await
        .unwrap();
    let invitations: Vec<String> = (0..invitations).map(|_| new_invitation()).collect();
    let digests: Vec<String> = invitations
        .iter()
        .map(|t| sha256_hex(t.as_bytes()))
        .collect();
    storage
        .insert_invitations(id, &digests, Some(now_ms() + 3_600_000))
        .await
        .unwrap();
    Study { id, invitations }
}

struct Client {
    http: reqwest::Client,
    server: Arc<TestServer>,
    bearer: String,
}

impl Client {
    fn new(server: &Arc<TestServer>, invitation: &str) -> Client {
        Client {
            // No pooled connections: a request the server refuses before
            // reading its body (too large, malformed) ends with the server
            // closing that connection, and a pooled client could send the
            // next request on it (hyper's IncompleteMessage, seen in CI).
            http: reqwest::Client::builder()
                .pool_max_idle_per_host(0)
                .build()
                .unwrap(),
            server: server.clone(),
            bearer: format!("Bearer {invitation}"),
        }
    }

    async fn send(
        &self,
        method: reqwest::Method,
        path: &str,
        body: Option<Value>,
    ) -> (StatusCode, Value) {
        let mut request = self
            .http
            .request(method, self.server.url(path))
            .header("authorization", &self.bearer);
        if let Some(body) = body {
            request = request.json(&body);
        }
        let reply = request.send().await.unwrap();
        let status = reply.status();
        let text = reply.text().await.unwrap();
        (status, serde_json::from_str(&text).unwrap_or(Value::Null))
    }

    async fn get(&self, path: &str) -> (StatusCode, Value) {
        self.send(reqwest::Method::GET, path, None).await
    }

    async fn post(&self, path: &str, body: Value) -> (StatusCode, Value) {
        self.send(reqwest::Method::POST, path, Some(body)).await
    }

    async fn put(&self, path: &str, body: Value) -> (StatusCode, Value) {
        self.send(reqwest::Method::PUT, path, Some(body)).await
    }

    async fn start(&self) -> (StatusCode, Value) {
        let consent = json!({"consent": true, "device": "desktop", "viewport": [1280, 800], "pixel_ratio": 2.0});
        self.post("/api/study/bust/session", consent).await
    }
}

fn answer(improvement: &str, sufficient: bool) -> Value {
    answer_shown(improvement, sufficient, STATE_MS)
}

fn answer_shown(improvement: &str, sufficient: bool, shown_ms: u64) -> Value {
    json!({"improvement": improvement, "sufficient": sufficient, "shown_ms": [shown_ms, shown_ms]})
}

/// One participant's whole session: sufficient from `good` on; the control
/// step answered with `control_answer`; stops before the last step when
/// `quit_early`.
async fn participate(
    client: Client,
    good: u32,
    control_answer: &'static str,
    quit_early: bool,
) -> Value {
    let (status, info) = client.get("/api/study/bust").await;
    assert_eq!(status, StatusCode::OK, "{info}");
    assert_eq!(info["invitation"], "valid");
    let (status, plan) = client.start().await;
    assert_eq!(status, StatusCode::CREATED, "{plan}");
    // Every level, the full one included, is open to the invitation.
    let (_, manifest) = client.get("/api/models/bust").await;
    assert_eq!(manifest["visitor"]["audience"], "study");
    assert_eq!(manifest["cap"]["level"], manifest["last_level"]);
    let last_url = manifest["levels"][manifest["last_level"].as_u64().unwrap() as usize]["url"]
        .as_str()
        .unwrap()
        .to_owned();
    let (status, _) = client.get(&last_url).await;
    assert_eq!(status, StatusCode::OK);
    let steps = plan["steps"].as_array().unwrap().clone();
    let take = if quit_early {
        steps.len() - 1
    } else {
        steps.len()
    };
    for step in &steps[..take] {
        tokio::time::sleep(Duration::from_millis(2 * STATE_MS + 5)).await;
        let control = step["control"].as_bool().unwrap();
        let to = step["to"].as_u64().unwrap() as u32;
        let improvement = if control { control_answer } else { "a-little" };
        let k = step["step"].as_u64().unwrap();
        let events = json!({"events": [
            {"at_ms": 10.0 * k as f64, "step": k, "state": "post", "kind": "camera",
             "camera": {"eye": [0.0, 0.0, 3.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 1.0, 0.0], "fov": 45.0}, "zoom": 1.0},
            {"at_ms": 10.0 * k as f64 + 1.0, "step": k, "state": "answer", "kind": "state"},
        ]});
        let (status, _) = client.post("/api/study/bust/session/views", events).await;
        assert_eq!(status, StatusCode::NO_CONTENT);
        let (status, body) = client
            .put(
                &format!("/api/study/bust/session/answers/{k}"),
                answer(improvement, to >= good),
            )
            .await;
        assert_eq!(status, StatusCode::CREATED, "step {k}: {body}");
    }
    if quit_early {
        let (status, _) = client
            .post("/api/study/bust/session/finish", json!({}))
            .await;
        assert_eq!(status, StatusCode::CONFLICT, "steps remain");
        return Value::Null;
    }
    let (status, finished) = client
        .post("/api/study/bust/session/finish", json!({}))
        .await;
    assert_eq!(status, StatusCode::OK, "{finished}");
    let (_, info) = client.get("/api/study/bust").await;
    assert_eq!(info["invitation"], "finished");
    finished
}

pub async fn scripted_participants(db: TestDb) {
    ingest_sample(&*db.storage, "bust", "exhibition").await;
    let study = open_study(&db.storage, "bust", 4, STATE_MS).await;
    let server = Arc::new(TestServer::start(db.storage.clone(), test_config()).await);
    let record = db.storage.model_by_slug("bust").await.unwrap().unwrap();
    let last = record.batch_count();
    let c = |k: usize| Client::new(&server, &study.invitations[k]);
    let (a, b, fooled, quitter) = tokio::join!(
        participate(c(0), last - 1, "none", false),
        participate(c(1), last, "none", false),
        participate(c(2), last - 2, "a-little", false),
        participate(c(3), last, "none", true),
    );
    assert_eq!(a["good_level"], last - 1);
    assert_eq!(b["good_level"], last);
    assert_eq!(fooled["good_level"], last - 2);
    assert!(quitter.is_null());

    let sessions = db.storage.study_sessions(study.id).await.unwrap();
    assert_eq!(sessions.len(), 4);
    // Sessions are stored in the order participants consented: three
    // complete, the quitter one step short.
    let mut short = 0;
    for (k, (session, answers)) in sessions.iter().enumerate() {
        let expected = if answers.len() < session.plan.len() {
            short += 1;
            session.plan.len() - 1
        } else {
            session.plan.len()
        };
        assert_eq!(
            answers.len(),
            expected,
            "session {k} stores exactly its answers"
        );
        assert_eq!(session.plan.iter().filter(|s| s.control).count(), 1);
        let steps: Vec<u32> = answers.iter().map(|a| a.judgement.step).collect();
        assert_eq!(steps, (1..=expected as u32).collect::<Vec<_>>());
        for a in answers {
            let planned = session.plan[a.judgement.step as usize - 1];
            assert_eq!(
                (a.judgement.from, a.judgement.to, a.judgement.control),
                (planned.from, planned.to, planned.control)
            );
            assert_eq!(a.shown_ms, Some((STATE_MS, STATE_MS)));
        }
    }
    assert_eq!(short, 1);
    let views = db.storage.study_views(study.id).await.unwrap();
    let answered: usize = sessions.iter().map(|(_, a)| a.len()).sum();
    assert_eq!(views.len(), 2 * answered);
    let r = report(&for_analysis(&sessions), last, 2);
    assert_eq!((r.valid_sessions, r.excluded_sessions), (2, 2));
    let mut reasons: Vec<String> = r
        .excluded
        .iter()
        .map(|e| format!("{:?}", e.reason))
        .collect();
    reasons.sort();
    assert_eq!(reasons, vec!["ControlImprovement", "Incomplete"]);
    // p90 of {last - 1, last}.
    assert_eq!(r.good_enough_level, Some(last));

    // The page's chart: the share of "sufficient" per level, public, and
    // linked from the manifest (which links nothing for a model without a
    // study: the page then never asks).
    let manifest: Value = reqwest::get(server.url("/api/models/bust"))
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert_eq!(manifest["study_results"], "/api/study/bust/results");
    let results: Value = reqwest::get(server.url("/api/study/bust/results"))
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert_eq!(results["valid_sessions"], 2);
    let top = results["levels"]
        .as_array()
        .unwrap()
        .last()
        .unwrap()
        .clone();
    assert_eq!(
        (
            top["level"].as_u64(),
            top["answers"].as_u64(),
            top["sufficient"].as_u64()
        ),
        (Some(last as u64), Some(2), Some(2))
    );
}

/// Counts of everything a refused request must not have added.
async fn stored(storage: &Arc<dyn Storage>, study: i64) -> (usize, usize, usize) {
    let sessions = storage.study_sessions(study).await.unwrap();
    let answers = sessions.iter().map(|(_, a)| a.len()).sum();
    let views = storage.study_views(study).await.unwrap().len();
    (sessions.len(), answers, views)
}

pub async fn bad_study_requests(db: TestDb) {
    ingest_sample(&*db.storage, "bust", "exhibition").await;
    let study = open_study(&db.storage, "bust", 2, SLOW_STATE_MS).await;
    let server = Arc::new(TestServer::start(db.storage.clone(), test_config()).await);
    let http = reqwest::Client::new();
    let storage = db.storage.clone();
    let nothing = (0, 0, 0);

    // Without an invitation, or with a bad one, the study is closed.
    let reply = http
        .get(server.url("/api/study/bust"))
        .send()
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::FORBIDDEN);
    assert_eq!(
        reply.json::<Value>().await.unwrap()["error"],
        "study_closed"
    );
    for token in ["inv_0000", "vtr_not_an_invitation"] {
        let (status, body) = Client::new(&server, token).get("/api/study/bust").await;
        assert_eq!(
            (status, body["error"].as_str()),
            (StatusCode::FORBIDDEN, Some("study_closed")),
            "{token}"
        );
    }
    let p = Client::new(&server, &study.invitations[0]);
    let (status, _) = p.get("/api/study/nosuch").await;
    assert_eq!(status, StatusCode::NOT_FOUND);
    // An invitation opens nothing but its model's study.
    ingest_sample(&*db.storage, "other", "exhibition").await;
    let (status, body) = p.get("/api/study/other").await;
    assert_eq!(
        (status, body["error"].as_str()),
        (StatusCode::FORBIDDEN, Some("study_closed"))
    );

    // Before a session: answers and views are refused.
    let (status, _) = p
        .put(
            "/api/study/bust/session/answers/1",
            answer_slow("none", true),
        )
        .await;
    assert_eq!(status, StatusCode::CONFLICT);
    // No consent, bad shapes, malformed JSON: no session.
    for (body, want) in [
        (
            json!({"consent": false, "device": "desktop", "viewport": [800, 600], "pixel_ratio": 1.0}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({"consent": true, "device": "fridge", "viewport": [800, 600], "pixel_ratio": 1.0}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({"consent": true, "device": "phone", "viewport": [0, 600], "pixel_ratio": 1.0}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({"consent": true, "device": "phone", "viewport": [800, 600], "pixel_ratio": -1.0}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (json!({"consent": true}), StatusCode::UNPROCESSABLE_ENTITY),
        (
            json!({"consent": true, "device": "phone", "viewport": [800, 600], "pixel_ratio": 1.0, "name": "Ana"}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
    ] {
        let (status, reply) = p.post("/api/study/bust/session", body.clone()).await;
        assert_eq!(status, want, "{body}: {reply}");
    }
    let malformed = http
        .post(server.url("/api/study/bust/session"))
        .header("authorization", &p.bearer)
        .header("content-type", "application/json")
        .body("{\"consent\": tru")
        .send()
        .await
        .unwrap();
    assert_eq!(malformed.status(), StatusCode::BAD_REQUEST);
    assert_eq!(stored(&storage, study.id).await, nothing);

    let (status, plan) = p.start().await;
    assert_eq!(status, StatusCode::CREATED);
    let (status, again) = p.start().await;
    assert_eq!(status, StatusCode::OK, "resumed");
    assert_eq!(again["participant"], plan["participant"]);
    assert_eq!(again["steps"], plan["steps"]);
    let after_start = (1, 0, 0);
    assert_eq!(stored(&storage, study.id).await, after_start);

    // Too early: both periods have not passed since the session started.
    let (status, body) = p
        .put(
            "/api/study/bust/session/answers/1",
            answer_slow("none", false),
        )
        .await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{body}");
    tokio::time::sleep(Duration::from_millis(2 * SLOW_STATE_MS + 5)).await;
    // Out of order, unknown step, a state shown too briefly, bad values.
    let (status, _) = p
        .put(
            "/api/study/bust/session/answers/2",
            answer_slow("none", false),
        )
        .await;
    assert_eq!(status, StatusCode::CONFLICT);
    let (status, _) = p
        .put(
            "/api/study/bust/session/answers/99",
            answer_slow("none", false),
        )
        .await;
    assert_eq!(status, StatusCode::NOT_FOUND);
    let brief = json!({"improvement": "none", "sufficient": false, "shown_ms": [SLOW_STATE_MS, SLOW_STATE_MS - 1]});
    let (status, _) = p.put("/api/study/bust/session/answers/1", brief).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY);
    let (status, _) = p
        .put(
            "/api/study/bust/session/answers/1",
            json!({"improvement": "lots", "sufficient": false, "shown_ms": [SLOW_STATE_MS, SLOW_STATE_MS]}),
        )
        .await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY);
    let (status, _) = p
        .put(
            "/api/study/bust/session/answers/x",
            answer_slow("none", false),
        )
        .await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    assert_eq!(stored(&storage, study.id).await, after_start);

    // Stored once; the same answer again is fine, a different one is not.
    let (status, receipt) = p
        .put(
            "/api/study/bust/session/answers/1",
            answer_slow("none", false),
        )
        .await;
    assert_eq!(status, StatusCode::CREATED);
    assert_eq!(receipt["next_step"], 2);
    let (status, _) = p
        .put(
            "/api/study/bust/session/answers/1",
            answer_slow("none", false),
        )
        .await;
    assert_eq!(status, StatusCode::OK);
    let (status, _) = p
        .put(
            "/api/study/bust/session/answers/1",
            answer_slow("greatly", false),
        )
        .await;
    assert_eq!(status, StatusCode::CONFLICT);
    assert_eq!(stored(&storage, study.id).await, (1, 1, 0));

    // View batches: too many events, a body over the limit, one bad event:
    // the whole batch is refused.
    let event = json!({"at_ms": 1.0, "step": 1, "state": "pre", "kind": "interaction", "interaction": "orbit"});
    let (status, _) = p
        .post(
            "/api/study/bust/session/views",
            json!({"events": vec![event.clone(); 201]}),
        )
        .await;
    assert_eq!(status, StatusCode::PAYLOAD_TOO_LARGE);
    let huge = json!({"events": [{"at_ms": 1.0, "step": 1, "state": "x".repeat(70_000), "kind": "state"}]});
    let (status, _) = p.post("/api/study/bust/session/views", huge).await;
    assert_eq!(status, StatusCode::PAYLOAD_TOO_LARGE);
    for bad in [
        json!({"at_ms": -1.0, "step": 1, "state": "pre", "kind": "state"}),
        json!({"at_ms": 1.0, "step": 99, "state": "pre", "kind": "state"}),
        json!({"at_ms": 1.0, "step": 1, "state": "dancing", "kind": "state"}),
        json!({"at_ms": 1.0, "step": 1, "state": "pre", "kind": "camera", "camera": {"eye": [0, 0, 1e300], "target": [0, 0, 0], "up": [0, 1, 0], "fov": 45}}),
        json!({"at_ms": 1.0, "step": 1, "state": "pre", "kind": "interaction", "interaction": "lick"}),
    ] {
        let (status, body) = p
            .post(
                "/api/study/bust/session/views",
                json!({"events": [event.clone(), bad.clone()]}),
            )
            .await;
        assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{bad}: {body}");
    }
    assert_eq!(stored(&storage, study.id).await, (1, 1, 0));
    let (status, _) = p
        .post("/api/study/bust/session/views", json!({"events": [event]}))
        .await;
    assert_eq!(status, StatusCode::NO_CONTENT);

    // The per-session request limit: counted in the database, refused past it.
    let session = sessions_of(&storage, study.id).await;
    let used = session.requests;
    assert!(storage.count_request(session.id, used + 2).await.unwrap());
    assert!(storage.count_request(session.id, used + 2).await.unwrap());
    assert!(!storage.count_request(session.id, used + 2).await.unwrap());

    // An expired invitation; a closed study.
    let expired = new_invitation();
    storage
        .insert_invitations(
            study.id,
            &[sha256_hex(expired.as_bytes())],
            Some(now_ms() - 1),
        )
        .await
        .unwrap();
    let (status, body) = Client::new(&server, &expired).get("/api/study/bust").await;
    assert_eq!(
        (status, body["error"].as_str()),
        (StatusCode::FORBIDDEN, Some("study_closed"))
    );
    storage.close_study(study.id).await.unwrap();
    let (status, _) = p.get("/api/study/bust").await;
    assert_eq!(status, StatusCode::FORBIDDEN);
    // The closed study's invitation opens no level above the public cap either.
    let (status, _) = p.get("/api/models/bust").await;
    assert_eq!(status, StatusCode::FORBIDDEN);
    assert_eq!(stored(&storage, study.id).await, (1, 1, 1));
}

async fn sessions_of(storage: &Arc<dyn Storage>, study: i64) -> vitrine::storage::SessionRecord {
    storage.study_sessions(study).await.unwrap().remove(0).0
}

fn answer_slow(improvement: &str, sufficient: bool) -> Value {
    answer_shown(improvement, sufficient, SLOW_STATE_MS)
}
