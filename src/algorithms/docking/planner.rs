//! The 2D planner of seed 002 (Tucci, Piranda, Bourgeois, §4.1), its
//! distributed behaviour simulated centrally as a discrete-event run.
//!
//! Every module in place runs the same rules on its own neighbourhood:
//!
//! * **Rules 2–3 (seeds).** A module attracts its north cell when it is a
//!   north seed — `N ∈ G` and (`NE ∉ G` or `E ∉ G`), the rightmost module
//!   under its north row — and its south cell when it is a south seed, the
//!   mirror image (leftmost).
//! * **Rules 4–5 (row merges).** A would-be north seed whose row, east of
//!   it, passes a gap under the north row and then continues, is not a seed
//!   when the gap is an internal hole: the row beyond the hole seeds the
//!   north row, so each row is one contiguous line. An external gap (open
//!   to the outside) cannot be reached from the other side first, so there
//!   the module stays a seed.
//! * **Algorithm 2 (west/east attraction).** West is attracted at once
//!   when `SW ∉ G`; otherwise only once `SW` is in place (the corner rule
//!   of Fig. 6): the south neighbour, when present, tells (one message);
//!   when `S ∉ G` the module is on a hole or concavity border and learns it
//!   by border following (the reply costs two messages a hop); when `S` is
//!   in the goal but empty, it attracts `S` first. East is the mirror image
//!   with `NE` and `N`.
//!
//! Delays are random (seeded RNG): a docking takes `dock_delay` time units
//! after its attraction, a message `message_delay` per hop, so each seed
//! gives another docking order, as the authors' simulations did.
//!
//! Messages are counted as the authors' simulator counts them (see the
//! facts of seed 002): on arrival, a request and a reply to each connected
//! x-neighbour (y-neighbours for a module starting a line) — the paper's
//! `2n`; one per permission reply; two per hop of a border-following
//! reply.

use super::goal::Goal;
use super::rule1;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rustc_hash::FxHashMap;
use serde::{Deserialize, Serialize};
use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

/// Random delays of the simulated distributed run, in time units.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Delays {
    /// A docking completes this long after its attraction (uniform range).
    pub dock: (u64, u64),
    /// One message hop takes this long (uniform range).
    pub message: (u64, u64),
}

impl Default for Delays {
    /// Docking slow against messages, both over a wide range ("random
    /// delays with a large range", §5).
    fn default() -> Self {
        Delays {
            dock: (10, 1000),
            message: (1, 10),
        }
    }
}

/// One docking of the run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Docking {
    pub cell: (i32, i32),
    /// The module in place that attracted it (a side neighbour); `None`
    /// for the initial seed.
    pub attractor: Option<(i32, i32)>,
    pub time: u64,
}

/// Message counts, as the paper defines them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Messages {
    /// Initial information exchange of each arriving module (≈ 2n).
    pub initial: u64,
    /// "Can fill left/right" permission replies through a side neighbour.
    pub permission: u64,
    /// Border-following (synchronisation) replies, two per hop.
    pub sync: u64,
}

impl Messages {
    pub fn total(&self) -> u64 {
        self.initial + self.permission + self.sync
    }
}

/// The outcome of one run.
#[derive(Clone, Debug)]
pub struct Run {
    pub order: Vec<Docking>,
    pub messages: Messages,
    /// After each docking (index = modules in place − 1): positions
    /// attracted and not yet docked.
    pub available: Vec<usize>,
    /// Dockings made while Rule 1 forbade them (the planner must give 0).
    pub rule1_violations: usize,
    /// Goal cells never filled (the planner must give 0).
    pub unfilled: usize,
    pub seed_cell: (i32, i32),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Ev {
    Dock { slot: usize, by: usize },
    Grant { module: usize, target: usize },
}

const NO: usize = usize::MAX;

struct Sim<'a> {
    g: &'a Goal,
    w: i32,
    holes: Vec<bool>,
    filled: Vec<bool>,
    attracted: Vec<bool>,
    /// Permission asked for (module slot, target slot).
    asked: FxHashMap<(usize, usize), ()>,
    /// Modules waiting for a corner cell: corner → (module, target, hops).
    waiting: FxHashMap<usize, Vec<(usize, usize, u64)>>,
    heap: BinaryHeap<Reverse<(u64, u64, Ev)>>,
    seq: u64,
    now: u64,
    rng: ChaCha8Rng,
    delays: Delays,
    pending: usize,
    run: Run,
}

