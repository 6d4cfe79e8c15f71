//! An analog drive: a speed (or, later, valve) setpoint in normalized units on an analog output,
//! an enable digital output, an optional ready digital input, and an encoder of its own, as
//! S7-1500T connects one (S7-1500T Motion Control V4.0 function manual, 'Drive and encoder
//! connection': "an analog output (e.g. ±10 V) with an optional enable DO and an optional ready
//! DI"; MC_Power: "Analog: the enable DO is set; Status becomes TRUE when the ready DI arrives
//! (if configured). On disable the enable DO drops only when the setpoint reaches 0. Loss of
//! ready while enabled means remove enable").
//!
//! Unlike a CiA 402 drive in CSP, an analog drive closes only its speed loop; tandem closes the
//! position loop. The pieces, each pure, allocation-free and stepped with time as an input:
//! - [`PositionController`]: the P position controller with velocity precontrol of 'Closed-loop
//!   control' (`Kv`, `Kpc`), its control difference formed against the balanced setpoint of the
//!   dynamic axis model ([`BalancingFilter`]), its output normalized to the reference velocity
//!   and clamped to what the analog output can give ([`MAX_COMMAND`]).
//! - [`output_word`]: the normalized command as the word of an S7 analog output (±27648 = ±10 V
//!   = ±100 %, overrange to ±32511).
//! - [`AnalogEnable`]: the enable DO / ready DI handshake with its timeout.
//! - [`AnalogConnection`]: the three together with the encoder (its raw word through
//!   [`RawCounter`] and [`Scaling`]), between the axis's [`DriveInputs`] / [`DriveOutputs`] and
//!   the drive's [`AnalogFeedback`] / [`AnalogCommand`]; what a node's process image runs for
//!   an axis with `[axes.<name>.drive] type = "analog"`.
//! - [`SimAnalogDrive`]: a simulated analog drive (a speed-controlled motor as a first-order lag
//!   with a speed limit, an input offset, its own stop ramp, enable input, ready output, faults a
//!   test can inject) with the encoder on its load.
//!
//! A valve command (the hydraulic axis of the Beckhoff hydraulic positioning library) plugs in
//! between the controller's normalized output and [`output_word`]: the controller's output is
//! the normalized set velocity that library calls `fLagCtrlOutput` + feed forward, and its
//! Finish stage (overlap, bend point, characteristic curve) would map it to the valve's
//! normalized output before the word is formed.

use core::fmt;

use super::drive::{Actual, Plant};
use super::link::{AxisSignals, DriveInputs, DriveOutputs, DriveState};
use super::mechanics::{RawCounter, Scaling, DEGREES_PER_REVOLUTION};
use crate::hydraulic::controller::{HydControlInput, HydController};
use crate::hydraulic::drive_output::ValveWords;
use crate::hydraulic::pressure::{ActualForce, ForceScaling};

pub use super::analog_word::{output_word, word_to_normalized, NOMINAL_WORD, OVERRANGE_WORD};

/// The voltage of [`NOMINAL_WORD`] (V).
pub const NOMINAL_VOLTAGE: f64 = 10.0;
/// The largest normalized command, `32511 / 27648` (about 117.6 %): the manual's "analog
/// outputs can be overdriven to ±117 %" ('Drive and encoder connection', NSET).
pub const MAX_COMMAND: f64 = OVERRANGE_WORD as f64 / NOMINAL_WORD as f64;
/// Cycles between a command and the actual value that shows it (the same order of a cycle as
/// the CiA 402 drives: written at the next boundary, acting for one cycle, sampled at the one
/// after). S7's `T_ipo + T_servo` of 'Simulated/virtual actual value'.
pub const TRANSPORT_CYCLES: usize = 2;
/// The step [`DriveState::Enabling`] and [`DriveState::EnableTimedOut`] name for an analog
/// drive: waiting for its ready DI after the enable DO was set (alarm 421 supplement
/// `0x10 + 4` = `0x14` when it does not come within the enable timeout). Numbered after the
/// CiA 402 steps 0-3 so that a supplement is unambiguous.
pub const READY_STEP: u8 = 4;
/// The largest `Kv` S7 accepts (`PositionControl.Kv`, 1/s).
pub const MAX_KV: f64 = 2_147_480.0;
/// The largest `Kpc` S7 accepts (`PositionControl.Kpc`, %).
pub const MAX_KPC_PERCENT: f64 = 150.0;
/// The largest time constant accepted (s). Inferred: the manual gives no bound; a speed loop
/// slower than this is no servo drive.
pub const MAX_TIME_CONSTANT: f64 = 10.0;

/// What is wrong with a parameter of the analog connection or the simulated analog drive.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum AnalogParamsProblem {
    /// Must be a finite number.
    NotFinite,
    /// Must be positive.
    NotPositive,
    /// Must be zero or positive.
    Negative,
    /// Outside its range (see the field's documentation).
    OutOfRange,
}

impl AnalogParamsProblem {
    /// The rule, in words.
    pub const fn text(self) -> &'static str {
        match self {
            Self::NotFinite => "must be a finite number",
            Self::NotPositive => "must be positive",
            Self::Negative => "must be zero or positive",
            Self::OutOfRange => "is out of range",
        }
    }
}

impl fmt::Display for AnalogParamsProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.text())
    }
}

/// A parameter of the analog connection or of the simulated analog drive that is refused.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct AnalogParamsError {
    /// The field's name in [`ControllerParams`], [`AnalogParams`] or [`SimAnalogParams`].
    pub field: &'static str,
    /// What is wrong with it.
    pub problem: AnalogParamsProblem,
}

