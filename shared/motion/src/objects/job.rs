//! Jobs: identifiers, the instructions they run, and the events they report (S7-1500T Motion
//! Control V4.0 function manual, 6.5 'Tracking active jobs').
//!
//! An Execute-type instruction starts a job and is answered at once with a [`JobId`] or a
//! rejection ([`crate::catalog::error_id::ErrorId`]); the job then reports its progress as
//! [`JobEvent`]s (Busy at start, then InVelocity / Done / CommandAborted / Error). Enable-type
//! instructions (MC_Power, MC_MoveJog, MC_MotionIn*) keep one job while their enable is held.

use crate::catalog::error_id::ErrorId;

/// Identifier of a job, unique per technology object (never 0).
pub type JobId = u32;

/// The PLCopen / S7-1500T instruction a job runs.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Instruction {
    /// `MC_Power`.
    Power,
    /// `MC_Reset`.
    Reset,
    /// `MC_Home`.
    Home,
    /// `MC_Halt`.
    Halt,
    /// `MC_Stop`.
    Stop,
    /// `MC_MoveAbsolute`.
    MoveAbsolute,
    /// `MC_MoveRelative`.
    MoveRelative,
    /// `MC_MoveVelocity`.
    MoveVelocity,
    /// `MC_MoveAdditive`.
    MoveAdditive,
    /// `MC_MoveJog`.
    MoveJog,
    /// `MC_MoveSuperimposed`.
    MoveSuperimposed,
    /// `MC_SetOverride` (tandem: writes `Override.Velocity`).
    SetOverride,
    /// `MC_WriteParameter` (a run-time parameter of the axis).
    WriteParameter,
    /// `MC_ReadParameter`.
    ReadParameter,
    /// `MC_MotionInPosition`.
    MotionInPosition,
    /// `MC_MotionInVelocity`.
    MotionInVelocity,
    /// `MC_AxCtrlPressure_BkPlcMc` (Beckhoff hydraulic library): pressure or force control.
    PressureControl,
    /// `MC_AxCtrlPressureFF_BkPlcMc` (Beckhoff hydraulic library): PID pressure or force
    /// control with feed-forward.
    PressureControlFf,
    /// `MC_AxCtrlAutoZero_BkPlcMc` (Beckhoff hydraulic library): automatic zero compensation.
    AutoZero,
    /// `MC_AxCtrlSlowDownOnPressureEx_BkPlcMc` (Beckhoff hydraulic library): slowing down on
    /// pressure.
    SlowDownOnPressure,
    /// `MC_EmergencyStop_BkPlcMc` (Beckhoff hydraulic library): stop on the emergency ramp,
    /// outputs locked while Execute.
    EmergencyStop,
    /// `MC_ImmediateStop_BkPlcMc` (Beckhoff hydraulic library): output 0 at once, locked while
    /// Execute.
    ImmediateStop,
    /// `MC_RampedStop_BkPlcMc` (Beckhoff hydraulic library): a time ramp of the set velocity.
    RampedStop,
    /// `MC_SetPosition_BkPlcMc` (Beckhoff hydraulic library): sets the actual position.
    SetPosition,
    /// `MC_SetReferenceFlag_BkPlcMc` (Beckhoff hydraulic library): sets the homed status.
    SetReferenceFlag,
    /// `MC_ResetAndStop_BkPlcMc` (Beckhoff hydraulic library): reset, abort and stop.
    ResetAndStop,
    /// `MC_MoveJog_BkPlcMc` (Beckhoff hydraulic library): jog in its four modes.
    HydMoveJog,
    /// `MC_MoveJoySticked_BkPlcMc` (Beckhoff hydraulic library): velocity from a joystick.
    MoveJoySticked,
    /// `MC_Home_BkPlcMc` (Beckhoff hydraulic library): homing in the library's modes.
    HydHome,
    /// `MC_AxRtSetDirectOutput_BkPlcMc` (Beckhoff hydraulic library): open-loop control value.
    SetDirectOutput,
    /// `MC_AxRtSetExtGenValues_BkPlcMc` (Beckhoff hydraulic library): external set values.
    SetExtGenValues,
    /// `MC_AxRtFollowUp_BkPlcMc` (Beckhoff hydraulic library): set values follow the actual ones.
    FollowUp,
    /// `MC_AxUtiOffsetLatch_BkPlcMc` (Beckhoff hydraulic library): the controller's output
    /// latched into the offset compensation.
    OffsetLatch,
    /// `MC_GearIn`.
    GearIn,
    /// `MC_GearInPos`.
    GearInPos,
    /// `MC_FlyingGear_BkPlcMc` (Beckhoff hydraulic library): gearing engaged and released in
    /// leader-position space.
    FlyingGear,
    /// `MC_GearOut`.
    GearOut,
    /// `MC_GearInVelocity`.
    GearInVelocity,
    /// `MC_CamIn`.
    CamIn,
    /// `MC_CamOut`.
    CamOut,
    /// `MC_SynchronizedMotionSimulation`.
    SynchronizedMotionSimulation,
    /// `MC_OffsetAbsolute`.
    OffsetAbsolute,
    /// `MC_OffsetRelative`.
    OffsetRelative,
    /// `MC_PhasingAbsolute`.
    PhasingAbsolute,
    /// `MC_PhasingRelative`.
    PhasingRelative,
    /// `MC_TorqueLimiting`: force/torque limiting and fixed stop detection.
    TorqueLimiting,
    /// `MC_TorqueAdditive`: an additive torque.
    TorqueAdditive,
    /// `MC_TorqueRange`: upper and lower torque limits.
    TorqueRange,
}

