use super::*;
use crate::certify::{self, Options, World};
use std::collections::HashMap;
use std::path::Path;

fn scaffold() -> Schedule {
    let sc = crate::scenario::Scenario::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/pyramid-h2-b8.toml"),
    )
    .unwrap();
    crate::algorithms::generate(&sc).unwrap()
}

/// The shipped physical model: its path (for `Options::model`) and the
/// model itself.
fn shipped_model() -> (std::path::PathBuf, crate::mechanics::Model) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/catom-3.6mm.toml");
    let model = crate::mechanics::Model::load(&path).unwrap();
    (path, model)
}

/// The bundled walk's first steps with a fixed module at (1, −1, 1), which
/// its first rotation cuts (as `tests/common`'s obstacle walk).
fn colliding_walk() -> Schedule {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/walk-fcc.json"),
    )
    .unwrap();
    let mut s: serde_json::Value = serde_json::from_str(&text).unwrap();
    s["steps"].as_array_mut().unwrap().truncate(3);
    s["modules"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({"id": 900, "cell": [1, -1, 1], "fixed": true}));
    Schedule::from_json(&s.to_string(), Path::new("walk.json")).unwrap()
}

/// The JSON object inlined in a page, read back.
fn inlined(html: &str) -> serde_json::Value {
    let open = "<script type=\"application/json\" id=\"reconfcheck-data\">";
    let start = html.find(open).expect("the page inlines its data") + open.len();
    let end = start + html[start..].find("</script>").unwrap();
    serde_json::from_str(&html[start..end].replace("<\\/", "</")).unwrap()
}

/// The data inlined in the page of `report` on `schedule`.
fn page_data(title: &str, report: &certify::Report, schedule: &Schedule) -> serde_json::Value {
    inlined(
        &Page {
            title: title.into(),
            report: Some(report),
            schedule: Some(schedule),
            ..Default::default()
        }
        .html(),
    )
}

#[test]
fn the_inlined_replay_gives_the_schedules_configuration_at_every_step() {
    let s = scaffold();
    assert!(
        s.steps.iter().any(|st| st
            .events
            .iter()
            .any(|e| matches!(e, crate::schedule::Event::Enter { .. }))),
        "the case has modules entering"
    );
    let html = Page {
        title: "scaffold".into(),
        schedule: Some(&s),
        ..Default::default()
    }
    .html();
    let replay: replay::Replay =
        serde_json::from_value(inlined(&html)["replay"]["replay"].clone()).unwrap();
    let mut world = World::initial(&s).unwrap();
    let config = |w: &World| -> HashMap<u32, Cell> { w.config().iter().collect() };
    assert_eq!(replay.cells_after(0), config(&world));
    for k in 0..s.steps.len() {
        certify::advance(&mut world, &s, k, |_| ()).unwrap();
        assert_eq!(
            replay.cells_after(k + 1),
            config(&world),
            "after step {}",
            k + 1
        );
    }
}

#[test]
fn the_page_places_every_violation_at_its_step_with_its_witness_points() {
    let s = colliding_walk();
    let report = certify::certify(&s, &Options::default()).unwrap();
    let collisions: Vec<&Violation> = report
        .violations_of(crate::certify::ViolationKind::Collision)
        .collect();
    assert!(!collisions.is_empty(), "the obstacle is cut");
    let data = page_data("walk", &report, &s);
    let shown = data["violations"].as_array().unwrap();
    assert_eq!(shown.len(), report.violations.len());
    for (v, p) in report.violations.iter().zip(shown) {
        assert_eq!(p["step"], v.step);
        assert_eq!(p["kind"], v.kind.name());
        assert_eq!(p["modules"], serde_json::json!(v.modules));
        assert_eq!(p["cells"].as_array().unwrap().len(), v.cells.len());
    }
    for (v, p) in report.violations.iter().zip(shown) {
        if v.kind != crate::certify::ViolationKind::Collision {
            continue;
        }
        let witness: Vec<[f64; 3]> = serde_json::from_value(p["witness"].clone()).unwrap();
        assert_eq!(witness.len(), 2);
        assert_eq!(serde_json::json!(witness[0]), v.detail["witness_mover"]);
        assert_eq!(serde_json::json!(witness[1]), v.detail["witness_other"]);
    }
    // The summary says what was checked.
    assert_eq!(data["summary"]["certified"], false);
    assert!(
        data["summary"]["checked"]
            .as_array()
            .unwrap()
            .iter()
            .any(|c| c.as_str().unwrap().starts_with("collision"))
    );
}

