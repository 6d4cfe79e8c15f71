//! `MC_Home_BkPlcMc` (Beckhoff TwinCAT PLC Hydraulic Positioning library, 4.2.11, with
//! `MC_HomingMode_BkPlcMc` 4.3.17, `E_TcMcHomingType` 4.3.7 and the encoder members of
//! `ST_TcHydAxParam`) on a hydraulic axis.
//!
//! "Homing can only be started from a stationary condition without errors"; the modes:
//! - **Default**: the method of `nEnc_HomingType` (OnBlock → Block, OnIndex → AbsSwitch,
//!   OnSync → RefPulse, OnExec → Direct; OnMultiSync has no mode: `dwTcHydErrCdHomingType`).
//! - **AbsSwitch** (`iTcMc_HomingOnIndex`): the control value `fEnc_RefIndexVelo · fRefVelo` in
//!   the direction of `bEnc_RefIndexPositive` until the cam (`CalibrationCam` or the axis'
//!   reference cam) is TRUE; the axis stops; then `fEnc_RefSyncVelo · fRefVelo` in the
//!   direction of `bEnc_RefSyncPositive` until the cam is left; the axis stops.
//! - **RefPulse** (`iTcMc_HomingOnSync`): as AbsSwitch, then on at the sync velocity with the
//!   encoder's latch armed until it has latched the zero pulse; the axis stops.
//! - **Direct** (`iTcMc_HomingOnExec`): actual := `Position` at once. Forced on a simulated
//!   encoder (the library's `iTcMc_EncoderSim`; in tandem a virtual axis).
//! - **Block** (`iTcMc_HomingOnBlock`): the index velocity until "no movement is detected over
//!   a period of" `fBlockDetectDelay` (2 s; below the cycle time at the start: 2 s); the
//!   output is 0 at once.
//! - LimitSwitch, Absolute, FlyingSwitch, FlyingRefPulse: "not currently supported".
//!
//! Decisions on what the manual leaves open (each inferred):
//! - The point that gets the value `Position` is the actual position of the first sample in
//!   which the cam is seen left (AbsSwitch: the cam is a level bit of `nDeCtrlDWord`, read each
//!   cycle, not latched), the latched position of the zero pulse (RefPulse), the actual
//!   position when the block is detected (Block). The distance travelled from there until
//!   the axis stands is kept: actual = `Position` + that distance, as the manual says for
//!   RefPulse and as the Part 5 blocks do (`RecordedPosition`, then `MC_SetPosition`).
//! - "Leaving the cam" is a TRUE → FALSE change seen during the sync travel (the level at its
//!   start counts): a cam overrun while stopping is not taken as left.
//! - "No movement": the actual velocity below 1 % of `fRefVelo` (the smallest homing velocity
//!   the library accepts), for `fBlockDetectDelay` without a break.
//! - The velocities are control values: the travel runs without position control (the
//!   generator's output alone, as the library's "control value … which is output"), ramped up
//!   with `fMaxAcc` and down with `fRefVelo / fStopRamp` (the library names no ramp). The
//!   loop closes at the actual position when the homing ends.
//! - The homed status (`dwTcHydNsDwReferenced`) is cleared when a homing with motion starts
//!   (so that software limits of the old coordinates do not stop it, as S7's active homing) and
//!   set when it is Done; Direct sets it at once.
//! - The velocities checked against 1 % of `fRefVelo` (`dwTcHydErrCdSetVelo`) are those the
//!   method uses (Block: the index velocity; AbsSwitch, RefPulse: both; Direct: none).
//!
//! In tandem the command is sent again with its current inputs while it runs (as the library
//! FB is called every cycle): `CalibrationCam` takes its new level; `Execute = FALSE` changes
//! nothing ("execution of homing that had started continues unaffected").

use super::{reduce, Axis, Goal};
use crate::catalog::error_id::ErrorId;
use crate::catalog::hyd_error::HydErrorCode;
use crate::catalog::override_table::NewJob;
use crate::hydraulic::profile_core::ProfileGenerator;
use crate::kinematics::profile::Limits;
use crate::objects::job::{Instruction, JobEventKind, JobId};

/// `MC_HomingMode_BkPlcMc` (4.3.17): the `HomingMode` input of `MC_Home_BkPlcMc`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum HydHomingMode {
    /// `MC_DefaultHomingMode_BkPlcMc` (0): the method of `nEnc_HomingType`.
    #[doc(alias = "MC_DefaultHomingMode_BkPlcMc")]
    Default,
    /// `MC_AbsSwitch_BkPlcMc` (1): `iTcMc_HomingOnIndex`.
    #[doc(alias = "MC_AbsSwitch_BkPlcMc")]
    AbsSwitch,
    /// `MC_LimitSwitch_BkPlcMc` (2): not supported.
    #[doc(alias = "MC_LimitSwitch_BkPlcMc")]
    LimitSwitch,
    /// `MC_RefPulse_BkPlcMc` (3): `iTcMc_HomingOnSync`.
    #[doc(alias = "MC_RefPulse_BkPlcMc")]
    RefPulse,
    /// `MC_Direct_BkPlcMc` (4): `iTcMc_HomingOnExec`.
    #[doc(alias = "MC_Direct_BkPlcMc")]
    Direct,
    /// `MC_Absolute_BkPlcMc` (5): not supported.
    #[doc(alias = "MC_Absolute_BkPlcMc")]
    Absolute,
    /// `MC_Block_BkPlcMc` (6): `iTcMc_HomingOnBlock`.
    #[doc(alias = "MC_Block_BkPlcMc")]
    Block,
    /// `MC_FlyingSwitch_BkPlcMc` (7): not supported.
    #[doc(alias = "MC_FlyingSwitch_BkPlcMc")]
    FlyingSwitch,
    /// `MC_FlyingRefPulse_BkPlcMc` (8): not supported.
    #[doc(alias = "MC_FlyingRefPulse_BkPlcMc")]
    FlyingRefPulse,
}

