//! Final approaches of a docking (seed 002): the lattice moves that can
//! bring a free module into a cell of the structure, and the exact sweep
//! that says whether one of them is clear.
//!
//! A docking is the module's last motion into its cell. On the square
//! lattice the candidates are the sliding-square moves ending in the cell
//! (`lattice::square`): four straight slides from a side neighbour, each
//! along one of two walls, and four corner moves from a diagonal
//! neighbour, each around one of two pivots — 16 in all. On the FCC
//! lattice they are the catom rotations ending in the cell: about any of
//! its 12 neighbours, from any neighbour of that pivot the rolling links
//! reach, by either route. Whether an
//! approach is clear is decided by the body geometry: the origin must be
//! free, the move's supports held, and the exact sweep of the mover
//! ([`super::sweep_model`]) must penetrate no module. Rule 1 of the paper
//! is not consulted here; it lives with the generator.

use super::rolling::Link;
use super::{Contact, ContactKind, SweepInput, Tolerance, sweep_model};
use crate::lattice::config::{Ground, ModuleId};
use crate::lattice::{Cell, Configuration, Lattice, LatticeKind, Motion, Route};
use rustc_hash::FxHashSet;

/// Cells around a mover's origin whose modules its sweep can touch.
const REACH: i32 = 3;

/// A candidate final approach into a cell.
#[derive(Clone, Debug, PartialEq)]
pub struct Approach {
    /// The cell the module comes from (must be free).
    pub from: Cell,
    /// The cell of the module it holds on to (wall or corner pivot).
    pub pivot: Cell,
    pub motion: Motion,
}

/// Every lattice move that ends in `cell`: 16 on the square lattice, the
/// rolling links into it on FCC. Other lattices have none here.
pub fn candidates(lattice: &dyn Lattice, cell: Cell) -> Vec<Approach> {
    match lattice.kind() {
        LatticeKind::Square => square_candidates(lattice, cell),
        LatticeKind::Fcc => fcc_candidates(lattice, cell),
        LatticeKind::Cubic => Vec::new(),
    }
}

/// The catom rotations into `cell`: pivot any neighbour, origin any other
/// neighbour of the pivot that a rolling link joins to `cell`.
fn fcc_candidates(lattice: &dyn Lattice, cell: Cell) -> Vec<Approach> {
    let mut out = Vec::new();
    for pivot in lattice.neighbours(cell) {
        for from in lattice.neighbours(pivot) {
            if from == cell {
                continue;
            }
            for route in [Route::Hexagonal, Route::Octagonal] {
                let motion = Motion::Rotate {
                    from,
                    to: cell,
                    pivot,
                    route,
                };
                if Link::of_motion(lattice, &motion).is_some()
                    && lattice.move_requirements(&motion).is_ok()
                {
                    out.push(Approach {
                        from,
                        pivot,
                        motion,
                    });
                }
            }
        }
    }
    out
}

fn square_candidates(lattice: &dyn Lattice, cell: Cell) -> Vec<Approach> {
    let mut out = Vec::new();
    let axes = [
        Cell::xy(1, 0),
        Cell::xy(0, 1),
        Cell::xy(-1, 0),
        Cell::xy(0, -1),
    ];
    for d in axes {
        // Straight slide from the side neighbour `cell + d`, along a wall
        // on either side perpendicular to d.
        let from = cell + d;
        for s in axes.iter().filter(|s| s.x * d.x + s.y * d.y == 0) {
            out.push(approach(from, from + *s, cell));
        }
    }
    for (dx, dy) in [(1, 1), (-1, 1), (-1, -1), (1, -1)] {
        // Corner move from the diagonal neighbour around either corner.
        let from = Cell::xy(cell.x + dx, cell.y + dy);
        for pivot in [Cell::xy(cell.x + dx, cell.y), Cell::xy(cell.x, cell.y + dy)] {
            out.push(approach(from, pivot, cell));
        }
    }
    out.retain(|a| lattice.move_requirements(&a.motion).is_ok());
    out
}

fn approach(from: Cell, pivot: Cell, to: Cell) -> Approach {
    Approach {
        from,
        pivot,
        motion: Motion::Slide {
            from,
            to,
            pivot: Some(pivot),
        },
    }
}

