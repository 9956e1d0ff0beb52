//! Shortest rotation paths of one catom through a static scene, by
//! breadth-first search over the geometry-derived motion rules
//! (`crate::geometry::rules`): every hop is a real rotation on a latched
//! static pivot whose sweep penetrates no occupied cell and no ground cell
//! (the certifier does not treat the ground as an obstacle for sweeps, so
//! the search does), and whose two sliding contacts never pinch it. In the
//! strict mode no hop even touches a module other than its pivot.

use crate::geometry::ContactKind;
use crate::geometry::rolling::{Link, Roll, links};
use crate::geometry::rules::table;
use crate::lattice::config::ModuleId;
use crate::lattice::{Cell, FccLattice, Lattice, Route, fcc};
use rustc_hash::{FxHashMap, FxHashSet};
use std::collections::VecDeque;
use std::sync::OnceLock;

/// One rotation in cell terms.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct Hop {
    pub from: Cell,
    pub to: Cell,
    pub pivot: Cell,
    pub route: Route,
}

/// A static scene: occupied cells (with their modules), the ground layer
/// and the box a mover may use.
#[derive(Clone, Debug)]
pub struct Scene {
    pub at: FxHashMap<Cell, ModuleId>,
    pub fixed: FxHashSet<ModuleId>,
    pub ground: Option<i32>,
    pub lo: Cell,
    pub hi: Cell,
    /// If set, the only cells a mover may enter (a streamline's region).
    pub region: Option<FxHashSet<Cell>>,
}

/// The links of a pivot grouped by their start connector.
fn links_from() -> &'static [Vec<Link>; 12] {
    static T: OnceLock<[Vec<Link>; 12]> = OnceLock::new();
    T.get_or_init(|| {
        let all = links();
        std::array::from_fn(|f| {
            all.iter()
                .copied()
                .filter(|l| l.from as usize == f)
                .collect()
        })
    })
}

/// How far below the ground plane a sampled sweep may dip (units of d).
pub const GROUND_TOLERANCE: f64 = 1e-4;

/// Lowest point of each link's swept body below its pivot's centre (units
/// of d, ≤ 0), sampled at 1024 points along the sweep (the ends exact: a
/// catom rolling onto the ground touches it at s = 1); indexed by (from,
/// to, route).
fn lowest(link: Link) -> f64 {
    static T: OnceLock<FxHashMap<(u8, u8, Route), f64>> = OnceLock::new();
    let t = T.get_or_init(|| {
        let down = glam::DVec3::new(0.0, 0.0, -1.0);
        links()
            .into_iter()
            .map(|l| {
                let roll = Roll::new(glam::DVec3::ZERO, l);
                let n = 1024;
                let low = (0..=n)
                    .map(|i| -roll.support(i as f64 / n as f64, down))
                    .fold(f64::INFINITY, f64::min);
                ((l.from, l.to, l.route), low)
            })
            .collect()
    });
    t[&(link.from, link.to, link.route)]
}

impl Scene {
    pub fn new(ground: Option<i32>) -> Scene {
        Scene {
            at: FxHashMap::default(),
            fixed: FxHashSet::default(),
            ground,
            lo: Cell::new(i32::MAX, i32::MAX, i32::MAX),
            hi: Cell::new(i32::MIN, i32::MIN, i32::MIN),
            region: None,
        }
    }

    pub fn insert(&mut self, id: ModuleId, c: Cell) {
        self.at.insert(c, id);
    }

    /// Sets the search box to the occupied cells' box grown by `margin`
    /// (never below the ground).
    pub fn fit_box(&mut self, extra: &[Cell], margin: i32) {
        let mut lo = Cell::new(i32::MAX, i32::MAX, i32::MAX);
        let mut hi = Cell::new(i32::MIN, i32::MIN, i32::MIN);
        for c in self.at.keys().chain(extra) {
            lo = Cell::new(lo.x.min(c.x), lo.y.min(c.y), lo.z.min(c.z));
            hi = Cell::new(hi.x.max(c.x), hi.y.max(c.y), hi.z.max(c.z));
        }
        self.lo = Cell::new(lo.x - margin, lo.y - margin, lo.z - margin);
        if let Some(g) = self.ground {
            self.lo.z = self.lo.z.max(g);
        }
        self.hi = Cell::new(hi.x + margin, hi.y + margin, hi.z + margin);
    }

    fn in_box(&self, c: Cell) -> bool {
        if let Some(r) = &self.region {
            return r.contains(&c);
        }
        (self.lo.x..=self.hi.x).contains(&c.x)
            && (self.lo.y..=self.hi.y).contains(&c.y)
            && (self.lo.z..=self.hi.z).contains(&c.z)
    }

    /// Whether `c` holds a module or is solid ground.
    pub fn blocked(&self, c: Cell) -> bool {
        self.at.contains_key(&c) || self.ground.is_some_and(|g| c.z < g)
    }

