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

/// Draws Fig. 10 as PNG (or SVG): the paper's two panels, messages
/// against rotations and time steps against the diameter, then rotations
/// against meta-modules, each with its least-squares line.
pub fn fig10(f: &crate::study::repost::Fig10, path: &Path) -> Result<(), Error> {
    let svg = crate::render::svg(path, |svg| {
        let root = SvgCanvas::with_string(svg, (1350, 400)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let areas = root.split_evenly((1, 3));
        let pts = |g: &dyn Fn(&crate::study::repost::SizeRow) -> (usize, usize)| {
            f.rows
                .iter()
                .map(|r| {
                    let (x, y) = g(r);
                    (x as f64, y as f64)
                })
                .collect::<Vec<_>>()
        };
        panel(
            &areas[0],
            "(a) messages vs motions",
            ("rotations", "messages (model)"),
            &pts(&|r| (r.rotations, r.messages.total())),
            f.messages_vs_rotations,
        )?;
        panel(
            &areas[1],
            "(b) time vs diameter",
            ("diameter (meta-modules)", "time steps"),
            &pts(&|r| (r.diameter, r.steps)),
            f.steps_vs_diameter,
        )?;
        panel(
            &areas[2],
            "(c) rotations vs size",
            ("meta-modules", "rotations"),
            &pts(&|r| (r.metas, r.rotations)),
            f.rotations_vs_metas,
        )?;
        root.present().map_err(draw_err)?;
        Ok(())
    })?;
    crate::render::save(&svg, path, 1.0)
}

/// One panel of Fig. 10: our points and their fitted line.
fn panel(
    area: &DrawingArea<SvgCanvas<'_>, plotters::coord::Shift>,
    title: &str,
    (xdesc, ydesc): (&str, &str),
    pts: &[(f64, f64)],
    fit: Option<crate::study::fit::LinearFit>,
) -> Result<(), crate::render::DrawError> {
    let xmax = pts.iter().map(|p| p.0).fold(1.0f64, f64::max) * 1.1;
    let ymax = pts.iter().map(|p| p.1).fold(1.0f64, f64::max) * 1.15;
    let mut chart = ChartBuilder::on(area)
        .caption(format!("Fig. 10 {title}"), ("sans-serif", 16))
        .margin(8)
        .x_label_area_size(30)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..xmax, 0.0..ymax)
        .map_err(draw_err)?;
    chart
        .configure_mesh()
        .x_labels(6)
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| format!("{y:.0}"))
        .x_desc(xdesc)
        .y_desc(ydesc)
        .draw()
        .map_err(draw_err)?;
    chart
        .draw_series(pts.iter().map(|&p| Circle::new(p, 5, BLUE.filled())))
        .map_err(draw_err)?
        .label("L -> C (ours)")
        .legend(|(x, y)| Circle::new((x + 7, y), 5, BLUE.filled()));
    if let Some(fit) = fit {
        let (x0, x1) = pts
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p.0), b.max(p.0))
            });
        chart
            .draw_series(LineSeries::new(
                [(x0, fit.at(x0)), (x1, fit.at(x1))],
                RED.stroke_width(2),
            ))
            .map_err(draw_err)?
            .label(format!(
                "fit: {:.1}·x {:+.0}, R² {:.3}",
                fit.slope, fit.intercept, fit.r2
            ))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 15, y)], RED));
    }
    crate::render::legend(&mut chart, SeriesLabelPosition::UpperLeft)
}
