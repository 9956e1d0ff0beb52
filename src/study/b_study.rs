//! The branch-length study (issue #4, SPEC §7): for a family of schedules
//! parameterised by the branch length `b`, check every intermediate
//! structure mechanically and find the largest `b` a connector pressure
//! allows — and the pressure each `b` needs — beside the closed-form bound
//! of the worst cantilever (a horizontal branch with a free agent at its
//! tip).
//!
//! Connector loads of the elastic model do not depend on the connector
//! pressure, so one pass per `b` gives the minimum pressure under both
//! bending criteria, and `b_max(p)` for any `p` follows without
//! re-solving.

use crate::certify::RangedReplay;
use crate::certify::StepOutcome;
use crate::certify::jobs::{self, Done};
use crate::certify::report::ViolationKind;
use crate::error::InputError;
use crate::mechanics::analysis::{Analysis, Critical, REGION_HOPS, Verdict};
use crate::mechanics::capacity::required_pressure;
use crate::mechanics::closed_form;
use crate::mechanics::model::{Bending, Capacity, Model};
use crate::mechanics::structure::Structure;
use crate::progress::Reporter;
use crate::schedule::Schedule;
use serde::Serialize;
use std::path::Path;

/// Results for one branch length.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct Row {
    pub b: usize,
    pub steps: usize,
    /// Lattice-level violations of the generated schedule (should be 0).
    pub lattice_violations: usize,
    /// Largest connector utilisation over every step, at the model's `p`.
    pub max_utilisation: f64,
    /// Some failing step's limit analysis left a pose without a bound
    /// unanalysed (see `Analysis::load_factor_partial`): the largest
    /// utilisation is then at least `max_utilisation`.
    #[serde(default)]
    pub max_utilisation_at_least: bool,
    pub critical_step: usize,
    pub critical_connector: String,
    /// Some step has no equilibrium whatever the connectors (tips, floats).
    pub no_equilibrium: bool,
    /// Minimum connector pressure (Pa) for every step to hold, per criterion.
    pub min_pressure_rigid_hinge: f64,
    pub min_pressure_elastic: f64,
    /// Closed form: root utilisation of the branch family's worst step,
    /// `b − 1` modules and an agent beyond the base (see
    /// `closed_branch_max`), and the pressures it needs.
    pub closed_utilisation: f64,
    pub closed_pressure_rigid_hinge: f64,
    pub closed_pressure_elastic: f64,
    /// Limit analyses (LP/SOCP solves) the replay took: where the time
    /// went (a load-factor tolerance spares some).
    #[serde(default)]
    pub limit_analyses: usize,
    /// Steps the limit analysis did not judge because their bound could
    /// not reach the row's worst (`--worst-only`, [`study_rows`]); 0 when
    /// every step was judged.
    #[serde(default)]
    pub steps_bounded: usize,
    /// Steps left with an infinite bound ([`Judging::UntilVerdict`]): no
    /// equilibrium within capacity was shown there at any scale, so the
    /// row's pressures are lower bounds (such a step might need more, or
    /// lack an equilibrium) and the pressure sweep does not count the row
    /// as holding. 0 when every step's bound was finite or judged.
    #[serde(default)]
    pub equilibria_unproved: usize,
    /// Bounded steps taken up by `prove_worst` (a region's bound, and the
    /// full limit analysis where that stays above the worst): where a
    /// worst-only study's time went.
    #[serde(default)]
    pub steps_judged: usize,
    /// Steps where a component was judged at the sampled poses of the
    /// movers' sweeps alone (`Analysis::sampled_only`): between samples
    /// the row's figures are not proved there.
    #[serde(default)]
    pub steps_judged_at_samples: usize,
}

impl Row {
    pub fn safe(&self) -> bool {
        self.lattice_violations == 0
            && !self.no_equilibrium
            && !crate::mechanics::capacity::overloaded(self.max_utilisation)
    }

    pub fn min_pressure(&self, bending: Bending) -> f64 {
        match bending {
            Bending::RigidHinge => self.min_pressure_rigid_hinge,
            Bending::Elastic => self.min_pressure_elastic,
        }
    }

    /// Whether every step holds at pressure `p` (Pa) under `bending`: its
    /// minimum pressure is at most `p`, and no step was left without a
    /// finite bound (which could need more).
    pub fn holds_at(&self, p: f64, bending: Bending) -> bool {
        self.equilibria_unproved == 0 && self.min_pressure(bending) <= p * (1.0 + 1e-9)
    }
}

/// `b_max` at one pressure, both criteria, simulated and closed-form.
#[derive(Clone, Debug, Serialize)]
pub struct SweepRow {
    pub pressure_kpa: f64,
    pub b_max_rigid_hinge: usize,
    pub b_max_elastic: usize,
    pub closed_rigid_hinge: usize,
    pub closed_elastic: usize,
}

/// A branch length the family's generator could not plan.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct Unplanned {
    pub b: usize,
    /// The generator's error.
    pub reason: String,
}

/// The whole study.
#[derive(Clone, Debug, Serialize)]
pub struct Study {
    pub family: String,
    pub model: String,
    pub pressure_kpa: f64,
    pub bending: Bending,
    pub rows: Vec<Row>,
    /// Branch lengths with no schedule: they are not studied, so they
    /// neither hold nor break `b_max` (a planner's limit is not a
    /// connector's).
    pub unplanned: Vec<Unplanned>,
    /// Largest studied `b` such that every `b' ≤ b` is safe (0 if none).
    pub b_max: usize,
    /// Closed-form largest `b` of the branch family (`closed_branch_max`).
    pub closed_b_max: usize,
    pub sweep: Vec<SweepRow>,
    /// The limit analysis's load-factor tolerance the rows were found with
    /// (0: exact). Which b are safe does not depend on it; a failing
    /// structure's utilisation `1/λ` may read up to this fraction low.
    pub load_factor_tolerance: f64,
    /// Which steps were limit-analysed ([`Judging`]).
    pub judging: Judging,
}

/// Which steps a study limit-analyses (the elastic screen sees every step).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Judging {
    /// Every step the elastic screen cannot clear, in its range.
    Every,
    /// Only the steps that could be a row's worst (`prove_worst`): the
    /// rows are those of judging every step.
    WorstOnly,
    /// As [`Judging::WorstOnly`], but a row proved to fail (a step judged
    /// above utilisation 1, or without an equilibrium) is judged no
    /// further: its verdict is decided, and its maximum is then marked
    /// `max_utilisation_at_least` where a step left bounded could exceed
    /// it. Safe rows, and so `b_max`, are exactly those of judging every
    /// step; what a failing row's table says beyond its verdict is a lower
    /// bound. For a study whose question is the largest safe b of a large
    /// scaffold, where judging every candidate step of the failing b costs
    /// hours.
    UntilVerdict,
}

impl Judging {
    /// The ranges run with the limit analysis off; `prove_worst` judges.
    fn bounds_only(self) -> bool {
        self != Judging::Every
    }
}

/// The closed form in the branch family's terms: growing a branch of `b`
/// (its first module included) beyond a fixed base, the worst step is the
/// agent hanging beyond the tip of the `b − 1` modules already placed — a
/// cantilever of `b − 1` modules plus the agent. So the largest `b` is one
/// more than the longest such cantilever, and the per-row figures are
/// those of `b − 1` modules plus the agent.
fn closed_branch_max(model: &Model) -> usize {
    if closed_form::cantilever_utilisation(model, 0, true) <= 1.0 {
        closed_form::cantilever_max_length(model, true) + 1
    } else {
        // Not even the first agent holds on the base.
        0
    }
}

