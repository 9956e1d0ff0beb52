//! RePoSt (Bassil et al., IROS 2022): a porous structure of 10-catom
//! meta-modules through which catoms flow along disjoint streamlines.
//!
//! * [`metamodule`]: the SPARSE loop, its FULL filling, the meta-module lattice;
//! * [`search`]: shortest rotation paths over the geometry-derived rules;
//! * [`operations`]: Dismantle, Transfer and Assemble in six directions,
//!   derived by that search on one streamline S → M → D → G.
//!
//! * [`planner`]: the §V planner (sources, destinations, streamlines by
//!   max-flow, transport), iterated to the goal shape.
//!
//! The generator `repost-operation` emits one derived operation scene as a
//! schedule, one rotation per time step; `repost` plans a reconfiguration
//! between two meta-module shape files ([`shape`]).

pub mod messages;
pub mod metamodule;
pub mod operations;
pub mod pipeline;
pub mod planner;
pub mod search;
pub mod shape;

use super::{Generator, parameters};
use crate::error::InputError;
use crate::lattice::LatticeKind;
use crate::lattice::config::Ground;
use crate::scenario::Scenario;
use crate::schedule::{Event, Length, ModuleSpec, Schedule, Step};
use metamodule::{Direction, State};
use operations::{OperationPlan, Role};
use serde::Deserialize;

/// Which goal an operation scene assembles.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Assemble {
    /// EMPTY → SPARSE.
    Sparse,
    /// SPARSE → FULL.
    Full,
}

/// Parameters of `repost-operation`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OperationParams {
    pub direction: Direction,
    pub assemble: Assemble,
    #[serde(default = "default_spacing")]
    pub spacing_mm: f64,
}

fn default_spacing() -> f64 {
    3.6
}

/// The schedule of a derived operation scene: ground at layer 0, no fixed
/// module (the structure rests on the ground), one rotation per step.
pub fn operation_schedule(plan: &OperationPlan, spacing_mm: f64) -> Schedule {
    let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(spacing_mm));
    s.ground = Some(Ground {
        layer: plan.scene.ground,
    });
    for (id, c, _) in &plan.scene.modules {
        s.modules.push(ModuleSpec {
            id: *id,
            cell: *c,
            fixed: false,
        });
    }
    for r in &plan.rotations {
        s.steps.push(Step {
            events: vec![Event::Rotate {
                module: r.module,
                pivot: r.pivot,
                from: r.hop.from,
                to: r.hop.to,
                route: r.hop.route,
            }],
        });
    }
    let sc = &plan.scene;
    s.meta.insert("algorithm".into(), "repost-operation".into());
    s.meta.insert("direction".into(), sc.dir.name().into());
    s.meta.insert(
        "assemble".into(),
        match sc.fill {
            State::Full => "full",
            _ => "sparse",
        }
        .into(),
    );
    s.meta.insert("strict".into(), plan.strict.into());
    s.meta.insert("order".into(), plan.order.into());
    for (k, role) in [
        ("dismantle_moves", Role::Dismantle),
        ("transfer_moves", Role::Transfer),
        ("assemble_moves", Role::Assemble),
        ("support_moves", Role::Support),
    ] {
        s.meta.insert(k.into(), plan.count(role).into());
    }
    s
}

/// One derived operation scene (`algorithm = "repost-operation"`).
pub struct RepostOperation;

impl Generator for RepostOperation {
    fn name(&self) -> &'static str {
        "repost-operation"
    }

    fn about(&self) -> &'static str {
        "RePoSt: dismantle, transfer and assemble one meta-module along a streamline, rotations found by search"
    }

    fn generate(&self, scenario: &Scenario) -> Result<Schedule, InputError> {
        let p: OperationParams = parameters(scenario)?;
        let fill = match p.assemble {
            Assemble::Sparse => State::Sparse,
            Assemble::Full => State::Full,
        };
        let plan = operations::derive(p.direction, fill).map_err(|e| e.in_file(&scenario.path))?;
        Ok(operation_schedule(&plan, p.spacing_mm))
    }
}

