//! `[axes.<name>]` to the engine's axis configuration, one function per sub-table.

use super::{pick, FieldError};
use crate::error::Problem;
use crate::schema::{AxisSection, ExtrapolationSection, HomingSection};
use tandem_motion::catalog::alarm::Reaction;
use tandem_motion::kinematics::dynamics::{DynamicDefaults, DynamicLimits};
use tandem_motion::kinematics::extrapolation::{ExtrapolationConfig, VelocityMode};
use tandem_motion::kinematics::modulo::Modulo;
use tandem_motion::objects::axis::{
    AxisConfig, AxisKind, EncoderType, FollowingErrorMonitoring, HomingConfig, HomingMark,
    MotionType, PassiveDirection, PositioningMonitoring, Sense, SoftwareLimits, StandstillSignal,
    TorqueConfig,
};
use tandem_motion::plant::drive::{DriveModel, Plant, ZeroMark};

/// The encoder types by name.
pub(super) const ENCODER_TYPES: [(&str, EncoderType); 3] = [
    ("incremental", EncoderType::Incremental),
    ("absolute", EncoderType::Absolute),
    // S7 `Sensor[n].Type` 2: homed like an absolute encoder; the count of traversed ranges is
    // retained (the measuring system, `[axes.<name>.encoder]`).
    ("cyclic_absolute", EncoderType::Absolute),
];

/// The axis configuration of `a` on a node with cycle `cycle` (s); not yet validated.
pub(super) fn axis_config(a: &AxisSection, cycle: f64) -> Result<AxisConfig, FieldError> {
    let kind = pick(
        "kind",
        &a.kind,
        &[
            ("speed", AxisKind::Speed),
            ("positioning", AxisKind::Positioning),
            ("synchronous", AxisKind::Synchronous),
            // A synchronous axis whose positionings run the hydraulic library's generator.
            (super::hydraulic::HYDRAULIC_KIND, AxisKind::Synchronous),
        ],
    )?;
    let hydraulic = match (&a.hydraulic, a.kind == super::hydraulic::HYDRAULIC_KIND) {
        (Some(h), true) => Some(super::hydraulic::profile(h)?),
        (None, true) => Some(super::hydraulic::profile(&Default::default())?),
        (Some(_), false) => {
            return Err((
                "hydraulic",
                Problem::Invalid("only for `kind = \"hydraulic\"`"),
            ))
        }
        (None, false) => None,
    };
    let motion_type = pick(
        "motion_type",
        &a.motion_type,
        &[
            ("linear", MotionType::Linear),
            ("rotary", MotionType::Rotary),
        ],
    )?;
    let encoder = pick("encoder", a.encoder.type_name(), &ENCODER_TYPES)?;
    let homing = homing(&a.homing)?;
    let drive = drive(a)?;
    let leader_missing_reaction = leader_missing_reaction(a)?;
    let extrapolation = extrapolation(&a.extrapolation)?;
    let dy = &a.dynamics;
    let hw = a.hw_limits.as_ref();
    Ok(AxisConfig {
        leader_missing_reaction,
        kind,
        motion_type,
        modulo: a.modulo.as_ref().map(|m| Modulo {
            start: m.start,
            length: m.length,
        }),
        encoder,
        virtual_axis: a.virtual_axis,
        cycle,
        limits: DynamicLimits {
            max_velocity: dy.max_velocity,
            max_acceleration: dy.max_acceleration,
            max_deceleration: dy.max_deceleration,
            max_jerk: dy.max_jerk,
        },
        defaults: DynamicDefaults {
            velocity: dy.velocity,
            acceleration: dy.acceleration,
            deceleration: dy.deceleration,
            jerk: dy.jerk,
            emergency_deceleration: dy.emergency_deceleration,
        },
        sw_limits: a.sw_limits.as_ref().map(|s| SoftwareLimits {
            min: s.min,
            max: s.max,
        }),
        hw_limits_active: hw.map(|h| h.active).unwrap_or(false),
        positioning: PositioningMonitoring {
            window: a.positioning.window,
            tolerance_time: a.positioning.tolerance_time,
            min_dwell_time: a.positioning.min_dwell_time,
        },
        following_error: FollowingErrorMonitoring {
            enable: a.following_error.enable,
            min_value: a.following_error.min_value,
            max_value: a.following_error.max_value,
            min_velocity: a.following_error.min_velocity,
            warning_level: a.following_error.warning_level,
        },
        standstill: StandstillSignal {
            velocity_threshold: a.standstill.velocity_threshold,
            min_dwell_time: a.standstill.min_dwell_time,
        },
        homing,
        drive,
        plant: plant(a),
        initial_position: a.initial_position,
        extrapolation,
        hydraulic,
        torque: TorqueConfig {
            limit_default: a.torque_limiting.limit_default,
            keep_position_monitorings: a.torque_limiting.keep_position_monitorings,
            clamping_deviation: a.clamping.following_error_deviation,
            clamping_tolerance: a.clamping.position_tolerance,
            position_unit_m: a.torque_limiting.position_unit_m,
        },
    })
}

