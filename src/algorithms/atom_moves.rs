//! Seed 004's meta-module moves as atom schedules: the sequences the
//! search of [`crate::geometry::atom_search`] derives, lifted to 3D
//! (2×2×2 meta-modules) and written as `atoms` schedules on the cubic
//! lattice, so that the certifier judges them like any other input.

use crate::geometry::atom_search::{Carry, Found, Op, Scene, lift, rest_spacing, slide_problem};
use crate::lattice::config::ModuleId;
use crate::lattice::{AtomRest, Face, LatticeKind};
use crate::schedule::{Event, ModuleSpec, Schedule, Step};

/// A derived SLIDE: the 2D-slice search result and its 3D schedule.
#[derive(Clone, Debug)]
pub struct DerivedSlide {
    pub rest: AtomRest,
    pub carry: Carry,
    pub found: Found,
    /// The 3D schedule (2×2×2 meta-modules).
    pub schedule: Schedule,
}

impl DerivedSlide {
    /// Parallel steps of the 3D move.
    pub fn parallel_steps(&self) -> usize {
        self.schedule.steps.len()
    }

    /// Atom operations of the 3D move.
    pub fn atom_operations(&self) -> usize {
        self.schedule.steps.iter().map(|s| s.events.len()).sum()
    }
}

/// Searches a SLIDE in the given model with the given carried
/// meta-modules; `None` if the search finds none within its bounds.
pub fn derive_slide(rest: AtomRest, carry: Carry) -> Option<DerivedSlide> {
    let (problem, _labels) = slide_problem(rest, carry);
    let found = problem.solve()?;
    let (scene, steps) = lift(&problem.start, &found.steps, rest_spacing(rest));
    let schedule = atom_schedule(&scene, &steps, rest, &format!("SLIDE, {}", carry.name()));
    Some(DerivedSlide {
        rest,
        carry,
        found,
        schedule,
    })
}

/// An `atoms` schedule of `scene` (atom `a` gets id `a`; atom 0, of the
/// wall, is fixed: it holds the frame) doing `steps`.
pub fn atom_schedule(scene: &Scene, steps: &[Vec<Op>], rest: AtomRest, what: &str) -> Schedule {
    let mut s = Schedule::new(LatticeKind::Cubic, crate::schedule::Length::mm(60.0));
    s.atoms = Some(rest);
    s.model = Some("../models/cube-atom.toml".into());
    s.modules = scene
        .pos
        .iter()
        .enumerate()
        .map(|(a, &cell)| ModuleSpec {
            id: a as ModuleId,
            cell,
            fixed: a == 0,
        })
        .collect();
    s.meta.insert("algorithm".into(), "atom-search".into());
    s.meta.insert("move".into(), what.into());
    s.steps = steps
        .iter()
        .map(|st| Step {
            events: st.iter().map(|op| event_of(*op)).collect(),
        })
        .collect();
    s
}

/// The schedule event of one operation (atom `a` is module `a`).
pub fn event_of(op: Op) -> Event {
    op.event(|a| a as ModuleId, |f| f)
}

/// The face names of a sequence, for reading a derived move.
pub fn describe(ops: &[Vec<Op>]) -> String {
    let face = |f: Face| f.name();
    ops.iter()
        .enumerate()
        .map(|(k, st)| {
            let words: Vec<String> = st
                .iter()
                .map(|op| match *op {
                    Op::Expand(a, f) => format!("expand {a}{}", face(f)),
                    Op::Contract(a, f) => format!("contract {a}{}", face(f)),
                    Op::Attach(a, b) => format!("attach {a}-{b}"),
                    Op::Detach(a, b) => format!("detach {a}-{b}"),
                })
                .collect();
            format!("{}: {}", k + 1, words.join(", "))
        })
        .collect::<Vec<_>>()
        .join("\n")
}
