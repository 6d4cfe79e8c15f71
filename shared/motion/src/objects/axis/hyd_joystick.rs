//! `MC_MoveJoySticked_BkPlcMc` (Beckhoff TwinCAT PLC Hydraulic Positioning library, 4.2.14) on
//! a hydraulic axis: a motion whose velocity comes from a proportional control unit.
//!
//! "The axis velocity is specified through JoyStick (±1.0) and fRefVelo. Changes in velocity
//! are accompanied by ramp limitation to fMaxAcc. If the axis moves towards an active software
//! limit switch, the velocity is limited, depending on the remaining distance, such that the
//! limit switch is approached correctly. A falling edge at Execute … if the axis is in motion,
//! it is decelerated with a stop ramp" (`fRefVelo / fStopRamp`). The axis shows
//! SynchronizedMotion while it runs (the library's `McState_Synchronizedmotion`).
//!
//! In tandem the command is sent again with its current inputs: `execute = true` with a new
//! `joystick` changes the velocity it ramps to; `execute = false` stops and the job is Done at
//! standstill. The set velocity ramps with `Acceleration` while its magnitude grows and
//! `Deceleration` while it falls (each 0: `fMaxAcc`; limited to `fMaxAcc`); the position
//! controller stays closed on the integrated set position (the library's generator state
//! `iTcHydStateExtGenerated`). Towards an active software limit the velocity is at most
//! the one from which the software limit supervision's stop (the axis' maximum deceleration
//! and jerk) ends within the remaining distance one cycle on, and never more than that
//! distance in one cycle, so the set position stops at the limit without crossing it or
//! raising alarm 533. Inferred: the deceleration towards the
//! limit is the job's `Deceleration`; the library names no value.

use super::{Axis, Goal};
use crate::catalog::error_id::ErrorId;
use crate::catalog::override_table::NewJob;
use crate::hydraulic::profile_core::ProfileGenerator;
use crate::kinematics::profile::Limits;
use crate::objects::job::{Instruction, JobEventKind, JobId};

/// A running MC_MoveJoySticked_BkPlcMc.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(super) struct JoyRun {
    job: JobId,
    /// The velocity it ramps to (`JoyStick · fRefVelo`).
    target: f64,
    /// The ramp while the velocity's magnitude grows, and while it falls (mm/s²).
    acc: f64,
    dec: f64,
}

impl Axis {
    /// `MC_MoveJoySticked_BkPlcMc` with its inputs (see the module documentation). Refused:
    /// `joystick` outside ±1.0 (16#8003), a ramp below 0 (16#8004 / 16#8005), and as any
    /// motion (not enabled, an alarm, a lock, the feed enable of the direction).
    pub(super) fn cmd_joystick(
        &mut self,
        execute: bool,
        joystick: f64,
        acceleration: f64,
        deceleration: f64,
    ) -> Result<JobId, ErrorId> {
        let (ref_velo, max_acc, stop_ramp, running) = match self.hyd.as_deref() {
            Some(h) => {
                let g = h.gen.params();
                (h.ref_velo, g.max_acc, g.stop_ramp, h.cmds.joystick)
            }
            None => return Err(ErrorId::IllegalObject),
        };
        let running = running.filter(|j| self.main.is_some_and(|m| m.id == j.job));
        if !execute {
            return Ok(self.joystick_release(running, ref_velo / stop_ramp));
        }
        if !(joystick.is_finite() && joystick.abs() <= 1.0) {
            return Err(ErrorId::IllegalVelocity);
        }
        let ramp = |given: f64, e: ErrorId| match given {
            g if g.is_finite() && g > 0.0 => Ok(g.min(max_acc)),
            0.0 => Ok(max_acc),
            _ => Err(e),
        };
        let acc = ramp(acceleration, ErrorId::IllegalAcceleration)?;
        let dec = ramp(deceleration, ErrorId::IllegalDeceleration)?;
        let target = (joystick * ref_velo)
            .clamp(-self.cfg.limits.max_velocity, self.cfg.limits.max_velocity);
        if let Some(run) = running {
            self.set_joystick(Some(JoyRun {
                target,
                acc,
                dec,
                ..run
            }));
            return Ok(run.job);
        }
        self.check_motion_allowed()?;
        if target != 0.0 {
            self.hyd_check_feed(self.actual_p + target)?;
        }
        self.apply_override_table(NewJob::Positioning);
        self.fold_superimposed();
        self.force_position_control();
        let v = self.basic.v;
        let lim = Limits {
            acc,
            dec,
            ..self.default_limits()
        };
        let job = self.start_main(
            Instruction::MoveJoySticked,
            lim,
            Goal::Direct {
                position: None,
                v,
                a: 0.0,
            },
        );
        self.set_joystick(Some(JoyRun {
            job,
            target,
            acc,
            dec,
        }));
        Ok(job)
    }

