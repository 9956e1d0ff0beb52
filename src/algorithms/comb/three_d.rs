//! Seed 004 in 3D (§3.2) at the meta-module level: 3D-COMBING to a
//! terrain, TERRAIN-TO-COMB (the base layer combed, carrying its towers),
//! Algorithm 3 (3D-COMB-TO-COMMON-COMB, tunnels with up to four turns),
//! and the target's phases in reverse.
//!
//! Both combings are one sweep ([`Robot3::sweep`]): a wall moving against
//! `down` through the meta-modules of a domain, the moving components of
//! each wall sliding past the stationary ones (one `slide` per stationary
//! neighbour they are attached to, carried meta-modules without pivot),
//! then the paper's attach and detach steps 2.4.1–2.4.3.

use super::common_comb::{Comb, MetaRobot, apply, join_reversed};
use super::{Robot, pair};
use crate::lattice::Cell;
use crate::lattice::config::ModuleId;
use crate::schedule::Event;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rustc_hash::{FxHashMap, FxHashSet};
use std::collections::{BTreeSet, VecDeque};

/// A 3D robot: its meta-module cells.
pub type Shape3 = BTreeSet<Cell>;

/// The meta-module state the 3D algorithms update.
#[derive(Clone, Debug)]
pub struct Robot3 {
    pub at: Vec<Cell>,
    by_cell: FxHashMap<Cell, usize>,
    /// Attached neighbouring pairs `(a, b)`, `a < b`.
    pub attached: FxHashSet<(usize, usize)>,
    pub steps: Vec<Vec<Event>>,
}

const X: Cell = Cell::new(1, 0, 0);
const Y: Cell = Cell::new(0, 1, 0);
const Z: Cell = Cell::new(0, 0, 1);

fn dot(a: Cell, b: Cell) -> i32 {
    a.x * b.x + a.y * b.y + a.z * b.z
}

impl MetaRobot for Robot3 {
    fn cell_of(&self, m: usize) -> Cell {
        self.at[m]
    }
    fn at_cell(&self, c: Cell) -> Option<usize> {
        self.by_cell.get(&c).copied()
    }
    fn attached_mut(&mut self) -> &mut FxHashSet<(usize, usize)> {
        &mut self.attached
    }
    fn move_all(&mut self, moves: &[(usize, Cell)]) {
        for &(k, _) in moves {
            self.by_cell.remove(&self.at[k]);
        }
        for &(k, to) in moves {
            self.at[k] = to;
            self.by_cell.insert(to, k);
        }
    }
    fn steps_mut(&mut self) -> &mut Vec<Vec<Event>> {
        &mut self.steps
    }
    fn attached(&self) -> &FxHashSet<(usize, usize)> {
        &self.attached
    }
    fn count(&self) -> usize {
        self.at.len()
    }
}

impl Robot3 {
    /// Every neighbouring pair attached; ids in the shape's order.
    pub fn new(shape: &Shape3) -> Robot3 {
        let at: Vec<Cell> = shape.iter().copied().collect();
        let by_cell: FxHashMap<Cell, usize> = at.iter().enumerate().map(|(k, &c)| (c, k)).collect();
        let mut attached = FxHashSet::default();
        for (k, &c) in at.iter().enumerate() {
            for d in [X, Y, Z] {
                if let Some(&o) = by_cell.get(&(c + d)) {
                    attached.insert(pair(k, o));
                }
            }
        }
        Robot3 {
            at,
            by_cell,
            attached,
            steps: Vec::new(),
        }
    }

    pub fn get(&self, c: Cell) -> Option<usize> {
        self.by_cell.get(&c).copied()
    }

    fn latch_step(&mut self, mut pairs: Vec<(usize, usize)>, attach: bool) {
        pairs = pairs.into_iter().map(|(a, b)| pair(a, b)).collect();
        pairs.sort_unstable();
        pairs.dedup();
        let events: Vec<Event> = pairs
            .into_iter()
            .filter(|p| self.attached.contains(p) != attach)
            .map(|(a, b)| {
                let (module, other) = (a as ModuleId, b as ModuleId);
                if attach {
                    Event::Attach { module, other }
                } else {
                    Event::Detach { module, other }
                }
            })
            .collect();
        if !events.is_empty() {
            apply(self, &events);
        }
    }

