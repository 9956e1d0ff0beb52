//! Seed 004's atoms: the certifier's checks on hand-made schedules (each
//! check must catch what it is for, mirror images included), bad input
//! refused with exit 2, and the SLIDE moves the search derives certified in
//! both atom models.

use crate::common;

use reconfcheck::algorithms::atom_moves::{derive_slide, describe};
use reconfcheck::certify::{self, Options, Report, ViolationKind};
use reconfcheck::geometry::atom_search::Carry;
use reconfcheck::lattice::AtomRest;
use reconfcheck::schedule::Schedule;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

fn model() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("models/cube-atom.toml")
}

fn schedule(rest: &str, atoms: &[(u32, [i32; 3], bool)], steps: Value) -> Schedule {
    let modules: Vec<Value> = atoms
        .iter()
        .map(|&(id, c, fixed)| json!({"id": id, "cell": c, "fixed": fixed}))
        .collect();
    let doc = json!({
        "format": "reconfcheck-schedule", "version": 1, "lattice": "cubic",
        "spacing": {"value": 60.0, "unit": "mm"}, "atoms": rest,
        "modules": modules, "steps": steps,
    });
    Schedule::from_json(&doc.to_string(), Path::new("test.json")).unwrap()
}

fn run(s: &Schedule) -> Report {
    let opts = Options {
        model: Some(model()),
        ..Default::default()
    };
    certify::certify(s, &opts).unwrap()
}

fn kinds(r: &Report) -> Vec<ViolationKind> {
    r.violations.iter().map(|v| v.kind).collect()
}

/// A row of three contracted atoms, the first fixed.
fn row() -> Vec<(u32, [i32; 3], bool)> {
    vec![
        (0, [0, 0, 0], true),
        (1, [1, 0, 0], false),
        (2, [2, 0, 0], false),
    ]
}

#[test]
fn an_inchworm_push_and_pull_of_a_row_is_certified() {
    let s = schedule(
        "contracted",
        &row(),
        json!([
            {"events": [{"op": "expand", "module": 1, "face": "+x"}]},
            {"events": [{"op": "contract", "module": 1, "face": "+x"}]},
            {"events": [{"op": "expand", "module": 1, "face": "+x"}]}
        ]),
    );
    let r = run(&s);
    assert!(r.certified, "{}", r.summary());
    assert_eq!(r.moves, 3);
    // Pushed out and pulled back to where it started, the row leaves the
    // union of its source and target boxes (which are then the same).
    let s = schedule(
        "contracted",
        &row(),
        json!([
            {"events": [{"op": "expand", "module": 1, "face": "+x"}]},
            {"events": [{"op": "contract", "module": 1, "face": "+x"}]}
        ]),
    );
    let r = run(&s);
    assert_eq!(
        kinds(&r),
        vec![ViolationKind::OutOfPlace, ViolationKind::OutOfPlace]
    );
    assert!(r.per_step[0].metrics["max_utilisation"] > 0.0);
}

/// A 2×2 square (0 fixed, 1 right, 3 above 0, 4 above 1) with 1–4
/// detached; `mirror` flips x.
fn square(mirror: bool) -> Vec<(u32, [i32; 3], bool)> {
    let m = |x: i32| if mirror { -x } else { x };
    vec![
        (0, [0, 0, 0], true),
        (1, [m(1), 0, 0], false),
        (3, [0, 1, 0], false),
        (4, [m(1), 1, 0], false),
    ]
}

#[test]
fn an_arm_expanding_into_an_unattached_neighbour_collides_mirror_too() {
    for mirror in [false, true] {
        let s = schedule(
            "contracted",
            &square(mirror),
            json!([
                {"events": [{"op": "detach", "module": 1, "other": 4}]},
                {"events": [{"op": "expand", "module": 1, "face": "+y"}]}
            ]),
        );
        let r = run(&s);
        assert_eq!(kinds(&r), vec![ViolationKind::Collision], "{}", r.summary());
        let v = &r.violations[0];
        assert_eq!(v.step, 2);
        // The arm reaches 4's body at once and is 1 deep at the end: the
        // middle of the overlap interval is the reported pose.
        assert!(v.detail["s"].as_f64().unwrap() > 0.0);
        assert!(v.detail["depth"].as_f64().unwrap() > 0.4);
    }
}

#[test]
fn a_single_arm_in_a_closed_square_is_an_arm_conflict_and_stops() {
    let s = schedule(
        "contracted",
        &square(false),
        json!([
            {"events": [{"op": "expand", "module": 0, "face": "+x"}]},
            {"events": [{"op": "contract", "module": 0, "face": "+x"}]}
        ]),
    );
    let r = run(&s);
    assert_eq!(kinds(&r), vec![ViolationKind::ArmConflict]);
    assert_eq!(r.stopped_at, Some(1));
    // Both x-arms of the square together are consistent.
    let s = schedule(
        "contracted",
        &square(false),
        json!([
            {"events": [{"op": "expand", "module": 0, "face": "+x"}, {"op": "expand", "module": 3, "face": "+x"}]}
        ]),
    );
    assert!(run(&s).certified);
}

