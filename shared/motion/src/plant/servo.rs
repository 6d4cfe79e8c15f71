//! A simulated CiA 402 servo drive: the device state machine of the IEC 61800-7-201 (CiA 402)
//! drive profile in front of a motor with load inertia, friction, a torque limit and the drive's
//! own control loops, speaking the cyclic synchronous PDOs ([`DriveCommand`] in,
//! [`DriveFeedback`] out), so that an axis drives it exactly as it drives a real drive.
//!
//! # Cycle
//!
//! [`SimServo::exchange`] latches the RxPDO at the cycle boundary and steps the device state
//! machine once with its controlword (so one transition per cycle, like a drive that handles its
//! controlword at SYNC0). [`SimServo::advance`] integrates the mechanics over the cycle.
//! [`SimServo::feedback`] is the TxPDO sampled at the next boundary. Time is an input; nothing
//! allocates after [`SimServo::new`].
//!
//! # Model
//!
//! - Mechanics (motor side): `J ω' = τ − b ω − c sgn(ω)` with inertia `J`, viscous friction `b`
//!   and coulomb friction `c` (stiction: at rest the motor stays at rest while `|τ| <= c`).
//!   Within a sub-step the torque is constant and the equation is solved in closed form,
//!   splitting where the velocity reaches zero, so the motion is exact for the sampled torque
//!   (no integration error; only floating-point rounding) and deterministic.
//! - Control (in operation enabled), sampled every sub-step: CSP is a P position loop (`kv`)
//!   on the set-point interpolated linearly over the interpolation period (0x60C2 = the cycle)
//!   with the velocity offset 0x60B1 as feedforward, over a PI velocity loop (gain
//!   `velocity_loop_gain`, integral time `velocity_loop_integral_time`, conditional
//!   integration against wind-up) with the torque offset 0x60B2 as feedforward; CSV is the
//!   velocity loop on target velocity 0x60FF + velocity offset; CST applies target torque
//!   0x6071 + torque offset. The torque is limited to the drive's own limit or max torque
//!   0x6072, whichever is smaller.
//! - Outside operation enabled the motor has no torque and coasts, except in quick stop active
//!   (0x605A: options 1, 2, 5, 6 brake with the torque that decelerates the configured inertia
//!   at `quick_stop_deceleration` after friction; 3, 4, 7, 8 brake at the torque limit; 0
//!   coasts) and in fault reaction active (braking as option 2; inferred: fault reaction
//!   option code 0x605E = 2, "quick stop ramp"). The braking torque opposes the motion like
//!   friction, so the motor stops exactly at zero velocity; the reaction has then finished and
//!   the next exchange takes transition 12 or 14.
//! - Sub-steps: at most 62.5 µs (a 16 kHz velocity loop), and short enough that the sampled
//!   loops are well inside their stability limit: at most 1/20 of `J / velocity_loop_gain`, of
//!   `1 / kv` and of the integral time.
//! - Position: continuous internally (increments, f64); position actual 0x6064 is the number
//!   of whole increments passed (floor, as a counter counts), wrapped as a two's-complement
//!   32-bit counter. CSP target positions are unwrapped the same way (each relative to the one
//!   before), so a motion runs across the wrap without a jump.
//! - Faults: an injected fault cause ([`SimServo::inject_fault`]) or the drive's own
//!   following-error fault 0x8611 (|position demand − actual| > following error window 0x6065
//!   in CSP, checked at the end of each cycle) takes transition 13 at the next exchange, with
//!   the error code 0x603F set; the code clears at the fault reset (transition 15).
//! - Touch probes 0x60B8..0x60BD (two probes; sources: the probe input, fed by
//!   [`SimServo::probe_edge`], and the encoder zero pulse, one per revolution at
//!   `zero_pulse_offset`). An edge latches the position at its exact instant within the cycle.
//!
//! Not modelled (inferred simplifications): the halt bit 8 (ignored in the cyclic modes, where
//! the controller owns the trajectory), the following error time-out 0x6066 (the window trips
//! at once), the slow-down ramp 0x6084 (options 1 and 5 use the quick stop deceleration), touch
//! probe sources other than the input and the zero pulse (they latch nothing), and any reaction
//! of the drive to its own limit switch inputs (the controller's hardware limit monitoring
//! reacts, S7-1500T Motion Control V4.0 function manual, 4.4 "Hardware limit switches").

use core::f64::consts::TAU;
use core::fmt;

use super::cia402::{
    statusword, touch_probe, Cia402State, DeviceInputs, DeviceStateMachine, DriveCommand,
    DriveFeedback, ModeOfOperation, QuickStopOption, Transition,
};

/// Error code 0x603F of the drive's own following-error fault.
#[doc(alias = "0x8611")]
pub const FOLLOWING_ERROR_CODE: u16 = 0x8611;

/// The longest sub-step (ns): a 16 kHz velocity loop.
const MAX_SUBSTEP_NS: i64 = 62_500;
/// The shortest sub-step a parameter set may need (ns); stiffer sets are refused.
const MIN_SUBSTEP_NS: i64 = 1_000;
/// Sub-steps per closed-loop time constant (or integral time) at least.
const SAMPLES_PER_TIME_CONSTANT: f64 = 20.0;
/// How many probe input edges can wait for the next [`SimServo::advance`].
pub const PROBE_EDGE_CAPACITY: usize = 8;

