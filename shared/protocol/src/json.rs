//! What travels on Zenoh: JSON for observers and operators (readable from any language and the
//! zenoh tools, no Rust types needed), and the binary codec (bincode 2) of a leading value
//! between hosts. Field names are part of the interface; docs/gateway.md lists them.

use crate::wire::{
    AxisTelemetry, CommandReply, Event, LeadingValueSample, NodeHealth, JOB_ABORTED, JOB_DONE,
    JOB_ERROR, JOB_REACHED, OUTCOME_ACCEPTED, OUTCOME_BUSY, OUTCOME_INVALID, OUTCOME_REJECTED,
};
use serde::{Deserialize, Serialize};
use tandem_motion::catalog::error_id::ErrorId;

/// The binary form of a leading value between hosts (fixed-width integers: 64 bytes).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
struct LeadingValueWire {
    t_ns: i64,
    seq: u64,
    p: f64,
    v: f64,
    a: f64,
    modulo_start: f64,
    modulo_length: f64,
    status: u32,
    leader: u32,
}

fn codec() -> impl bincode::config::Config {
    bincode::config::standard().with_fixed_int_encoding()
}

/// Encodes a leading value for Zenoh.
pub fn encode_leading_value(s: &LeadingValueSample) -> Vec<u8> {
    let w = LeadingValueWire {
        t_ns: s.t_ns,
        seq: s.seq,
        p: s.p,
        v: s.v,
        a: s.a,
        modulo_start: s.modulo_start,
        modulo_length: s.modulo_length,
        status: s.status,
        leader: s.leader,
    };
    bincode::serde::encode_to_vec(w, codec()).unwrap_or_default()
}

/// Bytes of an encoded leading value.
pub const LEADING_VALUE_BYTES: usize = 64;

/// Why a leading value from Zenoh was refused.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum DecodeError {
    /// The payload has `bytes` bytes; a leading value has [`LEADING_VALUE_BYTES`].
    Size {
        /// The payload's length.
        bytes: usize,
    },
    /// A position, velocity, acceleration or modulo value is NaN or infinite.
    NotFinite,
}

impl core::fmt::Display for DecodeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Size { bytes } => write!(
                f,
                "{bytes} bytes, a leading value has {LEADING_VALUE_BYTES}"
            ),
            Self::NotFinite => f.write_str("a value is not finite"),
        }
    }
}

impl std::error::Error for DecodeError {}

/// Decodes a leading value from Zenoh; a payload of the wrong size or with non-finite values
/// is refused, saying why.
pub fn decode_leading_value(bytes: &[u8]) -> Result<LeadingValueSample, DecodeError> {
    let size = DecodeError::Size { bytes: bytes.len() };
    if bytes.len() != LEADING_VALUE_BYTES {
        return Err(size);
    }
    let (w, _): (LeadingValueWire, usize) =
        bincode::serde::decode_from_slice(bytes, codec()).map_err(|_| size)?;
    if ![w.p, w.v, w.a, w.modulo_start, w.modulo_length]
        .iter()
        .all(|x| x.is_finite())
    {
        return Err(DecodeError::NotFinite);
    }
    Ok(LeadingValueSample {
        t_ns: w.t_ns,
        seq: w.seq,
        p: w.p,
        v: w.v,
        a: w.a,
        modulo_start: w.modulo_start,
        modulo_length: w.modulo_length,
        status: w.status,
        leader: w.leader,
    })
}

/// `tandem/<cell>/<node>/<axis>/state`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AxisState {
    /// Engine time of the snapshot (ns); the cell clock reads `epoch_ns + t_ns`.
    pub t_ns: i64,
    /// Cell clock time of engine time 0 (ns).
    pub epoch_ns: i64,
    /// Node.
    pub node: String,
    /// Axis.
    pub axis: String,
    /// PLCopen state.
    pub state: String,
    /// Setpoint position (modulo-reduced).
    pub position: f64,
    /// Setpoint velocity.
    pub velocity: f64,
    /// Setpoint acceleration.
    pub acceleration: f64,
    /// Actual position.
    pub actual_position: f64,
    /// Actual velocity.
    pub actual_velocity: f64,
    /// Following error.
    pub following_error: f64,
    /// `StatusWord`.
    pub status_word: u32,
    /// `ErrorWord`.
    pub error_word: u32,
    /// `WarningWord`.
    pub warning_word: u32,
    /// Pending alarm number, 0 for none.
    pub alarm: u32,
    /// Synchronous function: `none`, `GearIn`, `GearInPos`, `CamIn`.
    pub sync: String,
    /// The running job, 0 for none.
    pub job: u32,
    /// Jobs queued behind the running one (PLCopen `BufferMode`).
    #[serde(default)]
    pub queue_depth: u32,
}