#[test]
fn detaching_the_only_bond_disconnects_the_robot() {
    let s = schedule(
        "contracted",
        &row(),
        json!([{"events": [{"op": "detach", "module": 1, "other": 2}]}]),
    );
    let r = run(&s);
    assert_eq!(kinds(&r), vec![ViolationKind::Disconnected]);
    assert_eq!(r.violations[0].modules, vec![2]);
}

#[test]
fn a_free_arm_sticking_out_of_both_boxes_is_not_in_place() {
    let s = schedule(
        "contracted",
        &row(),
        json!([
            {"events": [{"op": "expand", "module": 2, "face": "-y"}]},
            {"events": [{"op": "contract", "module": 2, "face": "-y"}]}
        ]),
    );
    let r = run(&s);
    // Out while it extends and while it retracts.
    assert_eq!(
        kinds(&r),
        vec![ViolationKind::OutOfPlace, ViolationKind::OutOfPlace]
    );
    // Sticking out along the row, where the target box grows, is in place.
    let s = schedule(
        "contracted",
        &row(),
        json!([{"events": [{"op": "expand", "module": 2, "face": "+x"}]}]),
    );
    assert!(run(&s).certified);
}

#[test]
fn the_drive_load_matches_the_closed_form_and_overloads_a_weak_face() {
    // A row of n atoms pushed by the first arm: load = μ·m·g·(n − 1).
    let text = std::fs::read_to_string(model()).unwrap();
    let m = reconfcheck::mechanics::Model::from_toml(&text).unwrap();
    for n in [3, 6] {
        let atoms: Vec<(u32, [i32; 3], bool)> =
            (0..n).map(|i| (i as u32, [i, 0, 0], i == 0)).collect();
        let s = schedule(
            "contracted",
            &atoms,
            json!([{"events": [{"op": "expand", "module": 0, "face": "+x"}]}]),
        );
        let r = run(&s);
        let expected =
            m.ground.friction * m.mass * m.gravity * (n - 1) as f64 / m.connector.tension();
        let got = r.per_step[0].metrics["max_utilisation"];
        assert!(
            (got - expected).abs() < 1e-12,
            "n = {n}: {got} vs {expected}"
        );
    }
    // A face of 1 Pa cannot drag anything.
    let weak = common::scratch("cube-atom-weak", "file.toml");
    std::fs::write(
        &weak,
        text.replace("pressure_kpa = 10.0", "pressure_kpa = 0.001"),
    )
    .unwrap();
    let s = schedule(
        "contracted",
        &row(),
        json!([{"events": [{"op": "expand", "module": 0, "face": "+x"}]}]),
    );
    let r = certify::certify(
        &s,
        &Options {
            model: Some(weak),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(kinds(&r), vec![ViolationKind::Overload]);
}

#[test]
fn expanded_atoms_rest_three_units_apart_and_contract_together() {
    let atoms = vec![(0, [0, 0, 0], true), (1, [3, 0, 0], false)];
    let s = schedule(
        "expanded",
        &atoms,
        json!([
            {"events": [{"op": "contract", "module": 0, "face": "+x"}, {"op": "contract", "module": 1, "face": "-x"}]},
            {"events": [{"op": "expand", "module": 0, "face": "+x"}]}
        ]),
    );
    let r = run(&s);
    assert!(r.certified, "{}", r.summary());
    // Contracted-spacing atoms in the expanded model are not attached.
    let s = schedule(
        "expanded",
        &[(0, [0, 0, 0], true), (1, [1, 0, 0], false)],
        json!([]),
    );
    let r = run(&s);
    assert!(
        kinds(&r).contains(&ViolationKind::Collision)
            || kinds(&r).contains(&ViolationKind::Disconnected)
    );
}

fn cli_certify(name: &str, doc: &Value) -> (Option<i32>, String) {
    let dir = common::scratch_dir("atoms");
    let p = dir.join(name);
    std::fs::write(&p, doc.to_string()).unwrap();
    let o = common::bin()
        .arg("certify")
        .arg(&p)
        .arg("--lattice-only")
        .output()
        .unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn bad_atom_events_are_unusable_input_naming_file_step_and_module() {
    let base = |steps: Value| {
        json!({
            "format": "reconfcheck-schedule", "version": 1, "lattice": "cubic",
            "spacing": {"value": 60.0, "unit": "mm"}, "atoms": "contracted",
            "modules": [{"id": 0, "cell": [0,0,0]}, {"id": 7, "cell": [1,0,0]}],
            "steps": steps,
        })
    };
    let cases = [
        (
            "twice.json",
            json!([{"events": []}, {"events": [{"op": "contract", "module": 7, "face": "+x"}]}]),
            vec!["step 2", "module 7", "already contracted"],
        ),
        (
            "unknown.json",
            json!([{"events": [{"op": "expand", "module": 9, "face": "+x"}]}]),
            vec!["step 1", "module 9"],
        ),
        (
            "rotate.json",
            json!([{"events": [{"op": "slide", "module": 7, "from": [1,0,0], "to": [1,1,0]}]}]),
            vec!["step 1", "module 7", "atom"],
        ),
        (
            "face.json",
            json!([{"events": [{"op": "expand", "module": 7, "face": "+w"}]}]),
            vec!["face.json"],
        ),
    ];
    for (name, steps, needles) in cases {
        let (code, err) = cli_certify(name, &base(steps));
        assert_eq!(code, Some(2), "{name}: {err}");
        assert!(err.contains(name), "{name}: {err}");
        for n in needles {
            assert!(err.contains(n), "{name}: lacks {n}: {err}");
        }
    }
    // `atoms` on another lattice.
    let mut doc = base(json!([]));
    doc["lattice"] = json!("square");
    let (code, err) = cli_certify("square.json", &doc);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("cubic lattice only"), "{err}");
}

#[test]
fn derived_slides_certify_in_both_models() {
    // The contracted model's SLIDE is searched here; the expanded
    // model's is stored (models/moves), replayed and expanded.
    for rest in [AtomRest::Contracted, AtomRest::Expanded] {
        for carry in Carry::ALL {
            let d = derive_slide(rest, carry)
                .unwrap_or_else(|| panic!("no SLIDE found for {rest:?} {carry:?}"));
            let r = run(&d.schedule);
            assert!(
                r.certified,
                "{rest:?} {carry:?}:\n{}\n{}",
                describe(&d.found.steps),
                r.summary()
            );
            eprintln!(
                "SLIDE {rest:?} {}: {} parallel steps, {} atom operations (2D slice: {} ops, {} states)",
                carry.name(),
                d.parallel_steps(),
                d.atom_operations(),
                d.found.ops.len(),
                d.found.states_explored
            );
        }
    }
}

fn comb_schedule(m: usize, seed: u64, rest: AtomRest) -> Schedule {
    use rand::SeedableRng;
    use reconfcheck::algorithms::comb::{Robot, meta_schedule, random_polyomino};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let shape = random_polyomino(m, &mut rng);
    let mut r = Robot::new(&shape);
    r.comb();
    meta_schedule(&shape, &r.steps, rest)
}

#[test]
fn combing_random_polyominoes_in_the_expanded_model_certifies_atom_by_atom_in_place() {
    // The stored expanded SLIDE, and between two walls the same SLIDE run
    // one layer at a time (some of these combings need one).
    let mut two_walls = 0;
    for seed in 0..8 {
        let s = comb_schedule(10, seed, AtomRest::Expanded);
        two_walls += s
            .steps
            .iter()
            .filter(|st| {
                let mut sliders: Vec<u32> = st
                    .events
                    .iter()
                    .filter_map(|e| match e {
                        reconfcheck::schedule::Event::Slide {
                            module,
                            pivot: Some(_),
                            ..
                        } => Some(*module),
                        _ => None,
                    })
                    .collect();
                let n = sliders.len();
                sliders.sort_unstable();
                sliders.dedup();
                sliders.len() < n
            })
            .count();
        let r = run(&s);
        assert!(r.certified, "seed {seed}:\n{}", r.summary());
        assert!(r.checks.iter().any(|c| c.contains("in place")));
        assert_eq!(r.per_step.len(), r.steps);
    }
    assert!(two_walls > 0, "no SLIDE between two walls was exercised");
}

#[test]
fn the_bundled_expanded_model_scenarios_run_and_certify_from_the_command_line() {
    // Both need a SLIDE between two walls (seed 1 in 2D, seed 2 in 3D).
    for name in ["comb-2d-expanded.toml", "comb-3d-expanded.toml"] {
        let scenario = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios")
            .join(name);
        let text = common::succeeds(common::bin().args(["run", "--no-progress"]).arg(&scenario));
        assert!(
            text.contains("CERTIFIED") && text.contains("in place"),
            "{name}: {text}"
        );
    }
}

#[test]
fn combing_random_polyominoes_certifies_atom_by_atom_in_place() {
    for rest in [AtomRest::Contracted] {
        for seed in 0..6 {
            let s = comb_schedule(10, seed, rest);
            let r = run(&s);
            assert!(r.certified, "{rest:?} seed {seed}:\n{}", r.summary());
            // Every step was checked for the in-place bound.
            assert!(r.checks.iter().any(|c| c.contains("in place")));
            assert_eq!(r.per_step.len(), r.steps);
        }
    }
}

#[test]
fn a_comb_is_a_histogram_on_the_lowest_row() {
    use rand::SeedableRng;
    use reconfcheck::algorithms::comb::{Robot, random_polyomino};
    for seed in 0..20 {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let shape = random_polyomino(30, &mut rng);
        let mut r = Robot::new(&shape);
        r.comb();
        let cells: std::collections::BTreeSet<(i32, i32)> = r.at.iter().copied().collect();
        assert_eq!(cells.len(), shape.len());
        // Every column is one run starting on row 0, the handle.
        let xs: std::collections::BTreeSet<i32> = cells.iter().map(|c| c.0).collect();
        for x in xs {
            let h = cells.iter().filter(|c| c.0 == x).count() as i32;
            assert!(
                (0..h).all(|y| cells.contains(&(x, y))),
                "seed {seed} column {x}"
            );
        }
    }
}

#[test]
fn robots_that_are_not_aligned_blocks_or_not_connected_are_refused_naming_file_and_reason() {
    let dir = common::scratch_dir("comb");
    let good = "##\n##\n";
    let cases = [
        ("shifted.txt", ".##\n.##\n", good, "aligned 2×2×2"),
        (
            "apart.txt",
            "##..##\n##..##\n",
            "####\n####\n",
            "not connected",
        ),
        (
            "more.txt",
            "####\n####\n",
            good,
            "meta-modules and the target",
        ),
    ];
    for (name, src, tgt, reason) in cases {
        std::fs::write(dir.join(name), src).unwrap();
        std::fs::write(dir.join("t.txt"), tgt).unwrap();
        let scenario = dir.join("s.toml");
        std::fs::write(
            &scenario,
            format!(
                "name = \"x\"\nalgorithm = \"comb-2d\"\n[parameters]\nsource = \"{name}\"\ntarget = \"t.txt\"\n"
            ),
        )
        .unwrap();
        let o = common::bin()
            .arg("generate")
            .arg(&scenario)
            .arg("-o")
            .arg(dir.join("out.json"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        let file = if reason.contains("target") {
            "t.txt"
        } else {
            name
        };
        assert!(err.contains(file), "{name}: {err}");
        assert!(err.contains(reason), "{name}: {err}");
    }
}

/// A meta-module robot (`meta_modules: contracted`) of `metas` (id, cell,
/// fixed), with `steps`.
fn meta_doc(metas: &[(u32, [i32; 3], bool)], steps: Value) -> Value {
    let modules: Vec<Value> = metas
        .iter()
        .map(|&(id, c, fixed)| json!({"id": id, "cell": c, "fixed": fixed}))
        .collect();
    json!({
        "format": "reconfcheck-schedule", "version": 1, "lattice": "cubic",
        "spacing": {"value": 60.0, "unit": "mm"}, "meta_modules": "contracted",
        "modules": modules, "steps": steps,
    })
}

/// The 1-TUNNEL((x, y + 1), (x + 1, y)) of seed 004 Fig. 12 inside a
/// robot whose bounding boxes hold the corner between the legs: A (id 3)
/// on the turn B (2), B on L (1), L on L2 (0, fixed), and G (4) on L2,
/// which keeps the target's box as high as the source's. `map` places the
/// robot (turned or mirrored).
fn tunnel_robot(map: impl Fn([i32; 3]) -> [i32; 3]) -> (Vec<(u32, [i32; 3], bool)>, Value) {
    let metas = vec![
        (0, map([-2, 0, 0]), true),
        (1, map([-1, 0, 0]), false),
        (2, map([0, 0, 0]), false),
        (3, map([0, 1, 0]), false),
        (4, map([-2, 1, 0]), false),
    ];
    let path = json!([map([0, 1, 0]), map([0, 0, 0]), map([1, 0, 0])]);
    (
        metas,
        json!([{"events": [{"op": "tunnel", "module": 3, "path": path}]}]),
    )
}

#[test]
fn a_derived_one_tunnel_certifies_atom_by_atom_turned_and_mirrored() {
    let lib = reconfcheck::geometry::atom_expand::tunnel_library(
        AtomRest::Contracted,
        reconfcheck::geometry::atom_search::Legs {
            behind: false,
            ahead: false,
        },
    )
    .expect("the contracted 1-TUNNEL is found");
    eprintln!(
        "1-TUNNEL, contracted: {} parallel steps, {} atom operations in 3D (2D slice: {} ops, {} states)",
        lib.steps.len(),
        lib.atom_operations(),
        lib.found.ops.len(),
        lib.found.states_explored
    );
    // As placed; mirrored in x; turned so that the legs are z and −y and
    // the slice is lifted along x.
    let maps: [fn([i32; 3]) -> [i32; 3]; 3] =
        [|c| c, |[x, y, z]| [-x, y, z], |[x, y, z]| [z, -x, y]];
    for (k, map) in maps.into_iter().enumerate() {
        let (metas, steps) = tunnel_robot(map);
        let doc = meta_doc(&metas, steps);
        let s = Schedule::from_json(&doc.to_string(), Path::new("t.json")).unwrap();
        let r = run(&s);
        assert!(r.certified, "placement {k}:\n{}", r.summary());
        assert_eq!(r.steps, lib.steps.len(), "placement {k}");
    }
    // Without G the corner is outside both bounding boxes: the move is
    // not in place, and the certifier says so.
    let (mut metas, steps) = tunnel_robot(|c| c);
    metas.pop();
    let s = Schedule::from_json(&meta_doc(&metas, steps).to_string(), Path::new("t.json")).unwrap();
    let r = run(&s);
    assert!(!r.certified);
    assert!(
        kinds(&r).contains(&ViolationKind::OutOfPlace),
        "{}",
        r.summary()
    );
}

#[test]
fn a_one_tunnel_with_long_legs_certifies_atom_by_atom_turned_and_mirrored() {
    // The leaf D2 on top of an in-leg D2, D, A standing on the turn B; B
    // on L, L on L2 (fixed); the out-leg E, E2 beside B. D2 tunnels down
    // and out at (3, 0): every leg meta-module moves one cell along the
    // path, rigidly (where each meta-module's atoms end is the unit test
    // `after_a_tunnel_each_meta_module_is_the_atoms_in_its_cell`).
    let maps: [fn([i32; 3]) -> [i32; 3]; 3] =
        [|c| c, |[x, y, z]| [-x, y, z], |[x, y, z]| [z, -x, y]];
    for (k, map) in maps.into_iter().enumerate() {
        let metas = vec![
            (0, map([-2, 0, 0]), true),
            (1, map([-1, 0, 0]), false),
            (2, map([0, 0, 0]), false),
            (3, map([0, 1, 0]), false),
            (4, map([0, 2, 0]), false),
            (5, map([0, 3, 0]), false),
            (6, map([1, 0, 0]), false),
            (7, map([2, 0, 0]), false),
        ];
        let path: Vec<[i32; 3]> = [
            [0, 3, 0],
            [0, 2, 0],
            [0, 1, 0],
            [0, 0, 0],
            [1, 0, 0],
            [2, 0, 0],
            [3, 0, 0],
        ]
        .into_iter()
        .map(map)
        .collect();
        let steps = json!([{"events": [{"op": "tunnel", "module": 5, "path": path}]}]);
        let s =
            Schedule::from_json(&meta_doc(&metas, steps).to_string(), Path::new("t.json")).unwrap();
        let r = run(&s);
        assert!(r.certified, "placement {k}:\n{}", r.summary());
        assert!(r.checks.iter().any(|c| c.contains("in place")));
    }
}

/// `derive-moves --move` with a name that is no stored move is refused
/// (exit 2) before any search, listing the stored moves.
#[test]
fn derive_moves_refuses_an_unknown_move_naming_the_known_ones() {
    let o = common::bin()
        .args([
            "derive-moves",
            "--check",
            "--move",
            "tunnel-contracted-sideways",
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("tunnel-contracted-sideways")
            && err.contains("tunnel-contracted-both-legs")
            && err.contains("slide-expanded")
            && !err.contains("searching"),
        "{err}"
    );
}

/// `derive-moves --out` makes a missing folder, and one that cannot be a
/// folder (a file stands in its path) fails at once (exit 3, naming it),
/// not after the searches.
#[test]
fn derive_moves_makes_its_output_folder_or_fails_before_searching() {
    let file = common::scratch("derive-out", "a-file");
    std::fs::write(&file, "not a folder").unwrap();
    let out = file.join("moves");
    let o = common::bin()
        .args(["derive-moves", "--move", "slide-expanded", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(
        err.contains(&out.display().to_string()) && !err.contains("searching"),
        "{err}"
    );
}

#[test]
fn tunnels_other_than_the_derived_one_are_refused_naming_the_reason() {
    let (metas, _) = tunnel_robot(|c| c);
    let turn = json!([[0, 1, 0], [0, 0, 0], [1, 0, 0]]);
    // (file, a meta-module added to the robot, the path, what the error says)
    let cases = [
        (
            "straight.json",
            None,
            json!([[0, 1, 0], [0, 0, 0], [0, -1, 0]]),
            "this path turns 0 times",
        ),
        (
            "twice.json",
            None,
            json!([[0, 1, 0], [0, 0, 0], [1, 0, 0], [1, 1, 0]]),
            "this path turns 2 times",
        ),
        (
            "long.json",
            None,
            json!([[0, 1, 0], [0, 0, 0], [1, 0, 0], [2, 0, 0]]),
            "runs through (1, 0, 0), where there is no meta-module",
        ),
        (
            "nohold.json",
            None,
            json!([[0, 1, 0], [0, 0, 0], [-1, 0, 0]]),
            "must hang on a meta-module at (1, 0, 0), opposite the exit",
        ),
        (
            "below.json",
            Some((5, [0, -1, 0], false)),
            turn.clone(),
            "may touch only the path and the meta-module opposite the exit; meta-module 5 at (0, -1, 0)",
        ),
        (
            "exit.json",
            Some((5, [1, 0, 0], false)),
            turn,
            "the exit (1, 0, 0) is taken by meta-module 5",
        ),
    ];
    for (name, extra, path, needle) in cases {
        let mut robot = metas.clone();
        robot.extend(extra);
        let doc = meta_doc(
            &robot,
            json!([{"events": [{"op": "tunnel", "module": 3, "path": path}]}]),
        );
        let (code, err) = cli_certify(name, &doc);
        assert_eq!(code, Some(2), "{name}: {err}");
        for n in [name, "step 1", "module 3", needle] {
            assert!(err.contains(n), "{name}: lacks {n}: {err}");
        }
    }
}

#[test]
fn a_free_robot_holds_its_heaviest_part_and_the_arm_drags_the_lighter_mirror_too() {
    // Six atoms in a row, none fixed; the first listed is the end atom
    // whose arm pushes the other five away. Seen from it (the old frame),
    // the arm would drag five atoms; on a table the five hold by their
    // friction and the arm drags the one.
    let text = std::fs::read_to_string(model()).unwrap();
    let m = reconfcheck::mechanics::Model::from_toml(&text).unwrap();
    let one = m.ground.friction * m.mass * m.gravity / m.connector.tension();
    for mirror in [false, true] {
        let x = |i: i32| if mirror { -i } else { i };
        let atoms: Vec<(u32, [i32; 3], bool)> =
            (0..6).map(|i| (i as u32, [x(i), 0, 0], false)).collect();
        let face = if mirror { "-x" } else { "+x" };
        let s = schedule(
            "contracted",
            &atoms,
            json!([{"events": [{"op": "expand", "module": 0, "face": face}]}]),
        );
        let r = run(&s);
        assert!(r.certified, "{}", r.summary());
        let got = r.per_step[0].metrics["max_utilisation"];
        assert!(
            (got - one).abs() < 1e-12,
            "mirror {mirror}: {got} vs {one} (one atom dragged)"
        );
        // Listed last, the pushing atom is dragged all the same.
        let mut last = atoms.clone();
        last.rotate_left(1);
        let s = schedule(
            "contracted",
            &last,
            json!([{"events": [{"op": "expand", "module": 0, "face": face}]}]),
        );
        let got = run(&s).per_step[0].metrics["max_utilisation"];
        assert!(
            (got - one).abs() < 1e-12,
            "mirror {mirror}, listed last: {got}"
        );
    }
}

/// The 3D combing (seed 004 §3.2: 3D-COMBING to a terrain, then
/// TERRAIN-TO-COMB) of a random polycube, as a meta-module schedule.
fn comb3_schedule(m: usize, seed: u64, rest: AtomRest) -> Schedule {
    use rand::SeedableRng;
    use reconfcheck::algorithms::comb::three_d::{Robot3, random_polycube, schedule_of};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let shape = random_polycube(m, &mut rng);
    let mut r = Robot3::new(&shape);
    r.comb();
    schedule_of(&shape, r.steps, rest)
}

/// Certifies the 3D combing of each (meta-modules, seed) polycube atom by
/// atom in place, with the mechanics (some arm must carry a load);
/// returns how many sliders had walls on two perpendicular sides.
fn certify_3d_combings(cases: &[(usize, u64)], rest: AtomRest) -> usize {
    let mut perpendicular = 0;
    for &(m, seed) in cases {
        let s = comb3_schedule(m, seed, rest);
        perpendicular += perpendicular_walls(&s);
        let r = run(&s);
        assert!(
            r.certified,
            "{rest:?}, {m} meta-modules, seed {seed}:\n{}",
            r.summary()
        );
        assert!(r.checks.iter().any(|c| c.contains("in place")));
        assert_eq!(r.per_step.len(), r.steps);
        assert!(
            r.per_step
                .iter()
                .any(|st| st.metrics["max_utilisation"] > 0.0)
        );
    }
    perpendicular
}

/// Sliders with walls on two perpendicular sides, over the schedule.
fn perpendicular_walls(s: &Schedule) -> usize {
    let mut n = 0;
    for st in &s.steps {
        let mut walls: std::collections::HashMap<u32, Vec<u32>> = Default::default();
        for e in &st.events {
            if let reconfcheck::schedule::Event::Slide {
                module,
                pivot: Some(p),
                ..
            } = e
            {
                walls.entry(*module).or_default().push(*p);
            }
        }
        n += walls.values().filter(|w| w.len() > 1).count();
    }
    n
}

#[test]
fn combing_random_polycubes_in_3d_in_the_expanded_model_certifies_atom_by_atom() {
    // The stored expanded SLIDE with the 3D combing's hand-overs of walls
    // across the lift and loads beside the slice. The expanded SLIDE moves
    // its atoms in several steps: before each still atom held on to the
    // wall it faced when it stopped (B, then B's or C's other row, then C),
    // (8, 5), (8, 8) and (24, 5) were rejected by the certifier (three
    // meta-modules disconnected mid-slide).
    let perpendicular = certify_3d_combings(
        &[(8, 5), (8, 8), (24, 1), (24, 4), (24, 5), (24, 6)],
        AtomRest::Expanded,
    );
    assert!(perpendicular > 0, "no slider with two walls was exercised");
}

#[test]
fn combing_random_polycubes_in_3d_certifies_atom_by_atom_in_place() {
    // Chosen among the first seeds: (24, 4) carries meta-modules beside a
    // slider's slice, across its lift (attached to all four of the
    // slider's atoms on that face: an arm conflict before); the others
    // have sliders with walls on two perpendicular sides (refused before).
    let perpendicular = certify_3d_combings(
        &[(8, 5), (8, 8), (24, 1), (24, 4), (24, 5)],
        AtomRest::Contracted,
    );
    assert!(perpendicular > 0, "no slider with two walls was exercised");
}

/// A SLIDE carrying a tower: a static row of `row` meta-modules at
/// z = 0 (x = 1 − row … 1; B at x = 1, C at x = 0), the slider A on B at
/// (1, 0, 1) sliding −x onto C, and `k` meta-modules stacked on A (its
/// far side from the wall), carried. No meta-module is fixed. `mirror`
/// flips x.
fn carried_tower(row: i32, k: i32, mirror: bool) -> Value {
    let x = |v: i32| if mirror { -v } else { v };
    let mut metas: Vec<(u32, [i32; 3], bool)> = (0..row)
        .map(|i| (i as u32, [x(1 - i), 0, 0], false))
        .collect();
    let a = row as u32;
    metas.push((a, [x(1), 0, 1], false));
    let slide = |id: u32, z: i32| json!({"op": "slide", "module": id, "from": [x(1), 0, z], "to": [0, 0, z]});
    let mut events = vec![slide(a, 1)];
    events[0]["pivot"] = json!(0);
    for j in 1..=k {
        let id = a + j as u32;
        metas.push((id, [x(1), 0, 1 + j], false));
        events.push(slide(id, 1 + j));
    }
    meta_doc(&metas, json!([{"events": events}]))
}

#[test]
fn a_slides_drive_load_grows_with_what_it_carries_and_overloads_past_29_meta_modules() {
    // Closed form, independent of the drive-load code: in the SLIDE's
    // second step the slider's two contracting arms (one per layer, in
    // parallel) pull its other six atoms and everything it carries, 8k
    // atoms, while the static row (heavier) holds: each arm carries
    // μ·m·g·(6 + 8k)/2. At 36 N faces and 100 g atoms on friction 0.3 it
    // holds up to k = 29 (35.0 N) and not at k = 30 (36.2 N): the paper's
    // O(1) SLIDE carrying any number of meta-modules meets a load limit.
    let text = std::fs::read_to_string(model()).unwrap();
    let m = reconfcheck::mechanics::Model::from_toml(&text).unwrap();
    let per_atom = m.ground.friction * m.mass * m.gravity / m.connector.tension();
    for (k, holds, mirror) in [
        (1, true, false),
        (5, true, true),
        (29, true, false),
        (29, true, true),
        (30, false, false),
        (30, false, true),
    ] {
        let doc = carried_tower(40, k, mirror);
        let s = Schedule::from_json(&doc.to_string(), Path::new("t.json")).unwrap();
        let r = run(&s);
        let worst = r
            .per_step
            .iter()
            .map(|st| st.metrics["max_utilisation"])
            .fold(0.0, f64::max);
        let expected = per_atom * (6 + 8 * k) as f64 / 2.0;
        assert!(
            (worst - expected).abs() < 1e-12,
            "k = {k}, mirror {mirror}: {worst} vs {expected}"
        );
        assert_eq!(
            r.certified,
            holds,
            "k = {k}, mirror {mirror}:\n{}",
            r.summary()
        );
        if !holds {
            assert!(
                kinds(&r).iter().all(|&v| v == ViolationKind::Overload),
                "{}",
                r.summary()
            );
        }
    }
}

/// An expanded-model SLIDE through the expansion: a static row of three
/// (x = 1, 0, −1 at z = 0; B at x = 1, C at x = 0), the slider A on B
/// sliding −x onto C, carrying D behind it (x = 2) and/or E on it (z = 2),
/// or pushing P ahead of it from x = 0 to −1 (the SLIDE run backwards; P
/// lets go of C in a step before and holds the row's end in a step
/// after). No meta-module is fixed. `place` turns or mirrors the robot.
fn expanded_slide_doc(load: Load, place: impl Fn([i32; 3]) -> [i32; 3]) -> Value {
    let mut metas: Vec<(u32, [i32; 3], bool)> = (0..3)
        .map(|i| (i, place([1 - i as i32, 0, 0]), false))
        .collect();
    let slide = |id: u32, from: [i32; 3], to: [i32; 3]| json!({"op": "slide", "module": id, "from": place(from), "to": place(to)});
    metas.push((3, place([1, 0, 1]), false));
    let mut events = vec![slide(3, [1, 0, 1], [0, 0, 1])];
    events[0]["pivot"] = json!(0);
    if load.behind {
        metas.push((4, place([2, 0, 1]), false));
        events.push(slide(4, [2, 0, 1], [1, 0, 1]));
    }
    if load.above {
        metas.push((5, place([1, 0, 2]), false));
        events.push(slide(5, [1, 0, 2], [0, 0, 2]));
    }
    let mut steps = vec![json!({"events": events})];
    if load.ahead {
        metas.push((6, place([0, 0, 1]), false));
        steps[0]["events"]
            .as_array_mut()
            .unwrap()
            .push(slide(6, [0, 0, 1], [-1, 0, 1]));
        steps.insert(
            0,
            json!({"events": [{"op": "detach", "module": 6, "other": 1}]}),
        );
        steps.push(json!({"events": [{"op": "attach", "module": 6, "other": 2}]}));
    }
    let mut doc = meta_doc(&metas, Value::Array(steps));
    doc["meta_modules"] = json!("expanded");
    doc
}

/// Where a test robot's cells go (turned or mirrored).
type Place = fn([i32; 3]) -> [i32; 3];

#[derive(Clone, Copy, Debug)]
struct Load {
    behind: bool,
    above: bool,
    ahead: bool,
}

#[test]
fn the_stored_expanded_slide_certifies_atom_by_atom_with_each_load_turned_and_mirrored() {
    let places: [(&str, Place); 3] = [
        ("as is", |c| c),
        ("mirrored in x", |c| [-c[0], c[1], c[2]]),
        ("turned (slide along y, wall below in z)", |c| {
            [c[1], c[0], c[2]]
        }),
    ];
    let l = |behind, above, ahead| Load {
        behind,
        above,
        ahead,
    };
    for load in [
        l(false, false, false),
        l(true, false, false),
        l(false, true, false),
        l(true, true, false),
        l(false, false, true),
    ] {
        for (name, place) in places {
            let doc = expanded_slide_doc(load, place);
            let s = Schedule::from_json(&doc.to_string(), Path::new("t.json")).unwrap();
            let r = run(&s);
            assert!(r.certified, "{load:?}, {name}:\n{}", r.summary());
            // 12 parallel steps, 96 operations by the slider; a load on
            // its far side lets go of the top atom that drops into the
            // bottom row in the first step and latches again in the last;
            // a load ahead lets go and latches in steps of its own.
            let ops: usize = r
                .per_step
                .iter()
                .map(|st| st.metrics["atom_operations"] as usize)
                .sum();
            let (above, ahead) = (usize::from(load.above), usize::from(load.ahead));
            assert_eq!(r.steps, 12 + 2 * ahead, "{load:?}, {name}");
            assert_eq!(ops, 96 + 4 * above + 8 * ahead, "{load:?}, {name}");
        }
    }
    // Between two walls (B below, B′ above): the SLIDE run one layer at a
    // time, 24 steps; alone, and carrying a load behind, which rides on
    // the bottom layer and lets go of the top one for the move.
    for behind in [false, true] {
        for (name, place) in places {
            let mut doc = expanded_slide_doc(l(behind, false, false), place);
            doc["modules"].as_array_mut().unwrap().extend([
                json!({"id": 7, "cell": place([1, 0, 2]), "fixed": false}),
                json!({"id": 8, "cell": place([0, 0, 2]), "fixed": false}),
            ]);
            doc["steps"][0]["events"]
                .as_array_mut()
                .unwrap()
                .push(json!({
                    "op": "slide", "module": 3, "from": place([1, 0, 1]),
                    "to": place([0, 0, 1]), "pivot": 7
                }));
            let s = Schedule::from_json(&doc.to_string(), Path::new("t.json")).unwrap();
            let r = run(&s);
            assert!(
                r.certified,
                "two walls, behind {behind}, {name}:\n{}",
                r.summary()
            );
            let ops: usize = r
                .per_step
                .iter()
                .map(|st| st.metrics["atom_operations"] as usize)
                .sum();
            // Two layers of 48 operations; each lets go of B′ (2 pairs)
            // and takes C′ (2 pairs); the columns let go and latch again
            // (4 pairs each); a load behind relatches the top layer's 2.
            assert_eq!(r.steps, 24, "{name}");
            assert_eq!(ops, 2 * 48 + 8 + 8 + if behind { 4 } else { 0 }, "{name}");
        }
    }
}
