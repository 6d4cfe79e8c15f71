//! The Beckhoff TwinCAT PLC Hydraulic Positioning library's own stop and position instructions
//! on a hydraulic axis, where their semantics differ from S7's (the library's chapters
//! 4.2.5 'MC_EmergencyStop_BkPlcMc', 4.2.12 'MC_ImmediateStop_BkPlcMc', 4.2.17
//! 'MC_RampedStop_BkPlcMc', 4.1.13 'MC_SetPosition_BkPlcMc', 4.1.14
//! 'MC_SetReferenceFlag_BkPlcMc').
//!
//! - **MC_EmergencyStop_BkPlcMc**: the set velocity ramps to 0 on the displacement generator
//!   with `fRefVelo / RampTime` (`RampTime` not above 0: `fEmergencyRamp`,
//!   `iTcHydStateEmergencyBreak`); "once the control value output is reduced to 0, all control
//!   or regulating voltage outputs are suppressed, as long as Execute is set to TRUE"
//!   (`bLocked_Estop`): the valve output is 0, the set position follows the actual one, and
//!   motion is refused (16#80F0). `Execute = FALSE` (the command again with `execute = false`)
//!   releases the lock; the axis then holds where it stands.
//! - **MC_ImmediateStop_BkPlcMc**: "the control value of the axis is immediately set to 0,
//!   without any ramp", then the same lock.
//! - **MC_RampedStop_BkPlcMc**: a pure time ramp of the set velocity to 0 with `fRefVelo /
//!   RampTime`; "no defined end position is driven to and the axis can overrun a software
//!   limit switch". No lock; a new motion aborts it (inferred: as MC_Halt).
//! - **MC_SetPosition_BkPlcMc**: actual := `Position` (Mode FALSE) or actual + `Position` (Mode
//!   TRUE), also during a motion: the set position, the generator's target and set position and
//!   the target window move with it ("all other affected elements are automatically updated").
//! - **MC_SetReferenceFlag_BkPlcMc**: sets or clears the homed status.
//! - **MC_MoveJog_BkPlcMc** (4.2.19, `E_TcMcJogMode` 4.3.38): on a rising edge of an input
//!   (JogForward wins) a velocity motion with `fJogVeloSlow` / `fJogVeloFast` and the standard
//!   dynamics, or the command's velocity and dynamics (continuous), stopped when that input
//!   falls; or (inching) a relative positioning on the generator by `Position`, Done in the
//!   target window. No edge is accepted while the jog moves. The velocity modes run on
//!   tandem's profile with the loop closed, as every velocity motion of a hydraulic axis
//!   (inferred: the library runs MC_MoveVelocity_BkPlcMc as a positioning to the software
//!   limit); their stop uses the job's deceleration (inferred: the library's MC_Stop_BkPlcMc
//!   without Deceleration and RampTime takes `fMaxDec`).
//!
//! Refusals of the three stops, as the library's: an axis in error (16#80F3), one already
//! stopping (16#80F0, the library's `dwTcHydErrCdNotReady`), one coupled to another axis
//! (16#80A1, likewise); an axis that stands is Done at once. Every instruction here is refused
//! with 16#8002 on an electric axis.

use super::{reduce, Axis, Command, Goal, HydJogMode};
use crate::catalog::error_id::ErrorId;
use crate::catalog::override_table::NewJob;
use crate::hydraulic::profile_core::ProfileGenerator;
use crate::kinematics::dynamics::Dynamics;
use crate::kinematics::profile::{Limits, State};
use crate::objects::job::{Instruction, JobEventKind, JobId};

/// The lock of an emergency or immediate stop (`bLocked_Estop`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
struct StopLock {
    job: JobId,
    instr: Instruction,
    /// `Execute` is still TRUE.
    held: bool,
    /// The control value is 0: the valve output is suppressed.
    suppressing: bool,
}

/// A running MC_MoveJog_BkPlcMc.
#[derive(Copy, Clone, Debug, PartialEq)]
struct JogRun {
    job: JobId,
    mode: HydJogMode,
    positive: bool,
    lim: Limits,
}

