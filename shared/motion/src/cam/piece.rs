//! The pieces an interpolated cam is made of, and the interpolation of point chains (cubic
//! spline, monotone Bézier, linear, quintic transition).

use core::f64::consts::PI;

use super::{CamValue, MotionLaw};

/// What a piece of the interpolated cam comes from.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum PieceSource {
    /// (Part of) the segment with this index in [`super::CamDefinition::segments`].
    Segment(usize),
    /// Interpolated: between two points, or a transition across a gap.
    Interpolated,
}

/// The formula of a piece in its source parameter `t`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(crate) enum Formula {
    /// `y = Σ c[k]·tᵏ`.
    Poly([f64; 8]),
    /// `y = y0 + dy·s(t)`.
    Law { law: MotionLaw, y0: f64, dy: f64 },
    /// `y = Σ a[k]·tᵏ + amp·sin(w·t + phase)`, `t` the absolute leading value.
    S7 {
        a: [f64; 7],
        amp: f64,
        w: f64,
        phase: f64,
    },
}

/// One piece on `[xa, xb]`: `t = t0 + (x − xa)·k`, `y = formula(t)`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(crate) struct Piece {
    pub xa: f64,
    pub xb: f64,
    pub t0: f64,
    pub k: f64,
    pub formula: Formula,
    pub source: PieceSource,
}

/// `p(t)`, `p'(t)`, `p''(t)` of `Σ c[k]·tᵏ` (Horner).
#[inline]
fn horner<const N: usize>(c: &[f64; N], t: f64) -> (f64, f64, f64) {
    let mut p = c[N - 1];
    let mut d = 0.0;
    let mut dd = 0.0;
    for &ck in c[..N - 1].iter().rev() {
        dd = dd * t + d;
        d = d * t + p;
        p = p * t + ck;
    }
    (p, d, 2.0 * dd)
}

impl Piece {
    /// Value and derivatives with respect to `x` at `x` (not range-checked).
    #[inline]
    pub fn eval(&self, x: f64) -> CamValue {
        let t = self.t0 + (x - self.xa) * self.k;
        let (f, f1, f2) = match self.formula {
            Formula::Poly(c) => horner(&c, t),
            Formula::Law { law, y0, dy } => {
                let s = law.eval(t);
                (
                    y0 + dy * s.value,
                    dy * s.first_derivative,
                    dy * s.second_derivative,
                )
            }
            Formula::S7 { a, amp, w, phase } => {
                let (p, d, dd) = horner(&a, t);
                if amp == 0.0 {
                    (p, d, dd)
                } else {
                    let (sn, cs) = (w * t + phase).sin_cos();
                    (p + amp * sn, d + amp * w * cs, dd - amp * w * w * sn)
                }
            }
        };
        CamValue {
            value: f,
            first_derivative: f1 * self.k,
            second_derivative: f2 * self.k * self.k,
        }
    }

    /// The polynomial piece of a cubic Hermite span from `(xa, ya, ma)` to `(xb, yb, mb)`.
    pub fn hermite3(xa: f64, ya: f64, ma: f64, xb: f64, yb: f64, mb: f64) -> Piece {
        let h = xb - xa;
        let d = yb - ya;
        let (va, vb) = (h * ma, h * mb);
        Piece::local(
            xa,
            xb,
            [
                ya,
                va,
                3.0 * d - 2.0 * va - vb,
                -2.0 * d + va + vb,
                0.0,
                0.0,
                0.0,
                0.0,
            ],
        )
    }

    /// The quintic Hermite span matching value, slope and curvature at both ends.
    pub fn hermite5(xa: f64, a: CamValue, xb: f64, b: CamValue) -> Piece {
        let h = xb - xa;
        let d = b.value - a.value;
        let (va, vb) = (h * a.first_derivative, h * b.first_derivative);
        let (aa, ab) = (h * h * a.second_derivative, h * h * b.second_derivative);
        Piece::local(
            xa,
            xb,
            [
                a.value,
                va,
                0.5 * aa,
                10.0 * d - 6.0 * va - 4.0 * vb - 1.5 * aa + 0.5 * ab,
                -15.0 * d + 8.0 * va + 7.0 * vb + 1.5 * aa - ab,
                6.0 * d - 3.0 * va - 3.0 * vb - 0.5 * aa + 0.5 * ab,
                0.0,
                0.0,
            ],
        )
    }

