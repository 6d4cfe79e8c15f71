//! The coupling laws of synchronous operation, as data: gearing (`offset + ratio * x`) and the
//! absolute synchronization of MC_GearInPos and MC_CamIn (a quintic of the leading value up to
//! the sync point), with the math that sizes the synchronization.

use crate::kinematics::profile::{Limits, State};
use crate::objects::axis::{SyncDirection, SyncProfileReference};
use crate::objects::leading::LeadingValue;

/// A quintic polynomial of the leading value, on `[x0, x0 + len]` (len may be negative).
#[derive(Copy, Clone, Debug, PartialEq)]
pub(in crate::objects::axis) struct Quintic {
    x0: f64,
    len: f64,
    c: [f64; 6],
}

impl Quintic {
    /// The quintic with value, first and second derivative (in x) given at both ends.
    pub(super) fn hermite(x0: f64, len: f64, start: (f64, f64, f64), end: (f64, f64, f64)) -> Self {
        let (p0, v0, a0) = (start.0, start.1 * len, start.2 * len * len);
        let (p1, v1, a1) = (end.0, end.1 * len, end.2 * len * len);
        let d = p1 - p0;
        let c = [
            p0,
            v0,
            0.5 * a0,
            10.0 * d - 6.0 * v0 - 4.0 * v1 - 0.5 * (3.0 * a0 - a1),
            -15.0 * d + 8.0 * v0 + 7.0 * v1 + 0.5 * (3.0 * a0 - 2.0 * a1),
            6.0 * d - 3.0 * (v0 + v1) - 0.5 * (a0 - a1),
        ];
        Self { x0, len, c }
    }

    /// The exact maxima of `|y''|` and `|y'''|` (in x) over the quintic: `y''` is a cubic in `u`
    /// with its extremes at the ends or where the quadratic `y'''` vanishes; `y'''` a quadratic.
    pub(super) fn peak_curvature_and_jerk(&self) -> [f64; 2] {
        let c = &self.c;
        let l = self.len;
        let ddu = |u: f64| 2.0 * c[2] + u * (6.0 * c[3] + u * (12.0 * c[4] + u * 20.0 * c[5]));
        let dddu = |u: f64| 6.0 * c[3] + u * (24.0 * c[4] + u * 60.0 * c[5]);
        let mut a = ddu(0.0).abs().max(ddu(1.0).abs());
        // Roots of y''' = 60 c5 u^2 + 24 c4 u + 6 c3.
        let (qa, qb, qc) = (60.0 * c[5], 24.0 * c[4], 6.0 * c[3]);
        let mut roots = [f64::NAN; 2];
        if qa.abs() > 1e-300 {
            let disc = qb * qb - 4.0 * qa * qc;
            if disc >= 0.0 {
                let r = disc.sqrt();
                roots = [(-qb + r) / (2.0 * qa), (-qb - r) / (2.0 * qa)];
            }
        } else if qb.abs() > 1e-300 {
            roots[0] = -qc / qb;
        }
        for u in roots.into_iter().filter(|u| (0.0..=1.0).contains(u)) {
            a = a.max(ddu(u).abs());
        }
        // y'''' = 120 c5 u + 24 c4 vanishes at one point.
        let mut j = dddu(0.0).abs().max(dddu(1.0).abs());
        if c[5].abs() > 1e-300 {
            let u = -24.0 * c[4] / (120.0 * c[5]);
            if (0.0..=1.0).contains(&u) {
                j = j.max(dddu(u).abs());
            }
        }
        [a / (l * l), j / (l * l * l).abs()]
    }

    /// The exact maximum of `|y'|` (in x): the quartic `y'` has its extremes at the ends or
    /// where the cubic `y''` vanishes; `y''` is monotonic between the roots of `y'''`, so each
    /// of its roots is bracketed and found by bisection.
    pub(super) fn peak_slope(&self) -> f64 {
        let c = &self.c;
        let du =
            |u: f64| c[1] + u * (2.0 * c[2] + u * (3.0 * c[3] + u * (4.0 * c[4] + u * 5.0 * c[5])));
        let ddu = |u: f64| 2.0 * c[2] + u * (6.0 * c[3] + u * (12.0 * c[4] + u * 20.0 * c[5]));
        let (qa, qb, qc) = (60.0 * c[5], 24.0 * c[4], 6.0 * c[3]);
        let mut cuts = [0.0, 1.0, 1.0, 1.0];
        let mut n = 1;
        if qa.abs() > 1e-300 {
            let disc = qb * qb - 4.0 * qa * qc;
            if disc >= 0.0 {
                let r = disc.sqrt();
                let (r1, r2) = ((-qb - r) / (2.0 * qa), (-qb + r) / (2.0 * qa));
                for u in [r1.min(r2), r1.max(r2)] {
                    if u > 0.0 && u < 1.0 {
                        cuts[n] = u;
                        n += 1;
                    }
                }
            }
        } else if qb.abs() > 1e-300 {
            let u = -qc / qb;
            if u > 0.0 && u < 1.0 {
                cuts[n] = u;
                n += 1;
            }
        }
        cuts[n] = 1.0;
        let mut m = du(0.0).abs().max(du(1.0).abs());
        for w in cuts[..=n].windows(2) {
            let (mut a, mut b) = (w[0], w[1]);
            let (fa, fb) = (ddu(a), ddu(b));
            if fa * fb > 0.0 {
                continue;
            }
            for _ in 0..36 {
                let mid = 0.5 * (a + b);
                if ddu(mid) * fa > 0.0 {
                    a = mid;
                } else {
                    b = mid;
                }
            }
            m = m.max(du(0.5 * (a + b)).abs());
        }
        m / self.len.abs()
    }

