//! Configuration of an axis technology object (the "technology DB" start values).

use crate::kinematics::dynamics::{DynamicDefaults, DynamicLimits};
use crate::kinematics::extrapolation::ExtrapolationConfig;
use crate::kinematics::modulo::Modulo;
use crate::plant::drive::{DriveModel, Plant};

/// Speed, positioning or synchronous axis (S7-1500T Motion Control V4.0 function manual,
/// 3.3 'Speed-controlled axis technology object', 3.5 'Synchronous axis technology object').
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum AxisKind {
    /// `TO_SpeedAxis`: velocity setpoints only, no position control, no homing.
    Speed,
    /// `TO_PositioningAxis`.
    Positioning,
    /// `TO_SynchronousAxis`: a positioning axis that can also follow a leading value.
    Synchronous,
}

/// `Properties.MotionType`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum MotionType {
    /// Linear axis.
    Linear,
    /// Rotary axis.
    Rotary,
}

/// Encoder type (`Sensor[1].Type`): decides which homing modes are allowed.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum EncoderType {
    /// Incremental: not homed after start; active and passive homing.
    Incremental,
    /// Absolute: homed once adjusted (modes 6, 7).
    Absolute,
}

/// A direction of travel.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Sense {
    /// Positive direction.
    Positive,
    /// Negative direction.
    Negative,
}

impl Sense {
    /// +1 or -1.
    pub fn sign(self) -> f64 {
        match self {
            Sense::Positive => 1.0,
            Sense::Negative => -1.0,
        }
    }
}

/// What an active or passive homing job looks for (`Sensor[n].ActiveHoming.Mode`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum HomingMark {
    /// Encoder zero mark only.
    ZeroMark,
    /// Reference cam, then the first zero mark after leaving the cam.
    CamAndZeroMark,
    /// Edge of a digital input (the reference cam signal) on the side given by the homing
    /// direction (positive side = the edge at the higher position).
    DigitalInput,
}

/// Passive homing direction (`PassiveHoming.Direction`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum PassiveDirection {
    /// Armed only while moving positive.
    Positive,
    /// Armed only while moving negative.
    Negative,
    /// Armed in the direction the axis moves in.
    Current,
}

/// `Homing.*` and `Sensor[1].ActiveHoming/PassiveHoming.*`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct HomingConfig {
    /// Mark for active homing.
    pub active_mark: HomingMark,
    /// Mark for passive homing.
    pub passive_mark: HomingMark,
    /// `Homing.ApproachDirection`: where to search for the cam.
    pub approach_direction: Sense,
    /// `Sensor[1].ActiveHoming.Direction`: the direction in which the mark is approached
    /// (for a digital input: the side of the edge).
    pub homing_direction: Sense,
    /// `PassiveHoming.Direction`.
    pub passive_direction: PassiveDirection,
    /// `Homing.ApproachVelocity` (> 0).
    pub approach_velocity: f64,
    /// `Homing.ReferencingVelocity` (> 0).
    pub referencing_velocity: f64,
    /// `Homing.HomePosition` (modes 5 and 10).
    pub home_position: f64,
    /// `Sensor[1].ActiveHoming.HomePositionOffset`: home position minus mark position.
    pub home_position_offset: f64,
    /// `Homing.AutoReversal`: reverse at a hardware limit switch while searching.
    pub auto_reversal: bool,
}

impl Default for HomingConfig {
    fn default() -> Self {
        Self {
            active_mark: HomingMark::CamAndZeroMark,
            passive_mark: HomingMark::CamAndZeroMark,
            approach_direction: Sense::Positive,
            homing_direction: Sense::Positive,
            passive_direction: PassiveDirection::Current,
            approach_velocity: 10.0,
            referencing_velocity: 2.0,
            home_position: 0.0,
            home_position_offset: 0.0,
            auto_reversal: true,
        }
    }
}

