//! Certification: replays a schedule step by step and runs every check on
//! every step.
//!
//! Checks implement [`StepCheck`]; the lattice checks always run, geometric
//! and mechanical checks join them where the lattice has a model for them.

pub mod collision_check;
pub mod lattice_check;
pub mod load_check;
pub mod report;
pub mod world;

pub use collision_check::CollisionCheck;
pub use lattice_check::LatticeCheck;
pub use load_check::LoadCheck;
pub use report::{Report, StepResult, Violation, ViolationKind};
pub use world::{Move, StepPlan, World};

use crate::error::InputError;
use crate::schedule::Schedule;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Certification options.
#[derive(Clone, Debug)]
pub struct Options {
    /// Name of the schedule in the report (usually its path).
    pub name: String,
    /// Show a progress bar on standard error for long schedules.
    pub progress: bool,
    /// Force exact sweeps everywhere (no compiled rule tables).
    pub exact: bool,
    /// Collision tolerance in units of d.
    pub epsilon: f64,
    /// Run the lattice checks only (no geometry, no mechanics).
    pub lattice_only: bool,
    /// Physical model file for the mechanics check; overrides the
    /// schedule's own `model`.
    pub model: Option<PathBuf>,
    /// Directory the schedule's relative `model` path is resolved against
    /// (the schedule file's directory).
    pub base_dir: Option<PathBuf>,
    /// Steps per range for the checks that run over ranges of steps in
    /// parallel (see [`StepCheck::for_range`]): `None` chooses from the
    /// number of threads, `Some(0)` runs every check in one pass.
    pub range_steps: Option<usize>,
}

impl Options {
    /// Default options with the lattice checks only (no geometry, no
    /// mechanics): what generators' own tests and the lattice studies use.
    pub fn lattice_only() -> Options {
        Options {
            lattice_only: true,
            ..Default::default()
        }
    }
}

impl Default for Options {
    fn default() -> Self {
        Options {
            name: "schedule".into(),
            progress: false,
            exact: false,
            epsilon: crate::geometry::EPSILON,
            lattice_only: false,
            model: None,
            base_dir: None,
            range_steps: None,
        }
    }
}

/// What a check sees of one step: the scene before it and the step's moves.
pub struct StepContext<'a> {
    pub world: &'a World,
    pub plan: &'a StepPlan,
}

/// Findings of the checks on one step.
#[derive(Debug, Default)]
pub struct StepOutcome {
    pub violations: Vec<Violation>,
    pub warnings: Vec<Violation>,
    pub metrics: BTreeMap<String, f64>,
}

impl StepOutcome {
    /// An outcome that starts with what resolving the step's events found.
    pub fn of_plan(plan: &StepPlan) -> StepOutcome {
        StepOutcome {
            violations: plan.violations.clone(),
            ..Default::default()
        }
    }
}

