//! A `meta_modules` schedule (seed 004's 2×2×2 meta-modules on the cubic
//! lattice) expanded into the atom operations that realise it, so that it
//! is certified atom by atom and never on trust.
//!
//! * `slide` with a `pivot` (the wall B; C is the meta-module beside B in
//!   the slide direction): the SLIDE that [`crate::geometry::atom_search`]
//!   derives (the expanded model's stored by
//!   [`crate::geometry::stored_move`] and replayed on load; between two
//!   walls, in the expanded model, that SLIDE run one layer at a time),
//!   turned to the move's direction and wall by the lattice symmetry that
//!   maps the canonical slide (−x along a wall at −y) onto it.
//!   Every slide of one meta-level step runs in lockstep, shifted so that
//!   the steps in which their carried meta-modules move coincide. A wall
//!   across the slide's lift (3D: walls on two perpendicular sides) is
//!   handed over atom by atom; attached atoms of two moving meta-modules
//!   that the SLIDE moves at different times (a meta-module carried
//!   beside the slice) let go for the move and latch again after it
//!   (`in_lockstep`).
//! * `slide` without a `pivot`: a meta-module carried by a SLIDE of the
//!   same step (it has no operations of its own; its atoms move because
//!   they are attached to the slider's).
//! * `attach`, `detach`: the four pairs of touching atoms of two
//!   neighbouring meta-modules, in one step.
//! * `tunnel` along `[A, B, exit]`: the derived 1-TUNNEL (contracted
//!   model; a leaf A through the turn B, held by one meta-module opposite
//!   the exit, the exit and the corner between the legs free), turned like
//!   a slide and run in lockstep with the step's slides. Any other tunnel
//!   (longer paths, legs, more turns, the expanded model) is refused: it
//!   has no derived atom sequence, and a tunnel is not taken on trust.
//!
//! Atom `8·id + i + 2j + 4k` is atom `(i, j, k)` of meta-module `id` at the
//! start. The derived 1-TUNNEL exchanges atoms between A and B (no
//! sequence without exchange was found), so the expansion keeps each
//! meta-module's atoms: after a tunnel, a meta-module is the atoms in its
//! cell.

use super::atom_search::{
    Carry, Found, Legs, Op, Problem, Scene, lift, rest_spacing, slide_problem,
};
use crate::error::InputError;
use crate::lattice::config::ModuleId;
use crate::lattice::{AtomRest, Cell, Face};
use crate::schedule::{Event, ModuleSpec, Schedule, Step};
use rustc_hash::{FxHashMap, FxHashSet};
use std::sync::OnceLock;

/// The SLIDE used for every slide: the 2D-slice search with both carried
/// meta-modules present (valid, by construction, without them: they only
/// add obstacles and never hold the robot together), lifted to 3D; or,
/// between two walls in the expanded model, that model's SLIDE run one
/// layer at a time ([`layered_double_slide`]).
pub struct SlideLibrary {
    /// The 2D-slice sequence the move is made of, as the search found it.
    pub found: Found,
    /// The 3D steps; atom `q` of the lifted scene is atom `(q / 2) % 4` of
    /// the 2D slice's meta-module `q / 8`, at height `q % 2`.
    pub steps: Vec<Vec<Op>>,
    /// Where each atom of the lifted scene is before the first step and
    /// after each step (`track[t][q]`): how the slider's atoms move.
    pub track: Vec<Vec<Cell>>,
    /// Lifted atoms whose track the carried meta-modules follow (the
    /// scene's carried meta-modules; a layered SLIDE's last layer's
    /// trailing atom); none: they move a whole cell in
    /// [`Self::carrier_step`].
    pub carried: Vec<usize>,
}

/// The slider's atoms in a lifted slide scene (its third meta-module).
const SLIDER: std::ops::Range<usize> = 16..24;

impl SlideLibrary {
    /// The step in which the carried meta-modules start to move: the
    /// first move of the atoms they follow, where the library has them;
    /// else the last step in which the slider's atoms move (between two
    /// walls: the trailing column, which a meta-module behind it
    /// touches).
    pub fn carrier_step(&self) -> Option<usize> {
        let moves = |a: usize| {
            (0..self.track.len() - 1).filter(move |&t| self.track[t + 1][a] != self.track[t][a])
        };
        match self.carried.first() {
            Some(&a) => moves(a).next(),
            None => SLIDER.filter_map(|a| moves(a).next_back()).max(),
        }
    }

    /// How far the carried meta-modules have travelled along the slide
    /// after each step (index 0: the start; in atom lengths, ending at one
    /// meta cell): the track of the atoms they follow (the expanded SLIDE
    /// moves them in two steps, half a cell each), else the whole cell in
    /// [`Self::carrier_step`].
    pub fn carried_travel(&self) -> Vec<i32> {
        let last = self.track.len() - 1;
        let along = |t: usize, a: usize| self.track[0][a].x - self.track[t][a].x;
        match self.carried.first() {
            Some(&a) => (0..=last).map(|t| along(t, a)).collect(),
            None => {
                let step = self.carrier_step().unwrap_or(0);
                (0..=last)
                    .map(|t| {
                        if t <= step {
                            0
                        } else {
                            along(last, SLIDER.start)
                        }
                    })
                    .collect()
            }
        }
    }

    /// Replays lifted `steps` from `start` (the lift of `slice`'s start;
    /// frame: the lift of its anchors, tolerance its own), recording every
    /// atom's track; `None` if a step is invalid or the end is not `goal`
    /// (when given).
    fn replayed(
        found: Found,
        start: &Scene,
        goal: Option<&Scene>,
        steps: Vec<Vec<Op>>,
        slice: &Problem,
        carried: Vec<usize>,
    ) -> Option<SlideLibrary> {
        let anchors: Vec<usize> = slice
            .anchors
            .iter()
            .flat_map(|&a| [2 * a, 2 * a + 1])
            .collect();
        let mut scene = start.clone();
        let mut track = vec![scene.pos.clone()];
        for st in &steps {
            scene = scene.step(st, &anchors, slice.eps)?;
            track.push(scene.pos.clone());
        }
        if goal.is_some_and(|g| *g != scene) {
            return None;
        }
        Some(SlideLibrary {
            found,
            steps,
            track,
            carried,
        })
    }
}

/// The SLIDE between two walls: the contracted model's searched once per
/// process; the expanded model's composed from its one-wall SLIDE, one
/// layer at a time ([`layered_double_slide`]), since no search found it.
pub fn double_slide_library(rest: AtomRest) -> Option<&'static SlideLibrary> {
    static CONTRACTED: OnceLock<Option<SlideLibrary>> = OnceLock::new();
    static EXPANDED: OnceLock<Option<SlideLibrary>> = OnceLock::new();
    match rest {
        AtomRest::Contracted => library(rest, &CONTRACTED, || {
            let problem = super::atom_search::double_slide_problem(rest);
            let found = problem.solve()?;
            Some((problem, Vec::new(), found))
        }),
        AtomRest::Expanded => EXPANDED
            .get_or_init(|| {
                let (_, found) = super::stored_move::expanded_slide(Carry::None).ok()?;
                layered_double_slide(found)
            })
            .as_ref(),
    }
}

