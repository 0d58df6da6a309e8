//! Upload ingests as background jobs. Each job's state (queued, running
//! with a progress and a stage label, done, failed with the importer's
//! message) is a database row, so it survives the client leaving and any
//! instance can report it. The ingest runs in a tokio task of its own (the
//! encoder in `spawn_blocking`), at most `concurrent_jobs` at once; up to
//! `max_queued` more wait, and beyond that an upload is refused with 429.
//!
//! While a job waits or runs, its instance touches the row every
//! [`HEARTBEAT`]; a queued or running job untouched for [`STALE_AFTER`] is
//! served as failed ("interrupted"), so a curator whose server stopped
//! mid-ingest learns it from any instance instead of watching a bar that
//! never moves. The row itself is left as it is: reads decide, so no
//! instance has to tell a slow one from a dead one.

use super::Curator;
use crate::ingest::points::{detect_kind, ingest_points, load_cloud};
use crate::ingest::{ingest_coloured, IngestOptions, ModelMeta, ProgressHook, SourceInfo};
use crate::service::error::{AppError, ErrorBody};
use crate::service::servable::PathParams;
use crate::service::AppState;
use crate::source::load_coloured_frame;
use crate::storage::{JobRecord, JobState, ModelKind};
use axum::extract::State;
use axum::Json;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;
use tempfile::TempPath;
use tokio::sync::Semaphore;
use utoipa::{IntoParams, ToSchema};

/// Jobs `GET /api/jobs` lists.
const LISTED_JOBS: u32 = 50;

/// How often an instance touches the jobs it holds.
pub const HEARTBEAT: Duration = Duration::from_secs(10);

/// A queued or running job untouched this long is served as interrupted:
/// six heartbeats, so a busy database or a long encode step (which
/// reports no progress for a while) is not mistaken for a dead server.
pub const STALE_AFTER: Duration = Duration::from_secs(60);

/// What a stale job's `error` says.
pub const INTERRUPTED: &str = "interrupted: the server running this upload stopped \
     (no heartbeat for 60 s); upload the file again";

/// The runner every instance has.
pub struct JobRunner {
    permits: Arc<Semaphore>,
    waiting: Arc<AtomicUsize>,
    max_queued: usize,
}

impl JobRunner {
    pub fn new(concurrent: usize, max_queued: usize) -> JobRunner {
        JobRunner {
            permits: Arc::new(Semaphore::new(concurrent.max(1))),
            waiting: Arc::new(AtomicUsize::new(0)),
            max_queued,
        }
    }

    /// Takes a place in the queue, or `None` when it is full.
    pub fn reserve(&self) -> Option<QueuePlace> {
        let waiting = self.waiting.fetch_add(1, Ordering::SeqCst);
        let place = QueuePlace(self.waiting.clone());
        (waiting < self.max_queued).then_some(place)
    }
}

/// A place in the queue, given back when dropped.
pub struct QueuePlace(Arc<AtomicUsize>);

