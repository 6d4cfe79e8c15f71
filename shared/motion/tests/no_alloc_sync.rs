//! The cyclic path of synchronous operation does not allocate: a counting global allocator,
//! armed only on the test thread, counts every allocation while three leader/follower pairs run
//! 10,000 cycles of 1 ms with a script of commands and with their events drained every cycle:
//!
//! * (a) MC_GearIn (synchronizing, then InGear), an MC_PhasingRelative while in gear, a change
//!   of the leader's velocity, a second MC_GearIn with another ratio and a second phasing;
//! * (b) MC_CamIn cyclic appending on a cubic-spline cam, then a second MC_CamIn (its cam
//!   handed over with `provide_cam` inside the armed window) that takes over at the end of the
//!   cam cycle, MC_CamOut, and an MC_CamIn synchronizing over a master start distance;
//! * (c) MC_GearInPos pending, then starting (StartSync, InSync), and a second MC_GearInPos
//!   (dynamics reference) pending under the first, then taking over.
//!
//! The leading values come from real leader axes stepped in the loop (leader first, then its
//! setpoint handed to the follower). The cams are interpolated and put into `Arc`s before the
//! window; inside it only `Arc::clone` is used, which does not allocate.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::sync::Arc;

use tandem_motion::cam::{
    BoundaryCondition, Cam, CamDefinition, Interpolation, MotionLaw, SegmentDef,
};
use tandem_motion::catalog::alarm::status_bit;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::axis::{
    ApplicationMode, Axis, AxisConfig, AxisKind, AxisState, Command, StartMode, StopMode,
    SyncDirection, SyncProfileReference, VelocityDirection,
};
use tandem_motion::objects::job::{JobEvent, JobEventKind, JobId};
use tandem_motion::objects::leading::LeaderId;

use tandem_testkit::counting::{arm, disarm};

tandem_testkit::counting_allocator!();

const MS: i64 = 1_000_000;
const CYCLES: u32 = 10_000;
/// Cycles stepped before the window (the leaders reach their velocity).
const PRE: i64 = 300;
/// Job events kept per pair (fixed storage: nothing in the window may allocate).
const LOG: usize = 256;

fn dynamics(v: f64, a: f64, d: f64, j: f64) -> Dynamics {
    Dynamics {
        velocity: v,
        acceleration: a,
        deceleration: d,
        jerk: j,
    }
}

fn power_on() -> Command {
    Command::Power {
        enable: true,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Emergency,
    }
}

fn home() -> Command {
    Command::Home {
        mode: 0,
        position: 0.0,
    }
}

fn leader_velocity(v: f64) -> Command {
    Command::MoveVelocity {
        dynamics: dynamics(v, 2000.0, 2000.0, 40_000.0),
        direction: VelocityDirection::Positive,
        current: false,
        position_controlled: true,
    }
}

fn gear_in(master: LeaderId, num: i32, den: i32) -> Command {
    Command::GearIn {
        master,
        ratio_numerator: num,
        ratio_denominator: den,
        dynamics: dynamics(-1.0, 1000.0, 1000.0, 20_000.0),
    }
}

fn phasing_relative(shift: f64) -> Command {
    Command::Phasing {
        phase_shift: shift,
        absolute: false,
        dynamics: dynamics(50.0, 500.0, 500.0, 10_000.0),
    }
}

fn gear_in_pos(
    master: LeaderId,
    num: i32,
    (msp, ssp): (f64, f64),
    reference: SyncProfileReference,
    msd: f64,
) -> Command {
    Command::GearInPos {
        master,
        ratio_numerator: num,
        ratio_denominator: 1,
        master_sync_position: msp,
        slave_sync_position: ssp,
        sync_profile_reference: reference,
        master_start_distance: msd,
        dynamics: dynamics(400.0, 4000.0, 4000.0, 100_000.0),
        sync_direction: SyncDirection::Shortest,
    }
}

/// MC_CamIn on `cam` with scalings 1, the cam start as sync position.
fn cam_in(
    master: LeaderId,
    cam: u32,
    mode: ApplicationMode,
    reference: SyncProfileReference,
    (mo, so): (f64, f64),
) -> Command {
    Command::CamIn {
        master,
        cam,
        master_offset: mo,
        slave_offset: so,
        master_scaling: 1.0,
        slave_scaling: 1.0,
        master_sync_position: 0.0,
        sync_profile_reference: reference,
        master_start_distance: 300.0,
        dynamics: dynamics(1000.0, 4000.0, 4000.0, 80_000.0),
        application_mode: mode,
        sync_direction: SyncDirection::Shortest,
    }
}