    /// Whether every module but `without` stays connected, through latched
    /// neighbours, to the ground or a fixed module (to one component when
    /// the scene has neither).
    pub fn connected_without(&self, without: Option<Cell>) -> bool {
        let l = FccLattice;
        let mut seen: FxHashSet<Cell> = FxHashSet::default();
        let mut stack: Vec<Cell> = Vec::new();
        for (c, id) in &self.at {
            if Some(*c) == without {
                continue;
            }
            if self.fixed.contains(id) || self.ground.is_some_and(|g| c.z == g) {
                seen.insert(*c);
                stack.push(*c);
            }
        }
        if stack.is_empty()
            && let Some(c) = self.at.keys().find(|c| Some(**c) != without)
        {
            seen.insert(*c);
            stack.push(*c);
        }
        while let Some(c) = stack.pop() {
            for n in l.neighbours(c) {
                if Some(n) != without && self.at.contains_key(&n) && seen.insert(n) {
                    stack.push(n);
                }
            }
        }
        seen.len() == self.at.len() - usize::from(without.is_some_and(|w| self.at.contains_key(&w)))
    }

    /// Whether the rotation `hop` of a mover (whose start cell is not in
    /// `at`) is free of collisions, pinches and (strict) sliding contact.
    pub fn allows(&self, link: Link, hop: &Hop, strict: bool) -> bool {
        if let Some(g) = self.ground {
            // The ground plane is half a spacing below the centres of layer g.
            let l = FccLattice;
            let floor = l.centre(Cell::new(0, 0, g)).z - 0.5;
            // 1e-4 d: what the sampling may miss between samples.
            if l.centre(hop.pivot).z + lowest(link) < floor - GROUND_TOLERANCE {
                return false;
            }
        }
        let rules = table().get(link);
        let occ = |c: Cell| c != hop.from && c != hop.to && self.at.contains_key(&c);
        for e in &rules.entries {
            let c = e.offset.from(hop.pivot);
            if (e.kind == ContactKind::Collision || strict) && occ(c) {
                return false;
            }
        }
        !rules
            .pinches
            .iter()
            .any(|(a, b)| occ(a.from(hop.pivot)) && occ(b.from(hop.pivot)))
    }

    /// The rotations a mover in `c` can make (its own start cell already
    /// removed from `at`).
    pub fn hops(&self, c: Cell, strict: bool) -> Vec<Hop> {
        let l = FccLattice;
        let mut out = Vec::new();
        for k in 0..12 {
            let p = l.neighbour(c, k);
            if !self.at.contains_key(&p) {
                continue;
            }
            let f = fcc::opposite(k);
            for link in &links_from()[f] {
                let to = l.neighbour(p, link.to as usize);
                if self.blocked(to) || !self.in_box(to) {
                    continue;
                }
                let hop = Hop {
                    from: c,
                    to,
                    pivot: p,
                    route: link.route,
                };
                if self.allows(*link, &hop, strict) {
                    out.push(hop);
                }
            }
        }
        out
    }

    /// A shortest rotation path of the module in `start` to `goal`, the
    /// rest of the scene static; `None` if there is none inside the box.
    pub fn route(&self, start: Cell, goal: Cell, strict: bool) -> Option<Vec<Hop>> {
        let mut me = self.clone();
        me.at.remove(&start);
        me.route_free(start, goal, strict)
    }

    /// Shortest paths of the module in `start` to each of `goals` (one
    /// breadth-first search).
    pub fn routes(&self, start: Cell, goals: &[Cell], strict: bool) -> Vec<Option<Vec<Hop>>> {
        let mut me = self.clone();
        me.at.remove(&start);
        let mut prev: FxHashMap<Cell, Hop> = FxHashMap::default();
        let mut queue = VecDeque::from([start]);
        let mut seen: FxHashSet<Cell> = FxHashSet::from_iter([start]);
        let mut left = goals.iter().filter(|g| **g != start).count();
        while let Some(c) = queue.pop_front() {
            if left == 0 {
                break;
            }
            for h in me.hops(c, strict) {
                if !seen.insert(h.to) {
                    continue;
                }
                prev.insert(h.to, h);
                if goals.contains(&h.to) {
                    left -= 1;
                }
                queue.push_back(h.to);
            }
        }
        goals
            .iter()
            .map(|g| {
                if *g == start {
                    return Some(Vec::new());
                }
                let mut at = *g;
                let mut path = Vec::new();
                while at != start {
                    let h = *prev.get(&at)?;
                    path.push(h);
                    at = h.from;
                }
                path.reverse();
                Some(path)
            })
            .collect()
    }

    /// As [`Scene::route`], for a mover not in `at` (entering at `start`).
    pub fn route_free(&self, start: Cell, goal: Cell, strict: bool) -> Option<Vec<Hop>> {
        if start == goal {
            return Some(Vec::new());
        }
        let mut prev: FxHashMap<Cell, Hop> = FxHashMap::default();
        let mut queue = VecDeque::from([start]);
        let mut seen: FxHashSet<Cell> = FxHashSet::from_iter([start]);
        while let Some(c) = queue.pop_front() {
            for h in self.hops(c, strict) {
                if !seen.insert(h.to) {
                    continue;
                }
                prev.insert(h.to, h);
                if h.to == goal {
                    let mut path = vec![h];
                    let mut at = h.from;
                    while at != start {
                        let p = prev[&at];
                        path.push(p);
                        at = p.from;
                    }
                    path.reverse();
                    return Some(path);
                }
                queue.push_back(h.to);
            }
        }
        None
    }
}
