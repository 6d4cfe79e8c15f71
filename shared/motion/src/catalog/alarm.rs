//! Technology alarms, alarm reactions and the StatusWord / ErrorWord / WarningWord bit layout.
//!
//! Data from the S7-1500T Motion Control V4.0 function manual:
//! - 9.3 'Technology alarms': alarm classes and reactions;
//! - A.8.1 'List of the technology alarms': the overview table and the alarm detail pages;
//! - A.2.35 'StatusWord tag', A.2.36 'ErrorWord tag' and A.2.38 'WarningWord tag' (positioning
//!   axis/synchronous axis).
//!
//! The table is static data: [`ALARMS`] holds one [`AlarmSpec`] per [`AlarmId`] with its reaction,
//! ErrorWord/WarningWord bit, restart flag and text. [`AlarmId::spec`] is a `match`, so it is
//! total and cannot fail.
//!
//! # Where the manual contradicts itself
//! Where they disagree, tandem prefers the appendix *tables* and records the choice here: it
//! follows the **overview table** (A.8.1, "List of the technology alarms")
//! wherever it disagrees with the per-alarm detail pages:
//! - **603** (leader not position-controlled): the table says *remove enable*, the detail page
//!   says *no reaction*. Tandem: [`Reaction::RemoveEnable`], error bit 14.
//! - **752** (measuring range not recognized): the table says *remove enable*, the detail page
//!   says *no reaction*. Tandem: [`Reaction::RemoveEnable`], error bit 2.
//! - **702**: the table prints the text "Position value valid."; the detail page shows it means
//!   the position value is *not* valid (restart running or encoder values invalid). Tandem
//!   uses the corrected text.
//! - **703**: the table says "Cam track data faulty", the detail heading says "Output cam data
//!   faulty" (it describes the output cams of a cam track). Tandem uses the table text.
//!
//! # Scope
//! The list covers every alarm number of the list, including those raised on the measuring input,
//! output cam and cam track TOs (700–758). The reaction stored for them is the table value.
//! On those TOs the effective reaction is "terminate processing" (ErrorDetail.Reaction 6–10,
//! S7-1500T Motion Control V4.0 function manual, 9.3 'Technology alarms'), which [`Reaction`] does
//! not model because it holds the axis reactions 0–5.
//!
//! 601 ([`AlarmId::LeaderMissing`], "leading axis is not assigned or defective") also covers
//! a *missing leading value*, for example a network leader that stopped publishing, so tandem
//! adds no alarm for it.

use core::fmt;

/// Alarm reaction of an axis (`ErrorDetail.Reaction`, S7-1500T Motion Control V4.0 function manual,
/// 9.3 'Technology alarms').
///
/// The discriminant is the S7 code. The derived order is the **severity** order, least severe
/// first. The codes are already in that order: each reaction stops at least as hard as the one
/// before it. [`Reaction::TrackSetpoints`] ranks above [`Reaction::RemoveEnable`]: it also
/// removes the enable, and in addition hands the setpoint over to the drive's own motion
/// (alarm 550).
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(u8)]
pub enum Reaction {
    /// 0: no reaction (warnings). Jobs continue; dynamics may be limited.
    None = 0,
    /// 1: abort jobs and brake with the deceleration and jerk of the current job.
    StopCurrentDynamics = 1,
    /// 2: abort jobs and brake with `DynamicLimits.MaxDeceleration` and `MaxJerk`.
    StopMaxDynamics = 2,
    /// 3: abort jobs and brake with `DynamicDefaults.EmergencyDeceleration`, without jerk limit.
    EmergencyStop = 3,
    /// 4: abort jobs, output setpoint 0 and remove the enable. The drive brakes on its own ramp.
    RemoveEnable = 4,
    /// 5: abort jobs, setpoint 0, enable removed, and the drive's actual values are tracked as
    /// setpoints (drive-autonomous motion, e.g. safety; alarm 550).
    TrackSetpoints = 5,
}

impl Reaction {
    /// All reactions, least severe first.
    pub const ALL: &'static [Reaction] = &[
        Reaction::None,
        Reaction::StopCurrentDynamics,
        Reaction::StopMaxDynamics,
        Reaction::EmergencyStop,
        Reaction::RemoveEnable,
        Reaction::TrackSetpoints,
    ];

    /// The S7 code (`ErrorDetail.Reaction`), 0..=5.
    pub const fn code(self) -> u8 {
        self as u8
    }

    /// The reaction for an S7 code, or `None` outside 0..=5.
    pub const fn from_code(code: u8) -> Option<Reaction> {
        match code {
            0 => Some(Reaction::None),
            1 => Some(Reaction::StopCurrentDynamics),
            2 => Some(Reaction::StopMaxDynamics),
            3 => Some(Reaction::EmergencyStop),
            4 => Some(Reaction::RemoveEnable),
            5 => Some(Reaction::TrackSetpoints),
            _ => None,
        }
    }

    /// Severity rank, higher is more severe (equal to [`Reaction::code`]).
    pub const fn severity(self) -> u8 {
        self as u8
    }

    /// `true` if `self` is strictly more severe than `other`.
    pub const fn is_more_severe_than(self, other: Reaction) -> bool {
        self.severity() > other.severity()
    }

    /// The more severe of two reactions.
    pub const fn max_severity(self, other: Reaction) -> Reaction {
        if other.is_more_severe_than(self) {
            other
        } else {
            self
        }
    }

    /// `true` for reactions 1..=5: running jobs on the axis are aborted (S7-1500T Motion Control
    /// V4.0 function manual, 10.16 'Override response of Motion Control jobs V4', last paragraph:
    /// "any alarm with a stopping reaction" aborts everything).
    pub const fn aborts_jobs(self) -> bool {
        !matches!(self, Reaction::None)
    }

    /// `true` for reactions 4 and 5. The axis is disabled, and it re-enables automatically on
    /// acknowledgement if `MC_Power.Enable` is still TRUE (S7-1500T Motion Control V4.0 function
    /// manual, 9.3 'Technology alarms').
    pub const fn removes_enable(self) -> bool {
        matches!(self, Reaction::RemoveEnable | Reaction::TrackSetpoints)
    }
}

/// Static description of one technology alarm (one row of S7-1500T Motion Control V4.0 function
/// manual, A.8.1 'List of the technology alarms').
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub struct AlarmSpec {
    /// The alarm.
    pub id: AlarmId,
    /// Alarm number (`ErrorDetail.Number`), equal to `id.number()`.
    pub number: u16,
    /// Effective alarm reaction.
    pub reaction: Reaction,
    /// Bit index (0..=15) set in the ErrorWord while the alarm is pending; see [`error_bit`].
    pub error_bit: Option<u8>,
    /// Bit index (0..=15) set in the WarningWord while the alarm is pending; see [`warning_bit`].
    pub warning_bit: Option<u8>,
    /// `true` if acknowledging needs a TO restart (`MC_Reset` with `Restart = TRUE`).
    pub restart: bool,
    /// One-line alarm text.
    pub text: &'static str,
}

