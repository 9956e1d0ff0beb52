//! Seed 004's cubic atoms (crystalline / telecube style): the body, the
//! arms, and the kinematics of one parallel step of atom operations.
//!
//! An atom's body is the unit cube centred on its position (integer, in
//! atom lengths). Each face can expand by one atom length ([`ARM`]): the arm
//! is the box of the whole face's cross-section between the body and the
//! face plate. Two attached faces touch plate to plate, so the centres of
//! attached atoms `a`, `b` across `a`'s face `f` differ by
//! `f.dir() · (1 + ext_a(f) + ext_b(−f))`.
//!
//! In one parallel step every arm that changes length does so linearly in
//! the step parameter `s ∈ [0, 1]`. The attached faces make the robot a
//! tree (or graph) of rigid links whose lengths are linear in `s`, so every
//! atom translates linearly from its start to its end position, and every
//! face of every body or arm moves linearly too: the overlap of two such
//! boxes over the step is an intersection of linear inequalities in `s`,
//! decided exactly ([`first_overlap`]).

use crate::lattice::{Cell, Face};
use std::collections::VecDeque;

/// An arm's full extension, in atom lengths.
pub const ARM: i32 = 1;

/// Which faces of an atom are expanded, in [`Face`] order.
pub type Faces = [bool; 6];

/// The centre offset from `a` to an atom `b` attached on `a`'s face `f`.
pub fn bond_offset(f: Face, ext_a: &Faces, ext_b: &Faces) -> Cell {
    let len = 1 + ARM * (ext_a[f.index()] as i32 + ext_b[f.opposite().index()] as i32);
    let d = f.dir();
    Cell::new(d.x * len, d.y * len, d.z * len)
}

/// Whether atoms at `pa`, `pb` touch face to face, and through which of
/// `a`'s faces.
pub fn contact_face(pa: Cell, ea: &Faces, pb: Cell, eb: &Faces) -> Option<Face> {
    let d = pb - pa;
    let axis = [d.x, d.y, d.z];
    let mut nonzero = (0..3).filter(|&i| axis[i] != 0);
    let (Some(i), None) = (nonzero.next(), nonzero.next()) else {
        return None;
    };
    let f = Face::of(i, axis[i].signum());
    (bond_offset(f, ea, eb) == d).then_some(f)
}

/// An atom's body and its extended arms as moving boxes (at most 1 + 6),
/// inline: collision searches build them for every atom of every step.
pub type AtomBoxes = arrayvec::ArrayVec<(Option<Face>, MovingBox), 7>;

/// An axis-aligned box whose bounds move linearly over `s ∈ [0, 1]`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MovingBox {
    pub lo0: [f64; 3],
    pub hi0: [f64; 3],
    pub lo1: [f64; 3],
    pub hi1: [f64; 3],
}

impl MovingBox {
    pub fn at(&self, s: f64) -> ([f64; 3], [f64; 3]) {
        let l = |a: f64, b: f64| a + s * (b - a);
        (
            std::array::from_fn(|i| l(self.lo0[i], self.lo1[i])),
            std::array::from_fn(|i| l(self.hi0[i], self.hi1[i])),
        )
    }

    /// The smallest box holding the whole sweep (bounds move linearly,
    /// so their extremes are at `s = 0` or `s = 1`).
    pub fn hull(&self) -> ([f64; 3], [f64; 3]) {
        (
            std::array::from_fn(|i| self.lo0[i].min(self.lo1[i])),
            std::array::from_fn(|i| self.hi0[i].max(self.hi1[i])),
        )
    }
}

/// The smallest box holding every one of an atom's moving boxes over the
/// whole step.
pub fn sweep_hull(boxes: &[(Option<Face>, MovingBox)]) -> ([f64; 3], [f64; 3]) {
    boxes.iter().fold(
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(lo, hi), (_, b)| {
            let (l, h) = b.hull();
            (
                std::array::from_fn(|i| lo[i].min(l[i])),
                std::array::from_fn(|i| hi[i].max(h[i])),
            )
        },
    )
}

