//! Seed 004 §3.1.2–3.1.3: a comb to the common comb (Algorithm 2,
//! 2D-COMB-TO-COMMON-COMB), and Theorem 1's whole reconfiguration: the
//! source combed, then made the common comb, then the target's own combing
//! and comb-to-common-comb run in reverse.
//!
//! Meta-modules move by the paper's k-TUNNEL along an orthogonal path
//! (`tunnel` events: the leaf leaves its cell, the exit cell fills), one
//! tunnel per parallel step, as Algorithm 2 dequeues them.

use super::{Robot, Shape, pair};
use crate::lattice::Cell;
use crate::lattice::config::ModuleId;
use crate::schedule::Event;
use rustc_hash::FxHashSet;
use std::collections::VecDeque;

/// A comb (§3.1.1): a handle of `teeth.len()` meta-modules on row `y0`
/// from column `x0` rightwards, and on handle cell `i` a tooth of
/// `teeth[i]` meta-modules (the handle's not counted).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Comb {
    pub x0: i32,
    pub y0: i32,
    pub teeth: Vec<usize>,
}

impl Comb {
    /// The comb a shape is, if it is one: a contiguous handle on its lowest
    /// row and every column one run standing on it.
    pub fn of(shape: &Shape) -> Option<Comb> {
        let y0 = shape.iter().map(|c| c.1).min()?;
        let x0 = shape.iter().map(|c| c.0).min()?;
        let x1 = shape.iter().map(|c| c.0).max()?;
        let mut teeth = Vec::new();
        for x in x0..=x1 {
            let h = shape.iter().filter(|c| c.0 == x).count();
            if h == 0 || !(0..h as i32).all(|j| shape.contains(&(x, y0 + j))) {
                return None;
            }
            teeth.push(h - 1);
        }
        Some(Comb { x0, y0, teeth })
    }

    /// The paper's C_U: the longer handle, each tooth the longer of the
    /// two. Both combs must share their first handle cell.
    pub fn union(&self, other: &Comb) -> Comb {
        assert_eq!((self.x0, self.y0), (other.x0, other.y0), "aligned combs");
        let h = self.teeth.len().max(other.teeth.len());
        let at = |c: &Comb, i: usize| c.teeth.get(i).copied().unwrap_or(0);
        Comb {
            x0: self.x0,
            y0: self.y0,
            teeth: (0..h).map(|i| at(self, i).max(at(other, i))).collect(),
        }
    }

    /// The common comb of `m` meta-modules in this shell (C_U): its handle
    /// and a right-fill of the other `m − h` into the teeth, rightmost
    /// tooth first, each from the handle up.
    pub fn common_comb(&self, m: usize) -> Shape {
        let mut out: Shape = (0..self.teeth.len() as i32)
            .map(|i| (self.x0 + i, self.y0))
            .collect();
        let mut left = m.saturating_sub(self.teeth.len());
        for (i, &t) in self.teeth.iter().enumerate().rev() {
            let n = t.min(left);
            for j in 1..=n as i32 {
                out.insert((self.x0 + i as i32, self.y0 + j));
            }
            left -= n;
        }
        out
    }
}

/// The orthogonal path of Algorithm 2's tunnels: from `from` down its
/// tooth to the handle row `y0`, along the handle to the exit's column,
/// and up that column to the exit `to` (start cell first).
pub fn comb_path(from: (i32, i32), to: (i32, i32), y0: i32) -> Vec<(i32, i32)> {
    let mut p = vec![from];
    let mut c = from;
    while c.1 > y0 {
        c.1 -= 1;
        p.push(c);
    }
    while c.0 != to.0 {
        c.0 += (to.0 - c.0).signum();
        p.push(c);
    }
    while c.1 < to.1 {
        c.1 += 1;
        p.push(c);
    }
    p
}

impl Robot {
    /// One k-TUNNEL step along `path` (see [`apply`]).
    pub(super) fn tunnel(&mut self, path: Vec<(i32, i32)>) {
        let leaf = self.get(path[0]).expect("a leaf at the tunnel's start");
        let path = path.into_iter().map(super::cell).collect();
        apply(
            self,
            &[Event::Tunnel {
                module: leaf as ModuleId,
                path,
            }],
        );
    }

