//! tandem-motion: the pure motion engine of tandem.
//!
//! Profiles (jerk-limited online trajectory generation), the axis technology object with its
//! PLCopen state machine and jobs, monitoring, technology alarms and ErrorIDs, the override
//! tables, and a simulated drive. No IO, no clock, no threads; time is an input. Objects
//! allocate when they are built, never per cycle.
#![cfg_attr(not(test), warn(missing_docs))]

pub mod action;
pub mod alarm;
pub mod axis;
pub mod cam;
pub mod cam_track;
pub mod drive;
pub mod dynamics;
pub mod encoder;
pub mod error_id;
pub mod extrapolation;
pub mod job;
pub mod leading;
pub mod measuring;
pub mod modulo;
pub mod output_cam;
pub mod override_table;
pub mod profile;
pub mod timed_list;
