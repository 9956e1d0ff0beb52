//! Pipelined transport (§V, "modules of a stream keep one line"): the
//! catoms of a streamline set off one after another and travel together,
//! and the streamlines of an iteration run side by side.
//!
//! The paths come from the sequential planner (each catom planned against
//! the end state of the ones before it), so running them one after another
//! is valid by construction. Pipelining is prioritised planning on a time
//! axis: the catoms are committed in that same order, each at the earliest
//! departure step at which its whole path, rotation after rotation with no
//! wait, is valid against everything committed before it, and everything
//! committed before it stays valid:
//!
//! * every rotation: its target free and its pivot static at that step,
//!   clear of the cells occupied at the start of the step (the motion
//!   rules), and pairwise clear of the step's other rotations;
//! * the catom as an obstacle: its cell at the start of every step of its
//!   path, and its goal cell from its arrival on, must not block a
//!   committed rotation of that step;
//! * its start cell, once left, is not a committed rotation's pivot later;
//! * the structure stays anchored to the ground, as the certifier judges
//!   a step (the step's movers lifted, every catom at rest reaches the
//!   ground: the planner's [`Scene::connected_without`]), at its departure
//!   *and at every later step*: a catom that leaves while a later mover
//!   is still at rest can cut what that mover holds up once it moves too.
//!
//! Departing at the end of everything committed is the sequential order,
//! so the search always ends. A commit only empties its start cell from
//! its departure on and fills its goal after its arrival, so checking the
//! steps from its departure to the end keeps every step of the timeline
//! anchored; a debug assertion replays the finished timeline to say so.

use super::search::{Hop, Scene};
use crate::geometry::MotionRules;
use crate::lattice::config::ModuleId;
use crate::lattice::{Cell, Motion};
use rustc_hash::{FxHashMap, FxHashSet};

fn motion(h: &Hop) -> Motion {
    Motion::Rotate {
        from: h.from,
        to: h.to,
        pivot: h.pivot,
        route: h.route,
    }
}

/// What has been committed, on the time axis (step `t` = the `t`-th step
/// of the iteration; positions are at the start of a step).
struct Timeline<'a> {
    /// Every catom at its start cell.
    base: &'a Scene,
    rules: &'a dyn MotionRules,
    /// Start cell of a committed catom → the step it leaves at.
    departed: FxHashMap<Cell, usize>,
    /// Cells a committed catom holds after leaving its start: inclusive
    /// step ranges (`usize::MAX`: from its arrival on) and the catom.
    visits: FxHashMap<Cell, Vec<(usize, usize, ModuleId)>>,
    /// Committed rotations per step.
    moves: Vec<Vec<Hop>>,
    /// The last step at which a committed rotation pivots on a cell.
    pivot_last: FxHashMap<Cell, usize>,
}

