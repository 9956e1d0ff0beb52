//! The simple cubic lattice of seed 004 (atoms, or 2×2×2 meta-modules as
//! cells of a coarser cubic lattice).
//!
//! Cell `(x, y, z)` has its centre at `(x, y, z)·d`, gravity `−z`.
//! Connectors: 0 `+x`, 1 `+y`, 2 `+z`, 3 `−x`, 4 `−y`, 5 `−z`. Moves: SLIDE
//! along a wall (seed 004 §2: the slider is beside a substrate module B, and
//! B's neighbour C in the slide direction is present) and k-TUNNEL.

use super::moves::wall_slide;
use super::{Cell, Lattice, LatticeKind, Motion, MoveError, MoveRequirements};
use glam::DVec3;

const DIRS: [Cell; 6] = [
    Cell::new(1, 0, 0),
    Cell::new(0, 1, 0),
    Cell::new(0, 0, 1),
    Cell::new(-1, 0, 0),
    Cell::new(0, -1, 0),
    Cell::new(0, 0, -1),
];

/// One face of a cubic atom, in connector order (`+x, +y, +z, −x, −y, −z`);
/// written `"+x"` … `"-z"` in schedules.
#[derive(
    Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
pub enum Face {
    #[serde(rename = "+x")]
    PosX,
    #[serde(rename = "+y")]
    PosY,
    #[serde(rename = "+z")]
    PosZ,
    #[serde(rename = "-x")]
    NegX,
    #[serde(rename = "-y")]
    NegY,
    #[serde(rename = "-z")]
    NegZ,
}

impl Face {
    pub const ALL: [Face; 6] = [
        Face::PosX,
        Face::PosY,
        Face::PosZ,
        Face::NegX,
        Face::NegY,
        Face::NegZ,
    ];

    /// The connector index (0..6) of this face.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The outward unit step of the face.
    pub fn dir(self) -> Cell {
        DIRS[self.index()]
    }

    /// The axis (0 x, 1 y, 2 z) the face is normal to.
    pub fn axis(self) -> usize {
        self.index() % 3
    }

    /// +1 for the positive faces, −1 for the negative ones.
    pub fn sign(self) -> i32 {
        if self.index() < 3 { 1 } else { -1 }
    }

    pub fn opposite(self) -> Face {
        Face::ALL[(self.index() + 3) % 6]
    }

    /// The face normal to `axis` with `sign`.
    pub fn of(axis: usize, sign: i32) -> Face {
        Face::ALL[axis + if sign > 0 { 0 } else { 3 }]
    }

    pub fn name(self) -> &'static str {
        ["+x", "+y", "+z", "-x", "-y", "-z"][self.index()]
    }
}

/// How seed 004's atoms rest between moves: the paper's two models.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AtomRest {
    /// Every face contracted: attached atoms are 1 unit apart.
    Contracted,
    /// Every face expanded: attached atoms are 3 units apart (body 1, two arms of 1).
    Expanded,
}

/// The simple cubic lattice (unit spacing).
#[derive(Copy, Clone, Debug, Default)]
pub struct CubicLattice;

impl Lattice for CubicLattice {
    fn kind(&self) -> LatticeKind {
        LatticeKind::Cubic
    }

    fn connector_count(&self) -> usize {
        6
    }

    fn neighbour(&self, c: Cell, dir: usize) -> Cell {
        c + DIRS[dir]
    }

    fn centre(&self, c: Cell) -> DVec3 {
        DVec3::new(c.x as f64, c.y as f64, c.z as f64)
    }

    fn gravity(&self) -> DVec3 {
        DVec3::new(0.0, 0.0, -1.0)
    }

    fn layer(&self, c: Cell) -> i32 {
        c.z
    }

    fn move_requirements(&self, motion: &Motion) -> Result<MoveRequirements, MoveError> {
        match motion {
            Motion::Slide { from, to, pivot } => {
                wall_slide(*from, *to, *pivot, Cell::new(0, 0, -1))
            }
            Motion::Tunnel { path } => {
                if path.len() < 3 {
                    return Err(MoveError::NotAMove(
                        "a tunnel path needs a start, at least one interior cell and an end".into(),
                    ));
                }
                if let Some(w) = path.windows(2).find(|w| (w[1] - w[0]).l1() != 1) {
                    return Err(MoveError::NotAMove(format!(
                        "tunnel path steps from {} to {}, which are not neighbours",
                        w[0], w[1]
                    )));
                }
                let interior = path[1..path.len() - 1].to_vec();
                Ok(MoveRequirements {
                    supports: vec![path[path.len() - 2]],
                    pass_through: vec![],
                    occupied: interior,
                })
            }
            Motion::Rotate { .. } => Err(MoveError::Unsupported("rotate", "cubic")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn six_unit_neighbours() {
        let l = CubicLattice;
        let c = Cell::new(1, -2, 3);
        let n = l.neighbours(c);
        assert_eq!(n.len(), 6);
        for m in n {
            assert_eq!((l.centre(m) - l.centre(c)).length(), 1.0);
        }
    }

    #[test]
    fn tunnel_path_must_be_contiguous() {
        let l = CubicLattice;
        let ok = Motion::Tunnel {
            path: vec![
                Cell::new(0, 0, 1),
                Cell::new(0, 0, 0),
                Cell::new(1, 0, 0),
                Cell::new(1, 0, 1),
            ],
        };
        let r = l.move_requirements(&ok).unwrap();
        assert_eq!(r.occupied, vec![Cell::new(0, 0, 0), Cell::new(1, 0, 0)]);
        let gap = Motion::Tunnel {
            path: vec![Cell::new(0, 0, 1), Cell::new(0, 0, 0), Cell::new(2, 0, 0)],
        };
        assert!(l.move_requirements(&gap).is_err());
    }
}
