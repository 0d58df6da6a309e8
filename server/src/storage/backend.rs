//! The [`super::Storage`] implementation both backends share, as a macro over
//! the pool type: the queries are in `sql.rs`, the inserts of an ingest in
//! `stage.rs`.

/// Implements [`super::Storage`] for a backend struct with a `pool` field, a
/// `classify(sqlx::Error) -> StorageError`, a `prepare()` run before
/// migrations and a `begin_write()` that opens a write transaction.
macro_rules! sql_storage {
    ($storage:ty, $db:ty, $backend:literal, $migrator:expr) => {
        impl $storage {
            fn record_from_row(
                row: &<$db as sqlx::Database>::Row,
            ) -> $crate::storage::Result<ModelRecord> {
                use sqlx::Row;
                use $crate::storage::sql::narrow;
                let get = |e: sqlx::Error| StorageError::Corrupt(e.to_string());
                Ok(ModelRecord {
                    model_id: row.try_get("model_id").map_err(get)?,
                    slug: row.try_get("slug").map_err(get)?,
                    version: narrow(row.try_get("version").map_err(get)?, "model.version")?,
                    kind: Self::kind_from_row(row)?,
                    title: row.try_get("title").map_err(get)?,
                    description: row.try_get("description").map_err(get)?,
                    policy: AudiencePolicy {
                        name: row.try_get("policy_name").map_err(get)?,
                        public_access: row.try_get("public_access").map_err(get)?,
                        public_max_vertex_fraction: row
                            .try_get("public_max_vertex_fraction")
                            .map_err(get)?,
                        public_full_resolution: row
                            .try_get("public_full_resolution")
                            .map_err(get)?,
                        token_full_resolution: row.try_get("token_full_resolution").map_err(get)?,
                        downloads: row.try_get("downloads").map_err(get)?,
                    },
                    good_enough_level: match row
                        .try_get::<Option<i64>, _>("good_enough_level")
                        .map_err(get)?
                    {
                        Some(v) => Some(narrow(v, "model.good_enough_level")?),
                        None => None,
                    },
                    created_at_ms: row.try_get("created_at").map_err(get)?,
                    compression_id: row.try_get("compression_id").map_err(get)?,
                    quantization_bits: narrow(
                        row.try_get("quantization_bits").map_err(get)?,
                        "quantization_bits",
                    )?,
                    has_colour: row.try_get("has_colour").map_err(get)?,
                    stream_format: narrow(
                        row.try_get("codec_version").map_err(get)?,
                        "codec_version",
                    )?,
                    levels: Vec::new(),
                    mapping: None,
                    textures: Vec::new(),
                    has_study: row.try_get("has_study").map_err(get)?,
                    texts: $crate::storage::ModelTexts {
                        language: row.try_get("language").map_err(get)?,
                        translations: Default::default(),
                    },
                    curation: Curation {
                        up_axis: match row.try_get::<Option<String>, _>("up_axis").map_err(get)? {
                            Some(name) => Some(UpAxis::parse(&name).ok_or_else(|| {
                                StorageError::Corrupt(format!("model.up_axis = {name:?}"))
                            })?),
                            None => None,
                        },
                        unit: row.try_get("unit").map_err(get)?,
                        bounds: match row.try_get::<Option<String>, _>("bounds").map_err(get)? {
                            Some(json) => Some(Bounds::from_json(&json).ok_or_else(|| {
                                StorageError::Corrupt(format!("model.bounds = {json:?}"))
                            })?),
                            None => None,
                        },
                        thumbnail_sha256: row.try_get("thumbnail_sha256").map_err(get)?,
                        rights: Self::rights_from_row(row)?,
                    },
                })
            }

            /// Columns `model.credit` and `model.licence` of a row.
            fn rights_from_row(
                row: &<$db as sqlx::Database>::Row,
            ) -> $crate::storage::Result<$crate::storage::Rights> {
                use sqlx::Row;
                let get = |e: sqlx::Error| StorageError::Corrupt(e.to_string());
                Ok($crate::storage::Rights::from_stored(
                    row.try_get("credit").map_err(get)?,
                    row.try_get("licence").map_err(get)?,
                ))
            }

            /// Column `model.kind` of a row.
            fn kind_from_row(
                row: &<$db as sqlx::Database>::Row,
            ) -> $crate::storage::Result<ModelKind> {
                use sqlx::Row;
                let name: String = row
                    .try_get("kind")
                    .map_err(|e| StorageError::Corrupt(e.to_string()))?;
                ModelKind::parse(&name)
                    .ok_or_else(|| StorageError::Corrupt(format!("model.kind = {name:?}")))
            }

            /// Fills in levels and textures of a record read by `sql`.
            async fn record(
                &self,
                sql: &'static str,
                key: impl for<'q> sqlx::Encode<'q, $db> + sqlx::Type<$db> + Send + 'static,
            ) -> $crate::storage::Result<Option<ModelRecord>> {
                use sqlx::Row;
                use $crate::storage::sql::{narrow, LEVELS, TEXTURES};
                let c = Self::classify;
                let Some(row) = sqlx::query(sql)
                    .bind(key)
                    .fetch_optional(&self.pool)
                    .await
                    .map_err(c)?
                else {
                    return Ok(None);
                };
                let mut record = Self::record_from_row(&row)?;
                let mapping: Option<i64> = row.try_get("mapping_id").map_err(c)?;
                for row in sqlx::query(LEVELS)
                    .bind(record.compression_id)
                    .fetch_all(&self.pool)
                    .await
                    .map_err(c)?
                {
                    let iteration: i64 = row.try_get("iteration").map_err(c)?;
                    if iteration != record.levels.len() as i64 {
                        return Err(StorageError::Corrupt(format!(
                            "compression {} misses level {}",
                            record.compression_id,
                            record.levels.len()
                        )));
                    }
                    record.levels.push(LevelRecord {
                        vertices: narrow(row.try_get("vertices").map_err(c)?, "vertices")?,
                        faces: narrow(row.try_get("faces").map_err(c)?, "faces")?,
                        bytes: narrow(row.try_get("byte_len").map_err(c)?, "byte_len")?,
                        sha256: row.try_get("sha256").map_err(c)?,
                        hausdorff: row.try_get("hausdorff").map_err(c)?,
                        rmse: row.try_get("rmse").map_err(c)?,
                        roy_rmse: row.try_get("roy_rmse").map_err(c)?,
                    });
                }
                if record.levels.is_empty() {
                    return Err(StorageError::Corrupt(format!(
                        "compression {} has no base mesh",
                        record.compression_id
                    )));
                }
                if let Some(mapping) = mapping {
                    let parameters: Option<String> =
                        row.try_get("mapping_parameters").map_err(c)?;
                    let parameters = serde_json::from_str(parameters.as_deref().unwrap_or(""))
                        .map_err(|e| {
                            StorageError::Corrupt(format!(
                                "texture mapping {mapping} has unreadable parameters: {e}"
                            ))
                        })?;
                    record.mapping = Some(MappingRecord {
                        id: mapping,
                        parameters,
                    });
                    for row in sqlx::query(TEXTURES)
                        .bind(mapping)
                        .fetch_all(&self.pool)
                        .await
                        .map_err(c)?
                    {
                        let side = |name: &str| -> $crate::storage::Result<Option<u32>> {
                            match row.try_get::<Option<i64>, _>(name).map_err(c)? {
                                Some(v) => Ok(Some(narrow(v, "texture size")?)),
                                None => Ok(None),
                            }
                        };
                        record.textures.push(TextureRef {
                            id: row.try_get("id").map_err(c)?,
                            kind: row.try_get("kind").map_err(c)?,
                            role: row.try_get("role").map_err(c)?,
                            media_type: row.try_get("media_type").map_err(c)?,
                            bytes: narrow(row.try_get("byte_len").map_err(c)?, "texture.byte_len")?,
                            width: side("width")?,
                            height: side("height")?,
                        });
                    }
                }
                record.texts.translations = self.translations_of(record.model_id).await?;
                Ok(Some(record))
            }
        }

        #[async_trait::async_trait]
        impl Storage for $storage {
            fn backend(&self) -> &'static str {
                $backend
            }

            async fn migrate(&self) -> $crate::storage::Result<()> {
                self.prepare().await?;
                $migrator.run(&self.pool).await?;
                Ok(())
            }

            async fn ping(&self) -> $crate::storage::Result<()> {
                sqlx::query("SELECT 1")
                    .execute(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                Ok(())
            }

            async fn change_generation(&self) -> $crate::storage::Result<i64> {
                sqlx::query_scalar("SELECT generation FROM change_generation")
                    .fetch_one(&self.pool)
                    .await
                    .map_err(Self::classify)
            }

            async fn list_models(&self) -> $crate::storage::Result<Vec<ModelSummary>> {
                use sqlx::Row;
                use $crate::storage::sql::{narrow, LIST};
                let c = Self::classify;
                let rows = sqlx::query(LIST).fetch_all(&self.pool).await.map_err(c)?;
                let mut titles = $crate::storage::TextStorage::listed_titles(self).await?;
                rows.iter()
                    .map(|row| {
                        let slug: String = row.try_get("slug").map_err(c)?;
                        Ok(ModelSummary {
                            translations: titles.remove(&slug).unwrap_or_default(),
                            language: row.try_get("language").map_err(c)?,
                            slug,
                            title: row.try_get("title").map_err(c)?,
                            version: narrow(row.try_get("version").map_err(c)?, "model.version")?,
                            kind: Self::kind_from_row(row)?,
                            created_at_ms: row.try_get("created_at").map_err(c)?,
                            public_access: row.try_get("public_access").map_err(c)?,
                            batch_count: narrow(
                                row.try_get("batch_count").map_err(c)?,
                                "batch_count",
                            )?,
                            stream_format: narrow(
                                row.try_get("codec_version").map_err(c)?,
                                "codec_version",
                            )?,
                            has_thumbnail: row.try_get("has_thumbnail").map_err(c)?,
                            licence: row.try_get("licence").map_err(c)?,
                            has_parts: row.try_get("has_parts").map_err(c)?,
                        })
                    })
                    .collect()
            }

            async fn slugs_with_unmeasured_parts(&self) -> $crate::storage::Result<Vec<String>> {
                sqlx::query_scalar($crate::storage::sql::UNMEASURED_PARTS)
                    .fetch_all(&self.pool)
                    .await
                    .map_err(Self::classify)
            }

            async fn model_by_slug(
                &self,
                slug: &str,
            ) -> $crate::storage::Result<Option<ModelRecord>> {
                self.record($crate::storage::sql::RECORD_BY_SLUG, slug.to_owned())
                    .await
            }

            async fn model_by_compression(
                &self,
                id: i64,
            ) -> $crate::storage::Result<Option<ModelRecord>> {
                self.record($crate::storage::sql::RECORD_BY_COMPRESSION, id)
                    .await
            }

            async fn base_payload(&self, id: i64) -> $crate::storage::Result<Option<Vec<u8>>> {
                sqlx::query_scalar($crate::storage::sql::BASE)
                    .bind(id)
                    .fetch_optional(&self.pool)
                    .await
                    .map_err(Self::classify)
            }

            async fn batch_payload(
                &self,
                id: i64,
                iteration: u32,
            ) -> $crate::storage::Result<Option<Vec<u8>>> {
                sqlx::query_scalar($crate::storage::sql::BATCH)
                    .bind(id)
                    .bind(i64::from(iteration))
                    .fetch_optional(&self.pool)
                    .await
                    .map_err(Self::classify)
            }

            async fn parts(&self, id: i64) -> $crate::storage::Result<Vec<PartRecord>> {
                use sqlx::Row;
                use $crate::storage::sql::narrow;
                let c = Self::classify;
                let rows = sqlx::query($crate::storage::sql::PARTS)
                    .bind(id)
                    .fetch_all(&self.pool)
                    .await
                    .map_err(c)?;
                rows.iter()
                    .map(|row| {
                        let int = |name: &'static str| -> $crate::storage::Result<u32> {
                            narrow(row.try_get::<i64, _>(name).map_err(c)?, name)
                        };
                        Ok(PartRecord {
                            iteration: int("iteration")?,
                            chart: int("chart")?,
                            bytes: int("byte_len")?,
                            inserted: int("inserted")?,
                            error: row.try_get("error").map_err(c)?,
                            bulk_error: row.try_get("bulk_error").map_err(c)?,
                            phase: int("phase")?,
                            parent: row
                                .try_get::<Option<i64>, _>("parent")
                                .map_err(c)?
                                .map(|p| narrow(p, "parent"))
                                .transpose()?,
                        })
                    })
                    .collect()
            }

            async fn splits(&self, id: i64) -> $crate::storage::Result<Vec<SplitRecord>> {
                use sqlx::Row;
                use $crate::storage::sql::narrow;
                let c = Self::classify;
                let rows = sqlx::query($crate::storage::sql::SPLITS)
                    .bind(id)
                    .fetch_all(&self.pool)
                    .await
                    .map_err(c)?;
                rows.iter()
                    .map(|row| {
                        let int = |name: &'static str| -> $crate::storage::Result<u32> {
                            narrow(row.try_get::<i64, _>(name).map_err(c)?, name)
                        };
                        Ok(SplitRecord {
                            iteration: int("iteration")?,
                            parent: int("parent")?,
                            first_child: int("first_child")?,
                            children: int("children")?,
                            bytes: int("byte_len")?,
                        })
                    })
                    .collect()
            }

            async fn texture(&self, id: i64) -> $crate::storage::Result<Option<TexturePayload>> {
                use sqlx::Row;
                let c = Self::classify;
                let row = sqlx::query($crate::storage::sql::TEXTURE)
                    .bind(id)
                    .fetch_optional(&self.pool)
                    .await
                    .map_err(c)?;
                row.map(|row| {
                    Ok(TexturePayload {
                        media_type: row.try_get("media_type").map_err(c)?,
                        sha256: row.try_get("sha256").map_err(c)?,
                        bytes: row.try_get("bytes").map_err(c)?,
                        model_slug: row.try_get("slug").map_err(c)?,
                        public_access: row.try_get("public_access").map_err(c)?,
                    })
                })
                .transpose()
            }

            async fn token_grant(
                &self,
                sha256: &str,
                now_ms: i64,
            ) -> $crate::storage::Result<Option<TokenGrant>> {
                use sqlx::Row;
                let c = Self::classify;
                let row = sqlx::query($crate::storage::sql::TOKEN)
                    .bind(sha256.to_owned())
                    .bind(now_ms)
                    .fetch_optional(&self.pool)
                    .await
                    .map_err(c)?;
                row.map(|row| {
                    Ok(TokenGrant {
                        id: row.try_get("id").map_err(c)?,
                        label: row.try_get("label").map_err(c)?,
                        model_slug: row.try_get("model_slug").map_err(c)?,
                        scope: {
                            let name: String = row.try_get("scope").map_err(c)?;
                            TokenScope::parse(&name).ok_or_else(|| {
                                StorageError::Corrupt(format!("access_token.scope = {name:?}"))
                            })?
                        },
                    })
                })
                .transpose()
            }

            async fn insert_token(&self, token: &NewToken) -> $crate::storage::Result<i64> {
                sqlx::query_scalar($crate::storage::sql::INSERT_TOKEN)
                    .bind(token.token_sha256.clone())
                    .bind(token.label.clone())
                    .bind(token.model_slug.clone())
                    .bind(token.expires_at_ms)
                    .bind($crate::storage::now_ms())
                    .bind(token.scope.name())
                    .fetch_one(&self.pool)
                    .await
                    .map_err(Self::classify)
            }

            async fn stage_model(
                &self,
                model: &NewModel,
            ) -> $crate::storage::Result<Box<dyn StagedModel>> {
                let mut tx = self.begin_write().await?;
                let stored = $crate::storage::stage::stage_body!(tx, model, Self::classify);
                Ok(Box::new($crate::storage::sql::Staged {
                    tx,
                    stored,
                    classify: Self::classify,
                }))
            }
        }
    };
}

pub(super) use sql_storage;
