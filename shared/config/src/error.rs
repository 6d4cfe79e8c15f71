//! The one error type of the configuration: [`ConfigError`] says where (file, line, key) and
//! [`Problem`] what is wrong, with the data of each kind of problem.

use crate::command::CommandError;
use core::fmt;
use tandem_motion::cam::{CamError, CamParseError};
use tandem_motion::objects::axis::AxisConfigProblem;

/// A problem in a configuration file (a cell file or a script), located.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ConfigError {
    /// File (as given).
    pub file: String,
    /// 1-based line, when known.
    pub line: Option<usize>,
    /// Dotted key path, when known.
    pub key: String,
    /// What is wrong.
    pub problem: Box<Problem>,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{}: ", self.file, l)?,
            None => write!(f, "{}: ", self.file)?,
        }
        if self.key.is_empty() {
            write!(f, "{}", self.problem)
        } else {
            write!(f, "{}: {}", self.key, self.problem)
        }
    }
}

impl std::error::Error for ConfigError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &*self.problem {
            Problem::Command(c) => Some(c),
            _ => None,
        }
    }
}

/// What is wrong in a configuration file: one variant per kind of problem, with its data.
/// `Display` gives the message the tools print after the file, line and key.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Problem {
    /// The file cannot be read (the operating system's reason).
    Unreadable(String),
    /// The file is larger than the reader takes ([`crate::read`]).
    TooLarge {
        /// The largest size read (bytes).
        max: u64,
    },
    /// The file is not UTF-8 text: the first invalid byte, at the error's line.
    NotUtf8 {
        /// The byte's column in its line (1-based, in bytes).
        column: usize,
        /// The byte.
        byte: u8,
    },
    /// TOML syntax or schema (an unknown field, a wrong type), as the TOML parser says it.
    Syntax(String),
    /// A value outside what the key accepts; the text says what it must be.
    Invalid(&'static str),
    /// A value of an axis the engine refuses (`[axes.<name>]`, validated by the axis).
    Axis(AxisConfigProblem),
    /// A name that must be one of a fixed list.
    NotOneOf {
        /// The value given.
        value: String,
        /// The accepted names.
        options: Vec<&'static str>,
    },
    /// A name that refers to no object of its kind.
    Unknown {
        /// The kind of object (`host`, `axis`, `leader`).
        what: &'static str,
        /// The name given.
        name: String,
        /// The names the cell has, when the message lists them.
        known: Option<Vec<String>>,
    },
    /// A node that names no node of `[[nodes]]`.
    UnknownNode(String),
    /// A host name defined twice, empty or not plain.
    BadHostName(String),
    /// A node name that is not a plain name.
    BadNodeName(String),
    /// A node without `host` in a cell of several hosts.
    HostRequired(String),
    /// A SCHED_FIFO priority outside 1..=99.
    Priority(u8),
    /// A node cycle that is not a positive multiple of the base tick.
    Cycle {
        /// The node.
        node: String,
        /// Its cycle (µs).
        cycle_us: u64,
        /// The base tick (µs).
        base_us: u64,
    },
    /// A node defined twice.
    DuplicateNode(String),
    /// An encoder with the name of an axis.
    AlsoAnAxis(String),
    /// An object name that is empty or already used.
    NameTaken(String),
    /// A name that is not a plain name (1 to 64 letters, digits, `_` or `-`).
    BadName {
        /// What it names (`cell`, `axis`, `signal`, ...).
        what: &'static str,
        /// The name as written.
        name: String,
    },
    /// A node name that a protocol key takes at the same place.
    ReservedName {
        /// The name as written.
        name: String,
        /// The names taken.
        reserved: &'static [&'static str],
    },
    /// An axis that names itself as its leader.
    SelfLeader,
    /// A leader named `node/leader` that is hosted by another node.
    LeaderNode {
        /// The leader.
        leader: String,
        /// The node that hosts it.
        hosted: String,
        /// The node the key names.
        named: String,
    },
    /// A leading-value delay plus tolerance that does not fit the leader's buffer.
    LeadingBuffer {
        /// The cycles they span.
        cycles: i64,
        /// The leader's node.
        node: String,
        /// The most cycles that fit.
        max: usize,
    },
    /// A leading-value delay shorter than the link to a follower needs.
    DelayTooShort(DelayShortfall),
    /// A cam points file that cannot be read.
    CamFile {
        /// The path as resolved.
        path: String,
        /// The operating system's reason.
        error: String,
    },
    /// A valve's characteristic curve file that is refused (the library's table rules).
    CurveFile {
        /// The path as resolved.
        path: String,
        /// What is wrong, with the library's error code.
        error: String,
    },
    /// A cam points file with a bad line.
    CamCsv {
        /// The path as resolved.
        path: String,
        /// The bad line.
        error: CamParseError,
    },
    /// A cam segment that is not well defined.
    Segment {
        /// The segment (0-based, as in the file).
        index: usize,
        /// What is wrong with it.
        problem: SegmentProblem,
    },
    /// A cam that cannot be interpolated.
    Interpolation(CamError),
    /// A cam track with more cams than it holds.
    TooManyCams(usize),
    /// A cam of a cam track that is not well defined.
    TrackCam {
        /// The cam (1-based).
        cam: usize,
        /// What is wrong.
        problem: &'static str,
    },
    /// A sensor on an axis of another node than its measuring input's.
    SensorNode {
        /// The sensor's axis.
        sensor_axis: String,
        /// The measuring input's axis.
        axis: String,
    },
    /// An object refused by the engine.
    Rejected {
        /// The kind of object (`cam track`, `measuring input`).
        object: &'static str,
        /// The engine's reason.
        reason: tandem_motion::objects::measuring::MeasuringConfigError,
    },
    /// A switch or track of a digital cam switch refused by the engine, with the hydraulic
    /// library's error code (the key names the entry and its field).
    CamSwitch(tandem_motion::objects::digital_cam_switch::DcsError),
    /// A script instruction or its parameters.
    Command(CommandError),
    /// A required key that is missing.
    Missing(&'static str),
    /// A Zenoh endpoint that is not `<protocol>/<address>:<port>` as the gateway needs it.
    Endpoint {
        /// The endpoint as written.
        endpoint: String,
        /// What is wrong with it.
        why: &'static str,
    },
    /// A gateway endpoint reachable from the network in a cell without `[security]`: plain,
    /// unauthenticated Zenoh must be asked for explicitly (docs/security.md).
    PlainNotDeclared(String),
    /// A key of a drive of the process image on an axis with the simulated drive.
    OnlyWithDrive,
    /// A virtual axis bound to a drive.
    VirtualWithDrive,
    /// A drive of another node's process image.
    DeviceNode {
        /// The device.
        device: String,
        /// The axis's node (index).
        axis_node: usize,
        /// The device's node (index).
        device_node: usize,
    },
    /// A device already bound to another axis.
    DeviceTaken {
        /// The device.
        device: String,
        /// The axis it is bound to.
        axis: String,
    },
    /// Encoder or mechanics values that cannot convert increments to units.
    Mechanics(Box<tandem_motion::plant::mechanics::MechanicsError>),
    /// Parameters of a simulated servo drive that the model refuses.
    Servo(Box<tandem_motion::plant::servo::ServoParamsError>),
    /// A key of `[devices.<name>]` that the device's kind does not have.
    NotForKind(&'static str),
    /// A device of the wrong kind for what refers to it.
    DeviceKind {
        /// The device.
        device: String,
        /// Its kind.
        kind: &'static str,
        /// What the key needs (`a drive (sim_servo)`).
        needs: &'static str,
    },
    /// A signal's channel that the device does not have.
    ChannelRange {
        /// The device.
        device: String,
        /// The channel given.
        channel: u32,
        /// The device's channels (1 to this).
        channels: u8,
    },
    /// A channel already bound to another signal.
    ChannelTaken {
        /// The device.
        device: String,
        /// The channel.
        channel: u8,
        /// The signal it is bound to.
        signal: String,
    },
    /// An object driving a signal of another node's process image.
    SignalNode {
        /// The signal.
        signal: String,
        /// The node of the signal's device.
        signal_node: String,
        /// The node of the object's axis.
        object_node: String,
    },
    /// A signal already driven by another object.
    SignalDriven {
        /// The signal.
        signal: String,
        /// The object that drives it.
        by: String,
    },
    /// An input signal where an output is needed, or an output where an input is.
    SignalDirection {
        /// The signal.
        signal: String,
        /// What it is (`an input`).
        is: &'static str,
        /// What the key needs (`an output`).
        needs: &'static str,
    },
    /// A plain input signal where a timestamped one is needed.
    SignalType {
        /// The signal.
        signal: String,
        /// What the key needs.
        needs: &'static str,
    },
    /// A signal whose type is not the one needed: a `type` its channel does not have, or a
    /// consumer that needs another type.
    ChannelType {
        /// The signal.
        signal: String,
        /// What it is: its channel's type and device kind.
        is: String,
        /// What the key needs.
        needs: String,
    },
    /// An input signal already bound to another role.
    InputBound {
        /// The signal.
        signal: String,
        /// The key that binds it already.
        by: String,
    },
    /// A key that conflicts with another that gives the same thing.
    Conflict {
        /// What the other key is and says.
        other: String,
    },
}

/// A leading-value delay shorter than the link from a leader to a follower on another node
/// needs: the leader's cycle, the link budget and the follower's cycle.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DelayShortfall {
    /// The configured delay (µs).
    pub delay_us: i64,
    /// The follower.
    pub follower: String,
    /// The follower's node.
    pub node: String,
    /// The delay needed (µs).
    pub need_us: i64,
    /// The leader's cycle (µs).
    pub leader_cycle_us: i64,
    /// The budget key of the link (`ipc_budget_us` or `network_budget_us`).
    pub budget: &'static str,
    /// The link budget (µs).
    pub link_us: i64,
    /// The follower's cycle (µs).
    pub follower_cycle_us: i64,
}

