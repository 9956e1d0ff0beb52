//! The binary's subcommands that have logic of their own, one module each;
//! `main.rs` only parses arguments and dispatches here. Library code stays
//! in the library: these modules turn flags into validated library inputs
//! and library results into files, text and exit codes.

pub mod b_study;
pub mod comb;
pub mod density;
pub mod docking;
#[cfg(feature = "render")]
pub mod figures;
pub mod html;
pub mod interop;
pub mod moves;
pub mod output;
pub mod parallel;
#[cfg(feature = "render")]
pub mod pictures;
pub mod progress;
pub mod report;
pub mod repost;
pub mod schedule;
