//! A window of a schedule as a schedule of its own: the configuration
//! after its first `start` steps, then its next `count` steps. Certifying
//! a window of a long schedule takes a minute where the whole one takes
//! many (the speed work of issue #20 measures on one; `docs/mechanics.md`).
//! Its steps are numbered from 1; its elastic solves start afresh at its
//! first step, as a parallel run's ranges do, so its mechanical figures
//! agree with the whole run's to round-off.

use super::world::World;
use crate::error::InputError;
use crate::schedule::{ModuleSpec, Schedule};

/// Steps `start + 1 ..= start + count` of `s`, from the configuration its
/// replay reaches after step `start` (the lattice replay alone, by
/// [`super::advance`]: no check runs). Takes the schedule, whose steps
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
    for k in 0..start {
        let (_, _, clashes) = super::advance(&mut world, &s, k, |_| ())?;
        if let Some(v) = clashes.first() {
            return Err(InputError::new(format!(
                "step {}: {}; a window after it would start from no configuration",
                k + 1,
                v.message
            )));
        }
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
    use crate::certify::{Options, certify};

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
}
