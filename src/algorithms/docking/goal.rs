//! Goal shapes of the 2D docking planner: a set of square-lattice cells,
//! stored as a bitmap over its bounding box (with a margin, so that every
//! neighbour lookup of a goal cell stays inside).
//!
//! Shapes are read from the project's CSG files (`scaffold::csg`), sliced
//! at a height `z` and scaled: cell `(x, y)` is in the goal when the point
//! `(x / scale, y / scale, z)` lies in the solid — the paper's shapes are
//! CSG trees of cylinders along z and boxes (seed 002 §4), so the slice is
//! their 2D drawing.

use crate::algorithms::scaffold::csg::CsgShape;
use crate::error::InputError;
use glam::DVec3;
use std::collections::VecDeque;
use std::path::Path;

/// Margin of empty cells kept around the goal's bounding box.
const MARGIN: i32 = 2;
/// Largest side of a 2D goal, in cells.
pub const MAX_SIDE: i32 = 4096;

/// A 2D goal shape.
#[derive(Clone, Debug)]
pub struct Goal {
    pub name: String,
    x0: i32,
    y0: i32,
    w: i32,
    h: i32,
    cells: Vec<bool>,
    count: usize,
}

impl Goal {
    /// A goal from a list of cells (non-empty, validated by [`Goal::validate`]).
    pub fn from_cells(name: &str, cells: &[(i32, i32)]) -> Result<Goal, InputError> {
        let Some(&(fx, fy)) = cells.first() else {
            return Err(InputError::new(format!(
                "goal '{name}' has no cell: there is no cell for the seed"
            )));
        };
        let (mut lx, mut ly, mut hx, mut hy) = (fx, fy, fx, fy);
        for &(x, y) in cells {
            lx = lx.min(x);
            ly = ly.min(y);
            hx = hx.max(x);
            hy = hy.max(y);
        }
        let lim = crate::schedule::MAX_COORDINATE - MARGIN;
        if [lx, ly, hx, hy].iter().any(|v| v.abs() > lim) {
            return Err(InputError::new(format!(
                "goal '{name}' lies off the lattice: cells beyond ±{lim}"
            )));
        }
        if hx - lx >= MAX_SIDE || hy - ly >= MAX_SIDE {
            return Err(InputError::new(format!(
                "goal '{name}' is {}×{} cells, more than {MAX_SIDE} on a side",
                hx - lx + 1,
                hy - ly + 1
            )));
        }
        let (x0, y0) = (lx - MARGIN, ly - MARGIN);
        let (w, h) = (hx - lx + 1 + 2 * MARGIN, hy - ly + 1 + 2 * MARGIN);
        let mut g = Goal {
            name: name.to_string(),
            x0,
            y0,
            w,
            h,
            cells: vec![false; (w * h) as usize],
            count: 0,
        };
        for &(x, y) in cells {
            let i = g.index(x, y).expect("inside the box");
            if !g.cells[i] {
                g.cells[i] = true;
                g.count += 1;
            }
        }
        Ok(g)
    }

    /// The slice at height `z` of a CSG file, scaled by `scale`.
    pub fn from_csg(path: &Path, scale: f64, z: f64) -> Result<Goal, InputError> {
        let shape = CsgShape::load(path)?;
        Goal::from_csg_shape(&shape, scale, z).map_err(|e| e.in_file(path))
    }

    /// The slice at height `z` of a parsed CSG shape, scaled by `scale`.
    pub fn from_csg_shape(shape: &CsgShape, scale: f64, z: f64) -> Result<Goal, InputError> {
        if !(scale.is_finite() && scale > 0.0 && z.is_finite()) {
            return Err(InputError::new(format!(
                "scale {scale} and slice height {z} must be finite, the scale positive"
            )));
        }
        let (lo, hi) = shape.root.bounds();
        let (lo, hi) = (lo * scale, hi * scale);
        let lim = (crate::schedule::MAX_COORDINATE - MARGIN) as f64;
        if [lo.x, lo.y, hi.x, hi.y]
            .iter()
            .any(|v| !v.is_finite() || v.abs() > lim)
        {
            return Err(InputError::new(format!(
                "goal '{}' lies off the lattice: its extent [{}, {}] × [{}, {}] passes ±{lim}",
                shape.name, lo.x, hi.x, lo.y, hi.y
            )));
        }
        if hi.x - lo.x >= MAX_SIDE as f64 || hi.y - lo.y >= MAX_SIDE as f64 {
            return Err(InputError::new(format!(
                "goal '{}' is more than {MAX_SIDE} cells on a side",
                shape.name
            )));
        }
        let mut cells = Vec::new();
        for y in (lo.y.floor() as i32 - 1)..=(hi.y.ceil() as i32 + 1) {
            for x in (lo.x.floor() as i32 - 1)..=(hi.x.ceil() as i32 + 1) {
                let p = DVec3::new(x as f64 / scale, y as f64 / scale, z);
                if shape.root.contains(p) {
                    cells.push((x, y));
                }
            }
        }
        if cells.is_empty() {
            return Err(InputError::new(format!(
                "goal '{}' has no cell at z = {z}, scale {scale}: there is no cell for the seed",
                shape.name
            )));
        }
        Goal::from_cells(&shape.name, &cells)
    }

    fn index(&self, x: i32, y: i32) -> Option<usize> {
        let (i, j) = (x - self.x0, y - self.y0);
        (i >= 0 && j >= 0 && i < self.w && j < self.h).then(|| (j * self.w + i) as usize)
    }

    /// Whether `(x, y)` is a goal cell.
    pub fn contains(&self, x: i32, y: i32) -> bool {
        self.index(x, y).is_some_and(|i| self.cells[i])
    }

