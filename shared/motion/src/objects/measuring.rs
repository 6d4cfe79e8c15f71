//! The measuring input technology object (S7-1500T Measuring input and cam functions V5.0 function
//! manual, 3.1 'Measuring input technology object'): `MC_MeasuringInput`,
//! `MC_MeasuringInputCyclic`, `MC_AbortMeasuringInput`.
//!
//! # The interface: one step per cycle
//!
//! Every object of this module and of [`crate::objects::output_cam`] /
//! [`crate::objects::cam_track`] is stepped once per cycle with the motion of its axis over that
//! cycle, an [`AxisMotion`] (see [`crate::kinematics::cycle_motion`]). Output cams and cam tracks
//! treat its `jump` as a sudden position change (S7-1500T Measuring input and cam functions V5.0
//! function manual, 3.2 'Output cam technology object', homing and position jumps, 3.3.1 'Modulo
//! function' (homing)) and do not switch on an invalid position (S7-1500T Measuring input and cam
//! functions V5.0 function manual, 3.2 'Output cam technology object', position reference). Edges
//! come from the hardware or from a simulated sensor ([`crate::plant::sensor::SimulatedSensor`]).
//!
//! # Measuring input
//!
//! Edges arrive as timestamped events ([`InputEdge`], rising or falling, time in ns), given to
//! [`MeasuringInput::step`] in the cycle that contains them (an edge later than `t1_ns` is kept
//! and evaluated in the next cycle). The measured position is the axis position at
//! `t* = t_edge - CorrectionTime` on the interpolated curve of the cycle that contains `t*`; the
//! object keeps the motion of the last [`HISTORY`] cycles for that. An edge that carries the
//! position the hardware latched ([`InputEdge::latched`], a drive's touch probe: route
//! PROFIdrive, the drive latches the position) is measured at that position. Values on modulo axes are
//! reported reduced into the modulo range.
//!
//! Jobs (one active per object; a new one aborts the running one, S7-1500T Measuring input and cam
//! functions V5.0 function manual, 6.1 'MC_MeasuringInput V5' to 6.3 'MC_AbortMeasuringInput V5'
//! and [`crate::catalog::override_table::table3`]):
//!
//! | Instruction | Method | Outputs |
//! |---|---|---|
//! | `MC_MeasuringInput` | [`MeasuringInput::measuring_input`] | [`MeasuringJobStatus`]: `Done`, `Busy`, `CommandAborted`, `Error`, `ErrorID`, `MeasuredValue1/2` (with their edge times) |
//! | `MC_MeasuringInputCyclic` | [`MeasuringInput::measuring_input_cyclic`] | as above plus `MeasuredValue1Counter/2Counter`, `LostEdgeCounter1/2`; no `Done` |
//! | `MC_AbortMeasuringInput` | [`MeasuringInput::abort_measuring_input`] | `Done` at once (`Ok`) |
//! | `MC_Home` on the axis | [`MeasuringInput::axis_homing`] | aborts per table 3 (modes 2, 3, 5, 8, 9, 10) |
//! | `MC_Reset` | [`MeasuringInput::reset`] | acknowledges alarms; `restart` clears the TO data |
//!
//! A job's outputs are read with [`MeasuringInput::job_status`] (the current and the previous job
//! are kept, so an aborted FB sees its `CommandAborted`); the technology data block
//! (`<TO>.Status`, `<TO>.MeasuredValues.*`) with [`MeasuringInput::status`].
//!
//! ErrorIDs: `16#800A` illegal mode, `16#8002` cyclic measuring on a route other than Timer DI,
//! `16#8016` encoder not valid, `16#80A3` PROFIdrive measuring while homing, `16#80A5`/`16#80A6`
//! illegal window start/end. Alarms: 752 (one-time measurement left its window without the edges
//! it waits for: job ends with `Error`, `ErrorID = 16#8001`, `Status = MEASURING_ERROR`), 758 (an
//! edge whose time lies outside the kept motion history was not evaluated).
//!
//! Nothing here allocates; every buffer is a fixed array.

use crate::catalog::alarm::{supplement, AlarmId, AlarmInstance};
use crate::catalog::error_id::ErrorId;
use crate::catalog::override_table::{table3, NewMeasuringJob, RunningMeasuring};
use crate::kinematics::crossing::RangeSet;
use crate::kinematics::cycle_motion::AxisMotion;
use crate::kinematics::modulo::Modulo;
use crate::objects::job::JobId;
use crate::plant::sensor::{InputEdge, InputEdges};

