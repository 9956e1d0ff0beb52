//! The density study of seed 003 §V-B1 (Fig. 10): random desired
//! configurations of densities 10–70 % in 10 × 10 and 20 × 20 squares, the
//! same samples for SAS and PAS, time normalised by the number of excluded
//! modules; a table; the box plot is
//! [`crate::render::density`]'s.

use crate::algorithms::active_subtraction::pas::{self, PasTimes};
use crate::algorithms::active_subtraction::random::{Growth, random_shape_grown};
use crate::algorithms::active_subtraction::sas;
use crate::error::InputError;
use crate::progress::Reporter;
use rayon::prelude::*;
use serde::Serialize;

/// What to sample.
#[derive(Clone, Debug, Serialize)]
pub struct StudyConfig {
    /// Side lengths of the initial squares.
    pub sizes: Vec<i32>,
    /// Densities ρ in percent.
    pub densities: Vec<u32>,
    pub samples: usize,
    /// Base seed; sample `k` of `(size, ρ)` uses a seed derived from all four.
    pub seed: u64,
    /// How the random desired configurations grow.
    pub growth: Growth,
}

/// One random configuration, run with both solutions.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Sample {
    pub size: i32,
    pub density: u32,
    pub seed: u64,
    pub excluded: usize,
    /// Time steps per excluded module.
    pub sas: f64,
    pub pas: f64,
    /// Best-case sequential time (a lower bound for SAS), normalised too.
    pub best: f64,
}

/// Quartiles and whiskers (1.5 IQR, clipped to the data) of a sample set.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Summary {
    pub low: f64,
    pub q1: f64,
    pub median: f64,
    pub q3: f64,
    pub high: f64,
}

impl Summary {
    pub fn of(values: &[f64]) -> Summary {
        let mut v = values.to_vec();
        v.sort_by(f64::total_cmp);
        let q = |p: f64| {
            let x = p * (v.len() - 1) as f64;
            let (i, f) = (x.floor() as usize, x.fract());
            if i + 1 < v.len() {
                v[i] * (1.0 - f) + v[i + 1] * f
            } else {
                v[i]
            }
        };
        let (q1, median, q3) = (q(0.25), q(0.5), q(0.75));
        let iqr = q3 - q1;
        let low = v
            .iter()
            .copied()
            .find(|&x| x >= q1 - 1.5 * iqr)
            .unwrap_or(q1);
        let high = v
            .iter()
            .rev()
            .copied()
            .find(|&x| x <= q3 + 1.5 * iqr)
            .unwrap_or(q3);
        Summary {
            low,
            q1,
            median,
            q3,
            high,
        }
    }
}

fn sample_seed(base: u64, size: i32, density: u32, k: usize) -> u64 {
    base.wrapping_mul(1_000_003)
        .wrapping_add(size as u64 * 1_000_000)
        .wrapping_add(density as u64 * 10_000)
        .wrapping_add(k as u64)
}

/// Runs the study (in parallel over samples). Deterministic for a config.
pub fn run(cfg: &StudyConfig) -> Result<Vec<Sample>, InputError> {
    run_observed(cfg, &Reporter::silent())
}

/// Samples one study draws: sizes × densities × samples.
pub fn sample_count(cfg: &StudyConfig) -> usize {
    cfg.sizes.len() * cfg.densities.len() * cfg.samples
}

/// [`run`], advancing `bar` by one per sample.
pub fn run_observed(cfg: &StudyConfig, bar: &Reporter) -> Result<Vec<Sample>, InputError> {
    let jobs: Vec<(i32, u32, usize)> = cfg
        .sizes
        .iter()
        .flat_map(|&s| {
            cfg.densities
                .iter()
                .flat_map(move |&d| (0..cfg.samples).map(move |k| (s, d, k)))
        })
        .collect();
    jobs.par_iter()
        .map(|&(size, density, k)| {
            let seed = sample_seed(cfg.seed, size, density, k);
            let shape = random_shape_grown(size, size, density as f64 / 100.0, seed, cfg.growth)?;
            let run = sas::run(&shape)?;
            let n = run.removals.len().max(1) as f64;
            let sas_t = PasTimes::sequential(&run).time_steps() as f64;
            let pas_t = pas::plan(&shape, &run)?.time_steps() as f64;
            let best = sas::best_case_time(&shape) as f64 / n;
            bar.advance(1);
            Ok(Sample {
                size,
                density,
                seed,
                excluded: run.removals.len(),
                sas: sas_t / n,
                pas: pas_t / n,
                best,
            })
        })
        .collect()
}

