//! The cyclic part of the axis: sensors, setpoint generation, limit supervision, job
//! completion, monitoring, drive, status. Allocation-free.

use super::{
    sign, sync_function, ActiveHoming, Axis, AxisKind, AxisState, Goal, HomePhase, HomingMark,
    PassiveDirection, PosMon, Sense,
};
use crate::catalog::alarm::{status_bit, supplement, AlarmId, ErrorDetail, Reaction};
use crate::kinematics::profile::{plan_position, Limits, State};
use crate::objects::job::{Instruction, JobEventKind};
use crate::plant::link::{DriveLink, DriveOutputs, DriveState, HomingLatch};

impl Axis {
    /// Runs one cycle for time `now_ns` (cell clock, ns): the setpoint computed here is the
    /// setpoint for `now_ns`; the simulated drive then moves the plant to the next cycle.
    pub fn step(&mut self, now_ns: i64) {
        self.now = now_ns;
        let (inputs, connected) = match &mut self.link {
            DriveLink::Simulation(plant) => (plant.sample(), false),
            DriveLink::Connected { inputs, .. } => (*inputs, true),
        };
        self.signals = inputs.signals;
        if connected {
            self.in_limitation = inputs.in_limitation;
            self.drive_state(inputs.state);
        }
        let act = inputs.actual;
        let phys = act.p;
        let prev = self.prev_phys;
        self.prev_phys = phys;
        self.actual_p = phys + self.offset;
        self.actual_v = act.v;
        if self.actual_output {
            self.extrapolator.step(self.actual_p, self.actual_v);
        }

        self.check_hw_limits(phys);
        self.active_homing(prev, phys);
        self.passive_homing(prev, phys);
        self.generate();
        self.sync_step();
        self.lead = [None; 2];
        self.check_sw_limits();
        self.update_jobs();
        self.hyd_commands_cycle();
        self.hyd_direct_cycle();
        self.monitor(act.balanced + self.offset);
        if self.torque_active {
            self.torque_cycle();
        }
        self.hyd_auto_zero();

        let out = self.outputs();
        self.power.fault_reset = false;
        match &mut self.link {
            DriveLink::Simulation(plant) => plant.apply(&out),
            DriveLink::Connected { outputs, .. } => *outputs = out,
        }
        self.forget_status();
    }

    /// The drive outputs of this cycle: the total setpoint in physical coordinates. (Inlined:
    /// built in place where the step hands them to the drive, not returned through memory.)
    #[inline]
    pub(super) fn outputs(&self) -> DriveOutputs {
        let tot = self.total();
        let direct = self.hyd_direct_output();
        DriveOutputs {
            position: tot.p - self.offset,
            velocity: tot.v,
            enable: self.enabled || self.power.awaiting_drive,
            position_controlled: self.pos_ctrl && self.hyd_position_control_with(direct),
            fault_reset: self.power.fault_reset,
            acceleration: tot.a,
            quick_stop: self.power.quick_stop && !self.enabled && !self.power.awaiting_drive,
            homing_latch: self.homing_latch(),
            hydraulic: self.hyd_valve_outputs(direct),
            torque: if self.torque_active {
                self.torque.outputs()
            } else {
                crate::plant::link::TorqueOutputs::default()
            },
        }
    }

    /// The mark a homing job waits for now, for a drive that latches it: active homing in
    /// phase [`HomePhase::Armed`] (the zero mark) or on the cam with the digital input as its
    /// mark (the cam's edge); passive homing likewise. `None` while no job waits for a mark.
    ///
    /// Active homing arms the cam's edge only while the setpoint moves in the homing direction,
    /// so that a cam left on the wrong side while reversing on it is not latched (a first-event
    /// latch would keep that edge); the drive clears its latch when disarmed and arms afresh.
    fn homing_latch(&self) -> Option<HomingLatch> {
        let latch = |phase: HomePhase, mark: HomingMark| match (phase, mark) {
            (HomePhase::Armed, _) => Some(HomingLatch::ZeroMark),
            (HomePhase::OnCam, HomingMark::DigitalInput) => Some(HomingLatch::ReferenceCamEdge),
            _ => None,
        };
        let hc = &self.cfg.homing;
        // (Looked at in place: the job's homing state is not copied out.)
        if let Some(h) = self.main.as_ref().and_then(|m| m.homing.as_ref()) {
            let heading = sign(self.total().v) == hc.homing_direction.sign();
            return latch(h.phase, hc.active_mark)
                .filter(|l| *l == HomingLatch::ZeroMark || heading);
        }
        self.passive
            .as_ref()
            .and_then(|p| latch(p.phase, hc.passive_mark))
    }

