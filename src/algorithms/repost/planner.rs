//! The §V planner, centralised: the paper distributes the same three steps
//! over the meta-module leaders; computed in one place they give the same
//! sources, destinations and streamlines.
//!
//! Each iteration:
//! 1. **Sources**: SPARSE meta-modules outside the goal that are leaves of
//!    a breadth-first spanning tree rooted at the global coordinator (a
//!    meta-module in both shapes, the lowest), so that dismantling all of
//!    them together leaves the rest connected; when that plan fails, only
//!    the leaves nearest the far end of the structure (see [`plan`]). Every
//!    FULL meta-module the goal does not want FULL is a source too: its
//!    filling catoms leave, its loop stays.
//! 2. **Destinations**: SPARSE goal meta-modules next to an empty goal
//!    cell; each empty goal cell goes to exactly one destination and each
//!    destination serves one cell. Then SPARSE meta-modules the goal
//!    wants FULL (compression), lowest first: the catoms fill their
//!    interior (recorded as the pair `(d, d)`).
//! 3. **Streamlines**: maximum flow from sources to destinations with unit
//!    capacities on the meta-modules (node splitting), by Dinic's
//!    algorithm (`petgraph::algo::dinics`): streamlines are
//!    vertex-disjoint, as in the authors' code, because two streamlines
//!    crossing one meta-module would cross inside its loop.
//! 4. **Transport**: each streamline's ten catoms get their paths inside
//!    the streamline's meta-modules (their cell boxes) to the goal cell,
//!    each planned against the end state of the ones before it
//!    ([`super::operations::move_catoms`]); then they run pipelined, one
//!    behind another, the streamlines side by side
//!    ([`super::pipeline`]), or one at a time if a catom fits nowhere in
//!    the pipeline.

use super::messages::{self, IterationRecord, Messages};
use super::metamodule::{Meta, State, spanning_tree};
use super::operations::{DEEP_SEARCH_BUDGET, FILL_SEARCH_BUDGET, SEARCH_BUDGET, move_catoms};
use super::pipeline::pipeline;
use super::search::{Hop, Scene};
use crate::geometry::MotionRules;
use crate::lattice::Cell;
use crate::lattice::config::ModuleId;
use petgraph::graph::{DiGraph, NodeIndex};
use rustc_hash::{FxHashMap, FxHashSet};
use std::collections::BTreeMap;

/// Why a goal cannot be planned, with the meta-module it is about.
#[derive(Clone, Debug, PartialEq)]
pub enum PlanError {
    /// The goal size is outside ⌈N/20⌉ ≤ S_G ≤ N/10.
    Bound { catoms: usize, goal: usize },
    /// The goal's loops and fillings do not hold the initial catoms.
    Catoms { initial: usize, goal: usize },
    /// No meta-module is in both shapes (no global coordinator).
    NoCoordinator,
    /// An empty goal cell that no streamline can reach.
    Unreachable(Meta),
    /// The transport search found no rotation path to a cell of `0`.
    Stuck(Meta, Cell),
}

impl std::fmt::Display for PlanError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PlanError::Bound { catoms, goal } => write!(
                f,
                "goal of {goal} meta-modules is outside the bound ⌈N/20⌉ ≤ S_G ≤ N/10 for N = {catoms} catoms ({}..={})",
                catoms.div_ceil(20),
                catoms / 10
            ),
            PlanError::Catoms { initial, goal } => write!(
                f,
                "the goal's meta-modules hold {goal} catoms (10 per SPARSE, 20 per FULL), the initial shape {initial}: no reconfiguration ends on it"
            ),
            PlanError::NoCoordinator => write!(f, "no meta-module is in both shapes"),
            PlanError::Unreachable(m) => {
                write!(
                    f,
                    "goal meta-module {m} cannot be reached by any streamline"
                )
            }
            PlanError::Stuck(m, c) => write!(
                f,
                "no rotation path brings a catom to cell {c} of goal meta-module {m}"
            ),
        }
    }
}

