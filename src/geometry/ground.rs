//! The ground as a flat floor under the FCC catoms: how far a rolling
//! mover reaches below its pivot, and which moves of a step dig into the
//! floor.
//!
//! The floor is the plane tangent to the bottom of the ground layer's
//! catoms at rest: `z = z(ground layer) − h_B(−ẑ)` with `h_B(−ẑ) = ½ d`
//! (the catom's square face). A module at rest in the ground layer sits
//! flush on it; the floor is what the RePoSt operations roll over.
//!
//! The lowest point of the mover at `s` is `−h(s, −ẑ)`, with `h` the
//! mover's support function (`Roll::support`). It is `V`-Lipschitz in
//! `s` (`V` = `Roll::speed_bound`: every point of the inner polyhedron
//! moves at most `V·Δs`, and the rounding adds a constant), so its minimum
//! over the sweep is bracketed by Piyavskii's branch and bound: an interval
//! `[a, b]` holds nothing below `(f(a) + f(b) − V·(b − a))/2`. The bracket
//! is closed to [`BRACKET`] and the *lower* end is what the check uses, so
//! a reported clearance is never larger than the true one.
//!
//! The minimum depends only on the link (relative to the pivot's centre),
//! so the 120 links are bracketed once, on first use, and a step's check is
//! one comparison per rotating mover.
//!
//! A flush floor contact (|gap| ≤ ε) is not reported: it is the rest
//! contact of every ground-layer module, which rolls flush along the floor
//! about a pivot in its own layer (those halves turn about a vertical axis,
//! so the mover's extent along `z` is constant there).

use super::rolling::{Link, Roll, links};
use crate::lattice::config::ModuleId;
use glam::DVec3;
use rustc_hash::FxHashMap;
use serde::Serialize;
use std::collections::BinaryHeap;
use std::sync::OnceLock;

/// Width of the bracket kept for each link's lowest point, in units of d:
/// a tenth of the default ε. A move whose depth falls within the bracket
/// of ε is bracketed again, more finely, before it is decided.
pub const BRACKET: f64 = 1e-7;

/// The finest bracket a decision goes down to; a depth still undecided
/// there is reported as a collision (the conservative side).
pub const FINEST_BRACKET: f64 = 1e-13;

/// The lowest point a link's mover reaches, relative to its pivot's centre.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct LowestPoint {
    /// A lower bound on `min_s −h(s, −ẑ)` (height relative to the pivot's
    /// centre, units of d), within [`BRACKET`] of the minimum.
    pub z_bound: f64,
    /// The lowest height actually reached, at [`LowestPoint::s`].
    pub z: f64,
    /// The sweep parameter of `z`.
    pub s: f64,
    /// The mover's lowest point at `s`, relative to the pivot's centre.
    pub witness: DVec3,
}

/// A mover that digs into the floor during a step.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GroundContact {
    pub mover: ModuleId,
    /// Sweep parameter of the deepest point.
    pub s: f64,
    /// Penetration depth below the floor, units of d (an upper bound, within
    /// [`BRACKET`] of the exact depth).
    pub depth: f64,
    /// The mover's lowest point at `s`, world frame.
    pub witness: DVec3,
    /// Height of the floor, world frame.
    pub floor: f64,
}

/// Height of the mover's lowest point at `s`.
fn lowest(roll: &Roll, s: f64) -> f64 {
    -roll.support(s, DVec3::NEG_Z)
}

/// Interval `[a, b]` of Piyavskii's branch and bound, ordered so that the
/// heap pops the smallest lower bound first.
struct Interval {
    bound: f64,
    a: (f64, f64),
    b: (f64, f64),
}

impl PartialEq for Interval {
    fn eq(&self, o: &Self) -> bool {
        self.bound.total_cmp(&o.bound).is_eq()
    }
}
impl Eq for Interval {}
impl PartialOrd for Interval {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Interval {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        o.bound.total_cmp(&self.bound)
    }
}

/// Most evaluations spent on one link; the bracket found by then is still
/// a valid lower bound (only looser), so the cap never makes the check
/// unsound. No link comes near it.
const MAX_EVALUATIONS: usize = 1 << 20;

