//! Synchronous operation of a synchronous axis (seed 001 §1.6, §3.2): relative gearing
//! (MC_GearIn), absolute gearing with synchronization in advance (MC_GearInPos), MC_GearOut and
//! phasing. The leading value is an input of each cycle ([`Axis::set_leading_value`]); once
//! synchronous, the follower setpoint is the coupling function of the leading value, exactly.

use super::camming::CamStep;
use super::{Axis, AxisKind, Goal, SyncDirection, SyncProfileReference};
use crate::alarm::{supplement, AlarmId};
use crate::dynamics::Dynamics;
use crate::error_id::ErrorId;
use crate::job::{Instruction, JobEventKind, JobId};
use crate::leading::{LeaderId, LeadingValue};
use crate::override_table::{table2, NewJob, RunningSync};
use crate::profile::{plan_position, plan_velocity, Limits, Profile, State};

/// Phase of a synchronous operation job.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(super) enum SyncPhase {
    /// Waiting for the start condition (Busy, neither StartSync nor InSync).
    Pending,
    /// Synchronizing (`StartSync`, StatusWord.X21).
    Synchronizing,
    /// Synchronous (`InGear` / `InSync`, StatusWord.X22).
    Synchronous,
}

/// A quintic polynomial of the leading value, on `[x0, x0 + len]` (len may be negative).
#[derive(Copy, Clone, Debug, PartialEq)]
pub(super) struct Quintic {
    x0: f64,
    len: f64,
    c: [f64; 6],
}

impl Quintic {
    /// The quintic with value, first and second derivative (in x) given at both ends.
    fn hermite(x0: f64, len: f64, start: (f64, f64, f64), end: (f64, f64, f64)) -> Self {
        let (p0, v0, a0) = (start.0, start.1 * len, start.2 * len * len);
        let (p1, v1, a1) = (end.0, end.1 * len, end.2 * len * len);
        let d = p1 - p0;
        let c = [
            p0,
            v0,
            0.5 * a0,
            10.0 * d - 6.0 * v0 - 4.0 * v1 - 0.5 * (3.0 * a0 - a1),
            -15.0 * d + 8.0 * v0 + 7.0 * v1 + 0.5 * (3.0 * a0 - 2.0 * a1),
            6.0 * d - 3.0 * (v0 + v1) - 0.5 * (a0 - a1),
        ];
        Self { x0, len, c }
    }

    /// The exact maxima of `|y''|` and `|y'''|` (in x) over the quintic: `y''` is a cubic in `u`
    /// with its extremes at the ends or where the quadratic `y'''` vanishes; `y'''` a quadratic.
    fn peak_curvature_and_jerk(&self) -> [f64; 2] {
        let c = &self.c;
        let l = self.len;
        let ddu = |u: f64| 2.0 * c[2] + u * (6.0 * c[3] + u * (12.0 * c[4] + u * 20.0 * c[5]));
        let dddu = |u: f64| 6.0 * c[3] + u * (24.0 * c[4] + u * 60.0 * c[5]);
        let mut a = ddu(0.0).abs().max(ddu(1.0).abs());
        // Roots of y''' = 60 c5 u^2 + 24 c4 u + 6 c3.
        let (qa, qb, qc) = (60.0 * c[5], 24.0 * c[4], 6.0 * c[3]);
        let mut roots = [f64::NAN; 2];
        if qa.abs() > 1e-300 {
            let disc = qb * qb - 4.0 * qa * qc;
            if disc >= 0.0 {
                let r = disc.sqrt();
                roots = [(-qb + r) / (2.0 * qa), (-qb - r) / (2.0 * qa)];
            }
        } else if qb.abs() > 1e-300 {
            roots[0] = -qc / qb;
        }
        for u in roots.into_iter().filter(|u| (0.0..=1.0).contains(u)) {
            a = a.max(ddu(u).abs());
        }
        // y'''' = 120 c5 u + 24 c4 vanishes at one point.
        let mut j = dddu(0.0).abs().max(dddu(1.0).abs());
        if c[5].abs() > 1e-300 {
            let u = -24.0 * c[4] / (120.0 * c[5]);
            if (0.0..=1.0).contains(&u) {
                j = j.max(dddu(u).abs());
            }
        }
        [a / (l * l), j / (l * l * l).abs()]
    }

