//! Buffered and blended moves (PLCopen Motion Control Part 1 'BufferMode'; S7-Technology
//! `Mode` 1 append and 2 blend of MC_MoveAbsolute / MC_MoveRelative, MC_MoveAdditive): the
//! S7-Technology examples with their numbers, the seam velocity of every blending variant,
//! what a new job does to queued ones, refusals with their ErrorIDs that change nothing, and
//! property tests over random move sequences.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::axis::{
    AxisConfig, BufferMode, BufferedMotion, Command, Direction, VelocityDirection,
    JOB_QUEUE_CAPACITY,
};
use tandem_motion::objects::job::{JobEventKind, JobId};
use tandem_testkit::rig::{dynamics, Rig, LEADER};

/// The S7-Technology examples: Acceleration = Deceleration = 10, trapezoidal.
fn s7(v: f64) -> Dynamics {
    dynamics(v, 10.0, 10.0, 0.0)
}

/// An enabled axis homed at 0.
fn homed() -> Rig {
    let mut r = Rig::enabled(AxisConfig::example(0.001));
    let h = r
        .cmd(Command::Home {
            mode: 0,
            position: 0.0,
        })
        .unwrap();
    r.until(h, JobEventKind::Done, 10);
    r
}

fn abs(position: f64, d: Dynamics) -> BufferedMotion {
    BufferedMotion::MoveAbsolute {
        position,
        dynamics: d,
        direction: Direction::Shortest,
    }
}

fn rel(distance: f64, d: Dynamics) -> BufferedMotion {
    BufferedMotion::MoveRelative {
        distance,
        dynamics: d,
    }
}

fn buffered(motion: BufferedMotion, buffer_mode: BufferMode) -> Command {
    Command::Buffered {
        motion,
        buffer_mode,
    }
}

/// The time (ns) of `job`'s `kind` event.
fn at(r: &Rig, job: JobId, kind: JobEventKind) -> i64 {
    r.events
        .iter()
        .find(|e| e.job == job && e.kind == kind)
        .map(|e| e.time_ns)
        .unwrap_or_else(|| panic!("job {job} has no {kind:?}: {:?}", r.events))
}

/// Steps to `job`'s `kind`, recording the setpoint velocity of every cycle.
fn run_to(r: &mut Rig, job: JobId, kind: JobEventKind, max: usize, vs: &mut Vec<(f64, f64)>) {
    for _ in 0..max {
        if r.has(job, kind) {
            return;
        }
        r.step(1);
        let s = r.axis.status_value();
        vs.push((s.position, s.velocity));
    }
    panic!("job {job} did not report {kind:?}: {:?}", r.events);
}

#[test]
fn append_stops_at_the_first_target_then_continues() {
    // S7-Technology V4.1 function manual, 6.2.6 'FB410 MC_MoveAbsolute - Absolute
    // positioning', example "Append motion": v1 = 50 to 1000, the second to
    // 1500: the first decelerates to 0 at 1000 (Done_1), the second starts right after.
    let mut r = homed();
    let j1 = r
        .cmd(buffered(abs(1000.0, s7(50.0)), BufferMode::Aborting))
        .unwrap();
    r.step(100);
    let j2 = r
        .cmd(buffered(abs(1500.0, s7(30.0)), BufferMode::Buffered))
        .unwrap();
    assert!(r.has(j2, JobEventKind::Busy));
    assert_eq!(r.axis.status().queue_depth, 1);
    let mut vs = Vec::new();
    run_to(&mut r, j1, JobEventKind::Done, 40_000, &mut vs);
    let done1 = at(&r, j1, JobEventKind::Done);
    // Done at rest at 1000, and the second job active in the same cycle.
    let s = r.axis.status_value();
    assert!((s.position - 1000.0).abs() < 0.01, "{}", s.position);
    assert_eq!(at(&r, j2, JobEventKind::Active), done1);
    assert_eq!(s.queue_depth, 0);
    let stopped = vs.iter().rev().take(3).any(|(_, v)| *v == 0.0);
    assert!(
        stopped,
        "the axis stops at the seam: {:?}",
        &vs[vs.len() - 3..]
    );
    run_to(&mut r, j2, JobEventKind::Done, 40_000, &mut vs);
    assert_eq!(r.axis.status().position, 1500.0);
}

