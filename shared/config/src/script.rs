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
//! Use [`parse_cell`] to address them.

use crate::command::{self, Value};
use crate::ConfigError;
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
    };
    parse_with(file, src, &names, &cams, &objects)
}

/// The instructions of output cams, cam tracks and measuring inputs: name, the kind of object
/// it addresses (0 output cam, 1 cam track, 2 measuring input) and parameters with defaults.
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
];

/// An entry for an output cam, cam track or measuring input.
fn object_entry(t: &toml_edit::Table, spec: &ObjectInstruction) -> Result<Action, String> {
    let (name, _, params) = *spec;
    let mut vals: Vec<Value> = params.iter().map(|(_, v)| *v).collect();
    for (k, v) in t.iter() {
        if matches!(k, "t" | "axis" | "instruction") {
            continue;
        }
        let Some(i) = params.iter().position(|(p, _)| *p == k) else {
            let names: Vec<&str> = params.iter().map(|(p, _)| *p).collect();
            return Err(format!(
                "{name}: unknown parameter `{k}`; parameters: {}",
                names.join(", ")
            ));
        };
        vals[i] = match (params[i].1, v.as_bool(), num(v)) {
            (Value::Bool(_), Some(b), _) => Value::Bool(b),
            (Value::Num(_), _, Some(x)) if x.is_finite() => Value::Num(x),
            (Value::Bool(_), _, _) => return Err(format!("`{k}` must be true or false")),
            (Value::Num(_), _, _) => return Err(format!("`{k}` must be a number")),
        };
    }
    let b = |i: usize| matches!(vals.get(i), Some(Value::Bool(true)));
    let x = |i: usize| match vals.get(i) {
        Some(Value::Num(x)) => *x,
        _ => 0.0,
    };
    let code = |i: usize| -> Result<i32, String> {
        let v = x(i);
        if v.fract() == 0.0 && v.abs() < 1e6 {
            Ok(v as i32)
        } else {
            Err(format!("`{}` must be an integer", params[i].0))
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
        _ => Action::InputEdge { rising: b(0) },
    })
}

