//! Mechanics (SPEC §4.5): gravity stability and connector loads of every
//! intermediate structure. It builds on the lattice only; certification
//! runs it per step, and the branch-length study (`crate::study`) over many
//! schedules.
//!
//! * `model` — the physical model (TOML in `models/`): mass, connector
//!   capacity, ground contact;
//! * `capacity` — connector failure criteria and utilisation;
//! * `structure` — a configuration as rigid bodies, connector links and
//!   movers hanging on their pivots, from any [`crate::lattice::Lattice`];
//! * `analysis` — the static solve (elastic interface network, unilateral
//!   ground by active set) with reuse between consecutive steps;
//! * `solver`, `direct` — preconditioned CG over 6 × 6 blocks and the
//!   sparse Cholesky factor (faer) that preconditions it;
//! * `closed_form` — the cantilever bounds the study is checked against;
//! * `limit`, `proof` — the limit analysis (lower-bound theorem) and the
//!   proof of its factor; `pose_hull` — a few points holding a step's
//!   poses, where a region's bound is proved once for all of them;
//!   `sweep_bisection` — a sweep's smallest factor by branch and bound
//!   along the movers' path, bounding runs of poses by one triangle each.
//! * `superposition` — a step's poses as a few unit load cases: at most
//!   three per group of movers turning at one rate, however many movers.
//! * `tipping` — where a component that falls even on rigid connectors has
//!   its weight, against the convex hull of its ground contacts.
//!
//! See `docs/mechanics.md` for the derivations and the choice of model.

pub(crate) mod analysis;
pub mod atom;
pub(crate) mod capacity;
pub(crate) mod closed_form;
pub(crate) mod direct;
pub(crate) mod limit;
pub(crate) mod model;
pub(crate) mod pose_hull;
pub(crate) mod reuse;
pub(crate) mod solver;
pub(crate) mod structure;
pub(crate) mod superposition;
pub(crate) mod sweep_bisection;
pub(crate) mod tipping;

pub use analysis::{Analysis, Analyzer, Critical, LinkResult, Verdict};
pub use capacity::{ConnectorLoad, Mode, overloaded, severity, utilisation};
pub use direct::Factor;
pub use model::{Bending, Capacity, Model};
pub use solver::Vec6;
pub use structure::{End, SceneRef, Structure};

/// rapier's dynamic cross-check of the static analysis: test-only, so the
/// library does not carry a physics engine it never runs.
#[cfg(test)]
mod dynamics;
#[cfg(test)]
mod resting;
#[cfg(test)]
mod validation;
