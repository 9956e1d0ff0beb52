//! Bad input never panics: random edits of valid schedules (one to three of:
//! a value replaced by one of another kind or an extreme one, a key or an
//! element deleted, a step duplicated) are either refused as input errors
//! naming the file or certified with a verdict — through every check,
//! collision sweeps and mechanics included. The same for the shape files:
//! character-level edits of a CSG file, of a 2D grid file and of a RePoSt
//! meta-module shape file are refused or parsed; an edited stored atom
//! sequence (seed 004's expanded SLIDE) is refused or replays to its goal; and for the scenarios: each generator's parameters, edited, are
//! refused or generate a schedule that is certified. `PROPTEST_CASES=20000 cargo test --test suite fuzz::` searches longer.

use proptest::prelude::*;
use proptest::test_runner::FileFailurePersistence;
use reconfcheck::algorithms::random_walk::{WalkParams, walk};
use reconfcheck::certify::{Options, certify};
use reconfcheck::schedule::Schedule;
use serde_json::{Value, json};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

/// A small valid FCC walk, and the square-lattice U-shape of seed 003.
fn originals() -> Vec<Value> {
    let p = WalkParams {
        width: 4,
        depth: 4,
        walkers: 3,
        steps: 6,
        activity: 0.8,
        seed: 11,
        geometric: false,
    };
    let fcc = walk(&p, &|_, _, _| true);
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scenario = reconfcheck::scenario::Scenario::load(&root.join("scenarios/u-shape-pas.toml"))
        .expect("bundled scenario");
    let square = reconfcheck::algorithms::generate(&scenario).expect("generates");
    [fcc, square]
        .iter()
        .map(|s| serde_json::from_str(&s.to_json()).unwrap())
        .collect()
}

/// Paths to every value in `v` (object keys and array indices).
fn paths(v: &Value, prefix: &mut Vec<Value>, out: &mut Vec<Vec<Value>>) {
    out.push(prefix.clone());
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                prefix.push(json!(k));
                paths(x, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                prefix.push(json!(i));
                paths(x, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

fn at<'a>(v: &'a mut Value, path: &[Value]) -> &'a mut Value {
    path.iter().fold(v, |v, k| match k {
        Value::String(k) => &mut v[k.as_str()],
        _ => &mut v[k.as_u64().unwrap() as usize],
    })
}

/// Values that break assumptions: other kinds, zero, negatives, extremes.
fn replacements() -> Vec<Value> {
    vec![
        json!(null),
        json!(0),
        json!(-1),
        json!(1),
        json!(7),
        json!(3.5),
        json!(-2147483648i64),
        json!(2147483647i64),
        json!(4294967295u64),
        json!(1e300),
        json!("x"),
        json!(""),
        json!([]),
        json!([0, 0]),
        json!([0, 0, 0, 0]),
        json!({}),
        json!(true),
    ]
}

fn mutate(mut v: Value, what: usize, pick: prop::sample::Index, with: usize) -> Value {
    let mut all = Vec::new();
    paths(&v, &mut Vec::new(), &mut all);
    let path = pick.get(&all[1..]).clone();
    match what {
        // Replace the value.
        0 => *at(&mut v, &path) = replacements()[with % replacements().len()].clone(),
        // Delete it from its object or array.
        1 => {
            let (last, parent) = path.split_last().unwrap();
            match (at(&mut v, parent), last) {
                (Value::Object(m), Value::String(k)) => {
                    m.remove(k);
                }
                (Value::Array(a), Value::Number(i)) => {
                    a.remove(i.as_u64().unwrap() as usize);
                }
                _ => {}
            }
        }
        // Duplicate a step (its moves start from cells already left).
        _ => {
            if let Some(steps) = v["steps"].as_array_mut().filter(|s| !s.is_empty()) {
                let k = with % steps.len();
                let s = steps[k].clone();
                steps.insert(k, s);
            }
        }
    }
    v
}

/// `cases` cases, replaying first the failures saved in
/// `tests/suite/fuzz.proptest-regressions` (cargo runs integration tests
/// from the package root). Proptest's default path, derived from the
/// source file, no longer finds that file since the tests became one
/// binary, and would save new failures elsewhere.
fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        failure_persistence: Some(Box::new(FileFailurePersistence::Direct(
            "tests/suite/fuzz.proptest-regressions",
        ))),
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config(256))]

    #[test]
    fn edited_schedules_are_refused_or_certified_never_a_panic(
        which in 0usize..2,
        edits in prop::collection::vec((0usize..3, any::<prop::sample::Index>(), 0usize..64), 1..4),
    ) {
        let v = edits
            .into_iter()
            .fold(originals().swap_remove(which), |v, (what, pick, with)| mutate(v, what, pick, with));
        let text = serde_json::to_string(&v).unwrap();
        let models = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models");
        let model = if which == 0 { "catom-3.6mm.toml" } else { "sliding-square.toml" };
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            let s = Schedule::from_json(&text, Path::new("edited.json"))?;
            let opts = Options { model: Some(models.join(model)), ..Default::default() };
            // As the CLI does: an error inside a step names the step and the
            // module; the file is the caller's to add.
            certify(&s, &opts).map(|r| r.certified).map_err(|e| e.in_file("edited.json"))
        }));
        match outcome {
            Ok(Ok(_)) => {}
            Ok(Err(e)) => prop_assert!(e.to_string().contains("edited.json"), "{e}"),
            Err(_) => prop_assert!(false, "panicked on {text}"),
        }
    }
}

