//! Instruction names and parameters as people write them (script files, the CLI) to engine
//! commands. Names are the PLCopen ones, with or without `MC_`, in any case, with or without
//! underscores: `MC_MoveAbsolute`, `MoveAbsolute`, `move_absolute`. Parameters are the
//! references' input names in snake case (`position`, `velocity`, `abort_acceleration`...).
//! Defaults are the references' defaults (dynamics -1.0 = the axis defaults).

use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::axis::{
    ApplicationMode, CamId, Command, Direction, StartMode, StopMode, SyncDirection,
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
        ],
    },
    InstructionSpec {
        name: "MC_MoveRelative",
        params: &[("distance", None), DYN[0], DYN[1], DYN[2], DYN[3]],
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
        "MC_GearIn" | "MC_GearInPos" | "MC_GearInVelocity" | "MC_CamIn"
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

struct Args<'a> {
    spec: &'static InstructionSpec,
    given: &'a [(String, Value)],
}

impl Args<'_> {
    fn get(&self, key: &str) -> Result<Value, String> {
        if let Some((_, v)) = self.given.iter().rev().find(|(k, _)| k == key) {
            return Ok(*v);
        }
        match self.spec.params.iter().find(|(k, _)| *k == key) {
            Some((_, Some(d))) => Ok(*d),
            _ => Err(format!("{}: parameter `{key}` is required", self.spec.name)),
        }
    }

    fn num(&self, key: &str) -> Result<f64, String> {
        match self.get(key)? {
            Value::Num(x) => Ok(x),
            Value::Bool(_) => Err(format!("{}: `{key}` must be a number", self.spec.name)),
        }
    }

    fn flag(&self, key: &str) -> Result<bool, String> {
        match self.get(key)? {
            Value::Bool(b) => Ok(b),
            Value::Num(_) => Err(format!("{}: `{key}` must be true or false", self.spec.name)),
        }
    }

    fn code(&self, key: &str) -> Result<i32, String> {
        let x = self.num(key)?;
        if x.fract() != 0.0 || !(-1e6..=1e6).contains(&x) {
            return Err(format!("{}: `{key}` must be an integer", self.spec.name));
        }
        Ok(x as i32)
    }

    fn dynamics_no_velocity(&self) -> Result<Dynamics, String> {
        Ok(Dynamics {
            velocity: -1.0,
            acceleration: self.num("acceleration")?,
            deceleration: self.num("deceleration")?,
            jerk: self.num("jerk")?,
        })
    }

    fn dynamics(&self, vel_key: &str) -> Result<Dynamics, String> {
        Ok(Dynamics {
            velocity: self.num(vel_key)?,
            acceleration: self.num("acceleration")?,
            deceleration: self.num("deceleration")?,
            jerk: self.num("jerk")?,
        })
    }
}