impl Timeline<'_> {
    /// Whether `c` holds a catom at the start of step `t`, the uncommitted
    /// catoms at their start cells. (The ground is not a module: the
    /// planner's search keeps sweeps above it.)
    fn occupied(&self, c: Cell, t: usize) -> bool {
        if self.base.at.contains_key(&c) && self.departed.get(&c).is_none_or(|&d| t <= d) {
            return true;
        }
        self.visits
            .get(&c)
            .is_some_and(|v| v.iter().any(|&(a, b, _)| a <= t && t <= b))
    }

    fn moves_at(&self, t: usize) -> &[Hop] {
        self.moves.get(t).map_or(&[], Vec::as_slice)
    }

    /// Whether a catom sitting in `c` at the start of step `t` (its own
    /// start cell `start` already left) blocks none of that step's
    /// committed rotations.
    fn spares(&self, c: Cell, start: Cell, t: usize) -> bool {
        self.moves_at(t).iter().all(|o| {
            o.to != c
                && o.from != c
                && self.rules.allows(&motion(o), &|x| {
                    x != o.from && (x == c || (x != start && self.occupied(x, t)))
                })
        })
    }

    /// Whether the catom in `start`, leaving at step `t0` and rotating
    /// along `path` without waiting, fits the committed timeline.
    fn fits(&self, start: Cell, path: &[Hop], t0: usize) -> bool {
        if self.pivot_last.get(&start).is_some_and(|&p| p >= t0) {
            return false;
        }
        for (j, h) in path.iter().enumerate() {
            let t = t0 + j;
            let others = self.moves_at(t);
            let occ = |c: Cell| c != h.from && c != start && self.occupied(c, t);
            if self.occupied(h.to, t)
                || self.base.ground.is_some_and(|g| h.to.z < g)
                || !occ(h.pivot)
                || others
                    .iter()
                    .any(|o| o.from == h.pivot || o.pivot == h.from || o.to == h.to)
            {
                return false;
            }
            let m = motion(h);
            if !self.rules.allows(&m, &occ)
                || !others
                    .iter()
                    .all(|o| self.rules.concurrent_clear(&m, &motion(o)))
            {
                return false;
            }
            if j > 0 && !self.spares(h.from, start, t) {
                return false;
            }
        }
        let goal = path.last().map_or(start, |h| h.to);
        let end = t0 + path.len();
        (end..self.moves.len()).all(|t| self.spares(goal, start, t))
            && (t0..self.moves.len().max(end)).all(|t| self.anchored(t, Some(start)))
    }

    fn commit(&mut self, start: Cell, path: &[Hop], t0: usize) {
        let Some(last) = path.last() else {
            return;
        };
        self.departed.insert(start, t0);
        let id = self.base.at[&start];
        for (j, h) in path.iter().enumerate() {
            let t = t0 + j;
            if j > 0 {
                self.visits.entry(h.from).or_default().push((t, t, id));
            }
            if self.moves.len() <= t {
                self.moves.resize_with(t + 1, Vec::new);
            }
            self.moves[t].push(*h);
            let p = self.pivot_last.entry(h.pivot).or_default();
            *p = (*p).max(t);
        }
        self.visits
            .entry(last.to)
            .or_default()
            .push((t0 + path.len(), usize::MAX, id));
    }

    /// Whether, with the movers of step `t` lifted (and `leaving`, a catom
    /// about to move then), every catom at rest stays anchored: the
    /// planner's own rule ([`Scene::connected_without`]) on the catoms at
    /// rest at the start of step `t`, as the certifier judges a step.
    fn anchored(&self, t: usize, leaving: Option<Cell>) -> bool {
        let lifted: FxHashSet<Cell> = self
            .moves_at(t)
            .iter()
            .map(|h| h.from)
            .chain(leaving)
            .collect();
        let mut rest = self.base.clone();
        rest.at
            .retain(|c, _| !lifted.contains(c) && self.occupied(*c, t));
        for (c, v) in &self.visits {
            if let Some(&(_, _, id)) = v.iter().find(|&&(a, b, _)| a <= t && t <= b)
                && !lifted.contains(c)
            {
                rest.insert(id, *c);
            }
        }
        rest.connected_without(None)
    }
}

/// An iteration's rotations, step by step.
pub struct Pipelined {
    pub steps: Vec<Vec<Hop>>,
    /// How many lanes (streamlines) are under way at each step: from
    /// their first catom's departure to their last one's arrival.
    pub lanes_at: Vec<usize>,
}

/// One catom's path, committed in order: its lane (streamline) and the
/// earlier commits that must have arrived before it sets off.
#[derive(Clone, Debug)]
pub struct Commit {
    pub lane: usize,
    pub path: Vec<Hop>,
    /// Indices of earlier commits: this catom leaves no earlier than the
    /// step at which the last of them is at rest in its goal cell.
    pub after: Vec<usize>,
}

/// The catoms of each lane (one path per catom, in the order planned)
/// pipelined and the lanes side by side; `None` when a catom fits
/// nowhere (not even after everything committed; the sequential plan
/// makes that impossible unless the planner and the rules disagree).
pub fn pipeline(
    before: &Scene,
    lanes: &[Vec<Vec<Hop>>],
    rules: &dyn MotionRules,
) -> Option<Pipelined> {
    let commits: Vec<Commit> = lanes
        .iter()
        .enumerate()
        .flat_map(|(lane, paths)| {
            paths.iter().map(move |p| Commit {
                lane,
                path: p.clone(),
                after: Vec::new(),
            })
        })
        .collect();
    pipeline_commits(before, &commits, rules)
}

