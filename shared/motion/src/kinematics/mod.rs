//! Kinematics: the math of motion, below every object. One-degree-of-freedom trajectories
//! ([`profile`]), modulo ranges ([`modulo`]), dynamic limits and their parameter conventions
//! ([`dynamics`]), the motion of an axis over one cycle ([`cycle_motion`]) and the exact
//! crossing math on it ([`crossing`]), the filters and extrapolation of actual-value coupling
//! ([`extrapolation`]) and the fixed-capacity event list of one cycle ([`timed_list`]).

pub mod crossing;
pub mod cycle_motion;
pub mod dynamics;
pub mod extrapolation;
pub mod modulo;
pub mod profile;
pub mod timed_list;
