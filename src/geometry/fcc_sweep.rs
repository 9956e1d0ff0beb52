//! The FCC [`SweepModel`]: every mover's rolling sweep against the static
//! modules within reach and against the other movers of the step.
//!
//! * Static modules: exactly ([`sweep_pair`] against each occupied cell
//!   within reach) when `exact` is set or ε differs from the default, else
//!   from the compiled [`rule table`](super::rules::table), which holds the
//!   very same pair sweeps for a single obstacle at every offset.
//! * Other movers: always exact, both bodies advancing with the same `s`,
//!   for the pairs whose swept balls overlap.
//! * The pivot is the rolling contact and is skipped. A module in a moving
//!   set that is not a rotating mover (e.g. one leaving through a sink) is
//!   treated as static — conservative.

use super::ground::{GroundContact, floor_contact};
use super::rolling::{Link, Roll};
use super::rules::{offsets_within_reach, table};
use super::sweep::{PairOutcome, Path, Sample, sweep_pair};
use super::{Contact, ContactKind, EPSILON, SweepInput, SweepModel};
use crate::lattice::config::Ground;
use crate::lattice::config::ModuleId;
use crate::lattice::{Cell, Motion};
use glam::DVec3;
use rayon::prelude::*;
use rustc_hash::{FxHashMap, FxHashSet};
use std::sync::OnceLock;

/// The FCC body model.
pub struct FccSweep;

/// Below this many movers a step is checked on one thread.
const PARALLEL_MOVERS: usize = 64;

struct Mover {
    id: ModuleId,
    pivot_id: Option<ModuleId>,
    pivot: Cell,
    /// Start and target cells.
    ends: [Cell; 2],
    roll: Roll,
    /// Swept ball in world coordinates.
    ball: (DVec3, f64),
}

/// Swept balls of the 120 links relative to the pivot.
fn swept_ball(link: Link) -> (DVec3, f64) {
    static BALLS: OnceLock<FxHashMap<Link, (DVec3, f64)>> = OnceLock::new();
    BALLS.get_or_init(|| {
        super::rolling::links()
            .into_iter()
            .map(|l| (l, Roll::new(DVec3::ZERO, l).swept_ball()))
            .collect()
    })[&link]
}

fn contact(kind: ContactKind, x: Sample, mover: ModuleId, other: ModuleId) -> Contact {
    Contact {
        kind,
        s: x.s,
        mover,
        other,
        depth: if kind == ContactKind::Collision {
            (-x.gap.dist).max(0.0)
        } else {
            0.0
        },
        witness_mover: x.gap.p1,
        witness_other: x.gap.p2,
    }
}

fn outcome_contact(o: PairOutcome, mover: ModuleId, other: ModuleId) -> Option<Contact> {
    match o {
        PairOutcome::Clear => None,
        PairOutcome::Sliding(x) => Some(contact(ContactKind::SlidingContact, x, mover, other)),
        PairOutcome::Collision(x) => Some(contact(ContactKind::Collision, x, mover, other)),
    }
}

/// Whether two rotations executed in the same step keep clear of each
/// other (exact sweep where their swept balls overlap; sliding contact
/// counts as not clear). `true` for motions that are not FCC rotations.
pub fn rotations_clear(a: &Motion, b: &Motion) -> bool {
    let l = crate::lattice::FccLattice;
    let (Some(ra), Some(rb)) = (Roll::of_motion(&l, a), Roll::of_motion(&l, b)) else {
        return true;
    };
    let ((ca, rad_a), (cb, rad_b)) = (swept_ball(ra.link), swept_ball(rb.link));
    if (ca + ra.pivot - cb - rb.pivot).length() > rad_a + rad_b {
        return true;
    }
    sweep_pair(&ra, &Path::Rolling(rb), EPSILON).outcome == PairOutcome::Clear
}

