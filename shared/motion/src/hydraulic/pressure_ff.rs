//! The pressure or force controller with feed-forward of a hydraulic axis,
//! `MC_AxCtrlPressureFF_BkPlcMc` (Beckhoff TwinCAT PLC Hydraulic Positioning library, 4.4.1.3),
//! with its parameters `ST_TcPctrlParam` (4.3.36).
//!
//! The library: "a complete PID core, the individual components of which can be switched on and
//! off via Boolean inputs regardless of their parameters", "a pre-control input ... which makes it
//! easier to adapt the control against a moving object to the velocity of the object"
//! (`FeedVelocity`), and `FeedCharge`, "an instantaneously effective and permanent change in the
//! integral component". Its outputs are `Deviation`, `Proportional`, `Integrator`,
//! `Differential`, `Response` and `InWindup`. Like `MC_AxCtrlPressure_BkPlcMc`
//! ([`super::pressure`]), the response is the control value `fSetSpeed` (normalised, ±1.0 =
//! `fRefVelo`) that replaces the generator's and cancels the position controller's output.
//!
//! The arithmetic, with `e = Setpoint - Actual` (the library names the parts, not their
//! formulas; inferred as the textbook PID in the library's own parametrisation, the one its
//! `MC_AxCtrlPressure_BkPlcMc` uses for P and I):
//! - `Proportional = kP · e` with `Enable_P`, else 0;
//! - `Integrator`: `kP / fTn · ∫ e dt` with `Enable_P` and `Enable_I` ("activates the integrator
//!   if the proportional component is active") and `fTn > 0` ("if it is set to 0.0, the I part is
//!   switched off"); it starts at `fPreset` when the controller is activated ("this value
//!   initializes the I component when it is activated") and is limited to ±`fWuLimit`
//!   (`InWindup` while it is). Switched off by `Enable_I` it neither integrates nor counts, and
//!   keeps its memory until `Reset` (inferred);
//! - `FeedCharge`: each change of the input is added to the integrator in the cycle it is seen
//!   (instantaneous, and permanent because the integrator keeps it; a constant value adds
//!   nothing more; inferred), before the windup limit;
//! - `Differential = kP · fTv · de/dt` with `Enable_P` and `Enable_D` and `fTv > 0`, `de/dt` the
//!   difference of two cycles' deviations over the cycle time (0 in the first cycle), averaged
//!   over the last `nNf` cycles when `nNf` > 1 (the library: "a moving average filter that
//!   averages up to 100 values");
//! - `Response = Proportional + Integrator + Differential + FeedVelocity`.
//!
//! `Reset` (TRUE by default in the library) clears the I part's memory and keeps the controller
//! inactive, as for `MC_AxCtrlPressure_BkPlcMc`. Not built: `bAlignAreas` (the library does not
//! say by which ratio the response is adjusted; a `true` is refused rather than guessed).
//!
//! Pure: no IO, no clock (the cycle time is an input), no allocation (the filter is a fixed
//! array of 100).

use super::pressure::{ActualForce, PressureError, PressureOutput, PressureReading};

/// The most values the D part's moving average takes (`nNf`).
pub const MAX_FILTER: usize = 100;

/// `ST_TcPctrlParam` with the reading mode.
#[doc(alias = "ST_TcPctrlParam")]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PctrlParams {
    /// `kP` (>= 0): output (normalised) per bar or per newton.
    pub kp: f64,
    /// `fTn` (s, >= 0): the integral action time; 0: no I part.
    pub tn: f64,
    /// `fTv` (s, >= 0): the derivative action time; 0: no D part.
    pub tv: f64,
    /// `fPreset`: the I part when the controller is activated.
    pub preset: f64,
    /// `fWuLimit` (> 0): the limit of the I part.
    pub windup_limit: f64,
    /// `nNf` (0 to 100): the D part's moving average over that many cycles (0 and 1: none).
    pub nf: u16,
    /// `bAlignAreas` (only `false` is built).
    pub align_areas: bool,
    /// `ReadingMode` of the actual value: the differential pressure or the force.
    pub reading: PressureReading,
}

impl PctrlParams {
    /// Refuses a parameter out of its range, naming it (`dwTcHydAdsErrIllegalValue`).
    pub fn check(&self) -> Result<(), PressureError> {
        for (name, value, zero_ok) in [
            ("kP", self.kp, true),
            ("fTn", self.tn, true),
            ("fTv", self.tv, true),
            ("fWuLimit", self.windup_limit, false),
        ] {
            if !(value.is_finite() && (value > 0.0 || zero_ok && value == 0.0)) {
                return Err(PressureError { name, value });
            }
        }
        if !self.preset.is_finite() {
            return Err(PressureError {
                name: "fPreset",
                value: self.preset,
            });
        }
        if usize::from(self.nf) > MAX_FILTER {
            return Err(PressureError {
                name: "nNf",
                value: f64::from(self.nf),
            });
        }
        if self.align_areas {
            return Err(PressureError {
                name: "bAlignAreas",
                value: 1.0,
            });
        }
        Ok(())
    }
}

