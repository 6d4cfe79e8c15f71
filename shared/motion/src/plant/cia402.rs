//! The CiA 402 drive profile (IEC 61800-7-201) as pure data and state machines, both sides.
//!
//! - The objects: controlword 0x6040 and statusword 0x6041 bits ([`controlword`],
//!   [`statusword`]), the device states and their statusword patterns ([`Cia402State`]), the
//!   device commands ([`DeviceCommand`]), modes of operation 0x6060/0x6061
//!   ([`ModeOfOperation`]), quick stop option 0x605A ([`QuickStopOption`]) and the cyclic PDOs
//!   of a CSP/CSV/CST drive ([`DriveCommand`], [`DriveFeedback`]).
//! - The drive side: [`DeviceStateMachine`], every transition 0..16 of the profile's state
//!   diagram.
//! - The controller side: [`EnableSequence`], the enable handshake that MC_Power runs on a drive
//!   (S7-1500T Motion Control V4.0 function manual, 1.2 "Drive and encoder connection": the
//!   technology object enables the drive and reacts to its faults; MC_Reset acknowledges them on
//!   the drive).
//!
//! Reference: IEC 61800-7-201 (CiA 402) drive profile: objects 0x6040, 0x6041, 0x605A, 0x6060,
//! 0x6061, 0x60B8, 0x60B9 and the state diagram (transitions 0..16).
//!
//! Every function here is pure: no clock (time is an input), no allocation.

use core::fmt;

/// Controlword 0x6040 bits (IEC 61800-7-201 (CiA 402) drive profile, 0x6040).
#[doc(alias = "0x6040")]
pub mod controlword {
    /// Bit 0: switch on.
    pub const SWITCH_ON: u16 = 0x0001;
    /// Bit 1: enable voltage.
    pub const ENABLE_VOLTAGE: u16 = 0x0002;
    /// Bit 2: quick stop, active low (0 = quick stop requested).
    pub const QUICK_STOP: u16 = 0x0004;
    /// Bit 3: enable operation.
    pub const ENABLE_OPERATION: u16 = 0x0008;
    /// Bit 7: fault reset; acts on its rising edge.
    pub const FAULT_RESET: u16 = 0x0080;
    /// Bit 8: halt (mode-specific).
    pub const HALT: u16 = 0x0100;
    /// The bits that select a device command (7, 3, 2, 1, 0).
    pub const COMMAND_MASK: u16 =
        FAULT_RESET | ENABLE_OPERATION | QUICK_STOP | ENABLE_VOLTAGE | SWITCH_ON;
}

/// Statusword 0x6041 bits (IEC 61800-7-201 (CiA 402) drive profile, 0x6041).
#[doc(alias = "0x6041")]
pub mod statusword {
    /// Bit 0: ready to switch on.
    pub const READY_TO_SWITCH_ON: u16 = 0x0001;
    /// Bit 1: switched on.
    pub const SWITCHED_ON: u16 = 0x0002;
    /// Bit 2: operation enabled.
    pub const OPERATION_ENABLED: u16 = 0x0004;
    /// Bit 3: fault.
    pub const FAULT: u16 = 0x0008;
    /// Bit 4: voltage enabled.
    pub const VOLTAGE_ENABLED: u16 = 0x0010;
    /// Bit 5: quick stop, active low (0 = quick stop active).
    pub const QUICK_STOP: u16 = 0x0020;
    /// Bit 6: switch on disabled.
    pub const SWITCH_ON_DISABLED: u16 = 0x0040;
    /// Bit 7: warning.
    pub const WARNING: u16 = 0x0080;
    /// Bit 9: remote (the drive is controlled through the fieldbus).
    pub const REMOTE: u16 = 0x0200;
    /// Bit 10: target reached.
    pub const TARGET_REACHED: u16 = 0x0400;
    /// Bit 11: internal limit active.
    pub const INTERNAL_LIMIT_ACTIVE: u16 = 0x0800;
    /// Bit 12 in CSP, CSV and CST: the drive follows the command value.
    pub const FOLLOWS_COMMAND: u16 = 0x1000;
    /// Bit 13 in CSP: following error.
    pub const FOLLOWING_ERROR: u16 = 0x2000;
    /// The bits that encode the device state (6, 5, 3, 2, 1, 0).
    pub const STATE_MASK: u16 = 0x006F;
}

/// A state of the CiA 402 device state machine (IEC 61800-7-201 (CiA 402) drive profile, state
/// diagram; the statusword patterns of 0x6041).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Cia402State {
    /// Not ready to switch on: the drive initializes and runs its self test.
    NotReadyToSwitchOn,
    /// Switch on disabled: initialized; the power section cannot be switched on.
    SwitchOnDisabled,
    /// Ready to switch on: waits for "switch on".
    ReadyToSwitchOn,
    /// Switched on: the power section is ready; no torque.
    SwitchedOn,
    /// Operation enabled: the drive follows its set-points.
    OperationEnabled,
    /// Quick stop active: the drive stops on its quick stop reaction (0x605A).
    QuickStopActive,
    /// Fault reaction active: a fault occurred; the drive runs its fault reaction.
    FaultReactionActive,
    /// Fault: the fault reaction has ended; waits for a fault reset.
    Fault,
}

impl Cia402State {
    /// All states, in the order of the profile's state diagram.
    pub const ALL: [Cia402State; 8] = [
        Self::NotReadyToSwitchOn,
        Self::SwitchOnDisabled,
        Self::ReadyToSwitchOn,
        Self::SwitchedOn,
        Self::OperationEnabled,
        Self::QuickStopActive,
        Self::FaultReactionActive,
        Self::Fault,
    ];

    /// Decodes the state from a statusword with the profile's mask/value table (IEC 61800-7-201
    /// (CiA 402) drive profile, 0x6041): `sw & 0x4F == 0x00` not ready to switch on, `0x40`
    /// switch on disabled, `0x0F` fault reaction active, `0x08` fault; `sw & 0x6F == 0x21` ready
    /// to switch on, `0x23` switched on, `0x27` operation enabled, `0x07` quick stop active.
    /// `None` for a pattern the table does not define (e.g. `0x0001`, `0x0041`).
    pub const fn from_statusword(sw: u16) -> Option<Self> {
        match sw & 0x4F {
            0x00 => return Some(Self::NotReadyToSwitchOn),
            0x40 => return Some(Self::SwitchOnDisabled),
            0x0F => return Some(Self::FaultReactionActive),
            0x08 => return Some(Self::Fault),
            _ => {}
        }
        match sw & 0x6F {
            0x21 => Some(Self::ReadyToSwitchOn),
            0x23 => Some(Self::SwitchedOn),
            0x27 => Some(Self::OperationEnabled),
            0x07 => Some(Self::QuickStopActive),
            _ => None,
        }
    }