    /// What the state of a connected drive means for the axis (S7-1500T Motion Control V4.0
    /// function manual, technology alarm 421 "Faulty drive" and its causes): the enable comes
    /// when the drive is operational; a drive fault, a drive that shuts down on its own and an
    /// enable that is not possible raise alarm 421 (remove enable) with the cause in the
    /// supplement ([`supplement::drive_fault_code`]).
    fn drive_state(&mut self, state: DriveState) {
        match state {
            DriveState::Operational => {
                if self.power.awaiting_drive {
                    self.power.awaiting_drive = false;
                    self.power.after_reset = false;
                    self.enable_now();
                }
            }
            DriveState::Fault { code } => {
                // After MC_Reset the fault stays until the drive has processed the reset.
                if self.enabled || (self.power.awaiting_drive && !self.power.after_reset) {
                    self.raise_alarm(AlarmId::DriveFault, supplement::drive_fault_code(code));
                }
            }
            DriveState::EnableTimedOut { step } => {
                if self.power.awaiting_drive {
                    self.raise_alarm(
                        AlarmId::DriveFault,
                        supplement::DRIVE_ENABLE_NOT_POSSIBLE + u16::from(step),
                    );
                }
            }
            DriveState::Disabled | DriveState::Enabling { .. } | DriveState::Stopping => {
                if self.enabled {
                    self.raise_alarm(AlarmId::DriveFault, supplement::DRIVE_SHUT_DOWN);
                }
            }
        }
    }

    /// The total setpoint predicted one cycle ahead (for the software-limit look-ahead).
    fn predict(&self) -> State {
        let dt = self.cfg.cycle;
        let basic = match self.goal {
            Goal::Direct {
                position: Some(p),
                v,
                a,
            } => State {
                p: p + v * dt,
                v,
                a,
            },
            Goal::Direct {
                position: None,
                v,
                a,
            } => State {
                p: self.basic.p + v * dt,
                v,
                a,
            },
            Goal::Track => self.basic,
            Goal::Sync => State {
                p: self.basic.p + self.basic.v * dt,
                ..self.basic
            },
            _ if self.hyd_finished().is_some() => State {
                p: self.basic.p + self.basic.v * dt,
                ..self.basic
            },
            _ => self.prof.at(self.elapsed(self.t0) + dt),
        };
        let sup = match &self.sup_job {
            Some(j) => self.sup_prof.at(self.elapsed(j.t0) + dt),
            None => self.sup,
        };
        State {
            p: basic.p + sup.p,
            v: basic.v + sup.v,
            a: basic.a + sup.a,
        }
    }

    fn generate(&mut self) {
        let dt = self.cfg.cycle;
        let by_generator = self.hyd_direct_generate() || self.hyd_generate();
        match self.goal {
            _ if by_generator => {}
            Goal::Direct {
                position: Some(p),
                v,
                a,
            } => self.basic = State { p, v, a },
            Goal::Direct {
                position: None,
                v,
                a,
            } => {
                self.basic = State {
                    p: self.basic.p + v * dt,
                    v,
                    a,
                };
            }
            Goal::Sync => {}
            Goal::Track => {
                self.basic = State {
                    p: self.actual_p,
                    v: self.actual_v,
                    a: 0.0,
                };
                self.sup = State::default();
            }
            _ => self.basic = self.prof.at(self.elapsed(self.t0)),
        }
        if let Some(j) = &self.sup_job {
            self.sup = self.sup_prof.at(self.elapsed(j.t0));
        }
    }

