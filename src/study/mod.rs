//! Studies built on certification: the branch-length (`b`) upper bound.

pub mod b_study;
pub mod density;
#[cfg(feature = "render")]
pub mod loadmap;
pub mod synthetic;
