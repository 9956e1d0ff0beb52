//! Seed 000: deterministic scaffold assembly from a sandbox (Thalamy et
//! al.), as a generator of real per-step rotations.
//!
//! * [`shape`] / [`csg`] — goal shapes (h-pyramids, cubes, CSG files);
//! * [`scaffold`] — tiles, branches, supports, sandbox, entry points;
//! * [`polytree`] — the construction order;
//! * [`planner`] — motion of every module from the sandbox to its cell;
//! * [`paper`] — the paper's own motion constraint and light protocol;
//! * [`feed`] — when modules leave the sandbox (just in time, or eagerly
//!   as the authors' implementation feeds them);
//! * [`flow`] — No-Surplus, or Continuous Flow's surplus on the branches;
//! * the modules-placed-per-step curves (seed 000 Figs. 13–16) are drawn
//!   in [`crate::study::scaffold_figures`], not here.
//!
//! See `docs/scaffold.md`.

pub mod csg;
mod csg_text;
pub mod feed;
pub mod flow;
pub mod paper;
pub mod planner;
pub mod polytree;
#[allow(clippy::module_inception)]
pub mod scaffold;
pub mod shape;
pub mod vs_csg;

use super::{Generator, choice, parameters};
use crate::error::InputError;
use crate::geometry::MotionRules;
use crate::lattice::config::{Ground, ModuleId};
use crate::lattice::{Cell, LatticeKind};
use crate::scenario::Scenario;
use crate::schedule::{Event, Length, ModuleSpec, Schedule, Step};
use feed::Feed;
use flow::Flow;
use paper::Protocol;
use rustc_hash::FxHashMap;
use scaffold::Scaffold;
use serde::Deserialize;
use shape::{CubeShape, Pyramid, Shape, Skew};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// A goal shape, as the library API and scenarios name it.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeSpec {
    /// Seed 000 §4's h-pyramid (h tiles wide at the base, h tile layers).
    Pyramid { h: u32 },
    /// Seed 000 §5.3.1's cube of side `(h − 1)·b + e` modules.
    Cube { h: u32, e: u32 },
    /// A CSG file (see [`csg`]).
    Csg { path: PathBuf },
}

/// Rules the planner uses: for the safe protocol, the FCC motion rules the
/// geometry layer derives from the exact catom body (SPEC §4.4); for the
/// paper's, its §3 bridging constraint alone.
pub fn motion_rules(protocol: Protocol) -> Result<&'static dyn MotionRules, InputError> {
    match protocol {
        Protocol::Safe => crate::geometry::motion_rules(LatticeKind::Fcc)
            .ok_or_else(|| InputError::new("this build derives no FCC motion rules to plan with")),
        Protocol::Paper => Ok(&paper::BridgingRules),
    }
}

/// Largest side of a scaffold's shape, in cells (3.7 m of 3.6 mm catoms):
/// beyond it the input is refused before any work.
pub const MAX_EXTENT: i64 = 1024;
/// Largest scaffold planned, in modules (the sandcastle has 30,634).
pub const MAX_MODULES: usize = 1_000_000;

/// A side of `extent` cells, refused beyond [`MAX_EXTENT`] before any
/// arithmetic can overflow.
fn side(what: &str, extent: i64) -> Result<i32, InputError> {
    if extent > MAX_EXTENT {
        return Err(InputError::new(format!(
            "{what} spans {extent} cells; a scaffold spans at most {MAX_EXTENT} cells a side"
        )));
    }
    Ok(extent as i32)
}

