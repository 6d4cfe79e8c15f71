//! Simulator scripts: timed instructions for the axes of a cell.
//!
//! ```toml
//! [sim]
//! duration = 5.0          # virtual seconds to run
//!
//! [[at]]
//! t = 0.0                 # seconds
//! axis = "x"
//! instruction = "MC_Power"
//! enable = true           # the instruction's parameters follow
//! ```
//!
//! Synchronous operation names its leader: `master = "<axis>"` (the leader's id is its index
//! in the cell's axis list, in name order).
//!
//! Output cams, cam tracks and measuring inputs are addressed by name in `axis`:
//! `MC_OutputCam` (`enable`, `on_position`, `off_position`, `duration`, `mode`, `direction`),
//! `MC_CamTrack` (`enable`, `mode`, `invert_output`), `MC_MeasuringInput` and
//! `MC_MeasuringInputCyclic` (`mode`, `measuring_range`, `start_position`, `end_position`),
//! `MC_AbortMeasuringInput`, and `InputEdge` (`rising`): an input edge at the entry's `t`.
//! A digital cam switch (`[[digital_cam_switches]]`) takes `MC_DigitalCamSwitch_BkPlcMc`
//! (`enable`, default `true`; `enable_mask`, default `0xFFFFFFFF`: bit `n - 1` is track `n`).
//! A simulated drive (`[devices.<name>]`) takes `DriveFault` (`code`): a fault with that CiA 402
//! error code (0x603F, e.g. `code = 0x2310`) from the entry's `t`, or with `code = 0` its cause
//! removed (a fault reset then succeeds); a simulated servo also takes `FixedStop` (`min`,
//! `max`, positions of its axis's load; one left out: no stop on that side): its mechanical
//! stops from the entry's `t` (`FixedStop` alone: the stop gives way).
//! A simulated input signal (`[signals.<name>]` on a `sim_digital_input`) takes `SetInput`
//! (`value`, default `true`; `pulse`, s, default 0): the input's level from the entry's `t`
//! exactly, and with `pulse > 0` back to `!value` that long after (a timestamped input reports
//! both edges at those times). On an `integer` or `float` input signal (a `sim_counter`,
//! `sim_analog_input` channel) `value` is a number (whole for an `integer`), without `pulse`:
//! the value the channel reads from the entry's `t`, sampled at the next boundary at or after
//! it (a float quantized as its terminal does, an integer wrapped to its register).
//! Use [`parse_cell`] to address them.

use crate::command::{self, CommandError, Expected, Value};
use crate::{ConfigError, Problem};
use tandem_motion::objects::action::Action;

/// The names of the cell's output cams, cam tracks and measuring inputs (script targets).
#[derive(Clone, Debug, Default)]
pub struct ObjectNames<'a> {
    /// `[[output_cams]]`.
    pub output_cams: Vec<&'a str>,
    /// `[[cam_tracks]]`.
    pub cam_tracks: Vec<&'a str>,
    /// `[[measuring_inputs]]`.
    pub measuring_inputs: Vec<&'a str>,
    /// `[[digital_cam_switches]]`.
    pub digital_cam_switches: Vec<&'a str>,
    /// `[devices.<name>]`.
    pub devices: Vec<&'a str>,
    /// The input signals (`[signals.<name>]` on a `sim_digital_input`, `sim_analog_input` or
    /// `sim_counter`).
    pub input_signals: Vec<&'a str>,
    /// The input signals among them that take a number (`integer`, `float`), and whether
    /// it must be whole (`integer`).
    pub value_signals: Vec<(&'a str, bool)>,
    /// The `float` output signals (`SetOutput`: on a `sim_analog_output` or an EtherCAT
    /// `aio`).
    pub float_outputs: Vec<&'a str>,
}

/// One timed command.
#[derive(Clone, Debug, PartialEq)]
pub struct ScriptEntry {
    /// When (ns of virtual time).
    pub t_ns: i64,
    /// Target object name (axis, encoder, or cam for MC_InterpolateCam).
    pub axis: String,
    /// The instruction as written (for the log).
    pub instruction: &'static str,
    /// What it does.
    pub action: Action,
    /// Line in the script file.
    pub line: usize,
}

