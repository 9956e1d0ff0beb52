//! Seed 002, "Distributed self-assembly planning by docking" (Tucci,
//! Piranda, Bourgeois): a dense goal shape grows from one seed module;
//! modules in place attract new ones to docking positions in an order that
//! never leaves a goal cell impossible to fill.
//!
//! * [`goal`] — goal shapes (CSG slices), validated;
//! * [`rule1`] — the paper's docking rule (the planner's, not the
//!   certifier's);
//! * [`planner`] — Rules 2–5, Algorithm 2 and border following, simulated
//!   as a distributed run with random delays;
//! * [`naive`] — the two naive orders of Fig. 3.
//!
//! The generator emits one `dock` event per time step, in the run's
//! docking order, each with a final approach (origin cell and pivot) that
//! the geometry layer finds clear. See `docs/docking.md`.

pub mod goal;
pub mod naive;
pub mod plane_by_plane;
pub mod planner;
pub mod rule1;

use super::{Generator, parameters};
use crate::error::InputError;
use crate::geometry::Tolerance;
use crate::geometry::docking::{Approach, candidates, clear_approaches, grow_bounds, judge};
use crate::lattice::config::ModuleId;
use crate::lattice::{Cell, Configuration, LatticeKind, Motion, SquareLattice};
use crate::scenario::Scenario;
use crate::schedule::{Event, Length, ModuleSpec, Schedule, Step};
use goal::Goal;
use planner::{Delays, Run};
use serde::Deserialize;

/// Scenario parameters of `docking`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// Goal shape: a CSG file (relative to the scenario), sliced at `z`.
    pub shape: String,
    /// Scale applied to the CSG (cells per CSG unit).
    #[serde(default = "one")]
    pub scale: f64,
    /// Height of the slice, in CSG units.
    #[serde(default)]
    pub z: f64,
    /// RNG seed of the simulated delays.
    #[serde(default)]
    pub seed: u64,
    /// The seed module's cell (default: the goal cell nearest the centroid).
    #[serde(default)]
    pub seed_cell: Option<[i32; 2]>,
    #[serde(default)]
    pub delays: Option<Delays>,
}

fn one() -> f64 {
    1.0
}

/// The planner's run and the schedule made from it.
pub struct Planned {
    pub goal: Goal,
    pub run: Run,
    pub schedule: Schedule,
    /// Dockings for which the geometry found no clear approach (the
    /// schedule still names one; certification reports it).
    pub without_approach: usize,
}

/// Checks a goal and its seed cell; the default seed cell is the goal cell
/// nearest the centroid.
pub fn seed_cell_of(goal: &Goal, seed_cell: Option<[i32; 2]>) -> Result<(i32, i32), InputError> {
    goal.validate()?;
    match seed_cell {
        Some([x, y]) if goal.contains(x, y) => Ok((x, y)),
        Some([x, y]) => Err(InputError::new(format!(
            "goal '{}' has no cell for the seed at ({x}, {y})",
            goal.name
        ))),
        None => Ok(goal.central_cell()),
    }
}

/// Plans `goal` and emits its schedule.
pub fn plan(
    goal: Goal,
    seed_cell: Option<[i32; 2]>,
    seed: u64,
    delays: &Delays,
) -> Result<Planned, InputError> {
    let start = seed_cell_of(&goal, seed_cell)?;
    let run = planner::run(&goal, start, seed, delays);
    let (schedule, without_approach) = emit(&goal, &run);
    Ok(Planned {
        goal,
        run,
        schedule,
        without_approach,
    })
}

