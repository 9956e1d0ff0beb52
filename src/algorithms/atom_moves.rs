//! Seed 004's meta-module moves as atom schedules: the sequences the
//! search of [`crate::geometry::atom_search`] derives, lifted to 3D
//! (2×2×2 meta-modules) and written as `atoms` schedules on the cubic
//! lattice, so that the certifier judges them like any other input.

use crate::geometry::atom_expand::expand;
use crate::geometry::atom_search::{Carry, Found, Op, Scene, lift, rest_spacing, slide_problem};
use crate::geometry::stored_move;
use crate::lattice::config::ModuleId;
use crate::lattice::{AtomRest, Cell, Face, LatticeKind};
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

/// A SLIDE in the given model with the given carried meta-modules: the
/// contracted model's searched here; the expanded model's read from its
/// stored file, validated by replay, and placed by the meta-module
/// expansion (which adds the relatch a load on the far side needs).
/// `None` if the search finds none within its bounds or the stored
/// sequence fails its replay.
pub fn derive_slide(rest: AtomRest, carry: Carry) -> Option<DerivedSlide> {
    if rest == AtomRest::Expanded {
        return expanded_slide(carry);
    }
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

/// The expanded SLIDE: the slide scene's meta-modules (B fixed) as a
/// meta-module schedule of one `slide` step, expanded into atoms.
fn expanded_slide(carry: Carry) -> Option<DerivedSlide> {
    let (_, found) = stored_move::expanded_slide(Carry::None).ok()?;
    let c = |x, y| Cell::new(x, y, 0);
    let mut metas = vec![(c(1, 0), c(1, 0)), (c(0, 0), c(0, 0)), (c(1, 1), c(0, 1))];
    metas.extend([(c(-1, 1), c(-1, 1)), (c(-1, 0), c(-1, 0))]);
    if matches!(carry, Carry::Behind | Carry::Both) {
        metas.push((c(2, 1), c(1, 1)));
    }
    if matches!(carry, Carry::Above | Carry::Both) {
        metas.push((c(1, 2), c(0, 2)));
    }
    let mut meta = Schedule::new(LatticeKind::Cubic, crate::schedule::Length::mm(60.0));
    meta.meta_modules = Some(AtomRest::Expanded);
    meta.modules = metas
        .iter()
        .enumerate()
        .map(|(id, &(cell, _))| ModuleSpec {
            id: id as ModuleId,
            cell,
            fixed: id == 0,
        })
        .collect();
    let events = metas
        .iter()
        .enumerate()
        .filter(|(_, (from, to))| from != to)
        .map(|(id, &(from, to))| Event::Slide {
            module: id as ModuleId,
            from,
            to,
            pivot: (id == 2).then_some(0),
        })
        .collect();
    meta.steps = vec![Step { events }];
    let mut schedule = expand(&meta, AtomRest::Expanded).ok()?;
    schedule.model = Some("../models/cube-atom.toml".into());
    schedule
        .meta
        .insert("move".into(), format!("SLIDE, {}", carry.name()).into());
    Some(DerivedSlide {
        rest: AtomRest::Expanded,
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