// ---------------------------------------------------------------------------------------------
// Measuring input TO
// ---------------------------------------------------------------------------------------------

/// How the measuring input gets its edges (`Parameter.MeasuringInputType` and hardware route,
/// S7-1500T Measuring input and cam functions V5.0 function manual, A.1.3 '"Parameter" tag
/// (measuring input)').
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum MeasuringRoute {
    /// Timestamps from a TM Timer DIDQ (type 0). The only route that allows cyclic measuring.
    TimerDi,
    /// SINAMICS central probe, timestamps in telegram 39x (type 0). One-time only.
    CentralProbe,
    /// PROFIdrive telegram: the drive latches the position (type 1). One-time only.
    Profidrive,
}

/// Configuration of a measuring input (the TO's `Parameter.*`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MeasuringInputConfig {
    /// Hardware route.
    pub route: MeasuringRoute,
    /// `Parameter.CorrectionTime` (s, 0..1e9): the measured position is the one at
    /// `t_edge - correction_time`.
    pub correction_time: f64,
    /// `Parameter.MeasuringRangeAdditionalActivationTime` (s, >= 0).
    pub additional_activation_time: f64,
    /// Position control cycle `Tservo` (ns, > 0).
    pub servo_cycle_ns: i64,
    /// Bus send clock `TSend` (ns, > 0).
    pub send_cycle_ns: i64,
    /// Apply the hardware activation time ([`MeasuringTiming::effective_after_ns`]): edges
    /// earlier than that after the job start are not seen. `false` measures from the job start.
    pub apply_activation_time: bool,
}

impl MeasuringInputConfig {
    /// Timer DI, no correction, 1 ms cycles, activation time applied.
    pub const fn timer_di(cycle_ns: i64) -> Self {
        Self {
            route: MeasuringRoute::TimerDi,
            correction_time: 0.0,
            additional_activation_time: 0.0,
            servo_cycle_ns: cycle_ns,
            send_cycle_ns: cycle_ns,
            apply_activation_time: true,
        }
    }

    /// The system times of this configuration (S7-1500T Measuring input and cam functions V5.0
    /// function manual, 3.1.3 'Time-related boundary conditions').
    pub fn timing(&self) -> MeasuringTiming {
        MeasuringTiming::new(self.route, self.servo_cycle_ns, self.send_cycle_ns)
    }
}

/// A configuration value of a measuring input, an output cam or a cam track that is out of
/// its range: the object is not built (or the parameters are not written).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum MeasuringConfigError {
    /// `correction_time` outside `0..=1e9` s.
    CorrectionTime,
    /// `additional_activation_time` outside `0..=1e9` s.
    AdditionalActivationTime,
    /// `servo_cycle_ns` not positive.
    ServoCycle,
    /// `send_cycle_ns` not positive.
    SendCycle,
    /// `on_compensation` outside `0..=1e9` s.
    OnCompensation,
    /// `off_compensation` outside `0..=1e9` s.
    OffCompensation,
    /// `hysteresis` outside `0..=1e12`.
    Hysteresis,
    /// The cam track data (length, reference position, a cam's positions or duration).
    CamTrackData,
}

impl MeasuringConfigError {
    /// The name of the configuration value, as in the configuration.
    pub const fn field(self) -> &'static str {
        match self {
            Self::CorrectionTime => "correction_time",
            Self::AdditionalActivationTime => "additional_activation_time",
            Self::ServoCycle => "servo_cycle_ns",
            Self::SendCycle => "send_cycle_ns",
            Self::OnCompensation => "on_compensation",
            Self::OffCompensation => "off_compensation",
            Self::Hysteresis => "hysteresis",
            Self::CamTrackData => "cam track data",
        }
    }
}

impl core::fmt::Display for MeasuringConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "invalid configuration value: {}", self.field())
    }
}

impl std::error::Error for MeasuringConfigError {}

/// The system-inherent times of a measuring route (S7-1500T Measuring input and cam functions V5.0
/// function manual, 3.1.3 'Time-related boundary conditions'), all in ns.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct MeasuringTiming {
    route: MeasuringRoute,
    servo: i64,
    send: i64,
}

impl MeasuringTiming {
    /// Times for a route with position control cycle `servo_ns` and send clock `send_ns`.
    pub const fn new(route: MeasuringRoute, servo_ns: i64, send_ns: i64) -> Self {
        Self {
            route,
            servo: servo_ns,
            send: send_ns,
        }
    }

