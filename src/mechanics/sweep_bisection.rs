//! The smallest load factor over one sweep's poses by bisection: branch and
//! bound on the movers' paths, instead of a limit analysis at every pose.
//!
//! The poses of a step are `n` samples of the movers' paths and, between
//! each two, the poses [`Structure::between`] lists: for each group of
//! movers turning together, sample `i`, sample `i + 1` or the tangent point
//! where its paths' tangents at the two meet, in every combination but the
//! two samples themselves (`3^G − 2` per interval for `G` groups; with one
//! group, the tangent pose alone). The joint path lies in their convex
//! hull, and the analyser wants the smallest load factor `λ` over them.
//! The loads are affine in the movers' centres and the loads a component
//! carries within capacity form a convex set holding zero, so `1/λ` (that
//! set's gauge) is convex in the centres: anywhere in the convex hull of
//! some poses, `λ` is at least the smallest of theirs.
//!
//! For a run of samples `i … j`, each group's points (its samples and
//! tangent points in the run) lie in the triangle of samples `i` and `j`
//! and the *apex* where the tangents of the run's first and last edges meet
//! (checked numerically, one set of weights for every mover of the group).
//! So every pose of the run lies in the product of the groups' triangles,
//! the hull of its `3^G` corners (each group at sample `i`, sample `j` or
//! its apex). A pose is a mean of corners: with one group, its weights in
//! the triangle; with several, the groups' comonotone coupling
//! ([`coupling`]), which weighs only corners the groups reach together.
//! Since `1/λ` is convex, `1/λ(pose) ≤ Σ weight·(1/λ_corner)`: a bound
//! at least the corners' smallest, and close to the pose's own factor
//! where the corners far from it weigh little. Where the run's poses'
//! bounds are no smaller than the smallest factor found at a pose, the
//! run need not be solved; otherwise it is halved at its middle sample,
//! and a short run is solved pose by pose. The result is the smallest
//! factor over every pose, as when each is solved, from fewer limit
//! analyses where `λ` varies smoothly along the sweep (a corner that is
//! no pose is solved too, but only bounds; a corner no pose weighs is
//! not solved).

use super::limit::{fails, lowest};
use super::structure::{Point, Structure};
use glam::DVec3;

/// How far (units of `d`) a point may lie outside its run's triangle, or
/// off the weights its group shares, and still count as inside: the
/// round-off of the tangent points and of the apex.
const INSIDE_TOLERANCE: f64 = 1e-12;

/// What one limit analysis is asked for: a pose of the structure (sample
/// `k < n`, or pose `n + v` between samples, as [`Structure::mover_point`]
/// numbers them), or the movers' centres at a corner of a run's hull that
/// is no pose, one per mover.
#[derive(Clone, Debug, PartialEq)]
pub enum Corner {
    Pose(usize),
    Centres(Vec<DVec3>),
}

/// The bisection's result.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// The smallest factor over the wanted poses (NaN: a solve failed):
    /// the smallest solved, or a passed-over run's bound where lower (see
    /// [`PRUNE_SLACK`]).
    pub smallest: f64,
    /// A proved lower bound of the smallest over every wanted pose:
    /// `smallest` itself unless `partial`.
    pub lower: f64,
    /// The step failed (a pose below 1) while runs were left unresolved:
    /// their poses may lie lower than `smallest`, but not below `lower`.
    pub partial: bool,
    /// Limit analyses taken: poses and other corners.
    pub solves: usize,
    /// The wanted poses solved, with their factors (other corners, and
    /// poses solved only as corners, left out).
    pub poses: Vec<(usize, f64)>,
}

/// A step's sweep as the bisection takes it.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct Sweep {
    /// Samples per path (`n ≥ 3`).
    pub n: usize,
    /// Groups of movers (`G ≥ 1`).
    pub groups: usize,
    /// Poses between two samples: `3^G − 2`.
    pub per_interval: usize,
}

