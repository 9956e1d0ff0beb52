//! Gravity stability and connector loads (SPEC §4.5) of every intermediate
//! structure: the static modules of the step plus its movers hanging on
//! their pivots, through [`crate::mechanics`].
//!
//! Work is reused between consecutive steps: the analyser keeps the
//! previous step's solution of every connected component, re-solves only
//! the components the step changed, and warm-starts those from the
//! displacements of their modules in the previous step.

use super::report::{Severity, Violation, ViolationKind};
use super::{StepCheck, StepContext, StepOutcome, World};
use crate::error::InputError;
use crate::lattice::config::ModuleId;
use crate::mechanics::analysis::{Analysis, Critical, Settings, Verdict};
use crate::mechanics::structure::{End, MoverSpec, SceneRef, Structure};
use crate::mechanics::{Analyzer, Model};
use rustc_hash::FxHashSet;
use std::sync::Mutex;

/// Name of the check in reports.
pub const NAME: &str = "mechanics";

/// The mechanical check of every step.
pub struct LoadCheck {
    analyzer: Mutex<Analyzer>,
    /// The model at the schedule's spacing, and whether to reuse work.
    model: Model,
    incremental: bool,
    /// [`crate::mechanics::analysis::Settings::load_factor_tolerance`] of
    /// every analyser it makes.
    load_factor_tolerance: f64,
    /// `Settings::superpose` of every analyser it makes.
    superpose: bool,
}

impl LoadCheck {
    /// A check with `model` at the schedule's lattice spacing `spacing` (m),
    /// refused where the rescaled model loses the physics (a mass that
    /// underflows, a capacity that overflows).
    pub fn new(model: &Model, spacing: f64, incremental: bool) -> Result<LoadCheck, InputError> {
        Ok(LoadCheck::at_spacing(
            model.at_spacing_checked(spacing)?,
            incremental,
        ))
    }

    /// A check with a model that skipped validation: for the tests that
    /// prove a non-finite number still never certifies.
    #[cfg(test)]
    pub(crate) fn unvalidated(model: Model) -> LoadCheck {
        LoadCheck::at_spacing(model, true)
    }

    /// A check with `model` already at the schedule's spacing, and a fresh
    /// analyser.
    fn at_spacing(model: Model, incremental: bool) -> LoadCheck {
        LoadCheck {
            analyzer: Mutex::new(Analyzer::new(model.clone(), incremental)),
            model,
            incremental,
            load_factor_tolerance: 0.0,
            superpose: true,
        }
    }

    /// The settings of this check's own analyser (not yet shared).
    fn settings_mut(&mut self) -> &mut Settings {
        &mut self.analyzer.get_mut().expect("a fresh analyser").settings
    }

    /// This check with the poses superposed (the certifier's setting) or
    /// every sampled pose solved alone (see `Settings::superpose`): the
    /// poses between samples then go unjudged, for the tests that compare
    /// the two and see the report say so.
    fn with_superpose(mut self, on: bool) -> LoadCheck {
        self.superpose = on;
        self.settings_mut().superpose = on;
        self
    }

    /// This check with the limit analysis's factor reported within
    /// `tolerance` of the exact one (see
    /// `Settings::load_factor_tolerance` in the mechanics);
    /// 0 is exact.
    pub fn with_load_factor_tolerance(mut self, tolerance: f64) -> LoadCheck {
        self.load_factor_tolerance = tolerance;
        self.settings_mut().load_factor_tolerance = tolerance;
        self
    }

    /// This check with the limit analysis off (see
    /// `Settings::limit_analysis` in the mechanics): components the
    /// elastic screen cannot clear are bounded, not proved. Not for
    /// certification: for a study that then proves the steps that matter.
    fn without_limit_analysis(self) -> LoadCheck {
        self.analyzer
            .lock()
            .expect("analyser lock")
            .settings
            .limit_analysis = false;
        self
    }

    fn analyse(
        &self,
        world: &World,
        exclude: &FxHashSet<ModuleId>,
        movers: &[MoverSpec],
    ) -> (Structure, Analysis) {
        let scene = SceneRef {
            lattice: world.lattice(),
            ground: world.ground(),
            config: world.config(),
            fixed: world.fixed(),
            exclude,
            latched: &|a, b| world.latched(a, b),
        };
        let s = Structure::build(&scene, movers);
        let a = self.analyzer.lock().expect("analyser lock").analyse(&s);
        (s, a)
    }

    /// Step `step` (1-based) at the start of `ctx`: its lattice findings
    /// and the mechanics of its structure, movers hanging, for `visit`.
    fn visit_step<T>(
        &self,
        ctx: &StepContext<'_>,
        step: usize,
        visit: impl FnOnce(usize, &Structure, &Analysis, &StepOutcome) -> T,
    ) -> T {
        let mut out = StepOutcome::of_plan(ctx.plan);
        super::LatticeCheck.check(ctx, &mut out);
        let movers: Vec<MoverSpec> = ctx.plan.resolved_moves();
        let (s, a) = self.analyse(ctx.world, &ctx.plan.moving, &movers);
        visit(step, &s, &a, &out)
    }

