//! Seed 002 Figs. 10 and 11, drawn from `docking-study`'s data: messages
//! against modules with a least-squares line per shape beside the paper's
//! "≈ 5n", and available docking positions against percent built, the mean
//! curve per shape in a ±1 sd band.

use crate::error::Error;
use crate::render::{SvgCanvas, draw_err};
use crate::study::docking::{
    AvailabilityCurve, MessageRow, PAPER_MESSAGES_PER_MODULE, SHAPES, message_fits,
};
use plotters::prelude::*;
use std::path::Path;

/// The shapes' colours, in the order of [`SHAPES`] (a shape not there is
/// drawn in grey).
pub const COLOURS: [[u8; 3]; 4] = [[200, 0, 0], [0, 0, 210], [0, 140, 0], [150, 0, 150]];

/// Picture size in pixels (both figures).
pub const SIZE: (u32, u32) = (900, 560);

fn colour(shape: &str) -> RGBColor {
    match SHAPES.iter().position(|s| s.0 == shape) {
        Some(i) if i < COLOURS.len() => {
            let [r, g, b] = COLOURS[i];
            RGBColor(r, g, b)
        }
        _ => RGBColor(110, 110, 110),
    }
}

/// The shapes of `names` in first-seen order.
fn shapes<'a>(names: impl Iterator<Item = &'a str>) -> Vec<&'a str> {
    let mut v: Vec<&str> = Vec::new();
    for n in names {
        if !v.contains(&n) {
            v.push(n);
        }
    }
    v
}

/// The outline of shape `k`'s mark (circle, triangle, square, cross, in
/// turn) in pixel offsets about its point, `size` pixels from centre to
/// edge: one path per mark, so that every shape's marks and legend entry
/// are the same element type, and shapes whose points coincide stay apart.
fn outline(k: usize, size: i32) -> Vec<(i32, i32)> {
    let s = size as f64;
    let ring = |n: usize, phase: f64, r: f64| -> Vec<(i32, i32)> {
        (0..=n)
            .map(|j| {
                let a = phase + j as f64 * std::f64::consts::TAU / n as f64;
                ((r * a.cos()).round() as i32, (r * a.sin()).round() as i32)
            })
            .collect()
    };
    match k % 4 {
        0 => ring(16, 0.0, s),
        // Pointing up (pixel y grows downwards).
        1 => ring(3, -std::f64::consts::FRAC_PI_2, s * 1.3),
        2 => vec![
            (-size, -size),
            (size, -size),
            (size, size),
            (-size, size),
            (-size, -size),
        ],
        _ => vec![
            (-size, -size),
            (size, size),
            (0, 0),
            (size, -size),
            (-size, size),
        ],
    }
}

/// Fig. 10: mean messages against modules, one colour and mark per shape,
/// its least-squares line (slope in the legend), and the paper's ≈ 5n as a
/// dashed black line. `seeds` is the number of runs behind each mean.
pub fn fig10(rows: &[MessageRow], seeds: u64, path: &Path) -> Result<(), Error> {
    let fits = message_fits(rows);
    let svg = crate::render::svg(path, |svg| {
        let root = SvgCanvas::with_string(svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let xmax = rows.iter().map(|r| r.modules).max().unwrap_or(1) as f64 * 1.05;
        let ymax = rows
            .iter()
            .map(|r| r.messages)
            .fold(PAPER_MESSAGES_PER_MODULE * xmax, f64::max)
            * 1.05;
        let mut c = ChartBuilder::on(&root)
            .caption(
                format!(
                    "Fig. 10: messages against modules (seed 002, mean of {seeds} run{} per point)",
                    if seeds == 1 { "" } else { "s" }
                ),
                ("sans-serif", 18),
            )
            .margin(12)
            .margin_right(28)
            .x_label_area_size(44)
            .y_label_area_size(72)
            .build_cartesian_2d(0.0..xmax, 0.0..ymax)
            .map_err(draw_err)?;
        c.configure_mesh()
            .x_desc("modules n (goal cells)")
            .y_desc("messages sent (count)")
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| format!("{y:.0}"))
            .draw()
            .map_err(draw_err)?;
        // The paper's claim first, so that the data draw over it.
        c.draw_series(DashedLineSeries::new(
            [(0.0, 0.0), (xmax, PAPER_MESSAGES_PER_MODULE * xmax)],
            8,
            5,
            BLACK.stroke_width(2),
        ))
        .map_err(draw_err)?
        .label(format!(
            "paper's claim: ≈ {PAPER_MESSAGES_PER_MODULE}n messages"
        ))
        .legend(|(x, y)| PathElement::new([(x, y), (x + 18, y)], BLACK.stroke_width(2)));
        for (k, shape) in shapes(rows.iter().map(|r| r.shape.as_str()))
            .into_iter()
            .enumerate()
        {
            let col = colour(shape);
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.shape == shape)
                .map(|r| (r.modules as f64, r.messages))
                .collect();
            let fit = fits.iter().find(|f| f.0 == shape).map(|f| f.1);
            if let Some(f) = fit {
                let x1 = pts.iter().map(|p| p.0).fold(0.0, f64::max);
                c.draw_series(LineSeries::new(
                    [(0.0, f.at(0.0).max(0.0)), (x1, f.at(x1))],
                    col.stroke_width(1),
                ))
                .map_err(draw_err)?;
            }
            let label = match fit {
                Some(f) => format!(
                    "{shape}: fit {:.2}n {} {:.0}",
                    f.slope,
                    if f.intercept < 0.0 { '−' } else { '+' },
                    f.intercept.abs()
                ),
                None => shape.to_string(),
            };
            let style = col.stroke_width(2);
            c.draw_series(
                pts.iter()
                    .map(|&p| EmptyElement::at(p) + PathElement::new(outline(k, 5), style)),
            )
            .map_err(draw_err)?
            .label(label)
            .legend(move |(x, y)| {
                EmptyElement::at((x + 9, y))
                    + PathElement::new([(-9, 0), (9, 0)], col.stroke_width(1))
                    + PathElement::new(outline(k, 5), style)
            });
        }
        // The same runs counted as the authors' paper-era code counts
        // (filled dots), with one fit over every shape.
        let era: Vec<(f64, f64)> = rows
            .iter()
            .map(|r| (r.modules as f64, r.messages_paper_era))
            .collect();
        let era_label = match crate::study::fit::linear_fit(&era) {
            Some(f) => format!(
                "filled: counted as the Nov. 2017 code (fit {:.2}n)",
                f.slope
            ),
            None => "filled: counted as the Nov. 2017 code".to_string(),
        };
        c.draw_series(rows.iter().map(|r| {
            Circle::new(
                (r.modules as f64, r.messages_paper_era),
                4,
                colour(&r.shape).filled(),
            )
        }))
        .map_err(draw_err)?
        .label(era_label)
        .legend(|(x, y)| Circle::new((x + 9, y), 4, BLACK.filled()));
        crate::render::legend(&mut c, SeriesLabelPosition::UpperLeft)?;
        root.present().map_err(draw_err)?;
        Ok(())
    })?;
    crate::render::save(&svg, path, 1.0)
}

