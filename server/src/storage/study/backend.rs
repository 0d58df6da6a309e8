//! [`super::StudyStorage`] for a backend struct with a `pool`, a
//! `classify(sqlx::Error) -> StorageError` and a `begin_write()`, as a macro
//! over the pool type (like `storage/backend.rs`).

macro_rules! study_storage {
    ($storage:ty, $db:ty) => {
        impl $storage {
            fn study_from_row(
                row: &<$db as sqlx::Database>::Row,
            ) -> $crate::storage::Result<$crate::storage::StudyRecord> {
                use sqlx::Row;
                use $crate::storage::sql::narrow;
                let get = |e: sqlx::Error| StorageError::Corrupt(e.to_string());
                let steps: String = row.try_get("steps").map_err(get)?;
                let id: i64 = row.try_get("id").map_err(get)?;
                Ok($crate::storage::StudyRecord {
                    id,
                    model_id: row.try_get("model_id").map_err(get)?,
                    slug: row.try_get("slug").map_err(get)?,
                    version: narrow(row.try_get("version").map_err(get)?, "model.version")?,
                    title: row.try_get("title").map_err(get)?,
                    transitions: serde_json::from_str(&steps).map_err(|e| {
                        StorageError::Corrupt(format!("study {id} has unreadable steps: {e}"))
                    })?,
                    state_ms: narrow(row.try_get("state_ms").map_err(get)?, "study.state_ms")?,
                    open: row.try_get::<String, _>("state").map_err(get)? == "open",
                    created_at_ms: row.try_get("created_at").map_err(get)?,
                })
            }

            fn session_from_row(
                row: &<$db as sqlx::Database>::Row,
            ) -> $crate::storage::Result<$crate::storage::SessionRecord> {
                use sqlx::Row;
                let get = |e: sqlx::Error| StorageError::Corrupt(e.to_string());
                let plan: String = row.try_get("plan").map_err(get)?;
                let id: i64 = row.try_get("id").map_err(get)?;
                Ok($crate::storage::SessionRecord {
                    id,
                    participant: row.try_get("pseudonym").map_err(get)?,
                    plan: serde_json::from_str(&plan).map_err(|e| {
                        StorageError::Corrupt(format!(
                            "study session {id} has an unreadable plan: {e}"
                        ))
                    })?,
                    device: row.try_get("device").map_err(get)?,
                    started_at_ms: row.try_get("started_at").map_err(get)?,
                    finished_at_ms: row.try_get("finished_at").map_err(get)?,
                    requests: row.try_get("requests").map_err(get)?,
                    source: row.try_get("source").map_err(get)?,
                })
            }

            fn answer_from_row(
                row: &<$db as sqlx::Database>::Row,
            ) -> $crate::storage::Result<(i64, $crate::storage::AnswerRecord)> {
                use sqlx::Row;
                use $crate::storage::sql::narrow;
                let get = |e: sqlx::Error| StorageError::Corrupt(e.to_string());
                let improvement: String = row.try_get("improvement").map_err(get)?;
                let shown_from: Option<i64> = row.try_get("shown_from_ms").map_err(get)?;
                let shown_to: Option<i64> = row.try_get("shown_to_ms").map_err(get)?;
                let shown_ms = match (shown_from, shown_to) {
                    (Some(a), Some(b)) => {
                        Some((narrow(a, "shown_from_ms")?, narrow(b, "shown_to_ms")?))
                    }
                    _ => None,
                };
                let answer = $crate::storage::AnswerRecord {
                    judgement: $crate::study::Judgement {
                        step: narrow(row.try_get("step").map_err(get)?, "study_answer.step")?,
                        from: narrow(row.try_get("from_level").map_err(get)?, "from_level")?,
                        to: narrow(row.try_get("to_level").map_err(get)?, "to_level")?,
                        control: row.try_get("control").map_err(get)?,
                        improvement: $crate::study::Improvement::parse(&improvement).ok_or_else(
                            || StorageError::Corrupt(format!("improvement {improvement:?}")),
                        )?,
                        sufficient: row.try_get("sufficient").map_err(get)?,
                    },
                    shown_ms,
                    answered_at_ms: row.try_get("answered_at").map_err(get)?,
                };
                Ok((row.try_get("session_id").map_err(get)?, answer))
            }

            async fn study_where(
                &self,
                filter: &'static str,
                key: impl for<'q> sqlx::Encode<'q, $db> + sqlx::Type<$db> + Send + 'static,
            ) -> $crate::storage::Result<Option<$crate::storage::StudyRecord>> {
                use $crate::storage::study::sql::STUDY_SELECT;
                let sql = format!("{STUDY_SELECT}{filter}");
                let row = sqlx::query(&sql)
                    .bind(key)
                    .fetch_optional(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                row.map(|r| Self::study_from_row(&r)).transpose()
            }

            async fn session_where(
                &self,
                filter: &'static str,
                key: i64,
            ) -> $crate::storage::Result<Option<$crate::storage::SessionRecord>> {
                use $crate::storage::study::sql::SESSION_SELECT;
                let sql = format!("{SESSION_SELECT}{filter}");
                let row = sqlx::query(&sql)
                    .bind(key)
                    .fetch_optional(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                row.map(|r| Self::session_from_row(&r)).transpose()
            }

            /// A unique violation is the caller's conflict, said in `what`.
            fn conflict(what: String) -> impl Fn(sqlx::Error) -> StorageError {
                move |e| match &e {
                    sqlx::Error::Database(d) if d.is_unique_violation() => {
                        StorageError::Conflict(what.clone())
                    }
                    _ => Self::classify(e),
                }
            }
        }

        #[async_trait::async_trait]
        impl $crate::storage::StudyStorage for $storage {
            async fn current_study(
                &self,
                slug: &str,
            ) -> $crate::storage::Result<Option<$crate::storage::StudyRecord>> {
                self.study_where($crate::storage::study::sql::CURRENT_STUDY, slug.to_owned())
                    .await
            }

            async fn create_study(
                &self,
                model_id: i64,
                transitions: &[$crate::study::Transition],
                state_ms: u64,
            ) -> $crate::storage::Result<i64> {
                let steps = serde_json::to_string(transitions)
                    .map_err(|e| StorageError::Corrupt(e.to_string()))?;
                sqlx::query_scalar($crate::storage::study::sql::INSERT_STUDY)
                    .bind(model_id)
                    .bind(steps)
                    .bind(i64::try_from(state_ms).unwrap_or(i64::MAX))
                    .bind($crate::storage::now_ms())
                    .fetch_one(&self.pool)
                    .await
                    .map_err(Self::classify)
            }

            async fn close_study(&self, study_id: i64) -> $crate::storage::Result<()> {
                sqlx::query($crate::storage::study::sql::CLOSE_STUDY)
                    .bind(study_id)
                    .bind($crate::storage::now_ms())
                    .execute(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                Ok(())
            }

            async fn insert_invitations(
                &self,
                study_id: i64,
                digests: &[String],
                expires_at_ms: Option<i64>,
            ) -> $crate::storage::Result<()> {
                let mut tx = self.begin_write().await?;
                let now = $crate::storage::now_ms();
                for digest in digests {
                    sqlx::query($crate::storage::study::sql::INSERT_INVITATION)
                        .bind(study_id)
                        .bind(digest.clone())
                        .bind(expires_at_ms)
                        .bind(now)
                        .execute(&mut *tx)
                        .await
                        .map_err(Self::classify)?;
                }
                tx.commit().await.map_err(Self::classify)
            }

            async fn invitation(
                &self,
                digest: &str,
            ) -> $crate::storage::Result<Option<$crate::storage::InvitationRecord>> {
                use sqlx::Row;
                use $crate::storage::study::sql::*;
                let c = Self::classify;
                let Some(row) = sqlx::query(INVITATION)
                    .bind(digest.to_owned())
                    .fetch_optional(&self.pool)
                    .await
                    .map_err(c)?
                else {
                    return Ok(None);
                };
                let id: i64 = row.try_get("id").map_err(c)?;
                let study_id: i64 = row.try_get("study_id").map_err(c)?;
                let study = self
                    .study_where(STUDY_BY_ID, study_id)
                    .await?
                    .ok_or_else(|| {
                        StorageError::Corrupt(format!("invitation {id} has no study"))
                    })?;
                Ok(Some($crate::storage::InvitationRecord {
                    id,
                    study,
                    expires_at_ms: row.try_get("expires_at").map_err(c)?,
                    session: self.session_where(SESSION_BY_INVITATION, id).await?,
                }))
            }

            async fn start_session(
                &self,
                invitation_id: i64,
                study_id: i64,
                session: &$crate::storage::NewSession,
            ) -> $crate::storage::Result<$crate::storage::SessionRecord> {
                use $crate::storage::study::sql::*;
                let plan = serde_json::to_string(&session.plan)
                    .map_err(|e| StorageError::Corrupt(e.to_string()))?;
                let now = $crate::storage::now_ms();
                let mut tx = self.begin_write().await?;
                let participant: i64 = sqlx::query_scalar(INSERT_PARTICIPANT)
                    .bind(study_id)
                    .bind(Some(invitation_id))
                    .bind(session.pseudonym.clone())
                    .bind(Some(now))
                    .bind(now)
                    .fetch_one(&mut *tx)
                    .await
                    .map_err(Self::conflict(
                        "this invitation has started a session already".into(),
                    ))?;
                let id: i64 = sqlx::query_scalar(INSERT_SESSION)
                    .bind(participant)
                    .bind(plan)
                    .bind(Some(session.device.clone()))
                    .bind(Some(i64::from(session.viewport.0)))
                    .bind(Some(i64::from(session.viewport.1)))
                    .bind(Some(session.pixel_ratio))
                    .bind("web")
                    .bind(now)
                    .bind(None::<i64>)
                    .fetch_one(&mut *tx)
                    .await
                    .map_err(Self::classify)?;
                tx.commit().await.map_err(Self::classify)?;
                Ok($crate::storage::SessionRecord {
                    id,
                    participant: session.pseudonym.clone(),
                    plan: session.plan.clone(),
                    device: Some(session.device.clone()),
                    started_at_ms: now,
                    finished_at_ms: None,
                    requests: 0,
                    source: "web".into(),
                })
            }

            async fn answers(
                &self,
                session_id: i64,
            ) -> $crate::storage::Result<Vec<$crate::storage::AnswerRecord>> {
                use $crate::storage::study::sql::*;
                let sql = format!("{ANSWER_SELECT}{ANSWERS_OF_SESSION}");
                let rows = sqlx::query(&sql)
                    .bind(session_id)
                    .fetch_all(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                rows.iter()
                    .map(|r| Self::answer_from_row(r).map(|(_, a)| a))
                    .collect()
            }

            async fn insert_answer(
                &self,
                session_id: i64,
                answer: &$crate::storage::AnswerRecord,
            ) -> $crate::storage::Result<()> {
                let j = &answer.judgement;
                sqlx::query($crate::storage::study::sql::INSERT_ANSWER)
                    .bind(session_id)
                    .bind(i64::from(j.step))
                    .bind(i64::from(j.from))
                    .bind(i64::from(j.to))
                    .bind(j.control)
                    .bind(j.improvement.as_str())
                    .bind(j.sufficient)
                    .bind(answer.shown_ms.map(|s| s.0 as i64))
                    .bind(answer.shown_ms.map(|s| s.1 as i64))
                    .bind(answer.answered_at_ms)
                    .execute(&self.pool)
                    .await
                    .map_err(Self::conflict(format!(
                        "step {} is answered already",
                        j.step
                    )))?;
                Ok(())
            }

            async fn count_request(
                &self,
                session_id: i64,
                limit: i64,
            ) -> $crate::storage::Result<bool> {
                let done = sqlx::query($crate::storage::study::sql::COUNT_REQUEST)
                    .bind(session_id)
                    .bind(limit)
                    .execute(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                Ok(done.rows_affected() == 1)
            }

            async fn insert_views(
                &self,
                session_id: i64,
                events: &[$crate::storage::ViewEvent],
            ) -> $crate::storage::Result<()> {
                let mut tx = self.begin_write().await?;
                for e in events {
                    sqlx::query($crate::storage::study::sql::INSERT_VIEW)
                        .bind(session_id)
                        .bind(e.at_ms)
                        .bind(i64::from(e.step))
                        .bind(e.state.clone())
                        .bind(e.kind.clone())
                        .bind(e.data.clone())
                        .execute(&mut *tx)
                        .await
                        .map_err(Self::classify)?;
                }
                tx.commit().await.map_err(Self::classify)
            }

            async fn finish_session(&self, session_id: i64) -> $crate::storage::Result<()> {
                sqlx::query($crate::storage::study::sql::FINISH_SESSION)
                    .bind(session_id)
                    .bind($crate::storage::now_ms())
                    .execute(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                Ok(())
            }

            async fn study_sessions(
                &self,
                study_id: i64,
            ) -> $crate::storage::Result<
                Vec<(
                    $crate::storage::SessionRecord,
                    Vec<$crate::storage::AnswerRecord>,
                )>,
            > {
                use $crate::storage::study::sql::*;
                let c = Self::classify;
                let sql = format!("{SESSION_SELECT}{SESSIONS_OF_STUDY}");
                let rows = sqlx::query(&sql)
                    .bind(study_id)
                    .fetch_all(&self.pool)
                    .await
                    .map_err(c)?;
                let mut sessions: Vec<(_, Vec<_>)> = rows
                    .iter()
                    .map(|r| Self::session_from_row(r).map(|s| (s, Vec::new())))
                    .collect::<$crate::storage::Result<_>>()?;
                let index: std::collections::HashMap<i64, usize> = sessions
                    .iter()
                    .enumerate()
                    .map(|(k, (s, _))| (s.id, k))
                    .collect();
                let sql = format!("{ANSWER_SELECT}{ANSWERS_OF_STUDY}");
                for row in sqlx::query(&sql)
                    .bind(study_id)
                    .fetch_all(&self.pool)
                    .await
                    .map_err(c)?
                {
                    let (session, answer) = Self::answer_from_row(&row)?;
                    let k = index.get(&session).ok_or_else(|| {
                        StorageError::Corrupt(format!("answer of unknown session {session}"))
                    })?;
                    sessions[*k].1.push(answer);
                }
                Ok(sessions)
            }

            async fn study_views(
                &self,
                study_id: i64,
            ) -> $crate::storage::Result<Vec<(String, $crate::storage::ViewEvent)>> {
                use sqlx::Row;
                use $crate::storage::sql::narrow;
                let c = Self::classify;
                let rows = sqlx::query($crate::storage::study::sql::VIEWS_OF_STUDY)
                    .bind(study_id)
                    .fetch_all(&self.pool)
                    .await
                    .map_err(c)?;
                rows.iter()
                    .map(|r| {
                        Ok((
                            r.try_get("pseudonym").map_err(c)?,
                            $crate::storage::ViewEvent {
                                at_ms: r.try_get("at_ms").map_err(c)?,
                                step: narrow(r.try_get("step").map_err(c)?, "study_view.step")?,
                                state: r.try_get("state").map_err(c)?,
                                kind: r.try_get("kind").map_err(c)?,
                                data: r.try_get("data").map_err(c)?,
                            },
                        ))
                    })
                    .collect()
            }

            async fn import_sessions(
                &self,
                study_id: i64,
                sessions: &[$crate::study::csv::ImportedSession],
            ) -> $crate::storage::Result<()> {
                use $crate::storage::study::sql::*;
                let now = $crate::storage::now_ms();
                let mut tx = self.begin_write().await?;
                for s in sessions {
                    let participant: i64 = sqlx::query_scalar(INSERT_PARTICIPANT)
                        .bind(study_id)
                        .bind(None::<i64>)
                        .bind(s.participant.clone())
                        .bind(None::<i64>)
                        .bind(now)
                        .fetch_one(&mut *tx)
                        .await
                        .map_err(Self::conflict(format!(
                            "participant {:?} is in this study already",
                            s.participant
                        )))?;
                    let plan: Vec<$crate::study::Step> = s
                        .answers
                        .iter()
                        .map(|a| $crate::study::Step {
                            step: a.step,
                            from: a.from,
                            to: a.to,
                            control: a.control,
                        })
                        .collect();
                    let plan = serde_json::to_string(&plan)
                        .map_err(|e| StorageError::Corrupt(e.to_string()))?;
                    let session: i64 = sqlx::query_scalar(INSERT_SESSION)
                        .bind(participant)
                        .bind(plan)
                        .bind(None::<String>)
                        .bind(None::<i64>)
                        .bind(None::<i64>)
                        .bind(None::<f64>)
                        .bind("import")
                        .bind(now)
                        .bind(Some(now))
                        .fetch_one(&mut *tx)
                        .await
                        .map_err(Self::classify)?;
                    for j in &s.answers {
                        sqlx::query(INSERT_ANSWER)
                            .bind(session)
                            .bind(i64::from(j.step))
                            .bind(i64::from(j.from))
                            .bind(i64::from(j.to))
                            .bind(j.control)
                            .bind(j.improvement.as_str())
                            .bind(j.sufficient)
                            .bind(None::<i64>)
                            .bind(None::<i64>)
                            .bind(now)
                            .execute(&mut *tx)
                            .await
                            .map_err(Self::classify)?;
                    }
                }
                tx.commit().await.map_err(Self::classify)
            }

            async fn apply_good_enough(
                &self,
                model_id: i64,
                level: u32,
                study_id: i64,
            ) -> $crate::storage::Result<()> {
                sqlx::query($crate::storage::study::sql::APPLY_GOOD_ENOUGH)
                    .bind(model_id)
                    .bind(i64::from(level))
                    .bind(study_id)
                    .execute(&self.pool)
                    .await
                    .map_err(Self::classify)?;
                Ok(())
            }
        }
    };
}

pub(crate) use study_storage;
