//! The target window monitoring of a hydraulic axis (Beckhoff TwinCAT PLC Hydraulic Positioning
//! library, the status bits `dwTcHydNsDwInTargRng` and `dwTcHydNsDwInTarget` of `nStateDWord`,
//! the parameters `fMonPositionRange`, `fMonTargetRange`, `fMonTargetFilter`).
//!
//! - **InTargRng**: the actual position lies within `fMonPositionRange` of the target.
//! - **InTarget**: it has lain within `fMonTargetRange` of the target without interruption for
//!   `fMonTargetFilter` seconds.
//!
//! A positioning reports Done only when its generator is idle and both hold (the library's
//! MoveAbsolute / MoveRelative / Stop report Done once the axis is in target). A new target
//! restarts the filter time. Pure: no IO, no clock (the cycle time is an input), no allocation.

use crate::catalog::hyd_error::HydErrorCode;
/// The parameters of the monitoring (defaults as the library's: 1.0 mm, 1.0 mm, 1.0 s).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MonitorParams {
    /// `fMonPositionRange` (mm, > 0).
    pub position_range: f64,
    /// `fMonTargetRange` (mm, > 0).
    pub target_range: f64,
    /// `fMonTargetFilter` (s, >= 0).
    pub target_filter: f64,
}

impl Default for MonitorParams {
    fn default() -> Self {
        Self {
            position_range: 1.0,
            target_range: 1.0,
            target_filter: 1.0,
        }
    }
}

/// A monitoring parameter out of its range (named as the library names it).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MonitorError {
    /// The parameter.
    pub name: &'static str,
    /// Its value.
    pub value: f64,
}

impl MonitorError {
    /// The library's error code: `dwTcHydAdsErrIllegalValue`.
    pub fn code(&self) -> HydErrorCode {
        HydErrorCode::ILLEGAL_VALUE
    }
}

impl core::fmt::Display for MonitorError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{} = {} is out of its range", self.name, self.value)
    }
}

impl std::error::Error for MonitorError {}

/// The status bits of one cycle.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct TargetStatus {
    /// `dwTcHydNsDwInTargRng`.
    pub in_target_range: bool,
    /// `dwTcHydNsDwInTarget`.
    pub in_target: bool,
    /// The positioning is done: idle, InTargRng and InTarget.
    pub done: bool,
}

/// The target window monitoring of one axis.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TargetMonitor {
    p: MonitorParams,
    target: f64,
    /// Time within `fMonTargetRange` without interruption (s).
    within: f64,
}

impl TargetMonitor {
    /// The monitoring with parameters `p`.
    pub fn new(p: MonitorParams) -> Result<Self, MonitorError> {
        for (name, value, zero_ok) in [
            ("fMonPositionRange", p.position_range, false),
            ("fMonTargetRange", p.target_range, false),
            ("fMonTargetFilter", p.target_filter, true),
        ] {
            if !(value.is_finite() && (value > 0.0 || zero_ok && value == 0.0)) {
                return Err(MonitorError { name, value });
            }
        }
        Ok(Self {
            p,
            target: f64::NAN,
            within: 0.0,
        })
    }

    /// One cycle of `dt` seconds: the actual position, the target, and whether the generator
    /// is idle.
    pub fn step(&mut self, dt: f64, actual: f64, target: f64, idle: bool) -> TargetStatus {
        // A new target restarts the filter time (NaN != NaN: the first call too).
        #[allow(clippy::float_cmp)]
        if target != self.target {
            self.target = target;
            self.within = 0.0;
        }
        let d = (actual - target).abs();
        if d < self.p.target_range && dt.is_finite() && dt > 0.0 {
            self.within += dt;
        } else if d >= self.p.target_range || d.is_nan() {
            self.within = 0.0;
        }
        // The filter time is reached to within rounding of the summed cycles.
        let in_target = d < self.p.target_range && self.within >= self.p.target_filter - 1e-9;
        let in_target_range = d < self.p.position_range;
        TargetStatus {
            in_target_range,
            in_target,
            done: idle && in_target_range && in_target,
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    #[test]
    fn in_target_after_the_filter_time_without_interruption() {
        let mut m = TargetMonitor::new(MonitorParams {
            position_range: 1.0,
            target_range: 0.1,
            target_filter: 0.05,
        })
        .unwrap();
        // 0.5 mm off: in the target range, not in target.
        let s = m.step(1e-3, 99.5, 100.0, true);
        assert_eq!(
            (s.in_target_range, s.in_target, s.done),
            (true, false, false)
        );
        // Within 0.1 mm: in target after 50 cycles (0.05 s), not before.
        for k in 1..50 {
            assert!(!m.step(1e-3, 99.95, 100.0, true).in_target, "cycle {k}");
        }
        let s = m.step(1e-3, 99.95, 100.0, true);
        assert!(s.in_target && s.done);
        // Not done while the generator still moves.
        assert!(!m.step(1e-3, 99.95, 100.0, false).done);
        // Leaving the window restarts the time.
        assert!(!m.step(1e-3, 99.8, 100.0, true).in_target);
        assert!(!m.step(1e-3, 99.95, 100.0, true).in_target);
        // A new target restarts it too.
        for _ in 0..60 {
            m.step(1e-3, 99.95, 100.0, true);
        }
        assert!(!m.step(1e-3, 99.95, 99.96, true).in_target);
    }

    #[test]
    fn bad_parameters_are_refused() {
        let bad = |p| TargetMonitor::new(p).unwrap_err();
        let d = MonitorParams::default();
        assert_eq!(
            bad(MonitorParams {
                target_range: 0.0,
                ..d
            }),
            MonitorError {
                name: "fMonTargetRange",
                value: 0.0
            }
        );
        assert_eq!(
            bad(MonitorParams {
                target_filter: -1.0,
                ..d
            })
            .name,
            "fMonTargetFilter"
        );
        assert!(TargetMonitor::new(MonitorParams {
            target_filter: 0.0,
            ..d
        })
        .is_ok());
    }
}