impl HydHomingMode {
    /// The mode of the library's number (0 … 8), `None` for another.
    pub const fn from_number(n: i32) -> Option<Self> {
        Some(match n {
            0 => Self::Default,
            1 => Self::AbsSwitch,
            2 => Self::LimitSwitch,
            3 => Self::RefPulse,
            4 => Self::Direct,
            5 => Self::Absolute,
            6 => Self::Block,
            7 => Self::FlyingSwitch,
            8 => Self::FlyingRefPulse,
            _ => return None,
        })
    }
}

/// `E_TcMcHomingType` (4.3.7): `nEnc_HomingType`, the method of the default mode.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum HydHomingType {
    /// `iTcMc_HomingOnBlock` (0, the library's default): homing on a fixed stop.
    #[doc(alias = "iTcMc_HomingOnBlock")]
    OnBlock,
    /// `iTcMc_HomingOnIndex` (1): on the reference cam.
    #[doc(alias = "iTcMc_HomingOnIndex")]
    OnIndex,
    /// `iTcMc_HomingOnSync` (2): on the cam, then the encoder's zero pulse.
    #[doc(alias = "iTcMc_HomingOnSync")]
    OnSync,
    /// `iTcMc_HomingOnMultiSync` (3): distance-coded marks; no `MC_HomingMode_BkPlcMc` maps
    /// to it (the default mode refuses it with `dwTcHydErrCdHomingType`).
    #[doc(alias = "iTcMc_HomingOnMultiSync")]
    OnMultiSync,
    /// `iTcMc_HomingOnExec` (4): the actual value set at once.
    #[doc(alias = "iTcMc_HomingOnExec")]
    OnExec,
}

/// The homing members of `ST_TcHydAxParam` (`nEnc_HomingType`, `fEnc_RefIndexVelo`,
/// `fEnc_RefSyncVelo`, `bEnc_RefIndexPositive`, `bEnc_RefSyncPositive`,
/// `fEnc_DefaultHomePosition`) and `fBlockDetectDelay` of `ST_TcHydAxRtData`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct HydHomingParams {
    /// `nEnc_HomingType`.
    #[doc(alias = "nEnc_HomingType")]
    pub homing_type: HydHomingType,
    /// `fEnc_RefIndexVelo` (0 … 1): the control value, a fraction of `fRefVelo`, of the
    /// search for the cam (and of Block).
    #[doc(alias = "fEnc_RefIndexVelo")]
    pub ref_index_velo: f64,
    /// `fEnc_RefSyncVelo` (0 … 1): that of the search for the cam's end and the zero pulse.
    #[doc(alias = "fEnc_RefSyncVelo")]
    pub ref_sync_velo: f64,
    /// `bEnc_RefIndexPositive`: the cam is searched in the positive direction.
    #[doc(alias = "bEnc_RefIndexPositive")]
    pub ref_index_positive: bool,
    /// `bEnc_RefSyncPositive`: the cam's end and the zero pulse are searched positive.
    #[doc(alias = "bEnc_RefSyncPositive")]
    pub ref_sync_positive: bool,
    /// `fEnc_DefaultHomePosition` (mm): the reference position when the command gives none
    /// (as the library's PlcMcManager passes it).
    #[doc(alias = "fEnc_DefaultHomePosition")]
    pub default_home_position: f64,
    /// `fBlockDetectDelay` (s, ≥ 0): Block's time without movement; below the cycle time at
    /// the start of a homing: 2 s.
    #[doc(alias = "fBlockDetectDelay")]
    pub block_detect_delay: f64,
}

/// `fBlockDetectDelay` by default (s), also where a value below the cycle time is found.
pub const BLOCK_DETECT_DELAY_DEFAULT: f64 = 2.0;

impl Default for HydHomingParams {
    /// The library's defaults: on block, 0.1 of `fRefVelo` both, negative both, home 0, 2 s.
    fn default() -> Self {
        Self {
            homing_type: HydHomingType::OnBlock,
            ref_index_velo: 0.1,
            ref_sync_velo: 0.1,
            ref_index_positive: false,
            ref_sync_positive: false,
            default_home_position: 0.0,
            block_detect_delay: BLOCK_DETECT_DELAY_DEFAULT,
        }
    }
}

