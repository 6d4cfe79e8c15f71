//! The output cam technology object and `MC_OutputCam` (S7-1500T Measuring input and cam functions
//! V5.0 function manual, 3.2 'Output cam technology object'; S7-Technology V4.1 function manual,
//! 3.6 '"Output cam" technology object').
//!
//! # Interface
//!
//! An [`OutputCam`] is stepped once per cycle with the motion of the position it refers to (the
//! caller passes the setpoint or the actual value, as [`OutputCamConfig::position_type`] says),
//! an [`AxisMotion`] (see [`crate::kinematics::cycle_motion`] for its definition: continuous
//! positions, quintic Hermite between samples, optional knots, modulo, jump, validity):
//!
//! ```text
//! cam.call(instance, &McOutputCam { .. })      // the FB call (Enable-type), any time
//! cam.step(&motion, &mut edges)                // once per cycle
//! ```
//!
//! [`OutputCam::step`] fills a fixed-capacity [`CamEdges`] with the switching edges of the
//! output in this cycle, each with its exact time in ns ([`Edge`]): the time at which the motion
//! reaches the switching position, minus the on- or off-compensation (lead times), or the cycle
//! start for edges caused by an FB call, a homing jump or a validity change. Edges are sorted by
//! time and never go back in time: an edge whose compensated time would fall before the previous
//! edge of the output is reported at that previous edge's time (a zero-length pulse, when the
//! compensations exceed the cam's length in time). Edges may therefore carry times before
//! `t0_ns`. A caller whose output must switch at the edge times passes a motion that runs
//! ahead of the output: [`SwitchingAhead::predict`] gives it (S7 computes the switching times
//! two servo cycles ahead, S7-1500T Measuring input and cam functions V5.0 function manual, 3.2
//! 'Output cam technology object').
//!
//! # Switching rules
//!
//! - Distance cam: ON while the effective position lies in `[OnPosition, OffPosition]` (closed;
//!   `On > Off` wraps through the modulo boundary or, on a linear axis, is
//!   `(-inf, Off] U [On, inf)`; `On == Off` never switches) **and** the effective direction is
//!   enabled: Direction 3 always (standstill included), Direction 1 / 2 only after motion in
//!   that direction: a reversal against it switches off, a homing jump at standstill leaves it
//!   off, a start from standstill in the enabled direction inside the range switches on.
//! - Time cam: ON when the start position is crossed in an enabled direction, for `Duration`;
//!   not retriggered while on (the logical on time is `[t, t + Duration)`), not cut short by a
//!   reversal or homing, not started by a homing jump. Not started by a crossing in the first
//!   [`OutputCamConfig::arming_cycles`] cycles after the enable (S7-1500T Measuring input and
//!   cam functions V5.0 function manual, 6.4.1 'MC_OutputCam: Activate/deactivate output cam V5',
//!   timing rule).
//! - Hysteresis `H` (capped at a quarter of the modulo length or of the working range): a
//!   direction reversal at `p` arms a band from `p` back by `H`; inside it the effective position
//!   and direction are frozen. Leaving the band against the old direction is the reversal: the
//!   effective position jumps to the band end (distance cams take the state there, time cam
//!   starts inside the band fire then); leaving it past `p` in the old direction resumes without
//!   a reversal.
//! - Mode 1 standard, 2 inverted (the physical output is the negation, `StatusWord.X4`), 3 ON
//!   while enabled. On/off compensations apply to the physical on / off edges.
//! - Invalid position: a setpoint cam is off while the position is invalid and resumes when it is
//!   valid again; an actual-value cam raises alarm 702 (processing ends, output off) until
//!   `MC_Reset`, after which it resumes by itself. Alarm 704 when a time cam's
//!   `Duration <= OffCompensation - OnCompensation`.
//!
//! Several cams on one output: [`combine`] merges the edge lists of several cams by OR or AND
//! (`Interface.LogicOperation`), after each cam's inversion.
//!
//! ErrorIDs of the FB call: `16#8040` OnPosition, `16#8041` OffPosition (not finite or beyond
//! 1e12), `16#8042` Duration (time cam, not > 0), `16#800A` Mode, `16#8007` Direction,
//! `16#800C` a second active instance, `16#8001` while an alarm is pending.

