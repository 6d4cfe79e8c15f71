//! Instruction names and parameters as people write them (script files, the CLI) to engine
//! commands. Names are the PLCopen ones, with or without `MC_`, in any case, with or without
//! underscores: `MC_MoveAbsolute`, `MoveAbsolute`, `move_absolute`. Parameters are the
//! references' input names in snake case (`position`, `velocity`, `abort_acceleration`...).
//! Defaults are the references' defaults (dynamics -1.0 = the axis defaults).

use core::fmt;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::axis::{
    axis_parameter_number, ApplicationMode, BufferMode, BufferedMotion, CamId, Command, Direction,
    FlyingGearParams, HydHomeInputs, HydHomingMode, HydJogMode, StartMode, StopMode, SyncDirection,
    SyncProfileReference, VelocityDirection,
};
use tandem_motion::objects::leading::LeaderId;

/// A parameter value.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Value {
    /// A number.
    Num(f64),
    /// A boolean.
    Bool(bool),
}

/// One instruction with its parameters: name, and (parameter, default or `None` if required).
#[derive(Debug)]
pub struct InstructionSpec {
    /// PLCopen name.
    pub name: &'static str,
    /// Parameters: name and default (`None` = required).
    pub params: &'static [(&'static str, Option<Value>)],
}

/// The defaults of `MC_AxCtrlAutoZero_BkPlcMc`'s inputs.
const AUTO_ZERO: tandem_motion::hydraulic::auto_zero::AutoZeroParams =
    tandem_motion::hydraulic::auto_zero::AutoZeroParams::DEFAULT;

/// `BufferMode` (PLCopen Motion Control Part 1): 0 Aborting (default) .. 5 BlendingHigh; a
/// script or command line may also give the name (`buffer_mode = "BlendingLow"`), see
/// [`named_value`].
const BUFFER_MODE: (&str, Option<Value>) = ("buffer_mode", Some(Value::Num(0.0)));

const DYN: [(&str, Option<Value>); 4] = [
    ("velocity", Some(Value::Num(-1.0))),
    ("acceleration", Some(Value::Num(-1.0))),
    ("deceleration", Some(Value::Num(-1.0))),
    ("jerk", Some(Value::Num(-1.0))),
];