/// A homing parameter out of its range: its library name and value.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct HydHomingParamsError {
    /// The member's name (`fEnc_RefIndexVelo` …).
    pub name: &'static str,
    /// Its value.
    pub value: f64,
}

impl core::fmt::Display for HydHomingParamsError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "homing parameter `{}` = {} is out of its range",
            self.name, self.value
        )
    }
}

impl std::error::Error for HydHomingParamsError {}

impl HydHomingParams {
    /// The ranges: the velocities 0 … 1 (a control value; below 1 % is refused when a homing
    /// starts, as the library does), the home position finite, the delay finite and ≥ 0.
    pub fn check(&self) -> Result<(), HydHomingParamsError> {
        let checks = [
            ("fEnc_RefIndexVelo", self.ref_index_velo, (0.0..=1.0)),
            ("fEnc_RefSyncVelo", self.ref_sync_velo, (0.0..=1.0)),
            (
                "fEnc_DefaultHomePosition",
                self.default_home_position,
                (f64::MIN..=f64::MAX),
            ),
            (
                "fBlockDetectDelay",
                self.block_detect_delay,
                (0.0..=f64::MAX),
            ),
        ];
        for (name, value, range) in checks {
            if !range.contains(&value) {
                return Err(HydHomingParamsError { name, value });
            }
        }
        Ok(())
    }
}

/// The method a homing runs (the mode resolved).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum HomingMethod {
    /// On the cam's end.
    AbsSwitch,
    /// On the cam's end, then the zero pulse.
    RefPulse,
    /// Actual := Position at once.
    Direct,
    /// On a fixed stop.
    Block,
}

/// Why `MC_Home_BkPlcMc` refuses to start (nothing changes): the library's `ErrorID`
/// ([`HydHomeRefusal::code`]) and tandem's ([`HydHomeRefusal::error_id`]).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum HydHomeRefusal {
    /// A mode the library does not support (LimitSwitch, Absolute, FlyingSwitch,
    /// FlyingRefPulse): `dwTcHydErrCdNotSupport` 16#4107; tandem 16#800A.
    NotSupported {
        /// The mode.
        mode: HydHomingMode,
    },
    /// The default mode with `nEnc_HomingType = iTcMc_HomingOnMultiSync`:
    /// `dwTcHydErrCdHomingType` 16#4F00; tandem 16#800A.
    HomingType,
    /// Not at standstill (a motion, a coupling, a set velocity): `dwTcHydErrCdNotStartable`
    /// 16#4B01; tandem 16#8003 (as a moving follower of MC_FlyingGear_BkPlcMc).
    NotStartable,
    /// In an error state: `dwTcHydErrCdNotReady` 16#4B09; tandem 16#80F3.
    InError,
    /// A stop runs or holds the axis: `dwTcHydErrCdNotReady` 16#4B09; tandem 16#80F0.
    Stopping,
    /// Not enabled (`McState_Disabled` is not a standstill): `dwTcHydErrCdNotStartable`
    /// 16#4B01; tandem 16#800F.
    NotEnabled,
    /// A velocity below 1 % of `fRefVelo`: `dwTcHydErrCdSetVelo` 16#4359; tandem 16#8003.
    SetVelo {
        /// The parameter (`fEnc_RefIndexVelo`, `fEnc_RefSyncVelo`).
        name: &'static str,
    },
    /// `Position` is not a number: `dwTcHydAdsErrIllegalValue` 16#0706; tandem 16#8009.
    Position,
}

impl HydHomeRefusal {
    /// The library's `ErrorID`.
    pub const fn code(self) -> HydErrorCode {
        HydErrorCode(match self {
            Self::NotSupported { .. } => 0x4107,
            Self::HomingType => 0x4F00,
            Self::NotStartable | Self::NotEnabled => 0x4B01,
            Self::InError | Self::Stopping => 0x4B09,
            Self::SetVelo { .. } => 0x4359,
            Self::Position => 0x0706,
        })
    }

    /// Tandem's `ErrorID` of the refused job.
    pub const fn error_id(self) -> ErrorId {
        match self {
            Self::NotSupported { .. } | Self::HomingType => ErrorId::IllegalMode,
            Self::NotStartable | Self::SetVelo { .. } => ErrorId::IllegalVelocity,
            Self::InError => ErrorId::JobRejectedInErrorStop,
            Self::Stopping => ErrorId::AxisLocked,
            Self::NotEnabled => ErrorId::NotEnabled,
            Self::Position => ErrorId::IllegalPosition,
        }
    }
}

impl core::fmt::Display for HydHomeRefusal {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NotSupported { mode } => write!(f, "homing mode {mode:?} is not supported"),
            Self::HomingType => f.write_str("nEnc_HomingType has no homing mode"),
            Self::NotStartable => f.write_str("homing starts only from standstill"),
            Self::InError => f.write_str("the axis is in an error state"),
            Self::Stopping => f.write_str("the axis is stopping"),
            Self::NotEnabled => f.write_str("the axis is not enabled"),
            Self::SetVelo { name } => write!(f, "`{name}` is below 1 % of fRefVelo"),
            Self::Position => f.write_str("Position is not a number"),
        }
    }
}

impl std::error::Error for HydHomeRefusal {}