    /// The state bits of the statusword in this state (bits 0..6; the other bits are the
    /// drive's, e.g. remote 0x200).
    ///
    /// The bits the table leaves open ("x") are chosen so:
    /// - bit 4 voltage enabled is set in the states that follow an accepted "enable voltage"
    ///   (ready to switch on, switched on, operation enabled, quick stop active) and in fault
    ///   reaction active (the power section brakes the motor); it is clear in not ready to
    ///   switch on, switch on disabled and fault (inferred: the profile leaves it open in the
    ///   pattern; a healthy enabled drive reports 0x0237, so the enabled states set it);
    /// - bit 5 quick stop (active low) is set where the table requires it (ready to switch on,
    ///   switched on, operation enabled) and clear everywhere else.
    ///
    /// So: 0x0000, 0x0040, 0x0031, 0x0033, 0x0037, 0x0017, 0x001F, 0x0008 in the order of
    /// [`Cia402State::ALL`].
    pub const fn statusword(self) -> u16 {
        match self {
            Self::NotReadyToSwitchOn => 0x0000,
            Self::SwitchOnDisabled => 0x0040,
            Self::ReadyToSwitchOn => 0x0031,
            Self::SwitchedOn => 0x0033,
            Self::OperationEnabled => 0x0037,
            Self::QuickStopActive => 0x0017,
            Self::FaultReactionActive => 0x001F,
            Self::Fault => 0x0008,
        }
    }

    /// The state's name as the profile writes it.
    pub const fn name(self) -> &'static str {
        match self {
            Self::NotReadyToSwitchOn => "Not ready to switch on",
            Self::SwitchOnDisabled => "Switch on disabled",
            Self::ReadyToSwitchOn => "Ready to switch on",
            Self::SwitchedOn => "Switched on",
            Self::OperationEnabled => "Operation enabled",
            Self::QuickStopActive => "Quick stop active",
            Self::FaultReactionActive => "Fault reaction active",
            Self::Fault => "Fault",
        }
    }

    /// Whether the state is one of the two fault states (statusword bit 3 set).
    pub const fn is_fault(self) -> bool {
        matches!(self, Self::FaultReactionActive | Self::Fault)
    }
}

impl fmt::Display for Cia402State {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A device command, decoded from the controlword bits 7, 3, 2, 1, 0 (IEC 61800-7-201 (CiA 402)
/// drive profile, 0x6040 command table).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum DeviceCommand {
    /// `0 x 1 1 0` (typical 0x0006): transitions 2, 6, 8.
    Shutdown,
    /// `0 0 1 1 1` (typical 0x0007) outside operation enabled: transition 3.
    SwitchOn,
    /// `0 1 1 1 1` (typical 0x000F) in ready to switch on: transition 3, then 4.
    SwitchOnEnableOperation,
    /// `0 1 1 1 1` (typical 0x000F): transitions 4, 16.
    EnableOperation,
    /// `0 0 1 1 1` (typical 0x0007) in operation enabled: transition 5.
    DisableOperation,
    /// `0 x x 0 x` (typical 0x0000): transitions 7, 9, 10, 12.
    DisableVoltage,
    /// `0 x 0 1 x` (typical 0x0002): transitions 7, 10, 11.
    QuickStop,
    /// Rising edge of bit 7 (typical 0x0080): transition 15.
    FaultReset,
}

impl DeviceCommand {
    /// Decodes the command of `controlword` in `state`; `previous` is the controlword of the
    /// previous exchange (bit 7 acts on its rising edge).
    ///
    /// The words of switch on / disable operation (`0 0 1 1 1`) and of enable operation /
    /// switch on + enable operation (`0 1 1 1 1`) are the same; the state tells them apart.
    /// While bit 7 stays set without an edge no command is decoded (every other command has bit
    /// 7 clear in the table).
    pub const fn decode(state: Cia402State, previous: u16, controlword: u16) -> Option<Self> {
        use self::controlword as cw;
        if controlword & cw::FAULT_RESET != 0 {
            return if previous & cw::FAULT_RESET == 0 {
                Some(Self::FaultReset)
            } else {
                None
            };
        }
        if controlword & cw::ENABLE_VOLTAGE == 0 {
            return Some(Self::DisableVoltage);
        }
        if controlword & cw::QUICK_STOP == 0 {
            return Some(Self::QuickStop);
        }
        if controlword & cw::SWITCH_ON == 0 {
            return Some(Self::Shutdown);
        }
        let operation_enabled = matches!(state, Cia402State::OperationEnabled);
        let ready = matches!(state, Cia402State::ReadyToSwitchOn);
        Some(
            match (
                controlword & cw::ENABLE_OPERATION != 0,
                operation_enabled,
                ready,
            ) {
                (false, true, _) => Self::DisableOperation,
                (false, false, _) => Self::SwitchOn,
                (true, _, true) => Self::SwitchOnEnableOperation,
                (true, _, false) => Self::EnableOperation,
            },
        )
    }

