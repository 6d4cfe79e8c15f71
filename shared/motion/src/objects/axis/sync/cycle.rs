//! The cyclic part of synchronous operation: the start condition of a pending job, the set-up
//! from the first leading value, the coupling law, the shifts and the job events.

use super::camming::CamStep;
use super::job::{SyncJob, SyncPhase};
use super::law::{sync_length, target_rep, Quintic, SyncLaw};
use crate::catalog::alarm::{supplement, AlarmId};
use crate::catalog::error_id::ErrorId;
use crate::catalog::override_table::NewJob;
use crate::kinematics::profile::{plan_velocity, Limits, Profile, State};
use crate::objects::axis::{sync_status, Axis, Goal, SyncProfileReference};
use crate::objects::job::{Instruction, JobEventKind};
use crate::objects::leading::LeadingValue;

/// The job and instruction of the active synchronous operation (for its events).
#[derive(Clone, Copy)]
struct JobRef {
    id: crate::objects::job::JobId,
    instr: Instruction,
}

/// What evaluating the law did this cycle: the job events to report and the cam's step.
struct LawStep {
    events: [Option<JobEventKind>; 2],
    cam_step: Option<CamStep>,
}

impl Axis {
    /// The cyclic part: pending start conditions, set-up, the coupling law, job events.
    /// Runs after the basic setpoint of the current goal was computed for this cycle.
    pub(in crate::objects::axis) fn sync_step(&mut self) {
        if !self.step_pending_sync() {
            return;
        }
        // The active job is evaluated in place (it is 200 bytes: no copy in and out).
        if self.sync.is_none() {
            return;
        }
        let Some(lv) = self.lead[0] else {
            self.coupled_leader_missing();
            return;
        };
        self.advance_phasing();
        let x = State {
            p: lv.p + self.phase.p,
            v: lv.v + self.phase.v,
            a: lv.a + self.phase.a,
        };
        if self.sync.is_some_and(|j| !j.ready) {
            self.set_up_coupling(x);
        }
        // With a simulated synchronous operation the coupling runs logically only.
        let own = self.basic;
        let Some(law) = self.evaluate_law(x) else {
            return;
        };
        let Some(job) = self.sync.as_ref().map(|j| JobRef {
            id: j.id,
            instr: j.instr,
        }) else {
            return;
        };
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
            self.sync_flags = sync_status::SIMULATION;
            for e in law.events.into_iter().flatten() {
                self.emit(job.id, job.instr, e);
            }
            return;
        }
        for e in law.events.into_iter().flatten() {
            self.emit(job.id, job.instr, e);
        }
        if !self.finish_cam_step(job, law.cam_step, x) {
            return;
        }
        self.advance_offset();
        self.basic.p += self.shift_out.p;
        self.basic.v += self.shift_out.v;
        self.basic.a += self.shift_out.a;
        self.sync_flags = self.exceedance_flags() | self.flying_flags();
    }

    /// The pending job (GearInPos, CamIn): checks its start condition with its leader's value
    /// and, when it starts, makes it the active job (override tables, superimposed motion
    /// folded, StartSync). `false`: its leading value is missing (alarm 601 raised), the cycle's
    /// synchronous part ends here.
    fn step_pending_sync(&mut self) -> bool {
        let Some(mut p) = self.sync_pending.filter(|_| !self.pending_at_cycle_end()) else {
            return true;
        };
        let Some(lv) = self.lead[1] else {
            self.raise_alarm(AlarmId::LeaderMissing, supplement::NONE);
            return false;
        };
        let Some(started) = self.pending_start(&mut p, lv) else {
            self.sync_pending = Some(p);
            return true;
        };
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
        true
    }

    /// The active job's leading value is missing: no setpoint was computed for this cycle, so
    /// the last cycle's motion goes on by one cycle and the alarm reaction brakes from where the
    /// follower is now (the position and its velocity stay consistent; nothing jumps).
    fn coupled_leader_missing(&mut self) {
        if self.goal == Goal::Sync {
            let dt = self.cfg.cycle;
            let b = self.basic;
            self.basic = State {
                p: b.p + dt * (b.v + 0.5 * dt * b.a),
                v: b.v + dt * b.a,
                a: b.a,
            };
        }
        self.raise_alarm(AlarmId::LeaderMissing, supplement::NONE);
    }

    /// MC_PhasingAbsolute/Relative: the phase shift of the leading value follows its profile;
    /// the job is done at the profile's end.
    fn advance_phasing(&mut self) {
        if let Some(ph) = self.phasing {
            let prof = &self.phasing_prof;
            self.phase = prof.at(self.elapsed(ph.t0));
            if self.elapsed(ph.t0) >= prof.duration() {
                self.phase = prof.end();
                self.phasing = None;
                self.emit(ph.id, ph.instr, JobEventKind::Done);
            }
        }
    }

    /// Sets the coupling up from this cycle's follower setpoint (from the previous goal) and
    /// leading value `x`: for gearing, the relative profile that brings the relative velocity
    /// and acceleration to zero.
    fn set_up_coupling(&mut self, x: State) {
        let Some(job) = self.sync.as_mut() else {
            return;
        };
        let g = job.ratio;
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

    /// Evaluates the job's law at the leading value `x` into the basic setpoint. `None`: the
    /// leading value reversed during an absolute synchronization (alarm 608 raised, the job
    /// kept), the cycle's synchronous part ends here.
    fn evaluate_law(&mut self, x: State) -> Option<LawStep> {
        match self.sync.as_ref()?.law {
            SyncLaw::Gear { .. } => Some(self.evaluate_gear(x)),
            SyncLaw::GearPos { .. } => self.evaluate_gear_pos(x),
            SyncLaw::Flying(_) => self.evaluate_flying(x).map(|events| LawStep {
                events,
                cam_step: None,
            }),
        }
    }

    /// Relative gearing: the relative profile while synchronizing, then `offset + ratio * x`
    /// (velocity gearing integrates the leader's velocity).
    fn evaluate_gear(&mut self, x: State) -> LawStep {
        let mut events = [None; 2];
        let e = self.elapsed(self.t0);
        let Some(job) = self.sync.as_mut() else {
            return LawStep {
                events,
                cam_step: None,
            };
        };
        let g = job.ratio;
        if let SyncLaw::Gear { offset, prev } = &mut job.law {
            let velocity = job.instr == Instruction::GearInVelocity;
            if job.phase == SyncPhase::Synchronizing {
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
        LawStep {
            events,
            cam_step: None,
        }
    }

    /// Absolute synchronization (GearInPos, CamIn): the quintic up to the sync point, then
    /// `y_sync + ratio * (x - x_sync)` or the cam.
    fn evaluate_gear_pos(&mut self, x: State) -> Option<LawStep> {
        let mut events = [None; 2];
        let mut cam = false;
        let job = self.sync.as_mut()?;
        let g = job.ratio;
        if let SyncLaw::GearPos {
            lead_dir,
            x_sync,
            y_sync,
            quintic,
            ..
        } = &mut job.law
        {
            if job.phase == SyncPhase::Synchronizing && *lead_dir * (x.p - *x_sync) < 0.0 {
                if x.v * *lead_dir < 0.0 {
                    // The leading value reversed during synchronization (alarm 608).
                    self.raise_alarm(AlarmId::SynchronizationError, supplement::NONE);
                    return None;
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
                    cam = true;
                } else {
                    self.basic = State {
                        p: *y_sync + g * (x.p - *x_sync),
                        v: g * x.v,
                        a: g * x.a,
                    };
                }
            }
        }
        // The cam is evaluated once the job is no longer borrowed (it does not read it).
        let cam_step = cam.then(|| self.cam_synchronous(x));
        Some(LawStep { events, cam_step })
    }

    /// What a cam's step means for the job: EndOfProfile (and a pending cam taking over), the
    /// end of a once-through cam, or a failure. `false`: the synchronous operation ended.
    fn finish_cam_step(&mut self, job: JobRef, cam_step: Option<CamStep>, x: State) -> bool {
        match cam_step {
            Some(CamStep::Running(true)) => {
                self.emit(job.id, job.instr, JobEventKind::EndOfProfile);
                if self.pending_at_cycle_end() {
                    // A pending cam takes over here, seamlessly.
                    self.cam_change_at_cycle_end();
                    // Only the new cam's setpoint is wanted here: it starts at the start of
                    // its cycle, so its step has no cam end to report in this cycle.
                    let _ = self.cam_synchronous(x);
                }
                true
            }
            Some(CamStep::Ended) => {
                // A once-through cam ends synchronous operation (InSync and Busy fall).
                self.emit(job.id, job.instr, JobEventKind::EndOfProfile);
                self.end_sync_keep_velocity(JobEventKind::Done);
                false
            }
            Some(CamStep::Failed) => {
                self.end_sync_keep_velocity(JobEventKind::Error(ErrorId::NoFollowingValue));
                false
            }
            Some(CamStep::Running(false)) | None => true,
        }
    }

    /// MC_OffsetAbsolute/Relative: the shift of the following value follows its profile; the
    /// job is done at the profile's end.
    fn advance_offset(&mut self) {
        let offset_done = match &self.offset_job {
            Some(o) => {
                let e = self.elapsed(o.t0);
                let prof = &self.offset_prof;
                self.shift_out = prof.at(e);
                (e >= prof.duration()).then_some((o.id, o.instr, prof.end()))
            }
            None => None,
        };
        if let Some((id, instr, end)) = offset_done {
            self.shift_out = end;
            self.offset_job = None;
            self.emit(id, instr, JobEventKind::Done);
        }
    }

    /// Synchronous followers are not limited by their own dynamics: the [`sync_status`] bits of
    /// the exceeded limits.
    fn exceedance_flags(&self) -> u8 {
        let lim = &self.cfg.limits;
        let b = self.total();
        let mut flags = 0u8;
        if b.v.abs() > lim.max_velocity * (1.0 + 1e-12) {
            flags |= sync_status::MAX_VELOCITY_EXCEEDED;
        }
        if b.v * b.a > 0.0 && b.a.abs() > lim.max_acceleration * (1.0 + 1e-12) {
            flags |= sync_status::MAX_ACCELERATION_EXCEEDED;
        }
        if b.v * b.a < 0.0 && b.a.abs() > lim.max_deceleration * (1.0 + 1e-12) {
            flags |= sync_status::MAX_DECELERATION_EXCEEDED;
        }
        flags
    }

    /// Pending GearInPos: sets the sync positions up on first sight of the leader and checks the
    /// start condition. `Some(true)`: start now; `Some(false)`: the job ended with an error;
    /// `None`: still pending.
    fn pending_start(&mut self, job: &mut SyncJob, lv: LeadingValue) -> Option<bool> {
        // The total setpoint: a superimposed motion is folded into the coupling when it starts.
        let follower = self.total();
        let SyncLaw::GearPos {
            msp,
            reference,
            lead_dir,
            x_sync,
            x_start,
            y_sync,
            quintic,
            ..
        } = &mut job.law
        else {
            return Some(false);
        };
        if *lead_dir == 0.0 {
            *lead_dir = lead_direction(*msp, &lv);
        }
        if *reference == SyncProfileReference::Direct {
            // Synchronous at once: the sync point is where the leader and the follower are.
            *x_sync = lv.p;
            *x_start = lv.p;
            *y_sync = follower.p;
            *quintic = None;
            job.ready = true;
            return Some(true);
        }
        let len = self.pending_sync_length(job, lv, follower)?;
        if !self.place_sync_point(job, lv, len) {
            return Some(false);
        }
        self.start_synchronization(job, lv, follower)
    }

    /// Synchronization length: the start distance, or from the dynamics at the leader's
    /// current velocity. `None`: not computed in this cycle (the leader stands, or it is still
    /// far from the start and this is not every 32nd cycle): the job stays pending.
    fn pending_sync_length(&self, job: &SyncJob, lv: LeadingValue, follower: State) -> Option<f64> {
        let SyncLaw::GearPos {
            ssp,
            slope: g,
            curv,
            reference,
            msd,
            direction,
            lead_dir: dir,
            x_sync,
            x_start,
            ..
        } = job.law
        else {
            return None;
        };
        let cfg_mod = self.cfg.modulo;
        let len = match reference {
            SyncProfileReference::Direct => 0.0,
            SyncProfileReference::MasterStartDistance => msd,
            SyncProfileReference::Dynamics => {
                if lv.v == 0.0 {
                    return None;
                }
                // While the leader is far from the start the length is recomputed every 32nd
                // cycle only; on the approach every cycle (it depends on both axes' state).
                let last = dir * (x_sync - x_start);
                let far = dir * (x_sync - lv.p) > 4.0 * last + 40.0 * (lv.v * self.cfg.cycle).abs();
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
                            ssp,
                            cfg_mod,
                            direction,
                            follower.p,
                            follower.p + g * l * dir,
                        )
                    },
                )
            }
        };
        Some(len)
    }

    /// The next sync position ahead of the leader with room for the synchronization of length
    /// `len`, fixed when the job first sees the leader (moved with the length under the
    /// dynamics reference). `false`: the leader is already inside the start distance
    /// (16#8026 reported, the job ends).
    fn place_sync_point(&mut self, job: &mut SyncJob, lv: LeadingValue, len: f64) -> bool {
        let SyncLaw::GearPos {
            msp,
            reference,
            lead_dir,
            x_sync,
            x_start,
            ..
        } = &mut job.law
        else {
            return false;
        };
        let dir = *lead_dir;
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
                    return false;
                }
                // Dynamics: start at once over the remaining distance.
                *x_start = lv.p;
            }
        }
        true
    }

    /// Starts when the leader passes the start position (with the dynamics reference one cycle
    /// early rather than late, so that the remaining length is never shorter than the one the
    /// dynamics need): the quintic from this cycle's follower state to the sync point.
    /// `Some(true)`: started; `None`: not yet.
    fn start_synchronization(
        &self,
        job: &mut SyncJob,
        lv: LeadingValue,
        follower: State,
    ) -> Option<bool> {
        let cfg_mod = self.cfg.modulo;
        let SyncLaw::GearPos {
            ssp,
            slope,
            curv,
            reference,
            direction,
            lead_dir,
            x_sync,
            x_start,
            y_sync,
            quintic,
            ..
        } = &mut job.law
        else {
            return Some(false);
        };
        let dir = *lead_dir;
        let (g, curv) = (*slope, *curv);
        let ahead = match reference {
            SyncProfileReference::Dynamics => lv.v * self.cfg.cycle,
            SyncProfileReference::MasterStartDistance | SyncProfileReference::Direct => 0.0,
        };
        if dir * (lv.p + ahead - *x_start) < 0.0 {
            return None;
        }
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

/// The direction the leader approaches the sync position `msp` in: on a linear leader the
/// direction towards it; on a modulo leader the direction it moves in (positive at standstill).
fn lead_direction(msp: f64, lv: &LeadingValue) -> f64 {
    match lv.modulo {
        None if msp != lv.p => (msp - lv.p).signum(),
        _ if lv.v < 0.0 => -1.0,
        _ => 1.0,
    }
}
