//! [`super::TextStorage`] for a backend struct with a `pool` and a
//! `classify(sqlx::Error) -> StorageError`, as a macro over the pool type
//! (like `storage/tours/backend.rs`).

macro_rules! text_storage {
    ($storage:ty, $db:ty) => {
        impl $storage {
            /// The translations of a model row (also read with every record).
            pub(in crate::storage) async fn translations_of(
                &self,
                model_id: i64,
            ) -> $crate::storage::Result<$crate::storage::Translations> {
                use sqlx::Row;
                let get = |e: sqlx::Error| StorageError::Corrupt(e.to_string());
                let rows = sqlx::query($crate::storage::texts::sql::TRANSLATIONS)
                    .bind(model_id)
                    .fetch_all(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                rows.iter()
                    .map(|row| {
                        Ok((
                            row.try_get::<String, _>("language").map_err(get)?,
                            $crate::storage::Translation {
                                title: row.try_get("title").map_err(get)?,
                                description: row.try_get("description").map_err(get)?,
                                credit: row.try_get("credit").map_err(get)?,
                            },
                        ))
                    })
                    .collect()
            }
        }

        #[async_trait::async_trait]
        impl $crate::storage::TextStorage for $storage {
            async fn version_texts(
                &self,
                slug: &str,
                version: u32,
            ) -> $crate::storage::Result<Option<$crate::storage::VersionTexts>> {
                use sqlx::Row;
                let get = |e: sqlx::Error| StorageError::Corrupt(e.to_string());
                let Some(row) = sqlx::query($crate::storage::texts::sql::VERSION)
                    .bind(slug.to_owned())
                    .bind(i64::from(version))
                    .fetch_optional(&self.pool)
                    .await
                    .map_err(Self::classify)?
                else {
                    return Ok(None);
                };
                let model_id: i64 = row.try_get("id").map_err(get)?;
                Ok(Some($crate::storage::VersionTexts {
                    title: row.try_get("title").map_err(get)?,
                    description: row.try_get("description").map_err(get)?,
                    credit: row.try_get("credit").map_err(get)?,
                    texts: $crate::storage::ModelTexts {
                        language: row.try_get("language").map_err(get)?,
                        translations: self.translations_of(model_id).await?,
                    },
                }))
            }

            async fn set_version_texts(
                &self,
                slug: &str,
                version: u32,
                texts: &$crate::storage::ModelTexts,
            ) -> $crate::storage::Result<bool> {
                use $crate::storage::texts::sql;
                let c = Self::classify;
                let mut tx = self.pool.begin().await.map_err(c)?;
                let Some(model_id) = sqlx::query_scalar::<_, i64>(sql::VERSION)
                    .bind(slug.to_owned())
                    .bind(i64::from(version))
                    .fetch_optional(&mut *tx)
                    .await
                    .map_err(c)?
                else {
                    return Ok(false);
                };
                sqlx::query(sql::SET_LANGUAGE)
                    .bind(model_id)
                    .bind(texts.language.clone())
                    .execute(&mut *tx)
                    .await
                    .map_err(c)?;
                sqlx::query(sql::CLEAR)
                    .bind(model_id)
                    .execute(&mut *tx)
                    .await
                    .map_err(c)?;
                for (language, t) in &texts.translations {
                    sqlx::query(sql::INSERT)
                        .bind(model_id)
                        .bind(language.clone())
                        .bind(t.title.clone())
                        .bind(t.description.clone())
                        .bind(t.credit.clone())
                        .execute(&mut *tx)
                        .await
                        .map_err(c)?;
                }
                tx.commit().await.map_err(c)?;
                Ok(true)
            }

            async fn listed_titles(
                &self,
            ) -> $crate::storage::Result<
                std::collections::BTreeMap<String, $crate::storage::Translations>,
            > {
                use sqlx::Row;
                let get = |e: sqlx::Error| StorageError::Corrupt(e.to_string());
                let rows = sqlx::query($crate::storage::texts::sql::LISTED_TITLES)
                    .fetch_all(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                let mut titles =
                    std::collections::BTreeMap::<String, $crate::storage::Translations>::new();
                for row in &rows {
                    let slug: String = row.try_get("slug").map_err(get)?;
                    let language: String = row.try_get("language").map_err(get)?;
                    let title: Option<String> = row.try_get("title").map_err(get)?;
                    titles.entry(slug).or_default().insert(
                        language,
                        $crate::storage::Translation {
                            title,
                            ..Default::default()
                        },
                    );
                }
                Ok(titles)
            }
        }
    };
}

pub(in crate::storage) use text_storage;
