//! Certification of FCC schedules with the exact catom geometry.

use reconfcheck::algorithms::random_walk::{WalkParams, collision_free, walk};
use reconfcheck::certify::{Options, ViolationKind, certify};

fn params(seed: u64, geometric: bool) -> WalkParams {
    WalkParams {
        width: 10,
        depth: 10,
        walkers: 30,
        steps: 25,
        activity: 0.8,
        seed,
        geometric,
    }
}

fn count(r: &reconfcheck::certify::Report, k: ViolationKind) -> usize {
    r.violations
        .iter()
        .chain(&r.warnings)
        .filter(|v| v.kind == k)
        .count()
}

#[test]
fn walks_planned_with_the_derived_rules_certify_without_collisions_or_sliding() {
    for seed in 0..3 {
        let s = walk(&params(seed, true), &collision_free);
        assert!(s.move_count() > 100, "too few moves: {}", s.move_count());
        let r = certify(&s, &Options::default()).unwrap();
        assert!(r.checks.iter().any(|c| c == "collision"));
        assert!(
            r.certified,
            "{:#?}",
            &r.violations[..r.violations.len().min(5)]
        );
        assert_eq!(count(&r, ViolationKind::SlidingContact), 0);
    }
}

#[test]
fn unplanned_walks_collide_and_both_paths_report_the_same_contacts() {
    let s = walk(&params(11, false), &|_, _, _| true);
    let compiled = certify(&s, &Options::default()).unwrap();
    let exact = certify(
        &s,
        &Options {
            exact: true,
            ..Options::default()
        },
    )
    .unwrap();
    assert!(count(&compiled, ViolationKind::Collision) > 0);
    assert!(!compiled.certified);
    let key = |r: &reconfcheck::certify::Report| {
        let mut v: Vec<_> = r
            .violations
            .iter()
            .chain(&r.warnings)
            .filter(|v| {
                matches!(
                    v.kind,
                    ViolationKind::Collision | ViolationKind::SlidingContact
                )
            })
            .map(|v| (v.step, v.modules.clone(), v.kind))
            .collect();
        v.sort_by(|a, b| format!("{a:?}").cmp(&format!("{b:?}")));
        v
    };
    assert_eq!(key(&compiled), key(&exact));
}
