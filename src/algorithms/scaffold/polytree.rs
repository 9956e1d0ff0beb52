//! Construction order (seed 000 §3.2.3–3.2.4, §3.3.2): the construction
//! polytree of tiles and, inside each tile, the order of its components.
//!
//! The paper's IBR / TIR / RGP / PGP / CR / TCF messages enforce exactly
//! these precedences in a distributed way; this generator is centralised,
//! so it states them as a precedence graph on components:
//!
//! * a tile root comes after the tips of all the tile's ingoing branches
//!   ("a tile can only begin its own construction once all of its ingoing
//!   branches are complete"), which yields the diagonal growth from the
//!   seed tile at minimal x, y;
//! * the first module of each horizontal branch comes right after the
//!   root, then the supports (§3.2.3 rules 1–2, §5.2.2: Opp branches as
//!   early as possible). X1 lies between S_Z and S_RZ, Y1 between S_Z and
//!   S_LZ: put in after both supports, it would have to enter a cell
//!   between two opposite modules (bridging constraint);
//! * the rest of a horizontal branch grows outwards after all supports and
//!   first modules;
//! * rule 3 ("horizontal branches must be built before all vertical
//!   branches are grown") as the authors' implementation reads it: their
//!   per-tile construction queue (VisibleSim 1aa66fe4, b = 6) starts Z and
//!   RevZ after the third module of X and Y, and LZ and RZ after the
//!   horizontal branches and the fourth modules of Z and RevZ; upward
//!   branches grow outwards. Read strictly (every upward branch after
//!   every horizontal tip) it made the paper protocol 6–8 % slower on
//!   pyramids h ≥ 4 (docs/scaffold.md);
//! * the supports go in one after another (safe protocol) or together
//!   (paper protocol, as the authors' queue feeds them), see [`Supports`].

use super::scaffold::{Dir, Scaffold};
use super::shape::Skew;
use std::collections::BTreeMap;

/// When a tile's supports may go in (§3.2.3 rule 2 leaves it open).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Supports {
    /// One after another, after the root and the first horizontal
    /// modules: the safe protocol's order (supports arriving together at
    /// neighbouring entry cells can pinch a departing module, a
    /// `sliding_contact` the exact sweep reports).
    OneAfterAnother,
    /// All together once the root and the first horizontal modules are
    /// in, as the authors' tile queue feeds them (two at a time, from
    /// different entry points): the paper protocol's order.
    Together,
}

/// How many modules of an unsupported border branch go in before the
/// rest of its tile with [`BorderBranches::FirstModules`]. Measured on the
/// authors' cylinders, cubes and half-spheres of sizes 2-9 and every
/// bundled scaffold scenario, in both protocols: with 2 every one plans
/// (and the safe ones certify collision-free); with 1 a later module of
/// such a branch finds no route (cylinders of size 4 and 6, both
/// protocols). The whole branch early made the cylinders 3-9 % slower
/// (size 6: 804 -> 752 steps safe, 702 -> 643 paper).
pub const EARLY_MODULES: u32 = 2;

/// How much of an upward branch with no support under it (at a border)
/// goes in before the rest of its tile: once its neighbours stand, no
/// rotation reaches its next module from below.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum BorderBranches {
    /// Its first [`EARLY_MODULES`]; the rest follow without holding up
    /// the tile. Enough wherever measured but on long branches in dense
    /// tiles (the 2-cube with e = b = 8).
    FirstModules,
    /// The whole branch, before anything else of the tile but its first
    /// modules: plans on every shape measured.
    Whole,
}

impl BorderBranches {
    pub fn name(self) -> &'static str {
        match self {
            BorderBranches::FirstModules => "first-modules",
            BorderBranches::Whole => "whole",
        }
    }
}

/// Precedences of a scaffold's components.
#[derive(Clone, Debug)]
pub struct Polytree {
    /// Parent tiles of each tile (the tiles whose branches enter it).
    pub parents: BTreeMap<Skew, Vec<Skew>>,
    /// For each component (index into `Scaffold::components`), the
    /// components that must be in place before it is.
    pub preds: Vec<Vec<usize>>,
}

impl Polytree {
    pub fn build(s: &Scaffold) -> Polytree {
        Polytree::build_with(s, Supports::OneAfterAnother, BorderBranches::FirstModules)
    }