/// A small Theorem 1 schedule of seed 004 (tunnels, slides, latches).
fn theorem_1_original() -> Value {
    use rand::SeedableRng;
    use reconfcheck::algorithms::comb::common_comb::reconfigure;
    use reconfcheck::algorithms::comb::{meta_schedule_framed, random_polyomino};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let (a, b) = (random_polyomino(7, &mut rng), random_polyomino(7, &mut rng));
    let plan = reconfigure(&a, &b);
    let s = meta_schedule_framed(
        &a,
        &plan.steps(),
        reconfcheck::lattice::AtomRest::Contracted,
        None,
    );
    serde_json::from_str(&s.to_json()).unwrap()
}

/// Certifies `v` (an edited schedule) with `opts`: refused naming the
/// file, or certified either way, never a panic.
fn refused_or_certified(v: Value, opts: Options) -> Result<(), TestCaseError> {
    let text = serde_json::to_string(&v).unwrap();
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        let s = Schedule::from_json(&text, Path::new("edited.json"))?;
        certify(&s, &opts)
            .map(|r| r.certified)
            .map_err(|e| e.in_file("edited.json"))
    }));
    match outcome {
        Ok(Ok(_)) => {}
        Ok(Err(e)) => prop_assert!(e.to_string().contains("edited.json"), "{e}"),
        Err(_) => prop_assert!(false, "panicked on {text}"),
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(256))]

    #[test]
    fn edited_meta_module_schedules_are_refused_or_certified_at_meta_level_never_a_panic(
        edits in prop::collection::vec((0usize..3, any::<prop::sample::Index>(), 0usize..64), 1..4),
    ) {
        let v = edits
            .into_iter()
            .fold(theorem_1_original(), |v, (what, pick, with)| mutate(v, what, pick, with));
        refused_or_certified(v, Options { meta_level: true, ..Default::default() })?;
    }
}

/// A small 3D combing of seed 004 (slides along walls on two
/// perpendicular sides, meta-modules carried beside a slider's slice,
/// latches), which plain certification expands into atom operations.
fn comb_3d_original() -> Value {
    use rand::SeedableRng;
    use reconfcheck::algorithms::comb::three_d::{Robot3, random_polycube, schedule_of};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let shape = random_polycube(8, &mut rng);
    let mut r = Robot3::new(&shape);
    r.comb();
    let s = schedule_of(&shape, r.steps, reconfcheck::lattice::AtomRest::Contracted);
    serde_json::from_str(&s.to_json()).unwrap()
}

