//! The study's answers as CSV, for answers gathered elsewhere (paper, a lab
//! tool) and for analysis outside Vitrine:
//! `participant,step,from_level,to_level,control,improvement,sufficient`.
//! A malformed row is an error naming its line; nothing of a bad file is kept.

use super::analysis::Judgement;
use super::plan::Improvement;
use std::collections::{BTreeMap, HashSet};
use std::io::{Read, Write};

pub const HEADER: [&str; 7] = [
    "participant",
    "step",
    "from_level",
    "to_level",
    "control",
    "improvement",
    "sufficient",
];

/// Rows one file may hold (a study of 1,000 participants × 100 steps).
pub const MAX_ROWS: usize = 100_000;
const MAX_PARTICIPANT_CHARS: usize = 64;

/// One participant's rows, in step order.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportedSession {
    pub participant: String,
    pub answers: Vec<Judgement>,
}

#[derive(Debug, thiserror::Error)]
#[error("line {line}: {message}")]
pub struct CsvError {
    pub line: u64,
    pub message: String,
}

fn at(line: u64, message: impl Into<String>) -> CsvError {
    CsvError {
        line,
        message: message.into(),
    }
}

/// Reads every row, checking each against the model's `last_level`.
pub fn read(input: impl Read, last_level: u32) -> Result<Vec<ImportedSession>, CsvError> {
    let mut reader = ::csv::ReaderBuilder::new()
        .trim(::csv::Trim::All)
        .from_reader(input);
    let header = reader.headers().map_err(|e| at(1, e.to_string()))?;
    if header.iter().ne(HEADER) {
        return Err(at(
            1,
            format!(
                "the header must be {:?}, not {:?}",
                HEADER.join(","),
                header.iter().collect::<Vec<_>>().join(",")
            ),
        ));
    }
    let mut sessions: BTreeMap<String, Vec<Judgement>> = BTreeMap::new();
    let mut seen = HashSet::new();
    let mut rows = 0usize;
    for record in reader.records() {
        let record = record.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            at(line, e.to_string())
        })?;
        let line = record.position().map_or(0, |p| p.line());
        rows += 1;
        if rows > MAX_ROWS {
            return Err(at(line, format!("more than {MAX_ROWS} rows")));
        }
        let participant = record[0].to_owned();
        if participant.is_empty() || participant.chars().count() > MAX_PARTICIPANT_CHARS {
            return Err(at(
                line,
                format!("participant must be 1 to {MAX_PARTICIPANT_CHARS} characters"),
            ));
        }
        let number = |i: usize| -> Result<u32, CsvError> {
            record[i].parse().map_err(|_| {
                at(
                    line,
                    format!("{} {:?} is not a whole number", HEADER[i], &record[i]),
                )
            })
        };
        let (step, from, to) = (number(1)?, number(2)?, number(3)?);
        let control = match &record[4] {
            "true" => true,
            "false" => false,
            other => {
                return Err(at(
                    line,
                    format!("control must be true or false, not {other:?}"),
                ))
            }
        };
        let improvement = Improvement::parse(&record[5]).ok_or_else(|| {
            at(
                line,
                format!(
                    "improvement must be none, a-little, improved or greatly, not {:?}",
                    &record[5]
                ),
            )
        })?;
        let sufficient = match &record[6] {
            "yes" => true,
            "no" => false,
            other => {
                return Err(at(
                    line,
                    format!("sufficient must be yes or no, not {other:?}"),
                ))
            }
        };
        if step == 0 {
            return Err(at(line, "steps count from 1"));
        }
        if to > last_level {
            return Err(at(
                line,
                format!("to_level {to} is past the model's last level {last_level}"),
            ));
        }
        if control && from != to {
            return Err(at(line, "a control step has from_level = to_level"));
        }
        if !control && from >= to {
            return Err(at(
                line,
                format!("a transition goes up: from_level {from} to_level {to}"),
            ));
        }
        if !seen.insert((participant.clone(), step)) {
            return Err(at(
                line,
                format!("participant {participant:?} answers step {step} twice"),
            ));
        }
        sessions.entry(participant).or_default().push(Judgement {
            step,
            from,
            to,
            control,
            improvement,
            sufficient,
        });
    }
    if sessions.is_empty() {
        return Err(at(1, "the file has no answers"));
    }
    Ok(sessions
        .into_iter()
        .map(|(participant, mut answers)| {
            answers.sort_by_key(|a| a.step);
            ImportedSession {
                participant,
                answers,
            }
        })
        .collect())
}

/// Writes sessions' answers in the import format.
pub fn write<'a>(
    output: impl Write,
    sessions: impl IntoIterator<Item = (&'a str, &'a [Judgement])>,
) -> std::io::Result<()> {
    let mut writer = ::csv::Writer::from_writer(output);
    writer.write_record(HEADER)?;
    for (participant, answers) in sessions {
        for a in answers {
            writer.write_record([
                participant,
                &a.step.to_string(),
                &a.from.to_string(),
                &a.to.to_string(),
                if a.control { "true" } else { "false" },
                a.improvement.as_str(),
                if a.sufficient { "yes" } else { "no" },
            ])?;
        }
    }
    writer.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = "participant,step,from_level,to_level,control,improvement,sufficient\n\
        p1,1,0,1,false,greatly,no\n\
        p1,2,1,1,true,none,no\n\
        p1,3,1,2,false,a-little,yes\n\
        p2,1,0,1,false,improved,yes\n";

    #[test]
    fn round_trip() {
        let sessions = read(GOOD.as_bytes(), 2).unwrap();
        assert_eq!(sessions.len(), 2);
        assert_eq!(sessions[0].answers.len(), 3);
        assert!(sessions[0].answers[1].control);
        let mut out = Vec::new();
        write(
            &mut out,
            sessions
                .iter()
                .map(|s| (s.participant.as_str(), s.answers.as_slice())),
        )
        .unwrap();
        assert_eq!(String::from_utf8(out).unwrap(), GOOD);
    }

    #[test]
    fn bad_rows_name_their_line() {
        let cases = [
            ("p1,1,0,1,maybe,none,no", 2, "control"),
            ("p1,1,0,1,false,lots,no", 2, "improvement"),
            ("p1,1,0,1,false,none,perhaps", 2, "sufficient"),
            ("p1,1,0,9,false,none,no", 2, "last level"),
            ("p1,1,1,1,false,none,no", 2, "goes up"),
            ("p1,1,0,1,true,none,no", 2, "control step"),
            ("p1,x,0,1,false,none,no", 2, "whole number"),
            ("p1,0,0,1,false,none,no", 2, "from 1"),
            ("p1,1,0,1,false,none", 2, "fields"),
        ];
        for (row, line, what) in cases {
            let text = format!("{}\n{row}\n", HEADER.join(","));
            let e = read(text.as_bytes(), 2).unwrap_err();
            assert_eq!(e.line, line, "{row}: {e}");
            assert!(e.to_string().contains(what), "{row}: {e}");
        }
        let twice = format!("{GOOD}p2,1,0,1,false,none,no\n");
        let e = read(twice.as_bytes(), 2).unwrap_err();
        assert_eq!(e.line, 6);
        assert!(e.to_string().contains("twice"), "{e}");
        let e = read("participant,step\np1,1\n".as_bytes(), 2).unwrap_err();
        assert_eq!(e.line, 1);
        assert!(read(format!("{}\n", HEADER.join(",")).as_bytes(), 2).is_err());
    }
}
