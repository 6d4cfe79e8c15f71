//! The `#[repr(C)]` payloads of the iceoryx2 services (docs/processes.md, "Services"). Each carries a type name with
//! a version, so a process built from another version fails to open the service
//! (`IncompatibleTypes`) instead of misreading it.

use iceoryx2::prelude::ZeroCopySend;
use tandem_motion::kinematics::modulo::Modulo;
use tandem_motion::objects::axis::{AxisState, AxisStatus};
use tandem_motion::objects::job::JobEventKind;
use tandem_motion::objects::leading::LeadingSample;

/// [`LeadingValueSample::status`] bit: the value is valid.
pub const LV_VALID: u32 = 1;

/// One leading value of a leader (docs/processes.md, "Leading values"): at `t_ns` on the cell clock the leader was at
/// (`p`, `v`, `a`). Positions are continuous; a modulo leader sends its modulo range with them.
#[derive(Copy, Clone, Debug, PartialEq, ZeroCopySend)]
#[type_name("tandem.LeadingValueSample.v2")]
#[repr(C)]
pub struct LeadingValueSample {
    /// The time the value is valid for (ns, cell clock).
    pub t_ns: i64,
    /// Sequence number: the leader's cycle on the cell clock, `t_ns / cycle` (v2: so that it
    /// goes on increasing across restarts of the publisher; receivers refuse a sample whose
    /// number does not match its time, docs/processes.md "Refused samples").
    pub seq: u64,
    /// Position (continuous).
    pub p: f64,
    /// Velocity.
    pub v: f64,
    /// Acceleration.
    pub a: f64,
    /// Modulo start (with `modulo_length > 0`).
    pub modulo_start: f64,
    /// Modulo length; 0: not a modulo leader.
    pub modulo_length: f64,
    /// Bits: [`LV_VALID`].
    pub status: u32,
    /// The leader's index in the cell (axes, then encoders).
    pub leader: u32,
}

impl LeadingValueSample {
    /// The wire form of an engine sample of leader `leader`.
    pub fn from_sample(leader: u32, s: &LeadingSample) -> Self {
        Self {
            t_ns: s.t_ns,
            seq: s.seq,
            p: s.p,
            v: s.v,
            a: s.a,
            modulo_start: s.modulo.map_or(0.0, |m| m.start),
            modulo_length: s.modulo.map_or(0.0, |m| m.length),
            status: if s.valid { LV_VALID } else { 0 },
            leader,
        }
    }

    /// The engine form.
    pub fn to_sample(&self) -> LeadingSample {
        LeadingSample {
            t_ns: self.t_ns,
            seq: self.seq,
            p: self.p,
            v: self.v,
            a: self.a,
            modulo: (self.modulo_length > 0.0).then_some(Modulo {
                start: self.modulo_start,
                length: self.modulo_length,
            }),
            valid: self.status & LV_VALID != 0,
        }
    }
}

/// Bytes of text a command or event carries.
pub const TEXT_LEN: usize = 240;

/// Fixed-size UTF-8 text (truncated at a character boundary).
#[derive(Copy, Clone, Debug, PartialEq, Eq, ZeroCopySend)]
#[type_name("tandem.Text.v1")]
#[repr(C)]
pub struct Text {
    len: u32,
    bytes: [u8; TEXT_LEN],
}

impl Default for Text {
    fn default() -> Self {
        Self {
            len: 0,
            bytes: [0; TEXT_LEN],
        }
    }
}

impl Text {
    /// `s`, cut to [`TEXT_LEN`] bytes at a character boundary.
    pub fn new(s: &str) -> Self {
        let mut t = Self::default();
        t.push(s);
        t
    }

    /// Replaces the text (cut as in [`Text::new`]).
    pub fn set(&mut self, s: &str) {
        self.len = 0;
        self.push(s);
    }

    /// Appends `s`, cut at [`TEXT_LEN`] bytes in all at a character boundary.
    pub fn push(&mut self, s: &str) {
        let at = (self.len as usize).min(TEXT_LEN);
        let mut n = s.len().min(TEXT_LEN - at);
        while !s.is_char_boundary(n) {
            n -= 1;
        }
        self.bytes[at..at + n].copy_from_slice(&s.as_bytes()[..n]);
        self.len = (at + n) as u32;
    }

    /// The text; empty if the bytes are not UTF-8 (a foreign writer).
    pub fn as_str(&self) -> &str {
        let n = (self.len as usize).min(TEXT_LEN);
        core::str::from_utf8(&self.bytes[..n]).unwrap_or("")
    }
}