    /// Height of the tooth on handle column `x` (handle row `y0`).
    fn tooth(&self, x: i32, y0: i32) -> usize {
        (1..)
            .take_while(|&j| self.get((x, y0 + j)).is_some())
            .count()
    }

    /// Algorithm 2, 2D-COMB-TO-COMMON-COMB: this robot, a comb with its
    /// handle on `u`'s first cell, becomes the common comb in the shell
    /// `u` (C_U). Step 2 lengthens the handle by 1-TUNNELs from the queue
    /// of teeth in reverse lexicographic order; Step 3 fills the teeth
    /// right to left by 2-TUNNELs from the first non-empty tooth on their
    /// left.
    pub fn to_common_comb(&mut self, u: &Comb) {
        let (x0, y0) = (u.x0, u.y0);
        let mut teeth: Vec<(i32, i32)> = self.at.iter().copied().filter(|c| c.1 > y0).collect();
        teeth.sort_unstable_by(|a, b| b.cmp(a));
        let mut queue: VecDeque<(i32, i32)> = teeth.into();
        let handle = self.at.iter().filter(|c| c.1 == y0).count();
        for i in handle..u.teeth.len() {
            // Too few teeth to make the handle (3D Step 1 leaves it partial).
            let Some(o) = queue.pop_front() else {
                return;
            };
            self.tunnel(comb_path(o, (x0 + i as i32, y0), y0));
        }
        for i in (0..u.teeth.len()).rev() {
            let x = x0 + i as i32;
            let have = self.tooth(x, y0);
            for _ in 0..have {
                queue.pop_front();
            }
            for j in have..u.teeth[i] {
                let Some(o) = queue.pop_front() else {
                    return;
                };
                self.tunnel(comb_path(o, (x, y0 + 1 + j as i32), y0));
            }
        }
    }

    /// Applies recorded meta-module events (see [`apply`]).
    pub fn apply(&mut self, events: &[Event]) {
        apply(self, events);
    }
}

/// A meta-module robot the comb algorithms update, in 2D or 3D: where
/// each meta-module is, which pairs are attached, the steps so far.
pub trait MetaRobot: Clone {
    fn cell_of(&self, m: usize) -> Cell;
    fn at_cell(&self, c: Cell) -> Option<usize>;
    fn attached_mut(&mut self) -> &mut FxHashSet<(usize, usize)>;
    /// Moves meta-modules (all vacate, then all arrive).
    fn move_all(&mut self, moves: &[(usize, Cell)]);
    fn steps_mut(&mut self) -> &mut Vec<Vec<Event>>;
    fn attached(&self) -> &FxHashSet<(usize, usize)>;
    /// How many meta-modules the robot has.
    fn count(&self) -> usize;
}

impl MetaRobot for Robot {
    fn cell_of(&self, m: usize) -> Cell {
        super::cell(self.at[m])
    }
    fn at_cell(&self, c: Cell) -> Option<usize> {
        (c.z == 0).then(|| self.get((c.x, c.y))).flatten()
    }
    fn attached_mut(&mut self) -> &mut FxHashSet<(usize, usize)> {
        &mut self.attached
    }
    fn move_all(&mut self, moves: &[(usize, Cell)]) {
        let m: Vec<(usize, (i32, i32))> = moves.iter().map(|&(k, c)| (k, (c.x, c.y))).collect();
        self.relocate(&m);
    }
    fn steps_mut(&mut self) -> &mut Vec<Vec<Event>> {
        &mut self.steps
    }
    fn attached(&self) -> &FxHashSet<(usize, usize)> {
        &self.attached
    }
    fn count(&self) -> usize {
        self.at.len()
    }
}

