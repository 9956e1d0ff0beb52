//! The physical model of a module and its connectors, read from a TOML file
//! in `models/` (see `docs/mechanics.md` for every default and its source).
//!
//! Everything the static analysis needs is derived here, in SI units, from
//! a handful of documented inputs: the lattice spacing `d`, the body (its
//! volume as a multiple of `d³` and its connector square side `L` as a
//! multiple of `d`), a density (or an explicit mass), the adhesion pressure
//! `p` of the connectors, friction, the bending criterion, and the ground.

use crate::error::InputError;
use serde::Deserialize;
use std::f64::consts::PI;
use std::path::Path;

/// Standard gravity (m/s²), the default of `gravity` in model files.
pub const STANDARD_GRAVITY: f64 = 9.806_65;

/// How a connector's bending capacity is judged (SPEC §7).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Bending {
    /// Linear stress over the square, first fibre at `p`:
    /// `N/L² + 6(|M_u| + |M_v|)/L³ ≤ p` (conservative).
    Elastic,
    /// Rigid-plastic hinge on an edge: `max(|M_u|, |M_v|) ≤ (pL² − N)·L/2`
    /// (the upper limit of what the square can hold).
    RigidHinge,
}

impl Bending {
    pub fn name(self) -> &'static str {
        match self {
            Bending::Elastic => "elastic",
            Bending::RigidHinge => "rigid-hinge",
        }
    }
}

impl std::str::FromStr for Bending {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "elastic" => Ok(Bending::Elastic),
            "rigid-hinge" => Ok(Bending::RigidHinge),
            o => Err(format!(
                "unknown bending criterion '{o}' (known: elastic, rigid-hinge)"
            )),
        }
    }
}

/// Module body shapes the model knows: each fixes the body volume and the
/// connector side as multiples of the lattice spacing.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Body {
    /// The 3D Catom of SPEC §2: rhombicuboctahedron of edge `L = d/(3+√2)`
    /// dilated by a ball of radius `L`; connectors are squares of side `L`.
    Catom,
    /// A solid cube of side `d` (2D sliding squares extruded by `d`, or
    /// cubic-lattice modules); connectors are whole faces, side `d`.
    Cube,
}

impl Body {
    /// Body volume divided by `d³`.
    pub fn volume_fraction(self) -> f64 {
        match self {
            Body::Catom => catom_volume_fraction(),
            Body::Cube => 1.0,
        }
    }

    /// Connector square side divided by `d`.
    pub fn connector_fraction(self) -> f64 {
        match self {
            Body::Catom => 1.0 / (3.0 + std::f64::consts::SQRT_2),
            Body::Cube => 1.0,
        }
    }
}

/// Volume of the catom body over `d³`, exactly, by Steiner's formula for the
/// parallel body of a convex polytope `Q` at distance `r = L`:
/// `V(Q ⊕ rB) = V_Q + A_Q·r + r²·Σ_e ℓ_e(π − θ_e)/2 + 4/3·π·r³`, where the
/// sum runs over the edges with interior dihedral angles `θ_e`.
///
/// For the small rhombicuboctahedron of edge `L`: `V_Q = (12 + 10√2)/3·L³`,
/// `A_Q = (18 + 2√3)·L²`; of its 48 edges, 24 join a cube-axis square to an
/// edge square (θ = 135°, exterior angle π/4) and 24 join a triangle to an
/// edge square (θ = arccos(−√(2/3)), exterior angle arccos(√(2/3))).
pub fn catom_volume_fraction() -> f64 {
    let s2 = std::f64::consts::SQRT_2;
    let l = 1.0 / (3.0 + s2);
    let v_q = (12.0 + 10.0 * s2) / 3.0;
    let a_q = 18.0 + 2.0 * 3f64.sqrt();
    let edges = 24.0 * (PI / 4.0) / 2.0 + 24.0 * (2.0f64 / 3.0).sqrt().acos() / 2.0;
    let ball = 4.0 / 3.0 * PI;
    (v_q + a_q + edges + ball) * l.powi(3)
}

/// The model file, as written (units in the field names).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    pub name: String,
    #[serde(default)]
    pub description: String,
    pub module: ModuleSection,
    pub connector: ConnectorSection,
    #[serde(default)]
    pub ground: GroundSection,
    #[serde(default)]
    pub stiffness: StiffnessSection,
    #[serde(default)]
    pub actuator: ActuatorSection,
    #[serde(default = "default_gravity")]
    pub gravity: f64,
}

