//! Seed 004 in 2D (Aloupis et al., §3.1): the source robot of 2×2×2
//! meta-modules is combed (Algorithm 1, the wall sweep), and with
//! `until = "target"` made the common comb (Algorithm 2) and then the
//! target by the target's own two phases in reverse (Theorem 1,
//! [`common_comb`]); in 3D (§3.2, Theorem 2) by [`three_d`].
//!
//! The generator works on meta-modules (cells of the coarse cubic lattice,
//! `z = 0`) and writes a `meta_modules` schedule: `slide` (the paper's
//! SLIDE, carrying whatever is attached to the slider; `pivot` is the wall
//! meta-module B; carried meta-modules get a `slide` without pivot),
//! `tunnel` (k-TUNNEL along an orthogonal path), `attach` and `detach` of
//! whole meta-modules. The certifier expands that schedule into atom
//! operations where every move has a derived atom sequence, and certifies
//! it at the meta-module level otherwise (`certify --meta-level`).

pub mod common_comb;
pub mod three_d;

use super::{Generator, parameters};
use crate::error::InputError;
use crate::lattice::config::ModuleId;
use crate::lattice::{AtomRest, Cell, LatticeKind};
use crate::scenario::Scenario;
use crate::schedule::{Event, Length, ModuleSpec, Schedule, Step};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rustc_hash::{FxHashMap, FxHashSet};
use serde::Deserialize;
use std::collections::BTreeSet;

/// A 2D robot: its meta-module cells (x, y).
pub type Shape = BTreeSet<(i32, i32)>;

/// The meta-module state the algorithms update.
#[derive(Clone, Debug)]
pub struct Robot {
    /// Cell of each meta-module, by id.
    pub at: Vec<(i32, i32)>,
    by_cell: FxHashMap<(i32, i32), usize>,
    /// Attached neighbouring pairs `(a, b)`, `a < b`.
    pub attached: FxHashSet<(usize, usize)>,
    /// Meta-level steps so far.
    pub steps: Vec<Vec<Event>>,
}

pub(crate) fn pair(a: usize, b: usize) -> (usize, usize) {
    if a < b { (a, b) } else { (b, a) }
}

pub(crate) fn cell(c: (i32, i32)) -> Cell {
    Cell::new(c.0, c.1, 0)
}

impl Robot {
    /// Every neighbouring pair attached; ids in the shape's order.
    pub fn new(shape: &Shape) -> Robot {
        let at: Vec<(i32, i32)> = shape.iter().copied().collect();
        let by_cell: FxHashMap<(i32, i32), usize> =
            at.iter().enumerate().map(|(k, &c)| (c, k)).collect();
        let mut attached = FxHashSet::default();
        for (k, &(x, y)) in at.iter().enumerate() {
            for n in [(x + 1, y), (x, y + 1)] {
                if let Some(&o) = by_cell.get(&n) {
                    attached.insert(pair(k, o));
                }
            }
        }
        Robot {
            at,
            by_cell,
            attached,
            steps: Vec::new(),
        }
    }

    pub fn get(&self, c: (i32, i32)) -> Option<usize> {
        self.by_cell.get(&c).copied()
    }

    pub(crate) fn relocate(&mut self, moves: &[(usize, (i32, i32))]) {
        for &(k, _) in moves {
            self.by_cell.remove(&self.at[k]);
        }
        for &(k, to) in moves {
            self.at[k] = to;
            self.by_cell.insert(to, k);
        }
    }

    fn latch_step(&mut self, pairs: Vec<(usize, usize)>, attach: bool) {
        let mut events = Vec::new();
        let mut seen = FxHashSet::default();
        for (a, b) in pairs {
            let p = pair(a, b);
            let is = self.attached.contains(&p);
            if is == attach || !seen.insert(p) {
                continue;
            }
            if attach {
                self.attached.insert(p);
                events.push(Event::Attach {
                    module: p.0 as ModuleId,
                    other: p.1 as ModuleId,
                });
            } else {
                self.attached.remove(&p);
                events.push(Event::Detach {
                    module: p.0 as ModuleId,
                    other: p.1 as ModuleId,
                });
            }
        }
        if !events.is_empty() {
            self.steps.push(events);
        }
    }

