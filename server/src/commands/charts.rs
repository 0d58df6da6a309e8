//! `--charts`: whether a mesh's stream is cut into charts that decode on
//! several cores (format 5, `codec/core/FORMAT.md`), or into nested charts
//! for view-dependent streaming (format 6).

use std::str::FromStr;
use vitrine_codec::{Charts, MAX_CHARTS};

/// `off`, `auto`, a number of charts (2–64) or `nested`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ChartsArg(pub Charts);

impl FromStr for ChartsArg {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "off" | "1" => Ok(ChartsArg(Charts::Off)),
            "auto" => Ok(ChartsArg(Charts::Auto)),
            "nested" => Ok(ChartsArg(Charts::Nested)),
            n => match n.parse::<u32>() {
                Ok(k) if (2..=MAX_CHARTS as u32).contains(&k) => Ok(ChartsArg(Charts::Count(k))),
                _ => Err(format!(
                    "`{s}`: expected off, auto, nested or a number of charts from 2 to {MAX_CHARTS}"
                )),
            },
        }
    }
}

impl std::fmt::Display for ChartsArg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            Charts::Off => f.write_str("off"),
            Charts::Auto | Charts::PerVertices(_) => f.write_str("auto"),
            Charts::Count(k) => write!(f, "{k}"),
            Charts::Nested | Charts::NestedShape { .. } => f.write_str("nested"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_off_auto_and_counts() {
        assert_eq!("off".parse(), Ok(ChartsArg(Charts::Off)));
        assert_eq!("auto".parse(), Ok(ChartsArg(Charts::Auto)));
        assert_eq!("8".parse(), Ok(ChartsArg(Charts::Count(8))));
        assert_eq!("nested".parse(), Ok(ChartsArg(Charts::Nested)));
        assert_eq!("nested".parse::<ChartsArg>().unwrap().to_string(), "nested");
        for bad in ["0", "65", "many", "-2", ""] {
            assert!(bad.parse::<ChartsArg>().is_err(), "{bad}");
        }
        assert_eq!("auto".parse::<ChartsArg>().unwrap().to_string(), "auto");
    }
}