use crate::catalog::alarm::{supplement, AlarmId, AlarmInstance};
use crate::catalog::error_id::ErrorId;
use crate::kinematics::crossing::{point_crossings, Path, PathEvent, RangeSet};
use crate::kinematics::cycle_motion::AxisMotion;
use crate::kinematics::extrapolation::constant_acceleration;
use crate::kinematics::timed_list::{Timed, TimedList};
use crate::objects::measuring::MeasuringConfigError;

// ---------------------------------------------------------------------------------------------
// Edges
// ---------------------------------------------------------------------------------------------

/// One switching edge of an output.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct Edge {
    /// Time of the edge (ns, cell clock), compensations applied.
    pub time_ns: i64,
    /// Switched on (`true`) or off.
    pub on: bool,
    /// The cam that caused it (0 for an output cam; the cam index 0..32 on a cam track; the
    /// input index in [`combine`]).
    pub cam: u8,
}

/// Capacity of a [`CamEdges`] list.
pub const EDGE_CAPACITY: usize = 16;

/// The edges of one output in one cycle, sorted by time (fixed capacity; the excess is counted).
pub type CamEdges = TimedList<Edge, EDGE_CAPACITY>;

impl Timed for Edge {
    fn time_ns(&self) -> i64 {
        self.time_ns
    }
}

/// `Interface.LogicOperation`: how several cams on one output combine.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum LogicOperation {
    /// 0: OR.
    Or = 0,
    /// 1: AND.
    And = 1,
}

/// Maximum number of cams [`combine`] merges.
pub const COMBINE_MAX: usize = 32;

/// Merges the edge lists of several cams on one output: `cams[i]` is cam `i`'s output state at
/// the start of the cycle and its edges in the cycle. Writes the edges of the combined output to
/// `out` (`Edge::cam` is the index of the cam whose edge changed it) and returns the combined
/// state at the start of the cycle and at its end. Edges at equal times are applied in input
/// order. At most [`COMBINE_MAX`] cams are read.
pub fn combine(
    logic: LogicOperation,
    cams: &[(bool, &CamEdges)],
    out: &mut CamEdges,
) -> (bool, bool) {
    let cams = &cams[..cams.len().min(COMBINE_MAX)];
    let mut state = [false; COMBINE_MAX];
    let mut next = [0usize; COMBINE_MAX];
    for (s, c) in state.iter_mut().zip(cams) {
        *s = c.0;
    }
    let eval = |state: &[bool; COMBINE_MAX]| -> bool {
        let s = &state[..cams.len()];
        match logic {
            LogicOperation::Or => s.iter().any(|&b| b),
            LogicOperation::And => !s.is_empty() && s.iter().all(|&b| b),
        }
    };
    let start = eval(&state);
    let mut cur = start;
    loop {
        let mut best: Option<(usize, Edge)> = None;
        for (i, c) in cams.iter().enumerate() {
            if let Some(e) = c.1.as_slice().get(next[i]) {
                if best.is_none_or(|(_, b)| e.time_ns < b.time_ns) {
                    best = Some((i, *e));
                }
            }
        }
        let Some((i, e)) = best else {
            break;
        };
        next[i] += 1;
        state[i] = e.on;
        let new = eval(&state);
        if new != cur {
            cur = new;
            out.push(Edge {
                time_ns: e.time_ns,
                on: new,
                cam: i as u8,
            });
        }
    }
    (start, cur)
}

// ---------------------------------------------------------------------------------------------
// Switching ahead
// ---------------------------------------------------------------------------------------------

