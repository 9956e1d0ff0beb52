//! True collision check (SPEC §4.3): each step's sweeps, through the
//! lattice's [`SweepModel`].

use super::report::{Severity, Violation, ViolationKind};
use super::{StepCheck, StepContext, StepOutcome};
use crate::geometry::{Contact, ContactKind, Obstacle, SweepInput, SweepModel};
use crate::lattice::Motion;

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
            ground: ctx.world.ground(),
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
        if deepest > 0.0 {
            out.metrics.insert("max_penetration".into(), deepest);
        }
    }
}

/// The violation (or warning) of one contact, with the cells it concerns:
/// the mover's start and target cells (its link), then the other body's
/// cell at the start of the step (a module's, or the ground cell the mover
/// entered); the pivot's cell and the route are in the details.
fn contact_violation(c: &Contact, ctx: &StepContext<'_>) -> Violation {
    let step = ctx.plan.step;
    let config = ctx.world.config();
    let motion = ctx
        .plan
        .moves
        .iter()
        .find(|m| m.module == c.mover)
        .map(|m| &m.motion);
    let (kind, what) = match c.kind {
        ContactKind::Collision => (ViolationKind::Collision, "penetrates"),
        ContactKind::SlidingContact => (ViolationKind::SlidingContact, "slides in contact with"),
    };
    let v = Violation::new(
        kind,
        step,
        format!(
            "module {} {what} {} at s = {:.4} (depth {:.3e} d)",
            c.mover, c.other, c.s, c.depth
        ),
    )
    .modules(std::iter::once(c.mover).chain(c.other.module()))
    .cells(motion.map(|m| [m.from(), m.to()]).into_iter().flatten())
    .cells(c.other.cell(config))
    .detail("s", c.s)
    .detail("depth", c.depth)
    .detail("witness_mover", c.witness_mover.to_array())
    .detail("witness_other", c.witness_other.to_array());
    // A ground contact says so (a module contact is the default reading).
    let v = match c.other {
        Obstacle::Ground(_) => v.detail("obstacle", "ground"),
        Obstacle::Module(_) => v,
    };
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

#[cfg(test)]
mod tests {
    use crate::certify::{Options, ViolationKind, certify};
    use crate::geometry::rolling::links;
    use crate::lattice::{Cell, FccLattice, Ground, Lattice, LatticeKind};
    use crate::schedule::units::Length;
    use crate::schedule::{Event, ModuleSpec, Schedule, Step};

    /// A fixed pivot at `pivot` and a mover rolling by `link`, on a
    /// ground at layer 0 or without one.
    fn roll(pivot: Cell, link: crate::geometry::rolling::Link, ground: bool) -> Schedule {
        let l = FccLattice;
        let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(3.6));
        s.ground = ground.then_some(Ground { layer: 0 });
        let (from, to) = (
            l.neighbour(pivot, link.from as usize),
            l.neighbour(pivot, link.to as usize),
        );
        s.modules = vec![
            ModuleSpec {
                id: 0,
                cell: pivot,
                fixed: true,
            },
            ModuleSpec {
                id: 1,
                cell: from,
                fixed: false,
            },
        ];
        s.steps = vec![Step {
            events: vec![Event::Rotate {
                module: 1,
                pivot: 0,
                from,
                to,
                route: link.route,
            }],
        }];
        s
    }

    /// End to end: a roll along the ground layer that dips into the
    /// ground is a collision naming the ground and its cell, not a module;
    /// the very same roll with no ground below is clear.
    #[test]
    fn a_roll_that_dips_into_the_ground_is_a_collision_with_the_ground() {
        let l = FccLattice;
        let pivot = Cell::new(0, 0, 0);
        let mut dipped = 0;
        for link in links() {
            let (from, to) = (
                l.neighbour(pivot, link.from as usize),
                l.neighbour(pivot, link.to as usize),
            );
            if l.layer(from) != 0 || l.layer(to) != 0 {
                continue;
            }
            let with = certify(&roll(pivot, link, true), &Options::default()).unwrap();
            let hits: Vec<_> = with
                .violations
                .iter()
                .filter(|v| v.kind == ViolationKind::Collision)
                .collect();
            if hits.is_empty() {
                continue;
            }
            dipped += 1;
            for v in &hits {
                assert!(v.message.contains("the ground (cell"), "{}", v.message);
                assert_eq!(v.modules, vec![1], "only the mover is named");
                assert_eq!(v.detail["obstacle"], "ground");
                let cell = *v.cells.last().unwrap();
                assert!(
                    l.layer(cell) < 0,
                    "the blocking cell {cell} is below the ground"
                );
            }
            let without = certify(&roll(pivot, link, false), &Options::default()).unwrap();
            assert!(
                without
                    .violations
                    .iter()
                    .all(|v| v.kind != ViolationKind::Collision),
                "{link:?}: {:?}",
                without.violations
            );
        }
        assert!(dipped > 0, "no roll along the ground dips into it");
    }
}