/// The sweep of a step whose poses the bisection can take: every mover
/// with the same `n ≥ 3` samples and `n − 1` tangent points, groups
/// `0 … G − 1` each with a mover, and the poses between samples listed
/// interval by interval, `3^G − 2` each, every point of them in its
/// interval. `None` for any other step (no movers, too many groups for
/// [`Structure::between`]).
pub fn sweep(s: &Structure) -> Option<Sweep> {
    let n = s.hanging.first()?.path.len();
    let groups = s.groups();
    let same = s
        .hanging
        .iter()
        .all(|h| h.path.len() == n && h.hull.len() + 1 == n);
    let every_group = (0..groups).all(|g| s.hanging.iter().any(|h| h.group == g));
    let per_interval = 3usize.checked_pow(groups as u32)? - 2;
    let laid_out = s.between.len() == (n.checked_sub(1)?) * per_interval
        && s.between.iter().enumerate().all(|(v, pose)| {
            let i = v / per_interval;
            pose.len() == groups
                && pose.iter().all(|p| {
                    matches!(*p, Point::Sample(k) if k == i || k == i + 1)
                        || *p == Point::Tangent(i)
                })
        });
    (n >= 3 && same && every_group && laid_out).then_some(Sweep {
        n,
        groups,
        per_interval,
    })
}

/// [`sweep`]'s sample count where the step has one group of movers.
pub fn samples(s: &Structure) -> Option<usize> {
    sweep(s).filter(|w| w.groups == 1).map(|w| w.n)
}

/// A run of at most this many intervals is solved pose by pose rather
/// than halved: halving costs a middle sample and two hulls' corners
/// (`3^G − 2` each), against `3^G − 2` poses per interval.
fn direct(groups: usize) -> usize {
    if groups == 1 { 3 } else { 2 }
}

/// A run whose bound holds (≥ 1) and lies within this fraction under the
/// smallest factor solved is passed over too, its bound then counting as
/// the smallest where it is lower. Where the factor hardly varies along
/// the sweep (a mover far from what limits the structure), the corners
/// differ from the samples only by the proofs' round-off (1e-9 of the
/// factor, measured), and an exact comparison would halve every run down
/// to its poses. So the factor reported is a proved lower bound of every
/// pose's, and at most this fraction under the exact smallest.
pub const PRUNE_SLACK: f64 = 1e-7;

/// Whether sample `k` (not the first or the last) lies, for every mover
/// with one weight, on the segment between the tangent poses of its two
/// intervals, `k − 1` and `k` (every group at its tangent point): then its
/// factor is at least the smaller of theirs (the loads are affine in the
/// centres; see the module's comment), and it need not be solved where
/// both are.
pub fn between_tangents(s: &Structure, k: usize) -> bool {
    // The one weight α with sample = b + α·(a − b), a and b the tangent
    // points before and after it, least squares over movers.
    let (mut num, mut den) = (0.0, 0.0);
    for h in &s.hanging {
        let (a, b, m) = (h.hull[k - 1], h.hull[k], h.path[k]);
        num += (m - b).dot(a - b);
        den += (a - b).length_squared();
    }
    let alpha = if den > 0.0 { num / den } else { 0.0 };
    (0.0..=1.0).contains(&alpha)
        && s.hanging.iter().all(|h| {
            let (a, b, m) = (h.hull[k - 1], h.hull[k], h.path[k]);
            (m - (b + alpha * (a - b))).length() <= INSIDE_TOLERANCE
        })
}

/// A run's hull: each mover's apex, and where each of the run's points
/// lies in its group's triangle, as weights on the triangle's corners in
/// [`hull_corners`]' order: sample `i`, sample `j`, apex.
#[derive(Clone, Debug)]
pub struct RunHull {
    /// Per mover, where its tangents at samples `i` and `j` meet.
    pub apex: Vec<DVec3>,
    /// `samples[g][k − i]`: group `g`'s weights of sample `k` (`i … j`).
    samples: Vec<Vec<[f64; 3]>>,
    /// `tangents[g][v − i]`: group `g`'s weights of tangent point `v`.
    tangents: Vec<Vec<[f64; 3]>>,
    first: usize,
}