/// The method of `mode` with `params` (Direct on a simulated encoder, `simulated`), and the
/// velocities it uses checked against 1 % of full scale.
pub fn resolve(
    mode: HydHomingMode,
    params: &HydHomingParams,
    simulated: bool,
) -> Result<HomingMethod, HydHomeRefusal> {
    let method = match mode {
        HydHomingMode::Default => match params.homing_type {
            HydHomingType::OnBlock => HomingMethod::Block,
            HydHomingType::OnIndex => HomingMethod::AbsSwitch,
            HydHomingType::OnSync => HomingMethod::RefPulse,
            HydHomingType::OnExec => HomingMethod::Direct,
            HydHomingType::OnMultiSync => return Err(HydHomeRefusal::HomingType),
        },
        HydHomingMode::AbsSwitch => HomingMethod::AbsSwitch,
        HydHomingMode::RefPulse => HomingMethod::RefPulse,
        HydHomingMode::Direct => HomingMethod::Direct,
        HydHomingMode::Block => HomingMethod::Block,
        HydHomingMode::LimitSwitch
        | HydHomingMode::Absolute
        | HydHomingMode::FlyingSwitch
        | HydHomingMode::FlyingRefPulse => return Err(HydHomeRefusal::NotSupported { mode }),
    };
    if simulated {
        return Ok(HomingMethod::Direct);
    }
    let used: &[(&'static str, f64)] = match method {
        HomingMethod::Direct => &[],
        HomingMethod::Block => &[("fEnc_RefIndexVelo", params.ref_index_velo)],
        HomingMethod::AbsSwitch | HomingMethod::RefPulse => &[
            ("fEnc_RefIndexVelo", params.ref_index_velo),
            ("fEnc_RefSyncVelo", params.ref_sync_velo),
        ],
    };
    for &(name, v) in used {
        if v.is_nan() || v < 0.01 {
            return Err(HydHomeRefusal::SetVelo { name });
        }
    }
    Ok(method)
}

/// Where a running homing is.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum HomingPhase {
    /// Searching the cam at the index velocity (Block: the fixed stop).
    Index,
    /// On the cam: stopping before the sync travel.
    OnCam,
    /// At the sync velocity until the cam is left.
    Sync,
    /// The cam left (RefPulse): on at the sync velocity, the latch armed for the zero pulse.
    Latch,
    /// The mark found: stopping; Done at standstill.
    Stopping,
}

/// What a homing sees in one cycle.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct HomingInput {
    /// The cam: `CalibrationCam`, the plant's reference cam or the cam's input signal.
    pub cam: bool,
    /// The zero pulse latched in this cycle (physical position), if any.
    pub zero_mark: Option<f64>,
    /// The actual position (physical).
    pub actual: f64,
    /// The actual velocity.
    pub actual_velocity: f64,
}

/// What a homing gives in one cycle.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct HomingOutput {
    /// The set velocity (mm/s).
    pub velocity: f64,
    /// Done: the physical position that gets the value `Position`.
    pub done: Option<f64>,
}

/// The sequence of a homing with motion (AbsSwitch, RefPulse, Block): a pure per-cycle state
/// machine on the actual values (see the module documentation).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct HomingSequence {
    method: HomingMethod,
    phase: HomingPhase,
    /// Signed velocities of the index and the sync travel (mm/s).
    index_v: f64,
    sync_v: f64,
    /// The ramps up and down (mm/s²).
    acc: f64,
    dec: f64,
    dt: f64,
    /// Below this |actual velocity| the axis does not move (1 % of `fRefVelo`).
    still_below: f64,
    /// Block: the time without movement needed, and so far.
    block_delay: f64,
    still_for: f64,
    /// The sync travel has seen the cam TRUE.
    cam_seen: bool,
    /// The mark found (physical).
    mark: Option<f64>,
    velocity: f64,
}

/// The axis values a [`HomingSequence`] runs with.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct HomingAxis {
    /// `fRefVelo` (mm/s, > 0).
    pub ref_velo: f64,
    /// The ramp while the velocity grows (`fMaxAcc`, mm/s², > 0).
    pub acc: f64,
    /// The ramp while it falls (`fRefVelo / fStopRamp`, mm/s², > 0).
    pub dec: f64,
    /// The cycle (s, > 0).
    pub dt: f64,
}

impl HomingSequence {
    /// A homing with `method` (not Direct) and `params` on axis `ax`, standing.
    pub fn new(method: HomingMethod, params: &HydHomingParams, ax: &HomingAxis) -> Self {
        let dir = |positive: bool| if positive { 1.0 } else { -1.0 };
        let block_delay = if params.block_detect_delay < ax.dt {
            BLOCK_DETECT_DELAY_DEFAULT
        } else {
            params.block_detect_delay
        };
        Self {
            method,
            phase: HomingPhase::Index,
            index_v: dir(params.ref_index_positive) * params.ref_index_velo * ax.ref_velo,
            sync_v: dir(params.ref_sync_positive) * params.ref_sync_velo * ax.ref_velo,
            acc: ax.acc,
            dec: ax.dec,
            dt: ax.dt,
            still_below: 0.01 * ax.ref_velo,
            block_delay,
            still_for: 0.0,
            cam_seen: false,
            mark: None,
            velocity: 0.0,
        }
    }