/// The state of the library's instructions on a hydraulic axis.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(super) struct HydCommands {
    lock: Option<StopLock>,
    /// `fJogVeloSlow`, `fJogVeloFast`.
    jog_velo: [f64; 2],
    /// MC_MoveJog_BkPlcMc's inputs of the last command (for the rising edges).
    jog_inputs: (bool, bool),
    jog: Option<JogRun>,
    /// A running MC_MoveJoySticked_BkPlcMc.
    pub(super) joystick: Option<super::hyd_joystick::JoyRun>,
    /// A running MC_Home_BkPlcMc.
    pub(super) home: Option<super::hyd_home::HomeRun>,
    /// The reference cam's input signal (`[axes.<name>.inputs] reference_cam`).
    pub(super) cam_input: bool,
    /// MC_AxRtSetDirectOutput_BkPlcMc and MC_AxRtSetExtGenValues_BkPlcMc.
    pub(super) direct: super::hyd_direct::HydDirect,
}

impl HydCommands {
    /// Nothing running, with `fJogVeloSlow` and `fJogVeloFast`.
    pub(super) fn new(jog_velo: [f64; 2]) -> Self {
        Self {
            lock: None,
            jog_velo,
            jog_inputs: (false, false),
            jog: None,
            joystick: None,
            home: None,
            cam_input: false,
            direct: super::hyd_direct::HydDirect::default(),
        }
    }

    /// The valve output is suppressed (the lock of an emergency or immediate stop).
    pub(super) fn outputs_locked(&self) -> bool {
        self.lock.is_some_and(|l| l.suppressing)
    }
}

impl Axis {
    /// The library's instructions of this module.
    pub(super) fn apply_hyd_command(&mut self, cmd: &Command) -> Result<JobId, ErrorId> {
        if self.hyd.is_none() {
            return Err(ErrorId::IllegalObject);
        }
        match *cmd {
            Command::EmergencyStop { execute, ramp_time } => {
                self.cmd_locking_stop(Instruction::EmergencyStop, execute, ramp_time)
            }
            Command::ImmediateStop { execute } => {
                self.cmd_locking_stop(Instruction::ImmediateStop, execute, 0.0)
            }
            Command::RampedStop { ramp_time } => self.cmd_ramped_stop(ramp_time),
            Command::HydSetPosition { position, relative } => {
                self.cmd_hyd_set_position(position, relative)
            }
            Command::ResetAndStop {
                deceleration,
                ramp_time,
            } => self.cmd_reset_and_stop(deceleration, ramp_time),
            Command::HydMoveJog {
                forward,
                backward,
                mode,
                position,
                dynamics,
            } => self.cmd_hyd_jog(forward, backward, mode, position, &dynamics),
            Command::MoveJoySticked {
                execute,
                joystick,
                acceleration,
                deceleration,
            } => self.cmd_joystick(execute, joystick, acceleration, deceleration),
            Command::HydHome(ref inputs) => self.cmd_hyd_home(inputs),
            Command::SetReferenceFlag { reference_flag } => {
                Ok(self.instant_job(Instruction::SetReferenceFlag, |ax| {
                    ax.homed = reference_flag;
                }))
            }
            _ => Err(ErrorId::IllegalObject),
        }
    }

    /// A job that is Done at once after `f`.
    fn instant_job(&mut self, instr: Instruction, f: impl FnOnce(&mut Self)) -> JobId {
        let id = self.new_id();
        self.emit(id, instr, JobEventKind::Busy);
        f(self);
        self.emit(id, instr, JobEventKind::Done);
        id
    }

    /// The lock of an emergency or immediate stop holds (or its ramp still runs), or an
    /// MC_ResetAndStop_BkPlcMc stops the axis: motion is refused.
    pub(super) fn hyd_locked(&self) -> bool {
        self.hyd.as_deref().is_some_and(|h| h.cmds.lock.is_some())
            || self
                .main
                .is_some_and(|m| m.instr == Instruction::ResetAndStop)
    }

    /// The PLCopen state is Stopping: an emergency or immediate stop runs or holds its lock, or
    /// an MC_ResetAndStop_BkPlcMc runs (the library's MC_ReadStatus: "Stopping" for MC_Stop and
    /// MC_ResetAndStop).
    pub(super) fn hyd_stopping(&self, main: Option<Instruction>) -> bool {
        main == Some(Instruction::ResetAndStop) || self.hyd_locked()
    }

    /// The refusals of the library's stops (as MC_Stop_BkPlcMc's): not enabled, in error,
    /// already stopping, coupled.
    fn check_hyd_stop(&self) -> Result<(), ErrorId> {
        if !self.enabled || self.power.disabling {
            return Err(ErrorId::NotEnabled);
        }
        if self.stopping_alarm_pending() {
            return Err(ErrorId::JobRejectedInErrorStop);
        }
        let stopping = self.main.is_some_and(|m| m.instr == Instruction::Stop);
        if self.stop_lock || stopping || self.hyd_locked() {
            return Err(ErrorId::AxisLocked);
        }
        if self.sync.is_some() || self.sync_pending.is_some() {
            // The library: "controlled by a coupling with another axis" → NotReady.
            return Err(ErrorId::SyncJobActive);
        }
        Ok(())
    }

