//! The motion of an axis over one cycle ([`AxisMotion`]): what measuring inputs, output cams
//! and cam tracks are stepped with, and the interpolated curve they read positions and crossing
//! times from.
//!
//! - `t0_ns`, `t1_ns`: the cycle's start and end (ns on the cell clock), `t1_ns > t0_ns`;
//! - `start`, `end`: position, velocity and acceleration at `t0_ns` and `t1_ns`. Positions are
//!   **continuous** (modulo axes never wrap; see [`crate::kinematics::modulo`]);
//! - optional interior **knots** (up to [`MAX_KNOTS`]): further `(time, state)` samples inside
//!   the cycle;
//! - `modulo`: the axis' modulo setting (cam and window positions are reduced with it, measured
//!   values are reported reduced);
//! - `jump`: `Some(d)` if the position jumped by `d` at `t0_ns` (homing, a coordinate change):
//!   `start` is already in the new coordinates;
//! - `valid`: the position is valid (a setpoint of a position-controlled axis, or a valid actual
//!   value).
//!
//! **Motion between the samples** is the quintic Hermite interpolant through `(p, v, a)` at both
//! ends of every sub-interval (`start`, the knots, `end`). A motion of constant jerk is a cubic,
//! which the quintic Hermite reproduces exactly, so a caller that passes the segment boundaries of
//! its jerk-limited profile as knots ([`AxisMotion::from_profile`] does that) gets the exact
//! profile; a caller that only has cycle samples (an actual value) gets a smooth interpolant with
//! continuous position, velocity and acceleration. Crossing times of that curve are solved on
//! monotone pieces ([`Run`]; the real roots of the velocity are isolated first) to well below
//! 1 ns, and rounded to the nearest ns.

use crate::kinematics::modulo::Modulo;
use crate::kinematics::profile::{Profile, State};

/// Maximum number of interior knots of an [`AxisMotion`] (a profile has at most
/// [`crate::kinematics::profile::MAX_SEGMENTS`] segments, so every boundary fits).
pub const MAX_KNOTS: usize = crate::kinematics::profile::MAX_SEGMENTS;

/// One interior sample of an [`AxisMotion`].
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct Knot {
    /// Time after `t0_ns`, in seconds, strictly between the previous knot and the cycle end.
    pub dt: f64,
    /// Position, velocity, acceleration at that time.
    pub state: State,
}

/// The motion of the referenced axis over one cycle (see the module documentation).
#[derive(Copy, Clone, PartialEq)]
pub struct AxisMotion {
    /// Cycle start (ns).
    pub t0_ns: i64,
    /// Cycle end (ns), greater than `t0_ns`.
    pub t1_ns: i64,
    /// State at `t0_ns` (continuous position).
    pub start: State,
    /// State at `t1_ns` (continuous position).
    pub end: State,
    /// Modulo setting of the axis, if it is a modulo axis.
    pub modulo: Option<Modulo>,
    /// The position jumped by this amount at `t0_ns` (homing); `start` is after the jump.
    pub jump: Option<f64>,
    /// The position is valid (position-controlled setpoint, or valid actual value).
    pub valid: bool,
    knots: [Knot; MAX_KNOTS],
    n_knots: usize,
}

impl AxisMotion {
    /// A valid motion without knots, modulo or jump.
    pub fn new(t0_ns: i64, t1_ns: i64, start: State, end: State) -> Self {
        Self {
            t0_ns,
            t1_ns,
            start,
            end,
            modulo: None,
            jump: None,
            valid: true,
            knots: [Knot::default(); MAX_KNOTS],
            n_knots: 0,
        }
    }

    /// The motion sampled from a planned profile that started at `profile_start_ns`, with every
    /// segment boundary (and the profile end) inside the cycle as a knot, so that the
    /// interpolated curve is the profile itself.
    pub fn from_profile(profile: &Profile, profile_start_ns: i64, t0_ns: i64, t1_ns: i64) -> Self {
        let ta = (t0_ns - profile_start_ns) as f64 * 1e-9;
        let tb = (t1_ns - profile_start_ns) as f64 * 1e-9;
        let mut m = Self::new(t0_ns, t1_ns, profile.at(ta), profile.at(tb));
        for seg in profile.segments() {
            if seg.t0 > ta && seg.t0 < tb {
                m.push_knot(seg.t0 - ta, profile.at(seg.t0));
            }
        }
        let d = profile.duration();
        if d > ta && d < tb {
            m.push_knot(d - ta, profile.end());
        }
        m
    }

    /// Sets the modulo setting.
    pub fn with_modulo(mut self, modulo: Option<Modulo>) -> Self {
        self.modulo = modulo;
        self
    }

    /// Marks a position jump of `d` at `t0_ns`.
    pub fn with_jump(mut self, d: f64) -> Self {
        self.jump = Some(d);
        self
    }

