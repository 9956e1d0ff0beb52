//! Generate + certify times of seed 003's large cases (issue #5, "scale").
//! Run with `cargo bench --bench active_subtraction`. The SAS cases have
//! one movement per step (46,160 steps for the 50 × 50 one), so they
//! measure the per-step cost of certification.

use criterion::{Criterion, criterion_group, criterion_main};
use reconfcheck::algorithms;
use reconfcheck::certify::{Options, certify};
use reconfcheck::scenario::Scenario;
use std::path::Path;

fn generate_and_certify(c: &mut Criterion) {
    let mut g = c.benchmark_group("active-subtraction");
    g.sample_size(10);
    for name in [
        "humanoid-20x20-pas",
        "humanoid-20x20-sas",
        "random-50x50",
        "random-50x50-sas",
    ] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenarios/{name}.toml"));
        let sc = Scenario::load(&path).unwrap();
        g.bench_function(format!("{name}/generate"), |b| {
            b.iter(|| algorithms::generate(&sc).unwrap())
        });
        g.bench_function(format!("{name}/generate+certify"), |b| {
            b.iter(|| {
                let s = algorithms::generate(&sc).unwrap();
                let r = certify(&s, &Options::default()).unwrap();
                assert!(r.certified);
            })
        });
    }
    g.finish();
}

criterion_group!(benches, generate_and_certify);
criterion_main!(benches);
