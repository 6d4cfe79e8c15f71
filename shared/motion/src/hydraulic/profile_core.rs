//! What the two set value generators of a hydraulic axis share: their parameters, states,
//! errors and output (re-exported by [`super::generator`]), the set values, the feed enables
//! and the stops (`MC_Stop_BkPlcMc`, `MC_EmergencyStop_BkPlcMc`, a setpoint taken
//! over), and the one interface the axis runs either through ([`ProfileGenerator`]).
//!
//! The displacement-based generator ([`super::generator::CtrlBasedGenerator`]) and the
//! jerk-based one ([`super::jerk_generator::JerkBasedGenerator`]) differ in how a move and a stop
//! ramp run (their `advance` and `begin_stop`); what a command does to the state, and what a cycle
//! hands to the controller, is the same and lives here once.
//!
//! Pure: no IO, no clock, no allocation.

use crate::catalog::hyd_error::HydErrorCode;

/// The generator's state, as the library names it (`E_TcHydAxState`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum HydState {
    /// `iTcHydStateIdle`: not moving; the set position is the target.
    Idle,
    /// `iTcHydStateTcAccP` / `TcAccM`: the time-controlled start ramp.
    TcAcc,
    /// `iTcHydStateConstVeloP` / `ConstVeloM`: travel at the command's velocity.
    ConstVelo,
    /// `iTcHydStatePcDecP` / `PcDecM`: the displacement-controlled braking ramp.
    PcDec,
    /// `iTcHydStateCreepVeloP` / `CreepVeloM`: creep to the target.
    CreepVelo,
    /// `iTcHydStateTcDecP` / `TcDecM`: a regular stop with `fStopRamp`.
    TcDec,
    /// `iTcHydStateEmergencyBreak`: an emergency stop with `fEmergencyRamp`.
    EmergencyBreak,
    /// `iTcHydStateFeedStopPos` / `FeedStopNeg`: an intermediate stop with `fStopRamp` for a
    /// missing feed enable of the direction (`Enable_Positive` / `Enable_Negative` of
    /// MC_Power_BkPlcMc); the move waits, then goes on when the enable returns.
    FeedStop,
}

impl HydState {
    /// The library's name of the state in direction `positive`.
    pub const fn name(self, positive: bool) -> &'static str {
        match (self, positive) {
            (Self::Idle, _) => "iTcHydStateIdle",
            (Self::TcAcc, true) => "iTcHydStateTcAccP",
            (Self::TcAcc, false) => "iTcHydStateTcAccM",
            (Self::ConstVelo, true) => "iTcHydStateConstVeloP",
            (Self::ConstVelo, false) => "iTcHydStateConstVeloM",
            (Self::PcDec, true) => "iTcHydStatePcDecP",
            (Self::PcDec, false) => "iTcHydStatePcDecM",
            (Self::CreepVelo, true) => "iTcHydStateCreepVeloP",
            (Self::CreepVelo, false) => "iTcHydStateCreepVeloM",
            (Self::TcDec, true) => "iTcHydStateTcDecP",
            (Self::TcDec, false) => "iTcHydStateTcDecM",
            (Self::EmergencyBreak, _) => "iTcHydStateEmergencyBreak",
            (Self::FeedStop, true) => "iTcHydStateFeedStopPos",
            (Self::FeedStop, false) => "iTcHydStateFeedStopNeg",
        }
    }
}

/// The target approach of one direction (members of `ST_TcHydAxParam`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Approach {
    /// `fCreepSpeedP/M` (mm/s, > 0).
    pub creep_speed: f64,
    /// `fCreepDistanceP/M` (mm, >= 0).
    pub creep_distance: f64,
    /// `fBrakeDistanceP/M` (mm, >= 0).
    pub brake_distance: f64,
    /// `fBrakeDeadTimeP/M` (s, >= 0).
    pub brake_dead_time: f64,
}

