//! The coupling law of `MC_FlyingGear_BkPlcMc` (Beckhoff TwinCAT PLC Hydraulic Positioning
//! library, 4.2.6 'MC_FlyingGear_BkPlcMc'): a gear coupling engaged and released on the fly, for
//! press-type work strokes. Everything is a function of the *leader's position* (the library's
//! "master"), not of time: if the leader changes its speed inside a ramp, the follower follows
//! that ('Sample #1', last point).
//!
//! The phases, with `x` the leader position and `y` the follower (the library's "slave"):
//! - [`FlyingPhase::Waiting`]: the follower stands where it was at `Enable`; the leader is
//!   outside the engage section.
//! - [`FlyingPhase::Engaging`] (`StartSync`): the ratio ramps linearly in leader position from 0
//!   to `Ratio` over the engage section, which ends at `MasterSyncPosition`.
//! - [`FlyingPhase::InSync`] (`InSync`, `Active`): exactly geared,
//!   `y = SlaveSyncPosition + s·Ratio·(x − MasterSyncPosition)`, `s` = +1 when leader and
//!   follower work in the same direction, −1 when in opposite ones ('Sample #2').
//! - [`FlyingPhase::Releasing`] (`Active`): once the follower, geared, comes back to
//!   `SlaveDesyncPosition` against its working direction, the ratio ramps linearly from `Ratio`
//!   to 0 until it stands at `SlaveStopPosition`.
//! - [`FlyingPhase::Stopped`]: the follower stands at `SlaveStopPosition` (`Active` fell).
//!
//! inferred: the ramps (the reference gives the numbers of 'Sample #1', not the profile, whose
//! figure is lost) are linear ramps of the *ratio* over leader distance. Only that makes the
//! reference's factor 2 come out ("with a ratio of 1.0, the master has a distance to synchronize
//! of 2.0 · 50 mm"): the follower travels the integral of the ratio, `Ratio · D_leader / 2`, so
//! `D_leader = 2 · D_follower / Ratio`. The follower's position is then a quadratic of the
//! leader position inside a ramp; position and velocity (`ratio · v_leader`) are continuous at
//! both ends of both ramps, the acceleration steps there (by `Ratio·v²/D_leader`).

use core::fmt;

/// The inputs of `MC_FlyingGear_BkPlcMc` other than `Enable` (Beckhoff TwinCAT PLC Hydraulic
/// Positioning library, 4.2.6 'MC_FlyingGear_BkPlcMc', Inputs).
#[doc(alias = "MC_FlyingGear_BkPlcMc")]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct FlyingGearParams {
    /// `Ratio`: the gear ratio when fully coupled (> 0; the sign of the coupling comes from the
    /// working directions).
    #[doc(alias = "Ratio")]
    pub ratio: f64,
    /// `MasterSyncPosition`: the leader position at which the coupling is fully established.
    #[doc(alias = "MasterSyncPosition")]
    pub master_sync_position: f64,
    /// `SlaveSyncPosition`: the follower position at which the coupling is fully established.
    #[doc(alias = "SlaveSyncPosition")]
    pub slave_sync_position: f64,
    /// `SlaveDesyncPosition`: the follower position at which the release starts (on the way
    /// back).
    #[doc(alias = "SlaveDesyncPosition")]
    pub slave_desync_position: f64,
    /// `SlaveStopPosition`: the follower position at which the release is complete.
    #[doc(alias = "SlaveStopPosition")]
    pub slave_stop_position: f64,
    /// `DefaultSlaveNegative`: the follower's working direction when the positions do not tell
    /// it (the follower already at `SlaveSyncPosition` and `SlaveStopPosition` equal to
    /// `SlaveDesyncPosition`).
    #[doc(alias = "DefaultSlaveNegative")]
    pub default_slave_negative: bool,
}

/// Why a flying gear was refused. Refusing changes nothing.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum FlyingGearError {
    /// An input out of its range; `field` is the library's input name.
    Parameter {
        /// The input, e.g. `"Ratio"`.
        field: &'static str,
    },
    /// `SlaveStopPosition` lies beyond `SlaveDesyncPosition` in the follower's working
    /// direction; the release runs against it (the follower goes back).
    StopPositionSide {
        /// The follower's working direction (+1 / −1).
        slave_direction: f64,
    },
    /// The follower was moving at `Enable` (its start position is where it stands).
    SlaveMoving {
        /// Its set velocity.
        velocity: f64,
    },
    /// The leader is already inside (or past) the engage section when the coupling is enabled
    /// ("If the master is below this position when the coupling is enabled, an error is
    /// signaled").
    MasterInsideEngageSection {
        /// The leader position.
        master_position: f64,
        /// Where the engage section starts.
        engage_start: f64,
    },
}

