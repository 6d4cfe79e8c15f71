//! What a step reports besides its log: job events and I/O notes for a node to publish, kept
//! in fixed-capacity lists, and the log's formatting of times and job events.

use std::fmt;
use tandem_motion::objects::job::{Instruction, JobEventKind, JobId};

/// Formats ns as seconds with 9 decimals, exactly.
pub fn seconds(t_ns: i64) -> String {
    Secs(t_ns).to_string()
}

/// ns shown as seconds with 9 decimals, exactly, without allocating.
#[derive(Copy, Clone, Debug)]
pub struct Secs(pub i64);

impl fmt::Display for Secs {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sign = if self.0 < 0 { "-" } else { "" };
        let t = self.0.unsigned_abs();
        write!(f, "{sign}{}.{:09}", t / 1_000_000_000, t % 1_000_000_000)
    }
}

/// A job event kind as the log shows it.
#[derive(Copy, Clone, Debug)]
pub struct Describe(pub JobEventKind);

impl fmt::Display for Describe {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            JobEventKind::Error(e) => write!(f, "Error {e}"),
            JobEventKind::Status(on) => write!(f, "Status {}", if on { "TRUE" } else { "FALSE" }),
            other => write!(f, "{other:?}"),
        }
    }
}

/// A job event of an axis or encoder, for the node to publish.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct JobNote {
    /// When (ns).
    pub t_ns: i64,
    /// The object: its index in [`tandem_config::Cell::object_names`] (axes, then encoders,
    /// as [`tandem_config::Cell::leader_id`] numbers them).
    pub object: usize,
    /// The job.
    pub job: JobId,
    /// The instruction.
    pub instruction: Instruction,
    /// What happened.
    pub kind: JobEventKind,
}

/// What an output cam, cam track or measuring input did, for the node to publish.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct IoNote {
    /// The object: output cams, then cam tracks, then measuring inputs, in cell order.
    pub object: usize,
    /// The exact time (ns).
    pub t_ns: i64,
    /// `false`: an output edge (`value` 1 on, 0 off); `true`: a measured value.
    pub measured: bool,
    /// The cam number of a cam track's edge (1-based), or the measurement counter.
    pub counter: u32,
    /// 1/0, or the measured position.
    pub value: f64,
}

/// Notes kept per step for the caller; more are dropped (and counted).
pub const NOTES: usize = 256;

/// Keeps `n` in `notes` unless the step already has [`NOTES`] of them (then counts it in
/// `dropped`): the list never grows past the capacity it was created with.
pub(crate) fn keep<T>(notes: &mut Vec<T>, dropped: &mut u64, n: T) {
    if notes.len() < NOTES {
        notes.push(n);
    } else {
        *dropped += 1;
    }
}
