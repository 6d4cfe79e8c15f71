//! Hydraulic axes: `[axes.<name>.hydraulic]` (the members of the Beckhoff TwinCAT PLC Hydraulic
//! Positioning library's `ST_TcHydAxParam`, under its names, with its defaults) and the
//! `sim_valve_cylinder` device (`[devices.<name>.cylinder]`).

use super::FieldError;
use crate::error::Problem;
use crate::schema::{CylinderSection, DeviceSection, HydraulicSection, ProfileTypeValue};
use tandem_motion::hydraulic::controller::{HydController, HydControllerParams};
use tandem_motion::hydraulic::controller_ex::PosPiControllerExParams;
use tandem_motion::hydraulic::drive_output::{DriveOutputParams, ValveOutput};
use tandem_motion::hydraulic::finish::{FinishError, FinishParams};
use tandem_motion::hydraulic::generator::{
    Approach, CtrlBasedGenerator, GeneratorError, GeneratorParams,
};
use tandem_motion::hydraulic::jerk_generator::{
    JerkParams, ProfileSelection, ProfileType, JERK_ENABLED_BITS,
};
use tandem_motion::hydraulic::monitor::{MonitorParams, TargetMonitor};
use tandem_motion::hydraulic::pressure::ForceScaling;
use tandem_motion::hydraulic::valve_table::{ValveTable, MAX_POINTS};
use tandem_motion::objects::axis::{
    HydHomingParams, HydHomingType, HydraulicProfile, JOG_VELO_DEFAULTS,
};
use tandem_motion::plant::hydraulic::{CylinderParams, SimValveCylinderParams};

/// The axis kind of a hydraulic axis in the cell file.
pub(super) const HYDRAULIC_KIND: &str = "hydraulic";

/// `fMonPositionRange`, `fMonTargetRange`, `fMonTargetFilter` by default (mm, mm, s).
const MONITOR_DEFAULTS: MonitorParams = MonitorParams {
    position_range: 1.0,
    target_range: 1.0,
    target_filter: 1.0,
};

/// The forms of `valve_output` (the axis; `bDrive_AbsoluteOutput` apart).
const VALVE_OUTPUTS: [(&str, ValveOutput); 3] = [
    ("voltage", ValveOutput::Voltage),
    ("two_coil", ValveOutput::TwoCoil),
    ("one_coil", ValveOutput::OneCoil),
];

/// The forms of `valve_input` (a `sim_valve_cylinder`'s amplifier; `current` is the voltage
/// form as a magnitude with direction valves).
const VALVE_INPUTS: [(&str, (ValveOutput, bool)); 4] = [
    ("voltage", (ValveOutput::Voltage, false)),
    ("two_coil", (ValveOutput::TwoCoil, false)),
    ("one_coil", (ValveOutput::OneCoil, false)),
    ("current", (ValveOutput::Voltage, true)),
];

/// The keys of `[axes.<name>.hydraulic]` the generator, the target window and the position
/// controller with Finish check, as paths from the axis.
const PROFILE_KEYS: [&str; 46] = [
    "hydraulic.fRefVelo",
    "hydraulic.fMaxVelo",
    "hydraulic.fAcc",
    "hydraulic.fMaxAcc",
    "hydraulic.fDec",
    "hydraulic.fMaxDec",
    "hydraulic.fStopRamp",
    "hydraulic.fEmergencyRamp",
    "hydraulic.fCreepSpeedP",
    "hydraulic.fCreepSpeedM",
    "hydraulic.fCreepDistanceP",
    "hydraulic.fCreepDistanceM",
    "hydraulic.fBrakeDistanceP",
    "hydraulic.fBrakeDistanceM",
    "hydraulic.fBrakeDeadTimeP",
    "hydraulic.fBrakeDeadTimeM",
    "hydraulic.fReposDistance",
    "hydraulic.fTargetClamping",
    "hydraulic.fMonPositionRange",
    "hydraulic.fMonTargetRange",
    "hydraulic.fMonTargetFilter",
    "hydraulic.fLagAmp",
    "hydraulic.fLagAmpOutL",
    "hydraulic.fLagAmpTi",
    "hydraulic.fLagAmpDx",
    "hydraulic.fLagAmpWuL",
    "hydraulic.position_controller",
    "hydraulic.fLagAmpTd",
    "hydraulic.fLagAmpTdd",
    "hydraulic.fLagAmpCfb_kV",
    "hydraulic.fLagAmpCfb_tV",
    "hydraulic.fLagAmpCfb_kA",
    "hydraulic.fLagAmpCfb_tA",
    "hydraulic.fFeedForward",
    "hydraulic.fAreaRatio",
    "hydraulic.fValve_OverlapCompP",
    "hydraulic.fValve_OverlapCompM",
    "hydraulic.fValve_BendPointVelo",
    "hydraulic.fValve_BendPointOutput",
    "hydraulic.fZeroCompensation",
    "hydraulic.Valve_LinLimitP",
    "hydraulic.Valve_LinLimitM",
    "hydraulic.valve_output",
    "hydraulic.bDrive_AbsoluteOutput",
    "hydraulic.fJogVeloSlow",
    "hydraulic.fJogVeloFast",
];

