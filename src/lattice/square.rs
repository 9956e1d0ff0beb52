//! The 2D square lattice in a vertical plane (seeds 002 and 003).
//!
//! Cell `(x, y)` (stored with `z = 0`) has its centre at `(x·d, y·d, 0)`;
//! gravity is `−y`. Connectors: 0 `+x` (East), 1 `+y` (North), 2 `−x` (West),
//! 3 `−y` (South). Moves are sliding-square moves: a straight slide along a
//! wall of two modules (or along the ground), or a diagonal (corner) move
//! around a pivot at the corner through the free adjacent cell.

use super::moves::wall_slide;
use super::{Cell, Lattice, LatticeKind, Motion, MoveError, MoveRequirements, OffLattice};
use glam::DVec3;

const DIRS: [Cell; 4] = [
    Cell::xy(1, 0),
    Cell::xy(0, 1),
    Cell::xy(-1, 0),
    Cell::xy(0, -1),
];

/// The vertical 2D square lattice (unit spacing).
#[derive(Copy, Clone, Debug, Default)]
pub struct SquareLattice;

impl Lattice for SquareLattice {
    fn kind(&self) -> LatticeKind {
        LatticeKind::Square
    }

    fn connector_count(&self) -> usize {
        4
    }

    fn neighbour(&self, c: Cell, dir: usize) -> Cell {
        c + DIRS[dir]
    }

    fn centre(&self, c: Cell) -> DVec3 {
        DVec3::new(c.x as f64, c.y as f64, 0.0)
    }

    fn gravity(&self) -> DVec3 {
        DVec3::new(0.0, -1.0, 0.0)
    }

    fn layer(&self, c: Cell) -> i32 {
        c.y
    }

    fn check_cell(&self, c: Cell) -> Result<(), OffLattice> {
        if c.z == 0 {
            Ok(())
        } else {
            Err(OffLattice {
                cell: c,
                reason: "not in the plane of the 2D square lattice (z must be 0)",
            })
        }
    }

    fn move_requirements(&self, motion: &Motion) -> Result<MoveRequirements, MoveError> {
        let Motion::Slide { from, to, pivot } = *motion else {
            return Err(MoveError::Unsupported(motion.name(), "square"));
        };
        let d = to - from;
        if d.z != 0 || from.z != 0 {
            return Err(MoveError::NotAMove(format!(
                "{from} → {to} leaves the plane"
            )));
        }
        if d.l1() == 1 {
            return wall_slide(from, to, pivot, Cell::xy(0, -1));
        }
        if d.x.abs() == 1 && d.y.abs() == 1 {
            // The two cells adjacent to both ends: one holds the pivot, the
            // other is the free cell the corner move sweeps through.
            let a = Cell::xy(to.x, from.y);
            let b = Cell::xy(from.x, to.y);
            let Some(p) = pivot else {
                return Err(MoveError::NotAMove(format!(
                    "diagonal move {from} → {to} needs a pivot at {a} or {b}"
                )));
            };
            let via = if p == a {
                b
            } else if p == b {
                a
            } else {
                return Err(MoveError::NotAMove(format!(
                    "pivot cell {p} is not at a corner of the diagonal move {from} → {to} ({a} or {b})"
                )));
            };
            return Ok(MoveRequirements {
                supports: vec![p],
                pass_through: vec![via],
                occupied: vec![],
            });
        }
        Err(MoveError::NotAMove(format!(
            "{from} → {to} is neither an adjacent nor a diagonal move"
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbours_are_the_four_unit_steps() {
        let l = SquareLattice;
        let c = Cell::xy(3, 4);
        for n in l.neighbours(c) {
            assert_eq!((l.centre(n) - l.centre(c)).length(), 1.0);
        }
        assert_eq!(l.neighbours(c).len(), 4);
        assert!(l.check_cell(Cell::new(0, 0, 1)).is_err());
    }

    #[test]
    fn corner_move_passes_through_the_free_adjacent_cell() {
        let l = SquareLattice;
        let m = Motion::Slide {
            from: Cell::xy(2, 2),
            to: Cell::xy(1, 1),
            pivot: Some(Cell::xy(2, 1)),
        };
        let r = l.move_requirements(&m).unwrap();
        assert_eq!(r.supports, vec![Cell::xy(2, 1)]);
        assert_eq!(r.pass_through, vec![Cell::xy(1, 2)]);
        let bad = Motion::Slide {
            from: Cell::xy(2, 2),
            to: Cell::xy(1, 1),
            pivot: Some(Cell::xy(3, 1)),
        };
        assert!(l.move_requirements(&bad).is_err());
    }

    #[test]
    fn straight_slide_needs_a_wall_on_one_side() {
        let l = SquareLattice;
        let on_ground = Motion::Slide {
            from: Cell::xy(2, 1),
            to: Cell::xy(1, 1),
            pivot: None,
        };
        assert_eq!(
            l.move_requirements(&on_ground).unwrap().supports,
            vec![Cell::xy(2, 0), Cell::xy(1, 0)]
        );
        let along_wall = Motion::Slide {
            from: Cell::xy(2, 3),
            to: Cell::xy(2, 2),
            pivot: Some(Cell::xy(1, 3)),
        };
        assert_eq!(
            l.move_requirements(&along_wall).unwrap().supports,
            vec![Cell::xy(1, 3), Cell::xy(1, 2)]
        );
        let pivot_in_line = Motion::Slide {
            from: Cell::xy(2, 3),
            to: Cell::xy(2, 2),
            pivot: Some(Cell::xy(2, 4)),
        };
        assert!(l.move_requirements(&pivot_in_line).is_err());
        let jump = Motion::Slide {
            from: Cell::xy(0, 1),
            to: Cell::xy(2, 1),
            pivot: None,
        };
        assert!(l.move_requirements(&jump).is_err());
    }
}