    /// One combing sweep (Algorithm 1 generalised): the wall starts at the
    /// domain's highest layer against `down` and moves down a layer each
    /// iteration; wall meta-modules with nothing below move, in components
    /// joined along `lateral`, each component carried by a SLIDE(`down`)
    /// of each of its meta-modules along every stationary wall
    /// meta-module beside it, with everything attached above it.
    pub fn sweep(&mut self, down: Cell, lateral: &[Cell], domain: impl Fn(Cell) -> bool) {
        let h = |c: Cell| -dot(c, down);
        let heights: Vec<i32> = self
            .at
            .iter()
            .copied()
            .filter(|&c| domain(c))
            .map(h)
            .collect();
        let (Some(&top), Some(&bottom)) = (heights.iter().max(), heights.iter().min()) else {
            return;
        };
        let mut wall = top;
        while wall > bottom {
            let at_level = |r: &Robot3, m: usize, w: i32| domain(r.at[m]) && h(r.at[m]) == w;
            let moving = |r: &Robot3, m: usize| r.get(r.at[m] + down).is_none();
            let wall_ids: Vec<usize> = (0..self.at.len())
                .filter(|&m| at_level(self, m, wall))
                .collect();
            let stationary: FxHashSet<usize> = wall_ids
                .iter()
                .copied()
                .filter(|&m| !moving(self, m))
                .collect();
            let mut events = Vec::new();
            let mut carried: BTreeSet<usize> = BTreeSet::new();
            let mut sliders: FxHashSet<usize> = FxHashSet::default();
            for &a in wall_ids.iter().filter(|&&m| moving(self, m)) {
                for &l in lateral {
                    if let Some(s) = self.get(self.at[a] + l)
                        && stationary.contains(&s)
                        && self.attached.contains(&pair(a, s))
                    {
                        events.push(Event::Slide {
                            module: a as ModuleId,
                            from: self.at[a],
                            to: self.at[a] + down,
                            pivot: Some(s as ModuleId),
                        });
                        sliders.insert(a);
                    }
                }
                // Everything attached to the component, not through the
                // stationary wall, moves with it.
                if carried.insert(a) {
                    let mut stack = vec![a];
                    while let Some(m) = stack.pop() {
                        for d in [X, Y, Z, Cell::ZERO - X, Cell::ZERO - Y, Cell::ZERO - Z] {
                            if let Some(o) = self.get(self.at[m] + d)
                                && self.attached.contains(&pair(m, o))
                                && !stationary.contains(&o)
                                && carried.insert(o)
                            {
                                stack.push(o);
                            }
                        }
                    }
                }
            }
            for &m in &carried {
                if !sliders.contains(&m) {
                    events.push(Event::Slide {
                        module: m as ModuleId,
                        from: self.at[m],
                        to: self.at[m] + down,
                        pivot: None,
                    });
                }
            }
            if !events.is_empty() {
                apply(self, &events);
            }
            wall -= 1;
            // 2.4.1 and 2.4.3: the moved meta-modules attach to their new
            // neighbours in the wall, and the wall to what is below it.
            let mut attach = Vec::new();
            for &m in &carried {
                if at_level(self, m, wall) {
                    for &l in lateral {
                        if let Some(o) = self.get(self.at[m] + l)
                            && at_level(self, o, wall)
                        {
                            attach.push((m, o));
                        }
                    }
                }
            }
            for m in (0..self.at.len()).filter(|&m| at_level(self, m, wall)) {
                if let Some(o) = self.get(self.at[m] + down) {
                    attach.push((m, o));
                }
            }
            self.latch_step(attach, true);
            // 2.4.2: the meta-modules new above the wall let go of their
            // neighbours along the wall.
            let mut detach = Vec::new();
            for m in (0..self.at.len()).filter(|&m| at_level(self, m, wall + 1)) {
                for &l in lateral {
                    if let Some(o) = self.get(self.at[m] + l) {
                        detach.push((m, o));
                    }
                }
            }
            self.latch_step(detach, false);
        }
    }

