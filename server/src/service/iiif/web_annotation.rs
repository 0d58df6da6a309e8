//! Curators' annotations as W3C Web Annotations (IIIF Presentation 4's
//! commenting annotations on a Scene), and back.
//!
//! Out: each annotation is `motivation: commenting`, its title the
//! annotation's `label`, its Markdown text one `TextualBody` (`format:
//! text/markdown`, `language` when recorded; no body when the text is
//! empty), its target a `SpecificResource` on the Scene with a
//! `PointSelector`. The point is in Scene coordinates: glTF's frame, +Y up,
//! in metres, the frame the GLB download's node matrix puts the model in
//! ([`SceneFrame`]), not the stored model coordinates.
//!
//! In: the same shape, from Vitrine or from another tool. What Vitrine
//! stores and a Web Annotation may lack is filled in (see [`Imported`]);
//! what Vitrine cannot keep is refused, with the reason, rather than
//! dropped: several bodies, a body in another format than Markdown or
//! plain text, a target that is not a point on this model's Scene.

use super::ids::Ids;
use super::values::{language_maps, point_selector};
use crate::service::scene::SceneFrame;
use crate::storage::AnnotationRecord;
use serde_json::{json, Map, Value};

/// The commenting AnnotationPage of a model's annotations.
pub fn page(ids: &Ids<'_>, frame: &SceneFrame, annotations: &[AnnotationRecord]) -> Value {
    let scene = json!({ "id": ids.scene(), "type": "Scene" });
    let items: Vec<Value> = annotations
        .iter()
        .map(|a| {
            let language = a.language.as_deref();
            let translated = a
                .translations
                .iter()
                .map(|(tag, t)| (Some(tag.as_str()), t));
            let titles = translated.clone().map(|(tag, t)| (tag, t.title.as_str()));
            let mut item = json!({
                "id": ids.annotation(a.id),
                "type": "Annotation",
                "motivation": ["commenting"],
                "label": language_maps(std::iter::once((language, a.title.as_str())).chain(titles)),
                "target": {
                    "type": "SpecificResource",
                    "source": scene,
                    "selector": [point_selector(frame.to_scene(a.position))],
                },
            });
            // One text per language; several are alternatives of one
            // another, a `Choice` (as IIIF's captions in several languages).
            let mut bodies: Vec<Value> = std::iter::once((language, a.text.as_str()))
                .chain(translated.map(|(tag, t)| (tag, t.text.as_str())))
                .filter(|(_, text)| !text.is_empty())
                .map(|(language, text)| textual_body(language, text))
                .collect();
            match bodies.len() {
                0 => {}
                1 => item["body"] = bodies.remove(0),
                _ => item["body"] = json!({ "type": "Choice", "items": bodies }),
            }
            item
        })
        .collect();
    json!({
        "id": ids.annotations(),
        "type": "AnnotationPage",
        "items": items,
    })
}

fn textual_body(language: Option<&str>, text: &str) -> Value {
    let mut body = json!({
        "type": "TextualBody",
        "value": text,
        "format": "text/markdown",
    });
    if let Some(language) = language {
        body["language"] = language.into();
    }
    body
}

/// One annotation as read from an import, before Vitrine's own checks
/// (lengths, the language tag's shape) and before its point is turned into
/// model coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct Imported {
    /// The `label` (in the body's language, else `none`, else the first);
    /// without one, the text's first line.
    pub title: String,
    /// The body's `value`; empty without a body.
    pub text: String,
    /// The body's `language`, else the label's only language.
    pub language: Option<String>,
    /// Further languages: `(tag, title, text)`, from a `Choice` of bodies
    /// and the label's other languages.
    pub translations: Vec<(String, String, String)>,
    /// Scene coordinates.
    pub point: [f64; 3],
}

/// The items of an AnnotationPage, or of a bare list of annotations.
pub fn items_of(document: &Value) -> Result<&[Value], String> {
    match document {
        Value::Array(items) => Ok(items),
        Value::Object(page) => {
            match page.get("type").and_then(Value::as_str) {
                Some("AnnotationPage") => {}
                Some(other) => {
                    return Err(format!(
                        "type is {other:?}: send an AnnotationPage or a JSON array of Annotations"
                    ))
                }
                None => {
                    return Err(
                        "no type: send an AnnotationPage or a JSON array of Annotations".into(),
                    )
                }
            }
            match page.get("items") {
                Some(Value::Array(items)) => Ok(items),
                Some(_) => Err("the AnnotationPage's items is not an array".into()),
                None => Err("the AnnotationPage has no items".into()),
            }
        }
        _ => Err("send an AnnotationPage or a JSON array of Annotations".into()),
    }
}