/// A parsed script, entries sorted by time (stable: file order within one time).
#[derive(Clone, Debug, PartialEq)]
pub struct Script {
    /// Virtual duration (ns).
    pub duration_ns: i64,
    /// Entries.
    pub entries: Vec<ScriptEntry>,
}

fn line_at(src: &str, offset: usize) -> usize {
    src[..offset.min(src.len())].matches('\n').count() + 1
}

fn seconds_to_ns(x: f64) -> Option<i64> {
    (x.is_finite() && (0.0..=1e9).contains(&x)).then(|| (x * 1e9).round() as i64)
}

fn num(item: &toml_edit::Item) -> Option<f64> {
    item.as_float()
        .or_else(|| item.as_integer().map(|i| i as f64))
}

/// Parses a script; `file` names it in errors. `axes` are the names of the cell's objects that
/// can be addressed and lead (axes, then encoders: a leader's id is its index), `cams` the
/// names of its cams (a cam's id is its index).
pub fn parse(file: &str, src: &str, axes: &[&str], cams: &[&str]) -> Result<Script, ConfigError> {
    parse_with(file, src, axes, cams, &ObjectNames::default())
}

/// Reads (at most [`crate::read::SCRIPT_FILE_MAX`] bytes of UTF-8) and parses the script
/// file `path` for `cell` ([`parse_cell`]).
pub fn load(path: &std::path::Path, cell: &crate::Cell) -> Result<Script, ConfigError> {
    let src = crate::read::read_text(path, crate::read::SCRIPT_FILE_MAX)?;
    parse_cell(&path.display().to_string(), &src, cell)
}

/// Parses a script for `cell`: its axes, encoders, cams, output cams, cam tracks and measuring
/// inputs can be addressed.
pub fn parse_cell(file: &str, src: &str, cell: &crate::Cell) -> Result<Script, ConfigError> {
    let names = cell.object_names();
    let cams: Vec<&str> = cell.cams.iter().map(|c| c.name.as_str()).collect();
    let objects = ObjectNames {
        output_cams: cell.output_cams.iter().map(|c| c.name.as_str()).collect(),
        cam_tracks: cell.cam_tracks.iter().map(|c| c.name.as_str()).collect(),
        measuring_inputs: cell
            .measuring_inputs
            .iter()
            .map(|c| c.name.as_str())
            .collect(),
        digital_cam_switches: cell
            .digital_cam_switches
            .iter()
            .map(|c| c.name.as_str())
            .collect(),
        devices: cell.devices.iter().map(|d| d.name.as_str()).collect(),
        input_signals: cell
            .signals
            .iter()
            .filter(|x| x.direction == crate::cell::SignalDirection::Input)
            .map(|x| x.name.as_str())
            .collect(),
        value_signals: cell
            .signals
            .iter()
            .filter(|x| x.direction == crate::cell::SignalDirection::Input)
            .filter(|x| !x.signal_type.is_bool())
            .map(|x| {
                let whole = x.signal_type == crate::cell::SignalType::Integer;
                (x.name.as_str(), whole)
            })
            .collect(),
        float_outputs: cell
            .signals
            .iter()
            .filter(|x| x.direction == crate::cell::SignalDirection::Output)
            .filter(|x| x.signal_type == crate::cell::SignalType::Float)
            .map(|x| x.name.as_str())
            .collect(),
    };
    parse_with(file, src, &names, &cams, &objects)
}

