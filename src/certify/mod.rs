//! Certification: replays a schedule step by step and runs every check on
//! every step.
//!
//! Checks implement [`StepCheck`]; the lattice checks always run, geometric
//! and mechanical checks join them where the lattice has a model for them.

pub mod atom_check;
pub(crate) mod baseline;
pub(crate) mod collision_check;
pub(crate) mod docking_check;
pub mod jobs;
pub(crate) mod junit;
pub(crate) mod lattice_check;
pub(crate) mod load_check;
pub mod meta_check;
pub(crate) mod report;
pub(crate) mod window;
pub(crate) mod world;

pub use baseline::{Comparison, Rise, compare as compare_with_baseline, load as load_baseline};
pub use collision_check::CollisionCheck;
pub use docking_check::DockingCheck;
pub use junit::{check_of, to_junit};
pub use lattice_check::LatticeCheck;
pub use load_check::{LoadCheck, RangedReplay, load_maps_at, replay, replay_ranged};
pub use report::{Report, Severity, StepResult, StepSpan, Violation, ViolationKind};
pub use window::{StepRequest, window};
pub use world::{Move, StepPlan, World};

use crate::error::InputError;
use crate::progress::Reporter;
use crate::schedule::Schedule;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Certification options.
#[derive(Clone, Debug)]
pub struct Options {
    /// Name of the schedule in the report (usually its path).
    pub name: String,
    /// Where to report how many steps are checked.
    pub progress: Reporter,
    /// Force exact sweeps everywhere (no compiled rule tables).
    pub exact: bool,
    /// Collision tolerance.
    pub epsilon: crate::geometry::Tolerance,
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
    /// schedule's length alone, `Some(0)` runs every check in one pass.
    pub range_steps: Option<usize>,
    /// Called as each range of steps ends, with its wall time (scaling
    /// studies: where the time of a parallel run went).
    pub range_done: Option<fn(&RangeDone)>,
    /// How far above the exact smallest load factor of a step's poses the
    /// reported one may lie, as a fraction of it (0: exact; see
    /// `Settings::load_factor_tolerance` in the mechanics).
    pub load_factor_tolerance: f64,
    /// A meta-module schedule is certified at the meta-module level only
    /// ([`meta_check`]), not expanded into atom operations.
    pub meta_level: bool,
    /// Check only these steps (`--steps`), replaying the ones before them
    /// without checks; `None` checks every step.
    pub steps: Option<StepRequest>,
}

/// A range of steps that has been checked, and how long it took.
#[derive(Clone, Debug)]
pub struct RangeDone {
    /// Its index among the schedule's ranges.
    pub index: usize,
    /// Its first and last step (1-based, inclusive).
    pub steps: (usize, usize),
    /// Wall time, in seconds.
    pub seconds: f64,
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
            progress: Reporter::silent(),
            exact: false,
            epsilon: crate::geometry::Tolerance::DEFAULT,
            lattice_only: false,
            model: None,
            base_dir: None,
            range_steps: None,
            range_done: None,
            load_factor_tolerance: 0.0,
            meta_level: false,
            steps: None,
        }
    }
}

/// What a check sees of one step: the scene before it and the step's moves.
pub struct StepContext<'a> {
    pub world: &'a World,
    pub plan: &'a StepPlan,
}

/// Findings of the checks on one step.
#[derive(Debug, Default, serde::Serialize, serde::Deserialize)]
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

/// Ranges a schedule's ranged checks are split into by default: enough
/// that handing them out costliest first balances 16 workers (a range is
/// then at most a few per cent of the work), few enough that the scenes
/// kept at their starts stay small beside the structure.
const RANGES: usize = 64;

