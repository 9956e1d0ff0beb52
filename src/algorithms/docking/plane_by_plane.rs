//! Seed 002 in 3D on the FCC lattice: the goal is built plane by plane,
//! bottom up, each horizontal layer by the 2D planner ([`super::planner`]),
//! as the paper extends its 2D algorithm (§4.2).
//!
//! An FCC layer is a square grid (in-plane neighbours `(±1, 0)`, `(0, ±1)`),
//! so each in-plane component of a layer is a 2D goal. **EndOfPlane**: a
//! layer starts once the layer below is finished; each of its components is
//! seeded by a module docking onto the finished layer (its cell nearest the
//! component's centroid among those with a neighbour below), then grows in
//! its plane with the 2D rules, the components of one layer concurrently.
//! A component with nothing below it (an overhang) waits until the end and
//! is then seeded from any finished neighbour, above included; one that no
//! module touches even then is left unfilled and counted.
//!
//! Messages are the 2D runs' (the authors do not count plane-finished
//! messages); Rule 1 is checked in 3D as the authors coded it
//! ([`super::rule1::blocked_fcc`]) on the merged docking order.

use super::goal::Goal;
use super::planner::{self, Delays, Messages};
use super::rule1;
use crate::algorithms::scaffold::csg::CsgShape;
use crate::error::InputError;
use crate::lattice::{Cell, FccLattice, Lattice};
use rustc_hash::FxHashSet;
use std::collections::{BTreeMap, VecDeque};
use std::path::Path;

/// Largest 3D goal, in cells.
pub const MAX_CELLS: usize = 2_000_000;

/// A 3D goal on the FCC lattice.
#[derive(Clone, Debug)]
pub struct Goal3 {
    pub name: String,
    pub cells: FxHashSet<Cell>,
}

impl Goal3 {
    /// The FCC cells whose centres a CSG solid scaled by `scale` contains,
    /// shifted by an even number of layers so that the lowest is 0 or 1.
    pub fn from_csg(path: &Path, scale: f64) -> Result<Goal3, InputError> {
        let shape = CsgShape::load(path)?;
        Goal3::from_csg_shape(&shape, scale).map_err(|e| e.in_file(path))
    }