/// `PositioningMonitoring.*` (S7-1500T Motion Control V4.0 function manual, 3.2.10.2 'Positioning
/// monitoring').
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PositioningMonitoring {
    /// `Window` (>= 0).
    pub window: f64,
    /// `ToleranceTime` (s): time to enter the window after the setpoint reached the target.
    pub tolerance_time: f64,
    /// `MinDwellTime` (s): time the actual value must stay in the window.
    pub min_dwell_time: f64,
}

/// `FollowingError.*` (S7-1500T Motion Control V4.0 function manual, 3.2.10.3 'Following error
/// monitoring').
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct FollowingErrorMonitoring {
    /// `EnableMonitoring`.
    pub enable: bool,
    /// `MinValue`: permitted error below `min_velocity`.
    pub min_value: f64,
    /// `MaxValue`: permitted error at maximum velocity.
    pub max_value: f64,
    /// `MinVelocity`.
    pub min_velocity: f64,
    /// `WarningLevel` (% of the permitted value).
    pub warning_level: f64,
}

/// `StandstillSignal.*` (S7-1500T Motion Control V4.0 function manual, 3.2.10.4 'Standstill
/// signal').
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct StandstillSignal {
    /// `VelocityThreshold`.
    pub velocity_threshold: f64,
    /// `MinDwellTime` (s).
    pub min_dwell_time: f64,
}

/// `PositionLimits_SW.*` (active when present; S7-1500T Motion Control V4.0 function manual,
/// 3.2.7.3 'Software limit switch').
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SoftwareLimits {
    /// `MinPosition`.
    pub min: f64,
    /// `MaxPosition` (> min).
    pub max: f64,
}

/// Everything an axis is built from.
///
/// In this order (`repr(C)`): what an axis reads every cycle first, what it reads when a job
/// starts or at construction after.
#[derive(Clone, Debug, PartialEq)]
#[repr(C)]
pub struct AxisConfig {
    /// Servo cycle (s, > 0).
    pub cycle: f64,
    /// Speed or positioning axis.
    pub kind: AxisKind,
    /// Virtual axis / simulation mode (S7-1500T Motion Control V4.0 function manual, 3.2.5.7 'Axis
    /// in simulation'): homing completes at once without motion, hardware limit switches have no
    /// effect.
    pub virtual_axis: bool,
    /// `PositionLimits_HW.Active`: evaluate the plant's hardware limit switches.
    pub hw_limits_active: bool,
    /// Modulo settings (positioning axes).
    pub modulo: Option<Modulo>,
    /// Software limit switches (non-modulo axes), active when set.
    pub sw_limits: Option<SoftwareLimits>,
    /// `DynamicLimits`.
    pub limits: DynamicLimits,
    /// Standstill signal.
    pub standstill: StandstillSignal,
    /// Following-error monitoring.
    pub following_error: FollowingErrorMonitoring,
    /// Positioning monitoring.
    pub positioning: PositioningMonitoring,
    /// Linear or rotary.
    pub motion_type: MotionType,
    /// Encoder type.
    pub encoder: EncoderType,
    /// `DynamicDefaults`.
    pub defaults: DynamicDefaults,
    /// Homing.
    pub homing: HomingConfig,
    /// Simulated drive model.
    pub drive: DriveModel,
    /// Simulated plant (sensors in physical coordinates).
    pub plant: Plant,
    /// Physical position of the load at start.
    pub initial_position: f64,
    /// `Extrapolation.*`: how this axis' actual value is prepared when a follower couples to it
    /// by actual value.
    pub extrapolation: ExtrapolationConfig,
    /// The reaction to alarm 601 when a leading value is missing (a leader on another node that
    /// stopped publishing): stop with the current or the maximum dynamics (default, the table
    /// value), emergency stop, or remove the enable. `None`: the table value.
    pub leader_missing_reaction: Option<crate::catalog::alarm::Reaction>,
    /// A hydraulic axis (`kind = "hydraulic"` in a cell file): its positionings run the
    /// displacement-based generator of the Beckhoff TwinCAT PLC Hydraulic Positioning library
    /// instead of the jerk-limited profile. `None`: an electric axis.
    pub hydraulic: Option<HydraulicProfile>,
    /// `TorqueLimiting.*` and `Clamping.*`: MC_TorqueLimiting's default limit, fixed stop
    /// detection and the monitorings under torque limits.
    pub torque: TorqueConfig,
}

