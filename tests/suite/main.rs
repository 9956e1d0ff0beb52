//! The integration tests, one binary: each file is a module named after what
//! it tests. One binary links the library once instead of eighteen times,
//! which keeps CI's cold build short, and lets the test harness spread all
//! tests over the cores at once. Run a part with its module path, e.g.
//! `cargo test --test suite scaffold::` or `cargo test --test suite fuzz::`.

#[allow(dead_code)]
mod common;

mod active_subtraction;
mod architecture;
mod browser;
mod ci_gate;
mod cli;
mod comb_theorem;
mod cube_atoms;
mod docking;
mod edges;
mod faults;
mod fcc_geometry;
mod fuzz;
mod interop;
mod mpi;
mod properties;
mod report_page;
mod repost;
mod scaffold;