    /// The typical controlword of the command (the table's "typical word").
    pub const fn controlword(self) -> u16 {
        match self {
            Self::Shutdown => 0x0006,
            Self::SwitchOn | Self::DisableOperation => 0x0007,
            Self::SwitchOnEnableOperation | Self::EnableOperation => 0x000F,
            Self::DisableVoltage => 0x0000,
            Self::QuickStop => 0x0002,
            Self::FaultReset => 0x0080,
        }
    }
}

/// Modes of operation 0x6060 / display 0x6061 (INT8; IEC 61800-7-201 (CiA 402) drive profile).
#[doc(alias = "0x6060")]
#[doc(alias = "0x6061")]
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
#[repr(i8)]
pub enum ModeOfOperation {
    /// 0: no mode.
    NoMode = 0,
    /// 1: profile position (PP).
    ProfilePosition = 1,
    /// 3: profile velocity (PV).
    ProfileVelocity = 3,
    /// 4: profile torque (PT).
    ProfileTorque = 4,
    /// 6: homing.
    Homing = 6,
    /// 7: interpolated position (IP).
    InterpolatedPosition = 7,
    /// 8: cyclic synchronous position (CSP).
    CyclicSynchronousPosition = 8,
    /// 9: cyclic synchronous velocity (CSV).
    CyclicSynchronousVelocity = 9,
    /// 10: cyclic synchronous torque (CST).
    CyclicSynchronousTorque = 10,
}

impl ModeOfOperation {
    /// The mode's value in 0x6060 / 0x6061.
    pub const fn value(self) -> i8 {
        self as i8
    }

    /// Whether the mode is one of the cyclic synchronous modes (CSP, CSV, CST).
    pub const fn is_cyclic(self) -> bool {
        matches!(
            self,
            Self::CyclicSynchronousPosition
                | Self::CyclicSynchronousVelocity
                | Self::CyclicSynchronousTorque
        )
    }
}

/// A value of 0x6060 / 0x6061 that names no mode of the profile.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct UnknownModeOfOperation {
    /// The value that was given.
    pub value: i8,
}

impl fmt::Display for UnknownModeOfOperation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "modes of operation (0x6060) {} is not one of 0, 1, 3, 4, 6, 7, 8, 9, 10",
            self.value
        )
    }
}

impl std::error::Error for UnknownModeOfOperation {}

impl TryFrom<i8> for ModeOfOperation {
    type Error = UnknownModeOfOperation;

    fn try_from(value: i8) -> Result<Self, Self::Error> {
        Ok(match value {
            0 => Self::NoMode,
            1 => Self::ProfilePosition,
            3 => Self::ProfileVelocity,
            4 => Self::ProfileTorque,
            6 => Self::Homing,
            7 => Self::InterpolatedPosition,
            8 => Self::CyclicSynchronousPosition,
            9 => Self::CyclicSynchronousVelocity,
            10 => Self::CyclicSynchronousTorque,
            _ => return Err(UnknownModeOfOperation { value }),
        })
    }
}

/// Quick stop option code 0x605A (INT16): how the drive stops on a quick stop and whether it
/// then leaves quick stop active (IEC 61800-7-201 (CiA 402) drive profile, 0x605A).
#[doc(alias = "0x605A")]
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
#[repr(i16)]
pub enum QuickStopOption {
    /// 0: disable the drive function (the motor coasts), then switch on disabled.
    DisableDrive = 0,
    /// 1: stop on the slow-down ramp, then switch on disabled.
    SlowDownRamp = 1,
    /// 2: stop on the quick stop ramp, then switch on disabled.
    QuickStopRamp = 2,
    /// 3: stop at the current limit, then switch on disabled.
    CurrentLimit = 3,
    /// 4: stop at the voltage limit, then switch on disabled.
    VoltageLimit = 4,
    /// 5: stop on the slow-down ramp and stay in quick stop active.
    SlowDownRampStay = 5,
    /// 6: stop on the quick stop ramp and stay in quick stop active.
    QuickStopRampStay = 6,
    /// 7: stop at the current limit and stay in quick stop active.
    CurrentLimitStay = 7,
    /// 8: stop at the voltage limit and stay in quick stop active.
    VoltageLimitStay = 8,
}

impl QuickStopOption {
    /// The option's value in 0x605A.
    pub const fn value(self) -> i16 {
        self as i16
    }

    /// Options 5..8: the drive stays in quick stop active after stopping (and transition 16
    /// back to operation enabled is allowed); options 0..4 end in switch on disabled
    /// (transition 12).
    pub const fn stays_in_quick_stop(self) -> bool {
        (self as i16) >= 5
    }
}

/// A value of 0x605A outside 0..8.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct UnknownQuickStopOption {
    /// The value that was given.
    pub value: i16,
}

impl fmt::Display for UnknownQuickStopOption {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "quick stop option code (0x605A) {} is not one of 0..8",
            self.value
        )
    }
}

impl std::error::Error for UnknownQuickStopOption {}

impl TryFrom<i16> for QuickStopOption {
    type Error = UnknownQuickStopOption;

    fn try_from(value: i16) -> Result<Self, Self::Error> {
        Ok(match value {
            0 => Self::DisableDrive,
            1 => Self::SlowDownRamp,
            2 => Self::QuickStopRamp,
            3 => Self::CurrentLimit,
            4 => Self::VoltageLimit,
            5 => Self::SlowDownRampStay,
            6 => Self::QuickStopRampStay,
            7 => Self::CurrentLimitStay,
            8 => Self::VoltageLimitStay,
            _ => return Err(UnknownQuickStopOption { value }),
        })
    }
}

/// The receive PDO of a cyclic synchronous drive (controller → drive), latched by the drive at
/// the cycle boundary.
#[doc(alias = "RxPDO")]
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct DriveCommand {
    /// Controlword 0x6040 (see [`controlword`]).
    #[doc(alias = "0x6040")]
    pub controlword: u16,
    /// Modes of operation 0x6060 (see [`ModeOfOperation`]).
    #[doc(alias = "0x6060")]
    pub mode: i8,
    /// Target position 0x607A (increments), the CSP set-point.
    #[doc(alias = "0x607A")]
    pub target_position: i32,
    /// Target velocity 0x60FF (increments/s), the CSV set-point.
    #[doc(alias = "0x60FF")]
    pub target_velocity: i32,
    /// Target torque 0x6071 (per mille of the rated torque 0x6076), the CST set-point.
    #[doc(alias = "0x6071")]
    pub target_torque: i16,
    /// Velocity offset 0x60B1 (increments/s): velocity feedforward in CSP, added to the target
    /// velocity in CSV.
    #[doc(alias = "0x60B1")]
    pub velocity_offset: i32,
    /// Torque offset 0x60B2 (per mille of the rated torque): torque feedforward in CSP, CSV
    /// and CST.
    #[doc(alias = "0x60B2")]
    pub torque_offset: i16,
    /// Max torque 0x6072 (per mille of the rated torque). 0 means "no limit from the
    /// controller": the drive uses its own limit alone (inferred: a PDO that does not map
    /// 0x6072 leaves it 0, which must not mean "no torque"). Otherwise the smaller of this and
    /// the drive's own limit applies.
    #[doc(alias = "0x6072")]
    pub max_torque: u16,
    /// Positive torque limit value 0x60E0 (per mille of the rated torque): the largest torque
    /// in the positive direction; 0 as for 0x6072 (not sent: no limit from the controller).
    #[doc(alias = "0x60E0")]
    pub positive_torque_limit: u16,
    /// Negative torque limit value 0x60E1 (per mille, a magnitude): the largest torque in the
    /// negative direction; 0 as for 0x6072.
    #[doc(alias = "0x60E1")]
    pub negative_torque_limit: u16,
    /// Touch probe function 0x60B8 (see [`touch_probe`]).
    #[doc(alias = "0x60B8")]
    pub touch_probe_function: u16,
}