/// The instructions of output cams, cam tracks, measuring inputs and simulated devices: name,
/// the kind of object it addresses (0 output cam, 1 cam track, 2 measuring input, 3 device,
/// 4 input signal, 5 digital cam switch, 6 float output signal) and parameters with defaults.
type ObjectInstruction = (&'static str, u8, &'static [(&'static str, Value)]);

const OBJECT_INSTRUCTIONS: &[ObjectInstruction] = &[
    (
        "MC_OutputCam",
        0,
        &[
            ("enable", Value::Bool(true)),
            ("on_position", Value::Num(0.0)),
            ("off_position", Value::Num(0.0)),
            ("duration", Value::Num(0.0)),
            ("mode", Value::Num(1.0)),
            ("direction", Value::Num(3.0)),
        ],
    ),
    (
        "MC_CamTrack",
        1,
        &[
            ("enable", Value::Bool(true)),
            ("mode", Value::Num(1.0)),
            ("invert_output", Value::Bool(false)),
        ],
    ),
    (
        "MC_MeasuringInput",
        2,
        &[
            ("mode", Value::Num(0.0)),
            ("measuring_range", Value::Bool(false)),
            ("start_position", Value::Num(0.0)),
            ("end_position", Value::Num(0.0)),
        ],
    ),
    (
        "MC_MeasuringInputCyclic",
        2,
        &[
            ("mode", Value::Num(0.0)),
            ("measuring_range", Value::Bool(false)),
            ("start_position", Value::Num(0.0)),
            ("end_position", Value::Num(0.0)),
        ],
    ),
    ("MC_AbortMeasuringInput", 2, &[]),
    ("InputEdge", 2, &[("rising", Value::Bool(true))]),
    ("DriveFault", 3, &[("code", Value::Num(0.0))]),
    (
        "FixedStop",
        3,
        &[("min", Value::Num(f64::NAN)), ("max", Value::Num(f64::NAN))],
    ),
    (
        "SetInput",
        4,
        &[("value", Value::Bool(true)), ("pulse", Value::Num(0.0))],
    ),
    ("SetOutput", 6, &[("value", Value::Num(0.0))]),
    (
        "MC_DigitalCamSwitch_BkPlcMc",
        5,
        &[
            ("enable", Value::Bool(true)),
            // Inferred: every track by default (the PLC's DWORD input starts at 0).
            ("enable_mask", Value::Num(4_294_967_295.0)),
        ],
    ),
];

/// An entry for an output cam, cam track or measuring input.
fn object_entry(t: &toml_edit::Table, spec: &ObjectInstruction) -> Result<Action, CommandError> {
    let (name, _, params) = *spec;
    let mut vals: Vec<Value> = params.iter().map(|(_, v)| *v).collect();
    let wrong = |param: &str, expected| CommandError::WrongType {
        instruction: None,
        param: param.into(),
        expected,
    };
    for (k, v) in t.iter() {
        if matches!(k, "t" | "axis" | "instruction") {
            continue;
        }
        let Some(i) = params.iter().position(|(p, _)| *p == k) else {
            return Err(CommandError::UnknownParameter {
                instruction: name,
                name: k.into(),
                known: params.iter().map(|(p, _)| *p).collect(),
            });
        };
        vals[i] = match (params[i].1, v.as_bool(), num(v)) {
            (Value::Bool(_), Some(b), _) => Value::Bool(b),
            (Value::Num(_), _, Some(x)) if x.is_finite() => Value::Num(x),
            (Value::Bool(_), _, _) => return Err(wrong(k, Expected::Bool)),
            (Value::Num(_), _, _) => return Err(wrong(k, Expected::Number)),
        };
    }
    let b = |i: usize| matches!(vals.get(i), Some(Value::Bool(true)));
    let x = |i: usize| match vals.get(i) {
        Some(Value::Num(x)) => *x,
        _ => 0.0,
    };
    let code = |i: usize| -> Result<i32, CommandError> {
        let v = x(i);
        if v.fract() == 0.0 && v.abs() < 1e6 {
            Ok(v as i32)
        } else {
            Err(wrong(params[i].0, Expected::Integer))
        }
    };
    Ok(match name {
        "MC_OutputCam" => Action::OutputCam {
            enable: b(0),
            on_position: x(1),
            off_position: x(2),
            duration: x(3),
            mode: code(4)?,
            direction: code(5)?,
        },
        "MC_CamTrack" => Action::CamTrack {
            enable: b(0),
            mode: code(1)?,
            invert_output: b(2),
        },
        "MC_MeasuringInput" | "MC_MeasuringInputCyclic" => Action::MeasuringInput {
            cyclic: name == "MC_MeasuringInputCyclic",
            mode: code(0)?,
            window: b(1).then(|| (x(2), x(3))),
        },
        "MC_AbortMeasuringInput" => Action::AbortMeasuringInput,
        "DriveFault" => {
            let c = code(0)?;
            Action::DriveFault {
                code: u16::try_from(c).map_err(|_| wrong("code", Expected::Integer))?,
            }
        }
        "FixedStop" => Action::FixedStop {
            min: Some(x(0)).filter(|x| x.is_finite()),
            max: Some(x(1)).filter(|x| x.is_finite()),
        },
        "SetInput" => Action::SetInput {
            value: b(0),
            pulse_ns: Some(x(1))
                .filter(|p| (0.0..=3600.0).contains(p))
                .and_then(seconds_to_ns)
                .ok_or(wrong("pulse", Expected::Number))?,
        },
        "SetOutput" => {
            if !t.contains_key("value") {
                return Err(wrong("value", Expected::Number));
            }
            Action::SetOutputValue { value: x(0) }
        }
        "MC_DigitalCamSwitch_BkPlcMc" => Action::DigitalCamSwitch {
            enable: b(0),
            enable_mask: Some(x(1))
                .filter(|m| m.fract() == 0.0 && (0.0..=4_294_967_295.0).contains(m))
                .map(|m| m as u32)
                .ok_or(wrong("enable_mask", Expected::Integer))?,
        },
        _ => Action::InputEdge { rising: b(0) },
    })
}

/// What a script may address: the cell's leaders (axes, then encoders), cams and objects.
struct Targets<'a> {
    axes: &'a [&'a str],
    cams: &'a [&'a str],
    objects: &'a ObjectNames<'a>,
}