/// What is wrong with a cam segment.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SegmentProblem {
    /// A `law` segment without `law`.
    LawRequired,
    /// A law name or parameter the engine does not know.
    UnknownLaw(String),
    /// A `law` segment without `y`.
    YRequired,
    /// A `polynomial` segment without 1 to 8 coefficients.
    CoeffsRequired,
    /// An `s7_polynomial` segment with more than 7 coefficients.
    TooManyCoefficients,
    /// A segment type that does not exist.
    UnknownType(String),
}

impl From<CommandError> for Problem {
    fn from(c: CommandError) -> Self {
        Problem::Command(c)
    }
}

impl fmt::Display for SegmentProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SegmentProblem::LawRequired => f.write_str("`law` is required"),
            SegmentProblem::UnknownLaw(n) => write!(f, "unknown law `{n}` or bad parameter"),
            SegmentProblem::YRequired => f.write_str("`y = [y0, y1]` is required"),
            SegmentProblem::CoeffsRequired => f.write_str("`coeffs` (1 to 8 numbers) is required"),
            SegmentProblem::TooManyCoefficients => f.write_str("`a` has at most 7 coefficients"),
            SegmentProblem::UnknownType(t) => {
                write!(f, "type `{t}` is not one of law, polynomial, s7_polynomial")
            }
        }
    }
}

