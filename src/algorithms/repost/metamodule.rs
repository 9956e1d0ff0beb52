//! The RePoSt meta-module (Bassil et al., IROS 2022, §IV): a closed loop of
//! 10 catoms over 5 FCC layers (SPARSE) that 10 more catoms can fill
//! (FULL), placed on a cubic lattice of meta-modules.
//!
//! Meta-module `(X, Y, Z)` has its leader at cell `(4X, 3Y − (Z mod 2), 4Z)`
//! and uses the front-back variant when `X + Y` is even, back-front
//! otherwise. The leader sits on an even layer (4Z), so the relative cells
//! below add to it as plain cell coordinates.

use crate::lattice::Cell;
use serde::{Deserialize, Serialize};

/// A meta-module position on the cubic meta-module lattice.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Meta {
    pub x: i32,
    pub y: i32,
    pub z: i32,
}

impl Meta {
    pub const fn new(x: i32, y: i32, z: i32) -> Meta {
        Meta { x, y, z }
    }

    /// The neighbouring meta-module in direction `d`.
    pub fn step(self, d: Direction) -> Meta {
        let (dx, dy, dz) = d.delta();
        Meta::new(self.x + dx, self.y + dy, self.z + dz)
    }

    /// The direction from `self` to an adjacent meta-module, if adjacent.
    pub fn direction_to(self, other: Meta) -> Option<Direction> {
        Direction::ALL.into_iter().find(|d| self.step(*d) == other)
    }

    /// The six face neighbours, in [`Direction::ALL`] order.
    pub fn adjacent(self) -> impl Iterator<Item = Meta> {
        Direction::ALL.into_iter().map(move |d| self.step(d))
    }

    /// The catom–catom connectors between this SPARSE meta-module and
    /// `other`'s (lattice neighbours, one loop in each): one side by side
    /// (along X or Y), four stacked; 0 for meta-modules that do not touch.
    pub fn joints(self, other: Meta) -> usize {
        use crate::lattice::{FccLattice, Lattice};
        let (a, b) = (self.sparse_cells(), other.sparse_cells());
        a.iter()
            .map(|x| {
                b.iter()
                    .filter(|y| FccLattice.are_neighbours(*x, **y))
                    .count()
            })
            .sum()
    }
}

/// The breadth-first spanning tree of the meta-modules `present` from
/// `root` (neighbours in [`Meta::adjacent`] order): the planner's
/// connectivity tree, whose leaves may be dismantled, and the tree the
/// protocol's Go flood builds.
pub struct SpanningTree {
    /// Each reached meta-module's level (the root's is 0).
    pub depth: rustc_hash::FxHashMap<Meta, usize>,
    /// Each reached meta-module but the root → its parent.
    pub parent: rustc_hash::FxHashMap<Meta, Meta>,
    /// How many children each has (leaves have none, and no entry).
    pub children: rustc_hash::FxHashMap<Meta, usize>,
}

pub fn spanning_tree(present: impl Fn(&Meta) -> bool, root: Meta) -> SpanningTree {
    let mut t = SpanningTree {
        depth: rustc_hash::FxHashMap::from_iter([(root, 0)]),
        parent: rustc_hash::FxHashMap::default(),
        children: rustc_hash::FxHashMap::default(),
    };
    let mut queue = std::collections::VecDeque::from([root]);
    while let Some(m) = queue.pop_front() {
        for n in m.adjacent() {
            if present(&n) && !t.depth.contains_key(&n) {
                t.depth.insert(n, t.depth[&m] + 1);
                t.parent.insert(n, m);
                *t.children.entry(m).or_default() += 1;
                queue.push_back(n);
            }
        }
    }
    t
}

impl std::fmt::Display for Meta {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "({}, {}, {})", self.x, self.y, self.z)
    }
}

/// The six directions of the meta-module lattice. Right/left are ±X,
/// back/front ±Y, up/down ±Z (the paper names them without fixing axes;
/// this is our choice).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    Up,
    Down,
    Right,
    Left,
    Back,
    Front,
}