/// The schedule of a run: the seed fixed in place, then one docking per
/// step. Each docking's approach is the first usable one (clear, from an
/// origin reachable from outside) on the module that attracted it, else
/// the first usable one, else (none) a corner approach on the attractor,
/// left for certification to refuse.
fn emit(goal: &Goal, run: &Run) -> (Schedule, usize) {
    let lattice = &SquareLattice;
    let mut s = Schedule::new(LatticeKind::Square, Length::mm(50.0));
    let mut config = Configuration::new();
    let seed = Cell::xy(run.seed_cell.0, run.seed_cell.1);
    s.modules.push(ModuleSpec {
        id: 0,
        cell: seed,
        fixed: true,
    });
    config.insert(0, seed).expect("empty scene");
    let mut bounds = (seed, seed);
    let mut without = 0;
    for (k, d) in run.order.iter().enumerate().skip(1) {
        let id = k as ModuleId;
        let cell = Cell::xy(d.cell.0, d.cell.1);
        let attractor = d.attractor.map(|(x, y)| Cell::xy(x, y));
        let clear = clear_approaches(lattice, &config, None, bounds, cell, Tolerance::DEFAULT);
        let pick = |list: &[Approach]| -> Option<Approach> {
            list.iter()
                .find(|a| Some(a.pivot) == attractor)
                .or_else(|| list.first())
                .cloned()
        };
        let approach = pick(&clear).unwrap_or_else(|| {
            without += 1;
            let all = candidates(lattice, cell);
            // A sweep that is clear from an enclosed origin, if any: the
            // certifier then says why no module can get there.
            let swept: Vec<Approach> = all
                .iter()
                .filter(|a| judge(lattice, &config, None, a, Tolerance::DEFAULT).is_clear())
                .cloned()
                .collect();
            if let Some(a) = pick(&swept) {
                return a;
            }
            all.iter()
                .find(|a| Some(a.pivot) == attractor && a.from.x != cell.x && a.from.y != cell.y)
                .or_else(|| all.first())
                .cloned()
                .expect("the square lattice has approaches")
        });
        let pivot = config.at(approach.pivot).unwrap_or(0);
        s.steps.push(Step {
            events: vec![Event::Dock {
                module: id,
                cell,
                pivot,
                from: approach.from,
                route: None,
            }],
        });
        config
            .insert(id, cell)
            .expect("the planner docks a cell once");
        bounds = grow_bounds(bounds, cell);
    }
    s.meta.insert("algorithm".into(), "docking".into());
    s.meta.insert("goal".into(), goal.name.clone().into());
    s.meta.insert("modules".into(), goal.len().into());
    s.meta
        .insert("messages".into(), run.messages.total().into());
    s.meta
        .insert("rule1_violations".into(), run.rule1_violations.into());
    s.meta.insert("unfilled".into(), run.unfilled.into());
    (s, without)
}

/// Scenario parameters of `docking-3d`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params3d {
    /// Goal shape: a CSG file (relative to the scenario).
    pub shape: String,
    /// Scale applied to the CSG (module diameters per CSG unit).
    #[serde(default = "one")]
    pub scale: f64,
    /// RNG seed of the simulated delays.
    #[serde(default)]
    pub seed: u64,
    #[serde(default)]
    pub delays: Option<Delays>,
}

