//! The recorder thread: writes the trace rows and the log file, emits the cyclic thread's
//! diagnostic records (log lines, job events) as `tracing` events — the cyclic thread itself
//! never calls `tracing` — and stores the changed retained data ([`crate::retain`]), which
//! waits for the disk.
//!
//! Nothing is lost silently and no row or line is ever partly written (docs/processes.md,
//! "Recording on a full disk"): each loop turn (every [`IDLE_TURN_MS`] ms, or sooner when
//! the cyclic thread [`Wake`]s it) formats the rows and lines it
//! drained into one reused buffer per file ([`Sink`]) and writes it unbuffered at the file's
//! committed length, the end of its last whole row. When a write fails (a full disk: ENOSPC,
//! or any other error), the rows that reached the disk whole are kept, a row written in part
//! is cut off again (`set_len` back to the last whole row), and the rest of the turn's rows
//! are lost and counted exactly ([`Lost`], in the node's health and its end report). The
//! next turn tries again with its own rows, so recording resumes by itself when space
//! returns; there is no backlog (rows that arrive while the disk is full are lost, not
//! kept). Losing and resuming are each a `warn` event with the counts.

use crate::logring::{DiagRecord, Record, DIAG_RECORDS};
use crate::retain::Retainer;
use std::fs::File;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, SyncSender};
use std::sync::Arc;
use std::time::Duration;
use tandem_config::Cell;
use tandem_motion::objects::axis::AxisStatus;
use tandem_protocol::json::error_id_text;
use tandem_protocol::wire::{NodeHealth, EVENT_LOG, JOB_ERROR};
use tandem_runtime::exec::Secs;
use tandem_runtime::sim::AXIS_COLUMNS;
use tracing::{debug, info, warn};

/// A trace row: the cycle's time and the status of every owned axis.
pub(crate) type Row = (i64, Vec<AxisStatus>);

/// The rows the cyclic thread fills and the recorder thread writes, without allocating: a
/// row comes from `free`, goes out on `full`, and comes back to `free` once written.
#[derive(Debug)]
pub(crate) struct RowPool {
    /// Empty rows.
    pub(crate) free: Receiver<Row>,
    /// Filled rows, to the recorder.
    pub(crate) full: SyncSender<Row>,
}

/// What the recorder writes and where its records come from.
#[derive(Debug)]
pub(crate) struct RecorderPlan {
    /// The CSV trace file, if any.
    pub(crate) trace: Option<PathBuf>,
    /// The log file, if any.
    pub(crate) log: Option<PathBuf>,
    /// The axes of the node (the trace's columns).
    pub(crate) owned: Vec<usize>,
    /// Filled trace rows, and the pool to give them back to.
    pub(crate) rows: (Receiver<Row>, SyncSender<Row>),
    /// The cyclic thread's diagnostic records and changed retained data.
    pub(crate) diag: Receiver<Record>,
    /// Where the retained data is stored, if the node has any.
    pub(crate) retained: Option<Arc<tandem_rt::retain::RetainStore>>,
    /// The recorder's counts of what it could not write (shared with the cyclic thread).
    pub(crate) lost: Arc<Lost>,
}

/// Trace rows and log lines the recorder could not write to the disk, counted exactly; the
/// recorder adds, the cyclic thread copies them into the node's health, `run` into the report.
#[derive(Debug, Default)]
pub(crate) struct Lost {
    /// Trace rows lost.
    pub(crate) rows: AtomicU64,
    /// Log lines lost.
    pub(crate) lines: AtomicU64,
}

impl Lost {
    /// Copies the counts into the node's health (two relaxed loads: no lock, no wait).
    pub(crate) fn copy_into(&self, h: &mut NodeHealth) {
        h.trace_rows_lost = self.rows.load(Ordering::Relaxed);
        h.log_lines_lost = self.lines.load(Ordering::Relaxed);
    }
}

/// The recorder's turn when the cyclic thread does not wake it (ms): each turn is a wake-up
/// of a sleeping thread (20 to 35 µs of CPU on the project's 2-CPU VM, bench axes), so
/// the recorder sleeps long and the cyclic thread wakes it when its channels fill
/// (docs/processes.md, "Performance").
pub(crate) const IDLE_TURN_MS: u64 = 20;

/// Diagnostic records handed over since the last wake-up at which the cyclic thread wakes
/// the recorder: a quarter of the channel ([`DIAG_RECORDS`]), so that the recorder drains it
/// long before it is full (a full log ring and job events are at most 384 records a cycle).
const WAKE_RECORDS: u32 = (DIAG_RECORDS / 4) as u32;