    pub fn from_csg_shape(shape: &CsgShape, scale: f64) -> Result<Goal3, InputError> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(InputError::new(format!(
                "scale {scale} must be finite and positive"
            )));
        }
        let (lo, hi) = shape.root.bounds();
        let (lo, hi) = (lo * scale, hi * scale);
        let volume = (hi - lo + 3.0).element_product() * std::f64::consts::SQRT_2;
        if !(volume.is_finite() && volume <= 4.0 * MAX_CELLS as f64) {
            return Err(InputError::new(format!(
                "goal '{}' at scale {scale} spans more than {MAX_CELLS} cells",
                shape.name
            )));
        }
        let s2 = std::f64::consts::SQRT_2;
        let mut cells = FxHashSet::default();
        for z in (lo.z * s2).floor() as i32 - 1..=(hi.z * s2).ceil() as i32 + 1 {
            for y in lo.y.floor() as i32 - 2..=hi.y.ceil() as i32 + 2 {
                for x in lo.x.floor() as i32 - 2..=hi.x.ceil() as i32 + 2 {
                    let c = Cell::new(x, y, z);
                    if shape.root.contains(FccLattice.centre(c) / scale) {
                        cells.insert(c);
                    }
                }
            }
        }
        let zmin = cells.iter().map(|c| c.z).min().ok_or_else(|| {
            InputError::new(format!(
                "goal '{}' has no cell at scale {scale}: there is no cell for the seed",
                shape.name
            ))
        })?;
        let dz = zmin - zmin.rem_euclid(2);
        let lim = crate::schedule::MAX_COORDINATE - 2;
        if cells
            .iter()
            .any(|c| c.x.abs() > lim || c.y.abs() > lim || (c.z - dz).abs() > lim)
        {
            return Err(InputError::new(format!(
                "goal '{}' lies off the lattice: cells beyond ±{lim}",
                shape.name
            )));
        }
        let g = Goal3 {
            name: shape.name.clone(),
            cells: cells
                .into_iter()
                .map(|c| Cell::new(c.x, c.y, c.z - dz))
                .collect(),
        };
        g.validate()?;
        Ok(g)
    }

    /// Refuses a goal that is empty, too large or not connected.
    pub fn validate(&self) -> Result<(), InputError> {
        let Some(&start) = self.cells.iter().min() else {
            return Err(InputError::new(format!("goal '{}' has no cell", self.name)));
        };
        if self.cells.len() > MAX_CELLS {
            return Err(InputError::new(format!(
                "goal '{}' has {} cells, more than {MAX_CELLS}",
                self.name,
                self.cells.len()
            )));
        }
        let mut seen: FxHashSet<Cell> = [start].into_iter().collect();
        let mut q = VecDeque::from([start]);
        while let Some(c) = q.pop_front() {
            for n in FccLattice.neighbours(c) {
                if self.cells.contains(&n) && seen.insert(n) {
                    q.push_back(n);
                }
            }
        }
        if seen.len() != self.cells.len() {
            return Err(InputError::new(format!(
                "goal '{}' is disconnected: {} of its {} cells are not connected to {start}",
                self.name,
                self.cells.len() - seen.len(),
                self.cells.len()
            )));
        }
        Ok(())
    }

    pub fn len(&self) -> usize {
        self.cells.len()
    }

    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// The lowest layer.
    pub fn bottom(&self) -> i32 {
        self.cells.iter().map(|c| c.z).min().unwrap_or(0)
    }

    /// The in-plane components of each layer, bottom up.
    fn components(&self) -> BTreeMap<i32, Vec<Vec<(i32, i32)>>> {
        let mut layers: BTreeMap<i32, FxHashSet<(i32, i32)>> = BTreeMap::new();
        for c in &self.cells {
            layers.entry(c.z).or_default().insert((c.x, c.y));
        }
        layers
            .into_iter()
            .map(|(z, set)| {
                let mut seen: FxHashSet<(i32, i32)> = FxHashSet::default();
                let mut sorted: Vec<(i32, i32)> = set.iter().copied().collect();
                sorted.sort_unstable();
                let mut comps = Vec::new();
                for s in sorted {
                    if !seen.insert(s) {
                        continue;
                    }
                    let mut comp = vec![s];
                    let mut i = 0;
                    while i < comp.len() {
                        let (x, y) = comp[i];
                        for n in [(x + 1, y), (x - 1, y), (x, y + 1), (x, y - 1)] {
                            if set.contains(&n) && seen.insert(n) {
                                comp.push(n);
                            }
                        }
                        i += 1;
                    }
                    comps.push(comp);
                }
                (z, comps)
            })
            .collect()
    }
}

/// One docking of the 3D run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Docking3 {
    pub cell: Cell,
    /// The module in place that attracted it: a neighbour below (or, for
    /// an overhang, any neighbour) for a plane's seed, an in-plane
    /// neighbour otherwise. `None` for the first module.
    pub attractor: Option<Cell>,
    pub time: u64,
    /// The in-plane component it belongs to (numbered in run order), and
    /// that component's docking positions available after it.
    pub component: usize,
    pub available_in_component: usize,
}

/// The outcome of a 3D run.
#[derive(Clone, Debug, Default)]
pub struct Run3 {
    pub order: Vec<Docking3>,
    pub messages: Messages,
    /// Dockings made while the 3D Rule 1 forbade them (the planner must
    /// give 0).
    pub rule1_violations: usize,
    /// Goal cells never filled.
    pub unfilled: usize,
    /// Layers, and in-plane components run by the 2D planner.
    pub planes: usize,
    pub components: usize,
    /// Components seeded at the end because nothing was below them.
    pub overhangs: usize,
    /// After each docking: docking positions attracted and not yet docked,
    /// over the components growing at that moment (a layer's, or one
    /// overhang's).
    pub available: Vec<usize>,
}

