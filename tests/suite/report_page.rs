//! `--html` and the summary's coverage lines, through the binary.

use crate::common;

use crate::common::bin;
use std::path::Path;

fn walk(name: &str) -> std::path::PathBuf {
    let p = common::scratch("page", name);
    common::walk_with_obstacle(&p, true);
    p
}

fn model() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("models/catom-3.6mm.toml")
}

#[test]
fn an_html_path_in_a_missing_folder_is_refused_before_any_work_naming_it() {
    let s = walk("walk.json");
    let page = common::scratch("page", "no-such-folder/report.html");
    let o = bin()
        .arg("certify")
        .arg(&s)
        .arg("--no-progress")
        .arg("--html")
        .arg(&page)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains(&page.display().to_string()), "{err}");
    assert!(o.stdout.is_empty(), "nothing was certified");
}

#[test]
fn certify_writes_a_page_with_the_reports_violations_and_what_was_checked() {
    let s = walk("walk2.json");
    let page = common::scratch("page", "walk.html");
    let json = common::scratch("page", "walk-report.json");
    let o = bin()
        .arg("certify")
        .arg(&s)
        .args(["--no-progress", "--model"])
        .arg(model())
        .arg("--html")
        .arg(&page)
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{o:?}");
    let html = std::fs::read_to_string(&page).unwrap();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let open = "<script type=\"application/json\" id=\"reconfcheck-data\">";
    let start = html.find(open).unwrap() + open.len();
    let end = start + html[start..].find("</script>").unwrap();
    let data: serde_json::Value = serde_json::from_str(&html[start..end]).unwrap();
    let violations = report["violations"].as_array().unwrap();
    assert!(!violations.is_empty());
    for (v, p) in violations
        .iter()
        .zip(data["violations"].as_array().unwrap())
    {
        assert_eq!(v["step"], p["step"]);
        assert_eq!(v["kind"], p["kind"]);
    }
    // The mechanics ran, and the page says so.
    let checked = data["summary"]["checked"].as_array().unwrap();
    assert!(
        checked
            .iter()
            .any(|c| c.as_str().unwrap().starts_with("mechanics"))
    );
}

#[test]
fn the_summary_says_what_a_lattice_only_run_did_not_check() {
    let s = walk("walk3.json");
    let o = bin()
        .arg("certify")
        .arg(&s)
        .args(["--no-progress", "--lattice-only"])
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("checked: lattice (steps 1–1 and the final configuration)"),
        "{out}"
    );
    assert!(
        out.contains("NOT checked: collision: lattice checks only (--lattice-only)"),
        "{out}"
    );
    assert!(
        out.contains("NOT checked: mechanics: lattice checks only (--lattice-only)"),
        "{out}"
    );
}

#[test]
fn b_study_writes_a_page_with_its_rows() {
    let page = common::scratch("page", "study.html");
    common::branch_study_page(&page, 2, 3);
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.contains("\"family\":\"branch\""));
    assert!(html.contains("\"b\":2,") && html.contains("\"b\":3,"));
}

#[test]
fn b_study_page_replays_the_smallest_b_that_breaks_with_its_overload() {
    // The branch family under the default model holds up to b = 6 (the
    // closed form's b² ≤ pL³/(mgd) ≈ 46.6); b = 7's last agent overloads
    // the root connector.
    let page = common::scratch("page", "study-replay.html");
    common::branch_study_page(&page, 5, 7);
    let html = std::fs::read_to_string(&page).unwrap();
    let tag = "id=\"reconfcheck-data\">";
    let start = html.find(tag).unwrap() + tag.len();
    let end = start + html[start..].find("</script>").unwrap();
    let data: serde_json::Value = serde_json::from_str(&html[start..end]).unwrap();
    assert_eq!(data["study"]["b_max"], 6);
    assert!(
        data["note"]
            .as_str()
            .unwrap()
            .starts_with("The replay below is b = 7, the smallest b that does not hold"),
        "{}",
        data["note"]
    );
    // The replayed schedule is b = 7's: 7 modules join the fixed base.
    let summary = &data["summary"];
    assert_eq!(summary["certified"], false);
    assert_eq!(
        summary["final_modules"].as_u64().unwrap() - summary["modules"].as_u64().unwrap(),
        7
    );
    assert!(data["replay"].is_object());
    let overloads: Vec<&serde_json::Value> = data["violations"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["kind"] == "overload")
        .collect();
    assert!(!overloads.is_empty(), "{}", data["violations"]);
    // The load map of the worst step is on the page and shows the overload.
    let maps = data["load_maps"].as_array().unwrap();
    assert!(
        maps.iter()
            .any(|m| m["max_utilisation"].as_f64().unwrap() > 1.0)
    );
}
