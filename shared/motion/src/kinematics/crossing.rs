//! Exact crossing math on the motion of one cycle: sets of positions (a cam's ON range, a
//! measuring window) and where a monotone stretch of motion enters and leaves them, the
//! effective path of an output cam or cam track with hysteresis and direction, and the
//! crossings of periodic points.

use crate::kinematics::cycle_motion::{AxisMotion, Run};
use crate::kinematics::modulo::Modulo;

/// A set of positions made of closed intervals (a cam's ON range, a measuring window), in the
/// continuous coordinate.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(crate) enum RangeSet {
    /// No position.
    Empty,
    /// Every position.
    Full,
    /// `[lo, hi]`, `lo < hi`.
    Interval { lo: f64, hi: f64 },
    /// `(-inf, below] U [above, inf)`, `below < above`.
    Outside { below: f64, above: f64 },
    /// The union over all integers `k` of `[lo + k P, hi + k P]`, `0 < hi - lo < P`.
    Periodic { lo: f64, hi: f64, period: f64 },
}

impl RangeSet {
    /// `[lo, hi]` on a linear axis or, with `modulo`, the modulo range from `lo` to `hi` after
    /// both are reduced (wrapping through the modulo boundary when `lo > hi`). Equal bounds give
    /// `equal` (empty for cams, the whole range for windows).
    pub fn from_bounds(
        lo: f64,
        hi: f64,
        modulo: Option<Modulo>,
        wrap_linear: bool,
        equal: RangeSet,
    ) -> RangeSet {
        match modulo {
            Some(m) => {
                let a = m.wrap(lo);
                let b = m.wrap(hi);
                if a == b {
                    equal
                } else if a < b {
                    RangeSet::Periodic {
                        lo: a,
                        hi: b,
                        period: m.length,
                    }
                } else {
                    RangeSet::Periodic {
                        lo: a,
                        hi: b + m.length,
                        period: m.length,
                    }
                }
            }
            None => {
                if lo == hi {
                    equal
                } else if lo < hi {
                    RangeSet::Interval { lo, hi }
                } else if wrap_linear {
                    RangeSet::Outside {
                        below: hi,
                        above: lo,
                    }
                } else {
                    RangeSet::Interval { lo: hi, hi: lo }
                }
            }
        }
    }

    /// Periodic `[lo, hi]` with period `p` (cam tracks); `hi - lo >= p` is the full set,
    /// `hi <= lo` the empty one.
    pub fn periodic(lo: f64, hi: f64, p: f64) -> RangeSet {
        if hi <= lo {
            RangeSet::Empty
        } else if hi - lo >= p {
            RangeSet::Full
        } else {
            RangeSet::Periodic { lo, hi, period: p }
        }
    }

    /// `x` lies in the set (closed intervals).
    pub fn contains(&self, x: f64) -> bool {
        match *self {
            RangeSet::Empty => false,
            RangeSet::Full => true,
            RangeSet::Interval { lo, hi } => x >= lo && x <= hi,
            RangeSet::Outside { below, above } => x <= below || x >= above,
            RangeSet::Periodic { lo, hi, period } => {
                let k = ((x - lo) / period).floor();
                let r = x - (lo + k * period);
                r <= hi - lo || r >= period
            }
        }
    }