impl fmt::Display for AnalogParamsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "analog drive: {} {}", self.field, self.problem)
    }
}

impl std::error::Error for AnalogParamsError {}

/// Checks that `x` is finite and within `min..=max` (`min_exclusive`: above `min`).
fn check(
    field: &'static str,
    x: f64,
    min: f64,
    min_exclusive: bool,
    max: f64,
) -> Result<(), AnalogParamsError> {
    let problem = if !x.is_finite() {
        AnalogParamsProblem::NotFinite
    } else if min_exclusive && x <= min {
        AnalogParamsProblem::NotPositive
    } else if x < min && min == 0.0 {
        AnalogParamsProblem::Negative
    } else if x < min || x > max {
        AnalogParamsProblem::OutOfRange
    } else {
        return Ok(());
    };
    Err(AnalogParamsError { field, problem })
}

/// `exp(-dt / tau)`, 0 for `tau == 0` (no lag).
fn decay(dt: f64, tau: f64) -> f64 {
    if tau > 0.0 {
        (-dt / tau).exp()
    } else {
        0.0
    }
}

/// The parameters of tandem's position controller for an analog drive (S7-1500T Motion Control
/// V4.0 function manual, 'Closed-loop control' and 'Drive and encoder connection').
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ControllerParams {
    /// The position control cycle (ns, > 0): the node's cycle.
    pub cycle_ns: i64,
    /// `PositionControl.Kv` (1/s, 0..=[`MAX_KV`]).
    #[doc(alias = "PositionControl.Kv")]
    pub kv: f64,
    /// `PositionControl.Kpc`: velocity precontrol (%, 0..=[`MAX_KPC_PERCENT`]).
    #[doc(alias = "PositionControl.Kpc")]
    pub kpc_percent: f64,
    /// `DynamicAxisModel.VelocityTimeConstant` `T_vtc` (s, 0..=[`MAX_TIME_CONSTANT`]): the
    /// speed loop's equivalent time constant, a first-order lag of the balancing filter.
    #[doc(alias = "DynamicAxisModel.VelocityTimeConstant")]
    pub velocity_time_constant: f64,
    /// `DynamicAxisModel.AdditionalPositionTimeConstant` `T_addPtc` (s, 0..=
    /// [`MAX_TIME_CONSTANT`]). Inferred: modelled as a second first-order lag (the manual adds
    /// it to `T_t` like `T_vtc`; a first-order lag delays a ramp by exactly its time constant).
    #[doc(alias = "DynamicAxisModel.AdditionalPositionTimeConstant")]
    pub additional_position_time_constant: f64,
    /// The velocity of the load at a command of 100 % (10 V, word 27648), in the axis's units
    /// per second (> 0): S7's `Actor.DriveParameter.ReferenceSpeed` (a motor speed in 1/min)
    /// through the load gear and the leadscrew; the Beckhoff hydraulic library's `fRefVelo`.
    #[doc(alias = "ReferenceSpeed")]
    #[doc(alias = "fRefVelo")]
    pub reference_velocity: f64,
}

impl ControllerParams {
    /// Checks every field; the first refused is named.
    pub fn validate(&self) -> Result<(), AnalogParamsError> {
        if self.cycle_ns <= 0 {
            return Err(AnalogParamsError {
                field: "cycle_ns",
                problem: AnalogParamsProblem::NotPositive,
            });
        }
        check("kv", self.kv, 0.0, false, MAX_KV)?;
        check("kpc_percent", self.kpc_percent, 0.0, false, MAX_KPC_PERCENT)?;
        check(
            "velocity_time_constant",
            self.velocity_time_constant,
            0.0,
            false,
            MAX_TIME_CONSTANT,
        )?;
        check(
            "additional_position_time_constant",
            self.additional_position_time_constant,
            0.0,
            false,
            MAX_TIME_CONSTANT,
        )?;
        check(
            "reference_velocity",
            self.reference_velocity,
            0.0,
            true,
            f64::MAX,
        )
    }

    /// The cycle in seconds.
    pub fn cycle(&self) -> f64 {
        self.cycle_ns as f64 * 1e-9
    }
}

/// The balancing filter (S7 "dynamic axis model"): the position setpoint delayed by the
/// [`TRANSPORT_CYCLES`] of the process image, then through the first-order lags `T_addPtc` and
/// `T_vtc`, so that it stands where the actual value should be ('Closed-loop control': "the
/// position setpoint is delayed by the speed-loop equivalent time T_vtc plus
/// AdditionalPositionTimeConstant before the control difference is formed"; 'Simulated/virtual
/// actual value': `T_t = T_ipo + T_servo + T_vtc + T_addPtc`). Its output is S7's
/// `StatusServo.BalancedPosition`. Inferred: applied with and without precontrol, as tandem's
/// simulated drive model does; without precontrol it only shifts the reference the steady lag
/// `v / Kv` is measured from.
#[derive(Copy, Clone, Debug, PartialEq)]
#[doc(alias = "BalancedPosition")]
pub struct BalancingFilter {
    /// The setpoints of the last [`TRANSPORT_CYCLES`] cycles, the newest at `head`.
    delayed: [f64; TRANSPORT_CYCLES],
    head: usize,
    /// Output of the `T_addPtc` lag.
    additional: f64,
    /// Output of the `T_vtc` lag: the balanced setpoint.
    balanced: f64,
    decay_additional: f64,
    decay_velocity: f64,
}