    /// `Parameter.MeasuringRangeActivationTime` (MRAT): `2 Tservo` (Timer DI, central probe);
    /// PROFIdrive `3 Tservo` when `TSend == Tservo`, else `2 Tservo`.
    pub const fn range_activation_ns(&self) -> i64 {
        match self.route {
            MeasuringRoute::Profidrive if self.send == self.servo => 3 * self.servo,
            _ => 2 * self.servo,
        }
    }

    /// Time from the job start until an edge can be captured: MRAT (Timer DI, central probe);
    /// PROFIdrive `MRAT + 2 Tservo`, or `+ 3 Tservo` for two dedicated edges (modes 3, 4).
    pub const fn effective_after_ns(&self, dedicated_edges: bool) -> i64 {
        match self.route {
            MeasuringRoute::Profidrive => {
                self.range_activation_ns() + if dedicated_edges { 3 } else { 2 } * self.servo
            }
            _ => self.range_activation_ns(),
        }
    }

    /// Time from the edge until the result is shown: one-time `2 Tservo + TSend`, cyclic
    /// `Tservo + TSend` (Timer DI, central probe); PROFIdrive `7 Tservo` (one edge) or
    /// `13 Tservo` (two edges).
    pub const fn result_latency_ns(&self, cyclic: bool, two_edges: bool) -> i64 {
        match self.route {
            MeasuringRoute::Profidrive => {
                if two_edges {
                    13 * self.servo
                } else {
                    7 * self.servo
                }
            }
            _ => {
                if cyclic {
                    self.servo + self.send
                } else {
                    2 * self.servo + self.send
                }
            }
        }
    }

    /// Activation time with a measuring range: `MRAT + MRAAT` (Timer DI, central probe);
    /// PROFIdrive `MRAT + MRAAT + 2 Tservo` (or `+ 3 Tservo` for dedicated edges).
    pub const fn window_activation_ns(&self, additional_ns: i64, dedicated_edges: bool) -> i64 {
        self.effective_after_ns(dedicated_edges) + additional_ns
    }
}

/// `MC_MeasuringInput.Mode` (S7-1500T Measuring input and cam functions V5.0 function manual,
/// 6.1.1 'MC_MeasuringInput: Start measuring once V5').
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum OneTimeMode {
    /// 0: next rising edge.
    Rising = 0,
    /// 1: next falling edge.
    Falling = 1,
    /// 2: next two edges, any polarity.
    TwoEdges = 2,
    /// 3: two edges, rising first, then falling.
    RisingThenFalling = 3,
    /// 4: two edges, falling first, then rising.
    FallingThenRising = 4,
}

impl OneTimeMode {
    /// The mode for a `Mode` input, or `16#800A`.
    pub const fn from_code(code: i32) -> Result<Self, ErrorId> {
        match code {
            0 => Ok(Self::Rising),
            1 => Ok(Self::Falling),
            2 => Ok(Self::TwoEdges),
            3 => Ok(Self::RisingThenFalling),
            4 => Ok(Self::FallingThenRising),
            _ => Err(ErrorId::IllegalMode),
        }
    }

    const fn edges(self) -> u8 {
        match self {
            Self::Rising | Self::Falling => 1,
            _ => 2,
        }
    }

    const fn dedicated(self) -> bool {
        matches!(self, Self::RisingThenFalling | Self::FallingThenRising)
    }
}

/// `MC_MeasuringInputCyclic.Mode` (S7-1500T Measuring input and cam functions V5.0 function manual,
/// 6.2.1 'MC_MeasuringInputCyclic: Start cyclic measuring V5').
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum CyclicMode {
    /// 0: rising edges, up to two per cycle.
    Rising = 0,
    /// 1: falling edges, up to two per cycle.
    Falling = 1,
    /// 2: both: the first rising edge (MeasuredValue1) and the first falling edge
    /// (MeasuredValue2) of each cycle.
    Both = 2,
}

impl CyclicMode {
    /// The mode for a `Mode` input, or `16#800A`.
    pub const fn from_code(code: i32) -> Result<Self, ErrorId> {
        match code {
            0 => Ok(Self::Rising),
            1 => Ok(Self::Falling),
            2 => Ok(Self::Both),
            _ => Err(ErrorId::IllegalMode),
        }
    }
}