    /// The exact maximum of `|y'|` (in x): the quartic `y'` has its extremes at the ends or
    /// where the cubic `y''` vanishes; `y''` is monotonic between the roots of `y'''`, so each
    /// of its roots is bracketed and found by bisection.
    fn peak_slope(&self) -> f64 {
        let c = &self.c;
        let du =
            |u: f64| c[1] + u * (2.0 * c[2] + u * (3.0 * c[3] + u * (4.0 * c[4] + u * 5.0 * c[5])));
        let ddu = |u: f64| 2.0 * c[2] + u * (6.0 * c[3] + u * (12.0 * c[4] + u * 20.0 * c[5]));
        let (qa, qb, qc) = (60.0 * c[5], 24.0 * c[4], 6.0 * c[3]);
        let mut cuts = [0.0, 1.0, 1.0, 1.0];
        let mut n = 1;
        if qa.abs() > 1e-300 {
            let disc = qb * qb - 4.0 * qa * qc;
            if disc >= 0.0 {
                let r = disc.sqrt();
                let (r1, r2) = ((-qb - r) / (2.0 * qa), (-qb + r) / (2.0 * qa));
                for u in [r1.min(r2), r1.max(r2)] {
                    if u > 0.0 && u < 1.0 {
                        cuts[n] = u;
                        n += 1;
                    }
                }
            }
        } else if qb.abs() > 1e-300 {
            let u = -qc / qb;
            if u > 0.0 && u < 1.0 {
                cuts[n] = u;
                n += 1;
            }
        }
        cuts[n] = 1.0;
        let mut m = du(0.0).abs().max(du(1.0).abs());
        for w in cuts[..=n].windows(2) {
            let (mut a, mut b) = (w[0], w[1]);
            let (fa, fb) = (ddu(a), ddu(b));
            if fa * fb > 0.0 {
                continue;
            }
            for _ in 0..36 {
                let mid = 0.5 * (a + b);
                if ddu(mid) * fa > 0.0 {
                    a = mid;
                } else {
                    b = mid;
                }
            }
            m = m.max(du(0.5 * (a + b)).abs());
        }
        m / self.len.abs()
    }

    /// Value, first, second and third derivative with respect to x.
    #[inline]
    fn eval(&self, x: f64) -> [f64; 4] {
        let u = (x - self.x0) / self.len;
        let c = &self.c;
        let p = c[0] + u * (c[1] + u * (c[2] + u * (c[3] + u * (c[4] + u * c[5]))));
        let du = c[1] + u * (2.0 * c[2] + u * (3.0 * c[3] + u * (4.0 * c[4] + u * 5.0 * c[5])));
        let ddu = 2.0 * c[2] + u * (6.0 * c[3] + u * (12.0 * c[4] + u * 20.0 * c[5]));
        let dddu = 6.0 * c[3] + u * (24.0 * c[4] + u * 60.0 * c[5]);
        let l = self.len;
        [p, du / l, ddu / (l * l), dddu / (l * l * l)]
    }
}

/// The coupling law of a job.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(super) enum SyncLaw {
    /// MC_GearIn: synchronizing is a relative profile (follower minus ratio times leader) that
    /// brings relative velocity and acceleration to zero (kept in the axis' profile slot, which
    /// the synchronous goal does not otherwise use); then `offset + ratio * x`.
    Gear {
        offset: f64,
        /// The leading value of the previous cycle (velocity gearing integrates its velocity).
        prev: State,
    },
    /// MC_GearInPos: synchronizing follows a quintic of the leading value from `x_start` to
    /// `x_sync`; then `y_sync + ratio * (x - x_sync)`.
    GearPos {
        msp: f64,
        ssp: f64,
        /// Slope and curvature (in the leading value) of the follower at the sync point: the
        /// ratio and 0 for gearing, the scaled cam's for camming (MC_CamIn uses this law for
        /// its synchronization, then the cam map).
        slope: f64,
        curv: f64,
        reference: SyncProfileReference,
        msd: f64,
        direction: SyncDirection,
        /// Direction the leader travels in (+1 / -1), fixed when the job first sees it.
        lead_dir: f64,
        x_sync: f64,
        x_start: f64,
        y_sync: f64,
        quintic: Option<Quintic>,
    },
}