/// Applies recorded meta-module events as the comb algorithms do (a SLIDE
/// relatches its slider from the wall to the meta-module beside the wall
/// along the slide; a tunnel's leaf lets go of its neighbour and attaches
/// to the exit's neighbour on the path), recording the step. Used to
/// replay a reversed schedule.
pub fn apply<R: MetaRobot>(r: &mut R, events: &[Event]) {
    let mut moves = Vec::new();
    for e in events {
        match e {
            Event::Slide {
                module, to, pivot, ..
            } => {
                let a = *module as usize;
                if let Some(p) = pivot {
                    let p = *p as usize;
                    let d = *to - r.cell_of(a);
                    let c = r.at_cell(r.cell_of(p) + d).expect("a SLIDE's C");
                    r.attached_mut().remove(&pair(a, p));
                    r.attached_mut().insert(pair(a, c));
                }
                moves.push((a, *to));
            }
            Event::Tunnel { module, path } => {
                let leaf = *module as usize;
                let support = r.at_cell(path[path.len() - 2]).expect("an occupied path");
                r.attached_mut().retain(|&(a, b)| a != leaf && b != leaf);
                r.attached_mut().insert(pair(leaf, support));
                moves.push((leaf, *path.last().expect("a path")));
            }
            Event::Attach { module, other } => {
                r.attached_mut()
                    .insert(pair(*module as usize, *other as usize));
            }
            Event::Detach { module, other } => {
                r.attached_mut()
                    .remove(&pair(*module as usize, *other as usize));
            }
            _ => panic!("not a comb event: {e:?}"),
        }
    }
    r.move_all(&moves);
    r.steps_mut().push(events.to_vec());
}

/// The meta-module steps that undo `steps`, run from `start` (the
/// robot the steps were recorded on, before them), in reverse order: a
/// SLIDE slides back along the meta-module it arrived beside, a tunnel runs
/// its path backwards, attach and detach swap.
pub fn reversed<R: MetaRobot>(start: &R, steps: &[Vec<Event>]) -> Vec<Vec<Event>> {
    let mut r = start.clone();
    r.steps_mut().clear();
    let mut out = Vec::with_capacity(steps.len());
    for events in steps {
        // The walls' cells before the step (a wall does not move in it).
        let walls: Vec<Option<Cell>> = events
            .iter()
            .map(|e| match e {
                Event::Slide { pivot: Some(p), .. } => Some(r.cell_of(*p as usize)),
                _ => None,
            })
            .collect();
        apply(&mut r, events);
        let back = events
            .iter()
            .zip(walls)
            .map(|(e, wall)| match e {
                Event::Slide {
                    module,
                    from,
                    to,
                    pivot,
                } => Event::Slide {
                    module: *module,
                    from: *to,
                    to: *from,
                    pivot: pivot.map(|_| {
                        let c = wall.expect("a wall") + (*to - *from);
                        r.at_cell(c).expect("a SLIDE's C") as ModuleId
                    }),
                },
                Event::Tunnel { module, path } => Event::Tunnel {
                    module: *module,
                    path: path.iter().rev().copied().collect(),
                },
                Event::Attach { module, other } => Event::Detach {
                    module: *module,
                    other: *other,
                },
                Event::Detach { module, other } => Event::Attach {
                    module: *module,
                    other: *other,
                },
                e => e.clone(),
            })
            .collect();
        out.push(back);
    }
    out.reverse();
    out
}

/// Theorem 1's reconfiguration of `source` into `target` (the target
/// placed with its lowest row and leftmost column on the source's, the
/// paper's common origin of the two combs): the meta-module steps of each
/// of the four phases, and the robot at the end.
#[derive(Clone, Debug)]
pub struct Reconfiguration<S = Shape, R = Robot> {
    /// The target as reached (moved onto the source's origin).
    pub target: S,
    /// Steps of: combing the source; its comb to the common comb; the
    /// target's comb-to-common-comb reversed (with the attachment steps
    /// that make the two robots' latches agree first); the target's
    /// combing reversed.
    pub phases: [Vec<Vec<Event>>; 4],
    /// The robot after every phase, by the source's meta-module ids.
    pub end: R,
}

impl<S, R> Reconfiguration<S, R> {
    pub fn steps(&self) -> Vec<Vec<Event>> {
        self.phases.iter().flatten().cloned().collect()
    }
}