/// A page of part of a schedule (`--steps`) maps the loads of the steps
/// that were checked, every one of them when the budget allows, and no
/// other (not the final configuration, which was not reached).
#[test]
fn a_structure_that_tips_over_shows_where_its_weight_acts() {
    // Three catoms leaning half a cell per layer on one resting module.
    let mut s = Schedule::new(LatticeKind::Fcc, crate::schedule::Length::mm(3.6));
    s.ground = Some(crate::lattice::config::Ground { layer: 0 });
    for (i, (x, y, z)) in [(0, 0, 0), (0, 0, 1), (1, 1, 2)].into_iter().enumerate() {
        s.modules.push(crate::schedule::ModuleSpec {
            id: i as u32 + 1,
            cell: Cell::new(x, y, z),
            fixed: false,
        });
    }
    let (path, _) = shipped_model();
    let o = Options {
        model: Some(path),
        ..Default::default()
    };
    let report = certify::certify(&s, &o).unwrap();
    let data = page_data("leaning", &report, &s);
    let shown = data["violations"].as_array().unwrap();
    let tips: Vec<_> = shown.iter().filter(|p| p["kind"] == "unstable").collect();
    assert_eq!(tips.len(), 1, "{}", report.summary());
    let w: Vec<[f64; 3]> = serde_json::from_value(tips[0]["witness"].clone()).unwrap();
    assert_eq!(w.len(), 1);
    // The mean of the centres (0, 0), (½, ½), (1, 1), at ground level.
    assert!(
        (w[0][0] - 0.5).abs() < 1e-9 && (w[0][1] - 0.5).abs() < 1e-9,
        "{w:?}"
    );
}

#[test]
fn a_span_of_steps_has_load_maps_of_its_steps_only() {
    let s = scaffold();
    let (path, model) = shipped_model();
    let opts = Options {
        model: Some(path),
        steps: Some(certify::StepRequest::parse("30-40").unwrap()),
        ..Options::default()
    };
    let report = certify::certify(&s, &opts).unwrap();
    let maps = load_maps(&s, &model, &report, usize::MAX).unwrap();
    let steps: Vec<usize> = maps.iter().map(|m| m.step).collect();
    assert_eq!(steps, (30..=40).collect::<Vec<_>>());
}

/// A report of part of a schedule (`--steps`) is drawn at its steps'
/// numbers: the page reads the i-th per-step value as step i + 1.
#[test]
fn per_step_maxima_sit_at_their_step_numbers_when_a_span_was_checked() {
    let s = scaffold();
    let opts = Options {
        steps: Some(certify::StepRequest::parse("20-30").unwrap()),
        ..Options::lattice_only()
    };
    let mut report = certify::certify(&s, &opts).unwrap();
    for r in &mut report.per_step {
        r.metrics.insert("max_utilisation".into(), r.step as f64);
    }
    let data = inlined(
        &Page {
            title: "span".into(),
            report: Some(&report),
            ..Default::default()
        }
        .html(),
    );
    let values = data["metrics"][0][1].as_array().unwrap();
    assert_eq!(values.len(), 30);
    for (i, v) in values.iter().enumerate() {
        let step = i + 1;
        if (20..=30).contains(&step) {
            assert_eq!(v.as_f64(), Some(step as f64), "step {step}");
        } else {
            assert!(v.is_null(), "step {step}: {v}");
        }
    }
}

#[test]
fn the_page_loads_nothing_from_the_network() {
    let s = colliding_walk();
    let html = Page {
        title: "walk".into(),
        schedule: Some(&s),
        ..Default::default()
    }
    .html();
    let lower = html.to_lowercase();
    for loader in [
        "src=\"http",
        "href=\"http",
        "<link",
        "<img",
        "<iframe",
        "url(http",
    ] {
        assert!(
            !lower.contains(loader),
            "the page loads something: {loader}"
        );
    }
    // And the browser is told to refuse any load.
    assert!(html.contains("default-src 'none'"));
    assert!(html.contains(THREE_JS), "three.js is inlined whole");
}

