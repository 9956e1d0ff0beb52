//! The trivial generator: a hand-written schedule file.

use super::{Generator, parameters};
use crate::error::InputError;
use crate::scenario::Scenario;
use crate::schedule::Schedule;
use serde::Deserialize;

/// Loads the schedule named by `parameters.schedule`.
pub struct ScheduleFile;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    schedule: String,
}

impl Generator for ScheduleFile {
    fn name(&self) -> &'static str {
        "schedule"
    }

    fn about(&self) -> &'static str {
        "a hand-written schedule file"
    }

    fn generate(&self, scenario: &Scenario) -> Result<Schedule, InputError> {
        let p: Params = parameters(scenario)?;
        Schedule::load(&scenario.resolve(&p.schedule))
    }
}