    /// Calls `f(c, entering)` for every boundary `c` crossed by a monotone motion from `from`
    /// to `to` (`c` in `(from, to]` moving up, in `[to, from)` moving down), in the order of the
    /// motion; `entering` is true when the motion enters the set at `c`. Stops when `f` returns
    /// `false`.
    pub fn crossings(&self, from: f64, to: f64, mut f: impl FnMut(f64, bool) -> bool) {
        if to == from || !from.is_finite() || !to.is_finite() {
            return;
        }
        let up = to > from;
        let inside = |c: f64| passed(c, from, to);
        match *self {
            RangeSet::Empty | RangeSet::Full => {}
            RangeSet::Interval { lo, hi } => {
                let seq = if up {
                    [(lo, true), (hi, false)]
                } else {
                    [(hi, true), (lo, false)]
                };
                for (c, e) in seq {
                    if inside(c) && !f(c, e) {
                        return;
                    }
                }
            }
            RangeSet::Outside { below, above } => {
                let seq = if up {
                    [(below, false), (above, true)]
                } else {
                    [(above, false), (below, true)]
                };
                for (c, e) in seq {
                    if inside(c) && !f(c, e) {
                        return;
                    }
                }
            }
            RangeSet::Periodic { lo, hi, period } => {
                let (min, max) = if up { (from, to) } else { (to, from) };
                let k0 = ((min - hi) / period).floor() as i64;
                let k1 = ((max - lo) / period).ceil() as i64;
                let (k0, k1) = limit_periods(k0, k1, up);
                if up {
                    for k in k0..=k1 {
                        let base = k as f64 * period;
                        for (c, e) in [(lo + base, true), (hi + base, false)] {
                            if inside(c) && !f(c, e) {
                                return;
                            }
                        }
                    }
                } else {
                    for k in (k0..=k1).rev() {
                        let base = k as f64 * period;
                        for (c, e) in [(hi + base, true), (lo + base, false)] {
                            if inside(c) && !f(c, e) {
                                return;
                            }
                        }
                    }
                }
            }
        }
    }

    /// Whether a motion in direction `dir` is in the set just after passing `x` (a boundary
    /// counts as outside when the motion leaves there); `dir == 0` is [`RangeSet::contains`].
    pub fn contains_moving(&self, x: f64, dir: i8) -> bool {
        if dir == 0 || !self.contains(x) {
            return self.contains(x);
        }
        let mut leaving = false;
        let eps = 1e-9 * (1.0 + x.abs());
        let (from, to) = if dir > 0 { (x - eps, x) } else { (x + eps, x) };
        self.crossings(from, to, |_, entering| {
            leaving = !entering;
            true
        });
        !leaving
    }

    /// The monotone motion from `from` to `to` touches the set.
    pub fn touches(&self, from: f64, to: f64) -> bool {
        let mut hit = self.contains(from) || self.contains(to);
        if !hit {
            self.crossings(from, to, |_, _| {
                hit = true;
                false
            });
        }
        hit
    }
}

/// At most this many periods of a periodic set are evaluated for one monotone stretch of
/// motion (a motion over more periods within one cycle is cut there: nothing sensible can be
/// switched at that rate, and the loop stays bounded).
pub const MAX_PERIODS_PER_RUN: i64 = 4096;

/// Limits the period range `k0..=k1` to [`MAX_PERIODS_PER_RUN`], keeping the end the motion
/// starts from.
pub(crate) fn limit_periods(k0: i64, k1: i64, up: bool) -> (i64, i64) {
    if k1.saturating_sub(k0) <= MAX_PERIODS_PER_RUN {
        (k0, k1)
    } else if up {
        (k0, k0.saturating_add(MAX_PERIODS_PER_RUN))
    } else {
        (k1.saturating_sub(MAX_PERIODS_PER_RUN), k1)
    }
}

// ---------------------------------------------------------------------------------------------
// The effective path: hysteresis and direction
// ---------------------------------------------------------------------------------------------

/// What the effective position does, in time order (times in s after the cycle start).
#[derive(Copy, Clone, Debug)]
pub(crate) enum PathEvent<'a> {
    /// The effective position follows the motion of `run` from `from` to `to` (monotone).
    Move { run: &'a Run, from: f64, to: f64 },
    /// The effective direction changes to `dir` at `dt`, the effective position being `at`.
    Turn { dt: f64, dir: i8, at: f64 },
    /// The hysteresis band is left against the old direction at `dt`: the direction becomes
    /// `dir` and the effective position jumps from `from` to `to`.
    Sweep {
        dt: f64,
        dir: i8,
        from: f64,
        to: f64,
    },
}

/// The effective direction and the armed hysteresis band (S7-1500T Measuring input and cam
/// functions V5.0 function manual, 3.2.4 'Hysteresis').
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub(crate) struct Path {
    /// +1, -1, or 0 (no motion seen since the reset).
    pub dir: i8,
    /// Armed band: reversal position and the direction before the reversal.
    band: Option<(f64, i8)>,
}