impl AlarmSpec {
    /// ErrorWord mask of this alarm (0 if it sets no error bit).
    pub const fn error_mask(&self) -> u32 {
        match self.error_bit {
            Some(b) => 1u32 << (b & 31),
            None => 0,
        }
    }

    /// WarningWord mask of this alarm (0 if it sets no warning bit).
    pub const fn warning_mask(&self) -> u32 {
        match self.warning_bit {
            Some(b) => 1u32 << (b & 31),
            None => 0,
        }
    }

    /// `true` if the alarm sets an ErrorWord bit, so it counts as an error and not only as a
    /// warning.
    pub const fn is_error(&self) -> bool {
        self.error_bit.is_some()
    }

    /// Priority for `ErrorDetail`: `true` if `self` outranks `other`.
    ///
    /// The manual says only that ErrorDetail shows the "highest-priority" pending alarm (S7-1500T
    /// Motion Control V4.0 function manual, 9.3 'Technology alarms'). Tandem ranks pending alarms
    /// by these keys, in order:
    /// 1. the more severe [`Reaction`] wins ([`Reaction::severity`]);
    /// 2. at equal reaction, an alarm with an ErrorWord bit beats a pure warning (e.g. 758 beats
    ///    501);
    /// 3. then the lower alarm number wins.
    ///
    /// The ranking is a strict total order over distinct alarm numbers.
    pub const fn outranks(&self, other: &AlarmSpec) -> bool {
        if self.reaction.severity() != other.reaction.severity() {
            return self.reaction.severity() > other.reaction.severity();
        }
        if self.is_error() != other.is_error() {
            return self.is_error();
        }
        self.number < other.number
    }
}