/// Every instruction the axis accepts, with its parameters.
pub const INSTRUCTIONS: &[InstructionSpec] = &[
    InstructionSpec {
        name: "MC_Power",
        params: &[
            ("enable", Some(Value::Bool(true))),
            ("start_mode", Some(Value::Num(1.0))),
            ("stop_mode", Some(Value::Num(0.0))),
        ],
    },
    InstructionSpec {
        name: "MC_Reset",
        params: &[("restart", Some(Value::Bool(false)))],
    },
    InstructionSpec {
        name: "MC_Home",
        params: &[
            ("mode", Some(Value::Num(0.0))),
            ("position", Some(Value::Num(0.0))),
        ],
    },
    InstructionSpec {
        name: "MC_Halt",
        params: &[
            ("deceleration", Some(Value::Num(-1.0))),
            ("jerk", Some(Value::Num(-1.0))),
            ("abort_acceleration", Some(Value::Bool(false))),
        ],
    },
    InstructionSpec {
        name: "MC_Stop",
        params: &[
            ("execute", Some(Value::Bool(true))),
            ("deceleration", Some(Value::Num(-1.0))),
            ("jerk", Some(Value::Num(-1.0))),
        ],
    },
    InstructionSpec {
        name: "MC_MoveAbsolute",
        params: &[
            ("position", None),
            DYN[0],
            DYN[1],
            DYN[2],
            DYN[3],
            ("direction", Some(Value::Num(1.0))),
            BUFFER_MODE,
        ],
    },
    InstructionSpec {
        name: "MC_MoveRelative",
        params: &[
            ("distance", None),
            DYN[0],
            DYN[1],
            DYN[2],
            DYN[3],
            BUFFER_MODE,
        ],
    },
    InstructionSpec {
        name: "MC_MoveAdditive",
        params: &[
            ("distance", None),
            DYN[0],
            DYN[1],
            DYN[2],
            DYN[3],
            BUFFER_MODE,
        ],
    },
    InstructionSpec {
        name: "MC_MoveVelocity",
        params: &[
            ("velocity", Some(Value::Num(100.0))),
            DYN[1],
            DYN[2],
            DYN[3],
            ("direction", Some(Value::Num(0.0))),
            ("current", Some(Value::Bool(false))),
            ("position_controlled", Some(Value::Bool(true))),
            BUFFER_MODE,
        ],
    },
    InstructionSpec {
        name: "MC_MoveJog",
        params: &[
            ("jog_forward", Some(Value::Bool(false))),
            ("jog_backward", Some(Value::Bool(false))),
            ("velocity", Some(Value::Num(100.0))),
            DYN[1],
            DYN[2],
            DYN[3],
            ("position_controlled", Some(Value::Bool(true))),
        ],
    },
    InstructionSpec {
        name: "MC_MoveSuperimposed",
        params: &[
            ("distance", None),
            ("velocity_diff", Some(Value::Num(-1.0))),
            DYN[1],
            DYN[2],
            DYN[3],
        ],
    },
    InstructionSpec {
        name: "MC_SetOverride",
        params: &[("velocity", None)],
    },
    // A run-time parameter of the axis by its S7-1500T tag name or number
    // (docs/parameters.md); a boolean value as true/false or 1/0.
    InstructionSpec {
        name: "MC_WriteParameter",
        params: &[("tag", None), ("value", None)],
    },
    InstructionSpec {
        name: "MC_ReadParameter",
        params: &[("tag", None)],
    },
    // The Beckhoff hydraulic library's MC_Power with the feed enables of the two directions.
    InstructionSpec {
        name: "MC_Power_BkPlcMc",
        params: &[
            ("enable", Some(Value::Bool(true))),
            ("enable_positive", Some(Value::Bool(true))),
            ("enable_negative", Some(Value::Bool(true))),
        ],
    },
    // The Beckhoff hydraulic library's pressure or force controller (a hydraulic axis with
    // pressure inputs).
    InstructionSpec {
        name: "MC_AxCtrlPressure_BkPlcMc",
        params: &[
            ("enable", Some(Value::Bool(true))),
            ("set_value", Some(Value::Num(0.0))),
            ("kp", Some(Value::Num(0.0))),
            ("tn", Some(Value::Num(0.0))),
            ("preset", Some(Value::Num(0.0))),
            ("windup_limit", Some(Value::Num(1.0))),
            ("force", Some(Value::Bool(true))),
        ],
    },
    // The Beckhoff hydraulic library's PID pressure or force controller with feed-forward
    // (`ST_TcPctrlParam` in the same entry; `reset` is TRUE by default as in the library: a
    // script sets it false to run the controller).
    InstructionSpec {
        name: "MC_AxCtrlPressureFF_BkPlcMc",
        params: &[
            ("enable", Some(Value::Bool(true))),
            ("reset", Some(Value::Bool(true))),
            ("enable_p", Some(Value::Bool(true))),
            ("enable_i", Some(Value::Bool(true))),
            ("enable_d", Some(Value::Bool(true))),
            ("setpoint", Some(Value::Num(0.0))),
            ("feed_velocity", Some(Value::Num(0.0))),
            ("feed_charge", Some(Value::Num(0.0))),
            ("kp", Some(Value::Num(0.0))),
            ("tn", Some(Value::Num(0.0))),
            ("tv", Some(Value::Num(0.0))),
            ("preset", Some(Value::Num(0.0))),
            ("windup_limit", Some(Value::Num(1.0))),
            ("nf", Some(Value::Num(0.0))),
            ("align_areas", Some(Value::Bool(false))),
            ("force", Some(Value::Bool(true))),
        ],
    },
    // The Beckhoff hydraulic library's automatic zero compensation (defaults:
    // `AutoZeroParams::DEFAULT`).
    InstructionSpec {
        name: "MC_AxCtrlAutoZero_BkPlcMc",
        params: &[
            ("enable", Some(Value::Bool(true))),
            (
                "enable_on_moving",
                Some(Value::Bool(AUTO_ZERO.enable_on_moving)),
            ),
            ("offset_limit", Some(Value::Num(AUTO_ZERO.offset_limit))),
            ("tn", Some(Value::Num(AUTO_ZERO.tn))),
            ("threshold", Some(Value::Num(AUTO_ZERO.threshold))),
            ("filter", Some(Value::Num(AUTO_ZERO.filter))),
        ],
    },
    // The Beckhoff hydraulic library's slowing down on pressure: `set_point` (bar, or N with
    // `force`; its sign the working direction), `kp` (mm/s per bar or N).
    InstructionSpec {
        name: "MC_AxCtrlSlowDownOnPressureEx_BkPlcMc",
        params: &[
            ("enable", Some(Value::Bool(true))),
            ("enable_relief", Some(Value::Bool(false))),
            ("set_point", None),
            ("kp", None),
            ("feed_velocity", Some(Value::Num(0.0))),
            ("force", Some(Value::Bool(true))),
        ],
    },
    // The Beckhoff hydraulic library's stops (a hydraulic axis): `execute = false` releases the
    // lock of MC_EmergencyStop_BkPlcMc / MC_ImmediateStop_BkPlcMc; ramp_time 0: the
    // parameter's ramp.
    InstructionSpec {
        name: "MC_EmergencyStop_BkPlcMc",
        params: &[
            ("execute", Some(Value::Bool(true))),
            ("ramp_time", Some(Value::Num(0.0))),
        ],
    },
    InstructionSpec {
        name: "MC_ImmediateStop_BkPlcMc",
        params: &[("execute", Some(Value::Bool(true)))],
    },
    InstructionSpec {
        name: "MC_RampedStop_BkPlcMc",
        params: &[("ramp_time", Some(Value::Num(0.0)))],
    },
    InstructionSpec {
        name: "MC_ResetAndStop_BkPlcMc",
        params: &[
            ("deceleration", Some(Value::Num(0.0))),
            ("ramp_time", Some(Value::Num(0.0))),
        ],
    },
    // The Beckhoff hydraulic library's jog: level inputs re-sent with their values; mode 0
    // STANDARD_SLOW, 1 STANDARD_FAST, 2 CONTINUOUS, 3 INCHING (by `position`).
    InstructionSpec {
        name: "MC_MoveJog_BkPlcMc",
        params: &[
            ("jog_forward", Some(Value::Bool(false))),
            ("jog_backwards", Some(Value::Bool(false))),
            ("mode", Some(Value::Num(0.0))),
            ("position", Some(Value::Num(0.0))),
            ("velocity", Some(Value::Num(0.0))),
            ("acceleration", Some(Value::Num(0.0))),
            ("deceleration", Some(Value::Num(0.0))),
            ("jerk", Some(Value::Num(0.0))),
        ],
    },
    // The Beckhoff hydraulic library's MC_SetPosition (mode TRUE: relative) and
    // MC_SetReferenceFlag.
    InstructionSpec {
        name: "MC_SetPosition_BkPlcMc",
        params: &[("position", None), ("mode", Some(Value::Bool(false)))],
    },
    InstructionSpec {
        name: "MC_MoveJoySticked_BkPlcMc",
        params: &[
            ("execute", Some(Value::Bool(true))),
            ("joystick", Some(Value::Num(0.0))),
            ("acceleration", Some(Value::Num(0.0))),
            ("deceleration", Some(Value::Num(0.0))),
        ],
    },
    // MC_Home_BkPlcMc: `homing_mode` as MC_HomingMode_BkPlcMc (0 Default, 1 AbsSwitch,
    // 2 LimitSwitch, 3 RefPulse, 4 Direct, 5 Absolute, 6 Block, 7 FlyingSwitch, 8
    // FlyingRefPulse); without `position` the axis' fEnc_DefaultHomePosition.
    InstructionSpec {
        name: "MC_Home_BkPlcMc",
        params: &[
            ("execute", Some(Value::Bool(true))),
            ("position", None),
            ("homing_mode", Some(Value::Num(0.0))),
            ("calibration_cam", Some(Value::Bool(false))),
        ],
    },
    // The Beckhoff hydraulic library's direct output and external set values: level inputs
    // re-sent with their current values (`enable = false` ends them).
    InstructionSpec {
        name: "MC_AxRtSetDirectOutput_BkPlcMc",
        params: &[
            ("enable", Some(Value::Bool(true))),
            ("out_value", Some(Value::Num(0.0))),
            ("ramp_time", Some(Value::Num(0.0))),
        ],
    },
    InstructionSpec {
        name: "MC_AxRtSetExtGenValues_BkPlcMc",
        params: &[
            ("enable", Some(Value::Bool(true))),
            ("position", Some(Value::Num(0.0))),
            ("velocity", Some(Value::Num(0.0))),
            ("target_position", Some(Value::Num(0.0))),
        ],
    },
    InstructionSpec {
        name: "MC_AxRtFollowUp_BkPlcMc",
        params: &[("enable", Some(Value::Bool(true)))],
    },
    InstructionSpec {
        name: "MC_AxUtiOffsetLatch_BkPlcMc",
        params: &[
            ("execute", Some(Value::Bool(true))),
            ("offset_limit", Some(Value::Num(0.5))),
        ],
    },
    InstructionSpec {
        name: "MC_SetReferenceFlag_BkPlcMc",
        params: &[("reference_flag", Some(Value::Bool(true)))],
    },
    InstructionSpec {
        name: "MC_MotionInPosition",
        params: &[
            ("enable", Some(Value::Bool(true))),
            ("position", None),
            ("velocity", Some(Value::Num(0.0))),
            ("acceleration", Some(Value::Num(0.0))),
        ],
    },
    InstructionSpec {
        name: "MC_MotionInVelocity",
        params: &[
            ("enable", Some(Value::Bool(true))),
            ("velocity", Some(Value::Num(0.0))),
            ("acceleration", Some(Value::Num(0.0))),
            ("position_controlled", Some(Value::Bool(true))),
        ],
    },
    InstructionSpec {
        name: "MC_TorqueLimiting",
        params: &[
            ("enable", Some(Value::Bool(true))),
            ("limit", Some(Value::Num(-1.0))),
            ("mode", Some(Value::Num(0.0))),
        ],
    },
    InstructionSpec {
        name: "MC_TorqueAdditive",
        params: &[
            ("enable", Some(Value::Bool(true))),
            ("value", Some(Value::Num(0.0))),
        ],
    },
    InstructionSpec {
        name: "MC_TorqueRange",
        params: &[
            ("enable", Some(Value::Bool(true))),
            ("upper_limit", Some(Value::Num(1e12))),
            ("lower_limit", Some(Value::Num(-1e12))),
        ],
    },
    InstructionSpec {
        name: "MC_GearIn",
        params: &[
            ("ratio_numerator", Some(Value::Num(1.0))),
            ("ratio_denominator", Some(Value::Num(1.0))),
            DYN[1],
            DYN[2],
            DYN[3],
        ],
    },
    InstructionSpec {
        name: "MC_GearInPos",
        params: &[
            ("ratio_numerator", Some(Value::Num(1.0))),
            ("ratio_denominator", Some(Value::Num(1.0))),
            ("master_sync_position", None),
            ("slave_sync_position", None),
            ("sync_profile_reference", Some(Value::Num(1.0))),
            ("master_start_distance", Some(Value::Num(1.0))),
            DYN[0],
            DYN[1],
            DYN[2],
            DYN[3],
            ("sync_direction", Some(Value::Num(3.0))),
        ],
    },
    InstructionSpec {
        name: "MC_FlyingGear_BkPlcMc",
        params: &[
            ("enable", Some(Value::Bool(true))),
            ("ratio", Some(Value::Num(1.0))),
            ("master_sync_position", None),
            ("slave_sync_position", None),
            ("slave_desync_position", None),
            ("slave_stop_position", None),
            ("default_slave_negative", Some(Value::Bool(false))),
        ],
    },
    InstructionSpec {
        name: "MC_GearOut",
        params: &[],
    },
    InstructionSpec {
        name: "MC_GearInVelocity",
        params: &[
            ("ratio_numerator", Some(Value::Num(1.0))),
            ("ratio_denominator", Some(Value::Num(1.0))),
            DYN[1],
            DYN[2],
            DYN[3],
        ],
    },
    InstructionSpec {
        name: "MC_OffsetAbsolute",
        params: &[("offset", None), DYN[0], DYN[1], DYN[2], DYN[3]],
    },
    InstructionSpec {
        name: "MC_OffsetRelative",
        params: &[("offset", None), DYN[0], DYN[1], DYN[2], DYN[3]],
    },
    InstructionSpec {
        name: "MC_CamIn",
        params: &[
            ("master_offset", Some(Value::Num(0.0))),
            ("slave_offset", Some(Value::Num(0.0))),
            ("master_scaling", Some(Value::Num(1.0))),
            ("slave_scaling", Some(Value::Num(1.0))),
            ("master_sync_position", Some(Value::Num(0.0))),
            ("sync_profile_reference", Some(Value::Num(1.0))),
            ("master_start_distance", Some(Value::Num(0.0))),
            DYN[0],
            DYN[1],
            DYN[2],
            DYN[3],
            ("application_mode", Some(Value::Num(0.0))),
            ("sync_direction", Some(Value::Num(3.0))),
        ],
    },
    InstructionSpec {
        name: "MC_CamOut",
        params: &[],
    },
    InstructionSpec {
        name: "MC_SynchronizedMotionSimulation",
        params: &[("enable", Some(Value::Bool(true)))],
    },
    InstructionSpec {
        name: "MC_PhasingAbsolute",
        params: &[("phase_shift", None), DYN[0], DYN[1], DYN[2], DYN[3]],
    },
    InstructionSpec {
        name: "MC_PhasingRelative",
        params: &[("phase_shift", None), DYN[0], DYN[1], DYN[2], DYN[3]],
    },
];

