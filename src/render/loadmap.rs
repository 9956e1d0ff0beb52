//! Load map: a projected drawing of a structure with every connector
//! coloured by its utilisation (green → yellow → red at capacity, purple
//! beyond), modules as discs (fixed ones dark), movers as open circles at
//! the position where they load their pivot most.

use crate::certify::load_check::replay;
use crate::error::{Error, InputError};
use crate::mechanics::Model;
use crate::mechanics::analysis::Critical;
use crate::mechanics::structure::End;
use crate::mechanics::{Analysis, Structure};
use crate::render::{DrawError, draw_err};
use crate::schedule::Schedule;
use glam::DVec3;
use plotters::prelude::*;
use std::path::Path;

/// Colour of a utilisation: green (0) → yellow (½) → red (1); purple > 1.
pub fn colour(u: f64) -> RGBColor {
    if crate::mechanics::capacity::overloaded(u) {
        return RGBColor(150, 0, 200);
    }
    let u = u.clamp(0.0, 1.0);
    if u < 0.5 {
        RGBColor((510.0 * u) as u8, 180, 0)
    } else {
        RGBColor(255, (180.0 * (2.0 - 2.0 * u)) as u8, 0)
    }
}

/// Oblique projection: the horizontal axes across and into the picture,
/// gravity downwards. Returns (screen x, screen y, depth).
fn projector(gravity: DVec3) -> impl Fn(DVec3) -> (f64, f64, f64) {
    let up = -gravity;
    // Across: the world axis most perpendicular to up, first x.
    let across = if up.x.abs() < 0.5 { DVec3::X } else { DVec3::Z };
    let depth = up.cross(across).normalize();
    move |p: DVec3| {
        let (a, u, d) = (p.dot(across), p.dot(up), p.dot(depth));
        (a + 0.45 * d, u + 0.3 * d, d)
    }
}