    /// [`Polytree::build`] with the supports ordered as `supports` says and
    /// as much of each unsupported border branch early as `border` says.
    pub fn build_with(s: &Scaffold, supports: Supports, border: BorderBranches) -> Polytree {
        let b = s.b;
        let mut parents = BTreeMap::new();
        let mut preds = vec![Vec::new(); s.components.len()];
        for (&r, t) in &s.tiles {
            let idx = |c: Skew| s.index.get(&c).copied();
            let root = idx(r).expect("every tile has its root");
            let mut ps = Vec::new();
            let mut tips = Vec::new();
            for &u in &t.ingoing_up {
                if t.layer > 0 {
                    ps.push(r.offset(u.step().scale(-b)));
                    tips.extend(idx(r.offset(u.step().scale(-1))));
                }
            }
            for &h in &t.ingoing_h {
                ps.push(r.offset(h.step().scale(-b)));
                tips.extend(idx(r.offset(h.step().scale(-1))));
            }
            parents.insert(r, ps);
            preds[root] = tips;
            let mut early = vec![root];
            let mut horizontal_tips = Vec::new();
            for &(d, len) in t.branches.iter().filter(|(d, _)| !d.is_upward()) {
                let first = idx(r.offset(d.step())).expect("branch module");
                preds[first] = vec![root];
                early.push(first);
                horizontal_tips.push(idx(r.offset(d.step().scale(len as i32))).expect("tip"));
            }
            // A first branch module lies between two supports (X1 between
            // S_Z and S_RZ): it goes in before them (bridging constraint).
            let firsts = early.clone();
            // An upward branch with no support under it (its tile has no
            // ingoing branch of the mirror direction, at a border) has no
            // pivots for a climb from below once its neighbours are built:
            // its first modules (`border`) go in right after the tile's first
            // modules, before anything else of the tile hems them in; the
            // rest follow on them without holding up the tile. (The
            // supports of the paper protocol, which go in together, wait
            // for them only when the whole branch is early, as before.)
            let unsupported: Vec<(Dir, u32)> = t
                .branches
                .iter()
                .copied()
                .filter(|(d, _)| {
                    d.is_upward() && t.layer > 0 && !t.ingoing_up.contains(&d.mirror())
                })
                .collect();
            let mut before_supports = early.clone();
            let mut lone_prev: Option<usize> = None;
            for &(d, len) in &unsupported {
                for m in 1..=len as i32 {
                    let c = idx(r.offset(d.step().scale(m))).expect("branch module");
                    preds[c] = if m == 1 {
                        let mut p = firsts.clone();
                        p.extend(lone_prev);
                        p
                    } else {
                        vec![idx(r.offset(d.step().scale(m - 1))).expect("previous")]
                    };
                }
                let early_len = match border {
                    BorderBranches::FirstModules => len.min(EARLY_MODULES),
                    BorderBranches::Whole => len,
                };
                let held = idx(r.offset(d.step().scale(early_len as i32))).expect("branch module");
                early.push(held);
                lone_prev = Some(held);
            }
            if border == BorderBranches::Whole {
                before_supports = early.clone();
            }
            for &u in &t.ingoing_up {
                let si = idx(r.offset(u.mirror().support_offset())).expect("support exists");
                preds[si] = if supports == Supports::Together {
                    before_supports.clone()
                } else {
                    early.clone()
                };
                early.push(si);
            }
            for &(d, len) in t.branches.iter().filter(|(d, _)| !d.is_upward()) {
                for m in 2..=len as i32 {
                    let c = idx(r.offset(d.step().scale(m))).expect("branch module");
                    let mut p = early.clone();
                    p.push(idx(r.offset(d.step().scale(m - 1))).expect("previous"));
                    preds[c] = p;
                }
            }
            let ups: Vec<(Dir, u32)> = t
                .branches
                .iter()
                .copied()
                .filter(|b| b.0.is_upward() && !unsupported.contains(b))
                .collect();
            // Where each upward branch starts (rule 3, read as the
            // authors' tile queue reads it): Z and RevZ once the third
            // module of each X / Y branch is in (or its tip, if shorter),
            // LZ and RZ once the horizontal branches are complete and the
            // fourth modules of Z and RevZ are in. A tile that grows Opp
            // branches starts every upward branch after its horizontal
            // tips.
            let module = |d: Dir, len: u32, m: u32| {
                idx(r.offset(d.step().scale(m.min(len) as i32))).expect("branch module")
            };
            let has_opp = t
                .branches
                .iter()
                .any(|&(d, len)| matches!(d, Dir::OppX | Dir::OppY) && len > 1);
            for &(d, len) in &ups {
                let start: Vec<usize> = match d {
                    Dir::Z | Dir::RevZ if !has_opp => t
                        .branches
                        .iter()
                        .filter(|(h, _)| !h.is_upward())
                        .map(|&(h, hl)| module(h, hl, 3))
                        .collect(),
                    Dir::LZ | Dir::RZ => {
                        let mut p = horizontal_tips.clone();
                        p.extend(
                            ups.iter()
                                .filter(|(u, _)| matches!(u, Dir::Z | Dir::RevZ))
                                .map(|&(u, ul)| module(u, ul, 4)),
                        );
                        p
                    }
                    _ => horizontal_tips.clone(),
                };
                for m in 1..=len as i32 {
                    let c = idx(r.offset(d.step().scale(m))).expect("branch module");
                    preds[c] = if m == 1 {
                        let mut p = early.clone();
                        p.extend(&start);
                        p
                    } else {
                        vec![idx(r.offset(d.step().scale(m - 1))).expect("previous")]
                    };
                }
            }
        }
        Polytree { parents, preds }
    }

