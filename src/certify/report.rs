//! Certification results: typed violations, per-step results, and the two
//! renderings (JSON for machines, a summary for people).

use crate::lattice::config::ModuleId;
use crate::lattice::{Cell, LatticeKind};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// What went wrong (or, for warnings, what deserves a look).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ViolationKind {
    /// Two modules in one cell at the end of a step (or a blocked entry).
    Occupancy,
    /// The pivot named by a move is not in the scene.
    PivotMissing,
    /// The pivot moves in the same step as the module rolling on it.
    PivotMoving,
    /// The mover is not held: its latch to the pivot is released, or a
    /// support the move needs (wall, corner, ground) is absent or moving.
    MoverDetached,
    /// A cell the move sweeps through is occupied.
    PassageBlocked,
    /// The static structure is not connected to the ground/anchors.
    Disconnected,
    /// A module is given more than one move in one time step.
    MultipleMoves,
    /// A module enters somewhere other than a source cell.
    NotASource,
    /// A module leaves from somewhere other than a sink cell.
    NotASink,
    /// An attach/detach between modules that are not neighbours.
    LatchNotAdjacent,
    /// Two module bodies interpenetrate during a sweep (geometry check).
    Collision,
    /// A mover slides in contact with a module that is not its pivot.
    SlidingContact,
    /// A mover's body dips below the floor under the ground layer during
    /// its sweep (geometry check).
    GroundCollision,
    /// A docking's final approach is not clear by the exact geometry (seed
    /// 002): origin or passage occupied, a support missing, or a module
    /// penetrated along the sweep.
    DockingBlocked,
    /// The structure has no static equilibrium under gravity.
    Unstable,
    /// A connector load exceeds its capacity.
    Overload,
    /// Seed 004 atoms: the arms changing in one step disagree around a
    /// cycle of attached faces (the step would tear the robot apart).
    ArmConflict,
    /// Seed 004 atoms: an atom leaves the union of the source's and the
    /// target's bounding boxes (the paper's in-place claim).
    OutOfPlace,
    /// Seed 004 meta-modules: a k-TUNNEL whose start is not a leaf, whose
    /// legs are attached to other meta-modules between turns, whose path
    /// is not static and occupied or whose exit is not free, or that turns
    /// more than 4 times.
    TunnelPrecondition,
    /// A note: the mechanics judged a component at the sampled poses of
    /// its movers' sweeps alone, so between samples its verdict is not
    /// proved (`mechanics::analysis::SampledOnly` says why).
    JudgedAtSamples,
}

impl ViolationKind {
    /// Whether the kind is found by the lattice checks (as opposed to the
    /// geometric and mechanical ones).
    pub fn is_lattice_level(self) -> bool {
        !matches!(
            self,
            ViolationKind::Collision
                | ViolationKind::SlidingContact
                | ViolationKind::GroundCollision
                | ViolationKind::DockingBlocked
                | ViolationKind::Unstable
                | ViolationKind::Overload
                | ViolationKind::JudgedAtSamples
        )
    }

    pub fn name(self) -> String {
        serde_json::to_value(self)
            .ok()
            .and_then(|v| v.as_str().map(str::to_owned))
            .unwrap_or_default()
    }
}

/// How much a finding matters: a violation refuses the certificate, a
/// warning deserves a look, a note is information. Kept on each finding so
/// that readers (the summary, the HTML page, CI) rank them alike.
#[derive(
    Copy, Clone, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize,
)]
#[serde(rename_all = "snake_case")]
pub enum Severity {
    Note,
    Warning,
    #[default]
    Error,
}

impl Severity {
    pub fn name(self) -> &'static str {
        match self {
            Severity::Note => "note",
            Severity::Warning => "warning",
            Severity::Error => "error",
        }
    }

    /// Errors are the default and left out of the JSON, which keeps the
    /// violations' JSON as it was before severities existed.
    fn is_error(&self) -> bool {
        *self == Severity::Error
    }
}

