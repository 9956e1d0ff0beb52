//! Sequential active subtraction (seed 003 §III-A): the leader's choice of
//! the next excluded module (Alg. 1) and the active module's walk to the
//! sink with dynamic prioritisation (Alg. 2).

use super::shape::{Shape, neighbours4, xy};
use crate::error::InputError;
use crate::lattice::Cell;

/// The sink of seed 003 §II, at ground level West of the rectangle.
pub const SINK: Cell = Cell::xy(0, 1);

/// A direction of the Moore neighbourhood, numbered clockwise from South
/// as Alg. 2 probes them: S, SW, W, NW, N, NE, E, SE. `d + 1` is the next
/// direction clockwise.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub struct Dir(u8);

const VECTORS: [(i32, i32); 8] = [
    (0, -1),
    (-1, -1),
    (-1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
    (1, 0),
    (1, -1),
];
const NAMES: [&str; 8] = ["S", "SW", "W", "NW", "N", "NE", "E", "SE"];

impl Dir {
    pub const S: Dir = Dir(0);
    pub const W: Dir = Dir(2);

    /// The direction `k` steps clockwise (negative: counter-clockwise).
    pub fn turn(self, k: i32) -> Dir {
        Dir((self.0 as i32 + k).rem_euclid(8) as u8)
    }

    pub fn is_diagonal(self) -> bool {
        self.0 % 2 == 1
    }

    pub fn step(self, c: Cell) -> Cell {
        let (dx, dy) = VECTORS[self.0 as usize];
        Cell::xy(c.x + dx, c.y + dy)
    }

    pub fn name(self) -> &'static str {
        NAMES[self.0 as usize]
    }

    /// The direction of a one-cell move `from → to` (Moore neighbours).
    pub fn between(from: Cell, to: Cell) -> Option<Dir> {
        let d = (to.x - from.x, to.y - from.y);
        VECTORS.iter().position(|&v| v == d).map(|k| Dir(k as u8))
    }
}

/// Alg. 2, one decision: the direction an active module at `p` moves next,
/// given the direction `last` it moved before (`None` when it has just been
/// activated) and which cells are occupied (modules or ground).
///
/// The probing order is `S_D = {D−2, …, D+5}` (line 17); the initial order
/// `{S, SW, …, SE}` (line 1) is the same rule with `D = W`. An adjacent
/// direction needs its cell empty; a diagonal `d` also needs `d + 1` empty,
/// the adjacent cell it passes through (line 9). `None`: boxed in.
pub fn next_direction(p: Cell, last: Option<Dir>, occupied: &dyn Fn(Cell) -> bool) -> Option<Dir> {
    let first = last.unwrap_or(Dir::W).turn(-2);
    (0..8)
        .map(|k| first.turn(k))
        .find(|&d| !occupied(d.step(p)) && (!d.is_diagonal() || !occupied(d.turn(1).step(p))))
}

/// Occupancy of the plane during active subtraction: the rectangle's
/// modules (a dense grid with a margin of free space), ground below `y = 1`.
#[derive(Clone, Debug)]
pub struct Occupancy {
    x0: i32,
    w: i32,
    h: i32,
    cells: Vec<bool>,
}

/// Free space kept around the rectangle; active modules never leave the
/// Moore neighbourhood of the structure, so one cell would do.
const MARGIN: i32 = 2;

impl Occupancy {
    /// The full initial rectangle of `shape`.
    pub fn full(shape: &Shape) -> Occupancy {
        let x0 = 1 - MARGIN;
        let w = shape.width + 2 * MARGIN;
        let h = shape.height + MARGIN;
        let mut o = Occupancy {
            x0,
            w,
            h,
            cells: vec![false; (w * h) as usize],
        };
        for c in shape.cells() {
            o.set(c, true);
        }
        o
    }

    fn index(&self, c: Cell) -> Option<usize> {
        let (i, j) = (c.x - self.x0, c.y - 1);
        (i >= 0 && j >= 0 && i < self.w && j < self.h).then(|| (j * self.w + i) as usize)
    }

