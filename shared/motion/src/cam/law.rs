//! Normalized motion laws of VDI 2143 ("Bewegungsgesetze für Kurvengetriebe").
//!
//! Every law is a function `s(u)` on `u ∈ [0, 1]` with `s(0) = 0` and `s(1) = 1`, given with its
//! closed-form first and second derivatives `s'(u)` and `s''(u)`. A [`super::SegmentDef::Law`]
//! maps a law onto the box `[x0, x1] × [y0, y1]`:
//! `y(x) = y0 + (y1 − y0)·s(u)`, `u = (x − x0)/(x1 − x0)`, so
//! `y' = (y1 − y0)/(x1 − x0)·s'(u)` and `y'' = (y1 − y0)/(x1 − x0)²·s''(u)`.

use core::f64::consts::PI;

use super::CamValue;

/// `∫₀¹ g` of the modified-trapezoid acceleration shape `g` (see [`mat_shape`]).
const MAT_G1: f64 = 0.5 + 1.0 / PI;

/// A normalized VDI 2143 motion law on `u ∈ [0, 1]` (`s(0) = 0`, `s(1) = 1`).
///
/// Boundary values (normalized; R = dwell `v = a = 0`, G = constant velocity `v ≠ 0, a = 0`,
/// U = reversal `v = 0, a ≠ 0`, VDI 2143 working ranges) and characteristic values
/// (`Cv = max |s'|`, `Ca = max |s''|`):
///
/// | Law | s'(0), s''(0) | s'(1), s''(1) | Cv | Ca | smoothness inside |
/// |---|---|---|---|---|---|
/// | [`StraightLine`](MotionLaw::StraightLine) | 1, 0 (G) | 1, 0 (G) | 1 | 0 | C∞ |
/// | [`QuadraticParabola`](MotionLaw::QuadraticParabola) | 0, 4 | 0, −4 | 2 | 4 | C1 (s'' jumps at ½) |
/// | [`Poly5`](MotionLaw::Poly5) (3-4-5) | 0, 0 (R) | 0, 0 (R) | 15/8 = 1.875 | 10/√3 ≈ 5.7735 | C∞ |
/// | [`SimpleSine`](MotionLaw::SimpleSine) (harmonic) | 0, π²/2 (U) | 0, −π²/2 (U) | π/2 | π²/2 | C∞ |
/// | [`Cycloid`](MotionLaw::Cycloid) | 0, 0 (R) | 0, 0 (R) | 2 | 2π | C∞ |
/// | [`ModifiedSine`](MotionLaw::ModifiedSine) | 0, 0 (R) | 0, 0 (R) | 4π/(4+π) ≈ 1.7596 | 4π²/(4+π) ≈ 5.5280 | C2 |
/// | [`ModifiedTrapezoid`](MotionLaw::ModifiedTrapezoid) | 0, 0 (R) | 0, 0 (R) | 2 | 8π/(π+2) ≈ 4.8881 | C2 |
/// | [`ModifiedAccelerationTrapezoid`](MotionLaw::ModifiedAccelerationTrapezoid) `{λ}` | 0, 0 (R) | 0, 0 (R) | 2 | 2/(min(λ,1−λ)·(½+1/π)) | C2 |
/// | [`InclinedSine`](MotionLaw::InclinedSine) `{v}` | v, 0 | v, 0 | max(\|v\|, \|2−v\|) | 2π·\|1−v\| | C∞ |
/// | [`Poly7`](MotionLaw::Poly7) (4-5-6-7) | 0, 0 (R), s‴ = 0 | 0, 0 (R), s‴ = 0 | 35/16 = 2.1875 | 84/(5√5) ≈ 7.5132 | C∞ |
///
/// All laws except `StraightLine`, `InclinedSine` (`v ≠ 0`) and `ModifiedAccelerationTrapezoid`
/// (`λ ≠ ½`) are point-symmetric: `s(1 − u) = 1 − s(u)`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum MotionLaw {
    /// Straight line (Gerade), `s = u`. G-G: `s' = 1`, `s'' = 0` everywhere.
    StraightLine,
    /// Quadratic parabola (quadratische Parabel): `s = 2u²` for `u < ½`, `1 − 2(1−u)²` after.
    /// `s'(0) = s'(1) = 0`; the acceleration is `+4` then `−4`, so it jumps at 0, ½ and 1
    /// (minimum `Ca` of all rest-in-rest laws, infinite jerk).
    QuadraticParabola,
    /// Polynomial of degree 5, "3-4-5": `s = 10u³ − 15u⁴ + 6u⁵`. R-R (`s' = s'' = 0` at both ends).
    Poly5,
    /// Simple sine / harmonic (einfache Sinuslinie): `s = (1 − cos πu)/2`. `s' = 0` at the ends but
    /// `s'' = ±π²/2` there (U-U; an acceleration jump when joined to a dwell).
    SimpleSine,
    /// Cycloid (Sinoide, "inclined sine" of the rest-in-rest case):
    /// `s = u − sin(2πu)/(2π)`. R-R.
    Cycloid,
    /// Modified sine (modifizierte Sinuslinie, VDI 2143 form): sine acceleration quarter-waves on
    /// `[0, ⅛]` and `[⅞, 1]`, a three-quarter sine wave of the third frequency in between. R-R.
    ModifiedSine,
    /// Modified trapezoid (modifiziertes Beschleunigungstrapez, symmetric): acceleration ramps
    /// of sine quarter-waves of width ⅛, constant plateaus on `[⅛, ⅜]` and `[⅝, ⅞]`. R-R.
    /// The same as [`MotionLaw::ModifiedAccelerationTrapezoid`] with `λ = ½`.
    ModifiedTrapezoid,
    /// Modified acceleration trapezoid with its turning point (Wendepunkt, the zero crossing of
    /// the acceleration) at `u = λ`, `0 < λ < 1` (the Siemens editor's "Lambda"). The
    /// acceleration phase `[0, λ]` and the deceleration phase `[λ, 1]` each are a trapezoid with
    /// sine ramps over a quarter of the phase. R-R; `Cv = 2` for every `λ`, `s(λ) = λ`.
    ModifiedAccelerationTrapezoid {
        /// Turning point, `0 < λ < 1`.
        lambda: f64,
    },
    /// Inclined sine (geneigte Sinuslinie) for constant velocity in constant velocity with the
    /// same normalized velocity `v` at both ends: a full sine period of acceleration on an
    /// inclined line, `s = u − (1 − v)·sin(2πu)/(2π)`. `s' = v`, `s'' = 0` at both ends. `v = 0`
    /// is the [`MotionLaw::Cycloid`], `v = 1` the [`MotionLaw::StraightLine`].
    InclinedSine {
        /// Normalized end velocity `s'(0) = s'(1)` (finite; the law is monotonic for
        /// `0 ≤ v ≤ 2`).
        velocity: f64,
    },
    /// Polynomial of degree 7, "4-5-6-7": `s = 35u⁴ − 84u⁵ + 70u⁶ − 20u⁷`. R-R with zero jerk at
    /// both ends.
    Poly7,
}

