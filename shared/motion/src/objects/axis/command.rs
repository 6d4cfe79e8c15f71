//! The instructions an axis accepts, with their inputs as in the references (S7-1500T Motion
//! Control V4.0 function manual, chapter 10 'Instructions').

use crate::kinematics::dynamics::Dynamics;
use crate::objects::leading::LeaderId;

/// `MC_Power.StartMode`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum StartMode {
    /// 0: enable without position control.
    NonPositionControlled,
    /// 1: enable position-controlled (default).
    PositionControlled,
}

/// `MC_Power.StopMode` (applies to user disables only; alarms use their reaction).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum StopMode {
    /// 0: emergency stop ramp (`EmergencyDeceleration`, no jerk), then remove enable.
    Emergency,
    /// 1: remove enable at once; the drive brakes on its own ramp.
    Immediate,
    /// 2: maximum dynamics (`MaxDeceleration` with `MaxJerk`), then remove enable.
    MaxDynamics,
}

/// `MC_MoveAbsolute.Direction` on modulo axes.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Direction {
    /// 1: positive direction.
    Positive,
    /// 2: negative direction.
    Negative,
    /// 3: shortest way.
    Shortest,
}

impl Direction {
    /// From the reference's number (1, 2, 3).
    pub fn from_code(c: i32) -> Option<Self> {
        match c {
            1 => Some(Self::Positive),
            2 => Some(Self::Negative),
            3 => Some(Self::Shortest),
            _ => None,
        }
    }
}

/// `MC_MoveVelocity.Direction`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum VelocityDirection {
    /// 0: the sign of `Velocity`.
    BySign,
    /// 1: positive.
    Positive,
    /// 2: negative.
    Negative,
}

impl VelocityDirection {
    /// From the reference's number (0, 1, 2).
    pub fn from_code(c: i32) -> Option<Self> {
        match c {
            0 => Some(Self::BySign),
            1 => Some(Self::Positive),
            2 => Some(Self::Negative),
            _ => None,
        }
    }
}

/// `BufferMode` of the motion instructions (PLCopen Motion Control Part 1, 'BufferMode';
/// `Mode` 0 override, 1 append, 2 overlay of S7-Technology V4.1 function manual, 6.2.6 'FB410
/// MC_MoveAbsolute - Absolute positioning'). A tandem extension beyond the S7-1500T Motion
/// Control V4.0 function manual, which has none (every job acts as [`BufferMode::Aborting`],
/// the default).
///
/// The seam velocity of the blending modes is taken from the commanded velocities `v1` of the
/// job before and `v2` of the queued job; it is 0 when the direction reverses at the seam.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Hash)]
#[doc(alias = "MC_BUFFER_MODE")]
pub enum BufferMode {
    /// 0 `mcAborting` (S7-Technology Mode 0 "override"): starts at once, aborts the running job
    /// and every queued one.
    #[default]
    #[doc(alias = "mcAborting")]
    Aborting,
    /// 1 `mcBuffered` (S7-Technology Mode 1 "append"): starts when the job before it is Done
    /// (at rest at its target; a MoveVelocity before it: when InVelocity).
    #[doc(alias = "mcBuffered")]
    Buffered,
    /// 2 `mcBlendingLow` (S7-Technology Mode 2 "blend"): passes the seam at `min(v1, v2)`.
    #[doc(alias = "mcBlendingLow")]
    BlendingLow,
    /// 3 `mcBlendingPrevious`: passes the seam at `v1`.
    #[doc(alias = "mcBlendingPrevious")]
    BlendingPrevious,
    /// 4 `mcBlendingNext`: passes the seam at `v2`.
    #[doc(alias = "mcBlendingNext")]
    BlendingNext,
    /// 5 `mcBlendingHigh`: passes the seam at `max(v1, v2)`.
    #[doc(alias = "mcBlendingHigh")]
    BlendingHigh,
}

impl BufferMode {
    /// Every mode, in PLCopen order (the index is [`BufferMode::code`]).
    pub const ALL: [BufferMode; 6] = [
        Self::Aborting,
        Self::Buffered,
        Self::BlendingLow,
        Self::BlendingPrevious,
        Self::BlendingNext,
        Self::BlendingHigh,
    ];

    /// The PLCopen number (0 Aborting .. 5 BlendingHigh).
    pub const fn code(self) -> u8 {
        self as u8
    }

    /// From the PLCopen number (0..=5).
    pub fn from_code(c: i32) -> Option<Self> {
        usize::try_from(c)
            .ok()
            .and_then(|i| Self::ALL.get(i).copied())
    }

