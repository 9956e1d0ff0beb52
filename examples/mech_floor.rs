//! The floor of any factor-reusing mechanical replay of a scenario: the
//! time of one forward/back substitution per step, and of one numeric
//! factorisation per step, summed over the schedule from every `EVERY`-th
//! step (best of three solves; the factor as `direct::Factor::new` does it).
//! `cargo run --release --example mech_floor -- SCENARIO EVERY`
use reconfcheck::certify::World;
use reconfcheck::mechanics::Factor;
use reconfcheck::mechanics::Vec6;
use reconfcheck::mechanics::{Analyzer, Model};
use reconfcheck::mechanics::{SceneRef, Structure};
use reconfcheck::scenario::Scenario;
use std::time::Instant;
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let sc = Scenario::load(std::path::Path::new(&args[0])).unwrap();
    let s = reconfcheck::algorithms::generate(&sc).unwrap();
    let every: usize = args[1].parse().unwrap();
    let mut world = World::initial(&s).unwrap();
    let m = Model::default_catom();
    let mut an = Analyzer::new(m.at_spacing(s.spacing.metres()), false);
    let (mut solve_sum, mut factor_sum) = (0.0, 0.0);
    for (k, step) in s.steps.iter().enumerate() {
        let plan = world.resolve(k + 1, step).unwrap();
        if (k + 1) % every == 0 {
            let scene = SceneRef {
                lattice: world.lattice(),
                ground: world.ground(),
                config: world.config(),
                fixed: world.fixed(),
                exclude: &plan.moving,
                latched: &|a, b| world.latched(a, b),
            };
            let st = Structure::build(&scene, &plan.resolved_moves());
            let kmat = an.stiffness_matrix(&st);
            let t = Instant::now();
            let Some(f) = Factor::new(&kmat) else {
                continue;
            };
            let tf = t.elapsed().as_secs_f64();
            let mut best = f64::MAX;
            for _ in 0..3 {
                let mut x = vec![Vec6::repeat(1.0); kmat.len()];
                let t = Instant::now();
                f.solve_in_place(&mut x);
                best = best.min(t.elapsed().as_secs_f64());
            }
            solve_sum += best * every as f64;
            factor_sum += tf * every as f64;
            println!(
                "step {}: blocks {} factor {:.3}s solve {:.4}s",
                k + 1,
                kmat.len(),
                tf,
                best
            );
        }
        world.apply(&plan);
    }
    println!(
        "estimated sum over all steps: one solve each {:.1}s, one factor each {:.1}s",
        solve_sum, factor_sum
    );
}