/// A cubic-spline cam through 361 points over 0..360 that rises by 100 per cycle with a
/// superimposed wave (equal slopes at both ends: for cyclic appending).
fn spline_cam() -> Arc<Cam> {
    let points = (0..=360)
        .map(|i| {
            let x = f64::from(i);
            let w = std::f64::consts::TAU * x / 360.0;
            (x, 100.0 * x / 360.0 + 8.0 * w.sin() + 3.0 * (3.0 * w).sin())
        })
        .collect();
    let def = CamDefinition {
        points,
        segments: vec![],
        interpolation: Interpolation::CubicSpline,
        boundary: BoundaryCondition::EqualFirstDerivative,
    };
    Arc::new(Cam::interpolate(&def).unwrap())
}

/// Two rise/return pairs of 7th-degree polynomial laws over 0..360: cyclic (0 at both ends).
fn poly_cam() -> Arc<Cam> {
    let law = |x0: f64, y0: f64, y1: f64| SegmentDef::Law {
        law: MotionLaw::Poly7,
        x0,
        x1: x0 + 90.0,
        y0,
        y1,
    };
    let def = CamDefinition {
        points: vec![],
        segments: vec![
            law(0.0, 0.0, 30.0),
            law(90.0, 30.0, 0.0),
            law(180.0, 0.0, 20.0),
            law(270.0, 20.0, 0.0),
        ],
        interpolation: Interpolation::CubicSpline,
        boundary: BoundaryCondition::None,
    };
    Arc::new(Cam::interpolate(&def).unwrap())
}

/// A leader (positioning axis) and a synchronous follower, both homed and enabled, the leader
/// running at `v`; everything the window records lives in fixed-size storage.
struct Pair {
    id: LeaderId,
    leader: Axis,
    follower: Axis,
    /// Cycles stepped so far (the time base).
    k: i64,
    /// Follower job events with the window cycle they came in.
    log: [Option<(u32, JobEvent)>; LOG],
    n_log: usize,
    commands: u32,
    /// The first rejections: (window cycle, error).
    rejected: [Option<(u32, ErrorId)>; 8],
    n_rejected: usize,
    max_abs_velocity: f64,
}

impl Pair {
    fn new(id: LeaderId, v: f64) -> Self {
        let mut fc = AxisConfig::example(0.001);
        fc.kind = AxisKind::Synchronous;
        fc.following_error.enable = false;
        fc.limits.max_velocity = 5000.0;
        let mut p = Self {
            id,
            leader: Axis::new(AxisConfig::example(0.001)).unwrap(),
            follower: Axis::new(fc).unwrap(),
            k: 0,
            log: [None; LOG],
            n_log: 0,
            commands: 0,
            rejected: [None; 8],
            n_rejected: 0,
            max_abs_velocity: 0.0,
        };
        p.step_pre();
        for a in [&mut p.leader, &mut p.follower] {
            a.command(&power_on()).unwrap();
            a.command(&home()).unwrap();
        }
        p.step_pre();
        p.leader.command(&leader_velocity(v)).unwrap();
        while p.k < PRE {
            p.step_pre();
        }
        while p.follower.pop_event().is_some() {}
        assert!((p.leader.status().velocity - v).abs() < 1e-9);
        assert_eq!(p.follower.status().state, AxisState::Standstill);
        p
    }

    /// One cycle before the window (nothing recorded).
    fn step_pre(&mut self) {
        self.step();
        while self.follower.pop_event().is_some() {}
    }

    /// Leader first, then its setpoint as the follower's leading value, then the follower.
    fn step(&mut self) {
        let t = self.k * MS;
        self.leader.step(t);
        while self.leader.pop_event().is_some() {}
        self.follower
            .set_leading_value(self.id, Some(self.leader.setpoint_leading_value()));
        self.follower.step(t);
        self.k += 1;
    }

    fn drain(&mut self, k: u32) {
        while let Some(e) = self.follower.pop_event() {
            if self.n_log < LOG {
                self.log[self.n_log] = Some((k, e));
            }
            self.n_log += 1;
        }
    }

    /// A follower command in window cycle `k`; `None` (and recorded) when rejected.
    fn command(&mut self, k: u32, c: &Command) -> Option<JobId> {
        self.commands += 1;
        let r = self.follower.command(c);
        self.drain(k);
        match r {
            Ok(id) => Some(id),
            Err(e) => {
                if self.n_rejected < self.rejected.len() {
                    self.rejected[self.n_rejected] = Some((k, e));
                }
                self.n_rejected += 1;
                None
            }
        }
    }

    fn cycle(&mut self, k: u32) {
        self.step();
        self.drain(k);
        self.max_abs_velocity = self
            .max_abs_velocity
            .max(self.follower.status().velocity.abs());
    }

