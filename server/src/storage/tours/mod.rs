//! Guided tours (issue 44): a title and ordered steps, each a saved view
//! (the viewer's share-link fragment, `web/src/view-state.js`) with a title
//! and Markdown text per language. A tour belongs to one model version.
//! Same pattern as the curators' rows: one trait, the SQL written once
//! (`sql.rs`), one macro implementing it for each backend (`backend.rs`).

mod backend;
pub(crate) mod sql;

pub(in crate::storage) use backend::tour_storage;

use super::Result;
use async_trait::async_trait;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Text per BCP 47 language tag.
pub type LanguageMap = BTreeMap<String, String>;

/// One step of a tour, as stored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TourStep {
    /// The share-link fragment of the view (`camera=…&light=…`).
    pub view: String,
    pub title: LanguageMap,
    /// Markdown source per language.
    pub text: LanguageMap,
    /// `text` rendered and sanitised, per language.
    pub html: LanguageMap,
}

/// A stored tour.
#[derive(Clone, Debug, PartialEq)]
pub struct TourRecord {
    pub id: i64,
    pub slug: String,
    /// The model version the tour was recorded on.
    pub version: u32,
    pub title: LanguageMap,
    pub steps: Vec<TourStep>,
    pub created_at_ms: i64,
    pub updated_at_ms: i64,
}

/// What a curator writes; validated and rendered by the service.
#[derive(Clone, Debug, PartialEq)]
pub struct NewTour {
    pub version: u32,
    pub title: LanguageMap,
    pub steps: Vec<TourStep>,
}

/// Every method has a default that refuses, for storages without the table
/// (the service tests' doubles); both backends implement them all.
#[allow(unused_variables)] // the defaults ignore their arguments; the names document them
#[async_trait]
pub trait TourStorage: Send + Sync {
    /// The slug's tours, oldest first: of one version, or of all (`None`).
    async fn tours(&self, slug: &str, version: Option<u32>) -> Result<Vec<TourRecord>> {
        no_tours()
    }

    async fn insert_tour(&self, slug: &str, tour: &NewTour) -> Result<TourRecord> {
        no_tours()
    }

    /// Replaces title, steps (and so their order) and version; `None` when
    /// the slug has no tour `id`.
    async fn update_tour(&self, slug: &str, id: i64, tour: &NewTour) -> Result<Option<TourRecord>> {
        no_tours()
    }

    /// `false` when the slug has no tour `id`.
    async fn delete_tour(&self, slug: &str, id: i64) -> Result<bool> {
        no_tours()
    }
}

fn no_tours<T>() -> Result<T> {
    Err(super::StorageError::Unknown(
        "this storage keeps no tours".into(),
    ))
}