/// A synchronous operation job.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(super) struct SyncJob {
    pub id: JobId,
    pub instr: Instruction,
    pub master: LeaderId,
    pub ratio: f64,
    pub lim: Limits,
    pub phase: SyncPhase,
    pub law: SyncLaw,
    /// The law has been set up from the first leading value.
    pub ready: bool,
}

impl SyncLaw {
    /// The absolute synchronization (MC_GearInPos, MC_CamIn) to the follower value `ssp` with
    /// `(slope, curvature)` when the leader is at `msp`.
    pub(super) fn absolute(
        msp: f64,
        ssp: f64,
        (slope, curv): (f64, f64),
        reference: SyncProfileReference,
        msd: f64,
        direction: SyncDirection,
    ) -> Self {
        SyncLaw::GearPos {
            msp,
            ssp,
            slope,
            curv,
            reference,
            msd,
            direction,
            lead_dir: 0.0,
            x_sync: 0.0,
            x_start: 0.0,
            y_sync: 0.0,
            quintic: None,
        }
    }
}

impl SyncJob {
    /// The follower's coordinates moved by `delta` (homing): the coupling moves with them.
    pub(super) fn shift_follower(&mut self, delta: f64) {
        match &mut self.law {
            SyncLaw::Gear { offset, .. } => *offset += delta,
            SyncLaw::GearPos {
                y_sync, quintic, ..
            } => {
                *y_sync += delta;
                if let Some(q) = quintic {
                    q.c[0] += delta;
                }
            }
        }
    }
}

