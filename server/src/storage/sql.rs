//! The SQL both backends run, written once. `$n` placeholders work on SQLite
//! (sqlx binds `$n` by number) and PostgreSQL alike, and every column is an
//! integer, text, boolean, double or blob that decodes to the same Rust type on
//! both, so one macro expands the same queries for each pool type.

use super::{Result, StagedModel, StorageError, StoredModel};
use async_trait::async_trait;

macro_rules! record_select {
    () => {
        "SELECT m.id AS model_id, m.slug, m.version, m.kind, m.title, m.description, \
         m.good_enough_level, m.created_at, p.name AS policy_name, p.public_access, \
         p.public_max_vertex_fraction, p.public_full_resolution, p.token_full_resolution, p.downloads, \
         c.id AS compression_id, c.codec_version, c.quantization_bits, c.has_colour, c.mapping_id, \
         tm.parameters AS mapping_parameters, m.up_axis, m.unit, m.bounds, m.credit, m.licence, m.language, \
         th.sha256 AS thumbnail_sha256, \
         EXISTS (SELECT 1 FROM study s WHERE s.model_id = m.id) AS has_study \
         FROM model m JOIN audience_policy p ON p.id = m.policy_id \
         JOIN compression c ON c.model_id = m.id \
         LEFT JOIN texture_mapping tm ON tm.id = c.mapping_id \
         LEFT JOIN thumbnail th ON th.model_id = m.id "
    };
}

pub(super) const RECORD_BY_SLUG: &str = concat!(
    record_select!(),
    "WHERE m.slug = $1 AND m.status = 'ready' ORDER BY m.version DESC, c.id DESC LIMIT 1"
);
pub(super) const RECORD_BY_COMPRESSION: &str =
    concat!(record_select!(), "WHERE c.id = $1 AND m.status = 'ready'");
pub(super) const LEVELS: &str =
    "SELECT 0 AS iteration, vertices, faces, byte_len, sha256, hausdorff, rmse, roy_rmse \
     FROM base_mesh WHERE compression_id = $1 \
     UNION ALL SELECT iteration, vertices, faces, byte_len, sha256, hausdorff, rmse, roy_rmse \
     FROM refinement_batch WHERE compression_id = $1 ORDER BY iteration";
/// The images of mapping `$1` and which of its columns names each.
pub(super) const TEXTURES: &str = "SELECT t.id, t.kind, t.media_type, t.byte_len, t.width, t.height, \
     CASE WHEN t.id = tm.cell_texture_id THEN 'cell' \
     WHEN t.id = tm.colour_texture_id THEN 'colour' ELSE 'colour_low' END AS role \
     FROM texture_mapping tm \
     JOIN texture t ON t.id IN (tm.cell_texture_id, tm.colour_texture_id, tm.colour_low_texture_id) \
     WHERE tm.id = $1 ORDER BY t.id";
pub(super) const LIST: &str = "SELECT m.slug, m.title, m.version, m.kind, m.created_at, p.public_access, c.batch_count, c.codec_version, m.licence, m.language, \
     (th.model_id IS NOT NULL) AS has_thumbnail, \
     EXISTS (SELECT 1 FROM stream_part sp WHERE sp.compression_id = c.id) AS has_parts \
     FROM model m JOIN audience_policy p ON p.id = m.policy_id JOIN compression c ON c.model_id = m.id \
     LEFT JOIN thumbnail th ON th.model_id = m.id \
     WHERE m.status = 'ready' \
     AND m.version = (SELECT MAX(m2.version) FROM model m2 WHERE m2.slug = m.slug AND m2.status = 'ready') \
     AND c.id = (SELECT MAX(c2.id) FROM compression c2 WHERE c2.model_id = m.id) \
     ORDER BY m.slug";
/// The slugs whose visible version's newest compression has parts measured
/// before their bulk error was (`vitrine models` only: it reads every part
/// row, which the model list served to visitors must not).
pub(super) const UNMEASURED_PARTS: &str = "SELECT DISTINCT m.slug FROM model m \
     JOIN compression c ON c.model_id = m.id \
     JOIN stream_part sp ON sp.compression_id = c.id \
     WHERE m.status = 'ready' AND sp.bulk_error IS NULL \
     AND m.version = (SELECT MAX(m2.version) FROM model m2 WHERE m2.slug = m.slug AND m2.status = 'ready') \
     AND c.id = (SELECT MAX(c2.id) FROM compression c2 WHERE c2.model_id = m.id) \
     ORDER BY m.slug";
pub(super) const BASE: &str = "SELECT bytes FROM base_mesh WHERE compression_id = $1";
pub(super) const BATCH: &str =
    "SELECT bytes FROM refinement_batch WHERE compression_id = $1 AND iteration = $2";