    fn events(&self) -> impl Iterator<Item = (u32, JobEvent)> + '_ {
        self.log.iter().flatten().copied()
    }

    /// Window cycle of the first `kind` event of `job`.
    fn first(&self, job: Option<JobId>, kind: JobEventKind) -> Option<u32> {
        let job = job?;
        self.events()
            .find(|(_, e)| e.job == job && e.kind == kind)
            .map(|(k, _)| k)
    }

    fn count(&self, job: Option<JobId>, kind: JobEventKind) -> usize {
        self.events()
            .filter(|(_, e)| Some(e.job) == job && e.kind == kind)
            .count()
    }

    fn report(&self, name: &str) {
        println!(
            "{name}: {} commands, rejected {:?}, {} events (log full: {}), follower |v| max \
             {:.1}, state {:?}, alarms {:?}, dropped events {}",
            self.commands,
            &self.rejected[..self.n_rejected.min(self.rejected.len())],
            self.n_log,
            self.n_log > LOG,
            self.max_abs_velocity,
            self.follower.status().state,
            self.follower
                .alarms()
                .chain(self.leader.alarms())
                .map(|a| a.id)
                .collect::<Vec<_>>(),
            self.follower.dropped_events(),
        );
        for (k, e) in self.events() {
            if e.kind != JobEventKind::Busy {
                println!("  {k:5}: job {} {:?} {:?}", e.job, e.instruction, e.kind);
            }
        }
    }

    /// Common end checks: every command accepted, nothing lost, no alarm.
    fn check(&self) {
        assert_eq!(
            self.n_rejected,
            0,
            "rejected commands: {:?}",
            &self.rejected[..self.n_rejected.min(self.rejected.len())]
        );
        assert!(self.n_log <= LOG, "event log overflow");
        assert_eq!(self.follower.dropped_events(), 0);
        assert!(self.follower.alarms().next().is_none());
        assert!(self.leader.alarms().next().is_none());
    }
}

