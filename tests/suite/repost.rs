//! RePoSt (seed 001): the meta-module operations derived by search, each a
//! sequence of real rotations that certifies clean (lattice, exact sweeps,
//! mechanics under the default model, the structure resting on the ground).

use reconfcheck::algorithms::repost::metamodule::{Direction, Meta, State};
use reconfcheck::algorithms::repost::operation_schedule;
use reconfcheck::algorithms::repost::operations::{self, Role};
use reconfcheck::certify::{Options, World, certify};
use reconfcheck::lattice::Cell;
use std::path::PathBuf;

use crate::common;

fn fill_name(fill: State) -> &'static str {
    if fill == State::Full {
        "full"
    } else {
        "sparse"
    }
}

/// (direction, assemble, dismantle, transfer, assemble, support moves):
/// what the search derives today. A change in the rules, the scene or the
/// search that changes a count must be looked at (and docs/repost.md
/// updated), not just re-pinned.
/// Assemble FULL in the four horizontal directions needs the deep budget
/// (`operations::DEEP_SEARCH_BUDGET`).
const COUNTS: &[(Direction, State, usize, usize, usize, usize)] = &[
    (Direction::Up, State::Sparse, 15, 17, 46, 36),
    (Direction::Down, State::Sparse, 16, 39, 44, 34),
    (Direction::Right, State::Sparse, 33, 45, 80, 0),
    (Direction::Left, State::Sparse, 30, 48, 80, 0),
    (Direction::Back, State::Sparse, 31, 45, 78, 0),
    (Direction::Front, State::Sparse, 31, 45, 79, 0),
    (Direction::Up, State::Full, 18, 24, 56, 11),
    (Direction::Down, State::Full, 23, 28, 49, 8),
    (Direction::Right, State::Full, 33, 44, 114, 0),
    (Direction::Left, State::Full, 30, 47, 110, 0),
    (Direction::Back, State::Full, 31, 44, 115, 0),
    (Direction::Front, State::Full, 31, 44, 114, 0),
];

/// Each operation derived once for the tests of this file (the four
/// horizontal FULL ones take seconds each).
fn derived(dir: Direction, fill: State) -> &'static operations::OperationPlan {
    use std::sync::{Mutex, OnceLock};
    type Plans = Mutex<Vec<((Direction, State), &'static operations::OperationPlan)>>;
    static PLANS: OnceLock<Plans> = OnceLock::new();
    let mut plans = PLANS.get_or_init(|| Mutex::new(Vec::new())).lock().unwrap();
    if let Some(p) = plans.iter().find(|(k, _)| *k == (dir, fill)) {
        return p.1;
    }
    let p = operations::derive(dir, fill).unwrap_or_else(|e| panic!("{dir:?} {fill:?}: {e}"));
    let p: &'static operations::OperationPlan = Box::leak(Box::new(p));
    plans.push(((dir, fill), p));
    p
}

#[test]
fn every_operation_is_derived_in_all_six_directions_with_its_move_counts() {
    let mut got = Vec::new();
    for fill in [State::Sparse, State::Full] {
        for dir in Direction::ALL {
            let p = derived(dir, fill);
            got.push((
                dir,
                fill,
                p.count(Role::Dismantle),
                p.count(Role::Transfer),
                p.count(Role::Assemble),
                p.count(Role::Support),
            ));
            eprintln!(
                "{:>6} {:>6}: dismantle {:>3} transfer {:>3} assemble {:>3} support {:>3} total {:>3} strict {} {}",
                dir.name(),
                fill_name(fill),
                p.count(Role::Dismantle),
                p.count(Role::Transfer),
                p.count(Role::Assemble),
                p.count(Role::Support),
                p.rotations.len(),
                p.strict,
                p.order
            );
        }
    }
    assert_eq!(got, COUNTS);
}

/// Each derived operation is a schedule of real rotations (pivot latched
/// to both ends, pivot static, target free, structure connected) and ends
/// with the source cell empty and the goal cells filled.
#[test]
fn every_derived_operation_replays_as_lattice_moves_and_fills_its_goal() {
    for &(dir, fill, ..) in COUNTS {
        let p = derived(dir, fill);
        let s = operation_schedule(p, 3.6);
        let r = certify(&s, &Options::lattice_only()).unwrap();
        assert!(r.certified, "{dir:?} {fill:?}: {}", r.summary());
        let mut w = World::initial(&s).unwrap();
        for (k, step) in s.steps.iter().enumerate() {
            let plan = w.resolve(k + 1, step).unwrap();
            w.apply(&plan);
        }
        let filled: Vec<Cell> = p.scene.targets();
        for c in &filled {
            assert!(w.config().at(*c).is_some(), "{dir:?} {fill:?}: {c} empty");
        }
        for c in p.scene.source.sparse_cells() {
            assert!(
                w.config().at(c).is_none(),
                "{dir:?} {fill:?}: source {c} kept"
            );
        }
        assert_eq!(s.move_count(), p.rotations.len());
    }
}

/// The bundled scenario certifies clean with every check: lattice, exact
/// sweeps and mechanics under the default model, resting on the ground.
#[test]
fn the_bundled_operation_scenario_certifies_clean_with_sweeps_and_mechanics() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let o = common::bin()
        .arg("run")
        .arg(root.join("scenarios/repost-operation.toml"))
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{out}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        out.contains("CERTIFIED") && out.contains("mechanics"),
        "{out}"
    );
    assert!(out.contains("158 moves"), "{out}");
}