impl Instruction {
    /// The PLCopen name, e.g. `MC_MoveAbsolute`.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Power => "MC_Power",
            Self::Reset => "MC_Reset",
            Self::Home => "MC_Home",
            Self::Halt => "MC_Halt",
            Self::Stop => "MC_Stop",
            Self::MoveAbsolute => "MC_MoveAbsolute",
            Self::MoveRelative => "MC_MoveRelative",
            Self::MoveVelocity => "MC_MoveVelocity",
            Self::MoveAdditive => "MC_MoveAdditive",
            Self::MoveJog => "MC_MoveJog",
            Self::MoveSuperimposed => "MC_MoveSuperimposed",
            Self::SetOverride => "MC_SetOverride",
            Self::WriteParameter => "MC_WriteParameter",
            Self::ReadParameter => "MC_ReadParameter",
            Self::MotionInPosition => "MC_MotionInPosition",
            Self::MotionInVelocity => "MC_MotionInVelocity",
            Self::PressureControl => "MC_AxCtrlPressure_BkPlcMc",
            Self::PressureControlFf => "MC_AxCtrlPressureFF_BkPlcMc",
            Self::AutoZero => "MC_AxCtrlAutoZero_BkPlcMc",
            Self::SlowDownOnPressure => "MC_AxCtrlSlowDownOnPressureEx_BkPlcMc",
            Self::EmergencyStop => "MC_EmergencyStop_BkPlcMc",
            Self::ImmediateStop => "MC_ImmediateStop_BkPlcMc",
            Self::RampedStop => "MC_RampedStop_BkPlcMc",
            Self::SetPosition => "MC_SetPosition_BkPlcMc",
            Self::SetReferenceFlag => "MC_SetReferenceFlag_BkPlcMc",
            Self::ResetAndStop => "MC_ResetAndStop_BkPlcMc",
            Self::HydMoveJog => "MC_MoveJog_BkPlcMc",
            Self::MoveJoySticked => "MC_MoveJoySticked_BkPlcMc",
            Self::HydHome => "MC_Home_BkPlcMc",
            Self::SetDirectOutput => "MC_AxRtSetDirectOutput_BkPlcMc",
            Self::SetExtGenValues => "MC_AxRtSetExtGenValues_BkPlcMc",
            Self::FollowUp => "MC_AxRtFollowUp_BkPlcMc",
            Self::OffsetLatch => "MC_AxUtiOffsetLatch_BkPlcMc",
            Self::GearIn => "MC_GearIn",
            Self::GearInPos => "MC_GearInPos",
            Self::FlyingGear => "MC_FlyingGear_BkPlcMc",
            Self::GearOut => "MC_GearOut",
            Self::GearInVelocity => "MC_GearInVelocity",
            Self::CamIn => "MC_CamIn",
            Self::CamOut => "MC_CamOut",
            Self::SynchronizedMotionSimulation => "MC_SynchronizedMotionSimulation",
            Self::OffsetAbsolute => "MC_OffsetAbsolute",
            Self::OffsetRelative => "MC_OffsetRelative",
            Self::PhasingAbsolute => "MC_PhasingAbsolute",
            Self::PhasingRelative => "MC_PhasingRelative",
            Self::TorqueLimiting => "MC_TorqueLimiting",
            Self::TorqueAdditive => "MC_TorqueAdditive",
            Self::TorqueRange => "MC_TorqueRange",
        }
    }
}

