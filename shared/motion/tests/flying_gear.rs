//! MC_FlyingGear_BkPlcMc (Beckhoff TwinCAT PLC Hydraulic Positioning library, 4.2.6
//! 'MC_FlyingGear_BkPlcMc'): the law with the numbers of the reference's 'Sample #1' (and the
//! variants of 'Sample #2' and 'Sample #3'), the ramps' lengths, continuity in position and
//! velocity through both ramps, exact gearing in between, and the refusals; then on an axis
//! following a leader axis (a leader and a follower in one process, the leader stepped first).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::objects::axis::{
    sync_status, AxisConfig, AxisStatus, Command, Direction, FlyingGear, FlyingGearError,
    FlyingGearParams, FlyingPhase,
};
use tandem_motion::objects::job::{Instruction, JobEventKind};
use tandem_testkit::rig::{dynamics, Pair, LEADER};

/// 'Sample #1': master parked at 800, slave at 500; MasterSyncPosition 460, SlaveSyncPosition
/// 450, SlaveDesyncPosition 450, SlaveStopPosition 500, Ratio 1.
fn sample1() -> FlyingGearParams {
    FlyingGearParams {
        ratio: 1.0,
        master_sync_position: 460.0,
        slave_sync_position: 450.0,
        slave_desync_position: 450.0,
        slave_stop_position: 500.0,
        default_slave_negative: false,
    }
}

fn started(p: FlyingGearParams, slave: f64, master: f64) -> FlyingGear {
    let mut g = FlyingGear::new(p, slave).unwrap();
    g.start(master).unwrap();
    g
}

#[test]
fn sample_1_known_answers() {
    let mut g = started(sample1(), 500.0, 800.0);
    // "the synchronization of the master will start at 460.0 mm + 100 mm => 560 mm".
    assert_eq!(g.engage_start(), 560.0);
    // Waiting: the slave stands at 500 until the master reaches 560.
    for m in [800.0, 700.0, 560.000_001] {
        let f = g.step(m);
        assert_eq!(
            (f.position, f.slope, f.phase),
            (500.0, 0.0, FlyingPhase::Waiting)
        );
    }
    let f = g.step(560.0);
    assert_eq!(
        (f.position, f.slope, f.phase),
        (500.0, 0.0, FlyingPhase::Engaging)
    );
    assert!(f.phase.start_sync() && !f.phase.active() && !f.phase.in_sync());
    // Halfway (50 mm of master): the ratio is 0.5, the slave has gone 50·0.5/2 = 12.5.
    let f = g.step(510.0);
    assert_eq!((f.position, f.slope), (487.5, 0.5));
    // At the sync point: 450, ratio 1, InSync and Active.
    let f = g.step(460.0);
    assert_eq!(
        (f.position, f.slope, f.phase),
        (450.0, 1.0, FlyingPhase::InSync)
    );
    assert!(f.phase.in_sync() && f.phase.active() && !f.phase.start_sync());
    // In sync, same directions: slave = 450 - (460 - m).
    for m in [455.0, 400.0, 300.25, 459.0] {
        let f = g.step(m);
        assert_eq!(f.position, 450.0 - (460.0 - m));
        assert_eq!(f.phase, FlyingPhase::InSync);
    }
    // On the way back the release starts at SlaveDesyncPosition 450 (master 460) and ends at
    // SlaveStopPosition 500 after 2·50/1 = 100 mm of master.
    assert_eq!((g.release_start(), g.release_end()), (460.0, 560.0));
    let f = g.step(510.0);
    assert_eq!(
        (f.position, f.slope, f.phase),
        (487.5, 0.5, FlyingPhase::Releasing)
    );
    assert!(f.phase.active() && !f.phase.in_sync());
    let f = g.step(560.0);
    assert_eq!(
        (f.position, f.slope, f.phase),
        (500.0, 0.0, FlyingPhase::Stopped)
    );
    assert!(!f.phase.active());
    // Stopped stays stopped, wherever the master goes.
    for m in [800.0, 460.0, 300.0] {
        assert_eq!(g.step(m).position, 500.0);
    }
}

