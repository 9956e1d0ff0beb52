//! Studies: questions asked over many schedules. The branch-length (`b`)
//! upper bound, seed 003's density study, seed 000's figures (§5.4), and
//! synthetic workloads for the benchmarks. Their pictures are drawn by [`crate::render`].

pub mod b_study;
pub mod comb;
pub mod density;
pub mod docking;
pub mod fit;
pub mod repost;
pub mod scaffold_figures;
pub mod synthetic;