proptest! {
    #![proptest_config(config(128))]

    #[test]
    fn edited_3d_combings_are_refused_or_certified_atom_by_atom_never_a_panic(
        edits in prop::collection::vec((0usize..3, any::<prop::sample::Index>(), 0usize..64), 1..4),
    ) {
        let v = edits
            .into_iter()
            .fold(comb_3d_original(), |v, (what, pick, with)| mutate(v, what, pick, with));
        refused_or_certified(v, Options::default())?;
    }
}

/// Pieces that CSG and grid files are made of, and some that break them.
const PIECES: &[&str] = &[
    "(",
    ")",
    "[",
    "]",
    "{",
    "}",
    ",",
    ";",
    "=",
    "-",
    "+",
    "*",
    "/",
    ".",
    "0",
    "1",
    "-1",
    "1e400",
    "-1e12",
    "nan",
    "inf",
    "b",
    "r",
    "h",
    "union()",
    "difference()",
    "intersection()",
    "translate([",
    "rotate([",
    "scale([",
    "cube(",
    "sphere(r = ",
    "cylinder(h = ",
    "center = true",
    "//",
    "/*",
    "\n",
    "#",
    ".",
    "x",
    "é",
    "\u{0}",
];

/// `text` with `edits` applied: (position, what, piece) — delete a run,
/// insert a piece, or repeat a run.
fn edit_text(text: &str, edits: &[(prop::sample::Index, usize, usize)]) -> String {
    let mut chars: Vec<char> = text.chars().collect();
    for (at, what, piece) in edits {
        let i = at.index(chars.len() + 1);
        match what % 3 {
            0 => {
                let end = (i + piece % 12).min(chars.len());
                chars.drain(i..end);
            }
            1 => {
                let p: Vec<char> = PIECES[piece % PIECES.len()].chars().collect();
                chars.splice(i..i, p);
            }
            _ => {
                let end = (i + piece % 40).min(chars.len());
                let run: Vec<char> = chars[i..end].to_vec();
                chars.splice(i..i, run);
            }
        }
    }
    chars.into_iter().collect()
}

/// The bundled file at `path` (from the repository root), edited.
fn edited_model(path: &str, edits: &[(prop::sample::Index, usize, usize)]) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    edit_text(&std::fs::read_to_string(root.join(path)).unwrap(), edits)
}