#[test]
fn sample_2_opposite_directions_and_sample_3_longer_release() {
    // 'Sample #2': the slave starts 50 mm below SlaveSyncPosition and works upwards.
    let p2 = FlyingGearParams {
        slave_stop_position: 400.0,
        ..sample1()
    };
    let mut g = started(p2, 400.0, 800.0);
    assert_eq!(g.engage_start(), 560.0);
    assert_eq!(g.step(510.0).position, 412.5);
    let f = g.step(400.0);
    assert_eq!((f.position, f.slope), (450.0 + (460.0 - 400.0), -1.0));
    assert_eq!(g.step(560.0).position, 400.0);
    assert_eq!(g.phase(), FlyingPhase::Stopped);
    // 'Sample #3': Desync -> Stop is 100 mm, so the release takes 200 mm of master.
    let p3 = FlyingGearParams {
        slave_stop_position: 550.0,
        ..sample1()
    };
    let mut g = started(p3, 500.0, 800.0);
    g.step(400.0);
    assert_eq!((g.release_start(), g.release_end()), (460.0, 660.0));
    assert_eq!(g.step(560.0).position, 450.0 + 100.0 * 0.75);
    assert_eq!(g.step(660.0).position, 550.0);
    assert_eq!(g.phase(), FlyingPhase::Stopped);
}

#[test]
fn ramps_scale_with_the_ratio_and_the_tie_break() {
    // Ratio 0.8: the master needs 2·50/0.8 = 125 mm to engage.
    let g = started(
        FlyingGearParams {
            ratio: 0.8,
            ..sample1()
        },
        500.0,
        800.0,
    );
    assert_eq!(g.engage_start(), 585.0);
    // Slave already at SlaveSyncPosition, empty release: DefaultSlaveNegative decides.
    let p = FlyingGearParams {
        slave_stop_position: 450.0,
        ..sample1()
    };
    for (neg, y) in [(true, 450.0 - 10.0), (false, 450.0 + 10.0)] {
        let mut g = started(
            FlyingGearParams {
                default_slave_negative: neg,
                ..p
            },
            450.0,
            800.0,
        );
        assert_eq!(g.engage_start(), 460.0);
        g.step(460.0);
        assert_eq!(g.step(450.0).position, y);
    }
}

#[test]
fn refusals_name_the_input() {
    let bad = |p: FlyingGearParams| FlyingGear::new(p, 500.0).unwrap_err();
    for (p, field) in [
        (
            FlyingGearParams {
                ratio: 0.0,
                ..sample1()
            },
            "Ratio",
        ),
        (
            FlyingGearParams {
                ratio: -1.0,
                ..sample1()
            },
            "Ratio",
        ),
        (
            FlyingGearParams {
                ratio: f64::NAN,
                ..sample1()
            },
            "Ratio",
        ),
        (
            FlyingGearParams {
                master_sync_position: f64::INFINITY,
                ..sample1()
            },
            "MasterSyncPosition",
        ),
        (
            FlyingGearParams {
                slave_sync_position: f64::NAN,
                ..sample1()
            },
            "SlaveSyncPosition",
        ),
        (
            FlyingGearParams {
                slave_desync_position: f64::NAN,
                ..sample1()
            },
            "SlaveDesyncPosition",
        ),
        (
            FlyingGearParams {
                slave_stop_position: f64::NAN,
                ..sample1()
            },
            "SlaveStopPosition",
        ),
    ] {
        assert_eq!(bad(p), FlyingGearError::Parameter { field });
    }
    // The release must run back against the working direction (downwards here).
    assert_eq!(
        bad(FlyingGearParams {
            slave_stop_position: 400.0,
            ..sample1()
        }),
        FlyingGearError::StopPositionSide {
            slave_direction: -1.0
        }
    );
    // "If the master is below this position [560] when the coupling is enabled, an error is
    // signaled"; the refused start changes nothing.
    let mut g = FlyingGear::new(sample1(), 500.0).unwrap();
    let before = g;
    for m in [559.999, 460.0] {
        assert!(matches!(
            g.start(m),
            Err(FlyingGearError::MasterInsideEngageSection { .. })
        ));
        assert_eq!(g, before);
    }
    assert_eq!(g.start(560.0), Ok(()));
    // The master's working direction is towards MasterSyncPosition from where it is: below it,
    // the stroke is upwards and the engage section starts at 360.
    let mut g = FlyingGear::new(sample1(), 500.0).unwrap();
    assert_eq!(g.start(300.0), Ok(()));
    assert_eq!(g.engage_start(), 360.0);
}

