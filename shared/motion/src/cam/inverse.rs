//! `MC_GetCamLeadingValue`: the leading value for a following value.
//!
//! At build time every piece is split at the zeros of its first derivative into monotonic
//! *runs* (the derivative is sampled at 64 sub-intervals per piece and sign changes are refined by
//! bisection). A query then needs one root per run, found by Newton's method safeguarded by the
//! run's bracket. On a monotonic cam the runs are sorted in y as well, and the query is a binary
//! search: O(log n).

use super::piece::Piece;
use super::{Cam, CamError, Monotonicity};

/// Sub-intervals per piece when looking for zeros of the first derivative.
const SAMPLES: usize = 64;

/// A monotonic part `[xa, xb]` of piece `piece` with its end values.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(crate) struct Run {
    pub xa: f64,
    pub xb: f64,
    pub ya: f64,
    pub yb: f64,
    pub piece: usize,
}

impl Run {
    fn y_lo(&self) -> f64 {
        self.ya.min(self.yb)
    }

    fn y_hi(&self) -> f64 {
        self.ya.max(self.yb)
    }
}

/// The monotonic runs of all pieces, in x order.
pub(crate) fn runs(pieces: &[Piece]) -> Vec<Run> {
    let mut out = Vec::with_capacity(pieces.len());
    let mut crit = Vec::new();
    for (index, p) in pieces.iter().enumerate() {
        crit.clear();
        critical_points(p, &mut crit);
        crit.push(p.xb);
        let mut a = p.xa;
        let mut ya = p.eval(a).value;
        for &c in &crit {
            if c > a {
                let yc = p.eval(c).value;
                out.push(Run {
                    xa: a,
                    xb: c,
                    ya,
                    yb: yc,
                    piece: index,
                });
                a = c;
                ya = yc;
            }
        }
    }
    out
}

/// Interior zeros of `y'` on the piece where `y'` changes sign, in increasing order.
fn critical_points(p: &Piece, out: &mut Vec<f64>) {
    let h = (p.xb - p.xa) / SAMPLES as f64;
    let slope = |x: f64| p.eval(x).first_derivative;
    let mut last_sign = 0.0;
    let mut last_x = p.xa;
    let mut zero_at: Option<f64> = None;
    for j in 0..=SAMPLES {
        let x = if j == SAMPLES {
            p.xb
        } else {
            p.xa + j as f64 * h
        };
        let v = slope(x);
        if v == 0.0 {
            zero_at.get_or_insert(x);
            continue;
        }
        let s = v.signum();
        if last_sign != 0.0 && s != last_sign {
            let c = zero_at.unwrap_or_else(|| bisect(&slope, last_x, x, last_sign));
            if c > p.xa && c < p.xb {
                out.push(c);
            }
        }
        last_sign = s;
        last_x = x;
        zero_at = None;
    }
}

