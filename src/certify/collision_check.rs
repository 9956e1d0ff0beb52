//! True collision check (SPEC §4.3): each step's sweeps, through the
//! lattice's [`SweepModel`], against the other modules and, where the
//! scene has a ground, against the floor under it.

use super::report::{Severity, Violation, ViolationKind};
use super::{StepCheck, StepContext, StepOutcome};
use crate::geometry::{Contact, ContactKind, GroundContact, SweepInput, SweepModel};
use crate::lattice::Motion;
use crate::lattice::config::ModuleId;

/// Runs a sweep model on every step.
pub struct CollisionCheck {
    pub model: &'static dyn SweepModel,
    pub epsilon: crate::geometry::Tolerance,
    pub exact: bool,
}

impl StepCheck for CollisionCheck {
    fn name(&self) -> &'static str {
        "collision"
    }

    fn check(&self, ctx: &StepContext<'_>, out: &mut StepOutcome) {
        let moves = ctx.plan.resolved_moves();
        if moves.is_empty() {
            return;
        }
        let input = SweepInput {
            lattice: ctx.world.lattice(),
            config: ctx.world.config(),
            moves: &moves,
            moving: &ctx.plan.moving,
            epsilon: self.epsilon,
            exact: self.exact,
        };
        let mut deepest: f64 = 0.0;
        for c in self.model.check_step(&input) {
            deepest = deepest.max(c.depth);
            let v = contact_violation(&c, ctx);
            match c.kind {
                ContactKind::Collision => out.violations.push(v),
                ContactKind::SlidingContact => out.warnings.push(v.severity(Severity::Warning)),
            }
        }
        if let Some(ground) = ctx.world.ground() {
            for c in self.model.check_ground(&input, ground) {
                deepest = deepest.max(c.depth);
                out.violations.push(ground_violation(&c, ctx));
            }
        }
        if deepest > 0.0 {
            out.metrics.insert("max_penetration".into(), deepest);
        }
    }
}

/// The move of `mover` in this step, if it has one.
fn motion_of<'a>(ctx: &'a StepContext<'_>, mover: ModuleId) -> Option<&'a Motion> {
    ctx.plan
        .moves
        .iter()
        .find(|m| m.module == mover)
        .map(|m| &m.motion)
}

/// `v` with the move's link cells first, and its pivot cell and route in
/// the details.
fn with_move(v: Violation, motion: Option<&Motion>) -> Violation {
    let v = v.cells(motion.map(|m| [m.from(), m.to()]).into_iter().flatten());
    match motion {
        Some(Motion::Rotate { pivot, route, .. }) => {
            v.detail("pivot_cell", pivot).detail("route", route)
        }
        Some(Motion::Slide {
            pivot: Some(pivot), ..
        }) => v.detail("pivot_cell", pivot),
        _ => v,
    }
}

/// The violation (or warning) of one contact, with the cells it concerns:
/// the mover's start and target cells (its link), then the other module's
/// cell at the start of the step; the pivot's cell and the route are in the
/// details.
fn contact_violation(c: &Contact, ctx: &StepContext<'_>) -> Violation {
    let (kind, what) = match c.kind {
        ContactKind::Collision => (ViolationKind::Collision, "penetrates"),
        ContactKind::SlidingContact => (ViolationKind::SlidingContact, "slides in contact with"),
    };
    let v = Violation::new(
        kind,
        ctx.plan.step,
        format!(
            "module {} {what} module {} at s = {:.4} (depth {:.3e} d)",
            c.mover, c.other, c.s, c.depth
        ),
    )
    .modules([c.mover, c.other]);
    with_move(v, motion_of(ctx, c.mover))
        .cells(ctx.world.config().cell_of(c.other))
        .detail("s", c.s)
        .detail("depth", c.depth)
        .detail("witness_mover", c.witness_mover.to_array())
        .detail("witness_other", c.witness_other.to_array())
}

/// The violation of a mover digging into the floor: its link's cells and
/// its pivot's cell, the floor's height and the deepest point.
fn ground_violation(c: &GroundContact, ctx: &StepContext<'_>) -> Violation {
    let v = Violation::new(
        ViolationKind::GroundCollision,
        ctx.plan.step,
        format!(
            "module {} dips {:.3e} d below the floor (z = {:.4} d) at s = {:.4}",
            c.mover, c.depth, c.floor, c.s
        ),
    )
    .modules([c.mover]);
    with_move(v, motion_of(ctx, c.mover))
        .detail("s", c.s)
        .detail("depth", c.depth)
        .detail("floor_z", c.floor)
        .detail("witness_mover", c.witness.to_array())
}
