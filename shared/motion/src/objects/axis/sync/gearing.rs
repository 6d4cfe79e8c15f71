//! Gearing: MC_GearIn, MC_GearInVelocity (relative gearing), MC_GearInPos (absolute gearing
//! with synchronization in advance) and MC_GearOut.

use super::job::{AbsoluteSync, SyncJob, SyncPhase};
use super::law::SyncLaw;
use crate::catalog::error_id::ErrorId;
use crate::catalog::override_table::NewJob;
use crate::kinematics::dynamics::Dynamics;
use crate::kinematics::profile::{Limits, State};
use crate::objects::axis::{Axis, Goal, SyncProfileReference};
use crate::objects::job::{Instruction, JobEventKind, JobId};
use crate::objects::leading::LeaderId;

fn ratio_of(num: i32, den: i32) -> Result<f64, ErrorId> {
    if num == 0 {
        return Err(ErrorId::IllegalRatioNumerator);
    }
    if den < 1 {
        return Err(ErrorId::IllegalRatioDenominator);
    }
    Ok(f64::from(num) / f64::from(den))
}

impl Axis {
    /// MC_GearIn, or MC_GearInVelocity when `velocity` is set.
    pub(in crate::objects::axis) fn cmd_gear_in(
        &mut self,
        master: LeaderId,
        num: i32,
        den: i32,
        dynamics: &Dynamics,
        velocity: bool,
    ) -> Result<JobId, ErrorId> {
        self.require_new_sync()?;
        self.check_motion_allowed()?;
        let ratio = ratio_of(num, den)?;
        let d = Dynamics {
            velocity: -1.0,
            ..*dynamics
        };
        let r = self.cfg.limits.resolve(&self.cfg.defaults, &d, true)?;
        self.warn_clamped(r.clamped);
        let id = self.new_id();
        let instr = if velocity {
            Instruction::GearInVelocity
        } else {
            Instruction::GearIn
        };
        self.emit(id, instr, JobEventKind::Busy);
        let lim = Limits {
            vel: self.cfg.limits.max_velocity,
            ..r.limits
        };
        let job = SyncJob {
            id,
            instr,
            master,
            ratio,
            lim,
            phase: SyncPhase::Synchronizing,
            law: SyncLaw::Gear {
                offset: 0.0,
                prev: State::default(),
            },
            ready: false,
        };
        self.activate_sync(job, NewJob::GearIn);
        Ok(id)
    }

    /// MC_GearInPos with the gear ratio `num / den` and the follower's sync position `ssp`.
    pub(in crate::objects::axis) fn cmd_gear_in_pos(
        &mut self,
        sync: &AbsoluteSync,
        (num, den): (i32, i32),
        ssp: f64,
    ) -> Result<JobId, ErrorId> {
        let AbsoluteSync {
            master,
            master_sync_position: msp,
            reference,
            master_start_distance: msd,
            ref dynamics,
            direction,
        } = *sync;
        self.require_new_sync()?;
        self.check_motion_allowed()?;
        let ratio = ratio_of(num, den)?;
        if !msp.is_finite() {
            return Err(ErrorId::IllegalMasterSyncPosition);
        }
        if !ssp.is_finite() {
            return Err(ErrorId::IllegalSlaveSyncPosition);
        }
        if reference == SyncProfileReference::Direct {
            // Direct setting is for MC_CamIn only.
            return Err(ErrorId::IllegalSyncProfileReference);
        }
        if reference == SyncProfileReference::MasterStartDistance && !(msd.is_finite() && msd > 0.0)
        {
            return Err(ErrorId::IllegalMasterStartDistance);
        }
        let r = self
            .cfg
            .limits
            .resolve(&self.cfg.defaults, dynamics, false)?;
        self.warn_clamped(r.clamped);
        let id = self.new_id();
        self.emit(id, Instruction::GearInPos, JobEventKind::Busy);
        let job = SyncJob {
            id,
            instr: Instruction::GearInPos,
            master,
            ratio,
            lim: r.limits,
            phase: SyncPhase::Pending,
            law: SyncLaw::absolute(msp, ssp, (ratio, 0.0), reference, msd, direction),
            ready: false,
        };
        // A pending job aborts nothing but an older pending one (tables 1 and 2, "pending").
        self.apply_override_table(NewJob::GearInPosPending);
        self.sync_pending = Some(job);
        self.lead[1] = None;
        Ok(id)
    }

    pub(in crate::objects::axis) fn cmd_gear_out(&mut self) -> Result<JobId, ErrorId> {
        self.require_synchronous()?;
        let Some(s) = self
            .sync
            .filter(|s| s.phase != SyncPhase::Pending && s.instr != Instruction::CamIn)
        else {
            return Err(ErrorId::NoSynchronousOperation);
        };
        let id = self.new_id();
        self.emit(id, Instruction::GearOut, JobEventKind::Busy);
        let v = self.basic.v;
        self.sync = None;
        self.emit(s.id, s.instr, JobEventKind::CommandAborted);
        self.abort_phasing(JobEventKind::CommandAborted);
        self.abort_offset(JobEventKind::CommandAborted);
        self.shift_out = State::default();
        self.phase = State::default();
        // PLCopen: the follower continues with the velocity it has (acceleration released).
        let lim = Limits {
            vel: self.cfg.limits.max_velocity.max(v.abs()),
            ..self.default_limits()
        };
        self.set_goal(Goal::Velocity { v, lim });
        self.emit(id, Instruction::GearOut, JobEventKind::Done);
        Ok(id)
    }
}