/// One step of a replay, the loop body that certification, its parallel
/// ranges and [`load_check::replay`] share: resolves step `k` (0-based) of
/// `schedule` against `world`, shows `inspect` the scene before the step
/// with its plan, then applies the step. Returns what `inspect` returned,
/// the plan and the clashes of applying it.
pub fn advance<R>(
    world: &mut World,
    schedule: &Schedule,
    k: usize,
    inspect: impl FnOnce(&StepContext<'_>) -> R,
) -> Result<(R, StepPlan, Vec<Violation>), InputError> {
    let plan = world.resolve(k + 1, &schedule.steps[k])?;
    let seen = inspect(&StepContext { world, plan: &plan });
    let clashes = world.apply(&plan);
    Ok((seen, plan, clashes))
}

/// One kind of check, run on every step of a schedule.
pub trait StepCheck: Send + Sync {
    /// Short name listed in the report.
    fn name(&self) -> &'static str;
    /// Examines one step; `ctx.world` is the scene at the start of the step.
    fn check(&self, ctx: &StepContext<'_>, out: &mut StepOutcome);
    /// Examines the final configuration (after the last step).
    fn check_final(&self, world: &World, step: usize, out: &mut StepOutcome) {
        let _ = (world, step, out);
    }
    /// A fresh instance of this check for one range of consecutive steps,
    /// for checks that are costly per step and carry state from step to
    /// step (the mechanics' kept factors): the ranges then run in
    /// parallel, each from the scene at its first step. `None` (the
    /// default): the check runs in the one pass over the schedule.
    fn for_range(&self) -> Option<Box<dyn StepCheck>> {
        None
    }
    /// Whether [`StepCheck::for_range`] makes instances: asked when the
    /// checks are split, so that no instance is built just to find out.
    fn ranged(&self) -> bool {
        false
    }
}

/// Steps per range for `steps` steps: about four ranges per thread (the
/// later steps of a growing structure cost more, and rayon balances the
/// ranges), none below 16 steps or on one thread.
fn range_steps(opts: &Options, steps: usize) -> usize {
    match opts.range_steps {
        Some(n) => n,
        None => {
            let threads = rayon::current_num_threads();
            if threads < 2 || steps < 64 {
                0
            } else {
                steps.div_ceil(4 * threads).max(16)
            }
        }
    }
}

/// The checks that apply to a schedule: the lattice checks always, the
/// collision check where the lattice has a body model, the mechanics check
/// where a physical model is given (by the user or the schedule).
pub fn checks_for(
    schedule: &Schedule,
    opts: &Options,
) -> Result<Vec<Box<dyn StepCheck>>, InputError> {
    let mut checks: Vec<Box<dyn StepCheck>> = vec![Box::new(LatticeCheck)];
    if opts.lattice_only {
        return Ok(checks);
    }
    if let Some(model) = crate::geometry::sweep_model(schedule.lattice) {
        checks.push(Box::new(CollisionCheck {
            model,
            epsilon: opts.epsilon,
            exact: opts.exact,
        }));
    }
    if let Some(path) = model_path(schedule, opts) {
        let model = crate::mechanics::Model::load(&path)?;
        checks.push(Box::new(LoadCheck::new(
            &model,
            schedule.spacing.metres(),
            true,
        )));
    }
    Ok(checks)
}

/// The model file the mechanics check uses: the user's, else the
/// schedule's (relative to its directory), else none.
pub fn model_path(schedule: &Schedule, opts: &Options) -> Option<PathBuf> {
    opts.model.clone().or_else(|| {
        schedule.model.as_ref().map(|m| match &opts.base_dir {
            Some(dir) => dir.join(m),
            None => PathBuf::from(m),
        })
    })
}

/// What the report's check list says when no model was given.
pub const MECHANICS_NOT_RUN: &str =
    "mechanics: not run (no model: pass --model FILE or name one in the schedule)";

/// Certifies `schedule` with every check that applies to it.
pub fn certify(schedule: &Schedule, opts: &Options) -> Result<Report, InputError> {
    let checks = checks_for(schedule, opts)?;
    let refs: Vec<&dyn StepCheck> = checks.iter().map(|c| c.as_ref()).collect();
    let mut report = certify_with(schedule, opts, &refs)?;
    if !opts.lattice_only && !checks.iter().any(|c| c.name() == load_check::NAME) {
        report.checks.push(MECHANICS_NOT_RUN.to_string());
    }
    Ok(report)
}

/// Certifies `schedule` with the given checks. Input errors (not a schedule
/// this lattice can execute) abort; violations are collected in the report.
pub fn certify_with(
    schedule: &Schedule,
    opts: &Options,
    checks: &[&dyn StepCheck],
) -> Result<Report, InputError> {
    let mut world = World::initial(schedule)?;
    let range = range_steps(opts, schedule.steps.len());
    let (ranged, inline): (Vec<&dyn StepCheck>, Vec<&dyn StepCheck>) = checks
        .iter()
        .copied()
        .partition(|c| range > 0 && c.ranged());
    // The scene at the first step of every range, taken in the one pass.
    let mut starts: Vec<(usize, World)> = Vec::new();
    let mut report = Report {
        format: report::REPORT_FORMAT.to_string(),
        version: 1,
        schedule: opts.name.clone(),
        lattice: schedule.lattice,
        modules: schedule.modules.len(),
        final_modules: schedule.final_module_count(),
        steps: schedule.steps.len(),
        moves: schedule.move_count(),
        checks: checks.iter().map(|c| c.name().to_string()).collect(),
        certified: false,
        stopped_at: None,
        violations: Vec::new(),
        warnings: Vec::new(),
        per_step: Vec::with_capacity(schedule.steps.len()),
    };
    let passes = if ranged.is_empty() { 1 } else { 2 };
    let bar = progress_bar(opts, passes * schedule.steps.len());

    // The initial configuration must stand on its own.
    let nobody = Default::default();
    let loose = world.unanchored(&nobody);
    world.set_anchored(loose.is_empty());
    if !loose.is_empty() {
        report.violations.push(
            Violation::new(
                ViolationKind::Disconnected,
                0,
                format!(
                    "the initial configuration has {} module(s) not connected to the ground",
                    loose.len()
                ),
            )
            .modules(loose),
        );
    }

    for k in 0..schedule.steps.len() {
        let index = k + 1;
        if !ranged.is_empty() && k % range == 0 {
            starts.push((k, world.clone()));
        }
        let (mut out, plan, clashes) = advance(&mut world, schedule, k, |ctx| {
            let mut out = StepOutcome::of_plan(ctx.plan);
            for c in &inline {
                c.check(ctx, &mut out);
            }
            out
        })?;
        let stop = !clashes.is_empty();
        let tunnels = plan
            .moves
            .iter()
            .any(|m| matches!(m.motion, crate::lattice::Motion::Tunnel { .. }));
        let lattice_clean = out.violations.iter().all(|v| !v.kind.is_lattice_level());
        world.set_anchored(lattice_clean && plan.detaches.is_empty() && !tunnels);
        out.violations.extend(clashes);
        report.per_step.push(StepResult {
            step: index,
            moves: plan.moves.len(),
            violations: out.violations.len(),
            warnings: out.warnings.len(),
            metrics: out.metrics,
        });
        report.violations.extend(out.violations);
        report.warnings.extend(out.warnings);
        bar.inc(1);
        if stop {
            report.stopped_at = Some(index);
            break;
        }
    }
    if !ranged.is_empty() {
        let last = report.per_step.len();
        let outcomes = ranges_in_parallel(schedule, &ranged, &starts, range, last, &bar)?;
        for (k, out) in outcomes {
            let r = &mut report.per_step[k];
            r.violations += out.violations.len();
            r.warnings += out.warnings.len();
            r.metrics.extend(out.metrics);
            report.violations.extend(out.violations);
            report.warnings.extend(out.warnings);
        }
        // Back in step order, each step's own findings in check order.
        report.violations.sort_by_key(|v| v.step);
        report.warnings.sort_by_key(|v| v.step);
    }
    bar.finish_and_clear();

    if report.stopped_at.is_none() {
        let final_step = schedule.steps.len() + 1;
        world.set_anchored(false);
        let loose = world.unanchored(&nobody);
        if !loose.is_empty() {
            report.violations.push(
                Violation::new(
                    ViolationKind::Disconnected,
                    final_step,
                    format!(
                        "the final configuration has {} module(s) not connected to the ground",
                        loose.len()
                    ),
                )
                .modules(loose),
            );
        }
        let mut out = StepOutcome::default();
        for c in checks {
            // A ranged check's own instance saw no step: it analyses the
            // final scene from scratch.
            c.check_final(&world, final_step, &mut out);
        }
        report.violations.extend(out.violations);
        report.warnings.extend(out.warnings);
    }
    report.certified = report.violations.is_empty() && report.stopped_at.is_none();
    Ok(report)
}

/// Runs the `ranged` checks over the first `last` steps, one range of
/// `range` steps per scene in `starts`, in parallel; returns every step's
/// findings (0-based step index), in step order.
fn ranges_in_parallel(
    schedule: &Schedule,
    ranged: &[&dyn StepCheck],
    starts: &[(usize, World)],
    range: usize,
    last: usize,
    bar: &indicatif::ProgressBar,
) -> Result<Vec<(usize, StepOutcome)>, InputError> {
    use rayon::prelude::*;
    let per_range: Vec<Vec<(usize, StepOutcome)>> = starts
        .par_iter()
        .filter(|(first, _)| *first < last)
        .map(|(first, start)| {
            let checks: Vec<Box<dyn StepCheck>> = ranged
                .iter()
                .map(|c| c.for_range().expect("a ranged check makes range instances"))
                .collect();
            let mut world = start.clone();
            let mut found = Vec::new();
            for k in *first..(first + range).min(last) {
                let (out, _, _) = advance(&mut world, schedule, k, |ctx| {
                    let mut out = StepOutcome::default();
                    for c in &checks {
                        c.check(ctx, &mut out);
                    }
                    out
                })?;
                found.push((k, out));
                bar.inc(1);
            }
            Ok(found)
        })
        .collect::<Result<_, InputError>>()?;
    Ok(per_range.into_iter().flatten().collect())
}

fn progress_bar(opts: &Options, steps: usize) -> indicatif::ProgressBar {
    crate::progress::bar(
        opts.progress && steps >= 50,
        steps,
        "certifying {bar:40} {pos}/{len} steps ({per_sec}, eta {eta})",
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algorithms::random_walk::{WalkParams, walk};
    use std::sync::{Arc, Mutex};

    /// Records, per instance, the steps it checked: the prototype's own
    /// list and one list per range instance.
    struct Recorder {
        ranged: bool,
        seen: Arc<Mutex<Vec<Vec<usize>>>>,
        mine: usize,
    }

    impl Recorder {
        fn new(ranged: bool) -> Recorder {
            Recorder {
                ranged,
                seen: Arc::new(Mutex::new(vec![Vec::new()])),
                mine: 0,
            }
        }
    }

    impl StepCheck for Recorder {
        fn name(&self) -> &'static str {
            "recorder"
        }
        fn check(&self, ctx: &StepContext<'_>, out: &mut StepOutcome) {
            self.seen.lock().unwrap()[self.mine].push(ctx.plan.step);
            out.metrics.insert("seen".into(), 1.0);
        }
        fn for_range(&self) -> Option<Box<dyn StepCheck>> {
            let mut seen = self.seen.lock().unwrap();
            seen.push(Vec::new());
            Some(Box::new(Recorder {
                ranged: self.ranged,
                seen: self.seen.clone(),
                mine: seen.len() - 1,
            }))
        }
        fn ranged(&self) -> bool {
            self.ranged
        }
    }

    fn schedule() -> Schedule {
        let p = WalkParams {
            width: 5,
            depth: 5,
            walkers: 4,
            steps: 40,
            activity: 0.7,
            seed: 3,
            geometric: false,
        };
        walk(&p, &|_, _, _| true)
    }

    /// Certifies `s` with the lattice check and `rec`, ranges of 7 steps.
    fn in_ranges_of_7(s: &Schedule, rec: &Recorder) -> Report {
        let opts = Options {
            range_steps: Some(7),
            ..Options::lattice_only()
        };
        certify_with(s, &opts, &[&LatticeCheck, rec]).unwrap()
    }

    #[test]
    fn a_ranged_check_sees_every_step_once_through_one_instance_per_range() {
        let s = schedule();
        let rec = Recorder::new(true);
        let r = in_ranges_of_7(&s, &rec);
        let seen = rec.seen.lock().unwrap();
        assert!(seen[0].is_empty(), "the prototype checks no step itself");
        // Instances are made as rayon reaches the ranges: order them.
        let mut ranges = seen[1..].to_vec();
        ranges.sort_by_key(|r| r.first().copied());
        assert_eq!(ranges.len(), s.steps.len().div_ceil(7));
        for (k, steps) in ranges.iter().enumerate() {
            let first = 7 * k + 1;
            let want: Vec<usize> = (first..(first + 7).min(s.steps.len() + 1)).collect();
            assert_eq!(*steps, want, "range {k}: one instance, its steps in order");
        }
        // Every step's findings are merged back into its own result.
        assert!(r.per_step.iter().all(|p| p.metrics["seen"] == 1.0));
    }

    #[test]
    fn a_schedule_built_in_code_is_validated_before_replay() {
        // Not read from a file, not made by `algorithms::generate`: the
        // replay itself refuses what a file would be refused for.
        let mut s = schedule();
        s.spacing.value = -3.6;
        let e = certify(&s, &Options::lattice_only()).unwrap_err();
        assert!(e.message.contains("not a positive length"), "{e}");
        let mut s = schedule();
        s.modules[0].cell = crate::lattice::Cell::new(i32::MIN, 0, 0);
        let e = certify(&s, &Options::lattice_only()).unwrap_err();
        assert!(e.message.contains("beyond"), "{e}");
        assert_eq!(e.module, Some(s.modules[0].id));
    }

    #[test]
    fn a_check_that_is_not_ranged_runs_in_the_one_pass() {
        let s = schedule();
        let rec = Recorder::new(false);
        in_ranges_of_7(&s, &rec);
        let seen = rec.seen.lock().unwrap();
        assert_eq!(seen.len(), 1, "no range instance was made");
        assert_eq!(seen[0], (1..=s.steps.len()).collect::<Vec<_>>());
    }
}