/// The look-ahead of an output cam or cam track that drives an output: the motion it is
/// stepped with runs ahead of the cycle just computed, so that the edge times it reports are
/// the times the output must switch.
///
/// S7-1500T computes the exact switching time two position-control cycles before the output;
/// setpoint cams are shifted so that they fire when the setpoint reaches the drive (S7-1500T
/// Measuring input and cam functions V5.0 function manual, 3.2 'Output cam technology object').
/// Given the motion of the cycle `[t0, t1]` of the position the object switches on,
/// [`Self::predict`] returns the motion of `[t0 + H, t1 + H]` (`H` the horizon):
///
/// - **Setpoint**: the setpoint reaches the load `D` later (its transport delay: two cycles on a
///   drive of the process image), so the load's position at `τ` is the setpoint of `τ - D`. For
///   `H = D` that is the cycle's setpoint itself, shifted in time (exact); for `H > D` (a
///   compensation longer than the cycles of the look-ahead) the setpoint at both ends is
///   extrapolated `H - D` ahead with its constant acceleration.
/// - **Actual value**: the actual position at both ends extrapolated `H` ahead with the actual
///   velocity and acceleration ([`crate::kinematics::extrapolation::constant_acceleration`]).
///
/// Exact for motion of constant velocity or constant acceleration (the quintic Hermite between
/// the two extrapolated states reproduces a parabola). The predicted motions of consecutive
/// cycles join (each end is extrapolated from the same sample the next cycle's start is), so
/// an object walks a continuous path; a prediction error moves an edge, it never loses or
/// repeats one. Jump and validity are those of the cycle. Inferred: the reference does not say
/// how S7 predicts; this is the extrapolation of actual-value coupling without its filters.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct SwitchingAhead {
    /// `H` (ns): how far the predicted motion runs ahead of the cycle.
    pub horizon_ns: i64,
    /// How far the states are extrapolated (ns): `H - D` for a setpoint, `H` for an actual
    /// value.
    pub extrapolation_ns: i64,
}

impl SwitchingAhead {
    /// The look-ahead of an object on `position_type` for an output that needs its edges
    /// `horizon_ns` ahead, the setpoint reaching the load `setpoint_delay_ns` after it is
    /// computed. A setpoint cam's horizon is at least that delay (its edges are never earlier
    /// than the load passing the position, less the compensation). Negative values count as 0.
    pub fn new(position_type: PositionType, horizon_ns: i64, setpoint_delay_ns: i64) -> Self {
        let horizon_ns = horizon_ns.max(0);
        let delay = setpoint_delay_ns.max(0);
        match position_type {
            PositionType::Setpoint => {
                let horizon_ns = horizon_ns.max(delay);
                Self {
                    horizon_ns,
                    extrapolation_ns: horizon_ns - delay,
                }
            }
            PositionType::Actual => Self {
                horizon_ns,
                extrapolation_ns: horizon_ns,
            },
        }
    }

    /// The motion of `[t0 + H, t1 + H]` predicted from the motion `m` of `[t0, t1]` (see the
    /// type's documentation). Interior knots are extrapolated alike.
    pub fn predict(&self, m: &AxisMotion) -> AxisMotion {
        let mut p = *m;
        p.t0_ns = m.t0_ns.saturating_add(self.horizon_ns);
        p.t1_ns = m.t1_ns.saturating_add(self.horizon_ns);
        if self.extrapolation_ns == 0 {
            return p;
        }
        let dt = self.extrapolation_ns as f64 * 1e-9;
        let ahead = |s| constant_acceleration(s, dt);
        let mut q = AxisMotion::new(p.t0_ns, p.t1_ns, ahead(m.start), ahead(m.end))
            .with_modulo(m.modulo)
            .with_valid(m.valid);
        if let Some(d) = m.jump {
            q = q.with_jump(d);
        }
        for k in m.knots() {
            q.push_knot(k.dt, ahead(k.state));
        }
        q
    }
}

// ---------------------------------------------------------------------------------------------
// Output cam TO
// ---------------------------------------------------------------------------------------------

/// `Parameter.OutputCamType`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum OutputCamType {
    /// 0: distance cam (OnPosition..OffPosition).
    Distance = 0,
    /// 1: time cam (OnPosition, Duration).
    Time = 1,
}

/// `Parameter.PositionType`: which position the caller passes.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum PositionType {
    /// 0: setpoint (off while the axis is not position-controlled).
    Setpoint = 0,
    /// 1: actual value (alarm 702 when it is not valid).
    Actual = 1,
}