    /// Sets the validity flag.
    pub fn with_valid(mut self, valid: bool) -> Self {
        self.valid = valid;
        self
    }

    /// Adds an interior knot `dt` seconds after `t0_ns`. Returns `false` (and ignores it) if
    /// `dt` is not after the last knot and before the cycle end, or the knots are full.
    pub fn push_knot(&mut self, dt: f64, state: State) -> bool {
        let last = self.knots().last().map_or(0.0, |k| k.dt);
        if !(dt > last && dt < self.duration()) || self.n_knots >= MAX_KNOTS {
            return false;
        }
        if let Some(k) = self.knots.get_mut(self.n_knots) {
            *k = Knot { dt, state };
            self.n_knots += 1;
            true
        } else {
            false
        }
    }

    /// The interior knots.
    pub fn knots(&self) -> &[Knot] {
        &self.knots[..self.n_knots.min(MAX_KNOTS)]
    }

    /// Cycle length in seconds.
    pub fn duration(&self) -> f64 {
        self.t1_ns.saturating_sub(self.t0_ns).max(0) as f64 * 1e-9
    }

    /// The interpolated state `dt` seconds after `t0_ns` (clamped to the cycle).
    pub fn at(&self, dt: f64) -> State {
        let dt = dt.min(self.duration()).max(0.0);
        let mut found = None;
        self.for_each_piece(|pc| {
            if found.is_none() && dt <= pc.t_a + pc.h {
                found = Some(pc.state(((dt - pc.t_a) / pc.h).clamp(0.0, 1.0)));
            }
        });
        found.unwrap_or(self.end)
    }

    /// Calls `f` with every Hermite piece of the cycle, in time order.
    pub(crate) fn for_each_piece(&self, mut f: impl FnMut(&Piece)) {
        let mut prev_t = 0.0;
        let mut prev = self.start;
        for k in self.knots() {
            let h = k.dt - prev_t;
            if h > 0.0 {
                f(&Piece::hermite(prev_t, h, prev, k.state));
            }
            prev_t = k.dt;
            prev = k.state;
        }
        let h = self.duration() - prev_t;
        if h > 0.0 {
            f(&Piece::hermite(prev_t, h, prev, self.end));
        }
    }

    /// Calls `f` with every monotone run of the cycle, in time order.
    pub(crate) fn for_each_run(&self, mut f: impl FnMut(&Run)) {
        self.for_each_piece(|pc| pc.for_each_run(&mut f));
    }

    /// Absolute time (ns) of `dt` seconds after `t0_ns`, rounded to the nearest ns.
    pub(crate) fn ns(&self, dt: f64) -> i64 {
        self.t0_ns + (dt * 1e9).round() as i64
    }
}

impl core::fmt::Debug for AxisMotion {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("AxisMotion")
            .field("t0_ns", &self.t0_ns)
            .field("t1_ns", &self.t1_ns)
            .field("start", &self.start)
            .field("end", &self.end)
            .field("knots", &self.knots())
            .field("modulo", &self.modulo)
            .field("jump", &self.jump)
            .field("valid", &self.valid)
            .finish()
    }
}

/// One quintic Hermite piece: `p(s) = p0 + sum c[k] s^k`, `s = (t - t_a) / h` in `[0, 1]`.
#[derive(Copy, Clone, Debug)]
pub(crate) struct Piece {
    /// Piece start, seconds after the cycle start.
    pub t_a: f64,
    /// Piece length (s), > 0.
    pub h: f64,
    p0: f64,
    c: [f64; 6],
}

/// A monotone part of a piece: `s` in `[sa, sb]`, position from `xa` to `xb`.
#[derive(Copy, Clone, Debug)]
pub(crate) struct Run {
    pub piece: Piece,
    pub sa: f64,
    pub sb: f64,
    pub xa: f64,
    pub xb: f64,
}

impl Run {
    /// +1, -1, or 0 (standstill).
    pub fn dir(&self) -> i8 {
        if self.xb > self.xa {
            1
        } else if self.xb < self.xa {
            -1
        } else {
            0
        }
    }

    /// Time (s after the cycle start) of the run start and end.
    pub fn ta(&self) -> f64 {
        self.piece.time(self.sa)
    }

