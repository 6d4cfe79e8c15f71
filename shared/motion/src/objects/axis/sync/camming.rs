//! Camming of a synchronous axis (S7-1500T Motion Control V4.0 function manual, 3.5.7 'Camming' and
//! 10.12.5 'MC_CamIn V4'): the cam mapping
//! with offsets, scalings and application modes, the synchronization (shared with MC_GearInPos,
//! whose law it uses until the sync point), MC_CamOut, and the seamless change to a pending cam at
//! the end of a cam cycle.

use std::sync::Arc;

use super::job::{AbsoluteSync, SyncJob, SyncPhase};
use super::law::SyncLaw;
use crate::cam::Cam;
use crate::catalog::error_id::ErrorId;
use crate::catalog::override_table::NewJob;
use crate::kinematics::profile::{Limits, State};
use crate::objects::axis::{ApplicationMode, Axis, CamId, Goal, SyncProfileReference};
use crate::objects::job::{Instruction, JobEventKind, JobId};

/// How the leading value maps onto a cam and the cam onto the following value.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(in crate::objects::axis) struct CamMap {
    /// `MasterScaling` (> 0) and `SlaveScaling`, `SlaveOffset`.
    ms: f64,
    ss: f64,
    so: f64,
    /// `MasterSyncPosition` relative to the cam start.
    msp: f64,
    mode: ApplicationMode,
    /// The cam's leading range.
    c0: f64,
    c1: f64,
    /// `f(c1) - f(c0)`.
    rise: f64,
    /// Leader position where the current cam cycle starts (cam argument `c0`).
    x_cycle: f64,
    /// What is added to `ss * f + so`: appended cycles and the continuity at synchronization
    /// (the representation of a modulo follower, the direct setting).
    add: f64,
    /// Piece hint for the evaluation.
    hint: usize,
    /// A pending CamIn that takes over at the end of the active cam's cycle.
    at_cycle_end: bool,
}

/// What one synchronous cam evaluation did.
pub(in crate::objects::axis) enum CamStep {
    /// Synchronous; `true` if a cam end was passed (EndOfProfile).
    Running(bool),
    /// The once-through cam ended.
    Ended,
    /// The leading value left the cam where it cannot (should not happen): the job ends.
    Failed,
}

impl Axis {
    /// Hands the axis a cam for the next MC_CamIn naming `id` (interpolated off the cyclic
    /// path; the job keeps its own reference, so a new interpolation of the cam swaps atomically
    /// for later jobs and never under a running one).
    pub fn provide_cam(&mut self, id: CamId, cam: Arc<Cam>) {
        self.provided_cam = Some((id, cam));
    }

