//! The b-study's plot: utilisation and minimum pressure against b.

use crate::error::Error;
use crate::mechanics::Bending;
use crate::render::{SvgCanvas, draw_err};
use crate::study::b_study::Study;
use plotters::prelude::*;
use std::path::Path;

/// Plots utilisation against `b` (at the model's pressure) and the
/// minimum pressure against `b` (both criteria), with the closed forms.
pub fn plot(study: &Study, path: &Path) -> Result<(), Error> {
    let svg = crate::render::svg(path, |svg| {
        let root = SvgCanvas::with_string(svg, (1200, 500)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let (left, right) = root.split_horizontally(600);
        // One b more each side than studied: a single b is a point, not a
        // range, and its markers would sit on the frame.
        let bmax = study.rows.iter().map(|r| r.b).max().unwrap_or(1) as f64 + 1.0;
        let bmin = study.rows.iter().map(|r| r.b).min().unwrap_or(1) as f64 - 1.0;
        let umax = study
            .rows
            .iter()
            .flat_map(|r| [r.max_utilisation, r.closed_utilisation])
            .filter(|u| u.is_finite())
            .fold(1.2f64, f64::max)
            * 1.05;
        let mut c = ChartBuilder::on(&left)
            .caption(
                format!(
                    "max connector utilisation, p = {} kPa ({})",
                    study.pressure_kpa,
                    study.bending.name()
                ),
                ("sans-serif", 18),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(55)
            .build_cartesian_2d(bmin..bmax, 0.0..umax)
            .map_err(draw_err)?;
        c.configure_mesh()
            .x_desc("branch length b (modules)")
            .y_desc("load / capacity")
            .draw()
            .map_err(draw_err)?;
        c.draw_series(LineSeries::new(
            [(bmin, 1.0), (bmax, 1.0)],
            BLACK.stroke_width(1),
        ))
        .map_err(draw_err)?;
        let sim: Vec<(f64, f64)> = study
            .rows
            .iter()
            .map(|r| (r.b as f64, r.max_utilisation.min(umax)))
            .collect();
        c.draw_series(LineSeries::new(sim.clone(), BLUE.stroke_width(2)))
            .map_err(draw_err)?
            .label("every step, static analysis")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 18, y)], BLUE.stroke_width(2)));
        // A row's maximum that is only a lower bound (poses or steps left
        // unjudged, the table's "≥") is drawn hollow.
        let at_least = |r: &crate::study::b_study::Row| r.max_utilisation_at_least;
        c.draw_series(
            study
                .rows
                .iter()
                .zip(&sim)
                .filter(|(r, _)| !at_least(r))
                .map(|(_, &p)| Circle::new(p, 4, BLUE.filled())),
        )
        .map_err(draw_err)?;
        if study.rows.iter().any(at_least) {
            c.draw_series(
                study
                    .rows
                    .iter()
                    .zip(&sim)
                    .filter(|(r, _)| at_least(r))
                    .map(|(_, &p)| Circle::new(p, 5, BLUE.stroke_width(2))),
            )
            .map_err(draw_err)?
            .label("≥: a lower bound (poses or steps left unjudged)")
            .legend(|(x, y)| Circle::new((x + 9, y), 5, BLUE.stroke_width(2)));
        }
        let closed: Vec<(f64, f64)> = study
            .rows
            .iter()
            .map(|r| (r.b as f64, r.closed_utilisation.min(umax)))
            .collect();
        c.draw_series(LineSeries::new(closed.clone(), RED.stroke_width(1)))
            .map_err(draw_err)?
            .label("closed form: branch of b (b − 1 modules + agent)")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 18, y)], RED.stroke_width(1)));
        // Marked at each b, so that a study of one b shows its closed form.
        c.draw_series(
            closed
                .iter()
                .map(|&p| Cross::new(p, 5, RED.stroke_width(2))),
        )
        .map_err(draw_err)?;
        // Lower right: the curves rise with b, and a failing b's point
        // near the top-left stays visible.
        crate::render::legend(&mut c, SeriesLabelPosition::LowerRight)?;

        let pmax = study
            .rows
            .iter()
            .flat_map(|r| {
                [
                    r.min_pressure_rigid_hinge,
                    r.min_pressure_elastic,
                    r.closed_pressure_elastic,
                ]
            })
            .filter(|p| p.is_finite())
            .fold(150e3f64, f64::max)
            / 1e3
            * 1.5;
        let mut c = ChartBuilder::on(&right)
            .caption("minimum connector pressure", ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(55)
            .build_cartesian_2d(bmin..bmax, (0.1..pmax).log_scale())
            .map_err(draw_err)?;
        c.configure_mesh()
            .x_desc("branch length b (modules)")
            .y_desc("p (kPa)")
            .draw()
            .map_err(draw_err)?;
        for (kpa, label) in [
            (15.0, "practical electroadhesion 15 kPa"),
            (133.0, "ideal parallel plate 133 kPa"),
        ] {
            c.draw_series(LineSeries::new(
                [(bmin, kpa), (bmax, kpa)],
                BLACK.mix(0.5).stroke_width(1),
            ))
            .map_err(draw_err)?;
            c.draw_series(std::iter::once(Text::new(
                label,
                (bmin + 0.2, kpa * 1.08),
                ("sans-serif", 12),
            )))
            .map_err(draw_err)?;
        }
        let series = [
            (Bending::RigidHinge, BLUE, "rigid hinge"),
            (Bending::Elastic, GREEN, "elastic"),
        ];
        for (bending, colour, name) in series {
            let pts: Vec<(f64, f64)> = study
                .rows
                .iter()
                .filter(|r| r.min_pressure(bending).is_finite())
                .map(|r| (r.b as f64, (r.min_pressure(bending) / 1e3).max(0.1)))
                .collect();
            c.draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
                .map_err(draw_err)?
                .label(format!("{name}, every step"))
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 18, y)], colour.stroke_width(2))
                });
            c.draw_series(pts.iter().map(|&p| Circle::new(p, 4, colour.filled())))
                .map_err(draw_err)?;
            let closed: Vec<(f64, f64)> = study
                .rows
                .iter()
                .map(|r| {
                    let p = match bending {
                        Bending::RigidHinge => r.closed_pressure_rigid_hinge,
                        Bending::Elastic => r.closed_pressure_elastic,
                    };
                    (r.b as f64, (p / 1e3).max(0.1))
                })
                .collect();
            c.draw_series(DashedLineSeries::new(
                closed.clone(),
                6,
                4,
                colour.stroke_width(1),
            ))
            .map_err(draw_err)?
            .label(format!("{name}, closed form"))
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], colour.stroke_width(1)));
            c.draw_series(
                closed
                    .iter()
                    .map(|&p| Cross::new(p, 5, colour.stroke_width(2))),
            )
            .map_err(draw_err)?;
        }
        crate::render::legend(&mut c, SeriesLabelPosition::LowerRight)?;
        root.present().map_err(draw_err)?;
        Ok(())
    })?;
    crate::render::save(&svg, path, 1.0)
}
