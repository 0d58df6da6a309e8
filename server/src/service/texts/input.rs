//! What a curator may write as a version's texts in other languages: one
//! translation per well-formed BCP 47 tag, each giving at least one of
//! title, description and credit, within the limits the pages can show.

use crate::service::curator::annotations::parse_language;
use crate::storage::{parse_credit, ModelTexts, Translation, Translations};
use serde::Deserialize;
use std::collections::BTreeMap;
use utoipa::ToSchema;

/// Most translations of one version.
pub const MAX_LANGUAGES: usize = 20;
/// Longest title, in characters.
pub const MAX_TITLE_CHARS: usize = 200;
/// Longest description, in characters.
pub const MAX_DESCRIPTION_CHARS: usize = 10_000;
/// Largest request body of a texts write (the guard refuses more with 413):
/// twenty descriptions at their longest fit.
pub const MAX_TEXTS_BYTES: usize = 1 << 20;

/// A version's default language and every translation, replacing what
/// was there.
#[derive(Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct TextsInput {
    /// The BCP 47 tag of the version's own title, description and credit,
    /// or null when not stated.
    #[serde(default)]
    language: Option<String>,
    /// Per BCP 47 tag, `{"title", "description", "credit"}`, each optional
    /// (absent or blank: the version's own text stands); at most 20.
    #[serde(default)]
    #[schema(value_type = Object)]
    translations: BTreeMap<String, TranslationInput>,
}

/// One language's texts as typed.
#[derive(Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct TranslationInput {
    /// 1–200 characters.
    #[serde(default)]
    title: Option<String>,
    /// Up to 10,000 characters.
    #[serde(default)]
    description: Option<String>,
    /// One line, at most 300 bytes.
    #[serde(default)]
    credit: Option<String>,
}

impl TextsInput {
    /// The texts to store, or what is wrong with them.
    pub fn validate(self) -> Result<ModelTexts, String> {
        let language = match self.language.as_deref().map(str::trim) {
            None | Some("") => None,
            Some(tag) => Some(parse_language(tag)?),
        };
        if self.translations.len() > MAX_LANGUAGES {
            return Err(format!(
                "{} translations, more than {MAX_LANGUAGES}",
                self.translations.len()
            ));
        }
        let mut translations = Translations::new();
        for (tag, t) in self.translations {
            let (tag, translation) = translation(&tag, t.title, t.description, t.credit)?;
            if language
                .as_deref()
                .is_some_and(|own| own.eq_ignore_ascii_case(&tag))
            {
                return Err(format!(
                    "{tag} is the language of the version's own texts; edit those instead"
                ));
            }
            if translations.keys().any(|k| k.eq_ignore_ascii_case(&tag)) {
                return Err(format!("{tag} is given twice"));
            }
            translations.insert(tag, translation);
        }
        Ok(ModelTexts {
            language,
            translations,
        })
    }
}

/// One translation as typed (also `vitrine texts`): trimmed, blank fields
/// dropped, checked.
pub fn translation(
    tag: &str,
    title: Option<String>,
    description: Option<String>,
    credit: Option<String>,
) -> Result<(String, Translation), String> {
    let tag = parse_language(tag.trim())?;
    let blank_to_none =
        |s: Option<String>| s.map(|s| s.trim().to_owned()).filter(|s| !s.is_empty());
    let title = blank_to_none(title);
    if let Some(title) = &title {
        let chars = title.chars().count();
        if chars > MAX_TITLE_CHARS || title.chars().any(char::is_control) {
            return Err(format!(
                "the {tag} title must be one line of at most {MAX_TITLE_CHARS} characters \
                 ({chars} given)"
            ));
        }
    }
    let description = blank_to_none(description);
    if let Some(description) = &description {
        let chars = description.chars().count();
        if chars > MAX_DESCRIPTION_CHARS {
            return Err(format!(
                "the {tag} description is {chars} characters, more than {MAX_DESCRIPTION_CHARS}"
            ));
        }
    }
    let credit = parse_credit(credit.as_deref()).map_err(|e| format!("{tag}: {e}"))?;
    let translation = Translation {
        title,
        description,
        credit,
    };
    if translation.is_empty() {
        return Err(format!("the {tag} translation gives no text"));
    }
    Ok((tag, translation))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn input(value: serde_json::Value) -> Result<ModelTexts, String> {
        serde_json::from_value::<TextsInput>(value)
            .map_err(|e| e.to_string())?
            .validate()
    }

    #[test]
    fn keeps_what_is_given_and_drops_blanks() {
        let texts = input(json!({
            "language": " en ",
            "translations": { "pt-BR": { "title": " O profeta ", "description": "  " } }
        }))
        .unwrap();
        assert_eq!(texts.language.as_deref(), Some("en"));
        let pt = &texts.translations["pt-BR"];
        assert_eq!(pt.title.as_deref(), Some("O profeta"));
        assert_eq!(pt.description, None);
    }

    #[test]
    fn refuses_what_no_page_could_show() {
        let long = "x".repeat(MAX_TITLE_CHARS + 1);
        for bad in [
            json!({ "translations": { "not a tag": { "title": "t" } } }),
            json!({ "translations": { "pt": {} } }),
            json!({ "translations": { "pt": { "title": long } } }),
            json!({ "translations": { "pt": { "title": "two\nlines" } } }),
            json!({ "translations": { "pt": { "credit": "a\nb" } } }),
            json!({ "language": "pt", "translations": { "PT": { "title": "t" } } }),
            json!({ "translations": { "pt": { "title": "a" }, "PT": { "title": "b" } } }),
            json!({ "translations": { "pt": { "subtitle": "t" } } }),
        ] {
            assert!(input(bad.clone()).is_err(), "{bad}");
        }
        let many: serde_json::Map<_, _> = (0..=MAX_LANGUAGES)
            .map(|i| (format!("x-l{i}"), json!({ "title": "t" })))
            .collect();
        assert!(input(json!({ "translations": many })).is_err());
    }
}