/// The path from the axis of the library's parameter `name`.
fn profile_key(name: &str) -> &'static str {
    PROFILE_KEYS
        .iter()
        .find(|k| k.strip_prefix("hydraulic.") == Some(name))
        .copied()
        .unwrap_or("hydraulic")
}

/// The generator and the target window of section `h`, checked: the path of the parameter out
/// of range.
pub(super) fn profile(h: &HydraulicSection) -> Result<HydraulicProfile, FieldError> {
    let controller = controller(h).map_err(|(name, problem)| (profile_key(name), problem))?;
    let mut p = unchecked_profile(h, controller);
    p.profile = profile_selection(h)?;
    CtrlBasedGenerator::new(p.generator, 0.0).map_err(|e| {
        let name = match e {
            GeneratorError::Invalid { name, .. } => name,
            GeneratorError::FeedEnable { .. } => "hydraulic",
        };
        (
            profile_key(name),
            Problem::Invalid("out of its range (ST_TcHydAxParam)"),
        )
    })?;
    TargetMonitor::new(p.monitor).map_err(|e| {
        (
            profile_key(e.name),
            Problem::Invalid("out of its range (ST_TcHydAxParam)"),
        )
    })?;
    let p = HydraulicProfile {
        homing: homing(h)?,
        ..p
    };
    for (name, v) in ["fJogVeloSlow", "fJogVeloFast"].into_iter().zip(p.jog_velo) {
        if !(v.is_finite() && v > 0.0) {
            return Err((
                profile_key(name),
                Problem::Invalid("out of its range (ST_TcHydAxParam)"),
            ));
        }
    }
    Ok(p)
}

