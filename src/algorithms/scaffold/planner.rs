//! Motion planning (seed 000 §3.3.3–3.3.4), centralised.
//!
//! Every module enters at a sandbox entry point and rolls, one rotation per
//! time step, to its component. Modules are planned one at a time, in
//! order of the time their component becomes buildable (polytree
//! precedences), with prioritised space–time planning:
//!
//! 1. a static route is searched (A*) over the structure the earlier
//!    modules leave behind, with every rotation accepted by the
//!    [`MotionRules`] of the protocol: the rules derived from the exact
//!    catom body (safe), or the paper's bridging constraint (paper);
//! 2. the module then follows that route in time against the trajectories
//!    of the modules already planned, which move concurrently with it: it
//!    waits while a pivot or a predecessor component is not yet in place,
//!    while the next cell is held or swept by another agent, while the
//!    rotation is disallowed with the other agents (before and after the
//!    step) counted as obstacles or would sweep a cell another rotation of
//!    the step sweeps, and — in the paper's protocol — while its light
//!    pivot is red or orange (§3.3.4);
//! 3. if waiting is impossible (another module comes by), its departure
//!    is delayed by one step and it tries again. Departing after every
//!    earlier module has arrived always succeeds, so planning terminates.
//!    With an eager [`Feed`], a module that arrives late also tries
//!    leaving earlier and waiting in the structure (see [`super::feed`]).
//!
//! The safe protocol asks exactly what the swept cells require: no gap
//! between free agents beyond that (an earlier version kept free agents
//! out of neighbouring cells, 13–25 % slower, see docs/scaffold.md).

use super::feed::Feed;
use super::paper::Protocol;
use super::scaffold::Scaffold;
use super::shape::Skew;
use crate::error::InputError;
use crate::geometry::MotionRules;
use crate::lattice::config::ModuleId;
use crate::lattice::{Cell, FccLattice, Lattice, Motion, Route, fcc};
use crate::schedule::Event;
use rustc_hash::{FxHashMap, FxHashSet};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Rotation links of a pivot: for connector `f` (pivot → mover), the
/// connectors `t` reachable in one rotation and their routes (SPEC §3).
fn rotation_table() -> [[&'static [Route]; 12]; 12] {
    const SIXTY: &[Route] = &[Route::Octagonal, Route::Hexagonal];
    const NINETY: &[Route] = &[Route::Octagonal];
    const NONE: &[Route] = &[];
    let mut t = [[NONE; 12]; 12];
    for (f, row) in t.iter_mut().enumerate() {
        for (g, cell) in row.iter_mut().enumerate() {
            let dot = fcc::direction(f).dot(fcc::direction(g));
            *cell = if (dot - 0.5).abs() < 1e-9 {
                SIXTY
            } else if dot.abs() < 1e-9 {
                NINETY
            } else {
                NONE
            };
        }
    }
    t
}

/// One rotation of a route: target cell, pivot cell, route.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Hop {
    pub to: Cell,
    pub pivot: Cell,
    pub route: Route,
}

