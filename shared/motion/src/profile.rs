//! Online trajectory generation in one degree of freedom.
//!
//! From any current state `(p, v, a)` the planner produces a time-optimal profile under velocity,
//! acceleration, deceleration and jerk limits, either to a target position at rest
//! ([`plan_position`]) or to a target velocity with zero acceleration ([`plan_velocity`]).
//! Jerk `0` means a trapezoidal profile (the acceleration may jump), as in the references
//! (seed 001 §4.1).
//!
//! # Limit semantics
//! As in S7-1500T, `acc` bounds `|a|` while `|v|` increases and `dec` bounds `|a|` while `|v|`
//! decreases. A velocity ramp that crosses zero velocity is planned with the smaller of the two
//! for its whole length (a conservative simplification: the exact optimum would switch bounds at
//! `v = 0`). This deviation is listed in `docs/motion-engine.md`.
//!
//! # Method
//! Every time-optimal rest-to-rest or state-to-rest profile is a velocity ramp to a peak velocity
//! `v_p` (reached with `a = 0`), an optional cruise at `|v_p| = v_max`, and a ramp down to rest,
//! except for one family that never touches `a = 0` between the start and the brake (the "relaxed
//! brake": release the current deceleration for a time `tau`, then brake). The travelled distance
//! is monotonic along the ordered union of these families, so the planner brackets the target
//! distance and solves one scalar equation by Brent's method on closed-form segment integrals.
//! The result is at most [`MAX_SEGMENTS`] constant-jerk segments, stored inline: planning and
//! evaluation never allocate.
//!
//! A start state that violates the limits (|v| above `v_max` after the acceleration has been
//! released, or |a| above its bound) is first brought back within them as fast as the limits
//! allow (full jerk towards the bound, full deceleration down to `v_max`), then the plan continues
//! from there.

/// Maximum number of constant-jerk segments in one profile.
pub const MAX_SEGMENTS: usize = 12;

/// Kinematic state of one degree of freedom.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct State {
    /// Position.
    pub p: f64,
    /// Velocity.
    pub v: f64,
    /// Acceleration.
    pub a: f64,
}

impl State {
    /// A state at rest at `p`.
    pub const fn rest(p: f64) -> Self {
        Self { p, v: 0.0, a: 0.0 }
    }

    fn mirrored(self, sigma: f64) -> Self {
        Self {
            p: sigma * self.p,
            v: sigma * self.v,
            a: sigma * self.a,
        }
    }
}

/// Dynamic limits of one profile.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Limits {
    /// Maximum velocity magnitude, > 0.
    pub vel: f64,
    /// Maximum acceleration (while |v| increases), > 0.
    pub acc: f64,
    /// Maximum deceleration (while |v| decreases), > 0.
    pub dec: f64,
    /// Maximum jerk, > 0; `0` (or infinity) means trapezoidal.
    pub jerk: f64,
}

/// Why a profile could not be planned. Planning never changes anything on error.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum ProfileError {
    /// An input (start state or target) is NaN or infinite.
    NonFiniteInput,
    /// A limit is not positive and finite (jerk may also be 0 or infinite).
    InvalidLimit(LimitKind),
    /// The scalar solver did not converge (should not happen; reported rather than guessed).
    NoSolution,
}

/// Which limit of [`Limits`] an error refers to.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum LimitKind {
    /// `Limits::vel`.
    Velocity,
    /// `Limits::acc`.
    Acceleration,
    /// `Limits::dec`.
    Deceleration,
    /// `Limits::jerk`.
    Jerk,
}

impl core::fmt::Display for ProfileError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NonFiniteInput => write!(f, "start state or target is not a finite number"),
            Self::InvalidLimit(k) => write!(f, "{k:?} limit must be positive and finite"),
            Self::NoSolution => write!(f, "no profile found (solver did not converge)"),
        }
    }
}

/// One constant-jerk piece of a profile, starting at `t0` (s, from the profile start).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct Segment {
    /// Start time relative to the profile start.
    pub t0: f64,
    /// State at `t0`.
    pub start: State,
    /// Constant jerk over the segment.
    pub jerk: f64,
}

impl Segment {
    #[inline]
    fn eval(&self, dt: f64) -> State {
        let s = self.start;
        let j = self.jerk;
        State {
            p: s.p + dt * (s.v + dt * (0.5 * s.a + dt * j / 6.0)),
            v: s.v + dt * (s.a + 0.5 * dt * j),
            a: s.a + dt * j,
        }
    }
}