/// The last two phases of Theorem 1, in 2D or 3D: the target robot `t`'s
/// run (`t0` combed by `comb_t` into `after_comb_t`, which `ccs_t` made
/// the common comb `t` is now) reversed and renamed onto the source robot
/// `s`, which is in the same common comb: first the latch steps that make
/// the two robots' attachments agree there, then `ccs_t` reversed, then
/// `comb_t` reversed. Applies them to `s`; returns (latch steps and
/// `ccs_t` reversed, `comb_t` reversed).
pub fn join_reversed<R: MetaRobot>(
    s: &mut R,
    t: &R,
    t0: &R,
    comb_t: &[Vec<Event>],
    after_comb_t: &R,
    ccs_t: &[Vec<Event>],
) -> (Vec<Vec<Event>>, Vec<Vec<Event>>) {
    // The target's ids, renamed to the source robot's meta-module in the
    // same cell of the common comb.
    let name: Vec<usize> = (0..t.count())
        .map(|m| s.at_cell(t.cell_of(m)).expect("one common comb"))
        .collect();
    let t_attached: FxHashSet<(usize, usize)> = t
        .attached()
        .iter()
        .map(|&(a, b)| pair(name[a], name[b]))
        .collect();
    let latch = |pairs: Vec<(usize, usize)>, attach: bool| -> Vec<Event> {
        pairs
            .into_iter()
            .map(|(a, b)| {
                let (module, other) = (a as ModuleId, b as ModuleId);
                if attach {
                    Event::Attach { module, other }
                } else {
                    Event::Detach { module, other }
                }
            })
            .collect()
    };
    let mut out = Vec::new();
    let attach = latch(sorted(t_attached.difference(s.attached())).collect(), true);
    let detach = latch(
        sorted(s.attached().difference(&t_attached)).collect(),
        false,
    );
    for events in [attach, detach] {
        if !events.is_empty() {
            apply(s, &events);
            out.push(events);
        }
    }
    let rename = |steps: Vec<Vec<Event>>| -> Vec<Vec<Event>> {
        steps
            .into_iter()
            .map(|es| es.into_iter().map(|e| renamed(e, &name)).collect())
            .collect()
    };
    let back_common = rename(reversed(after_comb_t, ccs_t));
    let back_comb = rename(reversed(t0, comb_t));
    for es in back_common.iter().chain(&back_comb) {
        apply(s, es);
    }
    out.extend(back_common);
    (out, back_comb)
}

/// Theorem 1 in 2D (§3.1.3).
pub fn reconfigure(source: &Shape, target: &Shape) -> Reconfiguration {
    let origin = |s: &Shape| {
        (
            s.iter().map(|c| c.0).min().unwrap_or(0),
            s.iter().map(|c| c.1).min().unwrap_or(0),
        )
    };
    let (so, to) = (origin(source), origin(target));
    let target: Shape = target
        .iter()
        .map(|&(x, y)| (x - to.0 + so.0, y - to.1 + so.1))
        .collect();
    let mut s = Robot::new(source);
    s.comb();
    let comb_s = std::mem::take(&mut s.steps);
    let t0 = Robot::new(&target);
    let mut t = t0.clone();
    t.comb();
    let comb_t = std::mem::take(&mut t.steps);
    let after_comb_t = t.clone();
    let shape = |r: &Robot| -> Shape { r.at.iter().copied().collect() };
    let (cs, ct) = (
        Comb::of(&shape(&s)).expect("combing makes a comb"),
        Comb::of(&shape(&t)).expect("combing makes a comb"),
    );
    let u = cs.union(&ct);
    s.to_common_comb(&u);
    let common_s = std::mem::take(&mut s.steps);
    t.to_common_comb(&u);
    assert_eq!(shape(&s), shape(&t), "one common comb");
    let ccs_t = std::mem::take(&mut t.steps);
    let (phase3, back_comb) = join_reversed(&mut s, &t, &t0, &comb_t, &after_comb_t, &ccs_t);
    Reconfiguration {
        target,
        phases: [comb_s, common_s, phase3, back_comb],
        end: s,
    }
}

fn sorted<'a>(
    pairs: impl Iterator<Item = &'a (usize, usize)>,
) -> impl Iterator<Item = (usize, usize)> {
    let mut v: Vec<(usize, usize)> = pairs.copied().collect();
    v.sort_unstable();
    v.into_iter()
}

