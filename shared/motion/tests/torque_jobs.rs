//! MC_TorqueLimiting, MC_TorqueAdditive and MC_TorqueRange on the axis alone (S7-1500T Motion
//! Control V4.0, 10.15): the refusals that need no drive, the torque outputs handed to the
//! drive, the clamping windows of the configuration. The drive side and fixed stop detection:
//! `shared/runtime/tests/drive_axis/torque.rs`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::objects::axis::{Axis, AxisConfig, AxisConfigProblem, AxisKind, Command};

fn limiting(enable: bool, limit: f64, mode: i32) -> Command {
    Command::TorqueLimiting {
        enable,
        limit,
        mode,
    }
}

#[test]
fn an_axis_without_a_torque_interface_refuses_the_torque_jobs() {
    let mut axis = Axis::new(AxisConfig::example(0.001)).unwrap();
    assert_eq!(
        axis.command(&limiting(true, 10.0, 0)),
        Err(ErrorId::TorqueReductionNotConfigured)
    );
    assert_eq!(
        axis.command(&Command::TorqueAdditive {
            enable: true,
            value: 1.0
        }),
        Err(ErrorId::NoAdditionalTorqueTelegram)
    );
    assert_eq!(
        axis.command(&Command::TorqueRange {
            enable: true,
            upper_limit: 1.0,
            lower_limit: -1.0
        }),
        Err(ErrorId::NoAdditionalTorqueTelegram)
    );
    // Disabling what does not run is no error.
    assert_eq!(axis.command(&limiting(false, 10.0, 0)), Ok(0));
    assert_eq!(axis.drive_outputs().torque.limit, None);
}

#[test]
fn the_outputs_carry_the_jobs_values_and_a_disabled_axis_takes_them() {
    let mut axis = Axis::new(AxisConfig::example(0.001)).unwrap();
    axis.connect_drive();
    axis.set_torque_interface(true);
    let id = axis.command(&limiting(true, 12.5, 0)).unwrap();
    assert!(id > 0);
    axis.step(0);
    assert_eq!(axis.drive_outputs().torque.limit, Some(12.5));
    // Re-sent with a new limit: the same job.
    assert_eq!(axis.command(&limiting(true, 20.0, 0)), Ok(id));
    axis.step(1_000_000);
    assert_eq!(axis.drive_outputs().torque.limit, Some(20.0));
    assert!(axis.torque_status().limiting_active);
    assert_eq!(
        axis.command(&limiting(true, -1.0, 0)),
        Err(ErrorId::IllegalTorqueLimit),
        "no limit_default configured"
    );
    assert_eq!(
        axis.command(&limiting(true, f64::INFINITY, 0)),
        Err(ErrorId::IllegalTorqueLimit)
    );
    assert_eq!(axis.command(&limiting(false, 0.0, 0)), Ok(id));
    axis.command(&Command::TorqueAdditive {
        enable: true,
        value: -3.0,
    })
    .unwrap();
    axis.command(&Command::TorqueRange {
        enable: true,
        upper_limit: 5.0,
        lower_limit: -4.0,
    })
    .unwrap();
    axis.step(2_000_000);
    let t = axis.drive_outputs().torque;
    assert_eq!(
        (t.limit, t.range, t.additive),
        (None, Some((5.0, -4.0)), -3.0)
    );
    assert_eq!(
        axis.command(&limiting(true, 1.0, 0)),
        Err(ErrorId::TorqueLimitingRangeExclusive)
    );
}

#[test]
fn fixed_stop_detection_needs_a_positioning_axis() {
    let mut cfg = AxisConfig::example(0.001);
    cfg.kind = AxisKind::Speed;
    let mut axis = Axis::new(cfg).unwrap();
    axis.set_torque_interface(true);
    assert_eq!(
        axis.command(&limiting(true, 1.0, 1)),
        Err(ErrorId::IllegalMode)
    );
    assert!(axis.command(&limiting(true, 1.0, 0)).is_ok());
}

#[test]
fn the_clamping_tolerance_must_be_below_the_deviation() {
    let mut cfg = AxisConfig::example(0.001);
    cfg.torque.clamping_tolerance = 1.0;
    cfg.torque.clamping_deviation = 1.0;
    let err = Axis::new(cfg.clone()).unwrap_err();
    assert_eq!(err.problem, AxisConfigProblem::ClampingWindows);
    // Kept on under limiting, following error monitoring needs the deviation below its
    // maximum (10 in the example).
    cfg.torque.clamping_tolerance = 0.1;
    cfg.torque.clamping_deviation = 12.0;
    assert!(Axis::new(cfg.clone()).is_ok());
    cfg.torque.keep_position_monitorings = true;
    assert_eq!(
        Axis::new(cfg).unwrap_err().problem,
        AxisConfigProblem::ClampingWindows
    );
}