impl AxisState {
    /// The state of `axis` on `node` from a telemetry snapshot.
    pub fn new(h: &NodeHealth, node: &str, axis: &str, a: &AxisTelemetry) -> Self {
        Self {
            t_ns: h.t_ns,
            epoch_ns: h.epoch_ns,
            node: node.into(),
            axis: axis.into(),
            state: a.state_name().into(),
            position: a.position,
            velocity: a.velocity,
            acceleration: a.acceleration,
            actual_position: a.actual_position,
            actual_velocity: a.actual_velocity,
            following_error: a.following_error,
            status_word: a.status_word,
            error_word: a.error_word,
            warning_word: a.warning_word,
            alarm: a.alarm,
            sync: match a.sync_function {
                1 => "GearIn",
                2 => "GearInPos",
                3 => "CamIn",
                _ => "none",
            }
            .into(),
            job: a.job,
            queue_depth: a.queue_depth,
        }
    }
}

/// `tandem/<cell>/<node>/health`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Health {
    /// Node.
    pub node: String,
    /// Engine time (ns).
    pub t_ns: i64,
    /// Cell clock time of engine time 0 (ns).
    pub epoch_ns: i64,
    /// Servo cycle (µs).
    pub cycle_us: f64,
    /// Compute time of the last cycle (µs).
    pub compute_us: f64,
    /// Largest compute time (µs).
    pub max_compute_us: f64,
    /// Wake-up lateness of the last cycle (µs).
    pub lateness_us: f64,
    /// Largest lateness (µs).
    pub max_lateness_us: f64,
    /// Cycles that overran.
    pub overruns: u64,
    /// Cycles run.
    pub cycles: u64,
    /// Leading values bridged by extrapolation.
    pub extrapolated: u64,
    /// Leading-value samples refused.
    pub samples_rejected: u64,
    /// Process id.
    pub pid: u32,
    /// Log lines and notes dropped (more than fit in one cycle).
    #[serde(default)]
    pub log_dropped: u64,
    /// iceoryx2 sends of the cycle that failed.
    #[serde(default)]
    pub sends_failed: u64,
    /// Command replies the command thread could not take.
    #[serde(default)]
    pub commands_unanswered: u64,
    /// Script entries the node's objects refused or could not apply.
    #[serde(default)]
    pub script_rejected: u64,
    /// Cycles whose step reported an error.
    #[serde(default)]
    pub step_errors: u64,
    /// Diagnostic records the node's recorder thread could not take.
    #[serde(default)]
    pub diag_dropped: u64,
    /// Trace rows dropped because the recorder was behind.
    #[serde(default)]
    pub trace_dropped: u64,
    /// Leading-value samples refused as from the future.
    #[serde(default)]
    pub lv_future: u64,
    /// Leading-value samples refused as older than the buffer keeps.
    #[serde(default)]
    pub lv_stale: u64,
    /// Leading-value samples refused for their sequence number.
    #[serde(default)]
    pub lv_sequence: u64,
    /// Leading-value samples refused as a jump beyond the leader's dynamic limits.
    #[serde(default)]
    pub lv_jump: u64,
    /// Leaders followed again after a confirmed jump.
    #[serde(default)]
    pub lv_reanchored: u64,
    /// Leading-value samples of remote leaders that never arrived (sequence gaps).
    #[serde(default)]
    pub lv_lost: u64,
    /// Trace rows the node's recorder could not write to the disk (a full disk).
    #[serde(default)]
    pub trace_rows_lost: u64,
    /// Log lines the node's recorder could not write to the disk (a full disk).
    #[serde(default)]
    pub log_lines_lost: u64,
    /// Cycles skipped to rejoin the time grid after a stall.
    #[serde(default)]
    pub skipped_cycles: u64,
}