impl FccSweep {
    /// Height of the floor under the ground layer: flush with the bottom
    /// face of a catom at rest there (see [`super::ground`]).
    pub fn floor(lattice: &dyn crate::lattice::Lattice, ground: Ground) -> f64 {
        lattice.centre(Cell::new(0, 0, ground.layer)).z - super::catom().support(DVec3::NEG_Z)
    }

    fn statics(
        &self,
        input: &SweepInput<'_>,
        movers: &FxHashSet<ModuleId>,
        m: &Mover,
    ) -> Vec<Contact> {
        let others = |cell: Cell| {
            input
                .config
                .at(cell)
                .filter(|o| *o != m.id && Some(*o) != m.pivot_id && !movers.contains(o))
        };
        let mut out = Vec::new();
        if input.exact || table().tolerance() != input.epsilon {
            for off in offsets_within_reach() {
                let cell = off.from(m.pivot);
                if let Some(o) = others(cell) {
                    let centre = input.lattice.centre(cell);
                    let sw = sweep_pair(&m.roll, &Path::Static(centre), input.epsilon.get());
                    out.extend(outcome_contact(sw.outcome, m.id, o));
                }
            }
        } else {
            let shift = m.roll.pivot;
            for e in &table().get(m.roll.link).entries {
                if let Some(o) = others(e.offset.from(m.pivot)) {
                    out.push(Contact {
                        kind: e.kind,
                        s: e.s,
                        mover: m.id,
                        other: o,
                        depth: e.depth,
                        witness_mover: e.witness_mover + shift,
                        witness_other: e.witness_other + shift,
                    });
                }
            }
        }
        // A flush, zero-depth slide against a neighbour of the start or
        // target cell is that connector pair parting (or meeting): the
        // faces were (or will be) in contact, they only move tangentially,
        // nothing interpenetrates and, the latch being released (a mover
        // holds only its pivot), nothing presses them together. Not a
        // physical concern, so not a warning. Two or more flush contacts
        // of one mover may pinch it from opposite sides at zero clearance
        // (jammed for any real body): then every one stays a warning, as
        // does a flush brush against any other module.
        let slides = out
            .iter()
            .filter(|c| c.kind == ContactKind::SlidingContact)
            .count();
        if slides == 1 {
            out.retain(|c| {
                c.kind != ContactKind::SlidingContact
                    || !m.ends.iter().any(|&e| {
                        input
                            .config
                            .cell_of(c.other)
                            .is_some_and(|q| input.lattice.are_neighbours(q, e))
                    })
            });
        }
        out
    }
}