/// The generator's parameters (members of `ST_TcHydAxParam`; defaults as the library's).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct GeneratorParams {
    /// `fRefVelo` (mm/s, > 0).
    pub ref_velo: f64,
    /// `fMaxVelo` (mm/s, > 0; above `fRefVelo` it is `fRefVelo`).
    pub max_velo: f64,
    /// `fAcc` (mm/s², > 0).
    pub acc: f64,
    /// `fMaxAcc` (mm/s², > 0).
    pub max_acc: f64,
    /// `fDec` (mm/s², > 0).
    pub dec: f64,
    /// `fMaxDec` (mm/s², > 0).
    pub max_dec: f64,
    /// The approach of the positive direction (and of both without asymmetrical targeting).
    pub approach_p: Approach,
    /// The approach of the negative direction, with [`GeneratorParams::asymmetrical`].
    pub approach_m: Approach,
    /// `bAsymmetricalTargeting`.
    pub asymmetrical: bool,
    /// `fStopRamp` (s, > 0): a stop's ramp from `fRefVelo` to 0.
    pub stop_ramp: f64,
    /// `fEmergencyRamp` (s, > 0): an emergency stop's ramp from `fRefVelo` to 0.
    pub emergency_ramp: f64,
    /// `fTargetClamping` (V, 0..10): when greater than 0, at the target this output is given
    /// with the sign of the approach and the position control is suppressed (a pressing axis).
    pub target_clamping: f64,
    /// `fReposDistance` (mm, >= 0): when greater than 0, an idle axis further than this from
    /// its target starts a positioning to it again by itself.
    pub repos_distance: f64,
}

impl Default for GeneratorParams {
    /// The library's defaults: `fRefVelo` and `fMaxVelo` 500 mm/s, `fAcc`/`fDec` 2000 mm/s²,
    /// `fMaxAcc`/`fMaxDec` 500 mm/s², creep 80 mm/s from 1.0 mm, brake distance 0.1 mm, no dead
    /// time, stop ramp 1.0 s, emergency ramp 0.1 s, no target clamping, no repositioning.
    fn default() -> Self {
        let approach = Approach {
            creep_speed: 80.0,
            creep_distance: 1.0,
            brake_distance: 0.1,
            brake_dead_time: 0.0,
        };
        Self {
            ref_velo: 500.0,
            max_velo: 500.0,
            acc: 2000.0,
            max_acc: 500.0,
            dec: 2000.0,
            max_dec: 500.0,
            approach_p: approach,
            approach_m: approach,
            asymmetrical: false,
            stop_ramp: 1.0,
            emergency_ramp: 0.1,
            target_clamping: 0.0,
            repos_distance: 0.0,
        }
    }
}

/// Why the generator refused parameters or a command (nothing changes).
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum GeneratorError {
    /// A parameter or a command's value that must be finite and above 0 (or at least 0).
    Invalid {
        /// Its name (the library's for parameters; `Position`, `Velocity`, `Acceleration`,
        /// `Deceleration` for a command's inputs).
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A move in a direction whose feed enable is missing (`positive`: the positive one).
    FeedEnable {
        /// The direction of the move.
        positive: bool,
    },
}

impl GeneratorError {
    /// The library's error code: `dwTcHydErrCdRefVelo`, `dwTcHydErrCdSetVelo` (a command's
    /// velocity, `fMaxVelo`), `dwTcHydErrCdAcc`, `dwTcHydErrCdDec`, else
    /// `dwTcHydAdsErrIllegalValue`.
    pub fn code(&self) -> HydErrorCode {
        let name = match *self {
            Self::Invalid { name, .. } => name,
            Self::FeedEnable { positive: true } => return HydErrorCode::POS_FD_ENA,
            Self::FeedEnable { positive: false } => return HydErrorCode::NEG_FD_ENA,
        };
        match name {
            "fRefVelo" => HydErrorCode::REF_VELO,
            "Velocity" | "fMaxVelo" => HydErrorCode::SET_VELO,
            "Acceleration" | "fAcc" | "fMaxAcc" => HydErrorCode::ACC,
            "Deceleration" | "fDec" | "fMaxDec" => HydErrorCode::DEC,
            _ => HydErrorCode::ILLEGAL_VALUE,
        }
    }
}

impl core::fmt::Display for GeneratorError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::Invalid { name, value } => write!(f, "{name} = {value} is not valid here"),
            Self::FeedEnable { positive } => write!(
                f,
                "no feed enable for the {} direction (Enable_{})",
                if positive { "positive" } else { "negative" },
                if positive { "Positive" } else { "Negative" }
            ),
        }
    }
}

impl std::error::Error for GeneratorError {}

