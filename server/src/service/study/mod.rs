//! The study's JSON endpoints under `/api/study/{slug}` (issue 17). A
//! participant is known by their invitation (`Authorization: Bearer inv_…`):
//! it starts one session, after consent, and opens every level of the
//! studied version to the viewer (`Audience::Study`). Answers are idempotent
//! per step; anything refused stores nothing.

mod bodies;

pub use bodies::*;

use super::error::{AppError, ErrorBody};
use super::servable::{PathParams, ServableModel};
use super::visitor::VisitorHints;
use super::AppState;
use crate::storage::{
    now_ms, sha256_hex, valid_slug, AnswerRecord, InvitationRecord, ModelRecord, NewSession,
    SessionRecord, StorageError, StudyRecord,
};
use crate::study::plan::{control_position, session_plan};
use crate::study::{good_level, report, Judgement, Step};
use axum::extract::rejection::JsonRejection;
use axum::extract::{FromRequest, Request, State};
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde::de::DeserializeOwned;
use serde::Deserialize;
use std::sync::Arc;
use utoipa::IntoParams;

/// Requests one session may make: its answers, a view batch every few
/// seconds for an hour, and reloads.
pub const MAX_REQUESTS_PER_SESSION: i64 = 2_000;

/// The `{slug}` of a study route.
#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct StudySlug {
    #[param(pattern = "^[a-z0-9]([a-z0-9-]{0,62}[a-z0-9])?$")]
    pub slug: String,
}

/// The `{slug}` and `{step}` of an answer.
#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct StepPath {
    slug: String,
    /// 1-based step of the plan.
    step: u32,
}

/// axum's `Json`, with its refusals in the service's error body: malformed
/// JSON is a 400, well-formed JSON of the wrong shape a 422.
pub struct JsonBody<T>(pub T);

impl<T: DeserializeOwned, S: Send + Sync> FromRequest<S> for JsonBody<T> {
    type Rejection = AppError;

    async fn from_request(request: Request, state: &S) -> Result<Self, AppError> {
        match Json::<T>::from_request(request, state).await {
            Ok(Json(body)) => Ok(JsonBody(body)),
            Err(JsonRejection::JsonDataError(e)) => Err(AppError::Unprocessable(e.body_text())),
            Err(e) => Err(AppError::BadRequest(e.body_text())),
        }
    }
}

fn no_store(status: StatusCode, body: impl IntoResponse) -> Response {
    let mut response = (status, body).into_response();
    response
        .headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    response
}

/// The invitation behind `token`, if it still opens its study.
pub(super) async fn live_invitation(
    state: &AppState,
    token: &str,
) -> Result<InvitationRecord, AppError> {
    let invitation = state
        .storage()
        .invitation(&sha256_hex(token.as_bytes()))
        .await?
        .ok_or_else(|| AppError::StudyClosed("this invitation is unknown".into()))?;
    if !invitation.study.open {
        return Err(AppError::StudyClosed("the study is closed".into()));
    }
    if !invitation.live(now_ms()) {
        return Err(AppError::StudyClosed("this invitation has expired".into()));
    }
    Ok(invitation)
}

/// An invited participant of the slug's current study.
struct Participant {
    invitation: InvitationRecord,
    record: Arc<ModelRecord>,
}

impl Participant {
    async fn find(state: &AppState, slug: &str, hints: &VisitorHints) -> Result<Self, AppError> {
        if !valid_slug(slug) {
            return Err(AppError::BadRequest(format!(
                "{slug:?} is not a model slug"
            )));
        }
        let record = state.record_by_slug(slug).await?;
        // A restricted model's existence is not revealed to the uninvited.
        let closed = |why: &str| {
            if record.policy.public_access {
                AppError::StudyClosed(why.to_owned())
            } else {
                AppError::NotFound("model")
            }
        };
        let Some(token) = hints.token.as_deref() else {
            return Err(closed("the study is open to invited participants only"));
        };
        if !crate::study::is_invitation(token) {
            return Err(closed("the token is not a study invitation"));
        }
        let invitation = match live_invitation(state, token).await {
            Err(AppError::StudyClosed(why)) => return Err(closed(&why)),
            other => other?,
        };
        if invitation.study.slug != slug {
            return Err(closed("this invitation is for another model"));
        }
        if invitation.study.model_id != record.model_id {
            return Err(closed(&format!(
                "the study was of version {}; version {} is shown now",
                invitation.study.version, record.version
            )));
        }
        Ok(Participant { invitation, record })
    }

    fn study(&self) -> &StudyRecord {
        &self.invitation.study
    }

