//! `MC_FlyingGear_BkPlcMc` on an axis: the command (level-driven `Enable`) and the cyclic
//! evaluation of its law ([`super::flying`]) in the synchronous operation.

use super::flying::{FlyingGear, FlyingGearError, FlyingGearParams, FlyingPhase};
use super::job::{SyncJob, SyncPhase};
use super::law::SyncLaw;
use crate::catalog::error_id::ErrorId;
use crate::catalog::override_table::NewJob;
use crate::kinematics::profile::State;
use crate::objects::axis::{sync_status, Axis};
use crate::objects::job::{Instruction, JobEventKind, JobId};
use crate::objects::leading::LeaderId;

impl From<FlyingGearError> for ErrorId {
    /// The S7 numbers whose meaning matches (docs/alarms-and-errors.md): `Ratio` 16#8017 (the
    /// gear ratio), `MasterSyncPosition` 16#8034, `SlaveSyncPosition` 16#8035, the other
    /// positions 16#8009, a moving follower 16#8003, the leader already inside the engage
    /// section 16#8026 (as MC_GearInPos when the leader is inside the start distance).
    fn from(e: FlyingGearError) -> Self {
        match e {
            FlyingGearError::Parameter { field: "Ratio" } => ErrorId::IllegalRatioNumerator,
            FlyingGearError::Parameter {
                field: "MasterSyncPosition",
            } => ErrorId::IllegalMasterSyncPosition,
            FlyingGearError::Parameter {
                field: "SlaveSyncPosition",
            } => ErrorId::IllegalSlaveSyncPosition,
            FlyingGearError::Parameter { .. } | FlyingGearError::StopPositionSide { .. } => {
                ErrorId::IllegalPosition
            }
            FlyingGearError::SlaveMoving { .. } => ErrorId::IllegalVelocity,
            FlyingGearError::MasterInsideEngageSection { .. } => {
                ErrorId::IllegalMasterStartDistance
            }
        }
    }
}

/// The synchronous operation phase (status bits SYNCHRONIZING / SYNCHRONOUS) of a flying phase.
fn sync_phase(p: FlyingPhase) -> SyncPhase {
    match p {
        FlyingPhase::Armed | FlyingPhase::Waiting | FlyingPhase::Stopped => SyncPhase::Pending,
        FlyingPhase::Engaging | FlyingPhase::Releasing => SyncPhase::Synchronizing,
        FlyingPhase::InSync => SyncPhase::Synchronous,
    }
}

impl Axis {
    /// `MC_FlyingGear_BkPlcMc` with `Enable` = `enable`. A rising `Enable` checks the inputs
    /// against the follower's set position (which must stand) and starts the job; the follower
    /// stands until the leader reaches the engage section. `Enable` TRUE again keeps the job
    /// (its id is returned). `Enable` FALSE ends it like the library's MC_GearOut_BkPlcMc
    /// ('MC_GearOut_BkPlcMc': the coupled motion becomes an independent motion with the same
    /// velocity; a standing follower stays standing) and reports Done.
    pub(in crate::objects::axis) fn cmd_flying_gear(
        &mut self,
        master: LeaderId,
        enable: bool,
        params: &FlyingGearParams,
    ) -> Result<JobId, ErrorId> {
        let running = self
            .sync
            .filter(|s| s.instr == Instruction::FlyingGear)
            .map(|s| s.id);
        match (enable, running) {
            (true, Some(id)) => Ok(id),
            (false, Some(id)) => {
                // inferred: the library ends a flying gear with its Enable only; how the follower
                // then moves is not said, so it is what MC_GearOut_BkPlcMc does with a coupling.
                self.end_sync_keep_velocity(JobEventKind::Done);
                Ok(id)
            }
            (false, None) => Ok(0),
            (true, None) => self.start_flying_gear(master, params),
        }
    }

    fn start_flying_gear(
        &mut self,
        master: LeaderId,
        params: &FlyingGearParams,
    ) -> Result<JobId, ErrorId> {
        self.require_new_sync()?;
        self.check_motion_allowed()?;
        let here = self.total();
        let gear = FlyingGear::new(*params, here.p)?;
        // inferred: the slave's start is where it stands at Enable ('Sample #1': "The slave was
        // positioned at 500.0 mm"); a moving one has no start position and is refused.
        if here.v != 0.0 {
            return Err(FlyingGearError::SlaveMoving { velocity: here.v }.into());
        }
        let id = self.new_id();
        self.emit(id, Instruction::FlyingGear, JobEventKind::Busy);
        let job = SyncJob {
            id,
            instr: Instruction::FlyingGear,
            master,
            ratio: params.ratio,
            lim: self.default_limits(),
            phase: SyncPhase::Pending,
            law: SyncLaw::Flying(gear),
            ready: false,
        };
        self.activate_sync(job, NewJob::GearIn);
        Ok(id)
    }

    /// The flying gear at leading value `x`: the follower's setpoint and the StartSync / InSync
    /// events when their phases begin. `None`: the leader was already inside the engage section
    /// at the first leading value (the job ended with 16#8026, the follower stands).
    pub(in crate::objects::axis) fn evaluate_flying(
        &mut self,
        x: State,
    ) -> Option<[Option<JobEventKind>; 2]> {
        let job = self.sync.as_mut()?;
        let SyncLaw::Flying(gear) = &mut job.law else {
            return None;
        };
        if let Err(e) = gear.start(x.p) {
            self.end_sync_keep_velocity(JobEventKind::Error(e.into()));
            return None;
        }
        let before = gear.phase();
        let f = gear.step(x.p);
        job.phase = sync_phase(f.phase);
        self.basic = State {
            p: f.position,
            v: f.slope * x.v,
            a: f.curvature * x.v * x.v + f.slope * x.a,
        };
        let mut events = [None; 2];
        if f.phase != before {
            events[0] = match f.phase {
                FlyingPhase::Engaging => Some(JobEventKind::StartSync),
                FlyingPhase::InSync => Some(JobEventKind::InSync),
                _ => None,
            };
            // A leader jump from waiting straight into sync reports both.
            if before == FlyingPhase::Waiting && f.phase == FlyingPhase::InSync {
                events = [Some(JobEventKind::StartSync), Some(JobEventKind::InSync)];
            }
        }
        Some(events)
    }

    /// The [`sync_status`] bits of a running flying gear (StartSync, InSync, Active).
    pub(in crate::objects::axis) fn flying_flags(&self) -> u8 {
        // Borrowed, not copied: every synchronous axis asks each cycle.
        let Some(SyncLaw::Flying(g)) = self.sync.as_ref().map(|s| &s.law) else {
            return 0;
        };
        let p = g.phase();
        let bit = |on: bool, b: u8| if on { b } else { 0 };
        bit(p.start_sync(), sync_status::FLYING_START_SYNC)
            | bit(p.in_sync(), sync_status::FLYING_IN_SYNC)
            | bit(p.active(), sync_status::FLYING_ACTIVE)
    }
}
