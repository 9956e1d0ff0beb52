//! VisibleSim files through the command line (issue #15): configurations
//! in and out, CSG targets read as VisibleSim reads them, motion traces
//! certified move by move, and bad input refused with exit 2 naming the
//! file, the line and the element.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Output;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run(args: &[&str]) -> Output {
    common::bin()
        .args(args)
        .current_dir(root())
        .output()
        .expect("runs")
}

fn tmp(name: &str) -> PathBuf {
    common::scratch("interop", name)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

const MODEL: &str = "models/catom-3.6mm.toml";

#[test]
fn a_configuration_imports_certifies_and_round_trips_through_export() {
    let a = tmp("rolls.json");
    let o = run(&[
        "import",
        "visiblesim",
        "scenarios/visiblesim/rolls.xml",
        "-o",
        s(&a),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let c = run(&["certify", s(&a), "--model", MODEL]);
    assert_eq!(
        c.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&c.stdout)
    );
    let x = tmp("rolls-out.xml");
    let e = run(&["export", "visiblesim", s(&a), "-o", s(&x)]);
    assert_eq!(e.status.code(), Some(0), "{}", stderr(&e));
    let b = tmp("rolls-again.json");
    let o = run(&["import", "visiblesim", s(&x), "-o", s(&b)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let parse = |p: &Path| -> serde_json::Value {
        let mut v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
        // The source file's name is provenance, not configuration.
        v["meta"]["visiblesim"]
            .as_object_mut()
            .unwrap()
            .remove("source");
        v
    };
    assert_eq!(parse(&a), parse(&b));
}

#[test]
fn a_trace_certifies_and_its_hexagonal_twin_collides_with_cells_named() {
    let ok = tmp("trace-ok.json");
    let o = run(&[
        "import",
        "trace",
        "scenarios/visiblesim/rolls.csv",
        "--config",
        "scenarios/visiblesim/rolls.xml",
        "-o",
        s(&ok),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let sched: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&ok).unwrap()).unwrap();
    // The first two moves overlap in time: one step; the next two do not.
    assert_eq!(sched["steps"].as_array().unwrap().len(), 3);
    let c = run(&["certify", s(&ok), "--model", MODEL]);
    assert_eq!(
        c.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&c.stdout)
    );

    let hex = tmp("trace-hex.json");
    let o = run(&[
        "import",
        "trace",
        "scenarios/visiblesim/rolls-hexagonal.csv",
        "--config",
        "scenarios/visiblesim/rolls.xml",
        "-o",
        s(&hex),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let report = tmp("trace-hex-report.json");
    let c = run(&["certify", s(&hex), "--model", MODEL, "--json", s(&report)]);
    assert_eq!(c.status.code(), Some(1));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let v = &r["violations"][0];
    assert_eq!(v["kind"], "collision");
    assert!(!v["cells"].as_array().unwrap().is_empty());
}

#[test]
fn bad_traces_are_refused_with_exit_2_naming_the_line() {
    let header = "t_us,blockId,initX,initY,initZ,fromX,fromY,fromZ,toX,toY,toZ,pivotX,pivotY,pivotZ,linkTo,linkFace";
    let cases = [
        // Block 99 is not in the configuration.
        ("0,99,0,0,1,0,0,1,1,0,1,1,0,0,0,1", "line 2", "block 99"),
        // A jump of two cells is no rotation.
        ("0,13,0,0,1,0,0,1,3,0,1,1,0,0,0,1", "line 2", "not"),
        // 'from' is not where block 13 is.
        ("0,13,0,0,1,1,0,1,2,0,1,2,0,0,0,1", "line 2", "is at"),
    ];
    for (row, line, what) in cases {
        let t = tmp("bad.csv");
        std::fs::write(&t, format!("{header}\n{row}\n")).unwrap();
        let o = run(&[
            "import",
            "trace",
            s(&t),
            "--config",
            "scenarios/visiblesim/rolls.xml",
            "-o",
            s(&tmp("bad.json")),
        ]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{row}: {e}");
        assert!(
            e.contains("bad.csv") && e.contains(line) && e.contains(what),
            "{row}: {e}"
        );
    }
}

#[test]
fn bad_configurations_are_refused_with_exit_2_naming_file_line_and_element() {
    let deep = format!(
        "<world gridSize=\"5,5,5\"><blockList><block position=\"1,1,0\"/></blockList>\
         <targetList><target format=\"csg\"><csg content=\"{}cube(1,1,1);{}\"/></target></targetList></world>",
        "union() {".repeat(10_000),
        "}".repeat(10_000)
    );
    let cases = [
        ("<world gridSize=\"5,5,5\"><blockList>\n<block position=\"1,1\"/></blockList></world>".to_string(), "line 2, column 1, element <block>"),
        ("<world gridSize=\"5,5,5\"><blockList><block position=\"1,1,0\"/>\n<block position=\"1,1,0\"/></blockList></world>".to_string(), "two blocks in one cell"),
        ("<world gridSize=\"5,5,5\"><catoms2DList/></world>".to_string(), "unknown block type"),
        ("<world gridSize=\"5,5,5\"><blockList><block position=\"1,1,0\"></world>".to_string(), "malformed XML"),
        (deep, "nested more than"),
    ];
    for (xml, want) in cases {
        let p = tmp("bad.xml");
        std::fs::write(&p, &xml).unwrap();
        let o = run(&["import", "visiblesim", s(&p), "-o", s(&tmp("bad.json"))]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{e}");
        assert!(e.contains("bad.xml") && e.contains(want), "{e}");
    }
    let o = run(&[
        "import",
        "visiblesim",
        "scenarios/visiblesim/rolls.xml",
        "--lattice",
        "hexagonal",
        "-o",
        s(&tmp("x.json")),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("unknown VisibleSim lattice"));
}

/// The authors' cross target, in a small file of the same form: read as
/// VisibleSim reads it (centred cubes despite the positional `true`), it
/// is a plus, symmetric about both axes — the old reading was an L.
#[test]
fn the_cross_target_is_a_plus_not_an_l() {
    let p = tmp("cross.xml");
    std::fs::write(
        &p,
        "<?xml version=\"1.0\" standalone=\"no\" ?>\n<world gridSize=\"30,30,12\">\n\
         <blockList color=\"128,128,128\" blocksize=\"10,10,10\">\n\
         <block position=\"5,5,2\" color=\"0,255,255\" orientation=\"11\" />\n</blockList>\n\
         <targetList><target format=\"csg\" >\n<csg boundingBox=\"true\" translate=\"5,5,2\" content=\"\n\
         union() {\n  cube([4, 12, 3], true);\n  cube([12, 4, 3], true);\n}\"/>\n\
         </target></targetList></world>\n",
    )
    .unwrap();
    let out = tmp("cross.json");
    let o = run(&[
        "import",
        "visiblesim",
        s(&p),
        "--lattice",
        "skewed-fcc",
        "--target",
        "-o",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let cells: Vec<[i64; 3]> = v["modules"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| serde_json::from_value(m["cell"].clone()).unwrap())
        .collect();
    let z = cells[0][2];
    let layer: std::collections::BTreeSet<(i64, i64)> = cells
        .iter()
        .filter(|c| c[2] == z)
        .map(|c| (c[0], c[1]))
        .collect();
    let (x0, x1) = (
        layer.iter().map(|c| c.0).min().unwrap(),
        layer.iter().map(|c| c.0).max().unwrap(),
    );
    let (y0, y1) = (
        layer.iter().map(|c| c.1).min().unwrap(),
        layer.iter().map(|c| c.1).max().unwrap(),
    );
    for &(x, y) in &layer {
        assert!(layer.contains(&(x0 + x1 - x, y)), "not symmetric in x");
        assert!(layer.contains(&(x, y0 + y1 - y)), "not symmetric in y");
    }
    // The corners of the bounding square are empty: a plus.
    assert!(!layer.contains(&(x0, y0)) && !layer.contains(&(x1, y1)));
}

/// The project's own shapes stay readable under the stricter dialect.
#[test]
fn every_bundled_csg_shape_still_parses() {
    for e in std::fs::read_dir(root().join("models/shapes")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "csg") {
            reconfcheck::algorithms::scaffold::csg::CsgShape::load(&p)
                .unwrap_or_else(|e| panic!("{e}"));
        }
    }
}

/// A scaffold goal named as a VisibleSim configuration, read as the
/// authors' scaffolding_csg application reads it: a file of the same form
/// as their `config_cube_b_6.xml` gives exactly their 5,007 modules (the
/// sandbox's fixed modules aside).
#[test]
fn a_visiblesim_cube_target_gives_the_authors_5007_scaffold_modules() {
    use reconfcheck::algorithms::scaffold::paper::Protocol;
    use reconfcheck::algorithms::scaffold::{ShapeSpec, scaffold_schedule_with};
    use reconfcheck::schedule::Event;
    let p = tmp("cube_b_6.xml");
    std::fs::write(
        &p,
        "<?xml version=\"1.0\" standalone=\"no\" ?>\n<world gridSize=\"40,40,40\">\n\
         <blockList color=\"128,128,128\" blocksize=\"10,10,10\">\n\
         <block position=\"5,5,2\" color=\"0,255,255\" orientation=\"11\" />\n</blockList>\n\
         <targetList><target format=\"csg\">\n\
         <csg translate=\"5,5,2\" content=\"cube([30, 30, 22], true);\" />\n\
         </target></targetList></world>\n",
    )
    .unwrap();
    let s = scaffold_schedule_with(&ShapeSpec::Csg { path: p }, 6, Protocol::Paper).unwrap();
    let fixed = s.modules.iter().filter(|m| m.fixed).count();
    let entered = s
        .steps
        .iter()
        .flat_map(|st| &st.events)
        .filter(|e| matches!(e, Event::Enter { .. }))
        .count();
    assert_eq!(s.modules.len() - fixed + entered, 5007);
}