/// One finding of a check.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Violation {
    pub kind: ViolationKind,
    /// `error` for violations (left out of the JSON), lower for warnings.
    #[serde(default, skip_serializing_if = "Severity::is_error")]
    pub severity: Severity,
    /// Time step (1-based); `steps + 1` is the final configuration.
    pub step: usize,
    pub modules: Vec<ModuleId>,
    pub cells: Vec<Cell>,
    pub message: String,
    /// Check-specific numbers (sweep parameter, depth, witness points, load).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub detail: BTreeMap<String, serde_json::Value>,
}

impl Violation {
    pub fn new(kind: ViolationKind, step: usize, message: impl Into<String>) -> Self {
        Violation {
            kind,
            severity: Severity::Error,
            step,
            modules: Vec::new(),
            cells: Vec::new(),
            message: message.into(),
            detail: BTreeMap::new(),
        }
    }

    pub fn severity(mut self, s: Severity) -> Self {
        self.severity = s;
        self
    }

    pub fn modules(mut self, m: impl IntoIterator<Item = ModuleId>) -> Self {
        self.modules.extend(m);
        self
    }

    pub fn cells(mut self, c: impl IntoIterator<Item = Cell>) -> Self {
        self.cells.extend(c);
        self
    }

    pub fn detail(mut self, key: &str, value: impl Serialize) -> Self {
        self.detail.insert(
            key.to_string(),
            serde_json::to_value(value).expect("detail serialises"),
        );
        self
    }
}

/// Results of one step.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StepResult {
    pub step: usize,
    pub moves: usize,
    pub violations: usize,
    pub warnings: usize,
    /// Check-specific figures: e.g. `max_utilisation`, `min_clearance`.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub metrics: BTreeMap<String, f64>,
}

/// The steps a certification checked when it was asked for part of a
/// schedule (`certify --steps FIRST-LAST`), 1-based and inclusive as
/// steps are numbered everywhere. The steps before `first` were replayed
/// to reach its configuration, without checks; those after `last` were
/// not replayed.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepSpan {
    pub first: usize,
    pub last: usize,
}

impl StepSpan {
    /// Whether step `k` of a schedule of `steps` steps was checked: its
    /// initial configuration (`k` = 0) with the first step, its final one
    /// (`steps + 1`) with the last.
    pub fn holds(&self, k: usize, steps: usize) -> bool {
        (k == 0 && self.first == 1)
            || (self.first..=self.last).contains(&k)
            || (k == steps + 1 && self.last == steps)
    }
}

/// The certificate (or its refusal) for one schedule.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Report {
    pub format: String,
    pub version: u32,
    pub schedule: String,
    pub lattice: LatticeKind,
    /// Modules in the initial configuration.
    pub modules: usize,
    /// Modules at the end (initial + entered − left): a scaffold run starts
    /// with its sandbox and ends with sandbox and shape.
    #[serde(default)]
    pub final_modules: usize,
    pub steps: usize,
    pub moves: usize,
    /// The steps checked, where only part of the schedule was
    /// (`--steps`); absent when every step was.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window: Option<StepSpan>,
    /// Names of the checks that were run.
    pub checks: Vec<String>,
    /// How far above the exact smallest load factor of a step's poses the
    /// reported ones may lie, as a fraction of them
    /// (`--load-factor-tolerance`); absent when exact.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub load_factor_tolerance: f64,
    pub certified: bool,
    /// Set when a violation left the state undefined (two modules in one
    /// cell) and later steps could not be checked.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stopped_at: Option<usize>,
    pub violations: Vec<Violation>,
    pub warnings: Vec<Violation>,
    pub per_step: Vec<StepResult>,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

pub const REPORT_FORMAT: &str = "reconfcheck-report";