/// `MC_OutputCam.Mode`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum OutputCamMode {
    /// 1: standard.
    Standard = 1,
    /// 2: inverted output.
    Inverted = 2,
    /// 3: output ON while enabled.
    AlwaysOn = 3,
}

impl OutputCamMode {
    /// The mode for a `Mode` input, or `16#800A`.
    pub const fn from_code(code: i32) -> Result<Self, ErrorId> {
        match code {
            1 => Ok(Self::Standard),
            2 => Ok(Self::Inverted),
            3 => Ok(Self::AlwaysOn),
            _ => Err(ErrorId::IllegalMode),
        }
    }
}

/// `MC_OutputCam.Direction`: the effective direction.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum CamDirection {
    /// 1: positive.
    Positive = 1,
    /// 2: negative.
    Negative = 2,
    /// 3: both.
    Both = 3,
}

impl CamDirection {
    /// The direction for a `Direction` input, or `16#8007`.
    pub const fn from_code(code: i32) -> Result<Self, ErrorId> {
        match code {
            1 => Ok(Self::Positive),
            2 => Ok(Self::Negative),
            3 => Ok(Self::Both),
            _ => Err(ErrorId::IllegalDirection),
        }
    }

    /// Whether the effective direction `dir` (+1, -1, 0 for none) is enabled.
    pub const fn enables(self, dir: i8) -> bool {
        match self {
            Self::Both => true,
            Self::Positive => dir > 0,
            Self::Negative => dir < 0,
        }
    }
}

/// Configuration of an output cam (the TO's `Parameter.*`; compensations and hysteresis are DIR
/// tags and can be changed with [`OutputCam::set_parameters`]).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct OutputCamConfig {
    /// `Parameter.OutputCamType` (RES).
    pub cam_type: OutputCamType,
    /// `Parameter.PositionType` (RES).
    pub position_type: PositionType,
    /// DIR parameters.
    pub parameters: OutputCamParameters,
    /// Operating range of a linear axis (software limits): the hysteresis cap is a quarter of
    /// it. `None`: no cap on a linear axis.
    pub working_range: Option<(f64, f64)>,
    /// Time cams: a start crossed in the first `arming_cycles` cycles after the enable does not
    /// switch (S7: 2 application cycles). 0 switches at once.
    pub arming_cycles: u32,
}

/// The DIR parameters of an output cam or cam track.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct OutputCamParameters {
    /// `Parameter.OnCompensation`: lead time of the on edge (s, 0..1e9).
    pub on_compensation: f64,
    /// `Parameter.OffCompensation`: lead time of the off edge (s, 0..1e9).
    pub off_compensation: f64,
    /// `Parameter.Hysteresis` (>= 0, position units).
    pub hysteresis: f64,
}

impl OutputCamParameters {
    /// No compensation, no hysteresis.
    pub const NONE: Self = Self {
        on_compensation: 0.0,
        off_compensation: 0.0,
        hysteresis: 0.0,
    };

    pub(crate) fn check(&self) -> Result<(), MeasuringConfigError> {
        if !(self.on_compensation >= 0.0 && self.on_compensation <= 1e9) {
            return Err(MeasuringConfigError::OnCompensation);
        }
        if !(self.off_compensation >= 0.0 && self.off_compensation <= 1e9) {
            return Err(MeasuringConfigError::OffCompensation);
        }
        if !(self.hysteresis >= 0.0 && self.hysteresis <= 1e12) {
            return Err(MeasuringConfigError::Hysteresis);
        }
        Ok(())
    }
}

impl OutputCamConfig {
    /// A distance or time cam on the setpoint, no compensation, no hysteresis, armed after 2
    /// cycles.
    pub const fn new(cam_type: OutputCamType) -> Self {
        Self {
            cam_type,
            position_type: PositionType::Setpoint,
            parameters: OutputCamParameters::NONE,
            working_range: None,
            arming_cycles: 2,
        }
    }
}

