//! Dynamic limits, defaults and the parameter conventions of the references (S7-1500T Motion
//! Control V4.0 function manual, 6.3 'Motion Control instructions', 3.2.8 'Motion control and
//! limits for dynamics'): a negative value means "use the default", zero is rejected (except jerk 0
//! = trapezoidal and velocity 0 for velocity and jog jobs), a value above the limit is clamped and
//! reported as a warning (alarms 501, 502, 503).

use crate::catalog::error_id::ErrorId;
use crate::kinematics::profile::Limits;

/// `<TO>.DynamicLimits` (all > 0).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct DynamicLimits {
    /// `MaxVelocity`.
    pub max_velocity: f64,
    /// `MaxAcceleration`.
    pub max_acceleration: f64,
    /// `MaxDeceleration`.
    pub max_deceleration: f64,
    /// `MaxJerk`.
    pub max_jerk: f64,
}

/// `<TO>.DynamicDefaults`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct DynamicDefaults {
    /// `Velocity`.
    pub velocity: f64,
    /// `Acceleration`.
    pub acceleration: f64,
    /// `Deceleration`.
    pub deceleration: f64,
    /// `Jerk` (0 = trapezoidal).
    pub jerk: f64,
    /// `EmergencyDeceleration` (used without jerk limit; may exceed MaxDeceleration).
    pub emergency_deceleration: f64,
}

/// The dynamic inputs of a motion instruction, as given (negative = default).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Dynamics {
    /// `Velocity`.
    pub velocity: f64,
    /// `Acceleration`.
    pub acceleration: f64,
    /// `Deceleration`.
    pub deceleration: f64,
    /// `Jerk`.
    pub jerk: f64,
}

impl Dynamics {
    /// All defaults (`-1.0`), as an instruction's default inputs.
    pub const DEFAULT: Dynamics = Dynamics {
        velocity: -1.0,
        acceleration: -1.0,
        deceleration: -1.0,
        jerk: -1.0,
    };
}

impl Default for Dynamics {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Which values were clamped to their limit (each one is a warning alarm).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct Clamped {
    /// Velocity clamped (alarm 501).
    pub velocity: bool,
    /// Acceleration or deceleration clamped (alarm 502).
    pub acceleration: bool,
    /// Jerk clamped (alarm 503).
    pub jerk: bool,
}

impl Clamped {
    /// Any value clamped.
    pub fn any(&self) -> bool {
        self.velocity || self.acceleration || self.jerk
    }
}

/// Dynamics resolved against defaults and limits.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Resolved {
    /// The limits for the profile generator. `vel` is `0.0` only for velocity jobs with
    /// `Velocity = 0` (which the caller then plans as a stop).
    pub limits: Limits,
    /// Values clamped to the axis limits.
    pub clamped: Clamped,
}

fn pick(
    given: f64,
    default: f64,
    limit: f64,
    zero_ok: bool,
    err: ErrorId,
) -> Result<(f64, bool), ErrorId> {
    if !given.is_finite() {
        return Err(err);
    }
    let v = if given < 0.0 { default } else { given };
    if v == 0.0 && !zero_ok {
        return Err(err);
    }
    if v > limit {
        Ok((limit, true))
    } else {
        Ok((v, false))
    }
}

impl DynamicLimits {
    /// Profile limits with the maximum dynamics (reaction "stop with maximum dynamics").
    pub fn as_limits(&self) -> Limits {
        Limits {
            vel: self.max_velocity,
            acc: self.max_acceleration,
            dec: self.max_deceleration,
            jerk: self.max_jerk,
        }
    }

    /// Resolves a job's dynamics. `velocity_zero_ok` is set for MoveVelocity and MoveJog.
    pub fn resolve(
        &self,
        defaults: &DynamicDefaults,
        d: &Dynamics,
        velocity_zero_ok: bool,
    ) -> Result<Resolved, ErrorId> {
        let (vel, cv) = pick(
            d.velocity,
            defaults.velocity,
            self.max_velocity,
            velocity_zero_ok,
            ErrorId::IllegalVelocity,
        )?;
        let (acc, ca) = pick(
            d.acceleration,
            defaults.acceleration,
            self.max_acceleration,
            false,
            ErrorId::IllegalAcceleration,
        )?;
        let (dec, cd) = pick(
            d.deceleration,
            defaults.deceleration,
            self.max_deceleration,
            false,
            ErrorId::IllegalDeceleration,
        )?;
        let (jerk, cj) = pick(
            d.jerk,
            defaults.jerk,
            self.max_jerk,
            true,
            ErrorId::IllegalJerk,
        )?;
        Ok(Resolved {
            limits: Limits {
                vel,
                acc,
                dec,
                jerk,
            },
            clamped: Clamped {
                velocity: cv,
                acceleration: ca || cd,
                jerk: cj,
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIM: DynamicLimits = DynamicLimits {
        max_velocity: 100.0,
        max_acceleration: 1000.0,
        max_deceleration: 800.0,
        max_jerk: 10000.0,
    };
    const DEF: DynamicDefaults = DynamicDefaults {
        velocity: 50.0,
        acceleration: 500.0,
        deceleration: 400.0,
        jerk: 5000.0,
        emergency_deceleration: 2000.0,
    };

    #[test]
    fn sentinels() {
        let r = LIM.resolve(&DEF, &Dynamics::DEFAULT, false).unwrap();
        assert_eq!(
            r.limits,
            Limits {
                vel: 50.0,
                acc: 500.0,
                dec: 400.0,
                jerk: 5000.0
            }
        );
        assert!(!r.clamped.any());
        let zero_v = Dynamics {
            velocity: 0.0,
            ..Dynamics::DEFAULT
        };
        assert_eq!(
            LIM.resolve(&DEF, &zero_v, false),
            Err(ErrorId::IllegalVelocity)
        );
        assert_eq!(LIM.resolve(&DEF, &zero_v, true).unwrap().limits.vel, 0.0);
        let zero_a = Dynamics {
            acceleration: 0.0,
            ..Dynamics::DEFAULT
        };
        assert_eq!(
            LIM.resolve(&DEF, &zero_a, false),
            Err(ErrorId::IllegalAcceleration)
        );
        let zero_d = Dynamics {
            deceleration: 0.0,
            ..Dynamics::DEFAULT
        };
        assert_eq!(
            LIM.resolve(&DEF, &zero_d, false),
            Err(ErrorId::IllegalDeceleration)
        );
        let zero_j = Dynamics {
            jerk: 0.0,
            ..Dynamics::DEFAULT
        };
        assert_eq!(LIM.resolve(&DEF, &zero_j, false).unwrap().limits.jerk, 0.0);
        let nan = Dynamics {
            jerk: f64::NAN,
            ..Dynamics::DEFAULT
        };
        assert_eq!(LIM.resolve(&DEF, &nan, false), Err(ErrorId::IllegalJerk));
    }

    #[test]
    fn clamps_with_warning() {
        let d = Dynamics {
            velocity: 150.0,
            acceleration: 2000.0,
            deceleration: 100.0,
            jerk: 1e6,
        };
        let r = LIM.resolve(&DEF, &d, false).unwrap();
        assert_eq!(
            r.limits,
            Limits {
                vel: 100.0,
                acc: 1000.0,
                dec: 100.0,
                jerk: 10000.0
            }
        );
        assert_eq!(
            r.clamped,
            Clamped {
                velocity: true,
                acceleration: true,
                jerk: true
            }
        );
    }
}