/// `TorqueLimiting.*` and `Clamping.*` (S7-1500T Motion Control V4.0, 'Force/torque limiting'
/// and 'Fixed stop detection').
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TorqueConfig {
    /// `TorqueLimiting.LimitDefaults.Torque` / `.Force` (N·m, or N on a linear axis, >= 0):
    /// the limit of MC_TorqueLimiting with `Limit` < 0. `None`: such a job is refused
    /// (16#8043).
    #[doc(alias = "LimitDefaults")]
    pub limit_default: Option<f64>,
    /// `TorqueLimiting.PositionBasedMonitorings` = 1: the following error and positioning
    /// monitorings stay active under MC_TorqueLimiting and MC_TorqueRange (default false: off
    /// while limiting).
    #[doc(alias = "PositionBasedMonitorings")]
    pub keep_position_monitorings: bool,
    /// `Clamping.FollowingErrorDeviation` (position units, > 0): mode 1 detects the fixed stop
    /// when the following error exceeds it.
    #[doc(alias = "FollowingErrorDeviation")]
    pub clamping_deviation: f64,
    /// `Clamping.PositionTolerance` (position units, 0.001..deviation): while clamped, the
    /// axis leaving this window around the clamping position raises alarm 542.
    #[doc(alias = "PositionTolerance")]
    pub clamping_tolerance: f64,
    /// Metres per position unit of a linear axis (0.001: mm), so that its force is in N.
    pub position_unit_m: f64,
}

impl Default for TorqueConfig {
    fn default() -> Self {
        Self {
            limit_default: None,
            keep_position_monitorings: false,
            clamping_deviation: 1.0,
            clamping_tolerance: 0.1,
            position_unit_m: 0.001,
        }
    }
}

/// The displacement-based positioning of a hydraulic axis: the generator's parameters and the
/// target window (members of `ST_TcHydAxParam`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct HydraulicProfile {
    /// The generator `iTcMc_ProfileCtrlBased`.
    pub generator: crate::hydraulic::generator::GeneratorParams,
    /// `fMonPositionRange`, `fMonTargetRange`, `fMonTargetFilter`.
    pub monitor: crate::hydraulic::monitor::MonitorParams,
    /// The position controller and Finish (`fLagAmp`, `fLagAmpDx`, `fZeroCompensation` …):
    /// the basis of `MC_AxCtrlAutoZero_BkPlcMc` (the drive connection runs the controller).
    pub controller: crate::hydraulic::controller::HydControllerParams,
    /// `fJogVeloSlow` and `fJogVeloFast` (mm/s, > 0): MC_MoveJog_BkPlcMc's standard modes.
    #[doc(alias = "fJogVeloSlow")]
    #[doc(alias = "fJogVeloFast")]
    pub jog_velo: [f64; 2],
    /// `nProfileType` (the displacement-based or the jerk-based generator), `fMaxJerk`,
    /// `nJerkEnabled` and `bTimeBased`.
    pub profile: crate::hydraulic::jerk_generator::ProfileSelection,
    /// The homing members (`nEnc_HomingType`, `fEnc_RefIndexVelo` …) and `fBlockDetectDelay`:
    /// MC_Home_BkPlcMc.
    pub homing: super::hyd_home::HydHomingParams,
}

/// `fJogVeloSlow` and `fJogVeloFast` by default (mm/s), as the library's `ST_TcHydAxParam`.
pub const JOG_VELO_DEFAULTS: [f64; 2] = [25.0, 100.0];

