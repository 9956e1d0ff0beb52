//! reconfcheck — certifies that a lattice modular robot's reconfiguration is
//! physically feasible.
//!
//! Layers, each depending only on those before it in this list (the test
//! `tests/suite/architecture.rs` enforces it):
//!
//! 1. [`lattice`] — cells, neighbours, moves (FCC, square, cubic);
//! 2. [`schedule`], [`scenario`] — the versioned schedule format shared by
//!    every seed, and runnable cases (a generator's name and its inputs);
//! 3. [`geometry`] — module bodies, continuous sweeps, and the motion rules
//!    derived from them;
//! 4. [`mechanics`] — the frame model of a structure: equilibrium, connector
//!    loads, capacities;
//! 5. [`algorithms`] — generators that emit schedules; they plan with
//!    `geometry`'s motion rules and never see `mechanics` or `certify`;
//! 6. [`certify`] — replays a schedule and runs every check on every step;
//!    it never sees the generators;
//! 6. [`interop`] — VisibleSim configurations and webots-visiblesim motion
//!    traces in and out, converted at this edge (may read the scaffold's
//!    CSG model; nothing below depends on it);
//! 7. [`study`] — questions asked over many schedules (the b-study, the
//!    density study, load maps, synthetic benchmarks);
//! 8. [`render`] (feature `render`, on by default) — pictures and plots of
//!    all of the above;
//! 8. [`html`] — one self-contained HTML page of a report or a study: a 3D
//!    replay (three.js inlined), tables and curves.
//!
//! [`error`], [`number`] and [`progress`] are leaves every layer may use:
//! errors, validated numbers, progress reports. The library never prints,
//! reads the environment or draws a progress bar: the binary does.

#![cfg_attr(not(test), deny(clippy::print_stdout, clippy::print_stderr))]

pub mod algorithms;
pub mod certify;
pub mod error;
pub mod geometry;
pub mod html;
pub mod interop;
pub mod lattice;
pub mod mechanics;
pub mod number;
pub mod progress;
#[cfg(feature = "render")]
pub mod render;
pub mod scenario;
pub mod schedule;
pub mod study;

pub use error::{Error, InputError};
