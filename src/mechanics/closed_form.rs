//! Closed forms for straight horizontal cantilevers (SPEC §7), the yardstick
//! of the branch-length study.
//!
//! A horizontal branch of `n` modules held by a support at its root carries
//! at the root connector's contact face (half a spacing from the support's
//! centre) the shear `n·W` and the moment `W·d·Σᵢ(i − ½) = W·d·n²/2`.
//! SPEC §7 quotes `n(n+1)/2`, the moment about the supporting module's
//! centre (half a spacing further): slightly conservative; the face moment
//! is the one the connector feels. A free agent hanging at the tip (on the
//! tip module, worst position horizontally beyond it) adds `W·d·(n + ½)`:
//! the root moment becomes `W·d·(n + 1)²/2`.

use super::capacity::{ConnectorLoad, required_pressure, utilisation};
use super::model::Model;

/// Root connector load of a horizontal cantilever of `n` modules, plus a
/// free agent at its tip if `agent`.
pub fn cantilever_root_load(model: &Model, n: usize, agent: bool) -> ConnectorLoad {
    let w = model.weight();
    let d = model.spacing;
    let k = n as f64 + if agent { 1.0 } else { 0.0 };
    ConnectorLoad {
        axial: 0.0,
        shear: k * w,
        torsion: 0.0,
        moment_u: 0.0,
        moment_v: w * d * k * k / 2.0,
    }
}

/// Root utilisation of that cantilever.
pub fn cantilever_utilisation(model: &Model, n: usize, agent: bool) -> f64 {
    utilisation(&cantilever_root_load(model, n, agent), &model.connector).0
}

/// Pressure (Pa) the root connector needs.
pub fn cantilever_pressure(model: &Model, n: usize, agent: bool) -> f64 {
    required_pressure(&cantilever_root_load(model, n, agent), &model.connector)
}

/// The longest cantilever (modules) that holds, with or without an agent
/// at its tip: the largest `n` with root utilisation ≤ 1 (0 if none).
pub fn cantilever_max_length(model: &Model, agent: bool) -> usize {
    let mut n = 0;
    while n < 100_000 && cantilever_utilisation(model, n + 1, agent) <= 1.0 {
        n += 1;
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::model::Bending;

    #[test]
    fn spec_order_of_magnitude_six_at_100_kpa_two_at_10_kpa() {
        let m = Model::default_catom();
        let at = |kpa: f64| m.with_connector(kpa * 1e3, Bending::RigidHinge);
        assert_eq!(cantilever_max_length(&at(100.0), false), 6);
        assert_eq!(cantilever_max_length(&at(10.0), false), 2);
        // The agent at the tip costs exactly one module.
        assert_eq!(cantilever_max_length(&at(100.0), true), 5);
        // Elastic bending is three times stricter on the moment.
        assert!(cantilever_max_length(&m.with_connector(100e3, Bending::Elastic), false) < 6);
    }

    #[test]
    fn rigid_hinge_bound_is_n_squared_le_p_l3_over_m_g_d() {
        let m = Model::default_catom();
        let c = m.connector;
        let ratio = c.pressure * c.side.powi(3) / (m.weight() * m.spacing);
        let n = cantilever_max_length(&m, false) as f64;
        assert!(n * n <= ratio && (n + 1.0) * (n + 1.0) > ratio);
    }
}
