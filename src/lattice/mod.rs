//! Lattices: cells, neighbours, world positions and the kinematic rules of
//! each lattice's moves.
//!
//! Everything lattice-specific lives behind the [`Lattice`] trait so that the
//! schedule format, the certifier and the generators never branch on which
//! lattice they are working with.

mod cell;
pub(crate) mod config;
pub(crate) mod cubic;
pub(crate) mod fcc;
pub(crate) mod moves;
pub(crate) mod square;

pub use cell::Cell;
pub use config::{Configuration, Ground, ModuleId};
pub use cubic::{AtomRest, CubicLattice, Face};
pub use fcc::{FccLattice, directions as fcc_directions};
pub use moves::{Motion, MoveError, MoveRequirements, Route, path_turns};
pub use square::SquareLattice;

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// The lattices the tool knows, as named in schedule and scenario files.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, PartialOrd, Ord)]
#[serde(rename_all = "lowercase")]
pub enum LatticeKind {
    /// Face-centred cubic lattice of 3D Catoms (SPEC §1), seeds 000–002.
    Fcc,
    /// 2D square lattice in a vertical plane (gravity −y), seeds 002–003.
    Square,
    /// Simple cubic lattice (seed 004's atoms and meta-modules).
    Cubic,
}

impl LatticeKind {
    pub fn name(self) -> &'static str {
        match self {
            LatticeKind::Fcc => "fcc",
            LatticeKind::Square => "square",
            LatticeKind::Cubic => "cubic",
        }
    }

    /// The lattice object for this kind.
    pub fn lattice(self) -> &'static dyn Lattice {
        match self {
            LatticeKind::Fcc => &FccLattice,
            LatticeKind::Square => &SquareLattice,
            LatticeKind::Cubic => &CubicLattice,
        }
    }
}

/// A lattice name this build does not know.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown lattice '{0}' (known: fcc, square, cubic)")]
pub struct UnknownLattice(pub String);

impl std::str::FromStr for LatticeKind {
    type Err = UnknownLattice;
    fn from_str(s: &str) -> Result<Self, UnknownLattice> {
        match s {
            "fcc" => Ok(LatticeKind::Fcc),
            "square" => Ok(LatticeKind::Square),
            "cubic" => Ok(LatticeKind::Cubic),
            other => Err(UnknownLattice(other.to_string())),
        }
    }
}

/// A cell that is not a cell of the lattice at all.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("cell {cell} is {reason}")]
pub struct OffLattice {
    pub cell: Cell,
    pub reason: &'static str,
}

/// Up to 12 neighbour cells (the FCC maximum), without allocation.
pub type Neighbours = arrayvec::ArrayVec<Cell, 12>;

/// A lattice of identical modules, in unit spacing: world positions returned
/// here are in units of the lattice spacing `d` (multiply by `d` for metres).
pub trait Lattice: Send + Sync + std::fmt::Debug {
    fn kind(&self) -> LatticeKind;

    /// Number of latching neighbours (connectors) of a module.
    fn connector_count(&self) -> usize;

    /// The neighbour of `c` through connector `dir` (`0..connector_count()`),
    /// in the documented numbering of each lattice.
    fn neighbour(&self, c: Cell, dir: usize) -> Cell;

    /// All latching neighbours of `c`, in connector order.
    fn neighbours(&self, c: Cell) -> Neighbours {
        (0..self.connector_count())
            .map(|k| self.neighbour(c, k))
            .collect()
    }

    /// The connector of `a` that faces `b`, if they are neighbours.
    fn direction_to(&self, a: Cell, b: Cell) -> Option<usize> {
        (0..self.connector_count()).find(|&k| self.neighbour(a, k) == b)
    }

    fn are_neighbours(&self, a: Cell, b: Cell) -> bool {
        self.direction_to(a, b).is_some()
    }

    /// Centre of cell `c` in world coordinates, in units of `d`.
    fn centre(&self, c: Cell) -> DVec3;

    /// Unit vector of gravity in the world frame.
    fn gravity(&self) -> DVec3;

    /// The vertical layer index of a cell (ground layers are compared with it).
    fn layer(&self, c: Cell) -> i32;

    /// Whether `c` is a cell of this lattice at all (the 2D lattice needs z = 0).
    fn check_cell(&self, c: Cell) -> Result<(), OffLattice> {
        let _ = c;
        Ok(())
    }

    /// Kinematic check of one move: is it a move of this lattice, and what
    /// does it need from the surrounding cells? `Err` means the schedule asks
    /// for something that is not a move at all (unusable input); whether the
    /// requirements hold is the certifier's business.
    fn move_requirements(&self, motion: &Motion) -> Result<MoveRequirements, MoveError>;
}
