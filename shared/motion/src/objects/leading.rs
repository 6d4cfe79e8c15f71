//! Leading values: what a follower reads of its leader each cycle (see the leading values between
//! nodes, docs/processes.md 'Leading values').
//!
//! Positions are continuous (unwrapped) so that a modulo wrap is never mistaken for a jump; the
//! modulo settings travel with the value.

use crate::kinematics::modulo::Modulo;

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

/// One timestamped sample of a leader as it travels on the bus (see the leading values between
/// nodes, docs/processes.md 'Leading values').
///
/// Positions are continuous (unwrapped), as in [`LeadingValue`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct LeadingSample {
    /// Time the sample is valid for (ns, cell clock).
    pub t_ns: i64,
    /// Sequence number given by the sender: one more than the previous sample's.
    pub seq: u64,
    /// Position (continuous).
    pub p: f64,
    /// Velocity.
    pub v: f64,
    /// Acceleration.
    pub a: f64,
    /// The leader's modulo settings, if it is a modulo axis.
    pub modulo: Option<Modulo>,
    /// The leader vouches for the value; `false` (e.g. leader not referenced, encoder fault)
    /// makes every lookup that would use this sample [`Missing::Invalid`].
    pub valid: bool,
}

impl LeadingSample {
    /// The sample's value.
    #[inline]
    pub fn value(&self) -> LeadingValue {
        LeadingValue {
            p: self.p,
            v: self.v,
            a: self.a,
            modulo: self.modulo,
        }
    }
}

/// The result of asking the buffer for the leader at a time ([`LeadingValueBuffer::at`]).
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Lookup {
    /// The time lies within the buffered samples: the sample itself, or the quintic Hermite
    /// interpolant between the two samples around it.
    Interpolated(LeadingValue),
    /// The time lies after the newest sample, within the tolerance: extrapolated from the
    /// newest sample with its constant acceleration.
    Extrapolated {
        /// The extrapolated value.
        value: LeadingValue,
        /// How far past the newest sample the time lies (ns, `0 < age_ns <= tolerance`).
        age_ns: i64,
    },
    /// No value for the time (the follower raises alarm 601).
    Missing(Missing),
}

impl Lookup {
    /// The value, interpolated or extrapolated; `None` when missing.
    #[inline]
    pub fn value(&self) -> Option<LeadingValue> {
        match self {
            Self::Interpolated(v) | Self::Extrapolated { value: v, .. } => Some(*v),
            Self::Missing(_) => None,
        }
    }
}

/// Why the buffer has no value for a time.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Missing {
    /// No sample buffered yet (or since [`LeadingValueBuffer::clear`]).
    Empty,
    /// The time lies before the oldest buffered sample: the buffer is too short for the delay.
    TooOld {
        /// Time of the oldest buffered sample (ns).
        oldest_ns: i64,
    },
    /// The time lies after the newest sample by more than the tolerance.
    Late {
        /// Time of the newest buffered sample (ns).
        newest_ns: i64,
    },
    /// A sample the value would be computed from is marked invalid.
    Invalid,
}

/// Why [`LeadingValueBuffer::push`] refused a sample.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Rejected {
    /// Position, velocity or acceleration is NaN or infinite.
    NotFinite,
    /// The sample's time is not after the newest buffered sample's (late duplicate or
    /// reordered frame).
    OutOfOrder {
        /// Time of the newest buffered sample (ns).
        newest_ns: i64,
    },
}

/// An empty slot of the ring (never read: only the `len` slots from `head` are).
const EMPTY: LeadingSample = LeadingSample {
    t_ns: 0,
    seq: 0,
    p: 0.0,
    v: 0.0,
    a: 0.0,
    modulo: None,
    valid: false,
};

/// The last `N` samples of one leader, in time order, and the leading value at any time they
/// cover (see the leading values between nodes, docs/processes.md 'Leading values').
///
/// A follower computing its setpoint for time `t` asks for its leader at `t - D` (`D` the
/// leader's leading-value delay). Between two samples the value is the quintic Hermite
/// interpolant through position, velocity and acceleration at both samples: exact for motion
/// that is a polynomial of degree up to 5 between them, and continuous in position, velocity
/// and acceleration across every sample. After the newest sample the value is extrapolated with
/// constant acceleration for at most a tolerance (a late sample is bridged), beyond that it is
/// [`Missing::Late`]; before the oldest it is [`Missing::TooOld`].
///
/// A fixed ring of `N >= 1` samples: no allocation after construction. Lookups take
/// O(log N); a time within the last two sample intervals (the common case) takes O(1).
#[derive(Clone)]
pub struct LeadingValueBuffer<const N: usize> {
    buf: [LeadingSample; N],
    /// Slot of the oldest sample.
    head: usize,
    /// Samples buffered, `<= N`.
    len: usize,
    rejected: u64,
    lost: u64,
    /// Samples further apart than this are a gap (see [`Self::set_max_gap`]).
    max_gap_ns: i64,
}

