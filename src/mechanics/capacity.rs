//! Connector capacity: when does an electrostatic connector square of side
//! `L` and adhesion pressure `p` let go? (SPEC §7, derived in
//! `docs/mechanics.md`.)
//!
//! Loads are in the connector's frame: `N` axial (tension > 0), `V` shear
//! (magnitude), `T` torsion about the normal, `M_u`, `M_v` bending about the
//! square's edge axes. The contact takes unlimited compression; the
//! adhesion acts as a pressure `p` pressing the faces together.
//!
//! * Axial + bending, rigid hinge (lower-bound theorem: tension `p`
//!   everywhere plus a compressive resultant `C = pL² − N` anywhere in the
//!   square): `max(|M_u|, |M_v|) ≤ (pL² − N)·L/2`.
//! * Axial + bending, elastic (linear stress, first corner at `p`):
//!   `N + 6(|M_u| + |M_v|)/L ≤ pL²`.
//! * Shear + torsion share the friction of the clamping force `C`:
//!   `|V| + |T|/(r̄·L) ≤ μ·(pL² − N)`, `r̄ = 0.3826` (linear interaction, inside the
//!   exact convex friction limit surface, hence safe).
//!
//! Each criterion reads `demand ≤ capacity` with compression moved to the
//! capacity side; the utilisation is the largest ratio, so it stays defined
//! for a ground contact without adhesion (`p = 0`): there it is 1 exactly
//! when the resultant reaches the edge of the contact (tipping) or the
//! friction cone (sliding).

use super::model::{Bending, Capacity};

/// Torsional friction lever of a uniformly pressed square, as a fraction of
/// `L`: the mean distance from the centre, `∫|r| dA / A` over the unit
/// square, is exactly `(√2 + ln(1 + √2))/6 = 0.38259…` (SPEC §7 rounds it to
/// 0.383, 0.1 % on the unsafe side). `ln(1 + √2) = asinh(1)`; the
/// constant is that expression evaluated (checked by a test), because the
/// utilisation is evaluated for every link at every pose.
pub const fn torsion_lever() -> f64 {
    TORSION_LEVER
}

const TORSION_LEVER: f64 = 0.382_597_858_232_106_3;

/// Slack on the utilisation limit: solver round-off must not turn a load
/// at exactly its capacity into an overload.
pub const OVERLOAD_SLACK: f64 = 1e-9;

/// Whether a utilisation exceeds its capacity. The one predicate every check
/// judges utilisations by: a value that is not finite (NaN from a degenerate
/// solve, an infinity from a vanished capacity) counts as overloaded, so
/// that a number that compares false can never read as "within limits".
pub fn overloaded(u: f64) -> bool {
    !u.is_finite() || u > 1.0 + OVERLOAD_SLACK
}

/// Orders utilisations for "the most loaded": non-finite values rank above
/// every finite one, so a NaN is never hidden behind a finite maximum.
pub fn severity(u: f64) -> f64 {
    if u.is_finite() { u } else { f64::INFINITY }
}

/// A connector's load in its own frame (N, N·m).
#[derive(Copy, Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct ConnectorLoad {
    /// Axial force, tension positive.
    pub axial: f64,
    /// Shear force magnitude.
    pub shear: f64,
    /// Torsion about the normal.
    pub torsion: f64,
    /// Bending moment about the square's first edge axis.
    pub moment_u: f64,
    /// Bending moment about the square's second edge axis.
    pub moment_v: f64,
}

/// Which criterion governs a utilisation.
#[derive(Copy, Clone, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Tension and bending: the square peels or tips open.
    Bending,
    /// Shear and torsion: the square slides.
    Friction,
}

impl Mode {
    pub fn name(self) -> &'static str {
        match self {
            Mode::Bending => "bending",
            Mode::Friction => "friction",
        }
    }
}

impl ConnectorLoad {
    /// The load scaled by `k` (superposition).
    pub fn scaled(self, k: f64) -> ConnectorLoad {
        ConnectorLoad {
            axial: self.axial * k,
            shear: self.shear * k,
            torsion: self.torsion * k,
            moment_u: self.moment_u * k,
            moment_v: self.moment_v * k,
        }
    }
}

