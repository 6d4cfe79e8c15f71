//! Leading values: what a follower reads of its leader each cycle (design §4).
//!
//! Positions are continuous (unwrapped) so that a modulo wrap is never mistaken for a jump; the
//! modulo settings travel with the value.

use crate::modulo::Modulo;

/// Identifies a leader for the runtime that feeds leading values (an index or a hash the
/// runtime chooses; the engine only compares them).
pub type LeaderId = u32;

/// One leading value: the leader's position, velocity and acceleration for the follower's
/// current cycle.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct LeadingValue {
    /// Position (continuous).
    pub p: f64,
    /// Velocity.
    pub v: f64,
    /// Acceleration.
    pub a: f64,
    /// The leader's modulo settings, if it is a modulo axis.
    pub modulo: Option<Modulo>,
}
