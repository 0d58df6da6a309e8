//! The level cap: the highest level a visitor may reach now.
//!
//! Three limits, the lowest wins (thesis §6.5): the model's audience policy
//! (public exhibition vs. researcher with a token; the full-resolution level
//! only where the policy allows it), the device class (a vertex budget per
//! class), and server load (pressure moves the cap from the last level down to
//! the model's good-enough level, see [`super::load`]).

use crate::storage::ModelRecord;
use serde::Serialize;
use utoipa::ToSchema;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum Audience {
    Public,
    Researcher,
    /// A participant of the model version's quality study, by invitation:
    /// every level, whatever the policy, device or load (a study must show
    /// m_n, and its sessions are few).
    Study,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum DeviceClass {
    Phone,
    Tablet,
    Desktop,
}

impl DeviceClass {
    pub fn parse(s: &str) -> Option<DeviceClass> {
        match s {
            "phone" | "mobile" => Some(DeviceClass::Phone),
            "tablet" => Some(DeviceClass::Tablet),
            "desktop" => Some(DeviceClass::Desktop),
            _ => None,
        }
    }
}

/// Which limit set the cap. Audience and device caps are answered with 403,
/// load caps with 429 and `Retry-After`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum CapReason {
    Audience,
    Device,
    Load,
}

/// Device budgets and the good-enough rule.
#[derive(Clone, Debug, PartialEq)]
pub struct CapRules {
    pub phone_max_vertices: u32,
    pub tablet_max_vertices: u32,
    /// Without a study result, the good-enough level is the first with at
    /// least this fraction of the full level's vertices (thesis: 0.2).
    pub good_enough_fraction: f64,
}

impl Default for CapRules {
    fn default() -> Self {
        CapRules {
            phone_max_vertices: 300_000,
            tablet_max_vertices: 1_000_000,
            good_enough_fraction: 0.2,
        }
    }
}

/// How far load has pushed caps down: `level` of `steps` (0 = no load cap,
/// `steps` = every cap at its model's good-enough level).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Pressure {
    pub level: u8,
    pub steps: u8,
}

impl Pressure {
    pub const NONE: Pressure = Pressure { level: 0, steps: 1 };
}

/// A cap and the three limits it was taken from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, ToSchema)]
pub struct LevelCap {
    /// Highest level the visitor may reach: batches `1..=level` may be fetched.
    pub level: u32,
    /// `None` when the visitor may reach the last level.
    pub reason: Option<CapReason>,
    pub audience: u32,
    pub device: u32,
    pub load: u32,
}

/// The first level with at least `fraction` of the full level's vertices,
/// unless the model has a study result.
pub fn good_enough_level(record: &ModelRecord, rules: &CapRules) -> u32 {
    let last = record.batch_count();
    if let Some(level) = record.good_enough_level {
        return level.min(last);
    }
    let full = f64::from(record.levels[last as usize].vertices);
    let target = full * rules.good_enough_fraction;
    record
        .levels
        .iter()
        .position(|l| f64::from(l.vertices) >= target)
        .map_or(last, |k| k as u32)
}

/// Highest level whose vertex count is within `budget` (level 0 at least).
fn highest_within(record: &ModelRecord, budget: f64) -> u32 {
    record
        .levels
        .iter()
        .rposition(|l| f64::from(l.vertices) <= budget)
        .unwrap_or(0) as u32
}

/// The policy's cap for an audience. The base mesh is always allowed, even
/// when a tiny model has no batches and the base is the full mesh.
pub fn audience_cap(record: &ModelRecord, audience: Audience) -> u32 {
    let last = record.batch_count();
    let policy = &record.policy;
    match audience {
        Audience::Study => last,
        Audience::Researcher if policy.token_full_resolution => last,
        Audience::Researcher => last.saturating_sub(1),
        Audience::Public => {
            let full = f64::from(record.levels[last as usize].vertices);
            let cap = highest_within(record, full * policy.public_max_vertex_fraction);
            if policy.public_full_resolution {
                cap
            } else {
                cap.min(last.saturating_sub(1))
            }
        }
    }
}

pub fn device_cap(record: &ModelRecord, device: DeviceClass, rules: &CapRules) -> u32 {
    match device {
        DeviceClass::Desktop => record.batch_count(),
        DeviceClass::Tablet => highest_within(record, f64::from(rules.tablet_max_vertices)),
        DeviceClass::Phone => highest_within(record, f64::from(rules.phone_max_vertices)),
    }
}

/// Linear between the last level (no pressure) and the good-enough level
/// (full pressure).
pub fn load_cap(record: &ModelRecord, pressure: Pressure, rules: &CapRules) -> u32 {
    let last = record.batch_count();
    let floor = good_enough_level(record, rules);
    let steps = u32::from(pressure.steps.max(1));
    let level = u32::from(pressure.level).min(steps);
    floor + (last - floor) * (steps - level) / steps
}

