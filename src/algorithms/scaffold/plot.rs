//! Modules placed per time step (seed 000 Fig. 13–16), from any schedule:
//! a module is placed at the step of its last motion.

use crate::schedule::{Event, Schedule};
use std::collections::HashMap;

/// Number of modules that make their last move in each step (index = step − 1).
pub fn placed_per_step(s: &Schedule) -> Vec<usize> {
    let mut last: HashMap<u32, usize> = HashMap::new();
    for (k, step) in s.steps.iter().enumerate() {
        for e in &step.events {
            if matches!(e, Event::Rotate { .. }) {
                last.insert(e.module(), k);
            }
        }
    }
    let mut out = vec![0; s.steps.len()];
    for &k in last.values() {
        out[k] += 1;
    }
    out
}