/// The expanded SLIDE between two walls B (below) and B′ (above), made of
/// the expanded one-wall SLIDE (`single`, on the slice's atoms B, C, A),
/// run by one layer of the slider at a time: the slice search cannot find
/// it (none within 311,324 states: each wall needs its own holder, and the
/// lifted slice moves both layers alike). The top layer lets go of the
/// bottom layer and of B′ and slides along B while the bottom layer holds
/// both walls; it takes C′ on arrival; then the bottom layer lets go of
/// B′ and slides, B′ hanging on C′ and the top layer; on arrival it takes
/// C′ and the top layer again. 24 steps. Checked by replay against the
/// lifted two-wall scene's goal here, and by the certifier wherever used.
pub fn layered_double_slide(single: Found) -> Option<SlideLibrary> {
    let rest = AtomRest::Expanded;
    let sp = rest_spacing(rest);
    let p = super::atom_search::double_slide_problem(rest);
    let (start, _) = lift(&p.start, &[], sp);
    let (goal, _) = lift(&p.goal, &[], sp);
    let slider = 8..12;
    let (b2, c2) = (20..24, 24..28);
    let with = |bonds: &std::collections::BTreeSet<(usize, usize)>,
                other: &std::ops::Range<usize>| {
        bonds
            .iter()
            .copied()
            .filter(|&(a, b)| slider.contains(&a) && other.contains(&b))
            .collect::<Vec<_>>()
    };
    let (held, taken) = (with(&p.start.bonds, &b2), with(&p.goal.bonds, &c2));
    let mut steps: Vec<Vec<Op>> = Vec::new();
    for h in [1, 0] {
        let on = |a: usize| 2 * a + h;
        let mut run: Vec<Vec<Op>> = single
            .steps
            .iter()
            .map(|st| st.iter().map(|op| op.renamed(on)).collect())
            .collect();
        let (first, last) = (0, run.len() - 1);
        run[first].extend(held.iter().map(|&(a, b)| Op::Detach(on(a), on(b))));
        run[last].extend(taken.iter().map(|&(a, c)| Op::Attach(on(a), on(c))));
        let columns = slider.clone().map(|a| (2 * a, 2 * a + 1));
        if h == 1 {
            run[first].extend(columns.map(|(a, b)| Op::Detach(a, b)));
        } else {
            run[last].extend(columns.map(|(a, b)| Op::Attach(a, b)));
        }
        steps.extend(run);
    }
    // Loads behind follow the bottom layer's trailing atom (slice atom 9).
    SlideLibrary::replayed(single, &start, Some(&goal), steps, &p, vec![2 * 9])
}

/// The SLIDE of `rest`: the contracted model's searched once per process;
/// the expanded model's read from its stored file and validated by replay
/// ([`super::stored_move`]; its search takes about a minute), `None` if
/// the stored sequence fails that replay.
pub fn slide_library(rest: AtomRest) -> Option<&'static SlideLibrary> {
    static CONTRACTED: OnceLock<Option<SlideLibrary>> = OnceLock::new();
    static EXPANDED: OnceLock<Option<SlideLibrary>> = OnceLock::new();
    let carried = |label: &[char]| {
        (0..label.len())
            .filter(|&a| matches!(label[a], 'D' | 'E'))
            .collect()
    };
    match rest {
        AtomRest::Contracted => library(rest, &CONTRACTED, || {
            let (problem, label) = slide_problem(rest, Carry::Both);
            let found = problem.solve()?;
            Some((problem, carried(&label), found))
        }),
        // Validated alone and carrying one behind; the scene behind gives
        // the carried track. A load on the far side needs a relatch,
        // which the lockstep adds (it travels unlike the top atom that
        // drops into the bottom row).
        AtomRest::Expanded => library(rest, &EXPANDED, || {
            let (problem, found) = super::stored_move::expanded_slide(Carry::Behind).ok()?;
            let (_, label) = slide_problem(rest, Carry::Behind);
            Some((problem, carried(&label), found))
        }),
    }
}

/// Makes a slide library once per process (`cell`: its slot) from its
/// problem, carried atoms (of the slice) and sequence, lifted to 3D.
fn library(
    rest: AtomRest,
    cell: &'static OnceLock<Option<SlideLibrary>>,
    make: impl FnOnce() -> Option<(Problem, Vec<usize>, Found)>,
) -> Option<&'static SlideLibrary> {
    cell.get_or_init(|| {
        let (problem, carried, found) = make()?;
        let (start, steps) = lift(&problem.start, &found.steps, rest_spacing(rest));
        let carried = carried.iter().map(|&a| 2 * a).collect();
        SlideLibrary::replayed(found, &start, None, steps, &problem, carried)
    })
    .as_ref()
}

/// A derived 1-TUNNEL ([`super::atom_search::tunnel_problem`] with its
/// legs), lifted to 3D.
pub struct TunnelLibrary {
    pub legs: Legs,
    pub problem: Problem,
    pub found: Found,
    /// The 2D slice at the end of the move (where each atom ends up).
    pub end: Scene,
    /// The lifted steps (atom numbering as in [`SlideLibrary::steps`]).
    pub steps: Vec<Vec<Op>>,
}

impl TunnelLibrary {
    /// Atom operations of the 3D move.
    pub fn atom_operations(&self) -> usize {
        self.steps.iter().map(Vec::len).sum()
    }
}

/// The 1-TUNNEL of the contracted model with `legs` (a leg meta-module
/// behind the leaf A, one between the turn and the exit: each stands for
/// a leg of any length, whose further meta-modules ride rigidly), read
/// once per process from its stored file and validated by replay
/// ([`super::stored_move`]; its search, [`Problem::solve_bidirectional`],
/// explores up to 720,000 states); `None` for the expanded model (not
/// derived: see `docs/atoms.md`), or if the stored sequence fails that
/// replay.
pub fn tunnel_library(rest: AtomRest, legs: Legs) -> Option<&'static TunnelLibrary> {
    static CONTRACTED: [OnceLock<Option<TunnelLibrary>>; 4] = [const { OnceLock::new() }; 4];
    if rest != AtomRest::Contracted {
        return None;
    }
    CONTRACTED[usize::from(legs.behind) + 2 * usize::from(legs.ahead)]
        .get_or_init(|| {
            let (problem, found) = super::stored_move::contracted_tunnel(legs).ok()?;
            let mut end = problem.start.clone();
            for st in &found.steps {
                end = end.step(st, &problem.anchors, problem.eps)?;
            }
            let (_, steps) = lift(&problem.start, &found.steps, rest_spacing(rest));
            Some(TunnelLibrary {
                legs,
                problem,
                found,
                end,
                steps,
            })
        })
        .as_ref()
}

/// A signed axis permutation (a lattice symmetry, mirror images included).
#[derive(Copy, Clone, Debug)]
struct Turn {
    cols: [Cell; 3],
}

