//! The error codes of the Beckhoff TwinCAT PLC Hydraulic Positioning library (its 'Error Codes',
//! the constants for `ErrorID` of its function blocks and `nErrorCode` of an axis), as data: the
//! numbers the hydraulic stages report when they refuse a parameter or a command, so that a user
//! of the library finds the code they know.
//!
//! The list holds every code the library documents except the reserved and the ADS-transport
//! ones (unknown port / target, invalid size, no AMS address), which have nothing to do here.

/// One error code of the library (its `dwTcHyd…` constant).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub struct HydErrorCode(pub u32);

/// `(number, constant, meaning)` of every code (see the module documentation).
pub const CODES: &[(u32, &str, &str)] = &[
    (0x0000, "dwTcHydAdsErrNoError", "no error"),
    (0x0702, "dwTcHydAdsErrInvalidIdxGroup", "invalid IndexGroup"),
    (
        0x0703,
        "dwTcHydAdsErrInvalidIdxOffset",
        "invalid IndexOffset, or an index out of bounds",
    ),
    (
        0x0704,
        "dwTcHydAdsErrRdWrNotPermitted",
        "access not permitted (write-protected)",
    ),
    (
        0x0706,
        "dwTcHydAdsErrIllegalValue",
        "value outside its absolute limits or the limits other parameters set",
    ),
    (0x0707, "dwTcHydAdsErrNotReady", "not ready for operation"),
    (
        0x0708,
        "dwTcHydAdsErrBusy",
        "already active with another task",
    ),
    (
        0x070C,
        "dwTcHydAdsErrNoFile",
        "file missing or not accessible",
    ),
    (
        0x070D,
        "dwTcHydAdsErrSyntax",
        "invalid syntax in a command or a characteristic curve file",
    ),
    (0x0745, "dwTcHydAdsErrTimeout", "timeout"),
    (
        0x4040,
        "dwTcHydErrCdNotCompatible",
        "the axis is incompatible with the function",
    ),
    (
        0x4104,
        "dwTcHydErrCdIllegalOutputNumber",
        "output number outside the permitted range",
    ),
    (
        0x4107,
        "dwTcHydErrCdNotSupport",
        "function or command not supported",
    ),
    (0x4205, "dwTcHydErrCdCycleTime", "cycle time not permitted"),
    (
        0x4210,
        "dwTcHydErrCdMissingEnc",
        "no connection to an encoder interface",
    ),
    (
        0x4212,
        "dwTcHydErrCdMissingDrive",
        "no connection to a drive interface",
    ),
    (
        0x421A,
        "dwTcHydErrCdCannotSynchronize",
        "start distance inadequate to synchronize",
    ),
    (
        0x421B,
        "dwTcHydErrCdIllegalGearFactor",
        "gear coupling parameters not permitted",
    ),
    (
        0x4222,
        "dwTcHydErrCdSoftEnd",
        "target beyond an active software limit switch",
    ),
    (
        0x4228,
        "dwTcHydErrCdLowDist",
        "travel distance unacceptably small",
    ),
    (0x4239, "dwTcHydErrCdIllegalStartType", "invalid start type"),
    (
        0x423F,
        "dwTcHydErrCdCommandBufferOverflow",
        "command buffer full",
    ),
    (
        0x4260,
        "dwTcHydErrCdCtrlEnaLost",
        "controller enable withdrawn during the motion",
    ),
    (0x4309, "dwTcHydErrCdAcc", "acceleration not acceptable"),
    (0x430A, "dwTcHydErrCdDec", "deceleration not acceptable"),
    (0x430B, "dwTcHydErrCdJerk", "jerk limitation invalid"),
    (
        0x4345,
        "dwTcHydErrCdPtrPlcMc",
        "no connection to a required axis interface",
    ),
    (
        0x4346,
        "dwTcHydErrCdPtrMcPlc",
        "no connection to a required axis interface",
    ),
    (
        0x4356,
        "dwTcHydErrCdCtrlEna",
        "movement without controller enable",
    ),
    (
        0x4357,
        "dwTcHydErrCdNegFdEna",
        "negative movement without the negative advance enable",
    ),
    (
        0x4358,
        "dwTcHydErrCdPosFdEna",
        "positive movement without the positive advance enable",
    ),
    (
        0x4359,
        "dwTcHydErrCdSetVelo",
        "required velocity not acceptable",
    ),
    (
        0x435C,
        "dwTcHydErrCdPehTimeout",
        "target window not reached within the specified time",
    ),
    (
        0x435D,
        "dwTcHydErrCdNotMoving",
        "axis not moving, or not in the correct direction",
    ),
    (
        0x43A0,
        "dwTcHydErrCdConsequential",
        "consequential error: caused by another axis",
    ),
    (0x4401, "dwTcHydErrCdEncType", "encoder type invalid"),
    (
        0x4406,
        "dwTcHydErrCdEncScaling",
        "increment scaling not permitted",
    ),
    (
        0x4414,
        "dwTcHydErrCdEncSyncDist",
        "latch enable too close to the sync pulse",
    ),
    (
        0x4422,
        "dwTcHydErrCdEncSetActPos",
        "problem setting the actual value",
    ),
    (
        0x4442,
        "dwTcHydErrCdPtrPlcEncIn",
        "no encoder input interface",
    ),
    (
        0x4443,
        "dwTcHydErrCdPtrPlcEncOut",
        "no encoder output interface",
    ),
    (
        0x4450,
        "dwTcHydErrCdEncUnderrun",
        "actual position below the encoder's lower count limit",
    ),
    (
        0x4451,
        "dwTcHydErrCdEncOverrun",
        "actual position above the encoder's upper count limit",
    ),
    (
        0x4464,
        "dwTcHydErrCdEncHwFailed",
        "drive actuator or encoder reports a hardware fault",
    ),
    (0x4470, "dwTcHydErrCdSsi", "SSI encoder error"),
    (
        0x4550,
        "dwTcHydErrCdPosLag",
        "lag error exceeds an active limit",
    ),
    (0x4601, "dwTcHydErrCdDriveType", "drive type not permitted"),
    (
        0x4605,
        "dwTcHydErrCdRefVelo",
        "reference velocity fRefVelo invalid",
    ),
    (0x4636, "dwTcHydErrCdStepperStalled", "stall detected"),
    (
        0x4642,
        "dwTcHydErrCdPtrPlcDriveIn",
        "no drive input interface",
    ),
    (
        0x4643,
        "dwTcHydErrCdPtrPlcDriveOut",
        "no drive output interface",
    ),
    (
        0x4650,
        "dwTcHydErrCdDriveNotReady",
        "power section not ready for operation",
    ),
    (
        0x4A02,
        "dwTcHydErrCdTblEntryCount",
        "number of table entries not permitted",
    ),
    (
        0x4A04,
        "dwTcHydErrCdTblInvalidMasterStep",
        "table entries with an invalid master step",
    ),
    (0x4A10, "dwTcHydErrCdTblNoInit", "table not initialized"),
    (
        0x4A13,
        "dwTcHydErrCdTblIllegalIndex",
        "table index not permitted",
    ),
    (0x4A15, "dwTcHydErrCdTblLineCount", "too many table entries"),
    (
        0x4B01,
        "dwTcHydErrCdNotStartable",
        "axis in a state that does not allow a start",
    ),
    (
        0x4B07,
        "dwTcHydErrCdFuncTimeout",
        "function not reported complete in time",
    ),
    (
        0x4B09,
        "dwTcHydErrCdNotReady",
        "axis not in an operable state",
    ),
    (
        0x4F00,
        "dwTcHydErrCdHomingType",
        "referencing method not permitted",
    ),
    (
        0x4F01,
        "dwTcHydErrCdEncCutOff",
        "limit frequency of the actual value acquisition exceeded",
    ),
    (
        0x4F02,
        "dwTcHydErrCdIllegalDistance",
        "distance invalid: zero or negative",
    ),
    (
        0x4FF0,
        "dwTcHydErrEncDisconnected",
        "encoder hardware uncoupled",
    ),
    (
        0x4FF1,
        "dwTcHydErrDriveDisconnected",
        "drive hardware uncoupled",
    ),
    (
        0x4FF2,
        "dwTcHydErrDistanceInsufficient",
        "travel path inadequate",
    ),
    (
        0x4FF3,
        "dwTcHydErrIllegalAreas",
        "inadmissible effective areas of the cylinder",
    ),
    (
        0x4FF4,
        "dwTcHydErrIncompleteImplementation",
        "the axis implementation is incomplete",
    ),
];