/// The rows of the studied b, those the generator could not plan, and the
/// first generator error (see [`study_rows`]).
pub type StudyRows = (Vec<Row>, Vec<Unplanned>, Option<InputError>);

/// A generator of one schedule per branch length `b`.
pub type FamilyFn = Box<dyn Fn(usize) -> Result<Schedule, InputError>>;

/// The shape families `reconfcheck b-study --family` knows, each a
/// schedule generator over `b` at lattice spacing `spacing_mm`:
///
/// * `branch` — one horizontal branch of `b` modules grown from a fixed
///   base, agent by agent (the worst cantilever, built);
/// * `pyramid` — seed 000's scaffold of an `size`-pyramid (default 2),
///   assembled from the sandbox with branch length `b`;
/// * `cube` — seed 000's scaffold of the cube of `size` tiles a side
///   (default 2), side `(size − 1)·b + e` modules with `e = b − 1` (border
///   branches of `b − 2` modules). Not the generator's default `e = b`:
///   with it the planner finds no route for one module of the 2-tile cube
///   at `b = 4`; `e = b − 1` plans for every `b` from 4 to 10.
///
/// * `csg` — seed 000's scaffold of the shape in the CSG file `csg`
///   (e.g. `models/shapes/sandcastle.csg`): the b-study of one's own shape.
///   The shape is fixed in cells, so each `b` tiles the same volume.
///
/// `size` is ignored by `branch` and `csg`. Scaffold families need `b ≥ 4`
/// (seed 000 §3.2.2); the generator says so for smaller `b`.
pub fn family(
    name: &str,
    spacing_mm: f64,
    size: Option<u32>,
    csg: Option<&Path>,
) -> Result<FamilyFn, InputError> {
    use crate::algorithms::scaffold::{ShapeSpec, scaffold_schedule};
    if csg.is_some() != (name == "csg") {
        return Err(InputError::new(
            "b-study: a CSG shape file goes with --family csg, and only with it",
        ));
    }
    let h = size.unwrap_or(2);
    if h == 0 {
        return Err(InputError::new(
            "b-study: the shape size must be at least 1",
        ));
    }
    let scaffold = move |shape: ShapeSpec, b: usize| -> Result<Schedule, InputError> {
        let b = u32::try_from(b).map_err(|_| InputError::new(format!("b = {b} is too large")))?;
        let mut s = scaffold_schedule(&shape, b)?;
        s.spacing = crate::schedule::Length::mm(spacing_mm);
        Ok(s)
    };
    match name {
        "branch" => Ok(Box::new(move |b| {
            crate::algorithms::branch::branch_schedule(b, spacing_mm)
        })),
        "pyramid" => Ok(Box::new(move |b| scaffold(ShapeSpec::Pyramid { h }, b))),
        "cube" => Ok(Box::new(move |b| {
            let e = u32::try_from(b)
                .unwrap_or(u32::MAX)
                .saturating_sub(1)
                .max(1);
            scaffold(ShapeSpec::Cube { h, e }, b)
        })),
        "csg" => {
            let path = csg.expect("checked above").to_path_buf();
            if !path.is_file() {
                return Err(InputError::new("no such CSG shape file").in_file(&path));
            }
            Ok(Box::new(move |b| {
                scaffold(ShapeSpec::Csg { path: path.clone() }, b)
            }))
        }
        other => Err(InputError::new(format!(
            "unknown b-study family '{other}' (known: {})",
            FAMILIES.join(", ")
        ))),
    }
}

/// Names accepted by [`family`].
pub const FAMILIES: &[&str] = &["branch", "pyramid", "cube", "csg"];

/// The range of `b` a family is studied over by default: the branch from
/// 1, seed 000's scaffolds from their smallest branch length, 4.
pub fn default_range(name: &str) -> (usize, usize) {
    match name {
        "branch" => (1, 10),
        _ => (4, 8),
    }
}

/// Pressures of the sweep (kPa): 1…150, SPEC §7.
pub fn sweep_pressures() -> Vec<f64> {
    let mut v: Vec<f64> = (1..=20).map(f64::from).collect();
    v.extend((25..=150).step_by(5).map(f64::from));
    v
}

/// Runs the study for `lengths` with `generate(b)` producing the schedule;
/// `progress` hears of every schedule's steps, in one phase for all `b`
/// (a scaffold of the sandcastle's size takes minutes per `b`). A `b` the
/// generator cannot plan is recorded in [`Study::unplanned`] and the
/// study goes on; if no `b` can be planned, the first error is returned.
pub fn b_study(
    family: &str,
    model: &Model,
    lengths: &[usize],
    generate: impl Fn(usize) -> Result<Schedule, InputError>,
    progress: &Reporter,
) -> Result<Study, InputError> {
    let (rows, unplanned, first_error) = study_rows(
        model,
        lengths,
        generate,
        progress,
        0.0,
        Judging::Every,
        &on_threads,
    )?
    .expect("this process's threads fold the rows");
    if let (true, Some(e)) = (rows.is_empty(), first_error) {
        return Err(e);
    }
    Ok(assemble(
        family,
        model,
        rows,
        unplanned,
        0.0,
        Judging::Every,
    ))
}

/// What the study keeps of one step's analysis (sent between processes
/// when a study runs over MPI).
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct StepFinding {
    step: usize,
    lattice_violations: usize,
    no_equilibrium: bool,
    partial: bool,
    max_utilisation: f64,
    /// The step's critical element, described (the row keeps the one of
    /// its worst step).
    critical: String,
    min_pressure_rigid_hinge: f64,
    min_pressure_elastic: f64,
    limit_analyses: usize,
    /// A component the elastic screen could not clear was bounded, not
    /// limit-analysed: `max_utilisation` is an upper bound.
    #[serde(default)]
    bounded: bool,
    /// A component was judged at the sampled poses alone.
    #[serde(default)]
    sampled_only: bool,
}

impl StepFinding {
    /// The step (1-based; the schedule's steps + 1 is its final
    /// configuration).
    pub fn step(&self) -> usize {
        self.step
    }

    fn of(
        step: usize,
        s: &Structure,
        a: &Analysis,
        out: &StepOutcome,
        hinge: &Capacity,
        elastic: &Capacity,
    ) -> StepFinding {
        let critical = match a.critical {
            Some(Critical::Link(i)) => s.describe(&s.links[i]),
            Some(Critical::Pivot(i)) => {
                let h = &s.hanging[a.pivots[i].hanging];
                format!("pivot connector {}–{}", h.mover, s.bodies[h.pivot].module)
            }
            None => String::new(),
        };
        let loads = s
            .links
            .iter()
            .zip(&a.links)
            .filter(|(l, r)| !l.is_ground() && !r.released)
            .map(|(_, r)| r.load)
            .chain(a.pivots.iter().map(|p| p.load));
        let (mut rh, mut el) = (0.0f64, 0.0f64);
        for load in loads {
            rh = rh.max(required_pressure(&load, hinge));
            el = el.max(required_pressure(&load, elastic));
        }
        StepFinding {
            step,
            lattice_violations: out
                .violations
                .iter()
                .filter(|v| !matches!(v.kind, ViolationKind::Overload | ViolationKind::Unstable))
                .count(),
            no_equilibrium: a.verdict() == Verdict::NoEquilibrium,
            partial: a.load_factor_partial,
            max_utilisation: a.max_utilisation,
            critical,
            min_pressure_rigid_hinge: rh,
            min_pressure_elastic: el,
            limit_analyses: a.limit_analyses,
            bounded: a.bounded > 0,
            sampled_only: !a.sampled_only.is_empty(),
        }
    }
}

