//! Exact rolling kinematics of one rotation (SPEC §3).
//!
//! A mobile catom M rolls without slipping on its pivot P. Two identical
//! convex bodies rolling on each other stay mirror images through their
//! common tangent plane, so with the contact normal `m(s)` moving along the
//! great-circle arcs `n_f → a → n_t` (uniform in angle on each half):
//!
//! ```text
//! centre(s)   = p + 2·h_B(m(s))·m(s)
//! rotation(s) = H(m(s))·H(n_f),      H(u) = 2uuᵀ − I
//! ```
//!
//! # Speed bound (used by conservative advancement)
//!
//! On each half the arc angle is `φ`, so `|m'| = 2φ`. Since `m ⟂ m'`,
//! `c' = 2 (dh/ds) m + 2 h m'` with `|dh/ds| ≤ R_Q |m'|` (the gradient of the
//! support function of `Q` is a point of `Q`, and `h_B = h_Q + L` on unit
//! vectors) and `h ≤ R_B`, hence `|c'| ≤ 2|m'|·√(R_Q² + R_B²)`. `H(m(s))` is
//! `R_k(2α)·H(m₀)` when `m` turns by `α` about `k ⟂ m`, so the body turns at
//! angular speed `2|m'|`. A point of the inner polyhedron `Q` (|r| ≤ R_Q)
//! therefore moves at speed at most
//!
//! ```text
//! V = 4φ·(√(R_Q² + R_B²) + R_Q)
//! ```
//!
//! and between `s` and `s + Δ` every point of `Q(s)` moves by at most `V·Δ`.
//! The rounded body is `Q(s) ⊕ ball(L)`, whose Hausdorff distance to
//! `Q(s+Δ) ⊕ ball(L)` is at most that of the inner polyhedra, and a signed
//! distance changes by at most the Hausdorff distance of either body's
//! displacement. So `|dist(s+Δ) − dist(s)| ≤ (V₁ + V₂)·Δ` for two bodies
//! (`V = 0` for a static one). A numerical test checks the bound.

use super::catom::catom;
use crate::lattice::{Cell, Lattice, Motion, Route, fcc};
use glam::{DQuat, DVec3};
use parry3d_f64::math::Pose;
use serde::{Deserialize, Serialize};
use std::fmt;

/// A rotation link of a pivot: the mover goes from the cell in connector
/// direction `from` to the cell in direction `to` (directions from the
/// pivot, numbered as in [`crate::lattice::fcc`]) by `route`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Link {
    pub from: u8,
    pub to: u8,
    pub route: Route,
}

impl fmt::Display for Link {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let r = match self.route {
            Route::Hexagonal => "hex",
            Route::Octagonal => "oct",
        };
        write!(f, "{:>2}→{:<2} {r}", self.from, self.to)
    }
}

impl Link {
    /// The axis the contact normal passes through (hexagonal or octagonal).
    pub fn via(&self) -> Option<DVec3> {
        fcc::rotation_axis(
            fcc::direction(self.from as usize),
            fcc::direction(self.to as usize),
            self.route,
        )
    }

    /// Whether the two directions are 90° apart (octagonal only).
    pub fn is_right_angle(&self) -> bool {
        fcc::direction(self.from as usize)
            .dot(fcc::direction(self.to as usize))
            .abs()
            < 1e-9
    }

    /// The link of a rotation motion on the FCC lattice, if it is one.
    pub fn of_motion(lattice: &dyn Lattice, motion: &Motion) -> Option<Link> {
        let Motion::Rotate {
            from,
            to,
            pivot,
            route,
        } = motion
        else {
            return None;
        };
        let link = Link {
            from: lattice.direction_to(*pivot, *from)? as u8,
            to: lattice.direction_to(*pivot, *to)? as u8,
            route: *route,
        };
        link.via().map(|_| link)
    }
}

/// The 120 rotation links of a pivot (48 hexagonal, 72 octagonal), sorted.
pub fn links() -> Vec<Link> {
    let mut v = Vec::with_capacity(120);
    for from in 0..12u8 {
        for to in 0..12u8 {
            for route in [Route::Hexagonal, Route::Octagonal] {
                let l = Link { from, to, route };
                if l.via().is_some() {
                    v.push(l);
                }
            }
        }
    }
    v
}

/// Half-turn about the unit vector `u` as a quaternion.
fn half_turn(u: DVec3) -> DQuat {
    DQuat::from_xyzw(u.x, u.y, u.z, 0.0)
}

