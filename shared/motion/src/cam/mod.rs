//! The cam technology object: a transfer function `y = f(x)` from the leading value `x` to the
//! following value `y`, defined by interpolation points and segments and closed by
//! interpolation (S7-1500T Motion Control V4.0 function manual, 3.10 'Cam technology object',
//! S7-Technology V4.1 function manual, 3.5 '"Cam disk" technology object'; the user guide is
//! `docs/cams.md`).
//!
//! * [`CamDefinition`]: points, [`SegmentDef`]s (polynomials, VDI 2143 [`MotionLaw`]s, the S7
//!   technology-DB polynomial), [`Interpolation`] and [`BoundaryCondition`]; plain data.
//! * [`Cam::interpolate`] (`MC_InterpolateCam`) resolves conflicts, fills gaps and builds the
//!   evaluable cam. It allocates; call it off the cyclic path.
//! * [`Cam::following`] (`MC_GetCamFollowingValue`) and [`Cam::leading`]
//!   (`MC_GetCamLeadingValue`) are allocation-free: a binary search over the breakpoints, then one
//!   closed-form piece.
//! * [`parse_csv`] reads `x,y` point lists.
//!
//! # Rules (S7-1500T Motion Control V4.0 function manual, 3.10 'Cam technology object',
//! S7-Technology V4.1 function manual, 3.5 '"Cam disk" technology object')
//!
//! * Points may come in any order; among points with equal `x` the last one wins (`x` closer
//!   than [`POINT_RESOLUTION`] relative counts as equal).
//! * Overlapping segments: the later segment is used in full; the earlier one keeps its parts
//!   outside it. A segment wins over points on it or within [`GAP_THRESHOLD`] of its ends.
//! * Gaps between segments up to [`GAP_THRESHOLD`] (`1e-4`) are closed by pulling the segment
//!   ends together (to the middle); every larger gap, and every span between points, is closed
//!   by an interpolated piece.
//! * Two elements that touch with different `y` keep the jump; the right-hand value is output
//!   at the jump. [`Cam::junctions`] reports the continuity class at every breakpoint.
//! * The cam is defined from its minimum to its maximum leading value.
//!
//! # Text shape
//!
//! The config crate reads this TOML shape and builds a [`CamDefinition`] from it (names from
//! [`MotionLaw::name`], [`Interpolation::name`], [`BoundaryCondition::name`]):
//!
//! ```toml
//! [cam.lift]
//! interpolation = "cubic_spline"      # "linear" | "cubic_spline" | "bezier"
//! boundary = "none"                   # "none" | "equal_first_derivative"
//! points = [[0.0, 0.0], [40.0, 2.0]]  # [x, y]; or points_csv = "lift.csv" (x,y per line)
//!
//! [[cam.lift.segments]]               # a VDI 2143 law in the box [x0, x1] × [y0, y1]
//! type = "law"
//! law = "poly5"                       # see MotionLaw::name
//! x = [90.0, 180.0]
//! y = [10.0, 50.0]
//!
//! [[cam.lift.segments]]
//! type = "law"
//! law = "inclined_sine"
//! parameter = 0.5                     # v of inclined_sine (required), λ of
//!                                     # modified_acceleration_trapezoid (default 0.5)
//! x = [180.0, 200.0]
//! y = [50.0, 60.0]
//!
//! [[cam.lift.segments]]               # y = Σ coeffs[k]·uᵏ, u = (x − x0)/(x1 − x0) ∈ [0, 1]
//! type = "polynomial"
//! x = [200.0, 270.0]
//! coeffs = [60.0, 5.0, 0.0, -65.0]    # up to 8 (degree 7)
//!
//! [[cam.lift.segments]]               # S7 technology-DB form, absolute x
//! type = "s7_polynomial"
//! x = [300.0, 360.0]
//! a = [0.0, 0.0]                      # a0..a6, up to 7
//! sine = { amplitude = 0.0, period = 1.0, phase = 0.0 }
//! ```

use core::fmt;

use crate::catalog::error_id::ErrorId;

mod build;
mod csv;
mod definition;
mod inverse;
mod law;
mod piece;

