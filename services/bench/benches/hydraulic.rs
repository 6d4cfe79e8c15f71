//! The per-cycle cost of a hydraulic axis (the displacement-based generator, the target window,
//! the position controller and Finish) beside an electric axis on an analog drive (the
//! jerk-limited profile and tandem's position controller), in one run (issue 15: at most 2x).
//!
//! The hydraulic axis is `config/hydraulic.toml`'s, the electric one `config/analog.toml`'s;
//! `--axes N` of each (default 256), powered, homed and positioning to a target far away (both
//! travel at constant velocity through the run), for `--cycles K` cycles per round (default
//! 2,000), `--rounds R` rounds (default 7) alternating which goes first. Per axis and cycle: the
//! connection's inputs (encoder, enable handshake), `Axis::step`, the connection's command (the
//! output word); the plant is ideal (the encoder reads the set position of the cycle before),
//! so neither the cylinder's nor the motor's simulation is in the figure.
//!
//! ```sh
//! cargo bench -p tandem-bench --bench hydraulic
//! cargo bench -p tandem-bench --bench hydraulic -- --axes 64 --cycles 5000 --rounds 9
//! ```
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::hint::black_box;
use tandem_bench::{alternate, arg_usize, median, time_cycles};
use tandem_config::{AnalogDriveConnection, Cell, DriveConnection};
use tandem_motion::hydraulic::controller::HydController;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::axis::{Axis, Command, Direction, StartMode, StopMode};
use tandem_motion::plant::analog::{AnalogConnection, AnalogFeedback};

const MS: i64 = 1_000_000;

/// An axis with its analog connection and the ideal plant's last feedback.
struct Rig {
    axis: Axis,
    conn: AnalogConnection,
    feedback: AnalogFeedback,
}

impl Rig {
    fn new(cell: &Cell) -> Self {
        let entry = &cell.axes[0];
        let DriveConnection::Analog(c) = &entry.drive else {
            panic!("the example's axis is on an analog output");
        };
        let c: &AnalogDriveConnection = c;
        // The ideal plant travels on beyond the example's limit switches.
        let cfg = &tandem_motion::objects::axis::AxisConfig {
            hw_limits_active: false,
            ..entry.config.clone()
        };
        let p0 = cfg.initial_position;
        let conn = match c.hydraulic {
            Some(h) => AnalogConnection::hydraulic(
                c.params,
                HydController::new(h, None).unwrap(),
                cfg.plant,
                p0,
            )
            .unwrap(),
            None => AnalogConnection::new(c.params, cfg.plant, p0).unwrap(),
        };
        let mut axis = Axis::new(cfg.clone()).unwrap();
        axis.connect_drive();
        let feedback = AnalogFeedback {
            ready: false,
            encoder_raw: c.params.scaling.count(p0) as u32,
            ..AnalogFeedback::default()
        };
        Self {
            axis,
            conn,
            feedback,
        }
    }

    /// One cycle: inputs, step, command, and the ideal plant's feedback for the next one.
    #[inline]
    fn cycle(&mut self, k: i64) {
        let t = k * MS;
        let inputs = self.conn.inputs(t, &self.feedback);
        self.axis.set_drive_inputs(&inputs);
        self.axis.step(t);
        let out = self.axis.drive_outputs();
        let cmd = self.conn.command(&out);
        self.feedback = AnalogFeedback {
            ready: cmd.enable,
            encoder_raw: self.conn.params().scaling.count(out.position) as u32,
            ..AnalogFeedback::default()
        };
        while self.axis.pop_event().is_some() {}
    }

    /// MC_Power and MC_Home (0 here), 100 cycles, then MC_MoveAbsolute far away at 100
    /// units/s.
    fn start(&mut self) {
        let power = Command::Power {
            enable: true,
            start_mode: StartMode::PositionControlled,
            stop_mode: StopMode::Emergency,
        };
        self.axis.command(&power).unwrap();
        let home = Command::Home {
            mode: 0,
            position: 0.0,
        };
        self.axis.command(&home).unwrap();
        for k in 0..100 {
            self.cycle(k);
        }
        let mv = Command::MoveAbsolute {
            position: 1e9,
            dynamics: Dynamics {
                velocity: 100.0,
                acceleration: -1.0,
                deceleration: -1.0,
                jerk: -1.0,
            },
            direction: Direction::Shortest,
        };
        self.axis.command(&mv).unwrap();
        // Past the start ramps.
        for k in 100..1100 {
            self.cycle(k);
        }
    }
}

fn main() {
    let (n, cycles, rounds) = (
        arg_usize("--axes", 256),
        arg_usize("--cycles", 2000),
        arg_usize("--rounds", 7),
    );
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let load = |f: &str| -> Cell { tandem_config::load(&root.join("config").join(f)).unwrap() };
    let (electric_cell, hydraulic_cell) = (load("analog.toml"), load("hydraulic.toml"));
    let mut electric: Vec<Rig> = (0..n).map(|_| Rig::new(&electric_cell)).collect();
    let mut hydraulic: Vec<Rig> = (0..n).map(|_| Rig::new(&hydraulic_cell)).collect();
    for r in electric.iter_mut().chain(hydraulic.iter_mut()) {
        r.start();
    }
    let k0 = 1100i64;
    let per = alternate(
        rounds,
        |r| time_cycles(&mut electric, k0 + (r * cycles) as i64, cycles, Rig::cycle),
        |r| time_cycles(&mut hydraulic, k0 + (r * cycles) as i64, cycles, Rig::cycle),
    );
    for (r, (e, h)) in per.iter().enumerate() {
        println!(
            "round {r}: electric axis {e:.1} ns, hydraulic axis {h:.1} ns per axis and cycle, ratio {:.2}",
            h / e
        );
    }
    let ratios: Vec<f64> = per.iter().map(|(e, h)| h / e).collect();
    let e = median(per.iter().map(|p| p.0).collect());
    let h = median(per.iter().map(|p| p.1).collect());
    black_box((&electric, &hydraulic));
    println!(
        "{n} axes, {cycles} cycles x {rounds} rounds: electric axis {e:.1} ns, hydraulic axis {h:.1} ns \
         per axis and cycle (medians); hydraulic / electric = {:.2} (median of rounds; target <= 2.00)",
        median(ratios)
    );
    for r in &hydraulic {
        let s = r.axis.hydraulic_status().unwrap();
        assert_eq!(
            s.state.name(true),
            "iTcHydStateConstVeloP",
            "still travelling"
        );
    }
    for r in &electric {
        assert_eq!(
            r.axis.status().state.name(),
            "DiscreteMotion",
            "still moving"
        );
    }
}