/// Utilisation (load / capacity, failure at 1) and its governing mode.
pub fn utilisation(load: &ConnectorLoad, cap: &Capacity) -> (f64, Mode) {
    // A NaN component would vanish in the `max` below and read as
    // unloaded: NaN instead, which `overloaded` counts as over.
    let parts = [
        load.axial,
        load.shear,
        load.torsion,
        load.moment_u,
        load.moment_v,
    ];
    if parts.iter().any(|x| x.is_nan()) {
        return (f64::NAN, Mode::Bending);
    }
    let l = cap.side;
    let tension = load.axial.max(0.0);
    let compression = (-load.axial).max(0.0);
    let clamp = cap.tension() + compression;
    let bending_demand = tension
        + match cap.bending {
            Bending::RigidHinge => 2.0 * load.moment_u.abs().max(load.moment_v.abs()) / l,
            Bending::Elastic => 6.0 * (load.moment_u.abs() + load.moment_v.abs()) / l,
        };
    let friction_demand =
        tension + (load.shear.abs() + load.torsion.abs() / (torsion_lever() * l)) / cap.friction;
    let ratio = |demand: f64| {
        if demand <= 0.0 {
            0.0
        } else if clamp <= 0.0 {
            f64::INFINITY
        } else {
            demand / clamp
        }
    };
    let b = ratio(bending_demand);
    let f = ratio(friction_demand);
    if b >= f {
        (b, Mode::Bending)
    } else {
        (f, Mode::Friction)
    }
}

/// The smallest `k ≥ 1` such that `load / k` is within the utilisation
/// (≤ 1); ∞ where none is (a contact without adhesion loaded beyond it:
/// scaling changes no ratio), NaN for a NaN load. Both modes' demands `D`
/// scale with the load and the clamp `pL² + N_c` only in its compression,
/// so `(D/k)/(pL² + N_c/k) = 1` at `k = u + (u − 1)·N_c/pL²`: `u` itself
/// only for a link in tension (a compressed link scaled by `1/u` is still
/// above 1, its clamp having shrunk too).
pub fn scale_within(load: &ConnectorLoad, cap: &Capacity) -> f64 {
    let (u, _) = utilisation(load, cap);
    if u.is_nan() {
        return f64::NAN;
    }
    if u <= 1.0 {
        return 1.0;
    }
    let p = cap.tension();
    if p.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return f64::INFINITY;
    }
    let compression = (-load.axial).max(0.0);
    // A hair above: at `k` itself the centre of pressure lies on the
    // square's edge, where rounding could put it just beyond.
    (u + (u - 1.0) * compression / p) * (1.0 + 1e-12)
}

/// Below this utilisation the corner construction always carries a load
/// ([`corner_ratio`] ≤ 0.82), so the hot path need not evaluate it: with
/// `u ≤ k` the centre of pressure is within `k·a` of the centre on each
/// axis, the lever `ρC/J` at most `√2/(L(1 − k))`, and the corner demand at
/// most `(|V| + 0.541·|T|/(r̄L))/(1 − k) ≤ k·μC/(1 − k)`, within `μC` for
/// `k ≤ ½`.
pub const CORNER_FREE_BELOW: f64 = 0.45;

/// Whether the corner forces of the limit analysis ([`super::limit`]) can
/// carry `load`, as a ratio (≤ 1: they can). The utilisation's friction
/// chord treats torsion apart from where the square bears; the corner
/// model couples them (a square pressed on one edge resists little
/// torsion). An elastic solution is a witness for the limit analysis only
/// where this holds too.
///
/// Sufficient, by construction: spread the clamp `C = pL² − N` over the
/// four corners bilinearly so that its centroid is the centre of pressure
/// `e` (`|e_u| = |M_v|/C`, `|e_v| = |M_u|/C`; non-negative whenever the
/// bending is within capacity), give each corner the share `c_i/C` of the
/// shear and a torsion part `k·c_i·ẑ×(r_i − e)` with `k = T'/J`,
/// `J = Σ c_i|r_i − e|²` and `T' = T − (e × V)·n` (bounded here by
/// `|T| + |e|·|V|`, the shear's direction being unknown). Every corner is
/// then within its cone `‖t_i‖ ≤ μ c_i` when
/// `|V| + (|T| + |e||V|)·ρ·C/J ≤ μC`, `ρ` the largest `|r_i − e|` of a
/// loaded corner. Centred, the torsion lever is `L/√2`, above the chord's
/// `0.383 L`.
pub fn corner_ratio(load: &ConnectorLoad, cap: &Capacity) -> f64 {
    let a = cap.side / 2.0;
    let clamp = cap.tension() - load.axial;
    let (v, t) = (load.shear.abs(), load.torsion.abs());
    if v == 0.0 && t == 0.0 {
        return 0.0;
    }
    // (NaN fails these: no finite ratio.)
    if clamp.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
        || cap.friction.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
    {
        return f64::INFINITY;
    }
    let (eu, ev) = (load.moment_v.abs() / clamp, load.moment_u.abs() / clamp);
    if eu > a || ev > a {
        // Bending beyond the square: no clamp distribution exists.
        return f64::INFINITY;
    }
    // In units of a: the bilinear spread gives J = C·a²·(2 − x² − y²)
    // (x, y the centre of pressure over a), and the farthest loaded corner
    // is the opposite one while the centre is inside the square.
    let (x, y) = (eu / a, ev / a);
    let lever = if x < 1.0 && y < 1.0 {
        ((1.0 + x) * (1.0 + x) + (1.0 + y) * (1.0 + y)).sqrt() / (a * (2.0 - x * x - y * y))
    } else {
        // On an edge: the corners left loaded, summed out.
        let mut j = 0.0;
        let mut rho: f64 = 0.0;
        for (su, sv) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
            let c = 0.25 * (1.0 + su * x) * (1.0 + sv * y);
            let d2 = (su - x).powi(2) + (sv - y).powi(2);
            j += c * d2;
            if c > 0.0 {
                rho = rho.max(d2.sqrt());
            }
        }
        if j > 0.0 {
            rho / (a * j)
        } else {
            f64::INFINITY
        }
    };
    // (sqrt of a sum of squares: hypot's overflow care is not needed
    // for lengths within the square, and it is slow on this hot path.)
    let torsion = t + (eu * eu + ev * ev).sqrt() * v;
    let demand = if torsion == 0.0 {
        v
    } else {
        v + torsion * lever
    };
    demand / (cap.friction * clamp)
}