    fn check_sw_limits(&mut self) {
        let Some(sw) = self.cfg.sw_limits else {
            return;
        };
        if !self.homed || !self.enabled || self.cfg.kind == AxisKind::Speed {
            self.sw_active = None;
            return;
        }
        let tot = self.total();
        let eps = 1e-9 * (1.0 + sw.max.abs().max(sw.min.abs()));
        if tot.p > sw.max + eps {
            self.sw_active = Some(Sense::Positive);
            self.raise_alarm(AlarmId::SwLimitCrossed, supplement::POSITIVE);
            return;
        }
        if tot.p < sw.min - eps {
            self.sw_active = Some(Sense::Negative);
            self.raise_alarm(AlarmId::SwLimitCrossed, supplement::NEGATIVE);
            return;
        }
        // The status stays while the alarm is pending or the setpoint is at the limit.
        let pending =
            self.has_alarm(AlarmId::SwLimitReached) || self.has_alarm(AlarmId::SwLimitCrossed);
        match self.sw_active {
            Some(Sense::Positive) if !pending && tot.p < sw.max - eps => self.sw_active = None,
            Some(Sense::Negative) if !pending && tot.p > sw.min + eps => self.sw_active = None,
            _ => {}
        }
        let next = self.predict();
        let (limit, sense) = if next.v > 0.0 || (next.v == 0.0 && next.a > 0.0) {
            (sw.max, Sense::Positive)
        } else if next.v < 0.0 || next.a < 0.0 {
            (sw.min, Sense::Negative)
        } else {
            return;
        };
        let max = self.max_limits();
        let stop = self.stop_point(next, &max);
        let beyond = match sense {
            Sense::Positive => stop > limit + eps,
            Sense::Negative => stop < limit - eps,
        };
        if !beyond {
            return;
        }
        // Reaching the limit: stop exactly at it with maximum dynamics (alarm 533, the axis
        // stays enabled). If even that is impossible the setpoint will cross: alarm 534.
        self.sw_active = Some(sense);
        let supp = if sense == Sense::Positive {
            supplement::POSITIVE
        } else {
            supplement::NEGATIVE
        };
        self.raise_alarm(AlarmId::SwLimitReached, supp);
        self.fold_superimposed();
        let here = self.stop_point(self.basic, &max);
        let reachable = match sense {
            Sense::Positive => here <= limit + eps,
            Sense::Negative => here >= limit - eps,
        };
        if reachable {
            if let Ok(p) = plan_position(
                self.basic,
                limit,
                &Limits {
                    vel: max.vel.max(self.basic.v.abs()),
                    ..max
                },
            ) {
                self.goal = Goal::Stop { lim: max };
                self.hyd_disengage();
                self.prof = p;
                self.t0 = self.now;
            }
        }
    }

    fn check_hw_limits(&mut self, phys: f64) {
        if !self.cfg.hw_limits_active || self.cfg.virtual_axis {
            return;
        }
        let max_on = self.signals.limit_positive;
        let min_on = self.signals.limit_negative;
        if let Some((sense, at)) = self.hw_trigger {
            // Cleared once the switch is left and the axis is back beyond the stored position.
            let cleared = match sense {
                Sense::Positive => !max_on && phys < at,
                Sense::Negative => !min_on && phys > at,
            };
            if cleared {
                self.hw_trigger = None;
            }
        }
        if !self.enabled {
            return;
        }
        let homing_reverses = self.cfg.homing.auto_reversal
            && self
                .main
                .and_then(|m| m.homing)
                .map(|h| h.phase != HomePhase::Travel)
                .unwrap_or(false);
        if homing_reverses {
            return;
        }
        let v = self.total().v;
        for (sense, on) in [(Sense::Positive, max_on), (Sense::Negative, min_on)] {
            if !on {
                continue;
            }
            match self.hw_trigger {
                None => {
                    self.hw_trigger = Some((sense, phys));
                    let supp = if sense == Sense::Positive {
                        supplement::HW_LIMIT_POSITIVE
                    } else {
                        supplement::HW_LIMIT_NEGATIVE
                    };
                    self.raise_alarm(AlarmId::HwLimit, supp);
                }
                Some((s, _)) if s == sense && sign(v) == sense.sign() => {
                    self.raise_alarm(AlarmId::HwLimit, supplement::HW_LIMIT_ILLEGAL_DIRECTION);
                }
                _ => {}
            }
        }
    }

    fn hw_switch_hit(&self, dir: f64) -> bool {
        (dir > 0.0 && self.signals.limit_positive) || (dir < 0.0 && self.signals.limit_negative)
    }

