//! Seed 002 dockings certified by geometry: a docking is a module's last
//! motion into its cell, so it needs a real final approach — a free origin
//! next to the cell, a pivot (and, for a straight slide, its wall) already
//! in the structure, and a sweep into the cell that penetrates no module.
//! The approach the schedule names is judged with the exact sweep of the
//! lattice's bodies (`geometry::docking`); the paper's Rule 1 plays no part.
//! A blocked docking is reported with the step, the module, the blocking
//! cells, and whether any other approach into the cell would be clear.
//!
//! The origin must also be reachable: a module has to get there from
//! outside the structure, so an origin walled in by modules (and the
//! ground) is a blocked docking too, whatever its sweep.

use super::report::{Violation, ViolationKind};
use super::{StepCheck, StepContext, StepOutcome};
use crate::geometry::Tolerance;
use crate::geometry::docking::{Approach, bounds_of, clear_approaches, judge, origin_reachable};

/// The final-approach check of every `dock` event.
#[derive(Debug, Default)]
pub struct DockingCheck {
    pub epsilon: Tolerance,
}

impl StepCheck for DockingCheck {
    fn name(&self) -> &'static str {
        "docking"
    }

    fn check(&self, ctx: &StepContext<'_>, out: &mut StepOutcome) {
        let w = ctx.world;
        let plan = ctx.plan;
        let lattice = w.lattice();
        // Cells other events of the step fill or leave count as occupied:
        // a concurrent arrival may be there first.
        let busy = plan.moves.len() + plan.enters.len() > 1;
        let mut scene = busy.then(|| w.config().clone());
        if let Some(scene) = scene.as_mut() {
            for m in &plan.moves {
                let _ = scene.insert(m.module, m.motion.to());
            }
        }
        for d in &plan.docks {
            let cell = d.motion.to();
            let Some(pivot_cell) = d.pivot_cell else {
                out.violations.push(
                    Violation::new(
                        ViolationKind::DockingBlocked,
                        plan.step,
                        format!(
                            "module {} docks at {cell} on pivot {}, which is not in the structure",
                            d.module, d.pivot
                        ),
                    )
                    .modules([d.module, d.pivot])
                    .cells([cell]),
                );
                continue;
            };
            let config = match scene.as_mut() {
                Some(s) => {
                    // The other arrivals of this step, not this one.
                    for &(id, c) in &plan.enters {
                        if id != d.module {
                            let _ = s.insert(id, c);
                        }
                    }
                    &*s
                }
                None => w.config(),
            };
            let approach = Approach {
                from: d.motion.from(),
                pivot: pivot_cell,
                motion: d.motion.clone(),
            };
            let ground = w.ground();
            let bounds = bounds_of(config);
            let verdict = judge(lattice, config, ground, &approach, self.epsilon);
            // Only a clear approach needs the search: a blocked one fails anyway.
            let enclosed = verdict.is_clear()
                && !origin_reachable(lattice, config, ground, bounds, approach.from);
            if verdict.is_clear() && !enclosed && !plan.moving.contains(&d.pivot) {
                continue;
            }
            let others = clear_approaches(lattice, config, ground, bounds, cell, self.epsilon);
            let mut cells = verdict.blocking.clone();
            cells.extend(verdict.missing_supports.iter().copied());
            let mut why = Vec::new();
            if !verdict.blocking.is_empty() {
                why.push(format!("blocked by {}", list(&verdict.blocking)));
            }
            if let Some(depth) = verdict.below_floor {
                why.push(format!("its sweep dips {depth:.3e} d below the floor"));
            }
            if enclosed {
                cells.push(approach.from);
                why.push(format!(
                    "its origin {} is enclosed: no free path reaches it from outside the structure",
                    approach.from
                ));
            }
            if !verdict.missing_supports.is_empty() {
                why.push(format!(
                    "no module at {} to hold on to",
                    list(&verdict.missing_supports)
                ));
            }
            if plan.moving.contains(&d.pivot) {
                why.push(format!("its pivot {} moves in the same step", d.pivot));
            }
            let alternatives = if others.is_empty() {
                format!("no approach into {cell} is clear")
            } else {
                format!(
                    "{} other approach(es) into {cell} would be clear, e.g. from {} on {}",
                    others.len(),
                    others[0].from,
                    others[0].pivot
                )
            };
            out.violations.push(
                Violation::new(
                    ViolationKind::DockingBlocked,
                    plan.step,
                    format!(
                        "module {} docks at {cell} from {} on pivot {} at {pivot_cell}: {}; {alternatives}",
                        d.module,
                        approach.from,
                        d.pivot,
                        why.join(", ")
                    ),
                )
                .modules([d.module, d.pivot])
                .modules(verdict.blocking.iter().filter_map(|c| w.config().at(*c)))
                .cells(cells),
            );
        }
        out.metrics
            .insert("dockings".into(), plan.docks.len() as f64);
    }
}

fn list(cells: &[crate::lattice::Cell]) -> String {
    cells
        .iter()
        .map(|c| c.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}