/// Runs jobs (indices into one table of every b's ranges, handed out in
/// the order given) and returns what they found on the process that folds
/// the rows; `None` on the others (MPI ranks other than 0).
pub type Runner<'r> = &'r dyn Fn(
    &[usize],
    &(dyn Fn(usize) -> Result<Vec<StepFinding>, InputError> + Sync),
) -> Result<Option<Done<Vec<StepFinding>>>, InputError>;

/// The [`Runner`] of this process's threads.
pub fn on_threads(
    order: &[usize],
    job: &(dyn Fn(usize) -> Result<Vec<StepFinding>, InputError> + Sync),
) -> Result<Option<Done<Vec<StepFinding>>>, InputError> {
    Ok(Some(jobs::on_threads(order, job)))
}

/// The rows of the b values in `lengths`, each from checking every step of
/// its schedule; the b values the generator could not plan, and the first
/// such error. Every b's steps are cut into ranges as certification cuts
/// them ([`RangedReplay`]), and the ranges of all b are one pool of jobs
/// for `runner` — the final structures first, then the ranges from the
/// latest steps down — so that any number of threads or processes share
/// the work, one b or many. Each step's findings are folded in step order:
/// the rows do not depend on who ran what. `None` where `runner` returns
/// none (a process that does not fold).
///
/// [`Judging::WorstOnly`]: a row needs the exact utilisation of its worst
/// step, not of every step. The ranges then run with the limit analysis
/// off, so a step the elastic screen cannot clear gets an upper bound of
/// its utilisation (`Settings::limit_analysis`); `prove_worst` then
/// judges steps from the highest bound down, until no bound left exceeds
/// the worst utilisation proved. The rows' verdicts, maxima and pressures
/// are those of judging every step; `limit_analyses` and `steps_bounded`
/// say what was spared. [`Judging::UntilVerdict`] stops judging a row
/// once it is proved to fail.
pub fn study_rows(
    model: &Model,
    lengths: &[usize],
    generate: impl Fn(usize) -> Result<Schedule, InputError>,
    progress: &Reporter,
    load_factor_tolerance: f64,
    judging: Judging,
    runner: Runner<'_>,
) -> Result<Option<StudyRows>, InputError> {
    let mut planned = Vec::new();
    let mut unplanned = Vec::new();
    let mut first_error = None;
    for &b in lengths {
        match generate(b) {
            Ok(s) => planned.push((b, s)),
            Err(e) => {
                unplanned.push(Unplanned {
                    b,
                    reason: e.to_string(),
                });
                first_error.get_or_insert(e);
            }
        }
    }
    let mut studied = Vec::new();
    for (b, schedule) in &planned {
        let m = model.at_spacing_checked(schedule.spacing.metres())?;
        let range = crate::certify::default_range_steps(schedule.steps.len());
        let mut replay = RangedReplay::new(schedule, &m, load_factor_tolerance, range)?;
        if judging.bounds_only() {
            replay = replay.bounds_only();
        }
        let hinge = Capacity {
            bending: Bending::RigidHinge,
            ..m.connector
        };
        let elastic = Capacity {
            bending: Bending::Elastic,
            ..m.connector
        };
        studied.push((
            empty_row(*b, schedule.steps.len(), &m),
            replay,
            hinge,
            elastic,
        ));
    }
    // One table of (b, job) in b order, jobs in step order; handed out
    // final structures first (largest b first), then ranges by their
    // first step, latest first.
    let table: Vec<(usize, usize)> = studied
        .iter()
        .enumerate()
        .flat_map(|(r, (_, replay, _, _))| (0..replay.jobs()).map(move |j| (r, j)))
        .collect();
    let mut order: Vec<usize> = (0..table.len()).collect();
    order.sort_by_key(|&t| {
        let (r, j) = table[t];
        let replay = &studied[r].1;
        let range = j + 1 < replay.jobs();
        (
            range,
            std::cmp::Reverse((replay.first_step(j), studied[r].0.b)),
        )
    });
    let total: usize = planned.iter().map(|(_, s)| s.steps.len() + 1).sum();
    let bs: Vec<String> = planned.iter().map(|(b, _)| b.to_string()).collect();
    progress.start(&format!("b = {}", bs.join(", ")), total as u64);
    let job = |t: usize| {
        let (r, j) = table[t];
        let (_, replay, hinge, elastic) = &studied[r];
        replay.run(
            j,
            &|step, s, a, out| StepFinding::of(step, s, a, out, hinge, elastic),
            &|| progress.advance(1),
        )
    };
    let Some(done) = runner(&order, &job)? else {
        return Ok(None);
    };
    progress.finish();
    // In table order, b by b, each b's steps in order (final last).
    let mut found = jobs::in_order(done, table.len())?.into_iter();
    let mut per_b: Vec<Vec<StepFinding>> = studied
        .iter()
        .map(|(_, replay, _, _)| found.by_ref().take(replay.jobs()).flatten().collect())
        .collect();
    let judged = if judging.bounds_only() {
        prove_worst(&studied, &mut per_b, judging, progress)?
    } else {
        vec![0; per_b.len()]
    };
    let mut rows = Vec::new();
    for (((mut row, _, _, _), findings), judged) in studied.into_iter().zip(per_b).zip(judged) {
        row.steps_judged = judged;
        // The highest bound left unjudged: above the worst proved only
        // where judging stopped at the verdict.
        let mut left = 0.0f64;
        for f in findings {
            if f.bounded {
                left = left.max(f.max_utilisation);
            }
            row.fold(f);
        }
        if left > row.max_utilisation {
            row.max_utilisation_at_least = true;
        }
        if row.no_equilibrium {
            row.min_pressure_rigid_hinge = f64::INFINITY;
            row.min_pressure_elastic = f64::INFINITY;
        }
        rows.push(row);
    }
    Ok(Some((rows, unplanned, first_error)))
}

/// Steps judged together in `prove_worst`: a fixed number, so that which
/// steps are judged does not depend on the threads.
const PROVED_TOGETHER: usize = 4;

