//! [`super::CuratorStorage`] for a backend struct with a `pool` and a
//! `classify(sqlx::Error) -> StorageError`, as a macro over the pool type
//! (like `storage/backend.rs`).

macro_rules! curator_storage {
    ($storage:ty, $db:ty) => {
        impl $storage {
            fn annotation_from_row(
                row: &<$db as sqlx::Database>::Row,
            ) -> $crate::storage::Result<$crate::storage::AnnotationRecord> {
                use sqlx::Row;
                let get = |e: sqlx::Error| StorageError::Corrupt(e.to_string());
                let id: i64 = row.try_get("id").map_err(get)?;
                let vector = |name: &str| -> $crate::storage::Result<[f64; 3]> {
                    let json: String = row.try_get(name).map_err(get)?;
                    serde_json::from_str(&json).map_err(|e| {
                        StorageError::Corrupt(format!(
                            "annotation {id} has an unreadable {name}: {e}"
                        ))
                    })
                };
                let view: Option<String> = row.try_get("saved_view").map_err(get)?;
                Ok($crate::storage::AnnotationRecord {
                    id,
                    slug: row.try_get("model_slug").map_err(get)?,
                    title: row.try_get("title").map_err(get)?,
                    text: row.try_get("body").map_err(get)?,
                    html: row.try_get("html").map_err(get)?,
                    position: vector("position")?,
                    normal: vector("normal")?,
                    view: match view {
                        Some(json) => Some(serde_json::from_str(&json).map_err(|e| {
                            StorageError::Corrupt(format!(
                                "annotation {id} has an unreadable view: {e}"
                            ))
                        })?),
                        None => None,
                    },
                    language: row.try_get("language").map_err(get)?,
                    translations: match row
                        .try_get::<Option<String>, _>("translations")
                        .map_err(get)?
                    {
                        Some(json) => serde_json::from_str(&json).map_err(|e| {
                            StorageError::Corrupt(format!(
                                "annotation {id} has unreadable translations: {e}"
                            ))
                        })?,
                        None => Default::default(),
                    },
                    created_at_ms: row.try_get("created_at").map_err(get)?,
                    updated_at_ms: row.try_get("updated_at").map_err(get)?,
                })
            }

            fn job_from_row(
                row: &<$db as sqlx::Database>::Row,
            ) -> $crate::storage::Result<$crate::storage::JobRecord> {
                use sqlx::Row;
                use $crate::storage::sql::narrow;
                let get = |e: sqlx::Error| StorageError::Corrupt(e.to_string());
                let state: String = row.try_get("state").map_err(get)?;
                Ok($crate::storage::JobRecord {
                    id: row.try_get("id").map_err(get)?,
                    slug: row.try_get("slug").map_err(get)?,
                    title: row.try_get("title").map_err(get)?,
                    source_name: row.try_get("source_name").map_err(get)?,
                    state: $crate::storage::JobState::parse(&state).ok_or_else(|| {
                        StorageError::Corrupt(format!("ingest_job.state = {state:?}"))
                    })?,
                    progress: row.try_get("progress").map_err(get)?,
                    stage: row.try_get("stage").map_err(get)?,
                    error: row.try_get("error").map_err(get)?,
                    model_version: match row
                        .try_get::<Option<i64>, _>("model_version")
                        .map_err(get)?
                    {
                        Some(v) => Some(narrow(v, "ingest_job.model_version")?),
                        None => None,
                    },
                    created_at_ms: row.try_get("created_at").map_err(get)?,
                    updated_at_ms: row.try_get("updated_at").map_err(get)?,
                })
            }

            async fn annotation_by_id(
                &self,
                slug: &str,
                id: i64,
            ) -> $crate::storage::Result<Option<$crate::storage::AnnotationRecord>> {
                let row = sqlx::query($crate::storage::curator::sql::ANNOTATION)
                    .bind(slug.to_owned())
                    .bind(id)
                    .fetch_optional(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                row.as_ref().map(Self::annotation_from_row).transpose()
            }
        }

        #[async_trait::async_trait]
        impl $crate::storage::CuratorStorage for $storage {
            async fn annotations(
                &self,
                slug: &str,
            ) -> $crate::storage::Result<Vec<$crate::storage::AnnotationRecord>> {
                let rows = sqlx::query($crate::storage::curator::sql::ANNOTATIONS)
                    .bind(slug.to_owned())
                    .fetch_all(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                rows.iter().map(Self::annotation_from_row).collect()
            }

            async fn insert_annotation(
                &self,
                slug: &str,
                a: &$crate::storage::NewAnnotation,
            ) -> $crate::storage::Result<$crate::storage::AnnotationRecord> {
                let id: i64 = sqlx::query_scalar($crate::storage::curator::sql::INSERT_ANNOTATION)
                    .bind(slug.to_owned())
                    .bind(a.title.clone())
                    .bind(a.text.clone())
                    .bind(a.html.clone())
                    .bind(serde_json::json!(a.position).to_string())
                    .bind(serde_json::json!(a.normal).to_string())
                    .bind(a.view.as_ref().map(|v| v.to_string()))
                    .bind(a.language.clone())
                    .bind($crate::storage::curator::translations_json(&a.translations))
                    .bind($crate::storage::now_ms())
                    .fetch_one(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                self.annotation_by_id(slug, id).await?.ok_or_else(|| {
                    StorageError::Corrupt(format!("annotation {id} vanished after insert"))
                })
            }

            async fn update_annotation(
                &self,
                slug: &str,
                id: i64,
                a: &$crate::storage::NewAnnotation,
            ) -> $crate::storage::Result<Option<$crate::storage::AnnotationRecord>> {
                let done = sqlx::query($crate::storage::curator::sql::UPDATE_ANNOTATION)
                    .bind(slug.to_owned())
                    .bind(id)
                    .bind(a.title.clone())
                    .bind(a.text.clone())
                    .bind(a.html.clone())
                    .bind(serde_json::json!(a.position).to_string())
                    .bind(serde_json::json!(a.normal).to_string())
                    .bind(a.view.as_ref().map(|v| v.to_string()))
                    .bind(a.language.clone())
                    .bind($crate::storage::curator::translations_json(&a.translations))
                    .bind($crate::storage::now_ms())
                    .execute(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                if done.rows_affected() == 0 {
                    return Ok(None);
                }
                self.annotation_by_id(slug, id).await
            }

            async fn insert_annotations(
                &self,
                slug: &str,
                annotations: &[$crate::storage::NewAnnotation],
            ) -> $crate::storage::Result<usize> {
                let mut tx = self.begin_write().await?;
                let now = $crate::storage::now_ms();
                for a in annotations {
                    sqlx::query($crate::storage::curator::sql::INSERT_ANNOTATION)
                        .bind(slug.to_owned())
                        .bind(a.title.clone())
                        .bind(a.text.clone())
                        .bind(a.html.clone())
                        .bind(serde_json::json!(a.position).to_string())
                        .bind(serde_json::json!(a.normal).to_string())
                        .bind(a.view.as_ref().map(|v| v.to_string()))
                        .bind(a.language.clone())
                        .bind($crate::storage::curator::translations_json(&a.translations))
                        .bind(now)
                        .fetch_one(&mut *tx)
                        .await
                        .map_err(Self::classify)?;
                }
                tx.commit().await.map_err(Self::classify)?;
                Ok(annotations.len())
            }

            async fn delete_annotation(
                &self,
                slug: &str,
                id: i64,
            ) -> $crate::storage::Result<bool> {
                let done = sqlx::query($crate::storage::curator::sql::DELETE_ANNOTATION)
                    .bind(slug.to_owned())
                    .bind(id)
                    .execute(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                Ok(done.rows_affected() > 0)
            }

            async fn insert_job(
                &self,
                job: &$crate::storage::NewJob,
            ) -> $crate::storage::Result<$crate::storage::JobRecord> {
                let id: i64 = sqlx::query_scalar($crate::storage::curator::sql::INSERT_JOB)
                    .bind(job.slug.clone())
                    .bind(job.title.clone())
                    .bind(job.source_name.clone())
                    .bind(job.token_id)
                    .bind($crate::storage::now_ms())
                    .fetch_one(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                $crate::storage::CuratorStorage::job(self, id)
                    .await?
                    .ok_or_else(|| StorageError::Corrupt(format!("job {id} vanished after insert")))
            }

            async fn update_job(
                &self,
                id: i64,
                state: $crate::storage::JobState,
                progress: f64,
                stage: &str,
                error: Option<&str>,
                version: Option<u32>,
            ) -> $crate::storage::Result<()> {
                sqlx::query($crate::storage::curator::sql::UPDATE_JOB)
                    .bind(id)
                    .bind(state.name())
                    .bind(progress.clamp(0.0, 1.0))
                    .bind(stage.to_owned())
                    .bind(error.map(str::to_owned))
                    .bind(version.map(i64::from))
                    .bind($crate::storage::now_ms())
                    .execute(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                Ok(())
            }

            async fn touch_job(&self, id: i64) -> $crate::storage::Result<()> {
                sqlx::query($crate::storage::curator::sql::TOUCH_JOB)
                    .bind(id)
                    .bind($crate::storage::now_ms())
                    .execute(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                Ok(())
            }

            async fn job(
                &self,
                id: i64,
            ) -> $crate::storage::Result<Option<$crate::storage::JobRecord>> {
                let sql = format!("{}WHERE id = $1", $crate::storage::curator::sql::JOB_SELECT);
                let row = sqlx::query(&sql)
                    .bind(id)
                    .fetch_optional(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                row.as_ref().map(Self::job_from_row).transpose()
            }

            async fn jobs(
                &self,
                limit: u32,
            ) -> $crate::storage::Result<Vec<$crate::storage::JobRecord>> {
                let sql = format!(
                    "{}ORDER BY id DESC LIMIT $1",
                    $crate::storage::curator::sql::JOB_SELECT
                );
                let rows = sqlx::query(&sql)
                    .bind(i64::from(limit))
                    .fetch_all(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                rows.iter().map(Self::job_from_row).collect()
            }

            async fn versions(
                &self,
                slug: &str,
            ) -> $crate::storage::Result<Vec<$crate::storage::VersionRecord>> {
                use sqlx::Row;
                use $crate::storage::sql::narrow;
                let c = Self::classify;
                let rows = sqlx::query($crate::storage::curator::sql::VERSIONS)
                    .bind(slug.to_owned())
                    .fetch_all(&self.pool)
                    .await
                    .map_err(c)?;
                rows.iter()
                    .map(|row| {
                        Ok($crate::storage::VersionRecord {
                            model_id: row.try_get("id").map_err(c)?,
                            version: narrow(row.try_get("version").map_err(c)?, "model.version")?,
                            title: row.try_get("title").map_err(c)?,
                            status: row.try_get("status").map_err(c)?,
                            policy: row.try_get("policy").map_err(c)?,
                            good_enough_level: match row
                                .try_get::<Option<i64>, _>("good_enough_level")
                                .map_err(c)?
                            {
                                Some(v) => Some(narrow(v, "model.good_enough_level")?),
                                None => None,
                            },
                            levels: narrow::<u32>(
                                row.try_get::<Option<i64>, _>("batch_count")
                                    .map_err(c)?
                                    .unwrap_or(0),
                                "batch_count",
                            )? + 1,
                            created_at_ms: row.try_get("created_at").map_err(c)?,
                            rights: $crate::storage::Rights::from_stored(
                                row.try_get("credit").map_err(c)?,
                                row.try_get("licence").map_err(c)?,
                            ),
                        })
                    })
                    .collect()
            }

            async fn set_version_status(
                &self,
                slug: &str,
                version: u32,
                status: &str,
            ) -> $crate::storage::Result<bool> {
                let done = sqlx::query($crate::storage::curator::sql::SET_STATUS)
                    .bind(slug.to_owned())
                    .bind(i64::from(version))
                    .bind(status.to_owned())
                    .execute(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                Ok(done.rows_affected() > 0)
            }

            async fn set_version_rights(
                &self,
                slug: &str,
                version: u32,
                rights: &$crate::storage::Rights,
            ) -> $crate::storage::Result<bool> {
                let done = sqlx::query($crate::storage::curator::sql::SET_RIGHTS)
                    .bind(slug.to_owned())
                    .bind(i64::from(version))
                    .bind(rights.credit.clone())
                    .bind(rights.licence.map(|l| l.id))
                    .execute(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                Ok(done.rows_affected() > 0)
            }

            async fn set_good_enough_level(
                &self,
                slug: &str,
                version: u32,
                level: Option<u32>,
            ) -> $crate::storage::Result<bool> {
                let done = sqlx::query($crate::storage::curator::sql::SET_GOOD_ENOUGH)
                    .bind(slug.to_owned())
                    .bind(i64::from(version))
                    .bind(level.map(i64::from))
                    .execute(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                Ok(done.rows_affected() > 0)
            }

            async fn thumbnail(
                &self,
                model_id: i64,
            ) -> $crate::storage::Result<Option<$crate::storage::ThumbnailPayload>> {
                use sqlx::Row;
                let c = Self::classify;
                let row = sqlx::query($crate::storage::curator::sql::THUMBNAIL)
                    .bind(model_id)
                    .fetch_optional(&self.pool)
                    .await
                    .map_err(c)?;
                row.map(|row| {
                    Ok($crate::storage::ThumbnailPayload {
                        media_type: row.try_get("media_type").map_err(c)?,
                        sha256: row.try_get("sha256").map_err(c)?,
                        bytes: row.try_get("bytes").map_err(c)?,
                    })
                })
                .transpose()
            }
        }
    };
}

pub(in crate::storage) use curator_storage;