/// Generates a `repost` scenario over the shape files `shapes` (name,
/// text), written to a fresh folder `tag`: its exit code and stderr.
fn generate_repost(
    tag: &str,
    shapes: &[(&str, &str)],
    initial: &str,
    goal: &str,
) -> (Option<i32>, String) {
    for (name, text) in shapes {
        std::fs::write(common::scratch(tag, name), text).unwrap();
    }
    let sc = common::scratch(tag, "s.toml");
    std::fs::write(
        &sc,
        format!("name = \"{tag}\"\nalgorithm = \"repost\"\n[parameters]\ninitial = \"{initial}\"\ngoal = \"{goal}\"\n"),
    )
    .unwrap();
    let o = common::bin()
        .args(["generate", sc.to_str().unwrap(), "-o"])
        .arg(common::scratch(tag, "out.json"))
        .output()
        .unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// A shape file with a cell off the meta-module lattice is unusable input:
/// exit 2, naming the file and the cell.
#[test]
fn a_shape_cell_off_the_meta_module_lattice_exits_2_naming_file_and_cell() {
    let shapes = [
        ("bad.txt", "0 0 0\n4 1 0\n"),
        ("good.txt", "0 0 0\n4 0 0\n"),
    ];
    let (code, err) = generate_repost("bad", &shapes, "good.txt", "bad.txt");
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("bad.txt") && err.contains("(4, 1, 0)"),
        "{err}"
    );
}

/// A goal the planner cannot reach (no meta-module in both shapes, or a
/// goal outside the ⌈N/20⌉ ≤ S_G ≤ N/10 bound) is refused with exit 2.
#[test]
fn a_goal_outside_the_compression_bound_exits_2_naming_the_bound() {
    let shapes = [
        ("one.txt", "0 0 0\n"),
        ("three.txt", "0 0 0\n4 0 0\n8 0 0\n"),
    ];
    let (code, err) = generate_repost("bound", &shapes, "one.txt", "three.txt");
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("three.txt") && err.contains("N/10"), "{err}");
}

/// Generates the bundled scenario `scenarios/{name}.toml`.
fn generate_bundled(name: &str) -> reconfcheck::schedule::Schedule {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let sc = reconfcheck::scenario::Scenario::load(&root.join(format!("scenarios/{name}.toml")))
        .unwrap();
    reconfcheck::algorithms::generate(&sc).unwrap_or_else(|e| panic!("{e}"))
}

/// Certifies `s` with its model removed (lattice checks and the exact
/// sweeps of every concurrent pair) and asserts that it passes, the
/// collision check included.
fn certifies_collision_free(s: &reconfcheck::schedule::Schedule) {
    let mut geometry_only = s.clone();
    geometry_only.model = None;
    let r = certify(&geometry_only, &Options::default()).unwrap();
    assert!(r.checks.iter().any(|c| c == "collision"), "{:?}", r.checks);
    assert!(r.certified, "{}", r.summary());
}

/// Replays the schedule's rotations and asserts that the catoms end
/// exactly on the goal shape `file` (`models/shapes/repost/`): the loops
/// of its meta-modules, and the interiors of its FULL ones.
fn ends_on_the_goal(s: &reconfcheck::schedule::Schedule, file: &str) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    ends_on(s, &root.join("models/shapes/repost").join(file));
}

/// [`ends_on_the_goal`] for the shape file at `path`.
fn ends_on(s: &reconfcheck::schedule::Schedule, path: &std::path::Path) {
    use reconfcheck::algorithms::repost::shape;
    let file = path.display();
    let goal = shape::load(path).unwrap();
    let mut want: Vec<Cell> = goal
        .iter()
        .flat_map(|(m, st): (&Meta, &State)| m.cells(*st))
        .collect();
    let mut got: Vec<Cell> = common::final_cells(s).into_values().collect();
    want.sort();
    got.sort();
    assert_eq!(got, want, "the catoms do not end on the loops of {file}");
}

/// The paper's L → C case (Fig. 8) plans to the end: every leaf as a
/// source walls one in (a source on the ground between two meta-modules
/// still to go), so the plan peels from the far end of the L
/// (`source_width`, docs/repost.md). The schedule ends on the C's cells,
/// every catom of the C where the goal's SPARSE loops are, runs pipelined
/// (several catoms per step), and certifies with the lattice checks and
/// the exact sweeps of every concurrent mover (mechanics: measured in
/// docs/repost.md, far too long for the suite).
/// With the paper's goal order (any empty goal cell next to a SPARSE goal
/// meta-module), it takes the paper's 7 iterations.
#[test]
fn the_l_to_c_planner_completes_and_its_schedule_is_collision_free() {
    let s = generate_bundled("repost-l-to-c");
    assert_eq!(s.meta["goal_order"], "paper");
    assert_eq!(s.meta["iterations"].as_u64(), Some(7));
    assert!(
        s.meta["source_width"].is_u64(),
        "{:?}",
        s.meta["source_width"]
    );
    ends_on_the_goal(&s, "c-48.txt");
    // The streamlines run pipelined: every iteration, and several catoms
    // per step (one at a time would be 7,186 steps).
    let detail = s.meta["iteration_detail"].as_array().unwrap();
    assert!(
        detail.iter().all(|it| it["pipelined"] == true),
        "{detail:?}"
    );
    let rotations: usize = s.steps.iter().map(|st| st.events.len()).sum();
    assert!(
        rotations >= 4 * s.steps.len(),
        "{rotations} rotations in {} steps",
        s.steps.len()
    );
    assert!(s.steps.iter().any(|st| st.events.len() >= 10));
    // Concurrent movers are exactly what the certifier checks pairwise
    // with the exact body.
    certifies_collision_free(&s);
}

