//! MC_TorqueLimiting, MC_TorqueRange and MC_TorqueAdditive on `config/servo.toml`'s simulated
//! CiA 402 servo (S7-1500T Motion Control V4.0 function manual, 'Force/torque limiting',
//! 'Fixed stop detection', 'MC_TorqueLimiting V4', 'MC_TorqueAdditive V4', 'MC_TorqueRange
//! V4'): the limit in N through the mechanics to 0x6072, fixed stop detection at the
//! configured deviation, the clamping torque held at the limit, alarm 542 when the stop gives
//! way, and the refusals.
//!
//! The numbers: load gear 3:1 and a 10 mm leadscrew make 1 N·m at the motor
//! 3 · 2π / 10 mm = 1884.96 N at the load (efficiency 1); 500 N is 0.265258 N·m, 208.86 ‰ of
//! the rated 1.27 N·m: 0x6072 = 209.

use super::{cell, Run};
use tandem_motion::catalog::alarm::{status_bit, AlarmId};
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{AxisState, Command, StartMode, VelocityDirection};

/// `config/servo.toml` with a mechanical stop at 50 mm, the clamping windows of the test
/// (deviation 0.5 mm, tolerance 0.05 mm) and the drive's own following-error window opened
/// (the servo would fault at 0.83 mm while the load is held at the stop).
fn stop_cell() -> tandem_config::Cell {
    cell(|s| {
        s.replace(
            "following_error_window = 262144",
            "following_error_window = 4294967295",
        ) + "\n[axes.slide.plant]\nfixed_stop_max = 50.0\n\n[axes.slide.clamping]\n\
             following_error_deviation = 0.5\nposition_tolerance = 0.05\n\n\
             [axes.slide.torque_limiting]\nlimit_default = 300.0\n"
    })
}

fn try_cmd(r: &mut Run<'_>, c: Command) -> Result<Option<u32>, ErrorId> {
    let t = r.t();
    r.exec
        .apply(t, "slide", "test", Action::Command(c), &mut r.log)
        .unwrap()
}

fn limiting(limit: f64, mode: i32) -> Command {
    Command::TorqueLimiting {
        enable: true,
        limit,
        mode,
    }
}

fn enabled_at_zero(r: &mut Run<'_>) {
    r.power(StartMode::PositionControlled);
    r.cmd(Command::Home {
        mode: 0,
        position: 0.0,
    });
}

fn has(r: &mut Run<'_>, bit: u32) -> bool {
    r.status().status_word & bit != 0
}

#[test]
fn the_limit_in_newtons_is_max_torque_0x6072_in_per_mille_of_the_rated_torque() {
    let cell = stop_cell();
    let mut r = Run::new(&cell);
    enabled_at_zero(&mut r);
    r.step();
    assert_eq!(
        r.exec.drive_rx(0).unwrap().max_torque,
        0,
        "no job: no limit"
    );
    r.cmd(limiting(500.0, 0));
    r.step();
    assert_eq!(r.exec.drive_rx(0).unwrap().max_torque, 209);
    assert!(has(&mut r, status_bit::TORQUE_LIMITING_COMMAND));
    // Limit < 0: `torque_limiting.limit_default` = 300 N, 125.3 ‰.
    r.cmd(limiting(-1.0, 0));
    r.step();
    assert_eq!(r.exec.drive_rx(0).unwrap().max_torque, 125);
    // Limit 0 is allowed (S7: "0 value is permissible"): the smallest the object takes.
    r.cmd(limiting(0.0, 0));
    r.step();
    assert_eq!(r.exec.drive_rx(0).unwrap().max_torque, 1);
    // Refusals change nothing.
    assert_eq!(
        try_cmd(&mut r, limiting(f64::NAN, 0)),
        Err(ErrorId::IllegalTorqueLimit)
    );
    assert_eq!(
        try_cmd(&mut r, limiting(10.0, 2)),
        Err(ErrorId::IllegalMode)
    );
    assert_eq!(
        try_cmd(
            &mut r,
            Command::TorqueRange {
                enable: true,
                upper_limit: 1.0,
                lower_limit: -1.0
            }
        ),
        Err(ErrorId::TorqueLimitingRangeExclusive)
    );
    r.step();
    assert_eq!(r.exec.drive_rx(0).unwrap().max_torque, 1);
    r.cmd(Command::TorqueLimiting {
        enable: false,
        limit: 0.0,
        mode: 0,
    });
    r.step();
    assert_eq!(r.exec.drive_rx(0).unwrap().max_torque, 0);
    assert!(!has(&mut r, status_bit::TORQUE_LIMITING_COMMAND));
    assert!(
        r.log().contains("MC_TorqueLimiting job 3: Done"),
        "{}",
        r.log()
    );
}