/// The parameters of a [`SimServo`]. All quantities are on the motor side.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ServoParams {
    /// The cycle and interpolation period 0x60C2 (ns, > 0).
    #[doc(alias = "0x60C2")]
    pub cycle_ns: i64,
    /// Encoder increments per motor revolution (> 0).
    #[doc(alias = "0x608F")]
    pub increments_per_revolution: u32,
    /// Rated torque 0x6076 (N·m, > 0): the reference of every per mille torque value.
    #[doc(alias = "0x6076")]
    pub rated_torque: f64,
    /// The drive's own torque limit (per mille of the rated torque, > 0).
    #[doc(alias = "0x6072")]
    pub max_torque_per_mille: u16,
    /// Motor inertia plus the load inertia reflected to the motor (kg·m², > 0).
    pub inertia: f64,
    /// Viscous friction (N·m·s/rad, >= 0).
    pub viscous_friction: f64,
    /// Coulomb friction (N·m, >= 0).
    pub coulomb_friction: f64,
    /// Position loop gain in CSP (1/s, >= 0).
    pub kv: f64,
    /// Velocity loop proportional gain (N·m·s/rad, > 0).
    pub velocity_loop_gain: f64,
    /// Velocity loop integral time (s, >= 0; 0 = no integral action).
    pub velocity_loop_integral_time: f64,
    /// Deceleration of the quick stop and fault reactions (rad/s², > 0).
    #[doc(alias = "0x6085")]
    pub quick_stop_deceleration: f64,
    /// Quick stop option code 0x605A.
    #[doc(alias = "0x605A")]
    pub quick_stop_option: QuickStopOption,
    /// Following error window 0x6065 (increments, > 0; `u32::MAX` switches the monitoring off,
    /// as the profile defines for 0xFFFFFFFF).
    #[doc(alias = "0x6065")]
    pub following_error_window: u32,
    /// Where the encoder zero pulse is within a revolution (increments, below
    /// `increments_per_revolution`): pulses at `zero_pulse_offset + k · increments_per_revolution`.
    pub zero_pulse_offset: u32,
    /// The motor position at power-up (increments; finite, |value| <= 2^52), as an absolute
    /// encoder would report it.
    pub initial_position: f64,
}

impl ServoParams {
    /// A plausible small servo (a 400 W class motor with a load of three times its inertia)
    /// with a 20-bit encoder, for the given cycle: rated torque 1.27 N·m, limit 300 %, inertia
    /// 1e-4 kg·m², velocity loop bandwidth 1000 rad/s, Kv 100 1/s, quick stop 2000 rad/s²
    /// (option 2), following error window a quarter revolution.
    pub const fn example(cycle_ns: i64) -> Self {
        Self {
            cycle_ns,
            increments_per_revolution: 1 << 20,
            rated_torque: 1.27,
            max_torque_per_mille: 3000,
            inertia: 1e-4,
            viscous_friction: 1e-4,
            coulomb_friction: 0.02,
            kv: 100.0,
            velocity_loop_gain: 0.1,
            velocity_loop_integral_time: 0.01,
            quick_stop_deceleration: 2000.0,
            quick_stop_option: QuickStopOption::QuickStopRamp,
            following_error_window: 1 << 18,
            zero_pulse_offset: 0,
            initial_position: 0.0,
        }
    }

    /// Checks every field; returns the sub-step (ns) the model integrates with.
    fn validate(&self) -> Result<i64, ServoParamsError> {
        use ServoParamsProblem as P;
        let fail = |field, problem| Err(ServoParamsError { field, problem });
        if self.cycle_ns <= 0 {
            return fail("cycle_ns", P::NotPositive);
        }
        if self.increments_per_revolution == 0 {
            return fail("increments_per_revolution", P::NotPositive);
        }
        if self.max_torque_per_mille == 0 {
            return fail("max_torque_per_mille", P::NotPositive);
        }
        if self.following_error_window == 0 {
            return fail("following_error_window", P::NotPositive);
        }
        if self.zero_pulse_offset >= self.increments_per_revolution {
            return fail("zero_pulse_offset", P::OutOfRange);
        }
        positive("rated_torque", self.rated_torque)?;
        positive("inertia", self.inertia)?;
        non_negative("viscous_friction", self.viscous_friction)?;
        non_negative("coulomb_friction", self.coulomb_friction)?;
        non_negative("kv", self.kv)?;
        positive("velocity_loop_gain", self.velocity_loop_gain)?;
        non_negative(
            "velocity_loop_integral_time",
            self.velocity_loop_integral_time,
        )?;
        positive("quick_stop_deceleration", self.quick_stop_deceleration)?;
        if !self.initial_position.is_finite() {
            return fail("initial_position", P::NotFinite);
        }
        if self.initial_position.abs() > (1u64 << 52) as f64 {
            return fail("initial_position", P::OutOfRange);
        }
        self.substep_ns()
    }

    /// The sub-step: the shortest of 62.5 µs and 1/20 of each loop's time constant.
    fn substep_ns(&self) -> Result<i64, ServoParamsError> {
        let mut substep = MAX_SUBSTEP_NS as f64;
        let mut binding = "";
        let constraints = [
            ("velocity_loop_gain", self.inertia / self.velocity_loop_gain),
            (
                "kv",
                if self.kv > 0.0 {
                    1.0 / self.kv
                } else {
                    f64::INFINITY
                },
            ),
            (
                "velocity_loop_integral_time",
                if self.velocity_loop_integral_time > 0.0 {
                    self.velocity_loop_integral_time
                } else {
                    f64::INFINITY
                },
            ),
        ];
        for (field, time_constant) in constraints {
            let h = time_constant / SAMPLES_PER_TIME_CONSTANT * 1e9;
            if h < substep {
                substep = h;
                binding = field;
            }
        }
        if substep < MIN_SUBSTEP_NS as f64 {
            return Err(ServoParamsError {
                field: binding,
                problem: ServoParamsProblem::TooStiff,
            });
        }
        Ok(substep.floor() as i64)
    }
}

fn positive(field: &'static str, x: f64) -> Result<(), ServoParamsError> {
    let problem = if !x.is_finite() {
        ServoParamsProblem::NotFinite
    } else if x <= 0.0 {
        ServoParamsProblem::NotPositive
    } else {
        return Ok(());
    };
    Err(ServoParamsError { field, problem })
}

fn non_negative(field: &'static str, x: f64) -> Result<(), ServoParamsError> {
    let problem = if !x.is_finite() {
        ServoParamsProblem::NotFinite
    } else if x < 0.0 {
        ServoParamsProblem::Negative
    } else {
        return Ok(());
    };
    Err(ServoParamsError { field, problem })
}

/// What is wrong with a [`ServoParams`] field.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum ServoParamsProblem {
    /// Must be positive.
    NotPositive,
    /// Must be zero or positive.
    Negative,
    /// Must be a finite number.
    NotFinite,
    /// Outside its range (zero pulse offset: below the increments per revolution; initial
    /// position: |value| <= 2^52).
    OutOfRange,
    /// The loop would need sub-steps shorter than 1 µs to be simulated stably.
    TooStiff,
}

