//! MC_WriteParameter / MC_ReadParameter on the axis' run-time tags (docs/parameters.md; S7-1500T
//! Motion Control V4.0 function manual, A.2 'Tags of the positioning axis/synchronous axis
//! technology object'): every writable tag changed mid-motion is read back at once and moves
//! nothing by a jump in the next cycle; every invalid value is refused with its ErrorID and
//! leaves every parameter as it was; the effects of `DIR` and `CAL` tags. One cycle = 1 ms.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::axis::{
    axis_parameter, axis_parameter_number, AxisConfig, AxisKind, Command, AXIS_PARAMETERS,
};
use tandem_motion::objects::job::JobEventKind;
use tandem_motion::objects::parameter::ParamType;
use tandem_motion::plant::drive::DriveModel;
use tandem_testkit::rig::{dynamics as dyn_, Rig};

fn number(tag: &str) -> u16 {
    axis_parameter_number(tag).unwrap_or_else(|| panic!("no tag {tag}"))
}

fn write(tag: &str, value: f64) -> Command {
    Command::WriteParameter {
        parameter: number(tag),
        value,
    }
}

/// An enabled, homed axis moving from 0 to 400 at 300 u/s.
fn moving() -> (Rig, u32) {
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    let h = r
        .cmd(Command::Home {
            mode: 0,
            position: 0.0,
        })
        .unwrap();
    assert!(r.has(h, JobEventKind::Done));
    let m = r
        .cmd(Command::MoveAbsolute {
            position: 400.0,
            dynamics: dyn_(300.0, 1000.0, 1000.0, 20_000.0),
            direction: tandem_motion::objects::axis::Direction::Shortest,
        })
        .unwrap();
    (r, m)
}

/// A valid value other than `old` for the tag (within the example axis' other values).
fn changed(ty: ParamType, old: f64) -> f64 {
    match ty {
        ParamType::Bool => 1.0 - old,
        ParamType::Real if old != 0.0 => old * 0.8,
        ParamType::Real => old + 1.0,
    }
}

/// Every writable tag, written at several moments of a move (accelerating, cruising,
/// braking): accepted, read back at once, and the next cycle's setpoint continues the last
/// one (no step beyond what the acceleration limit allows in one cycle); the actual position
/// moves no more than the velocity allows.
#[test]
fn every_writable_tag_changed_mid_motion_takes_effect_without_a_jump() {
    let mut tried = 0;
    for (i, e) in AXIS_PARAMETERS.iter().enumerate() {
        if !e.effect.writable() {
            continue;
        }
        let n = u16::try_from(i + 1).unwrap();
        for at in [120, 700, 1300, 1560] {
            let (mut r, _) = moving();
            r.step(at);
            let before = r.axis.status_value();
            let old = r.axis.read_parameter(n).unwrap();
            let new = changed(e.ty, old);
            let id = r
                .cmd(Command::WriteParameter {
                    parameter: n,
                    value: new,
                })
                .unwrap_or_else(|err| panic!("{} = {new}: {err}", e.key));
            assert!(r.has(id, JobEventKind::Done), "{}", e.key);
            assert_eq!(r.axis.read_parameter(n), Ok(new), "{}", e.key);
            r.step(1);
            let s = r.axis.status_value();
            let dt = 1e-3;
            let predicted = before.position + before.velocity * dt;
            // One cycle of the largest acceleration and jerk of the example (5000 u/s²).
            let bound = 5000.0 * dt * dt + 1e-9;
            assert!(
                (s.position - predicted).abs() <= bound,
                "{} at cycle {at}: setpoint {} after {} at {} u/s",
                e.key,
                s.position,
                before.position,
                before.velocity
            );
            assert!(
                (s.actual_position - before.actual_position).abs() <= 500.0 * dt,
                "{} at cycle {at}: actual {} after {}",
                e.key,
                s.actual_position,
                before.actual_position
            );
            tried += 1;
        }
    }
    assert_eq!(tried, 4 * 28);
}

