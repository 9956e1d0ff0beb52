//! Probe: per-step statistics of a scenario's mechanical replay (bodies,
//! links, movers, bodies added/removed, factorisations, CG iterations).
//! `cargo run --release --example mech_stats -- SCENARIO [INCREMENTAL(1|0)] [STEPS]`
//! prints every 50th step, or every step with `ALL=1` in the environment.
use reconfcheck::certify::replay;
use reconfcheck::mechanics::Model;
use reconfcheck::scenario::Scenario;
use rustc_hash::FxHashSet;
use std::time::Instant;
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let sc = Scenario::load(std::path::Path::new(&args[0])).unwrap();
    let t = Instant::now();
    let s = reconfcheck::algorithms::generate(&sc).unwrap();
    eprintln!(
        "generated {} steps in {:.2}s",
        s.steps.len(),
        t.elapsed().as_secs_f64()
    );
    let incremental = args.get(1).map(|a| a == "1").unwrap_or(true);
    let limit: usize = args
        .get(2)
        .map(|a| a.parse().unwrap())
        .unwrap_or(usize::MAX);
    let mut s = s;
    s.steps.truncate(limit);
    let m = Model::default_catom();
    let mut prev: FxHashSet<(u32, [i32; 3])> = FxHashSet::default();
    let t = Instant::now();
    let mut last = Instant::now();
    let mut tot_its = 0;
    replay(&s, &m, incremental, |k, st, a, _| {
        let cur: FxHashSet<(u32, [i32; 3])> = st
            .bodies
            .iter()
            .filter(|b| !b.fixed)
            .map(|b| (b.module, b.cell.to_array()))
            .collect();
        let added = cur.difference(&prev).count();
        let removed = prev.difference(&cur).count();
        tot_its += a.iterations;
        if std::env::var("ALL").is_ok() || k % 50 == 0 || k < 5 {
            println!(
                "step {k}: free {} links {} hanging {} +{added} -{removed} factorisations {} its {} max_u {:.3} dt {:.3}s",
                cur.len(),
                st.links.len(),
                st.hanging.len(),
                a.factorizations,
                a.iterations,
                a.max_utilisation,
                last.elapsed().as_secs_f64()
            );
        }
        last = Instant::now();
        prev = cur;
    })
    .unwrap();
    println!("total {:.2}s its {tot_its}", t.elapsed().as_secs_f64());
}
