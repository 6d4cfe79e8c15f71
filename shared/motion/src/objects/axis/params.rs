//! The axis' technology-object tags under their S7-1500T names that MC_WriteParameter may change
//! while the axis runs, and MC_ReadParameter (docs/parameters.md).
//!
//! Which tags and when they take effect: S7-1500T Motion Control V4.0 function manual, A.2 'Tags
//! of the positioning axis/synchronous axis technology object' (A.2.15 'DynamicLimits tags' ..
//! A.2.25 'StandstillSignal tags'), column W: `DIR` from the next cycle, `CAL` from the next
//! job, `RES` only with a restart (refused here, `16#8081`). The write is checked with the
//! configuration's own check at load ([`AxisConfig::validate`]) on a copy; a refused write
//! changes nothing.
//!
//! A parameter's number is its position in [`AXIS_PARAMETERS`] plus one (rows are only ever
//! appended): the instruction carries the number, the tag name is mapped to it where the
//! command is parsed. S7-1500 V4.0 addresses tags by name only, and S7-Technology's parameter
//! numbers belong to another object model; these numbers are tandem's.

use super::{Axis, AxisConfig, AxisKind, Goal, SoftwareLimits};
use crate::catalog::error_id::ErrorId;
use crate::kinematics::profile::Limits;
use crate::objects::job::{Instruction, JobEventKind, JobId};
use crate::objects::parameter::{self, Effect, ParamEntry, ParamType};
use crate::plant::drive::DriveModel;
use crate::plant::link::DriveLink;

/// What MC_WriteParameter sees of an axis: its configuration and the values kept beside it.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisParams {
    /// The configuration (as [`Axis::config`] shows it after the write).
    pub cfg: AxisConfig,
    /// The values the configuration does not hold.
    pub extra: ParamExtras,
}

/// Parameter values kept beside the configuration.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ParamExtras {
    /// `DynamicLimits.MaxVelocity` (`RES`: the cell file's value). The configuration's
    /// `limits.max_velocity` is `DynamicLimits.Velocity`, the programmable maximum (`DIR`),
    /// which may not exceed it.
    pub max_velocity: f64,
    /// `PositionLimits_SW.MinPosition` / `MaxPosition`, also while the limits are inactive
    /// (the configuration holds them only while `PositionLimits_SW.Active`).
    pub sw: SoftwareLimits,
    /// `Override.Velocity` (%).
    pub override_pct: f64,
    /// The axis' position controller is the simulated drive's (`PositionControl.Kv`/`Kpc`
    /// act on it); with a connected drive they belong to the drive.
    pub own_position_loop: bool,
}

impl ParamExtras {
    /// The values at construction from `cfg`.
    pub(super) fn new(cfg: &AxisConfig) -> Self {
        Self {
            max_velocity: cfg.limits.max_velocity,
            // The reference's range of `MinPosition` / `MaxPosition` when none is configured.
            sw: cfg.sw_limits.unwrap_or(SoftwareLimits {
                min: -1e12,
                max: 1e12,
            }),
            override_pct: 100.0,
            own_position_loop: matches!(cfg.drive, DriveModel::PositionLoop { .. }),
        }
    }
}

/// The check of a changed view: the configuration's check at load, the software limits also
/// while inactive, the programmable maximum velocity within the configured one, the override
/// within 0..200 %.
fn check(v: &AxisParams) -> Result<(), ()> {
    v.cfg.validate().map_err(|_| ())?;
    let x = &v.extra;
    let ok = x.sw.max > x.sw.min
        && v.cfg.limits.max_velocity <= x.max_velocity
        && (0.0..=200.0).contains(&x.override_pct);
    ok.then_some(()).ok_or(())
}

fn positioning(v: &AxisParams) -> bool {
    v.cfg.kind != AxisKind::Speed
}

fn always(_: &AxisParams) -> bool {
    true
}

fn position_loop(v: &AxisParams) -> bool {
    positioning(v) && v.extra.own_position_loop
}

fn bool_value(b: bool) -> f64 {
    f64::from(u8::from(b))
}

fn kv(v: &AxisParams) -> f64 {
    match v.cfg.drive {
        DriveModel::PositionLoop { kv, .. } => kv,
        DriveModel::Delay { .. } => 0.0,
    }
}