/// Judges bounded steps (`StepFinding::bounded`) with the limit analysis,
/// highest bound first, in batches of [`PROVED_TOGETHER`] on this
/// process's threads, until every bound left is at most its row's worst
/// utilisation proved: those steps cannot raise it, and a finite bound
/// proves an equilibrium within capacity scaled by it (so they cannot
/// lack one, nor, at a bound ≤ 1, fail). An infinite bound sorts first.
/// Each step's bound is first tightened by a region's limit analysis
/// ([`RangedReplay::bound_step`], [`REGION_HOPS`] links around the
/// overloaded ones, stopping at the first pose above the row's worst):
/// only a step still above the worst is judged in full.
/// [`Judging::UntilVerdict`]: a row whose worst proved exceeds 1 (or has
/// no equilibrium) is decided, and none of its steps is judged further.
/// Returns how many steps of each row were judged.
fn prove_worst(
    studied: &[(Row, RangedReplay<'_>, Capacity, Capacity)],
    per_b: &mut [Vec<StepFinding>],
    judging: Judging,
    progress: &Reporter,
) -> Result<Vec<usize>, InputError> {
    let mut judged = vec![0; per_b.len()];
    let proved_max = |findings: &[StepFinding]| {
        findings
            .iter()
            .filter(|f| !f.bounded)
            .map(|f| f.max_utilisation)
            .fold(0.0, f64::max)
    };
    let mut worst: Vec<f64> = per_b.iter().map(|f| proved_max(f)).collect();
    let mut candidates: Vec<(usize, usize)> = per_b
        .iter()
        .enumerate()
        .flat_map(|(r, f)| {
            (0..f.len())
                .filter(move |&i| f[i].bounded)
                .map(move |i| (r, i))
        })
        .collect();
    // Among equal bounds (most often ∞: a ground contact pressed
    // off-centre, which no scaling of the elastic field carries), the
    // highest elastic loads first (the pressure they need): those steps are
    // the likeliest worst, and a high worst proved early spares the rest.
    candidates.sort_by(|&(r, i), &(q, j)| {
        let (a, b) = (&per_b[r][i], &per_b[q][j]);
        b.max_utilisation
            .total_cmp(&a.max_utilisation)
            .then(
                b.min_pressure_rigid_hinge
                    .total_cmp(&a.min_pressure_rigid_hinge),
            )
            .then((r, a.step).cmp(&(q, b.step)))
    });
    // Most candidates are never judged: the count is an upper limit.
    progress.start(
        "bounded steps judged, highest bound first (until none left can raise its row's worst)",
        candidates.len() as u64,
    );
    let decided =
        |w: f64| judging == Judging::UntilVerdict && crate::mechanics::capacity::overloaded(w);
    let mut next = candidates.into_iter();
    loop {
        let batch: Vec<(usize, usize)> = next
            .by_ref()
            .filter(|&(r, i)| per_b[r][i].max_utilisation > worst[r] && !decided(worst[r]))
            .take(PROVED_TOGETHER)
            .collect();
        if batch.is_empty() {
            break;
        }
        let order: Vec<usize> = (0..batch.len()).collect();
        let job = |t: usize| {
            let (r, i) = batch[t];
            let (_, replay, hinge, elastic) = &studied[r];
            let finding = |step: usize, s: &Structure, a: &Analysis, out: &StepOutcome| {
                StepFinding::of(step, s, a, out, hinge, elastic)
            };
            // First the region's bound (a small limit analysis around the
            // overloaded links per pose): a step it keeps at or below the
            // row's worst proved cannot raise it and is not judged.
            let step = per_b[r][i].step;
            let bounded = replay.bound_step(step, REGION_HOPS, worst[r], &finding)?;
            let found = if bounded.max_utilisation <= worst[r] {
                Ok(bounded)
            } else {
                replay.run_step(step, &finding)
            };
            progress.advance(1);
            found
        };
        let done = jobs::in_order(jobs::on_threads(&order, &job), batch.len())?;
        for ((r, i), mut f) in batch.into_iter().zip(done) {
            judged[r] += 1;
            worst[r] = worst[r].max(f.max_utilisation);
            // The pressures come from the elastic loads: keep those of the
            // ranges (a step analysed from scratch differs by round-off).
            let was = &per_b[r][i];
            f.min_pressure_rigid_hinge = was.min_pressure_rigid_hinge;
            f.min_pressure_elastic = was.min_pressure_elastic;
            per_b[r][i] = f;
        }
    }
    progress.finish();
    Ok(judged)
}

/// A row before any step is folded in: the closed forms of `b − 1`
/// modules and the agent.
fn empty_row(b: usize, steps: usize, m: &Model) -> Row {
    Row {
        b,
        steps,
        lattice_violations: 0,
        max_utilisation: 0.0,
        max_utilisation_at_least: false,
        critical_step: 0,
        critical_connector: String::new(),
        no_equilibrium: false,
        min_pressure_rigid_hinge: 0.0,
        min_pressure_elastic: 0.0,
        closed_utilisation: closed_form::cantilever_utilisation(m, b.saturating_sub(1), true),
        closed_pressure_rigid_hinge: closed_form::cantilever_pressure(
            &m.with_connector(m.connector.pressure, Bending::RigidHinge),
            b.saturating_sub(1),
            true,
        ),
        closed_pressure_elastic: closed_form::cantilever_pressure(
            &m.with_connector(m.connector.pressure, Bending::Elastic),
            b.saturating_sub(1),
            true,
        ),
        limit_analyses: 0,
        steps_bounded: 0,
        steps_judged_at_samples: 0,
        equilibria_unproved: 0,
        steps_judged: 0,
    }
}

impl Row {
    /// Folds one step's finding in (steps in order: the worst step is the
    /// first to reach the row's maximum).
    fn fold(&mut self, f: StepFinding) {
        self.lattice_violations += f.lattice_violations;
        self.limit_analyses += f.limit_analyses;
        self.no_equilibrium |= f.no_equilibrium;
        self.max_utilisation_at_least |= f.partial;
        // A bounded step was left bounded because its bound is no more
        // than the worst proved (see `prove_worst`): it cannot raise it.
        self.steps_bounded += usize::from(f.bounded);
        self.steps_judged_at_samples += usize::from(f.sampled_only);
        self.equilibria_unproved += usize::from(f.bounded && f.max_utilisation == f64::INFINITY);
        if !f.bounded && f.max_utilisation > self.max_utilisation {
            self.max_utilisation = f.max_utilisation;
            self.critical_step = f.step;
            self.critical_connector = f.critical;
        }
        self.min_pressure_rigid_hinge = self
            .min_pressure_rigid_hinge
            .max(f.min_pressure_rigid_hinge);
        self.min_pressure_elastic = self.min_pressure_elastic.max(f.min_pressure_elastic);
    }
}

/// The study of `family` from its rows (any order) and its unplanned b
/// values: the largest safe b, the pressure sweep and the closed forms.
pub fn assemble(
    family: &str,
    model: &Model,
    mut rows: Vec<Row>,
    mut unplanned: Vec<Unplanned>,
    load_factor_tolerance: f64,
    judging: Judging,
) -> Study {
    rows.sort_by_key(|r| r.b);
    unplanned.sort_by_key(|u| u.b);
    let prefix_max = |ok: &dyn Fn(&Row) -> bool| {
        let mut best = 0;
        let mut sorted: Vec<&Row> = rows.iter().collect();
        sorted.sort_by_key(|r| r.b);
        for r in sorted {
            if r.lattice_violations == 0 && ok(r) {
                best = r.b;
            } else {
                break;
            }
        }
        best
    };
    let b_max = prefix_max(&|r: &Row| r.safe());
    let sweep = sweep_pressures()
        .into_iter()
        .map(|kpa| {
            let p = kpa * 1e3;
            SweepRow {
                pressure_kpa: kpa,
                b_max_rigid_hinge: prefix_max(&|r: &Row| r.holds_at(p, Bending::RigidHinge)),
                b_max_elastic: prefix_max(&|r: &Row| r.holds_at(p, Bending::Elastic)),
                closed_rigid_hinge: closed_branch_max(
                    &model.with_connector(p, Bending::RigidHinge),
                ),
                closed_elastic: closed_branch_max(&model.with_connector(p, Bending::Elastic)),
            }
        })
        .collect();
    Study {
        family: family.to_string(),
        model: model.name.clone(),
        pressure_kpa: model.connector.pressure / 1e3,
        bending: model.connector.bending,
        rows,
        unplanned,
        b_max,
        closed_b_max: closed_branch_max(model),
        sweep,
        load_factor_tolerance,
        judging,
    }
}

impl Study {
    /// The branch length a study's page replays, and why: the smallest b
    /// that does not hold (what the structure looks like when a connector
    /// gives way), else the largest b studied. `None` for a study without
    /// rows.
    pub fn replayed_b(&self) -> Option<(usize, &'static str)> {
        let mut rows: Vec<&Row> = self.rows.iter().collect();
        rows.sort_by_key(|r| r.b);
        if let Some(r) = rows.iter().find(|r| !r.safe()) {
            return Some((r.b, "the smallest b that does not hold"));
        }
        rows.last()
            .map(|r| (r.b, "the largest b studied; every b holds"))
    }

    /// The study as text tables.
    pub fn table(&self) -> String {
        use std::fmt::Write as _;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "b-study: family '{}', model '{}' (p = {} kPa, {} bending)",
            self.family,
            self.model,
            self.pressure_kpa,
            self.bending.name()
        );
        if self.load_factor_tolerance > 0.0 {
            let _ = writeln!(
                s,
                "load-factor tolerance {}: safe b exact; a failing structure's max util may read up to that fraction low",
                self.load_factor_tolerance
            );
        }
        if self.judging == Judging::UntilVerdict {
            let _ = writeln!(
                s,
                "until the verdict: a failing row was judged no further than a step proved to fail; its max util (≥) and its pressures where steps were left unproved (≥) are lower bounds"
            );
        }
        if self.judging.bounds_only() {
            let bounded: Vec<String> = self
                .rows
                .iter()
                .map(|r| {
                    let unproved = match r.equilibria_unproved {
                        0 => String::new(),
                        n => format!(" ({n} with no finite bound)"),
                    };
                    format!(
                        "b = {}: {} of {}{unproved}, {} judged",
                        r.b,
                        r.steps_bounded,
                        r.steps + 1,
                        r.steps_judged
                    )
                })
                .collect();
            let _ = writeln!(
                s,
                "worst only: steps bounded, not limit-analysed{}: {}",
                if self.judging == Judging::WorstOnly {
                    " (they cannot raise the worst)"
                } else {
                    ""
                },
                bounded.join(", ")
            );
        }
        let sampled: Vec<String> = self
            .rows
            .iter()
            .filter(|r| r.steps_judged_at_samples > 0)
            .map(|r| {
                format!(
                    "b = {}: {} of {}",
                    r.b,
                    r.steps_judged_at_samples,
                    r.steps + 1
                )
            })
            .collect();
        if !sampled.is_empty() {
            let _ = writeln!(
                s,
                "NOT checked: mechanics between the sampled poses of the movers' sweeps, at steps judged at the samples only: {}",
                sampled.join(", ")
            );
        }
        let _ = writeln!(
            s,
            "{:>4} {:>6} {:>9} {:>9} {:>6} {:>10} {:>10} {:>10} {:>10}  critical",
            "b",
            "steps",
            "max util",
            "closed",
            "safe",
            "p_min RH",
            "p_min EL",
            "closed RH",
            "closed EL"
        );
        for r in &self.rows {
            // In kPa; "≥" where a step left with an infinite bound could
            // need more.
            let pressure = |pa: f64| {
                let at_least = if r.equilibria_unproved > 0 { "≥" } else { "" };
                format!("{at_least}{:.2}", pa / 1e3)
            };
            let _ = writeln!(
                s,
                "{:>4} {:>6} {:>9} {:>9.4} {:>6} {:>10} {:>10} {:>10.2} {:>10.2}  step {}: {}",
                r.b,
                r.steps,
                format!(
                    "{}{:.4}",
                    if r.max_utilisation_at_least {
                        "≥"
                    } else {
                        ""
                    },
                    r.max_utilisation
                ),
                r.closed_utilisation,
                if r.safe() { "yes" } else { "NO" },
                pressure(r.min_pressure_rigid_hinge),
                pressure(r.min_pressure_elastic),
                r.closed_pressure_rigid_hinge / 1e3,
                r.closed_pressure_elastic / 1e3,
                r.critical_step,
                r.critical_connector
            );
        }
        for u in &self.unplanned {
            let _ = writeln!(s, "{:>4}  no schedule, not studied: {}", u.b, u.reason);
        }
        let _ = writeln!(
            s,
            "largest safe b at {} kPa ({}): {} (closed form for a branch of b: b − 1 modules and the agent beyond the base: {})",
            self.pressure_kpa,
            self.bending.name(),
            self.b_max,
            self.closed_b_max
        );
        let _ = writeln!(
            s,
            "pressures in kPa; RH = rigid-hinge, EL = elastic bending"
        );
        let _ = writeln!(
            s,
            "\nb_max against pressure (largest studied b that holds; closed form beside):"
        );
        let _ = writeln!(
            s,
            "{:>7} {:>6} {:>6} {:>9} {:>9}",
            "p kPa", "RH", "EL", "closed RH", "closed EL"
        );
        for w in &self.sweep {
            let _ = writeln!(
                s,
                "{:>7} {:>6} {:>6} {:>9} {:>9}",
                w.pressure_kpa,
                w.b_max_rigid_hinge,
                w.b_max_elastic,
                w.closed_rigid_hinge,
                w.closed_elastic
            );
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algorithms::branch::branch_schedule;

    #[test]
    fn the_branch_study_agrees_with_the_closed_form_cantilever_bound() {
        let model = Model::default_catom();
        let lengths: Vec<usize> = (1..=7).collect();
        let st = b_study(
            "branch",
            &model,
            &lengths,
            |b| branch_schedule(b, 3.6),
            &Reporter::silent(),
        )
        .unwrap();
        for r in &st.rows {
            assert_eq!(r.lattice_violations, 0);
            // The worst step of growing a branch of b is the last agent
            // hanging beyond the tip of b − 1 modules: (b)² / 2 · W·d at the
            // root — the closed form for b − 1 modules plus an agent, at the
            // end of its swing. The envelope never reports less.
            let expected = closed_form::cantilever_utilisation(&model, r.b - 1, true);
            assert!(r.max_utilisation >= expected * (1.0 - 1e-9), "b = {}", r.b);
            if r.b >= 3 {
                assert!(
                    (r.max_utilisation - expected).abs() < 1e-6 * expected,
                    "b = {}: {} vs {expected}",
                    r.b,
                    r.max_utilisation
                );
            }
        }
        // At b = 2 the worst instant is mid-swing: the agent rounds the
        // tip's corner at (1 + √½, √½, 0) d, so the root connector (contact
        // at x = ½) carries, besides the bending (½ + ½ + √½)·W·d, the
        // torsion √½·W·d — and torsion, held by friction over a lever of
        // 0.38 L, is the weaker capacity. Hand statics of that pose:
        let w = model.weight();
        let d = model.spacing;
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let mid = crate::mechanics::ConnectorLoad {
            axial: 0.0,
            shear: 2.0 * w,
            torsion: h * w * d,
            moment_u: 0.0,
            moment_v: (1.0 + h) * w * d,
        };
        let (u_mid, _) = crate::mechanics::utilisation(&mid, &model.connector);
        let end = closed_form::cantilever_utilisation(&model, 1, true);
        assert!(u_mid > end * 1.1, "{u_mid} vs {end}");
        assert!(
            (st.rows[1].max_utilisation - u_mid).abs() < 1e-6 * u_mid,
            "{} vs {u_mid}",
            st.rows[1].max_utilisation
        );
        // 100 kPa rigid hinge: b² ≤ pL³/(mgd) ≈ 46.6 → b = 6 grows, 7 fails.
        assert_eq!(st.b_max, 6);
        // The page replays the failure, or the largest b where none fails.
        assert_eq!(
            st.replayed_b(),
            Some((7, "the smallest b that does not hold"))
        );
        let holding = assemble(
            "branch",
            &model,
            st.rows[..5].to_vec(),
            Vec::new(),
            0.0,
            Judging::Every,
        );
        assert_eq!(
            holding.replayed_b(),
            Some((5, "the largest b studied; every b holds"))
        );
        assert_eq!(
            assemble(
                "branch",
                &model,
                Vec::new(),
                Vec::new(),
                0.0,
                Judging::Every
            )
            .replayed_b(),
            None
        );
        // The summary's closed form counts the same weights as the family's
        // worst step: it agrees with the data, row by row and in b_max.
        assert_eq!(st.closed_b_max, st.b_max);
        for r in &st.rows[2..] {
            assert!((r.closed_utilisation - r.max_utilisation).abs() < 1e-6 * r.max_utilisation);
        }
        assert!(st.table().contains("largest safe b at 100 kPa (rigid-hinge): 6 (closed form for a branch of b: b − 1 modules and the agent beyond the base: 6)"), "{}", st.table());
        assert!(st.rows[6].max_utilisation > 1.0 && !st.rows[6].safe());
        // At the minimum pressure the worst step is exactly at capacity.
        let r = &st.rows[5];
        let at = model.with_connector(r.min_pressure_rigid_hinge, Bending::RigidHinge);
        let u = closed_form::cantilever_utilisation(&at, r.b - 1, true);
        assert!((u - 1.0).abs() < 1e-6, "{u}");
        // The sweep is monotone and matches the table at 100 kPa.
        let at100 = st.sweep.iter().find(|w| w.pressure_kpa == 100.0).unwrap();
        // Where not even b = 1 holds, the closed form says so too.
        let at1 = st.sweep.iter().find(|w| w.pressure_kpa == 1.0).unwrap();
        assert_eq!((at1.b_max_rigid_hinge, at1.closed_rigid_hinge), (0, 0));
        assert_eq!(at100.b_max_rigid_hinge, 6);
        assert!(at100.b_max_elastic < 6);
        assert!(
            st.sweep
                .windows(2)
                .all(|w| w[0].b_max_rigid_hinge <= w[1].b_max_rigid_hinge)
        );
    }

    #[test]
    fn a_branch_length_without_a_schedule_is_skipped_not_counted() {
        let model = Model::default_catom();
        let generate = |b: usize| {
            if b == 2 {
                Err(InputError::new("no route for module 9"))
            } else {
                branch_schedule(b, 3.6)
            }
        };
        let st = b_study("branch", &model, &[1, 2, 3], generate, &Reporter::silent()).unwrap();
        assert_eq!(st.rows.iter().map(|r| r.b).collect::<Vec<_>>(), [1, 3]);
        assert_eq!(st.unplanned.len(), 1);
        assert_eq!(st.unplanned[0].b, 2);
        assert!(
            st.table()
                .contains("no schedule, not studied: no route for module 9")
        );
        // b = 1 and 3 hold; the gap at 2 neither holds nor breaks b_max.
        assert_eq!(st.b_max, 3);
        // With no schedule at all, the study fails with the first error.
        let none = b_study("branch", &model, &[2, 2], generate, &Reporter::silent());
        assert!(none.unwrap_err().to_string().contains("module 9"));
    }

    #[test]
    fn an_overloaded_pyramid_reports_its_load_factor_not_an_unbounded_utilisation() {
        // At b = 10 the 2-pyramid is overloaded. The worst step is a
        // determinate ground-layer branch: 1/λ equals the closed form of
        // b − 3 = 7 modules and the agent (as for every b ≥ 5 of this
        // family).
        let model = Model::default_catom();
        let generate = family("pyramid", 3.6, None, None).unwrap();
        let st = b_study("pyramid", &model, &[10], generate, &Reporter::silent()).unwrap();
        let r = &st.rows[0];
        let expected = closed_form::cantilever_utilisation(&model, 7, true);
        assert!(
            (r.max_utilisation - expected).abs() < 1e-6 * expected,
            "{} vs {expected}",
            r.max_utilisation
        );
        assert!(!r.safe());
        // Poses whose bound exceeds the worst found were left out after
        // the step failed: the row says its figure is a lower bound, and
        // the table marks it.
        assert!(r.max_utilisation_at_least);
        assert!(st.table().contains("≥"), "{}", st.table());
        // A step that left poses out: its factor is the smallest solved,
        // and the bounds of the poses left out give a proven lower end.
        let schedule = family("pyramid", 3.6, None, None).unwrap()(10).unwrap();
        let m = model.at_spacing_checked(schedule.spacing.metres()).unwrap();
        let replay = RangedReplay::new(&schedule, &m, 0.0, 16).unwrap();
        let mut partial = Vec::new();
        for j in 0..replay.jobs() {
            let found = replay
                .run(
                    j,
                    &|_, _, a, _| (a.load_factor_partial, a.load_factor, a.load_factor_lower),
                    &|| {},
                )
                .unwrap();
            partial.extend(found.into_iter().filter(|f| f.0));
        }
        assert!(!partial.is_empty());
        for (_, factor, lower) in partial {
            let (factor, lower) = (factor.unwrap(), lower.expect("a lower end where partial"));
            assert!(lower > 0.0 && lower < factor, "{lower} vs {factor}");
        }
    }

    #[test]
    fn the_pyramid_family_is_lattice_clean_and_its_worst_connector_grows_with_b() {
        let model = Model::default_catom();
        let generate = family("pyramid", 3.6, None, None).unwrap();
        let st = b_study("pyramid", &model, &[4, 5, 6], generate, &Reporter::silent()).unwrap();
        assert_eq!(st.rows.len(), 3);
        for r in &st.rows {
            assert_eq!(r.lattice_violations, 0, "b = {}", r.b);
            assert!(!r.no_equilibrium && r.steps > 0, "b = {}", r.b);
        }
        assert!(
            st.rows
                .windows(2)
                .all(|w| w[1].max_utilisation > w[0].max_utilisation),
            "{:?}",
            st.rows
                .iter()
                .map(|r| r.max_utilisation)
                .collect::<Vec<_>>()
        );
        // From b = 5 the worst connector is the one between the first and
        // second module of a finished horizontal branch: b − 2 modules
        // beyond it, the closed-form moment of b − 3 modules plus an agent.
        for r in &st.rows[1..] {
            let expected = closed_form::cantilever_utilisation(&model, r.b - 3, true);
            assert!(
                (r.max_utilisation - expected).abs() < 1e-6 * expected,
                "b = {}: {} vs {expected}",
                r.b,
                r.max_utilisation
            );
        }
        // Every b here holds at the default 100 kPa.
        assert_eq!(st.b_max, 6);
    }

    /// The layer `z` of the critical connector's upper cell.
    fn critical_layer(r: &Row) -> i32 {
        let c = &r.critical_connector;
        let last = &c[c.rfind('(').expect("cells") + 1..];
        let last = &last[..last.find(')').expect("cells")];
        last.rsplit(", ").next().unwrap().parse().unwrap()
    }

    #[test]
    fn the_rows_do_not_depend_on_who_ran_which_range_nor_in_what_order() {
        // Two b values, one overloaded (limit analyses, a critical step):
        // on this process's threads, and split as two processes would be
        // (even and odd positions of the order, each run backwards, the
        // parts concatenated as rank 0 receives them).
        let model = Model::default_catom();
        let rows = |runner: Runner<'_>| {
            let generate = family("pyramid", 3.6, Some(2), None).unwrap();
            let (rows, unplanned, _) = study_rows(
                &model,
                &[6, 9],
                generate,
                &Reporter::silent(),
                0.0,
                Judging::Every,
                runner,
            )
            .unwrap()
            .expect("this runner folds");
            assert!(unplanned.is_empty());
            format!("{rows:?}")
        };
        let split =
            |order: &[usize],
             job: &(dyn Fn(usize) -> Result<Vec<StepFinding>, InputError> + Sync)| {
                let mut done = Vec::new();
                for parity in [1, 0] {
                    let mine: Vec<usize> = order
                        .iter()
                        .enumerate()
                        .filter(|(k, _)| k % 2 == parity)
                        .map(|(_, &t)| t)
                        .rev()
                        .collect();
                    done.extend(mine.into_iter().map(|t| (t, job(t))));
                }
                Ok(Some(done))
            };
        let threads = rows(&on_threads);
        assert!(threads.contains("limit_analyses: ") && threads.contains("b: 9"));
        assert_eq!(threads, rows(&split));
        // A runner that loses a job is an error, not a short row.
        let lossy =
            |order: &[usize],
             job: &(dyn Fn(usize) -> Result<Vec<StepFinding>, InputError> + Sync)| {
                Ok(Some(order[1..].iter().map(|&t| (t, job(t))).collect()))
            };
        let generate = family("pyramid", 3.6, Some(2), None).unwrap();
        assert!(
            study_rows(
                &model,
                &[6],
                generate,
                &Reporter::silent(),
                0.0,
                Judging::Every,
                &lossy
            )
            .is_err()
        );
    }

    #[test]
    fn judging_only_the_worst_steps_or_until_the_verdict_keeps_the_verdicts_of_judging_every_step()
    {
        // Pyramids at 30 kPa: b = 4 holds, b = 6 and 9 fail (the screen
        // fails: 7 and 92 limit analyses prove 1/λ =
        // 1.156 and 3.469). Worst-only must find the same verdicts, maxima (to the
        // solver's tolerance), critical steps and pressures, with fewer
        // limit analyses, and say how many steps it left bounded. (A factor
        // is proved to the solver's tolerance, 1e-8 of itself, and a step
        // analysed alone starts the solver at another regularisation than
        // one analysed after its range's earlier steps: b = 9's maximum
        // differs by 6.5e-9 of itself.) Until the verdict, the failing rows
        // stop at their first step proved to fail: the same verdicts and
        // pressures, the holding row as worst-only's, a failing row's
        // maximum a lower bound (marked where it is below the true one),
        // fewer steps judged where a failing row would go on.
        // The 2-pyramid's rows at `kpa` (rigid hinge) for `lengths`.
        let pyramid_rows = |kpa: f64, lengths: &[usize], judging: Judging| {
            let model = Model::default_catom().with_connector(kpa * 1e3, Bending::RigidHinge);
            let generate = family("pyramid", 3.6, Some(2), None).unwrap();
            study_rows(
                &model,
                lengths,
                generate,
                &Reporter::silent(),
                0.0,
                judging,
                &on_threads,
            )
            .unwrap()
            .expect("this process folds")
            .0
        };
        let rows = |judging: Judging| pyramid_rows(30.0, &[4, 6, 9], judging);
        let (every, worst, verdict) = (
            rows(Judging::Every),
            rows(Judging::WorstOnly),
            rows(Judging::UntilVerdict),
        );
        assert_eq!(every.len(), 3);
        let mut spared = 0;
        for (e, w) in every.iter().zip(&worst) {
            let what = format!("b = {}: {e:?}\n{w:?}", e.b);
            assert_eq!(e.safe(), w.safe(), "{what}");
            assert_eq!(e.no_equilibrium, w.no_equilibrium, "{what}");
            // The maxima agree to the solver's accuracy; the critical
            // step may be either of two mirror-image steps of one load
            // case, which worst-only need not both judge (b = 6: steps 23
            // and 45, 1/λ equal to 2e-9; b = 9: steps 39 and 77, to
            // 1.5e-7).
            assert!(
                (e.max_utilisation - w.max_utilisation).abs() <= 1e-6 * e.max_utilisation,
                "{what}"
            );
            assert_eq!(
                e.min_pressure_rigid_hinge, w.min_pressure_rigid_hinge,
                "{what}"
            );
            assert_eq!(e.min_pressure_elastic, w.min_pressure_elastic, "{what}");
            assert_eq!(e.steps_bounded, 0);
            assert!(w.limit_analyses <= e.limit_analyses, "{what}");
            spared += w.steps_bounded;
        }
        assert!(spared > 0, "no step was left bounded: {worst:?}");
        assert!(every.iter().any(|r| !r.safe()) && every.iter().any(|r| r.limit_analyses > 0));
        let (mut solved, mut solved_worst, mut judged, mut judged_worst) = (0, 0, 0, 0);
        for ((e, w), v) in every.iter().zip(&worst).zip(&verdict) {
            let what = format!("b = {}: {e:?}\n{v:?}", e.b);
            assert_eq!(e.safe(), v.safe(), "{what}");
            assert_eq!(e.min_pressure_rigid_hinge, v.min_pressure_rigid_hinge);
            assert_eq!(e.min_pressure_elastic, v.min_pressure_elastic);
            if e.safe() {
                assert_eq!(format!("{w:?}"), format!("{v:?}"));
            } else {
                assert!(v.max_utilisation > 1.0, "{what}");
                assert!(
                    v.max_utilisation <= e.max_utilisation * (1.0 + 1e-6),
                    "{what}"
                );
                if v.max_utilisation < e.max_utilisation * (1.0 - 1e-6) {
                    assert!(v.max_utilisation_at_least, "{what}");
                }
            }
            solved += v.limit_analyses;
            solved_worst += w.limit_analyses;
            judged += v.steps_judged;
            judged_worst += w.steps_judged;
        }
        assert!(solved <= solved_worst, "{solved} vs {solved_worst}");
        assert!(judged <= judged_worst, "{judged} vs {judged_worst}");
        // Every step's bound here is finite: the pressures are proved.
        assert!(verdict.iter().all(|r| r.equilibria_unproved == 0));
        // At 5 kPa b = 4 and 5 fail too, and worst-only goes on judging
        // after their first failing step (12 steps each); until the
        // verdict, one batch of 4 decides each.
        let (worst, verdict) = (
            pyramid_rows(5.0, &[4, 5], Judging::WorstOnly),
            pyramid_rows(5.0, &[4, 5], Judging::UntilVerdict),
        );
        for (w, v) in worst.iter().zip(&verdict) {
            assert!(!w.safe() && !v.safe(), "{w:?}\n{v:?}");
            assert!(v.max_utilisation <= w.max_utilisation * (1.0 + 1e-6));
            assert!(v.steps_judged < w.steps_judged, "{w:?}\n{v:?}");
        }
    }

    #[test]
    fn a_row_with_a_step_left_without_a_finite_bound_holds_at_no_pressure_of_the_sweep() {
        // Its pressures come from the elastic loads of steps whose
        // equilibrium was shown; a step left with an infinite bound might
        // need more, so the sweep must not count the row as holding.
        let m = Model::default_catom();
        let mut row = empty_row(4, 10, &m);
        row.max_utilisation = 0.5;
        row.min_pressure_rigid_hinge = 1e3;
        row.min_pressure_elastic = 1e3;
        let b_max_at_150 = |row: &Row| {
            let st = assemble(
                "t",
                &m,
                vec![row.clone()],
                vec![],
                0.0,
                Judging::UntilVerdict,
            );
            let w = st.sweep.iter().find(|w| w.pressure_kpa == 150.0).unwrap();
            (st.b_max, w.b_max_rigid_hinge, w.b_max_elastic, st.table())
        };
        let (b, rh, el, table) = b_max_at_150(&row);
        assert_eq!((b, rh, el), (4, 4, 4));
        assert!(!table.contains("≥1.00"), "{table}");
        row.equilibria_unproved = 1;
        let (_, rh, el, table) = b_max_at_150(&row);
        assert_eq!((rh, el), (0, 0));
        assert!(table.contains("≥1.00"), "{table}");
    }

    #[test]
    fn a_step_judged_at_its_samples_alone_is_counted_and_the_table_says_not_checked() {
        let m = Model::default_catom();
        let finding = |step: usize, sampled_only: bool| StepFinding {
            step,
            lattice_violations: 0,
            no_equilibrium: false,
            partial: false,
            max_utilisation: 0.25,
            critical: String::new(),
            min_pressure_rigid_hinge: 1e3,
            min_pressure_elastic: 1e3,
            limit_analyses: 0,
            bounded: false,
            sampled_only,
        };
        let mut row = empty_row(4, 10, &m);
        for k in 1..=11 {
            row.fold(finding(k, k == 3 || k == 7));
        }
        assert_eq!(row.steps_judged_at_samples, 2);
        let st = assemble("t", &m, vec![row.clone()], vec![], 0.0, Judging::Every);
        assert!(
            st.table().contains(
                "NOT checked: mechanics between the sampled poses of the movers' sweeps, at steps judged at the samples only: b = 4: 2 of 11"
            ),
            "{}",
            st.table()
        );
        row.steps_judged_at_samples = 0;
        let st = assemble("t", &m, vec![row], vec![], 0.0, Judging::Every);
        assert!(!st.table().contains("NOT checked"), "{}", st.table());
    }

    #[test]
    fn a_cube_of_three_tiles_is_limited_by_its_upper_tiles_not_its_ground_branches() {
        // At b = 7 the 2-tile cube holds (its worst connectors lie in the
        // ground-tile layer and its tilted branches); with a second tile
        // layer the connectors of the upper tiles are overloaded: the
        // shape's size lowers b_max (8 → 5, docs/mechanics.md).
        let model = Model::default_catom();
        let two = b_study(
            "cube",
            &model,
            &[7],
            family("cube", 3.6, Some(2), None).unwrap(),
            &Reporter::silent(),
        )
        .unwrap();
        let three = b_study(
            "cube",
            &model,
            &[7],
            family("cube", 3.6, Some(3), None).unwrap(),
            &Reporter::silent(),
        )
        .unwrap();
        let (two, three) = (&two.rows[0], &three.rows[0]);
        assert!(two.max_utilisation < 1.0, "{two:?}");
        assert!(three.max_utilisation > 1.3, "{three:?}");
        assert_eq!(three.lattice_violations, 0);
        assert!(critical_layer(three) > 2, "{}", three.critical_connector);
    }

    #[test]
    fn the_cube_family_is_lattice_clean_and_its_worst_connector_grows_with_b() {
        let model = Model::default_catom();
        let generate = family("cube", 3.6, None, None).unwrap();
        let st = b_study("cube", &model, &[4, 5], generate, &Reporter::silent()).unwrap();
        for r in &st.rows {
            assert_eq!(r.lattice_violations, 0, "b = {}", r.b);
            assert!(!r.no_equilibrium, "b = {}", r.b);
        }
        assert!(st.rows[1].max_utilisation > st.rows[0].max_utilisation);
        // A cube of 2 tiles a side holds more modules than the 2-pyramid of
        // equal b, and more as b grows.
        let modules = |f: &str, b: usize| {
            family(f, 3.6, None, None).unwrap()(b).unwrap().meta["scaffold_modules"]
                .as_u64()
                .unwrap()
        };
        assert!(modules("cube", 4) > modules("pyramid", 4));
        assert!(modules("cube", 5) > modules("cube", 4));
    }

    #[test]
    fn scaffold_families_take_the_size_and_refuse_bad_input() {
        let small = family("pyramid", 3.6, Some(1), None).unwrap()(4).unwrap();
        let large = family("pyramid", 3.6, Some(2), None).unwrap()(4).unwrap();
        assert!(small.steps.len() < large.steps.len());
        // The model's spacing is carried into the schedule.
        let s = family("pyramid", 2.0, Some(1), None).unwrap()(4).unwrap();
        assert!((s.spacing.metres() - 2e-3).abs() < 1e-12);
        // Seed 000 needs b ≥ 4; size 0 and unknown families are refused.
        assert!(family("pyramid", 3.6, None, None).unwrap()(3).is_err());
        assert!(family("cube", 3.6, Some(0), None).is_err());
        let e = family("torus", 3.6, None, None).err().unwrap();
        assert!(e.to_string().contains("pyramid"), "{e}");
    }

    #[cfg(feature = "render")]
    #[test]
    fn the_plot_is_written_as_png() {
        let model = Model::default_catom();
        let st = b_study(
            "branch",
            &model,
            &[1, 2, 3],
            |b| branch_schedule(b, 3.6),
            &Reporter::silent(),
        )
        .unwrap();
        let dir = std::env::temp_dir().join(format!("reconfcheck-bstudy-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("b.png");
        crate::render::b_study_plot(&st, &p).unwrap();
        let bytes = std::fs::read(&p).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        // A maximum that is only a lower bound (≥) is drawn hollow, with
        // its own legend entry; none without one.
        let svg = |st: &Study| {
            let p = dir.join("b.svg");
            crate::render::b_study_plot(st, &p).unwrap();
            std::fs::read_to_string(&p).unwrap()
        };
        let note = "a lower bound (poses or steps left unjudged)";
        assert!(!svg(&st).contains(note));
        let mut bounded = st.clone();
        bounded.rows[2].max_utilisation_at_least = true;
        assert!(svg(&bounded).contains(note));
        std::fs::remove_dir_all(&dir).ok();
    }
}
