//! Online trajectory generation in one degree of freedom.
//!
//! From any current state `(p, v, a)` the planner produces a time-optimal profile under velocity,
//! acceleration, deceleration and jerk limits, either to a target position at rest
//! ([`plan_position`]) or to a target velocity with zero acceleration ([`plan_velocity`]).
//! Jerk `0` means a trapezoidal profile (the acceleration may jump), as in the references
//! (S7-1500T Motion Control V4.0 function manual, 3.2.8.2 'Velocity profile').
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
pub const MAX_SEGMENTS: usize = 16;

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

impl std::error::Error for ProfileError {}

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
            p: s.p + dt * (s.v + dt * (0.5 * s.a + dt * j * (1.0 / 6.0))),
            v: s.v + dt * (s.a + 0.5 * dt * j),
            a: s.a + dt * j,
        }
    }
}

/// A planned profile: segments plus the exact end state, valid from its start for all `t >= 0`.
///
/// In this order (`repr(C)`): an evaluation reads the count, the duration and the end first,
/// then one segment, so they share cache lines with the first segments.
#[derive(Copy, Clone, Debug, PartialEq)]
#[repr(C)]
pub struct Profile {
    n: usize,
    duration: f64,
    end: State,
    segs: [Segment; MAX_SEGMENTS],
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

