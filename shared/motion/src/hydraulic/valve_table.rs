//! The characteristic curve of a valve and cylinder, for the linearisation of
//! `MC_AxRtFinishLinear_BkPlcMc` (Beckhoff TwinCAT PLC Hydraulic Positioning library, 4.4.7.4;
//! the table formats: FAQ #22 and FAQ #24).
//!
//! A table of points (normalised velocity, normalised output): the velocity relative to the
//! reference velocity `fRefVelo`, the output relative to full scale (±1.0 = ±10 V). The
//! linearisation looks up the output that gives a commanded velocity: between two points it
//! interpolates linearly; below the linearisation limit of its direction (`Valve_LinLimitP`,
//! `Valve_LinLimitM`, in mm/s) the curve is replaced by the straight line from the zero point
//! to the curve's point at that velocity (the resolution of a measured curve is poorest near
//! zero); beyond the table's ends it gives the end's output (inferred: the library does not say;
//! an output beyond full scale does not exist).
//!
//! The rules of FAQ #22, each checked ([`TableError`]): velocities and outputs within
//! -1.0..=1.0, velocities strictly increasing, the zero point (0, 0) present. FAQ #22 only
//! advises increasing outputs ("otherwise there would be a negative slope in this section. This
//! would result in a change of sign of the gain and therefore instability in an active
//! control"): tandem refuses a table whose output falls ([`TableError::OutputFalls`]), a stated
//! deviation. The export format of FAQ #24 (the output in equal steps from -1.0 to 1.0, an odd
//! number of points) is what [`ValveTable::is_export_format`] tells; a table need not have it.
//!
//! Pure: no IO, no allocation (the points are held inline, at most [`MAX_POINTS`]).

use crate::catalog::hyd_error::HydErrorCode;
/// The most points a table holds (the library's automatic identification measures 3 to 99).
pub const MAX_POINTS: usize = 256;

/// Why a characteristic curve was refused (nothing of it is kept).
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum TableError {
    /// Fewer than 2 points.
    TooFewPoints {
        /// Points given.
        count: usize,
    },
    /// More than [`MAX_POINTS`] points.
    TooManyPoints {
        /// Points given.
        count: usize,
    },
    /// A velocity or output is NaN, infinite or outside -1.0..=1.0.
    OutOfRange {
        /// Index of the point (from 0).
        index: usize,
        /// Its velocity.
        velocity: f64,
        /// Its output.
        output: f64,
    },
    /// A velocity is not higher than the one before it.
    VelocityNotIncreasing {
        /// Index of the point (from 0).
        index: usize,
        /// Its velocity.
        velocity: f64,
        /// The velocity of the point before it.
        previous: f64,
    },
    /// An output is lower than the one before it: a negative slope, a change of sign of the
    /// gain.
    OutputFalls {
        /// Index of the point (from 0).
        index: usize,
        /// Its output.
        output: f64,
        /// The output of the point before it.
        previous: f64,
    },
    /// No point (0.0, 0.0).
    NoZeroPoint,
    /// A line of a table file that is not two numbers (FAQ #22).
    Syntax {
        /// Line (from 1).
        line: usize,
    },
    /// A linearisation limit that is NaN, infinite or negative.
    BadLinLimit {
        /// The value.
        value: f64,
    },
}

impl TableError {
    /// The library's error code: `dwTcHydAdsErrSyntax` for a line of a file,
    /// `dwTcHydErrCdTblEntryCount` / `dwTcHydErrCdTblLineCount` for too few / too many points,
    /// `dwTcHydErrCdTblInvalidMasterStep` for velocities not increasing, else
    /// `dwTcHydAdsErrIllegalValue`.
    pub fn code(&self) -> HydErrorCode {
        match self {
            Self::Syntax { .. } => HydErrorCode::SYNTAX,
            Self::TooFewPoints { .. } => HydErrorCode::TBL_ENTRY_COUNT,
            Self::TooManyPoints { .. } => HydErrorCode::TBL_LINE_COUNT,
            Self::VelocityNotIncreasing { .. } => HydErrorCode::TBL_INVALID_MASTER_STEP,
            _ => HydErrorCode::ILLEGAL_VALUE,
        }
    }
}

