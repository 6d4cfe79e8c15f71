//! ErrorIDs returned by motion-control jobs (the `ErrorID` output of an S7 / PLCopen FB).
//!
//! One variant per ErrorID of the S7-1500T Motion Control V4.0 function manual, appendix A.9
//! A.9 'Error ID for Motion Control instructions', plus a small block of **tandem extensions** at
//! `16#80F0`–`16#80F4`, a range that the reference does not use (S7-1500T Motion Control V4.0
//! function manual, A.9 'Error ID for Motion Control instructions' uses `16#8001`–`16#8076`,
//! `16#80A1`–`16#80AE` and `16#8FFF`).
//!
//! Semantics (S7-1500T Motion Control V4.0 function manual, 6.3 'Motion Control instructions', A.9
//! 'Error ID for Motion Control instructions'): every ErrorID other than [`ErrorId::None`] means
//! the FB shows `Error = TRUE` and the job was **rejected**: running jobs are not affected and
//! nothing has to be acknowledged. The exception is [`ErrorId::TechnologyAlarm`] (`16#8001`): a
//! technology alarm occurred while the job ran, see `ErrorDetail.Number` and
//! [`crate::catalog::alarm`].
//!
//! # Tandem extensions
//!
//! | Code | Variant | Why |
//! |---|---|---|
//! | `16#80F0` | [`ErrorId::AxisLocked`] | S7-Technology MC_Stop locks the axis and rejects motion jobs with `8045` (S7-Technology V4.1 function manual, 6.2.3 'FB404 MC_Stop - Stopping an axis and preventing new motion commands'); in S7-1500 `16#8045` already means "fixed-stop travel active", so tandem uses a free code. |
//! | `16#80F1` | [`ErrorId::IllegalOverride`] | S7-1500 clamps `Override.Velocity` (a DIR tag, S7-1500T Motion Control V4.0 function manual, A.2.20 'Override tags (positioning axis/synchronous axis)'); tandem's job interface can also reject an override outside 0..200 %. |
//! | `16#80F2` | [`ErrorId::NotHomed`] | S7-1500 reacts to MC_MoveAbsolute on an axis that is not homed with technology alarm 321 (E-stop, ErrorID `16#8001`, S7-1500T Motion Control V4.0 function manual, 10.5.1 'MC_MoveAbsolute: Position axis absolutely V4'); the reference has no plain ErrorID for it. This code is for a rejection without an alarm. |
//! | `16#80F3` | [`ErrorId::JobRejectedInErrorStop`] | PLCopen ErrorStop: a motion job while a stopping technology alarm is pending and not acknowledged. S7-1500 has no own code for it; its manual only tells the user to check `ErrorDetail` before starting a job (S7-1500T Motion Control V4.0 function manual, 6.3 'Motion Control instructions'). |
//! | `16#80F4` | [`ErrorId::BufferModeNotAllowed`] | S7-Technology rejects append and blend with `8055` while a synchronous operation or MC_Halt is active and a MoveVelocity appended to a MoveVelocity (S7-Technology V4.1 function manual, 6.2.6 'FB410 MC_MoveAbsolute - Absolute positioning', 6.2.10 'FB 414 MC_MoveVelocity - Motion with speed preset'); S7-1500 has no BufferMode (S7-1500T Motion Control V4.0 function manual, 3.4 'No buffering or blending in V4.0'), and tandem keeps its own codes in the free `16#80F0` block rather than take S7-Technology's number inside the reference's range. A full queue is the reference's [`ErrorId::NoJobMemory`] (`16#8014`, S7-Technology `8005`). |
//!
//! | `16#80F7` | [`ErrorId::IllegalParameterValue`] | S7-Technology's MC_WriteParameter answers an illegal value with `8043` (S7-Technology V4.1 function manual, 6.7.5 'FB407 MC_WriteParameter - Changing parameters'), which S7-1500 uses for an illegal torque limit. |
//!
//! # From S7-Technology
//!
//! S7-1500 V4.0 has no MC_ReadParameter / MC_WriteParameter (the user program writes the
//! technology DB's tags). tandem's instructions answer with S7-Technology FB407's codes where
//! they fall outside the ranges S7-1500 uses: `16#8080` [`ErrorId::InvalidParameterNumber`],
//! `16#8081` [`ErrorId::ParameterNotWritable`], `16#8086` [`ErrorId::ParameterNotAvailable`],
//! `16#808B` [`ErrorId::InvalidRealFormat`] (docs/parameters.md).
//!
//! Whether the axis reports a missing homing as alarm 321 (S7-compatible) or as
//! [`ErrorId::NotHomed`] is the axis's choice. This module only defines the codes.