    /// Whether the axis carries out a motion (a job, or a set velocity other than 0).
    fn hyd_moving(&self) -> bool {
        self.main.is_some() || self.sup_job.is_some() || self.total().v != 0.0
    }

    /// `fRefVelo` and the generator's parameters.
    fn hyd_ramp(&self, ramp_time: f64, default_ramp: impl Fn(&Self) -> f64) -> f64 {
        let ref_velo = self.hyd.as_deref().map_or(1.0, |h| h.ref_velo);
        if ramp_time > 0.0 {
            ref_velo / ramp_time
        } else {
            ref_velo / default_ramp(self)
        }
    }

    /// Aborts the running motion and starts `instr` as a time ramp of the set velocity to 0
    /// with `dec` on the generator (engaged for it).
    fn start_generator_stop(&mut self, instr: Instruction, dec: f64) -> JobId {
        self.abort_main(JobEventKind::CommandAborted);
        self.abort_sup(JobEventKind::CommandAborted);
        self.force_position_control();
        if let Some(h) = self.hyd.as_deref_mut() {
            h.engaged = true;
        }
        let lim = Limits {
            acc: dec,
            dec,
            ..self.default_limits()
        };
        self.start_main(instr, lim, Goal::Stop { lim })
    }

    /// MC_EmergencyStop_BkPlcMc (`ramp_time`) and MC_ImmediateStop_BkPlcMc: with `execute` the
    /// stop and its lock; without, the lock is released.
    fn cmd_locking_stop(
        &mut self,
        instr: Instruction,
        execute: bool,
        ramp_time: f64,
    ) -> Result<JobId, ErrorId> {
        if !execute {
            return Ok(self.hyd_release(instr));
        }
        if !ramp_time.is_finite() {
            return Err(ErrorId::IllegalDeceleration);
        }
        self.check_hyd_stop()?;
        if instr == Instruction::ImmediateStop || !self.hyd_moving() {
            // The control value 0 at once (a standing axis: Done at once), then locked.
            let id = self.instant_job(instr, |ax| {
                ax.abort_main(JobEventKind::CommandAborted);
                ax.abort_sup(JobEventKind::CommandAborted);
                ax.hyd_suppress();
            });
            self.set_lock(Some(StopLock {
                job: id,
                instr,
                held: true,
                suppressing: true,
            }));
            return Ok(id);
        }
        let dec = self.hyd_ramp(ramp_time, |ax| {
            ax.hyd
                .as_deref()
                .map_or(1.0, |h| h.gen.params().emergency_ramp)
        });
        let id = self.start_generator_stop(instr, dec);
        if ramp_time <= 0.0 {
            // fEmergencyRamp: iTcHydStateEmergencyBreak.
            if let Some(h) = self.hyd.as_deref_mut() {
                h.gen.emergency_stop();
            }
        }
        self.set_lock(Some(StopLock {
            job: id,
            instr,
            held: true,
            suppressing: false,
        }));
        Ok(id)
    }

    fn set_lock(&mut self, lock: Option<StopLock>) {
        if let Some(h) = self.hyd.as_deref_mut() {
            h.cmds.lock = lock;
        }
    }

    /// The control value is 0 and the valve output suppressed: the set position follows the
    /// actual one (as on a disabled axis) and the generator is disengaged.
    fn hyd_suppress(&mut self) {
        self.fold_superimposed();
        self.basic = State::rest(self.actual_p);
        self.goal = Goal::Track;
        self.hyd_disengage();
    }

    /// `Execute = FALSE` of the stop that holds the lock: released (a ramp still running ends
    /// without it); the axis holds where it stands. Returns that stop's job (0: none).
    fn hyd_release(&mut self, instr: Instruction) -> JobId {
        let Some(mut l) = self.hyd.as_deref().and_then(|h| h.cmds.lock) else {
            return 0;
        };
        if l.instr != instr {
            return 0;
        }
        l.held = false;
        if l.suppressing {
            self.set_lock(None);
            if self.enabled {
                self.basic = State::rest(self.actual_p);
                self.set_goal(Goal::Hold);
            }
        } else {
            self.set_lock(Some(l));
        }
        l.job
    }

