//! A few points whose convex hull holds a set of points: the poses of a
//! step's movers, as coordinates of their moment changes, so that a bound
//! proved at those few points holds at every pose (loads and elastic
//! fields are affine in the coordinates, admissible forces convex).
//!
//! Movers that turn together at one rate trace an ellipse arc: their
//! coordinates lie in a plane (spanned by the cosine and sine of the
//! angle), and a convex arc turning by less than half a turn lies in the
//! triangle of its chord and its first and last segments produced. So 25
//! poses become 3 points. Movers turning at `k` rates span `2k` dimensions
//! and lie in a simplex of `2k + 1` corners (the sandcastle's steps: 6
//! dimensions, 7 corners for 25 poses). Where that is not fewer than the
//! caller allows, `None`, and the caller goes pose by pose.

use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// How far from the fitted plane, or outside the triangle, a point may lie,
/// relative to the points' extent plus one (in `W·d`, moments of modules of
/// unit weight): round-off of the fit, far below the elastic solve's own
/// tolerance (`WITNESS_RESIDUAL`, 1e-8 of the loads).
pub const HULL_TOLERANCE: f64 = 1e-9;

/// At most `max_corners` points whose convex hull holds every point of
/// `points` to within [`HULL_TOLERANCE`], each given as an affine
/// combination of `points` (index, weight; the weights sum to one), or
/// `None`. As combinations, whatever is affine in the points (loads, and
/// the elastic fields that balance them) follows at the corners without a
/// new solve.
///
/// The points are first put in the affine subspace of their principal
/// directions (its dimension `r` the smallest that holds them to the
/// tolerance). In a plane: the smallest triangle of a hull edge and its two
/// neighbours produced (an arc: its chord and end segments). Otherwise, or
/// where no such triangle holds them, the simplex of `r + 1` corners
/// `y ≥ lo`, `Σ (y_j − lo_j) / range_j ≤ T` with `T` the least that holds
/// every point.
pub fn enclosing(points: &[Vec<f64>], max_corners: usize) -> Option<Vec<Vec<(usize, f64)>>> {
    let n = points.len();
    let m = points.first()?.len();
    if max_corners == 0
        || points
            .iter()
            .any(|p| p.len() != m || p.iter().any(|v| !v.is_finite()))
    {
        return None;
    }
    let centre: Vec<f64> = (0..m)
        .map(|j| points.iter().map(|p| p[j]).sum::<f64>() / n as f64)
        .collect();
    let x = DMatrix::from_fn(n, m, |i, j| points[i][j] - centre[j]);
    let extent = (0..n).map(|i| x.row(i).norm()).fold(0.0, f64::max);
    let tol = HULL_TOLERANCE * (1.0 + extent);
    if extent <= tol {
        return Some(vec![vec![(0, 1.0)]]);
    }
    let eigen = SymmetricEigen::new(x.transpose() * &x);
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
    // The fewest principal directions that hold every point.
    let most = (max_corners - 1).min(m);
    let mut axes: Vec<DVector<f64>> = Vec::new();
    let mut y: Vec<Vec<f64>> = vec![Vec::new(); n];
    loop {
        let held = (0..n).all(|i| {
            let mut off = x.row(i).transpose();
            for (a, &c) in axes.iter().zip(&y[i]) {
                off -= a * c;
            }
            off.norm() <= tol
        });
        if held {
            break;
        }
        if axes.len() == most {
            return None;
        }
        let a = eigen.eigenvectors.column(order[axes.len()]).into_owned();
        for (i, yi) in y.iter_mut().enumerate() {
            yi.push(a.dot(&x.row(i).transpose()));
        }
        axes.push(a);
    }
    let r = axes.len();
    let planar = (r <= 2)
        .then(|| {
            let flat: Vec<[f64; 2]> = y
                .iter()
                .map(|v| [v[0], v.get(1).copied().unwrap_or(0.0)])
                .collect();
            triangle_around(&flat, tol)
        })
        .flatten()
        .map(|t| t.into_iter().map(|c| c[..r].to_vec()).collect::<Vec<_>>());
    let corners = match planar {
        Some(c) => c,
        None => corner_simplex(&y, tol),
    };
    if corners.len() > max_corners {
        return None;
    }
    // Anchors: r + 1 points spanning the subspace, each the farthest from
    // the span of those before (well conditioned).
    let mut anchors =
        vec![(0..n).max_by(|&i, &j| dist(&y[i], &y[0]).total_cmp(&dist(&y[j], &y[0])))?];
    let mut basis: Vec<Vec<f64>> = Vec::new();
    while anchors.len() <= r {
        let o = &y[anchors[0]];
        let residual = |i: usize| -> Vec<f64> {
            let mut v: Vec<f64> = y[i].iter().zip(o).map(|(a, b)| a - b).collect();
            for b in &basis {
                let c: f64 = v.iter().zip(b).map(|(p, q)| p * q).sum();
                v.iter_mut().zip(b).for_each(|(p, q)| *p -= c * q);
            }
            v
        };
        let len = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
        let next = (0..n).max_by(|&i, &j| len(&residual(i)).total_cmp(&len(&residual(j))))?;
        let v = residual(next);
        let l = len(&v);
        if l <= tol {
            return None;
        }
        basis.push(v.iter().map(|a| a / l).collect());
        anchors.push(next);
    }
    let o = &y[anchors[0]];
    let a = DMatrix::from_fn(r, r, |j, k| y[anchors[k + 1]][j] - o[j]);
    let lu = a.lu();
    corners
        .into_iter()
        .map(|c| {
            let rhs = DVector::from_fn(r, |j, _| c[j] - o[j]);
            let beta = lu.solve(&rhs)?;
            if beta.iter().any(|b| !b.is_finite()) {
                return None;
            }
            let mut w = vec![(anchors[0], 1.0 - beta.sum())];
            w.extend(anchors[1..].iter().zip(beta.iter()).map(|(&i, &b)| (i, b)));
            Some(w)
        })
        .collect()
}