    /// The session, counted against its request limit.
    async fn session(&self, state: &AppState) -> Result<&SessionRecord, AppError> {
        let session = self.invitation.session.as_ref().ok_or_else(|| {
            AppError::Conflict("no session yet: POST …/session with consent first".into())
        })?;
        if !state
            .storage()
            .count_request(session.id, MAX_REQUESTS_PER_SESSION)
            .await?
        {
            return Err(AppError::TooManyRequests(format!(
                "this session has made its {MAX_REQUESTS_PER_SESSION} requests"
            )));
        }
        Ok(session)
    }

    fn plan(&self, session: &SessionRecord, answers: &[AnswerRecord]) -> Plan {
        let answered: Vec<u32> = answers.iter().map(|a| a.judgement.step).collect();
        let next_step = session
            .plan
            .iter()
            .map(|s| s.step)
            .find(|s| !answered.contains(s));
        Plan {
            slug: self.study().slug.clone(),
            version: self.study().version,
            participant: session.participant.clone(),
            seconds: self.study().state_ms as f64 / 1000.0,
            last_level: self.record.batch_count(),
            steps: session.plan.clone(),
            answered,
            next_step,
            finished: session.finished_at_ms.is_some(),
        }
    }
}

/// The study's information for an invited participant.
#[utoipa::path(
    get,
    path = "/api/study/{slug}",
    params(StudySlug),
    responses(
        (status = 200, description = "The study and the invitation's state", body = StudyInfo),
        (status = 400, description = "Malformed slug or `Authorization`", body = ErrorBody),
        (status = 403, description = "No study open to this visitor (`study_closed`): none runs, \
            or the invitation is missing, unknown, expired or for another version", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
    ),
    security(("bearer" = []))
)]
pub async fn info(
    State(state): State<AppState>,
    PathParams(StudySlug { slug }): PathParams<StudySlug>,
    hints: VisitorHints,
) -> Result<Response, AppError> {
    let p = Participant::find(&state, &slug, &hints).await?;
    let invitation = match &p.invitation.session {
        None => "valid",
        Some(s) if s.finished_at_ms.is_some() => "finished",
        Some(_) => "started",
    };
    let study = p.study();
    Ok(no_store(
        StatusCode::OK,
        Json(StudyInfo {
            slug: study.slug.clone(),
            title: study.title.clone(),
            version: study.version,
            state: "open",
            seconds: study.state_ms as f64 / 1000.0,
            step_count: study.transitions.len() as u32 + 1,
            last_level: p.record.batch_count(),
            invitation,
        }),
    ))
}

/// Starts (after consent) or resumes the invitation's session.
#[utoipa::path(
    post,
    path = "/api/study/{slug}/session",
    params(StudySlug),
    request_body = StartBody,
    responses(
        (status = 201, description = "Session started: its plan", body = Plan),
        (status = 200, description = "Session resumed: its plan and what is answered", body = Plan),
        (status = 400, description = "Malformed JSON, slug or `Authorization`", body = ErrorBody),
        (status = 403, description = "No study open to this visitor (`study_closed`)", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
        (status = 409, description = "The session is finished", body = ErrorBody),
        (status = 422, description = "No consent, or a value out of range", body = ErrorBody),
    ),
    security(("bearer" = []))
)]
pub async fn start(
    State(state): State<AppState>,
    PathParams(StudySlug { slug }): PathParams<StudySlug>,
    hints: VisitorHints,
    JsonBody(body): JsonBody<StartBody>,
) -> Result<Response, AppError> {
    let p = Participant::find(&state, &slug, &hints).await?;
    let device = body.check()?;
    if let Some(session) = &p.invitation.session {
        if session.finished_at_ms.is_some() {
            return Err(AppError::Conflict(
                "this session is finished: thank you".into(),
            ));
        }
        let session = p.session(&state).await?;
        let answers = state.storage().answers(session.id).await?;
        return Ok(no_store(StatusCode::OK, Json(p.plan(session, &answers))));
    }
    let transitions = &p.study().transitions;
    let control_at = control_position(transitions.len(), rand::random::<f64>());
    let new = NewSession {
        pseudonym: format!("p-{}", hex::encode(rand::random::<[u8; 6]>())),
        plan: session_plan(transitions, control_at),
        device: format!("{device:?}").to_lowercase(),
        viewport: (body.viewport[0], body.viewport[1]),
        pixel_ratio: body.pixel_ratio,
    };
    let session = state
        .storage()
        .start_session(p.invitation.id, p.study().id, &new)
        .await
        .map_err(conflict)?;
    Ok(no_store(StatusCode::CREATED, Json(p.plan(&session, &[]))))
}

