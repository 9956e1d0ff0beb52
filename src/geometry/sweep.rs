//! Continuous collision checking of rolling catoms (SPEC §4.3).
//!
//! # Conservative advancement
//!
//! For a pair of bodies whose points move at most `V₁`, `V₂` per unit `s`
//! (see [`super::rolling`]), the signed distance is `(V₁+V₂)`-Lipschitz in
//! `s`. After measuring `dist(sᵢ)`, every `s ∈ [sᵢ, sᵢ + (dist(sᵢ)+ε)/(V₁+V₂)]`
//! has `dist(s) ≥ −ε`, so stepping by that amount never skips a penetration
//! deeper than ε (no tunnelling). The step shrinks near contact and grows
//! geometrically as bodies separate, so departing from a latched neighbour
//! costs a few dozen queries.

use super::catom::{Gap, catom};
use super::rolling::Roll;
use glam::DVec3;
use parry3d_f64::math::Pose;

/// Distances beyond this are not computed exactly (parry's `prediction`):
/// the pair is then known to be at least this far apart.
const FAR: f64 = 0.25;

/// How long (in `s`) a contact may last after `s = 0` (departure from a
/// latched neighbour) or before `s = 1` (arrival at one) and still count as
/// the latched face-to-face contact rather than sliding contact.
pub const LATCH_WINDOW: f64 = 0.01;

/// Distance queries one pair may spend proving itself clear; a pair that
/// exhausts it is reported as a collision (never a silent pass).
pub const QUERY_BUDGET: usize = 100_000;

/// Once a collision is proven, the rest of the sweep is sampled at this
/// step only to locate the deepest point (then refined by golden section).
const COLLISION_SAMPLING: f64 = 1.0 / 64.0;

/// Samples per half-sweep used to locate contacts on a half that the
/// planar certificate has already proven free of penetration.
const CONTACT_SAMPLES: usize = 128;

/// The path of the other body of a pair.
#[derive(Copy, Clone, Debug)]
pub enum Path {
    /// A module that stays put (at rest, centred here).
    Static(DVec3),
    /// A module rolling in the same step, with the same `s`.
    Rolling(Roll),
}

impl Path {
    fn pose(&self, s: f64) -> Pose {
        match self {
            Path::Static(c) => Pose::from_translation(*c),
            Path::Rolling(r) => r.pose(s),
        }
    }

    fn centre(&self, s: f64) -> DVec3 {
        match self {
            Path::Static(c) => *c,
            Path::Rolling(r) => r.centre(s),
        }
    }

    fn speed(&self) -> f64 {
        match self {
            Path::Static(_) => 0.0,
            Path::Rolling(r) => r.speed_bound(),
        }
    }

    fn support(&self, s: f64, u: DVec3) -> f64 {
        match self {
            Path::Static(c) => u.dot(*c) + catom().support(u),
            Path::Rolling(r) => r.support(s, u),
        }
    }
}

/// A measured point of a sweep.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Sample {
    pub s: f64,
    pub gap: Gap,
}

/// What the sweep of one pair found.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum PairOutcome {
    /// Never within ε, except the latched contact at an end.
    Clear,
    /// Within ±ε away from the latched contacts at the ends: the first
    /// such sample.
    Sliding(Sample),
    /// Deeper than ε: the deepest sample found.
    Collision(Sample),
}

/// The sweep of one pair with its cost.
#[derive(Clone, Debug, PartialEq)]
pub struct PairSweep {
    pub outcome: PairOutcome,
    /// The first sliding-contact sample on each half-sweep (`s < ½`,
    /// `s ≥ ½`), whatever the outcome.
    pub sliding: [Option<Sample>; 2],
    /// Distance queries spent.
    pub queries: usize,
}

fn gap_at(mover: &Roll, other: &Path, s: f64) -> Gap {
    let (a, b) = (mover.pose(s), other.pose(s));
    catom().gap(&a, &b, FAR).unwrap_or(Gap {
        dist: FAR,
        p1: a.translation,
        p2: b.translation,
        normal: (b.translation - a.translation).normalize_or_zero(),
    })
}