/// Spherical interpolation between unit vectors `a` and `b` (angle `phi`).
fn slerp(a: DVec3, b: DVec3, phi: f64, t: f64) -> DVec3 {
    let s = phi.sin();
    (a * ((1.0 - t) * phi).sin() + b * (t * phi).sin()) / s
}

/// One rolling rotation about a pivot, parameterised by `s ∈ [0, 1]`.
#[derive(Copy, Clone, Debug)]
pub struct Roll {
    pub link: Link,
    /// Pivot centre (units of d).
    pub pivot: DVec3,
    n_f: DVec3,
    via: DVec3,
    n_t: DVec3,
    /// Arc angle of each half (both halves are equal for every FCC link).
    phi1: f64,
    phi2: f64,
    speed: f64,
}

impl Roll {
    /// The rolling of `link` about a pivot centred at `pivot`.
    pub fn new(pivot: DVec3, link: Link) -> Roll {
        let n_f = fcc::direction(link.from as usize);
        let n_t = fcc::direction(link.to as usize);
        let via = link.via().expect("a link of the FCC lattice");
        let phi1 = n_f.dot(via).clamp(-1.0, 1.0).acos();
        let phi2 = via.dot(n_t).clamp(-1.0, 1.0).acos();
        let body = catom();
        let (rq, rb) = (body.radius_q(), body.radius());
        let speed = 4.0 * phi1.max(phi2) * ((rq * rq + rb * rb).sqrt() + rq);
        Roll {
            link,
            pivot,
            n_f,
            via,
            n_t,
            phi1,
            phi2,
            speed,
        }
    }

    /// The rolling of a rotation motion, if it is one on this lattice.
    pub fn of_motion(lattice: &dyn Lattice, motion: &Motion) -> Option<Roll> {
        let link = Link::of_motion(lattice, motion)?;
        let pivot: Cell = match motion {
            Motion::Rotate { pivot, .. } => *pivot,
            _ => return None,
        };
        Some(Roll::new(lattice.centre(pivot), link))
    }

    /// Contact normal `m(s)` (pivot → mover).
    pub fn normal(&self, s: f64) -> DVec3 {
        let s = s.clamp(0.0, 1.0);
        if s <= 0.5 {
            slerp(self.n_f, self.via, self.phi1, 2.0 * s)
        } else {
            slerp(self.via, self.n_t, self.phi2, 2.0 * s - 1.0)
        }
    }

    /// Mover centre at `s`.
    pub fn centre(&self, s: f64) -> DVec3 {
        let m = self.normal(s);
        self.pivot + 2.0 * catom().support(m) * m
    }

    /// Mover orientation at `s`: `H(m(s))·H(n_f)`.
    pub fn rotation(&self, s: f64) -> DQuat {
        (half_turn(self.normal(s)) * half_turn(self.n_f)).normalize()
    }

    /// Mover pose at `s`.
    pub fn pose(&self, s: f64) -> Pose {
        Pose::from_parts(self.centre(s), self.rotation(s))
    }

    /// Bound `V` on the speed (per unit `s`) of any point of the mover's
    /// inner polyhedron: see the module documentation.
    pub fn speed_bound(&self) -> f64 {
        self.speed
    }

    /// Axis `k` of the half-sweep containing `s` (`half` 0 for `s ≤ ½`):
    /// on each half the motion is planar, a rotation about `k` with the
    /// centre moving in a plane normal to `k`, so the mover's extent along
    /// `±k` is constant on that half.
    pub fn half_axis(&self, half: usize) -> DVec3 {
        if half == 0 {
            self.n_f.cross(self.via).normalize()
        } else {
            self.via.cross(self.n_t).normalize()
        }
    }

    /// Support function of the mover at `s` in the unit direction `u`.
    pub fn support(&self, s: f64, u: DVec3) -> f64 {
        let q = self.rotation(s);
        u.dot(self.centre(s)) + catom().support(q.inverse() * u)
    }

    /// Largest centre distance from the pivot along the sweep is below this
    /// (≈ 1.0450 d; the bound adds the Lipschitz slack of the sampling).
    pub fn reach(&self) -> f64 {
        let n = 256;
        let body = catom();
        let (rq, rb) = (body.radius_q(), body.radius());
        let vc = 4.0 * self.phi1.max(self.phi2) * (rq * rq + rb * rb).sqrt();
        (0..=n)
            .map(|i| (self.centre(i as f64 / n as f64) - self.pivot).length())
            .fold(0.0, f64::max)
            + vc / (2.0 * n as f64)
    }

