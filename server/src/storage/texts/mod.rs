//! A model version's texts in several languages (issue 43): the version's
//! own title, description and credit line are in its default language
//! (`model.language`, possibly unstated); a translation per further
//! language may replace any of the three (table `model_text`). Whoever
//! shows a text picks the visitor's language with a fallback to the
//! default ([`ModelTexts::pick`]) and marks it with the language it is in.
//! Same pattern as the tours: one trait, the SQL written once (`sql.rs`),
//! one macro implementing it for each backend (`backend.rs`).

mod backend;
pub(crate) mod sql;

pub(in crate::storage) use backend::text_storage;

use super::Result;
use async_trait::async_trait;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// One language's texts; a field left `None` falls back to the default.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Translation {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub title: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub credit: Option<String>,
}

impl Translation {
    pub fn is_empty(&self) -> bool {
        self.title.is_none() && self.description.is_none() && self.credit.is_none()
    }
}

/// Translations by BCP 47 tag, as given (`pt-BR`).
pub type Translations = BTreeMap<String, Translation>;

/// The languages of a version's texts: the default's tag and the
/// translations.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ModelTexts {
    /// The language of the version's own title, description and credit.
    pub language: Option<String>,
    pub translations: Translations,
}

/// Which of the three texts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextField {
    Title,
    Description,
    Credit,
}

impl TextField {
    fn of(self, t: &Translation) -> Option<&str> {
        match self {
            TextField::Title => t.title.as_deref(),
            TextField::Description => t.description.as_deref(),
            TextField::Credit => t.credit.as_deref(),
        }
    }
}

/// A text and the language it is in (`None`: not stated).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Picked<'a> {
    pub text: &'a str,
    pub language: Option<&'a str>,
}

impl ModelTexts {
    /// The best `field` for a visitor who prefers `wanted` (most wanted
    /// first): per preference, a text in exactly that language, then one
    /// that shares its primary subtag (`pt` for `pt-BR`, `pt-BR` for `pt`);
    /// the default text (`default`, in [`Self::language`]) counts as one
    /// more language. With no match, the default.
    pub fn pick<'a>(&'a self, field: TextField, default: &'a str, wanted: &[String]) -> Picked<'a> {
        let fallback = Picked {
            text: default,
            language: self.language.as_deref(),
        };
        let candidates = || {
            let own = self.language.as_deref().map(|tag| (tag, default));
            let translated = self
                .translations
                .iter()
                .filter_map(|(tag, t)| Some((tag.as_str(), field.of(t)?)));
            own.into_iter().chain(translated)
        };
        for want in wanted {
            let exact = candidates().find(|(tag, _)| tag.eq_ignore_ascii_case(want));
            let close = || candidates().find(|(tag, _)| same_primary(tag, want));
            if let Some((tag, text)) = exact.or_else(close) {
                return Picked {
                    text,
                    language: Some(tag),
                };
            }
        }
        fallback
    }

    /// `field` in every language it is written in: the default first (its
    /// language `None` when not stated), then each translation that gives
    /// it (a IIIF language map holds them all).
    pub fn every<'a>(
        &'a self,
        field: TextField,
        default: &'a str,
    ) -> impl Iterator<Item = (Option<&'a str>, &'a str)> + 'a {
        let translated = self
            .translations
            .iter()
            .filter_map(move |(tag, t)| Some((Some(tag.as_str()), field.of(t)?)));
        std::iter::once((self.language.as_deref(), default)).chain(translated)
    }

    /// The three texts for `wanted`, the default ones given.
    pub fn localize<'a>(
        &'a self,
        title: &'a str,
        description: &'a str,
        credit: Option<&'a str>,
        wanted: &[String],
    ) -> Localized<'a> {
        // A translated credit stands only where the version has a credit
        // at all: clearing the credit clears it in every language.
        let credit = credit.map(|c| self.pick(TextField::Credit, c, wanted));
        Localized {
            title: self.pick(TextField::Title, title, wanted),
            description: self.pick(TextField::Description, description, wanted),
            credit,
        }
    }
}