/// Instructions that name a leader (`master = "<axis>"`).
pub fn needs_master(spec: &InstructionSpec) -> bool {
    matches!(
        spec.name,
        "MC_GearIn" | "MC_GearInPos" | "MC_GearInVelocity" | "MC_CamIn" | "MC_FlyingGear_BkPlcMc"
    )
}

/// Instructions that name a cam (`cam = "<name>"`).
pub fn needs_cam(spec: &InstructionSpec) -> bool {
    spec.name == "MC_CamIn"
}

/// The objects an instruction names, resolved by the caller.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct Refs {
    /// The leader (`master`).
    pub master: Option<LeaderId>,
    /// The cam (`cam`).
    pub cam: Option<CamId>,
}

/// An instruction name without `MC_`, underscores, dashes or case.
pub fn normalize(s: &str) -> String {
    let s = s.to_ascii_lowercase().replace(['_', '-'], "");
    s.strip_prefix("mc").map(str::to_string).unwrap_or(s)
}

/// Finds an instruction by any accepted spelling.
pub fn find(name: &str) -> Option<&'static InstructionSpec> {
    let n = normalize(name);
    INSTRUCTIONS.iter().find(|i| normalize(i.name) == n)
}

/// The type a parameter must have.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Expected {
    /// A number.
    Number,
    /// `true` or `false`.
    Bool,
    /// A whole number.
    Integer,
    /// A number or `true`/`false`.
    NumberOrBool,
}

impl fmt::Display for Expected {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Expected::Number => "a number",
            Expected::Bool => "true or false",
            Expected::Integer => "an integer",
            Expected::NumberOrBool => "a number or true/false",
        })
    }
}

/// What is wrong with an instruction as written (in a script entry or on a command line).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CommandError {
    /// No instruction has this name in any spelling.
    UnknownInstruction(String),
    /// A parameter the instruction does not have.
    UnknownParameter {
        /// The instruction (PLCopen name).
        instruction: &'static str,
        /// The parameter given.
        name: String,
        /// The instruction's parameters.
        known: Vec<&'static str>,
    },
    /// A required parameter without a value.
    MissingParameter {
        /// The instruction.
        instruction: &'static str,
        /// The parameter.
        param: &'static str,
    },
    /// A required reference to an object (`master`, `cam`) without a value.
    MissingReference {
        /// The instruction.
        instruction: &'static str,
        /// The parameter.
        param: &'static str,
        /// What it names.
        what: &'static str,
    },
    /// A value of the wrong type.
    WrongType {
        /// The instruction, when the message names it.
        instruction: Option<&'static str>,
        /// The parameter.
        param: String,
        /// The type it must have.
        expected: Expected,
    },
    /// A code outside the values the parameter accepts.
    BadValue {
        /// The instruction.
        instruction: &'static str,
        /// The parameter.
        param: &'static str,
        /// The values it accepts.
        allowed: &'static str,
    },
    /// An instruction the command parser does not build.
    NoParser(&'static str),
    /// A name that refers to no object of its kind.
    UnknownObject {
        /// The instruction, when the message names it.
        instruction: Option<&'static str>,
        /// The kind of object (`axis`, `cam`, `master`, `output cam`...).
        what: &'static str,
        /// The name given.
        name: String,
        /// The names the cell has.
        known: Vec<String>,
    },
    /// An axis that names itself as its leader.
    SelfFollow(String),
    /// A reference that is not a name.
    NotAName {
        /// The parameter.
        param: &'static str,
        /// What it must name.
        what: &'static str,
    },
    /// A key every entry needs.
    MissingKey {
        /// The key.
        key: &'static str,
        /// What it gives, when the message says it.
        hint: Option<&'static str>,
    },
    /// A command-line parameter name that is not a plain name.
    BadParameterName(String),
    /// A command-line parameter that is a key of the entry, not of the instruction.
    ReservedParameter(String),
    /// A command line that gave no entry.
    NotUnderstood(String),
    /// An empty command line.
    Empty,
    /// A command line with an object and no instruction.
    NoInstruction(String),
    /// A command-line word where `--parameter` was expected.
    ExpectedParameter(String),
    /// A command-line parameter without a value.
    MissingValue(String),
}

