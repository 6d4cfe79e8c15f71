//! The synchronous operation jobs an axis keeps: the coupling job (its law and phase) and the
//! phasing / offset jobs that shift it.

use super::law::SyncLaw;
use crate::kinematics::dynamics::Dynamics;
use crate::kinematics::profile::Limits;
use crate::objects::axis::{SyncDirection, SyncProfileReference};
use crate::objects::job::{Instruction, JobId};
use crate::objects::leading::LeaderId;

/// Phase of a synchronous operation job.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(in crate::objects::axis) enum SyncPhase {
    /// Waiting for the start condition (Busy, neither StartSync nor InSync).
    Pending,
    /// Synchronizing (`StartSync`, StatusWord.X21).
    Synchronizing,
    /// Synchronous (`InGear` / `InSync`, StatusWord.X22).
    Synchronous,
}

/// A synchronous operation job. The law first (`repr(C)`): its discriminant is where an
/// `Option` of the job keeps whether there is one, which an axis' cycle reads next to the
/// state before it in the axis.
#[derive(Copy, Clone, Debug, PartialEq)]
#[repr(C)]
pub(in crate::objects::axis) struct SyncJob {
    pub law: SyncLaw,
    pub id: JobId,
    pub instr: Instruction,
    pub phase: SyncPhase,
    /// The law has been set up from the first leading value.
    pub ready: bool,
    pub master: LeaderId,
    pub ratio: f64,
    pub lim: Limits,
}

impl SyncJob {
    /// The follower's coordinates moved by `delta` (homing): the coupling moves with them.
    pub(in crate::objects::axis) fn shift_follower(&mut self, delta: f64) {
        self.law.shift_follower(delta);
    }
}

/// A phasing or offset job: the profile of the shift (leading value units for phasing, follower
/// units for offsets) starts at `t0`. The axis keeps the profile apart (its cycle looks at
/// whether a job runs, the profile is read only then).
#[derive(Copy, Clone, Debug, PartialEq)]
pub(in crate::objects::axis) struct PhasingJob {
    pub id: JobId,
    pub instr: Instruction,
    pub t0: i64,
}

/// The inputs shared by the absolute synchronizations (MC_GearInPos, MC_CamIn): the leader, where
/// and how the follower synchronizes, with which dynamics.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(in crate::objects::axis) struct AbsoluteSync {
    /// The leading value.
    pub master: LeaderId,
    /// `MasterSyncPosition`.
    pub master_sync_position: f64,
    /// `SyncProfileReference`.
    pub reference: SyncProfileReference,
    /// `MasterStartDistance`.
    pub master_start_distance: f64,
    /// `Velocity`, `Acceleration`, `Deceleration`, `Jerk` of the synchronization.
    pub dynamics: Dynamics,
    /// `SyncDirection`.
    pub direction: SyncDirection,
}
