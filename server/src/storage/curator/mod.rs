//! The curators' rows (issue 22): annotations, upload jobs, a model's
//! versions and thumbnails, and the up axis and bounds recorded per version.
//! Same pattern as the study: one trait, the SQL written once (`sql.rs`),
//! one macro implementing it for each backend (`backend.rs`).

mod backend;
mod rights;
pub(crate) mod sql;

pub(in crate::storage) use backend::curator_storage;
pub use rights::{parse_credit, parse_licence, Licence, Rights, LICENCES, MAX_CREDIT_BYTES};

use super::Result;
use async_trait::async_trait;
use serde::{Deserialize, Serialize};

/// Which model axis points up: `x`, `y`, `z`, `-x`, `-y` or `-z`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum UpAxis {
    #[serde(rename = "x")]
    X,
    #[serde(rename = "y")]
    Y,
    #[serde(rename = "z")]
    Z,
    #[serde(rename = "-x")]
    NegX,
    #[serde(rename = "-y")]
    NegY,
    #[serde(rename = "-z")]
    NegZ,
}

impl UpAxis {
    pub const ALL: [UpAxis; 6] = [
        UpAxis::X,
        UpAxis::Y,
        UpAxis::Z,
        UpAxis::NegX,
        UpAxis::NegY,
        UpAxis::NegZ,
    ];

    pub fn name(self) -> &'static str {
        match self {
            UpAxis::X => "x",
            UpAxis::Y => "y",
            UpAxis::Z => "z",
            UpAxis::NegX => "-x",
            UpAxis::NegY => "-y",
            UpAxis::NegZ => "-z",
        }
    }

    pub fn parse(name: &str) -> Option<UpAxis> {
        UpAxis::ALL.into_iter().find(|a| a.name() == name)
    }

    /// The rotation that stands the model upright in a +Y-up frame (glTF's,
    /// and the viewer's: `upRotation` in web/src/frame.js), as rows: world
    /// axis `r` is `rows[r] · p`. A proper rotation (determinant 1), so
    /// faces keep their winding.
    pub fn to_y_up(self) -> [[f32; 3]; 3] {
        match self {
            UpAxis::Y => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            UpAxis::NegY => [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]],
            UpAxis::Z => [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]],
            UpAxis::NegZ => [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]],
            UpAxis::X => [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
            UpAxis::NegX => [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
        }
    }

    /// The unit vector of the axis.
    pub fn vector(self) -> [f32; 3] {
        match self {
            UpAxis::X => [1.0, 0.0, 0.0],
            UpAxis::Y => [0.0, 1.0, 0.0],
            UpAxis::Z => [0.0, 0.0, 1.0],
            UpAxis::NegX => [-1.0, 0.0, 0.0],
            UpAxis::NegY => [0.0, -1.0, 0.0],
            UpAxis::NegZ => [0.0, 0.0, -1.0],
        }
    }
}

impl std::str::FromStr for UpAxis {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, String> {
        UpAxis::parse(s).ok_or_else(|| format!("{s:?} is not one of x, y, z, -x, -y, -z"))
    }
}

/// An axis-aligned box in model coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Bounds {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

impl Bounds {
    pub fn to_json(self) -> String {
        serde_json::to_string(&self).expect("finite numbers serialise")
    }

    pub fn from_json(json: &str) -> Option<Bounds> {
        serde_json::from_str(json).ok()
    }

    pub fn diagonal(&self) -> f64 {
        (0..3)
            .map(|i| (self.max[i] - self.min[i]).powi(2))
            .sum::<f64>()
            .sqrt()
    }
}

/// A stored annotation.
#[derive(Clone, Debug, PartialEq)]
pub struct AnnotationRecord {
    pub id: i64,
    pub slug: String,
    pub title: String,
    /// Markdown source.
    pub text: String,
    /// Sanitised HTML rendered from `text`.
    pub html: String,
    pub position: [f64; 3],
    /// Unit length.
    pub normal: [f64; 3],
    pub view: Option<serde_json::Value>,
    /// BCP 47 tag of the title and text, when stated.
    pub language: Option<String>,
    /// The title and text in further languages.
    pub translations: AnnotationTranslations,
    pub created_at_ms: i64,
    pub updated_at_ms: i64,
}

/// What a curator writes; validated and rendered by the service.
#[derive(Clone, Debug, PartialEq)]
pub struct NewAnnotation {
    pub title: String,
    pub text: String,
    pub html: String,
    pub position: [f64; 3],
    pub normal: [f64; 3],
    pub view: Option<serde_json::Value>,
    /// BCP 47 tag of the title and text, when stated.
    pub language: Option<String>,
    /// The title and text in further languages, rendered.
    pub translations: AnnotationTranslations,
}

/// An annotation's title and text in one further language.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, utoipa::ToSchema)]
pub struct AnnotationText {
    pub title: String,
    /// Markdown source.
    pub text: String,
    /// `text` rendered and sanitised.
    pub html: String,
}

/// Per BCP 47 tag.
pub type AnnotationTranslations = std::collections::BTreeMap<String, AnnotationText>;

/// The column's JSON; `None` (NULL) when there are none.
pub(crate) fn translations_json(t: &AnnotationTranslations) -> Option<String> {
    (!t.is_empty()).then(|| serde_json::json!(t).to_string())
}

/// Where an upload's ingest stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum JobState {
    Queued,
    Running,
    Done,
    Failed,
}

