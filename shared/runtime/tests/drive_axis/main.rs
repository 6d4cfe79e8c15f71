//! What an axis does with its CiA 402 drive beyond enabling it, end to end in the executive on
//! `config/servo.toml` (a simulated servo through the process image): quick stop for MC_Power
//! StopMode 1 and the alarm reaction "remove enable", the drive's internal limit as StatusWord
//! X27 "InLimitation", CSV for non-position-controlled operation and torque feedforward, and
//! homing through the drive's touch probe (S7-1500T Motion Control V4.0 function manual,
//! 'MC_Power', 'Technology alarms', 'Non-position-controlled operation', 'Homing';
//! IEC 61800-7-201 (CiA 402) drive profile, 0x6040/0x6041, 0x605A, 0x6060, 0x60B2, 0x60B8).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod homing;
mod modes;
mod stop;
mod torque;

use tandem_config::{AxisIndex, Cell};
use tandem_motion::catalog::alarm::AlarmId;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{AxisState, AxisStatus, Command, StartMode, StopMode};
use tandem_motion::plant::cia402::DriveFeedback;
use tandem_runtime::exec::Executive;
use tandem_testkit::workspace::root;

pub const MS: i64 = 1_000_000;

/// `config/servo.toml` edited by `edit`.
pub fn cell(edit: impl Fn(String) -> String) -> Cell {
    let src = std::fs::read_to_string(root().join("config/servo.toml")).unwrap();
    tandem_config::parse("servo.toml", &edit(src)).unwrap()
}

/// The executive of the cell and its log, stepped cycle by cycle.
#[allow(missing_debug_implementations)]
pub struct Run<'c> {
    pub exec: Executive<'c>,
    pub k: i64,
    pub log: Vec<u8>,
}

impl<'c> Run<'c> {
    pub fn new(cell: &'c Cell) -> Self {
        let mut r = Self {
            exec: Executive::new(cell, None).unwrap(),
            k: 0,
            log: Vec::new(),
        };
        r.step();
        r
    }

    pub fn t(&self) -> i64 {
        self.k * MS
    }

    pub fn apply(&mut self, target: &str, action: Action) {
        let t = self.t();
        let r = self
            .exec
            .apply_at(t, t, target, "test", action, &mut self.log)
            .unwrap();
        assert!(r.is_ok(), "{target}: {r:?}\n{}", self.log());
    }

    pub fn cmd(&mut self, c: Command) {
        self.apply("slide", Action::Command(c));
    }

    pub fn step(&mut self) {
        let t = self.t();
        self.exec.step(t, &mut self.log).unwrap();
        self.k += 1;
    }

    pub fn log(&self) -> String {
        String::from_utf8_lossy(&self.log).into_owned()
    }

    pub fn status(&mut self) -> AxisStatus {
        self.exec.status()[0]
    }

    pub fn state(&mut self) -> AxisState {
        self.status().state
    }

    pub fn alarm(&self, id: AlarmId) -> Option<u16> {
        let axis = self.exec.axis(AxisIndex(0)).unwrap();
        axis.alarms().find(|a| a.id == id).map(|a| a.supplement)
    }

    /// The drive's TxPDO sampled in the last step (none on a simulated axis).
    pub fn fb(&self) -> Option<DriveFeedback> {
        self.exec.drive_feedback(0).copied()
    }

    /// Steps until `f` holds, at most `max` cycles.
    pub fn until(&mut self, max: usize, what: &str, f: impl Fn(&mut Self) -> bool) {
        for _ in 0..max {
            if f(self) {
                return;
            }
            self.step();
        }
        panic!("{what}: not within {max} cycles\n{}", self.log());
    }

    /// MC_Power with `start_mode`, stepped until the axis is enabled.
    pub fn power(&mut self, start_mode: StartMode) {
        self.cmd(Command::Power {
            enable: true,
            start_mode,
            stop_mode: StopMode::Emergency,
        });
        self.until(50, "enabled", |r| r.status().status_word & 1 != 0);
    }

    pub fn move_to(&mut self, position: f64, velocity: f64, acceleration: f64) {
        self.cmd(Command::MoveAbsolute {
            position,
            dynamics: Dynamics {
                velocity,
                acceleration,
                deceleration: acceleration,
                jerk: 0.0,
            },
            direction: tandem_motion::objects::axis::Direction::Shortest,
        });
    }
}