/// Runs v1 to 1000 then `v2` to `second` blended with `mode`; returns the setpoint velocity at
/// the seam (the cycle of Done_1) and the smallest |v| between the start and the seam.
fn blend(mode: BufferMode, v2: f64, second: f64) -> (f64, f64) {
    let mut r = homed();
    let j1 = r
        .cmd(buffered(abs(1000.0, s7(50.0)), BufferMode::Aborting))
        .unwrap();
    r.step(8000);
    let j2 = r.cmd(buffered(abs(second, s7(v2)), mode)).unwrap();
    let mut vs = Vec::new();
    run_to(&mut r, j1, JobEventKind::Done, 40_000, &mut vs);
    let seam = r.axis.status_value();
    // Done_1 at the seam, the next job active in the same cycle, no positioning stop.
    assert_eq!(
        at(&r, j2, JobEventKind::Active),
        at(&r, j1, JobEventKind::Done)
    );
    assert!((seam.position - 1000.0).abs() <= 70.0 * 0.001 + 1e-9);
    let vmin = vs
        .iter()
        .map(|(_, v)| v.abs())
        .fold(f64::INFINITY, f64::min);
    run_to(&mut r, j2, JobEventKind::Done, 60_000, &mut vs);
    assert_eq!(r.axis.status().position, second);
    (seam.velocity, vmin)
}

#[test]
fn blend_passes_the_seam_at_min_v1_v2_without_a_gap() {
    // S7-Technology V4.1 function manual, 6.2.6, examples "Overlay motion 1/2/3": 50 then 30: passes 1000 at 30; 50 then 70:
    // passes 1000 at 50; reversal (1000 then 700): passes 1000 at 0, no gap.
    let (v, vmin) = blend(BufferMode::BlendingLow, 30.0, 1500.0);
    assert!((v - 30.0).abs() < 1e-9, "{v}");
    assert!(
        vmin >= 30.0 - 1e-9,
        "the axis slowed below the seam velocity: {vmin}"
    );
    let (v, vmin) = blend(BufferMode::BlendingLow, 70.0, 1500.0);
    assert!((v - 50.0).abs() < 1e-9, "{v}");
    assert!(vmin >= 50.0 - 1e-9 - 10.0 * 0.001, "{vmin}");
    let (v, _) = blend(BufferMode::BlendingLow, 30.0, 700.0);
    assert!(v.abs() < 1e-9, "{v}");
}

#[test]
fn seam_velocity_of_each_blending_variant() {
    // PLCopen Motion Control Part 1 'BufferMode': Low min(v1, v2), Previous v1, Next v2,
    // High max(v1, v2); v1 = 50.
    let cases = [
        (BufferMode::BlendingLow, 30.0, 30.0),
        (BufferMode::BlendingPrevious, 30.0, 50.0),
        (BufferMode::BlendingNext, 30.0, 30.0),
        (BufferMode::BlendingHigh, 30.0, 50.0),
        (BufferMode::BlendingLow, 70.0, 50.0),
        (BufferMode::BlendingPrevious, 70.0, 50.0),
        (BufferMode::BlendingNext, 70.0, 70.0),
        (BufferMode::BlendingHigh, 70.0, 70.0),
    ];
    for (mode, v2, want) in cases {
        let (v, _) = blend(mode, v2, 1500.0);
        assert!(
            (v - want).abs() < 1e-9,
            "{mode:?} v2 {v2}: seam at {v}, want {want}"
        );
    }
}

