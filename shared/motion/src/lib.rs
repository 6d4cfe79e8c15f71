//! tandem-motion: the pure motion engine of tandem.
//!
//! Profiles (jerk-limited online trajectory generation), the technology objects of a motion
//! controller with their PLCopen state machines and jobs (axes, encoders, leading values, output
//! cams, cam tracks, measuring inputs), monitoring, technology alarms and ErrorIDs, the override
//! tables, and a simulated drive. No IO, no clock, no threads; time is an input. Objects
//! allocate when they are built, never per cycle.
//!
//! # Layers
//!
//! The modules are grouped in layers; a layer imports only the layers above it in this list:
//!
//! | Layer | Modules | What it holds |
//! |---|---|---|
//! | [`catalog`] | `alarm`, `error_id`, `override_table` | the manuals' alarms, ErrorIDs and override tables, as data |
//! | [`kinematics`] | `profile`, `modulo`, `dynamics`, `cycle_motion`, `crossing`, `extrapolation`, `timed_list` | 1-DoF trajectories, the motion of one cycle and its exact crossing times, filters |
//! | [`cam`] | `cam` | the cam object: a position-to-position law built from points and segments |
//! | [`plant`] | `drive`, `sensor` | the simulated drive and sensors that stand in for the hardware |
//! | [`objects`] | `axis`, `encoder`, `leading`, `rejoin`, `output_cam`, `cam_track`, `measuring`, `job`, `action` | the technology objects, stepped once per cycle, and the command type |
//! | [`hydraulic`] | `generator`, `time_ramp`, `monitor`, `finish`, `valve_table` | the stages of a hydraulic axis of the Beckhoff hydraulic positioning library |
//!
//! The principal types are re-exported here ([`Axis`], [`Profile`], [`Cam`], ...); their home
//! modules are the paths to import.
//!
//! # Example
//!
//! Plan a jerk-limited move, then build an axis, enable it and let it run at a velocity for
//! half a second of 1 ms cycles:
//!
//! ```
//! use tandem_motion::kinematics::dynamics::Dynamics;
//! use tandem_motion::kinematics::profile::{plan_position, Limits, State};
//! use tandem_motion::objects::axis::{
//!     Axis, AxisConfig, AxisState, Command, StartMode, StopMode, VelocityDirection,
//! };
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! // From rest at 0 to 100 at rest: at most 200/s, 1000/s², 10000/s³.
//! let limits = Limits { vel: 200.0, acc: 1000.0, dec: 1000.0, jerk: 10_000.0 };
//! let profile = plan_position(State::default(), 100.0, &limits)?;
//! assert!((profile.end().p - 100.0).abs() < 1e-9);
//!
//! const MS: i64 = 1_000_000;
//! let mut axis = Axis::new(AxisConfig::example(1e-3))?;
//! axis.step(0);
//! axis.command(&Command::Power {
//!     enable: true,
//!     start_mode: StartMode::PositionControlled,
//!     stop_mode: StopMode::Emergency,
//! })?;
//! axis.step(MS);
//! axis.command(&Command::MoveVelocity {
//!     dynamics: Dynamics { velocity: 50.0, ..Dynamics::DEFAULT },
//!     direction: VelocityDirection::Positive,
//!     current: false,
//!     position_controlled: true,
//! })?;
//! for k in 2..500 {
//!     axis.step(k * MS);
//! }
//! assert_eq!(axis.status().state, AxisState::ContinuousMotion);
//! assert!(axis.status().position > 0.0);
//! # Ok(())
//! # }
//! ```
#![cfg_attr(not(test), warn(missing_docs))]

pub mod cam;
pub mod catalog;
pub mod hydraulic;
pub mod kinematics;
pub mod objects;
pub mod plant;

pub use cam::Cam;
pub use kinematics::cycle_motion::AxisMotion;
pub use kinematics::profile::{Limits, Profile, State};
pub use objects::action::Action;
pub use objects::axis::{Axis, AxisConfig, Command};
pub use objects::cam_track::CamTrack;
pub use objects::encoder::ExternalEncoder;
pub use objects::measuring::MeasuringInput;
pub use objects::output_cam::OutputCam;