impl fmt::Display for CommandError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CommandError::UnknownInstruction(name) => {
                let names: Vec<&str> = INSTRUCTIONS.iter().map(|i| i.name).collect();
                write!(
                    f,
                    "unknown instruction `{name}`; known: {}",
                    names.join(", ")
                )
            }
            CommandError::UnknownParameter {
                instruction,
                name,
                known,
            } => write!(
                f,
                "{instruction}: unknown parameter `{name}`; parameters: {}",
                known.join(", ")
            ),
            CommandError::MissingParameter { instruction, param } => {
                write!(f, "{instruction}: parameter `{param}` is required")
            }
            CommandError::MissingReference {
                instruction,
                param,
                what,
            } => write!(f, "{instruction}: parameter `{param}` ({what}) is required"),
            CommandError::WrongType {
                instruction,
                param,
                expected,
            } => {
                if let Some(i) = instruction {
                    write!(f, "{i}: ")?;
                }
                write!(f, "`{param}` must be {expected}")
            }
            CommandError::BadValue {
                instruction,
                param,
                allowed,
            } => write!(f, "{instruction}: {param} must be {allowed}"),
            CommandError::NoParser(i) => write!(f, "instruction `{i}` has no parser"),
            CommandError::UnknownObject {
                instruction,
                what,
                name,
                known,
            } => {
                if let Some(i) = instruction {
                    write!(f, "{i}: ")?;
                }
                write!(
                    f,
                    "unknown {what} `{name}`; the cell has: {}",
                    known.join(", ")
                )
            }
            CommandError::SelfFollow(axis) => write!(f, "axis `{axis}` cannot follow itself"),
            CommandError::NotAName { param, what } => write!(f, "`{param}` must be {what}"),
            CommandError::MissingKey { key, hint } => match hint {
                Some(h) => write!(f, "`{key}` ({h}) is required"),
                None => write!(f, "`{key}` is required"),
            },
            CommandError::BadParameterName(k) => write!(f, "`--{k}` is not a parameter name"),
            CommandError::ReservedParameter(k) => {
                write!(f, "`--{k}` is not a parameter of an instruction")
            }
            CommandError::NotUnderstood(i) => write!(f, "`{i}` was not understood"),
            CommandError::Empty => f.write_str("empty command"),
            CommandError::NoInstruction(o) => write!(f, "`{o}`: no instruction given"),
            CommandError::ExpectedParameter(w) => write!(f, "`{w}`: expected `--parameter value`"),
            CommandError::MissingValue(k) => write!(f, "`--{k}` needs a value"),
        }
    }
}

impl std::error::Error for CommandError {}

/// The parameters given to one instruction, read with its defaults.
struct Args<'a> {
    spec: &'static InstructionSpec,
    given: &'a [(String, Value)],
}

impl Args<'_> {
    fn get(&self, key: &'static str) -> Result<Value, CommandError> {
        if let Some((_, v)) = self.given.iter().rev().find(|(k, _)| k == key) {
            return Ok(*v);
        }
        match self.spec.params.iter().find(|(k, _)| *k == key) {
            Some((_, Some(d))) => Ok(*d),
            _ => Err(CommandError::MissingParameter {
                instruction: self.spec.name,
                param: key,
            }),
        }
    }

    fn wrong(&self, key: &'static str, expected: Expected) -> CommandError {
        CommandError::WrongType {
            instruction: Some(self.spec.name),
            param: key.to_string(),
            expected,
        }
    }

    fn num(&self, key: &'static str) -> Result<f64, CommandError> {
        match self.get(key)? {
            Value::Num(x) => Ok(x),
            Value::Bool(_) => Err(self.wrong(key, Expected::Number)),
        }
    }

    /// A number that may be left out (`None`).
    fn optional_num(&self, key: &'static str) -> Result<Option<f64>, CommandError> {
        match self.given.iter().rev().find(|(k, _)| k == key) {
            Some(_) => self.num(key).map(Some),
            None => Ok(None),
        }
    }

    fn flag(&self, key: &'static str) -> Result<bool, CommandError> {
        match self.get(key)? {
            Value::Bool(b) => Ok(b),
            Value::Num(_) => Err(self.wrong(key, Expected::Bool)),
        }
    }

    fn code(&self, key: &'static str) -> Result<i32, CommandError> {
        let x = self.num(key)?;
        if x.fract() != 0.0 || !(-1e6..=1e6).contains(&x) {
            return Err(self.wrong(key, Expected::Integer));
        }
        Ok(x as i32)
    }

    /// A code mapped to a value by `table`, or [`CommandError::BadValue`] naming `allowed`.
    fn choice<T: Copy>(
        &self,
        key: &'static str,
        table: &[(i32, T)],
        allowed: &'static str,
    ) -> Result<T, CommandError> {
        let c = self.code(key)?;
        table
            .iter()
            .find(|(k, _)| *k == c)
            .map(|(_, v)| *v)
            .ok_or(CommandError::BadValue {
                instruction: self.spec.name,
                param: key,
                allowed,
            })
    }

    /// `tag`: the parameter number (a tag name was mapped to it by [`named_value`]); a number
    /// the axis does not have is passed on as 0, which the axis refuses with 16#8080.
    fn parameter(&self) -> Result<u16, CommandError> {
        Ok(u16::try_from(self.code("tag")?).unwrap_or(0))
    }

    /// `buffer_mode`: the PLCopen number (a name was mapped to it by [`named_value`]).
    fn buffer_mode(&self) -> Result<BufferMode, CommandError> {
        BufferMode::from_code(self.code("buffer_mode")?).ok_or(CommandError::BadValue {
            instruction: self.spec.name,
            param: "buffer_mode",
            allowed: BUFFER_MODES,
        })
    }

    fn dynamics_no_velocity(&self) -> Result<Dynamics, CommandError> {
        Ok(Dynamics {
            velocity: -1.0,
            acceleration: self.num("acceleration")?,
            deceleration: self.num("deceleration")?,
            jerk: self.num("jerk")?,
        })
    }

    fn dynamics(&self, vel_key: &'static str) -> Result<Dynamics, CommandError> {
        Ok(Dynamics {
            velocity: self.num(vel_key)?,
            acceleration: self.num("acceleration")?,
            deceleration: self.num("deceleration")?,
            jerk: self.num("jerk")?,
        })
    }

    fn sync_direction(&self) -> Result<SyncDirection, CommandError> {
        self.choice(
            "sync_direction",
            &[
                (1, SyncDirection::Positive),
                (2, SyncDirection::Negative),
                (3, SyncDirection::Shortest),
            ],
            "1, 2 or 3",
        )
    }

    fn ratio(&self) -> Result<(i32, i32), CommandError> {
        Ok((
            self.code("ratio_numerator")?,
            self.code("ratio_denominator")?,
        ))
    }
}

/// The values `buffer_mode` accepts.
const BUFFER_MODES: &str = "0..5 or Aborting, Buffered, BlendingLow, BlendingPrevious, \
     BlendingNext, BlendingHigh";

/// The number a parameter given as a name stands for: `buffer_mode = "BlendingLow"` is 2 (the
/// PLCopen names, with or without `mc`, and S7-Technology's `override`, `append`, `blend`);
/// `tag = "DynamicLimits.MaxJerk"` is that tag's parameter number.
/// `None` for other parameters and unknown names (the value is then refused as not a number).
pub fn named_value(param: &str, name: &str) -> Option<Value> {
    match param {
        "buffer_mode" => BufferMode::from_name(name).map(|m| Value::Num(f64::from(m.code()))),
        // An S7-1500T tag name (`DynamicLimits.MaxJerk`); an unknown one is number 0, refused
        // by the axis with the reference's ErrorID (16#8080) like an unknown number.
        "tag" => Some(Value::Num(f64::from(
            axis_parameter_number(name).unwrap_or(0),
        ))),
        _ => None,
    }
}

/// A queued motion job, or the plain command for [`BufferMode::Aborting`] (unchanged).
fn with_buffer_mode(motion: BufferedMotion, buffer_mode: BufferMode) -> Command {
    if buffer_mode == BufferMode::Aborting {
        motion.aborting()
    } else {
        Command::Buffered {
            motion,
            buffer_mode,
        }
    }
}

/// The instruction named `instruction`, with every given parameter checked against its list.
fn spec_of(
    instruction: &str,
    params: &[(String, Value)],
) -> Result<&'static InstructionSpec, CommandError> {
    let spec =
        find(instruction).ok_or_else(|| CommandError::UnknownInstruction(instruction.into()))?;
    if let Some((k, _)) = params
        .iter()
        .find(|(k, _)| !spec.params.iter().any(|(p, _)| p == k))
    {
        return Err(CommandError::UnknownParameter {
            instruction: spec.name,
            name: k.clone(),
            known: spec.params.iter().map(|(p, _)| *p).collect(),
        });
    }
    Ok(spec)
}

