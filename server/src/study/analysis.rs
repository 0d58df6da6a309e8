//! From answers to a level (seed 000 §6.6, with the definitions it lacks):
//! a session's good level is the first level ℓ where Q2 = yes at ℓ and at
//! every later level shown; a session that reports an improvement on the
//! control step is excluded; the model's level is the nearest-rank 90th
//! percentile of the valid sessions' levels.

use super::plan::Improvement;
use serde::Serialize;
use std::collections::BTreeMap;

/// The percentile the model's level is taken at.
pub const PERCENTILE: f64 = 0.9;

/// One answered step.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Judgement {
    pub step: u32,
    pub from: u32,
    pub to: u32,
    pub control: bool,
    pub improvement: Improvement,
    pub sufficient: bool,
}

/// A session's answers and what is known of it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SessionAnswers {
    pub participant: String,
    pub device: Option<String>,
    /// Every step of the plan answered (imported sessions are complete).
    pub complete: bool,
    pub answers: Vec<Judgement>,
}

/// Why a session does not count.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Exclusion {
    /// It reported an improvement where nothing changed.
    ControlImprovement,
    /// It has no control step, so its answers cannot be checked.
    NoControl,
    /// It stopped before the last step.
    Incomplete,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Excluded {
    pub participant: String,
    pub reason: Exclusion,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SessionLevel {
    pub participant: String,
    pub device: Option<String>,
    /// `None`: Q2 was "no" at the last level shown.
    pub good_level: Option<u32>,
}

/// Q1 and Q2 answers of valid sessions about one level (steps ending there).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct LevelCounts {
    pub level: u32,
    pub none: u32,
    pub a_little: u32,
    pub improved: u32,
    pub greatly: u32,
    pub sufficient: u32,
    pub insufficient: u32,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DeviceLevel {
    pub device: String,
    pub valid_sessions: usize,
    /// Only when the class has at least the minimum number of sessions.
    pub good_enough_level: Option<u32>,
}

/// `vitrine study report`'s answer.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// `None` when no session is valid.
    pub good_enough_level: Option<u32>,
    pub percentile: f64,
    pub valid_sessions: usize,
    pub excluded_sessions: usize,
    pub excluded: Vec<Excluded>,
    /// Valid sessions that never found a level sufficient: they count as
    /// needing the last level.
    pub never_sufficient: usize,
    pub min_participants: usize,
    /// `valid_sessions >= min_participants`.
    pub enough: bool,
    pub last_level: u32,
    pub sessions: Vec<SessionLevel>,
    pub levels: Vec<LevelCounts>,
    /// Q1 on the control steps of valid sessions (all "none" by definition).
    pub control_steps: usize,
    pub devices: Vec<DeviceLevel>,
}

/// The first level ℓ shown where Q2 = yes at ℓ and at every later level
/// shown (transitions only: the control step's Q2 repeats a level already
/// judged). `None` if Q2 was "no" at the last level shown.
pub fn good_level(answers: &[Judgement]) -> Option<u32> {
    let mut by_level: BTreeMap<u32, bool> = BTreeMap::new();
    for a in answers.iter().filter(|a| !a.control) {
        let all_yes = by_level.entry(a.to).or_insert(true);
        *all_yes &= a.sufficient;
    }
    let mut good = None;
    for (&level, &yes) in by_level.iter().rev() {
        if !yes {
            break;
        }
        good = Some(level);
    }
    good
}

/// Nearest rank: the smallest value with at least `p` of the values at or
/// below it (rank ⌈p·n⌉, 1-based).
pub fn nearest_rank(values: &mut [u32], p: f64) -> Option<u32> {
    if values.is_empty() {
        return None;
    }
    values.sort_unstable();
    let rank = ((p * values.len() as f64).ceil() as usize).clamp(1, values.len());
    Some(values[rank - 1])
}