/// Fig. 11: available docking positions D/√N against percent built, the
/// mean over seeds per shape with a shaded ±1 sd band. `factor` is the
/// shapes' scale, `seeds` the runs behind each mean.
pub fn fig11(
    curves: &[AvailabilityCurve],
    factor: f64,
    seeds: u64,
    path: &Path,
) -> Result<(), Error> {
    let svg = crate::render::svg(path, |svg| {
        let root = SvgCanvas::with_string(svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let ymax = curves
            .iter()
            .flat_map(|c| c.mean.iter().zip(&c.std).map(|(m, s)| m + s))
            .fold(0.1f64, f64::max)
            * 1.25;
        let mut c = ChartBuilder::on(&root)
            .caption(
                format!(
                    "Fig. 11: available docking positions (seed 002, ×{factor} scale, mean ± 1 sd over {seeds} run{})",
                    if seeds == 1 { "" } else { "s" }
                ),
                ("sans-serif", 18),
            )
            .margin(12)
            .margin_right(28)
            .x_label_area_size(44)
            .y_label_area_size(72)
            .build_cartesian_2d(0.0..100.0, 0.0..ymax)
            .map_err(draw_err)?;
        c.configure_mesh()
            .x_desc("shape built (% of its modules docked)")
            .y_desc("available docking positions D / √N")
            .x_label_formatter(&|x| format!("{x:.0} %"))
            .y_label_formatter(&|y| format!("{y:.1}"))
            .draw()
            .map_err(draw_err)?;
        // Bands first, then every mean over them.
        for curve in curves {
            let col = colour(&curve.shape);
            let pct = curve.percent.iter().map(|&p| p as f64);
            let upper: Vec<(f64, f64)> = pct
                .clone()
                .zip(&curve.mean)
                .zip(&curve.std)
                .map(|((p, m), s)| (p, m + s))
                .collect();
            let lower: Vec<(f64, f64)> = pct
                .zip(&curve.mean)
                .zip(&curve.std)
                .map(|((p, m), s)| (p, (m - s).max(0.0)))
                .collect();
            let band: Vec<(f64, f64)> = upper.into_iter().chain(lower.into_iter().rev()).collect();
            c.draw_series(std::iter::once(Polygon::new(band, col.mix(0.18).filled())))
                .map_err(draw_err)?;
        }
        for (k, curve) in curves.iter().enumerate() {
            let col = colour(&curve.shape);
            let pts: Vec<(f64, f64)> = curve
                .percent
                .iter()
                .map(|&p| p as f64)
                .zip(curve.mean.iter().copied())
                .collect();
            c.draw_series(LineSeries::new(pts.clone(), col.stroke_width(2)))
                .map_err(draw_err)?
                .label(format!("{} (N = {})", curve.shape, curve.modules))
                .legend(move |(x, y)| {
                    EmptyElement::at((x + 9, y))
                        + Rectangle::new([(-9, -6), (9, 6)], col.mix(0.18).filled())
                        + PathElement::new([(-9, 0), (9, 0)], col.stroke_width(2))
                        + PathElement::new(outline(k, 3), col.stroke_width(1))
                });
            let style = col.stroke_width(1);
            c.draw_series(
                pts.iter()
                    .map(|&p| EmptyElement::at(p) + PathElement::new(outline(k, 3), style)),
            )
            .map_err(draw_err)?;
        }
        c.draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(draw_err)?
            .label("shaded: ± 1 sd over seeds")
            .legend(|(x, y)| {
                Rectangle::new(
                    [(x, y - 6), (x + 18, y + 6)],
                    RGBColor(120, 120, 120).mix(0.25).filled(),
                )
            });
        crate::render::legend(&mut c, SeriesLabelPosition::UpperRight)?;
        root.present().map_err(draw_err)?;
        Ok(())
    })?;
    crate::render::save(&svg, path, 1.0)
}