impl fmt::Display for DelayShortfall {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "leading-value delay {} µs is shorter than the link to follower `{}` on node `{}` needs: {} µs (leader cycle {} + {} {} + follower cycle {})",
            self.delay_us,
            self.follower,
            self.node,
            self.need_us,
            self.leader_cycle_us,
            self.budget,
            self.link_us,
            self.follower_cycle_us,
        )
    }
}

impl std::error::Error for Problem {}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Problem::Unreadable(e) => write!(f, "cannot read: {e}"),
            Problem::TooLarge { max } => write!(
                f,
                "larger than {max} bytes, more than any such file needs: not read"
            ),
            Problem::NotUtf8 { column, byte } => write!(
                f,
                "not UTF-8 text: byte 0x{byte:02X} at column {column} is not valid UTF-8"
            ),
            Problem::Missing(k) => write!(f, "`{k}` is required here"),
            Problem::Endpoint { endpoint, why } => write!(f, "endpoint `{endpoint}`: {why}"),
            Problem::PlainNotDeclared(e) => write!(
                f,
                "`{e}` is reachable from the network, and the cell has no [security]: add \
                 [security] (mode = \"mtls\", certificates from `tandem certs`), or write \
                 mode = \"plain\" there to run without authentication (docs/security.md)"
            ),
            Problem::OnlyWithDrive => f.write_str(
                "only for a drive of the process image (`[axes.<name>.drive] type = \"cia402\"`); \
                 this axis has the simulated drive",
            ),
            Problem::VirtualWithDrive => {
                f.write_str("a virtual axis has no drive; remove `virtual` or the drive's `type`")
            }
            Problem::DeviceNode {
                device,
                axis_node,
                device_node,
            } => write!(
                f,
                "device `{device}` is in the process image of node {device_node}, the axis runs \
                 on node {axis_node}: an axis drives only devices of its own node"
            ),
            Problem::DeviceTaken { device, axis } => {
                write!(f, "device `{device}` already drives axis `{axis}`")
            }
            Problem::NotForKind(kind) => write!(f, "not a key of a `{kind}` device"),
            Problem::DeviceKind {
                device,
                kind,
                needs,
            } => write!(f, "device `{device}` is a `{kind}`; this needs {needs}"),
            Problem::ChannelRange {
                device,
                channel,
                channels,
            } => write!(
                f,
                "channel {channel} of device `{device}`: it has channels 1 to {channels}"
            ),
            Problem::ChannelTaken {
                device,
                channel,
                signal,
            } => write!(
                f,
                "channel {channel} of device `{device}` is already bound to signal `{signal}`"
            ),
            Problem::SignalNode {
                signal,
                signal_node,
                object_node,
            } => write!(
                f,
                "signal `{signal}` is in the process image of node `{signal_node}`, the object \
                 runs on node `{object_node}`: an object drives only signals of its own node"
            ),
            Problem::SignalDriven { signal, by } => {
                write!(f, "signal `{signal}` is already driven by `{by}`")
            }
            Problem::SignalDirection { signal, is, needs } => {
                write!(f, "signal `{signal}` is {is}; this needs {needs}")
            }
            Problem::SignalType { signal, needs } => {
                write!(f, "signal `{signal}` is a plain `bool`; this needs {needs}")
            }
            Problem::ChannelType { signal, is, needs } => {
                write!(f, "signal `{signal}` is {is}; this needs {needs}")
            }
            Problem::InputBound { signal, by } => {
                write!(f, "input signal `{signal}` is already bound to `{by}`")
            }
            Problem::Conflict { other } => write!(f, "conflicts with {other}"),
            Problem::Mechanics(e) => write!(f, "{e}"),
            Problem::Servo(e) => write!(f, "{e}"),
            Problem::Syntax(m) => f.write_str(m),
            Problem::Invalid(m) => f.write_str(m),
            Problem::Axis(p) => f.write_str(p.text()),
            Problem::NotOneOf { value, options } => {
                write!(f, "`{value}` is not one of {}", options.join(", "))
            }
            Problem::Unknown { what, name, known } => {
                write!(f, "unknown {what} `{name}`")?;
                match known {
                    Some(k) => write!(f, "; the cell has: {}", k.join(", ")),
                    None => Ok(()),
                }
            }
            Problem::UnknownNode(n) => write!(f, "unknown node `{n}` (define it in [[nodes]])"),
            Problem::BadHostName(h) => {
                write!(
                    f,
                    "host `{h}` is defined twice or is not 1 to 64 letters, digits, `_` or `-`"
                )
            }
            Problem::BadNodeName(n) => write!(
                f,
                "`{n}`: a node name is 1 to 64 letters, digits, `_` or `-` (it names services, \
                 keys and files)"
            ),
            Problem::BadName { what, name } => write!(
                f,
                "`{name}`: a {what} name is 1 to 64 letters, digits, `_` or `-` (it names \
                 services, keys and files)"
            ),
            Problem::ReservedName { name, reserved } => write!(
                f,
                "`{name}`: the protocol's keys take the node names {} (tandem/<cell>/<name>/...)",
                reserved.join(", ")
            ),
            Problem::HostRequired(n) => write!(
                f,
                "node `{n}` needs `host = ...`: the cell has several hosts"
            ),
            Problem::Priority(p) => write!(f, "priority = {p}: SCHED_FIFO priorities are 1 to 99"),
            Problem::Cycle {
                node,
                cycle_us,
                base_us,
            } => write!(
                f,
                "node `{node}`: cycle_us = {cycle_us} is not a positive multiple of the base tick ({base_us} µs)"
            ),
            Problem::DuplicateNode(n) => write!(f, "node `{n}` is defined twice"),
            Problem::AlsoAnAxis(n) => write!(f, "`{n}` is also an axis: names must be unique"),
            Problem::NameTaken(n) => write!(
                f,
                "`{n}` is empty or already used: names must be unique"
            ),
            Problem::SelfLeader => f.write_str("an axis cannot lead itself"),
            Problem::LeaderNode {
                leader,
                hosted,
                named,
            } => write!(f, "`{leader}` is on node `{hosted}`, not `{named}`"),
            Problem::LeadingBuffer { cycles, node, max } => write!(
                f,
                "delay plus tolerance span {cycles} cycles of node `{node}`; at most {max} fit the buffer"
            ),
            Problem::DelayTooShort(d) => fmt::Display::fmt(d, f),
            Problem::CamFile { path, error } => write!(f, "cannot read {path}: {error}"),
            Problem::CamCsv { path, error } => write!(f, "{path}: {error}"),
            Problem::CurveFile { path, error } => write!(f, "{path}: {error}"),
            Problem::Segment { index, problem } => write!(f, "segment {index}: {problem}"),
            Problem::Interpolation(e) => {
                write!(f, "cannot interpolate: {e:?} ({})", e.error_id())
            }
            Problem::TooManyCams(n) => write!(f, "at most {n} cams"),
            Problem::TrackCam { cam, problem } => write!(f, "cam {cam}: {problem}"),
            Problem::SensorNode { sensor_axis, axis } => {
                write!(f, "`{sensor_axis}` must be on the node of `{axis}`")
            }
            Problem::Rejected { object, reason } => write!(f, "rejected by the {object}: {reason}"),
            Problem::CamSwitch(e) => {
                use tandem_motion::objects::digital_cam_switch::{DcsField, COMPENSATION_MAX};
                let rule = match e.field {
                    DcsField::SwitchCount => "too many switches",
                    DcsField::TrackCount => "too many tracks",
                    DcsField::TrackNumber => "must be 1..=32 and name an entry of `tracks`",
                    DcsField::FirstOnPosition => "must be finite, within ±1e12",
                    DcsField::AxisDirection => "must be 0 (both), 1 (positive) or 2 (negative)",
                    DcsField::CamSwitchMode => "must be 0 (position) or 1 (time)",
                    DcsField::LastOnPosition => {
                        "must be given for a position switch, finite, within ±1e12 and at least first_on_position"
                    }
                    DcsField::Duration => "must be given for a time switch, finite and >= 0 s",
                    DcsField::OnCompensation | DcsField::OffCompensation => {
                        return write!(
                            f,
                            "must be within ±{COMPENSATION_MAX} s ({} {})",
                            e.code,
                            e.code.meaning()
                        )
                    }
                    DcsField::Hysteresis => "must be 0..1e12",
                };
                write!(f, "{rule} ({} {})", e.code, e.code.meaning())
            }
            Problem::Command(c) => fmt::Display::fmt(c, f),
        }
    }
}
