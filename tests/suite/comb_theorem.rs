//! Seed 004's Theorem 1 in 2D at the meta-module level: the source combed,
//! made the common comb by 1- and 2-TUNNELs (Algorithm 2), and the target
//! reached by the target's phases in reverse; the meta-level certificate
//! (the paper's move preconditions, connectivity, in place) on generated
//! schedules, and catching each broken rule on hand-made ones.

use crate::common;

use rand::SeedableRng;
use reconfcheck::algorithms::comb::common_comb::reconfigure;
use reconfcheck::algorithms::comb::{Shape, meta_schedule_framed, random_polyomino};
use reconfcheck::certify::{self, Options, Report, ViolationKind};
use reconfcheck::lattice::AtomRest;
use reconfcheck::schedule::Schedule;
use serde_json::{Value, json};
use std::path::Path;

fn meta_level(s: &Schedule) -> Report {
    let opts = Options {
        meta_level: true,
        ..Default::default()
    };
    certify::certify(s, &opts).unwrap()
}

fn kinds(r: &Report) -> Vec<ViolationKind> {
    r.violations.iter().map(|v| v.kind).collect()
}

fn theorem_1(m: usize, seed: u64) -> (Shape, Schedule) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let (src, tgt) = (random_polyomino(m, &mut rng), random_polyomino(m, &mut rng));
    let plan = reconfigure(&src, &tgt);
    let s = meta_schedule_framed(&src, &plan.steps(), AtomRest::Contracted, None);
    (plan.target, s)
}

#[test]
fn theorem_1_schedules_certify_at_the_meta_level_in_place_and_end_at_the_target() {
    for (m, seed) in [(5, 0), (12, 1), (20, 2), (33, 3), (60, 4), (90, 5)] {
        let (target, s) = theorem_1(m, seed);
        let r = meta_level(&s);
        assert!(r.certified, "m {m} seed {seed}:\n{}", r.summary());
        // Every step was checked (in place and connectivity included).
        assert_eq!(r.per_step.len(), s.steps.len());
        assert!(r.checks.iter().any(|c| c.contains("in place")));
        assert!(r.checks.iter().any(|c| c.contains("NOT certified")));
        // The replay ends at the target.
        let mut at: std::collections::BTreeMap<u32, (i32, i32)> = s
            .modules
            .iter()
            .map(|m| (m.id, (m.cell.x, m.cell.y)))
            .collect();
        for e in s.steps.iter().flat_map(|st| &st.events) {
            match e {
                reconfcheck::schedule::Event::Slide { module, to, .. } => {
                    at.insert(*module, (to.x, to.y));
                }
                reconfcheck::schedule::Event::Tunnel { module, path } => {
                    let c = path.last().unwrap();
                    at.insert(*module, (c.x, c.y));
                }
                _ => {}
            }
        }
        let end: Shape = at.into_values().collect();
        assert_eq!(end, target, "m {m} seed {seed}");
    }
}

/// A meta-module schedule (`meta_modules: contracted`) of (id, [x, y]).
fn doc(metas: &[(u32, [i32; 2])], steps: Value) -> Schedule {
    let modules: Vec<Value> = metas
        .iter()
        .map(|&(id, [x, y])| json!({"id": id, "cell": [x, y, 0]}))
        .collect();
    let d = json!({
        "format": "reconfcheck-schedule", "version": 1, "lattice": "cubic",
        "spacing": {"value": 120.0, "unit": "mm"}, "meta_modules": "contracted",
        "modules": modules, "steps": steps,
    });
    Schedule::from_json(&d.to_string(), Path::new("t.json")).unwrap()
}

fn tunnel(module: u32, path: &[[i32; 2]]) -> Value {
    let p: Vec<[i32; 3]> = path.iter().map(|&[x, y]| [x, y, 0]).collect();
    json!({"op": "tunnel", "module": module, "path": p})
}

/// A comb: handle (0..3, 0), tooth of two on column 0, one on column 2.
fn comb() -> Vec<(u32, [i32; 2])> {
    vec![
        (0, [0, 0]),
        (1, [1, 0]),
        (2, [2, 0]),
        (3, [0, 1]),
        (4, [0, 2]),
        (5, [2, 1]),
    ]
}