impl MotionLaw {
    /// The laws without a parameter, plus the two parametrized ones at `λ = ½` and `v = ½`
    /// (for iteration in tests and tools).
    pub const EXAMPLES: [MotionLaw; 10] = [
        MotionLaw::StraightLine,
        MotionLaw::QuadraticParabola,
        MotionLaw::Poly5,
        MotionLaw::SimpleSine,
        MotionLaw::Cycloid,
        MotionLaw::ModifiedSine,
        MotionLaw::ModifiedTrapezoid,
        MotionLaw::ModifiedAccelerationTrapezoid { lambda: 0.5 },
        MotionLaw::InclinedSine { velocity: 0.5 },
        MotionLaw::Poly7,
    ];

    /// The snake_case name used by the text formats (`law = "poly5"`).
    pub const fn name(&self) -> &'static str {
        match self {
            MotionLaw::StraightLine => "straight_line",
            MotionLaw::QuadraticParabola => "quadratic_parabola",
            MotionLaw::Poly5 => "poly5",
            MotionLaw::SimpleSine => "simple_sine",
            MotionLaw::Cycloid => "cycloid",
            MotionLaw::ModifiedSine => "modified_sine",
            MotionLaw::ModifiedTrapezoid => "modified_trapezoid",
            MotionLaw::ModifiedAccelerationTrapezoid { .. } => "modified_acceleration_trapezoid",
            MotionLaw::InclinedSine { .. } => "inclined_sine",
            MotionLaw::Poly7 => "poly7",
        }
    }

    /// The law's parameter (`λ` or `v`), `None` for laws without one.
    pub const fn parameter(&self) -> Option<f64> {
        match self {
            MotionLaw::ModifiedAccelerationTrapezoid { lambda } => Some(*lambda),
            MotionLaw::InclinedSine { velocity } => Some(*velocity),
            _ => None,
        }
    }

    /// The law for a [`name`](Self::name) and its parameter. `modified_acceleration_trapezoid`
    /// takes `λ` (default ½), `inclined_sine` requires `v`; the other laws take none. `None`
    /// for an unknown name, a missing required parameter, a parameter given to a law without
    /// one, or an invalid parameter (see [`is_valid`](Self::is_valid)).
    pub fn from_name(name: &str, parameter: Option<f64>) -> Option<MotionLaw> {
        let law = match (name, parameter) {
            ("straight_line", None) => MotionLaw::StraightLine,
            ("quadratic_parabola", None) => MotionLaw::QuadraticParabola,
            ("poly5", None) => MotionLaw::Poly5,
            ("simple_sine", None) => MotionLaw::SimpleSine,
            ("cycloid", None) => MotionLaw::Cycloid,
            ("modified_sine", None) => MotionLaw::ModifiedSine,
            ("modified_trapezoid", None) => MotionLaw::ModifiedTrapezoid,
            ("modified_acceleration_trapezoid", p) => MotionLaw::ModifiedAccelerationTrapezoid {
                lambda: p.unwrap_or(0.5),
            },
            ("inclined_sine", Some(v)) => MotionLaw::InclinedSine { velocity: v },
            ("poly7", None) => MotionLaw::Poly7,
            _ => return None,
        };
        law.is_valid().then_some(law)
    }

    /// `false` for a parameter out of range: `λ` not in `(0, 1)` or `v` not finite.
    pub fn is_valid(&self) -> bool {
        match *self {
            MotionLaw::ModifiedAccelerationTrapezoid { lambda } => lambda > 0.0 && lambda < 1.0,
            MotionLaw::InclinedSine { velocity } => velocity.is_finite(),
            _ => true,
        }
    }

    /// `s(u)`, `s'(u)` and `s''(u)` as a [`CamValue`] (`value`, `first_derivative`,
    /// `second_derivative`). `u` is clamped to `[0, 1]`; NaN gives NaN. Where `s''` jumps (the
    /// quadratic parabola at ½) the right-hand value is returned.
    pub fn eval(&self, u: f64) -> CamValue {
        let u = u.clamp(0.0, 1.0);
        let (s, v, a) = match *self {
            MotionLaw::StraightLine => (u, 1.0, 0.0),
            MotionLaw::QuadraticParabola => {
                if u < 0.5 {
                    (2.0 * u * u, 4.0 * u, 4.0)
                } else {
                    let r = 1.0 - u;
                    (1.0 - 2.0 * r * r, 4.0 * r, -4.0)
                }
            }
            MotionLaw::Poly5 => {
                let r = 1.0 - u;
                (
                    u * u * u * (10.0 + u * (-15.0 + 6.0 * u)),
                    30.0 * u * u * r * r,
                    60.0 * u * r * (1.0 - 2.0 * u),
                )
            }
            MotionLaw::SimpleSine => {
                let (sn, cs) = (PI * u).sin_cos();
                (0.5 * (1.0 - cs), 0.5 * PI * sn, 0.5 * PI * PI * cs)
            }
            MotionLaw::Cycloid => inclined_sine(u, 0.0),
            MotionLaw::InclinedSine { velocity } => inclined_sine(u, velocity),
            MotionLaw::ModifiedSine => modified_sine(u),
            MotionLaw::ModifiedTrapezoid => modified_acceleration_trapezoid(u, 0.5),
            MotionLaw::ModifiedAccelerationTrapezoid { lambda } => {
                modified_acceleration_trapezoid(u, lambda)
            }
            MotionLaw::Poly7 => {
                let r = 1.0 - u;
                let u2 = u * u;
                (
                    u2 * u2 * (35.0 + u * (-84.0 + u * (70.0 - 20.0 * u))),
                    140.0 * u2 * u * r * r * r,
                    420.0 * u2 * r * r * (1.0 - 2.0 * u),
                )
            }
        };
        CamValue {
            value: s,
            first_derivative: v,
            second_derivative: a,
        }
    }

    /// `s(u)` (see [`eval`](Self::eval)).
    pub fn s(&self, u: f64) -> f64 {
        self.eval(u).value
    }

    /// Characteristic velocity `Cv = max |s'(u)|` (closed form).
    pub fn peak_velocity(&self) -> f64 {
        match *self {
            MotionLaw::StraightLine => 1.0,
            MotionLaw::QuadraticParabola => 2.0,
            MotionLaw::Poly5 => 15.0 / 8.0,
            MotionLaw::SimpleSine => 0.5 * PI,
            MotionLaw::Cycloid => 2.0,
            MotionLaw::ModifiedSine => 4.0 * PI / (4.0 + PI),
            MotionLaw::ModifiedTrapezoid | MotionLaw::ModifiedAccelerationTrapezoid { .. } => 2.0,
            MotionLaw::InclinedSine { velocity } => velocity.abs().max((2.0 - velocity).abs()),
            MotionLaw::Poly7 => 35.0 / 16.0,
        }
    }

    /// Characteristic acceleration `Ca = max |s''(u)|` (closed form; for the asymmetric
    /// modified acceleration trapezoid the larger of acceleration and deceleration).
    pub fn peak_acceleration(&self) -> f64 {
        match *self {
            MotionLaw::StraightLine => 0.0,
            MotionLaw::QuadraticParabola => 4.0,
            MotionLaw::Poly5 => 10.0 / 3f64.sqrt(),
            MotionLaw::SimpleSine => 0.5 * PI * PI,
            MotionLaw::Cycloid => 2.0 * PI,
            MotionLaw::ModifiedSine => 4.0 * PI * PI / (4.0 + PI),
            MotionLaw::ModifiedTrapezoid => 4.0 / MAT_G1,
            MotionLaw::ModifiedAccelerationTrapezoid { lambda } => {
                2.0 / (lambda.min(1.0 - lambda) * MAT_G1)
            }
            MotionLaw::InclinedSine { velocity } => 2.0 * PI * (1.0 - velocity).abs(),
            MotionLaw::Poly7 => 84.0 / (5.0 * 5f64.sqrt()),
        }
    }

    /// Interior points where the law switches between closed-form pieces (the smoothness there
    /// is C2, except C1 for the quadratic parabola at ½). Empty for single-formula laws.
    pub fn breakpoints(&self) -> &'static [f64] {
        match *self {
            MotionLaw::QuadraticParabola => &[0.5],
            MotionLaw::ModifiedSine => &[0.125, 0.875],
            MotionLaw::ModifiedTrapezoid => &[0.125, 0.375, 0.5, 0.625, 0.875],
            _ => &[],
        }
    }
}