/// What stands in the way of one approach.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Obstruction {
    /// Cells that must be free and are not (origin, passage) or whose
    /// module the exact sweep penetrates.
    pub blocking: Vec<Cell>,
    /// Supports the move needs that hold no module.
    pub missing_supports: Vec<Cell>,
    /// How deep the sweep dips below the floor under the ground layer, if
    /// it does (units of d).
    pub below_floor: Option<f64>,
}

impl Obstruction {
    pub fn is_clear(&self) -> bool {
        self.blocking.is_empty() && self.missing_supports.is_empty() && self.below_floor.is_none()
    }
}

/// Judges one approach against `config` (the scene before the docking):
/// supports held, origin and passage free and above the ground, no
/// penetration along the exact sweep of the mover (sliding contact is
/// allowed, as for any move), and no dip below the floor.
pub fn judge(
    lattice: &'static dyn Lattice,
    config: &Configuration,
    ground: Option<Ground>,
    approach: &Approach,
    epsilon: Tolerance,
) -> Obstruction {
    let mut out = Obstruction::default();
    if ground.is_some_and(|g| g.is_ground_cell(lattice, approach.from)) {
        out.blocking.push(approach.from);
        return out;
    }
    let Ok(req) = lattice.move_requirements(&approach.motion) else {
        out.blocking.push(approach.from);
        return out;
    };
    out.missing_supports = req
        .supports
        .iter()
        .copied()
        .filter(|c| config.is_free(*c))
        .collect();
    for c in std::iter::once(approach.from).chain(req.pass_through.iter().copied()) {
        if !config.is_free(c) && !out.blocking.contains(&c) {
            out.blocking.push(c);
        }
    }
    if !out.blocking.is_empty() {
        return out;
    }
    // The exact sweep, with the mover placed at its origin.
    let Some(model) = sweep_model(lattice.kind()) else {
        return out;
    };
    const MOVER: ModuleId = ModuleId::MAX;
    // Only modules within reach of the sweep matter (the square sweep looks
    // two cells around the mover's origin): a local scene keeps a docking's
    // check independent of the structure's size.
    let mut scene = Configuration::new();
    let f = approach.from;
    let dz = if lattice.kind() == LatticeKind::Square {
        0
    } else {
        REACH
    };
    for dx in -REACH..=REACH {
        for dy in -REACH..=REACH {
            for dz in -dz..=dz {
                let c = Cell::new(f.x + dx, f.y + dy, f.z + dz);
                if let Some(id) = config.at(c) {
                    scene.insert(id, c).expect("one module per cell");
                }
            }
        }
    }
    if scene.insert(MOVER, approach.from).is_err() {
        out.blocking.push(approach.from);
        return out;
    }
    let pivot = config.at(approach.pivot);
    let moves = [(MOVER, pivot, approach.motion.clone())];
    let moving: FxHashSet<ModuleId> = [MOVER].into_iter().collect();
    let input = SweepInput {
        lattice,
        config: &scene,
        moves: &moves,
        moving: &moving,
        epsilon,
        exact: true,
    };
    if let Some(g) = ground {
        out.below_floor = model.check_ground(&input, g).first().map(|c| c.depth);
    }
    let contacts: Vec<Contact> = model.check_step(&input);
    for c in contacts.iter().filter(|c| c.kind == ContactKind::Collision) {
        if let Some(cell) = config.cell_of(c.other)
            && !out.blocking.contains(&cell)
        {
            out.blocking.push(cell);
        }
    }
    out
}

/// The usable approaches into `cell`, in [`candidates`] order: clear (see
/// [`judge`]) from an origin a module can reach from outside the
/// structure, whose bounding box is `bounds` (see [`origin_reachable`]).
pub fn clear_approaches(
    lattice: &'static dyn Lattice,
    config: &Configuration,
    ground: Option<Ground>,
    bounds: (Cell, Cell),
    cell: Cell,
    epsilon: Tolerance,
) -> Vec<Approach> {
    candidates(lattice, cell)
        .into_iter()
        .filter(|a| {
            judge(lattice, config, ground, a, epsilon).is_clear()
                && origin_reachable(lattice, config, ground, bounds, a.from)
        })
        .collect()
}