proptest! {
    #![proptest_config(config(256))]

    /// The CSG parser and the solid it builds: an edited sandcastle, or an
    /// edited mug (rotate, scale), is refused or gives a solid whose
    /// bounds and membership can be asked.
    #[test]
    fn edited_csg_files_are_refused_or_parsed_never_a_panic(
        edits in prop::collection::vec((any::<prop::sample::Index>(), 0usize..3, 0usize..1000), 1..6),
        mug in any::<bool>(),
    ) {
        use reconfcheck::algorithms::scaffold::csg::CsgShape;
        use reconfcheck::algorithms::scaffold::shape::{Shape as _, Skew};
        let file = if mug { "models/docking/mug.csg" } else { "models/shapes/sandcastle.csg" };
        let edited = edited_model(file, &edits);
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            CsgShape::parse("edited", &edited).map(|s| {
                let (lo, hi) = s.skew_bounds();
                let mid = |a: i32, b: i32| ((a as i64 + b as i64) / 2) as i32;
                s.contains(Skew::new(mid(lo.x, hi.x), mid(lo.y, hi.y), mid(lo.z, hi.z)))
            })
        }));
        prop_assert!(outcome.is_ok(), "panicked on {edited:?}");
    }

    /// The 2D grid files of seed 003: an edited U-shape is refused with its
    /// file named, or is a valid shape.
    #[test]
    fn edited_grid_files_are_refused_or_parsed_never_a_panic(
        edits in prop::collection::vec((any::<prop::sample::Index>(), 0usize..3, 0usize..1000), 1..6),
    ) {
        use reconfcheck::algorithms::active_subtraction::Shape;
        let edited = edited_model("models/shapes2d/u-shape.txt", &edits);
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            Shape::parse(&edited, Path::new("edited.txt")).and_then(|s| {
                s.validate()?;
                Ok(s.included_count())
            })
        }));
        match outcome {
            Ok(Ok(_)) => {}
            Ok(Err(e)) => prop_assert!(e.to_string().contains("edited.txt") || e.file.is_none(), "{e}"),
            Err(_) => prop_assert!(false, "panicked on {edited:?}"),
        }
    }

    /// The meta-module shape files of seed 001: an edited FULL-bottom
    /// block is refused naming the file, or loads to meta-modules on the
    /// lattice that write back to the same shape.
    #[test]
    fn edited_repost_shape_files_are_refused_or_loaded_never_a_panic(
        edits in prop::collection::vec((any::<prop::sample::Index>(), 0usize..3, 0usize..1000), 1..6),
    ) {
        use reconfcheck::algorithms::repost::shape;
        let edited = edited_model("models/shapes/repost/block-2x2x3-full-bottom.txt", &edits);
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            shape::parse(&edited, Path::new("edited.txt")).map(|m| {
                let again = shape::parse(&shape::to_text(&m), Path::new("again.txt"));
                (m.clone(), again.ok())
            })
        }));
        match outcome {
            Ok(Ok((m, again))) => prop_assert_eq!(Some(m), again),
            Ok(Err(e)) => prop_assert!(e.to_string().contains("edited.txt"), "{e}"),
            Err(_) => prop_assert!(false, "panicked on {edited:?}"),
        }
    }

    /// The stored atom sequences of seed 004 (models/moves): an edited
    /// expanded SLIDE or contracted 1-TUNNEL is refused naming the file,
    /// or replays valid by the certifier's step rules to the goal.
    #[test]
    fn edited_stored_moves_are_refused_or_replay_to_the_goal_never_a_panic(
        which in 0usize..5,
        edits in prop::collection::vec((any::<prop::sample::Index>(), 0usize..3, 0usize..1000), 1..6),
    ) {
        use reconfcheck::geometry::atom_search::{Carry, expanded_slide_problem, tunnel_problem};
        use reconfcheck::geometry::stored_move::{GoalMatch, StoredId, StoredMove};
        use reconfcheck::lattice::AtomRest;
        let id = StoredId::ALL[which];
        let (file, _) = id.file();
        let edited = edited_model(file, &edits);
        let (p, end) = match id {
            StoredId::ExpandedSlide => (expanded_slide_problem(Carry::None).0, GoalMatch::OwnCells),
            StoredId::ContractedTunnel(legs) => {
                (tunnel_problem(AtomRest::Contracted, legs).0, GoalMatch::WithinGroups)
            }
        };
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            StoredMove::parse(&edited, "edited.json").and_then(|m| m.validated(&p, end, "edited.json"))
        }));
        match outcome {
            Ok(Ok(found)) => {
                let mut s = p.start.clone();
                for st in &found.steps {
                    s = s.step(st, &p.anchors, p.eps).expect("validated steps replay");
                }
                let reached = match end {
                    GoalMatch::OwnCells => s == p.goal,
                    GoalMatch::WithinGroups => p.meets_goal(&s),
                };
                prop_assert!(reached);
            }
            Ok(Err(e)) => prop_assert!(e.to_string().contains("edited.json"), "{e}"),
            Err(_) => prop_assert!(false, "panicked on {edited:?}"),
        }
    }
}

