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

/// A background program (the EtherCAT emulator) whose first line on stderr was awaited; its
/// other lines are passed on to the test's stderr. Killed and reaped on drop.
#[derive(Debug)]
pub struct Background(std::process::Child);

impl Background {
    /// Starts `c` with stderr piped and returns it with its first stderr line.
    ///
    /// # Panics
    /// When it cannot be started, or says nothing within `limit` (naming it `what`).
    pub fn start(c: &mut Command, limit: std::time::Duration, what: &str) -> (Self, String) {
        use std::io::{BufRead, BufReader};
        let mut child = c
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("spawn {what}: {e}"));
        let stderr = child.stderr.take().expect("stderr");
        let bg = Self(child);
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let mut lines = BufReader::new(stderr).lines();
            if let Some(Ok(line)) = lines.next() {
                // The receiver may have given up waiting; then nobody needs the line.
                let _ = tx.send(line);
            }
            // Keep draining so the program never blocks on a full pipe.
            for line in lines.map_while(Result::ok) {
                eprintln!("{line}");
            }
        });
        let line = rx
            .recv_timeout(limit)
            .unwrap_or_else(|_| panic!("{what} did not start within {limit:?}"));
        (bg, line)
    }
}

impl Drop for Background {
    fn drop(&mut self) {
        // The process may already have exited; either way it is reaped below.
        let _ = self.0.kill();
        // Reap it; its exit status is of no interest after a kill.
        let _ = self.0.wait();
    }
}
