//! The command line: exit codes, bad input named by file, step and module,
//! byte-identical reports.

use crate::common::{self, bin};

use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn scratch(name: &str) -> PathBuf {
    common::scratch("cli", name)
}

fn write(name: &str, text: &str) -> PathBuf {
    let p = scratch(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn certify(path: &Path) -> Output {
    bin()
        .arg("certify")
        .arg(path)
        .arg("--lattice-only")
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs `cmd`, asserts that it exits 0, and returns its standard output.
fn succeed(cmd: &mut Command) -> String {
    let o = cmd.output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// A JSON file a command wrote.
fn read_json(path: &Path) -> Value {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_slice(&bytes).unwrap()
}

/// A valid FCC schedule: one catom rolling twice over a fixed platform.
fn walk() -> Value {
    let mut modules: Vec<Value> = (0..3)
        .flat_map(|x| {
            (0..3).map(move |y| json!({"id": x * 3 + y, "cell": [x, y, 0], "fixed": true}))
        })
        .collect();
    modules.push(json!({"id": 100, "cell": [0, 0, 1]}));
    json!({
        "format": "reconfcheck-schedule",
        "version": 1,
        "lattice": "fcc",
        "spacing": {"value": 3.6, "unit": "mm"},
        "ground": {"layer": 0},
        "modules": modules,
        "steps": [
            {"events": [{"op": "rotate", "module": 100, "pivot": 3, "from": [0,0,1], "to": [1,0,1], "route": "octagonal"}]},
            {"events": [{"op": "rotate", "module": 100, "pivot": 6, "from": [1,0,1], "to": [2,0,1], "route": "octagonal"}]}
        ]
    })
}

/// Asserts exit code 2 and an error naming the file and every `needle`.
fn assert_input_error(name: &str, doc: &str, needles: &[&str]) {
    let p = write(name, doc);
    let o = certify(&p);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{name}: {err}");
    assert!(
        err.contains(name),
        "{name}: error does not name the file: {err}"
    );
    for n in needles {
        assert!(err.contains(n), "{name}: error lacks '{n}': {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn a_valid_schedule_exits_zero() {
    let p = write("valid.json", &walk().to_string());
    let o = certify(&p);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("CERTIFIED"));
}

#[test]
fn violations_exit_one() {
    let mut s = walk();
    // A second catom that ends in the same cell as the first.
    s["modules"]
        .as_array_mut()
        .unwrap()
        .push(json!({"id": 101, "cell": [1, 1, 1]}));
    s["steps"][0]["events"].as_array_mut().unwrap().push(
        json!({"op": "rotate", "module": 101, "pivot": 4, "from": [1,1,1], "to": [1,0,1], "route": "octagonal"}),
    );
    let p = write("clash.json", &s.to_string());
    let o = certify(&p);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("occupancy"));
}

#[test]
fn malformed_json_is_unusable_input() {
    assert_input_error(
        "malformed.json",
        "{\"format\": \"reconfcheck-schedule\", ",
        &["not a valid schedule"],
    );
}

#[test]
fn a_missing_file_is_unusable_input() {
    let o = bin()
        .args(["certify", "/nonexistent/where.json"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("/nonexistent/where.json"));
}

#[test]
fn an_unknown_lattice_is_unusable_input() {
    let mut s = walk();
    s["lattice"] = json!("hexagonal");
    assert_input_error("lattice.json", &s.to_string(), &["hexagonal", "fcc"]);
}

#[test]
fn an_unknown_version_is_unusable_input() {
    let mut s = walk();
    s["version"] = json!(7);
    assert_input_error("version.json", &s.to_string(), &["version 7"]);
}

#[test]
fn an_unknown_unit_is_unusable_input() {
    let mut s = walk();
    s["spacing"] = json!({"value": 3.6, "unit": "furlong"});
    assert_input_error("unit.json", &s.to_string(), &["furlong"]);
}

#[test]
fn an_unknown_module_id_is_named_with_its_step() {
    let mut s = walk();
    s["steps"][1]["events"][0]["module"] = json!(42);
    assert_input_error(
        "unknown.json",
        &s.to_string(),
        &["step 2", "module 42", "unknown module id"],
    );
}

#[test]
fn a_cell_beyond_the_coordinate_range_is_unusable_input() {
    // Found by tests/suite/fuzz.rs: i32::MIN as a coordinate overflowed the
    // neighbour arithmetic.
    let mut s = walk();
    s["steps"][1]["events"][0]["to"] = json!([-2147483648i64, 0, 1]);
    assert_input_error(
        "huge.json",
        &s.to_string(),
        &["step 2", "module 100", "beyond ±1048576"],
    );
    let mut s = walk();
    s["modules"][4]["cell"] = json!([0, 2000000, 0]);
    assert_input_error("huge-module.json", &s.to_string(), &["module 4", "beyond"]);
}

#[test]
fn a_spacing_that_is_not_a_positive_length_is_unusable_input() {
    for (name, value) in [
        ("zero.json", 0.0),
        ("negative.json", -3.6),
        ("subnormal.json", 1e-310),
    ] {
        let mut s = walk();
        s["spacing"]["value"] = json!(value);
        assert_input_error(name, &s.to_string(), &["spacing", "not a positive length"]);
    }
}

#[test]
fn scenario_parameters_out_of_range_are_refused_with_their_values() {
    // activity = -5 made the random-walk generator panic.
    let cases = [
        (
            "walk-activity.toml",
            "algorithm = \"random-walk\"\n[parameters]\nwidth = 5\ndepth = 5\nwalkers = 2\nsteps = 3\nactivity = -5.0\n",
            "activity is a probability in [0, 1], got -5",
        ),
        (
            "walk-size.toml",
            "algorithm = \"random-walk\"\n[parameters]\nwidth = 2147483647\ndepth = 3\nwalkers = 1\nsteps = 1\n",
            "got 2147483647 × 3",
        ),
        (
            "branch-spacing.toml",
            "algorithm = \"branch\"\n[parameters]\nlength = 3\nspacing_mm = -1.0\n",
            "spacing -1 mm is not a positive length",
        ),
    ];
    for (name, body, needle) in cases {
        let p = write(name, &format!("name = \"x\"\n{body}"));
        // `generate` refuses what `run` refuses: no schedule is written
        // that `certify` would not read.
        for command in ["run", "generate"] {
            let o = bin()
                .arg(command)
                .arg(&p)
                .args(["-o", scratch("refused.json").to_str().unwrap()])
                .output()
                .unwrap();
            let err = stderr(&o);
            assert_eq!(o.status.code(), Some(2), "{command} {name}: {err}");
            assert!(err.contains(name) && err.contains(needle), "{name}: {err}");
            assert!(!err.contains("panicked"), "{err}");
        }
    }
}

#[test]
fn a_move_to_a_non_neighbour_cell_is_unusable_input() {
    let mut s = walk();
    s["steps"][1]["events"][0]["to"] = json!([4, 0, 1]);
    assert_input_error(
        "far.json",
        &s.to_string(),
        &["step 2", "module 100", "not a fcc move"],
    );
}

#[test]
fn a_move_from_the_wrong_cell_is_unusable_input() {
    let mut s = walk();
    s["steps"][1]["events"][0]["from"] = json!([0, 0, 1]);
    assert_input_error(
        "from.json",
        &s.to_string(),
        &["step 2", "module 100", "impossible move"],
    );
}

#[test]
fn two_modules_in_one_initial_cell_are_unusable_input() {
    let mut s = walk();
    s["modules"]
        .as_array_mut()
        .unwrap()
        .push(json!({"id": 101, "cell": [0, 0, 1]}));
    assert_input_error(
        "twice.json",
        &s.to_string(),
        &["step 0", "module 101", "two modules in one cell"],
    );
}

#[test]
fn a_pivot_that_does_not_touch_the_mover_is_unusable_input() {
    let mut s = walk();
    s["steps"][0]["events"][0]["pivot"] = json!(8); // platform module at (2, 2, 0)
    assert_input_error(
        "pivot.json",
        &s.to_string(),
        &["step 1", "module 100", "not a neighbour"],
    );
}

#[test]
fn a_fixed_module_cannot_move() {
    let mut s = walk();
    s["steps"][0]["events"][0] = json!({"op": "rotate", "module": 0, "pivot": 1, "from": [0,0,0], "to": [1,0,0], "route": "octagonal"});
    assert_input_error(
        "fixed.json",
        &s.to_string(),
        &["step 1", "module 0", "fixed"],
    );
}

#[test]
fn an_unknown_event_field_is_unusable_input() {
    let mut s = walk();
    s["steps"][0]["events"][0]["speed"] = json!(3);
    assert_input_error("field.json", &s.to_string(), &["speed"]);
}

#[test]
fn a_malformed_scenario_is_unusable_input() {
    let p = write("bad.toml", "name = \"x\"\nalgorithm = [\n");
    let o = bin().arg("run").arg(&p).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("bad.toml"), "{}", stderr(&o));
}

#[test]
fn an_unknown_algorithm_is_unusable_input() {
    let p = write("algo.toml", "name = \"x\"\nalgorithm = \"teleport\"\n");
    let o = bin().arg("run").arg(&p).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(
        err.contains("algo.toml") && err.contains("teleport"),
        "{err}"
    );
}

#[test]
fn the_bundled_default_runs_and_certifies() {
    let o = bin().arg("run").output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("CERTIFIED"), "{out}");
    // The main job is the whole certification, physics included.
    assert!(
        out.contains("checks: lattice, collision, mechanics"),
        "{out}"
    );
    assert!(
        out.contains("highest max_utilisation over the steps: 0.3"),
        "{out}"
    );
}

#[test]
fn reports_are_byte_identical_across_runs() {
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/random-walk.toml");
    let run = |name: &str| {
        let out = scratch(name);
        let o = bin()
            .arg("run")
            .arg(&scenario)
            .arg("--json")
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        std::fs::read(out).unwrap()
    };
    let (a, b) = (run("r1.json"), run("r2.json"));
    assert!(a.len() > 1000);
    assert_eq!(a, b);
}

#[test]
fn generate_writes_a_schedule_that_certify_accepts() {
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/random-walk.toml");
    let out = scratch("generated.json");
    let o = bin()
        .arg("generate")
        .arg(&scenario)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = certify(&out);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn the_mechanics_check_runs_on_square_lattice_schedules_with_a_model() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = scratch("u-mech.json");
    let o = bin()
        .arg("run")
        .arg(root.join("scenarios/u-shape-sas.toml"))
        .arg("--model")
        .arg(root.join("models/sliding-square.toml"))
        .arg("--json")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let r: Value = read_json(&out);
    assert!(
        r["checks"]
            .as_array()
            .unwrap()
            .iter()
            .any(|c| c == "mechanics"),
        "{}",
        r["checks"]
    );
    let max = r["per_step"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|s| s["metrics"]["max_utilisation"].as_f64())
        .fold(0.0, f64::max);
    assert!(max > 0.0 && max < 1.0, "max utilisation {max}");
}

fn assert_png(path: &Path) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        bytes.len() > 1000,
        "{} is {} bytes",
        path.display(),
        bytes.len()
    );
    assert_eq!(&bytes[1..4], b"PNG", "{}", path.display());
}

/// A study of one b is a point per curve: its plot marks the closed forms
/// at that b (a cross each: two strokes in the closed form's colour), not
/// only the studied figures, and the range leaves room on either side.
#[cfg(feature = "render")]
#[test]
fn a_b_study_of_one_b_plots_its_closed_forms() {
    let svg = scratch("b-one.svg");
    succeed(
        bin()
            .arg("b-study")
            .args(["--family", "branch", "--b-min", "3", "--b-max", "3"])
            .arg("--plot")
            .arg(&svg),
    );
    let text = std::fs::read_to_string(&svg).unwrap();
    // Red: the utilisation's closed form; blue and green: the pressures'.
    for colour in ["#FF0000", "#0000FF", "#00FF00"] {
        let crosses = text
            .lines()
            .filter(|l| l.starts_with("<line") && l.contains(&format!("stroke=\"{colour}\"")))
            .count();
        assert!(crosses >= 2, "{colour}: {crosses} strokes");
    }
}

#[test]
fn b_study_of_the_pyramid_family_writes_a_table_a_plot_and_json() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let png = scratch("b-pyramid.png");
    let json = scratch("b-pyramid.json");
    let table = succeed(
        bin()
            .arg("b-study")
            .args(["--family", "pyramid", "--b-min", "4", "--b-max", "5"])
            .arg("--model")
            .arg(root.join("models/catom-3.6mm.toml"))
            .arg("--plot")
            .arg(&png)
            .arg("--json")
            .arg(&json),
    );
    assert!(table.contains("family 'pyramid'"), "{table}");
    assert!(table.contains("largest safe b at 100 kPa"), "{table}");
    assert_png(&png);
    let st: Value = read_json(&json);
    let rows = st["rows"].as_array().unwrap();
    assert_eq!(
        rows.iter()
            .map(|r| r["b"].as_u64().unwrap())
            .collect::<Vec<_>>(),
        [4, 5]
    );
    for r in rows {
        assert_eq!(r["lattice_violations"], 0, "{r}");
        let u = r["max_utilisation"].as_f64().unwrap();
        assert!(u > 0.0 && u < 1.0, "{r}");
    }
    assert_eq!(st["b_max"], 5);
}

