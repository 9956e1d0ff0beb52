//! The three meta-module operations (§IV) derived by search.
//!
//! One streamline of four meta-modules in a line, in direction `dir`:
//! a source S that is dismantled, an intermediate M that transfers, a
//! destination D that assembles, and the goal cell G (EMPTY → SPARSE, or
//! SPARSE → FULL). S's ten catoms go one at a time, each along a shortest
//! rotation path found by [`Scene::route`], the static structure connected
//! before each departure. Goal cells are filled bottom-up (the lowest goal
//! cell some catom can reach is taken first, so a new catom rests on what
//! is below it), each by the removable source catom with the shortest
//! path (ties: the highest, so the source is taken down from the top).
//!
//! A rotation belongs to the operation of the meta-module its pivot
//! belongs to: Dismantle (S), Transfer (M) and Assemble (D and G, the
//! catoms already placed included) — the paper's operation coordinators
//! are those meta-modules. Rotations on the support column of the
//! vertical scenes count apart.

use super::metamodule::{Direction, Meta, State};
use super::search::{Hop, Scene};
use crate::error::InputError;
use crate::lattice::Cell;
use crate::lattice::config::ModuleId;
use rustc_hash::FxHashSet;
use serde::Serialize;

/// Which operation a rotation belongs to.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    Dismantle,
    Transfer,
    Assemble,
    Support,
}

/// One planned rotation with module identities.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Rotation {
    pub module: ModuleId,
    pub pivot: ModuleId,
    pub hop: Hop,
    pub role: Role,
}

/// The scene of one operation test: the streamline S → M → D → G.
#[derive(Clone, Debug)]
pub struct OperationScene {
    pub dir: Direction,
    pub fill: State,
    pub source: Meta,
    pub transfer: Meta,
    pub destination: Meta,
    pub goal: Meta,
    /// Meta-modules that only hold the vertical streamlines up.
    pub support: Vec<Meta>,
    /// Initial modules: id, cell, role of its meta-module.
    pub modules: Vec<(ModuleId, Cell, Role)>,
    pub ground: i32,
}

impl OperationScene {
    /// The scene on the ground (layer 0): horizontal streamlines lie on it;
    /// vertical ones stand beside a column of SPARSE meta-modules that
    /// rests on it.
    pub fn new(dir: Direction, fill: State) -> OperationScene {
        let base = match dir {
            Direction::Down => Meta::new(0, 0, 3),
            _ => Meta::new(0, 0, 0),
        };
        let source = base;
        let transfer = source.step(dir);
        let destination = transfer.step(dir);
        let goal = destination.step(dir);
        let support = if dir.is_vertical() {
            (0..4).map(|z| Meta::new(1, 0, z)).collect()
        } else {
            Vec::new()
        };
        let mut modules = Vec::new();
        let mut add = |m: Meta, state: State, role: Role| {
            for c in m.cells(state) {
                modules.push((modules.len() as ModuleId, c, role));
            }
        };
        add(source, State::Sparse, Role::Dismantle);
        add(transfer, State::Sparse, Role::Transfer);
        add(destination, State::Sparse, Role::Assemble);
        if fill == State::Full {
            add(goal, State::Sparse, Role::Assemble);
        }
        for m in &support {
            add(*m, State::Sparse, Role::Support);
        }
        OperationScene {
            dir,
            fill,
            source,
            transfer,
            destination,
            goal,
            support,
            modules,
            ground: 0,
        }
    }

    /// The cells the operation fills.
    pub fn targets(&self) -> Vec<Cell> {
        match self.fill {
            State::Full => self.goal.filling_cells().to_vec(),
            _ => self.goal.sparse_cells().to_vec(),
        }
    }
}

/// The derived operation: its rotations in order and the counts per role.
#[derive(Clone, Debug)]
pub struct OperationPlan {
    pub scene: OperationScene,
    pub rotations: Vec<Rotation>,
    /// Whether every rotation avoids even sliding contact.
    pub strict: bool,
    /// The goal-cell order that succeeded (see [`orders`]).
    pub order: &'static str,
}