    /// Time (s after the cycle start) at which the run reaches `x` (which must lie between
    /// `xa` and `xb`).
    pub fn time_of(&self, x: f64) -> f64 {
        // Newton's method inside a shrinking bracket (the run is monotone, so the bracket
        // always holds the crossing); a step that leaves the bracket is replaced by bisection.
        // Ends at a zero, at a step below rounding noise, or when the bracket cannot shrink.
        let pc = &self.piece;
        let target = x - pc.p0;
        let (mut lo, mut hi) = (self.sa, self.sb);
        // The run's end positions are known: no evaluation for the bracket.
        let flo0 = self.xa - x;
        if flo0 == 0.0 {
            return pc.time(lo);
        }
        let fhi = self.xb - x;
        if fhi == 0.0 {
            return pc.time(hi);
        }
        let mut flo = flo0;
        // First guess: the secant through the run's ends.
        let mut s = lo - flo * (hi - lo) / (fhi - flo);
        if !(s > lo && s < hi) {
            s = 0.5 * (lo + hi);
        }
        for _ in 0..100 {
            let (q, ds) = pc.q_dq(s);
            let fs = q - target;
            if fs == 0.0 {
                break;
            }
            if (fs < 0.0) == (flo < 0.0) {
                lo = s;
                flo = fs;
            } else {
                hi = s;
            }
            // A step below 0.1 ns: the Newton update that follows leaves an error of order
            // (q'' / 2q') d² (d the step in units of the piece), i.e. below 1e-17 s times
            // that curvature ratio on a 1 ms piece: 0.01 ns even for a ratio of 1e6 (near a
            // reversal); the property tests check edges to 1 ns against exact crossings.
            let step = fs / ds;
            if step.abs() * pc.h <= 1e-10 {
                s = (s - step).clamp(lo, hi);
                break;
            }
            let newton = s - step;
            let next = if newton >= lo && newton <= hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if next == s {
                break;
            }
            s = next;
        }
        pc.time(s)
    }
}

impl Piece {
    fn hermite(t_a: f64, h: f64, a: State, b: State) -> Self {
        let dp = b.p - a.p;
        let v0 = a.v * h;
        let v1 = b.v * h;
        let a0 = a.a * h * h;
        let a1 = b.a * h * h;
        let c3 = 10.0 * dp - 6.0 * v0 - 4.0 * v1 - 0.5 * (3.0 * a0 - a1);
        let c4 = -15.0 * dp + 8.0 * v0 + 7.0 * v1 + 0.5 * (3.0 * a0 - 2.0 * a1);
        let c5 = 6.0 * dp - 3.0 * (v0 + v1) - 0.5 * (a0 - a1);
        Self {
            t_a,
            h,
            p0: a.p,
            c: [0.0, v0, 0.5 * a0, c3, c4, c5],
        }
    }

    fn q(&self, s: f64) -> f64 {
        horner(&self.c, s)
    }

    /// `q(s)` and `q'(s)` together, by Estrin's scheme (independent pairs, so the products
    /// overlap instead of waiting on each other as in Horner's).
    fn q_dq(&self, s: f64) -> (f64, f64) {
        let [c0, c1, c2, c3, c4, c5] = self.c;
        let s2 = s * s;
        let s4 = s2 * s2;
        let v = (c0 + c1 * s) + s2 * (c2 + c3 * s) + s4 * (c4 + c5 * s);
        let d = (c1 + 2.0 * c2 * s) + s2 * (3.0 * c3 + 4.0 * c4 * s) + s4 * (5.0 * c5);
        (v, d)
    }

    fn time(&self, s: f64) -> f64 {
        self.t_a + s * self.h
    }

    fn state(&self, s: f64) -> State {
        let c = &self.c;
        let d1 = [c[1], 2.0 * c[2], 3.0 * c[3], 4.0 * c[4], 5.0 * c[5]];
        let d2 = [d1[1], 2.0 * d1[2], 3.0 * d1[3], 4.0 * d1[4]];
        State {
            p: self.p0 + self.q(s),
            v: horner(&d1, s) / self.h,
            a: horner(&d2, s) / (self.h * self.h),
        }
    }

    fn for_each_run(&self, f: &mut impl FnMut(&Run)) {
        let c = &self.c;
        let d1 = [c[1], 2.0 * c[2], 3.0 * c[3], 4.0 * c[4], 5.0 * c[5]];
        let mut roots = [0.0; 5];
        let n = sign_change_roots(&d1, &mut roots);
        let mut sa = 0.0;
        let mut xa = self.p0;
        for &r in roots.iter().take(n).chain(core::iter::once(&1.0)) {
            let xb = self.p0 + self.q(r);
            if r > sa {
                f(&Run {
                    piece: *self,
                    sa,
                    sb: r,
                    xa,
                    xb,
                });
            }
            sa = r;
            xa = xb;
        }
    }
}

fn horner(c: &[f64], s: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &k| acc * s + k)
}