/// Steps per range for `steps` steps: about [`RANGES`] ranges of at least
/// 16 steps, whatever the number of threads. A ranged check starts each
/// range afresh (the mechanics solves its first step from scratch and
/// reuses factors after), so its floating-point results depend on where
/// ranges start: tying the boundaries to the schedule alone makes the
/// report the same bytes on 1 thread or 16. Short schedules (under 64
/// steps) run in one pass.
fn range_steps(opts: &Options, steps: usize) -> usize {
    opts.range_steps
        .unwrap_or_else(|| default_range_steps(steps))
}

/// The default steps per range (`Options::range_steps`) for a schedule of
/// `steps` steps (0: one pass), for other replays split the same way (the
/// b-study's).
pub fn default_range_steps(steps: usize) -> usize {
    if steps < 64 {
        0
    } else {
        steps.div_ceil(RANGES).max(16)
    }
}

/// The checks that apply to a schedule: the lattice checks always, the
/// collision check where the lattice has a body model, the mechanics check
/// where a physical model is given (by the user or the schedule).
pub fn checks_for(
    schedule: &Schedule,
    opts: &Options,
) -> Result<Vec<Box<dyn StepCheck>>, InputError> {
    let mut checks = geometric_checks(schedule, opts);
    if opts.lattice_only {
        return Ok(checks);
    }
    if let Some(path) = model_path(schedule, opts) {
        let model = crate::mechanics::Model::load(&path)?;
        // The model loaded; only its rescaling to the schedule's spacing
        // fails, so the error is the schedule's (its file is the caller's
        // to add) and names the model in its message.
        let check = LoadCheck::new(&model, schedule.spacing.metres(), true).map_err(|e| {
            InputError::new(format!(
                "the schedule's spacing does not fit the model {}: {}",
                path.display(),
                e.message
            ))
        })?;
        checks.push(Box::new(
            check.with_load_factor_tolerance(opts.load_factor_tolerance),
        ));
    }
    Ok(checks)
}

/// The checks of `schedule` that need no physical model: the lattice's,
/// and unless `opts` asks for the lattice only, the sweeps and dockings.
fn geometric_checks(schedule: &Schedule, opts: &Options) -> Vec<Box<dyn StepCheck>> {
    let mut checks: Vec<Box<dyn StepCheck>> = vec![Box::new(LatticeCheck)];
    if opts.lattice_only {
        return checks;
    }
    if let Some(model) = crate::geometry::sweep_model(schedule.lattice) {
        checks.push(Box::new(CollisionCheck {
            model,
            epsilon: opts.epsilon,
            exact: opts.exact,
        }));
    }
    let docks = schedule
        .steps
        .iter()
        .flat_map(|s| &s.events)
        .any(|e| matches!(e, crate::schedule::Event::Dock { .. }));
    if docks {
        checks.push(Box::new(DockingCheck {
            epsilon: opts.epsilon,
        }));
    }
    checks
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
    certify_by(schedule, opts, &Threads)
}

/// [`certify`], with the ranged checks' ranges run by `runner`.
pub fn certify_by(
    schedule: &Schedule,
    opts: &Options,
    runner: &dyn RangeRunner,
) -> Result<Report, InputError> {
    if opts.steps.is_some() && (schedule.atoms.is_some() || schedule.meta_modules.is_some()) {
        return Err(InputError::new(
            "--steps applies to schedules of modules; atom and meta-module schedules (seed 004) are certified whole",
        ));
    }
    if let Some(rest) = schedule.atoms {
        return atom_check::certify_atoms(schedule, rest, opts);
    }
    if opts.meta_level {
        if schedule.meta_modules.is_none() {
            return Err(InputError::new(
                "--meta-level certifies meta-module schedules (`meta_modules` set) only",
            ));
        }
        return meta_check::certify_meta_level(schedule, opts);
    }
    if let Some(rest) = schedule.meta_modules {
        let atoms = crate::geometry::atom_expand::expand(schedule, rest)?;
        return atom_check::certify_atoms(&atoms, rest, opts);
    }
    let checks = checks_for(schedule, opts)?;
    let refs: Vec<&dyn StepCheck> = checks.iter().map(|c| c.as_ref()).collect();
    let mut report = certify_on(schedule, opts, &refs, runner)?;
    if !opts.lattice_only && !checks.iter().any(|c| c.name() == load_check::NAME) {
        report.checks.push(MECHANICS_NOT_RUN.to_string());
    }
    Ok(report)
}

