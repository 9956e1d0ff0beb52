//! Output paths checked before the work: a certification of the sandcastle
//! or a Fig. 10 study runs for minutes, and its result should not be lost
//! to a typo in a flag.

use reconfcheck::error::{Error, InputError};
use std::path::Path;

/// Refuses an output `path` given with `flag` that is a folder, or whose
/// folder does not exist (exit 2, naming the flag and the path).
pub fn check_output(flag: &str, path: &Path) -> Result<(), Error> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if path.is_dir() {
        return Err(InputError::new(format!(
            "{flag} {}: is a folder, not a file",
            path.display()
        ))
        .into());
    }
    if !dir.is_dir() {
        return Err(InputError::new(format!(
            "{flag} {}: cannot write it there: the folder {} does not exist",
            path.display(),
            dir.display()
        ))
        .into());
    }
    Ok(())
}