pub use csv::{parse_csv, CamParseError, CamParseErrorKind};
pub use definition::{BoundaryCondition, CamDefinition, Interpolation, SegmentDef};
pub use law::MotionLaw;
pub use piece::PieceSource;

use inverse::Run;
use piece::{Formula, Piece};

/// Gaps (in x) between segments up to this width are closed by pulling the ends together;
/// points this close to a segment are dropped; larger gaps get a transition (S7-1500T Motion
/// Control V4.0 function manual, 3.10 'Cam technology object', the `1.0E-4` of
/// `MC_InterpolateCam`).
pub const GAP_THRESHOLD: f64 = 1e-4;

/// Points whose x differ by at most this much, relative to `max(1, |x|)`, are one x: the later
/// point wins, as for equal x. Inferred (the manuals name no resolution): without it two points
/// `1e-320` apart give a span whose slope and curvature are infinite, and a cam that answers
/// NaN. At `1e-9` a span between two points within [`VALUE_LIMIT`] has finite derivatives.
pub const POINT_RESOLUTION: f64 = 1e-9;

/// Largest magnitude of an x or y value (the `-1.0E12 to 1.0E12` range of the S7 cam tags).
pub const VALUE_LIMIT: f64 = 1e12;

/// Points of an S7-1500T cam TO (`Point[1..1000]`). Not enforced by [`Cam::interpolate`]; for a
/// configuration layer that wants S7 limits.
pub const S7_MAX_POINTS: usize = 1000;

/// Segments of an S7-1500T cam TO (`Segment[1..50]`). Not enforced by [`Cam::interpolate`].
pub const S7_MAX_SEGMENTS: usize = 50;

/// Value, first and second derivative of a cam (or a normalized law) at one point.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct CamValue {
    /// `y` (`Value`).
    pub value: f64,
    /// `dy/dx` (`FirstDerivative`).
    pub first_derivative: f64,
    /// `d²y/dx²` (`SecondDerivative`).
    pub second_derivative: f64,
}

/// Why a cam job failed; [`CamError::error_id`] gives the S7 ErrorID.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum CamError {
    /// No points and no segments (`16#80AA`).
    Empty,
    /// The cam is in use and cannot be interpolated (`16#80AB`). Never returned by
    /// [`Cam::interpolate`] itself; for the technology object that owns the cam.
    InUse,
    /// Fewer than two distinct points and no segment (`16#80AC`).
    TooFewPoints,
    /// The point with this index is not finite or exceeds [`VALUE_LIMIT`] (`16#80AC`).
    InvalidPoint {
        /// Index into [`CamDefinition::points`].
        index: usize,
    },
    /// The segment with this index is invalid: `x0 ≥ x1`, a value not finite or beyond
    /// [`VALUE_LIMIT`], an invalid law parameter, a sine with period 0, or a value or derivative
    /// on its span that is not finite (`16#80AC`).
    InvalidSegment {
        /// Index into [`CamDefinition::segments`].
        index: usize,
    },
    /// No leading value maps to the following value (`16#8063`).
    NoLeadingValue,
    /// The leading value lies outside the cam (`16#8064`).
    NoFollowingValue,
    /// The approach leading value is not finite (`16#8062`).
    IllegalApproachLeadingValue,
}

impl CamError {
    /// The ErrorID of the S7 instruction (S7-1500T Motion Control V4.0 function manual, A.9 'Error
    /// ID for Motion Control instructions').
    pub const fn error_id(self) -> ErrorId {
        match self {
            CamError::Empty => ErrorId::CamEmpty,
            CamError::InUse => ErrorId::CamInUse,
            CamError::TooFewPoints
            | CamError::InvalidPoint { .. }
            | CamError::InvalidSegment { .. } => ErrorId::CamInvalidPoints,
            CamError::NoLeadingValue => ErrorId::NoLeadingValue,
            CamError::NoFollowingValue => ErrorId::NoFollowingValue,
            CamError::IllegalApproachLeadingValue => ErrorId::IllegalApproachLeadingValue,
        }
    }
}

