//! Speed of the mechanical check (issue #4 item 6): replaying a schedule's
//! every intermediate structure with reuse between steps (`incremental`:
//! each component's sparse Cholesky factor is kept and preconditions CG,
//! warm-started, while only its loads or at most one body changed) against
//! factoring every step from scratch.
//!
//! `cargo bench --bench mechanics`
//!
//! * `scaffold` — seed 000's scaffold of a 3-pyramid, b = 6 (250 modules
//!   over a fixed sandbox, 194 steps): one structure that grows;
//! * `islands` — `study::synthetic::islands_with_walkers`: 3 × 3 blocks of
//!   6 × 6 × 4 catoms with walkers rolling over them: many structures,
//!   few of which change per step.

use criterion::{Criterion, criterion_group, criterion_main};
use reconfcheck::algorithms::scaffold::{ShapeSpec, scaffold_schedule};
use reconfcheck::certify::replay;
use reconfcheck::mechanics::Model;
use reconfcheck::schedule::Schedule;
use reconfcheck::study::synthetic::islands_with_walkers;
use std::hint::black_box;
use std::time::Duration;

/// Replays `s` and returns the largest utilisation seen (kept, so the
/// work cannot be optimised away).
fn run(s: &Schedule, m: &Model, incremental: bool) -> f64 {
    let mut max = 0.0f64;
    replay(s, m, incremental, |_, _, a, _| {
        max = max.max(a.max_utilisation)
    })
    .expect("replay");
    max
}

fn compare(c: &mut Criterion, name: &str, s: &Schedule) {
    let m = Model::default_catom();
    // Both modes must agree before their speeds are compared.
    let (a, b) = (run(s, &m, true), run(s, &m, false));
    assert!((a - b).abs() <= 1e-6 * a.max(1e-9), "{name}: {a} vs {b}");
    let mut g = c.benchmark_group(name);
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(30));
    g.bench_function("incremental", |bench| {
        bench.iter(|| run(black_box(s), &m, true))
    });
    g.bench_function("from_scratch", |bench| {
        bench.iter(|| run(black_box(s), &m, false))
    });
    g.finish();
}

fn scaffold(c: &mut Criterion) {
    let s = scaffold_schedule(&ShapeSpec::Pyramid { h: 3 }, 6).expect("pyramid h = 3, b = 6");
    compare(c, "mechanics_scaffold_pyramid_h3_b6", &s);
}

fn islands(c: &mut Criterion) {
    let s = islands_with_walkers(3, 6, 4, 12, 40, 1);
    compare(c, "mechanics_islands_3x3_6x6x4", &s);
}

criterion_group!(benches, scaffold, islands);
criterion_main!(benches);
