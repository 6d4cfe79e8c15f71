//! Synchronous operation of a synchronous axis (S7-1500T Motion Control V4.0 function manual,
//! 3.5 'Synchronous axis technology object' and 10.12 'Synchronous motion'): one synchronous
//! operation with two laws, gearing (MC_GearIn, MC_GearInVelocity, MC_GearInPos, MC_GearOut) and
//! camming (MC_CamIn, MC_CamOut), plus phasing and offsets. The leading value is an input of each
//! cycle ([`Axis::set_leading_value`]); once synchronous, the follower setpoint is the coupling
//! function of the leading value, exactly.
//!
//! The parts, each depending only on the ones before it:
//! - [`law`]: the coupling laws as data and the math of the synchronization;
//! - [`job`]: the jobs an axis keeps (coupling job with its phase, phasing and offset jobs);
//! - this module: what every synchronous job shares (leaders, override table 2, aborts, start,
//!   simulation);
//! - [`gearing`] and [`camming`]: the commands of each law (camming also its cam mapping);
//! - [`phasing`]: phase shift and offset commands;
//! - [`flying`] (the law) and `flying_job` (its command and cycle): MC_FlyingGear_BkPlcMc of the
//!   Beckhoff hydraulic library, engaged and released in leader-position space;
//! - [`cycle`]: the cyclic part (start conditions, set-up, evaluation of the law, shifts).

mod camming;
mod cycle;
pub(in crate::objects::axis) mod flying;
mod flying_job;
mod gearing;
mod job;
mod law;
mod phasing;

pub(in crate::objects::axis) use camming::CamMap;
use job::AbsoluteSync;
pub(in crate::objects::axis) use job::{PhasingJob, SyncJob, SyncPhase};

use crate::catalog::error_id::ErrorId;
use crate::catalog::override_table::{table2, NewJob, RunningSync};
use crate::kinematics::profile::State;
use crate::objects::axis::{Axis, AxisKind, Command, Goal};
use crate::objects::job::{Instruction, JobEventKind, JobId};
use crate::objects::leading::{LeaderId, LeadingValue};

impl Axis {
    /// The leaders this axis needs leading values for in the next cycle (active job first).
    pub fn leaders(&self) -> [Option<LeaderId>; 2] {
        [
            self.sync.as_ref().map(|s| s.master),
            self.sync_pending.as_ref().map(|s| s.master),
        ]
    }

    /// Hands the axis the value of leader `id` for its next cycle (`None`: not available).
    pub fn set_leading_value(&mut self, id: LeaderId, lv: Option<LeadingValue>) {
        if self.sync.as_ref().map(|s| s.master) == Some(id) {
            self.lead[0] = lv;
        }
        if self.sync_pending.as_ref().map(|s| s.master) == Some(id) {
            self.lead[1] = lv;
        }
    }

    /// A new synchronous operation job: a synchronous axis, and no simulation running
    /// (16#8076).
    pub(in crate::objects::axis) fn require_new_sync(&self) -> Result<(), ErrorId> {
        self.require_synchronous()?;
        if self.sync_sim.is_some() {
            return Err(ErrorId::SyncSimulationActive);
        }
        Ok(())
    }

    /// `MC_SynchronizedMotionSimulation` (S7-1500T Motion Control V4.0 function manual,
    /// 3.5.10 'Simulate synchronous operation'): enable while synchronous; the coupling goes on
    /// logically while the follower's own setpoint stands (velocity 0) and survives a disable; at
    /// the end the coupling is output again, without a new synchronization.
    pub(in crate::objects::axis) fn cmd_sync_simulation(
        &mut self,
        enable: bool,
    ) -> Result<JobId, ErrorId> {
        self.require_synchronous()?;
        match (enable, self.sync_sim) {
            (true, Some(id)) => Ok(id),
            (true, None) => {
                if !self
                    .sync
                    .as_ref()
                    .is_some_and(|s| s.phase == SyncPhase::Synchronous)
                {
                    return Err(ErrorId::NoSynchronousOperation);
                }
                let id = self.new_id();
                self.sync_sim = Some(id);
                self.emit(
                    id,
                    Instruction::SynchronizedMotionSimulation,
                    JobEventKind::Busy,
                );
                self.emit(
                    id,
                    Instruction::SynchronizedMotionSimulation,
                    JobEventKind::InSimulation(true),
                );
                Ok(id)
            }
            (false, Some(id)) => {
                self.sync_sim = None;
                self.emit(
                    id,
                    Instruction::SynchronizedMotionSimulation,
                    JobEventKind::InSimulation(false),
                );
                self.emit(
                    id,
                    Instruction::SynchronizedMotionSimulation,
                    JobEventKind::Done,
                );
                if self.sync.is_some() && self.enabled {
                    // The coupling is output again (a step if the positions changed meanwhile).
                    self.abort_main(JobEventKind::CommandAborted);
                    self.goal = Goal::Sync;
                }
                Ok(id)
            }
            (false, None) => Ok(0),
        }
    }

    pub(in crate::objects::axis) fn require_synchronous(&self) -> Result<(), ErrorId> {
        if self.cfg.kind != AxisKind::Synchronous {
            return Err(ErrorId::IllegalObject);
        }
        Ok(())
    }

    /// The table-2 classes of the running synchronous operation jobs.
    fn running_sync(&self) -> [(RunningSync, bool); 3] {
        let active = self.sync.as_ref().map(|s| match s.instr {
            Instruction::GearInPos => RunningSync::GearInPosActive,
            Instruction::CamIn => RunningSync::CamInActive,
            _ => RunningSync::GearIn,
        });
        let pending = self.sync_pending.as_ref().map(|s| match s.instr {
            Instruction::CamIn => RunningSync::CamInPending,
            _ => RunningSync::GearInPosPending,
        });
        [
            (active.unwrap_or(RunningSync::GearIn), active.is_some()),
            (
                pending.unwrap_or(RunningSync::GearInPosPending),
                pending.is_some(),
            ),
            (RunningSync::Phasing, self.phasing.is_some()),
        ]
    }

