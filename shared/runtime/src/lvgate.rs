//! The plausibility gate of a leader's samples (docs/processes.md, "Leading values", "Refused
//! samples"): what a follower's node checks of every sample it receives before the sample may
//! enter the leader's buffer.
//!
//! A sample is refused, counted by kind and changes nothing when
//! - a value is NaN or infinite ([`Refused::NotFinite`]);
//! - its time lies after the receiver's clock by more than one leader cycle plus the leader's
//!   tolerance ([`Refused::Future`]): a sample can only be for a cycle the leader has run;
//! - its time lies before the oldest time the buffer keeps, `now - LEADING_BUFFER` leader
//!   cycles ([`Refused::Stale`]);
//! - its sequence number is not its time in leader cycles (`seq * cycle == t_ns`), or not
//!   after the last accepted one ([`Refused::Sequence`]): the publisher numbers its samples by
//!   the cycle on the cell clock, so the numbers go on increasing across its restarts and a
//!   forged number cannot lie beyond the time window;
//! - its motion is not reachable from the last accepted sample within the leader's dynamic
//!   limits ([`Refused::Jump`]): velocity beyond `MaxVelocity`, position beyond what that
//!   velocity covers in the time between, velocity change beyond the acceleration limit, and
//!   (setpoint coupling) position off the kinematics: `|p_b - p_a - v_a·Δt| > amax·Δt²/2`.
//!
//! No sample can lock the gate: the window follows the receiver's clock, and a leader that
//! really jumped (homed with a new position, restarted at another position) is followed again
//! once no valid sample was accepted for longer than one leader cycle plus the delay D plus
//! the tolerance on the receiver's clock (its followers have stopped with 601 by then),
//! [`Verdict::Reanchored`]. While the
//! real samples flow, no forged jump is ever accepted; right after an outage, the first
//! plausible sample becomes the reference whoever sent it (only the leader's host may publish
//! on the leader's key: the access control of the Zenoh sessions, docs/gateway.md).
//! Pure: no IO, no clock (the time is an input), no allocation.

use tandem_config::{Cell, Coupling, Leader, LEADING_BUFFER};
use tandem_motion::objects::leading::LeadingSample;

/// Slack on the leader's dynamic limits for its setpoint (inferred: rounding of the profile
/// generator and a velocity override settle within 5 %).
pub const SETPOINT_SLACK: f64 = 1.05;

/// Slack on the leader's dynamic limits for its actual value (inferred: the filtered actual
/// velocity of a drive overshoots its setpoint by a following error; twice the limit keeps
/// noise out of the refusals while a forged jump of a revolution in a cycle is still refused).
pub const ACTUAL_SLACK: f64 = 2.0;

/// Absolute slack on positions and velocities (rounding of `f64` at large positions).
const EPS: f64 = 1e-9;

/// What the gate knows of one leader.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct GateConfig {
    /// The leader's cycle (ns, > 0): sequence numbers count these.
    pub cycle_ns: i64,
    /// How far after the receiver's clock a sample may lie (ns): one leader cycle plus the
    /// leader's leading-value tolerance (the clock offset between hosts stays within it).
    pub ahead_ns: i64,
    /// How far before the receiver's clock a sample may lie (ns): the buffer's span.
    pub behind_ns: i64,
    /// Largest plausible velocity (`MaxVelocity` times the slack; infinite for an external
    /// encoder, which has no dynamic limits).
    pub max_velocity: f64,
    /// Largest plausible change of velocity per second (the largest of `MaxAcceleration`,
    /// `MaxDeceleration` and the emergency deceleration, times the slack; infinite: unchecked).
    pub max_acceleration: f64,
    /// How long after the last accepted valid sample, on the receiver's clock (ns), a sample
    /// not reachable from it becomes the new reference: the leader's cycle plus its delay D
    /// plus its tolerance, when every follower reading `t - D` has bridged the tolerance and
    /// stopped with 601 ([`gate_config`]; [`GateConfig::new`] knows no D and takes one cycle
    /// plus the tolerance).
    pub reanchor_ns: i64,
    /// Check the position against the kinematics (setpoint coupling): with `|a| <= amax`
    /// between two samples, `|p_b - p_a - v_a·Δt| <= amax·Δt²/2`. Off for an actual value,
    /// whose filtered position and velocity need not agree so closely.
    pub kinematic: bool,
}