    /// One cycle of the library's instructions, after the jobs' update: an emergency stop whose
    /// ramp has reached 0 is Done and locks; a ramped stop that has reached 0 is Done.
    pub(super) fn hyd_commands_cycle(&mut self) {
        let Some(h) = self.hyd.as_deref() else {
            return;
        };
        if let Some(l) = h.cmds.lock {
            self.hyd_lock_cycle(l);
        }
        self.hyd_joystick_cycle();
        self.hyd_home_cycle();
        let Some(m) = self.main else {
            return;
        };
        let done = match m.instr {
            Instruction::RampedStop | Instruction::ResetAndStop => {
                self.hyd_finished() != Some(false)
            }
            Instruction::HydMoveJog if matches!(self.goal, Goal::Position { .. }) => {
                self.hyd_done() == Some(true)
            }
            Instruction::HydMoveJog if matches!(self.goal, Goal::Stop { .. }) => {
                self.main_motion_finished()
            }
            _ => false,
        };
        if done {
            self.finish_main(m.id, m.instr);
        }
    }

    fn hyd_lock_cycle(&mut self, mut l: StopLock) {
        if l.suppressing {
            if self.goal != Goal::Track {
                // Re-enabled while locked: still suppressed.
                self.hyd_suppress();
            }
            return;
        }
        let ours = self.main.is_some_and(|m| m.id == l.job);
        if ours && self.hyd_finished() == Some(false) {
            return;
        }
        if ours {
            self.main = None;
            self.emit(l.job, l.instr, JobEventKind::Done);
        }
        if l.held {
            l.suppressing = true;
            self.set_lock(Some(l));
            self.hyd_suppress();
        } else {
            self.set_lock(None);
            if ours {
                self.set_goal(Goal::Hold);
            }
        }
    }

    /// MC_RampedStop_BkPlcMc: the set velocity ramps to 0 in time with `fRefVelo / RampTime`
    /// (not above 0: `fStopRamp`, inferred); the axis stays where the ramp ends.
    fn cmd_ramped_stop(&mut self, ramp_time: f64) -> Result<JobId, ErrorId> {
        if !ramp_time.is_finite() {
            return Err(ErrorId::IllegalDeceleration);
        }
        self.check_hyd_stop()?;
        if !self.hyd_moving() {
            return Ok(self.instant_job(Instruction::RampedStop, |_| {}));
        }
        let dec = self.hyd_ramp(ramp_time, |ax| {
            ax.hyd.as_deref().map_or(1.0, |h| h.gen.params().stop_ramp)
        });
        Ok(self.start_generator_stop(Instruction::RampedStop, dec))
    }

    /// MC_ResetAndStop_BkPlcMc: the reset of MC_Reset (its own job), then, on an enabled
    /// axis that moves, a stop on the generator with `Deceleration`, else `fRefVelo /
    /// RampTime`, else `fMaxDec` (MC_Stop_BkPlcMc's order); Done at rest (at once on a standing
    /// or disabled axis). Refused with the error that the reset could not clear (16#80F3), while
    /// an emergency or immediate stop holds the axis (16#80F0) and on a coupled axis (16#80A1;
    /// inferred: decouple first, as for the library's stops).
    fn cmd_reset_and_stop(&mut self, deceleration: f64, ramp_time: f64) -> Result<JobId, ErrorId> {
        if !(deceleration.is_finite() && ramp_time.is_finite()) {
            return Err(ErrorId::IllegalDeceleration);
        }
        if self.hyd_locked() || self.stop_lock {
            return Err(ErrorId::AxisLocked);
        }
        if self.sync.is_some() || self.sync_pending.is_some() {
            return Err(ErrorId::SyncJobActive);
        }
        self.cmd_reset(false)?;
        if self.stopping_alarm_pending() {
            return Err(ErrorId::JobRejectedInErrorStop);
        }
        if !self.enabled || !self.hyd_moving() {
            return Ok(self.instant_job(Instruction::ResetAndStop, |_| {}));
        }
        let dec = if deceleration > 0.0 {
            deceleration
        } else {
            self.hyd_ramp(ramp_time, |ax| {
                // RampTime not above 0 either: fMaxDec, as a ramp time from fRefVelo.
                ax.hyd
                    .as_deref()
                    .map_or(1.0, |h| h.ref_velo / h.gen.params().max_dec)
            })
        };
        Ok(self.start_generator_stop(Instruction::ResetAndStop, dec))
    }