/// Running state of one pair's sweep.
struct Scan<'a> {
    mover: &'a Roll,
    other: &'a Path,
    eps: f64,
    queries: usize,
    deepest: Option<Sample>,
    sliding: Option<Sample>,
    halves: [Option<Sample>; 2],
    exhausted: bool,
}

impl Scan<'_> {
    /// Measures the signed distance at `s` (or a cheap lower bound when the
    /// bounding spheres are far apart) and records what it shows.
    fn measure(&mut self, s: f64) -> f64 {
        let centres = (self.mover.centre(s) - self.other.centre(s)).length();
        let lower = centres - 2.0 * catom().radius();
        if lower > FAR {
            return lower;
        }
        let gap = gap_at(self.mover, self.other, s);
        self.queries += 1;
        self.record(Sample { s, gap });
        gap.dist
    }

    fn record(&mut self, x: Sample) {
        let dist = x.gap.dist;
        if dist < -self.eps {
            if self.deepest.is_none_or(|d| dist < d.gap.dist) {
                self.deepest = Some(x);
            }
        } else if dist <= self.eps && x.s > LATCH_WINDOW && x.s < 1.0 - LATCH_WINDOW {
            self.sliding.get_or_insert(x);
            self.halves[usize::from(x.s >= 0.5)].get_or_insert(x);
        }
    }

    /// Conservative advancement over `[a, b]` (see the module docs).
    fn advance(&mut self, a: f64, b: f64) {
        let v = self.mover.speed_bound() + self.other.speed();
        let mut s = a;
        loop {
            let dist = self.measure(s);
            if s >= b {
                break;
            }
            if self.queries >= QUERY_BUDGET {
                self.exhausted = true;
                break;
            }
            if self.deepest.is_none() && dist < -0.5 * self.eps {
                // Advancement converges to a crossing of −ε and would stall
                // there (Zeno): look just ahead for the penetration.
                let mut h = 0.1 * self.eps;
                while h < 1e-2 && self.deepest.is_none() && s + h < b {
                    self.measure(s + h);
                    h *= 8.0;
                }
            }
            let step = if self.deepest.is_some() {
                // A collision is proven; sampling only locates the deepest.
                COLLISION_SAMPLING
            } else {
                (dist + self.eps) / v
            };
            s = (s + step).min(b);
        }
    }

    /// The planar certificate of a half-sweep: if both bodies move in planes
    /// normal to one axis `k` (a static body trivially does), their extents
    /// along `±k` are constant on the half, so the gap along `k`, a lower
    /// bound of the signed distance, is constant too. `Some(gap)` when it
    /// applies.
    fn planar_gap(&self, half: usize) -> Option<f64> {
        let k = self.mover.half_axis(half);
        if let Path::Rolling(r) = self.other
            && r.half_axis(half).cross(k).length() > 1e-12
        {
            return None;
        }
        let s = 0.25 + 0.5 * half as f64;
        let along = |u: DVec3| -self.other.support(s, -u) - self.mover.support(s, u);
        Some(along(k).max(along(-k)))
    }
}

