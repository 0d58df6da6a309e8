//! The curators' SQL, written once for both backends (`$n` placeholders,
//! types that decode alike; see `storage/sql.rs`).

pub(crate) const ANNOTATIONS: &str = "SELECT id, model_slug, title, body, html, position, normal, \
     saved_view, language, translations, created_at, updated_at FROM annotation WHERE model_slug = $1 \
     ORDER BY id";
pub(crate) const ANNOTATION: &str = "SELECT id, model_slug, title, body, html, position, normal, \
     saved_view, language, translations, created_at, updated_at FROM annotation \
     WHERE model_slug = $1 AND id = $2";
pub(crate) const INSERT_ANNOTATION: &str = "INSERT INTO annotation \
     (model_slug, title, body, html, position, normal, saved_view, language, translations, \
     created_at, updated_at) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $10) RETURNING id";
pub(crate) const UPDATE_ANNOTATION: &str = "UPDATE annotation SET title = $3, body = $4, \
     html = $5, position = $6, normal = $7, saved_view = $8, language = $9, translations = $10, \
     updated_at = $11 \
     WHERE model_slug = $1 AND id = $2";
pub(crate) const DELETE_ANNOTATION: &str =
    "DELETE FROM annotation WHERE model_slug = $1 AND id = $2";

pub(crate) const JOB_SELECT: &str = "SELECT id, slug, title, source_name, state, progress, stage, \
     error, model_version, created_at, updated_at FROM ingest_job ";
pub(crate) const INSERT_JOB: &str = "INSERT INTO ingest_job \
     (slug, title, source_name, state, progress, stage, token_id, created_at, updated_at) \
     VALUES ($1, $2, $3, 'queued', 0, 'queued', $4, $5, $5) RETURNING id";
pub(crate) const TOUCH_JOB: &str = "UPDATE ingest_job SET updated_at = $2 \
     WHERE id = $1 AND state IN ('queued', 'running')";
pub(crate) const UPDATE_JOB: &str = "UPDATE ingest_job SET state = $2, progress = $3, stage = $4, \
     error = $5, model_version = $6, updated_at = $7 WHERE id = $1";

pub(crate) const VERSIONS: &str = "SELECT m.id, m.version, m.title, m.status, p.name AS policy, \
     m.good_enough_level, m.created_at, m.credit, m.licence, \
     (SELECT c.batch_count FROM compression c WHERE c.model_id = m.id ORDER BY c.id DESC LIMIT 1) \
     AS batch_count \
     FROM model m JOIN audience_policy p ON p.id = m.policy_id \
     WHERE m.slug = $1 ORDER BY m.version DESC";
pub(crate) const SET_STATUS: &str = "UPDATE model SET status = $3 WHERE slug = $1 AND version = $2";
pub(crate) const SET_GOOD_ENOUGH: &str = "UPDATE model SET good_enough_level = $3, \
     good_enough_study_id = NULL WHERE slug = $1 AND version = $2";
pub(crate) const SET_RIGHTS: &str =
    "UPDATE model SET credit = $3, licence = $4 WHERE slug = $1 AND version = $2";
pub(crate) const THUMBNAIL: &str =
    "SELECT media_type, sha256, bytes FROM thumbnail WHERE model_id = $1";