/// A command for an object of a node: `<object> <instruction> [--param value]...`, parsed by
/// the node with the script's instruction table.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ZeroCopySend)]
#[type_name("tandem.CommandRequest.v2")]
#[repr(C)]
pub struct CommandRequest {
    /// The command line.
    pub text: Text,
    /// Who sends it (v2): `tandem cmd` fills in `<user>@<machine>`, the gateway the sender a
    /// Zenoh query names; empty counts as `anonymous`. The node rates, logs and audits
    /// commands by it (docs/gateway.md, "Command rate", "Audit trail"). Not authenticated
    /// until the mTLS work binds it to the certificate subject.
    pub sender: Text,
}

/// The sender of a command with an empty [`CommandRequest::sender`].
pub const ANONYMOUS: &str = "anonymous";

/// [`CommandReply::outcome`]: accepted; an Execute-type instruction's job id is in `job`.
pub const OUTCOME_ACCEPTED: u32 = 0;
/// Rejected by the object with the ErrorID in `error_id`; its running job goes on.
pub const OUTCOME_REJECTED: u32 = 1;
/// Not understood (unknown object, instruction or parameter); `message` says what.
pub const OUTCOME_INVALID: u32 = 2;
/// The node's command queue is full; try again.
pub const OUTCOME_BUSY: u32 = 3;

/// The node's answer to a [`CommandRequest`], sent once the command was applied in a cycle.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ZeroCopySend)]
#[type_name("tandem.CommandReply.v1")]
#[repr(C)]
pub struct CommandReply {
    /// One of the `OUTCOME_*` values.
    pub outcome: u32,
    /// The job id (Execute-type instructions), else 0.
    pub job: u32,
    /// The ErrorID (`16#80xx`) with [`OUTCOME_REJECTED`].
    pub error_id: u32,
    /// The cycle time at which it was applied (ns).
    pub t_ns: i64,
    /// What went wrong, in words.
    pub message: Text,
}

/// [`Event::kind`]: a line of the node's log (text only).
pub const EVENT_LOG: u32 = 0;
/// A job event: `object`, `job`, `code`, `error_id` are set, `message` describes it.
pub const EVENT_JOB: u32 = 1;

/// [`Event::code`] of a job event: the job ended with Done.
pub const JOB_DONE: u32 = 1;
/// The job was aborted by another.
pub const JOB_ABORTED: u32 = 2;
/// The job ended with an error (`error_id`).
pub const JOB_ERROR: u32 = 3;
/// The job reached its goal and goes on: InVelocity, InGear, InSync, or an Enable-type
/// instruction's `Status` TRUE.
pub const JOB_REACHED: u32 = 4;
/// Any other event of a running job (Busy, StartSync, EndOfProfile, ...).
pub const JOB_PROGRESS: u32 = 0;

/// The code of a job event kind, and its ErrorID.
pub fn job_code(kind: JobEventKind) -> (u32, u32) {
    match kind {
        JobEventKind::Done => (JOB_DONE, 0),
        JobEventKind::CommandAborted => (JOB_ABORTED, 0),
        JobEventKind::Error(e) => (JOB_ERROR, u32::from(e.code())),
        JobEventKind::InVelocity
        | JobEventKind::InGear
        | JobEventKind::InSync
        | JobEventKind::Status(true) => (JOB_REACHED, 0),
        _ => (JOB_PROGRESS, 0),
    }
}

/// A job event or a log line of a node, as it happens.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ZeroCopySend)]
#[type_name("tandem.Event.v1")]
#[repr(C)]
pub struct Event {
    /// When (ns, cell clock).
    pub t_ns: i64,
    /// [`EVENT_LOG`] or [`EVENT_JOB`].
    pub kind: u32,
    /// The object (index in the cell's object names: axes, then encoders).
    pub object: u32,
    /// The job id.
    pub job: u32,
    /// `JOB_*`.
    pub code: u32,
    /// The ErrorID of a failed job.
    pub error_id: u32,
    /// The text.
    pub message: Text,
}

/// The names of [`AxisState`] by [`state_code`].
pub const STATE_NAMES: [&str; 8] = [
    "Disabled",
    "Standstill",
    "Homing",
    "DiscreteMotion",
    "ContinuousMotion",
    "SynchronizedMotion",
    "Stopping",
    "ErrorStop",
];

/// The code of a PLCopen state (index into [`STATE_NAMES`]).
pub fn state_code(s: AxisState) -> u32 {
    match s {
        AxisState::Disabled => 0,
        AxisState::Standstill => 1,
        AxisState::Homing => 2,
        AxisState::DiscreteMotion => 3,
        AxisState::ContinuousMotion => 4,
        AxisState::SynchronizedMotion => 5,
        AxisState::Stopping => 6,
        AxisState::ErrorStop => 7,
    }
}