/// Certifies `schedule` with every check, the mechanics under `model` (a
/// model in memory, e.g. with a study's pressure override) rather than a
/// model file. Lattice-only options and atom schedules are certified as
/// [`certify`] does, without `model`.
pub fn certify_with_model(
    schedule: &Schedule,
    opts: &Options,
    model: &crate::mechanics::Model,
) -> Result<Report, InputError> {
    if opts.lattice_only || schedule.atoms.is_some() || schedule.meta_modules.is_some() {
        return certify(schedule, opts);
    }
    let mut checks = geometric_checks(schedule, opts);
    checks.push(Box::new(
        LoadCheck::new(model, schedule.spacing.metres(), true)?
            .with_load_factor_tolerance(opts.load_factor_tolerance),
    ));
    let refs: Vec<&dyn StepCheck> = checks.iter().map(|c| c.as_ref()).collect();
    certify_on(schedule, opts, &refs, &Threads)
}

/// Certifies `schedule` with the given checks. Input errors (not a schedule
/// this lattice can execute) abort; violations are collected in the report.
///
/// One pass replays the schedule with the lattice-level and other inline
/// checks, stopping at a step that cannot be applied; the costly ranged
/// checks then run over ranges of that pass, each range from the scene the
/// pass recorded at its first step, in parallel on this process's threads.
pub fn certify_with(
    schedule: &Schedule,
    opts: &Options,
    checks: &[&dyn StepCheck],
) -> Result<Report, InputError> {
    certify_on(schedule, opts, checks, &Threads)
}

/// [`certify_with`], with the ranges run by `runner` (another process
/// layout, e.g. MPI in the binary). Every runner gives the same report:
/// the ranges and their order are the schedule's, not the runner's.
pub fn certify_on(
    schedule: &Schedule,
    opts: &Options,
    checks: &[&dyn StepCheck],
    runner: &dyn RangeRunner,
) -> Result<Report, InputError> {
    let mut world = World::initial(schedule)?;
    let n = schedule.steps.len();
    let window = opts.steps.map(|r| r.within(n)).transpose()?.flatten();
    // 0-based steps `from..to` are checked.
    let (from, to) = window.map_or((0, n), |w| (w.first - 1, w.last));
    let range = range_steps(opts, to - from);
    let (ranged, inline): (Vec<&dyn StepCheck>, Vec<&dyn StepCheck>) = checks
        .iter()
        .copied()
        .partition(|c| range > 0 && c.ranged());
    let mut report = empty_report(schedule, opts, checks);
    report.window = window;
    let passes = if ranged.is_empty() { 1 } else { 2 };
    let bar = &opts.progress;
    bar.start("certifying", (passes * (to - from)) as u64);

    if !replay_to(&mut world, schedule, from, &mut report)? {
        bar.finish();
        return Ok(report);
    }
    let range_len = if ranged.is_empty() { 0 } else { range };
    let steps = from..to;
    let starts = one_pass(
        &mut world,
        schedule,
        steps,
        &inline,
        range_len,
        &mut report,
        bar,
    )?;
    if !ranged.is_empty() {
        let jobs = Ranges {
            schedule,
            checks: &ranged,
            starts: &starts,
            range,
            last: from + report.per_step.len(),
            bar,
            done: opts.range_done,
        };
        let mut outcomes = runner.run(&jobs)?;
        outcomes.sort_by_key(|(k, _)| *k);
        merge(&mut report, from, outcomes);
    }
    bar.finish();

    if report.stopped_at.is_none() && to == n {
        final_checks(&mut world, n + 1, checks, &mut report);
    }
    report.certified = report.violations.is_empty() && report.stopped_at.is_none();
    Ok(report)
}

