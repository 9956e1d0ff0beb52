//! The schedule: one versioned JSON format for every lattice and every seed.
//!
//! A schedule is an initial configuration followed by time steps; each step
//! is a set of events executed concurrently. See `docs/schedule-format.md`
//! for the full description with examples.

pub(crate) mod units;

use crate::error::InputError;
use crate::lattice::config::{Ground, ModuleId};
use crate::lattice::{AtomRest, Cell, Face, LatticeKind, Route};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
pub use units::Length;

/// The value of the `format` field of every schedule file.
pub const FORMAT: &str = "reconfcheck-schedule";
/// The schedule format version this build reads and writes.
pub const VERSION: u32 = 1;
/// Largest coordinate of a cell or ground layer, in lattice units (2²⁰:
/// about 3.8 km of 3.6 mm catoms). Neighbour and sweep arithmetic stays
/// far from `i32` overflow below it.
pub const MAX_COORDINATE: i32 = 1 << 20;

/// A reconfiguration schedule.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Schedule {
    pub format: String,
    pub version: u32,
    pub lattice: LatticeKind,
    /// Lattice spacing `d` (centre-to-centre distance of latched modules).
    pub spacing: Length,
    /// Path of the physical model (relative to the schedule file), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
    /// Cubic lattice only: the modules are seed 004's atoms, resting with
    /// every face contracted or every face expanded, every pair of touching
    /// faces attached (see `docs/schedule-format.md`, "Atoms").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub atoms: Option<AtomRest>,
    /// Cubic lattice only: the modules are seed 004's 2×2×2 meta-modules
    /// of atoms resting in this model; the certifier expands every event
    /// into atom operations (see `docs/atoms.md`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub meta_modules: Option<AtomRest>,
    /// The ground plane, if the scene has one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ground: Option<Ground>,
    /// The initial configuration, fixed (ground/sandbox) modules included.
    pub modules: Vec<ModuleSpec>,
    /// Cells where new modules may enter (sandbox or reserve outlets).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sources: Vec<Cell>,
    /// Cells through which modules leave the scene.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sinks: Vec<Cell>,
    /// Free-form provenance written by generators (algorithm, parameters).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub meta: BTreeMap<String, serde_json::Value>,
    pub steps: Vec<Step>,
}

/// One module of the initial configuration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModuleSpec {
    pub id: ModuleId,
    pub cell: Cell,
    /// Fixed modules (sandbox, anchored base) never move and anchor the
    /// structure like the ground does.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub fixed: bool,
}

/// One time step: events executed concurrently.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Step {
    pub events: Vec<Event>,
}

/// Something that happens to a module during a time step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "op", rename_all = "snake_case", deny_unknown_fields)]
pub enum Event {
    /// FCC rolling rotation of `module` on `pivot` (SPEC §3).
    Rotate {
        module: ModuleId,
        pivot: ModuleId,
        from: Cell,
        to: Cell,
        route: Route,
    },
    /// Sliding move on the square or cubic lattice. `pivot`: the module held
    /// (the wall beside `from`, or the corner of a diagonal move); absent for
    /// a slide along the ground.
    Slide {
        module: ModuleId,
        from: Cell,
        to: Cell,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pivot: Option<ModuleId>,
    },
    /// Seed 004 k-TUNNEL of a meta-module along `path` (start cell first).
    Tunnel { module: ModuleId, path: Vec<Cell> },
    /// A new module enters the scene at `cell` (from a sandbox or reserve).
    Enter { module: ModuleId, cell: Cell },
    /// Seed 002 docking: a new module joins the structure at `cell`, its
    /// final approach the lattice move from the free cell `from` on `pivot`
    /// (a module already in the structure). `route` is needed on FCC only.
    Dock {
        module: ModuleId,
        cell: Cell,
        pivot: ModuleId,
        from: Cell,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        route: Option<Route>,
    },
    /// `module` leaves the scene through the sink cell it is in at the end
    /// of this step (it may arrive there by a move in the same step).
    Leave { module: ModuleId },
    /// Latch the connectors between two neighbouring modules.
    Attach { module: ModuleId, other: ModuleId },
    /// Release the connectors between two neighbouring modules.
    Detach { module: ModuleId, other: ModuleId },
    /// Cubic atom (seed 004): extend `face` by one unit, pushing whatever
    /// is attached to it.
    Expand { module: ModuleId, face: Face },
    /// Cubic atom (seed 004): retract `face` by one unit, pulling whatever
    /// is attached to it.
    Contract { module: ModuleId, face: Face },
}

impl Event {
    /// The module the event is about (the first one for latch events).
    pub fn module(&self) -> ModuleId {
        match self {
            Event::Rotate { module, .. }
            | Event::Slide { module, .. }
            | Event::Tunnel { module, .. }
            | Event::Enter { module, .. }
            | Event::Dock { module, .. }
            | Event::Leave { module }
            | Event::Attach { module, .. }
            | Event::Detach { module, .. }
            | Event::Expand { module, .. }
            | Event::Contract { module, .. } => *module,
        }
    }

    /// Whether the event displaces its module between cells.
    pub fn is_motion(&self) -> bool {
        matches!(
            self,
            Event::Rotate { .. } | Event::Slide { .. } | Event::Tunnel { .. }
        )
    }
}

