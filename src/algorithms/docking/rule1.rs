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

/// Whether Rule 1 forbids docking at `(x, y)`, given which cells are
/// occupied.
pub fn blocked_2d(occupied: &dyn Fn(i32, i32) -> bool, x: i32, y: i32) -> bool {
    (occupied(x - 1, y) && occupied(x + 1, y)) || (occupied(x, y - 1) && occupied(x, y + 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn opposite_neighbours_block_and_a_corner_does_not() {
        let occ = |cells: &'static [(i32, i32)]| move |x: i32, y: i32| cells.contains(&(x, y));
        assert!(blocked_2d(&occ(&[(-1, 0), (1, 0)]), 0, 0));
        assert!(blocked_2d(&occ(&[(0, -1), (0, 1)]), 0, 0));
        assert!(!blocked_2d(&occ(&[(-1, 0), (0, 1)]), 0, 0));
        assert!(!blocked_2d(&occ(&[(1, 1), (-1, -1), (1, 0)]), 0, 0));
    }
}