/// A planned profile: segments plus the exact end state, valid from its start for all `t >= 0`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Profile {
    segs: [Segment; MAX_SEGMENTS],
    n: usize,
    duration: f64,
    end: State,
}

impl Profile {
    /// A profile that stays at `state` with its acceleration dropped (for rest: stays at rest).
    pub fn hold(state: State) -> Self {
        Self {
            segs: [Segment::default(); MAX_SEGMENTS],
            n: 0,
            duration: 0.0,
            end: State { a: 0.0, ..state },
        }
    }

    /// Total duration (s).
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// The state at the end of the profile (target reached).
    pub fn end(&self) -> State {
        self.end
    }

    /// The segments of the profile.
    pub fn segments(&self) -> &[Segment] {
        &self.segs[..self.n.min(MAX_SEGMENTS)]
    }

    /// The state at time `t` from the profile start. Before 0 the start state, after the end the
    /// end state extrapolated with its (constant) velocity.
    #[inline]
    pub fn at(&self, t: f64) -> State {
        if t >= self.duration || self.n == 0 {
            let dt = (t - self.duration).max(0.0);
            return State {
                p: self.end.p + self.end.v * dt,
                v: self.end.v,
                a: 0.0,
            };
        }
        let segs = self.segments();
        let mut i = segs.len() - 1;
        while i > 0 && segs[i].t0 > t {
            i -= 1;
        }
        let seg = &segs[i];
        seg.eval((t - seg.t0).max(0.0))
    }
}

/// Accumulates segments (when `REC`) and integrates the state exactly.
struct Builder<const REC: bool> {
    segs: [Segment; MAX_SEGMENTS],
    n: usize,
    t: f64,
    s: State,
    jerk: f64,
    acc: f64,
    dec: f64,
}

impl<const REC: bool> Builder<REC> {
    fn new(s: State, lim: &Limits) -> Self {
        Self {
            segs: [Segment::default(); MAX_SEGMENTS],
            n: 0,
            t: 0.0,
            s,
            jerk: effective_jerk(lim.jerk),
            acc: lim.acc,
            dec: lim.dec,
        }
    }

    fn trapezoidal(&self) -> bool {
        self.jerk.is_infinite()
    }

    /// Constant jerk `j` for `dt` seconds, from the current state (with acceleration `a`).
    #[inline]
    fn push(&mut self, j: f64, dt: f64) {
        if dt <= 0.0 {
            return;
        }
        let seg = Segment {
            t0: self.t,
            start: self.s,
            jerk: j,
        };
        if REC && self.n < MAX_SEGMENTS {
            self.segs[self.n] = seg;
        }
        self.n += 1;
        self.s = seg.eval(dt);
        self.t += dt;
    }

    /// Constant acceleration `a` (a jump if the current one differs; trapezoidal only).
    #[inline]
    fn push_acc(&mut self, a: f64, dt: f64) {
        self.s.a = a;
        self.push(0.0, dt);
        self.s.a = 0.0;
    }

    /// Acceleration bound for a plateau of sign `s` over the velocity interval `[lo, hi]`.
    #[inline]
    fn bound(&self, s: f64, lo: f64, hi: f64) -> f64 {
        if lo >= 0.0 {
            if s > 0.0 {
                self.acc
            } else {
                self.dec
            }
        } else if hi <= 0.0 {
            if s > 0.0 {
                self.dec
            } else {
                self.acc
            }
        } else {
            self.acc.min(self.dec)
        }
    }

    /// Velocity reached if the acceleration is released to zero at full jerk now.
    #[inline]
    fn v_nat(&self) -> f64 {
        if self.trapezoidal() {
            self.s.v
        } else {
            self.s.v + self.s.a * self.s.a.abs() / (2.0 * self.jerk)
        }
    }