/// A zero of `f` in `[lo, hi]` where `sign(f(lo)) = sign_lo = −sign(f(hi))`.
fn bisect(f: &impl Fn(f64) -> f64, mut lo: f64, mut hi: f64, sign_lo: f64) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        let v = f(mid);
        if v == 0.0 {
            return mid;
        }
        if v.signum() == sign_lo {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// `v` limited to `[a, b]` (never panics, `a` wins if `a > b`).
fn clamp_between(v: f64, a: f64, b: f64) -> f64 {
    if v <= a {
        a
    } else if v >= b {
        b.max(a)
    } else {
        v
    }
}

impl Cam {
    /// `true` when the run is constant (within the y tolerance).
    fn is_flat(&self, r: &Run) -> bool {
        (r.yb - r.ya).abs() <= self.y_tol
    }

    /// The root of `y(x) = y` on a strictly monotonic run: safeguarded Newton.
    fn solve_run(&self, r: &Run, y: f64) -> f64 {
        let Some(p) = self.pieces.get(r.piece) else {
            return r.xa;
        };
        let sg = if r.yb > r.ya { 1.0 } else { -1.0 };
        let ga = (r.ya - y) * sg;
        let gb = (r.yb - y) * sg;
        if ga >= 0.0 {
            return r.xa;
        }
        if gb <= 0.0 {
            return r.xb;
        }
        let (mut lo, mut hi) = (r.xa, r.xb);
        let scale = r.xa.abs().max(r.xb.abs()).max(r.xb - r.xa);
        let mut x = lo + (hi - lo) * (-ga / (gb - ga));
        if !(x > lo && x < hi) {
            x = 0.5 * (lo + hi);
        }
        let mut prev_step = f64::INFINITY;
        for _ in 0..200 {
            let v = p.eval(x);
            let g = (v.value - y) * sg;
            // Within the rounding noise of the evaluation: as exact as it gets.
            let noise = 2.0 * f64::EPSILON * (y.abs() + v.value.abs());
            if g.abs() <= noise {
                return x;
            }
            if g < 0.0 {
                lo = x;
            } else {
                hi = x;
            }
            let mut nx = x - g / (v.first_derivative * sg);
            let newton = nx > lo && nx < hi;
            if !newton {
                nx = 0.5 * (lo + hi);
            }
            let step = (nx - x).abs();
            if step <= 2.0 * f64::EPSILON * scale || nx <= lo || nx >= hi {
                return nx;
            }
            // Newton that no longer shrinks its step is bouncing in the noise.
            if newton && step >= prev_step {
                return x;
            }
            prev_step = if newton { step } else { f64::INFINITY };
            x = nx;
        }
        x
    }

    /// The lowest and the highest root on a run (equal unless the run is flat).
    fn run_roots(&self, r: &Run, y: f64) -> (f64, f64) {
        if self.is_flat(r) {
            (r.xa, r.xb)
        } else {
            let x = self.solve_run(r, y);
            (x, x)
        }
    }

    /// Monotonic cam: binary search for the runs that contain `y`; the solution set is the
    /// interval between the lowest and the highest root.
    pub(super) fn leading_monotonic(&self, y: f64, approach: f64) -> Result<f64, CamError> {
        let dir = if self.monotonicity == Monotonicity::NonIncreasing {
            -1.0
        } else {
            1.0
        };
        let z = dir * y;
        let tol = self.y_tol;
        let lo_z = |r: &Run| (dir * r.ya).min(dir * r.yb);
        let hi_z = |r: &Run| (dir * r.ya).max(dir * r.yb);
        let lo = self.runs.partition_point(|r| hi_z(r) < z - tol);
        let hi = self.runs.partition_point(|r| lo_z(r) <= z + tol);
        if lo >= hi {
            return Err(CamError::NoLeadingValue);
        }
        let (Some(first), Some(last)) = (self.runs.get(lo), self.runs.get(hi - 1)) else {
            return Err(CamError::NoLeadingValue);
        };
        let (a, _) = self.run_roots(first, y);
        let (_, b) = self.run_roots(last, y);
        Ok(clamp_between(approach, a, b))
    }

    /// Any cam: every run whose y range contains `y` gives a candidate; the nearest to
    /// `approach` wins, ties (within the x tolerance) go to the lower one.
    pub(super) fn leading_scan(&self, y: f64, approach: f64) -> Result<f64, CamError> {
        let tol = self.y_tol;
        let tie = self.x_tol;
        let mut best: Option<(f64, f64)> = None;
        for r in &self.runs {
            if let Some((_, bd)) = best {
                if r.xa - approach > bd + tie {
                    break;
                }
            }
            if y < r.y_lo() - tol || y > r.y_hi() + tol {
                continue;
            }
            let lower_bound = if approach < r.xa {
                r.xa - approach
            } else if approach > r.xb {
                approach - r.xb
            } else {
                0.0
            };
            if let Some((_, bd)) = best {
                if lower_bound > bd + tie {
                    continue;
                }
            }
            let x = if self.is_flat(r) {
                clamp_between(approach, r.xa, r.xb)
            } else {
                self.solve_run(r, y)
            };
            let d = (x - approach).abs();
            match best {
                Some((_, bd)) if d >= bd - tie => {}
                _ => best = Some((x, d)),
            }
        }
        best.map(|(x, _)| x).ok_or(CamError::NoLeadingValue)
    }
}