/// Leader positions `xs` through the law: the follower's position moves by at most the largest
/// ratio times the leader's move, its slope (velocity / leader velocity) by at most the ramp's
/// curvature times the leader's move, and it is exactly geared whenever InSync.
fn check_continuity(g: &mut FlyingGear, xs: impl Iterator<Item = f64>) -> [bool; 4] {
    let p = *g.params();
    let r = p.ratio;
    let l_min = (2.0 * (p.slave_sync_position - g.slave_start()).abs() / r)
        .min(2.0 * (p.slave_stop_position - p.slave_desync_position).abs() / r);
    let mut prev: Option<(f64, tandem_motion::objects::axis::FlyingPoint)> = None;
    let mut seen = [false; 4];
    for x in xs {
        let f = g.step(x);
        if let Some((x0, f0)) = prev {
            let dx = (x - x0).abs();
            let tol = 1e-9 * (1.0 + x.abs() + f.position.abs());
            assert!(
                (f.position - f0.position).abs() <= r * dx + tol,
                "position step {} for leader step {dx} at {x} ({:?} -> {:?})",
                f.position - f0.position,
                f0.phase,
                f.phase
            );
            assert!(
                (f.slope - f0.slope).abs() <= r / l_min * dx * (1.0 + 1e-9) + 1e-12,
                "ratio step {} for leader step {dx} at {x} ({:?} -> {:?})",
                f.slope - f0.slope,
                f0.phase,
                f.phase
            );
            // Inside a phase, the position is the integral of the slope (trapezoid exact for
            // a quadratic).
            if f.phase == f0.phase {
                let int = 0.5 * (f.slope + f0.slope) * (x - x0);
                assert!((f.position - f0.position - int).abs() <= tol);
            }
        }
        if f.phase == FlyingPhase::InSync {
            let s = f.slope.signum();
            let geared = p.slave_sync_position + s * r * (x - p.master_sync_position);
            assert!((f.position - geared).abs() <= 1e-9 * (1.0 + geared.abs()));
        }
        match f.phase {
            FlyingPhase::Engaging => seen[0] = true,
            FlyingPhase::InSync => seen[1] = true,
            FlyingPhase::Releasing => seen[2] = true,
            FlyingPhase::Stopped => seen[3] = true,
            _ => {}
        }
        prev = Some((x, f));
    }
    seen
}

/// A stroke of the leader from `from` to `turn` and back, with speed `v(k)` per step.
fn stroke(from: f64, turn: f64, v: impl Fn(usize) -> f64) -> Vec<f64> {
    let mut xs = vec![from];
    let mut x = from;
    let dir = (turn - from).signum();
    let mut k = 0;
    while dir * (turn - x) > 0.0 {
        x = if dir * (turn - (x + dir * v(k))) > 0.0 {
            x + dir * v(k)
        } else {
            turn
        };
        xs.push(x);
        k += 1;
    }
    while dir * (x - from) > 0.0 {
        x = if dir * (x - dir * v(k) - from) > 0.0 {
            x - dir * v(k)
        } else {
            from
        };
        xs.push(x);
        k += 1;
    }
    xs
}

#[test]
fn continuous_through_both_ramps_at_constant_and_changing_speed() {
    for v in [&(|_| 0.37) as &dyn Fn(usize) -> f64, &|k| {
        0.05 + 0.9 * ((k as f64) * 0.013).sin().abs()
    }] {
        let mut g = started(sample1(), 500.0, 800.0);
        let seen = check_continuity(&mut g, stroke(800.0, 350.0, v).into_iter());
        assert_eq!(seen, [true; 4]);
        assert_eq!(g.step(800.0).position, 500.0);
    }
}

