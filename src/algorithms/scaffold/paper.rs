//! Seed 000 as written: the motion constraint of §3 and the coordination
//! of §3.3.4 (green-light handshake), for `protocol = "paper"`.
//!
//! The paper states one motion constraint besides "rotate on a neighbour's
//! surface, one cell at a time": the *bridging constraint* — a module can
//! neither enter nor leave a cell surrounded by two opposing modules
//! (§3, Fig. 1c). [`BridgingRules`] is that constraint behind the
//! [`MotionRules`] trait, with no blocking cells: the exact catom body's
//! sweep is what `reconfcheck certify` checks afterwards, so that every
//! move the paper's model allows and the body forbids is listed.

use crate::geometry::MotionRules;
use crate::lattice::{Cell, FccLattice, Lattice, Motion};

/// Which coordination the scaffold generator follows.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Default)]
pub enum Protocol {
    /// Ours: motion rules from the exact catom body (blocking cells and
    /// pinches), no free agent next to another before or after a step,
    /// one step's swept cells disjoint. Every schedule is collision-free.
    #[default]
    Safe,
    /// The paper's: the bridging constraint only, and a move is gated by
    /// its light pivot's state (green: no other free agent on it).
    Paper,
}

impl Protocol {
    /// Parses a scenario's `protocol` parameter.
    pub fn parse(s: &str) -> Option<Protocol> {
        match s {
            "safe" => Some(Protocol::Safe),
            "paper" => Some(Protocol::Paper),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Protocol::Safe => "safe",
            Protocol::Paper => "paper",
        }
    }
}

/// The paper's §3 motion constraint (bridging) on the FCC lattice.
pub struct BridgingRules;

/// Whether `c` lies between two opposing occupied cells, the mover's own
/// cells (`skip`) not counted.
fn bridged(c: Cell, skip: [Cell; 2], occupied: &dyn Fn(Cell) -> bool) -> bool {
    let l = FccLattice;
    let occ = |q: Cell| !skip.contains(&q) && occupied(q);
    (0..12).any(|k| {
        let o = crate::lattice::fcc::opposite(k);
        k < o && occ(l.neighbour(c, k)) && occ(l.neighbour(c, o))
    })
}

impl MotionRules for BridgingRules {
    /// The paper names no swept cells: only the bridging constraint.
    fn blocking_cells(&self, _motion: &Motion) -> Vec<Cell> {
        Vec::new()
    }

    /// Nor any touched cells: the paper's model has no body to touch with.
    fn touched_cells(&self, _motion: &Motion) -> Vec<Cell> {
        Vec::new()
    }

    /// Concurrent moves are coordinated by the light handshake (the
    /// planner's gate), not by geometry: the rules alone never part them.
    fn concurrent_clear(&self, _a: &Motion, _b: &Motion) -> bool {
        true
    }

    fn allows(&self, motion: &Motion, occupied: &dyn Fn(Cell) -> bool) -> bool {
        let (from, to) = (motion.from(), motion.to());
        !bridged(from, [from, to], occupied) && !bridged(to, [from, to], occupied)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::Route;

    #[test]
    fn a_cell_between_two_opposing_modules_can_be_neither_entered_nor_left() {
        let l = FccLattice;
        let to = Cell::new(0, 0, 0);
        let pivot = l.neighbour(to, 0);
        // A `from` cell next to both `to` and the pivot.
        let from = (0..12)
            .map(|k| l.neighbour(to, k))
            .find(|&c| c != pivot && l.are_neighbours(c, pivot))
            .unwrap();
        let m = Motion::Rotate {
            from,
            to,
            pivot,
            route: Route::Octagonal,
        };
        let only_pivot = |c: Cell| c == pivot;
        assert!(BridgingRules.allows(&m, &only_pivot));
        // Opposite pair around `to` that involves neither mover cell.
        let (a, b) = (0..12)
            .map(|k| {
                (
                    l.neighbour(to, k),
                    l.neighbour(to, crate::lattice::fcc::opposite(k)),
                )
            })
            .find(|&(a, b)| ![from, pivot].contains(&a) && ![from, pivot].contains(&b))
            .unwrap();
        let pair = |c: Cell| c == pivot || c == a || c == b;
        assert!(!BridgingRules.allows(&m, &pair), "entering a bridged cell");
        let back = Motion::Rotate {
            from: to,
            to: from,
            pivot,
            route: Route::Octagonal,
        };
        assert!(
            !BridgingRules.allows(&back, &pair),
            "leaving a bridged cell"
        );
        // The mover's own start cell never counts as one of a pair.
        let k = (0..12).find(|&k| l.neighbour(to, k) == from).unwrap();
        let opp = l.neighbour(to, crate::lattice::fcc::opposite(k));
        let with_from = |c: Cell| c == pivot || c == from || c == opp;
        assert!(BridgingRules.allows(&m, &with_from));
    }
}
