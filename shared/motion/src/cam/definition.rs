//! The definition of a cam: interpolation points, segments and interpolation settings (the CAL
//! tags `Point[]`, `Segment[]` and `InterpolationSettings` of the S7-1500T cam TO, S7-1500T Motion
//! Control V4.0 function manual, 3.10 'Cam technology object'), as plain data without serde. The
//! config crate maps its TOML onto these types.

use super::MotionLaw;

/// One segment (a cam element with a formula) on `[x0, x1]`, `x0 < x1`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum SegmentDef {
    /// Polynomial of degree ≤ 7 in the **local normalized variable**
    /// `u = (x − x0)/(x1 − x0) ∈ [0, 1]`: `y = Σ coeffs[k]·uᵏ`. (The normalized form is the
    /// VDI 2143 / S7-Technology form and stays well conditioned far from `x = 0`; for the S7-1500T
    /// technology-DB form in absolute `x` use [`SegmentDef::S7Polynomial`].)
    Polynomial {
        /// Start of the segment (leading value).
        x0: f64,
        /// End of the segment, `> x0`.
        x1: f64,
        /// `coeffs[k]` multiplies `uᵏ`.
        coeffs: [f64; 8],
    },
    /// A normalized [`MotionLaw`] mapped onto the box: `y = y0 + (y1 − y0)·s((x − x0)/(x1 − x0))`.
    /// `y1 < y0` (a fall) and `y1 = y0` (a dwell) are allowed.
    Law {
        /// The law.
        law: MotionLaw,
        /// Start of the segment (leading value).
        x0: f64,
        /// End of the segment, `> x0`.
        x1: f64,
        /// Following value at `x0`.
        y0: f64,
        /// Following value at `x1`.
        y1: f64,
    },
    /// The S7-1500T technology-DB segment (`<TO>.Segment[i]`, S7-1500T Motion Control V4.0 function
    /// manual, A.7.4 'Segment tags (cam)'): `y = a0 + a1·x + … + a6·x⁶ +
    /// sineAmplitude·sin(2π·x/sinePeriod + sinePhase)` with `x` the **absolute** leading value.
    /// This is a literal reading of the tag descriptions ("coefficient for xᵏ", "period length",
    /// "phase offset \[rad\]"); the manual's formula itself is not in the reference text, so treat
    /// the sine part as unverified. With `sine_amplitude = 0` the period is ignored; otherwise it
    /// must be non-zero.
    #[doc(alias = "Segment")]
    S7Polynomial {
        /// `xmin`.
        xmin: f64,
        /// `xmax`, `> xmin`.
        xmax: f64,
        /// `a0 … a6`.
        a: [f64; 7],
        /// `sineAmplitude`.
        sine_amplitude: f64,
        /// `sinePeriod`: period length in leading-value units.
        sine_period: f64,
        /// `sinePhase` \[rad\].
        sine_phase: f64,
    },
}

impl SegmentDef {
    /// The leading-value range `(x0, x1)` of the segment.
    pub const fn span(&self) -> (f64, f64) {
        match *self {
            SegmentDef::Polynomial { x0, x1, .. } | SegmentDef::Law { x0, x1, .. } => (x0, x1),
            SegmentDef::S7Polynomial { xmin, xmax, .. } => (xmin, xmax),
        }
    }

    /// A polynomial segment from coefficients in `u`; fewer than 8 coefficients are padded
    /// with zeros, more are ignored (use at most 8).
    pub fn polynomial(x0: f64, x1: f64, coeffs: &[f64]) -> SegmentDef {
        let mut c = [0.0; 8];
        for (dst, src) in c.iter_mut().zip(coeffs) {
            *dst = *src;
        }
        SegmentDef::Polynomial { x0, x1, coeffs: c }
    }

    /// A straight line from `(x0, y0)` to `(x1, y1)`.
    pub fn line(x0: f64, y0: f64, x1: f64, y1: f64) -> SegmentDef {
        SegmentDef::Law {
            law: MotionLaw::StraightLine,
            x0,
            x1,
            y0,
            y1,
        }
    }
}

