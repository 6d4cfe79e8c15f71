//! The rejoin of an extrapolated leading value with the real one (docs/processes.md, "Leading
//! values", "Rejoin after extrapolation").
//!
//! A follower bridges a late sample of its leader by extrapolating the newest sample with
//! constant acceleration ([`LeadingValueBuffer::at`]). When the leader's motion changed its
//! acceleration meanwhile, the extrapolated value drifts from the real one (by `j·τ³/6` after
//! `τ` with jerk `j`), and when the samples come back the looked-up value would step to the real
//! one in one cycle, and a geared follower with it. [`Rejoin`] removes the step: at the cycle the
//! value stops being extrapolated from a sample (samples returned, or a newer sample is
//! extrapolated instead), it takes the difference `δ` in position, velocity and acceleration
//! between the value the follower was following and the new one, and adds to the new value a
//! correction that starts at `δ` and decays to zero, continuous in position, velocity and
//! acceleration (the quintic Hermite polynomial from `δ` to zero), over twice as long as the
//! extrapolation lasted. The follower's leading value is thus continuous in p, v and a through
//! the whole outage; after the correction it is the real value to the last bit.
//!
//! Inferred (the references extrapolate an actual value to compensate a dead time, S7-1500T
//! Motion Control V4.0 function manual, 'Actual value coupling', but say nothing on a leading
//! value whose transfer fails for a few cycles): the duration of the correction, `2τ` after an
//! extrapolation of `τ`. It scales with the error it removes (`δ` grows as `τ³`), so the added
//! acceleration stays of the order of what the leader's acceleration changed meanwhile (`j·τ`)
//! and the added jerk about ten times the leader's: after 90 ms in a phase of jerk 40,000 mm/s³
//! (a step of 4.86 mm removed), the correction adds at most 5,465 mm/s² of acceleration (1.5
//! times the 3,600 mm/s² the extrapolation lagged by) and the value's jerk peaks at
//! 450,000 mm/s³ (the `rejoin` unit tests). Over `τ` the jerk would peak at 1,520,000 mm/s³; over
//! `4τ` at 181,000, but the lag would last twice as long. The cure is a short
//! extrapolation: a delay D that covers the stalls, and a short tolerance.
//!
//! Pure: no IO, no clock (the time is an input), no allocation.

use crate::objects::leading::{hermite, LeadingSample, LeadingValue, LeadingValueBuffer, Lookup};

/// One rejoin, reported when it starts ([`Rejoin::at`]): the step it removed.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Rejoined {
    /// Time of the lookup (ns) at which the correction starts.
    pub t_ns: i64,
    /// The difference in position between the value followed so far and the new one at
    /// `t_ns` (what would have been a step).
    pub dp: f64,
    /// The difference in velocity.
    pub dv: f64,
    /// How long the value was extrapolated from the sample it is rejoined from (ns).
    pub extrapolated_ns: i64,
    /// How long the correction lasts (ns): twice as long as the extrapolation.
    pub duration_ns: i64,
}

/// The correction that decays from `start` (its `p`, `v`, `a` are the differences) to zero at
/// `end_ns`.
#[derive(Copy, Clone, Debug, PartialEq)]
struct Correction {
    start: LeadingSample,
    end: LeadingSample,
}

impl Correction {
    /// The correction at `t_ns`, `None` from its end on.
    fn at(&self, t_ns: i64) -> Option<LeadingValue> {
        if t_ns >= self.end.t_ns {
            return None;
        }
        if t_ns <= self.start.t_ns {
            return Some(self.start.value());
        }
        Some(hermite(&self.start, &self.end, t_ns))
    }
}

/// The rejoin state of one leader as one executive reads it (see the module documentation).
///
/// Ask [`Rejoin::at`] instead of [`LeadingValueBuffer::at`], with non-decreasing times; asking
/// again at the same time gives the same value.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct Rejoin {
    /// The sample the last lookup extrapolated from (`None`: it interpolated).
    from: Option<LeadingSample>,
    /// The correction in progress.
    correction: Option<Correction>,
}

impl Rejoin {
    /// No extrapolation, no correction.
    pub const fn new() -> Self {
        Self {
            from: None,
            correction: None,
        }
    }

    /// A correction is in progress: the value is not the leader's own yet.
    pub fn correcting(&self) -> bool {
        self.correction.is_some()
    }