    /// Value, first, second and third derivative with respect to x.
    #[inline]
    pub(super) fn eval(&self, x: f64) -> [f64; 4] {
        let u = (x - self.x0) / self.len;
        let c = &self.c;
        let p = c[0] + u * (c[1] + u * (c[2] + u * (c[3] + u * (c[4] + u * c[5]))));
        let du = c[1] + u * (2.0 * c[2] + u * (3.0 * c[3] + u * (4.0 * c[4] + u * 5.0 * c[5])));
        let ddu = 2.0 * c[2] + u * (6.0 * c[3] + u * (12.0 * c[4] + u * 20.0 * c[5]));
        let dddu = 6.0 * c[3] + u * (24.0 * c[4] + u * 60.0 * c[5]);
        let l = self.len;
        [p, du / l, ddu / (l * l), dddu / (l * l * l)]
    }
}

/// The coupling law of a job.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(in crate::objects::axis) enum SyncLaw {
    /// MC_GearIn: synchronizing is a relative profile (follower minus ratio times leader) that
    /// brings relative velocity and acceleration to zero (kept in the axis' profile slot, which
    /// the synchronous goal does not otherwise use); then `offset + ratio * x`.
    Gear {
        offset: f64,
        /// The leading value of the previous cycle (velocity gearing integrates its velocity).
        prev: State,
    },
    /// MC_GearInPos: synchronizing follows a quintic of the leading value from `x_start` to
    /// `x_sync`; then `y_sync + ratio * (x - x_sync)`.
    GearPos {
        msp: f64,
        ssp: f64,
        /// Slope and curvature (in the leading value) of the follower at the sync point: the
        /// ratio and 0 for gearing, the scaled cam's for camming (MC_CamIn uses this law for
        /// its synchronization, then the cam map).
        slope: f64,
        curv: f64,
        reference: SyncProfileReference,
        msd: f64,
        direction: SyncDirection,
        /// Direction the leader travels in (+1 / -1), fixed when the job first sees it.
        lead_dir: f64,
        x_sync: f64,
        x_start: f64,
        y_sync: f64,
        quintic: Option<Quintic>,
    },
    /// MC_FlyingGear_BkPlcMc: ratio ramps in leader position, geared in between.
    Flying(super::flying::FlyingGear),
}

impl SyncLaw {
    /// The absolute synchronization (MC_GearInPos, MC_CamIn) to the follower value `ssp` with
    /// `(slope, curvature)` when the leader is at `msp`.
    pub(in crate::objects::axis) fn absolute(
        msp: f64,
        ssp: f64,
        (slope, curv): (f64, f64),
        reference: SyncProfileReference,
        msd: f64,
        direction: SyncDirection,
    ) -> Self {
        SyncLaw::GearPos {
            msp,
            ssp,
            slope,
            curv,
            reference,
            msd,
            direction,
            lead_dir: 0.0,
            x_sync: 0.0,
            x_start: 0.0,
            y_sync: 0.0,
            quintic: None,
        }
    }

    /// The follower's coordinates moved by `delta` (homing): the law moves with them.
    pub(in crate::objects::axis) fn shift_follower(&mut self, delta: f64) {
        match self {
            SyncLaw::Gear { offset, .. } => *offset += delta,
            SyncLaw::GearPos {
                y_sync, quintic, ..
            } => {
                *y_sync += delta;
                if let Some(q) = quintic {
                    q.c[0] += delta;
                }
            }
            SyncLaw::Flying(g) => g.shift_follower(delta),
        }
    }
}