    /// `Execute` falls: a running motion stops with `dec` and is Done at standstill; without
    /// one the command is Done at once.
    fn joystick_release(&mut self, running: Option<JoyRun>, dec: f64) -> JobId {
        let Some(run) = running else {
            let id = self.new_id();
            self.emit(id, Instruction::MoveJoySticked, JobEventKind::Done);
            return id;
        };
        let lim = Limits {
            acc: dec,
            dec,
            ..self.default_limits()
        };
        if let Some(m) = self.main.as_mut() {
            m.lim = lim;
        }
        self.set_goal(Goal::Stop { lim });
        run.job
    }

    fn set_joystick(&mut self, run: Option<JoyRun>) {
        if let Some(h) = self.hyd.as_deref_mut() {
            h.cmds.joystick = run;
        }
    }

    /// One cycle of a running MC_MoveJoySticked_BkPlcMc: the set velocity one ramp step
    /// towards its target, limited before an active software limit; its stop Done at
    /// standstill. A job that is no longer the axis' (aborted) ends it.
    pub(super) fn hyd_joystick_cycle(&mut self) {
        let Some(run) = self.hyd.as_deref().and_then(|h| h.cmds.joystick) else {
            return;
        };
        let Some(m) = self.main.filter(|m| m.id == run.job) else {
            self.set_joystick(None);
            return;
        };
        if matches!(self.goal, Goal::Stop { .. }) {
            if self.main_motion_finished() {
                self.set_joystick(None);
                self.finish_main(m.id, m.instr);
            }
            return;
        }
        let dt = self.cfg.cycle;
        let (p, v0) = (self.basic.p, self.basic.v);
        let mut target = run.target;
        if let Some(sw) = self.cfg.sw_limits.filter(|_| self.homed) {
            let remaining = if target > 0.0 { sw.max - p } else { p - sw.min }.max(0.0);
            let cap = self.joystick_cap(run.dec, remaining).min(remaining / dt);
            target = target.clamp(-cap, cap);
        }
        let growing = target.abs() > v0.abs() && target * v0 >= 0.0;
        let rate = if growing { run.acc } else { run.dec } * dt;
        let v = v0 + (target - v0).clamp(-rate, rate);
        self.goal = Goal::Direct {
            position: None,
            v,
            a: (v - v0) / dt,
        };
    }

    /// The highest velocity from which the axis stops within `remaining` (mm) from two cycles
    /// on (this velocity acts from the next cycle, and the supervision predicts from the one
    /// after), as the software limit supervision predicts a stop (the axis' maximum
    /// deceleration and jerk, `dec` if lower): `v²/(2d) + v·(d/(2j) + 2·dt) <= remaining`.
    fn joystick_cap(&self, dec: f64, remaining: f64) -> f64 {
        let lim = &self.cfg.limits;
        let d = dec.min(lim.max_deceleration);
        let b = d / (2.0 * lim.max_jerk) + 2.0 * self.cfg.cycle;
        d * ((b * b + 2.0 * remaining / d).sqrt() - b)
    }
}