impl RunHull {
    /// Group `g`'s weights of `p`, a point of the run.
    fn weights(&self, g: usize, p: Point) -> [f64; 3] {
        match p {
            Point::Sample(k) => self.samples[g][k - self.first],
            Point::Tangent(v) => self.tangents[g][v - self.first],
        }
    }
}

/// The hull of samples `i … j` (`j ≥ i + 2`): per mover, the apex where
/// the line through sample `i` and tangent point `i` meets the line
/// through sample `j` and tangent point `j − 1`, ahead of both samples,
/// and the weights of every point of the run (samples `i … j`, tangent
/// points `i … j − 1`) in the triangle of samples `i`, `j` and the apex,
/// one set for every mover of its group. `None` where the lines miss each
/// other or meet behind, or where some point is not inside its triangle
/// with one set of weights (to [`INSIDE_TOLERANCE`]): then the run has no
/// bound and is halved.
pub fn hull(s: &Structure, i: usize, j: usize) -> Option<RunHull> {
    assert!(j >= i + 2);
    let mut t = Vec::with_capacity(s.hanging.len());
    for h in &s.hanging {
        let (p1, d1) = (h.path[i], h.hull[i] - h.path[i]);
        let (p2, d2) = (h.path[j], h.hull[j - 1] - h.path[j]);
        // Closest points p1 + a·d1 and p2 + b·d2 of the two lines.
        let w = p1 - p2;
        let (aa, ab, bb) = (d1.dot(d1), d1.dot(d2), d2.dot(d2));
        let (aw, bw) = (d1.dot(w), d2.dot(w));
        let det = aa * bb - ab * ab;
        if det.partial_cmp(&(1e-24 * aa * bb)) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let a = (ab * bw - bb * aw) / det;
        let b = (aa * bw - ab * aw) / det;
        let (q1, q2) = (p1 + a * d1, p2 + b * d2);
        if !(a > 0.0 && b > 0.0) || (q1 - q2).length() > INSIDE_TOLERANCE {
            return None;
        }
        t.push(0.5 * (q1 + q2));
    }
    let groups = s.groups();
    let inside = |g: usize, point: &dyn Fn(usize) -> DVec3| -> Option<[f64; 3]> {
        // point_h = A_h + β(T_h − A_h) + γ(B_h − A_h), one (β, γ) for
        // the group's movers, by least squares; then each one's residual.
        let movers = || s.hanging.iter().enumerate().filter(|(_, hg)| hg.group == g);
        let (mut m11, mut m12, mut m22, mut r1, mut r2) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (h, hg) in movers() {
            let a = hg.path[i];
            let (e1, e2, p) = (t[h] - a, hg.path[j] - a, point(h) - a);
            m11 += e1.dot(e1);
            m12 += e1.dot(e2);
            m22 += e2.dot(e2);
            r1 += e1.dot(p);
            r2 += e2.dot(p);
        }
        let det = m11 * m22 - m12 * m12;
        if det.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let beta = (m22 * r1 - m12 * r2) / det;
        let gamma = (m11 * r2 - m12 * r1) / det;
        let alpha = 1.0 - beta - gamma;
        let slack = -INSIDE_TOLERANCE;
        let on_it = alpha >= slack
            && beta >= slack
            && gamma >= slack
            && movers().all(|(h, hg)| {
                let a = hg.path[i];
                let on = a + beta * (t[h] - a) + gamma * (hg.path[j] - a);
                (on - point(h)).length() <= INSIDE_TOLERANCE
            });
        // Within the tolerance a weight may be a little negative: clamped,
        // the rest scaled to sum to 1 (a shift of the order of the
        // tolerance, far under PRUNE_SLACK's effect on the bound).
        let w = [alpha.max(0.0), gamma.max(0.0), beta.max(0.0)];
        let sum = w[0] + w[1] + w[2];
        on_it.then(|| w.map(|x| x / sum))
    };
    let mut samples = Vec::with_capacity(groups);
    let mut tangents = Vec::with_capacity(groups);
    for g in 0..groups {
        let mut at_samples = vec![[1.0, 0.0, 0.0]];
        for k in i + 1..j {
            at_samples.push(inside(g, &|h| s.hanging[h].path[k])?);
        }
        at_samples.push([0.0, 1.0, 0.0]);
        samples.push(at_samples);
        tangents.push(
            (i..j)
                .map(|v| inside(g, &|h| s.hanging[h].hull[v]))
                .collect::<Option<Vec<_>>>()?,
        );
    }
    Some(RunHull {
        apex: t,
        samples,
        tangents,
        first: i,
    })
}

