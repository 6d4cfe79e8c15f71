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
//! setpoints another generator computes (gearing, camming, velocity).
//!
//! The optional I part (the library: "the Ti parameter is used by this controller as Ki; 0.0
//! disables the I part"; its structure figure is not in the text, so the rest is inferred):
//! while the controller acts and the lag is beyond the response window `fLagAmpDx`, the I part
//! grows by `fLagAmpTi · lag · dt / fRefVelo` (normalised, like the P part), limited to
//! ±`fLagAmpWuL` (±1.0, full scale, when 0); within the window it holds. While the controller
//! does not act (a move in the displacement mode) the I part holds and the output is 0; without
//! the drive's enable it is cleared ([`HydController::reset`]), as the extended controller
//! documents. The sum is limited by `fLagAmpOutL`.
//!
//! With [`HydControllerParams::extended`] the controller is `MC_AxRtPosPiControllerEx_BkPlcMc`:
//! the same P and I parts plus the D part and the condition feedback of [`super::controller_ex`]
//! (normalised by `fRefVelo`), which act whenever the drive is enabled, also during a move in
//! the displacement mode (inferred: they feed back velocities, not the lag); the sum is limited
//! by `fLagAmpOutL`. Its output `InWindup` is [`HydControlOutput::in_windup`].
//!
//! [`HydControlInput::zero_compensation`] writes `fZeroCompensation` into Finish's parameters,
//! as `MC_AxCtrlAutoZero_BkPlcMc` writes it into `ST_TcHydAxParam`
//! ([`super::auto_zero`]).
//!
//! [`Setpoint::position_control`]: super::generator::Setpoint::position_control

use super::controller_ex::{ExInput, PosPiControllerEx, PosPiControllerExParams};
use super::finish::{Finish, FinishError, FinishInput, FinishParams};
use super::valve_table::ValveTable;

/// The parameters of the position controller and Finish (members of `ST_TcHydAxParam`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct HydControllerParams {
    /// `fLagAmp` (mm/s per mm, >= 0): the P gain of the position controller.
    pub lag_amp: f64,
    /// `fLagAmpOutL` (normalised, >= 0): the limit of the controller's output; 0: none.
    pub lag_out_limit: f64,
    /// `fLagAmpTi` (mm/s per mm and s, >= 0), used as Ki: the I part's gain; 0: no I part.
    pub lag_amp_ti: f64,
    /// `fLagAmpDx` (mm, >= 0): the response window; the I part grows only beyond it.
    pub lag_amp_dx: f64,
    /// `fLagAmpWuL` (normalised, >= 0): the I part's limit; 0: full scale (1.0).
    pub lag_amp_wul: f64,
    /// The Finish stage (`fRefVelo`, feed forward, area ratio, overlap, bend point, offset).
    pub finish: FinishParams,
    /// The drive stage after Finish (the valve's output form, `bDrive_AbsoluteOutput`,
    /// `bDrive_Reversed`); the drive connection applies it.
    pub drive: super::drive_output::DriveOutputParams,
    /// The extended controller `MC_AxRtPosPiControllerEx_BkPlcMc` in place of the default
    /// one: its D part and condition feedback; `None`: the default controller.
    #[doc(alias = "MC_AxRtPosPiControllerEx_BkPlcMc")]
    pub extended: Option<PosPiControllerExParams>,
}

