//! The cyclic path of the engine does not allocate: a counting global allocator, armed only on
//! the test thread, counts every allocation while three busy axes (a positioning axis with
//! software limits, a modulo axis and a speed axis) run 10,000 cycles of 1 ms with a script of
//! commands and with their events drained every cycle.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_motion::catalog::alarm::AlarmId;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::kinematics::modulo::Modulo;
use tandem_motion::objects::axis::{
    Axis, AxisConfig, AxisKind, AxisState, Command, Direction, SoftwareLimits, StartMode, StopMode,
    VelocityDirection,
};
use tandem_motion::objects::job::JobEventKind;

use tandem_testkit::counting::{arm, disarm};

tandem_testkit::counting_allocator!();

const MS: i64 = 1_000_000;
const CYCLES: u32 = 10_000;

fn dyn_(v: f64, a: f64, d: f64, j: f64) -> Dynamics {
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

fn jog(forward: bool, backward: bool) -> Command {
    Command::MoveJog {
        forward,
        backward,
        dynamics: dyn_(60.0, 800.0, 800.0, 20_000.0),
        position_controlled: true,
    }
}

fn velocity(v: f64) -> Command {
    Command::MoveVelocity {
        dynamics: dyn_(v, 2000.0, 2000.0, 40_000.0),
        direction: VelocityDirection::BySign,
        current: false,
        position_controlled: true,
    }
}

/// The command issued in cycle `k` (at most one per cycle). Two rounds of 5000 cycles with the
/// same instructions, then (cycles 9000..) a run into the software limit and a reset.
/// Enable-type instructions (jog, MotionInVelocity) are re-sent every cycle while held, as a
/// PLC program calls its FB every cycle.
fn script(k: u32) -> Option<Command> {
    if k >= 9000 {
        return match k {
            9000 => Some(velocity(500.0)),
            9800 => Some(Command::Reset { restart: false }),
            9850 => Some(Command::MoveRelative {
                distance: -10.0,
                dynamics: Dynamics::DEFAULT,
            }),
            _ => None,
        };
    }
    let round = k / 5000;
    let r = k % 5000;
    let sign = if round == 0 { 1.0 } else { -1.0 };
    match r {
        0 => Some(Command::MoveAbsolute {
            position: sign * 200.0,
            dynamics: dyn_(150.0, 1500.0, 1500.0, 30_000.0),
            direction: if round == 0 {
                Direction::Positive
            } else {
                Direction::Negative
            },
        }),
        // Mid-way through the MoveAbsolute (it needs about 1.4 s).
        300 => Some(Command::MoveRelative {
            distance: -sign * 80.0,
            dynamics: Dynamics::DEFAULT,
        }),
        500 => Some(Command::SetOverride { velocity: 50.0 }),
        700 => Some(Command::SetOverride { velocity: 0.0 }),
        900 => Some(Command::SetOverride { velocity: 150.0 }),
        1000 => Some(Command::MoveSuperimposed {
            distance: 10.0,
            dynamics: Dynamics::DEFAULT,
        }),
        1100 => Some(Command::SetOverride { velocity: 100.0 }),
        1800 => Some(velocity(sign * 120.0)),
        2000 => Some(Command::SetOverride { velocity: 50.0 }),
        2100 => Some(Command::MoveSuperimposed {
            distance: 5.0,
            dynamics: Dynamics::DEFAULT,
        }),
        2300 => Some(Command::SetOverride { velocity: 100.0 }),
        2500 => Some(Command::Halt {
            deceleration: -1.0,
            jerk: -1.0,
            abort_acceleration: false,
        }),
        2800..3300 => Some(jog(true, false)),
        3300..3500 => Some(jog(false, false)),
        3500..3800 => Some(jog(false, true)),
        3800..3900 => Some(jog(false, false)),
        3900..4300 => Some(Command::MotionInVelocity {
            enable: true,
            velocity: 20.0 + 0.05 * f64::from(r - 3900),
            acceleration: 50.0,
            position_controlled: true,
        }),
        4300 => Some(Command::MotionInVelocity {
            enable: false,
            velocity: 0.0,
            acceleration: 0.0,
            position_controlled: true,
        }),
        4350 => Some(velocity(-sign * 80.0)),
        4600 => Some(Command::Stop {
            execute: true,
            deceleration: -1.0,
            jerk: -1.0,
        }),
        4800 => Some(Command::Stop {
            execute: false,
            deceleration: -1.0,
            jerk: -1.0,
        }),
        4900 => Some(Command::MoveRelative {
            distance: 30.0,
            dynamics: Dynamics::DEFAULT,
        }),
        _ => None,
    }
}

fn positional(c: &Command) -> bool {
    matches!(
        c,
        Command::MoveAbsolute { .. }
            | Command::MoveRelative { .. }
            | Command::MoveSuperimposed { .. }
    )
}

/// What one axis did in the armed window, in fixed-size storage (nothing here may allocate).
#[derive(Debug, Default)]
struct Tally {
    commands: u32,
    ok: u32,
    /// The first rejections: (cycle, error).
    rejected: [Option<(u32, ErrorId)>; 16],
    n_rejected: usize,
    events: u32,
    done: u32,
    aborted: u32,
    errors: u32,
    in_velocity: u32,
    sw_limit_reached: bool,
    max_speed: f64,
    min_pos: f64,
    max_pos: f64,
    states_seen: [bool; 8],
}

fn state_index(s: AxisState) -> usize {
    match s {
        AxisState::Disabled => 0,
        AxisState::Standstill => 1,
        AxisState::Homing => 2,
        AxisState::DiscreteMotion => 3,
        AxisState::ContinuousMotion => 4,
        AxisState::SynchronizedMotion => 5,
        AxisState::Stopping => 6,
        AxisState::ErrorStop => 7,
    }
}

struct Subject {
    axis: Axis,
    tally: Tally,
}

impl Subject {
    fn new(cfg: AxisConfig) -> Self {
        let positioning = cfg.kind == AxisKind::Positioning;
        let mut axis = Axis::new(cfg).unwrap();
        axis.step(0);
        axis.command(&power_on()).unwrap();
        axis.step(MS);
        if positioning {
            axis.command(&Command::Home {
                mode: 0,
                position: 0.0,
            })
            .unwrap();
            assert!(axis
                .status()
                .has(tandem_motion::catalog::alarm::status_bit::HOMING_DONE));
        }
        axis.step(2 * MS);
        while axis.pop_event().is_some() {}
        assert_eq!(axis.status().state, AxisState::Standstill);
        Self {
            axis,
            tally: Tally {
                min_pos: f64::INFINITY,
                max_pos: f64::NEG_INFINITY,
                ..Tally::default()
            },
        }
    }

    fn drain(&mut self) {
        while let Some(e) = self.axis.pop_event() {
            let t = &mut self.tally;
            t.events += 1;
            match e.kind {
                JobEventKind::Done => t.done += 1,
                JobEventKind::CommandAborted => t.aborted += 1,
                JobEventKind::Error(_) => t.errors += 1,
                JobEventKind::InVelocity => t.in_velocity += 1,
                _ => {}
            }
        }
    }

    fn cycle(&mut self, k: u32, cmd: Option<Command>) {
        if let Some(c) = cmd {
            let speed_axis = self.axis.config().kind == AxisKind::Speed;
            if !(speed_axis && positional(&c)) {
                self.tally.commands += 1;
                match self.axis.command(&c) {
                    Ok(_) => self.tally.ok += 1,
                    Err(e) => {
                        let t = &mut self.tally;
                        if t.n_rejected < t.rejected.len() {
                            t.rejected[t.n_rejected] = Some((k, e));
                        }
                        t.n_rejected += 1;
                    }
                }
                self.drain();
            }
        }
        self.axis.step(i64::from(k + 3) * MS);
        self.drain();
        let s = self.axis.status();
        let t = &mut self.tally;
        t.max_speed = t.max_speed.max(s.velocity.abs());
        t.min_pos = t.min_pos.min(s.position_unwrapped);
        t.max_pos = t.max_pos.max(s.position_unwrapped);
        t.states_seen[state_index(s.state)] = true;
        t.sw_limit_reached |= self.axis.has_alarm(AlarmId::SwLimitReached);
    }
}

#[test]
fn cyclic_path_does_not_allocate() {
    // The counter works: an allocation on the armed thread is counted.
    arm();
    let probe = std::hint::black_box(Box::new(7u64));
    drop(probe);
    let (probe_allocs, _) = disarm();
    assert_eq!(probe_allocs, 1, "the counting allocator does not count");

    let mut pos_cfg = AxisConfig::example(0.001);
    pos_cfg.sw_limits = Some(SoftwareLimits {
        min: -350.0,
        max: 350.0,
    });
    let mut mod_cfg = AxisConfig::example(0.001);
    mod_cfg.modulo = Some(Modulo {
        start: 0.0,
        length: 360.0,
    });
    mod_cfg.sw_limits = None;
    let mut speed_cfg = AxisConfig::example(0.001);
    speed_cfg.kind = AxisKind::Speed;

    let mut subjects = [
        Subject::new(pos_cfg),
        Subject::new(mod_cfg),
        Subject::new(speed_cfg),
    ];

    arm();
    for k in 0..CYCLES {
        let cmd = script(k);
        for s in subjects.iter_mut() {
            s.cycle(k, cmd);
        }
    }
    let (allocs, deallocs) = disarm();

    println!(
        "armed window: {CYCLES} cycles x {} axes: {allocs} allocations, {deallocs} deallocations",
        subjects.len()
    );
    for (name, s) in ["positioning", "modulo", "speed"].iter().zip(&subjects) {
        let t = &s.tally;
        println!(
            "{name}: {} commands ({} ok), rejected {:?}, {} events ({} done, {} aborted, {} error, \
             {} in-velocity), |v| max {:.1}, position {:.1}..{:.1}, SW limit reached {}, \
             alarms now {:?}, dropped events {}",
            t.commands,
            t.ok,
            &t.rejected[..t.n_rejected.min(t.rejected.len())],
            t.events,
            t.done,
            t.aborted,
            t.errors,
            t.in_velocity,
            t.max_speed,
            t.min_pos,
            t.max_pos,
            t.sw_limit_reached,
            s.axis.alarms().map(|a| a.id).collect::<Vec<_>>(),
            s.axis.dropped_events(),
        );
    }
    assert_eq!(allocs, 0, "the cyclic path allocated {allocs} times");

    // The script really exercised the axes (otherwise zero allocations proves little).
    for s in &subjects {
        let t = &s.tally;
        assert_eq!(
            t.ok,
            t.commands,
            "rejected commands: {:?}",
            &t.rejected[..t.n_rejected.min(t.rejected.len())]
        );
        assert!(t.done >= 8 && t.aborted >= 4 && t.in_velocity >= 2, "{t:?}");
        assert!(t.max_speed >= 100.0);
        assert!(t.states_seen[state_index(AxisState::ContinuousMotion)]);
        assert!(t.states_seen[state_index(AxisState::Stopping)]);
        assert_eq!(s.axis.dropped_events(), 0);
    }
    // The positioning axis ran into its software limit (alarm 533, stop with maximum
    // dynamics, planned inside `step`) and was reset.
    assert!(subjects[0].tally.sw_limit_reached);
    assert!(subjects[0].tally.states_seen[state_index(AxisState::DiscreteMotion)]);
    assert!(subjects[0].tally.states_seen[state_index(AxisState::ErrorStop)]);
    assert!(subjects.iter().all(|s| s.axis.alarms().next().is_none()));
}