/// Small valid scenarios of every parameterised generator.
fn scenario_bases() -> Vec<(&'static str, &'static str)> {
    vec![
        (
            "random-walk",
            "width = 4\ndepth = 4\nwalkers = 2\nsteps = 3\nactivity = 0.5\nseed = 1\ngeometric = false",
        ),
        ("branch", "length = 3\nspacing_mm = 3.6"),
        ("scaffold", "shape = \"pyramid\"\nh = 1\nb = 4"),
        ("scaffold", "shape = \"cube\"\nh = 1\ne = 2\nb = 4"),
        (
            "scaffold",
            "shape = \"pyramid\"\nh = 1\nb = 4\nprotocol = \"paper\"",
        ),
        (
            "scaffold",
            "shape = \"pyramid\"\nh = 2\nb = 4\nfeed = \"eager\"",
        ),
        (
            "scaffold",
            "shape = \"pyramid\"\nh = 2\nb = 4\nfeed = \"eager\"\neager_window = 3",
        ),
        (
            "scaffold",
            "shape = \"pyramid\"\nh = 2\nb = 4\nflow = \"continuous\"",
        ),
        (
            "active-subtraction",
            "mode = \"pas\"\nshape = \"../models/shapes2d/u-shape.txt\"",
        ),
        ("comb-2d", "metas = 6\nseed = 1\nuntil = \"comb\""),
        ("comb-3d", "metas = 6\nseed = 1\nuntil = \"comb\""),
        (
            "active-subtraction",
            "mode = \"sas\"\n[random]\nwidth = 4\nheight = 4\ndensity = 0.5\nseed = 2\ngrowth = \"chain\"",
        ),
    ]
}

/// Parameter values that break assumptions (none large enough to be a
/// legitimately long run).
fn parameter_values() -> Vec<toml::Value> {
    use toml::Value as V;
    vec![
        V::Integer(-1),
        V::Integer(0),
        V::Integer(1),
        V::Integer(2),
        V::Integer(3),
        V::Integer(2147483647),
        V::Integer(-2147483648),
        V::Integer(4294967296),
        V::Integer(i64::MAX),
        V::Float(-1.5),
        V::Float(0.0),
        V::Float(0.5),
        V::Float(1.0),
        V::Float(f64::NAN),
        V::Float(f64::INFINITY),
        V::Float(1e300),
        V::String("x".into()),
        V::String("../../nowhere.txt".into()),
        V::Boolean(true),
        V::Array(vec![V::Integer(1)]),
    ]
}

proptest! {
    #![proptest_config(config(256))]

    /// Every generator with an edited parameter (a value replaced by one of
    /// another kind or an extreme one, or deleted): refused as input naming
    /// the scenario or a file, or generated and certified; never a panic.
    #[test]
    fn edited_scenario_parameters_are_refused_or_run_never_a_panic(
        base in 0usize..scenario_bases().len(),
        edits in prop::collection::vec((any::<prop::sample::Index>(), 0usize..21), 1..3),
    ) {
        use reconfcheck::scenario::Scenario;
        let (algorithm, text) = scenario_bases()[base];
        let mut parameters: toml::Table = toml::from_str(text).unwrap();
        for (pick, with) in &edits {
            // The keys of the table and of its nested `random` table.
            let mut keys: Vec<(Option<String>, String)> =
                parameters.keys().map(|k| (None, k.clone())).collect();
            if let Some(toml::Value::Table(r)) = parameters.get("random") {
                keys.extend(r.keys().map(|k| (Some("random".to_string()), k.clone())));
            }
            if keys.is_empty() {
                break;
            }
            let (outer, key) = pick.get(&keys).clone();
            let table = match &outer {
                Some(o) => match parameters.get_mut(o) {
                    Some(toml::Value::Table(t)) => t,
                    _ => continue,
                },
                None => &mut parameters,
            };
            match parameter_values().get(*with) {
                Some(v) => {
                    table.insert(key, v.clone());
                }
                None => {
                    table.remove(&key);
                }
            }
        }
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let path = root.join("scenarios/edited.toml");
        let scenario = Scenario {
            name: "edited".into(),
            description: String::new(),
            algorithm: algorithm.into(),
            model: None,
            parameters: parameters.clone(),
            dir: root.join("scenarios"),
            path: path.clone(),
        };
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            let s = reconfcheck::algorithms::generate(&scenario)?;
            certify(&s, &Options::lattice_only()).map(|r| r.certified)
        }));
        match outcome {
            Ok(Ok(_)) => {}
            Ok(Err(e)) => prop_assert!(e.file.is_some() || e.step.is_some(), "{algorithm} {parameters:?}: {e} names nothing"),
            Err(_) => prop_assert!(false, "{algorithm} panicked on {parameters:?}"),
        }
    }
}