/// Parameters of `repost`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlannerParams {
    /// Initial shape file (relative to the scenario).
    pub initial: String,
    /// Goal shape file; a FULL meta-module there is filled (compression).
    pub goal: String,
    #[serde(default = "default_spacing")]
    pub spacing_mm: f64,
    /// "paper" (default), "bottom-up", "supported" or "paired" (see
    /// [`planner::GoalOrder`]).
    #[serde(default)]
    pub goal_order: Option<String>,
}

/// The schedule of a planned reconfiguration: ground under the lowest
/// meta-module layer, no fixed module.
pub fn planner_schedule(p: &planner::Plan, spacing_mm: f64) -> Schedule {
    let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(spacing_mm));
    s.ground = Some(Ground { layer: p.ground });
    for (id, c) in p.modules.iter().enumerate() {
        s.modules.push(ModuleSpec {
            id: id as u32,
            cell: *c,
            fixed: false,
        });
    }
    for step in &p.steps {
        s.steps.push(Step {
            events: step
                .iter()
                .map(|(m, pivot, h)| Event::Rotate {
                    module: *m,
                    pivot: *pivot,
                    from: h.from,
                    to: h.to,
                    route: h.route,
                })
                .collect(),
        });
    }
    s.meta.insert("algorithm".into(), "repost".into());
    s.meta
        .insert("iterations".into(), p.iterations.len().into());
    s.meta.insert(
        "source_width".into(),
        p.source_width.map_or("every leaf".into(), |w| w.into()),
    );
    s.meta
        .insert("goal_order".into(), p.goal_order.name().into());
    s.meta.insert(
        "iteration_detail".into(),
        serde_json::to_value(&p.iterations).expect("iterations serialise"),
    );
    s.meta.insert(
        "streamlines_per_step".into(),
        serde_json::to_value(&p.streamlines_at).expect("counts serialise"),
    );
    s
}

/// The §V planner between two shape files (`algorithm = "repost"`).
pub struct Repost;

impl Generator for Repost {
    fn name(&self) -> &'static str {
        "repost"
    }

    fn about(&self) -> &'static str {
        "RePoSt: reconfigure a porous meta-module structure along disjoint streamlines (max-flow)"
    }

    fn generate(&self, scenario: &Scenario) -> Result<Schedule, InputError> {
        let p = plan_scenario(scenario)?;
        Ok(planner_schedule(&p.plan, p.spacing_mm))
    }
}

/// A planned `repost` scenario: its shapes, the plan and the lattice
/// spacing (mm).
pub struct Planned {
    pub initial: std::collections::BTreeMap<metamodule::Meta, State>,
    pub goal: std::collections::BTreeMap<metamodule::Meta, State>,
    pub plan: planner::Plan,
    pub spacing_mm: f64,
}

/// Plans a `repost` scenario; a goal the planner cannot reach is refused
/// naming the goal file.
pub fn plan_scenario(scenario: &Scenario) -> Result<Planned, InputError> {
    let p: PlannerParams = parameters(scenario)?;
    let (ip, gp) = (scenario.resolve(&p.initial), scenario.resolve(&p.goal));
    let initial = shape::load(&ip)?;
    let goal = shape::load(&gp)?;
    let rules = crate::geometry::motion_rules(LatticeKind::Fcc)
        .expect("the FCC lattice has derived motion rules");
    let order = super::choice(
        scenario,
        "goal_order",
        p.goal_order.as_deref(),
        planner::GoalOrder::parse,
        "paper, bottom-up, supported, paired",
    )?;
    let plan = planner::plan(&initial, &goal, rules, order).map_err(|e| {
        let file = match e {
            planner::PlanError::Bound { .. }
            | planner::PlanError::Catoms { .. }
            | planner::PlanError::Unreachable(_)
            | planner::PlanError::Stuck(..) => &gp,
            planner::PlanError::NoCoordinator => &ip,
        };
        InputError::new(e.to_string()).in_file(file)
    })?;
    Ok(Planned {
        initial,
        goal,
        plan,
        spacing_mm: p.spacing_mm,
    })
}
