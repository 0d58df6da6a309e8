//! The texts' SQL, written once for both backends (`$n` placeholders,
//! types that decode alike; see `storage/sql.rs`).

/// The translations of model `$1`.
pub(crate) const TRANSLATIONS: &str =
    "SELECT language, title, description, credit FROM model_text WHERE model_id = $1 \
     ORDER BY language";
pub(crate) const VERSION: &str = "SELECT id, title, description, credit, language FROM model \
     WHERE slug = $1 AND version = $2";
pub(crate) const SET_LANGUAGE: &str = "UPDATE model SET language = $2 WHERE id = $1";
pub(crate) const CLEAR: &str = "DELETE FROM model_text WHERE model_id = $1";
pub(crate) const INSERT: &str = "INSERT INTO model_text \
     (model_id, language, title, description, credit) VALUES ($1, $2, $3, $4, $5)";
/// The translated titles of each slug's visible version (as `LIST` picks it).
pub(crate) const LISTED_TITLES: &str = "SELECT m.slug, t.language, t.title FROM model_text t \
     JOIN model m ON m.id = t.model_id \
     WHERE t.title IS NOT NULL AND m.status = 'ready' \
     AND m.version = (SELECT MAX(m2.version) FROM model m2 WHERE m2.slug = m.slug AND m2.status = 'ready') \
     ORDER BY m.slug, t.language";
