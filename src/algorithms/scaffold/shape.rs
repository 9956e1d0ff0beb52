//! Goal shapes, as membership tests on seed 000's skewed grid.
//!
//! Seed 000 writes cells in a skewed grid `(x, y, z)` whose centre is
//! `((x + z/2)·d, (y + z/2)·d, z·d/√2)` (SPEC §1). Shapes answer "is this
//! skewed cell inside?"; the scaffold keeps the skewed frame for its tile
//! arithmetic and converts to the crate's cells with
//! [`FccLattice::from_skewed`](crate::lattice::FccLattice::from_skewed) at
//! the edge.

use glam::DVec3;

/// A cell of seed 000's skewed grid.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Skew {
    pub x: i32,
    pub y: i32,
    pub z: i32,
}

impl Skew {
    pub const fn new(x: i32, y: i32, z: i32) -> Skew {
        Skew { x, y, z }
    }

    /// The cell `o` away from this one.
    pub fn offset(self, o: Skew) -> Skew {
        Skew::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }

    pub fn scale(self, k: i32) -> Skew {
        Skew::new(self.x * k, self.y * k, self.z * k)
    }

    /// World centre in units of d (SPEC §1, skewed frame).
    pub fn world(self) -> DVec3 {
        DVec3::new(
            self.x as f64 + self.z as f64 / 2.0,
            self.y as f64 + self.z as f64 / 2.0,
            self.z as f64 / std::f64::consts::SQRT_2,
        )
    }

    /// The crate's internal cell of this skewed cell.
    pub fn cell(self) -> crate::lattice::Cell {
        crate::lattice::FccLattice::from_skewed(self.x, self.y, self.z)
    }
}

/// A goal shape: which cells of the skewed grid it contains.
pub trait Shape: Send + Sync {
    fn contains(&self, c: Skew) -> bool;
    /// A short description for errors and schedule metadata.
    fn describe(&self) -> String;
}

/// Seed 000 §4's h-pyramid of tiles: layer k holds tiles (i, j) with
/// 0 ≤ i, j < h − k, roots at skewed (b·i, b·j, b·k). As a solid it is the
/// skewed polytope `x, y ≥ 0, x + z ≤ (h−1)b, y + z ≤ (h−1)b, z ≥ 0` — a
/// square pyramid in the world frame whose faces hold the boundary
/// branches exactly (no partial branches: every branch is grown fully or
/// not at all, §4.1).
#[derive(Clone, Debug)]
pub struct Pyramid {
    pub h: u32,
    pub b: u32,
}

impl Shape for Pyramid {
    fn contains(&self, c: Skew) -> bool {
        let top = (self.h as i32 - 1) * self.b as i32;
        c.x >= 0 && c.y >= 0 && c.z >= 0 && c.x + c.z <= top && c.y + c.z <= top
    }
    fn describe(&self) -> String {
        format!("{}-pyramid", self.h)
    }
}

/// Seed 000 §5.3.1's cube of side `l = (h−1)·b + e` modules: world
/// `x, y ∈ [0, l−1]` and skewed layers `0 … l−1` (so its world height is
/// `(l−1)·d/√2`, the paper's `d × d × D` proportion).
#[derive(Clone, Debug)]
pub struct CubeShape {
    pub l: i32,
}

impl Shape for CubeShape {
    fn contains(&self, c: Skew) -> bool {
        let w = c.world();
        let top = (self.l - 1) as f64 + 1e-9;
        c.z >= 0 && c.z < self.l && w.x >= -1e-9 && w.y >= -1e-9 && w.x <= top && w.y <= top
    }
    fn describe(&self) -> String {
        format!("cube of side {}", self.l)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::{FccLattice, Lattice};

    #[test]
    fn skewed_world_centres_match_the_lattice() {
        let c = Skew::new(3, -2, 5);
        let w = FccLattice.centre(c.cell());
        assert!((w - c.world()).length() < 1e-12);
    }

    #[test]
    fn pyramid_faces_contain_boundary_branches_only() {
        let p = Pyramid { h: 3, b: 6 };
        assert!(p.contains(Skew::new(0, 0, 12)), "apex root");
        assert!(!p.contains(Skew::new(1, 0, 12)));
        assert!(p.contains(Skew::new(12, 12, 0)), "far base corner");
        assert!(
            !p.contains(Skew::new(12, 12, 1)),
            "no Z branch out of the far corner"
        );
    }
}