/// (tag, value, the ErrorID it is refused with) on the example axis.
const INVALID: &[(&str, f64, ErrorId)] = &[
    (
        "DynamicLimits.MaxVelocity",
        400.0,
        ErrorId::ParameterNotWritable,
    ),
    ("DynamicLimits.Velocity", 600.0, ErrorId::IllegalVelocity),
    ("DynamicLimits.Velocity", 50.0, ErrorId::IllegalVelocity),
    ("DynamicLimits.Velocity", 0.0, ErrorId::IllegalVelocity),
    (
        "DynamicLimits.MaxAcceleration",
        0.0,
        ErrorId::IllegalAcceleration,
    ),
    (
        "DynamicLimits.MaxAcceleration",
        500.0,
        ErrorId::IllegalAcceleration,
    ),
    (
        "DynamicLimits.MaxDeceleration",
        -1.0,
        ErrorId::IllegalDeceleration,
    ),
    ("DynamicLimits.MaxJerk", 0.0, ErrorId::IllegalJerk),
    ("DynamicDefaults.Velocity", 600.0, ErrorId::IllegalVelocity),
    (
        "DynamicDefaults.Acceleration",
        6000.0,
        ErrorId::IllegalAcceleration,
    ),
    (
        "DynamicDefaults.Deceleration",
        0.0,
        ErrorId::IllegalDeceleration,
    ),
    ("DynamicDefaults.Jerk", -1.0, ErrorId::IllegalJerk),
    (
        "DynamicDefaults.EmergencyDeceleration",
        0.0,
        ErrorId::IllegalDeceleration,
    ),
    (
        "PositionLimits_SW.Active",
        0.5,
        ErrorId::IllegalParameterValue,
    ),
    (
        "PositionLimits_SW.MinPosition",
        2e12,
        ErrorId::IllegalPosition,
    ),
    (
        "PositionLimits_SW.MaxPosition",
        -2e12,
        ErrorId::IllegalPosition,
    ),
    (
        "PositionLimits_HW.Active",
        1.0,
        ErrorId::ParameterNotWritable,
    ),
    ("Homing.AutoReversal", 0.0, ErrorId::ParameterNotWritable),
    (
        "Homing.ApproachDirection",
        2.0,
        ErrorId::IllegalParameterValue,
    ),
    ("Homing.ApproachVelocity", 0.0, ErrorId::IllegalVelocity),
    ("Homing.ReferencingVelocity", -5.0, ErrorId::IllegalVelocity),
    ("Override.Velocity", 250.0, ErrorId::IllegalOverride),
    ("PositionControl.Kv", 0.0, ErrorId::IllegalParameterValue),
    ("PositionControl.Kpc", 151.0, ErrorId::IllegalParameterValue),
    (
        "FollowingError.EnableMonitoring",
        0.0,
        ErrorId::ParameterNotWritable,
    ),
    (
        "FollowingError.MinValue",
        20.0,
        ErrorId::IllegalParameterValue,
    ),
    (
        "FollowingError.MaxValue",
        0.5,
        ErrorId::IllegalParameterValue,
    ),
    (
        "FollowingError.MinVelocity",
        -1.0,
        ErrorId::IllegalParameterValue,
    ),
    (
        "FollowingError.WarningLevel",
        101.0,
        ErrorId::IllegalParameterValue,
    ),
    (
        "PositioningMonitoring.ToleranceTime",
        -1.0,
        ErrorId::IllegalParameterValue,
    ),
    (
        "PositioningMonitoring.MinDwellTime",
        -0.5,
        ErrorId::IllegalParameterValue,
    ),
    (
        "PositioningMonitoring.Window",
        -0.01,
        ErrorId::IllegalParameterValue,
    ),
    (
        "StandstillSignal.VelocityThreshold",
        -1.0,
        ErrorId::IllegalParameterValue,
    ),
    (
        "StandstillSignal.MinDwellTime",
        -1.0,
        ErrorId::IllegalParameterValue,
    ),
];

/// Every invalid value, every writable tag with a value that is not a number, and unknown
/// numbers are refused with their ErrorID while the axis moves; every parameter, the
/// configuration and the motion are as before.
#[test]
fn every_invalid_value_is_refused_with_its_error_id_and_nothing_changes() {
    let (mut r, _) = moving();
    r.step(500);
    let mut cases: Vec<(u16, f64, ErrorId)> = INVALID
        .iter()
        .map(|&(tag, x, id)| (number(tag), x, id))
        .collect();
    for (i, e) in AXIS_PARAMETERS.iter().enumerate() {
        let n = u16::try_from(i + 1).unwrap();
        let id = if e.effect.writable() {
            ErrorId::InvalidRealFormat
        } else {
            ErrorId::ParameterNotWritable
        };
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            cases.push((n, x, id));
        }
    }
    let unknown = u16::try_from(AXIS_PARAMETERS.len() + 1).unwrap();
    for n in [0, unknown, 999, u16::MAX] {
        cases.push((n, 1.0, ErrorId::InvalidParameterNumber));
    }
    for (n, x, id) in cases {
        let params = r.axis.parameters();
        let cfg = r.axis.config().clone();
        let events = r.events.len();
        let got = r.cmd(Command::WriteParameter {
            parameter: n,
            value: x,
        });
        let tag = axis_parameter(n).map_or("(unknown)", |e| e.key);
        assert_eq!(got, Err(id), "{tag} = {x}");
        assert_eq!(r.axis.parameters(), params, "{tag} = {x}");
        assert_eq!(r.axis.config(), &cfg, "{tag} = {x}");
        assert_eq!(r.events.len(), events, "{tag} = {x}: no event");
    }
    // The move goes on as planned.
    let s = r.axis.status_value();
    assert!((s.velocity - 300.0).abs() < 1e-9, "{}", s.velocity);
}