    /// The same profile moved by `delta` in position.
    pub fn shifted(mut self, delta: f64) -> Self {
        let n = self.n.min(MAX_SEGMENTS);
        for seg in self.segs.iter_mut().take(n) {
            seg.start.p += delta;
        }
        self.end.p += delta;
        self
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

/// Integrates the state exactly and records the first `N` segments (`N = 0` for the distance
/// evaluations of the solver, which need only the end state).
#[derive(Copy, Clone)]
struct Builder<const N: usize> {
    segs: [Segment; N],
    n: usize,
    t: f64,
    s: State,
    jerk: f64,
    /// `1 / jerk` and `0.5 / jerk` (0 for trapezoidal profiles).
    ij: f64,
    h_ij: f64,
    acc: f64,
    dec: f64,
}

impl<const N: usize> Builder<N> {
    #[inline(always)]
    fn new(s: State, lim: &Limits) -> Self {
        let jerk = effective_jerk(lim.jerk);
        Self {
            segs: [Segment::default(); N],
            n: 0,
            t: 0.0,
            s,
            jerk,
            ij: 1.0 / jerk,
            h_ij: 0.5 / jerk,
            acc: lim.acc,
            dec: lim.dec,
        }
    }

    fn trapezoidal(&self) -> bool {
        self.jerk.is_infinite()
    }

    /// Constant jerk `j` for `dt` seconds, from the current state (with acceleration `a`).
    #[inline(always)]
    fn push(&mut self, j: f64, dt: f64) {
        if dt <= 0.0 {
            return;
        }
        let seg = Segment {
            t0: self.t,
            start: self.s,
            jerk: j,
        };
        if self.n < N {
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

    /// Velocity reached if the acceleration is released to zero at full jerk now.
    #[inline]
    fn v_nat(&self) -> f64 {
        if self.trapezoidal() {
            self.s.v
        } else {
            self.s.v + self.s.a * self.s.a.abs() * self.h_ij
        }
    }

    /// Time-optimal change of velocity to `v1`, ending with `a = 0`.
    ///
    /// The acceleration bound depends on what the velocity does: `acc` while `|v|` grows,
    /// `dec` while it shrinks. A ramp that crosses zero velocity switches from one to the other
    /// at `v = 0` (see [`Builder::crossing`]).
    #[inline(always)]
    fn vel_ramp(&mut self, v1: f64) {
        let v0 = self.s.v;
        if self.trapezoidal() {
            let dv = v1 - v0;
            let s = if dv >= 0.0 { 1.0 } else { -1.0 };
            if s * v0 < 0.0 && s * v1 > 0.0 {
                // Brake to zero with the deceleration, then speed up with the acceleration.
                self.push_acc(s * self.dec, v0.abs() / self.dec);
                self.push_acc(s * self.acc, v1.abs() / self.acc);
            } else {
                let bound = if s * v0 >= 0.0 { self.acc } else { self.dec };
                self.push_acc(s * bound, dv.abs() / bound);
            }
            self.s.v = v1;
            self.s.a = 0.0;
            return;
        }
        let a0 = self.s.a;
        let vn = self.v_nat();
        let dvn = v1 - vn;
        if dvn == 0.0 {
            let s = if a0 > 0.0 { -1.0 } else { 1.0 };
            self.push(s * self.jerk, a0.abs() * self.ij);
        } else {
            let s = if dvn > 0.0 { 1.0 } else { -1.0 };
            // In the ramp's direction: the lowest velocity on the way and the target.
            let vmin = (s * v0).min(s * vn);
            let v1s = s * v1;
            if v1s > 0.0 && vmin < 0.0 && self.acc != self.dec && self.crossing(s, v1s) {
                // Now at v = 0 with the crossing acceleration; speeding up from here.
                self.ramp_plain(s, v1, self.acc);
            } else {
                // The plateau lies where the velocity (in the ramp's direction) is negative:
                // braking (dec); or positive: speeding up (acc). Equal bounds need no switch.
                let bound = if v1s <= 0.0 {
                    self.dec
                } else if vmin >= 0.0 {
                    self.acc
                } else {
                    self.acc.min(self.dec)
                };
                self.ramp_plain(s, v1, bound);
            }
        }
        self.s.v = v1;
        self.s.a = 0.0;
    }

    /// The part of a ramp in direction `s` that reaches zero velocity, when the bound switches
    /// there from `dec` (braking) to `acc` (speeding up). The acceleration when crossing zero is
    /// the largest that both bounds, the rest of the ramp (`v1s`, in direction `s`) and the
    /// start state allow; before it the ramp rises to at most `dec` and comes down to it.
    /// Returns false (and changes nothing) when the start state cannot meet that (it already
    /// carries more acceleration than the crossing allows); the caller then uses one bound.
    #[inline(always)]
    fn crossing(&mut self, s: f64, v1s: f64) -> bool {
        let (j, ij, hij) = (self.jerk, self.ij, self.h_ij);
        let vs0 = s * self.s.v;
        let as0 = s * self.s.a;
        let b1 = self.dec;
        if as0 > b1 {
            return false;
        }
        // Velocity to gain (in direction s) up to zero, and the highest acceleration with which
        // zero can be reached after rising from as0 at full jerk.
        let g = -vs0;
        let reach_sq = (2.0 * j * g + as0 * as0).max(0.0);
        let a_star = b1
            .min(self.acc)
            .min((2.0 * j * v1s).sqrt())
            .min(reach_sq.sqrt());
        if as0 * as0 - 2.0 * j * g > a_star * a_star {
            return false;
        }
        let peak_sq = (reach_sq + a_star * a_star) * 0.5;
        if peak_sq <= b1 * b1 {
            let peak = peak_sq.sqrt();
            self.push(s * j, ((peak - as0) * ij).max(0.0));
            self.push(-s * j, ((peak - a_star) * ij).max(0.0));
        } else {
            let t2 = ((g - (2.0 * b1 * b1 - as0 * as0 - a_star * a_star) * hij) / b1).max(0.0);
            self.push(s * j, (b1 - as0) * ij);
            self.push(0.0, t2);
            self.push(-s * j, (b1 - a_star) * ij);
        }
        self.s.v = 0.0;
        self.s.a = s * a_star;
        true
    }

    /// The peak velocity (in direction `s`, signed result) beyond which the ramp from the current
    /// state to it holds the acceleration bound `acc`, so that its distance is quadratic in the
    /// peak velocity. `vn` is the released velocity of the current state.
    fn saturation(&self, s: f64, vn: f64) -> f64 {
        let vs0 = s * self.s.v;
        let as0 = s * self.s.a;
        let crossing = vs0.min(s * vn) < 0.0 && self.acc != self.dec;
        let from_zero = if crossing {
            let reach_sq = (as0 * as0 - 2.0 * self.jerk * vs0).max(0.0);
            let a_star = self.dec.min(self.acc).min(reach_sq.sqrt());
            (2.0 * self.acc * self.acc - a_star * a_star) * self.h_ij
        } else {
            vs0 + (2.0 * self.acc * self.acc - as0 * as0) * self.h_ij
        };
        s * from_zero
    }

    /// A ramp in direction `s` to `v1` with one acceleration bound, from the current state.
    #[inline(always)]
    fn ramp_plain(&mut self, s: f64, v1: f64, bound: f64) {
        let (j, ij, hij) = (self.jerk, self.ij, self.h_ij);
        let a0s = s * self.s.a;
        let dv = s * (v1 - self.s.v);
        if a0s > bound {
            // Already beyond the bound in the ramp's direction: back to the bound first.
            let t1 = (a0s - bound) * ij;
            let dv1 = (a0s * a0s - bound * bound) * hij;
            let t3 = bound * ij;
            let t2 = ((dv - dv1 - bound * bound * hij) / bound).max(0.0);
            self.push(-s * j, t1);
            self.push(0.0, t2);
            self.push(-s * j, t3);
        } else {
            let peak_sq = ((2.0 * j * dv + a0s * a0s) * 0.5).max(0.0);
            if peak_sq <= bound * bound {
                let peak = peak_sq.sqrt();
                self.push(s * j, ((peak - a0s) * ij).max(0.0));
                self.push(-s * j, peak * ij);
            } else {
                let t1 = (bound - a0s) * ij;
                let dvj = (2.0 * bound * bound - a0s * a0s) * hij;
                let t2 = ((dv - dvj) / bound).max(0.0);
                self.push(s * j, t1);
                self.push(0.0, t2);
                self.push(-s * j, bound * ij);
            }
        }
    }

    /// Appends the profile of `fam` with parameter `x` (peak velocity or relaxation time).
    #[inline(always)]
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
    #[inline(always)]
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
fn recover<const N: usize>(b: &mut Builder<N>, vmax: f64) {
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
        b.push(s * b.jerk, (a.abs() - bound) * b.ij);
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
    let mut b = Builder::<0>::new(start, lim);
    b.apply(fam, x, 0.0);
    b.s.p - start.p
}

/// Solves `dpk(x) = d` for the peak velocity on `[a, b]` (`fa <= 0 <= fb` are the residuals
/// at the ends). `sat` are the peak velocities where the up-ramp and the down-ramp start to
/// saturate their acceleration bound; beyond both (away from zero velocity) the distance is
/// exactly quadratic in the peak velocity with second derivative `c2`, so the root there has a
/// closed form (the caller checks where the profile lands and otherwise asks again without it).
/// Elsewhere Brent's method runs on the narrowed bracket.
fn solve_peak(
    dpk: impl Fn(f64) -> f64,
    d: f64,
    (mut a, mut b): (f64, f64),
    (mut fa, mut fb): (f64, f64),
    shape: Shape,
    tol: f64,
) -> Option<f64> {
    let Shape {
        sat,
        c2,
        closed_form,
    } = shape;
    let (x0, x1) = if sat.0 <= sat.1 {
        (sat.0, sat.1)
    } else {
        (sat.1, sat.0)
    };
    for x in [x0, x1] {
        if x > a && x < b {
            let fx = dpk(x) - d;
            if fx <= 0.0 {
                a = x;
                fa = fx;
            } else {
                b = x;
                fb = fx;
            }
        }
    }
    let quadratic = if c2 > 0.0 { a >= x1 } else { b <= x0 };
    if closed_form && quadratic && b > a {
        return Some(quad_root((a, b), (fa, fb), c2));
    }
    brent(|x| dpk(x) - d, (a, b), (fa, fb), tol)
}

/// Where the distance becomes quadratic in the peak velocity (see [`solve_peak`]).
#[derive(Copy, Clone)]
struct Shape {
    /// Saturation points of the up-ramp and the down-ramp.
    sat: (f64, f64),
    /// Second derivative of the distance beyond both.
    c2: f64,
    /// Whether the closed form may be used.
    closed_form: bool,
}

/// Root in `[a, b]` of the quadratic with second derivative `c2` through `(a, fa)`, `(b, fb)`.
fn quad_root((a, b): (f64, f64), (fa, fb): (f64, f64), c2: f64) -> f64 {
    let w = b - a;
    let m = (fb - fa) / w - 0.5 * c2 * w;
    // 0.5 c2 h^2 + m h + fa = 0, the numerically stable pair of roots.
    let disc = (m * m - 2.0 * c2 * fa).max(0.0);
    let q = -0.5 * (m + disc.sqrt().copysign(m));
    let h1 = if q != 0.0 { fa / q } else { 0.0 };
    let h2 = if c2 != 0.0 { q / (0.5 * c2) } else { h1 };
    let h = if (0.0..=w).contains(&h1) { h1 } else { h2 };
    a + h.clamp(0.0, w)
}

/// Brent's method for an increasing `f` on `[a, b]` with `fa = f(a) <= 0 <= f(b) = fb`.
fn brent(
    mut f: impl FnMut(f64) -> f64,
    (mut a, mut b): (f64, f64),
    (mut fa, mut fb): (f64, f64),
    tol_f: f64,
) -> Option<f64> {
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

fn finish(mut b: Builder<MAX_SEGMENTS>, origin: f64, sigma: f64, end: State) -> Profile {
    let n = b.n.min(MAX_SEGMENTS);
    for seg in b.segs.iter_mut().take(n) {
        seg.start = State {
            p: origin + sigma * seg.start.p,
            v: sigma * seg.start.v,
            a: sigma * seg.start.a,
        };
        seg.jerk *= sigma;
    }
    Profile {
        segs: b.segs,
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
    let probe = Builder::<0>::new(rel, lim);
    let sigma = if probe.v_nat() < 0.0 { -1.0 } else { 1.0 };
    let goal = sigma * (target - start.p);

    let mut pre = Builder::<MAX_SEGMENTS>::new(rel.mirrored(sigma), lim);
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

    let sub = State { p: 0.0, ..s0 };
    // The distance grows along the families: Peak(-vmax) <= Peak(0) = Relaxed(0) <=
    // Relaxed(tau_max) = Peak(vn) <= Peak(vmax). Evaluate only the brackets needed.
    let d_vn = dist(sub, lim, Family::Peak, vn);
    // Length scale of the motion (the net travel may be much shorter than the way there).
    let scale = goal.abs().max(s0.p.abs()).max(d_vn.abs()).max(1e-9);
    let choice = PositionChoice {
        sub,
        lim,
        pre: &pre,
        d,
        d_vn,
        vn,
        vmax,
        tau_max,
        trap,
        tol: 1e-13 * scale,
    };
    let select = |closed_form: bool| choice.select(closed_form);

    // Replay: recovery prefix, then the chosen family, all in one recorded builder. A closed-form
    // root that does not land (a breakpoint formula did not hold) is solved again iteratively.
    let (fam, x, cruise) = select(true)?;
    let mut b = pre;
    b.apply(fam, x, cruise);
    if (b.s.p - goal).abs() > 1e-10 * scale {
        let (fam, x, cruise) = select(false)?;
        b = pre;
        b.apply(fam, x, cruise);
    }
    if b.n > MAX_SEGMENTS {
        return Err(ProfileError::NoSolution);
    }
    Ok(finish(b, start.p, sigma, State::rest(target)))
}

/// The choice of the family and its parameter for [`plan_position`]: the distance `d` still to
/// go after the recovery prefix `pre` (ending in `sub`, at position 0), and the peak-family
/// distance `d_vn` at the natural velocity `vn`.
struct PositionChoice<'a> {
    sub: State,
    lim: &'a Limits,
    pre: &'a Builder<MAX_SEGMENTS>,
    d: f64,
    d_vn: f64,
    vn: f64,
    vmax: f64,
    tau_max: f64,
    trap: bool,
    tol: f64,
}

impl PositionChoice<'_> {
    /// The distance of the peak family with peak velocity `x`.
    fn dpk(&self, x: f64) -> f64 {
        dist(self.sub, self.lim, Family::Peak, x)
    }

    /// `(family, parameter, cruise)` that reaches `d`; `closed_form` allows the closed-form
    /// root of the peak family.
    fn select(&self, closed_form: bool) -> Result<(Family, f64, f64), ProfileError> {
        if self.d > self.d_vn {
            self.select_beyond_natural(closed_form)
        } else {
            self.select_within_natural(closed_form)
        }
    }

    /// `d` beyond the natural peak: a higher peak velocity (up to `vmax`, then a cruise).
    fn select_beyond_natural(&self, closed_form: bool) -> Result<(Family, f64, f64), ProfileError> {
        let (d, d_vn, vn, vmax, pre) = (self.d, self.d_vn, self.vn, self.vmax, self.pre);
        let d_pos = self.dpk(vmax);
        if d >= d_pos {
            return Ok((Family::Peak, vmax, (d - d_pos) / vmax));
        }
        // Where the up-ramp and the down-ramp start to saturate their bounds.
        let (x_up, x_dn) = if self.trap {
            (vn, 0.0)
        } else {
            (pre.saturation(1.0, vn), pre.dec * pre.dec * pre.ij)
        };
        let c2 = 1.0 / pre.acc + 1.0 / pre.dec;
        let x = solve_peak(
            |x| self.dpk(x),
            d,
            (vn, vmax),
            (d_vn - d, d_pos - d),
            Shape {
                sat: (x_up, x_dn),
                c2,
                closed_form,
            },
            self.tol,
        )
        .ok_or(ProfileError::NoSolution)?;
        Ok((Family::Peak, x, 0.0))
    }

    /// `d` up to the natural peak: a relaxed acceleration, the natural peak, or a lower (down
    /// to `-vmax`, then a cruise) peak velocity.
    fn select_within_natural(&self, closed_form: bool) -> Result<(Family, f64, f64), ProfileError> {
        let (d, d_vn, vn, vmax, pre) = (self.d, self.d_vn, self.vn, self.vmax, self.pre);
        let d_zero = self.dpk(0.0);
        if d > d_zero {
            if self.tau_max > 0.0 && d < d_vn {
                let x = brent(
                    |x| dist(self.sub, self.lim, Family::Relaxed, x) - d,
                    (0.0, self.tau_max),
                    (d_zero - d, d_vn - d),
                    self.tol,
                )
                .ok_or(ProfileError::NoSolution)?;
                return Ok((Family::Relaxed, x, 0.0));
            }
            return Ok((Family::Peak, vn, 0.0));
        }
        let d_neg = self.dpk(-vmax);
        if d <= d_neg {
            return Ok((Family::Peak, -vmax, (d_neg - d) / vmax));
        }
        let (x_up, x_dn) = if self.trap {
            (0.0, 0.0)
        } else {
            (pre.saturation(-1.0, vn), -pre.dec * pre.dec * pre.ij)
        };
        let c2 = -(1.0 / pre.acc + 1.0 / pre.dec);
        let x = solve_peak(
            |x| self.dpk(x),
            d,
            (-vmax, 0.0),
            (d_neg - d, d_zero - d),
            Shape {
                sat: (x_up, x_dn),
                c2,
                closed_form,
            },
            self.tol,
        )
        .ok_or(ProfileError::NoSolution)?;
        Ok((Family::Peak, x, 0.0))
    }
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
    let mut b = Builder::<MAX_SEGMENTS>::new(rel, lim);
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

/// Plans a time-optimal profile from `start` to the target position `target`, reached with the
/// velocity `end_v` and zero acceleration (PLCopen Motion Control Part 1, 'BufferMode': the
/// seam of two blended jobs). `end_v = 0` is exactly [`plan_position`]. An `|end_v|` above
/// `lim.vel` is reached in the final ramp: the profile keeps `|v| <= lim.vel` until then.
///
/// The families are those of [`plan_position`] with the end velocity `end_v` in place of rest:
/// a direct ramp to `end_v`, a relaxed deceleration then the ramp, or a peak velocity (up to
/// `lim.vel`, then a cruise) then the ramp down to `end_v`.
///
/// Inferred (the references do not say what happens when the seam velocity cannot be reached
/// within the distance): the profile never reverses to make room for it. When the distance is
/// too short to reach `end_v` going forward, the end velocity becomes the reachable one closest
/// to `end_v` (lower when the axis cannot speed up enough, higher when it cannot slow down
/// enough); when no forward profile reaches the target with `a = 0` at all, the profile ends at
/// rest as [`plan_position`] plans it. [`Profile::end`] tells the velocity actually planned.
///
/// Not proven time-optimal in one corner: speeding up to an end velocity above the released
/// velocity searches only the peak family (no "relaxed acceleration" family, the mirror of the
/// relaxed brake); the profile is within the limits and exact, possibly not the fastest.
#[doc(alias = "BufferMode")]
#[doc(alias = "mcBlendingLow")]
pub fn plan_position_velocity(
    start: State,
    target: f64,
    end_v: f64,
    lim: &Limits,
) -> Result<Profile, ProfileError> {
    check_limits(lim)?;
    if !finite_state(&start) || !target.is_finite() || !end_v.is_finite() {
        return Err(ProfileError::NonFiniteInput);
    }
    let want = end_v.abs();
    if want == 0.0 {
        return plan_position(start, target, lim);
    }
    if want <= lim.vel {
        return match plan_end(start, target, end_v, lim, None) {
            Some(p) => Ok(p),
            None => plan_position(start, target, lim),
        };
    }
    // Inferred: an end velocity above the velocity limit (PLCopen mcBlendingNext/High into a
    // faster job) is reached in the final ramp only: the job keeps to its limit until then.
    // If the distance is too short for that, the profile runs under the end velocity as limit.
    let sigma = if end_v < 0.0 { -1.0 } else { 1.0 };
    let mut up = Builder::<0>::new(
        State {
            p: 0.0,
            v: lim.vel,
            a: 0.0,
        },
        lim,
    );
    up.vel_ramp(want);
    let ramp = up.s.p;
    if let Some(p) = plan_end(
        start,
        target - sigma * ramp,
        sigma * lim.vel,
        lim,
        Some((target, end_v)),
    ) {
        return Ok(p);
    }
    let raised = Limits { vel: want, ..*lim };
    match plan_end(start, target, end_v, &raised, None) {
        Some(p) => Ok(p),
        None => plan_position(start, target, lim),
    }
}

/// [`plan_position_velocity`] with `0 < |end_v| <= lim.vel` (inputs checked); `then`: the
/// profile goes on from `(target, end_v)` with a ramp to the final `(target, end velocity)`.
/// `None` when no forward profile reaches the target with `a = 0` (or, with `then`, when the
/// end velocity had to be changed).
fn plan_end(
    start: State,
    target: f64,
    end_v: f64,
    lim: &Limits,
    then: Option<(f64, f64)>,
) -> Option<Profile> {
    let w = end_v.abs().min(lim.vel);
    let vmax = lim.vel;
    // Mirrored so that the end velocity is positive.
    let sigma = if end_v < 0.0 { -1.0 } else { 1.0 };
    let rel = State { p: 0.0, ..start }.mirrored(sigma);
    let goal = sigma * (then.map_or(target, |t| t.0) - start.p);
    let mut pre = Builder::<MAX_SEGMENTS>::new(rel, lim);
    if pre.v_nat() < -vmax {
        pre.vel_ramp(-vmax);
    } else {
        recover(&mut pre, vmax);
    }
    let s0 = pre.s;
    let d = sigma * (target - start.p) - s0.p;
    let sub = State { p: 0.0, ..s0 };
    let trap = pre.trapezoidal();
    let vn = if trap { s0.v } else { pre.v_nat() };
    let ends = EndChoice {
        sub,
        lim,
        d,
        w,
        vn,
        vmax,
        tau_max: if !trap && s0.a < 0.0 && w < vn {
            -s0.a / pre.jerk
        } else {
            0.0
        },
        tol: 1e-13 * goal.abs().max(s0.p.abs()).max(w * w / lim.dec).max(1e-9),
    };
    let (fam, x, cruise, w_end) = ends.select()?;
    let mut b = pre;
    b.apply_end(fam, x, cruise, w_end);
    let mut end = State {
        p: target,
        v: sigma * w_end,
        a: 0.0,
    };
    if let Some((final_target, final_v)) = then {
        if w_end != w {
            return None;
        }
        b.vel_ramp(sigma * final_v);
        end = State {
            p: final_target,
            v: final_v,
            a: 0.0,
        };
    }
    let scale = goal.abs().max(s0.p.abs()).max(1e-9);
    if (b.s.p - goal).abs() > 1e-10 * scale || b.n > MAX_SEGMENTS {
        // Not landed (a family was not monotonic where it was assumed to be).
        return None;
    }
    Some(finish(b, start.p, sigma, end))
}

/// The families of [`plan_position_velocity`] (mirrored frame, end velocity `w > 0`).
#[derive(Copy, Clone)]
enum EndFamily {
    /// Ramp to the peak velocity `x`, cruise, then ramp to the end velocity (`x = w`: the
    /// direct ramp).
    Peak,
    /// Release the deceleration for `x` seconds at full jerk, then ramp to the end velocity.
    Relaxed,
}

impl<const N: usize> Builder<N> {
    /// Appends the profile of `fam` with parameter `x` ending at velocity `w`, `a = 0`.
    #[inline(always)]
    fn apply_end(&mut self, fam: EndFamily, x: f64, cruise: f64, w: f64) {
        match fam {
            EndFamily::Peak => {
                self.vel_ramp(x);
                self.cruise(cruise);
            }
            EndFamily::Relaxed => self.push(self.jerk, x),
        }
        self.vel_ramp(w);
    }
}

/// The choice of the family for [`plan_position_velocity`]: the distance `d` to go from `sub`
/// (position 0), the end velocity `w > 0`, the released velocity `vn`.
struct EndChoice<'a> {
    sub: State,
    lim: &'a Limits,
    d: f64,
    w: f64,
    vn: f64,
    vmax: f64,
    /// The longest relaxation (> 0 only when decelerating towards an end velocity below `vn`).
    tau_max: f64,
    tol: f64,
}

impl EndChoice<'_> {
    fn dist(&self, fam: EndFamily, x: f64, w: f64) -> f64 {
        let mut b = Builder::<0>::new(self.sub, self.lim);
        b.apply_end(fam, x, 0.0, w);
        b.s.p
    }

    /// The distance of the direct ramp to the end velocity `w`.
    fn direct(&self, w: f64) -> f64 {
        self.dist(EndFamily::Peak, w, w)
    }

    /// `(family, parameter, cruise, end velocity)`, or `None` when no forward profile reaches
    /// the target with `a = 0`.
    fn select(&self) -> Option<(EndFamily, f64, f64, f64)> {
        let (d, w, vn, vmax) = (self.d, self.w, self.vn, self.vmax);
        let d_direct = self.direct(w);
        if d < d_direct {
            return self.reachable().map(|w2| (EndFamily::Peak, w2, 0.0, w2));
        }
        let lo = vn.max(w).min(vmax);
        let d_lo = self.dist(EndFamily::Peak, lo, w);
        if self.tau_max > 0.0 && d < d_lo {
            let x = brent(
                |x| self.dist(EndFamily::Relaxed, x, w) - d,
                (0.0, self.tau_max),
                (d_direct - d, d_lo - d),
                self.tol,
            )?;
            return Some((EndFamily::Relaxed, x, 0.0, w));
        }
        let d_hi = self.dist(EndFamily::Peak, vmax, w);
        if d >= d_hi {
            return Some((EndFamily::Peak, vmax, (d - d_hi) / vmax, w));
        }
        if d <= d_lo {
            return Some((EndFamily::Peak, lo, 0.0, w));
        }
        let x = brent(
            |x| self.dist(EndFamily::Peak, x, w) - d,
            (lo, vmax),
            (d_lo - d, d_hi - d),
            self.tol,
        )?;
        Some((EndFamily::Peak, x, 0.0, w))
    }

    /// The end velocity closest to `w` whose direct ramp ends exactly at `d` (the distance is
    /// too short for `w`): lower than `w` when the axis cannot speed up to it, higher when it
    /// cannot slow down to it. The direct ramp's distance is smallest at the released velocity.
    fn reachable(&self) -> Option<f64> {
        let (d, w) = (self.d, self.w);
        let pivot = self.vn.max(0.0).min(self.vmax);
        let d_pivot = self.direct(pivot);
        if d < d_pivot {
            return None;
        }
        let d_w = self.direct(w);
        let w2 = if w > pivot {
            brent(
                |x| self.direct(x) - d,
                (pivot, w),
                (d_pivot - d, d_w - d),
                self.tol,
            )?
        } else {
            // Decreasing in the end velocity on [w, pivot]: solve the mirrored residual.
            brent(
                |x| d - self.direct(x),
                (w, pivot),
                (d - d_w, d - d_pivot),
                self.tol,
            )?
        };
        (w2 > 0.0).then_some(w2)
    }
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