#[test]
fn the_meta_level_certificate_catches_each_broken_rule_mirrored_too() {
    // (what, metas, steps, the violation expected; None: certified)
    let ok_2 = json!([{"events": [tunnel(4, &[[0, 2], [0, 1], [0, 0], [1, 0], [1, 1]])]}]);
    type Case = (
        &'static str,
        Vec<(u32, [i32; 2])>,
        Value,
        Option<ViolationKind>,
    );
    let cases: Vec<Case> = vec![
        ("a 2-TUNNEL from a tooth's top", comb(), ok_2, None),
        (
            "a start that is not a leaf",
            comb(),
            json!([{"events": [tunnel(3, &[[0, 1], [0, 0], [1, 0], [1, 1]])]}]),
            Some(ViolationKind::TunnelPrecondition),
        ),
        (
            "a leg attached between turns",
            {
                let mut c = comb();
                c.push((6, [3, 0]));
                c.push((7, [3, 1]));
                c.push((8, [3, 2]));
                c.push((9, [2, 2]));
                c
            },
            // Along the handle's row 0 from column 0 to 3 and up: column
            // 1 and 2 are legs; 2 carries the tooth (2, 1) attached.
            json!([{"events": [tunnel(4, &[[0, 2], [0, 1], [0, 0], [1, 0], [2, 0], [3, 0], [3, 1], [3, 2], [3, 3]])]}]),
            Some(ViolationKind::TunnelPrecondition),
        ),
        (
            "five turns",
            comb(),
            json!([{"events": [tunnel(4, &[[0, 2], [0, 1], [0, 0], [1, 0], [1, 1], [1, 0], [2, 0], [2, 1], [2, 2]])]}]),
            Some(ViolationKind::TunnelPrecondition),
        ),
        (
            "an occupied exit",
            comb(),
            json!([{"events": [tunnel(4, &[[0, 2], [0, 1], [0, 0], [1, 0], [2, 0], [2, 1]])]}]),
            Some(ViolationKind::TunnelPrecondition),
        ),
        (
            "a SLIDE with no meta-module beside its wall",
            vec![(0, [0, 0]), (1, [1, 0]), (2, [1, 1])],
            json!([{"events": [{"op": "slide", "module": 2, "from": [1, 1, 0], "to": [2, 1, 0], "pivot": 1}]}]),
            Some(ViolationKind::MoverDetached),
        ),
        (
            "a slider still attached to a meta-module it leaves",
            vec![
                (0, [0, 0]),
                (1, [0, 1]),
                (2, [1, 1]),
                (3, [2, 1]),
                (4, [2, 0]),
            ],
            json!([{"events": [{"op": "slide", "module": 2, "from": [1, 1, 0], "to": [1, 0, 0], "pivot": 1}]}]),
            Some(ViolationKind::LatchNotAdjacent),
        ),
        (
            "a carried meta-module with no slider",
            vec![(0, [0, 0]), (1, [1, 0])],
            json!([{"events": [{"op": "slide", "module": 1, "from": [1, 0, 0], "to": [1, 1, 0]}]}]),
            Some(ViolationKind::MoverDetached),
        ),
        (
            "a detach that splits the robot",
            comb(),
            json!([{"events": [{"op": "detach", "module": 1, "other": 2}]}]),
            Some(ViolationKind::Disconnected),
        ),
        (
            "out of both boxes and back",
            comb(),
            json!([
                {"events": [tunnel(5, &[[2, 1], [2, 0], [3, 0]])]},
                {"events": [tunnel(5, &[[3, 0], [2, 0], [2, 1]])]}
            ]),
            Some(ViolationKind::OutOfPlace),
        ),
    ];
    for (what, metas, steps, want) in cases {
        for mirror in [1, -1] {
            let metas: Vec<(u32, [i32; 2])> = metas
                .iter()
                .map(|&(id, [x, y])| (id, [mirror * x, y]))
                .collect();
            let mut steps = steps.clone();
            for ev in steps
                .as_array_mut()
                .unwrap()
                .iter_mut()
                .flat_map(|s| s["events"].as_array_mut().unwrap().iter_mut())
            {
                for key in ["from", "to"] {
                    if let Some(c) = ev.get_mut(key) {
                        c[0] = json!(mirror * c[0].as_i64().unwrap() as i32);
                    }
                }
                if let Some(p) = ev.get_mut("path") {
                    for c in p.as_array_mut().unwrap() {
                        c[0] = json!(mirror * c[0].as_i64().unwrap() as i32);
                    }
                }
            }
            let r = meta_level(&doc(&metas, steps));
            match want {
                None => assert!(r.certified, "{what} (mirror {mirror}):\n{}", r.summary()),
                Some(k) => assert!(
                    kinds(&r).contains(&k),
                    "{what} (mirror {mirror}): want {k:?}:\n{}",
                    r.summary()
                ),
            }
        }
    }
}

