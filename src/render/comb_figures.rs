//! Seed 004's scaling claim drawn from `comb-study`'s rows: parallel steps
//! and atom operations of the combing against atoms n on log–log axes,
//! each with its fitted power law (slope and R² in the legend), beside the
//! naive one-meta-module-at-a-time baseline and guide lines of slope 1
//! (the paper's O(n)) and 2 (the O(n²) of sequential reconfiguration).

use crate::error::Error;
use crate::lattice::AtomRest;
use crate::render::{SvgCanvas, draw_err};
use crate::study::comb::{
    Row, Theorem3Row, TheoremRow, loglog_fit, series, theorem_series, theorem3_series,
};
use plotters::prelude::*;
use std::path::Path;

/// Picture size in pixels.
pub const SIZE: (u32, u32) = (900, 600);

const COLOURS: [RGBColor; 6] = [
    RGBColor(200, 0, 0),
    RGBColor(0, 0, 210),
    RGBColor(0, 140, 0),
    RGBColor(150, 0, 150),
    RGBColor(210, 120, 0),
    RGBColor(0, 150, 160),
];

/// One measured series of a log–log plot.
struct Series {
    name: String,
    points: Vec<(f64, f64)>,
    /// Drawn with hollow markers (a baseline).
    hollow: bool,
}

/// Draws the scaling plot of each atom model's rows to `path`: parallel
/// steps and atom operations of the combing, and the naive baseline's
/// atom operations (hollow), per model.
pub fn scaling(models: &[(AtomRest, Vec<Row>)], path: &Path) -> Result<(), Error> {
    let mut data: Vec<Series> = Vec::new();
    for (rest, rows) in models {
        for (k, (name, points)) in series(rows).into_iter().enumerate() {
            if k == 2 {
                continue; // naive steps: one per meta-module move, as in Theorem 1's rows
            }
            data.push(Series {
                name: format!("{rest:?}: {name}"),
                points,
                hollow: k >= 2,
            });
        }
    }
    loglog(&data, "Seed 004: 2D combing against n (log–log)", 2, path)
}

/// Draws Theorems 1 (2D) and 2 (3D) against atoms n: meta-module steps
/// from source to target and the combing phases' atom operations (the
/// phases certified atom by atom), beside `naive`, the naive
/// one-meta-module-at-a-time baseline's atom operations (2D combing).
pub fn theorems(
    two: &[TheoremRow],
    three: &[Theorem3Row],
    naive: &[(f64, f64)],
    path: &Path,
) -> Result<(), Error> {
    let t1 = theorem_series(two);
    let t2 = theorem3_series(three);
    let measured = |theorem: &str, (name, points): &(&str, Vec<(f64, f64)>)| Series {
        name: format!("{theorem}: {name}"),
        points: points.clone(),
        hollow: false,
    };
    let data = vec![
        measured("Theorem 1, 2D", &t1[0]),
        measured("Theorem 1, 2D", &t1[3]),
        measured("Theorem 2, 3D", &t2[0]),
        measured("Theorem 2, 3D", &t2[2]),
        Series {
            name: "naive baseline (2D combing, one at a time): atom operations".into(),
            points: naive.to_vec(),
            hollow: true,
        },
    ];
    loglog(
        &data,
        "Seed 004: Theorems 1 and 2 against n (contracted model, log–log)",
        4,
        path,
    )
}