/// The transmit PDO of a cyclic synchronous drive (drive → controller), sampled at the cycle
/// boundary.
#[doc(alias = "TxPDO")]
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct DriveFeedback {
    /// Statusword 0x6041 (see [`statusword`]).
    #[doc(alias = "0x6041")]
    pub statusword: u16,
    /// Modes of operation display 0x6061.
    #[doc(alias = "0x6061")]
    pub mode_display: i8,
    /// Position actual value 0x6064 (increments; a 32-bit counter that wraps).
    #[doc(alias = "0x6064")]
    pub position_actual: i32,
    /// Velocity actual value 0x606C (increments/s).
    #[doc(alias = "0x606C")]
    pub velocity_actual: i32,
    /// Torque actual value 0x6077 (per mille of the rated torque).
    #[doc(alias = "0x6077")]
    pub torque_actual: i16,
    /// Following error actual value 0x60F4 (increments): position demand − position actual.
    #[doc(alias = "0x60F4")]
    pub following_error: i32,
    /// Error code 0x603F (CiA 301 ranges; 0 = no error).
    #[doc(alias = "0x603F")]
    pub error_code: u16,
    /// Digital inputs 0x60FD (see [`digital_inputs`]).
    #[doc(alias = "0x60FD")]
    pub digital_inputs: u32,
    /// Touch probe status 0x60B9 (see [`touch_probe`]).
    #[doc(alias = "0x60B9")]
    pub touch_probe_status: u16,
    /// Touch probe 1 positive edge value 0x60BA (increments).
    #[doc(alias = "0x60BA")]
    pub touch_probe_1_positive: i32,
    /// Touch probe 1 negative edge value 0x60BB (increments).
    #[doc(alias = "0x60BB")]
    pub touch_probe_1_negative: i32,
    /// Touch probe 2 positive edge value 0x60BC (increments).
    #[doc(alias = "0x60BC")]
    pub touch_probe_2_positive: i32,
    /// Touch probe 2 negative edge value 0x60BD (increments).
    #[doc(alias = "0x60BD")]
    pub touch_probe_2_negative: i32,
}

/// Digital inputs 0x60FD bits (IEC 61800-7-201 (CiA 402) drive profile, 0x60FD).
#[doc(alias = "0x60FD")]
pub mod digital_inputs {
    /// Bit 0: negative limit switch.
    pub const NEGATIVE_LIMIT: u32 = 0x0001;
    /// Bit 1: positive limit switch.
    pub const POSITIVE_LIMIT: u32 = 0x0002;
    /// Bit 2: home switch.
    pub const HOME_SWITCH: u32 = 0x0004;
    /// Bit 3: interlock.
    pub const INTERLOCK: u32 = 0x0008;
}

/// Touch probe function 0x60B8 and status 0x60B9 bits (IEC 61800-7-201 (CiA 402) drive
/// profile, 0x60B8/0x60B9). The bits of touch probe 2 are those of touch probe 1 shifted left
/// by [`touch_probe::PROBE_2_SHIFT`].
#[doc(alias = "0x60B8")]
#[doc(alias = "0x60B9")]
pub mod touch_probe {
    /// Function bit 0: enable touch probe 1.
    pub const ENABLE: u16 = 0x0001;
    /// Function bit 1: 0 = first event only, 1 = continuous.
    pub const CONTINUOUS: u16 = 0x0002;
    /// Function bits 2..3: the trigger source (see [`SOURCE_INPUT`], [`SOURCE_ZERO_PULSE`]).
    pub const SOURCE_MASK: u16 = 0x000C;
    /// Trigger source 00: the touch probe input.
    pub const SOURCE_INPUT: u16 = 0x0000;
    /// Trigger source 01: the encoder zero pulse.
    pub const SOURCE_ZERO_PULSE: u16 = 0x0004;
    /// Trigger source 10: the source selected in 0x60D0:01.
    pub const SOURCE_60D0: u16 = 0x0008;
    /// Function bit 4: sample on the positive edge.
    pub const SAMPLE_POSITIVE: u16 = 0x0010;
    /// Function bit 5: sample on the negative edge.
    pub const SAMPLE_NEGATIVE: u16 = 0x0020;
    /// Status bit 0: touch probe 1 enabled.
    pub const STATUS_ENABLED: u16 = 0x0001;
    /// Status bit 1: a positive edge value is stored.
    pub const STATUS_POSITIVE_STORED: u16 = 0x0002;
    /// Status bit 2: a negative edge value is stored.
    pub const STATUS_NEGATIVE_STORED: u16 = 0x0004;
    /// Status bit 6 (user bit): toggles with every positive edge value stored in continuous
    /// mode (inferred: the usual use of the user bits).
    pub const STATUS_POSITIVE_TOGGLE: u16 = 0x0040;
    /// Status bit 7 (user bit): toggles with every negative edge value stored in continuous
    /// mode (inferred).
    pub const STATUS_NEGATIVE_TOGGLE: u16 = 0x0080;
    /// The shift from the touch probe 1 bits to the touch probe 2 bits.
    pub const PROBE_2_SHIFT: u32 = 8;
}

/// What the device knows besides the controlword when it steps its state machine.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct DeviceInputs {
    /// A fault cause is present (transition 13; transition 15 only once it is gone).
    pub fault: bool,
    /// The fault reaction or the quick stop ramp has ended (transitions 14 and 12).
    pub reaction_finished: bool,
    /// The self test after power-up is done (transition 1).
    pub self_test_done: bool,
}

