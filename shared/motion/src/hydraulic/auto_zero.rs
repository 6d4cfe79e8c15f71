//! The automatic zero compensation of a hydraulic axis, `MC_AxCtrlAutoZero_BkPlcMc` (Beckhoff
//! TwinCAT PLC Hydraulic Positioning library, 4.4.1.1): for a zero-overlap valve whose cylinder
//! drifts without position control, or stands with a permanent lag with it, it adjusts the
//! offset `fZeroCompensation` (V, added by Finish) at standstill until the lag is gone.
//!
//! Per cycle, in the library's call order (after the position controller, before Finish):
//! - **Enable logic.** Without `Enable` or the axis' controller enable nothing is adjusted, the
//!   comparison value for `Done` takes the present compensation and the time for `Done` is
//!   reset. Enabled and moving (not idle), the time is reset too, and the compensation is
//!   adjusted only with `EnableOnMoving` (inferred from the input's name: the library describes
//!   it no further).
//! - **Compensation and timing.** The correction is the position controller's P response to
//!   the lag, in volts: `10 V · fLagAmp · (fSetPos - fActPos) / fRefVelo` (inferred: the
//!   library forms it "from the lag error and the response of the controller"). Beyond the
//!   response window `fLagAmpDx` (the library's threshold, the I part's) and while the axis
//!   does not already move towards removing the lag (actual velocity of the other sign or 0),
//!   the compensation changes by `correction · dt / Tn`, limited to `10 V · dt / Tn` ("Tn
//!   defines a ramp time for an increase by 10 V"): `Active`. Within the window `Active` is
//!   FALSE. Whenever the compensation has moved more than `Threshold` from the comparison value,
//!   the comparison value takes it and the time restarts; otherwise the time grows.
//! - **Feedback.** The compensation is limited to ±`OffsetLimit` (also while not active):
//!   `Limiting`. `Done` when the time reaches `Filter`: the compensation has moved less than
//!   `Threshold` within the last `Filter` seconds at standstill (inferred: the library writes
//!   "when the function block is active", which the threshold would make never true once the
//!   lag is within the window; tandem takes "enabled at standstill").
//!
//! The library's warning stands: the compensation must be disabled while the axis does not
//! behave normally (pressing, the supply off), or it runs to its limit. tandem pauses it while
//! the pressure or force controller gives the control value (its lag means nothing then).
//!
//! Pure: no IO, no clock (the cycle time is an input), no allocation.

use std::fmt;

/// Full scale of the valve output (V).
const FULL_SCALE_V: f64 = 10.0;

/// The inputs of `MC_AxCtrlAutoZero_BkPlcMc` besides `Enable`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AutoZeroParams {
    /// `EnableOnMoving`: adjust also while the axis moves.
    pub enable_on_moving: bool,
    /// `OffsetLimit` (V, 0..=10): the limit of `fZeroCompensation`.
    pub offset_limit: f64,
    /// `Tn` (s, > 0): the time for a change by 10 V ("greater than 100 s are recommended").
    pub tn: f64,
    /// `Threshold` (V, >= 0): the change that restarts the time for `Done`.
    pub threshold: f64,
    /// `Filter` (s, >= 0): the time without such a change for `Done`.
    pub filter: f64,
}

impl AutoZeroParams {
    /// The library's defaults for `Threshold` (0.1 V) and `Filter` (0.1 s); `OffsetLimit` 1 V
    /// and `Tn` 100 s (the library's defaults, 0.0, are refused: they give no compensation and
    /// a division by zero). The instruction's defaults in a script are these.
    pub const DEFAULT: Self = Self {
        enable_on_moving: false,
        offset_limit: 1.0,
        tn: 100.0,
        threshold: 0.1,
        filter: 0.1,
    };
}

impl Default for AutoZeroParams {
    /// [`AutoZeroParams::DEFAULT`].
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// A parameter of [`AutoZeroParams`] out of its range (nothing of it is kept).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AutoZeroError {
    /// The library's name of the input.
    pub name: &'static str,
    /// Its value.
    pub value: f64,
}

