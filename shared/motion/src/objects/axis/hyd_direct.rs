//! `MC_AxRtSetDirectOutput_BkPlcMc` and `MC_AxRtSetExtGenValues_BkPlcMc` (Beckhoff TwinCAT PLC
//! Hydraulic Positioning library, 4.4.7.7 and 4.4.7.8) on a hydraulic axis: a control value or
//! set values that do not come from the axis' own generator (the library's generator state
//! `iTcHydStateExtGenerated`).
//!
//! # MC_AxRtSetDirectOutput_BkPlcMc
//! "A rising edge at Enable activates the function. The axis is put into states
//! McState_Continuousmotion and iTcHydStateExtGenerated and Busy becomes TRUE. The control value
//! of the axis is updated with OutValue. The rate of change is specified through RampTime"
//! ("the time in which the control value would reach full scale"). "If Enable is set to FALSE,
//! the control value is brought to 0.0 using RampTime, and the function is terminated. Only then
//! does Busy become FALSE. If another function block takes over control of the axis … the
//! function block terminates its function and indicates CommandAborted."
//!
//! In tandem the command is sent again with its current inputs (`enable = true` with a new
//! `out_value` or `ramp_time` retargets the running job; `enable = false` ramps it to 0 and
//! the job is Done when the control value is 0). Each cycle the control value moves towards
//! `OutValue` by at most `dt / RampTime` (full scale 1.0 in `RampTime` seconds; `RampTime` 0:
//! at once). Decisions where the text is silent (inferred):
//! - **Which control value.** `OutValue` is the normalised control value that Finish processes
//!   (±1.0 = full scale = `fRefVelo`), taken in place of step 1 of Finish (`fFeedForward ·
//!   fSetVelo / fRefVelo + fLagCtrlOutput`; the position controller is off, its output 0). The
//!   library's `fOutput` cannot be meant: Finish (called in `MC_AxStandardBody_BkPlcMc` after the
//!   instructions) forms `fOutput` anew each cycle from the set velocity and the controller's
//!   output, as it does for `MC_AxCtrlPressure_BkPlcMc`, whose "control value" is written to
//!   `fSetSpeed` for Finish to "consider automatically". So Finish applies: area ratio, bend,
//!   overlap compensation (ramped in over 0…creep speed), `fZeroCompensation`, or the
//!   characteristic curve; then the drive stage's output form and reversal. `fFeedForward`
//!   does not weight it (it weights the generator's set velocity).
//! - **Range.** `OutValue` within ±1.0 (full scale), else refused with 16#8003 (the library's
//!   `dwTcHydErrCdSetVelo`); `RampTime` finite and not below 0, else 16#8004
//!   (`dwTcHydErrCdAcc`, bad dynamics).
//! - **Start.** The slew starts from the axis' current normalised set velocity (0 at
//!   standstill), so a direct output taking over a motion does not step. Refused as any
//!   motion (not enabled, an alarm, a stop's lock), and without the feed enable of the
//!   direction of `OutValue` (16#80F6, as the library's jog and joystick).
//! - **While it runs** the set position follows the actual one (no lag, no following error),
//!   the set velocity shows `OutValue · fRefVelo`, and the software limit supervision acts on
//!   it as on any motion.
//! - **End.** At 0 the job is Done and the axis holds its actual position in position control
//!   (the library's "the function is terminated" leaves the axis at standstill).
//!
//! # MC_AxRtSetExtGenValues_BkPlcMc
//! "If a rising edge is detected …, the axis is put in state McState_Synchronizedmotion and
//! iTcHydStateExtGenerated. If [Enable] is TRUE, the values of Position, Velocity and
//! TargetPosition are entered in the runtime variables of the axis. … If a falling edge is
//! detected …, the function block puts the axis in the state McState_Standstill. If the axis is
//! not at standstill at this time, it is stopped via the time-controlled ramp set in fStopRamp.
//! The generator function block of the axis should still be called cyclically. It deals with
//! position control …" (the text says Execute; the input is Enable).
//!
//! In tandem the command is sent each cycle with the values of that cycle (from a script, the
//! node's command path, or a remote leader: an update is one write of the goal, no event);
//! they are the axis' set position and set velocity of the cycle, with the position controller
//! and its velocity feed forward closed on them, and the following error, the software limits
//! and the monitoring as for any motion. The set acceleration is the change of `Velocity` since
//! the last cycle's. `TargetPosition` is shown as the axis' target
//! ([`HydraulicStatus::target`](super::HydraulicStatus::target)). Decisions (inferred):
//! - `enable = false` ends the job (Done; the block has no Busy or Done, only Error) and the
//!   axis is in Standstill at once, as the text says; a set velocity other than 0 ramps down on
//!   the axis' generator with `fRefVelo / fStopRamp` from where it was (its `TcDec` stop), after
//!   which the generator holds the position it stopped at in position control.
//! - Values that are not finite are refused (16#8009 Position and TargetPosition, 16#8003
//!   Velocity) and change nothing; a running job keeps the last values. No dynamic limit is
//!   checked: the values are the application's (as MC_MotionInPosition's).
//! - A rising edge is refused as any motion is (not enabled, an alarm, a stop's lock); any
//!   other motion command aborts it (CommandAborted, as the PLCopen override rules).
//!
//! # MC_AxRtFollowUp_BkPlcMc
//! (4.4.9.3) "If Enable = TRUE, the actual position is copied to all target and set positions.
//! Target velocity, lag error and position controller output are set to 0.0. With a falling
//! edge at Enable, the axis will re-enable the position controller depending on parameters and
//! enables at the current actual position. … Because the position control is disabled, the axis
//! can drift. If the axis is to be moved by external actions, the required oil paths must be
//! opened by the application."
//!
//! In tandem `enable = true` starts the follow-up and `enable = false` ends it (each command Done
//! at once: the block has no outputs). While it is on, each cycle the set position (and the
//! generator's target) is the actual position, the set velocity 0 and the position controller
//! off, so Finish gives the valve only `fZeroCompensation` (the output that holds a compensated
//! valve still; the overlap compensation is 0 with no commanded value). Decisions (inferred):
//! - "should not be enabled for an axis that is performing an active movement": a running motion
//!   is aborted (CommandAborted) when it is enabled (the library would overwrite its set values
//!   every cycle); while it is on, motion is refused (16#80F0, as under a stop's lock, the
//!   library's `dwTcHydErrCdNotReady`); on a coupled follower it is refused (16#80A1: decouple
//!   first, as the library's stops).
//! - The I part of the position controller is held, not cleared (the text names the
//!   controller's output; `MC_AxUtiOffsetLatch_BkPlcMc` names the I part where it clears it).
//! - The axis shows Standstill (no motion job) while it follows up.
//!
//! # MC_AxUtiOffsetLatch_BkPlcMc
//! (4.4.9.5) "With a rising edge at Execute, Offset is updated with the current output of the
//! position controller", checked: "The axis must have a controller enable and must not be in an
//! active motion state or error state (… iTcHydStateIdle) (dwTcHydAdsErrBusy)"; "The detected
//! controller output must not be outside ±OffsetLimit (dwTcHydAdsErrIllegalValue)"; on an error
//! "the compensation remains unchanged". "Otherwise, offset is applied as the new compensation
//! value. Since from this point in time the part of the output value previously provided by the
//! position controller is taken over by the compensation, the output of the controller must be
//! canceled": once, the set and target positions := the actual one, the lag and the
//! controller's output 0, the default controller's I part wiped.
//!
//! In tandem each command with `execute = true` is a rising edge (Done at once, the new
//! `fZeroCompensation` in [`HydraulicStatus::zero_compensation`](super::HydraulicStatus));
//! `execute = false` does nothing (the block's outputs reset). Decisions (inferred):
//! - **Added, not replaced.** The controller's output (V: the normalised `fLagCtrlOutput` · 10 V)
//!   is added to the compensation in effect, so that the valve output does not change in the
//!   cycle of the latch: the text's reason ("the part … previously provided by the position
//!   controller is taken over by the compensation") holds only so; "applied as the new
//!   compensation" reads as the result. With the configured compensation 0 both readings agree.
//! - **The controller's output** is the P part `fLagAmp · (fSetPos - fActPos) / fRefVelo`
//!   (limited by `fLagAmpOutL`) of the cycle, as the analog connection computes it. With an I
//!   part configured (`fLagAmpTi` > 0) the latch is refused with 16#80F5: the axis does not see
//!   the I part the connection integrates, and latching without it would wipe the share the I
//!   part carries (a deviation; AutoZero serves such axes).
//! - **Refusals** in tandem's codes: not enabled 16#800F, an alarm 16#80F3, any motion or stop
//!   running (a job, a set velocity, the generator not idle, a direct output, a follow-up, a
//!   stop's lock) 16#80F0 (the library: `dwTcHydAdsErrBusy` 16#0708 for all of them);
//!   `OffsetLimit` below 0 or not finite, or the output beyond ±`OffsetLimit`, 16#80F5 (the
//!   library's `dwTcHydAdsErrIllegalValue` 16#0706). Each changes nothing.
//! - With MC_AxCtrlAutoZero_BkPlcMc in use, the latch writes its value (AutoZero goes on from
//!   it); AutoZero started later starts from the latched value.
//!
//! Pure and allocation-free: the state is two small `Copy` records, a flag and the latched
//! compensation in the hydraulic part of the axis.

