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
//!    the pipeline. In [`GoalOrder::Paired`] two goal cells of a row are
//!    transported together (`transport_pair`), their lanes interleaved.

use super::messages::{self, IterationRecord, Messages};
use super::metamodule::{Meta, State, spanning_tree};
use super::operations::{
    DEEP_SEARCH_BUDGET, FILL_SEARCH_BUDGET, SEARCH_BUDGET, move_catoms, move_catoms_in_order,
};
use super::pipeline::{Commit, pipeline_commits};
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
    /// Stricter still, ours: [`GoalOrder::Supported`], and a goal cell
    /// that would hang on one side connector (no other joint to what
    /// stays) is assembled together with a side neighbour in the goal,
    /// each loop grown from its holder towards the other along the
    /// shorter arc (either way where the joints are opposite), catom by
    /// catom in the arc's order, and neither completed before the two
    /// arcs have met
    /// (a SPARSE meta-module alone on one connector along Y breaks it at
    /// 100 kPa; the pair holds with margin: `docs/repost.md`). A cell
    /// whose partner gets no streamline in an iteration waits for one,
    /// unless nothing else would move. Every goal loop is filled from its
    /// lowest cells, and a pair's arcs take their source's highest
    /// catoms first, so that nothing hangs by its side joints while it
    /// grows or is taken down (the L → C-20 certifies at 100 kPa).
    Paired,
}

