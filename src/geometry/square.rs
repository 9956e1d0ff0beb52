//! Exact sweeps of the square lattice's bodies (SPEC §5): every module is
//! the unit square (side d) centred on its cell, axis-aligned at all times.
//!
//! Paths, as the sliding-square model moves a module:
//!
//! * a straight slide translates the square by one cell, `s ∈ [0, 1]`
//!   uniform;
//! * a corner (diagonal) move is the convex transition around its pivot: it
//!   translates to the free adjacent cell (the corner not held by the
//!   pivot) for `s ∈ [0, ½]`, then on to the target for `s ∈ [½, 1]` — an
//!   L-shaped path that keeps the mover's face on the pivot throughout.
//!
//! Two axis-aligned unit squares whose centres differ by `r` overlap by
//! `min(1 − |r_x|, 1 − |r_y|)` (the penetration depth, when positive). Both
//! paths are piecewise linear in `s`, so `r(s)` is too, and the depth is the
//! minimum of piecewise-linear functions: its maximum on each linear piece is
//! at an end of the piece, where `r_x` or `r_y` crosses 0, or where
//! `|r_x| = |r_y|`. Evaluating those points gives the exact deepest
//! penetration — no sampling, no tunnelling, no compiled tables (so
//! `SweepInput::exact` changes nothing here).
//!
//! Contacts reported: a `Collision` wherever the depth exceeds ε; a
//! `SlidingContact` where a face slides along another module's face over a
//! positive length of the path (|r| = 1 on one axis, overlap on the other,
//! relative motion along it), except with the move's own wall — the pivot
//! and the support cells the lattice requires (`move_requirements`) — which
//! is the contact the sliding-square model moves on. Point contacts at
//! corners and contacts without relative motion (a column of movers sliding
//! together) are not reported.

use super::{Contact, ContactKind, SweepInput, SweepModel};
use crate::lattice::config::ModuleId;
use crate::lattice::{Cell, Motion};
use glam::{DVec2, DVec3};

/// The square lattice's sweep model.
#[derive(Copy, Clone, Debug, Default)]
pub struct SquareSweep;

/// A piecewise-linear path of a square's centre: `(s, position)` knots.
#[derive(Clone, Debug)]
struct Path {
    knots: Vec<(f64, DVec2)>,
}

fn v(c: Cell) -> DVec2 {
    DVec2::new(c.x as f64, c.y as f64)
}

impl Path {
    fn fixed(c: Cell) -> Path {
        Path {
            knots: vec![(0.0, v(c)), (1.0, v(c))],
        }
    }

    /// The mover's path, or `None` for motions this model does not sweep.
    fn of(m: &Motion) -> Option<Path> {
        let Motion::Slide { from, to, pivot } = *m else {
            return None;
        };
        let d = to - from;
        if d.x.abs() == 1 && d.y.abs() == 1 {
            let (a, b) = (Cell::xy(to.x, from.y), Cell::xy(from.x, to.y));
            let via = if pivot == Some(a) { b } else { a };
            return Some(Path {
                knots: vec![(0.0, v(from)), (0.5, v(via)), (1.0, v(to))],
            });
        }
        Some(Path {
            knots: vec![(0.0, v(from)), (1.0, v(to))],
        })
    }

    fn at(&self, s: f64) -> DVec2 {
        for w in self.knots.windows(2) {
            let ((s0, p0), (s1, p1)) = (w[0], w[1]);
            if s <= s1 {
                return p0 + (p1 - p0) * ((s - s0) / (s1 - s0));
            }
        }
        self.knots.last().expect("paths have knots").1
    }

    fn breaks(&self) -> impl Iterator<Item = f64> + '_ {
        self.knots.iter().map(|k| k.0)
    }
}

/// What the sweep of one pair found.
struct PairResult {
    /// Deepest penetration and where.
    depth: f64,
    s_depth: f64,
    /// A sliding face contact, if any (at this s).
    sliding: Option<f64>,
}

fn penetration(r: DVec2) -> f64 {
    (1.0 - r.x.abs()).min(1.0 - r.y.abs())
}

