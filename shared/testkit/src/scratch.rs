//! Scratch directories of the tests, in the system's temporary directory.

use std::path::{Path, PathBuf};

/// An empty directory `name` in the system's temporary directory (what a previous run left
/// there is removed first). Put the process id in `name` to keep concurrent runs apart.
///
/// # Panics
/// When it cannot be created.
pub fn fresh_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(name);
    remove_dir(&d);
    std::fs::create_dir_all(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display()));
    d
}

/// Removes `dir` and what it holds, if it exists.
pub fn remove_dir(dir: &Path) {
    // What cannot be removed is only litter in the temporary directory, not a test failure.
    let _ = std::fs::remove_dir_all(dir);
}