impl HydErrorCode {
    /// `dwTcHydAdsErrIllegalValue`.
    pub const ILLEGAL_VALUE: Self = Self(0x0706);
    /// `dwTcHydAdsErrInvalidIdxOffset`: an index out of bounds.
    pub const INVALID_IDX_OFFSET: Self = Self(0x0703);
    /// `dwTcHydErrCdIllegalOutputNumber`.
    pub const ILLEGAL_OUTPUT_NUMBER: Self = Self(0x4104);
    /// `dwTcHydErrCdNotSupport`.
    pub const NOT_SUPPORT: Self = Self(0x4107);
    /// `dwTcHydAdsErrSyntax`.
    pub const SYNTAX: Self = Self(0x070D);
    /// `dwTcHydErrCdAcc`.
    pub const ACC: Self = Self(0x4309);
    /// `dwTcHydErrCdDec`.
    pub const DEC: Self = Self(0x430A);
    /// `dwTcHydErrCdNegFdEna`: a negative movement without the negative feed enable.
    pub const NEG_FD_ENA: Self = Self(0x4357);
    /// `dwTcHydErrCdPosFdEna`: a positive movement without the positive feed enable.
    pub const POS_FD_ENA: Self = Self(0x4358);
    /// `dwTcHydErrCdSetVelo`.
    pub const SET_VELO: Self = Self(0x4359);
    /// `dwTcHydErrCdRefVelo`.
    pub const REF_VELO: Self = Self(0x4605);
    /// `dwTcHydErrCdTblEntryCount`.
    pub const TBL_ENTRY_COUNT: Self = Self(0x4A02);
    /// `dwTcHydErrCdTblInvalidMasterStep`.
    pub const TBL_INVALID_MASTER_STEP: Self = Self(0x4A04);
    /// `dwTcHydErrCdTblLineCount`.
    pub const TBL_LINE_COUNT: Self = Self(0x4A15);
    /// `dwTcHydErrIllegalAreas`.
    pub const ILLEGAL_AREAS: Self = Self(0x4FF3);