impl Sim<'_> {
    fn slot(&self, x: i32, y: i32) -> usize {
        self.g.slot(x, y).unwrap_or(NO)
    }
    fn xy(&self, k: usize) -> (i32, i32) {
        self.g.cell_of_slot(k)
    }
    fn in_goal(&self, x: i32, y: i32) -> bool {
        self.g.contains(x, y)
    }
    fn is_filled(&self, x: i32, y: i32) -> bool {
        self.g.slot(x, y).is_some_and(|k| self.filled[k])
    }
    fn push(&mut self, t: u64, ev: Ev) {
        self.seq += 1;
        self.heap.push(Reverse((t, self.seq, ev)));
    }
    fn delay(&mut self, range: (u64, u64)) -> u64 {
        self.rng.random_range(range.0..=range.1.max(range.0))
    }

    /// Sends an attraction signal to a goal cell next to `by`.
    fn attract(&mut self, x: i32, y: i32, by: usize) {
        let k = self.slot(x, y);
        if k == NO || !self.in_goal(x, y) || self.filled[k] || self.attracted[k] {
            return;
        }
        self.attracted[k] = true;
        self.pending += 1;
        let t = self.now + self.delay(self.delays.dock);
        self.push(t, Ev::Dock { slot: k, by });
    }

    /// Rule 4 (north) or, mirrored, Rule 5 (south): the row, beyond the
    /// module in direction `dx`, passes a gap under (over) row `y + dy` and
    /// continues; `Some(gap cell)` when so.
    fn merge(&self, x: i32, y: i32, dx: i32, dy: i32) -> Option<(i32, i32)> {
        let mut j = 1;
        while !self.in_goal(x + j * dx, y) && self.in_goal(x + j * dx, y + dy) {
            j += 1;
        }
        (j > 1 && self.in_goal(x + j * dx, y) && self.in_goal(x + j * dx, y + dy))
            .then_some((x + dx, y))
    }

    fn internal(&self, c: (i32, i32)) -> bool {
        self.g.slot(c.0, c.1).is_some_and(|k| self.holes[k])
    }

    /// Rule 2 (dy = 1, dx = 1) or Rule 3 (dy = −1, dx = −1), with the
    /// merge exception of Rules 4–5 for internal holes.
    fn is_seed(&self, x: i32, y: i32, dx: i32, dy: i32) -> bool {
        self.in_goal(x, y + dy)
            && (!self.in_goal(x + dx, y + dy) || !self.in_goal(x + dx, y))
            && !self.merge(x, y, dx, dy).is_some_and(|gap| self.internal(gap))
    }

    /// Hops of a border-following message from `from` to `to` that avoids
    /// `avoid`: the shortest path through goal cells, which hugs the border
    /// of the hole or concavity between them. `None` if there is none.
    fn border_hops(&self, from: usize, to: usize, avoid: usize) -> Option<u64> {
        let mut dist: FxHashMap<usize, u64> = FxHashMap::default();
        dist.insert(from, 0);
        let mut q = VecDeque::from([from]);
        while let Some(k) = q.pop_front() {
            let d = dist[&k];
            if k == to {
                return Some(d);
            }
            let (x, y) = self.xy(k);
            for (a, b) in [(x + 1, y), (x, y + 1), (x - 1, y), (x, y - 1)] {
                let n = self.slot(a, b);
                if n != NO && n != avoid && self.in_goal(a, b) && !dist.contains_key(&n) {
                    dist.insert(n, d + 1);
                    q.push_back(n);
                }
            }
        }
        None
    }

    /// Algorithm 2's west (dx = −1, corner below) or east (dx = 1, corner
    /// above) attraction of module `k`.
    fn side(&mut self, k: usize, dx: i32) {
        let (x, y) = self.xy(k);
        let dy = -dx; // west waits for south-west, east for north-east
        let t = (x + dx, y);
        let ts = self.slot(t.0, t.1);
        if !self.in_goal(t.0, t.1) || self.filled[ts] || self.attracted[ts] {
            return;
        }
        if self.asked.contains_key(&(k, ts)) {
            return;
        }
        let corner = (x + dx, y + dy);
        if !self.in_goal(corner.0, corner.1) {
            self.attract(t.0, t.1, k);
            return;
        }
        let cs = self.slot(corner.0, corner.1);
        let via = (x, y + dy);
        if self.is_filled(via.0, via.1) {
            // Ask the neighbour on the corner's side; it replies once the
            // corner is in place (one counted message).
            self.asked.insert((k, ts), ());
            self.wait_or_grant(cs, k, ts, 1, false);
        } else if !self.in_goal(via.0, via.1) {
            // On a hole or concavity border: border following.
            match self.border_hops(k, cs, ts) {
                Some(h) => {
                    self.asked.insert((k, ts), ());
                    self.wait_or_grant(cs, k, ts, h, true);
                }
                // The corner is reachable only through the target: no
                // order can put it first.
                None => self.attract(t.0, t.1, k),
            }
        } else {
            // The corner's side neighbour is still to come: attract it.
            self.attract(via.0, via.1, k);
        }
    }

    fn wait_or_grant(&mut self, corner: usize, module: usize, target: usize, hops: u64, sync: bool) {
        let hops_code = if sync { hops | (1 << 62) } else { hops };
        if self.filled[corner] {
            self.grant_after(module, target, hops_code);
        } else {
            self.waiting
                .entry(corner)
                .or_default()
                .push((module, target, hops_code));
        }
    }

    fn grant_after(&mut self, module: usize, target: usize, code: u64) {
        let sync = code & (1 << 62) != 0;
        let hops = code & !(1 << 62);
        if sync {
            self.run.messages.sync += 2 * hops;
        } else {
            self.run.messages.permission += 1;
        }
        let mut t = self.now;
        for _ in 0..hops.max(1) {
            t += self.delay(self.delays.message);
        }
        self.push(t, Ev::Grant { module, target });
    }

    /// Everything module `k` may attract now.
    fn evaluate(&mut self, k: usize) {
        let (x, y) = self.xy(k);
        if self.is_seed(x, y, 1, 1) {
            self.attract(x, y + 1, k);
        }
        if self.is_seed(x, y, -1, -1) {
            self.attract(x, y - 1, k);
        }
        self.side(k, -1);
        self.side(k, 1);
    }

    fn dock(&mut self, k: usize, by: Option<usize>) {
        let (x, y) = self.xy(k);
        let occupied = |a: i32, b: i32| self.is_filled(a, b);
        if rule1::blocked_2d(&occupied, x, y) {
            self.run.rule1_violations += 1;
        }
        // Initial exchange: each connected x-neighbour, else y-neighbours.
        let row = [(x - 1, y), (x + 1, y)]
            .iter()
            .filter(|c| self.is_filled(c.0, c.1))
            .count() as u64;
        let col = [(x, y - 1), (x, y + 1)]
            .iter()
            .filter(|c| self.is_filled(c.0, c.1))
            .count() as u64;
        self.run.messages.initial += 2 * if row > 0 { row } else { col };
        self.filled[k] = true;
        self.run.order.push(Docking {
            cell: (x, y),
            attractor: by.map(|b| self.xy(b)),
            time: self.now,
        });
        self.run.available.push(self.pending);
        self.evaluate(k);
        for (a, b) in [(x + 1, y), (x, y + 1), (x - 1, y), (x, y - 1)] {
            if self.is_filled(a, b) {
                let n = self.slot(a, b);
                self.evaluate(n);
            }
        }
        if let Some(list) = self.waiting.remove(&k) {
            for (m, t, code) in list {
                self.grant_after(m, t, code);
            }
        }
    }
}