/// Trace rows handed over since the last wake-up at which the cyclic thread wakes the
/// recorder: a quarter of the smallest row pool.
const WAKE_ROWS: u32 = (crate::TRACE_ROWS_MIN / 4) as u32;

/// The cyclic thread's side of the recorder's sleep: counts what it handed over and wakes
/// the recorder ([`std::thread::Thread::unpark`]: an atomic swap, a futex wake only when the
/// recorder sleeps; no lock, no allocation) when that could fill a channel before the
/// recorder's next idle turn, or at once for retained data.
#[derive(Debug)]
pub(crate) struct Wake {
    recorder: std::thread::Thread,
    /// Records handed over since the last wake-up.
    records: u32,
    /// Trace rows handed over since the last wake-up.
    rows: u32,
}

impl Wake {
    /// The waker of the recorder thread `recorder`.
    pub(crate) fn new(recorder: std::thread::Thread) -> Self {
        Self {
            recorder,
            records: 0,
            rows: 0,
        }
    }

    /// `n` more diagnostic records handed over.
    pub(crate) fn records(&mut self, n: u32) {
        self.records = self.records.saturating_add(n);
        if self.records >= WAKE_RECORDS {
            self.now();
        }
    }

    /// `n` more trace rows handed over.
    pub(crate) fn rows(&mut self, n: u32) {
        self.rows = self.rows.saturating_add(n);
        if self.rows >= WAKE_ROWS {
            self.now();
        }
    }

    /// Wakes the recorder now: it drains everything handed over before it runs, so the counts
    /// start again (a bound on what its channels hold).
    pub(crate) fn now(&mut self) {
        self.recorder.unpark();
        self.records = 0;
        self.rows = 0;
    }
}

/// Runs until `stop`, then drains what is left.
pub(crate) fn recorder_thread(cell: &Cell, plan: &RecorderPlan, stop: &AtomicBool) {
    record(cell, plan, stop);
}

/// A file a [`Sink`] writes, or a test's disk.
trait Store: Sized {
    /// Creates (truncates) the file at `p`.
    fn open(p: &Path) -> io::Result<Self>;
    /// Writes at `offset`; returns the bytes written (maybe fewer than `buf` holds).
    fn write_at(&self, buf: &[u8], offset: u64) -> io::Result<usize>;
    /// Cuts the file to `len` bytes.
    fn set_len(&self, len: u64) -> io::Result<()>;
}

impl Store for File {
    fn open(p: &Path) -> io::Result<Self> {
        File::create(p)
    }

    fn write_at(&self, buf: &[u8], offset: u64) -> io::Result<usize> {
        std::os::unix::fs::FileExt::write_at(self, buf, offset)
    }

    fn set_len(&self, len: u64) -> io::Result<()> {
        File::set_len(self, len)
    }
}

/// Writes `buf` to `store` at `offset`; returns the bytes written and the error that stopped
/// it before the end, if one did.
fn write_from(store: &impl Store, buf: &[u8], offset: u64) -> (usize, Option<io::Error>) {
    let mut done = 0usize;
    while let Some(rest) = buf.get(done..).filter(|r| !r.is_empty()) {
        match store.write_at(rest, offset + done as u64) {
            Ok(0) => return (done, Some(io::ErrorKind::WriteZero.into())),
            Ok(k) => done += k,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return (done, Some(e)),
        }
    }
    (done, None)
}

/// A file of whole units (trace rows or log lines) written in batches, never a unit in part;
/// what could not be written is counted (module documentation).
struct Sink<S> {
    /// `trace rows` or `log lines`, for the messages.
    unit: &'static str,
    path: PathBuf,
    /// The open file; `None` until it could be created.
    store: Option<S>,
    /// The bytes before the first unit (the trace's header), and whether they are written.
    header: Vec<u8>,
    header_done: bool,
    /// The file's length up to the end of its last whole unit.
    committed: u64,
    /// Cutting back a partly written unit failed: the file may be longer than `committed`.
    torn: bool,
    /// This turn's units, formatted (allocated once, reused).
    batch: Vec<u8>,
    /// The end of each unit in `batch`.
    ends: Vec<usize>,
    /// Units written and lost so far.
    written: u64,
    lost: u64,
    /// While losing: the units lost since it began.
    losing: Option<u64>,
}

/// Bytes a sink's batch buffer starts with (a turn of 5 ms of a node with a few axes).
const BATCH_BYTES: usize = 64 * 1024;

/// Units a sink's batch starts with room for (the trace rows' pool holds 256).
const BATCH_UNITS: usize = 512;