/// The position of `name` in `list` (a cell's names of one kind), or
/// [`CommandError::UnknownObject`].
fn find_in(list: &[&str], what: &'static str, name: &str) -> Result<usize, CommandError> {
    list.iter()
        .position(|c| *c == name)
        .ok_or_else(|| CommandError::UnknownObject {
            instruction: None,
            what,
            name: name.into(),
            known: list.iter().map(|s| s.to_string()).collect(),
        })
}

/// The string at `key`, or [`CommandError::MissingKey`].
fn required<'t>(
    t: &'t toml_edit::Table,
    key: &'static str,
    hint: Option<&'static str>,
) -> Result<&'t str, CommandError> {
    t.get(key)
        .and_then(|x| x.as_str())
        .ok_or(CommandError::MissingKey { key, hint })
}

/// Every key of `t` is one of the entry's keys or of `params`, else
/// [`CommandError::UnknownParameter`] of `instruction`.
fn only_params(
    t: &toml_edit::Table,
    instruction: &'static str,
    params: &[&'static str],
) -> Result<(), CommandError> {
    match t
        .iter()
        .find(|(k, _)| !matches!(*k, "t" | "axis" | "instruction") && !params.contains(k))
    {
        Some((k, _)) => Err(CommandError::UnknownParameter {
            instruction,
            name: k.into(),
            known: params.to_vec(),
        }),
        None => Ok(()),
    }
}

/// One `[[at]]` table: when, and what to which object.
fn entry(
    t: &toml_edit::Table,
    targets: &Targets<'_>,
    line: usize,
) -> Result<ScriptEntry, CommandError> {
    let t_ns =
        t.get("t")
            .and_then(num)
            .and_then(seconds_to_ns)
            .ok_or(CommandError::MissingKey {
                key: "t",
                hint: Some("seconds >= 0"),
            })?;
    let instr_name = t.get("instruction").and_then(|x| x.as_str()).unwrap_or("");
    let objects = targets.objects;
    let object = t.get("axis").and_then(|x| x.as_str()).filter(|a| {
        objects.output_cams.contains(a)
            || objects.cam_tracks.contains(a)
            || objects.measuring_inputs.contains(a)
    });
    let normalized = command::normalize(instr_name);
    let (axis, instruction, action) =
        if let (Some(target), true) = (object, normalized == command::normalize("MC_Reset")) {
            (target, "MC_Reset", reset_object(t)?)
        } else if let Some(spec) = OBJECT_INSTRUCTIONS
            .iter()
            .find(|s| command::normalize(s.0) == normalized)
        {
            object_instruction(t, spec, objects)?
        } else if normalized == "interpolatecam" {
            interpolate_cam(t, targets.cams)?
        } else {
            axis_instruction(t, targets)?
        };
    Ok(ScriptEntry {
        t_ns,
        axis: axis.to_string(),
        instruction,
        action,
        line,
    })
}

/// MC_Reset addressed to an output cam, cam track or measuring input.
fn reset_object(t: &toml_edit::Table) -> Result<Action, CommandError> {
    let mut restart = false;
    for (k, v) in t.iter() {
        match (k, v.as_bool()) {
            ("t" | "axis" | "instruction", _) => {}
            ("restart", Some(b)) => restart = b,
            ("restart", None) => {
                return Err(CommandError::WrongType {
                    instruction: None,
                    param: "restart".into(),
                    expected: Expected::Bool,
                })
            }
            _ => only_params(t, "MC_Reset", &["restart"])?,
        }
    }
    Ok(Action::ResetObject { restart })
}

/// An instruction of an output cam, cam track or measuring input: the object, the
/// instruction and the action.
fn object_instruction<'t>(
    t: &'t toml_edit::Table,
    spec: &ObjectInstruction,
    objects: &ObjectNames<'_>,
) -> Result<(&'t str, &'static str, Action), CommandError> {
    let target = required(t, "axis", Some("the object's name"))?;
    let (list, what) = match spec.1 {
        0 => (&objects.output_cams, "output cam"),
        1 => (&objects.cam_tracks, "cam track"),
        2 => (&objects.measuring_inputs, "measuring input"),
        3 => (&objects.devices, "device"),
        5 => (&objects.digital_cam_switches, "digital cam switch"),
        6 => (&objects.float_outputs, "float output signal"),
        _ => (&objects.input_signals, "input signal"),
    };
    if !list.contains(&target) {
        return Err(CommandError::UnknownObject {
            instruction: Some(spec.0),
            what,
            name: target.into(),
            known: list.iter().map(|s| s.to_string()).collect(),
        });
    }
    if spec.0 == "SetInput" {
        let value = objects.value_signals.iter().find(|(n, _)| *n == target);
        if let Some(action) = set_input_value(t, value.map(|(_, whole)| *whole))? {
            return Ok((target, spec.0, action));
        }
    }
    Ok((target, spec.0, object_entry(t, spec)?))
}

