//! The study's SQL, for both backends (see `storage/sql.rs`).

pub(crate) const STUDY_SELECT: &str = "SELECT s.id, s.model_id, m.slug, m.version, m.title, \
     s.steps, s.state_ms, s.state, s.created_at FROM study s JOIN model m ON m.id = s.model_id ";
pub(crate) const CURRENT_STUDY: &str = "WHERE m.slug = $1 AND m.status = 'ready' \
     AND m.version = (SELECT MAX(m2.version) FROM model m2 WHERE m2.slug = $1 AND m2.status = 'ready') \
     ORDER BY s.id DESC LIMIT 1";
pub(crate) const STUDY_BY_ID: &str = "WHERE s.id = $1";
pub(crate) const INSERT_STUDY: &str =
    "INSERT INTO study (model_id, steps, state_ms, state, created_at) \
     VALUES ($1, $2, $3, 'open', $4) RETURNING id";
pub(crate) const CLOSE_STUDY: &str =
    "UPDATE study SET state = 'closed', closed_at = $2 WHERE id = $1 AND state = 'open'";
pub(crate) const INSERT_INVITATION: &str = "INSERT INTO study_invitation \
     (study_id, token_sha256, expires_at, created_at) VALUES ($1, $2, $3, $4)";
pub(crate) const INVITATION: &str =
    "SELECT id, study_id, expires_at FROM study_invitation WHERE token_sha256 = $1";
pub(crate) const SESSION_SELECT: &str = "SELECT se.id, p.pseudonym, se.plan, se.device, \
     se.started_at, se.finished_at, se.requests, se.source \
     FROM study_session se JOIN study_participant p ON p.id = se.participant_id ";
pub(crate) const SESSION_BY_INVITATION: &str = "WHERE p.invitation_id = $1";
pub(crate) const SESSIONS_OF_STUDY: &str = "WHERE p.study_id = $1 ORDER BY se.id";
pub(crate) const INSERT_PARTICIPANT: &str = "INSERT INTO study_participant \
     (study_id, invitation_id, pseudonym, consent_at, created_at) VALUES ($1, $2, $3, $4, $5) RETURNING id";
pub(crate) const INSERT_SESSION: &str = "INSERT INTO study_session (participant_id, plan, device, \
     viewport_width, viewport_height, pixel_ratio, source, started_at, finished_at) \
     VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9) RETURNING id";
pub(crate) const ANSWER_SELECT: &str = "SELECT session_id, step, from_level, to_level, control, \
     improvement, sufficient, shown_from_ms, shown_to_ms, answered_at FROM study_answer ";
pub(crate) const ANSWERS_OF_SESSION: &str = "WHERE session_id = $1 ORDER BY step";
pub(crate) const ANSWERS_OF_STUDY: &str = "WHERE session_id IN (SELECT se.id FROM study_session se \
     JOIN study_participant p ON p.id = se.participant_id WHERE p.study_id = $1) ORDER BY session_id, step";
pub(crate) const INSERT_ANSWER: &str = "INSERT INTO study_answer (session_id, step, from_level, \
     to_level, control, improvement, sufficient, shown_from_ms, shown_to_ms, answered_at) \
     VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10)";
pub(crate) const COUNT_REQUEST: &str =
    "UPDATE study_session SET requests = requests + 1 WHERE id = $1 AND requests < $2";
pub(crate) const INSERT_VIEW: &str =
    "INSERT INTO study_view (session_id, at_ms, step, state, kind, data) \
     VALUES ($1, $2, $3, $4, $5, $6)";
pub(crate) const VIEWS_OF_STUDY: &str = "SELECT p.pseudonym, v.at_ms, v.step, v.state, v.kind, v.data \
     FROM study_view v JOIN study_session se ON se.id = v.session_id \
     JOIN study_participant p ON p.id = se.participant_id WHERE p.study_id = $1 ORDER BY v.session_id, v.id";
pub(crate) const FINISH_SESSION: &str =
    "UPDATE study_session SET finished_at = $2 WHERE id = $1 AND finished_at IS NULL";
pub(crate) const APPLY_GOOD_ENOUGH: &str =
    "UPDATE model SET good_enough_level = $2, good_enough_study_id = $3 WHERE id = $1";