#[test]
fn relative_append_counts_from_the_previous_target() {
    // S7-Technology V4.1 function manual, 6.2.7 'FB411 MC_MoveRelative - Relative
    // positioning' examples: 1000 then 500 ends at 1500.
    let mut r = homed();
    r.cmd(buffered(rel(1000.0, s7(50.0)), BufferMode::Aborting))
        .unwrap();
    r.step(50);
    let j2 = r
        .cmd(buffered(rel(500.0, s7(50.0)), BufferMode::Buffered))
        .unwrap();
    r.until(j2, JobEventKind::Done, 60_000);
    assert_eq!(r.axis.status().position, 1500.0);
}

#[test]
fn move_additive_adds_to_the_running_target() {
    // S7-Technology V4.1 function manual, 6.2.8 'FB412 MC_MoveAdditive - Relative positioning
    // to current target position': a second MoveAdditive before the first finishes:
    // target = first target + second distance.
    let mut r = homed();
    let d = dynamics(100.0, 1000.0, 1000.0, 10_000.0);
    let j1 = r
        .cmd(Command::MoveAdditive {
            distance: 100.0,
            dynamics: d,
        })
        .unwrap();
    r.step(200);
    let j2 = r
        .cmd(Command::MoveAdditive {
            distance: 50.0,
            dynamics: d,
        })
        .unwrap();
    assert!(r.has(j1, JobEventKind::CommandAborted));
    r.until(j2, JobEventKind::Done, 10_000);
    assert_eq!(r.axis.status().position, 150.0);
}

#[test]
fn aborting_is_the_plain_command_bit_for_bit() {
    let d = dynamics(80.0, 700.0, 500.0, 9000.0);
    let mut a = homed();
    let mut b = homed();
    a.cmd(Command::MoveRelative {
        distance: 123.0,
        dynamics: d,
    })
    .unwrap();
    b.cmd(buffered(rel(123.0, d), BufferMode::Aborting))
        .unwrap();
    for _ in 0..2500 {
        a.step(1);
        b.step(1);
        assert_eq!(a.axis.status(), b.axis.status());
    }
}

/// An axis moving with one job and `n` Buffered jobs queued behind it.
fn with_queue(n: usize) -> (Rig, JobId, Vec<JobId>) {
    let mut r = homed();
    let d = dynamics(100.0, 1000.0, 1000.0, 10_000.0);
    let j = r
        .cmd(buffered(rel(100.0, d), BufferMode::Aborting))
        .unwrap();
    r.step(10);
    let q = (0..n)
        .map(|_| r.cmd(buffered(rel(10.0, d), BufferMode::Buffered)).unwrap())
        .collect();
    (r, j, q)
}

#[test]
fn a_full_queue_refuses_with_8014_and_changes_nothing() {
    let (mut r, _, _) = with_queue(JOB_QUEUE_CAPACITY);
    assert_eq!(r.axis.queue_depth(), JOB_QUEUE_CAPACITY);
    let before = r.axis.status_value();
    let n = r.events.len();
    let d = dynamics(100.0, 1000.0, 1000.0, 10_000.0);
    for mode in [BufferMode::Buffered, BufferMode::BlendingLow] {
        assert_eq!(
            r.cmd(buffered(rel(10.0, d), mode)),
            Err(ErrorId::NoJobMemory)
        );
    }
    assert_eq!(r.axis.status_value(), before);
    assert_eq!(r.events.len(), n);
}

#[test]
fn an_aborting_job_aborts_every_queued_job() {
    let (mut r, j, q) = with_queue(3);
    let d = dynamics(100.0, 1000.0, 1000.0, 10_000.0);
    r.cmd(buffered(rel(5.0, d), BufferMode::Aborting)).unwrap();
    assert!(r.has(j, JobEventKind::CommandAborted));
    for id in q {
        assert!(r.has(id, JobEventKind::CommandAborted), "{id}");
    }
    assert_eq!(r.axis.status().queue_depth, 0);
}

