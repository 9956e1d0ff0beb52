//! Generators: algorithms that emit schedules of real moves.
//!
//! Each generator implements [`Generator`] and is listed in [`registry`];
//! a scenario file names one by its [`Generator::name`]. Generators plan
//! with the lattice, the schedule format and the geometry's motion rules;
//! they never see the mechanics or certification (the layer list is in
//! `src/lib.rs`): a generator implements its paper, the certifier judges.

pub mod active_subtraction;
pub mod atom_moves;
pub mod branch;
pub mod comb;
pub mod docking;
pub mod random_walk;
pub mod repost;
pub mod scaffold;
pub mod schedule_file;

use crate::error::InputError;
use crate::scenario::Scenario;
use crate::schedule::Schedule;
use serde::de::DeserializeOwned;

/// An algorithm that turns a scenario into a schedule.
pub trait Generator: Sync {
    /// The name scenario files use in `algorithm = "…"`.
    fn name(&self) -> &'static str;
    /// One line on what it generates.
    fn about(&self) -> &'static str;
    fn generate(&self, scenario: &Scenario) -> Result<Schedule, InputError>;
}

/// Every generator this build knows.
pub fn registry() -> Vec<&'static dyn Generator> {
    vec![
        &schedule_file::ScheduleFile,
        &random_walk::RandomWalk,
        &active_subtraction::ActiveSubtraction,
        &branch::Branch,
        &scaffold::ScaffoldAssembly,
        &docking::Docking,
        &docking::Docking3d,
        &comb::Comb2d,
        &comb::Comb3d,
        &repost::RepostOperation,
        &repost::Repost,
    ]
}

/// Finds the generator a scenario names.
pub fn find(name: &str) -> Result<&'static dyn Generator, InputError> {
    registry()
        .into_iter()
        .find(|g| g.name() == name)
        .ok_or_else(|| {
            let known: Vec<_> = registry().iter().map(|g| g.name()).collect();
            InputError::new(format!(
                "unknown algorithm '{name}' (known: {})",
                known.join(", ")
            ))
        })
}

/// Runs the generator named by the scenario; its schedule is validated
/// ([`Schedule::validate`]) before it is returned.
pub fn generate(scenario: &Scenario) -> Result<Schedule, InputError> {
    let g = find(&scenario.algorithm).map_err(|e| e.in_file(&scenario.path))?;
    let mut s = g.generate(scenario)?;
    // What a generator made is held to what a file is held to, so that
    // `generate` never writes a schedule `certify` would refuse.
    s.validate().map_err(|e| e.in_file(&scenario.path))?;
    s.meta
        .entry("scenario".into())
        .or_insert_with(|| scenario.name.clone().into());
    if s.model.is_none() {
        s.model = scenario.model.clone();
    }
    Ok(s)
}

/// A named choice among `known`: its default when the scenario leaves it
/// out, an error naming the scenario and the parameter when unknown.
pub(crate) fn choice<T: Default>(
    scenario: &Scenario,
    param: &str,
    value: Option<&str>,
    parse: fn(&str) -> Option<T>,
    known: &str,
) -> Result<T, InputError> {
    match value {
        None => Ok(T::default()),
        Some(name) => parse(name).ok_or_else(|| {
            scenario.error(format!(
                "unknown {param} '{name}' in parameter {param} (known: {known})"
            ))
        }),
    }
}

/// Reads a generator's parameters from the scenario's `[parameters]` table.
pub fn parameters<P: DeserializeOwned>(scenario: &Scenario) -> Result<P, InputError> {
    scenario.parameters.clone().try_into().map_err(|e| {
        scenario.error(format!(
            "bad [parameters] for '{}': {e}",
            scenario.algorithm
        ))
    })
}