/// Two catoms rolling along a row on the ground, the second planned
/// against the first's end state: pipelined, the second follows the first
/// instead of waiting for it to arrive, and the certifier (lattice, exact
/// sweeps of both movers) finds nothing; the sequential order is the
/// sum of the paths.
#[test]
fn a_follower_catom_sets_off_before_its_leader_arrives_and_the_pipeline_certifies() {
    use reconfcheck::algorithms::repost::pipeline::pipeline;
    use reconfcheck::algorithms::repost::search::Scene;
    use reconfcheck::lattice::LatticeKind;
    use reconfcheck::schedule::{Event, ModuleSpec, Schedule, Step};
    let mut scene = Scene::new(Some(0));
    let mut cells: Vec<Cell> = (0..10).map(|x| Cell::new(x, 0, 0)).collect();
    cells.extend([Cell::new(1, 0, 1), Cell::new(0, 0, 1)]);
    for (id, c) in cells.iter().enumerate() {
        scene.insert(id as u32, *c);
    }
    scene.fit_box(&[], 2);
    let (lead, follow) = (Cell::new(1, 0, 1), Cell::new(0, 0, 1));
    let (lead_goal, follow_goal) = (Cell::new(8, 0, 1), Cell::new(7, 0, 1));
    let p1 = scene
        .route(lead, lead_goal, false)
        .expect("the leader has a path");
    let mut after = scene.clone();
    let id = after.at.remove(&lead).unwrap();
    after.insert(id, lead_goal);
    let p2 = after
        .route(follow, follow_goal, false)
        .expect("the follower has a path");
    let rules = reconfcheck::geometry::motion_rules(LatticeKind::Fcc).unwrap();
    let out = pipeline(&scene, &[vec![p1.clone(), p2.clone()]], rules)
        .expect("the pipeline keeps the row anchored");
    let rotations: usize = out.steps.iter().map(Vec::len).sum();
    assert_eq!(rotations, p1.len() + p2.len());
    assert!(
        out.steps.len() < p1.len() + p2.len(),
        "{} steps, sequential {}",
        out.steps.len(),
        p1.len() + p2.len()
    );
    assert!(out.steps.iter().any(|s| s.len() == 2));
    assert!(out.lanes_at.iter().all(|&n| n == 1));
    // Replay as a schedule and certify it.
    let mut s = Schedule::new(LatticeKind::Fcc, reconfcheck::schedule::Length::mm(3.6));
    s.ground = Some(reconfcheck::lattice::Ground { layer: 0 });
    for (id, c) in cells.iter().enumerate() {
        s.modules.push(ModuleSpec {
            id: id as u32,
            cell: *c,
            fixed: false,
        });
    }
    let mut at = scene.at.clone();
    for step in &out.steps {
        let events: Vec<Event> = step
            .iter()
            .map(|h| Event::Rotate {
                module: at[&h.from],
                pivot: at[&h.pivot],
                from: h.from,
                to: h.to,
                route: h.route,
            })
            .collect();
        for h in step {
            let m = at.remove(&h.from).unwrap();
            at.insert(h.to, m);
        }
        s.steps.push(Step { events });
    }
    assert_eq!(at.get(&lead_goal), Some(&10));
    assert_eq!(at.get(&follow_goal), Some(&11));
    let r = certify(&s, &Options::default()).unwrap();
    assert!(r.checks.iter().any(|c| c == "collision"), "{:?}", r.checks);
    assert!(r.certified, "{}", r.summary());
}

/// `repost-study` on a three-meta-module line whose end climbs onto the
/// middle: the iteration table (with the paper's peak, 10 × streamlines),
/// Fig. 9 drawn as a PNG, and the JSON curves, whose rotations add up to
/// the table's; a scenario of another generator is refused with exit 2,
/// naming the file.
#[test]
fn repost_study_tabulates_and_draws_fig9_and_refuses_other_generators() {
    let tag = "repost-study";
    std::fs::write(common::scratch(tag, "i.txt"), "0 0 0\n4 0 0\n8 0 0\n").unwrap();
    std::fs::write(common::scratch(tag, "g.txt"), "0 0 0\n4 0 0\n4 -1 4\n").unwrap();
    let sc = common::scratch(tag, "s.toml");
    std::fs::write(
        &sc,
        "name = \"climb\"\nalgorithm = \"repost\"\n[parameters]\ninitial = \"i.txt\"\ngoal = \"g.txt\"\n",
    )
    .unwrap();
    let (png, json) = (
        common::scratch(tag, "f9.png"),
        common::scratch(tag, "f9.json"),
    );
    let out = common::succeeds(
        common::bin()
            .arg("repost-study")
            .arg(&sc)
            .arg("--plot")
            .arg(&png)
            .arg("--json")
            .arg(&json),
    );
    assert!(out.contains("Fig. 9, climb"), "{out}");
    assert!(out.contains("10×streaml."), "{out}");
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let motions: u64 = v["motions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m.as_u64().unwrap())
        .sum();
    let rows = v["iterations"].as_array().unwrap();
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0]["rotations"].as_u64(), Some(motions));
    assert!(motions >= 10, "{motions} rotations to build a loop of ten");
    assert!(out.contains(&format!("{motions} rotations")), "{out}");
    // Another generator's scenario.
    let o = common::bin()
        .args(["repost-study", "scenarios/repost-operation.toml"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("repost-operation.toml") && err.contains("algorithm"),
        "{err}"
    );
}