    /// A ball containing the mover's body along the whole sweep: (centre
    /// relative to the pivot, radius). Sampled centres plus the Lipschitz
    /// slack of the sampling plus the body's circumradius.
    pub fn swept_ball(&self) -> (DVec3, f64) {
        let n = 256;
        let body = catom();
        let (rq, rb) = (body.radius_q(), body.radius());
        let vc = 4.0 * self.phi1.max(self.phi2) * (rq * rq + rb * rb).sqrt();
        let pts: Vec<DVec3> = (0..=n)
            .map(|i| self.centre(i as f64 / n as f64) - self.pivot)
            .collect();
        let lo = pts
            .iter()
            .copied()
            .fold(DVec3::splat(f64::INFINITY), DVec3::min);
        let hi = pts
            .iter()
            .copied()
            .fold(DVec3::splat(f64::NEG_INFINITY), DVec3::max);
        let mid = 0.5 * (lo + hi);
        let r = pts.iter().map(|p| (*p - mid).length()).fold(0.0, f64::max);
        (mid, r + vc / (2.0 * n as f64) + rb)
    }

    /// Unit direction pivot → target.
    #[cfg(test)]
    pub fn target_normal(&self) -> DVec3 {
        self.n_t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::catom::pose;

    fn pivot_pose() -> Pose {
        pose(DVec3::ZERO, DQuat::IDENTITY)
    }

    #[test]
    fn there_are_48_hexagonal_and_72_octagonal_links() {
        let all = links();
        let hex = all.iter().filter(|l| l.route == Route::Hexagonal).count();
        assert_eq!((hex, all.len() - hex), (48, 72));
        let right = all.iter().filter(|l| l.is_right_angle()).count();
        assert_eq!(right, 24);
    }

    /// Along the whole sweep the mover touches the pivot (no gap, no
    /// penetration) and its centre distance follows SPEC §3.
    #[test]
    fn mover_rolls_on_the_pivot_without_gap_or_penetration() {
        let body = catom();
        let mut peak: f64 = 0.0;
        for link in links() {
            let r = Roll::new(DVec3::ZERO, link);
            for i in 0..=64 {
                let s = i as f64 / 64.0;
                let g = body
                    .gap(&pivot_pose(), &r.pose(s), 1.0)
                    .expect("in contact");
                assert!(g.dist.abs() <= 1e-7, "{link} s={s}: {}", g.dist);
                peak = peak.max(r.centre(s).length());
            }
            let (c0, c1) = (r.centre(0.0), r.centre(1.0));
            assert!((c0 - fcc::direction(link.from as usize)).length() < 1e-12);
            assert!((c1 - fcc::direction(link.to as usize)).length() < 1e-12);
            let half = r.centre(0.5).length();
            match (link.route, link.is_right_angle()) {
                (Route::Hexagonal, _) => assert!((half - 1.0304).abs() < 1e-4, "{half}"),
                (Route::Octagonal, _) => assert!((half - 1.0).abs() < 1e-12, "{half}"),
            }
        }
        assert!((peak - 1.0450).abs() < 1e-4, "peak {peak}");
    }

    /// At s = 1 the mover is a catom at rest in the target cell: its body is
    /// the same point set (the rotation is a symmetry of the body).
    #[test]
    fn final_pose_is_the_target_cell() {
        let body = catom();
        for link in links() {
            let r = Roll::new(DVec3::ZERO, link);
            let q = r.rotation(1.0);
            let rest: Vec<DVec3> = body.vertices().to_vec();
            for v in body.vertices() {
                let w = q * *v;
                assert!(rest.iter().any(|x| (*x - w).length() < 1e-12), "{link}");
            }
            assert!((r.centre(1.0) - r.target_normal()).length() < 1e-12);
            assert!(r.rotation(0.0).angle_between(DQuat::IDENTITY) < 1e-12);
        }
    }

    /// No point of Q moves faster than the speed bound: finite differences
    /// over the sweep stay below V (with a margin that shows the bound is not
    /// vacuous either).
    #[test]
    fn speed_bound_holds_numerically() {
        let body = catom();
        for link in links() {
            let r = Roll::new(DVec3::new(0.3, -0.2, 0.7), link);
            let v = r.speed_bound();
            let mut fastest: f64 = 0.0;
            let n = 400;
            for i in 0..n {
                let (s0, s1) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
                let (p0, p1) = (r.pose(s0), r.pose(s1));
                for q in body.vertices() {
                    let speed = (p1 * *q - p0 * *q).length() * n as f64;
                    fastest = fastest.max(speed);
                }
            }
            assert!(fastest <= v, "{link}: {fastest} > {v}");
            assert!(fastest > 0.3 * v, "{link}: bound {v} is loose ({fastest})");
        }
    }
}