impl BalancingFilter {
    /// A filter at rest at `p`, for cycle `cycle` (s) and the two time constants (s).
    pub fn new(cycle: f64, velocity_time_constant: f64, additional: f64, p: f64) -> Self {
        Self {
            delayed: [p; TRANSPORT_CYCLES],
            head: 0,
            additional: p,
            balanced: p,
            decay_additional: decay(cycle, additional),
            decay_velocity: decay(cycle, velocity_time_constant),
        }
    }

    /// The balanced setpoint for the coming cycle.
    pub fn balanced(&self) -> f64 {
        self.balanced
    }

    /// Takes the setpoint of this cycle; the balanced setpoint moves to the next cycle.
    pub fn push(&mut self, p: f64) {
        let n = self.delayed.len();
        self.head = (self.head + 1) % n;
        if let Some(s) = self.delayed.get_mut(self.head) {
            *s = p;
        }
        // The oldest: the setpoint of TRANSPORT_CYCLES - 1 cycles ago, which the actual value
        // of the next cycle shows.
        let oldest = self.delayed.get((self.head + 1) % n).copied().unwrap_or(p);
        self.additional = oldest + (self.additional - oldest) * self.decay_additional;
        self.balanced = self.additional + (self.balanced - self.additional) * self.decay_velocity;
    }

    /// Rests the filter at `p` (the axis is not enabled: its setpoint follows the actual value).
    pub fn reset(&mut self, p: f64) {
        self.delayed = [p; TRANSPORT_CYCLES];
        self.additional = p;
        self.balanced = p;
    }
}

/// One cycle's result of the [`PositionController`].
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct ControllerOutput {
    /// The speed setpoint, normalized (1.0 = the reference velocity), within ±[`MAX_COMMAND`].
    pub normalized: f64,
    /// The control difference `balanced − actual` it was formed from (S7
    /// `StatusServo.ControlDifference`).
    #[doc(alias = "ControlDifference")]
    pub control_difference: f64,
    /// The command was clamped to ±[`MAX_COMMAND`].
    pub saturated: bool,
}

/// tandem's position controller for an analog drive: a P controller with velocity precontrol
/// (S7-1500T Motion Control V4.0 function manual, 'Closed-loop control'):
///
/// `speed setpoint = Kpc · v_setpoint + Kv · (balanced setpoint − actual position)`,
///
/// normalized to the reference velocity and clamped to ±[`MAX_COMMAND`]. Without position
/// control (MC_Power StartMode 0, MC_MoveVelocity PositionControlled FALSE) the velocity
/// setpoint alone is the speed setpoint (100 %, no Kv). The steady-state lag at constant velocity
/// `v` is `(1 − Kpc) · v / Kv` (`v / Kv` without precontrol, the manual's "[derived] 2 mm at
/// 100 mm/s and Kv = 50"), since the speed must equal `v`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PositionController {
    params: ControllerParams,
    kpc: f64,
    filter: BalancingFilter,
}

impl PositionController {
    /// A controller at rest at `p` (physical). Refuses parameters out of range.
    pub fn new(params: ControllerParams, p: f64) -> Result<Self, AnalogParamsError> {
        params.validate()?;
        Ok(Self {
            params,
            kpc: params.kpc_percent / 100.0,
            filter: BalancingFilter::new(
                params.cycle(),
                params.velocity_time_constant,
                params.additional_position_time_constant,
                p,
            ),
        })
    }

    /// Its parameters.
    pub fn params(&self) -> &ControllerParams {
        &self.params
    }

    /// The balanced setpoint the next [`step`](Self::step) forms its control difference with.
    pub fn balanced(&self) -> f64 {
        self.filter.balanced()
    }

    /// One cycle: the setpoint `(position, velocity)` of this cycle (physical) and the actual
    /// position sampled at its start. Returns the speed setpoint for the next cycle.
    pub fn step(
        &mut self,
        position: f64,
        velocity: f64,
        actual: f64,
        position_controlled: bool,
    ) -> ControllerOutput {
        let e = self.filter.balanced() - actual;
        let speed = if position_controlled {
            self.kpc * velocity + self.params.kv * e
        } else {
            velocity
        };
        self.filter.push(position);
        let n = speed / self.params.reference_velocity;
        let (normalized, saturated) = if n.is_nan() {
            (0.0, true)
        } else {
            let c = n.clamp(-MAX_COMMAND, MAX_COMMAND);
            (c, c != n)
        };
        ControllerOutput {
            normalized,
            control_difference: if position_controlled { e } else { 0.0 },
            saturated,
        }
    }

    /// Rests the controller at setpoint `p` (the axis is not enabled).
    pub fn reset(&mut self, p: f64) {
        self.filter.reset(p);
    }
}

/// Where the enable handshake of an analog drive stands.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum AnalogEnableStatus {
    /// Not enabled; the enable DO is off.
    #[default]
    Disabled,
    /// The enable DO is set; waiting for the ready DI (step [`READY_STEP`]) since this time.
    WaitingForReady {
        /// When the enable DO was set (ns).
        since_ns: i64,
    },
    /// Enabled: the drive follows the speed setpoint.
    Enabled,
    /// The enable was removed; the enable DO stays set until the setpoint written is 0.
    Disabling,
    /// The ready DI dropped while enabled: the enable DO is removed; latched until the enable
    /// request is removed.
    ReadyLost,
    /// The ready DI did not come within the timeout: the enable DO is removed; latched until
    /// the enable request is removed.
    TimedOut,
}