/// Measuring range (`MeasuringRange = TRUE`, `StartPosition`, `EndPosition`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MeasuringWindow {
    /// `StartPosition`.
    pub start: f64,
    /// `EndPosition`.
    pub end: f64,
}

impl MeasuringWindow {
    /// The window as a position set: on a linear axis `[min, max]` (Start > End swapped); on a
    /// modulo axis both reduced, and Start > End wraps through the modulo boundary; equal
    /// reduced bounds (e.g. 0 and 360) are the whole revolution.
    pub(crate) fn set(&self, modulo: Option<Modulo>) -> RangeSet {
        RangeSet::from_bounds(self.start, self.end, modulo, false, RangeSet::Full)
    }

    /// `true` if `x` (any representation on a modulo axis) lies in the window.
    pub fn contains(&self, x: f64, modulo: Option<Modulo>) -> bool {
        self.set(modulo).contains(x)
    }
}

/// What the job start needs to know about the axis.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct MeasuringContext {
    /// The encoder's actual value is valid (`StatusSensor.State = VALID`).
    pub encoder_valid: bool,
    /// An MC_Home job is running on the axis.
    pub homing_active: bool,
}

impl MeasuringContext {
    /// Valid encoder, no homing.
    pub const OK: Self = Self {
        encoder_valid: true,
        homing_active: false,
    };
}

/// `<TO>.Status` of a measuring input.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum MeasuringState {
    /// 0 `INACTIVE`.
    Inactive = 0,
    /// 1 `WAITING_FOR_TRIGGER`.
    WaitingForTrigger = 1,
    /// 2 `TRIGGER_OCCURRED`.
    TriggerOccurred = 2,
    /// 3 `MEASURING_ERROR`.
    MeasuringError = 3,
}

/// Which instruction a job runs.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum MeasuringJobKind {
    /// `MC_MeasuringInput`.
    OneTime(OneTimeMode),
    /// `MC_MeasuringInputCyclic`.
    Cyclic(CyclicMode),
}

/// The outputs of a measuring job's FB.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MeasuringJobStatus {
    /// The job.
    pub job: JobId,
    /// Its instruction and mode.
    pub kind: MeasuringJobKind,
    /// `Busy`.
    pub busy: bool,
    /// `Done` (one-time only).
    pub done: bool,
    /// `CommandAborted`.
    pub command_aborted: bool,
    /// `Error`.
    pub error: bool,
    /// `ErrorID` (`16#8001` when alarm 752 ended the job).
    pub error_id: ErrorId,
    /// `MeasuredValue1`.
    pub measured_value1: f64,
    /// `MeasuredValue2`.
    pub measured_value2: f64,
    /// Time of the edge of `MeasuredValue1` (ns), 0 before the first value.
    pub edge_time1_ns: i64,
    /// Time of the edge of `MeasuredValue2` (ns), 0 before the first value.
    pub edge_time2_ns: i64,
    /// `MeasuredValue1Counter` (cyclic), reset at the job start.
    pub counter1: u32,
    /// `MeasuredValue2Counter` (cyclic).
    pub counter2: u32,
    /// `LostEdgeCounter1` (cyclic), 0..=7.
    pub lost_edge_counter1: u8,
    /// `LostEdgeCounter2` (cyclic), 0..=7.
    pub lost_edge_counter2: u8,
}

impl MeasuringJobStatus {
    fn new(job: JobId, kind: MeasuringJobKind) -> Self {
        Self {
            job,
            kind,
            busy: true,
            done: false,
            command_aborted: false,
            error: false,
            error_id: ErrorId::None,
            measured_value1: 0.0,
            measured_value2: 0.0,
            edge_time1_ns: 0,
            edge_time2_ns: 0,
            counter1: 0,
            counter2: 0,
            lost_edge_counter1: 0,
            lost_edge_counter2: 0,
        }
    }
}

/// The technology data block of a measuring input (`<TO>.Status`, `<TO>.MeasuredValues.*`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MeasuringInputStatus {
    /// `<TO>.Status`.
    pub state: MeasuringState,
    /// `<TO>.InputState`: tandem reports whether a job is armed (the signal level is the
    /// caller's).
    pub input_state: bool,
    /// `MeasuredValues.MeasuredValue1` (the last captured value; never reset by a job).
    pub measured_value1: f64,
    /// `MeasuredValues.MeasuredValue2`.
    pub measured_value2: f64,
    /// `MeasuredValues.MeasuredValue1Counter`, 0..=2147483647, wraps to 0; cleared only by a
    /// restart.
    pub counter1: u32,
    /// `MeasuredValues.MeasuredValue2Counter`.
    pub counter2: u32,
    /// `MeasuredValues.LostEdgeCounter1`, 0..=7.
    pub lost_edge_counter1: u8,
    /// `MeasuredValues.LostEdgeCounter2`, 0..=7.
    pub lost_edge_counter2: u8,
    /// The pending technology alarm, if any (`ErrorDetail`).
    pub alarm: Option<AlarmInstance>,
    /// Edges not evaluated because their time was outside the kept motion history (alarm 758).
    pub edges_not_evaluated: u64,
}