    /// The straight line from `(xa, ya)` to `(xb, yb)`.
    pub fn line(xa: f64, ya: f64, xb: f64, yb: f64) -> Piece {
        Piece::local(xa, xb, [ya, yb - ya, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    }

    /// A polynomial piece in `t = (x − xa)/(xb − xa)`.
    fn local(xa: f64, xb: f64, c: [f64; 8]) -> Piece {
        Piece {
            xa,
            xb,
            t0: 0.0,
            k: 1.0 / (xb - xa),
            formula: Formula::Poly(c),
            source: PieceSource::Interpolated,
        }
    }

    /// The S7 formula for a period length (`w = 2π/period`; no sine when the amplitude is 0).
    pub fn s7_formula(a: [f64; 7], amp: f64, period: f64, phase: f64) -> Formula {
        if amp == 0.0 {
            Formula::S7 {
                a,
                amp: 0.0,
                w: 0.0,
                phase: 0.0,
            }
        } else {
            Formula::S7 {
                a,
                amp,
                w: 2.0 * PI / period,
                phase,
            }
        }
    }
}

/// End condition of a cubic spline chain.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(crate) enum End {
    /// `y'' = 0`.
    Natural,
    /// Prescribed first derivative.
    Slope(f64),
}

/// Slopes `m[i]` of the C2 cubic spline through `(xs[i], ys[i])` (Hermite form), solving the
/// strictly diagonally dominant tridiagonal system with the Thomas algorithm.
pub(crate) fn spline_slopes(xs: &[f64], ys: &[f64], left: End, right: End) -> Vec<f64> {
    let n = xs.len();
    let last = n - 1;
    let h: Vec<f64> = xs.windows(2).map(|w| w[1] - w[0]).collect();
    let del: Vec<f64> = (0..last).map(|i| (ys[i + 1] - ys[i]) / h[i]).collect();
    let mut a = vec![0.0; n];
    let mut b = vec![0.0; n];
    let mut c = vec![0.0; n];
    let mut d = vec![0.0; n];
    match left {
        End::Natural => {
            b[0] = 2.0;
            c[0] = 1.0;
            d[0] = 3.0 * del[0];
        }
        End::Slope(s) => {
            b[0] = 1.0;
            d[0] = s;
        }
    }
    for i in 1..last {
        a[i] = h[i];
        b[i] = 2.0 * (h[i - 1] + h[i]);
        c[i] = h[i - 1];
        d[i] = 3.0 * (h[i] * del[i - 1] + h[i - 1] * del[i]);
    }
    match right {
        End::Natural => {
            a[last] = 1.0;
            b[last] = 2.0;
            d[last] = 3.0 * del[last - 1];
        }
        End::Slope(s) => {
            b[last] = 1.0;
            d[last] = s;
        }
    }
    // Thomas algorithm.
    let mut cp = vec![0.0; n];
    let mut dp = vec![0.0; n];
    cp[0] = c[0] / b[0];
    dp[0] = d[0] / b[0];
    for i in 1..n {
        let w = b[i] - a[i] * cp[i - 1];
        cp[i] = c[i] / w;
        dp[i] = (d[i] - a[i] * dp[i - 1]) / w;
    }
    let mut m = vec![0.0; n];
    m[last] = dp[last];
    for i in (0..last).rev() {
        m[i] = dp[i] - cp[i] * m[i + 1];
    }
    m
}

/// Second derivative of the Hermite spline at its first knot.
pub(crate) fn spline_start_curvature(xs: &[f64], ys: &[f64], m: &[f64]) -> f64 {
    let h = xs[1] - xs[0];
    let del = (ys[1] - ys[0]) / h;
    (6.0 * del - 4.0 * m[0] - 2.0 * m[1]) / h
}

/// Second derivative of the Hermite spline at its last knot.
pub(crate) fn spline_end_curvature(xs: &[f64], ys: &[f64], m: &[f64]) -> f64 {
    let n = xs.len();
    let h = xs[n - 1] - xs[n - 2];
    let del = (ys[n - 1] - ys[n - 2]) / h;
    (-6.0 * del + 2.0 * m[n - 2] + 4.0 * m[n - 1]) / h
}

/// Clamps a Bézier end slope into `[min(0, 3δ), max(0, 3δ)]`: then both inner control points of
/// the span lie inside the span's y range (so does the curve, by the convex-hull property).
pub(crate) fn clip_slope(m: f64, secant: f64) -> f64 {
    let lim = 3.0 * secant;
    m.clamp(lim.min(0.0), lim.max(0.0))
}

/// The unconstrained one-sided slope estimate at an end knot (three-point formula of PCHIP),
/// clipped by [`clip_slope`]. `h0`/`d0` belong to the end span, `h1`/`d1` to its neighbour.
pub(crate) fn bezier_end_slope(h0: f64, d0: f64, h1: Option<(f64, f64)>) -> f64 {
    match h1 {
        None => d0,
        Some((h1, d1)) => clip_slope(((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1), d0),
    }
}

/// Slopes of the monotone (range-preserving) C1 Bézier chain: Brodlie's weighted harmonic mean
/// at interior knots (0 at local extrema), prescribed or one-sided estimates at the ends, all
/// clipped by [`clip_slope`].
pub(crate) fn bezier_slopes(
    xs: &[f64],
    ys: &[f64],
    left: Option<f64>,
    right: Option<f64>,
) -> Vec<f64> {
    let n = xs.len();
    let last = n - 1;
    let h: Vec<f64> = xs.windows(2).map(|w| w[1] - w[0]).collect();
    let del: Vec<f64> = (0..last).map(|i| (ys[i + 1] - ys[i]) / h[i]).collect();
    let mut m = vec![0.0; n];
    for i in 1..last {
        let (d0, d1) = (del[i - 1], del[i]);
        if d0 * d1 > 0.0 {
            let (h0, h1) = (h[i - 1], h[i]);
            let w1 = 2.0 * h1 + h0;
            let w2 = h1 + 2.0 * h0;
            m[i] = (w1 + w2) / (w1 / d0 + w2 / d1);
        }
    }
    m[0] = match left {
        Some(s) => clip_slope(s, del[0]),
        None => bezier_end_slope(h[0], del[0], (last > 1).then(|| (h[1], del[1]))),
    };
    m[last] = match right {
        Some(s) => clip_slope(s, del[last - 1]),
        None => bezier_end_slope(
            h[last - 1],
            del[last - 1],
            (last > 1).then(|| (h[last - 2], del[last - 2])),
        ),
    };
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-10 * (1.0 + a.abs().max(b.abs()))
    }

    #[test]
    fn hermite_pieces_match_their_end_conditions() {
        let a = CamValue {
            value: 1.0,
            first_derivative: -2.0,
            second_derivative: 3.0,
        };
        let b = CamValue {
            value: 4.0,
            first_derivative: 0.5,
            second_derivative: -7.0,
        };
        let p = Piece::hermite5(2.0, a, 3.5, b);
        let (ea, eb) = (p.eval(2.0), p.eval(3.5));
        assert!(close(ea.value, 1.0) && close(ea.first_derivative, -2.0));
        assert!(close(ea.second_derivative, 3.0));
        assert!(close(eb.value, 4.0) && close(eb.first_derivative, 0.5));
        assert!(close(eb.second_derivative, -7.0));
        let q = Piece::hermite3(-1.0, 2.0, 1.0, 1.0, -2.0, 3.0);
        let (qa, qb) = (q.eval(-1.0), q.eval(1.0));
        assert!(close(qa.value, 2.0) && close(qa.first_derivative, 1.0));
        assert!(close(qb.value, -2.0) && close(qb.first_derivative, 3.0));
    }

    #[test]
    fn natural_spline_of_a_line_is_the_line() {
        let xs = [0.0, 1.0, 3.0, 3.5];
        let ys = [1.0, 3.0, 7.0, 8.0];
        let m = spline_slopes(&xs, &ys, End::Natural, End::Natural);
        for mi in m {
            assert!(close(mi, 2.0));
        }
    }

    #[test]
    fn bezier_slopes_stay_in_the_allowed_cone() {
        let xs = [0.0, 0.1, 1.0, 1.2, 3.0, 3.1];
        let ys = [0.0, 5.0, 5.5, 9.0, 2.0, 2.0];
        let m = bezier_slopes(&xs, &ys, Some(1e9), None);
        for i in 0..xs.len() - 1 {
            let d = (ys[i + 1] - ys[i]) / (xs[i + 1] - xs[i]);
            for s in [m[i], m[i + 1]] {
                assert!(s * d >= 0.0 && s.abs() <= 3.0 * d.abs() + 1e-12, "{i}");
            }
        }
    }
}
