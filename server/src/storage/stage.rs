//! The inserts of one ingest, shared by both backends.

/// The inserts of one ingest, run on an open transaction `$tx`.
macro_rules! stage_body {
    ($tx:ident, $model:ident, $classify:expr) => {{
        use $crate::storage::sql::*;
        use $crate::storage::{now_ms, sha256_hex, OnExisting, StoredModel};
        let c = $classify;
        let policy_id: Option<i64> =
            sqlx::query_scalar(POLICY_ID).bind($model.policy.clone()).fetch_optional(&mut *$tx).await.map_err(c)?;
        let policy_id =
            policy_id.ok_or_else(|| StorageError::Unknown(format!("no audience policy named {:?}", $model.policy)))?;
        let latest: Option<i64> =
            sqlx::query_scalar(MAX_VERSION).bind($model.slug.clone()).fetch_one(&mut *$tx).await.map_err(c)?;
        if latest.is_some() && $model.on_existing == OnExisting::Refuse {
            return Err(StorageError::Conflict(format!(
                "model {:?} already exists (version {}); ingest with --new-version to add a version",
                $model.slug,
                latest.unwrap_or(0)
            )));
        }
        let version = latest.unwrap_or(0) + 1;
        let now = now_ms();
        let conflict = |e: sqlx::Error| match &e {
            sqlx::Error::Database(d) if d.is_unique_violation() => {
                StorageError::Conflict(format!("another ingest of {:?} committed first; retry", $model.slug))
            }
            _ => c(e),
        };
        let model_id: i64 = sqlx::query_scalar(INSERT_MODEL)
            .bind($model.slug.clone())
            .bind(version)
            .bind($model.title.clone())
            .bind($model.description.clone())
            .bind(policy_id)
            .bind($model.good_enough_level.map(i64::from))
            .bind($model.source_name.clone())
            .bind($model.source_vertices as i64)
            .bind($model.source_faces as i64)
            .bind(now)
            .bind($model.up_axis.map(|a| a.name()))
            .bind($model.unit.clone())
            .bind($model.bounds.map(|b| b.to_json()))
            .bind($model.kind.name())
            .bind($model.rights.credit.clone())
            .bind($model.rights.licence.map(|l| l.id))
            .bind($model.language.clone())
            .fetch_one(&mut *$tx)
            .await
            .map_err(conflict)?;
        if let Some(thumbnail) = &$model.thumbnail {
            sqlx::query(INSERT_THUMBNAIL)
                .bind(model_id)
                .bind(thumbnail.media_type)
                .bind(i64::from(thumbnail.width))
                .bind(i64::from(thumbnail.height))
                .bind(thumbnail.bytes.len() as i64)
                .bind(sha256_hex(&thumbnail.bytes))
                .bind(thumbnail.bytes.as_slice())
                .bind(now)
                .execute(&mut *$tx)
                .await
                .map_err(c)?;
        }
        let mut mapping_id: Option<i64> = None;
        if let Some(mapping) = &$model.mapping {
            let mut ids = [0i64; 3];
            for (id, texture) in ids.iter_mut().zip([&mapping.cell, &mapping.colour, &mapping.colour_low]) {
                *id = sqlx::query_scalar(INSERT_TEXTURE)
                    .bind(texture.kind)
                    .bind(texture.media_type)
                    .bind(i64::from(texture.width))
                    .bind(i64::from(texture.height))
                    .bind(texture.bytes.len() as i64)
                    .bind(sha256_hex(&texture.bytes))
                    .bind(texture.bytes.as_slice())
                    .bind(now)
                    .fetch_one(&mut *$tx)
                    .await
                    .map_err(c)?;
            }
            mapping_id = Some(
                sqlx::query_scalar(INSERT_MAPPING)
                    .bind(model_id)
                    .bind(ids[0])
                    .bind(ids[1])
                    .bind(ids[2])
                    .bind(mapping.parameters.clone())
                    .bind(now)
                    .fetch_one(&mut *$tx)
                    .await
                    .map_err(c)?,
            );
        }
        let comp = &$model.compression;
        let last = comp.batches.last().unwrap_or(&comp.base);
        let compression_id: i64 = sqlx::query_scalar(INSERT_COMPRESSION)
            .bind(model_id)
            .bind(i64::from(comp.codec_version))
            .bind(comp.options.clone())
            .bind(comp.stats.clone())
            .bind(i64::from(comp.quantization_bits))
            .bind(comp.has_colour)
            .bind(comp.batches.len() as i64)
            .bind(i64::from(last.vertices))
            .bind(i64::from(last.faces))
            .bind(comp.stream_bytes as i64)
            .bind(comp.encode_ms as i64)
            .bind(now)
            .bind(mapping_id)
            .fetch_one(&mut *$tx)
            .await
            .map_err(c)?;
        sqlx::query(INSERT_BASE)
            .bind(compression_id)
            .bind(i64::from(comp.base.vertices))
            .bind(i64::from(comp.base.faces))
            .bind(comp.base.bytes.len() as i64)
            .bind(sha256_hex(&comp.base.bytes))
            .bind(comp.base.bytes.as_slice())
            .bind(comp.base.metrics.map(|m| m.hausdorff).or(comp.base.hausdorff))
            .bind(comp.base.metrics.map(|m| m.image_rmse))
            .bind(comp.base.metrics.and_then(|m| m.roy_rmse))
            .execute(&mut *$tx)
            .await
            .map_err(c)?;
        for (k, batch) in comp.batches.iter().enumerate() {
            sqlx::query(INSERT_BATCH)
                .bind(compression_id)
                .bind(k as i64 + 1)
                .bind(i64::from(batch.vertices))
                .bind(i64::from(batch.faces))
                .bind(batch.bytes.len() as i64)
                .bind(sha256_hex(&batch.bytes))
                .bind(batch.bytes.as_slice())
                .bind(batch.metrics.map(|m| m.hausdorff).or(batch.hausdorff))
                .bind(batch.metrics.map(|m| m.image_rmse))
                .bind(batch.metrics.and_then(|m| m.roy_rmse))
                .execute(&mut *$tx)
                .await
                .map_err(c)?;
        }
        for part in &comp.parts {
            sqlx::query(INSERT_PART)
                .bind(compression_id)
                .bind(i64::from(part.iteration))
                .bind(i64::from(part.chart))
                .bind(i64::from(part.bytes))
                .bind(i64::from(part.inserted))
                .bind(part.error)
                .bind(part.bulk_error)
                .bind(i64::from(part.phase))
                .bind(part.parent.map(i64::from))
                .execute(&mut *$tx)
                .await
                .map_err(c)?;
        }
        for split in &comp.splits {
            sqlx::query(INSERT_SPLIT)
                .bind(compression_id)
                .bind(i64::from(split.iteration))
                .bind(i64::from(split.parent))
                .bind(i64::from(split.first_child))
                .bind(i64::from(split.children))
                .bind(i64::from(split.bytes))
                .execute(&mut *$tx)
                .await
                .map_err(c)?;
        }
        StoredModel { model_id, compression_id, version: narrow(version, "model.version")? }
    }};
}

pub(super) use stage_body;
