//! Seed 001's Figs. 9 and 10.
//!
//! Fig. 9: how many catoms move concurrently, and how many streamlines are
//! in use, at each time step of a RePoSt reconfiguration, with a row per
//! iteration (the paper's "bell curves"). The paper's observation to
//! compare with: the peak of an iteration is the meta-module size (10
//! catoms) times its streamlines, reached when every catom of the
//! dismantled sources moves at once.
//!
//! Fig. 10: the L → C reconfiguration at several sizes; time steps
//! against the configuration's diameter (the paper: linear), messages
//! against rotations (the paper: proportional; the messages are what the
//! authors' distributed protocol would send to carry out the plan,
//! [`crate::algorithms::repost::messages`]) and rotations against size,
//! with least-squares fits.

use super::fit::{LinearFit, linear_fit};
use crate::algorithms::repost::messages::Messages;
use crate::algorithms::repost::metamodule::Meta;
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
    /// Whether the catoms ran pipelined or (a catom fitting nowhere in
    /// the pipeline) one at a time.
    pub pipelined: bool,
    /// What the distributed protocol would send (all phases).
    pub messages: usize,
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

/// Refuses a scenario that is not the RePoSt planner's.
fn planner_scenario(scenario: &Scenario) -> Result<(), InputError> {
    if scenario.algorithm == "repost" {
        return Ok(());
    }
    Err(InputError::new(format!(
        "algorithm '{}' is not RePoSt's planner: the study needs a scenario with algorithm = \"repost\"",
        scenario.algorithm
    ))
    .in_file(&scenario.path))
}

/// Plans a `repost` scenario and measures its concurrency.
pub fn fig9(scenario: &Scenario) -> Result<Fig9, InputError> {
    planner_scenario(scenario)?;
    let p = plan_scenario(scenario)?;
    Ok(from_plan(&scenario.name, &p.plan))
}

/// One size of Fig. 10.
#[derive(Clone, Debug, Serialize)]
pub struct SizeRow {
    pub scenario: String,
    /// Meta-modules (of the initial shape; the goal has as many).
    pub metas: usize,
    /// The larger of the two shapes' diameters: the most face-to-face
    /// steps between two meta-modules of one shape (breadth first).
    pub diameter: usize,
    pub iterations: usize,
    pub steps: usize,
    pub rotations: usize,
    /// Summed over the iterations, by phase.
    pub messages: Messages,
}

/// Fig. 10's rows and fits.
#[derive(Clone, Debug, Serialize)]
pub struct Fig10 {
    pub rows: Vec<SizeRow>,
    /// Time steps against the diameter.
    pub steps_vs_diameter: Option<LinearFit>,
    /// Rotations against the meta-module count.
    pub rotations_vs_metas: Option<LinearFit>,
    /// Messages against rotations (the paper's Fig. 10a).
    pub messages_vs_rotations: Option<LinearFit>,
}

/// The graph diameter of a shape: the longest of the shortest
/// face-to-face paths between its meta-modules (0 for one or none; a
/// disconnected shape counts each part's).
pub fn diameter(metas: &std::collections::BTreeSet<Meta>) -> usize {
    let mut best = 0;
    for &a in metas {
        let mut seen = std::collections::BTreeMap::from([(a, 0usize)]);
        let mut queue = std::collections::VecDeque::from([a]);
        while let Some(m) = queue.pop_front() {
            let d = seen[&m];
            best = best.max(d);
            for n in m.adjacent() {
                if metas.contains(&n) && !seen.contains_key(&n) {
                    seen.insert(n, d + 1);
                    queue.push_back(n);
                }
            }
        }
    }
    best
}