impl Turn {
    /// Maps canonical −x to `d` (the slide) and −y to `w` (towards the wall).
    fn new(d: Cell, w: Cell) -> Turn {
        let ex = Cell::new(-d.x, -d.y, -d.z);
        let ey = Cell::new(-w.x, -w.y, -w.z);
        let u = Cell::new(
            (ex.x == 0 && ey.x == 0) as i32,
            (ex.y == 0 && ey.y == 0) as i32,
            (ex.z == 0 && ey.z == 0) as i32,
        );
        Turn { cols: [ex, ey, u] }
    }

    fn apply(&self, v: Cell) -> Cell {
        let [a, b, c] = self.cols;
        Cell::new(
            a.x * v.x + b.x * v.y + c.x * v.z,
            a.y * v.x + b.y * v.y + c.y * v.z,
            a.z * v.x + b.z * v.y + c.z * v.z,
        )
    }

    /// The world local index of canonical local atom `(i, j, k)`.
    fn local(&self, i: i32, j: i32, k: i32) -> u32 {
        // Centred at the meta-module's middle: coordinates ±1.
        let c = self.apply(Cell::new(2 * i - 1, 2 * j - 1, 2 * k - 1));
        let b = |v: i32| ((v + 1) / 2) as u32;
        b(c.x) + 2 * b(c.y) + 4 * b(c.z)
    }

    fn face(&self, f: Face) -> Face {
        let v = self.apply(f.dir());
        let (axis, sign) = if v.x != 0 {
            (0, v.x)
        } else if v.y != 0 {
            (1, v.y)
        } else {
            (2, v.z)
        };
        Face::of(axis, sign)
    }
}

/// The atoms of meta-module `id` at coarse cell `c`.
fn atoms_of(id: ModuleId, c: Cell, sp: i32) -> impl Iterator<Item = ModuleSpec> {
    (0..8u32).map(move |l| {
        let (i, j, k) = ((l & 1) as i32, ((l >> 1) & 1) as i32, ((l >> 2) & 1) as i32);
        ModuleSpec {
            id: id * 8 + l,
            cell: Cell::new((2 * c.x + i) * sp, (2 * c.y + j) * sp, (2 * c.z + k) * sp),
            fixed: false,
        }
    })
}

/// Each meta-module's atoms by local index (`i + 2j + 4k`).
type Owners = FxHashMap<ModuleId, [ModuleId; 8]>;

/// The world atom of atom `q` of a lifted 2D scene (atom `q / 2` of the
/// slice, at height `q % 2`; the slice's meta-modules, four atoms each,
/// are `ids`), placed by `turn`. Ids without atoms (the double slide's
/// absent F and H, which never act) fall back to the start's numbering.
fn lifted_atom(q: usize, ids: &[ModuleId], turn: &Turn, owner: &Owners) -> ModuleId {
    let a2 = q / 2;
    let (i, j) = [(0, 0), (1, 0), (0, 1), (1, 1)][a2 % 4];
    let m = ids[a2 / 4];
    let l = turn.local(i, j, (q % 2) as i32);
    owner.get(&m).map_or(m * 8 + l, |o| o[l as usize])
}

/// The touching atom pairs of meta-modules at `ca` and `cb`, as local
/// atom indices (`i + 2j + 4k`) of the first and of the second.
fn face_pairs(ca: Cell, cb: Cell) -> Option<Vec<(usize, usize)>> {
    let d = cb - ca;
    if d.l1() != 1 {
        return None;
    }
    let axis = if d.x != 0 {
        0
    } else if d.y != 0 {
        1
    } else {
        2
    };
    let sign = d.x + d.y + d.z;
    let bit = 1u32 << axis;
    Some(
        (0..8u32)
            .filter(|l| (l & bit != 0) == (sign > 0))
            .map(|l| (l as usize, (l ^ bit) as usize))
            .collect(),
    )
}

fn pair_of(a: ModuleId, b: ModuleId) -> (ModuleId, ModuleId) {
    if a < b { (a, b) } else { (b, a) }
}

/// One move of a meta-level step as atom steps: a SLIDE or a tunnel.
struct Plan {
    steps: Vec<Vec<Event>>,
    /// A SLIDE's walls across its lift, each with the meta-module beside
    /// it in the slide direction (B and C, as for the wall in the plane).
    lateral: Vec<(ModuleId, ModuleId)>,
    /// The sliding meta-module (a SLIDE's).
    mover: Option<ModuleId>,
    /// How far the meta-modules it carries have travelled after each step
    /// (a SLIDE's; [`SlideLibrary::carried_travel`] in this run's order).
    load: Option<Vec<i32>>,
    /// The mover's atoms, each with its offset from its start after each
    /// step (a SLIDE's; a tunnel's atoms are its library's business).
    motion: Vec<(ModuleId, Vec<Cell>)>,
}