/// `repost-study --fig10` over the two smallest bundled sizes: both plan,
/// the table has a row each with the diameter (7 and 9: the C's, the
/// larger) and both fits, the JSON rows agree with the table, and Fig. 9
/// refuses two scenarios (exit 2, pointing to --fig10).
#[test]
fn repost_study_fig10_plans_each_size_and_fits_time_against_diameter() {
    let root = env!("CARGO_MANIFEST_DIR");
    let json = common::scratch("repost-fig10", "f10.json");
    let out = common::succeeds(
        common::bin()
            .args([
                "repost-study",
                "--fig10",
                "scenarios/repost-l-to-c-20.toml",
                "scenarios/repost-l-to-c-28.toml",
                "--json",
            ])
            .arg(&json)
            .current_dir(root),
    );
    assert!(out.contains("time steps vs diameter: slope"), "{out}");
    assert!(out.contains("rotations vs meta-modules: slope"), "{out}");
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    let diam: Vec<u64> = rows
        .iter()
        .map(|r| r["diameter"].as_u64().unwrap())
        .collect();
    assert_eq!(diam, [7, 9]);
    for r in rows {
        let line = format!(
            "{:<22} {:>6} {:>8} {:>10} {:>6} {:>9}",
            r["scenario"].as_str().unwrap(),
            r["metas"].as_u64().unwrap(),
            r["diameter"].as_u64().unwrap(),
            r["iterations"].as_u64().unwrap(),
            r["steps"].as_u64().unwrap(),
            r["rotations"].as_u64().unwrap()
        );
        assert!(out.contains(&line), "{line}\n{out}");
        let rotations = r["rotations"].as_u64().unwrap();
        assert!(rotations >= 10 * r["iterations"].as_u64().unwrap());
        // Fig. 10a: every phase of the protocol sends messages, the table
        // prints their sum, and motion coordination costs at least one
        // message per rotation (its Coordinate or its latching points).
        let m = &r["messages"];
        let parts =
            ["tree", "max_flow", "termination", "transport"].map(|k| m[k].as_u64().unwrap());
        assert!(parts.iter().all(|&p| p > 0), "{m}");
        let total: u64 = parts.iter().sum();
        assert!(
            out.contains(&format!("{line} {total:>9}")),
            "{total}\n{out}"
        );
        assert!(parts[3] >= rotations && parts[3] <= 30 * rotations, "{m}");
    }
    assert!(out.contains("messages vs rotations: slope"), "{out}");
    // Two points: the fit passes through both.
    let fit = &v["steps_vs_diameter"];
    assert!((fit["r2"].as_f64().unwrap() - 1.0).abs() < 1e-12, "{fit}");
    let o = common::bin()
        .args([
            "repost-study",
            "scenarios/repost-l-to-c-20.toml",
            "scenarios/repost-l-to-c-28.toml",
        ])
        .current_dir(root)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--fig10"), "{err}");
    // An output in a folder that does not exist is refused before the
    // minute of planning, naming the flag.
    for flag in ["--plot", "--json"] {
        let o = common::bin()
            .args(["repost-study", "--fig10", flag, "no-such-folder/f.png"])
            .current_dir(root)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.contains(flag) && err.contains("no-such-folder"),
            "{err}"
        );
        assert!(!err.contains("planning"), "{err}");
    }
}

/// The paper's expansion case (`scenarios/repost-expand-6x6x3.toml`): the
/// 36 FULL bottom meta-modules are emptied, their filling catoms carried
/// up in parallel, one streamline each, into a new top layer, in one
/// iteration, as the paper's video shows. Every catom ends on a SPARSE
/// loop of the 6 × 6 × 4 goal and the schedule certifies (lattice, exact
/// sweeps of every concurrent pair).
#[test]
fn the_expansion_empties_every_full_meta_module_into_a_new_top_layer_in_one_iteration() {
    let s = generate_bundled("repost-expand-6x6x3");
    assert_eq!(s.modules.len(), 1440);
    assert_eq!(s.meta["iterations"].as_u64(), Some(1));
    let it = &s.meta["iteration_detail"][0];
    assert_eq!(it["streamlines"].as_array().unwrap().len(), 36, "{it}");
    assert_eq!(it["pipelined"], true);
    // The streamlines run together: more rotations in one step than there
    // are streamlines.
    assert!(s.steps.iter().any(|st| st.events.len() > 36));
    ends_on_the_goal(&s, "block-6x6x4.txt");
    certifies_collision_free(&s);
}