/// Whether two atoms whose sweeps lie in the boxes `a` and `b`
/// ([`sweep_hull`]) overlap by at most `eps` along some axis: then none of
/// their moving boxes overlap by more, at any `s`, and [`first_overlap`]
/// clears every pair. A tolerance that is no number, or negative, never
/// screens a pair (`first_overlap` rejects it).
pub fn sweeps_apart(a: &([f64; 3], [f64; 3]), b: &([f64; 3], [f64; 3]), eps: f64) -> bool {
    let ((la, ha), (lb, hb)) = (a, b);
    eps.is_finite() && eps >= 0.0 && (0..3).any(|i| ha[i].min(hb[i]) - la[i].max(lb[i]) <= eps)
}

/// The boxes of one atom over a step: the body, then one per face that is
/// expanded at the start or at the end (arms of length 0 are left out).
pub fn atom_boxes(p0: Cell, p1: Cell, e0: &Faces, e1: &Faces) -> AtomBoxes {
    let c0 = [p0.x as f64, p0.y as f64, p0.z as f64];
    let c1 = [p1.x as f64, p1.y as f64, p1.z as f64];
    let body = |c: [f64; 3]| {
        (
            std::array::from_fn(|i| c[i] - 0.5),
            std::array::from_fn(|i| c[i] + 0.5),
        )
    };
    let (lo0, hi0) = body(c0);
    let (lo1, hi1) = body(c1);
    let mut out = AtomBoxes::new();
    out.push((None, MovingBox { lo0, hi0, lo1, hi1 }));
    for f in Face::ALL {
        let (a, b) = (e0[f.index()], e1[f.index()]);
        if !a && !b {
            continue;
        }
        let arm = |c: [f64; 3], ext: bool| -> ([f64; 3], [f64; 3]) {
            let (mut lo, mut hi) = body(c);
            let len = if ext { ARM as f64 } else { 0.0 };
            let i = f.axis();
            if f.sign() > 0 {
                lo[i] = hi[i];
                hi[i] += len;
            } else {
                hi[i] = lo[i];
                lo[i] -= len;
            }
            (lo, hi)
        };
        let (lo0, hi0) = arm(c0, a);
        let (lo1, hi1) = arm(c1, b);
        out.push((Some(f), MovingBox { lo0, hi0, lo1, hi1 }));
    }
    out
}

/// Where two moving boxes interpenetrate by more than `eps` during the
/// step: the sweep parameter `s` (the middle of the interval of overlap)
/// and the depth there. Exact: the overlap along each axis is two linear
/// functions of `s`, so the set of `s` where every one exceeds `eps` is an
/// interval found in closed form, with no sampling.
pub fn first_overlap(a: &MovingBox, b: &MovingBox, eps: f64) -> Option<(f64, f64)> {
    if !(eps.is_finite() && eps >= 0.0) {
        // A tolerance that is no number cannot clear anything.
        return Some((0.0, f64::NAN));
    }
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    // Overlap functions g(s) = c0 + s (c1 − c0) that must all exceed eps.
    let gs: [(f64, f64); 6] = std::array::from_fn(|k| {
        let i = k / 2;
        if k % 2 == 0 {
            (a.hi0[i] - b.lo0[i], a.hi1[i] - b.lo1[i])
        } else {
            (b.hi0[i] - a.lo0[i], b.hi1[i] - a.lo1[i])
        }
    });
    for &(c0, c1) in &gs {
        if !(c0.is_finite() && c1.is_finite()) {
            return Some((0.0, f64::NAN));
        }
        let slope = c1 - c0;
        if slope == 0.0 {
            if c0 <= eps {
                return None;
            }
            continue;
        }
        let root = (eps - c0) / slope;
        if slope > 0.0 {
            lo = lo.max(root);
        } else {
            hi = hi.min(root);
        }
        if lo > hi {
            return None;
        }
    }
    let s = 0.5 * (lo + hi);
    let depth = gs
        .iter()
        .map(|&(c0, c1)| c0 + s * (c1 - c0))
        .fold(f64::INFINITY, f64::min);
    (depth > eps).then_some((s, depth))
}

