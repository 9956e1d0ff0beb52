//! Seed 004 at the meta-module level: a `meta_modules` schedule replayed on
//! its 2×2×2 cells, without expanding it into atom operations, for
//! schedules whose moves have no derived atom sequence (k-TUNNELs with
//! legs longer than one meta-module). What it checks is the paper's own
//! rules for its moves (§2, Lemmas 1–3), not the atoms':
//!
//! * SLIDE: the wall B beside the slider, static, attached to it, and the
//!   meta-module C beside B along the slide present and static; the slider
//!   lets go of B and ends attached to C. A carried meta-module (no pivot)
//!   is attached, through meta-modules moving the same way, to a slider.
//! * k-TUNNEL: an orthogonal path through static meta-modules to a free
//!   exit, at most 4 turns; the start a leaf attached only to the path; no
//!   meta-module attached to a leg between turns (the O(1)-operation
//!   precondition); the leaf ends attached to the exit's neighbour on the
//!   path.
//! * latches: detaching attached pairs, attaching neighbours.
//! * connectivity: the bonds held through each step, and those at its end,
//!   join every meta-module to a fixed one (or into one piece if none is).
//! * in place: every meta-module within the union of the source's and the
//!   target's bounding boxes.
//!
//! The atoms' kinematics, collisions and loads are not checked here; the
//! report says so.

use super::Options;
use super::report::{REPORT_FORMAT, Report, StepResult, Violation, ViolationKind};
use crate::error::InputError;
use crate::lattice::Cell;
use crate::lattice::config::ModuleId;
use crate::schedule::{Event, Schedule};
use rustc_hash::{FxHashMap, FxHashSet};
use std::collections::BTreeMap;

/// The check's line in the report.
pub const NAME: &str = "meta-module level (SLIDE and k-TUNNEL preconditions, latches, connectivity, in place); atom operations NOT certified";

/// Most turns of a tunnel (the paper's algorithms need k ≤ 4).
pub const MAX_TURNS: usize = 4;

fn pair(a: usize, b: usize) -> (usize, usize) {
    (a.min(b), a.max(b))
}

struct Scene {
    ids: Vec<ModuleId>,
    pos: Vec<Cell>,
    at: FxHashMap<Cell, usize>,
    attached: FxHashSet<(usize, usize)>,
    fixed: Vec<usize>,
}

impl Scene {
    /// The meta-modules attached to `m` (bonds join neighbours only: a
    /// pair that moves apart is reported and let go).
    fn partners(&self, m: usize) -> Vec<usize> {
        crate::lattice::Face::ALL
            .iter()
            .filter_map(|f| self.at.get(&(self.pos[m] + f.dir())).copied())
            .filter(|&o| self.attached.contains(&pair(m, o)))
            .collect()
    }

    /// Meta-modules not joined by `bonds` to a fixed one (to the first if
    /// none is fixed), by union–find over the bonds (petgraph's).
    fn loose(&self, bonds: &FxHashSet<(usize, usize)>) -> Vec<ModuleId> {
        let n = self.pos.len();
        let mut uf = petgraph::unionfind::UnionFind::<usize>::new(n);
        for &(a, b) in bonds {
            uf.union(a, b);
        }
        let roots: Vec<usize> = if self.fixed.is_empty() {
            (0..n.min(1)).collect()
        } else {
            self.fixed.clone()
        };
        (0..n)
            .filter(|&a| !roots.iter().any(|&r| uf.equiv(a, r)))
            .map(|a| self.ids[a])
            .collect()
    }
}

fn bounds(cells: impl Iterator<Item = Cell>) -> (Cell, Cell) {
    let mut lo = Cell::new(i32::MAX, i32::MAX, i32::MAX);
    let mut hi = Cell::new(i32::MIN, i32::MIN, i32::MIN);
    for c in cells {
        lo = Cell::new(lo.x.min(c.x), lo.y.min(c.y), lo.z.min(c.z));
        hi = Cell::new(hi.x.max(c.x), hi.y.max(c.y), hi.z.max(c.z));
    }
    (lo, hi)
}

fn inside(c: Cell, b: (Cell, Cell)) -> bool {
    (b.0.x..=b.1.x).contains(&c.x)
        && (b.0.y..=b.1.y).contains(&c.y)
        && (b.0.z..=b.1.z).contains(&c.z)
}

/// Where each motion ends, in one pass (the target of the in-place bound).
fn final_cells(s: &Schedule) -> Vec<Cell> {
    let mut at: BTreeMap<ModuleId, Cell> = s.modules.iter().map(|m| (m.id, m.cell)).collect();
    for step in &s.steps {
        for e in &step.events {
            match e {
                Event::Slide { module, to, .. } => {
                    at.insert(*module, *to);
                }
                Event::Tunnel { module, path } => {
                    if let Some(&c) = path.last() {
                        at.insert(*module, c);
                    }
                }
                _ => {}
            }
        }
    }
    at.into_values().collect()
}