/// One iteration's figures.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Iteration {
    pub sources: Vec<Meta>,
    pub destinations: Vec<(Meta, Meta)>,
    pub streamlines: Vec<Vec<Meta>>,
    pub first_step: usize,
    pub steps: usize,
    pub motions: usize,
    /// Whether the streamlines ran pipelined ([`super::pipeline`]) or,
    /// the pipeline failing, one catom at a time.
    pub pipelined: bool,
    /// What the paper's distributed protocol sends to do the same
    /// ([`super::messages`]).
    pub messages: Messages,
}

/// Which empty goal cells an iteration may assign to destinations.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Default)]
pub enum GoalOrder {
    /// The paper's rule (§V): every empty goal cell next to a SPARSE goal
    /// meta-module, one destination per cell and one cell per destination.
    #[default]
    Paper,
    /// Stricter, ours: a goal cell also waits until the cell below it is
    /// built (no meta-module hangs from its destination while it is
    /// assembled). On L → C: 11 iterations against the paper's 7.
    BottomUp,
    /// Stricter, ours: the paper's goal cells, but each is assembled from
    /// the neighbour that holds it best: the most catom–catom connectors
    /// to the new meta-module ([`Meta::joints`]: four from below, one from
    /// a side), then the most to the rest of the structure (the sources
    /// that leave in this iteration left out). The paper takes any SPARSE
    /// neighbour; one that itself hangs on one side connector then carries
    /// the new meta-module's catoms as well.
    Supported,
}

impl GoalOrder {
    /// Parses a scenario's `goal_order` parameter.
    pub fn parse(s: &str) -> Option<GoalOrder> {
        match s {
            "paper" => Some(GoalOrder::Paper),
            "bottom-up" => Some(GoalOrder::BottomUp),
            "supported" => Some(GoalOrder::Supported),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            GoalOrder::Paper => "paper",
            GoalOrder::BottomUp => "bottom-up",
            GoalOrder::Supported => "supported",
        }
    }
}

/// The plan: the initial catoms and the steps of rotations.
#[derive(Clone, Debug, Default)]
pub struct Plan {
    pub modules: Vec<Cell>,
    /// Per step: (module, pivot, hop).
    pub steps: Vec<Vec<(ModuleId, ModuleId, Hop)>>,
    pub iterations: Vec<Iteration>,
    /// Streamlines in use at each step (for Fig. 9).
    pub streamlines_at: Vec<usize>,
    pub ground: i32,
    /// The source rule that planned: `None` every leaf, `Some(w)` leaves
    /// within `w` BFS levels of the deepest (see [`plan`]).
    pub source_width: Option<usize>,
    /// The goal cells' order the plan was made with.
    pub goal_order: GoalOrder,
}

/// The cells of a meta-module's box: where its catoms and the catoms
/// flowing through it may be.
fn region(m: Meta) -> impl Iterator<Item = Cell> {
    let l = m.leader();
    (-1..=2).flat_map(move |x| {
        (-1..=1).flat_map(move |y| (0..=4).map(move |z| Cell::new(l.x + x, l.y + y, l.z + z)))
    })
}

/// The global coordinator: the lowest meta-module in both shapes.
fn coordinator(initial: &BTreeMap<Meta, State>, goal: &BTreeMap<Meta, State>) -> Option<Meta> {
    initial
        .keys()
        .filter(|m| goal.contains_key(m))
        .min_by_key(|m| (m.z, m.x, m.y))
        .copied()
}