/// The summaries of one `(size, density)` box.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Row {
    pub size: i32,
    pub density: u32,
    pub sas: Summary,
    pub pas: Summary,
    pub best: Summary,
}

/// Per `(size, density)`: the SAS, PAS and best-case summaries.
pub fn summarise(cfg: &StudyConfig, samples: &[Sample]) -> Vec<Row> {
    let mut out = Vec::new();
    for &size in &cfg.sizes {
        for &density in &cfg.densities {
            let of = |f: fn(&Sample) -> f64| -> Vec<f64> {
                samples
                    .iter()
                    .filter(|s| s.size == size && s.density == density)
                    .map(f)
                    .collect()
            };
            let (a, b, c) = (of(|s| s.sas), of(|s| s.pas), of(|s| s.best));
            if !a.is_empty() {
                out.push(Row {
                    size,
                    density,
                    sas: Summary::of(&a),
                    pas: Summary::of(&b),
                    best: Summary::of(&c),
                });
            }
        }
    }
    out
}

/// How much a box's median moves between independent studies: the mean
/// and standard deviation, over `repeats` studies with base seeds
/// `cfg.seed, cfg.seed + 1, …`, of the SAS and best-case medians per
/// `(size, density)`. Tells a trend from the noise of one 80-sample study
/// (seed 003's Fig. 10 is one such study).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Spread {
    pub size: i32,
    pub density: u32,
    /// Studies repeated.
    pub repeats: usize,
    /// (mean, standard deviation) of the SAS median.
    pub sas: (f64, f64),
    /// (mean, standard deviation) of the best-case median.
    pub best: (f64, f64),
    /// Studies in which this box's SAS median is below the previous
    /// density's (a "fall"); 0 for the first density.
    pub sas_falls: usize,
    /// Studies whose highest SAS median (over this size's densities) is
    /// this box's: where the curve peaks.
    pub sas_peaks: usize,
    /// The same for the best-case median.
    pub best_peaks: usize,
}

/// Per size, the studies whose curve "rises to a point and falls again"
/// (seed 003 §VI): the highest median at neither the lowest nor the highest
/// density. Returns `(size, SAS count, best-case count)`.
pub fn rise_and_fall(rows: &[Spread]) -> Vec<(i32, usize, usize)> {
    let mut out: Vec<(i32, usize, usize)> = Vec::new();
    for (k, r) in rows.iter().enumerate() {
        let first = k == 0 || rows[k - 1].size != r.size;
        let last = k + 1 == rows.len() || rows[k + 1].size != r.size;
        if first {
            out.push((r.size, 0, 0));
        }
        if !first && !last {
            let e = out.last_mut().expect("pushed at the size's first row");
            e.1 += r.sas_peaks;
            e.2 += r.best_peaks;
        }
    }
    out
}

/// Runs `repeats` studies (see [`Spread`]).
pub fn spread(cfg: &StudyConfig, repeats: usize) -> Result<Vec<Spread>, InputError> {
    spread_observed(cfg, repeats, &Reporter::silent())
}