impl<S: Store> Sink<S> {
    /// A sink for `path` writing `header` before its first unit; nothing is opened yet.
    fn new(unit: &'static str, path: &Path, header: Vec<u8>) -> Self {
        Self {
            unit,
            path: path.to_path_buf(),
            store: None,
            header,
            header_done: false,
            committed: 0,
            torn: false,
            batch: Vec::with_capacity(BATCH_BYTES),
            ends: Vec::with_capacity(BATCH_UNITS),
            written: 0,
            lost: 0,
            losing: None,
        }
    }

    /// Adds one unit to this turn's batch: `f` appends it, whole, to the buffer.
    fn push(&mut self, f: impl FnOnce(&mut Vec<u8>)) {
        f(&mut self.batch);
        self.ends.push(self.batch.len());
    }

    /// Makes the file ready for the next unit: created, cut back to its committed length if a
    /// cut failed before, the header written.
    fn prepare(&mut self) -> io::Result<()> {
        if self.store.is_none() {
            self.store = Some(S::open(&self.path)?);
            self.committed = 0;
            self.header_done = false;
            self.torn = false;
        }
        let Some(store) = &self.store else {
            return Err(io::ErrorKind::NotFound.into());
        };
        if self.torn {
            store.set_len(self.committed)?;
            self.torn = false;
        }
        if !self.header_done {
            if let (_, Some(e)) = write_from(store, &self.header, 0) {
                self.torn = store.set_len(0).is_err();
                return Err(e);
            }
            self.header_done = true;
            self.committed = self.header.len() as u64;
        }
        Ok(())
    }

    /// Writes the batch at the committed length: returns the units that reached the file
    /// whole (a unit written in part is cut off again) and the error that stopped the rest.
    fn write_batch(&mut self) -> (usize, Option<io::Error>) {
        if let Err(e) = self.prepare() {
            return (0, Some(e));
        }
        let Some(store) = &self.store else {
            return (0, Some(io::ErrorKind::NotFound.into()));
        };
        let (done, error) = write_from(store, &self.batch, self.committed);
        let whole = self.ends.partition_point(|end| *end <= done);
        let keep = whole
            .checked_sub(1)
            .and_then(|i| self.ends.get(i))
            .copied()
            .unwrap_or(0);
        if keep < done {
            self.torn = store.set_len(self.committed + keep as u64).is_err();
        }
        self.committed += keep as u64;
        (whole, error)
    }

    /// Writes this turn's units; counts those that could not be written into `total` (and
    /// says so when losing begins and when it ends).
    fn flush(&mut self, total: &AtomicU64) {
        let units = self.ends.len();
        if units == 0 {
            return;
        }
        let (whole, error) = self.write_batch();
        self.batch.clear();
        self.ends.clear();
        self.written += whole as u64;
        let lost = units.saturating_sub(whole) as u64;
        if lost == 0 {
            self.resumed();
            return;
        }
        self.lost += lost;
        total.fetch_add(lost, Ordering::Relaxed);
        match self.losing.as_mut() {
            Some(n) => *n += lost,
            None => {
                self.losing = Some(lost);
                let e = error.unwrap_or_else(|| io::ErrorKind::Other.into());
                let why = match e.kind() {
                    io::ErrorKind::StorageFull => "disk full",
                    io::ErrorKind::QuotaExceeded => "disk quota exceeded",
                    _ => "write error",
                };
                warn!(
                    file = %self.path.display(),
                    lost,
                    total = self.lost,
                    error = %e,
                    "recording lost {lost} {} ({why}): {}: {e}; what arrives while writing \
                     fails is lost and counted, recording resumes when it can write",
                    self.unit,
                    self.path.display()
                );
            }
        }
    }

    /// A batch was written whole: if it was losing, says that it resumed and what it lost.
    fn resumed(&mut self) {
        if let Some(lost) = self.losing.take() {
            warn!(
                file = %self.path.display(),
                lost,
                total = self.lost,
                "recording resumed: {}: {lost} {} lost while writing failed ({} in all)",
                self.path.display(),
                self.unit,
                self.lost
            );
        }
    }

    /// The end of the recording: what was written and lost.
    fn end(&self) {
        info!(
            file = %self.path.display(),
            written = self.written,
            lost = self.lost,
            "recording ended: {}: {} {} written, {} lost to the disk",
            self.path.display(),
            self.written,
            self.unit,
            self.lost
        );
    }
}

/// A sink for `path`, its file created now (a failure is a warning: it is tried again with
/// each batch).
fn open(unit: &'static str, path: &Path, header: Vec<u8>) -> Sink<File> {
    let mut s = Sink::new(unit, path, header);
    if let Err(e) = s.prepare() {
        warn!(file = %path.display(), error = %e, "cannot start {}: {e}; trying again with each batch", path.display());
    }
    s
}

