//! The test rig shared by the axis test files: an axis stepped at 1 ms with its job events
//! collected.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

pub mod counting;

use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::axis::{
    Axis, AxisConfig, AxisKind, AxisStatus, Command, StartMode, StopMode,
};
use tandem_motion::objects::job::{JobEvent, JobEventKind, JobId};
use tandem_motion::objects::leading::LeadingValue;

pub const MS: i64 = 1_000_000;

pub struct Rig {
    pub axis: Axis,
    pub k: i64,
    pub events: Vec<JobEvent>,
}

impl Rig {
    pub fn new(cfg: AxisConfig) -> Self {
        let mut r = Self {
            axis: Axis::new(cfg).unwrap(),
            k: 0,
            events: Vec::new(),
        };
        r.step(1);
        r
    }

    pub fn enabled(cfg: AxisConfig) -> Self {
        let mut r = Self::new(cfg);
        r.cmd(Command::Power {
            enable: true,
            start_mode: StartMode::PositionControlled,
            stop_mode: StopMode::Emergency,
        })
        .unwrap();
        r.step(1);
        r
    }

    pub fn now(&self) -> i64 {
        self.k * MS
    }

    /// Time of the last computed setpoint: a command takes effect from there.
    pub fn t_last(&self) -> f64 {
        (self.k - 1) as f64 * 1e-3
    }

    pub fn cmd(&mut self, c: Command) -> Result<JobId, ErrorId> {
        let r = self.axis.command(&c);
        self.drain();
        r
    }

    pub fn drain(&mut self) {
        while let Some(e) = self.axis.pop_event() {
            self.events.push(e);
        }
    }

    pub fn step(&mut self, n: usize) {
        for _ in 0..n {
            self.axis.step(self.now());
            self.drain();
            self.k += 1;
        }
    }

    /// Steps until `job` reports `kind` or `max` cycles pass; returns the cycle time in s.
    pub fn until(&mut self, job: JobId, kind: JobEventKind, max: usize) -> f64 {
        for _ in 0..max {
            if let Some(e) = self.events.iter().find(|e| e.job == job && e.kind == kind) {
                return e.time_ns as f64 * 1e-9;
            }
            self.step(1);
        }
        panic!(
            "job {job} did not report {kind:?} within {max} cycles; events {:?}",
            self.events
        );
    }

    pub fn has(&self, job: JobId, kind: JobEventKind) -> bool {
        self.events.iter().any(|e| e.job == job && e.kind == kind)
    }
}

pub fn dyn_(v: f64, a: f64, d: f64, j: f64) -> Dynamics {
    Dynamics {
        velocity: v,
        acceleration: a,
        deceleration: d,
        jerk: j,
    }
}

/// A leader and a synchronous follower stepped together, the leader first (D = 0).
pub const LEADER: u32 = 7;

pub struct Pair {
    pub leader: Axis,
    pub follower: Axis,
    pub k: i64,
    pub events: Vec<JobEvent>,
    /// Actual-value coupling instead of setpoint coupling.
    pub actual: bool,
}

pub fn power() -> Command {
    Command::Power {
        enable: true,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Emergency,
    }
}

pub fn dynamics(v: f64, a: f64, d: f64, j: f64) -> Dynamics {
    Dynamics {
        velocity: v,
        acceleration: a,
        deceleration: d,
        jerk: j,
    }
}

impl Pair {
    pub fn new(leader: AxisConfig, mut follower: AxisConfig) -> Self {
        follower.kind = AxisKind::Synchronous;
        let mut p = Self {
            leader: Axis::new(leader).unwrap(),
            follower: Axis::new(follower).unwrap(),
            k: 0,
            events: vec![],
            actual: false,
        };
        p.step(1);
        p.leader.command(&power()).unwrap();
        p.follower.command(&power()).unwrap();
        p.leader
            .command(&Command::Home {
                mode: 0,
                position: 0.0,
            })
            .unwrap();
        p.follower
            .command(&Command::Home {
                mode: 0,
                position: 0.0,
            })
            .unwrap();
        p.step(1);
        p
    }

    /// Couples by actual value from now on.
    pub fn use_actual(&mut self) {
        self.actual = true;
        self.leader.set_actual_value_output(true);
    }

    pub fn lv(&self) -> LeadingValue {
        let s = self.leader.status();
        LeadingValue {
            p: s.position_unwrapped,
            v: s.velocity,
            a: s.acceleration,
            modulo: self.leader.config().modulo,
        }
    }

    pub fn step(&mut self, n: usize) {
        for _ in 0..n {
            let t = self.k * 1_000_000;
            self.leader.step(t);
            let lv = self.lv();
            for id in self.follower.leaders().into_iter().flatten() {
                self.follower
                    .set_leading_value(id, (id == LEADER).then_some(lv));
            }
            self.follower.step(t);
            while let Some(e) = self.follower.pop_event() {
                self.events.push(e);
            }
            while self.leader.pop_event().is_some() {}
            self.k += 1;
        }
    }

    pub fn f(&mut self, c: Command) -> Result<JobId, ErrorId> {
        let r = self.follower.command(&c);
        while let Some(e) = self.follower.pop_event() {
            self.events.push(e);
        }
        r
    }

    pub fn has(&self, job: JobId, kind: JobEventKind) -> bool {
        self.events.iter().any(|e| e.job == job && e.kind == kind)
    }

    pub fn until(&mut self, job: JobId, kind: JobEventKind, max: usize) {
        for _ in 0..max {
            if self.has(job, kind) {
                return;
            }
            self.step(1);
        }
        panic!(
            "job {job}: no {kind:?} within {max} cycles: {:?}",
            self.events
        );
    }

    pub fn fs(&self) -> AxisStatus {
        *self.follower.status()
    }
}