fn kpc_percent(v: &AxisParams) -> f64 {
    match v.cfg.drive {
        DriveModel::PositionLoop { kpc, .. } => kpc * 100.0,
        DriveModel::Delay { .. } => 0.0,
    }
}

fn set_sw(v: &mut AxisParams, f: impl FnOnce(&mut SoftwareLimits)) {
    f(&mut v.extra.sw);
    if v.cfg.sw_limits.is_some() {
        v.cfg.sw_limits = Some(v.extra.sw);
    }
}

/// A row of [`AXIS_PARAMETERS`] (a short constructor keeps the table readable).
#[allow(clippy::too_many_arguments)]
const fn row(
    key: &'static str,
    unit: &'static str,
    ty: ParamType,
    effect: Effect,
    range: &'static str,
    invalid: ErrorId,
    reference: &'static str,
    available: fn(&AxisParams) -> bool,
    get: fn(&AxisParams) -> f64,
    set: fn(&mut AxisParams, f64),
) -> ParamEntry<&'static str, AxisParams> {
    ParamEntry {
        key,
        unit,
        ty,
        effect,
        range,
        invalid,
        reference,
        available,
        get,
        set,
    }
}

use ErrorId as E;
use ParamType::{Bool, Real};

const A215: &str = "A.2.15 'DynamicLimits tags (positioning axis/synchronous axis)'";
const A216: &str = "A.2.16 'DynamicDefaults tags (positioning axis/synchronous axis)'";
const A217: &str = "A.2.17 'PositionLimits_SW tags (positioning axis/synchronous axis)'";
const A218: &str = "A.2.18 'PositionLimits_HW tags (positioning axis/synchronous axis)'";
const A219: &str = "A.2.19 'Homing tags (positioning axis/synchronous axis)'";
const A220: &str = "A.2.20 'Override tags (positioning axis/synchronous axis)'";
const A221: &str = "A.2.21 'PositionControl tags (positioning axis/synchronous axis)'";
const A223: &str = "A.2.23 'FollowingError tags (positioning axis/synchronous axis)'";
const A224: &str = "A.2.24 'PositionMonitoring tags (positioning axis/synchronous axis)'";
const A225: &str = "A.2.25 'StandstillSignal tags (positioning axis/synchronous axis)'";