/// What happened to a job.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum JobEventKind {
    /// Accepted and running (`Busy`); a queued job (PLCopen `BufferMode`) is Busy while it
    /// waits.
    Busy,
    /// A queued job took over the axis (PLCopen `Active`).
    Active,
    /// The target velocity is reached (`InVelocity`, velocity and jog jobs).
    InVelocity,
    /// The target velocity is left again (override change, stop of a jog).
    LeftVelocity,
    /// Finished (`Done`).
    Done,
    /// `MC_Power.Status` changed (TRUE: enabled, FALSE: disabled).
    Status(bool),
    /// `InGear` (MC_GearIn): velocity and acceleration match the leader's times the ratio.
    InGear,
    /// `StartSync` (MC_GearInPos, MC_CamIn): synchronization has started.
    StartSync,
    /// `InSync` (MC_GearInPos, MC_CamIn): synchronous at the sync positions.
    InSync,
    /// `EndOfProfile` (MC_CamIn): the leading value passed an end of the cam.
    EndOfProfile,
    /// `InSimulation` (MC_SynchronizedMotionSimulation): TRUE or FALSE.
    InSimulation(bool),
    /// Aborted by another job or by an alarm reaction (`CommandAborted`).
    CommandAborted,
    /// Ended with an error (`Error`, `ErrorID`), e.g. 16#8001 when an alarm ended it.
    Error(ErrorId),
}

/// One job event, with the time (ns, cell clock) of the cycle it happened in.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct JobEvent {
    /// The job.
    pub job: JobId,
    /// Its instruction.
    pub instruction: Instruction,
    /// What happened.
    pub kind: JobEventKind,
    /// Cycle time (ns).
    pub time_ns: i64,
}

/// Capacity of an event queue.
pub const EVENT_CAPACITY: usize = 64;

/// Fixed-capacity FIFO of job events; when full the oldest event is dropped and counted.
///
/// The counts come last (`repr(C)`): the cycle reads them every time, the slots seldom, and
/// an axis keeps the state its cycle reads right after them.
#[derive(Clone, Debug)]
#[repr(C)]
pub struct EventQueue {
    buf: [Option<JobEvent>; EVENT_CAPACITY],
    head: usize,
    len: usize,
    dropped: u64,
}

impl Default for EventQueue {
    fn default() -> Self {
        Self {
            buf: [None; EVENT_CAPACITY],
            head: 0,
            len: 0,
            dropped: 0,
        }
    }
}

impl EventQueue {
    /// Appends an event (dropping the oldest when full).
    pub fn push(&mut self, e: JobEvent) {
        if self.len == EVENT_CAPACITY {
            self.head = (self.head + 1) % EVENT_CAPACITY;
            self.len -= 1;
            self.dropped += 1;
        }
        self.buf[(self.head + self.len) % EVENT_CAPACITY] = Some(e);
        self.len += 1;
    }

    /// Removes and returns the oldest event.
    pub fn pop(&mut self) -> Option<JobEvent> {
        if self.len == 0 {
            return None;
        }
        let e = self.buf[self.head].take();
        self.head = (self.head + 1) % EVENT_CAPACITY;
        self.len -= 1;
        e
    }

    /// Number of queued events.
    pub fn len(&self) -> usize {
        self.len
    }

    /// No queued events.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Events dropped because the queue was full.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn queue_drops_oldest_and_counts() {
        let mut q = EventQueue::default();
        for i in 0..(EVENT_CAPACITY as u32 + 3) {
            q.push(JobEvent {
                job: i + 1,
                instruction: Instruction::Halt,
                kind: JobEventKind::Done,
                time_ns: 0,
            });
        }
        assert_eq!(q.len(), EVENT_CAPACITY);
        assert_eq!(q.dropped(), 3);
        assert_eq!(q.pop().map(|e| e.job), Some(4));
    }
}