impl<const N: usize> Default for LeadingValueBuffer<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> core::fmt::Debug for LeadingValueBuffer<N> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("LeadingValueBuffer")
            .field("capacity", &N)
            .field("len", &self.len)
            .field("oldest", &self.sample(0))
            .field("newest", &self.newest())
            .field("rejected", &self.rejected)
            .field("lost", &self.lost)
            .finish()
    }
}

impl<const N: usize> LeadingValueBuffer<N> {
    /// An empty buffer. `N` must be at least 1 (checked at compile time).
    pub const fn new() -> Self {
        const { assert!(N >= 1, "a LeadingValueBuffer holds at least one sample") };
        Self {
            buf: [EMPTY; N],
            head: 0,
            len: 0,
            rejected: 0,
            lost: 0,
            max_gap_ns: i64::MAX,
        }
    }

    /// Two samples further apart than `ns` (typically the leader's cycle plus the tolerance)
    /// are a gap, a leader that stopped publishing and came back: inside it, the value is
    /// bridged no further than `tolerance_ns` after the sample before it, as a late sample would
    /// have been. Default: no gaps.
    pub fn set_max_gap(&mut self, ns: i64) {
        self.max_gap_ns = ns;
    }

    /// Slot of the `i`-th sample counted from the oldest (`i < N`).
    #[inline]
    fn slot(&self, i: usize) -> usize {
        let j = self.head + i;
        if j >= N {
            j - N
        } else {
            j
        }
    }

    /// The `i`-th buffered sample, counted from the oldest.
    #[inline]
    fn sample(&self, i: usize) -> Option<&LeadingSample> {
        if i < self.len {
            self.buf.get(self.slot(i))
        } else {
            None
        }
    }

    /// Appends a sample. Its time must be after the newest buffered sample's and its position,
    /// velocity and acceleration finite; otherwise nothing changes but [`Self::rejected`]. When
    /// the buffer is full the oldest sample is dropped. A sequence number other than the newest
    /// sample's plus one counts as a gap in [`Self::lost`] (a restart of the sender too).
    pub fn push(&mut self, s: LeadingSample) -> Result<(), Rejected> {
        if !(s.p.is_finite() && s.v.is_finite() && s.a.is_finite()) {
            self.rejected += 1;
            return Err(Rejected::NotFinite);
        }
        if let Some(newest) = self.newest() {
            if s.t_ns <= newest.t_ns {
                let newest_ns = newest.t_ns;
                self.rejected += 1;
                return Err(Rejected::OutOfOrder { newest_ns });
            }
            if s.seq.wrapping_sub(newest.seq) != 1 {
                self.lost += 1;
            }
        }
        let at = if self.len < N {
            self.len += 1;
            self.slot(self.len - 1)
        } else {
            // Full: overwrite the oldest, the next one becomes the oldest.
            let at = self.head;
            self.head = self.slot(1);
            at
        };
        if let Some(slot) = self.buf.get_mut(at) {
            *slot = s;
        }
        Ok(())
    }

    /// The leader at `t_ns`: the sample at exactly that time, the quintic Hermite interpolant
    /// between the two samples around it, or, after the newest sample by at most
    /// `tolerance_ns`, the newest sample extrapolated with constant acceleration. The modulo
    /// settings are those of the later sample used.
    ///
    /// Missing: [`Missing::Empty`] with no sample; [`Missing::TooOld`] before the oldest
    /// sample; [`Missing::Late`] after the newest by more than `tolerance_ns` (whether or not
    /// the newest is valid), or inside a gap ([`Self::set_max_gap`]) more than `tolerance_ns`
    /// after the sample before it; [`Missing::Invalid`] when a sample used is marked invalid.
    pub fn at(&self, t_ns: i64, tolerance_ns: i64) -> Lookup {
        let Some(newest) = self.newest() else {
            return Lookup::Missing(Missing::Empty);
        };
        if t_ns >= newest.t_ns {
            let age_ns = t_ns.saturating_sub(newest.t_ns);
            if age_ns > tolerance_ns && age_ns > 0 {
                return Lookup::Missing(Missing::Late {
                    newest_ns: newest.t_ns,
                });
            }
            if !newest.valid {
                return Lookup::Missing(Missing::Invalid);
            }
            if age_ns == 0 {
                return Lookup::Interpolated(newest.value());
            }
            let dt = age_ns as f64 * 1e-9;
            let value = LeadingValue {
                p: newest.p + dt * (newest.v + 0.5 * dt * newest.a),
                v: newest.v + dt * newest.a,
                a: newest.a,
                modulo: newest.modulo,
            };
            return Lookup::Extrapolated { value, age_ns };
        }
        // t < newest: the bracket `[i, i + 1]` with `t_i <= t < t_(i+1)`, `i <= len - 2`.
        let Some(i) = self.bracket(t_ns) else {
            let oldest_ns = self.sample(0).map_or(newest.t_ns, |s| s.t_ns);
            return Lookup::Missing(Missing::TooOld { oldest_ns });
        };
        let (Some(a), Some(b)) = (self.sample(i), self.sample(i + 1)) else {
            // Unreachable: `bracket` returns `i + 1 < len`.
            return Lookup::Missing(Missing::Empty);
        };
        if t_ns == a.t_ns {
            return if a.valid {
                Lookup::Interpolated(a.value())
            } else {
                Lookup::Missing(Missing::Invalid)
            };
        }
        if !(a.valid && b.valid) {
            return Lookup::Missing(Missing::Invalid);
        }
        // A gap in the samples (a leader that stopped publishing and came back) is not bridged
        // further than a late sample would have been: the follower saw no value there.
        if b.t_ns.saturating_sub(a.t_ns) > self.max_gap_ns
            && t_ns.saturating_sub(a.t_ns) > tolerance_ns
        {
            return Lookup::Missing(Missing::Late { newest_ns: a.t_ns });
        }
        Lookup::Interpolated(hermite(a, b, t_ns))
    }