/// Plans each scenario (the sizes of Fig. 10) and fits the paper's two
/// claims; `progress` is told each scenario as it starts.
pub fn fig10(scenarios: &[Scenario], progress: &dyn Fn(&str)) -> Result<Fig10, InputError> {
    let mut rows = Vec::new();
    for sc in scenarios {
        planner_scenario(sc)?;
        progress(&sc.name);
        let p = plan_scenario(sc)?;
        let start: std::collections::BTreeSet<Meta> = p.initial.keys().copied().collect();
        rows.push(SizeRow {
            scenario: sc.name.clone(),
            metas: start.len(),
            diameter: diameter(&start).max(diameter(&p.goal.keys().copied().collect())),
            iterations: p.plan.iterations.len(),
            steps: p.plan.steps.len(),
            rotations: p.plan.steps.iter().map(Vec::len).sum(),
            messages: p.plan.iterations.iter().map(|it| it.messages).sum(),
        });
    }
    let pts = |f: &dyn Fn(&SizeRow) -> (f64, f64)| rows.iter().map(f).collect::<Vec<_>>();
    Ok(Fig10 {
        steps_vs_diameter: linear_fit(&pts(&|r| (r.diameter as f64, r.steps as f64))),
        rotations_vs_metas: linear_fit(&pts(&|r| (r.metas as f64, r.rotations as f64))),
        messages_vs_rotations: linear_fit(&pts(&|r| {
            (r.rotations as f64, r.messages.total() as f64)
        })),
        rows,
    })
}

/// Fig. 10's table and fits.
pub fn fig10_table(f: &Fig10) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "Fig. 10: L -> C at several sizes");
    let _ = writeln!(
        s,
        "{:<22} {:>6} {:>8} {:>10} {:>6} {:>9} {:>9} {:>7} {:>8} {:>7} {:>9}",
        "scenario",
        "metas",
        "diameter",
        "iterations",
        "steps",
        "rotations",
        "messages",
        "tree",
        "max-flow",
        "termin.",
        "transport"
    );
    for r in &f.rows {
        let m = &r.messages;
        let _ = writeln!(
            s,
            "{:<22} {:>6} {:>8} {:>10} {:>6} {:>9} {:>9} {:>7} {:>8} {:>7} {:>9}",
            r.scenario,
            r.metas,
            r.diameter,
            r.iterations,
            r.steps,
            r.rotations,
            m.total(),
            m.tree,
            m.max_flow,
            m.termination,
            m.transport
        );
    }
    let line = |name: &str, fit: &Option<LinearFit>| match fit {
        Some(f) => format!(
            "{name}: slope {:.2}, intercept {:.1}, R² {:.3}\n",
            f.slope, f.intercept, f.r2
        ),
        None => format!("{name}: no fit (fewer than two distinct sizes)\n"),
    };
    s += &line("time steps vs diameter", &f.steps_vs_diameter);
    s += &line("rotations vs meta-modules", &f.rotations_vs_metas);
    s += &line("messages vs rotations", &f.messages_vs_rotations);
    s
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
                messages: it.messages.total(),
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
        "{:>4} {:>6} {:>6} {:>9} {:>11} {:>5} {:>11} {:>6} {:>9} {:>9}",
        "it",
        "first",
        "steps",
        "rotations",
        "streamlines",
        "peak",
        "10×streaml.",
        "mean",
        "pipelined",
        "messages"
    );
    for r in &f.iterations {
        let _ = writeln!(
            s,
            "{:>4} {:>6} {:>6} {:>9} {:>11} {:>5} {:>11} {:>6.2} {:>9} {:>9}",
            r.iteration,
            r.first_step + 1,
            r.steps,
            r.rotations,
            r.streamlines,
            r.peak,
            CATOMS_PER_META * r.streamlines,
            r.mean,
            if r.pipelined { "yes" } else { "no" },
            r.messages
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    #[test]
    fn the_diameter_counts_face_steps_between_the_farthest_meta_modules() {
        let m = |x, y, z| Meta { x, y, z };
        assert_eq!(diameter(&BTreeSet::new()), 0);
        assert_eq!(diameter(&BTreeSet::from([m(0, 0, 0)])), 0);
        let line: BTreeSet<Meta> = (0..5).map(|x| m(x, 0, 0)).collect();
        assert_eq!(diameter(&line), 4);
        // An L: 4 along X, then 3 up from its first: (3,0,0) to (0,0,3) is 6.
        let mut l = line.clone();
        l.remove(&m(4, 0, 0));
        l.extend((1..4).map(|z| m(0, 0, z)));
        assert_eq!(diameter(&l), 6);
        // A U: the ends are 2 apart in space but 6 apart through the shape.
        let u: BTreeSet<Meta> = [
            m(0, 0, 2),
            m(0, 0, 1),
            m(0, 0, 0),
            m(1, 0, 0),
            m(2, 0, 0),
            m(2, 0, 1),
            m(2, 0, 2),
        ]
        .into();
        assert_eq!(diameter(&u), 6);
    }
}