impl Direction {
    pub const ALL: [Direction; 6] = [
        Direction::Up,
        Direction::Down,
        Direction::Right,
        Direction::Left,
        Direction::Back,
        Direction::Front,
    ];

    pub fn delta(self) -> (i32, i32, i32) {
        match self {
            Direction::Up => (0, 0, 1),
            Direction::Down => (0, 0, -1),
            Direction::Right => (1, 0, 0),
            Direction::Left => (-1, 0, 0),
            Direction::Back => (0, 1, 0),
            Direction::Front => (0, -1, 0),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Direction::Up => "up",
            Direction::Down => "down",
            Direction::Right => "right",
            Direction::Left => "left",
            Direction::Back => "back",
            Direction::Front => "front",
        }
    }

    pub fn opposite(self) -> Direction {
        match self {
            Direction::Up => Direction::Down,
            Direction::Down => Direction::Up,
            Direction::Right => Direction::Left,
            Direction::Left => Direction::Right,
            Direction::Back => Direction::Front,
            Direction::Front => Direction::Back,
        }
    }

    pub fn is_vertical(self) -> bool {
        matches!(self, Direction::Up | Direction::Down)
    }
}

/// A meta-module cell's state (§IV): three-state cells of the cubic lattice.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum State {
    Empty,
    Sparse,
    Full,
}

/// The two mirror variants of the loop.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Variant {
    FrontBack,
    BackFront,
}

const FRONT_BACK: [(i32, i32, i32); 10] = [
    (0, 0, 0),
    (1, 0, 0),
    (1, 0, 1),
    (2, 1, 2),
    (1, 0, 3),
    (1, 0, 4),
    (0, 0, 4),
    (-1, -1, 3),
    (-1, -1, 2),
    (-1, -1, 1),
];

const BACK_FRONT: [(i32, i32, i32); 10] = [
    (0, 0, 0),
    (1, 0, 0),
    (1, -1, 1),
    (2, -1, 2),
    (1, -1, 3),
    (1, 0, 4),
    (0, 0, 4),
    (-1, 0, 3),
    (-1, 1, 2),
    (-1, 0, 1),
];

/// Filling cells of a FULL meta-module, by variant and parity of Z (facts
/// from the authors' code, checked by the tests below: interior to the
/// lattice of loops, disjoint from every loop and from each other).
const FILL_FB_EVEN: [(i32, i32, i32); 10] = [
    (0, -1, 1),
    (1, -1, 1),
    (0, -1, 2),
    (1, -1, 2),
    (2, -1, 2),
    (0, 0, 1),
    (-1, 0, 1),
    (-1, 0, 2),
    (-1, 0, 3),
    (0, 0, 3),
];
const FILL_BF_EVEN: [(i32, i32, i32); 10] = [
    (-1, -1, 1),
    (0, -1, 1),
    (0, -1, 2),
    (1, -1, 2),
    (-1, 0, 2),
    (0, 0, 1),
    (1, 0, 1),
    (2, 0, 2),
    (1, 0, 3),
    (0, 0, 3),
];
const FILL_FB_ODD: [(i32, i32, i32); 10] = [
    (0, 1, 2),
    (1, 1, 2),
    (-1, 1, 2),
    (-1, 0, 1),
    (0, 0, 1),
    (0, -1, 1),
    (1, -1, 1),
    (2, 0, 2),
    (1, -1, 3),
    (0, -1, 3),
];
const FILL_BF_ODD: [(i32, i32, i32); 10] = [
    (1, 1, 2),
    (0, 1, 2),
    (2, 0, 2),
    (1, 0, 1),
    (0, 0, 1),
    (0, -1, 1),
    (-1, -1, 1),
    (-1, 0, 2),
    (-1, -1, 3),
    (0, -1, 3),
];