impl core::fmt::Display for TableError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::TooFewPoints { count } => {
                write!(f, "a characteristic curve needs at least 2 points, it has {count}")
            }
            Self::TooManyPoints { count } => write!(
                f,
                "a characteristic curve holds at most {MAX_POINTS} points, it has {count}"
            ),
            Self::OutOfRange {
                index,
                velocity,
                output,
            } => write!(
                f,
                "point {index} ({velocity}, {output}): velocity and output must lie within -1.0 and 1.0"
            ),
            Self::VelocityNotIncreasing {
                index,
                velocity,
                previous,
            } => write!(
                f,
                "point {index}: velocity {velocity} is not higher than the previous point's {previous}"
            ),
            Self::OutputFalls {
                index,
                output,
                previous,
            } => write!(
                f,
                "point {index}: output {output} is lower than the previous point's {previous} \
                 (a negative slope changes the sign of the gain)"
            ),
            Self::NoZeroPoint => write!(f, "the characteristic curve has no zero point (0.0, 0.0)"),
            Self::Syntax { line } => write!(
                f,
                "line {line}: expected a velocity and an output, two numbers separated by spaces or tabs"
            ),
            Self::BadLinLimit { value } => write!(
                f,
                "linearisation limit {value}: must be a finite velocity of at least 0"
            ),
        }
    }
}

impl std::error::Error for TableError {}

/// A valve's characteristic curve (see the module documentation).
#[doc(alias = "ValveCharacteristicTable")]
#[derive(Clone, Debug, PartialEq)]
pub struct ValveTable {
    velocity: [f64; MAX_POINTS],
    output: [f64; MAX_POINTS],
    len: usize,
}

impl ValveTable {
    /// The table of `points` (normalised velocity, normalised output), checked as FAQ #22
    /// asks (see [`TableError`]).
    pub fn new(points: &[(f64, f64)]) -> Result<Self, TableError> {
        let count = points.len();
        if count < 2 {
            return Err(TableError::TooFewPoints { count });
        }
        if count > MAX_POINTS {
            return Err(TableError::TooManyPoints { count });
        }
        let mut t = Self {
            velocity: [0.0; MAX_POINTS],
            output: [0.0; MAX_POINTS],
            len: 0,
        };
        for (index, &(velocity, output)) in points.iter().enumerate() {
            let within = |x: f64| x.is_finite() && (-1.0..=1.0).contains(&x);
            if !within(velocity) || !within(output) {
                return Err(TableError::OutOfRange {
                    index,
                    velocity,
                    output,
                });
            }
            if let Some(&(pv, po)) = index.checked_sub(1).and_then(|i| points.get(i)) {
                if velocity <= pv {
                    return Err(TableError::VelocityNotIncreasing {
                        index,
                        velocity,
                        previous: pv,
                    });
                }
                if output < po {
                    return Err(TableError::OutputFalls {
                        index,
                        output,
                        previous: po,
                    });
                }
            }
            if let (Some(v), Some(o)) = (t.velocity.get_mut(index), t.output.get_mut(index)) {
                *v = velocity;
                *o = output;
            }
        }
        t.len = count;
        if !points.iter().any(|&(v, o)| v == 0.0 && o == 0.0) {
            return Err(TableError::NoZeroPoint);
        }
        Ok(t)
    }

    /// A table from the text of a table file (FAQ #22): one point per line, a velocity then an
    /// output, separated by spaces or tabs, the decimal separator a point or a comma; blank
    /// lines are skipped. `buf` holds the points while they are read (no allocation).
    pub fn parse(text: &str, buf: &mut [(f64, f64); MAX_POINTS]) -> Result<Self, TableError> {
        let mut n = 0;
        for (i, line) in text.lines().enumerate() {
            let mut fields = line.split([' ', '\t']).filter(|f| !f.is_empty());
            let (Some(v), Some(o), None) = (fields.next(), fields.next(), fields.next()) else {
                if line.trim().is_empty() {
                    continue;
                }
                return Err(TableError::Syntax { line: i + 1 });
            };
            let (Some(v), Some(o)) = (number(v), number(o)) else {
                return Err(TableError::Syntax { line: i + 1 });
            };
            let Some(slot) = buf.get_mut(n) else {
                return Err(TableError::TooManyPoints { count: n + 1 });
            };
            *slot = (v, o);
            n += 1;
        }
        Self::new(buf.get(..n).unwrap_or(&[]))
    }

    /// The points, in order.
    pub fn points(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.velocity
            .iter()
            .zip(self.output.iter())
            .take(self.len)
            .map(|(&v, &o)| (v, o))
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.len
    }

