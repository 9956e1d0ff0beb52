//! The poses of a step as a few unit load cases. A pose's loads differ
//! from the reference pose's only by each mover's moment on its pivot
//! (its weight acts at its centre). Movers of one group turn at one rate
//! (`Hanging::group`), each along at most two circular arcs that meet at
//! the same sample: on an arc a mover's centre is `p + cos φ·a + sin φ·b`
//! with `φ` common to the group, so the group's moments, stacked over all
//! its movers, lie in a space of at most three dimensions (two per arc,
//! one shared at the joint), however many movers it has. An orthonormal
//! basis of that space gives each pose's elastic field as the reference's
//! plus a combination of one solution per basis vector: a few solves per
//! group instead of one per pose, with the poses between samples (tangent
//! points, [`crate::mechanics::structure::Hanging::hull`]) in the same
//! space.
//!
//! The basis is not derived from the arcs but found from the points
//! themselves (pivoted Gram–Schmidt, orthogonalised twice), so a path of
//! any shape is served: it only costs more vectors. Every sample and
//! tangent point of the group is then reproduced to within
//! [`SPAN_TOLERANCE`] of the group's largest moment change, checked, not
//! assumed.

use super::structure::Structure;
use glam::DVec3;

/// One unit load case: a direction in the stacked moments of one group's
/// movers.
#[derive(Clone, Debug, PartialEq)]
pub struct Unit {
    pub group: usize,
    /// Per mover (`Structure::hanging` index), its moment along this
    /// direction (units `W·d`); all of them together have unit length.
    pub moments: Vec<(usize, DVec3)>,
}

impl Unit {
    /// The coordinate along this unit of the movers' moment changes
    /// `change(h)`: the weight of this unit's solution in a pose.
    pub fn coordinate(&self, change: impl Fn(usize) -> DVec3) -> f64 {
        self.moments.iter().map(|&(h, m)| change(h).dot(m)).sum()
    }
}

/// What is left of any sample's or tangent point's moment change outside
/// the basis, relative to the group's largest change: round-off. A larger
/// remainder is a direction of its own.
pub const SPAN_TOLERANCE: f64 = 1e-12;

/// An orthonormal basis, group by group, of the changes of the movers'
/// moments from their reference moments (`reference(h)`) over every
/// sample and tangent point of their paths; `moment(h, c)` is mover `h`'s
/// moment with its centre at `c`. `movers` are `Structure::hanging`
/// indices. A group whose moments never change has no unit. `None`
/// where a moment is not finite: no basis stands for such a pose (its
/// loads are for the solve to refuse).
pub fn units(
    s: &Structure,
    movers: &[usize],
    moment: &dyn Fn(usize, DVec3) -> DVec3,
    reference: &dyn Fn(usize) -> DVec3,
) -> Option<Vec<Unit>> {
    let mut out = Vec::new();
    for g in 0..s.groups() {
        let members: Vec<usize> = movers
            .iter()
            .copied()
            .filter(|&h| s.hanging[h].group == g)
            .collect();
        let Some(&first) = members.first() else {
            continue;
        };
        let (n, t) = (s.hanging[first].path.len(), s.hanging[first].hull.len());
        // Point k: sample k, or tangent point k − n.
        let point = |k: usize| -> Vec<DVec3> {
            members
                .iter()
                .map(|&h| {
                    let hg = &s.hanging[h];
                    let c = if k < n { hg.path[k] } else { hg.hull[k - n] };
                    moment(h, c) - reference(h)
                })
                .collect()
        };
        let points: Vec<Vec<DVec3>> = (0..n + t).map(point).collect();
        if !points.iter().flatten().all(|m| m.is_finite()) {
            return None;
        }
        out.extend(span(&points).into_iter().map(|b| Unit {
            group: g,
            moments: members.iter().copied().zip(b).collect(),
        }));
    }
    Some(out)
}

fn dot(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x.dot(*y)).sum()
}

/// `x` less its projection on the orthonormal `basis`, taken twice (one
/// pass of Gram–Schmidt loses orthogonality to round-off).
fn residual(x: &[DVec3], basis: &[Vec<DVec3>]) -> Vec<DVec3> {
    let mut r = x.to_vec();
    for _ in 0..2 {
        for b in basis {
            let c = dot(&r, b);
            r.iter_mut().zip(b).for_each(|(p, q)| *p -= c * *q);
        }
    }
    r
}