/// Plans the reconfiguration from `initial` to `goal` (meta-module states:
/// a FULL goal meta-module is filled, the paper's compression).
///
/// Which leaves to dismantle first is the paper's free choice. Taking
/// every leaf can wall a source in: a SPARSE meta-module on the ground
/// between two others whose loops leave its catoms no rotation path out
/// (L→C: source (4, 0, −1) beside (5, 0, −1), its catoms reaching only 42
/// cells). So the plan is tried with every leaf as a source, then peeling
/// from the far end — only leaves within `w` BFS levels of the deepest,
/// `w` from the structure's depth down to 0 — and the first width that
/// plans is kept (`Plan::source_width`).
pub fn plan(
    initial: &BTreeMap<Meta, State>,
    goal: &BTreeMap<Meta, State>,
    rules: &dyn MotionRules,
    order: GoalOrder,
) -> Result<Plan, PlanError> {
    let first = match plan_with(initial, goal, rules, order, None) {
        Ok(p) => return Ok(p),
        Err(e @ (PlanError::Bound { .. } | PlanError::NoCoordinator)) => return Err(e),
        Err(e) => e,
    };
    let deepest = coordinator(initial, goal).map_or(0, |gc| {
        let tree = spanning_tree(|m| initial.contains_key(m), gc);
        tree.depth.into_values().max().unwrap_or(0)
    });
    for w in (0..deepest).rev() {
        if let Ok(p) = plan_with(initial, goal, rules, order, Some(w)) {
            return Ok(p);
        }
    }
    Err(first)
}