/// The trace's header: `time_s` and every column of every axis.
fn header(cell: &Cell, owned: &[usize]) -> Vec<u8> {
    let mut h = String::from("time_s");
    for a in owned {
        let name = cell.axes.get(*a).map_or("?", |x| x.name.as_str());
        for c in AXIS_COLUMNS {
            h.push(',');
            h.push_str(name);
            h.push('.');
            h.push_str(c);
        }
    }
    h.push('\n');
    h.into_bytes()
}

/// Emits one record as a `tracing` event: a job that ended in error at `warn` with its
/// ErrorID and alarm, other job events and log lines at `debug` (they also reach observers and
/// `tandem up` as iceoryx2 events).
fn emit(names: &[&str], r: &DiagRecord) {
    let e = &r.event;
    let message = e.message.as_str();
    if e.kind == EVENT_LOG {
        debug!(target: "tandem_node::log", t = %Secs(e.t_ns), "{message}");
        return;
    }
    let object = names.get(e.object as usize).copied().unwrap_or("?");
    if e.code == JOB_ERROR {
        warn!(
            target: "tandem_node::job",
            t = %Secs(e.t_ns),
            object,
            job = e.job,
            error_id = %error_id_text(e.error_id),
            alarm = r.alarm,
            "{message}"
        );
    } else {
        debug!(target: "tandem_node::job", t = %Secs(e.t_ns), object, job = e.job, "{message}");
    }
}