/// One cycle of the generator's output.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Setpoint {
    /// `fSetVelo` (mm/s): the control value.
    pub velocity: f64,
    /// `fSetPos` (mm): the set position (the integral of the set velocity while moving, the
    /// target when idle).
    pub position: f64,
    /// The state after the cycle.
    pub state: HydState,
    /// The direction of the motion (`true`: positive).
    pub positive: bool,
    /// `fClampingOutput` (V): at the target with `fTargetClamping`, that output with the sign
    /// of the approach; 0 otherwise.
    pub clamping_output: f64,
    /// The position controller acts (idle at the target without target clamping; the library's
    /// displacement mode closes the loop only at standstill).
    pub position_control: bool,
}

/// The state both generators keep alike.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct GeneratorCore {
    /// The parameters.
    pub(super) p: GeneratorParams,
    /// `E_TcHydAxState`.
    pub(super) state: HydState,
    /// The direction of the motion (`true`: positive).
    pub(super) positive: bool,
    /// `fSetVelo` (mm/s).
    pub(super) velocity: f64,
    /// The set acceleration along the motion (mm/s², signed; the displacement-based generator
    /// keeps 0).
    pub(super) acceleration: f64,
    /// `fSetPos` (mm).
    pub(super) position: f64,
    /// `fTargetPos` (mm): the target of the running or last move.
    pub(super) target: f64,
    /// A move in the other direction waits for the stop ramp.
    pub(super) reverse_pending: bool,
    /// The deceleration of the running stop (`TcDec`, mm/s²): `fRefVelo / fStopRamp`, or the
    /// stop command's.
    pub(super) stop_dec: f64,
    /// The feed enables of the positive and the negative direction.
    pub(super) feed: [bool; 2],
    /// Automatic starts by `fReposDistance`.
    pub(super) repositioned: u64,
}

impl GeneratorCore {
    /// Idle at position `x` with parameters `p` (checked by the generator).
    pub(super) fn idle_at(p: GeneratorParams, x: f64) -> Self {
        Self {
            p,
            state: HydState::Idle,
            positive: true,
            velocity: 0.0,
            acceleration: 0.0,
            position: x,
            target: x,
            reverse_pending: false,
            stop_dec: p.ref_velo / p.stop_ramp,
            feed: [true; 2],
            repositioned: 0,
        }
    }

    /// The deceleration of a regular stop, `fRefVelo / fStopRamp` (mm/s²).
    pub(super) fn stop_ramp_dec(&self) -> f64 {
        self.p.ref_velo / self.p.stop_ramp
    }

    /// The deceleration of an emergency stop, `fRefVelo / fEmergencyRamp` (mm/s²).
    pub(super) fn emergency_dec(&self) -> f64 {
        self.p.ref_velo / self.p.emergency_ramp
    }

    /// `+1` in the positive direction, `-1` in the negative one.
    pub(super) fn sign(&self) -> f64 {
        if self.positive {
            1.0
        } else {
            -1.0
        }
    }

    /// The output of the cycle from the state after it.
    fn setpoint(&self) -> Setpoint {
        let idle = self.state == HydState::Idle;
        Setpoint {
            velocity: self.velocity,
            position: self.position,
            state: self.state,
            positive: self.positive,
            clamping_output: if idle && self.p.target_clamping > 0.0 {
                self.p.target_clamping.copysign(self.sign())
            } else {
                0.0
            },
            position_control: idle && self.p.target_clamping == 0.0,
        }
    }
}

