//! Moves in cell terms, before any module identities: what the lattice needs
//! to decide whether a move exists and what it requires around it.

use super::Cell;
use serde::{Deserialize, Serialize};

/// Which way a 60° FCC rotation passes around its pivot (SPEC §3). A 90°
/// rotation is octagonal only.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, PartialOrd, Ord)]
#[serde(rename_all = "lowercase")]
pub enum Route {
    Hexagonal,
    Octagonal,
}

/// A move of one module in lattice terms.
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    /// FCC rolling rotation of a module on its pivot.
    Rotate {
        from: Cell,
        to: Cell,
        pivot: Cell,
        route: Route,
    },
    /// Sliding move (square or cubic lattice). `pivot` is the module the
    /// mover keeps hold of: for a straight slide, the wall module beside
    /// `from` (the module beside `to` on the same side must then be present);
    /// for a diagonal (corner) move, the module at the corner. `None` means
    /// the mover slides on the ground (the side opposite to gravity's
    /// direction is the ground).
    Slide {
        from: Cell,
        to: Cell,
        pivot: Option<Cell>,
    },
    /// Seed 004 k-TUNNEL: a module pushed in at `path[0]` and popped out at
    /// the last cell, along an orthogonal path through the robot.
    Tunnel { path: Vec<Cell> },
}

impl Motion {
    pub fn from(&self) -> Cell {
        match self {
            Motion::Rotate { from, .. } | Motion::Slide { from, .. } => *from,
            Motion::Tunnel { path } => path[0],
        }
    }

    pub fn to(&self) -> Cell {
        match self {
            Motion::Rotate { to, .. } | Motion::Slide { to, .. } => *to,
            Motion::Tunnel { path } => *path.last().expect("tunnel path is non-empty"),
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            Motion::Rotate { .. } => "rotate",
            Motion::Slide { .. } => "slide",
            Motion::Tunnel { .. } => "tunnel",
        }
    }
}

/// What a valid move needs from its surroundings, as the lattice derives it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MoveRequirements {
    /// Cells that must hold a module that does not move in the same step (or
    /// lie in the ground) for the mover to stay attached.
    pub supports: Vec<Cell>,
    /// Cells the mover passes through, which must be empty during the step.
    pub pass_through: Vec<Cell>,
    /// Cells that must hold modules for the move to exist (tunnel interior).
    pub occupied: Vec<Cell>,
}

/// Why a requested move is not a move of the lattice.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum MoveError {
    #[error("{0}")]
    NotAMove(String),
    #[error("move '{0}' does not exist on the {1} lattice")]
    Unsupported(&'static str, &'static str),
}

/// A straight slide of one cell along a wall, shared by the square and cubic
/// lattices: the mover keeps contact with a wall formed by the module beside
/// `from` (the pivot, on side `s` perpendicular to the motion) and the cell
/// beside `to` on the same side. Without a pivot the wall is the ground:
/// side `s` is `down`.
pub(crate) fn wall_slide(
    from: Cell,
    to: Cell,
    pivot: Option<Cell>,
    down: Cell,
) -> Result<MoveRequirements, MoveError> {
    let d = to - from;
    if d.l1() != 1 {
        return Err(MoveError::NotAMove(format!(
            "{from} → {to} is not a one-cell straight slide"
        )));
    }
    let side = match pivot {
        Some(p) => p - from,
        None => down,
    };
    let perpendicular = side.l1() == 1 && side.x * d.x + side.y * d.y + side.z * d.z == 0;
    if !perpendicular {
        return Err(MoveError::NotAMove(match pivot {
            Some(p) => format!(
                "pivot cell {p} is not beside {from} on a side perpendicular to the slide {from} → {to}"
            ),
            None => format!(
                "{from} → {to} without a pivot slides on the ground, but the motion is not horizontal"
            ),
        }));
    }
    Ok(MoveRequirements {
        supports: vec![from + side, to + side],
        ..Default::default()
    })
}

/// The interior cells, by index, where an orthogonal path changes
/// direction: the turns of seed 004's k-TUNNEL (k of them).
pub fn path_turns(path: &[Cell]) -> Vec<usize> {
    (1..path.len().saturating_sub(1))
        .filter(|&i| path[i] - path[i - 1] != path[i + 1] - path[i])
        .collect()
}
