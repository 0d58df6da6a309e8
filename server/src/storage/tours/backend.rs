//! [`super::TourStorage`] for a backend struct with a `pool` and a
//! `classify(sqlx::Error) -> StorageError`, as a macro over the pool type
//! (like `storage/curator/backend.rs`).

macro_rules! tour_storage {
    ($storage:ty, $db:ty) => {
        impl $storage {
            fn tour_from_row(
                row: &<$db as sqlx::Database>::Row,
            ) -> $crate::storage::Result<$crate::storage::TourRecord> {
                use sqlx::Row;
                use $crate::storage::sql::narrow;
                let get = |e: sqlx::Error| StorageError::Corrupt(e.to_string());
                let id: i64 = row.try_get("id").map_err(get)?;
                let unreadable = |what: &str, e: serde_json::Error| {
                    StorageError::Corrupt(format!("tour {id} has an unreadable {what}: {e}"))
                };
                let title: String = row.try_get("title").map_err(get)?;
                let steps: String = row.try_get("steps").map_err(get)?;
                let version: i64 = row.try_get("model_version").map_err(get)?;
                Ok($crate::storage::TourRecord {
                    id,
                    slug: row.try_get("model_slug").map_err(get)?,
                    version: narrow(version, "tour.model_version")?,
                    title: serde_json::from_str(&title).map_err(|e| unreadable("title", e))?,
                    steps: serde_json::from_str(&steps).map_err(|e| unreadable("step list", e))?,
                    created_at_ms: row.try_get("created_at").map_err(get)?,
                    updated_at_ms: row.try_get("updated_at").map_err(get)?,
                })
            }

            async fn tour_by_id(
                &self,
                slug: &str,
                id: i64,
            ) -> $crate::storage::Result<Option<$crate::storage::TourRecord>> {
                let row = sqlx::query(&$crate::storage::tours::sql::tour())
                    .bind(slug.to_owned())
                    .bind(id)
                    .fetch_optional(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                row.as_ref().map(Self::tour_from_row).transpose()
            }
        }

        #[async_trait::async_trait]
        impl $crate::storage::TourStorage for $storage {
            async fn tours(
                &self,
                slug: &str,
                version: Option<u32>,
            ) -> $crate::storage::Result<Vec<$crate::storage::TourRecord>> {
                let sql = $crate::storage::tours::sql::tours(version.is_some());
                let mut query = sqlx::query(&sql).bind(slug.to_owned());
                if let Some(version) = version {
                    query = query.bind(i64::from(version));
                }
                let rows = query.fetch_all(&self.pool).await.map_err(Self::classify)?;
                rows.iter().map(Self::tour_from_row).collect()
            }

            async fn insert_tour(
                &self,
                slug: &str,
                tour: &$crate::storage::NewTour,
            ) -> $crate::storage::Result<$crate::storage::TourRecord> {
                let id: i64 = sqlx::query_scalar($crate::storage::tours::sql::INSERT_TOUR)
                    .bind(slug.to_owned())
                    .bind(i64::from(tour.version))
                    .bind(serde_json::json!(tour.title).to_string())
                    .bind(serde_json::json!(tour.steps).to_string())
                    .bind($crate::storage::now_ms())
                    .fetch_one(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                self.tour_by_id(slug, id).await?.ok_or_else(|| {
                    StorageError::Corrupt(format!("tour {id} vanished after insert"))
                })
            }

            async fn update_tour(
                &self,
                slug: &str,
                id: i64,
                tour: &$crate::storage::NewTour,
            ) -> $crate::storage::Result<Option<$crate::storage::TourRecord>> {
                let done = sqlx::query($crate::storage::tours::sql::UPDATE_TOUR)
                    .bind(slug.to_owned())
                    .bind(id)
                    .bind(i64::from(tour.version))
                    .bind(serde_json::json!(tour.title).to_string())
                    .bind(serde_json::json!(tour.steps).to_string())
                    .bind($crate::storage::now_ms())
                    .execute(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                if done.rows_affected() == 0 {
                    return Ok(None);
                }
                self.tour_by_id(slug, id).await
            }

            async fn delete_tour(&self, slug: &str, id: i64) -> $crate::storage::Result<bool> {
                let done = sqlx::query($crate::storage::tours::sql::DELETE_TOUR)
                    .bind(slug.to_owned())
                    .bind(id)
                    .execute(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                Ok(done.rows_affected() > 0)
            }
        }
    };
}

pub(in crate::storage) use tour_storage;
