//! The evolving scene during certification, and the resolution of a step's
//! events into typed moves against it.

use super::report::{Violation, ViolationKind};
use crate::error::InputError;
use crate::lattice::config::{Ground, ModuleId};
use crate::lattice::{Cell, Configuration, Lattice, Motion, MoveRequirements};
use crate::schedule::{Event, Schedule, Step};
use rustc_hash::{FxHashMap, FxHashSet};

/// The scene between two time steps. Its state changes only through
/// [`World::apply`], so the connectivity cache (`anchored`) cannot fall out
/// of step with the configuration; checks read it through accessors.
#[derive(Clone, Debug)]
pub struct World {
    lattice: &'static dyn Lattice,
    ground: Option<Ground>,
    config: Configuration,
    fixed: FxHashSet<ModuleId>,
    sources: FxHashSet<Cell>,
    sinks: FxHashSet<Cell>,
    detached: FxHashSet<(ModuleId, ModuleId)>,
    /// Every id that was ever in the scene, and the step it left at.
    left_at: FxHashMap<ModuleId, usize>,
    /// Whether the configuration is known to be anchored as a whole, which
    /// lets connectivity be checked locally around the movers.
    anchored: bool,
}

fn pair(a: ModuleId, b: ModuleId) -> (ModuleId, ModuleId) {
    (a.min(b), a.max(b))
}

/// One move of a step, resolved against the scene at the start of the step.
#[derive(Clone, Debug, PartialEq)]
pub struct Move {
    pub module: ModuleId,
    /// The pivot module, where the move names one and it is present.
    pub pivot: Option<ModuleId>,
    pub motion: Motion,
    pub requirements: MoveRequirements,
    /// False when the pivot is missing: the lattice could not derive the
    /// move's requirements, and checks that need the pivot skip it.
    pub pivot_resolved: bool,
}

/// A docking's final approach, resolved: the lattice move from `motion.from()`
/// into the docked cell on the pivot (`None` when the pivot has left the
/// scene: the certifier reports it).
#[derive(Clone, Debug, PartialEq)]
pub struct Dock {
    pub module: ModuleId,
    pub pivot: ModuleId,
    pub pivot_cell: Option<Cell>,
    pub motion: Motion,
    pub requirements: MoveRequirements,
}

/// A step's events, resolved and grouped.
#[derive(Clone, Debug, Default)]
pub struct StepPlan {
    /// 1-based time step.
    pub step: usize,
    pub moves: Vec<Move>,
    pub enters: Vec<(ModuleId, Cell)>,
    pub leaves: Vec<ModuleId>,
    pub attaches: Vec<(ModuleId, ModuleId)>,
    pub detaches: Vec<(ModuleId, ModuleId)>,
    /// Seed 002 dockings (each also listed in `enters`), with their final
    /// approach resolved against the scene.
    pub docks: Vec<Dock>,
    /// Modules that are not static during the step (movers and leavers).
    pub moving: FxHashSet<ModuleId>,
    /// Violations found while resolving (missing pivots, double moves).
    pub violations: Vec<Violation>,
}

impl StepPlan {
    /// The moves whose pivot could be resolved, as (mover, pivot, motion):
    /// what the geometric and mechanical checks examine.
    pub fn resolved_moves(&self) -> Vec<(ModuleId, Option<ModuleId>, Motion)> {
        self.moves
            .iter()
            .filter(|m| m.pivot_resolved)
            .map(|m| (m.module, m.pivot, m.motion.clone()))
            .collect()
    }
}

impl World {
    /// The initial scene of a schedule. Errors are input errors: duplicate
    /// ids, two modules in one cell, cells that are not on the lattice or
    /// inside the ground.
    pub fn initial(s: &Schedule) -> Result<World, InputError> {
        s.validate()?;
        let lattice = s.lattice.lattice();
        let mut world = World {
            lattice,
            ground: s.ground,
            config: Configuration::new(),
            fixed: FxHashSet::default(),
            sources: s.sources.iter().copied().collect(),
            sinks: s.sinks.iter().copied().collect(),
            detached: FxHashSet::default(),
            left_at: FxHashMap::default(),
            anchored: false,
        };
        for m in &s.modules {
            let err = |msg: String| InputError::new(msg).at_step(0).for_module(m.id);
            world.check_cell(m.cell).map_err(|e| err(e.message))?;
            if world.config.contains(m.id) {
                return Err(err(format!("module id {} is declared twice", m.id)));
            }
            if let Err(other) = world.config.insert(m.id, m.cell) {
                return Err(err(format!(
                    "two modules in one cell: {} and {other} are both at {}",
                    m.id, m.cell
                )));
            }
            if m.fixed {
                world.fixed.insert(m.id);
            }
        }
        for c in s.sources.iter().chain(&s.sinks) {
            lattice
                .check_cell(*c)
                .map_err(|e| InputError::new(format!("source/sink: {e}")))?;
        }
        Ok(world)
    }