/// The smallest adhesion pressure (Pa) at which `load` is within capacity
/// (utilisation ≤ 1), other parameters unchanged: every criterion is
/// `demand ≤ p·L² + compression`, so it is solved in closed form.
pub fn required_pressure(load: &ConnectorLoad, cap: &Capacity) -> f64 {
    let mut lo = Capacity {
        pressure: 0.0,
        ..*cap
    };
    let (u0, _) = utilisation(load, &lo);
    if u0 <= 1.0 {
        return 0.0;
    }
    // demand = u(p)·(pL² + compression) is independent of p.
    let compression = (-load.axial).max(0.0);
    lo.pressure = 1.0;
    let (u1, _) = utilisation(load, &lo);
    let demand = u1 * (lo.tension() + compression);
    (demand - compression) / (cap.side * cap.side)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cap(bending: Bending) -> Capacity {
        Capacity {
            pressure: 100e3,
            side: 1e-3,
            friction: 0.5,
            bending,
        }
    }

    #[test]
    fn a_load_scaled_by_scale_within_is_just_within_the_utilisation_and_inside_the_square() {
        // Against bisection on the utilisation itself, over a grid of
        // loads in tension and in compression (where scaling by 1/u is not
        // enough: the clamp shrinks with the compression), both bending
        // criteria.
        let mut checked = 0;
        for bending in [Bending::Elastic, Bending::RigidHinge] {
            let c = cap(bending);
            let t = c.tension();
            let m = t * c.side;
            for axial in [-20.0 * t, -3.0 * t, -0.5 * t, 0.0, 0.4 * t, 2.0 * t] {
                for (mu, mv) in [
                    (0.0, 0.0),
                    (2.0 * m, 0.0),
                    (0.7 * m, 5.0 * m),
                    (30.0 * m, 1.0 * m),
                ] {
                    for (shear, torsion) in [(0.0, 0.0), (3.0 * t, 0.0), (0.2 * t, 4.0 * m)] {
                        let load = ConnectorLoad {
                            axial,
                            shear,
                            torsion,
                            moment_u: mu,
                            moment_v: mv,
                        };
                        let k = scale_within(&load, &c);
                        let u = |k: f64| utilisation(&load.scaled(1.0 / k), &c).0;
                        let what = format!("{load:?} {bending:?}: k {k}");
                        assert!(k.is_finite() && k >= 1.0, "{what}");
                        assert!(u(k) <= 1.0, "{what}: {}", u(k));
                        if u(1.0) > 1.0 {
                            // The smallest such k, by bisection.
                            let (mut lo, mut hi) = (1.0, 2.0);
                            while u(hi) > 1.0 {
                                hi *= 2.0;
                            }
                            for _ in 0..200 {
                                let mid = 0.5 * (lo + hi);
                                if u(mid) > 1.0 { lo = mid } else { hi = mid }
                            }
                            assert!((k - hi).abs() <= 1e-9 * hi, "{what}: bisection {hi}");
                            assert!(
                                corner_ratio(&load.scaled(1.0 / k), &c).is_finite(),
                                "{what}"
                            );
                            checked += 1;
                        } else {
                            assert_eq!(k, 1.0, "{what}");
                        }
                    }
                }
            }
        }
        assert!(checked > 100, "{checked}");
        // Without adhesion no scaling helps; a NaN load has no scale.
        let bare = Capacity {
            pressure: 0.0,
            ..cap(Bending::RigidHinge)
        };
        let tipped = ConnectorLoad {
            axial: -1.0,
            moment_u: 1.0,
            ..Default::default()
        };
        assert_eq!(scale_within(&tipped, &bare), f64::INFINITY);
        let nan = ConnectorLoad {
            axial: f64::NAN,
            ..tipped
        };
        assert!(scale_within(&nan, &cap(Bending::Elastic)).is_nan());
    }

    #[test]
    fn a_load_with_a_nan_component_is_never_within_capacity() {
        // `f64::max` drops a NaN: an axial force of NaN once read as no
        // tension and no compression, so an otherwise unloaded connector
        // passed.
        let c = cap(Bending::Elastic);
        for i in 0..5 {
            let mut parts = [0.0; 5];
            parts[i] = f64::NAN;
            let load = ConnectorLoad {
                axial: parts[0],
                shear: parts[1],
                torsion: parts[2],
                moment_u: parts[3],
                moment_v: parts[4],
            };
            let (u, _) = utilisation(&load, &c);
            assert!(overloaded(u), "{load:?}: {u}");
        }
    }

    #[test]
    fn pure_tension_fails_at_p_l_squared() {
        for b in [Bending::Elastic, Bending::RigidHinge] {
            let c = cap(b);
            let load = ConnectorLoad {
                axial: c.tension(),
                ..Default::default()
            };
            assert!((utilisation(&load, &c).0 - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn rigid_hinge_moment_limit_is_p_l_cubed_over_two() {
        let c = cap(Bending::RigidHinge);
        let m = c.pressure * c.side.powi(3) / 2.0;
        let load = ConnectorLoad {
            moment_u: m,
            ..Default::default()
        };
        assert!((utilisation(&load, &c).0 - 1.0).abs() < 1e-12);
        // Elastic is three times stricter for the same moment.
        assert!((utilisation(&load, &cap(Bending::Elastic)).0 - 3.0).abs() < 1e-12);
    }

    #[test]
    fn compression_raises_moment_and_friction_capacity() {
        let c = Capacity {
            pressure: 0.0,
            ..cap(Bending::RigidHinge)
        };
        // Without adhesion a contact under 1 N compression tips when the
        // resultant reaches the edge: M = N·L/2.
        let edge = ConnectorLoad {
            axial: -1.0,
            moment_v: 0.5 * c.side,
            ..Default::default()
        };
        assert!((utilisation(&edge, &c).0 - 1.0).abs() < 1e-12);
        // … and slides when the shear reaches μN.
        let slide = ConnectorLoad {
            axial: -1.0,
            shear: 0.5,
            ..Default::default()
        };
        assert!((utilisation(&slide, &c).0 - 1.0).abs() < 1e-12);
        assert_eq!(utilisation(&slide, &c).1, Mode::Friction);
        let lifted = ConnectorLoad {
            axial: 1e-9,
            ..Default::default()
        };
        assert!(utilisation(&lifted, &c).0.is_infinite());
    }

    #[test]
    fn the_corner_ratio_is_the_corner_construction_and_tightens_off_centre() {
        let cap = Capacity {
            pressure: 100e3,
            side: 1e-3,
            friction: 0.5,
            bending: Bending::RigidHinge,
        };
        let c = cap.tension();
        // Centred, pure torsion: the lever is L/√2.
        let t = ConnectorLoad {
            torsion: 0.5 * c * 1e-3 / std::f64::consts::SQRT_2,
            ..Default::default()
        };
        assert!((corner_ratio(&t, &cap) - 1.0).abs() < 1e-12);
        // The same torsion with the clamp pushed towards an edge needs more.
        let off = ConnectorLoad {
            moment_u: 0.4 * c * 0.5e-3,
            ..t
        };
        assert!(corner_ratio(&off, &cap) > 1.2);
        // At a corner nothing resists torsion; beyond the square, nothing.
        let corner = ConnectorLoad {
            moment_u: c * 0.5e-3,
            moment_v: c * 0.5e-3,
            ..t
        };
        assert!(corner_ratio(&corner, &cap).is_infinite());
        // Random loads: wherever the ratio is ≤ 1, the construction gives
        // corner forces within their cones that add up to the load.
        let mut seed = 7u64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let a = cap.side / 2.0;
        let mut checked = 0;
        for _ in 0..20_000 {
            let n = (rnd() * 2.0 - 1.5) * c;
            let clamp = c - n;
            let (eu, ev) = ((rnd() * 2.0 - 1.0) * a, (rnd() * 2.0 - 1.0) * a);
            let phi = rnd() * std::f64::consts::TAU;
            let vmag = rnd() * 0.5 * clamp;
            let v = (vmag * phi.cos(), vmag * phi.sin());
            let torsion = (rnd() * 2.0 - 1.0) * 0.3 * clamp * a;
            let load = ConnectorLoad {
                axial: n,
                shear: vmag,
                torsion,
                moment_u: ev * clamp,
                moment_v: eu * clamp,
            };
            if corner_ratio(&load, &cap) > 1.0 {
                continue;
            }
            checked += 1;
            let corners = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)];
            let cs: Vec<f64> = corners
                .iter()
                .map(|(su, sv)| clamp / 4.0 * (1.0 + su * eu / a) * (1.0 + sv * ev / a))
                .collect();
            let j: f64 = corners
                .iter()
                .zip(&cs)
                .map(|((su, sv), ci)| ci * ((su * a - eu).powi(2) + (sv * a - ev).powi(2)))
                .sum();
            let t_prime = torsion - (eu * v.1 - ev * v.0);
            let k = if j > 0.0 { t_prime / j } else { 0.0 };
            let (mut fx, mut fy, mut mz) = (0.0, 0.0, 0.0);
            for ((su, sv), ci) in corners.iter().zip(&cs) {
                let (rx, ry) = (su * a, sv * a);
                let (dx, dy) = (rx - eu, ry - ev);
                let tx = v.0 * ci / clamp - k * ci * dy;
                let ty = v.1 * ci / clamp + k * ci * dx;
                assert!(
                    tx.hypot(ty) <= cap.friction * ci * (1.0 + 1e-9) + 1e-15,
                    "{load:?}"
                );
                fx += tx;
                fy += ty;
                mz += rx * ty - ry * tx;
            }
            assert!((fx - v.0).abs() < 1e-9 * clamp && (fy - v.1).abs() < 1e-9 * clamp);
            assert!((mz - torsion).abs() < 1e-9 * clamp * a, "{mz} vs {torsion}");
        }
        assert!(checked > 1000, "{checked}");
        // Below CORNER_FREE_BELOW the ratio never binds (the hot path skips it).
        for _ in 0..20_000 {
            let load = ConnectorLoad {
                axial: (rnd() * 2.0 - 1.5) * c,
                shear: rnd() * c,
                torsion: (rnd() * 2.0 - 1.0) * c * a,
                moment_u: (rnd() * 2.0 - 1.0) * c * a,
                moment_v: (rnd() * 2.0 - 1.0) * c * a,
            };
            for bending in [Bending::RigidHinge, Bending::Elastic] {
                let cap = Capacity { bending, ..cap };
                if utilisation(&load, &cap).0 <= CORNER_FREE_BELOW {
                    assert!(corner_ratio(&load, &cap) <= 0.83, "{load:?}");
                }
            }
        }
    }

    #[test]
    fn torsion_lever_is_the_mean_distance_of_the_unit_square() {
        // Independent: midpoint-rule quadrature of |r| over the unit square.
        let n = 2000;
        let h = 1.0 / n as f64;
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let (x, y) = ((i as f64 + 0.5) * h - 0.5, (j as f64 + 0.5) * h - 0.5);
                sum += (x * x + y * y).sqrt() * h * h;
            }
        }
        assert!(
            (torsion_lever() - sum).abs() < 1e-6,
            "{} vs {sum}",
            torsion_lever()
        );
        assert!((torsion_lever() - 0.3826).abs() < 5e-5);
        let exact = (std::f64::consts::SQRT_2 + 1f64.asinh()) / 6.0;
        assert!((torsion_lever() - exact).abs() <= f64::EPSILON * exact);
    }

    #[test]
    fn required_pressure_puts_the_load_exactly_at_capacity() {
        let c = cap(Bending::Elastic);
        let load = ConnectorLoad {
            axial: -0.02,
            shear: 0.01,
            torsion: 1e-6,
            moment_u: 3e-5,
            moment_v: 1e-5,
        };
        let p = required_pressure(&load, &c);
        let at = Capacity { pressure: p, ..c };
        assert!((utilisation(&load, &at).0 - 1.0).abs() < 1e-9, "{p}");
    }
}
