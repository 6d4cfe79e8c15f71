//! Camming: MC_CamIn with offsets, scalings, application modes, the three synchronization
//! references, MC_CamOut and the change to a pending cam at the end of a cycle (S7-1500T Motion
//! Control V4.0 function manual, 3.5.7 'Camming' and 10.12.5
//! 'MC_CamIn V4'). Exact synchronism: once InSync the follower equals the cam function of the
//! leading value in every cycle.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use std::sync::Arc;
use tandem_motion::cam::{Cam, CamDefinition, Interpolation, MotionLaw, SegmentDef};
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::axis::{
    ApplicationMode, AxisConfig, AxisState, Command, SyncDirection, SyncProfileReference,
    VelocityDirection,
};
use tandem_motion::objects::job::JobEventKind;
use tandem_testkit::rig::{dynamics, Pair, LEADER};

/// Rise 0 -> 100 over 0..180 and return over 180..360 (5th-degree polynomial laws): cyclic.
fn rise_return() -> Arc<Cam> {
    let def = CamDefinition {
        points: vec![],
        segments: vec![
            SegmentDef::Law {
                law: MotionLaw::Poly5,
                x0: 0.0,
                x1: 180.0,
                y0: 0.0,
                y1: 100.0,
            },
            SegmentDef::Law {
                law: MotionLaw::Poly5,
                x0: 180.0,
                x1: 360.0,
                y0: 100.0,
                y1: 0.0,
            },
        ],
        interpolation: Interpolation::CubicSpline,
        boundary: Default::default(),
    };
    Arc::new(Cam::interpolate(&def).unwrap())
}

/// Rise 0 -> 100 over 0..360 (7th-degree polynomial): for appending and once.
fn rise() -> Arc<Cam> {
    let def = CamDefinition {
        points: vec![],
        segments: vec![SegmentDef::Law {
            law: MotionLaw::Poly7,
            x0: 0.0,
            x1: 360.0,
            y0: 0.0,
            y1: 100.0,
        }],
        interpolation: Interpolation::CubicSpline,
        boundary: Default::default(),
    };
    Arc::new(Cam::interpolate(&def).unwrap())
}

struct CamIn {
    mo: f64,
    so: f64,
    ms: f64,
    ss: f64,
    msp: f64,
    reference: SyncProfileReference,
    msd: f64,
    mode: ApplicationMode,
}

impl CamIn {
    fn direct(mode: ApplicationMode) -> Self {
        Self {
            mo: 0.0,
            so: 0.0,
            ms: 1.0,
            ss: 1.0,
            msp: 0.0,
            reference: SyncProfileReference::Direct,
            msd: 1.0,
            mode,
        }
    }
    fn command(&self) -> Command {
        Command::CamIn {
            master: LEADER,
            cam: 1,
            master_offset: self.mo,
            slave_offset: self.so,
            master_scaling: self.ms,
            slave_scaling: self.ss,
            master_sync_position: self.msp,
            sync_profile_reference: self.reference,
            master_start_distance: self.msd,
            dynamics: dynamics(1000.0, 20000.0, 20000.0, 1e6),
            application_mode: self.mode,
            sync_direction: SyncDirection::Shortest,
        }
    }
}

fn leader_runs(p: &mut Pair, v: f64) {
    p.leader
        .command(&Command::MoveVelocity {
            dynamics: dynamics(v, 5000.0, 5000.0, 0.0),
            direction: VelocityDirection::Positive,
            current: false,
            position_controlled: true,
        })
        .unwrap();
}

fn pair() -> Pair {
    let mut fc = AxisConfig::example(0.001);
    fc.limits.max_velocity = 5000.0;
    fc.following_error.enable = false;
    Pair::new(AxisConfig::example(0.001), fc)
}