    /// The leader at `t_ns` as [`LeadingValueBuffer::at`] gives it, plus the correction in
    /// progress; and the rejoin that starts at this lookup, if one does. A missing value ends
    /// any correction (the follower stops with alarm 601; a new coupling starts afresh).
    pub fn at<const N: usize>(
        &mut self,
        buffer: &LeadingValueBuffer<N>,
        t_ns: i64,
        tolerance_ns: i64,
    ) -> (Lookup, Option<Rejoined>) {
        let lookup = buffer.at(t_ns, tolerance_ns);
        let (base, source) = match lookup {
            Lookup::Missing(_) => {
                *self = Self::new();
                return (lookup, None);
            }
            Lookup::Interpolated(v) => (v, None),
            Lookup::Extrapolated { value, .. } => (value, buffer.newest().copied()),
        };
        let mut rejoined = None;
        if let Some(old) = self
            .from
            .filter(|old| source.map(|s| s.t_ns) != Some(old.t_ns))
        {
            rejoined = Some(self.start(old, base, t_ns));
        }
        self.from = source;
        let value = match self.correction.and_then(|c| c.at(t_ns)) {
            Some(c) => LeadingValue {
                p: base.p + c.p,
                v: base.v + c.v,
                a: base.a + c.a,
                modulo: base.modulo,
            },
            None => {
                self.correction = None;
                base
            }
        };
        let lookup = match lookup {
            Lookup::Extrapolated { age_ns, .. } => Lookup::Extrapolated { value, age_ns },
            _ => Lookup::Interpolated(value),
        };
        (lookup, rejoined)
    }