/// The continuous representation of the follower sync position `ssp`: on a modulo follower the
/// one nearest to `natural` (where the follower would be if it were synchronous already) that
/// `direction` allows from `here`.
pub(super) fn target_rep(
    ssp: f64,
    modulo: Option<crate::kinematics::modulo::Modulo>,
    direction: SyncDirection,
    here: f64,
    natural: f64,
) -> f64 {
    let Some(m) = modulo else {
        return ssp;
    };
    let near = natural + m.shortest(natural, ssp);
    match direction {
        SyncDirection::Shortest => near,
        SyncDirection::Positive => {
            if near < here {
                near + m.length * ((here - near) / m.length).ceil()
            } else {
                near
            }
        }
        SyncDirection::Negative => {
            if near > here {
                near - m.length * ((near - here) / m.length).ceil()
            } else {
                near
            }
        }
    }
}

/// Synchronization length (leading value distance) for SyncProfileReference 0: the shortest
/// length for which the quintic synchronization at the leader's current velocity keeps the
/// follower within its velocity (or the synchronous velocity, if higher), acceleration and jerk.
pub(super) fn sync_length(
    follower: State,
    (g, curv): (f64, f64),
    lv: LeadingValue,
    lim: &Limits,
    (cycle, hint): (f64, f64),
    target: impl Fn(f64) -> f64,
) -> f64 {
    let v = lv.v.abs();
    let vmax = lim.vel.max((g * lv.v).abs()).max(follower.v.abs());
    let amax = lim.acc.min(lim.dec);
    let (d1, d2) = (
        follower.v / lv.v,
        (follower.a - follower.v / lv.v * lv.a) / (lv.v * lv.v),
    );
    let dir = lv.v.signum();
    let jmax = lim.jerk;
    let within = |l: f64| -> bool {
        let q = Quintic::hermite(0.0, dir * l, (follower.p, d1, d2), (target(l), g, curv));
        let [y2max, y3max] = q.peak_curvature_and_jerk();
        (y2max * v * v) <= amax * (1.0 + 1e-9)
            && (jmax == 0.0 || y3max * v * v * v <= jmax * (1.0 + 1e-9))
            && q.peak_slope() * v <= vmax * (1.0 + 1e-9)
    };
    // The synchronization starts in the cycle before the leader reaches the start, so the
    // length used is up to one cycle of leader travel longer; check that end too (the peak of
    // the quintic is not monotonic in its length).
    let step = v * cycle;
    let feasible = |l: f64| within(l) && within(l + step);
    // From the last length (a warm start, 1/4 around it) or by growing from a small one until
    // feasible; then bisection. The result is always a feasible length (slightly above the
    // shortest one, to 1/2^16 of the bracket).
    let (mut lo, mut hi) = (0.0, 0.0);
    if hint > 0.0 && feasible(hint * 1.25) {
        hi = hint * 1.25;
        lo = if feasible(hint * 0.8) {
            0.0
        } else {
            hint * 0.8
        };
        if lo == 0.0 {
            hi = hint * 0.8;
        }
    }
    if hi == 0.0 {
        hi = (v * v / amax).max(v * 1e-3).max(1e-9);
        let mut n = 0;
        while !feasible(hi) && n < 60 {
            hi *= 2.0;
            n += 1;
        }
        lo = if n == 0 { 0.0 } else { hi / 2.0 };
    }
    for _ in 0..16 {
        let mid = 0.5 * (lo + hi);
        if feasible(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quintic_meets_its_boundary_conditions() {
        let q = Quintic::hermite(10.0, -4.0, (1.0, 0.5, 0.25), (7.0, 2.0, -1.0));
        let [p0, d0, a0, _] = q.eval(10.0);
        let [p1, d1, a1, _] = q.eval(6.0);
        for (x, y) in [
            (p0, 1.0),
            (d0, 0.5),
            (a0, 0.25),
            (p1, 7.0),
            (d1, 2.0),
            (a1, -1.0),
        ] {
            assert!((x - y).abs() < 1e-12, "{x} vs {y}");
        }
    }

    #[test]
    fn target_representation_respects_the_direction() {
        let m = crate::kinematics::modulo::Modulo {
            start: 0.0,
            length: 360.0,
        };
        assert_eq!(
            target_rep(10.0, Some(m), SyncDirection::Shortest, 0.0, 355.0),
            370.0
        );
        assert_eq!(
            target_rep(10.0, Some(m), SyncDirection::Negative, 0.0, 355.0),
            10.0 - 360.0
        );
        assert_eq!(
            target_rep(10.0, Some(m), SyncDirection::Positive, 400.0, 355.0),
            730.0
        );
        assert_eq!(
            target_rep(10.0, None, SyncDirection::Positive, 400.0, 355.0),
            10.0
        );
    }
}