/// Certifies a `meta_modules` schedule at the meta-module level (see the
/// module doc). Unusable input (unknown meta-modules, a move from a cell
/// it is not in, a path that is not a chain of neighbours, a fixed
/// meta-module moving, an atom event) is an error naming the step and the
/// meta-module.
pub fn certify_meta_level(schedule: &Schedule, opts: &Options) -> Result<Report, InputError> {
    let index: FxHashMap<ModuleId, usize> = schedule
        .modules
        .iter()
        .enumerate()
        .map(|(k, m)| (m.id, k))
        .collect();
    let pos: Vec<Cell> = schedule.modules.iter().map(|m| m.cell).collect();
    let at: FxHashMap<Cell, usize> = pos.iter().enumerate().map(|(k, &c)| (c, k)).collect();
    let mut attached = FxHashSet::default();
    for (k, &c) in pos.iter().enumerate() {
        for d in [Cell::new(1, 0, 0), Cell::new(0, 1, 0), Cell::new(0, 0, 1)] {
            if let Some(&o) = at.get(&(c + d)) {
                attached.insert(pair(k, o));
            }
        }
    }
    let mut sc = Scene {
        ids: schedule.modules.iter().map(|m| m.id).collect(),
        fixed: (0..pos.len())
            .filter(|&k| schedule.modules[k].fixed)
            .collect(),
        pos,
        at,
        attached,
    };
    let (src, tgt) = (
        bounds(sc.pos.iter().copied()),
        bounds(final_cells(schedule).into_iter()),
    );
    let mut report = Report {
        format: REPORT_FORMAT.to_string(),
        version: 1,
        schedule: opts.name.clone(),
        lattice: schedule.lattice,
        modules: schedule.modules.len(),
        final_modules: schedule.modules.len(),
        steps: schedule.steps.len(),
        moves: schedule.move_count(),
        window: None,
        checks: vec![NAME.to_string()],
        load_factor_tolerance: 0.0,
        certified: false,
        stopped_at: None,
        violations: Vec::new(),
        warnings: Vec::new(),
        per_step: Vec::with_capacity(schedule.steps.len()),
    };
    let loose = sc.loose(&sc.attached);
    if !loose.is_empty() {
        report.violations.push(
            Violation::new(
                ViolationKind::Disconnected,
                0,
                "the source is not one attached piece",
            )
            .modules(loose),
        );
    }
    for (k0, step) in schedule.steps.iter().enumerate() {
        let k = k0 + 1;
        let before = report.violations.len();
        let mut v = Vec::new();
        meta_step(&mut sc, &index, k, &step.events, (src, tgt), &mut v)?;
        report.violations.extend(v);
        report.per_step.push(StepResult {
            step: k,
            moves: step.events.iter().filter(|e| e.is_motion()).count(),
            violations: report.violations.len() - before,
            warnings: 0,
            metrics: BTreeMap::new(),
        });
    }
    report.certified = report.violations.is_empty();
    Ok(report)
}