/// The generator and the target window of section `h`, with the checked `controller`.
fn unchecked_profile(h: &HydraulicSection, controller: HydControllerParams) -> HydraulicProfile {
    let d = GeneratorParams::default();
    let approach = |given: [Option<f64>; 4], of: &Approach| Approach {
        creep_speed: given[0].unwrap_or(of.creep_speed),
        creep_distance: given[1].unwrap_or(of.creep_distance),
        brake_distance: given[2].unwrap_or(of.brake_distance),
        brake_dead_time: given[3].unwrap_or(of.brake_dead_time),
    };
    let approach_p = approach(
        [
            h.fCreepSpeedP,
            h.fCreepDistanceP,
            h.fBrakeDistanceP,
            h.fBrakeDeadTimeP,
        ],
        &d.approach_p,
    );
    let approach_m = approach(
        [
            h.fCreepSpeedM,
            h.fCreepDistanceM,
            h.fBrakeDistanceM,
            h.fBrakeDeadTimeM,
        ],
        &d.approach_m,
    );
    let ref_velo = h.fRefVelo.unwrap_or(d.ref_velo);
    HydraulicProfile {
        generator: GeneratorParams {
            ref_velo,
            max_velo: h.fMaxVelo.unwrap_or(ref_velo),
            acc: h.fAcc.unwrap_or(d.acc),
            max_acc: h.fMaxAcc.unwrap_or(d.max_acc),
            dec: h.fDec.unwrap_or(d.dec),
            max_dec: h.fMaxDec.unwrap_or(d.max_dec),
            approach_p,
            approach_m,
            asymmetrical: h.bAsymmetricalTargeting.unwrap_or(d.asymmetrical),
            stop_ramp: h.fStopRamp.unwrap_or(d.stop_ramp),
            emergency_ramp: h.fEmergencyRamp.unwrap_or(d.emergency_ramp),
            target_clamping: h.fTargetClamping.unwrap_or(d.target_clamping),
            repos_distance: h.fReposDistance.unwrap_or(d.repos_distance),
        },
        monitor: MonitorParams {
            position_range: h
                .fMonPositionRange
                .unwrap_or(MONITOR_DEFAULTS.position_range),
            target_range: h.fMonTargetRange.unwrap_or(MONITOR_DEFAULTS.target_range),
            target_filter: h.fMonTargetFilter.unwrap_or(MONITOR_DEFAULTS.target_filter),
        },
        controller,
        jog_velo: [
            h.fJogVeloSlow.unwrap_or(JOG_VELO_DEFAULTS[0]),
            h.fJogVeloFast.unwrap_or(JOG_VELO_DEFAULTS[1]),
        ],
        profile: ProfileSelection::default(),
        homing: HydHomingParams::default(),
    }
}

/// `nProfileType`, `fMaxJerk`, `nJerkEnabled` and `bTimeBased` of section `h`, checked: the
/// key out of range. The generators a cell can select are the displacement-based and the
/// jerk-based one; the library's other types (`iTcMc_ProfileTimeRamp` 4, the obsolete 1 and 2,
/// the reserved 6, 7, 100) are refused.
fn profile_selection(h: &HydraulicSection) -> Result<ProfileSelection, FieldError> {
    let names = || {
        vec![
            "iTcMc_ProfileConstAcc (0)",
            "iTcMc_ProfileCtrlBased (3)",
            "iTcMc_ProfileJerkBased (5)",
        ]
    };
    let profile_type = match &h.nProfileType {
        None => ProfileType::default(),
        Some(ProfileTypeValue::Name(n)) => ProfileType::from_name(n).ok_or_else(|| {
            (
                "hydraulic.nProfileType",
                Problem::NotOneOf {
                    value: n.clone(),
                    options: names(),
                },
            )
        })?,
        Some(ProfileTypeValue::Number(k)) => ProfileType::from_number(*k).ok_or_else(|| {
            (
                "hydraulic.nProfileType",
                Problem::NotOneOf {
                    value: k.to_string(),
                    options: names(),
                },
            )
        })?,
    };
    let d = JerkParams::default();
    let max_jerk = h.fMaxJerk.unwrap_or(d.max_jerk);
    if !(max_jerk.is_finite() && max_jerk > 0.0) {
        return Err((
            "hydraulic.fMaxJerk",
            Problem::Invalid("must be a finite number above 0 (mm/s³; ST_TcHydAxParam)"),
        ));
    }
    let bits = h.nJerkEnabled.unwrap_or(i64::from(d.jerk_enabled));
    let jerk_enabled = u16::try_from(bits)
        .ok()
        .filter(|b| b & !JERK_ENABLED_BITS == 0)
        .ok_or((
            "hydraulic.nJerkEnabled",
            Problem::Invalid(
                "must be a combination of 0x0001 (acceleration built up with limited jerk), \
                 0x0002 (reduced with limited jerk) and 0x0100 (the end into the target)",
            ),
        ))?;
    Ok(ProfileSelection {
        profile_type,
        jerk: JerkParams {
            max_jerk,
            jerk_enabled,
        },
        time_based: h.bTimeBased.unwrap_or(false),
    })
}