/// `s = u − (1 − v)·sin(2πu)/(2π)`: the inclined sine, the cycloid for `v = 0`.
fn inclined_sine(u: f64, v: f64) -> (f64, f64, f64) {
    let w = 2.0 * PI * u;
    let (sn, cs) = w.sin_cos();
    let k = 1.0 - v;
    (u - k * sn / (2.0 * PI), 1.0 - k * cs, 2.0 * PI * k * sn)
}

/// VDI 2143 modified sine with the factor `1/(4 + π)`.
fn modified_sine(u: f64) -> (f64, f64, f64) {
    let k = 1.0 / (4.0 + PI);
    if u <= 0.125 || u > 0.875 {
        let w = 4.0 * PI * u;
        let (sn, cs) = w.sin_cos();
        let c = if u <= 0.125 { 0.0 } else { 4.0 };
        (
            k * (c + PI * u - 0.25 * sn),
            k * PI * (1.0 - cs),
            k * 4.0 * PI * PI * sn,
        )
    } else {
        let w = PI / 3.0 + 4.0 * PI * u / 3.0;
        let (sn, cs) = w.sin_cos();
        (
            k * (2.0 + PI * u - 2.25 * sn),
            k * PI * (1.0 - 3.0 * cs),
            k * 4.0 * PI * PI * sn,
        )
    }
}

