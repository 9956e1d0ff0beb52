//! Windows of a schedule: the steps a user asks to check
//! ([`StepRequest`], `certify --steps FIRST-LAST`: the certifier replays
//! the steps before them without checks and keeps the schedule's step
//! numbers), and a window as a schedule of its own ([`window`]: the
//! configuration after its first `start` steps, then its next `count`
//! steps, numbered from 1). Certifying a window of a long schedule takes a
//! minute where the whole one takes many (the speed work of issue #20
//! measures on one; `docs/mechanics.md`). Its elastic solves start afresh
//! at its first step, as a parallel run's ranges do, so its mechanical
//! figures agree with the whole run's to round-off.

use super::report::StepSpan;
use super::world::World;
use crate::error::InputError;
use crate::schedule::{ModuleSpec, Schedule};

/// The steps a user asked to check (`--steps FIRST-LAST`, `FIRST-` to the
/// end, or one step), before it is held against a schedule's length.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct StepRequest {
    /// 1-based.
    pub first: usize,
    /// 1-based, inclusive; `None`: the schedule's last step.
    pub last: Option<usize>,
}

impl StepRequest {
    /// Reads `FIRST-LAST`, `FIRST-` or `STEP` (steps numbered from 1, as
    /// in reports).
    pub fn parse(text: &str) -> Result<StepRequest, String> {
        let number = |t: &str| {
            t.trim()
                .parse::<usize>()
                .ok()
                .filter(|&k| k >= 1)
                .ok_or_else(|| format!("'{t}' is not a step number (steps are numbered from 1)"))
        };
        let (first, last) = match text.split_once('-') {
            Some((a, b)) if b.trim().is_empty() => (number(a)?, None),
            Some((a, b)) => (number(a)?, Some(number(b)?)),
            None => {
                let k = number(text)?;
                (k, Some(k))
            }
        };
        if let Some(last) = last
            && last < first
        {
            return Err(format!("{text}: the last step comes before the first"));
        }
        Ok(StepRequest { first, last })
    }

    /// The span of a schedule of `steps` steps this asks for; `None` when
    /// it is every step (the report is then the whole schedule's, byte for
    /// byte). Refused where it runs past the schedule's end.
    pub fn within(self, steps: usize) -> Result<Option<StepSpan>, InputError> {
        let last = self.last.unwrap_or(steps);
        if self.first > steps || last > steps {
            return Err(InputError::new(format!(
                "--steps {}-{}: the schedule has {steps} steps",
                self.first,
                self.last.map_or(String::new(), |l| l.to_string())
            )));
        }
        Ok((self.first > 1 || last < steps).then_some(StepSpan {
            first: self.first,
            last,
        }))
    }
}