/// The values of `nEnc_HomingType` (`E_TcMcHomingType`, the library's names).
const HOMING_TYPES: [(&str, HydHomingType); 5] = [
    ("iTcMc_HomingOnBlock", HydHomingType::OnBlock),
    ("iTcMc_HomingOnIndex", HydHomingType::OnIndex),
    ("iTcMc_HomingOnSync", HydHomingType::OnSync),
    ("iTcMc_HomingOnMultiSync", HydHomingType::OnMultiSync),
    ("iTcMc_HomingOnExec", HydHomingType::OnExec),
];

/// The paths of MC_Home_BkPlcMc's keys, by the library's name.
const HOMING_KEYS: [&str; 7] = [
    "hydraulic.nEnc_HomingType",
    "hydraulic.fEnc_RefIndexVelo",
    "hydraulic.fEnc_RefSyncVelo",
    "hydraulic.bEnc_RefIndexPositive",
    "hydraulic.bEnc_RefSyncPositive",
    "hydraulic.fEnc_DefaultHomePosition",
    "hydraulic.fBlockDetectDelay",
];

/// MC_Home_BkPlcMc's parameters of section `h` over the library's defaults, checked: the path
/// of the key out of range.
fn homing(h: &HydraulicSection) -> Result<HydHomingParams, FieldError> {
    let d = HydHomingParams::default();
    let key = |name: &str| {
        HOMING_KEYS
            .iter()
            .find(|k| k.strip_prefix("hydraulic.") == Some(name))
            .copied()
            .unwrap_or("hydraulic")
    };
    let homing_type = match &h.nEnc_HomingType {
        Some(v) => super::pick("nEnc_HomingType", v, &HOMING_TYPES)
            .map_err(|(_, p)| (key("nEnc_HomingType"), p))?,
        None => d.homing_type,
    };
    let p = HydHomingParams {
        homing_type,
        ref_index_velo: h.fEnc_RefIndexVelo.unwrap_or(d.ref_index_velo),
        ref_sync_velo: h.fEnc_RefSyncVelo.unwrap_or(d.ref_sync_velo),
        ref_index_positive: h.bEnc_RefIndexPositive.unwrap_or(d.ref_index_positive),
        ref_sync_positive: h.bEnc_RefSyncPositive.unwrap_or(d.ref_sync_positive),
        default_home_position: h
            .fEnc_DefaultHomePosition
            .unwrap_or(d.default_home_position),
        block_detect_delay: h.fBlockDetectDelay.unwrap_or(d.block_detect_delay),
    };
    p.check().map_err(|e| {
        let why = match e.name {
            "fBlockDetectDelay" => "must be a finite number >= 0 (s)",
            "fEnc_DefaultHomePosition" => "must be a finite number (mm)",
            _ => "must be a fraction of fRefVelo from 0 to 1 (ST_TcHydAxParam)",
        };
        (key(e.name), Problem::Invalid(why))
    })?;
    Ok(p)
}