impl Report {
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("reports serialise")
    }

    /// Whether step `k` (0: the initial configuration, `steps + 1`: the
    /// final one) lies in the steps this report was asked to check: every
    /// step unless `--steps` narrowed them (a stop is not considered).
    pub fn in_window(&self, k: usize) -> bool {
        self.window.is_none_or(|w| w.holds(k, self.steps))
    }

    /// The violations of one kind, in report order.
    pub fn violations_of(&self, kind: ViolationKind) -> impl Iterator<Item = &Violation> {
        self.violations.iter().filter(move |v| v.kind == kind)
    }

    /// Counts of violations by kind.
    pub fn violation_counts(&self) -> BTreeMap<ViolationKind, usize> {
        let mut m = BTreeMap::new();
        for v in &self.violations {
            *m.entry(v.kind).or_insert(0) += 1;
        }
        m
    }

    /// Counts of warnings by kind and severity.
    pub fn warning_counts(&self) -> BTreeMap<(ViolationKind, Severity), usize> {
        let mut m = BTreeMap::new();
        for w in &self.warnings {
            *m.entry((w.kind, w.severity)).or_insert(0) += 1;
        }
        m
    }

    /// What this report vouches for and what it does not: the checks that
    /// ran (with the steps they covered), and each check that did not run
    /// with the reason, so that a lattice-only pass is never read as a
    /// full certificate.
    pub fn coverage(&self) -> (Vec<String>, Vec<String>) {
        let ran = |name: &str| {
            self.checks
                .iter()
                .any(|c| c == name || c.starts_with(&format!("atoms: {name}")))
        };
        let no_model = self
            .checks
            .iter()
            .any(|c| c.starts_with("mechanics: not run"));
        let lattice_only = !ran("collision") && !ran("mechanics") && !no_model;
        let (first, last) = self.window.map_or((1, self.steps), |w| (w.first, w.last));
        let covered = match self.stopped_at {
            Some(k) if k < first => "no step".to_string(),
            Some(k) => format!("steps {first}–{k}"),
            None if self.steps == 0 => "no steps: the configuration".to_string(),
            None if last == self.steps => {
                format!("steps {first}–{last} and the final configuration")
            }
            None => format!("steps {first}–{last}"),
        };
        let checked = self
            .checks
            .iter()
            .filter(|c| !c.contains(": not run"))
            .map(|c| format!("{c} ({covered})"))
            .collect();
        let mut not_checked = Vec::new();
        let meta = self
            .checks
            .iter()
            .any(|c| c.starts_with("meta-module level"));
        if meta {
            not_checked.push(
                "atoms (kinematics, collisions, their connectivity and in-place bound) and mechanics: meta-module level only (--meta-level)"
                    .to_string(),
            );
        }
        if !meta && !ran("collision") {
            not_checked.push(if crate::geometry::sweep_model(self.lattice).is_none() {
                format!(
                    "collision: no body model for the {} lattice",
                    self.lattice.name()
                )
            } else if lattice_only {
                "collision: lattice checks only (--lattice-only)".to_string()
            } else {
                "collision: not requested".to_string()
            });
        }
        if !meta && !ran("mechanics") {
            not_checked.push(if no_model {
                "mechanics: no physical model (pass --model FILE or name one in the schedule)"
                    .to_string()
            } else if lattice_only {
                "mechanics: lattice checks only (--lattice-only)".to_string()
            } else {
                "mechanics: not requested".to_string()
            });
        }
        let mut sampled = self
            .warnings
            .iter()
            .filter(|w| w.kind == ViolationKind::JudgedAtSamples)
            .map(|w| w.step);
        if let Some(first) = sampled.next() {
            not_checked.push(format!(
                "mechanics between the sampled poses of the movers' sweeps at {} step(s), from step {first} ({} notes)",
                1 + sampled.count(),
                ViolationKind::JudgedAtSamples.name()
            ));
        }
        if first > 1 {
            not_checked.push(format!(
                "the initial configuration and steps 1–{}: replayed to reach step {first} (--steps)",
                first - 1
            ));
        }
        if let Some(k) = self.stopped_at {
            not_checked.push(format!(
                "steps after {k}: the state is undefined from there on"
            ));
        } else if last < self.steps {
            not_checked.push(format!(
                "steps {}–{} and the final configuration: after the steps asked for (--steps)",
                last + 1,
                self.steps
            ));
        }
        (checked, not_checked)
    }

    /// A readable summary: verdict, counts, the first findings.
    pub fn summary(&self) -> String {
        let mut s = String::new();
        let verdict = if self.certified {
            "CERTIFIED"
        } else {
            "NOT CERTIFIED"
        };
        let _ = writeln!(
            s,
            "{verdict}: {} ({} lattice, {} modules at the start, {} at the end, {} steps, {} moves)",
            self.schedule,
            self.lattice.name(),
            self.modules,
            self.final_modules,
            self.steps,
            self.moves
        );
        let _ = writeln!(s, "checks: {}", self.checks.join(", "));
        if self.load_factor_tolerance > 0.0 {
            let _ = writeln!(
                s,
                "load factors: each exact one is at least (1 − {}) × the reported one and at least its load_factor_lower_bound (--load-factor-tolerance); verdicts exact",
                self.load_factor_tolerance
            );
        }
        let (checked, not_checked) = self.coverage();
        let _ = writeln!(s, "checked: {}", checked.join("; "));
        for n in &not_checked {
            let _ = writeln!(s, "NOT checked: {n}");
        }
        for (k, n) in self.violation_counts() {
            let _ = writeln!(s, "  {n:>6} × {}", k.name());
        }
        if let Some(k) = self.stopped_at {
            let _ = writeln!(
                s,
                "stopped after step {k}: the state is undefined from there on"
            );
        }
        for v in self.violations.iter().take(10) {
            let _ = writeln!(s, "  step {}: {}: {}", v.step, v.kind.name(), v.message);
        }
        if self.violations.len() > 10 {
            let _ = writeln!(
                s,
                "  … {} more violations in the JSON report",
                self.violations.len() - 10
            );
        }
        if !self.warnings.is_empty() {
            let _ = writeln!(s, "warnings: {}", self.warnings.len());
            for ((k, sev), n) in self.warning_counts() {
                let _ = writeln!(s, "  {n:>6} × {} ({})", k.name(), sev.name());
            }
            for w in self.warnings.iter().take(5) {
                let _ = writeln!(
                    s,
                    "  step {}: {} {}: {}",
                    w.step,
                    w.severity.name(),
                    w.kind.name(),
                    w.message
                );
            }
            if self.warnings.len() > 5 {
                let _ = writeln!(
                    s,
                    "  … {} more warnings in the JSON report",
                    self.warnings.len() - 5
                );
            }
        }
        // Each metric's worst step: the highest, but for a load factor the
        // lowest (the step nearest to collapse).
        let lowest_is_worst = |k: &str| k.starts_with("load_factor");
        let mut metrics: BTreeMap<&str, (f64, usize)> = BTreeMap::new();
        for r in &self.per_step {
            for (k, &v) in &r.metrics {
                let low = lowest_is_worst(k);
                let start = if low {
                    f64::INFINITY
                } else {
                    f64::NEG_INFINITY
                };
                let e = metrics.entry(k.as_str()).or_insert((start, 0));
                if (low && v < e.0) || (!low && v > e.0) {
                    *e = (v, r.step);
                }
            }
        }
        for (k, (v, step)) in metrics {
            let which = if lowest_is_worst(k) {
                "lowest"
            } else {
                "highest"
            };
            let _ = writeln!(s, "{which} {k} over the steps: {v:.4} (step {step})");
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(violations: Vec<Violation>, warnings: Vec<Violation>) -> Report {
        Report {
            format: REPORT_FORMAT.into(),
            version: 1,
            schedule: "s.json".into(),
            lattice: LatticeKind::Fcc,
            modules: 3,
            final_modules: 5,
            steps: 9,
            moves: 9,
            window: None,
            checks: vec!["lattice".into()],
            load_factor_tolerance: 0.0,
            certified: violations.is_empty(),
            stopped_at: None,
            violations,
            warnings,
            per_step: Vec::new(),
        }
    }

    #[test]
    fn the_summary_says_what_a_lattice_only_pass_did_not_check() {
        let s = report(Vec::new(), Vec::new()).summary();
        assert!(
            s.contains("checked: lattice (steps 1–9 and the final configuration)"),
            "{s}"
        );
        assert!(
            s.contains("NOT checked: collision: lattice checks only (--lattice-only)"),
            "{s}"
        );
        assert!(
            s.contains("NOT checked: mechanics: lattice checks only (--lattice-only)"),
            "{s}"
        );
    }

    #[test]
    fn a_schedule_of_no_steps_is_checked_as_its_configuration_not_steps_1_to_0() {
        let mut r = report(Vec::new(), Vec::new());
        r.steps = 0;
        let s = r.summary();
        assert!(
            s.contains("checked: lattice (no steps: the configuration)"),
            "{s}"
        );
        assert!(!s.contains("1–0"), "{s}");
    }

    #[test]
    fn the_summary_says_mechanics_was_not_checked_without_a_model() {
        let mut r = report(Vec::new(), Vec::new());
        r.checks = vec![
            "lattice".into(),
            "collision".into(),
            crate::certify::MECHANICS_NOT_RUN.into(),
        ];
        let s = r.summary();
        assert!(
            s.contains(
                "checked: lattice (steps 1–9 and the final configuration); collision (steps 1–9"
            ),
            "{s}"
        );
        assert!(
            s.contains("NOT checked: mechanics: no physical model"),
            "{s}"
        );
        assert!(!s.contains("NOT checked: collision"), "{s}");
    }

    #[test]
    fn a_warning_keeps_its_severity_in_the_json_and_a_violation_stays_as_before() {
        let w =
            Violation::new(ViolationKind::SlidingContact, 2, "slide").severity(Severity::Warning);
        let json = serde_json::to_string(&w).unwrap();
        assert!(json.contains("\"severity\":\"warning\""), "{json}");
        let back: Violation = serde_json::from_str(&json).unwrap();
        assert_eq!(back.severity, Severity::Warning);
        let v = Violation::new(ViolationKind::Collision, 2, "bump");
        let json = serde_json::to_string(&v).unwrap();
        assert!(!json.contains("severity"), "{json}");
        let back: Violation = serde_json::from_str(&json).unwrap();
        assert_eq!(back.severity, Severity::Error);
    }

    #[test]
    fn the_summary_names_the_module_count_at_the_start_and_at_the_end() {
        let s = report(Vec::new(), Vec::new()).summary();
        assert!(s.contains("3 modules at the start, 5 at the end"), "{s}");
    }

    #[test]
    fn the_summary_counts_findings_by_kind_and_lists_the_first() {
        let slide = |k| {
            Violation::new(ViolationKind::SlidingContact, k, format!("slide {k}"))
                .severity(Severity::Warning)
        };
        let warnings: Vec<Violation> = (1..=7).map(slide).collect();
        let collision = Violation::new(ViolationKind::Collision, 4, "bump");
        let text = report(vec![collision], warnings).summary();
        assert!(text.starts_with("NOT CERTIFIED: s.json"), "{text}");
        assert!(text.contains("       1 × collision"), "{text}");
        assert!(
            text.contains("warnings: 7\n       7 × sliding_contact (warning)"),
            "{text}"
        );
        assert!(
            text.contains("step 5: warning sliding_contact: slide 5"),
            "{text}"
        );
        assert!(!text.contains("slide 6"), "{text}");
        assert!(
            text.contains("… 2 more warnings in the JSON report"),
            "{text}"
        );
    }
}
