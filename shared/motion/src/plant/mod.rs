//! The machine side of the axes: the CiA 402 drive profile ([`cia402`]) and a simulated servo
//! drive that speaks it ([`servo`]); encoders and mechanics between drive increments and the
//! axis's units ([`mechanics`]); the axis's connection to its drive ([`link`]); the simulated
//! drive model and plant of an axis in simulation ([`drive`]); a simulated proportional valve and
//! differential cylinder ([`hydraulic`]); and the timestamped edges of a mark sensor ([`sensor`]).

pub mod analog;
pub mod analog_word;
pub mod cia402;
pub mod cylinder_error;
pub mod drive;
pub mod hydraulic;
pub mod link;
pub mod mechanics;
pub mod sensor;
pub mod servo;
