//! The CI gate: JUnit XML for CI systems, and regression against a
//! baseline report (exit 1 only for new violations or utilisation rises).

use proptest::prelude::*;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common;

use crate::common::bin;

fn scratch(name: &str) -> PathBuf {
    common::scratch("ci", name)
}

/// The walk with (or without) the obstacle its first rotation cuts.
fn walk(name: &str, obstacle: bool) -> PathBuf {
    let p = scratch(name);
    common::walk_with_obstacle(&p, obstacle);
    p
}

fn certify(schedule: &Path, extra: &[&str]) -> Output {
    bin()
        .arg("certify")
        .arg(schedule)
        .arg("--no-progress")
        .args(extra)
        .output()
        .unwrap()
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

#[test]
fn junit_has_a_case_per_check_and_step_and_fails_the_colliding_step() {
    let xml = scratch("junit.xml");
    let o = certify(
        &walk("junit.json", true),
        &["--junit", xml.to_str().unwrap()],
    );
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let body = std::fs::read_to_string(&xml).unwrap();
    let doc = roxmltree::Document::parse(&body).expect("well-formed JUnit XML");
    let suites: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("testsuite"))
        .map(|n| n.attribute("name").unwrap().to_string())
        .collect();
    assert_eq!(suites, ["lattice", "collision", "mechanics"]);
    let cases = doc
        .descendants()
        .filter(|n| n.has_tag_name("testcase"))
        .count();
    assert_eq!(
        cases,
        2 * 3 + 1,
        "initial, step 1, final, per check run; one for mechanics"
    );
    let skipped = doc
        .descendants()
        .find(|n| n.has_tag_name("skipped"))
        .unwrap();
    assert!(
        skipped.attribute("message").unwrap().contains("no model"),
        "what was not checked"
    );
    let failure = doc
        .descendants()
        .find(|n| n.has_tag_name("failure"))
        .expect("the collision fails its case");
    assert_eq!(failure.attribute("type"), Some("collision"));
    assert_eq!(failure.parent().unwrap().attribute("name"), Some("step 1"));
    let detail = failure.text().unwrap();
    assert!(
        detail.contains("900") && detail.contains("(1, -1, 1)"),
        "{detail}"
    );
}

#[test]
fn a_baseline_tolerates_known_violations_and_fails_only_on_new_ones() {
    let dirty = walk("dirty.json", true);
    let clean = walk("clean.json", false);
    let (dirty_report, clean_report) = (scratch("dirty-report.json"), scratch("clean-report.json"));
    assert_eq!(
        certify(&dirty, &["--json", dirty_report.to_str().unwrap()])
            .status
            .code(),
        Some(1)
    );
    assert_eq!(
        certify(&clean, &["--json", clean_report.to_str().unwrap()])
            .status
            .code(),
        Some(0)
    );
    // The same collision as before: known, not a regression.
    let o = certify(&dirty, &["--baseline", dirty_report.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(
        text(&o).contains("0 new violation(s), 0 fixed, 1 known"),
        "{}",
        text(&o)
    );
    // Fixed since the baseline: listed, exit 0.
    let o = certify(&clean, &["--baseline", dirty_report.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(
        text(&o).contains("1 fixed") && text(&o).contains("fixed step 1"),
        "{}",
        text(&o)
    );
    // New since the baseline: exit 1, named.
    let o = certify(&dirty, &["--baseline", clean_report.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(
        text(&o).contains("1 new violation(s)") && text(&o).contains("new   step 1"),
        "{}",
        text(&o)
    );
}

#[test]
fn an_unusable_baseline_is_refused_naming_both_files() {
    let schedule = walk("current.json", true);
    let good = scratch("good-report.json");
    certify(&schedule, &["--json", good.to_str().unwrap()]);
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&good).unwrap()).unwrap();
    let mut other_schedule = report.clone();
    other_schedule["modules"] = Value::from(3);
    let mut other_version = report.clone();
    other_version["version"] = Value::from(2);
    let cases = [
        ("missing.json", None, "cannot read baseline report"),
        (
            "garbage.json",
            Some("{not json".to_string()),
            "not a reconfcheck report",
        ),
        (
            "other-schedule.json",
            Some(other_schedule.to_string()),
            "a different schedule",
        ),
        (
            "other-version.json",
            Some(other_version.to_string()),
            "version 2 cannot be compared",
        ),
    ];
    for (name, body, needle) in cases {
        let p = scratch(name);
        match body {
            Some(b) => std::fs::write(&p, b).unwrap(),
            None => {
                let _ = std::fs::remove_file(&p);
            }
        }
        let o = certify(&schedule, &["--baseline", p.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert!(
            err.contains(name) && err.contains("current.json"),
            "{name}: {err}"
        );
        assert!(err.contains(needle), "{name}: {err}");
    }
}

#[test]
fn a_baseline_tolerance_that_is_not_a_finite_non_negative_number_is_refused() {
    let schedule = walk("tol.json", false);
    let report = scratch("tol-report.json");
    certify(&schedule, &["--json", report.to_str().unwrap()]);
    for tol in ["nan", "-1", "inf"] {
        let o = certify(
            &schedule,
            &[
                "--baseline",
                report.to_str().unwrap(),
                &format!("--baseline-tolerance={tol}"),
            ],
        );
        assert_eq!(o.status.code(), Some(2), "{tol}: {}", text(&o));
        assert!(text(&o).contains("--baseline-tolerance"), "{tol}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// A baseline edited at random (a value replaced, a key removed) is
    /// refused with exit 2 or compared (exit 0 or 1): never a panic.
    #[test]
    fn edited_baselines_are_refused_or_compared_never_a_panic(
        edits in prop::collection::vec((any::<prop::sample::Index>(), 0usize..4), 1..4),
    ) {
        let schedule = walk("fuzz.json", true);
        let good = scratch("fuzz-good.json");
        if !good.exists() {
            certify(&schedule, &["--json", good.to_str().unwrap()]);
        }
        let mut v: Value = serde_json::from_str(&std::fs::read_to_string(&good).unwrap()).unwrap();
        for (at, how) in &edits {
            let Value::Object(map) = &mut v else { break };
            let keys: Vec<String> = map.keys().cloned().collect();
            if keys.is_empty() { break; }
            let k = &keys[at.index(keys.len())];
            match how {
                0 => { map.remove(k); }
                1 => { map.insert(k.clone(), Value::from(-1)); }
                2 => { map.insert(k.clone(), Value::from("x")); }
                _ => { map.insert(k.clone(), serde_json::json!([{"step": 1e300}])); }
            }
        }
        let p = scratch(&format!("fuzz-{}.json", edits.len()));
        std::fs::write(&p, v.to_string()).unwrap();
        let o = certify(&schedule, &["--baseline", p.to_str().unwrap()]);
        let code = o.status.code();
        prop_assert!(matches!(code, Some(0..=2)), "exit {:?}: {}", code, text(&o));
        prop_assert!(!String::from_utf8_lossy(&o.stderr).contains("panicked"));
    }
}
