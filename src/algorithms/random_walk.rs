//! Synthetic workload: catoms rolling at random over a fixed FCC platform.
//!
//! Used by property tests (random valid walks must certify clean) and by
//! the benchmarks (large schedules of many concurrent movers). Walkers stay
//! in layer 1, rolling over the platform modules of layer 0, so every
//! walker is held by a fixed pivot and the static structure stays anchored.

use super::{Generator, parameters};
use crate::error::InputError;
use crate::lattice::config::{Configuration, Ground, ModuleId};
use crate::lattice::{Cell, FccLattice, Lattice, LatticeKind, Motion, Route, fcc};
use crate::scenario::Scenario;
use crate::schedule::{Event, Length, ModuleSpec, Schedule, Step};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rustc_hash::FxHashSet;
use serde::Deserialize;

/// Parameters of a random walk.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WalkParams {
    /// Platform size in cells along x and y.
    pub width: i32,
    pub depth: i32,
    /// Number of walking catoms.
    pub walkers: usize,
    pub steps: usize,
    /// Probability that a walker tries to move in a step.
    #[serde(default = "default_activity")]
    pub activity: f64,
    #[serde(default)]
    pub seed: u64,
    /// Keep only moves the body geometry allows (no collision, no sliding
    /// contact): the default. `false` takes every lattice-valid move.
    #[serde(default = "default_geometric")]
    pub geometric: bool,
}

fn default_geometric() -> bool {
    true
}

/// The geometric move filter: a candidate rotation is taken when none of
/// the cells its sweep penetrates or touches (derived motion rules,
/// [`crate::geometry::MotionRules::touched_cells`]) is occupied at the start of the step or
/// claimed as a target by a move already chosen, and when its sweep keeps
/// clear of every chosen move's sweep ([`crate::geometry::MotionRules::concurrent_clear`]).
/// Walks generated with it certify without collisions or sliding contacts.
pub fn collision_free(config: &Configuration, m: &Motion, chosen: &[Motion]) -> bool {
    let rules = crate::geometry::motion_rules(LatticeKind::Fcc)
        .expect("the FCC lattice has motion rules derived from the catom body");
    let claimed = |c: Cell| chosen.iter().any(|x| x.to() == c);
    rules
        .touched_cells(m)
        .into_iter()
        .all(|c| config.is_free(c) && !claimed(c))
        && chosen.iter().all(|x| rules.concurrent_clear(m, x))
}

fn default_activity() -> f64 {
    0.5
}

/// Decides whether a candidate move may be taken, given the configuration
/// at the start of the step and the moves already chosen for it. The
/// default accepts every lattice-valid move; callers plug in geometric
/// motion rules.
pub type MoveFilter<'a> = dyn Fn(&Configuration, &Motion, &[Motion]) -> bool + 'a;

/// A random rolling move for the walker at `from`: one of its
/// down-neighbours (connectors 8..12) that `is_pivot` accepts, and that
/// pivot's up-neighbours (connectors 4..8) that are free, not `from`, and
/// neither claimed nor being vacated in this step — both drawn in random
/// order. Shared by the walker workloads so that they draw alike.
pub fn random_pivot_and_targets(
    config: &Configuration,
    from: Cell,
    is_pivot: impl Fn(Cell) -> bool,
    claimed: &FxHashSet<Cell>,
    leaving: &FxHashSet<Cell>,
    rng: &mut ChaCha8Rng,
) -> Option<(Cell, Vec<Cell>)> {
    let l = FccLattice;
    let mut pivots: Vec<Cell> = (8..12)
        .map(|k| l.neighbour(from, k))
        .filter(|&c| is_pivot(c))
        .collect();
    pivots.shuffle(rng);
    let &pivot = pivots.first()?;
    let mut targets: Vec<Cell> = (4..8)
        .map(|k| l.neighbour(pivot, k))
        .filter(|&t| {
            t != from && config.is_free(t) && !claimed.contains(&t) && !leaving.contains(&t)
        })
        .collect();
    targets.shuffle(rng);
    Some((pivot, targets))
}

/// Largest platform side (cells) and number of steps a scenario may ask
/// for: a synthetic workload far larger than any seed's.
pub const MAX_SIDE: i32 = 1024;
pub const MAX_STEPS: usize = 1_000_000;

/// The random-walk generator.
pub struct RandomWalk;