/// The scaffold of a shape with branch length `b`, refused (with the
/// reason) when it is larger than [`MAX_EXTENT`] or [`MAX_MODULES`].
pub fn build_scaffold(shape: &ShapeSpec, b: u32) -> Result<Scaffold, InputError> {
    if b as i64 > MAX_EXTENT {
        return Err(InputError::new(format!(
            "branch length b = {b} is longer than a scaffold's largest side, {MAX_EXTENT} cells"
        )));
    }
    let bi = b as i32;
    match shape {
        ShapeSpec::Pyramid { h } => {
            if *h < 1 {
                return Err(InputError::new("a pyramid needs h ≥ 1"));
            }
            let top = side(
                &format!("a {h}-pyramid with b = {b}"),
                (*h as i64 - 1) * bi as i64,
            )?;
            Scaffold::build(
                &Pyramid { h: *h, b },
                b,
                (Skew::new(0, 0, 0), Skew::new(top, top, top)),
            )
        }
        ShapeSpec::Cube { h, e } => {
            if *h < 1 || *e < 1 || *e > b {
                return Err(InputError::new(format!(
                    "a cube needs h ≥ 1 and 1 ≤ e ≤ b (got h = {h}, e = {e}, b = {b})"
                )));
            }
            // Seed 000 §3.2.2 puts the lower bound at b = 4 for tiles to
            // let modules through. For cubes at b = 4 the planner finds no
            // route to the tip of an upward branch once a tile stands on a
            // full-length branch: measured failing for h = 2 with e = b and
            // for h = 3 with every e = 1…4; h = 2 with e ≤ 3 plans and
            // certifies. Refused up front (naming the parameters) rather
            // than failing mid-plan on one module.
            if b == 4 && (*h >= 3 || *e == b) {
                return Err(InputError::new(format!(
                    "a cube with b = 4 plans only for h ≤ 2 and e < b (got h = {h}, e = {e}, \
                     b = {b}): the 4-tiles are too dense for modules to reach the tips of \
                     upward branches; use b ≥ 5, or e ≤ 3 with h = 2"
                )));
            }
            let l = side(
                &format!("a cube of {h} tiles with e = {e}, b = {b}"),
                (*h as i64 - 1) * bi as i64 + *e as i64,
            )?;
            Scaffold::build(
                &CubeShape { l },
                b,
                (Skew::new(-l, -l, 0), Skew::new(l, l, l)),
            )
        }
        ShapeSpec::Csg { path } if path.extension().is_some_and(|e| e == "xml") => {
            // A VisibleSim configuration: its CSG target, read as the
            // authors' scaffolding_csg application reads it.
            let s = vs_csg::VsCsgShape::load(path)?;
            let bounds = s.skew_bounds().ok_or_else(|| {
                InputError::new("the CSG target contains no grid cell").in_file(path)
            })?;
            Scaffold::build(&s as &dyn Shape, b, bounds).map_err(|e| e.in_file(path))
        }
        ShapeSpec::Csg { path } => {
            let s = csg::CsgShape::load(path)?;
            let bounds = s.skew_bounds();
            Scaffold::build(&s as &dyn Shape, b, bounds).map_err(|e| e.in_file(path))
        }
    }
}

/// Generates the schedule that assembles `shape`'s scaffold with branch
/// length `b` from the sandbox (No-Surplus variant: exactly one module per
/// scaffold cell).
pub fn scaffold_schedule(shape: &ShapeSpec, b: u32) -> Result<Schedule, InputError> {
    scaffold_schedule_with(shape, b, Protocol::Safe)
}

/// [`scaffold_schedule`] with the coordination `protocol` (see [`paper`]).
pub fn scaffold_schedule_with(
    shape: &ShapeSpec,
    b: u32,
    protocol: Protocol,
) -> Result<Schedule, InputError> {
    scaffold_schedule_fed(shape, b, protocol, Feed::JustInTime)
}

/// [`scaffold_schedule_fed`] with surplus modules as `flow` says (see
/// [`flow`]).
pub fn scaffold_schedule_flowing(
    shape: &ShapeSpec,
    b: u32,
    protocol: Protocol,
    feed: Feed,
    flow: Flow,
) -> Result<Schedule, InputError> {
    let s = build_scaffold(shape, b)?;
    let mut sched = schedule_for(&s, motion_rules(protocol)?, protocol, feed, flow)?;
    sched
        .meta
        .insert("shape".into(), format!("{shape:?}").into());
    Ok(sched)
}

/// [`scaffold_schedule_with`], the sandbox releasing modules as `feed`
/// says (see [`feed`]).
pub fn scaffold_schedule_fed(
    shape: &ShapeSpec,
    b: u32,
    protocol: Protocol,
    feed: Feed,
) -> Result<Schedule, InputError> {
    scaffold_schedule_flowing(shape, b, protocol, feed, Flow::NoSurplus)
}

/// Plans every module of a scaffold and writes the schedule: with the
/// first modules of each unsupported border branch early, or, where some
/// module then finds no route, with the whole branch early (see
/// [`polytree::BorderBranches`]; the schedule's `meta.border_branches`
/// says which).
pub fn schedule_for(
    s: &Scaffold,
    rules: &dyn MotionRules,
    protocol: Protocol,
    feed: Feed,
    flow: Flow,
) -> Result<Schedule, InputError> {
    schedule_with_border(
        s,
        rules,
        protocol,
        feed,
        flow,
        polytree::BorderBranches::FirstModules,
    )
    .or_else(|_| {
        schedule_with_border(
            s,
            rules,
            protocol,
            feed,
            flow,
            polytree::BorderBranches::Whole,
        )
    })
}

