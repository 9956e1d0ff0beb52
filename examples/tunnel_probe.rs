//! Probe: does a 1-TUNNEL((x, y + 1), (x + 1, y)) of a two-meta-module
//! robot exist in the contracted atom model, in place? (seed 004, issue
//! #18; the result is recorded in docs/atoms.md.)
//!
//! The robot: meta-module A (the leaf that tunnels) on top of B (the
//! turn); the goal: B's cells and E's, beside B, occupied (by any atoms:
//! atoms are interchangeable), every face contracted, every touching pair
//! attached. States are canonical (atoms sorted by position and faces), so
//! permutations of identical atoms count once; the search is best-first
//! (operations so far + 2 × distance of misplaced atoms to the free goal
//! cells) over single atom operations (`--pairs`: also every pair of face
//! operations in one step, for inchworm moves around a cycle of bonds),
//! with the certifier's own step rules (`atom_search::Scene::step`: arm
//! kinematics, exact moving-box collisions, connectivity). Every body and
//! arm must stay inside the union of the start's and the goal's bounding
//! boxes (the in-place claim); `--loose` widens it by one atom all round,
//! `--corner` adds the meta cell between the two legs (inside the robot's
//! bounding box wherever a comb tunnels), `--with-l` adds the meta-module
//! the turn hangs on, opposite the exit (the frame).
//!
//! ```sh
//! cargo run --release --example tunnel_probe                  # 2D slice, in place
//! cargo run --release --example tunnel_probe -- --pairs
//! cargo run --release --example tunnel_probe -- --loose
//! cargo run --release --example tunnel_probe -- --three-d --max-states 3000000
//! cargo run --release --example tunnel_probe -- --corner --with-l
//! ```

use reconfcheck::geometry::atom::contact_face;
use reconfcheck::geometry::atom_search::{Op, Scene};
use reconfcheck::lattice::{Cell, Face};
use rustc_hash::FxHashMap;
use std::cmp::Reverse;
use std::collections::{BTreeSet, BinaryHeap};

struct Setup {
    loose: bool,
    corner: bool,
    with_l: bool,
    pairs: bool,
    zmax: i32,
    max_states: usize,
}