fn default_gravity() -> f64 {
    STANDARD_GRAVITY
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModuleSection {
    pub body: Body,
    /// Default lattice spacing (mm); a schedule's own spacing overrides it.
    pub spacing_mm: f64,
    /// Density of the body material (g/cm³).
    pub density_g_cm3: Option<f64>,
    /// Explicit module mass (mg); overrides the density.
    pub mass_mg: Option<f64>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConnectorSection {
    /// Maximum adhesion pressure `p` over the connector square (kPa).
    pub pressure_kpa: f64,
    /// Friction coefficient between two latched connector faces.
    pub friction: f64,
    pub bending: Bending,
    /// Explicit square side (mm); default from the body.
    pub side_mm: Option<f64>,
}

/// The ground (or sandbox top) a module of the ground layer rests on.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroundSection {
    /// Adhesion pressure of a ground contact (kPa): 0 for a module merely
    /// resting on the ground; the connector pressure for a latched sandbox.
    #[serde(default)]
    pub pressure_kpa: f64,
    #[serde(default = "default_ground_friction")]
    pub friction: f64,
}

fn default_ground_friction() -> f64 {
    0.5
}

impl Default for GroundSection {
    fn default() -> Self {
        GroundSection {
            pressure_kpa: 0.0,
            friction: default_ground_friction(),
        }
    }
}

/// The pivot's actuator surface that holds a mover during a rotation
/// (seed 000 §3.1.1: the hexagonal and octagonal actuators), not a latched
/// connector. The hold is judged like a connector square of side `side_mm`
/// at `pressure_kpa` with friction `friction`. No published figure exists;
/// the defaults are the connector's (the octagonal actuator's flat face is a
/// square of the connector's side `L`), so that a model without this
/// section judges the hold as before. `docs/mechanics.md` gives the
/// hexagonal actuator's smaller triangle as the conservative alternative.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ActuatorSection {
    pub pressure_kpa: Option<f64>,
    pub side_mm: Option<f64>,
    pub friction: Option<f64>,
}

/// Elastic interface of a connector (only ratios matter: see `Stiffness`).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StiffnessSection {
    #[serde(default = "default_poisson")]
    pub poisson: f64,
}

fn default_poisson() -> f64 {
    0.35
}

impl Default for StiffnessSection {
    fn default() -> Self {
        StiffnessSection {
            poisson: default_poisson(),
        }
    }
}

/// One connector type's capacity parameters (SI units).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Capacity {
    /// Adhesion pressure `p` (Pa).
    pub pressure: f64,
    /// Square side `L` (m).
    pub side: f64,
    /// Friction coefficient `μ`.
    pub friction: f64,
    pub bending: Bending,
}

impl Capacity {
    /// Pure tension capacity `p·L²` (N).
    pub fn tension(&self) -> f64 {
        self.pressure * self.side * self.side
    }
}

/// The model, resolved to SI units for one lattice spacing.
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    pub name: String,
    pub body: Body,
    /// Lattice spacing `d` (m).
    pub spacing: f64,
    /// Module mass (kg).
    pub mass: f64,
    /// Gravitational acceleration (m/s²).
    pub gravity: f64,
    /// Density used for the mass (kg/m³), when the mass was derived.
    pub density: Option<f64>,
    pub connector: Capacity,
    pub ground: Capacity,
    /// The pivot actuator's hold on a mover during its rotation, where the
    /// model gives one; `None` holds like a connector ([`Model::hold`]).
    pub actuator: Option<Capacity>,
    pub poisson: f64,
}