/// [`schedule_for`] with as much of each border branch early as `border`
/// says, and no fallback.
pub fn schedule_with_border(
    s: &Scaffold,
    rules: &dyn MotionRules,
    protocol: Protocol,
    feed: Feed,
    flow: Flow,
    border: polytree::BorderBranches,
) -> Result<Schedule, InputError> {
    let tree = polytree::Polytree::build_with(
        s,
        match protocol {
            Protocol::Safe => polytree::Supports::OneAfterAnother,
            Protocol::Paper => polytree::Supports::Together,
        },
        border,
    );
    let n = s.components.len();
    let mut succ = vec![Vec::new(); n];
    let mut missing: Vec<usize> = tree.preds.iter().map(Vec::len).collect();
    for (i, ps) in tree.preds.iter().enumerate() {
        for &p in ps {
            succ[p].push(i);
        }
    }
    let rank: Vec<usize> = {
        let mut r = vec![0; n];
        for (k, i) in tree.topological().into_iter().enumerate() {
            r[i] = k;
        }
        r
    };
    let mut ready_at = vec![0usize; n];
    let mut open: std::collections::BinaryHeap<std::cmp::Reverse<(usize, usize, usize)>> = (0..n)
        .filter(|&i| missing[i] == 0)
        .map(|i| std::cmp::Reverse((0, rank[i], i)))
        .collect();
    let mut planner = planner::Planner::new(s, rules, protocol, feed);
    let mut next_id = s.sandbox.len() as ModuleId;
    let mut sources = std::collections::BTreeSet::new();
    let all_sources: Vec<(Skew, Cell)> = s
        .tiles
        .iter()
        .filter(|(_, t)| t.layer == 0)
        .flat_map(|(&g, _)| scaffold::Dir::UPWARD.map(|u| (g, s.source(g, u).cell())))
        .collect();
    let mut planned = 0;
    while let Some(std::cmp::Reverse((ready, _, i))) = open.pop() {
        let c = &s.components[i];
        // The entry point of the feeding chain first (§3.3.2); the others
        // of its ground tile, then any, at a penalty: an entry point hemmed
        // in by finished branches cannot send modules anywhere.
        let preferred = s.source_for(c);
        let ground = preferred.offset(scaffold::Dir::Z.epl_offset().scale(-1));
        let ground = all_sources
            .iter()
            .map(|&(g, _)| g)
            .find(|g| {
                scaffold::Dir::UPWARD
                    .iter()
                    .any(|&u| s.source(*g, u) == preferred)
            })
            .unwrap_or(ground);
        let srcs: Vec<(Cell, u32)> = all_sources
            .iter()
            .map(|&(g, cell)| {
                (
                    cell,
                    if cell == preferred.cell() {
                        0
                    } else if g == ground {
                        3
                    } else {
                        8
                    },
                )
            })
            .collect();
        let near: Vec<(Cell, u32)> = srcs.iter().copied().filter(|s| s.1 <= 3).collect();
        let (src, at) = planner
            .plan(next_id, &near, c.cell.cell(), ready)
            .or_else(|_| planner.plan(next_id, &srcs, c.cell.cell(), ready))
            .map_err(|e| {
                InputError::new(format!(
                    "{:?} of tile {:?}: {}",
                    c.part,
                    (c.tile.x, c.tile.y, c.tile.z),
                    e.message
                ))
                .for_module(next_id)
            })?;
        sources.insert(src);
        next_id += 1;
        planned += 1;
        for &j in &succ[i] {
            ready_at[j] = ready_at[j].max(at);
            missing[j] -= 1;
            if missing[j] == 0 {
                open.push(std::cmp::Reverse((ready_at[j], rank[j], j)));
            }
        }
    }
    if planned != n {
        return Err(InputError::new(format!(
            "construction order is cyclic: {planned} of {n} components planned"
        )));
    }
    let scaffold_complete = planner.horizon();
    let surplus = match flow {
        Flow::NoSurplus => None,
        Flow::Continuous => Some(plan_surplus(s, &mut planner, &mut next_id, &mut sources)),
    };
    let mut sched = Schedule::new(LatticeKind::Fcc, Length::mm(3.6));
    sched.ground = Some(Ground {
        layer: s.sandbox_layer,
    });
    sched.modules = s
        .sandbox
        .iter()
        .enumerate()
        .map(|(i, c)| ModuleSpec {
            id: i as ModuleId,
            cell: c.cell(),
            fixed: true,
        })
        .collect();
    sched.sources = sources.into_iter().collect();
    sched.steps = planner
        .events
        .into_iter()
        .map(|mut events| {
            events.sort_by_key(|e| e.module());
            Step { events }
        })
        .collect();
    sched.meta.insert("algorithm".into(), "scaffold".into());
    sched.meta.insert("b".into(), s.b.into());
    sched.meta.insert("protocol".into(), protocol.name().into());
    sched.meta.insert("feed".into(), feed.name().into());
    sched
        .meta
        .insert("border_branches".into(), border.name().into());
    if let Feed::Eager { window } = feed {
        sched.meta.insert("eager_window".into(), window.into());
    }
    sched.meta.insert("flow".into(), flow.name().into());
    if let Some(surplus) = surplus {
        let m = &mut sched.meta;
        m.insert("scaffold_complete_step".into(), scaffold_complete.into());
        m.insert("surplus_modules".into(), surplus.parked.into());
        m.insert("surplus_unreached".into(), surplus.unreached.into());
        m.insert("surplus_chains".into(), surplus.chains.into());
        let ub = flow::upward_branches(s);
        m.insert("upward_branches".into(), ub.into());
        m.insert(
            "paper_surplus".into(),
            flow::paper_surplus(ub, s.b as u32).into(),
        );
    }
    sched.meta.insert("tiles".into(), s.tiles.len().into());
    // Seed 000's Eq. 6 times the critical path: the step at which the
    // first tile root of each tile layer is in place (1-based steps).
    let mut layer_roots: BTreeMap<i32, Vec<Cell>> = BTreeMap::new();
    for (root, t) in &s.tiles {
        layer_roots.entry(t.layer).or_default().push(root.cell());
    }
    let arrival: FxHashMap<Cell, usize> = sched
        .steps
        .iter()
        .enumerate()
        .flat_map(|(k, st)| {
            st.events.iter().filter_map(move |e| match e {
                Event::Rotate { to, .. } => Some((*to, k + 1)),
                _ => None,
            })
        })
        .collect();
    let root_steps: Vec<usize> = layer_roots
        .values()
        .map(|cells| {
            cells
                .iter()
                .filter_map(|c| arrival.get(c).copied())
                .min()
                .unwrap_or(0)
        })
        .collect();
    sched
        .meta
        .insert("tile_layers".into(), layer_roots.len().into());
    sched
        .meta
        .insert("layer_root_steps".into(), root_steps.into());
    sched.meta.insert("scaffold_modules".into(), n.into());
    sched
        .meta
        .insert("sandbox_modules".into(), s.sandbox.len().into());
    Ok(sched)
}