/// Reads one annotation that must target the Scene of model `slug`.
pub fn read(item: &Value, slug: &str) -> Result<Imported, String> {
    let item = item.as_object().ok_or("not a JSON object")?;
    match item.get("type").and_then(Value::as_str) {
        Some("Annotation") => {}
        Some(other) => return Err(format!("type is {other:?}, not \"Annotation\"")),
        None => return Err("no type (an Annotation has \"type\": \"Annotation\")".into()),
    }
    check_motivation(item.get("motivation"))?;
    let mut bodies = bodies_of(item.get("body"))?.into_iter();
    let body = bodies.next().unwrap_or(Body {
        text: String::new(),
        language: None,
    });
    let others: Vec<Body> = bodies.collect();
    let point = point_of(item.get("target").ok_or("no target")?, slug)?;
    let label = item.get("label").map(label_of).transpose()?;
    let language = body
        .language
        .clone()
        .or_else(|| label.as_ref().and_then(only_language));
    let title = match label.as_ref().and_then(|l| pick(l, language.as_deref())) {
        Some(title) => title,
        None => first_line(&body.text).ok_or("neither a label nor any text to title it with")?,
    };
    let translations = translations_of(label.as_ref(), language.as_deref(), others)?;
    Ok(Imported {
        title,
        text: body.text,
        language,
        translations,
        point,
    })
}

/// The further languages: each other body of a `Choice` (which must name
/// its language), titled by the label in that language or its first line;
/// then the label's other languages without a text.
fn translations_of(
    label: Option<&Map<String, Value>>,
    own: Option<&str>,
    others: Vec<Body>,
) -> Result<Vec<(String, String, String)>, String> {
    let titled = |tag: &str| label.and_then(|l| l.get(tag)).and_then(first_text);
    let mut out: Vec<(String, String, String)> = Vec::new();
    for body in others {
        let tag = body
            .language
            .ok_or("a Choice's bodies after the first must each state their language")?;
        let title = titled(&tag)
            .or_else(|| first_line(&body.text))
            .ok_or_else(|| format!("the {tag} text has no title and no line to take one from"))?;
        out.push((tag, title, body.text));
    }
    for (tag, values) in label.into_iter().flatten() {
        let known =
            tag == "none" || own.is_some_and(|o| o == tag) || out.iter().any(|(t, _, _)| t == tag);
        if let (false, Some(title)) = (known, first_text(values)) {
            out.push((tag.clone(), title, String::new()));
        }
    }
    Ok(out)
}

/// A text's first non-empty line, Markdown heading marks removed, cut to a
/// title's length.
fn first_line(text: &str) -> Option<String> {
    text.lines()
        .map(str::trim)
        .find(|line| !line.is_empty())
        .map(|line| {
            line.trim_start_matches('#')
                .trim()
                .chars()
                .take(crate::service::curator::annotations::MAX_TITLE_CHARS)
                .collect()
        })
}

/// Comments are what Vitrine's annotations are: `commenting` or
/// `describing`, or none stated.
fn check_motivation(motivation: Option<&Value>) -> Result<(), String> {
    let names: Vec<&str> = match motivation {
        None | Some(Value::Null) => return Ok(()),
        Some(Value::String(one)) => vec![one.as_str()],
        Some(Value::Array(many)) => many
            .iter()
            .map(|m| m.as_str().ok_or("motivation holds a non-string"))
            .collect::<Result<_, _>>()?,
        Some(_) => return Err("motivation is neither a string nor a list of strings".into()),
    };
    match names
        .iter()
        .find(|m| !matches!(**m, "commenting" | "describing"))
    {
        Some(other) => Err(format!(
            "motivation {other:?}: only commenting (or describing) annotations are imported"
        )),
        None => Ok(()),
    }
}

struct Body {
    text: String,
    language: Option<String>,
}

/// The texts of an annotation: none, one, or a `Choice` of one per
/// language (the first the annotation's own).
fn bodies_of(body: Option<&Value>) -> Result<Vec<Body>, String> {
    let body = match body {
        None | Some(Value::Null) => None,
        Some(Value::Array(bodies)) => match bodies.as_slice() {
            [] => None,
            [one] => Some(one),
            more => {
                return Err(format!(
                    "{} bodies: Vitrine keeps one text per language, given as a Choice",
                    more.len()
                ))
            }
        },
        Some(one) => Some(one),
    };
    let Some(body) = body else {
        return Ok(Vec::new());
    };
    if body.get("type").and_then(Value::as_str) == Some("Choice") {
        let items = match body.get("items") {
            Some(Value::Array(items)) if !items.is_empty() => items,
            _ => return Err("the Choice has no items".into()),
        };
        return items.iter().map(body_of).collect();
    }
    Ok(vec![body_of(body)?])
}