/// One cycle's result of [`AnalogEnable::step`].
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct AnalogEnableOutput {
    /// The enable digital output to write with this cycle's command.
    pub enable_do: bool,
    /// Where the handshake stands.
    pub status: AnalogEnableStatus,
}

/// The timeout of an [`AnalogEnable`] is not positive.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct InvalidReadyTimeout {
    /// The value that was given (ns).
    pub timeout_ns: i64,
}

impl fmt::Display for InvalidReadyTimeout {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "enable timeout {} ns must be positive", self.timeout_ns)
    }
}

impl std::error::Error for InvalidReadyTimeout {}

/// The enable handshake of an analog drive, as MC_Power runs it (S7-1500T Motion Control V4.0
/// function manual, MC_Power: "Analog: the enable DO is set; Status becomes TRUE when the ready
/// DI arrives (if configured). On disable the enable DO drops only when the setpoint reaches 0.
/// Loss of ready while enabled means remove enable").
///
/// Stepped once per cycle with the time, the enable request of the last cycle, the ready DI
/// sampled now, and whether the setpoint last written is 0:
/// - Disabled + request: the enable DO is set. Without a ready DI configured the drive is
///   enabled at once; with one, [`AnalogEnableStatus::WaitingForReady`] until a sample shows
///   ready (at the earliest the cycle after the DO was set), or [`AnalogEnableStatus::TimedOut`]
///   once `now - since >= timeout` (the DO is removed).
/// - Enabled, ready DI configured and not ready: [`AnalogEnableStatus::ReadyLost`], the DO is
///   removed at once.
/// - Enabled, request removed: [`AnalogEnableStatus::Disabling`] with the DO still set until the
///   setpoint written is 0, then Disabled.
/// - ReadyLost and TimedOut stay until the request is removed; a new request then starts over.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct AnalogEnable {
    timeout_ns: i64,
    ready_configured: bool,
    status: AnalogEnableStatus,
}

impl AnalogEnable {
    /// A handshake that waits at most `timeout_ns` (> 0) for the ready DI, if
    /// `ready_configured`.
    pub const fn new(timeout_ns: i64, ready_configured: bool) -> Result<Self, InvalidReadyTimeout> {
        if timeout_ns <= 0 {
            return Err(InvalidReadyTimeout { timeout_ns });
        }
        Ok(Self {
            timeout_ns,
            ready_configured,
            status: AnalogEnableStatus::Disabled,
        })
    }

    /// Where the handshake stands.
    pub const fn status(&self) -> AnalogEnableStatus {
        self.status
    }

    /// One cycle at `now_ns`.
    pub fn step(
        &mut self,
        now_ns: i64,
        request: bool,
        ready: bool,
        setpoint_zero: bool,
    ) -> AnalogEnableOutput {
        use AnalogEnableStatus as S;
        let ready_ok = ready || !self.ready_configured;
        self.status = match self.status {
            S::Disabled | S::Disabling if request => {
                if self.ready_configured {
                    S::WaitingForReady { since_ns: now_ns }
                } else {
                    S::Enabled
                }
            }
            S::Disabling if !setpoint_zero => S::Disabling,
            S::Disabled | S::Disabling => S::Disabled,
            S::WaitingForReady { .. } if !request => S::Disabled,
            S::WaitingForReady { .. } if ready => S::Enabled,
            S::WaitingForReady { since_ns } => {
                if now_ns.saturating_sub(since_ns) >= self.timeout_ns {
                    S::TimedOut
                } else {
                    S::WaitingForReady { since_ns }
                }
            }
            S::Enabled if !ready_ok => S::ReadyLost,
            S::Enabled if !request => {
                if setpoint_zero {
                    S::Disabled
                } else {
                    S::Disabling
                }
            }
            S::Enabled => S::Enabled,
            S::ReadyLost | S::TimedOut if !request => S::Disabled,
            latched @ (S::ReadyLost | S::TimedOut) => latched,
        };
        AnalogEnableOutput {
            enable_do: matches!(
                self.status,
                S::WaitingForReady { .. } | S::Enabled | S::Disabling
            ),
            status: self.status,
        }
    }

    /// The state the axis sees ([`DriveState`]): enabled is operational; waiting for ready is
    /// enabling step [`READY_STEP`]; a timeout names that step (alarm 421 supplement 0x14); a
    /// lost ready is a drive that shut down on its own (alarm 421 supplement 3, "drive has shut
    /// down": an analog drive gives no error code).
    pub const fn drive_state(&self) -> DriveState {
        match self.status {
            AnalogEnableStatus::Enabled => DriveState::Operational,
            AnalogEnableStatus::WaitingForReady { .. } => DriveState::Enabling { step: READY_STEP },
            AnalogEnableStatus::TimedOut => DriveState::EnableTimedOut { step: READY_STEP },
            AnalogEnableStatus::Disabled
            | AnalogEnableStatus::Disabling
            | AnalogEnableStatus::ReadyLost => DriveState::Disabled,
        }
    }
}

/// What the node writes to an analog drive: its process image outputs.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct AnalogCommand {
    /// The enable digital output.
    pub enable: bool,
    /// The output words: `word` is the analog output word ([`output_word`]); a hydraulic axis'
    /// valve output in the form of its drive stage (coil A's current with two coils, coil B's
    /// in `word_b`, the direction bits; [`crate::hydraulic::drive_output`]).
    #[doc(alias = "NSET")]
    pub words: ValveWords,
}