/// One transition of the device state machine (IEC 61800-7-201 (CiA 402) drive profile, state
/// diagram transitions 0..16).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct Transition {
    /// The transition number of the state diagram, 0..=16.
    pub number: u8,
    /// The state before; `None` only for transition 0 (from "Start", before power-up).
    pub from: Option<Cia402State>,
    /// The state after.
    pub to: Cia402State,
}

/// The drive side of the profile: the device state machine with every transition 0..16 of the
/// state diagram, stepped once per exchange with the controlword.
///
/// At most one transition per [`DeviceStateMachine::step`]: "switch on + enable operation"
/// (0x000F in ready to switch on) takes transition 3 in one exchange and 4 in the next (inferred:
/// the device passes through switched on; the table lists both transitions for the command).
/// Transition 0 (start → not ready to switch on) is reported by the first step.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct DeviceStateMachine {
    state: Cia402State,
    powered_up: bool,
    quick_stop_option: QuickStopOption,
    previous_controlword: u16,
}

impl DeviceStateMachine {
    /// A device before power-up; its state reads not ready to switch on. `quick_stop_option`
    /// (0x605A) decides transitions 12 and 16.
    pub const fn new(quick_stop_option: QuickStopOption) -> Self {
        Self {
            state: Cia402State::NotReadyToSwitchOn,
            powered_up: false,
            quick_stop_option,
            previous_controlword: 0,
        }
    }

    /// The current state.
    pub const fn state(&self) -> Cia402State {
        self.state
    }

    /// The state bits of the statusword (see [`Cia402State::statusword`]).
    pub const fn statusword(&self) -> u16 {
        self.state.statusword()
    }

    /// The quick stop option code 0x605A the device was built with.
    pub const fn quick_stop_option(&self) -> QuickStopOption {
        self.quick_stop_option
    }

    /// One exchange: applies `controlword` (compared with the previous one for the fault reset
    /// edge) and `inputs`, and returns the transition taken, if any.
    ///
    /// Precedence: transition 0 on the first step; then a fault cause outside the fault states
    /// (13, from any state); then the state's own transitions. A command the state has no
    /// transition for is ignored (e.g. enable operation in switch on disabled).
    pub fn step(&mut self, controlword: u16, inputs: DeviceInputs) -> Option<Transition> {
        let previous = core::mem::replace(&mut self.previous_controlword, controlword);
        if !self.powered_up {
            self.powered_up = true;
            self.state = Cia402State::NotReadyToSwitchOn;
            return Some(Transition {
                number: 0,
                from: None,
                to: self.state,
            });
        }
        let from = self.state;
        let (number, to) = self.next(previous, controlword, inputs)?;
        self.state = to;
        Some(Transition {
            number,
            from: Some(from),
            to,
        })
    }

    fn next(
        &self,
        previous: u16,
        controlword: u16,
        inputs: DeviceInputs,
    ) -> Option<(u8, Cia402State)> {
        use Cia402State as S;
        use DeviceCommand as C;
        let from = self.state;
        if inputs.fault && !from.is_fault() {
            return Some((13, S::FaultReactionActive));
        }
        let command = DeviceCommand::decode(from, previous, controlword);
        let stays = self.quick_stop_option.stays_in_quick_stop();
        // Option 0 has no ramp to wait for: the drive function is disabled at once.
        let quick_stop_done = !stays
            && (inputs.reaction_finished
                || self.quick_stop_option == QuickStopOption::DisableDrive);
        Some(match (from, command) {
            (S::NotReadyToSwitchOn, _) if inputs.self_test_done => (1, S::SwitchOnDisabled),
            (S::SwitchOnDisabled, Some(C::Shutdown)) => (2, S::ReadyToSwitchOn),
            (S::ReadyToSwitchOn, Some(C::SwitchOn | C::SwitchOnEnableOperation)) => {
                (3, S::SwitchedOn)
            }
            (S::SwitchedOn, Some(C::EnableOperation)) => (4, S::OperationEnabled),
            (S::OperationEnabled, Some(C::DisableOperation)) => (5, S::SwitchedOn),
            (S::SwitchedOn, Some(C::Shutdown)) => (6, S::ReadyToSwitchOn),
            (S::ReadyToSwitchOn, Some(C::DisableVoltage | C::QuickStop)) => {
                (7, S::SwitchOnDisabled)
            }
            (S::OperationEnabled, Some(C::Shutdown)) => (8, S::ReadyToSwitchOn),
            (S::OperationEnabled, Some(C::DisableVoltage)) => (9, S::SwitchOnDisabled),
            (S::SwitchedOn, Some(C::DisableVoltage | C::QuickStop)) => (10, S::SwitchOnDisabled),
            (S::OperationEnabled, Some(C::QuickStop)) => (11, S::QuickStopActive),
            (S::QuickStopActive, Some(C::DisableVoltage)) => (12, S::SwitchOnDisabled),
            (S::QuickStopActive, _) if quick_stop_done => (12, S::SwitchOnDisabled),
            (S::QuickStopActive, Some(C::EnableOperation)) if stays => (16, S::OperationEnabled),
            (S::FaultReactionActive, _) if inputs.reaction_finished => (14, S::Fault),
            (S::Fault, Some(C::FaultReset)) if !inputs.fault => (15, S::SwitchOnDisabled),
            _ => return None,
        })
    }
}

/// What MC_Power and MC_Reset ask of the drive in one cycle.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct PowerRequest {
    /// Enable the drive (MC_Power.Enable).
    pub enable: bool,
    /// Stop with the drive's quick stop (controlword 0x0002) and keep it stopped.
    pub quick_stop: bool,
    /// Acknowledge (MC_Reset): its rising edge sends one fault reset pulse when the drive is in
    /// fault and acknowledges a latched time-out or loss of enable.
    pub fault_reset: bool,
}

