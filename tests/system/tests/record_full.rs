//! Recording on a full disk (issue 12, "Recording that does not lose data silently"), with
//! real processes: `tandem up --record DIR` runs a one-node cell (1 ms cycle) whose record
//! directory is a 20 MB tmpfs, nearly filled by a filler file so that the trace hits ENOSPC
//! within seconds. While the disk is full `tandem status` shows the rows lost (the node's
//! health); then the filler is removed, the node runs on and is stopped. The trace holds whole
//! rows only, resumed by itself, and its rows plus the rows reported lost are exactly the
//! cycles the node ran, the lost ones being exactly the gap in its time column.
//!
//! Needs root (mount). Every wait has a timeout; nothing depends on the wall clock.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;
use tandem_testkit::process::{run, text, until, Spawned};
use tandem_testkit::scratch::{fresh_dir, remove_dir};
use tandem_testkit::tandem::tandem;

/// The cycle of the test's node (ns).
const CYCLE_NS: i64 = 1_000_000;

/// The size of the tmpfs and the room the filler leaves (about 3 s of rows of 53 bytes).
const DISK_BYTES: u64 = 20 * 1024 * 1024;
const ROOM_BYTES: u64 = 160 * 1024;

/// A tmpfs mounted on `dir`, unmounted (and `dir`'s scratch parent removed) when dropped,
/// also when the test fails.
struct Tmpfs {
    dir: PathBuf,
    scratch: PathBuf,
}

impl Tmpfs {
    fn mount(scratch: &Path) -> Tmpfs {
        let dir = scratch.join("rec");
        std::fs::create_dir_all(&dir).unwrap();
        let o = run(
            {
                let mut c = Command::new("mount");
                c.args(["-t", "tmpfs", "-o", "size=20m", "tmpfs"]).arg(&dir);
                c
            },
            Duration::from_secs(20),
        );
        assert!(o.status.success(), "mount (root needed): {}", text(&o));
        Tmpfs {
            dir,
            scratch: scratch.to_path_buf(),
        }
    }
}

impl Drop for Tmpfs {
    fn drop(&mut self) {
        let umount = |lazy: bool| {
            let mut c = Command::new("umount");
            if lazy {
                c.arg("-l");
            }
            c.arg(&self.dir);
            run(c, Duration::from_secs(20)).status.success()
        };
        // A busy mount (a process still writing into it) is detached lazily.
        if !umount(false) && !umount(true) {
            eprintln!("could not unmount {}", self.dir.display());
        }
        remove_dir(&self.scratch);
    }
}

/// A one-node cell with one virtual axis, on a 1 ms cycle.
fn cell(dir: &Path) -> PathBuf {
    let p = dir.join("cell.toml");
    std::fs::write(
        &p,
        format!(
            r#"[cell]
name = "recfull{}"

[[nodes]]
name = "rec"
cycle_us = {}

[axes.slide]
node = "rec"
virtual = true

[axes.slide.dynamics]
max_velocity = 500.0
max_acceleration = 5000.0
max_deceleration = 5000.0
max_jerk = 100000.0
velocity = 100.0
acceleration = 1000.0
deceleration = 1000.0
jerk = 20000.0
emergency_deceleration = 10000.0
"#,
            std::process::id(),
            CYCLE_NS / 1000
        ),
    )
    .unwrap();
    p
}

/// Whole lines of the trace so far (a line without its newline is not counted).
fn whole_lines(p: &Path) -> usize {
    std::fs::read(p).map_or(0, |b| b.iter().filter(|c| **c == b'\n').count())
}

/// `tandem status` of the cell.
fn status(cell: &Path) -> String {
    let mut c = tandem();
    c.arg("status").arg("--cell").arg(cell);
    text(&run(c, Duration::from_secs(20)))
}

/// The number in `line` right after `before` (e.g. `stopped after ` → the cycles).
fn number_after(line: &str, before: &str) -> u64 {
    line.split(before)
        .nth(1)
        .and_then(|r| r.split(|c: char| !c.is_ascii_digit()).next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no number after {before:?} in {line}"))
}

/// The one line of `log` containing every one of `parts`.
fn line_with<'a>(log: &'a str, parts: &[&str]) -> &'a str {
    let found: Vec<&str> = log
        .lines()
        .filter(|l| parts.iter().all(|p| l.contains(p)))
        .collect();
    assert_eq!(found.len(), 1, "one line with {parts:?}:\n{log}");
    found[0]
}

/// What the test did while the node ran: the trace's whole lines when the filler was
/// removed, and what `tandem status` showed while the disk was full.
struct Run {
    lines_at_removal: usize,
    status_while_full: String,
}

/// Commands sent while the disk is full and after it is freed: two log lines each
/// (`MC_Reset job n: Busy` and `... Done`).
const RESETS_WHILE_FULL: u64 = 5;
const RESETS_AFTER: u64 = 3;