#[test]
fn cam_in_direct_cyclic_follows_the_cam_exactly() {
    let mut p = pair();
    let cam = rise_return();
    leader_runs(&mut p, 200.0);
    p.step(100);
    p.follower.provide_cam(1, Arc::clone(&cam));
    let c = CamIn {
        ss: 2.0,
        so: 5.0,
        ms: 1.5,
        ..CamIn::direct(ApplicationMode::Cyclic)
    };
    let id = p.f(c.command()).unwrap();
    p.step(1);
    assert!(p.has(id, JobEventKind::InSync), "direct: InSync at once");
    assert_eq!(p.fs().state, AxisState::SynchronizedMotion);
    assert_eq!(p.fs().sync_function, 3);
    // The sync point (cam start) is where the leader was; the cam value there is where the
    // follower was: y = 2 f((x - x0) / 1.5 mod 360) + y0 - 2 f(0).
    let (x_first, first) = (p.lv().p, p.fs().position_unwrapped);
    let f = |x: f64| cam.following(x.rem_euclid(540.0) / 1.5).unwrap().value;
    let base = first - 2.0 * f(0.0);
    for _ in 0..8000 {
        p.step(1);
        let y = p.fs().position_unwrapped;
        let x = p.lv().p - x_first;
        assert!(
            (y - (base + 2.0 * f(x))).abs() < 1e-9,
            "x {x}: {y} vs {}",
            base + 2.0 * f(x)
        );
    }
    let ends = p
        .events
        .iter()
        .filter(|e| e.job == id && e.kind == JobEventKind::EndOfProfile)
        .count();
    // 8 s at 200/s = 1600 of leader travel, cycles of 540: two ends passed.
    assert_eq!(ends, 2);
}

#[test]
fn cam_in_appending_accumulates_the_rise() {
    let mut p = pair();
    let cam = rise();
    leader_runs(&mut p, 360.0);
    p.step(100);
    p.follower.provide_cam(1, Arc::clone(&cam));
    let id = p
        .f(CamIn::direct(ApplicationMode::CyclicAppending).command())
        .unwrap();
    p.step(1);
    let (x0, y0) = (p.lv().p, p.fs().position_unwrapped);
    for _ in 0..3500 {
        p.step(1);
        let x = p.lv().p - x0;
        let n = (x / 360.0).floor();
        let expect = y0 + 100.0 * n + cam.following(x - 360.0 * n).unwrap().value;
        assert!((p.fs().position_unwrapped - expect).abs() < 1e-9);
    }
    assert!(p.has(id, JobEventKind::EndOfProfile));
}

#[test]
fn cam_in_once_ends_at_the_cam_end() {
    let mut p = pair();
    leader_runs(&mut p, 300.0);
    p.step(100);
    p.follower.provide_cam(1, rise());
    let id = p.f(CamIn::direct(ApplicationMode::Once).command()).unwrap();
    p.step(1);
    let y0 = p.fs().position_unwrapped;
    p.until(id, JobEventKind::Done, 3000);
    assert!(p.has(id, JobEventKind::EndOfProfile));
    p.step(50);
    // The cam ends at rest: the follower stands at the cam's end value.
    assert!((p.fs().position_unwrapped - (y0 + 100.0)).abs() < 1e-6);
    assert_eq!(p.fs().velocity, 0.0);
    assert_eq!(p.fs().state, AxisState::Standstill);
}