fn exclusion(session: &SessionAnswers) -> Option<Exclusion> {
    if !session.complete {
        return Some(Exclusion::Incomplete);
    }
    let controls: Vec<_> = session.answers.iter().filter(|a| a.control).collect();
    if controls.is_empty() {
        Some(Exclusion::NoControl)
    } else if controls.iter().any(|a| a.improvement != Improvement::None) {
        Some(Exclusion::ControlImprovement)
    } else {
        None
    }
}

pub fn report(sessions: &[SessionAnswers], last_level: u32, min_participants: usize) -> Report {
    let mut excluded = Vec::new();
    let mut valid = Vec::new();
    for s in sessions {
        match exclusion(s) {
            Some(reason) => excluded.push(Excluded {
                participant: s.participant.clone(),
                reason,
            }),
            None => valid.push(s),
        }
    }
    let session_levels: Vec<SessionLevel> = valid
        .iter()
        .map(|s| SessionLevel {
            participant: s.participant.clone(),
            device: s.device.clone(),
            good_level: good_level(&s.answers),
        })
        .collect();
    let needed = |levels: &[&SessionLevel]| {
        let mut values: Vec<u32> = levels
            .iter()
            .map(|s| s.good_level.unwrap_or(last_level))
            .collect();
        nearest_rank(&mut values, PERCENTILE)
    };
    let all: Vec<&SessionLevel> = session_levels.iter().collect();
    let mut by_device: BTreeMap<&str, Vec<&SessionLevel>> = BTreeMap::new();
    for s in &session_levels {
        if let Some(d) = &s.device {
            by_device.entry(d).or_default().push(s);
        }
    }
    let devices = by_device
        .into_iter()
        .map(|(device, levels)| DeviceLevel {
            device: device.to_owned(),
            valid_sessions: levels.len(),
            good_enough_level: (levels.len() >= min_participants)
                .then(|| needed(&levels))
                .flatten(),
        })
        .collect();
    let mut levels: BTreeMap<u32, LevelCounts> = BTreeMap::new();
    let mut control_steps = 0;
    for a in valid.iter().flat_map(|s| &s.answers) {
        if a.control {
            control_steps += 1;
            continue;
        }
        let c = levels.entry(a.to).or_insert_with(|| LevelCounts {
            level: a.to,
            ..LevelCounts::default()
        });
        *match a.improvement {
            Improvement::None => &mut c.none,
            Improvement::ALittle => &mut c.a_little,
            Improvement::Improved => &mut c.improved,
            Improvement::Greatly => &mut c.greatly,
        } += 1;
        *if a.sufficient {
            &mut c.sufficient
        } else {
            &mut c.insufficient
        } += 1;
    }
    Report {
        good_enough_level: needed(&all),
        percentile: PERCENTILE,
        valid_sessions: valid.len(),
        excluded_sessions: excluded.len(),
        excluded,
        never_sufficient: session_levels
            .iter()
            .filter(|s| s.good_level.is_none())
            .count(),
        min_participants,
        enough: valid.len() >= min_participants,
        last_level,
        sessions: session_levels,
        levels: levels.into_values().collect(),
        control_steps,
        devices,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn step(step: u32, from: u32, to: u32, sufficient: bool) -> Judgement {
        Judgement {
            step,
            from,
            to,
            control: from == to,
            improvement: Improvement::ALittle,
            sufficient,
        }
    }

    #[test]
    fn good_level_needs_yes_from_there_on() {
        let a = [
            step(1, 0, 1, false),
            step(2, 1, 2, true),
            step(3, 2, 3, false),
            step(4, 3, 4, true),
            step(5, 4, 5, true),
        ];
        assert_eq!(good_level(&a), Some(4));
        let never = [step(1, 0, 1, true), step(2, 1, 2, false)];
        assert_eq!(good_level(&never), None);
        // The control step's Q2 does not count.
        let with_control = [
            step(1, 0, 1, true),
            step(2, 1, 1, false),
            step(3, 1, 2, true),
        ];
        assert_eq!(good_level(&with_control), Some(1));
    }

    #[test]
    fn nearest_rank_percentile() {
        assert_eq!(nearest_rank(&mut [7, 6, 7, 8], 0.9), Some(8));
        assert_eq!(
            nearest_rank(&mut [1, 2, 3, 4, 5, 6, 7, 8, 9, 10], 0.9),
            Some(9)
        );
        assert_eq!(nearest_rank(&mut [3], 0.9), Some(3));
        assert_eq!(nearest_rank(&mut [], 0.9), None);
    }

    #[test]
    fn control_improvement_and_incomplete_sessions_are_excluded() {
        let mut control = step(2, 1, 1, true);
        let good = SessionAnswers {
            participant: "a".into(),
            device: Some("desktop".into()),
            complete: true,
            answers: vec![step(1, 0, 1, false), control.clone(), step(3, 1, 2, true)],
        };
        control.improvement = Improvement::None;
        let mut fixed = good.clone();
        fixed.answers[1] = control;
        let mut partial = fixed.clone();
        partial.participant = "c".into();
        partial.complete = false;
        let mut unchecked = fixed.clone();
        unchecked.participant = "d".into();
        unchecked.answers.remove(1);
        let mut ok = fixed.clone();
        ok.participant = "b".into();
        let r = report(&[good, ok, partial, unchecked], 2, 1);
        assert_eq!(r.valid_sessions, 1);
        assert_eq!(r.excluded_sessions, 3);
        let reasons: Vec<_> = r
            .excluded
            .iter()
            .map(|e| (e.participant.as_str(), e.reason))
            .collect();
        assert_eq!(
            reasons,
            vec![
                ("a", Exclusion::ControlImprovement),
                ("c", Exclusion::Incomplete),
                ("d", Exclusion::NoControl)
            ]
        );
        assert_eq!(r.good_enough_level, Some(2));
        assert_eq!(r.levels.len(), 2);
        assert_eq!((r.levels[0].level, r.levels[0].insufficient), (1, 1));
        assert_eq!(r.devices[0].good_enough_level, Some(2));
    }

    #[test]
    fn never_sufficient_counts_as_the_last_level() {
        let control = Judgement {
            improvement: Improvement::None,
            ..step(2, 1, 1, true)
        };
        let s = |name: &str, last_yes: bool| SessionAnswers {
            participant: name.into(),
            device: None,
            complete: true,
            answers: vec![
                step(1, 0, 1, true),
                control.clone(),
                step(3, 1, 2, last_yes),
            ],
        };
        let r = report(&[s("a", true), s("b", false)], 2, 10);
        assert_eq!(r.never_sufficient, 1);
        assert_eq!(r.good_enough_level, Some(2));
        assert!(!r.enough);
    }

    /// Seed 000's Tabela 18: good levels 7, 6, 7, 8 give the model level 8.
    #[test]
    fn tabela_18_gives_level_8() {
        let text = include_str!("../../tests/fixtures/tabela18.csv");
        let sessions: Vec<SessionAnswers> = crate::study::csv::read(text.as_bytes(), 12)
            .unwrap()
            .into_iter()
            .map(|s| SessionAnswers {
                participant: s.participant,
                device: None,
                complete: true,
                answers: s.answers,
            })
            .collect();
        assert!(sessions.iter().all(|s| s.answers.len() == 13));
        let r = report(&sessions, 12, 4);
        let levels: Vec<_> = r.sessions.iter().map(|s| s.good_level).collect();
        assert_eq!(levels, vec![Some(7), Some(6), Some(7), Some(8)]);
        assert_eq!(
            (r.good_enough_level, r.valid_sessions, r.excluded_sessions),
            (Some(8), 4, 0)
        );
        assert!(r.enough);
        assert_eq!(r.control_steps, 4);
    }
}
