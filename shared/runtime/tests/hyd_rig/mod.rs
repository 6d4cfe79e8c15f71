//! The rig of the hydraulic axis tests: one executive of a cell whose first axis is the
//! hydraulic `ram` on its simulated valve and cylinder (`config/hydraulic.toml` or a variant),
//! stepped a millisecond at a time, with the commands and readings those tests share.
// Each test crate that includes this module uses a part of it.
#![allow(dead_code)]

use tandem_config::script::Script;
use tandem_config::{AxisIndex, Cell};
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::hydraulic::generator::HydState;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{
    AxisState, AxisStatus, Command, Direction, HydraulicStatus, StartMode, StopMode,
};
use tandem_runtime::exec::Executive;

/// A cycle of the bundled hydraulic cells (ns).
pub const MS: i64 = 1_000_000;

/// The executive of `cell`, its cycle count and its log.
pub struct Run<'c> {
    pub exec: Executive<'c>,
    pub k: i64,
    pub log: Vec<u8>,
}

impl<'c> Run<'c> {
    /// The axis powered and homed at 100 mm, standing.
    pub fn enabled(cell: &'c Cell) -> Self {
        Self::enabled_at(cell, 100.0)
    }

    /// The axis powered and homed at `position` (mm), standing.
    pub fn enabled_at(cell: &'c Cell, position: f64) -> Self {
        let mut r = Self {
            exec: Executive::new(cell, None).unwrap(),
            k: 0,
            log: Vec::new(),
        };
        r.step();
        r.cmd(Command::Power {
            enable: true,
            start_mode: StartMode::PositionControlled,
            stop_mode: StopMode::Emergency,
        });
        r.cmd(Command::Home { mode: 0, position });
        r.until(100, "enabled", |r| r.state() == AxisState::Standstill);
        r
    }

    /// Applies `c` to the ram now: its job, or the refusal.
    pub fn try_cmd(&mut self, c: Command) -> Result<Option<u32>, ErrorId> {
        let t = self.k * MS;
        self.exec
            .apply_at(t, t, "ram", "test", Action::Command(c), &mut self.log)
            .unwrap()
    }

    /// Applies `c`, which must be accepted.
    pub fn cmd(&mut self, c: Command) {
        let r = self.try_cmd(c);
        assert!(r.is_ok(), "{c:?}: {r:?}\n{}", self.log());
    }

    /// One cycle.
    pub fn step(&mut self) {
        self.exec.step(self.k * MS, &mut self.log).unwrap();
        self.k += 1;
    }

    /// The log so far.
    pub fn log(&self) -> String {
        String::from_utf8_lossy(&self.log).into_owned()
    }

    /// The ram's status.
    pub fn status(&self) -> AxisStatus {
        *self.exec.axis(AxisIndex(0)).unwrap().status()
    }

    /// The ram's state.
    pub fn state(&self) -> AxisState {
        self.status().state
    }

    /// The ram's hydraulic status.
    pub fn hyd(&self) -> HydraulicStatus {
        let axis = self.exec.axis(AxisIndex(0)).unwrap();
        axis.hydraulic_status().unwrap()
    }

    /// The valve's output word.
    pub fn word(&self) -> i16 {
        self.exec.analog_drive(0).unwrap().link.word
    }

    /// Steps until `f` holds; fails after `max` cycles naming `what`.
    pub fn until(&mut self, max: usize, what: &str, f: impl Fn(&Self) -> bool) {
        for _ in 0..max {
            if f(self) {
                return;
            }
            self.step();
        }
        panic!("{what}: not within {max} cycles\n{}", self.log());
    }

    /// MC_MoveAbsolute to `position` at `velocity`, the axis' other dynamics.
    pub fn try_move_to(&mut self, position: f64, velocity: f64) -> Result<Option<u32>, ErrorId> {
        self.try_cmd(Command::MoveAbsolute {
            position,
            dynamics: Dynamics {
                velocity,
                acceleration: -1.0,
                deceleration: -1.0,
                jerk: -1.0,
            },
            direction: Direction::Shortest,
        })
    }

    /// The same, which must be accepted.
    pub fn move_to(&mut self, position: f64, velocity: f64) {
        let r = self.try_move_to(position, velocity);
        assert!(r.is_ok(), "to {position}: {r:?}\n{}", self.log());
    }

    /// Whether the generator is in `state`.
    pub fn in_state(&self, state: HydState) -> bool {
        self.hyd().state == state
    }
}

/// Steps `exec` through `script` a millisecond at a time from 0 to its duration: the entries
/// due at a cycle are applied before its step (each must be accepted), then `each(k, exec)`
/// looks at cycle `k`.
pub fn replay(
    exec: &mut Executive<'_>,
    script: &Script,
    log: &mut Vec<u8>,
    mut each: impl FnMut(i64, &mut Executive<'_>),
) {
    let mut next = 0;
    for k in 0..=script.duration_ns / MS {
        let t = k * MS;
        while let Some(e) = script.entries.get(next).filter(|e| e.t_ns <= t) {
            next += 1;
            let r = exec
                .apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, log)
                .unwrap();
            assert!(r.is_ok(), "{r:?}\n{}", String::from_utf8_lossy(log));
        }
        exec.step(t, log).unwrap();
        each(k, exec);
    }
}