#[test]
fn cam_in_synchronizes_by_master_start_distance_exactly_at_the_sync_position() {
    // MasterOffset 1000, MasterSyncPosition 90 (cam argument 90): synchronous when the leader
    // passes 1090, with the follower at 10 * f(90) + 7.
    let mut p = pair();
    let cam = rise_return();
    leader_runs(&mut p, 150.0);
    p.follower.provide_cam(1, Arc::clone(&cam));
    let c = CamIn {
        mo: 1000.0,
        so: 7.0,
        ms: 1.0,
        ss: 10.0,
        msp: 90.0,
        reference: SyncProfileReference::MasterStartDistance,
        msd: 300.0,
        mode: ApplicationMode::Cyclic,
    };
    let id = p.f(c.command()).unwrap();
    let mut checked = 0;
    for _ in 0..15_000 {
        p.step(1);
        let x = p.lv().p;
        if x >= 790.0 && !p.has(id, JobEventKind::StartSync) {
            panic!("no StartSync at {x}");
        }
        if x >= 1090.0 {
            assert!(p.has(id, JobEventKind::InSync));
            let u = (x - 1000.0).rem_euclid(360.0);
            let expect = 10.0 * cam.following(u).unwrap().value + 7.0;
            assert!((p.fs().position_unwrapped - expect).abs() < 1e-9, "x {x}");
            checked += 1;
        }
        if x > 2000.0 {
            break;
        }
    }
    assert!(checked > 1000);
}

#[test]
fn a_pending_cam_takes_over_at_the_end_of_the_cycle() {
    let mut p = pair();
    leader_runs(&mut p, 360.0);
    p.step(100);
    p.follower.provide_cam(1, rise());
    let a = p
        .f(CamIn::direct(ApplicationMode::CyclicAppending).command())
        .unwrap();
    p.step(200);
    p.follower.provide_cam(1, rise_return());
    let b = p
        .f(CamIn::direct(ApplicationMode::Cyclic).command())
        .unwrap();
    assert!(
        !p.has(a, JobEventKind::CommandAborted),
        "pending: the active cam goes on"
    );
    let mut prev = p.fs();
    let mut switched = false;
    for _ in 0..2000 {
        p.step(1);
        let s = p.fs();
        // Continuous: no jump in position at the change.
        assert!(
            (s.position_unwrapped - prev.position_unwrapped).abs() < 1.0,
            "{prev:?} -> {s:?}"
        );
        prev = s;
        if p.has(b, JobEventKind::InSync) {
            switched = true;
            assert!(p.has(a, JobEventKind::CommandAborted));
            break;
        }
    }
    assert!(switched);
}

#[test]
fn cam_in_checks_its_inputs() {
    let mut p = pair();
    // No cam provided for the id.
    assert_eq!(
        p.f(CamIn::direct(ApplicationMode::Cyclic).command()),
        Err(ErrorId::IllegalObject)
    );
    p.follower.provide_cam(1, rise());
    let bad = |c: CamIn| c.command();
    assert_eq!(
        p.f(bad(CamIn {
            msp: 400.0,
            ..CamIn::direct(ApplicationMode::Cyclic)
        })),
        Err(ErrorId::SyncPositionOutsideCam)
    );
    assert_eq!(
        p.f(bad(CamIn {
            ms: 0.0,
            ..CamIn::direct(ApplicationMode::Cyclic)
        })),
        Err(ErrorId::IllegalMasterScaling)
    );
    assert_eq!(
        p.f(bad(CamIn {
            ss: 0.0,
            ..CamIn::direct(ApplicationMode::Cyclic)
        })),
        Err(ErrorId::IllegalSlaveScaling)
    );
    assert_eq!(p.f(Command::CamOut), Err(ErrorId::NoSynchronousOperation));
    leader_runs(&mut p, 100.0);
    let id = p
        .f(CamIn::direct(ApplicationMode::Cyclic).command())
        .unwrap();
    p.until(id, JobEventKind::InSync, 10);
    assert_eq!(p.f(Command::GearOut), Err(ErrorId::NoSynchronousOperation));
    assert_eq!(
        p.f(Command::Phasing {
            phase_shift: 1.0,
            absolute: false,
            dynamics: Dynamics::DEFAULT
        }),
        Err(ErrorId::CammingActive)
    );
    assert_eq!(
        p.f(Command::Home {
            mode: 0,
            position: 0.0
        }),
        Err(ErrorId::SyncJobActive)
    );
    let out = p.f(Command::CamOut).unwrap();
    assert!(p.has(out, JobEventKind::Done));
    assert!(p.has(id, JobEventKind::CommandAborted));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, failure_persistence: None, rng_seed: proptest::test_runner::RngSeed::Fixed(0xca00_0017), ..ProptestConfig::default() })]

    /// Exact synchronism over random scalings, offsets, modes and leader speeds.
    #[test]
    fn camming_is_exact(
        ms in 0.25f64..4.0, ss in prop_oneof![-5.0f64..-0.2, 0.2f64..5.0], so in -100.0f64..100.0,
        msp in 0.0f64..360.0, v in 20.0f64..600.0, appending in any::<bool>(),
    ) {
        let mut p = pair();
        let cam = if appending { rise() } else { rise_return() };
        leader_runs(&mut p, v);
        p.step(50);
        p.follower.provide_cam(1, Arc::clone(&cam));
        let mode = if appending { ApplicationMode::CyclicAppending } else { ApplicationMode::Cyclic };
        let c = CamIn { ms, ss, so, msp, ..CamIn::direct(mode) };
        let id = p.f(c.command()).unwrap();
        p.step(1);
        prop_assert!(p.has(id, JobEventKind::InSync));
        let (x0, y0) = (p.lv().p, p.fs().position_unwrapped);
        let f0 = cam.following(msp).unwrap().value;
        for _ in 0..3000 {
            p.step(1);
            let t = msp + (p.lv().p - x0) / ms;
            let n = (t / 360.0).floor();
            let add = if appending { n * 100.0 * ss } else { 0.0 };
            let expect = y0 + ss * (cam.following(t - 360.0 * n).unwrap().value - f0) + add;
            prop_assert!((p.fs().position_unwrapped - expect).abs() <= 1e-9 * (1.0 + expect.abs()), "{} vs {}", p.fs().position_unwrapped, expect);
        }
    }
}