/// Number of past cycles whose motion a measuring input keeps for edges that arrive late.
pub const HISTORY: usize = 8;

/// Saturation of the lost-edge counters.
pub const LOST_EDGE_MAX: u8 = 7;

const DB_COUNTER_MAX: u32 = 2_147_483_647;

#[derive(Copy, Clone, Debug, PartialEq)]
enum Active {
    None,
    OneTime {
        mode: OneTimeMode,
        window: Option<MeasuringWindow>,
        captured: u8,
        been_inside: bool,
    },
    Cyclic {
        mode: CyclicMode,
        window: Option<MeasuringWindow>,
    },
}

/// The measuring input technology object (see the module documentation).
#[derive(Clone, Debug)]
pub struct MeasuringInput {
    config: MeasuringInputConfig,
    history: [Option<AxisMotion>; HISTORY],
    hist_next: usize,
    carried: InputEdges,
    active: Active,
    /// The job has not seen a step yet: its start time is the next cycle start.
    pending_start: bool,
    effective_from_ns: i64,
    current: Option<MeasuringJobStatus>,
    previous: Option<MeasuringJobStatus>,
    next_job: JobId,
    status: MeasuringInputStatus,
}

impl MeasuringInput {
    /// A measuring input with the given configuration.
    pub fn new(config: MeasuringInputConfig) -> Result<Self, MeasuringConfigError> {
        if !(config.correction_time >= 0.0 && config.correction_time <= 1e9) {
            return Err(MeasuringConfigError::CorrectionTime);
        }
        if !(config.additional_activation_time >= 0.0 && config.additional_activation_time <= 1e9) {
            return Err(MeasuringConfigError::AdditionalActivationTime);
        }
        if config.servo_cycle_ns <= 0 {
            return Err(MeasuringConfigError::ServoCycle);
        }
        if config.send_cycle_ns <= 0 {
            return Err(MeasuringConfigError::SendCycle);
        }
        Ok(Self {
            config,
            history: [None; HISTORY],
            hist_next: 0,
            carried: InputEdges::default(),
            active: Active::None,
            pending_start: false,
            effective_from_ns: 0,
            current: None,
            previous: None,
            next_job: 1,
            status: MeasuringInputStatus {
                state: MeasuringState::Inactive,
                input_state: false,
                measured_value1: 0.0,
                measured_value2: 0.0,
                counter1: 0,
                counter2: 0,
                lost_edge_counter1: 0,
                lost_edge_counter2: 0,
                alarm: None,
                edges_not_evaluated: 0,
            },
        })
    }

    /// The configuration.
    pub fn config(&self) -> &MeasuringInputConfig {
        &self.config
    }

    /// The technology data block.
    pub fn status(&self) -> &MeasuringInputStatus {
        &self.status
    }

    /// The FB outputs of job `job` (the current or the previous job), or `None`.
    pub fn job_status(&self, job: JobId) -> Option<&MeasuringJobStatus> {
        [self.current.as_ref(), self.previous.as_ref()]
            .into_iter()
            .flatten()
            .find(|s| s.job == job)
    }

    /// The running job, if any.
    pub fn active_job(&self) -> Option<JobId> {
        match self.active {
            Active::None => None,
            _ => self.current.map(|s| s.job),
        }
    }

    fn running_column(&self) -> Option<RunningMeasuring> {
        match self.active {
            Active::None => None,
            Active::OneTime { .. } => Some(RunningMeasuring::MeasuringInput),
            Active::Cyclic { .. } => Some(RunningMeasuring::MeasuringInputCyclic),
        }
    }

    /// Applies table 3 for a new job: the running job ends with `CommandAborted`.
    fn preempt(&mut self, new: NewMeasuringJob) -> bool {
        let Some(col) = self.running_column() else {
            return false;
        };
        if !table3(new, col).aborts() {
            return false;
        }
        if let Some(cur) = self.current.as_mut() {
            cur.busy = false;
            cur.command_aborted = true;
        }
        self.active = Active::None;
        self.status.input_state = false;
        true
    }