/// The axis' parameters (S7-1500T Motion Control V4.0 function manual, the sections named in
/// each row). Numbers: position + 1; append only.
#[rustfmt::skip]
pub static AXIS_PARAMETERS: [ParamEntry<&str, AxisParams>; 32] = [
    row("DynamicLimits.MaxVelocity", "u/s", Real, Effect::Restart, "> 0", E::IllegalVelocity, A215, always,
        |v| v.extra.max_velocity, |v, x| v.extra.max_velocity = x),
    row("DynamicLimits.Velocity", "u/s", Real, Effect::NextCycle, "0 < x <= MaxVelocity, >= DynamicDefaults.Velocity", E::IllegalVelocity, A215, always,
        |v| v.cfg.limits.max_velocity, |v, x| v.cfg.limits.max_velocity = x),
    row("DynamicLimits.MaxAcceleration", "u/s²", Real, Effect::NextCycle, "> 0, >= DynamicDefaults.Acceleration", E::IllegalAcceleration, A215, always,
        |v| v.cfg.limits.max_acceleration, |v, x| v.cfg.limits.max_acceleration = x),
    row("DynamicLimits.MaxDeceleration", "u/s²", Real, Effect::NextCycle, "> 0, >= DynamicDefaults.Deceleration", E::IllegalDeceleration, A215, always,
        |v| v.cfg.limits.max_deceleration, |v, x| v.cfg.limits.max_deceleration = x),
    row("DynamicLimits.MaxJerk", "u/s³", Real, Effect::NextCycle, "> 0, >= DynamicDefaults.Jerk", E::IllegalJerk, A215, always,
        |v| v.cfg.limits.max_jerk, |v, x| v.cfg.limits.max_jerk = x),
    row("DynamicDefaults.Velocity", "u/s", Real, Effect::NextJob, "0 < x <= DynamicLimits.Velocity", E::IllegalVelocity, A216, always,
        |v| v.cfg.defaults.velocity, |v, x| v.cfg.defaults.velocity = x),
    row("DynamicDefaults.Acceleration", "u/s²", Real, Effect::NextJob, "0 < x <= MaxAcceleration", E::IllegalAcceleration, A216, always,
        |v| v.cfg.defaults.acceleration, |v, x| v.cfg.defaults.acceleration = x),
    row("DynamicDefaults.Deceleration", "u/s²", Real, Effect::NextJob, "0 < x <= MaxDeceleration", E::IllegalDeceleration, A216, always,
        |v| v.cfg.defaults.deceleration, |v, x| v.cfg.defaults.deceleration = x),
    row("DynamicDefaults.Jerk", "u/s³", Real, Effect::NextJob, "0 <= x <= MaxJerk (0: trapezoidal)", E::IllegalJerk, A216, always,
        |v| v.cfg.defaults.jerk, |v, x| v.cfg.defaults.jerk = x),
    row("DynamicDefaults.EmergencyDeceleration", "u/s²", Real, Effect::NextCycle, "> 0", E::IllegalDeceleration, A216, always,
        |v| v.cfg.defaults.emergency_deceleration, |v, x| v.cfg.defaults.emergency_deceleration = x),
    row("PositionLimits_SW.Active", "", Bool, Effect::NextCycle, "0, 1 (not on a modulo axis)", E::IllegalParameterValue, A217, positioning,
        |v| bool_value(v.cfg.sw_limits.is_some()),
        |v, x| v.cfg.sw_limits = (x != 0.0).then_some(v.extra.sw)),
    row("PositionLimits_SW.MinPosition", "u", Real, Effect::NextCycle, "< MaxPosition", E::IllegalPosition, A217, positioning,
        |v| v.extra.sw.min, |v, x| set_sw(v, |s| s.min = x)),
    row("PositionLimits_SW.MaxPosition", "u", Real, Effect::NextCycle, "> MinPosition", E::IllegalPosition, A217, positioning,
        |v| v.extra.sw.max, |v, x| set_sw(v, |s| s.max = x)),
    row("PositionLimits_HW.Active", "", Bool, Effect::Restart, "0, 1", E::IllegalParameterValue, A218, positioning,
        |v| bool_value(v.cfg.hw_limits_active), |v, x| v.cfg.hw_limits_active = x != 0.0),
    row("Homing.AutoReversal", "", Bool, Effect::Restart, "0, 1", E::IllegalParameterValue, A219, positioning,
        |v| bool_value(v.cfg.homing.auto_reversal), |v, x| v.cfg.homing.auto_reversal = x != 0.0),
    row("Homing.ApproachDirection", "", Bool, Effect::NextJob, "0 positive, 1 negative", E::IllegalParameterValue, A219, positioning,
        |v| bool_value(v.cfg.homing.approach_direction == super::Sense::Negative),
        |v, x| v.cfg.homing.approach_direction = if x != 0.0 { super::Sense::Negative } else { super::Sense::Positive }),
    row("Homing.ApproachVelocity", "u/s", Real, Effect::NextJob, "> 0", E::IllegalVelocity, A219, positioning,
        |v| v.cfg.homing.approach_velocity, |v, x| v.cfg.homing.approach_velocity = x),
    row("Homing.ReferencingVelocity", "u/s", Real, Effect::NextJob, "> 0", E::IllegalVelocity, A219, positioning,
        |v| v.cfg.homing.referencing_velocity, |v, x| v.cfg.homing.referencing_velocity = x),
    row("Homing.HomePosition", "u", Real, Effect::NextJob, "finite", E::IllegalPosition, A219, positioning,
        |v| v.cfg.homing.home_position, |v, x| v.cfg.homing.home_position = x),
    row("Override.Velocity", "%", Real, Effect::NextCycle, "0..200", E::IllegalOverride, A220, always,
        |v| v.extra.override_pct, |v, x| v.extra.override_pct = x),
    row("PositionControl.Kv", "1/s", Real, Effect::NextCycle, "> 0", E::IllegalParameterValue, A221, position_loop,
        kv, |v, x| if let DriveModel::PositionLoop { kv, .. } = &mut v.cfg.drive { *kv = x }),
    row("PositionControl.Kpc", "%", Real, Effect::NextCycle, "0..150", E::IllegalParameterValue, A221, position_loop,
        kpc_percent, |v, x| if let DriveModel::PositionLoop { kpc, .. } = &mut v.cfg.drive { *kpc = x / 100.0 }),
    row("FollowingError.EnableMonitoring", "", Bool, Effect::Restart, "0, 1", E::IllegalParameterValue, A223, positioning,
        |v| bool_value(v.cfg.following_error.enable), |v, x| v.cfg.following_error.enable = x != 0.0),
    row("FollowingError.MinValue", "u", Real, Effect::NextCycle, "> 0, <= MaxValue", E::IllegalParameterValue, A223, positioning,
        |v| v.cfg.following_error.min_value, |v, x| v.cfg.following_error.min_value = x),
    row("FollowingError.MaxValue", "u", Real, Effect::NextCycle, "> 0, >= MinValue", E::IllegalParameterValue, A223, positioning,
        |v| v.cfg.following_error.max_value, |v, x| v.cfg.following_error.max_value = x),
    row("FollowingError.MinVelocity", "u/s", Real, Effect::NextCycle, ">= 0", E::IllegalParameterValue, A223, positioning,
        |v| v.cfg.following_error.min_velocity, |v, x| v.cfg.following_error.min_velocity = x),
    row("FollowingError.WarningLevel", "%", Real, Effect::NextCycle, "0..100", E::IllegalParameterValue, A223, positioning,
        |v| v.cfg.following_error.warning_level, |v, x| v.cfg.following_error.warning_level = x),
    row("PositioningMonitoring.ToleranceTime", "s", Real, Effect::NextCycle, ">= 0", E::IllegalParameterValue, A224, positioning,
        |v| v.cfg.positioning.tolerance_time, |v, x| v.cfg.positioning.tolerance_time = x),
    row("PositioningMonitoring.MinDwellTime", "s", Real, Effect::NextCycle, ">= 0", E::IllegalParameterValue, A224, positioning,
        |v| v.cfg.positioning.min_dwell_time, |v, x| v.cfg.positioning.min_dwell_time = x),
    row("PositioningMonitoring.Window", "u", Real, Effect::NextCycle, ">= 0", E::IllegalParameterValue, A224, positioning,
        |v| v.cfg.positioning.window, |v, x| v.cfg.positioning.window = x),
    row("StandstillSignal.VelocityThreshold", "u/s", Real, Effect::NextCycle, ">= 0", E::IllegalParameterValue, A225, always,
        |v| v.cfg.standstill.velocity_threshold, |v, x| v.cfg.standstill.velocity_threshold = x),
    row("StandstillSignal.MinDwellTime", "s", Real, Effect::NextCycle, ">= 0", E::IllegalParameterValue, A225, always,
        |v| v.cfg.standstill.min_dwell_time, |v, x| v.cfg.standstill.min_dwell_time = x),
];