/// [`spread`], advancing `bar` by one per sample of every study.
pub fn spread_observed(
    cfg: &StudyConfig,
    repeats: usize,
    bar: &Reporter,
) -> Result<Vec<Spread>, InputError> {
    let mut medians: Vec<Vec<Row>> = Vec::new();
    for r in 0..repeats as u64 {
        let c = StudyConfig {
            seed: cfg.seed.wrapping_add(r),
            ..cfg.clone()
        };
        medians.push(summarise(&c, &run_observed(&c, bar)?));
    }
    let stats = |v: &[f64]| {
        let n = v.len() as f64;
        let m = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
        (m, var.sqrt())
    };
    let first = medians.first().cloned().unwrap_or_default();
    Ok(first
        .iter()
        .enumerate()
        .map(|(k, row)| {
            let sas: Vec<f64> = medians.iter().map(|rs| rs[k].sas.median).collect();
            let best: Vec<f64> = medians.iter().map(|rs| rs[k].best.median).collect();
            let prev_same_size = k > 0 && first[k - 1].size == row.size;
            // Where each study's curve peaks: the first of its highest medians.
            let same_size: Vec<usize> = (0..first.len())
                .filter(|&j| first[j].size == row.size)
                .collect();
            let peaks = |f: fn(&Row) -> f64| {
                medians
                    .iter()
                    .filter(|rs| {
                        let top = same_size
                            .iter()
                            .copied()
                            .reduce(|a, b| if f(&rs[b]) > f(&rs[a]) { b } else { a });
                        top == Some(k)
                    })
                    .count()
            };
            let sas_falls = if prev_same_size {
                medians
                    .iter()
                    .filter(|rs| rs[k].sas.median < rs[k - 1].sas.median)
                    .count()
            } else {
                0
            };
            Spread {
                size: row.size,
                density: row.density,
                repeats,
                sas: stats(&sas),
                best: stats(&best),
                sas_falls,
                sas_peaks: peaks(|r| r.sas.median),
                best_peaks: peaks(|r| r.best.median),
            }
        })
        .collect())
}

/// The spread table, one row per `(size, density)`.
pub fn spread_table(rows: &[Spread], repeats: usize) -> String {
    let mut s = format!(
        "medians over {repeats} studies (mean ± sd); studies whose SAS median is below the previous ρ's, and whose curves peak at this ρ\nsize    rho  SAS median       best-case median   SAS below previous   SAS peak   best peak\n"
    );
    for r in rows {
        let size = r.size;
        s += &format!(
            "{size:>2}x{size:<2}  {:>2}%  {:>6.2} ± {:>4.2}    {:>6.2} ± {:>4.2}      {:>3} / {repeats}    {:>9}   {:>9}\n",
            r.density, r.sas.0, r.sas.1, r.best.0, r.best.1, r.sas_falls, r.sas_peaks, r.best_peaks
        );
    }
    for (size, sas, best) in rise_and_fall(rows) {
        s += &format!(
            "{size}x{size}: the curve rises to a point and falls again (peak inside the range) in {sas} / {repeats} studies for SAS, {best} / {repeats} for the best case\n"
        );
    }
    s
}

/// The whole study as JSON: the configuration, every sample, the box
/// summaries and, when the study was repeated, the spread of the medians
/// and the per-size counts of curves that rise and fall.
pub fn to_json(cfg: &StudyConfig, samples: &[Sample], rows: &[Row], spread: &[Spread]) -> String {
    let rise_and_fall: Vec<serde_json::Value> = rise_and_fall(spread)
        .into_iter()
        .map(|(size, sas, best)| serde_json::json!({"size": size, "sas": sas, "best": best}))
        .collect();
    let doc = serde_json::json!({
        "format": "reconfcheck-density-study",
        "version": 1,
        "config": cfg,
        "samples": samples,
        "rows": rows,
        "spread": spread,
        "rise_and_fall": rise_and_fall,
    });
    serde_json::to_string_pretty(&doc).expect("the study serialises")
}

/// The summary table, one row per `(size, density)`.
pub fn table(rows: &[Row]) -> String {
    let mut s = String::from(
        "size    rho  SAS q1 / median / q3        PAS q1 / median / q3    best-case median\n",
    );
    for r in rows {
        let (size, d, a, b) = (r.size, r.density, r.sas, r.pas);
        s += &format!(
            "{size:>2}x{size:<2}  {d:>2}%  {:>7.2} / {:>7.2} / {:>7.2}   {:>6.2} / {:>6.2} / {:>6.2}   {:>6.2}\n",
            a.q1, a.median, a.q3, b.q1, b.median, b.q3, r.best.median
        );
    }
    s
}
