//! Running programs as the system tests do: started with their output collected, waited for
//! with a timeout (killed when it passes), conditions polled with a timeout. Every wait of a
//! system test goes through here, so none can hang the suite.
//!
//! ```
//! use std::process::Command;
//! use std::time::Duration;
//! use tandem_testkit::process::{run, text, until, Spawned};
//!
//! let mut echo = Command::new("sh");
//! echo.args(["-c", "echo out; echo err >&2"]);
//! let (status, said) = Spawned::start(&mut echo).wait(Duration::from_secs(10), "sh");
//! assert!(status.success());
//! assert_eq!(said, "out\nerr\n", "stdout, then stderr");
//!
//! let o = run(Command::new("true"), Duration::from_secs(10));
//! assert!(o.status.success() && text(&o).is_empty());
//!
//! let mut polls = 0;
//! until(Duration::from_secs(10), "the third poll", || {
//!     polls += 1;
//!     polls == 3
//! });
//! ```

use std::io::Read;
use std::process::{Child, Command, ExitStatus, Output, Stdio};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Reads all of `from` on a thread of its own; what could not be read is left out (the test
/// then fails on the output it expected).
fn collect(mut from: impl Read + Send + 'static) -> JoinHandle<Vec<u8>> {
    std::thread::spawn(move || {
        let mut s = Vec::new();
        // A read error ends the output early: the assertions on it say what is missing.
        let _ = from.read_to_end(&mut s);
        s
    })
}

/// The threads collecting a program's stdout and stderr.
#[derive(Debug)]
struct Collectors {
    stdout: Option<JoinHandle<Vec<u8>>>,
    stderr: Option<JoinHandle<Vec<u8>>>,
}

impl Collectors {
    /// Starts `c` with its stdout and stderr piped and collected.
    ///
    /// # Panics
    /// When it cannot be started.
    fn start(c: &mut Command) -> (Child, Collectors) {
        let mut child = c
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start {c:?}: {e}"));
        let collectors = Collectors {
            stdout: child.stdout.take().map(collect),
            stderr: child.stderr.take().map(collect),
        };
        (child, collectors)
    }

    /// What the program wrote to stdout and to stderr (once it ended: the pipes closed).
    fn join(self) -> (Vec<u8>, Vec<u8>) {
        let joined = |t: JoinHandle<Vec<u8>>| t.join().unwrap_or_default();
        let out = self.stdout.map(joined).unwrap_or_default();
        (out, self.stderr.map(joined).unwrap_or_default())
    }
}

/// A started program whose stdout and stderr are collected until it ends.
#[derive(Debug)]
pub struct Spawned {
    child: Child,
    output: Collectors,
}

impl Spawned {
    /// Starts `c` with its stdout and stderr piped and collected.
    ///
    /// # Panics
    /// When it cannot be started.
    pub fn start(c: &mut Command) -> Spawned {
        let (child, output) = Collectors::start(c);
        Spawned { child, output }
    }

    /// The program's process id.
    pub fn id(&self) -> u32 {
        self.child.id()
    }

    /// Waits for the program to end within `limit`; returns its status and its stdout followed
    /// by its stderr.
    ///
    /// # Panics
    /// When it does not end in time (it is killed first), naming it `what`.
    pub fn wait(mut self, limit: Duration, what: &str) -> (ExitStatus, String) {
        let status = wait_for(&mut self.child, limit, what);
        let (mut said, err) = self.output.join();
        said.extend(err);
        (status, String::from_utf8_lossy(&said).into_owned())
    }
}

/// Waits for `child` to exit within `limit`.
///
/// # Panics
/// When it does not, after killing it, naming it `what`.
pub fn wait_for(child: &mut Child, limit: Duration, what: &str) -> ExitStatus {
    let deadline = Instant::now() + limit;
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return s;
        }
        if Instant::now() > deadline {
            // The test fails below either way; the kill only keeps the process from outliving it.
            let _ = child.kill();
            // Reaps it (the error, if any, is that it was reaped already).
            let _ = child.wait();
            panic!("{what} did not end within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Polls `f` every 100 ms until it is true.
///
/// # Panics
/// When `limit` passes first, naming the condition `what`.
pub fn until(limit: Duration, what: &str, mut f: impl FnMut() -> bool) {
    let deadline = Instant::now() + limit;
    while !f() {
        assert!(Instant::now() < deadline, "{what}: not within {limit:?}");
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// Runs a short command to its end with a timeout; returns its status and output.
///
/// # Panics
/// When it cannot be started, or does not end within `limit` (it is killed).
pub fn run(mut c: Command, limit: Duration) -> Output {
    let (mut child, output) = Collectors::start(&mut c);
    let status = wait_for(&mut child, limit, &format!("{c:?}"));
    let (stdout, stderr) = output.join();
    Output {
        status,
        stdout,
        stderr,
    }
}

/// The stdout followed by the stderr of `o`, as text.
pub fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}