    /// §3.2.1–3.2.2: 3D-COMBING into a terrain (towers on a base layer),
    /// then the base layer combed along −y, carrying its towers: a 3D comb
    /// (an xy-comb whose teeth and handle cells are the handles of
    /// z-combs).
    pub fn comb(&mut self) {
        let lateral_xy = [X, Y, Cell::ZERO - X, Cell::ZERO - Y];
        self.sweep(Cell::ZERO - Z, &lateral_xy, |_| true);
        let Some(z0) = self.at.iter().map(|c| c.z).min() else {
            return;
        };
        self.sweep(Cell::ZERO - Y, &[X, Cell::ZERO - X], |c| c.z == z0);
    }
}

/// A 3D comb (§3.2.3): its xy-comb's handle from `(x0, y0, z0)` along x,
/// and in each plane `x0 + i` the z-comb `planes[i]` (a 2D comb in
/// (y, z), its handle from `(y0, z0)`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Comb3 {
    pub x0: i32,
    pub y0: i32,
    pub z0: i32,
    pub planes: Vec<Comb>,
}

fn plane_of(shape: &Shape3, x: i32) -> super::Shape {
    shape
        .iter()
        .filter(|c| c.x == x)
        .map(|c| (c.y, c.z))
        .collect()
}

impl Comb3 {
    /// The 3D comb a shape is, if it is one.
    pub fn of(shape: &Shape3) -> Option<Comb3> {
        let x0 = shape.iter().map(|c| c.x).min()?;
        let x1 = shape.iter().map(|c| c.x).max()?;
        let y0 = shape.iter().map(|c| c.y).min()?;
        let z0 = shape.iter().map(|c| c.z).min()?;
        let mut planes = Vec::new();
        for x in x0..=x1 {
            let c = Comb::of(&plane_of(shape, x))?;
            if (c.x0, c.y0) != (y0, z0) {
                return None;
            }
            planes.push(c);
        }
        Some(Comb3 { x0, y0, z0, planes })
    }

    /// C_U: the longer xy handle, each z-comb the union of the two.
    pub fn union(&self, other: &Comb3) -> Comb3 {
        assert_eq!(
            (self.x0, self.y0, self.z0),
            (other.x0, other.y0, other.z0),
            "aligned combs"
        );
        let empty = Comb {
            x0: self.y0,
            y0: self.z0,
            teeth: vec![],
        };
        let n = self.planes.len().max(other.planes.len());
        Comb3 {
            planes: (0..n)
                .map(|i| {
                    self.planes
                        .get(i)
                        .unwrap_or(&empty)
                        .union(other.planes.get(i).unwrap_or(&empty))
                })
                .collect(),
            ..self.clone()
        }
    }

    /// The 3D common comb of `m` meta-modules in this shell: the xy
    /// handle, then in the order the paper lists them (planes from the
    /// far end, in each its handle outwards, then its teeth by decreasing
    /// y, each from the handle up) the first `m − u`.
    pub fn common_comb(&self, m: usize) -> Shape3 {
        let u = self.planes.len();
        let mut out: Shape3 = (0..u as i32)
            .map(|i| Cell::new(self.x0 + i, self.y0, self.z0))
            .collect();
        let mut list = Vec::new();
        for (i, p) in self.planes.iter().enumerate().rev() {
            let x = self.x0 + i as i32;
            for j in 1..p.teeth.len() as i32 {
                list.push(Cell::new(x, self.y0 + j, self.z0));
            }
            for (j, &t) in p.teeth.iter().enumerate().rev() {
                for k in 1..=t as i32 {
                    list.push(Cell::new(x, self.y0 + j as i32, self.z0 + k));
                }
            }
        }
        out.extend(list.into_iter().take(m.saturating_sub(u)));
        out
    }
}