impl Generator for RandomWalk {
    fn name(&self) -> &'static str {
        "random-walk"
    }

    fn about(&self) -> &'static str {
        "catoms rolling at random over a fixed platform (synthetic workload)"
    }

    fn generate(&self, scenario: &Scenario) -> Result<Schedule, InputError> {
        let p: WalkParams = parameters(scenario)?;
        if p.width < 2 || p.depth < 2 || p.width > MAX_SIDE || p.depth > MAX_SIDE {
            return Err(scenario.error(format!(
                "random-walk needs a platform of 2 × 2 to {MAX_SIDE} × {MAX_SIDE} cells, got {} × {}",
                p.width, p.depth
            )));
        }
        if p.steps > MAX_STEPS {
            return Err(scenario.error(format!(
                "random-walk makes at most {MAX_STEPS} steps, got {}",
                p.steps
            )));
        }
        if !(0.0..=1.0).contains(&p.activity) {
            return Err(scenario.error(format!(
                "activity is a probability in [0, 1], got {}",
                p.activity
            )));
        }
        if p.walkers > ((p.width - 1) * (p.depth - 1)) as usize {
            return Err(scenario.error(format!(
                "{} walkers do not fit on a {} × {} platform",
                p.walkers, p.width, p.depth
            )));
        }
        if p.geometric {
            Ok(walk(&p, &collision_free))
        } else {
            Ok(walk(&p, &|_, _, _| true))
        }
    }
}

/// Generates a random walk whose moves all pass `filter`.
pub fn walk(p: &WalkParams, filter: &MoveFilter<'_>) -> Schedule {
    let l = FccLattice;
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
    let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(3.6));
    s.ground = Some(Ground { layer: 0 });
    s.meta.insert("algorithm".into(), "random-walk".into());
    s.meta.insert("seed".into(), p.seed.into());
    let mut config = Configuration::new();
    let mut id: ModuleId = 0;
    for x in 0..p.width {
        for y in 0..p.depth {
            let c = Cell::new(x, y, 0);
            s.modules.push(ModuleSpec {
                id,
                cell: c,
                fixed: true,
            });
            config.insert(id, c).expect("distinct cells");
            id += 1;
        }
    }
    let platform: FxHashSet<Cell> = config.iter().map(|(_, c)| c).collect();
    // Layer-1 cells resting on four platform modules.
    let mut spots: Vec<Cell> = (0..p.width - 1)
        .flat_map(|x| (0..p.depth - 1).map(move |y| Cell::new(x, y, 1)))
        .collect();
    spots.shuffle(&mut rng);
    let mut walkers = Vec::new();
    for &c in spots.iter().take(p.walkers) {
        s.modules.push(ModuleSpec {
            id,
            cell: c,
            fixed: false,
        });
        config.insert(id, c).expect("distinct cells");
        walkers.push(id);
        id += 1;
    }

    for _ in 0..p.steps {
        walkers.shuffle(&mut rng);
        let mut chosen: Vec<Motion> = Vec::new();
        let mut events = Vec::new();
        let mut claimed: FxHashSet<Cell> = FxHashSet::default();
        let mut leaving: FxHashSet<Cell> = FxHashSet::default();
        for &w in &walkers {
            if !rng.random_bool(p.activity) {
                continue;
            }
            let from = config.cell_of(w).expect("walkers stay in the scene");
            let Some((pivot, targets)) = random_pivot_and_targets(
                &config,
                from,
                |c| platform.contains(&c),
                &claimed,
                &leaving,
                &mut rng,
            ) else {
                continue;
            };
            for to in targets {
                let n_f = (l.centre(from) - l.centre(pivot)).normalize();
                let n_t = (l.centre(to) - l.centre(pivot)).normalize();
                let routes: &[Route] = if fcc::rotation_axis(n_f, n_t, Route::Hexagonal).is_some() {
                    &[Route::Octagonal, Route::Hexagonal]
                } else {
                    &[Route::Octagonal]
                };
                let route = routes[rng.random_range(0..routes.len())];
                let m = Motion::Rotate {
                    from,
                    to,
                    pivot,
                    route,
                };
                if !filter(&config, &m, &chosen) {
                    continue;
                }
                let pivot_id = config.at(pivot).expect("platform pivot");
                events.push(Event::Rotate {
                    module: w,
                    pivot: pivot_id,
                    from,
                    to,
                    route,
                });
                claimed.insert(to);
                leaving.insert(from);
                chosen.push(m);
                break;
            }
        }
        for e in &events {
            if let Event::Rotate { module, to, .. } = e {
                config.remove(*module);
                config
                    .insert(*module, *to)
                    .expect("claimed targets are distinct");
            }
        }
        events.sort_by_key(Event::module);
        s.steps.push(Step { events });
    }
    s
}
