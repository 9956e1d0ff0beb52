//! Rule 1 of seed 002, the docking rule: "a module can dock on a cell only
//! if there is no two adjacent cells in symmetrically opposed planes to
//! that cell that are occupied". On the square lattice, as the authors
//! implemented it (`neighborRestriction.cpp`): a cell is blocked when its
//! west and east neighbours are both occupied, or its south and north
//! neighbours are.
//!
//! This is the planner's rule. Certification never uses it: it judges a
//! docking by the exact geometry of its final approach
//! (`geometry::docking`).

use crate::lattice::{Cell, FccLattice, Lattice, fcc};

/// Whether Rule 1 forbids docking at `(x, y)`, given which cells are
/// occupied.
pub fn blocked_2d(occupied: &dyn Fn(i32, i32) -> bool, x: i32, y: i32) -> bool {
    (occupied(x - 1, y) && occupied(x + 1, y)) || (occupied(x, y - 1) && occupied(x, y + 1))
}

/// Whether Rule 1 forbids docking at FCC cell `p`, as the authors coded
/// it in 3D: (a) the 2D rule in `p`'s layer (its in-plane neighbours
/// `(±1, 0)` and `(0, ±1)`), or (b) through each of the three planes
/// through `p` — horizontal, x = const and y = const — an occupied
/// neighbour lies strictly on either side (below against above; world
/// x > 0 against x < 0, the ±y neighbours ignored; likewise for y).
pub fn blocked_fcc(occupied: &dyn Fn(Cell) -> bool, p: Cell) -> bool {
    let in_plane = |x: i32, y: i32| occupied(Cell::new(x, y, p.z));
    if blocked_2d(&in_plane, p.x, p.y) {
        return true;
    }
    let mut sides = [[false; 2]; 3];
    for (k, u) in fcc::directions().iter().enumerate() {
        if !occupied(FccLattice.neighbour(p, k)) {
            continue;
        }
        for (axis, v) in [u.z, u.x, u.y].into_iter().enumerate() {
            if v > 1e-9 {
                sides[axis][0] = true;
            } else if v < -1e-9 {
                sides[axis][1] = true;
            }
        }
    }
    sides.iter().all(|s| s[0] && s[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn in_fcc_the_layer_rule_or_three_sandwiching_planes_block() {
        let p = Cell::new(0, 0, 0);
        let occ = |cells: Vec<Cell>| move |c: Cell| cells.contains(&c);
        // (a) west and east in the layer.
        assert!(blocked_fcc(
            &occ(vec![Cell::new(-1, 0, 0), Cell::new(1, 0, 0)]),
            p
        ));
        // A neighbour below and one above on opposite x and y sides
        // sandwich all three planes.
        let below = FccLattice.neighbour(
            p,
            (0..12)
                .find(|&k| {
                    let u = fcc::direction(k);
                    u.z < 0.0 && u.x < 0.0 && u.y < 0.0
                })
                .unwrap(),
        );
        let above = FccLattice.neighbour(
            p,
            (0..12)
                .find(|&k| {
                    let u = fcc::direction(k);
                    u.z > 0.0 && u.x > 0.0 && u.y > 0.0
                })
                .unwrap(),
        );
        assert!(blocked_fcc(&occ(vec![below, above]), p));
        // Below only (a finished plane under p): never blocked.
        let all_below: Vec<Cell> = FccLattice
            .neighbours(p)
            .into_iter()
            .filter(|c| c.z < 0)
            .collect();
        assert!(!blocked_fcc(&occ(all_below), p));
    }

    #[test]
    fn opposite_neighbours_block_and_a_corner_does_not() {
        let occ = |cells: &'static [(i32, i32)]| move |x: i32, y: i32| cells.contains(&(x, y));
        assert!(blocked_2d(&occ(&[(-1, 0), (1, 0)]), 0, 0));
        assert!(blocked_2d(&occ(&[(0, -1), (0, 1)]), 0, 0));
        assert!(!blocked_2d(&occ(&[(-1, 0), (0, 1)]), 0, 0));
        assert!(!blocked_2d(&occ(&[(1, 1), (-1, -1), (1, 0)]), 0, 0));
    }
}