    /// Sets the axis position so that the physical mark `m` has the axis value `home`.
    fn home_at_mark(&mut self, m: f64, home: f64) {
        let delta = home - (m + self.offset);
        self.shift(delta);
        self.homed = true;
    }

    fn active_homing(&mut self, prev: f64, phys: f64) {
        // (Looked at in place first: the job is copied only while it homes.)
        if self.main.as_ref().is_none_or(|m| m.homing.is_none()) {
            return;
        }
        let Some(job) = self.main else {
            return;
        };
        let Some(mut h) = job.homing else {
            return;
        };
        let vlim = Limits {
            vel: self.cfg.limits.max_velocity,
            ..job.lim
        };
        let Some(mut new_goal) = self.homing_phase(&mut h, vlim, sign(phys - prev)) else {
            // Nothing found: the alarm is raised.
            return;
        };
        if h.phase == HomePhase::Travel && job.homing.map(|o| o.phase) != Some(HomePhase::Travel) {
            // Travel to the end position at approach velocity (shortest way on modulo axes).
            let here = self.basic.p;
            let target = match self.cfg.modulo {
                Some(m) => here + m.shortest(here, h.end),
                None => h.end,
            };
            let lim = Limits {
                vel: self.cfg.homing.approach_velocity,
                ..job.lim
            };
            new_goal = Some(Goal::Position {
                target,
                lim,
                end_v: 0.0,
            });
        }
        if let Some(m) = self.main.as_mut() {
            m.homing = Some(h);
        }
        if let Some(g) = new_goal {
            // Homing motions ignore the override.
            let ovr = self.override_pct;
            self.override_pct = 100.0;
            self.set_goal(g);
            self.override_pct = ovr;
        }
    }

    /// One cycle of active homing's search (S7-1500T Motion Control V4.0 function manual,
    /// 'Active homing'): `h` advances on the reversing cam, the reference cam and the zero
    /// mark, `moved` being the direction the axis moved in this cycle. Returns the new goal
    /// of the homing motion, if any (`Some(None)`: keep going), or `None` when the second
    /// reversal found nothing and alarm `HomingNotFound` was raised.
    fn homing_phase(
        &mut self,
        h: &mut ActiveHoming,
        vlim: Limits,
        moved: f64,
    ) -> Option<Option<Goal>> {
        let hc = self.cfg.homing;
        let hd = hc.homing_direction.sign();
        // The direction the homing motion is commanded in (a reversal is counted once, when
        // the switch lies ahead of it, not again while braking on the switch).
        let heading = if h.phase == HomePhase::Search {
            h.search_dir
        } else {
            hd
        };
        match h.phase {
            HomePhase::Search | HomePhase::OnCam | HomePhase::Armed
                if hc.auto_reversal && self.hw_switch_hit(heading) =>
            {
                // Reversing cam: brake with the maximum deceleration, continue the other way at
                // approach velocity. The second reversal means nothing was found.
                h.reversals += 1;
                if h.reversals >= 2 {
                    self.raise_alarm(AlarmId::HomingNotFound, supplement::NONE);
                    return None;
                }
                h.search_dir = -heading;
                h.phase = HomePhase::Search;
                let lim = Limits {
                    dec: self.cfg.limits.max_deceleration,
                    ..vlim
                };
                return Some(Some(Goal::Velocity {
                    v: h.search_dir * hc.approach_velocity,
                    lim,
                }));
            }
            HomePhase::Search => {
                if self.signals.reference_cam {
                    h.phase = HomePhase::OnCam;
                    return Some(Some(Goal::Velocity {
                        v: hd * hc.referencing_velocity,
                        lim: vlim,
                    }));
                }
            }
            HomePhase::OnCam => {
                if !self.signals.reference_cam && moved == hd {
                    if hc.active_mark == HomingMark::DigitalInput {
                        if let Some(m) = self.signals.reference_cam_left {
                            self.home_at_mark(m, h.home);
                            h.phase = HomePhase::Travel;
                        }
                    } else {
                        h.phase = HomePhase::Armed;
                    }
                }
            }
            HomePhase::Armed => {
                if moved == hd {
                    if let Some(m) = self.signals.zero_mark {
                        self.home_at_mark(m, h.home);
                        h.phase = HomePhase::Travel;
                    }
                }
            }
            HomePhase::Travel => {}
        }
        Some(None)
    }

