//! Pressure and force of a hydraulic axis (Beckhoff TwinCAT PLC Hydraulic Positioning library):
//! the acquisition of the chambers' pressures and the force on the load
//! (`MC_AxRtReadForceDiff_BkPlcMc`, 4.4.3.2) and the pressure or force controller
//! (`MC_AxCtrlPressure_BkPlcMc`, 4.4.1.2).
//!
//! **Acquisition**: each chamber's pressure from its analog input word, `p = ScaleFactor ·
//! AdcValue + ScaleOffset` (bar; the library's commissioning option B gives the two numbers from
//! two measured points); the force on the load `F = p_A · A_A - p_B · A_B` (N, with the areas in
//! mm² and 1 bar = 0.1 N/mm²), the differential pressure `p_A - p_B · A_B / A_A` (bar, the
//! pressure on A that makes the same force; inferred: the library names the quantity, not its
//! formula). Not built: the `SlippingOffset` for sliding friction.
//!
//! **Controller**: a PI controller on the actual pressure or force (`ReadingMode`) to its set
//! value `fSetPressure`: P part `kP · e`, I part `kP / Tn · ∫ e dt` (`Tn` = 0: none), preloaded
//! with `PreSet` on the rising edge of `Enable` and limited to ±`WindupLimit` (> 0; `InWindup`
//! while it is); `Reset` clears both parts and keeps the controller inactive. Its output, the sum
//! of the parts, is the control value `fSetSpeed` (normalised, ±1.0 = `fRefVelo`) that replaces
//! the generator's and cancels the position controller's output (the library: "it cancels
//! fLagCtrlOutput"); Finish forms the valve output from it. The gain is in output per bar or per
//! newton (inferred: the library gives "between 0.1 and 0.5" for kP with pressures in bar).
//!
//! Pure: no IO, no clock (the cycle time is an input), no allocation.

use crate::catalog::hyd_error::HydErrorCode;

/// Which actual value the controller controls (`E_TcMcPressureReadingMode`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum PressureReading {
    /// `iTcHydPressureReadingActPressure` (and the default): the differential pressure (bar).
    Pressure,
    /// `iTcHydPressureReadingActForce`: the force on the load (N).
    Force,
}

/// The scaling of the two pressure inputs and the areas (`MC_AxRtReadForceDiff_BkPlcMc`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ForceScaling {
    /// `ScaleFactorA` (bar per ADC increment).
    pub factor_a: f64,
    /// `ScaleOffsetA` (bar).
    pub offset_a: f64,
    /// `ScaleFactorB` (bar per ADC increment).
    pub factor_b: f64,
    /// `ScaleOffsetB` (bar).
    pub offset_b: f64,
    /// `ScaleArreaA` (mm², > 0): the piston area.
    pub area_a: f64,
    /// `ScaleArreaB` (mm², > 0): the annulus area.
    pub area_b: f64,
}

/// A value out of its range (nothing of it is kept).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PressureError {
    /// The library's name of the parameter.
    pub name: &'static str,
    /// Its value.
    pub value: f64,
}

impl PressureError {
    /// The library's error code: `dwTcHydAdsErrIllegalValue`.
    pub fn code(&self) -> HydErrorCode {
        HydErrorCode::ILLEGAL_VALUE
    }
}

impl core::fmt::Display for PressureError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{} = {} is out of its range", self.name, self.value)
    }
}

impl std::error::Error for PressureError {}

/// The actual pressures and the force of one cycle (`fActPressureA`, `fActPressureB`,
/// `fActPressure`, `fActForce`).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct ActualForce {
    /// `fActPressureA` (bar).
    pub pressure_a: f64,
    /// `fActPressureB` (bar).
    pub pressure_b: f64,
    /// `fActPressure` (bar): the differential pressure referred to area A.
    pub pressure: f64,
    /// `fActForce` (N).
    pub force: f64,
}

impl ActualForce {
    /// The value a controller with `reading` controls.
    pub fn value(&self, reading: PressureReading) -> f64 {
        match reading {
            PressureReading::Pressure => self.pressure,
            PressureReading::Force => self.force,
        }
    }
}