    /// The final configuration `world`, reported as step `step`, for
    /// `visit`.
    fn visit_final<T>(
        &self,
        world: &World,
        step: usize,
        visit: impl FnOnce(usize, &Structure, &Analysis, &StepOutcome) -> T,
    ) -> T {
        let (s, a) = self.analyse(world, &FxHashSet::default(), &[]);
        visit(step, &s, &a, &StepOutcome::default())
    }
}

/// How far outside its support polygon (in units of `d`) a component's
/// weight must act for an `unstable` violation to say that it tips: below
/// it, the rigid failure is not told by the weight's position (a failed
/// solve, or a weight on the hull's edge).
const TIPPING_TOL: f64 = 1e-9;

/// The links of a collapse mechanism a violation lists, largest share
/// first (the count of all of them is a detail of its own).
const MECHANISM_LISTED: usize = 10;

/// Describes the critical element of an analysis as a violation detail.
pub fn critical_violation(
    kind: ViolationKind,
    step: usize,
    what: &str,
    s: &Structure,
    a: &Analysis,
) -> Violation {
    let overloaded = a
        .links
        .iter()
        .filter(|r| crate::mechanics::capacity::overloaded(r.utilisation))
        .count()
        + a.pivots
            .iter()
            .filter(|r| crate::mechanics::capacity::overloaded(r.utilisation))
            .count();
    let mut v = match a.critical {
        Some(Critical::Link(i)) => {
            let l = &s.links[i];
            let r = &a.links[i];
            let mut modules = vec![s.bodies[l.a].module];
            let mut cells = vec![s.bodies[l.a].cell];
            match l.b {
                End::Body(b) => {
                    modules.push(s.bodies[b].module);
                    cells.push(s.bodies[b].cell);
                }
                End::Ground(c) => cells.push(c),
            }
            // A limit-analysis failure names the link its collapse
            // mechanism works hardest, with that link's share of the work.
            let mechanism = a.mechanism.as_ref().and_then(|m| {
                let share = m.links.iter().find(|(li, _)| *li == i)?.1;
                Some((m, share))
            });
            let message = match mechanism {
                Some((m, share)) => format!(
                    "{what}: its collapse mechanism works the {} hardest \
                     ({:.0} % of the work it dissipates; {} connector(s) take 1 % or more)",
                    s.describe(l),
                    100.0 * share,
                    m.links.iter().filter(|x| x.1 >= 0.01).count()
                ),
                None => format!(
                    "{what}: most loaded is the {} at utilisation {:.3} ({})",
                    s.describe(l),
                    r.utilisation,
                    r.mode.map(|m| m.name()).unwrap_or("-")
                ),
            };
            let mut v = Violation::new(kind, step, message)
                .modules(modules)
                .cells(cells)
                .detail("connector", s.describe(l));
            if let Some((m, share)) = mechanism {
                let listed: Vec<serde_json::Value> = m
                    .links
                    .iter()
                    .take(MECHANISM_LISTED)
                    .map(|&(li, share)| {
                        serde_json::json!({
                            "connector": s.describe(&s.links[li]),
                            "share": share,
                        })
                    })
                    .collect();
                v = v
                    .detail("share", share)
                    .detail("mechanism", listed)
                    .detail("mechanism_connectors", m.links.len());
            }
            // The elastic estimate's figures, except where the screen left
            // the component to the limit analysis without a witness for
            // this link (zeros, not loads).
            if mechanism.is_none() || r.mode.is_some() {
                v = v
                    .detail("utilisation", r.utilisation)
                    .detail("mode", r.mode.map(|m| m.name()))
                    .detail("load", r.load);
            }
            v
        }
        Some(Critical::Pivot(i)) => {
            let p = &a.pivots[i];
            let h = &s.hanging[p.hanging];
            let pivot = &s.bodies[h.pivot];
            Violation::new(
                kind,
                step,
                format!(
                    "{what}: mover {} on its pivot {} at utilisation {:.3} ({}, s = {:.2})",
                    h.mover,
                    pivot.module,
                    p.utilisation,
                    p.mode.name(),
                    p.s
                ),
            )
            .modules([h.mover, pivot.module])
            .cells([pivot.cell])
            .detail(
                "connector",
                format!("pivot connector {}–{}", h.mover, pivot.module),
            )
            .detail("utilisation", p.utilisation)
            .detail("mode", p.mode.name())
            .detail("s", p.s)
            .detail("load", p.load)
        }
        None => Violation::new(kind, step, what.to_string()),
    };
    v = v.detail("overloaded_connectors", overloaded);
    v
}

