//! Numbers at the boundary: every numeric flag is validated before any
//! library code runs. A NaN compares false with every limit, an infinity or
//! a huge tolerance turns a collision into "within limits": each must be
//! refused with exit code 2 naming the flag, never certified.

use serde_json::Value;
use std::path::PathBuf;
use std::process::Output;

use crate::common;

use crate::common::{bin, walk_with_obstacle};

fn scratch(name: &str) -> PathBuf {
    common::scratch("edges", name)
}

/// The penetrating walk (see [`walk_with_obstacle`]), one file per `tag`.
fn penetrating_schedule(tag: &str) -> PathBuf {
    let p = scratch(&format!("penetrating-{tag}.json"));
    walk_with_obstacle(&p, true);
    p
}

fn certify_with(epsilon: &str, exact: bool) -> Output {
    let mut cmd = bin();
    cmd.arg("certify")
        .arg(penetrating_schedule(&format!("{epsilon}-{exact}")))
        .arg(format!("--epsilon={epsilon}"))
        .arg("--no-progress");
    if exact {
        cmd.arg("--exact");
    }
    cmd.output().unwrap()
}

#[test]
fn a_tolerance_that_is_not_in_its_range_is_refused_naming_the_flag() {
    for eps in [
        "nan", "NaN", "inf", "-inf", "-1", "0", "1e9", "0.2", "1e-320",
    ] {
        for exact in [false, true] {
            let o = certify_with(eps, exact);
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "--epsilon {eps}: {err}");
            assert!(err.contains("--epsilon"), "--epsilon {eps}: {err}");
            assert!(!String::from_utf8_lossy(&o.stdout).contains("CERTIFIED"));
        }
    }
}

#[test]
fn the_penetration_is_a_collision_at_every_accepted_tolerance() {
    // The largest tolerance accepted is far below the 0.28 d penetration:
    // no valid ε can certify it, by table or by exact sweep.
    for eps in ["1e-6", "1e-3", "0.1"] {
        for exact in [false, true] {
            let o = certify_with(eps, exact);
            let out = String::from_utf8_lossy(&o.stdout);
            assert_eq!(o.status.code(), Some(1), "--epsilon {eps}: {out}");
            assert!(out.contains("collision"), "--epsilon {eps}: {out}");
        }
    }
}

#[test]
fn a_pressure_that_is_not_a_positive_finite_number_is_refused_by_the_b_study() {
    for kpa in ["nan", "inf", "-1", "0", "1e306"] {
        let o = bin()
            .args([
                "b-study",
                "--family",
                "branch",
                "--b-max",
                "3",
                "--no-progress",
            ])
            .arg(format!("--pressure={kpa}"))
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "--pressure {kpa}: {err}");
        assert!(err.contains("--pressure"), "--pressure {kpa}: {err}");
        assert!(
            o.stdout.is_empty(),
            "no study is printed for --pressure {kpa}"
        );
    }
}