proptest! {
    #![proptest_config(config(256))]

    /// VisibleSim configurations (issue #15): an edited bundled
    /// `rolls.xml` is refused naming the file, or imports, exports and
    /// re-imports to the same schedule; its CSG target is read or refused.
    #[test]
    fn edited_visiblesim_configurations_are_refused_or_imported_never_a_panic(
        edits in prop::collection::vec((any::<prop::sample::Index>(), 0usize..3, 0usize..1000), 1..6),
        skewed in any::<bool>(),
    ) {
        use reconfcheck::interop::{GroundChoice, VsLattice, export_config, import_config, read_config, target_cells};
        use reconfcheck::schedule::Length;
        let edited = edited_model("scenarios/visiblesim/rolls.xml", &edits);
        let lattice = if skewed { VsLattice::SkewedFcc } else { VsLattice::Fcc };
        let outcome = catch_unwind(AssertUnwindSafe(|| -> Result<(), String> {
            let file = Path::new("edited.xml");
            let cfg = match read_config(&edited, file, lattice) {
                Ok(c) => c,
                Err(e) if e.to_string().starts_with("edited.xml: ") => return Ok(()),
                Err(e) => return Err(format!("names no file: {e}")),
            };
            let _ = target_cells(&cfg, lattice);
            let s = import_config(&cfg, lattice, GroundChoice::Lowest, Length::mm(3.6), "e");
            let xml = export_config(&s, 0, lattice).map_err(|e| e.to_string())?;
            let back = read_config(&xml, file, lattice).map_err(|e| format!("{e}\n{xml}"))?;
            let s2 = import_config(&back, lattice, GroundChoice::Lowest, Length::mm(3.6), "e");
            if s2 != s {
                return Err(format!("round trip differs:\n{xml}"));
            }
            certify(&s, &Options::lattice_only()).map_err(|e| e.to_string())?;
            Ok(())
        }));
        match outcome {
            Ok(Ok(())) => {}
            Ok(Err(e)) => prop_assert!(false, "{e} on {edited:?}"),
            Err(_) => prop_assert!(false, "panicked on {edited:?}"),
        }
    }

    /// Motion traces: an edited bundled `rolls.csv` is refused (naming a
    /// line or the header) or becomes a schedule that is certified.
    #[test]
    fn edited_motion_traces_are_refused_or_imported_never_a_panic(
        edits in prop::collection::vec((any::<prop::sample::Index>(), 0usize..3, 0usize..1000), 1..6),
        one_per_step in any::<bool>(),
    ) {
        use reconfcheck::interop::{GroundChoice, TraceOptions, VsLattice, read_config, read_trace, trace_to_schedule};
        use reconfcheck::schedule::Length;
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let xml = std::fs::read_to_string(root.join("scenarios/visiblesim/rolls.xml")).unwrap();
        let cfg = read_config(&xml, Path::new("rolls.xml"), VsLattice::Fcc).unwrap();
        let edited = edited_model("scenarios/visiblesim/rolls.csv", &edits);
        let opts = TraceOptions {
            move_us: 400_000,
            one_per_step,
            ground: GroundChoice::Lowest,
            lattice: VsLattice::Fcc,
            spacing: Length::mm(3.6),
        };
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            for config in [Some(&cfg), None] {
                match read_trace(&edited).and_then(|rows| trace_to_schedule(&rows, config, &opts)) {
                    Ok(s) => {
                        s.validate().map_err(|e| e.to_string())?;
                        certify(&s, &Options::lattice_only()).map_err(|e| e.to_string())?;
                    }
                    Err(e) if e.message.starts_with("line ") || e.message.contains("trace")
                        || e.message.contains("start in one cell") => {}
                    Err(e) => return Err(format!("names no line: {e}")),
                }
            }
            Ok::<(), String>(())
        }));
        match outcome {
            Ok(Ok(())) => {}
            Ok(Err(e)) => prop_assert!(false, "{e} on {edited:?}"),
            Err(_) => prop_assert!(false, "panicked on {edited:?}"),
        }
    }
}