impl SweepModel for FccSweep {
    fn name(&self) -> &'static str {
        "fcc-catom"
    }

    fn check_ground(&self, input: &SweepInput<'_>, ground: Ground) -> Vec<GroundContact> {
        let floor = Self::floor(input.lattice, ground);
        input
            .moves
            .iter()
            .filter_map(|(id, _, motion)| {
                let roll = Roll::of_motion(input.lattice, motion)?;
                floor_contact(*id, &roll, floor, input.epsilon.get())
            })
            .collect()
    }

    fn check_step(&self, input: &SweepInput<'_>) -> Vec<Contact> {
        let movers: Vec<Mover> = input
            .moves
            .iter()
            .filter_map(|(id, pivot_id, motion)| {
                let roll = Roll::of_motion(input.lattice, motion)?;
                let Motion::Rotate {
                    pivot, from, to, ..
                } = motion
                else {
                    return None;
                };
                let (c, r) = swept_ball(roll.link);
                Some(Mover {
                    id: *id,
                    pivot_id: *pivot_id,
                    pivot: *pivot,
                    ends: [*from, *to],
                    roll,
                    ball: (c + roll.pivot, r),
                })
            })
            .collect();
        let ids: FxHashSet<ModuleId> = movers.iter().map(|m| m.id).collect();

        // Pairs of movers whose swept balls overlap, via a uniform grid.
        let cell_size = 2.0 * movers.iter().map(|m| m.ball.1).fold(0.0, f64::max) + 1e-9;
        let key = |p: DVec3| {
            let q = (p / cell_size).floor();
            (q.x as i64, q.y as i64, q.z as i64)
        };
        let mut grid: FxHashMap<(i64, i64, i64), Vec<usize>> = FxHashMap::default();
        for (i, m) in movers.iter().enumerate() {
            grid.entry(key(m.ball.0)).or_default().push(i);
        }
        let mut pairs = Vec::new();
        for (i, m) in movers.iter().enumerate() {
            let (kx, ky, kz) = key(m.ball.0);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        for &j in grid.get(&(kx + dx, ky + dy, kz + dz)).into_iter().flatten() {
                            let n = &movers[j];
                            if j > i && (m.ball.0 - n.ball.0).length() <= m.ball.1 + n.ball.1 {
                                pairs.push((i, j));
                            }
                        }
                    }
                }
            }
        }

        let pair_check = |&(i, j): &(usize, usize)| {
            let (a, b) = (&movers[i], &movers[j]);
            let sw = sweep_pair(&a.roll, &Path::Rolling(b.roll), input.epsilon.get());
            outcome_contact(sw.outcome, a.id, b.id)
        };
        let mut out: Vec<Contact>;
        if movers.len() >= PARALLEL_MOVERS {
            out = movers
                .par_iter()
                .flat_map_iter(|m| self.statics(input, &ids, m))
                .collect();
            out.extend(pairs.par_iter().filter_map(pair_check).collect::<Vec<_>>());
        } else {
            out = movers
                .iter()
                .flat_map(|m| self.statics(input, &ids, m))
                .collect();
            out.extend(pairs.iter().filter_map(pair_check));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::rolling::links;
    use crate::geometry::sweep::sweep_pair;
    use crate::lattice::{Configuration, FccLattice, Lattice, Route};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A scene: pivot (id 0), mover (id 1) and obstacles (ids 2..).
    struct Scene {
        config: Configuration,
        moves: Vec<(ModuleId, Option<ModuleId>, Motion)>,
        moving: FxHashSet<ModuleId>,
    }

    fn scene(pivot: Cell, link: Link, obstacles: &[Cell]) -> Scene {
        let l = FccLattice;
        let from = l.neighbour(pivot, link.from as usize);
        let to = l.neighbour(pivot, link.to as usize);
        let mut config = Configuration::new();
        config.insert(0, pivot).unwrap();
        config.insert(1, from).unwrap();
        for (i, c) in obstacles.iter().enumerate() {
            config.insert(2 + i as ModuleId, *c).unwrap();
        }
        let motion = Motion::Rotate {
            from,
            to,
            pivot,
            route: link.route,
        };
        Scene {
            config,
            moves: vec![(1, Some(0), motion)],
            moving: [1].into_iter().collect(),
        }
    }

    fn check(s: &Scene, exact: bool) -> Vec<Contact> {
        let input = SweepInput {
            lattice: &FccLattice,
            config: &s.config,
            moves: &s.moves,
            moving: &s.moving,
            epsilon: crate::geometry::Tolerance::DEFAULT,
            exact,
        };
        let mut v = FccSweep.check_step(&input);
        v.sort_by_key(|c| (c.mover, c.other));
        v
    }

    fn kinds(v: &[Contact]) -> Vec<(ModuleId, ModuleId, ContactKind)> {
        v.iter().map(|c| (c.mover, c.other, c.kind)).collect()
    }

    fn link(from: u8, to: u8, route: Route) -> Link {
        Link { from, to, route }
    }

    #[test]
    fn rolling_on_the_pivot_alone_is_not_a_contact() {
        for l in links() {
            let s = scene(Cell::new(0, 0, 1), l, &[]);
            assert!(check(&s, true).is_empty(), "{l}");
            assert!(check(&s, false).is_empty(), "{l}");
        }
    }

    #[test]
    fn a_module_in_the_corner_cell_is_penetrated_with_depth_and_witnesses() {
        // +x → +y around the pivot via the cubic axis (x+y)/√2: the cell
        // (1,1,0) is cut through.
        let s = scene(
            Cell::new(0, 0, 0),
            link(0, 1, Route::Octagonal),
            &[Cell::new(1, 1, 0)],
        );
        for exact in [true, false] {
            let c = check(&s, exact);
            assert_eq!(kinds(&c), vec![(1, 2, ContactKind::Collision)]);
            let c = &c[0];
            assert!((c.depth - 0.6197).abs() < 1e-3, "{}", c.depth);
            assert!((c.s - 0.572).abs() < 5e-3, "{}", c.s);
            // Witnesses: the deepest points of each body inside the other,
            // as far apart as the depth.
            assert!(((c.witness_mover - c.witness_other).length() - c.depth).abs() < 1e-6);
        }
    }

    #[test]
    fn a_lone_flush_slide_off_a_neighbour_of_the_start_is_no_warning() {
        // +x → up-(½,½) by the hexagonal route: the mover's connector face
        // slides flush along the module at (1,1,0), a neighbour of its
        // start cell, at zero depth: the connector pair parting.
        let (pivot, lk, other) = (
            Cell::new(0, 0, 0),
            link(0, 4, Route::Hexagonal),
            Cell::new(1, 1, 0),
        );
        let l = FccLattice;
        let from = l.neighbour(pivot, 0);
        let to = l.neighbour(pivot, 4);
        assert!(l.are_neighbours(other, from) || l.are_neighbours(other, to));
        let s = scene(pivot, lk, &[other]);
        for exact in [true, false] {
            assert!(check(&s, exact).is_empty(), "exact = {exact}");
        }
        // The raw sweep does find the flush contact (zero depth).
        let roll = Roll::of_motion(&l, &s.moves[0].2).unwrap();
        let sw = sweep_pair(&roll, &Path::Static(l.centre(other)), EPSILON);
        assert!(
            matches!(sw.outcome, PairOutcome::Sliding(_)),
            "{:?}",
            sw.outcome
        );
    }

    /// Flush contacts that may pinch the mover stay warnings: every link,
    /// every pair of obstacles that each slide alone.
    #[test]
    fn two_flush_slides_on_one_mover_stay_warnings() {
        let l = FccLattice;
        let pivot = Cell::new(0, 0, 0);
        let mut seen = 0;
        for lk in links() {
            let from = l.neighbour(pivot, lk.from as usize);
            let to = l.neighbour(pivot, lk.to as usize);
            let slides: Vec<Cell> = offsets_within_reach()
                .iter()
                .map(|o| o.from(pivot))
                .filter(|&c| c != pivot && c != from && c != to)
                .filter(|&c| {
                    let roll = Roll::of_motion(
                        &l,
                        &Motion::Rotate {
                            from,
                            to,
                            pivot,
                            route: lk.route,
                        },
                    )
                    .unwrap();
                    matches!(
                        sweep_pair(&roll, &Path::Static(l.centre(c)), EPSILON).outcome,
                        PairOutcome::Sliding(_)
                    )
                })
                .collect();
            if slides.len() >= 2 {
                let s = scene(pivot, lk, &slides[..2]);
                let c = check(&s, true);
                assert_eq!(
                    c.iter()
                        .filter(|c| c.kind == ContactKind::SlidingContact)
                        .count(),
                    2,
                    "{lk}"
                );
                seen += 1;
            }
        }
        assert!(seen > 0, "some link has two flush contacts");
    }

    /// The compiled table agrees with the exact sweep for every link and
    /// every single obstacle within reach, on a pivot in an odd layer (the
    /// table was derived on an even one).
    #[test]
    fn compiled_table_agrees_with_exact_sweeps_for_every_single_obstacle() {
        let l = FccLattice;
        let pivot = Cell::new(3, -2, 1);
        let all: Vec<(Link, Cell)> = links()
            .into_iter()
            .flat_map(|k| {
                let (from, to) = (
                    l.neighbour(pivot, k.from as usize),
                    l.neighbour(pivot, k.to as usize),
                );
                offsets_within_reach()
                    .iter()
                    .map(move |o| (k, o.from(pivot)))
                    .filter(move |(_, c)| *c != from && *c != to)
            })
            .collect();
        assert_eq!(all.len(), 120 * 52);
        let disagreements: Vec<String> = all
            .par_iter()
            .filter_map(|&(k, c)| {
                let s = scene(pivot, k, &[c]);
                let (e, t) = (check(&s, true), check(&s, false));
                (kinds(&e) != kinds(&t)).then(|| format!("{k} obstacle {c}: {e:?} vs {t:?}"))
            })
            .collect();
        assert!(disagreements.is_empty(), "{disagreements:#?}");
    }

    fn random_neighbourhoods(n: usize, seed: u64) -> usize {
        let l = FccLattice;
        let all = links();
        let found: Vec<usize> = (0..n)
            .into_par_iter()
            .map(|i| {
                let mut rng = ChaCha8Rng::seed_from_u64(seed + i as u64);
                let pivot = Cell::new(
                    rng.random_range(-5..5),
                    rng.random_range(-5..5),
                    rng.random_range(-5..5),
                );
                let k = all[rng.random_range(0..all.len())];
                let (from, to) = (
                    l.neighbour(pivot, k.from as usize),
                    l.neighbour(pivot, k.to as usize),
                );
                let density = rng.random_range(0.2..0.8);
                let obstacles: Vec<Cell> = offsets_within_reach()
                    .iter()
                    .map(|o| o.from(pivot))
                    .filter(|c| *c != from && *c != to && rng.random_bool(density))
                    .collect();
                let s = scene(pivot, k, &obstacles);
                let (e, t) = (check(&s, true), check(&s, false));
                assert_eq!(kinds(&e), kinds(&t), "{k} at {pivot} with {obstacles:?}");
                e.len()
            })
            .collect();
        found.iter().sum()
    }

    #[test]
    fn compiled_table_agrees_with_exact_sweeps_in_random_dense_neighbourhoods() {
        let contacts = random_neighbourhoods(1500, 7);
        assert!(
            contacts > 1500,
            "the neighbourhoods must exercise contacts: {contacts}"
        );
    }

    #[test]
    #[ignore = "large sample: cargo test --release -- --ignored"]
    fn compiled_table_agrees_with_exact_sweeps_in_many_random_neighbourhoods() {
        random_neighbourhoods(50_000, 1_000_000);
    }

    #[test]
    fn two_movers_swapping_around_one_pivot_collide() {
        let l = FccLattice;
        let p = Cell::new(0, 0, 0);
        let (a, b) = (l.neighbour(p, 0), l.neighbour(p, 1));
        let mut config = Configuration::new();
        config.insert(0, p).unwrap();
        config.insert(1, a).unwrap();
        config.insert(2, b).unwrap();
        let moves = vec![
            (
                1,
                Some(0),
                Motion::Rotate {
                    from: a,
                    to: b,
                    pivot: p,
                    route: Route::Octagonal,
                },
            ),
            (
                2,
                Some(0),
                Motion::Rotate {
                    from: b,
                    to: a,
                    pivot: p,
                    route: Route::Octagonal,
                },
            ),
        ];
        let moving = [1, 2].into_iter().collect();
        for exact in [true, false] {
            let input = SweepInput {
                lattice: &l,
                config: &config,
                moves: &moves,
                moving: &moving,
                epsilon: crate::geometry::Tolerance::DEFAULT,
                exact,
            };
            let c = FccSweep.check_step(&input);
            assert_eq!(kinds(&c), vec![(1, 2, ContactKind::Collision)]);
            assert!(c[0].depth > 0.5, "head-on: {}", c[0].depth);
        }
    }

    #[test]
    fn latched_movers_rolling_in_step_stay_in_contact() {
        // Two latched neighbours rolling the same link on two latched pivots
        // keep their relative pose: a contact throughout, never a collision.
        let l = FccLattice;
        let (p, q) = (Cell::new(0, 0, 0), Cell::new(0, 1, 0));
        let k = link(0, 4, Route::Hexagonal);
        let mut config = Configuration::new();
        let mut moves = Vec::new();
        for (i, pv) in [p, q].into_iter().enumerate() {
            let (from, to) = (l.neighbour(pv, 0), l.neighbour(pv, 4));
            config.insert(10 + i as ModuleId, pv).unwrap();
            config.insert(i as ModuleId, from).unwrap();
            moves.push((
                i as ModuleId,
                Some(10 + i as ModuleId),
                Motion::Rotate {
                    from,
                    to,
                    pivot: pv,
                    route: k.route,
                },
            ));
        }
        let moving = [0, 1].into_iter().collect();
        let input = SweepInput {
            lattice: &l,
            config: &config,
            moves: &moves,
            moving: &moving,
            epsilon: crate::geometry::Tolerance::DEFAULT,
            exact: true,
        };
        let c = FccSweep.check_step(&input);
        assert!(
            c.iter().all(|c| c.kind == ContactKind::SlidingContact),
            "{c:?}"
        );
        assert!(c.iter().any(|c| (c.mover, c.other) == (0, 1)), "{c:?}");
    }

    /// A penetration of 2ε lasting a sliver of the sweep, straddled by the
    /// points of a 256-sample grid, is still found: advancement does not
    /// tunnel between samples.
    #[test]
    fn brief_shallow_penetrations_are_not_tunnelled() {
        use crate::geometry::catom::catom;
        let r = Roll::new(DVec3::ZERO, link(0, 1, Route::Octagonal));
        let u = r.normal(0.37);
        // The mover's extent along u peaks near s = 0.37; find the peak.
        let (mut lo, mut hi) = (0.3, 0.45);
        for _ in 0..100 {
            let (a, b) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
            if r.support(a, u) < r.support(b, u) {
                lo = a
            } else {
                hi = b
            }
        }
        let s0 = 0.5 * (lo + hi);
        // An obstacle beyond the mover along u, touching it at the mover's
        // support point (normals match: both bodies are rounded) and pushed
        // in by 2ε.
        let q = r.rotation(s0);
        let tip = r.centre(s0) + q * catom().support_point(q.inverse() * u);
        let centre = tip - catom().support_point(-u) - 2.0 * EPSILON * u;
        let other = Path::Static(centre);
        let at = parry3d_f64::math::Pose::from_translation(centre);
        let grid_min = (-128..128)
            .map(|i| {
                let s = s0 + (i as f64 + 0.5) / 256.0;
                catom().gap(&r.pose(s), &at, 1.0).map_or(1.0, |g| g.dist)
            })
            .fold(f64::INFINITY, f64::min);
        assert!(
            grid_min > -EPSILON,
            "the grid alone would see it: {grid_min}"
        );
        let d0 = catom().gap(&r.pose(s0), &at, 1.0).unwrap().dist;
        assert!(
            (d0 + 2.0 * EPSILON).abs() < 1e-9,
            "constructed depth {d0:e}"
        );
        let sw = sweep_pair(&r, &other, EPSILON);
        match sw.outcome {
            PairOutcome::Collision(x) => {
                assert!((x.s - s0).abs() < 1e-3, "{} vs {s0}", x.s);
                assert!(
                    -x.gap.dist > EPSILON && -x.gap.dist < 2.5 * EPSILON,
                    "{}",
                    x.gap.dist
                );
            }
            o => panic!("missed: {o:?}"),
        }
    }
}
