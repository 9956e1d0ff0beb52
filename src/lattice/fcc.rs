//! The face-centred cubic lattice of 3D Catoms (SPEC §1).
//!
//! Cell `(i, j, k)` has its centre at
//! `((i + (k mod 2)/2)·d, (j + (k mod 2)/2)·d, k·d/√2)`: horizontal square
//! layers stacked with a half-cell offset on odd layers, world `z` up.
//!
//! Connector (direction) numbering, used in reports and rule tables:
//!
//! | id | direction            | id | direction             |
//! |----|----------------------|----|-----------------------|
//! | 0  | `(+1, 0, 0)`         | 6  | `(−½, −½, +1/√2)`     |
//! | 1  | `(0, +1, 0)`         | 7  | `(+½, −½, +1/√2)`     |
//! | 2  | `(−1, 0, 0)`         | 8  | `(+½, +½, −1/√2)`     |
//! | 3  | `(0, −1, 0)`         | 9  | `(−½, +½, −1/√2)`     |
//! | 4  | `(+½, +½, +1/√2)`    | 10 | `(−½, −½, −1/√2)`     |
//! | 5  | `(−½, +½, +1/√2)`    | 11 | `(+½, −½, −1/√2)`     |
//!
//! Direction `k + 6` is opposite to direction `k` for k in 4..6, and `k ± 2`
//! for the horizontal ones; [`opposite`] gives it.

use super::{Cell, Lattice, LatticeKind, Motion, MoveError, MoveRequirements, Route};
use glam::DVec3;

pub const SQRT2: f64 = std::f64::consts::SQRT_2;

/// World-frame sign patterns of the 12 directions: `(sx, sy, sz)` where a
/// horizontal direction has `sz = 0` and unit components, an inclined one
/// has `sx, sy = ±1` meaning ±½ and `sz = ±1` meaning ±1/√2.
const DIRS: [(i32, i32, i32); 12] = [
    (1, 0, 0),
    (0, 1, 0),
    (-1, 0, 0),
    (0, -1, 0),
    (1, 1, 1),
    (-1, 1, 1),
    (-1, -1, 1),
    (1, -1, 1),
    (1, 1, -1),
    (-1, 1, -1),
    (-1, -1, -1),
    (1, -1, -1),
];

/// The FCC lattice of SPEC §1 (unit spacing).
#[derive(Copy, Clone, Debug, Default)]
pub struct FccLattice;

/// Unit vector of connector direction `dir` in the world frame.
pub fn direction(dir: usize) -> DVec3 {
    let (sx, sy, sz) = DIRS[dir];
    if sz == 0 {
        DVec3::new(sx as f64, sy as f64, 0.0)
    } else {
        DVec3::new(0.5 * sx as f64, 0.5 * sy as f64, sz as f64 / SQRT2)
    }
}

/// All 12 unit neighbour directions, in connector order.
pub fn directions() -> [DVec3; 12] {
    std::array::from_fn(direction)
}

/// The connector opposite to `dir`.
pub fn opposite(dir: usize) -> usize {
    let (sx, sy, sz) = DIRS[dir];
    DIRS.iter()
        .position(|&d| d == (-sx, -sy, -sz))
        .expect("every direction has an opposite")
}

/// The 6 "octagonal" (cubic-axis) directions of SPEC §1: `±ẑ`, `±(x̂+ŷ)/√2`,
/// `±(x̂−ŷ)/√2`.
pub fn octagonal_axes() -> [DVec3; 6] {
    let a = 1.0 / SQRT2;
    [
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(0.0, 0.0, -1.0),
        DVec3::new(a, a, 0.0),
        DVec3::new(-a, -a, 0.0),
        DVec3::new(a, -a, 0.0),
        DVec3::new(-a, a, 0.0),
    ]
}

/// The 8 "hexagonal" directions of SPEC §1: `(±√(2/3), 0, ±1/√3)` and
/// `(0, ±√(2/3), ±1/√3)`.
pub fn hexagonal_axes() -> [DVec3; 8] {
    let a = (2.0f64 / 3.0).sqrt();
    let c = 1.0 / 3f64.sqrt();
    [
        DVec3::new(a, 0.0, c),
        DVec3::new(-a, 0.0, c),
        DVec3::new(0.0, a, c),
        DVec3::new(0.0, -a, c),
        DVec3::new(a, 0.0, -c),
        DVec3::new(-a, 0.0, -c),
        DVec3::new(0.0, a, -c),
        DVec3::new(0.0, -a, -c),
    ]
}