impl Drop for QueuePlace {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

/// What the job ingests.
pub struct JobInput {
    pub file: TempPath,
    pub meta: ModelMeta,
    pub options: IngestOptions,
    /// As the form asked; `None`: from the file.
    pub kind: Option<ModelKind>,
}

/// Runs the job in the background; the request that made it may go.
pub fn spawn(state: AppState, job: JobRecord, place: QueuePlace, input: JobInput) {
    tokio::spawn(async move {
        let heartbeat = tokio::spawn(beat(state.storage().clone(), job.id));
        let permit = state.jobs().permits.clone().acquire_owned().await;
        drop(place);
        let outcome = match permit {
            Ok(_permit) => run(&state, &job, input).await,
            Err(_) => Err(anyhow::anyhow!("the job runner stopped")),
        };
        heartbeat.abort();
        let storage = state.storage();
        let written = match outcome {
            Ok(version) => {
                state.invalidate();
                tracing::info!(job = job.id, slug = %job.slug, version, "upload ingested");
                storage
                    .update_job(job.id, JobState::Done, 1.0, "done", None, Some(version))
                    .await
            }
            Err(e) => {
                let message = format!("{e:#}");
                tracing::info!(job = job.id, slug = %job.slug, error = %message, "upload failed");
                storage
                    .update_job(
                        job.id,
                        JobState::Failed,
                        1.0,
                        "failed",
                        Some(&message),
                        None,
                    )
                    .await
            }
        };
        if let Err(e) = written {
            tracing::warn!(job = job.id, error = %e, "could not record the job's end");
        }
    });
}

/// Touches job `id` every [`HEARTBEAT`] until aborted.
async fn beat(storage: Arc<dyn crate::storage::Storage>, id: i64) {
    let mut every = tokio::time::interval(HEARTBEAT);
    every.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    every.tick().await; // the first tick is immediate; the row is new
    loop {
        every.tick().await;
        if let Err(e) = storage.touch_job(id).await {
            tracing::warn!(job = id, error = %e, "could not record the job's heartbeat");
        }
    }
}

/// Imports, encodes, measures and stores; the new version's number. Every
/// progress row is written before this returns, so none lands after the end.
async fn run(state: &AppState, job: &JobRecord, input: JobInput) -> anyhow::Result<u32> {
    let storage = state.storage().clone();
    // Progress goes through a channel so that its rows are written in order.
    let (tx, mut rx) = tokio::sync::mpsc::unbounded_channel::<(&'static str, f64)>();
    let id = job.id;
    let writer = {
        let storage = storage.clone();
        tokio::spawn(async move {
            while let Some((stage, done)) = rx.recv().await {
                if let Err(e) = storage
                    .update_job(id, JobState::Running, done, stage, None, None)
                    .await
                {
                    tracing::warn!(job = id, error = %e, "could not record progress");
                }
            }
        })
    };
    let hook = ProgressHook(Arc::new(move |stage: &'static str, done: f64| {
        let _ = tx.send((stage, done));
    }));
    let result = ingest_upload(&*storage, job, input, hook).await;
    // The hook (the channel's last sender) is gone with the ingest's options.
    let _ = writer.await;
    result
}

async fn ingest_upload(
    storage: &dyn crate::storage::Storage,
    job: &JobRecord,
    input: JobInput,
    hook: ProgressHook,
) -> anyhow::Result<u32> {
    (hook.0)("importing", 0.05);
    let JobInput {
        file,
        mut meta,
        mut options,
        kind,
    } = input;
    let source_name = job.source_name.clone();
    let spooled = file.to_string_lossy().into_owned();
    let shown = source_name.clone();
    let detected = detect_kind(&file)?;
    match kind.unwrap_or(detected) {
        ModelKind::Points => {
            let cloud = tokio::task::spawn_blocking(move || {
                let cloud = load_cloud(&file);
                drop(file);
                cloud.map_err(|e| anyhow::anyhow!(format!("{e:#}").replace(&spooled, &shown)))
            })
            .await??;
            meta.source = Some(SourceInfo {
                name: source_name,
                vertices: cloud.len() as u64,
                faces: 0,
                repair: None,
            });
            options.progress = Some(hook);
            let report = ingest_points(storage, cloud, meta, &options).await?;
            return Ok(report.stored.version);
        }
        ModelKind::Mesh if detected == ModelKind::Points => {
            anyhow::bail!(
                "{source_name} is a point cloud (no faces): it cannot be stored as a mesh \
                 (leave `kind` out, or send `points`)"
            );
        }
        ModelKind::Mesh => {}
    }
    let source = tokio::task::spawn_blocking(move || {
        let source = load_coloured_frame(&file, 0);
        drop(file); // the spooled upload is removed once read
                    // The importer's message names the file as the curator sent it,
                    // not the spool file.
        source.map_err(|e| anyhow::anyhow!(format!("{e:#}").replace(&spooled, &shown)))
    })
    .await??;
    meta.source = Some(SourceInfo {
        name: source_name,
        vertices: source.imported_vertices as u64,
        faces: source.imported_faces as u64,
        repair: Some(source.repair.to_string()),
    });
    options.progress = Some(hook);
    let report = ingest_coloured(storage, source.mesh, source.texture, meta, &options).await?;
    Ok(report.stored.version)
}

/// A job as served.
#[derive(Serialize, ToSchema)]
pub struct Job {
    id: i64,
    slug: String,
    title: String,
    /// The uploaded file's name as sent (never used as a path).
    source_name: String,
    state: JobState,
    /// 0–1.
    progress: f64,
    /// What it is doing: `queued`, `importing`, `estimating normals` (a
    /// point cloud), `encoding`, `measuring`,
    /// `rendering the thumbnail`, `storing`, `done` or `failed`.
    stage: String,
    /// The importer's or encoder's message, when failed.
    error: Option<String>,
    /// The version it stored, when done.
    model_version: Option<u32>,
    /// The manifest, when done.
    model_url: Option<String>,
    status_url: String,
    /// Unix milliseconds.
    created_at: i64,
    updated_at: i64,
}

impl Job {
    /// `j` as served at `now_ms`: failed when it has been queued or
    /// running without a heartbeat for [`STALE_AFTER`].
    fn served(mut j: JobRecord, now_ms: i64) -> Job {
        let waiting = matches!(j.state, JobState::Queued | JobState::Running);
        if waiting && now_ms - j.updated_at_ms > STALE_AFTER.as_millis() as i64 {
            j.state = JobState::Failed;
            j.stage = "failed".into();
            j.error = Some(INTERRUPTED.into());
        }
        Job::from(j)
    }
}

impl From<JobRecord> for Job {
    fn from(j: JobRecord) -> Self {
        Job {
            model_url: (j.state == JobState::Done).then(|| format!("/api/models/{}", j.slug)),
            status_url: format!("/api/jobs/{}", j.id),
            id: j.id,
            slug: j.slug,
            title: j.title,
            source_name: j.source_name,
            state: j.state,
            progress: j.progress,
            stage: j.stage,
            error: j.error,
            model_version: j.model_version,
            created_at: j.created_at_ms,
            updated_at: j.updated_at_ms,
        }
    }
}

#[derive(Serialize, ToSchema)]
pub struct JobList {
    /// The newest 50, newest first.
    jobs: Vec<Job>,
}

#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct JobPath {
    id: i64,
}