/// A phasing job: a profile of the phase shift (leading value units).
#[derive(Copy, Clone, Debug, PartialEq)]
pub(super) struct PhasingJob {
    pub id: JobId,
    pub instr: Instruction,
    pub prof: Profile,
    pub t0: i64,
}

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
    pub(super) fn require_new_sync(&self) -> Result<(), ErrorId> {
        self.require_synchronous()?;
        if self.sync_sim.is_some() {
            return Err(ErrorId::SyncSimulationActive);
        }
        Ok(())
    }

    /// `MC_SynchronizedMotionSimulation` (seed 001 §1.6): enable while synchronous; the coupling
    /// goes on logically while the follower's own setpoint stands (velocity 0) and survives a
    /// disable; at the end the coupling is output again, without a new synchronization.
    pub(super) fn cmd_sync_simulation(&mut self, enable: bool) -> Result<JobId, ErrorId> {
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

    pub(super) fn require_synchronous(&self) -> Result<(), ErrorId> {
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

    /// Aborts the synchronous operation jobs that `new` overrides (seed 001 §3.3 table 2).
    pub(super) fn apply_table2(&mut self, new: NewJob) {
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
    pub(super) fn abort_sync(&mut self, how: JobEventKind) {
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
    pub(super) fn abort_pending(&mut self, how: JobEventKind) {
        if let Some(p) = self.sync_pending.take() {
            self.emit(p.id, p.instr, how);
        }
        self.cams[1] = None;
        self.cam_maps[1] = None;
    }

    /// Ends phasing and offsets; their shifts are reset with the synchronous operation.
    pub(super) fn clear_shifts(&mut self, how: JobEventKind) {
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

    /// MC_GearIn, or MC_GearInVelocity when `velocity` is set.
    pub(super) fn cmd_gear_in(
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

    #[allow(clippy::too_many_arguments)]
    pub(super) fn cmd_gear_in_pos(
        &mut self,
        master: LeaderId,
        num: i32,
        den: i32,
        msp: f64,
        ssp: f64,
        reference: SyncProfileReference,
        msd: f64,
        dynamics: &Dynamics,
        direction: SyncDirection,
    ) -> Result<JobId, ErrorId> {
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

    pub(super) fn cmd_gear_out(&mut self) -> Result<JobId, ErrorId> {
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

    pub(super) fn cmd_phasing(
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
        let mut job = self.plan_shift(
            self.phase,
            (shift, absolute),
            dynamics,
            (Instruction::PhasingAbsolute, Instruction::PhasingRelative),
        )?;
        self.apply_table2(NewJob::Phasing);
        job.id = self.new_id();
        self.emit(job.id, job.instr, JobEventKind::Busy);
        self.phasing = Some(job);
        Ok(job.id)
    }

    /// A shift profile (phasing or offset) from `current` to the value (absolute) or by it.
    fn plan_shift(
        &mut self,
        current: State,
        (value, absolute): (f64, bool),
        dynamics: &Dynamics,
        (abs_instr, rel_instr): (Instruction, Instruction),
    ) -> Result<PhasingJob, ErrorId> {
        let r = self
            .cfg
            .limits
            .resolve(&self.cfg.defaults, dynamics, false)?;
        self.warn_clamped(r.clamped);
        let target = if absolute { value } else { current.p + value };
        let prof =
            plan_position(current, target, &r.limits).map_err(|_| ErrorId::IllegalDistance)?;
        let instr = if absolute { abs_instr } else { rel_instr };
        Ok(PhasingJob {
            id: 0,
            instr,
            prof,
            t0: self.now,
        })
    }

    pub(super) fn cmd_offset(
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
        let mut job = self.plan_shift(
            self.shift_out,
            (offset, absolute),
            dynamics,
            (Instruction::OffsetAbsolute, Instruction::OffsetRelative),
        )?;
        self.abort_offset(JobEventKind::CommandAborted);
        job.id = self.new_id();
        self.emit(job.id, job.instr, JobEventKind::Busy);
        self.offset_job = Some(job);
        Ok(job.id)
    }

    /// The cyclic part: pending start conditions, set-up, the coupling law, job events.
    /// Runs after the basic setpoint of the current goal was computed for this cycle.
    pub(super) fn sync_step(&mut self) {
        if let Some(mut p) = self.sync_pending.filter(|_| !self.pending_at_cycle_end()) {
            match self.lead[1] {
                None => {
                    self.raise(AlarmId::LeaderMissing, supplement::NONE);
                    return;
                }
                Some(lv) => {
                    if let Some(started) = self.pending_start(&mut p, lv) {
                        self.sync_pending = None;
                        let camming = p.instr == Instruction::CamIn;
                        if started {
                            self.lead[0] = Some(lv);
                            self.apply_override_table(if camming {
                                NewJob::CamInActive
                            } else {
                                NewJob::GearInPosActive
                            });
                            self.fold_superimposed();
                            self.force_position_control();
                            self.emit(p.id, p.instr, JobEventKind::StartSync);
                            p.phase = SyncPhase::Synchronizing;
                            if camming {
                                if let SyncLaw::GearPos { x_sync, y_sync, .. } = p.law {
                                    self.activate_cam(x_sync, y_sync);
                                }
                            }
                            self.sync = Some(p);
                            self.goal = Goal::Sync;
                        } else if camming {
                            self.cams[1] = None;
                            self.cam_maps[1] = None;
                        }
                    } else {
                        self.sync_pending = Some(p);
                    }
                }
            }
        }
        let Some(mut job) = self.sync else {
            return;
        };
        let Some(lv) = self.lead[0] else {
            // No setpoint was computed for this cycle: continue the last cycle's motion by
            // one cycle, so the alarm reaction brakes from where the follower is now (the
            // position and its velocity stay consistent; nothing jumps).
            if self.goal == Goal::Sync {
                let dt = self.cfg.cycle;
                let b = self.basic;
                self.basic = State {
                    p: b.p + dt * (b.v + 0.5 * dt * b.a),
                    v: b.v + dt * b.a,
                    a: b.a,
                };
            }
            self.raise(AlarmId::LeaderMissing, supplement::NONE);
            return;
        };
        if let Some(ph) = self.phasing {
            self.phase = ph.prof.at(self.elapsed(ph.t0));
            if self.elapsed(ph.t0) >= ph.prof.duration() {
                self.phase = ph.prof.end();
                self.phasing = None;
                self.emit(ph.id, ph.instr, JobEventKind::Done);
            }
        }
        let x = State {
            p: lv.p + self.phase.p,
            v: lv.v + self.phase.v,
            a: lv.a + self.phase.a,
        };
        let g = job.ratio;
        if !job.ready {
            // Set up from this cycle's follower setpoint (from the previous goal) and leader.
            if let SyncLaw::Gear { .. } = job.law {
                let r = State {
                    p: self.basic.p - g * x.p,
                    v: self.basic.v - g * x.v,
                    a: self.basic.a - g * x.a,
                };
                let lim = Limits {
                    vel: job.lim.vel.max(r.v.abs()),
                    ..job.lim
                };
                self.prof = plan_velocity(r, 0.0, &lim).unwrap_or_else(|_| {
                    Profile::hold(State {
                        v: 0.0,
                        a: 0.0,
                        ..r
                    })
                });
                self.t0 = self.now;
            }
            job.ready = true;
            self.goal = Goal::Sync;
        }
        let mut events = [None; 2];
        let mut cam_step = None;
        // With a simulated synchronous operation the coupling runs logically only.
        let own = self.basic;
        match &mut job.law {
            SyncLaw::Gear { offset, prev } => {
                let velocity = job.instr == Instruction::GearInVelocity;
                if job.phase == SyncPhase::Synchronizing {
                    let e = self.elapsed(self.t0);
                    let r = self.prof.at(e);
                    self.basic = State {
                        p: g * x.p + r.p,
                        v: g * x.v + r.v,
                        a: g * x.a + r.a,
                    };
                    if e >= self.prof.duration() {
                        *offset = self.prof.end().p;
                        job.phase = SyncPhase::Synchronous;
                        events[0] = Some(if velocity {
                            JobEventKind::InSync
                        } else {
                            JobEventKind::InGear
                        });
                    }
                } else {
                    if velocity {
                        // Integrate the leader's velocity: a jump of its position is not
                        // followed (the offset absorbs what the position did beyond it).
                        let dx = 0.5 * (prev.v + x.v) * self.cfg.cycle;
                        *offset += g * (dx - (x.p - prev.p));
                    }
                    self.basic = State {
                        p: *offset + g * x.p,
                        v: g * x.v,
                        a: g * x.a,
                    };
                }
                *prev = x;
            }
            SyncLaw::GearPos {
                lead_dir,
                x_sync,
                y_sync,
                quintic,
                ..
            } => {
                if job.phase == SyncPhase::Synchronizing && *lead_dir * (x.p - *x_sync) < 0.0 {
                    if x.v * *lead_dir < 0.0 {
                        // The leading value reversed during synchronization (alarm 608).
                        self.sync = Some(job);
                        self.raise(AlarmId::SynchronizationError, supplement::NONE);
                        return;
                    }
                    if let Some(q) = quintic {
                        let [y, d1, d2, _] = q.eval(x.p);
                        self.basic = State {
                            p: y,
                            v: d1 * x.v,
                            a: d2 * x.v * x.v + d1 * x.a,
                        };
                    }
                } else {
                    if job.phase == SyncPhase::Synchronizing {
                        job.phase = SyncPhase::Synchronous;
                        events[0] = Some(JobEventKind::InSync);
                    }
                    if job.instr == Instruction::CamIn {
                        cam_step = Some(self.cam_synchronous(x));
                    } else {
                        self.basic = State {
                            p: *y_sync + g * (x.p - *x_sync),
                            v: g * x.v,
                            a: g * x.a,
                        };
                    }
                }
            }
        }
        self.sync = Some(job);
        if self.sync_sim.is_some() {
            self.basic = if self.goal == Goal::Sync {
                State {
                    v: 0.0,
                    a: 0.0,
                    ..own
                }
            } else {
                own
            };
            self.sync_flags = 8;
            for e in events.into_iter().flatten() {
                self.emit(job.id, job.instr, e);
            }
            return;
        }
        for e in events.into_iter().flatten() {
            self.emit(job.id, job.instr, e);
        }
        match cam_step {
            Some(CamStep::Running(true)) => {
                self.emit(job.id, job.instr, JobEventKind::EndOfProfile);
                if self.pending_at_cycle_end() {
                    // A pending cam takes over here, seamlessly.
                    self.cam_change_at_cycle_end();
                    let _ = self.cam_synchronous(x);
                }
            }
            Some(CamStep::Ended) => {
                // A once-through cam ends synchronous operation (InSync and Busy fall).
                self.emit(job.id, job.instr, JobEventKind::EndOfProfile);
                self.end_sync_keep_velocity(JobEventKind::Done);
                return;
            }
            Some(CamStep::Failed) => {
                self.end_sync_keep_velocity(JobEventKind::Error(ErrorId::NoFollowingValue));
                return;
            }
            Some(CamStep::Running(false)) | None => {}
        }
        // MC_OffsetAbsolute/Relative: a profile shift of the following value.
        let offset_done = match &self.offset_job {
            Some(o) => {
                let e = self.elapsed(o.t0);
                self.shift_out = o.prof.at(e);
                (e >= o.prof.duration()).then_some((o.id, o.instr, o.prof.end()))
            }
            None => None,
        };
        if let Some((id, instr, end)) = offset_done {
            self.shift_out = end;
            self.offset_job = None;
            self.emit(id, instr, JobEventKind::Done);
        }
        self.basic.p += self.shift_out.p;
        self.basic.v += self.shift_out.v;
        self.basic.a += self.shift_out.a;
        // Synchronous followers are not limited by their own dynamics: flag exceedances.
        let lim = &self.cfg.limits;
        let b = self.total();
        let mut flags = 0u8;
        if b.v.abs() > lim.max_velocity * (1.0 + 1e-12) {
            flags |= 1;
        }
        if b.v * b.a > 0.0 && b.a.abs() > lim.max_acceleration * (1.0 + 1e-12) {
            flags |= 2;
        }
        if b.v * b.a < 0.0 && b.a.abs() > lim.max_deceleration * (1.0 + 1e-12) {
            flags |= 4;
        }
        self.sync_flags = flags;
    }

    /// Pending GearInPos: sets the sync positions up on first sight of the leader and checks the
    /// start condition. `Some(true)`: start now; `Some(false)`: the job ended with an error;
    /// `None`: still pending.
    fn pending_start(&mut self, job: &mut SyncJob, lv: LeadingValue) -> Option<bool> {
        // The total setpoint: a superimposed motion is folded into the coupling when it starts.
        let follower = self.total();
        let cfg_mod = self.cfg.modulo;
        let SyncLaw::GearPos {
            msp,
            ssp,
            slope,
            curv,
            reference,
            msd,
            direction,
            lead_dir,
            x_sync,
            x_start,
            y_sync,
            quintic,
        } = &mut job.law
        else {
            return Some(false);
        };
        if *lead_dir == 0.0 {
            // The leader approaches the sync position: on a linear leader the direction towards
            // it; on a modulo leader the direction it moves in (positive at standstill).
            *lead_dir = match lv.modulo {
                None if *msp != lv.p => (*msp - lv.p).signum(),
                _ if lv.v < 0.0 => -1.0,
                _ => 1.0,
            };
        }
        let dir = *lead_dir;
        let (g, curv) = (*slope, *curv);
        if *reference == SyncProfileReference::Direct {
            // Synchronous at once: the sync point is where the leader and the follower are.
            *x_sync = lv.p;
            *x_start = lv.p;
            *y_sync = follower.p;
            *quintic = None;
            job.ready = true;
            return Some(true);
        }
        // Synchronization length: the start distance, or from the dynamics at the leader's
        // current velocity.
        let len = match reference {
            SyncProfileReference::Direct => 0.0,
            SyncProfileReference::MasterStartDistance => *msd,
            SyncProfileReference::Dynamics => {
                if lv.v == 0.0 {
                    return None;
                }
                // While the leader is far from the start the length is recomputed every 32nd
                // cycle only; on the approach every cycle (it depends on both axes' state).
                let last = dir * (*x_sync - *x_start);
                let far =
                    dir * (*x_sync - lv.p) > 4.0 * last + 40.0 * (lv.v * self.cfg.cycle).abs();
                let cycle_ns = (self.cfg.cycle * 1e9).round() as i64;
                let tick = cycle_ns > 0 && (self.now / cycle_ns) % 32 == 0;
                if job.ready && last > 0.0 && far && !tick {
                    return None;
                }
                sync_length(
                    follower,
                    (g, curv),
                    lv,
                    &job.lim,
                    (self.cfg.cycle, last),
                    |l| {
                        target_rep(
                            *ssp,
                            cfg_mod,
                            *direction,
                            follower.p,
                            follower.p + g * l * dir,
                        )
                    },
                )
            }
        };
        // The next sync position ahead of the leader with room for the synchronization, fixed
        // when the job first sees the leader.
        let xs = match lv.modulo {
            Some(_) if job.ready => *x_sync,
            Some(m) => {
                let ahead = if dir > 0.0 {
                    m.forward(lv.p, *msp)
                } else {
                    -m.forward(*msp, lv.p)
                };
                let mut xs = lv.p + ahead;
                if dir * (xs - lv.p) < len - 1e-12 * m.length {
                    xs += dir * m.length * ((len - dir * (xs - lv.p)) / m.length).ceil();
                }
                xs
            }
            None => *msp,
        };
        if !job.ready || *reference == SyncProfileReference::Dynamics {
            *x_sync = xs;
            *x_start = xs - dir * len;
        }
        if !job.ready {
            job.ready = true;
            if lv.modulo.is_none() && dir * (*x_start - lv.p) < 0.0 {
                if *reference == SyncProfileReference::MasterStartDistance {
                    // The leader is already inside the start distance.
                    self.emit(
                        job.id,
                        job.instr,
                        JobEventKind::Error(ErrorId::IllegalMasterStartDistance),
                    );
                    return Some(false);
                }
                // Dynamics: start at once over the remaining distance.
                *x_start = lv.p;
            }
        }
        // Start when the leader passes the start position; with the dynamics reference one
        // cycle early rather than late, so that the remaining length is never shorter than the
        // one the dynamics need.
        let ahead = match reference {
            SyncProfileReference::Dynamics => lv.v * self.cfg.cycle,
            SyncProfileReference::MasterStartDistance | SyncProfileReference::Direct => 0.0,
        };
        if dir * (lv.p + ahead - *x_start) < 0.0 {
            return None;
        }
        // Start: the quintic from this cycle's follower state to the sync point.
        let len = *x_sync - lv.p;
        let yt = target_rep(*ssp, cfg_mod, *direction, follower.p, follower.p + g * len);
        *y_sync = yt;
        let (d1, d2) = if lv.v.abs() > 1e-12 {
            let d1 = follower.v / lv.v;
            (d1, (follower.a - d1 * lv.a) / (lv.v * lv.v))
        } else {
            (0.0, 0.0)
        };
        *quintic = (len.abs() > 0.0)
            .then(|| Quintic::hermite(lv.p, len, (follower.p, d1, d2), (yt, g, curv)));
        Some(true)
    }
}

/// The continuous representation of the follower sync position `ssp`: on a modulo follower the
/// one nearest to `natural` (where the follower would be if it were synchronous already) that
/// `direction` allows from `here`.
fn target_rep(
    ssp: f64,
    modulo: Option<crate::modulo::Modulo>,
    direction: SyncDirection,
    here: f64,
    natural: f64,
) -> f64 {
    let Some(m) = modulo else {
        return ssp;
    };
    let near = natural + m.shortest(natural, ssp);
    match direction {
        SyncDirection::Shortest => near,
        SyncDirection::Positive => {
            if near < here {
                near + m.length * ((here - near) / m.length).ceil()
            } else {
                near
            }
        }
        SyncDirection::Negative => {
            if near > here {
                near - m.length * ((near - here) / m.length).ceil()
            } else {
                near
            }
        }
    }
}

/// Synchronization length (leading value distance) for SyncProfileReference 0: the shortest
/// length for which the quintic synchronization at the leader's current velocity keeps the
/// follower within its velocity (or the synchronous velocity, if higher), acceleration and jerk.
fn sync_length(
    follower: State,
    (g, curv): (f64, f64),
    lv: LeadingValue,
    lim: &Limits,
    (cycle, hint): (f64, f64),
    target: impl Fn(f64) -> f64,
) -> f64 {
    let v = lv.v.abs();
    let vmax = lim.vel.max((g * lv.v).abs()).max(follower.v.abs());
    let amax = lim.acc.min(lim.dec);
    let (d1, d2) = (
        follower.v / lv.v,
        (follower.a - follower.v / lv.v * lv.a) / (lv.v * lv.v),
    );
    let dir = lv.v.signum();
    let jmax = lim.jerk;
    let within = |l: f64| -> bool {
        let q = Quintic::hermite(0.0, dir * l, (follower.p, d1, d2), (target(l), g, curv));
        let [y2max, y3max] = q.peak_curvature_and_jerk();
        (y2max * v * v) <= amax * (1.0 + 1e-9)
            && (jmax == 0.0 || y3max * v * v * v <= jmax * (1.0 + 1e-9))
            && q.peak_slope() * v <= vmax * (1.0 + 1e-9)
    };
    // The synchronization starts in the cycle before the leader reaches the start, so the
    // length used is up to one cycle of leader travel longer; check that end too (the peak of
    // the quintic is not monotonic in its length).
    let step = v * cycle;
    let feasible = |l: f64| within(l) && within(l + step);
    // From the last length (a warm start, 1/4 around it) or by growing from a small one until
    // feasible; then bisection. The result is always a feasible length (slightly above the
    // shortest one, to 1/2^16 of the bracket).
    let (mut lo, mut hi) = (0.0, 0.0);
    if hint > 0.0 && feasible(hint * 1.25) {
        hi = hint * 1.25;
        lo = if feasible(hint * 0.8) {
            0.0
        } else {
            hint * 0.8
        };
        if lo == 0.0 {
            hi = hint * 0.8;
        }
    }
    if hi == 0.0 {
        hi = (v * v / amax).max(v * 1e-3).max(1e-9);
        let mut n = 0;
        while !feasible(hi) && n < 60 {
            hi *= 2.0;
            n += 1;
        }
        lo = if n == 0 { 0.0 } else { hi / 2.0 };
    }
    for _ in 0..16 {
        let mid = 0.5 * (lo + hi);
        if feasible(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quintic_meets_its_boundary_conditions() {
        let q = Quintic::hermite(10.0, -4.0, (1.0, 0.5, 0.25), (7.0, 2.0, -1.0));
        let [p0, d0, a0, _] = q.eval(10.0);
        let [p1, d1, a1, _] = q.eval(6.0);
        for (x, y) in [
            (p0, 1.0),
            (d0, 0.5),
            (a0, 0.25),
            (p1, 7.0),
            (d1, 2.0),
            (a1, -1.0),
        ] {
            assert!((x - y).abs() < 1e-12, "{x} vs {y}");
        }
    }

    #[test]
    fn target_representation_respects_the_direction() {
        let m = crate::modulo::Modulo {
            start: 0.0,
            length: 360.0,
        };
        assert_eq!(
            target_rep(10.0, Some(m), SyncDirection::Shortest, 0.0, 355.0),
            370.0
        );
        assert_eq!(
            target_rep(10.0, Some(m), SyncDirection::Negative, 0.0, 355.0),
            10.0 - 360.0
        );
        assert_eq!(
            target_rep(10.0, Some(m), SyncDirection::Positive, 400.0, 355.0),
            730.0
        );
        assert_eq!(
            target_rep(10.0, None, SyncDirection::Positive, 400.0, 355.0),
            10.0
        );
    }
}