impl fmt::Display for CamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.error_id())?;
        match self {
            CamError::TooFewPoints => f.write_str(": fewer than two points and no segment"),
            CamError::InvalidPoint { index } => write!(f, ": point {index} is invalid"),
            CamError::InvalidSegment { index } => write!(f, ": segment {index} is invalid"),
            _ => Ok(()),
        }
    }
}

impl std::error::Error for CamError {}

/// Continuity class at a breakpoint, from worst to best.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Continuity {
    /// The value jumps.
    Discontinuous,
    /// Value continuous, first derivative jumps.
    C0,
    /// Value and first derivative continuous, second derivative jumps.
    C1,
    /// Value, first and second derivative continuous.
    C2,
}

/// A breakpoint between two pieces of the interpolated cam.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Junction {
    /// Leading value of the breakpoint.
    pub x: f64,
    /// Class, with a tolerance of `1e-9` relative to the largest magnitude of the same quantity
    /// at any breakpoint of the cam (at least 1).
    pub continuity: Continuity,
    /// Limit from the left.
    pub left: CamValue,
    /// Value from the right (what [`Cam::following`] returns at `x`).
    pub right: CamValue,
}

/// Whether the cam is monotonic (decides how [`Cam::leading`] searches).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Monotonicity {
    /// Constant over the whole leading range.
    Constant,
    /// Never decreasing (jumps up allowed).
    NonDecreasing,
    /// Never increasing.
    NonIncreasing,
    /// Neither.
    None,
}

/// One piece of the interpolated cam (for inspection).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PieceInfo {
    /// Start leading value.
    pub x_start: f64,
    /// End leading value.
    pub x_end: f64,
    /// Segment or interpolation.
    pub source: PieceSource,
}

/// An interpolated cam: evaluable, immutable, cheap to share (`Send + Sync`).
#[derive(Clone, Debug)]
#[doc(alias = "TO_Cam")]
pub struct Cam {
    pieces: Vec<Piece>,
    /// `pieces[i].xa`, for the binary search.
    starts: Vec<f64>,
    junctions: Vec<Junction>,
    runs: Vec<Run>,
    monotonicity: Monotonicity,
    interpolation: Interpolation,
    x_start: f64,
    x_end: f64,
    y_min: f64,
    y_max: f64,
    /// Leading values this close outside the range are clamped into it; also the tie tolerance.
    x_tol: f64,
    /// Tolerance on following values (range membership, flatness, monotonicity).
    y_tol: f64,
}

impl Cam {
    /// `MC_InterpolateCam`: builds the cam from its definition (see the module documentation
    /// for the rules). Allocates; not for the cyclic path.
    #[doc(alias = "MC_InterpolateCam")]
    pub fn interpolate(def: &CamDefinition) -> Result<Cam, CamError> {
        build::build(def)
    }

