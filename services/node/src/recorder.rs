//! The recorder thread: writes the trace rows and the log file, emits the cyclic thread's
//! diagnostic records (log lines, job events) as `tracing` events — the cyclic thread itself
//! never calls `tracing` — and stores the changed retained data ([`crate::retain`]), which
//! waits for the disk.

use crate::cycle::Row;
use crate::logring::{DiagRecord, Record};
use crate::retain::Retainer;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, SyncSender};
use std::sync::Arc;
use std::time::Duration;
use tandem_config::Cell;
use tandem_protocol::json::error_id_text;
use tandem_protocol::wire::{EVENT_LOG, JOB_ERROR};
use tandem_runtime::exec::Secs;
use tandem_runtime::sim::AXIS_COLUMNS;
use tracing::{debug, error, warn};

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
}

/// Runs until `stop`, then drains what is left.
pub(crate) fn recorder_thread(cell: &Cell, plan: &RecorderPlan, stop: &AtomicBool) {
    if let Err(e) = record(cell, plan, stop) {
        error!(error = %e, "recorder stopped: the trace or log is incomplete");
    }
}

/// Creates a file for buffered writing, naming it in the error.
fn create(p: &Path) -> io::Result<BufWriter<File>> {
    File::create(p)
        .map(BufWriter::new)
        .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", p.display())))
}

/// Writes the trace's header: `time_s` and every column of every axis.
fn header(w: &mut impl Write, cell: &Cell, owned: &[usize]) -> io::Result<()> {
    write!(w, "time_s")?;
    for a in owned {
        for c in AXIS_COLUMNS {
            write!(w, ",{}.{c}", cell.axes[*a].name)?;
        }
    }
    writeln!(w)
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
fn record(cell: &Cell, plan: &RecorderPlan, stop: &AtomicBool) -> io::Result<()> {
    let mut trace = plan.trace.as_deref().map(create).transpose()?;
    let mut log = plan.log.as_deref().map(create).transpose()?;
    if let Some(w) = trace.as_mut() {
        header(w, cell, &plan.owned)?;
    }
    let names = cell.object_names();
    let mut retainer = Retainer::new(plan.retained.clone());
    let (rows, free) = &plan.rows;
    loop {
        let stopping = stop.load(Ordering::SeqCst);
        while let Ok((t, row)) = rows.try_recv() {
            if let Some(w) = trace.as_mut() {
                tandem_runtime::sim::write_row(w, t, &row, &[], "")?;
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
            if let (Some(w), EVENT_LOG) = (log.as_mut(), r.event.kind) {
                writeln!(w, "{}", r.event.message.as_str())?;
            }
        }
        retainer.flush(cell);
        if stopping {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    if let Some(w) = trace.as_mut() {
        w.flush()?;
    }
    if let Some(w) = log.as_mut() {
        w.flush()?;
    }
    Ok(())
}