    /// Number of goal cells.
    pub fn len(&self) -> usize {
        self.count
    }

    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The box (with margin) as (x0, y0, width, height).
    pub fn frame(&self) -> (i32, i32, i32, i32) {
        (self.x0, self.y0, self.w, self.h)
    }

    /// Every goal cell, row by row from the bottom, west to east.
    pub fn cells(&self) -> Vec<(i32, i32)> {
        let mut v = Vec::with_capacity(self.count);
        for j in 0..self.h {
            for i in 0..self.w {
                if self.cells[(j * self.w + i) as usize] {
                    v.push((self.x0 + i, self.y0 + j));
                }
            }
        }
        v
    }

    /// Refuses a goal the planner cannot build: one that is not a single
    /// 4-connected piece (a docking module latches to a side neighbour).
    pub fn validate(&self) -> Result<(), InputError> {
        let cells = self.cells();
        let Some(&start) = cells.first() else {
            return Err(InputError::new(format!(
                "goal '{}' has no cell: there is no cell for the seed",
                self.name
            )));
        };
        let reached = self.reach(start, |x, y| self.contains(x, y));
        if reached < self.count {
            return Err(InputError::new(format!(
                "goal '{}' is disconnected: {} of its {} cells are not side-connected to {:?}",
                self.name,
                self.count - reached,
                self.count,
                start
            )));
        }
        Ok(())
    }

    /// Number of cells 4-reachable from `start` through cells that pass `ok`.
    fn reach(&self, start: (i32, i32), ok: impl Fn(i32, i32) -> bool) -> usize {
        let mut seen = vec![false; self.cells.len()];
        let mut queue = VecDeque::from([start]);
        seen[self.index(start.0, start.1).expect("inside")] = true;
        let mut n = 0;
        while let Some((x, y)) = queue.pop_front() {
            n += 1;
            for (dx, dy) in [(1, 0), (0, 1), (-1, 0), (0, -1)] {
                let (a, b) = (x + dx, y + dy);
                if let Some(i) = self.index(a, b)
                    && !seen[i]
                    && ok(a, b)
                {
                    seen[i] = true;
                    queue.push_back((a, b));
                }
            }
        }
        n
    }

    /// For every cell of the box: whether it is a non-goal cell enclosed by
    /// the goal (an internal hole), found by flooding the complement from
    /// the box's border, 8-connected (the digital dual of the goal's
    /// 4-connectivity: a gap between two diagonal cells lets the outside in).
    pub fn internal_holes(&self) -> Vec<bool> {
        let mut outside = vec![false; self.cells.len()];
        let mut queue = VecDeque::new();
        for j in 0..self.h {
            for i in 0..self.w {
                if i == 0 || j == 0 || i == self.w - 1 || j == self.h - 1 {
                    let k = (j * self.w + i) as usize;
                    outside[k] = true;
                    queue.push_back((i, j));
                }
            }
        }
        while let Some((i, j)) = queue.pop_front() {
            for di in -1..=1 {
                for dj in -1..=1 {
                    let (a, b) = (i + di, j + dj);
                    if a < 0 || b < 0 || a >= self.w || b >= self.h {
                        continue;
                    }
                    let k = (b * self.w + a) as usize;
                    if !outside[k] && !self.cells[k] {
                        outside[k] = true;
                        queue.push_back((a, b));
                    }
                }
            }
        }
        (0..self.cells.len())
            .map(|k| !self.cells[k] && !outside[k])
            .collect()
    }

    /// Index of a cell of the box, for per-cell tables of the planner.
    pub fn slot(&self, x: i32, y: i32) -> Option<usize> {
        self.index(x, y)
    }

    /// The cell of a slot.
    pub fn cell_of_slot(&self, k: usize) -> (i32, i32) {
        let k = k as i32;
        (self.x0 + k % self.w, self.y0 + k / self.w)
    }

    /// Number of slots (cells of the box).
    pub fn slots(&self) -> usize {
        self.cells.len()
    }

    /// The goal cell nearest the centroid of the goal (ties: lowest, then
    /// westmost) — the paper starts from a seed "relative to the middle".
    pub fn central_cell(&self) -> (i32, i32) {
        let cells = self.cells();
        let n = cells.len() as f64;
        let cx = cells.iter().map(|c| c.0 as f64).sum::<f64>() / n;
        let cy = cells.iter().map(|c| c.1 as f64).sum::<f64>() / n;
        *cells
            .iter()
            .min_by(|a, b| {
                let da = (a.0 as f64 - cx).powi(2) + (a.1 as f64 - cy).powi(2);
                let db = (b.0 as f64 - cx).powi(2) + (b.1 as f64 - cy).powi(2);
                da.total_cmp(&db)
            })
            .expect("a validated goal has cells")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ring_has_an_internal_hole_and_a_c_has_none() {
        let mut ring = Vec::new();
        for x in 0..5 {
            for y in 0..5 {
                if !(x == 2 && y == 2) {
                    ring.push((x, y));
                }
            }
        }
        let g = Goal::from_cells("ring", &ring).unwrap();
        let holes = g.internal_holes();
        assert!(holes[g.slot(2, 2).unwrap()]);
        let c: Vec<_> = ring.into_iter().filter(|&(x, y)| x != 2 || y < 3).collect();
        let g = Goal::from_cells("c", &c).unwrap();
        assert!(g.internal_holes().iter().all(|h| !h));
    }

    #[test]
    fn a_disconnected_goal_is_refused() {
        let g = Goal::from_cells("two", &[(0, 0), (2, 0)]).unwrap();
        let e = g.validate().unwrap_err();
        assert!(e.message.contains("disconnected"), "{e}");
    }
}
