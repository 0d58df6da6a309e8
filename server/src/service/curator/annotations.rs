//! `/api/models/{slug}/annotations`: curator-authored hotspots, a point and
//! a normal in model coordinates with a title, Markdown text (served also as
//! sanitised HTML) and an optional saved view. Anyone who may see the model
//! reads them; writing needs a curator token. They belong to the slug, not
//! to one version, since they are in model coordinates.

use super::markdown;
use super::Curator;
use crate::service::error::{AppError, ErrorBody};
use crate::service::servable::{PathParams, ServableModel, SlugParam};
use crate::service::AppState;
use crate::storage::{
    valid_slug, AnnotationRecord, AnnotationText, AnnotationTranslations, NewAnnotation,
};
use axum::extract::rejection::JsonRejection;
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use utoipa::{IntoParams, ToSchema};

/// Longest title, in characters.
pub const MAX_TITLE_CHARS: usize = 200;
/// Longest text (Markdown source), in characters.
pub const MAX_TEXT_CHARS: usize = 10_000;
/// Largest saved view, serialised.
pub const MAX_VIEW_BYTES: usize = 4_096;

/// An annotation as served.
#[derive(Serialize, ToSchema)]
pub struct Annotation {
    id: i64,
    title: String,
    /// Markdown source.
    text: String,
    /// `text` rendered and sanitised (no raw HTML, scripts or `javascript:` URLs).
    html: String,
    /// Model coordinates (those of the decoded stream).
    position: [f64; 3],
    /// Unit length, model coordinates.
    normal: [f64; 3],
    /// The saved camera, as the viewer sent it.
    #[schema(value_type = Option<Object>)]
    view: Option<serde_json::Value>,
    /// BCP 47 tag of the title and text (`en`, `pt-BR`), or null when not stated.
    language: Option<String>,
    /// The title and text in further languages, per BCP 47 tag: `{"title",
    /// "text", "html"}` (the viewer shows the visitor's, else the above).
    #[schema(value_type = Object)]
    translations: AnnotationTranslations,
    /// Unix milliseconds.
    created_at: i64,
    updated_at: i64,
}

impl From<AnnotationRecord> for Annotation {
    fn from(a: AnnotationRecord) -> Self {
        Annotation {
            id: a.id,
            title: a.title,
            text: a.text,
            html: a.html,
            position: a.position,
            normal: a.normal,
            view: a.view,
            language: a.language,
            translations: a.translations,
            created_at: a.created_at_ms,
            updated_at: a.updated_at_ms,
        }
    }
}

/// What a curator sends to create or replace an annotation.
#[derive(Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct AnnotationInput {
    /// 1–200 characters.
    title: String,
    /// Markdown, at most 10,000 characters.
    #[serde(default)]
    text: String,
    position: [f64; 3],
    /// Non-zero; stored normalised.
    normal: [f64; 3],
    /// A saved camera (a JSON object of at most 4 KiB), or null.
    #[serde(default)]
    #[schema(value_type = Option<Object>)]
    view: Option<serde_json::Value>,
    /// BCP 47 tag of the title and text (`en`, `pt-BR`), or null. Absent
    /// from a replacement: the annotation keeps the language it had.
    #[serde(default, deserialize_with = "super::admin::present")]
    #[schema(value_type = Option<String>)]
    language: Option<Option<String>>,
    /// The title (1–200 characters) and Markdown text (at most 10,000) in
    /// further languages, per BCP 47 tag: `{"pt": {"title": "…", "text":
    /// "…"}}`, at most 20. Absent from a replacement: the annotation keeps
    /// the translations it had; `{}` removes them.
    #[serde(default)]
    #[schema(value_type = Option<Object>)]
    translations: Option<BTreeMap<String, TranslationInput>>,
}

/// An annotation's title and text in one further language, as typed.
#[derive(Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct TranslationInput {
    title: String,
    #[serde(default)]
    text: String,
}

/// Most further languages of one annotation.
pub const MAX_TRANSLATIONS: usize = 20;

impl AnnotationInput {
    /// An annotation from elsewhere (a IIIF import), without a saved view.
    pub fn new(
        title: String,
        text: String,
        position: [f64; 3],
        normal: [f64; 3],
        language: Option<String>,
    ) -> AnnotationInput {
        AnnotationInput {
            title,
            text,
            position,
            normal,
            view: None,
            language: Some(language),
            translations: None,
        }
    }

    /// With its title and text in further languages (`(tag, title, text)`).
    pub fn with_translations(mut self, translations: Vec<(String, String, String)>) -> Self {
        self.translations = Some(
            translations
                .into_iter()
                .map(|(tag, title, text)| (tag, TranslationInput { title, text }))
                .collect(),
        );
        self
    }

    /// Checks limits and numbers; renders the text.
    fn validate(self) -> Result<NewAnnotation, AppError> {
        self.checked().map_err(AppError::Unprocessable)
    }