fn config(seed: u64) -> ProptestConfig {
    ProptestConfig {
        cases: 256,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(seed),
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config(0x00f1_1e6e))]
    /// Random positions, ratios, working directions and leader speeds: the follower is
    /// continuous in position and ratio (velocity) at every leader step, exactly geared in sync,
    /// and the stroke ends at SlaveStopPosition.
    #[test]
    fn continuity_holds_for_any_geometry(
        ratio in 0.1..3.0_f64,
        msp in -1000.0..1000.0_f64,
        ssp in -1000.0..1000.0_f64,
        engage in 10.0..200.0_f64,
        desync in -100.0..100.0_f64,
        release in 10.0..200.0_f64,
        slave_neg in any::<bool>(),
        master_neg in any::<bool>(),
        margin in 0.0..300.0_f64,
        overshoot in 1.0..300.0_f64,
        speed in 0.01..3.0_f64,
        wobble in 0.0..0.9_f64,
    ) {
        let ds = if slave_neg { -1.0 } else { 1.0 };
        let dm = if master_neg { -1.0 } else { 1.0 };
        let s = ds * dm;
        let p = FlyingGearParams {
            ratio,
            master_sync_position: msp,
            slave_sync_position: ssp,
            slave_desync_position: ssp + ds * desync,
            slave_stop_position: ssp + ds * desync - ds * release,
            default_slave_negative: false,
        };
        let l = 2.0 * engage / ratio;
        let from = msp - dm * (l + margin);
        let mut g = started(p, ssp - ds * engage, from);
        // Far enough past the sync point for the geared follower to pass the desync position.
        let m_desync = msp + ds * desync / (s * ratio);
        let turn = if dm * (m_desync - msp) > 0.0 { m_desync } else { msp } + dm * overshoot;
        let xs = stroke(from, turn, |k| speed * (1.0 - wobble * ((k as f64) * 0.07).sin()));
        // Back far enough for the release to end.
        let back = g.release_end() - dm * 1.0;
        let tail = (0..=1000).map(|k| from + (back - from) * f64::from(k) / 1000.0);
        let seen = check_continuity(&mut g, xs.into_iter().chain(tail));
        prop_assert_eq!(seen, [true; 4]);
        prop_assert_eq!(g.step(back).position, p.slave_stop_position);
    }
}

// --- on an axis ---------------------------------------------------------------------------

/// Leader at 800, follower at 500 (homed there), both standing.
fn pair() -> Pair {
    let mut p = Pair::new(AxisConfig::example(0.001), AxisConfig::example(0.001));
    p.leader
        .command(&Command::Home {
            mode: 0,
            position: 800.0,
        })
        .unwrap();
    p.follower
        .command(&Command::Home {
            mode: 0,
            position: 500.0,
        })
        .unwrap();
    p.step(2);
    p
}

fn flying(enable: bool, params: FlyingGearParams) -> Command {
    Command::FlyingGear {
        master: LEADER,
        enable,
        params,
    }
}

fn leader_to(p: &mut Pair, position: f64, v: f64, a: f64) {
    p.leader
        .command(&Command::MoveAbsolute {
            position,
            dynamics: dynamics(v, a, a, 100.0 * a),
            direction: Direction::Shortest,
        })
        .unwrap();
}

/// Steps `n` cycles checking the follower's setpoint from cycle to cycle: position moves by the
/// mean velocity times the cycle (to the leader's jerk-limited profile's rounding), the
/// velocity by at most `dv_max`. Returns the flags seen.
fn run_checked(p: &mut Pair, n: usize, dv_max: f64) -> u8 {
    let dt = 0.001;
    let mut flags = 0;
    let mut s0: AxisStatus = p.fs();
    for _ in 0..n {
        p.step(1);
        let s = p.fs();
        let x = p.lv();
        let dp = s.position_unwrapped - s0.position_unwrapped;
        assert!(
            (dp - 0.5 * (s.velocity + s0.velocity) * dt).abs() <= 0.5 * dv_max * dt + 1e-9,
            "position step {dp} vs velocities {} {} at leader {}",
            s0.velocity,
            s.velocity,
            x.p
        );
        assert!(
            (s.velocity - s0.velocity).abs() <= dv_max,
            "velocity step {} -> {} at leader {}",
            s0.velocity,
            s.velocity,
            x.p
        );
        if s.sync_status_word & sync_status::FLYING_IN_SYNC != 0 {
            assert!((s.position_unwrapped - (450.0 - (460.0 - x.p))).abs() <= 1e-9);
            assert_eq!(s.velocity, x.v);
        }
        flags |= s.sync_status_word;
        s0 = s;
    }
    flags
}

