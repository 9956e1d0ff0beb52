//! Seed 003, "Self-Reconfiguration in Two-Dimensions via Active Subtraction
//! with Modular Robots": excluded modules leave a solid rectangle one by one
//! (SAS, Alg. 1–2) or in parallel (PAS, Alg. 3) through a sink at `(0, 1)`,
//! leaving the desired configuration standing on the ground.
//!
//! The generator emits schedules on the square lattice in the paper's
//! coordinates (`ground: {layer: 1}`, `sinks: [[0, 1]]`): one `slide` per
//! module movement, with the pivot the sliding-square rules of
//! `lattice::square` expect, and a `leave` in the step a module reaches the
//! sink. Time steps count as the paper counts them: one movement per active
//! module per step. See `docs/active-subtraction.md`.

pub mod pas;
pub mod random;
pub mod sas;
pub mod shape;

use super::{Generator, parameters};
use crate::error::InputError;
use crate::lattice::config::{Ground, ModuleId};
use crate::lattice::{Cell, Configuration, LatticeKind};
use crate::scenario::Scenario;
use crate::schedule::{Event, Length, ModuleSpec, Schedule, Step};
use pas::PasTimes;
use rustc_hash::FxHashSet;
use sas::{SINK, SasRun};
use serde::Deserialize;
pub use shape::Shape;
use shape::xy;

/// Sequential or parallel active subtraction.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    Sas,
    Pas,
}

impl Mode {
    pub fn name(self) -> &'static str {
        match self {
            Mode::Sas => "sas",
            Mode::Pas => "pas",
        }
    }
}

/// A §V-B random desired configuration.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RandomSpec {
    pub width: i32,
    pub height: i32,
    /// Fraction of included modules, ρ/100 (e.g. 0.6).
    pub density: f64,
    #[serde(default)]
    pub seed: u64,
    /// The growth rule (`member`, §V-B as written, unless set).
    #[serde(default)]
    pub growth: random::Growth,
}

/// Scenario parameters of `active-subtraction`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    pub mode: Mode,
    /// Desired configuration: an ASCII grid file (relative to the scenario)…
    #[serde(default)]
    pub shape: Option<String>,
    /// …or a random one.
    #[serde(default)]
    pub random: Option<RandomSpec>,
    /// Initial rectangle, if larger than the shape grid (shape at its
    /// bottom-left).
    #[serde(default)]
    pub width: Option<i32>,
    #[serde(default)]
    pub height: Option<i32>,
}

/// The result of planning: SAS removals, their timing and the schedule.
#[derive(Clone, Debug)]
pub struct Plan {
    pub shape: Shape,
    pub mode: Mode,
    pub run: SasRun,
    pub times: PasTimes,
    /// Reconfiguration time as the paper counts it.
    pub time_steps: usize,
}

impl Plan {
    /// Runs SAS, and Alg. 3 for PAS.
    pub fn new(shape: Shape, mode: Mode) -> Result<Plan, InputError> {
        shape.validate()?;
        let run = sas::run(&shape)?;
        let times = match mode {
            Mode::Sas => PasTimes::sequential(&run),
            Mode::Pas => pas::plan(&shape, &run)?,
        };
        let time_steps = times.time_steps();
        Ok(Plan {
            shape,
            mode,
            run,
            times,
            time_steps,
        })
    }

    /// Normalised time of §V: time steps per excluded module.
    pub fn normalised_time(&self) -> f64 {
        self.time_steps as f64 / self.run.removals.len().max(1) as f64
    }

    /// The schedule of this plan, and the number of movements that the
    /// sliding-square rules do not support (see [`Emitted`]).
    pub fn schedule(&self) -> Result<Emitted, InputError> {
        emit(self)
    }
}

/// An emitted schedule with what the emitter found on the way.
#[derive(Clone, Debug)]
pub struct Emitted {
    pub schedule: Schedule,
    /// Movements Alg. 2 makes that have no sliding-square support (no wall
    /// on either side of a straight slide, no pivot at a corner move).
    pub unsupported: usize,
}

/// The `active-subtraction` generator.
pub struct ActiveSubtraction;

impl Generator for ActiveSubtraction {
    fn name(&self) -> &'static str {
        "active-subtraction"
    }

    fn about(&self) -> &'static str {
        "seed 003: excluded modules leave a 2D rectangle through a sink (SAS/PAS)"
    }

    fn generate(&self, scenario: &Scenario) -> Result<Schedule, InputError> {
        let p: Params = parameters(scenario)?;
        let shape = match (&p.shape, &p.random) {
            (Some(file), None) => {
                let path = scenario.resolve(file);
                let s = Shape::load(&path)?;
                let (w, h) = (p.width.unwrap_or(s.width), p.height.unwrap_or(s.height));
                // The rectangle comes from the scenario, the shape from its
                // file: the error names the scenario and quotes the file.
                s.within(w, h).map_err(|e| {
                    scenario.error(format!("{} (shape {})", e.message, path.display()))
                })?
            }
            (None, Some(r)) => {
                if p.width.is_some() || p.height.is_some() {
                    return Err(scenario.error(
                        "give the size of a random configuration inside [parameters.random]",
                    ));
                }
                random::random_shape_grown(r.width, r.height, r.density, r.seed, r.growth)
                    .map_err(|e| e.in_file(&scenario.path))?
            }
            _ => {
                return Err(scenario.error(
                    "active-subtraction needs exactly one of `shape` (a grid file) or `[parameters.random]`",
                ));
            }
        };
        let plan = Plan::new(shape, p.mode).map_err(|e| e.in_file(&scenario.path))?;
        let mut out = plan.schedule().map_err(|e| e.in_file(&scenario.path))?;
        if let Some(r) = &p.random {
            out.schedule
                .meta
                .insert("random_seed".into(), r.seed.into());
            out.schedule.meta.insert("density".into(), r.density.into());
        }
        Ok(out.schedule)
    }
}

