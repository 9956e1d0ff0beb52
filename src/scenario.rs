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
        let text = crate::error::read_file(path, "scenario")?;
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

    /// A path written in the scenario, rewritten so that it resolves from
    /// the folder of `output` (a file the scenario's results are written
    /// to): relative when both lie under a common folder, else absolute.
    /// Schedules name their model relative to their own folder, so copying
    /// the scenario's text verbatim breaks when the output goes elsewhere.
    pub fn path_from(&self, rel: &str, output: &Path) -> String {
        let abs = |p: &Path| {
            p.canonicalize()
                .or_else(|_| std::path::absolute(p))
                .unwrap_or_else(|_| p.to_path_buf())
        };
        let target = abs(&self.resolve(rel));
        let out_dir = abs(output
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new(".")));
        let (t, o): (Vec<_>, Vec<_>) = (
            target.components().collect(),
            out_dir.components().collect(),
        );
        let common = t.iter().zip(&o).take_while(|(a, b)| a == b).count();
        // Only the root in common: an absolute path is clearer than "../../..".
        if common <= 1 {
            return target.display().to_string();
        }
        let mut r = PathBuf::new();
        for _ in common..o.len() {
            r.push("..");
        }
        for c in &t[common..] {
            r.push(c);
        }
        r.display().to_string()
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