#[test]
fn a_collision_names_the_cells_of_both_modules_and_the_link() {
    let o = bin()
        .arg("certify")
        .arg(penetrating_schedule("cells"))
        .args(["--print-json", "--no-progress"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let report: Value = serde_json::from_slice(&o.stdout).unwrap();
    let v = report["violations"]
        .as_array()
        .unwrap()
        .iter()
        .find(|v| v["kind"] == "collision")
        .expect("a collision");
    // The mover's start and target, then the penetrated module's cell.
    assert_eq!(
        v["cells"],
        serde_json::json!([[0, 0, 1], [1, 0, 1], [1, -1, 1]])
    );
    assert_eq!(v["detail"]["pivot_cell"], serde_json::json!([1, 0, 0]));
    assert_eq!(v["detail"]["route"], "octagonal");
}

/// Three catoms in a row with neither ground nor fixed module: the end one
/// rolls up onto the middle one and back. A free-floating structure is
/// connected when it is one component, on every step (the incremental
/// check once had no anchor to look for and reported it loose).
#[test]
fn a_free_floating_structure_that_stays_one_component_is_connected_on_every_step() {
    use reconfcheck::certify::{Options, certify};
    use reconfcheck::lattice::{Cell, LatticeKind, Route};
    use reconfcheck::schedule::{Event, Length, ModuleSpec, Schedule, Step};
    let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(3.6));
    for x in 0..3 {
        s.modules.push(ModuleSpec {
            id: x as u32,
            cell: Cell::new(x, 0, 0),
            fixed: false,
        });
    }
    let (down, up) = (Cell::new(2, 0, 0), Cell::new(1, 0, 1));
    for (from, to) in [(down, up), (up, down), (down, up), (up, down)] {
        s.steps.push(Step {
            events: vec![Event::Rotate {
                module: 2,
                pivot: 1,
                from,
                to,
                route: Route::Octagonal,
            }],
        });
    }
    let r = certify(&s, &Options::lattice_only()).unwrap();
    assert!(r.certified, "{:?}", r.violations);
    // Splitting it is still a disconnection: the middle module rolls up
    // on the end one, and the first is left on its own.
    s.steps.clear();
    s.steps.push(Step {
        events: vec![Event::Rotate {
            module: 1,
            pivot: 2,
            from: Cell::new(1, 0, 0),
            to: Cell::new(1, 0, 1),
            route: Route::Octagonal,
        }],
    });
    let r = certify(&s, &Options::lattice_only()).unwrap();
    assert!(!r.certified);
    let loose: Vec<_> = r
        .violations_of(reconfcheck::certify::ViolationKind::Disconnected)
        .collect();
    assert!(!loose.is_empty(), "{:?}", r.violations);
}

/// The shipped model with one line replaced, written beside the test's
/// other files.
fn edited_model(tag: &str, from: &str, to: &str) -> PathBuf {
    let text = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models/catom-3.6mm.toml"),
    )
    .unwrap();
    assert!(text.contains(from), "{from}");
    let p = scratch(&format!("model-{tag}.toml"));
    std::fs::write(&p, text.replacen(from, to, 1)).unwrap();
    p
}

/// The 7-branch (its root overloaded under the shipped model at 10 kPa)
/// as a schedule file with the given spacing in mm.
fn branch_schedule(tag: &str, spacing_mm: f64) -> PathBuf {
    let p = scratch(&format!("branch-{tag}.json"));
    let o = bin()
        .args(["generate", "scenarios/branch.toml", "-o"])
        .arg(&p)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
    v["spacing"] = serde_json::json!({ "value": spacing_mm, "unit": "mm" });
    std::fs::write(&p, serde_json::to_string(&v).unwrap()).unwrap();
    p
}

#[test]
fn a_model_whose_rescaled_mass_would_vanish_is_refused_naming_the_field() {
    // A spacing of 1e200 mm: rescaled to the schedule's 3.6 mm the mass
    // would underflow to 0 and an overloaded branch read as unloaded.
    let model = edited_model("huge-spacing", "spacing_mm = 3.6", "spacing_mm = 1e200");
    let o = bin()
        .arg("certify")
        .arg(branch_schedule("huge-model-spacing", 3.6))
        .arg("--model")
        .arg(&model)
        .arg("--no-progress")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("module.spacing_mm"), "{err}");
    assert!(err.contains("model-huge-spacing.toml"), "{err}");
    assert!(!String::from_utf8_lossy(&o.stdout).contains("CERTIFIED"));
}

