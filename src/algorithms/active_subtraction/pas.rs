//! Parallel active subtraction (seed 003 §III-B, Alg. 3): start times for
//! the SAS removals so that several modules move at once, each on its SAS
//! path, arriving in the SAS order.
//!
//! A candidate start time `s_i` is rejected (and delayed by one step, line
//! 8) when the leader's simulation finds a *collision*: two active modules
//! in each other's Moore neighbourhood at some time. The paper's Theorem 6
//! states that every module then follows its SAS path; this implementation
//! checks that instead of assuming it — a start that would change any active
//! module's Alg. 2 decision (a module vacating its start cell next to
//! another's route) or would leave the static structure unsupported (a later
//! module starting before an earlier one above it) counts as a collision
//! too. [`PasTimes`] reports how often each reason delayed a start.

use super::sas::{Removal, SasRun, next_direction};
use super::shape::{Shape, neighbours4, xy};
use crate::error::InputError;
use crate::lattice::Cell;
use rustc_hash::FxHashMap;

/// Start and arrival times of every removal (SAS arrival order), in time
/// steps: module `i` is active from `start[i]` (still in its start cell) and
/// makes its moves in steps `start[i] + 1 ..= arrival[i]`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PasTimes {
    pub start: Vec<usize>,
    pub arrival: Vec<usize>,
    /// Start times delayed because two active modules came within each
    /// other's Moore neighbourhood (the paper's collision).
    pub delayed_moore: usize,
    /// Delayed because an active module's route would have differed from
    /// its SAS route.
    pub delayed_route: usize,
    /// Delayed because the static structure would have lost its support.
    pub delayed_support: usize,
}

impl PasTimes {
    /// SAS timing: each module starts when its predecessor arrives.
    pub fn sequential(run: &SasRun) -> PasTimes {
        let mut t = PasTimes::default();
        let mut now = 0;
        for r in &run.removals {
            t.start.push(now);
            now += r.duration();
            t.arrival.push(now);
        }
        t
    }

    /// Reconfiguration time: the last arrival.
    pub fn time_steps(&self) -> usize {
        self.arrival.last().copied().unwrap_or(0)
    }
}

/// Why a candidate start time fails.
enum Clash {
    Moore,
    Route,
    Support,
}

struct Planner<'a> {
    shape: &'a Shape,
    removals: &'a [Removal],
    /// Start cell → removal index.
    owner: FxHashMap<Cell, usize>,
    start: Vec<usize>,
    arrival: Vec<usize>,
}