fn report(step: usize, s: &Structure, a: &Analysis, out: &mut StepOutcome) {
    if let Some(note) = judged_at_samples(step, a) {
        out.warnings.push(note);
    }
    out.metrics
        .insert("max_utilisation".into(), a.max_utilisation);
    if !a.pivots.is_empty() {
        out.metrics
            .insert("hold_utilisation".into(), a.hold_utilisation);
    }
    if let Some(lf) = a.load_factor.filter(|x| x.is_finite()) {
        out.metrics.insert("load_factor".into(), lf);
    }
    // With a tolerance, what is proven of the exact factor: it lies
    // between this and `load_factor`.
    if let Some(lower) = a.load_factor_lower.filter(|x| x.is_finite()) {
        out.metrics.insert("load_factor_lower_bound".into(), lower);
    }
    // Where the limit analysis judged, its load factor says by how much.
    let at_most = if a.load_factor_partial {
        "at most "
    } else {
        ""
    };
    let limit = |what: &str| match a.load_factor {
        Some(lf) if lf.is_finite() => {
            format!("{what} (limit analysis: load factor {at_most}{lf:.3})")
        }
        Some(_) => format!("{what} (limit analysis failed to solve: not certified)"),
        None => what.to_string(),
    };
    match a.verdict() {
        Verdict::Stable => {}
        Verdict::Overloaded => {
            let v = critical_violation(
                ViolationKind::Overload,
                step,
                &limit("connector overloaded"),
                s,
                a,
            );
            out.violations.push(match a.load_factor {
                Some(lf) if lf.is_finite() && a.load_factor_partial => v
                    .detail("load_factor", lf)
                    .detail("load_factor_is_upper_bound", true),
                Some(lf) if lf.is_finite() => v.detail("load_factor", lf),
                _ => v,
            });
        }
        Verdict::NoEquilibrium => {
            let loose: Vec<ModuleId> = a.unsupported.iter().map(|&b| s.bodies[b].module).collect();
            let what = if loose.is_empty() {
                "no static equilibrium: a ground contact slides".to_string()
            } else {
                format!(
                    "no static equilibrium: {} module(s) tip over, slide or are unsupported",
                    loose.len()
                )
            };
            // Tipping: the weight passes outside the support polygon. The
            // witness replaces the critical element, which the rigid
            // failure does not involve (a mover's hold, say).
            let tipping = a.tipping.as_ref().filter(|t| t.outside > TIPPING_TOL);
            let mut v = match tipping {
                Some(t) => {
                    let p = t.weight_at_ground;
                    Violation::new(
                        ViolationKind::Unstable,
                        step,
                        limit(&format!(
                            "no static equilibrium: {} module(s) tip over: their weight acts at \
                             ({:.2}, {:.2}, {:.2}) d at ground level, {:.3} d outside the convex \
                             hull of their {} ground contact(s)",
                            loose.len(),
                            p.x,
                            p.y,
                            p.z,
                            t.outside,
                            t.contacts
                        )),
                    )
                    .detail("weight_at_ground", [p.x, p.y, p.z])
                    .detail("outside_support_d", t.outside)
                    .detail("ground_contacts", t.contacts)
                }
                None => critical_violation(ViolationKind::Unstable, step, &limit(&what), s, a),
            };
            v.modules.extend(loose.iter().take(50));
            out.violations
                .push(v.detail("unsupported_modules", loose.len()));
        }
    }
}

/// The note of a step whose analysis judged some component at the sampled
/// poses alone (`Analysis::sampled_only`): the certificate then holds at
/// those poses, not between them, and the report says so rather than
/// passing the gap over in silence.
fn judged_at_samples(step: usize, a: &Analysis) -> Option<Violation> {
    let first = *a.sampled_only.iter().min()?;
    let n = a.sampled_only.len();
    Some(
        Violation::new(
            ViolationKind::JudgedAtSamples,
            step,
            format!(
                "mechanics judged {n} component(s) at the sampled poses of the movers' sweeps only, not between them ({})",
                first.describe()
            ),
        )
        .severity(Severity::Note)
        .detail("components", n),
    )
}

impl StepCheck for LoadCheck {
    fn name(&self) -> &'static str {
        NAME
    }

    fn check(&self, ctx: &StepContext<'_>, out: &mut StepOutcome) {
        let movers: Vec<MoverSpec> = ctx.plan.resolved_moves();
        let (s, a) = self.analyse(ctx.world, &ctx.plan.moving, &movers);
        report(ctx.plan.step, &s, &a, out);
    }

    fn check_final(&self, world: &World, step: usize, out: &mut StepOutcome) {
        let (s, a) = self.analyse(world, &FxHashSet::default(), &[]);
        report(step, &s, &a, out);
    }

    /// Every step's analysis dominates certification of a large schedule,
    /// so ranges of steps run in parallel, each with its own analyser: the
    /// reuse between steps is lost only at a range's first step.
    fn for_range(&self) -> Option<Box<dyn StepCheck>> {
        Some(Box::new(
            LoadCheck::at_spacing(self.model.clone(), self.incremental)
                .with_load_factor_tolerance(self.load_factor_tolerance)
                .with_superpose(self.superpose),
        ))
    }

    fn ranged(&self) -> bool {
        true
    }
}

