//! Seed 002's figures, recomputed: Fig. 10 (messages against modules, four
//! shapes at three scales), Fig. 11 (available docking positions against
//! percent built, mean and spread over seeds) and the naive orders of
//! Fig. 3 against the planner.
//!
//! The shapes are the bundled CSG files of `models/docking/`, at the base
//! scales of [`SHAPES`] (each doubled twice, as the paper scales by two).

use super::fit::{LinearFit, linear_fit};
use crate::algorithms::docking::goal::Goal;
use crate::algorithms::docking::naive::{self, NaiveCounts, Order};
use crate::algorithms::docking::planner::{self, Delays};
use crate::algorithms::docking::seed_cell_of;
use crate::error::InputError;
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;

/// The paper's four shape classes: (name, CSG file in `models/docking/`,
/// base scale). The power button's base scale gives 824, 3,335 and 13,420
/// modules at ×1, ×2, ×4 (the paper: 815, 3,318, 13,233); the others'
/// give comparable sizes.
pub const SHAPES: &[(&str, &str, f64)] = &[
    ("power button", "power-button.csg", 1.79),
    ("letter C", "letter-c.csg", 0.62),
    ("bumpy", "bumpy.csg", 0.52),
    ("2D locomotive", "locomotive-2d.csg", 1.11),
];

/// Scale factors of the three versions of each shape.
pub const FACTORS: [f64; 3] = [1.0, 2.0, 4.0];

/// Loads shape `i` of [`SHAPES`] at `factor` × its base scale.
pub fn goal(models: &Path, i: usize, factor: f64) -> Result<Goal, InputError> {
    let (_, file, base) = SHAPES[i];
    Goal::from_csg(&models.join(file), base * factor, 0.0)
}

/// One Fig. 10 point: a shape at one scale, over seeds.
#[derive(Clone, Debug, Serialize)]
pub struct MessageRow {
    pub shape: String,
    pub factor: f64,
    pub modules: usize,
    /// Mean over seeds of the total, and of each part.
    pub messages: f64,
    pub initial: f64,
    pub permission: f64,
    pub sync: f64,
    pub per_module: f64,
    /// Mean total as the authors' paper-era code counts it (see
    /// [`planner::Messages`]), and per module.
    pub messages_paper_era: f64,
    pub paper_era_per_module: f64,
    /// Sum over seeds of Rule 1 violations and of unfilled cells.
    pub rule1_violations: usize,
    pub unfilled: usize,
}

/// Fig. 10: every shape at every scale, `seeds` runs each.
pub fn messages(models: &Path, seeds: u64) -> Result<Vec<MessageRow>, InputError> {
    let mut jobs = Vec::new();
    for i in 0..SHAPES.len() {
        for f in FACTORS {
            jobs.push((i, f));
        }
    }
    jobs.par_iter()
        .map(|&(i, f)| {
            let g = goal(models, i, f)?;
            let start = seed_cell_of(&g, None)?;
            let runs: Vec<_> = (0..seeds)
                .map(|s| planner::run(&g, start, s, &Delays::default()))
                .collect();
            let k = runs.len() as f64;
            let mean =
                |f: &dyn Fn(&planner::Run) -> u64| runs.iter().map(f).sum::<u64>() as f64 / k;
            let messages = mean(&|r| r.messages.total());
            let paper_era = mean(&|r| r.messages.total_paper());
            Ok(MessageRow {
                messages_paper_era: paper_era,
                paper_era_per_module: paper_era / g.len() as f64,
                shape: SHAPES[i].0.to_string(),
                factor: f,
                modules: g.len(),
                messages,
                initial: mean(&|r| r.messages.initial),
                permission: mean(&|r| r.messages.permission),
                sync: mean(&|r| r.messages.sync),
                per_module: messages / g.len() as f64,
                rule1_violations: runs.iter().map(|r| r.rule1_violations).sum(),
                unfilled: runs.iter().map(|r| r.unfilled).sum(),
            })
        })
        .collect()
}

/// The paper's claim for Fig. 10: about five messages per module ("≈ 5n").
pub const PAPER_MESSAGES_PER_MODULE: f64 = 5.0;

