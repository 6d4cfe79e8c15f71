//! The per-cycle cost of an axis on a CiA 402 drive with its process-image stages, beside the
//! same axis on the simulated drive, in one run (issue 11: the I/O stages may add at most 50 %).
//!
//! Both run `config/servo.toml`'s axis, powered and moving at constant velocity, `--axes N` of
//! each (default 256) for `--cycles K` cycles per round (default 2,000), `--rounds R` rounds
//! (default 7) alternating which goes first. Per axis and cycle:
//! - *simulated drive*: `Axis::step` with the drive model inside the axis (its cost included);
//! - *CiA 402 drive*: the link's inputs (position word through the raw counter and the
//!   mechanics, the enable sequence, the switches), `Axis::step`, the link's command (CSP
//!   target and feedforward in increments), on an ideal drive that returns the commanded
//!   position with a CiA 402 state machine (its cost included; a real drive is on the bus).
//!
//! ```sh
//! cargo bench -p tandem-bench --bench drives
//! cargo bench -p tandem-bench --bench drives -- --axes 64 --cycles 5000 --rounds 9
//! ```
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::hint::black_box;
use std::time::Instant;
use tandem_bench::{arg_usize, median};
use tandem_config::{AxisEntry, Cell, DriveConnection};
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::axis::{Axis, Command, StartMode, StopMode, VelocityDirection};
use tandem_motion::plant::cia402::{
    DeviceInputs, DeviceStateMachine, DriveFeedback, QuickStopOption,
};
use tandem_runtime::drives::Cia402Link;

const MS: i64 = 1_000_000;

/// An ideal CiA 402 drive: its state machine, and the commanded position as its actual value.
struct IdealDrive {
    device: DeviceStateMachine,
    feedback: DriveFeedback,
}

impl IdealDrive {
    fn new() -> Self {
        Self {
            device: DeviceStateMachine::new(QuickStopOption::QuickStopRamp),
            feedback: DriveFeedback::default(),
        }
    }

    fn apply(&mut self, cmd: &tandem_motion::plant::cia402::DriveCommand) {
        let inputs = DeviceInputs {
            fault: false,
            reaction_finished: true,
            self_test_done: true,
        };
        // The transition taken does not matter here; the state is in the statusword.
        let _ = self.device.step(cmd.controlword, inputs);
        self.feedback.statusword = self.device.statusword();
        self.feedback.position_actual = cmd.target_position;
        self.feedback.velocity_actual = cmd.velocity_offset;
    }
}

/// One cycle of an axis: on the simulated drive (`link == None`) or through its link and
/// the ideal drive.
#[inline]
fn cycle(axis: &mut Axis, k: i64, link: Option<(&mut Cia402Link, &mut IdealDrive)>) {
    let t = k * MS;
    match link {
        None => axis.step(t),
        Some((link, drive)) => {
            let inputs = link.inputs(t, &drive.feedback);
            axis.set_drive_inputs(&inputs);
            axis.step(t);
            let cmd = match axis.connected_outputs() {
                Some(out) => link.command(out),
                None => link.command(&axis.drive_outputs()),
            };
            drive.apply(&cmd);
        }
    }
    while axis.pop_event().is_some() {}
}

/// MC_Power, 50 cycles (the drive's enable sequence), then MC_MoveVelocity at 50 units/s.
fn start(axis: &mut Axis, mut link: Option<(&mut Cia402Link, &mut IdealDrive)>) {
    let power = Command::Power {
        enable: true,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Emergency,
    };
    axis.command(&power).unwrap();
    for k in 0..50 {
        let l = link.as_mut().map(|(l, d)| (&mut **l, &mut **d));
        cycle(axis, k, l);
    }
    let mv = Command::MoveVelocity {
        dynamics: Dynamics {
            velocity: 50.0,
            acceleration: 1000.0,
            deceleration: 1000.0,
            jerk: 0.0,
        },
        direction: VelocityDirection::BySign,
        current: false,
        position_controlled: true,
    };
    axis.command(&mv).unwrap();
    while axis.pop_event().is_some() {}
}

fn main() {
    let (n, cycles, rounds) = (
        arg_usize("--axes", 256),
        arg_usize("--cycles", 2000),
        arg_usize("--rounds", 7),
    );
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cell: Cell = tandem_config::load(&root.join("config/servo.toml")).unwrap();
    let entry: &AxisEntry = &cell.axes[0];
    let DriveConnection::Cia402(conn) = &entry.drive else {
        panic!("config/servo.toml's axis is on a CiA 402 drive");
    };
    let cfg = &entry.config;
    let mut sim: Vec<Axis> = (0..n).map(|_| Axis::new(cfg.clone()).unwrap()).collect();
    for a in &mut sim {
        start(a, None);
    }
    let mut cia: Vec<(Axis, Cia402Link, IdealDrive)> = (0..n)
        .map(|i| {
            let mut a = Axis::new(cfg.clone()).unwrap();
            a.connect_drive();
            let link = Cia402Link::new(i, conn, cfg.plant, cfg.initial_position).unwrap();
            (a, link, IdealDrive::new())
        })
        .collect();
    for (a, l, d) in &mut cia {
        start(a, Some((l, d)));
    }
    let mut k = 50i64;
    let mut per = (Vec::new(), Vec::new());
    for r in 0..rounds {
        let mut run_sim = |k0: i64| {
            let t0 = Instant::now();
            for c in 0..cycles as i64 {
                for a in sim.iter_mut() {
                    cycle(a, k0 + c, None);
                }
            }
            t0.elapsed().as_nanos() as f64 / (cycles * n) as f64
        };
        let mut run_cia = |k0: i64| {
            let t0 = Instant::now();
            for c in 0..cycles as i64 {
                for (a, l, d) in cia.iter_mut() {
                    cycle(a, k0 + c, Some((l, d)));
                }
            }
            t0.elapsed().as_nanos() as f64 / (cycles * n) as f64
        };
        let (s, c) = if r % 2 == 0 {
            let s = run_sim(k);
            (s, run_cia(k))
        } else {
            let c = run_cia(k);
            (run_sim(k), c)
        };
        k += cycles as i64;
        println!("round {r}: simulated drive {s:.1} ns, CiA 402 drive {c:.1} ns per axis and cycle, ratio {:.2}", c / s);
        per.0.push(s);
        per.1.push(c);
    }
    let ratios: Vec<f64> = per.0.iter().zip(&per.1).map(|(s, c)| c / s).collect();
    let (s, c, q) = (median(per.0), median(per.1), median(ratios));
    black_box((&sim, &cia));
    println!(
        "{n} axes, {cycles} cycles x {rounds} rounds: simulated drive {s:.1} ns, CiA 402 drive {c:.1} ns \
         per axis and cycle (medians); CiA 402 / simulated = {q:.2} (median of rounds; target <= 1.50)"
    );
    for (a, _, _) in &cia {
        assert_eq!(a.status().state.name(), "ContinuousMotion", "still moving");
    }
}