use super::{Axis, Command, Goal};
use crate::catalog::error_id::ErrorId;
use crate::catalog::override_table::NewJob;
use crate::hydraulic::finish::FULL_SCALE_V;
use crate::hydraulic::generator::HydState;
use crate::hydraulic::profile_core::ProfileGenerator;
use crate::kinematics::profile::State;
use crate::objects::job::{Instruction, JobEventKind, JobId};

/// A control value slewed towards its target at a rate of full scale (1.0) per `RampTime`
/// (the library's `RampTime`: "the time in which the control value would reach full scale").
#[derive(Copy, Clone, Debug, PartialEq)]
pub(super) struct Slew {
    /// The control value now (normalised).
    value: f64,
    /// Where it goes.
    target: f64,
    /// Full scale per second (`1 / RampTime`; infinite for `RampTime` 0).
    rate: f64,
}

impl Slew {
    /// At `value`, going nowhere.
    fn at(value: f64) -> Self {
        Self {
            value,
            target: value,
            rate: f64::INFINITY,
        }
    }

    /// Towards `target` with full scale in `ramp_time` seconds (0: at once); `ramp_time` is
    /// checked by the caller (finite, not below 0).
    fn retarget(&mut self, target: f64, ramp_time: f64) {
        self.target = target;
        self.rate = if ramp_time > 0.0 {
            1.0 / ramp_time
        } else {
            f64::INFINITY
        };
    }