/// A component run by the 2D planner from its seed cell, attracted by the
/// module at `below` (`start`), its dockings offset to start at `t0`.
fn grow_component(
    z: i32,
    comp: &[(i32, i32)],
    start: ((i32, i32), Cell),
    t0: u64,
    rng_seed: u64,
    delays: &Delays,
    run: &mut Run3,
) -> Vec<Docking3> {
    let (seed, below) = start;
    let g = Goal::from_cells(&format!("layer {z}"), comp).expect("a non-empty component");
    let r = planner::run(&g, seed, rng_seed, delays);
    run.messages.add(&r.messages);
    run.unfilled += r.unfilled;
    run.components += 1;
    let component = run.components;
    r.order
        .iter()
        .zip(&r.available)
        .map(|(d, &available_in_component)| Docking3 {
            component,
            available_in_component,
            cell: Cell::new(d.cell.0, d.cell.1, z),
            attractor: Some(match d.attractor {
                Some((x, y)) => Cell::new(x, y, z),
                None => below,
            }),
            time: t0 + d.time,
        })
        .collect()
}

/// The cell of `comp` nearest its centroid among those `touching` accepts,
/// with the filled neighbour it touches.
fn seed_of(
    z: i32,
    comp: &[(i32, i32)],
    touching: impl Fn(Cell) -> Option<Cell>,
) -> Option<((i32, i32), Cell)> {
    let n = comp.len() as f64;
    let cx = comp.iter().map(|c| c.0 as f64).sum::<f64>() / n;
    let cy = comp.iter().map(|c| c.1 as f64).sum::<f64>() / n;
    comp.iter()
        .filter_map(|&(x, y)| touching(Cell::new(x, y, z)).map(|b| ((x, y), b)))
        .min_by(|a, b| {
            let d = |p: (i32, i32)| (p.0 as f64 - cx).powi(2) + (p.1 as f64 - cy).powi(2);
            d(a.0).total_cmp(&d(b.0)).then(a.0.cmp(&b.0))
        })
}

/// Runs the plane-by-plane planner on `goal` with RNG seed `seed`.
pub fn run(goal: &Goal3, seed: u64, delays: &Delays) -> Run3 {
    let mut run = Run3::default();
    let mut filled: FxHashSet<Cell> = FxHashSet::default();
    let mut t0 = 0;
    let mut waiting: Vec<(i32, Vec<(i32, i32)>)> = Vec::new();
    let layers = goal.components();
    run.planes = layers.len();
    let first_layer = goal.bottom();
    let below_of = |c: Cell, filled: &FxHashSet<Cell>| {
        FccLattice
            .neighbours(c)
            .into_iter()
            .find(|n| n.z < c.z && filled.contains(n))
    };
    let mut k = 0u64;
    for (z, comps) in layers {
        let mut dockings: Vec<Docking3> = Vec::new();
        for (i, comp) in comps.into_iter().enumerate() {
            k += 1;
            let rng_seed = seed ^ k.wrapping_mul(0x9E37_79B9_7F4A_7C15);
            if z == first_layer && i == 0 && filled.is_empty() {
                // The first module: the first component's central cell, on
                // the ground.
                let (s, _) = seed_of(z, &comp, Some).expect("a cell");
                let here = Cell::new(s.0, s.1, z);
                let mut d = grow_component(z, &comp, (s, here), t0, rng_seed, delays, &mut run);
                d[0].attractor = None;
                dockings.extend(d);
                continue;
            }
            match seed_of(z, &comp, |c| below_of(c, &filled)) {
                Some(start) => dockings.extend(grow_component(
                    z, &comp, start, t0, rng_seed, delays, &mut run,
                )),
                None => waiting.push((z, comp)),
            }
        }
        // The layer's components grow concurrently: merge by time.
        dockings.sort_by_key(|d| d.time);
        t0 = dockings.last().map_or(t0, |d| d.time) + 1;
        let mut open: rustc_hash::FxHashMap<usize, usize> = Default::default();
        for d in dockings {
            open.insert(d.component, d.available_in_component);
            run.available.push(open.values().sum());
            push(&mut run, &mut filled, d);
        }
    }
    // Overhangs: seeded from any finished neighbour, until none is left
    // that a module touches.
    run.overhangs = waiting.len();
    loop {
        let before = waiting.len();
        let mut rest = Vec::new();
        for (z, comp) in std::mem::take(&mut waiting) {
            let touching = |c: Cell| {
                FccLattice
                    .neighbours(c)
                    .into_iter()
                    .find(|n| filled.contains(n))
            };
            match seed_of(z, &comp, touching) {
                Some(start) => {
                    k += 1;
                    let rng_seed = seed ^ k.wrapping_mul(0x9E37_79B9_7F4A_7C15);
                    let d = grow_component(z, &comp, start, t0, rng_seed, delays, &mut run);
                    t0 = d.last().map_or(t0, |d| d.time) + 1;
                    for d in d {
                        run.available.push(d.available_in_component);
                        push(&mut run, &mut filled, d);
                    }
                }
                None => rest.push((z, comp)),
            }
        }
        waiting = rest;
        if waiting.is_empty() || waiting.len() == before {
            break;
        }
    }
    run.unfilled += waiting.iter().map(|(_, c)| c.len()).sum::<usize>();
    run
}