    /// No points (never true of a table [`ValveTable::new`] accepted).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The table has the export format of FAQ #24: outputs in equal steps (to 1e-9) from -1.0
    /// to 1.0 through 0.0, an odd number of points.
    pub fn is_export_format(&self) -> bool {
        let n = self.len;
        if n < 3 || n % 2 == 0 {
            return false;
        }
        let step = 2.0 / (n - 1) as f64;
        self.points()
            .enumerate()
            .all(|(i, (_, o))| (o - (-1.0 + step * i as f64)).abs() <= 1e-9)
    }

    /// The normalised output for normalised velocity `v` (see the module documentation):
    /// linear between the points, the ends' outputs beyond them, and below `lin_limit` of `v`'s
    /// direction (normalised: `Valve_LinLimitP` or `Valve_LinLimitM` over `fRefVelo`) the
    /// straight line from (0, 0) to the curve at that limit.
    #[doc(alias = "MC_AxRtFinishLinear_BkPlcMc")]
    pub fn output(&self, v: f64, lin_limit: f64) -> f64 {
        if lin_limit > 0.0 && v.abs() < lin_limit {
            let edge = self.curve(lin_limit.copysign(v));
            return edge * (v.abs() / lin_limit);
        }
        self.curve(v)
    }

    /// The curve itself at `v`: linear between the points, the ends' outputs beyond them.
    fn curve(&self, v: f64) -> f64 {
        let (vel, out) = (&self.velocity[..self.len], &self.output[..self.len]);
        let (Some(&v0), Some(&vn)) = (vel.first(), vel.last()) else {
            return 0.0;
        };
        if v <= v0 {
            return out.first().copied().unwrap_or(0.0);
        }
        if v >= vn {
            return out.last().copied().unwrap_or(0.0);
        }
        // The first point above v: 1..len (v0 < v < vn).
        let hi = vel.partition_point(|&x| x <= v);
        match (vel.get(hi - 1), vel.get(hi), out.get(hi - 1), out.get(hi)) {
            (Some(&va), Some(&vb), Some(&oa), Some(&ob)) => oa + (ob - oa) * (v - va) / (vb - va),
            _ => 0.0,
        }
    }
}

/// A number of a table file: an optional minus sign, digits, a point or a comma, digits, an
/// optional exponent (FAQ #24's `-1.81408951053528e-1`).
fn number(s: &str) -> Option<f64> {
    let mut buf = [0u8; 64];
    let bytes = s.as_bytes();
    let b = buf.get_mut(..bytes.len())?;
    for (d, &c) in b.iter_mut().zip(bytes) {
        *d = if c == b',' { b'.' } else { c };
    }
    let t = core::str::from_utf8(b).ok()?;
    // Only what FAQ #22 allows: no sign other than a leading minus, no "inf"/"nan".
    let body = t.strip_prefix('-').unwrap_or(t);
    if !body.starts_with(|c: char| c.is_ascii_digit()) {
        return None;
    }
    t.parse::<f64>().ok().filter(|x| x.is_finite())
}