#[test]
fn halt_stop_and_alarms_clear_the_queue() {
    let (mut r, _, q) = with_queue(2);
    r.cmd(Command::Halt {
        deceleration: -1.0,
        jerk: -1.0,
        abort_acceleration: false,
    })
    .unwrap();
    assert!(q.iter().all(|id| r.has(*id, JobEventKind::CommandAborted)));
    assert_eq!(r.axis.queue_depth(), 0);

    let (mut r, _, q) = with_queue(2);
    r.cmd(Command::Stop {
        execute: true,
        deceleration: -1.0,
        jerk: -1.0,
    })
    .unwrap();
    assert!(q.iter().all(|id| r.has(*id, JobEventKind::CommandAborted)));
    assert_eq!(r.axis.queue_depth(), 0);

    let (mut r, _, q) = with_queue(2);
    r.axis.raise(
        tandem_motion::catalog::alarm::AlarmId::PositioningMonitoring,
        0,
    );
    r.drain();
    assert!(q
        .iter()
        .all(|id| r.has(*id, JobEventKind::Error(ErrorId::TechnologyAlarm))));
    assert_eq!(r.axis.queue_depth(), 0);
}

#[test]
fn refusals_with_8055_counterpart_change_nothing() {
    let v = |velocity: f64| BufferedMotion::MoveVelocity {
        dynamics: dynamics(velocity, 1000.0, 1000.0, 10_000.0),
        direction: VelocityDirection::BySign,
        current: false,
        position_controlled: true,
    };
    // MoveVelocity cannot append to MoveVelocity (S7-Technology V4.1 function manual, 6.2.10
    // 'FB 414 MC_MoveVelocity - Motion with speed preset', `Mode`).
    let mut r = homed();
    r.cmd(buffered(v(50.0), BufferMode::Aborting)).unwrap();
    r.step(5);
    let before = r.axis.status_value();
    assert_eq!(
        r.cmd(buffered(v(20.0), BufferMode::Buffered)),
        Err(ErrorId::BufferModeNotAllowed)
    );
    assert_eq!(r.axis.status_value(), before);
    // Not behind MC_Halt (S7-Technology 8055).
    r.cmd(Command::Halt {
        deceleration: -1.0,
        jerk: -1.0,
        abort_acceleration: false,
    })
    .unwrap();
    r.step(1);
    let before = r.axis.status_value();
    let n = r.events.len();
    assert_eq!(
        r.cmd(buffered(rel(10.0, s7(10.0)), BufferMode::BlendingLow)),
        Err(ErrorId::BufferModeNotAllowed)
    );
    assert_eq!(r.axis.status_value(), before);
    assert_eq!(r.events.len(), n);
    // A buffered job behind a MoveVelocity starts at InVelocity; the MoveVelocity is aborted.
    let mut r = homed();
    let jv = r.cmd(buffered(v(50.0), BufferMode::Aborting)).unwrap();
    let jr = r
        .cmd(buffered(rel(10.0, s7(50.0)), BufferMode::Buffered))
        .unwrap();
    r.until(jr, JobEventKind::Active, 1000);
    assert!(r.has(jv, JobEventKind::InVelocity));
    assert!(r.has(jv, JobEventKind::CommandAborted));
    r.until(jr, JobEventKind::Done, 20_000);
}

#[test]
fn no_blending_while_a_synchronous_operation_is_active() {
    // S7-Technology 8055: append or blend while GearIn / CamIn is active.
    let mut p =
        tandem_testkit::rig::Pair::new(AxisConfig::example(0.001), AxisConfig::example(0.001));
    p.f(Command::GearIn {
        master: LEADER,
        ratio_numerator: 1,
        ratio_denominator: 1,
        dynamics: Dynamics::DEFAULT,
    })
    .unwrap();
    p.step(5);
    let before = p.fs();
    assert_eq!(
        p.f(buffered(rel(10.0, s7(10.0)), BufferMode::BlendingLow)),
        Err(ErrorId::BufferModeNotAllowed)
    );
    assert_eq!(p.fs(), before);
}