/// Parameters the axis does not have: a speed axis' position-related tags, the position
/// controller of a delay-model drive (16#8086); reading them is refused the same way.
#[test]
fn parameters_the_axis_does_not_have_are_not_available() {
    let mut speed = AxisConfig::example(0.001);
    speed.kind = AxisKind::Speed;
    let mut r = Rig::enabled(speed);
    for tag in [
        "PositionLimits_SW.Active",
        "PositionLimits_SW.MaxPosition",
        "Homing.HomePosition",
        "PositionControl.Kv",
        "FollowingError.MaxValue",
        "PositioningMonitoring.Window",
    ] {
        assert_eq!(
            r.cmd(write(tag, 1.0)),
            Err(ErrorId::ParameterNotAvailable),
            "{tag}"
        );
        assert_eq!(
            r.axis.read_parameter(number(tag)),
            Err(ErrorId::ParameterNotAvailable)
        );
    }
    assert!(r.cmd(write("DynamicLimits.MaxJerk", 50_000.0)).is_ok());
    let mut delay = AxisConfig::example(0.001);
    delay.drive = DriveModel::Delay { delay: 0.002 };
    let mut r = Rig::enabled(delay);
    assert_eq!(
        r.cmd(write("PositionControl.Kpc", 50.0)),
        Err(ErrorId::ParameterNotAvailable)
    );
}

/// `DynamicLimits.Velocity` (`DIR`) below the running job's velocity: from the next cycle the
/// job brakes (at its deceleration, no jump) down to the new limit and cruises there; it still
/// reaches its target. A higher limit does not speed the job up.
#[test]
fn a_lower_velocity_limit_brakes_the_running_job_from_the_next_cycle() {
    let (mut r, m) = moving();
    r.step(600);
    assert!((r.axis.status_value().velocity - 300.0).abs() < 1e-9);
    r.cmd(write("DynamicLimits.Velocity", 200.0)).unwrap();
    let mut last = r.axis.status_value();
    r.step(1);
    assert!(
        r.axis.status_value().velocity < last.velocity,
        "braking at once"
    );
    for _ in 0..300 {
        last = r.axis.status_value();
        r.step(1);
        let s = r.axis.status_value();
        assert!(s.velocity <= last.velocity + 1e-9, "never faster");
        assert!(
            (s.acceleration).abs() <= 1000.0 + 1e-6,
            "{}",
            s.acceleration
        );
    }
    let v = r.axis.status_value().velocity;
    assert!((v - 200.0).abs() < 1e-6, "cruises at the new limit: {v}");
    r.cmd(write("DynamicLimits.Velocity", 500.0)).unwrap();
    r.step(50);
    let v = r.axis.status_value().velocity;
    assert!(
        (v - 200.0).abs() < 1e-6,
        "a higher limit keeps the job's dynamics: {v}"
    );
    r.until(m, JobEventKind::Done, 5000);
    assert!((r.axis.status_value().position - 400.0).abs() < 0.01);
}

/// `DynamicDefaults.Velocity` (`CAL`): the running job keeps the default it started with; the
/// next job that asks for the default gets the new one.
#[test]
fn dynamic_defaults_apply_at_the_next_job() {
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    let far = Command::MoveRelative {
        distance: 10_000.0,
        dynamics: Dynamics::DEFAULT,
    };
    r.cmd(far).unwrap();
    r.step(500);
    assert!((r.axis.status_value().velocity - 100.0).abs() < 1e-9);
    r.cmd(write("DynamicDefaults.Velocity", 50.0)).unwrap();
    r.step(500);
    assert!((r.axis.status_value().velocity - 100.0).abs() < 1e-9);
    r.cmd(far).unwrap();
    r.step(500);
    assert!((r.axis.status_value().velocity - 50.0).abs() < 1e-9);
}