fn conflict(e: StorageError) -> AppError {
    match e {
        StorageError::Conflict(m) => AppError::Conflict(m),
        e => e.into(),
    }
}

/// The session's plan and progress.
#[utoipa::path(
    get,
    path = "/api/study/{slug}/session",
    params(StudySlug),
    responses(
        (status = 200, description = "The plan and what is answered", body = Plan),
        (status = 400, description = "Malformed slug or `Authorization`", body = ErrorBody),
        (status = 403, description = "No study open to this visitor (`study_closed`)", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
        (status = 409, description = "No session yet", body = ErrorBody),
        (status = 429, description = "The session has made its requests", body = ErrorBody),
    ),
    security(("bearer" = []))
)]
pub async fn plan(
    State(state): State<AppState>,
    PathParams(StudySlug { slug }): PathParams<StudySlug>,
    hints: VisitorHints,
) -> Result<Response, AppError> {
    let p = Participant::find(&state, &slug, &hints).await?;
    let session = p.session(&state).await?;
    let answers = state.storage().answers(session.id).await?;
    Ok(no_store(StatusCode::OK, Json(p.plan(session, &answers))))
}

/// Answers one step. The same answer again is accepted (200); a different
/// one, a step out of order or one sooner than both periods allow is not.
#[utoipa::path(
    put,
    path = "/api/study/{slug}/session/answers/{step}",
    params(StepPath),
    request_body = AnswerBody,
    responses(
        (status = 201, description = "Stored", body = AnswerReceipt),
        (status = 200, description = "The same answer was stored already", body = AnswerReceipt),
        (status = 400, description = "Malformed JSON, path or `Authorization`", body = ErrorBody),
        (status = 403, description = "No study open to this visitor (`study_closed`)", body = ErrorBody),
        (status = 404, description = "No such model or step", body = ErrorBody),
        (status = 409, description = "Step out of order, answered differently before, the \
            session finished, or no session yet", body = ErrorBody),
        (status = 422, description = "A state shown for less than T, or the answer came sooner \
            than 2·T after the previous one", body = ErrorBody),
        (status = 429, description = "The session has made its requests", body = ErrorBody),
    ),
    security(("bearer" = []))
)]
pub async fn answer(
    State(state): State<AppState>,
    PathParams(StepPath { slug, step }): PathParams<StepPath>,
    hints: VisitorHints,
    JsonBody(body): JsonBody<AnswerBody>,
) -> Result<Response, AppError> {
    let p = Participant::find(&state, &slug, &hints).await?;
    let session = p.session(&state).await?;
    let planned: Step = *session
        .plan
        .iter()
        .find(|s| s.step == step)
        .ok_or(AppError::NotFound("step"))?;
    let answers = state.storage().answers(session.id).await?;
    let judgement = Judgement {
        step,
        from: planned.from,
        to: planned.to,
        control: planned.control,
        improvement: body.improvement,
        sufficient: body.sufficient,
    };
    let shown = (body.shown_ms[0], body.shown_ms[1]);
    if let Some(earlier) = answers.iter().find(|a| a.judgement.step == step) {
        if earlier.judgement == judgement && earlier.shown_ms == Some(shown) {
            let next = p.plan(session, &answers).next_step;
            return Ok(no_store(
                StatusCode::OK,
                Json(AnswerReceipt {
                    step,
                    next_step: next,
                }),
            ));
        }
        return Err(AppError::Conflict(format!(
            "step {step} was answered differently before"
        )));
    }
    if session.finished_at_ms.is_some() {
        return Err(AppError::Conflict("this session is finished".into()));
    }
    let next = p.plan(session, &answers).next_step;
    if next != Some(step) {
        return Err(AppError::Conflict(format!(
            "step {step} is out of order: the next step is {}",
            next.map_or("none".into(), |n| n.to_string())
        )));
    }
    let t = p.study().state_ms;
    if shown.0 < t || shown.1 < t {
        return Err(AppError::Unprocessable(format!(
            "each state is shown at least {t} ms; the page reports {} and {} ms",
            shown.0, shown.1
        )));
    }
    let now = now_ms();
    let since = answers
        .iter()
        .map(|a| a.answered_at_ms)
        .max()
        .unwrap_or(session.started_at_ms);
    // Both periods follow the previous answer, by the server's own clock
    // (20 ms for rounding to whole milliseconds on either side).
    let min_gap = 2 * t as i64 - 20;
    if now - since < min_gap {
        return Err(AppError::Unprocessable(format!(
            "step {step} was answered {} ms after the previous one; both states take at least {} ms",
            now - since,
            2 * t
        )));
    }
    let record = AnswerRecord {
        judgement,
        shown_ms: Some(shown),
        answered_at_ms: now,
    };
    state
        .storage()
        .insert_answer(session.id, &record)
        .await
        .map_err(conflict)?;
    let mut all = answers;
    all.push(record);
    let next_step = p.plan(session, &all).next_step;
    Ok(no_store(
        StatusCode::CREATED,
        Json(AnswerReceipt { step, next_step }),
    ))
}