/// Builds [`AlarmId`], [`ALARMS`], [`AlarmId::spec`] and [`AlarmId::from_number`] from one list,
/// so that they cannot drift apart. A duplicate number is a compile error (duplicate discriminant).
macro_rules! alarms {
    (
        $(#[$enum_attr:meta])*
        pub enum AlarmId {
            $(
                $(#[$attr:meta])*
                $name:ident = $num:literal => {
                    $reaction:ident, error: $ebit:expr, warning: $wbit:expr,
                    restart: $restart:literal, $text:literal $(,)?
                },
            )*
        }
    ) => {
        $(#[$enum_attr])*
        pub enum AlarmId {
            $(
                #[doc = concat!("Alarm ", stringify!($num), ": ", $text)]
                #[doc = ""]
                $(#[$attr])*
                $name = $num,
            )*
        }

        /// Every technology alarm of S7-1500T Motion Control V4.0 function manual, A.8.1 'List of
        /// the technology alarms' with its reaction, ErrorWord/WarningWord bit, restart flag and
        /// text, sorted by number.
        pub const ALARMS: &[AlarmSpec] = &[$(*AlarmId::$name.spec(),)*];

        impl AlarmId {
            /// Every alarm, sorted by number.
            pub const ALL: &'static [AlarmId] = &[$(AlarmId::$name,)*];

            /// The static description of this alarm (total: a `match`, not a search).
            pub const fn spec(self) -> &'static AlarmSpec {
                match self {
                    $(
                        AlarmId::$name => &AlarmSpec {
                            id: AlarmId::$name,
                            number: $num,
                            reaction: Reaction::$reaction,
                            error_bit: $ebit,
                            warning_bit: $wbit,
                            restart: $restart,
                            text: $text,
                        },
                    )*
                }
            }

            /// The alarm with this number, or `None` if the number is not in S7-1500T Motion
            /// Control V4.0 function manual, A.8.1 'List of the technology alarms'.
            pub const fn from_number(n: u16) -> Option<AlarmId> {
                match n {
                    $($num => Some(AlarmId::$name),)*
                    _ => None,
                }
            }

            /// The identifier (the variant name, e.g. `"SwLimitReached"`).
            pub const fn name(self) -> &'static str {
                match self {
                    $(AlarmId::$name => stringify!($name),)*
                }
            }
        }
    };
}

alarms! {
    /// Technology alarm number (`ErrorDetail.Number`, S7-1500T Motion Control V4.0 function manual,
    /// A.8.1 'List of the technology alarms').
    ///
    /// The discriminant is the alarm number. The variants are declared in number order.
    #[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
    #[repr(u16)]
    pub enum AlarmId {
        /// Bad configuration value, load gear, no encoder, bad Kv, Simulation.Mode out of range,
        /// bad homing combination, telegram mismatch ...
        ConfigurationError = 101 => {
            RemoveEnable, error: Some(1), warning: None, restart: true,
            "Configuration error.",
        },
        DriveAdaptationError = 102 => {
            RemoveEnable, error: Some(15), warning: None, restart: true,
            "Drive configuration adaptation error.",
        },
        EncoderAdaptationError = 103 => {
            RemoveEnable, error: Some(15), warning: None, restart: true,
            "Encoder configuration adaptation error.",
        },
        /// Raised when `PositionLimits_SW.MinPosition > MaxPosition`.
        SwLimitSpecification = 104 => {
            StopMaxDynamics, error: Some(1), warning: None, restart: false,
            "SW limit switch specification error (negative limit greater than positive limit).",
        },
        DriveConfigurationError = 105 => {
            RemoveEnable, error: Some(1), warning: None, restart: true,
            "Drive configuration error.",
        },
        /// E.g. the drive was not initialized when the axis was enabled.
        DriveConnectionError = 106 => {
            RemoveEnable, error: Some(1), warning: None, restart: false,
            "Drive connection configuration error.",
        },
        EncoderConfigurationError = 107 => {
            RemoveEnable, error: Some(1), warning: None, restart: true,
            "Encoder configuration error.",
        },
        /// E.g. the encoder was not initialized (StatusSensor.State not VALID) at enable.
        EncoderConnectionError = 108 => {
            RemoveEnable, error: Some(1), warning: None, restart: false,
            "Encoder connection configuration error.",
        },
        IoConfigurationError = 109 => {
            RemoveEnable, error: Some(1), warning: None, restart: true,
            "Configuration error (I/O of limit switches, homing cams, analog drive, measuring input or output cam).",
        },
        ConfigurationAdjusted = 110 => {
            None, error: None, warning: Some(1), restart: false,
            "Configuration is adjusted internally.",
        },
        DriveConfigInconsistent = 111 => {
            None, error: None, warning: Some(15), restart: false,
            "TO and drive configuration inconsistent.",
        },
        EncoderConfigInconsistent = 112 => {
            None, error: None, warning: Some(15), restart: false,
            "TO and encoder configuration inconsistent.",
        },
        IsochronousNotPossible = 113 => {
            RemoveEnable, error: Some(2), warning: None, restart: true,
            "Isochronous mode not possible.",
        },
        /// Same text as 203. 201 is also entered in the diagnostics buffer.
        InternalError = 201 => {
            RemoveEnable, error: Some(0), warning: None, restart: true,
            "Internal error.",
        },
        InternalConfigurationError = 202 => {
            None, error: Some(0), warning: None, restart: true,
            "Internal configuration error.",
        },
        /// Same text and reaction as 201; not entered in the diagnostics buffer.
        InternalFault = 203 => {
            RemoveEnable, error: Some(0), warning: None, restart: true,
            "Internal error.",
        },
        /// E.g. connection to the engineering tool (control panel) interrupted.
        CommissioningError = 204 => {
            RemoveEnable, error: Some(0), warning: None, restart: false,
            "Commissioning error.",
        },
        VelocityLimitZero = 304 => {
            EmergencyStop, error: Some(2), warning: None, restart: false,
            "Velocity limit is zero.",
        },
        /// Supplement: [`supplement::ACCELERATION`] or [`supplement::DECELERATION`].
        AccelerationLimitZero = 305 => {
            EmergencyStop, error: Some(2), warning: None, restart: false,
            "Acceleration or deceleration limit is zero.",
        },
        JerkLimitZero = 306 => {
            EmergencyStop, error: Some(2), warning: None, restart: false,
            "Jerk limit is zero.",
        },
        /// Supplement: [`supplement::NEGATIVE`] or [`supplement::POSITIVE`].
        PositionRangeReached = 307 => {
            StopMaxDynamics, error: Some(2), warning: None, restart: false,
            "Numerical value range of the position reached.",
        },
        /// Supplement: [`supplement::NEGATIVE`] or [`supplement::POSITIVE`].
        PositionRangeExceeded = 308 => {
            RemoveEnable, error: Some(2), warning: None, restart: false,
            "Numerical value range of the position exceeded.",
        },
        /// Raised by an absolute positioning job on an axis that is not homed (S7-1500T Motion
        /// Control V4.0 function manual, 10.5.1 'MC_MoveAbsolute: Position axis absolutely V4').
        /// See also [`crate::catalog::error_id::ErrorId::NotHomed`].
        AxisNotHomed = 321 => {
            EmergencyStop, error: Some(3), warning: None, restart: false,
            "Axis not homed.",
        },
        /// Supplement: [`supplement::RESTART_NOT_READY`] or
        /// [`supplement::RESTART_CONDITION_NOT_MET`].
        RestartNotExecuted = 322 => {
            None, error: None, warning: Some(3), restart: false,
            "Restart not executed.",
        },
        HomeNotPossible = 323 => {
            RemoveEnable, error: Some(3), warning: None, restart: false,
            "MC_Home could not be performed.",
        },
        /// Supplement: [`supplement::APPROACH_VELOCITY_ZERO`] or
        /// [`supplement::HOMING_VELOCITY_ZERO`].
        HomingDataError = 341 => {
            StopMaxDynamics, error: Some(10), warning: None, restart: false,
            "Error in homing data.",
        },
        HomingNotFound = 342 => {
            EmergencyStop, error: Some(10), warning: None, restart: false,
            "Reference cam/encoder zero mark not found.",
        },
        HomingNotSupported = 343 => {
            RemoveEnable, error: Some(1), warning: None, restart: false,
            "Homing function not supported by device.",
        },
        AddressAccessError = 401 => {
            RemoveEnable, error: Some(13), warning: None, restart: false,
            "Error accessing logical address.",
        },
        EncoderFault = 411 => {
            RemoveEnable, error: Some(5), warning: None, restart: false,
            "Faulty encoder at the logical address.",
        },
        /// Supplement: [`supplement::NEGATIVE`], [`supplement::POSITIVE`] or
        /// [`supplement::MODULO`].
        ActualValueRangeExceeded = 412 => {
            RemoveEnable, error: Some(5), warning: None, restart: false,
            "Permitted actual value range exceeded.",
        },
        DriveFault = 421 => {
            RemoveEnable, error: Some(4), warning: None, restart: false,
            "Faulty drive at the logical address.",
        },
        CommunicationFault = 431 => {
            RemoveEnable, error: Some(7), warning: None, restart: false,
            "Faulty communication with device at logical address.",
        },
        VelocityLimited = 501 => {
            None, error: None, warning: Some(6), restart: false,
            "Programmed velocity is limited.",
        },
        /// Supplement: [`supplement::ACCELERATION`] or [`supplement::DECELERATION`].
        AccelerationLimited = 502 => {
            None, error: None, warning: Some(6), restart: false,
            "Programmed acceleration/deceleration is limited.",
        },
        JerkLimited = 503 => {
            None, error: None, warning: Some(6), restart: false,
            "Programmed jerk is limited.",
        },
        SpeedSetpointMonitoring = 504 => {
            None, error: None, warning: Some(6), restart: false,
            "Speed setpoint monitoring active.",
        },
        /// Supplement: [`supplement::VELOCITY`], [`supplement::ACCELERATION`] or
        /// [`supplement::DECELERATION`].
        KinematicsLimitsViolated = 511 => {
            None, error: None, warning: Some(6), restart: false,
            "Dynamic limits are violated by the kinematics motion.",
        },
        FollowingError = 521 => {
            RemoveEnable, error: Some(11), warning: None, restart: false,
            "Following error.",
        },
        FollowingErrorWarning = 522 => {
            None, error: None, warning: Some(11), restart: false,
            "Warning following error tolerance.",
        },
        /// Supplement: [`supplement::HW_LIMIT_POSITIVE`], [`supplement::HW_LIMIT_NEGATIVE`],
        /// [`supplement::HW_LIMIT_ILLEGAL_DIRECTION`], [`supplement::HW_LIMIT_POLARITY`] or
        /// [`supplement::HW_LIMIT_BOTH`].
        HwLimit = 531 => {
            RemoveEnable, error: Some(9), warning: None, restart: false,
            "HW limit switch approached.",
        },
        /// Reached from an active motion: stops with maximum dynamics and keeps the axis enabled.
        /// Supplement: [`supplement::NEGATIVE`] or [`supplement::POSITIVE`].
        SwLimitReached = 533 => {
            StopMaxDynamics, error: Some(8), warning: None, restart: false,
            "SW limit switch approached.",
        },
        /// Crossed: removes the enable. Supplement: [`supplement::NEGATIVE`] or
        /// [`supplement::POSITIVE`].
        SwLimitCrossed = 534 => {
            RemoveEnable, error: Some(8), warning: None, restart: false,
            "SW limit switch crossed.",
        },
        /// Supplement: [`supplement::TARGET_NOT_REACHED`] or [`supplement::TARGET_LEFT`].
        PositioningMonitoring = 541 => {
            RemoveEnable, error: Some(12), warning: None, restart: false,
            "Position monitoring error.",
        },
        ClampingMonitoring = 542 => {
            RemoveEnable, error: Some(2), warning: None, restart: false,
            "Clamping monitoring error: axis left the clamping tolerance window.",
        },
        DriveAutonomousMotion = 550 => {
            TrackSetpoints, error: Some(4), warning: None, restart: false,
            "Drive-autonomous motion is being executed.",
        },
        /// The only alarm that sets both an error bit (2) and a warning bit (6).
        MaxVelocityUnreachable = 551 => {
            None, error: Some(2), warning: Some(6), restart: false,
            "Maximum velocity cannot be reached with drive/axis parameters.",
        },
        EncoderAdaptationPowerUp = 552 => {
            RemoveEnable, error: Some(15), warning: None, restart: false,
            "Adaptation error of encoder during power-up.",
        },
        /// Also used by tandem for a *missing leading value* (e.g. a network leader that stopped
        /// publishing): "not assigned or defective" covers it, so there is no extension alarm.
        LeaderMissing = 601 => {
            StopMaxDynamics, error: Some(14), warning: None, restart: false,
            "Leading axis is not assigned or defective.",
        },
        /// **Contradiction:** the overview table says remove enable, the detail page says no
        /// reaction. Tandem follows the table (see the module documentation).
        LeaderNotPositionControlled = 603 => {
            RemoveEnable, error: Some(14), warning: None, restart: false,
            "Leading axis is not in position-controlled mode.",
        },
        /// E.g. the leader reversed during synchronization.
        SynchronizationError = 608 => {
            StopMaxDynamics, error: Some(14), warning: None, restart: false,
            "Error during synchronization.",
        },
        CamNotAvailable = 611 => {
            RemoveEnable, error: Some(2), warning: None, restart: false,
            "Cam not configured, not available or not interpolated.",
        },
        CamNotInterpolated = 612 => {
            RemoveEnable, error: Some(2), warning: None, restart: false,
            "Specified cam has not been interpolated.",
        },
        /// Supplement: [`supplement::ON_POSITION`] or [`supplement::OFF_POSITION`].
        OutputCamLimiting = 700 => {
            RemoveEnable, error: Some(2), warning: None, restart: false,
            "Output cam limiting error.",
        },
        OutputIoError = 701 => {
            RemoveEnable, error: Some(13), warning: None, restart: false,
            "I/O output error.",
        },
        /// The overview table prints "Position value valid."; the detail page shows the
        /// meaning is "not valid" (restart running or encoder values invalid).
        PositionValueInvalid = 702 => {
            RemoveEnable, error: Some(2), warning: None, restart: false,
            "Position value not valid.",
        },
        CamTrackDataFaulty = 703 => {
            RemoveEnable, error: Some(2), warning: None, restart: false,
            "Cam track data faulty.",
        },
        OutputCamDataFaulty = 704 => {
            RemoveEnable, error: Some(2), warning: None, restart: false,
            "Output cam data faulty.",
        },
        MeasuringDuringHoming = 750 => {
            RemoveEnable, error: Some(2), warning: None, restart: false,
            "Measuring job not possible during homing of assigned axis.",
        },
        /// **Contradiction:** the overview table says remove enable, the detail page says no
        /// reaction. Tandem follows the table (see the module documentation).
        MeasuringRangeNotRecognized = 752 => {
            RemoveEnable, error: Some(2), warning: None, restart: false,
            "Validity range of measuring job not recognized.",
        },
        MeasuringEncoderBusy = 753 => {
            RemoveEnable, error: Some(2), warning: None, restart: false,
            "Only one measuring input can access an encoder at a time.",
        },
        MeasuringConfigError = 754 => {
            RemoveEnable, error: Some(2), warning: None, restart: false,
            "Measuring input configuration in external device is not correct.",
        },
        MeasuringNotPossible = 755 => {
            RemoveEnable, error: Some(13), warning: None, restart: false,
            "Measuring job not possible.",
        },
        /// The edge came before the module was ready; the value comes with the next edge.
        MeasuringEdgeNotEvaluated = 758 => {
            None, error: Some(2), warning: None, restart: false,
            "A measuring edge was not evaluated.",
        },
    }
}

impl AlarmId {
    /// The alarm number (`ErrorDetail.Number`).
    pub const fn number(self) -> u16 {
        self as u16
    }

    /// Shortcut for `self.spec().reaction`.
    pub const fn reaction(self) -> Reaction {
        self.spec().reaction
    }

    /// Priority for `ErrorDetail`; see [`AlarmSpec::outranks`].
    pub const fn outranks(self, other: AlarmId) -> bool {
        self.spec().outranks(other.spec())
    }
}

impl fmt::Display for AlarmId {
    /// `533 SwLimitReached`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.number(), self.name())
    }
}

/// Supplement values of [`AlarmInstance::supplement`].
///
/// The manual names the sub-causes of an alarm in its text (e.g. 541 "target range not reached"
/// / "exit target range again") but gives them no numbers. These numbers are a **tandem
/// convention**. `0` means "no supplement".
pub mod supplement {
    /// No supplement.
    pub const NONE: u16 = 0;

    /// 307, 308, 412, 533, 534: negative direction or limit.
    pub const NEGATIVE: u16 = 1;
    /// 307, 308, 412, 533, 534: positive direction or limit.
    pub const POSITIVE: u16 = 2;
    /// 412: modulo length versus encoder range.
    pub const MODULO: u16 = 3;

    /// 511: velocity.
    pub const VELOCITY: u16 = 1;
    /// 305, 502, 511: acceleration.
    pub const ACCELERATION: u16 = 2;
    /// 305, 502, 511: deceleration.
    pub const DECELERATION: u16 = 3;

    /// 322: the technology object is not ready for restart.
    pub const RESTART_NOT_READY: u16 = 1;
    /// 322: the condition for restart is not satisfied (TO not disabled).
    pub const RESTART_CONDITION_NOT_MET: u16 = 2;

    /// 341: approach velocity is zero.
    pub const APPROACH_VELOCITY_ZERO: u16 = 1;
    /// 341: homing (referencing) velocity is zero.
    pub const HOMING_VELOCITY_ZERO: u16 = 2;

    /// 531: positive HW limit switch reached.
    pub const HW_LIMIT_POSITIVE: u16 = 1;
    /// 531: negative HW limit switch reached.
    pub const HW_LIMIT_NEGATIVE: u16 = 2;
    /// 531: illegal free-travel direction of the active HW limit switch.
    pub const HW_LIMIT_ILLEGAL_DIRECTION: u16 = 3;
    /// 531: HW limit switch polarity reversed, free travel not possible.
    pub const HW_LIMIT_POLARITY: u16 = 4;
    /// 531: both HW limit switches active, retraction not possible.
    pub const HW_LIMIT_BOTH: u16 = 5;

    /// 421 "Alarm message from drive" when the drive gives no error code of its own.
    pub const DRIVE_ALARM: u16 = 1;
    /// 421 "Drive has shut down": the drive left operation without a fault while enabled.
    pub const DRIVE_SHUT_DOWN: u16 = 3;
    /// 421 "Drive enable not possible": this plus the step of the enable sequence that did not
    /// complete in time (0 fault reset, 1 shutdown, 2 switch on, 3 enable operation for a
    /// CiA 402 drive).
    pub const DRIVE_ENABLE_NOT_POSSIBLE: u16 = 0x10;

    /// 421 "Alarm message from drive": the drive's own error code (CiA 402 object 0x603F, CiA
    /// 301 ranges from 0x1000), or [`DRIVE_ALARM`] when it gives none.
    pub const fn drive_fault_code(code: u16) -> u16 {
        if code == 0 {
            DRIVE_ALARM
        } else {
            code
        }
    }

    /// 541: the target range was not reached within the tolerance time.
    pub const TARGET_NOT_REACHED: u16 = 1;
    /// 541: the target range was left again during the minimum dwell time.
    pub const TARGET_LEFT: u16 = 2;

    /// 700: the OnPosition could not be computed.
    pub const ON_POSITION: u16 = 1;
    /// 700: the OffPosition could not be computed.
    pub const OFF_POSITION: u16 = 2;
}

/// A raised technology alarm with its supplement value (see [`supplement`]).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub struct AlarmInstance {
    /// Which alarm.
    pub id: AlarmId,
    /// Sub-cause; [`supplement::NONE`] if the alarm has none.
    pub supplement: u16,
    /// The effective reaction: the table's, unless the configuration sets another (alarm 601).
    pub reaction: Reaction,
}

