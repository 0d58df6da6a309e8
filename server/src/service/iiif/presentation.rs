//! A model as a IIIF Presentation 4 Manifest (draft of the IIIF 3D group,
//! IIIF/api `source/presentation/4.0/model.md`): one Scene whose painting
//! page paints the model's GLB download as a Model at the Scene's origin,
//! with the viewer's home camera and two lights; the curators' annotations
//! in `annotations`; and links back to Vitrine (the model page, the
//! progressive stream's JSON manifest).
//!
//! Scene coordinates are the GLB's world coordinates: +Y up, in metres
//! ([`crate::service::scene`]), so the Model needs no transform.
//!
//! Text a model carries (title, description, credit) is keyed by the
//! version's language and each translation's (issue 43); a version whose
//! language was never stated keys its own text `none`, as Presentation's
//! language maps ask for text of unknown language. Vitrine's own labels ("Attribution") are `en`.

use super::ids::{self, Ids, CONTEXT};
use super::values::{language_map, language_maps, point_selector};
use super::web_annotation;
use crate::service::scene::SceneFrame;
use crate::storage::{AnnotationRecord, Bounds, ModelRecord, TextField, TourRecord};
use serde_json::{json, Value};

/// The viewer's vertical field of view, degrees (`web/src/camera.js`).
const FIELD_OF_VIEW_DEGREES: f64 = 40.0;
/// The viewer's home orbit (`web/src/camera.js`): yaw and pitch, radians.
const HOME_YAW: f64 = 0.5;
const HOME_PITCH: f64 = 0.4;

/// Everything a Manifest says, gathered by the handler.
pub struct ManifestInput<'a> {
    pub ids: Ids<'a>,
    pub record: &'a ModelRecord,
    /// The level whose GLB the Scene paints; `None`: no download is offered
    /// to the public, and the Scene paints no Model (see [`manifest`]).
    pub level: Option<u32>,
    pub annotations: &'a [AnnotationRecord],
    /// The guided tours of the version described (`tours.rs`: as Ranges).
    pub tours: &'a [TourRecord],
    /// `/api/models/{slug}/thumbnail?v=…`, when the version has one.
    pub thumbnail: Option<String>,
}

/// The Manifest of a model. A model whose policy offers the public no
/// download (or a point cloud, which is not served as GLB) paints no Model:
/// its Scene keeps the camera and lights, and a client reaches the scan
/// through `homepage` (the viewer) and `service` (the progressive stream).
/// No restricted level is ever named.
pub fn manifest(input: &ManifestInput<'_>) -> Value {
    let ManifestInput { ids, record, .. } = input;
    let base = ids.base;
    let mut manifest = json!({
        "@context": CONTEXT,
        "id": ids.manifest(),
        "type": "Manifest",
        "label": title_map(record),
        "metadata": metadata(record),
        "homepage": [{
            "id": crate::service::web::page_url(base, &record.slug),
            "type": "Text",
            "label": title_map(record),
            "format": "text/html",
        }],
        "seeAlso": [{
            "id": format!("{base}/api/models/{}", record.slug),
            "type": "Dataset",
            "label": language_map(Some("en"), "Vitrine manifest of the progressive stream"),
            "format": "application/json",
            "profile": format!("{base}/api/openapi.json"),
        }],
        "service": [{
            "id": format!("{base}/api/models/{}", record.slug),
            "type": "VitrineProgressiveStream",
            "profile": format!("{base}/api/openapi.json"),
        }],
        "items": [scene(input)],
        "annotations": [web_annotation::page(ids, &SceneFrame::of(&record.curation), input.annotations)],
    });
    let description = record.description.trim();
    if !description.is_empty() {
        manifest["summary"] = language_maps(
            record
                .texts
                .every(TextField::Description, description)
                .map(|(l, t)| (l, t.trim())),
        );
    }
    if let Some(structures) =
        super::tours::structures(ids, &SceneFrame::of(&record.curation), input.tours)
    {
        manifest["structures"] = structures;
    }
    rights(&mut manifest, record);
    if let Some(thumbnail) = &input.thumbnail {
        manifest["thumbnail"] = thumbnail_of(base, thumbnail);
    }
    manifest
}

/// The title in every language it is written in.
fn title_map(record: &ModelRecord) -> Value {
    language_maps(record.texts.every(TextField::Title, &record.title))
}

fn thumbnail_of(base: &str, path: &str) -> Value {
    let side = crate::ingest::curation::THUMBNAIL_SIZE;
    json!([{
        "id": format!("{base}{path}"),
        "type": "Image",
        "format": "image/png",
        "width": side,
        "height": side,
    }])
}

fn metadata(record: &ModelRecord) -> Value {
    let entry = |label: &str, value: String| json!({ "label": language_map(Some("en"), label), "value": language_map(None, &value) });
    let mut entries = vec![
        entry("Version", record.version.to_string()),
        entry("Levels", (record.batch_count() + 1).to_string()),
        entry(
            "Vertices",
            record.levels.last().map_or(0, |l| l.vertices).to_string(),
        ),
    ];
    if let Some(licence) = record.curation.rights.licence {
        entries.push(entry("Licence", licence.name.to_owned()));
    }
    Value::Array(entries)
}

/// `requiredStatement` is the credit; `rights` the licence's URI as IIIF
/// asks for it: Creative Commons deeds by their machine-actionable `http`
/// URIs (rightsstatements.org's already are).
fn rights(manifest: &mut Value, record: &ModelRecord) {
    let rights = &record.curation.rights;
    if let Some(credit) = &rights.credit {
        manifest["requiredStatement"] = json!({
            "label": language_map(Some("en"), "Attribution"),
            "value": language_maps(record.texts.every(TextField::Credit, credit)),
        });
    }
    if let Some(licence) = rights.licence {
        let uri = match licence.url.strip_prefix("https://creativecommons.org/") {
            Some(rest) => format!("http://creativecommons.org/{rest}"),
            None => licence.url.to_owned(),
        };
        manifest["rights"] = uri.into();
    }
}