/// One step: detaches, the moves (checked against the scene before them),
/// relatching, attaches; then connectivity and the in-place bound.
fn meta_step(
    sc: &mut Scene,
    index: &FxHashMap<ModuleId, usize>,
    k: usize,
    events: &[Event],
    boxes: ((Cell, Cell), (Cell, Cell)),
    out: &mut Vec<Violation>,
) -> Result<(), InputError> {
    let id = |m: ModuleId| -> Result<usize, InputError> {
        index.get(&m).copied().ok_or_else(|| {
            InputError::new(format!("meta-module {m} is not in the schedule"))
                .at_step(k)
                .for_module(m)
        })
    };
    let mut held = sc.attached.clone();
    let mut attaches = Vec::new();
    let mut moves: FxHashMap<usize, Cell> = FxHashMap::default();
    for e in events {
        match e {
            Event::Detach { module, other } => {
                let p = pair(id(*module)?, id(*other)?);
                if !held.remove(&p) {
                    out.push(
                        Violation::new(
                            ViolationKind::LatchNotAdjacent,
                            k,
                            format!("meta-modules {module} and {other} are not attached; they cannot detach"),
                        )
                        .modules([*module, *other]),
                    );
                }
            }
            Event::Attach { module, other } => attaches.push((id(*module)?, id(*other)?)),
            Event::Slide { module, .. } | Event::Tunnel { module, .. } => {
                let a = id(*module)?;
                let (from, to) = match e {
                    Event::Slide { from, to, .. } => (*from, *to),
                    Event::Tunnel { path, .. } => (
                        *path.first().ok_or_else(|| {
                            InputError::new("an empty tunnel path")
                                .at_step(k)
                                .for_module(*module)
                        })?,
                        *path.last().expect("not empty"),
                    ),
                    _ => unreachable!(),
                };
                let err = |m: String| InputError::new(m).at_step(k).for_module(*module);
                if sc.pos[a] != from {
                    return Err(err(format!(
                        "meta-module {module} is at {}, not at {from}",
                        sc.pos[a]
                    )));
                }
                if sc.fixed.contains(&a) {
                    return Err(err(format!(
                        "meta-module {module} is fixed and cannot move"
                    )));
                }
                if let Some(&other) = moves.get(&a)
                    && other != to
                {
                    return Err(err(format!(
                        "meta-module {module} is given two different moves"
                    )));
                }
                moves.insert(a, to);
            }
            e => {
                return Err(InputError::new(format!(
                    "a meta-module schedule holds SLIDEs, tunnels, attaches and detaches, not {e:?}"
                ))
                .at_step(k)
                .for_module(e.module()));
            }
        }
    }
    let moving = |m: usize| moves.contains_key(&m);
    let mut relatch: Vec<((usize, usize), (usize, usize))> = Vec::new();
    let mut carried = Vec::new();
    for e in events {
        match e {
            Event::Slide {
                module,
                from,
                to,
                pivot: Some(p),
            } => {
                let (a, b) = (id(*module)?, id(*p)?);
                let d = *to - *from;
                let wall = sc.pos[b];
                let side = wall - *from;
                let c = sc.at.get(&(wall + d)).copied();
                let why = if side.l1() != 1
                    || d.l1() != 1
                    || side.x * d.x + side.y * d.y + side.z * d.z != 0
                {
                    Some(format!(
                        "its wall {p} at {wall} is not beside {from} across the slide {from} → {to}"
                    ))
                } else if moving(b) {
                    Some(format!("its wall {p} moves in the same step"))
                } else if !held.contains(&pair(a, b)) {
                    Some(format!("it is not attached to its wall {p}"))
                } else if c.is_none_or(moving) {
                    Some(format!(
                        "no static meta-module beside its wall at {}",
                        wall + d
                    ))
                } else {
                    None
                };
                if let Some(why) = why {
                    out.push(
                        Violation::new(
                            ViolationKind::MoverDetached,
                            k,
                            format!("SLIDE of meta-module {module}: {why}"),
                        )
                        .modules([*module, *p])
                        .cells([*from, *to]),
                    );
                } else if let Some(c) = c {
                    relatch.push((pair(a, b), pair(a, c)));
                }
            }
            Event::Slide {
                module,
                from,
                to,
                pivot: None,
            } => carried.push((id(*module)?, *to - *from)),
            Event::Tunnel { module, path } => {
                let a = id(*module)?;
                if let Some(w) = path.windows(2).find(|w| (w[1] - w[0]).l1() != 1) {
                    return Err(InputError::new(format!(
                        "the tunnel path steps from {} to {}, which are not neighbours",
                        w[0], w[1]
                    ))
                    .at_step(k)
                    .for_module(*module));
                }
                if path.len() < 3 {
                    return Err(InputError::new(
                        "a tunnel path needs a start, at least one interior cell and an exit",
                    )
                    .at_step(k)
                    .for_module(*module));
                }
                let tunnel = |why: String| {
                    Violation::new(
                        ViolationKind::TunnelPrecondition,
                        k,
                        format!("tunnel of meta-module {module}: {why}"),
                    )
                    .modules([*module])
                    .cells(path.iter().copied())
                };
                let exit = *path.last().expect("long enough");
                if sc.at.contains_key(&exit) {
                    out.push(tunnel(format!("its exit {exit} is occupied")));
                }
                let turns = crate::lattice::path_turns(path);
                let mut ok = true;
                for (i, c) in path.iter().enumerate().take(path.len() - 1).skip(1) {
                    match sc.at.get(c) {
                        Some(&m) if !moving(m) => {
                            let off: Vec<usize> = sc
                                .partners(m)
                                .into_iter()
                                .filter(|&o| {
                                    held.contains(&pair(m, o)) && !path.contains(&sc.pos[o])
                                })
                                .collect();
                            if !turns.contains(&i) && !off.is_empty() {
                                out.push(tunnel(format!(
                                    "meta-module {} is attached to the leg at {c} between turns",
                                    sc.ids[off[0]]
                                )));
                            }
                        }
                        _ => {
                            out.push(tunnel(format!(
                                "its path cell {c} holds no static meta-module"
                            )));
                            ok = false;
                        }
                    }
                }
                if turns.len() > MAX_TURNS {
                    out.push(tunnel(format!(
                        "{} turns, more than {MAX_TURNS}",
                        turns.len()
                    )));
                }
                let partners: Vec<usize> = sc
                    .partners(a)
                    .into_iter()
                    .filter(|&o| held.contains(&pair(a, o)))
                    .collect();
                let next = sc.at.get(&path[1]).copied();
                if partners.len() != 1 || next != Some(partners[0]) {
                    out.push(tunnel(format!(
                        "its start {} is not a leaf attached only to the path's next cell",
                        path[0]
                    )));
                }
                if ok {
                    let support = sc.at[&path[path.len() - 2]];
                    for o in partners {
                        relatch.push((pair(a, o), pair(a, support)));
                    }
                }
            }
            _ => {}
        }
    }
    // A carried meta-module rides, through meta-modules moving the same
    // way, on a slider.
    let pivoted: FxHashSet<usize> = events
        .iter()
        .filter_map(|e| match e {
            Event::Slide {
                module,
                pivot: Some(_),
                ..
            } => index.get(module).copied(),
            _ => None,
        })
        .collect();
    for (a, d) in carried {
        let mut seen = FxHashSet::from_iter([a]);
        let mut stack = vec![a];
        let mut rides = false;
        while let Some(m) = stack.pop() {
            if pivoted.contains(&m) {
                rides = true;
                break;
            }
            for o in sc.partners(m) {
                if held.contains(&pair(m, o))
                    && moves.get(&o).is_some_and(|&t| t - sc.pos[o] == d)
                    && seen.insert(o)
                {
                    stack.push(o);
                }
            }
        }
        if !rides {
            out.push(
                Violation::new(
                    ViolationKind::MoverDetached,
                    k,
                    format!(
                        "carried meta-module {} is not attached, through meta-modules moving with it, to a slider",
                        sc.ids[a]
                    ),
                )
                .modules([sc.ids[a]]),
            );
        }
    }
    let loose = sc.loose(&held);
    if !loose.is_empty() {
        out.push(
            Violation::new(
                ViolationKind::Disconnected,
                k,
                format!(
                    "the bonds held through the step leave {} meta-module(s) apart",
                    loose.len()
                ),
            )
            .modules(loose),
        );
    }
    // Apply: moves, relatching, attaches.
    for a in moves.keys() {
        sc.at.remove(&sc.pos[*a]);
    }
    let mut arrivals: Vec<(usize, Cell)> = moves.iter().map(|(&a, &c)| (a, c)).collect();
    arrivals.sort_unstable();
    for (a, c) in arrivals {
        if let Some(&o) = sc.at.get(&c) {
            out.push(
                Violation::new(
                    ViolationKind::Occupancy,
                    k,
                    format!(
                        "meta-modules {} and {} both end the step at {c}",
                        sc.ids[a], sc.ids[o]
                    ),
                )
                .modules([sc.ids[a], sc.ids[o]])
                .cells([c]),
            );
        }
        sc.pos[a] = c;
        sc.at.insert(c, a);
        if !inside(c, boxes.0) && !inside(c, boxes.1) {
            out.push(
                Violation::new(
                    ViolationKind::OutOfPlace,
                    k,
                    format!(
                        "meta-module {} at {c} leaves the union of the source's and the target's bounding boxes",
                        sc.ids[a]
                    ),
                )
                .modules([sc.ids[a]])
                .cells([c]),
            );
        }
    }
    sc.attached = held;
    for (old, new) in relatch {
        sc.attached.remove(&old);
        sc.attached.insert(new);
    }
    for (a, b) in attaches {
        if (sc.pos[a] - sc.pos[b]).l1() != 1 {
            out.push(
                Violation::new(
                    ViolationKind::LatchNotAdjacent,
                    k,
                    format!(
                        "meta-modules {} at {} and {} at {} are not neighbours; they cannot attach",
                        sc.ids[a], sc.pos[a], sc.ids[b], sc.pos[b]
                    ),
                )
                .modules([sc.ids[a], sc.ids[b]]),
            );
        } else {
            sc.attached.insert(pair(a, b));
        }
    }
    let mut torn: Vec<(usize, usize)> = sc
        .attached
        .iter()
        .copied()
        .filter(|&(a, b)| (sc.pos[a] - sc.pos[b]).l1() != 1)
        .collect();
    torn.sort_unstable();
    for (a, b) in torn {
        out.push(
            Violation::new(
                ViolationKind::LatchNotAdjacent,
                k,
                format!(
                    "meta-modules {} and {} move apart while attached",
                    sc.ids[a], sc.ids[b]
                ),
            )
            .modules([sc.ids[a], sc.ids[b]]),
        );
        sc.attached.remove(&(a, b));
    }
    let loose = sc.loose(&sc.attached);
    if !loose.is_empty() {
        out.push(
            Violation::new(
                ViolationKind::Disconnected,
                k,
                format!(
                    "at the end of the step {} meta-module(s) hang apart",
                    loose.len()
                ),
            )
            .modules(loose),
        );
    }
    Ok(())
}