/// Builds a command. Unknown instructions and parameters, missing required parameters and
/// values of the wrong type are errors naming what was wrong. `master` is the leader the
/// instruction names (resolved by the caller), for the instructions that need one.
pub fn parse(
    instruction: &str,
    params: &[(String, Value)],
    refs: Refs,
) -> Result<Command, CommandError> {
    let spec = spec_of(instruction, params)?;
    let a = Args {
        spec,
        given: params,
    };
    match sync_command(&a, refs)? {
        Some(c) => Ok(c),
        None => single_axis_command(&a),
    }
}

/// The synchronous operation instructions (gearing, camming, offset, phasing); `None` for the
/// others.
fn sync_command(a: &Args<'_>, refs: Refs) -> Result<Option<Command>, CommandError> {
    let name = a.spec.name;
    let leader = || {
        refs.master.ok_or(CommandError::MissingReference {
            instruction: name,
            param: "master",
            what: "the leading axis",
        })
    };
    Ok(Some(match name {
        "MC_GearIn" | "MC_GearInVelocity" => {
            let master = leader()?;
            let (ratio_numerator, ratio_denominator) = a.ratio()?;
            let dynamics = a.dynamics_no_velocity()?;
            if name == "MC_GearIn" {
                Command::GearIn {
                    master,
                    ratio_numerator,
                    ratio_denominator,
                    dynamics,
                }
            } else {
                Command::GearInVelocity {
                    master,
                    ratio_numerator,
                    ratio_denominator,
                    dynamics,
                }
            }
        }
        "MC_GearInPos" => gear_in_pos(a, leader()?)?,
        "MC_FlyingGear_BkPlcMc" => Command::FlyingGear {
            master: leader()?,
            enable: a.flag("enable")?,
            params: FlyingGearParams {
                ratio: a.num("ratio")?,
                master_sync_position: a.num("master_sync_position")?,
                slave_sync_position: a.num("slave_sync_position")?,
                slave_desync_position: a.num("slave_desync_position")?,
                slave_stop_position: a.num("slave_stop_position")?,
                default_slave_negative: a.flag("default_slave_negative")?,
            },
        },
        "MC_GearOut" => Command::GearOut,
        "MC_CamIn" => {
            let master = leader()?;
            let cam = refs.cam.ok_or(CommandError::MissingReference {
                instruction: name,
                param: "cam",
                what: "the cam's name",
            })?;
            cam_in(a, master, cam)?
        }
        "MC_CamOut" => Command::CamOut,
        "MC_SynchronizedMotionSimulation" => Command::SynchronizedMotionSimulation {
            enable: a.flag("enable")?,
        },
        "MC_OffsetAbsolute" | "MC_OffsetRelative" => Command::Offset {
            offset: a.num("offset")?,
            absolute: name == "MC_OffsetAbsolute",
            dynamics: a.dynamics("velocity")?,
        },
        "MC_PhasingAbsolute" | "MC_PhasingRelative" => Command::Phasing {
            phase_shift: a.num("phase_shift")?,
            absolute: name == "MC_PhasingAbsolute",
            dynamics: a.dynamics("velocity")?,
        },
        _ => return Ok(None),
    }))
}

/// MC_GearInPos with its leader.
fn gear_in_pos(a: &Args<'_>, master: LeaderId) -> Result<Command, CommandError> {
    let (ratio_numerator, ratio_denominator) = a.ratio()?;
    Ok(Command::GearInPos {
        master,
        ratio_numerator,
        ratio_denominator,
        master_sync_position: a.num("master_sync_position")?,
        slave_sync_position: a.num("slave_sync_position")?,
        sync_profile_reference: a.choice(
            "sync_profile_reference",
            &[
                (0, SyncProfileReference::Dynamics),
                (1, SyncProfileReference::MasterStartDistance),
            ],
            "0 or 1",
        )?,
        master_start_distance: a.num("master_start_distance")?,
        dynamics: a.dynamics("velocity")?,
        sync_direction: a.sync_direction()?,
    })
}

/// MC_CamIn with its leader and cam.
fn cam_in(a: &Args<'_>, master: LeaderId, cam: CamId) -> Result<Command, CommandError> {
    Ok(Command::CamIn {
        master,
        cam,
        master_offset: a.num("master_offset")?,
        slave_offset: a.num("slave_offset")?,
        master_scaling: a.num("master_scaling")?,
        slave_scaling: a.num("slave_scaling")?,
        master_sync_position: a.num("master_sync_position")?,
        sync_profile_reference: a.choice(
            "sync_profile_reference",
            &[
                (0, SyncProfileReference::Dynamics),
                (1, SyncProfileReference::MasterStartDistance),
                (2, SyncProfileReference::Direct),
            ],
            "0, 1 or 2",
        )?,
        master_start_distance: a.num("master_start_distance")?,
        dynamics: a.dynamics("velocity")?,
        application_mode: a.choice(
            "application_mode",
            &[
                (0, ApplicationMode::Once),
                (1, ApplicationMode::Cyclic),
                (2, ApplicationMode::CyclicAppending),
            ],
            "0, 1 or 2",
        )?,
        sync_direction: a.sync_direction()?,
    })
}

/// The positioning and velocity jobs that take a `buffer_mode` (MC_MoveAbsolute, MC_MoveRelative,
/// MC_MoveAdditive, MC_MoveVelocity); `None` for another instruction.
fn buffered_move(a: &Args<'_>) -> Result<Option<Command>, CommandError> {
    let name = a.spec.name;
    let bad = |param: &'static str, allowed: &'static str| CommandError::BadValue {
        instruction: name,
        param,
        allowed,
    };
    Ok(Some(match name {
        "MC_MoveAbsolute" => with_buffer_mode(
            BufferedMotion::MoveAbsolute {
                position: a.num("position")?,
                dynamics: a.dynamics("velocity")?,
                direction: Direction::from_code(a.code("direction")?)
                    .ok_or(bad("direction", "1, 2 or 3"))?,
            },
            a.buffer_mode()?,
        ),
        "MC_MoveRelative" => with_buffer_mode(
            BufferedMotion::MoveRelative {
                distance: a.num("distance")?,
                dynamics: a.dynamics("velocity")?,
            },
            a.buffer_mode()?,
        ),
        "MC_MoveAdditive" => with_buffer_mode(
            BufferedMotion::MoveAdditive {
                distance: a.num("distance")?,
                dynamics: a.dynamics("velocity")?,
            },
            a.buffer_mode()?,
        ),
        "MC_MoveVelocity" => with_buffer_mode(
            BufferedMotion::MoveVelocity {
                dynamics: a.dynamics("velocity")?,
                direction: VelocityDirection::from_code(a.code("direction")?)
                    .ok_or(bad("direction", "0, 1 or 2"))?,
                current: a.flag("current")?,
                position_controlled: a.flag("position_controlled")?,
            },
            a.buffer_mode()?,
        ),
        _ => return Ok(None),
    }))
}