    /// [`AnnotationInput::validate`], the reason as text.
    pub fn checked(self) -> Result<NewAnnotation, String> {
        let bad = |m: String| Err(m);
        let title = checked_text("", &self.title, &self.text)?;
        if !self
            .position
            .iter()
            .chain(&self.normal)
            .all(|v| v.is_finite())
        {
            return bad("position and normal must be finite numbers".into());
        }
        let length = self.normal.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(length > 1e-12 && length.is_finite()) {
            return bad("normal must not be zero".into());
        }
        let normal = self.normal.map(|v| v / length);
        let view = match self.view {
            None | Some(serde_json::Value::Null) => None,
            Some(v @ serde_json::Value::Object(_)) => {
                if v.to_string().len() > MAX_VIEW_BYTES {
                    return bad(format!("view is larger than {MAX_VIEW_BYTES} bytes"));
                }
                Some(v)
            }
            Some(_) => return bad("view must be an object or null".into()),
        };
        let language = match self.language.flatten().as_deref().map(str::trim) {
            None | Some("") => None,
            Some(tag) => Some(parse_language(tag)?),
        };
        let translations =
            translations(self.translations.unwrap_or_default(), language.as_deref())?;
        Ok(NewAnnotation {
            html: markdown::render(&self.text),
            title,
            text: self.text,
            position: self.position,
            normal,
            view,
            language,
            translations,
        })
    }
}

/// A title (trimmed, 1–200 characters) and text (at most 10,000
/// characters) checked; `which` names the language in the message.
fn checked_text(which: &str, title: &str, text: &str) -> Result<String, String> {
    let title = title.trim().to_owned();
    if title.is_empty() {
        return Err(format!("{which}title must not be empty"));
    }
    if title.chars().count() > MAX_TITLE_CHARS {
        return Err(format!(
            "{which}title is longer than {MAX_TITLE_CHARS} characters"
        ));
    }
    if text.chars().count() > MAX_TEXT_CHARS {
        return Err(format!(
            "{which}text is longer than {MAX_TEXT_CHARS} characters"
        ));
    }
    Ok(title)
}

/// The further languages checked and rendered: well-formed tags, none the
/// annotation's own or given twice, at most [`MAX_TRANSLATIONS`].
fn translations(
    given: BTreeMap<String, TranslationInput>,
    own: Option<&str>,
) -> Result<AnnotationTranslations, String> {
    if given.len() > MAX_TRANSLATIONS {
        return Err(format!(
            "{} translations, more than {MAX_TRANSLATIONS}",
            given.len()
        ));
    }
    let mut out = AnnotationTranslations::new();
    for (tag, t) in given {
        let tag = parse_language(tag.trim())?;
        if own.is_some_and(|own| own.eq_ignore_ascii_case(&tag)) {
            return Err(format!("{tag} is the annotation's own language"));
        }
        if out.keys().any(|k| k.eq_ignore_ascii_case(&tag)) {
            return Err(format!("{tag} is given twice"));
        }
        let title = checked_text(&format!("the {tag} "), &t.title, &t.text)?;
        let html = markdown::render(&t.text);
        out.insert(
            tag,
            AnnotationText {
                title,
                text: t.text,
                html,
            },
        );
    }
    Ok(out)
}

/// Longest language tag accepted (RFC 5646 §4.4.1 asks for at least 35).
pub const MAX_LANGUAGE_BYTES: usize = 35;

/// A BCP 47 language tag in its well-formed shape (RFC 5646 §2.1: subtags of
/// 1–8 letters or digits joined by `-`, the first of letters); the registry
/// itself is not consulted.
pub fn parse_language(tag: &str) -> Result<String, String> {
    let mut subtags = tag.split('-');
    let primary_ok = subtags
        .next()
        .is_some_and(|p| (1..=8).contains(&p.len()) && p.bytes().all(|b| b.is_ascii_alphabetic()));
    let rest_ok =
        subtags.all(|s| (1..=8).contains(&s.len()) && s.bytes().all(|b| b.is_ascii_alphanumeric()));
    if tag.len() <= MAX_LANGUAGE_BYTES && primary_ok && rest_ok {
        Ok(tag.to_owned())
    } else {
        Err(format!(
            "language {tag:?} is not a BCP 47 tag such as \"en\" or \"pt-BR\""
        ))
    }
}

/// `{slug}` and `{id}`.
#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct AnnotationPath {
    slug: String,
    id: i64,
}

/// A JSON body, malformed ones answered 422 with serde's message.
fn body(input: Result<Json<AnnotationInput>, JsonRejection>) -> Result<NewAnnotation, AppError> {
    match input {
        Ok(Json(input)) => input.validate(),
        Err(e) => Err(AppError::Unprocessable(e.body_text())),
    }
}