impl fmt::Display for AutoZeroError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let range = match self.name {
            "OffsetLimit" => "0 to 10 V",
            "Tn" => "above 0 s",
            _ => "0 or above",
        };
        write!(
            f,
            "MC_AxCtrlAutoZero_BkPlcMc: {} = {}: must be {range}",
            self.name, self.value
        )
    }
}

impl std::error::Error for AutoZeroError {}

impl AutoZeroParams {
    /// Checks each input; the first out of its range is named.
    pub fn check(&self) -> Result<(), AutoZeroError> {
        let within = |name, value: f64, ok: bool| {
            if value.is_finite() && ok {
                Ok(())
            } else {
                Err(AutoZeroError { name, value })
            }
        };
        within(
            "OffsetLimit",
            self.offset_limit,
            (0.0..=FULL_SCALE_V).contains(&self.offset_limit),
        )?;
        within("Tn", self.tn, self.tn > 0.0)?;
        within("Threshold", self.threshold, self.threshold >= 0.0)?;
        within("Filter", self.filter, self.filter >= 0.0)
    }
}

/// One cycle's values into the compensation.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct AutoZeroInput {
    /// `Enable` and the axis' controller enable.
    pub enabled: bool,
    /// The axis stands (the library's idle state: no motion).
    pub idle: bool,
    /// `fSetPos - fActPos` (mm).
    pub lag: f64,
    /// `fLagAmp` (mm/s per mm).
    pub lag_amp: f64,
    /// `fRefVelo` (mm/s, > 0).
    pub ref_velo: f64,
    /// `fLagAmpDx` (mm): the response window.
    pub window: f64,
    /// `fActVelo` (mm/s).
    pub actual_velocity: f64,
    /// The cycle (s).
    pub dt: f64,
}

/// The outputs of `MC_AxCtrlAutoZero_BkPlcMc` and the compensation.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct AutoZeroStatus {
    /// `fZeroCompensation` (V).
    pub compensation: f64,
    /// `Active`: the compensation is being adjusted.
    pub active: bool,
    /// `Limiting`: the compensation is at ±`OffsetLimit`.
    pub limiting: bool,
    /// `Done`: the compensation has levelled out.
    pub done: bool,
}

/// The automatic zero compensation of one axis (see the module documentation).
#[doc(alias = "MC_AxCtrlAutoZero_BkPlcMc")]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AutoZero {
    p: AutoZeroParams,
    /// `OldValue`: the comparison value for `Done`.
    old_value: f64,
    /// The time since the compensation last moved by `Threshold` (s).
    timer: f64,
    status: AutoZeroStatus,
}

impl AutoZero {
    /// The compensation with `params` (checked), starting from `compensation` (V, the axis'
    /// `fZeroCompensation`).
    pub fn new(params: AutoZeroParams, compensation: f64) -> Result<Self, AutoZeroError> {
        params.check()?;
        if !compensation.is_finite() {
            return Err(AutoZeroError {
                name: "fZeroCompensation",
                value: compensation,
            });
        }
        Ok(Self {
            p: params,
            old_value: compensation,
            timer: 0.0,
            status: AutoZeroStatus {
                compensation,
                ..AutoZeroStatus::default()
            },
        })
    }

    /// New parameters (checked) for the running compensation, its value and timing kept.
    pub fn retune(&mut self, params: AutoZeroParams) -> Result<(), AutoZeroError> {
        params.check()?;
        self.p = params;
        Ok(())
    }

    /// Writes `fZeroCompensation` (V) from outside, as `MC_AxUtiOffsetLatch_BkPlcMc` does: the
    /// compensation goes on from it (`OldValue` too); a value that is not finite changes
    /// nothing.
    pub fn set_compensation(&mut self, compensation: f64) {
        if compensation.is_finite() {
            self.status.compensation = compensation;
            self.old_value = compensation;
        }
    }