/// The moves of one meta-level step run together, as atom steps.
///
/// Every SLIDE's carried meta-modules move together, along the slide, in
/// one of its steps (the contracted SLIDE's second; the first when it runs
/// backwards) or two (the expanded SLIDE's, half a cell each): the moves
/// are shifted so that the first steps in which their loads move
/// coincide, and every carried meta-module travels as the load of the
/// slide latest to start moving its load.
/// Then any attached pair of atoms of two different moving meta-modules
/// (sliders or carried) that would travel differently, for instance a
/// meta-module carried beside the slider's slice, across the lift, is
/// attached to all four of the slider's atoms on that face, one of which
/// the SLIDE moves a step earlier, is detached in the first step and
/// attached again in the last, when both have arrived. Pairs that travel
/// alike stay attached and carry. Bonds to meta-modules that do not move
/// are left as the schedule has them: releasing those is the schedule's
/// business, and the certifier's to check.
fn in_lockstep(
    plans: Vec<Plan>,
    carried: &[(ModuleId, Cell)],
    owner: &Owners,
    at: &FxHashMap<ModuleId, Cell>,
    by_cell: &FxHashMap<Cell, ModuleId>,
    bonds: &FxHashSet<(ModuleId, ModuleId)>,
    sp: i32,
) -> Vec<Vec<Event>> {
    let starts: Vec<Option<usize>> = plans
        .iter()
        .map(|p| {
            p.load
                .as_ref()
                .and_then(|l| (0..l.len() - 1).find(|&t| l[t + 1] != l[t]))
        })
        .collect();
    let carrier = starts.iter().flatten().copied().max().unwrap_or(0);
    let shift: Vec<usize> = starts
        .iter()
        .map(|c| c.map_or(0, |c| carrier - c))
        .collect();
    let len = plans
        .iter()
        .zip(&shift)
        .map(|(p, s)| p.steps.len() + s)
        .max()
        .unwrap_or(0);
    let mut steps: Vec<Vec<Event>> = vec![Vec::new(); len];
    // Each moving atom's offset from its start after each step, and its
    // meta-module.
    let mut travel: FxHashMap<ModuleId, Vec<Cell>> = FxHashMap::default();
    let mut movers: Vec<ModuleId> = Vec::new();
    for (p, &s) in plans.iter().zip(&shift) {
        for (t, st) in p.steps.iter().enumerate() {
            steps[t + s].extend(st.iter().cloned());
        }
        for (a, offsets) in &p.motion {
            let global = (0..=len)
                .map(|t| offsets[t.saturating_sub(s).min(offsets.len() - 1)])
                .collect();
            travel.insert(*a, global);
        }
    }
    movers.extend(plans.iter().filter_map(|p| p.mover));
    // The load of the slide whose load starts latest, on the global clock.
    let lead = (0..plans.len()).find(|&i| starts[i] == Some(carrier));
    let load: Vec<(i32, i32)> = (0..=len)
        .map(|t| match lead {
            Some(i) => {
                let l = plans[i].load.as_ref().expect("a load");
                let full = *l.last().expect("a step");
                (l[t.saturating_sub(shift[i]).min(l.len() - 1)], full)
            }
            None => (i32::from(t > carrier), 1),
        })
        .collect();
    // Each carried meta-module rides on the moving atoms it is attached
    // to: of their travels that go straight along the slide to its goal,
    // the load's own if one is, else the one most of its pairs share
    // (between two walls in the expanded model a load beside the slice is
    // attached to one layer, which moves while the other stands). A load
    // attached only to other loads rides on theirs; one attached to none,
    // on the load's.
    let lead_way = |d: Cell| -> Vec<Cell> {
        load.iter()
            .map(|&(x, full)| Cell::new(d.x * x / full, d.y * x / full, d.z * x / full))
            .collect()
    };
    let mut pending: Vec<(ModuleId, Cell)> = carried.to_vec();
    loop {
        let before = pending.len();
        pending.retain(|&(m, d)| {
            let own = lead_way(d);
            let straight = |w: &Vec<Cell>| {
                w.last() == Some(&d)
                    && w.iter().all(|o| {
                        o.x * d.y == o.y * d.x && o.x * d.z == o.z * d.x && o.y * d.z == o.z * d.y
                    })
            };
            let mut votes: Vec<(&Vec<Cell>, usize)> = Vec::new();
            for n in Face::ALL
                .iter()
                .filter_map(|f| by_cell.get(&(at[&m] + f.dir())))
            {
                for (la, lb) in face_pairs(at[&m], at[n]).expect("neighbours") {
                    let (a, b) = (owner[&m][la], owner[n][lb]);
                    let Some(w) = travel.get(&b).filter(|w| straight(w)) else {
                        continue;
                    };
                    if !bonds.contains(&pair_of(a, b)) {
                        continue;
                    }
                    match votes.iter_mut().find(|(v, _)| *v == w) {
                        Some((_, k)) => *k += 1,
                        None => votes.push((w, 1)),
                    }
                }
            }
            let way = if votes.iter().any(|(w, _)| **w == own) {
                own
            } else if let Some((w, _)) = votes.iter().max_by_key(|(_, k)| *k) {
                (*w).clone()
            } else {
                return true;
            };
            for &a in &owner[&m] {
                travel.insert(a, way.clone());
            }
            false
        });
        if pending.len() == before {
            break;
        }
    }
    for &(m, d) in &pending {
        for &a in &owner[&m] {
            travel.insert(a, lead_way(d));
        }
    }
    movers.extend(carried.iter().map(|&(m, _)| m));
    if len == 0 {
        return steps;
    }
    movers.sort_unstable();
    movers.dedup();
    let mut relatch = Vec::new();
    for &m in &movers {
        let c = at[&m];
        for d in [Cell::new(1, 0, 0), Cell::new(0, 1, 0), Cell::new(0, 0, 1)] {
            let Some(&o) = by_cell.get(&(c + d)) else {
                continue;
            };
            if movers.binary_search(&o).is_err() {
                continue;
            }
            for (la, lb) in face_pairs(c, c + d).expect("neighbours") {
                let (a, b) = (owner[&m][la], owner[&o][lb]);
                if bonds.contains(&pair_of(a, b)) && travel.get(&a) != travel.get(&b) {
                    relatch.push((a, b));
                }
            }
        }
    }
    for (a, b) in relatch {
        steps[0].push(Event::Detach {
            module: a,
            other: b,
        });
        steps[len - 1].push(Event::Attach {
            module: a,
            other: b,
        });
    }
    // A wall across the lift: each of the slider's atoms on that face lets
    // go of the wall in the step it starts to move, and whenever it stops
    // facing an atom of B or C (the wall and the meta-module beside it
    // along the slide), holds that atom until it moves again: the slider
    // holds on to that side throughout by the atoms standing still. (The
    // contracted SLIDE moves each atom in one step, from facing B to facing
    // C; the expanded one moves its atoms in several, half a cell at a
    // time, and between moves they face B's or C's other row.)
    for p in &plans {
        let Some(m) = p.mover else { continue };
        for &(b, c) in &p.lateral {
            let across = at[&b] - at[&m];
            let across = Cell::new(across.x * sp, across.y * sp, across.z * sp);
            let wall: FxHashMap<Cell, ModuleId> = [b, c]
                .iter()
                .flat_map(|w| {
                    atoms_of(*w, at[w], sp)
                        .enumerate()
                        .map(move |(l, a)| (a.cell, owner[w][l]))
                })
                .collect();
            for (la, lb) in face_pairs(at[&m], at[&b]).expect("a wall beside the slider") {
                let a = owner[&m][la];
                let Some(way) = travel.get(&a) else { continue };
                let start = atoms_of(m, at[&m], sp).nth(la).expect("eight atoms").cell;
                // A slider the schedule let go of this wall is left alone.
                if !bonds.contains(&pair_of(a, owner[&b][lb])) {
                    continue;
                }
                let mut held = Some(owner[&b][lb]);
                for t in 0..len {
                    if way[t + 1] == way[t] {
                        continue;
                    }
                    if let Some(w) = held.take() {
                        steps[t].push(Event::Detach {
                            module: a,
                            other: w,
                        });
                    }
                    let still = t + 1 == len || way[t + 2] == way[t + 1];
                    if let Some(&w) = wall.get(&(start + way[t + 1] + across)).filter(|_| still) {
                        steps[t].push(Event::Attach {
                            module: a,
                            other: w,
                        });
                        held = Some(w);
                    }
                }
            }
        }
    }
    steps
}

/// A 1-TUNNEL placed in the robot: the library of its legs, the scene's
/// meta-modules (L, B, A, then D and E where the legs are longer), the
/// symmetry's canonical −x and −y, and each path cell with the
/// meta-module in it (the exit last, empty).
struct PlacedTunnel {
    lib: &'static TunnelLibrary,
    ids: Vec<ModuleId>,
    d: Cell,
    w: Cell,
    path: Vec<(Cell, Option<ModuleId>)>,
    turn: usize,
}