    /// One cycle of `dt` seconds: the value moves by at most `rate · dt` and lands exactly on
    /// the target. Returns the new value.
    fn step(&mut self, dt: f64) -> f64 {
        let max = self.rate * dt;
        let d = self.target - self.value;
        self.value = if d.abs() <= max {
            self.target
        } else {
            self.value + max.copysign(d)
        };
        self.value
    }
}

/// A running MC_AxRtSetDirectOutput_BkPlcMc.
#[derive(Copy, Clone, Debug, PartialEq)]
struct DirectRun {
    job: JobId,
    slew: Slew,
    /// `Enable` fell: the value ramps to 0 and the job ends there.
    releasing: bool,
}

/// A running MC_AxRtSetExtGenValues_BkPlcMc.
#[derive(Copy, Clone, Debug, PartialEq)]
struct ExtGenRun {
    job: JobId,
    /// `TargetPosition`.
    target: f64,
}

/// The state of the instructions of this module on one hydraulic axis.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub(super) struct HydDirect {
    direct: Option<DirectRun>,
    ext_gen: Option<ExtGenRun>,
    /// MC_AxRtFollowUp_BkPlcMc's `Enable`.
    follow_up: bool,
    /// `fZeroCompensation` (V) as MC_AxUtiOffsetLatch_BkPlcMc last latched it (without
    /// AutoZero).
    latched_zero: Option<f64>,
}

impl HydDirect {
    /// `fZeroCompensation` (V) as MC_AxUtiOffsetLatch_BkPlcMc last latched it; `None`: never
    /// (or into AutoZero's).
    pub(super) fn latched_zero(&self) -> Option<f64> {
        self.latched_zero
    }
}