    /// Algorithm 1, 2D-COMBING: the wall sweeps down from the top row.
    pub fn comb(&mut self) {
        let Some(top) = self.at.iter().map(|c| c.1).max() else {
            return;
        };
        let bottom = self.at.iter().map(|c| c.1).min().expect("not empty");
        let mut wall = top;
        while wall > bottom {
            // 2.1–2.2: moving wall meta-modules, in runs along x.
            let mut row: Vec<i32> = self
                .at
                .iter()
                .filter(|c| c.1 == wall)
                .map(|c| c.0)
                .collect();
            row.sort_unstable();
            let moving = |x: i32| self.get((x, wall - 1)).is_none();
            let mut components: Vec<(i32, i32)> = Vec::new();
            for &x in &row {
                if !moving(x) {
                    continue;
                }
                match components.last_mut() {
                    Some((_, end)) if *end == x - 1 => *end = x,
                    _ => components.push((x, x)),
                }
            }
            // 2.3: the ends beside a stationary wall meta-module slide down,
            // carrying their component and the teeth on it.
            let mut events = Vec::new();
            let mut moves = Vec::new();
            let mut relatch = Vec::new();
            let mut sliders = FxHashSet::default();
            for &(x0, x1) in &components {
                for (end, side) in [(x0, x0 - 1), (x1, x1 + 1)] {
                    let (Some(s), Some(a)) = (self.get((side, wall)), self.get((end, wall))) else {
                        continue;
                    };
                    // A lone moving meta-module between two stationary
                    // ones slides along both (two events, one per wall).
                    sliders.insert(a);
                    let below = self.get((side, wall - 1)).expect("stationary");
                    events.push(Event::Slide {
                        module: a as ModuleId,
                        from: cell((end, wall)),
                        to: cell((end, wall - 1)),
                        pivot: Some(s as ModuleId),
                    });
                    relatch.push((a, s, below));
                }
                for x in x0..=x1 {
                    let mut y = wall;
                    while let Some(k) = self.get((x, y)) {
                        moves.push((k, (x, y - 1)));
                        y += 1;
                    }
                }
            }
            // The carried meta-modules move with their sliders.
            for &(k, to) in &moves {
                if !sliders.contains(&k) {
                    events.push(Event::Slide {
                        module: k as ModuleId,
                        from: cell(self.at[k]),
                        to: cell(to),
                        pivot: None,
                    });
                }
            }
            if !sliders.is_empty() {
                self.steps.push(events);
            }
            for (a, s, below) in relatch {
                self.attached.remove(&pair(a, s));
                self.attached.insert(pair(a, below));
            }
            self.relocate(&moves);
            wall -= 1;
            // 2.4.1 and 2.4.3: attach the moved ends to new neighbours, and
            // w⁻ to the wall above it.
            let mut attach = Vec::new();
            for &(x0, x1) in &components {
                for (end, side) in [(x0, x0 - 1), (x1, x1 + 1)] {
                    if let (Some(a), Some(b)) = (self.get((end, wall)), self.get((side, wall))) {
                        attach.push((a, b));
                    }
                }
            }
            for &(x, y) in &self.at {
                if y == wall
                    && let (Some(a), Some(b)) = (self.get((x, y)), self.get((x, y - 1)))
                {
                    attach.push((a, b));
                }
            }
            attach.sort_unstable();
            self.latch_step(attach, true);
            // 2.4.2: the meta-modules new in w⁺ let go of their sides.
            let mut detach = Vec::new();
            for &(x, y) in &self.at {
                if y == wall + 1 {
                    let a = self.get((x, y)).expect("present");
                    for side in [x - 1, x + 1] {
                        if let Some(b) = self.get((side, y)) {
                            detach.push((a, b));
                        }
                    }
                }
            }
            detach.sort_unstable();
            self.latch_step(detach, false);
        }
    }
}