/// The orthogonal path of Algorithm 3's tunnels: from `from` down to the
/// base layer, along −y to the xy handle, along x to the exit's plane,
/// along +y and up to the exit (start cell first; at most four turns).
pub fn comb3_path(from: Cell, to: Cell, y0: i32, z0: i32) -> Vec<Cell> {
    let mut p = vec![from];
    let mut c = from;
    let go = |c: &mut Cell, d: Cell, n: i32, p: &mut Vec<Cell>| {
        for _ in 0..n {
            *c = *c + d;
            p.push(*c);
        }
    };
    go(&mut c, Cell::ZERO - Z, from.z - z0, &mut p);
    go(&mut c, Cell::ZERO - Y, from.y - y0, &mut p);
    let dx = if to.x >= c.x { X } else { Cell::ZERO - X };
    go(&mut c, dx, (to.x - from.x).abs(), &mut p);
    go(&mut c, Y, to.y - y0, &mut p);
    go(&mut c, Z, to.z - z0, &mut p);
    p
}

impl Robot3 {
    fn tunnel3(&mut self, from: Cell, to: Cell, y0: i32, z0: i32) {
        let leaf = self.get(from).expect("a leaf") as ModuleId;
        let path = comb3_path(from, to, y0, z0);
        apply(self, &[Event::Tunnel { module: leaf, path }]);
    }

    fn plane_count(&self, x: i32) -> usize {
        self.at.iter().filter(|c| c.x == x).count()
    }

    /// Algorithm 3, 3D-COMB-TO-COMMON-COMB, into the shell `u` (C_U).
    pub fn to_common_comb(&mut self, u: &Comb3) {
        let (x0, y0, z0) = (u.x0, u.y0, u.z0);
        let s = self.at.iter().filter(|c| c.y == y0 && c.z == z0).count();
        // Step 1: each z-comb to its 2D common comb, in its yz plane.
        for (i, plane) in u.planes.iter().enumerate().take(s) {
            let x = x0 + i as i32;
            let ids: Vec<usize> = (0..self.at.len()).filter(|&m| self.at[m].x == x).collect();
            let shape: super::Shape = ids.iter().map(|&m| (self.at[m].y, self.at[m].z)).collect();
            let mut r = Robot::new(&shape);
            // The 2D robot's ids follow its shape's order; map them back.
            let global: Vec<usize> =
                r.at.iter()
                    .map(|&(y, z)| self.get(Cell::new(x, y, z)).expect("in the plane"))
                    .collect();
            r.attached
                .retain(|&(a, b)| self.attached.contains(&pair(global[a], global[b])));
            r.to_common_comb(plane);
            for events in std::mem::take(&mut r.steps) {
                let lifted: Vec<Event> = events
                    .into_iter()
                    .map(|e| match e {
                        Event::Tunnel { module, path } => Event::Tunnel {
                            module: global[module as usize] as ModuleId,
                            path: path.iter().map(|c| Cell::new(x, c.x, c.y)).collect(),
                        },
                        e => panic!("Algorithm 2 moves by tunnels only: {e:?}"),
                    })
                    .collect();
                apply(self, &lifted);
            }
        }
        // Step 2: the queue, planes from the far end: teeth by increasing
        // y then decreasing z, then handle cells by decreasing y.
        let mut queue: VecDeque<Cell> = VecDeque::new();
        for i in (0..s).rev() {
            let x = x0 + i as i32;
            let mut teeth: Vec<Cell> = self
                .at
                .iter()
                .copied()
                .filter(|c| c.x == x && c.z > z0)
                .collect();
            teeth.sort_unstable_by_key(|c| (c.y, -c.z));
            let mut handle: Vec<Cell> = self
                .at
                .iter()
                .copied()
                .filter(|c| c.x == x && c.z == z0 && c.y > y0)
                .collect();
            handle.sort_unstable_by_key(|c| -c.y);
            queue.extend(teeth);
            queue.extend(handle);
        }
        // Step 3: the xy handle to length u.
        for i in s..u.planes.len() {
            let Some(o) = queue.pop_front() else { return };
            self.tunnel3(o, Cell::new(x0 + i as i32, y0, z0), y0, z0);
        }
        // Step 4: each z-comb's handle, then its short teeth.
        for i in (0..u.planes.len()).rev() {
            let x = x0 + i as i32;
            for _ in 1..self.plane_count(x) {
                queue.pop_front();
            }
            let handle = |r: &Robot3| {
                (0..)
                    .take_while(|&j| r.get(Cell::new(x, y0 + j, z0)).is_some())
                    .count()
            };
            let plane = &u.planes[i];
            for j in handle(self)..plane.teeth.len() {
                let Some(o) = queue.pop_front() else { return };
                self.tunnel3(o, Cell::new(x, y0 + j as i32, z0), y0, z0);
            }
            for j in (0..handle(self)).rev() {
                let have = (1..)
                    .take_while(|&k| self.get(Cell::new(x, y0 + j as i32, z0 + k)).is_some())
                    .count();
                for k in have..plane.teeth[j] {
                    let Some(o) = queue.pop_front() else { return };
                    self.tunnel3(o, Cell::new(x, y0 + j as i32, z0 + 1 + k as i32), y0, z0);
                }
            }
        }
    }
}