impl fmt::Display for FlyingGearError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::Parameter { field } => write!(f, "MC_FlyingGear_BkPlcMc: {field} out of range"),
            Self::StopPositionSide { slave_direction } => write!(
                f,
                "MC_FlyingGear_BkPlcMc: SlaveStopPosition lies beyond SlaveDesyncPosition in the \
                 slave's working direction ({slave_direction:+}); the release runs against it"
            ),
            Self::SlaveMoving { velocity } => write!(
                f,
                "MC_FlyingGear_BkPlcMc: the slave moves ({velocity}) when enabled"
            ),
            Self::MasterInsideEngageSection {
                master_position,
                engage_start,
            } => write!(
                f,
                "MC_FlyingGear_BkPlcMc: the master ({master_position}) is already past the start \
                 of the engage section ({engage_start})"
            ),
        }
    }
}

impl std::error::Error for FlyingGearError {}

impl FlyingGearParams {
    /// The checks that need no position: every position finite, `Ratio` finite and > 0.
    pub fn check(&self) -> Result<(), FlyingGearError> {
        let bad = |field| Err(FlyingGearError::Parameter { field });
        if !(self.ratio.is_finite() && self.ratio > 0.0) {
            return bad("Ratio");
        }
        for (v, field) in [
            (self.master_sync_position, "MasterSyncPosition"),
            (self.slave_sync_position, "SlaveSyncPosition"),
            (self.slave_desync_position, "SlaveDesyncPosition"),
            (self.slave_stop_position, "SlaveStopPosition"),
        ] {
            if !v.is_finite() {
                return bad(field);
            }
        }
        Ok(())
    }
}

/// Where the flying gear is (the library's outputs follow from it).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum FlyingPhase {
    /// Enabled, the leader not yet seen (the follower stands).
    Armed,
    /// The follower stands at its start; the leader is outside the engage section.
    Waiting,
    /// The ratio ramps up with the leader position (`StartSync`).
    Engaging,
    /// Fully coupled (`InSync`, `Active`).
    InSync,
    /// The ratio ramps down with the leader position (`Active`).
    Releasing,
    /// The follower stands at `SlaveStopPosition` (`Active` fell); the job is over until the
    /// next rising `Enable`.
    Stopped,
}

impl FlyingPhase {
    /// `StartSync`: the leader is inside the section that establishes the coupling.
    #[doc(alias = "StartSync")]
    pub fn start_sync(self) -> bool {
        self == Self::Engaging
    }

    /// `InSync`: the coupling is fully active.
    #[doc(alias = "InSync")]
    pub fn in_sync(self) -> bool {
        self == Self::InSync
    }

    /// `Active`: from the leader passing `MasterSyncPosition` in the working direction until
    /// the follower reaches `SlaveStopPosition` on its way back.
    #[doc(alias = "Active")]
    pub fn active(self) -> bool {
        matches!(self, Self::InSync | Self::Releasing)
    }
}

/// The follower at one leader position: its position and the first and second derivative of
/// its position with respect to the leader position (velocity = `slope · v_leader`,
/// acceleration = `curvature · v_leader² + slope · a_leader`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct FlyingPoint {
    /// Follower position.
    pub position: f64,
    /// dy/dx: the instantaneous ratio, signed.
    pub slope: f64,
    /// d²y/dx².
    pub curvature: f64,
    /// The phase after this leader position.
    pub phase: FlyingPhase,
}