/// `MC_Reset` on the node's axis (two log lines: Busy, Done).
fn reset(cell: &Path) {
    let mut c = tandem();
    c.arg("cmd")
        .arg("--cell")
        .arg(cell)
        .args(["rec/slide", "MC_Reset"]);
    let o = run(c, Duration::from_secs(20));
    assert!(o.status.success(), "{}", text(&o));
}

/// The counts of `recording lost N trace rows, M log lines` in `tandem status`, if shown.
fn shown_lost(status: &str) -> Option<(u64, u64)> {
    let l = status.lines().find(|l| l.contains("recording lost "))?;
    Some((
        number_after(l, "recording lost "),
        number_after(l, "trace rows, "),
    ))
}

/// Waits for the disk to fill and rows to be lost for a while (seen in the node's health
/// through `tandem status`), sends commands whose log lines are lost, removes the filler,
/// waits until the trace grows again, sends commands whose log lines are written.
fn fill_and_free(cell: &Path, filler: &Path, dir: &Path) -> Run {
    let mut status_while_full = String::new();
    until(
        Duration::from_secs(60),
        "status shows 1000 rows lost",
        || {
            status_while_full = status(cell);
            shown_lost(&status_while_full).is_some_and(|(rows, _)| rows >= 1000)
        },
    );
    for _ in 0..RESETS_WHILE_FULL {
        reset(cell);
    }
    until(
        Duration::from_secs(30),
        "status shows the log lines lost",
        || {
            status_while_full = status(cell);
            shown_lost(&status_while_full).is_some_and(|(_, lines)| lines == 2 * RESETS_WHILE_FULL)
        },
    );
    let trace = dir.join("rec.csv");
    let lines_at_removal = whole_lines(&trace);
    std::fs::remove_file(filler).unwrap();
    until(Duration::from_secs(60), "the trace grows again", || {
        whole_lines(&trace) > lines_at_removal + 1000
    });
    for _ in 0..RESETS_AFTER {
        reset(cell);
    }
    until(
        Duration::from_secs(30),
        "the log lines after are written",
        || whole_lines(&dir.join("rec.log")) as u64 == 2 * RESETS_AFTER,
    );
    Run {
        lines_at_removal,
        status_while_full,
    }
}