    fn passive_homing(&mut self, prev: f64, phys: f64) {
        let Some(mut ph) = self.passive else {
            return;
        };
        let moved = sign(phys - prev);
        let dir_ok = match self.cfg.homing.passive_direction {
            PassiveDirection::Positive => moved > 0.0,
            PassiveDirection::Negative => moved < 0.0,
            PassiveDirection::Current => moved != 0.0,
        };
        let mark = self.cfg.homing.passive_mark;
        let mut hit = None;
        match ph.phase {
            HomePhase::Search => {
                if dir_ok && self.signals.reference_cam {
                    ph.phase = HomePhase::OnCam;
                }
            }
            HomePhase::OnCam => {
                if !self.signals.reference_cam {
                    if dir_ok {
                        if mark == HomingMark::DigitalInput {
                            hit = self.signals.reference_cam_left;
                        } else {
                            ph.phase = HomePhase::Armed;
                            ph.armed_dir = moved;
                        }
                    } else {
                        ph.phase = HomePhase::Search;
                    }
                }
            }
            HomePhase::Armed => {
                if ph.armed_dir != 0.0 && moved != 0.0 && moved != ph.armed_dir {
                    // A reversal after leaving the cam: the cam must be detected again.
                    ph.phase = HomePhase::Search;
                } else if dir_ok {
                    hit = self.signals.zero_mark;
                }
            }
            HomePhase::Travel => {}
        }
        if let Some(m) = hit {
            // Passive homing applies no home position offset.
            self.home_at_mark(m, ph.home);
            self.passive = None;
            self.emit(ph.job, Instruction::Home, JobEventKind::Done);
        } else {
            self.passive = Some(ph);
        }
    }

    fn update_jobs(&mut self) {
        let sup_done = self
            .sup_job
            .as_ref()
            .filter(|j| self.elapsed(j.t0) >= self.sup_prof.duration())
            .map(|j| (j.id, self.sup_prof.end()));
        if let Some((id, end)) = sup_done {
            self.sup = end;
            self.sup_job = None;
            self.emit(id, Instruction::MoveSuperimposed, JobEventKind::Done);
        }
        // Without a basic motion job and a disabling, nothing below applies: the profile's end
        // (a cache line of its own, which a follower's cycle need not touch) is not looked at.
        if self.main.is_none() && !self.power.disabling {
            return;
        }
        let finished = self.main_motion_finished();
        if self.power.disabling && finished {
            self.remove_enable();
            return;
        }
        // Every case below waits for the end of the profile (and the job is not copied before).
        if !finished {
            return;
        }
        let Some(mut m) = self.main else {
            return;
        };
        let ovr_stopped = self.override_pct == 0.0 && matches!(self.goal, Goal::Position { .. });
        if !self.queue.is_empty() && self.queue_takes_over(&m, ovr_stopped) {
            self.hand_over(m);
            return;
        }
        match (m.instr, self.goal) {
            (Instruction::MoveVelocity | Instruction::MoveJog, Goal::Velocity { .. })
                if finished && !m.in_velocity =>
            {
                m.in_velocity = true;
                self.emit(m.id, m.instr, JobEventKind::InVelocity);
            }
            (Instruction::MoveJog, Goal::Stop { .. }) if finished => {
                self.finish_main(m.id, m.instr);
                return;
            }
            (Instruction::Stop, _) if finished && !self.stop_lock => {
                self.finish_main(m.id, m.instr);
                return;
            }
            (
                Instruction::MoveAbsolute
                | Instruction::MoveRelative
                | Instruction::MoveAdditive
                | Instruction::Halt
                | Instruction::Home,
                Goal::Position { target: _, .. } | Goal::Stop { .. },
            ) if finished && !ovr_stopped => {
                if (m.instr == Instruction::Home
                    && m.homing
                        .map(|h| h.phase != HomePhase::Travel)
                        .unwrap_or(false))
                    || self.sup_job.is_some()
                {
                    // Still searching (a stop in between is not the end), or a superimposed
                    // motion is still running: positioning monitoring waits for the total.
                } else if let Some(done) = self.hyd_done() {
                    // The hydraulic library's Done: idle, InTargRng and InTarget.
                    if done {
                        self.finish_main(m.id, m.instr);
                        return;
                    }
                } else {
                    let target = self.total().p;
                    let pm = *m.monitoring.get_or_insert(PosMon {
                        target,
                        start_ns: self.now,
                        entered_ns: None,
                    });
                    match self.positioning_monitor(pm) {
                        Some(true) => {
                            self.finish_main(m.id, m.instr);
                            return;
                        }
                        Some(false) => return,
                        None => {
                            if let Some(pm2) = m.monitoring.as_mut() {
                                if pm2.entered_ns.is_none() && self.pm_inside(pm2.target) {
                                    pm2.entered_ns = Some(self.now);
                                }
                            }
                        }
                    }
                }
            }
            _ => {}
        }
        if let Some(slot) = self.main.as_mut() {
            if slot.id == m.id {
                *slot = m;
            }
        }
    }