/// The number of the parameter `name` (S7-1500T tag name, e.g. `"DynamicLimits.MaxJerk"`).
pub fn axis_parameter_number(name: &str) -> Option<u16> {
    let i = AXIS_PARAMETERS.iter().position(|e| e.key == name)?;
    u16::try_from(i + 1).ok()
}

/// The row of parameter number `number`.
pub fn axis_parameter(number: u16) -> Option<&'static ParamEntry<&'static str, AxisParams>> {
    AXIS_PARAMETERS.get(usize::from(number).checked_sub(1)?)
}

/// `lim` within `max` (a trapezoidal job, jerk 0, stays trapezoidal).
fn within(lim: Limits, max: &Limits) -> Limits {
    Limits {
        vel: lim.vel.min(max.vel),
        acc: lim.acc.min(max.acc),
        dec: lim.dec.min(max.dec),
        jerk: if lim.jerk > 0.0 {
            lim.jerk.min(max.jerk)
        } else {
            lim.jerk
        },
    }
}

impl Axis {
    /// What MC_WriteParameter sees: the configuration and the values beside it (a copy; no
    /// allocation).
    pub fn parameters(&self) -> AxisParams {
        AxisParams {
            cfg: self.cfg.clone(),
            extra: ParamExtras {
                override_pct: self.override_pct,
                ..self.param_extra
            },
        }
    }

    /// MC_ReadParameter: the current value of parameter `number` (a boolean as 0 or 1), or
    /// 16#8080 (no such number), 16#8086 (not on this axis).
    #[doc(alias = "MC_ReadParameter")]
    pub fn read_parameter(&self, number: u16) -> Result<f64, ErrorId> {
        let e = axis_parameter(number).ok_or(ErrorId::InvalidParameterNumber)?;
        parameter::read(&AXIS_PARAMETERS, &e.key, &self.parameters())
    }

