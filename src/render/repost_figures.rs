//! Seed 001's Fig. 9: rotations running concurrently and streamlines in
//! use at each time step, iteration boundaries marked, with the paper's
//! peak (10 catoms × streamlines) as a dashed curve.

use crate::error::Error;
use crate::render::{SvgCanvas, draw_err};
use crate::study::repost::{CATOMS_PER_META, Fig9};
use plotters::prelude::*;
use std::path::Path;

/// Draws Fig. 9 as PNG (or SVG, by the extension).
pub fn fig9(f: &Fig9, path: &Path) -> Result<(), Error> {
    let svg = crate::render::svg(path, |svg| {
        let root = SvgCanvas::with_string(svg, (1000, 420)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let steps = f.motions.len().max(1) as f64;
        let peak = f
            .motions
            .iter()
            .copied()
            .chain(f.streamlines.iter().map(|s| s * CATOMS_PER_META))
            .max()
            .unwrap_or(1)
            .max(1) as f64;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!(
                    "Fig. 9, {}: {} iterations, {} time steps",
                    f.scenario,
                    f.iterations.len(),
                    f.motions.len()
                ),
                ("sans-serif", 16),
            )
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(40)
            .build_cartesian_2d(0.0..steps, 0.0..peak * 1.1)
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .x_desc("time step")
            .y_desc("count")
            .draw()
            .map_err(draw_err)?;
        let grey = RGBColor(170, 170, 170);
        for it in f.iterations.iter().skip(1) {
            let x = it.first_step as f64;
            chart
                .draw_series(LineSeries::new([(x, 0.0), (x, peak * 1.1)], grey))
                .map_err(draw_err)?;
        }
        let curve = |v: &[usize], scale: usize| -> Vec<(f64, f64)> {
            v.iter()
                .enumerate()
                .map(|(i, &n)| ((i + 1) as f64, (n * scale) as f64))
                .collect()
        };
        chart
            .draw_series(LineSeries::new(curve(&f.motions, 1), BLUE))
            .map_err(draw_err)?
            .label("concurrent rotations")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 15, y)], BLUE));
        chart
            .draw_series(LineSeries::new(
                curve(&f.streamlines, 1),
                RED.stroke_width(2),
            ))
            .map_err(draw_err)?
            .label("streamlines")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 15, y)], RED));
        chart
            .draw_series(DashedLineSeries::new(
                curve(&f.streamlines, CATOMS_PER_META),
                5,
                4,
                RED.mix(0.6).stroke_width(1),
            ))
            .map_err(draw_err)?
            .label("paper's peak: 10 × streamlines")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 15, y)], RED.mix(0.6)));
        crate::render::legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        root.present().map_err(draw_err)?;
        Ok(())
    })?;
    crate::render::save(&svg, path, 1.0)
}
