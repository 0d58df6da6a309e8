//! What a curator sends for a tour, and its checks: a title and 1–50 steps,
//! each a saved view (the viewer's share-link fragment,
//! `web/src/view-state.js`, which must place the camera) with a title and
//! Markdown text per language. Limits are documented in the OpenAPI
//! description and the README; refusals name the step and the field.

use crate::service::curator::annotations::parse_language;
use crate::service::curator::markdown;
use crate::storage::{LanguageMap, NewTour, TourStep};
use serde::Deserialize;
use std::collections::BTreeMap;
use utoipa::ToSchema;

/// Most steps in a tour.
pub const MAX_STEPS: usize = 50;
/// Longest title (a tour's or a step's), in characters, per language.
pub const MAX_TITLE_CHARS: usize = 200;
/// Longest step text (Markdown source), in characters, per language.
pub const MAX_TEXT_CHARS: usize = 10_000;
/// Most languages in one title or text.
pub const MAX_LANGUAGES: usize = 12;
/// Longest saved view (the fragment), in bytes (the viewer reads at most 2,048).
pub const MAX_VIEW_BYTES: usize = 2_048;
/// Largest request body of a tour write (the guard refuses more with 413).
pub const MAX_TOUR_BYTES: usize = 1 << 20;

/// A tour to create or replace; the steps' order is the tour's.
#[derive(Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct TourInput {
    /// Title per BCP 47 language tag (`{"en": "…", "pt": "…"}`): at least
    /// one, each 1–200 characters.
    #[schema(value_type = Object)]
    pub title: BTreeMap<String, String>,
    /// 1–50 steps, in the order they are played.
    pub steps: Vec<TourStepInput>,
    /// The model version the views were recorded on; absent: the version
    /// served now.
    #[serde(default)]
    pub version: Option<u32>,
}

/// One step of a tour.
#[derive(Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct TourStepInput {
    /// The share-link fragment of the view, at most 2,048 bytes, with a
    /// `camera` (`camera=tx,ty,tz,distance,yaw,pitch&light=…&section=…&note=…&measure=…`).
    pub view: String,
    /// Title per language, 1–200 characters each; at least one.
    #[schema(value_type = Object)]
    pub title: BTreeMap<String, String>,
    /// Markdown text per language, at most 10,000 characters each.
    #[serde(default)]
    #[schema(value_type = Object)]
    pub text: BTreeMap<String, String>,
}

impl TourInput {
    /// The tour to store for `version` (the one served when the input names none).
    pub fn checked(self, served: u32) -> Result<NewTour, String> {
        let title = titles(self.title, "title")?;
        if self.steps.is_empty() {
            return Err("a tour needs at least one step".into());
        }
        if self.steps.len() > MAX_STEPS {
            return Err(format!("a tour has at most {MAX_STEPS} steps"));
        }
        let steps = self
            .steps
            .into_iter()
            .enumerate()
            .map(|(k, step)| step.checked().map_err(|e| format!("step {}: {e}", k + 1)))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(NewTour {
            version: self.version.unwrap_or(served),
            title,
            steps,
        })
    }
}

impl TourStepInput {
    fn checked(self) -> Result<TourStep, String> {
        check_view(&self.view)?;
        let title = titles(self.title, "title")?;
        let text = texts(self.text)?;
        let html = text
            .iter()
            .map(|(language, source)| (language.clone(), markdown::render(source)))
            .collect();
        Ok(TourStep {
            view: self.view,
            title,
            text,
            html,
        })
    }
}

/// Language tags checked, values trimmed, empty ones dropped.
fn language_map(
    map: BTreeMap<String, String>,
    what: &str,
    limit: usize,
) -> Result<LanguageMap, String> {
    if map.len() > MAX_LANGUAGES {
        return Err(format!("{what} has more than {MAX_LANGUAGES} languages"));
    }
    let mut out = LanguageMap::new();
    for (tag, value) in map {
        let tag = parse_language(tag.trim())?;
        let value = value.trim().to_owned();
        if value.chars().count() > limit {
            return Err(format!(
                "{what} in {tag:?} is longer than {limit} characters"
            ));
        }
        if !value.is_empty() {
            out.insert(tag, value);
        }
    }
    Ok(out)
}

fn titles(map: BTreeMap<String, String>, what: &str) -> Result<LanguageMap, String> {
    let out = language_map(map, what, MAX_TITLE_CHARS)?;
    if out.is_empty() {
        return Err(format!("{what} needs a text in at least one language"));
    }
    Ok(out)
}

fn texts(map: BTreeMap<String, String>) -> Result<LanguageMap, String> {
    language_map(map, "text", MAX_TEXT_CHARS)
}