/// The unit acceleration shape of one phase of the modified trapezoid on `t ∈ [0, 1]`:
/// `g = sin 2πt` on `[0, ¼]`, `1` on `[¼, ¾]`, `sin 2π(1−t)` on `[¾, 1]`, with its integrals
/// `G(t) = ∫₀ᵗ g` and `H(t) = ∫₀ᵗ G` (`G(1) = ½ + 1/π`, `H(1) = G(1)/2`).
fn mat_shape(t: f64) -> (f64, f64, f64) {
    let tau = 2.0 * PI;
    if t <= 0.25 {
        let (sn, cs) = (tau * t).sin_cos();
        (sn, (1.0 - cs) / tau, t / tau - sn / (tau * tau))
    } else if t <= 0.75 {
        let d = t - 0.25;
        let hq = 1.0 / (8.0 * PI) - 1.0 / (4.0 * PI * PI);
        (1.0, 1.0 / tau + d, hq + d / tau + 0.5 * d * d)
    } else {
        let r = 1.0 - t;
        let (sn, cs) = (tau * r).sin_cos();
        (
            sn,
            MAT_G1 - (1.0 - cs) / tau,
            0.5 * MAT_G1 - MAT_G1 * r + r / tau - sn / (tau * tau),
        )
    }
}

/// Modified acceleration trapezoid with turning point `λ`: acceleration `2/(λ·G1)·g(u/λ)` on
/// `[0, λ]`, deceleration `−2/((1−λ)·G1)·g((u−λ)/(1−λ))` on `[λ, 1]`.
fn modified_acceleration_trapezoid(u: f64, lambda: f64) -> (f64, f64, f64) {
    if u <= lambda {
        let (g, gi, hi) = mat_shape(u / lambda);
        (
            2.0 * lambda / MAT_G1 * hi,
            2.0 / MAT_G1 * gi,
            2.0 / (lambda * MAT_G1) * g,
        )
    } else {
        let mu = 1.0 - lambda;
        let w = (u - lambda) / mu;
        let (g, gi, hi) = mat_shape(w);
        (
            lambda + 2.0 * mu * w - 2.0 * mu / MAT_G1 * hi,
            2.0 - 2.0 / MAT_G1 * gi,
            -2.0 / (mu * MAT_G1) * g,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for law in MotionLaw::EXAMPLES {
            assert_eq!(MotionLaw::from_name(law.name(), law.parameter()), Some(law));
        }
        assert_eq!(MotionLaw::from_name("poly5", Some(1.0)), None);
        assert_eq!(MotionLaw::from_name("inclined_sine", None), None);
        assert_eq!(
            MotionLaw::from_name("modified_acceleration_trapezoid", Some(1.0)),
            None
        );
        assert_eq!(
            MotionLaw::from_name("modified_acceleration_trapezoid", None),
            Some(MotionLaw::ModifiedAccelerationTrapezoid { lambda: 0.5 })
        );
        assert_eq!(MotionLaw::from_name("Poly5", None), None);
    }

    #[test]
    fn shape_integrals_are_consistent() {
        let (g, gi, hi) = mat_shape(1.0);
        assert!(g.abs() < 1e-15);
        assert!((gi - MAT_G1).abs() < 1e-15);
        assert!((hi - 0.5 * MAT_G1).abs() < 1e-15);
        for t in [0.25, 0.75] {
            let a = mat_shape(t - 1e-12);
            let b = mat_shape(t + 1e-12);
            assert!((a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-9);
            assert!((a.2 - b.2).abs() < 1e-9);
        }
    }
}