impl OperationPlan {
    pub fn count(&self, role: Role) -> usize {
        self.rotations.iter().filter(|r| r.role == role).count()
    }
}

/// The orders in which goal cells are tried: bottom-up first (a new catom
/// rests on what is below it), then along the loop and against it (each
/// new catom latches the previous one).
pub fn orders(targets: &[Cell]) -> Vec<(&'static str, Vec<Cell>)> {
    let mut up = targets.to_vec();
    up.sort_by_key(|c| (c.z, c.x, c.y));
    let chain = targets.to_vec();
    let mut back = targets.to_vec();
    back.reverse();
    vec![("bottom-up", up), ("loop", chain), ("loop-reversed", back)]
}

/// Derives the operation of `scene`: strictly (no sliding contact) if
/// possible, else with sliding contact allowed (still no collision); in
/// each mode the first order of [`orders`] that reaches every goal cell;
/// all of that within [`SEARCH_BUDGET`] states, then, if none does,
/// within [`DEEP_SEARCH_BUDGET`] (what the horizontal FULL Assemble
/// needs; the operations found within the first are kept as they were).
pub fn derive(dir: Direction, fill: State) -> Result<OperationPlan, InputError> {
    let scene = OperationScene::new(dir, fill);
    let mut last = None;
    for budget in [SEARCH_BUDGET, DEEP_SEARCH_BUDGET] {
        for strict in [true, false] {
            for (name, order) in orders(&scene.targets()) {
                match plan(&scene, &order, strict, budget) {
                    Ok(mut p) => {
                        p.order = name;
                        return Ok(p);
                    }
                    Err(e) => last = Some(e),
                }
            }
        }
    }
    Err(last.expect("at least one order was tried"))
}

/// Moves the catoms in `sources` to the cells `targets`, one at a time,
/// each along a shortest path, by depth-first search over the choices:
/// the earliest target in the given order first, then the shortest path,
/// then the highest source catom; a choice that leads to a state where
/// no catom can reach any remaining target is undone. Only removable
/// source catoms (the rest stays connected) move. The scene is updated;
/// the paths are returned in execution order. The search expands at
/// most `budget` states. On failure, the first goal cell of the order that
/// stays unfilled.
pub fn move_catoms(
    s: &mut Scene,
    sources: &[Cell],
    targets: &[Cell],
    strict: bool,
    budget: usize,
) -> Result<Vec<Vec<Hop>>, Cell> {
    search_moves(s, sources, targets, strict, budget, false, false)
}

/// [`move_catoms`] with the targets filled strictly in their order (a
/// chain grown from its first cell, each catom latching to the one
/// before, never from its far end inwards); with `top_first`, each by
/// the highest source catom that reaches it, then the shortest path: a
/// source is taken down from its top, so that what stays of it stands on
/// what is below while the chain grows (the catoms of a source on the
/// ground that leave first from its bottom leave the rest hanging on its
/// side joints).
pub fn move_catoms_in_order(
    s: &mut Scene,
    sources: &[Cell],
    targets: &[Cell],
    strict: bool,
    budget: usize,
    top_first: bool,
) -> Result<Vec<Vec<Hop>>, Cell> {
    search_moves(s, sources, targets, strict, budget, true, top_first)
}

fn search_moves(
    s: &mut Scene,
    sources: &[Cell],
    targets: &[Cell],
    strict: bool,
    budget: usize,
    in_order: bool,
    top_first: bool,
) -> Result<Vec<Vec<Hop>>, Cell> {
    assert!(sources.len() <= 32 && targets.len() <= 32);
    let mut search = Dfs {
        sources,
        targets,
        strict,
        in_order,
        top_first,
        failed: FxHashSet::default(),
        budget,
        paths: Vec::new(),
        best_depth: (0, 0),
    };
    if search.run(s, 0, 0) {
        Ok(search.paths)
    } else {
        let placed = search.best_depth.1;
        Err(targets
            .iter()
            .enumerate()
            .find(|(i, _)| placed & (1 << i) == 0)
            .map(|(_, c)| *c)
            .unwrap_or(targets[0]))
    }
}