impl fmt::Display for ServoParamsProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NotPositive => "must be positive",
            Self::Negative => "must be zero or positive",
            Self::NotFinite => "must be a finite number",
            Self::OutOfRange => "is out of range",
            Self::TooStiff => "makes the loop too stiff to simulate (sub-steps below 1 µs)",
        })
    }
}

/// A [`ServoParams`] field that is not acceptable: which one, and why.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct ServoParamsError {
    /// The field's name in [`ServoParams`].
    pub field: &'static str,
    /// What is wrong with it.
    pub problem: ServoParamsProblem,
}

impl fmt::Display for ServoParamsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "simulated servo: {} {}", self.field, self.problem)
    }
}

impl std::error::Error for ServoParamsError {}

/// A test input the simulated servo refuses (nothing changes).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum SimServoError {
    /// The touch probe is not 1 or 2.
    NoSuchProbe {
        /// The probe that was given.
        probe: u8,
    },
    /// A probe edge before the start of the coming cycle.
    NegativeEdgeOffset {
        /// The offset that was given (ns).
        offset_ns: i64,
    },
    /// [`PROBE_EDGE_CAPACITY`] edges are already waiting.
    ProbeEdgeQueueFull,
    /// Error code 0 means "no error"; a fault needs a code.
    NoErrorCode,
}

impl fmt::Display for SimServoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoSuchProbe { probe } => write!(f, "touch probe {probe} does not exist (1 or 2)"),
            Self::NegativeEdgeOffset { offset_ns } => {
                write!(
                    f,
                    "probe edge offset {offset_ns} ns is before the coming cycle"
                )
            }
            Self::ProbeEdgeQueueFull => {
                write!(f, "more than {PROBE_EDGE_CAPACITY} probe edges waiting")
            }
            Self::NoErrorCode => f.write_str("error code 0x0000 means no error; give a fault code"),
        }
    }
}

impl std::error::Error for SimServoError {}

/// One touch probe (IEC 61800-7-201 (CiA 402) drive profile, 0x60B8/0x60B9): its function bits
/// (shifted to the touch probe 1 position) and what it has stored.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
struct Probe {
    function: u16,
    enabled: bool,
    positive_stored: bool,
    negative_stored: bool,
    positive_toggle: bool,
    negative_toggle: bool,
    positive: i32,
    negative: i32,
}

impl Probe {
    /// Applies the function bits of this exchange: a rising enable bit arms the probe (the
    /// stored flags clear); a clear enable bit disables it.
    fn set_function(&mut self, function: u16) {
        let enable = function & touch_probe::ENABLE != 0;
        if enable != self.enabled {
            self.positive_stored = false;
            self.negative_stored = false;
            self.positive_toggle = false;
            self.negative_toggle = false;
        }
        self.enabled = enable;
        self.function = function;
    }

    fn source(&self) -> u16 {
        self.function & touch_probe::SOURCE_MASK
    }

    /// An edge of the probe's source at `value`: stored if that edge is sampled and, in
    /// first-event mode, nothing is stored for it yet.
    fn latch(&mut self, rising: bool, value: i32) {
        if !self.enabled {
            return;
        }
        let continuous = self.function & touch_probe::CONTINUOUS != 0;
        let (sample, stored, toggle, slot) = if rising {
            (
                touch_probe::SAMPLE_POSITIVE,
                &mut self.positive_stored,
                &mut self.positive_toggle,
                &mut self.positive,
            )
        } else {
            (
                touch_probe::SAMPLE_NEGATIVE,
                &mut self.negative_stored,
                &mut self.negative_toggle,
                &mut self.negative,
            )
        };
        if self.function & sample == 0 || (*stored && !continuous) {
            return;
        }
        *slot = value;
        *stored = true;
        if continuous {
            *toggle = !*toggle;
        }
    }

    /// The probe's status bits (touch probe 1 position).
    fn status(&self) -> u16 {
        if !self.enabled {
            return 0;
        }
        let mut s = touch_probe::STATUS_ENABLED;
        let bits = [
            (self.positive_stored, touch_probe::STATUS_POSITIVE_STORED),
            (self.negative_stored, touch_probe::STATUS_NEGATIVE_STORED),
            (self.positive_toggle, touch_probe::STATUS_POSITIVE_TOGGLE),
            (self.negative_toggle, touch_probe::STATUS_NEGATIVE_TOGGLE),
        ];
        for (on, bit) in bits {
            if on {
                s |= bit;
            }
        }
        s
    }
}

/// A probe input edge waiting for its instant.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
struct PendingEdge {
    /// 0 for touch probe 1, 1 for touch probe 2.
    probe: usize,
    rising: bool,
    /// From the start of the coming advance (ns).
    offset_ns: i64,
}

/// What the drive does with the motor during one sub-step.
#[derive(Copy, Clone, Debug, PartialEq)]
enum Actuation {
    /// No torque.
    Coast,
    /// A motor torque (N·m); `limited` when the torque limit cut it.
    Torque { torque: f64, limited: bool },
    /// A braking torque (N·m, >= 0) that opposes the motion and vanishes at rest.
    Brake { torque: f64 },
}

/// The motion over a time span under constant torque.
#[derive(Copy, Clone, Debug, PartialEq)]
struct Evolution {
    /// Distance travelled (rad).
    distance: f64,
    /// Velocity at the end (rad/s).
    omega: f64,
    /// The distance at which the motor came to rest on the way (rad), if it did and then
    /// moved on (or stayed).
    stop: Option<f64>,
}

/// Solves `J ω' = τ − b ω − c sgn(ω)` exactly over `t` seconds (`c` >= 0 opposes the motion;
/// at rest the motor stays while `|τ| <= c`). At most one stop: after it the motor accelerates
/// in the direction of `τ` and cannot stop again under the same torque.
fn evolve(inertia: f64, viscous: f64, omega: f64, torque: f64, resist: f64, t: f64) -> Evolution {
    let lambda = viscous / inertia;
    let mut w = omega;
    let mut rest = t;
    let mut distance = 0.0;
    let mut stop = None;
    for _ in 0..2 {
        if rest <= 0.0 {
            break;
        }
        let sign = if w > 0.0 {
            1.0
        } else if w < 0.0 {
            -1.0
        } else if torque > resist {
            1.0
        } else if torque < -resist {
            -1.0
        } else {
            break; // at rest, held by friction
        };
        // The acceleration without the viscous term.
        let a = (torque - resist * sign) / inertia;
        if let Some(t_rest) = time_to_rest(w, a, lambda).filter(|&t_rest| t_rest < rest) {
            distance += travel(w, a, lambda, t_rest);
            w = 0.0;
            rest -= t_rest;
            stop = Some(distance);
            continue;
        }
        distance += travel(w, a, lambda, rest);
        let end = speed(w, a, lambda, rest);
        // Rounding must not carry the motor through zero: that is a stop.
        w = if end * sign < 0.0 { 0.0 } else { end };
        rest = 0.0;
    }
    Evolution {
        distance,
        omega: w,
        stop,
    }
}