    /// Aborts the synchronous operation jobs that `new` overrides (S7-1500T Motion Control V4.0
    /// function manual, 10.16 'Override response of Motion Control jobs V4' table 2).
    pub(in crate::objects::axis) fn apply_table2(&mut self, new: NewJob) {
        let [active, pending, phasing] = self.running_sync();
        // A simulated synchronous operation is not aborted by single-axis jobs.
        if active.1 && table2(new, active.0).aborts() && self.sync_sim.is_none() {
            self.abort_sync(JobEventKind::CommandAborted);
        }
        if pending.1 && table2(new, pending.0).aborts() {
            self.abort_pending(JobEventKind::CommandAborted);
        }
        if phasing.1 && table2(new, phasing.0).aborts() {
            self.abort_phasing(JobEventKind::CommandAborted);
        }
    }

    /// Ends the active synchronous operation (the phase shift is reset with it).
    pub(in crate::objects::axis) fn abort_sync(&mut self, how: JobEventKind) {
        if let Some(s) = self.sync.take() {
            self.emit(s.id, s.instr, how);
        }
        self.cams[0] = None;
        self.cam_maps[0] = None;
        self.clear_shifts(how);
        if self.goal == Goal::Sync {
            // The caller sets the next goal; until then hold the current motion.
            self.goal = Goal::Velocity {
                v: self.basic.v,
                lim: self.default_limits(),
            };
            self.replan();
        }
    }

    /// Drops the pending synchronous operation job.
    pub(in crate::objects::axis) fn abort_pending(&mut self, how: JobEventKind) {
        if let Some(p) = self.sync_pending.take() {
            self.emit(p.id, p.instr, how);
        }
        self.cams[1] = None;
        self.cam_maps[1] = None;
    }

    /// Ends phasing and offsets; their shifts are reset with the synchronous operation.
    pub(in crate::objects::axis) fn clear_shifts(&mut self, how: JobEventKind) {
        self.abort_phasing(how);
        self.abort_offset(how);
        self.phase = State::default();
        self.shift_out = State::default();
    }

    fn abort_phasing(&mut self, how: JobEventKind) {
        if let Some(p) = self.phasing.take() {
            self.emit(p.id, p.instr, how);
        }
    }

    fn abort_offset(&mut self, how: JobEventKind) {
        if let Some(o) = self.offset_job.take() {
            self.emit(o.id, o.instr, how);
        }
    }

    /// Starts an active synchronous operation job (table 1 and 2 as for an active sync job).
    fn activate_sync(&mut self, mut job: SyncJob, new: NewJob) {
        self.apply_override_table(new);
        self.fold_superimposed();
        self.force_position_control();
        // Until the first leading value sets the coupling up, the current motion goes on from
        // the (folded) setpoint.
        self.replan();
        job.ready = false;
        self.sync = Some(job);
    }

    /// Applies a synchronous operation command (gearing, camming, phasing, offsets, simulation).
    pub(in crate::objects::axis) fn apply_sync(&mut self, cmd: &Command) -> Result<JobId, ErrorId> {
        match *cmd {
            Command::GearIn {
                master,
                ratio_numerator,
                ratio_denominator,
                dynamics,
            } => self.cmd_gear_in(master, ratio_numerator, ratio_denominator, &dynamics, false),
            Command::GearInPos {
                master,
                ratio_numerator,
                ratio_denominator,
                master_sync_position,
                slave_sync_position,
                sync_profile_reference,
                master_start_distance,
                dynamics,
                sync_direction,
            } => self.cmd_gear_in_pos(
                &AbsoluteSync {
                    master,
                    master_sync_position,
                    reference: sync_profile_reference,
                    master_start_distance,
                    dynamics,
                    direction: sync_direction,
                },
                (ratio_numerator, ratio_denominator),
                slave_sync_position,
            ),
            Command::FlyingGear {
                master,
                enable,
                ref params,
            } => self.cmd_flying_gear(master, enable, params),
            Command::GearOut => self.cmd_gear_out(),
            Command::CamIn {
                master,
                cam,
                master_offset,
                slave_offset,
                master_scaling,
                slave_scaling,
                master_sync_position,
                sync_profile_reference,
                master_start_distance,
                dynamics,
                application_mode,
                sync_direction,
            } => self.cmd_cam_in(
                &AbsoluteSync {
                    master,
                    master_sync_position,
                    reference: sync_profile_reference,
                    master_start_distance,
                    dynamics,
                    direction: sync_direction,
                },
                cam,
                (master_offset, slave_offset, master_scaling, slave_scaling),
                application_mode,
            ),
            Command::CamOut => self.cmd_cam_out(),
            Command::SynchronizedMotionSimulation { enable } => self.cmd_sync_simulation(enable),
            Command::GearInVelocity {
                master,
                ratio_numerator,
                ratio_denominator,
                dynamics,
            } => self.cmd_gear_in(master, ratio_numerator, ratio_denominator, &dynamics, true),
            Command::Offset {
                offset,
                absolute,
                dynamics,
            } => self.cmd_offset(offset, absolute, &dynamics),
            Command::Phasing {
                phase_shift,
                absolute,
                dynamics,
            } => self.cmd_phasing(phase_shift, absolute, &dynamics),
            // Not a synchronous operation command: `apply` handles it (never passed here).
            _ => Err(ErrorId::IllegalObject),
        }
    }
}
