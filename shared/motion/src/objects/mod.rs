//! The technology objects, each stepped once per cycle: the axis with its jobs and synchronous
//! operation ([`axis`]), the external encoder ([`encoder`]), leading values for followers
//! ([`leading`]), output cams ([`output_cam`]), cam tracks ([`cam_track`]), the hydraulic library's
//! digital cam switch ([`digital_cam_switch`]) and measuring inputs
//! ([`measuring`]); the job bookkeeping they share ([`job`]), the run-time parameter tables'
//! mechanism ([`parameter`]) and the command type the runtime applies to them ([`action`]).

pub mod action;
pub mod axis;
pub mod cam_track;
pub mod digital_cam_switch;
pub mod encoder;
pub mod job;
pub mod leading;
pub mod measuring;
pub mod output_cam;
pub mod parameter;
pub mod rejoin;