/// Velocity after `t` from `w` with acceleration `a` and viscous decay rate `lambda`.
fn speed(w: f64, a: f64, lambda: f64, t: f64) -> f64 {
    if lambda > 0.0 {
        let w_inf = a / lambda;
        w_inf + (w - w_inf) * (-lambda * t).exp()
    } else {
        w + a * t
    }
}

/// Distance travelled in `t` from `w` with acceleration `a` and viscous decay rate `lambda`.
fn travel(w: f64, a: f64, lambda: f64, t: f64) -> f64 {
    if lambda > 0.0 {
        let w_inf = a / lambda;
        w_inf * t + (w - w_inf) * (-(-lambda * t).exp_m1()) / lambda
    } else {
        w * t + 0.5 * a * t * t
    }
}

/// When a motor moving at `w` (not 0) comes to rest, if the acceleration opposes the motion.
fn time_to_rest(w: f64, a: f64, lambda: f64) -> Option<f64> {
    if w == 0.0 {
        return None;
    }
    if lambda > 0.0 {
        let w_inf = a / lambda;
        // Heading for a velocity of the other sign: crosses zero at ln(1 + w/(-w_inf))/lambda.
        (w_inf * w < 0.0).then(|| (-w / w_inf).ln_1p() / lambda)
    } else {
        (a * w < 0.0).then(|| -w / a)
    }
}

/// Floor of a continuous position as a wrapping 32-bit counter value.
fn counter(position: f64) -> i32 {
    // Two's-complement wrap of the whole increments passed, as a 32-bit counter does.
    (position.floor() as i64) as i32
}

/// A simulated CiA 402 servo drive (see the module documentation).
#[derive(Clone, Debug)]
pub struct SimServo {
    params: ServoParams,
    substep_ns: i64,
    /// Increments per radian.
    counts_per_rad: f64,
    device: DeviceStateMachine,
    /// The RxPDO latched at the last exchange.
    command: DriveCommand,
    /// Modes of operation display 0x6061.
    mode: i8,
    /// Continuous position (increments).
    position: f64,
    /// Velocity (rad/s).
    omega: f64,
    /// Motor torque of the last sub-step (N·m).
    torque: f64,
    torque_limited: bool,
    /// Integral of the velocity error (rad).
    integral: f64,
    /// CSP: following set-points (operation enabled, mode 8).
    csp_active: bool,
    /// CSP: where the interpolation of this cycle starts (increments).
    interpolation_from: f64,
    /// CSP: the unwrapped target of this cycle (increments) and its raw value.
    target: i64,
    target_raw: i32,
    since_exchange_ns: i64,
    injected: Option<u16>,
    /// The drive's own fault (following error), taken by the next exchange.
    pending_fault: Option<u16>,
    error_code: u16,
    reaction_done: bool,
    following_error: i32,
    following_error_exceeded: bool,
    digital_inputs: u32,
    probes: [Probe; 2],
    edges: [Option<PendingEdge>; PROBE_EDGE_CAPACITY],
    /// Marks on the load that switch the probe inputs: input `k` is high while the position
    /// (increments) is within `marks[k]`.
    marks: [Option<(f64, f64)>; 2],
    /// Mechanical stops on the load (increments): rigid walls the motor cannot pass below the
    /// first or above the second.
    fixed_stops: (Option<f64>, Option<f64>),
}

impl SimServo {
    /// A drive before power-up (its first exchange takes transition 0, the next transition 1
    /// to switch on disabled), the motor at rest at `params.initial_position`.
    pub fn new(params: ServoParams) -> Result<Self, ServoParamsError> {
        let substep_ns = params.validate()?;
        Ok(Self {
            params,
            substep_ns,
            counts_per_rad: f64::from(params.increments_per_revolution) / TAU,
            device: DeviceStateMachine::new(params.quick_stop_option),
            command: DriveCommand::default(),
            mode: ModeOfOperation::NoMode.value(),
            position: params.initial_position,
            omega: 0.0,
            torque: 0.0,
            torque_limited: false,
            integral: 0.0,
            csp_active: false,
            interpolation_from: params.initial_position,
            target: 0,
            target_raw: 0,
            since_exchange_ns: 0,
            injected: None,
            pending_fault: None,
            error_code: 0,
            reaction_done: true,
            following_error: 0,
            following_error_exceeded: false,
            digital_inputs: 0,
            probes: [Probe::default(); 2],
            edges: [None; PROBE_EDGE_CAPACITY],
            marks: [None; 2],
            fixed_stops: (None, None),
        })
    }

    /// Puts rigid mechanical stops in the way of the load (motor increments): the motor stops
    /// dead when it reaches `min` from above or `max` from below (an inelastic impact) and
    /// stays there while its torque pushes into the stop; `None` removes a stop (the stop
    /// gives way). A stop moved to where the motor already is beyond it holds it there.
    #[doc(alias = "fixed stop")]
    pub fn set_fixed_stops(&mut self, min: Option<f64>, max: Option<f64>) {
        self.fixed_stops = (min.filter(|x| x.is_finite()), max.filter(|x| x.is_finite()));
    }

    /// The mechanical stops (motor increments).
    pub const fn fixed_stops(&self) -> (Option<f64>, Option<f64>) {
        self.fixed_stops
    }

    /// Puts a mark on the load in front of touch probe input `probe` (1 or 2): the input is
    /// high while the motor position is within `[low, high]` increments (a mark sensor), so
    /// the input's edges are the crossings of `low` and `high`, latched at the exact crossing
    /// (the counter value of the boundary). `None` removes it.
    pub fn set_probe_mark(
        &mut self,
        probe: u8,
        mark: Option<(f64, f64)>,
    ) -> Result<(), SimServoError> {
        let slot = match probe {
            1 => &mut self.marks[0],
            2 => &mut self.marks[1],
            _ => return Err(SimServoError::NoSuchProbe { probe }),
        };
        *slot = mark.filter(|(lo, hi)| lo.is_finite() && hi.is_finite() && lo <= hi);
        Ok(())
    }

