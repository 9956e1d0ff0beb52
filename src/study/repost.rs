//! Seed 001's Fig. 9: how many catoms move concurrently, and how many
//! streamlines are in use, at each time step of a RePoSt reconfiguration,
//! with a row per iteration (the paper's "bell curves").
//!
//! The paper's observation to compare with: the peak of an iteration is
//! the meta-module size (10 catoms) times its streamlines, reached when
//! every catom of the dismantled sources moves at once.

use crate::algorithms::repost::{plan_scenario, planner::Plan};
use crate::error::InputError;
use crate::scenario::Scenario;
use serde::Serialize;
use std::fmt::Write;

/// Catoms of a SPARSE meta-module: the paper's unit of peak concurrency.
pub const CATOMS_PER_META: usize = 10;

/// One iteration's figures.
#[derive(Clone, Debug, Serialize)]
pub struct IterationRow {
    /// 1-based, as the paper counts.
    pub iteration: usize,
    pub first_step: usize,
    pub steps: usize,
    pub rotations: usize,
    pub streamlines: usize,
    /// Most rotations in one step.
    pub peak: usize,
    /// Rotations per step, on average over the iteration.
    pub mean: f64,
    /// Whether the catoms ran pipelined or (the pipeline failing its
    /// anchoring replay) one at a time.
    pub pipelined: bool,
}

/// Fig. 9's two curves and the iteration table.
#[derive(Clone, Debug, Serialize)]
pub struct Fig9 {
    pub scenario: String,
    /// Rotations at each time step.
    pub motions: Vec<usize>,
    /// Streamlines under way at each time step.
    pub streamlines: Vec<usize>,
    pub iterations: Vec<IterationRow>,
}

/// Plans a `repost` scenario and measures its concurrency.
pub fn fig9(scenario: &Scenario) -> Result<Fig9, InputError> {
    if scenario.algorithm != "repost" {
        return Err(InputError::new(format!(
            "algorithm '{}' is not RePoSt's planner: Fig. 9 needs a scenario with algorithm = \"repost\"",
            scenario.algorithm
        ))
        .in_file(&scenario.path));
    }
    let (plan, _) = plan_scenario(scenario)?;
    Ok(from_plan(&scenario.name, &plan))
}

/// Fig. 9's data of a plan.
pub fn from_plan(name: &str, plan: &Plan) -> Fig9 {
    let motions: Vec<usize> = plan.steps.iter().map(Vec::len).collect();
    let iterations = plan
        .iterations
        .iter()
        .enumerate()
        .map(|(i, it)| {
            let m = &motions[it.first_step..it.first_step + it.steps];
            IterationRow {
                iteration: i + 1,
                first_step: it.first_step,
                steps: it.steps,
                rotations: m.iter().sum(),
                streamlines: it.streamlines.len(),
                peak: m.iter().copied().max().unwrap_or(0),
                mean: m.iter().sum::<usize>() as f64 / it.steps.max(1) as f64,
                pipelined: it.pipelined,
            }
        })
        .collect();
    Fig9 {
        scenario: name.to_string(),
        motions,
        streamlines: plan.streamlines_at.clone(),
        iterations,
    }
}

/// The iteration table, with the paper's peak (10 × streamlines) beside
/// ours, and the totals.
pub fn table(f: &Fig9) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Fig. 9, {}: concurrent rotations per time step",
        f.scenario
    );
    let _ = writeln!(
        s,
        "{:>4} {:>6} {:>6} {:>9} {:>11} {:>5} {:>11} {:>6} {:>9}",
        "it",
        "first",
        "steps",
        "rotations",
        "streamlines",
        "peak",
        "10×streaml.",
        "mean",
        "pipelined"
    );
    for r in &f.iterations {
        let _ = writeln!(
            s,
            "{:>4} {:>6} {:>6} {:>9} {:>11} {:>5} {:>11} {:>6.2} {:>9}",
            r.iteration,
            r.first_step + 1,
            r.steps,
            r.rotations,
            r.streamlines,
            r.peak,
            CATOMS_PER_META * r.streamlines,
            r.mean,
            if r.pipelined { "yes" } else { "no" }
        );
    }
    let total: usize = f.motions.iter().sum();
    let _ = writeln!(
        s,
        "total: {} iterations, {} time steps, {} rotations, {:.2} per step on average, at most {}",
        f.iterations.len(),
        f.motions.len(),
        total,
        total as f64 / f.motions.len().max(1) as f64,
        f.motions.iter().copied().max().unwrap_or(0)
    );
    s
}