/// `SetInput` on an input signal that takes a number (`whole`: an `integer` one; `None`: a
/// `bool` one, left to [`object_entry`]): `value` a number (whole for an integer), no `pulse`.
/// A number for a `bool` signal is refused as the parameter's wrong type.
fn set_input_value(
    t: &toml_edit::Table,
    whole: Option<bool>,
) -> Result<Option<Action>, CommandError> {
    let wrong = |param: &str, expected| CommandError::WrongType {
        instruction: Some("SetInput"),
        param: param.into(),
        expected,
    };
    let Some(whole) = whole else {
        return Ok(None);
    };
    if t.contains_key("pulse") {
        return Err(CommandError::UnknownParameter {
            instruction: "SetInput",
            name: "pulse".into(),
            known: vec!["value"],
        });
    }
    let expected = if whole {
        Expected::Integer
    } else {
        Expected::Number
    };
    let value = t
        .get("value")
        .and_then(num)
        .filter(|v| v.is_finite())
        .ok_or(wrong("value", expected))?;
    // Whole and exact in an f64: a register of at most 32 bits is far inside 2^53.
    if whole && !(value.fract() == 0.0 && value.abs() <= 9.007_199_254_740_992e15) {
        return Err(wrong("value", Expected::Integer));
    }
    Ok(Some(Action::SetInputValue { value }))
}