/// A goal whose loops and fillings do not hold exactly the initial catoms
/// cannot be reached: exit 2, naming the goal file and both counts.
#[test]
fn a_goal_that_holds_a_different_number_of_catoms_is_refused_naming_the_goal_file() {
    let (code, err) = generate_repost(
        "repost-catoms",
        &[
            ("i.txt", "0 0 0\n4 0 0\n8 0 0\n"),
            ("g.txt", "0 0 0 full\n4 0 0 full\n"),
        ],
        "i.txt",
        "g.txt",
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("g.txt") && err.contains("hold 40 catoms") && err.contains("initial shape 30"),
        "{err}"
    );
}

/// Compression from the side: two meta-modules side by side along x
/// become one FULL meta-module, the right one's catoms filling the left
/// one's interior from the side (found with the deep search budget,
/// `operations::DEEP_SEARCH_BUDGET`). The catoms end on its loop and
/// interior, and the schedule certifies (lattice, exact sweeps).
#[test]
fn two_meta_modules_side_by_side_compress_into_one_full_filled_from_the_side() {
    let tag = "repost-side";
    let (code, err) = generate_repost(
        tag,
        &[("i.txt", "0 0 0\n4 0 0\n"), ("g.txt", "0 0 0 full\n")],
        "i.txt",
        "g.txt",
    );
    assert_eq!(code, Some(0), "{err}");
    let out = common::scratch(tag, "out.json");
    let s =
        reconfcheck::schedule::Schedule::from_json(&std::fs::read_to_string(&out).unwrap(), &out)
            .unwrap();
    assert_eq!(s.modules.len(), 20);
    ends_on(&s, &common::scratch(tag, "g.txt"));
    certifies_collision_free(&s);
}

/// Compression (filling destinations, §V-A), at its smallest: the
/// expansion case reversed, 2 × 2 × 4 SPARSE → 2 × 2 × 3 with a FULL
/// bottom. Each iteration's destinations are the meta-modules being
/// filled, the catoms end on the goal's loops and in its FULL interiors,
/// and the schedule certifies (lattice, exact sweeps of every concurrent
/// pair).
#[test]
fn compression_fills_the_bottom_meta_modules_with_the_top_layer() {
    let s = generate_bundled("repost-compress-2x2x4");
    assert_eq!(s.modules.len(), 160);
    let its = s.meta["iteration_detail"].as_array().unwrap();
    let mut filled = Vec::new();
    for it in its {
        for d in it["destinations"].as_array().unwrap() {
            assert_eq!(d[0], d[1], "a filling destination is its own goal: {it}");
            assert_eq!(d[0]["z"], 0, "{it}");
            filled.push(d[0].clone());
        }
        for src in it["sources"].as_array().unwrap() {
            assert_eq!(src["z"], 3, "{it}");
        }
    }
    assert_eq!(filled.len(), 4, "each bottom meta-module filled once");
    ends_on_the_goal(&s, "block-2x2x3-full-bottom.txt");
    certifies_collision_free(&s);
}

/// `goal_order`: the paper's (default) assigns any empty goal cell next to
/// a SPARSE goal meta-module; "bottom-up" (ours, stricter) makes a cell
/// wait for the one below it. Counted independently on the iterations'
/// destinations: cells filled above a goal cell not yet built (neither in
/// the initial shape nor an earlier destination). The paper's order fills
/// more of them, in half the iterations (the 28-meta-module L → C: 4
/// against 8); both end on the goal and certify collision-free.
#[test]
fn the_papers_goal_order_fills_cells_above_empty_ones_and_needs_fewer_iterations() {
    use reconfcheck::algorithms::repost::metamodule::{Direction, Meta};
    use reconfcheck::algorithms::repost::shape;
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let base = reconfcheck::scenario::Scenario::load(&root.join("scenarios/repost-l-to-c-28.toml"))
        .unwrap();
    let initial = shape::load(&root.join("models/shapes/repost/l-28.txt")).unwrap();
    let goal = shape::load(&root.join("models/shapes/repost/c-28.txt")).unwrap();
    let run = |order: &str| {
        let mut sc = base.clone();
        sc.parameters
            .insert("goal_order".into(), toml::Value::String(order.into()));
        let s = reconfcheck::algorithms::generate(&sc).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.meta["goal_order"], order);
        ends_on_the_goal(&s, "c-28.txt");
        certifies_collision_free(&s);
        // Destination cells filled above a cell never built.
        let mut built: std::collections::BTreeSet<Meta> = initial.keys().copied().collect();
        let mut hanging = 0;
        for it in s.meta["iteration_detail"].as_array().unwrap() {
            let cells: Vec<(Meta, Meta)> =
                serde_json::from_value(it["destinations"].clone()).unwrap();
            for &(d, e) in &cells {
                let below = e.step(Direction::Down);
                if d != e && goal.contains_key(&below) && !built.contains(&below) {
                    hanging += 1;
                }
            }
            built.extend(cells.iter().map(|&(_, e)| e));
        }
        (s.meta["iterations"].as_u64().unwrap(), hanging)
    };
    let (paper, bottom_up) = (run("paper"), run("bottom-up"));
    assert_eq!((paper.0, bottom_up.0), (4, 8));
    // Bottom-up does so only where no goal cell is ready at all (then
    // every empty one is, or the plan would stop).
    assert!(paper.1 > bottom_up.1, "{paper:?} {bottom_up:?}");
    let mut bad = base.clone();
    bad.parameters
        .insert("goal_order".into(), toml::Value::String("top-down".into()));
    let e = reconfcheck::algorithms::generate(&bad).unwrap_err();
    assert!(
        e.message.contains("parameter goal_order") && e.message.contains("'top-down'"),
        "{}",
        e.message
    );
    assert_eq!(e.file.as_deref(), Some(base.path.as_path()));
}

