//! Geometry: module bodies and the continuous sweeps of their moves.
//!
//! Each lattice with a body model provides a [`SweepModel`]; certification
//! asks [`sweep_model`] for the one of the schedule's lattice and turns the
//! contacts it reports into violations and warnings.

pub mod atom;
pub mod atom_expand;
pub mod atom_search;
pub(crate) mod catom;
pub mod docking;
pub(crate) mod fcc_sweep;
pub mod ground;
pub(crate) mod rolling;
pub(crate) mod rules;
pub mod stored_move;
pub(crate) mod sweep;

use crate::lattice::config::{Ground, ModuleId};
use crate::lattice::{Configuration, Lattice, LatticeKind, Motion};
use glam::DVec3;
pub use ground::GroundContact;
use rustc_hash::FxHashSet;
use serde::{Deserialize, Serialize};

pub(crate) mod square;

pub use catom::catom;
pub use fcc_sweep::FccSweep;
pub use rules::{FccRules, LinkRules, RuleTable, offsets_within_reach, table};
pub use square::SquareSweep;

/// Default certification tolerance, in units of the lattice spacing d.
pub const EPSILON: f64 = 1e-6;

/// The collision tolerance ε, in units of the lattice spacing d: penetration
/// deeper than ε is a collision, contact within ±ε sliding contact.
///
/// Validated to (0, [`Tolerance::MAX`]]: ε ≤ 0 stalls the conservative
/// advancement (its step (dist + ε)/v is never positive), NaN compares false
/// and would certify anything, and a large ε turns deep penetrations into
/// "sliding contact" warnings.
#[derive(Copy, Clone, Debug, PartialEq, PartialOrd, Serialize)]
pub struct Tolerance(f64);

impl Tolerance {
    /// The default, [`EPSILON`].
    pub const DEFAULT: Tolerance = Tolerance(EPSILON);
    /// The largest tolerance accepted: a tenth of the lattice spacing.
    pub const MAX: f64 = 0.1;

    pub fn new(eps: f64) -> Result<Tolerance, crate::number::InvalidNumber> {
        let eps = crate::number::within(eps, 0.0, Self::MAX, "a tolerance in (0, 0.1] d")?;
        crate::number::positive(eps)
            .map(Tolerance)
            .map_err(|e| crate::number::InvalidNumber {
                expected: "a tolerance in (0, 0.1] d",
                ..e
            })
    }

    /// ε in units of d.
    pub fn get(self) -> f64 {
        self.0
    }
}

impl Default for Tolerance {
    fn default() -> Self {
        Tolerance::DEFAULT
    }
}

impl std::fmt::Display for Tolerance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// One step's moves, as the sweep model sees them.
pub struct SweepInput<'a> {
    pub lattice: &'a dyn Lattice,
    /// Occupancy at the start of the step (movers at their start cells).
    pub config: &'a Configuration,
    /// The moves of the step: mover, its pivot (if any) and its motion.
    pub moves: &'a [(ModuleId, Option<ModuleId>, Motion)],
    /// Modules that do not stay put during the step.
    pub moving: &'a FxHashSet<ModuleId>,
    /// Tolerance ε: penetration deeper than ε is a collision, contact
    /// within ±ε with a module other than the pivot is sliding contact.
    pub epsilon: Tolerance,
    /// Force the exact sweep (no compiled rule tables).
    pub exact: bool,
}

/// What a sweep found between a mover and another module.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Contact {
    pub kind: ContactKind,
    /// Sweep parameter s ∈ [0, 1] of the deepest point found.
    pub s: f64,
    /// The mover.
    pub mover: ModuleId,
    /// The other module (static, or another mover).
    pub other: ModuleId,
    /// Penetration depth in units of d (0 for sliding contact).
    pub depth: f64,
    /// Witness points on each body, world frame, units of d.
    pub witness_mover: DVec3,
    pub witness_other: DVec3,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactKind {
    /// Signed distance below −ε: the bodies interpenetrate.
    Collision,
    /// Signed distance within ±ε of a module that is not the pivot.
    SlidingContact,
}

/// Continuous collision checking of one lattice's module bodies.
pub trait SweepModel: Send + Sync {
    fn name(&self) -> &'static str;
    /// All collisions and sliding contacts of one step's concurrent moves.
    fn check_step(&self, input: &SweepInput<'_>) -> Vec<Contact>;

    /// The moves of the step that dig deeper than ε into the scene's
    /// ground. The default reports none: right for a body model whose
    /// movers never leave the cells at or above the ground layer (the
    /// square lattice's axis-aligned paths, which stay within the rows of
    /// their start and target cells).
    fn check_ground(&self, input: &SweepInput<'_>, ground: Ground) -> Vec<GroundContact> {
        let _ = (input, ground);
        Vec::new()
    }
}

/// The sweep model of a lattice, if this build has a body model for it.
pub fn sweep_model(kind: LatticeKind) -> Option<&'static dyn SweepModel> {
    match kind {
        LatticeKind::Fcc => Some(&fcc_sweep::FccSweep),
        LatticeKind::Square => Some(&square::SquareSweep),
        LatticeKind::Cubic => None,
    }
}

/// Motion rules derived from the body geometry: which cells a move needs
/// empty. Generators plan with these; certification checks sweeps exactly.
pub trait MotionRules: Send + Sync {
    /// The cells (absolute lattice cells) whose occupant the move's sweep
    /// would penetrate: every one of them must be empty (or hold a module
    /// that is itself leaving) for the move to be collision-free against
    /// static modules. The pivot, the start and the target are not listed.
    fn blocking_cells(&self, motion: &Motion) -> Vec<crate::lattice::Cell>;

    /// The cells whose occupant the move's sweep penetrates *or touches*
    /// (blocking and sliding-contact cells, the target excluded): what a
    /// planner that wants neither collisions nor sliding contact keeps
    /// empty.
    fn touched_cells(&self, motion: &Motion) -> Vec<crate::lattice::Cell>;

    /// Whether two moves executed in the same step keep clear of each other
    /// (sliding contact counts as not clear).
    fn concurrent_clear(&self, a: &Motion, b: &Motion) -> bool;

    /// Whether `motion` is free of collisions with static modules, given
    /// which cells are occupied at the start of the step.
    fn allows(&self, motion: &Motion, occupied: &dyn Fn(crate::lattice::Cell) -> bool) -> bool {
        self.blocking_cells(motion)
            .into_iter()
            .all(|c| !occupied(c))
    }
}

/// The motion rules of a lattice, if this build derives them.
pub fn motion_rules(kind: LatticeKind) -> Option<&'static dyn MotionRules> {
    match kind {
        LatticeKind::Fcc => Some(&rules::FccRules),
        LatticeKind::Square | LatticeKind::Cubic => None,
    }
}