/// MC_InterpolateCam of a cam technology object: `axis` names the cam, `from` another cam's
/// definition.
fn interpolate_cam<'t>(
    t: &'t toml_edit::Table,
    cams: &[&str],
) -> Result<(&'t str, &'static str, Action), CommandError> {
    let target = required(t, "axis", Some("the cam's name"))?;
    let cam = find_in(cams, "cam", target)?;
    let from = match t.get("from") {
        None => cam,
        Some(f) => find_in(
            cams,
            "cam",
            f.as_str().ok_or(CommandError::NotAName {
                param: "from",
                what: "a cam name",
            })?,
        )?,
    };
    only_params(t, "MC_InterpolateCam", &["from"])?;
    let action = Action::InterpolateCam {
        cam: cam as u32,
        from: from as u32,
    };
    Ok((target, "MC_InterpolateCam", action))
}

/// An instruction of an axis or encoder, with its leader and cam resolved by name.
fn axis_instruction<'t>(
    t: &'t toml_edit::Table,
    targets: &Targets<'_>,
) -> Result<(&'t str, &'static str, Action), CommandError> {
    let axes = targets.axes;
    let axis = required(t, "axis", Some("a name"))?;
    find_in(axes, "axis", axis)?;
    let instr = required(t, "instruction", None)?;
    // A leader is named by its name; its id is its index among the axes, then encoders.
    let master = match t.get("master") {
        None => None,
        Some(m) => {
            let name = m.as_str().ok_or(CommandError::NotAName {
                param: "master",
                what: "an axis name",
            })?;
            let idx = find_in(axes, "master", name)?;
            if name == axis {
                return Err(CommandError::SelfFollow(axis.into()));
            }
            Some(idx as u32)
        }
    };
    let cam = match t.get("cam") {
        None => None,
        Some(c) => {
            let name = c.as_str().ok_or(CommandError::NotAName {
                param: "cam",
                what: "a cam name",
            })?;
            Some(find_in(targets.cams, "cam", name)? as u32)
        }
    };
    let mut params = Vec::new();
    for (k, v) in t.iter() {
        if matches!(k, "t" | "axis" | "instruction" | "master" | "cam") {
            continue;
        }
        let value = if let Some(b) = v.as_bool() {
            Value::Bool(b)
        } else if let Some(x) = num(v) {
            Value::Num(x)
        } else if let Some(named) = v.as_str().and_then(|n| command::named_value(k, n)) {
            // A parameter given by name (`buffer_mode = "BlendingLow"`).
            named
        } else {
            return Err(CommandError::WrongType {
                instruction: None,
                param: k.into(),
                expected: Expected::NumberOrBool,
            });
        };
        params.push((k.to_string(), value));
    }
    let command = command::parse(instr, &params, command::Refs { master, cam })?;
    let name = command::find(instr).map(|s| s.name).unwrap_or("?");
    Ok((axis, name, Action::Command(command)))
}

/// Parses the script's TOML and checks its sections (`[sim]` and `[[at]]` only).
fn document<'s>(file: &str, src: &'s str) -> Result<toml_edit::ImDocument<&'s str>, ConfigError> {
    let doc = toml_edit::ImDocument::parse(src).map_err(|x| ConfigError {
        file: file.into(),
        line: x.span().map(|s| line_at(src, s.start)),
        key: String::new(),
        problem: Box::new(Problem::Syntax(x.message().to_string())),
    })?;
    if let Some((k, _)) = doc.iter().find(|(k, _)| *k != "sim" && *k != "at") {
        return Err(ConfigError {
            file: file.into(),
            line: crate::locate(src, &[k]),
            key: k.into(),
            problem: Box::new(Problem::Invalid(
                "unknown section (expected [sim] and [[at]])",
            )),
        });
    }
    Ok(doc)
}

