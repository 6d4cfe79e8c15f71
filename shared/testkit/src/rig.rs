//! The axis rig of the motion tests: an axis stepped at 1 ms with its job events collected
//! ([`Rig`]), and a leader with a synchronous follower stepped together ([`Pair`]).
//!
//! ```
//! use tandem_motion::objects::axis::{AxisConfig, Command};
//! use tandem_motion::objects::job::JobEventKind;
//! use tandem_testkit::rig::{dynamics, Rig};
//!
//! let mut rig = Rig::enabled(AxisConfig::example(0.001));
//! let job = rig
//!     .cmd(Command::MoveRelative {
//!         distance: 10.0,
//!         dynamics: dynamics(100.0, 1000.0, 1000.0, 10_000.0),
//!     })
//!     .unwrap();
//! let done = rig.until(job, JobEventKind::Done, 2000);
//! assert!(done > 0.1 && done < 0.5, "done at {done} s");
//! ```

use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::axis::{
    Axis, AxisConfig, AxisKind, AxisStatus, Command, StartMode, StopMode,
};
use tandem_motion::objects::job::{JobEvent, JobEventKind, JobId};
use tandem_motion::objects::leading::LeadingValue;

/// One cycle of the rig: 1 ms, in ns.
pub const MS: i64 = 1_000_000;

/// The leader's id as the follower of a [`Pair`] names it.
pub const LEADER: u32 = 7;

/// `MC_Power` enabling position-controlled, stopping with the emergency ramp.
pub fn power() -> Command {
    Command::Power {
        enable: true,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Emergency,
    }
}

/// The dynamics of a motion command: velocity, acceleration, deceleration, jerk.
pub fn dynamics(v: f64, a: f64, d: f64, j: f64) -> Dynamics {
    Dynamics {
        velocity: v,
        acceleration: a,
        deceleration: d,
        jerk: j,
    }
}

/// Whether `events` hold `kind` of `job`.
fn reported(events: &[JobEvent], job: JobId, kind: JobEventKind) -> Option<&JobEvent> {
    events.iter().find(|e| e.job == job && e.kind == kind)
}

/// One axis stepped at 1 ms, its job events collected.
#[derive(Debug)]
pub struct Rig {
    /// The axis under test.
    pub axis: Axis,
    /// The next cycle to step (cycle `k` runs at `k` ms).
    pub k: i64,
    /// Every job event so far, in order.
    pub events: Vec<JobEvent>,
}

impl Rig {
    /// The axis of `cfg`, stepped once.
    ///
    /// # Panics
    /// When the configuration is refused.
    pub fn new(cfg: AxisConfig) -> Self {
        let mut r = Self {
            axis: Axis::new(cfg).unwrap(),
            k: 0,
            events: Vec::new(),
        };
        r.step(1);
        r
    }

    /// The axis of `cfg`, powered ([`power`]) and stepped once more.
    ///
    /// # Panics
    /// When the configuration or `MC_Power` is refused.
    pub fn enabled(cfg: AxisConfig) -> Self {
        let mut r = Self::new(cfg);
        r.cmd(power()).unwrap();
        r.step(1);
        r
    }

    /// The time of the next cycle (ns).
    pub fn now(&self) -> i64 {
        self.k * MS
    }

    /// Time of the last computed setpoint: a command takes effect from there.
    pub fn t_last(&self) -> f64 {
        (self.k - 1) as f64 * 1e-3
    }

    /// Issues `c`; its events are collected.
    pub fn cmd(&mut self, c: Command) -> Result<JobId, ErrorId> {
        let r = self.axis.command(&c);
        self.drain();
        r
    }

    /// Collects the axis' pending job events.
    pub fn drain(&mut self) {
        while let Some(e) = self.axis.pop_event() {
            self.events.push(e);
        }
    }

    /// Steps `n` cycles.
    pub fn step(&mut self, n: usize) {
        for _ in 0..n {
            self.axis.step(self.now());
            self.drain();
            self.k += 1;
        }
    }

    /// Steps until `job` reports `kind` or `max` cycles pass; returns the cycle time in s.
    ///
    /// # Panics
    /// When `max` cycles pass without it, listing the events.
    pub fn until(&mut self, job: JobId, kind: JobEventKind, max: usize) -> f64 {
        for _ in 0..max {
            if let Some(e) = reported(&self.events, job, kind) {
                return e.time_ns as f64 * 1e-9;
            }
            self.step(1);
        }
        panic!(
            "job {job} did not report {kind:?} within {max} cycles; events {:?}",
            self.events
        );
    }

    /// Whether `job` reported `kind`.
    pub fn has(&self, job: JobId, kind: JobEventKind) -> bool {
        reported(&self.events, job, kind).is_some()
    }
}

/// A leader and a synchronous follower stepped together, the leader first (no leading-value
/// delay), both powered and homed at 0.
#[derive(Debug)]
pub struct Pair {
    /// The leading axis.
    pub leader: Axis,
    /// The following axis (its kind forced to synchronous).
    pub follower: Axis,
    /// The next cycle to step (cycle `k` runs at `k` ms).
    pub k: i64,
    /// The follower's job events so far, in order.
    pub events: Vec<JobEvent>,
    /// Actual-value coupling instead of setpoint coupling.
    pub actual: bool,
}

impl Pair {
    /// The pair of `leader` and `follower`, powered, homed at 0 and stepped twice.
    ///
    /// # Panics
    /// When a configuration or a command is refused.
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
        let home = Command::Home {
            mode: 0,
            position: 0.0,
        };
        for axis in [&mut p.leader, &mut p.follower] {
            axis.command(&power()).unwrap();
        }
        for axis in [&mut p.leader, &mut p.follower] {
            axis.command(&home).unwrap();
        }
        p.step(1);
        p
    }

    /// Couples by actual value from now on.
    pub fn use_actual(&mut self) {
        self.actual = true;
        self.leader.set_actual_value_output(true);
    }

    /// The leader's leading value now.
    pub fn lv(&self) -> LeadingValue {
        let s = self.leader.status();
        LeadingValue {
            p: s.position_unwrapped,
            v: s.velocity,
            a: s.acceleration,
            modulo: self.leader.config().modulo,
        }
    }

    /// Steps `n` cycles: the leader, then the follower with the leader's value.
    pub fn step(&mut self, n: usize) {
        for _ in 0..n {
            let t = self.k * MS;
            self.leader.step(t);
            let lv = self.lv();
            for id in self.follower.leaders().into_iter().flatten() {
                self.follower
                    .set_leading_value(id, (id == LEADER).then_some(lv));
            }
            self.follower.step(t);
            self.drain();
            while self.leader.pop_event().is_some() {}
            self.k += 1;
        }
    }

    /// Collects the follower's pending job events.
    fn drain(&mut self) {
        while let Some(e) = self.follower.pop_event() {
            self.events.push(e);
        }
    }

    /// Issues `c` to the follower; its events are collected.
    pub fn f(&mut self, c: Command) -> Result<JobId, ErrorId> {
        let r = self.follower.command(&c);
        self.drain();
        r
    }

    /// Whether the follower's `job` reported `kind`.
    pub fn has(&self, job: JobId, kind: JobEventKind) -> bool {
        reported(&self.events, job, kind).is_some()
    }

    /// Steps until the follower's `job` reports `kind`.
    ///
    /// # Panics
    /// When `max` cycles pass without it, listing the events.
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

    /// The follower's status.
    pub fn fs(&self) -> AxisStatus {
        *self.follower.status()
    }
}
