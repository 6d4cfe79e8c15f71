//! Buffered and blended moves do not allocate: a counting global allocator, armed only on the
//! test thread, counts every allocation while an axis accepts queued jobs up to a full queue
//! (and the refusal past it), blends through them, appends, is aborted with its queue, and runs
//! 20,000 cycles of 1 ms with its events drained every cycle.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::objects::axis::{
    Axis, AxisConfig, BufferMode, BufferedMotion, Command, StartMode, StopMode, JOB_QUEUE_CAPACITY,
};
use tandem_motion::objects::job::JobEventKind;
use tandem_testkit::counting::{arm, disarm};
use tandem_testkit::rig::dynamics;

tandem_testkit::counting_allocator!();

const MS: i64 = 1_000_000;

fn rel(distance: f64, v: f64, buffer_mode: BufferMode) -> Command {
    Command::Buffered {
        motion: BufferedMotion::MoveRelative {
            distance,
            dynamics: dynamics(v, 1000.0, 1000.0, 20_000.0),
        },
        buffer_mode,
    }
}

/// The command of cycle `k`: a full queue of blended moves at 0, appended ones at 8000, an
/// aborting job with a full queue at 12,000, a MoveAdditive at 15,000.
fn script(k: u32, queued: &mut u32) -> Option<Command> {
    let modes = [
        BufferMode::BlendingLow,
        BufferMode::BlendingPrevious,
        BufferMode::BlendingNext,
        BufferMode::BlendingHigh,
    ];
    match k {
        0 => Some(rel(20.0, 100.0, BufferMode::Aborting)),
        // One job a cycle: the queue fills, then one more is refused.
        1..=9 => {
            *queued += 1;
            let m = modes[(k as usize) % modes.len()];
            Some(rel(10.0 + f64::from(k), 60.0 + 10.0 * f64::from(k), m))
        }
        8000..=8008 | 12_001..=12_009 => Some(rel(5.0, 80.0, BufferMode::Buffered)),
        12_000 => Some(rel(-50.0, 100.0, BufferMode::Aborting)),
        12_010 => Some(rel(1.0, 100.0, BufferMode::Aborting)),
        15_000 => Some(Command::MoveAdditive {
            distance: 7.0,
            dynamics: dynamics(50.0, 500.0, 500.0, 10_000.0),
        }),
        _ => None,
    }
}

#[test]
fn queued_and_blended_moves_do_not_allocate() {
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

    let (mut ok, mut full, mut done, mut active, mut aborted, mut max_depth) = (0, 0, 0, 0, 0, 0);
    let mut queued = 0;
    arm();
    for k in 0..20_000u32 {
        if let Some(c) = script(k, &mut queued) {
            match axis.command(&c) {
                Ok(_) => ok += 1,
                Err(ErrorId::NoJobMemory) => full += 1,
                Err(e) => panic!("cycle {k}: {e:?}"),
            }
        }
        max_depth = max_depth.max(axis.queue_depth());
        axis.step(i64::from(k + 2) * MS);
        while let Some(e) = axis.pop_event() {
            match e.kind {
                JobEventKind::Done => done += 1,
                JobEventKind::Active => active += 1,
                JobEventKind::CommandAborted => aborted += 1,
                _ => {}
            }
        }
    }
    let (allocations, _) = disarm();
    assert_eq!(allocations, 0, "the cycle or a queued command allocated");
    // The script did what it says: a full queue, a refusal, blends, appends, an abort.
    assert_eq!(max_depth, JOB_QUEUE_CAPACITY);
    assert_eq!(full, 2, "the ninth queued job of each round is refused");
    assert!(ok >= 20, "{ok}");
    assert!(active >= 16 && done >= 17, "active {active}, done {done}");
    assert!(aborted >= 9, "aborted {aborted}");
    assert_eq!(queued, 9);
}