    /// The library's constant, e.g. `dwTcHydErrCdSetVelo` (`"?"` for a number it lacks).
    pub fn name(self) -> &'static str {
        CODES.iter().find(|c| c.0 == self.0).map_or("?", |c| c.1)
    }

    /// What the code means.
    pub fn meaning(self) -> &'static str {
        CODES
            .iter()
            .find(|c| c.0 == self.0)
            .map_or("unknown error code", |c| c.2)
    }
}

impl core::fmt::Display for HydErrorCode {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "16#{:04X} {}", self.0, self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_numbers_are_unique_ascending_and_named_as_the_library() {
        for w in CODES.windows(2) {
            assert!(w[0].0 < w[1].0, "{:?} before {:?}", w[0], w[1]);
        }
        assert_eq!(HydErrorCode::SET_VELO.name(), "dwTcHydErrCdSetVelo");
        assert_eq!(HydErrorCode(17241), HydErrorCode::SET_VELO);
        assert_eq!(
            HydErrorCode::ILLEGAL_AREAS.to_string(),
            "16#4FF3 dwTcHydErrIllegalAreas"
        );
        assert_eq!(HydErrorCode(0x1234).name(), "?");
        for c in [
            HydErrorCode::ILLEGAL_VALUE,
            HydErrorCode::SYNTAX,
            HydErrorCode::ACC,
            HydErrorCode::DEC,
            HydErrorCode::REF_VELO,
            HydErrorCode::TBL_ENTRY_COUNT,
            HydErrorCode::TBL_INVALID_MASTER_STEP,
            HydErrorCode::TBL_LINE_COUNT,
        ] {
            assert_ne!(c.name(), "?", "{c:?}");
        }
    }
}
