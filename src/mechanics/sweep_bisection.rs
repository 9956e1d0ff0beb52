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
//! (checked numerically, one weight for every mover of the group). So
//! every pose of the run lies in the product of the groups' triangles, the
//! hull of its `3^G` corners (each group at sample `i`, sample `j` or its
//! apex), and has `λ` at least the smallest of theirs. Where that is no
//! smaller than the smallest factor found at a pose, the run need not be
//! solved; otherwise it is halved at its middle sample, and a short run is
//! solved pose by pose. The result is the smallest factor over every pose,
//! as when each is solved, from fewer limit analyses where `λ` varies
//! smoothly along the sweep (a corner that is no pose is solved too, but
//! only bounds).

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
    /// The smallest factor over the poses (NaN: a solve failed): the
    /// smallest solved, or a passed-over run's bound where lower (see
    /// [`PRUNE_SLACK`]).
    pub smallest: f64,
    /// A proved lower bound of the smallest over every pose: `smallest`
    /// itself unless `partial`.
    pub lower: f64,
    /// The step failed (a pose below 1) while runs were left unresolved:
    /// their poses may lie lower than `smallest`, but not below `lower`.
    pub partial: bool,
    /// Limit analyses taken: poses and other corners.
    pub solves: usize,
    /// The poses solved, with their factors (other corners left out).
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
    let groups = s.hanging.iter().map(|h| h.group + 1).max()?;
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

/// The apexes of samples `i … j` (`j ≥ i + 2`): per mover, where the line
/// through sample `i` and tangent point `i` meets the line through sample
/// `j` and tangent point `j − 1`, ahead of both samples. `None` where the
/// lines miss each other or meet behind, or where some point of the run
/// (samples `i + 1 … j − 1`, tangent points `i … j − 1`) is not inside
/// the triangle of samples `i`, `j` and the apex with one set of weights
/// for every mover of its group: then the run has no bound and is halved.
pub fn apex(s: &Structure, i: usize, j: usize) -> Option<Vec<DVec3>> {
    debug_assert!(j >= i + 2);
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
    let groups = s.hanging.iter().map(|h| h.group + 1).max().unwrap_or(0);
    let inside = |g: usize, point: &dyn Fn(usize) -> DVec3| -> bool {
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
            return false;
        }
        let beta = (m22 * r1 - m12 * r2) / det;
        let gamma = (m11 * r2 - m12 * r1) / det;
        let alpha = 1.0 - beta - gamma;
        let slack = -INSIDE_TOLERANCE;
        alpha >= slack
            && beta >= slack
            && gamma >= slack
            && movers().all(|(h, hg)| {
                let a = hg.path[i];
                let on = a + beta * (t[h] - a) + gamma * (hg.path[j] - a);
                (on - point(h)).length() <= INSIDE_TOLERANCE
            })
    };
    let all_inside = (0..groups).all(|g| {
        (i + 1..j).all(|k| inside(g, &|h| s.hanging[h].path[k]))
            && (i..j).all(|v| inside(g, &|h| s.hanging[h].hull[v]))
    });
    all_inside.then_some(t)
}

/// The corners of run `i … j`'s hull other than its two samples: each
/// group at sample `i`, sample `j` or its apex (`apex`, per mover), as
/// the movers' centres.
fn hull_corners(s: &Structure, w: &Sweep, i: usize, j: usize, apex: &[DVec3]) -> Vec<Corner> {
    let mut out = Vec::with_capacity(w.per_interval);
    for code in 0..3usize.pow(w.groups as u32) {
        let choice = |g: usize| code / 3usize.pow(g as u32) % 3;
        if (0..w.groups).all(|g| choice(g) == 0) || (0..w.groups).all(|g| choice(g) == 1) {
            continue;
        }
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
        out.push(Corner::Centres(centres));
    }
    out
}

