//! A model version's guided tours in its Manifest, as Ranges in
//! `structures`. Why Ranges rather than annotations: a Range is
//! Presentation's ordered, labelled path through a Manifest's Containers —
//! what a tour is — and IIIF viewers (Mirador, Universal Viewer) already show
//! Ranges as a navigable table of contents, so a viewer that knows nothing of
//! 3D cameras still lists each tour and its steps in order; the Manifest's
//! commenting annotations are the curators' notes, unordered, and tour steps
//! among them would mix the two in every client. Each step is a
//! SpecificResource of the Scene whose PointSelector is the point the step
//! looks at (Scene coordinates, +Y up, metres), with its title as `label`,
//! its text as `summary`, and as `homepage` the viewer opened at that step
//! (which also restores the camera, light and section).

use super::ids::Ids;
use super::values::point_selector;
use crate::service::scene::SceneFrame;
use crate::service::tours::input::camera_of;
use crate::storage::{LanguageMap, TourRecord};
use serde_json::{json, Map, Value};

/// `{"en": ["…"]}` from `{"en": "…"}`.
fn language_map(map: &LanguageMap) -> Value {
    Value::Object(
        map.iter()
            .map(|(tag, text)| (tag.clone(), json!([text])))
            .collect::<Map<_, _>>(),
    )
}

/// The Ranges of `tours` (none: `None`, and the Manifest has no `structures`).
pub fn structures(ids: &Ids<'_>, frame: &SceneFrame, tours: &[TourRecord]) -> Option<Value> {
    if tours.is_empty() {
        return None;
    }
    let page = crate::service::web::page_url(ids.base, ids.slug);
    let ranges = tours
        .iter()
        .map(|tour| {
            let items: Vec<Value> = tour
                .steps
                .iter()
                .enumerate()
                .map(|(k, step)| {
                    let mut item = json!({
                        "id": ids.tour_step(tour.id, k + 1),
                        "type": "SpecificResource",
                        "source": { "id": ids.scene(), "type": "Scene" },
                        "label": language_map(&step.title),
                        "homepage": [{
                            "id": format!("{page}?tour={}&step={}", tour.id, k + 1),
                            "type": "Text",
                            "label": language_map(&step.title),
                            "format": "text/html",
                        }],
                    });
                    if let Some((_, target)) = camera_of(&step.view) {
                        item["selector"] = json!([point_selector(frame.upright_to_scene(target))]);
                    }
                    if !step.text.is_empty() {
                        item["summary"] = language_map(&step.text);
                    }
                    item
                })
                .collect();
            json!({
                "id": ids.tour(tour.id),
                "type": "Range",
                "label": language_map(&tour.title),
                "items": items,
            })
        })
        .collect();
    Some(Value::Array(ranges))
}