/// The inputs of `MC_AxCtrlPressureFF_BkPlcMc` read each cycle besides `Enable` and `Reset`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PidInputs {
    /// `Enable_P`.
    pub enable_p: bool,
    /// `Enable_I` (acts with `Enable_P`).
    pub enable_i: bool,
    /// `Enable_D` (acts with `Enable_P`).
    pub enable_d: bool,
    /// `Setpoint`: bar, or N reading the force.
    pub setpoint: f64,
    /// `FeedVelocity` (normalised): added to the response.
    pub feed_velocity: f64,
    /// `FeedCharge` (normalised): its changes are added to the I part.
    pub feed_charge: f64,
}

impl PidInputs {
    /// The library's defaults (every part enabled, the values 0).
    pub const DEFAULT: Self = Self {
        enable_p: true,
        enable_i: true,
        enable_d: true,
        setpoint: 0.0,
        feed_velocity: 0.0,
        feed_charge: 0.0,
    };
}

/// The outputs of one cycle.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct PidOutput {
    /// The controller is active (enabled, not reset): its response replaces the generator's.
    pub active: bool,
    /// `Deviation`: `Setpoint - Actual`.
    pub deviation: f64,
    /// `Proportional`.
    pub proportional: f64,
    /// `Integrator`.
    pub integrator: f64,
    /// `Differential` (after the moving average).
    pub differential: f64,
    /// `Response` (normalised): the control value `fSetSpeed`.
    pub response: f64,
    /// `InWindup`: the I part is at ±`fWuLimit`.
    pub in_windup: bool,
}

impl PidOutput {
    /// What the axis takes from it, in the form of `MC_AxCtrlPressure_BkPlcMc`'s output.
    pub fn control(&self) -> PressureOutput {
        PressureOutput {
            active: self.active,
            set_speed: self.response,
            in_windup: self.in_windup,
        }
    }
}

/// The D part's moving average over the last `n` values.
#[derive(Copy, Clone, Debug, PartialEq)]
struct MovingAverage {
    values: [f64; MAX_FILTER],
    n: usize,
    len: usize,
    next: usize,
    sum: f64,
}

impl MovingAverage {
    const fn new(n: usize) -> Self {
        Self {
            values: [0.0; MAX_FILTER],
            n,
            len: 0,
            next: 0,
            sum: 0.0,
        }
    }

    /// Takes `x`; the mean of the values taken, at most the last `n` (`n` <= 1, or above
    /// [`MAX_FILTER`], which the parameters' check refuses: `x`).
    fn push(&mut self, x: f64) -> f64 {
        let Some(slot) = self.values.get_mut(self.next).filter(|_| self.n > 1) else {
            return x;
        };
        if self.len == self.n {
            self.sum -= *slot;
        } else {
            self.len += 1;
        }
        *slot = x;
        self.sum += x;
        self.next = (self.next + 1) % self.n;
        // Summed afresh once per pass through the buffer, so that the running sum does not
        // collect rounding (n additions every n cycles).
        if self.next == 0 {
            self.sum = self.values.iter().take(self.len).sum();
        }
        self.sum / self.len as f64
    }

    fn clear(&mut self) {
        *self = Self::new(self.n);
    }
}

/// `MC_AxCtrlPressureFF_BkPlcMc` of one axis.
#[doc(alias = "MC_AxCtrlPressureFF_BkPlcMc")]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PressureFfController {
    p: PctrlParams,
    active: bool,
    i: f64,
    /// The deviation of the last cycle (`None` in the first cycle after activation).
    last_e: Option<f64>,
    /// `FeedCharge` of the last cycle.
    last_charge: f64,
    d_filter: MovingAverage,
}

impl PressureFfController {
    /// The controller, inactive. Refuses a parameter out of its range.
    pub fn new(p: PctrlParams) -> Result<Self, PressureError> {
        p.check()?;
        Ok(Self {
            p,
            active: false,
            i: 0.0,
            last_e: None,
            last_charge: 0.0,
            d_filter: MovingAverage::new(usize::from(p.nf)),
        })
    }

    /// The parameters.
    pub fn params(&self) -> &PctrlParams {
        &self.p
    }

    /// The controller with new parameters `p` (checked), its state kept (the I part, the last
    /// deviation; the D filter restarts if `nNf` changed): a change while it runs.
    pub fn retuned(self, p: PctrlParams) -> Result<Self, PressureError> {
        p.check()?;
        let d_filter = if p.nf == self.p.nf {
            self.d_filter
        } else {
            MovingAverage::new(usize::from(p.nf))
        };
        Ok(Self {
            p,
            d_filter,
            ..self
        })
    }

