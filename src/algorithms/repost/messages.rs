//! Messages of the distributed protocol (the paper's Fig. 10a), counted
//! on the plan.
//!
//! The planner is centralised; the paper's agents compute the same things
//! by messages. This module counts what the authors' IROS-era protocol
//! (jadbassil/VisibleSim, branch `RePoSt`) would send to carry out each
//! iteration of the plan, **as VisibleSim counts them: one per one-hop
//! transmission** (a message between meta-modules is routed leader to
//! leader through the catoms of the two loops and counts once per hop).
//! What is counted, per iteration:
//!
//! * **tree**: the coordinator's Go flood builds the spanning tree whose
//!   leaves may be sources; every meta-module sends Go to each neighbour
//!   but its parent, and each Go is answered by one Back.
//! * **max-flow**: one breadth-first search from the open sources per
//!   streamline found, and a last one that finds none. Each meta-module
//!   it reaches forwards BFS to every neighbour and returns ConfirmEdge to
//!   its parent; a found path costs ConfirmPath back along it, CutOff to
//!   every other reached meta-module, ConfirmStreamline forward and
//!   Available to each path meta-module's two path neighbours. The authors
//!   acknowledge each of these messages, so each counts twice.
//! * **termination**: one detection wave, GoTerm down the tree and BackTerm
//!   up.
//! * **transport**: per rotation, one PLS to each latching point (an
//!   occupied neighbour of the target cell other than the pivot and the
//!   catoms moving in that step) and its GLO reply, each over the shortest
//!   route through catoms at rest; per catom, one Coordinate when it sets
//!   off and one each time its pivot passes to another meta-module (an
//!   operation ends there), with one FTR ("free to rotate") to each
//!   neighbour where an operation ends and where it arrives; and one
//!   CoordinateBack when its Dismantle ends.
//!
//! Choices where the code leaves room, each a lower bound: the Go flood
//! with no re-parenting, one termination wave, a CoordinateBack of one
//! hop, the BFS of a round reaching everything reachable once (no
//! augmenting paths through committed streamlines; the planner's paths
//! are vertex-disjoint). Initialisation, the choice of destinations and
//! the start of each phase cost nothing: the authors' code reads them from
//! global maps.

use super::metamodule::{Meta, SpanningTree, State};
use super::search::Hop;
use crate::lattice::config::ModuleId;
use crate::lattice::{Cell, FccLattice, Lattice};
use rustc_hash::{FxHashMap, FxHashSet};
use std::collections::{BTreeMap, VecDeque};

/// An iteration's messages, by phase (one-hop transmissions).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Messages {
    pub tree: usize,
    pub max_flow: usize,
    pub termination: usize,
    pub transport: usize,
}

impl Messages {
    pub fn total(&self) -> usize {
        self.tree + self.max_flow + self.termination + self.transport
    }
}

impl std::iter::Sum for Messages {
    fn sum<I: Iterator<Item = Messages>>(it: I) -> Messages {
        it.fold(Messages::default(), |mut a, m| {
            a += m;
            a
        })
    }
}

impl std::ops::AddAssign for Messages {
    fn add_assign(&mut self, o: Messages) {
        self.tree += o.tree;
        self.max_flow += o.max_flow;
        self.termination += o.termination;
        self.transport += o.transport;
    }
}

/// What an iteration did, as the planner knows it.
pub struct IterationRecord<'a> {
    /// The meta-modules at the start of the iteration.
    pub present: &'a BTreeMap<Meta, State>,
    /// The spanning tree the coordinator's Go flood builds over
    /// `present`: the planner's own.
    pub tree: &'a SpanningTree,
    pub sources: &'a [Meta],
    /// In the order the flow found them.
    pub streamlines: &'a [Vec<Meta>],
    /// Catom cells at the start of the iteration.
    pub cells: &'a FxHashMap<Cell, ModuleId>,
    /// The iteration's steps: (module, pivot module, rotation).
    pub steps: &'a [Vec<(ModuleId, ModuleId, Hop)>],
}

/// Shortest route, in hops, from `from` to `to` through the cells that
/// `pass` admits (`to` itself need not be admitted).
fn hops(from: Cell, to: Cell, pass: &dyn Fn(Cell) -> bool) -> Option<usize> {
    if from == to {
        return Some(0);
    }
    let l = FccLattice;
    let mut seen = FxHashSet::from_iter([from]);
    let mut queue = VecDeque::from([(from, 0)]);
    while let Some((c, d)) = queue.pop_front() {
        for n in l.neighbours(c) {
            if n == to {
                return Some(d + 1);
            }
            if pass(n) && seen.insert(n) {
                queue.push_back((n, d + 1));
            }
        }
    }
    None
}

/// Hops of one message between adjacent meta-modules: leader to leader
/// through the catoms of the two (through the whole structure if the two
/// alone do not connect them; one hop if nothing does).
fn meta_hops(cells: &FxHashMap<Cell, ModuleId>, a: Meta, b: Meta) -> usize {
    let own =
        |c: Cell| cells.contains_key(&c) && Meta::owner(c).is_some_and(|(m, _)| m == a || m == b);
    hops(a.leader(), b.leader(), &own)
        .or_else(|| hops(a.leader(), b.leader(), &|c| cells.contains_key(&c)))
        .unwrap_or(1)
}