fn body_of(body: &Value) -> Result<Body, String> {
    let body = body.as_object().ok_or("the body is not a JSON object")?;
    match body.get("type").and_then(Value::as_str) {
        Some("TextualBody") | None => {}
        Some(other) => {
            return Err(format!(
                "the body is a {other:?}: only a TextualBody is imported"
            ))
        }
    }
    match body.get("format").and_then(Value::as_str) {
        None | Some("text/markdown") | Some("text/plain") => {}
        Some(other) => {
            return Err(format!(
                "the body's format is {other:?}: Vitrine stores text/markdown or text/plain"
            ))
        }
    }
    let text = match body.get("value") {
        Some(Value::String(text)) => text.clone(),
        Some(_) => return Err("the body's value is not a string".into()),
        None => return Err("the TextualBody has no value".into()),
    };
    let language = match body.get("language") {
        None | Some(Value::Null) => None,
        Some(Value::String(tag)) => Some(tag.clone()),
        Some(_) => return Err("the body's language is not a string (one BCP 47 tag)".into()),
    };
    Ok(Body { text, language })
}

/// A Presentation language map: `{ tag: [text, …] }`.
fn label_of(label: &Value) -> Result<Map<String, Value>, String> {
    let map = label
        .as_object()
        .ok_or("the label is not a language map ({\"en\": [\"…\"]})")?;
    for (tag, values) in map {
        let values = values
            .as_array()
            .ok_or_else(|| format!("the label's {tag:?} entry is not a list of strings"))?;
        if values.iter().any(|v| !v.is_string()) {
            return Err(format!(
                "the label's {tag:?} entry is not a list of strings"
            ));
        }
    }
    Ok(map.clone())
}

fn only_language(label: &Map<String, Value>) -> Option<String> {
    match label.keys().collect::<Vec<_>>().as_slice() {
        [tag] if *tag != "none" => Some((*tag).clone()),
        _ => None,
    }
}

/// The label's first text in `language`, else under `none`, else the first.
fn pick(label: &Map<String, Value>, language: Option<&str>) -> Option<String> {
    language
        .and_then(|l| label.get(l))
        .and_then(first_text)
        .or_else(|| label.get("none").and_then(first_text))
        .or_else(|| label.values().find_map(first_text))
}

/// A language map entry's first non-blank text.
fn first_text(values: &Value) -> Option<String> {
    values
        .as_array()?
        .iter()
        .filter_map(Value::as_str)
        .find(|t| !t.trim().is_empty())
        .map(str::to_owned)
}

