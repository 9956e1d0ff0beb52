//! Probe: could the agents of a schedule be loads rather than bodies
//! (issue #20)? Per step it builds the mechanical structure (no analysis)
//! and splits its free bodies into **settled** modules (they never move
//! again) and **agents** (resting now, moving later), then counts
//!
//! * how many connectors hold each resting agent (one: statically
//!   determinate, exactly a load on its neighbour; more: it adds stiffness);
//! * the bodies that come or go between consecutive steps: all of them
//!   (what changes the stiffness matrix today), the settled ones alone
//!   (what would change it with every agent a load), and those left after
//!   pruning the determinate trees (bodies held by one connector, then
//!   their parents, …; exact).
//!
//! `cargo run --release --example agent_probe -- SCENARIO` (seconds: no
//! mechanics is solved). Figures in `docs/mechanics.md`, "Agents as loads".
use reconfcheck::certify::{World, advance};
use reconfcheck::mechanics::{End, SceneRef, Structure};
use reconfcheck::scenario::Scenario;
use rustc_hash::{FxHashMap, FxHashSet};

type Key = (u32, [i32; 3]);

/// Bodies that stay after pruning every free body held by a single
/// connector (a ground contact keeps a body: it is a support).
fn core(st: &Structure) -> Vec<bool> {
    let n = st.bodies.len();
    let mut degree = vec![0usize; n];
    let mut grounded = vec![false; n];
    let mut adjacent: Vec<Vec<usize>> = vec![Vec::new(); n];
    for l in &st.links {
        degree[l.a] += 1;
        match l.b {
            End::Body(b) => {
                degree[b] += 1;
                adjacent[l.a].push(b);
                adjacent[b].push(l.a);
            }
            End::Ground(_) => grounded[l.a] = true,
        }
    }
    let prunable = |b: usize, d: usize| d == 1 && !grounded[b] && !st.bodies[b].fixed;
    let mut kept = vec![true; n];
    let mut stack: Vec<usize> = (0..n).filter(|&b| prunable(b, degree[b])).collect();
    while let Some(b) = stack.pop() {
        if !kept[b] {
            continue;
        }
        kept[b] = false;
        for &o in &adjacent[b] {
            if kept[o] {
                degree[o] -= 1;
                if prunable(o, degree[o]) {
                    stack.push(o);
                }
            }
        }
    }
    kept
}

fn main() {
    let path = std::env::args()
        .nth(1)
        .expect("usage: agent_probe SCENARIO");
    let sc = Scenario::load(std::path::Path::new(&path)).unwrap();
    let s = reconfcheck::algorithms::generate(&sc).unwrap();
    let n = s.steps.len();
    // The last step (0-based) in which each module moves.
    let mut world = World::initial(&s).unwrap();
    let mut last: FxHashMap<u32, usize> = FxHashMap::default();
    for k in 0..n {
        let (_, plan, _) = advance(&mut world, &s, k, |_| ()).unwrap();
        for m in &plan.moving {
            last.insert(*m, k);
        }
    }
    let mut world = World::initial(&s).unwrap();
    let mut previous: [FxHashSet<Key>; 3] = Default::default();
    let mut changed = [0usize; 3];
    let mut by_changes = [[0usize; 21]; 3];
    let mut holds = [0usize; 7];
    for k in 0..n {
        advance(&mut world, &s, k, |ctx| {
            let scene = SceneRef {
                lattice: ctx.world.lattice(),
                ground: ctx.world.ground(),
                config: ctx.world.config(),
                fixed: ctx.world.fixed(),
                exclude: &ctx.plan.moving,
                latched: &|a, b| ctx.world.latched(a, b),
            };
            let st = Structure::build(&scene, &ctx.plan.resolved_moves());
            let agent = |b: usize| last.get(&st.bodies[b].module).is_some_and(|&l| l > k);
            let mut degree = vec![0usize; st.bodies.len()];
            for l in &st.links {
                degree[l.a] += 1;
                if let End::Body(b) = l.b {
                    degree[b] += 1;
                }
            }
            let kept = core(&st);
            let mut sets: [FxHashSet<Key>; 3] = Default::default();
            for (i, b) in st.bodies.iter().enumerate().filter(|(_, b)| !b.fixed) {
                let key = (b.module, b.cell.to_array());
                sets[0].insert(key);
                if agent(i) {
                    holds[degree[i].min(6)] += 1;
                } else {
                    sets[1].insert(key);
                }
                if kept[i] {
                    sets[2].insert(key);
                }
            }
            for w in 0..3 {
                let c = sets[w].symmetric_difference(&previous[w]).count();
                changed[w] += c;
                by_changes[w][c.min(20)] += 1;
            }
            if k % 250 == 0 {
                println!(
                    "step {}: free bodies {}, settled {}, movers {}",
                    k + 1,
                    sets[0].len(),
                    sets[1].len(),
                    st.hanging.len()
                );
            }
            previous = sets;
        })
        .unwrap();
    }
    println!("{n} steps");
    println!("resting agents by connectors holding them (0, 1, …, 6+): {holds:?}");
    for (w, name) in ["every body", "settled only", "after pruning trees"]
        .iter()
        .enumerate()
    {
        println!(
            "{name}: {} bodies came or went; steps by that count (0, 1, …, 20+): {:?}",
            changed[w], by_changes[w]
        );
    }
}
