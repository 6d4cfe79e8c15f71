//! The Finish stage of a hydraulic axis: the control values (set velocity with its feed forward,
//! the position controller's output, the overlap compensation, the clamping output and the
//! offset) combined into the valve's normalised output, with the valve's and cylinder's
//! non-linearities compensated, as `MC_AxRtFinish_BkPlcMc` (sectional linearisation) and
//! `MC_AxRtFinishLinear_BkPlcMc` (characteristic curve) do it (Beckhoff TwinCAT PLC Hydraulic
//! Positioning library, 4.4.7.3, 4.4.7.4 and 5.5 'Final processing').
//!
//! Units as in the library: velocities in mm/s (the axis' unit per second), the normalised
//! values relative to the reference velocity `fRefVelo` (±1.0 ≙ `fRefVelo` ≙ full-scale
//! output, ±10 V), the offset `fZeroCompensation` and the clamping output in volts.
//!
//! # Sectional linearisation ([`Finish::sectional`])
//! The library describes the steps, not the arithmetic; each formula below is inferred from its
//! prose and stated:
//! 1. `v = fFeedForward · fSetVelo / fRefVelo + fLagCtrlOutput` ("the set velocity weighted
//!    with the pre-control and the controller output are added to the output velocity").
//! 2. Direction dependency: `v · fAreaRatio` when `v > 0` and `fAreaRatio >= 1`, `v /
//!    fAreaRatio` when `v < 0` and `fAreaRatio <= 1` (as 5.5 says: only the slower direction is
//!    raised).
//! 3. The bend of the characteristic curve: `|v|` up to `fValve_BendPointVelo` is mapped
//!    linearly onto `0..fValve_BendPointOutput`, above it linearly onto
//!    `fValve_BendPointOutput..1` (inferred: two straight sections through the bend point and
//!    full scale, the same for both directions; a bend point of 0 or 1 means none). With the bend
//!    of FAQ #22's example (velocity 0.16 at output 0.4) it gives that table's positive side
//!    exactly (unit test).
//! 4. The overlap compensation of the direction of `v` (`fValve_OverlapCompP`, or with
//!    `bAsymmetricalTargeting` `fValve_OverlapCompM` for `v < 0`), "ramped linearly from zero to
//!    the set overlap compensation between 0 and V_Creep" (inferred: against the velocity of step
//!    1, `fCreepSpeedP/M / fRefVelo`; with a creep speed of 0 fully effective for any `v != 0`).
//! 5. `fOutput` = the result of 3 + the overlap + `fClampingOutput / 10` + `fZeroCompensation /
//!    10`, limited to full scale ±1 (inferred: an analog output gives no more).
//!
//! # Characteristic curve ([`Finish::linear`])
//! Step 1, then the output of the [`ValveTable`] for `v` (with the linearisation limit of its
//! direction, `Valve_LinLimitP/M`), then the clamping output and the offset as in step 5. The area
//! ratio, the bend point and the overlap compensation have no effect: they belong in the table
//! (4.4.7.4).
//!
//! Pure: no IO, no clock, no allocation.

use crate::catalog::hyd_error::HydErrorCode;
use crate::hydraulic::valve_table::ValveTable;

/// Full scale of the valve output in volts (the normalised output ±1.0).
pub const FULL_SCALE_V: f64 = 10.0;

/// The parameters of the Finish stage (members of `ST_TcHydAxParam`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct FinishParams {
    /// `fRefVelo` (mm/s, > 0): the velocity at full-scale output.
    pub ref_velo: f64,
    /// `fFeedForward` (1, finite, >= 0; default 1.0): the weight of the set velocity.
    pub feed_forward: f64,
    /// `fAreaRatio` (1, finite, > 0; default 1.0): the direction compensation.
    pub area_ratio: f64,
    /// `fValve_OverlapCompP` (1, 0..1): the overlap compensation (positive direction, or both).
    pub overlap_comp_p: f64,
    /// `fValve_OverlapCompM` (1, 0..1): the overlap compensation of the negative direction, with
    /// [`FinishParams::asymmetrical`].
    pub overlap_comp_m: f64,
    /// `fCreepSpeedP` (mm/s, >= 0): where the overlap compensation is fully ramped in.
    pub creep_speed_p: f64,
    /// `fCreepSpeedM` (mm/s, >= 0), with [`FinishParams::asymmetrical`].
    pub creep_speed_m: f64,
    /// `bAsymmetricalTargeting`: the M values serve the negative direction.
    pub asymmetrical: bool,
    /// `fValve_BendPointVelo` (1, 0..1; 0: no bend).
    pub bend_point_velo: f64,
    /// `fValve_BendPointOutput` (1, 0..1; 0: no bend).
    pub bend_point_output: f64,
    /// `fZeroCompensation` (V, within ±10): the offset of the analog output.
    pub zero_compensation: f64,
    /// `Valve_LinLimitP` (mm/s, >= 0): below it the characteristic curve is a straight line
    /// through zero (positive direction).
    pub lin_limit_p: f64,
    /// `Valve_LinLimitM` (mm/s, >= 0): the same for the negative direction.
    pub lin_limit_m: f64,
}