/// `PositioningMonitoring.Window` and `FollowingError.MaxValue` (`DIR`) act in the next cycle;
/// MC_ReadParameter reads what was written; `Override.Velocity` written as a tag is the
/// override.
#[test]
fn monitoring_tags_and_the_override_act_from_the_next_cycle() {
    let (mut r, _) = moving();
    r.step(300);
    r.cmd(write("Override.Velocity", 50.0)).unwrap();
    assert_eq!(r.axis.status_value().override_velocity, 50.0);
    r.step(2000);
    assert!((r.axis.status_value().velocity - 150.0).abs() < 1e-6);
    r.cmd(write("FollowingError.MaxValue", 2.5)).unwrap();
    assert_eq!(r.axis.config().following_error.max_value, 2.5);
    assert_eq!(
        r.axis.read_parameter(number("FollowingError.MaxValue")),
        Ok(2.5)
    );
    r.cmd(write("PositionLimits_SW.MaxPosition", 1000.0))
        .unwrap();
    assert_eq!(r.axis.config().sw_limits, None, "inactive until Active");
    r.cmd(write("PositionLimits_SW.MinPosition", -1000.0))
        .unwrap();
    r.cmd(write("PositionLimits_SW.Active", 1.0)).unwrap();
    let sw = r.axis.config().sw_limits.expect("active");
    assert_eq!((sw.min, sw.max), (-1000.0, 1000.0));
    assert_eq!(
        r.axis.read_parameter(number("PositionLimits_SW.Active")),
        Ok(1.0)
    );
}

/// `write_parameters` (the retained values at start) applies all or none, checked together:
/// a lower limit and the lower default it needs are accepted in either order.
#[test]
fn several_parameters_at_once_are_checked_together() {
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    let acc = number("DynamicLimits.MaxAcceleration");
    let def = number("DynamicDefaults.Acceleration");
    assert!(r
        .axis
        .write_parameters(&[(acc, 800.0), (def, 700.0)])
        .is_ok());
    assert_eq!(r.axis.read_parameter(acc), Ok(800.0));
    assert_eq!(r.axis.read_parameter(def), Ok(700.0));
    let before = r.axis.parameters();
    assert_eq!(
        r.axis.write_parameters(&[(def, 900.0), (acc, 850.0)]),
        Err((acc, ErrorId::IllegalAcceleration))
    );
    assert_eq!(
        r.axis
            .write_parameters(&[(acc, 900.0), (number("DynamicLimits.MaxVelocity"), 1.0)]),
        Err((
            number("DynamicLimits.MaxVelocity"),
            ErrorId::ParameterNotWritable
        ))
    );
    assert_eq!(r.axis.parameters(), before);
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 512,
        rng_algorithm: proptest::test_runner::RngAlgorithm::ChaCha,
        ..ProptestConfig::with_source_file(file!())
    })]

    /// Any value for any parameter number: accepted and read back exactly, or refused with
    /// the row's ErrorID (or 16#8080 / 16#8081 / 16#808B) and nothing changed.
    #[test]
    fn any_write_is_applied_exactly_or_refused_unchanged(
        n in 0u16..40,
        x in prop_oneof![-1e4f64..1e4, Just(0.0), Just(1.0), Just(f64::NAN), -2e12f64..2e12],
        at in 0usize..1500,
    ) {
        let (mut r, _) = moving();
        r.step(at);
        let before = r.axis.parameters();
        match r.cmd(Command::WriteParameter { parameter: n, value: x }) {
            Ok(_) => prop_assert_eq!(r.axis.read_parameter(n), Ok(x)),
            Err(id) => {
                let allowed = match axis_parameter(n) {
                    None => id == ErrorId::InvalidParameterNumber,
                    Some(e) => [e.invalid, ErrorId::ParameterNotWritable, ErrorId::InvalidRealFormat]
                        .contains(&id),
                };
                prop_assert!(allowed, "{} = {}: {}", n, x, id);
                prop_assert_eq!(r.axis.parameters(), before);
            }
        }
    }
}

/// docs/parameters.md lists every row of the table as the code has it (number, tag, unit,
/// type, effect, range, ErrorID, section).
#[test]
fn the_documented_table_is_the_code_table() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let doc = std::fs::read_to_string(root.join("docs/parameters.md")).unwrap_or_default();
    let mut missing = Vec::new();
    for (i, e) in AXIS_PARAMETERS.iter().enumerate() {
        let ty = match e.ty {
            ParamType::Real => "LREAL",
            ParamType::Bool => "BOOL",
        };
        let line = format!(
            "| {} | `{}` | {} | {ty} | {} | {} | `16#{:04X}` | {} |",
            i + 1,
            e.key,
            if e.unit.is_empty() { "–" } else { e.unit },
            e.effect.code(),
            e.range,
            e.invalid.code(),
            e.reference
        );
        if !doc.contains(&line) {
            missing.push(line);
        }
    }
    assert!(
        missing.is_empty(),
        "not in docs/parameters.md:\n{}",
        missing.join("\n")
    );
}