/// What is wrong with a value of an [`AxisConfig`] (see [`AxisConfigError`]).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum AxisConfigProblem {
    /// Not a positive number.
    NotPositive,
    /// Negative or not a number.
    Negative,
    /// Not a finite number.
    NotFinite,
    /// A reaction that does not stop the follower when its leading value is missing.
    LeaderMissingMustStop,
    /// The default exceeds `max_velocity`.
    ExceedsMaxVelocity,
    /// The default exceeds `max_acceleration`.
    ExceedsMaxAcceleration,
    /// The default exceeds `max_deceleration`.
    ExceedsMaxDeceleration,
    /// The default exceeds `max_jerk`.
    ExceedsMaxJerk,
    /// A modulo setting on a speed axis.
    SpeedAxisModulo,
    /// The upper software limit is not above the lower one (alarm 104).
    SoftwareLimitsReversed,
    /// Software limit switches on a modulo axis (not supported yet).
    SoftwareLimitsOnModulo,
    /// The maximum following error is below the minimum.
    FollowingErrorMaxBelowMin,
    /// A warning level outside 0..=100 %.
    WarningLevelOutOfRange,
    /// A velocity precontrol outside 0..=150 %.
    KpcOutOfRange,
    /// A reference cam whose high end is not above its low end.
    ReferenceCamReversed,
    /// The upper hardware limit switch is not above the lower one.
    HardwareLimitsReversed,
    /// A parameter of a hydraulic axis out of its range (the field is the library's name).
    HydraulicParameter,
    /// `Clamping.PositionTolerance` not below `Clamping.FollowingErrorDeviation`, or the
    /// deviation not below the maximum following error.
    ClampingWindows,
}

impl AxisConfigProblem {
    /// The problem in words, as the configuration's error messages show it.
    pub const fn text(self) -> &'static str {
        match self {
            Self::NotPositive => "must be a positive number",
            Self::Negative => "must be zero or a positive number",
            Self::NotFinite => "must be a finite number",
            Self::LeaderMissingMustStop => "a follower without its leading value must stop: stop_current_dynamics, stop_max_dynamics, emergency_stop or remove_enable",
            Self::ExceedsMaxVelocity => "exceeds max_velocity",
            Self::ExceedsMaxAcceleration => "exceeds max_acceleration",
            Self::ExceedsMaxDeceleration => "exceeds max_deceleration",
            Self::ExceedsMaxJerk => "exceeds max_jerk",
            Self::SpeedAxisModulo => "a speed axis has no modulo",
            Self::SoftwareLimitsReversed => "must be greater than sw_limits.min (alarm 104)",
            Self::SoftwareLimitsOnModulo => "software limit switches on a modulo axis are not supported yet",
            Self::FollowingErrorMaxBelowMin => "must not be less than following_error.min_value",
            Self::WarningLevelOutOfRange => "must be between 0 and 100 (%)",
            Self::KpcOutOfRange => "must be between 0 and 150 %",
            Self::ReferenceCamReversed => "must be [low, high] with high > low",
            Self::HardwareLimitsReversed => "must be greater than plant.hw_limit_min",
            Self::HydraulicParameter => "is out of its range (Beckhoff hydraulic positioning library, ST_TcHydAxParam)",
            Self::ClampingWindows => "must satisfy 0.001 <= clamping.position_tolerance < clamping.following_error_deviation (and that < following_error.max_value with torque_limiting.keep_position_monitorings)",
        }
    }
}

impl core::fmt::Display for AxisConfigProblem {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.text())
    }
}

/// A configuration value that is not acceptable: which field, and why.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct AxisConfigError {
    /// The key, as in the cell file (e.g. `dynamics.max_velocity`).
    pub field: &'static str,
    /// What is wrong with it.
    pub problem: AxisConfigProblem,
}

impl core::fmt::Display for AxisConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}: {}", self.field, self.problem)
    }
}

impl std::error::Error for AxisConfigError {}

fn positive(field: &'static str, x: f64) -> Result<(), AxisConfigError> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(AxisConfigError {
            field,
            problem: AxisConfigProblem::NotPositive,
        })
    }
}