/// Maximum hysteresis (S7-1500T Measuring input and cam functions V5.0 function manual,
/// 3.2.4 'Hysteresis'): a quarter of the modulo length on a modulo axis, a quarter of the working
/// range otherwise; `None` without either.
pub fn max_hysteresis(
    modulo_length: Option<f64>,
    working_range: Option<(f64, f64)>,
) -> Option<f64> {
    match (modulo_length, working_range) {
        (Some(l), _) => Some(0.25 * l),
        (None, Some((lo, hi))) => Some(0.25 * (hi - lo).abs()),
        (None, None) => None,
    }
}

/// The inputs of `MC_OutputCam`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct McOutputCam {
    /// `Enable`.
    pub enable: bool,
    /// `OnPosition` (mapped into the modulo range on modulo axes).
    pub on_position: f64,
    /// `OffPosition` (distance cams).
    pub off_position: f64,
    /// `Duration` (s, time cams, > 0).
    pub duration: f64,
    /// `Mode`.
    pub mode: OutputCamMode,
    /// `Direction`.
    pub direction: CamDirection,
}

impl McOutputCam {
    /// Enabled, standard mode, positive direction.
    pub const fn distance(on_position: f64, off_position: f64) -> Self {
        Self {
            enable: true,
            on_position,
            off_position,
            duration: 0.0,
            mode: OutputCamMode::Standard,
            direction: CamDirection::Positive,
        }
    }

    /// Enabled time cam, standard mode, positive direction.
    pub const fn time(on_position: f64, duration: f64) -> Self {
        Self {
            enable: true,
            on_position,
            off_position: 0.0,
            duration,
            mode: OutputCamMode::Standard,
            direction: CamDirection::Positive,
        }
    }

    /// The same with another direction.
    pub const fn with_direction(mut self, direction: CamDirection) -> Self {
        self.direction = direction;
        self
    }

    /// The same with another mode.
    pub const fn with_mode(mut self, mode: OutputCamMode) -> Self {
        self.mode = mode;
        self
    }
}

/// The outputs of `MC_OutputCam`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct OutputCamFb {
    /// `CamOutput`: the output as of the last step.
    pub cam_output: bool,
    /// `Busy`: processing (this instance owns the cam and Enable is TRUE).
    pub busy: bool,
    /// `Error`.
    pub error: bool,
    /// `ErrorID`.
    pub error_id: ErrorId,
}

/// Status of an output cam (technology data block).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct OutputCamStatus {
    /// `<TO>.CamOutput`: the output after inversion / forcing, after the edges of the last step.
    pub cam_output: bool,
    /// Processing (an instance holds Enable TRUE).
    pub busy: bool,
    /// `StatusWord.X4 OutputInverted`.
    pub output_inverted: bool,
    /// The hysteresis in effect (after the cap).
    pub hysteresis: f64,
    /// The configured hysteresis exceeds the cap (`WarningWord.X1`, parameter adjusted).
    pub hysteresis_limited: bool,
    /// Pending alarm (702, 704).
    pub alarm: Option<AlarmInstance>,
}

/// A running time cam: its physical off edge (not yet reported) and the end of its logical on
/// time (ns).
#[derive(Copy, Clone, Debug, PartialEq)]
struct Running {
    off_edge_ns: Option<i64>,
    logical_end_ns: i64,
}

/// The output cam technology object (see the module documentation).
#[derive(Clone, Debug)]
pub struct OutputCam {
    config: OutputCamConfig,
    owner: Option<u32>,
    input: McOutputCam,
    /// Processing runs (the path and the cam state are initialised).
    live: bool,
    /// Cycles until a time cam is armed.
    arming: u32,
    /// The input changed: re-evaluate at the next step.
    changed: bool,
    path: Path,
    /// Distance cam: the logical (uninverted) state.
    logic: bool,
    running: Option<Running>,
    output: bool,
    last_edge_ns: i64,
    alarm: Option<AlarmInstance>,
    status: OutputCamStatus,
}

fn check_position(x: f64) -> bool {
    x.is_finite() && x.abs() <= 1e12
}