    /// Whether the basic motion's profile (or the engaged hydraulic generator) has ended.
    pub(super) fn main_motion_finished(&self) -> bool {
        self.hyd_finished()
            .unwrap_or_else(|| self.elapsed(self.t0) >= self.prof.duration())
    }

    pub(super) fn finish_main(&mut self, id: crate::objects::job::JobId, instr: Instruction) {
        self.main = None;
        self.emit(id, instr, JobEventKind::Done);
        // A Buffered job waiting behind it starts now (PLCopen BufferMode).
        if self.queue.is_empty() || !self.start_queued() {
            self.set_goal(Goal::Hold);
        }
    }

    fn pm_inside(&self, target: f64) -> bool {
        (self.actual_p - target).abs() <= self.cfg.positioning.window
    }

    /// Positioning monitoring (S7-1500T Motion Control V4.0 function manual, 3.2.10.2 'Positioning
    /// monitoring'): `Some(true)` done, `Some(false)` failed (alarm 541 raised), `None` still
    /// waiting.
    fn positioning_monitor(&mut self, pm: PosMon) -> Option<bool> {
        if !self.pos_ctrl {
            return Some(true);
        }
        let pmc = self.cfg.positioning;
        let inside = self.pm_inside(pm.target);
        let ns = |s: f64| (s * 1e9).round() as i64;
        match pm.entered_ns {
            None => {
                if inside {
                    if pmc.min_dwell_time <= 0.0 {
                        return Some(true);
                    }
                    None
                } else if self.now - pm.start_ns > ns(pmc.tolerance_time)
                    && !self.position_monitorings_off()
                {
                    self.raise_alarm(
                        AlarmId::PositioningMonitoring,
                        supplement::TARGET_NOT_REACHED,
                    );
                    Some(false)
                } else {
                    None
                }
            }
            Some(t) => {
                if !inside {
                    self.raise_alarm(AlarmId::PositioningMonitoring, supplement::TARGET_LEFT);
                    Some(false)
                } else if self.now - t >= ns(pmc.min_dwell_time) {
                    Some(true)
                } else {
                    None
                }
            }
        }
    }

    fn monitor(&mut self, balanced: f64) {
        let ss = self.cfg.standstill;
        if self.actual_v.abs() <= ss.velocity_threshold {
            self.standstill_since.get_or_insert(self.now);
        } else {
            self.standstill_since = None;
        }
        let fe_cfg = self.cfg.following_error;
        self.fe = if self.enabled && self.pos_ctrl {
            balanced - self.actual_p
        } else {
            0.0
        };
        if !(fe_cfg.enable && self.enabled && self.pos_ctrl) || self.position_monitorings_off() {
            return;
        }
        let v = self.total().v.abs();
        // `DynamicLimits.MaxVelocity` (the configured one, not the programmable `Velocity`).
        let vmax = self.param_extra.max_velocity;
        let allowed = if v <= fe_cfg.min_velocity || vmax <= fe_cfg.min_velocity {
            fe_cfg.min_value
        } else {
            let f = ((v - fe_cfg.min_velocity) / (vmax - fe_cfg.min_velocity)).min(1.0);
            fe_cfg.min_value + (fe_cfg.max_value - fe_cfg.min_value) * f
        };
        let err = self.fe.abs();
        if err > allowed {
            self.raise_alarm(AlarmId::FollowingError, supplement::NONE);
        } else if err > allowed * fe_cfg.warning_level / 100.0 {
            self.raise_alarm(AlarmId::FollowingErrorWarning, supplement::NONE);
        }
    }