/// Recent upload jobs (curator token).
#[utoipa::path(
    get,
    path = "/api/jobs",
    security(("bearer" = [])),
    responses(
        (status = 200, description = "Jobs, newest first", body = JobList),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token", body = ErrorBody),
    )
)]
pub async fn list(State(state): State<AppState>, _: Curator) -> Result<Json<JobList>, AppError> {
    let jobs = state.storage().jobs(LISTED_JOBS).await?;
    let now = crate::storage::now_ms();
    Ok(Json(JobList {
        jobs: jobs.into_iter().map(|j| Job::served(j, now)).collect(),
    }))
}

/// One upload job (curator token).
#[utoipa::path(
    get,
    path = "/api/jobs/{id}",
    params(JobPath),
    security(("bearer" = [])),
    responses(
        (status = 200, description = "The job", body = Job),
        (status = 400, description = "Malformed id", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token", body = ErrorBody),
        (status = 404, description = "No such job", body = ErrorBody),
    )
)]
pub async fn job(
    State(state): State<AppState>,
    _: Curator,
    PathParams(JobPath { id }): PathParams<JobPath>,
) -> Result<Json<Job>, AppError> {
    let job = state.storage().job(id).await?;
    let job = job.ok_or(AppError::NotFound("job"))?;
    Ok(Json(Job::served(job, crate::storage::now_ms())))
}
