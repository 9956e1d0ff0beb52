//! Speed of the FCC collision check: one exact sweep check, one compiled
//! table check, and certification of a ≥100k-move synthetic schedule.
//!
//! `cargo bench --bench geometry`

use criterion::{Criterion, criterion_group, criterion_main};
use reconfcheck::algorithms::random_walk::{WalkParams, collision_free, walk};
use reconfcheck::certify::{Options, certify};
use reconfcheck::geometry::FccSweep;
use reconfcheck::geometry::{SweepInput, SweepModel};
use reconfcheck::geometry::{offsets_within_reach, table};
use reconfcheck::lattice::ModuleId;
use reconfcheck::lattice::{Cell, Configuration, FccLattice, Lattice, Motion, Route};
use rustc_hash::FxHashSet;
use std::hint::black_box;

/// One move (0→4, hexagonal) on a pivot with every other cell within
/// reach occupied: 52 static modules to sweep against.
fn dense_scene() -> (Configuration, Vec<(ModuleId, Option<ModuleId>, Motion)>) {
    let l = FccLattice;
    let pivot = Cell::new(0, 0, 0);
    let (from, to) = (l.neighbour(pivot, 0), l.neighbour(pivot, 4));
    let mut config = Configuration::new();
    config.insert(0, pivot).unwrap();
    config.insert(1, from).unwrap();
    let mut id = 2;
    for o in offsets_within_reach() {
        let c = o.from(pivot);
        if c != from && c != to {
            config.insert(id, c).unwrap();
            id += 1;
        }
    }
    let m = Motion::Rotate {
        from,
        to,
        pivot,
        route: Route::Hexagonal,
    };
    (config, vec![(1, Some(0), m)])
}

fn sweep_checks(c: &mut Criterion) {
    table(); // derived once per process, outside the measurement
    let (config, moves) = dense_scene();
    let moving: FxHashSet<ModuleId> = [1].into_iter().collect();
    for (name, exact) in [
        ("exact sweep check (1 move, 52 neighbours)", true),
        ("compiled table check (1 move, 52 neighbours)", false),
    ] {
        c.bench_function(name, |b| {
            b.iter(|| {
                let input = SweepInput {
                    lattice: &FccLattice,
                    config: &config,
                    moves: &moves,
                    moving: &moving,
                    epsilon: reconfcheck::geometry::Tolerance::DEFAULT,
                    exact,
                };
                black_box(FccSweep.check_step(&input))
            })
        });
    }
}

fn certification(c: &mut Criterion) {
    table();
    let p = WalkParams {
        width: 80,
        depth: 80,
        walkers: 600,
        steps: 300,
        activity: 0.8,
        seed: 1,
        geometric: true,
    };
    let s = walk(&p, &collision_free);
    let moves = s.move_count();
    assert!(moves >= 100_000, "{moves} moves");
    let r = certify(&s, &Options::default()).unwrap();
    assert!(r.certified);
    eprintln!(
        "synthetic schedule: {} modules, {} steps, {moves} moves",
        s.modules.len(),
        s.steps.len()
    );
    let mut g = c.benchmark_group("certify");
    g.sample_size(10);
    g.bench_function(format!("random walk, {moves} moves, compiled"), |b| {
        b.iter(|| black_box(certify(&s, &Options::default()).unwrap().certified))
    });
    g.bench_function(
        format!("random walk, {moves} moves, lattice checks only"),
        |b| {
            let opts = Options::lattice_only();
            b.iter(|| black_box(certify(&s, &opts).unwrap().certified))
        },
    );
    g.finish();
}

criterion_group!(benches, sweep_checks, certification);
criterion_main!(benches);