/// Runs the planner on `goal` from `seed_cell` with RNG seed `seed`.
pub fn run(goal: &Goal, seed_cell: (i32, i32), seed: u64, delays: &Delays) -> Run {
    let mut sim = Sim {
        g: goal,
        w: goal.frame().2,
        holes: goal.internal_holes(),
        filled: vec![false; goal.slots()],
        attracted: vec![false; goal.slots()],
        asked: FxHashMap::default(),
        waiting: FxHashMap::default(),
        heap: BinaryHeap::new(),
        seq: 0,
        now: 0,
        rng: ChaCha8Rng::seed_from_u64(seed),
        delays: delays.clone(),
        pending: 0,
        run: Run {
            order: Vec::with_capacity(goal.len()),
            messages: Messages::default(),
            available: Vec::with_capacity(goal.len()),
            rule1_violations: 0,
            unfilled: 0,
            seed_cell,
        },
    };
    let _ = sim.w;
    let s = sim.slot(seed_cell.0, seed_cell.1);
    sim.dock(s, None);
    while let Some(Reverse((t, _, ev))) = sim.heap.pop() {
        sim.now = t;
        match ev {
            Ev::Dock { slot, by } => {
                sim.attracted[slot] = false;
                sim.pending -= 1;
                sim.dock(slot, Some(by));
            }
            Ev::Grant { module, target } => {
                let (x, y) = sim.xy(target);
                sim.asked.remove(&(module, target));
                sim.attract(x, y, module);
            }
        }
    }
    sim.run.unfilled = goal.len() - sim.run.order.len();
    sim.run
}