impl ForceScaling {
    /// Checks the scaling: finite numbers, areas above 0.
    pub fn check(&self) -> Result<(), PressureError> {
        for (name, value) in [
            ("ScaleFactorA", self.factor_a),
            ("ScaleOffsetA", self.offset_a),
            ("ScaleFactorB", self.factor_b),
            ("ScaleOffsetB", self.offset_b),
        ] {
            if !value.is_finite() {
                return Err(PressureError { name, value });
            }
        }
        for (name, value) in [("ScaleArreaA", self.area_a), ("ScaleArreaB", self.area_b)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(PressureError { name, value });
            }
        }
        Ok(())
    }

    /// The actual values from the two input words.
    pub fn read(&self, adc_a: i16, adc_b: i16) -> ActualForce {
        let pressure_a = self.factor_a * f64::from(adc_a) + self.offset_a;
        let pressure_b = self.factor_b * f64::from(adc_b) + self.offset_b;
        ActualForce {
            pressure_a,
            pressure_b,
            pressure: pressure_a - pressure_b * self.area_b / self.area_a,
            force: 0.1 * (pressure_a * self.area_a - pressure_b * self.area_b),
        }
    }
}

/// The parameters of `MC_AxCtrlPressure_BkPlcMc`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PressureParams {
    /// `kP` (>= 0): output per bar or per newton.
    pub kp: f64,
    /// `Tn` (s, >= 0): the integral action time; 0: no I part.
    pub tn: f64,
    /// `PreSet`: the I part on the rising edge of `Enable`.
    pub preset: f64,
    /// `WindupLimit` (> 0): the limit of the I part.
    pub windup_limit: f64,
    /// `ReadingMode`.
    pub reading: PressureReading,
}

/// One cycle's output of the controller.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct PressureOutput {
    /// The controller is active (enabled, not reset): its output replaces the generator's.
    pub active: bool,
    /// `fSetSpeed` (normalised): the control value.
    pub set_speed: f64,
    /// `InWindup`: the I part is at its limit.
    pub in_windup: bool,
}

/// The pressure or force controller of one axis.
#[doc(alias = "MC_AxCtrlPressure_BkPlcMc")]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PressureController {
    p: PressureParams,
    enabled: bool,
    i: f64,
}