/// The simplex `y ≥ lo`, `Σ (y_j − lo_j) / range_j ≤ T` (T the least that
/// holds every point, moved out by the tolerance): its `r + 1` corners.
fn corner_simplex(y: &[Vec<f64>], tol: f64) -> Vec<Vec<f64>> {
    let r = y[0].len();
    let lo: Vec<f64> = (0..r)
        .map(|j| y.iter().map(|v| v[j]).fold(f64::INFINITY, f64::min) - tol)
        .collect();
    let range: Vec<f64> = (0..r)
        .map(|j| y.iter().map(|v| v[j]).fold(f64::NEG_INFINITY, f64::max) + tol - lo[j])
        .collect();
    let t = y
        .iter()
        .map(|v| (0..r).map(|j| (v[j] - lo[j]) / range[j]).sum::<f64>())
        .fold(0.0, f64::max)
        * (1.0 + HULL_TOLERANCE);
    let mut corners = vec![lo.clone()];
    for j in 0..r {
        let mut c = lo.clone();
        c[j] += t * range[j];
        corners.push(c);
    }
    corners
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (p - q) * (p - q))
        .sum::<f64>()
        .sqrt()
}

/// The smallest triangle, over the hull's edges as a base with the two
/// edges beside it produced, that holds every point (to `tol`); a segment
/// or the hull itself where it has at most three corners.
fn triangle_around(points: &[[f64; 2]], tol: f64) -> Option<Vec<[f64; 2]>> {
    let hull = convex_hull(points, tol);
    if hull.len() <= 3 {
        return Some(hull);
    }
    let k = hull.len();
    let mut best: Option<(f64, [[f64; 2]; 3])> = None;
    for i in 0..k {
        let (a, b) = (hull[i], hull[(i + 1) % k]);
        let (before, after) = (hull[(i + k - 1) % k], hull[(i + 2) % k]);
        let Some(apex) = meet(before, a, b, after) else {
            continue;
        };
        let t = [a, b, apex];
        let area = cross(sub(b, a), sub(apex, a)).abs() / 2.0;
        if best.is_some_and(|(s, _)| s <= area) {
            continue;
        }
        if points.iter().all(|&p| inside(t, p, tol)) {
            best = Some((area, t));
        }
    }
    best.map(|(_, t)| t.to_vec())
}