    /// The phase.
    pub fn phase(&self) -> HomingPhase {
        self.phase
    }

    /// The signed velocity of the first travel (for its feed enable).
    pub fn index_velocity(&self) -> f64 {
        self.index_v
    }

    /// One cycle.
    pub fn step(&mut self, i: &HomingInput) -> HomingOutput {
        let target = match self.phase {
            HomingPhase::Index => self.index_cycle(i),
            HomingPhase::OnCam => {
                if self.velocity == 0.0 {
                    self.phase = HomingPhase::Sync;
                    self.cam_seen = i.cam;
                    self.sync_v
                } else {
                    0.0
                }
            }
            HomingPhase::Sync => {
                self.cam_seen |= i.cam;
                if self.cam_seen && !i.cam {
                    if self.method == HomingMethod::RefPulse {
                        self.phase = HomingPhase::Latch;
                        self.sync_v
                    } else {
                        self.found(i.actual)
                    }
                } else {
                    self.sync_v
                }
            }
            HomingPhase::Latch => match i.zero_mark {
                Some(m) => self.found(m),
                None => self.sync_v,
            },
            HomingPhase::Stopping => 0.0,
        };
        self.ramp(target);
        let done = match self.phase {
            HomingPhase::Stopping if self.velocity == 0.0 => self.mark,
            _ => None,
        };
        HomingOutput {
            velocity: self.velocity,
            done,
        }
    }

    /// The index travel: the cam (AbsSwitch, RefPulse) or the block (Block).
    fn index_cycle(&mut self, i: &HomingInput) -> f64 {
        if self.method != HomingMethod::Block {
            if i.cam {
                self.phase = HomingPhase::OnCam;
                return 0.0;
            }
            return self.index_v;
        }
        if i.actual_velocity.abs() < self.still_below {
            self.still_for += self.dt;
        } else {
            self.still_for = 0.0;
        }
        // (The time compared with a tenth of a cycle's margin: a sum of cycles.)
        if self.still_for + 0.1 * self.dt >= self.block_delay {
            // On the block: the output 0 at once.
            self.velocity = 0.0;
            return self.found(i.actual);
        }
        self.index_v
    }

    /// The mark at `at` (physical): stop.
    fn found(&mut self, at: f64) -> f64 {
        self.mark = Some(at);
        self.phase = HomingPhase::Stopping;
        0.0
    }

    /// The set velocity one ramp step towards `target`.
    fn ramp(&mut self, target: f64) {
        let v0 = self.velocity;
        let growing = target.abs() > v0.abs() && target * v0 >= 0.0;
        let rate = if growing { self.acc } else { self.dec } * self.dt;
        self.velocity = v0 + (target - v0).clamp(-rate, rate);
    }
}

/// The inputs of `MC_Home_BkPlcMc` (4.2.11).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct HydHomeInputs {
    /// `Execute`: TRUE starts a homing (or, while one runs, updates `CalibrationCam`); FALSE
    /// changes nothing of a running one.
    pub execute: bool,
    /// `Position` (mm); `None`: `fEnc_DefaultHomePosition`.
    pub position: Option<f64>,
    /// `HomingMode`.
    pub mode: HydHomingMode,
    /// `CalibrationCam`: the cam given by the application (or'ed with the axis' reference cam).
    pub calibration_cam: bool,
}

/// A running MC_Home_BkPlcMc.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(super) struct HomeRun {
    job: JobId,
    /// The reference position (reduced on a modulo axis).
    position: f64,
    calibration_cam: bool,
    seq: HomingSequence,
}

impl Axis {
    /// `MC_Home_BkPlcMc` with its inputs (see the module documentation).
    pub(super) fn cmd_hyd_home(&mut self, i: &HydHomeInputs) -> Result<JobId, ErrorId> {
        let (params, ref_velo, max_acc, stop_ramp, running) = match self.hyd.as_deref() {
            Some(h) => {
                let g = h.gen.params();
                let params = self.cfg.hydraulic.map(|p| p.homing).unwrap_or_default();
                (params, h.ref_velo, g.max_acc, g.stop_ramp, h.cmds.home)
            }
            None => return Err(ErrorId::IllegalObject),
        };
        if let Some(mut run) = running.filter(|r| self.main.is_some_and(|m| m.id == r.job)) {
            if i.execute {
                run.calibration_cam = i.calibration_cam;
                self.set_home_run(Some(run));
            }
            return Ok(run.job);
        }
        if !i.execute {
            return Ok(0);
        }
        let position = i.position.unwrap_or(params.default_home_position);
        let home = reduce(self.cfg.modulo, position);
        let method = self
            .check_hyd_home(i.mode, position, &params)
            .map_err(HydHomeRefusal::error_id)?;
        if method == HomingMethod::Direct {
            let id = self.new_id();
            self.emit(id, Instruction::HydHome, JobEventKind::Busy);
            self.shift(home - self.actual_p);
            self.homed = true;
            self.emit(id, Instruction::HydHome, JobEventKind::Done);
            return Ok(id);
        }
        let ax = HomingAxis {
            ref_velo,
            acc: max_acc,
            dec: ref_velo / stop_ramp,
            dt: self.cfg.cycle,
        };
        let seq = HomingSequence::new(method, &params, &ax);
        self.hyd_check_feed(self.actual_p + seq.index_velocity())?;
        self.apply_override_table(NewJob::Positioning);
        self.fold_superimposed();
        self.homed = false;
        self.set_position_control(false);
        let lim = Limits {
            vel: self.cfg.limits.max_velocity,
            acc: ax.acc,
            dec: ax.dec,
            ..self.default_limits()
        };
        let goal = Goal::Direct {
            position: None,
            v: 0.0,
            a: 0.0,
        };
        let job = self.start_main(Instruction::HydHome, lim, goal);
        self.set_home_run(Some(HomeRun {
            job,
            position: home,
            calibration_cam: i.calibration_cam,
            seq,
        }));
        Ok(job)
    }