/// [`plan`] with sources restricted to leaves within `width` BFS levels of
/// the deepest leaf (`None`: every leaf).
fn plan_with(
    initial: &BTreeMap<Meta, State>,
    goal: &BTreeMap<Meta, State>,
    rules: &dyn MotionRules,
    order: GoalOrder,
    width: Option<usize>,
) -> Result<Plan, PlanError> {
    let held = |m: &BTreeMap<Meta, State>| -> usize {
        m.values()
            .map(|s| match s {
                State::Full => 20,
                State::Sparse => 10,
                State::Empty => 0,
            })
            .sum()
    };
    let catoms = held(initial);
    if goal.len() < catoms.div_ceil(20) || goal.len() > catoms / 10 {
        return Err(PlanError::Bound {
            catoms,
            goal: goal.len(),
        });
    }
    if held(goal) != catoms {
        return Err(PlanError::Catoms {
            initial: catoms,
            goal: held(goal),
        });
    }
    let gc = coordinator(initial, goal).ok_or(PlanError::NoCoordinator)?;
    let ground = 4 * initial.keys().map(|m| m.z).min().unwrap_or(0);
    let mut scene = Scene::new(Some(ground));
    let mut modules = Vec::new();
    for (m, st) in initial {
        for c in m.cells(*st) {
            scene.insert(modules.len() as ModuleId, c);
            modules.push(c);
        }
    }
    let mut state = initial.clone();
    let mut out = Plan {
        modules,
        ground,
        source_width: width,
        goal_order: order,
        ..Default::default()
    };
    loop {
        let empty: Vec<Meta> = goal
            .keys()
            .filter(|m| !state.contains_key(m))
            .copied()
            .collect();
        let extra: Vec<Meta> = state
            .keys()
            .filter(|m| !goal.contains_key(m))
            .copied()
            .collect();
        // FULL meta-modules the goal wants SPARSE or gone give their
        // filling; SPARSE ones the goal wants FULL are to be filled.
        let full: Vec<Meta> = state
            .iter()
            .filter(|(m, st)| **st == State::Full && goal.get(m) != Some(&State::Full))
            .map(|(m, _)| *m)
            .collect();
        let to_fill: Vec<Meta> = state
            .iter()
            .filter(|(m, st)| **st == State::Sparse && goal.get(m) == Some(&State::Full))
            .map(|(m, _)| *m)
            .collect();
        if empty.is_empty() && extra.is_empty() && full.is_empty() && to_fill.is_empty() {
            return Ok(out);
        }
        // 1. Sources: leaves of the BFS tree from the coordinator outside
        // the goal, and every FULL meta-module the goal does not want FULL
        // (emptied to SPARSE, its loop stays: nothing disconnects).
        let tree = spanning_tree(|m| state.contains_key(m), gc);
        let (depth, children) = (&tree.depth, &tree.children);
        let mut sources: Vec<Meta> = extra
            .iter()
            .filter(|m| children.get(m).copied().unwrap_or(0) == 0 && state[m] == State::Sparse)
            .copied()
            .collect();
        if let Some(w) = width {
            // A source the tree does not reach (a disconnected input) has
            // no level; it counts as the coordinator's.
            let level = |m: &Meta| depth.get(m).copied().unwrap_or(0);
            let deepest = sources.iter().map(level).max().unwrap_or(0);
            sources.retain(|m| level(m) + w >= deepest);
        }
        sources.extend(&full);
        // 2. Destinations: one per empty goal cell, lowest cells first.
        // Bottom-up (not the paper's): a goal cell whose cell below is
        // empty waits.
        let low = goal.keys().map(|m| m.z).min().unwrap_or(0);
        let mut empty_sorted: Vec<Meta> = empty
            .iter()
            .filter(|m| {
                order != GoalOrder::BottomUp
                    || m.z == low
                    || state.contains_key(&m.step(super::metamodule::Direction::Down))
            })
            .copied()
            .collect();
        if empty_sorted.is_empty() {
            empty_sorted = empty.clone();
        }
        empty_sorted.sort_by_key(|m| (m.z, m.x, m.y));
        let mut taken: FxHashSet<Meta> = FxHashSet::default();
        let mut destinations: Vec<(Meta, Meta)> = Vec::new();
        for e in &empty_sorted {
            let mut candidates = e.adjacent().filter(|d| {
                goal.contains_key(d) && state.get(d) == Some(&State::Sparse) && !taken.contains(d)
            });
            let chosen = if order == GoalOrder::Supported {
                // The first of the best, so ties keep the paper's choice;
                // this iteration's SPARSE sources leave while `e` is
                // assembled (a FULL one stays, SPARSE).
                let stays = |n: &Meta| match state.get(n) {
                    Some(State::Sparse) => !sources.contains(n),
                    Some(State::Full) => true,
                    _ => false,
                };
                let held = |d: &Meta| {
                    let rest: usize = d
                        .adjacent()
                        .filter(|n| n != e && stays(n))
                        .map(|n| d.joints(n))
                        .sum();
                    (d.joints(*e), rest)
                };
                candidates.fold(None, |best: Option<Meta>, d| match best {
                    Some(b) if held(&b) >= held(&d) => Some(b),
                    _ => Some(d),
                })
            } else {
                candidates.next()
            };
            if let Some(d) = chosen {
                taken.insert(d);
                destinations.push((d, *e));
            }
        }
        // Filling destinations (compression), lowest first: `(d, d)`, the
        // catoms go into d's interior.
        let mut to_fill = to_fill;
        to_fill.sort_by_key(|m| (m.z, m.x, m.y));
        for d in to_fill {
            if taken.insert(d) {
                destinations.push((d, d));
            }
        }
        // 3. Streamlines by max-flow with unit vertex capacities, and
        // 4. transport. A streamline whose catoms find no rotation path is
        // deferred: its source is left out and the flow recomputed, the
        // streamlines already planned kept (a source can be walled in by
        // a neighbour that a later iteration dismantles first).
        let first_step = out.steps.len();
        let before = scene.clone();
        let present = state.clone();
        let mut lanes: Vec<Vec<Vec<Hop>>> = Vec::new();
        let mut planned: Vec<Vec<Meta>> = Vec::new();
        let mut deferred: FxHashSet<Meta> = FxHashSet::default();
        let mut stuck = None;
        loop {
            let open: Vec<Meta> = sources
                .iter()
                .filter(|m| !deferred.contains(m) && state.contains_key(m))
                .copied()
                .collect();
            let open_dest: Vec<(Meta, Meta)> = destinations
                .iter()
                .filter(|(d, e)| {
                    if d == e {
                        state.get(d) == Some(&State::Sparse)
                    } else {
                        !state.contains_key(e)
                    }
                })
                .copied()
                .collect();
            let lines = streamlines(&state, &open, &open_dest);
            if lines.is_empty() {
                break;
            }
            let mut progress = false;
            for line in lines {
                let (src, dst) = (line[0], *line.last().expect("a streamline has an end"));
                let goal_meta = open_dest
                    .iter()
                    .find(|(d, _)| *d == dst)
                    .map(|(_, e)| *e)
                    .expect("a destination has its goal cell");
                let fill = goal_meta == dst;
                match transport(&scene, &line, state[&src], goal_meta, fill) {
                    Ok(paths) => {
                        // The next streamline plans against this one's end state.
                        for p in &paths {
                            let (a, b) = (p[0].from, p[p.len() - 1].to);
                            let id = scene.at.remove(&a).expect("mover in place");
                            scene.insert(id, b);
                        }
                        lanes.push(paths);
                        if state[&src] == State::Full {
                            state.insert(src, State::Sparse);
                        } else {
                            state.remove(&src);
                        }
                        state.insert(goal_meta, if fill { State::Full } else { State::Sparse });
                        planned.push(line);
                        progress = true;
                    }
                    Err(c) => {
                        stuck.get_or_insert((goal_meta, c));
                        deferred.insert(src);
                    }
                }
            }
            if progress {
                break;
            }
        }
        if planned.is_empty() {
            return Err(match stuck {
                Some((m, c)) => PlanError::Stuck(m, c),
                None => PlanError::Unreachable(
                    empty_sorted
                        .first()
                        .or(extra.first())
                        .copied()
                        .unwrap_or(gc),
                ),
            });
        }
        let streamlines = planned;
        let motions: usize = lanes.iter().flatten().map(Vec::len).sum();
        scene = before.clone();
        let pipelined = match pipeline(&before, &lanes, rules) {
            Some(p) => {
                emit(&mut scene, p.steps, p.lanes_at, &mut out);
                true
            }
            None => {
                // No pipeline (a catom that fits nowhere): run the
                // streamlines one after another, the order they were
                // planned in (valid by construction).
                for lane in lanes {
                    let steps: Vec<Vec<Hop>> =
                        lane.into_iter().flatten().map(|h| vec![h]).collect();
                    let n = steps.len();
                    emit(&mut scene, steps, vec![1; n], &mut out);
                }
                false
            }
        };
        let messages = messages::count(&IterationRecord {
            present: &present,
            tree: &tree,
            sources: &sources,
            streamlines: &streamlines,
            cells: &before.at,
            steps: &out.steps[first_step..],
        });
        out.iterations.push(Iteration {
            messages,
            sources,
            destinations: streamlines
                .iter()
                .map(|l| {
                    let d = *l.last().expect("non-empty");
                    *destinations.iter().find(|x| x.0 == d).expect("listed")
                })
                .collect(),
            steps: out.steps.len() - first_step,
            first_step,
            motions,
            pipelined,
            streamlines: streamlines.clone(),
        });
    }
}