    /// Time-optimal change of velocity to `v1`, ending with `a = 0`.
    fn vel_ramp(&mut self, v1: f64) {
        let v0 = self.s.v;
        if self.trapezoidal() {
            let dv = v1 - v0;
            let s = if dv >= 0.0 { 1.0 } else { -1.0 };
            let bound = self.bound(s, v0.min(v1), v0.max(v1));
            self.push_acc(s * bound, dv.abs() / bound);
            self.s.v = v1;
            self.s.a = 0.0;
            return;
        }
        let j = self.jerk;
        let a0 = self.s.a;
        let vn = self.v_nat();
        let dvn = v1 - vn;
        if dvn == 0.0 {
            let s = if a0 > 0.0 { -1.0 } else { 1.0 };
            self.push(s * j, a0.abs() / j);
        } else {
            let s = if dvn > 0.0 { 1.0 } else { -1.0 };
            let lo = v0.min(vn).min(v1);
            let hi = v0.max(vn).max(v1);
            let bound = self.bound(s, lo, hi);
            let a0s = s * a0;
            let dv = s * (v1 - v0);
            if a0s > bound {
                // Already beyond the bound in the ramp's direction: back to the bound first.
                let t1 = (a0s - bound) / j;
                let dv1 = (a0s * a0s - bound * bound) / (2.0 * j);
                let t3 = bound / j;
                let t2 = ((dv - dv1 - bound * bound / (2.0 * j)) / bound).max(0.0);
                self.push(-s * j, t1);
                self.push(0.0, t2);
                self.push(-s * j, t3);
            } else {
                let peak_sq = (2.0 * j * dv + a0s * a0s) * 0.5;
                let peak = peak_sq.max(0.0).sqrt();
                if peak <= bound {
                    self.push(s * j, ((peak - a0s) / j).max(0.0));
                    self.push(-s * j, peak / j);
                } else {
                    let t1 = (bound - a0s) / j;
                    let dvj = (bound * bound - a0s * a0s) / (2.0 * j) + bound * bound / (2.0 * j);
                    let t2 = ((dv - dvj) / bound).max(0.0);
                    self.push(s * j, t1);
                    self.push(0.0, t2);
                    self.push(-s * j, bound / j);
                }
            }
        }
        self.s.v = v1;
        self.s.a = 0.0;
    }

    /// Appends the profile of `fam` with parameter `x` (peak velocity or relaxation time).
    fn apply(&mut self, fam: Family, x: f64, cruise: f64) {
        match fam {
            Family::Peak => {
                self.vel_ramp(x);
                self.cruise(cruise);
            }
            Family::Relaxed => self.push(self.jerk, x),
        }
        self.vel_ramp(0.0);
    }

    /// Cruise at the current velocity for `dt`.
    fn cruise(&mut self, dt: f64) {
        self.s.a = 0.0;
        self.push(0.0, dt);
    }
}

fn effective_jerk(j: f64) -> f64 {
    if j == 0.0 || j.is_infinite() {
        f64::INFINITY
    } else {
        j
    }
}

fn check_limits(lim: &Limits) -> Result<(), ProfileError> {
    let ok = |x: f64| x.is_finite() && x > 0.0;
    if !ok(lim.vel) {
        return Err(ProfileError::InvalidLimit(LimitKind::Velocity));
    }
    if !ok(lim.acc) {
        return Err(ProfileError::InvalidLimit(LimitKind::Acceleration));
    }
    if !ok(lim.dec) {
        return Err(ProfileError::InvalidLimit(LimitKind::Deceleration));
    }
    if lim.jerk.is_nan() || lim.jerk < 0.0 {
        return Err(ProfileError::InvalidLimit(LimitKind::Jerk));
    }
    Ok(())
}

fn finite_state(s: &State) -> bool {
    s.p.is_finite() && s.v.is_finite() && s.a.is_finite()
}

/// Brings a state that violates the acceleration bound or whose released velocity exceeds
/// `vmax` back within the limits, as fast as the limits allow (mirrored frame, `v_nat >= 0`).
fn recover<const REC: bool>(b: &mut Builder<REC>, vmax: f64) {
    if b.v_nat() > vmax {
        b.vel_ramp(vmax);
        return;
    }
    if b.trapezoidal() {
        return;
    }
    let a = b.s.a;
    let v = b.s.v;
    // Bound of the current acceleration: speeding up (a and v of one sign) uses acc, else dec.
    let bound = if a * v > 0.0 { b.acc } else { b.dec };
    if a.abs() > bound {
        let s = if a > 0.0 { -1.0 } else { 1.0 };
        b.push(s * b.jerk, (a.abs() - bound) / b.jerk);
    }
}