impl GateConfig {
    /// The gate of a leader with cycle `cycle_ns`, tolerance `tolerance_ns`, a buffer of
    /// `buffer` samples and the limits given (already with their slack).
    pub fn new(
        cycle_ns: i64,
        tolerance_ns: i64,
        buffer: usize,
        max_velocity: f64,
        max_acceleration: f64,
    ) -> Self {
        let cycle_ns = cycle_ns.max(1);
        let n = i64::try_from(buffer).unwrap_or(i64::MAX);
        Self {
            cycle_ns,
            ahead_ns: cycle_ns.saturating_add(tolerance_ns.max(0)),
            behind_ns: cycle_ns.saturating_mul(n),
            max_velocity,
            max_acceleration,
            reanchor_ns: cycle_ns.saturating_add(tolerance_ns.max(0)),
            kinematic: true,
        }
    }
}

/// The gate of `leader` (read in `coupling`) at a follower of cell `cell`: its node's cycle,
/// its tolerance, the buffer's span ([`LEADING_BUFFER`]) and, for an axis, its dynamic limits
/// with [`SETPOINT_SLACK`] or [`ACTUAL_SLACK`] (an external encoder has none: unchecked).
pub fn gate_config(cell: &Cell, leader: Leader, coupling: Coupling) -> GateConfig {
    let (v, a) = match leader {
        Leader::Axis(i) => cell.axis(i).map_or((f64::INFINITY, f64::INFINITY), |x| {
            let l = &x.config.limits;
            let slack = match coupling {
                Coupling::Setpoint => SETPOINT_SLACK,
                Coupling::Actual => ACTUAL_SLACK,
            };
            let acc = l
                .max_acceleration
                .max(l.max_deceleration)
                .max(x.config.defaults.emergency_deceleration);
            (l.max_velocity * slack, acc * slack)
        }),
        Leader::Encoder(_) => (f64::INFINITY, f64::INFINITY),
    };
    let lv = cell.leading(leader);
    let g = GateConfig::new(
        cell.leader_cycle_ns(leader),
        lv.tolerance_ns,
        LEADING_BUFFER,
        v,
        a,
    );
    GateConfig {
        kinematic: coupling == Coupling::Setpoint,
        reanchor_ns: g.reanchor_ns.saturating_add(lv.delay_ns.max(0)),
        ..g
    }
}

/// Why the gate refused a sample.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Refused {
    /// Position, velocity or acceleration is NaN or infinite.
    NotFinite,
    /// The sample's time lies after the receiver's clock by more than the window allows.
    Future {
        /// The sample's time (ns).
        t_ns: i64,
        /// The latest time accepted now (ns).
        latest_ns: i64,
    },
    /// The sample's time lies before the oldest time the buffer keeps.
    Stale {
        /// The sample's time (ns).
        t_ns: i64,
        /// The oldest time accepted now (ns).
        oldest_ns: i64,
    },
    /// The sequence number does not match the time, or is not after the last accepted one.
    Sequence {
        /// The sample's sequence number.
        seq: u64,
        /// The last accepted sequence number (0 before the first).
        last: u64,
    },
    /// The motion is not reachable from the last accepted sample within the dynamic limits.
    Jump {
        /// The sample's sequence number.
        seq: u64,
    },
}

impl core::fmt::Display for Refused {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::NotFinite => write!(f, "a value is not finite"),
            Self::Future { t_ns, latest_ns } => write!(
                f,
                "time {t_ns} ns lies after the latest plausible time {latest_ns} ns"
            ),
            Self::Stale { t_ns, oldest_ns } => write!(
                f,
                "time {t_ns} ns lies before the oldest time kept {oldest_ns} ns"
            ),
            Self::Sequence { seq, last } => write!(
                f,
                "sequence number {seq} does not match its time or is not after {last}"
            ),
            Self::Jump { seq } => write!(
                f,
                "sample {seq} is not reachable within the leader's dynamic limits"
            ),
        }
    }
}

impl std::error::Error for Refused {}

/// A sample the gate let through.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Plausible: into the buffer.
    Accepted,
    /// Not reachable from the reference, but after an outage longer than the leader's cycle,
    /// D and the tolerance ([`GateConfig::reanchor_ns`]): into the
    /// buffer, the new reference.
    Reanchored,
}