use core::fmt;

/// Builds [`ErrorId`] and its lookup methods from a single list, so that code, name and
/// description cannot drift apart. A duplicate code is a compile error (duplicate discriminant).
macro_rules! error_ids {
    (
        $(#[$enum_attr:meta])*
        pub enum ErrorId {
            $( $(#[$attr:meta])* $name:ident = $code:literal => $desc:literal, )*
        }
    ) => {
        $(#[$enum_attr])*
        pub enum ErrorId {
            $(
                #[doc = concat!("`", stringify!($code), "`: ", $desc)]
                #[doc = ""]
                $(#[$attr])*
                $name = $code,
            )*
        }

        impl ErrorId {
            /// Every ErrorID, sorted by code.
            pub const ALL: &'static [ErrorId] = &[$(ErrorId::$name,)*];

            /// The identifier (the variant name, e.g. `"IllegalVelocity"`).
            pub const fn name(self) -> &'static str {
                match self {
                    $(ErrorId::$name => stringify!($name),)*
                }
            }

            /// One-line description (the meaning column of S7-1500T Motion Control V4.0 function
            /// manual, A.9 'Error ID for Motion Control instructions', or the tandem extension).
            pub const fn description(self) -> &'static str {
                match self {
                    $(ErrorId::$name => $desc,)*
                }
            }

            /// The ErrorID for a numeric code, or `None` for a code that is not defined.
            pub const fn from_code(code: u16) -> Option<ErrorId> {
                match code {
                    $($code => Some(ErrorId::$name),)*
                    _ => None,
                }
            }
        }
    };
}

error_ids! {
    /// ErrorID of a motion-control job (S7-1500T Motion Control V4.0 function manual,
    /// A.9 'Error ID for Motion Control instructions').
    ///
    /// The discriminant is the code (`16#8003` is `0x8003`). The variants are declared in code
    /// order and [`ErrorId::ALL`] lists them in that order.
    #[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
    #[repr(u16)]
    #[doc(alias = "ErrorID")]
    pub enum ErrorId {
        None = 0x0000 => "No error.",
        /// The only code that does not mean "job rejected". Read `ErrorDetail.Number`.
        TechnologyAlarm = 0x8001 => "A technology alarm occurred while the job was processed; see ErrorDetail.",
        IllegalObject = 0x8002 => "Illegal technology object (Axis, Master, Slave, Cam, measuring input type ...).",
        IllegalVelocity = 0x8003 => "Illegal velocity.",
        IllegalAcceleration = 0x8004 => "Illegal acceleration.",
        IllegalDeceleration = 0x8005 => "Illegal deceleration.",
        IllegalJerk = 0x8006 => "Illegal jerk.",
        /// Also JogForward and JogBackward both TRUE: the axis brakes with the last valid
        /// deceleration (S7-1500T Motion Control V4.0 function manual, 6.3 'Motion Control
        /// instructions').
        IllegalDirection = 0x8007 => "Illegal Direction or SyncDirection, or JogForward and JogBackward both TRUE.",
        IllegalDistance = 0x8008 => "Illegal distance.",
        IllegalPosition = 0x8009 => "Illegal position.",
        IllegalMode = 0x800A => "Illegal Mode.",
        IllegalStopMode = 0x800B => "Illegal StopMode.",
        OnlyOneInstance = 0x800C => "Only one instance of this instruction per technology object is allowed.",
        RestartActive = 0x800D => "Job not permitted: a restart of the technology object is running.",
        RestartWhileEnabled = 0x800E => "Restart not possible while the technology object is enabled.",
        NotEnabled = 0x800F => "Job not possible: the technology object is locked (not enabled).",
        IllegalHomingModeIncremental = 0x8010 => "Homing mode invalid for an incremental encoder (6, 7).",
        IllegalHomingModeAbsolute = 0x8011 => "Homing mode invalid for an absolute encoder (2, 3, 5, 8, 10).",
        ControlPanelActive = 0x8012 => "Job not possible: the axis control panel has master control.",
        ControlPanelConnectionLost = 0x8013 => "Online connection between CPU and engineering tool (control panel) lost.",
        NoJobMemory = 0x8014 => "No internal job memory available.",
        ResetNotPossible = 0x8015 => "Acknowledgement with MC_Reset not possible: configuration error.",
        ActualValuesInvalid = 0x8016 => "Actual values are not valid (StatusSensor.State is not VALID).",
        IllegalRatioNumerator = 0x8017 => "Illegal gear ratio numerator (0).",
        IllegalRatioDenominator = 0x8018 => "Illegal gear ratio denominator (< 1).",
        RecursiveSyncChain = 0x8019 => "The follower is the original leader of the synchronous operation chain.",
        IllegalMasterOffset = 0x8021 => "Illegal MasterOffset.",
        IllegalSlaveOffset = 0x8022 => "Illegal SlaveOffset.",
        IllegalMasterScaling = 0x8023 => "Illegal MasterScaling.",
        IllegalSlaveScaling = 0x8024 => "Illegal SlaveScaling.",
        IllegalMasterStartDistance = 0x8026 => "Illegal MasterStartDistance.",
        IllegalApplicationMode = 0x8027 => "Illegal ApplicationMode.",
        IllegalMasterSyncPosition = 0x8034 => "Illegal MasterSyncPosition.",
        IllegalSlaveSyncPosition = 0x8035 => "Illegal SlaveSyncPosition.",
        IllegalSyncProfileReference = 0x8036 => "Illegal SyncProfileReference.",
        IllegalOnPosition = 0x8040 => "Illegal OnPosition of the output cam.",
        IllegalOffPosition = 0x8041 => "Illegal OffPosition of the output cam.",
        IllegalDuration = 0x8042 => "Illegal Duration of the time-based output cam.",
        IllegalTorqueLimit = 0x8043 => "Illegal force/torque limit.",
        TorqueReductionNotConfigured = 0x8044 => "Axis not configured for torque reduction (needs telegram 102, 103, 105 or 106).",
        /// Not to be confused with the S7-Technology `8045` of MC_Stop: see
        /// [`ErrorId::AxisLocked`].
        FixedStopActive = 0x8045 => "Job not possible: travel to fixed stop active (no switch to non-position-controlled).",
        InClamping = 0x8046 => "MC_TorqueLimiting cannot be disabled while InClamping.",
        MotionIntoFixedStop = 0x8047 => "The motion goes into the fixed stop; only motions away from it are allowed.",
        IllegalAdditiveTorque = 0x804A => "Illegal additive torque value.",
        IllegalUpperTorqueLimit = 0x804B => "Illegal upper torque limit.",
        IllegalLowerTorqueLimit = 0x804C => "Illegal lower torque limit.",
        TorqueLimitsInverted = 0x804D => "Upper torque limit is less than or equal to the lower limit.",
        TorqueLimitingRangeExclusive = 0x804E => "MC_TorqueLimiting and MC_TorqueRange are mutually exclusive.",
        NoAdditionalTorqueTelegram = 0x804F => "Axis not configured for additional torque values (telegram 750).",
        IllegalSensor = 0x8050 => "Illegal encoder number (1..4).",
        IllegalReferenceSensor = 0x8051 => "Illegal reference encoder number.",
        IllegalApproachLeadingValue = 0x8062 => "Illegal ApproachLeadingValue.",
        NoLeadingValue = 0x8063 => "No leading value exists for the given following value.",
        NoFollowingValue = 0x8064 => "No following value exists for the given leading value.",
        IllegalPhaseShift = 0x8070 => "Illegal PhaseShift.",
        NotPositionControlled = 0x8071 => "Job not possible: the axis is not in position-controlled mode.",
        HomingActive = 0x8074 => "Job not possible: an MC_Home job is active (encoder switch refused).",
        NoSynchronousOperation = 0x8075 => "Job not possible: no synchronous operation is active on the axis.",
        SyncSimulationActive = 0x8076 => "Job not possible: synchronous operation is being simulated on the axis.",
        /// **S7-Technology.** MC_ReadParameter / MC_WriteParameter: the axis has no parameter
        /// of this number or tag (S7-Technology V4.1 function manual, 6.7.5 'FB407
        /// MC_WriteParameter - Changing parameters', ErrorID `8080`).
        #[doc(alias = "8080")]
        InvalidParameterNumber = 0x8080 => "Invalid parameter number or tag: the technology object has no such parameter.",
        /// **S7-Technology.** MC_WriteParameter on a parameter that cannot be written while
        /// the axis runs: read-only, or (S7-1500 `RES`) effective only after a restart of the
        /// technology object (S7-Technology V4.1 function manual, 6.7.5, ErrorID `8081`).
        #[doc(alias = "8081")]
        ParameterNotWritable = 0x8081 => "Parameter cannot be changed while running (read-only, or needs a restart of the technology object).",
        /// **S7-Technology.** The parameter exists but not on this axis: a speed axis' position
        /// control, a position controller in a connected drive, a hydraulic axis
        /// (S7-Technology V4.1 function manual, 6.7.5, ErrorID `8086`).
        #[doc(alias = "8086")]
        ParameterNotAvailable = 0x8086 => "Parameter not available on this technology object.",
        /// **S7-Technology.** The value is not a finite number (S7-Technology V4.1 function
        /// manual, 6.7.5, ErrorID `808B` "Parameter value of invalid REAL format").
        #[doc(alias = "808B")]
        InvalidRealFormat = 0x808B => "Parameter value of invalid REAL format (not a finite number).",
        SyncJobActive = 0x80A1 => "MC_Home on a follower refused while MC_CamIn or MC_GearInPos is active.",
        MeasuringRangeInvalidModulo = 0x80A2 => "Measuring range invalid with the configured modulo settings.",
        MeasuringRejectedHomingActive = 0x80A3 => "PROFIdrive measuring job refused: a homing job is active.",
        IllegalMeasuringStart = 0x80A5 => "Illegal start position of the measuring range.",
        IllegalMeasuringEnd = 0x80A6 => "Illegal end position of the measuring range.",
        MeasuredOutsideRange = 0x80A7 => "Measured position outside the measuring range; value discarded.",
        CammingActive = 0x80A8 => "Phasing refused: camming is active on the axis.",
        SynchronizingActive = 0x80A9 => "Phasing refused: the follower is still synchronizing (StartSync) or a kinematics motion is active.",
        CamEmpty = 0x80AA => "The cam contains no points or segments.",
        CamInUse = 0x80AB => "The cam is in use and cannot be interpolated.",
        CamInvalidPoints = 0x80AC => "The cam contains invalid points or segments.",
        SyncPositionOutsideCam = 0x80AD => "MasterSyncPosition outside the definition range of the cam.",
        KinematicsMotionActive = 0x80AE => "Job not possible: a kinematics motion is active.",
        /// **Tandem extension.** Counterpart of the S7-Technology MC_Stop lock (S7-Technology V4.1
        /// function manual, 6.2.3 'FB404 MC_Stop - Stopping an axis and preventing new motion
        /// commands', error `8045` there): while an MC_Stop job holds the axis (its Execute still
        /// TRUE), every new motion job is rejected, even across disable/re-enable.
        AxisLocked = 0x80F0 => "Tandem extension: job rejected, the axis is locked by an active MC_Stop.",
        /// **Tandem extension.** Velocity override outside 0.0..=200.0 % (S7-1500T Motion Control
        /// V4.0 function manual, A.2.20 'Override tags (positioning axis/synchronous
        /// axis)', range of `Override.Velocity`) or not finite.
        IllegalOverride = 0x80F1 => "Tandem extension: override outside 0..200 %.",
        /// **Tandem extension.** Absolute positioning requested on an axis that is not homed.
        /// S7-1500 raises technology alarm 321 instead (E-stop reaction, job ErrorID `16#8001`,
        /// S7-1500T Motion Control V4.0 function manual, 10.5.1 'MC_MoveAbsolute: Position axis
        /// absolutely V4').
        NotHomed = 0x80F2 => "Tandem extension: absolute move rejected, the axis is not homed (S7-1500: alarm 321).",
        /// **Tandem extension.** PLCopen ErrorStop: a technology alarm with a stopping reaction
        /// (1..=5) is pending and not yet acknowledged with MC_Reset.
        JobRejectedInErrorStop = 0x80F3 => "Tandem extension: job rejected, a stopping technology alarm is pending (ErrorStop).",
        /// **Tandem extension.** A Buffered or blending job (`BufferMode` 1..5) where the
        /// references do not allow one: a synchronous operation is active or pending, the
        /// running job is not a MoveAbsolute, MoveRelative, MoveAdditive or MoveVelocity (e.g.
        /// MC_Halt), or a MoveVelocity behind a MoveVelocity. S7-Technology rejects these with
        /// `8055` "Latching motion not allowed in current state" (S7-Technology V4.1 function
        /// manual, 6.2.6 'FB410 MC_MoveAbsolute - Absolute positioning' and 6.2.10 'FB 414
        /// MC_MoveVelocity - Motion with speed preset', `Mode`); S7-1500 has no BufferMode and
        /// no code for it.
        BufferModeNotAllowed = 0x80F4 => "Tandem extension: BufferMode not allowed now (synchronous operation, MC_Halt, or MoveVelocity behind MoveVelocity).",
        /// **Tandem extension.** A parameter of a hydraulic axis' controller instruction out of
        /// its range (MC_AxCtrlPressure_BkPlcMc: `kP`, `Tn`, `PreSet`, `WindupLimit`, the set
        /// value), or the instruction on an axis that is not hydraulic or has no pressure
        /// inputs. The Beckhoff hydraulic library answers with `dwTcHydAdsErrIllegalValue`
        /// (16#0706); S7 has no such instruction.
        IllegalControllerParameter = 0x80F5 => "Tandem extension: hydraulic controller parameter out of range, or no pressure inputs (Beckhoff hydraulic library: 16#0706).",
        /// **Tandem extension.** A positioning of a hydraulic axis in a direction whose feed
        /// enable (`Enable_Positive` / `Enable_Negative` of MC_Power_BkPlcMc) is off. The
        /// Beckhoff hydraulic library answers with `dwTcHydErrCdPosFdEna` (16#4358) or
        /// `dwTcHydErrCdNegFdEna` (16#4357); S7 has no direction enables.
        NoFeedEnable = 0x80F6 => "Tandem extension: move in a direction without its feed enable (Beckhoff hydraulic library: 16#4358 / 16#4357).",
        /// **Tandem extension.** MC_WriteParameter with a value outside the parameter's range
        /// or inconsistent with the other parameters (the check the configuration makes at
        /// load), for a parameter that is not a velocity, acceleration, deceleration, jerk or
        /// position (those answer `16#8003`..`16#8006`, `16#8009`). S7-Technology answers
        /// `8043` "Illegal parameter value" (S7-Technology V4.1 function manual, 6.7.5 'FB407
        /// MC_WriteParameter - Changing parameters'), which S7-1500 uses for an illegal
        /// torque limit.
        IllegalParameterValue = 0x80F7 => "Tandem extension: parameter value out of range or inconsistent (S7-Technology MC_WriteParameter: 8043).",
        Unspecified = 0x8FFF => "Unspecified error.",
    }
}

impl ErrorId {
    /// The numeric ErrorID (`16#8003` is `0x8003`).
    pub const fn code(self) -> u16 {
        self as u16
    }

    /// `true` for everything except [`ErrorId::None`].
    pub const fn is_error(self) -> bool {
        !matches!(self, ErrorId::None)
    }

    /// `true` for the codes tandem adds beyond S7-1500T Motion Control V4.0 function manual, A.9
    /// 'Error ID for Motion Control instructions' (see the module documentation).
    pub const fn is_tandem_extension(self) -> bool {
        matches!(
            self,
            ErrorId::AxisLocked
                | ErrorId::IllegalOverride
                | ErrorId::NotHomed
                | ErrorId::JobRejectedInErrorStop
                | ErrorId::BufferModeNotAllowed
                | ErrorId::IllegalControllerParameter
                | ErrorId::NoFeedEnable
                | ErrorId::IllegalParameterValue
        )
    }
}

impl fmt::Display for ErrorId {
    /// S7 notation: `16#8003 IllegalVelocity`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "16#{:04X} {}", self.code(), self.name())
    }
}

impl std::error::Error for ErrorId {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_are_unique() {
        for (i, a) in ErrorId::ALL.iter().enumerate() {
            for b in &ErrorId::ALL[i + 1..] {
                assert_ne!(a.code(), b.code(), "{a:?} and {b:?} share a code");
            }
        }
    }

    #[test]
    fn names_are_unique_and_match_debug() {
        for (i, a) in ErrorId::ALL.iter().enumerate() {
            assert_eq!(a.name(), format!("{a:?}"));
            assert!(!a.description().is_empty());
            for b in &ErrorId::ALL[i + 1..] {
                assert_ne!(a.name(), b.name());
            }
        }
    }

    #[test]
    fn from_code_round_trips_all() {
        for &e in ErrorId::ALL {
            assert_eq!(ErrorId::from_code(e.code()), Some(e));
        }
        let mut defined = 0usize;
        for code in 0..=u16::MAX {
            if let Some(e) = ErrorId::from_code(code) {
                assert_eq!(e.code(), code);
                defined += 1;
            }
        }
        assert_eq!(defined, ErrorId::ALL.len());
    }

    #[test]
    fn all_is_sorted_by_code() {
        for w in ErrorId::ALL.windows(2) {
            assert!(w[0].code() < w[1].code(), "{:?} before {:?}", w[0], w[1]);
        }
    }

    #[test]
    fn reference_codes() {
        // Spot checks against S7-1500T Motion Control V4.0 function manual, A.9 'Error ID for
        // Motion Control instructions'.
        assert_eq!(ErrorId::None.code(), 0x0000);
        assert_eq!(ErrorId::TechnologyAlarm.code(), 0x8001);
        assert_eq!(ErrorId::IllegalVelocity.code(), 0x8003);
        assert_eq!(ErrorId::IllegalJerk.code(), 0x8006);
        assert_eq!(ErrorId::IllegalDirection.code(), 0x8007);
        assert_eq!(ErrorId::IllegalStopMode.code(), 0x800B);
        assert_eq!(ErrorId::NotEnabled.code(), 0x800F);
        assert_eq!(ErrorId::IllegalRatioDenominator.code(), 0x8018);
        assert_eq!(ErrorId::FixedStopActive.code(), 0x8045);
        assert_eq!(ErrorId::NotPositionControlled.code(), 0x8071);
        assert_eq!(ErrorId::SyncPositionOutsideCam.code(), 0x80AD);
        assert_eq!(ErrorId::KinematicsMotionActive.code(), 0x80AE);
        assert_eq!(ErrorId::Unspecified.code(), 0x8FFF);
        // Unused codes of the reference stay undefined.
        for code in [0x8020, 0x8025, 0x8048, 0x8049, 0x8072, 0x80A4, 0x80AF] {
            assert_eq!(ErrorId::from_code(code), None);
        }
        // 73 codes in S7-1500T Motion Control V4.0 function manual, A.9 'Error ID for Motion
        // Control instructions', 4 of S7-Technology's MC_WriteParameter, plus 8 tandem
        // extensions.
        let s7t = |e: &&ErrorId| (0x8080..=0x808F).contains(&e.code());
        let reference = ErrorId::ALL
            .iter()
            .filter(|e| !e.is_tandem_extension() && !s7t(e))
            .count();
        assert_eq!(reference, 73);
        assert_eq!(ErrorId::ALL.iter().filter(s7t).count(), 4);
        assert_eq!(ErrorId::ALL.len(), 85);
    }

    #[test]
    fn extensions_use_a_free_block() {
        for &e in ErrorId::ALL {
            let in_block = (0x80F0..=0x80FF).contains(&e.code());
            assert_eq!(e.is_tandem_extension(), in_block, "{e:?}");
            if e.is_tandem_extension() {
                assert!(e.description().starts_with("Tandem extension"));
            }
        }
        assert!(!ErrorId::None.is_error());
        assert!(ErrorId::Unspecified.is_error());
    }

    #[test]
    fn display_uses_s7_notation() {
        assert_eq!(
            ErrorId::IllegalVelocity.to_string(),
            "16#8003 IllegalVelocity"
        );
        assert_eq!(ErrorId::None.to_string(), "16#0000 None");
    }
}