/// The PointSelector of a target on this model's Scene.
fn point_of(target: &Value, slug: &str) -> Result<[f64; 3], String> {
    let target = target
        .as_object()
        .ok_or("the target is not a SpecificResource on the Scene")?;
    match target.get("type").and_then(Value::as_str) {
        Some("SpecificResource") | None => {}
        Some(other) => {
            return Err(format!(
                "the target is a {other:?}: a point needs a SpecificResource with a PointSelector"
            ))
        }
    }
    let source = target.get("source").ok_or("the target has no source")?;
    let (source_id, source_type) = match source {
        Value::String(id) => (id.as_str(), None),
        Value::Object(o) => (
            o.get("id")
                .and_then(Value::as_str)
                .ok_or("the target's source has no id")?,
            o.get("type").and_then(Value::as_str),
        ),
        _ => return Err("the target's source is neither a URI nor an object".into()),
    };
    if source_type.is_some_and(|t| t != "Scene") {
        return Err(format!(
            "the target's source is a {:?}, not this model's Scene",
            source_type.unwrap_or_default()
        ));
    }
    let scene_path = Ids::scene_path(slug);
    if !source_id.ends_with(&scene_path) {
        return Err(format!(
            "the target is {source_id:?}, not this model's Scene (…{scene_path})"
        ));
    }
    let selectors = match target.get("selector") {
        Some(Value::Array(many)) => many.as_slice(),
        Some(one @ Value::Object(_)) => std::slice::from_ref(one),
        _ => return Err("the target has no selector".into()),
    };
    let selector = selectors
        .iter()
        .find(|s| s.get("type").and_then(Value::as_str) == Some("PointSelector"))
        .ok_or("the target has no PointSelector")?;
    let coordinate = |axis: &str| -> Result<f64, String> {
        selector
            .get(axis)
            .and_then(Value::as_f64)
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("the PointSelector's {axis} is missing or not a finite number"))
    };
    Ok([coordinate("x")?, coordinate("y")?, coordinate("z")?])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn annotation(target_source: &str) -> Value {
        json!({
            "id": "https://elsewhere.example/a/1",
            "type": "Annotation",
            "motivation": "commenting",
            "label": { "fr": ["Marque d'outil"] },
            "body": { "type": "TextualBody", "value": "Un *trait*", "language": "fr" },
            "target": {
                "type": "SpecificResource",
                "source": target_source,
                "selector": { "type": "PointSelector", "x": 0.5, "y": 1, "z": -2.25 }
            }
        })
    }

    #[test]
    fn a_web_annotation_is_read() {
        let read = read(&annotation("https://m.example/iiif/stele/scene"), "stele").unwrap();
        assert_eq!(
            read,
            Imported {
                title: "Marque d'outil".into(),
                text: "Un *trait*".into(),
                language: Some("fr".into()),
                translations: vec![],
                point: [0.5, 1.0, -2.25],
            }
        );
    }

    #[test]
    fn a_choice_of_texts_gives_the_further_languages() {
        let mut a = annotation("https://m.example/iiif/stele/scene");
        a["label"]["pt"] = json!(["Marca de ferramenta"]);
        a["label"]["de"] = json!(["Werkzeugspur"]);
        let fr = a["body"].clone();
        let pt = json!({ "type": "TextualBody", "value": "Um *traço*", "language": "pt" });
        a["body"] = json!({ "type": "Choice", "items": [fr, pt] });
        let read = read(&a, "stele").unwrap();
        assert_eq!(read.language.as_deref(), Some("fr"));
        assert_eq!(
            read.translations,
            vec![
                (
                    "pt".into(),
                    "Marca de ferramenta".into(),
                    "Um *traço*".into()
                ),
                ("de".into(), "Werkzeugspur".into(), String::new()),
            ]
        );
        // A further text must say which language it is in.
        a["body"]["items"][1]
            .as_object_mut()
            .unwrap()
            .remove("language");
        let err = super::read(&a, "stele").unwrap_err();
        assert!(err.contains("state their language"), "{err}");
    }

    #[test]
    fn what_cannot_be_kept_is_refused_with_the_reason() {
        type Spoil = fn(&mut Value);
        let cases: [(&str, Spoil); 7] = [
            ("not this model's Scene", |a| {
                a["target"]["source"] = "https://m.example/iiif/other/scene".into()
            }),
            (
                "PointSelector",
                |a| {
                    a["target"]["selector"] =
                        json!({ "type": "FragmentSelector", "value": "xywh=1,2,3,4" })
                },
            ),
            ("finite number", |a| {
                a["target"]["selector"]["z"] = "far".into()
            }),
            ("painting", |a| a["motivation"] = json!(["painting"])),
            ("2 bodies", |a| {
                a["body"] = json!([a["body"].clone(), a["body"].clone()])
            }),
            ("text/html", |a| a["body"]["format"] = "text/html".into()),
            ("not \"Annotation\"", |a| a["type"] = "Canvas".into()),
        ];
        for (expected, spoil) in cases {
            let mut a = annotation("https://m.example/iiif/stele/scene");
            spoil(&mut a);
            let err = read(&a, "stele").unwrap_err();
            assert!(err.contains(expected), "{expected}: {err}");
        }
    }

    #[test]
    fn a_title_comes_from_the_text_without_a_label() {
        let mut a = annotation("https://m.example/iiif/stele/scene");
        a.as_object_mut().unwrap().remove("label");
        a["body"]["value"] = "\n## Crack\nalong the base".into();
        assert_eq!(read(&a, "stele").unwrap().title, "Crack");
        a.as_object_mut().unwrap().remove("body");
        assert!(read(&a, "stele").unwrap_err().contains("neither a label"));
    }

    #[test]
    fn pages_and_lists_hold_items() {
        assert_eq!(items_of(&json!([1, 2])).unwrap().len(), 2);
        let page = json!({ "type": "AnnotationPage", "items": [1] });
        assert_eq!(items_of(&page).unwrap().len(), 1);
        assert!(items_of(&json!({ "type": "Manifest" })).is_err());
        assert!(items_of(&json!("x")).is_err());
    }
}