/// The model must exist (any audience: curators annotate restricted models too).
async fn existing(state: &AppState, slug: &str) -> Result<(), AppError> {
    if !valid_slug(slug) {
        return Err(AppError::BadRequest(format!(
            "{slug:?} is not a model slug"
        )));
    }
    state.record_by_slug(slug).await.map(|_| ())
}

/// The model's annotations, oldest first.
#[utoipa::path(
    get,
    path = "/api/models/{slug}/annotations",
    params(SlugParam),
    responses(
        (status = 200, description = "Annotations", body = Vec<Annotation>),
        (status = 400, description = "Malformed slug or `Authorization`", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody),
    )
)]
pub async fn list(
    State(state): State<AppState>,
    model: ServableModel,
) -> Result<Json<Vec<Annotation>>, AppError> {
    let rows = state.storage().annotations(&model.record.slug).await?;
    Ok(Json(rows.into_iter().map(Annotation::from).collect()))
}

/// Adds an annotation (curator token).
#[utoipa::path(
    post,
    path = "/api/models/{slug}/annotations",
    params(SlugParam),
    request_body = AnnotationInput,
    security(("bearer" = [])),
    responses(
        (status = 201, description = "Created", body = Annotation),
        (status = 400, description = "Malformed slug or `Authorization`", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token, or one for another model", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
        (status = 422, description = "Invalid annotation; the message says why", body = ErrorBody),
    )
)]
pub async fn create(
    State(state): State<AppState>,
    curator: Curator,
    PathParams(SlugPath { slug }): PathParams<SlugPath>,
    input: Result<Json<AnnotationInput>, JsonRejection>,
) -> Result<Response, AppError> {
    curator.check_model(&slug)?;
    existing(&state, &slug).await?;
    let new = body(input)?;
    let stored = state.storage().insert_annotation(&slug, &new).await?;
    Ok((StatusCode::CREATED, Json(Annotation::from(stored))).into_response())
}

/// Replaces an annotation (curator token).
#[utoipa::path(
    put,
    path = "/api/models/{slug}/annotations/{id}",
    params(AnnotationPath),
    request_body = AnnotationInput,
    security(("bearer" = [])),
    responses(
        (status = 200, description = "Replaced", body = Annotation),
        (status = 400, description = "Malformed path or `Authorization`", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token, or one for another model", body = ErrorBody),
        (status = 404, description = "No such model or annotation", body = ErrorBody),
        (status = 422, description = "Invalid annotation; the message says why", body = ErrorBody),
    )
)]
pub async fn update(
    State(state): State<AppState>,
    curator: Curator,
    PathParams(AnnotationPath { slug, id }): PathParams<AnnotationPath>,
    input: Result<Json<AnnotationInput>, JsonRejection>,
) -> Result<Json<Annotation>, AppError> {
    curator.check_model(&slug)?;
    existing(&state, &slug).await?;
    let keep_language = matches!(&input, Ok(Json(i)) if i.language.is_none());
    let keep_translations = matches!(&input, Ok(Json(i)) if i.translations.is_none());
    let mut new = body(input)?;
    if keep_language || keep_translations {
        let stored = state.storage().annotations(&slug).await?;
        let before = stored.into_iter().find(|a| a.id == id);
        if keep_language {
            new.language = before.as_ref().and_then(|a| a.language.clone());
        }
        if keep_translations {
            new.translations = before.map(|a| a.translations).unwrap_or_default();
        }
    }
    if let Some(own) = &new.language {
        // The annotation's own language is not a translation of it (a kept
        // language and a new list, or the other way round, may meet here).
        new.translations
            .retain(|tag, _| !tag.eq_ignore_ascii_case(own));
    }
    let stored = state.storage().update_annotation(&slug, id, &new).await?;
    Ok(Json(stored.ok_or(AppError::NotFound("annotation"))?.into()))
}

/// Deletes an annotation (curator token).
#[utoipa::path(
    delete,
    path = "/api/models/{slug}/annotations/{id}",
    params(AnnotationPath),
    security(("bearer" = [])),
    responses(
        (status = 204, description = "Deleted"),
        (status = 400, description = "Malformed path or `Authorization`", body = ErrorBody),
        (status = 401, description = "No token, or an unknown one", body = ErrorBody),
        (status = 403, description = "Not a curator token, or one for another model", body = ErrorBody),
        (status = 404, description = "No such model or annotation", body = ErrorBody),
    )
)]
pub async fn delete(
    State(state): State<AppState>,
    curator: Curator,
    PathParams(AnnotationPath { slug, id }): PathParams<AnnotationPath>,
) -> Result<StatusCode, AppError> {
    curator.check_model(&slug)?;
    existing(&state, &slug).await?;
    if state.storage().delete_annotation(&slug, id).await? {
        Ok(StatusCode::NO_CONTENT)
    } else {
        Err(AppError::NotFound("annotation"))
    }
}

/// `{slug}` alone, readable here (`SlugParam` keeps its field private).
#[derive(Deserialize)]
pub struct SlugPath {
    pub slug: String,
}