impl OutputCam {
    /// An output cam with the given configuration.
    pub fn new(config: OutputCamConfig) -> Result<Self, MeasuringConfigError> {
        config.parameters.check()?;
        Ok(Self {
            config,
            owner: None,
            input: McOutputCam::distance(0.0, 0.0),
            live: false,
            arming: 0,
            changed: false,
            path: Path::default(),
            logic: false,
            running: None,
            output: false,
            last_edge_ns: i64::MIN,
            alarm: None,
            status: OutputCamStatus {
                cam_output: false,
                busy: false,
                output_inverted: false,
                hysteresis: config.parameters.hysteresis,
                hysteresis_limited: false,
                alarm: None,
            },
        })
    }

    /// The configuration.
    pub fn config(&self) -> &OutputCamConfig {
        &self.config
    }

    /// Writes the DIR parameters (compensations, hysteresis); effective at the next step.
    pub fn set_parameters(&mut self, p: OutputCamParameters) -> Result<(), MeasuringConfigError> {
        p.check()?;
        self.config.parameters = p;
        Ok(())
    }

    /// The status (data block).
    pub fn status(&self) -> &OutputCamStatus {
        &self.status
    }

    fn fb(&self, busy: bool, err: Option<ErrorId>) -> OutputCamFb {
        let err = err.or(self.alarm.map(|_| ErrorId::TechnologyAlarm));
        OutputCamFb {
            cam_output: self.status.cam_output,
            busy,
            error: err.is_some(),
            error_id: err.unwrap_or(ErrorId::None),
        }
    }

    /// `MC_OutputCam` called by FB instance `instance` (Enable-type: call it every cycle or
    /// whenever an input changes). Inputs take effect at the next step. A call with invalid
    /// inputs is rejected and changes nothing (a running cam keeps its last valid inputs).
    pub fn call(&mut self, instance: u32, input: &McOutputCam) -> OutputCamFb {
        if !input.enable {
            if self.owner == Some(instance) {
                self.owner = None;
                self.changed = true;
            }
            return self.fb(false, None);
        }
        if self.owner.is_some_and(|o| o != instance) {
            return OutputCamFb {
                cam_output: false,
                busy: false,
                error: true,
                error_id: ErrorId::OnlyOneInstance,
            };
        }
        let busy = self.owner == Some(instance);
        if !check_position(input.on_position) {
            return self.fb(busy, Some(ErrorId::IllegalOnPosition));
        }
        if self.config.cam_type == OutputCamType::Distance && !check_position(input.off_position) {
            return self.fb(busy, Some(ErrorId::IllegalOffPosition));
        }
        if self.config.cam_type == OutputCamType::Time
            && !(input.duration > 0.0 && input.duration <= 1e9)
        {
            return self.fb(busy, Some(ErrorId::IllegalDuration));
        }
        if self.owner.is_none() {
            self.owner = Some(instance);
            self.live = false;
            self.changed = true;
        } else if *input != self.input {
            self.changed = true;
        }
        self.input = *input;
        self.status.busy = true;
        self.fb(true, None)
    }

    /// `MC_Reset`: acknowledges the pending alarm; an enabled cam resumes at the next step.
    pub fn reset(&mut self) {
        if self.alarm.take().is_some() {
            self.live = false;
        }
        self.status.alarm = None;
    }

    fn emit(&mut self, edges: &mut CamEdges, t_ns: i64, on: bool) {
        if on == self.output {
            return;
        }
        let t = t_ns.max(self.last_edge_ns);
        self.last_edge_ns = t;
        self.output = on;
        edges.push(Edge {
            time_ns: t,
            on,
            cam: 0,
        });
    }

    /// The physical output for a logical state.
    fn physical(&self, logic: bool) -> bool {
        match self.input.mode {
            OutputCamMode::Standard => logic,
            OutputCamMode::Inverted => !logic,
            OutputCamMode::AlwaysOn => true,
        }
    }

    /// Logical transition at exact time `t0 + dt` (s) from the motion: compensated edge.
    fn switch_at(&mut self, edges: &mut CamEdges, motion: &AxisMotion, dt: f64, logic: bool) {
        let phys = self.physical(logic);
        if phys == self.output {
            return;
        }
        let p = &self.config.parameters;
        let comp = if phys {
            p.on_compensation
        } else {
            p.off_compensation
        };
        let t = motion.ns(dt - comp);
        self.emit(edges, t, phys);
    }