/// Whether the box `[lo, hi]` lies within the union of boxes `s` and `t`
/// (each `(lo, hi)`), up to `eps`. Exact: the part of the box outside `s`
/// is cut into at most six boxes, each of which must lie in `t`.
pub fn within_union(
    lo: [f64; 3],
    hi: [f64; 3],
    s: ([f64; 3], [f64; 3]),
    t: ([f64; 3], [f64; 3]),
    eps: f64,
) -> bool {
    let inside = |lo: [f64; 3], hi: [f64; 3], b: ([f64; 3], [f64; 3])| {
        (0..3).all(|i| lo[i] >= b.0[i] - eps && hi[i] <= b.1[i] + eps)
    };
    if inside(lo, hi, s) || inside(lo, hi, t) {
        return true;
    }
    let (mut lo, mut hi) = (lo, hi);
    for i in 0..3 {
        if hi[i] - lo[i] <= eps {
            return true;
        }
        // The slab below s along axis i.
        if lo[i] < s.0[i] - eps {
            let mut h = hi;
            h[i] = h[i].min(s.0[i]);
            if !inside(lo, h, t) {
                return false;
            }
            lo[i] = s.0[i].min(hi[i]);
        }
        if hi[i] > s.1[i] + eps {
            let mut l = lo;
            l[i] = l[i].max(s.1[i]);
            if !inside(l, hi, t) {
                return false;
            }
            hi[i] = s.1[i].max(lo[i]);
        }
    }
    true
}

/// A bond between two atoms: `a`'s face `face` is attached to `b`'s
/// opposite face.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Bond {
    pub a: usize,
    pub face: Face,
    pub b: usize,
}

/// Two bonds in a cycle whose arms disagree on where an atom ends up.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Conflict {
    pub atoms: (usize, usize),
    pub expected: Cell,
    pub found: Cell,
}