impl AnalogCommand {
    /// The enable output and a single ±10 V output word (an electric axis' speed setpoint).
    pub fn new(enable: bool, word: i16) -> Self {
        Self {
            enable,
            words: ValveWords {
                word,
                ..ValveWords::default()
            },
        }
    }
}

/// What the node reads of an analog drive and its encoder: its process image inputs.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct AnalogFeedback {
    /// The ready digital input.
    pub ready: bool,
    /// The encoder's raw position word (its low `raw_bits` count; an incremental encoder's
    /// counter on a technology module, e.g. an EL5101 counter value).
    pub encoder_raw: u32,
    /// The pressure sensor of chamber A of a hydraulic axis, its analog input word (0 where
    /// there is none).
    pub pressure_a: i16,
    /// The pressure sensor of chamber B, its analog input word.
    pub pressure_b: i16,
}

/// The configuration of an axis's analog drive connection.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AnalogParams {
    /// The position controller.
    pub controller: ControllerParams,
    /// The time allowed for the ready DI after the enable DO (ns, > 0).
    pub enable_timeout_ns: i64,
    /// A ready DI is wired (S7: optional); without it the drive counts as ready once enabled.
    pub ready: bool,
    /// The encoder and the mechanics (`Actor.InverseDirection` inverts the command).
    pub scaling: Scaling,
}

/// What an [`AnalogConnection`] shows of its last cycle (for traces and tests).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct AnalogStatus {
    /// The handshake.
    pub enable: AnalogEnableStatus,
    /// The enable DO written.
    pub enable_do: bool,
    /// The ready DI read.
    pub ready: bool,
    /// The command written, normalized (after the drive's inversion).
    pub normalized: f64,
    /// The word written.
    pub word: i16,
    /// The control difference of the last command.
    pub control_difference: f64,
    /// The command was clamped.
    pub saturated: bool,
    /// A hydraulic axis: the position controller's output `fLagCtrlOutput` (normalised, P and
    /// I part) of the last cycle; 0 while it does not act, and for an electric axis.
    #[doc(alias = "fLagCtrlOutput")]
    pub lag_ctrl_output: f64,
}

/// An axis's connection to an analog drive: the encoder, the handshake and tandem's position
/// controller between the axis's [`DriveInputs`] / [`DriveOutputs`] and the drive's
/// [`AnalogFeedback`] / [`AnalogCommand`]. The node calls [`inputs`](Self::inputs) with the
/// sample of the cycle boundary before the axis steps and [`command`](Self::command) with the
/// axis's outputs after it (docs/io.md, "The process image and the order of a cycle").
#[derive(Clone, Debug, PartialEq)]
pub struct AnalogConnection {
    params: AnalogParams,
    controller: PositionController,
    /// A hydraulic axis' position controller and Finish, in place of `controller`'s speed
    /// setpoint ([`AnalogConnection::hydraulic`]).
    hydraulic: Option<HydController>,
    /// A hydraulic axis' pressure inputs: their scaling, and the actual values of the last
    /// sample.
    force: Option<(ForceScaling, ActualForce)>,
    enable: AnalogEnable,
    /// The encoder's raw word extended, from the first sample on.
    counter: Option<RawCounter>,
    /// The count of the previous sample (for the velocity).
    previous_count: i64,
    /// The actual position of the last sample (physical).
    actual: f64,
    /// The actual velocity of the last sample (physical, the count's change over the cycle).
    actual_velocity: f64,
    /// The enable request of the last command.
    request: bool,
    /// The enable DO decided with the last inputs.
    enable_do: bool,
    /// The simulated plant's switches (physical), read as digital inputs at the sample.
    plant: Plant,
    status: AnalogStatus,
    /// A hydraulic axis: the set position of the last command, the reference of its following
    /// error (the library's lag `fSetPos - fActPos`; the speed controller's balancing filter
    /// does not run for it).
    hyd_set_position: f64,
}

impl AnalogConnection {
    /// The connection with `params`, the plant's switches `plant`, the axis at physical
    /// position `p0`.
    pub fn new(params: AnalogParams, plant: Plant, p0: f64) -> Result<Self, AnalogConnectionError> {
        let controller = PositionController::new(params.controller, p0)
            .map_err(AnalogConnectionError::Params)?;
        let enable = AnalogEnable::new(params.enable_timeout_ns, params.ready)
            .map_err(AnalogConnectionError::Timeout)?;
        Ok(Self {
            params,
            controller,
            hydraulic: None,
            force: None,
            enable,
            counter: None,
            previous_count: 0,
            actual: p0,
            actual_velocity: 0.0,
            request: false,
            enable_do: false,
            plant,
            status: AnalogStatus::default(),
            hyd_set_position: p0,
        })
    }

    /// The connection of a hydraulic axis: the valve's output word comes from the library's
    /// position controller and Finish (`hydraulic`) on the axis' set position and set
    /// velocity, not from the speed controller of `params.controller` (whose cycle and
    /// balancing filter the connection still uses).
    pub fn hydraulic(
        params: AnalogParams,
        hydraulic: HydController,
        plant: Plant,
        p0: f64,
    ) -> Result<Self, AnalogConnectionError> {
        let mut c = Self::new(params, plant, p0)?;
        c.hydraulic = Some(hydraulic);
        Ok(c)
    }

    /// Reads the two pressure inputs of each sample with `scaling`
    /// (`MC_AxRtReadForceDiff_BkPlcMc`): [`AnalogConnection::actual_force`].
    pub fn with_pressure_inputs(
        mut self,
        scaling: ForceScaling,
    ) -> Result<Self, AnalogConnectionError> {
        scaling.check().map_err(AnalogConnectionError::Pressure)?;
        self.force = Some((scaling, ActualForce::default()));
        Ok(self)
    }