    /// The parameters.
    pub const fn params(&self) -> &ServoParams {
        &self.params
    }

    /// The sub-step the mechanics and loops are integrated with (ns).
    pub const fn substep_ns(&self) -> i64 {
        self.substep_ns
    }

    /// The device state.
    pub const fn state(&self) -> Cia402State {
        self.device.state()
    }

    /// The continuous motor position (increments, not wrapped).
    pub const fn position(&self) -> f64 {
        self.position
    }

    /// The motor velocity (increments/s).
    pub fn velocity(&self) -> f64 {
        self.omega * self.counts_per_rad
    }

    /// The motor torque of the last sub-step (N·m; braking torque included).
    pub const fn torque(&self) -> f64 {
        self.torque
    }

    /// The cycle boundary: latches the RxPDO and steps the device state machine once with its
    /// controlword. Returns the transition taken, if any.
    pub fn exchange(&mut self, command: &DriveCommand) -> Option<Transition> {
        self.command = *command;
        self.since_exchange_ns = 0;
        let inputs = DeviceInputs {
            fault: self.injected.is_some() || self.pending_fault.is_some(),
            reaction_finished: self.reaction_done,
            self_test_done: true,
        };
        let transition = self.device.step(command.controlword, inputs);
        if let Some(t) = transition {
            self.on_transition(t);
        }
        self.latch_mode(command.mode);
        self.latch_target(command.target_position);
        let tp2 = command.touch_probe_function >> touch_probe::PROBE_2_SHIFT;
        let [p1, p2] = &mut self.probes;
        p1.set_function(command.touch_probe_function & 0x00FF);
        p2.set_function(tp2 & 0x00FF);
        transition
    }

    fn on_transition(&mut self, t: Transition) {
        match t.number {
            13 => {
                // The injected cause first; 0x1000 (generic error) cannot occur: a fault
                // transition needs one of the two.
                self.error_code = self.injected.or(self.pending_fault).unwrap_or(0x1000);
                self.pending_fault = None;
                self.reaction_done = self.omega == 0.0;
            }
            11 => {
                self.reaction_done = self.omega == 0.0
                    || self.params.quick_stop_option == QuickStopOption::DisableDrive;
            }
            15 => self.error_code = 0,
            4 | 16 => {
                self.integral = 0.0;
                self.csp_active = false;
            }
            _ => {}
        }
    }

    /// Takes over a supported mode (0, 8, 9, 10); any other value is not taken over and the
    /// display keeps the mode in force (inferred: a real drive refuses it).
    fn latch_mode(&mut self, mode: i8) {
        use ModeOfOperation as M;
        if let Ok(
            M::NoMode
            | M::CyclicSynchronousPosition
            | M::CyclicSynchronousVelocity
            | M::CyclicSynchronousTorque,
        ) = ModeOfOperation::try_from(mode)
        {
            if mode != self.mode {
                self.csp_active = false;
            }
            self.mode = mode;
        }
    }

    /// CSP: unwraps the new target relative to the previous one; on the first cycle the
    /// interpolation starts at the actual position and the target is unwrapped relative to it.
    fn latch_target(&mut self, raw: i32) {
        let following = self.device.state() == Cia402State::OperationEnabled
            && self.mode == ModeOfOperation::CyclicSynchronousPosition.value();
        if following && self.csp_active {
            self.interpolation_from = self.target as f64;
            self.target += i64::from(raw.wrapping_sub(self.target_raw));
        } else if following {
            let actual = self.position.floor() as i64;
            self.interpolation_from = self.position;
            // The 32-bit difference to position actual, as a real drive sees it.
            self.target = actual + i64::from(raw.wrapping_sub(actual as i32));
        }
        self.target_raw = raw;
        self.csp_active = following;
    }

    /// Integrates the drive over `dt_ns` (normally one cycle): sub-steps of at most
    /// [`SimServo::substep_ns`], probe edges at their instants. A non-positive `dt_ns` does
    /// nothing (time does not run backwards).
    pub fn advance(&mut self, dt_ns: i64) {
        if dt_ns <= 0 {
            return;
        }
        let n = dt_ns / self.substep_ns + i64::from(dt_ns % self.substep_ns != 0);
        let mut start = 0;
        for i in 1..=n {
            let end = (i128::from(dt_ns) * i128::from(i) / i128::from(n)) as i64;
            self.substep(start, end);
            start = end;
        }
        self.since_exchange_ns = self.since_exchange_ns.saturating_add(dt_ns);
        for edge in self.edges.iter_mut().flatten() {
            edge.offset_ns -= dt_ns;
        }
        self.end_of_advance();
    }

    /// One sub-step from `start` to `end` (ns from the start of the advance).
    fn substep(&mut self, start: i64, end: i64) {
        let h = (end - start) as f64 * 1e-9;
        let actuation = self.actuation(self.since_exchange_ns.saturating_add(start), h);
        let (torque, brake) = match actuation {
            Actuation::Coast => (0.0, 0.0),
            Actuation::Torque { torque, .. } => (torque, 0.0),
            Actuation::Brake { torque } => (0.0, torque),
        };
        self.torque_limited = matches!(actuation, Actuation::Torque { limited: true, .. });
        let mut t = start;
        while let Some(k) = self.next_edge(t, end) {
            let Some(edge) = self.edges.get_mut(k).and_then(Option::take) else {
                break;
            };
            self.motion(torque, brake, edge.offset_ns - t);
            t = edge.offset_ns;
            let value = counter(self.position);
            if let Some(probe) = self.probes.get_mut(edge.probe) {
                if probe.source() == touch_probe::SOURCE_INPUT {
                    probe.latch(edge.rising, value);
                }
            }
        }
        self.motion(torque, brake, end - t);
        // A braking torque acts only while the motor moves.
        self.torque = match (brake > 0.0, self.omega == 0.0) {
            (false, _) => torque,
            (true, true) => 0.0,
            (true, false) => -brake.copysign(self.omega),
        };
    }