/// The Beckhoff hydraulic library's single-axis instructions (`*_BkPlcMc`: power, stops, jog,
/// homing, positions; the controllers through [`hydraulic_control_command`]); `None` for
/// another.
fn hydraulic_command(a: &Args<'_>) -> Result<Option<Command>, CommandError> {
    Ok(Some(match a.spec.name {
        "MC_Power_BkPlcMc" => Command::HydPower {
            enable: a.flag("enable")?,
            enable_positive: a.flag("enable_positive")?,
            enable_negative: a.flag("enable_negative")?,
        },
        "MC_EmergencyStop_BkPlcMc" => Command::EmergencyStop {
            execute: a.flag("execute")?,
            ramp_time: a.num("ramp_time")?,
        },
        "MC_ImmediateStop_BkPlcMc" => Command::ImmediateStop {
            execute: a.flag("execute")?,
        },
        "MC_RampedStop_BkPlcMc" => Command::RampedStop {
            ramp_time: a.num("ramp_time")?,
        },
        "MC_ResetAndStop_BkPlcMc" => Command::ResetAndStop {
            deceleration: a.num("deceleration")?,
            ramp_time: a.num("ramp_time")?,
        },
        "MC_MoveJog_BkPlcMc" => Command::HydMoveJog {
            forward: a.flag("jog_forward")?,
            backward: a.flag("jog_backwards")?,
            mode: a.choice(
                "mode",
                &[
                    (0, HydJogMode::StandardSlow),
                    (1, HydJogMode::StandardFast),
                    (2, HydJogMode::Continuous),
                    (3, HydJogMode::Inching),
                ],
                "0 STANDARD_SLOW, 1 STANDARD_FAST, 2 CONTINUOUS, 3 INCHING",
            )?,
            position: a.num("position")?,
            dynamics: a.dynamics("velocity")?,
        },
        "MC_SetPosition_BkPlcMc" => Command::HydSetPosition {
            position: a.num("position")?,
            relative: a.flag("mode")?,
        },
        "MC_MoveJoySticked_BkPlcMc" => Command::MoveJoySticked {
            execute: a.flag("execute")?,
            joystick: a.num("joystick")?,
            acceleration: a.num("acceleration")?,
            deceleration: a.num("deceleration")?,
        },
        "MC_Home_BkPlcMc" => Command::HydHome(HydHomeInputs {
            execute: a.flag("execute")?,
            position: a.optional_num("position")?,
            mode: HydHomingMode::from_number(a.code("homing_mode")?).ok_or(
                CommandError::BadValue {
                    instruction: a.spec.name,
                    param: "homing_mode",
                    allowed: "0 Default, 1 AbsSwitch, 2 LimitSwitch, 3 RefPulse, 4 Direct, \
                              5 Absolute, 6 Block, 7 FlyingSwitch, 8 FlyingRefPulse",
                },
            )?,
            calibration_cam: a.flag("calibration_cam")?,
        }),
        "MC_SetReferenceFlag_BkPlcMc" => Command::SetReferenceFlag {
            reference_flag: a.flag("reference_flag")?,
        },
        _ => return hydraulic_control_command(a),
    }))
}

/// MC_AxCtrlPressureFF_BkPlcMc with its `ST_TcPctrlParam` (an `nf` outside 0..65535 stands
/// as 65535, which the axis refuses with the other values out of range).
fn pressure_ff_command(a: &Args<'_>) -> Result<Command, CommandError> {
    use tandem_motion::hydraulic::pressure::PressureReading;
    use tandem_motion::hydraulic::pressure_ff::{PctrlParams, PidInputs};
    Ok(Command::PressureControlFf {
        enable: a.flag("enable")?,
        reset: a.flag("reset")?,
        inputs: PidInputs {
            enable_p: a.flag("enable_p")?,
            enable_i: a.flag("enable_i")?,
            enable_d: a.flag("enable_d")?,
            setpoint: a.num("setpoint")?,
            feed_velocity: a.num("feed_velocity")?,
            feed_charge: a.num("feed_charge")?,
        },
        params: PctrlParams {
            kp: a.num("kp")?,
            tn: a.num("tn")?,
            tv: a.num("tv")?,
            preset: a.num("preset")?,
            windup_limit: a.num("windup_limit")?,
            nf: u16::try_from(a.code("nf")?).unwrap_or(u16::MAX),
            align_areas: a.flag("align_areas")?,
            reading: if a.flag("force")? {
                PressureReading::Force
            } else {
                PressureReading::Pressure
            },
        },
    })
}

/// The Beckhoff hydraulic library's controllers and set-value hooks (pressure, AutoZero,
/// slow-down, direct output, external set values, follow-up, offset latch); `None` for another.
fn hydraulic_control_command(a: &Args<'_>) -> Result<Option<Command>, CommandError> {
    Ok(Some(match a.spec.name {
        "MC_AxCtrlPressure_BkPlcMc" => Command::PressureControl {
            enable: a.flag("enable")?,
            set_value: a.num("set_value")?,
            kp: a.num("kp")?,
            tn: a.num("tn")?,
            preset: a.num("preset")?,
            windup_limit: a.num("windup_limit")?,
            force: a.flag("force")?,
        },
        "MC_AxCtrlPressureFF_BkPlcMc" => pressure_ff_command(a)?,
        "MC_AxCtrlAutoZero_BkPlcMc" => Command::AutoZero {
            enable: a.flag("enable")?,
            params: tandem_motion::hydraulic::auto_zero::AutoZeroParams {
                enable_on_moving: a.flag("enable_on_moving")?,
                offset_limit: a.num("offset_limit")?,
                tn: a.num("tn")?,
                threshold: a.num("threshold")?,
                filter: a.num("filter")?,
            },
        },
        "MC_AxCtrlSlowDownOnPressureEx_BkPlcMc" => Command::SlowDownOnPressure {
            enable: a.flag("enable")?,
            params: tandem_motion::hydraulic::slow_down::SlowDownParams {
                enable_relief: a.flag("enable_relief")?,
                set_point: a.num("set_point")?,
                kp: a.num("kp")?,
                feed_velocity: a.num("feed_velocity")?,
                reading: if a.flag("force")? {
                    tandem_motion::hydraulic::pressure::PressureReading::Force
                } else {
                    tandem_motion::hydraulic::pressure::PressureReading::Pressure
                },
            },
        },
        "MC_AxRtSetDirectOutput_BkPlcMc" => Command::SetDirectOutput {
            enable: a.flag("enable")?,
            out_value: a.num("out_value")?,
            ramp_time: a.num("ramp_time")?,
        },
        "MC_AxRtSetExtGenValues_BkPlcMc" => Command::SetExtGenValues {
            enable: a.flag("enable")?,
            position: a.num("position")?,
            velocity: a.num("velocity")?,
            target_position: a.num("target_position")?,
        },
        "MC_AxRtFollowUp_BkPlcMc" => Command::FollowUp {
            enable: a.flag("enable")?,
        },
        "MC_AxUtiOffsetLatch_BkPlcMc" => Command::OffsetLatch {
            execute: a.flag("execute")?,
            offset_limit: a.num("offset_limit")?,
        },
        _ => return Ok(None),
    }))
}

/// The single-axis instructions (power, homing, stop, moves, monitoring).
fn single_axis_command(a: &Args<'_>) -> Result<Command, CommandError> {
    if let Some(c) = buffered_move(a)? {
        return Ok(c);
    }
    if let Some(c) = hydraulic_command(a)? {
        return Ok(c);
    }
    let name = a.spec.name;
    let bad = |param: &'static str, allowed: &'static str| CommandError::BadValue {
        instruction: name,
        param,
        allowed,
    };
    Ok(match name {
        "MC_Power" => Command::Power {
            enable: a.flag("enable")?,
            start_mode: a.choice(
                "start_mode",
                &[
                    (0, StartMode::NonPositionControlled),
                    (1, StartMode::PositionControlled),
                ],
                "0 or 1",
            )?,
            stop_mode: a.choice(
                "stop_mode",
                &[
                    (0, StopMode::Emergency),
                    (1, StopMode::Immediate),
                    (2, StopMode::MaxDynamics),
                ],
                "0, 1 or 2",
            )?,
        },
        "MC_Reset" => Command::Reset {
            restart: a.flag("restart")?,
        },
        "MC_Home" => {
            let mode = a.code("mode")?;
            Command::Home {
                mode: u8::try_from(mode).map_err(|_| bad("mode", "0..10"))?,
                position: a.num("position")?,
            }
        }
        "MC_Halt" => Command::Halt {
            deceleration: a.num("deceleration")?,
            jerk: a.num("jerk")?,
            abort_acceleration: a.flag("abort_acceleration")?,
        },
        "MC_Stop" => Command::Stop {
            execute: a.flag("execute")?,
            deceleration: a.num("deceleration")?,
            jerk: a.num("jerk")?,
        },
        "MC_MoveJog" => Command::MoveJog {
            forward: a.flag("jog_forward")?,
            backward: a.flag("jog_backward")?,
            dynamics: a.dynamics("velocity")?,
            position_controlled: a.flag("position_controlled")?,
        },
        "MC_MoveSuperimposed" => Command::MoveSuperimposed {
            distance: a.num("distance")?,
            dynamics: a.dynamics("velocity_diff")?,
        },
        "MC_SetOverride" => Command::SetOverride {
            velocity: a.num("velocity")?,
        },
        other => return parameter_or_torque_command(a, other),
    })
}