/// The fields of a saved view and how many numbers each holds (`section`
/// and `note` are not numbers: `x|y|z,fraction,0|1` and an annotation id).
const VIEW_FIELDS: [(&str, usize); 5] = [
    ("camera", 6),
    ("light", 4),
    ("measure", 6),
    ("section", 3),
    ("note", 1),
];

/// A saved view as the viewer writes it: known fields, finite numbers, a camera.
pub fn check_view(view: &str) -> Result<(), String> {
    if view.len() > MAX_VIEW_BYTES {
        return Err(format!("view is longer than {MAX_VIEW_BYTES} bytes"));
    }
    let mut camera = false;
    for field in view.split('&').filter(|f| !f.is_empty()) {
        let (name, value) = field
            .split_once('=')
            .ok_or_else(|| format!("view field {field:?} has no value"))?;
        let (_, count) = VIEW_FIELDS
            .iter()
            .find(|(known, _)| *known == name)
            .ok_or_else(|| format!("view has an unknown field {name:?}"))?;
        let parts: Vec<&str> = value.split(',').collect();
        if parts.len() != *count {
            return Err(format!("view field {name} needs {count} values"));
        }
        let numbers = match name {
            "section" => &parts[1..2],
            "note" => &[][..],
            _ => &parts[..],
        };
        if !numbers
            .iter()
            .all(|p| p.parse::<f64>().is_ok_and(f64::is_finite))
        {
            return Err(format!(
                "view field {name} has a value that is not a finite number"
            ));
        }
        if name == "section"
            && !(["x", "y", "z"].contains(&parts[0]) && ["0", "1"].contains(&parts[2]))
        {
            return Err("view field section is axis,fraction,flip (x|y|z, 0–1, 0|1)".into());
        }
        if name == "note"
            && !value
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b == b'-')
        {
            return Err("view field note is not an annotation id".into());
        }
        if name == "camera" {
            camera = parts[3].parse::<f64>().is_ok_and(|d| d > 0.0);
            if !camera {
                return Err("view field camera needs a positive distance".into());
            }
        }
    }
    if !camera {
        return Err("view has no camera".into());
    }
    Ok(())
}

/// Where the camera of a saved view is and what it looks at, in the viewer's
/// world frame (the model turned upright, model units): `camera.js`'s orbit.
pub fn camera_of(view: &str) -> Option<([f64; 3], [f64; 3])> {
    let value = view.split('&').find_map(|f| f.strip_prefix("camera="))?;
    let n: Vec<f64> = value
        .split(',')
        .map(|p| p.parse().ok())
        .collect::<Option<_>>()?;
    let numbers: [f64; 6] = n.as_slice().try_into().ok()?;
    let [tx, ty, tz, distance, yaw, pitch] = numbers;
    let back = [
        yaw.sin() * pitch.cos(),
        pitch.sin(),
        yaw.cos() * pitch.cos(),
    ];
    let target = [tx, ty, tz];
    let eye = [0, 1, 2].map(|k| target[k] + distance * back[k]);
    Some((eye, target))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn views_as_the_viewer_writes_them_pass() {
        check_view("camera=0.5,-1.25,3,12.5,0.7,-0.2&light=0.6,0,0.8,0.2&section=y,0.42,1&note=17&measure=1,2,3,4,5,6.5").unwrap();
        check_view("camera=0,0,0,1,0,0").unwrap();
    }

    #[test]
    fn malformed_views_are_refused_with_the_field() {
        for (view, needle) in [
            ("light=0,0,1,1", "no camera"),
            ("camera=0,0,0,0,0,0", "positive distance"),
            ("camera=0,0,0,1,0", "needs 6"),
            ("camera=0,0,0,1,0,NaN", "finite"),
            ("camera=0,0,0,1,0,0&zoom=2", "unknown field"),
            ("camera=0,0,0,1,0,0&section=w,0.5,0", "section"),
            ("camera=0,0,0,1,0,0&note=<b>", "note"),
        ] {
            let error = check_view(view).unwrap_err();
            assert!(error.contains(needle), "{view}: {error}");
        }
        assert!(check_view(&format!("camera=0,0,0,1,0,0&note={}", "1".repeat(3000))).is_err());
    }

    #[test]
    fn the_orbit_gives_eye_and_target() {
        let (eye, target) = camera_of("camera=1,2,3,2,0,0").unwrap();
        assert_eq!(target, [1.0, 2.0, 3.0]);
        assert!((eye[2] - 5.0).abs() < 1e-12 && (eye[0] - 1.0).abs() < 1e-12);
    }
}
