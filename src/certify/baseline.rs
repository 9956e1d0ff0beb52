//! Regression against an earlier report of the same schedule: the CI use
//! case, where a known violation is tolerated and a new one fails the job.
//!
//! A violation is the same one when its kind, step, modules and cells are
//! the same (as a multiset: two identical findings need two in the
//! baseline). Utilisations are compared step by step where both reports
//! have the step, and as the schedule's peak: a rise by more than the
//! tolerance is a regression, and so is a value that is not finite.

use super::report::{REPORT_FORMAT, Report, Violation};
use crate::error::InputError;
use crate::lattice::{Cell, ModuleId};
use std::collections::BTreeMap;
use std::path::Path;

/// The metric compared between reports.
const UTILISATION: &str = "max_utilisation";

/// What changed since the baseline.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Comparison {
    /// Violations the baseline did not have.
    pub new: Vec<Violation>,
    /// Baseline violations that are gone.
    pub fixed: Vec<Violation>,
    /// Violations in both.
    pub known: usize,
    /// Utilisations that rose by more than the tolerance.
    pub rises: Vec<Rise>,
}

/// A utilisation that rose: at one step, or (`step: None`) the peak over
/// the schedule.
#[derive(Clone, Debug, PartialEq)]
pub struct Rise {
    pub step: Option<usize>,
    pub before: f64,
    pub after: f64,
}

impl Comparison {
    /// Whether the comparison fails a CI job: a new violation or a rise.
    pub fn regressed(&self) -> bool {
        !self.new.is_empty() || !self.rises.is_empty()
    }

    /// A readable account: counts, then each new violation, rise and fix.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "against the baseline: {} new violation(s), {} fixed, {} known, {} utilisation rise(s)\n",
            self.new.len(),
            self.fixed.len(),
            self.known,
            self.rises.len()
        );
        for v in &self.new {
            s += &format!("  new   step {}: {}\n", v.step, v.message);
        }
        for r in &self.rises {
            let at = r.step.map_or("peak".to_string(), |k| format!("step {k}"));
            s += &format!("  rise  {at}: utilisation {} → {}\n", r.before, r.after);
        }
        for v in &self.fixed {
            s += &format!("  fixed step {}: {}\n", v.step, v.message);
        }
        s
    }
}

type Key = (String, usize, Vec<ModuleId>, Vec<Cell>);

fn key(v: &Violation) -> Key {
    let mut modules = v.modules.clone();
    modules.sort_unstable();
    let mut cells = v.cells.clone();
    cells.sort_unstable_by_key(|c| (c.x, c.y, c.z));
    (v.kind.name(), v.step, modules, cells)
}

/// Whether `after` is a regression from `before`: more than `tolerance`
/// higher, or not a finite number at all.
fn rose(before: f64, after: f64, tolerance: f64) -> bool {
    !(after.is_finite() && after <= before + tolerance)
}

/// The peak of a report's per-step utilisations at the steps `within`
/// holds (NaN ranks highest).
fn peak(r: &Report, within: impl Fn(usize) -> bool) -> Option<f64> {
    r.per_step
        .iter()
        .filter(|s| within(s.step))
        .filter_map(|s| s.metrics.get(UTILISATION).copied())
        .map(crate::mechanics::severity)
        .reduce(f64::max)
}

/// Compares `current` with `baseline`; `tolerance` is the rise in
/// utilisation (a fraction of capacity) still accepted.
pub fn compare(current: &Report, baseline: &Report, tolerance: f64) -> Comparison {
    let mut out = Comparison::default();
    // Where the current report checked part of the schedule (`--steps`),
    // the baseline's findings elsewhere are neither fixed nor compared.
    let within = |step: usize| current.in_window(step);
    let baseline_violations: Vec<&Violation> = baseline
        .violations
        .iter()
        .filter(|v| within(v.step))
        .collect();
    let mut remaining: BTreeMap<Key, usize> = BTreeMap::new();
    for v in &baseline_violations {
        *remaining.entry(key(v)).or_insert(0) += 1;
    }
    for v in &current.violations {
        match remaining.get_mut(&key(v)) {
            Some(n) if *n > 0 => {
                *n -= 1;
                out.known += 1;
            }
            _ => out.new.push(v.clone()),
        }
    }
    let mut unmatched = remaining;
    for v in baseline_violations {
        if let Some(n) = unmatched.get_mut(&key(v))
            && *n > 0
        {
            *n -= 1;
            out.fixed.push(v.clone());
        }
    }
    let before: BTreeMap<usize, f64> = baseline
        .per_step
        .iter()
        .filter_map(|s| s.metrics.get(UTILISATION).map(|&u| (s.step, u)))
        .collect();
    for s in &current.per_step {
        if let (Some(&after), Some(&b)) = (s.metrics.get(UTILISATION), before.get(&s.step))
            && rose(b, after, tolerance)
        {
            out.rises.push(Rise {
                step: Some(s.step),
                before: b,
                after,
            });
        }
    }
    if let (Some(b), Some(a)) = (peak(baseline, within), peak(current, |_| true))
        && rose(b, a, tolerance)
    {
        out.rises.push(Rise {
            step: None,
            before: b,
            after: a,
        });
    }
    out
}