/// What Continuous Flow parked (see [`flow`]).
struct Surplus {
    parked: usize,
    unreached: usize,
    chains: usize,
}

/// Plans Continuous Flow's surplus modules after the scaffold's: each
/// chain's parking cells, terminal first, round-robin over the chains.
fn plan_surplus(
    s: &Scaffold,
    planner: &mut planner::Planner,
    next_id: &mut ModuleId,
    sources: &mut std::collections::BTreeSet<Cell>,
) -> Surplus {
    let chains = flow::chains(s);
    // Each chain's route over the finished scaffold, entry point first.
    let routes: Vec<(Cell, Vec<Cell>)> = chains
        .iter()
        .map(|c| {
            let (src, terminal) = (c.source.cell(), c.terminal.cell());
            let cells = match planner.route(&[(src, 0)], terminal) {
                Some((_, hops)) if !planner.is_occupied(terminal) => std::iter::once(src)
                    .chain(hops.iter().map(|h| h.to))
                    .collect(),
                _ => Vec::new(),
            };
            (src, cells)
        })
        .collect();
    let parking: Vec<Vec<usize>> = routes
        .iter()
        .map(|(_, cells)| {
            let layers: Vec<i32> = cells
                .iter()
                .map(|&c| crate::lattice::FccLattice::to_skewed(c).2)
                .collect();
            flow::parking_indices(&layers)
        })
        .collect();
    // A chain that climbs a branch and has no route to its terminal
    // parks nothing: its terminal counts as unreached.
    let mut out = Surplus {
        parked: 0,
        unreached: chains
            .iter()
            .zip(&routes)
            .filter(|(c, (_, cells))| c.branches > 0 && cells.is_empty())
            .count(),
        chains: chains.len(),
    };
    let rounds = parking.iter().map(Vec::len).max().unwrap_or(0);
    for r in 0..rounds {
        for ((src, cells), spots) in routes.iter().zip(&parking) {
            let Some(&i) = spots.get(r) else { continue };
            // A cell another chain's module took is that chain's surplus.
            let tries: Vec<usize> = [i, i - 1]
                .into_iter()
                .filter(|&k| k >= flow::PARKING_CLEARANCE && !planner.is_occupied(cells[k]))
                .collect();
            let mut parked = false;
            for k in tries {
                if planner
                    .plan_when_route_stands(*next_id, &[(*src, 0)], cells[k])
                    .is_ok()
                {
                    sources.insert(*src);
                    *next_id += 1;
                    parked = true;
                    break;
                }
            }
            if parked {
                out.parked += 1;
            } else if !planner.is_occupied(cells[i]) {
                out.unreached += 1;
            }
        }
    }
    out
}

