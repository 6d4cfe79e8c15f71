//! The axis technology object: speed axis and positioning axis with the PLCopen state machine,
//! the jobs of the S7-1500T Motion Control V4.0 function manual (chapter 10 'Instructions'), its
//! monitoring functions and technology alarms, over a simulated drive. One call of [`Axis::step`]
//! is one servo/interpolator cycle; commands are applied between cycles with [`Axis::command`].
//! Nothing here allocates after [`Axis::new`].
//!
//! Positions are kept continuous (unwrapped) inside; modulo positions are what the status shows.

mod adjustment;
mod buffer;
mod command;
mod config;
mod hyd_commands;
mod hyd_direct;
mod hyd_home;
mod hyd_joystick;
mod hyd_slow_down;
mod hydraulic;
mod params;
mod step;
mod sync;
mod torque;

pub use adjustment::{AbsoluteOffset, RestoreOffsetError};
pub use buffer::JOB_QUEUE_CAPACITY;
pub use command::{
    ApplicationMode, BufferMode, BufferedMotion, CamId, Command, Direction, HydJogMode, StartMode,
    StopMode, SyncDirection, SyncProfileReference, VelocityDirection,
};
pub use config::{
    AxisConfig, AxisConfigError, AxisConfigProblem, AxisKind, EncoderType,
    FollowingErrorMonitoring, HomingConfig, HomingMark, HydraulicProfile, MotionType,
    PassiveDirection, PositioningMonitoring, Sense, SoftwareLimits, StandstillSignal, TorqueConfig,
    JOG_VELO_DEFAULTS,
};
pub use hyd_home::{
    resolve as resolve_hyd_homing, HomingAxis, HomingInput, HomingMethod, HomingOutput,
    HomingPhase, HomingSequence, HydHomeInputs, HydHomeRefusal, HydHomingMode, HydHomingParams,
    HydHomingParamsError, HydHomingType, BLOCK_DETECT_DELAY_DEFAULT,
};
pub use hydraulic::HydraulicStatus;
pub use params::{axis_parameter, axis_parameter_number, AxisParams, ParamExtras, AXIS_PARAMETERS};
pub use sync::flying::{FlyingGear, FlyingGearError, FlyingGearParams, FlyingPhase, FlyingPoint};
pub use torque::{TorqueStatus, TORQUE_VALUE_MAX};

use crate::catalog::alarm::{supplement, AlarmId, AlarmInstance, ErrorDetail, Reaction};
use crate::catalog::error_id::ErrorId;
use crate::catalog::override_table::{table1, NewJob, RunningMotion};
use crate::kinematics::dynamics::{Clamped, Dynamics};
use crate::kinematics::extrapolation::{Extrapolated, Extrapolator};
use crate::kinematics::modulo::Modulo;
use crate::kinematics::profile::{
    plan_position, plan_position_velocity, plan_velocity, Limits, Profile, State,
};
use crate::objects::job::{EventQueue, Instruction, JobEvent, JobEventKind, JobId};
use crate::objects::leading::LeadingValue;
use crate::plant::link::{AxisSignals, DriveInputs, DriveLink, DriveOutputs, SimPlant};
use std::cell::{Cell, OnceCell};

/// PLCopen axis states (S7-1500T Motion Control V4.0 function manual, A.2.35 'StatusWord tag' (the
/// manual draws no state diagram), PLCopen Motion Control part 1, axis state diagram).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum AxisState {
    /// Not enabled.
    Disabled,
    /// Enabled, no motion job.
    Standstill,
    /// Active homing.
    Homing,
    /// A positioning or halt job (MoveAbsolute, MoveRelative, Halt, superimposed alone).
    DiscreteMotion,
    /// A velocity, jog or MotionIn job.
    ContinuousMotion,
    /// Following a leader (synchronous axis).
    SynchronizedMotion,
    /// MC_Stop active (the axis is locked).
    Stopping,
    /// A technology alarm with a stopping reaction is pending.
    ErrorStop,
}

impl AxisState {
    /// PLCopen name.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Disabled => "Disabled",
            Self::Standstill => "Standstill",
            Self::Homing => "Homing",
            Self::DiscreteMotion => "DiscreteMotion",
            Self::ContinuousMotion => "ContinuousMotion",
            Self::SynchronizedMotion => "SynchronizedMotion",
            Self::Stopping => "Stopping",
            Self::ErrorStop => "ErrorStop",
        }
    }
}

/// A snapshot of everything an axis shows, taken at the end of each cycle.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AxisStatus {
    /// Cycle time (ns).
    pub time_ns: i64,
    /// PLCopen state.
    pub state: AxisState,
    /// `StatusWord` (bits in [`status_bit`]).
    pub status_word: u32,
    /// `ErrorWord`.
    pub error_word: u32,
    /// `WarningWord`.
    pub warning_word: u32,
    /// `ErrorDetail`.
    pub error_detail: ErrorDetail,
    /// `Position` setpoint (modulo-reduced).
    pub position: f64,
    /// `Velocity` setpoint.
    pub velocity: f64,
    /// `Acceleration` setpoint.
    pub acceleration: f64,
    /// `ActualPosition` (modulo-reduced).
    pub actual_position: f64,
    /// `ActualVelocity`.
    pub actual_velocity: f64,
    /// `StatusPositioning.FollowingError`.
    pub following_error: f64,
    /// `Override.Velocity` (%).
    pub override_velocity: f64,
    /// Setpoint position, continuous (not reduced).
    pub position_unwrapped: f64,
    /// Actual position, continuous (not reduced).
    pub actual_position_unwrapped: f64,
    /// The running basic-motion job.
    pub motion_job: Option<(JobId, Instruction)>,
    /// The running superimposed job.
    pub superimposed_job: Option<(JobId, Instruction)>,
    /// The active synchronous operation job.
    pub sync_job: Option<(JobId, Instruction)>,
    /// `StatusSynchronizedMotion.FunctionState`: one of [`sync_function`] (0 none, 1 GearIn,
    /// 2 GearInPos, 3 CamIn).
    pub sync_function: u8,
    /// `StatusSynchronizedMotion.StatusWord`: the bits of [`sync_status`] (bit 0
    /// MaxVelocityExceeded, 1 MaxAccelerationExceeded, 2 MaxDecelerationExceeded, 3 simulated).
    pub sync_status_word: u8,
    /// `StatusSynchronizedMotion.PhaseShift`.
    pub phase_shift: f64,
    /// Jobs queued behind the running one (PLCopen `BufferMode`), at most
    /// [`JOB_QUEUE_CAPACITY`].
    pub queue_depth: u32,
}

/// The values of [`AxisStatus::sync_function`] (`StatusSynchronizedMotion.FunctionState`), as
/// they appear in traces and on the wire.
pub mod sync_function {
    /// 0: no synchronous operation.
    pub const NONE: u8 = 0;
    /// 1: relative gearing (MC_GearIn).
    pub const GEAR_IN: u8 = 1;
    /// 2: absolute gearing (MC_GearInPos).
    pub const GEAR_IN_POS: u8 = 2;
    /// 3: camming (MC_CamIn).
    pub const CAM_IN: u8 = 3;
}

/// The bits of [`AxisStatus::sync_status_word`] (`StatusSynchronizedMotion.StatusWord`).
pub mod sync_status {
    /// Bit 0 "MaxVelocityExceeded": the coupled setpoint exceeds the axis' maximum velocity.
    pub const MAX_VELOCITY_EXCEEDED: u8 = 1 << 0;
    /// Bit 1 "MaxAccelerationExceeded": it exceeds the maximum acceleration.
    pub const MAX_ACCELERATION_EXCEEDED: u8 = 1 << 1;
    /// Bit 2 "MaxDecelerationExceeded": it exceeds the maximum deceleration.
    pub const MAX_DECELERATION_EXCEEDED: u8 = 1 << 2;
    /// Bit 3: the synchronous operation runs simulated (MC_SynchronizedMotionSimulation); the
    /// coupling goes on logically while the follower stands.
    pub const SIMULATION: u8 = 1 << 3;
    /// Bit 4: `StartSync` of MC_FlyingGear_BkPlcMc (the leader is in the engage section).
    #[doc(alias = "StartSync")]
    pub const FLYING_START_SYNC: u8 = 1 << 4;
    /// Bit 5: `InSync` of MC_FlyingGear_BkPlcMc (fully coupled).
    #[doc(alias = "InSync")]
    pub const FLYING_IN_SYNC: u8 = 1 << 5;
    /// Bit 6: `Active` of MC_FlyingGear_BkPlcMc (from the sync point until the follower reaches
    /// its stop position).
    #[doc(alias = "Active")]
    pub const FLYING_ACTIVE: u8 = 1 << 6;
}

