//! MC_TorqueLimiting (force/torque limiting, fixed stop detection and clamping), MC_TorqueAdditive
//! and MC_TorqueRange (S7-1500T Motion Control V4.0 function manual, 'Force/torque limiting',
//! 'Fixed stop detection', 'Additive setpoint torque', 'Permissible torque range' and the
//! instructions 'MC_TorqueLimiting V4', 'MC_TorqueAdditive V4', 'MC_TorqueRange V4').
//!
//! All three are enable-type jobs that no other job aborts and that abort none (except the
//! motion job the fixed stop ends): the axis keeps their values and hands them to its drive
//! every cycle ([`TorqueOutputs`]); the drive link converts them to the drive's per mille.
//! Only an axis on a drive with a torque interface takes them
//! ([`Axis::set_torque_interface`]).

use super::{Axis, AxisKind, Goal};
use crate::catalog::alarm::{supplement, AlarmId};
use crate::catalog::error_id::ErrorId;
use crate::kinematics::profile::State;
use crate::objects::job::{Instruction, JobEventKind, JobId};
use crate::plant::link::TorqueOutputs;

/// The largest torque value the instructions take (`Value`, `UpperLimit`, `LowerLimit`).
pub const TORQUE_VALUE_MAX: f64 = 1e12;

/// A torque value the instructions take: a number within ±[`TORQUE_VALUE_MAX`].
fn torque_value(x: f64) -> bool {
    (-TORQUE_VALUE_MAX..=TORQUE_VALUE_MAX).contains(&x)
}

/// The running MC_TorqueLimiting job.
#[derive(Copy, Clone, Debug, PartialEq)]
struct Limiting {
    id: JobId,
    /// The limit in force (N·m or N, >= 0).
    limit: f64,
    /// `Mode`: 0 force/torque limiting, 1 fixed stop detection.
    mode: i32,
    /// While clamped: the actual position at detection and the sign of the direction towards
    /// the stop.
    clamp: Option<(f64, f64)>,
}

/// The torque jobs of an axis and what the drive reports.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub(super) struct TorqueJobs {
    /// The drive has a torque interface (limits, additive torque, actual torque).
    capable: bool,
    limiting: Option<Limiting>,
    /// MC_TorqueAdditive: its job and value.
    additive: Option<(JobId, f64)>,
    /// MC_TorqueRange: its job, upper and lower limit.
    range: Option<(JobId, f64, f64)>,
}

/// `StatusTorqueData` and the outputs of the torque instructions.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
#[doc(alias = "StatusTorqueData")]
pub struct TorqueStatus {
    /// `CommandAdditiveTorqueActive`.
    pub additive_active: bool,
    /// `CommandTorqueRangeActive`.
    pub range_active: bool,
    /// `ActualTorque` (N·m, or N on a linear axis).
    pub actual_torque: f64,
    /// MC_TorqueLimiting is active (StatusWord X26 "TorqueLimitingCommand").
    pub limiting_active: bool,
    /// MC_TorqueLimiting.InClamping (StatusWord X30).
    pub in_clamping: bool,
    /// The limit in force of MC_TorqueLimiting (N·m or N; 0 without the job).
    pub limit: f64,
}

impl TorqueJobs {
    /// What the drive gets this cycle.
    #[inline]
    pub(super) fn outputs(&self) -> TorqueOutputs {
        TorqueOutputs {
            limit: self.limiting.map(|l| l.limit),
            range: self.range.map(|(_, up, lo)| (up, lo)),
            additive: self.additive.map_or(0.0, |(_, v)| v),
        }
    }

    /// Clamped at a fixed stop.
    pub(super) fn in_clamping(&self) -> bool {
        self.limiting.is_some_and(|l| l.clamp.is_some())
    }

    /// MC_TorqueLimiting is active.
    pub(super) fn limiting_active(&self) -> bool {
        self.limiting.is_some()
    }

    /// Any job active.
    fn any(&self) -> bool {
        self.limiting.is_some() || self.additive.is_some() || self.range.is_some()
    }

    /// The status, with the drive's actual torque `actual`.
    fn status(&self, actual: f64) -> TorqueStatus {
        TorqueStatus {
            additive_active: self.additive.is_some(),
            range_active: self.range.is_some(),
            actual_torque: actual,
            limiting_active: self.limiting.is_some(),
            in_clamping: self.in_clamping(),
            limit: self.limiting.map_or(0.0, |l| l.limit),
        }
    }
}