#[cfg(test)]
pub(crate) mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    /// FAQ #22's example: a cylinder that reaches only half the velocity in the negative
    /// direction (single-sided rod), a zero-overlap valve with a bend at 40 %.
    pub(crate) const FAQ22: &str = "-0.500 -1.000\n-0.430 -0.900\n-0.360 -0.800\n-0.290 -0.700\n\
        -0.220 -0.600\n-0.150 -0.500\n-0.080 -0.400\n-0.060 -0.300\n-0.040 -0.200\n-0.020 -0.100\n\
        0.000 0.000\n0.040 0.100\n0.080 0.200\n0.120 0.300\n0.160 0.400\n0.300 0.500\n\
        0.440 0.600\n0.580 0.700\n0.720 0.800\n0.860 0.900\n1.000 1.000\n";

    fn faq22() -> ValveTable {
        ValveTable::parse(FAQ22, &mut [(0.0, 0.0); MAX_POINTS]).unwrap()
    }

    #[test]
    fn the_faq_22_example_reads_and_gives_its_points() {
        let t = faq22();
        assert_eq!(t.len(), 21);
        assert!(t.is_export_format());
        for (v, o) in t.points() {
            assert_eq!(t.output(v, 0.0), o, "at {v}");
        }
        // Between points: linear. 0.1 lies halfway between 0.08 (0.2) and 0.12 (0.3).
        assert!((t.output(0.1, 0.0) - 0.25).abs() < 1e-12);
        // Above the bend: 0.23 between 0.16 (0.4) and 0.30 (0.5).
        assert!((t.output(0.23, 0.0) - 0.45).abs() < 1e-12);
        // The negative side reaches only half the velocity: -0.5 needs full output.
        assert_eq!(t.output(-0.5, 0.0), -1.0);
        assert!((t.output(-0.465, 0.0) + 0.95).abs() < 1e-12);
        // Beyond the ends: the ends' outputs.
        assert_eq!(t.output(-0.8, 0.0), -1.0);
        assert_eq!(t.output(1.0, 0.0), 1.0);
    }

    #[test]
    fn below_the_linearisation_limit_the_curve_is_a_line_through_zero() {
        let t = faq22();
        // Limit 0.1: the curve at 0.1 is 0.25; at 0.05 the line gives 0.125 (the table 0.125
        // too, it is straight there), at -0.05 the line to the curve at -0.1 (-0.4 + ...).
        let at_minus = t.output(-0.1, 0.0);
        assert!((at_minus - (-0.5 + 0.1 * 0.05 / 0.07)).abs() < 1e-12);
        assert!((t.output(-0.05, 0.1) - at_minus * 0.5).abs() < 1e-12);
        assert!((t.output(0.05, 0.1) - 0.125).abs() < 1e-12);
        assert_eq!(t.output(0.0, 0.1), 0.0);
        // At and above the limit the curve itself.
        assert_eq!(t.output(0.1, 0.1), t.output(0.1, 0.0));
    }

    #[test]
    fn commas_tabs_and_exponents_are_read() {
        let t = ValveTable::parse(
            "-1,0\t-1.0e0\n  0,000   0.0\n1.81408951053528e-1 5.0e-1\n1.0 1.0\n",
            &mut [(0.0, 0.0); MAX_POINTS],
        )
        .unwrap();
        let p: Vec<_> = t.points().collect();
        assert_eq!(
            p,
            [
                (-1.0, -1.0),
                (0.0, 0.0),
                (0.181408951053528, 0.5),
                (1.0, 1.0)
            ]
        );
        assert!(!t.is_export_format());
    }

    #[test]
    fn bad_tables_are_refused_naming_what_is_wrong() {
        let mut buf = [(0.0, 0.0); MAX_POINTS];
        let parse = |s: &str, buf: &mut [(f64, f64); MAX_POINTS]| ValveTable::parse(s, buf);
        assert_eq!(
            parse("-1 -1\n0 0\n1 x\n", &mut buf),
            Err(TableError::Syntax { line: 3 })
        );
        assert_eq!(
            parse("-1 -1\n0 0\n1 x\n", &mut buf)
                .unwrap_err()
                .code()
                .name(),
            "dwTcHydAdsErrSyntax"
        );
        assert_eq!(
            parse("-1 -1\n0 0 0\n", &mut buf),
            Err(TableError::Syntax { line: 2 })
        );
        assert_eq!(
            parse("-1 -1\n+0.5 0\n", &mut buf),
            Err(TableError::Syntax { line: 2 })
        );
        assert_eq!(
            parse("-1 -1\nnan 0\n", &mut buf),
            Err(TableError::Syntax { line: 2 })
        );
        assert_eq!(
            ValveTable::new(&[(0.0, 0.0)]),
            Err(TableError::TooFewPoints { count: 1 })
        );
        assert_eq!(
            ValveTable::new(&[(-1.0, -1.0), (0.0, 0.0), (1.5, 1.0)]),
            Err(TableError::OutOfRange {
                index: 2,
                velocity: 1.5,
                output: 1.0
            })
        );
        assert_eq!(
            ValveTable::new(&[(-1.0, -1.0), (0.0, 0.0), (0.0, 0.5)]),
            Err(TableError::VelocityNotIncreasing {
                index: 2,
                velocity: 0.0,
                previous: 0.0
            })
        );
        assert_eq!(
            ValveTable::new(&[(-1.0, -1.0), (0.0, 0.0), (0.5, -0.1)]),
            Err(TableError::OutputFalls {
                index: 2,
                output: -0.1,
                previous: 0.0
            })
        );
        assert_eq!(
            ValveTable::new(&[(-1.0, -1.0), (0.1, 0.1), (1.0, 1.0)]),
            Err(TableError::NoZeroPoint)
        );
        let many = [(0.0, 0.0); MAX_POINTS + 1];
        assert_eq!(
            ValveTable::new(&many),
            Err(TableError::TooManyPoints {
                count: MAX_POINTS + 1
            })
        );
        assert!(TableError::NoZeroPoint.to_string().contains("zero point"));
    }
}
