//! Integer lattice cells.

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;
use std::ops::{Add, Neg, Sub};

/// A lattice cell in the lattice's own integer coordinates.
///
/// Every lattice uses three integers; the 2D square lattice keeps `z = 0`.
/// In JSON a cell is written `[x, y, z]`; `[x, y]` is accepted as `[x, y, 0]`
/// so that 2D schedules read naturally.
#[derive(Copy, Clone, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct Cell {
    pub x: i32,
    pub y: i32,
    pub z: i32,
}

impl Cell {
    pub const ZERO: Cell = Cell { x: 0, y: 0, z: 0 };

    pub const fn new(x: i32, y: i32, z: i32) -> Cell {
        Cell { x, y, z }
    }

    pub const fn xy(x: i32, y: i32) -> Cell {
        Cell { x, y, z: 0 }
    }

    pub fn to_array(self) -> [i32; 3] {
        [self.x, self.y, self.z]
    }

    /// Manhattan norm, used for adjacency on the square and cubic lattices.
    pub fn l1(self) -> i32 {
        self.x.abs() + self.y.abs() + self.z.abs()
    }

    /// Chebyshev norm (Moore neighbourhood distance).
    pub fn linf(self) -> i32 {
        self.x.abs().max(self.y.abs()).max(self.z.abs())
    }
}

impl Add for Cell {
    type Output = Cell;
    fn add(self, o: Cell) -> Cell {
        Cell::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl Sub for Cell {
    type Output = Cell;
    fn sub(self, o: Cell) -> Cell {
        Cell::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl Neg for Cell {
    type Output = Cell;
    fn neg(self) -> Cell {
        Cell::new(-self.x, -self.y, -self.z)
    }
}

impl fmt::Debug for Cell {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({}, {}, {})", self.x, self.y, self.z)
    }
}

impl fmt::Display for Cell {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self, f)
    }
}

impl Serialize for Cell {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.to_array().serialize(s)
    }
}

impl<'de> Deserialize<'de> for Cell {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Cell, D::Error> {
        let v: Vec<i32> = Vec::deserialize(d)?;
        match v.as_slice() {
            [x, y] => Ok(Cell::xy(*x, *y)),
            [x, y, z] => Ok(Cell::new(*x, *y, *z)),
            _ => Err(serde::de::Error::custom(format!(
                "a cell is [x, y] or [x, y, z], got {} numbers",
                v.len()
            ))),
        }
    }
}