/// Replays `schedule` and analyses every intermediate structure (and the
/// final one, reported as step `steps + 1`), handing each to `visit` with
/// the step's lattice-check findings. Used by the b-study, the load map and
/// the benchmarks; `incremental` selects reuse between steps.
pub fn replay(
    schedule: &crate::schedule::Schedule,
    model: &Model,
    incremental: bool,
    mut visit: impl FnMut(usize, &Structure, &Analysis, &StepOutcome),
) -> Result<(), crate::error::InputError> {
    let check = LoadCheck::new(model, schedule.spacing.metres(), incremental)?;
    let mut world = World::initial(schedule)?;
    for k in 0..schedule.steps.len() {
        let (_, _, clashes) = super::advance(&mut world, schedule, k, |ctx| {
            check.visit_step(ctx, k + 1, &mut visit)
        })?;
        if let Some(clash) = clashes.first() {
            return Err(crate::error::InputError::new(format!(
                "step {}: {}",
                k + 1,
                clash.message
            )));
        }
    }
    check.visit_final(&world, schedule.steps.len() + 1, visit);
    Ok(())
}

/// [`replay`] split into ranges of `range` consecutive steps (0: one range)
/// that run in parallel on this process's threads, each from the scene a
/// first cheap pass recorded at its start and with its own analyser (the
/// reuse between steps restarts at each range, as in certification), with
/// the limit analysis's `load_factor_tolerance`. `visit` sees every step
/// (1-based; `steps + 1` is the final configuration) and returns what the
/// caller keeps of it; the results come back in step order. Range
/// boundaries depend on `range` alone, so the results are the same on any
/// number of threads. `tick` is called once per step analysed.
pub fn replay_ranged<T: Send>(
    schedule: &crate::schedule::Schedule,
    model: &Model,
    load_factor_tolerance: f64,
    range: usize,
    visit: impl Fn(usize, &Structure, &Analysis, &StepOutcome) -> T + Sync,
    tick: impl Fn() + Sync,
) -> Result<Vec<T>, crate::error::InputError> {
    let replay = RangedReplay::new(schedule, model, load_factor_tolerance, range)?;
    let done = super::jobs::on_threads(&replay.order(), &|job| replay.run(job, &visit, &tick));
    Ok(super::jobs::in_order(done, replay.jobs())?
        .into_iter()
        .flatten()
        .collect())
}

/// A schedule's replay cut into independent jobs, for whoever runs them
/// (this process's threads, or processes): job `i < ranges` is the range
/// of steps starting at step `i · range`, the last job the final
/// configuration. Jobs in index order are the steps in order.
pub struct RangedReplay<'a> {
    schedule: &'a crate::schedule::Schedule,
    model: Model,
    load_factor_tolerance: f64,
    range: usize,
    /// Whether [`RangedReplay::run`] runs the limit analysis (see
    /// [`RangedReplay::bounds_only`]).
    limit_analysis: bool,
    /// The scene at each range's first step (0-based step, world).
    starts: Vec<(usize, World)>,
    /// The final configuration.
    last: World,
}