/// Draws the load map of `s` with results `a` into an SVG string.
pub fn draw(s: &Structure, a: &Analysis, title: &str) -> Result<String, DrawError> {
    let proj = projector(s.gravity);
    let mut pts: Vec<(f64, f64)> = s
        .bodies
        .iter()
        .map(|b| {
            let (x, y, _) = proj(b.centre);
            (x, y)
        })
        .collect();
    for h in &s.hanging {
        for c in &h.path {
            let (x, y, _) = proj(*c);
            pts.push((x, y));
        }
    }
    if pts.is_empty() {
        pts.push((0.0, 0.0));
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y) in &pts {
        x0 = x0.min(*x);
        x1 = x1.max(*x);
        y0 = y0.min(*y);
        y1 = y1.max(*y);
    }
    let pad = 1.0;
    let (w, h) = (x1 - x0 + 2.0 * pad, y1 - y0 + 2.0 * pad);
    let px = 900.0;
    let scale = (px / w).min(640.0 / h).min(60.0);
    let width = (w * scale) as u32 + 40;
    let height = (h * scale) as u32 + 110;
    let to_screen = |(x, y): (f64, f64)| -> (i32, i32) {
        (
            (20.0 + (x - x0 + pad) * scale) as i32,
            (70.0 + (y1 + pad - y) * scale) as i32,
        )
    };
    let mut svg = String::new();
    {
        let root =
            super::SvgCanvas::with_string(&mut svg, (width.max(420), height)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        root.draw(&Text::new(title.to_string(), (10, 8), ("sans-serif", 16)))
            .map_err(draw_err)?;
        // Colour bar.
        for k in 0..=100 {
            let u = k as f64 / 100.0 * 1.2;
            root.draw(&Rectangle::new(
                [(10 + 3 * k, 34), (13 + 3 * k, 48)],
                colour(u).filled(),
            ))
            .map_err(draw_err)?;
        }
        for (u, label) in [(0.0, "0"), (0.5, "0.5"), (1.0, "1"), (1.2, "> 1")] {
            let x = 10 + (u / 1.2 * 300.0) as i32;
            root.draw(&Text::new(label, (x, 50), ("sans-serif", 11)))
                .map_err(draw_err)?;
        }
        root.draw(&Text::new(
            "connector utilisation (load / capacity)",
            (320, 36),
            ("sans-serif", 12),
        ))
        .map_err(draw_err)?;
        let r = (0.22 * scale).max(2.0) as i32;
        // Far things first.
        let mut order: Vec<usize> = (0..s.bodies.len()).collect();
        order.sort_by(|&i, &j| {
            proj(s.bodies[j].centre)
                .2
                .total_cmp(&proj(s.bodies[i].centre).2)
        });
        let mut links: Vec<usize> = (0..s.links.len()).collect();
        links.sort_by(|&i, &j| {
            proj(s.links[j].contact)
                .2
                .total_cmp(&proj(s.links[i].contact).2)
        });
        for &i in &order {
            let b = &s.bodies[i];
            let (x, y, _) = proj(b.centre);
            let fill = if b.fixed {
                RGBColor(90, 90, 90)
            } else {
                RGBColor(205, 205, 205)
            };
            root.draw(&Circle::new(to_screen((x, y)), r, fill.filled()))
                .map_err(draw_err)?;
        }
        for &li in &links {
            let l = &s.links[li];
            let res = &a.links[li];
            let pa = s.bodies[l.a].centre;
            let pb = match l.b {
                End::Body(b) => s.bodies[b].centre,
                End::Ground(_) => l.contact + 0.25 * l.normal,
            };
            let (ax, ay, _) = proj(pa);
            let (bx, by, _) = proj(pb);
            let width = if crate::mechanics::capacity::overloaded(res.utilisation) {
                4
            } else {
                2 + (res.utilisation * 2.0) as u32
            };
            let style = if res.released {
                RGBColor(160, 160, 160).stroke_width(1)
            } else {
                colour(res.utilisation).stroke_width(width)
            };
            root.draw(&PathElement::new(
                [to_screen((ax, ay)), to_screen((bx, by))],
                style,
            ))
            .map_err(draw_err)?;
        }
        for p in &a.pivots {
            let hang = &s.hanging[p.hanging];
            let k =
                ((p.s * (hang.path.len() - 1) as f64).round() as usize).min(hang.path.len() - 1);
            let (mx, my, _) = proj(hang.path[k]);
            let (px_, py_, _) = proj(s.bodies[hang.pivot].centre);
            root.draw(&PathElement::new(
                [to_screen((mx, my)), to_screen((px_, py_))],
                colour(p.utilisation).stroke_width(3),
            ))
            .map_err(draw_err)?;
            root.draw(&Circle::new(to_screen((mx, my)), r, BLACK.stroke_width(2)))
                .map_err(draw_err)?;
        }
        root.present().map_err(draw_err)?;
    }
    Ok(svg)
}

/// Replays `schedule` to `step` (1-based; `steps + 1` is the final
/// configuration), analyses it with `model` and writes the load map to
/// `path`. Returns a one-line summary.
pub fn render_step(
    schedule: &Schedule,
    model: &Model,
    step: usize,
    path: &Path,
) -> Result<String, Error> {
    let last = schedule.steps.len() + 1;
    if step == 0 || step > last {
        return Err(InputError::new(format!("step must be in 1..={last}, got {step}")).into());
    }
    let mut picture = None;
    let mut summary = String::new();
    // Stop early: a truncated copy of the schedule replays only what is needed.
    let mut upto = schedule.clone();
    upto.steps.truncate(step.min(schedule.steps.len()));
    let wanted = if step == last {
        upto.steps.len() + 1
    } else {
        step
    };
    replay(&upto, model, true, |k, s, a, _| {
        if k != wanted {
            return;
        }
        let critical = match a.critical {
            Some(Critical::Link(i)) => s.describe(&s.links[i]),
            Some(Critical::Pivot(i)) => {
                format!("pivot of mover {}", s.hanging[a.pivots[i].hanging].mover)
            }
            None => "-".into(),
        };
        summary = format!(
            "step {step}: {} modules, {} connectors, max utilisation {:.4} at {critical}, {:?}",
            s.bodies.len(),
            s.links.len(),
            a.max_utilisation,
            a.verdict()
        );
        let title = format!(
            "{}: step {step}, max utilisation {:.3} ({:?})",
            model.name,
            a.max_utilisation,
            a.verdict()
        );
        picture = Some(draw(s, a, &title));
    })?;
    let svg = picture
        .expect("the wanted step is replayed")
        .map_err(|e| Error::Render {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    crate::render::save(&svg, path, 1.0)?;
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_run_from_green_through_red_to_purple_beyond_capacity() {
        assert_eq!(colour(0.0), RGBColor(0, 180, 0));
        assert_eq!(colour(1.0), RGBColor(255, 0, 0));
        assert_eq!(colour(1.5), RGBColor(150, 0, 200));
        assert_eq!(colour(f64::INFINITY), RGBColor(150, 0, 200));
    }

    use crate::algorithms::branch::branch_schedule;

    #[test]
    fn a_load_map_of_a_branch_step_is_written_and_names_the_root() {
        let s = branch_schedule(3, 3.6).unwrap();
        let dir = std::env::temp_dir().join(format!("reconfcheck-loadmap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("map.png");
        let summary = render_step(&s, &Model::default_catom(), s.steps.len(), &p).unwrap();
        assert!(summary.contains("connector 0–1"), "{summary}");
        assert_eq!(&std::fs::read(&p).unwrap()[1..4], b"PNG");
        let svg = dir.join("map.svg");
        render_step(&s, &Model::default_catom(), s.steps.len() + 1, &svg).unwrap();
        assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
        assert!(render_step(&s, &Model::default_catom(), 0, &p).is_err());
        std::fs::remove_dir_all(&dir).ok();
    }
}