#[test]
fn a_default_is_needed_for_a_negative_limit() {
    let cell = cell(|s| s);
    let mut r = Run::new(&cell);
    assert_eq!(
        try_cmd(&mut r, limiting(-1.0, 0)),
        Err(ErrorId::IllegalTorqueLimit)
    );
    // The TO need not be enabled.
    assert!(try_cmd(&mut r, limiting(100.0, 0)).is_ok());
}

/// Drives the slide into the stop at 50 mm at 50 mm/s under fixed stop detection with 500 N.
fn clamp(r: &mut Run<'_>) {
    enabled_at_zero(r);
    r.cmd(limiting(500.0, 1));
    r.move_to(100.0, 50.0, 1000.0);
    r.until(2000, "InClamping", |r| {
        r.status().status_word & status_bit::IN_CLAMPING != 0
    });
}

#[test]
fn the_fixed_stop_is_detected_at_the_deviation_and_held_at_the_limit() {
    let cell = stop_cell();
    let mut r = Run::new(&cell);
    clamp(&mut r);
    let s = r.status();
    // Detected in the first cycle the following error exceeds 0.5 mm, against the stop.
    assert!(
        s.following_error > 0.5 && s.following_error < 0.6,
        "{}",
        s.following_error
    );
    assert!((s.actual_position - 50.0).abs() < 1e-3, "{s:?}");
    assert!(
        r.log().contains("MC_MoveAbsolute job 4: CommandAborted"),
        "{}",
        r.log()
    );
    let frozen = s.position;
    for _ in 0..300 {
        r.step();
        let s = r.status();
        assert_eq!(s.position, frozen, "the setpoint holds");
        assert_eq!(s.state, AxisState::Standstill);
        assert!(has(&mut r, status_bit::IN_CLAMPING));
    }
    // The clamping torque: the limit, 209 ‰ in 0x6077; 500 N as ActualTorque within the
    // drive's resolution (1 ‰ is 2.39 N); the drive works at its limit (X27).
    let fb = r.fb().unwrap();
    assert_eq!(fb.torque_actual, 209, "{fb:?}");
    let t = r
        .exec
        .axis(tandem_config::AxisIndex(0))
        .unwrap()
        .torque_status();
    assert!((t.actual_torque - 500.0).abs() <= 2.4, "{t:?}");
    assert!(t.in_clamping && t.limiting_active);
    assert!(has(&mut r, status_bit::IN_LIMITATION));
    assert_eq!(r.alarm(AlarmId::FollowingError), None);

    // While clamped: no disable (16#8046), no motion into the stop (16#8047), no switch to
    // non-position-controlled (16#8045).
    assert_eq!(
        try_cmd(
            &mut r,
            Command::TorqueLimiting {
                enable: false,
                limit: 500.0,
                mode: 1
            }
        ),
        Err(ErrorId::InClamping)
    );
    assert_eq!(
        try_cmd(
            &mut r,
            Command::MoveRelative {
                distance: 5.0,
                dynamics: Dynamics::default()
            }
        ),
        Err(ErrorId::MotionIntoFixedStop)
    );
    assert_eq!(
        try_cmd(
            &mut r,
            Command::MoveVelocity {
                dynamics: Dynamics {
                    velocity: 10.0,
                    ..Dynamics::default()
                },
                direction: VelocityDirection::Negative,
                current: false,
                position_controlled: false,
            }
        ),
        Err(ErrorId::FixedStopActive)
    );
    // The clamping force may change: 200 N is 83.6 ‰.
    r.cmd(limiting(200.0, 1));
    for _ in 0..50 {
        r.step();
    }
    assert_eq!(r.fb().unwrap().torque_actual, 84);
    assert!(has(&mut r, status_bit::IN_CLAMPING));
}

#[test]
fn the_clamping_alarm_when_the_stop_gives_way() {
    let cell = stop_cell();
    let mut r = Run::new(&cell);
    clamp(&mut r);
    for _ in 0..50 {
        r.step();
    }
    assert!(r.exec.set_fixed_stops(0, None, None));
    r.until(50, "alarm 542", |r| {
        r.alarm(AlarmId::ClampingMonitoring).is_some()
    });
    let s = r.status();
    // Raised in the cycle the load leaves the 0.05 mm window.
    assert!(
        s.actual_position > 50.05 && s.actual_position < 50.1,
        "{s:?}"
    );
    r.step();
    assert_eq!(r.state(), AxisState::ErrorStop);
    assert!(!has(&mut r, status_bit::IN_CLAMPING));
    assert_eq!(
        r.status().status_word & status_bit::ENABLE,
        0,
        "remove enable"
    );
    // MC_TorqueLimiting is not aborted: it stays and may now be disabled.
    assert!(has(&mut r, status_bit::TORQUE_LIMITING_COMMAND));
    assert!(try_cmd(
        &mut r,
        Command::TorqueLimiting {
            enable: false,
            limit: 500.0,
            mode: 1
        }
    )
    .is_ok());
}

