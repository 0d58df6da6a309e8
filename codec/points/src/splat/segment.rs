//! Surface ids: breadth-first search over the continuous (non-sharp) edges,
//! so that two surfaces crossing each other get different ids.

use std::collections::VecDeque;

use super::{dot, Graph};

/// One id per splat, numbered 0.. in the order the parts are found.
pub fn surface_ids(normals: &[[f32; 3]], graph: &Graph, sharp_threshold: f32) -> Vec<u32> {
    let n = normals.len();
    let mut ids = vec![u32::MAX; n];
    let mut next = 0u32;
    let mut queue = VecDeque::new();
    for seed in 0..n {
        if ids[seed] != u32::MAX {
            continue;
        }
        ids[seed] = next;
        queue.push_back(seed);
        while let Some(i) = queue.pop_front() {
            for &j in graph.neighbours(i) {
                let j = j as usize;
                if ids[j] == u32::MAX && dot(normals[i], normals[j]) >= sharp_threshold {
                    ids[j] = next;
                    queue.push_back(j);
                }
            }
        }
        next += 1;
    }
    ids
}