/// The position controller and Finish of section `h`, checked: the key of the parameter out
/// of range and its problem.
pub(super) fn controller(h: &HydraulicSection) -> Result<HydControllerParams, FieldError> {
    let d = FinishParams::default();
    let g = GeneratorParams::default();
    let asymmetrical = h.bAsymmetricalTargeting.unwrap_or(d.asymmetrical);
    let creep_p = h.fCreepSpeedP.unwrap_or(g.approach_p.creep_speed);
    let output = match &h.valve_output {
        Some(v) => super::pick("valve_output", v, &VALVE_OUTPUTS)?,
        None => ValveOutput::Voltage,
    };
    let params = HydControllerParams {
        drive: DriveOutputParams {
            output,
            absolute: h.bDrive_AbsoluteOutput.unwrap_or(false),
            reversed: h.bDrive_Reversed.unwrap_or(false),
        },
        lag_amp: h.fLagAmp.unwrap_or(HydControllerParams::default().lag_amp),
        lag_out_limit: h.fLagAmpOutL.unwrap_or(0.0),
        lag_amp_ti: h.fLagAmpTi.unwrap_or(0.0),
        lag_amp_dx: h.fLagAmpDx.unwrap_or(0.0),
        lag_amp_wul: h.fLagAmpWuL.unwrap_or(0.0),
        extended: extended_controller(h)?,
        finish: FinishParams {
            ref_velo: h.fRefVelo.unwrap_or(d.ref_velo),
            feed_forward: h.fFeedForward.unwrap_or(d.feed_forward),
            area_ratio: h.fAreaRatio.unwrap_or(d.area_ratio),
            overlap_comp_p: h.fValve_OverlapCompP.unwrap_or(d.overlap_comp_p),
            overlap_comp_m: h.fValve_OverlapCompM.unwrap_or(d.overlap_comp_m),
            creep_speed_p: creep_p,
            creep_speed_m: h.fCreepSpeedM.unwrap_or(creep_p),
            asymmetrical,
            bend_point_velo: h.fValve_BendPointVelo.unwrap_or(d.bend_point_velo),
            bend_point_output: h.fValve_BendPointOutput.unwrap_or(d.bend_point_output),
            zero_compensation: h.fZeroCompensation.unwrap_or(d.zero_compensation),
            lin_limit_p: h.Valve_LinLimitP.unwrap_or(d.lin_limit_p),
            lin_limit_m: h.Valve_LinLimitM.unwrap_or(d.lin_limit_m),
        },
    };
    HydController::new(params, None).map_err(|e| match e {
        FinishError::DriveOutput(_) => (
            "bDrive_AbsoluteOutput",
            Problem::Invalid(
                "only with `valve_output = \"voltage\"`: a coil output carries its direction",
            ),
        ),
        FinishError::OutOfRange { parameter, .. } | FinishError::NotAbove { parameter, .. } => (
            parameter,
            Problem::Invalid("out of its range (ST_TcHydAxParam)"),
        ),
        FinishError::BendPoint { .. } => (
            "fValve_BendPointVelo",
            Problem::Invalid(
                "with fValve_BendPointOutput: both 0 (no bend) or both above 0 and below 1",
            ),
        ),
    })?;
    Ok(params)
}

/// `position_controller` (tandem's key) and the extended controller's parameters: `None` for
/// the default controller, which refuses them (they would have no effect).
fn extended_controller(
    h: &HydraulicSection,
) -> Result<Option<PosPiControllerExParams>, FieldError> {
    let extended = match h.position_controller.as_deref() {
        None => false,
        Some(v) => super::pick(
            "position_controller",
            v,
            &[("default", false), ("extended", true)],
        )?,
    };
    let keys = [
        ("fLagAmpTd", h.fLagAmpTd),
        ("fLagAmpTdd", h.fLagAmpTdd),
        ("fLagAmpCfb_kV", h.fLagAmpCfb_kV),
        ("fLagAmpCfb_tV", h.fLagAmpCfb_tV),
        ("fLagAmpCfb_kA", h.fLagAmpCfb_kA),
        ("fLagAmpCfb_tA", h.fLagAmpCfb_tA),
    ];
    if !extended {
        return match keys.iter().find(|(_, v)| v.is_some()) {
            Some((name, _)) => Err((
                name,
                Problem::Invalid(
                    "a parameter of the extended controller: only with \
                     `position_controller = \"extended\"`",
                ),
            )),
            None => Ok(None),
        };
    }
    let [td, tdd, cfb_kv, cfb_tv, cfb_ka, cfb_ta] = keys.map(|(_, v)| v.unwrap_or(0.0));
    Ok(Some(PosPiControllerExParams {
        td,
        tdd,
        cfb_kv,
        cfb_tv,
        cfb_ka,
        cfb_ta,
    }))
}