    /// The earliest waiting edge in `[from, to)`.
    fn next_edge(&self, from: i64, to: i64) -> Option<usize> {
        let mut best: Option<(usize, i64)> = None;
        for (k, edge) in self.edges.iter().enumerate() {
            if let Some(e) = edge {
                let in_span = e.offset_ns >= from && e.offset_ns < to;
                if in_span && best.is_none_or(|(_, t)| e.offset_ns < t) {
                    best = Some((k, e.offset_ns));
                }
            }
        }
        best.map(|(k, _)| k)
    }

    /// Moves the mechanics for `dt_ns` under a motor torque and a braking torque, latching
    /// zero pulses on the way.
    fn motion(&mut self, torque: f64, brake: f64, dt_ns: i64) {
        if dt_ns <= 0 {
            return;
        }
        let p = &self.params;
        let e = evolve(
            p.inertia,
            p.viscous_friction,
            self.omega,
            torque,
            p.coulomb_friction + brake,
            dt_ns as f64 * 1e-9,
        );
        let from = self.position;
        let mut to = from + e.distance * self.counts_per_rad;
        let mut omega = e.omega;
        let mut stop = e.stop;
        if let Some(m) = self.fixed_stops.1.filter(|&m| to > m) {
            to = from.max(m);
            omega = omega.min(0.0);
            stop = None;
        }
        if let Some(m) = self.fixed_stops.0.filter(|&m| to < m) {
            to = from.min(m);
            omega = omega.max(0.0);
            stop = None;
        }
        match stop {
            Some(d) => {
                let turn = from + d * self.counts_per_rad;
                self.zero_pulses(from, turn);
                self.zero_pulses(turn, to);
                self.mark_edges(from, turn);
                self.mark_edges(turn, to);
            }
            None => {
                self.zero_pulses(from, to);
                self.mark_edges(from, to);
            }
        }
        self.position = to;
        self.omega = omega;
    }

    /// Latches the edges of the probe inputs' marks crossed moving monotonically from `from`
    /// to `to`, in the order they are crossed: entering a mark is the rising edge, leaving it
    /// the falling one; the value is the counter value of the boundary crossed.
    fn mark_edges(&mut self, from: f64, to: f64) {
        if from == to {
            return;
        }
        let inside = |m: (f64, f64), x: f64| x >= m.0 && x <= m.1;
        for k in 0..2 {
            let (Some(m), Some(probe)) = (self.marks[k], self.probes.get_mut(k)) else {
                continue;
            };
            if !probe.enabled || probe.source() != touch_probe::SOURCE_INPUT {
                continue;
            }
            let (was, is) = (inside(m, from), inside(m, to));
            // Crossed boundaries in the order of travel.
            let (first, second) = if to > from { (m.0, m.1) } else { (m.1, m.0) };
            if !was && !is {
                // Passed over the whole mark within the motion.
                let over = (from < m.0 && to > m.1) || (from > m.1 && to < m.0);
                if over {
                    probe.latch(true, counter(first));
                    probe.latch(false, counter(second));
                }
            } else if !was && is {
                probe.latch(true, counter(first));
            } else if was && !is {
                probe.latch(false, counter(second));
            }
        }
    }

    /// Latches the zero pulses crossed moving monotonically from `from` to `to` (a pulse at
    /// the end counts, one at the start does not) in the probes whose source is the zero
    /// pulse: the first, and in continuous mode the last (inferred: a zero pulse is sampled as
    /// a positive edge; the negative edge is not sampled).
    fn zero_pulses(&mut self, from: f64, to: f64) {
        if from == to
            || !self
                .probes
                .iter()
                .any(|p| p.enabled && p.source() == touch_probe::SOURCE_ZERO_PULSE)
        {
            return;
        }
        let period = f64::from(self.params.increments_per_revolution);
        let offset = f64::from(self.params.zero_pulse_offset);
        let (first, last) = if to > from {
            let first = offset + (((from - offset) / period).floor() + 1.0) * period;
            let last = offset + ((to - offset) / period).floor() * period;
            (first, last)
        } else {
            let first = offset + (((from - offset) / period).ceil() - 1.0) * period;
            let last = offset + ((to - offset) / period).ceil() * period;
            (first, last)
        };
        let crossed = if to > from { first <= to } else { first >= to };
        if !crossed {
            return;
        }
        for probe in &mut self.probes {
            if probe.source() == touch_probe::SOURCE_ZERO_PULSE {
                probe.latch(true, counter(first));
                if last != first {
                    probe.latch(true, counter(last));
                }
            }
        }
    }

    /// The drive's output for the sub-step starting `elapsed_ns` after the exchange.
    fn actuation(&mut self, elapsed_ns: i64, h: f64) -> Actuation {
        match self.device.state() {
            Cia402State::OperationEnabled => self.control(elapsed_ns, h),
            Cia402State::QuickStopActive => self.brake(self.params.quick_stop_option),
            Cia402State::FaultReactionActive => self.brake(QuickStopOption::QuickStopRamp),
            _ => Actuation::Coast,
        }
    }

    /// The torque limit in force (N·m): the drive's own, or max torque 0x6072 if smaller and
    /// not 0.
    fn torque_limit(&self) -> f64 {
        let own = self.params.max_torque_per_mille;
        let per_mille = match self.command.max_torque {
            0 => own,
            m => m.min(own),
        };
        self.params.rated_torque * f64::from(per_mille) * 1e-3
    }

    /// The torque range of the loops (N·m): the limit in force, narrowed by the positive and
    /// negative torque limit values 0x60E0 / 0x60E1 where they are not 0.
    fn torque_bounds(&self) -> (f64, f64) {
        let limit = self.torque_limit();
        let of = |per_mille: u16| match per_mille {
            0 => limit,
            m => limit.min(self.params.rated_torque * f64::from(m) * 1e-3),
        };
        (
            -of(self.command.negative_torque_limit),
            of(self.command.positive_torque_limit),
        )
    }

    fn brake(&self, option: QuickStopOption) -> Actuation {
        use QuickStopOption as O;
        let p = &self.params;
        let limit = self.torque_limit();
        match option {
            O::DisableDrive => Actuation::Coast,
            O::SlowDownRamp | O::QuickStopRamp | O::SlowDownRampStay | O::QuickStopRampStay => {
                let friction = p.coulomb_friction + p.viscous_friction * self.omega.abs();
                let needed = p.inertia * p.quick_stop_deceleration - friction;
                Actuation::Brake {
                    torque: needed.clamp(0.0, limit),
                }
            }
            O::CurrentLimit | O::VoltageLimit | O::CurrentLimitStay | O::VoltageLimitStay => {
                Actuation::Brake { torque: limit }
            }
        }
    }