/// Whether the cells form one 4-connected piece.
pub fn connected(shape: &Shape) -> bool {
    let Some(&first) = shape.iter().next() else {
        return true;
    };
    let mut seen = FxHashSet::default();
    seen.insert(first);
    let mut stack = vec![first];
    while let Some((x, y)) = stack.pop() {
        for n in [(x + 1, y), (x - 1, y), (x, y + 1), (x, y - 1)] {
            if shape.contains(&n) && seen.insert(n) {
                stack.push(n);
            }
        }
    }
    seen.len() == shape.len()
}

/// A random connected polyomino of `m` cells grown from the origin (each
/// new cell a random free neighbour of the shape), moved to have its
/// lowest row and leftmost column at 0.
pub fn random_polyomino(m: usize, rng: &mut ChaCha8Rng) -> Shape {
    let mut cells: Vec<(i32, i32)> = vec![(0, 0)];
    let mut set: FxHashSet<(i32, i32)> = cells.iter().copied().collect();
    while cells.len() < m {
        let (x, y) = cells[rng.random_range(0..cells.len())];
        let n = [(x + 1, y), (x - 1, y), (x, y + 1), (x, y - 1)][rng.random_range(0..4)];
        if set.insert(n) {
            cells.push(n);
        }
    }
    normalise(&cells.into_iter().collect())
}

/// The shape moved so that its lowest row and leftmost column are 0.
pub fn normalise(shape: &Shape) -> Shape {
    let x0 = shape.iter().map(|c| c.0).min().unwrap_or(0);
    let y0 = shape.iter().map(|c| c.1).min().unwrap_or(0);
    shape.iter().map(|&(x, y)| (x - x0, y - y0)).collect()
}

/// A shape of atoms in the xy-plane (each a column of two atoms in z)
/// read as meta-modules: refused unless it is a union of 2×2 blocks aligned
/// on even coordinates, connected, and not empty.
pub fn metas_of_atoms(atoms: &BTreeSet<(i32, i32)>) -> Result<Shape, String> {
    if atoms.is_empty() {
        return Err("it has no atoms".into());
    }
    let mut metas = Shape::new();
    for &(x, y) in atoms {
        let m = (x.div_euclid(2), y.div_euclid(2));
        if metas.insert(m) {
            for (i, j) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let a = (2 * m.0 + i, 2 * m.1 + j);
                if !atoms.contains(&a) {
                    return Err(format!(
                        "it is not a union of aligned 2×2×2 meta-modules: the block at atom ({}, {}) lacks atom ({}, {})",
                        2 * m.0,
                        2 * m.1,
                        a.0,
                        a.1
                    ));
                }
            }
        }
    }
    if !connected(&metas) {
        return Err("its meta-modules are not connected".into());
    }
    Ok(metas)
}

/// Reads an atom picture: one line per row of atoms, top row first, `#`
/// an atom (a column of two in z), `.` or space none.
pub fn parse_picture(text: &str) -> BTreeSet<(i32, i32)> {
    let rows: Vec<&str> = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect();
    let h = rows.len() as i32;
    let mut out = BTreeSet::new();
    for (r, line) in rows.iter().enumerate() {
        for (x, ch) in line.chars().enumerate() {
            if ch == '#' {
                out.insert((x as i32, h - 1 - r as i32));
            }
        }
    }
    out
}

/// A meta-module schedule of the robot's recorded steps, the frame the
/// leftmost meta-module of the lowest row (which neither the combing nor
/// the comb-to-common-comb moves).
pub fn meta_schedule(start: &Shape, steps: &[Vec<Event>], rest: AtomRest) -> Schedule {
    let anchor = start.iter().min_by_key(|c| (c.1, c.0)).copied();
    meta_schedule_framed(start, steps, rest, anchor)
}