    fn stop(&mut self, edges: &mut CamEdges, t0: i64) {
        self.emit(edges, t0, false);
        self.live = false;
        self.logic = false;
        self.running = None;
    }

    /// One cycle: the edges of the output in this cycle go to `edges` (cleared first).
    pub fn step(&mut self, motion: &AxisMotion, edges: &mut CamEdges) {
        edges.clear();
        let t0 = motion.t0_ns;
        let enabled = self.owner.is_some();
        let changed = core::mem::take(&mut self.changed);
        let h = self.cap_hysteresis(motion);
        if enabled {
            self.check_inputs(motion);
        }

        if !enabled || self.alarm.is_some() || !motion.valid {
            self.stop(edges, t0);
            self.finish(edges, motion);
            return;
        }

        if !self.live {
            // First activation (or resumption): the state at the cycle start, no compensation.
            self.live = true;
            self.path.reset(motion);
            self.running = None;
            self.arming = if changed {
                self.config.arming_cycles
            } else {
                0
            };
            self.last_edge_ns = self.last_edge_ns.max(t0);
            self.logic = self.distance_state(motion.start.p, self.path.dir, motion);
            let phys = self.physical(self.logic);
            self.emit(edges, t0, phys);
        } else if changed || motion.jump.is_some() {
            // New inputs or a homing jump: re-evaluate at the cycle start.
            if motion.jump.is_some() {
                self.path.reset(motion);
            }
            self.logic = self.distance_state(motion.start.p, self.path.dir, motion);
            let phys = match self.config.cam_type {
                OutputCamType::Distance => self.physical(self.logic),
                OutputCamType::Time => self.physical(self.running.is_some()),
            };
            self.emit(edges, t0, phys);
        }

        let armed = self.arming == 0;
        self.arming = self.arming.saturating_sub(1);
        let mut path = self.path;
        match self.config.cam_type {
            OutputCamType::Distance => self.walk_distance_cam(&mut path, motion, h, edges),
            OutputCamType::Time => self.walk_time_cam(&mut path, motion, (h, armed), edges),
        }
        self.path = path;
        self.finish(edges, motion);
    }

    /// The hysteresis, capped at a quarter of the modulo length or working range.
    fn cap_hysteresis(&mut self, motion: &AxisMotion) -> f64 {
        let cap = max_hysteresis(motion.modulo.map(|m| m.length), self.config.working_range);
        let h_cfg = self.config.parameters.hysteresis;
        let h = cap.map_or(h_cfg, |c| h_cfg.min(c));
        self.status.hysteresis = h;
        self.status.hysteresis_limited = h < h_cfg;
        h
    }

    /// The alarms of an enabled cam's inputs: 704 when the time cam's pulse would be empty,
    /// 702 when the position it follows (the actual value) is not valid.
    fn check_inputs(&mut self, motion: &AxisMotion) {
        // Alarm 704: the time cam's pulse would be empty.
        if self.config.cam_type == OutputCamType::Time && self.alarm.is_none() {
            let p = &self.config.parameters;
            let d = self.input.duration;
            let bad = d <= p.off_compensation - p.on_compensation
                || (self.input.mode == OutputCamMode::Inverted
                    && d <= p.on_compensation - p.off_compensation);
            if bad {
                self.alarm = Some(AlarmInstance::new(
                    AlarmId::OutputCamDataFaulty,
                    supplement::NONE,
                ));
            }
        }
        // Invalid position.
        if !motion.valid
            && self.alarm.is_none()
            && self.config.position_type == PositionType::Actual
        {
            self.alarm = Some(AlarmInstance::new(
                AlarmId::PositionValueInvalid,
                supplement::NONE,
            ));
        }
    }

