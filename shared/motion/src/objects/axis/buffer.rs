//! Buffered and blended moves: the per-axis queue of pending jobs (PLCopen Motion Control Part 1,
//! 'BufferMode'; the `Mode` 1 append and 2 overlay of S7-Technology V4.1 function manual, 6.2.6
//! 'FB410 MC_MoveAbsolute - Absolute positioning', 6.2.7 'FB411 MC_MoveRelative - Relative
//! positioning' and 6.2.10 'FB 414 MC_MoveVelocity - Motion with speed preset') and
//! MC_MoveAdditive (6.2.8 'FB412 MC_MoveAdditive - Relative positioning to current target
//! position'). A tandem extension: the
//! S7-1500T Motion Control V4.0 function manual has no BufferMode (3.4 'No buffering or blending
//! in V4.0'); with [`BufferMode::Aborting`] (the default) every job behaves exactly as before.
//!
//! The queue has a fixed capacity ([`JOB_QUEUE_CAPACITY`]) and lives inline in the axis: nothing
//! here allocates.
//!
//! # Rules (each one in docs/override-tables.md)
//! - A Buffered or blending job with no job running starts at once, as an aborting one.
//! - It may only follow a MoveAbsolute, MoveRelative, MoveAdditive or MoveVelocity; not while a
//!   synchronous operation is active or pending, nor behind MC_Halt (S7-Technology `8055`
//!   "Latching motion not allowed in current state", 6.2.6), nor a MoveVelocity behind a
//!   MoveVelocity (6.2.10, `Mode`): [`ErrorId::BufferModeNotAllowed`].
//! - A full queue refuses it with [`ErrorId::NoJobMemory`] (S7-1500 `16#8014`, S7-Technology
//!   `8005` "command memory full").
//! - A job that aborts the running job (every aborting motion job, MC_Halt, MC_Stop, a
//!   synchronous operation that starts, a disable, a stopping alarm) ends every queued job the
//!   same way (`CommandAborted`, or `Error 16#8001` for an alarm).
//! - Buffered: the job starts when the one before it is Done (at rest at its target, after
//!   positioning monitoring); behind a MoveVelocity when it is InVelocity (inferred from PLCopen:
//!   a velocity job is never Done), which then ends with `CommandAborted`.
//! - Blending behind a positioning job: that job is replanned to pass its target at the seam
//!   velocity ([`BufferMode::seam_speed`] of the two commanded velocities, 0 when the direction
//!   reverses) and reports Done there, without positioning monitoring; the queued job reports
//!   `Active` and continues from the seam state without a stop. Blending behind a MoveVelocity
//!   acts as Buffered (there is no target to blend at).
//! - Relative and additive distances of queued jobs count from the target of the job before
//!   (S7-Technology 6.2.7 examples: 1000 then 500 ends at 1500); behind a
//!   MoveVelocity, from the position where the job starts.

use super::{Axis, Goal, MotionJob};
use crate::catalog::error_id::ErrorId;
use crate::kinematics::profile::Limits;
use crate::objects::axis::command::{BufferMode, BufferedMotion, Direction, VelocityDirection};
use crate::objects::job::{Instruction, JobEventKind, JobId};

/// How many jobs an axis holds queued behind the running one.
pub const JOB_QUEUE_CAPACITY: usize = 8;

/// Where a queued positioning job goes.
#[derive(Copy, Clone, Debug, PartialEq)]
enum Target {
    /// A continuous target known when the job was queued.
    Fixed(f64),
    /// A distance from the position where the job starts (behind a MoveVelocity).
    FromStart(f64),
    /// A modulo position, resolved with its direction where the job starts (behind a
    /// MoveVelocity on a modulo axis).
    Modulo(f64, Direction),
}

/// What a queued job does.
#[derive(Copy, Clone, Debug, PartialEq)]
enum QueuedGoal {
    Position(Target),
    /// A signed velocity, or the velocity at its start (`Current`).
    Velocity {
        v: f64,
        current: bool,
    },
}

/// A job waiting in the queue.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(super) struct QueuedJob {
    id: JobId,
    instr: Instruction,
    mode: BufferMode,
    goal: QueuedGoal,
    lim: Limits,
    position_controlled: bool,
    /// The velocity at which it passes its target into the job behind it (0: at rest).
    end_v: f64,
}

/// A fixed-capacity FIFO of queued jobs.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub(super) struct JobQueue {
    slots: [Option<QueuedJob>; JOB_QUEUE_CAPACITY],
    head: usize,
    len: usize,
}