/// Whether `c` can bear on a mover: ground, or a module that is not moving.
fn supports(config: &Configuration, moving: &FxHashSet<ModuleId>, c: Cell) -> bool {
    c.y < 1 || config.at(c).is_some_and(|m| !moving.contains(&m))
}

/// The pivot a sliding-square move `from → to` holds on to, and whether the
/// lattice's preconditions hold: a straight slide needs a wall (the pivot
/// beside `from` and a support beside `to` on the same side, or the ground
/// beneath both: pivot `None`); a corner move needs the pivot at one corner
/// and the other corner free.
fn pivot_for(
    config: &Configuration,
    moving: &FxHashSet<ModuleId>,
    from: Cell,
    to: Cell,
) -> Result<(Option<ModuleId>, bool), InputError> {
    let d = to - from;
    let free = |c: Cell| c.y >= 1 && config.is_free(c);
    if d.l1() == 2 {
        let (a, b) = (Cell::xy(to.x, from.y), Cell::xy(from.x, to.y));
        for (p, via) in [(a, b), (b, a)] {
            if let Some(m) = config.at(p).filter(|m| !moving.contains(m)) {
                return Ok((Some(m), free(via)));
            }
        }
        return Err(InputError::new(format!(
            "corner move {from} → {to} has no module at either corner to pivot on"
        )));
    }
    let sides = [Cell::xy(-d.y, d.x), Cell::xy(d.y, -d.x)];
    let wall = |s: Cell| supports(config, moving, from + s) && supports(config, moving, to + s);
    let pivot = |s: Cell| config.at(from + s);
    if let Some(&s) = sides.iter().find(|&&s| wall(s)) {
        return Ok((pivot(s), true));
    }
    // No wall: name a module beside `from`, so certification reports the
    // missing support instead of rejecting the schedule.
    match sides.iter().find_map(|&s| pivot(s)) {
        Some(m) => Ok((Some(m), false)),
        None if d.y == 0 && from.y == 1 => Ok((None, true)),
        None => Err(InputError::new(format!(
            "straight move {from} → {to} touches no module beside its start cell"
        ))),
    }
}

fn emit(plan: &Plan) -> Result<Emitted, InputError> {
    let shape = &plan.shape;
    let mut s = Schedule::new(LatticeKind::Square, Length::mm(50.0));
    s.ground = Some(Ground { layer: 1 });
    s.sinks = vec![SINK];
    let mut config = Configuration::new();
    for c in shape.cells() {
        let id = shape.module_id(c);
        s.modules.push(ModuleSpec {
            id,
            cell: c,
            fixed: false,
        });
        config.insert(id, c).expect("distinct cells");
    }
    let ids: Vec<ModuleId> = plan
        .run
        .removals
        .iter()
        .map(|r| shape.module_id(r.start()))
        .collect();
    let total = plan.time_steps;
    let mut by_step: Vec<Vec<usize>> = vec![Vec::new(); total + 1];
    for i in 0..plan.run.removals.len() {
        let steps = plan.times.start[i] + 1..=plan.times.arrival[i];
        for movers in &mut by_step[steps] {
            movers.push(i);
        }
    }
    let mut unsupported = 0;
    for (t, movers) in by_step.iter().enumerate().skip(1) {
        let moving: FxHashSet<ModuleId> = movers.iter().map(|&i| ids[i]).collect();
        let mut events = Vec::with_capacity(movers.len() + 1);
        let mut moves = Vec::with_capacity(movers.len());
        for &i in movers {
            let j = t - plan.times.start[i];
            let cells = &plan.run.removals[i].cells;
            let (from, to) = (cells[j - 1], cells[j]);
            let (pivot, ok) = pivot_for(&config, &moving, from, to)
                .map_err(|e| InputError::new(format!("step {t}, module {}: {e}", ids[i])))?;
            if !ok {
                unsupported += 1;
            }
            events.push(Event::Slide {
                module: ids[i],
                from,
                to,
                pivot,
            });
            if to == SINK {
                events.push(Event::Leave { module: ids[i] });
            }
            moves.push((ids[i], to));
        }
        for &(id, _) in &moves {
            config.remove(id);
        }
        for &(id, to) in &moves {
            if to != SINK {
                config.insert(id, to).map_err(|o| {
                    InputError::new(format!("step {t}: modules {id} and {o} meet at {}", xy(to)))
                })?;
            }
        }
        s.steps.push(Step { events });
    }
    s.meta
        .insert("algorithm".into(), "active-subtraction".into());
    s.meta.insert("mode".into(), plan.mode.name().into());
    s.meta.insert("time_steps".into(), total.into());
    s.meta
        .insert("excluded".into(), plan.run.removals.len().into());
    s.meta
        .insert("included".into(), shape.included_count().into());
    s.meta.insert(
        "initial".into(),
        format!("{} x {}", shape.width, shape.height).into(),
    );
    s.meta
        .insert("unsupported_moves".into(), unsupported.into());
    if plan.mode == Mode::Pas {
        let t = &plan.times;
        s.meta.insert(
            "pas_delays".into(),
            serde_json::json!({"moore": t.delayed_moore, "route": t.delayed_route, "support": t.delayed_support}),
        );
    }
    Ok(Emitted {
        schedule: s,
        unsupported,
    })
}