    fn check_start(
        &self,
        window: Option<MeasuringWindow>,
        ctx: MeasuringContext,
    ) -> Result<(), ErrorId> {
        if !ctx.encoder_valid {
            return Err(ErrorId::ActualValuesInvalid);
        }
        if ctx.homing_active && self.config.route == MeasuringRoute::Profidrive {
            return Err(ErrorId::MeasuringRejectedHomingActive);
        }
        if let Some(w) = window {
            if !(w.start.is_finite() && w.start.abs() <= 1e12) {
                return Err(ErrorId::IllegalMeasuringStart);
            }
            if !(w.end.is_finite() && w.end.abs() <= 1e12) || w.end == w.start {
                return Err(ErrorId::IllegalMeasuringEnd);
            }
        }
        Ok(())
    }

    fn start_job(&mut self, kind: MeasuringJobKind, active: Active) -> JobId {
        let job = self.next_job;
        self.next_job = self.next_job.wrapping_add(1).max(1);
        if let Some(cur) = self.current.take() {
            self.previous = Some(cur);
        }
        self.current = Some(MeasuringJobStatus::new(job, kind));
        self.active = active;
        self.pending_start = true;
        self.status.state = MeasuringState::WaitingForTrigger;
        self.status.input_state = true;
        job
    }

    /// `MC_MeasuringInput` (rising `Execute`): a one-time measurement of one or two edges,
    /// optionally only inside `window`. Aborts the running job. Takes effect at the next step.
    pub fn measuring_input(
        &mut self,
        mode: OneTimeMode,
        window: Option<MeasuringWindow>,
        ctx: MeasuringContext,
    ) -> Result<JobId, ErrorId> {
        self.check_start(window, ctx)?;
        self.preempt(NewMeasuringJob::MeasuringInput);
        Ok(self.start_job(
            MeasuringJobKind::OneTime(mode),
            Active::OneTime {
                mode,
                window,
                captured: 0,
                been_inside: false,
            },
        ))
    }

    /// `MC_MeasuringInputCyclic` (rising `Execute`): cyclic measuring until aborted; the FB
    /// counters start at 0. Timer DI only (`16#8002` otherwise). Aborts the running job.
    pub fn measuring_input_cyclic(
        &mut self,
        mode: CyclicMode,
        window: Option<MeasuringWindow>,
        ctx: MeasuringContext,
    ) -> Result<JobId, ErrorId> {
        if self.config.route != MeasuringRoute::TimerDi {
            return Err(ErrorId::IllegalObject);
        }
        self.check_start(window, ctx)?;
        self.preempt(NewMeasuringJob::MeasuringInputCyclic);
        Ok(self.start_job(
            MeasuringJobKind::Cyclic(mode),
            Active::Cyclic { mode, window },
        ))
    }

    /// `MC_AbortMeasuringInput`: ends the running job (`CommandAborted`) and sets the TO
    /// inactive. `Ok(true)` if a job was aborted; the abort FB reports `Done` either way.
    pub fn abort_measuring_input(&mut self) -> Result<bool, ErrorId> {
        let aborted = self.preempt(NewMeasuringJob::AbortMeasuringInput);
        if self.status.state != MeasuringState::MeasuringError {
            self.status.state = MeasuringState::Inactive;
        }
        Ok(aborted)
    }

    /// An `MC_Home` job of `mode` started on the axis: modes 2, 3, 5, 8, 9, 10 abort the running
    /// measuring job (table 3). Returns `true` if a job was aborted.
    pub fn axis_homing(&mut self, mode: u8) -> bool {
        let aborted = self.preempt(NewMeasuringJob::from_home_mode(mode));
        if aborted {
            self.status.state = MeasuringState::Inactive;
        }
        aborted
    }

    /// `MC_Reset`: acknowledges the pending alarm (status back to `INACTIVE` after an error).
    /// With `restart` the TO restarts: the running job is aborted and the measured values,
    /// counters and lost-edge counters of the data block are cleared.
    pub fn reset(&mut self, restart: bool) {
        self.status.alarm = None;
        if self.status.state == MeasuringState::MeasuringError {
            self.status.state = MeasuringState::Inactive;
        }
        if restart {
            if self.preempt(NewMeasuringJob::AbortMeasuringInput) {
                self.status.state = MeasuringState::Inactive;
            }
            self.status.state = MeasuringState::Inactive;
            self.status.measured_value1 = 0.0;
            self.status.measured_value2 = 0.0;
            self.status.counter1 = 0;
            self.status.counter2 = 0;
            self.status.lost_edge_counter1 = 0;
            self.status.lost_edge_counter2 = 0;
            self.carried.clear();
        }
    }