/// Theorem 2's reconfiguration in 3D: the four phases as in 2D, the
/// combing being the two sweeps of [`Robot3::comb`].
pub type Reconfiguration3 = super::common_comb::Reconfiguration<Shape3, Robot3>;

/// A `meta_modules` schedule of `steps` from the robot `start` (ids in
/// its order), no meta-module fixed (the robot must stay one piece).
pub fn schedule_of(
    start: &Shape3,
    steps: Vec<Vec<Event>>,
    rest: crate::lattice::AtomRest,
) -> crate::schedule::Schedule {
    let at: Vec<Cell> = start.iter().copied().collect();
    schedule_at(&at, steps, rest)
}

/// [`schedule_of`] from meta-module `k` at `at[k]` (a robot in the middle
/// of a run, its ids kept).
pub fn schedule_at(
    at: &[Cell],
    steps: Vec<Vec<Event>>,
    rest: crate::lattice::AtomRest,
) -> crate::schedule::Schedule {
    let mut s = crate::schedule::Schedule::new(
        crate::lattice::LatticeKind::Cubic,
        crate::schedule::Length::mm(120.0),
    );
    s.meta_modules = Some(rest);
    s.modules = at
        .iter()
        .enumerate()
        .map(|(k, &cell)| crate::schedule::ModuleSpec {
            id: k as ModuleId,
            cell,
            fixed: false,
        })
        .collect();
    s.steps = steps
        .into_iter()
        .map(|events| crate::schedule::Step { events })
        .collect();
    s
}

/// §3.2: `source` to `target` (moved onto the source's lowest corner).
pub fn reconfigure3(source: &Shape3, target: &Shape3) -> Reconfiguration3 {
    let corner = |s: &Shape3| {
        Cell::new(
            s.iter().map(|c| c.x).min().unwrap_or(0),
            s.iter().map(|c| c.y).min().unwrap_or(0),
            s.iter().map(|c| c.z).min().unwrap_or(0),
        )
    };
    let shift = corner(source) - corner(target);
    let target: Shape3 = target.iter().map(|&c| c + shift).collect();
    let shape = |r: &Robot3| -> Shape3 { r.at.iter().copied().collect() };
    let mut s = Robot3::new(source);
    s.comb();
    let comb_s = std::mem::take(&mut s.steps);
    let t0 = Robot3::new(&target);
    let mut t = t0.clone();
    t.comb();
    let comb_t = std::mem::take(&mut t.steps);
    let after_comb_t = t.clone();
    let u = Comb3::of(&shape(&s))
        .expect("combing makes a 3D comb")
        .union(&Comb3::of(&shape(&t)).expect("combing makes a 3D comb"));
    s.to_common_comb(&u);
    let common_s = std::mem::take(&mut s.steps);
    t.to_common_comb(&u);
    assert_eq!(shape(&s), shape(&t), "one common comb");
    let ccs_t = std::mem::take(&mut t.steps);
    let (phase3, back_comb) = join_reversed(&mut s, &t, &t0, &comb_t, &after_comb_t, &ccs_t);
    super::common_comb::Reconfiguration {
        target,
        phases: [comb_s, common_s, phase3, back_comb],
        end: s,
    }
}