/// States the depth-first search of [`move_catoms`] may expand.
pub const SEARCH_BUDGET: usize = 300;

/// The budget tried where [`SEARCH_BUDGET`] (or [`FILL_SEARCH_BUDGET`])
/// finds no order: filling a meta-module's interior from the side, whose
/// cell at the leader's level and one layer up is reached only after
/// the right few of its neighbours are placed (the four horizontal FULL
/// Assembles are found strictly, bottom-up, within 3,000 to 5,000 states,
/// about 2 s each in release).
pub const DEEP_SEARCH_BUDGET: usize = 10_000;

/// The budget for filling a meta-module's interior inside a structure
/// (the planner's compression): its neighbours, FULL already, leave the
/// interior cells fewer ways in, and 300 states do not find one (the
/// 3 × 3 × 4 compression stops at its eighth meta-module with 300 and
/// plans with 3,000).
pub const FILL_SEARCH_BUDGET: usize = 3000;

struct Dfs<'a> {
    sources: &'a [Cell],
    targets: &'a [Cell],
    strict: bool,
    /// Only the first target not yet filled is open.
    in_order: bool,
    /// The highest source catom first, then the shortest path.
    top_first: bool,
    failed: FxHashSet<(u32, u32)>,
    budget: usize,
    paths: Vec<Vec<Hop>>,
    /// Deepest state reached: (catoms placed, placed mask).
    best_depth: (u32, u32),
}

impl Dfs<'_> {
    fn run(&mut self, s: &mut Scene, placed: u32, used: u32) -> bool {
        let n = self.targets.len();
        if placed.count_ones() as usize == n {
            return true;
        }
        if placed.count_ones() > self.best_depth.0 {
            self.best_depth = (placed.count_ones(), placed);
        }
        if self.budget == 0 || self.failed.contains(&(placed, used)) {
            return false;
        }
        self.budget -= 1;
        let open: Vec<(usize, Cell)> = self
            .targets
            .iter()
            .enumerate()
            .filter(|(i, _)| placed & (1 << i) == 0)
            .map(|(i, c)| (i, *c))
            .take(if self.in_order { 1 } else { n })
            .collect();
        let goals: Vec<Cell> = open.iter().map(|x| x.1).collect();
        let mut cands = Vec::new();
        for (si, from) in self.sources.iter().enumerate() {
            if used & (1 << si) != 0 || !s.connected_without(Some(*from)) {
                continue;
            }
            for (k, p) in s.routes(*from, &goals, self.strict).into_iter().enumerate() {
                if let Some(p) = p {
                    cands.push((open[k].0, p.len(), -from.z, si, p));
                }
            }
        }
        if self.top_first {
            cands.sort_by_key(|c| (c.0, c.2, c.1, c.3));
        } else {
            cands.sort_by_key(|c| (c.0, c.1, c.2, c.3));
        }
        for (ti, _, _, si, p) in cands {
            let (from, to) = (self.sources[si], self.targets[ti]);
            let id = s.at.remove(&from).expect("a source cell holds a catom");
            s.insert(id, to);
            self.paths.push(p);
            if self.run(s, placed | 1 << ti, used | 1 << si) {
                return true;
            }
            self.paths.pop();
            s.at.remove(&to);
            s.insert(id, from);
            if self.budget == 0 {
                return false;
            }
        }
        self.failed.insert((placed, used));
        false
    }
}