    /// Whether `c` holds a module or is ground.
    pub fn occupied(&self, c: Cell) -> bool {
        c.y < 1 || self.index(c).is_some_and(|k| self.cells[k])
    }

    /// Whether `c` is inside the tracked area (rectangle plus margin).
    pub fn tracked(&self, c: Cell) -> bool {
        c.y < 1 || self.index(c).is_some()
    }

    pub fn set(&mut self, c: Cell, on: bool) {
        let k = self.index(c).expect("cell inside the tracked area");
        self.cells[k] = on;
    }
}

/// One excluded module's removal: its start cell and the cells it passes,
/// from the start cell (first) to the sink (last). `Δ = cells.len() − 1`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Removal {
    pub cells: Vec<Cell>,
}

impl Removal {
    pub fn start(&self) -> Cell {
        self.cells[0]
    }

    /// Δ: the number of moves (time steps) the module is active.
    pub fn duration(&self) -> usize {
        self.cells.len() - 1
    }

    /// The direction of each move.
    pub fn directions(&self) -> impl Iterator<Item = Dir> + '_ {
        self.cells
            .windows(2)
            .map(|w| Dir::between(w[0], w[1]).expect("moves are one cell"))
    }
}

/// A SAS run: the removals in the order the modules reach the sink (φ).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SasRun {
    pub removals: Vec<Removal>,
}

impl SasRun {
    /// SAS reconfiguration time: one module moves at a time, `Σ Δ_i`.
    pub fn time_steps(&self) -> usize {
        self.removals.iter().map(Removal::duration).sum()
    }
}

/// Alg. 1's choice among the remaining excluded modules: the highest layer
/// holding one with a free connector (`F_v > 0`), then the most westerly.
fn choose(excluded: &[Cell], occ: &Occupancy) -> Option<usize> {
    let free_face = |c: Cell| neighbours4(c).iter().any(|&n| !occ.occupied(n));
    excluded
        .iter()
        .enumerate()
        .filter(|&(_, &c)| free_face(c))
        .max_by_key(|&(_, &c)| (c.y, -c.x))
        .map(|(k, _)| k)
}

/// Walks one active module from `start` to the sink with Alg. 2 (the module
/// itself must already be lifted out of `occ`). Bounded by Theorem 5's
/// perimeter argument, with room to spare; an error names the start cell.
pub fn walk(
    start: Cell,
    occ: &dyn Fn(Cell) -> bool,
    tracked: &dyn Fn(Cell) -> bool,
    bound: usize,
) -> Result<Removal, InputError> {
    let mut cells = vec![start];
    let mut p = start;
    let mut last = None;
    while p != SINK {
        if cells.len() > bound {
            return Err(InputError::new(format!(
                "the module from {start} did not reach the sink within {bound} moves"
            )));
        }
        let Some(d) = next_direction(p, last, occ) else {
            return Err(InputError::new(format!(
                "the module from {} is boxed in at {}",
                xy(start),
                xy(p)
            )));
        };
        p = d.step(p);
        if !tracked(p) {
            return Err(InputError::new(format!(
                "the module from {start} wandered away from the structure, to {p}"
            )));
        }
        cells.push(p);
        last = Some(d);
    }
    Ok(Removal { cells })
}

/// The move bound passed to [`walk`]: Theorem 5 gives `2|V₀| + 2`; twice
/// that leaves room for the margin around the rectangle.
pub fn move_bound(shape: &Shape) -> usize {
    4 * (shape.width * shape.height) as usize + 4 * (shape.width + shape.height) as usize + 16
}