/// A step of the enable handshake; each waits for one state of the drive.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum EnableStep {
    /// Fault reset sent; waiting for the drive to leave fault (transition 15, to switch on
    /// disabled).
    LeaveFault,
    /// Shutdown (0x0006) sent; waiting for ready to switch on (transition 2). A drive still in
    /// not ready to switch on (self test) is waited for in this step too.
    Shutdown,
    /// Switch on (0x0007) sent; waiting for switched on (transition 3).
    SwitchOn,
    /// Enable operation (0x000F) sent; waiting for operation enabled (transition 4, or 16 from
    /// quick stop active).
    EnableOperation,
}

impl EnableStep {
    /// The state the step waits for.
    pub const fn target(self) -> Cia402State {
        match self {
            Self::LeaveFault => Cia402State::SwitchOnDisabled,
            Self::Shutdown => Cia402State::ReadyToSwitchOn,
            Self::SwitchOn => Cia402State::SwitchedOn,
            Self::EnableOperation => Cia402State::OperationEnabled,
        }
    }

    /// The step's name, for alarm texts.
    pub const fn name(self) -> &'static str {
        match self {
            Self::LeaveFault => "fault reset",
            Self::Shutdown => "shutdown",
            Self::SwitchOn => "switch on",
            Self::EnableOperation => "enable operation",
        }
    }
}

impl fmt::Display for EnableStep {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} (waiting for {})", self.name(), self.target())
    }
}

/// Where the enable handshake stands.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum EnableStatus {
    /// Not enabled and not asked to be.
    Disabled,
    /// Enabling: the step now waiting for the drive.
    Enabling {
        /// The current step.
        step: EnableStep,
    },
    /// The drive is in operation enabled.
    Enabled,
    /// Enable removed; the drive has not left operation enabled / quick stop active yet.
    Disabling,
    /// Quick stop requested; the drive is in (or entering) quick stop active.
    QuickStopping,
    /// The drive is in fault reaction active or fault (its error code is in 0x603F).
    Fault,
    /// A step did not complete within the timeout. Latched (controlword 0x0000) until
    /// acknowledged by a fault reset request or until enable is removed (its falling edge).
    TimedOut {
        /// The step that did not complete.
        step: EnableStep,
        /// The state the drive was left in (`None`: a statusword the profile does not define).
        state: Option<Cia402State>,
    },
    /// The drive left operation enabled on its own, without a fault (e.g. safe torque off or a
    /// local disable). Latched (controlword 0x0000, never re-enabled silently) until
    /// acknowledged by a fault reset request or until enable is removed (its falling edge).
    Lost {
        /// The state the drive went to.
        state: Option<Cia402State>,
    },
}

/// One cycle's result of the enable handshake.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct EnableOutput {
    /// The controlword to send (0x6040).
    pub controlword: u16,
    /// Where the handshake stands.
    pub status: EnableStatus,
    /// The drive state decoded from the statusword given to this step.
    pub drive_state: Option<Cia402State>,
}

/// The timeout of an [`EnableSequence`] is not positive.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct InvalidEnableTimeout {
    /// The value that was given (ns).
    pub timeout_ns: i64,
}

impl fmt::Display for InvalidEnableTimeout {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "enable timeout {} ns must be positive", self.timeout_ns)
    }
}

impl std::error::Error for InvalidEnableTimeout {}

/// The controller side of the profile: the enable handshake that MC_Power runs on a CiA 402
/// drive, with a timeout per step (S7-1500T Motion Control V4.0 function manual, 1.2 "Drive and
/// encoder connection"; the steps are the profile's transitions 2, 3, 4).
///
/// Stepped once per cycle with the time, the request and the statusword of the drive; returns
/// the controlword for the drive and the status. Behaviour:
/// - Enable: shutdown (0x0006) until ready to switch on, switch on (0x0007) until switched
///   on, enable operation (0x000F) until operation enabled. Each step waits for its state; a
///   drive that answers in the same exchange is enabled after three exchanges. The timeout
///   counts from the cycle in which the step started; at `now - start >= timeout` the status
///   becomes [`EnableStatus::TimedOut`] naming the step and the state the drive was in.
/// - Enable removed: disable voltage (0x0000), so the drive goes to switch on disabled by
///   transition 7, 9, 10 or 12 (inferred: the axis has already braked before it removes the
///   enable; disable voltage leaves every enabled state, including quick stop active).
/// - Quick stop: 0x0002 (transitions 11, 7, 10).
/// - Fault: a drive in fault reaction active or fault is reported as [`EnableStatus::Fault`]
///   with controlword 0x0000. A rising edge of [`PowerRequest::fault_reset`] arms one fault
///   reset; it is sent as soon as the drive is in fault: bit 7 set for exactly one exchange
///   (controlword 0x0080), then cleared again, so the drive sees one rising edge. Then step
///   [`EnableStep::LeaveFault`] waits (with the timeout) for the drive to leave fault; with
///   enable still set the handshake then enables again (S7: after the drive-side
///   acknowledgement MC_Reset re-enables the axis if MC_Power.Enable is still TRUE).
/// - A drive that leaves operation enabled on its own is never re-enabled silently: a fault
///   shows as [`EnableStatus::Fault`] until reset, anything else as [`EnableStatus::Lost`]
///   until acknowledged.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct EnableSequence {
    timeout_ns: i64,
    previous_fault_reset: bool,
    previous_enable: bool,
    /// A fault reset was requested and waits for the drive to be in fault.
    reset_armed: bool,
    /// The fault reset pulse was sent at this time; waiting for the drive to leave fault.
    leave_fault_since: Option<i64>,
    /// The enabling step in progress and the time it started.
    step: Option<(EnableStep, i64)>,
    /// A latched time-out or loss of enable.
    latched: Option<EnableStatus>,
    /// The drive was in operation enabled at the previous step with enable requested.
    enabled: bool,
}

impl EnableSequence {
    /// A handshake with `timeout_ns` (> 0) per step.
    pub const fn new(timeout_ns: i64) -> Result<Self, InvalidEnableTimeout> {
        if timeout_ns <= 0 {
            return Err(InvalidEnableTimeout { timeout_ns });
        }
        Ok(Self {
            timeout_ns,
            previous_fault_reset: false,
            previous_enable: false,
            reset_armed: false,
            leave_fault_since: None,
            step: None,
            latched: None,
            enabled: false,
        })
    }

    /// The timeout per step (ns).
    pub const fn timeout_ns(&self) -> i64 {
        self.timeout_ns
    }