    /// The status of the axis as it is now.
    pub(super) fn current_status(&self) -> super::AxisStatus {
        let tot = self.total();
        let (ew, ww, detail) = self.alarm_words();
        let main = self.main.as_ref().map(|m| m.instr);
        let mut sw = self.job_status_bits(main, &detail) | self.motion_status_bits(tot);
        if self.cfg.kind == AxisKind::Speed {
            sw &= status_bit::SPEED_AXIS_MASK;
        }
        let state = self.plc_state(&detail, main, tot);
        super::AxisStatus {
            time_ns: self.now,
            state,
            status_word: sw,
            error_word: ew,
            warning_word: ww,
            error_detail: detail,
            position: self.wrap(tot.p),
            velocity: tot.v,
            acceleration: tot.a,
            actual_position: self.wrap(self.actual_p),
            actual_velocity: self.actual_v,
            following_error: self.fe,
            override_velocity: self.override_pct,
            position_unwrapped: tot.p,
            actual_position_unwrapped: self.actual_p,
            motion_job: self.main.as_ref().map(|m| (m.id, m.instr)),
            superimposed_job: self
                .sup_job
                .as_ref()
                .map(|s| (s.id, Instruction::MoveSuperimposed)),
            sync_job: self.sync.as_ref().map(|s| (s.id, s.instr)),
            sync_function: match self.sync.as_ref().map(|s| s.instr) {
                Some(Instruction::GearIn) => sync_function::GEAR_IN,
                // MC_FlyingGear_BkPlcMc: a gearing synchronised on positions, as MC_GearInPos.
                Some(Instruction::GearInPos | Instruction::FlyingGear) => {
                    sync_function::GEAR_IN_POS
                }
                Some(Instruction::CamIn) => sync_function::CAM_IN,
                _ => sync_function::NONE,
            },
            sync_status_word: if self.sync.is_some() {
                self.sync_flags
            } else {
                0
            },
            phase_shift: self.phase.p,
            queue_depth: self.queue.len() as u32,
        }
    }

    /// ErrorWord, WarningWord and ErrorDetail from the pending alarms.
    fn alarm_words(&self) -> (u32, u32, ErrorDetail) {
        let mut ew = 0u32;
        let mut ww = 0u32;
        let detail = if self.alarm_pending {
            for a in self.alarms() {
                let spec = a.spec();
                ew |= spec.error_mask();
                ww |= spec.warning_mask();
            }
            ErrorDetail::from_pending(self.alarms())
        } else {
            ErrorDetail::NONE
        };
        (ew, ww, detail)
    }

    /// The StatusWord bits of the enable, the alarms and the running jobs. (The running job's
    /// instruction and the synchronous phase are each matched once, not compared per bit.)
    fn job_status_bits(&self, main: Option<Instruction>, detail: &ErrorDetail) -> u32 {
        use super::sync::SyncPhase;
        let main_bits = match main {
            Some(
                Instruction::MoveAbsolute | Instruction::MoveRelative | Instruction::MoveAdditive,
            ) => status_bit::POSITIONING_COMMAND,
            Some(Instruction::MoveJog) => status_bit::JOG_COMMAND,
            Some(Instruction::MoveVelocity) => status_bit::VELOCITY_COMMAND,
            Some(Instruction::Home) => status_bit::HOMING_COMMAND,
            Some(Instruction::MotionInPosition | Instruction::MotionInVelocity) => {
                status_bit::MOTION_IN_COMMAND
            }
            _ => 0,
        };
        let sync_bits = match self.sync.as_ref().map(|j| j.phase) {
            Some(SyncPhase::Synchronizing) => status_bit::SYNCHRONIZING,
            Some(SyncPhase::Synchronous) => status_bit::SYNCHRONOUS,
            _ => 0,
        };
        main_bits
            | sync_bits
            | bit(status_bit::ENABLE, self.enabled)
            | bit(status_bit::ERROR, detail.number != 0)
            | bit(status_bit::HOMING_DONE, self.homed)
            | bit(
                status_bit::DONE,
                self.main.is_none() && self.sup_job.is_none() && self.sync.is_none(),
            )
            | bit(status_bit::HOMING_COMMAND, self.passive.is_some())
            | bit(
                status_bit::SUPERIMPOSED_MOTION_COMMAND,
                self.sup_job.is_some(),
            )
            | bit(status_bit::PHASING_COMMAND, self.phasing.is_some())
    }