/// The bounding box of the occupied cells (an empty box for no cells).
pub fn bounds_of(config: &Configuration) -> (Cell, Cell) {
    let empty = (
        Cell::new(i32::MAX, i32::MAX, i32::MAX),
        Cell::new(i32::MIN, i32::MIN, i32::MIN),
    );
    config.iter().fold(empty, |b, (_, c)| grow_bounds(b, c))
}

/// The bounding box `b` grown to hold `c`.
pub fn grow_bounds(b: (Cell, Cell), c: Cell) -> (Cell, Cell) {
    (
        Cell::new(b.0.x.min(c.x), b.0.y.min(c.y), b.0.z.min(c.z)),
        Cell::new(b.1.x.max(c.x), b.1.y.max(c.y), b.1.z.max(c.z)),
    )
}

/// Whether `c` holds no module and is not inside the ground.
fn is_open(lattice: &dyn Lattice, config: &Configuration, ground: Option<Ground>, c: Cell) -> bool {
    config.is_free(c) && !ground.is_some_and(|g| g.is_ground_cell(lattice, c))
}

/// Whether the motion rules (the compiled tables, not an exact sweep)
/// find `approach` clear in `config`: origin free and above the ground,
/// pivot and supports held, every cell the sweep penetrates free — and,
/// when `strict`, every cell it touches too — and no dip below the floor.
/// What a generator plans with; certification judges exactly ([`judge`]).
pub fn planned_clear(
    lattice: &dyn Lattice,
    config: &Configuration,
    ground: Option<Ground>,
    approach: &Approach,
    strict: bool,
) -> bool {
    let free = |c: Cell| is_open(lattice, config, ground, c);
    if !free(approach.from) || config.is_free(approach.pivot) {
        return false;
    }
    let Ok(req) = lattice.move_requirements(&approach.motion) else {
        return false;
    };
    if req.supports.iter().any(|c| config.is_free(*c)) || !req.pass_through.iter().all(|c| free(*c))
    {
        return false;
    }
    if let Some(rules) = super::motion_rules(lattice.kind()) {
        let cells = if strict {
            rules.touched_cells(&approach.motion)
        } else {
            rules.blocking_cells(&approach.motion)
        };
        if !cells
            .into_iter()
            .all(|c| c == approach.motion.to() || free(c))
        {
            return false;
        }
    }
    if let (Some(g), Some(roll)) = (
        ground,
        super::rolling::Roll::of_motion(lattice, &approach.motion),
    ) {
        let floor = super::FccSweep::floor(lattice, g);
        if super::ground::floor_contact(0, &roll, floor, super::EPSILON).is_some() {
            return false;
        }
    }
    true
}

/// Most free cells an [`origin_reachable`] search visits before it gives
/// up (and the origin counts as enclosed: the conservative answer).
pub const REACH_SEARCH_LIMIT: usize = 200_000;