    /// Assembles a cam from contiguous pieces sorted by x.
    fn assemble(pieces: Vec<Piece>, interpolation: Interpolation) -> Cam {
        let starts: Vec<f64> = pieces.iter().map(|p| p.xa).collect();
        let x_start = pieces.first().map_or(0.0, |p| p.xa);
        let x_end = pieces.last().map_or(0.0, |p| p.xb);
        let mut scale = [1.0f64; 3];
        for p in &pieces {
            for x in [p.xa, p.xb] {
                let v = p.eval(x);
                scale[0] = scale[0].max(v.value.abs());
                scale[1] = scale[1].max(v.first_derivative.abs());
                scale[2] = scale[2].max(v.second_derivative.abs());
            }
        }
        let near = |a: f64, b: f64, s: f64| (a - b).abs() <= 1e-9 * s;
        let junctions = pieces
            .windows(2)
            .map(|w| {
                let left = w[0].eval(w[0].xb);
                let right = w[1].eval(w[1].xa);
                let continuity = if !near(left.value, right.value, scale[0]) {
                    Continuity::Discontinuous
                } else if !near(left.first_derivative, right.first_derivative, scale[1]) {
                    Continuity::C0
                } else if !near(left.second_derivative, right.second_derivative, scale[2]) {
                    Continuity::C1
                } else {
                    Continuity::C2
                };
                Junction {
                    x: w[1].xa,
                    continuity,
                    left,
                    right,
                }
            })
            .collect();
        let runs = inverse::runs(&pieces);
        let y_min = runs
            .iter()
            .map(|r| r.ya.min(r.yb))
            .fold(f64::INFINITY, f64::min);
        let y_max = runs
            .iter()
            .map(|r| r.ya.max(r.yb))
            .fold(f64::NEG_INFINITY, f64::max);
        let y_tol = 1e-12 * y_min.abs().max(y_max.abs()).max(1.0);
        let x_tol = 1e-12 * x_start.abs().max(x_end.abs()).max(1.0);
        let (mut inc, mut dec) = (true, true);
        let mut prev: Option<f64> = None;
        for r in &runs {
            let mut check = |from: f64, to: f64| {
                if to < from - y_tol {
                    inc = false;
                }
                if to > from + y_tol {
                    dec = false;
                }
            };
            if let Some(p) = prev {
                check(p, r.ya);
            }
            check(r.ya, r.yb);
            prev = Some(r.yb);
        }
        let monotonicity = match (inc, dec) {
            (true, true) => Monotonicity::Constant,
            (true, false) => Monotonicity::NonDecreasing,
            (false, true) => Monotonicity::NonIncreasing,
            (false, false) => Monotonicity::None,
        };
        Cam {
            pieces,
            starts,
            junctions,
            runs,
            monotonicity,
            interpolation,
            x_start,
            x_end,
            y_min,
            y_max,
            x_tol,
            y_tol,
        }
    }

    /// `x` clamped into the leading range, or `None` when it lies outside (beyond the
    /// tolerance) or is NaN.
    #[inline]
    fn clamp_x(&self, x: f64) -> Option<f64> {
        if x >= self.x_start - self.x_tol && x <= self.x_end + self.x_tol {
            Some(x.max(self.x_start).min(self.x_end))
        } else {
            None
        }
    }

    /// Index of the piece that holds `x` (binary search, O(log n)); at a breakpoint the piece
    /// to the right. `None` outside the leading range.
    #[inline]
    pub fn piece_index(&self, x: f64) -> Option<usize> {
        let x = self.clamp_x(x)?;
        Some(self.starts.partition_point(|&s| s <= x).saturating_sub(1))
    }

    /// `MC_GetCamFollowingValue`: value, first and second derivative at the leading value `x`.
    /// At a jump the right-hand value is returned. Leading values outside the leading range
    /// (beyond a tolerance of `1e-12` relative to the range's magnitude) or NaN give
    /// [`CamError::NoFollowingValue`] (`16#8064`). O(log n), no allocation.
    #[doc(alias = "MC_GetCamFollowingValue")]
    pub fn following(&self, x: f64) -> Result<CamValue, CamError> {
        let x = self.clamp_x(x).ok_or(CamError::NoFollowingValue)?;
        let i = self.starts.partition_point(|&s| s <= x).saturating_sub(1);
        self.pieces
            .get(i)
            .map(|p| p.eval(x))
            .ok_or(CamError::NoFollowingValue)
    }

    /// [`following`](Self::following) with a caller-owned hint: the piece index of the previous
    /// call. The hinted piece and its right neighbour are tried first (O(1) for a leader that
    /// moves forward), then the binary search. The hint is updated; any value is safe.
    pub fn following_with_hint(&self, x: f64, hint: &mut usize) -> Result<CamValue, CamError> {
        let x = self.clamp_x(x).ok_or(CamError::NoFollowingValue)?;
        let holds = |i: usize| {
            self.starts.get(i).is_some_and(|&s| s <= x)
                && self.starts.get(i + 1).is_none_or(|&next| x < next)
        };
        let next = hint.wrapping_add(1);
        let i = if holds(*hint) {
            *hint
        } else if holds(next) {
            next
        } else {
            self.starts.partition_point(|&s| s <= x).saturating_sub(1)
        };
        *hint = i;
        self.pieces
            .get(i)
            .map(|p| p.eval(x))
            .ok_or(CamError::NoFollowingValue)
    }