    /// MC_CamIn with the cam `cam_id` (provided just before), its offsets and scalings
    /// `(MasterOffset, SlaveOffset, MasterScaling, SlaveScaling)` and application mode.
    pub(in crate::objects::axis) fn cmd_cam_in(
        &mut self,
        sync: &AbsoluteSync,
        cam_id: CamId,
        (mo, so, ms, ss): (f64, f64, f64, f64),
        mode: ApplicationMode,
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
        // The job takes the provided reference once accepted (the runtime's table keeps its own).
        let cam = match &self.provided_cam {
            Some((id, cam)) if *id == cam_id => Arc::clone(cam),
            _ => return Err(ErrorId::IllegalObject),
        };
        if !mo.is_finite() {
            return Err(ErrorId::IllegalMasterOffset);
        }
        if !so.is_finite() {
            return Err(ErrorId::IllegalSlaveOffset);
        }
        if !(ms.is_finite() && ms > 0.0) {
            return Err(ErrorId::IllegalMasterScaling);
        }
        if !(ss.is_finite() && ss != 0.0) {
            return Err(ErrorId::IllegalSlaveScaling);
        }
        let (c0, c1) = cam.leading_range();
        if !(msp.is_finite() && msp >= 0.0 && c0 + msp <= c1) {
            return Err(ErrorId::SyncPositionOutsideCam);
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
        let at_sync = cam.following(c0 + msp).map_err(|e| e.error_id())?;
        let id = self.new_id();
        self.emit(id, Instruction::CamIn, JobEventKind::Busy);
        // Follower value, slope and curvature (in the leading value) at the sync point.
        let ssp = ss * at_sync.value + so;
        let slope = ss * at_sync.first_derivative / ms;
        let curv = ss * at_sync.second_derivative / (ms * ms);
        // A new cam while a cyclic cam runs: it takes over at the end of the current cycle.
        let at_cycle_end = self
            .sync
            .as_ref()
            .is_some_and(|s| s.instr == Instruction::CamIn)
            && self.cam_maps[0].is_some_and(|m| m.mode != ApplicationMode::Once);
        let job = SyncJob {
            id,
            instr: Instruction::CamIn,
            master,
            ratio: slope,
            lim: r.limits,
            phase: SyncPhase::Pending,
            law: SyncLaw::absolute(
                mo + ms * (c0 + msp),
                ssp,
                (slope, curv),
                reference,
                msd,
                direction,
            ),
            ready: false,
        };
        self.apply_override_table(NewJob::CamInPending);
        self.provided_cam = None;
        self.sync_pending = Some(job);
        self.lead[1] = None;
        self.cams[1] = Some(cam);
        self.cam_maps[1] = Some(CamMap {
            ms,
            ss,
            so,
            msp,
            mode,
            c0,
            c1,
            rise: 0.0,
            x_cycle: 0.0,
            add: 0.0,
            hint: 0,
            at_cycle_end,
        });
        Ok(id)
    }

    pub(in crate::objects::axis) fn cmd_cam_out(&mut self) -> Result<JobId, ErrorId> {
        self.require_synchronous()?;
        if !self
            .sync
            .is_some_and(|s| s.instr == Instruction::CamIn && s.phase != SyncPhase::Pending)
        {
            return Err(ErrorId::NoSynchronousOperation);
        }
        let id = self.new_id();
        self.emit(id, Instruction::CamOut, JobEventKind::Busy);
        self.end_sync_keep_velocity(JobEventKind::CommandAborted);
        self.emit(id, Instruction::CamOut, JobEventKind::Done);
        Ok(id)
    }

    /// Ends the active synchronous operation; the follower continues with its velocity.
    pub(in crate::objects::axis) fn end_sync_keep_velocity(&mut self, how: JobEventKind) {
        let v = self.basic.v;
        if let Some(s) = self.sync.take() {
            self.emit(s.id, s.instr, how);
        }
        self.cams[0] = None;
        self.cam_maps[0] = None;
        self.clear_shifts(JobEventKind::CommandAborted);
        let lim = Limits {
            vel: self.cfg.limits.max_velocity.max(v.abs()),
            ..self.default_limits()
        };
        self.set_goal(Goal::Velocity { v, lim });
    }

    /// A pending CamIn became the active job: its cam and map follow, the map anchored so that
    /// the cam's sync point is at `x_sync` and the follower continuous at `y_sync`.
    pub(in crate::objects::axis) fn activate_cam(&mut self, x_sync: f64, y_sync: f64) {
        self.cams[0] = self.cams[1].take();
        self.cam_maps[0] = self.cam_maps[1].take();
        let (Some(cam), Some(map)) = (self.cams[0].as_ref(), self.cam_maps[0].as_mut()) else {
            return;
        };
        map.x_cycle = x_sync - map.msp * map.ms;
        let f = cam
            .following_with_hint(map.c0 + map.msp, &mut map.hint)
            .unwrap_or_default();
        map.add = y_sync - (map.ss * f.value + map.so);
        map.rise = map.ss * cam.rise();
    }

    /// Whether the pending job is a CamIn waiting for the end of the active cam's cycle.
    pub(in crate::objects::axis) fn pending_at_cycle_end(&self) -> bool {
        self.sync_pending
            .is_some_and(|p| p.instr == Instruction::CamIn)
            && self.cam_maps[1].is_some_and(|m| m.at_cycle_end)
    }

    /// One synchronous evaluation of the active cam at the leading value `x` (position,
    /// velocity, acceleration), writing the basic setpoint.
    pub(in crate::objects::axis) fn cam_synchronous(&mut self, x: State) -> CamStep {
        let (Some(cam), Some(map)) = (self.cams[0].as_ref(), self.cam_maps[0].as_mut()) else {
            return CamStep::Failed;
        };
        let span = map.c1 - map.c0;
        let cycle_len = span * map.ms;
        let mut u = map.c0 + (x.p - map.x_cycle) / map.ms;
        let mut wrapped = false;
        let mut ended = false;
        for _ in 0..4 {
            if u > map.c1 {
                if map.mode == ApplicationMode::Once {
                    u = map.c1;
                    ended = true;
                    break;
                }
                map.x_cycle += cycle_len;
                if map.mode == ApplicationMode::CyclicAppending {
                    map.add += map.rise;
                }
                u -= span;
                wrapped = true;
            } else if u < map.c0 {
                if map.mode == ApplicationMode::Once {
                    u = map.c0;
                    ended = true;
                    break;
                }
                map.x_cycle -= cycle_len;
                if map.mode == ApplicationMode::CyclicAppending {
                    map.add -= map.rise;
                }
                u += span;
                wrapped = true;
            } else {
                break;
            }
        }
        let Ok(f) = cam.following_with_hint(u, &mut map.hint) else {
            return CamStep::Failed;
        };
        let (ms, ss) = (map.ms, map.ss);
        let d1 = ss * f.first_derivative / ms;
        let d2 = ss * f.second_derivative / (ms * ms);
        self.basic = State {
            p: ss * f.value + map.so + map.add,
            v: if ended { 0.0 } else { d1 * x.v },
            a: if ended {
                0.0
            } else {
                d2 * x.v * x.v + d1 * x.a
            },
        };
        if ended {
            CamStep::Ended
        } else {
            CamStep::Running(wrapped)
        }
    }

    /// At the end of a cycle of the active cam: a pending CamIn waiting for it takes over, the
    /// new cam starting where the leader is and the follower continuing from where it is.
    pub(in crate::objects::axis) fn cam_change_at_cycle_end(&mut self) {
        if !self.pending_at_cycle_end() {
            return;
        }
        let Some(mut p) = self.sync_pending.take() else {
            return;
        };
        let x_start = self.cam_maps[0].map(|m| m.x_cycle).unwrap_or(0.0);
        if let Some(old) = self.sync.take() {
            self.emit(old.id, old.instr, JobEventKind::CommandAborted);
        }
        self.clear_shifts(JobEventKind::CommandAborted);
        self.lead[0] = self.lead[1].or(self.lead[0]);
        if let Some(m) = self.cam_maps[1].as_mut() {
            // The new cam starts (cam argument c0) at the old cycle's end.
            m.msp = 0.0;
        }
        // The follower value at the boundary: the old cam at its start after the wrap (with the
        // appended rise), which for a cyclic cam is its value at the end.
        let y = match (self.cams[0].as_ref(), self.cam_maps[0].as_mut()) {
            (Some(cam), Some(m)) => {
                let f = cam
                    .following_with_hint(m.c0, &mut m.hint)
                    .unwrap_or_default();
                m.ss * f.value + m.so + m.add
            }
            _ => self.basic.p,
        };
        self.activate_cam(x_start, y);
        p.phase = SyncPhase::Synchronous;
        p.ready = true;
        self.emit(p.id, p.instr, JobEventKind::StartSync);
        self.emit(p.id, p.instr, JobEventKind::InSync);
        self.sync = Some(p);
    }
}