/// [`pipeline`] with the paths committed in the order given, which need
/// not be lane after lane (a pair of goal meta-modules assembled
/// together interleaves its two lanes), each no earlier than its lane's
/// previous catom and than the arrivals it waits for. The order must be
/// the one the paths were planned in: run one after another, they are
/// valid, which is what makes the search end.
pub fn pipeline_commits(
    before: &Scene,
    commits: &[Commit],
    rules: &dyn MotionRules,
) -> Option<Pipelined> {
    let mut tl = Timeline {
        base: before,
        rules,
        departed: FxHashMap::default(),
        visits: FxHashMap::default(),
        moves: Vec::new(),
        pivot_last: FxHashMap::default(),
    };
    let lanes = commits.iter().map(|c| c.lane + 1).max().unwrap_or(0);
    let mut earliest = vec![0; lanes];
    let mut spans: Vec<Option<(usize, usize)>> = vec![None; lanes];
    // Each commit's first step at rest in its goal cell.
    let mut arrival: Vec<usize> = Vec::with_capacity(commits.len());
    for c in commits {
        let path = &c.path;
        let wait = c.after.iter().map(|&i| arrival[i]).max().unwrap_or(0);
        let Some(first) = path.first() else {
            arrival.push(wait);
            continue;
        };
        let start = first.from;
        let horizon = tl.moves.len();
        let lo = earliest[c.lane].max(wait);
        let t0 = (lo..=horizon.max(lo)).find(|&t0| tl.fits(start, path, t0))?;
        tl.commit(start, path, t0);
        earliest[c.lane] = t0 + 1;
        arrival.push(t0 + path.len());
        let end = t0 + path.len() - 1;
        let span = &mut spans[c.lane];
        *span = Some(span.map_or((t0, end), |(a, b)| (a.min(t0), b.max(end))));
    }
    assert!(
        (0..tl.moves.len()).all(|t| tl.anchored(t, None)),
        "every commit checks the steps its absence affects"
    );
    let spans: Vec<(usize, usize)> = spans.into_iter().flatten().collect();
    let lanes_at = (0..tl.moves.len())
        .map(|t| spans.iter().filter(|(a, b)| *a <= t && t <= *b).count())
        .collect();
    Some(Pipelined {
        steps: tl.moves,
        lanes_at,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::Route;

    /// Rules that allow every rotation and every pair: what is left to the
    /// timeline is occupancy, pivots and anchoring.
    struct Free;
    impl MotionRules for Free {
        fn blocking_cells(&self, _: &Motion) -> Vec<Cell> {
            Vec::new()
        }
        fn touched_cells(&self, _: &Motion) -> Vec<Cell> {
            Vec::new()
        }
        fn concurrent_clear(&self, _: &Motion, _: &Motion) -> bool {
            true
        }
    }

    fn c(x: i32, y: i32) -> Cell {
        Cell::new(x, y, 5)
    }

    fn hop(from: Cell, to: Cell, pivot: Cell) -> Hop {
        Hop {
            from,
            to,
            pivot,
            route: Route::Hexagonal,
        }
    }

    /// A scene of catoms in `cells`, the first one fixed.
    fn fixed_first(cells: &[Cell]) -> Scene {
        let mut before = Scene {
            at: FxHashMap::default(),
            fixed: FxHashSet::default(),
            ground: None,
            lo: c(-5, -5),
            hi: c(5, 5),
            region: None,
        };
        for (i, x) in cells.iter().enumerate() {
            before.insert(i as ModuleId, *x);
        }
        before.fixed.insert(0);
        before
    }

    /// The catoms at rest at the start of each step, movers lifted, all
    /// reach the fixed catom (a breadth-first search written here).
    fn every_step_anchored(before: &Scene, steps: &[Vec<Hop>]) -> Vec<bool> {
        let mut at: FxHashSet<Cell> = before.at.keys().copied().collect();
        let anchor = c(0, 0);
        steps
            .iter()
            .map(|step| {
                let rest: FxHashSet<Cell> = at
                    .iter()
                    .copied()
                    .filter(|x| step.iter().all(|h| h.from != *x))
                    .collect();
                let mut seen = FxHashSet::from_iter([anchor]);
                let mut stack = vec![anchor];
                while let Some(x) = stack.pop() {
                    for n in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
                        let y = c(x.x + n.0, x.y + n.1);
                        if rest.contains(&y) && seen.insert(y) {
                            stack.push(y);
                        }
                    }
                }
                for h in step {
                    at.remove(&h.from);
                    at.insert(h.to);
                }
                seen.len() == rest.len()
            })
            .collect()
    }

    /// A commit that names an earlier one leaves only once that one has
    /// arrived; without it both leave at once (F fixed, A and B beside it).
    #[test]
    fn a_commit_waits_for_the_arrivals_it_names() {
        let [f, a, b] = [(0, 0), (1, 0), (-1, 0)].map(|(x, y)| c(x, y));
        let before = fixed_first(&[f, a, b]);
        let first = Commit {
            lane: 0,
            path: vec![hop(a, c(0, 1), f)],
            after: Vec::new(),
        };
        let second = |after: Vec<usize>| Commit {
            lane: 1,
            path: vec![hop(b, c(0, -1), f)],
            after,
        };
        let leaves = |commits: &[Commit]| {
            let p = pipeline_commits(&before, commits, &Free).expect("fits");
            p.steps.iter().position(|st| st.iter().any(|h| h.from == b))
        };
        assert_eq!(leaves(&[first.clone(), second(Vec::new())]), Some(0));
        assert_eq!(leaves(&[first, second(vec![0])]), Some(1));
    }

    /// In one layer, F (fixed) holds R, R2 and S up through two routes:
    /// M, and K–Z. Lane 1 sends M0 round F, then M (leaving at step 1)
    /// to the cell beside M0 and S, which gives R a route again from
    /// step 2; lane 2 sends Z away for good. Leaving at step 0 is fine
    /// *at* step 0 (M still holds R), but at step 1 M is a mover and Z is
    /// gone: R, R2 and S would hang from nothing. Z must wait until M has
    /// arrived.
    #[test]
    fn a_catom_waits_until_its_absence_cannot_cut_the_structure_at_a_later_step() {
        let [f, k, m, z, r, r2, s, m0] = [
            (0, 0),
            (0, 1),
            (1, 0),
            (1, 1),
            (2, 0),
            (2, 1),
            (2, -1),
            (-1, 0),
        ]
        .map(|(x, y)| c(x, y));
        let before = fixed_first(&[f, k, m, z, r, r2, s, m0]);
        let lane1 = vec![vec![hop(m0, c(0, -1), f)], vec![hop(m, c(1, -1), f)]];
        let z_path = vec![hop(z, c(1, 2), k), hop(c(1, 2), c(0, 2), k)];
        let p = pipeline(&before, &[lane1, vec![z_path.clone()]], &Free)
            .expect("Z fits once M has arrived");
        let z_leaves = p.steps.iter().position(|st| st.iter().any(|h| h.from == z));
        assert_eq!(z_leaves, Some(2), "Z leaves when M is in place again");
        assert!(every_step_anchored(&before, &p.steps).iter().all(|&a| a));
        // Leaving at step 0, as a departure-only check allowed, cuts step 1.
        let mut early: Vec<Vec<Hop>> = p
            .steps
            .iter()
            .map(|st| st.iter().filter(|h| !z_path.contains(h)).copied().collect())
            .collect();
        early[0].push(z_path[0]);
        early[1].push(z_path[1]);
        assert_eq!(
            every_step_anchored(&before, &early)[..3],
            [true, false, true],
            "leaving at step 0 hangs R, R2 and S from nothing at step 1"
        );
    }
}