impl Default for HydControllerParams {
    /// The library's defaults: `fLagAmp` 0.05, no output limit, Finish's defaults.
    fn default() -> Self {
        Self {
            lag_amp: 0.05,
            lag_out_limit: 0.0,
            lag_amp_ti: 0.0,
            lag_amp_dx: 0.0,
            lag_amp_wul: 0.0,
            finish: FinishParams::default(),
            drive: super::drive_output::DriveOutputParams::default(),
            extended: None,
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
    /// `fActVelo` (mm/s): the extended controller's D part and feedback use it.
    pub actual_velocity: f64,
    /// The position controller acts this cycle.
    pub position_control: bool,
    /// `fClampingOutput` (V): the pressing output of target clamping.
    pub clamping_output: f64,
    /// `fZeroCompensation` (V) as `MC_AxCtrlAutoZero_BkPlcMc` has set it; `None`: unchanged.
    pub zero_compensation: Option<f64>,
    /// The control value of `MC_AxRtSetDirectOutput_BkPlcMc` (normalised): with it, Finish
    /// takes it as its commanded value (step 1) in place of the set velocity and the position
    /// controller's output (0, the I part held); the clamping output is not added.
    pub direct_output: Option<f64>,
    /// The cycle (s, > 0): the I part's time step.
    pub dt: f64,
}

/// One cycle's values out of the controller.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct HydControlOutput {
    /// `fLagCtrlOutput` (normalised): P and I part.
    pub lag_ctrl_output: f64,
    /// The I part (normalised).
    pub i_part: f64,
    /// `fOutput` (normalised, ±1.0 = ±10 V).
    pub output: f64,
    /// The overlap compensation in the output.
    pub active_overlap: f64,
    /// `InWindup`: the I part is at its limit.
    pub in_windup: bool,
}

/// The position controller and Finish of one hydraulic axis; with a characteristic curve, the
/// Finish is `MC_AxRtFinishLinear_BkPlcMc`, else the sectional linearisation.
#[derive(Clone, Debug, PartialEq)]
pub struct HydController {
    params: HydControllerParams,
    finish: Finish,
    /// The characteristic curve (4 KiB: boxed when built, never per cycle).
    table: Option<Box<ValveTable>>,
    /// The I part (normalised).
    i_part: f64,
    /// The extended controller's D part and condition feedback.
    ex: Option<PosPiControllerEx>,
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
            ("fLagAmpTi", params.lag_amp_ti),
            ("fLagAmpDx", params.lag_amp_dx),
            ("fLagAmpWuL", params.lag_amp_wul),
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
        params.drive.check().map_err(FinishError::DriveOutput)?;
        let ex = match params.extended {
            Some(e) => Some(PosPiControllerEx::new(e).map_err(|(parameter, value)| {
                FinishError::OutOfRange {
                    parameter,
                    value,
                    min: 0.0,
                    max: f64::MAX,
                }
            })?),
            None => None,
        };
        Ok(Self {
            finish: Finish::new(params.finish)?,
            params,
            table: table.map(Box::new),
            i_part: 0.0,
            ex,
        })
    }

    /// Clears the I part and the extended controller's states (the drive is not enabled).
    pub fn reset(&mut self) {
        self.i_part = 0.0;
        if let Some(ex) = &mut self.ex {
            ex.reset();
        }
    }

    /// The parameters.
    pub fn params(&self) -> &HydControllerParams {
        &self.params
    }

    /// One cycle: the controller's output from the lag (0 without position control), then
    /// Finish. Non-finite inputs give an output of 0 and change nothing.
    pub fn step(&mut self, i: &HydControlInput) -> HydControlOutput {
        let finite = [
            i.set_position,
            i.set_velocity,
            i.actual_position,
            i.actual_velocity,
            i.clamping_output,
            i.dt,
            i.zero_compensation.unwrap_or(0.0),
        ]
        .iter()
        .all(|x| x.is_finite());
        if !finite {
            return HydControlOutput::default();
        }
        if let Some(z) = i.zero_compensation {
            self.finish.set_zero_compensation(z);
        }
        let pi = if i.position_control && i.direct_output.is_none() {
            self.lag_ctrl_output(i.set_position - i.actual_position, i.dt)
        } else {
            0.0
        };
        let ex = match &mut self.ex {
            Some(ex) if i.direct_output.is_none() => {
                let response = ex.step(&ExInput {
                    set_velocity: i.set_velocity,
                    actual_velocity: i.actual_velocity,
                    dt: i.dt,
                });
                response / self.params.finish.ref_velo
            }
            _ => 0.0,
        };
        let lag = match self.params.lag_out_limit {
            l if l > 0.0 => (pi + ex).clamp(-l, l),
            _ => pi + ex,
        };
        let input = match i.direct_output {
            // Step 1 of Finish gives `fFeedForward · fSetVelo / fRefVelo + fLagCtrlOutput`;
            // the direct control value stands for that sum.
            Some(d) if d.is_finite() => FinishInput {
                set_velocity: 0.0,
                lag_ctrl_output: d,
                clamping_output: 0.0,
            },
            _ => FinishInput {
                set_velocity: i.set_velocity,
                lag_ctrl_output: lag,
                clamping_output: i.clamping_output,
            },
        };
        let out = match &self.table {
            Some(t) => self.finish.linear(t, &input),
            None => self.finish.sectional(&input),
        };
        HydControlOutput {
            lag_ctrl_output: lag,
            i_part: self.i_part,
            output: out.output,
            active_overlap: out.active_overlap,
            in_windup: self.params.lag_amp_ti > 0.0 && self.i_part.abs() >= self.i_limit(),
        }
    }