/// A random connected polycube of `m` cells grown from the origin, moved
/// to have its lowest corner at 0.
pub fn random_polycube(m: usize, rng: &mut ChaCha8Rng) -> Shape3 {
    let dirs = [X, Y, Z, Cell::ZERO - X, Cell::ZERO - Y, Cell::ZERO - Z];
    let mut cells = vec![Cell::ZERO];
    let mut set: FxHashSet<Cell> = cells.iter().copied().collect();
    while cells.len() < m {
        let c = cells[rng.random_range(0..cells.len())] + dirs[rng.random_range(0..6)];
        if set.insert(c) {
            cells.push(c);
        }
    }
    let lo = Cell::new(
        cells.iter().map(|c| c.x).min().unwrap_or(0),
        cells.iter().map(|c| c.y).min().unwrap_or(0),
        cells.iter().map(|c| c.z).min().unwrap_or(0),
    );
    cells.into_iter().map(|c| c - lo).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn combing_in_3d_makes_a_terrain_then_a_3d_comb() {
        for seed in 0..20 {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let shape = random_polycube(40, &mut rng);
            let mut r = Robot3::new(&shape);
            let lateral = [X, Y, Cell::ZERO - X, Cell::ZERO - Y];
            r.sweep(Cell::ZERO - Z, &lateral, |_| true);
            let cells: Shape3 = r.at.iter().copied().collect();
            // A terrain: every (x, y) column one run from the base layer.
            for c in &cells {
                assert!(
                    (0..c.z).all(|z| cells.contains(&Cell::new(c.x, c.y, z))),
                    "seed {seed}"
                );
            }
            let mut r = Robot3::new(&shape);
            r.comb();
            let cells: Shape3 = r.at.iter().copied().collect();
            assert_eq!(cells.len(), shape.len());
            assert!(Comb3::of(&cells).is_some(), "seed {seed}: not a 3D comb");
        }
    }

    #[test]
    fn theorem_2_reaches_the_target_through_the_3d_common_comb() {
        for seed in 0..30 {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let m = 5 + (seed as usize % 6) * 9;
            let (a, b) = (random_polycube(m, &mut rng), random_polycube(m, &mut rng));
            let plan = reconfigure3(&a, &b);
            let end: Shape3 = plan.end.at.iter().copied().collect();
            assert_eq!(end, plan.target, "seed {seed}");
            // After the second phase: the common comb.
            let mut r = Robot3::new(&a);
            for es in plan.phases[..2].iter().flatten() {
                apply(&mut r, es);
            }
            let mut cs = Robot3::new(&a);
            cs.comb();
            let mut ct = Robot3::new(&plan.target);
            ct.comb();
            let shape = |r: &Robot3| -> Shape3 { r.at.iter().copied().collect() };
            let u = Comb3::of(&shape(&cs))
                .unwrap()
                .union(&Comb3::of(&shape(&ct)).unwrap());
            assert_eq!(shape(&r), u.common_comb(m), "seed {seed}");
            for e in plan.phases[1].iter().flatten() {
                if let Event::Tunnel { path, .. } = e {
                    let turns = crate::lattice::path_turns(path).len();
                    assert!(turns <= 4, "seed {seed}: {turns} turns");
                }
            }
        }
    }
}