/// Exact sweep of square `b` relative to square `a`.
fn sweep_pair(a: &Path, b: &Path, eps: f64) -> PairResult {
    let mut knots: Vec<f64> = a.breaks().chain(b.breaks()).collect();
    knots.sort_by(f64::total_cmp);
    knots.dedup();
    let rel = |s: f64| b.at(s) - a.at(s);
    let mut out = PairResult {
        depth: f64::NEG_INFINITY,
        s_depth: 0.0,
        sliding: None,
    };
    for w in knots.windows(2) {
        let (s0, s1) = (w[0], w[1]);
        if s1 - s0 <= 0.0 {
            continue;
        }
        let (r0, r1) = (rel(s0), rel(s1));
        let dr = r1 - r0;
        // Points where one of the piecewise-linear pieces of the depth bends.
        let mut cand = vec![s0, s1];
        let mut root = |num: f64, den: f64| {
            if den.abs() > 1e-15 {
                let u = num / den;
                if (0.0..=1.0).contains(&u) {
                    cand.push(s0 + u * (s1 - s0));
                }
            }
        };
        root(-r0.x, dr.x);
        root(-r0.y, dr.y);
        root(r0.y - r0.x, dr.x - dr.y);
        root(-(r0.x + r0.y), dr.x + dr.y);
        for s in cand {
            let d = penetration(rel(s));
            if d > out.depth {
                out.depth = d;
                out.s_depth = s;
            }
        }
        // Face sliding: one axis pinned at distance 1, overlap and relative
        // motion along the other.
        for (pinned, dpinned, (q0, dq)) in [(r0.x, dr.x, (r0.y, dr.y)), (r0.y, dr.y, (r0.x, dr.x))]
        {
            let rubbing =
                dq.abs() > eps && dpinned.abs() <= eps && (pinned.abs() - 1.0).abs() <= eps;
            if out.sliding.is_none() && rubbing {
                // Largest overlap along the free axis on this piece.
                let q1 = q0 + dq;
                let mut best = (1.0 - q0.abs(), s0);
                if 1.0 - q1.abs() > best.0 {
                    best = (1.0 - q1.abs(), s1);
                }
                if q0 * q1 < 0.0 {
                    best = (1.0, s0 + (-q0 / dq) * (s1 - s0));
                }
                if best.0 > eps {
                    out.sliding = Some(best.1);
                }
            }
        }
    }
    out
}

fn contact(
    kind: ContactKind,
    mover: ModuleId,
    other: ModuleId,
    s: f64,
    depth: f64,
    a: &Path,
    b: &Path,
) -> Contact {
    let (pa, pb) = (a.at(s), b.at(s));
    // Witnesses: the points of each square nearest the other's centre.
    let clamp = |p: DVec2, q: DVec2| p + (q - p).clamp(DVec2::splat(-0.5), DVec2::splat(0.5));
    let (wa, wb) = (clamp(pa, pb), clamp(pb, pa));
    Contact {
        kind,
        s,
        mover,
        other,
        depth,
        witness_mover: DVec3::new(wa.x, wa.y, 0.0),
        witness_other: DVec3::new(wb.x, wb.y, 0.0),
    }
}