#[test]
fn b_study_refuses_an_unknown_family_and_a_too_short_scaffold_branch() {
    let o = bin()
        .args(["b-study", "--family", "torus"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("pyramid"), "{}", stderr(&o));
    let o = bin()
        .args([
            "b-study", "--family", "cube", "--b-min", "3", "--b-max", "3",
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("b ≥ 4"), "{}", stderr(&o));
    // The CSG family needs its shape file, and the file must exist.
    let o = bin().args(["b-study", "--family", "csg"]).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--family csg"), "{}", stderr(&o));
    let o = bin()
        .args(["b-study", "--family", "csg", "--shape", "no-such-shape.csg"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("no-such-shape.csg"), "{}", stderr(&o));
}

#[test]
fn b_study_of_a_csg_shape_checks_its_scaffold_for_each_b() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let json = scratch("b-half-sphere.json");
    let o = bin()
        .args(["b-study", "--family", "csg", "--b-min", "5", "--b-max", "6"])
        .arg("--shape")
        .arg(root.join("models/shapes/half-sphere-d3.csg"))
        .arg("--model")
        .arg(root.join("models/catom-3.6mm.toml"))
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let st: Value = read_json(&json);
    let rows = st["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    for r in rows {
        assert_eq!(r["lattice_violations"], 0, "{r}");
        // The half-sphere of side 3 holds b = 5 and 6 (0.52, 0.58).
        let u = r["max_utilisation"].as_f64().unwrap();
        assert!(u > 0.3 && u < 0.8, "{r}");
    }
    assert_eq!(st["b_max"], 6);
}

#[test]
fn loadmap_draws_a_scaffold_step_and_names_its_critical_connector() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scenario = write(
        "p2b6.toml",
        "name = \"p2b6\"\nalgorithm = \"scaffold\"\n[parameters]\nshape = \"pyramid\"\nh = 2\nb = 6\n",
    );
    let schedule = scratch("p2b6.json");
    let o = bin()
        .arg("generate")
        .arg(&scenario)
        .arg("-o")
        .arg(&schedule)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let png = scratch("p2b6-loadmap.png");
    let o = bin()
        .arg("loadmap")
        .arg(&schedule)
        .args(["--step", "22"])
        .arg("--model")
        .arg(root.join("models/catom-3.6mm.toml"))
        .arg("-o")
        .arg(&png)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let summary = String::from_utf8_lossy(&o.stdout);
    // The b-study's worst step of this pyramid: the first connector of a
    // horizontal branch of b = 6 carries (b − 2)(b − 1)/2 = 10 module
    // weights times d, 0.347 of the 100 kPa rigid-hinge capacity.
    assert!(summary.contains("step 22"), "{summary}");
    assert!(summary.contains("max utilisation 0.3469"), "{summary}");
    assert_png(&png);
    // A step beyond the final configuration is unusable input.
    let o = bin()
        .arg("loadmap")
        .arg(&schedule)
        .args(["--step", "100000"])
        .arg("--model")
        .arg(root.join("models/catom-3.6mm.toml"))
        .arg("-o")
        .arg(scratch("never.png"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// `generate` used to copy the scenario's relative `model` path verbatim;
/// `certify` resolves it against the schedule's folder, so a schedule
/// written elsewhere (here a temp dir) lost its model (exit 2).
#[test]
fn a_generated_schedule_certifies_with_its_model_from_another_folder() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = scratch("generated/pyramid-h2-b8.json");
    std::fs::create_dir_all(out.parent().unwrap()).unwrap();
    let g = bin()
        .current_dir(root)
        .args(["generate", "scenarios/pyramid-h2-b8.toml", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(g.status.code(), Some(0), "{}", stderr(&g));
    let s: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let model = s["model"].as_str().expect("the schedule names its model");
    assert!(
        out.parent().unwrap().join(model).is_file(),
        "model {model} does not resolve from {}",
        out.display()
    );
    let c = bin()
        .current_dir(out.parent().unwrap())
        .arg("certify")
        .arg(&out)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&c.stdout);
    assert_eq!(c.status.code(), Some(0), "{}{text}", stderr(&c));
    assert!(text.contains("mechanics"), "{text}");
}

#[test]
fn density_study_takes_a_growth_rule_writes_json_and_refuses_an_unknown_rule() {
    let png = scratch("density-chain.png");
    let json = scratch("density-chain.json");
    let table = succeed(
        bin()
            .arg("density-study")
            .args(["--sizes", "10", "--densities", "30,60", "--samples", "3"])
            .args(["--repeats", "2", "--growth", "chain", "-o"])
            .arg(&png)
            .arg("--json")
            .arg(&json),
    );
    assert!(table.contains("10x10  60%"), "{table}");
    assert!(
        table.contains("rises to a point and falls again"),
        "{table}"
    );
    assert_png(&png);
    let doc: Value = read_json(&json);
    assert_eq!(doc["format"], "reconfcheck-density-study");
    assert_eq!(doc["config"]["growth"], "chain");
    assert_eq!(doc["samples"].as_array().unwrap().len(), 2 * 3);
    assert_eq!(doc["rows"].as_array().unwrap().len(), 2);
    assert_eq!(doc["spread"][1]["repeats"], 2);
    assert_eq!(doc["rise_and_fall"][0]["size"], 10);
    // The JSON and the table tell the same medians.
    let median = doc["rows"][1]["sas"]["median"].as_f64().unwrap();
    assert!(
        table.contains(&format!("{median:.2}")),
        "{median} not in {table}"
    );
    let o = bin()
        .arg("density-study")
        .args(["--growth", "spiral", "-o"])
        .arg(&png)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("spiral"), "{}", stderr(&o));
}

#[test]
fn a_random_scenario_names_its_growth_rule() {
    let scenario = |growth: &str| {
        format!(
            "name = \"g\"\nalgorithm = \"active-subtraction\"\n[parameters]\nmode = \"pas\"\n\
             [parameters.random]\nwidth = 12\nheight = 12\ndensity = 0.4\nseed = 3\n{growth}"
        )
    };
    let generate = |name: &str, growth: &str| {
        let p = write(name, &scenario(growth));
        let out = scratch(&format!("{name}.json"));
        let o = bin()
            .arg("generate")
            .arg(&p)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        (o, out)
    };
    let (o, member) = generate("member.toml", "");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (o, chain) = generate("chain.toml", "growth = \"chain\"\n");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_ne!(
        std::fs::read(&member).unwrap(),
        std::fs::read(&chain).unwrap(),
        "the growth rule changes the configuration"
    );
    assert_eq!(certify(&chain).status.code(), Some(0));
    let (o, _) = generate("spiral.toml", "growth = \"spiral\"\n");
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(
        err.contains("spiral.toml") && err.contains("spiral"),
        "{err}"
    );
}

#[test]
fn plot_figure_12_draws_the_canonical_shapes_beside_the_published_points() {
    let out = scratch("fig12.png");
    let table = succeed(
        bin()
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .args([
                "plot",
                "--figure",
                "12",
                "--sizes",
                "2..3",
                "--no-progress",
                "-o",
            ])
            .arg(&out),
    );
    // Both protocols of the four shapes at two sizes, the pyramid beside
    // Eq. 6 and the cube beside the authors' run (their module counts).
    assert_eq!(table.lines().count(), 1 + 4 * 2 * 2, "{table}");
    assert!(
        table.contains("pyramid              2 paper    just-in-time       65")
            && table.contains("80 ("),
        "{table}"
    );
    assert!(
        table.contains("243 (") && table.contains("414 ="),
        "{table}"
    );
    let png = std::fs::read(&out).unwrap();
    assert!(png.starts_with(b"\x89PNG") && png.len() > 10_000);
    // The authors' feeding, on request: every run says so.
    let eager = succeed(
        bin()
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .args(["plot", "--figure", "12", "--sizes", "2", "--feed", "eager"])
            .args(["--no-progress", "-o"])
            .arg(&out),
    );
    assert_eq!(eager.lines().count(), 1 + 4 * 2, "{eager}");
    assert!(
        eager.lines().skip(1).all(|l| l.contains(" eager ")),
        "{eager}"
    );
}

#[test]
fn plot_refuses_an_unknown_figure_and_sizes_outside_the_authors_targets() {
    for args in [
        vec!["--figure", "10"],
        vec!["--figure", "11", "--sizes", "1..12"],
        vec!["--figure", "11", "--sizes", "two"],
        vec!["--figure", "11", "--feed", "flood"],
    ] {
        let o = bin()
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .arg("plot")
            .args(&args)
            .arg("-o")
            .arg(scratch("bad-fig.png"))
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(
            e.contains("--figure") || e.contains("--sizes") || e.contains("--feed"),
            "{e}"
        );
    }
}