/// [`meta_schedule`] with the frame the meta-module at `anchor` (none:
/// no meta-module fixed; the robot must then stay one piece).
pub fn meta_schedule_framed(
    start: &Shape,
    steps: &[Vec<Event>],
    rest: AtomRest,
    anchor: Option<(i32, i32)>,
) -> Schedule {
    let at: Vec<(i32, i32)> = start.iter().copied().collect();
    meta_schedule_at(&at, steps, rest, anchor)
}

/// [`meta_schedule_framed`] from meta-module `k` at `at[k]` (a robot in the
/// middle of a run, its ids kept).
pub fn meta_schedule_at(
    at: &[(i32, i32)],
    steps: &[Vec<Event>],
    rest: AtomRest,
    anchor: Option<(i32, i32)>,
) -> Schedule {
    let mut s = Schedule::new(LatticeKind::Cubic, Length::mm(120.0));
    s.meta_modules = Some(rest);
    s.modules = at
        .iter()
        .enumerate()
        .map(|(k, &c)| ModuleSpec {
            id: k as ModuleId,
            cell: cell(c),
            fixed: Some(c) == anchor,
        })
        .collect();
    s.steps = steps.iter().map(|e| Step { events: e.clone() }).collect();
    s
}

/// Parameters of the `comb-2d` generator.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CombParams {
    /// Atom pictures (see [`parse_picture`]) of the source and the target,
    /// relative to the scenario; or, without them, random polyominoes of
    /// `metas` meta-modules from `seed`.
    #[serde(default)]
    pub source: Option<String>,
    #[serde(default)]
    pub target: Option<String>,
    #[serde(default = "default_metas")]
    pub metas: usize,
    #[serde(default)]
    pub seed: u64,
    /// The atoms' rest model: `"contracted"` (default) or `"expanded"`.
    #[serde(default = "default_rest")]
    pub model: AtomRest,
    /// How far to go (see [`Until`]).
    #[serde(default)]
    pub until: Until,
}

/// How far the `comb-2d` generator takes the source.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Until {
    /// The source's comb (Algorithm 1): SLIDEs and latches only, every one
    /// with a derived atom sequence, so the certifier checks every atom.
    #[default]
    Comb,
    /// The target (Theorem 1): the comb, the common comb, and the target's
    /// phases reversed. Its 2-TUNNELs have no derived atom sequence: such
    /// a schedule is certified at the meta-module level
    /// (`certify --meta-level`).
    Target,
}

fn default_metas() -> usize {
    16
}
fn default_rest() -> AtomRest {
    AtomRest::Contracted
}

/// Most meta-modules of a random robot: the studies go to 4,096;
/// a larger count is refused rather than left to run for hours.
pub const MAX_METAS: usize = 65_536;

fn check_metas(scenario: &Scenario, metas: usize) -> Result<(), InputError> {
    if (1..=MAX_METAS).contains(&metas) {
        Ok(())
    } else {
        Err(scenario.error(format!("metas must be 1 … {MAX_METAS}, not {metas}")))
    }
}

/// The source and target a scenario names, as meta-module shapes.
pub fn shapes(scenario: &Scenario, p: &CombParams) -> Result<(Shape, Shape), InputError> {
    let read = |rel: &str| -> Result<Shape, InputError> {
        let path = scenario.resolve(rel);
        let text = crate::error::read_file(&path, "robot picture")?;
        metas_of_atoms(&parse_picture(&text))
            .map_err(|why| InputError::new(format!("refused: {why}")).in_file(&path))
    };
    match (&p.source, &p.target) {
        (Some(s), Some(t)) => {
            let (src, tgt) = (read(s)?, read(t)?);
            if src.len() != tgt.len() {
                return Err(InputError::new(format!(
                    "refused: the source has {} meta-modules and the target {}",
                    src.len(),
                    tgt.len()
                ))
                .in_file(scenario.resolve(t)));
            }
            Ok((src, tgt))
        }
        (None, None) => {
            check_metas(scenario, p.metas)?;
            let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
            let s = random_polyomino(p.metas, &mut rng);
            let t = random_polyomino(p.metas, &mut rng);
            Ok((s, t))
        }
        _ => Err(scenario.error("give both `source` and `target`, or neither")),
    }
}