fn non_negative(field: &'static str, x: f64) -> Result<(), AxisConfigError> {
    if x.is_finite() && x >= 0.0 {
        Ok(())
    } else {
        Err(AxisConfigError {
            field,
            problem: AxisConfigProblem::Negative,
        })
    }
}

fn finite(field: &'static str, x: f64) -> Result<(), AxisConfigError> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(AxisConfigError {
            field,
            problem: AxisConfigProblem::NotFinite,
        })
    }
}

impl AxisConfig {
    /// A positioning axis with plausible defaults (mm, mm/s ...), for tests and examples.
    pub fn example(cycle: f64) -> Self {
        Self {
            kind: AxisKind::Positioning,
            motion_type: MotionType::Linear,
            modulo: None,
            encoder: EncoderType::Incremental,
            virtual_axis: false,
            cycle,
            limits: DynamicLimits {
                max_velocity: 500.0,
                max_acceleration: 5000.0,
                max_deceleration: 5000.0,
                max_jerk: 100_000.0,
            },
            defaults: DynamicDefaults {
                velocity: 100.0,
                acceleration: 1000.0,
                deceleration: 1000.0,
                jerk: 20_000.0,
                emergency_deceleration: 10_000.0,
            },
            sw_limits: None,
            hw_limits_active: false,
            positioning: PositioningMonitoring {
                window: 0.01,
                tolerance_time: 1.0,
                min_dwell_time: 0.0,
            },
            following_error: FollowingErrorMonitoring {
                enable: true,
                min_value: 1.0,
                max_value: 10.0,
                min_velocity: 10.0,
                warning_level: 90.0,
            },
            standstill: StandstillSignal {
                velocity_threshold: 0.1,
                min_dwell_time: 0.01,
            },
            homing: HomingConfig::default(),
            drive: DriveModel::PositionLoop {
                kv: 100.0,
                kpc: 1.0,
                t_vtc: 0.002,
            },
            plant: Plant::default(),
            initial_position: 0.0,
            extrapolation: ExtrapolationConfig::default(),
            leader_missing_reaction: None,
            hydraulic: None,
            torque: TorqueConfig::default(),
        }
    }

    /// Checks every value; the first problem found is returned with the key that has it.
    pub fn validate(&self) -> Result<(), AxisConfigError> {
        positive("cycle", self.cycle)?;
        if matches!(
            self.leader_missing_reaction,
            Some(
                crate::catalog::alarm::Reaction::None
                    | crate::catalog::alarm::Reaction::TrackSetpoints
            )
        ) {
            return Err(AxisConfigError {
                field: "leader_missing_reaction",
                problem: AxisConfigProblem::LeaderMissingMustStop,
            });
        }
        self.validate_dynamics()?;
        self.validate_ranges()?;
        self.validate_monitoring()?;
        self.validate_homing_and_drive()?;
        self.validate_plant()?;
        self.validate_extrapolation()?;
        self.validate_hydraulic()?;
        self.validate_torque()?;
        Ok(())
    }

    /// `TorqueLimiting.*` and `Clamping.*`: the tolerance below the deviation, the deviation
    /// below the maximum following error when that monitoring stays on under limiting
    /// (S7-1500T Motion Control V4.0, 'Fixed stop detection': "When following error
    /// monitoring is activated, the configured following error must be greater").
    fn validate_torque(&self) -> Result<(), AxisConfigError> {
        let t = &self.torque;
        if let Some(l) = t.limit_default {
            non_negative("torque_limiting.limit_default", l)?;
            finite("torque_limiting.limit_default", l)?;
        }
        positive("torque_limiting.position_unit_m", t.position_unit_m)?;
        positive("clamping.following_error_deviation", t.clamping_deviation)?;
        positive("clamping.position_tolerance", t.clamping_tolerance)?;
        let fe = &self.following_error;
        let windows = t.clamping_tolerance >= 0.001
            && t.clamping_tolerance < t.clamping_deviation
            && (!(fe.enable && t.keep_position_monitorings) || t.clamping_deviation < fe.max_value);
        if !windows {
            return Err(AxisConfigError {
                field: "clamping.position_tolerance",
                problem: AxisConfigProblem::ClampingWindows,
            });
        }
        Ok(())
    }