    /// The PLCopen name without `mc` (`"BlendingLow"`).
    pub const fn name(self) -> &'static str {
        match self {
            Self::Aborting => "Aborting",
            Self::Buffered => "Buffered",
            Self::BlendingLow => "BlendingLow",
            Self::BlendingPrevious => "BlendingPrevious",
            Self::BlendingNext => "BlendingNext",
            Self::BlendingHigh => "BlendingHigh",
        }
    }

    /// From a name: the PLCopen one with or without `mc` in any case (`BlendingLow`,
    /// `mcBlendingLow`, `blending_low`), or S7-Technology's `override`, `append`, `blend`.
    pub fn from_name(name: &str) -> Option<Self> {
        let n: String = name
            .chars()
            .filter(|c| *c != '_' && *c != '-')
            .flat_map(char::to_lowercase)
            .collect();
        let n = n.strip_prefix("mc").unwrap_or(&n);
        match n {
            "override" => return Some(Self::Aborting),
            "append" => return Some(Self::Buffered),
            "blend" => return Some(Self::BlendingLow),
            _ => {}
        }
        Self::ALL
            .iter()
            .copied()
            .find(|m| m.name().eq_ignore_ascii_case(n))
    }

    /// One of the four blending modes.
    pub const fn is_blending(self) -> bool {
        matches!(
            self,
            Self::BlendingLow | Self::BlendingPrevious | Self::BlendingNext | Self::BlendingHigh
        )
    }

    /// The seam speed of a blending mode from the commanded speeds `v1` (the job before) and
    /// `v2` (this job), both >= 0; 0 for the other modes.
    pub fn seam_speed(self, v1: f64, v2: f64) -> f64 {
        match self {
            Self::BlendingLow => v1.min(v2),
            Self::BlendingPrevious => v1,
            Self::BlendingNext => v2,
            Self::BlendingHigh => v1.max(v2),
            Self::Aborting | Self::Buffered => 0.0,
        }
    }
}

/// A motion job that can be queued behind the running one ([`Command::Buffered`]).
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum BufferedMotion {
    /// `MC_MoveAbsolute`: `Position`, dynamics, `Direction` (modulo axes).
    #[doc(alias = "MC_MoveAbsolute")]
    MoveAbsolute {
        /// `Position`.
        position: f64,
        /// Dynamics.
        dynamics: Dynamics,
        /// `Direction` (modulo axes only).
        direction: Direction,
    },
    /// `MC_MoveRelative`: `Distance` from the target of the job before (from the position at
    /// its start when the job before has no target).
    #[doc(alias = "MC_MoveRelative")]
    MoveRelative {
        /// `Distance`.
        distance: f64,
        /// Dynamics.
        dynamics: Dynamics,
    },
    /// `MC_MoveAdditive`: `Distance` added to the last commanded target.
    #[doc(alias = "MC_MoveAdditive")]
    MoveAdditive {
        /// `Distance`.
        distance: f64,
        /// Dynamics.
        dynamics: Dynamics,
    },
    /// `MC_MoveVelocity`.
    #[doc(alias = "MC_MoveVelocity")]
    MoveVelocity {
        /// Dynamics (`Velocity` may be 0; its sign counts with `Direction` 0).
        dynamics: Dynamics,
        /// `Direction`.
        direction: VelocityDirection,
        /// `Current`: keep the velocity at job start.
        current: bool,
        /// `PositionControlled`.
        position_controlled: bool,
    },
}

impl BufferedMotion {
    /// The same job as an aborting command.
    pub fn aborting(self) -> Command {
        match self {
            Self::MoveAbsolute {
                position,
                dynamics,
                direction,
            } => Command::MoveAbsolute {
                position,
                dynamics,
                direction,
            },
            Self::MoveRelative { distance, dynamics } => {
                Command::MoveRelative { distance, dynamics }
            }
            Self::MoveAdditive { distance, dynamics } => {
                Command::MoveAdditive { distance, dynamics }
            }
            Self::MoveVelocity {
                dynamics,
                direction,
                current,
                position_controlled,
            } => Command::MoveVelocity {
                dynamics,
                direction,
                current,
                position_controlled,
            },
        }
    }

    /// The job's dynamics.
    pub fn dynamics(&self) -> &Dynamics {
        match self {
            Self::MoveAbsolute { dynamics, .. }
            | Self::MoveRelative { dynamics, .. }
            | Self::MoveAdditive { dynamics, .. }
            | Self::MoveVelocity { dynamics, .. } => dynamics,
        }
    }
}