    /// The outputs of the last cycle.
    pub fn status(&self) -> AutoZeroStatus {
        self.status
    }

    /// One cycle. Non-finite inputs change nothing.
    pub fn step(&mut self, i: &AutoZeroInput) -> AutoZeroStatus {
        let finite = [
            i.lag,
            i.lag_amp,
            i.ref_velo,
            i.window,
            i.actual_velocity,
            i.dt,
        ]
        .iter()
        .all(|x| x.is_finite());
        if !finite || i.ref_velo <= 0.0 || i.dt <= 0.0 {
            return self.status;
        }
        let mut c = self.status.compensation;
        let mut active = false;
        if !i.enabled {
            self.old_value = c;
            self.timer = 0.0;
        } else {
            if !i.idle {
                self.timer = 0.0;
            }
            if i.idle || self.p.enable_on_moving {
                let correction = FULL_SCALE_V * i.lag_amp * i.lag / i.ref_velo;
                let towards = (i.lag > 0.0 && i.actual_velocity > 0.0)
                    || (i.lag < 0.0 && i.actual_velocity < 0.0);
                if i.lag.abs() >= i.window && i.lag != 0.0 && !towards {
                    let max = FULL_SCALE_V * i.dt / self.p.tn;
                    c += (correction * i.dt / self.p.tn).clamp(-max, max);
                    active = true;
                }
            }
            if (c - self.old_value).abs() > self.p.threshold {
                self.old_value = c;
                self.timer = 0.0;
            } else if i.idle {
                self.timer += i.dt;
            }
        }
        let l = self.p.offset_limit;
        let limited = c.clamp(-l, l);
        self.status = AutoZeroStatus {
            compensation: limited,
            active,
            limiting: limited != c || limited.abs() >= l,
            done: i.enabled && i.idle && self.timer >= self.p.filter,
        };
        self.status
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    fn standing(lag: f64) -> AutoZeroInput {
        AutoZeroInput {
            enabled: true,
            idle: true,
            lag,
            lag_amp: 10.0,
            ref_velo: 100.0,
            window: 0.01,
            actual_velocity: 0.0,
            dt: 0.001,
        }
    }

    fn params() -> AutoZeroParams {
        AutoZeroParams {
            enable_on_moving: false,
            offset_limit: 0.5,
            tn: 10.0,
            threshold: 0.05,
            filter: 2.0,
        }
    }

    /// A value written from outside (MC_AxUtiOffsetLatch_BkPlcMc) is where the compensation
    /// goes on from; a value that is not finite changes nothing.
    #[test]
    fn a_written_compensation_is_kept_and_integrated_from() {
        let mut a = AutoZero::new(params(), 0.1).unwrap();
        a.set_compensation(-0.2);
        a.set_compensation(f64::NAN);
        assert_eq!(a.status().compensation, -0.2);
        // Inside the window nothing moves.
        let s = a.step(&standing(0.005));
        assert_eq!(s.compensation, -0.2);
    }

    #[test]
    fn the_compensation_integrates_the_p_response_over_tn() {
        let mut a = AutoZero::new(params(), 0.1).unwrap();
        // 0.5 mm behind at 10 mm/s per mm of 100 mm/s: 0.5 V; 1 ms of 10 s: 50 µV a cycle.
        let s = a.step(&standing(0.5));
        assert!(
            (s.compensation - (0.1 + 0.5 * 0.001 / 10.0)).abs() < 1e-15,
            "{s:?}"
        );
        assert!(s.active && !s.limiting && !s.done);
        // Ahead of the set position: down.
        let s = a.step(&standing(-0.5));
        assert!((s.compensation - 0.1).abs() < 1e-15, "{s:?}");
    }

    #[test]
    fn a_large_correction_is_limited_to_ten_volts_per_tn() {
        let mut a = AutoZero::new(params(), 0.0).unwrap();
        let s = a.step(&standing(1000.0));
        assert!(
            (s.compensation - 10.0 * 0.001 / 10.0).abs() < 1e-15,
            "{s:?}"
        );
    }

    #[test]
    fn within_the_window_or_moving_towards_the_set_position_nothing_changes() {
        let mut a = AutoZero::new(params(), 0.2).unwrap();
        let s = a.step(&standing(0.005));
        assert_eq!((s.compensation, s.active), (0.2, false));
        let s = a.step(&AutoZeroInput {
            actual_velocity: 0.3,
            ..standing(0.5)
        });
        assert_eq!((s.compensation, s.active), (0.2, false));
        // Moving away from it: it adjusts.
        let s = a.step(&AutoZeroInput {
            actual_velocity: -0.3,
            ..standing(0.5)
        });
        assert!(s.active && s.compensation > 0.2);
    }

    #[test]
    fn moving_without_enable_on_moving_or_disabled_it_holds() {
        let mut a = AutoZero::new(params(), 0.2).unwrap();
        let moving = AutoZeroInput {
            idle: false,
            ..standing(0.5)
        };
        assert_eq!(a.step(&moving).compensation, 0.2);
        let off = AutoZeroInput {
            enabled: false,
            ..standing(0.5)
        };
        let s = a.step(&off);
        assert_eq!((s.compensation, s.active, s.done), (0.2, false, false));
        a.retune(AutoZeroParams {
            enable_on_moving: true,
            ..params()
        })
        .unwrap();
        assert!(a.step(&moving).compensation > 0.2);
    }

    #[test]
    fn the_limit_holds_the_compensation_and_is_reported() {
        let mut a = AutoZero::new(params(), 0.0).unwrap();
        let mut s = a.status();
        for _ in 0..100_000 {
            s = a.step(&standing(1000.0));
        }
        assert_eq!(s.compensation, 0.5);
        assert!(s.limiting, "{s:?}");
        // A start value beyond the limit is limited at the first cycle.
        let mut a = AutoZero::new(params(), -3.0).unwrap();
        let s = a.step(&standing(0.0));
        assert_eq!((s.compensation, s.limiting), (-0.5, true));
    }

    #[test]
    fn done_after_the_filter_time_without_a_change_by_the_threshold() {
        let mut a = AutoZero::new(params(), 0.0).unwrap();
        // 2 s standing within the window: Done at the 2,000th cycle.
        let mut first = None;
        for k in 1..=2_500 {
            if a.step(&standing(0.0)).done && first.is_none() {
                first = Some(k);
            }
        }
        assert!(matches!(first, Some(1999..=2001)), "{first:?}");
        // A move resets the time.
        let s = a.step(&AutoZeroInput {
            idle: false,
            ..standing(0.0)
        });
        assert!(!s.done);
        assert!(!a.step(&standing(0.0)).done);
    }

    #[test]
    fn bad_parameters_are_refused_by_name() {
        for (bad, name) in [
            (
                AutoZeroParams {
                    offset_limit: 11.0,
                    ..params()
                },
                "OffsetLimit",
            ),
            (
                AutoZeroParams {
                    tn: 0.0,
                    ..params()
                },
                "Tn",
            ),
            (
                AutoZeroParams {
                    threshold: -1.0,
                    ..params()
                },
                "Threshold",
            ),
            (
                AutoZeroParams {
                    filter: f64::NAN,
                    ..params()
                },
                "Filter",
            ),
        ] {
            let e = AutoZero::new(bad, 0.0).unwrap_err();
            assert_eq!(e.name, name);
            assert!(e.to_string().contains(name), "{e}");
            let mut a = AutoZero::new(params(), 0.3).unwrap();
            assert_eq!(a.retune(bad).unwrap_err().name, name);
            assert_eq!(a, AutoZero::new(params(), 0.3).unwrap());
        }
    }
}
