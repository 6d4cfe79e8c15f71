//! Known-answer tests of the axis jobs against the references (S7-1500T Motion Control V4.0
//! function manual, 6.3 'Motion Control instructions', 3.2.10 'Position monitoring functions',
//! 3.2.9 'Homing'; S7-Technology V4.1 function manual on MC_Stop). One cycle = 1 ms unless said
//! otherwise.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_motion::catalog::alarm::{status_bit, AlarmId};
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::kinematics::modulo::Modulo;
use tandem_motion::objects::axis::{
    AxisConfig, AxisState, Command, Direction, HomingMark, Sense, SoftwareLimits, StartMode,
    StopMode, VelocityDirection,
};
use tandem_motion::objects::job::{Instruction, JobEventKind};
use tandem_motion::plant::drive::{DriveModel, ZeroMark};

use tandem_testkit::rig::{dynamics as dyn_, Rig};

fn homed(cfg: AxisConfig) -> Rig {
    let mut r = Rig::enabled(cfg);
    let id = r
        .cmd(Command::Home {
            mode: 0,
            position: 0.0,
        })
        .unwrap();
    assert!(r.has(id, JobEventKind::Done));
    r
}

#[test]
fn power_enables_at_once_and_disables_with_emergency_ramp() {
    let mut r = Rig::new(AxisConfig::example(0.001));
    assert_eq!(r.axis.status().state, AxisState::Disabled);
    let p = r
        .cmd(Command::Power {
            enable: true,
            start_mode: StartMode::PositionControlled,
            stop_mode: StopMode::Emergency,
        })
        .unwrap();
    assert!(r.has(p, JobEventKind::Status(true)));
    assert_eq!(r.axis.status().state, AxisState::Standstill);
    let v = r
        .cmd(Command::MoveVelocity {
            dynamics: dyn_(100.0, 1000.0, 1000.0, 0.0),
            direction: VelocityDirection::BySign,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    r.until(v, JobEventKind::InVelocity, 1000);
    // Disable with StopMode 0: emergency deceleration 10000 without jerk: 100/10000 = 10 ms.
    r.cmd(Command::Power {
        enable: false,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Emergency,
    })
    .unwrap();
    assert!(r.has(v, JobEventKind::CommandAborted));
    let t0 = r.t_last();
    let t1 = r.until(p, JobEventKind::Status(false), 100);
    assert!((t1 - t0 - 0.010).abs() <= 0.0011, "{}", t1 - t0);
    assert_eq!(r.axis.status().state, AxisState::Disabled);
    assert_eq!(
        r.cmd(Command::MoveRelative {
            distance: 1.0,
            dynamics: Dynamics::DEFAULT
        }),
        Err(ErrorId::NotEnabled)
    );
}

#[test]
fn move_relative_known_duration_and_done_after_positioning_monitoring() {
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    // v 100, a 1000, j 10000 over 100: 100/100 + 100/1000 + 1000/10000 = 1.2 s.
    let id = r
        .cmd(Command::MoveRelative {
            distance: 100.0,
            dynamics: dyn_(100.0, 1000.0, 1000.0, 10000.0),
        })
        .unwrap();
    let t_start = r.t_last();
    assert_eq!(r.axis.status().state, AxisState::DiscreteMotion);
    assert!(r.axis.status().has(status_bit::POSITIONING_COMMAND));
    let t_done = r.until(id, JobEventKind::Done, 3000);
    let s = r.axis.status();
    assert_eq!(s.position, 101.0 - 1.0);
    assert!((s.actual_position - 100.0).abs() <= 0.01);
    // Done when the setpoint arrived (1.2 s) and the actual value entered the window.
    assert!(
        t_done - t_start >= 1.2 - 1e-9 && t_done - t_start < 1.3,
        "{}",
        t_done - t_start
    );
    r.step(20);
    assert_eq!(r.axis.status().state, AxisState::Standstill);
    assert!(r.axis.status().has(status_bit::STANDSTILL));
    assert!(r.axis.status().has(status_bit::DONE));
}

#[test]
fn absolute_moves_need_homing_and_reduce_modulo() {
    let mut cfg = AxisConfig::example(0.001);
    cfg.modulo = Some(Modulo {
        start: 0.0,
        length: 360.0,
    });
    let mut r = Rig::enabled(cfg);
    assert_eq!(
        r.cmd(Command::MoveAbsolute {
            position: 10.0,
            dynamics: Dynamics::DEFAULT,
            direction: Direction::Shortest
        }),
        Err(ErrorId::NotHomed)
    );
    // Home position -20 is reduced to 340.
    let h = r
        .cmd(Command::Home {
            mode: 0,
            position: -20.0,
        })
        .unwrap();
    assert!(r.has(h, JobEventKind::Done));
    r.step(1);
    assert!((r.axis.status().position - 340.0).abs() < 1e-9);
    assert!(r.axis.status().has(status_bit::HOMING_DONE));
    // Target 400 -> 40: positive direction from 340 is +60.
    let id = r
        .cmd(Command::MoveAbsolute {
            position: 400.0,
            dynamics: Dynamics::DEFAULT,
            direction: Direction::Positive,
        })
        .unwrap();
    r.until(id, JobEventKind::Done, 5000);
    assert!((r.axis.status().position - 40.0).abs() < 1e-9);
    assert!((r.axis.status().position_unwrapped - 400.0).abs() < 1e-9);
    // Negative direction to 30: -10; positive direction to 30: +350; shortest to 350: -50.
    for (target, dir, travel) in [
        (30.0, Direction::Negative, -10.0),
        (30.0, Direction::Positive, 0.0),
        (20.0, Direction::Positive, 350.0),
        (330.0, Direction::Shortest, -50.0),
    ] {
        let before = r.axis.status().position_unwrapped;
        let id = r
            .cmd(Command::MoveAbsolute {
                position: target,
                dynamics: dyn_(500.0, 5000.0, 5000.0, 100000.0),
                direction: dir,
            })
            .unwrap();
        r.until(id, JobEventKind::Done, 5000);
        let s = r.axis.status();
        assert!((s.position - target).abs() < 1e-9, "{target} {dir:?}");
        assert!(
            (s.position_unwrapped - before - travel).abs() < 1e-9,
            "{target} {dir:?}: {}",
            s.position_unwrapped - before
        );
    }
}

#[test]
fn dynamic_sentinels_and_clamping() {
    let mut r = homed(AxisConfig::example(0.001));
    let mv = |d| Command::MoveAbsolute {
        position: 10.0,
        dynamics: d,
        direction: Direction::Shortest,
    };
    assert_eq!(
        r.cmd(mv(dyn_(0.0, -1.0, -1.0, -1.0))),
        Err(ErrorId::IllegalVelocity)
    );
    assert_eq!(
        r.cmd(mv(dyn_(-1.0, 0.0, -1.0, -1.0))),
        Err(ErrorId::IllegalAcceleration)
    );
    assert_eq!(
        r.cmd(mv(dyn_(-1.0, -1.0, 0.0, -1.0))),
        Err(ErrorId::IllegalDeceleration)
    );
    assert_eq!(
        r.cmd(mv(dyn_(f64::NAN, -1.0, -1.0, -1.0))),
        Err(ErrorId::IllegalVelocity)
    );
    // A rejected job changes nothing: still standstill, no alarm.
    assert_eq!(r.axis.status().state, AxisState::Standstill);
    // Jerk 0: trapezoidal, accepted. Above the limit: clamped with warning 501.
    let id = r.cmd(mv(dyn_(1000.0, -1.0, -1.0, 0.0))).unwrap();
    assert!(r.axis.has_alarm(AlarmId::VelocityLimited));
    assert_eq!(r.axis.status().state, AxisState::DiscreteMotion);
    r.until(id, JobEventKind::Done, 2000);
    // MoveVelocity accepts velocity 0: it stops and stays busy with InVelocity.
    let v = r
        .cmd(Command::MoveVelocity {
            dynamics: dyn_(0.0, -1.0, -1.0, -1.0),
            direction: VelocityDirection::BySign,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    r.until(v, JobEventKind::InVelocity, 10);
    assert_eq!(r.axis.status().motion_job.map(|m| m.0), Some(v));
}

#[test]
fn halt_aborts_and_finishes_at_standstill() {
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    let v = r
        .cmd(Command::MoveVelocity {
            dynamics: dyn_(100.0, 1000.0, 1000.0, 10000.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    r.until(v, JobEventKind::InVelocity, 1000);
    let h = r
        .cmd(Command::Halt {
            deceleration: 1000.0,
            jerk: 10000.0,
            abort_acceleration: false,
        })
        .unwrap();
    assert!(r.has(v, JobEventKind::CommandAborted));
    let t0 = r.t_last();
    // Braking 100 -> 0 with 1000 and jerk 10000: 0.1 + 0.1 = 0.2 s.
    let t1 = r.until(h, JobEventKind::Done, 1000);
    assert!(t1 - t0 >= 0.2 - 1e-9 && t1 - t0 < 0.25, "{}", t1 - t0);
    assert_eq!(r.axis.status().velocity, 0.0);
}

#[test]
fn stop_locks_the_axis_until_released() {
    let mut r = homed(AxisConfig::example(0.001));
    let m = r
        .cmd(Command::MoveRelative {
            distance: 100.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    r.step(100);
    let s = r
        .cmd(Command::Stop {
            execute: true,
            deceleration: -1.0,
            jerk: -1.0,
        })
        .unwrap();
    assert!(r.has(m, JobEventKind::CommandAborted));
    assert_eq!(r.axis.status().state, AxisState::Stopping);
    r.step(500);
    assert_eq!(r.axis.status().velocity, 0.0);
    assert!(
        !r.has(s, JobEventKind::Done),
        "not done while Execute is held"
    );
    assert_eq!(
        r.cmd(Command::MoveRelative {
            distance: 1.0,
            dynamics: Dynamics::DEFAULT
        }),
        Err(ErrorId::AxisLocked)
    );
    assert_eq!(
        r.cmd(Command::Halt {
            deceleration: -1.0,
            jerk: -1.0,
            abort_acceleration: false
        }),
        Err(ErrorId::AxisLocked)
    );
    // The lock survives a disable / re-enable while Execute is held.
    let power = |enable| Command::Power {
        enable,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Immediate,
    };
    r.cmd(power(false)).unwrap();
    assert!(r.has(s, JobEventKind::CommandAborted));
    r.cmd(power(true)).unwrap();
    r.step(5);
    assert_eq!(
        r.cmd(Command::MoveRelative {
            distance: 1.0,
            dynamics: Dynamics::DEFAULT
        }),
        Err(ErrorId::AxisLocked)
    );
    assert_eq!(r.axis.status().state, AxisState::Stopping);
    let s = r
        .cmd(Command::Stop {
            execute: true,
            deceleration: -1.0,
            jerk: -1.0,
        })
        .unwrap();
    r.cmd(Command::Stop {
        execute: false,
        deceleration: -1.0,
        jerk: -1.0,
    })
    .unwrap();
    r.until(s, JobEventKind::Done, 10);
    assert_eq!(r.axis.status().state, AxisState::Standstill);
    assert!(r
        .cmd(Command::MoveRelative {
            distance: 1.0,
            dynamics: Dynamics::DEFAULT
        })
        .is_ok());
}

#[test]
fn override_scales_velocity_jobs_and_is_checked() {
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    let v = r
        .cmd(Command::MoveVelocity {
            dynamics: dyn_(100.0, 1000.0, 1000.0, 10000.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    r.until(v, JobEventKind::InVelocity, 1000);
    assert_eq!(
        r.cmd(Command::SetOverride { velocity: 250.0 }),
        Err(ErrorId::IllegalOverride)
    );
    assert_eq!(
        r.cmd(Command::SetOverride { velocity: -1.0 }),
        Err(ErrorId::IllegalOverride)
    );
    r.cmd(Command::SetOverride { velocity: 50.0 }).unwrap();
    assert!(r.has(v, JobEventKind::LeftVelocity));
    let n_in = r
        .events
        .iter()
        .filter(|e| e.job == v && e.kind == JobEventKind::InVelocity)
        .count();
    r.step(300);
    let n_in2 = r
        .events
        .iter()
        .filter(|e| e.job == v && e.kind == JobEventKind::InVelocity)
        .count();
    assert_eq!(n_in2, n_in + 1);
    assert!((r.axis.status().velocity - 50.0).abs() < 1e-9);
    // 200 % is clamped to the velocity limit (500) of the axis: 100 * 2 = 200.
    r.cmd(Command::SetOverride { velocity: 200.0 }).unwrap();
    r.step(300);
    assert!((r.axis.status().velocity - 200.0).abs() < 1e-9);
}

#[test]
fn override_zero_halts_a_positioning_job_which_then_continues() {
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    let id = r
        .cmd(Command::MoveRelative {
            distance: 100.0,
            dynamics: dyn_(100.0, 1000.0, 1000.0, 10000.0),
        })
        .unwrap();
    r.step(300);
    r.cmd(Command::SetOverride { velocity: 0.0 }).unwrap();
    r.step(500);
    assert_eq!(r.axis.status().velocity, 0.0);
    assert!(!r.has(id, JobEventKind::Done));
    r.cmd(Command::SetOverride { velocity: 100.0 }).unwrap();
    r.until(id, JobEventKind::Done, 3000);
    assert_eq!(r.axis.status().position, 100.0);
}

#[test]
fn jog_runs_while_held_and_both_inputs_are_an_error() {
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    let jog = |f, b| Command::MoveJog {
        forward: f,
        backward: b,
        dynamics: dyn_(-50.0, 1000.0, 1000.0, 0.0),
        position_controlled: true,
    };
    let id = r.cmd(jog(false, true)).unwrap();
    r.until(id, JobEventKind::InVelocity, 1000);
    // Negative Velocity: its absolute value (no: negative means default 100 for jog? the
    // reference: "Jog uses the absolute value of a negative Velocity").
    assert!((r.axis.status().velocity + 50.0).abs() < 1e-9);
    assert_eq!(r.cmd(jog(false, true)), Ok(id));
    r.cmd(jog(false, false)).unwrap();
    r.until(id, JobEventKind::Done, 1000);
    assert_eq!(r.axis.status().velocity, 0.0);
    let id2 = r.cmd(jog(true, false)).unwrap();
    r.step(10);
    assert_eq!(r.cmd(jog(true, true)), Err(ErrorId::IllegalDirection));
    assert!(r.has(id2, JobEventKind::Error(ErrorId::IllegalDirection)));
    r.step(200);
    assert_eq!(r.axis.status().velocity, 0.0);
}

#[test]
fn superimposed_adds_to_a_positioning_move() {
    // S7-1500T Motion Control V4.0 function manual, 10.9.1 'MC_MoveSuperimposed: Position axes
    // overlapping V4': MoveRelative 50 plus superimposed 50 gives 100 in total.
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    let m = r
        .cmd(Command::MoveRelative {
            distance: 50.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    r.step(50);
    let s = r
        .cmd(Command::MoveSuperimposed {
            distance: 50.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    assert!(
        !r.has(m, JobEventKind::CommandAborted),
        "table 1: superimposed does not abort motion"
    );
    r.until(s, JobEventKind::Done, 5000);
    r.until(m, JobEventKind::Done, 5000);
    assert!((r.axis.status().position - 100.0).abs() < 1e-9);
    // Relative +50 with superimposed -50 ends where it started.
    let start = r.axis.status().position;
    let m = r
        .cmd(Command::MoveRelative {
            distance: 50.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    let s = r
        .cmd(Command::MoveSuperimposed {
            distance: -50.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    r.until(s, JobEventKind::Done, 5000);
    r.until(m, JobEventKind::Done, 5000);
    assert!((r.axis.status().position - start).abs() < 1e-9);
    // A new motion job aborts a running superimposed one (table 1).
    let s = r
        .cmd(Command::MoveSuperimposed {
            distance: 100.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    r.step(100);
    r.cmd(Command::MoveRelative {
        distance: 10.0,
        dynamics: Dynamics::DEFAULT,
    })
    .unwrap();
    assert!(r.has(s, JobEventKind::CommandAborted));
}

#[test]
fn software_limit_is_reached_exactly_and_crossing_removes_enable() {
    let mut cfg = AxisConfig::example(0.001);
    cfg.sw_limits = Some(SoftwareLimits {
        min: -100.0,
        max: 200.0,
    });
    let mut r = homed(cfg);
    let v = r
        .cmd(Command::MoveVelocity {
            dynamics: dyn_(300.0, 2000.0, 2000.0, 20000.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    let mut max_p = f64::MIN;
    for _ in 0..3000 {
        r.step(1);
        max_p = max_p.max(r.axis.status().position);
    }
    assert!(r.has(v, JobEventKind::Error(ErrorId::TechnologyAlarm)));
    assert!(r.axis.has_alarm(AlarmId::SwLimitReached));
    assert!((max_p - 200.0).abs() < 1e-9, "stopped at {max_p}");
    assert!(max_p <= 200.0 + 1e-9);
    assert!(
        r.axis.status().has(status_bit::ENABLE),
        "533 keeps the axis enabled"
    );
    assert!(r.axis.status().has(status_bit::SW_LIMIT_MAX_ACTIVE));
    assert_eq!(r.axis.status().state, AxisState::ErrorStop);
    // Acknowledge, move away: fine.
    r.cmd(Command::Reset { restart: false }).unwrap();
    let id = r
        .cmd(Command::MoveRelative {
            distance: -10.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    r.until(id, JobEventKind::Done, 3000);
    assert!(!r.axis.status().has(status_bit::SW_LIMIT_MAX_ACTIVE));
    // A setpoint jump across the limit (MotionIn has no limits): 534, enable removed.
    r.cmd(Command::MotionInPosition {
        enable: true,
        position: 250.0,
        velocity: 0.0,
        acceleration: 0.0,
    })
    .unwrap();
    r.step(2);
    assert!(r.axis.has_alarm(AlarmId::SwLimitCrossed));
    assert!(!r.axis.status().has(status_bit::ENABLE));
}

#[test]
fn hardware_limit_removes_enable_and_reset_re_enables() {
    let mut cfg = AxisConfig::example(0.001);
    cfg.hw_limits_active = true;
    cfg.plant.hw_limit_max = Some(50.0);
    cfg.following_error.enable = false;
    let mut r = Rig::enabled(cfg);
    let v = r
        .cmd(Command::MoveVelocity {
            dynamics: dyn_(100.0, -1.0, -1.0, -1.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    r.until(v, JobEventKind::Error(ErrorId::TechnologyAlarm), 2000);
    assert!(r.axis.has_alarm(AlarmId::HwLimit));
    assert!(!r.axis.status().has(status_bit::ENABLE));
    assert!(r.axis.status().has(status_bit::HW_LIMIT_MAX_ACTIVE));
    r.step(200); // the drive brakes on its own ramp
    r.cmd(Command::Reset { restart: false }).unwrap();
    assert!(
        r.axis.status().has(status_bit::ENABLE),
        "automatic re-enable while Enable is held"
    );
    // Moving further into the switch re-triggers; moving back clears.
    let id = r
        .cmd(Command::MoveRelative {
            distance: -20.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    r.step(100);
    let alarms: Vec<_> = r.axis.alarms().collect();
    assert!(alarms.is_empty(), "{alarms:?} {:?}", r.axis.status());
    r.until(id, JobEventKind::Done, 3000);
    assert!(!r.axis.status().has(status_bit::HW_LIMIT_MAX_ACTIVE));
    assert!(!r.axis.has_alarm(AlarmId::HwLimit));
}

#[test]
fn following_error_alarm_when_the_drive_cannot_follow() {
    let mut cfg = AxisConfig::example(0.001);
    cfg.drive = DriveModel::PositionLoop {
        kv: 5.0,
        kpc: 0.0,
        t_vtc: 0.01,
    };
    let mut r = Rig::enabled(cfg);
    let v = r
        .cmd(Command::MoveVelocity {
            dynamics: dyn_(200.0, 5000.0, 5000.0, 0.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    r.until(v, JobEventKind::Error(ErrorId::TechnologyAlarm), 2000);
    assert!(r.axis.has_alarm(AlarmId::FollowingErrorWarning));
    assert!(r.axis.has_alarm(AlarmId::FollowingError));
    assert_eq!(r.axis.status().state, AxisState::ErrorStop);
    assert_eq!(
        r.cmd(Command::MoveRelative {
            distance: 1.0,
            dynamics: Dynamics::DEFAULT
        }),
        Err(ErrorId::NotEnabled)
    );
}

#[test]
fn positioning_monitoring_fails_when_the_window_is_not_reached() {
    let mut cfg = AxisConfig::example(0.001);
    cfg.drive = DriveModel::Delay { delay: 0.5 };
    cfg.positioning.tolerance_time = 0.1;
    cfg.following_error.enable = false;
    let mut r = Rig::enabled(cfg);
    let id = r
        .cmd(Command::MoveRelative {
            distance: 10.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    r.until(id, JobEventKind::Error(ErrorId::TechnologyAlarm), 3000);
    assert!(r.axis.has_alarm(AlarmId::PositioningMonitoring));
    assert!(
        !r.axis.status().has(status_bit::ENABLE),
        "541 removes the enable"
    );
}

#[test]
fn active_homing_with_cam_and_zero_mark() {
    let mut cfg = AxisConfig::example(0.001);
    cfg.initial_position = 3.0;
    cfg.plant.reference_cam = Some((20.0, 30.0));
    cfg.plant.zero_mark = Some(ZeroMark {
        period: 10.0,
        offset: 5.0,
    });
    cfg.homing.active_mark = HomingMark::CamAndZeroMark;
    cfg.homing.approach_direction = Sense::Positive;
    cfg.homing.homing_direction = Sense::Positive;
    cfg.homing.approach_velocity = 20.0;
    cfg.homing.referencing_velocity = 5.0;
    cfg.homing.home_position_offset = 2.0;
    let mut r = Rig::enabled(cfg);
    let id = r
        .cmd(Command::Home {
            mode: 3,
            position: 100.0,
        })
        .unwrap();
    assert_eq!(r.axis.status().state, AxisState::Homing);
    r.until(id, JobEventKind::Done, 20_000);
    // The first zero mark after leaving the cam (at 30) is at 35; it got the value
    // Position - HomePositionOffset = 98, then the axis travelled to 100: physically 37.
    let s = r.axis.status();
    assert!((s.position - 100.0).abs() < 1e-9, "{}", s.position);
    assert!((s.actual_position - 100.0).abs() < 0.01);
    assert!(s.has(status_bit::HOMING_DONE));
    // Physical check: axis 100 <-> physical 37: a relative move of -2 puts the mark (98) back.
    let id = r
        .cmd(Command::MoveAbsolute {
            position: 98.0,
            dynamics: Dynamics::DEFAULT,
            direction: Direction::Shortest,
        })
        .unwrap();
    r.until(id, JobEventKind::Done, 3000);
    assert!((r.axis.status().position - 98.0).abs() < 1e-9);
}

#[test]
fn passive_homing_on_the_fly_sets_the_position_at_the_mark() {
    let mut cfg = AxisConfig::example(0.001);
    cfg.plant.reference_cam = Some((20.0, 30.0));
    cfg.plant.zero_mark = Some(ZeroMark {
        period: 10.0,
        offset: 5.0,
    });
    cfg.homing.passive_mark = HomingMark::CamAndZeroMark;
    let mut r = Rig::enabled(cfg);
    let v = r
        .cmd(Command::MoveVelocity {
            dynamics: dyn_(20.0, -1.0, -1.0, -1.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    let h = r
        .cmd(Command::Home {
            mode: 8,
            position: 1000.0,
        })
        .unwrap();
    r.until(h, JobEventKind::Done, 5000);
    assert!(
        !r.has(v, JobEventKind::CommandAborted),
        "passive homing runs beside the motion"
    );
    assert!(r.axis.status().has(status_bit::HOMING_DONE));
    // The mark at physical 35 is now 1000 (no offset in passive homing).
    let s = r.axis.status();
    let phys_now = s.actual_position - 1000.0 + 35.0;
    assert!(phys_now > 35.0 && phys_now < 36.0, "{phys_now}");
}

#[test]
fn homing_mode_checks() {
    let mut r = Rig::new(AxisConfig::example(0.001));
    assert_eq!(
        r.cmd(Command::Home {
            mode: 3,
            position: 0.0
        }),
        Err(ErrorId::NotEnabled)
    );
    assert_eq!(
        r.cmd(Command::Home {
            mode: 6,
            position: 0.0
        }),
        Err(ErrorId::IllegalHomingModeIncremental)
    );
    assert_eq!(
        r.cmd(Command::Home {
            mode: 4,
            position: 0.0
        }),
        Err(ErrorId::IllegalMode)
    );
    // Direct homing works disabled too.
    assert!(r
        .cmd(Command::Home {
            mode: 1,
            position: 5.0
        })
        .is_ok());
    assert!((r.axis.status().actual_position - 5.0).abs() < 1e-12);
}

#[test]
fn restart_needs_the_axis_disabled_and_clears_homing() {
    let mut r = homed(AxisConfig::example(0.001));
    assert_eq!(
        r.cmd(Command::Reset { restart: true }),
        Err(ErrorId::RestartWhileEnabled)
    );
    r.cmd(Command::Power {
        enable: false,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Immediate,
    })
    .unwrap();
    assert!(r.cmd(Command::Reset { restart: true }).is_ok());
    assert!(!r.axis.status().has(status_bit::HOMING_DONE));
}

#[test]
fn aborting_job_continues_smoothly() {
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    r.cmd(Command::MoveRelative {
        distance: 100.0,
        dynamics: dyn_(200.0, 2000.0, 2000.0, 20000.0),
    })
    .unwrap();
    r.step(57);
    let before = *r.axis.status();
    r.cmd(Command::MoveRelative {
        distance: -30.0,
        dynamics: dyn_(50.0, 1000.0, 500.0, 5000.0),
    })
    .unwrap();
    r.step(1);
    let after = *r.axis.status();
    // One cycle later the setpoint moved by about v*dt, velocity by at most a*dt.
    assert!((after.position - before.position - before.velocity * 0.001).abs() < 0.01);
    assert!((after.velocity - before.velocity).abs() <= 20000.0 * 0.001 + 1e-9);
}

#[test]
fn motion_in_velocity_sets_setpoints_directly() {
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    let id = r
        .cmd(Command::MotionInVelocity {
            enable: true,
            velocity: 30.0,
            acceleration: 0.0,
            position_controlled: true,
        })
        .unwrap();
    r.step(1);
    assert_eq!(r.axis.status().velocity, 30.0);
    assert!(r.axis.status().has(status_bit::MOTION_IN_COMMAND));
    r.step(99);
    r.cmd(Command::MotionInVelocity {
        enable: false,
        velocity: 30.0,
        acceleration: 0.0,
        position_controlled: true,
    })
    .unwrap();
    assert!(r.has(id, JobEventKind::Done));
    r.step(1);
    assert_eq!(r.axis.status().velocity, 0.0);
    assert_eq!(r.axis.status().motion_job, None);
    assert_eq!(
        r.events
            .iter()
            .filter(|e| e.instruction == Instruction::MotionInVelocity)
            .count(),
        2
    );
}

#[test]
fn homing_needs_the_sensors_of_its_mark() {
    // The example config has no reference cam and no zero marks.
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    assert_eq!(
        r.cmd(Command::Home {
            mode: 3,
            position: 0.0
        }),
        Err(ErrorId::IllegalMode)
    );
    assert_eq!(
        r.cmd(Command::Home {
            mode: 8,
            position: 0.0
        }),
        Err(ErrorId::IllegalMode)
    );
    assert_eq!(r.axis.status().state, AxisState::Standstill);
    // A virtual axis homes at once without motion.
    let mut cfg = AxisConfig::example(0.001);
    cfg.virtual_axis = true;
    let mut r = Rig::enabled(cfg);
    let id = r
        .cmd(Command::Home {
            mode: 3,
            position: 12.5,
        })
        .unwrap();
    assert!(r.has(id, JobEventKind::Done));
    r.step(1);
    assert!((r.axis.status().position - 12.5).abs() < 1e-12);
}

fn homing_cfg() -> AxisConfig {
    let mut cfg = AxisConfig::example(0.001);
    cfg.plant.reference_cam = Some((20.0, 30.0));
    cfg.plant.zero_mark = Some(ZeroMark {
        period: 10.0,
        offset: 5.0,
    });
    cfg.homing.approach_velocity = 20.0;
    cfg.homing.referencing_velocity = 5.0;
    cfg
}

#[test]
fn active_homing_zero_mark_only_mode_5_ends_at_home_position() {
    // Mode 5: the mark gets HomePosition - HomePositionOffset, the axis ends at HomePosition;
    // zero mark only: the first mark in the homing direction (negative from 3: the mark at -5).
    let mut cfg = homing_cfg();
    cfg.initial_position = 3.0;
    cfg.homing.active_mark = HomingMark::ZeroMark;
    cfg.homing.homing_direction = Sense::Negative;
    cfg.homing.home_position = 50.0;
    cfg.homing.home_position_offset = -1.5;
    let mut r = Rig::enabled(cfg);
    let id = r
        .cmd(Command::Home {
            mode: 5,
            position: 999.0,
        })
        .unwrap();
    r.until(id, JobEventKind::Done, 20_000);
    let s = r.axis.status();
    assert!((s.position - 50.0).abs() < 1e-9);
    // The mark at physical -5 is 51.5, so the axis at 50 is physically at -6.5.
    let phys = s.actual_position - 51.5 + (-5.0);
    assert!((phys + 6.5).abs() < 0.011, "{phys}");
}

#[test]
fn active_homing_on_a_digital_input_edge() {
    // Digital input (the cam signal) mode: the edge on the homing-direction side is the mark.
    // Negative side: the lower edge (20) gets Position - offset = 10 - 0 = 10.
    let mut cfg = homing_cfg();
    cfg.initial_position = 40.0;
    cfg.homing.active_mark = HomingMark::DigitalInput;
    cfg.homing.approach_direction = Sense::Negative;
    cfg.homing.homing_direction = Sense::Negative;
    let mut r = Rig::enabled(cfg);
    let id = r
        .cmd(Command::Home {
            mode: 3,
            position: 10.0,
        })
        .unwrap();
    r.until(id, JobEventKind::Done, 20_000);
    let s = r.axis.status();
    assert!((s.position - 10.0).abs() < 1e-9);
    // Physically the axis stands at the edge (20): actual 10 <-> physical 20.
    let id = r
        .cmd(Command::MoveRelative {
            distance: 5.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    r.until(id, JobEventKind::Done, 3000);
    assert!((r.axis.status().actual_position - 15.0).abs() < 0.011);
}

#[test]
fn active_homing_reverses_at_a_hardware_limit_switch() {
    // The cam lies in the positive direction but the search starts negative: the axis reaches
    // the negative limit switch, brakes, reverses at approach velocity and homes normally,
    // without alarm 531 (AutoReversal).
    let mut cfg = homing_cfg();
    cfg.initial_position = 0.0;
    cfg.hw_limits_active = true;
    cfg.plant.hw_limit_min = Some(-30.0);
    cfg.homing.approach_direction = Sense::Negative;
    cfg.homing.homing_direction = Sense::Positive;
    cfg.following_error.enable = false;
    let mut r = Rig::enabled(cfg);
    let id = r
        .cmd(Command::Home {
            mode: 3,
            position: 0.0,
        })
        .unwrap();
    let mut min_pos = f64::MAX;
    for _ in 0..30_000 {
        r.step(1);
        min_pos = min_pos.min(r.axis.status().actual_position);
        if r.has(id, JobEventKind::Done) {
            break;
        }
    }
    assert!(r.has(id, JobEventKind::Done), "{:?}", r.events);
    assert!(min_pos < -30.0, "it reached the switch");
    assert!(!r.axis.has_alarm(AlarmId::HwLimit));
    // Without AutoReversal the same search ends with 531.
    let mut cfg = homing_cfg();
    cfg.hw_limits_active = true;
    cfg.plant.hw_limit_min = Some(-30.0);
    cfg.homing.approach_direction = Sense::Negative;
    cfg.homing.auto_reversal = false;
    let mut r = Rig::enabled(cfg);
    let id = r
        .cmd(Command::Home {
            mode: 3,
            position: 0.0,
        })
        .unwrap();
    r.until(id, JobEventKind::Error(ErrorId::TechnologyAlarm), 30_000);
    assert!(r.axis.has_alarm(AlarmId::HwLimit));
}

#[test]
fn active_homing_finds_nothing_between_two_switches() {
    let mut cfg = homing_cfg();
    cfg.plant.reference_cam = Some((200.0, 210.0));
    cfg.hw_limits_active = true;
    cfg.plant.hw_limit_min = Some(-30.0);
    cfg.plant.hw_limit_max = Some(60.0);
    cfg.following_error.enable = false;
    let mut r = Rig::enabled(cfg);
    let id = r
        .cmd(Command::Home {
            mode: 3,
            position: 0.0,
        })
        .unwrap();
    r.until(id, JobEventKind::Error(ErrorId::TechnologyAlarm), 60_000);
    assert!(r.axis.has_alarm(AlarmId::HomingNotFound));
    assert!(!r.axis.status().has(status_bit::HOMING_DONE));
}

#[test]
fn absolute_encoder_adjustment_and_passive_mode_10() {
    let mut cfg = homing_cfg();
    cfg.encoder = tandem_motion::objects::axis::EncoderType::Absolute;
    let mut r = Rig::enabled(cfg);
    assert!(
        r.axis.status().has(status_bit::HOMING_DONE),
        "absolute: homed from the start"
    );
    assert_eq!(
        r.cmd(Command::Home {
            mode: 3,
            position: 0.0
        }),
        Err(ErrorId::IllegalHomingModeAbsolute)
    );
    // Mode 7: actual := Position; mode 6: shift by Position.
    r.cmd(Command::Home {
        mode: 7,
        position: 100.0,
    })
    .unwrap();
    r.step(1);
    assert!((r.axis.status().actual_position - 100.0).abs() < 1e-9);
    r.cmd(Command::Home {
        mode: 6,
        position: -30.0,
    })
    .unwrap();
    r.step(1);
    assert!((r.axis.status().actual_position - 70.0).abs() < 1e-9);
    // The adjustment survives a restart (the offset is retentive).
    r.cmd(Command::Power {
        enable: false,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Immediate,
    })
    .unwrap();
    r.cmd(Command::Reset { restart: true }).unwrap();
    r.step(1);
    assert!((r.axis.status().actual_position - 70.0).abs() < 1e-9);
    assert!(r.axis.status().has(status_bit::HOMING_DONE));

    // Passive mode 10: the mark gets Homing.HomePosition (Position ignored), no offset.
    let mut cfg = homing_cfg();
    cfg.homing.home_position = 500.0;
    cfg.homing.home_position_offset = 7.0;
    cfg.homing.passive_mark = HomingMark::ZeroMark;
    cfg.homing.passive_direction = tandem_motion::objects::axis::PassiveDirection::Negative;
    let mut r = Rig::enabled(cfg);
    let h = r
        .cmd(Command::Home {
            mode: 10,
            position: 1.0,
        })
        .unwrap();
    // Moving positive: not armed (direction negative).
    let m = r
        .cmd(Command::MoveRelative {
            distance: 12.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    r.until(m, JobEventKind::Done, 3000);
    assert!(!r.has(h, JobEventKind::Done));
    assert!(
        !r.axis.status().has(status_bit::HOMING_DONE),
        "mode 10 clears HomingDone at start"
    );
    // Back from 12: the mark at 5 is crossed going negative: it becomes 500.
    let m = r
        .cmd(Command::MoveRelative {
            distance: -12.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    r.until(h, JobEventKind::Done, 3000);
    r.until(m, JobEventKind::Done, 3000);
    // The move continued in the new coordinates: it ends 5 below the mark.
    assert!(
        (r.axis.status().actual_position - 495.0).abs() < 0.011,
        "{}",
        r.axis.status().actual_position
    );
}