/// Reads a baseline report and checks that it can be compared with
/// `current`: the same report format and version, and the same schedule
/// (its lattice and initial module count). Errors name both files.
pub fn load(path: &Path, current: &Report, current_name: &str) -> Result<Report, InputError> {
    let both =
        |m: String| InputError::new(format!("{m} (baseline for {current_name})")).in_file(path);
    let text = crate::error::read_file(path, "baseline report").map_err(|e| both(e.message))?;
    let r: Report =
        serde_json::from_str(&text).map_err(|e| both(format!("not a reconfcheck report: {e}")))?;
    if r.format != REPORT_FORMAT || r.version != current.version {
        return Err(both(format!(
            "report format {} version {} cannot be compared with {} version {}",
            r.format, r.version, REPORT_FORMAT, current.version
        )));
    }
    if r.lattice != current.lattice || r.modules != current.modules {
        return Err(both(format!(
            "a different schedule: {} lattice with {} modules, against {} with {}",
            r.lattice.name(),
            r.modules,
            current.lattice.name(),
            current.modules
        )));
    }
    Ok(r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::certify::{StepResult, ViolationKind};

    fn report(violations: Vec<Violation>, utilisations: &[f64]) -> Report {
        Report {
            format: REPORT_FORMAT.into(),
            version: 1,
            schedule: "s".into(),
            lattice: crate::lattice::LatticeKind::Fcc,
            modules: 5,
            final_modules: 5,
            steps: utilisations.len(),
            moves: 0,
            window: None,
            checks: vec![],
            load_factor_tolerance: 0.0,
            certified: violations.is_empty(),
            stopped_at: None,
            violations,
            warnings: vec![],
            per_step: utilisations
                .iter()
                .enumerate()
                .map(|(k, &u)| StepResult {
                    step: k + 1,
                    metrics: [(UTILISATION.to_string(), u)].into(),
                    ..Default::default()
                })
                .collect(),
        }
    }

    fn collision(step: usize, a: u32, b: u32) -> Violation {
        Violation::new(ViolationKind::Collision, step, format!("{a} hits {b}")).modules([a, b])
    }

    #[test]
    fn only_new_violations_and_rises_regress() {
        let old = report(vec![collision(1, 1, 2), collision(2, 3, 4)], &[0.5, 0.6]);
        // The same findings (modules in another order), one fixed.
        let cur = report(vec![collision(1, 2, 1)], &[0.5, 0.6]);
        let c = compare(&cur, &old, 1e-3);
        assert!(!c.regressed(), "{c:?}");
        assert_eq!((c.known, c.fixed.len()), (1, 1));
        // A new one, and a rise beyond the tolerance.
        let cur = report(vec![collision(1, 1, 2), collision(2, 3, 5)], &[0.5, 0.61]);
        let c = compare(&cur, &old, 1e-3);
        assert!(c.regressed());
        assert_eq!(c.new.len(), 1);
        assert_eq!(c.rises.len(), 2, "step 2 and the peak: {c:?}");
        // Within the tolerance is no rise.
        let cur = report(vec![], &[0.5, 0.6005]);
        assert!(compare(&cur, &old, 1e-3).rises.is_empty());
    }

    #[test]
    fn a_span_of_steps_is_compared_with_the_baseline_there_only() {
        // The whole run: findings at steps 1 and 3, its peak at step 1.
        let old = report(
            vec![collision(1, 1, 2), collision(3, 3, 4)],
            &[0.9, 0.5, 0.6, 0.4],
        );
        // Steps 2-3 checked (`--steps 2-3`), with the same finding at 3:
        // step 1's is not fixed, and the peak is step 3's, not 0.9.
        let mut cur = report(vec![collision(3, 3, 4)], &[0.5, 0.6]);
        cur.steps = 4;
        cur.window = Some(crate::certify::StepSpan { first: 2, last: 3 });
        for s in &mut cur.per_step {
            s.step += 1;
        }
        let c = compare(&cur, &old, 1e-3);
        assert_eq!((c.known, c.fixed.len(), c.new.len()), (1, 0, 0), "{c:?}");
        assert!(!c.regressed());
        // A rise there is still one, at the step and as the span's peak.
        cur.per_step[1].metrics.insert(UTILISATION.into(), 0.7);
        let c = compare(&cur, &old, 1e-3);
        assert_eq!(c.rises.len(), 2, "{c:?}");
        // And the finding fixed there is fixed.
        cur.violations.clear();
        assert_eq!(compare(&cur, &old, 1e-3).fixed.len(), 1);
    }

    #[test]
    fn a_duplicate_finding_needs_its_own_match_in_the_baseline() {
        let old = report(vec![collision(1, 1, 2)], &[]);
        let cur = report(vec![collision(1, 1, 2), collision(1, 1, 2)], &[]);
        assert_eq!(compare(&cur, &old, 0.0).new.len(), 1);
    }

    #[test]
    fn a_utilisation_that_is_not_finite_is_a_rise() {
        let old = report(vec![], &[0.5]);
        for bad in [f64::NAN, f64::INFINITY] {
            let c = compare(&report(vec![], &[bad]), &old, 1.0);
            assert!(c.regressed(), "{bad}");
        }
    }
}