impl Health {
    /// The JSON form of a node's health.
    pub fn new(node: &str, h: &NodeHealth) -> Self {
        Self {
            node: node.into(),
            t_ns: h.t_ns,
            epoch_ns: h.epoch_ns,
            cycle_us: h.cycle_ns as f64 * 1e-3,
            compute_us: h.compute_ns as f64 * 1e-3,
            max_compute_us: h.max_compute_ns as f64 * 1e-3,
            lateness_us: h.lateness_ns as f64 * 1e-3,
            max_lateness_us: h.max_lateness_ns as f64 * 1e-3,
            overruns: h.overruns,
            cycles: h.cycles,
            extrapolated: h.extrapolated,
            samples_rejected: h.samples_rejected,
            pid: h.pid,
            log_dropped: h.log_dropped,
            sends_failed: h.sends_failed,
            commands_unanswered: h.commands_unanswered,
            script_rejected: h.script_rejected,
            step_errors: h.step_errors,
            diag_dropped: h.diag_dropped,
            trace_dropped: h.trace_dropped,
            lv_future: h.lv_future,
            lv_stale: h.lv_stale,
            lv_sequence: h.lv_sequence,
            lv_jump: h.lv_jump,
            lv_reanchored: h.lv_reanchored,
            lv_lost: h.lv_lost,
            trace_rows_lost: h.trace_rows_lost,
            log_lines_lost: h.log_lines_lost,
            skipped_cycles: h.skipped_cycles,
        }
    }
}

/// The S7 notation of an ErrorID code, with its name when known: `16#8003 IllegalVelocity`.
pub fn error_id_text(code: u32) -> String {
    u16::try_from(code)
        .ok()
        .and_then(ErrorId::from_code)
        .map_or(format!("16#{code:04X}"), |e| e.to_string())
}

/// `tandem/<cell>/<node>/<object>/events` (job events) and `tandem/<cell>/<node>/log` (lines).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EventJson {
    /// Engine time (ns).
    pub t_ns: i64,
    /// The object, or empty for a log line.
    pub object: String,
    /// The job, 0 for a log line.
    pub job: u32,
    /// `done`, `aborted`, `error`, `reached`, `progress`, `log`, or `command` (a command answered,
    /// with its [`EventJson::sender`]).
    pub outcome: String,
    /// The ErrorID of an `error`, `16#8001 TechnologyAlarm`; empty otherwise.
    pub error_id: String,
    /// The event or line, as the log shows it.
    pub message: String,
    /// Who sent the command of a `command` event (the certificate's subject in an mTLS cell);
    /// absent for the node's own events.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sender: Option<String>,
}

impl EventJson {
    /// A `command` event: who sent command `line` to `object` and how it was answered
    /// (docs/gateway.md, "Audit trail"), as the gateway publishes it on the object's events key.
    pub fn command(object: &str, sender: &str, line: &str, reply: &ReplyJson) -> Self {
        let mut message = format!("{line}: {}", reply.outcome);
        if !reply.message.is_empty() {
            message.push_str(&format!(" ({})", reply.message));
        }
        Self {
            t_ns: reply.t_ns,
            object: object.into(),
            job: reply.job,
            outcome: "command".into(),
            error_id: reply.error_id.clone(),
            message,
            sender: Some(sender.into()),
        }
    }

    /// The JSON form of a node event (`object` named by the caller).
    pub fn new(e: &Event, object: &str) -> Self {
        let outcome = match (e.kind, e.code) {
            (crate::wire::EVENT_LOG, _) => "log",
            (_, JOB_DONE) => "done",
            (_, JOB_ABORTED) => "aborted",
            (_, JOB_ERROR) => "error",
            (_, JOB_REACHED) => "reached",
            _ => "progress",
        };
        Self {
            t_ns: e.t_ns,
            object: object.into(),
            job: e.job,
            outcome: outcome.into(),
            error_id: if e.code == JOB_ERROR {
                error_id_text(e.error_id)
            } else {
                String::new()
            },
            message: e.message.as_str().into(),
            sender: None,
        }
    }
}

/// A command as a JSON query payload: `{"instruction": "MC_MoveVelocity", "params":
/// {"velocity": 100}}`. A plain-text payload `MC_MoveVelocity --velocity 100` is accepted too.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CommandJson {
    /// Instruction, any accepted spelling.
    pub instruction: String,
    /// Parameters by name: numbers, booleans, or names (leader `node/axis`, cam).
    #[serde(default)]
    pub params: serde_json::Map<String, serde_json::Value>,
    /// Who sends it (docs/gateway.md, "Command rate"); a Zenoh attachment `sender=<name>`
    /// does the same for a text payload.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sender: Option<String>,
}

/// A parameter of a [`CommandJson`] the command line cannot carry.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParamError {
    /// The parameter's name.
    pub key: String,
    /// Its JSON value.
    pub value: String,
}