/// Steps `start + 1 ..= start + count` of `s`, from the configuration its
/// replay reaches after step `start` (the lattice replay alone, by
/// [`super::replay_unchecked`]: no check runs). Takes the schedule, whose steps
/// the window keeps a slice of (the sandcastle's are 46 MB). Refused where the window is empty or runs past the end, where
/// a step before it cannot be replayed, and where pairs of modules are
/// detached at its start (the schedule format has no field for that:
/// the window would latch them).
pub fn window(mut s: Schedule, start: usize, count: usize) -> Result<Schedule, InputError> {
    let n = s.steps.len();
    if count == 0 || start.checked_add(count).is_none_or(|end| end > n) {
        return Err(InputError::new(format!(
            "a window of {count} steps after step {start} is not within the schedule's {n} steps"
        )));
    }
    let mut world = World::initial(&s)?;
    if let Some((k, clashes)) = super::replay_unchecked(&mut world, &s, start)? {
        return Err(InputError::new(format!(
            "step {}: {}; a window after it would start from no configuration",
            k + 1,
            clashes[0].message
        )));
    }
    if world.detached_pairs() > 0 {
        return Err(InputError::new(format!(
            "after step {start}, {} pairs of modules are detached, which a schedule's initial configuration cannot say",
            world.detached_pairs()
        )));
    }
    s.modules = world
        .config()
        .modules()
        .into_iter()
        .map(|(id, cell)| ModuleSpec {
            id,
            cell,
            fixed: world.fixed().contains(&id),
        })
        .collect();
    s.steps.truncate(start + count);
    s.steps.drain(..start);
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::certify::{Options, Report, Violation, certify};

    /// The default scenario's schedule, and the folder its model path
    /// is relative to.
    fn default_schedule() -> (Schedule, std::path::PathBuf) {
        let scenario =
            crate::scenario::Scenario::load(&crate::scenario::Scenario::default_path()).unwrap();
        (
            crate::algorithms::generate(&scenario).unwrap(),
            scenario.dir,
        )
    }

    #[test]
    fn a_window_starts_from_the_configuration_the_whole_replay_reaches() {
        let (s, dir) = default_schedule();
        let (start, count) = (40, 25);
        let w = window(s.clone(), start, count).unwrap();
        assert_eq!(w.steps, s.steps[start..start + count]);
        // Replayed independently: the configuration after the window's
        // steps is the whole schedule's after step start + count.
        let end = |sched: &Schedule, steps: usize| {
            let mut world = World::initial(sched).unwrap();
            for (k, step) in sched.steps[..steps].iter().enumerate() {
                let plan = world.resolve(k + 1, step).unwrap();
                assert!(world.apply(&plan).is_empty());
            }
            world.config().modules()
        };
        assert_eq!(end(&w, count), end(&s, start + count));
        assert_ne!(end(&w, 0), end(&s, 0), "the window starts elsewhere");
        let fixed = |sched: &Schedule| sched.modules.iter().filter(|m| m.fixed).count();
        assert_eq!(fixed(&w), fixed(&s));
        // And it certifies as its steps do in the whole schedule: the
        // same findings, and (its elastic solves started afresh) the same
        // utilisations to round-off.
        let opts = Options {
            base_dir: Some(dir),
            ..Options::default()
        };
        let (whole, part) = (certify(&s, &opts).unwrap(), certify(&w, &opts).unwrap());
        assert_eq!(part.per_step.len(), count);
        for (a, b) in part.per_step.iter().zip(&whole.per_step[start..]) {
            assert_eq!((a.step + start, a.moves), (b.step, b.moves));
            assert_eq!((a.violations, a.warnings), (b.violations, b.warnings));
            assert!(a.metrics.keys().eq(b.metrics.keys()), "step {}", b.step);
            for ((name, x), y) in a.metrics.iter().zip(b.metrics.values()) {
                assert!((x - y).abs() <= 1e-9, "step {} {name}: {x} {y}", b.step);
            }
        }
        assert!(
            part.per_step
                .iter()
                .any(|r| r.metrics.contains_key("max_utilisation")),
            "the mechanics ran"
        );
    }

    #[test]
    fn a_window_past_the_end_or_empty_is_refused() {
        let (s, _) = default_schedule();
        let n = s.steps.len();
        assert!(window(s.clone(), 0, n).is_ok());
        for (start, count) in [(0, 0), (n, 1), (n - 1, 2), (1, usize::MAX)] {
            let e = window(s.clone(), start, count).unwrap_err().to_string();
            assert!(e.contains("not within"), "{start}, {count}: {e}");
        }
    }

    /// Asserts that `part`, a report of steps `first..=last` of the
    /// schedule `whole` reports, has the whole run's steps, findings and
    /// metrics there, and says what it left out. Its mechanics start afresh
    /// at `first`, as a range of a parallel run does, so its figures agree
    /// to 1e-9, and a limit analysis exact in one run may be bracketed in
    /// the other (`load_factor_lower_bound`, then no higher than the other
    /// run's factor): never another verdict.
    fn assert_span_agrees(part: &Report, whole: &Report, first: usize, last: usize) {
        const LOWER: &str = "load_factor_lower_bound";
        let n = whole.steps;
        assert_eq!(part.window, Some(StepSpan { first, last }));
        assert_eq!((part.steps, part.moves), (whole.steps, whole.moves));
        let steps: Vec<usize> = part.per_step.iter().map(|r| r.step).collect();
        assert_eq!(steps, (first..=last).collect::<Vec<_>>());
        for (a, b) in part.per_step.iter().zip(&whole.per_step[first - 1..]) {
            assert_eq!((a.step, a.moves), (b.step, b.moves));
            assert_eq!((a.violations, a.warnings), (b.violations, b.warnings));
            let names = |r: &crate::certify::StepResult| -> Vec<String> {
                r.metrics.keys().filter(|k| *k != LOWER).cloned().collect()
            };
            assert_eq!(names(a), names(b), "step {}", b.step);
            for name in names(a) {
                let (x, y) = (a.metrics[&name], b.metrics[&name]);
                assert!((x - y).abs() <= 1e-9, "step {} {name}: {x} {y}", b.step);
            }
            for (r, other) in [(a, b), (b, a)] {
                if let Some(lower) = r.metrics.get(LOWER) {
                    assert!(
                        lower - other.metrics["load_factor"] <= 1e-9,
                        "step {}",
                        b.step
                    );
                }
            }
        }
        // The same findings where the span reaches (the final
        // configuration's too when it runs to the end), none elsewhere.
        let inside =
            |v: &&Violation| (first..=last).contains(&v.step) || (v.step == n + 1 && last == n);
        let key = |v: &Violation| (v.kind, v.step, v.modules.clone(), v.cells.clone());
        for (mine, all) in [
            (&part.violations, &whole.violations),
            (&part.warnings, &whole.warnings),
        ] {
            let a: Vec<_> = mine.iter().map(key).collect();
            let b: Vec<_> = all.iter().filter(inside).map(key).collect();
            assert_eq!(a, b, "{first}-{last}");
        }
        let (checked, not_checked) = part.coverage();
        assert!(
            checked
                .iter()
                .all(|c| c.contains(&format!("steps {first}–{last}")))
        );
        assert_eq!(
            not_checked.iter().any(|c| c.contains("replayed to reach")),
            first > 1,
            "{not_checked:?}"
        );
        assert_eq!(part.certified, part.violations.is_empty());
    }

    fn with_steps(opts: &Options, steps: &str) -> Options {
        Options {
            steps: Some(StepRequest::parse(steps).unwrap()),
            ..opts.clone()
        }
    }

    #[test]
    fn certifying_a_span_of_steps_finds_what_the_whole_run_finds_there() {
        let (s, dir) = default_schedule();
        let n = s.steps.len();
        let opts = Options {
            base_dir: Some(dir),
            ..Options::default()
        };
        let whole = certify(&s, &opts).unwrap();
        // Its metrics are the mechanics' at every step; its findings are
        // none (the next test has some).
        assert!(
            whole
                .per_step
                .iter()
                .all(|r| r.metrics.contains_key("max_utilisation"))
        );
        // Every step asked for: the whole report, byte for byte.
        let all = certify(&s, &with_steps(&opts, "1-")).unwrap();
        assert_eq!(all.to_json(), whole.to_json());
        for (text, first, last) in [("41-65", 41, 65), ("150-", 150, n), ("1-30", 1, 30)] {
            let part = certify(&s, &with_steps(&opts, text)).unwrap();
            assert_span_agrees(&part, &whole, first, last);
        }
        for bad in ["0", "5-3", "x", "3-y", ""] {
            assert!(StepRequest::parse(bad).is_err(), "{bad}");
        }
        for past in [format!("{}", n + 1), format!("{n}-{}", n + 1)] {
            let e = certify(&s, &with_steps(&opts, &past))
                .unwrap_err()
                .to_string();
            assert!(e.contains(&format!("the schedule has {n} steps")), "{e}");
        }
    }

    #[test]
    fn a_span_of_an_overloaded_schedule_has_the_whole_runs_violations_there() {
        // The 2-pyramid at b = 9 is overloaded at steps 36-39 and 73-77 (of
        // 121): spans across the first run and from inside the second.
        let shape = crate::algorithms::scaffold::ShapeSpec::Pyramid { h: 2 };
        let s = crate::algorithms::scaffold::scaffold_schedule(&shape, 9).unwrap();
        let model =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models/catom-3.6mm.toml");
        let opts = Options {
            model: Some(model),
            ..Options::default()
        };
        let whole = certify(&s, &opts).unwrap();
        assert!(
            whole.violations.iter().any(|v| v.step < 40),
            "overloaded early"
        );
        let n = s.steps.len();
        for (text, first, last) in [("30-40", 30, 40), ("75-", 75, n)] {
            let part = certify(&s, &with_steps(&opts, text)).unwrap();
            assert!(!part.violations.is_empty(), "{text}");
            assert_span_agrees(&part, &whole, first, last);
        }
    }
}
