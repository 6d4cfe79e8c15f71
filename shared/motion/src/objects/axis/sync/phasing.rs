//! Phasing and offsets of a synchronous operation: MC_PhasingAbsolute / MC_PhasingRelative
//! shift the leading value, MC_OffsetAbsolute / MC_OffsetRelative the following value, each
//! with a profile of the shift.

use super::job::{PhasingJob, SyncPhase};
use crate::catalog::error_id::ErrorId;
use crate::catalog::override_table::NewJob;
use crate::kinematics::dynamics::Dynamics;
use crate::kinematics::profile::Profile;
use crate::kinematics::profile::{plan_position, State};
use crate::objects::axis::Axis;
use crate::objects::job::{Instruction, JobEventKind, JobId};

impl Axis {
    pub(in crate::objects::axis) fn cmd_phasing(
        &mut self,
        shift: f64,
        absolute: bool,
        dynamics: &Dynamics,
    ) -> Result<JobId, ErrorId> {
        self.require_synchronous()?;
        if !shift.is_finite() {
            return Err(ErrorId::IllegalPhaseShift);
        }
        let Some(s) = self.sync else {
            return Err(ErrorId::NoSynchronousOperation);
        };
        if s.instr == Instruction::GearInVelocity {
            // Phasing shifts a position coupling; velocity gearing has none.
            return Err(ErrorId::NoSynchronousOperation);
        }
        if s.instr == Instruction::CamIn {
            return Err(ErrorId::CammingActive);
        }
        if s.phase != SyncPhase::Synchronous {
            return Err(ErrorId::SynchronizingActive);
        }
        let (mut job, prof) = self.plan_shift(
            self.phase,
            (shift, absolute),
            dynamics,
            (Instruction::PhasingAbsolute, Instruction::PhasingRelative),
        )?;
        self.apply_table2(NewJob::Phasing);
        job.id = self.new_id();
        self.emit(job.id, job.instr, JobEventKind::Busy);
        self.phasing = Some(job);
        self.phasing_prof = prof;
        Ok(job.id)
    }

    /// A shift job (phasing or offset) and its profile from `current` to the value (absolute)
    /// or by it.
    fn plan_shift(
        &mut self,
        current: State,
        (value, absolute): (f64, bool),
        dynamics: &Dynamics,
        (abs_instr, rel_instr): (Instruction, Instruction),
    ) -> Result<(PhasingJob, Profile), ErrorId> {
        let r = self
            .cfg
            .limits
            .resolve(&self.cfg.defaults, dynamics, false)?;
        self.warn_clamped(r.clamped);
        let target = if absolute { value } else { current.p + value };
        let prof =
            plan_position(current, target, &r.limits).map_err(|_| ErrorId::IllegalDistance)?;
        let instr = if absolute { abs_instr } else { rel_instr };
        Ok((
            PhasingJob {
                id: 0,
                instr,
                t0: self.now,
            },
            prof,
        ))
    }

    pub(in crate::objects::axis) fn cmd_offset(
        &mut self,
        offset: f64,
        absolute: bool,
        dynamics: &Dynamics,
    ) -> Result<JobId, ErrorId> {
        self.require_synchronous()?;
        if !offset.is_finite() {
            return Err(ErrorId::IllegalSlaveOffset);
        }
        let Some(s) = self.sync else {
            return Err(ErrorId::NoSynchronousOperation);
        };
        if s.phase != SyncPhase::Synchronous {
            return Err(ErrorId::SynchronizingActive);
        }
        let (mut job, prof) = self.plan_shift(
            self.shift_out,
            (offset, absolute),
            dynamics,
            (Instruction::OffsetAbsolute, Instruction::OffsetRelative),
        )?;
        self.abort_offset(JobEventKind::CommandAborted);
        job.id = self.new_id();
        self.emit(job.id, job.instr, JobEventKind::Busy);
        self.offset_job = Some(job);
        self.offset_prof = prof;
        Ok(job.id)
    }
}