    /// `MC_GetCamLeadingValue`: a leading value `x` with `f(x) = y`. When several exist the one
    /// nearest to `approach` is returned, and of two equally near (within `1e-12` relative) the
    /// lower one (S7-Technology V4.1 function manual, 3.5 '"Cam disk" technology object',
    /// MC_GetCamPoint Mode 1); `approach` may lie outside the cam. Where the cam is constant at `y`
    /// over an interval, the point of that interval nearest to `approach`. No solution (also a `y`
    /// inside a jump) gives [`CamError::NoLeadingValue`] (`16#8063`); a non-finite `approach`
    /// [`CamError::IllegalApproachLeadingValue`] (`16#8062`).
    ///
    /// Monotonic cams: binary search, O(log n); otherwise every monotonic run is checked
    /// (O(n), pruned by distance). The root is found by Newton's method inside the run's
    /// bracket, to machine precision. No allocation.
    #[doc(alias = "MC_GetCamLeadingValue")]
    pub fn leading(&self, y: f64, approach: f64) -> Result<f64, CamError> {
        if !approach.is_finite() {
            return Err(CamError::IllegalApproachLeadingValue);
        }
        if !y.is_finite() {
            return Err(CamError::NoLeadingValue);
        }
        match self.monotonicity {
            Monotonicity::None => self.leading_scan(y, approach),
            _ => self.leading_monotonic(y, approach),
        }
    }

    /// `(StartLeadingValue, EndLeadingValue)`: the leading range.
    #[doc(alias = "StartLeadingValue")]
    #[doc(alias = "EndLeadingValue")]
    pub fn leading_range(&self) -> (f64, f64) {
        (self.x_start, self.x_end)
    }

    /// `(min, max)` of the following value over the leading range (after interpolation; a
    /// cubic spline may exceed the points).
    pub fn following_range(&self) -> (f64, f64) {
        (self.y_min, self.y_max)
    }

    /// Value and derivatives at the start of the leading range.
    pub fn start(&self) -> CamValue {
        self.pieces
            .first()
            .map(|p| p.eval(p.xa))
            .unwrap_or_default()
    }

    /// Value and derivatives at the end of the leading range (of the last piece).
    pub fn end(&self) -> CamValue {
        self.pieces.last().map(|p| p.eval(p.xb)).unwrap_or_default()
    }

    /// `f(x_end) − f(x_start)`: what a cyclic relative follower adds per cam cycle.
    pub fn rise(&self) -> f64 {
        self.end().value - self.start().value
    }

    /// The breakpoints between pieces, in x order, with their continuity class.
    pub fn junctions(&self) -> &[Junction] {
        &self.junctions
    }

    /// The worst continuity class of the cam: of all junctions and inside the pieces (a
    /// quadratic-parabola segment is C1 inside). `C2` for a single smooth piece.
    pub fn continuity(&self) -> Continuity {
        let inner = self
            .pieces
            .iter()
            .map(|p| match p.formula {
                Formula::Law {
                    law: MotionLaw::QuadraticParabola,
                    ..
                } => Continuity::C1,
                _ => Continuity::C2,
            })
            .min()
            .unwrap_or(Continuity::C2);
        self.junctions
            .iter()
            .map(|j| j.continuity)
            .min()
            .map_or(inner, |c| c.min(inner))
    }

    /// Whether the cam is monotonic.
    pub fn monotonicity(&self) -> Monotonicity {
        self.monotonicity
    }

    /// The interpolation the cam was built with.
    pub fn interpolation(&self) -> Interpolation {
        self.interpolation
    }

    /// Number of pieces.
    pub fn piece_count(&self) -> usize {
        self.pieces.len()
    }

    /// The pieces in x order.
    pub fn pieces(&self) -> impl ExactSizeIterator<Item = PieceInfo> + '_ {
        self.pieces.iter().map(|p| PieceInfo {
            x_start: p.xa,
            x_end: p.xb,
            source: p.source,
        })
    }
}

#[cfg(test)]
mod tests;