impl SweepModel for SquareSweep {
    fn name(&self) -> &'static str {
        "square-boxes"
    }

    fn check_step(&self, input: &SweepInput<'_>) -> Vec<Contact> {
        let eps = input.epsilon.get();
        let movers: Vec<(ModuleId, &Motion, Path)> = input
            .moves
            .iter()
            .filter_map(|(id, _, m)| Path::of(m).map(|p| (*id, m, p)))
            .collect();
        let mut out = Vec::new();
        let mut report = |r: PairResult,
                          mover: ModuleId,
                          other: ModuleId,
                          expected: bool,
                          a: &Path,
                          b: &Path| {
            if r.depth > eps {
                out.push(contact(
                    ContactKind::Collision,
                    mover,
                    other,
                    r.s_depth,
                    r.depth,
                    a,
                    b,
                ));
            } else if let (Some(s), false) = (r.sliding, expected) {
                out.push(contact(
                    ContactKind::SlidingContact,
                    mover,
                    other,
                    s,
                    0.0,
                    a,
                    b,
                ));
            }
        };
        for (id, motion, path) in &movers {
            let from = motion.from();
            let wall: Vec<Cell> = input
                .lattice
                .move_requirements(motion)
                .map(|r| r.supports)
                .unwrap_or_default();
            let pivot_cell = match motion {
                Motion::Slide { pivot, .. } => *pivot,
                _ => None,
            };
            // Every square the path can touch has its centre within 2 cells.
            for dx in -2..=2 {
                for dy in -2..=2 {
                    let c = Cell::xy(from.x + dx, from.y + dy);
                    let Some(other) = input.config.at(c) else {
                        continue;
                    };
                    if other == *id || input.moving.contains(&other) {
                        continue;
                    }
                    let expected = Some(c) == pivot_cell || wall.contains(&c);
                    let fixed = Path::fixed(c);
                    report(
                        sweep_pair(path, &fixed, eps),
                        *id,
                        other,
                        expected,
                        path,
                        &fixed,
                    );
                }
            }
        }
        for (i, (a_id, _, a)) in movers.iter().enumerate() {
            for (b_id, _, b) in &movers[i + 1..] {
                let near = (a.at(0.0) - b.at(0.0)).abs().max_element() <= 4.0;
                if near {
                    report(sweep_pair(a, b, eps), *a_id, *b_id, false, a, b);
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::config::ModuleId;
    use crate::lattice::{Configuration, SquareLattice};
    use rustc_hash::FxHashSet;

    type Xy = (i32, i32);

    /// Sweeps `moves` (module, from, to, pivot cell) among static modules.
    fn run(statics: &[Xy], moves: &[(ModuleId, Xy, Xy, Option<Xy>)]) -> Vec<Contact> {
        let mut config = Configuration::new();
        for (k, &(x, y)) in statics.iter().enumerate() {
            config.insert(100 + k as ModuleId, Cell::xy(x, y)).unwrap();
        }
        let mut list = Vec::new();
        let mut moving = FxHashSet::default();
        for &(id, f, t, p) in moves {
            config.insert(id, Cell::xy(f.0, f.1)).unwrap();
            let pivot = p.map(|(x, y)| Cell::xy(x, y));
            let pid = pivot.and_then(|c| config.at(c));
            list.push((
                id,
                pid,
                Motion::Slide {
                    from: Cell::xy(f.0, f.1),
                    to: Cell::xy(t.0, t.1),
                    pivot,
                },
            ));
            moving.insert(id);
        }
        let input = SweepInput {
            lattice: &SquareLattice,
            config: &config,
            moves: &list,
            moving: &moving,
            epsilon: crate::geometry::Tolerance::DEFAULT,
            exact: true,
        };
        SquareSweep.check_step(&input)
    }

    #[test]
    fn a_slide_along_its_wall_touches_only_the_wall() {
        // Module 1 slides West on top of a row: the wall is expected contact.
        let c = run(
            &[(1, 1), (2, 1), (3, 1)],
            &[(1, (3, 2), (2, 2), Some((3, 1)))],
        );
        assert!(c.is_empty(), "{c:?}");
    }

    #[test]
    fn a_module_in_the_target_is_penetrated_fully_at_the_end() {
        let c = run(
            &[(1, 1), (2, 1), (2, 2)],
            &[(1, (1, 2), (2, 2), Some((1, 1)))],
        );
        assert_eq!(c.len(), 1);
        assert_eq!(c[0].kind, ContactKind::Collision);
        assert!(
            (c[0].depth - 1.0).abs() < 1e-12 && (c[0].s - 1.0).abs() < 1e-12,
            "{c:?}"
        );
        assert_eq!(c[0].other, 102);
    }

    #[test]
    fn a_corner_move_passes_through_the_free_corner() {
        // Around pivot (2,1): from (2,2) over (1,2) down to (1,1).
        let ok = run(&[(2, 1)], &[(1, (2, 2), (1, 1), Some((2, 1)))]);
        assert!(ok.is_empty(), "{ok:?}");
        // A module in the free corner is hit, deepest at s = ½.
        let hit = run(&[(2, 1), (1, 2)], &[(1, (2, 2), (1, 1), Some((2, 1)))]);
        assert_eq!(hit.len(), 1);
        assert_eq!(hit[0].kind, ContactKind::Collision);
        assert!((hit[0].s - 0.5).abs() < 1e-12 && (hit[0].depth - 1.0).abs() < 1e-12);
        // Modules beyond the path are touched at most at a corner point.
        let near = run(
            &[(2, 1), (0, 3), (3, 3)],
            &[(1, (2, 2), (1, 1), Some((2, 1)))],
        );
        assert!(near.is_empty(), "{near:?}");
    }

    #[test]
    fn a_slide_through_a_corridor_rubs_the_far_wall() {
        // Up a one-wide corridor: the wall on the left holds it, the right
        // wall is sliding contact.
        let c = run(
            &[(1, 1), (1, 2), (3, 1), (3, 2)],
            &[(1, (2, 1), (2, 2), Some((1, 1)))],
        );
        assert_eq!(c.len(), 2, "{c:?}");
        assert!(
            c.iter()
                .all(|c| c.kind == ContactKind::SlidingContact && c.depth == 0.0)
        );
        let others: FxHashSet<_> = c.iter().map(|c| c.other).collect();
        assert_eq!(others, [102, 103].into_iter().collect());
    }

    #[test]
    fn movers_are_swept_against_each_other() {
        // Head-on swap: full overlap at s = ½.
        let swap = run(&[], &[(1, (1, 1), (2, 1), None), (2, (2, 1), (1, 1), None)]);
        assert_eq!(swap.len(), 1);
        assert_eq!(swap[0].kind, ContactKind::Collision);
        assert!((swap[0].s - 0.5).abs() < 1e-12 && (swap[0].depth - 1.0).abs() < 1e-12);
        // A train moving together keeps its contact: nothing to report.
        let train = run(&[], &[(1, (2, 1), (3, 1), None), (2, (1, 1), (2, 1), None)]);
        assert!(train.is_empty(), "{train:?}");
        // Passing in adjacent rows, in opposite directions: they rub.
        let pass = run(&[], &[(1, (1, 1), (2, 1), None), (2, (2, 2), (1, 2), None)]);
        assert_eq!(pass.len(), 1);
        assert_eq!(pass[0].kind, ContactKind::SlidingContact);
        // A corner move cutting across a straight mover's path, exactly.
        let cross = run(
            &[(3, 1)],
            &[(1, (3, 2), (2, 1), Some((3, 1))), (2, (1, 2), (2, 2), None)],
        );
        assert!(
            cross.iter().any(|c| c.kind == ContactKind::Collision),
            "{cross:?}"
        );
    }
}
