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
use crate::lattice::Cell;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rustc_hash::FxHashSet;
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

/// One growth on the square lattice: returns (Rule 1 violations, cells
/// filled).
fn grow(
    goal: &Goal,
    seed_cell: (i32, i32),
    order: Order,
    seed: u64,
    refuse: bool,
) -> (usize, usize) {
    let sides = [(1, 0), (0, 1), (-1, 0), (0, -1)];
    grow_on(
        seed_cell,
        &|c: (i32, i32)| goal.contains(c.0, c.1),
        &|c: (i32, i32)| sides.iter().map(|d| (c.0 + d.0, c.1 + d.1)).collect(),
        &|occupied: &dyn Fn((i32, i32)) -> bool, c: (i32, i32)| {
            blocked_2d(&|x, y| occupied((x, y)), c.0, c.1)
        },
        order,
        seed,
        refuse,
    )
}

/// Runs `order` on a 3D goal on the FCC lattice from `seed_cell`, Rule 1
/// as the authors coded it in 3D ([`super::rule1::blocked_fcc`]), the
/// frontier over the 12 neighbours.
pub fn run_fcc(
    goal: &super::plane_by_plane::Goal3,
    seed_cell: Cell,
    order: Order,
    seed: u64,
) -> NaiveCounts {
    use crate::lattice::{FccLattice, Lattice};
    let go = |refuse| {
        grow_on(
            seed_cell,
            &|c: Cell| goal.cells.contains(&c),
            &|c: Cell| FccLattice.neighbours(c).into_iter().collect(),
            &|occupied: &dyn Fn(Cell) -> bool, c: Cell| super::rule1::blocked_fcc(occupied, c),
            order,
            seed,
            refuse,
        )
    };
    let (violations, _) = go(false);
    let (_, filled) = go(true);
    NaiveCounts {
        violations,
        unfillable: goal.len() - filled,
    }
}

/// One growth over any cells: the frontier (free goal cells next to the
/// structure) is a bag drawn at random or a first-in-first-out queue.
/// Returns (Rule 1 violations, cells filled).
#[allow(clippy::type_complexity)]
fn grow_on<C: Copy + Eq + std::hash::Hash>(
    start: C,
    in_goal: &dyn Fn(C) -> bool,
    neighbours: &dyn Fn(C) -> Vec<C>,
    blocked: &dyn Fn(&dyn Fn(C) -> bool, C) -> bool,
    order: Order,
    seed: u64,
    refuse: bool,
) -> (usize, usize) {
    let mut filled: FxHashSet<C> = FxHashSet::default();
    let mut queued: FxHashSet<C> = FxHashSet::default();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut violations = 0;
    let mut frontier: VecDeque<C> = VecDeque::new();
    let place =
        |c: C, filled: &mut FxHashSet<C>, queued: &mut FxHashSet<C>, frontier: &mut VecDeque<C>| {
            filled.insert(c);
            for n in neighbours(c) {
                if in_goal(n) && !filled.contains(&n) && queued.insert(n) {
                    frontier.push_back(n);
                }
            }
        };
    place(start, &mut filled, &mut queued, &mut frontier);
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
        if blocked(&|x| filled.contains(&x), c) {
            violations += 1;
            if refuse {
                continue;
            }
        }
        place(c, &mut filled, &mut queued, &mut frontier);
    }
    (violations, filled.len())
}