/// Counts an iteration's messages.
pub fn count(it: &IterationRecord) -> Messages {
    let mut memo: FxHashMap<(Meta, Meta), usize> = FxHashMap::default();
    let mut route = |a: Meta, b: Meta| {
        let key = if a < b { (a, b) } else { (b, a) };
        *memo
            .entry(key)
            .or_insert_with(|| meta_hops(it.cells, key.0, key.1))
    };
    let present = |m: &Meta| it.present.contains_key(m);
    let mut out = Messages::default();
    for &m in it.tree.depth.keys() {
        let p = it.tree.parent.get(&m).copied();
        for n in m.adjacent().filter(present) {
            if Some(n) != p {
                out.tree += 2 * route(m, n); // Go, and its Back
            }
        }
        if let Some(p) = p {
            out.termination += 2 * route(m, p); // GoTerm down, BackTerm up
        }
    }
    // Max-flow: a search per streamline found, and one that finds none.
    let mut used: FxHashSet<Meta> = FxHashSet::default();
    for round in 0..=it.streamlines.len() {
        let open: Vec<Meta> = it
            .sources
            .iter()
            .filter(|s| present(s) && !used.contains(s))
            .copied()
            .collect();
        let free =
            |m: &Meta| present(m) && !used.contains(m) && it.present.get(m) != Some(&State::Full);
        let mut reached: BTreeMap<Meta, Option<Meta>> = open.iter().map(|&s| (s, None)).collect();
        let mut queue: VecDeque<Meta> = open.iter().copied().collect();
        let mut logical = 0;
        while let Some(m) = queue.pop_front() {
            for n in m.adjacent().filter(present) {
                logical += route(m, n); // BFS to every neighbour
                if free(&n) && !reached.contains_key(&n) {
                    reached.insert(n, Some(m));
                    logical += route(n, m); // ConfirmEdge
                    queue.push_back(n);
                }
            }
        }
        if let Some(line) = it.streamlines.get(round) {
            for w in line.windows(2) {
                // ConfirmPath back, ConfirmStreamline forward, Available
                // both ways.
                logical += 4 * route(w[0], w[1]);
            }
            for (m, p) in &reached {
                if let Some(p) = p
                    && !line.contains(m)
                {
                    logical += route(*p, *m); // CutOff
                }
            }
            used.extend(line.iter().copied());
        }
        out.max_flow += 2 * logical; // each acknowledged
    }
    out.transport = transport(it);
    out
}