#[test]
fn text_that_would_end_a_script_element_stays_inside_the_data() {
    let s = colliding_walk();
    let mut report = certify::certify(&s, &Options::lattice_only()).unwrap();
    report.schedule = "evil</script><script>alert(1)</script>.json".into();
    let title = "a <b> & </script>";
    let html = Page {
        title: title.into(),
        report: Some(&report),
        ..Default::default()
    }
    .html();
    // Four script elements, each closed once, and nothing opened in the data.
    assert_eq!(
        html.matches("</script>").count(),
        4,
        "no script was ended early"
    );
    assert_eq!(html.matches("<script").count(), 4, "no script was injected");
    let data = inlined(&html);
    assert_eq!(data["summary"]["schedule"], report.schedule.as_str());
    assert_eq!(data["title"], title);
}

#[test]
fn a_load_map_colours_every_connector_by_its_utilisation() {
    let s = scaffold();
    let (_, model) = shipped_model();
    let last = s.steps.len() + 1;
    let maps = certify::load_maps_at(&s, &model, &[3, last]).unwrap();
    assert_eq!(maps.iter().map(|m| m.0).collect::<Vec<_>>(), [3, last]);
    let (step, st, a) = &maps[1];
    let m = load_map(*step, st, a);
    assert_eq!(m.links.len(), st.links.len());
    assert!(!m.links.is_empty());
    let top = m.links.iter().map(|l| l[6]).fold(0f32, f32::max);
    assert!((top as f64 - a.max_utilisation).abs() < 1e-5 * a.max_utilisation.max(1.0));
}

#[test]
fn every_step_has_a_load_map_when_they_fit_and_the_budget_holds_when_not() {
    let s = scaffold();
    let (path, model) = shipped_model();
    let opts = Options {
        model: Some(path),
        ..Options::default()
    };
    let report = certify::certify(&s, &opts).unwrap();
    let last = s.steps.len() + 1;
    let all = load_maps(&s, &model, &report, usize::MAX).unwrap();
    // Every step whose structure has a connector, the final one included,
    // each with the connectors of that step analysed alone.
    let every: Vec<_> = certify::load_maps_at(&s, &model, &(1..=last).collect::<Vec<_>>())
        .unwrap()
        .into_iter()
        .filter(|(_, st, _)| !st.links.is_empty())
        .collect();
    assert!(every.len() > 20);
    assert_eq!(
        all.iter().map(|m| m.step).collect::<Vec<_>>(),
        every.iter().map(|m| m.0).collect::<Vec<_>>()
    );
    for (m, (k, st, a)) in all.iter().zip(&every) {
        let alone = load_map(*k, st, a);
        assert_eq!(m.links.len(), alone.links.len(), "step {k}");
        for (x, y) in m.links.iter().zip(&alone.links) {
            assert!((x[6] - y[6]).abs() <= 1e-6 * y[6].max(1.0), "step {k}");
        }
    }
    let worst = report
        .per_step
        .iter()
        .filter_map(|r| r.metrics.get("max_utilisation").map(|u| (*u, r.step)))
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap()
        .1;
    assert_eq!(
        all.iter()
            .find(|m| m.why == load_maps::Why::Worst)
            .map(|m| m.step),
        Some(worst)
    );
    assert_eq!(all.last().unwrap().step, last);
    // A budget with room for three more maps beyond the ones that always
    // come: those, and at most three spread steps, within the budget.
    let firsts: usize = all
        .iter()
        .filter(|m| m.why != load_maps::Why::Spread)
        .map(|m| m.links.len())
        .sum();
    let largest = all.iter().map(|m| m.links.len()).max().unwrap();
    let budget = firsts + 3 * largest;
    let some = load_maps(&s, &model, &report, budget).unwrap();
    let total: usize = some.iter().map(|m| m.links.len()).sum();
    assert!(total <= budget, "{total} > {budget}");
    let spread = some
        .iter()
        .filter(|m| m.why == load_maps::Why::Spread)
        .count();
    assert!((1..=3).contains(&spread), "{spread}");
    assert!(some.iter().any(|m| m.why == load_maps::Why::Worst));
    // Packed on the page, one entry per map with its connector count.
    let page = Page {
        title: "t".into(),
        report: Some(&report),
        schedule: Some(&s),
        load_maps: some.clone(),
        ..Default::default()
    };
    let data = inlined(&page.html());
    let maps = data["load_maps"].as_array().unwrap();
    assert_eq!(maps.len(), some.len());
    assert_eq!(data["load_maps_of"], last);
    for (d, m) in maps.iter().zip(&some) {
        assert_eq!(d["connectors"], m.links.len());
        let back = load_maps::unpack(&replay::unbase64(d["links"].as_str().unwrap()));
        assert_eq!(back.len(), m.links.len());
    }
}