pub(super) fn renamed(e: Event, name: &[usize]) -> Event {
    let n = |m: ModuleId| name[m as usize] as ModuleId;
    match e {
        Event::Slide {
            module,
            from,
            to,
            pivot,
        } => Event::Slide {
            module: n(module),
            from,
            to,
            pivot: pivot.map(n),
        },
        Event::Tunnel { module, path } => Event::Tunnel {
            module: n(module),
            path,
        },
        Event::Attach { module, other } => Event::Attach {
            module: n(module),
            other: n(other),
        },
        Event::Detach { module, other } => Event::Detach {
            module: n(module),
            other: n(other),
        },
        e => e,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algorithms::comb::random_polyomino;
    use rand::SeedableRng;

    fn cells(r: &Robot) -> Shape {
        r.at.iter().copied().collect()
    }

    /// Replays `steps` from `start`, checking before each tunnel the
    /// paper's preconditions on the robot's attachments: the start a leaf
    /// attached only to the path, every leg cell between turns attached to
    /// nothing off the path, the exit free. Returns the tunnels' turns.
    fn tunnel_turns(start: &Robot, steps: &[Vec<Event>]) -> Vec<usize> {
        let mut r = start.clone();
        let mut ks = Vec::new();
        for es in steps {
            for e in es {
                if let Event::Tunnel { path, .. } = e {
                    let p: Vec<(i32, i32)> = path.iter().map(|c| (c.x, c.y)).collect();
                    let on_path = |c: (i32, i32)| p.contains(&c);
                    let partners = |c: (i32, i32)| -> Vec<(i32, i32)> {
                        let m = r.get(c).expect("path occupied");
                        r.attached
                            .iter()
                            .filter(|&&(a, b)| a == m || b == m)
                            .map(|&(a, b)| r.at[if a == m { b } else { a }])
                            .collect()
                    };
                    assert_eq!(partners(p[0]), vec![p[1]], "leaf {p:?}");
                    assert!(r.get(*p.last().unwrap()).is_none(), "exit free {p:?}");
                    for w in 1..p.len() - 1 {
                        let straight = (p[w].0 - p[w - 1].0, p[w].1 - p[w - 1].1)
                            == (p[w + 1].0 - p[w].0, p[w + 1].1 - p[w].1);
                        if straight {
                            assert!(
                                partners(p[w]).into_iter().all(on_path),
                                "leg cell {:?} attached off the path {p:?}",
                                p[w]
                            );
                        }
                    }
                    ks.push(crate::lattice::path_turns(path).len());
                }
            }
            r.apply(es);
        }
        ks
    }

    #[test]
    fn the_common_comb_is_the_handle_and_a_right_fill_of_the_union() {
        let u = Comb {
            x0: 0,
            y0: 0,
            teeth: vec![3, 0, 2, 1],
        };
        // 4 handle + 4 teeth: tooth 3 (1), tooth 2 (2), then 1 of tooth 0.
        let want: Shape = [
            (0, 0),
            (1, 0),
            (2, 0),
            (3, 0),
            (3, 1),
            (2, 1),
            (2, 2),
            (0, 1),
        ]
        .into_iter()
        .collect();
        assert_eq!(u.common_comb(8), want);
        assert_eq!(Comb::of(&want).unwrap().teeth, vec![1, 0, 2, 1]);
        assert!(Comb::of(&[(0, 0), (0, 2)].into_iter().collect()).is_none());
    }

    #[test]
    fn theorem_1_reaches_the_target_through_the_common_comb_by_one_and_two_tunnels() {
        let mut tunnels = [0usize; 3];
        for seed in 0..40 {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let m = 6 + (seed as usize % 5) * 7;
            let (src, tgt) = (random_polyomino(m, &mut rng), random_polyomino(m, &mut rng));
            let plan = reconfigure(&src, &tgt);
            assert_eq!(cells(&plan.end), plan.target, "seed {seed}");
            // Phase by phase, from the source: comb, common comb, back.
            let mut r = Robot::new(&src);
            let [comb, common, back_common, back_comb] = &plan.phases;
            for es in comb {
                r.apply(es);
            }
            let cs = Comb::of(&cells(&r)).expect("a comb");
            let forward = tunnel_turns(&r, common);
            for es in common {
                r.apply(es);
            }
            let mut t = Robot::new(&plan.target);
            t.comb();
            let u = cs.union(&Comb::of(&cells(&t)).unwrap());
            assert_eq!(cells(&r), u.common_comb(m), "seed {seed}");
            let backward = tunnel_turns(&r, back_common);
            assert!(
                back_comb
                    .iter()
                    .flatten()
                    .all(|e| !matches!(e, Event::Tunnel { .. }))
            );
            for k in forward.iter().chain(&backward) {
                assert!((1..=2).contains(k), "seed {seed}: a {k}-TUNNEL");
                tunnels[*k] += 1;
            }
            // At most one tunnel per meta-module moved, one step each.
            assert!(forward.len() <= m && backward.len() <= m);
        }
        assert!(tunnels[1] > 0 && tunnels[2] > 0, "{tunnels:?}");
    }
}