/// The axis a rotation passes through, for unit directions `n_f → n_t` from
/// the pivot: the hexagonal or octagonal axis adjacent to both (SPEC §3).
/// `None` if the two directions are not one rotation apart or the route does
/// not exist for that angle.
pub fn rotation_axis(n_f: DVec3, n_t: DVec3, route: Route) -> Option<DVec3> {
    let dot = n_f.dot(n_t);
    let sixty = (dot - 0.5).abs() < 1e-9;
    let ninety = dot.abs() < 1e-9;
    match (route, sixty, ninety) {
        (Route::Hexagonal, true, _) => hexagonal_axes()
            .into_iter()
            .find(|h| h.dot(n_f) > 0.8 && h.dot(n_t) > 0.8),
        (Route::Octagonal, true, _) | (Route::Octagonal, _, true) => octagonal_axes()
            .into_iter()
            .find(|o| o.dot(n_f) > 0.7 && o.dot(n_t) > 0.7),
        _ => None,
    }
}

/// Parity of a layer index (0 for even, 1 for odd), valid for negatives.
fn parity(k: i32) -> i32 {
    k.rem_euclid(2)
}

impl FccLattice {
    /// Converts seed 000's skewed grid `(x, y, z)` (centre
    /// `((x + z/2)·d, (y + z/2)·d, z·d/√2)`) to this crate's cell.
    pub fn from_skewed(x: i32, y: i32, z: i32) -> Cell {
        let h = z.div_euclid(2);
        Cell::new(x + h, y + h, z)
    }

    /// Inverse of [`FccLattice::from_skewed`].
    pub fn to_skewed(c: Cell) -> (i32, i32, i32) {
        let h = c.z.div_euclid(2);
        (c.x - h, c.y - h, c.z)
    }
}

impl Lattice for FccLattice {
    fn kind(&self) -> LatticeKind {
        LatticeKind::Fcc
    }

    fn connector_count(&self) -> usize {
        12
    }

    fn neighbour(&self, c: Cell, dir: usize) -> Cell {
        let (sx, sy, sz) = DIRS[dir];
        if sz == 0 {
            return Cell::new(c.x + sx, c.y + sy, c.z);
        }
        // Half-cell steps: from an even layer (offset 0) a +½ step lands on
        // the same index of the odd layer (offset ½); from an odd layer a +½
        // step lands on index + 1 of the even layer.
        let p = parity(c.z);
        let step = |s: i32| if s > 0 { p } else { p - 1 };
        Cell::new(c.x + step(sx), c.y + step(sy), c.z + sz)
    }

    fn direction_to(&self, a: Cell, b: Cell) -> Option<usize> {
        let dz = b.z - a.z;
        if dz.abs() > 1 {
            return None;
        }
        (0..12).find(|&k| self.neighbour(a, k) == b)
    }

    fn centre(&self, c: Cell) -> DVec3 {
        let off = 0.5 * parity(c.z) as f64;
        DVec3::new(c.x as f64 + off, c.y as f64 + off, c.z as f64 / SQRT2)
    }

    fn gravity(&self) -> DVec3 {
        DVec3::new(0.0, 0.0, -1.0)
    }

    fn layer(&self, c: Cell) -> i32 {
        c.z
    }