impl Meta {
    /// The leader's cell (the bottom-left catom of Fig. 3).
    pub fn leader(self) -> Cell {
        Cell::new(4 * self.x, 3 * self.y - self.z.rem_euclid(2), 4 * self.z)
    }

    pub fn variant(self) -> Variant {
        if (self.x + self.y).rem_euclid(2) == 0 {
            Variant::FrontBack
        } else {
            Variant::BackFront
        }
    }

    fn at(self, rel: &[(i32, i32, i32); 10]) -> [Cell; 10] {
        let l = self.leader();
        rel.map(|(x, y, z)| Cell::new(l.x + x, l.y + y, l.z + z))
    }

    /// The 10 cells of the SPARSE loop, leader first.
    pub fn sparse_cells(self) -> [Cell; 10] {
        match self.variant() {
            Variant::FrontBack => self.at(&FRONT_BACK),
            Variant::BackFront => self.at(&BACK_FRONT),
        }
    }

    /// The 10 cells a FULL meta-module adds to its loop.
    pub fn filling_cells(self) -> [Cell; 10] {
        match (self.variant(), self.z.rem_euclid(2) == 0) {
            (Variant::FrontBack, true) => self.at(&FILL_FB_EVEN),
            (Variant::BackFront, true) => self.at(&FILL_BF_EVEN),
            (Variant::FrontBack, false) => self.at(&FILL_FB_ODD),
            (Variant::BackFront, false) => self.at(&FILL_BF_ODD),
        }
    }

    /// Every cell of the meta-module in `state`.
    pub fn cells(self, state: State) -> Vec<Cell> {
        match state {
            State::Empty => Vec::new(),
            State::Sparse => self.sparse_cells().to_vec(),
            State::Full => {
                let mut v = self.sparse_cells().to_vec();
                v.extend(self.filling_cells());
                v
            }
        }
    }

    /// The meta-module whose loop or filling holds `c`, if any (searched
    /// among the meta-modules whose leader is within reach).
    pub fn owner(c: Cell) -> Option<(Meta, bool)> {
        let (x0, y0, z0) = (c.x.div_euclid(4), c.y.div_euclid(3), c.z.div_euclid(4));
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let m = Meta::new(x0 + dx, y0 + dy, z0 + dz);
                    if m.sparse_cells().contains(&c) {
                        return Some((m, false));
                    }
                    if m.filling_cells().contains(&c) {
                        return Some((m, true));
                    }
                }
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::{FccLattice, Lattice};
    use std::collections::BTreeSet;

    #[test]
    fn a_sparse_loop_is_a_closed_chain_of_ten_latched_catoms() {
        let l = FccLattice;
        for m in [Meta::new(0, 0, 0), Meta::new(1, 0, 0), Meta::new(0, 1, 1)] {
            let c = m.sparse_cells();
            // Each catom latches its two loop neighbours (in listing order).
            for i in 0..10 {
                assert!(l.are_neighbours(c[i], c[(i + 1) % 10]), "{m} {i}");
            }
        }
    }

    #[test]
    fn a_full_block_of_27_meta_modules_holds_540_distinct_cells() {
        let mut all = BTreeSet::new();
        for x in 0..3 {
            for y in 0..3 {
                for z in 0..3 {
                    all.extend(Meta::new(x, y, z).cells(State::Full));
                }
            }
        }
        assert_eq!(all.len(), 540);
    }

    #[test]
    fn adjacent_meta_modules_latch_and_owners_are_found() {
        let l = FccLattice;
        let m = Meta::new(1, 1, 1);
        for d in Direction::ALL {
            let n = m.step(d);
            let touch = m
                .sparse_cells()
                .iter()
                .any(|a| n.sparse_cells().iter().any(|b| l.are_neighbours(*a, *b)));
            assert!(touch, "{m} {d:?}");
        }
        for c in m.sparse_cells() {
            assert_eq!(Meta::owner(c), Some((m, false)));
        }
        for c in m.filling_cells() {
            assert_eq!(Meta::owner(c), Some((m, true)));
        }
    }
}