    /// Index `i` (from the oldest) with `t_i <= t < t_(i+1)`, for `t` before the newest sample;
    /// `None` when `t` is before the oldest. The last two intervals are tried first.
    #[inline]
    fn bracket(&self, t_ns: i64) -> Option<usize> {
        let n = self.len;
        // Fast path: the last two intervals, `[n - 2, n - 1]` and `[n - 3, n - 2]`.
        let mut hi = n.checked_sub(1)?;
        for _ in 0..2 {
            let lo = hi.checked_sub(1)?;
            if self.sample(lo)?.t_ns <= t_ns {
                return Some(lo);
            }
            hi = lo;
        }
        // Binary search in `[0, hi]`: invariant `t_lo <= t < t_hi` once `t_0 <= t` holds.
        let mut lo = 0;
        if self.sample(lo)?.t_ns > t_ns {
            return None;
        }
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            if self.sample(mid)?.t_ns <= t_ns {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Some(lo)
    }

    /// The newest buffered sample.
    #[inline]
    pub fn newest(&self) -> Option<&LeadingSample> {
        self.sample(self.len.checked_sub(1)?)
    }

    /// Number of buffered samples (at most `N`).
    #[inline]
    pub fn len(&self) -> usize {
        self.len
    }

    /// No sample buffered.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Drops all samples (the counters [`Self::rejected`] and [`Self::lost`] stay). The next
    /// sample may have any time and sequence number.
    pub fn clear(&mut self) {
        self.head = 0;
        self.len = 0;
    }

    /// Samples refused by [`Self::push`] (since creation).
    #[inline]
    pub fn rejected(&self) -> u64 {
        self.rejected
    }

    /// Sequence gaps seen by [`Self::push`]: accepted samples whose sequence number was not the
    /// newest sample's plus one (since creation).
    #[inline]
    pub fn lost(&self) -> u64 {
        self.lost
    }
}

/// The quintic Hermite interpolant through `(p, v, a)` of `a` and `b` at `t_ns`
/// (`a.t_ns < t_ns < b.t_ns`): exact for polynomials up to degree 5.
///
/// In the normalised time `s = (t - t_a) / h`: `p = p_a + c1 s + ... + c5 s^5` with
/// `c1 = v_a h`, `c2 = a_a h² / 2` and `c3..c5` matching `p`, `v`, `a` of `b` at `s = 1`.
#[inline]
pub(crate) fn hermite(a: &LeadingSample, b: &LeadingSample, t_ns: i64) -> LeadingValue {
    // Differences in ns are exact in f64 below 2^53 ns (104 days).
    let h_ns = b.t_ns.saturating_sub(a.t_ns) as f64;
    let s = t_ns.saturating_sub(a.t_ns) as f64 / h_ns;
    let h = h_ns * 1e-9;
    let dp = b.p - a.p;
    let v0 = a.v * h;
    let v1 = b.v * h;
    let a0 = a.a * h * h;
    let a1 = b.a * h * h;
    let c1 = v0;
    let c2 = 0.5 * a0;
    let c3 = 10.0 * dp - 6.0 * v0 - 4.0 * v1 - 0.5 * (3.0 * a0 - a1);
    let c4 = -15.0 * dp + 8.0 * v0 + 7.0 * v1 + 0.5 * (3.0 * a0 - 2.0 * a1);
    let c5 = 6.0 * dp - 3.0 * (v0 + v1) - 0.5 * (a0 - a1);
    let q = s * (c1 + s * (c2 + s * (c3 + s * (c4 + s * c5))));
    let dq = c1 + s * (2.0 * c2 + s * (3.0 * c3 + s * (4.0 * c4 + s * (5.0 * c5))));
    let ddq = 2.0 * c2 + s * (6.0 * c3 + s * (12.0 * c4 + s * (20.0 * c5)));
    LeadingValue {
        p: a.p + q,
        v: dq / h,
        a: ddq / (h * h),
        modulo: b.modulo,
    }
}