impl PressureController {
    /// The controller, inactive. Refuses a parameter out of its range.
    pub fn new(p: PressureParams) -> Result<Self, PressureError> {
        for (name, value, zero_ok) in [
            ("kP", p.kp, true),
            ("Tn", p.tn, true),
            ("WindupLimit", p.windup_limit, false),
        ] {
            if !(value.is_finite() && (value > 0.0 || zero_ok && value == 0.0)) {
                return Err(PressureError { name, value });
            }
        }
        if !p.preset.is_finite() {
            return Err(PressureError {
                name: "PreSet",
                value: p.preset,
            });
        }
        Ok(Self {
            p,
            enabled: false,
            i: 0.0,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &PressureParams {
        &self.p
    }

    /// The controller with new parameters `p` (checked by [`PressureController::new`]), its
    /// state (active, I part) kept: a change while it runs (no new `PreSet`).
    pub fn retuned(self, p: PressureParams) -> Self {
        Self { p, ..self }
    }

    /// One cycle of `dt` seconds: `Enable`, `Reset`, the set value `fSetPressure` and the
    /// actual values. A non-finite set or actual value holds the output at its I part.
    pub fn step(
        &mut self,
        enable: bool,
        reset: bool,
        set: f64,
        actual: &ActualForce,
        dt: f64,
    ) -> PressureOutput {
        if reset || !enable {
            self.enabled = false;
            self.i = 0.0;
            return PressureOutput::default();
        }
        if !self.enabled {
            self.enabled = true;
            self.i = self.p.preset;
        }
        let e = set - actual.value(self.p.reading);
        let (e, dt) = if e.is_finite() && dt.is_finite() && dt > 0.0 {
            (e, dt)
        } else {
            (0.0, 0.0)
        };
        if self.p.tn > 0.0 {
            self.i += self.p.kp / self.p.tn * e * dt;
        }
        let l = self.p.windup_limit;
        let in_windup = self.i.abs() >= l;
        self.i = self.i.clamp(-l, l);
        PressureOutput {
            active: true,
            set_speed: self.p.kp * e + self.i,
            in_windup,
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    fn scaling() -> ForceScaling {
        // 250 bar at word 27648 (10 V), no offset; a 63/45 mm cylinder.
        ForceScaling {
            factor_a: 250.0 / 27648.0,
            offset_a: 0.0,
            factor_b: 250.0 / 27648.0,
            offset_b: 0.0,
            area_a: 3117.0,
            area_b: 1527.0,
        }
    }

    #[test]
    fn the_force_is_the_pressures_times_the_areas() {
        let a = scaling().read(11059, 5530);
        // 100 bar on A and 50 bar on B (to the ADC's increment).
        assert!((a.pressure_a - 11059.0 * 250.0 / 27648.0).abs() < 1e-12);
        let f = 0.1 * (a.pressure_a * 3117.0 - a.pressure_b * 1527.0);
        assert!((a.force - f).abs() < 1e-9);
        assert!((a.force - (31170.0 - 7635.0)).abs() < 5.0, "{a:?}");
        // The differential pressure makes the same force on area A.
        assert!((a.pressure * 3117.0 * 0.1 - a.force).abs() < 1e-9);
    }

    #[test]
    fn the_controller_is_pi_with_preset_and_windup_limit() {
        let mut c = PressureController::new(PressureParams {
            kp: 0.01,
            tn: 0.5,
            preset: 0.05,
            windup_limit: 0.1,
            reading: PressureReading::Pressure,
        })
        .unwrap();
        let at = |p: f64| ActualForce {
            pressure: p,
            ..ActualForce::default()
        };
        // Inactive until enabled.
        assert_eq!(
            c.step(false, false, 50.0, &at(40.0), 1e-3),
            PressureOutput::default()
        );
        // Rising edge: I = PreSet, then kP/Tn · e · dt: 0.05 + 0.02 · 10 · 0.001.
        let o = c.step(true, false, 50.0, &at(40.0), 1e-3);
        assert!(o.active && !o.in_windup);
        assert!((o.set_speed - (0.1 + 0.05 + 0.0002)).abs() < 1e-15, "{o:?}");
        // The I part stops at the windup limit.
        for _ in 0..1000 {
            c.step(true, false, 50.0, &at(40.0), 1e-3);
        }
        let o = c.step(true, false, 50.0, &at(40.0), 1e-3);
        assert!(o.in_windup);
        assert!((o.set_speed - (0.1 + 0.1)).abs() < 1e-12);
        // Reset clears it; the next edge preloads again.
        assert_eq!(
            c.step(true, true, 50.0, &at(40.0), 1e-3),
            PressureOutput::default()
        );
        let o = c.step(true, false, 50.0, &at(50.0), 1e-3);
        assert_eq!(o.set_speed, 0.05);
    }

    #[test]
    fn bad_parameters_are_refused_with_the_library_code() {
        let p = PressureParams {
            kp: 0.1,
            tn: 0.0,
            preset: 0.0,
            windup_limit: 1.0,
            reading: PressureReading::Force,
        };
        for (bad, name) in [
            (PressureParams { kp: -1.0, ..p }, "kP"),
            (PressureParams { tn: f64::NAN, ..p }, "Tn"),
            (
                PressureParams {
                    windup_limit: 0.0,
                    ..p
                },
                "WindupLimit",
            ),
            (
                PressureParams {
                    preset: f64::INFINITY,
                    ..p
                },
                "PreSet",
            ),
        ] {
            let e = PressureController::new(bad).unwrap_err();
            assert_eq!((e.name, e.code()), (name, HydErrorCode::ILLEGAL_VALUE));
        }
        let e = ForceScaling {
            area_b: 0.0,
            ..scaling()
        }
        .check()
        .unwrap_err();
        assert_eq!(e.name, "ScaleArreaB");
    }
}