    /// The axis position at absolute time `t_ns - correction` (s), from the current motion or
    /// the history; `None` if no kept cycle contains it.
    fn position_at(&self, motion: &AxisMotion, t_ns: i64) -> Option<f64> {
        let corr = self.config.correction_time;
        let probe = |m: &AxisMotion| -> Option<f64> {
            let dt = t_ns.saturating_sub(m.t0_ns) as f64 * 1e-9 - corr;
            let h = m.duration();
            if dt >= 0.0 && dt <= h {
                Some(m.at(dt).p)
            } else {
                None
            }
        };
        if let Some(p) = probe(motion) {
            return Some(p);
        }
        // Newest first.
        for i in 1..=HISTORY {
            let idx = (self.hist_next + HISTORY - i) % HISTORY;
            if let Some(m) = self.history.get(idx).copied().flatten() {
                if let Some(p) = probe(&m) {
                    return Some(p);
                }
            }
        }
        None
    }

    /// One cycle: evaluates the edges of this cycle (`edges`, any order; edges later than
    /// `motion.t1_ns` are kept for the next cycle) against the motion of the axis.
    pub fn step(&mut self, motion: &AxisMotion, edges: &[InputEdge]) {
        if self.pending_start {
            self.pending_start = false;
            let dedicated = matches!(self.active, Active::OneTime { mode, .. } if mode.dedicated());
            let mut from = motion.t0_ns;
            if self.config.apply_activation_time {
                from += self.config.timing().effective_after_ns(dedicated);
            }
            self.effective_from_ns = from;
        }
        // This cycle's edges: the carried ones and the new ones, in time order.
        let mut now = InputEdges::default();
        let mut later = InputEdges::default();
        for e in self.carried.as_slice().iter().chain(edges.iter()) {
            if e.time_ns <= motion.t1_ns {
                now.push(*e);
            } else {
                later.push(*e);
            }
        }
        self.status.edges_not_evaluated += now.dropped + later.dropped;
        self.carried = later;
        now.sort();

        match self.active {
            Active::None => {}
            Active::OneTime { .. } => self.one_time_cycle(motion, now.as_slice()),
            Active::Cyclic { mode, window } => {
                self.cyclic_cycle(motion, now.as_slice(), mode, window)
            }
        }

        self.history[self.hist_next % HISTORY] = Some(*motion);
        self.hist_next = (self.hist_next + 1) % HISTORY;
    }

    /// Position of edge `e` if it counts (after the activation time, inside the window);
    /// reduced into the modulo range.
    fn measure(
        &mut self,
        motion: &AxisMotion,
        e: &InputEdge,
        window: Option<MeasuringWindow>,
    ) -> Option<f64> {
        if e.time_ns < self.effective_from_ns {
            return None;
        }
        // A position latched by the hardware (a drive's touch probe) is the measured value.
        let Some(p) = e.latched.or_else(|| self.position_at(motion, e.time_ns)) else {
            self.status.edges_not_evaluated += 1;
            self.status.alarm = Some(AlarmInstance::new(
                AlarmId::MeasuringEdgeNotEvaluated,
                supplement::NONE,
            ));
            return None;
        };
        if let Some(w) = window {
            if !w.contains(p, motion.modulo) {
                return None;
            }
        }
        Some(match motion.modulo {
            Some(m) => m.wrap(p),
            None => p,
        })
    }