/// Draws `data` on log–log axes, each series with its fitted power law,
/// and guide lines of slope 1 and 2 through the first positive point of
/// series `guide`.
fn loglog(data: &[Series], caption: &str, guide: usize, path: &Path) -> Result<(), Error> {
    let positive = |v: f64| v.is_finite() && v > 0.0;
    let xs: Vec<f64> = data
        .iter()
        .flat_map(|s| s.points.iter().map(|q| q.0))
        .filter(|&x| positive(x))
        .collect();
    let ys: Vec<f64> = data
        .iter()
        .flat_map(|s| s.points.iter().map(|q| q.1))
        .filter(|&y| positive(y))
        .collect();
    let (x0, x1) = bounds(&xs);
    let (y0, y1) = bounds(&ys);
    let svg = crate::render::svg(path, |svg| {
        let root = SvgCanvas::with_string(svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let mut c = ChartBuilder::on(&root)
            .caption(caption, ("sans-serif", 18))
            .margin(12)
            .margin_right(28)
            .x_label_area_size(44)
            .y_label_area_size(72)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(draw_err)?;
        c.configure_mesh()
            .x_desc("atoms n")
            .y_desc("count")
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| format!("{y:.0}"))
            .draw()
            .map_err(draw_err)?;
        // Guide lines through the guide series' smallest point: slope 1
        // (O(n)) and 2 (O(n²)).
        let anchor = data.get(guide).and_then(|s| {
            s.points
                .iter()
                .copied()
                .find(|p| positive(p.0) && positive(p.1))
        });
        if let Some((ax, ay)) = anchor {
            for (power, label) in [
                (1.0, "guide: slope 1, O(n)"),
                (2.0, "guide: slope 2, O(n²)"),
            ] {
                let at = |x: f64| ay * (x / ax).powf(power);
                let xe = if at(x1) > y1 {
                    ax * (y1 / ay).powf(1.0 / power)
                } else {
                    x1
                };
                let style = RGBColor(120, 120, 120).stroke_width(if power == 1.0 { 1 } else { 2 });
                c.draw_series(DashedLineSeries::new([(ax, ay), (xe, at(xe))], 6, 5, style))
                    .map_err(draw_err)?
                    .label(label)
                    .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], style));
            }
        }
        for (k, s) in data.iter().enumerate() {
            let col = COLOURS[k % COLOURS.len()];
            let pts: Vec<(f64, f64)> = s
                .points
                .iter()
                .copied()
                .filter(|p| positive(p.0) && positive(p.1))
                .collect();
            let fit = loglog_fit(&pts);
            if let Some(f) = fit {
                let y = |x: f64| (f.intercept + f.slope * x.ln()).exp();
                let (a, b) = bounds(&pts.iter().map(|p| p.0).collect::<Vec<_>>());
                c.draw_series(LineSeries::new(
                    [(a, y(a)), (b, y(b))].into_iter().filter(|p| positive(p.1)),
                    col.stroke_width(1),
                ))
                .map_err(draw_err)?;
            }
            let label = match fit {
                Some(f) => format!("{}: slope {:.2}, R² {:.3}", s.name, f.slope, f.r2),
                None => s.name.clone(),
            };
            let hollow = s.hollow;
            c.draw_series(pts.iter().map(|&p| {
                if hollow {
                    Circle::new(p, 4, col.stroke_width(2))
                } else {
                    Circle::new(p, 4, col.filled())
                }
            }))
            .map_err(draw_err)?
            .label(label)
            .legend(move |(x, y)| {
                EmptyElement::at((x + 9, y))
                    + PathElement::new([(-9, 0), (9, 0)], col.stroke_width(1))
                    + if hollow {
                        Circle::new((0, 0), 4, col.stroke_width(2))
                    } else {
                        Circle::new((0, 0), 4, col.filled())
                    }
            });
        }
        crate::render::legend(&mut c, SeriesLabelPosition::UpperLeft)?;
        root.present().map_err(draw_err)?;
        Ok(())
    })?;
    crate::render::save(&svg, path, 1.0)
}

/// A log axis's range around `v`'s positive values, half a decade of room
/// on each side (1..10 when there are none).
fn bounds(v: &[f64]) -> (f64, f64) {
    let lo = v
        .iter()
        .copied()
        .filter(|x| *x > 0.0)
        .fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().filter(|x| *x > 0.0).fold(0.0, f64::max);
    if lo.is_finite() && hi > 0.0 {
        (lo / 1.5, hi * 1.5)
    } else {
        (1.0, 10.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(metas: usize, steps: usize, ops: usize, naive: usize) -> Row {
        Row {
            metas,
            atoms: 8 * metas,
            meta_steps: steps,
            steps,
            operations: ops,
            baseline_steps: naive,
            baseline_operations: 10 * naive,
            generate_s: 0.0,
            certify_s: None,
            certified: None,
        }
    }

    #[test]
    fn the_scaling_plot_is_a_png_even_with_a_zero_count() {
        let dir = std::env::temp_dir().join(format!("rc-comb-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("scaling.png");
        let rows = [
            row(8, 3, 24, 0),
            row(64, 22, 356, 214),
            row(512, 105, 3088, 6364),
        ];
        let expanded = rows
            .iter()
            .map(|r| Row {
                operations: 5 * r.operations,
                ..r.clone()
            })
            .collect();
        scaling(
            &[
                (AtomRest::Contracted, rows.to_vec()),
                (AtomRest::Expanded, expanded),
            ],
            &p,
        )
        .unwrap();
        let png = std::fs::read(&p).unwrap();
        assert!(
            png.starts_with(b"\x89PNG") && png.len() > 10_000,
            "{}",
            png.len()
        );
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn log_bounds_ignore_non_positive_values() {
        assert_eq!(bounds(&[0.0, -3.0]), (1.0, 10.0));
        let (a, b) = bounds(&[0.0, 10.0, 100.0]);
        assert!((a - 10.0 / 1.5).abs() < 1e-12 && (b - 150.0).abs() < 1e-12);
    }
}