impl JobState {
    pub fn name(self) -> &'static str {
        match self {
            JobState::Queued => "queued",
            JobState::Running => "running",
            JobState::Done => "done",
            JobState::Failed => "failed",
        }
    }

    pub fn parse(name: &str) -> Option<JobState> {
        [
            JobState::Queued,
            JobState::Running,
            JobState::Done,
            JobState::Failed,
        ]
        .into_iter()
        .find(|s| s.name() == name)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct NewJob {
    pub slug: String,
    pub title: String,
    pub source_name: String,
    pub token_id: Option<i64>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct JobRecord {
    pub id: i64,
    pub slug: String,
    pub title: String,
    pub source_name: String,
    pub state: JobState,
    /// 0–1.
    pub progress: f64,
    /// What it is doing (`importing`, `encoding`, …).
    pub stage: String,
    /// The importer's or encoder's message, when failed.
    pub error: Option<String>,
    pub model_version: Option<u32>,
    pub created_at_ms: i64,
    pub updated_at_ms: i64,
}

/// One stored version of a model, whatever its status.
#[derive(Clone, Debug, PartialEq)]
pub struct VersionRecord {
    pub model_id: i64,
    pub version: u32,
    pub title: String,
    /// `ready` or `withdrawn`.
    pub status: String,
    pub policy: String,
    pub good_enough_level: Option<u32>,
    /// Levels including the base (of its newest compression).
    pub levels: u32,
    pub created_at_ms: i64,
    /// Credit line and licence.
    pub rights: Rights,
}

/// A version's thumbnail.
#[derive(Clone, Debug)]
pub struct ThumbnailPayload {
    pub media_type: String,
    pub sha256: String,
    pub bytes: Vec<u8>,
}

/// Every method has a default that refuses, for storages without these
/// tables (the service tests' doubles); both backends implement them all.
#[allow(unused_variables)] // the defaults ignore their arguments; the names document them
#[async_trait]
pub trait CuratorStorage: Send + Sync {
    /// The model's annotations, oldest first.
    async fn annotations(&self, slug: &str) -> Result<Vec<AnnotationRecord>> {
        no_curators()
    }

    async fn insert_annotation(&self, slug: &str, a: &NewAnnotation) -> Result<AnnotationRecord> {
        no_curators()
    }

    /// `None` when the slug has no annotation `id`.
    async fn update_annotation(
        &self,
        slug: &str,
        id: i64,
        a: &NewAnnotation,
    ) -> Result<Option<AnnotationRecord>> {
        no_curators()
    }

    /// Adds every one of `annotations` in one transaction, or none of them;
    /// answers how many were added.
    async fn insert_annotations(&self, slug: &str, annotations: &[NewAnnotation]) -> Result<usize> {
        no_curators()
    }

    /// `false` when the slug has no annotation `id`.
    async fn delete_annotation(&self, slug: &str, id: i64) -> Result<bool> {
        no_curators()
    }

    async fn insert_job(&self, job: &NewJob) -> Result<JobRecord> {
        no_curators()
    }

    /// Records a job's progress or end; `version` once done, `error` once failed.
    async fn update_job(
        &self,
        id: i64,
        state: JobState,
        progress: f64,
        stage: &str,
        error: Option<&str>,
        version: Option<u32>,
    ) -> Result<()> {
        no_curators()
    }

    /// The running instance's heartbeat for a queued or running job: its
    /// `updated_at` becomes now (an ended job is left as it is).
    async fn touch_job(&self, id: i64) -> Result<()> {
        no_curators()
    }

    async fn job(&self, id: i64) -> Result<Option<JobRecord>> {
        no_curators()
    }

    /// The newest `limit` jobs, newest first.
    async fn jobs(&self, limit: u32) -> Result<Vec<JobRecord>> {
        no_curators()
    }

    /// Every version of the slug, newest first.
    async fn versions(&self, slug: &str) -> Result<Vec<VersionRecord>> {
        no_curators()
    }

    /// Sets a version's status (`ready` or `withdrawn`); `false` if no such version.
    async fn set_version_status(&self, slug: &str, version: u32, status: &str) -> Result<bool> {
        no_curators()
    }

    /// Sets a version's credit line and licence (either may be cleared);
    /// `false` if no such version.
    async fn set_version_rights(&self, slug: &str, version: u32, rights: &Rights) -> Result<bool> {
        no_curators()
    }

    /// Sets (or clears, with `None`) a version's good-enough level.
    async fn set_good_enough_level(
        &self,
        slug: &str,
        version: u32,
        level: Option<u32>,
    ) -> Result<bool> {
        no_curators()
    }

    async fn thumbnail(&self, model_id: i64) -> Result<Option<ThumbnailPayload>> {
        no_curators()
    }
}

fn no_curators<T>() -> Result<T> {
    Err(super::StorageError::Unknown(
        "this storage keeps no annotations, jobs or thumbnails".into(),
    ))
}

#[cfg(test)]
mod tests {
    use super::UpAxis;

    #[test]
    fn every_up_axis_turns_to_plus_y_by_a_rotation() {
        for axis in UpAxis::ALL {
            let r = axis.to_y_up();
            let v = axis.vector();
            let turned: Vec<f32> = r
                .iter()
                .map(|row| row.iter().zip(v).map(|(a, b)| a * b).sum())
                .collect();
            assert_eq!(turned, [0.0, 1.0, 0.0], "{axis:?}");
            let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
                - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
                + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
            assert_eq!(det, 1.0, "{axis:?}");
        }
    }
}