/// Fig. 10's fits: per shape (in the order of `rows`), the least-squares
/// line of mean messages against modules over its scales. A shape with
/// fewer than two scales has no fit and is left out.
pub fn message_fits(rows: &[MessageRow]) -> Vec<(String, LinearFit)> {
    let mut shapes: Vec<&str> = Vec::new();
    for r in rows {
        if !shapes.contains(&r.shape.as_str()) {
            shapes.push(&r.shape);
        }
    }
    shapes
        .into_iter()
        .filter_map(|s| {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.shape == s)
                .map(|r| (r.modules as f64, r.messages))
                .collect();
            linear_fit(&pts).map(|f| (s.to_string(), f))
        })
        .collect()
}

/// One Fig. 11 curve: D/√N at each percent built, mean and standard
/// deviation over seeds.
#[derive(Clone, Debug, Serialize)]
pub struct AvailabilityCurve {
    pub shape: String,
    pub modules: usize,
    /// Percent built at each point (5, 10, …, 100).
    pub percent: Vec<u32>,
    pub mean: Vec<f64>,
    pub std: Vec<f64>,
}

/// Percent steps of the Fig. 11 table.
pub const PERCENT_STEP: u32 = 5;

/// Fig. 11: every shape at `factor`, `seeds` runs each.
pub fn availability(
    models: &Path,
    factor: f64,
    seeds: u64,
) -> Result<Vec<AvailabilityCurve>, InputError> {
    (0..SHAPES.len())
        .into_par_iter()
        .map(|i| {
            let g = goal(models, i, factor)?;
            let start = seed_cell_of(&g, None)?;
            let n = g.len();
            let percent: Vec<u32> = (1..=100 / PERCENT_STEP).map(|k| k * PERCENT_STEP).collect();
            let samples: Vec<Vec<f64>> = (0..seeds)
                .map(|s| {
                    let r = planner::run(&g, start, s, &Delays::default());
                    percent
                        .iter()
                        .map(|&p| {
                            let k = ((p as usize * n).div_ceil(100)).clamp(1, r.available.len());
                            r.available[k - 1] as f64 / (n as f64).sqrt()
                        })
                        .collect()
                })
                .collect();
            let k = samples.len() as f64;
            let mean: Vec<f64> = (0..percent.len())
                .map(|j| samples.iter().map(|s| s[j]).sum::<f64>() / k)
                .collect();
            let std = (0..percent.len())
                .map(|j| {
                    let m = mean[j];
                    (samples.iter().map(|s| (s[j] - m).powi(2)).sum::<f64>() / k).sqrt()
                })
                .collect();
            Ok(AvailabilityCurve {
                shape: SHAPES[i].0.to_string(),
                modules: n,
                percent,
                mean,
                std,
            })
        })
        .collect()
}

/// Naive orders against the planner on one shape.
#[derive(Clone, Debug, Serialize)]
pub struct NaiveRow {
    pub shape: String,
    pub modules: usize,
    pub random: NaiveCounts,
    pub neighbourhood: NaiveCounts,
    pub planner: NaiveCounts,
}

/// Fig. 3's baselines on every shape at `factor`.
pub fn naive_orders(models: &Path, factor: f64, seed: u64) -> Result<Vec<NaiveRow>, InputError> {
    (0..SHAPES.len())
        .into_par_iter()
        .map(|i| {
            let g = goal(models, i, factor)?;
            let start = seed_cell_of(&g, None)?;
            let r = planner::run(&g, start, seed, &Delays::default());
            Ok(NaiveRow {
                shape: SHAPES[i].0.to_string(),
                modules: g.len(),
                random: naive::run(&g, start, Order::Random, seed),
                neighbourhood: naive::run(&g, start, Order::Neighbourhood, seed),
                planner: NaiveCounts {
                    violations: r.rule1_violations,
                    unfillable: r.unfilled,
                },
            })
        })
        .collect()
}