/// The families of state-to-rest profiles, in the mirrored frame (`v_nat >= 0`).
#[derive(Copy, Clone)]
enum Family {
    /// Peak velocity `v_p` then brake (with a cruise of the given length at the peak).
    Peak,
    /// Release the acceleration for `tau` seconds at full jerk, then brake.
    Relaxed,
}

#[inline]
fn dist(start: State, lim: &Limits, fam: Family, x: f64) -> f64 {
    let mut b = Builder::<false>::new(start, lim);
    b.apply(fam, x, 0.0);
    b.s.p - start.p
}

/// Brent's method for an increasing `f` on `[a, b]` with `f(a) <= 0 <= f(b)`.
fn brent(mut f: impl FnMut(f64) -> f64, mut a: f64, mut b: f64, tol_f: f64) -> Option<f64> {
    let mut fa = f(a);
    let mut fb = f(b);
    if fa.abs() <= tol_f {
        return Some(a);
    }
    if fb.abs() <= tol_f {
        return Some(b);
    }
    if fa * fb > 0.0 {
        return None;
    }
    let mut c = a;
    let mut fc = fa;
    let mut d = b - a;
    let mut e = d;
    for _ in 0..200 {
        if fb * fc > 0.0 {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol_x = 2.0 * f64::EPSILON * b.abs() + 1e-300;
        let m = 0.5 * (c - b);
        if fb.abs() <= tol_f || m.abs() <= tol_x {
            return Some(b);
        }
        if e.abs() >= tol_x && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * m * s;
                q = 1.0 - s;
            } else {
                let qq = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * m * qq * (qq - r) - (b - a) * (r - 1.0));
                q = (qq - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * m * q - (tol_x * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        } else {
            d = m;
            e = m;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol_x {
            d
        } else {
            tol_x.copysign(m)
        };
        fb = f(b);
    }
    Some(b)
}

fn finish<const REC: bool>(b: Builder<REC>, origin: f64, sigma: f64, end: State) -> Profile {
    let mut segs = [Segment::default(); MAX_SEGMENTS];
    let n = b.n.min(MAX_SEGMENTS);
    for (dst, src) in segs.iter_mut().zip(b.segs.iter()).take(n) {
        *dst = Segment {
            t0: src.t0,
            start: State {
                p: origin + sigma * src.start.p,
                v: sigma * src.start.v,
                a: sigma * src.start.a,
            },
            jerk: sigma * src.jerk,
        };
    }
    Profile {
        segs,
        n,
        duration: b.t,
        end,
    }
}

/// Plans a time-optimal profile from `start` to rest at `target`.
#[doc(alias = "MC_MoveAbsolute")]
pub fn plan_position(start: State, target: f64, lim: &Limits) -> Result<Profile, ProfileError> {
    check_limits(lim)?;
    if !finite_state(&start) || !target.is_finite() {
        return Err(ProfileError::NonFiniteInput);
    }
    let vmax = lim.vel;
    // Work relative to the start position, mirrored so that the released velocity is >= 0.
    let rel = State { p: 0.0, ..start };
    let probe = Builder::<false>::new(rel, lim);
    let sigma = if probe.v_nat() < 0.0 { -1.0 } else { 1.0 };
    let goal = sigma * (target - start.p);

    let mut pre = Builder::<true>::new(rel.mirrored(sigma), lim);
    recover(&mut pre, vmax);
    let s0 = pre.s;
    let d = goal - s0.p;
    let trap = pre.trapezoidal();
    let vn = if trap { s0.v } else { pre.v_nat() };
    let tau_max = if !trap && s0.a < 0.0 {
        -s0.a / pre.jerk
    } else {
        0.0
    };

    let scale = goal.abs().max(s0.p.abs()).max(1e-9);
    let tol = 1e-13 * scale;

    let sub = State { p: 0.0, ..s0 };
    let d_neg = dist(sub, lim, Family::Peak, -vmax);
    let d_zero = dist(sub, lim, Family::Peak, 0.0);
    let d_vn = dist(sub, lim, Family::Peak, vn);
    let d_pos = dist(sub, lim, Family::Peak, vmax);

    let (fam, x, cruise) = if d >= d_pos {
        (Family::Peak, vmax, (d - d_pos) / vmax)
    } else if d <= d_neg {
        (Family::Peak, -vmax, (d_neg - d) / vmax)
    } else if d <= d_zero {
        let x = brent(|x| dist(sub, lim, Family::Peak, x) - d, -vmax, 0.0, tol)
            .ok_or(ProfileError::NoSolution)?;
        (Family::Peak, x, 0.0)
    } else if d < d_vn && tau_max > 0.0 {
        let x = brent(
            |x| dist(sub, lim, Family::Relaxed, x) - d,
            0.0,
            tau_max,
            tol,
        )
        .ok_or(ProfileError::NoSolution)?;
        (Family::Relaxed, x, 0.0)
    } else if d <= d_vn {
        (Family::Peak, vn, 0.0)
    } else {
        let x = brent(|x| dist(sub, lim, Family::Peak, x) - d, vn, vmax, tol)
            .ok_or(ProfileError::NoSolution)?;
        (Family::Peak, x, 0.0)
    };

    // Replay: recovery prefix, then the chosen family, all in one recorded builder.
    let mut b = pre;
    b.apply(fam, x, cruise);
    if b.n > MAX_SEGMENTS {
        return Err(ProfileError::NoSolution);
    }
    Ok(finish(b, start.p, sigma, State::rest(target)))
}

/// Plans a time-optimal profile from `start` to the velocity `target_v` with zero acceleration.
/// `|target_v|` above `lim.vel` is clamped to it (the caller reports the warning).
#[doc(alias = "MC_MoveVelocity")]
pub fn plan_velocity(start: State, target_v: f64, lim: &Limits) -> Result<Profile, ProfileError> {
    check_limits(lim)?;
    if !finite_state(&start) || !target_v.is_finite() {
        return Err(ProfileError::NonFiniteInput);
    }
    let vt = target_v.clamp(-lim.vel, lim.vel);
    let rel = State { p: 0.0, ..start };
    let mut b = Builder::<true>::new(rel, lim);
    b.vel_ramp(vt);
    let end_p = b.s.p;
    if b.n > MAX_SEGMENTS {
        return Err(ProfileError::NoSolution);
    }
    Ok(finish(
        b,
        start.p,
        1.0,
        State {
            p: start.p + end_p,
            v: vt,
            a: 0.0,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lim(vel: f64, acc: f64, dec: f64, jerk: f64) -> Limits {
        Limits {
            vel,
            acc,
            dec,
            jerk,
        }
    }

    #[test]
    fn rest_to_rest_symmetric_known_answer() {
        // v=100, a=1000, j=10000, distance 1000: t_j = 0.1, t_a = 0.1 (ramp reaches v in
        // 0.2 s over 10 units... ) total = distance/v + v/a + a/j = 10 + 0.1 + 0.1.
        let p = plan_position(
            State::rest(0.0),
            1000.0,
            &lim(100.0, 1000.0, 1000.0, 10000.0),
        )
        .unwrap();
        assert!((p.duration() - 10.2).abs() < 1e-9, "{}", p.duration());
        let e = p.at(p.duration() - 1e-12);
        assert!((e.p - 1000.0).abs() < 1e-9);
    }

    #[test]
    fn trapezoid_known_answer() {
        // v=100, acc=1000, dec=500: duration = d/v + v/(2acc) + v/(2dec) = 10 + 0.05 + 0.1.
        let p = plan_position(State::rest(0.0), 1000.0, &lim(100.0, 1000.0, 500.0, 0.0)).unwrap();
        assert!((p.duration() - 10.15).abs() < 1e-9, "{}", p.duration());
    }

    #[test]
    fn velocity_ramp_known_answer() {
        // 0 -> 100 with a = 1000, j = 10000: t = v/a + a/j = 0.2.
        let p = plan_velocity(
            State::rest(0.0),
            100.0,
            &lim(200.0, 1000.0, 1000.0, 10000.0),
        )
        .unwrap();
        assert!((p.duration() - 0.2).abs() < 1e-12);
        assert_eq!(p.end().v, 100.0);
    }

    #[test]
    fn rejects_bad_limits_and_inputs() {
        assert_eq!(
            plan_position(State::rest(0.0), 1.0, &lim(0.0, 1.0, 1.0, 1.0)),
            Err(ProfileError::InvalidLimit(LimitKind::Velocity))
        );
        assert_eq!(
            plan_position(State::rest(0.0), f64::NAN, &lim(1.0, 1.0, 1.0, 1.0)),
            Err(ProfileError::NonFiniteInput)
        );
    }
}
