//! A retained record survives `kill -9` of its writer at any moment: a child process stores a
//! counter record in a tight loop and reports each completed store on its stdout; the parent
//! kills it with SIGKILL at 30 different moments (1..=30 ms after its first store), and after each
//! kill `load` returns a whole record whose counter is the last one reported or the one after
//! (the store in flight, if its rename happened), never an error, never a torn value. Finally the
//! parent stores and loads one more record, and no temporary file is left.
//!
//! The child is this test binary itself, run with [`WRITER_ENV`] naming the directory: the same
//! test then becomes the writer.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::io::{BufRead, BufReader, Write};
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::thread;
use std::time::{Duration, Instant};
use tandem_rt::retain::RetainStore;

/// Set in the child: the directory it writes to.
const WRITER_ENV: &str = "TANDEM_RETAIN_KILL_WRITER_DIR";
/// The record.
const RECORD: &str = "counter";
/// Copies of the counter in a payload: a torn payload would show copies that differ.
const COPIES: usize = 8;
/// How long the parent waits for anything from or about the child.
const TIMEOUT: Duration = Duration::from_secs(30);

fn encode(n: u64) -> Vec<u8> {
    n.to_le_bytes().repeat(COPIES)
}

/// The counter of a payload, `None` if it is torn (wrong length or copies that differ).
fn decode(payload: &[u8]) -> Option<u64> {
    let mut copies = payload.chunks_exact(8);
    let first = copies.next()?;
    let all_equal = payload.len() == 8 * COPIES && copies.all(|c| c == first);
    all_equal.then(|| u64::from_le_bytes(first.try_into().unwrap()))
}

/// The child: stores the counter, from one past the retained one, for ever (until killed).
fn write_forever(dir: &Path) -> ! {
    let store = RetainStore::open(dir).unwrap();
    let mut n = match store.load(RECORD).unwrap() {
        Some(p) => decode(&p).expect("a whole record at the start of a writer"),
        None => 0,
    };
    let mut out = std::io::stdout().lock();
    loop {
        n += 1;
        store.store(RECORD, &encode(n)).unwrap();
        writeln!(out, "stored {n}").unwrap();
        out.flush().unwrap();
    }
}

/// Starts a writer on `dir` and a thread forwarding its reported counters.
fn spawn_writer(dir: &Path) -> (Child, Receiver<u64>, thread::JoinHandle<()>) {
    let mut child = Command::new(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "retained_record_survives_kill_9",
            "--nocapture",
            "--test-threads=1",
        ])
        .env(WRITER_ENV, dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let stdout = child.stdout.take().unwrap();
    let (tx, rx) = mpsc::channel();
    let reader = thread::spawn(move || {
        for line in BufReader::new(stdout).lines() {
            let Ok(line) = line else { break };
            if let Some(n) = line.strip_prefix("stored ").and_then(|n| n.parse().ok()) {
                if tx.send(n).is_err() {
                    break;
                }
            }
        }
    });
    (child, rx, reader)
}

/// Waits for `child` to end, at most [`TIMEOUT`].
fn wait_with_timeout(child: &mut Child) -> std::process::ExitStatus {
    let deadline = Instant::now() + TIMEOUT;
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        assert!(
            Instant::now() < deadline,
            "the writer did not end after SIGKILL"
        );
        thread::sleep(Duration::from_millis(1));
    }
}

/// Every counter still in the pipe after the child ended, until its end, at most [`TIMEOUT`].
fn drain(rx: &Receiver<u64>, mut last: u64) -> u64 {
    let deadline = Instant::now() + TIMEOUT;
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        match rx.recv_timeout(left) {
            Ok(n) => last = last.max(n),
            Err(RecvTimeoutError::Disconnected) => return last,
            Err(RecvTimeoutError::Timeout) => panic!("the writer's stdout did not end"),
        }
    }
}

/// The temporary files in `dir` (names starting with `.`).
fn temporaries(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with('.'))
        .collect()
}

#[test]
fn retained_record_survives_kill_9() {
    if let Some(dir) = std::env::var_os(WRITER_ENV) {
        write_forever(Path::new(&dir));
    }
    let dir =
        Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("retain_kill_{}", std::process::id()));
    // A leftover of an earlier run with the same pid may or may not exist.
    let _ = std::fs::remove_dir_all(&dir);
    let mut previous = 0u64;
    let mut killed_mid_store = 0;
    for delay_ms in 1..=30u64 {
        let (mut child, rx, reader) = spawn_writer(&dir);
        let first = rx
            .recv_timeout(TIMEOUT)
            .expect("the writer reported its first store");
        thread::sleep(Duration::from_millis(delay_ms));
        tandem_rt::send_signal(child.id(), libc::SIGKILL).unwrap();
        let status = wait_with_timeout(&mut child);
        assert_eq!(
            status.signal(),
            Some(libc::SIGKILL),
            "the writer was still writing when killed ({status})"
        );
        let reported = drain(&rx, first);
        reader.join().unwrap();
        // Killed between creating its temporary file and the rename.
        killed_mid_store += usize::from(!temporaries(&dir).is_empty());

        let store = RetainStore::open(&dir).unwrap();
        assert!(
            temporaries(&dir).is_empty(),
            "open removes the dead writer's temporary"
        );
        let payload = store
            .load(RECORD)
            .unwrap_or_else(|e| panic!("kill after {delay_ms} ms: {e}"))
            .expect("a record");
        let n = decode(&payload).unwrap_or_else(|| panic!("torn record: {payload:?}"));
        assert!(
            n == reported || n == reported + 1,
            "kill after {delay_ms} ms: loaded {n}, last reported {reported}"
        );
        assert!(
            n > previous,
            "each writer stored at least once: {n} after {previous}"
        );
        previous = n;
    }
    let store = RetainStore::open(&dir).unwrap();
    store.store(RECORD, &encode(previous + 1)).unwrap();
    let n = decode(&store.load(RECORD).unwrap().unwrap()).unwrap();
    assert_eq!(n, previous + 1);
    assert!(temporaries(&dir).is_empty());
    eprintln!(
        "30 kills: {killed_mid_store} left a temporary file (killed mid-store); last counter {n}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