#[test]
fn sample_1_on_axes_at_constant_and_changing_leader_speed() {
    for (v, a) in [(100.0, 100_000.0), (150.0, 400.0)] {
        let mut p = pair();
        let id = p.f(flying(true, sample1())).unwrap();
        assert_eq!(p.fs().sync_job, Some((id, Instruction::FlyingGear)));
        // Enable TRUE again keeps the job.
        assert_eq!(p.f(flying(true, sample1())), Ok(id));
        leader_to(&mut p, 400.0, v, a);
        // Velocity steps: leader acceleration times the ratio, plus the ramp's curvature
        // (Ratio / 100 mm) times v² over one cycle.
        let dv = (a + v * v / 100.0) * 0.001 * 1.01 + 1e-9;
        let mut flags = run_checked(&mut p, 300, dv);
        assert_eq!(p.fs().position_unwrapped, 500.0);
        flags |= run_checked(&mut p, 4000, dv);
        assert!(p.has(id, JobEventKind::StartSync) && p.has(id, JobEventKind::InSync));
        leader_to(&mut p, 800.0, v, a);
        flags |= run_checked(&mut p, 8000, dv);
        assert_eq!(
            flags
                & (sync_status::FLYING_START_SYNC
                    | sync_status::FLYING_IN_SYNC
                    | sync_status::FLYING_ACTIVE),
            sync_status::FLYING_START_SYNC
                | sync_status::FLYING_IN_SYNC
                | sync_status::FLYING_ACTIVE
        );
        let s = p.fs();
        assert_eq!((s.position_unwrapped, s.velocity), (500.0, 0.0));
        assert_eq!(s.sync_status_word & sync_status::FLYING_ACTIVE, 0);
        // Enable FALSE ends the job (Done); the standing follower stays.
        assert_eq!(p.f(flying(false, sample1())), Ok(id));
        assert!(p.has(id, JobEventKind::Done));
        p.step(10);
        let s = p.fs();
        assert_eq!(
            (s.position_unwrapped, s.velocity, s.sync_job),
            (500.0, 0.0, None)
        );
    }
}

#[test]
fn refusals_on_an_axis_change_nothing() {
    let mut p = pair();
    let before = p.fs();
    let n = p.events.len();
    for (params, e) in [
        (
            FlyingGearParams {
                ratio: 0.0,
                ..sample1()
            },
            ErrorId::IllegalRatioNumerator,
        ),
        (
            FlyingGearParams {
                master_sync_position: f64::NAN,
                ..sample1()
            },
            ErrorId::IllegalMasterSyncPosition,
        ),
        (
            FlyingGearParams {
                slave_stop_position: 400.0,
                ..sample1()
            },
            ErrorId::IllegalPosition,
        ),
    ] {
        assert_eq!(p.f(flying(true, params)), Err(e));
        assert_eq!(p.fs(), before);
        assert_eq!(p.events.len(), n);
    }
    // The master already past 560: accepted, then ended at the first leading value with
    // 16#8026; the follower never moved.
    p.leader
        .command(&Command::Home {
            mode: 0,
            position: 540.0,
        })
        .unwrap();
    p.step(1);
    let id = p.f(flying(true, sample1())).unwrap();
    p.step(3);
    assert!(p.has(id, JobEventKind::Error(ErrorId::IllegalMasterStartDistance)));
    let s = p.fs();
    assert_eq!(
        (s.position_unwrapped, s.velocity, s.sync_job),
        (500.0, 0.0, None)
    );
}

#[test]
fn enable_false_while_geared_continues_with_the_velocity() {
    let mut p = pair();
    let id = p.f(flying(true, sample1())).unwrap();
    leader_to(&mut p, 0.0, 100.0, 100_000.0);
    p.until(id, JobEventKind::InSync, 5000);
    p.step(100);
    let v = p.fs().velocity;
    assert!((v + 100.0).abs() < 1e-9, "{v}");
    p.f(flying(false, sample1())).unwrap();
    assert!(p.has(id, JobEventKind::Done));
    p.step(5);
    let s = p.fs();
    assert_eq!(s.sync_job, None);
    assert!((s.velocity - v).abs() < 1e-9, "{}", s.velocity);
}

#[test]
fn a_motion_command_aborts_it_and_gear_out_ends_it_once_coupling() {
    // A positioning of the follower aborts the flying gear (override table 2, as MC_GearIn).
    let mut p = pair();
    let id = p.f(flying(true, sample1())).unwrap();
    p.step(5);
    p.f(Command::MoveAbsolute {
        position: 520.0,
        dynamics: dynamics(100.0, 1000.0, 1000.0, 10_000.0),
        direction: Direction::Shortest,
    })
    .unwrap();
    assert!(p.has(id, JobEventKind::CommandAborted));
    assert_eq!(p.fs().sync_job.map(|j| j.1), None);
    // MC_GearOut: refused while the follower waits, ends the coupling once it engages.
    let mut p = pair();
    let id = p.f(flying(true, sample1())).unwrap();
    p.step(5);
    assert_eq!(p.f(Command::GearOut), Err(ErrorId::NoSynchronousOperation));
    leader_to(&mut p, 400.0, 100.0, 100_000.0);
    p.until(id, JobEventKind::StartSync, 5000);
    p.step(10);
    p.f(Command::GearOut).unwrap();
    assert!(p.has(id, JobEventKind::CommandAborted));
    assert_eq!(p.fs().sync_job, None);
}