/// The schedule of a 3D run on FCC: the first module fixed on the ground,
/// then one docking per step, each a catom rotation into its cell chosen
/// by the motion rules — no sliding contact if possible, on the attractor
/// if possible, from an origin reachable from outside. Returns the
/// schedule and the dockings with no such approach (their event names a
/// rotation about a module in place, for certification to refuse).
pub fn emit_3d(goal: &plane_by_plane::Goal3, run: &plane_by_plane::Run3) -> (Schedule, usize) {
    use crate::geometry::docking::{origin_reachable, planned_clear};
    use crate::lattice::{FccLattice, Ground};
    let lattice = &FccLattice;
    let ground = Some(Ground {
        layer: goal.bottom(),
    });
    let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(3.6));
    s.ground = ground;
    let mut config = Configuration::new();
    let mut without = 0;
    let Some(first) = run.order.first() else {
        return (s, 0);
    };
    s.modules.push(ModuleSpec {
        id: 0,
        cell: first.cell,
        fixed: true,
    });
    config.insert(0, first.cell).expect("empty scene");
    let mut bounds = (first.cell, first.cell);
    for (k, d) in run.order.iter().enumerate().skip(1) {
        let id = k as ModuleId;
        let all: Vec<Approach> = candidates(lattice, d.cell)
            .into_iter()
            .filter(|a| !config.is_free(a.pivot) && config.is_free(a.from))
            .collect();
        let usable = |strict: bool, on_attractor: bool| {
            all.iter().find(|a| {
                (!on_attractor || Some(a.pivot) == d.attractor)
                    && planned_clear(lattice, &config, ground, a, strict)
                    && origin_reachable(lattice, &config, ground, bounds, a.from)
            })
        };
        let approach = usable(true, true)
            .or_else(|| usable(true, false))
            .or_else(|| usable(false, true))
            .or_else(|| usable(false, false))
            .or_else(|| {
                without += 1;
                all.first()
            })
            .cloned();
        let Some(a) = approach else {
            // No module in place to roll on: cannot happen for a docking
            // next to the structure; counted, and emitted as an entry.
            without += 1;
            s.steps.push(Step {
                events: vec![Event::Enter {
                    module: id,
                    cell: d.cell,
                }],
            });
            config.insert(id, d.cell).expect("one docking per cell");
            continue;
        };
        let Motion::Rotate { route, .. } = a.motion else {
            unreachable!("FCC approaches are rotations")
        };
        s.steps.push(Step {
            events: vec![Event::Dock {
                module: id,
                cell: d.cell,
                pivot: config.at(a.pivot).expect("a module in place"),
                from: a.from,
                route: Some(route),
            }],
        });
        config.insert(id, d.cell).expect("one docking per cell");
        bounds = grow_bounds(bounds, d.cell);
    }
    s.meta.insert("algorithm".into(), "docking-3d".into());
    s.meta.insert("goal".into(), goal.name.clone().into());
    s.meta.insert("modules".into(), goal.len().into());
    s.meta
        .insert("messages".into(), run.messages.total().into());
    s.meta
        .insert("rule1_violations".into(), run.rule1_violations.into());
    s.meta.insert("unfilled".into(), run.unfilled.into());
    s.meta.insert(
        "messages_paper_era".into(),
        run.messages.total_paper().into(),
    );
    s.meta.insert(
        "max_available".into(),
        run.available.iter().copied().max().unwrap_or(0).into(),
    );
    s.meta.insert("planes".into(), run.planes.into());
    s.meta.insert("components".into(), run.components.into());
    s.meta.insert("overhangs".into(), run.overhangs.into());
    s.meta.insert("without_approach".into(), without.into());
    (s, without)
}

/// The `docking-3d` generator.
pub struct Docking3d;

impl Generator for Docking3d {
    fn name(&self) -> &'static str {
        "docking-3d"
    }

    fn about(&self) -> &'static str {
        "seed 002 in 3D: docking self-assembly on FCC, plane by plane (EndOfPlane), 3D Rule 1"
    }

    fn generate(&self, scenario: &Scenario) -> Result<Schedule, InputError> {
        let p: Params3d = parameters(scenario)?;
        let path = scenario.resolve(&p.shape);
        let goal = plane_by_plane::Goal3::from_csg(&path, p.scale)?;
        let run = plane_by_plane::run(&goal, p.seed, &p.delays.unwrap_or_default());
        let (mut s, _) = emit_3d(&goal, &run);
        s.meta.insert("seed".into(), p.seed.into());
        Ok(s)
    }
}

/// The `docking` generator.
pub struct Docking;

impl Generator for Docking {
    fn name(&self) -> &'static str {
        "docking"
    }

    fn about(&self) -> &'static str {
        "seed 002: distributed self-assembly by docking on the square lattice (Rules 1-5, border following)"
    }

    fn generate(&self, scenario: &Scenario) -> Result<Schedule, InputError> {
        let p: Params = parameters(scenario)?;
        let path = scenario.resolve(&p.shape);
        let goal = Goal::from_csg(&path, p.scale, p.z)?;
        let seed_cell = p.seed_cell;
        let planned = plan(goal, seed_cell, p.seed, &p.delays.unwrap_or_default())
            .map_err(|e| e.in_file(&path))?;
        let mut s = planned.schedule;
        s.meta.insert("seed".into(), p.seed.into());
        Ok(s)
    }
}