    /// MC_SetPosition_BkPlcMc: the actual position becomes `position` (or moves by it with
    /// `relative`); everything that depends on it moves with it, also during a motion. The
    /// homed status stays (MC_SetReferenceFlag_BkPlcMc sets it; inferred from the library
    /// having both).
    fn cmd_hyd_set_position(&mut self, position: f64, relative: bool) -> Result<JobId, ErrorId> {
        if !position.is_finite() {
            return Err(ErrorId::IllegalPosition);
        }
        let new = if relative {
            self.actual_p + position
        } else {
            position
        };
        let delta = reduce(self.cfg.modulo, new) - self.actual_p;
        if !delta.is_finite() {
            return Err(ErrorId::IllegalPosition);
        }
        Ok(self.instant_job(Instruction::SetPosition, |ax| ax.shift(delta)))
    }

    /// MC_MoveJog_BkPlcMc with its inputs of now: a running jog goes on (a velocity mode stops
    /// when the input of its direction falls); otherwise a rising edge starts one.
    fn cmd_hyd_jog(
        &mut self,
        forward: bool,
        backward: bool,
        mode: HydJogMode,
        position: f64,
        dynamics: &Dynamics,
    ) -> Result<JobId, ErrorId> {
        let Some(h) = self.hyd.as_deref_mut() else {
            return Err(ErrorId::IllegalObject);
        };
        let (was_forward, was_backward) = h.cmds.jog_inputs;
        h.cmds.jog_inputs = (forward, backward);
        let (jog, jog_velo) = (h.cmds.jog, h.cmds.jog_velo);
        let running = jog.filter(|j| self.main.is_some_and(|m| m.id == j.job));
        if let Some(j) = running {
            let held = if j.positive { forward } else { backward };
            if j.mode != HydJogMode::Inching && !held && !matches!(self.goal, Goal::Stop { .. }) {
                self.set_goal(Goal::Stop { lim: j.lim });
            }
            return Ok(j.job);
        }
        let positive = forward && !was_forward;
        let negative = backward && !was_backward;
        if !(positive || negative) {
            return Ok(0);
        }
        let sign = if positive { 1.0 } else { -1.0 };
        // The library: 0.0 for Acceleration or Deceleration is the axis' default (Jerk is
        // reserved: the axis' default).
        let default0 = |x: f64| if x == 0.0 { -1.0 } else { x };
        let dynamics = Dynamics {
            acceleration: default0(dynamics.acceleration),
            deceleration: default0(dynamics.deceleration),
            jerk: -1.0,
            ..*dynamics
        };
        let id = match mode {
            HydJogMode::Inching => {
                let distance = position.abs() * sign;
                if distance == 0.0 {
                    return Err(ErrorId::IllegalDistance);
                }
                self.cmd_positioning(Instruction::HydMoveJog, distance, &dynamics, |ax, _| {
                    ax.basic.p + distance
                })?
            }
            _ => {
                let velocity = match mode {
                    HydJogMode::StandardSlow => jog_velo[0],
                    HydJogMode::StandardFast => jog_velo[1],
                    _ => dynamics.velocity.abs(),
                };
                let d = if mode == HydJogMode::Continuous {
                    Dynamics {
                        velocity,
                        ..dynamics
                    }
                } else {
                    Dynamics {
                        velocity,
                        ..Dynamics::DEFAULT
                    }
                };
                self.start_jog_velocity(sign, &d)?
            }
        };
        let lim = self.main.map_or_else(|| self.default_limits(), |m| m.lim);
        if let Some(h) = self.hyd.as_deref_mut() {
            h.cmds.jog = Some(JogRun {
                job: id,
                mode,
                positive,
                lim,
            });
        }
        Ok(id)
    }

    /// The velocity motion of a jog in direction `sign` with dynamics `d` (velocity below 1 %
    /// of `fRefVelo`: 16#8003, the library's `dwTcHydErrCdSetVelo`).
    fn start_jog_velocity(&mut self, sign: f64, d: &Dynamics) -> Result<JobId, ErrorId> {
        let ref_velo = self.hyd.as_deref().map_or(0.0, |h| h.ref_velo);
        if !(d.velocity.is_finite() && d.velocity >= 0.01 * ref_velo) {
            return Err(ErrorId::IllegalVelocity);
        }
        self.check_motion_allowed()?;
        self.hyd_check_feed(self.actual_p + sign)?;
        let r = self.cfg.limits.resolve(&self.cfg.defaults, d, true)?;
        self.warn_clamped(r.clamped);
        self.apply_override_table(NewJob::Positioning);
        self.fold_superimposed();
        self.force_position_control();
        let lim = Limits {
            vel: self.cfg.limits.max_velocity,
            ..r.limits
        };
        let v = sign * r.limits.vel;
        Ok(self.start_main(Instruction::HydMoveJog, lim, Goal::Velocity { v, lim }))
    }
}