/// The smallest factor over the poses of a step whose [`sweep`] is `w`,
/// by bisection (see the module's comment). `solve` returns the factor at
/// each corner asked, in order (it may solve them in parallel: what is
/// asked does not depend on how). With a load-factor `tolerance` (> 0), a
/// run that holds and whose bound lies within that fraction under the
/// smallest is passed over as well, its bound counting only towards
/// `lower` (the factor is then within `[lower, smallest]`, as
/// `--load-factor-tolerance` promises). Once a pose fails, the runs still open
/// are left, and their bounds make `lower`: the larger of the run's
/// corners' smallest and its poses' smallest `floor` (a proved lower
/// bound of each pose's factor known beforehand, 0 where none is).
pub fn smallest_factor(
    s: &Structure,
    w: &Sweep,
    solve: &mut dyn FnMut(&[Corner]) -> Vec<f64>,
    floor: &dyn Fn(usize) -> f64,
    tolerance: f64,
) -> Outcome {
    let n = w.n;
    let mut sample: Vec<Option<f64>> = vec![None; n];
    let mut out = Outcome {
        smallest: f64::INFINITY,
        lower: f64::INFINITY,
        partial: false,
        solves: 0,
        poses: Vec::new(),
    };
    let mut ask = |corners: &[Corner], out: &mut Outcome| -> Vec<f64> {
        let values = solve(corners);
        assert_eq!(values.len(), corners.len(), "one factor per corner");
        out.solves += corners.len();
        for (c, &v) in corners.iter().zip(&values) {
            if let Corner::Pose(k) = c {
                out.poses.push((*k, v));
                out.smallest = lowest(out.smallest, v);
            }
        }
        values
    };
    let ends = ask(&[Corner::Pose(0), Corner::Pose(n - 1)], &mut out);
    sample[0] = Some(ends[0]);
    sample[n - 1] = Some(ends[1]);
    let mut runs = vec![(0, n - 1)];
    // The bounds of the runs left open when a failing pose ends the search.
    let mut open: Vec<(usize, usize, f64)> = Vec::new();
    // The smallest bound of a run passed over.
    let mut pruned = f64::INFINITY;
    while !runs.is_empty() {
        open.clear();
        // A short run is solved pose by pose: the poses between its
        // samples, and any interior sample not between its two tangent
        // poses (the others are dominated). A long one is bounded by its
        // hull's corners, if every point of it lies in its triangles.
        let (short, long): (Vec<_>, Vec<_>) =
            runs.iter().partition(|&&(i, j)| j - i <= direct(w.groups));
        let mut asked: Vec<Corner> = Vec::new();
        for &(i, j) in &short {
            let between = i * w.per_interval..j * w.per_interval;
            asked.extend(between.map(|v| Corner::Pose(n + v)));
            asked.extend(
                (i + 1..j)
                    .filter(|&k| !between_tangents(s, k))
                    .map(Corner::Pose),
            );
        }
        let corners: Vec<Option<Vec<Corner>>> = long
            .iter()
            .map(|&(i, j)| apex(s, i, j).map(|t| hull_corners(s, w, i, j, &t)))
            .collect();
        let first_corner = asked.len();
        asked.extend(corners.iter().flatten().flatten().cloned());
        let values = ask(&asked, &mut out);
        let mut at_corner = values[first_corner..].iter();
        let mut halves = Vec::new();
        for (&(i, j), c) in long.iter().zip(&corners) {
            // The run's bound: the smallest of its corners (NaN: none).
            let b = match (sample[i], sample[j], c) {
                (Some(x), Some(y), Some(c)) => (0..c.len())
                    .map(|_| *at_corner.next().expect("one value per corner"))
                    .fold(lowest(x, y), lowest),
                _ => f64::NAN,
            };
            // `b ≥ …` is false for a NaN on either side.
            let within = |slack: f64| b >= 1.0 && b >= (1.0 - slack) * out.smallest;
            if b >= out.smallest || within(PRUNE_SLACK) {
                pruned = lowest(pruned, b);
                continue;
            }
            if within(tolerance) {
                // Spared by the load-factor tolerance: its bound is the
                // lower end, not the factor.
                out.lower = lowest(out.lower, b);
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
            // their parents' bounds.
            break;
        }
    }
    out.smallest = lowest(out.smallest, pruned);
    // Runs stay open only when a failing pose ended the search.
    out.partial = !open.is_empty();
    if out.partial {
        for (i, j, b) in open {
            let poses = (i..=j).chain((i * w.per_interval..j * w.per_interval).map(|v| n + v));
            let known = poses.map(floor).fold(f64::INFINITY, f64::min).max(0.0);
            out.lower = lowest(out.lower, if b.is_nan() { known } else { b.max(known) });
        }
    }
    out.lower = lowest(out.lower, out.smallest);
    // Open runs whose bounds reach the smallest leave nothing unknown.
    out.partial &= out.lower.partial_cmp(&out.smallest) == Some(std::cmp::Ordering::Less)
        || out.lower.is_nan()
        || out.smallest.is_nan();
    out
}