    /// One cycle at `now_ns`: `request` from MC_Power / MC_Reset, `feedback_statusword` the
    /// drive's statusword 0x6041 of this cycle.
    pub fn step(
        &mut self,
        now_ns: i64,
        request: PowerRequest,
        feedback_statusword: u16,
    ) -> EnableOutput {
        let state = Cia402State::from_statusword(feedback_statusword);
        let (controlword, status) = self.decide(now_ns, request, state);
        EnableOutput {
            controlword,
            status,
            drive_state: state,
        }
    }

    fn decide(
        &mut self,
        now: i64,
        request: PowerRequest,
        state: Option<Cia402State>,
    ) -> (u16, EnableStatus) {
        use Cia402State as S;
        if self.enabled
            && self.previous_enable
            && !self.previous_fault_reset
            && request.enable
            && !request.quick_stop
            && !request.fault_reset
            && state == Some(S::OperationEnabled)
            && self.latched.is_none()
            && self.leave_fault_since.is_none()
        {
            // Enabled and staying so (every cycle of a moving axis): what the steps below
            // decide in this case, without them (no edge, no fault, nothing latched; `enabled`
            // implies no step in progress).
            self.step = None;
            return (
                DeviceCommand::EnableOperation.controlword(),
                EnableStatus::Enabled,
            );
        }
        let in_fault = state.is_some_and(Cia402State::is_fault);
        if request.fault_reset && !self.previous_fault_reset {
            // The acknowledgement: clears a latched time-out or loss, and arms a fault reset
            // if there is a fault to reset.
            self.latched = None;
            self.reset_armed = in_fault;
        }
        self.previous_fault_reset = request.fault_reset;
        if !request.enable && self.previous_enable {
            // Removing the enable acknowledges a latched time-out or loss too.
            self.latched = None;
        }
        self.previous_enable = request.enable;
        if in_fault || self.leave_fault_since.is_some() {
            if let Some(out) = self.fault_path(now, request, state) {
                return out;
            }
        }
        if let Some(latched) = self.latched {
            self.forget_enable();
            return (0x0000, latched);
        }
        let moving = matches!(state, Some(S::OperationEnabled | S::QuickStopActive));
        if !request.enable {
            self.forget_enable();
            let status = if moving {
                EnableStatus::Disabling
            } else {
                EnableStatus::Disabled
            };
            return (DeviceCommand::DisableVoltage.controlword(), status);
        }
        if request.quick_stop {
            self.forget_enable();
            let status = if moving {
                EnableStatus::QuickStopping
            } else {
                EnableStatus::Disabled
            };
            return (DeviceCommand::QuickStop.controlword(), status);
        }
        self.enable_path(now, state)
    }

    /// The drive is in a fault state, or a fault reset pulse waits for the drive to leave it.
    /// `None` when the drive has left fault after the pulse (the caller goes on as usual).
    fn fault_path(
        &mut self,
        now: i64,
        request: PowerRequest,
        state: Option<Cia402State>,
    ) -> Option<(u16, EnableStatus)> {
        self.forget_enable();
        let in_fault = state.is_some_and(Cia402State::is_fault);
        let waiting = if request.enable {
            EnableStatus::Enabling {
                step: EnableStep::LeaveFault,
            }
        } else {
            EnableStatus::Fault
        };
        if state == Some(Cia402State::Fault) && self.reset_armed {
            // The pulse: bit 7 set for this one exchange; the next controlword clears it.
            self.reset_armed = false;
            self.leave_fault_since = Some(now);
            return Some((DeviceCommand::FaultReset.controlword(), waiting));
        }
        if let Some(since) = self.leave_fault_since {
            if !in_fault {
                self.leave_fault_since = None;
                return None;
            }
            if now.saturating_sub(since) >= self.timeout_ns {
                self.leave_fault_since = None;
                let timed_out = EnableStatus::TimedOut {
                    step: EnableStep::LeaveFault,
                    state,
                };
                self.latched = Some(timed_out);
                return Some((0x0000, timed_out));
            }
            return Some((0x0000, waiting));
        }
        Some((0x0000, self.latched.unwrap_or(EnableStatus::Fault)))
    }

    fn enable_path(&mut self, now: i64, state: Option<Cia402State>) -> (u16, EnableStatus) {
        use Cia402State as S;
        if state == Some(S::OperationEnabled) {
            self.enabled = true;
            self.step = None;
            return (
                DeviceCommand::EnableOperation.controlword(),
                EnableStatus::Enabled,
            );
        }
        if self.enabled {
            // Dropped out of operation enabled on its own (a fault took the fault path).
            self.forget_enable();
            let lost = EnableStatus::Lost { state };
            self.latched = Some(lost);
            return (0x0000, lost);
        }
        let step = match state {
            Some(S::ReadyToSwitchOn) => EnableStep::SwitchOn,
            Some(S::SwitchedOn | S::QuickStopActive) => EnableStep::EnableOperation,
            _ => EnableStep::Shutdown,
        };
        let since = match self.step {
            Some((current, since)) if current == step => since,
            _ => {
                self.step = Some((step, now));
                now
            }
        };
        if now.saturating_sub(since) >= self.timeout_ns {
            self.step = None;
            let timed_out = EnableStatus::TimedOut { step, state };
            self.latched = Some(timed_out);
            return (0x0000, timed_out);
        }
        let controlword = match step {
            EnableStep::SwitchOn => DeviceCommand::SwitchOn.controlword(),
            EnableStep::EnableOperation => DeviceCommand::EnableOperation.controlword(),
            EnableStep::Shutdown | EnableStep::LeaveFault => DeviceCommand::Shutdown.controlword(),
        };
        (controlword, EnableStatus::Enabling { step })
    }