fn parse_with(
    file: &str,
    src: &str,
    axes: &[&str],
    cams: &[&str],
    objects: &ObjectNames<'_>,
) -> Result<Script, ConfigError> {
    let e = |line: Option<usize>, key: &str, message: String| ConfigError {
        file: file.into(),
        line,
        key: key.into(),
        message,
    };
    let doc = toml_edit::ImDocument::parse(src).map_err(|x| {
        e(
            x.span().map(|s| line_at(src, s.start)),
            "",
            x.message().to_string(),
        )
    })?;
    for (k, _) in doc.iter() {
        if k != "sim" && k != "at" {
            return Err(e(
                crate::locate(src, &[k]),
                k,
                "unknown section (expected [sim] and [[at]])".into(),
            ));
        }
    }
    let duration = doc
        .get("sim")
        .and_then(|s| s.get("duration"))
        .ok_or_else(|| {
            e(
                None,
                "sim.duration",
                "is required (virtual seconds to run)".into(),
            )
        })?;
    let duration_ns = num(duration).and_then(seconds_to_ns).ok_or_else(|| {
        e(
            crate::locate(src, &["sim", "duration"]),
            "sim.duration",
            "must be a number of seconds >= 0".into(),
        )
    })?;
    let mut entries = Vec::new();
    // Line numbers by binary search over the newlines (a script may have thousands of entries).
    let newlines: Vec<usize> = src.match_indices('\n').map(|(i, _)| i).collect();
    if let Some(at) = doc.get("at") {
        let tables = at.as_array_of_tables().ok_or_else(|| {
            e(
                crate::locate(src, &["at"]),
                "at",
                "must be written as [[at]] tables".into(),
            )
        })?;
        for (i, t) in tables.iter().enumerate() {
            let line = t
                .span()
                .map(|s| newlines.partition_point(|&i| i < s.start) + 1);
            let key = format!("at[{i}]");
            let time = t
                .get("t")
                .and_then(num)
                .and_then(seconds_to_ns)
                .ok_or_else(|| e(line, &key, "`t` (seconds >= 0) is required".into()))?;
            let instr_name = t.get("instruction").and_then(|x| x.as_str()).unwrap_or("");
            let object = t.get("axis").and_then(|x| x.as_str()).filter(|a| {
                objects.output_cams.contains(a)
                    || objects.cam_tracks.contains(a)
                    || objects.measuring_inputs.contains(a)
            });
            if let (Some(target), true) = (
                object,
                command::normalize(instr_name) == command::normalize("MC_Reset"),
            ) {
                // MC_Reset addressed to an output cam, cam track or measuring input.
                let mut restart = false;
                for (k, v) in t.iter() {
                    match (k, v.as_bool()) {
                        ("t" | "axis" | "instruction", _) => {}
                        ("restart", Some(b)) => restart = b,
                        ("restart", None) => {
                            return Err(e(line, &key, "`restart` must be true or false".into()))
                        }
                        _ => {
                            return Err(e(
                                line,
                                &key,
                                format!("MC_Reset: unknown parameter `{k}`; parameters: restart"),
                            ))
                        }
                    }
                }
                entries.push(ScriptEntry {
                    t_ns: time,
                    axis: target.to_string(),
                    instruction: "MC_Reset",
                    action: Action::ResetObject { restart },
                    line: line.unwrap_or(0),
                });
                continue;
            }
            if let Some(spec) = OBJECT_INSTRUCTIONS
                .iter()
                .find(|s| command::normalize(s.0) == command::normalize(instr_name))
            {
                let target = t.get("axis").and_then(|x| x.as_str()).ok_or_else(|| {
                    e(line, &key, "`axis` (the object's name) is required".into())
                })?;
                let (list, what) = match spec.1 {
                    0 => (&objects.output_cams, "output cam"),
                    1 => (&objects.cam_tracks, "cam track"),
                    _ => (&objects.measuring_inputs, "measuring input"),
                };
                if !list.contains(&target) {
                    return Err(e(
                        line,
                        &key,
                        format!(
                            "{}: unknown {what} `{target}`; the cell has: {}",
                            spec.0,
                            list.join(", ")
                        ),
                    ));
                }
                let action = object_entry(t, spec).map_err(|m| e(line, &key, m))?;
                entries.push(ScriptEntry {
                    t_ns: time,
                    axis: target.to_string(),
                    instruction: spec.0,
                    action,
                    line: line.unwrap_or(0),
                });
                continue;
            }
            if command::normalize(instr_name) == "interpolatecam" {
                // A cam technology object: `axis` names the cam, `from` another cam's definition.
                let target = t
                    .get("axis")
                    .and_then(|x| x.as_str())
                    .ok_or_else(|| e(line, &key, "`axis` (the cam's name) is required".into()))?;
                let find = |name: &str| {
                    cams.iter().position(|c| *c == name).ok_or_else(|| {
                        e(
                            line,
                            &key,
                            format!("unknown cam `{name}`; the cell has: {}", cams.join(", ")),
                        )
                    })
                };
                let cam = find(target)?;
                let from = match t.get("from") {
                    None => cam,
                    Some(f) => find(
                        f.as_str()
                            .ok_or_else(|| e(line, &key, "`from` must be a cam name".into()))?,
                    )?,
                };
                for (k, _) in t.iter() {
                    if !matches!(k, "t" | "axis" | "instruction" | "from") {
                        return Err(e(
                            line,
                            &key,
                            format!("MC_InterpolateCam: unknown parameter `{k}`; parameters: from"),
                        ));
                    }
                }
                entries.push(ScriptEntry {
                    t_ns: time,
                    axis: target.to_string(),
                    instruction: "MC_InterpolateCam",
                    action: Action::InterpolateCam {
                        cam: cam as u32,
                        from: from as u32,
                    },
                    line: line.unwrap_or(0),
                });
                continue;
            }
            let axis = t
                .get("axis")
                .and_then(|x| x.as_str())
                .ok_or_else(|| e(line, &key, "`axis` (a name) is required".into()))?;
            if !axes.contains(&axis) {
                return Err(e(
                    line,
                    &key,
                    format!("unknown axis `{axis}`; the cell has: {}", axes.join(", ")),
                ));
            }
            let instr = t
                .get("instruction")
                .and_then(|x| x.as_str())
                .ok_or_else(|| e(line, &key, "`instruction` is required".into()))?;
            // A leader is named by its axis name; its id is the axis' index in the cell.
            let master = match t.get("master") {
                None => None,
                Some(m) => {
                    let name = m
                        .as_str()
                        .ok_or_else(|| e(line, &key, "`master` must be an axis name".into()))?;
                    let idx = axes.iter().position(|a| *a == name).ok_or_else(|| {
                        e(
                            line,
                            &key,
                            format!("unknown master `{name}`; the cell has: {}", axes.join(", ")),
                        )
                    })?;
                    if name == axis {
                        return Err(e(line, &key, format!("axis `{axis}` cannot follow itself")));
                    }
                    Some(idx as u32)
                }
            };
            let cam = match t.get("cam") {
                None => None,
                Some(c) => {
                    let name = c
                        .as_str()
                        .ok_or_else(|| e(line, &key, "`cam` must be a cam name".into()))?;
                    let idx = cams.iter().position(|c| *c == name).ok_or_else(|| {
                        e(
                            line,
                            &key,
                            format!("unknown cam `{name}`; the cell has: {}", cams.join(", ")),
                        )
                    })?;
                    Some(idx as u32)
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
                } else {
                    return Err(e(
                        line,
                        &key,
                        format!("`{k}` must be a number or true/false"),
                    ));
                };
                params.push((k.to_string(), value));
            }
            let refs = command::Refs { master, cam };
            let command = command::parse(instr, &params, refs).map_err(|m| e(line, &key, m))?;
            let name = command::find(instr).map(|s| s.name).unwrap_or("?");
            entries.push(ScriptEntry {
                t_ns: time,
                axis: axis.to_string(),
                instruction: name,
                action: Action::Command(command),
                line: line.unwrap_or(0),
            });
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
) -> Result<ScriptEntry, String> {
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
    let _ = writeln!(src, "axis = {}", quote(object));
    let _ = writeln!(src, "instruction = {}", quote(instruction));
    for (k, v) in params {
        if k.is_empty() || !k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(format!("`--{k}` is not a parameter name"));
        }
        if matches!(k.as_str(), "t" | "axis" | "instruction") {
            return Err(format!("`--{k}` is not a parameter of an instruction"));
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
        let _ = writeln!(src, "{k} = {value}");
    }
    let script = parse_cell("command", &src, cell).map_err(|e| e.message)?;
    script
        .entries
        .into_iter()
        .next()
        .ok_or_else(|| format!("`{instruction}` was not understood"))
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
pub fn split_command(text: &str) -> Result<CommandLine, String> {
    let mut words = text.split_whitespace();
    let object = words.next().ok_or("empty command")?.to_string();
    let instruction = words
        .next()
        .ok_or_else(|| format!("`{object}`: no instruction given"))?
        .to_string();
    let mut params = Vec::new();
    while let Some(w) = words.next() {
        let Some(key) = w.strip_prefix("--") else {
            return Err(format!("`{w}`: expected `--parameter value`"));
        };
        let (k, v) = match key.split_once('=') {
            Some((k, v)) => (k.to_string(), v.to_string()),
            None => (
                key.to_string(),
                words
                    .next()
                    .ok_or_else(|| format!("`--{key}` needs a value"))?
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
        assert!(e.message.contains("unknown parameter `distanc`"), "{e}");
        let e = parse("s.toml", src, &["y"], &[]).unwrap_err();
        assert!(e.message.contains("unknown axis `x`"));
    }
}