impl Default for FinishParams {
    /// The library's defaults (`ST_TcHydAxParam`): `fRefVelo` 500 mm/s, feed forward 1.0, area
    /// ratio 1.0, creep speed 80 mm/s, no overlap compensation, bend, offset or linearisation
    /// limit.
    fn default() -> Self {
        Self {
            ref_velo: 500.0,
            feed_forward: 1.0,
            area_ratio: 1.0,
            overlap_comp_p: 0.0,
            overlap_comp_m: 0.0,
            creep_speed_p: 80.0,
            creep_speed_m: 80.0,
            asymmetrical: false,
            bend_point_velo: 0.0,
            bend_point_output: 0.0,
            zero_compensation: 0.0,
            lin_limit_p: 0.0,
            lin_limit_m: 0.0,
        }
    }
}

/// Why Finish parameters were refused (nothing of them is kept).
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum FinishError {
    /// A parameter outside its range.
    OutOfRange {
        /// The library's name of the parameter.
        parameter: &'static str,
        /// Its value.
        value: f64,
        /// The lowest value allowed.
        min: f64,
        /// The highest value allowed.
        max: f64,
    },
    /// A parameter that must be above a bound is not.
    NotAbove {
        /// The library's name of the parameter.
        parameter: &'static str,
        /// Its value.
        value: f64,
        /// The bound it must exceed.
        bound: f64,
    },
    /// Only one of the two coordinates of the bend point is set (both 0: no bend; both within
    /// 0 and 1: a bend).
    BendPoint {
        /// `fValve_BendPointVelo`.
        velo: f64,
        /// `fValve_BendPointOutput`.
        output: f64,
    },
    /// The drive stage's form and `bDrive_AbsoluteOutput` do not go together.
    DriveOutput(super::drive_output::DriveOutputError),
}

impl FinishError {
    /// The library's error code: `dwTcHydErrCdRefVelo` for `fRefVelo`, else
    /// `dwTcHydAdsErrIllegalValue`.
    pub fn code(&self) -> HydErrorCode {
        match self {
            Self::NotAbove {
                parameter: "fRefVelo",
                ..
            } => HydErrorCode::REF_VELO,
            _ => HydErrorCode::ILLEGAL_VALUE,
        }
    }
}

impl core::fmt::Display for FinishError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::OutOfRange {
                parameter,
                value,
                min,
                max,
            } => write!(f, "{parameter} = {value}: must lie within {min} and {max}"),
            Self::NotAbove {
                parameter,
                value,
                bound,
            } => write!(f, "{parameter} = {value}: must be above {bound}"),
            Self::BendPoint { velo, output } => write!(
                f,
                "bend point (fValve_BendPointVelo {velo}, fValve_BendPointOutput {output}): \
                 both 0 (no bend) or both above 0 and below 1"
            ),
            Self::DriveOutput(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for FinishError {}

/// One cycle's control values into the Finish stage (members of `ST_TcHydAxRtData`).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct FinishInput {
    /// `fSetVelo` (mm/s): the generator's set velocity.
    pub set_velocity: f64,
    /// `fLagCtrlOutput` (1): the position controller's output, normalised.
    pub lag_ctrl_output: f64,
    /// `fClampingOutput` (V): the generator's pressing output (`fTargetClamping` with the sign
    /// of the approach, at the target; 0 otherwise).
    pub clamping_output: f64,
}