impl<'a> RangedReplay<'a> {
    /// Records, in a cheap pass (lattice only), the scene at each range's
    /// start and the final one; a step whose moves clash is an error.
    pub fn new(
        schedule: &'a crate::schedule::Schedule,
        model: &Model,
        load_factor_tolerance: f64,
        range: usize,
    ) -> Result<RangedReplay<'a>, crate::error::InputError> {
        let model = model.at_spacing_checked(schedule.spacing.metres())?;
        let n = schedule.steps.len();
        let range = if range == 0 { n.max(1) } else { range };
        let mut world = World::initial(schedule)?;
        let mut starts = Vec::new();
        for k in 0..n {
            if k % range == 0 {
                starts.push((k, world.clone()));
            }
            let (_, _, clashes) = super::advance(&mut world, schedule, k, |_| ())?;
            if let Some(clash) = clashes.first() {
                return Err(crate::error::InputError::new(format!(
                    "step {}: {}",
                    k + 1,
                    clash.message
                )));
            }
        }
        Ok(RangedReplay {
            schedule,
            model,
            load_factor_tolerance,
            range,
            limit_analysis: true,
            starts,
            last: world,
        })
    }

    /// This replay with the limit analysis off in [`RangedReplay::run`]:
    /// a step's `max_utilisation` is then an upper bound where the
    /// elastic screen could not clear a component (`Analysis::bounded`),
    /// and [`RangedReplay::run_step`] proves the steps that matter.
    pub fn bounds_only(mut self) -> RangedReplay<'a> {
        self.limit_analysis = false;
        self
    }

    /// Step `step` alone (1-based; the number of steps + 1 is the final
    /// configuration), analysed from scratch with the limit analysis on:
    /// the scene is replayed (lattice only) from the start of its range.
    pub fn run_step<T>(
        &self,
        step: usize,
        visit: &(dyn Fn(usize, &Structure, &Analysis, &StepOutcome) -> T + Sync),
    ) -> Result<T, crate::error::InputError> {
        let check = LoadCheck::at_spacing(self.model.clone(), false)
            .with_load_factor_tolerance(self.load_factor_tolerance);
        self.step_with(&check, step, visit)
    }

    /// Step `step` alone as [`RangedReplay::run_step`], with the limit
    /// analysis off and each bound of `1/λ` tightened by a region's limit
    /// analysis of `hops` links until one stays above `until`
    /// (`Settings::region_hops`, `region_until` in the mechanics): whether
    /// the step can exceed `until`, at a fraction of a judgement's cost.
    pub fn bound_step<T>(
        &self,
        step: usize,
        hops: usize,
        until: f64,
        visit: &(dyn Fn(usize, &Structure, &Analysis, &StepOutcome) -> T + Sync),
    ) -> Result<T, crate::error::InputError> {
        let check = LoadCheck::at_spacing(self.model.clone(), false)
            .with_load_factor_tolerance(self.load_factor_tolerance)
            .without_limit_analysis();
        {
            let mut analyzer = check.analyzer.lock().expect("analyser lock");
            analyzer.settings.region_hops = hops;
            analyzer.settings.region_until = until;
        }
        self.step_with(&check, step, visit)
    }

    fn step_with<T>(
        &self,
        check: &LoadCheck,
        step: usize,
        visit: &(dyn Fn(usize, &Structure, &Analysis, &StepOutcome) -> T + Sync),
    ) -> Result<T, crate::error::InputError> {
        let n = self.schedule.steps.len();
        if step == n + 1 {
            return Ok(check.visit_final(&self.last, step, visit));
        }
        let k = step
            .checked_sub(1)
            .filter(|&k| k < n)
            .ok_or_else(|| crate::error::InputError::new(format!("no step {step} to analyse")))?;
        let (first, start) = &self.starts[k / self.range];
        let mut w = start.clone();
        for j in *first..k {
            super::advance(&mut w, self.schedule, j, |_| ())?;
        }
        let (seen, _, _) = super::advance(&mut w, self.schedule, k, |ctx| {
            check.visit_step(ctx, step, visit)
        })?;
        Ok(seen)
    }

    /// How many jobs: the ranges and the final configuration.
    pub fn jobs(&self) -> usize {
        self.starts.len() + 1
    }

    /// The first step of job `job` (0-based; the final configuration's is
    /// the number of steps): later steps have larger structures.
    pub fn first_step(&self, job: usize) -> usize {
        self.starts
            .get(job)
            .map_or(self.schedule.steps.len(), |(k, _)| *k)
    }

    /// The order to hand jobs out in: the final configuration (the
    /// largest structure) first, then the ranges last first — structures
    /// grow, so the costliest go out first.
    pub fn order(&self) -> Vec<usize> {
        (0..self.jobs()).rev().collect()
    }

    /// Runs job `job` with a fresh analyser: what `visit` keeps of each of
    /// its steps, in step order (see [`replay_ranged`]).
    pub fn run<T>(
        &self,
        job: usize,
        visit: &(dyn Fn(usize, &Structure, &Analysis, &StepOutcome) -> T + Sync),
        tick: &(dyn Fn() + Sync),
    ) -> Result<Vec<T>, crate::error::InputError> {
        let mut check = LoadCheck::at_spacing(self.model.clone(), true)
            .with_load_factor_tolerance(self.load_factor_tolerance);
        if !self.limit_analysis {
            check = check.without_limit_analysis();
        }
        let n = self.schedule.steps.len();
        let Some((first, start)) = self.starts.get(job) else {
            let found = check.visit_final(&self.last, n + 1, visit);
            tick();
            return Ok(vec![found]);
        };
        let mut w = start.clone();
        let mut found = Vec::new();
        for k in *first..(first + self.range).min(n) {
            let (seen, _, _) = super::advance(&mut w, self.schedule, k, |ctx| {
                check.visit_step(ctx, k + 1, visit)
            })?;
            tick();
            found.push(seen);
        }
        Ok(found)
    }
}