impl Model {
    /// Reads a model file.
    pub fn load(path: &Path) -> Result<Model, InputError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| InputError::new(format!("cannot read model: {e}")).in_file(path))?;
        Model::from_toml(&text).map_err(|e| e.in_file(path))
    }

    pub fn from_toml(text: &str) -> Result<Model, InputError> {
        let f: ModelFile =
            toml::from_str(text).map_err(|e| InputError::new(format!("not a valid model: {e}")))?;
        Model::from_file(&f)
    }

    pub fn from_file(f: &ModelFile) -> Result<Model, InputError> {
        let bad = |m: String| InputError::new(format!("model '{}': {m}", f.name));
        // Every field in a range with a reason: beyond it the model's
        // physics (rigid modules, a contact pressure, dry friction) means
        // nothing, or its arithmetic underflows or overflows.
        let ranged = |v: f64, what: &str, lo: f64, lo_open: bool, hi: f64, why: &str| {
            let above = if lo_open { v > lo } else { v >= lo };
            if v.is_finite() && above && v <= hi {
                Ok(v)
            } else {
                let open = if lo_open { "(" } else { "[" };
                Err(bad(format!(
                    "{what} must be in {open}{lo}, {hi}], got {v} ({why})"
                )))
            }
        };
        let d = ranged(
            f.module.spacing_mm,
            "module.spacing_mm",
            1e-6,
            false,
            1e6,
            "a module between 1 nm and 1 km; outside, the rescaled masses and capacities lose the physics",
        )? * 1e-3;
        let (mass, density) = match (f.module.mass_mg, f.module.density_g_cm3) {
            (Some(m), _) => (
                ranged(
                    m,
                    "module.mass_mg",
                    0.0,
                    true,
                    1e15,
                    "at most a million tonnes",
                )? * 1e-6,
                None,
            ),
            (None, Some(rho)) => {
                let rho = ranged(
                    rho,
                    "module.density_g_cm3",
                    1e-6,
                    false,
                    100.0,
                    "between a rarefied gas and well above the densest element, osmium (22.6)",
                )? * 1e3;
                (rho * f.module.body.volume_fraction() * d.powi(3), Some(rho))
            }
            (None, None) => return Err(bad("module needs density_g_cm3 or mass_mg".into())),
        };
        let side = match f.connector.side_mm {
            Some(s) => {
                ranged(
                    s,
                    "connector.side_mm",
                    0.0,
                    true,
                    f.module.spacing_mm,
                    "a connector square no wider than the module spacing",
                )? * 1e-3
            }
            None => f.module.body.connector_fraction() * d,
        };
        const PRESSURE_WHY: &str = "at most 10 GPa, beyond the strength of any material";
        const FRICTION_WHY: &str = "a dry-friction coefficient";
        let connector = Capacity {
            pressure: ranged(
                f.connector.pressure_kpa,
                "connector.pressure_kpa",
                0.0,
                true,
                1e7,
                PRESSURE_WHY,
            )? * 1e3,
            side,
            friction: ranged(
                f.connector.friction,
                "connector.friction",
                0.0,
                true,
                10.0,
                FRICTION_WHY,
            )?,
            bending: f.connector.bending,
        };
        let ground = Capacity {
            pressure: ranged(
                f.ground.pressure_kpa,
                "ground.pressure_kpa",
                0.0,
                false,
                1e7,
                PRESSURE_WHY,
            )? * 1e3,
            side,
            friction: ranged(
                f.ground.friction,
                "ground.friction",
                0.0,
                true,
                10.0,
                FRICTION_WHY,
            )?,
            bending: f.connector.bending,
        };
        let actuator_side = match f.actuator.side_mm {
            Some(a) => {
                ranged(
                    a,
                    "actuator.side_mm",
                    0.0,
                    true,
                    f.module.spacing_mm,
                    "a holding patch no wider than the module spacing",
                )? * 1e-3
            }
            None => side,
        };
        let a = &f.actuator;
        let actuator = if a.pressure_kpa.is_none() && a.side_mm.is_none() && a.friction.is_none() {
            None
        } else {
            Some(Capacity {
                pressure: match a.pressure_kpa {
                    Some(p) => {
                        ranged(p, "actuator.pressure_kpa", 0.0, true, 1e7, PRESSURE_WHY)? * 1e3
                    }
                    None => connector.pressure,
                },
                side: actuator_side,
                friction: match a.friction {
                    Some(mu) => ranged(mu, "actuator.friction", 0.0, true, 10.0, FRICTION_WHY)?,
                    None => connector.friction,
                },
                bending: f.connector.bending,
            })
        };
        let nu = f.stiffness.poisson;
        if !(0.0..0.5).contains(&nu) {
            return Err(bad(format!(
                "stiffness.poisson must be in [0, 0.5), got {nu}"
            )));
        }
        let m = Model {
            name: f.name.clone(),
            body: f.module.body,
            spacing: d,
            mass,
            gravity: ranged(
                f.gravity,
                "gravity",
                1e-6,
                false,
                1e4,
                "between micro-gravity and far above any planet's surface gravity, in m/s²",
            )?,
            density,
            connector,
            ground,
            actuator,
            poisson: nu,
        };
        m.check_derived().map_err(|e| bad(e.message))?;
        Ok(m)
    }

    /// Refuses a model whose derived quantities lost the physics: the
    /// weight, the capacities and their ratios to the weight must be normal
    /// positive floats (not 0 by underflow, not infinite by overflow), so
    /// that no verdict can follow from a number that vanished.
    pub fn check_derived(&self) -> Result<(), InputError> {
        let w = self.weight();
        let normal = |v: f64| v.is_normal() && v > 0.0;
        let checks = [
            (
                "module mass (from module.spacing_mm and the density)",
                self.mass,
            ),
            ("module weight m·g", w),
            (
                "connector capacity p·L² (connector.pressure_kpa, side)",
                self.connector.tension(),
            ),
            (
                "connector capacity over weight p·L²/(m·g)",
                self.connector.tension() / w,
            ),
            (
                "connector moment capacity over weight moment p·L³/(m·g·d)",
                self.connector.tension() * self.connector.side / (w * self.spacing),
            ),
            (
                "actuator hold p·L² over weight (actuator.*)",
                self.hold().tension() / w,
            ),
            (
                "weight over connector capacity",
                w / self.connector.tension(),
            ),
        ];
        for (what, v) in checks {
            if !normal(v) {
                return Err(InputError::new(format!(
                    "{what} is {v:e} at spacing {} m: the arithmetic underflows or overflows",
                    self.spacing
                )));
            }
        }
        for (what, mu) in [
            ("connector.friction", self.connector.friction),
            ("ground.friction", self.ground.friction),
            ("actuator.friction", self.hold().friction),
        ] {
            if !normal(mu) {
                return Err(InputError::new(format!(
                    "{what} is {mu}: a friction coefficient must be positive and finite"
                )));
            }
        }
        if !(self.ground.pressure.is_finite() && self.ground.pressure >= 0.0) {
            return Err(InputError::new(format!(
                "ground.pressure_kpa gives {} Pa: not a pressure",
                self.ground.pressure
            )));
        }
        if self.ground.pressure > 0.0 && !normal(self.ground.tension() / w) {
            return Err(InputError::new(format!(
                "ground capacity over weight (ground.pressure_kpa) is {:e}: the arithmetic underflows or overflows",
                self.ground.tension() / w
            )));
        }
        Ok(())
    }

    /// What holds a mover on its pivot during a rotation: the actuator's
    /// capacity, or the connector's where the model gives none (so that a
    /// connector pressure swept by the b-study moves the hold with it).
    pub fn hold(&self) -> Capacity {
        self.actuator.unwrap_or(self.connector)
    }

    /// Module weight `m·g` (N), the force unit of the analysis.
    pub fn weight(&self) -> f64 {
        self.mass * self.gravity
    }

    /// The same model at another lattice spacing: the mass scales with `d³`
    /// when it was derived from a density, the connector side with `d`.
    pub fn at_spacing(&self, d: f64) -> Model {
        let k = d / self.spacing;
        let mut m = self.clone();
        m.spacing = d;
        if let Some(rho) = m.density {
            m.mass = rho * m.body.volume_fraction() * d.powi(3);
        }
        m.connector.side *= k;
        m.ground.side *= k;
        if let Some(a) = m.actuator.as_mut() {
            a.side *= k;
        }
        m
    }

    /// [`Model::at_spacing`], refused where the rescaled model's derived
    /// quantities underflow or overflow (e.g. a 1e200 mm model spacing
    /// rescaled to a schedule's 3.6 mm makes the mass vanish).
    pub fn at_spacing_checked(&self, d: f64) -> Result<Model, InputError> {
        let m = self.at_spacing(d);
        m.check_derived().map_err(|e| {
            InputError::new(format!(
                "model '{}' at the schedule's spacing {d} m: {}",
                self.name, e.message
            ))
        })?;
        Ok(m)
    }

    /// The capacity of a link: the ground's for a ground contact, the
    /// connector's otherwise.
    pub fn capacity_of(&self, ground: bool) -> &Capacity {
        if ground {
            &self.ground
        } else {
            &self.connector
        }
    }

    /// The same model with another connector pressure (Pa) and bending rule.
    pub fn with_connector(&self, pressure: f64, bending: Bending) -> Model {
        let mut m = self.clone();
        m.connector.pressure = pressure;
        m.connector.bending = bending;
        m.ground.bending = bending;
        if let Some(a) = m.actuator.as_mut() {
            a.bending = bending;
        }
        m
    }

    /// The bundled default catom model (`models/catom-3.6mm.toml`).
    pub fn default_catom() -> Model {
        Model::from_toml(include_str!("../../models/catom-3.6mm.toml"))
            .expect("bundled model is valid")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catom_body_volume_is_about_0_595_d3() {
        let v = catom_volume_fraction();
        assert!((v - 0.595).abs() < 0.0015, "V = {v} d³");
        // The body contains the ball of radius d/2 (its faces are at d/2)
        // and fits in the unit cube around its centre.
        let inner = 4.0 / 3.0 * PI * 0.5f64.powi(3); // inscribed ball of radius d/2
        assert!(v > inner && v < 1.0, "{v}");
    }

    #[test]
    fn steiner_formula_matches_a_monte_carlo_estimate_of_the_body() {
        // Independent of the formula: sample points and keep those within
        // L of the polytope Q (parry's exact point projection).
        use parry3d_f64::query::PointQuery;
        use parry3d_f64::shape::ConvexPolyhedron;
        use rand::{Rng, SeedableRng};
        let l = 1.0 / (3.0 + std::f64::consts::SQRT_2);
        let b = l / 2.0;
        let a = b * (1.0 + std::f64::consts::SQRT_2);
        let mut verts = Vec::new();
        for p in [[0, 1, 2], [1, 0, 2], [2, 0, 1]] {
            for sx in [-1.0, 1.0] {
                for sy in [-1.0, 1.0] {
                    for sz in [-1.0, 1.0] {
                        let mut v = [0.0; 3];
                        v[p[0]] = sx * a;
                        v[p[1]] = sy * b;
                        v[p[2]] = sz * b;
                        verts.push(glam::DVec3::from_array(v));
                    }
                }
            }
        }
        let q = ConvexPolyhedron::from_convex_hull(&verts).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let n = 40_000;
        let half = 0.55;
        let inside = (0..n)
            .filter(|_| {
                let x = glam::DVec3::new(
                    rng.random_range(-half..half),
                    rng.random_range(-half..half),
                    rng.random_range(-half..half),
                );
                q.distance_to_local_point(x, true) <= l
            })
            .count();
        let mc = inside as f64 / n as f64 * (2.0 * half).powi(3);
        let exact = catom_volume_fraction();
        // Standard error of the estimate ≈ 0.0025.
        assert!(
            (mc - exact).abs() < 0.01,
            "Monte Carlo {mc} vs Steiner {exact}"
        );
    }

    #[test]
    fn default_catom_weighs_about_33_mg() {
        let m = Model::default_catom();
        assert!((m.spacing - 3.6e-3).abs() < 1e-12);
        assert!((m.mass * 1e6 - 33.3).abs() < 0.2, "{} mg", m.mass * 1e6);
        assert!((m.connector.side / m.spacing - 0.2265).abs() < 1e-3);
    }

    #[test]
    fn mass_override_wins_over_density_and_survives_rescaling() {
        let text = include_str!("../../models/catom-3.6mm.toml")
            .replace("density_g_cm3 = 1.2", "density_g_cm3 = 1.2\nmass_mg = 50.0");
        let m = Model::from_toml(&text).unwrap();
        assert!((m.mass - 50e-6).abs() < 1e-15);
        assert!((m.at_spacing(7.2e-3).mass - 50e-6).abs() < 1e-15);
        let d = Model::default_catom().at_spacing(7.2e-3);
        assert!((d.mass / Model::default_catom().mass - 8.0).abs() < 1e-9);
    }

    #[test]
    fn bad_models_are_input_errors() {
        let text = include_str!("../../models/catom-3.6mm.toml");
        for (from, to) in [
            ("pressure_kpa = 100.0", "pressure_kpa = -1.0"),
            ("bending = \"rigid-hinge\"", "bending = \"plastic\""),
            ("spacing_mm = 3.6", "spacing_mm = 0.0"),
        ] {
            assert!(text.contains(from), "{from}");
            let e = Model::from_toml(&text.replacen(from, to, 1)).unwrap_err();
            assert!(!e.message.is_empty());
        }
    }
}
