//! Errors about unusable input: they name the file, the step and the module.

use crate::lattice::config::ModuleId;
use std::fmt;
use std::path::{Path, PathBuf};

/// Input that cannot be certified at all: malformed files, unknown versions,
/// lattices or units, moves that are not moves of the lattice, references to
/// modules that do not exist. Always exit code 2 at the command line.
#[derive(Clone, Debug, PartialEq)]
pub struct InputError {
    pub file: Option<PathBuf>,
    /// Time step (1-based), where the problem is inside one.
    pub step: Option<usize>,
    pub module: Option<ModuleId>,
    pub message: String,
}

impl InputError {
    pub fn new(message: impl Into<String>) -> Self {
        InputError {
            file: None,
            step: None,
            module: None,
            message: message.into(),
        }
    }

    pub fn at_step(mut self, step: usize) -> Self {
        self.step = Some(step);
        self
    }

    pub fn for_module(mut self, module: ModuleId) -> Self {
        self.module = Some(module);
        self
    }

    /// Names the file, unless a more specific one is already named.
    pub fn in_file(mut self, file: impl AsRef<Path>) -> Self {
        if self.file.is_none() {
            self.file = Some(file.as_ref().to_path_buf());
        }
        self
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = Vec::new();
        if let Some(file) = &self.file {
            parts.push(file.display().to_string());
        }
        if let Some(s) = self.step {
            parts.push(format!("step {s}"));
        }
        if let Some(m) = self.module {
            parts.push(format!("module {m}"));
        }
        if parts.is_empty() {
            write!(f, "{}", self.message)
        } else {
            write!(f, "{}: {}", parts.join(", "), self.message)
        }
    }
}

impl std::error::Error for InputError {}