impl Setup {
    fn inside(&self, c: Cell) -> bool {
        let m = self.loose as i32;
        let in_box = |x0: i32, x1: i32, y0: i32, y1: i32| {
            (x0 - m..=x1 + m).contains(&c.x) && (y0 - m..=y1 + m).contains(&c.y)
        };
        (0..=self.zmax).contains(&c.z)
            && ((self.with_l && in_box(-2, -1, 0, 1))
                || in_box(0, 3, 0, 1)
                || in_box(0, 1, 0, 3)
                || (self.corner && in_box(2, 3, 2, 3)))
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let has = |f: &str| args.iter().any(|a| a == f);
    let max_states = args
        .iter()
        .position(|a| a == "--max-states")
        .and_then(|i| args.get(i + 1))
        .map_or(3_000_000, |v| v.parse().expect("--max-states N"));
    let set = Setup {
        loose: has("--loose"),
        corner: has("--corner"),
        with_l: has("--with-l"),
        pairs: has("--pairs"),
        zmax: has("--three-d") as i32,
        max_states,
    };
    let layers = |cells: &[(i32, i32)]| -> Vec<Cell> {
        (0..=set.zmax)
            .flat_map(|z| cells.iter().map(move |&(x, y)| Cell::new(x, y, z)))
            .collect()
    };
    let (a, b, e) = (
        [(0, 2), (1, 2), (0, 3), (1, 3)],
        [(0, 0), (1, 0), (0, 1), (1, 1)],
        [(2, 0), (3, 0), (2, 1), (3, 1)],
    );
    let l = [(-2, 0), (-1, 0), (-2, 1), (-1, 1)];
    let with_l = set.with_l;
    let mut pos: Vec<Cell> = layers(&b).into_iter().chain(layers(&a)).collect();
    if with_l {
        pos.extend(layers(&l));
    }
    let ext = vec![[false; 6]; pos.len()];
    let bonds = Scene::all_bonds(&pos, &ext);
    let start = Scene { pos, ext, bonds }.canonical().0;
    let mut goal: BTreeSet<Cell> = layers(&b).into_iter().chain(layers(&e)).collect();
    if with_l {
        goal.extend(layers(&l));
    }
    let mut faces = vec![Face::PosX, Face::NegX, Face::PosY, Face::NegY];
    if set.zmax > 0 {
        faces.extend([Face::PosZ, Face::NegZ]);
    }
    let at_rest = |s: &Scene| s.ext.iter().all(|e| e.iter().all(|&x| !x));
    let is_goal = |s: &Scene| {
        at_rest(s)
            && s.pos.iter().copied().collect::<BTreeSet<_>>() == goal
            && s.bonds == Scene::all_bonds(&s.pos, &s.ext)
    };
    let h = |s: &Scene| -> i64 {
        let occ: BTreeSet<Cell> = s.pos.iter().copied().collect();
        let free: Vec<Cell> = goal.iter().copied().filter(|g| !occ.contains(g)).collect();
        s.pos
            .iter()
            .filter(|c| !goal.contains(c))
            .map(|c| {
                free.iter()
                    .map(|g| (*g - *c).l1() as i64)
                    .min()
                    .unwrap_or(0)
            })
            .sum()
    };
    let mut parent: FxHashMap<Scene, Option<(Scene, Vec<Op>)>> = FxHashMap::default();
    parent.insert(start.clone(), None);
    let mut states = vec![start.clone()];
    let mut open = BinaryHeap::from([Reverse((2 * h(&start), 0usize, 0usize))]);
    let t = std::time::Instant::now();
    while let Some(Reverse((_, g, id))) = open.pop() {
        let s = states[id].clone();
        if is_goal(&s) {
            let mut steps = Vec::new();
            let mut cur = s;
            while let Some(Some((p, ops))) = parent.get(&cur).cloned() {
                steps.push(ops);
                cur = p;
            }
            steps.reverse();
            let ops: usize = steps.iter().map(Vec::len).sum();
            println!(
                "found: {} steps, {ops} atom operations; {} states, {:.1} s",
                steps.len(),
                parent.len(),
                t.elapsed().as_secs_f64()
            );
            for st in &steps {
                println!("  {st:?}");
            }
            return;
        }
        if parent.len() >= set.max_states {
            println!("stopped at {} states", parent.len());
            break;
        }
        let n = s.pos.len();
        let mut single: Vec<Op> = Vec::new();
        for a in 0..n {
            for &f in &faces {
                single.push(if s.ext[a][f.index()] {
                    Op::Contract(a, f)
                } else {
                    Op::Expand(a, f)
                });
            }
        }
        let face_ops = single.clone();
        single.extend(s.bonds.iter().map(|&(a, b)| Op::Detach(a, b)));
        for a in 0..n {
            for b in a + 1..n {
                if !s.bonds.contains(&(a, b))
                    && contact_face(s.pos[a], &s.ext[a], s.pos[b], &s.ext[b]).is_some()
                {
                    single.push(Op::Attach(a, b));
                }
            }
        }
        let mut groups: Vec<Vec<Op>> = single.iter().map(|&o| vec![o]).collect();
        if set.pairs {
            for i in 0..face_ops.len() {
                for j in i + 1..face_ops.len() {
                    groups.push(vec![face_ops[i], face_ops[j]]);
                }
            }
        }
        // The frame: the atom on B's corner cell (always a goal cell).
        let anchors: Vec<usize> = (0..n)
            .find(|&i| s.pos[i] == Cell::new(if with_l { -2 } else { 0 }, 0, 0))
            .into_iter()
            .collect();
        let anchors = if anchors.is_empty() { vec![0] } else { anchors };
        for ops in groups {
            let Some(next) = s.step(&ops, &anchors, 1e-6) else {
                continue;
            };
            let in_place = next.pos.iter().zip(&next.ext).all(|(p, e)| {
                set.inside(*p)
                    && faces
                        .iter()
                        .all(|f| !e[f.index()] || set.inside(*p + f.dir()))
            });
            let next = next.canonical().0;
            if !in_place || parent.contains_key(&next) {
                continue;
            }
            parent.insert(next.clone(), Some((s.clone(), ops)));
            open.push(Reverse((g as i64 + 1 + 2 * h(&next), g + 1, states.len())));
            states.push(next);
        }
    }
    let rest: BTreeSet<Vec<Cell>> = parent
        .keys()
        .filter(|s| at_rest(s))
        .map(|s| s.pos.clone())
        .collect();
    println!(
        "not found: {} states ({} configurations at rest), {:.1} s",
        parent.len(),
        rest.len(),
        t.elapsed().as_secs_f64()
    );
}