/// `MC_FlyingGear_BkPlcMc` as a law of the leader position: built at the rising `Enable` from
/// the inputs and the follower's position, started with the first leader position, then stepped
/// with each leader position. Pure: no allocation, no clock.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct FlyingGear {
    p: FlyingGearParams,
    /// Where the follower stood at `Enable`.
    slave_start: f64,
    /// Follower working direction (+1 / −1).
    dir_s: f64,
    /// Leader working direction (+1 / −1), fixed by [`FlyingGear::start`].
    dir_m: f64,
    /// Leader distance of the engage ramp (`2 · |SlaveSyncPosition − start| / Ratio`).
    engage_len: f64,
    /// Leader distance of the release ramp (`2 · |SlaveStopPosition − SlaveDesyncPosition| /
    /// Ratio`).
    release_len: f64,
    /// Leader position at which the geared follower is at `SlaveDesyncPosition`.
    master_desync: f64,
    /// The geared follower has been at or beyond `SlaveDesyncPosition` in its working direction
    /// (the release starts only on the way back from there; inferred: the reference names the
    /// position, not the crossing, and a follower geared past it on the way down must not
    /// release there).
    armed: bool,
    phase: FlyingPhase,
}

impl FlyingGear {
    /// The flying gear for a follower standing at `slave_position`. The follower's working
    /// direction is the direction from there to `SlaveSyncPosition`; if they coincide, the
    /// direction opposite to the release (`SlaveDesyncPosition` → `SlaveStopPosition`); if that
    /// is empty too, `DefaultSlaveNegative` (inferred: the reference says only that the tie-break
    /// applies "in some cases"). The release must run against the working direction
    /// ('MC_FlyingGear_BkPlcMc', output Active: "FALSE when the SlaveStopPosition is reached in
    /// the opposite direction").
    pub fn new(p: FlyingGearParams, slave_position: f64) -> Result<Self, FlyingGearError> {
        p.check()?;
        if !slave_position.is_finite() {
            return Err(FlyingGearError::Parameter {
                field: "Slave.ActualPosition",
            });
        }
        let engage = p.slave_sync_position - slave_position;
        let release = p.slave_stop_position - p.slave_desync_position;
        let dir_s = if engage != 0.0 {
            engage.signum()
        } else if release != 0.0 {
            -release.signum()
        } else if p.default_slave_negative {
            -1.0
        } else {
            1.0
        };
        if release * dir_s > 0.0 {
            return Err(FlyingGearError::StopPositionSide {
                slave_direction: dir_s,
            });
        }
        Ok(Self {
            p,
            slave_start: slave_position,
            dir_s,
            dir_m: 0.0,
            engage_len: 2.0 * engage.abs() / p.ratio,
            release_len: 2.0 * release.abs() / p.ratio,
            master_desync: 0.0,
            armed: false,
            phase: FlyingPhase::Armed,
        })
    }

    /// The first leader position: fixes the leader's working direction (towards
    /// `MasterSyncPosition`) and refuses a leader already past the start of the engage section.
    /// Once started, a further call changes nothing.
    pub fn start(&mut self, master_position: f64) -> Result<(), FlyingGearError> {
        if self.phase != FlyingPhase::Armed {
            return Ok(());
        }
        // inferred: the master's working direction is towards MasterSyncPosition from where it
        // is when the coupling starts (the reference deduces it "from the transferred
        // parameters" and gives the error for a master already past the engage start).
        let to_sync = self.p.master_sync_position - master_position;
        let engage_start = self.engage_start_for(to_sync.signum());
        // At the sync position the direction is unknown: that leader is inside the section.
        if !(to_sync != 0.0 && to_sync.abs() >= self.engage_len) {
            return Err(FlyingGearError::MasterInsideEngageSection {
                master_position,
                engage_start,
            });
        }
        self.dir_m = to_sync.signum();
        let s = self.dir_s * self.dir_m;
        self.master_desync = self.p.master_sync_position
            + (self.p.slave_desync_position - self.p.slave_sync_position) / (s * self.p.ratio);
        self.phase = FlyingPhase::Waiting;
        Ok(())
    }

    fn engage_start_for(&self, dir_m: f64) -> f64 {
        self.p.master_sync_position - dir_m * self.engage_len
    }

    /// Where the engage section starts (leader position; valid once started).
    pub fn engage_start(&self) -> f64 {
        self.engage_start_for(self.dir_m)
    }

    /// Where the release ends (leader position; valid once started).
    pub fn release_end(&self) -> f64 {
        self.master_desync - self.dir_m * self.release_len
    }

    /// The leader position at which the release starts (valid once started).
    pub fn release_start(&self) -> f64 {
        self.master_desync
    }

    /// The phase.
    pub fn phase(&self) -> FlyingPhase {
        self.phase
    }

    /// Where the follower stood at `Enable`.
    pub fn slave_start(&self) -> f64 {
        self.slave_start
    }

    /// The inputs.
    pub fn params(&self) -> &FlyingGearParams {
        &self.p
    }