/// Sweeps `mover` against `other` over `s ∈ [0, 1]` with tolerance `eps`.
///
/// Each half-sweep is either proven free of penetration at once by the
/// planar certificate (`Scan::planar_gap`) — then sampled only to find
/// sliding contacts — or swept by conservative advancement. Contacts within
/// [`LATCH_WINDOW`] of either end are the latched contacts of the start and
/// target cells and are not reported.
pub fn sweep_pair(mover: &Roll, other: &Path, eps: f64) -> PairSweep {
    let mut scan = Scan {
        mover,
        other,
        eps,
        queries: 0,
        deepest: None,
        sliding: None,
        halves: [None; 2],
        exhausted: false,
    };
    let same_motion = matches!(other, Path::Rolling(r) if r.link == mover.link);
    if same_motion {
        // Both bodies undergo the same rigid motion from different pivots:
        // one is the other translated, so their distance never changes.
        scan.measure(0.0);
        if scan.deepest.is_none() && scan.sliding.is_none() {
            let gap = gap_at(mover, other, 0.5);
            scan.queries += 1;
            scan.record(Sample { s: 0.5, gap });
        }
    } else {
        for half in 0..2 {
            let (a, b) = (0.5 * half as f64, 0.5 * (half + 1) as f64);
            match scan.planar_gap(half) {
                Some(g) if g >= -eps => {
                    if g <= eps {
                        for i in 0..=CONTACT_SAMPLES {
                            scan.measure(a + (b - a) * i as f64 / CONTACT_SAMPLES as f64);
                        }
                    }
                }
                _ => scan.advance(a, b),
            }
            if scan.exhausted {
                break;
            }
        }
    }
    let mut queries = scan.queries;
    let outcome = match (scan.deepest, scan.sliding) {
        (Some(d), _) => PairOutcome::Collision(refine(mover, other, d, &mut queries)),
        (None, _) if scan.exhausted => {
            // Unresolved within the budget: conservatively a collision.
            let gap = gap_at(mover, other, 0.5);
            PairOutcome::Collision(Sample { s: 0.5, gap })
        }
        (None, Some(x)) => PairOutcome::Sliding(x),
        (None, None) => PairOutcome::Clear,
    };
    PairSweep {
        outcome,
        sliding: scan.halves,
        queries,
    }
}

/// Golden-section search for the deepest point near a penetrating sample.
fn refine(mover: &Roll, other: &Path, d: Sample, queries: &mut usize) -> Sample {
    let h = COLLISION_SAMPLING;
    let (mut lo, mut hi) = ((d.s - h).max(0.0), (d.s + h).min(1.0));
    let mut best = d;
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut ga, mut gb) = (gap_at(mover, other, a), gap_at(mover, other, b));
    *queries += 2;
    for _ in 0..24 {
        for (s, gap) in [(a, ga), (b, gb)] {
            if gap.dist < best.gap.dist {
                best = Sample { s, gap };
            }
        }
        if ga.dist < gb.dist {
            hi = b;
            b = a;
            gb = ga;
            a = hi - g * (hi - lo);
            ga = gap_at(mover, other, a);
        } else {
            lo = a;
            a = b;
            ga = gb;
            b = lo + g * (hi - lo);
            gb = gap_at(mover, other, b);
        }
        *queries += 1;
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::EPSILON;
    use crate::geometry::rolling::links;
    use crate::lattice::{Cell, FccLattice, Lattice};

    /// Exploration: prints, per link, what each cell within reach does.
    #[test]
    #[ignore]
    fn explore_single_obstacles() {
        let l = FccLattice;
        let p = Cell::new(0, 0, 0);
        let pc = l.centre(p);
        let mut cells = Vec::new();
        for x in -3..=3 {
            for y in -3..=3 {
                for z in -3..=3 {
                    let c = Cell::new(x, y, z);
                    let d = (l.centre(c) - pc).length();
                    if c != p && d < 2.2 {
                        cells.push(c);
                    }
                }
            }
        }
        let mut total = 0;
        for link in links() {
            let r = Roll::new(pc, link);
            let from = l.neighbour(p, link.from as usize);
            let to = l.neighbour(p, link.to as usize);
            let mut line = format!("{link}:");
            for &c in &cells {
                if c == from || c == to {
                    continue;
                }
                let sw = sweep_pair(&r, &Path::Static(l.centre(c)), EPSILON);
                total += sw.queries;
                match sw.outcome {
                    PairOutcome::Clear => {
                        if sw.queries > 200 {
                            line += &format!(" [{c} clear q={}]", sw.queries);
                        }
                    }
                    PairOutcome::Sliding(x) => {
                        line += &format!(" [{c} SLIDE s={:.4} q={}]", x.s, sw.queries)
                    }
                    PairOutcome::Collision(x) => {
                        line += &format!(
                            " [{c} X s={:.3} d={:.4} q={}]",
                            x.s, -x.gap.dist, sw.queries
                        )
                    }
                }
            }
            println!("{line}");
        }
        println!("cells {} total queries {total}", cells.len());
    }
}
