//! The 2D planner of seed 002 (Tucci, Piranda, Bourgeois, §4.1), its
//! distributed behaviour simulated centrally as a discrete-event run.
//!
//! The paper keeps two conditions (§3.2): **one contiguous line of modules
//! per row**, which its seed rules enforce (Rules 2–3 elect one seed per
//! row, Rules 4–5 withdraw the second seed where a row merges over a hole),
//! and **attraction in an existing row only once the corner cell is in
//! place** (Fig. 6, Algorithm 2: west waits for south-west, east for
//! north-east), which makes each column grow as one line too. The planner
//! keeps both as they act on the cells: a module attracts a free goal
//! neighbour `c` when `c`'s row-run (maximal run of goal cells in its row)
//! is empty or `c` touches that run's line, and the same holds for `c`'s
//! column-run. A run's line is started by one module only (the first
//! attraction reserves the run, as the seed election does); after that it
//! grows at its ends. So no free cell ever lies between two modules of its
//! row or column: Rule 1 is never broken, and no cell is left unfillable.
//!
//! A module learns the condition across its attraction from the corner
//! cell: through its neighbour next to the corner (one permission reply),
//! or, when that neighbour is not in the goal (a hole or concavity), by
//! border following — the shortest path through goal cells around the
//! border, two messages a hop for the reply.
//!
//! Delays are random (seeded RNG): a permission takes `message_delay` per
//! hop, a docking `dock_delay` after its attraction, so each seed gives
//! another docking order, as the authors' simulations did.
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

/// Message counts, as the authors' simulator counts them.
///
/// Two versions of their code count the permissions differently (read in
/// ProgrammableMatterProject/VisibleSim, `applicationsSrc/reconfCatoms3D`):
///
/// * **paper-era** (85228ead, Nov. 2017, the code behind the paper's ≈ 5n):
///   an arriving module that needs a corner to attract sideways sends a
///   "can fill left/right" request to the neighbour next to it (1), which
///   replies at once if the corner is there (1) and drops it otherwise;
///   and every module that receives an arrival's initial request also
///   sends, unasked, a "can fill left" reply to its north when it has
///   north and west neighbours and a "can fill right" reply to its south
///   when it has east and south ones (1 each) — one of which delivers a
///   dropped permission, most of which are redundant;
/// * **later** (77ca516c, "lower number of messages", Dec. 2017, the code
///   the facts file describes): one reply per permission, no request.
///
/// Both count the initial exchange (≈ 2n) and two per hop of a
/// border-following reply alike.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Messages {
    /// Initial information exchange of each arriving module (≈ 2n).
    pub initial: u64,
    /// Later code: "can fill left/right" replies, one per permission.
    pub permission: u64,
    /// Border-following (synchronisation) replies, two per hop.
    pub sync: u64,
    /// Paper-era code: permission requests of arriving modules.
    pub request: u64,
    /// Paper-era code: replies to those requests (the corner was there).
    pub reply: u64,
    /// Paper-era code: unasked replies sent on every initial request.
    pub unasked: u64,
}

impl Messages {
    /// Adds `o`'s counts to these.
    pub fn add(&mut self, o: &Messages) {
        self.initial += o.initial;
        self.permission += o.permission;
        self.sync += o.sync;
        self.request += o.request;
        self.reply += o.reply;
        self.unasked += o.unasked;
    }

    /// The total as the later code counts it (≈ 2.9n).
    pub fn total(&self) -> u64 {
        self.initial + self.permission + self.sync
    }

    /// The total as the paper-era code counts it: ≈ 5n on the authors'
    /// own docking order (the paper's figure), ≈ 4.2n on this planner's.
    pub fn total_paper(&self) -> u64 {
        self.initial + self.request + self.reply + self.unasked + self.sync
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
    Attract { slot: usize, by: usize },
}

const NO: usize = usize::MAX;

struct Sim<'a> {
    g: &'a Goal,
    filled: Vec<bool>,
    /// Attracted (possibly still waiting for a permission) or docked.
    taken: Vec<bool>,
    /// Row-run and column-run of each goal slot, and how many of each
    /// run's cells are taken.
    row_of: Vec<usize>,
    col_of: Vec<usize>,
    row_taken: Vec<usize>,
    col_taken: Vec<usize>,
    heap: BinaryHeap<Reverse<(u64, u64, Ev)>>,
    seq: u64,
    now: u64,
    rng: ChaCha8Rng,
    delays: Delays,
    pending: usize,
    run: Run,
}