    /// Whether `c` may hold a module: a cell of the lattice, not inside the
    /// ground. The message says why not.
    fn check_cell(&self, c: Cell) -> Result<(), InputError> {
        self.lattice
            .check_cell(c)
            .map_err(|e| InputError::new(e.to_string()))?;
        if let Some(g) = self.ground
            && g.is_ground_cell(self.lattice, c)
        {
            return Err(InputError::new(format!(
                "cell {c} is inside the ground (below layer {})",
                g.layer
            )));
        }
        Ok(())
    }

    pub fn lattice(&self) -> &'static dyn Lattice {
        self.lattice
    }

    pub fn ground(&self) -> Option<Ground> {
        self.ground
    }

    /// Which module is in which cell.
    pub fn config(&self) -> &Configuration {
        &self.config
    }

    /// The modules that never move (anchors, like the ground).
    pub fn fixed(&self) -> &FxHashSet<ModuleId> {
        &self.fixed
    }

    /// Whether a module may enter the scene at `c`: anywhere when the
    /// schedule names no source cells.
    pub fn may_enter_at(&self, c: Cell) -> bool {
        self.sources.is_empty() || self.sources.contains(&c)
    }

    /// Whether a module may leave the scene from `c`: only at a sink cell.
    pub fn may_leave_from(&self, c: Cell) -> bool {
        self.sinks.contains(&c)
    }

    /// How many pairs of touching modules are detached now.
    pub fn detached_pairs(&self) -> usize {
        self.detached.len()
    }

    pub fn latched(&self, a: ModuleId, b: ModuleId) -> bool {
        !self.detached.contains(&pair(a, b))
    }

    /// Whether cell `c` holds a module that can bear on a mover during a
    /// step: a module that is not moving, or the ground.
    pub fn is_support(&self, c: Cell, moving: &FxHashSet<ModuleId>) -> bool {
        if self
            .ground
            .is_some_and(|g| g.is_ground_cell(self.lattice, c))
        {
            return true;
        }
        self.config.at(c).is_some_and(|m| !moving.contains(&m))
    }

    /// The modules not connected to the ground or a fixed module, with
    /// `exclude` taken out of the structure. When the scene is known to be
    /// anchored (see [`World::check_anchored`] and
    /// [`World::confirm_anchored`]) only the neighbours of the
    /// lifted modules can have lost their anchor, and the search stays local
    /// to them ([`Configuration::unanchored_near`]): a step then costs in
    /// proportion to the movers' surroundings, not to the whole structure.
    /// With any latch released the full search runs (a mover could have come
    /// to rest beside a module it is unlatched from), and so it does in a
    /// scene with neither ground nor fixed modules: there a structure is
    /// connected when it is one component, and the local search, which
    /// looks for anchors, would find none.
    ///
    /// This is the one place connectivity is decided: the lattice check and
    /// the initial and final checks all ask it.
    pub fn unanchored(&self, exclude: &FxHashSet<ModuleId>) -> Vec<ModuleId> {
        let latched = |a, b| self.latched(a, b);
        let has_anchor = self.ground.is_some() || !self.fixed.is_empty();
        if self.anchored && self.detached.is_empty() && has_anchor {
            self.config
                .unanchored_near(self.lattice, self.ground, &self.fixed, exclude, &latched)
        } else {
            self.config
                .unanchored(self.lattice, self.ground, &self.fixed, exclude, &latched)
        }
    }

    /// Runs the full connectivity search over the whole scene and records
    /// its answer: the modules not connected to an anchor (none: the scene
    /// is known to be anchored from now on, until a step says otherwise).
    pub fn check_anchored(&mut self) -> Vec<ModuleId> {
        self.anchored = false;
        let loose = self.unanchored(&FxHashSet::default());
        self.anchored = loose.is_empty();
        loose
    }

    /// After [`World::apply`]: records that the step just applied kept every
    /// module anchored, which the caller establishes from its lattice
    /// checks: a step with no lattice-level violation, no released latch
    /// and no tunnel had an anchored static part, and each mover ended
    /// latched to a static pivot or support.
    pub fn confirm_anchored(&mut self) {
        self.anchored = true;
    }

    fn require_present(&self, id: ModuleId, step: usize) -> Result<Cell, InputError> {
        if let Some(c) = self.config.cell_of(id) {
            return Ok(c);
        }
        let msg = match self.left_at.get(&id) {
            Some(k) => format!("module {id} is not in the scene (it left at step {k})"),
            None => format!("unknown module id {id}"),
        };
        Err(InputError::new(msg).at_step(step).for_module(id))
    }

    /// Resolves a step's events against the scene. Input errors: references
    /// to modules that are not there, a `from` cell that is not where the
    /// module is, a move that is not a move of the lattice.
    pub fn resolve(&self, step: usize, events: &Step) -> Result<StepPlan, InputError> {
        let mut plan = StepPlan {
            step,
            ..Default::default()
        };
        let mut seen_motion: FxHashSet<ModuleId> = FxHashSet::default();
        for ev in &events.events {
            let id = ev.module();
            let err = |msg: String| InputError::new(msg).at_step(step).for_module(id);
            match ev {
                Event::Rotate { .. } | Event::Slide { .. } | Event::Tunnel { .. } => {
                    let here = self.require_present(id, step)?;
                    let (from, pivot_id) = match ev {
                        Event::Rotate { from, pivot, .. } => (*from, Some(*pivot)),
                        Event::Slide { from, pivot, .. } => (*from, *pivot),
                        Event::Tunnel { path, .. } => {
                            let first = *path
                                .first()
                                .ok_or_else(|| err("empty tunnel path".into()))?;
                            (first, None)
                        }
                        _ => unreachable!(),
                    };
                    if self.fixed.contains(&id) {
                        return Err(err(format!(
                            "module {id} is fixed (ground/sandbox) and cannot move"
                        )));
                    }
                    if from != here {
                        return Err(err(format!(
                            "impossible move: the module is at {here}, not at {from}"
                        )));
                    }
                    if !seen_motion.insert(id) {
                        plan.violations.push(
                            Violation::new(
                                ViolationKind::MultipleMoves,
                                step,
                                format!("module {id} is given more than one move in one time step"),
                            )
                            .modules([id]),
                        );
                        continue;
                    }
                    let pivot_cell = match pivot_id {
                        Some(p) if p == id => {
                            return Err(err("a module cannot be its own pivot".into()));
                        }
                        Some(p) => match self.config.cell_of(p) {
                            Some(c) => Some(c),
                            None if self.left_at.contains_key(&p) => {
                                plan.violations.push(
                                    Violation::new(
                                        ViolationKind::PivotMissing,
                                        step,
                                        format!("module {id} rolls on pivot {p}, which is not in the scene"),
                                    )
                                    .modules([id, p]),
                                );
                                None
                            }
                            None => return Err(err(format!("unknown pivot module id {p}"))),
                        },
                        None => None,
                    };
                    let motion = match ev {
                        Event::Rotate { to, route, .. } => Motion::Rotate {
                            from,
                            to: *to,
                            pivot: pivot_cell.unwrap_or(from),
                            route: *route,
                        },
                        Event::Slide { to, .. } => Motion::Slide {
                            from,
                            to: *to,
                            pivot: pivot_cell,
                        },
                        Event::Tunnel { path, .. } => Motion::Tunnel { path: path.clone() },
                        _ => unreachable!(),
                    };
                    for c in [motion.from(), motion.to()] {
                        self.check_cell(c).map_err(|e| err(e.message))?;
                    }
                    let pivot_resolved = pivot_id.is_none() || pivot_cell.is_some();
                    let requirements = if pivot_resolved {
                        self.lattice.move_requirements(&motion).map_err(|e| {
                            err(format!("not a {} move: {e}", self.lattice.kind().name()))
                        })?
                    } else {
                        MoveRequirements::default()
                    };
                    plan.moving.insert(id);
                    plan.moves.push(Move {
                        module: id,
                        pivot: pivot_id.filter(|_| pivot_cell.is_some()),
                        motion,
                        requirements,
                        pivot_resolved,
                    });
                }
                Event::Enter { cell, .. } => {
                    if self.config.contains(id) {
                        return Err(err(format!(
                            "module {id} enters but is already in the scene"
                        )));
                    }
                    self.check_cell(*cell).map_err(|e| err(e.message))?;
                    plan.enters.push((id, *cell));
                }
                Event::Dock {
                    cell,
                    pivot,
                    from,
                    route,
                    ..
                } => {
                    if self.config.contains(id) {
                        return Err(err(format!(
                            "module {id} docks but is already in the scene"
                        )));
                    }
                    for c in [*cell, *from] {
                        self.check_cell(c).map_err(|e| err(e.message))?;
                    }
                    let pivot_cell = self.config.cell_of(*pivot);
                    if pivot_cell.is_none() && !self.left_at.contains_key(pivot) {
                        return Err(err(format!("unknown pivot module id {pivot}")));
                    }
                    let motion = match self.lattice.kind() {
                        crate::lattice::LatticeKind::Fcc => Motion::Rotate {
                            from: *from,
                            to: *cell,
                            pivot: pivot_cell.unwrap_or(*from),
                            route: route.ok_or_else(|| {
                                err("a docking on the FCC lattice needs its rotation's route"
                                    .into())
                            })?,
                        },
                        _ => Motion::Slide {
                            from: *from,
                            to: *cell,
                            pivot: pivot_cell,
                        },
                    };
                    let requirements = match pivot_cell {
                        Some(_) => self.lattice.move_requirements(&motion).map_err(|e| {
                            err(format!(
                                "docking approach is not a {} move: {e}",
                                self.lattice.kind().name()
                            ))
                        })?,
                        None => MoveRequirements::default(),
                    };
                    plan.enters.push((id, *cell));
                    plan.docks.push(Dock {
                        module: id,
                        pivot: *pivot,
                        pivot_cell,
                        motion,
                        requirements,
                    });
                }
                Event::Leave { .. } => {
                    self.require_present(id, step)?;
                    plan.moving.insert(id);
                    plan.leaves.push(id);
                }
                Event::Expand { .. } | Event::Contract { .. } => {
                    return Err(err(
                        "expand/contract are atom operations: only a cubic schedule with `atoms` set has them"
                            .into(),
                    ));
                }
                Event::Attach { other, .. } | Event::Detach { other, .. } => {
                    self.require_present(id, step)?;
                    self.require_present(*other, step)?;
                    if matches!(ev, Event::Attach { .. }) {
                        plan.attaches.push((id, *other));
                    } else {
                        plan.detaches.push((id, *other));
                    }
                }
            }
        }
        Ok(plan)
    }

    /// Applies a step. Returns the occupancy clashes (two modules ending in
    /// one cell); on a clash the later module stays where it was. The scene
    /// is no longer known to be anchored (see [`World::confirm_anchored`]).
    pub fn apply(&mut self, plan: &StepPlan) -> Vec<Violation> {
        self.anchored = false;
        let mut clashes = Vec::new();
        for m in &plan.moves {
            self.config.remove(m.module);
        }
        let arrivals = plan
            .moves
            .iter()
            .map(|m| (m.module, m.motion.to(), m.motion.from()))
            .chain(plan.enters.iter().map(|&(id, c)| (id, c, c)));
        for (id, to, from) in arrivals {
            if let Err(other) = self.config.insert(id, to) {
                clashes.push(
                    Violation::new(
                        ViolationKind::Occupancy,
                        plan.step,
                        format!(
                            "two modules in one cell: {id} and {other} both end the step at {to}"
                        ),
                    )
                    .modules([id, other])
                    .cells([to]),
                );
                if from != to {
                    let _ = self.config.insert(id, from);
                }
            }
        }
        for &(a, b) in &plan.attaches {
            self.detached.remove(&pair(a, b));
        }
        for &(a, b) in &plan.detaches {
            self.detached.insert(pair(a, b));
        }
        for &id in &plan.leaves {
            self.config.remove(id);
            self.left_at.insert(id, plan.step);
            self.detached.retain(|&(a, b)| a != id && b != id);
        }
        clashes
    }
}