impl AlarmInstance {
    /// New instance, with the table's reaction.
    pub const fn new(id: AlarmId, supplement: u16) -> Self {
        Self {
            id,
            supplement,
            reaction: id.reaction(),
        }
    }

    /// The same alarm with a configured reaction.
    pub const fn with_reaction(self, reaction: Reaction) -> Self {
        Self { reaction, ..self }
    }

    /// The static description of the alarm.
    pub const fn spec(self) -> &'static AlarmSpec {
        self.id.spec()
    }

    /// Priority for `ErrorDetail`; see [`AlarmSpec::outranks`]. The supplement does not count.
    pub const fn outranks(self, other: AlarmInstance) -> bool {
        self.id.outranks(other.id)
    }
}

/// The highest-priority alarm of `pending` (the one `ErrorDetail` shows), by
/// [`AlarmSpec::outranks`]. `None` if nothing is pending. Does not allocate.
pub fn highest_priority<I>(pending: I) -> Option<AlarmInstance>
where
    I: IntoIterator<Item = AlarmInstance>,
{
    let mut best: Option<AlarmInstance> = None;
    for a in pending {
        best = match best {
            Some(b) if !a.outranks(b) => Some(b),
            _ => Some(a),
        };
    }
    best
}

/// `<TO>.ErrorDetail` (S7-1500T Motion Control V4.0 function manual, A.2.37 'ErrorDetail tags
/// (positioning axis/synchronous axis)'): number and reaction of the highest-priority pending
/// alarm.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub struct ErrorDetail {
    /// Alarm number, 0 if none is pending.
    pub number: u16,
    /// Effective reaction, [`Reaction::None`] if none is pending.
    pub reaction: Reaction,
}