#[test]
fn a_schedule_spacing_that_makes_the_model_underflow_or_overflow_is_refused() {
    // Normal spacings (1e-300 mm, 1e300 m) whose cube, the module mass,
    // underflows or overflows. The model loads; only its rescaling fails,
    // so the schedule is at fault: exit 2 naming the schedule's file, with
    // the model in the message.
    for (tag, spacing_mm) in [("tiny-spacing", 1e-300), ("huge-spacing", 1e303)] {
        let o = bin()
            .arg("certify")
            .arg(branch_schedule(tag, spacing_mm))
            .arg("--model")
            .arg(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models/catom-3.6mm.toml"))
            .arg("--no-progress")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains("underflows or overflows"), "{err}");
        assert!(err.contains(&format!("branch-{tag}.json")), "{err}");
        assert!(err.contains("catom-3.6mm.toml"), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn model_fields_out_of_their_range_are_refused_naming_the_field() {
    for (tag, from, to, field) in [
        (
            "pressure",
            "pressure_kpa = 100.0",
            "pressure_kpa = 1e300",
            "connector.pressure_kpa",
        ),
        (
            "density",
            "density_g_cm3 = 1.2",
            "density_g_cm3 = 1e-300",
            "module.density_g_cm3",
        ),
        (
            "friction",
            "friction = 0.5 ",
            "friction = inf ",
            "connector.friction",
        ),
        (
            "gravity",
            "gravity = 9.80665",
            "gravity = 1e-320",
            "gravity",
        ),
        (
            "actuator",
            "[stiffness]",
            "[actuator]\npressure_kpa = nan\n\n[stiffness]",
            "actuator.pressure_kpa",
        ),
    ] {
        let model = edited_model(tag, from, to);
        let o = bin()
            .arg("certify")
            .arg(branch_schedule(&format!("field-{tag}"), 3.6))
            .arg("--model")
            .arg(&model)
            .arg("--no-progress")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{tag}: {err}");
        assert!(err.contains(field), "{tag}: {err}");
    }
}

/// `run` on the default scenario with `flag` at each of `values`: exit 2,
/// the flag named, nothing certified.
fn refused_on_default(flag: &str, values: &[&str]) {
    for v in values {
        let o = bin()
            .args(["run", "--no-progress"])
            .arg(format!("{flag}={v}"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{v}: {err}");
        assert!(err.contains(flag), "{v}: {err}");
        assert!(o.stdout.is_empty(), "{v}: nothing certified");
    }
}

/// The JSON report of `run` on the default scenario with `flags`, which
/// must certify it.
fn certified_default(name: &str, flags: &[&str]) -> Value {
    let path = scratch(name);
    let o = bin()
        .args(["run", "--no-progress", "--json"])
        .arg(&path)
        .args(flags)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{flags:?}: {err}");
    serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap()
}

#[test]
fn a_load_factor_tolerance_outside_0_to_one_half_is_refused_naming_the_flag() {
    refused_on_default(
        "--load-factor-tolerance",
        &["nan", "inf", "-inf", "-0.01", "0.5", "1", "1e9"],
    );
    // Accepted, the report records it, and the default scenario (whose
    // steps the elastic screen clears) reads the same as the exact run.
    let a = certified_default("lft-0.json", &["--load-factor-tolerance=0"]);
    let b = certified_default("lft-5.json", &["--load-factor-tolerance=0.05"]);
    assert!(
        a.get("load_factor_tolerance").is_none(),
        "absent when exact"
    );
    assert_eq!(b["load_factor_tolerance"], 0.05);
    assert_eq!(a["per_step"], b["per_step"]);
}

#[test]
fn a_range_size_below_one_step_is_refused_and_any_other_gives_the_same_verdicts() {
    refused_on_default("--range-steps", &["0", "-3", "nan", "1.5"]);
    let a = certified_default("ranges-default.json", &[]);
    let b = certified_default("ranges-3.json", &["--range-steps=3"]);
    // Every step judged, with the same findings; the utilisations agree to
    // the solver's rounding.
    let (sa, sb) = (
        a["per_step"].as_array().unwrap(),
        b["per_step"].as_array().unwrap(),
    );
    assert_eq!(sa.len(), sb.len());
    for (x, y) in sa.iter().zip(sb) {
        assert_eq!(x["violations"], y["violations"]);
        let (u, v) = (
            x["metrics"]["max_utilisation"].as_f64().unwrap(),
            y["metrics"]["max_utilisation"].as_f64().unwrap(),
        );
        assert!(
            (u - v).abs() <= 1e-9 * u.max(1.0),
            "step {}: {u} vs {v}",
            x["step"]
        );
    }
}

#[test]
fn steps_outside_the_schedule_or_unreadable_are_refused_and_a_span_keeps_its_numbers() {
    refused_on_default("--steps", &["0", "5-3", "x", "1-y", "-4", "175", "100-175"]);
    // The default scenario has 174 steps: a span of them, by their numbers,
    // with the steps before it and after it named as not checked.
    let path = scratch("steps-span.json");
    let o = bin()
        .args(["run", "--no-progress", "--steps", "101-120", "--json"])
        .arg(&path)
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{out}");
    assert!(out.contains("checked: lattice (steps 101–120)"), "{out}");
    assert!(
        out.contains("NOT checked: the initial configuration and steps 1–100"),
        "{out}"
    );
    assert!(
        out.contains("NOT checked: steps 121–174 and the final configuration"),
        "{out}"
    );
    let r: Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    assert_eq!(r["window"], serde_json::json!({"first": 101, "last": 120}));
    assert_eq!(r["steps"], 174);
    let steps: Vec<u64> = r["per_step"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["step"].as_u64().unwrap())
        .collect();
    assert_eq!(steps, (101..=120).collect::<Vec<_>>());
}

/// A cantilever two modules deep from one fixed root, seven long, with a
/// module swinging on its upper tip: it holds only plastically, at every
/// pose (one step).
fn plastic_cantilever() -> reconfcheck::schedule::Schedule {
    use reconfcheck::lattice::{Cell, LatticeKind};
    use reconfcheck::schedule::{Length, ModuleSpec, Schedule};
    let n = 7;
    let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(3.6));
    let mut id = 0;
    for z in 0..2 {
        for x in 0..=n {
            s.modules.push(ModuleSpec {
                id,
                cell: Cell::new(x, 0, z),
                fixed: id == 0,
            });
            id += 1;
        }
    }
    s.modules.push(ModuleSpec {
        id,
        cell: Cell::new(n + 1, 0, 1),
        fixed: false,
    });
    let pivot = 2 * n as u32 + 1;
    common::step(
        &mut s,
        vec![common::rot(
            id,
            pivot,
            Cell::new(n + 1, 0, 1),
            Cell::new(n, 1, 1),
        )],
    );
    s
}

/// A run with a load-factor tolerance reports, at every step the limit
/// analysis judged, a proven lower bound of the exact factor beside the
/// reported one; an exact run reports none (on [`plastic_cantilever`]).
#[test]
fn a_load_factor_tolerance_reports_a_proven_lower_bound_of_each_judged_factor() {
    use reconfcheck::certify::{Options, certify};
    let s = plastic_cantilever();
    let model = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models/catom-3.6mm.toml");
    let run = |tolerance: f64| {
        let opts = Options {
            model: Some(model.clone()),
            load_factor_tolerance: tolerance,
            ..Default::default()
        };
        certify(&s, &opts).expect("usable input")
    };
    let exact = run(0.0);
    let spared = run(0.05);
    let metric = |r: &reconfcheck::certify::Report, k: &str| r.per_step[0].metrics.get(k).copied();
    let lambda = metric(&exact, "load_factor").expect("judged by the limit analysis");
    assert_eq!(metric(&exact, "load_factor_lower_bound"), None);
    let reported = metric(&spared, "load_factor").unwrap();
    let lower = metric(&spared, "load_factor_lower_bound").expect("a lower bound with τ");
    assert!(lower <= lambda * (1.0 + 1e-9) && lambda <= reported * (1.0 + 1e-9));
    assert!(
        lower >= 0.95 * reported * (1.0 - 1e-9),
        "{lower} vs {reported}"
    );
    assert!(spared.summary().contains("lowest load_factor_lower_bound"));
    assert!(exact.certified && spared.certified, "{}", exact.summary());
    assert!(lambda > 1.0, "{lambda}");
}

/// The b-study passes its load-factor tolerance to the limit analysis:
/// on a structure that holds only plastically it solves fewer limit
/// analyses than the exact study, finds the same b safe with the same
/// elastic pressures, and records the tolerance; outside [0, 0.5) the
/// flag is refused by name with exit code 2.
#[test]
fn the_b_study_spares_limit_analyses_within_its_tolerance_and_keeps_its_verdicts() {
    use reconfcheck::mechanics::Model;
    use reconfcheck::progress::Reporter;
    use reconfcheck::study::b_study::{Judging, assemble, on_threads, study_rows};
    let model =
        Model::load(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models/catom-3.6mm.toml"))
            .unwrap();
    let study = |tolerance: f64| {
        let (rows, unplanned, _) = study_rows(
            &model,
            &[3],
            |_| Ok(plastic_cantilever()),
            &Reporter::silent(),
            tolerance,
            Judging::Every,
            &on_threads,
        )
        .unwrap()
        .expect("threads fold the rows");
        assemble(
            "cantilever",
            &model,
            rows,
            unplanned,
            tolerance,
            Judging::Every,
        )
    };
    let (exact, spared) = (study(0.0), study(0.05));
    let (e, t) = (&exact.rows[0], &spared.rows[0]);
    assert!(e.limit_analyses > 0, "{e:?}");
    // The exact study bisects the sweep (4 analyses here: the ends, the
    // sweep's apex and one more); the tolerance never costs more. That it
    // spares poses is tested on the enumeration in the library's tests.
    assert!(
        t.limit_analyses <= e.limit_analyses,
        "{} vs {}",
        t.limit_analyses,
        e.limit_analyses
    );
    assert!(e.safe() && t.safe());
    assert_eq!(exact.b_max, spared.b_max);
    assert_eq!(
        e.min_pressure_elastic.to_bits(),
        t.min_pressure_elastic.to_bits()
    );
    assert_eq!(
        e.min_pressure_rigid_hinge.to_bits(),
        t.min_pressure_rigid_hinge.to_bits()
    );
    assert!(t.max_utilisation <= e.max_utilisation * (1.0 + 1e-9));
    assert!(t.max_utilisation >= e.max_utilisation * (1.0 - 0.05) * (1.0 - 1e-9));
    assert_eq!(spared.load_factor_tolerance, 0.05);
    assert!(
        spared.table().contains("load-factor tolerance 0.05"),
        "{}",
        spared.table()
    );
    assert!(!exact.table().contains("load-factor tolerance"));
    for bad in ["0.5", "-0.1", "NaN"] {
        let out = common::bin()
            .args([
                "b-study",
                "--family",
                "branch",
                "--b-max",
                "2",
                "--no-progress",
            ])
            .arg(format!("--load-factor-tolerance={bad}"))
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{bad}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("--load-factor-tolerance"), "{bad}: {err}");
    }
}

/// A certifier must not certify what a finer analysis rejects, between the
/// samples of a move too. Step 169 of the default scenario (5 movers
/// turning at two rates) is judged at 25 samples per move; walked densely
/// (16 points per interval, on the true arcs), its worst connector is
/// about 2e-4 more loaded. The poses between samples the analysis judges
/// (`Structure::between`: per interval, every group of movers at either
/// sample or at its tangent point) bound that walk from above, closely:
/// analysed as poses of their own, their worst connector is at least the
/// dense walk's and within 0.1 % of it.
#[test]
fn the_poses_between_samples_bound_a_dense_walk_of_the_moves() {
    use reconfcheck::algorithms::scaffold::{ShapeSpec, scaffold_schedule};
    use reconfcheck::certify::load_maps_at;
    use reconfcheck::mechanics::{Analyzer, Model, Structure};
    let schedule = scaffold_schedule(&ShapeSpec::Pyramid { h: 3 }, 6).unwrap();
    let model =
        Model::load(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models/catom-3.6mm.toml"))
            .unwrap()
            .at_spacing_checked(schedule.spacing.metres())
            .unwrap();
    let (_, built, a) = load_maps_at(&schedule, &model, &[169]).unwrap().remove(0);
    let groups = built.hanging.iter().map(|h| h.group).max().unwrap() + 1;
    assert!(built.hanging.len() == 5 && groups == 2, "{groups} groups");
    assert_eq!(built.between.len(), 24 * (9 - 2));
    // Every interval was cleared by its bound (nothing near capacity).
    assert_eq!((a.between_poses, a.sampled_only.len()), (0, 0));
    // Each structure's movers walk the given points, at a common index.
    let walking = |points: &dyn Fn(usize) -> Vec<glam::DVec3>| {
        let mut t = built.clone();
        t.between.clear();
        for (h, hg) in t.hanging.iter_mut().enumerate() {
            hg.path = points(h);
            hg.hull.clear();
        }
        t
    };
    let dense = walking(&|h| {
        let hg = &built.hanging[h];
        let c = built.bodies[hg.pivot].centre;
        let mut path = Vec::new();
        for w in hg.path.windows(2) {
            let (u1, u2) = (w[0] - c, w[1] - c);
            let ang = u1.angle_between(u2);
            for j in 0..16 {
                let t = j as f64 / 16.0;
                path.push(c + (u1 * ((1.0 - t) * ang).sin() + u2 * (t * ang).sin()) / ang.sin());
            }
        }
        path.push(*hg.path.last().unwrap());
        path
    });
    let corners = walking(&|h| {
        let n = built.hanging[h].path.len();
        (0..n + built.between.len())
            .map(|k| built.mover_point(h, k))
            .collect()
    });
    let worst = |s: &Structure| {
        Analyzer::new(model.clone(), false)
            .analyse(s)
            .max_utilisation
    };
    let (at_samples, on_walk, at_corners) = (a.max_utilisation, worst(&dense), worst(&corners));
    assert!(
        on_walk > at_samples * (1.0 + 1e-4),
        "{on_walk} vs {at_samples}"
    );
    assert!(
        at_corners >= on_walk,
        "{at_corners} < {on_walk}: the walk leaves the hull"
    );
    assert!(at_corners <= on_walk * 1.001, "{at_corners} ≫ {on_walk}");
}