/// Brackets the minimum over `s ∈ [0, 1]` of the lowest point of `roll`
/// to within `bracket`.
///
/// A half that turns about a vertical axis keeps the mover's extent along
/// `z` constant (see `Roll::half_axis`), so its value at either end is
/// its minimum; bracketing it by Lipschitz bounds would never close. The
/// other halves go through the branch and bound.
pub fn lowest_point(roll: &Roll, bracket: f64) -> LowestPoint {
    let v = roll.speed_bound();
    let interval = |a: (f64, f64), b: (f64, f64)| Interval {
        bound: 0.5 * (a.1 + b.1 - v * (b.0 - a.0)),
        a,
        b,
    };
    // The two halves join at s = ½ with a kink; start from both.
    let knots = [0.0, 0.5, 1.0].map(|s| (s, lowest(roll, s)));
    let mut best = knots
        .iter()
        .copied()
        .min_by(|x, y| x.1.total_cmp(&y.1))
        .expect("three knots");
    let mut heap: BinaryHeap<Interval> = (0..2)
        .filter(|&half| roll.half_axis(half).z.abs() < 1.0 - 1e-12)
        .map(|half| interval(knots[half], knots[half + 1]))
        .collect();
    let mut evaluations = 0;
    let z_bound = loop {
        let Some(top) = heap.pop() else {
            break best.1;
        };
        if best.1 - top.bound <= bracket || evaluations >= MAX_EVALUATIONS {
            break top.bound.min(best.1);
        }
        let m = 0.5 * (top.a.0 + top.b.0);
        let mid = (m, lowest(roll, m));
        evaluations += 1;
        if mid.1 < best.1 {
            best = mid;
        }
        heap.push(interval(top.a, mid));
        heap.push(interval(mid, top.b));
    };
    let q = roll.rotation(best.0);
    let local = super::catom::catom().support_point(q.inverse() * DVec3::NEG_Z);
    LowestPoint {
        z_bound,
        z: best.1,
        s: best.0,
        witness: roll.centre(best.0) + q * local - roll.pivot,
    }
}

/// The lowest point of every link, bracketed once.
pub fn lowest_point_of(link: Link) -> LowestPoint {
    static TABLE: OnceLock<FxHashMap<Link, LowestPoint>> = OnceLock::new();
    TABLE.get_or_init(|| {
        links()
            .into_iter()
            .map(|l| (l, lowest_point(&Roll::new(DVec3::ZERO, l), BRACKET)))
            .collect()
    })[&link]
}