impl GoalOrder {
    /// Parses a scenario's `goal_order` parameter.
    pub fn parse(s: &str) -> Option<GoalOrder> {
        match s {
            "paper" => Some(GoalOrder::Paper),
            "bottom-up" => Some(GoalOrder::BottomUp),
            "supported" => Some(GoalOrder::Supported),
            "paired" => Some(GoalOrder::Paired),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            GoalOrder::Paper => "paper",
            GoalOrder::BottomUp => "bottom-up",
            GoalOrder::Supported => "supported",
            GoalOrder::Paired => "paired",
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

/// `scene` confined to the transport region: the boxes of `metas` grown
/// by `margin` cells in x and y, or with `None` the structure's box with
/// `targets`, grown by three cells.
fn within<'a>(
    scene: &Scene,
    metas: impl Iterator<Item = &'a Meta>,
    margin: Option<i32>,
    targets: &[Cell],
) -> Scene {
    let mut s = scene.clone();
    match margin {
        Some(margin) => {
            let mut reg: FxHashSet<Cell> = FxHashSet::default();
            for m in metas {
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
        None => s.fit_box(targets, 3),
    }
    s
}

/// Whether meta-module `n` stays through an iteration with these
/// `sources`: a SPARSE one unless it is a source (it leaves while the
/// iteration's goal cells are assembled), a FULL one always (only its
/// filling leaves; it stays, SPARSE).
fn stays(state: &BTreeMap<Meta, State>, sources: &[Meta], n: &Meta) -> bool {
    match state.get(n) {
        Some(State::Sparse) => !sources.contains(n),
        Some(State::Full) => true,
        _ => false,
    }
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
    // Meta-modules on this layer rest on the ground: none hangs.
    let floor = initial.keys().map(|m| m.z).min().unwrap_or(0);
    // Each goal cell's distance from the coordinator inside the goal.
    let reach = spanning_tree(|m| goal.contains_key(m), gc).depth;
    let ground = 4 * floor;
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
            let chosen = if matches!(order, GoalOrder::Supported | GoalOrder::Paired) {
                // The first of the best, so ties keep the paper's choice.
                let held = |d: &Meta| {
                    let rest: usize = d
                        .adjacent()
                        .filter(|n| n != e && stays(&state, &sources, n))
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
        // Lanes assembled as pairs: (first lane, the commit order of
        // their paths).
        let mut pair_commits: Vec<(usize, Vec<PairCommit>)> = Vec::new();
        let mut planned: Vec<Vec<Meta>> = Vec::new();
        let mut deferred: FxHashSet<Meta> = FxHashSet::default();
        let partners = |e: Meta| -> Vec<Meta> {
            if order != GoalOrder::Paired || e.z == floor || present.contains_key(&e) {
                return Vec::new();
            }
            let held: usize = e
                .adjacent()
                .filter(|n| stays(&present, &sources, n))
                .map(|n| e.joints(n))
                .sum();
            if held > 1 {
                return Vec::new();
            }
            e.adjacent()
                .filter(|p| {
                    p.z == e.z
                        && goal.contains_key(p)
                        && !present.contains_key(p)
                        && destinations.iter().any(|(d, g)| g == p && d != g)
                })
                .collect()
        };
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
            let open_dest = if order == GoalOrder::Paired {
                paired_first(&state, &open, &open_dest, &partners, &reach)
            } else {
                open_dest
            };
            let mut lines = streamlines(&state, &open, &open_dest);
            if lines.is_empty() {
                break;
            }
            if order == GoalOrder::Paired {
                // A source resting on another goes first (below).
                lines.sort_by_key(|l| std::cmp::Reverse(l[0].z));
            }
            let goal_of = |line: &[Meta]| {
                let dst = *line.last().expect("a streamline has an end");
                open_dest
                    .iter()
                    .find(|(d, _)| *d == dst)
                    .map(|(_, e)| *e)
                    .expect("a destination has its goal cell")
            };
            let served: Vec<Meta> = lines.iter().map(|l| goal_of(l)).collect();
            let mut progress = false;
            let mut paired: FxHashSet<Meta> = FxHashSet::default();
            for (k, line) in lines.iter().enumerate() {
                let src = line[0];
                let goal_meta = served[k];
                if paired.contains(&goal_meta) {
                    continue;
                }
                // Its partner's streamline, when both are to be assembled
                // now: the two loops grow towards each other.
                let sparse = |l: &[Meta]| state.get(&l[0]) == Some(&State::Sparse);
                let mate = partners(goal_meta).into_iter().find_map(|p| {
                    let j = served.iter().position(|e| *e == p)?;
                    (j != k && !paired.contains(&p) && sparse(line) && sparse(&lines[j]))
                        .then_some(j)
                });
                if let Some(j) = mate {
                    let (other, partner) = (&lines[j], served[j]);
                    if let Some((a, b, commit)) =
                        transport_pair(&scene, line, goal_meta, other, partner)
                    {
                        for p in a.iter().chain(&b) {
                            let (x, y) = (p[0].from, p[p.len() - 1].to);
                            let id = scene.at.remove(&x).expect("mover in place");
                            scene.insert(id, y);
                        }
                        let base = lanes.len();
                        pair_commits.push((base, commit));
                        lanes.push(a);
                        lanes.push(b);
                        for (l, g) in [(line, goal_meta), (other, partner)] {
                            state.remove(&l[0]);
                            state.insert(g, State::Sparse);
                            planned.push(l.clone());
                            paired.insert(g);
                        }
                        progress = true;
                        continue;
                    }
                }
                let line = line.clone();
                let fill = goal_meta == *line.last().expect("a streamline has an end");
                let lowest_first = order == GoalOrder::Paired;
                match transport(&scene, &line, state[&src], goal_meta, fill, lowest_first) {
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
        // `Paired`: a source resting on another source is dismantled
        // before the one under it sets off, which would otherwise leave
        // its last catoms hanging from its side neighbours.
        let waits: Vec<(usize, usize)> = if order == GoalOrder::Paired {
            (0..streamlines.len())
                .filter_map(|l| {
                    let up = streamlines[l][0].step(super::metamodule::Direction::Up);
                    let u = streamlines.iter().position(|p| p[0] == up)?;
                    (u < l).then_some((l, u))
                })
                .collect()
        } else {
            Vec::new()
        };
        let commits = commit_order(&lanes, &pair_commits, &waits);
        let pipelined = match pipeline_commits(&before, &commits, rules) {
            Some(p) => {
                emit(&mut scene, p.steps, p.lanes_at, &mut out);
                true
            }
            None => {
                // No pipeline (a catom that fits nowhere): run the
                // catoms one after another, in the order they were
                // planned (valid by construction).
                let steps: Vec<Vec<Hop>> = commits
                    .into_iter()
                    .flat_map(|c| c.path)
                    .map(|h| vec![h])
                    .collect();
                let n = steps.len();
                emit(&mut scene, steps, vec![1; n], &mut out);
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
    lowest_first: bool,
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
    } else if lowest_first {
        // `Paired`: the lowest cells first (in loop order within a
        // layer), so that a loop reaches what is below it, the ground or
        // the meta-module under it, before it grows far from its joint;
        // where no catom finds that order, the loop's own.
        let mut t = targets.to_vec();
        t.sort_by_key(|c| c.z);
        vec![t, targets.to_vec()]
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
        let s = within(scene, line.iter().chain([&goal_meta]), margin, &targets);
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

/// The destinations of a `GoalOrder::Paired` iteration, chosen greedily
/// (the sets of destinations that vertex-disjoint streamlines can serve
/// together form a matroid, a gammoid, so the choice is maximal; a pair
/// taken only whole can leave a cell unserved that the plain maximum
/// flow would serve): first each pair of cells that would
/// hang on one side connector alone, both or neither; then the other
/// cells, those farthest from the coordinator first (the arms' far rows
/// get their holders while sources remain to assemble them as pairs). A
/// cell that would hang alone and has no partner to go with waits; if
/// nothing else can be served, every destination is open, as in the paper.
fn paired_first(
    state: &BTreeMap<Meta, State>,
    open: &[Meta],
    open_dest: &[(Meta, Meta)],
    partners: &dyn Fn(Meta) -> Vec<Meta>,
    reach: &FxHashMap<Meta, usize>,
) -> Vec<(Meta, Meta)> {
    let mut units: Vec<Vec<(Meta, Meta)>> = Vec::new();
    for &(d, e) in open_dest {
        for p in partners(e) {
            if let Some(&dp) = open_dest.iter().find(|(_, g)| *g == p)
                && e < p
            {
                units.push(vec![(d, e), dp]);
            }
        }
    }
    let mut singles: Vec<(Meta, Meta)> = open_dest
        .iter()
        .filter(|(_, e)| partners(*e).is_empty())
        .copied()
        .collect();
    singles.sort_by_key(|(_, e)| std::cmp::Reverse(reach.get(e).copied().unwrap_or(0)));
    units.extend(singles.into_iter().map(|x| vec![x]));
    let mut chosen: Vec<(Meta, Meta)> = Vec::new();
    for u in units {
        if u.iter()
            .any(|x| chosen.iter().any(|c| c.0 == x.0 || c.1 == x.1))
        {
            continue;
        }
        let mut trial = chosen.clone();
        trial.extend(&u);
        if streamlines(state, open, &trial).len() == trial.len() {
            chosen = trial;
        }
    }
    if chosen.is_empty() {
        open_dest.to_vec()
    } else {
        chosen
    }
}

/// A path of a pair assembled together ([`transport_pair`]): which of
/// the two lanes, its index there, and the earlier paths of the pair (by
/// their place in the pair's order) that must have arrived first.
#[derive(Clone, Debug)]
struct PairCommit {
    second: bool,
    index: usize,
    after: Vec<usize>,
}

/// A pair's paths: the first lane's, the second's, and their order.
type PairPaths = (Vec<Vec<Hop>>, Vec<Vec<Hop>>, Vec<PairCommit>);

/// Every lane's paths in the order they were planned: lane after lane,
/// but a pair's two lanes (`pairs`: first lane, order) interleaved; a
/// lane of `waits` (lane, earlier lane) sets off only once the earlier
/// lane's catoms have all arrived.
fn commit_order(
    lanes: &[Vec<Vec<Hop>>],
    pairs: &[(usize, Vec<PairCommit>)],
    waits: &[(usize, usize)],
) -> Vec<Commit> {
    let mut out: Vec<Commit> = Vec::new();
    let mut lane = 0;
    while lane < lanes.len() {
        if let Some((_, order)) = pairs.iter().find(|(first, _)| *first == lane) {
            let start = out.len();
            for c in order {
                let l = lane + usize::from(c.second);
                out.push(Commit {
                    lane: l,
                    path: lanes[l][c.index].clone(),
                    after: c.after.iter().map(|i| start + i).collect(),
                });
            }
            lane += 2;
        } else {
            out.extend(lanes[lane].iter().map(|p| Commit {
                lane,
                path: p.clone(),
                after: Vec::new(),
            }));
            lane += 1;
        }
    }
    for &(l, u) in waits {
        let Some(last) = out.iter().rposition(|c| c.lane == u) else {
            continue;
        };
        for c in out.iter_mut().skip(last + 1).filter(|c| c.lane == l) {
            c.after.push(last);
        }
    }
    out
}

/// The loop of `e` split for a pair: the arc from its cell joined to
/// `holder` to its cell joined to `partner`, the shorter way round (both
/// ends included; both ways where the two joints are opposite on the
/// loop), then the rest of the loop onwards from the arc's end. Empty
/// unless each is joined by exactly one cell (side neighbours).
fn arcs(e: Meta, holder: Meta, partner: Meta) -> Vec<(Vec<Cell>, Vec<Cell>)> {
    use crate::lattice::{FccLattice, Lattice};
    let cells = e.sparse_cells();
    let joined = |m: Meta| {
        let other = m.sparse_cells();
        let mut at = (0..10).filter(|&i| {
            other
                .iter()
                .any(|c| FccLattice.are_neighbours(cells[i], *c))
        });
        let i = at.next()?;
        at.next().is_none().then_some(i)
    };
    let (Some(a), Some(b)) = (joined(holder), joined(partner)) else {
        return Vec::new();
    };
    let forward = (b + 10 - a) % 10;
    let steps: &[usize] = match forward {
        5 => &[1, 9],
        f if f < 5 => &[1],
        _ => &[9],
    };
    steps
        .iter()
        .filter_map(|&step| {
            let mut arc = vec![a];
            let mut i = a;
            while i != b {
                i = (i + step) % 10;
                arc.push(i);
            }
            let mut rest = Vec::new();
            i = (b + step) % 10;
            while i != a {
                rest.push(i);
                i = (i + step) % 10;
            }
            let order: Vec<usize> = arc.iter().chain(&rest).copied().collect();
            // Each catom latches the one before it (the loop's own order).
            let linked = order
                .windows(2)
                .all(|w| w[1] == arc[0] || FccLattice.are_neighbours(cells[w[0]], cells[w[1]]));
            linked.then(|| {
                (
                    arc.iter().map(|&i| cells[i]).collect(),
                    rest.iter().map(|&i| cells[i]).collect(),
                )
            })
        })
        .collect()
}

/// Two SPARSE goal meta-modules side by side, each hanging on one side
/// connector from its destination, assembled together: each streamline's
/// catoms first build the arc of its loop towards the other, then the
/// rest, which sets off only once both arcs are in place (so neither
/// meta-module hangs complete, or nearly, on its connector alone). The
/// paths of each lane and their order; `None` if the split does not
/// apply or no region or mode finds it (then each is transported alone).
fn transport_pair(
    scene: &Scene,
    line_a: &[Meta],
    a: Meta,
    line_b: &[Meta],
    b: Meta,
) -> Option<PairPaths> {
    let (arcs_a, arcs_b) = (arcs(a, *line_a.last()?, b), arcs(b, *line_b.last()?, a));
    let (from_a, from_b) = (line_a[0].sparse_cells(), line_b[0].sparse_cells());
    // Either way round where the joints are opposite, and each rest
    // grown from either end of its arc: from the partner's joint onwards
    // or from the holder's joint back.
    let backwards = |r: &[Cell]| r.iter().rev().copied().collect::<Vec<Cell>>();
    let mut splits: Vec<[Vec<Cell>; 4]> = Vec::new();
    for (arc_a, rest_a) in &arcs_a {
        for (arc_b, rest_b) in &arcs_b {
            for (ra, rb) in [
                (rest_a.clone(), rest_b.clone()),
                (backwards(rest_a), backwards(rest_b)),
                (rest_a.clone(), backwards(rest_b)),
                (backwards(rest_a), rest_b.clone()),
            ] {
                splits.push([arc_a.clone(), ra, arc_b.clone(), rb]);
            }
        }
    }
    // The regions of `transport`, widening; in each, strictly first.
    let all: Vec<Cell> = a
        .sparse_cells()
        .into_iter()
        .chain(b.sparse_cells())
        .collect();
    let tries: Vec<(Scene, bool)> = [Some(0), Some(1), None]
        .into_iter()
        .flat_map(|margin| {
            let metas = line_a.iter().chain(line_b).chain([&a, &b]);
            let s = within(scene, metas, margin, &all);
            [true, false].map(|strict| (s.clone(), strict))
        })
        .collect();
    // Each source taken down from its top where that finds a split, else
    // by the shortest paths; then the fewest catoms of one loop before the
    // other's arc joins it (none beyond its own arc if the paths allow, at
    // most `PAIR_EARLY` more), in any region; else each is transported
    // alone.
    for top_first in [true, false] {
        for k in 0..=PAIR_EARLY {
            for (s, strict) in &tries {
                for swap in [false, true] {
                    for [arc_a, ra, arc_b, rb] in &splits {
                        let (x, y) = (
                            (&from_a, &arc_a[..], &ra[..]),
                            (&from_b, &arc_b[..], &rb[..]),
                        );
                        let (x, y) = if swap { (y, x) } else { (x, y) };
                        let Some((px, py, mut order)) =
                            split(s, x, y, k, *strict, SEARCH_BUDGET, top_first)
                        else {
                            continue;
                        };
                        if swap {
                            for c in &mut order {
                                c.second = !c.second;
                            }
                            return Some((py, px, order));
                        }
                        return Some((px, py, order));
                    }
                }
            }
        }
    }
    None
}

/// How many catoms of one loop's rest [`transport_pair`] may place
/// before the other's arc joins it: beyond that the first loop hangs
/// nearly complete on its connector anyway, and the failing searches
/// cost seconds each.
const PAIR_EARLY: usize = 3;

/// One try of [`transport_pair`]: `x`'s arc and the first `k` cells of
/// its rest, then `y`'s arc (the joint), then the rest of both, which
/// wait for the joint. Each side is (source cells, arc, rest).
fn split(
    scene: &Scene,
    x: (&[Cell; 10], &[Cell], &[Cell]),
    y: (&[Cell; 10], &[Cell], &[Cell]),
    k: usize,
    strict: bool,
    budget: usize,
    top_first: bool,
) -> Option<PairPaths> {
    if k > x.2.len() {
        return None;
    }
    let left = |t: &Scene, from: &[Cell; 10]| -> Vec<Cell> {
        from.iter()
            .copied()
            .filter(|c| t.at.contains_key(c))
            .collect()
    };
    // Until the two arcs meet, each grows strictly in its order from its
    // holder's joint: a cell filled out of order would hang its catom,
    // and those after it, on whatever it touches first, the other
    // loop's tip (both loops, twelve catoms, on one connector). After
    // the joint the rests may fill in any order: both loops are held at
    // both ends.
    let mut t = scene.clone();
    let mut px = move_catoms_in_order(&mut t, x.0, x.1, strict, budget, top_first).ok()?;
    let from = left(&t, x.0);
    px.extend(move_catoms_in_order(&mut t, &from, &x.2[..k], strict, budget, top_first).ok()?);
    let py = move_catoms_in_order(&mut t, y.0, y.1, strict, budget, top_first).ok()?;
    let from = left(&t, x.0);
    let rx = move_catoms(&mut t, &from, &x.2[k..], strict, budget).ok()?;
    let from = left(&t, y.0);
    let ry = move_catoms(&mut t, &from, y.2, strict, budget).ok()?;
    let met = vec![px.len() - 1, px.len() + py.len() - 1];
    let mut order = Vec::new();
    let mut push = |second: bool, range: std::ops::Range<usize>, after: &[usize]| {
        for index in range {
            order.push(PairCommit {
                second,
                index,
                after: after.to_vec(),
            });
        }
    };
    push(false, 0..px.len(), &[]);
    push(true, 0..py.len(), &[]);
    push(false, px.len()..px.len() + rx.len(), &met);
    push(true, py.len()..py.len() + ry.len(), &met);
    let lane_x = px.into_iter().chain(rx).collect();
    let lane_y = py.into_iter().chain(ry).collect();
    Some((lane_x, lane_y, order))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::{FccLattice, Lattice};

    /// The side joints of two meta-modules of the C's top arm, found here
    /// by scanning every pair of cells: the arc runs from the cell that
    /// touches the holder to the cell that touches the partner, each cell
    /// touching the one before, and the rest closes the loop.
    #[test]
    fn a_pair_s_loop_grows_from_its_holder_to_its_partner_along_the_loop() {
        let touching = |c: Cell, m: Meta| {
            m.sparse_cells()
                .iter()
                .any(|x| FccLattice.are_neighbours(c, *x))
        };
        // In the rows next to the C's spine the two joints are opposite on
        // the loop; in the tip row (x, 3, 5) one cell touches both.
        let m = Meta::new;
        for (e, holder, partner, arc_len) in [
            (m(1, 2, 4), m(1, 1, 4), m(0, 2, 4), 6),
            (m(0, 2, 4), m(0, 1, 4), m(1, 2, 4), 6),
            (m(1, 3, 5), m(1, 2, 5), m(0, 3, 5), 1),
            (m(0, 2, 0), m(0, 1, 0), m(1, 2, 0), 6),
        ] {
            let ways = arcs(e, holder, partner);
            assert_eq!(
                ways.len(),
                if arc_len == 6 { 2 } else { 1 },
                "{e}: both ways when opposite"
            );
            for (arc, rest) in ways {
                assert_eq!(arc.len(), arc_len, "{e}");
                assert!(touching(arc[0], holder) && touching(arc[arc.len() - 1], partner));
                let whole: Vec<Cell> = arc.iter().chain(&rest).copied().collect();
                let mut sorted = whole.clone();
                sorted.sort_by_key(|c| (c.x, c.y, c.z));
                let mut cells = e.sparse_cells().to_vec();
                cells.sort_by_key(|c| (c.x, c.y, c.z));
                assert_eq!(sorted, cells, "{e}: every cell once");
                // Each catom latches to one already placed.
                for i in 1..whole.len() {
                    assert!(
                        whole[..i]
                            .iter()
                            .any(|c| FccLattice.are_neighbours(*c, whole[i])),
                        "{e}: cell {i}"
                    );
                }
                // Only the arc's ends touch the holder and the partner.
                assert_eq!(whole.iter().filter(|c| touching(**c, holder)).count(), 1);
                assert_eq!(whole.iter().filter(|c| touching(**c, partner)).count(), 1);
            }
        }
        // Stacked meta-modules touch through four cells: no arc.
        assert!(arcs(Meta::new(0, 0, 1), Meta::new(0, 0, 0), Meta::new(1, 0, 1)).is_empty());
    }

    /// Two goal cells that would each hang on one side connector go to
    /// streamlines together or not at all; a single goal cell is served
    /// instead when only one source can move, and with nothing else the
    /// paper's destinations stay open.
    #[test]
    fn the_paired_order_serves_a_hanging_pair_both_or_neither() {
        let m = Meta::new;
        let mut state: BTreeMap<Meta, State> = BTreeMap::new();
        for x in [-1, 0, 1, 2] {
            state.insert(m(x, 0, 0), State::Sparse);
        }
        state.insert(m(0, 0, 1), State::Sparse);
        state.insert(m(1, 0, 1), State::Sparse);
        let (a, b, floor_cell) = (m(0, 1, 1), m(1, 1, 1), m(1, 1, 0));
        let dest = [(m(0, 0, 1), a), (m(1, 0, 1), b), (m(1, 0, 0), floor_cell)];
        let partners = |e: Meta| -> Vec<Meta> {
            match e {
                e if e == a => vec![b],
                e if e == b => vec![a],
                _ => Vec::new(),
            }
        };
        let reach: FxHashMap<Meta, usize> = [(a, 3), (b, 3), (floor_cell, 2)].into_iter().collect();
        let both = [m(-1, 0, 0), m(2, 0, 0)];
        let chosen = paired_first(&state, &both, &dest, &partners, &reach);
        assert_eq!(chosen, vec![dest[0], dest[1]], "two sources: the pair");
        let one = [m(2, 0, 0)];
        let chosen = paired_first(&state, &one, &dest, &partners, &reach);
        assert_eq!(chosen, vec![dest[2]], "one source: not half a pair");
        let chosen = paired_first(&state, &one, &dest[..2], &partners, &reach);
        assert_eq!(chosen, dest[..2].to_vec(), "nothing else: the paper's");
    }
}