/// The structure and its analysis at each of `steps` (1-based; `steps + 1`
/// of the schedule is the final configuration), in one replay that solves
/// only those steps: what a viewer needs to show a few load maps of a long
/// schedule without the cost of analysing every step.
pub fn load_maps_at(
    schedule: &crate::schedule::Schedule,
    model: &Model,
    steps: &[usize],
) -> Result<Vec<(usize, Structure, Analysis)>, crate::error::InputError> {
    let check = LoadCheck::new(model, schedule.spacing.metres(), false)?;
    let mut world = World::initial(schedule)?;
    let mut found = Vec::new();
    let last = steps.iter().copied().max().unwrap_or(0);
    for k in 0..schedule.steps.len().min(last) {
        let wanted = steps.contains(&(k + 1));
        let (seen, _, clashes) = super::advance(&mut world, schedule, k, |ctx| {
            wanted.then(|| {
                let movers: Vec<MoverSpec> = ctx.plan.resolved_moves();
                check.analyse(ctx.world, &ctx.plan.moving, &movers)
            })
        })?;
        if let Some((s, a)) = seen {
            found.push((k + 1, s, a));
        }
        if !clashes.is_empty() {
            return Ok(found);
        }
    }
    if steps.contains(&(schedule.steps.len() + 1)) {
        let (s, a) = check.analyse(&world, &FxHashSet::default(), &[]);
        found.push((schedule.steps.len() + 1, s, a));
    }
    Ok(found)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::certify::{MECHANICS_NOT_RUN, Options, certify};
    use crate::lattice::{Cell, FccLattice, Lattice, LatticeKind, Route};
    use crate::schedule::{Event, Length, ModuleSpec, Schedule, Step};
    use std::path::PathBuf;

    fn models() -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models")
    }

    /// A fixed root, a horizontal branch of `n` modules, and a free agent
    /// above the tip that rolls over it to extend the branch.
    fn branch_schedule(n: i32) -> Schedule {
        let l = FccLattice;
        let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(3.6));
        for i in 0..=n {
            s.modules.push(ModuleSpec {
                id: i as u32 + 1,
                cell: Cell::new(i, 0, 0),
                fixed: i == 0,
            });
        }
        let tip = Cell::new(n, 0, 0);
        let from = l.neighbour(tip, 4);
        let agent = n as u32 + 2;
        s.modules.push(ModuleSpec {
            id: agent,
            cell: from,
            fixed: false,
        });
        s.steps.push(Step {
            events: vec![Event::Rotate {
                module: agent,
                pivot: n as u32 + 1,
                from,
                to: l.neighbour(tip, 0),
                route: Route::Octagonal,
            }],
        });
        s
    }

    fn opts(model: Option<&str>) -> Options {
        Options {
            model: model.map(|m| models().join(m)),
            ..Default::default()
        }
    }

    /// A column of three catoms leaning one half-cell per layer, resting
    /// on one ground module: its weight (mean centre x = y = ½ d) lies past
    /// the base's lower faces (a quarter cell and half a square side out).
    fn leaning_column(mirror: bool) -> Schedule {
        let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(3.6));
        s.ground = Some(crate::lattice::config::Ground { layer: 0 });
        let cells = if mirror {
            [(0, 0, 0), (-1, -1, 1), (-1, -1, 2)]
        } else {
            [(0, 0, 0), (0, 0, 1), (1, 1, 2)]
        };
        for (i, (x, y, z)) in cells.into_iter().enumerate() {
            s.modules.push(ModuleSpec {
                id: i as u32 + 1,
                cell: Cell::new(x, y, z),
                fixed: false,
            });
        }
        s
    }

    #[test]
    fn a_leaning_column_tips_over_on_the_ground_and_stands_on_a_latched_base() {
        for mirror in [false, true] {
            let col = leaning_column(mirror);
            let r = certify(&col, &opts(Some("catom-3.6mm.toml"))).unwrap();
            let v: Vec<_> = r.violations_of(ViolationKind::Unstable).collect();
            assert_eq!(v.len(), 1, "the final configuration: {}", r.summary());
            assert!(
                v[0].message.contains("3 module(s) tip over"),
                "{}",
                v[0].message
            );
            assert!(
                v[0].message
                    .contains("outside the convex hull of their 4 ground contact(s)")
            );
            // The weight acts at the mean centre, (½, ½) d from the base's
            // centre (mirrored: (−½, −½)); the lower faces' squares reach
            // less than half a cell out, so it is outside by a margin.
            let at = &v[0].detail["weight_at_ground"];
            let sign = if mirror { -1.0 } else { 1.0 };
            for k in 0..2 {
                let x = at[k].as_f64().unwrap();
                assert!((x - sign * 0.5).abs() < 1e-9, "{at}");
            }
            let out = v[0].detail["outside_support_d"].as_f64().unwrap();
            assert!(out > 0.05 && out < 0.5, "{out}");
            let latched = certify(&col, &opts(Some("catom-3.6mm-latched-base.toml"))).unwrap();
            assert!(latched.certified, "{}", latched.summary());
        }
    }

    #[test]
    fn a_short_branch_extended_by_an_agent_is_certified_with_its_utilisation() {
        let r = certify(&branch_schedule(3), &opts(Some("catom-3.6mm.toml"))).unwrap();
        assert!(r.checks.contains(&NAME.to_string()));
        assert!(r.certified, "{}", r.summary());
        // Step 1: three modules plus the agent hanging beyond the tip:
        // (n+1)²/2 · W·d against p·L³/2 (rigid hinge).
        let m = Model::default_catom();
        let expected = crate::mechanics::closed_form::cantilever_utilisation(&m, 3, true);
        let got = r.per_step[0].metrics["max_utilisation"];
        assert!(
            (got - expected).abs() < 1e-6 * expected,
            "{got} vs {expected}"
        );
    }

    #[test]
    fn an_agent_overloading_the_root_of_a_branch_is_reported_with_the_connector() {
        // 10 kPa, elastic bending: one module holds (1 ≤ pL³/(3mgd) ≈ 1.55),
        // one module plus the agent does not (4 > 1.55).
        let r = certify(&branch_schedule(1), &opts(Some("catom-3.6mm-10kpa.toml"))).unwrap();
        assert!(!r.certified);
        let v: Vec<_> = r.violations_of(ViolationKind::Overload).collect();
        assert_eq!(v.len(), 2, "{}", r.summary()); // the step and the final structure
        assert_eq!(v[0].step, 1);
        assert_eq!(
            v[0].modules,
            vec![1, 2],
            "the root connector: {}",
            v[0].message
        );
        assert!(v[0].detail["utilisation"].as_f64().unwrap() > 1.0);
        // The limit analysis judged it: a determinate branch carries 1/u
        // times its weight, and the report says so.
        let lf = v[0].detail["load_factor"].as_f64().unwrap();
        let u = r.per_step[0].metrics["max_utilisation"];
        assert!((lf * u - 1.0).abs() < 1e-6, "λ = {lf}, u = {u}");
        assert!(
            v[0].message.contains("limit analysis: load factor"),
            "{}",
            v[0].message
        );
        assert_eq!(r.per_step[0].metrics["load_factor"], lf);
        assert!(r.per_step[0].metrics["hold_utilisation"] > 0.0);
        assert!(
            r.summary().contains(&format!(
                "lowest load_factor over the steps: {lf:.4} (step 1)"
            )),
            "{}",
            r.summary()
        );
    }

    #[test]
    fn ranges_of_steps_checked_in_parallel_give_the_results_of_one_pass() {
        use crate::algorithms::scaffold::{ShapeSpec, scaffold_schedule};
        use crate::certify::{LatticeCheck, certify_with};
        // The 2-pyramid at b = 9 is overloaded from its step 84 on.
        let s = scaffold_schedule(&ShapeSpec::Pyramid { h: 2 }, 9).unwrap();
        let model = Model::load(&models().join("catom-3.6mm.toml")).unwrap();
        let run = |range_steps| {
            let load = LoadCheck::new(&model, s.spacing.metres(), true).unwrap();
            let o = Options {
                range_steps: Some(range_steps),
                ..Default::default()
            };
            certify_with(&s, &o, &[&LatticeCheck, &load]).unwrap()
        };
        let (one, ranged) = (run(0), run(7));
        assert!(!one.certified);
        assert_eq!(one.per_step.len(), ranged.per_step.len());
        for (a, b) in one.per_step.iter().zip(&ranged.per_step) {
            let (ua, ub) = (a.metrics["max_utilisation"], b.metrics["max_utilisation"]);
            assert!(
                (ua - ub).abs() <= 1e-6 * ua.max(1e-9),
                "step {}: {ua} vs {ub}",
                a.step
            );
            assert_eq!(a.violations, b.violations, "step {}", a.step);
        }
        let key = |r: &crate::certify::Report| -> Vec<(usize, ViolationKind)> {
            r.violations.iter().map(|v| (v.step, v.kind)).collect()
        };
        assert_eq!(key(&one), key(&ranged));
        assert!(key(&one).iter().any(|&(_, k)| k == ViolationKind::Overload));
    }

    #[test]
    fn a_replay_in_ranges_matches_the_one_pass_and_does_not_depend_on_the_threads() {
        // The overloaded 2-pyramid at b = 9: elastic steps and failing
        // ones (limit analyses), in ranges of 7 steps that restart the
        // analyser's reuse.
        let s = crate::algorithms::scaffold::scaffold_schedule(
            &crate::algorithms::scaffold::ShapeSpec::Pyramid { h: 2 },
            9,
        )
        .unwrap();
        let m = Model::default_catom();
        let key = |a: &Analysis| (a.max_utilisation, a.verdict(), a.load_factor);
        let mut one = Vec::new();
        replay(&s, &m, true, |k, _, a, _| one.push((k, key(a)))).unwrap();
        let ranged = |threads: usize| {
            let ticks = std::sync::atomic::AtomicUsize::new(0);
            let found = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    replay_ranged(
                        &s,
                        &m,
                        0.0,
                        7,
                        |k, _, a, _| (k, key(a)),
                        || {
                            ticks.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        },
                    )
                })
                .unwrap();
            assert_eq!(ticks.into_inner(), found.len());
            found
        };
        let (r1, r3) = (ranged(1), ranged(3));
        assert_eq!(format!("{r1:?}"), format!("{r3:?}"));
        assert_eq!(r1.len(), s.steps.len() + 1);
        assert!(r1.iter().any(|(_, (_, v, _))| *v == Verdict::Overloaded));
        for ((k, (u, v, l)), (k1, (u1, v1, l1))) in r1.iter().zip(&one) {
            assert_eq!(k, k1);
            assert_eq!(v, v1, "step {k}");
            assert!(
                (u - u1).abs() <= 1e-9 * u1.abs().max(1.0),
                "step {k}: {u} vs {u1}"
            );
            assert_eq!(l.is_some(), l1.is_some(), "step {k}");
            if let (Some(l), Some(l1)) = (l, l1) {
                assert!((l - l1).abs() <= 1e-6 * l1, "step {k}: {l} vs {l1}");
            }
        }
    }

    #[test]
    fn without_a_model_the_report_says_the_mechanics_did_not_run() {
        let r = certify(&branch_schedule(1), &opts(None)).unwrap();
        assert!(r.checks.iter().any(|c| c == MECHANICS_NOT_RUN));
        assert!(!r.per_step[0].metrics.contains_key("max_utilisation"));
    }

    #[test]
    fn the_schedule_names_its_model_relative_to_its_own_file() {
        let mut s = branch_schedule(1);
        s.model = Some("catom-3.6mm-10kpa.toml".into());
        let o = Options {
            base_dir: Some(models()),
            ..Default::default()
        };
        let r = certify(&s, &o).unwrap();
        assert!(
            r.violations
                .iter()
                .any(|v| v.kind == ViolationKind::Overload)
        );
        // A missing model file is unusable input, not a silent pass.
        s.model = Some("no-such-model.toml".into());
        assert!(certify(&s, &o).is_err());
    }

    /// A fixed floor, a free layer resting on it, and `k` agents on the
    /// free layer, each rolling across its pivot's top in the one step:
    /// `k` movers on one component.
    fn agents_on_a_slab(k: usize) -> Schedule {
        let l = FccLattice;
        let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(3.6));
        let mut id = 0;
        let mut add = |s: &mut Schedule, cell: Cell, fixed: bool| {
            id += 1;
            s.modules.push(ModuleSpec { id, cell, fixed });
            id
        };
        for x in 0..9 {
            for y in 0..7 {
                add(&mut s, Cell::new(x, y, 0), true);
            }
        }
        let mut free = std::collections::HashMap::new();
        for x in 0..8 {
            for y in 0..6 {
                free.insert((x, y), add(&mut s, Cell::new(x, y, 1), false));
            }
        }
        let mut events = Vec::new();
        for (x, y) in (0..6).flat_map(|y| [0, 2, 4, 6].map(|x| (x, y))).take(k) {
            let pivot = Cell::new(x, y, 1);
            let from = l.neighbour(pivot, 4);
            let agent = add(&mut s, from, false);
            events.push(Event::Rotate {
                module: agent,
                pivot: free[&(x, y)],
                from,
                to: l.neighbour(pivot, 5),
                route: Route::Octagonal,
            });
        }
        s.steps.push(Step { events });
        s
    }

    #[test]
    fn a_step_judged_at_its_samples_alone_is_noted_and_listed_as_not_checked() {
        // 24 movers on one component, turning at one rate: superposed
        // from at most three unit load cases, and the poses between
        // samples judged. Solved pose by pose instead: judged at the
        // samples alone, and the report says so.
        let o = opts(Some("catom-3.6mm.toml"));
        let r = certify(&agents_on_a_slab(24), &o).unwrap();
        assert!(r.certified, "{}", r.summary());
        assert!(
            r.warnings
                .iter()
                .all(|w| w.kind != ViolationKind::JudgedAtSamples),
            "{}",
            r.summary()
        );
        assert!(r.coverage().1.is_empty(), "{:?}", r.coverage());
        let s = agents_on_a_slab(24);
        let model = Model::load(&models().join("catom-3.6mm.toml")).unwrap();
        let check = LoadCheck::new(&model, s.spacing.metres(), true)
            .unwrap()
            .with_superpose(false);
        let r =
            crate::certify::certify_with(&s, &o, &[&crate::certify::LatticeCheck, &check]).unwrap();
        assert!(r.certified, "a note does not refuse: {}", r.summary());
        let notes: Vec<_> = r
            .warnings
            .iter()
            .filter(|w| w.kind == ViolationKind::JudgedAtSamples)
            .collect();
        assert_eq!(notes.len(), 1, "{}", r.summary());
        assert_eq!((notes[0].step, notes[0].severity), (1, Severity::Note));
        assert!(
            notes[0].message.contains("24 movers"),
            "{}",
            notes[0].message
        );
        assert_eq!(notes[0].detail["components"], 1);
        assert!(r.per_step[0].warnings >= 1);
        // (Only the lattice and mechanics checks ran: collisions are not
        // checked either.)
        let (_, not_checked) = r.coverage();
        let mechanics: Vec<&str> = not_checked
            .iter()
            .map(String::as_str)
            .filter(|l| l.starts_with("mechanics"))
            .collect();
        assert_eq!(
            mechanics,
            vec![
                "mechanics between the sampled poses of the movers' sweeps at 1 step(s), from step 1 (judged_at_samples notes)"
            ]
        );
        assert!(
            r.summary()
                .contains("NOT checked: mechanics between the sampled poses")
        );
        assert!(r.to_json().contains("\"kind\": \"judged_at_samples\""));
    }
}