pub fn level_cap(
    record: &ModelRecord,
    audience: Audience,
    device: DeviceClass,
    pressure: Pressure,
    rules: &CapRules,
) -> LevelCap {
    let a = audience_cap(record, audience);
    let (d, l) = if audience == Audience::Study {
        (a, a)
    } else {
        (
            device_cap(record, device, rules),
            load_cap(record, pressure, rules),
        )
    };
    let level = a.min(d).min(l);
    // A lasting reason first: the viewer should not retry what load relief
    // would not change.
    let reason = if level == record.batch_count() {
        None
    } else if a == level {
        Some(CapReason::Audience)
    } else if d == level {
        Some(CapReason::Device)
    } else {
        Some(CapReason::Load)
    };
    LevelCap {
        level,
        reason,
        audience: a,
        device: d,
        load: l,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::storage::{AudiencePolicy, LevelRecord};

    fn record(vertices: &[u32], policy: AudiencePolicy) -> ModelRecord {
        ModelRecord {
            model_id: 1,
            slug: "m".into(),
            version: 1,
            kind: Default::default(),
            title: "M".into(),
            description: String::new(),
            policy,
            good_enough_level: None,
            created_at_ms: 0,
            compression_id: 1,
            quantization_bits: 12,
            has_colour: false,
            stream_format: vitrine_codec::VERSION,
            levels: vertices
                .iter()
                .map(|&v| LevelRecord {
                    vertices: v,
                    faces: 2 * v,
                    bytes: 1,
                    sha256: String::new(),
                    hausdorff: None,
                    rmse: None,
                    roy_rmse: None,
                })
                .collect(),
            mapping: None,
            textures: vec![],
            texts: Default::default(),
            has_study: false,
            curation: Default::default(),
        }
    }

    fn exhibition() -> AudiencePolicy {
        AudiencePolicy {
            name: "exhibition".into(),
            public_access: true,
            public_max_vertex_fraction: 1.0,
            public_full_resolution: false,
            token_full_resolution: true,
            downloads: false,
        }
    }

    const LEVELS: [u32; 7] = [100, 200, 400, 800, 1600, 3200, 6400];

    #[test]
    fn good_enough_is_first_level_with_a_fifth_of_the_vertices() {
        let mut r = record(&LEVELS, exhibition());
        assert_eq!(good_enough_level(&r, &CapRules::default()), 4); // 1280 needed
        r.good_enough_level = Some(2);
        assert_eq!(good_enough_level(&r, &CapRules::default()), 2);
        r.good_enough_level = Some(99);
        assert_eq!(good_enough_level(&r, &CapRules::default()), 6);
    }

    #[test]
    fn public_never_gets_full_resolution_on_exhibition() {
        let r = record(&LEVELS, exhibition());
        assert_eq!(audience_cap(&r, Audience::Public), 5);
        assert_eq!(audience_cap(&r, Audience::Researcher), 6);
        let mut half = exhibition();
        half.public_max_vertex_fraction = 0.5;
        half.public_full_resolution = true;
        assert_eq!(audience_cap(&record(&LEVELS, half), Audience::Public), 5);
        let mut quarter = exhibition();
        quarter.public_max_vertex_fraction = 0.25;
        assert_eq!(audience_cap(&record(&LEVELS, quarter), Audience::Public), 4);
    }

    #[test]
    fn device_budgets() {
        let r = record(&LEVELS, exhibition());
        let rules = CapRules {
            phone_max_vertices: 500,
            tablet_max_vertices: 2000,
            ..CapRules::default()
        };
        assert_eq!(device_cap(&r, DeviceClass::Phone, &rules), 2);
        assert_eq!(device_cap(&r, DeviceClass::Tablet, &rules), 4);
        assert_eq!(device_cap(&r, DeviceClass::Desktop, &rules), 6);
        let tiny = CapRules {
            phone_max_vertices: 10,
            ..rules
        };
        assert_eq!(device_cap(&r, DeviceClass::Phone, &tiny), 0);
    }

    #[test]
    fn load_moves_cap_down_to_good_enough() {
        let mut r = record(&[100, 200, 300, 400, 500, 600, 700, 800, 900], exhibition());
        r.good_enough_level = Some(4);
        let rules = CapRules::default();
        let caps: Vec<u32> = (0..=4)
            .map(|level| load_cap(&r, Pressure { level, steps: 4 }, &rules))
            .collect();
        assert_eq!(caps, vec![8, 7, 6, 5, 4]);
        assert_eq!(load_cap(&r, Pressure { level: 9, steps: 4 }, &rules), 4);
    }

    #[test]
    fn lowest_limit_wins_and_names_itself() {
        let open = AudiencePolicy {
            public_full_resolution: true,
            ..exhibition()
        };
        let r = record(&LEVELS, open);
        let rules = CapRules {
            phone_max_vertices: 500,
            ..CapRules::default()
        };
        let full = Pressure { level: 4, steps: 4 };
        let none = Pressure::NONE;
        let cap = level_cap(&r, Audience::Public, DeviceClass::Desktop, none, &rules);
        assert_eq!((cap.level, cap.reason), (6, None));
        let cap = level_cap(&r, Audience::Public, DeviceClass::Phone, full, &rules);
        assert_eq!((cap.level, cap.reason), (2, Some(CapReason::Device)));
        let cap = level_cap(&r, Audience::Public, DeviceClass::Desktop, full, &rules);
        assert_eq!((cap.level, cap.reason), (4, Some(CapReason::Load)));
        let r = record(&LEVELS, exhibition());
        let cap = level_cap(&r, Audience::Public, DeviceClass::Desktop, none, &rules);
        assert_eq!((cap.level, cap.reason), (5, Some(CapReason::Audience)));
        // A tie names the lasting reason, not load.
        let half = Pressure { level: 1, steps: 2 };
        let cap = level_cap(&r, Audience::Public, DeviceClass::Desktop, half, &rules);
        assert_eq!(
            (cap.level, cap.audience, cap.load, cap.reason),
            (5, 5, 5, Some(CapReason::Audience))
        );
    }
}