/// The contact of a roll with the floor at height `floor`, if the roll digs
/// deeper than `eps` into it. A depth within the bracket of `eps` is
/// bracketed again, ten times finer each time, until it is decided.
pub fn floor_contact(mover: ModuleId, roll: &Roll, floor: f64, eps: f64) -> Option<GroundContact> {
    let mut low = lowest_point_of(roll.link);
    let mut bracket = BRACKET;
    // Depth below the floor: at most `deep`, at least `reached`.
    let depths = |low: &LowestPoint| {
        let base = floor - roll.pivot.z;
        (base - low.z_bound, base - low.z)
    };
    let (mut deep, mut reached) = depths(&low);
    while deep > eps && reached <= eps && bracket > FINEST_BRACKET {
        bracket /= 10.0;
        low = lowest_point(&Roll::new(DVec3::ZERO, roll.link), bracket);
        (deep, reached) = depths(&low);
    }
    // A NaN height reads as a collision, never as a clearance.
    let clear = deep.partial_cmp(&eps).is_some_and(|o| o.is_le());
    (!clear).then(|| GroundContact {
        mover,
        s: low.s,
        depth: deep,
        witness: roll.pivot + low.witness,
        floor,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::fcc;

    /// Brute-force minimum over a fine grid, with the grid's Lipschitz
    /// slack: an independent bracket of the same minimum.
    fn sampled(roll: &Roll, n: usize) -> (f64, f64) {
        let z = (0..=n)
            .map(|i| lowest(roll, i as f64 / n as f64))
            .fold(f64::INFINITY, f64::min);
        (z - roll.speed_bound() / (2.0 * n as f64), z)
    }

    #[test]
    fn the_bracket_agrees_with_a_fine_grid_on_every_link() {
        for (i, l) in links().into_iter().enumerate() {
            let roll = Roll::new(DVec3::ZERO, l);
            let low = lowest_point_of(l);
            let (lo, hi) = sampled(&roll, 4_000);
            assert!(
                low.z_bound <= low.z && low.z - low.z_bound <= BRACKET,
                "{l}"
            );
            if i % 10 == 0 {
                // A finer bracket lies within the kept one.
                let fine = lowest_point(&roll, 1e-10);
                assert!(fine.z_bound >= low.z_bound - 1e-15, "{l}");
                assert!(fine.z <= low.z + 1e-15, "{l}");
            }
            // The grid's best value is reached, so the true minimum is at
            // most `hi`; the bracket's lower end may not exceed it.
            assert!(low.z_bound <= hi + 1e-15, "{l}: {} > {hi}", low.z_bound);
            // Nor may the grid find a value below the reached minimum by
            // more than its own slack.
            assert!(low.z >= lo - 1e-15, "{l}: {} < {lo}", low.z);
            // The witness is a point of the body at the lowest height.
            assert!((low.witness.z - low.z).abs() < 1e-12, "{l}");
        }
    }

    #[test]
    fn a_catom_at_rest_is_flush_with_a_floor_half_a_spacing_below_its_centre() {
        for l in links() {
            let roll = Roll::new(DVec3::ZERO, l);
            let from = fcc::direction(l.from as usize);
            assert!((lowest(&roll, 0.0) - (from.z - 0.5)).abs() < 1e-12, "{l}");
        }
    }

    #[test]
    fn rolls_about_a_ground_layer_pivot_stay_on_the_floor_and_one_layer_up_dig_in() {
        // Pivot in the ground layer (centre at z = 0, floor at −½): links
        // between cells at or above the ground never go below the floor.
        // Pivot one layer up (centre at 1/√2): 36 links dip, up to 0.3306 d.
        let up = 1.0 / std::f64::consts::SQRT_2;
        let (mut in_ground, mut dipping, mut deepest) = (0, 0, 0.0_f64);
        for l in links() {
            let (f, t) = (
                fcc::direction(l.from as usize),
                fcc::direction(l.to as usize),
            );
            let low = lowest_point_of(l);
            if f.z >= 0.0 && t.z >= 0.0 {
                in_ground += 1;
                assert!(low.z_bound >= -0.5 - BRACKET, "{l}: {}", low.z_bound);
                let on_ground = Roll::new(DVec3::ZERO, l);
                assert_eq!(floor_contact(1, &on_ground, -0.5, 1e-6), None, "{l}");
            }
            if f.z + up >= -1e-9 && t.z + up >= -1e-9 {
                let pivot = DVec3::new(0.0, 0.0, up);
                let c = floor_contact(1, &Roll::new(pivot, l), -0.5, 1e-6);
                if let Some(c) = c {
                    dipping += 1;
                    deepest = deepest.max(c.depth);
                    assert!(c.witness.z < -0.5 && (c.witness.z + 0.5 + c.depth).abs() <= BRACKET);
                }
            }
        }
        assert_eq!(in_ground, 60);
        assert_eq!(dipping, 36);
        assert!((deepest - 0.3306).abs() < 1e-4, "{deepest}");
    }

    #[test]
    fn a_nan_floor_is_a_contact_not_a_clearance() {
        let l = links()[0];
        let c = floor_contact(7, &Roll::new(DVec3::ZERO, l), f64::NAN, 1e-6);
        assert!(c.is_some());
    }

    #[test]
    fn a_depth_within_the_bracket_of_epsilon_is_decided_by_a_finer_bracket() {
        // The deepest dip of a roll about a pivot one layer up, its floor
        // placed 3e-8 d either side of "exactly ε deep": inside the kept
        // bracket (1e-7), so only the finer bracket can tell.
        let eps = 1e-6;
        let link = links()
            .into_iter()
            .min_by(|a, b| lowest_point_of(*a).z.total_cmp(&lowest_point_of(*b).z))
            .expect("120 links");
        let roll = Roll::new(DVec3::ZERO, link);
        let low = lowest_point(&roll, 1e-11);
        let exactly_eps = low.z + eps;
        assert!(floor_contact(1, &roll, exactly_eps - 3e-8, eps).is_none());
        let c = floor_contact(1, &roll, exactly_eps + 3e-8, eps).expect("a contact");
        // The reported depth is the bracket's deep end.
        assert!(
            c.depth > eps && c.depth <= eps + 3e-8 + BRACKET,
            "{}",
            c.depth
        );
    }
}