impl JobQueue {
    pub(super) fn len(&self) -> usize {
        self.len
    }

    pub(super) fn is_empty(&self) -> bool {
        self.len == 0
    }

    fn front(&self) -> Option<&QueuedJob> {
        if self.len == 0 {
            return None;
        }
        self.slots.get(self.head).and_then(Option::as_ref)
    }

    fn back_mut(&mut self) -> Option<&mut QueuedJob> {
        let i = (self.head + self.len.checked_sub(1)?) % JOB_QUEUE_CAPACITY;
        self.slots.get_mut(i).and_then(Option::as_mut)
    }

    fn back(&self) -> Option<&QueuedJob> {
        let i = (self.head + self.len.checked_sub(1)?) % JOB_QUEUE_CAPACITY;
        self.slots.get(i).and_then(Option::as_ref)
    }

    fn push(&mut self, j: QueuedJob) -> bool {
        if self.len == JOB_QUEUE_CAPACITY {
            return false;
        }
        if let Some(s) = self
            .slots
            .get_mut((self.head + self.len) % JOB_QUEUE_CAPACITY)
        {
            *s = Some(j);
            self.len += 1;
            return true;
        }
        false
    }

    fn pop(&mut self) -> Option<QueuedJob> {
        if self.len == 0 {
            return None;
        }
        let j = self.slots.get_mut(self.head).and_then(Option::take);
        self.head = (self.head + 1) % JOB_QUEUE_CAPACITY;
        self.len -= 1;
        j
    }

    /// Moves every fixed target by `delta` (homing shifts the coordinate system).
    pub(super) fn shift(&mut self, delta: f64) {
        for j in self.slots.iter_mut().flatten() {
            if let QueuedGoal::Position(Target::Fixed(t)) = &mut j.goal {
                *t += delta;
            }
        }
    }
}

/// The instructions a queued job may follow.
fn bufferable(instr: Instruction) -> bool {
    matches!(
        instr,
        Instruction::MoveAbsolute
            | Instruction::MoveRelative
            | Instruction::MoveAdditive
            | Instruction::MoveVelocity
    )
}

fn positioning(instr: Instruction) -> bool {
    matches!(
        instr,
        Instruction::MoveAbsolute | Instruction::MoveRelative | Instruction::MoveAdditive
    )
}

/// A queued job as checked, before it gets its id.
struct Accepted {
    instr: Instruction,
    goal: QueuedGoal,
    lim: Limits,
    clamped: crate::kinematics::dynamics::Clamped,
    position_controlled: bool,
}

/// The job before a new queued one: its instruction, its target (positioning jobs) and the
/// position it starts from, and its commanded speed.
#[derive(Copy, Clone)]
struct Before {
    instr: Instruction,
    target: Option<f64>,
    from: Option<f64>,
    speed: f64,
}

impl Axis {
    /// The number of jobs waiting behind the running one.
    pub fn queue_depth(&self) -> usize {
        self.queue.len()
    }

    /// The target of the running positioning job (MC_MoveAdditive adds to it).
    pub(super) fn running_target(&self) -> Option<f64> {
        match (self.main, self.goal) {
            (Some(m), Goal::Position { target, .. }) if positioning(m.instr) => Some(target),
            _ => None,
        }
    }

    /// Ends every queued job with `how` (the running job was aborted the same way).
    pub(super) fn abort_queued(&mut self, how: JobEventKind) {
        while let Some(j) = self.queue.pop() {
            self.emit(j.id, j.instr, how);
        }
    }

    /// The job a new queued job follows: the last queued one, else the running one.
    fn before(&self) -> Option<Before> {
        if let Some(q) = self.queue.back() {
            let prev_target = self.queue_target_before(self.queue.len() - 1);
            return Some(Before {
                instr: q.instr,
                target: match q.goal {
                    QueuedGoal::Position(Target::Fixed(t)) => Some(t),
                    _ => None,
                },
                from: prev_target,
                speed: q.lim.vel,
            });
        }
        let m = self.main?;
        Some(Before {
            instr: m.instr,
            target: self.running_target(),
            from: Some(self.basic.p),
            speed: m.lim.vel,
        })
    }

    /// The fixed target of the job before queue slot `k` (the running job's for `k = 0`).
    fn queue_target_before(&self, k: usize) -> Option<f64> {
        if k == 0 {
            return self.running_target();
        }
        let i = (self.queue.head + k - 1) % JOB_QUEUE_CAPACITY;
        match self.queue.slots.get(i).and_then(Option::as_ref)?.goal {
            QueuedGoal::Position(Target::Fixed(t)) => Some(t),
            _ => None,
        }
    }