    /// The loops of the mode in force, sampled at the start of a sub-step of `h` seconds.
    fn control(&mut self, elapsed_ns: i64, h: f64) -> Actuation {
        use ModeOfOperation as M;
        let rated = self.params.rated_torque * 1e-3;
        let torque_offset = f64::from(self.command.torque_offset) * rated;
        let k = self.counts_per_rad;
        match ModeOfOperation::try_from(self.mode) {
            Ok(M::CyclicSynchronousPosition) => {
                let s = (elapsed_ns as f64 / self.params.cycle_ns as f64).clamp(0.0, 1.0);
                let demand =
                    self.interpolation_from + (self.target as f64 - self.interpolation_from) * s;
                let v = f64::from(self.command.velocity_offset)
                    + self.params.kv * (demand - self.position);
                self.velocity_loop(v / k, torque_offset, h)
            }
            Ok(M::CyclicSynchronousVelocity) => {
                let v = f64::from(self.command.target_velocity)
                    + f64::from(self.command.velocity_offset);
                self.velocity_loop(v / k, torque_offset, h)
            }
            Ok(M::CyclicSynchronousTorque) => {
                let demand = (i32::from(self.command.target_torque)
                    + i32::from(self.command.torque_offset)) as f64
                    * rated;
                let (lo, hi) = self.torque_bounds();
                let torque = demand.clamp(lo, hi);
                Actuation::Torque {
                    torque,
                    limited: torque != demand,
                }
            }
            _ => Actuation::Coast,
        }
    }

    /// PI velocity loop on `omega_set` (rad/s) with torque feedforward, torque limited, with
    /// conditional integration (the integral does not run on into the limit).
    fn velocity_loop(&mut self, omega_set: f64, feedforward: f64, h: f64) -> Actuation {
        let p = &self.params;
        let error = omega_set - self.omega;
        let ti = p.velocity_loop_integral_time;
        let integral_term = if ti > 0.0 { self.integral / ti } else { 0.0 };
        let demand = p.velocity_loop_gain * (error + integral_term) + feedforward;
        let (lo, hi) = self.torque_bounds();
        let torque = demand.clamp(lo, hi);
        let limited = torque != demand;
        if ti > 0.0 && (!limited || (demand > 0.0) != (error > 0.0)) {
            self.integral += error * h;
        }
        Actuation::Torque { torque, limited }
    }

    /// After the cycle's motion: the following error and its monitoring, the end of a
    /// reaction.
    fn end_of_advance(&mut self) {
        let state = self.device.state();
        if self.csp_active {
            let s = (self.since_exchange_ns as f64 / self.params.cycle_ns as f64).clamp(0.0, 1.0);
            let demand =
                self.interpolation_from + (self.target as f64 - self.interpolation_from) * s;
            let error = demand.round() as i64 - self.position.floor() as i64;
            self.following_error = error.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32;
            let window = self.params.following_error_window;
            self.following_error_exceeded =
                window != u32::MAX && error.unsigned_abs() > u64::from(window);
            if self.following_error_exceeded && state == Cia402State::OperationEnabled {
                self.pending_fault.get_or_insert(FOLLOWING_ERROR_CODE);
            }
        } else {
            self.following_error = 0;
            self.following_error_exceeded = false;
        }
        if matches!(
            state,
            Cia402State::QuickStopActive | Cia402State::FaultReactionActive
        ) {
            let coasting = state == Cia402State::QuickStopActive
                && self.params.quick_stop_option == QuickStopOption::DisableDrive;
            self.reaction_done = self.omega == 0.0 || coasting;
        }
    }

    /// The TxPDO at the cycle boundary.
    pub fn feedback(&self) -> DriveFeedback {
        let [p1, p2] = &self.probes;
        DriveFeedback {
            statusword: self.statusword(),
            mode_display: self.mode,
            position_actual: counter(self.position),
            velocity_actual: self.velocity().round() as i32,
            torque_actual: (self.torque / self.params.rated_torque * 1e3).round() as i16,
            following_error: self.following_error,
            error_code: self.error_code,
            digital_inputs: self.digital_inputs,
            touch_probe_status: p1.status() | (p2.status() << touch_probe::PROBE_2_SHIFT),
            touch_probe_1_positive: p1.positive,
            touch_probe_1_negative: p1.negative,
            touch_probe_2_positive: p2.positive,
            touch_probe_2_negative: p2.negative,
        }
    }

    /// The statusword 0x6041: the state bits, remote (always), target reached (quick stop
    /// active at standstill), internal limit active (torque at the limit in operation enabled),
    /// drive follows the command value (operation enabled in CSP, CSV or CST), following error
    /// (CSP, beyond the window).
    pub fn statusword(&self) -> u16 {
        let state = self.device.state();
        let enabled = state == Cia402State::OperationEnabled;
        let cyclic = ModeOfOperation::try_from(self.mode).is_ok_and(ModeOfOperation::is_cyclic);
        let bits = [
            (true, statusword::REMOTE),
            (
                state == Cia402State::QuickStopActive && self.reaction_done,
                statusword::TARGET_REACHED,
            ),
            (
                enabled && self.torque_limited,
                statusword::INTERNAL_LIMIT_ACTIVE,
            ),
            (enabled && cyclic, statusword::FOLLOWS_COMMAND),
            (self.following_error_exceeded, statusword::FOLLOWING_ERROR),
        ];
        bits.into_iter()
            .filter(|(on, _)| *on)
            .fold(self.device.statusword(), |sw, (_, bit)| sw | bit)
    }

    /// Injects a fault cause with its error code 0x603F (e.g. 0x2310 overcurrent, 0x4310
    /// over-temperature): the next exchange takes transition 13. The cause stays present (a
    /// fault reset is refused) until [`SimServo::clear_fault_cause`].
    pub fn inject_fault(&mut self, code: u16) -> Result<(), SimServoError> {
        if code == 0 {
            return Err(SimServoError::NoErrorCode);
        }
        self.injected = Some(code);
        Ok(())
    }