    /// The generator's and the target window's parameters of a hydraulic axis.
    fn validate_hydraulic(&self) -> Result<(), AxisConfigError> {
        let Some(h) = &self.hydraulic else {
            return Ok(());
        };
        let refused = |field| AxisConfigError {
            field,
            problem: AxisConfigProblem::HydraulicParameter,
        };
        crate::hydraulic::generator::CtrlBasedGenerator::new(h.generator, 0.0).map_err(|e| {
            refused(match e {
                crate::hydraulic::generator::GeneratorError::Invalid { name, .. } => name,
                crate::hydraulic::generator::GeneratorError::FeedEnable { .. } => "hydraulic",
            })
        })?;
        crate::hydraulic::monitor::TargetMonitor::new(h.monitor).map_err(|e| refused(e.name))?;
        h.homing.check().map_err(|e| refused(e.name))?;
        Ok(())
    }

    /// The dynamic limits and defaults: positive, the defaults within the limits.
    fn validate_dynamics(&self) -> Result<(), AxisConfigError> {
        positive("dynamics.max_velocity", self.limits.max_velocity)?;
        positive("dynamics.max_acceleration", self.limits.max_acceleration)?;
        positive("dynamics.max_deceleration", self.limits.max_deceleration)?;
        positive("dynamics.max_jerk", self.limits.max_jerk)?;
        positive("dynamics.velocity", self.defaults.velocity)?;
        positive("dynamics.acceleration", self.defaults.acceleration)?;
        positive("dynamics.deceleration", self.defaults.deceleration)?;
        non_negative("dynamics.jerk", self.defaults.jerk)?;
        positive(
            "dynamics.emergency_deceleration",
            self.defaults.emergency_deceleration,
        )?;
        if self.defaults.velocity > self.limits.max_velocity {
            return Err(AxisConfigError {
                field: "dynamics.velocity",
                problem: AxisConfigProblem::ExceedsMaxVelocity,
            });
        }
        if self.defaults.acceleration > self.limits.max_acceleration {
            return Err(AxisConfigError {
                field: "dynamics.acceleration",
                problem: AxisConfigProblem::ExceedsMaxAcceleration,
            });
        }
        if self.defaults.deceleration > self.limits.max_deceleration {
            return Err(AxisConfigError {
                field: "dynamics.deceleration",
                problem: AxisConfigProblem::ExceedsMaxDeceleration,
            });
        }
        if self.defaults.jerk > self.limits.max_jerk {
            return Err(AxisConfigError {
                field: "dynamics.jerk",
                problem: AxisConfigProblem::ExceedsMaxJerk,
            });
        }
        Ok(())
    }

    /// The modulo range and the software limit switches.
    fn validate_ranges(&self) -> Result<(), AxisConfigError> {
        if let Some(m) = self.modulo {
            finite("modulo.start", m.start)?;
            positive("modulo.length", m.length)?;
            if self.kind == AxisKind::Speed {
                return Err(AxisConfigError {
                    field: "modulo",
                    problem: AxisConfigProblem::SpeedAxisModulo,
                });
            }
        }
        if let Some(sw) = self.sw_limits {
            finite("sw_limits.min", sw.min)?;
            finite("sw_limits.max", sw.max)?;
            if sw.max <= sw.min {
                return Err(AxisConfigError {
                    field: "sw_limits.max",
                    problem: AxisConfigProblem::SoftwareLimitsReversed,
                });
            }
            if self.modulo.is_some() {
                return Err(AxisConfigError {
                    field: "sw_limits",
                    problem: AxisConfigProblem::SoftwareLimitsOnModulo,
                });
            }
        }
        Ok(())
    }