/// The disk fills, rows are lost and counted, the trace never holds a partial row, recording
/// resumes when space returns; rows written + rows lost = cycles run, the gap in the time
/// column is exactly the rows lost, and `tandem up` relays the loss.
#[test]
fn a_full_record_disk_loses_whole_rows_counted_and_recording_resumes() {
    let scratch = fresh_dir(&format!("tandem-recfull-{}", std::process::id()));
    let disk = Tmpfs::mount(&scratch);
    let cell = cell(&scratch);
    let filler = disk.dir.join("filler");
    std::fs::write(&filler, vec![0u8; (DISK_BYTES - ROOM_BYTES) as usize]).unwrap();
    let trace = disk.dir.join("rec.csv");

    let up =
        Spawned::start(tandem_testkit::tandem::up(tandem(), &cell, &disk.dir).arg("--no-gateway"));
    let result = std::panic::catch_unwind(|| fill_and_free(&cell, &filler, &disk.dir));
    // It may have ended already (then its status says why below).
    let _ = tandem_rt::send_signal(up.id(), libc::SIGTERM);
    let (stopped, up_log) = up.wait(Duration::from_secs(30), "tandem up after SIGTERM");
    let ran = match result {
        Ok(r) => r,
        Err(e) => {
            eprintln!("tandem up said:\n{up_log}");
            std::panic::resume_unwind(e);
        }
    };
    assert!(stopped.success(), "{stopped}\n{up_log}");
    assert!(!up_log.contains("panicked"), "{up_log}");
    assert!(!up_log.contains("crashed"), "{up_log}");

    // The node's end report, relayed by `tandem up`.
    let stopped_line = line_with(&up_log, &["[rec]", "stopped after "]);
    let cycles = number_after(stopped_line, "stopped after ");
    let dropped = number_after(stopped_line, "trace_dropped=");
    let ended = line_with(&up_log, &["[rec]", "recording ended: ", "rec.csv"]);
    let written = number_after(ended, "rec.csv: ");
    let lost = number_after(ended, "trace rows written, ");
    let total = line_with(&up_log, &["[rec]", "recording lost ", "in this run"]);
    assert_eq!(number_after(total, "recording lost "), lost, "{total}");
    // Losing began and ended once, each said with its count, relayed by `tandem up`.
    let began = line_with(
        &up_log,
        &["[rec]", "recording lost ", "trace rows (disk full)"],
    );
    assert!(began.contains("WARN"), "{began}");
    let resumed = line_with(&up_log, &["[rec]", "recording resumed: ", "rec.csv"]);
    assert!(resumed.contains(&format!("({lost} in all)")), "{resumed}");
    // The health while the disk was full, as `tandem status` shows it.
    let (shown, _) = shown_lost(&ran.status_while_full).unwrap();
    assert!(shown >= 1000 && shown <= lost, "{shown} of {lost}");

    // The log: the lines of the commands while the disk was full lost and counted (apart
    // from the ring's `log_dropped`), those after it written whole.
    let log_ended = line_with(&up_log, &["[rec]", "recording ended: ", "rec.log"]);
    let lines_written = number_after(log_ended, "rec.log: ");
    let lines_lost = number_after(log_ended, "log lines written, ");
    assert_eq!(lines_lost, 2 * RESETS_WHILE_FULL, "{log_ended}");
    assert_eq!(lines_written, 2 * RESETS_AFTER, "{log_ended}");
    assert_eq!(
        number_after(stopped_line, "log_dropped="),
        0,
        "{stopped_line}"
    );
    assert_eq!(
        number_after(total, "trace rows and "),
        lines_lost,
        "{total}"
    );
    line_with(
        &up_log,
        &["[rec]", "recording lost ", "log lines (disk full)"],
    );
    let log = std::fs::read_to_string(disk.dir.join("rec.log")).unwrap();
    assert!(log.ends_with('\n'), "{log}");
    assert_eq!(log.lines().count() as u64, lines_written, "{log}");
    for l in log.lines() {
        tandem_testkit::node_log::log_time(l);
        assert!(l.contains("slide MC_Reset job "), "{l}");
    }

    // Whole rows only: each line has every column, and each parses.
    let bytes = std::fs::read(&trace).unwrap();
    assert_eq!(bytes.last(), Some(&b'\n'), "the trace ends in a whole row");
    let csv = String::from_utf8(bytes).unwrap();
    let mut lines = csv.lines();
    let columns = lines.next().unwrap().split(',').count();
    assert_eq!(columns, 14, "time_s and the 13 columns of one axis");
    let mut times = Vec::new();
    for (i, l) in lines.enumerate() {
        let f: Vec<&str> = l.split(',').collect();
        assert_eq!(f.len(), columns, "row {i} has {} columns: {l:?}", f.len());
        let t: f64 = f[0]
            .parse()
            .unwrap_or_else(|e| panic!("row {i}: {l:?}: {e}"));
        assert!(
            f[1].chars().all(|c| c.is_ascii_alphabetic()),
            "row {i}: {l:?}"
        );
        for x in &f[2..13] {
            x.parse::<f64>()
                .unwrap_or_else(|e| panic!("row {i}: {x:?} in {l:?}: {e}"));
        }
        times.push((t * 1e9).round() as i64);
    }
    let present = times.len() as u64;
    assert_eq!(present, written, "rows in the file = rows the node wrote");
    assert!(lost > 0, "the disk was full: rows were lost");
    assert_eq!(
        present + lost + dropped,
        cycles,
        "rows present {present} + lost {lost} + dropped by a late recorder {dropped} = cycles"
    );

    // The time column: one row per cycle, but for the gap where rows were lost.
    let gaps: Vec<(usize, i64)> = times
        .windows(2)
        .enumerate()
        .filter(|(_, w)| w[1] - w[0] != CYCLE_NS)
        .map(|(i, w)| (i + 1, (w[1] - w[0]) / CYCLE_NS - 1))
        .collect();
    assert!(
        times
            .windows(2)
            .all(|w| (w[1] - w[0]) % CYCLE_NS == 0 && w[1] > w[0]),
        "times on the cycle grid, increasing"
    );
    let missing: i64 = gaps.iter().map(|g| g.1).sum();
    assert_eq!(
        missing as u64,
        lost + dropped,
        "the gaps {gaps:?} are the rows lost"
    );
    if dropped == 0 {
        assert_eq!(gaps.len(), 1, "one gap, where the disk was full: {gaps:?}");
    }
    // The rows after the gap were written after the filler was removed: it resumed.
    let (gap_at, _) = *gaps.iter().max_by_key(|g| g.1).unwrap();
    assert!(
        gap_at < ran.lines_at_removal && present as usize > ran.lines_at_removal,
        "the gap (row {gap_at}) lies before the rows written after the filler was removed \
         (from row {})",
        ran.lines_at_removal
    );
    println!(
        "cycles {cycles}: {present} rows in the trace, {lost} lost to the full disk \
         (status showed {shown} while full), {dropped} dropped; gap of {missing} rows at row \
         {gap_at}, resumed at t = {:.3} s; log lines: {lines_written} written, {lines_lost} \
         lost",
        times[gap_at] as f64 * 1e-9
    );
    drop(disk);
}