/// The planner's state: the static structure and the space–time
/// reservations of every module planned so far.
pub struct Planner<'a> {
    rules: &'a dyn MotionRules,
    protocol: Protocol,
    feed: Feed,
    table: [[&'static [Route]; 12]; 12],
    /// Cells holding a static module once everything planned is in place.
    occupied: FxHashSet<Cell>,
    /// Module of each static cell, and the step at the end of which it is
    /// in place (0 for the sandbox).
    module_at: FxHashMap<Cell, (ModuleId, usize)>,
    /// Free agents' cells at the end of each step (index = step).
    positions: Vec<FxHashMap<Cell, ModuleId>>,
    /// Blocking cells of the rotations of each step.
    swept: Vec<FxHashSet<Cell>>,
    /// Last step in which a cell is crossed: held by a free agent or among
    /// a rotation's blocking cells.
    last_use: FxHashMap<Cell, usize>,
    /// Rotations planned so far, by pivot cell: a module placed later must
    /// not make any of them illegal (the rules' pinches depend on pairs of
    /// occupied cells, not only on blocking cells).
    moves_by_pivot: FxHashMap<Cell, Vec<(usize, Motion)>>,
    /// Cells within 2 d of a cell (lattice offsets, both parities).
    reach: [Vec<(i32, i32, i32)>; 2],
    /// Events of each step (index = step − 1).
    pub events: Vec<Vec<Event>>,
    /// Number of modules reaching their component in each step.
    pub placed_per_step: Vec<usize>,
    lo: Skew,
    hi: Skew,
    min_layer: i32,
    /// Seconds spent searching routes and following them in time.
    pub timing: (f64, f64),
}

impl<'a> Planner<'a> {
    /// A planner over `scaffold`'s sandbox (module ids `0..sandbox.len()`).
    pub fn new(
        scaffold: &Scaffold,
        rules: &'a dyn MotionRules,
        protocol: Protocol,
        feed: Feed,
    ) -> Planner<'a> {
        let mut occupied = FxHashSet::default();
        let mut module_at = FxHashMap::default();
        for (i, s) in scaffold.sandbox.iter().enumerate() {
            occupied.insert(s.cell());
            module_at.insert(s.cell(), (i as ModuleId, 0));
        }
        let mut lo = Skew::new(i32::MAX, i32::MAX, i32::MAX);
        let mut hi = Skew::new(i32::MIN, i32::MIN, i32::MIN);
        for c in scaffold.components.iter().map(|c| c.cell) {
            lo = Skew::new(lo.x.min(c.x), lo.y.min(c.y), lo.z.min(c.z));
            hi = Skew::new(hi.x.max(c.x), hi.y.max(c.y), hi.z.max(c.z));
        }
        Planner {
            rules,
            protocol,
            feed,
            table: rotation_table(),
            occupied,
            module_at,
            positions: vec![FxHashMap::default()],
            swept: vec![FxHashSet::default()],
            last_use: FxHashMap::default(),
            moves_by_pivot: FxHashMap::default(),
            reach: [0, 1].map(|parity| {
                let l = FccLattice;
                let o = Cell::new(0, 0, parity);
                let mut v = Vec::new();
                for x in -3..=3 {
                    for y in -3..=3 {
                        for z in -3..=3 {
                            let c = Cell::new(x, y, parity + z);
                            if (l.centre(c) - l.centre(o)).length() < 2.0 + 1e-9 {
                                v.push((x, y, z));
                            }
                        }
                    }
                }
                v
            }),
            events: Vec::new(),
            placed_per_step: Vec::new(),
            lo: Skew::new(lo.x - 4, lo.y - 4, -1),
            hi: Skew::new(hi.x + 4, hi.y + 4, hi.z + 2),
            min_layer: -1,
            timing: (0.0, 0.0),
        }
    }

    /// Whether a static module holds `c` once everything planned is in place.
    pub fn is_occupied(&self, c: Cell) -> bool {
        self.occupied.contains(&c)
    }

    /// Last step of the schedule so far.
    pub fn horizon(&self) -> usize {
        self.positions.len() - 1
    }

    fn in_bounds(&self, c: Cell) -> bool {
        let (x, y, z) = FccLattice::to_skewed(c);
        z >= self.min_layer
            && (self.lo.x..=self.hi.x).contains(&x)
            && (self.lo.y..=self.hi.y).contains(&y)
            && z <= self.hi.z
    }

    /// A* over the static structure: rotations from one of `srcs` (each
    /// with a start penalty, in moves) to `dst`. Returns the source used.
    pub fn route(&self, srcs: &[(Cell, u32)], dst: Cell) -> Option<(Cell, Vec<Hop>)> {
        let l = FccLattice;
        let goal = l.centre(dst);
        let h = |c: Cell| {
            ((l.centre(c) - goal).length() / std::f64::consts::SQRT_2 * 2.0 * 1024.0) as u64
        };
        let mut best: FxHashMap<Cell, (u32, Option<(Cell, Hop)>)> = FxHashMap::default();
        let mut open = BinaryHeap::new();
        for &(src, pen) in srcs {
            if best.get(&src).is_none_or(|&(g, _)| g > pen) {
                best.insert(src, (pen, None));
                open.push(Reverse((pen as u64 * 1024 + h(src), pen, src)));
            }
        }
        let occ = |c: Cell| self.occupied.contains(&c);
        let mut expanded = 0usize;
        while let Some(Reverse((_, g, c))) = open.pop() {
            if best.get(&c).is_some_and(|&(bg, _)| bg < g) {
                continue;
            }
            if c == dst {
                let mut hops = Vec::new();
                let mut cur = c;
                while let Some((prev, hop)) = best[&cur].1 {
                    hops.push(hop);
                    cur = prev;
                }
                hops.reverse();
                return Some((cur, hops));
            }
            expanded += 1;
            if expanded > 400_000 {
                return None;
            }
            for k in 0..12 {
                let pivot = l.neighbour(c, k);
                if !self.occupied.contains(&pivot) {
                    continue;
                }
                let f = fcc::opposite(k);
                for t in 0..12 {
                    let routes = self.table[f][t];
                    if routes.is_empty() {
                        continue;
                    }
                    let to = l.neighbour(pivot, t);
                    if self.occupied.contains(&to) || !self.in_bounds(to) {
                        continue;
                    }
                    let ng = g + 1;
                    if best.get(&to).is_some_and(|&(bg, _)| bg <= ng) {
                        continue;
                    }
                    // The paper's model allows both routes of a 60° link;
                    // its catoms take the hexagonal one (the shorter
                    // actuator path, §3 Fig. 1b). The safe protocol takes
                    // the first the body allows.
                    let mut order = routes.to_vec();
                    if self.protocol == Protocol::Paper {
                        order.reverse();
                    }
                    let Some(&route) = order.iter().find(|&&route| {
                        self.rules.allows(
                            &Motion::Rotate {
                                from: c,
                                to,
                                pivot,
                                route,
                            },
                            &occ,
                        )
                    }) else {
                        continue;
                    };
                    best.insert(to, (ng, Some((c, Hop { to, pivot, route }))));
                    open.push(Reverse((ng as u64 * 1024 + h(to), ng, to)));
                }
            }
        }
        None
    }

    /// Whether cell `c` is free at the end of step `t`: no free agent
    /// holds it and no rotation of that step sweeps it. That is all the
    /// geometry asks of the cells themselves; the rest is checked per
    /// move (the rules with the agents as obstacles, disjoint sweeps) and,
    /// in the paper's protocol, by the light pivots.
    fn clear(&self, c: Cell, t: usize) -> bool {
        t >= self.positions.len()
            || (!self.swept[t].contains(&c) && !self.positions[t].contains_key(&c))
    }

    /// Whether a module arriving at `c` at the end of `step` leaves every
    /// later planned rotation allowed by the rules.
    fn keeps_later_moves_legal(&self, c: Cell, step: usize) -> bool {
        let par = c.z.rem_euclid(2) as usize;
        for &(x, y, z) in &self.reach[par] {
            let p = Cell::new(c.x + x, c.y + y, c.z + z);
            let Some(moves) = self.moves_by_pivot.get(&p) else {
                continue;
            };
            for (s, m) in moves.iter().filter(|(s, _)| *s > step) {
                let occ =
                    |q: Cell| q == c || self.module_at.get(&q).is_some_and(|&(_, at)| at < *s);
                if !self.rules.allows(m, &occ) {
                    return false;
                }
            }
        }
        true
    }

    /// Whether `m`'s blocking cells are crossed by no other rotation of
    /// `step`: two movers of one step may each be legal against the
    /// structure and the agents' cells, yet sweep through the same empty
    /// cell at the same time (the collision of pyramid h = 2, b = 8).
    fn sweep_is_free(&self, m: &Motion, step: usize) -> bool {
        step >= self.swept.len()
            || self
                .rules
                .blocking_cells(m)
                .into_iter()
                .all(|b| !self.swept[step].contains(&b))
    }

    /// The *light pivot* of a rotation to `to` (§3.3.4): among the static
    /// modules `to` will touch, the one further along the path — nearest
    /// to `aim` (the next cell of the route, or `to` itself on the last
    /// hop), the rotation's pivot only when it is the sole neighbour.
    fn light_pivot(&self, to: Cell, pivot: Cell, aim: Cell, step: usize) -> Cell {
        let l = FccLattice;
        let a = l.centre(aim);
        (0..12)
            .map(|k| l.neighbour(to, k))
            .filter(|&q| q != pivot && self.module_at.get(&q).is_some_and(|&(_, at)| at < step))
            .min_by(|&p, &q| {
                let (dp, dq) = ((l.centre(p) - a).length(), (l.centre(q) - a).length());
                dp.total_cmp(&dq)
                    .then((p.x, p.y, p.z).cmp(&(q.x, q.y, q.z)))
            })
            .unwrap_or(pivot)
    }

    /// Whether light pivot `lp` is green at the end of step `t`: no free
    /// agent on any of its connectors. An agent standing on its final
    /// cell has sent FINAL-TARGET-REACHED and no longer counts.
    fn light_is_green(&self, lp: Cell, t: usize) -> bool {
        if t >= self.positions.len() {
            return true;
        }
        let l = FccLattice;
        let p = &self.positions[t];
        (0..12)
            .map(|k| l.neighbour(lp, k))
            .all(|q| !p.contains_key(&q) || self.module_at.get(&q).is_some_and(|&(_, at)| at <= t))
    }

    fn free_of_agents(&self, c: Cell, t: usize) -> bool {
        t >= self.positions.len() || !self.positions[t].contains_key(&c)
    }

    /// Tries to follow `hops` from `src`, entering at step `t0`. Returns
    /// the cell after each step from `t0` on, and the step of each hop.
    fn follow(
        &self,
        t0: usize,
        src: Cell,
        hops: &[Hop],
        ready: usize,
    ) -> Option<(Vec<Cell>, Vec<usize>)> {
        if !self.clear(src, t0 - 1) || !self.clear(src, t0) {
            return None;
        }
        let mut cells = vec![src];
        let mut steps = Vec::with_capacity(hops.len());
        let mut t = t0;
        let mut cur = src;
        for (i, hop) in hops.iter().enumerate() {
            let last = i + 1 == hops.len();
            loop {
                let step = t + 1;
                let pivot_ready = self
                    .module_at
                    .get(&hop.pivot)
                    .is_some_and(|&(_, at)| at < step);
                let mut ok = pivot_ready && (!last || step > ready);
                ok = ok
                    && self.clear(hop.to, t)
                    && self.clear(hop.to, step)
                    && self.clear(cur, step);
                if ok {
                    let m = Motion::Rotate {
                        from: cur,
                        to: hop.to,
                        pivot: hop.pivot,
                        route: hop.route,
                    };
                    // Static modules in place and free agents (before or
                    // after the step) are all obstacles.
                    let occ = |q: Cell| {
                        self.module_at.get(&q).is_some_and(|&(_, at)| at < step)
                            || !self.free_of_agents(q, t)
                            || !self.free_of_agents(q, step)
                    };
                    ok = self.rules.allows(&m, &occ) && self.sweep_is_free(&m, step);
                    if ok && self.protocol == Protocol::Paper {
                        // PROBE-LIGHT-STATE / GREEN-LIGHT-ON: the move
                        // waits while its light pivot is red or orange
                        // (another free agent on it), before or after.
                        let aim = hops.get(i + 1).map_or(hop.to, |h| h.to);
                        let lp = self.light_pivot(hop.to, hop.pivot, aim, step);
                        ok = self.light_is_green(lp, t) && self.light_is_green(lp, step);
                    }
                }
                if ok && last {
                    // Once in place, the module must not stand in the way
                    // of rotations planned for later steps.
                    ok = self.last_use.get(&hop.to).is_none_or(|&u| u <= step)
                        && self.keeps_later_moves_legal(hop.to, step);
                }
                if ok {
                    cur = hop.to;
                    t = step;
                    cells.push(cur);
                    steps.push(step);
                    break;
                }
                if !self.clear(cur, step) {
                    return None;
                }
                cells.push(cur);
                t = step;
            }
        }
        Some((cells, steps))
    }

    /// Plans module `id` from one of `srcs` (entry points with a start
    /// penalty) to `dst`, arriving after step `ready`. Returns the entry
    /// point used and the step at the end of which it is in place.
    pub fn plan(
        &mut self,
        id: ModuleId,
        srcs: &[(Cell, u32)],
        dst: Cell,
        ready: usize,
    ) -> Result<(Cell, usize), InputError> {
        let (src, hops) = self.route_or_explain(id, srcs, dst)?;
        Ok((src, self.commit(id, src, &hops, dst, ready)))
    }

    /// Plans module `id` to `dst` as [`Planner::plan`] does, ready as soon
    /// as its route stands: every pivot in place and every earlier use of
    /// `dst` over (a surplus module, [`super::flow`], has no component
    /// waiting for it).
    pub fn plan_when_route_stands(
        &mut self,
        id: ModuleId,
        srcs: &[(Cell, u32)],
        dst: Cell,
    ) -> Result<(Cell, usize), InputError> {
        let (src, hops) = self.route_or_explain(id, srcs, dst)?;
        let ready = hops
            .iter()
            .map(|h| self.module_at.get(&h.pivot).map_or(0, |&(_, at)| at))
            .chain(self.last_use.get(&dst).copied())
            .max()
            .unwrap_or(0);
        Ok((src, self.commit(id, src, &hops, dst, ready)))
    }

    fn route_or_explain(
        &mut self,
        id: ModuleId,
        srcs: &[(Cell, u32)],
        dst: Cell,
    ) -> Result<(Cell, Vec<Hop>), InputError> {
        let t_route = std::time::Instant::now();
        let routed = self.route(srcs, dst);
        self.timing.0 += t_route.elapsed().as_secs_f64();
        routed.ok_or_else(|| {
            InputError::new(format!(
                "no sequence of rotations leads from any entry point to cell {dst} over the structure \
                 built so far"
            ))
            .for_module(id)
        })
    }

    /// Follows `hops` in time from `src`, arriving at `dst` after step
    /// `ready`, and reserves the module's cells, sweeps and events.
    /// Returns the step at the end of which it is in place.
    fn commit(&mut self, id: ModuleId, src: Cell, hops: &[Hop], dst: Cell, ready: usize) -> usize {
        let t_follow = std::time::Instant::now();
        let mut t0 = (ready + 1).saturating_sub(hops.len()).max(1);
        let (mut cells, mut steps) = loop {
            if let Some(found) = self.follow(t0, src, hops, ready) {
                break found;
            }
            t0 += 1;
        };
        if let Feed::Eager { window } = self.feed {
            // Leave earlier while that arrives sooner (later departures
            // first: among equal arrivals the module holds cells least).
            let soonest = (ready + 1).max(hops.len() + 1);
            let mut arrival = *steps.last().unwrap_or(&t0);
            let earliest = (ready + 1).saturating_sub(hops.len() + window).max(1);
            for e in (earliest..t0).rev() {
                if arrival == soonest {
                    break;
                }
                if let Some((c, s)) = self.follow(e, src, hops, ready) {
                    let a = *s.last().unwrap_or(&e);
                    if a < arrival {
                        (arrival, t0, cells, steps) = (a, e, c, s);
                    }
                }
            }
        }
        self.timing.1 += t_follow.elapsed().as_secs_f64();
        let arrival = *steps.last().unwrap_or(&t0);
        while self.positions.len() <= arrival {
            self.positions.push(FxHashMap::default());
            self.swept.push(FxHashSet::default());
        }
        while self.events.len() < arrival {
            self.events.push(Vec::new());
            self.placed_per_step.push(0);
        }
        for (k, &c) in cells.iter().enumerate() {
            self.positions[t0 + k].insert(c, id);
            let u = self.last_use.entry(c).or_insert(0);
            *u = (*u).max(t0 + k);
        }
        self.events[t0 - 1].push(Event::Enter {
            module: id,
            cell: src,
        });
        let mut from = src;
        for (hop, &step) in hops.iter().zip(&steps) {
            let m = Motion::Rotate {
                from,
                to: hop.to,
                pivot: hop.pivot,
                route: hop.route,
            };
            self.moves_by_pivot
                .entry(hop.pivot)
                .or_default()
                .push((step, m.clone()));
            for b in self.rules.blocking_cells(&m) {
                self.swept[step].insert(b);
                let u = self.last_use.entry(b).or_insert(0);
                *u = (*u).max(step);
            }
            let pivot = self.module_at[&hop.pivot].0;
            self.events[step - 1].push(Event::Rotate {
                module: id,
                pivot,
                from,
                to: hop.to,
                route: hop.route,
            });
            from = hop.to;
        }
        self.placed_per_step[arrival - 1] += 1;
        self.occupied.insert(dst);
        self.module_at.insert(dst, (id, arrival));
        arrival
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_pivot_offers_48_hexagonal_and_72_octagonal_links() {
        let t = rotation_table();
        let hex = t
            .iter()
            .flatten()
            .filter(|r| r.contains(&Route::Hexagonal))
            .count();
        let oct = t
            .iter()
            .flatten()
            .filter(|r| r.contains(&Route::Octagonal))
            .count();
        assert_eq!((hex, oct), (48, 72));
    }
}
