//! Slowing down on pressure (Beckhoff TwinCAT PLC Hydraulic Positioning library,
//! `MC_AxCtrlSlowDownOnPressureEx_BkPlcMc`, 4.4.1.5): the axis is braked so that an actual
//! pressure or force does not exceed its set value.
//!
//! The library: "The sign of Setpoint determines the working direction ... it intervenes when
//! Actual approaches the setpoint from below in an ascending direction" (from above for a
//! negative one); "the function block determines the difference between the setpoint and the
//! actual value, taking into account the working direction, and calculates the still
//! permissible velocity with the kP ... If the target velocity exceeds this value, Active goes
//! TRUE and the velocity is limited. When the actual value reaches the setpoint, the still
//! permissible velocity = 0.0 ... If the actual value continues to increase, an opposite
//! movement is only triggered with EnableRelief"; `FeedVelocity` pre-controls the velocity of
//! a moving counterpart. Its prerequisites: the set value recognisably different from 0, the
//! axis displacement-controlled and without an external setpoint generator, and
//! `|Setpoint| · kP` not below the axis' creep velocity.
//!
//! Decided (inferred): the permissible velocity is `kP · (Setpoint − Actual) · sign(Setpoint) +
//! FeedVelocity` (mm/s, so `kP` is in mm/s per bar or per N), floored at 0 without
//! `EnableRelief`; it limits the magnitude of the generator's set velocity in the direction of
//! the running move (the library does not tie the working direction to a direction of motion),
//! and a negative one (relief) reverses it; "recognisably different from 0" is taken as
//! `|Setpoint| · kP` at least the creep velocity, which it implies; the creep velocity is the
//! smaller of the two directions' (refused only where the axis could creep in neither). Pure: no IO, no clock, no allocation.

use super::pressure::{ActualForce, PressureReading};
use crate::catalog::hyd_error::HydErrorCode;
use core::fmt;

/// The inputs of `MC_AxCtrlSlowDownOnPressureEx_BkPlcMc` besides `Enable` (`kP` from its
/// parameter structure `ST_TcPctrlParam`, given with the instruction).
#[derive(Copy, Clone, Debug, PartialEq)]
#[doc(alias = "MC_AxCtrlSlowDownOnPressureEx_BkPlcMc")]
pub struct SlowDownParams {
    /// `EnableRelief`: back off when the actual value is beyond the set value.
    pub enable_relief: bool,
    /// `Setpoint` (bar or N; its sign is the working direction).
    pub set_point: f64,
    /// `kP` (mm/s per bar or per N, > 0): the permissible velocity per unit of margin.
    pub kp: f64,
    /// `FeedVelocity` (mm/s): the velocity of a moving counterpart.
    pub feed_velocity: f64,
    /// The actual value: the differential pressure or the force.
    pub reading: PressureReading,
}

/// A refused input (nothing of it is kept).
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum SlowDownError {
    /// `Setpoint`, `kP` or `FeedVelocity` not finite, or `kP` not above 0.
    Invalid {
        /// The input's name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// `|Setpoint| · kP` below the axis' creep velocity: the axis could not move sensibly.
    BelowCreep {
        /// `|Setpoint| · kP` (mm/s).
        permissible: f64,
        /// The creep velocity (mm/s).
        creep: f64,
    },
}

impl SlowDownError {
    /// The library's error code (`dwTcHydAdsErrIllegalValue`).
    pub fn code(&self) -> HydErrorCode {
        HydErrorCode::ILLEGAL_VALUE
    }
}

impl fmt::Display for SlowDownError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Invalid { name, value } => {
                write!(
                    f,
                    "MC_AxCtrlSlowDownOnPressureEx_BkPlcMc: {name} = {value} is out of its range"
                )
            }
            Self::BelowCreep { permissible, creep } => write!(
                f,
                "MC_AxCtrlSlowDownOnPressureEx_BkPlcMc: |Setpoint| · kP = {permissible} mm/s is \
                 below the creep velocity {creep} mm/s"
            ),
        }
    }
}

impl std::error::Error for SlowDownError {}

/// What the limiter did in a cycle.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct SlowDownStatus {
    /// `Busy`: enabled with its prerequisites met.
    pub busy: bool,
    /// `Active`: it limits the velocity this cycle.
    pub active: bool,
    /// The permissible velocity of this cycle (mm/s; negative: relief).
    pub permissible: f64,
}