/// Scenario parameters of the `scaffold` generator.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    /// "pyramid", "cube" or "csg".
    shape: String,
    #[serde(default)]
    h: Option<u32>,
    #[serde(default)]
    e: Option<u32>,
    #[serde(default = "default_b")]
    b: u32,
    /// CSG file, relative to the scenario (with `shape = "csg"`).
    #[serde(default)]
    csg: Option<String>,
    /// "safe" (default) or "paper" (see [`paper::Protocol`]).
    #[serde(default)]
    protocol: Option<String>,
    /// "just-in-time" (default) or "eager" (see [`feed::Feed`]).
    #[serde(default)]
    feed: Option<String>,
    /// With `feed = "eager"`: how many steps before its just-in-time
    /// departure a module may leave (default [`feed::EAGER_WINDOW`]).
    #[serde(default)]
    eager_window: Option<u32>,
    /// "no-surplus" (default) or "continuous" (see [`flow::Flow`]).
    #[serde(default)]
    flow: Option<String>,
}

/// The widest `eager_window` a scenario may ask for: each step of window
/// is one more departure tried per module (the sandcastle takes 86 s to
/// generate at 100), and from 40 on the window no longer binds.
const MAX_EAGER_WINDOW: u32 = 1000;

fn default_b() -> u32 {
    6
}

/// The `scaffold` generator (seed 000).
pub struct ScaffoldAssembly;

impl Generator for ScaffoldAssembly {
    fn name(&self) -> &'static str {
        "scaffold"
    }

    fn about(&self) -> &'static str {
        "seed 000: scaffold assembly from a sandbox (pyramids, cubes, semi-convex CSG shapes)"
    }

    fn generate(&self, scenario: &Scenario) -> Result<Schedule, InputError> {
        let p: Params = parameters(scenario)?;
        let need = |v: Option<u32>, what: &str| {
            v.ok_or_else(|| scenario.error(format!("shape '{}' needs parameter {what}", p.shape)))
        };
        let spec = match p.shape.as_str() {
            "pyramid" => ShapeSpec::Pyramid { h: need(p.h, "h")? },
            "cube" => ShapeSpec::Cube {
                h: need(p.h, "h")?,
                e: p.e.unwrap_or(p.b),
            },
            "csg" => {
                let rel = p
                    .csg
                    .clone()
                    .ok_or_else(|| scenario.error("shape 'csg' needs parameter csg (a file)"))?;
                ShapeSpec::Csg {
                    path: scenario.resolve(&rel),
                }
            }
            other => {
                return Err(scenario.error(format!(
                    "unknown shape '{other}' (known: pyramid, cube, csg)"
                )));
            }
        };
        let protocol = choice(
            scenario,
            "protocol",
            p.protocol.as_deref(),
            Protocol::parse,
            "safe, paper",
        )?;
        let feed = choice(
            scenario,
            "feed",
            p.feed.as_deref(),
            Feed::parse,
            "just-in-time, eager",
        )?;
        let feed = match (feed, p.eager_window) {
            (_, None) => feed,
            (Feed::Eager { .. }, Some(w)) if w <= MAX_EAGER_WINDOW => {
                Feed::Eager { window: w as usize }
            }
            (Feed::Eager { .. }, Some(w)) => {
                return Err(scenario.error(format!(
                    "parameter eager_window is {w}: at most {MAX_EAGER_WINDOW} steps"
                )));
            }
            (Feed::JustInTime, Some(_)) => {
                return Err(scenario.error(
                    "parameter eager_window applies only with feed = \"eager\"".to_string(),
                ));
            }
        };
        let flow = choice(
            scenario,
            "flow",
            p.flow.as_deref(),
            Flow::parse,
            "no-surplus, continuous",
        )?;
        scaffold_schedule_flowing(&spec, p.b, protocol, feed, flow)
            .map_err(|e| e.in_file(&scenario.path))
    }
}
