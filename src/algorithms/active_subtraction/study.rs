//! The density study of seed 003 §V-B1 (Fig. 10): random desired
//! configurations of densities 10–70 % in 10 × 10 and 20 × 20 squares, the
//! same samples for SAS and PAS, time normalised by the number of excluded
//! modules; a table and a box plot.

use super::pas::{self, PasTimes};
use super::random::{Growth, random_shape_grown};
use super::sas;
use crate::render::{SvgCanvas, save};
use indicatif::ProgressBar;
use plotters::prelude::*;
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;

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
pub fn run(cfg: &StudyConfig) -> Result<Vec<Sample>, String> {
    run_observed(cfg, &ProgressBar::hidden())
}

/// Samples one study draws: sizes × densities × samples.
pub fn sample_count(cfg: &StudyConfig) -> usize {
    cfg.sizes.len() * cfg.densities.len() * cfg.samples
}

/// [`run`], advancing `bar` by one per sample.
pub fn run_observed(cfg: &StudyConfig, bar: &ProgressBar) -> Result<Vec<Sample>, String> {
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
            bar.inc(1);
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

fn spread_len(spread: &[Spread]) -> usize {
    spread.first().map_or(0, |r| r.repeats)
}

/// Runs `repeats` studies (see [`Spread`]).
pub fn spread(cfg: &StudyConfig, repeats: usize) -> Result<Vec<Spread>, String> {
    spread_observed(cfg, repeats, &ProgressBar::hidden())
}

/// [`spread`], advancing `bar` by one per sample of every study.
pub fn spread_observed(
    cfg: &StudyConfig,
    repeats: usize,
    bar: &ProgressBar,
) -> Result<Vec<Spread>, String> {
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

/// Box plot of the normalised times (log scale), like the paper's Fig. 10:
/// per density, SAS and PAS for each size (lighter boxes: smaller size).
pub fn plot(cfg: &StudyConfig, rows: &[Row], path: &Path) -> Result<(), String> {
    plot_with_spread(cfg, rows, &[], path)
}

/// [`plot`], plus — when `spread` is not empty — the mean over repeated
/// studies of each box's SAS median (a dashed line per size), which shows
/// the expected trend behind the noise of one study's medians.
pub fn plot_with_spread(
    cfg: &StudyConfig,
    rows: &[Row],
    spread: &[Spread],
    path: &Path,
) -> Result<(), String> {
    let mut svg = String::new();
    {
        let root = SvgCanvas::with_string(&mut svg, (960, 540)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let lo = rows
            .iter()
            .map(|r| r.pas.low.min(r.sas.low))
            .fold(f64::INFINITY, f64::min)
            .max(1e-3);
        let hi = rows
            .iter()
            .map(|r| r.pas.high.max(r.sas.high))
            .fold(0.0, f64::max)
            .max(lo * 2.0);
        let n = cfg.densities.len() as f64;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!(
                    "Active subtraction: time per excluded module ({} samples per box{})",
                    cfg.samples,
                    match cfg.growth {
                        Growth::Member => "",
                        Growth::Chain => ", chain growth",
                    }
                ),
                ("sans-serif", 20),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(-0.5..n - 0.5, (lo / 1.5).log10()..(hi * 8.0).log10())
            .map_err(|e| e.to_string())?;
        let densities = cfg.densities.clone();
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(cfg.densities.len() + 1)
            .x_label_formatter(&|x| {
                let k = x.round();
                if (x - k).abs() < 1e-6 && k >= 0.0 && (k as usize) < densities.len() {
                    format!("{} %", densities[k as usize])
                } else {
                    String::new()
                }
            })
            .disable_y_mesh()
            .y_labels(0)
            .x_desc("density of included modules ρ")
            .y_desc("time steps / excluded module")
            .draw()
            .map_err(|e| e.to_string())?;
        // Log scale by hand: the axis is log10 of the value, with ticks at
        // 1-2-5 steps (plotters' log axis labels decades only).
        let (y0, y1) = ((lo / 1.5).log10(), (hi * 8.0).log10());
        let ticks: Vec<f64> = (-3..4)
            .flat_map(|e| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(e)))
            .filter(|t| (y0..=y1).contains(&t.log10()))
            .collect();
        let grey = RGBColor(200, 200, 200);
        for &t in &ticks {
            let y = t.log10();
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(-0.5, y), (n - 0.5, y)],
                    grey,
                )))
                .map_err(|e| e.to_string())?;
            chart
                .draw_series(std::iter::once(Text::new(
                    format!("{t}"),
                    (-0.5 - 0.02 * n, y),
                    ("sans-serif", 13).into_font().color(&BLACK).pos(
                        plotters::style::text_anchor::Pos::new(
                            plotters::style::text_anchor::HPos::Right,
                            plotters::style::text_anchor::VPos::Center,
                        ),
                    ),
                )))
                .map_err(|e| e.to_string())?;
        }
        let kinds = cfg.sizes.len() * 2;
        let width = 0.8 / kinds as f64;
        let sas_c = RGBColor(31, 119, 180);
        let pas_c = RGBColor(255, 127, 14);
        for (si, &size) in cfg.sizes.iter().enumerate() {
            for (mi, (name, colour)) in [("SAS", sas_c), ("PAS", pas_c)].into_iter().enumerate() {
                let slot = si * 2 + mi;
                let light = si + 1 < cfg.sizes.len();
                let fill = if light {
                    colour.mix(0.35).filled()
                } else {
                    colour.mix(0.85).filled()
                };
                let boxes: Vec<(f64, Summary)> = rows
                    .iter()
                    .filter(|r| r.size == size)
                    .map(|r| {
                        let k = cfg
                            .densities
                            .iter()
                            .position(|&d| d == r.density)
                            .unwrap_or(0) as f64;
                        let x = k - 0.4 + width * (slot as f64 + 0.5);
                        let v = if mi == 0 { r.sas } else { r.pas };
                        let l = |x: f64| x.log10();
                        (
                            x,
                            Summary {
                                low: l(v.low),
                                q1: l(v.q1),
                                median: l(v.median),
                                q3: l(v.q3),
                                high: l(v.high),
                            },
                        )
                    })
                    .collect();
                let half = width * 0.4;
                chart
                    .draw_series(
                        boxes.iter().map(|&(x, s)| {
                            Rectangle::new([(x - half, s.q1), (x + half, s.q3)], fill)
                        }),
                    )
                    .map_err(|e| e.to_string())?
                    .label(format!("{name} {size}×{size}"))
                    .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], fill));
                let black = BLACK.stroke_width(1);
                for &(x, s) in &boxes {
                    let lines = [
                        vec![(x - half, s.median), (x + half, s.median)],
                        vec![(x, s.q3), (x, s.high)],
                        vec![(x, s.q1), (x, s.low)],
                        vec![(x - half / 2.0, s.high), (x + half / 2.0, s.high)],
                        vec![(x - half / 2.0, s.low), (x + half / 2.0, s.low)],
                    ];
                    chart
                        .draw_series(lines.into_iter().map(|l| PathElement::new(l, black)))
                        .map_err(|e| e.to_string())?;
                    chart
                        .draw_series(std::iter::once(Rectangle::new(
                            [(x - half, s.q1), (x + half, s.q3)],
                            black,
                        )))
                        .map_err(|e| e.to_string())?;
                }
            }
        }
        // The paper's overlay: median best-case sequential time per size.
        for (si, &size) in cfg.sizes.iter().enumerate() {
            let light = si + 1 < cfg.sizes.len();
            let style = if light {
                BLACK.mix(0.45).stroke_width(2)
            } else {
                BLACK.stroke_width(2)
            };
            let points: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.size == size)
                .filter_map(|r| {
                    let k = cfg.densities.iter().position(|&d| d == r.density)? as f64;
                    Some((k, r.best.median.log10()))
                })
                .collect();
            chart
                .draw_series(LineSeries::new(points.clone(), style))
                .map_err(|e| e.to_string())?
                .label(format!("best case {size}×{size} (median)"))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], style));
            chart
                .draw_series(
                    points
                        .into_iter()
                        .map(|p| Circle::new(p, 3, style.filled())),
                )
                .map_err(|e| e.to_string())?;
        }
        for (si, &size) in cfg.sizes.iter().enumerate() {
            let points: Vec<(f64, f64)> = spread
                .iter()
                .filter(|r| r.size == size)
                .filter_map(|r| {
                    let k = cfg.densities.iter().position(|&d| d == r.density)? as f64;
                    Some((k, r.sas.0.log10()))
                })
                .collect();
            if points.is_empty() {
                continue;
            }
            let light = si + 1 < cfg.sizes.len();
            let colour = RGBColor(31, 119, 180).mix(if light { 0.5 } else { 1.0 });
            let style = colour.stroke_width(2);
            chart
                .draw_series(DashedLineSeries::new(points, 6, 4, style))
                .map_err(|e| e.to_string())?
                .label(format!(
                    "SAS {size}×{size}: mean median of {} studies",
                    spread_len(spread)
                ))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], style));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    save(&svg, path, 1.0)
}