pub(super) const TEXTURE: &str = "SELECT t.media_type, t.sha256, t.bytes, m.slug, p.public_access \
     FROM texture t \
     JOIN texture_mapping tm ON t.id IN (tm.cell_texture_id, tm.colour_texture_id, tm.colour_low_texture_id) \
     JOIN model m ON m.id = tm.model_id JOIN audience_policy p ON p.id = m.policy_id \
     WHERE t.id = $1 AND m.status = 'ready' ORDER BY p.public_access DESC LIMIT 1";
pub(super) const TOKEN: &str = "SELECT id, label, model_slug, scope FROM access_token \
     WHERE token_sha256 = $1 AND revoked_at IS NULL AND (expires_at IS NULL OR expires_at > $2)";
pub(super) const INSERT_TOKEN: &str =
    "INSERT INTO access_token (token_sha256, label, model_slug, expires_at, created_at, scope) \
     VALUES ($1, $2, $3, $4, $5, $6) RETURNING id";
pub(super) const POLICY_ID: &str = "SELECT id FROM audience_policy WHERE name = $1";
pub(super) const MAX_VERSION: &str = "SELECT MAX(version) AS v FROM model WHERE slug = $1";
pub(super) const INSERT_MODEL: &str =
    "INSERT INTO model (slug, version, title, description, policy_id, \
     good_enough_level, source_name, source_vertices, source_faces, status, created_at, \
     up_axis, unit, bounds, kind, credit, licence, language) \
     VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, 'ready', $10, $11, $12, $13, $14, $15, $16, $17) \
     RETURNING id";
pub(super) const INSERT_THUMBNAIL: &str = "INSERT INTO thumbnail \
     (model_id, media_type, width, height, byte_len, sha256, bytes, created_at) \
     VALUES ($1, $2, $3, $4, $5, $6, $7, $8)";
pub(super) const INSERT_COMPRESSION: &str = "INSERT INTO compression (model_id, codec_version, options, stats, \
     quantization_bits, has_colour, batch_count, final_vertices, final_faces, stream_bytes, encode_ms, created_at, \
     mapping_id) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12, $13) RETURNING id";
pub(super) const INSERT_BASE: &str =
    "INSERT INTO base_mesh (compression_id, vertices, faces, byte_len, sha256, bytes, \
     hausdorff, rmse, roy_rmse) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9)";
pub(super) const INSERT_TEXTURE: &str = "INSERT INTO texture \
     (kind, media_type, width, height, byte_len, sha256, bytes, created_at) \
     VALUES ($1, $2, $3, $4, $5, $6, $7, $8) RETURNING id";
pub(super) const INSERT_MAPPING: &str = "INSERT INTO texture_mapping \
     (model_id, cell_texture_id, colour_texture_id, colour_low_texture_id, parameters, created_at) \
     VALUES ($1, $2, $3, $4, $5, $6) RETURNING id";
pub(super) const INSERT_PART: &str = "INSERT INTO stream_part \
     (compression_id, iteration, chart, byte_len, inserted, error, bulk_error, phase, parent) \
     VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9)";
pub(super) const PARTS: &str =
    "SELECT iteration, chart, byte_len, inserted, error, bulk_error, phase, parent FROM stream_part \
     WHERE compression_id = $1 ORDER BY iteration, chart";
pub(super) const INSERT_SPLIT: &str = "INSERT INTO stream_split \
     (compression_id, iteration, parent, first_child, children, byte_len) \
     VALUES ($1, $2, $3, $4, $5, $6)";
pub(super) const SPLITS: &str =
    "SELECT iteration, parent, first_child, children, byte_len FROM stream_split \
     WHERE compression_id = $1 ORDER BY iteration, parent";
pub(super) const INSERT_BATCH: &str = "INSERT INTO refinement_batch \
     (compression_id, iteration, vertices, faces, byte_len, sha256, bytes, hausdorff, rmse, roy_rmse) \
     VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10)";

/// A model version written inside a transaction that is still open.
pub(super) struct Staged<DB: sqlx::Database> {
    pub tx: sqlx::Transaction<'static, DB>,
    pub stored: StoredModel,
    pub classify: fn(sqlx::Error) -> StorageError,
}

#[async_trait]
impl<DB: sqlx::Database> StagedModel for Staged<DB> {
    fn stored(&self) -> &StoredModel {
        &self.stored
    }

    async fn commit(self: Box<Self>) -> Result<StoredModel> {
        let stored = self.stored;
        self.tx.commit().await.map_err(self.classify)?;
        Ok(stored)
    }
}

/// Converts a stored integer, refusing values the schema should never hold.
pub(super) fn narrow<T: TryFrom<i64>>(value: i64, what: &str) -> Result<T> {
    T::try_from(value)
        .map_err(|_| StorageError::Corrupt(format!("{what} = {value} is out of range")))
}
