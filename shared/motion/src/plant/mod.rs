//! The simulated plant and sensors: a drive with its position loop and mechanics ([`drive`]),
//! and the timestamped edges of a mark sensor ([`sensor`]). Objects use these in simulation in
//! place of the real hardware.

pub mod drive;
pub mod mechanics;
pub mod sensor;
