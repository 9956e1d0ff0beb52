//! Modules placed per time step (seed 000 Figs. 13–16).

use crate::error::Error;
use crate::render::{SvgCanvas, draw_err};
use plotters::prelude::*;
use std::path::Path;

/// Draws one or more placement curves (label, per-step counts) as a PNG
/// or SVG: instantaneous placements per step, and the cumulative count.
/// `marks` are published times (label, step), drawn as dashed verticals
/// on both charts.
pub fn draw(
    curves: &[(String, Vec<usize>)],
    title: &str,
    marks: &[(String, f64)],
    path: &Path,
) -> Result<(), Error> {
    let svg = crate::render::svg(path, |svg| {
        let root = SvgCanvas::with_string(svg, (900, 420)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let (left, right) = root.split_horizontally(450);
        let steps = curves
            .iter()
            .map(|c| c.1.len() as f64)
            .chain(marks.iter().map(|m| m.1 * 1.02))
            .fold(1.0f64, f64::max);
        let window = 10usize;
        let smooth = |v: &[usize]| -> Vec<(f64, f64)> {
            (0..v.len())
                .map(|i| {
                    let a = i.saturating_sub(window / 2);
                    let b = (i + window / 2).min(v.len());
                    let s: usize = v[a..b].iter().sum();
                    ((i + 1) as f64, s as f64 / (b - a) as f64)
                })
                .collect()
        };
        let ymax = curves
            .iter()
            .flat_map(|c| smooth(&c.1).into_iter().map(|p| p.1))
            .fold(1.0f64, f64::max);
        let mut chart = ChartBuilder::on(&left)
            .caption(format!("{title}: placed per step"), ("sans-serif", 16))
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(40)
            .build_cartesian_2d(0.0..steps, 0.0..ymax * 1.1)
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .x_desc("time step")
            .y_desc(format!("modules placed ({window}-step mean)"))
            .draw()
            .map_err(draw_err)?;
        let colours = [RED, BLUE, GREEN, MAGENTA, BLACK, CYAN];
        for (k, (label, v)) in curves.iter().enumerate() {
            let col = colours[k % colours.len()];
            chart
                .draw_series(LineSeries::new(smooth(v), &col))
                .map_err(draw_err)?
                .label(label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 15, y)], col));
        }
        for (k, (label, t)) in marks.iter().enumerate() {
            let col = RGBColor(90, 90, 90);
            chart
                .draw_series(DashedLineSeries::new(
                    [(*t, 0.0), (*t, ymax * 1.1)],
                    6,
                    4,
                    col.stroke_width(2),
                ))
                .map_err(draw_err)?;
            chart
                .draw_series(std::iter::once(Text::new(
                    label.clone(),
                    (*t, ymax * (1.05 - 0.07 * k as f64)),
                    ("sans-serif", 12).into_font().color(&BLACK),
                )))
                .map_err(draw_err)?;
        }
        crate::render::legend(&mut chart, SeriesLabelPosition::MiddleRight)?;
        let total = curves
            .iter()
            .map(|c| c.1.iter().sum::<usize>())
            .max()
            .unwrap_or(1)
            .max(1);
        let mut cum = ChartBuilder::on(&right)
            .caption(format!("{title}: modules in place"), ("sans-serif", 16))
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..steps, 0.0..total as f64 * 1.05)
            .map_err(draw_err)?;
        cum.configure_mesh()
            .x_desc("time step")
            .y_desc("modules")
            .draw()
            .map_err(draw_err)?;
        for (k, (_, v)) in curves.iter().enumerate() {
            let col = colours[k % colours.len()];
            let mut acc = 0;
            let pts: Vec<(f64, f64)> = v
                .iter()
                .enumerate()
                .map(|(i, &n)| {
                    acc += n;
                    ((i + 1) as f64, acc as f64)
                })
                .collect();
            cum.draw_series(LineSeries::new(pts, &col))
                .map_err(draw_err)?;
        }
        for (_, t) in marks {
            cum.draw_series(DashedLineSeries::new(
                [(*t, 0.0), (*t, total as f64 * 1.05)],
                6,
                4,
                RGBColor(90, 90, 90).stroke_width(2),
            ))
            .map_err(draw_err)?;
        }
        root.present().map_err(draw_err)?;
        Ok(())
    })?;
    crate::render::save(&svg, path, 1.0)
}
