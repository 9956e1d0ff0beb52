//! The library's errors. [`Error`] is what every fallible library function
//! returns where more than one kind of failure is possible; [`InputError`]
//! is the one kind a user fixes by changing the input, and names the file,
//! the step and the module.
//!
//! The binary maps [`Error::exit_code`] straight to the process's exit code:
//! 2 unusable input, 3 an output file could not be written.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A module's id in a schedule (the lattice layer's [`crate::lattice::ModuleId`];
/// repeated here so that this leaf module depends on nothing).
type ModuleId = u32;

/// Every failure the library reports.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Input that cannot be certified at all (exit code 2).
    #[error(transparent)]
    Input(#[from] InputError),
    /// An output file could not be written (exit code 3).
    #[error("{}: cannot write: {source}", path.display())]
    Write {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A picture could not be rendered to `path` (exit code 3).
    #[error("{}: cannot render: {message}", path.display())]
    Render { path: PathBuf, message: String },
}

impl Error {
    /// The command line's exit code for this failure.
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::Input(_) => 2,
            Error::Write { .. } | Error::Render { .. } => 3,
        }
    }

    /// Names the file of an input error, unless a more specific one is
    /// already named; other errors already name theirs.
    pub fn in_file(self, file: impl AsRef<Path>) -> Self {
        match self {
            Error::Input(e) => Error::Input(e.in_file(file)),
            other => other,
        }
    }
}

/// Writes `text` to `path`, keeping the I/O error as the source.
pub fn write_file(path: &Path, text: impl AsRef<[u8]>) -> Result<(), Error> {
    std::fs::write(path, text).map_err(|source| Error::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// Reads `path` as text; a failure is the input's (the file named, the I/O
/// error kept as the source). `what` says what the file was meant to be.
pub fn read_file(path: &Path, what: &str) -> Result<String, InputError> {
    std::fs::read_to_string(path)
        .map_err(|e| InputError::io(format!("cannot read {what}"), e).in_file(path))
}

/// Input that cannot be certified at all: malformed files, unknown versions,
/// lattices or units, moves that are not moves of the lattice, references to
/// modules that do not exist, numbers outside their range. Always exit code
/// 2 at the command line.
#[derive(Clone, Debug)]
pub struct InputError {
    pub file: Option<PathBuf>,
    /// Time step (1-based), where the problem is inside one.
    pub step: Option<usize>,
    pub module: Option<ModuleId>,
    pub message: String,
    /// The I/O error behind a file that could not be read.
    source: Option<Arc<std::io::Error>>,
}

impl InputError {
    pub fn new(message: impl Into<String>) -> Self {
        InputError {
            file: None,
            step: None,
            module: None,
            message: message.into(),
            source: None,
        }
    }

    /// A file that could not be read: the message, then the I/O error, which
    /// stays reachable as [`std::error::Error::source`].
    pub fn io(message: impl Into<String>, source: std::io::Error) -> Self {
        InputError {
            message: format!("{}: {source}", message.into()),
            source: Some(Arc::new(source)),
            ..InputError::new("")
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

impl std::error::Error for InputError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.source
            .as_deref()
            .map(|e| e as &(dyn std::error::Error + 'static))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error as _;

    #[test]
    fn an_unreadable_file_keeps_its_io_error_as_the_source() {
        let e = read_file(Path::new("/nonexistent/x.json"), "schedule").unwrap_err();
        assert_eq!(e.file.as_deref(), Some(Path::new("/nonexistent/x.json")));
        assert!(
            e.to_string()
                .starts_with("/nonexistent/x.json: cannot read schedule: ")
        );
        let io = e.source().expect("the I/O error is kept");
        assert!(io.downcast_ref::<std::io::Error>().is_some());
    }

    #[test]
    fn exit_codes_tell_input_from_output() {
        assert_eq!(Error::from(InputError::new("x")).exit_code(), 2);
        let w = write_file(Path::new("/nonexistent/dir/out.json"), "x").unwrap_err();
        assert_eq!(w.exit_code(), 3);
        assert!(w.source().is_some());
        assert!(
            w.to_string()
                .contains("/nonexistent/dir/out.json: cannot write")
        );
    }
}
