//! A study's transitions and a session's plan: the transitions in order with
//! one control step (no transition) at a position drawn per session.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

/// Minimum time each of m_a and m_b is shown (thesis §6.6.2: 20 s).
pub const DEFAULT_STATE_SECONDS: f64 = 20.0;

/// A transition m_from → m_to, stored as `[from, to]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Transition(pub u32, pub u32);

impl Transition {
    pub fn from(self) -> u32 {
        self.0
    }
    pub fn to(self) -> u32 {
        self.1
    }
}

/// One step of a session: a transition, or the control step (from == to).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
pub struct Step {
    /// 1-based position in the session.
    pub step: u32,
    pub from: u32,
    pub to: u32,
    /// The step without a transition, which catches false positives.
    pub control: bool,
}

/// Q1, "Did you perceive an improvement during this step?"
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Improvement {
    None,
    ALittle,
    Improved,
    Greatly,
}

impl Improvement {
    pub const ALL: [Improvement; 4] = [
        Improvement::None,
        Improvement::ALittle,
        Improvement::Improved,
        Improvement::Greatly,
    ];

    pub fn as_str(self) -> &'static str {
        match self {
            Improvement::None => "none",
            Improvement::ALittle => "a-little",
            Improvement::Improved => "improved",
            Improvement::Greatly => "greatly",
        }
    }

    pub fn parse(s: &str) -> Option<Improvement> {
        Improvement::ALL.into_iter().find(|i| i.as_str() == s)
    }
}

/// The default transitions: every consecutive pair from the first level with
/// at least 1 % of the full level's vertices (the thesis wants a base "not too
/// degraded"; its Habacuc base held 1.16 %) up to the last level.
/// `vertices[k]` is level k's vertex count.
pub fn default_transitions(vertices: &[u32]) -> Vec<Transition> {
    let Some(&full) = vertices.last() else {
        return Vec::new();
    };
    let last = vertices.len() as u32 - 1;
    let first = vertices
        .iter()
        .position(|&v| f64::from(v) >= 0.01 * f64::from(full))
        .map_or(0, |k| k as u32)
        .min(last.saturating_sub(1));
    (first..last).map(|a| Transition(a, a + 1)).collect()
}

/// Checks transitions for a study shown through the page: at least one, each
/// m_a → m_b with a < b ≤ `last_level`, each starting where the previous one
/// ended (the page shows one continuous model).
pub fn check_transitions(transitions: &[Transition], last_level: u32) -> Result<(), String> {
    if transitions.is_empty() {
        return Err("a study needs at least one transition".into());
    }
    for (k, t) in transitions.iter().enumerate() {
        if t.from() >= t.to() {
            return Err(format!(
                "transition {} goes from level {} to level {}: it must go up",
                k + 1,
                t.from(),
                t.to()
            ));
        }
        if t.to() > last_level {
            return Err(format!(
                "transition {} ends at level {}, past the last level {last_level}",
                k + 1,
                t.to()
            ));
        }
        if k > 0 && transitions[k - 1].to() != t.from() {
            return Err(format!(
                "transition {} starts at level {}, not where transition {k} ended ({})",
                k + 1,
                t.from(),
                transitions[k - 1].to()
            ));
        }
    }
    Ok(())
}

/// Where the control step goes among `n` transitions (1-based, `1..=n + 1`):
/// drawn from `draw` (uniform in `0..1`), never first when there is a later
/// place, so the participant has seen a real transition before it.
pub fn control_position(n: usize, draw: f64) -> u32 {
    let (low, high) = if n >= 2 { (2, n) } else { (1, n + 1) };
    let span = (high - low + 1) as f64;
    (low + ((draw.clamp(0.0, 1.0 - f64::EPSILON) * span) as usize)) as u32
}

/// The session's steps: the transitions in order, and the control step at
/// `control_at`, showing the level on screen at that point.
pub fn session_plan(transitions: &[Transition], control_at: u32) -> Vec<Step> {
    let mut steps = Vec::with_capacity(transitions.len() + 1);
    let mut shown = transitions.first().map_or(0, |t| t.from());
    let mut transitions = transitions.iter();
    let total = steps.capacity() as u32;
    for step in 1..=total {
        if step == control_at {
            steps.push(Step {
                step,
                from: shown,
                to: shown,
                control: true,
            });
        } else if let Some(t) = transitions.next() {
            steps.push(Step {
                step,
                from: t.from(),
                to: t.to(),
                control: false,
            });
            shown = t.to();
        }
    }
    steps
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_transitions_start_at_one_percent() {
        let vertices = [5, 40, 100, 300, 1000, 4000];
        assert_eq!(
            default_transitions(&vertices),
            vec![
                Transition(1, 2),
                Transition(2, 3),
                Transition(3, 4),
                Transition(4, 5)
            ]
        );
        assert_eq!(default_transitions(&[10, 20]), vec![Transition(0, 1)]);
        assert!(default_transitions(&[10]).is_empty());
    }

    #[test]
    fn transitions_must_climb_continuously() {
        assert!(check_transitions(&[Transition(0, 1), Transition(1, 3)], 3).is_ok());
        assert!(check_transitions(&[], 3).is_err());
        assert!(check_transitions(&[Transition(1, 1)], 3).is_err());
        assert!(check_transitions(&[Transition(0, 4)], 3).is_err());
        let gap = check_transitions(&[Transition(0, 1), Transition(2, 3)], 3).unwrap_err();
        assert!(gap.contains("transition 2 starts at level 2"), "{gap}");
    }

    #[test]
    fn control_step_sits_between_transitions() {
        let t = [Transition(0, 1), Transition(1, 2), Transition(2, 3)];
        for (draw, at) in [(0.0, 2), (0.5, 3), (0.999, 3)] {
            assert_eq!(control_position(3, draw), at);
        }
        assert_eq!(control_position(1, 0.0), 1);
        assert_eq!(control_position(1, 0.9), 2);
        let plan = session_plan(&t, 3);
        let shape: Vec<_> = plan
            .iter()
            .map(|s| (s.step, s.from, s.to, s.control))
            .collect();
        assert_eq!(
            shape,
            vec![
                (1, 0, 1, false),
                (2, 1, 2, false),
                (3, 2, 2, true),
                (4, 2, 3, false)
            ]
        );
        assert_eq!(
            session_plan(&t, 1)[0],
            Step {
                step: 1,
                from: 0,
                to: 0,
                control: true
            }
        );
        assert_eq!(
            session_plan(&t, 4)[3],
            Step {
                step: 4,
                from: 3,
                to: 3,
                control: true
            }
        );
    }
}
