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

/// A ground-layer catom (id 11, cell (0,0,0)) rolling under a pivot one
/// layer up (id 10, cell (0,0,1)) to the next ground cell (1,0,0) by the
/// hexagonal route; fixed modules behind hold the pivot. `mirror` flips
/// the scene through the plane x = ½ d (FCC cells: x ↦ 1 − x in even
/// layers, x ↦ −x in odd ones, whose centres sit ½ d over).
fn dip_under_a_pivot(ground_layer: Option<i32>, mirror: bool) -> reconfcheck::schedule::Schedule {
    use reconfcheck::lattice::{Cell, Ground, LatticeKind, Route};
    use reconfcheck::schedule::{Event, Length, ModuleSpec, Schedule, Step};
    let m = |c: Cell| match (mirror, c.z.rem_euclid(2)) {
        (false, _) => c,
        (true, 0) => Cell::new(1 - c.x, c.y, c.z),
        (true, _) => Cell::new(-c.x, c.y, c.z),
    };
    let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(3.6));
    s.ground = ground_layer.map(|layer| Ground { layer });
    for (id, x) in [(0, -1), (1, 0), (2, 1), (3, 2)] {
        let cell = m(Cell::new(x, 1, 0));
        s.modules.push(ModuleSpec {
            id,
            cell,
            fixed: true,
        });
    }
    for (id, cell) in [(10, Cell::new(0, 0, 1)), (11, Cell::new(0, 0, 0))] {
        s.modules.push(ModuleSpec {
            id,
            cell: m(cell),
            fixed: false,
        });
    }
    s.steps.push(Step {
        events: vec![Event::Rotate {
            module: 11,
            pivot: 10,
            from: m(Cell::new(0, 0, 0)),
            to: m(Cell::new(1, 0, 0)),
            route: Route::Hexagonal,
        }],
    });
    s
}

fn ground_collisions(s: &reconfcheck::schedule::Schedule) -> Vec<f64> {
    let r = certify(s, &Options::default()).unwrap();
    r.violations_of(ViolationKind::GroundCollision)
        .map(|v| v.detail["depth"].as_f64().unwrap())
        .collect()
}

#[test]
fn a_roll_that_dips_below_the_floor_is_a_ground_collision_in_either_mirror_image() {
    // Lattice-legal and clear of every module: only the floor stops it.
    // Its lowest point, found by sampling the roll independently (4,001
    // samples per link, docs/geometry.md), is 0.0345 d below the floor.
    for mirror in [false, true] {
        let s = dip_under_a_pivot(Some(0), mirror);
        let r = certify(&s, &Options::default()).unwrap();
        let kinds: Vec<_> = r.violations.iter().map(|v| v.kind).collect();
        assert_eq!(kinds, [ViolationKind::GroundCollision], "mirror {mirror}");
        let v = &r.violations[0];
        let depth = v.detail["depth"].as_f64().unwrap();
        assert!((depth - 0.0345).abs() < 5e-4, "{depth}");
        let witness_z = v.detail["witness_mover"][2].as_f64().unwrap();
        let floor = v.detail["floor_z"].as_f64().unwrap();
        assert_eq!(floor, -0.5);
        assert!((witness_z - (floor - depth)).abs() < 1e-6, "{witness_z}");
        assert!(!r.certified);
    }
}

#[test]
fn the_same_roll_over_a_lower_floor_or_without_a_ground_touches_nothing() {
    assert_eq!(
        ground_collisions(&dip_under_a_pivot(Some(-1), false)),
        Vec::<f64>::new()
    );
    assert_eq!(
        ground_collisions(&dip_under_a_pivot(None, false)),
        Vec::<f64>::new()
    );
}