/// `goal_order = "supported"` (ours, stricter): each empty goal cell is
/// assembled from the SPARSE neighbour that holds it best, by the most
/// connectors to it and then to the rest of the structure. The L → C-36's
/// top arm in small: the goal cell (0, 1, 1) has two SPARSE neighbours,
/// (1, 1, 1), which hangs on one side connector from (1, 0, 1), and
/// (0, 0, 1), stacked on (0, 0, 0). The paper's rule takes the first in
/// its order of directions, the hanging one; "supported" the stacked one.
/// Both plans end on the goal and certify collision-free.
#[test]
fn the_supported_goal_order_assembles_a_cell_from_its_best_held_neighbour() {
    let tag = "repost-supported";
    // Leaders of (0,0,0) (1,0,0) (0,0,1) (1,0,1) (1,1,1), then the
    // source (-1,0,0) or the goal cell (0,1,1).
    let common_cells = "0 0 0\n4 0 0\n0 -1 4\n4 -1 4\n4 2 4\n";
    std::fs::write(
        common::scratch(tag, "i.txt"),
        format!("{common_cells}-4 0 0\n"),
    )
    .unwrap();
    std::fs::write(
        common::scratch(tag, "g.txt"),
        format!("{common_cells}0 2 4\n"),
    )
    .unwrap();
    let destination = |order: &str| {
        let sc = common::scratch(tag, &format!("{order}.toml"));
        std::fs::write(
            &sc,
            format!("name = \"{tag}\"\nalgorithm = \"repost\"\n[parameters]\ninitial = \"i.txt\"\ngoal = \"g.txt\"\ngoal_order = \"{order}\"\n"),
        )
        .unwrap();
        let scenario = reconfcheck::scenario::Scenario::load(&sc).unwrap();
        let s = reconfcheck::algorithms::generate(&scenario).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.meta["goal_order"], order);
        ends_on(&s, &common::scratch(tag, "g.txt"));
        certifies_collision_free(&s);
        let its = s.meta["iteration_detail"].as_array().unwrap();
        assert_eq!(its.len(), 1, "{order}");
        let cells: Vec<(Meta, Meta)> =
            serde_json::from_value(its[0]["destinations"].clone()).unwrap();
        assert_eq!(cells.len(), 1, "{order}");
        assert_eq!(cells[0].1, Meta::new(0, 1, 1), "{order}");
        cells[0].0
    };
    assert_eq!(destination("paper"), Meta::new(1, 1, 1));
    assert_eq!(destination("supported"), Meta::new(0, 0, 1));
    // The joints it weighs: (1, 1, 1) holds on to (1, 0, 1) alone, by one
    // connector; (0, 0, 1) to (0, 0, 0) by four and to (1, 0, 1) by one.
    assert_eq!(Meta::new(1, 1, 1).joints(Meta::new(1, 0, 1)), 1);
    assert_eq!(Meta::new(0, 0, 1).joints(Meta::new(0, 0, 0)), 4);
    // The bundled L -> C-36 in this order names the model it certifies
    // under (docs/repost.md): connectors at 125 kPa, the base at 100.
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let sc = reconfcheck::scenario::Scenario::load(
        &root.join("scenarios/repost-l-to-c-36-supported.toml"),
    )
    .unwrap();
    assert_eq!(sc.parameters["goal_order"].as_str(), Some("supported"));
    let model =
        reconfcheck::mechanics::Model::load(&sc.resolve(sc.model.as_ref().unwrap())).unwrap();
    assert_eq!(
        (model.connector.pressure, model.ground.pressure),
        (125e3, 100e3)
    );
}