impl Path {
    /// Starts at the motion's start: direction from the start velocity, no band.
    pub fn reset(&mut self, motion: &AxisMotion) {
        let v = motion.start.v;
        self.dir = if v > 0.0 {
            1
        } else if v < 0.0 {
            -1
        } else {
            0
        };
        self.band = None;
    }

    /// Walks the motion of one cycle with hysteresis `h`, reporting the effective path.
    pub fn walk(&mut self, motion: &AxisMotion, h: f64, mut f: impl FnMut(PathEvent<'_>)) {
        motion.for_each_run(|run| {
            let s = run.dir();
            if s == 0 {
                return;
            }
            if self.band.is_none() {
                if self.dir == s {
                    f(PathEvent::Move {
                        run,
                        from: run.xa,
                        to: run.xb,
                    });
                    return;
                }
                if self.dir == 0 || h <= 0.0 {
                    self.dir = s;
                    f(PathEvent::Turn {
                        dt: run.ta(),
                        dir: s,
                        at: run.xa,
                    });
                    f(PathEvent::Move {
                        run,
                        from: run.xa,
                        to: run.xb,
                    });
                    return;
                }
                // A reversal with hysteresis: arm the band at the reversal point.
                self.band = Some((run.xa, self.dir));
            }
            let Some((p_rev, d_old)) = self.band else {
                return;
            };
            let d = f64::from(d_old);
            if s == d_old {
                // Back in the old direction: past the reversal point the band is left.
                if (run.xb - p_rev) * d > 0.0 {
                    self.band = None;
                    f(PathEvent::Move {
                        run,
                        from: p_rev,
                        to: run.xb,
                    });
                }
            } else {
                let far = p_rev - d * h;
                if (run.xb - far) * d < 0.0 {
                    let dt = run.time_of(far);
                    self.band = None;
                    self.dir = s;
                    f(PathEvent::Sweep {
                        dt,
                        dir: s,
                        from: p_rev,
                        to: far,
                    });
                    f(PathEvent::Move {
                        run,
                        from: far,
                        to: run.xb,
                    });
                }
            }
        });
    }
}

/// Whether a monotone motion from `from` to `to` crosses `c`: `c` in `(from, to]` moving up, in
/// `[to, from)` moving down.
fn passed(c: f64, from: f64, to: f64) -> bool {
    if to > from {
        c > from && c <= to
    } else {
        c >= to && c < from
    }
}

/// Calls `f(c)` for every point `p + k * period` (every `k`; only `p` without a period) crossed
/// by a monotone motion from `from` to `to` (`(from, to]` or `[to, from)`), in motion order.
pub(crate) fn point_crossings(
    p: f64,
    period: Option<f64>,
    from: f64,
    to: f64,
    mut f: impl FnMut(f64) -> bool,
) {
    if from == to || !from.is_finite() || !to.is_finite() {
        return;
    }
    let up = to > from;
    let inside = |c: f64| passed(c, from, to);
    match period {
        None => {
            if inside(p) {
                f(p);
            }
        }
        Some(l) => {
            let (min, max) = if up { (from, to) } else { (to, from) };
            let k0 = ((min - p) / l).floor() as i64;
            let k1 = ((max - p) / l).ceil() as i64;
            let (k0, k1) = limit_periods(k0, k1, up);
            if up {
                for k in k0..=k1 {
                    let c = p + k as f64 * l;
                    if inside(c) && !f(c) {
                        return;
                    }
                }
            } else {
                for k in (k0..=k1).rev() {
                    let c = p + k as f64 * l;
                    if inside(c) && !f(c) {
                        return;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn periodic_crossings_in_order() {
        let s = RangeSet::Periodic {
            lo: 30.0,
            hi: 70.0,
            period: 50.0,
        };
        let mut v = [(0.0, false); 8];
        let mut n = 0;
        s.crossings(0.0, 150.0, |c, e| {
            v[n] = (c, e);
            n += 1;
            true
        });
        assert_eq!(
            &v[..n],
            &[
                (20.0, false),
                (30.0, true),
                (70.0, false),
                (80.0, true),
                (120.0, false),
                (130.0, true)
            ]
        );
        assert!(s.contains(0.0) && s.contains(20.0) && !s.contains(25.0) && s.contains(30.0));
    }
}