/// The longest script (s): an hour of virtual time, as long as the longest time key of a
/// cell; a script is a test, a demonstration or a soak run, and a day of a 1 ms cell would keep
/// `tandem sim` busy for hours.
pub const MAX_DURATION_S: f64 = 3600.0;

/// `[sim] duration`: the virtual time to run (ns).
fn duration(file: &str, src: &str, doc: &toml_edit::ImDocument<&str>) -> Result<i64, ConfigError> {
    let e = |line, problem| ConfigError {
        file: file.into(),
        line,
        key: "sim.duration".into(),
        problem: Box::new(problem),
    };
    let duration = doc
        .get("sim")
        .and_then(|s| s.get("duration"))
        .ok_or_else(|| {
            e(
                None,
                Problem::Invalid("is required (virtual seconds to run)"),
            )
        })?;
    num(duration)
        .filter(|s| *s <= MAX_DURATION_S)
        .and_then(seconds_to_ns)
        .ok_or_else(|| {
            e(
                crate::locate(src, &["sim", "duration"]),
                Problem::Invalid("must be a number of seconds from 0 to 3600 (one hour)"),
            )
        })
}

fn parse_with(
    file: &str,
    src: &str,
    axes: &[&str],
    cams: &[&str],
    objects: &ObjectNames<'_>,
) -> Result<Script, ConfigError> {
    let doc = document(file, src)?;
    let duration_ns = duration(file, src, &doc)?;
    let targets = Targets {
        axes,
        cams,
        objects,
    };
    let mut entries = Vec::new();
    // Line numbers by binary search over the newlines (a script may have thousands of entries).
    let newlines: Vec<usize> = src.match_indices('\n').map(|(i, _)| i).collect();
    if let Some(at) = doc.get("at") {
        let tables = at.as_array_of_tables().ok_or_else(|| ConfigError {
            file: file.into(),
            line: crate::locate(src, &["at"]),
            key: "at".into(),
            problem: Box::new(Problem::Invalid("must be written as [[at]] tables")),
        })?;
        for (i, t) in tables.iter().enumerate() {
            let line = t
                .span()
                .map(|s| newlines.partition_point(|&i| i < s.start) + 1);
            let entry = entry(t, &targets, line.unwrap_or(0)).map_err(|c| ConfigError {
                file: file.into(),
                line,
                key: format!("at[{i}]"),
                problem: Box::new(Problem::Command(c)),
            })?;
            entries.push(entry);
        }
    }
    entries.sort_by_key(|x| x.t_ns);
    Ok(Script {
        duration_ns,
        entries,
    })
}

/// Parses one command as the CLI gives it (`<object> <instruction> --param value ...`) with the
/// script's rules: the same instruction names, parameters, defaults and errors. A value that is
/// a number or `true`/`false` is one; anything else is a name (a leader, a cam). A leader may be
/// named `node/object`.
pub fn parse_command(
    cell: &crate::Cell,
    object: &str,
    instruction: &str,
    params: &[(String, String)],
) -> Result<ScriptEntry, Problem> {
    use std::fmt::Write as _;
    let quote = |s: &str| {
        let mut q = String::from("\"");
        for c in s.chars() {
            match c {
                '"' => q.push_str("\\\""),
                '\\' => q.push_str("\\\\"),
                c if c.is_control() => {}
                c => q.push(c),
            }
        }
        q.push('"');
        q
    };
    let mut src = String::from("[sim]\nduration = 0\n[[at]]\nt = 0\n");
    // Writing into a String cannot fail.
    let _ = writeln!(src, "axis = {}", quote(object));
    // Writing into a String cannot fail.
    let _ = writeln!(src, "instruction = {}", quote(instruction));
    for (k, v) in params {
        if k.is_empty() || !k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(CommandError::BadParameterName(k.clone()).into());
        }
        if matches!(k.as_str(), "t" | "axis" | "instruction") {
            return Err(CommandError::ReservedParameter(k.clone()).into());
        }
        let value = if v == "true" || v == "false" || v.parse::<f64>().is_ok_and(f64::is_finite) {
            v.clone()
        } else {
            // `node/object` names a leader on its node.
            let name = match v.split_once('/') {
                Some((node, o)) if cell.node(node).is_some() => o,
                _ => v.as_str(),
            };
            quote(name)
        };
        // Writing into a String cannot fail.
        let _ = writeln!(src, "{k} = {value}");
    }
    let script = parse_cell("command", &src, cell).map_err(|e| *e.problem)?;
    script
        .entries
        .into_iter()
        .next()
        .ok_or_else(|| CommandError::NotUnderstood(instruction.into()).into())
}