impl Axis {
    /// Says whether the axis's drive has a torque interface (the runtime: a CiA 402 drive with
    /// a rated torque). Without it the torque instructions are refused (16#8044, 16#804F).
    pub fn set_torque_interface(&mut self, on: bool) {
        self.torque.capable = on;
    }

    /// `StatusTorqueData` and the state of MC_TorqueLimiting (`ActualTorque` as the connected
    /// drive last reported it; 0 in simulation).
    pub fn torque_status(&self) -> TorqueStatus {
        let actual = match &self.link {
            super::DriveLink::Connected { inputs, .. } => inputs.torque_actual,
            super::DriveLink::Simulation(_) => 0.0,
        };
        self.torque.status(actual)
    }

    /// MC_TorqueLimiting, MC_TorqueAdditive and MC_TorqueRange; any other command is refused
    /// (16#8002).
    pub(super) fn apply_torque(&mut self, cmd: &super::Command) -> Result<JobId, ErrorId> {
        let r = self.torque_command(cmd);
        self.torque_active = self.torque.any();
        r
    }

    fn torque_command(&mut self, cmd: &super::Command) -> Result<JobId, ErrorId> {
        use super::Command as C;
        match *cmd {
            C::TorqueLimiting {
                enable,
                limit,
                mode,
            } => self.cmd_torque_limiting(enable, limit, mode),
            C::TorqueAdditive { enable, value } => self.cmd_torque_additive(enable, value),
            C::TorqueRange {
                enable,
                upper_limit,
                lower_limit,
            } => self.cmd_torque_range(enable, upper_limit, lower_limit),
            _ => Err(ErrorId::IllegalObject),
        }
    }

    /// MC_TorqueLimiting: Enable, Limit (< 0: the configured default) and Mode, re-read while
    /// enabled. Disabling while InClamping is refused (16#8046) and the job stays.
    fn cmd_torque_limiting(
        &mut self,
        enable: bool,
        limit: f64,
        mode: i32,
    ) -> Result<JobId, ErrorId> {
        let running = self.torque.limiting;
        if !enable {
            let Some(l) = running else {
                return Ok(0);
            };
            if l.clamp.is_some() {
                return Err(ErrorId::InClamping);
            }
            self.torque.limiting = None;
            self.emit(l.id, Instruction::TorqueLimiting, JobEventKind::Done);
            return Ok(l.id);
        }
        if !self.torque.capable {
            return Err(ErrorId::TorqueReductionNotConfigured);
        }
        if self.torque.range.is_some() {
            return Err(ErrorId::TorqueLimitingRangeExclusive);
        }
        let limit = if limit.is_nan() || limit.is_infinite() {
            return Err(ErrorId::IllegalTorqueLimit);
        } else if limit < 0.0 {
            self.cfg
                .torque
                .limit_default
                .ok_or(ErrorId::IllegalTorqueLimit)?
        } else {
            limit
        };
        // Fixed stop detection: positioning and synchronous axes only.
        match mode {
            0 => {}
            1 if self.cfg.kind != AxisKind::Speed => {}
            _ => return Err(ErrorId::IllegalMode),
        }
        if let Some(mut l) = running {
            if l.clamp.is_some() && mode != 1 {
                // Leaving fixed stop detection would end the clamping: as a disable.
                return Err(ErrorId::InClamping);
            }
            l.limit = limit;
            l.mode = mode;
            self.torque.limiting = Some(l);
            return Ok(l.id);
        }
        let id = self.new_id();
        self.emit(id, Instruction::TorqueLimiting, JobEventKind::Busy);
        self.torque.limiting = Some(Limiting {
            id,
            limit,
            mode,
            clamp: None,
        });
        Ok(id)
    }

    /// MC_TorqueAdditive: Enable, Value (-1e12..1e12), re-read while enabled.
    fn cmd_torque_additive(&mut self, enable: bool, value: f64) -> Result<JobId, ErrorId> {
        let running = self.torque.additive;
        if !enable {
            let Some((id, _)) = running else {
                return Ok(0);
            };
            self.torque.additive = None;
            self.emit(id, Instruction::TorqueAdditive, JobEventKind::Done);
            return Ok(id);
        }
        if !self.torque.capable {
            return Err(ErrorId::NoAdditionalTorqueTelegram);
        }
        if !torque_value(value) {
            return Err(ErrorId::IllegalAdditiveTorque);
        }
        let id = match running {
            Some((id, _)) => id,
            None => {
                let id = self.new_id();
                self.emit(id, Instruction::TorqueAdditive, JobEventKind::Busy);
                id
            }
        };
        self.torque.additive = Some((id, value));
        Ok(id)
    }

