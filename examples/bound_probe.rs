//! Probe: how tight is the screen's bound of `1/λ` (limit analysis off)
//! against the limit analysis, at chosen steps of a CSG shape's scaffold?
//! `cargo run --release --example bound_probe -- SHAPE.csg B STEP...`
use reconfcheck::certify::RangedReplay;
use reconfcheck::mechanics::{Analyzer, Model};
use reconfcheck::study::b_study::family;
use std::path::Path;
use std::time::Instant;

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let model = Model::load(Path::new("models/catom-3.6mm.toml")).unwrap();
    let t = Instant::now();
    let generate = family("csg", model.spacing * 1e3, None, Some(Path::new(&a[0]))).unwrap();
    let b: usize = a[1].parse().unwrap();
    let schedule = generate(b).unwrap();
    let n = schedule.steps.len();
    eprintln!("{n} steps generated in {:.1}s", t.elapsed().as_secs_f64());
    let m = model.at_spacing_checked(schedule.spacing.metres()).unwrap();
    let replay = RangedReplay::new(&schedule, &model, 0.0, 40).unwrap();
    for step in a[2..].iter().map(|s| s.parse::<usize>().unwrap()) {
        replay
            .run_step(step, &|_, s, _, _| {
                let run = |la: bool, hops: usize| {
                    let mut z = Analyzer::new(m.clone(), false);
                    z.settings.limit_analysis = la;
                    z.settings.region_hops = hops;
                    let t = Instant::now();
                    let r = z.analyse(s);
                    let u = r.links.iter().map(|l| l.utilisation).fold(0.0, f64::max);
                    (
                        r.max_utilisation,
                        u,
                        r.region_analyses,
                        t.elapsed().as_secs_f64(),
                    )
                };
                let mut line = format!(
                    "step {step}: {} bodies, {} links;",
                    s.bodies.len(),
                    s.links.len()
                );
                for hops in 0..=3 {
                    let (bound, u, nb, tb) = run(false, hops);
                    line += &format!(
                        " hops {hops}: {bound:.4} ({nb} region analyses, {tb:.2}s, u {u:.4});"
                    );
                }
                if std::env::var("EXACT").is_ok() {
                    let (exact, _, _, te) = run(true, 0);
                    line += &format!(" exact {exact:.4} ({te:.1}s)");
                }
                println!("{line}");
            })
            .unwrap();
    }
}