/// Docks `d`, counting it if the 3D Rule 1 forbids it.
fn push(run: &mut Run3, filled: &mut FxHashSet<Cell>, d: Docking3) {
    if rule1::blocked_fcc(&|c| filled.contains(&c), d.cell) {
        run.rule1_violations += 1;
    }
    filled.insert(d.cell);
    run.order.push(d);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cup() -> Goal3 {
        // A 6 × 6 floor two layers thick with a one-cell wall three layers
        // high: every layer above the floor is a ring (an in-plane hole).
        let mut cells = FxHashSet::default();
        for z in 0..5 {
            for x in 0..6 {
                for y in 0..6 {
                    let wall = x == 0 || y == 0 || x == 5 || y == 5;
                    if z < 2 || wall {
                        cells.insert(Cell::new(x, y, z));
                    }
                }
            }
        }
        Goal3 {
            name: "cup".into(),
            cells,
        }
    }

    #[test]
    fn a_cup_is_built_plane_by_plane_without_rule1_violations_or_gaps() {
        let g = cup();
        g.validate().unwrap();
        for seed in 0..4 {
            let r = run(&g, seed, &Delays::default());
            assert_eq!(r.order.len(), g.len());
            assert_eq!((r.rule1_violations, r.unfilled), (0, 0));
            assert_eq!(r.planes, 5);
            assert_eq!(r.available.len(), r.order.len());
            assert_eq!(*r.available.last().unwrap(), 0);
            assert!(r.available.iter().any(|&a| a > 1), "{:?}", r.available);
            // EndOfPlane: every docking of layer z comes after every one
            // of layer z − 1.
            let mut top = i32::MIN;
            for d in &r.order {
                assert!(d.cell.z >= top, "{:?} after layer {top}", d.cell);
                top = d.cell.z;
            }
            // Each docking touches a module already in place.
            let mut placed: FxHashSet<Cell> = FxHashSet::default();
            for d in &r.order {
                if let Some(a) = d.attractor {
                    assert!(placed.contains(&a) && FccLattice.are_neighbours(a, d.cell));
                }
                placed.insert(d.cell);
            }
        }
    }

    #[test]
    fn an_overhang_is_seeded_after_the_planes_from_its_finished_neighbour() {
        // A column of two cells with a cell hanging from the top one's
        // side, one layer down, over nothing.
        let cells: FxHashSet<Cell> = [Cell::new(0, 0, 0), Cell::new(0, 0, 1), Cell::new(1, 1, 0)]
            .into_iter()
            .collect();
        let hang = Cell::new(1, 1, 0);
        assert!(FccLattice.are_neighbours(hang, Cell::new(0, 0, 1)));
        assert!(!FccLattice.are_neighbours(hang, Cell::new(0, 0, 0)));
        let g = Goal3 {
            name: "hook".into(),
            cells,
        };
        let r = run(&g, 0, &Delays::default());
        assert_eq!(r.overhangs, 1);
        assert_eq!(r.unfilled, 0);
        assert_eq!(r.order.last().unwrap().cell, hang);
    }

    #[test]
    fn a_disconnected_goal_is_refused() {
        let g = Goal3 {
            name: "two".into(),
            cells: [Cell::new(0, 0, 0), Cell::new(5, 0, 0)]
                .into_iter()
                .collect(),
        };
        assert!(g.validate().unwrap_err().message.contains("disconnected"));
    }
}
