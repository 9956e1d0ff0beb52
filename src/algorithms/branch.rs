//! The "branch" family: a horizontal FCC branch of length `b` grown module
//! by module from a fixed base by free agents rolling out along its top —
//! the mechanically critical part of seed 000's scaffold (a horizontal X/Y
//! branch being fed from its root), small enough to study for every `b`.
//!
//! The base is a fixed module at `(0, 0, 0)`; the branch cells are
//! `(1..=b, 0, 0)`, in the air (no ground). Agents enter at the source cell
//! `(0, 0, 1)` above the base, roll along the top cells `(i, 0, 1)` with the
//! branch module `(i, 0, 0)` as pivot (octagonal route over the pivot's
//! top, a 60° turn from direction 5 to 4), and finally roll down over the
//! tip to extend the branch (the free agent at the tip: the worst load on
//! the branch root). One agent travels at a time.

use super::{Generator, parameters};
use crate::error::InputError;
use crate::lattice::config::ModuleId;
use crate::lattice::{Cell, FccLattice, Lattice, LatticeKind, Route};
use crate::scenario::Scenario;
use crate::schedule::{Event, Length, ModuleSpec, Schedule, Step};
use serde::Deserialize;

/// Parameters of the branch generator.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BranchParams {
    /// Branch length `b` in modules.
    pub length: usize,
    /// Lattice spacing (mm); default seed 000's 3.6 mm.
    #[serde(default = "default_spacing")]
    pub spacing_mm: f64,
}

fn default_spacing() -> f64 {
    3.6
}

/// Upper limit on `b`, to keep schedules small (O(b²) steps).
pub const MAX_LENGTH: usize = 200;

/// The schedule growing a branch of `b` modules (see the module docs).
pub fn branch_schedule(b: usize, spacing_mm: f64) -> Result<Schedule, InputError> {
    if b == 0 || b > MAX_LENGTH {
        return Err(InputError::new(format!(
            "branch length must be in 1..={MAX_LENGTH}, got {b}"
        )));
    }
    let l = FccLattice;
    let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(spacing_mm));
    s.modules.push(ModuleSpec {
        id: 0,
        cell: Cell::new(0, 0, 0),
        fixed: true,
    });
    let source = Cell::new(0, 0, 1);
    s.sources.push(source);
    s.meta.insert("algorithm".into(), "branch".into());
    s.meta.insert("branch_length".into(), b.into());
    for k in 0..b as i32 {
        // The branch holds modules 1..=k; agent k+1 extends it to k+1.
        let agent = k as ModuleId + 1;
        s.steps.push(Step {
            events: vec![Event::Enter {
                module: agent,
                cell: source,
            }],
        });
        let pivot_id = |x: i32| x as ModuleId; // branch module at x has id x
        for x in 1..=k {
            s.steps.push(Step {
                events: vec![Event::Rotate {
                    module: agent,
                    pivot: pivot_id(x),
                    from: Cell::new(x - 1, 0, 1),
                    to: Cell::new(x, 0, 1),
                    route: Route::Octagonal,
                }],
            });
        }
        let tip = Cell::new(k, 0, 0);
        assert_eq!(l.neighbour(tip, 4), Cell::new(k, 0, 1));
        s.steps.push(Step {
            events: vec![Event::Rotate {
                module: agent,
                pivot: pivot_id(k),
                from: Cell::new(k, 0, 1),
                to: l.neighbour(tip, 0),
                route: Route::Octagonal,
            }],
        });
    }
    Ok(s)
}

/// The branch generator, for scenario files (`algorithm = "branch"`).
pub struct Branch;

impl Generator for Branch {
    fn name(&self) -> &'static str {
        "branch"
    }

    fn about(&self) -> &'static str {
        "a horizontal FCC branch of length b grown by agents rolling along it (b-study family)"
    }

    fn generate(&self, scenario: &Scenario) -> Result<Schedule, InputError> {
        let p: BranchParams = parameters(scenario)?;
        branch_schedule(p.length, p.spacing_mm).map_err(|e| e.in_file(&scenario.path))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::certify::{Options, certify};

    #[test]
    fn a_grown_branch_is_lattice_valid_and_ends_straight() {
        let s = branch_schedule(5, 3.6).unwrap();
        let r = certify(&s, &Options::lattice_only()).unwrap();
        assert!(r.certified, "{}", r.summary());
        // 5 entries, then 1 + 2 + … + 5 rolls.
        assert_eq!(s.steps.len(), 5 + 15);
        let mut w = crate::certify::World::initial(&s).unwrap();
        for (k, step) in s.steps.iter().enumerate() {
            let plan = w.resolve(k + 1, step).unwrap();
            w.apply(&plan);
        }
        for x in 0..=5 {
            assert!(w.config().at(Cell::new(x, 0, 0)).is_some(), "x = {x}");
        }
        assert_eq!(w.config().len(), 6);
    }

    #[test]
    fn lengths_out_of_range_are_input_errors() {
        assert!(branch_schedule(0, 3.6).is_err());
        assert!(branch_schedule(MAX_LENGTH + 1, 3.6).is_err());
    }
}