/// What the Finish stage gives the drive stage (members of `ST_TcHydAxRtData`).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct FinishOutput {
    /// `fOutput` (1, within ±1): the valve's normalised output.
    pub output: f64,
    /// `fActiveOverlap` (1): the overlap compensation included (0 with a characteristic curve).
    pub active_overlap: f64,
}

/// The Finish stage of one axis, its parameters checked (see the module documentation).
#[doc(alias = "MC_AxRtFinish_BkPlcMc")]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Finish {
    p: FinishParams,
}

impl Finish {
    /// The stage with parameters `p`, each checked ([`FinishError`]).
    pub fn new(p: FinishParams) -> Result<Self, FinishError> {
        let above = |parameter, value: f64, bound| {
            if value.is_finite() && value > bound {
                Ok(())
            } else {
                Err(FinishError::NotAbove {
                    parameter,
                    value,
                    bound,
                })
            }
        };
        let within = |parameter, value: f64, min, max| {
            if value.is_finite() && (min..=max).contains(&value) {
                Ok(())
            } else {
                Err(FinishError::OutOfRange {
                    parameter,
                    value,
                    min,
                    max,
                })
            }
        };
        above("fRefVelo", p.ref_velo, 0.0)?;
        within("fFeedForward", p.feed_forward, 0.0, 10.0)?;
        above("fAreaRatio", p.area_ratio, 0.0)?;
        within("fValve_OverlapCompP", p.overlap_comp_p, 0.0, 1.0)?;
        within("fValve_OverlapCompM", p.overlap_comp_m, 0.0, 1.0)?;
        within("fCreepSpeedP", p.creep_speed_p, 0.0, p.ref_velo)?;
        within("fCreepSpeedM", p.creep_speed_m, 0.0, p.ref_velo)?;
        within(
            "fZeroCompensation",
            p.zero_compensation,
            -FULL_SCALE_V,
            FULL_SCALE_V,
        )?;
        within("Valve_LinLimitP", p.lin_limit_p, 0.0, p.ref_velo)?;
        within("Valve_LinLimitM", p.lin_limit_m, 0.0, p.ref_velo)?;
        let (bv, bo) = (p.bend_point_velo, p.bend_point_output);
        let none = bv == 0.0 && bo == 0.0;
        let inside = |x: f64| x > 0.0 && x < 1.0;
        if !(none || inside(bv) && inside(bo)) {
            return Err(FinishError::BendPoint {
                velo: bv,
                output: bo,
            });
        }
        Ok(Self { p })
    }

    /// The parameters.
    pub fn params(&self) -> &FinishParams {
        &self.p
    }

    /// Writes `fZeroCompensation` (V), limited to ±10 V (what `MC_AxCtrlAutoZero_BkPlcMc`
    /// does to `ST_TcHydAxParam`); a value that is not a number changes nothing.
    pub fn set_zero_compensation(&mut self, volts: f64) {
        if !volts.is_nan() {
            self.p.zero_compensation = volts.clamp(-FULL_SCALE_V, FULL_SCALE_V);
        }
    }

    /// Step 1: the commanded velocity, normalised.
    fn commanded(&self, i: &FinishInput) -> f64 {
        self.p.feed_forward * i.set_velocity / self.p.ref_velo + i.lag_ctrl_output
    }

    /// Step 5: the clamping output and the offset added, limited to full scale.
    fn output(&self, v: f64, i: &FinishInput, active_overlap: f64) -> FinishOutput {
        let out =
            v + active_overlap + (i.clamping_output + self.p.zero_compensation) / FULL_SCALE_V;
        FinishOutput {
            output: if out.is_nan() {
                0.0
            } else {
                out.clamp(-1.0, 1.0)
            },
            active_overlap,
        }
    }

    /// `MC_AxRtFinish_BkPlcMc`: the sectional linearisation (steps 1 to 5 of the module
    /// documentation).
    pub fn sectional(&self, i: &FinishInput) -> FinishOutput {
        let p = &self.p;
        let v = self.commanded(i);
        let v_area = if v > 0.0 && p.area_ratio >= 1.0 {
            v * p.area_ratio
        } else if v < 0.0 && p.area_ratio <= 1.0 {
            v / p.area_ratio
        } else {
            v
        };
        let v_bend = self.bend(v_area);
        let negative = v < 0.0 && p.asymmetrical;
        let (ovl, creep) = if negative {
            (p.overlap_comp_m, p.creep_speed_m)
        } else {
            (p.overlap_comp_p, p.creep_speed_p)
        };
        let creep_n = creep / p.ref_velo;
        let ramp = if v == 0.0 {
            0.0
        } else if creep_n > 0.0 {
            (v.abs() / creep_n).min(1.0)
        } else {
            1.0
        };
        self.output(v_bend, i, (ovl * ramp).copysign(v))
    }