/// The paths of a streamline's ten catoms to the goal meta-module's loop
/// (its interior, if `fill`), planned against `scene`: inside the
/// streamline's meta-module boxes first, then with one cell of margin,
/// then anywhere in the structure's
/// box grown by three cells (the ground cells of a goal beside the
/// structure may be reachable only around it); strictly (no sliding
/// contact) first in each. On failure, the first goal cell left unfilled.
fn transport(
    scene: &Scene,
    line: &[Meta],
    source: State,
    goal_meta: Meta,
    fill: bool,
) -> Result<Vec<Vec<Hop>>, Cell> {
    // A FULL source gives its ten filling catoms; a SPARSE one its loop.
    let from = if source == State::Full {
        line[0].filling_cells()
    } else {
        line[0].sparse_cells()
    };
    let targets = if fill {
        goal_meta.filling_cells()
    } else {
        goal_meta.sparse_cells()
    };
    // The loop in its own order (each catom latches the one before); an
    // interior in the orders the operations were derived with.
    let orders: Vec<Vec<Cell>> = if fill {
        super::operations::orders(&targets)
            .into_iter()
            .map(|(_, o)| o)
            .collect()
    } else {
        vec![targets.to_vec()]
    };
    // An interior the first budget does not fill in any region, mode or
    // order is tried again with the deep one (filling from the side).
    let budgets: &[usize] = if fill {
        &[FILL_SEARCH_BUDGET, DEEP_SEARCH_BUDGET]
    } else {
        &[SEARCH_BUDGET]
    };
    let mut last = targets[0];
    for (budget, margin) in budgets
        .iter()
        .flat_map(|&b| [Some(0), Some(1), None].map(|m| (b, m)))
    {
        let mut s = scene.clone();
        match margin {
            Some(margin) => {
                let mut reg: FxHashSet<Cell> = FxHashSet::default();
                for m in line.iter().chain([&goal_meta]) {
                    for c in region(*m) {
                        for dx in -margin..=margin {
                            for dy in -margin..=margin {
                                reg.insert(Cell::new(c.x + dx, c.y + dy, c.z));
                            }
                        }
                    }
                }
                s.region = Some(reg);
            }
            None => s.fit_box(&targets, 3),
        }
        for strict in [true, false] {
            for order in &orders {
                match move_catoms(&mut s.clone(), &from, order, strict, budget) {
                    Ok(p) => return Ok(p),
                    Err(c) => last = c,
                }
            }
        }
    }
    Err(last)
}

