//! Why a component with no equilibrium even on rigid connectors falls:
//! where its weight's line of action meets the level of its ground
//! contacts, against the convex hull of those contacts' corners (the
//! support polygon). A rigid body on contacts that push and rub, under
//! its weight alone, stands exactly when that line passes through the
//! hull; so where the rigid limit analysis fails, the line passes outside
//! it, and how far says how badly the structure is out of balance.

use super::limit::{corners, half_side};
use super::model::Model;
use super::pose_hull::convex_hull;
use super::solver::Vec6;
use super::structure::{End, Structure};
use glam::{DVec2, DVec3};

/// The tipping witness of one component at one pose.
#[derive(Clone, Debug, PartialEq)]
pub struct Tipping {
    /// Where the weight's line of action meets the mean level of the
    /// ground contacts (world, in units of `d`).
    pub weight_at_ground: DVec3,
    /// Its distance outside the support polygon, in units of `d` (0 on or
    /// inside it).
    pub outside: f64,
    /// Ground contacts of the component.
    pub contacts: usize,
}

/// The witness of the free bodies `bodies` under `loads` (forces in `W`,
/// moments about each body's centre in `W·d`), supported by the ground
/// contacts among `links`; `None` without ground contacts (nothing to
/// stand on: reported as unsupported) or without a net weight.
pub fn tipping(
    s: &Structure,
    model: &Model,
    loads: &[Vec6],
    bodies: &[usize],
    links: &[usize],
) -> Option<Tipping> {
    let (mut force, mut moment) = (DVec3::ZERO, DVec3::ZERO);
    for &i in bodies.iter().filter(|&&i| !s.bodies[i].fixed) {
        let f = DVec3::new(loads[i][0], loads[i][1], loads[i][2]);
        let m = DVec3::new(loads[i][3], loads[i][4], loads[i][5]);
        force += f;
        moment += s.bodies[i].centre.cross(f) + m;
    }
    let weight = force.length();
    if !(weight.is_finite() && weight > 0.0) {
        return None;
    }
    let down = force / weight;
    // The point of the line of action nearest the origin: F × M / |F|².
    // A NaN moment gives no witness (never a distance that compares false).
    let on_line = force.cross(moment) / (weight * weight);
    if !on_line.is_finite() {
        return None;
    }
    // The squares' corners as the limit analysis places them.
    let support: Vec<DVec3> = links
        .iter()
        .filter(|&&li| matches!(s.links[li].b, End::Ground(_)))
        .flat_map(|&li| corners(&s.links[li], half_side(s, model, li)).map(|(_, c)| c))
        .collect();
    if support.is_empty() {
        return None;
    }
    let level = support.iter().map(|c| c.dot(down)).sum::<f64>() / support.len() as f64;
    let weight_at_ground = on_line + down * (level - on_line.dot(down));
    let (e1, e2) = down.any_orthonormal_pair();
    let plane = |p: DVec3| [p.dot(e1), p.dot(e2)];
    let points: Vec<[f64; 2]> = support.iter().map(|&c| plane(c)).collect();
    let hull = convex_hull(&points, 1e-12);
    Some(Tipping {
        weight_at_ground,
        outside: outside(&hull, plane(weight_at_ground)),
        contacts: support.len() / 4,
    })
}

/// The distance of `p` outside the convex polygon `hull` (counter-clockwise;
/// a point or a segment where degenerate), 0 on or inside it.
fn outside(hull: &[[f64; 2]], p: [f64; 2]) -> f64 {
    let v = |a: [f64; 2]| DVec2::new(a[0], a[1]);
    let p = v(p);
    let to_segment = |a: DVec2, b: DVec2| {
        let ab = b - a;
        let t = if ab.length_squared() > 0.0 {
            ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (a + t * ab - p).length()
    };
    match hull.len() {
        0 => f64::INFINITY,
        1 => (v(hull[0]) - p).length(),
        2 => to_segment(v(hull[0]), v(hull[1])),
        n => {
            let edges = (0..n).map(|i| (v(hull[i]), v(hull[(i + 1) % n])));
            if edges.clone().all(|(a, b)| (b - a).perp_dot(p - a) >= 0.0) {
                0.0
            } else {
                edges
                    .map(|(a, b)| to_segment(a, b))
                    .fold(f64::INFINITY, f64::min)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::outside;

    #[test]
    fn a_point_that_is_not_finite_is_never_read_as_inside() {
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert_ne!(outside(&sq, [f64::NAN, 0.5]), 0.0);
    }

    #[test]
    fn a_point_inside_a_square_is_zero_outside_and_one_beyond_an_edge_is_its_distance() {
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert_eq!(outside(&sq, [0.5, 0.5]), 0.0);
        assert_eq!(outside(&sq, [1.0, 0.5]), 0.0);
        assert!((outside(&sq, [1.5, 0.5]) - 0.5).abs() < 1e-15);
        assert!((outside(&sq, [2.0, 2.0]) - 2f64.sqrt()).abs() < 1e-15);
        assert!((outside(&[[0.0, 0.0], [2.0, 0.0]], [1.0, 3.0]) - 3.0).abs() < 1e-15);
    }
}