/// The three tables as text.
pub fn tables(messages: &[MessageRow], curves: &[AvailabilityCurve], naive: &[NaiveRow]) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(s, "Fig. 10 — messages against modules (mean over seeds)");
    let _ = writeln!(
        s,
        "{:<14} {:>6} {:>7} {:>10} {:>9} {:>10} {:>8} {:>7} {:>9} {:>6} {:>8}",
        "shape",
        "scale",
        "n",
        "messages",
        "initial",
        "permission",
        "sync",
        "msg/n",
        "2017-11/n",
        "R1",
        "unfilled"
    );
    for r in messages {
        let _ = writeln!(
            s,
            "{:<14} {:>6} {:>7} {:>10.0} {:>9.0} {:>10.0} {:>8.0} {:>7.2} {:>9.2} {:>6} {:>8}",
            r.shape,
            format!("×{}", r.factor),
            r.modules,
            r.messages,
            r.initial,
            r.permission,
            r.sync,
            r.per_module,
            r.paper_era_per_module,
            r.rule1_violations,
            r.unfilled
        );
    }
    let fits = message_fits(messages);
    if !fits.is_empty() {
        let _ = writeln!(
            s,
            "least-squares fit of messages against n (the paper: ≈ {PAPER_MESSAGES_PER_MODULE}n)"
        );
        for (shape, f) in &fits {
            let _ = writeln!(
                s,
                "{shape:<14} {:.3} n {} {:>5.0}   (R² {:.6})",
                f.slope,
                if f.intercept < 0.0 { '−' } else { '+' },
                f.intercept.abs(),
                f.r2
            );
        }
    }
    let _ = writeln!(
        s,
        "\nFig. 11 — available docking positions D/√N against percent built (mean ± sd over seeds)"
    );
    let _ = write!(s, "{:>5}", "%");
    for c in curves {
        let _ = write!(s, " {:>20}", format!("{} ({})", c.shape, c.modules));
    }
    let _ = writeln!(s);
    if let Some(first) = curves.first() {
        for (j, p) in first.percent.iter().enumerate() {
            let _ = write!(s, "{p:>5}");
            for c in curves {
                let _ = write!(s, " {:>20}", format!("{:.3} ± {:.3}", c.mean[j], c.std[j]));
            }
            let _ = writeln!(s);
        }
    }
    let _ = writeln!(
        s,
        "\nFig. 3 — naive orders: Rule 1 violations (all docked) / cells left unfillable (forbidden dockings refused)"
    );
    let _ = writeln!(
        s,
        "{:<14} {:>7} {:>16} {:>20} {:>12}",
        "shape", "n", "random", "neighbourhood fill", "planner"
    );
    for r in naive {
        let f = |c: &NaiveCounts| format!("{} / {}", c.violations, c.unfillable);
        let _ = writeln!(
            s,
            "{:<14} {:>7} {:>16} {:>20} {:>12}",
            r.shape,
            r.modules,
            f(&r.random),
            f(&r.neighbourhood),
            f(&r.planner)
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(shape: &str, modules: usize, messages: f64) -> MessageRow {
        MessageRow {
            shape: shape.into(),
            factor: 1.0,
            modules,
            messages,
            initial: 0.0,
            permission: 0.0,
            messages_paper_era: 0.0,
            paper_era_per_module: 0.0,
            sync: 0.0,
            per_module: messages / modules as f64,
            rule1_violations: 0,
            unfilled: 0,
        }
    }

    #[test]
    fn message_fits_fit_each_shape_apart_in_the_rows_order() {
        let rows = [
            row("b", 100, 300.0),
            row("a", 100, 500.0),
            row("b", 200, 600.0),
            row("a", 300, 1500.0),
            row("lone", 50, 1.0),
        ];
        let fits = message_fits(&rows);
        let names: Vec<&str> = fits.iter().map(|(s, _)| s.as_str()).collect();
        assert_eq!(names, ["b", "a"]);
        assert!((fits[0].1.slope - 3.0).abs() < 1e-12);
        assert!((fits[1].1.slope - 5.0).abs() < 1e-12);
        assert!(fits[1].1.intercept.abs() < 1e-9);
    }
}