/// Nothing running (an electric axis' state).
const IDLE: HydDirect = HydDirect {
    direct: None,
    ext_gen: None,
    follow_up: false,
    latched_zero: None,
};

/// The largest `|OutValue|`: full scale.
const FULL_SCALE: f64 = 1.0;

impl Axis {
    /// MC_AxRtSetDirectOutput_BkPlcMc and MC_AxRtSetExtGenValues_BkPlcMc (16#8002 on an
    /// electric axis or for any other command).
    pub(super) fn apply_hyd_direct(&mut self, cmd: &Command) -> Result<JobId, ErrorId> {
        if self.hyd.is_none() {
            return Err(ErrorId::IllegalObject);
        }
        match *cmd {
            Command::SetDirectOutput {
                enable,
                out_value,
                ramp_time,
            } => self.cmd_direct_output(enable, out_value, ramp_time),
            Command::SetExtGenValues {
                enable,
                position,
                velocity,
                target_position,
            } => self.cmd_ext_gen(enable, position, velocity, target_position),
            Command::FollowUp { enable } => self.cmd_follow_up(enable),
            Command::OffsetLatch {
                execute,
                offset_limit,
            } => self.cmd_offset_latch(execute, offset_limit),
            _ => Err(ErrorId::IllegalObject),
        }
    }

    /// The state of this module's instructions (borrowed: looked at every cycle).
    fn direct_state(&self) -> &HydDirect {
        self.hyd.as_deref().map_or(&IDLE, |h| &h.cmds.direct)
    }

    fn set_direct_state(&mut self, f: impl FnOnce(&mut HydDirect)) {
        if let Some(h) = self.hyd.as_deref_mut() {
            f(&mut h.cmds.direct);
        }
    }

    /// Whether job `job` is still the axis' motion job (not aborted, not ended).
    fn still_main(&self, job: JobId) -> bool {
        self.main.is_some_and(|m| m.id == job)
    }

    /// MC_AxRtSetDirectOutput_BkPlcMc with its inputs of now (the module documentation).
    fn cmd_direct_output(
        &mut self,
        enable: bool,
        out_value: f64,
        ramp_time: f64,
    ) -> Result<JobId, ErrorId> {
        let running = self
            .direct_state()
            .direct
            .filter(|r| self.still_main(r.job));
        if !enable {
            let Some(mut run) = running else {
                return Ok(0);
            };
            // Brought to 0 with the RampTime it runs with.
            run.slew.target = 0.0;
            run.releasing = true;
            self.set_direct_state(|d| d.direct = Some(run));
            return Ok(run.job);
        }
        if !(out_value.is_finite() && out_value.abs() <= FULL_SCALE) {
            return Err(ErrorId::IllegalVelocity);
        }
        if !(ramp_time.is_finite() && ramp_time >= 0.0) {
            return Err(ErrorId::IllegalAcceleration);
        }
        if let Some(mut run) = running {
            run.slew.retarget(out_value, ramp_time);
            run.releasing = false;
            self.set_direct_state(|d| d.direct = Some(run));
            return Ok(run.job);
        }
        self.check_motion_allowed()?;
        if out_value != 0.0 {
            self.hyd_check_feed(self.actual_p + out_value)?;
        }
        let ref_velo = self.hyd.as_deref().map_or(1.0, |h| h.ref_velo);
        self.apply_override_table(NewJob::Positioning);
        self.fold_superimposed();
        self.hyd_disengage();
        let v = self.basic.v;
        let lim = self.default_limits();
        let job = self.start_main(
            Instruction::SetDirectOutput,
            lim,
            Goal::Direct {
                position: None,
                v,
                a: 0.0,
            },
        );
        let mut slew = Slew::at((v / ref_velo).clamp(-FULL_SCALE, FULL_SCALE));
        slew.retarget(out_value, ramp_time);
        self.set_direct_state(|d| {
            d.direct = Some(DirectRun {
                job,
                slew,
                releasing: false,
            });
        });
        Ok(job)
    }

