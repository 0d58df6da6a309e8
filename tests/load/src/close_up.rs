//! Close-up visitors (issue 41): each looks closely at one region of a
//! charted (format 5) or nested (format 6) stream and fetches what the
//! viewer's view-dependent refinement would for it (`web/src/part-refinement.js`):
//! the whole batches before the charts begin, then the part index, the
//! first parted batch's head, and from there only the parts of the chart
//! under its camera, and in a nested stream its ancestors' parts and the
//! split entries on the way down to it.
//!
//! The region is one leaf chart, drawn per visitor, so a crowd's visitors
//! spread over the object as a museum's visitors do; they share the prefix
//! and the top charts' parts, the server's payload cache holds those.

use serde::Deserialize;
use std::collections::{BTreeMap, HashMap};

/// The part index (`server/src/service/parts.rs`), the fields read here.
#[derive(Deserialize)]
pub struct PartIndex {
    phases: usize,
    first_level: usize,
    head_url: String,
    part_url: String,
    parts: Vec<PartEntry>,
    #[serde(default)]
    split_url: Option<String>,
    #[serde(default)]
    splits: Vec<SplitEntry>,
}

#[derive(Deserialize)]
struct PartEntry {
    level: usize,
    chart: usize,
    phase: usize,
    #[serde(default)]
    parent: Option<usize>,
    bytes: u64,
}

#[derive(Deserialize)]
struct SplitEntry {
    level: usize,
    parent: usize,
    bytes: u64,
}

/// What one close-up fetches from the first parted batch on.
#[derive(Debug, PartialEq)]
pub struct ClosePath {
    pub first_level: usize,
    /// For each level from `first_level`: the URLs fetched for it, in
    /// order (the first also carries the head), and their bytes.
    pub steps: Vec<(Vec<String>, u64)>,
}

impl PartIndex {
    /// The path down to leaf chart `pick` × (leaves) of the last phase
    /// (`pick` in [0, 1)).
    pub fn close_path(&self, pick: f64) -> Result<ClosePath, String> {
        let last = self
            .phases
            .checked_sub(1)
            .ok_or("an index without phases")?;
        let leaves: BTreeMap<usize, Option<usize>> = self
            .parts
            .iter()
            .filter(|p| p.phase == last)
            .map(|p| (p.chart, p.parent))
            .collect();
        if leaves.is_empty() {
            return Err("no chart in the last phase".into());
        }
        let n = leaves.len();
        let leaf = *leaves
            .keys()
            .nth(((pick.clamp(0.0, 1.0) * n as f64) as usize).min(n - 1))
            .ok_or("no leaf")?;
        // The chart on the path in each phase, leaf first, up to phase 0.
        let parents: HashMap<(usize, usize), Option<usize>> = self
            .parts
            .iter()
            .map(|p| ((p.phase, p.chart), p.parent))
            .collect();
        let mut chain = vec![leaf];
        for phase in (1..=last).rev() {
            let chart = chain[chain.len() - 1];
            let parent = parents
                .get(&(phase, chart))
                .copied()
                .flatten()
                .ok_or_else(|| format!("chart {chart} of phase {phase} has no parent"))?;
            chain.push(parent);
        }
        chain.reverse();
        // The path's part in each batch, found in one pass (an index of a
        // 25 M-vertex stream has some 8,000 parts; every visitor reads it).
        let on_path: HashMap<usize, &PartEntry> = self
            .parts
            .iter()
            .filter(|p| chain.get(p.phase) == Some(&p.chart))
            .map(|p| (p.level, p))
            .collect();

        let levels: BTreeMap<usize, usize> =
            self.parts.iter().map(|p| (p.level, p.phase)).collect();
        let mut steps = Vec::with_capacity(levels.len());
        let mut previous_phase = None;
        for (&level, &phase) in &levels {
            let mut urls = Vec::new();
            let mut bytes = 0;
            if level == self.first_level {
                urls.push(self.head_url.clone());
            }
            if phase > 0 && previous_phase != Some(phase) {
                let parent = chain[phase - 1];
                let entry = self
                    .splits
                    .iter()
                    .find(|s| s.level == level && s.parent == parent)
                    .ok_or_else(|| format!("no split entry for chart {parent} at level {level}"))?;
                let url = self
                    .split_url
                    .as_deref()
                    .ok_or("splits without a split_url")?;
                urls.push(fill(url, level, "{parent}", parent));
                bytes += entry.bytes;
            }
            let chart = chain[phase];
            if let Some(part) = on_path
                .get(&level)
                .filter(|p| p.phase == phase && p.bytes > 0)
            {
                urls.push(fill(&self.part_url, level, "{chart}", chart));
                bytes += part.bytes;
            }
            previous_phase = Some(phase);
            steps.push((urls, bytes));
        }
        if levels.keys().next() != Some(&self.first_level) {
            return Err("the first parted level is not the index's first_level".into());
        }
        Ok(ClosePath {
            first_level: self.first_level,
            steps,
        })
    }
}