    fn move_requirements(&self, motion: &Motion) -> Result<MoveRequirements, MoveError> {
        let Motion::Rotate {
            from,
            to,
            pivot,
            route,
        } = motion
        else {
            return Err(MoveError::Unsupported(motion.name(), "fcc"));
        };
        let f = self.direction_to(*pivot, *from).ok_or_else(|| {
            MoveError::NotAMove(format!(
                "pivot cell {pivot} is not a neighbour of the start cell {from}"
            ))
        })?;
        let t = self.direction_to(*pivot, *to).ok_or_else(|| {
            MoveError::NotAMove(format!(
                "target cell {to} is not a neighbour of the pivot cell {pivot}"
            ))
        })?;
        let (n_f, n_t) = (direction(f), direction(t));
        if rotation_axis(n_f, n_t, *route).is_none() {
            let angle = n_f.dot(n_t).clamp(-1.0, 1.0).acos().to_degrees();
            return Err(MoveError::NotAMove(format!(
                "{from} → {to} is a {angle:.0}° turn about the pivot; a rotation \
                 turns 60° (hexagonal or octagonal route) or 90° (octagonal only), \
                 and this one asks for the {route:?} route"
            )));
        }
        Ok(MoveRequirements {
            supports: vec![*pivot],
            ..Default::default()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_neighbour_is_at_distance_exactly_d() {
        let l = FccLattice;
        for z in -3..3 {
            for x in -2..2 {
                let c = Cell::new(x, 1 - x, z);
                for k in 0..12 {
                    let n = l.neighbour(c, k);
                    let dist = (l.centre(n) - l.centre(c)).length();
                    assert!((dist - 1.0).abs() < 1e-12, "{c} dir {k}: {dist}");
                    let dir = (l.centre(n) - l.centre(c)).normalize();
                    assert!((dir - direction(k)).length() < 1e-12);
                    assert_eq!(l.neighbour(n, opposite(k)), c);
                    assert_eq!(l.direction_to(c, n), Some(k));
                }
            }
        }
    }

    #[test]
    fn odd_layers_are_offset_by_half_a_cell() {
        let l = FccLattice;
        assert_eq!(l.centre(Cell::new(0, 0, 0)), DVec3::ZERO);
        let c = l.centre(Cell::new(0, 0, 1));
        assert!((c - DVec3::new(0.5, 0.5, 1.0 / SQRT2)).length() < 1e-15);
        let c = l.centre(Cell::new(2, -1, -1));
        assert!((c - DVec3::new(2.5, -0.5, -1.0 / SQRT2)).length() < 1e-15);
    }

    #[test]
    fn no_other_cell_is_within_distance_d() {
        let l = FccLattice;
        let c = Cell::new(0, 0, 1);
        let mut count = 0;
        for x in -3..=3 {
            for y in -3..=3 {
                for z in -2..=4 {
                    let o = Cell::new(x, y, z);
                    let dist = (l.centre(o) - l.centre(c)).length();
                    if o != c && dist < 1.0 + 1e-9 {
                        count += 1;
                        assert!(l.are_neighbours(c, o));
                    }
                }
            }
        }
        assert_eq!(count, 12);
    }

    #[test]
    fn skewed_grid_matches_spec_positions() {
        let l = FccLattice;
        for z in -3..4 {
            for x in -2..3 {
                for y in -2..3 {
                    let c = FccLattice::from_skewed(x, y, z);
                    let want = DVec3::new(
                        x as f64 + z as f64 / 2.0,
                        y as f64 + z as f64 / 2.0,
                        z as f64 / SQRT2,
                    );
                    assert!((l.centre(c) - want).length() < 1e-12);
                    assert_eq!(FccLattice::to_skewed(c), (x, y, z));
                }
            }
        }
        // Seed 000's Z branch step (0,0,1) is the world direction (½, ½, 1/√2).
        let a = FccLattice::from_skewed(0, 0, 0);
        let b = FccLattice::from_skewed(0, 0, 1);
        assert_eq!(l.direction_to(a, b), Some(4));
    }

    #[test]
    fn a_pivot_has_48_hexagonal_and_72_octagonal_links() {
        let mut hex = 0;
        let mut oct = 0;
        for f in 0..12 {
            for t in 0..12 {
                let (a, b) = (direction(f), direction(t));
                if rotation_axis(a, b, Route::Hexagonal).is_some() {
                    hex += 1;
                }
                if rotation_axis(a, b, Route::Octagonal).is_some() {
                    oct += 1;
                }
            }
        }
        assert_eq!((hex, oct), (48, 72));
    }

    #[test]
    fn rotations_must_be_sixty_or_ninety_degrees() {
        let l = FccLattice;
        let p = Cell::new(0, 0, 0);
        let from = l.neighbour(p, 0);
        let opposite_cell = l.neighbour(p, 2);
        let m = Motion::Rotate {
            from,
            to: opposite_cell,
            pivot: p,
            route: Route::Octagonal,
        };
        assert!(matches!(
            l.move_requirements(&m),
            Err(MoveError::NotAMove(_))
        ));
        // 90° (+x → +y) exists only as an octagonal rotation.
        let to = l.neighbour(p, 1);
        let hex = Motion::Rotate {
            from,
            to,
            pivot: p,
            route: Route::Hexagonal,
        };
        let oct = Motion::Rotate {
            from,
            to,
            pivot: p,
            route: Route::Octagonal,
        };
        assert!(l.move_requirements(&hex).is_err());
        assert_eq!(l.move_requirements(&oct).unwrap().supports, vec![p]);
    }
}