/// A command line: `<object> <instruction> [--param value | --param=value]...`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CommandLine {
    /// The object, `object` or `node/object`.
    pub object: String,
    /// The instruction.
    pub instruction: String,
    /// Parameters in order (dashes in names become underscores).
    pub params: Vec<(String, String)>,
}

/// Splits a command line into object, instruction and `--param value` pairs.
pub fn split_command(text: &str) -> Result<CommandLine, CommandError> {
    let mut words = text.split_whitespace();
    let object = words.next().ok_or(CommandError::Empty)?.to_string();
    let instruction = words
        .next()
        .ok_or_else(|| CommandError::NoInstruction(object.clone()))?
        .to_string();
    let mut params = Vec::new();
    while let Some(w) = words.next() {
        let Some(key) = w.strip_prefix("--") else {
            return Err(CommandError::ExpectedParameter(w.into()));
        };
        let (k, v) = match key.split_once('=') {
            Some((k, v)) => (k.to_string(), v.to_string()),
            None => (
                key.to_string(),
                words
                    .next()
                    .ok_or_else(|| CommandError::MissingValue(key.into()))?
                    .to_string(),
            ),
        };
        params.push((k.replace('-', "_"), v));
    }
    Ok(CommandLine {
        object,
        instruction,
        params,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_reports_lines() {
        let src = "[sim]\nduration = 1.5\n\n[[at]]\nt = 0.5\naxis = \"x\"\ninstruction = \"MoveRelative\"\ndistance = 10\n\n[[at]]\nt = 0\naxis = \"x\"\ninstruction = \"MC_Power\"\n";
        let s = parse("s.toml", src, &["x"], &[]).unwrap();
        assert_eq!(s.duration_ns, 1_500_000_000);
        assert_eq!(s.entries.len(), 2);
        assert_eq!(s.entries[0].instruction, "MC_Power");
        assert_eq!(s.entries[1].line, 4);
        let bad = src.replace("distance = 10", "distanc = 10");
        let e = parse("s.toml", &bad, &["x"], &[]).unwrap_err();
        assert_eq!(e.line, Some(4));
        assert!(
            e.problem
                .to_string()
                .contains("unknown parameter `distanc`"),
            "{e}"
        );
        let e = parse("s.toml", src, &["y"], &[]).unwrap_err();
        assert!(e.problem.to_string().contains("unknown axis `x`"));
    }

    #[test]
    fn errors_are_typed() {
        let src = "[sim]\nduration = 1\n[[at]]\nt = 0\naxis = \"x\"\ninstruction = \"MC_Fly\"\n";
        let e = parse("s.toml", src, &["x"], &[]).unwrap_err();
        assert_eq!(
            *e.problem,
            Problem::Command(CommandError::UnknownInstruction("MC_Fly".into()))
        );
        assert_eq!(
            split_command("x MC_Power --enable"),
            Err(CommandError::MissingValue("enable".into()))
        );
        assert_eq!(split_command("  "), Err(CommandError::Empty));
        assert_eq!(
            split_command("x").unwrap_err().to_string(),
            "`x`: no instruction given"
        );
    }
}