    /// A motion job with a BufferMode ([`crate::objects::axis::Command::Buffered`]).
    pub(super) fn cmd_buffered(
        &mut self,
        motion: &BufferedMotion,
        mode: BufferMode,
    ) -> Result<JobId, ErrorId> {
        if mode == BufferMode::Aborting {
            return self.apply(&motion.aborting());
        }
        // Not while a synchronous operation is active or pending (S7-Technology 8055).
        if self.sync.is_some() || self.sync_pending.is_some() {
            return Err(ErrorId::BufferModeNotAllowed);
        }
        if self.main.is_none() {
            return self.apply(&motion.aborting());
        }
        let velocity_job = matches!(motion, BufferedMotion::MoveVelocity { .. });
        if !velocity_job {
            self.require_positioning()?;
        }
        self.check_motion_allowed()?;
        let before = self.before().ok_or(ErrorId::BufferModeNotAllowed)?;
        if !bufferable(before.instr) || (velocity_job && before.instr == Instruction::MoveVelocity)
        {
            return Err(ErrorId::BufferModeNotAllowed);
        }
        if self.queue.len() >= JOB_QUEUE_CAPACITY {
            return Err(ErrorId::NoJobMemory);
        }
        let a = self.queued_goal(motion, before)?;
        // Checked: nothing has changed so far. From here the job is accepted.
        self.warn_clamped(a.clamped);
        let instr = a.instr;
        let job = QueuedJob {
            id: self.new_id(),
            instr,
            mode,
            goal: a.goal,
            lim: a.lim,
            position_controlled: a.position_controlled,
            end_v: 0.0,
        };
        if mode.is_blending() {
            if let Some(v) = seam_velocity(mode, before, &job) {
                self.set_seam(v);
            }
        }
        let id = job.id;
        // Capacity was checked above.
        let _ = self.queue.push(job);
        self.emit(id, instr, JobEventKind::Busy);
        Ok(id)
    }

    /// The instruction, goal, limits, clamping and position control of a queued job, checked.
    fn queued_goal(&self, motion: &BufferedMotion, before: Before) -> Result<Accepted, ErrorId> {
        let defaults = &self.cfg.defaults;
        let limits = &self.cfg.limits;
        match *motion {
            BufferedMotion::MoveVelocity {
                dynamics,
                direction,
                current,
                position_controlled,
            } => {
                let d = crate::kinematics::dynamics::Dynamics {
                    velocity: dynamics.velocity.abs(),
                    ..dynamics
                };
                let r = limits.resolve(defaults, &d, true)?;
                let speed = r.limits.vel;
                let v = match direction {
                    VelocityDirection::BySign => speed.copysign(dynamics.velocity),
                    VelocityDirection::Positive => speed,
                    VelocityDirection::Negative => -speed,
                };
                // As MC_MoveVelocity: the limit is the axis' maximum, the speed is the goal's.
                Ok(Accepted {
                    instr: Instruction::MoveVelocity,
                    goal: QueuedGoal::Velocity { v, current },
                    lim: Limits {
                        vel: limits.max_velocity,
                        ..r.limits
                    },
                    clamped: r.clamped,
                    position_controlled,
                })
            }
            BufferedMotion::MoveAbsolute {
                position,
                dynamics,
                direction,
            } => {
                if !position.is_finite() {
                    return Err(ErrorId::IllegalPosition);
                }
                if !self.homed {
                    return Err(ErrorId::NotHomed);
                }
                let r = limits.resolve(defaults, &dynamics, false)?;
                let target = match (self.cfg.modulo, before.target) {
                    (None, _) => Target::Fixed(position),
                    (Some(m), Some(prev)) => Target::Fixed(match direction {
                        Direction::Shortest => prev + m.shortest(prev, position),
                        Direction::Positive => prev + m.forward(prev, position),
                        Direction::Negative => prev - m.forward(position, prev),
                    }),
                    (Some(_), None) => Target::Modulo(position, direction),
                };
                Ok(Accepted {
                    instr: Instruction::MoveAbsolute,
                    goal: QueuedGoal::Position(target),
                    lim: r.limits,
                    clamped: r.clamped,
                    position_controlled: true,
                })
            }
            BufferedMotion::MoveRelative { distance, dynamics }
            | BufferedMotion::MoveAdditive { distance, dynamics } => {
                if !distance.is_finite() {
                    return Err(ErrorId::IllegalDistance);
                }
                let r = limits.resolve(defaults, &dynamics, false)?;
                let target = match before.target {
                    Some(prev) => Target::Fixed(prev + distance),
                    None => Target::FromStart(distance),
                };
                let instr = if matches!(motion, BufferedMotion::MoveRelative { .. }) {
                    Instruction::MoveRelative
                } else {
                    Instruction::MoveAdditive
                };
                Ok(Accepted {
                    instr,
                    goal: QueuedGoal::Position(target),
                    lim: r.limits,
                    clamped: r.clamped,
                    position_controlled: true,
                })
            }
        }
    }