/// Checks that a `tunnel` event is a derived 1-TUNNEL: a path of
/// neighbouring cells with one turn B, its cells occupied up to a free
/// exit, B held by L on the side opposite the exit and touched by nothing
/// else, and the corner between the two legs free. The legs may be of any
/// length (their further meta-modules ride rigidly on the scene's D and
/// E); whether anything else holds them is the certifier's to find.
/// Anything else is refused with the reason.
fn one_tunnel(
    here: Cell,
    path: &[Cell],
    by_cell: &FxHashMap<Cell, ModuleId>,
    rest: AtomRest,
) -> Result<PlacedTunnel, String> {
    if path.len() < 3 {
        return Err(format!(
            "a 1-TUNNEL path has at least 3 cells, not {}",
            path.len()
        ));
    }
    if path[0] != here {
        return Err(format!(
            "the tunnel starts at {}, but the meta-module is at {here}",
            path[0]
        ));
    }
    if let Some(w) = path.windows(2).find(|w| (w[1] - w[0]).l1() != 1) {
        return Err(format!(
            "a tunnel path steps between neighbouring cells; {} and {} are not",
            w[0], w[1]
        ));
    }
    let turns = crate::lattice::path_turns(path);
    let [t] = turns[..] else {
        return Err(format!(
            "only the 1-TUNNEL (one turn) is derived; this path turns {} times",
            turns.len()
        ));
    };
    let (b, up, out) = (path[t], path[t - 1] - path[t], path[t + 1] - path[t]);
    if up.x * out.x + up.y * out.y + up.z * out.z != 0 {
        return Err(format!("the path turns back on itself at {b}"));
    }
    let exit = *path.last().expect("long enough");
    let mut cells = Vec::with_capacity(path.len());
    for &c in &path[..path.len() - 1] {
        let m = *by_cell.get(&c).ok_or_else(|| {
            format!("the tunnel path runs through {c}, where there is no meta-module")
        })?;
        cells.push((c, Some(m)));
    }
    cells.push((exit, None));
    let behind = b - out;
    let l = *by_cell.get(&behind).ok_or_else(|| {
        format!("the turn {b} must hang on a meta-module at {behind}, opposite the exit")
    })?;
    for (cell, what) in [
        (exit, "the exit"),
        (b + up + out, "the corner between the legs"),
    ] {
        if let Some(o) = by_cell.get(&cell) {
            return Err(format!("{what} {cell} is taken by meta-module {o}"));
        }
    }
    for n in Face::ALL
        .map(|f| b + f.dir())
        .into_iter()
        .filter(|&n| n != path[t - 1] && n != path[t + 1] && n != behind)
    {
        if let Some(o) = by_cell.get(&n) {
            return Err(format!(
                "the turn {b} may touch only the path and the meta-module opposite the exit; meta-module {o} at {n} touches it"
            ));
        }
    }
    let legs = Legs {
        behind: t >= 2,
        ahead: t + 2 < path.len(),
    };
    // Searched last, and once per process: refusals above cost nothing.
    let lib = tunnel_library(rest, legs).ok_or_else(|| {
        format!(
            "no atom sequence for 1-TUNNEL ({}) was derived in the {} model",
            legs.name(),
            format!("{rest:?}").to_lowercase()
        )
    })?;
    let mut ids = vec![
        l,
        cells[t].1.expect("occupied"),
        cells[t - 1].1.expect("occupied"),
    ];
    if legs.behind {
        ids.push(cells[t - 2].1.expect("occupied"));
    }
    if legs.ahead {
        ids.push(cells[t + 1].1.expect("occupied"));
    }
    Ok(PlacedTunnel {
        lib,
        ids,
        d: Cell::ZERO - out,
        w: Cell::ZERO - up,
        path: cells,
        turn: t,
    })
}

/// Expands a `meta_modules` schedule into an `atoms` schedule.
pub fn expand(s: &Schedule, rest: AtomRest) -> Result<Schedule, InputError> {
    Ok(expand_tracked(s, rest)?.0)
}