/// The end positions of one parallel step. `start`: positions at the
/// start; `ext1`: faces at the end; `bonds`: the attachments held through
/// the step; `anchors`: atoms that keep their position (the world frame).
/// Each connected component of the bond graph is laid out from its first
/// anchor (or, without one, from its lowest-numbered atom, which then
/// stays put).
pub fn solve_step(
    start: &[Cell],
    ext1: &[Faces],
    bonds: &[Bond],
    anchors: &[usize],
) -> Result<Vec<Cell>, Conflict> {
    let n = start.len();
    let mut adj: Vec<Vec<(usize, Face)>> = vec![Vec::new(); n];
    for b in bonds {
        adj[b.a].push((b.b, b.face));
        adj[b.b].push((b.a, b.face.opposite()));
    }
    let mut end: Vec<Option<Cell>> = vec![None; n];
    let mut roots: Vec<usize> = anchors.to_vec();
    roots.extend(0..n);
    let mut queue = VecDeque::new();
    for r in roots {
        if end[r].is_some() {
            // An anchor laid out from another anchor must not have moved.
            if anchors.contains(&r) && end[r] != Some(start[r]) {
                return Err(Conflict {
                    atoms: (r, r),
                    expected: start[r],
                    found: end[r].unwrap_or(start[r]),
                });
            }
            continue;
        }
        end[r] = Some(start[r]);
        queue.push_back(r);
        while let Some(u) = queue.pop_front() {
            let pu = end[u].expect("laid out");
            for &(v, f) in &adj[u] {
                let want = pu + bond_offset(f, &ext1[u], &ext1[v]);
                match end[v] {
                    None => {
                        end[v] = Some(want);
                        queue.push_back(v);
                    }
                    Some(p) if p != want => {
                        return Err(Conflict {
                            atoms: (u, v),
                            expected: want,
                            found: p,
                        });
                    }
                    Some(_) => {}
                }
            }
        }
    }
    Ok(end
        .into_iter()
        .map(|p| p.expect("every atom laid out"))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atoms_whose_sweeps_are_apart_have_no_overlapping_boxes_by_enumeration() {
        // Every pair of one atom moving one unit along x with one arm out
        // (or none), against a still atom with one arm out, on a 4³ grid of
        // offsets: wherever the screen calls them apart, no box pair
        // overlaps by more than eps at any s (checked box by box with
        // `first_overlap`); both cases occur.
        let arms: Vec<Faces> = std::iter::once([false; 6])
            .chain(Face::ALL.iter().map(|f| {
                let mut e = [false; 6];
                e[f.index()] = true;
                e
            }))
            .collect();
        let (mut apart, mut overlapping) = (0, 0);
        for ea in &arms {
            let a = atom_boxes(Cell::new(0, 0, 0), Cell::new(1, 0, 0), ea, ea);
            for eb in &arms {
                for (x, y, z) in
                    (-2..2).flat_map(|x| (-2..2).flat_map(move |y| (-2..2).map(move |z| (x, y, z))))
                {
                    let b = atom_boxes(Cell::new(x, y, z), Cell::new(x, y, z), eb, eb);
                    let any = a
                        .iter()
                        .any(|(_, p)| b.iter().any(|(_, q)| first_overlap(p, q, 1e-9).is_some()));
                    let screened = sweeps_apart(&sweep_hull(&a), &sweep_hull(&b), 1e-9);
                    assert!(!(screened && any), "{ea:?} {eb:?} ({x}, {y}, {z})");
                    apart += usize::from(screened);
                    overlapping += usize::from(any);
                }
            }
        }
        assert!(
            apart > 0 && overlapping > 0,
            "{apart} apart, {overlapping} overlapping"
        );
        let h = sweep_hull(&atom_boxes(
            Cell::new(0, 0, 0),
            Cell::new(0, 0, 0),
            &arms[0],
            &arms[0],
        ));
        let far = ([9.0; 3], [10.0; 3]);
        assert!(sweeps_apart(&h, &far, 0.0));
        for eps in [f64::NAN, f64::INFINITY, -1.0] {
            assert!(!sweeps_apart(&h, &far, eps), "{eps}");
        }
    }

    fn still(c: [f64; 3], h: f64) -> MovingBox {
        let lo = [c[0] - h, c[1] - h, c[2] - h];
        let hi = [c[0] + h, c[1] + h, c[2] + h];
        MovingBox {
            lo0: lo,
            hi0: hi,
            lo1: lo,
            hi1: hi,
        }
    }

    #[test]
    fn touching_cubes_do_not_overlap_but_penetrating_ones_do() {
        let a = still([0.0, 0.0, 0.0], 0.5);
        assert!(first_overlap(&a, &still([1.0, 0.0, 0.0], 0.5), 1e-6).is_none());
        let (_, d) = first_overlap(&a, &still([0.9, 0.0, 0.0], 0.5), 1e-6).unwrap();
        assert!((d - 0.1).abs() < 1e-12);
    }

    #[test]
    fn a_box_passing_through_another_is_caught_mid_sweep() {
        // Starts left of b, ends right of it: both ends are clear, the
        // middle is not (no sampling can miss it).
        let mut a = still([-2.0, 0.0, 0.0], 0.5);
        a.lo1 = [1.5, -0.5, -0.5];
        a.hi1 = [2.5, 0.5, 0.5];
        let b = still([0.0, 0.0, 0.0], 0.5);
        let (s, d) = first_overlap(&a, &b, 1e-6).unwrap();
        assert!((s - 0.5).abs() < 1e-9, "s = {s}");
        assert!((d - 1.0).abs() < 1e-9);
        // Mirror image in x: the low x corner is the mirrored high one,
        // y and z stay as they are. Same instant, same depth.
        let lo = |l: [f64; 3], h: [f64; 3]| [-h[0], l[1], l[2]];
        let hi = |l: [f64; 3], h: [f64; 3]| [-l[0], h[1], h[2]];
        let am = MovingBox {
            lo0: lo(a.lo0, a.hi0),
            hi0: hi(a.lo0, a.hi0),
            lo1: lo(a.lo1, a.hi1),
            hi1: hi(a.lo1, a.hi1),
        };
        let (sm, dm) = first_overlap(&am, &b, 1e-6).unwrap();
        assert!((sm - s).abs() < 1e-9 && (dm - d).abs() < 1e-9, "{sm} {dm}");
    }

    #[test]
    fn non_finite_inputs_never_pass_as_clear() {
        let mut a = still([0.0, 0.0, 0.0], 0.5);
        let b = still([5.0, 0.0, 0.0], 0.5);
        assert!(first_overlap(&a, &b, f64::NAN).is_some());
        a.hi1[0] = f64::INFINITY;
        assert!(first_overlap(&a, &b, 1e-6).is_some());
    }

    #[test]
    fn an_expanding_arm_pushes_its_attached_neighbour_one_unit() {
        let start = [Cell::new(0, 0, 0), Cell::new(1, 0, 0)];
        let mut e = [[false; 6]; 2];
        e[0][Face::PosX.index()] = true;
        let bonds = [Bond {
            a: 0,
            face: Face::PosX,
            b: 1,
        }];
        let end = solve_step(&start, &e, &bonds, &[0]).unwrap();
        assert_eq!(end, vec![Cell::new(0, 0, 0), Cell::new(2, 0, 0)]);
        // Anchored on the other atom, the first one is pushed instead.
        let end = solve_step(&start, &e, &bonds, &[1]).unwrap();
        assert_eq!(end, vec![Cell::new(-1, 0, 0), Cell::new(1, 0, 0)]);
    }

    #[test]
    fn arms_that_disagree_around_a_cycle_are_a_conflict() {
        // A 2×2 square of contracted atoms; one arm expands: the square
        // cannot stay closed.
        let start = [
            Cell::new(0, 0, 0),
            Cell::new(1, 0, 0),
            Cell::new(0, 1, 0),
            Cell::new(1, 1, 0),
        ];
        let bond = |a, face, b| Bond { a, face, b };
        let bonds = [
            bond(0, Face::PosX, 1),
            bond(0, Face::PosY, 2),
            bond(1, Face::PosY, 3),
            bond(2, Face::PosX, 3),
        ];
        let mut e = [[false; 6]; 4];
        assert!(solve_step(&start, &e, &bonds, &[0]).is_ok());
        e[0][Face::PosX.index()] = true;
        assert!(solve_step(&start, &e, &bonds, &[0]).is_err());
        // Both x-arms of the square expand together: consistent.
        e[2][Face::PosX.index()] = true;
        let end = solve_step(&start, &e, &bonds, &[0]).unwrap();
        assert_eq!(end[3], Cell::new(2, 1, 0));
    }

    #[test]
    fn union_of_boxes_is_exact_for_an_l_shape() {
        let s = ([0.0, 0.0, 0.0], [4.0, 2.0, 1.0]);
        let t = ([0.0, 0.0, 0.0], [2.0, 4.0, 1.0]);
        let within = |lo, hi| within_union(lo, hi, s, t, 1e-9);
        assert!(within([1.0, 1.0, 0.0], [2.0, 3.0, 1.0]));
        assert!(within([0.0, 1.0, 0.0], [3.0, 2.0, 1.0]));
        // The corner (2..4, 2..4) is in neither box.
        assert!(!within([1.5, 1.5, 0.0], [2.5, 2.5, 1.0]));
        assert!(!within([0.0, 0.0, 0.0], [1.0, 1.0, 1.5]));
    }

    #[test]
    fn contact_face_needs_the_plates_to_meet() {
        let mut ea = [false; 6];
        let eb = [false; 6];
        let (a, b) = (Cell::new(0, 0, 0), Cell::new(2, 0, 0));
        assert_eq!(contact_face(a, &ea, b, &eb), None);
        ea[Face::PosX.index()] = true;
        assert_eq!(contact_face(a, &ea, b, &eb), Some(Face::PosX));
        assert_eq!(contact_face(b, &eb, a, &ea), Some(Face::NegX));
        assert_eq!(contact_face(a, &ea, Cell::new(2, 1, 0), &eb), None);
    }
}