impl AxisStatus {
    /// Tests a [`status_bit`].
    pub fn has(&self, bit: u32) -> bool {
        self.status_word & bit != 0
    }
}

/// Why the basic setpoint moves.
#[derive(Copy, Clone, Debug, PartialEq)]
enum Goal {
    /// Hold the current position.
    Hold,
    /// To `target` (continuous coordinates), at rest or, blending into a queued job, passing it
    /// at `end_v` (signed); velocities scaled by the override.
    Position {
        target: f64,
        lim: Limits,
        end_v: f64,
    },
    /// To the velocity `v` (scaled by the override).
    Velocity { v: f64, lim: Limits },
    /// To standstill, not scaled by the override.
    Stop { lim: Limits },
    /// Direct setpoints (MotionIn); `position` is `None` for MotionInVelocity.
    Direct {
        position: Option<f64>,
        v: f64,
        a: f64,
    },
    /// Disabled: the setpoint follows the actual value.
    Track,
    /// Synchronous operation: the setpoint is the coupling function of the leading value.
    Sync,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum HomePhase {
    /// Looking for the reference cam.
    Search,
    /// On the cam, moving in the homing direction until it is left.
    OnCam,
    /// Armed: the next mark in the homing direction homes the axis.
    Armed,
    /// Homed; travelling to the home position.
    Travel,
}

#[derive(Copy, Clone, Debug, PartialEq)]
struct ActiveHoming {
    /// Axis position given to the mark (end position minus the home position offset).
    home: f64,
    /// Where the axis travels after homing (`Position` or `Homing.HomePosition`).
    end: f64,
    phase: HomePhase,
    search_dir: f64,
    reversals: u8,
}

#[derive(Copy, Clone, Debug, PartialEq)]
struct PassiveHoming {
    job: JobId,
    home: f64,
    phase: HomePhase,
    /// Direction of travel when the cam was left (for the re-arm rule).
    armed_dir: f64,
}

#[derive(Copy, Clone, Debug, PartialEq)]
struct MotionJob {
    id: JobId,
    instr: Instruction,
    in_velocity: bool,
    /// Positioning monitoring started (the setpoint reached its target or stop).
    monitoring: Option<PosMon>,
    homing: Option<ActiveHoming>,
    /// MoveJog: which inputs are held.
    jog: (bool, bool),
    /// Dynamics of the job (for reaction 1 and jog stops).
    lim: Limits,
}

#[derive(Copy, Clone, Debug, PartialEq)]
struct PosMon {
    target: f64,
    start_ns: i64,
    entered_ns: Option<i64>,
}

/// A superimposed job: its profile (kept apart in the axis, read only while the job runs)
/// starts at `t0`.
#[derive(Copy, Clone, Debug, PartialEq)]
struct SupJob {
    id: JobId,
    t0: i64,
}

const MAX_ALARMS: usize = 12;

/// Power sequencing.
#[derive(Copy, Clone, Debug, PartialEq)]
struct Power {
    enable: bool,
    start_mode: StartMode,
    stop_mode: StopMode,
    job: JobId,
    /// A user disable is braking before the enable is removed.
    disabling: bool,
    /// A connected drive was asked for its enable and is not operational yet.
    awaiting_drive: bool,
    /// MC_Reset asked the connected drive to acknowledge its fault (sent with the next outputs).
    fault_reset: bool,
    /// The enable being awaited follows a fault reset: the drive may still report its fault
    /// until it has processed the reset.
    after_reset: bool,
    /// The enable was removed to stop on the drive's own ramp (StopMode 1, alarm reactions 4
    /// and 5): a connected drive is asked for its quick stop ([`DriveOutputs::quick_stop`]).
    quick_stop: bool,
}

/// An axis technology object with its drive connection.
///
/// The fields are in this order (`repr(C)`) so that what every cycle of every axis reads and
/// writes lies together (a node steps a thousand axes a millisecond: their state does not stay
/// in the caches between two cycles): the job events' counts (at the end of the queue), the
/// state, the running jobs and the synchronous jobs' discriminants; then what followers and
/// running jobs read; then what is read seldom. Aligned to a cache line, so that every axis of
/// a `Vec` has the same lines (and no axis shares one with the next).
#[derive(Clone, Debug)]
#[repr(C, align(64))]
pub struct Axis {
    /// Job events (their counts last: next to the state below).
    events: EventQueue,
    now: i64,
    t0: i64,
    basic: State,
    sup: State,
    /// Axis position = physical position + offset.
    offset: f64,
    actual_p: f64,
    actual_v: f64,
    prev_phys: f64,
    fe: f64,
    override_pct: f64,
    /// Phase shift state (leading value units).
    phase: State,
    /// Offset of the following value (MC_OffsetAbsolute/Relative), follower units.
    shift_out: State,
    goal: Goal,
    standstill_since: Option<i64>,
    hw_trigger: Option<(Sense, f64)>,
    power: Power,
    enabled: bool,
    /// The connected drive works at its own limit (StatusWord X27 "InLimitation").
    in_limitation: bool,
    /// A torque job is active (`torque` has one): the cycle looks at `torque` only then.
    torque_active: bool,
    pos_ctrl: bool,
    homed: bool,
    stop_lock: bool,
    actual_output: bool,
    /// Whether `alarms` has one (kept with it, so the cycle need not scan the slots).
    alarm_pending: bool,
    sw_active: Option<Sense>,
    sync_flags: u8,
    /// MC_SynchronizedMotionSimulation running (its job).
    sync_sim: Option<JobId>,
    /// The input signals of the last cycle.
    signals: AxisSignals,
    passive: Option<PassiveHoming>,
    sup_job: Option<SupJob>,
    phasing: Option<sync::PhasingJob>,
    offset_job: Option<sync::PhasingJob>,
    main: Option<MotionJob>,
    /// A hydraulic axis' generator and target window ([`AxisConfig::hydraulic`]): read every
    /// cycle (`None` for an electric axis), so with the hot fields.
    hyd: Option<Box<hydraulic::HydAxis>>,
    /// Leading values for this cycle: of the active and of the pending job's leader.
    lead: [Option<crate::objects::leading::LeadingValue>; 2],
    /// Whether `status` holds the status (so that a cycle need not look at it).
    status_kept: Cell<bool>,
    /// The drive (every cycle samples and steps it) and the configuration (its per-cycle
    /// fields first), next to the state so that a cycle's lines are mostly consecutive.
    link: DriveLink,
    cfg: AxisConfig,
    sync_pending: Option<sync::SyncJob>,
    sync: Option<sync::SyncJob>,
    prof: Profile,
    /// Cams of the active and the pending CamIn, with their mappings.
    cams: [Option<std::sync::Arc<crate::cam::Cam>>; 2],
    cam_maps: [Option<sync::CamMap>; 2],
    /// The status after the last cycle or command, computed when first read (most cycles
    /// nobody reads it): emptied by [`Axis::step`] and [`Axis::command`], pinned before a
    /// change between them that must not show until then ([`Axis::raise`]).
    status: OnceCell<AxisStatus>,
    /// The profiles of `sup_job`, `phasing` and `offset_job` (meaningful while they run).
    sup_prof: Profile,
    phasing_prof: Profile,
    offset_prof: Profile,
    /// The actual value prepared for actual-value coupling (run only while a follower may use
    /// it: [`Axis::set_actual_value_output`]).
    extrapolator: Extrapolator,
    alarms: [Option<AlarmInstance>; MAX_ALARMS],
    /// The cam handed over for the next MC_CamIn.
    provided_cam: Option<(CamId, std::sync::Arc<crate::cam::Cam>)>,
    next_id: JobId,
    /// The absolute encoder adjustment (MC_Home 6/7), retained by the runtime.
    absolute: AbsoluteOffset,
    /// Jobs queued behind `main` (PLCopen BufferMode); read only when a job ends.
    queue: buffer::JobQueue,
    /// MC_TorqueLimiting, MC_TorqueAdditive and MC_TorqueRange (read by the cycle only while
    /// `torque_active`).
    torque: torque::TorqueJobs,
    /// The run-time parameters kept beside `cfg` (MC_WriteParameter).
    param_extra: ParamExtras,
}

fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

impl Axis {
    /// Builds an axis from a validated configuration, disabled, at rest.
    pub fn new(cfg: AxisConfig) -> Result<Self, AxisConfigError> {
        cfg.validate()?;
        let link = DriveLink::Simulation(SimPlant::new(
            cfg.drive,
            cfg.plant,
            cfg.cycle,
            cfg.defaults.emergency_deceleration,
            cfg.initial_position,
        ));
        let p0 = cfg.initial_position;
        let absolute = AbsoluteOffset::initial(cfg.encoder);
        Ok(Self {
            link,
            signals: AxisSignals::default(),
            power: Power {
                enable: false,
                start_mode: StartMode::PositionControlled,
                stop_mode: StopMode::Emergency,
                job: 0,
                disabling: false,
                awaiting_drive: false,
                fault_reset: false,
                after_reset: false,
                quick_stop: false,
            },
            enabled: false,
            in_limitation: false,
            torque_active: false,
            pos_ctrl: false,
            offset: 0.0,
            absolute,
            homed: absolute.adjusted,
            basic: State::rest(p0),
            sup: State::default(),
            goal: Goal::Track,
            prof: Profile::hold(State::rest(p0)),
            t0: 0,
            override_pct: 100.0,
            main: None,
            sup_job: None,
            passive: None,
            stop_lock: false,
            sync: None,
            sync_pending: None,
            phasing: None,
            phase: State::default(),
            offset_job: None,
            sup_prof: Profile::hold(State::default()),
            phasing_prof: Profile::hold(State::default()),
            offset_prof: Profile::hold(State::default()),
            sync_sim: None,
            cams: [None, None],
            cam_maps: [None; 2],
            provided_cam: None,
            shift_out: State::default(),
            lead: [None; 2],
            sync_flags: 0,
            extrapolator: Extrapolator::new(cfg.extrapolation, cfg.cycle),
            actual_output: false,
            alarms: [None; MAX_ALARMS],
            alarm_pending: false,
            hw_trigger: None,
            sw_active: None,
            standstill_since: None,
            fe: 0.0,
            actual_p: p0,
            actual_v: 0.0,
            prev_phys: p0,
            events: EventQueue::default(),
            next_id: 1,
            queue: buffer::JobQueue::default(),
            torque: torque::TorqueJobs::default(),
            hyd: cfg
                .hydraulic
                .as_ref()
                .and_then(|h| hydraulic::HydAxis::new(h, p0)),
            now: 0,
            status: OnceCell::new(),
            status_kept: Cell::new(false),
            param_extra: ParamExtras::new(&cfg),
            cfg,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &AxisConfig {
        &self.cfg
    }

    /// The status after the last cycle (or command).
    pub fn status(&self) -> &AxisStatus {
        self.status_kept.set(true);
        self.status.get_or_init(|| self.current_status())
    }

    /// The status if it was built since the last cycle or command.
    fn kept_status(&self) -> Option<&AxisStatus> {
        if self.status_kept.get() {
            self.status.get()
        } else {
            None
        }
    }

    /// Forgets the status (the end of a cycle or command).
    fn forget_status(&mut self) {
        if self.status_kept.get() {
            self.status = OnceCell::new();
            self.status_kept.set(false);
        }
    }

    /// The status after the last cycle (or command), as [`Axis::status`] has it, by value:
    /// for a caller that keeps its own copy (it is not kept here too).
    pub fn status_value(&self) -> AxisStatus {
        match self.kept_status() {
            Some(s) => *s,
            None => self.current_status(),
        }
    }

    /// Takes the oldest pending job event.
    pub fn pop_event(&mut self) -> Option<JobEvent> {
        self.events.pop()
    }

    /// Whether a job event is pending (as `pop_event().is_some()`, without taking it).
    pub fn has_events(&self) -> bool {
        !self.events.is_empty()
    }

    /// Whether a technology alarm is pending (as `alarms().next().is_some()`, without scanning).
    pub fn alarm_pending(&self) -> bool {
        self.alarm_pending
    }

    /// Pending technology alarms.
    pub fn alarms(&self) -> impl Iterator<Item = AlarmInstance> + '_ {
        self.alarms.iter().flatten().copied()
    }

    /// Whether the alarm `id` is pending.
    pub fn has_alarm(&self, id: AlarmId) -> bool {
        // `alarm_pending` is kept with the slots: without it no slot need be scanned (the
        // software limits ask every cycle).
        self.alarm_pending && self.alarms().any(|a| a.id == id)
    }

    /// This axis as a leader with setpoint coupling: its total setpoint (continuous position).
    pub fn setpoint_leading_value(&self) -> LeadingValue {
        // The total setpoint as the status shows it, without building the status: unless the
        // status was pinned, the setpoint has not changed since the last cycle or command.
        let s = match self.kept_status() {
            Some(s) => State {
                p: s.position_unwrapped,
                v: s.velocity,
                a: s.acceleration,
            },
            None => self.total(),
        };
        LeadingValue {
            p: s.p,
            v: s.v,
            a: s.a,
            modulo: self.cfg.modulo,
        }
    }

    /// Runs the extrapolation of the actual value every cycle (for followers coupled by actual
    /// value); switched on by the runtime for the axes that lead that way.
    pub fn set_actual_value_output(&mut self, on: bool) {
        if on && !self.actual_output {
            self.extrapolator.reset(self.actual_p, self.actual_v);
        }
        self.actual_output = on;
    }

    /// This axis as a leader with actual-value coupling: its actual value filtered and
    /// extrapolated (`StatusExtrapolation`, see [`crate::kinematics::extrapolation`]); the plain
    /// actual value while [`Axis::set_actual_value_output`] is off.
    pub fn actual_leading_value(&self) -> LeadingValue {
        if !self.actual_output {
            return LeadingValue {
                p: self.actual_p,
                v: self.actual_v,
                a: 0.0,
                modulo: self.cfg.modulo,
            };
        }
        let e = self.extrapolator.last();
        LeadingValue {
            p: e.position,
            v: e.velocity,
            a: e.acceleration,
            modulo: self.cfg.modulo,
        }
    }

    /// `StatusExtrapolation`.
    pub fn extrapolation_status(&self) -> Extrapolated {
        self.extrapolator.last()
    }

    /// Job events dropped because nobody drained them.
    pub fn dropped_events(&self) -> u64 {
        self.events.dropped()
    }

    // ----------------------------------------------------------------------------------------
    // helpers

    fn new_id(&mut self) -> JobId {
        let id = self.next_id;
        self.next_id = self.next_id.wrapping_add(1).max(1);
        id
    }

    fn emit(&mut self, job: JobId, instruction: Instruction, kind: JobEventKind) {
        self.events.push(JobEvent {
            job,
            instruction,
            kind,
            time_ns: self.now,
        });
    }

    fn wrap(&self, p: f64) -> f64 {
        match self.cfg.modulo {
            Some(m) => m.wrap(p),
            None => p,
        }
    }

    fn total(&self) -> State {
        State {
            p: self.basic.p + self.sup.p,
            v: self.basic.v + self.sup.v,
            a: self.basic.a + self.sup.a,
        }
    }

    fn elapsed(&self, t0: i64) -> f64 {
        (self.now - t0) as f64 * 1e-9
    }

    fn max_limits(&self) -> Limits {
        self.cfg.limits.as_limits()
    }

    fn default_limits(&self) -> Limits {
        let d = &self.cfg.defaults;
        Limits {
            vel: d.velocity,
            acc: d.acceleration,
            dec: d.deceleration,
            jerk: d.jerk,
        }
    }

    fn emergency_limits(&self) -> Limits {
        let d = self.cfg.defaults.emergency_deceleration;
        Limits {
            vel: self.cfg.limits.max_velocity.max(1e-9),
            acc: d,
            dec: d,
            jerk: 0.0,
        }
    }

    fn stopping_alarm_pending(&self) -> bool {
        self.alarms().any(|a| a.reaction != Reaction::None)
    }

    fn warn_clamped(&mut self, c: Clamped) {
        if c.velocity {
            self.raise_alarm(AlarmId::VelocityLimited, supplement::NONE);
        }
        if c.acceleration {
            self.raise_alarm(AlarmId::AccelerationLimited, supplement::NONE);
        }
        if c.jerk {
            self.raise_alarm(AlarmId::JerkLimited, supplement::NONE);
        }
    }

    /// Plans the current goal from the current basic setpoint at the current time.
    fn replan(&mut self) {
        if self.hyd_replan() {
            return;
        }
        let s = self.basic;
        let ovr = self.override_pct / 100.0;
        let planned = match self.goal {
            Goal::Sync => {
                // The coupling law computes the setpoint (and owns the profile slot).
                return;
            }
            Goal::Hold | Goal::Direct { .. } | Goal::Track => {
                self.basic = State { a: 0.0, ..s };
                Ok(Profile::hold(self.basic))
            }
            Goal::Position { target, lim, end_v } => {
                if ovr > 0.0 && end_v != 0.0 {
                    plan_position_velocity(
                        s,
                        target,
                        end_v * ovr,
                        &Limits {
                            vel: lim.vel * ovr,
                            ..lim
                        },
                    )
                } else if ovr > 0.0 {
                    plan_position(
                        s,
                        target,
                        &Limits {
                            vel: lim.vel * ovr,
                            ..lim
                        },
                    )
                } else {
                    plan_velocity(s, 0.0, &lim)
                }
            }
            Goal::Velocity { v, lim } => plan_velocity(
                s,
                v * ovr,
                &Limits {
                    vel: lim.vel.max(v.abs()).max(1e-12),
                    ..lim
                },
            ),
            Goal::Stop { lim } => plan_velocity(
                s,
                0.0,
                &Limits {
                    vel: lim.vel.max(1e-12),
                    ..lim
                },
            ),
        };
        // Inputs were validated when the job was accepted; a planning failure here can only be
        // a non-finite state, which is a fault, not a panic: stop as hard as allowed.
        self.prof = match planned {
            Ok(p) => p,
            Err(_) => Profile::hold(State {
                v: 0.0,
                a: 0.0,
                ..s
            }),
        };
        self.t0 = self.now;
    }

    fn set_goal(&mut self, g: Goal) {
        self.goal = g;
        self.replan();
    }

    /// Moves the superimposed motion into the basic setpoint (when it is aborted) so the total
    /// does not jump.
    fn fold_superimposed(&mut self) {
        if self.sup != State::default() {
            self.basic.p += self.sup.p;
            self.basic.v += self.sup.v;
            self.basic.a += self.sup.a;
            self.sup = State::default();
        }
    }

    fn running_classes(&self) -> [(RunningMotion, bool); 3] {
        let main = self.main.as_ref().map(|m| match m.instr {
            Instruction::Home => RunningMotion::HomingActive,
            Instruction::MotionInPosition | Instruction::MotionInVelocity => {
                RunningMotion::MotionIn
            }
            _ => RunningMotion::Motion,
        });
        [
            (main.unwrap_or(RunningMotion::Motion), main.is_some()),
            (RunningMotion::Superimposed, self.sup_job.is_some()),
            (RunningMotion::HomingPassive, self.passive.is_some()),
        ]
    }

    /// Aborts the running jobs that `new` overrides (S7-1500T Motion Control V4.0 function manual,
    /// 10.16 'Override response of Motion Control jobs V4' tables 1 and 2).
    fn apply_override_table(&mut self, new: NewJob) {
        self.apply_table2(new);
        let [main, sup, passive] = self.running_classes();
        if main.1 && table1(new, main.0).aborts() {
            self.abort_main(JobEventKind::CommandAborted);
        }
        if sup.1 && table1(new, sup.0).aborts() {
            self.abort_sup(JobEventKind::CommandAborted);
        }
        if passive.1 && table1(new, passive.0).aborts() {
            self.abort_passive(JobEventKind::CommandAborted);
        }
    }

    fn abort_main(&mut self, how: JobEventKind) {
        if let Some(m) = self.main.take() {
            // An aborted MC_Stop keeps its lock while its Execute is held (S7-Technology V4.1
            // function manual, 6.2.3 'FB404 MC_Stop - Stopping an axis and preventing new motion
            // commands': "even across disable/re-enable"); only releasing it unlocks the axis.
            self.emit(m.id, m.instr, how);
        }
        // The jobs queued behind it end with it (PLCopen BufferMode: an aborting job aborts
        // the queue).
        if !self.queue.is_empty() {
            self.abort_queued(how);
        }
    }

    fn abort_sup(&mut self, how: JobEventKind) {
        if let Some(s) = self.sup_job.take() {
            self.emit(s.id, Instruction::MoveSuperimposed, how);
        }
        self.fold_superimposed();
    }

    fn abort_passive(&mut self, how: JobEventKind) {
        if let Some(p) = self.passive.take() {
            self.emit(p.job, Instruction::Home, how);
        }
    }

    fn abort_all(&mut self, how: JobEventKind) {
        // A simulated synchronous operation survives disables and alarms (S7-1500T Motion Control
        // V4.0 function manual, 3.5.10 'Simulate synchronous operation').
        if self.sync_sim.is_none() {
            self.abort_sync(how);
            self.abort_pending(how);
        }
        self.abort_main(how);
        self.abort_sup(how);
        self.abort_passive(how);
        self.replan();
    }

    /// Raises a technology alarm and applies its reaction (S7-1500T Motion Control V4.0 function
    /// manual, 9.3 'Technology alarms'). Between cycles the status shows it from the next cycle
    /// or command on, as before.
    pub fn raise(&mut self, id: AlarmId, supp: u16) {
        self.status();
        self.raise_alarm(id, supp);
    }

    /// [`Axis::raise`] within a cycle or command (whose end empties the status).
    fn raise_alarm(&mut self, id: AlarmId, supp: u16) {
        if self.alarms().any(|a| a.id == id && a.supplement == supp) {
            return;
        }
        let reaction = match (id, self.config().leader_missing_reaction) {
            (AlarmId::LeaderMissing, Some(r)) => r,
            _ => id.reaction(),
        };
        if let Some(slot) = self.alarms.iter_mut().find(|a| a.is_none()) {
            *slot = Some(AlarmInstance::new(id, supp).with_reaction(reaction));
            self.alarm_pending = true;
        }
        if reaction == Reaction::None {
            return;
        }
        let job_lim = self
            .main
            .map(|m| m.lim)
            .unwrap_or_else(|| self.default_limits());
        self.abort_all(JobEventKind::Error(ErrorId::TechnologyAlarm));
        self.power.disabling = false;
        match reaction {
            Reaction::None => {}
            Reaction::StopCurrentDynamics => self.set_goal(Goal::Stop { lim: job_lim }),
            Reaction::StopMaxDynamics => {
                let lim = self.max_limits();
                self.set_goal(Goal::Stop { lim })
            }
            Reaction::EmergencyStop => {
                let lim = self.emergency_limits();
                self.set_goal(Goal::Stop { lim })
            }
            Reaction::RemoveEnable | Reaction::TrackSetpoints => self.remove_enable_by_drive(),
        }
    }

    /// The enable: at once in simulation; a connected drive is asked for it and the axis is
    /// enabled when the drive reports it operational ([`Axis::drive_state`]).
    fn request_enable(&mut self) {
        self.power.quick_stop = false;
        match self.link {
            DriveLink::Simulation(_) => self.enable_now(),
            DriveLink::Connected { .. } => self.power.awaiting_drive = true,
        }
    }

    /// Removes the enable to stop on the drive's own ramp (S7-1500T Motion Control V4.0
    /// function manual, 'MC_Power' StopMode 1 and the alarm reactions 'Remove enable' and
    /// 'Track setpoints': "output setpoint 0 and remove the enable; the drive brakes on its own
    /// ramp"): a connected drive is asked for its quick stop.
    fn remove_enable_by_drive(&mut self) {
        self.remove_enable();
        self.power.quick_stop = true;
    }

    /// Removes the enable (after the axis has braked, or at once on the drive's ramp through
    /// [`Axis::remove_enable_by_drive`]).
    fn remove_enable(&mut self) {
        self.power.quick_stop = false;
        self.power.awaiting_drive = false;
        if self.enabled {
            self.enabled = false;
            self.emit(
                self.power.job,
                Instruction::Power,
                JobEventKind::Status(false),
            );
        }
        self.power.disabling = false;
        self.goal = Goal::Track;
        self.standstill_since = None;
    }

    fn enable_now(&mut self) {
        self.enabled = true;
        self.pos_ctrl = self.cfg.kind != AxisKind::Speed
            && self.power.start_mode == StartMode::PositionControlled;
        // The setpoint takes over the actual position (StartMode 1 pulls a moving axis back
        // to the position it had when the enable came).
        self.basic = State::rest(self.actual_p);
        self.sup = State::default();
        self.set_goal(Goal::Hold);
        self.emit(
            self.power.job,
            Instruction::Power,
            JobEventKind::Status(true),
        );
    }

    fn check_motion_allowed(&self) -> Result<(), ErrorId> {
        if !self.enabled || self.power.disabling {
            return Err(ErrorId::NotEnabled);
        }
        if self.stopping_alarm_pending() {
            return Err(ErrorId::JobRejectedInErrorStop);
        }
        if self.stop_lock || self.hyd_locked() || self.hyd_following_up() {
            return Err(ErrorId::AxisLocked);
        }
        Ok(())
    }

    fn require_positioning(&self) -> Result<(), ErrorId> {
        if self.cfg.kind == AxisKind::Speed {
            return Err(ErrorId::IllegalObject);
        }
        Ok(())
    }

    fn start_main(&mut self, instr: Instruction, lim: Limits, goal: Goal) -> JobId {
        let id = self.new_id();
        self.main = Some(MotionJob {
            id,
            instr,
            in_velocity: false,
            monitoring: None,
            homing: None,
            jog: (false, false),
            lim,
        });
        self.emit(id, instr, JobEventKind::Busy);
        self.set_goal(goal);
        id
    }

    /// Stop distance of the total setpoint with the given limits (signed).
    fn stop_point(&self, s: State, lim: &Limits) -> f64 {
        match plan_velocity(
            s,
            0.0,
            &Limits {
                vel: lim.vel.max(s.v.abs()).max(1e-12),
                ..*lim
            },
        ) {
            Ok(p) => p.end().p,
            Err(_) => s.p,
        }
    }

    // ----------------------------------------------------------------------------------------
    // commands

    /// Applies an instruction now (between cycles). Returns the job id, or the ErrorID of a
    /// rejection; a rejected command changes nothing.
    ///
    /// The command takes effect from the setpoint of the last cycle: the next [`Axis::step`]
    /// continues from there, so nothing jumps.
    pub fn command(&mut self, cmd: &Command) -> Result<JobId, ErrorId> {
        let r = self.apply(cmd);
        self.forget_status();
        r
    }

    fn apply(&mut self, cmd: &Command) -> Result<JobId, ErrorId> {
        match *cmd {
            Command::Power {
                enable,
                start_mode,
                stop_mode,
            } => Ok(self.cmd_power(enable, start_mode, stop_mode)),
            Command::Reset { restart } => self.cmd_reset(restart),
            Command::Home { mode, position } => self.cmd_home(mode, position),
            Command::Halt {
                deceleration,
                jerk,
                abort_acceleration,
            } => self.cmd_halt(deceleration, jerk, abort_acceleration),
            Command::Stop {
                execute,
                deceleration,
                jerk,
            } => self.cmd_stop(execute, deceleration, jerk),
            Command::MoveAbsolute {
                position,
                dynamics,
                direction,
            } => self.cmd_positioning(Instruction::MoveAbsolute, position, &dynamics, |ax, lim| {
                ax.absolute_target(position, direction, lim)
            }),
            Command::MoveRelative { distance, dynamics } => {
                self.cmd_positioning(Instruction::MoveRelative, distance, &dynamics, |ax, _| {
                    ax.basic.p + distance
                })
            }
            Command::MoveAdditive { distance, dynamics } => {
                // The target of the running positioning job, taken before it is aborted.
                let base = self.running_target();
                self.cmd_positioning(Instruction::MoveAdditive, distance, &dynamics, |ax, _| {
                    base.unwrap_or(ax.basic.p) + distance
                })
            }
            Command::Buffered {
                motion,
                buffer_mode,
            } => self.cmd_buffered(&motion, buffer_mode),
            Command::MoveVelocity {
                dynamics,
                direction,
                current,
                position_controlled,
            } => self.cmd_move_velocity(&dynamics, direction, current, position_controlled),
            Command::MoveJog {
                forward,
                backward,
                dynamics,
                position_controlled,
            } => self.cmd_jog(forward, backward, dynamics, position_controlled),
            Command::MoveSuperimposed { distance, dynamics } => {
                self.cmd_superimposed(distance, &dynamics)
            }
            Command::GearIn { .. }
            | Command::GearInPos { .. }
            | Command::FlyingGear { .. }
            | Command::GearOut
            | Command::CamIn { .. }
            | Command::CamOut
            | Command::SynchronizedMotionSimulation { .. }
            | Command::GearInVelocity { .. }
            | Command::Offset { .. }
            | Command::Phasing { .. } => self.apply_sync(cmd),
            Command::SetOverride { velocity } => self.cmd_set_override(velocity),
            Command::WriteParameter { parameter, value } => {
                self.cmd_write_parameter(parameter, value)
            }
            Command::ReadParameter { parameter } => self.cmd_read_parameter(parameter),
            Command::HydPower { .. }
            | Command::PressureControl { .. }
            | Command::PressureControlFf { .. }
            | Command::AutoZero { .. }
            | Command::SlowDownOnPressure { .. } => self.apply_hyd_control(cmd),
            Command::EmergencyStop { .. }
            | Command::ImmediateStop { .. }
            | Command::RampedStop { .. }
            | Command::HydSetPosition { .. }
            | Command::SetReferenceFlag { .. }
            | Command::ResetAndStop { .. }
            | Command::HydMoveJog { .. }
            | Command::MoveJoySticked { .. }
            | Command::HydHome(_) => self.apply_hyd_command(cmd),
            Command::SetDirectOutput { .. }
            | Command::SetExtGenValues { .. }
            | Command::FollowUp { .. }
            | Command::OffsetLatch { .. } => self.apply_hyd_direct(cmd),
            Command::MotionInPosition { .. } | Command::MotionInVelocity { .. } => {
                self.apply_motion_in(cmd)
            }
            Command::TorqueLimiting { .. }
            | Command::TorqueAdditive { .. }
            | Command::TorqueRange { .. } => self.apply_torque(cmd),
        }
    }

    /// MC_MotionInPosition and MC_MotionInVelocity; any other command is refused (16#8002).
    fn apply_motion_in(&mut self, cmd: &Command) -> Result<JobId, ErrorId> {
        match *cmd {
            Command::MotionInPosition {
                enable,
                position,
                velocity,
                acceleration,
            } => {
                self.require_positioning()?;
                self.cmd_motion_in(
                    Instruction::MotionInPosition,
                    enable,
                    Some(position),
                    velocity,
                    acceleration,
                    true,
                )
            }
            Command::MotionInVelocity {
                enable,
                velocity,
                acceleration,
                position_controlled,
            } => self.cmd_motion_in(
                Instruction::MotionInVelocity,
                enable,
                None,
                velocity,
                acceleration,
                position_controlled,
            ),
            _ => Err(ErrorId::IllegalObject),
        }
    }

    /// MC_Halt: stop with the given deceleration and jerk (the job stays until standstill).
    fn cmd_halt(
        &mut self,
        deceleration: f64,
        jerk: f64,
        abort_acceleration: bool,
    ) -> Result<JobId, ErrorId> {
        self.check_motion_allowed()?;
        let lim = self.stop_limits(deceleration, jerk)?;
        if abort_acceleration {
            self.basic.a = 0.0;
        }
        Ok(self.start_main(Instruction::Halt, lim, Goal::Stop { lim }))
    }

    /// MC_MoveVelocity: a velocity goal from the dynamics, the direction or the current
    /// velocity.
    fn cmd_move_velocity(
        &mut self,
        dynamics: &Dynamics,
        direction: VelocityDirection,
        current: bool,
        position_controlled: bool,
    ) -> Result<JobId, ErrorId> {
        self.check_motion_allowed()?;
        // MoveVelocity: the sign of Velocity is a direction (Direction 0), not the
        // "default" sentinel; 0 is allowed (stop and stay busy).
        let d = Dynamics {
            velocity: dynamics.velocity.abs(),
            ..*dynamics
        };
        let r = self.cfg.limits.resolve(&self.cfg.defaults, &d, true)?;
        let speed = r.limits.vel;
        let v = if current {
            self.total().v
        } else {
            match direction {
                VelocityDirection::BySign => speed.copysign(dynamics.velocity),
                VelocityDirection::Positive => speed,
                VelocityDirection::Negative => -speed,
            }
        };
        self.check_clamping(sign(v), position_controlled)?;
        self.warn_clamped(r.clamped);
        self.apply_override_table(NewJob::Positioning);
        self.fold_superimposed();
        self.set_position_control(position_controlled);
        let lim = Limits {
            vel: self.cfg.limits.max_velocity,
            ..r.limits
        };
        Ok(self.start_main(Instruction::MoveVelocity, lim, Goal::Velocity { v, lim }))
    }

    /// MC_MoveSuperimposed: a relative motion added to the basic motion.
    fn cmd_superimposed(&mut self, distance: f64, dynamics: &Dynamics) -> Result<JobId, ErrorId> {
        self.require_positioning()?;
        self.check_motion_allowed()?;
        if !distance.is_finite() {
            return Err(ErrorId::IllegalDistance);
        }
        let r = self
            .cfg
            .limits
            .resolve(&self.cfg.defaults, dynamics, false)?;
        self.warn_clamped(r.clamped);
        // A running superimposed job is aborted (table 1) without folding its motion
        // into the basic motion: the new one continues from its state.
        if let Some(old) = self.sup_job.take() {
            self.emit(
                old.id,
                Instruction::MoveSuperimposed,
                JobEventKind::CommandAborted,
            );
        }
        self.apply_override_table(NewJob::Superimposed);
        self.force_position_control();
        // A new superimposed job continues from the current superimposed state; its
        // distance counts from the current superimposed position.
        let s = self.sup;
        let prof =
            plan_position(s, s.p + distance, &r.limits).map_err(|_| ErrorId::IllegalDistance)?;
        let id = self.new_id();
        self.sup_job = Some(SupJob { id, t0: self.now });
        self.sup_prof = prof;
        self.emit(id, Instruction::MoveSuperimposed, JobEventKind::Busy);
        Ok(id)
    }

    /// MC_SetOverride: the velocity override in percent (0..=200); a running positioning or
    /// velocity job is replanned with it.
    fn cmd_set_override(&mut self, velocity: f64) -> Result<JobId, ErrorId> {
        if !(velocity.is_finite() && (0.0..=200.0).contains(&velocity)) {
            return Err(ErrorId::IllegalOverride);
        }
        let id = self.new_id();
        self.set_override(velocity);
        self.emit(id, Instruction::SetOverride, JobEventKind::Done);
        Ok(id)
    }

    /// Writes `Override.Velocity` (checked): the running positioning or velocity job is
    /// replanned from the current setpoint with the new override.
    fn set_override(&mut self, velocity: f64) {
        if velocity != self.override_pct {
            self.override_pct = velocity;
            if matches!(self.goal, Goal::Position { .. } | Goal::Velocity { .. }) {
                self.replan();
                self.running_job_replanned();
            }
        }
    }

    /// After the running positioning or velocity job was replanned with other dynamics: it
    /// leaves its velocity (reached again with the new plan) and its positioning monitoring.
    fn running_job_replanned(&mut self) {
        let mut left = None;
        if let Some(m) = self.main.as_mut() {
            if m.in_velocity {
                m.in_velocity = false;
                left = Some((m.id, m.instr));
            }
            // A positioning job that had stopped at override 0 moves again.
            m.monitoring = None;
        }
        if let Some((mid, instr)) = left {
            self.emit(mid, instr, JobEventKind::LeftVelocity);
        }
    }

    /// MC_MoveAbsolute (`value` = Position) and MC_MoveRelative (`value` = Distance): checks,
    /// override table, then a position goal at `target` (computed after any superimposed
    /// motion has been folded into the basic motion, from the position at job start).
    fn cmd_positioning(
        &mut self,
        instr: Instruction,
        value: f64,
        dynamics: &Dynamics,
        target: impl FnOnce(&Self, &Limits) -> f64,
    ) -> Result<JobId, ErrorId> {
        self.require_positioning()?;
        self.check_motion_allowed()?;
        let absolute = instr == Instruction::MoveAbsolute;
        if !value.is_finite() {
            return Err(if absolute {
                ErrorId::IllegalPosition
            } else {
                ErrorId::IllegalDistance
            });
        }
        if absolute && !self.homed {
            return Err(ErrorId::NotHomed);
        }
        // Clamped at a fixed stop: only away from it (16#8047).
        let toward = if absolute {
            value - self.total().p
        } else {
            value
        };
        self.check_clamping(sign(toward), true)?;
        let r = self
            .cfg
            .limits
            .resolve(&self.cfg.defaults, dynamics, false)?;
        self.warn_clamped(r.clamped);
        self.apply_override_table(NewJob::Positioning);
        self.fold_superimposed();
        self.force_position_control();
        let target = target(self, &r.limits);
        self.hyd_check_feed(target)?;
        let lim = r.limits;
        Ok(self.start_main(
            instr,
            lim,
            Goal::Position {
                target,
                lim,
                end_v: 0.0,
            },
        ))
    }

    fn force_position_control(&mut self) {
        self.set_position_control(true);
    }

    fn set_position_control(&mut self, on: bool) {
        let on = on && self.cfg.kind != AxisKind::Speed;
        if on && !self.pos_ctrl {
            // Closing the loop: the position setpoint takes over the actual position.
            self.basic.p = self.actual_p - self.sup.p;
        }
        self.pos_ctrl = on;
    }

    /// Continuous target of MoveAbsolute: modulo reduction and Direction (S7-1500T Motion Control
    /// V4.0 function manual, 10.5.1 'MC_MoveAbsolute: Position axis absolutely V4').
    fn absolute_target(&self, position: f64, direction: Direction, lim: &Limits) -> f64 {
        let Some(m) = self.cfg.modulo else {
            return position;
        };
        let s = self.total();
        let here = s.p;
        match direction {
            Direction::Shortest => here + m.shortest(here, position),
            Direction::Positive | Direction::Negative => {
                let dir = if direction == Direction::Positive {
                    1.0
                } else {
                    -1.0
                };
                let mut d = if dir > 0.0 {
                    m.forward(here, position)
                } else {
                    -m.forward(position, here)
                };
                // Keep the direction: if the axis cannot stop before the target, go one more
                // modulo length around.
                let stop = self.stop_point(s, lim) - here;
                while dir * stop > dir * d + 1e-12 * m.length {
                    d += dir * m.length;
                }
                here + d
            }
        }
    }

    fn cmd_power(&mut self, enable: bool, start_mode: StartMode, stop_mode: StopMode) -> JobId {
        if enable && !self.power.enable {
            self.power = Power {
                enable,
                start_mode,
                stop_mode,
                job: self.new_id(),
                disabling: false,
                awaiting_drive: false,
                fault_reset: false,
                after_reset: false,
                quick_stop: false,
            };
            self.emit(self.power.job, Instruction::Power, JobEventKind::Busy);
            if !self.alarms().any(|a| a.reaction.removes_enable()) {
                self.request_enable();
            }
        } else if !enable && self.power.enable {
            self.power.enable = false;
            self.power.awaiting_drive = false;
            self.power.stop_mode = stop_mode;
            self.abort_all(JobEventKind::CommandAborted);
            if self.enabled {
                match stop_mode {
                    StopMode::Immediate => self.remove_enable_by_drive(),
                    StopMode::Emergency => {
                        self.power.disabling = true;
                        let lim = self.emergency_limits();
                        self.set_goal(Goal::Stop { lim });
                    }
                    StopMode::MaxDynamics => {
                        self.power.disabling = true;
                        let lim = self.max_limits();
                        self.set_goal(Goal::Stop { lim });
                    }
                }
            }
        } else {
            self.power.stop_mode = stop_mode;
        }
        self.power.job
    }

    fn cmd_reset(&mut self, restart: bool) -> Result<JobId, ErrorId> {
        if restart && (self.enabled || self.power.enable) {
            return Err(ErrorId::RestartWhileEnabled);
        }
        let id = self.new_id();
        self.emit(id, Instruction::Reset, JobEventKind::Busy);
        if restart {
            // A restart ends a simulated synchronous operation too.
            if let Some(j) = self.sync_sim.take() {
                self.emit(
                    j,
                    Instruction::SynchronizedMotionSimulation,
                    JobEventKind::InSimulation(false),
                );
            }
            self.abort_sync(JobEventKind::CommandAborted);
            self.abort_pending(JobEventKind::CommandAborted);
            self.alarms = [None; MAX_ALARMS];
            self.alarm_pending = false;
            self.homed = self.absolute.adjusted;
            self.offset = self.absolute.offset;
            self.override_pct = 100.0;
            self.hw_trigger = None;
            self.sw_active = None;
            self.actual_p = self.drive_actual().p + self.offset;
            self.basic = State::rest(self.actual_p);
        } else {
            for a in self.alarms.iter_mut() {
                if a.map(|x| !x.spec().restart).unwrap_or(false) {
                    *a = None;
                }
            }
            self.alarm_pending = self.alarms.iter().any(Option::is_some);
        }
        // A connected drive acknowledges its own fault with the next outputs.
        if matches!(self.link, DriveLink::Connected { .. }) {
            self.power.fault_reset = true;
        }
        // Automatic re-enable after acknowledgement while Enable is still held.
        if self.power.enable && !self.enabled && !self.alarms().any(|a| a.reaction.removes_enable())
        {
            self.power.after_reset = true;
            self.request_enable();
        }
        self.emit(id, Instruction::Reset, JobEventKind::Done);
        Ok(id)
    }

    fn cmd_stop(&mut self, execute: bool, deceleration: f64, jerk: f64) -> Result<JobId, ErrorId> {
        if !execute {
            // Release the lock; the job is done once the axis stands still.
            self.stop_lock = false;
            let id = self
                .main
                .filter(|m| m.instr == Instruction::Stop)
                .map(|m| m.id)
                .unwrap_or(0);
            return Ok(id);
        }
        if !self.enabled || self.power.disabling {
            return Err(ErrorId::NotEnabled);
        }
        if self.stopping_alarm_pending() {
            return Err(ErrorId::JobRejectedInErrorStop);
        }
        let lim = self.stop_limits(deceleration, jerk)?;
        let id = self.start_main(Instruction::Stop, lim, Goal::Stop { lim });
        self.stop_lock = true;
        Ok(id)
    }

    /// The braking limits of MC_Halt / MC_Stop (deceleration also used as acceleration), after
    /// the override table and folding the superimposed motion into the basic one.
    fn stop_limits(&mut self, deceleration: f64, jerk: f64) -> Result<Limits, ErrorId> {
        let d = Dynamics {
            deceleration,
            jerk,
            ..Dynamics::DEFAULT
        };
        let r = self.cfg.limits.resolve(&self.cfg.defaults, &d, true)?;
        self.warn_clamped(r.clamped);
        self.apply_override_table(NewJob::Halt);
        self.fold_superimposed();
        Ok(Limits {
            acc: r.limits.dec,
            ..r.limits
        })
    }

    fn cmd_jog(
        &mut self,
        forward: bool,
        backward: bool,
        dynamics: Dynamics,
        position_controlled: bool,
    ) -> Result<JobId, ErrorId> {
        let running = self.main.filter(|m| m.instr == Instruction::MoveJog);
        if running.is_none() && !forward && !backward {
            return Ok(0);
        }
        self.check_motion_allowed()?;
        // Jog uses the absolute value of a negative Velocity (S7-1500T Motion Control V4.0
        // function manual, 10.8.1 'MC_MoveJog: Move axis in jog mode V4').
        let d = Dynamics {
            velocity: dynamics.velocity.abs(),
            ..dynamics
        };
        let r = self.cfg.limits.resolve(&self.cfg.defaults, &d, true)?;
        if forward != backward {
            self.check_clamping(if forward { 1.0 } else { -1.0 }, position_controlled)?;
        }
        if forward && backward {
            // Both inputs: brake with the last valid deceleration and report 16#8007.
            if let Some(m) = running {
                self.main = None;
                self.emit(
                    m.id,
                    m.instr,
                    JobEventKind::Error(ErrorId::IllegalDirection),
                );
                self.set_goal(Goal::Stop { lim: m.lim });
            }
            return Err(ErrorId::IllegalDirection);
        }
        let lim = Limits {
            vel: self.cfg.limits.max_velocity,
            ..r.limits
        };
        let v = if forward {
            r.limits.vel
        } else if backward {
            -r.limits.vel
        } else {
            0.0
        };
        match running {
            Some(m) if m.jog == (forward, backward) => Ok(m.id),
            Some(m) => {
                // Same job, inputs changed.
                if let Some(job) = self.main.as_mut() {
                    job.jog = (forward, backward);
                    job.lim = lim;
                    if job.in_velocity {
                        job.in_velocity = false;
                        self.emit(m.id, m.instr, JobEventKind::LeftVelocity);
                    }
                }
                if forward || backward {
                    self.set_goal(Goal::Velocity { v, lim });
                } else {
                    self.set_goal(Goal::Stop { lim });
                }
                Ok(m.id)
            }
            None => {
                self.warn_clamped(r.clamped);
                self.apply_override_table(NewJob::Positioning);
                self.fold_superimposed();
                self.set_position_control(position_controlled);
                let id = self.start_main(Instruction::MoveJog, lim, Goal::Velocity { v, lim });
                if let Some(job) = self.main.as_mut() {
                    job.jog = (forward, backward);
                }
                Ok(id)
            }
        }
    }

    fn cmd_motion_in(
        &mut self,
        instr: Instruction,
        enable: bool,
        position: Option<f64>,
        velocity: f64,
        acceleration: f64,
        position_controlled: bool,
    ) -> Result<JobId, ErrorId> {
        let running = self.main.filter(|m| m.instr == instr);
        if !enable {
            if let Some(m) = running {
                // Enable FALSE: velocity and acceleration to 0 at once, position holds.
                self.main = None;
                self.basic.v = 0.0;
                self.basic.a = 0.0;
                self.set_goal(Goal::Hold);
                self.emit(m.id, instr, JobEventKind::Done);
                return Ok(m.id);
            }
            return Ok(0);
        }
        if !(velocity.is_finite() && acceleration.is_finite()) {
            return Err(ErrorId::IllegalVelocity);
        }
        if position.map(|p| !p.is_finite()).unwrap_or(false) {
            return Err(ErrorId::IllegalPosition);
        }
        let goal = Goal::Direct {
            position,
            v: velocity,
            a: acceleration,
        };
        if let Some(m) = running {
            self.goal = goal;
            return Ok(m.id);
        }
        self.check_motion_allowed()?;
        self.apply_override_table(NewJob::MotionIn);
        self.fold_superimposed();
        self.set_position_control(position_controlled);
        let lim = self.default_limits();
        let id = self.start_main(instr, lim, goal);
        self.goal = goal;
        Ok(id)
    }

    /// MC_Home: checks the mode against the encoder, the enable and the plant, then homes
    /// directly (modes 0, 1, 6, 7), arms passive homing (2, 8, 10; 9 aborts it) or starts active
    /// homing (3, 5).
    fn cmd_home(&mut self, mode: u8, position: f64) -> Result<JobId, ErrorId> {
        self.check_home(mode, position)?;
        let id = self.new_id();
        self.emit(id, Instruction::Home, JobEventKind::Busy);
        let modulo = self.cfg.modulo;
        match mode {
            0 | 7 => {
                // Direct / absolute-encoder adjustment, absolute: actual := Position.
                let delta = reduce(modulo, position) - self.actual_p;
                self.home_directly(id, delta, mode == 7);
            }
            1 | 6 => {
                // Relative: actual := actual + Position (reduced on modulo axes).
                let delta = reduce(modulo, self.actual_p + position) - self.actual_p;
                self.home_directly(id, delta, mode == 6);
            }
            9 => {
                self.abort_passive(JobEventKind::CommandAborted);
                self.emit(id, Instruction::Home, JobEventKind::Done);
            }
            2 | 8 | 10 => {
                self.abort_passive(JobEventKind::CommandAborted);
                if mode != 2 {
                    self.homed = false;
                }
                let home = reduce(
                    modulo,
                    if mode == 10 {
                        self.cfg.homing.home_position
                    } else {
                        position
                    },
                );
                let phase = match self.cfg.homing.passive_mark {
                    HomingMark::ZeroMark => HomePhase::Armed,
                    _ => HomePhase::Search,
                };
                self.passive = Some(PassiveHoming {
                    job: id,
                    home,
                    phase,
                    armed_dir: 0.0,
                });
            }
            _ => self.start_active_homing(id, mode, position),
        }
        Ok(id)
    }

    /// The checks of MC_Home: no absolute synchronous operation, a finite position, a mode the
    /// encoder type, the enable and the plant's sensors allow.
    fn check_home(&mut self, mode: u8, position: f64) -> Result<(), ErrorId> {
        self.require_positioning()?;
        let absolute_sync = |s: Option<sync::SyncJob>| {
            s.map(|j| matches!(j.instr, Instruction::GearInPos | Instruction::CamIn))
                .unwrap_or(false)
        };
        if absolute_sync(self.sync) || absolute_sync(self.sync_pending) {
            return Err(ErrorId::SyncJobActive);
        }
        if !position.is_finite() {
            return Err(ErrorId::IllegalPosition);
        }
        let incremental = self.cfg.encoder == EncoderType::Incremental;
        match mode {
            0 | 1 | 9 => {}
            2 | 3 | 5 | 8 | 10 => {
                if !incremental {
                    return Err(ErrorId::IllegalHomingModeAbsolute);
                }
                if !self.enabled {
                    return Err(ErrorId::NotEnabled);
                }
            }
            6 | 7 => {
                if incremental {
                    return Err(ErrorId::IllegalHomingModeIncremental);
                }
                if !self.enabled || !self.pos_ctrl {
                    return Err(ErrorId::NotPositionControlled);
                }
            }
            _ => return Err(ErrorId::IllegalMode),
        }
        if matches!(mode, 3 | 5) {
            self.check_motion_allowed()?;
        }
        // The plant must have the sensors the configured homing mark needs (S7: alarm 343
        // "homing not supported by the device"; here the job is rejected and nothing changes).
        let mark = match mode {
            3 | 5 if !self.cfg.virtual_axis => Some(self.cfg.homing.active_mark),
            2 | 8 | 10 => Some(self.cfg.homing.passive_mark),
            _ => None,
        };
        if let Some(mark) = mark {
            // A drive of the process image latches the marks with its touch probe: the
            // encoder's zero pulse and the home switch on the probe input (docs/io.md,
            // 'Homing through the touch probe'); what is wired to it is the drive's business.
            let (cam, zero) = match self.link {
                DriveLink::Simulation(_) => (
                    self.cfg.plant.reference_cam.is_some(),
                    self.cfg.plant.zero_mark.is_some(),
                ),
                DriveLink::Connected { .. } => (true, true),
            };
            let cam_ok = cam || mark == HomingMark::ZeroMark;
            let zero_ok = zero || mark == HomingMark::DigitalInput;
            if !(cam_ok && zero_ok) {
                return Err(ErrorId::IllegalMode);
            }
        }
        Ok(())
    }

    /// Direct homing (modes 0, 1, 6, 7): the coordinates move by `delta`; with an absolute
    /// encoder (`absolute`, modes 6, 7) its offset is kept.
    fn home_directly(&mut self, id: JobId, delta: f64, absolute: bool) {
        self.shift(delta);
        if absolute {
            self.note_absolute_adjustment();
        }
        self.homed = true;
        self.emit(id, Instruction::Home, JobEventKind::Done);
    }

    /// Active homing (modes 3, 5): aborts all motion, re-enables position control and starts
    /// the search for the homing mark (on a virtual axis it completes at once).
    fn start_active_homing(&mut self, id: JobId, mode: u8, position: f64) {
        let modulo = self.cfg.modulo;
        // 3 / 5: active homing. Aborts all motion and re-enables position control.
        self.apply_override_table(NewJob::HomeActive);
        self.fold_superimposed();
        self.force_position_control();
        self.homed = false;
        let h = &self.cfg.homing;
        let end = reduce(modulo, if mode == 5 { h.home_position } else { position });
        let lim = self.default_limits();
        if self.cfg.virtual_axis {
            // Simulation: homing completes at once without motion (S7-1500T Motion Control V4.0
            // function manual, 3.2.5.7 'Axis in simulation').
            let delta = end - self.actual_p;
            self.shift(delta);
            self.homed = true;
            self.emit(id, Instruction::Home, JobEventKind::Done);
            return;
        }
        let home = end - h.home_position_offset;
        let search_dir = h.approach_direction.sign();
        let on_cam = self.on_reference_cam_now();
        let (phase, v) = match (h.active_mark, on_cam) {
            (HomingMark::ZeroMark, _) => (
                HomePhase::Armed,
                h.homing_direction.sign() * h.referencing_velocity,
            ),
            (_, true) => (
                HomePhase::OnCam,
                h.homing_direction.sign() * h.referencing_velocity,
            ),
            (_, false) => (HomePhase::Search, search_dir * h.approach_velocity),
        };
        self.main = Some(MotionJob {
            id,
            instr: Instruction::Home,
            in_velocity: false,
            monitoring: None,
            homing: Some(ActiveHoming {
                home,
                end,
                phase,
                search_dir,
                reversals: 0,
            }),
            jog: (false, false),
            lim,
        });
        let vlim = Limits {
            vel: self.cfg.limits.max_velocity,
            ..lim
        };
        self.set_goal(Goal::Velocity { v, lim: vlim });
        // Homing velocities are not scaled by the override: undo the scaling.
        if self.override_pct != 100.0 {
            let ovr = self.override_pct;
            self.override_pct = 100.0;
            self.replan();
            self.override_pct = ovr;
        }
    }

    /// Shifts the axis coordinate system by `delta` (homing): actual, setpoint and the running
    /// goal move together, so nothing jumps physically.
    fn shift(&mut self, delta: f64) {
        self.offset += delta;
        self.actual_p += delta;
        // Homing is a jump of the actual value: the extrapolation starts again from it.
        self.extrapolator.reset(self.actual_p, self.actual_v);
        self.basic.p += delta;
        match &mut self.goal {
            Goal::Position { target, .. } => *target += delta,
            Goal::Direct {
                position: Some(p), ..
            } => *p += delta,
            _ => {}
        }
        self.queue.shift(delta);
        if let Some(m) = self.main.as_mut() {
            if let Some(pm) = m.monitoring.as_mut() {
                pm.target += delta;
            }
        }
        if let Some(s) = self.sync.as_mut() {
            s.shift_follower(delta);
            if self.goal == Goal::Sync {
                // A synchronizing GearIn keeps its relative profile in the profile slot.
                self.prof = self.prof.shifted(delta);
            }
        }
        self.replan();
    }

    /// The drive's actual values now: in simulation the drive after its last step, else the
    /// inputs as last set.
    fn drive_actual(&self) -> crate::plant::drive::Actual {
        match &self.link {
            DriveLink::Simulation(p) => p.actual(),
            DriveLink::Connected { inputs, .. } => inputs.actual,
        }
    }

    /// Whether the reference cam is active now (when a homing job starts between cycles).
    fn on_reference_cam_now(&self) -> bool {
        match &self.link {
            DriveLink::Simulation(p) => p.reference_cam_now(),
            DriveLink::Connected { inputs, .. } => inputs.signals.reference_cam,
        }
    }

    /// The homing offset: axis position = physical position + this.
    pub fn position_offset(&self) -> f64 {
        self.offset
    }

    /// Connects the axis to a drive behind the process image instead of its simulated drive.
    /// The drive's inputs are then set before each cycle ([`Axis::set_drive_inputs`]) and its
    /// outputs read after it ([`Axis::drive_outputs`]).
    pub fn connect_drive(&mut self) {
        let actual = self.drive_actual();
        self.link = DriveLink::Connected {
            inputs: DriveInputs {
                actual,
                ..DriveInputs::default()
            },
            outputs: DriveOutputs {
                position: actual.p,
                ..DriveOutputs::default()
            },
        };
        // The position controller is now the drive's (`PositionControl.*` are its parameters).
        self.param_extra.own_position_loop = false;
    }

    /// Sets the switches read from input signals of the process image for the coming cycle,
    /// in place of the simulated plant's (ignored on a connected drive, whose inputs carry
    /// them).
    pub fn set_switch_inputs(&mut self, s: crate::plant::link::SwitchInputs) {
        if let DriveLink::Simulation(p) = &mut self.link {
            p.set_switch_inputs(s);
        } else if let Some(h) = self.hyd.as_deref_mut() {
            // A hydraulic axis on its analog connection: the reference cam's input signal for
            // MC_Home_BkPlcMc (the library's dwTcHydDcDwRefIndex).
            h.cmds.cam_input = s.reference_cam.unwrap_or(false);
        }
    }

    /// Sets the inputs of a connected drive for the coming cycle (ignored in simulation).
    pub fn set_drive_inputs(&mut self, inp: &DriveInputs) {
        if let DriveLink::Connected { inputs, .. } = &mut self.link {
            *inputs = *inp;
        }
    }

    /// The outputs the axis wrote in its last cycle to its connected drive, in place (`None`
    /// in simulation: [`Axis::drive_outputs`] computes them). For the cyclic path: the
    /// caller reads the fields where the step stored them, without copying the struct.
    #[inline]
    pub fn connected_outputs(&self) -> Option<&DriveOutputs> {
        match &self.link {
            DriveLink::Simulation(_) => None,
            DriveLink::Connected { outputs, .. } => Some(outputs),
        }
    }

    /// The outputs the axis wrote in its last cycle (in simulation: those applied to the
    /// simulated drive).
    pub fn drive_outputs(&self) -> DriveOutputs {
        match &self.link {
            DriveLink::Simulation(_) => self.outputs(),
            DriveLink::Connected { outputs, .. } => *outputs,
        }
    }
}

/// `p` reduced into the modulo range (unchanged on a linear axis).
fn reduce(modulo: Option<Modulo>, p: f64) -> f64 {
    match modulo {
        Some(m) => m.wrap(p),
        None => p,
    }
}
