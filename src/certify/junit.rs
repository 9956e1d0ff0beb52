//! The report as JUnit XML, the test-result format GitLab, GitHub Actions
//! reporters and Jenkins read: one test suite per check, one test case per
//! step (0 is the initial configuration, `steps + 1` the final one), a
//! failure per violation naming its kind, modules and cells. Written with
//! quick-xml, which escapes what it writes.

use super::report::{Report, Violation, ViolationKind};
use quick_xml::Writer;
use quick_xml::events::{BytesDecl, BytesEnd, BytesStart, BytesText, Event};
use std::io::Cursor;

/// The check whose findings a kind of violation is.
pub fn check_of(kind: ViolationKind) -> &'static str {
    match kind {
        ViolationKind::Collision
        | ViolationKind::SlidingContact
        | ViolationKind::GroundCollision => "collision",
        ViolationKind::Unstable | ViolationKind::Overload | ViolationKind::JudgedAtSamples => {
            "mechanics"
        }
        ViolationKind::DockingBlocked => "docking",
        _ => "lattice",
    }
}

/// A violation in words: its message, then its modules and cells.
fn describe(v: &Violation) -> String {
    let cells: Vec<String> = v.cells.iter().map(|c| c.to_string()).collect();
    let modules: Vec<String> = v.modules.iter().map(|m| m.to_string()).collect();
    format!(
        "{}\nmodules: {}\ncells: {}",
        v.message,
        modules.join(", "),
        cells.join(", ")
    )
}