fn plan(
    scene: &OperationScene,
    order: &[Cell],
    strict: bool,
    budget: usize,
) -> Result<OperationPlan, InputError> {
    let mut s = Scene::new(Some(scene.ground));
    let mut role_of: Vec<Role> = Vec::new();
    for (id, c, role) in &scene.modules {
        s.insert(*id, *c);
        role_of.push(*role);
    }
    let targets = order.to_vec();
    s.fit_box(&targets, 2);
    let sources: Vec<Cell> = scene
        .modules
        .iter()
        .filter(|m| m.2 == Role::Dismantle)
        .map(|m| m.1)
        .collect();
    let start = s.clone();
    let paths = move_catoms(&mut s, &sources, &targets, strict, budget).map_err(|cell| {
        InputError::new(format!(
            "RePoSt assemble-{} {}: no source catom can reach goal cell {cell}",
            match scene.fill {
                State::Full => "full",
                _ => "sparse",
            },
            scene.dir.name(),
        ))
    })?;
    // Replay with identities, to name pivots and attribute rotations.
    let mut at = start.at;
    let mut rotations = Vec::new();
    for path in paths {
        let (Some(first), Some(last)) = (path.first(), path.last()) else {
            continue;
        };
        let m = at
            .remove(&first.from)
            .expect("the mover is in its start cell");
        for h in &path {
            let pivot = at[&h.pivot];
            rotations.push(Rotation {
                module: m,
                pivot,
                hop: *h,
                role: role_of[pivot as usize],
            });
        }
        at.insert(last.to, m);
        // A placed catom belongs to the assembled meta-module.
        role_of[m as usize] = Role::Assemble;
    }
    Ok(OperationPlan {
        scene: scene.clone(),
        rotations,
        strict,
        order: "",
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::{FccLattice, Lattice};

    /// A 5 × 5 patch on the ground with two removable corner catoms, and
    /// two goal cells: `b` on the patch, `a` on `b` alone (one layer
    /// higher, so it touches nothing else). `a` is reachable only once
    /// `b` holds a catom to pivot on.
    fn patch_with_a_chain() -> (Scene, [Cell; 2], Cell, Cell) {
        let mut s = Scene::new(Some(0));
        let mut id = 0;
        for x in 0..5 {
            for y in 0..5 {
                s.insert(id, Cell::new(x, y, 0));
                id += 1;
            }
        }
        s.fit_box(&[], 3);
        let b = FccLattice
            .neighbours(Cell::new(2, 2, 0))
            .into_iter()
            .find(|c| c.z == 1)
            .expect("a cell above");
        let a = FccLattice
            .neighbours(b)
            .into_iter()
            .find(|c| c.z == 2)
            .expect("a cell above that");
        (s, [Cell::new(0, 0, 0), Cell::new(4, 4, 0)], a, b)
    }

    /// Unordered, the search fills the goal it can reach first and comes
    /// back for the other; in order, a chain is grown only from its first
    /// cell, and a first cell nothing can reach yet is where it stops.
    #[test]
    fn a_chain_in_order_is_grown_from_its_first_cell_or_not_at_all() {
        let (s, sources, a, b) = patch_with_a_chain();
        let paths = move_catoms(&mut s.clone(), &sources, &[a, b], true, SEARCH_BUDGET)
            .expect("b, then a on it");
        let ends: Vec<Cell> = paths.iter().map(|p| p[p.len() - 1].to).collect();
        assert_eq!(ends, [b, a], "unordered: the far end first");
        assert_eq!(
            move_catoms_in_order(&mut s.clone(), &sources, &[a, b], true, SEARCH_BUDGET, true),
            Err(a)
        );
        let paths =
            move_catoms_in_order(&mut s.clone(), &sources, &[b, a], true, SEARCH_BUDGET, true)
                .expect("in its own order the chain grows");
        let ends: Vec<Cell> = paths.iter().map(|p| p[p.len() - 1].to).collect();
        assert_eq!(ends, [b, a]);
    }
}
