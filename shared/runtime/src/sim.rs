//! The deterministic simulator: every axis of a cell steps at its node's cycle on a virtual
//! clock; script commands are applied between cycles at their times; every signal of every
//! axis is written to CSV every base tick. The same inputs give byte-identical output.
//!
//! It runs one [`Executive`] that owns the whole cell, the same code a node runs for its part
//! of the cell, so leading-value delays act as they do between processes.

pub use crate::error::SimError;
use crate::exec::Executive;
pub use crate::notes::{seconds, Secs};
use std::io::{self, Write};
use tandem_config::script::Script;
use tandem_config::Cell;
use tandem_motion::objects::axis::AxisStatus;
use tandem_motion::objects::encoder::EncoderStatus;

/// The per-axis columns of the trace, in order (prefixed with `<axis>.`).
pub const AXIS_COLUMNS: &[&str] = &[
    "state",
    "position",
    "velocity",
    "acceleration",
    "actual_position",
    "actual_velocity",
    "following_error",
    "status_word",
    "error_word",
    "warning_word",
    "alarm",
    "override",
    "job",
];

/// The per-encoder columns of the trace, in order (prefixed with `<encoder>.`).
pub const ENCODER_COLUMNS: &[&str] = &[
    "state",
    "position",
    "velocity",
    "extrapolated_position",
    "extrapolated_velocity",
    "status_word",
];

/// What a run did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Summary {
    /// Trace rows written.
    pub rows: u64,
    /// Script commands applied.
    pub commands: usize,
    /// Script commands rejected with an ErrorID.
    pub rejected: usize,
    /// Axes with a pending technology alarm at the end.
    pub axes_in_alarm: usize,
}

/// Writes one trace row: the time, each axis and encoder, then the objects' columns.
pub fn write_row(
    out: &mut impl Write,
    t_ns: i64,
    status: &[AxisStatus],
    encoders: &[EncoderStatus],
    objects: &str,
) -> io::Result<()> {
    write!(out, "{}", Secs(t_ns))?;
    for s in status {
        let job = s
            .motion_job
            .or(s.sync_job)
            .map(|(_, i)| i.name())
            .unwrap_or("");
        write!(
            out,
            ",{},{},{},{},{},{},{},{},{},{},{},{},{}",
            s.state.name(),
            s.position,
            s.velocity,
            s.acceleration,
            s.actual_position,
            s.actual_velocity,
            s.following_error,
            s.status_word,
            s.error_word,
            s.warning_word,
            s.error_detail.number,
            s.override_velocity,
            job
        )?;
    }
    for e in encoders {
        let state = if e.has(tandem_motion::catalog::alarm::status_bit::ENABLE) {
            "Enabled"
        } else {
            "Disabled"
        };
        write!(
            out,
            ",{},{},{},{},{},{}",
            state,
            e.position,
            e.velocity,
            e.extrapolated.position,
            e.extrapolated.velocity,
            e.status_word
        )?;
    }
    writeln!(out, "{objects}")
}

/// Runs `script` on `cell`, writing the CSV trace to `trace` and a log of job events,
/// rejections and alarms to `log`. Fails when the engine refuses the cell or a write fails.
pub fn run(
    cell: &Cell,
    script: &Script,
    trace: &mut impl Write,
    log: &mut impl Write,
) -> Result<Summary, SimError> {
    let mut exec = Executive::new(cell, None)?;
    let tick = exec.tick_ns();
    write!(trace, "time_s")?;
    for a in &cell.axes {
        for c in AXIS_COLUMNS {
            write!(trace, ",{}.{c}", a.name)?;
        }
    }
    for e in &cell.encoders {
        for c in ENCODER_COLUMNS {
            write!(trace, ",{}.{c}", e.name)?;
        }
    }
    Executive::objects_header(cell, trace)?;
    writeln!(trace)?;
    let mut summary = Summary::default();
    let mut next = 0;
    let mut k: i64 = 0;
    loop {
        let t = k * tick;
        if t > script.duration_ns {
            break;
        }
        while let Some(e) = script.entries.get(next).filter(|e| e.t_ns <= t) {
            next += 1;
            // A rejection is in the log and the summary; a failed write of it is an error.
            let _ = exec.apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, log)?;
        }
        exec.step(t, log)?;
        // The log has every event; the notes are for a node's services.
        exec.drain_job_notes(|_| {});
        exec.drain_io_notes(|_| {});
        let (status, encoders) = (exec.status().to_vec(), exec.encoder_status().to_vec());
        write_row(trace, t, &status, &encoders, exec.objects_row())?;
        summary.rows += 1;
        k += 1;
    }
    summary.commands = exec.commands;
    summary.rejected = exec.rejected;
    summary.axes_in_alarm = exec.axes_in_alarm();
    Ok(summary)
}