    /// Starts the correction at `t_ns` from the value followed so far (extrapolated from
    /// `old`, plus the correction in progress) to `base`.
    fn start(&mut self, old: LeadingSample, base: LeadingValue, t_ns: i64) -> Rejoined {
        let dt = t_ns.saturating_sub(old.t_ns) as f64 * 1e-9;
        let mut dp = old.p + dt * (old.v + 0.5 * dt * old.a) - base.p;
        let mut dv = old.v + dt * old.a - base.v;
        let mut da = old.a - base.a;
        if let Some(c) = self.correction.and_then(|c| c.at(t_ns)) {
            dp += c.p;
            dv += c.v;
            da += c.a;
        }
        let extrapolated_ns = t_ns.saturating_sub(old.t_ns);
        let duration_ns = extrapolated_ns.saturating_mul(2).max(1);
        let start = LeadingSample {
            t_ns,
            seq: 0,
            p: dp,
            v: dv,
            a: da,
            modulo: None,
            valid: true,
        };
        let end = LeadingSample {
            t_ns: t_ns.saturating_add(duration_ns),
            p: 0.0,
            v: 0.0,
            a: 0.0,
            ..start
        };
        self.correction = Some(Correction { start, end });
        Rejoined {
            t_ns,
            dp,
            dv,
            extrapolated_ns,
            duration_ns,
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    const MS: i64 = 1_000_000;

    /// A leader at rest until 0, then with constant jerk `J`: the extrapolation of the sample
    /// at 0 (a = 0) lags the real motion.
    const J: f64 = 40_000.0;

    fn real(t_ns: i64) -> LeadingSample {
        let t = t_ns.max(0) as f64 * 1e-9;
        LeadingSample {
            t_ns,
            seq: u64::try_from(t_ns / MS).unwrap_or(0),
            p: J * t * t * t / 6.0,
            v: J * t * t / 2.0,
            a: J * t,
            modulo: None,
            valid: true,
        }
    }

    /// Reads the leader every ms from `-5 ms` to `until`, with no sample published in
    /// `(gap_from, gap_to)` until the follower's time reaches `gap_to` (a stalled link that
    /// then delivers the backlog); returns the values read and whether a rejoin started.
    fn run(gap_from: i64, gap_to: i64, until: i64) -> Vec<(i64, LeadingValue, bool)> {
        let mut buffer = LeadingValueBuffer::<256>::new();
        let mut rejoin = Rejoin::new();
        let mut out = Vec::new();
        let mut next = -5;
        for k in -5..=until / MS {
            let t = k * MS;
            if t <= gap_from || t >= gap_to {
                for j in next..=k {
                    buffer.push(real(j * MS)).unwrap();
                }
                next = k + 1;
            }
            let (l, r) = rejoin.at(&buffer, t, 200 * MS);
            out.push((t, l.value().unwrap(), r.is_some()));
        }
        out
    }

    #[test]
    fn without_an_outage_the_value_is_the_buffers_to_the_last_bit() {
        for (t, v, rejoined) in run(1_000 * MS, 0, 300 * MS) {
            assert!(!rejoined);
            let r = real(t);
            assert_eq!((v.p, v.v, v.a), (r.p, r.v, r.a), "t={t}");
        }
    }

    #[test]
    fn an_outage_in_the_jerk_phase_rejoins_without_a_step() {
        // 90 ms without samples from 0: the extrapolation stays at rest while the leader runs
        // up with jerk 40,000: J·τ³/6 = 4.86 mm behind when the samples return.
        let out = run(0, 90 * MS, 400 * MS);
        assert_eq!(out.iter().filter(|o| o.2).count(), 1, "one rejoin");
        let step = |w: &[(i64, LeadingValue, bool)]| {
            let (a, b) = (w[0].1, w[1].1);
            ((b.p - a.p) - 0.5 * (a.v + b.v) * 1e-3).abs()
        };
        // Continuity: between two reads the position changes as the mean velocity says, up to
        // the trapezoid rule's error `jerk·dt³/12` (the correction's jerk is about ten times the
        // leader's here: 1.2e-4 mm): no step, where the value without the rejoin steps 4.86 mm.
        let worst = out.windows(2).map(step).fold(0.0, f64::max);
        assert!(worst < 1e-3, "largest step {worst} mm");
        let worst_da = out
            .windows(2)
            .map(|w| (w[1].1.a - w[0].1.a).abs())
            .fold(0.0, f64::max);
        // The leader's own change of acceleration per ms is 40; with the correction it peaks
        // at 450 (jerk 450,000 mm/s³).
        assert!(
            worst_da < 460.0,
            "largest change of acceleration {worst_da} per ms"
        );
        let worst_a = out
            .iter()
            .map(|(t, v, _)| (v.a - real(*t).a).abs())
            .fold(0.0, f64::max);
        assert!(
            worst_a < 5_470.0,
            "correction's largest acceleration {worst_a}"
        );
        // From the end of the correction (180 ms after the rejoin) the value is the real one.
        for (t, v, _) in out.iter().filter(|o| o.0 >= 270 * MS) {
            let r = real(*t);
            assert_eq!((v.p, v.v, v.a), (r.p, r.v, r.a), "t={t}");
        }
        // Without the rejoin the value would have stepped by the extrapolation's error.
        let at_return = out.iter().find(|o| o.2).unwrap();
        assert!((real(at_return.0).p - at_return.1.p) > 4.0);
    }

    #[test]
    fn a_missing_value_ends_the_correction() {
        let mut buffer = LeadingValueBuffer::<64>::new();
        let mut rejoin = Rejoin::new();
        buffer.push(real(0)).unwrap();
        assert!(matches!(
            rejoin.at(&buffer, 5 * MS, 10 * MS).0,
            Lookup::Extrapolated { .. }
        ));
        for k in 1..=5 {
            buffer.push(real(k * MS)).unwrap();
        }
        let (_, r) = rejoin.at(&buffer, 5 * MS, 10 * MS);
        assert!(r.is_some());
        assert!(rejoin.correcting());
        assert!(matches!(
            rejoin.at(&buffer, 30 * MS, 10 * MS).0,
            Lookup::Missing(_)
        ));
        assert!(!rejoin.correcting());
        assert_eq!(rejoin, Rejoin::new());
    }

    #[test]
    fn asking_twice_at_the_same_time_gives_the_same_value() {
        let mut buffer = LeadingValueBuffer::<64>::new();
        let mut rejoin = Rejoin::new();
        buffer.push(real(0)).unwrap();
        let a = rejoin.at(&buffer, 20 * MS, 50 * MS).0;
        assert_eq!(a, rejoin.at(&buffer, 20 * MS, 50 * MS).0);
        for k in 1..=20 {
            buffer.push(real(k * MS)).unwrap();
        }
        let (b, r) = rejoin.at(&buffer, 20 * MS, 50 * MS);
        assert!(r.is_some());
        let (c, r2) = rejoin.at(&buffer, 20 * MS, 50 * MS);
        assert_eq!(b, c);
        assert!(r2.is_none());
        // At the rejoin the value is the one followed so far: the extrapolation.
        let (a, b) = (a.value().unwrap(), b.value().unwrap());
        assert!(
            (a.p - b.p).abs() < 1e-12 && (a.v - b.v).abs() < 1e-9,
            "{a:?} {b:?}"
        );
        assert!((a.a - b.a).abs() < 1e-6, "{a:?} {b:?}");
    }
}