    /// The control value of a running MC_AxRtSetDirectOutput_BkPlcMc, which Finish takes in
    /// place of the set velocity and the position controller's output (`None`: none runs).
    pub(super) fn hyd_direct_output(&self) -> Option<f64> {
        self.direct_state()
            .direct
            .filter(|r| self.still_main(r.job))
            .map(|r| r.slew.value)
    }

    /// One cycle's setpoint of MC_AxRtFollowUp_BkPlcMc or of a running
    /// MC_AxRtSetDirectOutput_BkPlcMc (before the generator): following up, the set position
    /// at the actual one at rest; a direct output's control value one slew step on, the set
    /// velocity `value · fRefVelo`, the set position at the actual one. Returns whether either
    /// ran.
    pub(super) fn hyd_direct_generate(&mut self) -> bool {
        // Looked at by reference: most cycles of most axes run neither (no copy of the state).
        let (follow_up, direct) = {
            let d = self.direct_state();
            (d.follow_up, d.direct)
        };
        if follow_up {
            self.follow_actual();
            return true;
        }
        let Some(mut run) = direct else {
            return false;
        };
        if !self.still_main(run.job) {
            self.set_direct_state(|d| d.direct = None);
            return false;
        }
        let (dt, v0) = (self.cfg.cycle, self.basic.v);
        let ref_velo = self.hyd.as_deref().map_or(1.0, |h| h.ref_velo);
        let v = run.slew.step(dt) * ref_velo;
        let a = (v - v0) / dt;
        self.set_direct_state(|d| d.direct = Some(run));
        self.basic = State {
            p: self.actual_p,
            v,
            a,
        };
        self.goal = Goal::Direct {
            position: None,
            v,
            a,
        };
        true
    }

    /// After the jobs' update: a released direct output at 0 is Done (the axis holds its
    /// actual position in position control); runs whose job is no longer the axis' (aborted)
    /// end.
    pub(super) fn hyd_direct_cycle(&mut self) {
        let d = self.direct_state();
        if d.direct.is_none() && d.ext_gen.is_none() {
            return;
        }
        let state = *d;
        if let Some(run) = state.direct {
            if !self.still_main(run.job) {
                self.set_direct_state(|d| d.direct = None);
            } else if run.releasing && run.slew.value == 0.0 {
                self.set_direct_state(|d| d.direct = None);
                self.basic = State::rest(self.actual_p);
                self.finish_main(run.job, Instruction::SetDirectOutput);
            }
        }
        if let Some(run) = state.ext_gen {
            if !self.still_main(run.job) {
                self.set_direct_state(|d| d.ext_gen = None);
            }
        }
    }

    /// MC_AxRtSetExtGenValues_BkPlcMc with its inputs of now (the module documentation).
    fn cmd_ext_gen(
        &mut self,
        enable: bool,
        position: f64,
        velocity: f64,
        target_position: f64,
    ) -> Result<JobId, ErrorId> {
        let running = self
            .direct_state()
            .ext_gen
            .filter(|r| self.still_main(r.job));
        if !enable {
            return Ok(running.map_or(0, |run| self.ext_gen_release(run.job)));
        }
        if !(position.is_finite() && target_position.is_finite()) {
            return Err(ErrorId::IllegalPosition);
        }
        if !velocity.is_finite() {
            return Err(ErrorId::IllegalVelocity);
        }
        let a = (velocity - self.basic.v) / self.cfg.cycle;
        let goal = Goal::Direct {
            position: Some(position),
            v: velocity,
            a: if a.is_finite() { a } else { 0.0 },
        };
        if let Some(run) = running {
            self.goal = goal;
            self.set_direct_state(|d| {
                d.ext_gen = Some(ExtGenRun {
                    target: target_position,
                    ..run
                });
            });
            return Ok(run.job);
        }
        self.check_motion_allowed()?;
        self.apply_override_table(NewJob::MotionIn);
        self.fold_superimposed();
        self.force_position_control();
        self.hyd_disengage();
        let lim = self.default_limits();
        let job = self.start_main(Instruction::SetExtGenValues, lim, goal);
        self.goal = goal;
        self.set_direct_state(|d| {
            d.ext_gen = Some(ExtGenRun {
                job,
                target: target_position,
            });
        });
        Ok(job)
    }