/// The comonotone coupling of the groups' weights (`weights[g]` on
/// sample `i`, sample `j` and the apex): a distribution over the hull's
/// corners (`code` = Σ choice_g·3^g, choice 0, 1, 2 as in
/// [`hull_corners`]) whose marginal for every group is its weights, so its
/// mean is the pose. Taking the corners in the order sample `i`, apex,
/// sample `j`, the groups walk together: a pose where they have gone
/// equally far weighs only corners where every group is at one place,
/// and the product's far corners (one group at the start, another at the
/// end) get no weight.
fn coupling(weights: &[[f64; 3]]) -> Vec<(usize, f64)> {
    // Where each group leaves sample i and leaves the apex.
    let mut cuts: Vec<f64> = vec![0.0, 1.0];
    for w in weights {
        cuts.extend([w[0], w[0] + w[2]].map(|c| c.clamp(0.0, 1.0)));
    }
    cuts.sort_by(f64::total_cmp);
    let mut out: Vec<(usize, f64)> = Vec::with_capacity(cuts.len());
    for q in cuts.windows(2) {
        let mass = q[1] - q[0];
        if mass <= 0.0 {
            continue;
        }
        let mid = 0.5 * (q[0] + q[1]);
        let code = weights.iter().rev().fold(0, |code, w| {
            let choice = if mid < w[0] {
                0
            } else if mid < w[0] + w[2] {
                2
            } else {
                1
            };
            3 * code + choice
        });
        match out.last_mut() {
            Some((c, m)) if *c == code => *m += mass,
            _ => out.push((code, mass)),
        }
    }
    out
}

/// A pose's bound from its coupling: `1/λ` is convex, so at a mean of
/// corners it is at most the same mean of theirs, and `λ` at least
/// `1 / Σ mass·(1/λ_corner)` (NaN if a corner's factor is).
fn weighted_bound(coupling: &[(usize, f64)], factor: &dyn Fn(usize) -> f64) -> f64 {
    let mut gauge = 0.0;
    for &(code, mass) in coupling {
        let f = factor(code);
        if f.is_nan() {
            return f64::NAN;
        }
        gauge += mass / f.max(0.0);
    }
    1.0 / gauge
}

/// The corners `codes` of run `i … j`'s hull (Σ choice_g·3^g: each group
/// at sample `i` (0), sample `j` (1) or its apex (2)), as the movers'
/// centres.
fn hull_corners(s: &Structure, i: usize, j: usize, apex: &[DVec3], codes: &[usize]) -> Vec<Corner> {
    codes
        .iter()
        .map(|&code| {
            let choice = |g: usize| code / 3usize.pow(g as u32) % 3;
            let centres = s
                .hanging
                .iter()
                .enumerate()
                .map(|(h, hg)| match choice(hg.group) {
                    0 => hg.path[i],
                    1 => hg.path[j],
                    _ => apex[h],
                })
                .collect();
            Corner::Centres(centres)
        })
        .collect()
}

/// A long run's poses (other than its two samples) with their couplings,
/// and the corners some coupling weighs, by code.
type RunBound = (Vec<Vec<(usize, f64)>>, Vec<usize>);

