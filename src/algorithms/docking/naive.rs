//! The two naive docking orders of seed 002 Fig. 3, baselines for the
//! planner: a stochastic order (each docking a random free goal cell next
//! to the structure) and a regular neighbourhood fill (each module, in
//! arrival order, fills its side neighbours in turn: east, north, west,
//! south).
//!
//! Each order is run twice. *Forced*, every cell is docked when its turn
//! comes and a docking Rule 1 forbids is counted as a violation (the
//! paper's red modules, left, "3,691 modules that do not verify the
//! docking rule"). *Refusing*, a cell Rule 1 forbids is left empty — Rule 1
//! blocking only grows as modules arrive, so it stays empty — and the goal
//! cells never filled are counted (right, "231 positions that could not
//! be filled").

use super::goal::Goal;
use super::rule1::blocked_2d;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// Which naive order.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Order {
    Random,
    Neighbourhood,
}

impl Order {
    pub fn name(self) -> &'static str {
        match self {
            Order::Random => "random",
            Order::Neighbourhood => "neighbourhood fill",
        }
    }
}

/// Counts of one naive order on one goal.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct NaiveCounts {
    /// Dockings Rule 1 forbids, when every cell is docked anyway.
    pub violations: usize,
    /// Goal cells left empty, when forbidden dockings are refused.
    pub unfillable: usize,
}

/// Runs `order` on `goal` from `seed_cell` (forced and refusing).
pub fn run(goal: &Goal, seed_cell: (i32, i32), order: Order, seed: u64) -> NaiveCounts {
    let (violations, _) = grow(goal, seed_cell, order, seed, false);
    let (_, filled) = grow(goal, seed_cell, order, seed, true);
    NaiveCounts {
        violations,
        unfillable: goal.len() - filled,
    }
}

/// One growth: returns (Rule 1 violations, cells filled).
fn grow(
    goal: &Goal,
    seed_cell: (i32, i32),
    order: Order,
    seed: u64,
    refuse: bool,
) -> (usize, usize) {
    let slot = |x: i32, y: i32| goal.slot(x, y);
    let mut filled = vec![false; goal.slots()];
    let mut queued = vec![false; goal.slots()];
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (mut violations, mut count) = (0, 0);
    let sides = [(1, 0), (0, 1), (-1, 0), (0, -1)];
    // Frontier: free goal cells next to the structure, in the order's data
    // structure (a bag for random, a queue for the neighbourhood fill).
    let mut frontier: VecDeque<(i32, i32)> = VecDeque::new();
    let mut place = |c: (i32, i32),
                     filled: &mut Vec<bool>,
                     queued: &mut Vec<bool>,
                     frontier: &mut VecDeque<(i32, i32)>| {
        filled[slot(c.0, c.1).expect("goal cell")] = true;
        count += 1;
        for (dx, dy) in sides {
            let n = (c.0 + dx, c.1 + dy);
            if goal.contains(n.0, n.1) {
                let k = slot(n.0, n.1).expect("goal cell");
                if !filled[k] && !queued[k] {
                    queued[k] = true;
                    frontier.push_back(n);
                }
            }
        }
    };
    place(seed_cell, &mut filled, &mut queued, &mut frontier);
    loop {
        let next = match order {
            Order::Random => {
                if frontier.is_empty() {
                    break;
                }
                let i = rng.random_range(0..frontier.len());
                frontier.swap_remove_back(i)
            }
            Order::Neighbourhood => frontier.pop_front(),
        };
        let Some(c) = next else { break };
        let occupied = |x: i32, y: i32| slot(x, y).is_some_and(|k| filled[k]);
        if blocked_2d(&occupied, c.0, c.1) {
            violations += 1;
            if refuse {
                continue;
            }
        }
        place(c, &mut filled, &mut queued, &mut frontier);
    }
    (violations, count)
}