/// The porous structure's joints, counted from the lattice's neighbours:
/// two SPARSE meta-modules side by side (along X or Y) touch through
/// exactly one catom–catom connector, one above the other through four.
/// So a meta-module held only by a side neighbour hangs on one connector:
/// under the default model (100 kPa) it holds along X and not along Y,
/// where the collapse mechanism is that one connector at load factor
/// 0.939 — the overloads of the 28-meta-module L → C (`docs/repost.md`).
#[test]
fn a_sparse_meta_module_hangs_on_one_connector_from_a_side_neighbour_and_breaks_it_along_y() {
    use reconfcheck::certify::ViolationKind;
    use reconfcheck::lattice::{FccLattice, Lattice, LatticeKind};
    use reconfcheck::schedule::{Length, ModuleSpec, Schedule};
    let joints = |a: Meta, b: Meta| {
        let other: Vec<Cell> = b.sparse_cells().to_vec();
        a.sparse_cells()
            .iter()
            .flat_map(|&c| FccLattice.neighbours(c))
            .filter(|n| other.contains(n))
            .count()
    };
    for m in [Meta::new(0, 0, 0), Meta::new(1, 0, 1), Meta::new(0, 1, 0)] {
        for (d, n) in [((1, 0, 0), 1), ((0, 1, 0), 1), ((0, 0, 1), 4)] {
            let next = Meta::new(m.x + d.0, m.y + d.1, m.z + d.2);
            assert_eq!(joints(m, next), n, "{m:?} to {next:?}");
            assert_eq!(m.joints(next), n, "the planner's count, {m:?} to {next:?}");
            assert_eq!(next.joints(m), n, "{next:?} to {m:?}");
        }
    }
    let model = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models/catom-3.6mm.toml");
    let hanging = |side: Meta| {
        let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(3.6));
        let cells = Meta::new(0, 0, 0)
            .sparse_cells()
            .into_iter()
            .map(|c| (c, true));
        let free = side.sparse_cells().into_iter().map(|c| (c, false));
        for (i, (cell, fixed)) in cells.chain(free).enumerate() {
            s.modules.push(ModuleSpec {
                id: i as u32 + 1,
                cell,
                fixed,
            });
        }
        let o = Options {
            model: Some(model.clone()),
            ..Default::default()
        };
        certify(&s, &o).unwrap()
    };
    assert!(hanging(Meta::new(1, 0, 0)).certified, "along X it holds");
    let r = hanging(Meta::new(0, 1, 0));
    let v: Vec<_> = r.violations_of(ViolationKind::Overload).collect();
    assert_eq!(v.len(), 1, "{}", r.summary());
    let lf = v[0].detail["load_factor"].as_f64().unwrap();
    assert!((lf - 0.939).abs() < 1e-3, "{lf}");
    assert!(v[0].detail["share"].as_f64().unwrap() > 0.999);
    // The connector named joins the fixed meta-module (ids 1-10) to the
    // hanging one (11-20).
    let ids = &v[0].modules;
    assert!(ids.len() == 2 && ids.iter().any(|&i| i <= 10) && ids.iter().any(|&i| i > 10));
}

/// The meta-modules of the shape files `initial_file` and `goal_file`
/// (`models/shapes/repost/`), and the goal's that are built (not in the
/// initial shape) off the ground layer.
fn built_off_the_floor(initial_file: &str, goal_file: &str) -> (Vec<Meta>, Vec<Meta>, Vec<Meta>) {
    use reconfcheck::algorithms::repost::shape;
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models/shapes/repost");
    let initial = shape::load(&dir.join(initial_file)).unwrap();
    let goal = shape::load(&dir.join(goal_file)).unwrap();
    let floor = initial.keys().map(|m| m.z).min().unwrap();
    let built = goal
        .keys()
        .filter(|m| !initial.contains_key(m) && m.z != floor)
        .copied()
        .collect();
    (
        initial.into_keys().collect(),
        goal.into_keys().collect(),
        built,
    )
}

/// For each goal meta-module that is built (not in `initial_file`) off
/// the ground layer: the connectors from its loop to catoms outside it,
/// counted from the lattice at the step its last catom arrives.
fn joints_at_completion(
    s: &reconfcheck::schedule::Schedule,
    initial_file: &str,
    goal_file: &str,
) -> Vec<(Meta, usize)> {
    use reconfcheck::lattice::{FccLattice, Lattice};
    use reconfcheck::schedule::Event;
    let (_, _, mut open) = built_off_the_floor(initial_file, goal_file);
    let mut at: std::collections::HashSet<Cell> = s.modules.iter().map(|m| m.cell).collect();
    let mut out = Vec::new();
    for step in &s.steps {
        for e in &step.events {
            if let Event::Rotate { from, to, .. } = e {
                at.remove(from);
                at.insert(*to);
            }
        }
        open.retain(|m| {
            let cells = m.sparse_cells();
            if !cells.iter().all(|c| at.contains(c)) {
                return true;
            }
            let joints = cells
                .iter()
                .flat_map(|c| FccLattice.neighbours(*c))
                .filter(|n| at.contains(n) && !cells.contains(n))
                .count();
            out.push((*m, joints));
            false
        });
    }
    assert!(
        open.is_empty(),
        "goal meta-modules never completed: {open:?}"
    );
    out
}

/// The goal meta-modules built off the ground layer whose first catom
/// to come to rest (the first of its loop cells to receive the catom
/// that stays there) touches no catom of a complete meta-module at that
/// step: a loop begun on what is still being built, hanging from it.
fn loops_begun_on_an_unfinished_neighbour(
    s: &reconfcheck::schedule::Schedule,
    initial_file: &str,
    goal_file: &str,
) -> Vec<Meta> {
    use reconfcheck::lattice::{FccLattice, Lattice};
    use reconfcheck::schedule::Event;
    use std::collections::{HashMap, HashSet};
    let (initial, goal, built) = built_off_the_floor(initial_file, goal_file);
    // The step at which each cell receives the catom that stays there.
    let mut last: HashMap<Cell, usize> = HashMap::new();
    for (k, step) in s.steps.iter().enumerate() {
        for e in &step.events {
            if let Event::Rotate { to, .. } = e {
                last.insert(*to, k);
            }
        }
    }
    let first: HashMap<Meta, (usize, Cell)> = built
        .iter()
        .map(|m| {
            let c = m
                .sparse_cells()
                .into_iter()
                .min_by_key(|c| last[c])
                .unwrap();
            (*m, (last[&c], c))
        })
        .collect();
    // A complete loop is one of the initial shape's or one built.
    let metas: HashSet<Meta> = initial.into_iter().chain(goal).collect();
    let mut at: HashSet<Cell> = s.modules.iter().map(|m| m.cell).collect();
    let mut out = Vec::new();
    for (k, step) in s.steps.iter().enumerate() {
        for e in &step.events {
            if let Event::Rotate { from, to, .. } = e {
                at.remove(from);
                at.insert(*to);
            }
        }
        for (m, &(step_of, c)) in &first {
            if step_of != k {
                continue;
            }
            let held = metas.iter().any(|n| {
                let loop_ = n.sparse_cells();
                n != m
                    && loop_.iter().all(|x| at.contains(x))
                    && loop_.iter().any(|x| FccLattice.are_neighbours(*x, c))
            });
            if !held {
                out.push(*m);
            }
        }
    }
    out
}

