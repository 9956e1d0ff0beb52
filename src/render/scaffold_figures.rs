//! Seed 000 Figs. 11–13: reconfiguration time, time per height level and
//! modules per step against the shape's size, one curve per shape and
//! protocol, with the published points (Eq. 6 for the pyramid, the
//! authors' cube runs) as large open marks.

use crate::error::Error;
use crate::render::{SvgCanvas, draw_err};
use crate::study::scaffold_figures::{Family, Run, published};
use plotters::prelude::*;
use std::path::Path;

/// What a size figure plots.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Metric {
    /// Fig. 11: total time steps.
    Steps,
    /// Fig. 12: time steps per height level.
    StepsPerLevel,
    /// Fig. 13: modules placed per time step.
    ModulesPerStep,
}

impl Metric {
    fn of(self, r: &Run) -> f64 {
        match self {
            Metric::Steps => r.steps as f64,
            Metric::StepsPerLevel => r.steps_per_level(),
            Metric::ModulesPerStep => r.modules_per_step(),
        }
    }

    /// The published value at a (steps, modules) point, given our level
    /// count of the same shape.
    fn published(self, steps: usize, modules: usize, levels: usize) -> f64 {
        match self {
            Metric::Steps => steps as f64,
            Metric::StepsPerLevel => steps as f64 / levels.max(1) as f64,
            Metric::ModulesPerStep => modules as f64 / steps.max(1) as f64,
        }
    }

    fn caption(self) -> &'static str {
        match self {
            Metric::Steps => "Fig. 11: reconfiguration time",
            Metric::StepsPerLevel => "Fig. 12: time steps per height level",
            Metric::ModulesPerStep => "Fig. 13: modules placed per time step",
        }
    }
}

/// The title's note of the feeds, when a run does not use the default.
fn feeds(runs: &[Run]) -> String {
    use crate::algorithms::scaffold::feed::Feed;
    let names: std::collections::BTreeSet<&str> = runs.iter().map(|r| r.feed.name()).collect();
    if runs.iter().all(|r| r.feed == Feed::default()) {
        String::new()
    } else {
        format!(", feed {}", Vec::from_iter(names).join(" / "))
    }
}

fn colour(f: Family) -> RGBColor {
    match f {
        Family::HalfSphere => RGBColor(0, 140, 0),
        Family::Pyramid => RGBColor(200, 0, 0),
        Family::Cylinder => RGBColor(0, 0, 210),
        Family::Cube => RGBColor(150, 0, 150),
        Family::StackedCylinder => RGBColor(0, 140, 160),
    }
}

/// Draws `metric` against size for every (family, protocol) of `runs`:
/// solid lines the paper's protocol, dashed the safe one, open circles
/// the published points.
pub fn draw(runs: &[Run], metric: Metric, path: &Path) -> Result<(), Error> {
    let svg = crate::render::svg(path, |svg| {
        let root = SvgCanvas::with_string(svg, (900, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let smin = runs.iter().map(|r| r.size).min().unwrap_or(2) as f64 - 0.3;
        let smax = runs.iter().map(|r| r.size).max().unwrap_or(9) as f64 + 0.3;
        let published_pts: Vec<(Family, f64, f64)> = runs
            .iter()
            .filter(|r| r.protocol.name() == "paper")
            .filter_map(|r| {
                published::point(r.family, r.size)
                    .map(|(t, n)| (r.family, r.size as f64, metric.published(t, n, r.levels)))
            })
            .collect();
        let ymax = runs
            .iter()
            .map(|r| metric.of(r))
            .chain(published_pts.iter().map(|p| p.2))
            .fold(1.0f64, f64::max)
            * 1.1;
        let mut c = ChartBuilder::on(&root)
            .caption(
                format!("{} (seed 000, b = 6{})", metric.caption(), feeds(runs)),
                ("sans-serif", 18),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(smin..smax, 0.0..ymax)
            .map_err(draw_err)?;
        c.configure_mesh()
            .x_desc("size (tiles: h of the pyramid, N of the authors' shapes)")
            .y_desc(match metric {
                Metric::Steps => "time steps",
                Metric::StepsPerLevel => "time steps / tile layer",
                Metric::ModulesPerStep => "modules / time step",
            })
            .draw()
            .map_err(draw_err)?;
        let mut families: Vec<Family> = runs.iter().map(|r| r.family).collect();
        families.dedup();
        for f in families {
            let col = colour(f);
            for protocol in ["paper", "safe"] {
                let pts: Vec<(f64, f64)> = runs
                    .iter()
                    .filter(|r| r.family == f && r.protocol.name() == protocol)
                    .map(|r| (r.size as f64, metric.of(r)))
                    .collect();
                if pts.is_empty() {
                    continue;
                }
                let label = format!("{}, {protocol} protocol", f.name());
                if protocol == "paper" {
                    c.draw_series(LineSeries::new(pts.clone(), col.stroke_width(2)))
                        .map_err(draw_err)?
                        .label(label)
                        .legend(move |(x, y)| {
                            PathElement::new([(x, y), (x + 18, y)], col.stroke_width(2))
                        });
                    c.draw_series(pts.iter().map(|&p| Circle::new(p, 3, col.filled())))
                        .map_err(draw_err)?;
                } else {
                    c.draw_series(DashedLineSeries::new(pts, 5, 4, col.stroke_width(1)))
                        .map_err(draw_err)?
                        .label(label)
                        .legend(move |(x, y)| {
                            PathElement::new([(x, y), (x + 18, y)], col.stroke_width(1))
                        });
                }
            }
            let mine: Vec<(f64, f64)> = published_pts
                .iter()
                .filter(|p| p.0 == f)
                .map(|p| (p.1, p.2))
                .collect();
            if !mine.is_empty() {
                c.draw_series(mine.iter().map(|&p| Circle::new(p, 7, col.stroke_width(2))))
                    .map_err(draw_err)?
                    .label(format!(
                        "{}, published ({})",
                        f.name(),
                        if f == Family::Pyramid {
                            "Eq. 6"
                        } else {
                            "authors' runs"
                        }
                    ))
                    .legend(move |(x, y)| Circle::new((x + 9, y), 6, col.stroke_width(2)));
            }
        }
        crate::render::legend(&mut c, SeriesLabelPosition::UpperLeft)?;
        root.present().map_err(draw_err)?;
        Ok(())
    })?;
    crate::render::save(&svg, path, 1.0)
}