impl Planner<'_> {
    /// Position of removal `m` (assigned, `m ≤ k`) at time `t` while active.
    fn active_at(&self, m: usize, t: usize) -> Option<Cell> {
        let (s, a) = (self.start[m], self.arrival[m]);
        (s <= t && t <= a).then(|| self.removals[m].cells[t - s])
    }

    /// Whether cell `c` holds a module (or is ground) at time `t`, with
    /// removals `0..=k` scheduled and the later ones still in place.
    fn occupied(&self, c: Cell, t: usize, k: usize, actives: &[(usize, Cell)]) -> bool {
        if c.y < 1 || self.shape.contains(c) {
            return true;
        }
        // A module still in its start cell: not yet scheduled, or not started.
        if self
            .owner
            .get(&c)
            .is_some_and(|&m| m > k || t <= self.start[m])
        {
            return true;
        }
        actives.iter().any(|&(_, p)| p == c)
    }

    fn actives(&self, t: usize, from: usize, k: usize) -> Vec<(usize, Cell)> {
        (from..=k)
            .filter_map(|m| self.active_at(m, t).map(|p| (m, p)))
            .collect()
    }

    /// Alg. 3 line 6: simulates the modules active from `start[k]` on.
    fn check(&self, k: usize) -> Result<(), Clash> {
        let sk = self.start[k];
        let home = self.removals[k].start();
        // Removals already gone by s_k do not interact (line 5).
        let first = self.arrival[..k].partition_point(|&a| a < sk);
        let end = self.arrival[first..=k].iter().copied().max().unwrap_or(sk);
        for t in sk..=end {
            let actives = self.actives(t, first, k);
            let Some(&(_, pk)) = actives.iter().find(|&&(m, _)| m == k) else {
                // k is done; the others only feel its vacated start cell.
                for &(m, p) in &actives {
                    if t < self.arrival[m] && (p - home).linf() <= 1 {
                        self.check_decision(m, t, k, &actives)?;
                    }
                }
                continue;
            };
            for &(m, p) in &actives {
                if m != k && (p - pk).linf() <= 1 {
                    return Err(Clash::Moore);
                }
            }
            for &(m, p) in &actives {
                let affected = m == k || (t > sk && (p - home).linf() <= 1);
                if affected && t < self.arrival[m] {
                    self.check_decision(m, t, k, &actives)?;
                }
            }
        }
        self.check_support(k)
    }

    /// Whether removal `m`'s Alg. 2 decision at time `t` is its SAS move.
    fn check_decision(
        &self,
        m: usize,
        t: usize,
        k: usize,
        actives: &[(usize, Cell)],
    ) -> Result<(), Clash> {
        let j = t - self.start[m];
        let cells = &self.removals[m].cells;
        let last = (j > 0)
            .then(|| super::sas::Dir::between(cells[j - 1], cells[j]).expect("one-cell moves"));
        let d = next_direction(cells[j], last, &|c| self.occupied(c, t, k, actives));
        if d.map(|d| d.step(cells[j])) == Some(cells[j + 1]) {
            Ok(())
        } else {
            Err(Clash::Route)
        }
    }

    /// When `k` starts before an earlier removal, the static structure of
    /// every step up to that removal's start differs from any SAS stage:
    /// check it stands (connected to the ground).
    fn check_support(&self, k: usize) -> Result<(), Clash> {
        let sk = self.start[k];
        let mut events: Vec<usize> = self.start[..k]
            .iter()
            .copied()
            .filter(|&s| s > sk)
            .collect();
        if events.is_empty() {
            return Ok(());
        }
        events.push(sk);
        events.sort_unstable();
        events.dedup();
        for s in events {
            // Static modules during step s + 1: those that have not started.
            let stands = |c: Cell| {
                self.shape.contains(c)
                    || self
                        .owner
                        .get(&c)
                        .is_some_and(|&m| m > k || self.start[m] > s)
            };
            if !grounded(self.shape, &stands) {
                return Err(Clash::Support);
            }
        }
        Ok(())
    }
}

/// Whether every cell of the rectangle for which `present` holds is
/// connected to the ground through present cells.
fn grounded(shape: &Shape, present: &dyn Fn(Cell) -> bool) -> bool {
    let w = shape.width as usize;
    let idx = |c: Cell| (c.y as usize - 1) * w + (c.x as usize - 1);
    let mut seen = vec![false; w * shape.height as usize];
    let mut stack: Vec<Cell> = (1..=shape.width)
        .map(|x| Cell::xy(x, 1))
        .filter(|&c| present(c))
        .collect();
    for &c in &stack {
        seen[idx(c)] = true;
    }
    while let Some(c) = stack.pop() {
        for n in neighbours4(c) {
            if shape.in_rectangle(n) && present(n) && !seen[idx(n)] {
                seen[idx(n)] = true;
                stack.push(n);
            }
        }
    }
    shape.cells().all(|c| !present(c) || seen[idx(c)])
}