/// A node's health, the header of each telemetry snapshot.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, ZeroCopySend)]
#[type_name("tandem.NodeHealth.v4")]
#[repr(C)]
pub struct NodeHealth {
    /// The cycle's engine time (ns); it runs on the cell clock at `epoch_ns + t_ns`.
    pub t_ns: i64,
    /// The cell clock's time of engine time 0 (ns, CLOCK_REALTIME).
    pub epoch_ns: i64,
    /// Servo cycle (ns).
    pub cycle_ns: i64,
    /// Compute time of the previous cycle (ns).
    pub compute_ns: i64,
    /// Wake-up lateness of this cycle (ns).
    pub lateness_ns: i64,
    /// Largest compute time so far (ns).
    pub max_compute_ns: i64,
    /// Largest lateness so far (ns).
    pub max_lateness_ns: i64,
    /// Cycles whose compute ended after the next cycle's start.
    pub overruns: u64,
    /// Cycles run.
    pub cycles: u64,
    /// Leading-value samples refused: by the plausibility gate (every kind below and non-finite
    /// values) or by the buffer.
    pub samples_rejected: u64,
    /// Leading values bridged by extrapolation because a sample was late.
    pub extrapolated: u64,
    /// Log lines and notes dropped because more than fit came in one cycle.
    pub log_dropped: u64,
    /// Process id.
    pub pid: u32,
    /// Axes in the snapshot.
    pub axes: u32,
    /// iceoryx2 sends of the cycle (leading values, the published event, output edges and
    /// measured values, events, telemetry) that failed.
    pub sends_failed: u64,
    /// Command replies the command thread could not take (it stopped or fell behind): the
    /// command was applied, its client waits in vain.
    pub commands_unanswered: u64,
    /// Script entries the node's objects refused (an ErrorID) or could not apply.
    pub script_rejected: u64,
    /// Cycles whose step reported an error (writing its log lines failed).
    pub step_errors: u64,
    /// Diagnostic records (log lines, job events) the diagnostics thread could not take.
    pub diag_dropped: u64,
    /// Trace rows dropped because the recorder thread was behind.
    pub trace_dropped: u64,
    /// Cycles between two telemetry snapshots (1: every cycle).
    pub telemetry_every: u64,
    /// Leading-value samples refused as from the future (after the receiver's clock by more
    /// than one leader cycle plus the tolerance).
    pub lv_future: u64,
    /// Samples refused as older than the buffer keeps.
    pub lv_stale: u64,
    /// Samples refused for a sequence number not matching their time or not increasing.
    pub lv_sequence: u64,
    /// Samples refused as a jump beyond the leader's dynamic limits.
    pub lv_jump: u64,
    /// Leaders followed again after a confirmed jump (three consistent samples).
    pub lv_reanchored: u64,
    /// Leading-value samples of remote leaders that never arrived (sequence gaps): a follower
    /// reading inside a gap gets the interpolant between the samples around it.
    pub lv_lost: u64,
    /// Trace rows the recorder could not write to the disk (`--trace`; a full disk or another
    /// write error): never partly written, counted exactly (v4). Not `trace_dropped`.
    pub trace_rows_lost: u64,
    /// Log lines the recorder could not write to the disk (`--log`), as `trace_rows_lost` (v4).
    /// Not `log_dropped` (lines the cycle's ring had no room for).
    pub log_lines_lost: u64,
    /// Cycles skipped to rejoin the time grid after a stall (a cycle overflow) instead of
    /// being run back to back (docs/processes.md, "Stalls").
    pub skipped_cycles: u64,
}

/// One axis in a telemetry snapshot.
#[derive(Copy, Clone, Debug, Default, PartialEq, ZeroCopySend)]
#[type_name("tandem.AxisTelemetry.v1")]
#[repr(C)]
pub struct AxisTelemetry {
    /// The axis' index in the cell.
    pub axis: u32,
    /// [`state_code`].
    pub state: u32,
    /// `StatusWord`.
    pub status_word: u32,
    /// `ErrorWord`.
    pub error_word: u32,
    /// `WarningWord`.
    pub warning_word: u32,
    /// `ErrorDetail.Number`: the pending alarm, 0 for none.
    pub alarm: u32,
    /// `StatusSynchronizedMotion.FunctionState`: 0 none, 1 GearIn, 2 GearInPos, 3 CamIn.
    pub sync_function: u32,
    /// The running job's id (basic motion, else synchronous operation), 0 for none.
    pub job: u32,
    /// Setpoint position (modulo-reduced).
    pub position: f64,
    /// Setpoint velocity.
    pub velocity: f64,
    /// Setpoint acceleration.
    pub acceleration: f64,
    /// Setpoint position, continuous.
    pub position_unwrapped: f64,
    /// Actual position (modulo-reduced).
    pub actual_position: f64,
    /// Actual velocity.
    pub actual_velocity: f64,
    /// Following error.
    pub following_error: f64,
    /// Velocity override (%).
    pub override_velocity: f64,
    /// Jobs queued behind the running one (PLCopen `BufferMode`).
    pub queue_depth: u32,
}