    /// MC_TorqueRange: Enable, UpperLimit, LowerLimit (each within ±1e12, upper > lower),
    /// re-read while enabled; refused while MC_TorqueLimiting is active (16#804E).
    fn cmd_torque_range(&mut self, enable: bool, upper: f64, lower: f64) -> Result<JobId, ErrorId> {
        let running = self.torque.range;
        if !enable {
            let Some((id, ..)) = running else {
                return Ok(0);
            };
            self.torque.range = None;
            self.emit(id, Instruction::TorqueRange, JobEventKind::Done);
            return Ok(id);
        }
        if !self.torque.capable {
            return Err(ErrorId::NoAdditionalTorqueTelegram);
        }
        if self.torque.limiting.is_some() {
            return Err(ErrorId::TorqueLimitingRangeExclusive);
        }
        if !torque_value(upper) {
            return Err(ErrorId::IllegalUpperTorqueLimit);
        }
        if !torque_value(lower) {
            return Err(ErrorId::IllegalLowerTorqueLimit);
        }
        if upper <= lower {
            return Err(ErrorId::TorqueLimitsInverted);
        }
        let id = match running {
            Some((id, ..)) => id,
            None => {
                let id = self.new_id();
                self.emit(id, Instruction::TorqueRange, JobEventKind::Busy);
                id
            }
        };
        self.torque.range = Some((id, upper, lower));
        Ok(id)
    }

    /// Whether the position-based monitorings (following error, the time limits of positioning
    /// and standstill) are off now: under MC_TorqueLimiting or MC_TorqueRange unless
    /// `TorqueLimiting.PositionBasedMonitorings` keeps them.
    pub(super) fn position_monitorings_off(&self) -> bool {
        self.torque_active
            && (self.torque.limiting.is_some() || self.torque.range.is_some())
            && !self.cfg.torque.keep_position_monitorings
    }

    /// A new motion job in direction `dir` (its sign; 0: none) while clamped: towards the
    /// stop 16#8047; a job not position-controlled 16#8045.
    pub(super) fn check_clamping(
        &self,
        dir: f64,
        position_controlled: bool,
    ) -> Result<(), ErrorId> {
        let Some((_, towards)) = self.torque.limiting.and_then(|l| l.clamp) else {
            return Ok(());
        };
        if !position_controlled {
            return Err(ErrorId::FixedStopActive);
        }
        if dir * towards > 0.0 {
            return Err(ErrorId::MotionIntoFixedStop);
        }
        Ok(())
    }

    /// The cycle's part while a torque job is active, after the following error is formed:
    /// fixed stop detection and the clamping monitoring.
    pub(super) fn torque_cycle(&mut self) {
        let Some(mut l) = self.torque.limiting else {
            return;
        };
        if l.mode != 1 || !(self.enabled && self.pos_ctrl) {
            if l.clamp.take().is_some() {
                self.torque.limiting = Some(l);
            }
            return;
        }
        match l.clamp {
            None => {
                if self.fe.abs() > self.cfg.torque.clamping_deviation {
                    l.clamp = Some((self.actual_p, self.fe.signum()));
                    self.torque.limiting = Some(l);
                    self.clamp_at_stop();
                }
            }
            Some((at, towards)) => {
                let moved = self.actual_p - at;
                if moved.abs() > self.cfg.torque.clamping_tolerance {
                    l.clamp = None;
                    self.torque.limiting = Some(l);
                    // Retracting: a motion job away from the stop takes the axis out of the
                    // window on the far side. Anything else is the stop giving way (or
                    // pushing back).
                    let retracting = moved * towards < 0.0 && self.main.is_some();
                    if !retracting {
                        self.raise_alarm(AlarmId::ClampingMonitoring, supplement::NONE);
                    }
                }
            }
        }
    }

    /// The fixed stop is reached: the running motion job ends with CommandAborted and the
    /// setpoint stays where it is (the following error stays constant); position control
    /// stays on.
    fn clamp_at_stop(&mut self) {
        self.abort_main(JobEventKind::CommandAborted);
        self.abort_sup(JobEventKind::CommandAborted);
        self.basic = State {
            v: 0.0,
            a: 0.0,
            ..self.basic
        };
        self.set_goal(Goal::Hold);
    }
}