    /// The I part's limit: `fLagAmpWuL`, full scale when 0.
    fn i_limit(&self) -> f64 {
        match self.params.lag_amp_wul {
            l if l > 0.0 => l,
            _ => 1.0,
        }
    }

    /// The P part and the I part grown beyond the response window for `lag` (mm), before the
    /// output limit.
    fn lag_ctrl_output(&mut self, lag: f64, dt: f64) -> f64 {
        let p = &self.params;
        let ref_velo = p.finish.ref_velo;
        if p.lag_amp_ti > 0.0 && lag.abs() > p.lag_amp_dx {
            let limit = self.i_limit();
            self.i_part = (self.i_part + p.lag_amp_ti * lag * dt / ref_velo).clamp(-limit, limit);
        }
        self.params.lag_amp * lag / ref_velo + self.i_part
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    fn params() -> HydControllerParams {
        HydControllerParams {
            lag_amp: 20.0,
            finish: FinishParams {
                ref_velo: 200.0,
                ..FinishParams::default()
            },
            ..HydControllerParams::default()
        }
    }

    fn at(set_position: f64, actual_position: f64) -> HydControlInput {
        HydControlInput {
            set_position,
            actual_position,
            position_control: true,
            dt: 0.001,
            ..HydControlInput::default()
        }
    }

    #[test]
    fn the_p_part_is_the_lag_times_the_gain_over_the_reference_velocity() {
        let mut c = HydController::new(params(), None).unwrap();
        // 0.5 mm behind at 20 mm/s per mm: 10 mm/s of 200, 0.05; plus 40 mm/s fed forward.
        let out = c.step(&HydControlInput {
            set_velocity: 40.0,
            ..at(10.5, 10.0)
        });
        assert!((out.lag_ctrl_output - 0.05).abs() < 1e-15);
        assert!((out.output - 0.25).abs() < 1e-15, "{out:?}");
        // Without position control only the feed forward.
        let out = c.step(&HydControlInput {
            set_velocity: 40.0,
            position_control: false,
            ..at(10.5, 10.0)
        });
        assert_eq!((out.lag_ctrl_output, out.output), (0.0, 0.2));
    }

    /// MC_AxRtSetDirectOutput_BkPlcMc's control value stands for Finish's step 1: the set
    /// velocity, the lag and the clamping output do not count; the offset does.
    #[test]
    fn a_direct_output_replaces_the_set_velocity_and_the_controller() {
        let mut c = HydController::new(params(), None).unwrap();
        let out = c.step(&HydControlInput {
            set_velocity: 40.0,
            clamping_output: 2.0,
            direct_output: Some(-0.35),
            ..at(10.5, 10.0)
        });
        assert_eq!((out.lag_ctrl_output, out.output), (0.0, -0.35));
        let mut c = HydController::new(
            HydControllerParams {
                finish: FinishParams {
                    zero_compensation: 0.5,
                    ..params().finish
                },
                ..params()
            },
            None,
        )
        .unwrap();
        let out = c.step(&HydControlInput {
            direct_output: Some(0.25),
            ..at(10.5, 10.0)
        });
        assert!((out.output - 0.3).abs() < 1e-15, "{out:?}");
    }

    #[test]
    fn the_output_limit_bounds_the_controller_and_bad_values_are_refused() {
        let mut c = HydController::new(
            HydControllerParams {
                lag_out_limit: 0.1,
                ..params()
            },
            None,
        )
        .unwrap();
        let out = c.step(&at(100.0, 0.0));
        assert_eq!(out.lag_ctrl_output, 0.1);
        for (bad, name) in [
            (
                HydControllerParams {
                    lag_amp: -1.0,
                    ..params()
                },
                "fLagAmp",
            ),
            (
                HydControllerParams {
                    lag_amp_ti: f64::NAN,
                    ..params()
                },
                "fLagAmpTi",
            ),
            (
                HydControllerParams {
                    lag_amp_dx: -0.1,
                    ..params()
                },
                "fLagAmpDx",
            ),
            (
                HydControllerParams {
                    lag_amp_wul: -1.0,
                    ..params()
                },
                "fLagAmpWuL",
            ),
        ] {
            let e = HydController::new(bad, None).unwrap_err();
            assert!(e.to_string().contains(name), "{e}");
        }
        let out = c.step(&HydControlInput {
            set_position: f64::NAN,
            ..at(0.0, 0.0)
        });
        assert_eq!(out, HydControlOutput::default());
    }

    #[test]
    fn the_i_part_grows_beyond_the_window_holds_within_it_and_is_limited() {
        let mut c = HydController::new(
            HydControllerParams {
                lag_amp_ti: 50.0,
                lag_amp_dx: 0.1,
                lag_amp_wul: 0.02,
                ..params()
            },
            None,
        )
        .unwrap();
        // 0.2 mm behind: 50 · 0.2 · 0.001 / 200 = 5e-5 a cycle, on top of the P part's 0.02.
        let out = c.step(&at(10.2, 10.0));
        assert!((out.i_part - 5e-5).abs() < 1e-18, "{out:?}");
        assert!(
            (out.lag_ctrl_output - (0.02 + 5e-5)).abs() < 1e-15,
            "{out:?}"
        );
        // Within the window it holds.
        let out = c.step(&at(10.05, 10.0));
        assert!((out.i_part - 5e-5).abs() < 1e-18, "{out:?}");
        // Without position control it holds and gives nothing.
        let out = c.step(&HydControlInput {
            position_control: false,
            ..at(10.2, 10.0)
        });
        assert_eq!(out.lag_ctrl_output, 0.0);
        assert!((out.i_part - 5e-5).abs() < 1e-18, "{out:?}");
        // Limited to fLagAmpWuL.
        for _ in 0..10_000 {
            c.step(&at(10.2, 10.0));
        }
        assert_eq!(c.step(&at(10.2, 10.0)).i_part, 0.02);
        // Cleared without the drive's enable.
        c.reset();
        assert_eq!(c.step(&at(10.05, 10.0)).i_part, 0.0);
    }

    #[test]
    fn without_ti_there_is_no_i_part_and_the_zero_compensation_is_written() {
        let mut c = HydController::new(params(), None).unwrap();
        for _ in 0..1000 {
            assert_eq!(c.step(&at(10.2, 10.0)).i_part, 0.0);
        }
        // 0.5 V written: 0.05 of full scale at standstill on the set position.
        let out = c.step(&HydControlInput {
            zero_compensation: Some(0.5),
            ..at(10.0, 10.0)
        });
        assert!((out.output - 0.05).abs() < 1e-15, "{out:?}");
        // It stays when the axis no longer sends it.
        assert!((c.step(&at(10.0, 10.0)).output - 0.05).abs() < 1e-15);
    }
}