    /// Step 3: the bend of the characteristic curve.
    fn bend(&self, v: f64) -> f64 {
        let (bv, bo) = (self.p.bend_point_velo, self.p.bend_point_output);
        if bv == 0.0 {
            return v;
        }
        let a = v.abs();
        let mapped = if a <= bv {
            a * bo / bv
        } else {
            bo + (a - bv) * (1.0 - bo) / (1.0 - bv)
        };
        mapped.copysign(v)
    }

    /// `MC_AxRtFinishLinear_BkPlcMc`: the characteristic curve `table` (the module
    /// documentation); without a table the library falls back to [`Finish::sectional`], which
    /// the caller does by calling it.
    pub fn linear(&self, table: &ValveTable, i: &FinishInput) -> FinishOutput {
        let v = self.commanded(i);
        let limit = if v < 0.0 {
            self.p.lin_limit_m
        } else {
            self.p.lin_limit_p
        };
        self.output(table.output(v, limit / self.p.ref_velo), i, 0.0)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;
    use crate::hydraulic::valve_table::MAX_POINTS;

    fn input(set_velocity: f64) -> FinishInput {
        FinishInput {
            set_velocity,
            ..FinishInput::default()
        }
    }

    fn close(a: f64, b: f64) {
        assert!((a - b).abs() < 1e-12, "{a} != {b}");
    }

    #[test]
    fn with_the_defaults_the_output_is_the_normalised_set_velocity_plus_the_controller() {
        let f = Finish::new(FinishParams::default()).unwrap();
        close(f.sectional(&input(100.0)).output, 0.2);
        let i = FinishInput {
            set_velocity: -100.0,
            lag_ctrl_output: 0.05,
            clamping_output: 0.0,
        };
        close(f.sectional(&i).output, -0.15);
        // Full scale is the limit.
        assert_eq!(f.sectional(&input(900.0)).output, 1.0);
        assert_eq!(f.sectional(&input(-900.0)).output, -1.0);
        assert_eq!(f.sectional(&input(0.0)).output, 0.0);
    }

    #[test]
    fn the_area_ratio_raises_only_the_slower_direction() {
        let with = |r| {
            Finish::new(FinishParams {
                area_ratio: r,
                ..FinishParams::default()
            })
            .unwrap()
        };
        // Ratio >= 1: positive is the slower direction, multiplied.
        close(with(1.5).sectional(&input(100.0)).output, 0.3);
        close(with(1.5).sectional(&input(-100.0)).output, -0.2);
        // Ratio <= 1: negative is the slower direction, divided.
        close(with(0.5).sectional(&input(-100.0)).output, -0.4);
        close(with(0.5).sectional(&input(100.0)).output, 0.2);
    }

    #[test]
    fn the_overlap_compensation_is_ramped_in_up_to_creep_speed() {
        // Creep 50 mm/s of 500: fully in from 0.1 normalised.
        let p = FinishParams {
            overlap_comp_p: 0.1,
            overlap_comp_m: 0.2,
            creep_speed_p: 50.0,
            creep_speed_m: 25.0,
            ..FinishParams::default()
        };
        let f = Finish::new(p).unwrap();
        let o = f.sectional(&input(25.0));
        close(o.active_overlap, 0.05);
        close(o.output, 0.05 + 0.05);
        close(f.sectional(&input(100.0)).active_overlap, 0.1);
        // Symmetric (not asymmetrical): the P values for both directions.
        close(f.sectional(&input(-25.0)).active_overlap, -0.05);
        assert_eq!(f.sectional(&input(0.0)).active_overlap, 0.0);
        // Asymmetrical: the M values for the negative direction (creep 25 mm/s: fully in).
        let f = Finish::new(FinishParams {
            asymmetrical: true,
            ..p
        })
        .unwrap();
        close(f.sectional(&input(-25.0)).active_overlap, -0.2);
        close(f.sectional(&input(-12.5)).active_overlap, -0.1);
        close(f.sectional(&input(25.0)).active_overlap, 0.05);
    }

    #[test]
    fn the_bend_point_gives_the_faq_22_curve_on_its_positive_side() {
        // FAQ #22: velocity 0.16 at output 0.4, full scale at 1.0.
        let f = Finish::new(FinishParams {
            bend_point_velo: 0.16,
            bend_point_output: 0.4,
            ..FinishParams::default()
        })
        .unwrap();
        let table = ValveTable::parse(
            crate::hydraulic::valve_table::tests::FAQ22,
            &mut [(0.0, 0.0); MAX_POINTS],
        )
        .unwrap();
        for k in 0..=1000 {
            let v = f64::from(k) / 1000.0;
            let s = f.sectional(&input(v * 500.0)).output;
            let l = f.linear(&table, &input(v * 500.0)).output;
            assert!((s - l).abs() < 1e-12, "at {v}: sectional {s}, table {l}");
        }
        // And symmetric on the negative side (where the table also holds the area ratio).
        close(f.sectional(&input(-40.0)).output, -0.2);
    }

    #[test]
    fn offset_and_clamping_output_are_added_in_volts() {
        let f = Finish::new(FinishParams {
            zero_compensation: 0.5,
            ..FinishParams::default()
        })
        .unwrap();
        close(f.sectional(&input(0.0)).output, 0.05);
        let pressing = FinishInput {
            clamping_output: -2.0,
            ..FinishInput::default()
        };
        close(f.sectional(&pressing).output, -0.15);
        let table = ValveTable::new(&[(-1.0, -1.0), (0.0, 0.0), (1.0, 1.0)]).unwrap();
        close(f.linear(&table, &pressing).output, -0.15);
        close(f.linear(&table, &input(100.0)).output, 0.25);
    }

    #[test]
    fn with_a_table_area_ratio_bend_and_overlap_have_no_effect() {
        let f = Finish::new(FinishParams {
            area_ratio: 2.0,
            overlap_comp_p: 0.1,
            bend_point_velo: 0.5,
            bend_point_output: 0.2,
            lin_limit_p: 50.0,
            ..FinishParams::default()
        })
        .unwrap();
        let table = ValveTable::parse(
            crate::hydraulic::valve_table::tests::FAQ22,
            &mut [(0.0, 0.0); MAX_POINTS],
        )
        .unwrap();
        let o = f.linear(&table, &input(150.0));
        // 150 mm/s is 0.3: the table's point (0.3, 0.5).
        close(o.output, 0.5);
        assert_eq!(o.active_overlap, 0.0);
        // Below Valve_LinLimitP (50 mm/s = 0.1): the line through zero to the curve at 0.1.
        close(f.linear(&table, &input(25.0)).output, 0.25 * 0.5);
    }

    #[test]
    fn bad_parameters_are_refused_naming_them() {
        let bad = |p: FinishParams| Finish::new(p).unwrap_err();
        let d = FinishParams::default();
        assert_eq!(
            bad(FinishParams { ref_velo: 0.0, ..d }),
            FinishError::NotAbove {
                parameter: "fRefVelo",
                value: 0.0,
                bound: 0.0
            }
        );
        assert_eq!(
            bad(FinishParams { ref_velo: 0.0, ..d }).code().name(),
            "dwTcHydErrCdRefVelo"
        );
        assert!(matches!(
            bad(FinishParams {
                area_ratio: f64::NAN,
                ..d
            }),
            FinishError::NotAbove {
                parameter: "fAreaRatio",
                ..
            }
        ));
        assert_eq!(
            bad(FinishParams {
                zero_compensation: 12.0,
                ..d
            }),
            FinishError::OutOfRange {
                parameter: "fZeroCompensation",
                value: 12.0,
                min: -10.0,
                max: 10.0
            }
        );
        assert!(matches!(
            bad(FinishParams {
                overlap_comp_m: -0.1,
                ..d
            }),
            FinishError::OutOfRange {
                parameter: "fValve_OverlapCompM",
                ..
            }
        ));
        assert_eq!(
            bad(FinishParams {
                bend_point_velo: 0.3,
                ..d
            }),
            FinishError::BendPoint {
                velo: 0.3,
                output: 0.0
            }
        );
        assert!(bad(FinishParams {
            bend_point_velo: 1.0,
            bend_point_output: 0.5,
            ..d
        })
        .to_string()
        .contains("both 0 (no bend)"));
    }
}