/// The ranged checks' work: ranges of consecutive steps, each independent
/// of the others once the scene at its first step is known.
pub struct Ranges<'a> {
    schedule: &'a Schedule,
    checks: &'a [&'a dyn StepCheck],
    starts: &'a [(usize, World)],
    range: usize,
    last: usize,
    bar: &'a Reporter,
    done: Option<fn(&RangeDone)>,
}

impl Ranges<'_> {
    /// How many ranges there are (some may lie past a stop and be empty).
    pub fn count(&self) -> usize {
        self.starts.len()
    }

    /// The order ranges are handed out in: the last first, since
    /// structures grow over a schedule and late ranges cost the most; the
    /// cheap early ones then fill the gaps at the end (longest job first
    /// balances workers).
    pub fn order(&self) -> Vec<usize> {
        (0..self.count()).rev().collect()
    }

    /// Every step's findings, in step order, from the ranges' results
    /// ([`jobs::Done`], as any runner returns them); the first error in
    /// step order if a range failed.
    pub fn findings(
        &self,
        done: jobs::Done<Vec<(usize, StepOutcome)>>,
    ) -> Result<Vec<(usize, StepOutcome)>, InputError> {
        Ok(jobs::in_order(done, self.count())?
            .into_iter()
            .flatten()
            .collect())
    }

    /// Runs range `i` (0-based): every step's findings, as (0-based step,
    /// outcome), in step order.
    pub fn run(&self, i: usize) -> Result<Vec<(usize, StepOutcome)>, InputError> {
        let (first, start) = &self.starts[i];
        let mut found = Vec::new();
        if *first >= self.last {
            return Ok(found);
        }
        let checks: Vec<Box<dyn StepCheck>> = self
            .checks
            .iter()
            .map(|c| c.for_range().expect("a ranged check makes range instances"))
            .collect();
        let clock = std::time::Instant::now();
        let mut world = start.clone();
        let end = (first + self.range).min(self.last);
        for k in *first..end {
            let (out, _, _) = advance(&mut world, self.schedule, k, |ctx| {
                let mut out = StepOutcome::default();
                for c in &checks {
                    c.check(ctx, &mut out);
                }
                out
            })?;
            found.push((k, out));
            self.bar.advance(1);
        }
        if let Some(done) = self.done {
            done(&RangeDone {
                index: i,
                steps: (first + 1, end),
                seconds: clock.elapsed().as_secs_f64(),
            });
        }
        Ok(found)
    }
}

