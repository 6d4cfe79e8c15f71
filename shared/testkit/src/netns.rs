//! A network namespace that a test creates for itself (it needs root; a test that cannot
//! create one fails, never skips), with a veth pair inside it: what the EtherCAT tests run the
//! emulated segment and the MainDevice on. Deleted on drop, which deletes the pair too.

use std::path::Path;
use std::process::Command;

/// A network namespace with a veth pair `main` – `sub` and the loopback, all up.
#[derive(Debug)]
pub struct VethNetns {
    name: String,
}

impl VethNetns {
    /// Creates namespace `<prefix><pid>` with the veth pair `main` – `sub` (both up, and `lo`).
    pub fn create(prefix: &str, main: &str, sub: &str) -> Self {
        let name = format!("{prefix}{}", std::process::id());
        ip(&["netns", "add", &name]);
        let ns = Self { name };
        ip(&[
            "-n", &ns.name, "link", "add", main, "type", "veth", "peer", "name", sub,
        ]);
        for dev in [main, sub, "lo"] {
            ip(&["-n", &ns.name, "link", "set", dev, "up"]);
        }
        ns
    }

    /// The namespace's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Its file, for `setns(2)`: `/var/run/netns/<name>`.
    pub fn path(&self) -> String {
        format!("/var/run/netns/{}", self.name)
    }

    /// `ip netns exec <name> <program>`: a command that runs `program` inside the namespace.
    pub fn exec(&self, program: &Path) -> Command {
        let mut c = Command::new("ip");
        c.args(["netns", "exec", &self.name]).arg(program);
        c
    }
}

impl Drop for VethNetns {
    fn drop(&mut self) {
        // Best effort at teardown: nothing more can be done if the delete fails.
        let _ = Command::new("ip")
            .args(["netns", "del", &self.name])
            .status();
    }
}

/// Runs `ip <args>` and fails the test, naming the command and its error, if it fails.
pub fn ip(args: &[&str]) {
    let out = Command::new("ip").args(args).output().expect("run ip");
    assert!(
        out.status.success(),
        "ip {}: {} (the test needs root to create a network namespace)",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
}