    /// The pressures and the force of the last sample; `None` without pressure inputs.
    pub fn actual_force(&self) -> Option<&ActualForce> {
        self.force.as_ref().map(|(_, a)| a)
    }

    /// The configuration.
    pub fn params(&self) -> &AnalogParams {
        &self.params
    }

    /// What the last cycle did.
    pub fn status(&self) -> &AnalogStatus {
        &self.status
    }

    /// The encoder's extended count, from the first sample on.
    pub fn count(&self) -> Option<i64> {
        self.counter.map(|c| c.count())
    }

    /// What the axis reads at `t` from sample `fb`: the actual position through the encoder's
    /// raw counter and scaling, the velocity from the count's change over the cycle, the
    /// balanced setpoint, the plant's switches at the actual position, and the handshake
    /// stepped with the last request and the ready DI.
    pub fn inputs(&mut self, t: i64, fb: &AnalogFeedback) -> DriveInputs {
        let scaling = &self.params.scaling;
        let (count, v) = match &mut self.counter {
            Some(c) => {
                let n = c.update(fb.encoder_raw);
                let dc = n.wrapping_sub(self.previous_count) as f64;
                (n, scaling.velocity(dc / self.params.controller.cycle()))
            }
            None => {
                // A signed start: an incremental encoder near 0 reads a small negative count
                // as negative. `raw_bits` was validated with the scaling.
                let c = RawCounter::new_signed(scaling.encoder().raw_bits, fb.encoder_raw)
                    .unwrap_or_else(|_| scaling.raw_counter(fb.encoder_raw));
                self.counter = Some(c);
                (c.count(), 0.0)
            }
        };
        self.previous_count = count;
        if let Some((s, a)) = &mut self.force {
            *a = s.read(fb.pressure_a, fb.pressure_b);
        }
        let p = scaling.position(count);
        let prev = std::mem::replace(&mut self.actual, p);
        self.actual_velocity = v;
        let out = self
            .enable
            .step(t, self.request, fb.ready, self.status.word == 0);
        self.enable_do = out.enable_do;
        self.status.enable = out.status;
        self.status.ready = fb.ready;
        DriveInputs {
            actual: Actual {
                p,
                v,
                balanced: if self.hydraulic.is_some() {
                    self.hyd_set_position
                } else {
                    self.controller.balanced()
                },
            },
            // The simulated plant latches the cam's edge and the zero mark exactly, as an
            // encoder's or a drive's measuring input would (homing modes 2, 3, 5, 8, 10).
            signals: AxisSignals::of_plant(&self.plant, prev, p),
            in_limitation: false,
            torque_actual: 0.0,
            state: self.enable.drive_state(),
        }
    }

    /// The drive's command for the axis's outputs of this cycle: the enable DO of the
    /// handshake, and while enabled with the enable requested the controller's speed setpoint
    /// (inverted with `Actor.InverseDirection`) as the output word; otherwise 0 and the
    /// controller rests at the setpoint. A fault reset has no channel on an analog drive: the
    /// drive is reset by removing its enable (inferred; the manual names only enable and ready).
    pub fn command(&mut self, out: &DriveOutputs) -> AnalogCommand {
        self.request = out.enable;
        let active = out.enable && self.enable.status() == AnalogEnableStatus::Enabled;
        let c = if self.hydraulic.is_some() {
            self.hydraulic_output(active, out)
        } else if active {
            self.controller.step(
                out.position,
                out.velocity,
                self.actual,
                out.position_controlled,
            )
        } else {
            self.controller.reset(out.position);
            ControllerOutput::default()
        };
        let sign = if self.params.scaling.mechanics().inverse_drive {
            -1.0
        } else {
            1.0
        };
        let normalized = sign * c.normalized;
        let words = match &self.hydraulic {
            Some(h) => h.params().drive.encode(normalized),
            None => ValveWords {
                word: output_word(normalized),
                ..ValveWords::default()
            },
        };
        let word = words.word;
        self.status = AnalogStatus {
            enable_do: self.enable_do,
            normalized,
            word,
            control_difference: c.control_difference,
            saturated: c.saturated,
            ..self.status
        };
        AnalogCommand {
            enable: self.enable_do,
            words,
        }
    }
}

impl AnalogConnection {
    /// The hydraulic controller's cycle: the lag from the set position of this cycle and the
    /// actual position of its sample, the axis' pressing output and zero compensation; nothing
    /// while the valve is not enabled (the I part cleared).
    fn hydraulic_output(&mut self, active: bool, out: &DriveOutputs) -> ControllerOutput {
        let dt = self.params.controller.cycle();
        let actual = self.actual;
        self.hyd_set_position = out.position;
        let Some(h) = self.hydraulic.as_mut() else {
            return ControllerOutput::default();
        };
        if !active || out.hydraulic.locked {
            h.reset();
            self.status.lag_ctrl_output = 0.0;
            return ControllerOutput::default();
        }
        let o = h.step(&HydControlInput {
            set_position: out.position,
            set_velocity: out.velocity,
            actual_position: actual,
            actual_velocity: self.actual_velocity,
            position_control: out.position_controlled,
            clamping_output: out.hydraulic.clamping_output,
            zero_compensation: out.hydraulic.zero_compensation,
            direct_output: out.hydraulic.direct_output,
            dt,
        });
        self.status.lag_ctrl_output = o.lag_ctrl_output;
        ControllerOutput {
            normalized: o.output,
            control_difference: out.position - actual,
            saturated: o.output.abs() >= 1.0,
        }
    }
}