/// Stores a batch of view parameters and state changes, all or none.
#[utoipa::path(
    post,
    path = "/api/study/{slug}/session/views",
    params(StudySlug),
    request_body = ViewBatch,
    responses(
        (status = 204, description = "Stored"),
        (status = 400, description = "Malformed JSON, slug or `Authorization`", body = ErrorBody),
        (status = 403, description = "No study open to this visitor (`study_closed`)", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
        (status = 409, description = "No session yet", body = ErrorBody),
        (status = 422, description = "An event out of range (the message names it)", body = ErrorBody),
        (status = 429, description = "The session has made its requests", body = ErrorBody),
    ),
    security(("bearer" = []))
)]
pub async fn views(
    State(state): State<AppState>,
    PathParams(StudySlug { slug }): PathParams<StudySlug>,
    hints: VisitorHints,
    JsonBody(body): JsonBody<ViewBatch>,
) -> Result<Response, AppError> {
    let p = Participant::find(&state, &slug, &hints).await?;
    let session = p.session(&state).await?;
    let events = body.check(session.plan.len() as u32)?;
    state.storage().insert_views(session.id, &events).await?;
    Ok(no_store(StatusCode::NO_CONTENT, ()))
}

/// Ends the session once every step is answered.
#[utoipa::path(
    post,
    path = "/api/study/{slug}/session/finish",
    params(StudySlug),
    responses(
        (status = 200, description = "Finished: the session's good level", body = Finished),
        (status = 400, description = "Malformed slug or `Authorization`", body = ErrorBody),
        (status = 403, description = "No study open to this visitor (`study_closed`)", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
        (status = 409, description = "Steps remain, or no session yet", body = ErrorBody),
        (status = 429, description = "The session has made its requests", body = ErrorBody),
    ),
    security(("bearer" = []))
)]
pub async fn finish(
    State(state): State<AppState>,
    PathParams(StudySlug { slug }): PathParams<StudySlug>,
    hints: VisitorHints,
) -> Result<Response, AppError> {
    let p = Participant::find(&state, &slug, &hints).await?;
    let session = p.session(&state).await?;
    let answers = state.storage().answers(session.id).await?;
    if let Some(next) = p.plan(session, &answers).next_step {
        return Err(AppError::Conflict(format!(
            "step {next} of {} is not answered yet",
            session.plan.len()
        )));
    }
    state.storage().finish_session(session.id).await?;
    let judgements: Vec<Judgement> = answers.into_iter().map(|a| a.judgement).collect();
    Ok(no_store(
        StatusCode::OK,
        Json(Finished {
            good_level: good_level(&judgements),
        }),
    ))
}

/// The share of "sufficient" per level in the current study's valid
/// sessions, for the model page's quality chart.
#[utoipa::path(
    get,
    path = "/api/study/{slug}/results",
    params(StudySlug),
    responses(
        (status = 200, description = "Answers per level", body = StudyResults),
        (status = 400, description = "Malformed slug, query or `Authorization`", body = ErrorBody),
        (status = 404, description = "No such model, or no study of the visible version \
            (the manifest's `study_results` is then absent)", body = ErrorBody),
    )
)]
pub async fn results(
    State(state): State<AppState>,
    ServableModel { record, .. }: ServableModel,
) -> Result<Response, AppError> {
    let storage = state.storage();
    let study = storage
        .current_study(&record.slug)
        .await?
        .filter(|s| s.model_id == record.model_id)
        .ok_or(AppError::NotFound("study"))?;
    // A study without answers yet answers no sessions and no levels: the
    // manifest links it, and a link that answers 404 is a failed request.
    let sessions = storage.study_sessions(study.id).await?;
    let sessions = crate::storage::for_analysis(&sessions);
    let r = report(&sessions, record.batch_count(), 1);
    Ok(no_store(
        StatusCode::OK,
        Json(StudyResults {
            valid_sessions: r.valid_sessions,
            levels: r
                .levels
                .iter()
                .map(|l| LevelShare {
                    level: l.level,
                    answers: l.sufficient + l.insufficient,
                    sufficient: l.sufficient,
                })
                .collect(),
        }),
    ))
}
