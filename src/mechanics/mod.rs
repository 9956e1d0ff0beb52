//! Mechanics (SPEC §4.5): gravity stability and connector loads of every
//! intermediate structure, and the branch-length study.
//!
//! * [`model`] — the physical model (TOML in `models/`): mass, connector
//!   capacity, ground contact;
//! * [`capacity`] — connector failure criteria and utilisation;
//! * [`structure`] — a configuration as rigid bodies, connector links and
//!   movers hanging on their pivots, from any [`crate::lattice::Lattice`];
//! * [`analysis`] — the static solve (elastic interface network, unilateral
//!   ground by active set) with reuse between consecutive steps;
//! * [`solver`], [`direct`] — preconditioned CG over 6 × 6 blocks and the
//!   sparse Cholesky factor (faer) that preconditions it;
//! * [`closed_form`] — the cantilever bounds the study is checked against.
//!
//! See `docs/mechanics.md` for the derivations and the choice of model.

pub mod analysis;
pub mod capacity;
pub mod closed_form;
pub mod direct;
pub mod model;
pub mod reuse;
pub mod solver;
pub mod structure;

pub use analysis::{Analysis, Analyzer, Critical, LinkResult, Verdict};
pub use capacity::{ConnectorLoad, Mode, utilisation};
pub use model::{Bending, Model};
pub use structure::{SceneRef, Structure};

/// rapier's dynamic cross-check of the static analysis: test-only, so the
/// library does not carry a physics engine it never runs.
#[cfg(test)]
mod dynamics;
#[cfg(test)]
mod validation;