/// Refusals by kind ([`Refused`]) and re-anchorings of one gate.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct GateCounts {
    /// [`Refused::NotFinite`].
    pub not_finite: u64,
    /// [`Refused::Future`].
    pub future: u64,
    /// [`Refused::Stale`].
    pub stale: u64,
    /// [`Refused::Sequence`].
    pub sequence: u64,
    /// [`Refused::Jump`].
    pub jump: u64,
    /// [`Verdict::Reanchored`].
    pub reanchored: u64,
}

impl GateCounts {
    /// Every refusal.
    pub fn refused(&self) -> u64 {
        self.not_finite + self.future + self.stale + self.sequence + self.jump
    }

    /// Adds `other`'s counts.
    pub fn add(&mut self, other: &GateCounts) {
        self.not_finite += other.not_finite;
        self.future += other.future;
        self.stale += other.stale;
        self.sequence += other.sequence;
        self.jump += other.jump;
        self.reanchored += other.reanchored;
    }
}

/// The gate of one leader at one receiver (module docs).
#[derive(Copy, Clone, Debug)]
pub struct LeadingValueGate {
    config: GateConfig,
    /// The last accepted sample.
    last: Option<LeadingSample>,
    /// The last accepted valid sample: the reference of the motion check.
    anchor: Option<LeadingSample>,
    /// What was refused.
    pub counts: GateCounts,
}

impl LeadingValueGate {
    /// A gate that has accepted nothing yet.
    pub const fn new(config: GateConfig) -> Self {
        Self {
            config,
            last: None,
            anchor: None,
            counts: GateCounts {
                not_finite: 0,
                future: 0,
                stale: 0,
                sequence: 0,
                jump: 0,
                reanchored: 0,
            },
        }
    }

    /// Checks sample `s` received when the receiver's clock reads `now_ns` (ns, engine time):
    /// let through, or refused and counted (nothing else changes).
    pub fn check(&mut self, now_ns: i64, s: &LeadingSample) -> Result<Verdict, Refused> {
        let r = self.judge(now_ns, s);
        match r {
            Ok(Verdict::Accepted) => {}
            Ok(Verdict::Reanchored) => self.counts.reanchored += 1,
            Err(Refused::NotFinite) => self.counts.not_finite += 1,
            Err(Refused::Future { .. }) => self.counts.future += 1,
            Err(Refused::Stale { .. }) => self.counts.stale += 1,
            Err(Refused::Sequence { .. }) => self.counts.sequence += 1,
            Err(Refused::Jump { .. }) => self.counts.jump += 1,
        }
        r
    }

    fn judge(&mut self, now_ns: i64, s: &LeadingSample) -> Result<Verdict, Refused> {
        if !(s.p.is_finite() && s.v.is_finite() && s.a.is_finite()) {
            return Err(Refused::NotFinite);
        }
        let c = &self.config;
        let latest_ns = now_ns.saturating_add(c.ahead_ns);
        if s.t_ns > latest_ns {
            return Err(Refused::Future {
                t_ns: s.t_ns,
                latest_ns,
            });
        }
        let oldest_ns = now_ns.saturating_sub(c.behind_ns);
        if s.t_ns < oldest_ns {
            return Err(Refused::Stale {
                t_ns: s.t_ns,
                oldest_ns,
            });
        }
        let last_seq = self.last.map_or(0, |l| l.seq);
        let on_grid = i64::try_from(s.seq)
            .ok()
            .and_then(|q| q.checked_mul(c.cycle_ns))
            == Some(s.t_ns);
        if !on_grid || self.last.is_some_and(|l| s.seq <= l.seq) {
            return Err(Refused::Sequence {
                seq: s.seq,
                last: last_seq,
            });
        }
        let anchor = match self.anchor {
            Some(a) if s.valid => a,
            _ => {
                // The first valid sample, or an invalid one (no motion to check).
                self.accept(s);
                return Ok(Verdict::Accepted);
            }
        };
        if self.reachable(&anchor, s) {
            self.accept(s);
            return Ok(Verdict::Accepted);
        }
        // Not reachable from the reference: a forgery, or a leader that jumped (homed with a new
        // position, restarted elsewhere). Once nothing valid was accepted for longer than the
        // leader's cycle, D and the tolerance on the receiver's clock (not the sample's time,
        // which a forger may stamp up to the window's end), the followers have bridged their
        // tolerance and stopped with 601: the sample is the new reference.
        if now_ns.saturating_sub(anchor.t_ns) > c.reanchor_ns {
            self.accept(s);
            return Ok(Verdict::Reanchored);
        }
        Err(Refused::Jump { seq: s.seq })
    }