/// `goal_order = "paired"` on the 20-meta-module L -> C
/// (`scenarios/repost-l-to-c-20-paired.toml`): each loop of the C's
/// top-arm pair is begun at the cell that touches its complete holder and
/// grown from there towards the other (before, the second loop was begun
/// at its joint with the first loop's tip, out of the arc's order, and
/// its arc hung from that tip: twelve catoms on one connector, load
/// factor 0.374 at 100 kPa). The pair is assembled together, every goal
/// meta-module off the ground completes with two connectors or more, and
/// the plan ends on the goal, collision-free.
#[test]
fn the_paired_order_begins_each_loop_at_its_holder() {
    let s = generate_bundled("repost-l-to-c-20-paired");
    ends_on_the_goal(&s, "c-20.txt");
    certifies_collision_free(&s);
    assert_eq!(
        loops_begun_on_an_unfinished_neighbour(&s, "l-20.txt", "c-20.txt"),
        []
    );
    let joints = joints_at_completion(&s, "l-20.txt", "c-20.txt");
    assert_eq!(joints.len(), 4, "{joints:?}");
    assert!(joints.iter().all(|(_, j)| *j >= 2), "{joints:?}");
}

/// The paired L -> C-20 certifies with every check at the default 100 kPa
/// on the latched base (`models/catom-3.6mm-latched-base.toml`): lowest
/// load factor 1.109 at step 166, where the paper's order fails at six
/// steps (0.827) and the paired order before its loops were grown in
/// order at 35 (0.374). Ignored: about 9 minutes in release (`cargo
/// test --release --test suite repost::the_paired_l_to_c_20 --
/// --ignored`).
#[test]
#[ignore]
fn the_paired_l_to_c_20_certifies_at_100_kpa_on_a_latched_base() {
    let s = generate_bundled("repost-l-to-c-20-paired");
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let o = Options {
        model: Some(root.join("models/catom-3.6mm-latched-base.toml")),
        load_factor_tolerance: 0.2,
        ..Default::default()
    };
    let r = certify(&s, &o).unwrap();
    assert!(r.checks.iter().any(|c| c == "mechanics"), "{:?}", r.checks);
    assert!(r.certified, "{}", r.summary());
}

/// `goal_order = "paired"` on the 28-meta-module L -> C: the C's arm rows
/// that would each hang on one side connector are assembled in pairs,
/// so every goal meta-module off the ground completes with at least two
/// connectors to the rest; in the "supported" order two of them complete
/// on one (the overloads at 100 kPa, docs/repost.md). The plan ends on
/// the goal and certifies collision-free; every goal loop is begun at its
/// holder. Ignored: planning both orders takes about 40 s in release (`cargo test --release --test suite
/// repost::the_paired_order -- --ignored`).
#[test]
#[ignore]
fn the_paired_order_completes_no_goal_meta_module_on_a_single_connector() {
    let s = generate_bundled("repost-l-to-c-28-paired");
    assert_eq!(s.meta["goal_order"], "paired");
    ends_on_the_goal(&s, "c-28.txt");
    certifies_collision_free(&s);
    let paired = joints_at_completion(&s, "l-28.txt", "c-28.txt");
    assert!(paired.len() >= 8, "{paired:?}");
    assert!(paired.iter().all(|(_, j)| *j >= 2), "{paired:?}");
    assert_eq!(
        loops_begun_on_an_unfinished_neighbour(&s, "l-28.txt", "c-28.txt"),
        []
    );
    let tag = "repost-paired";
    let sc = common::scratch(tag, "supported.toml");
    let shapes = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models/shapes/repost");
    std::fs::write(
        &sc,
        format!(
            "name = \"{tag}\"\nalgorithm = \"repost\"\n[parameters]\ninitial = \"{}\"\ngoal = \"{}\"\ngoal_order = \"supported\"\n",
            shapes.join("l-28.txt").display(),
            shapes.join("c-28.txt").display()
        ),
    )
    .unwrap();
    let scenario = reconfcheck::scenario::Scenario::load(&sc).unwrap();
    let supported = reconfcheck::algorithms::generate(&scenario).unwrap();
    let single: Vec<_> = joints_at_completion(&supported, "l-28.txt", "c-28.txt")
        .into_iter()
        .filter(|(_, j)| *j < 2)
        .collect();
    assert_eq!(single.len(), 2, "{single:?}");
}
