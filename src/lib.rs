//! reconfcheck — certifies that a lattice modular robot's reconfiguration is
//! physically feasible.
//!
//! Layers, each depending only on those above it in this list:
//!
//! * [`lattice`] — cells, neighbours, moves (FCC, square, cubic);
//! * [`schedule`] — the versioned schedule format shared by every seed;
//! * [`scenario`] — runnable cases: a generator's name and its inputs;
//! * [`geometry`] — module bodies, continuous sweeps, and the motion rules
//!   derived from them;
//! * [`mechanics`] — the frame model of a structure: equilibrium, connector
//!   loads, capacities;
//! * [`certify`] — replays a schedule and runs every check on every step;
//! * [`algorithms`] — generators that emit schedules (depend on `lattice`,
//!   `schedule` and `geometry`'s motion rules, never on `mechanics` or
//!   `certify`);
//! * [`study`] — questions asked over many schedules (the b-study, load
//!   maps, synthetic benchmarks).
//!
//! [`render`] (SVG → PNG) and [`progress`] (progress bars) are leaves that
//! any layer may use.

pub mod algorithms;
pub mod certify;
pub mod error;
pub mod geometry;
pub mod lattice;
pub mod mechanics;
pub mod progress;
pub mod render;
pub mod scenario;
pub mod schedule;
pub mod study;

pub use error::InputError;