    fn forget_enable(&mut self) {
        self.enabled = false;
        self.step = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statusword_encodes_and_decodes_every_state() {
        for s in Cia402State::ALL {
            assert_eq!(Cia402State::from_statusword(s.statusword()), Some(s), "{s}");
            // The drive's extra bits do not change the decoded state.
            let extra = statusword::REMOTE
                | statusword::TARGET_REACHED
                | statusword::INTERNAL_LIMIT_ACTIVE
                | statusword::FOLLOWS_COMMAND
                | statusword::FOLLOWING_ERROR
                | statusword::WARNING
                | 0x8100;
            assert_eq!(
                Cia402State::from_statusword(s.statusword() | extra),
                Some(s),
                "{s}"
            );
        }
    }

    #[test]
    fn statusword_table_known_answers() {
        use Cia402State as S;
        // The typical words of drives: 0x0237 enabled, 0x0250 switch on disabled, 0x0231
        // ready, 0x0233 switched on, 0x0217 quick stop, 0x0218 fault, 0x021F fault reaction.
        let cases = [
            (0x0237, Some(S::OperationEnabled)),
            (0x0250, Some(S::SwitchOnDisabled)),
            (0x0270, Some(S::SwitchOnDisabled)),
            (0x0231, Some(S::ReadyToSwitchOn)),
            (0x0221, Some(S::ReadyToSwitchOn)),
            (0x0233, Some(S::SwitchedOn)),
            (0x0217, Some(S::QuickStopActive)),
            (0x0007, Some(S::QuickStopActive)),
            (0x0218, Some(S::Fault)),
            (0x0238, Some(S::Fault)),
            (0x021F, Some(S::FaultReactionActive)),
            (0x0000, Some(S::NotReadyToSwitchOn)),
            (0x0020, Some(S::NotReadyToSwitchOn)),
            // Undefined patterns.
            (0x0001, None),
            (0x0041, None),
            (0x0061, None),
            (0x0003, None),
            (0x0027 | 0x0040, None),
            (0x0004, None),
            (0x000C, None),
        ];
        for (sw, state) in cases {
            assert_eq!(Cia402State::from_statusword(sw), state, "{sw:#06x}");
        }
        // The defined patterns of bits 0..6, as a check on the table: 4 states × 4 (mask 0x4F
        // leaves bits 4 and 5 free) + 4 states × 2 (mask 0x6F leaves bit 4 free).
        let defined = (0u16..128)
            .filter(|&sw| Cia402State::from_statusword(sw).is_some())
            .count();
        assert_eq!(defined, 4 * 4 + 4 * 2);
    }

    #[test]
    fn statusword_encoding_is_documented_choice() {
        let words: Vec<u16> = Cia402State::ALL.iter().map(|s| s.statusword()).collect();
        assert_eq!(
            words,
            [0x0000, 0x0040, 0x0031, 0x0033, 0x0037, 0x0017, 0x001F, 0x0008]
        );
    }

    #[test]
    fn commands_decode_per_table() {
        use Cia402State as S;
        use DeviceCommand as C;
        let cases = [
            (S::SwitchOnDisabled, 0x0006, Some(C::Shutdown)),
            (S::SwitchOnDisabled, 0x000E, Some(C::Shutdown)),
            (S::ReadyToSwitchOn, 0x0007, Some(C::SwitchOn)),
            (S::ReadyToSwitchOn, 0x000F, Some(C::SwitchOnEnableOperation)),
            (S::SwitchedOn, 0x000F, Some(C::EnableOperation)),
            (S::QuickStopActive, 0x000F, Some(C::EnableOperation)),
            (S::OperationEnabled, 0x0007, Some(C::DisableOperation)),
            (S::OperationEnabled, 0x0000, Some(C::DisableVoltage)),
            (S::OperationEnabled, 0x000D, Some(C::DisableVoltage)),
            (S::OperationEnabled, 0x0002, Some(C::QuickStop)),
            (S::OperationEnabled, 0x000B, Some(C::QuickStop)),
            (S::OperationEnabled, 0x010F, Some(C::EnableOperation)),
            (S::Fault, 0x0080, Some(C::FaultReset)),
            (S::Fault, 0x008F, Some(C::FaultReset)),
        ];
        for (state, cw, command) in cases {
            assert_eq!(
                DeviceCommand::decode(state, 0, cw),
                command,
                "{state} {cw:#06x}"
            );
        }
        // Bit 7 held: no edge, no command.
        assert_eq!(DeviceCommand::decode(S::Fault, 0x0080, 0x0080), None);
        assert_eq!(DeviceCommand::decode(S::Fault, 0x0080, 0x008F), None);
        for c in [
            C::Shutdown,
            C::SwitchOn,
            C::EnableOperation,
            C::DisableVoltage,
            C::QuickStop,
        ] {
            assert_eq!(
                DeviceCommand::decode(S::SwitchedOn, 0, c.controlword()).map(|d| d.controlword()),
                Some(c.controlword())
            );
        }
    }

    #[test]
    fn modes_and_options_convert_with_typed_errors() {
        for v in [0i8, 1, 3, 4, 6, 7, 8, 9, 10] {
            let m = ModeOfOperation::try_from(v);
            assert_eq!(m.map(ModeOfOperation::value), Ok(v));
        }
        for v in [-1i8, 2, 5, 11, 127, -128] {
            assert_eq!(
                ModeOfOperation::try_from(v),
                Err(UnknownModeOfOperation { value: v })
            );
        }
        assert!(ModeOfOperation::CyclicSynchronousTorque.is_cyclic());
        assert!(!ModeOfOperation::ProfilePosition.is_cyclic());
        for v in 0i16..=8 {
            let o = QuickStopOption::try_from(v);
            assert_eq!(o.map(QuickStopOption::value), Ok(v));
            assert_eq!(o.map(QuickStopOption::stays_in_quick_stop), Ok(v >= 5));
        }
        for v in [-1i16, 9, 0x7FFF] {
            assert_eq!(
                QuickStopOption::try_from(v),
                Err(UnknownQuickStopOption { value: v })
            );
        }
        assert_eq!(
            UnknownModeOfOperation { value: 5 }.to_string(),
            "modes of operation (0x6060) 5 is not one of 0, 1, 3, 4, 6, 7, 8, 9, 10"
        );
    }

    #[test]
    fn enable_timeout_must_be_positive() {
        assert_eq!(
            EnableSequence::new(0),
            Err(InvalidEnableTimeout { timeout_ns: 0 })
        );
        assert_eq!(
            EnableSequence::new(-5),
            Err(InvalidEnableTimeout { timeout_ns: -5 })
        );
        assert_eq!(EnableSequence::new(1).map(|s| s.timeout_ns()), Ok(1));
    }
}