    /// Height of the construction polytree: the longest chain of tiles.
    pub fn height(&self) -> usize {
        let mut depth: BTreeMap<Skew, usize> = BTreeMap::new();
        // Parents sort before children (lower layer, or same layer and
        // smaller x / y), so one pass in tile order suffices.
        let mut tiles: Vec<&Skew> = self.parents.keys().collect();
        tiles.sort_by_key(|r| (r.z, r.x + r.y, r.x));
        for r in tiles {
            let d = self.parents[r]
                .iter()
                .map(|p| depth[p] + 1)
                .max()
                .unwrap_or(0);
            depth.insert(*r, d);
        }
        depth.values().copied().max().unwrap_or(0)
    }

    /// A topological order of the components (every component after its
    /// predecessors), for planners that place them one by one.
    pub fn topological(&self) -> Vec<usize> {
        let n = self.preds.len();
        let mut indeg: Vec<usize> = self.preds.iter().map(Vec::len).collect();
        let mut succ = vec![Vec::new(); n];
        for (i, ps) in self.preds.iter().enumerate() {
            for &p in ps {
                succ[p].push(i);
            }
        }
        let mut ready: std::collections::VecDeque<usize> =
            (0..n).filter(|&i| indeg[i] == 0).collect();
        let mut out = Vec::with_capacity(n);
        while let Some(i) = ready.pop_front() {
            out.push(i);
            for &j in &succ[i] {
                indeg[j] -= 1;
                if indeg[j] == 0 {
                    ready.push_back(j);
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::super::shape::Pyramid;
    use super::*;

    fn pyramid(h: u32) -> Scaffold {
        let top = (h as i32 - 1) * 6;
        Scaffold::build(
            &Pyramid { h, b: 6 },
            6,
            (Skew::new(0, 0, 0), Skew::new(top, top, top)),
        )
        .unwrap()
    }

    #[test]
    fn polytree_height_is_three_h_minus_one_for_pyramids() {
        // Seed 000 Theorem 1.
        for h in 2..=6 {
            assert_eq!(
                Polytree::build(&pyramid(h)).height(),
                3 * (h as usize - 1),
                "h = {h}"
            );
        }
    }

    #[test]
    fn a_tile_root_waits_for_all_its_ingoing_branches() {
        let s = pyramid(3);
        let p = Polytree::build(&s);
        let r = Skew::new(6, 6, 0);
        let root = s.index[&r];
        let want: Vec<usize> = [Skew::new(5, 6, 0), Skew::new(6, 5, 0)]
            .iter()
            .map(|c| s.index[c])
            .collect();
        let mut got = p.preds[root].clone();
        got.sort();
        let mut want = want;
        want.sort();
        assert_eq!(got, want);
        // A layer-1 root waits for its 4 ingoing upward branch tips (and none horizontal at the seed corner).
        let up = s.index[&Skew::new(0, 0, 6)];
        assert_eq!(p.preds[up].len(), 4);
    }

    #[test]
    fn upward_branches_start_as_the_authors_tile_queue_feeds_them() {
        // Tile (6, 6, 0) of the 3-pyramid grows X, Y, Z, RevZ, LZ and RZ.
        let s = pyramid(3);
        let p = Polytree::build(&s);
        let r = Skew::new(6, 6, 0);
        let at = |d: Dir, m: i32| s.index[&r.offset(d.step().scale(m))];
        let z1 = &p.preds[at(Dir::Z, 1)];
        assert!(z1.contains(&at(Dir::X, 3)) && z1.contains(&at(Dir::Y, 3)));
        assert!(
            !z1.contains(&at(Dir::X, 5)),
            "Z waits only for X3, not X's tip"
        );
        let lz1 = &p.preds[at(Dir::LZ, 1)];
        for need in [
            at(Dir::X, 5),
            at(Dir::Y, 5),
            at(Dir::Z, 4),
            at(Dir::RevZ, 4),
        ] {
            assert!(lz1.contains(&need), "{:?}", s.components[need].part);
        }
        assert_eq!(p.preds[at(Dir::Z, 2)], vec![at(Dir::Z, 1)]);
    }

    #[test]
    fn supports_go_in_together_or_one_after_another() {
        let s = pyramid(3);
        let r = Skew::new(6, 6, 6);
        let supports: Vec<usize> = Dir::UPWARD
            .iter()
            .map(|u| s.index[&r.offset(u.support_offset())])
            .collect();
        let waits_for_a_support = |p: &Polytree| {
            supports
                .iter()
                .filter(|&&i| p.preds[i].iter().any(|q| supports.contains(q)))
                .count()
        };
        assert_eq!(
            waits_for_a_support(&Polytree::build_with(
                &s,
                Supports::Together,
                BorderBranches::FirstModules
            )),
            0
        );
        assert_eq!(waits_for_a_support(&Polytree::build(&s)), 3);
    }

    #[test]
    fn topological_order_covers_every_component_once() {
        let s = pyramid(3);
        let p = Polytree::build(&s);
        let order = p.topological();
        assert_eq!(order.len(), s.components.len());
        let pos: Vec<usize> = {
            let mut v = vec![0; order.len()];
            for (k, &i) in order.iter().enumerate() {
                v[i] = k;
            }
            v
        };
        for (i, ps) in p.preds.iter().enumerate() {
            for &q in ps {
                assert!(pos[q] < pos[i]);
            }
        }
    }
}