/// Run `i … j`'s poses other than its two samples, each with its
/// coupling ([`coupling`]) on the hull's corners.
fn run_couplings(
    s: &Structure,
    w: &Sweep,
    hull: &RunHull,
    i: usize,
    j: usize,
) -> Vec<Vec<(usize, f64)>> {
    let at = |points: &mut dyn Iterator<Item = Point>| -> Vec<(usize, f64)> {
        let weights: Vec<[f64; 3]> = points
            .enumerate()
            .map(|(g, p)| hull.weights(g, p))
            .collect();
        coupling(&weights)
    };
    let samples = (i + 1..j).map(|k| at(&mut (0..w.groups).map(|_| Point::Sample(k))));
    let between =
        (i * w.per_interval..j * w.per_interval).map(|v| at(&mut s.between[v].iter().copied()));
    samples.chain(between).collect()
}

/// The smallest factor over the wanted poses of a step whose [`sweep`] is
/// `w`, by bisection (see the module's comment). `floor(k)` is `None` for
/// a pose not wanted (the elastic screen cleared it: it is solved only
/// where a run's bound needs it as a corner, and never counts), else a
/// proved lower bound of its factor known beforehand (0 where none is):
/// a run whose wanted poses' floors all reach the smallest factor found
/// is passed over unsolved, and a run with no wanted pose is dropped.
/// `solve` returns the factor at each corner asked, in order (it may
/// solve them in parallel: what is asked does not depend on how). With a
/// load-factor `tolerance` (> 0), a run that holds and whose bound lies
/// within that fraction under the smallest is passed over as well, its
/// bound counting only towards `lower` (the factor is then within
/// `[lower, smallest]`, as `--load-factor-tolerance` promises). Once a
/// pose fails, the runs still open are left, and their bounds make
/// `lower`: the smallest, over each such run's wanted poses, of the best
/// bound known of the pose (its floor, or a hull's where higher).
pub fn smallest_factor(
    s: &Structure,
    w: &Sweep,
    solve: &mut dyn FnMut(&[Corner]) -> Vec<f64>,
    floor: &dyn Fn(usize) -> Option<f64>,
    tolerance: f64,
) -> Outcome {
    let n = w.n;
    let poses = n + s.between.len();
    let mut sample: Vec<Option<f64>> = vec![None; n];
    let mut out = Outcome {
        smallest: f64::INFINITY,
        lower: f64::INFINITY,
        partial: false,
        solves: 0,
        poses: Vec::new(),
    };
    let wanted = |k: usize| floor(k).is_some();
    // The best proved lower bound of each wanted pose's factor so far:
    // its floor, raised by every hull that holds it (NaN floors count 0).
    let mut known: Vec<f64> = (0..poses)
        .map(|k| floor(k).map_or(f64::NAN, |f| if f.is_nan() { 0.0 } else { f.max(0.0) }))
        .collect();
    let mut ask = |corners: &[Corner], out: &mut Outcome| -> Vec<f64> {
        let values = solve(corners);
        assert_eq!(values.len(), corners.len(), "one factor per corner");
        out.solves += corners.len();
        for (c, &v) in corners.iter().zip(&values) {
            if let Corner::Pose(k) = c
                && wanted(*k)
            {
                out.poses.push((*k, v));
                out.smallest = lowest(out.smallest, v);
            }
        }
        values
    };
    // A run's poses other than its two samples.
    let inner = move |i: usize, j: usize| {
        (i + 1..j).chain((i * w.per_interval..j * w.per_interval).map(move |v| n + v))
    };
    // The smallest known bound of a run's wanted poses (∞: none wanted).
    let run_bound = |known: &[f64], i: usize, j: usize| {
        inner(i, j)
            .filter(|&k| wanted(k))
            .fold(f64::INFINITY, |m, k| m.min(known[k]))
    };
    // Pose "every group at its tangent point" of interval `v`.
    let all_tangent = |v: usize| {
        (v * w.per_interval..(v + 1) * w.per_interval)
            .find(|&u| s.between[u].iter().all(|p| *p == Point::Tangent(v)))
            .map(|u| n + u)
    };
    let ends = ask(&[Corner::Pose(0), Corner::Pose(n - 1)], &mut out);
    sample[0] = Some(ends[0]);
    sample[n - 1] = Some(ends[1]);
    let mut runs = vec![(0, n - 1)];
    // The bounds of the runs left open when a failing pose ends the search.
    let mut open: Vec<(usize, usize, f64)> = Vec::new();
    // The smallest bound of a run passed over.
    let mut pruned = f64::INFINITY;
    // Whether a run bounded by `b` needs no solving: passed over (its
    // bound may count as the smallest, within PRUNE_SLACK), spared by the
    // tolerance (its bound then the lower end), or still open.
    let judge = |b: f64, out: &mut Outcome, pruned: &mut f64| -> bool {
        // `b ≥ …` is false for a NaN on either side.
        let within = |slack: f64| b >= 1.0 && b >= (1.0 - slack) * out.smallest;
        if b >= out.smallest || within(PRUNE_SLACK) {
            *pruned = lowest(*pruned, b);
            return true;
        }
        if within(tolerance) {
            out.lower = lowest(out.lower, b);
            return true;
        }
        false
    };
    while !runs.is_empty() {
        open.clear();
        // What is known already may settle a run: no wanted pose, or
        // bounds (floors, hulls of the runs it was cut from) enough.
        runs.retain(|&(i, j)| {
            let b = run_bound(&known, i, j);
            !(b.is_infinite() || judge(b, &mut out, &mut pruned))
        });
        // A short run is solved pose by pose: its wanted poses between
        // its samples, and any wanted interior sample not between two
        // tangent poses solved here (the others are dominated). A long
        // one is bounded through its hull's corners, if every point of it
        // lies in its triangles.
        let (short, long): (Vec<_>, Vec<_>) =
            runs.iter().partition(|&&(i, j)| j - i <= direct(w.groups));
        let mut asked: Vec<Corner> = Vec::new();
        for &(i, j) in &short {
            let between = (i * w.per_interval..j * w.per_interval).map(|v| n + v);
            asked.extend(between.filter(|&k| wanted(k)).map(Corner::Pose));
            let dominated = |k: usize| {
                between_tangents(s, k)
                    && [k - 1, k]
                        .iter()
                        .all(|&v| all_tangent(v).is_some_and(&wanted))
            };
            asked.extend(
                (i + 1..j)
                    .filter(|&k| wanted(k) && !dominated(k))
                    .map(Corner::Pose),
            );
        }
        let short_asked = asked.len();
        // Each long run's poses with their couplings, and the corners
        // other than its samples that some coupling weighs.
        let all_j = (3usize.pow(w.groups as u32) - 1) / 2;
        let bounded: Vec<Option<RunBound>> = long
            .iter()
            .map(|&(i, j)| {
                let hull = hull(s, i, j)?;
                let couplings = run_couplings(s, w, &hull, i, j);
                let mut codes: Vec<usize> = couplings.iter().flatten().map(|&(c, _)| c).collect();
                codes.sort_unstable();
                codes.dedup();
                codes.retain(|&c| c != 0 && c != all_j);
                asked.extend(hull_corners(s, i, j, &hull.apex, &codes));
                Some((couplings, codes))
            })
            .collect();
        let values = ask(&asked, &mut out);
        let mut at_corner = values[short_asked..].iter();
        let mut halves = Vec::new();
        for (&(i, j), c) in long.iter().zip(&bounded) {
            // Each pose's bound from the hull's corners raises what is
            // known of it (a NaN corner gives none).
            if let (Some(x), Some(y), Some((couplings, codes))) = (sample[i], sample[j], c) {
                let solved: Vec<f64> = codes
                    .iter()
                    .map(|_| *at_corner.next().expect("one value per corner"))
                    .collect();
                let factor = |code: usize| match code {
                    0 => x,
                    c if c == all_j => y,
                    c => solved[codes.binary_search(&c).expect("a corner asked")],
                };
                for (k, coupling) in inner(i, j).zip(couplings) {
                    let b = weighted_bound(coupling, &factor);
                    if b > known[k] {
                        known[k] = b;
                    }
                }
            }
            let b = run_bound(&known, i, j);
            if judge(b, &mut out, &mut pruned) {
                continue;
            }
            open.push((i, j, b));
            halves.push((i, (i + j) / 2, j));
        }
        if fails(out.smallest) && !open.is_empty() {
            break;
        }
        let middles: Vec<Corner> = halves.iter().map(|&(_, m, _)| Corner::Pose(m)).collect();
        let values = ask(&middles, &mut out);
        for (&(_, m, _), v) in halves.iter().zip(values) {
            sample[m] = Some(v);
        }
        runs = halves
            .into_iter()
            .flat_map(|(i, m, j)| [(i, m), (m, j)])
            .collect();
        if fails(out.smallest) && !runs.is_empty() {
            // Failed at a middle sample: the halves are left, bounded by
            // what is known of their poses.
            open = runs
                .iter()
                .map(|&(i, j)| (i, j, run_bound(&known, i, j)))
                .collect();
            break;
        }
    }
    out.smallest = lowest(out.smallest, pruned);
    // Runs stay open only when a failing pose ended the search; what is
    // known of their poses makes the lower end.
    out.partial = !open.is_empty();
    for &(_, _, b) in &open {
        out.lower = lowest(out.lower, b);
    }
    out.lower = lowest(out.lower, out.smallest);
    // Open runs whose bounds reach the smallest leave nothing unknown.
    out.partial &= out.lower.partial_cmp(&out.smallest) == Some(std::cmp::Ordering::Less)
        || out.lower.is_nan()
        || out.smallest.is_nan();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Weights on (sample i, sample j, apex) from a small generator.
    fn weights(seed: &mut u64) -> [f64; 3] {
        let mut next = || {
            *seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (*seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let w = [next(), next(), next()];
        let sum = w[0] + w[1] + w[2];
        w.map(|x| x / sum)
    }

    #[test]
    fn the_coupling_of_groups_has_each_groups_weights_as_its_marginal() {
        let mut seed = 7;
        for groups in 1..=3 {
            for _ in 0..200 {
                let w: Vec<[f64; 3]> = (0..groups).map(|_| weights(&mut seed)).collect();
                let c = coupling(&w);
                assert!((c.iter().map(|(_, m)| m).sum::<f64>() - 1.0).abs() < 1e-12);
                assert!(c.iter().all(|&(_, m)| m > 0.0));
                for (g, wg) in w.iter().enumerate() {
                    let mut marginal = [0.0; 3];
                    for &(code, m) in &c {
                        marginal[code / 3usize.pow(g as u32) % 3] += m;
                    }
                    for x in 0..3 {
                        assert!((marginal[x] - wg[x]).abs() < 1e-12, "{w:?} {c:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn groups_at_the_same_place_weigh_only_corners_where_they_are_together() {
        let mut seed = 11;
        for _ in 0..50 {
            let w = weights(&mut seed);
            let c = coupling(&[w, w]);
            // Codes 0, 4, 8: both at sample i, both at sample j, both at
            // the apex.
            assert!(
                c.iter().all(|&(code, _)| [0, 4, 8].contains(&code)),
                "{c:?}"
            );
        }
        // One group at sample i, the other at sample j: the far corner.
        assert_eq!(
            coupling(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
            vec![(3, 1.0)]
        );
    }

    #[test]
    fn a_weighted_bound_is_the_harmonic_mean_and_a_failed_corner_sticks() {
        let c = [(0, 0.5), (2, 0.5)];
        let b = weighted_bound(&c, &|code| if code == 0 { 2.0 } else { 4.0 });
        assert!((b - 1.0 / (0.25 + 0.125)).abs() < 1e-15);
        assert!(b >= 2.0);
        assert!(weighted_bound(&c, &|code| if code == 0 { f64::NAN } else { 4.0 }).is_nan());
        assert_eq!(
            weighted_bound(&c, &|code| if code == 0 { 0.0 } else { 4.0 }),
            0.0
        );
        assert_eq!(weighted_bound(&c, &|_| f64::INFINITY), f64::INFINITY);
    }
}