    /// The refusals of MC_Home_BkPlcMc (see [`HydHomeRefusal`]); the method to run.
    fn check_hyd_home(
        &self,
        mode: HydHomingMode,
        position: f64,
        params: &HydHomingParams,
    ) -> Result<HomingMethod, HydHomeRefusal> {
        if !position.is_finite() {
            return Err(HydHomeRefusal::Position);
        }
        match self.check_motion_allowed() {
            Err(ErrorId::NotEnabled) => return Err(HydHomeRefusal::NotEnabled),
            Err(ErrorId::JobRejectedInErrorStop) => return Err(HydHomeRefusal::InError),
            Err(_) => return Err(HydHomeRefusal::Stopping),
            Ok(()) => {}
        }
        let coupled = self.sync.is_some() || self.sync_pending.is_some();
        if self.main.is_some() || self.sup_job.is_some() || coupled || self.total().v != 0.0 {
            return Err(HydHomeRefusal::NotStartable);
        }
        resolve(mode, params, self.cfg.virtual_axis)
    }

    fn set_home_run(&mut self, run: Option<HomeRun>) {
        if let Some(h) = self.hyd.as_deref_mut() {
            h.cmds.home = run;
        }
    }

    /// One cycle of a running MC_Home_BkPlcMc: the sequence on this cycle's actual values and
    /// cam; at its end the actual value set, the homed status set, the loop closed, Done. A job
    /// that is no longer the axis' (aborted) ends it, and the loop closes again unless the job
    /// that took over chose its own mode (a velocity motion).
    pub(super) fn hyd_home_cycle(&mut self) {
        let Some((mut run, cam_input)) = self
            .hyd
            .as_deref()
            .and_then(|h| h.cmds.home.map(|r| (r, h.cmds.cam_input)))
        else {
            return;
        };
        let Some(m) = self.main.filter(|m| m.id == run.job) else {
            self.set_home_run(None);
            let own_mode = self.main.is_some_and(|m| {
                matches!(
                    m.instr,
                    Instruction::MoveVelocity
                        | Instruction::MotionInVelocity
                        | Instruction::MoveJog
                )
            });
            if !own_mode {
                self.set_position_control(true);
            }
            return;
        };
        let input = HomingInput {
            cam: run.calibration_cam || self.signals.reference_cam || cam_input,
            zero_mark: self.signals.zero_mark,
            actual: self.actual_p - self.offset,
            actual_velocity: self.actual_v,
        };
        let v0 = self.basic.v;
        // Without position control the set position follows the actual one (an abort then
        // closes the loop where the axis is).
        self.basic.p = self.actual_p - self.sup.p;
        let out = run.seq.step(&input);
        self.goal = Goal::Direct {
            position: None,
            v: out.velocity,
            a: (out.velocity - v0) / self.cfg.cycle,
        };
        let Some(mark) = out.done else {
            self.set_home_run(Some(run));
            return;
        };
        self.set_home_run(None);
        self.shift(run.position - (mark + self.offset));
        self.homed = true;
        self.basic.v = 0.0;
        self.set_position_control(true);
        self.finish_main(m.id, m.instr);
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    const AX: HomingAxis = HomingAxis {
        ref_velo: 200.0,
        acc: 1000.0,
        dec: 200.0,
        dt: 0.001,
    };

    fn input(cam: bool, actual: f64, v: f64) -> HomingInput {
        HomingInput {
            cam,
            zero_mark: None,
            actual,
            actual_velocity: v,
        }
    }

    /// Runs `seq` on a plant that follows the set velocity exactly, with a cam on `[lo, hi]`
    /// and a zero mark at `zero`; returns the mark and the cycles.
    fn run(seq: &mut HomingSequence, p0: f64, cam: (f64, f64), zero: Option<f64>) -> (f64, usize) {
        let mut p = p0;
        let mut v = 0.0;
        for k in 0..100_000 {
            let prev = p;
            p += v * AX.dt;
            let z = zero.filter(|z| (prev - z) * (p - z) <= 0.0 && prev != p);
            let on = (cam.0..=cam.1).contains(&p);
            let out = seq.step(&HomingInput {
                cam: on,
                zero_mark: z,
                actual: p,
                actual_velocity: v,
            });
            if let Some(m) = out.done {
                return (m, k);
            }
            v = out.velocity;
        }
        panic!("no end in {:?}", seq.phase());
    }

    #[test]
    fn the_modes_resolve_as_the_library_maps_them() {
        let p = HydHomingParams::default();
        let r = |m, p: &HydHomingParams| resolve(m, p, false);
        assert_eq!(r(HydHomingMode::Default, &p), Ok(HomingMethod::Block));
        for (t, m) in [
            (HydHomingType::OnIndex, HomingMethod::AbsSwitch),
            (HydHomingType::OnSync, HomingMethod::RefPulse),
            (HydHomingType::OnExec, HomingMethod::Direct),
        ] {
            let q = HydHomingParams {
                homing_type: t,
                ..p
            };
            assert_eq!(r(HydHomingMode::Default, &q), Ok(m));
        }
        let multi = HydHomingParams {
            homing_type: HydHomingType::OnMultiSync,
            ..p
        };
        let e = r(HydHomingMode::Default, &multi).unwrap_err();
        assert_eq!((e, e.code().0), (HydHomeRefusal::HomingType, 0x4F00));
        for n in [2, 5, 7, 8] {
            let mode = HydHomingMode::from_number(n).unwrap();
            let e = r(mode, &p).unwrap_err();
            assert_eq!(e.code().0, 0x4107, "{mode:?}");
            assert_eq!(e.error_id(), ErrorId::IllegalMode);
        }
        assert_eq!(HydHomingMode::from_number(9), None);
        // A simulated encoder homes Direct whatever the mode.
        assert_eq!(
            resolve(HydHomingMode::Block, &p, true),
            Ok(HomingMethod::Direct)
        );
    }

    #[test]
    fn velocities_below_one_percent_are_refused_with_set_velo() {
        let p = HydHomingParams {
            ref_sync_velo: 0.0099,
            ..HydHomingParams::default()
        };
        // Block does not use the sync velocity.
        assert_eq!(
            resolve(HydHomingMode::Block, &p, false),
            Ok(HomingMethod::Block)
        );
        let e = resolve(HydHomingMode::AbsSwitch, &p, false).unwrap_err();
        assert_eq!(
            e,
            HydHomeRefusal::SetVelo {
                name: "fEnc_RefSyncVelo"
            }
        );
        assert_eq!(
            (e.code().0, e.error_id()),
            (0x4359, ErrorId::IllegalVelocity)
        );
        let q = HydHomingParams {
            ref_sync_velo: 0.01,
            ..p
        };
        assert!(resolve(HydHomingMode::AbsSwitch, &q, false).is_ok());
    }

    #[test]
    fn parameter_ranges_name_the_member() {
        assert!(HydHomingParams::default().check().is_ok());
        for (p, name) in [
            (
                HydHomingParams {
                    ref_index_velo: 1.5,
                    ..HydHomingParams::default()
                },
                "fEnc_RefIndexVelo",
            ),
            (
                HydHomingParams {
                    ref_sync_velo: f64::NAN,
                    ..HydHomingParams::default()
                },
                "fEnc_RefSyncVelo",
            ),
            (
                HydHomingParams {
                    block_detect_delay: -1.0,
                    ..HydHomingParams::default()
                },
                "fBlockDetectDelay",
            ),
            (
                HydHomingParams {
                    default_home_position: f64::INFINITY,
                    ..HydHomingParams::default()
                },
                "fEnc_DefaultHomePosition",
            ),
        ] {
            assert_eq!(p.check().unwrap_err().name, name);
        }
    }

    /// AbsSwitch, both directions negative (the defaults): the index travel at 0.1 · 200 mm/s
    /// onto the cam [40, 50] from 100, a stop on it, the sync travel on until the cam is left
    /// at 40: the mark is the first sample below 40, within one cycle's travel at the sync
    /// velocity (20 mm/s · 1 ms = 0.02 mm).
    #[test]
    fn abs_switch_marks_where_the_cam_is_left() {
        let p = HydHomingParams::default();
        let mut s = HomingSequence::new(HomingMethod::AbsSwitch, &p, &AX);
        assert_eq!(s.index_velocity(), -20.0);
        let (m, _) = run(&mut s, 100.0, (40.0, 50.0), None);
        assert!((40.0 - 20.0 * AX.dt - 1e-9..40.0).contains(&m), "{m}");
    }

    /// The sync travel reversed (positive): the cam is left at its upper end, 50.
    #[test]
    fn abs_switch_with_the_sync_reversed_leaves_at_the_other_end() {
        let p = HydHomingParams {
            ref_sync_positive: true,
            ref_sync_velo: 0.05,
            ..HydHomingParams::default()
        };
        let mut s = HomingSequence::new(HomingMethod::AbsSwitch, &p, &AX);
        let (m, _) = run(&mut s, 100.0, (40.0, 50.0), None);
        assert!(m > 50.0 && m <= 50.0 + 10.0 * AX.dt + 1e-9, "{m}");
    }

    /// A cam already passed when the sync travel starts is not taken as left: the sync travel
    /// (reversed) must find it again and leave it.
    #[test]
    fn a_cam_overrun_while_stopping_is_not_taken_as_left() {
        let p = HydHomingParams {
            ref_sync_positive: true,
            ..HydHomingParams::default()
        };
        let mut s = HomingSequence::new(HomingMethod::AbsSwitch, &p, &AX);
        // A cam of 0.5 mm: the stop from 20 mm/s at 200 mm/s² needs 1 mm.
        let (m, _) = run(&mut s, 100.0, (40.0, 40.5), None);
        assert!(m > 40.5 && m <= 40.5 + 20.0 * AX.dt + 1e-9, "{m}");
    }

    /// RefPulse: after the cam, on to the next zero mark in the sync direction; the mark is
    /// the latched position, exactly.
    #[test]
    fn ref_pulse_marks_the_latched_zero_pulse() {
        let p = HydHomingParams {
            homing_type: HydHomingType::OnSync,
            ..HydHomingParams::default()
        };
        let mut s = HomingSequence::new(HomingMethod::RefPulse, &p, &AX);
        let (m, _) = run(&mut s, 100.0, (40.0, 50.0), Some(37.5));
        assert_eq!(m, 37.5);
    }

    /// Block: Done exactly after fBlockDetectDelay without movement, the output 0 at once.
    #[test]
    fn block_is_detected_after_the_delay_without_movement() {
        let p = HydHomingParams {
            block_detect_delay: 0.5,
            ..HydHomingParams::default()
        };
        let mut s = HomingSequence::new(HomingMethod::Block, &p, &AX);
        // Moving: never detected.
        for _ in 0..2000 {
            let o = s.step(&input(false, 50.0, -20.0));
            assert!(o.done.is_none());
        }
        // Stalled: 500 cycles of 1 ms.
        let mut k = 0;
        let out = loop {
            k += 1;
            let o = s.step(&input(false, 3.0, 0.0));
            if o.done.is_some() {
                break o;
            }
            assert_eq!(o.velocity, -20.0, "cycle {k}");
        };
        assert_eq!(k, 500);
        assert_eq!(out.velocity, 0.0);
        assert_eq!(out.done, Some(3.0));
    }

    /// fBlockDetectDelay below the cycle time: 2 s.
    #[test]
    fn a_block_delay_below_the_cycle_is_two_seconds() {
        let p = HydHomingParams {
            block_detect_delay: 0.0,
            ..HydHomingParams::default()
        };
        let mut s = HomingSequence::new(HomingMethod::Block, &p, &AX);
        let k = (1..=3000)
            .find(|_| s.step(&input(false, 3.0, 0.0)).done.is_some())
            .unwrap();
        assert_eq!(k, 2000);
    }

    proptest::proptest! {
        #![proptest_config(proptest::test_runner::Config {
            cases: 500,
            rng_seed: proptest::test_runner::RngSeed::Fixed(0x40_4E5E),
            failure_persistence: None,
            ..proptest::test_runner::Config::default()
        })]

        /// AbsSwitch with any cam (wider than the index travel's stop), velocities and
        /// directions: the mark lies beyond the edge the sync travel leaves (the lower end
        /// going negative, the upper going positive) by at most one cycle's travel at the
        /// sync velocity.
        #[test]
        fn abs_switch_marks_the_edge_within_one_cycle(
            lo in -50.0..50.0f64,
            width in 5.0..40.0f64,
            index in 0.01..0.2f64,
            sync in 0.01..0.2f64,
            index_positive in proptest::bool::ANY,
            sync_positive in proptest::bool::ANY,
        ) {
            let p = HydHomingParams {
                ref_index_velo: index,
                ref_sync_velo: sync,
                ref_index_positive: index_positive,
                ref_sync_positive: sync_positive,
                ..HydHomingParams::default()
            };
            let hi = lo + width;
            let start = if index_positive { lo - 30.0 } else { hi + 30.0 };
            let mut s = HomingSequence::new(HomingMethod::AbsSwitch, &p, &AX);
            let (m, _) = run(&mut s, start, (lo, hi), None);
            let step = sync * AX.ref_velo * AX.dt + 1e-9;
            if sync_positive {
                proptest::prop_assert!(m > hi && m <= hi + step, "{m} after {hi}");
            } else {
                proptest::prop_assert!(m < lo && m >= lo - step, "{m} before {lo}");
            }
        }
    }

    /// The ramps: up with the acceleration, down with the stop ramp's deceleration.
    #[test]
    fn the_velocity_ramps_with_the_axis_ramps() {
        let p = HydHomingParams::default();
        let mut s = HomingSequence::new(HomingMethod::AbsSwitch, &p, &AX);
        let o = s.step(&input(false, 100.0, 0.0));
        assert!((o.velocity + 1.0).abs() < 1e-12, "{}", o.velocity);
        for _ in 0..30 {
            s.step(&input(false, 100.0, -20.0));
        }
        let o = s.step(&input(true, 50.0, -20.0));
        assert_eq!(s.phase(), HomingPhase::OnCam);
        assert!((o.velocity + 19.8).abs() < 1e-12, "{}", o.velocity);
    }
}