/// The JUnit XML of `report`.
pub fn to_junit(report: &Report) -> String {
    let mut w = Writer::new_with_indent(Cursor::new(Vec::new()), b' ', 2);
    let last = report.steps + 1;
    let stopped = report.stopped_at.unwrap_or(usize::MAX);
    let ran = report.checks.iter().filter(|c| !c.contains(": ")).count();
    let total_cases = ran * (last + 1) + (report.checks.len() - ran);
    let failures = report.violations.len();
    w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))
        .expect("writing to memory");
    let mut suites = BytesStart::new("testsuites");
    suites.push_attribute(("name", format!("reconfcheck {}", report.schedule).as_str()));
    suites.push_attribute(("tests", total_cases.to_string().as_str()));
    suites.push_attribute(("failures", failures.to_string().as_str()));
    w.write_event(Event::Start(suites))
        .expect("writing to memory");
    for check in &report.checks {
        // A check that did not run ("mechanics: not run (…)") is one
        // skipped case, so CI shows what was not checked.
        if let Some((name, why)) = check.split_once(": ") {
            let mut suite = BytesStart::new("testsuite");
            suite.push_attribute(("name", name));
            suite.push_attribute(("tests", "1"));
            suite.push_attribute(("skipped", "1"));
            w.write_event(Event::Start(suite))
                .expect("writing to memory");
            let mut case = BytesStart::new("testcase");
            case.push_attribute(("classname", format!("reconfcheck.{name}").as_str()));
            case.push_attribute(("name", "every step"));
            w.write_event(Event::Start(case))
                .expect("writing to memory");
            let mut skipped = BytesStart::new("skipped");
            skipped.push_attribute(("message", why));
            w.write_event(Event::Empty(skipped))
                .expect("writing to memory");
            w.write_event(Event::End(BytesEnd::new("testcase")))
                .expect("writing to memory");
            w.write_event(Event::End(BytesEnd::new("testsuite")))
                .expect("writing to memory");
            continue;
        }
        let mine: Vec<&Violation> = report
            .violations
            .iter()
            .filter(|v| check_of(v.kind) == check.as_str())
            .collect();
        let mut suite = BytesStart::new("testsuite");
        suite.push_attribute(("name", check.as_str()));
        suite.push_attribute(("tests", (last + 1).to_string().as_str()));
        suite.push_attribute(("failures", mine.len().to_string().as_str()));
        w.write_event(Event::Start(suite))
            .expect("writing to memory");
        for step in 0..=last {
            let mut case = BytesStart::new("testcase");
            case.push_attribute(("classname", format!("reconfcheck.{check}").as_str()));
            let name = match step {
                0 => "initial configuration".to_string(),
                s if s == last => "final configuration".to_string(),
                s => format!("step {s}"),
            };
            case.push_attribute(("name", name.as_str()));
            w.write_event(Event::Start(case))
                .expect("writing to memory");
            let why = if step > stopped {
                Some(format!("not checked: the replay stopped at step {stopped}"))
            } else {
                report
                    .window
                    .filter(|_| !report.in_window(step))
                    .map(|w| format!("not checked: outside --steps {}-{}", w.first, w.last))
            };
            if let Some(why) = why {
                let mut skipped = BytesStart::new("skipped");
                skipped.push_attribute(("message", why.as_str()));
                w.write_event(Event::Empty(skipped))
                    .expect("writing to memory");
            }
            for v in mine.iter().filter(|v| v.step == step) {
                let mut f = BytesStart::new("failure");
                f.push_attribute(("type", v.kind.name().as_str()));
                f.push_attribute(("message", v.message.as_str()));
                w.write_event(Event::Start(f)).expect("writing to memory");
                w.write_event(Event::Text(BytesText::new(&describe(v))))
                    .expect("writing to memory");
                w.write_event(Event::End(BytesEnd::new("failure")))
                    .expect("writing to memory");
            }
            w.write_event(Event::End(BytesEnd::new("testcase")))
                .expect("writing to memory");
        }
        w.write_event(Event::End(BytesEnd::new("testsuite")))
            .expect("writing to memory");
    }
    w.write_event(Event::End(BytesEnd::new("testsuites")))
        .expect("writing to memory");
    String::from_utf8(w.into_inner().into_inner()).expect("quick-xml writes UTF-8")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::certify::StepSpan;

    /// Reads back, with an independent parser, (element, attributes) of
    /// every element in document order, and the text inside failures.
    /// (element name, its attributes) in document order.
    type Elements = Vec<(String, Vec<(String, String)>)>;

    fn parse(xml: &str) -> (Elements, Vec<String>) {
        let doc = roxmltree::Document::parse(xml).expect("well-formed XML");
        let mut tags = Vec::new();
        let mut texts = Vec::new();
        for n in doc.descendants().filter(|n| n.is_element()) {
            let attrs = n
                .attributes()
                .map(|a| (a.name().to_string(), a.value().to_string()))
                .collect();
            tags.push((n.tag_name().name().to_string(), attrs));
            if n.tag_name().name() == "failure" {
                texts.push(n.text().unwrap_or_default().to_string());
            }
        }
        (tags, texts)
    }

    fn report() -> Report {
        let v = Violation::new(
            ViolationKind::Collision,
            2,
            "module 7 penetrates module <9> & more",
        )
        .modules([7, 9])
        .cells([crate::lattice::Cell::new(1, -1, 1)]);
        Report {
            format: "reconfcheck-report".into(),
            version: 1,
            schedule: "s.json".into(),
            lattice: crate::lattice::LatticeKind::Fcc,
            modules: 10,
            final_modules: 10,
            steps: 3,
            moves: 3,
            window: None,
            checks: vec!["lattice".into(), "collision".into()],
            load_factor_tolerance: 0.0,
            certified: false,
            stopped_at: None,
            violations: vec![v],
            warnings: Vec::new(),
            per_step: Vec::new(),
        }
    }

    #[test]
    fn one_case_per_check_and_step_and_a_failure_per_violation() {
        let xml = to_junit(&report());
        let (tags, texts) = parse(&xml);
        let cases: Vec<_> = tags.iter().filter(|t| t.0 == "testcase").collect();
        assert_eq!(cases.len(), 2 * 5, "2 checks × (initial, 3 steps, final)");
        let failures: Vec<_> = tags.iter().filter(|t| t.0 == "failure").collect();
        assert_eq!(failures.len(), 1);
        assert!(failures[0].1.contains(&("type".into(), "collision".into())));
        // The failure sits in the collision suite's case of step 2.
        let i = tags.iter().position(|t| t.0 == "failure").unwrap();
        assert!(tags[i - 1].1.contains(&("name".into(), "step 2".into())));
        assert!(
            tags[i - 1]
                .1
                .contains(&("classname".into(), "reconfcheck.collision".into()))
        );
        // Escaped on the way out, intact on the way back.
        let text = texts.iter().find(|t| t.contains("penetrates")).unwrap();
        assert!(text.contains("<9> & more"), "{text}");
        assert!(
            text.contains("modules: 7, 9") && text.contains("cells: (1, -1, 1)"),
            "{text}"
        );
    }

    #[test]
    fn steps_after_a_stop_are_skipped_not_passed() {
        let mut r = report();
        r.stopped_at = Some(2);
        let (tags, _) = parse(&to_junit(&r));
        let skipped = tags.iter().filter(|t| t.0 == "skipped").count();
        assert_eq!(
            skipped,
            2 * 2,
            "step 3 and the final configuration, per check"
        );
    }

    #[test]
    fn steps_outside_a_window_are_skipped_not_passed() {
        // Steps 2-3 of 3 checked: the initial configuration and step 1
        // were replayed unchecked; the final one was checked.
        let skipped_cases = |r: &Report| {
            let (tags, _) = parse(&to_junit(r));
            let mut out = Vec::new();
            for (i, t) in tags.iter().enumerate() {
                if t.0 == "skipped" {
                    let name = tags[i - 1].1.iter().find(|a| a.0 == "name").unwrap();
                    out.push(name.1.clone());
                }
            }
            out
        };
        let mut r = report();
        r.window = Some(StepSpan { first: 2, last: 3 });
        assert_eq!(
            skipped_cases(&r),
            ["initial configuration", "step 1"].repeat(2)
        );
        // Steps 1-2: the initial configuration checked, step 3 and the
        // final one not.
        r.window = Some(StepSpan { first: 1, last: 2 });
        assert_eq!(
            skipped_cases(&r),
            ["step 3", "final configuration"].repeat(2)
        );
    }
}