/// `SyncProfileReference` of MC_GearInPos.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum SyncProfileReference {
    /// 0: synchronize using the dynamics; the synchronization length follows from them.
    Dynamics,
    /// 1: synchronize over the leading value distance `MasterStartDistance`.
    MasterStartDistance,
    /// 2 (MC_CamIn only): set synchronous at once at the current positions.
    Direct,
}

/// `ApplicationMode` of MC_CamIn.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum ApplicationMode {
    /// 0: once; ends at the cam end going forward, at the cam start going backward.
    Once,
    /// 1: cyclic (absolute): the cam repeats; start and end values should match.
    Cyclic,
    /// 2: cyclic appending: each cycle adds the cam's rise to the following value.
    CyclicAppending,
}

/// Identifies a cam for the runtime that provides it ([`crate::objects::axis::Axis::provide_cam`]).
pub type CamId = u32;

/// `SyncDirection` of a modulo follower (MC_GearInPos, MC_CamIn).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum SyncDirection {
    /// 1: the follower moves only in the positive direction while synchronizing.
    Positive,
    /// 2: only in the negative direction.
    Negative,
    /// 3: the shortest way (default).
    Shortest,
}

/// An instruction for an axis. Execute-type instructions start a job per command;
/// enable-type ones (`Power`, `MoveJog`, `MotionIn*`, the `Stop` lock) are re-sent with their
/// current inputs and keep one job while enabled.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Command {
    /// `MC_Power`.
    #[doc(alias = "MC_Power")]
    Power {
        /// `Enable`.
        enable: bool,
        /// `StartMode`.
        start_mode: StartMode,
        /// `StopMode`.
        stop_mode: StopMode,
    },
    /// `MC_Reset`.
    #[doc(alias = "MC_Reset")]
    Reset {
        /// `Restart`: re-initialize the TO (needs it disabled).
        restart: bool,
    },
    /// `MC_Home` (modes 0..10 of S7-1500T Motion Control V4.0 function manual, 3.2.9.3 'Homing
    /// mode').
    #[doc(alias = "MC_Home")]
    Home {
        /// `Mode`.
        mode: u8,
        /// `Position`.
        position: f64,
    },
    /// `MC_Halt`.
    #[doc(alias = "MC_Halt")]
    Halt {
        /// `Deceleration` (< 0: default).
        deceleration: f64,
        /// `Jerk` (< 0: default, 0: trapezoidal).
        jerk: f64,
        /// `AbortAcceleration`: drop the acceleration to 0 at once.
        abort_acceleration: bool,
    },
    /// `MC_Stop` (PLCopen; S7-Technology FB404): stops and locks the axis while `execute`
    /// is held; `execute: false` releases the lock.
    #[doc(alias = "MC_Stop")]
    Stop {
        /// `Execute` level.
        execute: bool,
        /// `Deceleration`.
        deceleration: f64,
        /// `Jerk`.
        jerk: f64,
    },
    /// `MC_MoveAbsolute`.
    #[doc(alias = "MC_MoveAbsolute")]
    MoveAbsolute {
        /// `Position`.
        position: f64,
        /// `Velocity`, `Acceleration`, `Deceleration`, `Jerk`.
        dynamics: Dynamics,
        /// `Direction` (modulo axes only).
        direction: Direction,
    },
    /// `MC_MoveRelative`.
    #[doc(alias = "MC_MoveRelative")]
    MoveRelative {
        /// `Distance`.
        distance: f64,
        /// Dynamics.
        dynamics: Dynamics,
    },
    /// `MC_MoveAdditive` (S7-Technology V4.1 function manual, 6.2.8 'FB412 MC_MoveAdditive -
    /// Relative positioning to current target position'; PLCopen Motion Control Part 1): the new target
    /// is the target of the running positioning job plus `distance`; with no positioning job
    /// running (standstill, a velocity job) it acts as MC_MoveRelative.
    #[doc(alias = "MC_MoveAdditive")]
    MoveAdditive {
        /// `Distance`.
        distance: f64,
        /// Dynamics.
        dynamics: Dynamics,
    },
    /// A motion job with a `BufferMode` ([`BufferMode::Aborting`] is the plain command).
    #[doc(alias = "BufferMode")]
    Buffered {
        /// The job.
        motion: BufferedMotion,
        /// `BufferMode`.
        buffer_mode: BufferMode,
    },
    /// `MC_MoveVelocity`.
    #[doc(alias = "MC_MoveVelocity")]
    MoveVelocity {
        /// Dynamics (`Velocity` may be 0; its sign counts with `Direction` 0).
        dynamics: Dynamics,
        /// `Direction`.
        direction: VelocityDirection,
        /// `Current`: keep the velocity and direction at job start.
        current: bool,
        /// `PositionControlled`.
        position_controlled: bool,
    },
    /// `MC_MoveJog`.
    #[doc(alias = "MC_MoveJog")]
    MoveJog {
        /// `JogForward`.
        forward: bool,
        /// `JogBackward`.
        backward: bool,
        /// Dynamics (the absolute value of `Velocity` is used; 0 allowed).
        dynamics: Dynamics,
        /// `PositionControlled`.
        position_controlled: bool,
    },
    /// `MC_MoveSuperimposed`.
    #[doc(alias = "MC_MoveSuperimposed")]
    MoveSuperimposed {
        /// `Distance`.
        distance: f64,
        /// `VelocityDiff` (as `velocity`), `Acceleration`, `Deceleration`, `Jerk`.
        dynamics: Dynamics,
    },
    /// `MC_Power_BkPlcMc` (Beckhoff TwinCAT PLC Hydraulic Positioning library): MC_Power of a
    /// hydraulic axis (StartMode position controlled, StopMode emergency) with the feed
    /// enables of the two directions.
    #[doc(alias = "MC_Power_BkPlcMc")]
    HydPower {
        /// `Enable`.
        enable: bool,
        /// `Enable_Positive`: motion in the positive direction allowed.
        enable_positive: bool,
        /// `Enable_Negative`: motion in the negative direction allowed.
        enable_negative: bool,
    },
    /// The pressure or force controller of a hydraulic axis (Beckhoff TwinCAT PLC Hydraulic
    /// Positioning library, `MC_AxCtrlPressure_BkPlcMc` with `fSetPressure`): with `enable` it
    /// takes the control value from the generator and controls the actual pressure or force
    /// to `set_value`; without, the axis stands in position control where it is.
    #[doc(alias = "MC_AxCtrlPressure_BkPlcMc")]
    PressureControl {
        /// `Enable`.
        enable: bool,
        /// `fSetPressure`: bar, or N with `force`.
        set_value: f64,
        /// `kP`: output (normalised) per bar or per N.
        kp: f64,
        /// `Tn` (s; 0: no I part).
        tn: f64,
        /// `PreSet`: the I part on enabling.
        preset: f64,
        /// `WindupLimit` (> 0).
        windup_limit: f64,
        /// `ReadingMode`: the force (`iTcHydPressureReadingActForce`), else the pressure.
        force: bool,
    },
    /// The PID pressure or force controller with feed-forward of a hydraulic axis (Beckhoff
    /// TwinCAT PLC Hydraulic Positioning library, `MC_AxCtrlPressureFF_BkPlcMc` with
    /// `ST_TcPctrlParam`): enabled and not reset it takes the control value from the generator
    /// and controls the actual pressure or force to `inputs.setpoint`; a running one takes the
    /// new inputs and parameters each time it is given; disabled or reset, the axis stands in
    /// position control where it is.
    #[doc(alias = "MC_AxCtrlPressureFF_BkPlcMc")]
    PressureControlFf {
        /// `Enable`.
        enable: bool,
        /// `Reset`: the I part cleared, the controller inactive.
        reset: bool,
        /// `Enable_P`, `Enable_I`, `Enable_D`, `Setpoint`, `FeedVelocity`, `FeedCharge`.
        inputs: crate::hydraulic::pressure_ff::PidInputs,
        /// `ST_TcPctrlParam` (`pParam`) and the reading mode.
        params: crate::hydraulic::pressure_ff::PctrlParams,
    },
    /// The automatic zero compensation of a hydraulic axis with a zero-overlap valve (Beckhoff
    /// TwinCAT PLC Hydraulic Positioning library, `MC_AxCtrlAutoZero_BkPlcMc`): with `enable` it
    /// adjusts `fZeroCompensation` at standstill until the lag is gone; without, the value
    /// stays.
    #[doc(alias = "MC_AxCtrlAutoZero_BkPlcMc")]
    AutoZero {
        /// `Enable`.
        enable: bool,
        /// `EnableOnMoving`, `OffsetLimit`, `Tn`, `Threshold`, `Filter`.
        params: crate::hydraulic::auto_zero::AutoZeroParams,
    },
    /// `MC_AxCtrlSlowDownOnPressureEx_BkPlcMc` (Beckhoff TwinCAT PLC Hydraulic Positioning
    /// library, 4.4.1.5): with `enable` the hydraulic axis' moves are braked so that the
    /// actual pressure or force does not pass `params.set_point`; without, the limit ends.
    #[doc(alias = "MC_AxCtrlSlowDownOnPressureEx_BkPlcMc")]
    SlowDownOnPressure {
        /// `Enable`.
        enable: bool,
        /// `EnableRelief`, `Setpoint`, `kP`, `FeedVelocity` and the reading.
        params: crate::hydraulic::slow_down::SlowDownParams,
    },
    /// `MC_EmergencyStop_BkPlcMc` (Beckhoff TwinCAT PLC Hydraulic Positioning library, from
    /// V3.0.5): the set velocity ramps to 0 on the generator (`RampTime` from `fRefVelo`, else
    /// `fEmergencyRamp`); once it is 0 the valve output is suppressed while `execute` stays
    /// TRUE (`bLocked_Estop`). Re-sent with `execute = false` to release the lock.
    #[doc(alias = "MC_EmergencyStop_BkPlcMc")]
    EmergencyStop {
        /// `Execute` (TRUE: stop and lock; FALSE: release).
        execute: bool,
        /// `RampTime` (s from `fRefVelo` to 0; not above 0: `fEmergencyRamp`).
        ramp_time: f64,
    },
    /// `MC_ImmediateStop_BkPlcMc` (Beckhoff hydraulic library, from V3.0.5): the control value
    /// is 0 at once, no ramp; the valve output is suppressed while `execute` stays TRUE.
    #[doc(alias = "MC_ImmediateStop_BkPlcMc")]
    ImmediateStop {
        /// `Execute` (TRUE: stop and lock; FALSE: release).
        execute: bool,
    },
    /// `MC_RampedStop_BkPlcMc` (Beckhoff hydraulic library): a pure time ramp of the set
    /// velocity to 0, with no defined end position (it may overrun a software limit).
    #[doc(alias = "MC_RampedStop_BkPlcMc")]
    RampedStop {
        /// `RampTime` (s from `fRefVelo` to 0; not above 0: `fStopRamp`).
        ramp_time: f64,
    },
    /// `MC_SetPosition_BkPlcMc` (Beckhoff hydraulic library): sets the actual position, also
    /// during a motion (the set position, the target and the target window move with it).
    #[doc(alias = "MC_SetPosition_BkPlcMc")]
    HydSetPosition {
        /// `Position` (mm): the new actual position, or the shift with `relative`.
        position: f64,
        /// `Mode`: TRUE shifts the actual position by `position`, FALSE sets it.
        relative: bool,
    },
    /// `MC_SetReferenceFlag_BkPlcMc` (Beckhoff hydraulic library): sets or clears the axis'
    /// homed status (`dwTcHydNsDwReferenced`).
    #[doc(alias = "MC_SetReferenceFlag_BkPlcMc")]
    SetReferenceFlag {
        /// `ReferenceFlag`.
        reference_flag: bool,
    },
    /// `MC_ResetAndStop_BkPlcMc` (Beckhoff hydraulic library): acknowledges the axis' errors
    /// as MC_Reset does, aborts a motion and stops it (not interruptible); Done once the axis is
    /// error-free and stands.
    #[doc(alias = "MC_ResetAndStop_BkPlcMc")]
    ResetAndStop {
        /// `Deceleration` (mm/s²; not above 0: `RampTime`).
        deceleration: f64,
        /// `RampTime` (s from `fRefVelo` to 0; not above 0 either: `fMaxDec`).
        ramp_time: f64,
    },
    /// `MC_MoveJog_BkPlcMc` (Beckhoff hydraulic library, 4.2.19): level inputs, re-sent with
    /// their current values; a rising edge starts (JogForward wins), no edge is accepted while
    /// the axis moves. The velocity modes stop when the input of their direction falls; inching
    /// moves by `position` per rising edge.
    #[doc(alias = "MC_MoveJog_BkPlcMc")]
    HydMoveJog {
        /// `JogForward`.
        forward: bool,
        /// `JogBackwards`.
        backward: bool,
        /// `Mode` (`E_TcMcJogMode`).
        mode: HydJogMode,
        /// `Position` (mm): the distance of an inching step (its sign is the input's).
        position: f64,
        /// `Velocity`, `Acceleration`, `Deceleration` (0 or -1: the axis' defaults; used by
        /// the continuous and inching modes).
        dynamics: Dynamics,
    },
    /// `MC_MoveJoySticked_BkPlcMc` (Beckhoff hydraulic library, 4.2.14): a motion at
    /// `joystick · fRefVelo`, sent again with the current inputs; `execute = false` stops it.
    #[doc(alias = "MC_MoveJoySticked_BkPlcMc")]
    MoveJoySticked {
        /// `Execute`.
        execute: bool,
        /// `JoyStick` (±1.0).
        joystick: f64,
        /// `Acceleration` (mm/s², 0: `fMaxAcc`).
        acceleration: f64,
        /// `Deceleration` (mm/s², 0: `fMaxAcc`).
        deceleration: f64,
    },
    /// `MC_Home_BkPlcMc` (Beckhoff hydraulic library, 4.2.11): homing in the library's modes
    /// (AbsSwitch, RefPulse, Direct, Block) from an error-free standstill, sent again with the
    /// current inputs while it runs.
    #[doc(alias = "MC_Home_BkPlcMc")]
    HydHome(super::hyd_home::HydHomeInputs),
    /// `MC_AxRtSetDirectOutput_BkPlcMc` (Beckhoff hydraulic library, 4.4.7.7): the control
    /// value `out_value` output open loop, slewed with `ramp_time`; sent again with the current
    /// inputs, `enable = false` ramps it to 0 and ends it.
    #[doc(alias = "MC_AxRtSetDirectOutput_BkPlcMc")]
    SetDirectOutput {
        /// `Enable`.
        enable: bool,
        /// `OutValue` (normalised, ±1.0 = full scale).
        out_value: f64,
        /// `RampTime` (s for full scale; 0: at once).
        ramp_time: f64,
    },
    /// `MC_AxRtSetExtGenValues_BkPlcMc` (Beckhoff hydraulic library, 4.4.7.8): set values from
    /// outside the axis' generator, sent each cycle; `enable = false` ends it (a moving axis
    /// stops with `fStopRamp`).
    #[doc(alias = "MC_AxRtSetExtGenValues_BkPlcMc")]
    SetExtGenValues {
        /// `Enable`.
        enable: bool,
        /// `Position` (mm): the set position of this cycle.
        position: f64,
        /// `Velocity` (mm/s): the set velocity of this cycle.
        velocity: f64,
        /// `TargetPosition` (mm): the target of the current motion.
        target_position: f64,
    },
    /// `MC_AxRtFollowUp_BkPlcMc` (Beckhoff hydraulic library, 4.4.9.3): while `enable`, the set
    /// position follows the actual one with the position controller off; `enable = false`
    /// closes the loop again at the actual position.
    #[doc(alias = "MC_AxRtFollowUp_BkPlcMc")]
    FollowUp {
        /// `Enable`.
        enable: bool,
    },
    /// `MC_AxUtiOffsetLatch_BkPlcMc` (Beckhoff hydraulic library, 4.4.9.5): with `execute`,
    /// the position controller's output at standstill becomes part of `fZeroCompensation`.
    #[doc(alias = "MC_AxUtiOffsetLatch_BkPlcMc")]
    OffsetLatch {
        /// `Execute` (each command with `true` is a rising edge).
        execute: bool,
        /// `OffsetLimit` (V, default 0.5): the largest controller output accepted.
        offset_limit: f64,
    },
    /// Writes `Override.Velocity` (0..200 %), effective at once with the jobs' dynamics.
    #[doc(alias = "MC_SetOverride")]
    SetOverride {
        /// Velocity override in %.
        velocity: f64,
    },
    /// `MC_WriteParameter`: writes the run-time parameter `parameter` (the tag's number in
    /// `AXIS_PARAMETERS`, docs/parameters.md) to `value` (a boolean as 0 or 1), effective as the
    /// tag's row says; refused with the row's ErrorID (16#8080, 16#8081, 16#8086, 16#808B or
    /// the value's), changing nothing.
    #[doc(alias = "MC_WriteParameter")]
    WriteParameter {
        /// The parameter number (tag name mapped by the parser).
        parameter: u16,
        /// The new value.
        value: f64,
    },
    /// `MC_ReadParameter`: checks that the axis has the parameter (Done) or refuses it (16#8080,
    /// 16#8086); the value is read with `Axis::read_parameter`.
    #[doc(alias = "MC_ReadParameter")]
    ReadParameter {
        /// The parameter number.
        parameter: u16,
    },
    /// `MC_MotionInPosition`: direct position setpoints, no profile, no limits.
    #[doc(alias = "MC_MotionInPosition")]
    MotionInPosition {
        /// `Enable`.
        enable: bool,
        /// `Position`.
        position: f64,
        /// `Velocity` (precontrol).
        velocity: f64,
        /// `Acceleration`.
        acceleration: f64,
    },
    /// `MC_MotionInVelocity`: direct velocity setpoints, no profile, no limits.
    #[doc(alias = "MC_MotionInVelocity")]
    MotionInVelocity {
        /// `Enable`.
        enable: bool,
        /// `Velocity`.
        velocity: f64,
        /// `Acceleration` (only used when another job takes over).
        acceleration: f64,
        /// `PositionControlled`.
        position_controlled: bool,
    },
    /// `MC_TorqueLimiting`: force/torque limiting (mode 0) or fixed stop detection (mode 1),
    /// an enable-type job (S7-1500T Motion Control V4.0, 'MC_TorqueLimiting V4'). Sent each
    /// cycle while enabled (Limit and Mode are re-read); `enable` false ends the job.
    #[doc(alias = "MC_TorqueLimiting")]
    TorqueLimiting {
        /// `Enable`.
        enable: bool,
        /// `Limit` (N·m, or N on a linear axis): >= 0 used (0 too); < 0 the configured
        /// `torque_limiting.limit_default`.
        limit: f64,
        /// `Mode`: 0 force/torque limiting, 1 fixed stop detection.
        mode: i32,
    },
    /// `MC_TorqueAdditive`: an additive torque while enabled (S7-1500T Motion Control V4.0,
    /// 'MC_TorqueAdditive V4').
    #[doc(alias = "MC_TorqueAdditive")]
    TorqueAdditive {
        /// `Enable`.
        enable: bool,
        /// `Value` (N·m, or N on a linear axis; -1e12..1e12).
        value: f64,
    },
    /// `MC_TorqueRange`: upper and lower torque limits while enabled (S7-1500T Motion Control
    /// V4.0, 'MC_TorqueRange V4').
    #[doc(alias = "MC_TorqueRange")]
    TorqueRange {
        /// `Enable`.
        enable: bool,
        /// `UpperLimit` (default 1e12).
        upper_limit: f64,
        /// `LowerLimit` (default -1e12).
        lower_limit: f64,
    },
    /// `MC_GearIn`: relative gearing; synchronizes with the given dynamics, then `InGear`.
    #[doc(alias = "MC_GearIn")]
    GearIn {
        /// The leader (the runtime resolves names to ids).
        master: LeaderId,
        /// `RatioNumerator` (DINT, not 0; negative reverses).
        ratio_numerator: i32,
        /// `RatioDenominator` (DINT, >= 1).
        ratio_denominator: i32,
        /// `Acceleration`, `Deceleration`, `Jerk` (velocity unused).
        dynamics: Dynamics,
    },
    /// `MC_GearInPos`: absolute gearing, synchronous exactly at the sync positions.
    #[doc(alias = "MC_GearInPos")]
    GearInPos {
        /// The leader.
        master: LeaderId,
        /// `RatioNumerator`.
        ratio_numerator: i32,
        /// `RatioDenominator`.
        ratio_denominator: i32,
        /// `MasterSyncPosition`.
        master_sync_position: f64,
        /// `SlaveSyncPosition`.
        slave_sync_position: f64,
        /// `SyncProfileReference`.
        sync_profile_reference: SyncProfileReference,
        /// `MasterStartDistance` (> 0; used with reference 1).
        master_start_distance: f64,
        /// `Velocity`, `Acceleration`, `Deceleration`, `Jerk` (used with reference 0).
        dynamics: Dynamics,
        /// `SyncDirection` (modulo followers).
        sync_direction: SyncDirection,
    },
    /// `MC_FlyingGear_BkPlcMc` (Beckhoff TwinCAT PLC Hydraulic Positioning library, 4.2.6):
    /// level-driven gearing engaged and released on the fly, with ratio ramps in leader-position
    /// space (see `docs/hydraulics.md`). Re-sent with its current inputs; `enable = false` ends
    /// it.
    #[doc(alias = "MC_FlyingGear_BkPlcMc")]
    FlyingGear {
        /// The leader (`Master`).
        master: LeaderId,
        /// `Enable`.
        enable: bool,
        /// `Ratio`, the sync, desync and stop positions, `DefaultSlaveNegative`.
        params: super::sync::flying::FlyingGearParams,
    },
    /// `MC_CamIn`: camming. `following = f((leading - MasterOffset) / MasterScaling) *
    /// SlaveScaling + SlaveOffset`; synchronous at `MasterSyncPosition` (relative to the cam
    /// start) after a synchronization like MC_GearInPos, or at once (reference `Direct`).
    #[doc(alias = "MC_CamIn")]
    CamIn {
        /// The leader.
        master: LeaderId,
        /// The cam (provided with [`crate::objects::axis::Axis::provide_cam`] just before).
        cam: CamId,
        /// `MasterOffset`.
        master_offset: f64,
        /// `SlaveOffset`.
        slave_offset: f64,
        /// `MasterScaling` (> 0).
        master_scaling: f64,
        /// `SlaveScaling` (not 0).
        slave_scaling: f64,
        /// `MasterSyncPosition`, relative to the cam start, inside the cam.
        master_sync_position: f64,
        /// `SyncProfileReference` 0, 1 or 2.
        sync_profile_reference: SyncProfileReference,
        /// `MasterStartDistance` (reference 1).
        master_start_distance: f64,
        /// `Velocity`, `Acceleration`, `Deceleration`, `Jerk` (reference 0).
        dynamics: Dynamics,
        /// `ApplicationMode`.
        application_mode: ApplicationMode,
        /// `SyncDirection` (modulo followers).
        sync_direction: SyncDirection,
    },
    /// `MC_CamOut`: ends camming; the follower continues with its current velocity.
    #[doc(alias = "MC_CamOut")]
    CamOut,
    /// `MC_SynchronizedMotionSimulation` (Enable-type): keeps a synchronous operation logically
    /// active while the follower stands still or is disabled (a safety door is open).
    #[doc(alias = "MC_SynchronizedMotionSimulation")]
    SynchronizedMotionSimulation {
        /// `Enable`.
        enable: bool,
    },
    /// `MC_GearOut`: ends gearing; the follower continues with its current velocity.
    #[doc(alias = "MC_GearOut")]
    GearOut,
    /// `MC_GearInVelocity`: velocity gearing. Synchronizes like MC_GearIn, then follows the
    /// leader's velocity times the ratio; the position is integrated, not locked, so a jump of
    /// the leader's position (homing) does not move the follower.
    #[doc(alias = "MC_GearInVelocity")]
    GearInVelocity {
        /// The leader.
        master: LeaderId,
        /// `RatioNumerator`.
        ratio_numerator: i32,
        /// `RatioDenominator`.
        ratio_denominator: i32,
        /// `Acceleration`, `Deceleration`, `Jerk`.
        dynamics: Dynamics,
    },
    /// `MC_OffsetAbsolute` / `MC_OffsetRelative`: shifts the following value of a synchronous
    /// operation (follower units).
    #[doc(alias = "MC_OffsetAbsolute")]
    #[doc(alias = "MC_OffsetRelative")]
    Offset {
        /// `Offset`.
        offset: f64,
        /// Absolute (the total becomes `offset`) or relative (added).
        absolute: bool,
        /// `Velocity`, `Acceleration`, `Deceleration`, `Jerk` of the shift.
        dynamics: Dynamics,
    },
    /// `MC_PhasingAbsolute` / `MC_PhasingRelative`: shifts the leading value the follower sees.
    #[doc(alias = "MC_PhasingAbsolute")]
    #[doc(alias = "MC_PhasingRelative")]
    Phasing {
        /// `PhaseShift` (leading value units).
        phase_shift: f64,
        /// Absolute (the total shift becomes `phase_shift`) or relative (added).
        absolute: bool,
        /// `Velocity`, `Acceleration`, `Deceleration`, `Jerk` of the shift.
        dynamics: Dynamics,
    },
}

/// `E_TcMcJogMode` of `MC_MoveJog_BkPlcMc` (Beckhoff hydraulic library, 4.3.38).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum HydJogMode {
    /// `MC_JOGMODE_STANDARD_SLOW` (0): `fJogVeloSlow` with the standard dynamics while the
    /// input is held.
    #[doc(alias = "MC_JOGMODE_STANDARD_SLOW")]
    StandardSlow,
    /// `MC_JOGMODE_STANDARD_FAST` (1): `fJogVeloFast` likewise.
    #[doc(alias = "MC_JOGMODE_STANDARD_FAST")]
    StandardFast,
    /// `MC_JOGMODE_CONTINUOUS` (2): the command's velocity and dynamics while held.
    #[doc(alias = "MC_JOGMODE_CONTINUOUS")]
    Continuous,
    /// `MC_JOGMODE_INCHING` (3): a relative move by `Position` per rising edge.
    #[doc(alias = "MC_JOGMODE_INCHING")]
    Inching,
}