/// An [`AnalogConnection`] that cannot be built.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum AnalogConnectionError {
    /// A controller parameter.
    Params(AnalogParamsError),
    /// The enable timeout.
    Timeout(InvalidReadyTimeout),
    /// A hydraulic axis' position controller or Finish parameter.
    Hydraulic(crate::hydraulic::finish::FinishError),
    /// A simulated valve and cylinder's parameter out of its range.
    Cylinder(super::cylinder_error::CylinderError),
    /// The scaling of a hydraulic axis' pressure inputs.
    Pressure(crate::hydraulic::pressure::PressureError),
}

impl fmt::Display for AnalogConnectionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Params(e) => write!(f, "{e}"),
            Self::Timeout(e) => write!(f, "analog drive: {e}"),
            Self::Hydraulic(e) => write!(f, "hydraulic axis: {e}"),
            Self::Cylinder(e) => write!(f, "valve and cylinder: {e}"),
            Self::Pressure(e) => write!(f, "pressure inputs: {e}"),
        }
    }
}

impl std::error::Error for AnalogConnectionError {}

/// The parameters of a simulated analog drive: a speed-controlled motor.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SimAnalogParams {
    /// Motor speed at 10 V (word 27648), 1/min (> 0): the drive's reference speed (SINAMICS
    /// p2000 for its analog input).
    #[doc(alias = "p2000")]
    pub reference_speed: f64,
    /// The drive's speed limit, 1/min (> 0).
    pub max_speed: f64,
    /// The speed loop as a first-order lag (s, 0..=[`MAX_TIME_CONSTANT`]).
    pub time_constant: f64,
    /// The ramp the drive brakes on without its enable or in a fault: time from the reference
    /// speed to standstill (s, > 0).
    pub ramp_down_time: f64,
    /// Time from the enable input to the ready output (s, 0..=[`MAX_TIME_CONSTANT`]).
    pub ready_delay: f64,
    /// Offset of the analog input (V, -10..=10): the drive runs at `offset / 10 V` of its
    /// reference speed with a 0 command.
    pub offset: f64,
    /// The motor's position at start (revolutions, finite).
    pub initial_revolutions: f64,
}

impl SimAnalogParams {
    /// A 3000/min drive with a 4 ms speed loop, 3300/min limit, 0.1 s stop ramp, 10 ms to
    /// ready, no offset, at revolution 0.
    pub const fn example() -> Self {
        Self {
            reference_speed: 3000.0,
            max_speed: 3300.0,
            time_constant: 0.004,
            ramp_down_time: 0.1,
            ready_delay: 0.01,
            offset: 0.0,
            initial_revolutions: 0.0,
        }
    }

    /// Checks every field; the first refused is named.
    pub fn validate(&self) -> Result<(), AnalogParamsError> {
        check("reference_speed", self.reference_speed, 0.0, true, f64::MAX)?;
        check("max_speed", self.max_speed, 0.0, true, f64::MAX)?;
        check(
            "time_constant",
            self.time_constant,
            0.0,
            false,
            MAX_TIME_CONSTANT,
        )?;
        check("ramp_down_time", self.ramp_down_time, 0.0, true, f64::MAX)?;
        check(
            "ready_delay",
            self.ready_delay,
            0.0,
            false,
            MAX_TIME_CONSTANT,
        )?;
        check(
            "offset",
            self.offset,
            -NOMINAL_VOLTAGE,
            false,
            NOMINAL_VOLTAGE,
        )?;
        check(
            "initial_revolutions",
            self.initial_revolutions,
            f64::MIN,
            false,
            f64::MAX,
        )
    }
}

/// A simulated analog drive with an encoder on its load: the motor's speed follows the analog
/// command as a first-order lag (`time_constant`) towards `command · reference_speed` (plus
/// the input offset), limited to `max_speed`; without its enable, or in a fault, it brakes on its
/// ramp (`ramp_down_time` from the reference speed) and its ready output is off. Ready comes
/// `ready_delay` after the enable. An injected fault drops ready and is latched until the
/// enable input is off and the cause is cleared.
///
/// The load moves by the mechanics (load gear, leadscrew, `Actor.InverseDirection`) of the
/// axis's [`Scaling`]; the encoder gives the load's position as its raw word (the count of
/// [`Scaling::count`], wrapping in `raw_bits`). Integration is exact for the piecewise-constant
/// command; nothing allocates.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SimAnalogDrive {
    params: SimAnalogParams,
    scaling: Scaling,
    /// Load units per motor revolution (signed by the drive's inversion).
    units_per_revolution: f64,
    /// Motor position (revolutions) and speed (revolutions/s).
    revolutions: f64,
    speed: f64,
    /// The latched command, the ready output and the fault latch.
    amplifier: Amplifier,
}

/// The process-data side of a simulated device on an analog output (a drive, a valve
/// amplifier): the command latched at the boundary, the ready output a delay after the enable
/// input, and a fault latched until its cause is gone and the enable input is off.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Amplifier {
    command: AnalogCommand,
    /// From the enable input to the ready output (s).
    ready_delay: f64,
    /// Time enabled without fault (s).
    enabled_for: f64,
    fault_latched: bool,
    fault_cause: bool,
}