fn scene(input: &ManifestInput<'_>) -> Value {
    let ids = &input.ids;
    let record = input.record;
    let scene_ref = json!({ "id": ids.scene(), "type": "Scene" });
    let mut painted = Vec::new();
    if let Some(level) = input.level {
        painted.push(json!({
            "id": ids.painting("model"),
            "type": "Annotation",
            "motivation": ["painting"],
            "body": {
                "id": format!("{}{}", ids.base, crate::service::download::url(&record.slug, level)),
                "type": "Model",
                "label": title_map(record),
                "format": "model/gltf-binary",
            },
            "target": scene_ref,
        }));
    }
    let frame = SceneFrame::of(&record.curation);
    if let Some(bounds) = record.curation.bounds {
        painted.extend(camera_and_light(
            ids,
            &scene_ref,
            &scene_bounds(&frame, bounds),
        ));
    }
    painted.push(json!({
        "id": ids.painting("ambient-light"),
        "type": "Annotation",
        "motivation": ["painting"],
        "body": {
            "id": ids.scene_component("lights/ambient"),
            "type": "AmbientLight",
            "color": "#FFFFFF",
            "intensity": { "type": "Quantity", "quantityValue": 0.4, "unit": "relative" },
        },
        "target": scene_ref,
    }));
    json!({
        "id": ids.scene(),
        "type": "Scene",
        "label": title_map(record),
        "items": [{
            "id": ids.painting("page"),
            "type": "AnnotationPage",
            "items": painted,
        }],
    })
}

/// The model's bounds in the Scene: its eight corners turned and scaled.
fn scene_bounds(frame: &SceneFrame, bounds: Bounds) -> Bounds {
    let mut min = [f64::INFINITY; 3];
    let mut max = [f64::NEG_INFINITY; 3];
    for corner in 0..8 {
        let p = [0, 1, 2].map(|axis| {
            if corner & (1 << axis) == 0 {
                bounds.min[axis]
            } else {
                bounds.max[axis]
            }
        });
        let q = frame.to_scene(p);
        for axis in 0..3 {
            min[axis] = min[axis].min(q[axis]);
            max[axis] = max[axis].max(q[axis]);
        }
    }
    Bounds { min, max }
}

/// The viewer's home view as a PerspectiveCamera (the default camera: the
/// first one not hidden), and a DirectionalLight from above and in front,
/// both looking at the centre of the model's bounds.
fn camera_and_light(ids: &Ids<'_>, scene_ref: &Value, bounds: &Bounds) -> [Value; 2] {
    let centre = [0, 1, 2].map(|i| (bounds.min[i] + bounds.max[i]) / 2.0);
    let radius = (bounds.diagonal() / 2.0).max(1e-6);
    let distance = 1.1 * radius / (FIELD_OF_VIEW_DEGREES.to_radians() / 2.0).sin();
    let direction = [
        HOME_YAW.sin() * HOME_PITCH.cos(),
        HOME_PITCH.sin(),
        HOME_YAW.cos() * HOME_PITCH.cos(),
    ];
    let at = |d: [f64; 3], length: f64| [0, 1, 2].map(|i| centre[i] + d[i] * length);
    let look_at = point_selector(centre);
    let placed = |p: [f64; 3]| {
        json!({
            "type": "SpecificResource",
            "source": scene_ref,
            "selector": [point_selector(p)],
        })
    };
    let camera = json!({
        "id": ids.painting("camera"),
        "type": "Annotation",
        "motivation": ["painting"],
        "body": {
            "id": ids.scene_component("cameras/home"),
            "type": "PerspectiveCamera",
            "label": language_map(Some("en"), "Home view"),
            "fieldOfView": FIELD_OF_VIEW_DEGREES,
            "near": (distance - 2.0 * radius).max(distance / 1000.0),
            "far": distance + 2.0 * radius,
            "lookAt": look_at,
        },
        "target": placed(at(direction, distance)),
    });
    let light = json!({
        "id": ids.painting("directional-light"),
        "type": "Annotation",
        "motivation": ["painting"],
        "body": {
            "id": ids.scene_component("lights/key"),
            "type": "DirectionalLight",
            "color": "#FFFFFF",
            "intensity": { "type": "Quantity", "quantityValue": 0.8, "unit": "relative" },
            "lookAt": look_at,
        },
        "target": placed(at([0.3, 0.8, 0.52], 2.0 * radius)),
    });
    [camera, light]
}

/// One entry of the Collection.
pub struct Listed<'a> {
    pub slug: &'a str,
    pub title: &'a str,
    pub thumbnail: Option<String>,
}

/// Every public model's Manifest, by reference.
pub fn collection(base: &str, site_name: &str, models: &[Listed<'_>]) -> Value {
    let items: Vec<Value> = models
        .iter()
        .map(|m| {
            let ids = Ids { base, slug: m.slug };
            let mut item = json!({
                "id": ids.manifest(),
                "type": "Manifest",
                "label": language_map(None, m.title),
            });
            if let Some(thumbnail) = &m.thumbnail {
                item["thumbnail"] = thumbnail_of(base, thumbnail);
            }
            item
        })
        .collect();
    json!({
        "@context": CONTEXT,
        "id": ids::collection(base),
        "type": "Collection",
        "label": language_map(None, site_name),
        "items": items,
    })
}
