//! The dynamic branches of the extended position controller of a hydraulic axis (Beckhoff
//! TwinCAT PLC Hydraulic Positioning library, `MC_AxRtPosPiControllerEx_BkPlcMc`, 4.4.1.7, from
//! V3.0.40): the D part realised as a velocity P controller with a damping time, and the
//! condition (state) feedback of the filtered actual velocity and actual acceleration, with the
//! compensation of the velocity feedback's static effect on the feed forward. Its P part and
//! its I part with threshold and windup limit are the default controller's
//! ([`super::controller`]), which adds this module's response to them.
//!
//! The library describes the structure in prose and a figure that is not in the text; the
//! following is decided from the prose (inferred where marked):
//! - D part: `fLagAmpTd · (fSetVelo − fActVelo)` ("the differentiated set position is provided
//!   by the setpoint generator; an actual velocity is determined by differentiating the actual
//!   position; Td acts as a proportionality factor"), through a first-order lag of time
//!   `fLagAmpTdd` (the "attenuation time"; inferred: a PT1). `fLagAmpTd` = 0 disables it.
//! - Velocity feedback: `− fLagAmpCfb_kV · PT1(fActVelo, fLagAmpCfb_tV)` ("filtered and
//!   activated with a weighting factor; as it is subtracted, it has an attenuating effect").
//! - Acceleration feedback: `− fLagAmpCfb_kA · PT1(d fActVelo / dt, fLagAmpCfb_tA)`; the
//!   library gives `kA` the unit 1, tandem reads it in s so that the term is a velocity like
//!   the others (inferred).
//! - The compensation of the static effect: "a velocity activation generates a statically
//!   effective reduction of the velocity pre-control ... eliminated by automatic adjustment of
//!   the pre-control". Decided: `+ fLagAmpCfb_kV · PT1(fSetVelo, fLagAmpCfb_tV)`, the same
//!   filter on the set velocity, so that at a constant velocity followed without error the
//!   feedback and its compensation cancel exactly; `kV` = 0 disables both.
//! - The force feedback (`fLagAmpCfb_kF`, `fLagAmpCfb_tF`) is listed among the parameters but
//!   not among the controller's components; it is not built.
//!
//! The four first-order lags form one discrete linear system, exact for inputs held over a
//! cycle (zero-order hold: `x⁺ = A·x + B·u`, `aᵢ = e^(−dt/Tᵢ)`, `bᵢ = 1 − aᵢ`; a time of 0 passes
//! its input through), with the response `y = C·x` (velocity units, mm/s). Its matrices are
//! computed when the cycle time changes, not per cycle. Reset (or a missing enable) clears
//! the states, as the library's `Reset` input and missing controller enable clear "all
//! internal and external controller responses".

use nalgebra::{Matrix4, RowVector4, Vector4};

/// The parameters of the extended controller's dynamic branches (members of
/// `ST_TcHydAxParam` only `MC_AxRtPosPiControllerEx_BkPlcMc` uses).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
#[doc(alias = "MC_AxRtPosPiControllerEx_BkPlcMc")]
pub struct PosPiControllerExParams {
    /// `fLagAmpTd` (1, >= 0): the D part's gain on `fSetVelo − fActVelo`; 0: no D part.
    pub td: f64,
    /// `fLagAmpTdd` (s, >= 0): the D part's damping time (a first-order lag); 0: none.
    pub tdd: f64,
    /// `fLagAmpCfb_kV` (1, >= 0): the weight of the actual velocity feedback; 0: none.
    pub cfb_kv: f64,
    /// `fLagAmpCfb_tV` (s, >= 0): the filter time of the actual velocity feedback.
    pub cfb_tv: f64,
    /// `fLagAmpCfb_kA` (s, >= 0; the library: 1): the weight of the actual acceleration
    /// feedback; 0: none.
    pub cfb_ka: f64,
    /// `fLagAmpCfb_tA` (s, >= 0): the filter time of the actual acceleration feedback.
    pub cfb_ta: f64,
}

impl PosPiControllerExParams {
    /// The first parameter out of its range (finite, >= 0), with its library name.
    pub fn check(&self) -> Result<(), (&'static str, f64)> {
        [
            ("fLagAmpTd", self.td),
            ("fLagAmpTdd", self.tdd),
            ("fLagAmpCfb_kV", self.cfb_kv),
            ("fLagAmpCfb_tV", self.cfb_tv),
            ("fLagAmpCfb_kA", self.cfb_ka),
            ("fLagAmpCfb_tA", self.cfb_ta),
        ]
        .into_iter()
        .find(|(_, v)| !(v.is_finite() && *v >= 0.0))
        .map_or(Ok(()), Err)
    }
}

/// The states of the four lags, in this order.
const V_ACT: usize = 0;
const V_SET: usize = 1;
const ACC: usize = 2;
const D: usize = 3;

/// One cycle's inputs of the dynamic branches.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct ExInput {
    /// `fSetVelo` (mm/s).
    pub set_velocity: f64,
    /// `fActVelo` (mm/s): the differentiated actual position.
    pub actual_velocity: f64,
    /// The cycle (s, > 0).
    pub dt: f64,
}