    /// The falling edge of MC_AxRtSetExtGenValues_BkPlcMc: the job ends (Done) and the axis is
    /// in Standstill; the generator takes the setpoint over and, when the set velocity is not
    /// 0, stops it with `fRefVelo / fStopRamp` (its time ramp), then holds in position control.
    fn ext_gen_release(&mut self, job: JobId) -> JobId {
        self.set_direct_state(|d| d.ext_gen = None);
        if let Some(h) = self.hyd.as_deref_mut() {
            h.engaged = true;
        }
        self.finish_main(job, Instruction::SetExtGenValues);
        job
    }

    /// MC_AxRtFollowUp_BkPlcMc with its `Enable` of now (the module documentation): Done at
    /// once.
    fn cmd_follow_up(&mut self, enable: bool) -> Result<JobId, ErrorId> {
        let on = self.direct_state().follow_up;
        if enable && !on {
            if self.sync.is_some() || self.sync_pending.is_some() {
                return Err(ErrorId::SyncJobActive);
            }
            self.abort_main(JobEventKind::CommandAborted);
            self.abort_sup(JobEventKind::CommandAborted);
            self.hyd_disengage();
            self.set_direct_state(|d| d.follow_up = true);
            self.follow_actual();
        } else if !enable && on {
            // Position control again, at the actual position.
            self.set_direct_state(|d| d.follow_up = false);
            self.basic = State::rest(self.actual_p);
            self.set_goal(Goal::Hold);
        }
        let id = self.new_id();
        self.emit(id, Instruction::FollowUp, JobEventKind::Busy);
        self.emit(id, Instruction::FollowUp, JobEventKind::Done);
        Ok(id)
    }

    /// The set position (and the generator's) at the actual position, at rest.
    fn follow_actual(&mut self) {
        let p = self.actual_p;
        self.basic = State::rest(p);
        self.goal = Goal::Direct {
            position: Some(p),
            v: 0.0,
            a: 0.0,
        };
        if let Some(h) = self.hyd.as_deref_mut() {
            h.gen.take_over(p, 0.0);
        }
    }

    /// MC_AxRtFollowUp_BkPlcMc is enabled: the position controller is off and motion is
    /// refused.
    pub(super) fn hyd_following_up(&self) -> bool {
        self.direct_state().follow_up
    }

    /// `fZeroCompensation` in effect (V): AutoZero's, else the latched one, else the
    /// configured one.
    pub(super) fn hyd_zero_compensation(&self) -> f64 {
        match self.hyd.as_deref() {
            Some(h) => h
                .auto_zero
                .map(|(a, _)| a.status().compensation)
                .or(h.cmds.direct.latched_zero)
                .unwrap_or(h.controller.finish.zero_compensation),
            None => 0.0,
        }
    }

    /// The refusals of MC_AxUtiOffsetLatch_BkPlcMc's state checks (the module documentation).
    fn check_offset_latch_idle(&self) -> Result<(), ErrorId> {
        if !self.enabled || self.power.disabling {
            return Err(ErrorId::NotEnabled);
        }
        if self.stopping_alarm_pending() {
            return Err(ErrorId::JobRejectedInErrorStop);
        }
        let state = self.direct_state();
        let generator_busy = self
            .hyd
            .as_deref()
            .is_some_and(|h| h.engaged && h.gen.state() != HydState::Idle);
        if self.main.is_some()
            || self.sup_job.is_some()
            || self.total().v != 0.0
            || generator_busy
            || state.follow_up
            || state.direct.is_some()
            || self.stop_lock
            || self.hyd_locked()
            || self.sync.is_some()
        {
            return Err(ErrorId::AxisLocked);
        }
        Ok(())
    }