/// The roots in `(0, 1)` at which the polynomial `c` (degree `c.len() - 1` <= 5) changes sign,
/// ascending; returns their number. Recursive on the derivative: between consecutive
/// sign-changing roots of the derivative the polynomial is monotone.
fn sign_change_roots(c: &[f64], out: &mut [f64; 5]) -> usize {
    let mut deg = c.len().saturating_sub(1);
    while deg > 0 && c.get(deg).copied().unwrap_or(0.0) == 0.0 {
        deg -= 1;
    }
    let c = &c[..=deg.min(c.len().saturating_sub(1))];
    if deg == 0 {
        return 0;
    }
    // On [0, 1], |c[1] s + c[2] s^2 + ...| <= |c[1]| + |c[2]| + ...: a constant term larger
    // than that (with a margin for rounding) keeps the sign, so there is no root (the common
    // case: an axis that does not reverse within the cycle).
    if let Some((&c0, rest)) = c.split_first() {
        let bound: f64 = rest.iter().map(|k| k.abs()).sum();
        if c0.abs() > bound * (1.0 + 1e-12) {
            return 0;
        }
    }
    let mut crit = [0.0; 5];
    let nc = if deg >= 2 {
        let mut d = [0.0; 5];
        for (k, dk) in d.iter_mut().enumerate().take(deg) {
            *dk = (k + 1) as f64 * c.get(k + 1).copied().unwrap_or(0.0);
        }
        sign_change_roots(&d[..deg], &mut crit)
    } else {
        0
    };
    let f = |s: f64| horner(c, s);
    let mut n = 0;
    let mut a = 0.0;
    let mut fa = f(a);
    for &b in crit.iter().take(nc).chain(core::iter::once(&1.0)) {
        let fb = f(b);
        if (fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0) {
            let (mut lo, mut hi) = (a, b);
            let mut flo = fa;
            for _ in 0..100 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                let fm = f(mid);
                if fm == 0.0 {
                    lo = mid;
                    hi = mid;
                    break;
                }
                if (fm < 0.0) == (flo < 0.0) {
                    lo = mid;
                    flo = fm;
                } else {
                    hi = mid;
                }
            }
            if let Some(slot) = out.get_mut(n) {
                *slot = 0.5 * (lo + hi);
                n += 1;
            }
        }
        a = b;
        fa = fb;
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Run::time_of` (Newton in a bracket) agrees with plain bisection to full precision to
    /// within 1e-12 s, on 20,000 random cycles (1 ms, random p/v/a at both ends, reversals
    /// included) and random positions in each monotone run.
    #[test]
    fn crossing_times_agree_with_bisection() {
        let mut seed = 0x5eed_0004_7177_0001u64;
        let mut rnd = move || {
            seed ^= seed >> 12;
            seed ^= seed << 25;
            seed ^= seed >> 27;
            (seed.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut worst: f64 = 0.0;
        let mut runs = 0;
        for _ in 0..20_000 {
            let a = State {
                p: rnd() * 100.0,
                v: (rnd() - 0.5) * 2000.0,
                a: (rnd() - 0.5) * 40_000.0,
            };
            let (v1, a1) = ((rnd() - 0.5) * 2000.0, (rnd() - 0.5) * 40_000.0);
            let b = State {
                p: a.p + (a.v + v1) * 0.5e-3,
                v: v1,
                a: a1,
            };
            let m = AxisMotion::new(0, 1_000_000, a, b);
            m.for_each_run(|run| {
                if run.xa == run.xb {
                    return;
                }
                let x = run.xa + (0.02 + 0.96 * rnd()) * (run.xb - run.xa);
                let pc = &run.piece;
                let f = |s: f64| pc.p0 + pc.q(s) - x;
                let (mut lo, mut hi) = (run.sa, run.sb);
                let flo = f(lo);
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if mid <= lo || mid >= hi {
                        break;
                    }
                    if (f(mid) < 0.0) == (flo < 0.0) {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let exact = pc.time(0.5 * (lo + hi));
                worst = worst.max((run.time_of(x) - exact).abs());
                runs += 1;
            });
        }
        assert!(runs > 20_000, "{runs} runs");
        assert!(worst < 1e-12, "worst difference {worst:e} s");
    }

    #[test]
    fn roots_of_a_cubic() {
        // (s - 0.2)(s - 0.5)(s - 0.9)
        let c = [-0.09, 0.73, -1.6, 1.0];
        let mut r = [0.0; 5];
        let n = sign_change_roots(&c, &mut r);
        assert_eq!(n, 3);
        for (got, want) in r.iter().zip([0.2, 0.5, 0.9]) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
    }

    #[test]
    fn hermite_reproduces_a_cubic() {
        let j = 7.0;
        let s0 = State {
            p: 1.0,
            v: -2.0,
            a: 3.0,
        };
        let at = |t: f64| State {
            p: s0.p + t * (s0.v + t * (0.5 * s0.a + t * j / 6.0)),
            v: s0.v + t * (s0.a + 0.5 * t * j),
            a: s0.a + t * j,
        };
        let m = AxisMotion::new(0, 1_000_000, s0, at(1e-3));
        for i in 0..=10 {
            let t = i as f64 * 1e-4;
            assert!((m.at(t).p - at(t).p).abs() < 1e-14);
        }
    }
}