impl AxisTelemetry {
    /// The telemetry of axis `axis` from its status.
    pub fn from_status(axis: u32, s: &AxisStatus) -> Self {
        Self {
            axis,
            state: state_code(s.state),
            status_word: s.status_word,
            error_word: s.error_word,
            warning_word: s.warning_word,
            alarm: u32::from(s.error_detail.number),
            sync_function: u32::from(s.sync_function),
            job: s.motion_job.or(s.sync_job).map_or(0, |(j, _)| j),
            position: s.position,
            velocity: s.velocity,
            acceleration: s.acceleration,
            position_unwrapped: s.position_unwrapped,
            actual_position: s.actual_position,
            actual_velocity: s.actual_velocity,
            following_error: s.following_error,
            override_velocity: s.override_velocity,
            queue_depth: s.queue_depth,
        }
    }

    /// The PLCopen state name.
    pub fn state_name(&self) -> &'static str {
        STATE_NAMES.get(self.state as usize).copied().unwrap_or("?")
    }
}

/// [`IoEvent::kind`]: an output switched on (`value` = 1) or off (0).
pub const IO_OUTPUT: u32 = 0;
/// A measured value (`value` = the position, `counter` its measurement counter).
pub const IO_MEASURED: u32 = 1;

/// An output edge of an output cam or cam track, or a measured value of a measuring input.
#[derive(Copy, Clone, Debug, PartialEq, ZeroCopySend)]
#[type_name("tandem.IoEvent.v1")]
#[repr(C)]
pub struct IoEvent {
    /// The exact time of the edge (ns, cell clock).
    pub t_ns: i64,
    /// `IO_*`.
    pub kind: u32,
    /// The measurement counter, or the cam number of a cam track (1-based; 0 for an output cam).
    pub counter: u32,
    /// 1/0 for an output, the position for a measured value.
    pub value: f64,
}

/// [`SignalEvent::flags`]: the signal is an input (else an output).
pub const SIGNAL_INPUT: u32 = 1;
/// The signal's channel is timestamped: `t_ns` is the edge's own time.
pub const SIGNAL_TIMESTAMPED: u32 = 2;
/// An output switched later than its channel could (see the output stage).
pub const SIGNAL_LATE: u32 = 4;
/// The signal is an `integer` one: [`SignalEvent::value`] is its new reading (whole).
pub const SIGNAL_INTEGER: u32 = 8;
/// The signal is a `float` one: [`SignalEvent::value`] is its new reading (quantized).
pub const SIGNAL_FLOAT: u32 = 16;

/// One edge of a signal of a node's process image, or a new reading of an `integer` or
/// `float` one (docs/io.md, "Input signals", "Integer and float signals" and "Outputs").
///
/// v2 adds [`SignalEvent::value`] after the v1 fields, which keep their places and meanings;
/// a value change carries `SIGNAL_INTEGER` or `SIGNAL_FLOAT`, an edge neither.
#[derive(Copy, Clone, Debug, Default, PartialEq, ZeroCopySend)]
#[type_name("tandem.SignalEvent.v2")]
#[repr(C)]
pub struct SignalEvent {
    /// The instant the signal changed (ns, cell clock): an input's edge time (its own on a
    /// timestamped input, the sampling boundary on a plain one or a value); the instant an
    /// output switched.
    pub t_ns: i64,
    /// An input: the boundary whose sample carried the edge or value; an output: the edge
    /// time the output cam or cam track computed, its switching time (computed ahead; `t_ns`
    /// differs from it on a plain output or when late).
    pub ref_ns: i64,
    /// The signal's index in the cell (`[signals.<name>]` in name order).
    pub signal: u32,
    /// The new level: 1 on, 0 off (a value: 1 when it is not 0).
    pub level: u32,
    /// `SIGNAL_*` bits.
    pub flags: u32,
    /// Reserved (0).
    pub reserved: u32,
    /// A value change (`SIGNAL_INTEGER`, `SIGNAL_FLOAT`): the new reading (V for an analog
    /// channel); an edge: the level, 1.0 or 0.0.
    pub value: f64,
}