impl ErrorDetail {
    /// Nothing pending.
    pub const NONE: ErrorDetail = ErrorDetail {
        number: 0,
        reaction: Reaction::None,
    };

    /// ErrorDetail for a set of pending alarms ([`highest_priority`]).
    pub fn from_pending<I>(pending: I) -> ErrorDetail
    where
        I: IntoIterator<Item = AlarmInstance>,
    {
        match highest_priority(pending) {
            Some(a) => ErrorDetail {
                number: a.id.number(),
                reaction: a.reaction,
            },
            None => ErrorDetail::NONE,
        }
    }
}

impl Default for ErrorDetail {
    fn default() -> Self {
        ErrorDetail::NONE
    }
}

/// Bit masks of `<TO>.StatusWord` of positioning and synchronous axes (S7-1500T Motion Control V4.0
/// function manual, A.2.35 'StatusWord tag (positioning axis/synchronous axis)').
pub mod status_bit {
    /// 0 "Enable": the TO is enabled.
    pub const ENABLE: u32 = 1 << 0;
    /// 1 "Error": an alarm is pending.
    pub const ERROR: u32 = 1 << 1;
    /// 2 "RestartActive": re-initialization in progress.
    pub const RESTART_ACTIVE: u32 = 1 << 2;
    /// 3 "OnlineStartValuesChanged": restart tags changed; a restart is needed to apply them.
    pub const ONLINE_START_VALUES_CHANGED: u32 = 1 << 3;
    /// 4 "ControlPanelActive": the axis control panel has master control.
    pub const CONTROL_PANEL_ACTIVE: u32 = 1 << 4;
    /// 5 "HomingDone": the axis is homed.
    pub const HOMING_DONE: u32 = 1 << 5;
    /// 6 "Done": no motion job is running and the control panel is off.
    pub const DONE: u32 = 1 << 6;
    /// 7 "Standstill": standstill signal.
    pub const STANDSTILL: u32 = 1 << 7;
    /// 8 "PositioningCommand": MC_MoveAbsolute or MC_MoveRelative is running.
    pub const POSITIONING_COMMAND: u32 = 1 << 8;
    /// 9 "JogCommand": MC_MoveJog is running.
    pub const JOG_COMMAND: u32 = 1 << 9;
    /// 10 "VelocityCommand": MC_MoveVelocity is running.
    pub const VELOCITY_COMMAND: u32 = 1 << 10;
    /// 11 "HomingCommand": MC_Home is running.
    pub const HOMING_COMMAND: u32 = 1 << 11;
    /// 12 "ConstantVelocity": setpoint velocity reached (also TRUE at standstill).
    pub const CONSTANT_VELOCITY: u32 = 1 << 12;
    /// 13 "Accelerating".
    pub const ACCELERATING: u32 = 1 << 13;
    /// 14 "Decelerating".
    pub const DECELERATING: u32 = 1 << 14;
    /// 15 "SWLimitMinActive": negative SW limit reached or exceeded.
    pub const SW_LIMIT_MIN_ACTIVE: u32 = 1 << 15;
    /// 16 "SWLimitMaxActive": positive SW limit reached or exceeded.
    pub const SW_LIMIT_MAX_ACTIVE: u32 = 1 << 16;
    /// 17 "HWLimitMinActive": negative HW limit reached or exceeded.
    pub const HW_LIMIT_MIN_ACTIVE: u32 = 1 << 17;
    /// 18 "HWLimitMaxActive": positive HW limit reached or exceeded.
    pub const HW_LIMIT_MAX_ACTIVE: u32 = 1 << 18;
    /// 19: reserved.
    pub const RESERVED_19: u32 = 1 << 19;
    /// 20: reserved.
    pub const RESERVED_20: u32 = 1 << 20;
    /// 21 "Synchronizing" (synchronous axis only): synchronizing to a leading value.
    pub const SYNCHRONIZING: u32 = 1 << 21;
    /// 22 "Synchronous" (synchronous axis only): moving synchronously to a leading value.
    pub const SYNCHRONOUS: u32 = 1 << 22;
    /// 23 "SuperimposedMotionCommand": MC_MoveSuperimposed is running.
    pub const SUPERIMPOSED_MOTION_COMMAND: u32 = 1 << 23;
    /// 24 "PhasingCommand" (synchronous axis only): MC_PhasingAbsolute/Relative is running.
    pub const PHASING_COMMAND: u32 = 1 << 24;
    /// 25 "AxisSimulation": simulation active (also virtual axes).
    pub const AXIS_SIMULATION: u32 = 1 << 25;
    /// 26 "TorqueLimitingCommand": MC_TorqueLimiting is running.
    pub const TORQUE_LIMITING_COMMAND: u32 = 1 << 26;
    /// 27 "InLimitation": the drive operates at the torque limit.
    pub const IN_LIMITATION: u32 = 1 << 27;
    /// 28 "NonPositionControlled": the axis is not position-controlled.
    pub const NON_POSITION_CONTROLLED: u32 = 1 << 28;
    /// 29 "KinematicsMotionCommand": the axis is used by a kinematics job.
    pub const KINEMATICS_MOTION_COMMAND: u32 = 1 << 29;
    /// 30 "InClamping": clamped at a fixed stop.
    pub const IN_CLAMPING: u32 = 1 << 30;
    /// 31 "MotionInCommand": MC_MotionInVelocity or MC_MotionInPosition is active.
    pub const MOTION_IN_COMMAND: u32 = 1 << 31;