    /// Positioning, following error and standstill monitoring.
    fn validate_monitoring(&self) -> Result<(), AxisConfigError> {
        non_negative("positioning.window", self.positioning.window)?;
        non_negative(
            "positioning.tolerance_time",
            self.positioning.tolerance_time,
        )?;
        non_negative(
            "positioning.min_dwell_time",
            self.positioning.min_dwell_time,
        )?;
        let fe = &self.following_error;
        if fe.enable {
            positive("following_error.min_value", fe.min_value)?;
            positive("following_error.max_value", fe.max_value)?;
            non_negative("following_error.min_velocity", fe.min_velocity)?;
            if fe.max_value < fe.min_value {
                return Err(AxisConfigError {
                    field: "following_error.max_value",
                    problem: AxisConfigProblem::FollowingErrorMaxBelowMin,
                });
            }
            if !(0.0..=100.0).contains(&fe.warning_level) {
                return Err(AxisConfigError {
                    field: "following_error.warning_level",
                    problem: AxisConfigProblem::WarningLevelOutOfRange,
                });
            }
        }
        non_negative(
            "standstill.velocity_threshold",
            self.standstill.velocity_threshold,
        )?;
        non_negative("standstill.min_dwell_time", self.standstill.min_dwell_time)?;
        Ok(())
    }

    /// The homing velocities and positions, the drive model.
    fn validate_homing_and_drive(&self) -> Result<(), AxisConfigError> {
        positive("homing.approach_velocity", self.homing.approach_velocity)?;
        positive(
            "homing.referencing_velocity",
            self.homing.referencing_velocity,
        )?;
        finite("homing.home_position", self.homing.home_position)?;
        finite(
            "homing.home_position_offset",
            self.homing.home_position_offset,
        )?;
        match self.drive {
            DriveModel::Delay { delay } => non_negative("drive.delay", delay)?,
            DriveModel::PositionLoop { kv, kpc, t_vtc } => {
                positive("drive.kv", kv)?;
                if !(0.0..=1.5).contains(&kpc) {
                    return Err(AxisConfigError {
                        field: "drive.kpc",
                        problem: AxisConfigProblem::KpcOutOfRange,
                    });
                }
                non_negative("drive.t_vtc", t_vtc)?;
            }
        }
        Ok(())
    }

    /// The simulated plant (reference cam, zero marks, hardware limits) and the initial position.
    fn validate_plant(&self) -> Result<(), AxisConfigError> {
        if let Some((lo, hi)) = self.plant.reference_cam {
            if !(lo.is_finite() && hi.is_finite() && hi > lo) {
                return Err(AxisConfigError {
                    field: "plant.reference_cam",
                    problem: AxisConfigProblem::ReferenceCamReversed,
                });
            }
        }
        if let Some(z) = self.plant.zero_mark {
            positive("plant.zero_mark_period", z.period)?;
            finite("plant.zero_mark_offset", z.offset)?;
        }
        if let (Some(lo), Some(hi)) = (self.plant.hw_limit_min, self.plant.hw_limit_max) {
            if hi <= lo {
                return Err(AxisConfigError {
                    field: "plant.hw_limit_max",
                    problem: AxisConfigProblem::HardwareLimitsReversed,
                });
            }
        }
        finite("initial_position", self.initial_position)?;
        Ok(())
    }

    /// The filters and times of actual-value extrapolation.
    fn validate_extrapolation(&self) -> Result<(), AxisConfigError> {
        let ex = &self.extrapolation;
        non_negative("extrapolation.position_t1", ex.position_t1)?;
        non_negative("extrapolation.position_t2", ex.position_t2)?;
        non_negative("extrapolation.velocity_t1", ex.velocity_t1)?;
        non_negative("extrapolation.velocity_t2", ex.velocity_t2)?;
        non_negative("extrapolation.velocity_tolerance", ex.velocity_tolerance)?;
        non_negative("extrapolation.hysteresis", ex.hysteresis)?;
        non_negative("extrapolation.following_time", ex.following_time)?;
        non_negative("extrapolation.acquisition_time", ex.acquisition_time)?;
        Ok(())
    }
}