    /// The job before the last queued one (or the running one) passes its target at `v`.
    fn set_seam(&mut self, v: f64) {
        if let Some(q) = self.queue.back_mut() {
            q.end_v = v;
            return;
        }
        let finished = self.main_motion_finished();
        if let Goal::Position { target, lim, .. } = self.goal {
            if !finished {
                self.set_goal(Goal::Position {
                    target,
                    lim,
                    end_v: v,
                });
            }
        }
    }

    /// Whether the queued job at the front takes over from the running job `m` now (its
    /// profile has ended): a blending job behind a positioning job at the seam, any job
    /// behind a MoveVelocity at InVelocity. Buffered jobs behind a positioning job start from
    /// [`Axis::finish_main`] when it is Done.
    pub(super) fn queue_takes_over(&self, m: &MotionJob, ovr_stopped: bool) -> bool {
        let Some(head) = self.queue.front() else {
            return false;
        };
        match (m.instr, self.goal) {
            (Instruction::MoveVelocity, Goal::Velocity { .. }) => true,
            (i, Goal::Position { .. }) if positioning(i) => {
                head.mode.is_blending() && !ovr_stopped && m.monitoring.is_none()
            }
            _ => false,
        }
    }

    /// The running job `m` hands over to the front of the queue (see
    /// [`Axis::queue_takes_over`]): a positioning job is Done at the seam, a MoveVelocity is
    /// InVelocity and then aborted.
    pub(super) fn hand_over(&mut self, m: MotionJob) {
        self.main = None;
        if m.instr == Instruction::MoveVelocity {
            if !m.in_velocity {
                self.emit(m.id, m.instr, JobEventKind::InVelocity);
            }
            self.emit(m.id, m.instr, JobEventKind::CommandAborted);
        } else {
            self.emit(m.id, m.instr, JobEventKind::Done);
        }
        self.start_queued();
    }

    /// Starts the job at the front of the queue from the current setpoint; false if there is
    /// none.
    pub(super) fn start_queued(&mut self) -> bool {
        let Some(q) = self.queue.pop() else {
            return false;
        };
        let here = self.basic.p;
        let goal = match q.goal {
            QueuedGoal::Position(t) => {
                self.set_position_control(true);
                let target = match t {
                    Target::Fixed(x) => x,
                    Target::FromStart(d) => here + d,
                    Target::Modulo(p, dir) => self.absolute_target(p, dir, &q.lim),
                };
                Goal::Position {
                    target,
                    lim: q.lim,
                    end_v: q.end_v,
                }
            }
            QueuedGoal::Velocity { v, current } => {
                self.set_position_control(q.position_controlled);
                let v = if current { self.total().v } else { v };
                Goal::Velocity { v, lim: q.lim }
            }
        };
        self.main = Some(MotionJob {
            id: q.id,
            instr: q.instr,
            in_velocity: false,
            monitoring: None,
            homing: None,
            jog: (false, false),
            lim: q.lim,
        });
        self.emit(q.id, q.instr, JobEventKind::Active);
        self.set_goal(goal);
        true
    }
}

/// The seam velocity (signed) between the job `before` and the queued job `next` for a
/// blending mode, or `None` when there is no seam (the job before has no target: the queued
/// job then starts at InVelocity).
fn seam_velocity(mode: BufferMode, before: Before, next: &QueuedJob) -> Option<f64> {
    let t1 = before.target?;
    let from = before.from?;
    let dir1 = (t1 - from).signum();
    let (dir2, v2) = match next.goal {
        QueuedGoal::Position(Target::Fixed(t2)) => ((t2 - t1).signum(), next.lim.vel),
        QueuedGoal::Position(_) => return Some(0.0),
        QueuedGoal::Velocity { v, current } => {
            if current {
                return Some(0.0);
            }
            (v.signum(), v.abs())
        }
    };
    // Inferred: a job that does not move (zero distance) passes its target at rest.
    if t1 == from || dir2 == 0.0 || v2 == 0.0 || dir1 != dir2 {
        return Some(0.0);
    }
    Some(dir1 * mode.seam_speed(before.speed, v2))
}
