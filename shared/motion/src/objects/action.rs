//! The instruction for one technology object, as the runtime applies it.

use crate::objects::axis::{CamId, Command};

/// What an instruction does to a technology object: an axis or encoder command, or one of the
/// instructions of the cam, output cam, cam track and measuring input objects. Script files,
/// the CLI and the command services parse into it; the runtime applies it.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Action {
    /// An instruction for an axis or an external encoder.
    Command(Command),
    /// `MC_InterpolateCam`: interpolate the cam `cam` again from the definition of the cam
    /// `from` (itself by default); refused while a job uses the cam (16#80AB).
    InterpolateCam {
        /// The cam replaced.
        cam: CamId,
        /// The cam whose definition is interpolated.
        from: CamId,
    },
    /// `MC_OutputCam` on the output cam named by the entry (Enable-type: the inputs hold until
    /// a later entry changes them). Codes are checked when applied (16#800A, 16#8007...).
    OutputCam {
        /// `Enable`.
        enable: bool,
        /// `OnPosition`.
        on_position: f64,
        /// `OffPosition`.
        off_position: f64,
        /// `Duration` (s).
        duration: f64,
        /// `Mode` (1, 2, 3).
        mode: i32,
        /// `Direction` (1, 2, 3).
        direction: i32,
    },
    /// `MC_Reset` on the output cam, cam track or measuring input named by the entry:
    /// acknowledges its alarms; `Restart` also clears a measuring input's data block.
    ResetObject {
        /// `Restart`.
        restart: bool,
    },
    /// `MC_CamTrack` on the cam track named by the entry (Enable-type).
    CamTrack {
        /// `Enable`.
        enable: bool,
        /// `Mode` (0, 1, 2).
        mode: i32,
        /// `InvertOutput`.
        invert_output: bool,
    },
    /// `MC_DigitalCamSwitch_BkPlcMc` on the digital cam switch named by the entry
    /// (level-type: the inputs hold until a later entry changes them).
    DigitalCamSwitch {
        /// `Enable`.
        enable: bool,
        /// `EnableMask`: bit `n - 1` lets track `n` through.
        enable_mask: u32,
    },
    /// `MC_MeasuringInput` (one-time) or `MC_MeasuringInputCyclic` on the measuring input
    /// named by the entry.
    MeasuringInput {
        /// Cyclic measuring.
        cyclic: bool,
        /// `Mode`.
        mode: i32,
        /// `MeasuringRange`: `(StartPosition, EndPosition)`.
        window: Option<(f64, f64)>,
    },
    /// `MC_AbortMeasuringInput` on the measuring input named by the entry.
    AbortMeasuringInput,
    /// An edge of the measuring input named by the entry, at the entry's time exactly.
    InputEdge {
        /// Rising (true) or falling edge.
        rising: bool,
    },
    /// A fault of the simulated drive named by the entry, with its CiA 402 error code (0x603F),
    /// from the entry's time; code 0 removes the cause again.
    DriveFault {
        /// The error code, or 0.
        code: u16,
    },
    /// The mechanical stops of the simulated servo named by the entry moved to `min` / `max`
    /// (positions of its axis's load; `None`: no stop there, e.g. the stop gave way), from the
    /// entry's time.
    FixedStop {
        /// The stop below the load, if any.
        min: Option<f64>,
        /// The stop above the load, if any.
        max: Option<f64>,
    },
    /// The simulated input signal named by the entry set to `value` at the entry's time
    /// exactly; with `pulse_ns > 0`, back to `!value` that long after.
    SetInput {
        /// The level from the entry's time.
        value: bool,
        /// Length of the pulse (ns); 0: the level stays.
        pulse_ns: i64,
    },
    /// The simulated `integer` or `float` input signal named by the entry set to `value` from
    /// the entry's time (a whole number for an integer; a float in its channel's units).
    SetInputValue {
        /// The value from the entry's time.
        value: f64,
    },
    /// The `float` output signal named by the entry set to `value` (its channel's units, V)
    /// from the entry's time: the terminal drives the value as its channel quantizes it.
    SetOutputValue {
        /// The value from the entry's time.
        value: f64,
    },
}
