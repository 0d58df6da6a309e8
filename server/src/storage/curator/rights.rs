//! Who made a scan and on what terms it may be reused: a credit line and a
//! licence (or rights statement) per version. The viewer shows them under
//! the model, the model page states them to search engines, and a GLB
//! download carries them, so a scan that leaves the site keeps its credit.
//!
//! The licence is one of a fixed list, not free text: the Creative Commons
//! licences and public-domain tools museums publish open access under, and
//! the rightsstatements.org statements for what they cannot license. A
//! known identifier always links to the deed, and a typo cannot publish a
//! scan under terms nobody meant.

use serde::Serialize;

/// A licence or rights statement a version may be published under.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, utoipa::ToSchema)]
pub struct Licence {
    /// `CC-BY-4.0`, `CC0-1.0`, `InC`, … (SPDX identifiers for the Creative
    /// Commons licences, rightsstatements.org's own for its statements).
    pub id: &'static str,
    /// How it is named to a visitor: `CC BY 4.0`.
    pub name: &'static str,
    /// The deed or statement.
    pub url: &'static str,
}

const fn licence(id: &'static str, name: &'static str, url: &'static str) -> Licence {
    Licence { id, name, url }
}

/// Every licence and statement a version may name, in the order an upload
/// form offers them.
pub const LICENCES: [Licence; 14] = [
    licence(
        "CC0-1.0",
        "CC0 1.0 Universal",
        "https://creativecommons.org/publicdomain/zero/1.0/",
    ),
    licence(
        "PDM-1.0",
        "Public Domain Mark 1.0",
        "https://creativecommons.org/publicdomain/mark/1.0/",
    ),
    licence(
        "CC-BY-4.0",
        "CC BY 4.0",
        "https://creativecommons.org/licenses/by/4.0/",
    ),
    licence(
        "CC-BY-SA-4.0",
        "CC BY-SA 4.0",
        "https://creativecommons.org/licenses/by-sa/4.0/",
    ),
    licence(
        "CC-BY-NC-4.0",
        "CC BY-NC 4.0",
        "https://creativecommons.org/licenses/by-nc/4.0/",
    ),
    licence(
        "CC-BY-NC-SA-4.0",
        "CC BY-NC-SA 4.0",
        "https://creativecommons.org/licenses/by-nc-sa/4.0/",
    ),
    licence(
        "CC-BY-ND-4.0",
        "CC BY-ND 4.0",
        "https://creativecommons.org/licenses/by-nd/4.0/",
    ),
    licence(
        "CC-BY-NC-ND-4.0",
        "CC BY-NC-ND 4.0",
        "https://creativecommons.org/licenses/by-nc-nd/4.0/",
    ),
    licence(
        "InC",
        "In Copyright",
        "http://rightsstatements.org/vocab/InC/1.0/",
    ),
    licence(
        "InC-EDU",
        "In Copyright – Educational Use Permitted",
        "http://rightsstatements.org/vocab/InC-EDU/1.0/",
    ),
    licence(
        "InC-NC",
        "In Copyright – Non-Commercial Use Permitted",
        "http://rightsstatements.org/vocab/InC-NC/1.0/",
    ),
    licence(
        "NoC-NC",
        "No Copyright – Non-Commercial Use Only",
        "http://rightsstatements.org/vocab/NoC-NC/1.0/",
    ),
    licence(
        "NKC",
        "No Known Copyright",
        "http://rightsstatements.org/vocab/NKC/1.0/",
    ),
    licence(
        "CNE",
        "Copyright Not Evaluated",
        "http://rightsstatements.org/vocab/CNE/1.0/",
    ),
];

impl Licence {
    /// The licence with identifier `id` (exact, as listed).
    pub fn find(id: &str) -> Option<&'static Licence> {
        LICENCES.iter().find(|l| l.id == id)
    }
}

/// Longest credit line, in bytes: a line under the model, not a text.
pub const MAX_CREDIT_BYTES: usize = 300;

/// A version's credit line and licence; both optional (versions ingested
/// before they were recorded have neither).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Rights {
    /// `Scan: Museo Nacional, 2019`: shown as given, one line.
    pub credit: Option<String>,
    pub licence: Option<&'static Licence>,
}

impl Rights {
    /// Checks what a curator typed: the credit trimmed (blank is none), one
    /// line of at most [`MAX_CREDIT_BYTES`]; the licence one of [`LICENCES`]
    /// (blank is none). The error says what is wrong and what is allowed.
    pub fn parse(credit: Option<&str>, licence: Option<&str>) -> Result<Rights, String> {
        Ok(Rights {
            credit: parse_credit(credit)?,
            licence: parse_licence(licence)?,
        })
    }