    /// Bits that only a synchronous axis uses (21, 22, 24); reserved on a positioning axis.
    pub const SYNCHRONOUS_AXIS_ONLY: u32 = SYNCHRONIZING | SYNCHRONOUS | PHASING_COMMAND;

    /// Bits a **speed axis** uses: 0–4, 6, 9, 10, 12–14, 25–27 (S7-1500T Motion Control V4.0
    /// function manual, A.1.15 'StatusWord tag (speed axis)').
    pub const SPEED_AXIS_MASK: u32 = ENABLE
        | ERROR
        | RESTART_ACTIVE
        | ONLINE_START_VALUES_CHANGED
        | CONTROL_PANEL_ACTIVE
        | DONE
        | JOG_COMMAND
        | VELOCITY_COMMAND
        | CONSTANT_VELOCITY
        | ACCELERATING
        | DECELERATING
        | AXIS_SIMULATION
        | TORQUE_LIMITING_COMMAND
        | IN_LIMITATION;
}

/// Bit masks of `<TO>.ErrorWord` of positioning and synchronous axes (S7-1500T Motion Control V4.0
/// function manual, A.2.36 'ErrorWord tag (positioning axis/synchronous axis)'). Bits
/// 16–31 are reserved. [`AlarmSpec::error_bit`] holds the bit *index*.
pub mod error_bit {
    /// 0 "SystemFault": system-internal error.
    pub const SYSTEM_FAULT: u32 = 1 << 0;
    /// 1 "ConfigFault": configuration parameters inconsistent or invalid.
    pub const CONFIG_FAULT: u32 = 1 << 1;
    /// 2 "UserFault": error in the user program at a motion instruction or its use.
    pub const USER_FAULT: u32 = 1 << 2;
    /// 3 "CommandNotAccepted": an instruction cannot run because requirements are not met.
    pub const COMMAND_NOT_ACCEPTED: u32 = 1 << 3;
    /// 4 "DriveFault".
    pub const DRIVE_FAULT: u32 = 1 << 4;
    /// 5 "SensorFault": error in the encoder system.
    pub const SENSOR_FAULT: u32 = 1 << 5;
    /// 6 "DynamicError": dynamic values limited to permissible values.
    pub const DYNAMIC_ERROR: u32 = 1 << 6;
    /// 7 "CommunicationFault": missing or faulty communication.
    pub const COMMUNICATION_FAULT: u32 = 1 << 7;
    /// 8 "SWLimit": SW limit switch reached or overtravelled.
    pub const SW_LIMIT: u32 = 1 << 8;
    /// 9 "HWLimit": HW limit switch reached or overtravelled.
    pub const HW_LIMIT: u32 = 1 << 9;
    /// 10 "HomingError": homing cannot be completed.
    pub const HOMING_ERROR: u32 = 1 << 10;
    /// 11 "FollowingErrorFault": following-error limit exceeded.
    pub const FOLLOWING_ERROR_FAULT: u32 = 1 << 11;
    /// 12 "PositioningFault": positioning error.
    pub const POSITIONING_FAULT: u32 = 1 << 12;
    /// 13 "PeripheralError": error accessing a logical address.
    pub const PERIPHERAL_ERROR: u32 = 1 << 13;
    /// 14 "SynchronousError" (synchronous axis only): error during synchronous operation.
    pub const SYNCHRONOUS_ERROR: u32 = 1 << 14;
    /// 15 "AdaptionError": error in automatic data transfer.
    pub const ADAPTION_ERROR: u32 = 1 << 15;
}

/// Bit masks of `<TO>.WarningWord` of positioning and synchronous axes (S7-1500T Motion Control
/// V4.0 function manual, A.2.38 'WarningWord tag (positioning axis/synchronous axis)').
/// Same layout as [`error_bit`] with "…Warning" names, except that bits 8 and 9 are split into SW
/// limit min / max. Bits 16–31 are reserved.
pub mod warning_bit {
    /// 0 "SystemWarning".
    pub const SYSTEM_WARNING: u32 = 1 << 0;
    /// 1 "ConfigWarning": configuration parameters adjusted internally (alarm 110).
    pub const CONFIG_WARNING: u32 = 1 << 1;
    /// 2 "UserWarning".
    pub const USER_WARNING: u32 = 1 << 2;
    /// 3 "CommandNotAccepted".
    pub const COMMAND_NOT_ACCEPTED: u32 = 1 << 3;
    /// 4 "DriveWarning".
    pub const DRIVE_WARNING: u32 = 1 << 4;
    /// 5 "SensorWarning".
    pub const SENSOR_WARNING: u32 = 1 << 5;
    /// 6 "DynamicError": dynamic values limited (alarms 501–504, 511, 551).
    pub const DYNAMIC_ERROR: u32 = 1 << 6;
    /// 7 "CommunicationWarning".
    pub const COMMUNICATION_WARNING: u32 = 1 << 7;
    /// 8 "SWLimitMin".
    pub const SW_LIMIT_MIN: u32 = 1 << 8;
    /// 9 "SWLimitMax".
    pub const SW_LIMIT_MAX: u32 = 1 << 9;
    /// 10 "HomingWarning".
    pub const HOMING_WARNING: u32 = 1 << 10;
    /// 11 "FollowingErrorWarning": warning level of following-error monitoring reached (522).
    pub const FOLLOWING_ERROR_WARNING: u32 = 1 << 11;
    /// 12 "PositioningWarning".
    pub const POSITIONING_WARNING: u32 = 1 << 12;
    /// 13 "PeripheralWarning".
    pub const PERIPHERAL_WARNING: u32 = 1 << 13;
    /// 14 "SynchronousWarning" (synchronous axis only).
    pub const SYNCHRONOUS_WARNING: u32 = 1 << 14;
    /// 15 "AdaptionWarning".
    pub const ADAPTION_WARNING: u32 = 1 << 15;
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(n: u16) -> AlarmSpec {
        let id = AlarmId::from_number(n);
        assert!(id.is_some(), "alarm {n} missing");
        id.map_or(ALARMS[0], |id| *id.spec())
    }