/// The parameters of a `sim_valve_cylinder` device: `load` and `[devices.<name>.cylinder]`
/// over the defaults, checked: the key out of range.
pub(super) fn valve_cylinder(d: &DeviceSection) -> Result<SimValveCylinderParams, FieldError> {
    let c = d.cylinder.as_ref();
    let e = CylinderParams::example();
    let get =
        |f: fn(&CylinderSection) -> Option<f64>, default: f64| c.and_then(f).unwrap_or(default);
    let cylinder = CylinderParams {
        area_a: get(|c| c.area_a, e.area_a),
        area_b: get(|c| c.area_b, e.area_b),
        stroke: get(|c| c.stroke, e.stroke),
        dead_volume: get(|c| c.dead_volume, e.dead_volume),
        mass: get(|c| c.mass, e.mass),
        bulk_modulus: get(|c| c.bulk_modulus, e.bulk_modulus),
        viscous: get(|c| c.viscous, e.viscous),
        coulomb: get(|c| c.coulomb, e.coulomb),
        supply: get(|c| c.supply, e.supply),
        tank: get(|c| c.tank, e.tank),
        nominal_flow: get(|c| c.nominal_flow, e.nominal_flow),
        flow_ratio_b: get(|c| c.flow_ratio_b, e.flow_ratio_b),
        nominal_drop: get(|c| c.nominal_drop, e.nominal_drop),
        overlap: get(|c| c.overlap, e.overlap),
        offset: get(|c| c.offset, e.offset),
        bend_opening: get(|c| c.bend_opening, e.bend_opening),
        bend_flow: get(|c| c.bend_flow, e.bend_flow),
        response_time: get(|c| c.response_time, e.response_time),
    };
    let p = SimValveCylinderParams {
        cylinder,
        ready_delay: d.ready_delay.unwrap_or(0.01),
        load: d.load.unwrap_or(0.0),
        pressure_range: d.pressure_range.unwrap_or(250.0),
        input: match &d.valve_input {
            Some(v) => {
                let (output, absolute) = super::pick("valve_input", v, &VALVE_INPUTS)?;
                DriveOutputParams {
                    output,
                    absolute,
                    reversed: false,
                }
            }
            None => DriveOutputParams::default(),
        },
    };
    p.check().map_err(|e| {
        let why = match e.name {
            "ready_delay" => "must be a finite number >= 0 (s)",
            "pressure_range" => "must be a number above 0 (bar at 10 V)",
            _ => "out of its range",
        };
        (e.name, Problem::Invalid(why))
    })?;
    Ok(p)
}

/// The pressure inputs of section `h` (`None` without `ScaleFactorA`), checked: the key out of
/// range.
pub(super) fn pressure_inputs(h: &HydraulicSection) -> Result<Option<ForceScaling>, FieldError> {
    let Some(factor_a) = h.ScaleFactorA else {
        return Ok(None);
    };
    let s = ForceScaling {
        factor_a,
        offset_a: h.ScaleOffsetA.unwrap_or(0.0),
        factor_b: h.ScaleFactorB.unwrap_or(factor_a),
        offset_b: h.ScaleOffsetB.unwrap_or(0.0),
        area_a: h.ScaleArreaA.unwrap_or(1.0),
        area_b: h.ScaleArreaB.unwrap_or(1.0),
    };
    s.check().map_err(|e| {
        (
            e.name,
            Problem::Invalid("out of its range (MC_AxRtReadForceDiff_BkPlcMc)"),
        )
    })?;
    Ok(Some(s))
}

/// The characteristic curve of section `h` (`characteristic_curve`, a table file relative to
/// `dir`), read and checked as the library's table rules ask; `None` without the key.
pub(super) fn characteristic_curve(
    h: &HydraulicSection,
    dir: Option<&std::path::Path>,
) -> Result<Option<Box<ValveTable>>, FieldError> {
    let Some(file) = &h.characteristic_curve else {
        return Ok(None);
    };
    let path = dir
        .map(|d| d.join(file))
        .unwrap_or_else(|| std::path::PathBuf::from(file));
    let refused = |error: String| {
        (
            "characteristic_curve",
            Problem::CurveFile {
                path: path.display().to_string(),
                error,
            },
        )
    };
    let text = crate::read::read_text(&path, crate::read::CAM_FILE_MAX)
        .map_err(|e| refused(e.problem.to_string()))?;
    let mut buf = Box::new([(0.0, 0.0); MAX_POINTS]);
    let table =
        ValveTable::parse(&text, &mut buf).map_err(|e| refused(format!("{e} ({})", e.code())))?;
    Ok(Some(Box::new(table)))
}