fn fill(template: &str, level: usize, key: &str, value: usize) -> String {
    template
        .replace("{level}", &level.to_string())
        .replace(key, &value.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A nested index of two phases: 2 top charts over levels 3–4, each
    /// split in two at level 5, leaves over levels 5–6.
    fn nested() -> PartIndex {
        let mut parts = Vec::new();
        for level in 3..=4 {
            for chart in 0..2 {
                parts.push(serde_json::json!({"level": level, "chart": chart, "phase": 0, "bytes": 100 + chart}));
            }
        }
        for level in 5..=6 {
            for chart in 0..4 {
                let bytes = if level == 6 && chart == 3 {
                    0
                } else {
                    10 + chart
                };
                parts.push(serde_json::json!({"level": level, "chart": chart, "phase": 1, "parent": chart / 2, "bytes": bytes}));
            }
        }
        serde_json::from_value(serde_json::json!({
            "phases": 2, "first_level": 3,
            "head_url": "/h/3", "part_url": "/b/{level}/parts/{chart}",
            "split_url": "/b/{level}/splits/{parent}",
            "parts": parts,
            "splits": [{"level": 5, "parent": 0, "bytes": 7}, {"level": 5, "parent": 1, "bytes": 8}],
        }))
        .unwrap()
    }

    #[test]
    fn a_leaf_path_fetches_its_ancestors_parts_and_split() {
        let path = nested().close_path(0.99).unwrap();
        assert_eq!(path.first_level, 3);
        let urls: Vec<Vec<&str>> = path
            .steps
            .iter()
            .map(|(u, _)| u.iter().map(String::as_str).collect())
            .collect();
        assert_eq!(
            urls,
            vec![
                vec!["/h/3", "/b/3/parts/1"],
                vec!["/b/4/parts/1"],
                vec!["/b/5/splits/1", "/b/5/parts/3"],
                // Leaf 3 sits level 6 out.
                vec![],
            ]
        );
        let bytes: Vec<u64> = path.steps.iter().map(|s| s.1).collect();
        assert_eq!(bytes, vec![101, 101, 8 + 13, 0]);
    }

    #[test]
    fn picks_spread_over_the_leaves() {
        let index = nested();
        let first_leaf_part = |pick: f64| index.close_path(pick).unwrap().steps[2].0[1].clone();
        assert_eq!(first_leaf_part(0.0), "/b/5/parts/0");
        assert_eq!(first_leaf_part(0.3), "/b/5/parts/1");
        assert_eq!(first_leaf_part(0.6), "/b/5/parts/2");
    }

    #[test]
    fn a_broken_index_is_an_error_not_a_panic() {
        let mut index = nested();
        index.splits.clear();
        assert!(index
            .close_path(0.5)
            .unwrap_err()
            .contains("no split entry"));
        index.parts.clear();
        assert!(index.close_path(0.5).is_err());
    }
}
