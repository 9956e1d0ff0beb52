//! Pictures of the catom geometry: the body, one sweep, one collision.
//!
//! Orthographic projection drawn straight into an SVG string (painter's
//! algorithm: bodies back to front, each body's silhouette then its flat
//! faces, Lambert-shaded), written by [`crate::render::save`].

use crate::geometry::EPSILON;
use crate::geometry::catom::{L, catom};
use crate::geometry::rolling::{Link, Roll};
use crate::geometry::rules::{Offset, table};
use crate::geometry::sweep::{PairOutcome, Path, sweep_pair};
use crate::lattice::{Cell, FccLattice, Lattice, Route, fcc};
use glam::{DQuat, DVec2, DVec3};
use std::fmt::Write;

/// What to draw.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Picture {
    /// The catom body from three directions.
    Body,
    /// A 90° octagonal rotation: start, middle and end poses with the
    /// cells that block it.
    Sweep,
    /// The deepest point of a collision, with its witness points.
    Collision,
}

/// A body to draw: pose and colour.
struct Solid {
    centre: DVec3,
    rotation: DQuat,
    colour: (u8, u8, u8),
    opacity: f64,
}

/// The flat faces of `Q` (26 of them: 12 connectors, 6 octagonal, 8
/// hexagonal), each as its outward normal and vertices in order.
fn faces() -> Vec<(DVec3, Vec<DVec3>)> {
    let body = catom();
    let mut normals: Vec<DVec3> = fcc::directions().to_vec();
    normals.extend(fcc::octagonal_axes());
    normals.extend(fcc::hexagonal_axes());
    normals
        .into_iter()
        .map(|n| {
            let h = body.support_q(n);
            let mut vs: Vec<DVec3> = body
                .vertices()
                .iter()
                .copied()
                .filter(|v| (v.dot(n) - h).abs() < 1e-9)
                .collect();
            let c = vs.iter().copied().sum::<DVec3>() / vs.len() as f64;
            let e1 = (vs[0] - c).normalize();
            let e2 = n.cross(e1);
            vs.sort_by(|a, b| {
                let (pa, pb) = (*a - c, *b - c);
                pa.dot(e2)
                    .atan2(pa.dot(e1))
                    .total_cmp(&pb.dot(e2).atan2(pb.dot(e1)))
            });
            (n, vs.into_iter().map(|v| v + L * n).collect())
        })
        .collect()
}

/// 2D convex hull (monotone chain).
fn hull(mut p: Vec<DVec2>) -> Vec<DVec2> {
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    let cross = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut h: Vec<DVec2> = Vec::new();
    for pass in 0..2 {
        let start = h.len();
        let iter: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in iter {
            while h.len() >= start + 2 && cross(h[h.len() - 2], h[h.len() - 1], q) <= 0.0 {
                h.pop();
            }
            h.push(q);
        }
        h.pop();
    }
    h
}

/// An orthographic camera looking along `-back`.
struct Camera {
    right: DVec3,
    up: DVec3,
    back: DVec3,
    scale: f64,
    origin: DVec2,
}

impl Camera {
    fn new(back: DVec3, scale: f64, origin: DVec2) -> Camera {
        let back = back.normalize();
        let right = DVec3::Z.cross(back).try_normalize().unwrap_or(DVec3::X);
        let up = back.cross(right);
        Camera {
            right,
            up,
            back,
            scale,
            origin,
        }
    }

    /// A camera that fits the bodies centred at `centres` in the box
    /// `(x0, y0)–(x1, y1)` of the picture.
    fn fit(back: DVec3, centres: &[DVec3], x0: f64, y0: f64, x1: f64, y1: f64) -> Camera {
        let unit = Camera::new(back, 1.0, DVec2::ZERO);
        let r = catom().radius();
        let pts: Vec<DVec2> = centres.iter().map(|c| unit.project(*c)).collect();
        let lo = pts
            .iter()
            .copied()
            .fold(DVec2::splat(f64::INFINITY), DVec2::min)
            - r;
        let hi = pts
            .iter()
            .copied()
            .fold(DVec2::splat(f64::NEG_INFINITY), DVec2::max)
            + r;
        let scale = ((x1 - x0) / (hi.x - lo.x)).min((y1 - y0) / (hi.y - lo.y));
        let mid = 0.5 * (lo + hi);
        let origin = DVec2::new(0.5 * (x0 + x1), 0.5 * (y0 + y1)) - mid * scale;
        Camera::new(back, scale, origin)
    }