#[test]
fn retracting_away_from_the_stop_ends_the_clamping_without_an_alarm() {
    let cell = stop_cell();
    let mut r = Run::new(&cell);
    clamp(&mut r);
    r.step();
    // Gently: under the 500 N limit the default 2000 mm/s² would need 0.38 N·m at the motor
    // for the inertia alone, the lag would pass the 0.5 mm deviation and detect a "stop".
    r.cmd(Command::MoveRelative {
        distance: -5.0,
        dynamics: Dynamics {
            velocity: 20.0,
            acceleration: 200.0,
            deceleration: 200.0,
            jerk: 0.0,
        },
    });
    r.until(2000, "clamping left", |r| {
        r.status().status_word & status_bit::IN_CLAMPING == 0
    });
    r.until(3000, "retracted", |r| {
        r.log().contains("MC_MoveRelative job 5: Done")
    });
    assert_eq!(r.alarm(AlarmId::ClampingMonitoring), None);
    assert!((r.status().actual_position - (r.status().position)).abs() < 0.01);
    // Fixed stop detection is armed again: disable is allowed.
    assert!(try_cmd(
        &mut r,
        Command::TorqueLimiting {
            enable: false,
            limit: 500.0,
            mode: 1
        }
    )
    .is_ok());
}

#[test]
fn torque_range_and_additive_torque_in_the_drive_objects() {
    let cell = stop_cell();
    let mut r = Run::new(&cell);
    enabled_at_zero(&mut r);
    let range = |upper, lower| Command::TorqueRange {
        enable: true,
        upper_limit: upper,
        lower_limit: lower,
    };
    assert_eq!(
        try_cmd(&mut r, range(100.0, 100.0)),
        Err(ErrorId::TorqueLimitsInverted)
    );
    assert_eq!(
        try_cmd(&mut r, range(2e12, 0.0)),
        Err(ErrorId::IllegalUpperTorqueLimit)
    );
    assert_eq!(
        try_cmd(&mut r, range(1.0, f64::NAN)),
        Err(ErrorId::IllegalLowerTorqueLimit)
    );
    // 500 N up, 300 N down: 209 ‰ in 0x60E0, 125 ‰ in 0x60E1.
    r.cmd(range(500.0, -300.0));
    assert_eq!(
        try_cmd(&mut r, limiting(100.0, 0)),
        Err(ErrorId::TorqueLimitingRangeExclusive)
    );
    // 100 N additive: 41.8 ‰ in 0x60B2.
    r.cmd(Command::TorqueAdditive {
        enable: true,
        value: 100.0,
    });
    assert_eq!(
        try_cmd(
            &mut r,
            Command::TorqueAdditive {
                enable: true,
                value: f64::INFINITY
            }
        ),
        Err(ErrorId::IllegalAdditiveTorque)
    );
    r.step();
    let c = *r.exec.drive_rx(0).unwrap();
    assert_eq!(
        (
            c.positive_torque_limit,
            c.negative_torque_limit,
            c.max_torque
        ),
        (209, 125, 0)
    );
    assert_eq!(c.torque_offset, 42);
    let t = r
        .exec
        .axis(tandem_config::AxisIndex(0))
        .unwrap()
        .torque_status();
    assert!(t.range_active && t.additive_active && !t.limiting_active);
    r.cmd(Command::TorqueRange {
        enable: false,
        upper_limit: 0.0,
        lower_limit: 0.0,
    });
    r.cmd(Command::TorqueAdditive {
        enable: false,
        value: 0.0,
    });
    r.step();
    let c = *r.exec.drive_rx(0).unwrap();
    assert_eq!(
        (
            c.positive_torque_limit,
            c.negative_torque_limit,
            c.torque_offset
        ),
        (0, 0, 0)
    );
}

#[test]
fn an_inverted_drive_swaps_and_negates_the_range_and_inverts_the_additive_torque() {
    let cell = cell(|s| s.replace("inverse_drive = false", "inverse_drive = true"));
    let mut r = Run::new(&cell);
    enabled_at_zero(&mut r);
    r.cmd(Command::TorqueRange {
        enable: true,
        upper_limit: 500.0,
        lower_limit: -300.0,
    });
    r.cmd(Command::TorqueAdditive {
        enable: true,
        value: 100.0,
    });
    r.step();
    let c = *r.exec.drive_rx(0).unwrap();
    assert_eq!(
        (c.positive_torque_limit, c.negative_torque_limit),
        (125, 209)
    );
    assert_eq!(c.torque_offset, -42);
}
