//! The position controller and the Finish stage of a hydraulic axis, as one stage between the
//! axis' setpoint and its valve output (Beckhoff TwinCAT PLC Hydraulic Positioning library,
//! `MC_AxRtController_BkPlcMc` then `MC_AxRtFinish_BkPlcMc` / `MC_AxRtFinishLinear_BkPlcMc`,
//! in the order of `MC_AxRuntime_BkPlcMc`).
//!
//! The controller is the library's default one: a P part with `fLagAmp` (mm/s per mm, so 1/s)
//! on the lag `fSetPos - fActPos`, normalised by `fRefVelo` to the output's scale (inferred: the
//! library gives the unit, not the formula; ±1.0 is `fRefVelo` as for the set velocity),
//! limited to ±`fLagAmpOutL` when that is above 0 ("in preparation" in the library; 0 there
//! means no limit). It acts only while the generator asks for position control: at standstill
//! in the displacement-based mode (the generator's [`Setpoint::position_control`]), always for
//! setpoints another generator computes (gearing, camming, velocity). Not built yet: the I part
//! (`fLagAmpTi`, `fLagAmpDx`, `fLagAmpWuL`) and the extended controller
//! `MC_AxRtPosPiControllerEx_BkPlcMc`.
//!
//! [`Setpoint::position_control`]: super::generator::Setpoint::position_control

use super::finish::{Finish, FinishError, FinishInput, FinishParams};
use super::valve_table::ValveTable;

/// The parameters of the position controller and Finish (members of `ST_TcHydAxParam`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct HydControllerParams {
    /// `fLagAmp` (mm/s per mm, >= 0): the P gain of the position controller.
    pub lag_amp: f64,
    /// `fLagAmpOutL` (normalised, >= 0): the limit of the controller's output; 0: none.
    pub lag_out_limit: f64,
    /// The Finish stage (`fRefVelo`, feed forward, area ratio, overlap, bend point, offset).
    pub finish: FinishParams,
}

impl Default for HydControllerParams {
    /// The library's defaults: `fLagAmp` 0.05, no output limit, Finish's defaults.
    fn default() -> Self {
        Self {
            lag_amp: 0.05,
            lag_out_limit: 0.0,
            finish: FinishParams::default(),
        }
    }
}

/// One cycle's values into the controller.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct HydControlInput {
    /// `fSetPos` (mm).
    pub set_position: f64,
    /// `fSetVelo` (mm/s).
    pub set_velocity: f64,
    /// `fActPos` (mm).
    pub actual_position: f64,
    /// The position controller acts this cycle.
    pub position_control: bool,
    /// `fClampingOutput` (V): the pressing output of target clamping.
    pub clamping_output: f64,
}

/// One cycle's values out of the controller.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct HydControlOutput {
    /// `fLagCtrlOutput` (normalised).
    pub lag_ctrl_output: f64,
    /// `fOutput` (normalised, ±1.0 = ±10 V).
    pub output: f64,
    /// The overlap compensation in the output.
    pub active_overlap: f64,
}

/// The position controller and Finish of one hydraulic axis; with a characteristic curve, the
/// Finish is `MC_AxRtFinishLinear_BkPlcMc`, else the sectional linearisation.
#[derive(Clone, Debug, PartialEq)]
pub struct HydController {
    params: HydControllerParams,
    finish: Finish,
    /// The characteristic curve (4 KiB: boxed when built, never per cycle).
    table: Option<Box<ValveTable>>,
}

impl HydController {
    /// The controller with `params` and, optionally, a characteristic curve. Refuses a
    /// parameter out of range ([`FinishError`] names it; `fLagAmp` and `fLagAmpOutL` too).
    pub fn new(
        params: HydControllerParams,
        table: Option<ValveTable>,
    ) -> Result<Self, FinishError> {
        for (parameter, value) in [
            ("fLagAmp", params.lag_amp),
            ("fLagAmpOutL", params.lag_out_limit),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(FinishError::OutOfRange {
                    parameter,
                    value,
                    min: 0.0,
                    max: f64::MAX,
                });
            }
        }
        Ok(Self {
            finish: Finish::new(params.finish)?,
            params,
            table: table.map(Box::new),
        })
    }

    /// The parameters.
    pub fn params(&self) -> &HydControllerParams {
        &self.params
    }

    /// One cycle: the controller's output from the lag (0 without position control), then
    /// Finish. Non-finite inputs give an output of 0.
    pub fn step(&self, i: &HydControlInput) -> HydControlOutput {
        let finite = [
            i.set_position,
            i.set_velocity,
            i.actual_position,
            i.clamping_output,
        ]
        .iter()
        .all(|x| x.is_finite());
        if !finite {
            return HydControlOutput::default();
        }
        let lag = if i.position_control {
            let u = self.params.lag_amp * (i.set_position - i.actual_position)
                / self.params.finish.ref_velo;
            match self.params.lag_out_limit {
                l if l > 0.0 => u.clamp(-l, l),
                _ => u,
            }
        } else {
            0.0
        };
        let input = FinishInput {
            set_velocity: i.set_velocity,
            lag_ctrl_output: lag,
            clamping_output: i.clamping_output,
        };
        let out = match &self.table {
            Some(t) => self.finish.linear(t, &input),
            None => self.finish.sectional(&input),
        };
        HydControlOutput {
            lag_ctrl_output: lag,
            output: out.output,
            active_overlap: out.active_overlap,
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    fn params() -> HydControllerParams {
        HydControllerParams {
            lag_amp: 20.0,
            lag_out_limit: 0.0,
            finish: FinishParams {
                ref_velo: 200.0,
                ..FinishParams::default()
            },
        }
    }

    #[test]
    fn the_p_part_is_the_lag_times_the_gain_over_the_reference_velocity() {
        let c = HydController::new(params(), None).unwrap();
        // 0.5 mm behind at 20 mm/s per mm: 10 mm/s of 200, 0.05; plus 40 mm/s fed forward.
        let out = c.step(&HydControlInput {
            set_position: 10.5,
            set_velocity: 40.0,
            actual_position: 10.0,
            position_control: true,
            clamping_output: 0.0,
        });
        assert!((out.lag_ctrl_output - 0.05).abs() < 1e-15);
        assert!((out.output - 0.25).abs() < 1e-15, "{out:?}");
        // Without position control only the feed forward.
        let out = c.step(&HydControlInput {
            set_position: 10.5,
            set_velocity: 40.0,
            actual_position: 10.0,
            position_control: false,
            clamping_output: 0.0,
        });
        assert_eq!((out.lag_ctrl_output, out.output), (0.0, 0.2));
    }

    #[test]
    fn the_output_limit_bounds_the_controller_and_bad_values_are_refused() {
        let c = HydController::new(
            HydControllerParams {
                lag_out_limit: 0.1,
                ..params()
            },
            None,
        )
        .unwrap();
        let out = c.step(&HydControlInput {
            set_position: 100.0,
            actual_position: 0.0,
            position_control: true,
            ..HydControlInput::default()
        });
        assert_eq!(out.lag_ctrl_output, 0.1);
        let e = HydController::new(
            HydControllerParams {
                lag_amp: -1.0,
                ..params()
            },
            None,
        )
        .unwrap_err();
        assert!(e.to_string().contains("fLagAmp"), "{e}");
        let out = c.step(&HydControlInput {
            set_position: f64::NAN,
            position_control: true,
            ..HydControlInput::default()
        });
        assert_eq!(out, HydControlOutput::default());
    }
}