/// A version's texts in one visitor's language.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Localized<'a> {
    pub title: Picked<'a>,
    pub description: Picked<'a>,
    pub credit: Option<Picked<'a>>,
}

fn primary(tag: &str) -> &str {
    tag.split(['-', '_']).next().unwrap_or(tag)
}

fn same_primary(a: &str, b: &str) -> bool {
    primary(a).eq_ignore_ascii_case(primary(b))
}

/// A version's default texts and its translations, as `/admin` edits them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VersionTexts {
    pub title: String,
    pub description: String,
    pub credit: Option<String>,
    pub texts: ModelTexts,
}

/// Every method has a default that refuses, for storages without the table
/// (the service tests' doubles); both backends implement them all.
#[allow(unused_variables)] // the defaults ignore their arguments; the names document them
#[async_trait]
pub trait TextStorage: Send + Sync {
    /// A version's texts; `None` when the slug has no such version.
    async fn version_texts(&self, slug: &str, version: u32) -> Result<Option<VersionTexts>> {
        no_texts()
    }

    /// Replaces a version's default language and all its translations, in
    /// one transaction; `false` when the slug has no such version.
    async fn set_version_texts(
        &self,
        slug: &str,
        version: u32,
        texts: &ModelTexts,
    ) -> Result<bool> {
        no_texts()
    }

    /// The translated titles of every visible model, by slug (the gallery).
    async fn listed_titles(&self) -> Result<BTreeMap<String, Translations>> {
        Ok(BTreeMap::new())
    }
}

fn no_texts<T>() -> Result<T> {
    Err(super::StorageError::Unknown(
        "this storage keeps no texts in other languages".into(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texts() -> ModelTexts {
        let pt = Translation {
            title: Some("O profeta Daniel".into()),
            description: None,
            credit: Some("Digitalização: Museu".into()),
        };
        let es = Translation {
            title: Some("El profeta Daniel".into()),
            ..Translation::default()
        };
        ModelTexts {
            language: Some("en".into()),
            translations: [("pt-BR".to_owned(), pt), ("es".to_owned(), es)].into(),
        }
    }

    fn wanted(tags: &[&str]) -> Vec<String> {
        tags.iter().map(|t| (*t).to_owned()).collect()
    }

    #[test]
    fn picks_the_visitors_language_then_its_family_then_the_default() {
        let t = texts();
        let pick = |w: &[&str]| t.pick(TextField::Title, "The prophet Daniel", &wanted(w));
        assert_eq!(pick(&["pt-BR"]).text, "O profeta Daniel");
        assert_eq!(pick(&["pt"]).language, Some("pt-BR"));
        assert_eq!(pick(&["de", "es"]).text, "El profeta Daniel");
        assert_eq!(pick(&["de"]).language, Some("en"));
        assert_eq!(pick(&["en-GB", "pt"]).text, "The prophet Daniel");
        assert_eq!(pick(&[]).text, "The prophet Daniel");
    }

    #[test]
    fn a_missing_field_falls_back_field_by_field() {
        let t = texts();
        let l = t.localize(
            "Daniel",
            "A soapstone statue.",
            Some("Scan: Museum"),
            &wanted(&["pt"]),
        );
        assert_eq!(l.title.language, Some("pt-BR"));
        assert_eq!(l.description.text, "A soapstone statue.");
        assert_eq!(l.description.language, Some("en"));
        assert_eq!(l.credit.map(|c| c.text), Some("Digitalização: Museu"));
        // No credit on the version: none in any language.
        assert_eq!(
            t.localize("Daniel", "", None, &wanted(&["pt"])).credit,
            None
        );
    }

    #[test]
    fn an_unstated_default_language_is_only_the_fallback() {
        let mut t = texts();
        t.language = None;
        let p = t.pick(TextField::Title, "Daniel", &wanted(&["fr"]));
        assert_eq!((p.text, p.language), ("Daniel", None));
    }
}