/// Whether a module can come to `origin` from outside the structure: a
/// path of free lattice neighbours (above the ground) from `origin` to a
/// cell outside the bounding box `(lo, hi)` of the occupied cells. Free
/// cells are a necessary condition for a real path, not a planned one. The
/// search goes best-first towards the nearest face of the box, so an open
/// origin costs a few cells; an enclosed one costs its cavity.
pub fn origin_reachable(
    lattice: &dyn Lattice,
    config: &Configuration,
    ground: Option<Ground>,
    bounds: (Cell, Cell),
    origin: Cell,
) -> bool {
    use std::cmp::Reverse;
    let (lo, hi) = bounds;
    let outside =
        |c: Cell| c.x < lo.x || c.y < lo.y || c.z < lo.z || c.x > hi.x || c.y > hi.y || c.z > hi.z;
    let to_face = |c: Cell| {
        [
            c.x - lo.x,
            hi.x - c.x,
            c.y - lo.y,
            hi.y - c.y,
            c.z - lo.z,
            hi.z - c.z,
        ]
        .into_iter()
        .min()
        .unwrap_or(0)
        .max(0)
    };
    let open = |c: Cell| is_open(lattice, config, ground, c);
    if !open(origin) {
        return false;
    }
    let mut seen: FxHashSet<Cell> = [origin].into_iter().collect();
    let mut heap = std::collections::BinaryHeap::from([Reverse((to_face(origin), origin))]);
    while let Some(Reverse((_, c))) = heap.pop() {
        if outside(c) {
            return true;
        }
        if seen.len() > REACH_SEARCH_LIMIT {
            return false;
        }
        for n in lattice.neighbours(c) {
            if open(n) && seen.insert(n) {
                heap.push(Reverse((to_face(n), n)));
            }
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::SquareLattice;

    fn scene(cells: &[(i32, i32)]) -> Configuration {
        let mut c = Configuration::new();
        for (k, &(x, y)) in cells.iter().enumerate() {
            c.insert(k as ModuleId, Cell::xy(x, y)).unwrap();
        }
        c
    }

    #[test]
    fn a_square_cell_has_sixteen_candidate_approaches() {
        assert_eq!(candidates(&SquareLattice, Cell::xy(0, 0)).len(), 16);
    }

    #[test]
    fn a_cell_beside_one_module_is_reached_around_its_corner() {
        let c = scene(&[(1, 0)]);
        let ok = clear_approaches(
            &SquareLattice,
            &c,
            None,
            bounds_of(&c),
            Cell::xy(0, 0),
            Tolerance::DEFAULT,
        );
        assert!(ok.iter().any(|a| a.from == Cell::xy(1, 1)), "{ok:?}");
        // A module in the corner's passage blocks that approach.
        let c = scene(&[(1, 0), (0, 1)]);
        let a = candidates(&SquareLattice, Cell::xy(0, 0))
            .into_iter()
            .find(|a| a.from == Cell::xy(1, 1) && a.pivot == Cell::xy(1, 0))
            .unwrap();
        let o = judge(&SquareLattice, &c, None, &a, Tolerance::DEFAULT);
        assert_eq!(o.blocking, vec![Cell::xy(0, 1)]);
    }

    #[test]
    fn an_origin_inside_a_closed_ring_is_enclosed_and_one_gap_opens_it() {
        let ring = [
            (-1, -1),
            (0, -1),
            (1, -1),
            (-1, 0),
            (1, 0),
            (-1, 1),
            (0, 1),
            (1, 1),
        ];
        let c = scene(&ring);
        let b = bounds_of(&c);
        let o = Cell::xy(0, 0);
        assert!(!origin_reachable(&SquareLattice, &c, None, b, o));
        assert!(origin_reachable(
            &SquareLattice,
            &c,
            None,
            b,
            Cell::xy(2, 0)
        ));
        let gap: Vec<(i32, i32)> = ring.iter().copied().filter(|&c| c != (0, 1)).collect();
        let open = scene(&gap);
        assert!(origin_reachable(
            &SquareLattice,
            &open,
            None,
            bounds_of(&open),
            o
        ));
        // An occupied origin is never reachable.
        assert!(!origin_reachable(
            &SquareLattice,
            &c,
            None,
            b,
            Cell::xy(1, 0)
        ));
        // On FCC the ground closes a cup from below: a catom on the ground
        // walled in on its four sides and capped is enclosed.
        use crate::lattice::FccLattice;
        let mut cup = Configuration::new();
        let mut id = 0;
        for cell in FccLattice.neighbours(Cell::new(0, 0, 0)) {
            if cell.z >= 0 {
                cup.insert(id, cell).unwrap();
                id += 1;
            }
        }
        let g = Some(Ground { layer: 0 });
        let b = bounds_of(&cup);
        assert!(!origin_reachable(
            &FccLattice,
            &cup,
            g,
            b,
            Cell::new(0, 0, 0)
        ));
        assert!(origin_reachable(
            &FccLattice,
            &cup,
            None,
            b,
            Cell::new(0, 0, 0)
        ));
    }

    #[test]
    fn a_catom_cell_has_rotations_into_it_about_each_neighbour() {
        use crate::lattice::FccLattice;
        let c = candidates(&FccLattice, Cell::new(0, 0, 0));
        let pivots: FxHashSet<Cell> = c.iter().map(|a| a.pivot).collect();
        assert_eq!(pivots.len(), 12);
        assert!(
            c.iter()
                .all(|a| matches!(a.motion, Motion::Rotate { to, .. } if to == Cell::ZERO))
        );
    }
}