/// A cam with f(50) = 70 (a line 0 -> 140 over 0..100).
fn line_cam() -> Arc<Cam> {
    let def = CamDefinition {
        points: vec![],
        segments: vec![SegmentDef::line(0.0, 0.0, 100.0, 140.0)],
        interpolation: Interpolation::Linear,
        boundary: Default::default(),
    };
    Arc::new(Cam::interpolate(&def).unwrap())
}

#[test]
fn reference_examples_slave_offset_and_sync_window() {
    // S7-Technology V4.1 function manual, 4.7.4 'Synchronization' example 7 (in S7-1500
    // terms: SlaveOffset): the cam gives 70 at master 50; with a slave offset of 80 the follower is
    // synchronous at 150 when the master is at 50.
    let mut p = pair();
    leader_runs(&mut p, 50.0);
    p.follower.provide_cam(1, line_cam());
    let c = CamIn {
        so: 80.0,
        msp: 50.0,
        reference: SyncProfileReference::MasterStartDistance,
        msd: 30.0,
        ..CamIn::direct(ApplicationMode::Once)
    };
    let id = p.f(c.command()).unwrap();
    // S7-Technology V4.1 function manual, 4.7.4 'Synchronization' examples 4/5 (S7-1500
    // terms): synchronizing over the 30 before the sync position, i.e. while the master moves 20 ->
    // 50.
    let mut started = None;
    for _ in 0..3000 {
        p.step(1);
        let x = p.lv().p;
        if started.is_none() && p.has(id, JobEventKind::StartSync) {
            started = Some(x);
        }
        if p.has(id, JobEventKind::InSync) {
            assert!((50.0..50.06).contains(&x), "InSync at {x}");
            let expect = 1.4 * x + 80.0;
            assert!((p.fs().position_unwrapped - expect).abs() < 1e-9);
            assert!((1.4f64 * 50.0 + 80.0 - 150.0).abs() < 1e-12);
            break;
        }
    }
    let s = started.unwrap();
    assert!((20.0..20.06).contains(&s), "StartSync at {s}");
}