    #[test]
    fn numbers_are_unique_and_sorted() {
        for w in ALARMS.windows(2) {
            assert!(
                w[0].number < w[1].number,
                "{} before {}",
                w[0].number,
                w[1].number
            );
        }
        for w in AlarmId::ALL.windows(2) {
            assert!(w[0].number() < w[1].number());
        }
        assert_eq!(ALARMS.len(), AlarmId::ALL.len());
        assert_eq!(ALARMS.len(), 64);
    }

    #[test]
    fn table_and_match_agree() {
        for (s, &id) in ALARMS.iter().zip(AlarmId::ALL) {
            assert_eq!(s.id, id);
            assert_eq!(s.number, id.number());
            assert_eq!(id.spec(), s);
            assert!(!s.text.is_empty());
            assert_eq!(id.name(), format!("{id:?}"));
        }
    }

    #[test]
    fn from_number_round_trips() {
        for &id in AlarmId::ALL {
            assert_eq!(AlarmId::from_number(id.number()), Some(id));
        }
        let defined = (0..=u16::MAX)
            .filter(|&n| AlarmId::from_number(n).is_some())
            .count();
        assert_eq!(defined, ALARMS.len());
        for n in [
            0, 100, 114, 200, 301, 309, 320, 344, 505, 523, 532, 535, 553, 602, 610, 751, 759,
        ] {
            assert_eq!(AlarmId::from_number(n), None);
        }
    }

    #[test]
    fn reference_number_list() {
        // The alarm numbers of S7-1500T Motion Control V4.0 function manual, A.8.1 'List of the
        // technology alarms', written out separately from the table.
        let expected: &[u16] = &[
            101, 102, 103, 104, 105, 106, 107, 108, 109, 110, 111, 112, 113, 201, 202, 203, 204,
            304, 305, 306, 307, 308, 321, 322, 323, 341, 342, 343, 401, 411, 412, 421, 431, 501,
            502, 503, 504, 511, 521, 522, 531, 533, 534, 541, 542, 550, 551, 552, 601, 603, 608,
            611, 612, 700, 701, 702, 703, 704, 750, 752, 753, 754, 755, 758,
        ];
        let actual: Vec<u16> = ALARMS.iter().map(|s| s.number).collect();
        assert_eq!(actual, expected);
    }

    #[test]
    fn bits_in_range() {
        for s in ALARMS {
            assert!(s.error_bit.is_none_or(|b| b < 16), "{}", s.number);
            assert!(s.warning_bit.is_none_or(|b| b < 16), "{}", s.number);
            assert!(
                s.error_bit.is_some() || s.warning_bit.is_some(),
                "{} sets no bit",
                s.number
            );
            // Warnings only (no error bit) never stop the axis.
            if s.error_bit.is_none() {
                assert_eq!(s.reaction, Reaction::None, "{}", s.number);
            }
        }
    }

    #[test]
    fn spot_checks_against_reference() {
        let s = spec(533);
        assert_eq!(
            (s.reaction, s.error_bit, s.warning_bit),
            (Reaction::StopMaxDynamics, Some(8), None)
        );
        assert_eq!(s.error_mask(), error_bit::SW_LIMIT);
        let s = spec(534);
        assert_eq!((s.reaction, s.error_bit), (Reaction::RemoveEnable, Some(8)));
        let s = spec(521);
        assert_eq!(
            (s.reaction, s.error_bit),
            (Reaction::RemoveEnable, Some(11))
        );
        assert_eq!(s.error_mask(), error_bit::FOLLOWING_ERROR_FAULT);
        let s = spec(522);
        assert_eq!(
            (s.reaction, s.error_bit, s.warning_bit),
            (Reaction::None, None, Some(11))
        );
        assert_eq!(s.warning_mask(), warning_bit::FOLLOWING_ERROR_WARNING);
        let s = spec(541);
        assert_eq!(
            (s.reaction, s.error_bit),
            (Reaction::RemoveEnable, Some(12))
        );
        let s = spec(531);
        assert_eq!((s.reaction, s.error_bit), (Reaction::RemoveEnable, Some(9)));
        for n in [304, 305, 306] {
            assert_eq!(
                (spec(n).reaction, spec(n).error_bit),
                (Reaction::EmergencyStop, Some(2))
            );
        }
        assert_eq!(
            (spec(321).reaction, spec(321).error_bit),
            (Reaction::EmergencyStop, Some(3))
        );
        assert!(spec(101).restart);
        assert_eq!(spec(101).reaction, Reaction::RemoveEnable);
        for n in [501, 502, 503, 504, 511] {
            assert_eq!(
                (spec(n).reaction, spec(n).warning_bit),
                (Reaction::None, Some(6))
            );
            assert_eq!(spec(n).warning_mask(), warning_bit::DYNAMIC_ERROR);
        }
        assert_eq!(
            (spec(341).reaction, spec(341).error_bit),
            (Reaction::StopMaxDynamics, Some(10))
        );
        assert_eq!(
            (spec(342).reaction, spec(342).error_bit),
            (Reaction::EmergencyStop, Some(10))
        );
        assert_eq!(
            (spec(550).reaction, spec(550).error_bit),
            (Reaction::TrackSetpoints, Some(4))
        );
        assert_eq!(
            (spec(551).error_bit, spec(551).warning_bit),
            (Some(2), Some(6))
        );
        assert_eq!(
            (spec(601).reaction, spec(601).error_bit),
            (Reaction::StopMaxDynamics, Some(14))
        );
        assert_eq!(
            (spec(608).reaction, spec(608).error_bit),
            (Reaction::StopMaxDynamics, Some(14))
        );
        // Contradictions resolved by the overview table.
        assert_eq!(spec(603).reaction, Reaction::RemoveEnable);
        assert_eq!(spec(752).reaction, Reaction::RemoveEnable);
        // Restart-needed alarms (column R of the table).
        let restart: Vec<u16> = ALARMS
            .iter()
            .filter(|s| s.restart)
            .map(|s| s.number)
            .collect();
        assert_eq!(restart, [101, 102, 103, 105, 107, 109, 113, 201, 202, 203]);
        // Names requested by the design.
        assert_eq!(AlarmId::SwLimitReached.number(), 533);
        assert_eq!(AlarmId::SwLimitCrossed.number(), 534);
        assert_eq!(AlarmId::FollowingError.number(), 521);
        assert_eq!(AlarmId::FollowingErrorWarning.number(), 522);
        assert_eq!(AlarmId::PositioningMonitoring.number(), 541);
        assert_eq!(AlarmId::HwLimit.number(), 531);
        assert_eq!(AlarmId::VelocityLimited.number(), 501);
        assert_eq!(AlarmId::AccelerationLimited.number(), 502);
        assert_eq!(AlarmId::JerkLimited.number(), 503);
        assert_eq!(AlarmId::AxisNotHomed.number(), 321);
        assert_eq!(AlarmId::HomingNotFound.number(), 342);
        assert_eq!(AlarmId::HomingDataError.number(), 341);
        assert_eq!(AlarmId::LeaderMissing.number(), 601);
        assert_eq!(AlarmId::SynchronizationError.number(), 608);
    }

