//! Known answers taken from the references' own numbers (S7-1500T Motion Control V4.0 function
//! manual, 3.2.8.2 'Velocity profile', 3.2.10.2 'Positioning monitoring', 3.2.10.3 'Following error
//! monitoring', 10.16 'Override response of Motion Control jobs V4'), and the remaining job
//! semantics (MoveVelocity Direction/Current, override table cases).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_motion::catalog::alarm::AlarmId;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::kinematics::profile::{plan_velocity, Limits, State};
use tandem_motion::objects::axis::{
    AxisConfig, AxisState, Command, HomingMark, StartMode, StopMode, VelocityDirection,
};
use tandem_motion::objects::job::JobEventKind;
use tandem_motion::plant::drive::{DriveModel, ZeroMark};

use tandem_testkit::rig::{dynamics, Rig};

#[test]
fn ramp_and_smoothing_times_of_the_velocity_profile_example() {
    // Accel 1000, Decel 500, Jerk 10000: smoothing 0.1 s on acceleration, 0.05 s on
    // deceleration; ramp-up 0 -> 100 = v/a + a/j = 0.2 s (the smoothing phases meet);
    // ramp-down 100 -> 0 = v/d + d/j = 0.25 s.
    let lim = Limits {
        vel: 200.0,
        acc: 1000.0,
        dec: 500.0,
        jerk: 10000.0,
    };
    let up = plan_velocity(State::rest(0.0), 100.0, &lim).unwrap();
    assert!((up.duration() - 0.2).abs() < 1e-12);
    let segs = up.segments();
    assert!(
        (segs[1].t0 - 0.1).abs() < 1e-12,
        "accel smoothing time a/j = 0.1"
    );
    let down = plan_velocity(
        State {
            p: 0.0,
            v: 100.0,
            a: 0.0,
        },
        0.0,
        &lim,
    )
    .unwrap();
    assert!((down.duration() - 0.25).abs() < 1e-12);
    assert!(
        (down.segments()[1].t0 - 0.05).abs() < 1e-12,
        "decel smoothing time d/j = 0.05"
    );
    // Trapezoidal (jerk 0): ramp-up time = v/a, ramp-down time = v/d.
    let trap = Limits { jerk: 0.0, ..lim };
    assert!(
        (plan_velocity(State::rest(0.0), 100.0, &trap)
            .unwrap()
            .duration()
            - 0.1)
            .abs()
            < 1e-12
    );
    assert!(
        (plan_velocity(
            State {
                p: 0.0,
                v: 100.0,
                a: 0.0
            },
            0.0,
            &trap
        )
        .unwrap()
        .duration()
            - 0.2)
            .abs()
            < 1e-12
    );
    // E-stop ramp-down time = velocity / EmergencyDeceleration: 100 / 10000 = 10 ms on an axis.
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    let v = r
        .cmd(Command::MoveVelocity {
            dynamics: dynamics(100.0, -1.0, -1.0, 0.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    r.until(v, JobEventKind::InVelocity, 1000);
    let p = r
        .cmd(Command::Power {
            enable: false,
            start_mode: StartMode::PositionControlled,
            stop_mode: StopMode::Emergency,
        })
        .unwrap();
    let t0 = r.t_last();
    let t1 = r.until(p, JobEventKind::Status(false), 100);
    assert!((t1 - t0 - 0.010).abs() < 1e-9, "{}", t1 - t0);
}

#[test]
fn positioning_monitoring_example_of_the_manual() {
    // Window 0.1, ToleranceTime 1.0, MinDwellTime 0.05: Done at the earliest 0.05 s after the
    // actual value entered the window. With the delay model the actual lags by T_t = 0.2 s.
    let mut cfg = AxisConfig::example(0.001);
    cfg.drive = DriveModel::Delay { delay: 0.2 };
    cfg.following_error.enable = false;
    cfg.positioning.window = 0.1;
    cfg.positioning.tolerance_time = 1.0;
    cfg.positioning.min_dwell_time = 0.05;
    let mut r = Rig::enabled(cfg);
    // Trapezoid 100 at v 100, a = d = 1000: 1.1 s.
    let id = r
        .cmd(Command::MoveRelative {
            distance: 100.0,
            dynamics: dynamics(100.0, 1000.0, 1000.0, 0.0),
        })
        .unwrap();
    let t0 = r.t_last();
    let mut entered = None;
    for _ in 0..3000 {
        r.step(1);
        let s = *r.axis.status();
        if entered.is_none() && (s.actual_position - 100.0).abs() <= 0.1 {
            entered = Some(r.t_last());
        }
        if r.has(id, JobEventKind::Done) {
            break;
        }
    }
    let t_done = r.until(id, JobEventKind::Done, 1);
    let entered = entered.unwrap();
    // The actual enters the window while the delayed setpoint is within 0.1 of the target:
    // setpoint error 0.1 = d t^2 / 2 before the end -> t = sqrt(0.2/1000) = 0.01414 s.
    let expect_enter = t0 + 1.1 + 0.2 - (0.2f64 / 1000.0).sqrt();
    assert!(
        (entered - expect_enter).abs() <= 0.0011,
        "entered {entered} expected {expect_enter}"
    );
    assert!(
        (t_done - (entered + 0.05)).abs() <= 0.0011,
        "done {t_done} entered {entered}"
    );
}

#[test]
fn following_error_limit_and_warning_of_the_manual() {
    // Permitted error grows linearly from MinValue (below MinVelocity) to MaxValue at the
    // maximum velocity; the warning comes at WarningLevel % of the current permitted value.
    // Constant velocity 255 on an axis with MaxVelocity 500, MinVelocity 10: permitted
    // 1 + 9 * (255 - 10) / 490 = 5.5. Without precontrol the lag is v/Kv = 255/50 = 5.1:
    // above 90 % of 5.5 (4.95): warning 522, but no 521.
    let mut cfg = AxisConfig::example(0.001);
    cfg.drive = DriveModel::PositionLoop {
        kv: 50.0,
        kpc: 0.0,
        t_vtc: 0.0,
    };
    let mut r = Rig::enabled(cfg);
    r.cmd(Command::MoveVelocity {
        dynamics: dynamics(255.0, 500.0, 500.0, 0.0),
        direction: VelocityDirection::Positive,
        current: false,
        position_controlled: true,
    })
    .unwrap();
    r.step(2000);
    let fe = r.axis.status().following_error;
    assert!((fe - 5.1).abs() < 0.01, "{fe}");
    assert!(r.axis.has_alarm(AlarmId::FollowingErrorWarning));
    assert!(!r.axis.has_alarm(AlarmId::FollowingError));
    // With Kv = 40 at 380: lag 380/40 = 9.5 above the permitted 1 + 9 * 370/490 = 7.80: 521.
    let mut cfg = AxisConfig::example(0.001);
    cfg.drive = DriveModel::PositionLoop {
        kv: 40.0,
        kpc: 0.0,
        t_vtc: 0.0,
    };
    let mut r = Rig::enabled(cfg);
    r.cmd(Command::MoveVelocity {
        dynamics: dynamics(380.0, 500.0, 500.0, 0.0),
        direction: VelocityDirection::Positive,
        current: false,
        position_controlled: true,
    })
    .unwrap();
    r.step(2000);
    assert!(r.axis.has_alarm(AlarmId::FollowingError));
    assert_eq!(r.axis.status().state, AxisState::ErrorStop);
}

#[test]
fn move_velocity_direction_and_current() {
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    let mv = |v: f64, dir, current| Command::MoveVelocity {
        dynamics: dynamics(v, 1000.0, 1000.0, 0.0),
        direction: dir,
        current,
        position_controlled: true,
    };
    // Direction 0: the sign of Velocity.
    let id = r.cmd(mv(-40.0, VelocityDirection::BySign, false)).unwrap();
    r.until(id, JobEventKind::InVelocity, 1000);
    assert_eq!(r.axis.status().velocity, -40.0);
    // Direction 1 with a negative value: positive.
    let id = r
        .cmd(mv(-40.0, VelocityDirection::Positive, false))
        .unwrap();
    r.until(id, JobEventKind::InVelocity, 1000);
    assert_eq!(r.axis.status().velocity, 40.0);
    // Direction 2: negative.
    let id = r.cmd(mv(30.0, VelocityDirection::Negative, false)).unwrap();
    r.step(20);
    // Current: keep the velocity at job start (whatever it is, mid-ramp).
    let v_now = r.axis.status().velocity;
    let id2 = r.cmd(mv(999.0, VelocityDirection::BySign, true)).unwrap();
    assert!(r.has(id, JobEventKind::CommandAborted));
    r.until(id2, JobEventKind::InVelocity, 100);
    assert!((r.axis.status().velocity - v_now).abs() < 1e-9);
}

#[test]
fn override_table_cases_on_an_axis() {
    // Table 1: passive homing survives motion jobs; active homing aborts it; Home 9 aborts it.
    let mut cfg = AxisConfig::example(0.001);
    cfg.plant.reference_cam = Some((1000.0, 1010.0));
    cfg.plant.zero_mark = Some(ZeroMark {
        period: 10.0,
        offset: 5.0,
    });
    cfg.homing.passive_mark = HomingMark::CamAndZeroMark;
    let mut r = Rig::enabled(cfg);
    let passive = r
        .cmd(Command::Home {
            mode: 2,
            position: 0.0,
        })
        .unwrap();
    let m = r
        .cmd(Command::MoveRelative {
            distance: 10.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    let h = r
        .cmd(Command::Halt {
            deceleration: -1.0,
            jerk: -1.0,
            abort_acceleration: false,
        })
        .unwrap();
    assert!(
        r.has(m, JobEventKind::CommandAborted),
        "Halt aborts a motion job"
    );
    assert!(
        !r.has(passive, JobEventKind::CommandAborted),
        "motion does not abort passive homing"
    );
    r.until(h, JobEventKind::Done, 1000);
    let abort = r
        .cmd(Command::Home {
            mode: 9,
            position: 0.0,
        })
        .unwrap();
    assert!(r.has(passive, JobEventKind::CommandAborted));
    assert!(r.has(abort, JobEventKind::Done));
    // Table 1: a MoveSuperimposed is aborted by a new MoveSuperimposed, not by Home 0.
    let s1 = r
        .cmd(Command::MoveSuperimposed {
            distance: 50.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    r.step(10);
    r.cmd(Command::Home {
        mode: 0,
        position: 0.0,
    })
    .unwrap();
    assert!(!r.has(s1, JobEventKind::CommandAborted));
    let s2 = r
        .cmd(Command::MoveSuperimposed {
            distance: 10.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    assert!(r.has(s1, JobEventKind::CommandAborted));
    r.until(s2, JobEventKind::Done, 2000);
    // MotionIn aborts positioning; a new positioning job aborts MotionIn.
    let mi = r
        .cmd(Command::MotionInVelocity {
            enable: true,
            velocity: 5.0,
            acceleration: 0.0,
            position_controlled: true,
        })
        .unwrap();
    r.step(5);
    let mr = r
        .cmd(Command::MoveRelative {
            distance: 1.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    assert!(r.has(mi, JobEventKind::CommandAborted));
    r.until(mr, JobEventKind::Done, 2000);
}

#[test]
fn alarm_with_stop_reaction_keeps_the_axis_enabled_and_reset_returns_to_standstill() {
    let mut cfg = AxisConfig::example(0.001);
    cfg.sw_limits = Some(tandem_motion::objects::axis::SoftwareLimits {
        min: -5.0,
        max: 5.0,
    });
    let mut r = Rig::enabled(cfg);
    r.cmd(Command::Home {
        mode: 0,
        position: 0.0,
    })
    .unwrap();
    let id = r
        .cmd(Command::MoveRelative {
            distance: 50.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    r.until(id, JobEventKind::Error(ErrorId::TechnologyAlarm), 2000);
    r.step(300);
    assert_eq!(r.axis.status().state, AxisState::ErrorStop);
    assert!((r.axis.status().position - 5.0).abs() < 1e-9);
    assert_eq!(r.axis.status().error_detail.number, 533);
    assert_eq!(
        r.cmd(Command::MoveRelative {
            distance: -1.0,
            dynamics: Dynamics::DEFAULT
        }),
        Err(ErrorId::JobRejectedInErrorStop)
    );
    r.cmd(Command::Reset { restart: false }).unwrap();
    r.step(1);
    assert_eq!(r.axis.status().state, AxisState::Standstill);
    assert_eq!(r.axis.status().error_detail.number, 0);
}

#[test]
fn non_position_controlled_mode_is_sticky_until_a_positioning_job() {
    // StartMode 0 enables without position control (StatusWord.X28); MoveVelocity with
    // PositionControlled FALSE keeps it after the job; Halt keeps the mode; MoveRelative forces
    // position control (S7-1500T Motion Control V4.0 function manual, 6.3.4 'Non
    // position-controlled operation').
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    r.cmd(Command::Power {
        enable: false,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Immediate,
    })
    .unwrap();
    r.cmd(Command::Power {
        enable: true,
        start_mode: StartMode::NonPositionControlled,
        stop_mode: StopMode::Emergency,
    })
    .unwrap();
    r.step(1);
    let npc = tandem_motion::catalog::alarm::status_bit::NON_POSITION_CONTROLLED;
    assert!(r.axis.status().has(npc));
    let v = r
        .cmd(Command::MoveVelocity {
            dynamics: dynamics(50.0, -1.0, -1.0, -1.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: false,
        })
        .unwrap();
    r.until(v, JobEventKind::InVelocity, 1000);
    assert!(r.axis.status().has(npc));
    assert_eq!(r.axis.status().following_error, 0.0);
    let h = r
        .cmd(Command::Halt {
            deceleration: -1.0,
            jerk: -1.0,
            abort_acceleration: false,
        })
        .unwrap();
    r.until(h, JobEventKind::Done, 1000);
    assert!(r.axis.status().has(npc), "Halt keeps the mode");
    let m = r
        .cmd(Command::MoveRelative {
            distance: 10.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    r.step(1);
    assert!(
        !r.axis.status().has(npc),
        "MoveRelative forces position control"
    );
    r.until(m, JobEventKind::Done, 3000);
}

#[test]
fn a_state_beyond_new_limits_is_brought_back_as_fast_as_they_allow() {
    // Running at 400; a MoveAbsolute with Velocity 100 and Deceleration 2000 brakes at once
    // with 2000 (jerk 0 here) down to 100: 300/2000 = 0.15 s, then cruises.
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    r.cmd(Command::Home {
        mode: 0,
        position: 0.0,
    })
    .unwrap();
    let v = r
        .cmd(Command::MoveVelocity {
            dynamics: dynamics(400.0, 5000.0, 5000.0, 0.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    r.until(v, JobEventKind::InVelocity, 1000);
    r.cmd(Command::MoveAbsolute {
        position: 10_000.0,
        dynamics: dynamics(100.0, 1000.0, 2000.0, 0.0),
        direction: tandem_motion::objects::axis::Direction::Shortest,
    })
    .unwrap();
    r.step(1);
    assert!((r.axis.status().velocity - (400.0 - 2000.0 * 0.001)).abs() < 1e-9);
    r.step(148);
    assert!(
        (r.axis.status().velocity - 102.0).abs() < 1e-9,
        "{}",
        r.axis.status().velocity
    );
    r.step(2);
    assert!((r.axis.status().velocity - 100.0).abs() < 1e-9);
    // The same with an override drop from 100 % to 25 % on a velocity job.
    r.cmd(Command::SetOverride { velocity: 25.0 }).unwrap();
    r.step(1);
    assert!((r.axis.status().velocity - (100.0 - 2000.0 * 0.001)).abs() < 1e-9);
}

#[test]
fn speed_axis_has_velocity_jobs_only() {
    let mut cfg = AxisConfig::example(0.001);
    cfg.kind = tandem_motion::objects::axis::AxisKind::Speed;
    let mut r = Rig::enabled(cfg);
    assert_eq!(
        r.cmd(Command::MoveRelative {
            distance: 1.0,
            dynamics: Dynamics::DEFAULT
        }),
        Err(ErrorId::IllegalObject)
    );
    assert_eq!(
        r.cmd(Command::Home {
            mode: 0,
            position: 0.0
        }),
        Err(ErrorId::IllegalObject)
    );
    let v = r
        .cmd(Command::MoveVelocity {
            dynamics: dynamics(120.0, -1.0, -1.0, -1.0),
            direction: VelocityDirection::BySign,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    r.until(v, JobEventKind::InVelocity, 1000);
    let s = r.axis.status();
    assert_eq!(s.velocity, 120.0);
    assert_eq!(
        s.status_word & !tandem_motion::catalog::alarm::status_bit::SPEED_AXIS_MASK,
        0
    );
}