// ---------------------------------------------------------------------------------------------
// Property tests over random move sequences.

fn config(seed: u64) -> ProptestConfig {
    ProptestConfig {
        cases: 48,
        rng_seed: RngSeed::Fixed(seed),
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

const MODES: [BufferMode; 5] = [
    BufferMode::Buffered,
    BufferMode::BlendingLow,
    BufferMode::BlendingPrevious,
    BufferMode::BlendingNext,
    BufferMode::BlendingHigh,
];

/// One random move: distance, velocity, acceleration, jerk, buffer mode index.
type Move = (f64, f64, f64, f64, usize);

/// Runs the sequence (the first aborting, the rest queued at once) and checks every cycle:
/// |v| within the largest commanded velocity, |a| within the largest acceleration, p, v and a
/// continuous, every Done at its target (at rest, or passing it at a blend). Returns the final
/// position.
fn run_sequence(moves: &[Move], modes: Option<BufferMode>) -> f64 {
    run_sequence_with_delays(moves, modes, &[])
}

/// [`run_sequence`] with job `k` issued `delays[k]` cycles after job `k - 1` (while the jobs
/// before move, so that blends replan a moving job; a job issued after the one before ended
/// starts at once).
fn run_sequence_with_delays(moves: &[Move], modes: Option<BufferMode>, delays: &[usize]) -> f64 {
    let mut r = homed();
    let mut ids: Vec<JobId> = Vec::new();
    let mut targets = Vec::new();
    let mut target = 0.0;
    let (mut vmax, mut amax, mut jmax) = (0.0f64, 0.0f64, 0.0f64);
    for &(_, v, a, j, _) in moves {
        vmax = vmax.max(v);
        amax = amax.max(a);
        // A trapezoidal move may jump in acceleration.
        jmax = if j == 0.0 { f64::INFINITY } else { jmax.max(j) };
    }
    let dt = 0.001;
    let mut prev = r.axis.status_value();
    let (mut checked, mut wait) = (0, 0);
    for _ in 0..200_000 {
        // The next job when its delay has passed.
        if let Some(&(dist, v, a, j, m)) = moves.get(ids.len()) {
            let k = ids.len();
            if wait >= delays.get(k).copied().unwrap_or(0) {
                let mode = match (k, modes) {
                    (0, _) => BufferMode::Aborting,
                    (_, Some(all)) => all,
                    (_, None) => MODES[m % MODES.len()],
                };
                ids.push(
                    r.cmd(buffered(rel(dist, dynamics(v, a, a, j)), mode))
                        .unwrap(),
                );
                target += dist;
                targets.push(target);
                wait = 0;
                continue;
            }
            wait += 1;
        }
        r.step(1);
        let s = r.axis.status_value();
        assert!(
            s.velocity.abs() <= vmax * (1.0 + 1e-9) + 1e-9,
            "v {}",
            s.velocity
        );
        assert!(
            s.acceleration.abs() <= amax * (1.0 + 1e-9) + 1e-9,
            "a {}",
            s.acceleration
        );
        assert!((s.position - prev.position).abs() <= vmax * dt * (1.0 + 1e-9) + 1e-9);
        assert!((s.velocity - prev.velocity).abs() <= amax * dt * (1.0 + 1e-9) + 1e-9);
        assert!(
            (s.acceleration - prev.acceleration).abs() <= jmax * dt * (1.0 + 1e-9) + 1e-9,
            "a jumps {} -> {}",
            prev.acceleration,
            s.acceleration
        );
        prev = s;
        // Every Done at its target: at rest inside the positioning window, or (at a blend)
        // passing it within one cycle's travel.
        while let Some(&id) = ids.get(checked) {
            let Some(e) = r
                .events
                .iter()
                .find(|e| e.job == id && e.kind == JobEventKind::Done)
            else {
                break;
            };
            assert_eq!(e.time_ns, r.now() - 1_000_000);
            let t = targets[checked];
            assert!(
                (s.position - t).abs() <= s.velocity.abs() * dt + 0.011,
                "job {id} done at {} for target {t}",
                s.position
            );
            checked += 1;
        }
        if ids.len() == moves.len() && checked == moves.len() {
            assert!(r.events.iter().all(|e| !matches!(
                e.kind,
                JobEventKind::CommandAborted | JobEventKind::Error(_)
            )));
            return s.position;
        }
    }
    panic!("sequence did not finish: {:?}", r.events);
}

/// The same moves one after the other, each started when the previous is Done.
fn run_single(moves: &[Move]) -> f64 {
    let mut r = homed();
    for &(dist, v, a, j, _) in moves {
        let id = r
            .cmd(Command::MoveRelative {
                distance: dist,
                dynamics: dynamics(v, a, a, j),
            })
            .unwrap();
        r.until(id, JobEventKind::Done, 200_000);
    }
    r.axis.status_value().position
}

fn moves() -> impl Strategy<Value = Vec<Move>> {
    proptest::collection::vec(
        (
            prop_oneof![-200.0f64..-1.0, 1.0f64..200.0],
            10.0f64..300.0,
            200.0f64..3000.0,
            prop_oneof![Just(0.0), 5_000.0f64..60_000.0],
            0usize..5,
        ),
        1..=5,
    )
}

proptest! {
    #![proptest_config(config(0xB0FF_E214))]

    /// Random sequences with random buffer modes: limits, continuity, every target reached.
    #[test]
    fn random_sequences_keep_limits_and_reach_each_target(ms in moves()) {
        let end = run_sequence(&ms, None);
        let sum: f64 = ms.iter().fold(0.0, |acc, m| acc + m.0);
        prop_assert!((end - sum).abs() <= 1e-9, "{end} vs {sum}");
    }

    /// Jobs queued while the ones before move (blends replan a moving job): the same checks.
    #[test]
    fn jobs_queued_while_moving_keep_limits_and_reach_each_target(
        ms in moves(),
        delays in proptest::collection::vec(0usize..400, 5),
    ) {
        let end = run_sequence_with_delays(&ms, None, &delays);
        let sum: f64 = ms.iter().fold(0.0, |acc, m| acc + m.0);
        prop_assert!((end - sum).abs() <= 1e-9, "{end} vs {sum}");
    }

    /// A Buffered sequence ends where the sequence of single moves ends.
    #[test]
    fn buffered_sequence_ends_where_single_moves_end(ms in moves()) {
        let queued = run_sequence(&ms, Some(BufferMode::Buffered));
        let single = run_single(&ms);
        prop_assert!((queued - single).abs() <= 1e-9, "{queued} vs {single}");
    }
}

#[test]
fn blend_into_a_velocity_job() {
    // A MoveVelocity blended behind a positioning job: the positioning job passes its target at
    // min(v1, v2) (Done there), the velocity job continues from it and reports InVelocity.
    let mut r = homed();
    let j1 = r
        .cmd(buffered(abs(1000.0, s7(50.0)), BufferMode::Aborting))
        .unwrap();
    let v = BufferedMotion::MoveVelocity {
        dynamics: s7(30.0),
        direction: VelocityDirection::BySign,
        current: false,
        position_controlled: true,
    };
    let j2 = r.cmd(buffered(v, BufferMode::BlendingLow)).unwrap();
    r.until(j1, JobEventKind::Done, 40_000);
    let s = r.axis.status_value();
    assert!((s.velocity - 30.0).abs() < 1e-9, "{}", s.velocity);
    assert!((s.position - 1000.0).abs() <= 0.03 + 1e-9, "{}", s.position);
    r.until(j2, JobEventKind::InVelocity, 10);
    // Against the direction of travel: the seam is at rest.
    let mut r = homed();
    let j1 = r
        .cmd(buffered(abs(100.0, s7(50.0)), BufferMode::Aborting))
        .unwrap();
    let back = BufferedMotion::MoveVelocity {
        dynamics: s7(-30.0),
        direction: VelocityDirection::BySign,
        current: false,
        position_controlled: true,
    };
    r.cmd(buffered(back, BufferMode::BlendingHigh)).unwrap();
    r.until(j1, JobEventKind::Done, 40_000);
    assert_eq!(r.axis.status_value().velocity, 0.0);
    assert_eq!(r.axis.status_value().position, 100.0);
}

#[test]
fn seams_between_queued_jobs() {
    // Three jobs queued at once: 1000 at 50, +500 at 30, +500 at 60, blended with BlendingLow
    // then BlendingNext: the first seam at min(50, 30) = 30, the second (between two queued
    // jobs) at 60.
    let mut r = homed();
    let j1 = r
        .cmd(buffered(rel(1000.0, s7(50.0)), BufferMode::Aborting))
        .unwrap();
    let j2 = r
        .cmd(buffered(rel(500.0, s7(30.0)), BufferMode::BlendingLow))
        .unwrap();
    let j3 = r
        .cmd(buffered(rel(500.0, s7(60.0)), BufferMode::BlendingNext))
        .unwrap();
    assert_eq!(r.axis.queue_depth(), 2);
    r.until(j1, JobEventKind::Done, 60_000);
    assert!((r.axis.status_value().velocity - 30.0).abs() < 1e-9);
    r.until(j2, JobEventKind::Done, 60_000);
    let s = r.axis.status_value();
    assert!((s.velocity - 60.0).abs() < 1e-9, "{}", s.velocity);
    assert!((s.position - 1500.0).abs() <= 0.06 + 1e-9, "{}", s.position);
    assert_eq!(
        at(&r, j3, JobEventKind::Active),
        at(&r, j2, JobEventKind::Done)
    );
    r.until(j3, JobEventKind::Done, 60_000);
    assert_eq!(r.axis.status_value().position, 2000.0);
}

#[test]
fn queued_absolute_moves_on_a_modulo_axis_go_on_from_the_target_before() {
    // Modulo 0..360: to 350 in the positive direction, then 10 in the positive direction
    // blended: over 360, ending at 370 continuous (10 shown), passing 350 at min(v1, v2)
    // without a stop.
    let mut cfg = AxisConfig::example(0.001);
    cfg.modulo = Some(tandem_motion::kinematics::modulo::Modulo {
        start: 0.0,
        length: 360.0,
    });
    let mut r = Rig::enabled(cfg);
    let h = r
        .cmd(Command::Home {
            mode: 0,
            position: 0.0,
        })
        .unwrap();
    r.until(h, JobEventKind::Done, 10);
    let d = dynamics(100.0, 1000.0, 1000.0, 10_000.0);
    let j1 = r
        .cmd(Command::MoveAbsolute {
            position: 350.0,
            dynamics: d,
            direction: Direction::Positive,
        })
        .unwrap();
    let j2 = r
        .cmd(buffered(
            BufferedMotion::MoveAbsolute {
                position: 10.0,
                dynamics: dynamics(40.0, 1000.0, 1000.0, 10_000.0),
                direction: Direction::Positive,
            },
            BufferMode::BlendingLow,
        ))
        .unwrap();
    r.until(j1, JobEventKind::Done, 10_000);
    assert!((r.axis.status_value().velocity - 40.0).abs() < 1e-9);
    r.until(j2, JobEventKind::Done, 10_000);
    let s = r.axis.status_value();
    assert_eq!(s.position_unwrapped, 370.0);
    assert!((s.position - 10.0).abs() < 1e-9, "{}", s.position);
}
