//! reconfcheck — certifies that a lattice modular robot's reconfiguration is
//! physically feasible.
//!
//! Layers, each depending only on those above it in this list:
//!
//! * [`lattice`] — cells, neighbours, moves (FCC, square, cubic);
//! * [`schedule`] — the versioned schedule format shared by every seed;
//! * [`geometry`] — module bodies and continuous sweeps;
//! * [`certify`] — replays a schedule and runs every check on every step;
//! * [`algorithms`] — generators that emit schedules (depend on `lattice`
//!   and `schedule`, never on `certify`);
//! * [`scenario`] — runnable cases that name a generator and its inputs.

pub mod algorithms;
pub mod certify;
pub mod error;
pub mod geometry;
pub mod lattice;
pub mod mechanics;
pub mod render;
pub mod scenario;
pub mod schedule;
pub mod study;

pub use error::InputError;