    fn project(&self, p: DVec3) -> DVec2 {
        self.origin + DVec2::new(p.dot(self.right), -p.dot(self.up)) * self.scale
    }
}

fn polygon(svg: &mut String, pts: &[DVec2], fill: (u8, u8, u8), opacity: f64, stroke: &str) {
    let path: Vec<String> = pts
        .iter()
        .map(|p| format!("{:.1},{:.1}", p.x, p.y))
        .collect();
    let _ = writeln!(
        svg,
        r#"<polygon points="{}" fill="rgb({},{},{})" fill-opacity="{opacity:.2}" stroke="{stroke}" stroke-width="0.6" stroke-opacity="{opacity:.2}"/>"#,
        path.join(" "),
        fill.0,
        fill.1,
        fill.2
    );
}

fn draw(svg: &mut String, cam: &Camera, solids: &mut [Solid]) {
    let faces = faces();
    let light = DVec3::new(0.4, 0.3, 0.85).normalize();
    let sphere: Vec<DVec3> = (0..64)
        .map(|i| {
            let z = 1.0 - (i as f64 + 0.5) / 32.0;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let a = i as f64 * 2.399963;
            DVec3::new(r * a.cos(), r * a.sin(), z)
        })
        .collect();
    solids.sort_by(|a, b| a.centre.dot(cam.back).total_cmp(&b.centre.dot(cam.back)));
    for s in solids.iter() {
        let shade = |k: f64| {
            let f = |c: u8| ((c as f64) * k).clamp(0.0, 255.0) as u8;
            (f(s.colour.0), f(s.colour.1), f(s.colour.2))
        };
        let outline: Vec<DVec2> = catom()
            .vertices()
            .iter()
            .flat_map(|v| sphere.iter().map(move |u| *v + L * *u))
            .map(|p| cam.project(s.centre + s.rotation * p))
            .collect();
        polygon(svg, &hull(outline), shade(0.55), s.opacity, "#333");
        for (n, vs) in &faces {
            let n = s.rotation * *n;
            if n.dot(cam.back) <= 0.0 {
                continue;
            }
            let k = 0.55 + 0.45 * n.dot(light).max(0.0);
            let pts: Vec<DVec2> = vs
                .iter()
                .map(|v| cam.project(s.centre + s.rotation * *v))
                .collect();
            polygon(svg, &pts, shade(k), s.opacity, "#222");
        }
    }
}

fn label(svg: &mut String, at: DVec2, text: &str, size: u32) {
    let _ = writeln!(
        svg,
        r##"<text x="{:.1}" y="{:.1}" font-family="DejaVu Sans" font-size="{size}" fill="#222">{text}</text>"##,
        at.x, at.y
    );
}

fn document(w: u32, h: u32, body: &str) -> String {
    format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}"><rect width="100%" height="100%" fill="white"/>{body}</svg>"#
    )
}

const BLUE: (u8, u8, u8) = (90, 140, 220);
const GREY: (u8, u8, u8) = (185, 185, 185);
const RED: (u8, u8, u8) = (225, 90, 80);

fn rest(c: DVec3, colour: (u8, u8, u8), opacity: f64) -> Solid {
    Solid {
        centre: c,
        rotation: DQuat::IDENTITY,
        colour,
        opacity,
    }
}