    #[test]
    fn reaction_codes_and_order() {
        for (i, &r) in Reaction::ALL.iter().enumerate() {
            assert_eq!(usize::from(r.code()), i);
            assert_eq!(Reaction::from_code(r.code()), Some(r));
        }
        assert_eq!(Reaction::from_code(6), None);
        assert!(Reaction::TrackSetpoints > Reaction::RemoveEnable);
        assert!(Reaction::RemoveEnable.is_more_severe_than(Reaction::EmergencyStop));
        assert!(!Reaction::None.aborts_jobs());
        assert!(Reaction::StopCurrentDynamics.aborts_jobs());
        assert!(Reaction::RemoveEnable.removes_enable());
        assert!(Reaction::TrackSetpoints.removes_enable());
        assert!(!Reaction::EmergencyStop.removes_enable());
        assert_eq!(
            Reaction::StopMaxDynamics.max_severity(Reaction::EmergencyStop),
            Reaction::EmergencyStop
        );
    }

    #[test]
    fn priority_is_a_strict_total_order() {
        for &a in AlarmId::ALL {
            assert!(!a.outranks(a));
            for &b in AlarmId::ALL {
                if a != b {
                    assert!(a.outranks(b) != b.outranks(a), "{a} vs {b}");
                }
            }
        }
    }

    #[test]
    fn highest_priority_picks_most_severe() {
        let i = |id, s| AlarmInstance::new(id, s);
        assert_eq!(highest_priority([]), None);
        let pending = [
            i(AlarmId::FollowingErrorWarning, 0),
            i(AlarmId::SwLimitReached, supplement::POSITIVE),
            i(AlarmId::PositioningMonitoring, supplement::TARGET_LEFT),
            i(AlarmId::AxisNotHomed, 0),
        ];
        assert_eq!(highest_priority(pending), Some(pending[2]));
        // Equal reaction (remove enable): lower number wins.
        assert_eq!(
            highest_priority([
                i(AlarmId::PositioningMonitoring, 1),
                i(AlarmId::FollowingError, 0)
            ]),
            Some(i(AlarmId::FollowingError, 0))
        );
        // Equal reaction (none): error bit beats warning, even with a higher number.
        assert_eq!(
            highest_priority([
                i(AlarmId::VelocityLimited, 0),
                i(AlarmId::MeasuringEdgeNotEvaluated, 0)
            ]),
            Some(i(AlarmId::MeasuringEdgeNotEvaluated, 0))
        );
        let d = ErrorDetail::from_pending(pending);
        assert_eq!(
            d,
            ErrorDetail {
                number: 541,
                reaction: Reaction::RemoveEnable
            }
        );
        assert_eq!(ErrorDetail::from_pending([]), ErrorDetail::NONE);
        assert_eq!(ErrorDetail::default(), ErrorDetail::NONE);
    }

    #[test]
    fn status_word_layout() {
        let all = [
            status_bit::ENABLE,
            status_bit::ERROR,
            status_bit::RESTART_ACTIVE,
            status_bit::ONLINE_START_VALUES_CHANGED,
            status_bit::CONTROL_PANEL_ACTIVE,
            status_bit::HOMING_DONE,
            status_bit::DONE,
            status_bit::STANDSTILL,
            status_bit::POSITIONING_COMMAND,
            status_bit::JOG_COMMAND,
            status_bit::VELOCITY_COMMAND,
            status_bit::HOMING_COMMAND,
            status_bit::CONSTANT_VELOCITY,
            status_bit::ACCELERATING,
            status_bit::DECELERATING,
            status_bit::SW_LIMIT_MIN_ACTIVE,
            status_bit::SW_LIMIT_MAX_ACTIVE,
            status_bit::HW_LIMIT_MIN_ACTIVE,
            status_bit::HW_LIMIT_MAX_ACTIVE,
            status_bit::RESERVED_19,
            status_bit::RESERVED_20,
            status_bit::SYNCHRONIZING,
            status_bit::SYNCHRONOUS,
            status_bit::SUPERIMPOSED_MOTION_COMMAND,
            status_bit::PHASING_COMMAND,
            status_bit::AXIS_SIMULATION,
            status_bit::TORQUE_LIMITING_COMMAND,
            status_bit::IN_LIMITATION,
            status_bit::NON_POSITION_CONTROLLED,
            status_bit::KINEMATICS_MOTION_COMMAND,
            status_bit::IN_CLAMPING,
            status_bit::MOTION_IN_COMMAND,
        ];
        for (i, m) in all.iter().enumerate() {
            assert_eq!(*m, 1u32 << i);
        }
        // Speed axis: bits 0-4, 6, 9, 10, 12-14, 25-27.
        let speed: u32 = [0, 1, 2, 3, 4, 6, 9, 10, 12, 13, 14, 25, 26, 27]
            .iter()
            .map(|b| 1u32 << b)
            .sum();
        assert_eq!(status_bit::SPEED_AXIS_MASK, speed);
        assert_eq!(
            status_bit::SYNCHRONOUS_AXIS_ONLY,
            (1 << 21) | (1 << 22) | (1 << 24)
        );
    }

    #[test]
    fn error_and_warning_word_layout() {
        let e = [
            error_bit::SYSTEM_FAULT,
            error_bit::CONFIG_FAULT,
            error_bit::USER_FAULT,
            error_bit::COMMAND_NOT_ACCEPTED,
            error_bit::DRIVE_FAULT,
            error_bit::SENSOR_FAULT,
            error_bit::DYNAMIC_ERROR,
            error_bit::COMMUNICATION_FAULT,
            error_bit::SW_LIMIT,
            error_bit::HW_LIMIT,
            error_bit::HOMING_ERROR,
            error_bit::FOLLOWING_ERROR_FAULT,
            error_bit::POSITIONING_FAULT,
            error_bit::PERIPHERAL_ERROR,
            error_bit::SYNCHRONOUS_ERROR,
            error_bit::ADAPTION_ERROR,
        ];
        let w = [
            warning_bit::SYSTEM_WARNING,
            warning_bit::CONFIG_WARNING,
            warning_bit::USER_WARNING,
            warning_bit::COMMAND_NOT_ACCEPTED,
            warning_bit::DRIVE_WARNING,
            warning_bit::SENSOR_WARNING,
            warning_bit::DYNAMIC_ERROR,
            warning_bit::COMMUNICATION_WARNING,
            warning_bit::SW_LIMIT_MIN,
            warning_bit::SW_LIMIT_MAX,
            warning_bit::HOMING_WARNING,
            warning_bit::FOLLOWING_ERROR_WARNING,
            warning_bit::POSITIONING_WARNING,
            warning_bit::PERIPHERAL_WARNING,
            warning_bit::SYNCHRONOUS_WARNING,
            warning_bit::ADAPTION_WARNING,
        ];
        for i in 0..16 {
            assert_eq!(e[i], 1u32 << i);
            assert_eq!(w[i], 1u32 << i);
        }
    }

    #[test]
    fn display() {
        assert_eq!(AlarmId::SwLimitReached.to_string(), "533 SwLimitReached");
    }
}