#[test]
fn synchronous_operation_does_not_allocate() {
    // The counter works: an allocation on the armed thread is counted.
    arm();
    let probe = std::hint::black_box(Box::new(7u64));
    drop(probe);
    let (probe_allocs, _) = disarm();
    assert_eq!(probe_allocs, 1, "the counting allocator does not count");

    // Everything that allocates happens here: axes, cams, the Arcs.
    let spline = spline_cam();
    let poly = poly_cam();
    let mut a = Pair::new(1, 100.0);
    let mut b = Pair::new(2, 360.0);
    let mut c = Pair::new(3, 150.0);

    // Job ids and window-computed inputs (plain Copy values).
    let (mut ga1, mut ga2, mut pa1, mut pa2) = (None, None, None, None);
    let (mut cb1, mut cb2, mut out_b, mut cb3) = (None, None, None, None);
    let (mut gc1, mut gc2) = (None, None);

    arm();
    for k in 0..CYCLES {
        // (a) MC_GearIn, phasing, leader change, a second MC_GearIn, phasing.
        match k {
            100 => ga1 = a.command(k, &gear_in(a.id, 3, 2)),
            1500 => pa1 = a.command(k, &phasing_relative(20.0)),
            3000 => {
                a.leader.command(&leader_velocity(200.0)).unwrap();
            }
            7000 => ga2 = a.command(k, &gear_in(a.id, -1, 1)),
            8500 => pa2 = a.command(k, &phasing_relative(-15.0)),
            _ => {}
        }
        a.cycle(k);

        // (b) MC_CamIn appending on the spline cam, a cam change at the end of a cycle,
        // MC_CamOut and an MC_CamIn over a master start distance.
        match k {
            100 => {
                b.follower.provide_cam(1, Arc::clone(&spline));
                cb1 = b.command(
                    k,
                    &cam_in(
                        b.id,
                        1,
                        ApplicationMode::CyclicAppending,
                        SyncProfileReference::Direct,
                        (0.0, 0.0),
                    ),
                );
            }
            5000 => {
                b.follower.provide_cam(2, Arc::clone(&poly));
                cb2 = b.command(
                    k,
                    &cam_in(
                        b.id,
                        2,
                        ApplicationMode::Cyclic,
                        SyncProfileReference::Direct,
                        (0.0, 0.0),
                    ),
                );
            }
            7500 => out_b = b.command(k, &Command::CamOut),
            7501 => {
                // Synchronous where the leader will be 400 further on; the follower there
                // about where its current velocity takes it.
                let x = b.leader.status().position_unwrapped;
                let f = *b.follower.status();
                let so = f.position_unwrapped + f.velocity * 400.0 / 360.0;
                b.follower.provide_cam(3, Arc::clone(&poly));
                cb3 = b.command(
                    k,
                    &cam_in(
                        b.id,
                        3,
                        ApplicationMode::Cyclic,
                        SyncProfileReference::MasterStartDistance,
                        (x + 400.0, so),
                    ),
                );
            }
            _ => {}
        }
        b.cycle(k);

        // (c) MC_GearInPos pending then starting; a second one pending under it, then
        // taking over.
        match k {
            100 => {
                gc1 = c.command(
                    k,
                    &gear_in_pos(
                        c.id,
                        1,
                        (600.0, 50.0),
                        SyncProfileReference::MasterStartDistance,
                        200.0,
                    ),
                );
            }
            4500 => {
                gc2 = c.command(
                    k,
                    &gear_in_pos(
                        c.id,
                        2,
                        (1300.0, 800.0),
                        SyncProfileReference::Dynamics,
                        1.0,
                    ),
                );
            }
            _ => {}
        }
        c.cycle(k);
    }
    let (allocs, deallocs) = disarm();

    println!(
        "armed window: {CYCLES} cycles x 3 leader/follower pairs: {allocs} allocations, \
         {deallocs} deallocations"
    );
    a.report("(a) GearIn + phasing");
    b.report("(b) CamIn + cam change");
    c.report("(c) GearInPos");

    assert_eq!(
        allocs, 0,
        "the synchronous cyclic path allocated {allocs} times"
    );

    // The script really exercised the followers (otherwise zero allocations proves little).
    use JobEventKind::{CommandAborted, Done, EndOfProfile, InGear, InSync, StartSync};
    for p in [&a, &b, &c] {
        p.check();
    }

    // (a): both gears synchronized in the window, the first one was replaced by the second,
    // both phasings ran to their end while in gear.
    let in_gear_1 = a.first(ga1, InGear).expect("GearIn 1 not in gear");
    assert!(in_gear_1 > 100);
    assert!(a.first(pa1, Done).is_some_and(|k| k > in_gear_1));
    assert!(a.first(ga1, CommandAborted).is_some_and(|k| k == 7000));
    let in_gear_2 = a.first(ga2, InGear).expect("GearIn 2 not in gear");
    assert!(in_gear_2 > 7000 && in_gear_2 < 8500);
    assert!(a.first(pa2, Done).is_some());
    let s = a.follower.status();
    assert_eq!(s.state, AxisState::SynchronizedMotion);
    assert!(s.has(status_bit::SYNCHRONOUS));
    assert!((s.velocity + 200.0).abs() < 1e-9, "{}", s.velocity);

    // (b): the appending cam ran several cycles; the second cam took over at the end of a
    // cycle (not at once) and ran to its ends; MC_CamOut, then the third cam synchronized.
    assert_eq!(b.first(cb1, InSync), Some(100));
    assert!(b.count(cb1, EndOfProfile) >= 4);
    let change = b
        .first(cb2, InSync)
        .expect("the pending cam never took over");
    assert!(change > 5000 && change <= 6002, "{change}");
    assert_eq!(b.first(cb1, CommandAborted), Some(change));
    assert!(b.count(cb2, EndOfProfile) >= 2);
    assert!(b.first(out_b, Done).is_some());
    assert_eq!(b.first(cb2, CommandAborted), Some(7500));
    let start3 = b.first(cb3, StartSync).expect("CamIn 3 never started");
    let sync3 = b.first(cb3, InSync).expect("CamIn 3 never synchronous");
    assert!(7501 < start3 && start3 < sync3);
    assert!(b.count(cb3, EndOfProfile) >= 1);
    let s = b.follower.status();
    assert_eq!(s.state, AxisState::SynchronizedMotion);
    assert!(s.has(status_bit::SYNCHRONOUS));
    assert_eq!(s.sync_function, 3);

    // (c): the first GearInPos waited, started and synchronized; the second waited under it,
    // then took over and synchronized.
    let start1 = c.first(gc1, StartSync).expect("GearInPos 1 never started");
    let sync1 = c.first(gc1, InSync).expect("GearInPos 1 never synchronous");
    assert!(1000 < start1 && start1 < sync1 && sync1 < 4500);
    let start2 = c.first(gc2, StartSync).expect("GearInPos 2 never started");
    let sync2 = c.first(gc2, InSync).expect("GearInPos 2 never synchronous");
    assert!(4500 < start2 && start2 < sync2);
    assert_eq!(c.first(gc1, CommandAborted), Some(start2));
    let s = c.follower.status();
    assert_eq!(s.state, AxisState::SynchronizedMotion);
    assert!(s.has(status_bit::SYNCHRONOUS));
    assert!((s.velocity - 300.0).abs() < 1e-9, "{}", s.velocity);
}