#[test]
fn a_theorem_1_scenario_is_refused_at_atom_level_naming_the_tunnel_and_certified_at_meta_level() {
    let dir = common::scratch_dir("comb-theorem");
    let out = dir.join("t1.json");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/comb-2d-theorem-1.toml");
    let o = common::bin()
        .arg("generate")
        .arg(&scenario)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = common::bin().arg("certify").arg(&out).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("t1.json") && err.contains("1-TUNNEL") && err.contains("turns 2 times"),
        "{err}"
    );
    let text = common::succeeds(
        common::bin()
            .args(["certify", "--meta-level", "--no-progress"])
            .arg(&out),
    );
    assert!(
        text.contains("CERTIFIED") && text.contains("NOT certified"),
        "{text}"
    );
    // An unknown `until` is refused naming the scenario and the parameter.
    let bad = dir.join("bad.toml");
    std::fs::write(
        &bad,
        "name = \"x\"\nalgorithm = \"comb-2d\"\n[parameters]\nuntil = \"common\"\n",
    )
    .unwrap();
    let o = common::bin()
        .arg("generate")
        .arg(&bad)
        .arg("-o")
        .arg(dir.join("x.json"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("bad.toml") && err.contains("until"), "{err}");
}

#[test]
fn a_combing_run_in_reverse_certifies_atom_by_atom() {
    // Source and target the same shape: Theorem 1's schedule is the
    // combing and the combing reversed (no tunnel), so every SLIDE run
    // backwards, up along the meta-module it had arrived beside, is
    // expanded into atom operations and certified.
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/cube-atom.toml");
    for seed in 0..4 {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let src = random_polyomino(10, &mut rng);
        let plan = reconfigure(&src, &src);
        assert_eq!(plan.phases[1].len(), 0, "seed {seed}: no tunnel");
        let slides_back = plan.phases[3]
            .iter()
            .flatten()
            .filter(|e| {
                matches!(
                    e,
                    reconfcheck::schedule::Event::Slide { pivot: Some(_), .. }
                )
            })
            .count();
        assert!(slides_back > 0, "seed {seed}");
        let anchor = src.iter().min_by_key(|c| (c.1, c.0)).copied();
        let s = meta_schedule_framed(&src, &plan.steps(), AtomRest::Contracted, anchor);
        let opts = Options {
            model: Some(model.clone()),
            ..Default::default()
        };
        let r = certify::certify(&s, &opts).unwrap();
        assert!(r.certified, "seed {seed}:\n{}", r.summary());
        assert!(r.checks.iter().any(|c| c.contains("in place")));
    }
}

#[test]
fn theorem_2_schedules_in_3d_certify_at_the_meta_level_and_end_at_the_target() {
    use reconfcheck::algorithms::comb::three_d::{random_polycube, reconfigure3, schedule_of};
    use reconfcheck::schedule::Event;
    let mut turns_seen = std::collections::BTreeSet::new();
    for (m, seed) in [(4, 0), (9, 1), (16, 2), (27, 3), (48, 4), (80, 5)] {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let (a, b) = (random_polycube(m, &mut rng), random_polycube(m, &mut rng));
        let plan = reconfigure3(&a, &b);
        let s = schedule_of(&a, plan.steps(), AtomRest::Contracted);
        let r = meta_level(&s);
        assert!(r.certified, "m {m} seed {seed}:\n{}", r.summary());
        assert_eq!(r.per_step.len(), s.steps.len());
        let mut at: std::collections::BTreeMap<u32, reconfcheck::lattice::Cell> =
            s.modules.iter().map(|m| (m.id, m.cell)).collect();
        for e in s.steps.iter().flat_map(|st| &st.events) {
            match e {
                Event::Slide { module, to, .. } => {
                    at.insert(*module, *to);
                }
                Event::Tunnel { module, path } => {
                    at.insert(*module, *path.last().unwrap());
                    turns_seen.insert(reconfcheck::lattice::path_turns(path).len());
                }
                _ => {}
            }
        }
        let end: std::collections::BTreeSet<_> = at.into_values().collect();
        assert_eq!(end, plan.target, "m {m} seed {seed}");
    }
    // Tunnels of more than two turns occur (Algorithm 3's k ≤ 4).
    assert!(turns_seen.iter().any(|&k| k > 2), "{turns_seen:?}");
}

#[test]
fn theorem_2s_combing_phases_certify_atom_by_atom_and_the_theorems_are_drawn() {
    use reconfcheck::study::comb::theorem3;
    let model = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models/cube-atom.toml");
    let rows = theorem3(&[8, 16], 4, AtomRest::Contracted, 16, Some(model)).unwrap();
    for r in &rows {
        assert_eq!(r.atoms_certified, Some(true), "{} meta-modules", r.metas);
        assert_eq!(r.meta_certified, Some(true));
        let u = r.comb_utilisation.unwrap();
        assert!(u > 0.0 && u < 1.0, "{u}");
        assert!(r.comb_operations > 0 && r.comb_steps > 0);
    }
    #[cfg(feature = "render")]
    {
        let png = common::scratch("theorems-plot", "theorems.png");
        reconfcheck::render::comb_figures::theorems(&[], &rows, &[], &png).unwrap();
        let bytes = std::fs::read(&png).unwrap();
        assert!(bytes.starts_with(b"\x89PNG") && bytes.len() > 10_000);
    }
}