/// `[axes.<name>.homing]`.
fn homing(h: &HomingSection) -> Result<HomingConfig, FieldError> {
    let marks = [
        ("zero_mark", HomingMark::ZeroMark),
        ("cam_and_zero_mark", HomingMark::CamAndZeroMark),
        ("digital_input", HomingMark::DigitalInput),
    ];
    let senses = [("positive", Sense::Positive), ("negative", Sense::Negative)];
    Ok(HomingConfig {
        active_mark: pick("homing.active_mark", &h.active_mark, &marks)?,
        passive_mark: pick("homing.passive_mark", &h.passive_mark, &marks)?,
        approach_direction: pick("homing.approach_direction", &h.approach_direction, &senses)?,
        homing_direction: pick("homing.homing_direction", &h.homing_direction, &senses)?,
        passive_direction: pick(
            "homing.passive_direction",
            &h.passive_direction,
            &[
                ("positive", PassiveDirection::Positive),
                ("negative", PassiveDirection::Negative),
                ("current", PassiveDirection::Current),
            ],
        )?,
        approach_velocity: h.approach_velocity,
        referencing_velocity: h.referencing_velocity,
        home_position: h.home_position,
        home_position_offset: h.home_position_offset,
        auto_reversal: h.auto_reversal,
    })
}

/// `[axes.<name>.drive]`: the drive model.
fn drive(a: &AxisSection) -> Result<DriveModel, FieldError> {
    let d = &a.drive;
    Ok(match d.model.as_str() {
        "position_loop" => DriveModel::PositionLoop {
            kv: d.kv,
            kpc: d.kpc / 100.0,
            t_vtc: d.t_vtc,
        },
        "delay" => DriveModel::Delay { delay: d.delay },
        other => {
            return Err((
                "drive.model",
                Problem::NotOneOf {
                    value: other.into(),
                    options: vec!["position_loop", "delay"],
                },
            ));
        }
    })
}

/// `leader_missing_reaction`: the reaction to a missing leading value.
fn leader_missing_reaction(a: &AxisSection) -> Result<Option<Reaction>, FieldError> {
    a.leader_missing_reaction
        .as_ref()
        .map(|r| {
            pick(
                "leader_missing_reaction",
                r,
                &[
                    ("stop_current_dynamics", Reaction::StopCurrentDynamics),
                    ("stop_max_dynamics", Reaction::StopMaxDynamics),
                    ("emergency_stop", Reaction::EmergencyStop),
                    ("remove_enable", Reaction::RemoveEnable),
                ],
            )
        })
        .transpose()
}

/// `[axes.<name>.plant]` and the hardware limit switches: the simulated plant.
fn plant(a: &AxisSection) -> Plant {
    let hw = a.hw_limits.as_ref();
    Plant {
        reference_cam: a.plant.reference_cam.map(|[lo, hi]| (lo, hi)),
        zero_mark: a.plant.zero_mark_period.map(|period| ZeroMark {
            period,
            offset: a.plant.zero_mark_offset,
        }),
        hw_limit_min: hw.and_then(|h| h.min),
        hw_limit_max: hw.and_then(|h| h.max),
        fixed_stop_min: a.plant.fixed_stop_min,
        fixed_stop_max: a.plant.fixed_stop_max,
    }
}

/// `[<axes|encoders>.<name>.extrapolation]`: the actual-value extrapolation.
pub(super) fn extrapolation(x: &ExtrapolationSection) -> Result<ExtrapolationConfig, FieldError> {
    Ok(ExtrapolationConfig {
        position_t1: x.position_t1,
        position_t2: x.position_t2,
        velocity_t1: x.velocity_t1,
        velocity_t2: x.velocity_t2,
        velocity_tolerance: x.velocity_tolerance,
        hysteresis: x.hysteresis,
        following_time: x.following_time,
        acquisition_time: x.acquisition_time,
        system_defined: x.system_defined,
        velocity_mode: pick(
            "extrapolation.velocity_mode",
            &x.velocity_mode,
            &[
                ("filtered", VelocityMode::Filtered),
                ("differentiation", VelocityMode::Differentiation),
            ],
        )?,
    })
}