/// How gaps between points and segments are closed (`InterpolationSettings.InterpolationMode`).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Hash)]
#[doc(alias = "InterpolationMode")]
pub enum Interpolation {
    /// `0`: straight lines between neighbouring elements (C0).
    Linear,
    /// `1`: a C2 cubic spline through the points; clamped to the slope of adjacent segments
    /// (C1 there); a gap between two segments gets a quintic transition (C2). May overshoot the
    /// y range of the points.
    #[default]
    CubicSpline,
    /// `2`: a C1 chain of cubic Bézier curves through the points whose control points stay inside
    /// each span's y range, so the cam never leaves the y range of its points (monotone data
    /// stays monotone). Segment slopes are taken over where that range rule allows.
    Bezier,
}

impl Interpolation {
    /// The text-format name: `"linear"`, `"cubic_spline"`, `"bezier"`.
    pub const fn name(self) -> &'static str {
        match self {
            Interpolation::Linear => "linear",
            Interpolation::CubicSpline => "cubic_spline",
            Interpolation::Bezier => "bezier",
        }
    }

    /// The interpolation for a [`name`](Self::name).
    pub fn from_name(name: &str) -> Option<Interpolation> {
        match name {
            "linear" => Some(Interpolation::Linear),
            "cubic_spline" => Some(Interpolation::CubicSpline),
            "bezier" => Some(Interpolation::Bezier),
            _ => None,
        }
    }

    /// From the S7 tag value (0 linear, 1 cubic splines, 2 Bézier splines).
    pub const fn from_s7(mode: i32) -> Option<Interpolation> {
        match mode {
            0 => Some(Interpolation::Linear),
            1 => Some(Interpolation::CubicSpline),
            2 => Some(Interpolation::Bezier),
            _ => None,
        }
    }
}

/// Conditions at the start and end of the cam (`InterpolationSettings.BoundaryConditions`).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Hash)]
#[doc(alias = "BoundaryConditions")]
pub enum BoundaryCondition {
    /// `0`: no condition; a spline end at the cam edge is natural (`y'' = 0`), a Bézier end
    /// takes a one-sided estimate.
    #[default]
    None,
    /// `1`: first derivative equal at the start and the end of the cam, for cyclic use. Only
    /// interpolated ends can be adjusted (a segment at an edge keeps its own slope); a cubic
    /// spline whose both edges are interpolated also gets equal second derivatives. Ignored by
    /// [`Interpolation::Linear`].
    EqualFirstDerivative,
}

impl BoundaryCondition {
    /// The text-format name: `"none"`, `"equal_first_derivative"`.
    pub const fn name(self) -> &'static str {
        match self {
            BoundaryCondition::None => "none",
            BoundaryCondition::EqualFirstDerivative => "equal_first_derivative",
        }
    }

    /// The boundary condition for a [`name`](Self::name).
    pub fn from_name(name: &str) -> Option<BoundaryCondition> {
        match name {
            "none" => Some(BoundaryCondition::None),
            "equal_first_derivative" => Some(BoundaryCondition::EqualFirstDerivative),
            _ => None,
        }
    }

    /// From the S7 tag value (0 none, 1 first derivative equal at start and end).
    pub const fn from_s7(value: i32) -> Option<BoundaryCondition> {
        match value {
            0 => Some(BoundaryCondition::None),
            1 => Some(BoundaryCondition::EqualFirstDerivative),
            _ => None,
        }
    }
}

/// Everything [`super::Cam::interpolate`] needs: the input of `MC_InterpolateCam`.
///
/// Order matters: among points with the same `x` the **last** one wins, and a later segment
/// overwrites an earlier one where they overlap (S7-1500T Motion Control V4.0 function manual, 3.10
/// 'Cam technology object').
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CamDefinition {
    /// Interpolation points `(x, y)` in any order.
    pub points: Vec<(f64, f64)>,
    /// Segments in definition order.
    pub segments: Vec<SegmentDef>,
    /// How gaps are closed.
    pub interpolation: Interpolation,
    /// Conditions at the cam edges.
    pub boundary: BoundaryCondition,
}

impl CamDefinition {
    /// A cam of points only.
    pub fn from_points(points: Vec<(f64, f64)>, interpolation: Interpolation) -> CamDefinition {
        CamDefinition {
            points,
            segments: Vec::new(),
            interpolation,
            boundary: BoundaryCondition::None,
        }
    }
}