/// Runs [`Ranges`] somewhere and returns all their findings (any order).
pub trait RangeRunner {
    fn run(&self, ranges: &Ranges<'_>) -> Result<Vec<(usize, StepOutcome)>, InputError>;
}

/// Runs the ranges on this process's threads (rayon), in
/// [`Ranges::order`].
pub struct Threads;

impl RangeRunner for Threads {
    fn run(&self, ranges: &Ranges<'_>) -> Result<Vec<(usize, StepOutcome)>, InputError> {
        ranges.findings(jobs::on_threads(&ranges.order(), &|i| ranges.run(i)))
    }
}

/// Replays the first `steps` steps (0-based) without checks, up to the
/// first that leaves two modules in one cell: that step and its clashes,
/// if one does. The lattice replay the window schedule and `--steps`
/// share.
pub(crate) fn replay_unchecked(
    world: &mut World,
    schedule: &Schedule,
    steps: usize,
) -> Result<Option<(usize, Vec<Violation>)>, InputError> {
    for k in 0..steps {
        let (_, _, clashes) = advance(world, schedule, k, |_| ())?;
        if !clashes.is_empty() {
            return Ok(Some((k, clashes)));
        }
    }
    Ok(None)
}

/// Brings `world` to the first step to check, `steps` (0-based; more than
/// 0 when `--steps` starts later), replaying the steps before it without
/// checks. A clash on the way stops the replay, reported. The
/// configuration reached must then stand on its own: the initial one, or
/// the one after unchecked steps, which cannot vouch for it (nor be taken
/// to keep it anchored, which the connectivity search's shortcut relies
/// on). Returns whether the replay reached the first step to check.
fn replay_to(
    world: &mut World,
    schedule: &Schedule,
    steps: usize,
    report: &mut Report,
) -> Result<bool, InputError> {
    if let Some((k, clashes)) = replay_unchecked(world, schedule, steps)? {
        report.violations.extend(clashes);
        report.stopped_at = Some(k + 1);
        return Ok(false);
    }
    let loose = world.check_anchored();
    if !loose.is_empty() {
        let which = match steps {
            0 => "initial configuration".to_string(),
            _ => format!("configuration after step {steps}, where --steps starts,"),
        };
        report.violations.push(disconnected(steps, &which, loose));
    }
    Ok(true)
}

/// A report with its header filled in and nothing found yet.
fn empty_report(schedule: &Schedule, opts: &Options, checks: &[&dyn StepCheck]) -> Report {
    Report {
        format: report::REPORT_FORMAT.to_string(),
        version: 1,
        schedule: opts.name.clone(),
        lattice: schedule.lattice,
        modules: schedule.modules.len(),
        final_modules: schedule.final_module_count(),
        steps: schedule.steps.len(),
        moves: schedule.move_count(),
        window: None,
        checks: checks.iter().map(|c| c.name().to_string()).collect(),
        load_factor_tolerance: opts.load_factor_tolerance,
        certified: false,
        stopped_at: None,
        violations: Vec::new(),
        warnings: Vec::new(),
        per_step: Vec::with_capacity(schedule.steps.len()),
    }
}

/// The violation of a configuration (`which`: "initial configuration", …) with
/// modules not connected to the ground.
fn disconnected(step: usize, which: &str, loose: Vec<crate::lattice::ModuleId>) -> Violation {
    Violation::new(
        ViolationKind::Disconnected,
        step,
        format!(
            "the {which} has {} module(s) not connected to the ground",
            loose.len()
        ),
    )
    .modules(loose)
}

/// Replays every step with the `inline` checks, recording each step's
/// result in `report`, until a step cannot be applied (two modules ending
/// in one cell). Returns the scene at the first step of every range of
/// `range` steps (none when `range` is 0).
fn one_pass(
    world: &mut World,
    schedule: &Schedule,
    steps: std::ops::Range<usize>,
    inline: &[&dyn StepCheck],
    range: usize,
    report: &mut Report,
    bar: &Reporter,
) -> Result<Vec<(usize, World)>, InputError> {
    let mut starts = Vec::new();
    for k in steps.clone() {
        let index = k + 1;
        if range > 0 && (k - steps.start).is_multiple_of(range) {
            starts.push((k, world.clone()));
        }
        let (mut out, plan, clashes) = advance(world, schedule, k, |ctx| {
            let mut out = StepOutcome::of_plan(ctx.plan);
            for c in inline {
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
        if lattice_clean && plan.detaches.is_empty() && !tunnels {
            world.confirm_anchored();
        }
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
        bar.advance(1);
        if stop {
            report.stopped_at = Some(index);
            break;
        }
    }
    Ok(starts)
}

/// Merges the ranged checks' findings (0-based step, outcome) into the
/// report, whose results start at step `from` (0-based), then puts the
/// findings back in step order, each step's own in check order.
fn merge(report: &mut Report, from: usize, outcomes: Vec<(usize, StepOutcome)>) {
    for (k, out) in outcomes {
        let r = &mut report.per_step[k - from];
        r.violations += out.violations.len();
        r.warnings += out.warnings.len();
        r.metrics.extend(out.metrics);
        report.violations.extend(out.violations);
        report.warnings.extend(out.warnings);
    }
    report.violations.sort_by_key(|v| v.step);
    report.warnings.sort_by_key(|v| v.step);
}

/// The final configuration: connected, and whatever each check asks of it.
fn final_checks(
    world: &mut World,
    final_step: usize,
    checks: &[&dyn StepCheck],
    report: &mut Report,
) {
    let loose = world.check_anchored();
    if !loose.is_empty() {
        report
            .violations
            .push(disconnected(final_step, "final configuration", loose));
    }
    let mut out = StepOutcome::default();
    for c in checks {
        // A ranged check's own instance saw no step: it analyses the
        // final scene from scratch.
        c.check_final(world, final_step, &mut out);
    }
    report.violations.extend(out.violations);
    report.warnings.extend(out.warnings);
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

    /// A model whose numbers were made in code, not read and validated:
    /// whatever turns non-finite, the load check must not certify.
    #[test]
    fn non_finite_model_numbers_never_certify_a_structure() {
        use crate::mechanics::Model;
        let s = crate::algorithms::branch::branch_schedule(3, 3.6).unwrap();
        type Edit = (&'static str, fn(&mut Model));
        let edits: [Edit; 6] = [
            ("mass NaN", |m| {
                m.density = None;
                m.mass = f64::NAN
            }),
            ("mass ∞", |m| {
                m.density = None;
                m.mass = f64::INFINITY
            }),
            ("gravity NaN", |m| m.gravity = f64::NAN),
            ("gravity ∞", |m| m.gravity = f64::INFINITY),
            ("pressure NaN", |m| m.connector.pressure = f64::NAN),
            ("friction NaN", |m| m.connector.friction = f64::NAN),
        ];
        for (what, edit) in edits {
            let mut m = Model::default_catom();
            edit(&mut m);
            // Refused at the boundary …
            assert!(
                LoadCheck::new(&m, s.spacing.metres(), true).is_err(),
                "{what}: accepted"
            );
            // … and, were it to get past, never certified.
            let check = LoadCheck::unvalidated(m.at_spacing(s.spacing.metres()));
            let r = certify_with(&s, &Options::default(), &[&LatticeCheck, &check]).unwrap();
            assert!(!r.certified, "{what}: certified");
            assert!(
                r.violations.iter().any(|v| v.kind == ViolationKind::Overload
                    || v.kind == ViolationKind::Unstable),
                "{what}: {:?}",
                r.violations
            );
        }
    }

    #[test]
    fn a_non_finite_utilisation_is_overloaded_and_ranks_above_every_finite_one() {
        use crate::mechanics::capacity::{overloaded, severity};
        for u in [f64::NAN, f64::INFINITY, -f64::INFINITY, 1.0 + 1e-6] {
            assert!(overloaded(u), "{u}");
        }
        for u in [0.0, 0.5, 1.0, 1.0 + 1e-10] {
            assert!(!overloaded(u), "{u}");
        }
        assert!(severity(f64::NAN) > severity(1e300));
    }

    /// The report of a schedule with the mechanics is the same bytes on
    /// one thread and on several (range boundaries do not follow the
    /// thread count).
    #[test]
    fn the_report_does_not_depend_on_the_number_of_threads() {
        let scenario =
            crate::scenario::Scenario::load(&crate::scenario::Scenario::default_path()).unwrap();
        let s = crate::algorithms::generate(&scenario).unwrap();
        let opts = Options {
            base_dir: Some(scenario.dir.clone()),
            ..Options::default()
        };
        let on = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| certify(&s, &opts).unwrap().to_json())
        };
        let one = on(1);
        assert!(one.contains("max_utilisation"), "the mechanics ran");
        // Not assert_eq: the reports are long; the point is equality.
        assert!(one == on(2), "1 and 2 threads give different reports");
        assert!(one == on(3), "1 and 3 threads give different reports");
    }
}