/// MC_WriteParameter / MC_ReadParameter and the torque instructions (MC_TorqueLimiting,
/// MC_TorqueAdditive, MC_TorqueRange).
fn parameter_or_torque_command(a: &Args<'_>, name: &'static str) -> Result<Command, CommandError> {
    Ok(match name {
        "MC_WriteParameter" => Command::WriteParameter {
            parameter: a.parameter()?,
            value: match a.get("value")? {
                Value::Num(x) => x,
                Value::Bool(b) => f64::from(u8::from(b)),
            },
        },
        "MC_ReadParameter" => Command::ReadParameter {
            parameter: a.parameter()?,
        },
        "MC_MotionInPosition" => Command::MotionInPosition {
            enable: a.flag("enable")?,
            position: a.num("position")?,
            velocity: a.num("velocity")?,
            acceleration: a.num("acceleration")?,
        },
        "MC_MotionInVelocity" => Command::MotionInVelocity {
            enable: a.flag("enable")?,
            velocity: a.num("velocity")?,
            acceleration: a.num("acceleration")?,
            position_controlled: a.flag("position_controlled")?,
        },
        "MC_TorqueLimiting" => Command::TorqueLimiting {
            enable: a.flag("enable")?,
            limit: a.num("limit")?,
            mode: a.code("mode")?,
        },
        "MC_TorqueAdditive" => Command::TorqueAdditive {
            enable: a.flag("enable")?,
            value: a.num("value")?,
        },
        "MC_TorqueRange" => Command::TorqueRange {
            enable: a.flag("enable")?,
            upper_limit: a.num("upper_limit")?,
            lower_limit: a.num("lower_limit")?,
        },
        other => return Err(CommandError::NoParser(other)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(k: &str, v: Value) -> (String, Value) {
        (k.to_string(), v)
    }

    #[test]
    fn names_in_any_spelling() {
        for n in [
            "MC_MoveAbsolute",
            "moveabsolute",
            "move_absolute",
            "MOVE-ABSOLUTE",
        ] {
            assert_eq!(find(n).map(|s| s.name), Some("MC_MoveAbsolute"));
        }
        assert!(find("MC_Fly").is_none());
    }

    #[test]
    fn the_library_stops_and_set_position_take_their_inputs() {
        let c = parse("MC_EmergencyStop_BkPlcMc", &[], Refs::default()).unwrap();
        assert_eq!(
            c,
            Command::EmergencyStop {
                execute: true,
                ramp_time: 0.0
            }
        );
        let c = parse(
            "MC_ImmediateStop_BkPlcMc",
            &[p("execute", Value::Bool(false))],
            Refs::default(),
        )
        .unwrap();
        assert_eq!(c, Command::ImmediateStop { execute: false });
        let c = parse(
            "MC_RampedStop_BkPlcMc",
            &[p("ramp_time", Value::Num(1.5))],
            Refs::default(),
        )
        .unwrap();
        assert_eq!(c, Command::RampedStop { ramp_time: 1.5 });
        let c = parse(
            "MC_SetPosition_BkPlcMc",
            &[p("position", Value::Num(5.0)), p("mode", Value::Bool(true))],
            Refs::default(),
        )
        .unwrap();
        assert_eq!(
            c,
            Command::HydSetPosition {
                position: 5.0,
                relative: true
            }
        );
        assert!(parse("MC_SetPosition_BkPlcMc", &[], Refs::default()).is_err());
        let c = parse(
            "MC_MoveJog_BkPlcMc",
            &[
                p("jog_backwards", Value::Bool(true)),
                p("mode", Value::Num(3.0)),
                p("position", Value::Num(2.5)),
            ],
            Refs::default(),
        )
        .unwrap();
        assert_eq!(
            c,
            Command::HydMoveJog {
                forward: false,
                backward: true,
                mode: HydJogMode::Inching,
                position: 2.5,
                dynamics: Dynamics {
                    velocity: 0.0,
                    acceleration: 0.0,
                    deceleration: 0.0,
                    jerk: 0.0
                },
            }
        );
        assert!(parse(
            "MC_MoveJog_BkPlcMc",
            &[p("mode", Value::Num(4.0))],
            Refs::default()
        )
        .is_err());
        let c = parse(
            "MC_ResetAndStop_BkPlcMc",
            &[p("deceleration", Value::Num(100.0))],
            Refs::default(),
        )
        .unwrap();
        assert_eq!(
            c,
            Command::ResetAndStop {
                deceleration: 100.0,
                ramp_time: 0.0
            }
        );
        let c = parse("MC_SetReferenceFlag_BkPlcMc", &[], Refs::default()).unwrap();
        assert_eq!(
            c,
            Command::SetReferenceFlag {
                reference_flag: true
            }
        );
    }

    #[test]
    fn direct_output_and_external_set_values_take_the_library_inputs() {
        let c = parse(
            "MC_AxRtSetDirectOutput_BkPlcMc",
            &[
                p("out_value", Value::Num(-0.4)),
                p("ramp_time", Value::Num(0.5)),
            ],
            Refs::default(),
        )
        .unwrap();
        assert_eq!(
            c,
            Command::SetDirectOutput {
                enable: true,
                out_value: -0.4,
                ramp_time: 0.5
            }
        );
        let c = parse(
            "MC_AxRtSetExtGenValues_BkPlcMc",
            &[
                p("position", Value::Num(12.5)),
                p("velocity", Value::Num(30.0)),
                p("target_position", Value::Num(200.0)),
            ],
            Refs::default(),
        )
        .unwrap();
        assert_eq!(
            c,
            Command::SetExtGenValues {
                enable: true,
                position: 12.5,
                velocity: 30.0,
                target_position: 200.0
            }
        );
        let c = parse(
            "MC_AxRtSetExtGenValues_BkPlcMc",
            &[p("enable", Value::Bool(false))],
            Refs::default(),
        )
        .unwrap();
        assert_eq!(
            c,
            Command::SetExtGenValues {
                enable: false,
                position: 0.0,
                velocity: 0.0,
                target_position: 0.0
            }
        );
        assert!(parse(
            "MC_AxRtSetDirectOutput_BkPlcMc",
            &[p("enable", Value::Num(1.0))],
            Refs::default()
        )
        .is_err());
        let c = parse(
            "MC_AxRtFollowUp_BkPlcMc",
            &[p("enable", Value::Bool(false))],
            Refs::default(),
        )
        .unwrap();
        assert_eq!(c, Command::FollowUp { enable: false });
        let c = parse("MC_AxUtiOffsetLatch_BkPlcMc", &[], Refs::default()).unwrap();
        assert_eq!(
            c,
            Command::OffsetLatch {
                execute: true,
                offset_limit: 0.5
            }
        );
    }

    #[test]
    fn auto_zero_takes_the_library_inputs_with_defaults() {
        let c = parse(
            "MC_AxCtrlAutoZero_BkPlcMc",
            &[
                p("tn", Value::Num(20.0)),
                p("enable_on_moving", Value::Bool(true)),
            ],
            Refs::default(),
        )
        .unwrap();
        assert_eq!(
            c,
            Command::AutoZero {
                enable: true,
                params: tandem_motion::hydraulic::auto_zero::AutoZeroParams {
                    enable_on_moving: true,
                    tn: 20.0,
                    ..Default::default()
                },
            }
        );
    }

    #[test]
    fn slow_down_on_pressure_takes_the_library_inputs() {
        let c = parse(
            "MC_AxCtrlSlowDownOnPressureEx_BkPlcMc",
            &[
                p("set_point", Value::Num(10_000.0)),
                p("kp", Value::Num(0.01)),
            ],
            Refs::default(),
        )
        .unwrap();
        assert_eq!(
            c,
            Command::SlowDownOnPressure {
                enable: true,
                params: tandem_motion::hydraulic::slow_down::SlowDownParams {
                    enable_relief: false,
                    set_point: 10_000.0,
                    kp: 0.01,
                    feed_velocity: 0.0,
                    reading: tandem_motion::hydraulic::pressure::PressureReading::Force,
                },
            }
        );
        assert!(parse(
            "MC_AxCtrlSlowDownOnPressureEx_BkPlcMc",
            &[p("kp", Value::Num(0.01))],
            Refs::default()
        )
        .is_err());
    }

    #[test]
    fn builds_commands_with_defaults() {
        let c = parse(
            "MoveAbsolute",
            &[
                p("position", Value::Num(40.0)),
                p("direction", Value::Num(3.0)),
            ],
            Refs::default(),
        )
        .unwrap();
        assert_eq!(
            c,
            Command::MoveAbsolute {
                position: 40.0,
                dynamics: Dynamics::DEFAULT,
                direction: Direction::Shortest
            }
        );
        assert!(parse("MoveAbsolute", &[], Refs::default())
            .unwrap_err()
            .to_string()
            .contains("`position` is required"));
        assert!(parse(
            "MoveAbsolute",
            &[p("postion", Value::Num(1.0))],
            Refs::default()
        )
        .unwrap_err()
        .to_string()
        .contains("unknown parameter `postion`"));
        assert!(
            parse("MC_Power", &[p("enable", Value::Num(1.0))], Refs::default())
                .unwrap_err()
                .to_string()
                .contains("true or false")
        );
        assert!(
            parse("MC_Home", &[p("mode", Value::Num(2.5))], Refs::default())
                .unwrap_err()
                .to_string()
                .contains("integer")
        );
    }

    #[test]
    fn buffer_mode_by_number_and_by_name() {
        let c = parse(
            "MC_MoveRelative",
            &[
                p("distance", Value::Num(5.0)),
                p("buffer_mode", Value::Num(2.0)),
            ],
            Refs::default(),
        )
        .unwrap();
        assert_eq!(
            c,
            Command::Buffered {
                motion: BufferedMotion::MoveRelative {
                    distance: 5.0,
                    dynamics: Dynamics::DEFAULT
                },
                buffer_mode: BufferMode::BlendingLow
            }
        );
        // Aborting (the default, 0) is the plain command.
        let plain = parse(
            "MC_MoveRelative",
            &[
                p("distance", Value::Num(5.0)),
                p("buffer_mode", Value::Num(0.0)),
            ],
            Refs::default(),
        )
        .unwrap();
        assert_eq!(
            plain,
            Command::MoveRelative {
                distance: 5.0,
                dynamics: Dynamics::DEFAULT
            }
        );
        assert_eq!(
            named_value("buffer_mode", "BlendingHigh"),
            Some(Value::Num(5.0))
        );
        assert_eq!(
            named_value("buffer_mode", "mcBuffered"),
            Some(Value::Num(1.0))
        );
        assert_eq!(named_value("buffer_mode", "blend"), Some(Value::Num(2.0)));
        assert_eq!(named_value("buffer_mode", "Sometimes"), None);
        assert_eq!(named_value("direction", "Positive"), None);
        assert!(parse(
            "MC_MoveAdditive",
            &[
                p("distance", Value::Num(1.0)),
                p("buffer_mode", Value::Num(6.0))
            ],
            Refs::default()
        )
        .unwrap_err()
        .to_string()
        .contains("buffer_mode must be 0..5"));
    }

    #[test]
    fn flying_gear_parses_with_its_inputs_and_leader() {
        let given = [
            p("master_sync_position", Value::Num(460.0)),
            p("slave_sync_position", Value::Num(450.0)),
            p("slave_desync_position", Value::Num(450.0)),
            p("slave_stop_position", Value::Num(500.0)),
            p("ratio", Value::Num(0.98)),
        ];
        let refs = Refs {
            master: Some(3),
            cam: None,
        };
        let c = parse("flying_gear_bkplcmc", &given, refs).unwrap();
        assert_eq!(
            c,
            Command::FlyingGear {
                master: 3,
                enable: true,
                params: FlyingGearParams {
                    ratio: 0.98,
                    master_sync_position: 460.0,
                    slave_sync_position: 450.0,
                    slave_desync_position: 450.0,
                    slave_stop_position: 500.0,
                    default_slave_negative: false,
                },
            }
        );
        assert!(needs_master(find("MC_FlyingGear_BkPlcMc").unwrap()));
        assert_eq!(
            parse("MC_FlyingGear_BkPlcMc", &given, Refs::default()),
            Err(CommandError::MissingReference {
                instruction: "MC_FlyingGear_BkPlcMc",
                param: "master",
                what: "the leading axis",
            })
        );
        let off = [
            p("enable", Value::Bool(false)),
            given[0].clone(),
            given[1].clone(),
        ];
        assert!(matches!(
            parse("MC_FlyingGear_BkPlcMc", &off, refs),
            Err(CommandError::MissingParameter {
                param: "slave_desync_position",
                ..
            })
        ));
    }

    /// MC_Home_BkPlcMc: the library's mode numbers, `position` optional (the axis'
    /// fEnc_DefaultHomePosition), a number beyond 8 refused naming the modes.
    #[test]
    fn mc_home_bkplcmc_parses_its_inputs() {
        let c = parse(
            "MC_Home_BkPlcMc",
            &[
                p("position", Value::Num(12.5)),
                p("homing_mode", Value::Num(6.0)),
            ],
            Refs::default(),
        )
        .unwrap();
        assert_eq!(
            c,
            Command::HydHome(HydHomeInputs {
                execute: true,
                position: Some(12.5),
                mode: HydHomingMode::Block,
                calibration_cam: false,
            })
        );
        let c = parse(
            "MC_Home_BkPlcMc",
            &[p("calibration_cam", Value::Bool(true))],
            Refs::default(),
        )
        .unwrap();
        assert_eq!(
            c,
            Command::HydHome(HydHomeInputs {
                execute: true,
                position: None,
                mode: HydHomingMode::Default,
                calibration_cam: true,
            })
        );
        assert!(matches!(
            parse(
                "MC_Home_BkPlcMc",
                &[p("homing_mode", Value::Num(9.0))],
                Refs::default()
            ),
            Err(CommandError::BadValue {
                param: "homing_mode",
                ..
            })
        ));
    }

    #[test]
    fn every_instruction_parses_with_its_required_parameters() {
        for spec in INSTRUCTIONS {
            let given: Vec<(String, Value)> = spec
                .params
                .iter()
                .filter(|(_, d)| d.is_none())
                .map(|(k, _)| p(k, Value::Num(1.0)))
                .collect();
            assert!(
                parse(
                    spec.name,
                    &given,
                    Refs {
                        master: Some(0),
                        cam: Some(0)
                    }
                )
                .is_ok(),
                "{}",
                spec.name
            );
        }
    }
}
