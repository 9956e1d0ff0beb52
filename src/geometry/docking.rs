//! Final approaches of a docking (seed 002): the lattice moves that can
//! bring a free module into a cell of the structure, and the exact sweep
//! that says whether one of them is clear.
//!
//! A docking is the module's last motion into its cell. On the square
//! lattice the candidates are the sliding-square moves ending in the cell
//! (`lattice::square`): four straight slides from a side neighbour, each
//! along one of two walls, and four corner moves from a diagonal
//! neighbour, each around one of two pivots — 16 in all. Whether an
//! approach is clear is decided by the body geometry: the origin must be
//! free, the move's supports held, and the exact sweep of the mover
//! ([`super::sweep_model`]) must penetrate no module. Rule 1 of the paper
//! is not consulted here; it lives with the generator.

use super::{Contact, ContactKind, SweepInput, Tolerance, sweep_model};
use crate::lattice::config::ModuleId;
use crate::lattice::{Cell, Configuration, Lattice, LatticeKind, Motion};
use rustc_hash::FxHashSet;

/// Cells around a mover's origin whose modules its sweep can touch.
const REACH: i32 = 3;

/// A candidate final approach into a cell.
#[derive(Clone, Debug, PartialEq)]
pub struct Approach {
    /// The cell the module comes from (must be free).
    pub from: Cell,
    /// The cell of the module it holds on to (wall or corner pivot).
    pub pivot: Cell,
    pub motion: Motion,
}

/// Every lattice move that ends in `cell`, on the square lattice (16).
/// Other lattices have none here.
pub fn candidates(lattice: &dyn Lattice, cell: Cell) -> Vec<Approach> {
    let mut out = Vec::new();
    if lattice.kind() != LatticeKind::Square {
        return out;
    }
    let axes = [
        Cell::xy(1, 0),
        Cell::xy(0, 1),
        Cell::xy(-1, 0),
        Cell::xy(0, -1),
    ];
    for d in axes {
        // Straight slide from the side neighbour `cell + d`, along a wall
        // on either side perpendicular to d.
        let from = cell + d;
        for s in axes.iter().filter(|s| s.x * d.x + s.y * d.y == 0) {
            out.push(approach(from, from + *s, cell));
        }
    }
    for (dx, dy) in [(1, 1), (-1, 1), (-1, -1), (1, -1)] {
        // Corner move from the diagonal neighbour around either corner.
        let from = Cell::xy(cell.x + dx, cell.y + dy);
        for pivot in [Cell::xy(cell.x + dx, cell.y), Cell::xy(cell.x, cell.y + dy)] {
            out.push(approach(from, pivot, cell));
        }
    }
    out.retain(|a| lattice.move_requirements(&a.motion).is_ok());
    out
}

fn approach(from: Cell, pivot: Cell, to: Cell) -> Approach {
    Approach {
        from,
        pivot,
        motion: Motion::Slide {
            from,
            to,
            pivot: Some(pivot),
        },
    }
}

/// What stands in the way of one approach.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Obstruction {
    /// Cells that must be free and are not (origin, passage) or whose
    /// module the exact sweep penetrates.
    pub blocking: Vec<Cell>,
    /// Supports the move needs that hold no module.
    pub missing_supports: Vec<Cell>,
}

impl Obstruction {
    pub fn is_clear(&self) -> bool {
        self.blocking.is_empty() && self.missing_supports.is_empty()
    }
}

/// Judges one approach against `config` (the scene before the docking):
/// supports held, origin and passage free, and no penetration along the
/// exact sweep of the mover (sliding contact is allowed, as for any move).
pub fn judge(
    lattice: &'static dyn Lattice,
    config: &Configuration,
    approach: &Approach,
    epsilon: Tolerance,
) -> Obstruction {
    let mut out = Obstruction::default();
    let Ok(req) = lattice.move_requirements(&approach.motion) else {
        out.blocking.push(approach.from);
        return out;
    };
    out.missing_supports = req
        .supports
        .iter()
        .copied()
        .filter(|c| config.is_free(*c))
        .collect();
    for c in std::iter::once(approach.from).chain(req.pass_through.iter().copied()) {
        if !config.is_free(c) && !out.blocking.contains(&c) {
            out.blocking.push(c);
        }
    }
    if !out.blocking.is_empty() {
        return out;
    }
    // The exact sweep, with the mover placed at its origin.
    let Some(model) = sweep_model(lattice.kind()) else {
        return out;
    };
    const MOVER: ModuleId = ModuleId::MAX;
    // Only modules within reach of the sweep matter (the square sweep looks
    // two cells around the mover's origin): a local scene keeps a docking's
    // check independent of the structure's size.
    let mut scene = Configuration::new();
    let f = approach.from;
    let dz = if lattice.kind() == LatticeKind::Square {
        0
    } else {
        REACH
    };
    for dx in -REACH..=REACH {
        for dy in -REACH..=REACH {
            for dz in -dz..=dz {
                let c = Cell::new(f.x + dx, f.y + dy, f.z + dz);
                if let Some(id) = config.at(c) {
                    scene.insert(id, c).expect("one module per cell");
                }
            }
        }
    }
    if scene.insert(MOVER, approach.from).is_err() {
        out.blocking.push(approach.from);
        return out;
    }
    let pivot = config.at(approach.pivot);
    let moves = [(MOVER, pivot, approach.motion.clone())];
    let moving: FxHashSet<ModuleId> = [MOVER].into_iter().collect();
    let input = SweepInput {
        lattice,
        config: &scene,
        moves: &moves,
        moving: &moving,
        epsilon,
        exact: true,
    };
    let contacts: Vec<Contact> = model.check_step(&input);
    for c in contacts.iter().filter(|c| c.kind == ContactKind::Collision) {
        if let Some(cell) = config.cell_of(c.other)
            && !out.blocking.contains(&cell)
        {
            out.blocking.push(cell);
        }
    }
    out
}

/// The clear approaches into `cell` (see [`judge`]), in [`candidates`] order.
pub fn clear_approaches(
    lattice: &'static dyn Lattice,
    config: &Configuration,
    cell: Cell,
    epsilon: Tolerance,
) -> Vec<Approach> {
    candidates(lattice, cell)
        .into_iter()
        .filter(|a| judge(lattice, config, a, epsilon).is_clear())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::SquareLattice;

    fn scene(cells: &[(i32, i32)]) -> Configuration {
        let mut c = Configuration::new();
        for (k, &(x, y)) in cells.iter().enumerate() {
            c.insert(k as ModuleId, Cell::xy(x, y)).unwrap();
        }
        c
    }

    #[test]
    fn a_square_cell_has_sixteen_candidate_approaches() {
        assert_eq!(candidates(&SquareLattice, Cell::xy(0, 0)).len(), 16);
    }

    #[test]
    fn a_cell_beside_one_module_is_reached_around_its_corner() {
        let c = scene(&[(1, 0)]);
        let ok = clear_approaches(&SquareLattice, &c, Cell::xy(0, 0), Tolerance::DEFAULT);
        assert!(ok.iter().any(|a| a.from == Cell::xy(1, 1)), "{ok:?}");
        // A module in the corner's passage blocks that approach.
        let c = scene(&[(1, 0), (0, 1)]);
        let a = candidates(&SquareLattice, Cell::xy(0, 0))
            .into_iter()
            .find(|a| a.from == Cell::xy(1, 1) && a.pivot == Cell::xy(1, 0))
            .unwrap();
        let o = judge(&SquareLattice, &c, &a, Tolerance::DEFAULT);
        assert_eq!(o.blocking, vec![Cell::xy(0, 1)]);
    }
}