    /// MC_ReadParameter as a job: Done at once, or refused as [`Axis::read_parameter`].
    pub(super) fn cmd_read_parameter(&mut self, number: u16) -> Result<JobId, ErrorId> {
        self.read_parameter(number)?;
        let id = self.new_id();
        self.emit(id, Instruction::ReadParameter, JobEventKind::Done);
        Ok(id)
    }

    /// MC_WriteParameter: checks and applies the write (docs/parameters.md). The value counts
    /// from the next cycle; a lower dynamic limit replans the running job from the current
    /// setpoint (nothing jumps). On a hydraulic axis the S7 tags are not available (16#8086).
    pub(super) fn cmd_write_parameter(
        &mut self,
        number: u16,
        value: f64,
    ) -> Result<JobId, ErrorId> {
        let e = axis_parameter(number).ok_or(ErrorId::InvalidParameterNumber)?;
        if self.cfg.hydraulic.is_some() && e.effect.writable() {
            return Err(ErrorId::ParameterNotAvailable);
        }
        let mut view = self.parameters();
        parameter::write(&AXIS_PARAMETERS, &e.key, &mut view, value, check)?;
        self.apply_parameters(view);
        let id = self.new_id();
        self.emit(id, Instruction::WriteParameter, JobEventKind::Done);
        Ok(id)
    }

    /// Several parameters at once, checked together (the retained values at start, where
    /// the order they were written in is not kept): either all are applied or none. Refused
    /// with the number and ErrorID of the first value that is refused on its own, or of the
    /// last value when only the whole is inconsistent.
    pub fn write_parameters(&mut self, values: &[(u16, f64)]) -> Result<(), (u16, ErrorId)> {
        let mut view = self.parameters();
        let mut last = None;
        for &(n, x) in values {
            let refuse = |id| (n, id);
            let e = axis_parameter(n).ok_or(refuse(ErrorId::InvalidParameterNumber))?;
            if self.cfg.hydraulic.is_some() {
                return Err(refuse(ErrorId::ParameterNotAvailable));
            }
            // Each value on its own, checked against the view so far but not yet as a whole.
            parameter::write(&AXIS_PARAMETERS, &e.key, &mut view, x, |_| Ok::<(), ()>(()))
                .map_err(refuse)?;
            last = Some((n, e.invalid));
        }
        if let Some(last) = last {
            check(&view).map_err(|()| last)?;
            self.apply_parameters(view);
        }
        Ok(())
    }

    /// Makes a checked view the axis' parameters.
    fn apply_parameters(&mut self, view: AxisParams) {
        let AxisParams { cfg, extra } = view;
        let gains = (cfg.drive != self.cfg.drive).then_some(cfg.drive);
        self.cfg = cfg;
        self.param_extra = extra;
        self.set_override(extra.override_pct);
        if let (Some(DriveModel::PositionLoop { kv, kpc, .. }), DriveLink::Simulation(sim)) =
            (gains, &mut self.link)
        {
            sim.set_gains(kv, kpc);
        }
        self.keep_running_job_within_limits();
    }

    /// `DynamicLimits.*` are `DIR`: no job moves with dynamics above them from the next cycle
    /// on (S7-1500T Motion Control V4.0 function manual, A.2.15 'DynamicLimits tags'). A
    /// running positioning or velocity job whose dynamics exceed new, lower limits is
    /// replanned from the current setpoint with its dynamics brought within them (a velocity
    /// above the new limit is braked down at the job's deceleration, motion engine deviation
    /// 2); higher limits leave it as it is (it keeps the dynamics it started with). Stops and
    /// alarm reactions keep theirs.
    fn keep_running_job_within_limits(&mut self) {
        let max = self.max_limits();
        let goal = match self.goal {
            Goal::Position { target, lim, end_v } => Goal::Position {
                target,
                lim: within(lim, &max),
                end_v: end_v.clamp(-max.vel, max.vel),
            },
            Goal::Velocity { v, lim } => Goal::Velocity {
                v: v.clamp(-max.vel, max.vel),
                lim: within(lim, &max),
            },
            _ => return,
        };
        if goal == self.goal {
            return;
        }
        if let Some(m) = self.main.as_mut() {
            m.lim = within(m.lim, &max);
        }
        self.set_goal(goal);
        self.running_job_replanned();
    }
}