/// Renders a picture as an SVG document.
pub fn svg(picture: Picture) -> String {
    let mut body = String::new();
    match picture {
        Picture::Body => {
            let views = [
                (
                    DVec3::new(1.0, -1.0, 0.0),
                    "side: connector (1,0,0) faces right",
                ),
                (DVec3::new(0.0, 0.0, 1.0), "top: octagonal square on ẑ"),
                (DVec3::new(1.3, -0.8, 0.7), "oblique"),
            ];
            for (i, (back, title)) in views.iter().enumerate() {
                let cam = Camera::new(*back, 300.0, DVec2::new(200.0 + 400.0 * i as f64, 230.0));
                draw(&mut body, &cam, &mut [rest(DVec3::ZERO, BLUE, 1.0)]);
                label(
                    &mut body,
                    DVec2::new(60.0 + 400.0 * i as f64, 420.0),
                    title,
                    16,
                );
            }
            label(
                &mut body,
                DVec2::new(20.0, 30.0),
                "3D Catom: rhombicuboctahedron of edge L = d/(3+√2) ⊕ ball of radius L",
                18,
            );
            document(1200, 450, &body)
        }
        Picture::Sweep => {
            let link = Link {
                from: 0,
                to: 1,
                route: Route::Octagonal,
            };
            let roll = Roll::new(DVec3::ZERO, link);
            let mut solids = vec![rest(DVec3::ZERO, GREY, 1.0)];
            for o in table().get(link).blocking() {
                if o != Offset::between(
                    Cell::new(0, 0, 0),
                    FccLattice.neighbour(Cell::new(0, 0, 0), 1),
                ) {
                    solids.push(rest(o.vector(), RED, 0.35));
                }
            }
            for (s, op) in [(0.0, 0.55), (0.5, 0.8), (1.0, 0.55)] {
                solids.push(Solid {
                    centre: roll.centre(s),
                    rotation: roll.rotation(s),
                    colour: BLUE,
                    opacity: op,
                });
            }
            let centres: Vec<DVec3> = solids.iter().map(|s| s.centre).collect();
            let cam = Camera::fit(
                DVec3::new(0.35, 0.25, 1.0),
                &centres,
                20.0,
                70.0,
                820.0,
                700.0,
            );
            draw(&mut body, &cam, &mut solids);
            label(
                &mut body,
                DVec2::new(20.0, 30.0),
                &format!("rotation {link}: pivot (grey), mover at s = 0, ½, 1 (blue)"),
                18,
            );
            label(
                &mut body,
                DVec2::new(20.0, 55.0),
                "cells whose occupant the sweep penetrates (red, derived)",
                16,
            );
            document(840, 720, &body)
        }
        Picture::Collision => {
            let link = Link {
                from: 0,
                to: 1,
                route: Route::Octagonal,
            };
            let roll = Roll::new(DVec3::ZERO, link);
            let obstacle = Offset::between(Cell::new(0, 0, 0), Cell::new(0, 2, 0)).vector();
            let PairOutcome::Collision(x) =
                sweep_pair(&roll, &Path::Static(obstacle), EPSILON).outcome
            else {
                unreachable!("the in-line neighbour of a 90° target is penetrated (tested)")
            };
            let cam = Camera::fit(
                DVec3::new(0.0, 0.0, 1.0),
                &[DVec3::ZERO, obstacle],
                20.0,
                80.0,
                680.0,
                700.0,
            );
            let mut solids = vec![
                rest(DVec3::ZERO, GREY, 1.0),
                rest(obstacle, RED, 0.6),
                Solid {
                    centre: roll.centre(x.s),
                    rotation: roll.rotation(x.s),
                    colour: BLUE,
                    opacity: 0.6,
                },
            ];
            draw(&mut body, &cam, &mut solids);
            for (p, c) in [(x.gap.p1, "#0033aa"), (x.gap.p2, "#aa1100")] {
                let q = cam.project(p);
                let _ = writeln!(
                    body,
                    r#"<circle cx="{:.1}" cy="{:.1}" r="4" fill="{c}"/>"#,
                    q.x, q.y
                );
            }
            label(
                &mut body,
                DVec2::new(20.0, 30.0),
                &format!("collision: rotation {link} with a module at (0,2,0)"),
                18,
            );
            label(
                &mut body,
                DVec2::new(20.0, 55.0),
                &format!(
                    "deepest at s = {:.3}: depth {:.4} d (witness points marked), seen from above",
                    x.s, -x.gap.dist
                ),
                16,
            );
            document(700, 720, &body)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_picture_renders_to_png() {
        for p in [Picture::Body, Picture::Sweep, Picture::Collision] {
            let svg = svg(p);
            assert!(svg.matches("<polygon").count() > 20, "{p:?}");
            let png = crate::render::rasterise(&svg, 1.0).unwrap();
            assert_eq!(&png[1..4], b"PNG");
        }
    }

    #[test]
    fn faces_of_q_are_26_with_the_right_vertex_counts() {
        let f = faces();
        assert_eq!(f.len(), 26);
        assert_eq!(f.iter().filter(|(_, v)| v.len() == 4).count(), 18);
        assert_eq!(f.iter().filter(|(_, v)| v.len() == 3).count(), 8);
    }
}