/// Labels the maximal runs of goal cells along `(dx, dy)`.
fn runs(g: &Goal, dx: i32, dy: i32) -> (Vec<usize>, usize) {
    let mut label = vec![NO; g.slots()];
    let mut n = 0;
    for (x, y) in g.cells() {
        let k = g.slot(x, y).expect("goal cell");
        if label[k] != NO {
            continue;
        }
        let (mut a, mut b) = (x, y);
        while g.contains(a - dx, b - dy) {
            a -= dx;
            b -= dy;
        }
        while g.contains(a, b) {
            label[g.slot(a, b).expect("goal cell")] = n;
            a += dx;
            b += dy;
        }
        n += 1;
    }
    (label, n)
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

    /// Whether module `by` may attract the free goal cell `c` next to it,
    /// and if so the messages that permission costs: the row condition
    /// (one contiguous line per row: Rules 2–5) and the column condition
    /// (the corner rule of Fig. 6 / Algorithm 2) must both hold.
    fn permission(&mut self, c: usize, by: usize) -> Option<(u64, u64)> {
        let (x, y) = self.xy(c);
        let (bx, by_y) = self.xy(by);
        let horizontal = by_y == y;
        let row_ok = self.is_filled(x - 1, y) || self.is_filled(x + 1, y);
        let col_ok = self.is_filled(x, y - 1) || self.is_filled(x, y + 1);
        let row_free = self.row_taken[self.row_of[c]] == 0;
        let col_free = self.col_taken[self.col_of[c]] == 0;
        if !(row_ok || row_free) || !(col_ok || col_free) {
            return None;
        }
        // Messages: the condition across the move's direction is learnt
        // from the cell diagonal to `by` (the corner). A neighbour of `by`
        // relays it (one reply); across a hole or concavity border
        // following does (two per hop). A run still empty needs none: the
        // seed rules decide from the shape alone.
        let across_ok = if horizontal { col_ok } else { row_ok };
        if !across_ok {
            return Some((0, 0));
        }
        // The corner: the filled cell across, next to c.
        let corners: Vec<(i32, i32)> = if horizontal {
            vec![(x, y - 1), (x, y + 1)]
        } else {
            vec![(x - 1, y), (x + 1, y)]
        };
        let corner = corners
            .into_iter()
            .find(|&(a, b)| self.is_filled(a, b))
            .expect("across_ok");
        // The relay: by's neighbour next to the corner.
        let relay = (bx + corner.0 - x, by_y + corner.1 - y);
        if self.is_filled(relay.0, relay.1) {
            Some((1, 0))
        } else {
            let cs = self.slot(corner.0, corner.1);
            let hops = self.border_hops(by, cs, c).unwrap_or(1);
            Some((0, 2 * hops))
        }
    }

    /// Tries every free goal neighbour of the module at `k`.
    fn evaluate(&mut self, k: usize) {
        let (x, y) = self.xy(k);
        for (a, b) in [(x + 1, y), (x, y + 1), (x - 1, y), (x, y - 1)] {
            if !self.in_goal(a, b) {
                continue;
            }
            let c = self.slot(a, b);
            if self.taken[c] {
                continue;
            }
            if let Some((perm, sync)) = self.permission(c, k) {
                self.taken[c] = true;
                self.row_taken[self.row_of[c]] += 1;
                self.col_taken[self.col_of[c]] += 1;
                self.run.messages.permission += perm;
                self.run.messages.sync += sync;
                let hops = perm + sync / 2;
                let mut t = self.now;
                for _ in 0..hops {
                    t += self.delay(self.delays.message);
                }
                self.push(t, Ev::Attract { slot: c, by: k });
            }
        }
    }

    /// The paper-era permission messages of a module arriving at `(x, y)`
    /// (see [`Messages`]); `in_row` when its initial requests go to its
    /// x-neighbours (else to its y-neighbours, as a line's start).
    fn paper_era_permissions(&mut self, x: i32, y: i32, in_row: bool) {
        let f = |a: i32, b: i32| self.is_filled(a, b);
        let g = |a: i32, b: i32| self.in_goal(a, b);
        let (mut request, mut reply, mut unasked) = (0, 0, 0);
        // West needs the south-west corner, asked of the south neighbour;
        // east needs the north-east corner, asked of the north neighbour.
        for (side, corner, asked) in [
            ((x - 1, y), (x - 1, y - 1), (x, y - 1)),
            ((x + 1, y), (x + 1, y + 1), (x, y + 1)),
        ] {
            if g(side.0, side.1)
                && !f(side.0, side.1)
                && g(corner.0, corner.1)
                && f(asked.0, asked.1)
            {
                request += 1;
                if f(corner.0, corner.1) {
                    reply += 1;
                }
            }
        }
        // Every neighbour that gets an initial request replies unasked.
        let told: Vec<(i32, i32)> = if in_row {
            vec![(x - 1, y), (x + 1, y)]
        } else {
            vec![(x, y - 1), (x, y + 1)]
        };
        for (a, b) in told.into_iter().filter(|&(a, b)| f(a, b)) {
            unasked +=
                u64::from(f(a, b + 1) && f(a - 1, b)) + u64::from(f(a + 1, b) && f(a, b - 1));
        }
        self.run.messages.request += request;
        self.run.messages.reply += reply;
        self.run.messages.unasked += unasked;
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
        self.paper_era_permissions(x, y, row > 0);
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
    }
}

/// Runs the planner on `goal` from `seed_cell` with RNG seed `seed`.
pub fn run(goal: &Goal, seed_cell: (i32, i32), seed: u64, delays: &Delays) -> Run {
    let (row_of, rows) = runs(goal, 1, 0);
    let (col_of, cols) = runs(goal, 0, 1);
    let mut sim = Sim {
        g: goal,
        filled: vec![false; goal.slots()],
        taken: vec![false; goal.slots()],
        row_of,
        col_of,
        row_taken: vec![0; rows],
        col_taken: vec![0; cols],
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
    let s = sim.slot(seed_cell.0, seed_cell.1);
    sim.taken[s] = true;
    sim.row_taken[sim.row_of[s]] += 1;
    sim.col_taken[sim.col_of[s]] += 1;
    sim.dock(s, None);
    while let Some(Reverse((t, _, ev))) = sim.heap.pop() {
        sim.now = t;
        match ev {
            Ev::Attract { slot, by } => {
                // The signal reaches the cell: it is now a docking position.
                sim.pending += 1;
                let t = sim.now + sim.delay(sim.delays.dock);
                sim.push(t, Ev::Dock { slot, by });
            }
            Ev::Dock { slot, by } => {
                sim.pending -= 1;
                sim.dock(slot, Some(by));
            }
        }
    }
    sim.run.unfilled = goal.len() - sim.run.order.len();
    sim.run
}
