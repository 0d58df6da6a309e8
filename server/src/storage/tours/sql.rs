//! The tours' SQL, written once for both backends (`$n` placeholders,
//! types that decode alike; see `storage/sql.rs`).

const SELECT: &str =
    "SELECT id, model_slug, model_version, title, steps, created_at, updated_at FROM tour ";

pub(crate) fn tours(of_version: bool) -> String {
    if of_version {
        format!("{SELECT}WHERE model_slug = $1 AND model_version = $2 ORDER BY id")
    } else {
        format!("{SELECT}WHERE model_slug = $1 ORDER BY id")
    }
}

pub(crate) fn tour() -> String {
    format!("{SELECT}WHERE model_slug = $1 AND id = $2")
}

pub(crate) const INSERT_TOUR: &str = "INSERT INTO tour \
     (model_slug, model_version, title, steps, created_at, updated_at) \
     VALUES ($1, $2, $3, $4, $5, $5) RETURNING id";
pub(crate) const UPDATE_TOUR: &str = "UPDATE tour SET model_version = $3, title = $4, \
     steps = $5, updated_at = $6 WHERE model_slug = $1 AND id = $2";
pub(crate) const DELETE_TOUR: &str = "DELETE FROM tour WHERE model_slug = $1 AND id = $2";
