//! Where the tests find the repository and the workspace's programs.
//!
//! Cargo tells a test where its own package's programs are (`CARGO_BIN_EXE_<name>`), but not
//! where another package's are. Every program of the workspace is built into one directory,
//! `target/<profile>/`, and a test executable runs from `target/<profile>/deps/`, so
//! [`bin_dir`] is found from the test's own path.
//!
//! ```
//! use tandem_testkit::workspace::{binary, root};
//!
//! assert!(root().join("config/line.toml").exists());
//! let missing = binary("tandem-no-such-program").unwrap_err();
//! assert!(missing.to_string().contains("tandem-no-such-program is missing: build it first"));
//! ```

use std::fmt;
use std::path::{Path, PathBuf};

/// The repository's root directory (the workspace's).
pub fn root() -> PathBuf {
    let kit = Path::new(env!("CARGO_MANIFEST_DIR"));
    // This crate is `shared/testkit` of the workspace.
    kit.ancestors()
        .nth(2)
        .map_or_else(|| kit.join("../.."), Path::to_path_buf)
}

/// The directory of the workspace's programs for the running test's profile:
/// `target/<profile>/`, the parent of the test executable's `deps/` directory.
///
/// # Panics
/// When the running executable's path is unknown or has no grandparent (never for a test run
/// by cargo).
pub fn bin_dir() -> PathBuf {
    let exe = std::env::current_exe()
        .unwrap_or_else(|e| panic!("the path of the running test is unknown: {e}"));
    exe.parent()
        .and_then(Path::parent)
        .map(Path::to_path_buf)
        .unwrap_or_else(|| panic!("{}: not in target/<profile>/deps/", exe.display()))
}

/// A program of the workspace that is not built.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MissingBinary {
    /// Where it should be.
    pub path: PathBuf,
}

impl fmt::Display for MissingBinary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} is missing: build it first, in the profile of the tests \
             (cargo build --release --workspace --bins, as tests/run.sh does)",
            self.path.display()
        )
    }
}

impl std::error::Error for MissingBinary {}

/// The path of the workspace's program `name` (`tandem`, `tandem-node`, `tandem-gateway`),
/// if it is built.
pub fn binary(name: &str) -> Result<PathBuf, MissingBinary> {
    let path = bin_dir().join(name);
    if path.exists() {
        Ok(path)
    } else {
        Err(MissingBinary { path })
    }
}

/// The path of the workspace's program `name`.
///
/// # Panics
/// When it is not built, saying how to build it.
pub fn bin(name: &str) -> PathBuf {
    binary(name).unwrap_or_else(|e| panic!("{e}"))
}