/// Where the line through `p`, `q` meets the line through `r`, `s`, on the
/// far side of `q` from `p` and of `r` from `s` (a produced edge); `None`
/// where they are parallel or meet behind.
fn meet(p: [f64; 2], q: [f64; 2], r: [f64; 2], s: [f64; 2]) -> Option<[f64; 2]> {
    let (d1, d2) = (sub(q, p), sub(r, s));
    let den = cross(d1, d2);
    if den.abs() <= f64::EPSILON * norm(d1) * norm(d2) {
        return None;
    }
    let w = sub(r, q);
    let t = cross(w, d2) / den;
    let u = cross(w, d1) / den;
    (t >= 0.0 && u >= 0.0).then(|| [q[0] + t * d1[0], q[1] + t * d1[1]])
}

/// Whether `p` lies in triangle `t`, each edge moved out by `tol`.
fn inside(t: [[f64; 2]; 3], p: [f64; 2], tol: f64) -> bool {
    let orient = cross(sub(t[1], t[0]), sub(t[2], t[0])).signum();
    (0..3).all(|i| {
        let (a, b) = (t[i], t[(i + 1) % 3]);
        let e = sub(b, a);
        orient * cross(e, sub(p, a)) >= -tol * norm(e)
    })
}

/// The convex hull, counter-clockwise (Andrew's monotone chain), points
/// closer than `tol` to an edge dropped.
pub(super) fn convex_hull(points: &[[f64; 2]], tol: f64) -> Vec<[f64; 2]> {
    let mut p = points.to_vec();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup_by(|a, b| norm(sub(*a, *b)) <= tol);
    if p.len() <= 2 {
        return p;
    }
    let turn = |h: &[[f64; 2]], c: [f64; 2]| {
        let (a, b) = (h[h.len() - 2], h[h.len() - 1]);
        cross(sub(b, a), sub(c, a)) <= tol * norm(sub(c, a))
    };
    let mut lower: Vec<[f64; 2]> = Vec::new();
    for &c in &p {
        while lower.len() >= 2 && turn(&lower, c) {
            lower.pop();
        }
        lower.push(c);
    }
    let mut upper: Vec<[f64; 2]> = Vec::new();
    for &c in p.iter().rev() {
        while upper.len() >= 2 && turn(&upper, c) {
            upper.pop();
        }
        upper.push(c);
    }
    lower.pop();
    upper.pop();
    lower.extend(upper);
    lower
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn norm(a: [f64; 2]) -> f64 {
    a[0].hypot(a[1])
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The corners as points, from their combinations.
    fn lift(points: &[Vec<f64>], corners: &[Vec<(usize, f64)>]) -> Vec<Vec<f64>> {
        corners
            .iter()
            .map(|c| {
                (0..points[0].len())
                    .map(|j| c.iter().map(|&(i, w)| w * points[i][j]).sum())
                    .collect()
            })
            .collect()
    }

    /// Whether `p` is a convex combination of `v` to `tol`, by an
    /// independent formulation (Carathéodory): some subset of the corners
    /// whose least-squares weights (with `Σ w = 1`) are non-negative and
    /// fit `p`. Every subset is tried, so nearly coincident corners do not
    /// upset it.
    fn in_hull(v: &[Vec<f64>], p: &[f64], tol: f64) -> bool {
        let (m, k) = (p.len(), v.len());
        (1..1usize << k).any(|set| {
            let idx: Vec<usize> = (0..k).filter(|&i| set >> i & 1 == 1).collect();
            let o = &v[idx[0]];
            let b = nalgebra::DVector::from_fn(m, |j, _| p[j] - o[j]);
            if idx.len() == 1 {
                return b.norm() <= tol;
            }
            // p − o = Σ w_i (v_i − o) over the rest of the subset.
            let a = DMatrix::from_fn(m, idx.len() - 1, |j, c| v[idx[c + 1]][j] - o[j]);
            let Ok(w) = a.clone().svd(true, true).solve(&b, 1e-12) else {
                return false;
            };
            let fit = (&a * &w - &b).norm();
            fit <= tol && w.iter().all(|&x| x >= -1e-9) && 1.0 - w.sum() >= -1e-9
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// Movers turning together at one rate, each about its own axis
        /// with its own lever, sampled along the turn: three corners hold
        /// every sample (the test's own least-squares weights).
        #[test]
        fn an_arc_of_movers_turning_together_lies_in_three_corners(
            movers in 1usize..6,
            turn in 0.2f64..2.8,
            samples in 3usize..30,
            seed in proptest::collection::vec(-2.0f64..2.0, 36),
        ) {
            let points: Vec<Vec<f64>> = (0..samples)
                .map(|k| {
                    let phi = turn * k as f64 / (samples - 1) as f64;
                    (0..2 * movers)
                        .map(|j| seed[3 * j] * phi.cos() + seed[3 * j + 1] * phi.sin() + seed[3 * j + 2])
                        .collect()
                })
                .collect();
            let corners = enclosing(&points, 3).expect("an arc of less than half a turn");
            prop_assert!(corners.len() <= 3);
            for c in &corners {
                prop_assert!((c.iter().map(|w| w.1).sum::<f64>() - 1.0).abs() < 1e-9);
            }
            let corners = lift(&points, &corners);
            for p in &points {
                prop_assert!(in_hull(&corners, p, 1e-7), "{p:?} outside {corners:?}");
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// Movers turning at up to three rates: the coordinates span up to
        /// six dimensions, and the simplex of one corner more holds every
        /// sample; never more corners than allowed.
        #[test]
        fn movers_turning_at_several_rates_lie_in_a_simplex_of_one_corner_more_than_their_dimensions(
            movers in 1usize..6,
            rates in proptest::collection::vec(0.3f64..1.0, 3),
            turn in 0.2f64..2.8,
            samples in 8usize..30,
            seed in proptest::collection::vec(-2.0f64..2.0, 40),
            max_corners in 2usize..9,
        ) {
            let points: Vec<Vec<f64>> = (0..samples)
                .map(|k| {
                    let phi = turn * k as f64 / (samples - 1) as f64;
                    (0..2 * movers)
                        .map(|j| {
                            let rate = rates[(j / 2) % 3];
                            seed[3 * j] * (rate * phi).cos() + seed[3 * j + 1] * (rate * phi).sin() + seed[3 * j + 2]
                        })
                        .collect()
                })
                .collect();
            if let Some(corners) = enclosing(&points, max_corners) {
                prop_assert!(corners.len() <= max_corners);
                let corners = lift(&points, &corners);
                for p in &points {
                    prop_assert!(in_hull(&corners, p, 1e-6), "{p:?} outside {corners:?}");
                }
            }
        }
    }

    #[test]
    fn points_off_one_plane_need_more_than_three_corners() {
        // Two rates of turning: the coordinates leave every plane, and span
        // four dimensions: five corners.
        let points: Vec<Vec<f64>> = (0..20)
            .map(|k| {
                let phi = k as f64 * 0.1;
                vec![phi.cos(), phi.sin(), (2.0 * phi).cos(), (2.0 * phi).sin()]
            })
            .collect();
        assert!(enclosing(&points, 3).is_none());
        let corners = enclosing(&points, 5).unwrap();
        assert_eq!(corners.len(), 5);
        let corners = lift(&points, &corners);
        assert!(points.iter().all(|p| in_hull(&corners, p, 1e-7)));
    }

    #[test]
    fn a_full_turn_has_no_triangle_of_produced_edges_but_a_segment_has_two_ends() {
        let circle: Vec<Vec<f64>> = (0..24)
            .map(|k| {
                let phi = k as f64 * std::f64::consts::TAU / 24.0;
                vec![phi.cos(), phi.sin()]
            })
            .collect();
        // Every base's produced neighbours meet, but the triangle misses
        // points across the circle: the smallest that holds them all is
        // found or none is; either way nothing outside is returned.
        if let Some(c) = enclosing(&circle, 3) {
            let c = lift(&circle, &c);
            assert!(circle.iter().all(|p| in_hull(&c, p, 1e-7)));
        }
        let line: Vec<Vec<f64>> = (0..10)
            .map(|k| vec![k as f64, 2.0 * k as f64, 1.0])
            .collect();
        let ends = lift(&line, &enclosing(&line, 3).unwrap());
        assert_eq!(ends.len(), 2);
        assert!(line.iter().all(|p| in_hull(&ends, p, 1e-7)));
        assert!(enclosing(&[vec![f64::NAN, 0.0]], 3).is_none());
    }
}
