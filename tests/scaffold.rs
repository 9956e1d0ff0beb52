//! Seed 000 scaffold schedules certify clean.

use reconfcheck::algorithms::scaffold::{ShapeSpec, scaffold_schedule};
use reconfcheck::certify::{Options, certify};

fn certify_clean(shape: ShapeSpec) -> reconfcheck::schedule::Schedule {
    let s = scaffold_schedule(&shape, 6).unwrap();
    let opts = Options {
        lattice_only: reconfcheck::geometry::sweep_model(s.lattice).is_none(),
        ..Default::default()
    };
    let r = certify(&s, &opts).unwrap();
    assert!(r.certified, "{shape:?}: {}", r.summary());
    s
}

#[test]
fn pyramid_h2_certifies_clean() {
    let s = certify_clean(ShapeSpec::Pyramid { h: 2 });
    eprintln!("h2: {} steps", s.steps.len());
}

#[test]
fn pyramids_h3_h4_certify_clean() {
    for h in 3..=4 {
        let s = certify_clean(ShapeSpec::Pyramid { h });
        eprintln!(
            "pyramid h{h}: {} steps, {} moves",
            s.steps.len(),
            s.move_count()
        );
    }
}
