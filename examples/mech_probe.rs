//! Probe: time the mechanics replay of a synthetic workload.
//! `cargo run --release --example mech_probe -- N W H WALKERS STEPS INCREMENTAL(0|1)`
use reconfcheck::certify::replay;
use reconfcheck::mechanics::Model;
use reconfcheck::study::synthetic::islands_with_walkers;
use std::time::Instant;
fn main() {
    let a: Vec<i64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    let s = islands_with_walkers(
        a[0] as i32,
        a[1] as i32,
        a[2] as i32,
        a[3] as usize,
        a[4] as usize,
        1,
    );
    let m = Model::default_catom();
    let t = Instant::now();
    let (mut its, mut factorizations) = (0, 0);
    replay(&s, &m, a[5] != 0, |_, _, r, _| {
        its += r.iterations;
        factorizations += r.factorizations;
    })
    .unwrap();
    println!(
        "{} modules, {} steps: {:.2}s, CG iterations {its}, factorisations {factorizations}",
        s.modules.len(),
        s.steps.len(),
        t.elapsed().as_secs_f64()
    );
}