    /// The columns as stored. A licence this build does not list (written
    /// by a newer one) is left out with a warning rather than hiding the
    /// model.
    pub fn from_stored(credit: Option<String>, licence: Option<String>) -> Rights {
        let licence = licence.as_deref().and_then(|id| {
            let found = Licence::find(id);
            if found.is_none() {
                tracing::warn!(licence = id, "stored licence is not one this build lists");
            }
            found
        });
        Rights { credit, licence }
    }

    /// The one line a GLB's `asset.copyright` carries: the credit, then the
    /// licence's name and deed. `None` when neither is recorded.
    pub fn notice(&self) -> Option<String> {
        let licence = self
            .licence
            .map(|l| format!("Licence: {} ({})", l.name, l.url));
        match (&self.credit, licence) {
            (Some(credit), Some(licence)) => Some(format!("{credit}. {licence}")),
            (Some(credit), None) => Some(credit.clone()),
            (None, licence) => licence,
        }
    }
}

/// A credit line as typed; `None` when blank.
pub fn parse_credit(credit: Option<&str>) -> Result<Option<String>, String> {
    let Some(credit) = credit.map(str::trim).filter(|c| !c.is_empty()) else {
        return Ok(None);
    };
    if credit.len() > MAX_CREDIT_BYTES {
        return Err(format!(
            "the credit line is {} bytes, more than {MAX_CREDIT_BYTES}",
            credit.len()
        ));
    }
    if credit.chars().any(char::is_control) {
        return Err(
            "the credit line must be one line of text (no line breaks or control characters)"
                .into(),
        );
    }
    Ok(Some(credit.to_owned()))
}

/// A licence identifier as typed; `None` when blank.
pub fn parse_licence(licence: Option<&str>) -> Result<Option<&'static Licence>, String> {
    let Some(id) = licence.map(str::trim).filter(|l| !l.is_empty()) else {
        return Ok(None);
    };
    Licence::find(id).map(Some).ok_or_else(|| {
        let ids: Vec<&str> = LICENCES.iter().map(|l| l.id).collect();
        format!("licence {id:?} must be one of {}", ids.join(", "))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identifiers_are_unique_and_deeds_are_links() {
        for (i, l) in LICENCES.iter().enumerate() {
            assert_eq!(Licence::find(l.id), Some(l));
            assert!(LICENCES[..i].iter().all(|m| m.id != l.id), "{} twice", l.id);
            assert!(
                l.url.starts_with("http") && l.url.ends_with('/'),
                "{}",
                l.url
            );
        }
    }

    #[test]
    fn what_a_curator_types_is_checked() {
        let r = Rights::parse(Some("  Scan: Museo, 2019 "), Some("CC-BY-4.0")).unwrap();
        assert_eq!(r.credit.as_deref(), Some("Scan: Museo, 2019"));
        assert_eq!(r.licence.map(|l| l.name), Some("CC BY 4.0"));
        assert_eq!(
            Rights::parse(Some(" "), Some("")).unwrap(),
            Rights::default()
        );
        assert_eq!(Rights::parse(None, None).unwrap(), Rights::default());
        let err = Rights::parse(None, Some("cc-by")).unwrap_err();
        assert!(
            err.contains("\"cc-by\"") && err.contains("CC-BY-4.0"),
            "{err}"
        );
        assert!(Rights::parse(Some("a\nb"), None).is_err());
        assert!(Rights::parse(Some(&"é".repeat(151)), None).is_err());
        assert!(Rights::parse(Some(&"é".repeat(150)), None).is_ok());
    }

    #[test]
    fn the_notice_names_credit_and_deed() {
        let both = Rights::parse(Some("Scan: Museo"), Some("CC0-1.0")).unwrap();
        assert_eq!(
            both.notice().unwrap(),
            "Scan: Museo. Licence: CC0 1.0 Universal \
             (https://creativecommons.org/publicdomain/zero/1.0/)"
        );
        let credit = Rights::parse(Some("Scan: Museo"), None).unwrap();
        assert_eq!(credit.notice().unwrap(), "Scan: Museo");
        let licence = Rights::parse(None, Some("InC")).unwrap();
        assert_eq!(
            licence.notice().unwrap(),
            "Licence: In Copyright (http://rightsstatements.org/vocab/InC/1.0/)"
        );
        assert_eq!(Rights::default().notice(), None);
    }
}