    /// The StatusWord bits of the motion (`tot`: the total setpoint), the limit switches and
    /// the control mode.
    fn motion_status_bits(&self, tot: State) -> u32 {
        let standstill = self
            .standstill_since
            .map(|t| self.now - t >= (self.cfg.standstill.min_dwell_time * 1e9).round() as i64)
            .unwrap_or(false);
        let sw_limit = match self.sw_active {
            Some(Sense::Negative) => status_bit::SW_LIMIT_MIN_ACTIVE,
            Some(Sense::Positive) => status_bit::SW_LIMIT_MAX_ACTIVE,
            None => 0,
        };
        let hw_limit = match self.hw_trigger {
            Some((Sense::Negative, _)) => status_bit::HW_LIMIT_MIN_ACTIVE,
            Some((Sense::Positive, _)) => status_bit::HW_LIMIT_MAX_ACTIVE,
            None => 0,
        };
        sw_limit
            | hw_limit
            | bit(
                status_bit::STANDSTILL,
                standstill && self.cfg.kind != AxisKind::Speed,
            )
            | bit(status_bit::CONSTANT_VELOCITY, tot.a == 0.0)
            | bit(
                status_bit::ACCELERATING,
                tot.a != 0.0 && tot.a * tot.v >= 0.0,
            )
            | bit(status_bit::DECELERATING, tot.a * tot.v < 0.0)
            | bit(status_bit::AXIS_SIMULATION, self.cfg.virtual_axis)
            | bit(
                status_bit::NON_POSITION_CONTROLLED,
                self.enabled && !self.pos_ctrl,
            )
            | bit(status_bit::IN_LIMITATION, self.in_limitation)
            | bit(
                status_bit::TORQUE_LIMITING_COMMAND,
                self.torque_active && self.torque.limiting_active(),
            )
            | bit(
                status_bit::IN_CLAMPING,
                self.torque_active && self.torque.in_clamping(),
            )
    }

    /// The PLCopen state from the alarm reaction, the enable and the running jobs.
    fn plc_state(&self, detail: &ErrorDetail, main: Option<Instruction>, tot: State) -> AxisState {
        if detail.reaction != Reaction::None {
            AxisState::ErrorStop
        } else if !self.enabled {
            AxisState::Disabled
        } else if self.stop_lock
            || main == Some(Instruction::Stop)
            || self.power.disabling
            || self.hyd_stopping(main)
        {
            AxisState::Stopping
        } else {
            match main {
                Some(Instruction::Home) => AxisState::Homing,
                // The library's McState_Homing for MC_Home_BkPlcMc.
                Some(Instruction::HydHome) => AxisState::Homing,
                // The library's McState_Synchronizedmotion for MC_MoveJoySticked_BkPlcMc.
                Some(Instruction::MoveJoySticked) => AxisState::SynchronizedMotion,
                // MC_AxRtSetExtGenValues_BkPlcMc: McState_Synchronizedmotion; and
                // MC_AxRtSetDirectOutput_BkPlcMc: McState_Continuousmotion.
                Some(Instruction::SetExtGenValues) => AxisState::SynchronizedMotion,
                Some(Instruction::SetDirectOutput) => AxisState::ContinuousMotion,
                Some(
                    Instruction::MoveVelocity
                    | Instruction::MoveJog
                    | Instruction::MotionInPosition
                    | Instruction::MotionInVelocity
                    | Instruction::PressureControl
                    | Instruction::PressureControlFf,
                ) => AxisState::ContinuousMotion,
                Some(_) => AxisState::DiscreteMotion,
                None if self.sync.is_some() => AxisState::SynchronizedMotion,
                None if self.sup_job.is_some() => AxisState::DiscreteMotion,
                // After MC_GearOut the axis keeps moving with no job (PLCopen).
                None if matches!(self.goal, Goal::Velocity { .. }) && tot.v != 0.0 => {
                    AxisState::ContinuousMotion
                }
                None => AxisState::Standstill,
            }
        }
    }
}

/// `bit` if `on`, else 0.
fn bit(bit: u32, on: bool) -> u32 {
    if on {
        bit
    } else {
        0
    }
}