    /// One cycle of `dt` seconds with `Enable`, `Reset`, the inputs `u` and the actual values.
    /// A non-finite set, actual or feed value, or a `dt` not above 0, changes no part (the
    /// response is the parts of the last cycle's state).
    pub fn step(
        &mut self,
        enable: bool,
        reset: bool,
        u: &PidInputs,
        actual: &ActualForce,
        dt: f64,
    ) -> PidOutput {
        if reset || !enable {
            self.active = false;
            self.i = 0.0;
            self.last_e = None;
            self.last_charge = 0.0;
            self.d_filter.clear();
            return PidOutput::default();
        }
        if !self.active {
            self.active = true;
            self.i = self.p.preset;
        }
        let e = u.setpoint - actual.value(self.p.reading);
        let valid = e.is_finite()
            && u.feed_velocity.is_finite()
            && u.feed_charge.is_finite()
            && dt.is_finite()
            && dt > 0.0;
        let (e, dt) = if valid { (e, dt) } else { (0.0, 0.0) };
        let p_on = u.enable_p;
        if valid {
            self.i += u.feed_charge - self.last_charge;
            self.last_charge = u.feed_charge;
        }
        if p_on && u.enable_i && self.p.tn > 0.0 {
            self.i += self.p.kp / self.p.tn * e * dt;
        }
        let l = self.p.windup_limit;
        let in_windup = self.i.abs() >= l;
        self.i = self.i.clamp(-l, l);
        let rate = match self.last_e {
            Some(last) if dt > 0.0 => (e - last) / dt,
            _ => 0.0,
        };
        if valid {
            self.last_e = Some(e);
        }
        let d_raw = if p_on && u.enable_d && self.p.tv > 0.0 {
            self.p.kp * self.p.tv * rate
        } else {
            0.0
        };
        let differential = if valid {
            self.d_filter.push(d_raw)
        } else {
            0.0
        };
        let proportional = if p_on { self.p.kp * e } else { 0.0 };
        let integrator = if p_on && u.enable_i { self.i } else { 0.0 };
        let feed = if valid { u.feed_velocity } else { 0.0 };
        PidOutput {
            active: true,
            deviation: e,
            proportional,
            integrator,
            differential,
            response: proportional + integrator + differential + feed,
            in_windup,
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    const DT: f64 = 1e-3;

    fn params() -> PctrlParams {
        PctrlParams {
            kp: 0.2,
            tn: 0.5,
            tv: 0.01,
            preset: 0.0,
            windup_limit: 1.0,
            nf: 0,
            align_areas: false,
            reading: PressureReading::Pressure,
        }
    }

    fn at(pressure: f64) -> ActualForce {
        ActualForce {
            pressure,
            ..ActualForce::default()
        }
    }

    fn inputs(setpoint: f64) -> PidInputs {
        PidInputs {
            setpoint,
            ..PidInputs::DEFAULT
        }
    }

    #[test]
    fn the_parts_have_their_numbers() {
        let mut c = PressureFfController::new(params()).unwrap();
        // First cycle: e = 10 bar; P = 0.2 · 10 = 2; I = 0.2 / 0.5 · 10 · 0.001 = 0.004;
        // D = 0 (no earlier deviation).
        let o = c.step(true, false, &inputs(100.0), &at(90.0), DT);
        assert!(o.active);
        assert_eq!(o.deviation, 10.0);
        assert!((o.proportional - 2.0).abs() < 1e-12);
        assert!((o.integrator - 0.004).abs() < 1e-12);
        assert_eq!(o.differential, 0.0);
        // Second cycle: e = 8 bar; I = 0.004 + 0.4 · 8 · 0.001 = 0.0072;
        // D = 0.2 · 0.01 · (8 - 10) / 0.001 = -4.
        let o = c.step(true, false, &inputs(100.0), &at(92.0), DT);
        assert!((o.proportional - 1.6).abs() < 1e-12);
        assert!((o.integrator - 0.0072).abs() < 1e-12);
        assert!((o.differential + 4.0).abs() < 1e-9);
        assert!((o.response - (1.6 + 0.0072 - 4.0)).abs() < 1e-9);
    }

    #[test]
    fn each_part_switches_off_with_its_input_and_i_and_d_need_p() {
        let mut c = PressureFfController::new(params()).unwrap();
        let only_p = PidInputs {
            enable_i: false,
            enable_d: false,
            ..inputs(100.0)
        };
        c.step(true, false, &only_p, &at(90.0), DT);
        let o = c.step(true, false, &only_p, &at(92.0), DT);
        assert_eq!((o.integrator, o.differential), (0.0, 0.0));
        assert!((o.response - 1.6).abs() < 1e-12);
        let no_p = PidInputs {
            enable_p: false,
            ..inputs(100.0)
        };
        let o = c.step(true, false, &no_p, &at(95.0), DT);
        assert_eq!(o.response, 0.0, "I and D act only with P: {o:?}");
    }

    #[test]
    fn preset_feed_charge_and_feed_velocity() {
        let p = PctrlParams {
            preset: 0.3,
            tn: 0.0,
            tv: 0.0,
            ..params()
        };
        let mut c = PressureFfController::new(p).unwrap();
        let o = c.step(true, false, &inputs(50.0), &at(50.0), DT);
        assert_eq!(o.integrator, 0.3, "fPreset on activation");
        // FeedCharge 0.1: added once, at once, and kept.
        let charged = PidInputs {
            feed_charge: 0.1,
            feed_velocity: 0.25,
            ..inputs(50.0)
        };
        let o = c.step(true, false, &charged, &at(50.0), DT);
        assert!((o.integrator - 0.4).abs() < 1e-15);
        assert!((o.response - 0.65).abs() < 1e-15);
        let o = c.step(true, false, &charged, &at(50.0), DT);
        assert!(
            (o.integrator - 0.4).abs() < 1e-15,
            "a constant FeedCharge adds nothing"
        );
        // Reset clears the I part; the next activation starts at fPreset again.
        assert_eq!(
            c.step(true, true, &charged, &at(50.0), DT),
            PidOutput::default()
        );
        let o = c.step(true, false, &inputs(50.0), &at(50.0), DT);
        assert_eq!(o.integrator, 0.3);
    }

    #[test]
    fn the_windup_limit_holds_the_i_part() {
        let p = PctrlParams {
            windup_limit: 0.05,
            tv: 0.0,
            ..params()
        };
        let mut c = PressureFfController::new(p).unwrap();
        let mut o = PidOutput::default();
        for _ in 0..1000 {
            o = c.step(true, false, &inputs(100.0), &at(0.0), DT);
        }
        assert_eq!(o.integrator, 0.05);
        assert!(o.in_windup);
    }

    #[test]
    fn the_d_part_is_averaged_over_nnf_cycles() {
        let p = PctrlParams {
            tn: 0.0,
            nf: 4,
            ..params()
        };
        let mut c = PressureFfController::new(p).unwrap();
        // A step of the actual value by 1 bar: the raw D is -0.2 · 0.01 · 1 / 0.001 = -2 in one
        // cycle; averaged over 4 it is -2/2 (two values so far), then -2/3, -2/4 for 2 more
        // cycles, then 0 once it has left the window.
        c.step(true, false, &inputs(10.0), &at(0.0), DT);
        let d: Vec<f64> = [1.0, 1.0, 1.0, 1.0, 1.0]
            .iter()
            .map(|&x| c.step(true, false, &inputs(10.0), &at(x), DT).differential)
            .collect();
        let want = [-1.0, -2.0 / 3.0, -0.5, -0.5, 0.0];
        for (got, want) in d.iter().zip(want) {
            assert!((got - want).abs() < 1e-12, "{d:?}");
        }
    }

    #[test]
    fn bad_parameters_are_refused_by_name() {
        for (bad, name) in [
            (
                PctrlParams {
                    kp: -1.0,
                    ..params()
                },
                "kP",
            ),
            (
                PctrlParams {
                    tn: f64::NAN,
                    ..params()
                },
                "fTn",
            ),
            (
                PctrlParams {
                    tv: -0.1,
                    ..params()
                },
                "fTv",
            ),
            (
                PctrlParams {
                    windup_limit: 0.0,
                    ..params()
                },
                "fWuLimit",
            ),
            (
                PctrlParams {
                    preset: f64::INFINITY,
                    ..params()
                },
                "fPreset",
            ),
            (
                PctrlParams {
                    nf: 101,
                    ..params()
                },
                "nNf",
            ),
            (
                PctrlParams {
                    align_areas: true,
                    ..params()
                },
                "bAlignAreas",
            ),
        ] {
            assert_eq!(PressureFfController::new(bad).unwrap_err().name, name);
        }
        let c = PressureFfController::new(params()).unwrap();
        assert!(c
            .retuned(PctrlParams {
                nf: 200,
                ..params()
            })
            .is_err());
    }

    #[test]
    fn a_non_finite_input_changes_no_part() {
        let mut c = PressureFfController::new(params()).unwrap();
        let o1 = c.step(true, false, &inputs(100.0), &at(90.0), DT);
        let before = c;
        let o = c.step(true, false, &inputs(f64::NAN), &at(90.0), DT);
        assert_eq!(c, before);
        assert_eq!(o.integrator, o1.integrator);
        assert_eq!(o.proportional, 0.0);
    }
}