    /// MC_AxUtiOffsetLatch_BkPlcMc's rising edge (`execute`), with `OffsetLimit` (V).
    fn cmd_offset_latch(&mut self, execute: bool, offset_limit: f64) -> Result<JobId, ErrorId> {
        let refused = ErrorId::IllegalControllerParameter;
        if !execute {
            return Ok(0);
        }
        if !(offset_limit.is_finite() && offset_limit >= 0.0) {
            return Err(refused);
        }
        self.check_offset_latch_idle()?;
        let (params, current) = match self.hyd.as_deref() {
            Some(h) => (h.controller, self.hyd_zero_compensation()),
            None => return Err(ErrorId::IllegalObject),
        };
        if params.lag_amp_ti > 0.0 {
            return Err(refused);
        }
        // The controller acts (not while target clamping presses): its P part of this cycle.
        let acting = self.pos_ctrl && self.hyd_position_control();
        let lag = if acting {
            self.total().p - self.actual_p
        } else {
            0.0
        };
        let u = params.lag_amp * lag / params.finish.ref_velo;
        let u = match params.lag_out_limit {
            l if l > 0.0 => u.clamp(-l, l),
            _ => u,
        };
        let offset = u * FULL_SCALE_V;
        if !(offset.is_finite() && offset.abs() <= offset_limit) {
            return Err(refused);
        }
        let new = (current + offset).clamp(-FULL_SCALE_V, FULL_SCALE_V);
        if let Some(h) = self.hyd.as_deref_mut() {
            match h.auto_zero.as_mut() {
                Some((a, _)) => a.set_compensation(new),
                None => h.cmds.direct.latched_zero = Some(new),
            }
        }
        let id = self.new_id();
        self.emit(id, Instruction::OffsetLatch, JobEventKind::Busy);
        // Once: the set and target positions at the actual one, the lag and the controller's
        // output 0 (the generator, if it holds the axis, takes the position over).
        self.fold_superimposed();
        self.basic = State::rest(self.actual_p);
        self.set_goal(Goal::Hold);
        self.emit(id, Instruction::OffsetLatch, JobEventKind::Done);
        Ok(id)
    }

    /// `TargetPosition` of a running MC_AxRtSetExtGenValues_BkPlcMc.
    pub(super) fn hyd_ext_gen_target(&self) -> Option<f64> {
        self.direct_state()
            .ext_gen
            .filter(|r| self.still_main(r.job))
            .map(|r| r.target)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    /// A cycle of 1/1024 s: the steps below are exact in binary floating point.
    const DT: f64 = 1.0 / 1024.0;

    /// RampTime 0.5 s for full scale: from 0 to 1.0 in exactly 512 cycles of 1/1024 s, each
    /// 1/512 of full scale (computed by hand: 0.5 s · 1024 cycles/s).
    #[test]
    fn full_scale_takes_exactly_ramp_time() {
        let mut s = Slew::at(0.0);
        s.retarget(1.0, 0.5);
        for n in 1..=512 {
            let v = s.step(DT);
            assert_eq!(v, f64::from(n) / 512.0, "cycle {n}");
        }
        assert_eq!(s.step(DT), 1.0);
        // Down to -0.25 is 1.25 of full scale: 1.25 RampTime, 640 cycles, landing exactly.
        s.retarget(-0.25, 0.5);
        for n in 1..=640 {
            assert_eq!(s.step(DT), 1.0 - f64::from(n) / 512.0, "cycle {n}");
        }
        assert_eq!(s.step(DT), -0.25);
    }

    /// Enable FALSE: the value ramps to 0 with the same RampTime and stays there; a target not
    /// on the step grid is landed on exactly.
    #[test]
    fn release_ramps_to_zero_and_lands_exactly() {
        let mut s = Slew::at(0.0);
        s.retarget(0.3, 2.0);
        let mut n = 0;
        while s.step(0.001) != 0.3 {
            n += 1;
            assert!(n < 1000, "not at 0.3");
        }
        // 0.3 of full scale at 0.0005 a cycle: 600 cycles (the last lands on 0.3).
        assert_eq!(n + 1, 600);
        s.target = 0.0;
        let mut last = 0.3;
        let mut m = 0;
        loop {
            let v = s.step(0.001);
            assert!(last - v <= 0.0005 + 1e-15 && v <= last, "{last} -> {v}");
            last = v;
            m += 1;
            if v == 0.0 {
                break;
            }
        }
        assert_eq!(m, 600);
        assert_eq!(s.step(0.001), 0.0);
    }

    /// RampTime 0: the value jumps to its target in one cycle.
    #[test]
    fn ramp_time_zero_is_a_step() {
        let mut s = Slew::at(0.2);
        s.retarget(-0.7, 0.0);
        assert_eq!(s.step(0.001), -0.7);
    }
}
