//! `--charts`: whether a mesh's stream is cut into charts that decode on
//! several cores (format 5, `codec/core/FORMAT.md`), or into nested charts
//! for view-dependent streaming (format 6).

use std::str::FromStr;
use vitrine_codec::{Charts, NestedShape, MAX_CHARTS};

/// `off`, `auto`, a number of charts (2–64), `nested` or
/// `nested:TOP,FANOUT,PHASES`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ChartsArg(pub Charts);

impl FromStr for ChartsArg {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "off" | "1" => Ok(ChartsArg(Charts::Off)),
            "auto" => Ok(ChartsArg(Charts::Auto)),
            "nested" => Ok(ChartsArg(Charts::Nested)),
            _ if s.starts_with("nested:") => nested_shape(&s["nested:".len()..])
                .map(ChartsArg)
                .ok_or_else(|| {
                    format!(
                        "`{s}`: expected nested:TOP,FANOUT,PHASES with 2–{MAX_CHARTS} top charts, \
                         1–{MAX_CHARTS} children and at least one phase (a tree of at most \
                         {} leaves)",
                        vitrine_codec::MAX_PHASE_CHARTS
                    )
                }),
            n => match n.parse::<u32>() {
                Ok(k) if (2..=MAX_CHARTS as u32).contains(&k) => Ok(ChartsArg(Charts::Count(k))),
                _ => Err(format!(
                    "`{s}`: expected off, auto, nested, nested:TOP,FANOUT,PHASES or a number of \
                     charts from 2 to {MAX_CHARTS}"
                )),
            },
        }
    }
}

/// `TOP,FANOUT,PHASES`, checked as the encoder checks a shape, so that a
/// shape it would refuse fails here, before any work.
fn nested_shape(text: &str) -> Option<Charts> {
    let numbers: Vec<u8> = text
        .split(',')
        .map(|n| n.trim().parse::<u8>().ok())
        .collect::<Option<_>>()?;
    let [top, fanout, phases] = numbers[..] else {
        return None;
    };
    NestedShape::new(top.into(), fanout.into(), phases.into()).ok()?;
    Some(Charts::NestedShape {
        top,
        fanout,
        phases,
    })
}

impl std::fmt::Display for ChartsArg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            Charts::Off => f.write_str("off"),
            Charts::Auto | Charts::PerVertices(_) => f.write_str("auto"),
            Charts::Count(k) => write!(f, "{k}"),
            Charts::Nested => f.write_str("nested"),
            Charts::NestedShape {
                top,
                fanout,
                phases,
            } => write!(f, "nested:{top},{fanout},{phases}"),
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

    #[test]
    fn parses_a_nested_shape() {
        let shape = Charts::NestedShape {
            top: 2,
            fanout: 2,
            phases: 3,
        };
        assert_eq!("nested:2,2,3".parse(), Ok(ChartsArg(shape)));
        assert_eq!(ChartsArg(shape).to_string(), "nested:2,2,3");
        assert_eq!(
            "nested:4,3,1".parse::<ChartsArg>().unwrap().to_string(),
            "nested:4,3,1"
        );
        // Out of the encoder's range (1 top chart, 0 children, no phase,
        // too many leaves) or not three numbers.
        for bad in [
            "nested:1,2,3",
            "nested:2,0,3",
            "nested:2,2,0",
            "nested:64,64,64",
            "nested:2,2",
            "nested:2,2,3,4",
            "nested:",
            "nested:a,b,c",
            "nested:2,2,300",
        ] {
            assert!(bad.parse::<ChartsArg>().is_err(), "{bad}");
        }
    }
}