    /// A distance cam: switches where the effective path enters and leaves the cam's range
    /// (with the configured direction).
    fn walk_distance_cam(
        &mut self,
        path: &mut Path,
        motion: &AxisMotion,
        h: f64,
        edges: &mut CamEdges,
    ) {
        let set = self.range(motion);
        let dir_cfg = self.input.direction;
        path.walk(motion, h, |ev| match ev {
            PathEvent::Move { run, from, to } => {
                let dir = run.dir();
                set.crossings(from, to, |c, entering| {
                    let logic = entering && dir_cfg.enables(dir);
                    if logic != self.logic {
                        self.logic = logic;
                        self.switch_at(edges, motion, run.time_of(c), logic);
                    }
                    true
                });
            }
            PathEvent::Turn { dt, dir, at }
            | PathEvent::Sweep {
                dt, dir, to: at, ..
            } => {
                let logic = set.contains_moving(at, dir) && dir_cfg.enables(dir);
                if logic != self.logic {
                    self.logic = logic;
                    self.switch_at(edges, motion, dt, logic);
                }
            }
        });
    }

    /// A time cam: triggers where the effective path crosses the start point (once armed, in
    /// the configured direction).
    fn walk_time_cam(
        &mut self,
        path: &mut Path,
        motion: &AxisMotion,
        (h, armed): (f64, bool),
        edges: &mut CamEdges,
    ) {
        let (p, period) = self.start_point(motion);
        let dir_cfg = self.input.direction;
        path.walk(motion, h, |ev| {
            let (dt_of, sweep_dt, dir, from, to) = match ev {
                PathEvent::Move { run, from, to } => (Some(run), 0.0, run.dir(), from, to),
                PathEvent::Sweep { dt, dir, from, to } => (None, dt, dir, from, to),
                PathEvent::Turn { .. } => return,
            };
            if !armed || !dir_cfg.enables(dir) {
                return;
            }
            point_crossings(p, period, from, to, |c| {
                let dt = dt_of.map_or(sweep_dt, |r| r.time_of(c));
                self.trigger(edges, motion, dt);
                true
            });
        });
    }

    /// A time cam's start crossed at `t0 + dt`.
    fn trigger(&mut self, edges: &mut CamEdges, motion: &AxisMotion, dt: f64) {
        let t_ns = motion.ns(dt);
        if let Some(r) = self.running {
            if t_ns < r.logical_end_ns {
                return; // not retriggered while on
            }
            if let Some(off) = r.off_edge_ns {
                let phys = self.physical(false);
                self.emit(edges, off, phys);
            }
            self.running = None;
        }
        let p = self.config.parameters;
        let d = self.input.duration;
        self.switch_at(edges, motion, dt, true);
        let phys_off = self.physical(false);
        let comp = if phys_off {
            p.on_compensation
        } else {
            p.off_compensation
        };
        let off = motion.ns(dt + d - comp);
        self.running = Some(Running {
            off_edge_ns: Some(off),
            logical_end_ns: motion.ns(dt + d),
        });
    }

    fn finish(&mut self, edges: &mut CamEdges, motion: &AxisMotion) {
        if let Some(mut r) = self.running {
            if let Some(off) = r.off_edge_ns {
                if off <= motion.t1_ns {
                    let phys = self.physical(false);
                    self.emit(edges, off, phys);
                    r.off_edge_ns = None;
                }
            }
            self.running = if r.off_edge_ns.is_none() && r.logical_end_ns <= motion.t1_ns {
                None
            } else {
                Some(r)
            };
        }
        edges.sort();
        self.status.cam_output = self.output;
        self.status.busy = self.owner.is_some();
        self.status.output_inverted =
            self.owner.is_some() && self.input.mode == OutputCamMode::Inverted;
        self.status.alarm = self.alarm;
    }

    fn range(&self, motion: &AxisMotion) -> RangeSet {
        RangeSet::from_bounds(
            self.input.on_position,
            self.input.off_position,
            motion.modulo,
            true,
            RangeSet::Empty,
        )
    }

    fn start_point(&self, motion: &AxisMotion) -> (f64, Option<f64>) {
        match motion.modulo {
            Some(m) => (m.wrap(self.input.on_position), Some(m.length)),
            None => (self.input.on_position, None),
        }
    }

    fn distance_state(&self, x: f64, dir: i8, motion: &AxisMotion) -> bool {
        self.config.cam_type == OutputCamType::Distance
            && self.range(motion).contains_moving(x, dir)
            && self.input.direction.enables(dir)
    }
}