/// The dynamic branches of `MC_AxRtPosPiControllerEx_BkPlcMc` as a discrete linear system.
#[derive(Clone, Debug, PartialEq)]
pub struct PosPiControllerEx {
    params: PosPiControllerExParams,
    /// The cycle `a` and `b` are for (s); 0 before the first step.
    dt: f64,
    /// `x⁺ = A·x + B·u` (diagonal: the lags are independent).
    a: Matrix4<f64>,
    b: Matrix4<f64>,
    /// `y = C·x`.
    c: RowVector4<f64>,
    x: Vector4<f64>,
    /// `fActVelo` of the previous cycle, for the actual acceleration; `None` after a reset.
    previous_velocity: Option<f64>,
}

impl PosPiControllerEx {
    /// The branches with `params`; refuses a parameter out of range naming it.
    pub fn new(params: PosPiControllerExParams) -> Result<Self, (&'static str, f64)> {
        params.check()?;
        Ok(Self {
            params,
            dt: 0.0,
            a: Matrix4::zeros(),
            b: Matrix4::identity(),
            c: RowVector4::new(-params.cfb_kv, params.cfb_kv, -params.cfb_ka, 1.0),
            x: Vector4::zeros(),
            previous_velocity: None,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &PosPiControllerExParams {
        &self.params
    }

    /// Clears the states (the library's `Reset`, or no controller enable).
    pub fn reset(&mut self) {
        self.x = Vector4::zeros();
        self.previous_velocity = None;
    }

    /// The discretisation for cycle `dt`: `aᵢ = e^(−dt/Tᵢ)`, `bᵢ = 1 − aᵢ` (0 and 1 for a time
    /// of 0).
    fn discretise(&mut self, dt: f64) {
        let p = &self.params;
        let lag = |t: f64| if t > 0.0 { (-dt / t).exp() } else { 0.0 };
        let a = Vector4::new(lag(p.cfb_tv), lag(p.cfb_tv), lag(p.cfb_ta), lag(p.tdd));
        self.a = Matrix4::from_diagonal(&a);
        self.b = Matrix4::from_diagonal(&a.map(|ai| 1.0 - ai));
        self.dt = dt;
    }

    /// The static gain of the system, `C · (I − A)⁻¹ · B`, per input (the response to each
    /// input held constant); `None` before the first step or where a lag does not settle.
    pub fn static_gain(&self) -> Option<RowVector4<f64>> {
        let settle = (Matrix4::identity() - self.a).try_inverse()?;
        (self.dt > 0.0).then(|| self.c * settle * self.b)
    }

    /// One cycle: the response (mm/s) of the D part and the condition feedback. Non-finite
    /// inputs give 0 and change nothing.
    pub fn step(&mut self, i: &ExInput) -> f64 {
        let usable = i.set_velocity.is_finite()
            && i.actual_velocity.is_finite()
            && i.dt.is_finite()
            && i.dt > 0.0;
        if !usable {
            return 0.0;
        }
        if i.dt != self.dt {
            self.discretise(i.dt);
        }
        let acceleration = self
            .previous_velocity
            .map_or(0.0, |v0| (i.actual_velocity - v0) / i.dt);
        self.previous_velocity = Some(i.actual_velocity);
        let mut u = Vector4::zeros();
        u[V_ACT] = i.actual_velocity;
        u[V_SET] = i.set_velocity;
        u[ACC] = acceleration;
        u[D] = self.params.td * (i.set_velocity - i.actual_velocity);
        self.x = self.a * self.x + self.b * u;
        (self.c * self.x)[0]
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;
    use proptest::prelude::*;

    const DT: f64 = 0.001;

    fn at(set_velocity: f64, actual_velocity: f64) -> ExInput {
        ExInput {
            set_velocity,
            actual_velocity,
            dt: DT,
        }
    }

    #[test]
    fn the_d_part_without_damping_is_td_times_the_velocity_error() {
        let mut c = PosPiControllerEx::new(PosPiControllerExParams {
            td: 0.4,
            ..PosPiControllerExParams::default()
        })
        .unwrap();
        // 0.4 · (100 − 90) = 4 mm/s at once.
        assert!((c.step(&at(100.0, 90.0)) - 4.0).abs() < 1e-12);
        assert!((c.step(&at(50.0, 60.0)) + 4.0).abs() < 1e-12);
    }

    #[test]
    fn the_damping_time_is_a_first_order_lag_exact_for_a_held_input() {
        let mut c = PosPiControllerEx::new(PosPiControllerExParams {
            td: 1.0,
            tdd: 0.01,
            ..PosPiControllerExParams::default()
        })
        .unwrap();
        // A held error of 10 mm/s: after n cycles 10 · (1 − e^(−n·dt/Tdd)); at n = 10 one time
        // constant, 6.3212 mm/s.
        let mut y = 0.0;
        for _ in 0..10 {
            y = c.step(&at(10.0, 0.0));
        }
        let expected = 10.0 * (1.0 - (-1.0_f64).exp());
        assert!((y - expected).abs() < 1e-12, "{y} {expected}");
        c.reset();
        assert!((c.step(&at(10.0, 0.0)) - 10.0 * (1.0 - (-0.1_f64).exp())).abs() < 1e-12);
    }

    #[test]
    fn the_velocity_feedback_attenuates_and_its_compensation_cancels_it_when_followed() {
        let mut c = PosPiControllerEx::new(PosPiControllerExParams {
            cfb_kv: 0.5,
            cfb_tv: 0.005,
            ..PosPiControllerExParams::default()
        })
        .unwrap();
        // Followed exactly: feedback and compensation cancel in every cycle.
        for _ in 0..50 {
            assert!(c.step(&at(80.0, 80.0)).abs() < 1e-12);
        }
        // The axis 20 mm/s too fast: −0.5 · 20 = −10 mm/s once the filter has settled.
        let mut y = 0.0;
        for _ in 0..200 {
            y = c.step(&at(80.0, 100.0));
        }
        assert!((y + 10.0).abs() < 1e-9, "{y}");
    }

    #[test]
    fn the_acceleration_feedback_is_the_filtered_differentiated_actual_velocity() {
        let mut c = PosPiControllerEx::new(PosPiControllerExParams {
            cfb_ka: 0.02,
            ..PosPiControllerExParams::default()
        })
        .unwrap();
        // The first cycle has no previous velocity: no acceleration.
        assert_eq!(c.step(&at(0.0, 0.0)), 0.0);
        // 0.5 mm/s more per 1 ms: 500 mm/s², times 0.02 s: −10 mm/s.
        assert!((c.step(&at(0.0, 0.5)) + 10.0).abs() < 1e-9);
        assert!((c.step(&at(0.0, 1.0)) + 10.0).abs() < 1e-9);
    }

    #[test]
    fn the_static_gain_is_the_sum_of_the_branches_weights() {
        let p = PosPiControllerExParams {
            td: 0.3,
            tdd: 0.002,
            cfb_kv: 0.7,
            cfb_tv: 0.004,
            cfb_ka: 0.01,
            cfb_ta: 0.003,
        };
        let mut c = PosPiControllerEx::new(p).unwrap();
        assert_eq!(c.static_gain(), None);
        c.step(&at(0.0, 0.0));
        let g = c.static_gain().unwrap();
        // Per state input: actual velocity −kV, set velocity +kV, acceleration −kA, D 1.
        for (k, expected) in [-0.7, 0.7, -0.01, 1.0].into_iter().enumerate() {
            assert!((g[k] - expected).abs() < 1e-12, "{g}");
        }
    }

    #[test]
    fn bad_parameters_are_refused_naming_them_and_bad_inputs_change_nothing() {
        let bad = PosPiControllerEx::new(PosPiControllerExParams {
            cfb_tv: -1.0,
            ..PosPiControllerExParams::default()
        });
        assert_eq!(bad, Err(("fLagAmpCfb_tV", -1.0)));
        let bad = PosPiControllerEx::new(PosPiControllerExParams {
            td: f64::NAN,
            ..PosPiControllerExParams::default()
        });
        assert!(matches!(bad, Err(("fLagAmpTd", v)) if v.is_nan()));
        let mut c = PosPiControllerEx::new(PosPiControllerExParams {
            td: 1.0,
            tdd: 0.01,
            ..PosPiControllerExParams::default()
        })
        .unwrap();
        c.step(&at(10.0, 0.0));
        let before = c.clone();
        assert_eq!(c.step(&at(f64::NAN, 0.0)), 0.0);
        assert_eq!(
            c.step(&ExInput {
                dt: 0.0,
                ..at(1.0, 0.0)
            }),
            0.0
        );
        assert_eq!(c, before);
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, rng_seed: proptest::test_runner::RngSeed::Fixed(15), ..ProptestConfig::default() })]
        /// Held inputs: the response converges to the static gain times the inputs (the D part
        /// and the velocity feedback's net `kV · (fSetVelo − fActVelo)`).
        #[test]
        fn held_inputs_settle_to_the_static_response(
            td in 0.0..2.0_f64, tdd in 0.0..0.02_f64, kv in 0.0..1.0_f64, tv in 0.0..0.02_f64,
            vs in -300.0..300.0_f64, va in -300.0..300.0_f64,
        ) {
            let mut c = PosPiControllerEx::new(PosPiControllerExParams {
                td, tdd, cfb_kv: kv, cfb_tv: tv, ..PosPiControllerExParams::default()
            }).unwrap();
            c.step(&at(vs, va));
            let expected = td * (vs - va) + kv * (vs - va);
            let mut y = 0.0;
            for _ in 0..1000 {
                y = c.step(&at(vs, va));
            }
            prop_assert!((y - expected).abs() <= 1e-9 * expected.abs().max(1.0), "{} {}", y, expected);
        }
    }
}