/// Vertex-disjoint source → destination paths of maximum number.
fn streamlines(
    state: &BTreeMap<Meta, State>,
    sources: &[Meta],
    destinations: &[(Meta, Meta)],
) -> Vec<Vec<Meta>> {
    let mut g: DiGraph<(), u32> = DiGraph::new();
    let s = g.add_node(());
    let t = g.add_node(());
    let mut io: BTreeMap<Meta, (NodeIndex, NodeIndex)> = BTreeMap::new();
    for (m, st) in state {
        // FULL meta-modules are never crossed; a FULL source only starts
        // a streamline (no edge leads into it, below).
        if *st == State::Full && !sources.contains(m) {
            continue;
        }
        let i = g.add_node(());
        let o = g.add_node(());
        g.add_edge(i, o, 1);
        io.insert(*m, (i, o));
    }
    for (m, (_, o)) in &io {
        for n in m.adjacent() {
            if state.get(&n) == Some(&State::Full) {
                continue;
            }
            if let Some((i2, _)) = io.get(&n) {
                g.add_edge(*o, *i2, 1);
            }
        }
    }
    for m in sources {
        if let Some((i, _)) = io.get(m) {
            g.add_edge(s, *i, 1);
        }
    }
    for (d, _) in destinations {
        if let Some((_, o)) = io.get(d) {
            g.add_edge(*o, t, 1);
        }
    }
    let (_, flows) = petgraph::algo::dinics(&g, s, t);
    // Follow the unit flows from each source.
    let node_meta: FxHashMap<NodeIndex, Meta> = io.iter().map(|(m, (i, _))| (*i, *m)).collect();
    let out_of: FxHashMap<NodeIndex, Meta> = io.iter().map(|(m, (_, o))| (*o, *m)).collect();
    let mut next: FxHashMap<NodeIndex, NodeIndex> = FxHashMap::default();
    for e in g.edge_indices() {
        if flows[e.index()] > 0 {
            let (a, b) = g.edge_endpoints(e).expect("edge exists");
            next.insert(a, b);
        }
    }
    let mut lines = Vec::new();
    for e in g.edges(s) {
        use petgraph::visit::EdgeRef;
        if flows[e.id().index()] == 0 {
            continue;
        }
        let mut line = Vec::new();
        let mut at = e.target();
        while at != t {
            if let Some(m) = node_meta.get(&at) {
                line.push(*m);
            }
            let _ = out_of.get(&at);
            at = next[&at];
        }
        lines.push(line);
    }
    lines.sort();
    lines
}

/// Appends `steps` of rotations to the plan, naming each mover and pivot
/// by the module in its cell.
fn emit(scene: &mut Scene, steps: Vec<Vec<Hop>>, lanes_at: Vec<usize>, out: &mut Plan) {
    for (step, lanes) in steps.into_iter().zip(lanes_at) {
        let mut events = Vec::new();
        for h in step {
            let id = scene.at.remove(&h.from).expect("the mover is in place");
            let pivot = scene.at[&h.pivot];
            events.push((id, pivot, h));
        }
        for (id, _, h) in &events {
            scene.insert(*id, h.to);
        }
        out.streamlines_at.push(lanes);
        out.steps.push(events);
    }
}