/// Checks a move command's inputs: `target` finite, `velocity` finite and above 0, each of
/// `at_least_0` finite and at least 0 (names as [`GeneratorError::Invalid`] gives them).
pub(super) fn check_move(
    target: f64,
    velocity: f64,
    at_least_0: &[(&'static str, f64)],
) -> Result<(), GeneratorError> {
    for (name, value) in [("Position", target), ("Velocity", velocity)] {
        if !value.is_finite() || (name == "Velocity" && value <= 0.0) {
            return Err(GeneratorError::Invalid { name, value });
        }
    }
    for &(name, value) in at_least_0 {
        if !(value.is_finite() && value >= 0.0) {
            return Err(GeneratorError::Invalid { name, value });
        }
    }
    Ok(())
}

/// A set value generator of a hydraulic axis: what differs between the profiles is how a cycle
/// advances and how a stop ramp begins; the commands and the cycle's output are common.
pub trait ProfileGenerator {
    /// The shared state.
    fn core(&self) -> &GeneratorCore;
    /// The shared state, to change.
    fn core_mut(&mut self) -> &mut GeneratorCore;
    /// The state machine of one cycle of `dt` seconds (inputs already checked finite).
    fn advance(&mut self, dt: f64, actual: f64, actual_velocity: f64);
    /// A stop ramp to standstill in `state` (`TcDec`, `EmergencyBreak`) with deceleration
    /// `dec`, from the present set values.
    fn begin_stop(&mut self, state: HydState, dec: f64);
    /// The remaining distance at which the braking ramp of the running move begins.
    fn brake_point(&self) -> f64;

    /// The parameters.
    fn params(&self) -> &GeneratorParams {
        &self.core().p
    }

    /// The state.
    fn state(&self) -> HydState {
        self.core().state
    }

    /// The target of the running or last move (`fTargetPos`).
    fn target(&self) -> f64 {
        self.core().target
    }

    /// Automatic starts by `fReposDistance` since creation.
    fn repositioned(&self) -> u64 {
        self.core().repositioned
    }

    /// The feed enables of the two directions (`Enable_Positive`, `Enable_Negative` of
    /// MC_Power_BkPlcMc, the `dwTcHydDcDwFdPosEna` / `FdNegEna` bits). A move whose direction
    /// loses its enable makes an intermediate stop with `fStopRamp` and waits
    /// ([`HydState::FeedStop`]); it goes on, from the start ramp, when the enable returns. A
    /// move started in a direction without enable is refused (`dwTcHydErrCdPosFdEna` /
    /// `NegFdEna`; inferred: the library checks it at the start).
    fn set_feed_enables(&mut self, positive: bool, negative: bool) {
        self.core_mut().feed = [positive, negative];
    }

    /// Whether direction `positive` has its feed enable.
    fn feed_enabled(&self, positive: bool) -> bool {
        self.core().feed[usize::from(!positive)]
    }

    /// A regular stop (`MC_Stop_BkPlcMc`): the set velocity ramps to 0 with `fStopRamp`.
    fn stop(&mut self) {
        let dec = self.core().stop_ramp_dec();
        self.stop_with(dec);
    }

    /// A stop with the command's `Deceleration` (mm/s², `MC_Stop_BkPlcMc` from V3.0.5; a
    /// value that is not finite and above 0 takes `fStopRamp`'s): the set velocity ramps to 0
    /// with it (`iTcHydStateTcDecP/M`). Idle or in an emergency stop, nothing changes.
    fn stop_with(&mut self, deceleration: f64) {
        let c = self.core_mut();
        if c.state != HydState::Idle && c.state != HydState::EmergencyBreak {
            let dec = if deceleration.is_finite() && deceleration > 0.0 {
                deceleration
            } else {
                c.stop_ramp_dec()
            };
            c.reverse_pending = false;
            self.begin_stop(HydState::TcDec, dec);
        }
    }

    /// An emergency stop: the set velocity ramps to 0 with `fEmergencyRamp`.
    fn emergency_stop(&mut self) {
        let c = self.core_mut();
        if c.state != HydState::Idle {
            c.reverse_pending = false;
            let dec = c.emergency_dec();
            self.begin_stop(HydState::EmergencyBreak, dec);
        }
    }

    /// Takes over a setpoint another generator produced (set position and set velocity,
    /// mm and mm/s; the acceleration taken as 0), as the axis does when a positioning follows a
    /// motion the generator did not run: the next move starts from it without a step. An idle
    /// generator with a velocity other than 0 ramps it down with the stop ramp until a move is
    /// given. Values that are not finite change nothing.
    fn take_over(&mut self, position: f64, velocity: f64) {
        if !(position.is_finite() && velocity.is_finite()) {
            return;
        }
        let c = self.core_mut();
        c.position = position;
        c.velocity = velocity;
        c.acceleration = 0.0;
        c.reverse_pending = false;
        if velocity == 0.0 {
            c.state = HydState::Idle;
            c.target = position;
        } else {
            c.positive = velocity > 0.0;
            let dec = c.stop_ramp_dec();
            self.begin_stop(HydState::TcDec, dec);
        }
    }

    /// One cycle of `dt` seconds with the actual position `actual` and actual velocity
    /// `actual_velocity` (for the dead-time term of the braking distance). Inputs that are not
    /// finite (or `dt` not above 0) advance nothing: the last cycle's setpoint is given again.
    fn step(&mut self, dt: f64, actual: f64, actual_velocity: f64) -> Setpoint {
        if dt.is_finite() && dt > 0.0 && actual.is_finite() && actual_velocity.is_finite() {
            self.advance(dt, actual, actual_velocity);
        }
        self.core().setpoint()
    }
}
