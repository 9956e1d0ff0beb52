//! Scenario files (TOML): a runnable case naming a generator, its
//! parameters, the goal shape and the physical model.
//!
//! ```toml
//! name = "walk-fcc"
//! description = "Two catoms roll across a fixed platform."
//! algorithm = "schedule"            # see `algorithms::registry`
//! model = "../models/catom-3.6mm.toml"
//!
//! [parameters]                      # handed to the generator as is
//! schedule = "walk-fcc.json"
//! ```
//!
//! Relative paths are relative to the scenario file.

use crate::error::InputError;
use serde::Deserialize;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    pub name: String,
    #[serde(default)]
    pub description: String,
    pub algorithm: String,
    #[serde(default)]
    pub model: Option<String>,
    #[serde(default)]
    pub parameters: toml::Table,
    /// Directory of the scenario file, for relative paths.
    #[serde(skip)]
    pub dir: PathBuf,
    #[serde(skip)]
    pub path: PathBuf,
}

impl Scenario {
    pub fn load(path: &Path) -> Result<Scenario, InputError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| InputError::new(format!("cannot read scenario: {e}")).in_file(path))?;
        let mut s: Scenario = toml::from_str(&text)
            .map_err(|e| InputError::new(format!("not a valid scenario: {e}")).in_file(path))?;
        s.dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        s.path = path.to_path_buf();
        Ok(s)
    }

    /// A path written in the scenario, resolved against its directory.
    pub fn resolve(&self, rel: &str) -> PathBuf {
        self.dir.join(rel)
    }

    /// An error about this scenario file.
    pub fn error(&self, msg: impl Into<String>) -> InputError {
        InputError::new(msg).in_file(&self.path)
    }

    /// The bundled default scenario of `reconfcheck run`.
    pub fn default_path() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/default.toml")
    }
}