impl core::fmt::Display for ParamError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "parameter `{}`: {} is not a number, a boolean or a name",
            self.key, self.value
        )
    }
}

impl std::error::Error for ParamError {}

impl CommandJson {
    /// The command line the node parses: `<instruction> --k v ...`.
    pub fn to_line(&self) -> Result<String, ParamError> {
        let mut line = self.instruction.clone();
        for (k, v) in &self.params {
            let v = match v {
                serde_json::Value::Number(n) => n.to_string(),
                serde_json::Value::Bool(b) => b.to_string(),
                serde_json::Value::String(s) if !s.contains(char::is_whitespace) => s.clone(),
                other => {
                    return Err(ParamError {
                        key: k.clone(),
                        value: other.to_string(),
                    })
                }
            };
            line.push_str(&format!(" --{k} {v}"));
        }
        Ok(line)
    }
}

/// The reply to a command query.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReplyJson {
    /// `accepted`, `rejected` (ErrorID), `invalid` (not understood), `busy`, `unreachable`.
    pub outcome: String,
    /// The job id of an accepted Execute-type instruction, else 0.
    pub job: u32,
    /// The cycle time it was applied at (ns).
    pub t_ns: i64,
    /// The ErrorID of a rejection, `16#8003 IllegalVelocity`; empty otherwise.
    pub error_id: String,
    /// What went wrong, in words; when accepted, empty or MC_ReadParameter's and
    /// MC_WriteParameter's `Tag = value` (the value the axis has now).
    pub message: String,
}

impl ReplyJson {
    /// The JSON form of a node's reply.
    pub fn from_reply(r: &CommandReply) -> Self {
        let outcome = match r.outcome {
            OUTCOME_ACCEPTED => "accepted",
            OUTCOME_REJECTED => "rejected",
            OUTCOME_INVALID => "invalid",
            OUTCOME_BUSY => "busy",
            _ => "unknown",
        };
        Self {
            outcome: outcome.into(),
            job: r.job,
            t_ns: r.t_ns,
            error_id: if r.outcome == OUTCOME_REJECTED {
                error_id_text(r.error_id)
            } else {
                String::new()
            },
            message: r.message.as_str().into(),
        }
    }

    /// A reply the gateway gives itself (the node did not answer, the query was malformed).
    pub fn failed(outcome: &str, message: impl Into<String>) -> Self {
        Self {
            outcome: outcome.into(),
            job: 0,
            t_ns: 0,
            error_id: String::new(),
            message: message.into(),
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn leading_values_round_trip_and_malformed_ones_are_refused() {
        let s = LeadingValueSample {
            t_ns: -5,
            seq: 7,
            p: 1.5,
            v: -2.25,
            a: 1e-300,
            modulo_start: 0.0,
            modulo_length: 360.0,
            status: 1,
            leader: 3,
        };
        let b = encode_leading_value(&s);
        assert_eq!(b.len(), 64);
        assert_eq!(decode_leading_value(&b).unwrap(), s);
        assert!(decode_leading_value(&b[..63]).is_err());
        let mut longer = b.clone();
        longer.push(0);
        assert!(decode_leading_value(&longer)
            .unwrap_err()
            .to_string()
            .contains("65 bytes"));
        assert_eq!(
            decode_leading_value(&longer),
            Err(DecodeError::Size { bytes: 65 })
        );
        assert!(decode_leading_value(b"").is_err());
        let nan = LeadingValueSample { p: f64::NAN, ..s };
        assert!(decode_leading_value(&encode_leading_value(&nan)).is_err());
        assert_eq!(
            decode_leading_value(&encode_leading_value(&nan)),
            Err(DecodeError::NotFinite)
        );
    }

    #[test]
    fn a_json_command_becomes_the_node_command_line() {
        let c: CommandJson = serde_json::from_str(
            r#"{"instruction": "MC_MoveVelocity", "params": {"velocity": 100.5, "current": false}}"#,
        )
        .unwrap();
        assert_eq!(
            c.to_line().unwrap(),
            "MC_MoveVelocity --current false --velocity 100.5"
        );
        let bad: CommandJson =
            serde_json::from_str(r#"{"instruction": "MC_Halt", "params": {"x": [1]}}"#).unwrap();
        assert!(bad.to_line().is_err());
        assert_eq!(
            bad.to_line().unwrap_err().to_string(),
            "parameter `x`: [1] is not a number, a boolean or a name"
        );
    }
}