/// The motion-coordination messages of the iteration's rotations.
fn transport(it: &IterationRecord) -> usize {
    /// A catom under way: the meta-module of its last pivot, and whether
    /// its first operation (the Dismantle) has ended.
    struct Track {
        meta: Option<Meta>,
        dismantled: bool,
    }
    let l = FccLattice;
    let mut at: FxHashMap<Cell, ModuleId> = it.cells.clone();
    let mut track: FxHashMap<ModuleId, Track> = FxHashMap::default();
    let mut arrived: FxHashMap<ModuleId, Cell> = FxHashMap::default();
    let occupied_around = |at: &FxHashMap<Cell, ModuleId>, c: Cell| {
        l.neighbours(c)
            .into_iter()
            .filter(|x| at.contains_key(x))
            .count()
    };
    let mut n = 0;
    for step in it.steps {
        let moving: FxHashSet<Cell> = step.iter().map(|(_, _, h)| h.from).collect();
        let rest = |c: Cell| at.contains_key(&c) && !moving.contains(&c);
        for (id, _, h) in step {
            for lp in l.neighbours(h.to) {
                if lp != h.pivot && rest(lp) {
                    n += 2 * hops(h.from, lp, &rest).unwrap_or(1); // PLS, GLO
                }
            }
            let pivot_meta = Meta::owner(h.pivot).map(|(m, _)| m);
            match track.get_mut(id) {
                None => {
                    n += 1; // Coordinate from the source
                    track.insert(
                        *id,
                        Track {
                            meta: pivot_meta,
                            dismantled: false,
                        },
                    );
                }
                Some(t) => match (t.meta, pivot_meta) {
                    (Some(a), Some(b)) if a != b => {
                        // An operation ends at `from`: FTR to each
                        // neighbour, the next coordinator's Coordinate,
                        // and CoordinateBack if it was the Dismantle.
                        n += occupied_around(&at, h.from) + 1 + usize::from(!t.dismantled);
                        t.dismantled = true;
                        t.meta = pivot_meta;
                    }
                    (None, _) => t.meta = pivot_meta,
                    _ => {}
                },
            }
        }
        for (_, _, h) in step {
            at.remove(&h.from);
        }
        for (id, _, h) in step {
            at.insert(h.to, *id);
            arrived.insert(*id, h.to);
        }
    }
    // Arrival: FTR to each neighbour at the goal.
    n + arrived
        .values()
        .map(|&c| occupied_around(&at, c))
        .sum::<usize>()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algorithms::repost::metamodule::{Direction, spanning_tree};

    fn sparse(metas: &[Meta]) -> FxHashMap<Cell, ModuleId> {
        let mut at = FxHashMap::default();
        for m in metas {
            for c in m.sparse_cells() {
                at.insert(c, at.len() as ModuleId);
            }
        }
        at
    }

    fn hop(from: Cell, to: Cell, pivot: Cell) -> Hop {
        Hop {
            from,
            to,
            pivot,
            route: crate::lattice::Route::Hexagonal,
        }
    }

    /// Shortest leader-to-leader routes through the two loops. The authors'
    /// fixed routing tables take 4 to 7 hops (about 5.5): ours are the
    /// same range, and the same either way.
    #[test]
    fn a_message_between_adjacent_meta_modules_takes_four_to_seven_hops_either_way() {
        let mut all = Vec::new();
        for a in [(0, 0, 0), (1, 0, 0), (0, 0, 1), (1, 0, 1)].map(|(x, y, z)| Meta::new(x, y, z)) {
            for d in Direction::ALL {
                let b = a.step(d);
                let at = sparse(&[a, b]);
                let h = meta_hops(&at, a, b);
                assert_eq!(h, meta_hops(&at, b, a), "{a} {d:?}");
                assert!((4..=7).contains(&h), "{a} {d:?}: {h} hops");
                all.push(h);
            }
        }
        assert_eq!(all.iter().sum::<usize>(), 132, "5.5 hops on average");
        // Right and left (along X) are 6.
        let (a, b) = (Meta::new(0, 0, 0), Meta::new(1, 0, 0));
        assert_eq!(meta_hops(&sparse(&[a, b]), a, b), 6);
    }

    /// Three meta-modules in a row, S - M - D, one streamline S → D, the
    /// coordinator at D; every route 6 hops. By hand:
    /// * Go D→M, M→S, each answered by Back: 2 · (6 + 6) = 24;
    /// * the termination wave over the same two tree edges: 24;
    /// * the first search: BFS S→M, ConfirmEdge M→S, BFS M→S and M→D,
    ///   ConfirmEdge D→M, BFS D→M (6 routes), then ConfirmPath,
    ///   ConfirmStreamline and Available both ways on 2 edges (8 routes):
    ///   14 · 6 = 84, acknowledged: 168; the second search has no open
    ///   source left: 0.
    #[test]
    fn a_row_of_three_sends_the_hand_counted_control_messages() {
        let [s, m, d] = [0, 1, 2].map(|x| Meta::new(x, 0, 0));
        let present = BTreeMap::from([(s, State::Sparse), (m, State::Sparse), (d, State::Sparse)]);
        let cells = sparse(&[s, m, d]);
        let got = count(&IterationRecord {
            present: &present,
            tree: &spanning_tree(|m| present.contains_key(m), d),
            sources: &[s],
            streamlines: &[vec![s, m, d]],
            cells: &cells,
            steps: &[],
        });
        assert_eq!(
            got,
            Messages {
                tree: 24,
                max_flow: 168,
                termination: 24,
                transport: 0
            }
        );
        assert_eq!(got.total(), 216);
    }

    /// One catom X in layer 0 next to catoms P (pivot, in meta-module
    /// (0,0,0)'s loop) and Q, then a second rotation on a pivot R of
    /// meta-module (1,0,0). By hand:
    /// * step 1, X (0,1,0) → (1,1,0) on P: the target's one latching point
    ///   is Q, two hops from X (through P): PLS and GLO, 4; Coordinate, 1;
    /// * step 2, X (1,1,0) → (2,1,0) on R: no latching point; the pivot's
    ///   meta-module changes, so the Dismantle ends at (1,1,0): FTR to its
    ///   one neighbour Q, Coordinate and CoordinateBack: 3;
    /// * arrival at (2,1,0): no neighbour, no FTR. Total 8.
    #[test]
    fn a_catom_crossing_two_meta_modules_sends_the_hand_counted_coordination_messages() {
        let c = |x, y| Cell::new(x, y, 0);
        let (p, q, r, x) = (c(0, 0), c(1, 0), c(4, 0), c(0, 1));
        assert_eq!(Meta::owner(p).map(|o| o.0), Some(Meta::new(0, 0, 0)));
        assert_eq!(Meta::owner(r).map(|o| o.0), Some(Meta::new(1, 0, 0)));
        let cells = FxHashMap::from_iter([(p, 0), (q, 1), (r, 2), (x, 3)]);
        let steps = vec![
            vec![(3, 0, hop(x, c(1, 1), p))],
            vec![(3, 2, hop(c(1, 1), c(2, 1), r))],
        ];
        let present = BTreeMap::new();
        let it = IterationRecord {
            present: &present,
            tree: &spanning_tree(|_| false, Meta::new(0, 0, 0)),
            sources: &[],
            streamlines: &[],
            cells: &cells,
            steps: &steps,
        };
        assert_eq!(transport(&it), 8);
        assert_eq!(
            transport(&IterationRecord {
                steps: &steps[..1],
                ..it
            }),
            4 + 1 + 1
        );
    }
}