impl SlowDownParams {
    /// Checks the inputs against the axis' creep velocity `creep` (mm/s).
    pub fn check(&self, creep: f64) -> Result<(), SlowDownError> {
        for (name, value) in [
            ("Setpoint", self.set_point),
            ("kP", self.kp),
            ("FeedVelocity", self.feed_velocity),
        ] {
            if !value.is_finite() || (name == "kP" && value <= 0.0) {
                return Err(SlowDownError::Invalid { name, value });
            }
        }
        let permissible = self.set_point.abs() * self.kp;
        if permissible < creep {
            return Err(SlowDownError::BelowCreep { permissible, creep });
        }
        Ok(())
    }

    /// The permissible velocity for `actual` (mm/s; floored at 0 without `EnableRelief`).
    pub fn permissible(&self, actual: &ActualForce) -> f64 {
        let margin = (self.set_point - actual.value(self.reading)) * self.set_point.signum();
        let v = self.kp * margin + self.feed_velocity;
        if self.enable_relief {
            v
        } else {
            v.max(0.0)
        }
    }

    /// The limiter's cycle: the status for a set velocity of magnitude `speed` (mm/s) and the
    /// actual pressures `actual`.
    pub fn step(&self, speed: f64, actual: &ActualForce) -> SlowDownStatus {
        let permissible = self.permissible(actual);
        SlowDownStatus {
            busy: true,
            active: speed > permissible,
            permissible,
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    fn force(f: f64) -> ActualForce {
        ActualForce {
            force: f,
            ..ActualForce::default()
        }
    }

    fn params(set_point: f64) -> SlowDownParams {
        SlowDownParams {
            enable_relief: false,
            set_point,
            kp: 0.01,
            feed_velocity: 0.0,
            reading: PressureReading::Force,
        }
    }

    #[test]
    fn the_permissible_velocity_is_kp_times_the_margin_in_the_working_direction() {
        let p = params(10_000.0);
        // 10 kN − 4 kN at 0.01 mm/s per N: 60 mm/s.
        assert!((p.permissible(&force(4_000.0)) - 60.0).abs() < 1e-12);
        assert_eq!(p.permissible(&force(10_000.0)), 0.0);
        // Beyond the set value: 0 without relief, backing off with it.
        assert_eq!(p.permissible(&force(11_000.0)), 0.0);
        let relief = SlowDownParams {
            enable_relief: true,
            ..p
        };
        assert!((relief.permissible(&force(11_000.0)) + 10.0).abs() < 1e-12);
        // A negative set value works from above: −10 kN, actual −4 kN: 60 mm/s.
        assert!((params(-10_000.0).permissible(&force(-4_000.0)) - 60.0).abs() < 1e-12);
        // The counterpart's velocity adds.
        let fed = SlowDownParams {
            feed_velocity: 5.0,
            ..p
        };
        assert!((fed.permissible(&force(10_000.0)) - 5.0).abs() < 1e-12);
        // The pressure reading takes fActPressure.
        let bar = SlowDownParams {
            reading: PressureReading::Pressure,
            kp: 1.0,
            set_point: 50.0,
            ..p
        };
        let a = ActualForce {
            pressure: 20.0,
            force: 1e9,
            ..ActualForce::default()
        };
        assert!((bar.permissible(&a) - 30.0).abs() < 1e-12);
    }

    #[test]
    fn it_is_active_only_when_the_set_velocity_exceeds_the_permissible_one() {
        let p = params(10_000.0);
        let s = p.step(50.0, &force(4_000.0));
        assert_eq!((s.busy, s.active), (true, false));
        let s = p.step(80.0, &force(4_000.0));
        assert_eq!((s.busy, s.active), (true, true));
    }

    #[test]
    fn the_prerequisites_are_checked() {
        assert_eq!(params(10_000.0).check(80.0), Ok(()));
        // 0.01 · 5000 = 50 mm/s below a creep velocity of 80.
        assert_eq!(
            params(5_000.0).check(80.0),
            Err(SlowDownError::BelowCreep {
                permissible: 50.0,
                creep: 80.0
            })
        );
        assert!(matches!(
            params(0.0).check(1.0),
            Err(SlowDownError::BelowCreep { .. })
        ));
        let bad = SlowDownParams {
            kp: 0.0,
            ..params(10_000.0)
        };
        assert_eq!(
            bad.check(0.0),
            Err(SlowDownError::Invalid {
                name: "kP",
                value: 0.0
            })
        );
        let e = SlowDownParams {
            set_point: f64::NAN,
            ..params(1.0)
        }
        .check(0.0)
        .unwrap_err();
        assert!(e.to_string().contains("Setpoint"), "{e}");
        assert_eq!(e.code(), HydErrorCode::ILLEGAL_VALUE);
    }
}
