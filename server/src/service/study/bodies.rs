//! What the study page sends and receives, and the checks on what it sends.

use super::super::cap::DeviceClass;
use super::super::error::AppError;
use crate::storage::ViewEvent;
use crate::study::{Improvement, Step};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

/// View events one request may carry.
pub const MAX_EVENTS_PER_BATCH: usize = 200;
/// Latest `at_ms` accepted: a day, far past any session.
const MAX_AT_MS: f64 = 86_400_000.0;

/// `GET /api/study/{slug}`: what the information page needs.
#[derive(Serialize, ToSchema)]
pub struct StudyInfo {
    pub slug: String,
    pub title: String,
    pub version: u32,
    /// `open`.
    pub state: &'static str,
    /// T: each state is shown at least this long.
    pub seconds: f64,
    /// Steps a session has: the transitions plus the control step.
    pub step_count: u32,
    pub last_level: u32,
    /// `valid` (not started), `started` or `finished`.
    pub invitation: &'static str,
}

/// `POST /api/study/{slug}/session`: consent and the device.
#[derive(Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct StartBody {
    /// Must be `true`: nothing is stored without consent.
    pub consent: bool,
    #[schema(value_type = DeviceClass)]
    pub device: String,
    /// CSS pixels, `[width, height]`.
    pub viewport: [u32; 2],
    pub pixel_ratio: f64,
}

impl StartBody {
    pub fn check(&self) -> Result<DeviceClass, AppError> {
        if !self.consent {
            return Err(AppError::Unprocessable(
                "consent must be true: nothing is stored without it".into(),
            ));
        }
        let device = DeviceClass::parse(&self.device).ok_or_else(|| {
            AppError::Unprocessable(format!(
                "device must be phone, tablet or desktop, not {:?}",
                self.device
            ))
        })?;
        if self.viewport.iter().any(|&s| s == 0 || s > 16_384) {
            return Err(AppError::Unprocessable(
                "viewport sides must be 1 to 16384 pixels".into(),
            ));
        }
        if !(self.pixel_ratio > 0.0 && self.pixel_ratio <= 16.0) {
            return Err(AppError::Unprocessable(
                "pixel_ratio must be above 0 and at most 16".into(),
            ));
        }
        Ok(device)
    }
}

/// A session's plan and progress.
#[derive(Serialize, ToSchema)]
pub struct Plan {
    pub slug: String,
    pub version: u32,
    /// The participant's pseudonym.
    pub participant: String,
    pub seconds: f64,
    pub last_level: u32,
    pub steps: Vec<Step>,
    pub answered: Vec<u32>,
    /// `null` once every step is answered.
    pub next_step: Option<u32>,
    pub finished: bool,
}

/// `PUT /api/study/{slug}/session/answers/{step}`.
#[derive(Deserialize, PartialEq, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct AnswerBody {
    /// Q1, "Did you perceive an improvement during this step?"
    pub improvement: Improvement,
    /// Q2, "Is this quality sufficient?"
    pub sufficient: bool,
    /// How long the page showed m_a and m_b, in milliseconds.
    pub shown_ms: [u64; 2],
}

#[derive(Serialize, ToSchema)]
pub struct AnswerReceipt {
    pub step: u32,
    pub next_step: Option<u32>,
}

/// `POST /api/study/{slug}/session/views`.
#[derive(Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ViewBatch {
    pub events: Vec<ViewEventBody>,
}

#[derive(Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ViewEventBody {
    /// Milliseconds since the page started the session.
    pub at_ms: f64,
    /// The step on screen (0 before the first).
    pub step: u32,
    /// `info`, `practice`, `original`, `pre`, `transition`, `post` or `answer`.
    pub state: String,
    /// `camera`, `state` or `interaction`.
    pub kind: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera: Option<CameraBody>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zoom: Option<f64>,
    /// `orbit`, `pan`, `zoom`, `pinch` or `key`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interaction: Option<String>,
}

#[derive(Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct CameraBody {
    pub eye: [f64; 3],
    pub target: [f64; 3],
    pub up: [f64; 3],
    /// Vertical field of view, degrees.
    pub fov: f64,
}

const STATES: [&str; 7] = [
    "info",
    "practice",
    "original",
    "pre",
    "transition",
    "post",
    "answer",
];
const KINDS: [&str; 3] = ["camera", "state", "interaction"];
const INTERACTIONS: [&str; 5] = ["orbit", "pan", "zoom", "pinch", "key"];

impl ViewBatch {
    /// The events as stored, or why the whole batch is refused.
    pub fn check(self, steps: u32) -> Result<Vec<ViewEvent>, AppError> {
        if self.events.len() > MAX_EVENTS_PER_BATCH {
            return Err(AppError::PayloadTooLarge);
        }
        self.events
            .into_iter()
            .enumerate()
            .map(|(k, e)| {
                e.check(steps)
                    .map_err(|m| AppError::Unprocessable(format!("event {k}: {m}")))
            })
            .collect()
    }
}

impl ViewEventBody {
    fn check(self, steps: u32) -> Result<ViewEvent, String> {
        if !(self.at_ms.is_finite() && (0.0..=MAX_AT_MS).contains(&self.at_ms)) {
            return Err(format!("at_ms must be 0 to {MAX_AT_MS}"));
        }
        if self.step > steps {
            return Err(format!("step {} is past the plan's {steps}", self.step));
        }
        if !STATES.contains(&self.state.as_str()) {
            return Err(format!("state must be one of {}", STATES.join(", ")));
        }
        if !KINDS.contains(&self.kind.as_str()) {
            return Err(format!("kind must be one of {}", KINDS.join(", ")));
        }
        if let Some(i) = &self.interaction {
            if !INTERACTIONS.contains(&i.as_str()) {
                return Err(format!(
                    "interaction must be one of {}",
                    INTERACTIONS.join(", ")
                ));
            }
        }
        if let Some(c) = &self.camera {
            let finite = c
                .eye
                .iter()
                .chain(&c.target)
                .chain(&c.up)
                .all(|v| v.is_finite() && v.abs() < 1e9);
            if !(finite && c.fov > 0.0 && c.fov < 180.0) {
                return Err("camera vectors must be finite and fov between 0 and 180".into());
            }
        }
        if self.zoom.is_some_and(|z| !(z.is_finite() && z > 0.0)) {
            return Err("zoom must be positive".into());
        }
        let data = serde_json::json!({
            "camera": self.camera,
            "zoom": self.zoom,
            "interaction": self.interaction,
        });
        Ok(ViewEvent {
            at_ms: self.at_ms,
            step: self.step,
            state: self.state,
            kind: self.kind,
            data: data.to_string(),
        })
    }
}

/// `POST /api/study/{slug}/session/finish`.
#[derive(Serialize, ToSchema)]
pub struct Finished {
    /// The session's good level (`null`: no level was judged sufficient to the end).
    pub good_level: Option<u32>,
}

/// `GET /api/study/{slug}/results`: the share of "sufficient" per level.
#[derive(Serialize, ToSchema)]
pub struct StudyResults {
    pub valid_sessions: usize,
    pub levels: Vec<LevelShare>,
}

#[derive(Serialize, ToSchema)]
pub struct LevelShare {
    pub level: u32,
    /// Answers about this level (steps that ended on it) in valid sessions.
    pub answers: u32,
    /// Of which "sufficient".
    pub sufficient: u32,
}