/// Runs SAS (Alg. 1 + Alg. 2) on a validated shape.
pub fn run(shape: &Shape) -> Result<SasRun, InputError> {
    let mut occ = Occupancy::full(shape);
    let mut excluded: Vec<Cell> = shape.cells().filter(|&c| !shape.contains(c)).collect();
    let bound = move_bound(shape);
    let mut removals = Vec::with_capacity(excluded.len());
    while !excluded.is_empty() {
        let k = choose(&excluded, &occ).ok_or_else(|| {
            InputError::new(
                "no excluded module has a free connector: the desired configuration is hollow",
            )
        })?;
        let m = excluded.swap_remove(k);
        occ.set(m, false);
        let r = walk(m, &|c| occ.occupied(c), &|c| occ.tracked(c), bound)?;
        removals.push(r);
    }
    Ok(SasRun { removals })
}

/// The *best-case sequential time* of seed 003 §V-B1, a lower bound for
/// SAS: the sum over excluded modules of the shortest route to the sink
/// through cells not held by included modules (excluded modules count as
/// empty), by the paper's moves. A diagonal move needs one of its two
/// adjacent cells free (the paper leaves the side open; either way round the
/// corner is a valid route).
pub fn best_case_time(shape: &Shape) -> usize {
    let (x0, x1, y1) = (1 - MARGIN, shape.width + MARGIN, shape.height + MARGIN);
    let w = (x1 - x0 + 1) as usize;
    let idx = |c: Cell| (c.y - 1) as usize * w + (c.x - x0) as usize;
    let open = |c: Cell| c.x >= x0 && c.x <= x1 && c.y >= 1 && c.y <= y1 && !shape.contains(c);
    let mut dist = vec![usize::MAX; w * y1 as usize];
    let mut queue = std::collections::VecDeque::from([SINK]);
    dist[idx(SINK)] = 0;
    while let Some(c) = queue.pop_front() {
        for d in (0..8).map(|k| Dir::S.turn(k)) {
            let n = d.step(c);
            let passable = !d.is_diagonal() || open(d.turn(1).step(c)) || open(d.turn(-1).step(c));
            if open(n) && passable && dist[idx(n)] == usize::MAX {
                dist[idx(n)] = dist[idx(c)] + 1;
                queue.push_back(n);
            }
        }
    }
    shape
        .cells()
        .filter(|&c| !shape.contains(c))
        .map(|c| dist[idx(c)])
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn shape(t: &str) -> Shape {
        let s = Shape::parse(t, Path::new("t")).unwrap();
        s.validate().unwrap();
        s
    }

    #[test]
    fn probing_order_turns_with_the_last_direction() {
        // Nothing around: the first probe wins. Initially South…
        let none = |c: Cell| c.y < 1;
        let p = Cell::xy(5, 5);
        assert_eq!(next_direction(p, None, &none), Some(Dir::S));
        // …after moving North, the order starts at W (D − 2).
        assert_eq!(next_direction(p, Some(Dir::S.turn(4)), &none), Some(Dir::W));
        // A diagonal needs the next cell clockwise free: SW passes through W.
        let wall = |c: Cell| c.y < 1 || c == Cell::xy(5, 4) || c == Cell::xy(4, 5);
        assert_eq!(next_direction(p, None, &wall).map(Dir::name), Some("NW"));
    }

    #[test]
    fn the_leader_takes_the_highest_then_most_westerly_free_module() {
        let s = shape("#..#\n#..#\n#..#\n####\n");
        let run = run(&s).unwrap();
        let starts: Vec<Cell> = run.removals.iter().map(Removal::start).collect();
        assert_eq!(
            starts,
            [(2, 4), (3, 4), (2, 3), (3, 3), (2, 2), (3, 2)].map(|(x, y)| Cell::xy(x, y))
        );
        for r in &run.removals {
            assert_eq!(*r.cells.last().unwrap(), SINK);
        }
        // SAS takes 5 + 6 + 6 + 7 + 7 + 8; the best case cuts diagonally
        // across the inside: (2,4) 5, (3,4) 6, (2,3) 6, (3,3) 6, (2,2) 7,
        // (3,2) 7.
        let best = best_case_time(&s);
        assert_eq!(run.time_steps(), 39);
        assert_eq!(best, 5 + 6 + 6 + 6 + 7 + 7);
    }
}