/// The recorder's loop.
fn record(cell: &Cell, plan: &RecorderPlan, stop: &AtomicBool) {
    let mut trace = plan
        .trace
        .as_deref()
        .map(|p| open("trace rows", p, header(cell, &plan.owned)));
    let mut log = plan
        .log
        .as_deref()
        .map(|p| open("log lines", p, Vec::new()));
    let names = cell.object_names();
    let mut retainer = Retainer::new(plan.retained.clone());
    let (rows, free) = &plan.rows;
    loop {
        let stopping = stop.load(Ordering::SeqCst);
        while let Ok((t, row)) = rows.try_recv() {
            if let Some(s) = trace.as_mut() {
                s.push(|b| {
                    // Writing into a Vec cannot fail.
                    let _ = tandem_runtime::sim::write_row(b, t, &row, &[], "");
                });
            }
            // The pool's channel holds every row there is: giving one back always fits.
            let _ = free.try_send((t, row));
        }
        while let Ok(r) = plan.diag.try_recv() {
            let r = match r {
                Record::Diag(r) => r,
                Record::Retain(change) => {
                    retainer.push(change);
                    continue;
                }
            };
            emit(&names, &r);
            if let (Some(s), EVENT_LOG) = (log.as_mut(), r.event.kind) {
                s.push(|b| {
                    b.extend_from_slice(r.event.message.as_str().as_bytes());
                    b.push(b'\n');
                });
            }
        }
        if let Some(s) = trace.as_mut() {
            s.flush(&plan.lost.rows);
        }
        if let Some(s) = log.as_mut() {
            s.flush(&plan.lost.lines);
        }
        retainer.flush(cell);
        if stopping {
            break;
        }
        // Woken early by the cyclic thread ([`Wake`]) or at `stop`; a spurious wake-up is an
        // early turn.
        std::thread::park_timeout(Duration::from_millis(IDLE_TURN_MS));
    }
    for s in [trace.as_ref(), log.as_ref()].into_iter().flatten() {
        s.end();
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
    use super::*;
    use std::cell::{Cell as Shared, RefCell};
    use std::rc::Rc;

    /// A disk with room for `room` bytes of file: a write beyond it is cut short, the next
    /// one fails with ENOSPC (as a full tmpfs does).
    #[derive(Default)]
    struct Disk {
        data: RefCell<Vec<u8>>,
        room: Shared<usize>,
        cuts: Shared<usize>,
    }

    impl Store for Rc<Disk> {
        fn open(_: &Path) -> io::Result<Self> {
            Err(io::ErrorKind::Unsupported.into())
        }

        fn write_at(&self, buf: &[u8], offset: u64) -> io::Result<usize> {
            let mut d = self.data.borrow_mut();
            let at = usize::try_from(offset).unwrap();
            let n = buf.len().min(self.room.get().saturating_sub(at));
            if n == 0 {
                return Err(io::ErrorKind::StorageFull.into());
            }
            if d.len() < at + n {
                d.resize(at + n, 0);
            }
            d[at..at + n].copy_from_slice(&buf[..n]);
            Ok(n)
        }

        fn set_len(&self, len: u64) -> io::Result<()> {
            self.cuts.set(self.cuts.get() + 1);
            self.data
                .borrow_mut()
                .resize(usize::try_from(len).unwrap(), 0);
            Ok(())
        }
    }

    /// The cyclic thread wakes the recorder when it handed over a quarter of the diagnostic
    /// channel or of the smallest row pool since the last wake-up, and counts again from
    /// there; below that the recorder's idle turn drains the channels.
    #[test]
    fn the_recorder_is_woken_at_a_quarter_of_its_channels() {
        assert_eq!(WAKE_RECORDS, 1024);
        assert_eq!(WAKE_ROWS, 64);
        let mut w = Wake::new(std::thread::current());
        w.records(WAKE_RECORDS - 1);
        w.rows(WAKE_ROWS - 1);
        assert_eq!((w.records, w.rows), (WAKE_RECORDS - 1, WAKE_ROWS - 1));
        w.records(1);
        assert_eq!(
            (w.records, w.rows),
            (0, 0),
            "woken: both counts start again"
        );
        w.rows(WAKE_ROWS - 1);
        w.rows(1);
        assert_eq!(w.rows, 0);
        w.records(3);
        w.now();
        assert_eq!(w.records, 0);
    }

    fn sink(disk: &Rc<Disk>) -> Sink<Rc<Disk>> {
        let mut s = Sink::new("trace rows", Path::new("t.csv"), b"h\n".to_vec());
        s.store = Some(Rc::clone(disk));
        s
    }

    /// Pushes rows `from..to`, each `row <i>` padded to 10 bytes, and flushes.
    fn turn(s: &mut Sink<Rc<Disk>>, rows: std::ops::Range<u32>, lost: &AtomicU64) {
        for i in rows {
            s.push(|b| b.extend_from_slice(format!("row {i:05}\n").as_bytes()));
        }
        s.flush(lost);
    }

    /// A disk filling up mid-batch: the whole rows stay, the partial one is cut off, the rest
    /// and every row of the full turns are counted lost; with room again it resumes; the file
    /// holds whole rows only, and written + lost = pushed.
    #[test]
    fn a_full_disk_loses_whole_rows_counted_and_recording_resumes() {
        let disk = Rc::new(Disk::default());
        disk.room.set(2 + 10 * 25 + 4); // the header, 25 rows and 4 bytes of the 26th
        let lost = AtomicU64::new(0);
        let mut s = sink(&disk);
        turn(&mut s, 0..20, &lost);
        assert_eq!(
            (s.written, s.lost, lost.load(Ordering::Relaxed)),
            (20, 0, 0)
        );
        turn(&mut s, 20..30, &lost); // 5 fit, the 6th in part
        assert_eq!((s.written, s.lost), (25, 5));
        assert_eq!(disk.cuts.get(), 1, "the partial row was cut off");
        assert_eq!(disk.data.borrow().len(), 2 + 250);
        turn(&mut s, 30..40, &lost); // full: all lost
        assert_eq!((s.written, s.lost, s.losing), (25, 15, Some(15)));
        disk.room.set(1 << 20);
        turn(&mut s, 40..45, &lost);
        assert_eq!((s.written, s.lost, s.losing), (30, 15, None));
        assert_eq!(lost.load(Ordering::Relaxed), 15);
        let text = String::from_utf8(disk.data.borrow().clone()).unwrap();
        let rows: Vec<&str> = text.lines().skip(1).collect();
        assert_eq!(rows.len(), 30);
        assert!(rows.iter().all(|r| r.len() == 9 && r.starts_with("row ")));
        assert_eq!(rows[24], "row 00024");
        assert_eq!(rows[25], "row 00040", "the gap is where the rows were lost");
    }

    /// A disk full from the start: the header is written once there is room, before the
    /// first row; the rows before are lost and counted.
    #[test]
    fn the_header_waits_for_room() {
        let disk = Rc::new(Disk::default());
        let lost = AtomicU64::new(0);
        let mut s = sink(&disk);
        turn(&mut s, 0..3, &lost);
        assert_eq!((s.written, lost.load(Ordering::Relaxed)), (0, 3));
        disk.room.set(1); // half the header
        turn(&mut s, 3..4, &lost);
        assert!(
            disk.data.borrow().is_empty(),
            "a partial header was cut off"
        );
        disk.room.set(100);
        turn(&mut s, 4..6, &lost);
        assert_eq!(&disk.data.borrow()[..], b"h\nrow 00004\nrow 00005\n");
        assert_eq!((s.written, s.lost), (2, 4));
    }
}
