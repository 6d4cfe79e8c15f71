//! The runtime's errors: a configuration the engine refuses ([`ExecError`]) and a failed
//! simulation ([`SimError`]).

use std::fmt;
use std::io;
use tandem_motion::catalog::error_id::ErrorId;

/// A technology object whose configuration the engine refuses, when an
/// [`Executive`](crate::exec::Executive) is created: which object, and the engine's reason.
#[derive(Clone, Debug, PartialEq)]
pub enum ExecError {
    /// An axis.
    Axis {
        /// Its name.
        name: String,
        /// The engine's reason.
        reason: tandem_motion::objects::axis::AxisConfigError,
    },
    /// An external encoder.
    Encoder {
        /// Its name.
        name: String,
        /// The ErrorID that refused it.
        reason: ErrorId,
    },
    /// An output cam, cam track or measuring input.
    Object {
        /// The kind of object (`output cam`, `cam track`, `measuring input`).
        kind: &'static str,
        /// Its name.
        name: String,
        /// The engine's reason.
        reason: tandem_motion::objects::measuring::MeasuringConfigError,
    },
    /// A digital cam switch whose switch or track set the engine refuses.
    CamSwitch {
        /// Its name.
        name: String,
        /// The engine's reason.
        reason: tandem_motion::objects::digital_cam_switch::DcsError,
    },
    /// A simulated device whose parameters the model refuses.
    Device {
        /// Its name.
        name: String,
        /// The model's reason.
        reason: tandem_motion::plant::servo::ServoParamsError,
    },
    /// A drive's enable timeout that is not positive.
    EnableTimeout(tandem_motion::plant::cia402::InvalidEnableTimeout),
    /// An analog drive, or an axis's connection to one, whose parameters the model refuses.
    AnalogDrive {
        /// The device's name.
        name: String,
        /// The model's reason.
        reason: tandem_motion::plant::analog::AnalogConnectionError,
    },
}

impl fmt::Display for ExecError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ExecError::Axis { name, reason } => write!(f, "axis {name}: {reason}"),
            ExecError::Encoder { name, reason } => write!(f, "encoder {name}: {reason}"),
            ExecError::Object { kind, name, reason } => write!(f, "{kind} {name}: {reason}"),
            ExecError::CamSwitch { name, reason } => {
                write!(f, "digital cam switch {name}: {reason}")
            }
            ExecError::Device { name, reason } => write!(f, "device {name}: {reason}"),
            ExecError::EnableTimeout(e) => write!(f, "{e}"),
            ExecError::AnalogDrive { name, reason } => write!(f, "device {name}: {reason}"),
        }
    }
}

impl std::error::Error for ExecError {}

/// Why a simulation stopped: the cell was refused, or the trace or log could not be written.
#[derive(Debug)]
pub enum SimError {
    /// The engine refused the cell's configuration.
    Exec(ExecError),
    /// Writing the trace or the log failed.
    Io(io::Error),
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimError::Exec(e) => fmt::Display::fmt(e, f),
            SimError::Io(e) => fmt::Display::fmt(e, f),
        }
    }
}

impl std::error::Error for SimError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            SimError::Exec(e) => Some(e),
            SimError::Io(e) => Some(e),
        }
    }
}

impl From<io::Error> for SimError {
    fn from(e: io::Error) -> Self {
        SimError::Io(e)
    }
}

impl From<ExecError> for SimError {
    fn from(e: ExecError) -> Self {
        SimError::Exec(e)
    }
}