    fn one_time_cycle(&mut self, motion: &AxisMotion, edges: &[InputEdge]) {
        let Active::OneTime {
            mode,
            window,
            mut captured,
            mut been_inside,
        } = self.active
        else {
            return;
        };
        let need = mode.edges();
        for e in edges {
            if captured >= need {
                break;
            }
            let wanted = match (mode, captured) {
                (OneTimeMode::Rising, _) => e.rising,
                (OneTimeMode::Falling, _) => !e.rising,
                (OneTimeMode::TwoEdges, _) => true,
                (OneTimeMode::RisingThenFalling, 0) => e.rising,
                (OneTimeMode::RisingThenFalling, _) => !e.rising,
                (OneTimeMode::FallingThenRising, 0) => !e.rising,
                (OneTimeMode::FallingThenRising, _) => e.rising,
            };
            if !wanted {
                continue;
            }
            let Some(p) = self.measure(motion, e, window) else {
                continue;
            };
            captured += 1;
            if let Some(cur) = self.current.as_mut() {
                if captured == 1 {
                    cur.measured_value1 = p;
                    cur.edge_time1_ns = e.time_ns;
                } else {
                    cur.measured_value2 = p;
                    cur.edge_time2_ns = e.time_ns;
                }
            }
            if captured == 1 {
                self.status.measured_value1 = p;
            } else {
                self.status.measured_value2 = p;
            }
        }
        if captured >= need {
            if let Some(cur) = self.current.as_mut() {
                cur.busy = false;
                cur.done = true;
            }
            self.active = Active::None;
            self.status.state = MeasuringState::TriggerOccurred;
            self.status.input_state = false;
            return;
        }
        if let Some(w) = window {
            let set = w.set(motion.modulo);
            let mut touched = false;
            motion.for_each_run(|run| touched |= set.touches(run.xa, run.xb));
            been_inside |= touched || set.contains(motion.start.p);
            if been_inside && !set.contains(motion.end.p) {
                // Left the window without the edges: cancelled with alarm 752.
                if let Some(cur) = self.current.as_mut() {
                    cur.busy = false;
                    cur.error = true;
                    cur.error_id = ErrorId::TechnologyAlarm;
                }
                self.active = Active::None;
                self.status.state = MeasuringState::MeasuringError;
                self.status.input_state = false;
                self.status.alarm = Some(AlarmInstance::new(
                    AlarmId::MeasuringRangeNotRecognized,
                    supplement::NONE,
                ));
                return;
            }
        }
        self.active = Active::OneTime {
            mode,
            window,
            captured,
            been_inside,
        };
    }

    fn cyclic_cycle(
        &mut self,
        motion: &AxisMotion,
        edges: &[InputEdge],
        mode: CyclicMode,
        window: Option<MeasuringWindow>,
    ) {
        // Matching edges of this cycle: the captured ones and the count of the others.
        let mut v1: Option<(f64, i64)> = None;
        let mut v2: Option<(f64, i64)> = None;
        let mut matching: u32 = 0;
        for e in edges {
            let wanted = match mode {
                CyclicMode::Rising => e.rising,
                CyclicMode::Falling => !e.rising,
                CyclicMode::Both => true,
            };
            if !wanted {
                continue;
            }
            let Some(p) = self.measure(motion, e, window) else {
                continue;
            };
            matching += 1;
            match mode {
                CyclicMode::Rising | CyclicMode::Falling => {
                    if v1.is_none() {
                        v1 = Some((p, e.time_ns));
                    } else if v2.is_none() {
                        v2 = Some((p, e.time_ns));
                    }
                }
                CyclicMode::Both => {
                    if e.rising && v1.is_none() {
                        v1 = Some((p, e.time_ns));
                    } else if !e.rising && v2.is_none() {
                        v2 = Some((p, e.time_ns));
                    }
                }
            }
        }
        let captured = u32::from(v1.is_some()) + u32::from(v2.is_some());
        let lost = matching
            .saturating_sub(captured)
            .min(u32::from(LOST_EDGE_MAX)) as u8;
        let db = &mut self.status;
        if let Some((p, t)) = v1 {
            db.measured_value1 = p;
            db.counter1 = if db.counter1 >= DB_COUNTER_MAX {
                0
            } else {
                db.counter1 + 1
            };
            db.lost_edge_counter1 = lost;
            if let Some(cur) = self.current.as_mut() {
                cur.measured_value1 = p;
                cur.edge_time1_ns = t;
                cur.counter1 = cur.counter1.wrapping_add(1);
                cur.lost_edge_counter1 = lost;
            }
        }
        if let Some((p, t)) = v2 {
            db.measured_value2 = p;
            db.counter2 = if db.counter2 >= DB_COUNTER_MAX {
                0
            } else {
                db.counter2 + 1
            };
            db.lost_edge_counter2 = lost;
            if let Some(cur) = self.current.as_mut() {
                cur.measured_value2 = p;
                cur.edge_time2_ns = t;
                cur.counter2 = cur.counter2.wrapping_add(1);
                cur.lost_edge_counter2 = lost;
            }
        }
    }
}