/// The `comb-2d` generator.
pub struct Comb2d;

impl Generator for Comb2d {
    fn name(&self) -> &'static str {
        "comb-2d"
    }

    fn about(&self) -> &'static str {
        "seed 004 in 2D: COMBING (Algorithm 1) of the source, as a meta-module schedule"
    }

    fn generate(&self, scenario: &Scenario) -> Result<Schedule, InputError> {
        let p: CombParams = parameters(scenario)?;
        let (src, tgt) = shapes(scenario, &p)?;
        let mut s = match p.until {
            Until::Comb => {
                let mut r = Robot::new(&src);
                r.comb();
                meta_schedule(&src, &r.steps, p.model)
            }
            Until::Target => {
                let plan = common_comb::reconfigure(&src, &tgt);
                let lowest = |s: &Shape| -> BTreeSet<(i32, i32)> {
                    let y0 = s.iter().map(|c| c.1).min().unwrap_or(0);
                    s.iter().copied().filter(|c| c.1 == y0).collect()
                };
                // The frame: a meta-module in the lowest row of both, which
                // no phase moves; else none (the robot must stay one piece).
                let anchor = lowest(&src)
                    .intersection(&lowest(&plan.target))
                    .next()
                    .copied();
                let mut s = meta_schedule_framed(&src, &plan.steps(), p.model, anchor);
                let phases: Vec<serde_json::Value> =
                    plan.phases.iter().map(|ph| ph.len().into()).collect();
                s.meta.insert("phase_steps".into(), phases.into());
                s
            }
        };
        s.meta.insert("algorithm".into(), "comb-2d".into());
        s.meta.insert("meta_modules".into(), src.len().into());
        s.meta.insert("seed".into(), p.seed.into());
        Ok(s)
    }
}

/// Parameters of the `comb-3d` generator.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Comb3Params {
    /// Random connected polycubes of `metas` meta-modules from `seed`
    /// (source, then target).
    #[serde(default = "default_metas")]
    pub metas: usize,
    #[serde(default)]
    pub seed: u64,
    #[serde(default = "default_rest")]
    pub model: AtomRest,
    /// How far to go (see [`Until`]); `"target"` is Theorem 2.
    #[serde(default)]
    pub until: Until,
}

/// The `comb-3d` generator (§3.2, at the meta-module level: its SLIDEs
/// along perpendicular walls and its k-TUNNELs have no derived atom
/// sequence; certify with `--meta-level`).
pub struct Comb3d;

impl Generator for Comb3d {
    fn name(&self) -> &'static str {
        "comb-3d"
    }

    fn about(&self) -> &'static str {
        "seed 004 in 3D: combing to a terrain and a 3D comb, and with until = \"target\" the 3D common comb and the target (meta-module level)"
    }

    fn generate(&self, scenario: &Scenario) -> Result<Schedule, InputError> {
        let p: Comb3Params = parameters(scenario)?;
        check_metas(scenario, p.metas)?;
        let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
        let src = three_d::random_polycube(p.metas, &mut rng);
        let tgt = three_d::random_polycube(p.metas, &mut rng);
        let (steps, phases) = match p.until {
            Until::Comb => {
                let mut r = three_d::Robot3::new(&src);
                r.comb();
                (r.steps, vec![])
            }
            Until::Target => {
                let plan = three_d::reconfigure3(&src, &tgt);
                let phases: Vec<serde_json::Value> =
                    plan.phases.iter().map(|ph| ph.len().into()).collect();
                (plan.steps(), phases)
            }
        };
        let mut s = three_d::schedule_of(&src, steps, p.model);
        if !phases.is_empty() {
            s.meta.insert("phase_steps".into(), phases.into());
        }
        s.meta.insert("algorithm".into(), "comb-3d".into());
        s.meta.insert("meta_modules".into(), src.len().into());
        s.meta.insert("seed".into(), p.seed.into());
        Ok(s)
    }
}
