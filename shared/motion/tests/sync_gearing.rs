//! Synchronous operation: MC_GearIn, MC_GearInPos, MC_GearOut, phasing (S7-1500T Motion Control
//! V4.0 function manual, 3.5 'Synchronous axis technology object', 10.12 'Synchronous motion',
//! 10.16.2 'Override response V4: Synchronous operation jobs'). A leader and a follower in one
//! process, the leader stepped first (D = 0).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use tandem_motion::catalog::alarm::{status_bit, AlarmId};
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::kinematics::modulo::Modulo;
use tandem_motion::objects::axis::{
    AxisConfig, AxisState, Command, Direction, StartMode, StopMode, SyncDirection,
    SyncProfileReference, VelocityDirection,
};
use tandem_motion::objects::job::JobEventKind;

use tandem_testkit::rig::{dynamics, power, Pair, LEADER};

fn gear_in(num: i32, den: i32) -> Command {
    Command::GearIn {
        master: LEADER,
        ratio_numerator: num,
        ratio_denominator: den,
        dynamics: dynamics(-1.0, 2000.0, 2000.0, 40000.0),
    }
}

#[test]
fn gear_in_synchronizes_then_follows_exactly() {
    let mut p = Pair::new(AxisConfig::example(0.001), AxisConfig::example(0.001));
    p.leader
        .command(&Command::MoveVelocity {
            dynamics: dynamics(100.0, 1000.0, 1000.0, 10000.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    p.step(50);
    let g = p.f(gear_in(3, 2)).unwrap();
    assert_eq!(p.fs().state, AxisState::SynchronizedMotion);
    p.step(1);
    assert!(p.fs().has(status_bit::SYNCHRONIZING));
    p.until(g, JobEventKind::InGear, 5000);
    assert!(p.fs().has(status_bit::SYNCHRONOUS));
    assert_eq!(p.fs().sync_function, 1);
    let offset = p.fs().position_unwrapped - 1.5 * p.lv().p;
    // Leader: reversals and stops; follower: exactly offset + 1.5 x in every cycle.
    for target in [500.0, -200.0, 50.0] {
        p.leader
            .command(&Command::MoveAbsolute {
                position: target,
                dynamics: dynamics(300.0, 3000.0, 2000.0, 50000.0),
                direction: Direction::Shortest,
            })
            .unwrap();
        for _ in 0..1500 {
            p.step(1);
            let s = p.fs();
            let x = p.lv();
            assert!(
                (s.position_unwrapped - (offset + 1.5 * x.p)).abs() <= 1e-9 * 1000.0,
                "{} vs {}",
                s.position_unwrapped,
                offset + 1.5 * x.p
            );
            assert_eq!(s.velocity, 1.5 * x.v);
            assert_eq!(s.acceleration, 1.5 * x.a);
        }
    }
    assert!(!p.has(g, JobEventKind::CommandAborted));
}

#[test]
fn gear_in_checks_its_inputs_and_the_axis_type() {
    let mut p = Pair::new(AxisConfig::example(0.001), AxisConfig::example(0.001));
    assert_eq!(p.f(gear_in(0, 1)), Err(ErrorId::IllegalRatioNumerator));
    assert_eq!(p.f(gear_in(1, 0)), Err(ErrorId::IllegalRatioDenominator));
    assert_eq!(p.f(Command::GearOut), Err(ErrorId::NoSynchronousOperation));
    assert_eq!(
        p.f(Command::Phasing {
            phase_shift: 1.0,
            absolute: false,
            dynamics: Dynamics::DEFAULT
        }),
        Err(ErrorId::NoSynchronousOperation)
    );
    // A positioning axis cannot follow.
    assert_eq!(
        p.leader.command(&gear_in(1, 1)),
        Err(ErrorId::IllegalObject)
    );
}

#[test]
fn gear_out_continues_with_the_current_velocity_and_table_2() {
    let mut p = Pair::new(AxisConfig::example(0.001), AxisConfig::example(0.001));
    p.leader
        .command(&Command::MoveVelocity {
            dynamics: dynamics(80.0, -1.0, -1.0, -1.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    let g = p.f(gear_in(-1, 1)).unwrap();
    p.until(g, JobEventKind::InGear, 5000);
    // MoveSuperimposed on a follower does not abort gearing (table 2) and moves only it.
    let s = p
        .f(Command::MoveSuperimposed {
            distance: 10.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    assert!(
        !p.has(g, JobEventKind::CommandAborted),
        "table 2: superimposed does not abort GearIn"
    );
    p.until(s, JobEventKind::Done, 3000);
    let before = p.fs();
    let out = p.f(Command::GearOut).unwrap();
    assert!(p.has(out, JobEventKind::Done));
    assert!(p.has(g, JobEventKind::CommandAborted));
    p.step(300);
    let after = p.fs();
    assert!((after.velocity + 80.0).abs() < 1e-9, "{}", after.velocity);
    assert!((before.velocity + 80.0).abs() < 1e-9);
    assert_eq!(after.state, AxisState::ContinuousMotion);
    // Halt aborts gearing (table 2).
    let alarms: Vec<_> = p.follower.alarms().collect();
    assert!(alarms.is_empty(), "{alarms:?} {:?}", p.fs());
    let g = p.f(gear_in(1, 1)).unwrap();
    p.step(10);
    let alarms: Vec<_> = p.follower.alarms().collect();
    assert!(alarms.is_empty(), "{alarms:?} {:?}", p.fs());
    let h = p
        .f(Command::Halt {
            deceleration: -1.0,
            jerk: -1.0,
            abort_acceleration: false,
        })
        .unwrap();
    assert!(p.has(g, JobEventKind::CommandAborted));
    p.until(h, JobEventKind::Done, 3000);
}

fn gear_in_pos(msp: f64, ssp: f64, msd: f64, reference: SyncProfileReference) -> Command {
    Command::GearInPos {
        master: LEADER,
        ratio_numerator: 1,
        ratio_denominator: 1,
        master_sync_position: msp,
        slave_sync_position: ssp,
        sync_profile_reference: reference,
        master_start_distance: msd,
        dynamics: dynamics(400.0, 4000.0, 4000.0, 100000.0),
        sync_direction: SyncDirection::Shortest,
    }
}

#[test]
fn gear_in_pos_is_synchronous_exactly_at_the_sync_positions() {
    // Leader at constant 100; MasterSyncPosition 300, SlaveSyncPosition 50, MasterStartDistance
    // 100: StartSync when the leader passes 200, InSync at 300 with the follower at 50.
    let mut p = Pair::new(AxisConfig::example(0.001), AxisConfig::example(0.001));
    p.leader
        .command(&Command::MoveVelocity {
            dynamics: dynamics(100.0, 1000.0, 1000.0, 0.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    let m = p
        .f(Command::MoveVelocity {
            dynamics: dynamics(20.0, -1.0, -1.0, -1.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    let g = p
        .f(gear_in_pos(
            300.0,
            50.0,
            100.0,
            SyncProfileReference::MasterStartDistance,
        ))
        .unwrap();
    assert!(
        !p.has(m, JobEventKind::CommandAborted),
        "a pending GearInPos aborts nothing"
    );
    let mut started_at = None;
    let mut insync_at = None;
    for _ in 0..4000 {
        p.step(1);
        let x = p.lv().p;
        if started_at.is_none() && p.has(g, JobEventKind::StartSync) {
            started_at = Some(x);
            assert!(
                p.has(m, JobEventKind::CommandAborted),
                "StartSync aborts the motion"
            );
        }
        if insync_at.is_none() && p.has(g, JobEventKind::InSync) {
            insync_at = Some(x);
        }
        if x >= 300.0 {
            assert!(
                (p.fs().position_unwrapped - (50.0 + (x - 300.0))).abs() < 1e-9,
                "x {x}: {}",
                p.fs().position_unwrapped
            );
        }
        if x > 400.0 {
            break;
        }
    }
    let s = started_at.unwrap();
    assert!((200.0..200.0 + 0.1 + 1e-9).contains(&s), "StartSync at {s}");
    let i = insync_at.unwrap();
    assert!((300.0..300.1 + 1e-9).contains(&i), "InSync at {i}");
}

#[test]
fn gear_in_pos_inside_the_start_distance_is_an_error_and_reversal_is_alarm_608() {
    let mut p = Pair::new(AxisConfig::example(0.001), AxisConfig::example(0.001));
    p.leader
        .command(&Command::Home {
            mode: 0,
            position: 250.0,
        })
        .unwrap();
    p.step(1);
    let g = p
        .f(gear_in_pos(
            300.0,
            0.0,
            100.0,
            SyncProfileReference::MasterStartDistance,
        ))
        .unwrap();
    p.step(2);
    assert!(p.has(g, JobEventKind::Error(ErrorId::IllegalMasterStartDistance)));
    // Reversal during synchronization.
    p.leader
        .command(&Command::Home {
            mode: 0,
            position: 0.0,
        })
        .unwrap();
    p.leader
        .command(&Command::MoveVelocity {
            dynamics: dynamics(100.0, 1000.0, 1000.0, 0.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    let g = p
        .f(gear_in_pos(
            300.0,
            0.0,
            250.0,
            SyncProfileReference::MasterStartDistance,
        ))
        .unwrap();
    p.until(g, JobEventKind::StartSync, 2000);
    p.step(200);
    p.leader
        .command(&Command::MoveVelocity {
            dynamics: dynamics(100.0, 1000.0, 1000.0, 0.0),
            direction: VelocityDirection::Negative,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    p.until(g, JobEventKind::Error(ErrorId::TechnologyAlarm), 2000);
    assert!(p.follower.has_alarm(AlarmId::SynchronizationError));
}

#[test]
fn phasing_shifts_the_leading_value() {
    let mut p = Pair::new(AxisConfig::example(0.001), AxisConfig::example(0.001));
    p.leader
        .command(&Command::MoveVelocity {
            dynamics: dynamics(50.0, -1.0, -1.0, -1.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    let g = p.f(gear_in(2, 1)).unwrap();
    p.until(g, JobEventKind::InGear, 5000);
    let offset = p.fs().position_unwrapped - 2.0 * p.lv().p;
    // Relative 50 twice: 100 in total; the follower moves 2 * 100 more.
    for _ in 0..2 {
        let ph = p
            .f(Command::Phasing {
                phase_shift: 50.0,
                absolute: false,
                dynamics: Dynamics::DEFAULT,
            })
            .unwrap();
        assert!(p.fs().has(status_bit::PHASING_COMMAND));
        p.until(ph, JobEventKind::Done, 5000);
    }
    p.step(1);
    assert!((p.fs().phase_shift - 100.0).abs() < 1e-9);
    assert!((p.fs().position_unwrapped - (offset + 2.0 * (p.lv().p + 100.0))).abs() < 1e-9);
    // Absolute to the same value: no motion.
    let ph = p
        .f(Command::Phasing {
            phase_shift: 100.0,
            absolute: true,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    p.until(ph, JobEventKind::Done, 10);
    // Overriding the gearing resets the shift.
    p.f(Command::Halt {
        deceleration: -1.0,
        jerk: -1.0,
        abort_acceleration: false,
    })
    .unwrap();
    p.step(1);
    assert_eq!(p.fs().phase_shift, 0.0);
}

#[test]
fn gear_in_pos_on_modulo_axes_with_dynamics_reference() {
    // Modulo leader and follower (360); sync by dynamics: the follower keeps its limits while
    // synchronizing behind a constant-speed leader and is synchronous at the next 90 degrees.
    let mut lc = AxisConfig::example(0.001);
    lc.modulo = Some(Modulo {
        start: 0.0,
        length: 360.0,
    });
    let mut fc = AxisConfig::example(0.001);
    fc.modulo = Some(Modulo {
        start: 0.0,
        length: 360.0,
    });
    fc.limits.max_velocity = 1000.0;
    let mut p = Pair::new(lc, fc);
    p.leader
        .command(&Command::MoveVelocity {
            dynamics: dynamics(200.0, 2000.0, 2000.0, 0.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    p.step(500);
    let g = p
        .f(Command::GearInPos {
            master: LEADER,
            ratio_numerator: 1,
            ratio_denominator: 1,
            master_sync_position: 90.0,
            slave_sync_position: 180.0,
            sync_profile_reference: SyncProfileReference::Dynamics,
            master_start_distance: -1.0,
            dynamics: dynamics(400.0, 1500.0, 1500.0, 30000.0),
            sync_direction: SyncDirection::Shortest,
        })
        .unwrap();
    p.until(g, JobEventKind::StartSync, 10_000);
    let mut max_a: f64 = 0.0;
    let mut max_v: f64 = 0.0;
    while !p.has(g, JobEventKind::InSync) {
        p.step(1);
        if p.k > 30_000 {
            panic!("no InSync");
        }
        max_a = max_a.max(p.fs().acceleration.abs());
        max_v = max_v.max(p.fs().velocity.abs());
    }
    assert!(max_a <= 1500.0 * (1.0 + 1e-6), "{max_a}");
    assert!(max_v <= 400.0 * (1.0 + 1e-6), "{max_v}");
    p.step(1);
    let s = p.fs();
    let x = p.follower.status();
    // Read for its side of the borrow only; the assertions use the pair.
    let _ = x;
    let leader_mod = p.leader.status().position;
    // Synchronous: follower = 180 + (leader - 90) modulo 360.
    let expect = Modulo {
        start: 0.0,
        length: 360.0,
    }
    .wrap(180.0 + leader_mod - 90.0);
    assert!(
        (s.position - expect).abs() < 1e-9,
        "{} vs {expect}",
        s.position
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, failure_persistence: None, rng_seed: proptest::test_runner::RngSeed::Fixed(0x5e_ed_6e_a2), ..ProptestConfig::default() })]

    /// Exact synchronism for random ratios and leader profiles, and GearInPos hitting the sync
    /// positions exactly for constant-speed and accelerating leaders.
    #[test]
    fn gearing_is_exact(
        num in prop_oneof![-5i32..-1, 1i32..6], den in 1i32..5,
        moves in prop::collection::vec((-800.0f64..800.0, 50.0f64..400.0), 1..4),
        msd in 20.0f64..200.0, accel in prop::bool::ANY,
    ) {
        let g = f64::from(num) / f64::from(den);
        let mut fc = AxisConfig::example(0.001);
        fc.limits.max_velocity = 5000.0;
        fc.following_error.enable = false;
        let mut p = Pair::new(AxisConfig::example(0.001), fc);
        let gid = p.f(gear_in(num, den)).unwrap();
        p.until(gid, JobEventKind::InGear, 5000);
        let offset = p.fs().position_unwrapped - g * p.lv().p;
        for (target, v) in &moves {
            p.leader.command(&Command::MoveAbsolute { position: *target, dynamics: dynamics(*v, 2000.0, 1500.0, 30000.0), direction: Direction::Shortest }).unwrap();
            for _ in 0..800 {
                p.step(1);
                let s = p.fs();
                prop_assert!((s.position_unwrapped - (offset + g * p.lv().p)).abs() <= 1e-9 * 1000.0 * g.abs().max(1.0));
            }
        }
        // GearInPos: the leader starts from rest 500 before the sync position, constant speed
        // or accelerating through the synchronization; exact at MasterSyncPosition.
        let x0 = p.lv().p;
        let msp = x0 + 500.0;
        let lead = if accel { dynamics(400.0, 300.0, 300.0, 0.0) } else { dynamics(150.0, 5000.0, 5000.0, 0.0) };
        p.leader.command(&Command::MoveVelocity { dynamics: lead, direction: VelocityDirection::Positive, current: false, position_controlled: true }).unwrap();
        let gp = p.f(Command::GearInPos {
            master: LEADER, ratio_numerator: num, ratio_denominator: den,
            master_sync_position: msp, slave_sync_position: 123.0,
            sync_profile_reference: SyncProfileReference::MasterStartDistance, master_start_distance: msd,
            dynamics: Dynamics::DEFAULT, sync_direction: SyncDirection::Shortest,
        }).unwrap();
        let mut prev = p.fs().position_unwrapped;
        for _ in 0..20_000 {
            p.step(1);
            let x = p.lv().p;
            let y = p.fs().position_unwrapped;
            if x >= msp {
                prop_assert!(p.has(gp, JobEventKind::InSync));
                prop_assert!((y - (123.0 + g * (x - msp))).abs() <= 1e-9 * 1000.0 * g.abs().max(1.0), "{} vs {}", y, 123.0 + g * (x - msp));
            }
            prop_assert!(y.is_finite() && (y - prev).abs() < 100.0);
            prev = y;
            if x > msp + 50.0 { break; }
        }
        prop_assert!(p.has(gp, JobEventKind::InSync));
    }
}

#[test]
fn actual_value_coupling_compensates_the_leader_delay() {
    // The leader's actual value lags its setpoint by T_t = 4 ms (delay model). Extrapolating
    // by cycle (1 ms) + following time (3 ms) brings it back: at constant velocity the follower
    // coupled by actual value is where a setpoint-coupled one would be.
    let mut lc = AxisConfig::example(0.001);
    lc.drive = tandem_motion::plant::drive::DriveModel::Delay { delay: 0.004 };
    lc.following_error.enable = false;
    lc.extrapolation.position_t1 = 0.002;
    lc.extrapolation.velocity_t1 = 0.005;
    lc.extrapolation.following_time = 0.003;
    let mut p = Pair::new(lc, AxisConfig::example(0.001));
    p.use_actual();
    p.leader
        .command(&Command::MoveVelocity {
            dynamics: dynamics(120.0, 1000.0, 1000.0, 0.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    p.step(500);
    let g = p.f(gear_in(1, 1)).unwrap();
    p.until(g, JobEventKind::InGear, 5000);
    let offset = p.fs().position_unwrapped - p.lv().p;
    p.step(200);
    // Extrapolated actual = setpoint at constant velocity, to rounding.
    let sp = p.leader.setpoint_leading_value();
    let ex = p.leader.actual_leading_value();
    assert!((ex.p - sp.p).abs() < 1e-9, "{} vs {}", ex.p, sp.p);
    assert!((ex.v - 120.0).abs() < 1e-9);
    assert!((p.fs().position_unwrapped - (offset + sp.p)).abs() < 1e-9);
}

#[test]
fn velocity_gearing_ignores_a_leader_position_jump_and_offsets_shift_the_follower() {
    let mut p = Pair::new(AxisConfig::example(0.001), AxisConfig::example(0.001));
    p.leader
        .command(&Command::MoveVelocity {
            dynamics: dynamics(60.0, -1.0, -1.0, -1.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    p.step(300);
    let g = p
        .f(Command::GearInVelocity {
            master: LEADER,
            ratio_numerator: 2,
            ratio_denominator: 1,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    p.until(g, JobEventKind::InSync, 5000);
    p.step(10);
    assert!((p.fs().velocity - 120.0).abs() < 1e-9);
    // Homing the leader (a jump of 500) does not move a velocity-geared follower.
    let before = p.fs().position_unwrapped;
    p.leader
        .command(&Command::Home {
            mode: 1,
            position: 500.0,
        })
        .unwrap();
    p.step(1);
    let after = p.fs().position_unwrapped;
    assert!(
        (after - before - 120.0 * 0.001).abs() < 1e-9,
        "{}",
        after - before
    );
    assert!(p
        .f(Command::Phasing {
            phase_shift: 1.0,
            absolute: false,
            dynamics: Dynamics::DEFAULT
        })
        .is_err());

    // Position gearing with an offset of the following value: relative +10 then absolute 0.
    let g = p.f(gear_in(1, 1)).unwrap();
    p.until(g, JobEventKind::InGear, 5000);
    let base = p.fs().position_unwrapped - p.lv().p;
    let o = p
        .f(Command::Offset {
            offset: 10.0,
            absolute: false,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    p.until(o, JobEventKind::Done, 5000);
    p.step(1);
    assert!((p.fs().position_unwrapped - (base + 10.0 + p.lv().p)).abs() < 1e-9);
    let o = p
        .f(Command::Offset {
            offset: 0.0,
            absolute: true,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    p.until(o, JobEventKind::Done, 5000);
    p.step(1);
    assert!((p.fs().position_unwrapped - (base + p.lv().p)).abs() < 1e-9);
}

#[test]
fn superimposed_on_the_leader_moves_its_followers_and_exceedances_are_flagged() {
    // S7-1500T Motion Control V4.0 function manual, 10.9.1 'MC_MoveSuperimposed: Position axes
    // overlapping V4': on a leader it moves leader and followers.
    let mut fc = AxisConfig::example(0.001);
    fc.following_error.enable = false;
    let mut p = Pair::new(AxisConfig::example(0.001), fc);
    let g = p.f(gear_in(1, 1)).unwrap();
    p.until(g, JobEventKind::InGear, 1000);
    let before = p.fs().position_unwrapped;
    let s = p
        .leader
        .command(&Command::MoveSuperimposed {
            distance: 10.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    for _ in 0..2000 {
        p.step(1);
        if p.leader.status().superimposed_job.is_none() {
            break;
        }
    }
    // The state before is not needed past this point.
    let _ = s;
    assert!((p.fs().position_unwrapped - before - 10.0).abs() < 1e-9);
    // Synchronous followers are not clamped to their own limits: ratio 8 at leader 100/s is
    // 800/s on a follower limited to 500/s: MaxVelocityExceeded, no alarm, exact coupling.
    let g = p.f(gear_in(8, 1)).unwrap();
    p.leader
        .command(&Command::MoveVelocity {
            dynamics: dynamics(100.0, 1000.0, 1000.0, 0.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    p.until(g, JobEventKind::InGear, 5000);
    p.step(300);
    let st = p.fs();
    assert!((st.velocity - 800.0).abs() < 1e-9);
    assert_eq!(st.sync_status_word & 1, 1, "MaxVelocityExceeded");
    assert!(p.follower.alarms().next().is_none());
}

#[test]
fn synchronized_motion_simulation_keeps_the_coupling_through_a_disable() {
    let mut fc = AxisConfig::example(0.001);
    fc.following_error.enable = false;
    fc.drive = tandem_motion::plant::drive::DriveModel::Delay { delay: 0.002 };
    let mut p = Pair::new(AxisConfig::example(0.001), fc);
    let g = p.f(gear_in(1, 1)).unwrap();
    p.until(g, JobEventKind::InGear, 1000);
    let offset = p.fs().position_unwrapped - p.lv().p;
    let sim = p
        .f(Command::SynchronizedMotionSimulation { enable: true })
        .unwrap();
    assert!(p.has(sim, JobEventKind::InSimulation(true)));
    assert_eq!(p.f(gear_in(2, 1)), Err(ErrorId::SyncSimulationActive));
    // The safety door opens: the follower is disabled; the coupling stays.
    p.f(Command::Power {
        enable: false,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Immediate,
    })
    .unwrap();
    assert!(!p.has(g, JobEventKind::CommandAborted));
    let held = p.fs().position_unwrapped;
    p.leader
        .command(&Command::MoveRelative {
            distance: 100.0,
            dynamics: Dynamics::DEFAULT,
        })
        .unwrap();
    p.step(3000);
    assert!(
        (p.fs().position_unwrapped - held).abs() < 1e-9,
        "the follower stood still"
    );
    assert_eq!(p.fs().sync_status_word & 8, 8, "InSimulation");
    p.f(power()).unwrap();
    p.step(10);
    assert!((p.fs().position_unwrapped - held).abs() < 1e-9);
    // The end of the simulation outputs the coupling again: a step of the leader's 100.
    p.f(Command::SynchronizedMotionSimulation { enable: false })
        .unwrap();
    assert!(p.has(sim, JobEventKind::InSimulation(false)));
    p.step(1);
    assert!((p.fs().position_unwrapped - (offset + p.lv().p)).abs() < 1e-9);
    assert!((p.fs().position_unwrapped - held - 100.0).abs() < 1e-6);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 20, failure_persistence: None, rng_seed: proptest::test_runner::RngSeed::Fixed(0x5e_ed_d7_a1), ..ProptestConfig::default() })]

    /// SyncProfileReference 0: behind a constant-speed leader the follower keeps the given
    /// velocity (or the synchronous one, if higher) and acceleration while synchronizing (to
    /// 1e-4: the synchronization starts within a cycle of the computed start, which lengthens
    /// it by up to one cycle of leader travel), and is synchronous exactly at the sync positions.
    #[test]
    fn gear_in_pos_by_dynamics_respects_them(
        num in prop_oneof![-3i32..-1, 1i32..4], den in 1i32..3,
        v_lead in 100.0f64..300.0, acc in 500.0f64..5000.0, ssp in -200.0f64..200.0,
        start_v in -50.0f64..50.0,
    ) {
        let g = f64::from(num) / f64::from(den);
        let mut fc = AxisConfig::example(0.001);
        fc.limits.max_velocity = 5000.0;
        fc.limits.max_acceleration = 50000.0;
        fc.limits.max_deceleration = 50000.0;
        fc.limits.max_jerk = 1e7;
        fc.following_error.enable = false;
        let mut p = Pair::new(AxisConfig::example(0.001), fc);
        p.leader.command(&Command::MoveVelocity { dynamics: dynamics(v_lead, 50000.0, 50000.0, 0.0), direction: VelocityDirection::Positive, current: false, position_controlled: true }).unwrap();
        if start_v != 0.0 {
            p.f(Command::MoveVelocity { dynamics: dynamics(start_v.abs(), 5000.0, 5000.0, 0.0), direction: if start_v > 0.0 { VelocityDirection::Positive } else { VelocityDirection::Negative }, current: false, position_controlled: true }).unwrap();
        }
        p.step(100);
        let msp = p.lv().p + 8000.0;
        let vel = 400.0;
        let gp = p.f(Command::GearInPos {
            master: LEADER, ratio_numerator: num, ratio_denominator: den,
            master_sync_position: msp, slave_sync_position: ssp,
            sync_profile_reference: SyncProfileReference::Dynamics, master_start_distance: -1.0,
            dynamics: dynamics(vel, acc, acc, 0.0), sync_direction: SyncDirection::Shortest,
        }).unwrap();
        let mut started = false;
        for _ in 0..100_000 {
            p.step(1);
            let x = p.lv().p;
            let s = p.fs();
            if p.has(gp, JobEventKind::StartSync) && !p.has(gp, JobEventKind::InSync) {
                started = true;
                prop_assert!(s.velocity.abs() <= vel.max((g * v_lead).abs()).max(start_v.abs()) * (1.0 + 1e-4) + 1e-9, "v {}", s.velocity);
                prop_assert!(s.acceleration.abs() <= acc * (1.0 + 1e-4), "a {} > {acc}", s.acceleration);
            }
            if x >= msp {
                prop_assert!(p.has(gp, JobEventKind::InSync));
                prop_assert!((s.position_unwrapped - (ssp + g * (x - msp))).abs() < 1e-9 * 1000.0);
                break;
            }
        }
        prop_assert!(started);
    }
}

/// A missing leading value (a leader on another node that stopped publishing) is alarm 601 with
/// the follower's configured reaction: by default the table's stop with maximum dynamics; a
/// configured emergency stop brakes with the emergency deceleration; remove enable disables.
/// Each reaction shows in ErrorDetail. The follower never jumps.
#[test]
fn a_missing_leading_value_raises_601_with_the_configured_reaction() {
    use tandem_motion::catalog::alarm::Reaction;
    for configured in [
        None,
        Some(Reaction::StopCurrentDynamics),
        Some(Reaction::EmergencyStop),
        Some(Reaction::RemoveEnable),
    ] {
        let mut cfg = AxisConfig::example(0.001);
        cfg.leader_missing_reaction = configured;
        let mut p = Pair::new(AxisConfig::example(0.001), cfg);
        p.leader
            .command(&Command::MoveVelocity {
                dynamics: dynamics(200.0, 2000.0, 2000.0, 40000.0),
                direction: VelocityDirection::Positive,
                current: false,
                position_controlled: true,
            })
            .unwrap();
        p.step(10);
        let g = p.f(gear_in(1, 1)).unwrap();
        p.until(g, JobEventKind::InGear, 5000);
        p.step(500);
        let before = p.fs();
        assert!((before.velocity - 200.0).abs() < 1e-9);
        // The leading value is gone from now on.
        let t = p.k * 1_000_000;
        p.follower.set_leading_value(LEADER, None);
        p.follower.step(t);
        let s = p.fs();
        let expected = configured.unwrap_or(Reaction::StopMaxDynamics);
        assert_eq!(s.error_detail.number, AlarmId::LeaderMissing.number());
        assert_eq!(s.error_detail.reaction, expected, "{configured:?}");
        assert!(p
            .follower
            .alarms()
            .any(|a| a.id == AlarmId::LeaderMissing && a.reaction == expected));
        // No jump: the first cycle without the leader continues from the last state.
        let step = s.position_unwrapped - before.position_unwrapped;
        assert!(
            (step - 0.2).abs() < 1e-3,
            "{configured:?}: moved {step} in the first cycle without the leader"
        );
        match expected {
            Reaction::RemoveEnable => {
                assert_eq!(s.state, AxisState::ErrorStop);
                assert!(!s.has(status_bit::ENABLE));
            }
            _ => {
                assert_eq!(s.state, AxisState::ErrorStop);
                // Braking: the deceleration of the reaction (max 5000, emergency 10000; the
                // job's 2000 for the current dynamics), ramped up by the jerk where it has one.
                let mut v = s.velocity;
                let mut decel = 0.0f64;
                for k in 0..400 {
                    let t = (p.k + 1 + k) * 1_000_000;
                    p.follower.set_leading_value(LEADER, None);
                    p.follower.step(t);
                    let now = p.fs();
                    decel = decel.max((v - now.velocity) / 0.001);
                    v = now.velocity;
                }
                assert_eq!(v, 0.0, "{expected:?}: braked to standstill");
                let limit = match expected {
                    Reaction::StopCurrentDynamics => 2000.0,
                    Reaction::StopMaxDynamics => 5000.0,
                    _ => 10000.0,
                };
                assert!(
                    decel <= limit * (1.0 + 1e-6) && decel > 0.5 * limit,
                    "{expected:?}: deceleration {decel}, limit {limit}"
                );
            }
        }
    }
}
