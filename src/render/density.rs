//! The density study's box plot (seed 003 Fig. 10).

use crate::algorithms::active_subtraction::random::Growth;
use crate::error::Error;
use crate::render::{SvgCanvas, draw_err, save};
use crate::study::density::{Row, Spread, StudyConfig, Summary};
use plotters::prelude::*;
use std::path::Path;

/// Box plot of the normalised times (log scale), like the paper's Fig. 10:
/// per density, SAS and PAS for each size (lighter boxes: smaller size).
pub fn plot(cfg: &StudyConfig, rows: &[Row], path: &Path) -> Result<(), Error> {
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
) -> Result<(), Error> {
    let svg = crate::render::svg(path, |svg| {
        let root = SvgCanvas::with_string(svg, (960, 540)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
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
            .map_err(draw_err)?;
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
            .map_err(draw_err)?;
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
                .map_err(draw_err)?;
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
                .map_err(draw_err)?;
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
                    .map_err(draw_err)?
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
                        .map_err(draw_err)?;
                    chart
                        .draw_series(std::iter::once(Rectangle::new(
                            [(x - half, s.q1), (x + half, s.q3)],
                            black,
                        )))
                        .map_err(draw_err)?;
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
                .map_err(draw_err)?
                .label(format!("best case {size}×{size} (median)"))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], style));
            chart
                .draw_series(
                    points
                        .into_iter()
                        .map(|p| Circle::new(p, 3, style.filled())),
                )
                .map_err(draw_err)?;
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
                .map_err(draw_err)?
                .label(format!(
                    "SAS {size}×{size}: mean median of {} studies",
                    spread_len(spread)
                ))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], style));
        }
        crate::render::legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        root.present().map_err(draw_err)?;
        Ok(())
    })?;
    save(&svg, path, 1.0)
}

/// How many studies a spread summarises (0 without repeats).
fn spread_len(spread: &[Spread]) -> usize {
    spread.first().map_or(0, |r| r.repeats)
}