/// An orthonormal basis of the span of `points`, each new vector the
/// point farthest from the span so far, until every point lies within
/// `SPAN_TOLERANCE` of the largest point's length of it.
fn span(points: &[Vec<DVec3>]) -> Vec<Vec<DVec3>> {
    let scale = points.iter().map(|p| dot(p, p).sqrt()).fold(0.0, f64::max);
    let mut basis: Vec<Vec<DVec3>> = Vec::new();
    if scale == 0.0 {
        return basis;
    }
    loop {
        let farthest = points
            .iter()
            .map(|p| residual(p, &basis))
            .map(|r| (dot(&r, &r).sqrt(), r))
            .max_by(|a, b| a.0.total_cmp(&b.0));
        match farthest {
            Some((len, r)) if len > SPAN_TOLERANCE * scale => {
                basis.push(r.into_iter().map(|v| v / len).collect());
            }
            _ => return basis,
        }
        if basis.len() >= points.first().map_or(0, |p| 3 * p.len()) {
            return basis;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::config::ModuleId;
    use crate::lattice::{Cell, Configuration, FccLattice, Lattice, Motion, Route};
    use crate::mechanics::structure::{MoverSpec, SceneRef};
    use rustc_hash::FxHashSet;

    /// A fixed slab with `k` movers rolling over it, mover `i` by the
    /// rotation `links[i % links.len()]` (neighbour indices about its
    /// pivot), and the units of their moments about gravity.
    fn slab_with_movers(k: usize, links: &[(usize, usize, Route)]) -> (Structure, Vec<usize>) {
        let l = FccLattice;
        let mut config = Configuration::default();
        let mut fixed = FxHashSet::default();
        let mut id: ModuleId = 0;
        let mut pivots = Vec::new();
        for x in 0..12 {
            for y in 0..12 {
                id += 1;
                config.insert(id, Cell::new(2 * x, 2 * y, 0)).unwrap();
                fixed.insert(id);
                pivots.push((id, Cell::new(2 * x, 2 * y, 0)));
            }
        }
        let mut movers: Vec<MoverSpec> = Vec::new();
        let mut exclude = FxHashSet::default();
        for (i, &(pid, pc)) in pivots.iter().take(k).enumerate() {
            let (f, t, route) = links[i % links.len()];
            id += 1;
            exclude.insert(id);
            movers.push((
                id,
                Some(pid),
                Motion::Rotate {
                    from: l.neighbour(pc, f),
                    to: l.neighbour(pc, t),
                    pivot: pc,
                    route,
                },
            ));
        }
        let scene = SceneRef {
            lattice: &l,
            ground: None,
            config: &config,
            fixed: &fixed,
            exclude: &exclude,
            latched: &|_, _| true,
        };
        let s = Structure::build(&scene, &movers);
        let all = (0..s.hanging.len()).collect();
        (s, all)
    }

    /// A rotation link about a pivot: neighbour indices `(from, to)` whose
    /// directions have the dot product `cos` (0.5: 60°, 0: 90°).
    fn link(cos: f64, route: Route) -> (usize, usize, Route) {
        let d = crate::lattice::fcc_directions();
        (0..12)
            .flat_map(|f| (0..12).map(move |t| (f, t)))
            .find(|&(f, t)| (d[f].dot(d[t]) - cos).abs() < 1e-9)
            .map(|(f, t)| (f, t, route))
            .unwrap()
    }

    fn moment(s: &Structure, h: usize, c: DVec3) -> DVec3 {
        (c - s.bodies[s.hanging[h].pivot].centre).cross(s.gravity)
    }

    /// Every sample's and tangent point's stacked moment change, rebuilt
    /// from the units by plain least squares over the group's movers
    /// (not the units' own projection): the largest misfit, relative.
    fn misfit(s: &Structure, units: &[Unit], reference: &dyn Fn(usize) -> DVec3) -> f64 {
        let mut worst: f64 = 0.0;
        for g in 0..s.groups() {
            let us: Vec<&Unit> = units.iter().filter(|u| u.group == g).collect();
            let members: Vec<usize> = (0..s.hanging.len())
                .filter(|&h| s.hanging[h].group == g)
                .collect();
            let n = s.hanging[members[0]].path.len();
            for k in 0..2 * n - 1 {
                let change = |h: usize| {
                    let hg = &s.hanging[h];
                    let c = if k < n { hg.path[k] } else { hg.hull[k - n] };
                    moment(s, h, c) - reference(h)
                };
                // Normal equations of the units' columns.
                let m = us.len();
                let a = nalgebra::DMatrix::from_fn(m, m, |i, j| {
                    members
                        .iter()
                        .map(|&h| {
                            let at = |u: &Unit| u.moments.iter().find(|x| x.0 == h).unwrap().1;
                            at(us[i]).dot(at(us[j]))
                        })
                        .sum::<f64>()
                });
                let rhs = nalgebra::DVector::from_fn(m, |i, _| us[i].coordinate(change));
                let c = a.lu().solve(&rhs).unwrap_or(nalgebra::DVector::zeros(m));
                let mut err = 0.0;
                let mut len = 0.0;
                for &h in &members {
                    let mut fit = DVec3::ZERO;
                    for (i, u) in us.iter().enumerate() {
                        fit += c[i] * u.moments.iter().find(|x| x.0 == h).unwrap().1;
                    }
                    err += (change(h) - fit).length_squared();
                    len += change(h).length_squared();
                }
                worst = worst.max(err.sqrt() / len.sqrt().max(1.0));
            }
        }
        worst
    }

    #[test]
    fn one_group_of_many_movers_needs_at_most_three_units_and_rebuilds_every_pose() {
        // 40 movers on one octagonal 90° link and 40 on a 60° one
        // (hexagonal route): two groups.
        let (ninety, sixty) = (link(0.0, Route::Octagonal), link(0.5, Route::Hexagonal));
        for links in [vec![ninety], vec![sixty], vec![ninety, sixty]] {
            let (s, movers) = slab_with_movers(80, &links);
            let reference = |h: usize| moment(&s, h, s.hanging[h].path[0]);
            let us = units(&s, &movers, &|h, c| moment(&s, h, c), &reference).unwrap();
            let groups = s.groups();
            assert_eq!(groups, links.len());
            for g in 0..groups {
                let n = us.iter().filter(|u| u.group == g).count();
                assert!((1..=3).contains(&n), "group {g}: {n} units");
            }
            // Orthonormal.
            for (i, a) in us.iter().enumerate() {
                for (j, b) in us.iter().enumerate() {
                    let d: f64 = if a.group != b.group {
                        0.0
                    } else {
                        a.moments
                            .iter()
                            .zip(&b.moments)
                            .map(|(x, y)| x.1.dot(y.1))
                            .sum()
                    };
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((d - want).abs() < 1e-12, "{i}·{j} = {d}");
                }
            }
            assert!(misfit(&s, &us, &reference) < 1e-12);
        }
    }

    #[test]
    fn a_path_off_its_arcs_gets_more_units_and_is_still_rebuilt() {
        // Bend one mover's path off its circle: its group's moments leave
        // the three dimensions of the arcs, and the basis grows to hold
        // every point again; a basis cut short would not.
        let (mut s, movers) = slab_with_movers(6, &[link(0.0, Route::Octagonal)]);
        let before = {
            let reference = |h: usize| moment(&s, h, s.hanging[h].path[0]);
            units(&s, &movers, &|h, c| moment(&s, h, c), &reference)
                .unwrap()
                .len()
        };
        for (k, c) in s.hanging[2].path.iter_mut().enumerate() {
            *c += DVec3::new(0.01 * (k as f64).sin(), 0.02 * (k * k) as f64 * 1e-3, 0.0);
        }
        let reference = |h: usize| moment(&s, h, s.hanging[h].path[0]);
        let us = units(&s, &movers, &|h, c| moment(&s, h, c), &reference).unwrap();
        assert!(us.len() > before, "{} > {before}", us.len());
        assert!(misfit(&s, &us, &reference) < 1e-12);
        let mut short = us.clone();
        short.pop();
        assert!(misfit(&s, &short, &reference) > 1e-6);
    }

    #[test]
    fn movers_that_never_change_their_moment_have_no_unit_and_a_non_finite_moment_no_basis() {
        let (s, movers) = slab_with_movers(3, &[link(0.0, Route::Octagonal)]);
        let us = units(&s, &movers, &|_, _| DVec3::ZERO, &|_| DVec3::ZERO);
        assert_eq!(us, Some(vec![]));
        for bad in [f64::NAN, f64::INFINITY] {
            let m = move |_: usize, _: DVec3| DVec3::new(0.0, bad, 0.0);
            assert_eq!(units(&s, &movers, &m, &|_| DVec3::ZERO), None);
        }
    }
}
