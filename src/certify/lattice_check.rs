//! Lattice-level checks of a step (SPEC §4.1–4.2): occupancy, pivots and
//! supports, passages, sources and sinks, and connectivity of the static
//! structure to the ground.

use super::report::{Violation, ViolationKind};
use super::{StepCheck, StepContext, StepOutcome};
use rustc_hash::FxHashSet;

/// SPEC §4.1 (lattice validity) and §4.2 (connectivity).
#[derive(Debug, Default)]
pub struct LatticeCheck;

impl StepCheck for LatticeCheck {
    fn name(&self) -> &'static str {
        "lattice"
    }

    fn check(&self, ctx: &StepContext<'_>, out: &mut StepOutcome) {
        moves(ctx, out);
        entries(ctx, out);
        exits(ctx, out);
        latches(ctx, out);
        connectivity(ctx, out);
    }
}

/// Each move's pivot (static and latched), supports, tunnelled cells and
/// passage.
fn moves(ctx: &StepContext<'_>, out: &mut StepOutcome) {
    let w = ctx.world;
    let plan = ctx.plan;
    let step = plan.step;
    let moving = &plan.moving;
    let targets: FxHashSet<_> = plan.moves.iter().map(|m| m.motion.to()).collect();
    for m in plan.moves.iter().filter(|m| m.pivot_resolved) {
        if let Some(p) = m.pivot {
            if moving.contains(&p) {
                out.violations.push(
                    Violation::new(
                        ViolationKind::PivotMoving,
                        step,
                        format!(
                            "module {} rolls on pivot {p}, which moves in the same step",
                            m.module
                        ),
                    )
                    .modules([m.module, p]),
                );
            } else if !w.latched(m.module, p) {
                out.violations.push(
                    Violation::new(
                        ViolationKind::MoverDetached,
                        step,
                        format!(
                            "module {} moves on pivot {p}, but their connectors are released",
                            m.module
                        ),
                    )
                    .modules([m.module, p]),
                );
            }
        }
        for &c in &m.requirements.supports {
            let pivot_cell = m.pivot.and_then(|p| w.config().cell_of(p));
            if Some(c) == pivot_cell && m.pivot.is_some_and(|p| moving.contains(&p)) {
                continue; // already reported as a moving pivot
            }
            if !w.is_support(c, moving) {
                out.violations.push(
                    Violation::new(
                        ViolationKind::MoverDetached,
                        step,
                        format!(
                            "module {} moving {} → {} needs a static support at {c}, which is {}",
                            m.module,
                            m.motion.from(),
                            m.motion.to(),
                            if w.config().is_free(c) {
                                "empty"
                            } else {
                                "moving"
                            }
                        ),
                    )
                    .modules([m.module])
                    .cells([c]),
                );
            }
        }
        for &c in &m.requirements.occupied {
            if w.config().is_free(c) {
                out.violations.push(
                    Violation::new(
                        ViolationKind::MoverDetached,
                        step,
                        format!("module {} tunnels through {c}, which is empty", m.module),
                    )
                    .modules([m.module])
                    .cells([c]),
                );
            }
        }
        for &c in &m.requirements.pass_through {
            if !w.config().is_free(c) || targets.contains(&c) {
                out.violations.push(
                    Violation::new(
                        ViolationKind::PassageBlocked,
                        step,
                        format!(
                            "module {} moving {} → {} sweeps through {c}, which is occupied",
                            m.module,
                            m.motion.from(),
                            m.motion.to()
                        ),
                    )
                    .modules([m.module])
                    .modules(w.config().at(c))
                    .cells([c]),
                );
            }
        }
    }
}

/// Modules entering: at a source cell, with something to latch to.
fn entries(ctx: &StepContext<'_>, out: &mut StepOutcome) {
    let w = ctx.world;
    let plan = ctx.plan;
    let step = plan.step;
    let moving = &plan.moving;
    for &(id, cell) in &plan.enters {
        if !w.may_enter_at(cell) {
            out.violations.push(
                Violation::new(
                    ViolationKind::NotASource,
                    step,
                    format!("module {id} enters at {cell}, which is not a source cell"),
                )
                .modules([id])
                .cells([cell]),
            );
        }
        let held = w
            .lattice()
            .neighbours(cell)
            .iter()
            .any(|&n| w.is_support(n, moving));
        if !held {
            out.violations.push(
                Violation::new(
                    ViolationKind::MoverDetached,
                    step,
                    format!("module {id} enters at {cell} with nothing to latch to"),
                )
                .modules([id])
                .cells([cell]),
            );
        }
    }
}

/// Modules leaving: from a sink cell.
fn exits(ctx: &StepContext<'_>, out: &mut StepOutcome) {
    let w = ctx.world;
    let plan = ctx.plan;
    let step = plan.step;
    for &id in &plan.leaves {
        let end = plan
            .moves
            .iter()
            .find(|m| m.module == id)
            .map(|m| m.motion.to())
            .or_else(|| w.config().cell_of(id));
        if let Some(c) = end.filter(|&c| !w.may_leave_from(c)) {
            out.violations.push(
                Violation::new(
                    ViolationKind::NotASink,
                    step,
                    format!("module {id} leaves from {c}, which is not a sink cell"),
                )
                .modules([id])
                .cells([c]),
            );
        }
    }
}

/// Latching and unlatching: only between neighbours.
fn latches(ctx: &StepContext<'_>, out: &mut StepOutcome) {
    let w = ctx.world;
    let plan = ctx.plan;
    let step = plan.step;
    let moving = &plan.moving;
    for &(a, b) in plan.attaches.iter().chain(&plan.detaches) {
        let (ca, cb) = (w.config().cell_of(a), w.config().cell_of(b));
        if let (Some(ca), Some(cb)) = (ca, cb)
            && !w.lattice().are_neighbours(ca, cb)
            && !moving.contains(&a)
            && !moving.contains(&b)
        {
            out.violations.push(
                    Violation::new(
                        ViolationKind::LatchNotAdjacent,
                        step,
                        format!("modules {a} at {ca} and {b} at {cb} are not neighbours; they cannot latch or unlatch"),
                    )
                    .modules([a, b])
                    .cells([ca, cb]),
                );
        }
    }
}

/// With the movers lifted, the static structure is anchored
/// ([`super::World::unanchored`]).
fn connectivity(ctx: &StepContext<'_>, out: &mut StepOutcome) {
    let w = ctx.world;
    let plan = ctx.plan;
    let step = plan.step;
    let moving = &plan.moving;
    let loose = w.unanchored(moving);
    if !loose.is_empty() {
        let shown: Vec<String> = loose.iter().take(8).map(|m| m.to_string()).collect();
        out.violations.push(
            Violation::new(
                ViolationKind::Disconnected,
                step,
                format!(
                    "with its movers lifted, the structure leaves {} module(s) unconnected to the ground: {}{}",
                    loose.len(),
                    shown.join(", "),
                    if loose.len() > 8 { ", …" } else { "" }
                ),
            )
            .modules(loose),
        );
    }
}