/// Alg. 3: start times for the SAS removals of `run` on `shape`. Fails
/// only if `run` is not what SAS produces on `shape` (a route Alg. 2 would
/// not take even with every earlier module gone).
pub fn plan(shape: &Shape, run: &SasRun) -> Result<PasTimes, InputError> {
    let n = run.removals.len();
    let mut p = Planner {
        shape,
        removals: &run.removals,
        owner: run
            .removals
            .iter()
            .enumerate()
            .map(|(k, r)| (r.start(), k))
            .collect(),
        start: Vec::with_capacity(n),
        arrival: Vec::with_capacity(n),
    };
    let mut out = PasTimes::default();
    for (k, r) in run.removals.iter().enumerate() {
        let delta = r.duration();
        // Line 4: arrive at least two steps after the predecessor.
        let mut s = match k {
            0 => 0,
            _ => (p.arrival[k - 1] + 2).saturating_sub(delta),
        };
        p.start.push(s);
        p.arrival.push(s + delta);
        // Once every earlier module has arrived nothing can interfere.
        let quiet = p.arrival[..k].iter().copied().max().map_or(0, |a| a + 1);
        loop {
            match p.check(k) {
                Ok(()) => break,
                Err(_) if s > quiet => {
                    return Err(InputError::new(format!(
                        "removal {k} from {} does not follow Alg. 2 on this configuration",
                        xy(r.start())
                    )));
                }
                Err(clash) => {
                    match clash {
                        Clash::Moore => out.delayed_moore += 1,
                        Clash::Route => out.delayed_route += 1,
                        Clash::Support => out.delayed_support += 1,
                    }
                    s += 1; // line 8
                    p.start[k] = s;
                    p.arrival[k] = s + delta;
                }
            }
        }
    }
    out.start = p.start;
    out.arrival = p.arrival;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algorithms::active_subtraction::sas;
    use std::path::Path;

    fn shape(t: &str) -> Shape {
        Shape::parse(t, Path::new("t")).unwrap()
    }

    #[test]
    fn u_shape_start_times_are_delayed_only_by_moore_collisions() {
        let u = shape("#..#\n#..#\n#..#\n####\n");
        let run = sas::run(&u).unwrap();
        let durations: Vec<usize> = run.removals.iter().map(Removal::duration).collect();
        assert_eq!(durations, [5, 6, 6, 7, 7, 8]);
        let t = plan(&u, &run).unwrap();
        // Line 4 proposes 0, 1, 3, 4, 7, 8; the 4th and 6th would start
        // next to the module ahead of them and wait one step.
        assert_eq!(t.start, [0, 1, 3, 5, 7, 9]);
        assert_eq!(t.arrival, [5, 7, 9, 12, 14, 17]);
        assert_eq!(
            (t.delayed_moore, t.delayed_route, t.delayed_support),
            (2, 0, 0)
        );
    }

    #[test]
    fn a_route_alg_2_would_not_take_is_refused() {
        let u = shape("#..#\n#..#\n#..#\n####\n");
        let mut run = sas::run(&u).unwrap();
        // Send the first module the long way round: East first.
        let r = &mut run.removals[0];
        r.cells.insert(1, Cell::xy(3, 5));
        r.cells.insert(2, Cell::xy(2, 5));
        let e = plan(&u, &run).unwrap_err();
        assert!(e.message.contains("does not follow Alg. 2"), "{e}");
    }

    #[test]
    fn starting_below_a_waiting_module_is_a_support_clash() {
        // A column on one included module: (1,2) below (1,3).
        let s = shape(".\n.\n#\n");
        let top = Removal {
            cells: vec![Cell::xy(1, 3), Cell::xy(0, 2), Cell::xy(0, 1)],
        };
        let low = Removal {
            cells: vec![Cell::xy(1, 2), Cell::xy(0, 1)],
        };
        let removals = [top, low];
        let planner = |start: Vec<usize>| Planner {
            shape: &s,
            removals: &removals,
            owner: removals
                .iter()
                .enumerate()
                .map(|(k, r)| (r.start(), k))
                .collect(),
            arrival: start
                .iter()
                .zip(&removals)
                .map(|(s, r)| s + r.duration())
                .collect(),
            start,
        };
        // The lower module leaving first strands the upper one.
        assert!(matches!(
            planner(vec![5, 0]).check_support(1),
            Err(Clash::Support)
        ));
        assert!(planner(vec![0, 4]).check_support(1).is_ok());
    }
}
