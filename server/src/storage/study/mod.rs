//! The quality study's rows (issue 17): studies, invitations, participants,
//! sessions, answers and the view log. Same pattern as the model tables: one
//! trait, the SQL written once (`sql.rs`), one macro implementing it for
//! each backend (`backend.rs`).

mod backend;
pub(crate) mod sql;

pub(super) use backend::study_storage;

use super::Result;
use crate::study::csv::ImportedSession;
use crate::study::{Judgement, SessionAnswers, Step, Transition};
use async_trait::async_trait;

/// A study of one model version.
#[derive(Clone, Debug, PartialEq)]
pub struct StudyRecord {
    pub id: i64,
    pub model_id: i64,
    pub slug: String,
    pub version: u32,
    pub title: String,
    pub transitions: Vec<Transition>,
    /// T, the minimum time each state is shown.
    pub state_ms: u64,
    pub open: bool,
    pub created_at_ms: i64,
}

/// An invitation, its study and the session it started, if any.
#[derive(Clone, Debug, PartialEq)]
pub struct InvitationRecord {
    pub id: i64,
    pub study: StudyRecord,
    pub expires_at_ms: Option<i64>,
    pub session: Option<SessionRecord>,
}

impl InvitationRecord {
    pub fn live(&self, now_ms: i64) -> bool {
        self.study.open && self.expires_at_ms.is_none_or(|t| t > now_ms)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct SessionRecord {
    pub id: i64,
    /// The participant's pseudonym.
    pub participant: String,
    pub plan: Vec<Step>,
    pub device: Option<String>,
    pub started_at_ms: i64,
    pub finished_at_ms: Option<i64>,
    /// API requests made so far (limited per session).
    pub requests: i64,
    /// `web` or `import`.
    pub source: String,
}

/// What the page says when the participant consents.
#[derive(Clone, Debug, PartialEq)]
pub struct NewSession {
    pub pseudonym: String,
    pub plan: Vec<Step>,
    pub device: String,
    pub viewport: (u32, u32),
    pub pixel_ratio: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct AnswerRecord {
    pub judgement: Judgement,
    /// How long the page showed m_a and m_b; `None` when imported.
    pub shown_ms: Option<(u64, u64)>,
    pub answered_at_ms: i64,
}

/// One logged view parameter or state change.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewEvent {
    pub at_ms: f64,
    pub step: u32,
    pub state: String,
    pub kind: String,
    /// JSON: camera, zoom, interaction.
    pub data: String,
}

/// Every method has a default that refuses, for storages without the study
/// tables (the service tests' doubles); both backends implement them all.
#[allow(unused_variables)] // the defaults ignore their arguments; the names document them
#[async_trait]
pub trait StudyStorage: Send + Sync {
    /// The newest study of the slug's visible version.
    async fn current_study(&self, slug: &str) -> Result<Option<StudyRecord>> {
        no_studies()
    }

    async fn create_study(
        &self,
        model_id: i64,
        transitions: &[Transition],
        state_ms: u64,
    ) -> Result<i64> {
        no_studies()
    }

    async fn close_study(&self, study_id: i64) -> Result<()> {
        no_studies()
    }

    /// Stores invitation digests, all or none.
    async fn insert_invitations(
        &self,
        study_id: i64,
        digests: &[String],
        expires_at_ms: Option<i64>,
    ) -> Result<()> {
        no_studies()
    }

    /// The invitation with this token digest.
    async fn invitation(&self, digest: &str) -> Result<Option<InvitationRecord>> {
        no_studies()
    }

    /// Creates the participant and the session; `Conflict` if the invitation
    /// already started one.
    async fn start_session(
        &self,
        invitation_id: i64,
        study_id: i64,
        session: &NewSession,
    ) -> Result<SessionRecord> {
        no_studies()
    }

    async fn answers(&self, session_id: i64) -> Result<Vec<AnswerRecord>> {
        no_studies()
    }

    /// `Conflict` if the step is answered already.
    async fn insert_answer(&self, session_id: i64, answer: &AnswerRecord) -> Result<()> {
        no_studies()
    }

    /// Counts one request; `false` (and nothing counted) past `limit`.
    async fn count_request(&self, session_id: i64, limit: i64) -> Result<bool> {
        no_studies()
    }

    /// Stores a batch of view events, all or none.
    async fn insert_views(&self, session_id: i64, events: &[ViewEvent]) -> Result<()> {
        no_studies()
    }

    async fn finish_session(&self, session_id: i64) -> Result<()> {
        no_studies()
    }

    /// Every session of a study with its answers, by session id.
    async fn study_sessions(
        &self,
        study_id: i64,
    ) -> Result<Vec<(SessionRecord, Vec<AnswerRecord>)>> {
        no_studies()
    }

    /// The study's view log: (participant, event), in session and time order.
    async fn study_views(&self, study_id: i64) -> Result<Vec<(String, ViewEvent)>> {
        no_studies()
    }

    /// Stores imported participants with their answers, all or none
    /// (`Conflict` if a participant is already in the study).
    async fn import_sessions(&self, study_id: i64, sessions: &[ImportedSession]) -> Result<()> {
        no_studies()
    }

    /// Sets the version's good-enough level and the study that set it.
    async fn apply_good_enough(&self, model_id: i64, level: u32, study_id: i64) -> Result<()> {
        no_studies()
    }
}

fn no_studies<T>() -> Result<T> {
    Err(super::StorageError::Unknown(
        "this storage keeps no quality studies".into(),
    ))
}

/// Sessions as the analysis reads them: complete when imported or when every
/// planned step is answered.
pub fn for_analysis(sessions: &[(SessionRecord, Vec<AnswerRecord>)]) -> Vec<SessionAnswers> {
    sessions
        .iter()
        .map(|(s, answers)| SessionAnswers {
            participant: s.participant.clone(),
            device: s.device.clone(),
            complete: s.source == "import" || answers.len() >= s.plan.len(),
            answers: answers.iter().map(|a| a.judgement.clone()).collect(),
        })
        .collect()
}