    /// Takes `s` as the last accepted sample (and as the motion reference if valid).
    fn accept(&mut self, s: &LeadingSample) {
        self.last = Some(*s);
        if s.valid {
            self.anchor = Some(*s);
        }
    }

    /// Whether valid sample `b` can follow valid sample `a` within the dynamic limits. (An
    /// invalid sample carries no motion: it is checked for time and sequence only, and the
    /// buffer makes every lookup that uses it missing.)
    fn reachable(&self, a: &LeadingSample, b: &LeadingSample) -> bool {
        let c = &self.config;
        let dt = (b.t_ns.saturating_sub(a.t_ns)) as f64 * 1e-9;
        let tol = |x: f64| EPS * (1.0 + x.abs());
        let v_ok = b.v.abs() <= c.max_velocity + tol(b.v);
        let p_ok = (b.p - a.p).abs() <= c.max_velocity * dt + tol(b.p);
        let a_ok = (b.v - a.v).abs() <= c.max_acceleration * dt + tol(b.v);
        let k_ok = !c.kinematic
            || (b.p - a.p - a.v * dt).abs() <= 0.5 * c.max_acceleration * dt * dt + tol(b.p);
        v_ok && p_ok && a_ok && k_ok
    }

    /// The last accepted sample.
    pub fn last(&self) -> Option<&LeadingSample> {
        self.last.as_ref()
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
    use super::*;
    use proptest::prelude::*;

    const MS: i64 = 1_000_000;

    /// A leader with a 1 ms cycle, tolerance 4 ms, 256 samples kept, 100 units/s, 1000 units/s².
    fn gate() -> LeadingValueGate {
        LeadingValueGate::new(GateConfig::new(MS, 4 * MS, 256, 100.0, 1000.0))
    }

    /// A leader moving at constant velocity `v` from 0: its sample of cycle `k`.
    fn at(k: u64, v: f64) -> LeadingSample {
        let t_ns = k as i64 * MS;
        LeadingSample {
            t_ns,
            seq: k,
            p: v * t_ns as f64 * 1e-9,
            v,
            a: 0.0,
            modulo: None,
            valid: true,
        }
    }

    #[test]
    fn the_real_samples_pass() {
        let mut g = gate();
        for k in 1000..2000 {
            // Received one cycle later than their time.
            assert_eq!(
                g.check((k as i64 + 1) * MS, &at(k, 50.0)),
                Ok(Verdict::Accepted)
            );
        }
        assert_eq!(g.counts, GateCounts::default());
    }

    #[test]
    fn an_hour_in_the_future_is_refused_and_locks_nothing() {
        let mut g = gate();
        let now = 1000 * MS;
        assert_eq!(g.check(now, &at(999, 50.0)), Ok(Verdict::Accepted));
        let hour = 3_600_000u64;
        let forged = at(999 + hour, 50.0);
        assert!(matches!(g.check(now, &forged), Err(Refused::Future { .. })));
        // The next real sample still passes.
        assert_eq!(g.check(now + MS, &at(1000, 50.0)), Ok(Verdict::Accepted));
        assert_eq!(g.counts.future, 1);
        assert_eq!(g.counts.refused(), 1);
    }

    #[test]
    fn the_window_edges_are_exact() {
        let mut g = gate();
        let now = 1000 * MS;
        // Latest: now + cycle + tolerance = 1005 ms.
        assert_eq!(g.check(now, &at(1005, 0.0)), Ok(Verdict::Accepted));
        let mut g = gate();
        assert_eq!(
            g.check(now, &at(1006, 0.0)),
            Err(Refused::Future {
                t_ns: 1006 * MS,
                latest_ns: 1005 * MS
            })
        );
        // Oldest: now - 256 cycles = 744 ms.
        assert_eq!(g.check(now, &at(744, 0.0)), Ok(Verdict::Accepted));
        let mut g = gate();
        assert_eq!(
            g.check(now, &at(743, 0.0)),
            Err(Refused::Stale {
                t_ns: 743 * MS,
                oldest_ns: 744 * MS
            })
        );
    }

    #[test]
    fn duplicates_reordered_and_off_grid_sequence_numbers_are_refused() {
        let mut g = gate();
        let now = 1000 * MS;
        g.check(now, &at(998, 1.0)).unwrap();
        assert_eq!(
            g.check(now, &at(998, 1.0)),
            Err(Refused::Sequence {
                seq: 998,
                last: 998
            })
        );
        assert!(matches!(
            g.check(now, &at(997, 1.0)),
            Err(Refused::Sequence { .. })
        ));
        // A sequence number far ahead of its time (which would block the real ones).
        let mut s = at(999, 1.0);
        s.seq = u64::MAX;
        assert!(matches!(g.check(now, &s), Err(Refused::Sequence { .. })));
        assert_eq!(g.counts.sequence, 3);
        assert_eq!(g.check(now, &at(999, 1.0)), Ok(Verdict::Accepted));
    }

    #[test]
    fn not_finite_values_are_refused() {
        let mut g = gate();
        let mut s = at(10, 1.0);
        s.v = f64::NAN;
        assert_eq!(g.check(10 * MS, &s), Err(Refused::NotFinite));
        s.v = 1.0;
        s.p = f64::INFINITY;
        assert_eq!(g.check(10 * MS, &s), Err(Refused::NotFinite));
        assert_eq!(g.counts.not_finite, 2);
        assert!(g.last().is_none());
    }

    #[test]
    fn a_jump_beyond_the_limits_is_refused_and_the_real_leader_goes_on() {
        let mut g = gate();
        g.check(1000 * MS, &at(1000, 50.0)).unwrap();
        // 1 ms later the position may change by at most 100 * 0.001 = 0.1.
        let mut s = at(1001, 50.0);
        s.p += 0.2;
        assert_eq!(g.check(1001 * MS, &s), Err(Refused::Jump { seq: 1001 }));
        // Velocity beyond MaxVelocity.
        let mut s = at(1002, 150.0);
        s.p = at(1002, 50.0).p;
        assert!(matches!(g.check(1002 * MS, &s), Err(Refused::Jump { .. })));
        // A velocity change beyond MaxAcceleration * dt (1000 * 0.003 = 3).
        let mut s = at(1003, 50.0);
        s.v = 54.0;
        assert!(matches!(g.check(1003 * MS, &s), Err(Refused::Jump { .. })));
        assert_eq!(g.check(1004 * MS, &at(1004, 50.0)), Ok(Verdict::Accepted));
        assert_eq!(g.counts.jump, 3);
    }

    #[test]
    fn a_small_offset_off_the_kinematics_is_refused_even_after_a_few_cycles() {
        let mut g = gate();
        g.check(1000 * MS, &at(1000, 50.0)).unwrap();
        // 4 ms later, 0.2 off the constant-velocity path: within MaxVelocity * 4 ms (0.4 above
        // the 0.2 travelled), but more than amax·Δt²/2 = 0.008.
        let mut s = at(1004, 50.0);
        s.p += 0.2;
        assert!(matches!(g.check(1004 * MS, &s), Err(Refused::Jump { .. })));
        // Without the kinematic check (actual-value coupling) it passes.
        let mut g = LeadingValueGate::new(GateConfig {
            kinematic: false,
            ..GateConfig::new(MS, 4 * MS, 256, 100.0, 1000.0)
        });
        g.check(1000 * MS, &at(1000, 50.0)).unwrap();
        assert_eq!(g.check(1004 * MS, &s), Ok(Verdict::Accepted));
    }

    #[test]
    fn a_leader_that_really_jumped_is_followed_again_after_a_gap() {
        let mut g = gate();
        g.check(1000 * MS, &at(1000, 0.0)).unwrap();
        let moved = |k: u64| {
            let mut s = at(k, 0.0);
            s.p = 360.0;
            s
        };
        // Refused for a gap: cycle + tolerance = 5 ms after the reference.
        for k in 1001..=1005 {
            assert!(g.check(k as i64 * MS, &moved(k)).is_err(), "{k}");
        }
        assert_eq!(g.check(1006 * MS, &moved(1006)), Ok(Verdict::Reanchored));
        assert_eq!(g.check(1007 * MS, &moved(1007)), Ok(Verdict::Accepted));
        assert_eq!((g.counts.jump, g.counts.reanchored), (5, 1));
    }

    #[test]
    fn an_outage_reanchors_only_after_cycle_delay_and_tolerance_on_the_receivers_clock() {
        // D = 10 ms: the followers stop with 601 at 1 + 10 + 4 = 15 ms after the last sample.
        let mut g = LeadingValueGate::new(GateConfig {
            reanchor_ns: 15 * MS,
            ..GateConfig::new(MS, 4 * MS, 256, 100.0, 1000.0)
        });
        g.check(1000 * MS, &at(1000, 0.0)).unwrap();
        let moved = |k: u64| {
            let mut s = at(k, 0.0);
            s.p = 360.0;
            s
        };
        // A forger stamps the latest time the window takes (now + cycle + tolerance): 9 ms
        // into the outage its sample lies 14 ms after the reference, and is still a jump.
        assert_eq!(
            g.check(1009 * MS, &moved(1014)),
            Err(Refused::Jump { seq: 1014 })
        );
        assert_eq!(
            g.check(1015 * MS, &moved(1019)),
            Err(Refused::Jump { seq: 1019 })
        );
        assert_eq!(g.check(1016 * MS, &moved(1020)), Ok(Verdict::Reanchored));
    }

    #[test]
    fn forgeries_between_real_samples_never_reanchor() {
        let mut g = gate();
        for k in 1000..1100u64 {
            let real = at(k, 10.0);
            assert_eq!(g.check(k as i64 * MS, &real), Ok(Verdict::Accepted));
            // A forged sample for the next cycle a little ahead of the real one: refused as a
            // jump (10 units away), and the real one of that cycle is then refused as a
            // duplicate... unless it arrives first, as here every other cycle.
            let mut forged = at(k + 1, 10.0);
            forged.p += 10.0;
            if k % 2 == 0 {
                assert!(matches!(
                    g.check(k as i64 * MS, &forged),
                    Err(Refused::Jump { .. })
                ));
            }
        }
        assert_eq!(g.counts.reanchored, 0);
        assert_eq!(g.counts.jump, 50);
    }

    #[test]
    fn invalid_samples_pass_on_time_and_sequence_only() {
        let mut g = gate();
        g.check(1000 * MS, &at(1000, 10.0)).unwrap();
        let mut s = at(1001, 0.0);
        s.valid = false;
        s.p = 1e9;
        assert_eq!(g.check(1001 * MS, &s), Ok(Verdict::Accepted));
        // The motion reference stays the last valid sample.
        let mut j = at(1002, 10.0);
        j.p = 1e9;
        assert!(matches!(g.check(1002 * MS, &j), Err(Refused::Jump { .. })));
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, rng_seed: proptest::test_runner::RngSeed::Fixed(12), ..ProptestConfig::default() })]

        /// Motion within the limits, received with any lateness within the window, is always
        /// accepted; a sample later than the window is always refused and changes nothing.
        #[test]
        fn plausible_motion_always_passes(
            v0 in -100.0f64..100.0,
            acc in prop::collection::vec(-1000.0f64..1000.0, 1..200),
            lateness in prop::collection::vec(0i64..200, 1..200),
            forged_ahead in 6i64..1_000_000,
        ) {
            let mut g = gate();
            let (mut p, mut v) = (0.0f64, v0);
            let dt = 1e-3;
            for (k, a) in acc.iter().enumerate() {
                let k = k as u64 + 1;
                let a = if (v + a * dt).abs() > 100.0 { 0.0 } else { *a };
                p += v * dt + 0.5 * a * dt * dt;
                v += a * dt;
                let s = LeadingSample { t_ns: k as i64 * MS, seq: k, p, v, a, modulo: None, valid: true };
                let late = lateness.get(k as usize % lateness.len()).copied().unwrap_or(0);
                let now = s.t_ns + late * MS / 100;
                prop_assert_eq!(g.check(now, &s), Ok(Verdict::Accepted));
                let before = (*g.last().unwrap(), g.counts.jump);
                let f = LeadingSample { t_ns: (k as i64 + forged_ahead) * MS, seq: k + forged_ahead as u64, ..s };
                let r = g.check(now, &f);
                prop_assert!(matches!(r, Err(Refused::Future { .. })), "{:?}", r);
                prop_assert_eq!((*g.last().unwrap(), g.counts.jump), before);
            }
            prop_assert_eq!(g.counts.refused(), g.counts.future);
        }
    }
}