    /// The follower's coordinates moved by `delta` (homing): the law moves with them.
    pub fn shift_follower(&mut self, delta: f64) {
        self.slave_start += delta;
        self.p.slave_sync_position += delta;
        self.p.slave_desync_position += delta;
        self.p.slave_stop_position += delta;
    }

    /// The follower at leader position `x`: the phase moves on (a jump of the leader may cross
    /// several phases in one step), then the law of the phase is evaluated. Before
    /// [`FlyingGear::start`] the follower stands at its start.
    pub fn step(&mut self, x: f64) -> FlyingPoint {
        // Leader distance still to go to MasterSyncPosition (the engage ramp is 0..engage_len),
        // and leader distance past the release start on the way back (0..release_len).
        let d = self.dir_m * (self.p.master_sync_position - x);
        let e = -self.dir_m * (x - self.master_desync);
        for _ in 0..5 {
            let next = match self.phase {
                FlyingPhase::Waiting if d <= self.engage_len => FlyingPhase::Engaging,
                FlyingPhase::Engaging if d > self.engage_len => FlyingPhase::Waiting,
                FlyingPhase::Engaging if d <= 0.0 => FlyingPhase::InSync,
                FlyingPhase::InSync => {
                    if e <= 0.0 {
                        self.armed = true;
                    }
                    if self.armed && e > 0.0 {
                        FlyingPhase::Releasing
                    } else {
                        break;
                    }
                }
                FlyingPhase::Releasing if e < 0.0 => FlyingPhase::InSync,
                FlyingPhase::Releasing if e >= self.release_len => FlyingPhase::Stopped,
                _ => break,
            };
            self.phase = next;
        }
        self.eval(x, d, e)
    }

    /// The law of the current phase at leader position `x` (`d`, `e` as in [`FlyingGear::step`]).
    fn eval(&self, x: f64, d: f64, e: f64) -> FlyingPoint {
        let r = self.p.ratio;
        let s = self.dir_s * self.dir_m;
        let point = |position, slope, curvature| FlyingPoint {
            position,
            slope,
            curvature,
            phase: self.phase,
        };
        match self.phase {
            FlyingPhase::Armed | FlyingPhase::Waiting => point(self.slave_start, 0.0, 0.0),
            // ratio(d) = R·(1 − d/L); the follower is short of SlaveSyncPosition by the
            // integral of it from 0 to d: R·(d − d²/2L).
            FlyingPhase::Engaging => {
                let l = self.engage_len;
                let short = r * (d - d * d / (2.0 * l));
                point(
                    self.p.slave_sync_position - self.dir_s * short,
                    s * r * (1.0 - d / l),
                    s * r * self.dir_m / l,
                )
            }
            FlyingPhase::InSync => point(
                self.p.slave_sync_position + s * r * (x - self.p.master_sync_position),
                s * r,
                0.0,
            ),
            // ratio(e) = R·(1 − e/L); the follower has gone back from SlaveDesyncPosition by
            // R·(e − e²/2L).
            FlyingPhase::Releasing => {
                let l = self.release_len;
                let back = r * (e - e * e / (2.0 * l));
                point(
                    self.p.slave_desync_position - self.dir_s * back,
                    s * r * (1.0 - e / l),
                    s * r * self.dir_m / l,
                )
            }
            // inferred: the stroke is over; the reference's 'Sample #3' returns the slave with
            // its own command after the function block is deactivated.
            FlyingPhase::Stopped => point(self.p.slave_stop_position, 0.0, 0.0),
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn sample1() -> FlyingGearParams {
        FlyingGearParams {
            ratio: 1.0,
            master_sync_position: 460.0,
            slave_sync_position: 450.0,
            slave_desync_position: 450.0,
            slave_stop_position: 500.0,
            default_slave_negative: false,
        }
    }

    #[test]
    fn sample_1_section_ends() {
        let mut g = FlyingGear::new(sample1(), 500.0).unwrap();
        assert_eq!(g.start(800.0), Ok(()));
        assert_eq!(g.engage_start(), 560.0);
        assert_eq!(g.release_start(), 460.0);
        assert_eq!(g.release_end(), 560.0);
        assert_eq!(g.step(560.0).position, 500.0);
        assert_eq!(g.step(460.0).position, 450.0);
        assert_eq!(g.phase(), FlyingPhase::InSync);
    }
}