    /// Removes the injected fault cause (a fault reset can then succeed).
    pub fn clear_fault_cause(&mut self) {
        self.injected = None;
    }

    /// Sets the digital inputs 0x60FD (bit 0 negative limit, bit 1 positive limit, bit 2 home
    /// switch, ...), as the plant's switches see the load.
    pub fn set_digital_inputs(&mut self, inputs: u32) {
        self.digital_inputs = inputs;
    }

    /// An edge of touch probe input `probe` (1 or 2) `offset_ns` after the start of the coming
    /// [`SimServo::advance`] (an edge beyond that advance waits for the next one). The probe
    /// latches the position at that instant if it is enabled with the input as source and
    /// samples that edge.
    ///
    /// Accuracy: the motion inside the sub-step is evaluated in closed form at the edge
    /// instant, so the continuous position there is exact up to floating-point rounding
    /// (about 1e-7 increment at 2^31 increments); the latched value is its floor, the counter
    /// value, so it is below the true position by less than one increment.
    pub fn probe_edge(
        &mut self,
        probe: u8,
        rising: bool,
        offset_ns: i64,
    ) -> Result<(), SimServoError> {
        let index = match probe {
            1 => 0,
            2 => 1,
            _ => return Err(SimServoError::NoSuchProbe { probe }),
        };
        if offset_ns < 0 {
            return Err(SimServoError::NegativeEdgeOffset { offset_ns });
        }
        let slot = self
            .edges
            .iter_mut()
            .find(|e| e.is_none())
            .ok_or(SimServoError::ProbeEdgeQueueFull)?;
        *slot = Some(PendingEdge {
            probe: index,
            rising,
            offset_ns,
        });
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn evolve_matches_closed_forms() {
        // Constant acceleration, no friction.
        let e = evolve(2.0, 0.0, 1.0, 4.0, 0.0, 0.5);
        assert!((e.omega - 2.0).abs() < 1e-15 && (e.distance - 0.75).abs() < 1e-15);
        // Coulomb friction stops the motor after w J / c = 4 s, at J w² / (2 c) = 6, and it
        // stays.
        let e = evolve(2.0, 0.0, 3.0, 0.0, 1.5, 10.0);
        assert_eq!(e.omega, 0.0);
        assert!((e.distance - 6.0).abs() < 1e-14, "{}", e.distance);
        assert!((e.stop.unwrap_or(f64::NAN) - 6.0).abs() < 1e-14);
        let e = evolve(2.0, 0.0, 3.0, 0.0, 1.5, 3.0);
        assert!((e.omega - 0.75).abs() < 1e-15 && e.stop.is_none());
        // A torque beyond the friction after the stop reverses the motion.
        let e = evolve(1.0, 0.0, 1.0, -2.0, 1.0, 2.0);
        // Decelerates at 3 until t = 1/3 (distance 1/6), then accelerates at -1 for 5/3.
        assert!((e.omega + 5.0 / 3.0).abs() < 1e-12, "{}", e.omega);
        let expected = 1.0 / 6.0 - 0.5 * (5.0f64 / 3.0).powi(2);
        assert!(
            (e.distance - expected).abs() < 1e-12,
            "{} {}",
            e.distance,
            expected
        );
        // Viscous decay: w e^{-b t / J}, distance w J / b (1 - e^{-b t/J}).
        let e = evolve(1.0, 2.0, 4.0, 0.0, 0.0, 0.25);
        assert!((e.omega - 4.0 * (-0.5f64).exp()).abs() < 1e-14);
        assert!((e.distance - 2.0 * (1.0 - (-0.5f64).exp())).abs() < 1e-14);
        // At rest with a torque below the friction: nothing moves.
        assert_eq!(
            evolve(1.0, 1.0, 0.0, 0.5, 0.6, 1.0),
            Evolution {
                distance: 0.0,
                omega: 0.0,
                stop: None
            }
        );
    }

    #[test]
    fn counter_wraps_like_a_32_bit_counter() {
        assert_eq!(counter(2_147_483_647.5), i32::MAX);
        assert_eq!(counter(2_147_483_648.0), i32::MIN);
        assert_eq!(counter(-0.5), -1);
        assert_eq!(counter(4_294_967_296.0 + 5.25), 5);
    }

    #[test]
    fn params_are_validated_naming_the_field() {
        let ok = ServoParams::example(1_000_000);
        assert!(SimServo::new(ok).is_ok());
        type Edit = fn(&mut ServoParams);
        let cases: [(Edit, &str, ServoParamsProblem); 9] = [
            (
                |p| p.cycle_ns = 0,
                "cycle_ns",
                ServoParamsProblem::NotPositive,
            ),
            (
                |p| p.inertia = 0.0,
                "inertia",
                ServoParamsProblem::NotPositive,
            ),
            (
                |p| p.rated_torque = f64::NAN,
                "rated_torque",
                ServoParamsProblem::NotFinite,
            ),
            (
                |p| p.coulomb_friction = -1.0,
                "coulomb_friction",
                ServoParamsProblem::Negative,
            ),
            (
                |p| p.zero_pulse_offset = 1 << 20,
                "zero_pulse_offset",
                ServoParamsProblem::OutOfRange,
            ),
            (
                |p| p.following_error_window = 0,
                "following_error_window",
                ServoParamsProblem::NotPositive,
            ),
            (
                |p| p.velocity_loop_gain = 1e3,
                "velocity_loop_gain",
                ServoParamsProblem::TooStiff,
            ),
            (|p| p.kv = 1e5, "kv", ServoParamsProblem::TooStiff),
            (
                |p| p.initial_position = f64::INFINITY,
                "initial_position",
                ServoParamsProblem::NotFinite,
            ),
        ];
        for (edit, field, problem) in cases {
            let mut p = ok;
            edit(&mut p);
            assert_eq!(
                SimServo::new(p).err(),
                Some(ServoParamsError { field, problem })
            );
        }
        assert_eq!(
            ServoParamsError {
                field: "inertia",
                problem: ServoParamsProblem::NotPositive
            }
            .to_string(),
            "simulated servo: inertia must be positive"
        );
        // The example: 1/20 of J/Kp = 1e-3 s is 50 µs.
        assert_eq!(SimServo::new(ok).map(|s| s.substep_ns()), Ok(50_000));
    }
}