impl Schedule {
    /// An empty schedule on `lattice` with unit spacing.
    pub fn new(lattice: LatticeKind, spacing: Length) -> Self {
        Schedule {
            format: FORMAT.to_string(),
            version: VERSION,
            lattice,
            spacing,
            model: None,
            atoms: None,
            meta_modules: None,
            ground: None,
            modules: Vec::new(),
            sources: Vec::new(),
            sinks: Vec::new(),
            meta: BTreeMap::new(),
            steps: Vec::new(),
        }
    }

    /// Number of motion events over all steps.
    pub fn move_count(&self) -> usize {
        self.steps
            .iter()
            .map(|s| s.events.iter().filter(|e| e.is_motion()).count())
            .sum()
    }

    /// Modules at the end: the initial ones, plus those that enter, less
    /// those that leave.
    pub fn final_module_count(&self) -> usize {
        let (mut enter, mut leave) = (0usize, 0usize);
        for e in self.steps.iter().flat_map(|s| &s.events) {
            match e {
                Event::Enter { .. } | Event::Dock { .. } => enter += 1,
                Event::Leave { .. } => leave += 1,
                _ => {}
            }
        }
        (self.modules.len() + enter).saturating_sub(leave)
    }

    /// Parses a schedule from JSON text; `origin` names it in errors.
    pub fn from_json(text: &str, origin: &Path) -> Result<Schedule, InputError> {
        let schedule: Schedule = serde_json::from_str(text)
            .map_err(|e| InputError::new(format!("not a valid schedule: {e}")).in_file(origin))?;
        schedule.validate().map_err(|e| e.in_file(origin))?;
        Ok(schedule)
    }

    /// Reads and parses a schedule file.
    pub fn load(path: &Path) -> Result<Schedule, InputError> {
        let text = crate::error::read_file(path, "schedule")?;
        Schedule::from_json(&text, path)
    }

    /// Writes the schedule as JSON (compact: schedules get large).
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("schedules serialise")
    }

    /// What a schedule must satisfy before it is replayed, whether read
    /// from a file or made by a generator: the format and version, a
    /// positive finite spacing (a normal number in metres), and cells within [`MAX_COORDINATE`].
    pub fn validate(&self) -> Result<(), InputError> {
        self.check_header()?;
        if (self.atoms.is_some() || self.meta_modules.is_some())
            && self.lattice != LatticeKind::Cubic
        {
            return Err(InputError::new(format!(
                "`atoms` and `meta_modules` are for the cubic lattice only (this schedule is {})",
                self.lattice.name()
            )));
        }
        if self.atoms.is_some() && self.meta_modules.is_some() {
            return Err(InputError::new(
                "a schedule has `atoms` or `meta_modules`, not both",
            ));
        }
        // In metres, after the unit's factor: a value that over- or
        // underflows there (1e-320 mm) is no length either.
        if crate::number::positive(self.spacing.value)
            .and_then(|_| crate::number::positive(self.spacing.metres()))
            .is_err()
        {
            return Err(InputError::new(format!(
                "spacing {} {} is not a positive length",
                self.spacing.value,
                self.spacing.unit.name()
            )));
        }
        self.check_extent()
    }

    /// Refuses cells and ground layers beyond [`MAX_COORDINATE`], naming
    /// the step and the module.
    fn check_extent(&self) -> Result<(), InputError> {
        let far = |c: &Cell| {
            [c.x, c.y, c.z]
                .iter()
                .any(|v| v.unsigned_abs() > MAX_COORDINATE as u32)
        };
        let refuse = |c: &Cell| {
            InputError::new(format!(
                "cell ({}, {}, {}) lies beyond ±{MAX_COORDINATE} lattice units",
                c.x, c.y, c.z
            ))
        };
        if let Some(g) = &self.ground
            && g.layer.unsigned_abs() > MAX_COORDINATE as u32
        {
            return Err(InputError::new(format!(
                "ground layer {} lies beyond ±{MAX_COORDINATE}",
                g.layer
            )));
        }
        for m in &self.modules {
            if far(&m.cell) {
                return Err(refuse(&m.cell).for_module(m.id));
            }
        }
        if let Some(c) = self.sources.iter().chain(&self.sinks).find(|c| far(c)) {
            return Err(refuse(c));
        }
        for (k, step) in self.steps.iter().enumerate() {
            for e in &step.events {
                let cells: Vec<&Cell> = match e {
                    Event::Rotate { from, to, .. } | Event::Slide { from, to, .. } => {
                        vec![from, to]
                    }
                    Event::Tunnel { path, .. } => path.iter().collect(),
                    Event::Enter { cell, .. } => vec![cell],
                    Event::Dock { cell, from, .. } => vec![cell, from],
                    Event::Leave { .. }
                    | Event::Attach { .. }
                    | Event::Detach { .. }
                    | Event::Expand { .. }
                    | Event::Contract { .. } => vec![],
                };
                if let Some(c) = cells.into_iter().find(|c| far(c)) {
                    return Err(refuse(c).at_step(k + 1).for_module(e.module()));
                }
            }
        }
        Ok(())
    }

    fn check_header(&self) -> Result<(), InputError> {
        if self.format != FORMAT {
            return Err(InputError::new(format!(
                "format is '{}', expected '{FORMAT}'",
                self.format
            )));
        }
        if self.version != VERSION {
            return Err(InputError::new(format!(
                "unsupported schedule version {} (this build reads version {VERSION})",
                self.version
            )));
        }
        Ok(())
    }
}
