//! A museum's own words in the viewer: `[ui.strings.<language>]` tables in
//! `vitrine serve`'s TOML file put text in place of any message of the
//! viewer's catalogues (`web/src/i18n/`), per language, without editing
//! code:
//!
//! ```toml
//! [ui.strings.en]
//! "page.allModels" = "← All stories"
//!
//! [ui.strings.pt.page]
//! allModels = "← Todas as histórias"   # the same as "page.allModels"
//! ```
//!
//! Every page of the viewer carries them in a JSON script element that the
//! viewer reads before it writes any text (`web/src/i18n/switch.js`); a
//! key the catalogues lack is carried and never shown.

use super::language::is_supported;
use std::collections::BTreeMap;
use std::fmt;

/// The longest text one message may be given, in bytes.
const MAX_TEXT_BYTES: usize = 4096;

/// Text per language (a supported code) and catalogue key (`page.allModels`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct UiStrings(BTreeMap<String, BTreeMap<String, String>>);

/// Why the `ui` table was refused: the setting's path, and what is wrong.
#[derive(Debug, PartialEq, Eq)]
pub struct UiStringsError {
    pub at: String,
    pub problem: String,
}

impl fmt::Display for UiStringsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "`{}`: {}", self.at, self.problem)
    }
}

impl std::error::Error for UiStringsError {}

impl UiStrings {
    /// Reads the file's `ui` table, whose one key is `strings`.
    pub fn from_toml(ui: &toml::Value) -> Result<UiStrings, UiStringsError> {
        let refuse = |at: &str, problem: &str| UiStringsError {
            at: at.to_owned(),
            problem: problem.to_owned(),
        };
        let table = ui
            .as_table()
            .ok_or_else(|| refuse("ui", "expected a table"))?;
        let mut strings = BTreeMap::new();
        for (key, value) in table {
            if key != "strings" {
                return Err(refuse(
                    &format!("ui.{key}"),
                    "unknown setting (`ui.strings` is the one)",
                ));
            }
            let languages = value
                .as_table()
                .ok_or_else(|| refuse("ui.strings", "expected a table of languages"))?;
            for (code, messages) in languages {
                let at = format!("ui.strings.{code}");
                if !is_supported(code) {
                    return Err(refuse(
                        &at,
                        "not a language the viewer speaks (en, pt, es, fr, de, it, ar)",
                    ));
                }
                let messages = messages
                    .as_table()
                    .ok_or_else(|| refuse(&at, "expected a table of messages"))?;
                let mut flat = BTreeMap::new();
                flatten(&at, "", messages, &mut flat)?;
                strings.insert(code.clone(), flat);
            }
        }
        Ok(UiStrings(strings))
    }

    pub fn is_empty(&self) -> bool {
        self.0.values().all(BTreeMap::is_empty)
    }

    /// The text given for `key` in `language`, if any.
    pub fn get(&self, language: &str, key: &str) -> Option<&str> {
        self.0.get(language)?.get(key).map(String::as_str)
    }

    /// The element each page carries before `</head>`: a JSON script, its
    /// `<` written `\u003c` so that no text can end it; empty when no
    /// string is given.
    pub fn script(&self) -> String {
        if self.is_empty() {
            return String::new();
        }
        let json = serde_json::to_string(&self.0)
            .unwrap_or_else(|_| "{}".to_owned())
            .replace('<', "\\u003c");
        format!("<script type=\"application/json\" id=\"vitrine-ui-strings\">{json}</script>\n")
    }
}

/// `page.allModels = "…"` and `[…page] allModels = "…"` alike become
/// `"page.allModels"`; each key part is a catalogue key's (letters only).
fn flatten(
    at: &str,
    prefix: &str,
    table: &toml::Table,
    out: &mut BTreeMap<String, String>,
) -> Result<(), UiStringsError> {
    for (part, value) in table {
        let key = if prefix.is_empty() {
            part.clone()
        } else {
            format!("{prefix}.{part}")
        };
        let here = format!("{at}.\"{key}\"");
        let refuse = |problem: &str| UiStringsError {
            at: here.clone(),
            problem: problem.to_owned(),
        };
        let well_formed = key
            .split('.')
            .all(|p| !p.is_empty() && p.chars().all(|c| c.is_ascii_alphabetic()));
        if !well_formed {
            return Err(refuse(
                "not a catalogue key (words of letters joined by dots, as `page.allModels`)",
            ));
        }
        match value {
            toml::Value::String(text) if text.trim().is_empty() => {
                return Err(refuse("empty text"))
            }
            toml::Value::String(text) if text.len() > MAX_TEXT_BYTES => {
                return Err(refuse(&format!("longer than {MAX_TEXT_BYTES} bytes")))
            }
            toml::Value::String(text) => {
                out.insert(key, text.clone());
            }
            toml::Value::Table(inner) => flatten(at, &key, inner, out)?,
            other => {
                return Err(refuse(&format!(
                    "expected text, found {}",
                    other.type_str()
                )))
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<UiStrings, UiStringsError> {
        let table: toml::Table = text.parse().expect("valid TOML");
        UiStrings::from_toml(&table["ui"])
    }

    #[test]
    fn dotted_keys_and_nested_tables_are_the_same_message() {
        let strings = parse(
            "[ui.strings.en]\n\"page.allModels\" = \"← All stories\"\n\
             [ui.strings.pt.page]\nallModels = \"← Todas as histórias\"\n",
        )
        .expect("accepted");
        assert_eq!(strings.get("en", "page.allModels"), Some("← All stories"));
        assert_eq!(
            strings.get("pt", "page.allModels"),
            Some("← Todas as histórias")
        );
        assert_eq!(strings.get("de", "page.allModels"), None);
    }

    #[test]
    fn the_script_cannot_be_ended_by_a_text() {
        let strings =
            parse("[ui.strings.en]\n\"gallery.intro\" = \"</script><b>x\"\n").expect("accepted");
        let script = strings.script();
        assert!(script
            .starts_with("<script type=\"application/json\" id=\"vitrine-ui-strings\">{\"en\":"));
        assert_eq!(script.matches("</script>").count(), 1, "{script}");
        assert!(script.contains("\\u003c/script>\\u003cb>x"), "{script}");
        assert_eq!(UiStrings::default().script(), "");
    }

    #[test]
    fn refusals_name_the_setting() {
        let cases = [
            ("[ui.strings.ja]\n\"page.embed\" = \"x\"\n", "ui.strings.ja"),
            (
                "[ui.strings.en]\n\"page embed\" = \"x\"\n",
                "ui.strings.en.\"page embed\"",
            ),
            (
                "[ui.strings.en]\n\"page.embed\" = 3\n",
                "ui.strings.en.\"page.embed\"",
            ),
            (
                "[ui.strings.en]\n\"page.embed\" = \" \"\n",
                "ui.strings.en.\"page.embed\"",
            ),
            ("[ui.colours]\nx = 1\n", "ui.colours"),
        ];
        for (text, at) in cases {
            assert_eq!(parse(text).expect_err(text).at, at, "{text}");
        }
    }
}