impl Amplifier {
    /// Not enabled, no fault, ready `ready_delay` seconds after its enable input.
    pub fn new(ready_delay: f64) -> Self {
        Self {
            command: AnalogCommand::default(),
            ready_delay,
            enabled_for: 0.0,
            fault_latched: false,
            fault_cause: false,
        }
    }

    /// Latches the command of the boundary; an enable removed with the cause gone
    /// acknowledges a fault.
    pub fn exchange(&mut self, command: &AnalogCommand) {
        self.command = *command;
        if !command.enable && !self.fault_cause {
            self.fault_latched = false;
        }
    }

    /// Whether it drives its output: enabled and not in fault.
    pub fn on(&self) -> bool {
        self.command.enable && !self.fault_latched
    }

    /// `dt` seconds pass (after the device has run them).
    pub fn advance(&mut self, dt: f64) {
        self.enabled_for = if self.on() {
            self.enabled_for + dt
        } else {
            0.0
        };
    }

    /// The ready output now.
    pub fn ready(&self) -> bool {
        self.on() && self.enabled_for >= self.ready_delay && self.enabled_for > 0.0
    }

    /// The latched command.
    pub fn command(&self) -> &AnalogCommand {
        &self.command
    }

    /// A fault: ready drops. Latched until the cause is cleared and the enable input is off.
    pub fn inject_fault(&mut self) {
        self.fault_cause = true;
        self.fault_latched = true;
    }

    /// The cause of the fault is gone (the latch stays until the enable input is off).
    pub fn clear_fault_cause(&mut self) {
        self.fault_cause = false;
    }

    /// Whether it is in fault.
    pub fn in_fault(&self) -> bool {
        self.fault_latched
    }
}

impl SimAnalogDrive {
    /// A drive at rest with `params`, its load and encoder by `scaling`. Refuses parameters out
    /// of range.
    pub fn new(params: SimAnalogParams, scaling: Scaling) -> Result<Self, AnalogParamsError> {
        params.validate()?;
        let m = scaling.mechanics();
        let load = m.leadscrew_pitch.unwrap_or(DEGREES_PER_REVOLUTION);
        let sign = if m.inverse_drive { -1.0 } else { 1.0 };
        let units_per_revolution =
            sign * load * f64::from(m.load_gear_denominator) / f64::from(m.load_gear_numerator);
        Ok(Self {
            params,
            scaling,
            units_per_revolution,
            revolutions: params.initial_revolutions,
            speed: 0.0,
            amplifier: Amplifier::new(params.ready_delay),
        })
    }

    /// The motor revolutions that put the load at `position` (units, physical).
    pub fn revolutions_at(scaling: &Scaling, position: f64) -> f64 {
        let m = scaling.mechanics();
        let load = m.leadscrew_pitch.unwrap_or(DEGREES_PER_REVOLUTION);
        let sign = if m.inverse_drive { -1.0 } else { 1.0 };
        sign * position * f64::from(m.load_gear_numerator)
            / (load * f64::from(m.load_gear_denominator))
    }

    /// Latches the command of the boundary (its effect starts now).
    pub fn exchange(&mut self, command: &AnalogCommand) {
        self.amplifier.exchange(command);
    }

    /// Runs `dt_ns` with the latched command.
    pub fn advance(&mut self, dt_ns: i64) {
        let dt = dt_ns.max(0) as f64 * 1e-9;
        let reference = self.params.reference_speed / 60.0;
        if self.amplifier.on() {
            let volts = word_to_normalized(self.amplifier.command().words.word) * NOMINAL_VOLTAGE
                + self.params.offset;
            let limit = self.params.max_speed / 60.0;
            let target = (volts / NOMINAL_VOLTAGE * reference).clamp(-limit, limit);
            let tau = self.params.time_constant;
            let e = decay(dt, tau);
            self.revolutions += target * dt + (self.speed - target) * tau * (1.0 - e);
            self.speed = target + (self.speed - target) * e;
        } else {
            let deceleration = reference / self.params.ramp_down_time;
            let stop = self.speed.abs() / deceleration;
            if stop <= dt {
                self.revolutions += 0.5 * self.speed * stop;
                self.speed = 0.0;
            } else {
                let v1 = self.speed - (deceleration * dt).copysign(self.speed);
                self.revolutions += 0.5 * (self.speed + v1) * dt;
                self.speed = v1;
            }
        }
        self.amplifier.advance(dt);
    }

    /// The process image inputs now: the ready output and the encoder's raw word.
    pub fn feedback(&self) -> AnalogFeedback {
        AnalogFeedback {
            ready: self.amplifier.ready(),
            // The low 32 bits; the counter masks them to `raw_bits`.
            encoder_raw: self.scaling.count(self.position()) as u32,
            pressure_a: 0,
            pressure_b: 0,
        }
    }

    /// The load's position (units, physical).
    pub fn position(&self) -> f64 {
        self.revolutions * self.units_per_revolution
    }

    /// The load's velocity (units/s).
    pub fn velocity(&self) -> f64 {
        self.speed * self.units_per_revolution
    }

    /// The motor speed (1/min).
    pub fn speed(&self) -> f64 {
        self.speed * 60.0
    }

    /// The latched command, the ready output and the fault latch. A fault (e.g. overcurrent,
    /// [`Amplifier::inject_fault`]) drops ready and the drive brakes on its ramp.
    pub fn amplifier(&self) -> &Amplifier {
        &self.amplifier
    }

    /// The same, to inject or clear a fault.
    pub fn amplifier_mut(&mut self) -> &mut Amplifier {
        &mut self.amplifier
    }
}
