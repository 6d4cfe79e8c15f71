//! The per-cycle cost of an axis with a full queue of blended moves (PLCopen BufferMode
//! `BlendingLow`), beside the same axis with a single move, in one run (issue 14: at most 1.5×).
//!
//! `--axes N` of each (default 256), `--cycles K` cycles per round (default 2,000), `--rounds R`
//! rounds (default 7) alternating which goes first. Per axis and cycle, `Axis::step` and the
//! draining of its job events:
//! - *single move*: one long jerk-limited MC_MoveRelative, moving through every round;
//! - *blended queue*: jerk-limited MC_MoveRelative moves of `--distance` units (default 20)
//!   at 40 or 60 units/s, about 0.4 s each, with [`JOB_QUEUE_CAPACITY`] more queued behind the running one with
//!   `BlendingLow`: every round passes about five seams per axis (Done, Active, the next
//!   profile planned to its seam velocity). Before each round (not timed) the queue is filled
//!   up again.
//!
//! ```sh
//! cargo bench -p tandem-bench --bench buffer
//! cargo bench -p tandem-bench --bench buffer -- --axes 64 --cycles 5000 --rounds 9
//! # a seam every 50 cycles or so (2-unit moves), rounds short enough not to empty the queue:
//! cargo bench -p tandem-bench --bench buffer -- --distance 2 --cycles 300
//! ```
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::hint::black_box;
use std::time::Instant;
use tandem_bench::{arg_usize, median};
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::axis::{
    Axis, AxisConfig, BufferMode, BufferedMotion, Command, StartMode, StopMode, JOB_QUEUE_CAPACITY,
};

const MS: i64 = 1_000_000;

fn dynamics(velocity: f64) -> Dynamics {
    Dynamics {
        velocity,
        acceleration: 1000.0,
        deceleration: 1000.0,
        jerk: 20_000.0,
    }
}

fn relative(distance: f64, velocity: f64, buffer_mode: BufferMode) -> Command {
    Command::Buffered {
        motion: BufferedMotion::MoveRelative {
            distance,
            dynamics: dynamics(velocity),
        },
        buffer_mode,
    }
}

/// One cycle of an axis.
#[inline]
fn cycle(axis: &mut Axis, k: i64) {
    axis.step(k * MS);
    while axis.pop_event().is_some() {}
}

/// A powered axis at cycle 2.
fn powered() -> Axis {
    let mut axis = Axis::new(AxisConfig::example(0.001)).unwrap();
    axis.step(0);
    axis.command(&Command::Power {
        enable: true,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Emergency,
    })
    .unwrap();
    axis.step(MS);
    while axis.pop_event().is_some() {}
    axis
}

/// Fills the queue of `axis` with blended moves (alternating 40 and 60 units/s).
fn fill(axis: &mut Axis, n: &mut u64, distance: f64) {
    while axis.queue_depth() < JOB_QUEUE_CAPACITY {
        let v = if *n % 2 == 0 { 40.0 } else { 60.0 };
        *n += 1;
        axis.command(&relative(distance, v, BufferMode::BlendingLow))
            .unwrap();
    }
    while axis.pop_event().is_some() {}
}

fn main() {
    let (n, cycles, rounds) = (
        arg_usize("--axes", 256),
        arg_usize("--cycles", 2000),
        arg_usize("--rounds", 7),
    );
    let distance = arg_usize("--distance", 20) as f64;
    let mut single: Vec<Axis> = (0..n).map(|_| powered()).collect();
    for a in &mut single {
        a.command(&relative(1e7, 50.0, BufferMode::Aborting))
            .unwrap();
        while a.pop_event().is_some() {}
    }
    let mut queued: Vec<(Axis, u64)> = (0..n).map(|_| (powered(), 0)).collect();
    for (a, _) in &mut queued {
        a.command(&relative(distance, 50.0, BufferMode::Aborting))
            .unwrap();
    }
    let mut k = 2i64;
    let mut per = (Vec::new(), Vec::new());
    let mut depth_after = usize::MAX;
    for r in 0..rounds {
        for (a, count) in &mut queued {
            fill(a, count, distance);
        }
        let mut run_single = |k0: i64| {
            let t0 = Instant::now();
            for c in 0..cycles as i64 {
                for a in single.iter_mut() {
                    cycle(a, k0 + c);
                }
            }
            t0.elapsed().as_nanos() as f64 / (cycles * n) as f64
        };
        let mut run_queued = |k0: i64| {
            let t0 = Instant::now();
            for c in 0..cycles as i64 {
                for (a, _) in queued.iter_mut() {
                    cycle(a, k0 + c);
                }
            }
            t0.elapsed().as_nanos() as f64 / (cycles * n) as f64
        };
        let (s, q) = if r % 2 == 0 {
            let s = run_single(k);
            (s, run_queued(k))
        } else {
            let q = run_queued(k);
            (run_single(k), q)
        };
        k += cycles as i64;
        depth_after = depth_after.min(queued.iter().map(|(a, _)| a.queue_depth()).min().unwrap());
        println!(
            "round {r}: single move {s:.1} ns, blended queue {q:.1} ns per axis and cycle, ratio {:.2}",
            q / s
        );
        per.0.push(s);
        per.1.push(q);
    }
    let ratios: Vec<f64> = per.0.iter().zip(&per.1).map(|(s, q)| q / s).collect();
    let (s, q, ratio) = (median(per.0), median(per.1), median(ratios));
    black_box((&single, &queued));
    let seams: u64 = queued.iter().map(|(_, c)| *c).sum::<u64>() / n as u64;
    println!(
        "{n} axes, {cycles} cycles x {rounds} rounds: single move {s:.1} ns, blended queue {q:.1} ns \
         per axis and cycle (medians); blended / single = {ratio:.2} (median of rounds; target <= 1.50); \
         {seams} moves queued per axis, queue depth after a round >= {depth_after}"
    );
    // The queued axes really passed seams, and never ran dry.
    assert!(
        depth_after < JOB_QUEUE_CAPACITY && depth_after > 0,
        "{depth_after}"
    );
    for a in &single {
        assert_eq!(a.status().state.name(), "DiscreteMotion", "still moving");
    }
}