/// [`expand`], with each meta-module's atoms and cell at the end.
fn expand_tracked(
    s: &Schedule,
    rest: AtomRest,
) -> Result<(Schedule, Owners, FxHashMap<ModuleId, Cell>), InputError> {
    let sp = rest_spacing(rest);
    let mut out = Schedule::new(s.lattice, s.spacing);
    out.atoms = Some(rest);
    out.model = s.model.clone();
    out.meta = s.meta.clone();
    out.meta
        .insert("expanded_from".into(), "meta_modules".into());
    let mut at: FxHashMap<ModuleId, Cell> = FxHashMap::default();
    // The atoms of each meta-module by local index: `8·id + l` at the
    // start; a tunnel exchanges atoms between the meta-modules it involves.
    let mut owner: Owners = FxHashMap::default();
    let mut by_cell: FxHashMap<Cell, ModuleId> = FxHashMap::default();
    for m in &s.modules {
        if m.id > u32::MAX / 8 - 1 {
            return Err(
                InputError::new("meta-module id too large to number its atoms").for_module(m.id),
            );
        }
        if at.insert(m.id, m.cell).is_some() {
            return Err(
                InputError::new(format!("meta-module id {} is used twice", m.id)).for_module(m.id),
            );
        }
        if by_cell.insert(m.cell, m.id).is_some() {
            return Err(InputError::new(format!("two meta-modules at {}", m.cell)).for_module(m.id));
        }
        owner.insert(m.id, std::array::from_fn(|l| m.id * 8 + l as ModuleId));
        out.modules.extend(atoms_of(m.id, m.cell, sp).map(|mut a| {
            a.fixed = m.fixed;
            a
        }));
    }
    // The attached atom pairs between meta-modules (at the start every
    // touching pair, as the certifier has it), kept up to date from the
    // latches emitted.
    let mut bonds: FxHashSet<(ModuleId, ModuleId)> = FxHashSet::default();
    for (&id, &c) in &at {
        for d in [Cell::new(1, 0, 0), Cell::new(0, 1, 0), Cell::new(0, 0, 1)] {
            if let Some(o) = by_cell.get(&(c + d)) {
                for (la, lb) in face_pairs(c, c + d).expect("neighbours") {
                    bonds.insert(pair_of(owner[&id][la], owner[o][lb]));
                }
            }
        }
    }
    for (k, step) in s.steps.iter().enumerate() {
        let k1 = k + 1;
        let mut latch: Vec<Event> = Vec::new();
        let mut slides: Vec<Plan> = Vec::new();
        let mut tunnelled: Vec<ModuleId> = Vec::new();
        let mut moved: Vec<(ModuleId, Cell)> = Vec::new();
        let mut walls: FxHashMap<ModuleId, Vec<(Cell, Cell, ModuleId, ModuleId)>> =
            FxHashMap::default();
        let mut retag: Vec<(ModuleId, [ModuleId; 8])> = Vec::new();
        let mut wall_cells: FxHashMap<ModuleId, Cell> = FxHashMap::default();
        for e in &step.events {
            let id = e.module();
            let err = |m: String| InputError::new(m).at_step(k1).for_module(id);
            let here = *at
                .get(&id)
                .ok_or_else(|| err(format!("meta-module {id} is not in the robot")))?;
            match e {
                Event::Attach { other, .. } | Event::Detach { other, .. } => {
                    let there = *at
                        .get(other)
                        .ok_or_else(|| err(format!("meta-module {other} is not in the robot")))?;
                    let pairs = face_pairs(here, there).ok_or_else(|| {
                        err(format!("meta-modules {id} and {other} are not neighbours"))
                    })?;
                    for (la, lb) in pairs {
                        let (a, b) = (owner[&id][la], owner[other][lb]);
                        latch.push(if matches!(e, Event::Attach { .. }) {
                            Event::Attach {
                                module: a,
                                other: b,
                            }
                        } else {
                            Event::Detach {
                                module: a,
                                other: b,
                            }
                        });
                    }
                }
                Event::Slide {
                    from, to, pivot, ..
                } => {
                    if *from != here {
                        return Err(err(format!(
                            "the slide starts at {from}, but the meta-module is at {here}"
                        )));
                    }
                    let d = *to - *from;
                    if d.l1() != 1 {
                        return Err(err(format!("a SLIDE moves one cell, not {from} to {to}")));
                    }
                    if !moved.iter().any(|&(m, _)| m == id) {
                        moved.push((id, *to));
                    }
                    let Some(b) = pivot else { continue };
                    let cb = *at.get(b).ok_or_else(|| {
                        err(format!("the wall meta-module {b} is not in the robot"))
                    })?;
                    let w = cb - here;
                    if w.l1() != 1 || (w.x * d.x + w.y * d.y + w.z * d.z) != 0 {
                        return Err(err(format!(
                            "the wall meta-module {b} at {cb} is not beside the slider, across the slide"
                        )));
                    }
                    let c = *by_cell.get(&(cb + d)).ok_or_else(|| {
                        err(format!("SLIDE needs a meta-module at {} (beside the wall, in the slide direction)", cb + d))
                    })?;
                    walls.entry(id).or_default().push((d, w, *b, c));
                    wall_cells.entry(id).or_insert(here);
                }
                Event::Tunnel { path, .. } => {
                    let t = one_tunnel(here, path, &by_cell, rest).map_err(err)?;
                    let lib = t.lib;
                    let turn = Turn::new(t.d, t.w);
                    let atom = |q: usize| lifted_atom(q, &t.ids, &turn, &owner);
                    slides.push(Plan {
                        steps: lib
                            .steps
                            .iter()
                            .map(|st| {
                                st.iter()
                                    .map(|op| op.event(atom, |f| turn.face(f)))
                                    .collect()
                            })
                            .collect(),
                        lateral: Vec::new(),
                        mover: None,
                        load: None,
                        motion: Vec::new(),
                    });
                    tunnelled.push(id);
                    // Whose atoms each path cell holds at the end: the
                    // scene's where the search left them, the further leg
                    // meta-modules' one cell along the path; each cell
                    // keeps its meta-module but the leaf's, whose is the
                    // exit.
                    let b = t.path[t.turn].0;
                    let mut new: FxHashMap<Cell, [ModuleId; 8]> = FxHashMap::default();
                    for q in 0..lib.end.pos.len() * 2 {
                        let e = lib.end.pos[q / 2];
                        let cell =
                            b + turn.apply(Cell::new(e.x.div_euclid(2), e.y.div_euclid(2), 0));
                        let to = turn.local(e.x.rem_euclid(2), e.y.rem_euclid(2), (q % 2) as i32);
                        new.entry(cell).or_insert([0; 8])[to as usize] = atom(q);
                    }
                    let far = |i: usize| i + 2 < t.turn || (i > t.turn + 1 && i + 1 < t.path.len());
                    for i in (0..t.path.len() - 1).filter(|&i| far(i)) {
                        let m = t.path[i].1.expect("occupied");
                        new.insert(t.path[i + 1].0, owner[&m]);
                    }
                    for (k, &(cell, m)) in t.path.iter().enumerate().skip(1) {
                        let m = if k + 1 == t.path.len() {
                            id
                        } else {
                            m.expect("occupied")
                        };
                        let atoms = *new
                            .get(&cell)
                            .ok_or_else(|| err(format!("the tunnel leaves {cell} empty")))?;
                        retag.push((m, atoms));
                    }
                    moved.push((id, t.path.last().expect("a path").0));
                }
                _ => {
                    return Err(err(
                        "a meta-module schedule has slide, attach and detach events only".into(),
                    ));
                }
            }
        }
        let mut ids_in_order: Vec<ModuleId> = walls.keys().copied().collect();
        ids_in_order.sort_unstable();
        for id in ids_in_order {
            let ws = &walls[&id];
            let err = |m: String| InputError::new(m).at_step(k1).for_module(id);
            // A slider pushing a carried meta-module ahead of it (a comb
            // run in reverse) runs the derived SLIDE backwards: the slide
            // from its end cell back to its start, along the meta-module
            // beside its wall ahead, with every step's operations undone
            // in reverse order. The derived SLIDE carries loads behind and
            // on the far side only.
            let here = wall_cells[&id];
            let d0 = ws[0].0;
            let carried = |c: Cell| {
                by_cell
                    .get(&c)
                    .is_some_and(|m| moved.iter().any(|&(o, to)| o == *m && to == c + d0))
            };
            let back = carried(here + d0);
            if back && carried(here - d0) {
                return Err(err(
                    "a SLIDE carrying meta-modules both ahead of and behind the slider has no derived atom sequence".into(),
                ));
            }
            // The walls in the slide's plane run the derived SLIDE (one
            // wall, or two opposite ones); a wall across the lift (the 3D
            // combing's perpendicular walls) is handed over atom by atom.
            if ws.iter().any(|x| x.0 != d0) {
                return Err(err("a meta-module slides in two directions at once".into()));
            }
            let opposite = (0..ws.len()).find_map(|i| {
                (i + 1..ws.len())
                    .find(|&j| ws[j].1 == Cell::ZERO - ws[i].1)
                    .map(|j| (i, j))
            });
            let in_plane: Vec<usize> = opposite.map_or(vec![0], |(i, j)| vec![i, j]);
            let lateral: Vec<(ModuleId, ModuleId)> = (0..ws.len())
                .filter(|i| !in_plane.contains(i))
                .map(|i| (ws[i].2, ws[i].3))
                .collect();
            let w0 = ws[in_plane[0]].1;
            if (0..ws.len())
                .any(|i| !in_plane.contains(&i) && (ws[i].1 == w0 || ws[i].1 == Cell::ZERO - w0))
                || lateral.len() > 2
            {
                return Err(err("a meta-module slides along the same wall twice".into()));
            }
            let primary: Vec<_> = in_plane.iter().map(|&i| ws[i]).collect();
            let (lib, ids, (d, w)) = match primary.as_slice() {
                [(d, w, b, c)] => {
                    let lib = slide_library(rest).ok_or_else(|| {
                        err("no atom sequence for SLIDE was found by the search".into())
                    })?;
                    let ids = if back {
                        vec![*c, *b, id]
                    } else {
                        vec![*b, *c, id]
                    };
                    (lib, ids, (*d, *w))
                }
                [(d, w, b, c), (d2, w2, b2, c2)] if d == d2 && *w2 == Cell::ZERO - *w => {
                    let lib = double_slide_library(rest).ok_or_else(|| {
                        err("no atom sequence for a SLIDE between two walls was found by the search".into())
                    })?;
                    let ids = if back {
                        vec![*c, *b, id, 0, 0, *c2, *b2]
                    } else {
                        vec![*b, *c, id, 0, 0, *b2, *c2]
                    };
                    (lib, ids, (*d, *w))
                }
                _ => unreachable!("one wall or an opposite pair"),
            };
            let turn = Turn::new(if back { Cell::ZERO - d } else { d }, w);
            let atom = |q: usize| lifted_atom(q, &ids, &turn, &owner);
            let event = |op: &Op| {
                let op = if back { op.inverse() } else { *op };
                op.event(atom, |f| turn.face(f))
            };
            let steps: Vec<Vec<Event>> = if back {
                lib.steps
                    .iter()
                    .rev()
                    .map(|st| st.iter().map(event).collect())
                    .collect()
            } else {
                lib.steps
                    .iter()
                    .map(|st| st.iter().map(event).collect())
                    .collect()
            };
            // The slider's atoms (the scene's third meta-module), where
            // they are after each step of the run.
            let last = lib.track.len() - 1;
            let motion = SLIDER
                .map(|q| {
                    let offsets = (0..=last)
                        .map(|t| {
                            turn.apply(if back {
                                lib.track[last - t][q] - lib.track[last][q]
                            } else {
                                lib.track[t][q] - lib.track[0][q]
                            })
                        })
                        .collect();
                    (atom(q), offsets)
                })
                .collect();
            slides.push(Plan {
                steps,
                lateral,
                mover: Some(id),
                load: Some({
                    let l = lib.carried_travel();
                    if back {
                        l.iter().rev().map(|x| l[last] - x).collect()
                    } else {
                        l
                    }
                }),
                motion,
            });
        }
        let first_new = out.steps.len();
        if !latch.is_empty() {
            out.steps.push(Step { events: latch });
        }
        let carried: Vec<(ModuleId, Cell)> = moved
            .iter()
            .filter(|(m, _)| !walls.contains_key(m) && !tunnelled.contains(m))
            .map(|&(m, to)| {
                let d = to - at[&m];
                (m, Cell::new(d.x * 2 * sp, d.y * 2 * sp, d.z * 2 * sp))
            })
            .collect();
        out.steps.extend(
            in_lockstep(slides, &carried, &owner, &at, &by_cell, &bonds, sp)
                .into_iter()
                .map(|events| Step { events }),
        );
        for st in &out.steps[first_new..] {
            for e in &st.events {
                match *e {
                    Event::Attach { module, other } => {
                        bonds.insert(pair_of(module, other));
                    }
                    Event::Detach { module, other } => {
                        bonds.remove(&pair_of(module, other));
                    }
                    _ => {}
                }
            }
        }
        for (m, atoms) in retag {
            owner.insert(m, atoms);
        }
        for &(id, _) in &moved {
            by_cell.remove(&at[&id]);
        }
        for (id, to) in moved {
            if let Some(o) = by_cell.insert(to, id) {
                return Err(
                    InputError::new(format!("meta-modules {o} and {id} both end at {to}"))
                        .at_step(k1)
                        .for_module(id),
                );
            }
            at.insert(id, to);
        }
    }
    Ok((out, owner, at))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_canonical_turn_is_the_identity_and_turns_are_bijections() {
        let t = Turn::new(Cell::new(-1, 0, 0), Cell::new(0, -1, 0));
        for l in 0..8 {
            let (i, j, k) = (l & 1, (l >> 1) & 1, (l >> 2) & 1);
            assert_eq!(t.local(i, j, k), l as u32);
        }
        for f in Face::ALL {
            assert_eq!(t.face(f), f);
        }
        // Slide down along a wall on the left, and its mirror image.
        for w in [Cell::new(-1, 0, 0), Cell::new(1, 0, 0)] {
            let t = Turn::new(Cell::new(0, -1, 0), w);
            let mut seen: Vec<u32> = (0..8)
                .map(|l| t.local(l & 1, (l >> 1) & 1, (l >> 2) & 1))
                .collect();
            seen.sort_unstable();
            assert_eq!(seen, (0..8).collect::<Vec<_>>());
            assert_eq!(t.face(Face::NegX), Face::NegY);
            assert_eq!(
                t.face(Face::NegY),
                if w.x < 0 { Face::NegX } else { Face::PosX }
            );
        }
    }

    /// A meta-module of a test schedule.
    fn meta(id: ModuleId, c: [i32; 3], fixed: bool) -> ModuleSpec {
        ModuleSpec {
            id,
            cell: Cell::new(c[0], c[1], c[2]),
            fixed,
        }
    }

    /// Replays an atom schedule's events with the search's step rules.
    fn replay(atoms: &Schedule) -> FxHashMap<ModuleId, Cell> {
        let ids: Vec<ModuleId> = atoms.modules.iter().map(|m| m.id).collect();
        let ix = |m: ModuleId| ids.iter().position(|&i| i == m).unwrap();
        let pos: Vec<Cell> = atoms.modules.iter().map(|m| m.cell).collect();
        let ext = vec![[atoms.atoms == Some(AtomRest::Expanded); 6]; pos.len()];
        let mut scene = Scene {
            bonds: Scene::all_bonds(&pos, &ext),
            pos,
            ext,
        };
        let anchors: Vec<usize> = (0..ids.len()).filter(|&a| atoms.modules[a].fixed).collect();
        for st in &atoms.steps {
            let ops: Vec<Op> = st
                .events
                .iter()
                .map(|e| match *e {
                    Event::Expand { module, face } => Op::Expand(ix(module), face),
                    Event::Contract { module, face } => Op::Contract(ix(module), face),
                    Event::Attach { module, other } => Op::Attach(ix(module), ix(other)),
                    Event::Detach { module, other } => Op::Detach(ix(module), ix(other)),
                    _ => unreachable!(),
                })
                .collect();
            scene = scene
                .step(&ops, &anchors, 1e-6)
                .unwrap_or_else(|| panic!("an invalid step: {ops:?}"));
        }
        ids.iter().copied().zip(scene.pos).collect()
    }

    #[test]
    fn after_a_tunnel_each_meta_module_is_the_atoms_in_its_cell() {
        // L2 (fixed), L, the turn B, the leaf A on B, G on L2; A tunnels
        // through B to the exit (1, 0, 0), turned so that the slice is
        // lifted along y. Then the same with long legs: an in-leg of three
        // (A, D, D2 the leaf) and an out-leg E, E2 before the exit.
        let m = |id: ModuleId, c: [i32; 3]| meta(id, c, id == 0);
        let cells = |p: &[[i32; 3]]| {
            p.iter()
                .map(|c| Cell::new(c[0], c[1], c[2]))
                .collect::<Vec<Cell>>()
        };
        let short = (
            vec![
                m(0, [-2, 0, 0]),
                m(1, [-1, 0, 0]),
                m(2, [0, 0, 0]),
                m(3, [0, 0, 1]),
                m(4, [-2, 0, 1]),
            ],
            3,
            cells(&[[0, 0, 1], [0, 0, 0], [1, 0, 0]]),
        );
        let long = (
            vec![
                m(0, [-2, 0, 0]),
                m(1, [-1, 0, 0]),
                m(2, [0, 0, 0]),
                m(3, [0, 0, 1]),
                m(4, [0, 0, 2]),
                m(5, [0, 0, 3]),
                m(6, [1, 0, 0]),
                m(7, [2, 0, 0]),
            ],
            5,
            cells(&[
                [0, 0, 3],
                [0, 0, 2],
                [0, 0, 1],
                [0, 0, 0],
                [1, 0, 0],
                [2, 0, 0],
                [3, 0, 0],
            ]),
        );
        for (k, (modules, leaf, path)) in [short, long].into_iter().enumerate() {
            let mut s = Schedule::new(
                crate::lattice::LatticeKind::Cubic,
                crate::schedule::Length::mm(60.0),
            );
            s.meta_modules = Some(AtomRest::Contracted);
            s.modules = modules;
            let exit = *path.last().unwrap();
            s.steps = vec![Step {
                events: vec![Event::Tunnel { module: leaf, path }],
            }];
            let (atoms, owners, at) = expand_tracked(&s, AtomRest::Contracted).unwrap();
            assert_eq!(at[&leaf], exit);
            assert_eq!(at[&2], Cell::new(0, 0, 0));
            let end = replay(&atoms);
            let mut exchanged = 0;
            for (id, own) in &owners {
                for (l, a) in own.iter().enumerate() {
                    let want = atoms_of(*id, at[id], 1).nth(l).unwrap().cell;
                    assert_eq!(end[a], want, "case {k}: meta-module {id}, local atom {l}");
                    exchanged += (*a / 8 != *id) as usize;
                }
            }
            // The derived moves exchange atoms between A and B, and the
            // legs' atoms move one cell along (docs/atoms.md).
            assert!(exchanged > 0);
        }
    }

    #[test]
    fn after_an_expanded_slide_every_meta_module_is_its_own_atoms_in_its_new_cell() {
        // A static row (x = 1, 0, −1 at z = 0; the last fixed), the slider
        // A (3) on B (0) sliding −x onto C (1) carrying D (4) behind it and
        // E (5) on it; then the same slide run backwards: A pushes P (6)
        // ahead of it instead (P lets go of C before and holds the row's
        // end after: the schedule's latches).
        let m = |id: ModuleId, c: [i32; 3]| meta(id, c, id == 2);
        let slide =
            |id: ModuleId, from: [i32; 3], to: [i32; 3], pivot: Option<ModuleId>| Event::Slide {
                module: id,
                from: Cell::new(from[0], from[1], from[2]),
                to: Cell::new(to[0], to[1], to[2]),
                pivot,
            };
        let row = [
            m(0, [1, 0, 0]),
            m(1, [0, 0, 0]),
            m(2, [-1, 0, 0]),
            m(3, [1, 0, 1]),
        ];
        let loaded = (
            [row.as_slice(), &[m(4, [2, 0, 1]), m(5, [1, 0, 2])]].concat(),
            vec![
                slide(3, [1, 0, 1], [0, 0, 1], Some(0)),
                slide(4, [2, 0, 1], [1, 0, 1], None),
                slide(5, [1, 0, 2], [0, 0, 2], None),
            ],
        );
        let pushing = (
            [row.as_slice(), &[m(6, [0, 0, 1])]].concat(),
            vec![
                slide(3, [1, 0, 1], [0, 0, 1], Some(0)),
                slide(6, [0, 0, 1], [-1, 0, 1], None),
            ],
        );
        let latch = |op: fn(ModuleId, ModuleId) -> Event, a, b| Step {
            events: vec![op(a, b)],
        };
        for (k, (modules, events)) in [loaded, pushing].into_iter().enumerate() {
            let detach = |module, other| Event::Detach { module, other };
            let attach = |module, other| Event::Attach { module, other };
            let mut s = Schedule::new(
                crate::lattice::LatticeKind::Cubic,
                crate::schedule::Length::mm(60.0),
            );
            s.meta_modules = Some(AtomRest::Expanded);
            s.modules = modules;
            s.steps = if k == 0 {
                vec![Step { events }]
            } else {
                vec![latch(detach, 6, 1), Step { events }, latch(attach, 6, 2)]
            };
            let (atoms, owners, at) = expand_tracked(&s, AtomRest::Expanded).unwrap();
            assert_eq!(atoms.steps.len(), 12 + 2 * k, "case {k}");
            let end = replay(&atoms);
            for (id, own) in &owners {
                for (l, a) in own.iter().enumerate() {
                    assert_eq!(*a, 8 * id + l as ModuleId, "a slide exchanges no atoms");
                    let want = atoms_of(*id, at[id], 3).nth(l).unwrap().cell;
                    assert_eq!(end[a], want, "case {k}: meta-module {id}, local atom {l}");
                }
            }
        }
    }

    #[test]
    fn the_expanded_slide_between_two_walls_replays_one_layer_at_a_time() {
        let lib = double_slide_library(AtomRest::Expanded).expect("replays to the goal");
        assert_eq!(lib.steps.len(), 24);
        let ops: usize = lib.steps.iter().map(Vec::len).sum();
        assert_eq!(ops, 2 * 48 + 16);
        // The top layer (odd atoms) moves in the first 12 steps only, the
        // bottom layer in the last 12 only.
        let moves = |q: usize, t: usize| lib.track[t + 1][q] != lib.track[t][q];
        for q in SLIDER {
            let (first, second) = if q % 2 == 1 {
                (0..12, 12..24)
            } else {
                (12..24, 0..12)
            };
            assert!(first.clone().any(|t| moves(q, t)), "atom {q}");
            assert!(!second.clone().any(|t| moves(q, t)), "atom {q}");
        }
        // Loads behind start with the bottom layer.
        assert_eq!(lib.carrier_step(), Some(12 + 5));
        // Without its last step it does not end at the goal: refused.
        let (_, single) = super::super::stored_move::expanded_slide(Carry::None).unwrap();
        let mut cut = single.clone();
        cut.steps.pop();
        assert!(layered_double_slide(cut).is_none());
    }

    #[test]
    fn neighbouring_meta_modules_touch_through_four_atom_pairs() {
        let p = face_pairs(Cell::new(0, 0, 0), Cell::new(1, 0, 0)).unwrap();
        assert_eq!(p, vec![(1, 0), (3, 2), (5, 4), (7, 6)]);
        assert!(face_pairs(Cell::new(0, 0, 0), Cell::new(1, 1, 0)).is_none());
    }
}
