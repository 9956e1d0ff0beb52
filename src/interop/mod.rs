//! Reading and writing what VisibleSim users already have: configuration
//! XML files (`<world>` / `<blockList>` / `<targetList>`) and the motion
//! traces (CSV) of webots-visiblesim. Everything is converted at this edge
//! into the one internal frame (SPEC §1); see `docs/visiblesim.md`.
//!
//! This layer sits above `algorithms` (it may read the scaffold's CSG
//! model) and below the command line; nothing in `algorithms` or
//! `certify` depends on it.

mod target;
mod trace;
mod visiblesim;

pub use crate::algorithms::scaffold::vs_csg::{MAX_VS_DEPTH, VsNode, parse_vs_csg};
pub use target::target_cells;
pub use trace::{TraceOptions, TraceRow, read_trace, trace_to_schedule};
pub use visiblesim::{
    GroundChoice, VsBlock, VsConfig, VsLattice, config_at_step, export_config, import_config,
    read_config,
};