/// Builds a command. Unknown instructions and parameters, missing required parameters and
/// values of the wrong type are errors naming what was wrong. `master` is the leader the
/// instruction names (resolved by the caller), for the instructions that need one.
pub fn parse(instruction: &str, params: &[(String, Value)], refs: Refs) -> Result<Command, String> {
    let master: Option<LeaderId> = refs.master;
    let spec = find(instruction).ok_or_else(|| {
        let names: Vec<&str> = INSTRUCTIONS.iter().map(|i| i.name).collect();
        format!(
            "unknown instruction `{instruction}`; known: {}",
            names.join(", ")
        )
    })?;
    for (k, _) in params {
        if !spec.params.iter().any(|(p, _)| p == k) {
            let names: Vec<&str> = spec.params.iter().map(|(p, _)| *p).collect();
            return Err(format!(
                "{}: unknown parameter `{k}`; parameters: {}",
                spec.name,
                names.join(", ")
            ));
        }
    }
    let a = Args {
        spec,
        given: params,
    };
    let leader = || {
        master.ok_or_else(|| {
            format!(
                "{}: parameter `master` (the leading axis) is required",
                spec.name
            )
        })
    };
    let ratio = |k: &str| -> Result<i32, String> { a.code(k) };
    let cmd = match spec.name {
        "MC_GearIn" => Command::GearIn {
            master: leader()?,
            ratio_numerator: ratio("ratio_numerator")?,
            ratio_denominator: ratio("ratio_denominator")?,
            dynamics: a.dynamics_no_velocity()?,
        },
        "MC_GearInPos" => Command::GearInPos {
            master: leader()?,
            ratio_numerator: ratio("ratio_numerator")?,
            ratio_denominator: ratio("ratio_denominator")?,
            master_sync_position: a.num("master_sync_position")?,
            slave_sync_position: a.num("slave_sync_position")?,
            sync_profile_reference: match a.code("sync_profile_reference")? {
                0 => SyncProfileReference::Dynamics,
                1 => SyncProfileReference::MasterStartDistance,
                _ => return Err("MC_GearInPos: sync_profile_reference must be 0 or 1".into()),
            },
            master_start_distance: a.num("master_start_distance")?,
            dynamics: a.dynamics("velocity")?,
            sync_direction: match a.code("sync_direction")? {
                1 => SyncDirection::Positive,
                2 => SyncDirection::Negative,
                3 => SyncDirection::Shortest,
                _ => return Err("MC_GearInPos: sync_direction must be 1, 2 or 3".into()),
            },
        },
        "MC_GearOut" => Command::GearOut,
        "MC_CamIn" => Command::CamIn {
            master: leader()?,
            cam: refs
                .cam
                .ok_or("MC_CamIn: parameter `cam` (the cam's name) is required")?,
            master_offset: a.num("master_offset")?,
            slave_offset: a.num("slave_offset")?,
            master_scaling: a.num("master_scaling")?,
            slave_scaling: a.num("slave_scaling")?,
            master_sync_position: a.num("master_sync_position")?,
            sync_profile_reference: match a.code("sync_profile_reference")? {
                0 => SyncProfileReference::Dynamics,
                1 => SyncProfileReference::MasterStartDistance,
                2 => SyncProfileReference::Direct,
                _ => return Err("MC_CamIn: sync_profile_reference must be 0, 1 or 2".into()),
            },
            master_start_distance: a.num("master_start_distance")?,
            dynamics: a.dynamics("velocity")?,
            application_mode: match a.code("application_mode")? {
                0 => ApplicationMode::Once,
                1 => ApplicationMode::Cyclic,
                2 => ApplicationMode::CyclicAppending,
                _ => return Err("MC_CamIn: application_mode must be 0, 1 or 2".into()),
            },
            sync_direction: match a.code("sync_direction")? {
                1 => SyncDirection::Positive,
                2 => SyncDirection::Negative,
                3 => SyncDirection::Shortest,
                _ => return Err("MC_CamIn: sync_direction must be 1, 2 or 3".into()),
            },
        },
        "MC_CamOut" => Command::CamOut,
        "MC_SynchronizedMotionSimulation" => Command::SynchronizedMotionSimulation {
            enable: a.flag("enable")?,
        },
        "MC_GearInVelocity" => Command::GearInVelocity {
            master: leader()?,
            ratio_numerator: ratio("ratio_numerator")?,
            ratio_denominator: ratio("ratio_denominator")?,
            dynamics: a.dynamics_no_velocity()?,
        },
        "MC_OffsetAbsolute" | "MC_OffsetRelative" => Command::Offset {
            offset: a.num("offset")?,
            absolute: spec.name == "MC_OffsetAbsolute",
            dynamics: a.dynamics("velocity")?,
        },
        "MC_PhasingAbsolute" | "MC_PhasingRelative" => Command::Phasing {
            phase_shift: a.num("phase_shift")?,
            absolute: spec.name == "MC_PhasingAbsolute",
            dynamics: a.dynamics("velocity")?,
        },
        "MC_Power" => Command::Power {
            enable: a.flag("enable")?,
            start_mode: match a.code("start_mode")? {
                0 => StartMode::NonPositionControlled,
                1 => StartMode::PositionControlled,
                _ => return Err("MC_Power: start_mode must be 0 or 1".into()),
            },
            stop_mode: match a.code("stop_mode")? {
                0 => StopMode::Emergency,
                1 => StopMode::Immediate,
                2 => StopMode::MaxDynamics,
                _ => return Err("MC_Power: stop_mode must be 0, 1 or 2".into()),
            },
        },
        "MC_Reset" => Command::Reset {
            restart: a.flag("restart")?,
        },
        "MC_Home" => {
            let mode = a.code("mode")?;
            Command::Home {
                mode: u8::try_from(mode).map_err(|_| "MC_Home: mode must be 0..10".to_string())?,
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
        "MC_MoveAbsolute" => Command::MoveAbsolute {
            position: a.num("position")?,
            dynamics: a.dynamics("velocity")?,
            direction: Direction::from_code(a.code("direction")?)
                .ok_or("MC_MoveAbsolute: direction must be 1, 2 or 3")?,
        },
        "MC_MoveRelative" => Command::MoveRelative {
            distance: a.num("distance")?,
            dynamics: a.dynamics("velocity")?,
        },
        "MC_MoveVelocity" => Command::MoveVelocity {
            dynamics: a.dynamics("velocity")?,
            direction: VelocityDirection::from_code(a.code("direction")?)
                .ok_or("MC_MoveVelocity: direction must be 0, 1 or 2")?,
            current: a.flag("current")?,
            position_controlled: a.flag("position_controlled")?,
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
        other => return Err(format!("instruction `{other}` has no parser")),
    };
    Ok(cmd)
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
            .contains("`position` is required"));
        assert!(parse(
            "MoveAbsolute",
            &[p("postion", Value::Num(1.0))],
            Refs::default()
        )
        .unwrap_err()
        .contains("unknown parameter `postion`"));
        assert!(
            parse("MC_Power", &[p("enable", Value::Num(1.0))], Refs::default())
                .unwrap_err()
                .contains("true or false")
        );
        assert!(
            parse("MC_Home", &[p("mode", Value::Num(2.5))], Refs::default())
                .unwrap_err()
                .contains("integer")
        );
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
