//! The commands of the `tandem` program as the system tests start them.
//!
//! ```no_run
//! use std::path::Path;
//! use std::time::Duration;
//! use tandem_testkit::process::Spawned;
//! use tandem_testkit::tandem::{tandem, up};
//!
//! let (cell, record) = (Path::new("config/line.toml"), Path::new("/tmp/rec"));
//! let run = Spawned::start(up(tandem(), cell, record).args(["--duration", "2"]));
//! let (status, said) = run.wait(Duration::from_secs(60), "tandem up");
//! assert!(status.success(), "{said}");
//! ```

use crate::workspace::bin;
use std::path::Path;
use std::process::Command;

/// The workspace's `tandem` program, as a command to add arguments to.
///
/// # Panics
/// When it is not built.
pub fn tandem() -> Command {
    Command::new(bin("tandem"))
}

/// `tandem up <cell> --record <record> --no-view` appended to `launcher`: [`tandem`] itself, or
/// a command that runs it (e.g. `ip netns exec <namespace> <tandem>`). The caller adds the
/// other options (`--script`, `--duration`, `--host`, ...) and starts it.
///
/// # Panics
/// When `tandem-node` or `tandem-gateway` (which `tandem up` starts from beside itself) is not
/// built, saying how to build them.
pub fn up(mut launcher: Command, cell: &Path, record: &Path) -> Command {
    bin("tandem-node");
    bin("tandem-gateway");
    launcher
        .arg("up")
        .arg(cell)
        .arg("--record")
        .arg(record)
        .arg("--no-view");
    launcher
}
