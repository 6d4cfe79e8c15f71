//! Actual-value coupling: the leader's actual position filtered, extrapolated and passed through
//! a hysteresis before followers use it (S7-1500T Motion Control V4.0 function manual,
//! 3.5.3.4 'Extrapolation of the leading values for actual value coupling'; S7-1500T Axis
//! functions V5.0 function manual, 4.2.4.8 'Configuration - Actual value extrapolation
//! (S7-1500T)').
//!
//! Pipeline, once per cycle of the leader:
//! 1. position filter: PT2 (`T1`, `T2`, two first-order stages) of the actual position;
//! 2. velocity filter: PT2 (`T1`, `T2`) of the actual velocity, then a tolerance band: the output
//!    only moves when the filtered velocity leaves the band of width `Range` around it, and then
//!    follows it at half the band's distance;
//! 3. extrapolation: `filtered position + velocity * T`, with `T` = the leading-axis-dependent time
//!    (acquisition time + cycle + position filter `T1 + T2`, when "system defined" is on) plus the
//!    following-axis-dependent time (the follower's setpoint execution time, set by the user);
//! 4. hysteresis on the extrapolated position: a reversal counts only once the value has moved
//!    back by at least the hysteresis;
//! 5. velocity of the leading value: the filtered velocity, or the derivative of the
//!    extrapolated position; acceleration: the derivative of that velocity.
//!
//! In steady motion at constant velocity the filters' lag is compensated exactly: the
//! extrapolated position is the actual position plus velocity times (acquisition time + cycle +
//! following-axis time). No allocation; time is the cycle.

use crate::kinematics::profile::State;

/// The state `dt` seconds after `s` (`dt` may be negative) at the constant acceleration of
/// `s`: `p + v·dt + a·dt²/2`, `v + a·dt`, `a`. Exact for motion of constant velocity or
/// constant acceleration. The same extrapolation the leading values use after their newest
/// sample; output cams and cam tracks that drive a signal predict the position they switch on
/// with it (see [`crate::objects::output_cam::SwitchingAhead`]).
#[inline]
pub fn constant_acceleration(s: State, dt: f64) -> State {
    State {
        p: s.p + dt * (s.v + 0.5 * dt * s.a),
        v: s.v + dt * s.a,
        a: s.a,
    }
}

/// Which velocity the leading value carries (`Extrapolation.Settings.ExtrapolatedVelocityMode`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum VelocityMode {
    /// 0: the filtered velocity (after the tolerance band).
    Filtered,
    /// 1: the derivative of the extrapolated position.
    Differentiation,
}

/// `<TO>.Extrapolation.*` of a leading axis or external encoder.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ExtrapolationConfig {
    /// `PositionFilter.T1` (s, >= 0).
    pub position_t1: f64,
    /// `PositionFilter.T2` (s, >= 0).
    pub position_t2: f64,
    /// `VelocityFilter.T1` (s, >= 0).
    pub velocity_t1: f64,
    /// `VelocityFilter.T2` (s, >= 0).
    pub velocity_t2: f64,
    /// `VelocityTolerance.Range` (>= 0): width of the tolerance band.
    pub velocity_tolerance: f64,
    /// `Hysteresis.Value` (>= 0), position units.
    pub hysteresis: f64,
    /// `FollowingAxisDependentTime` (s, >= 0).
    pub following_time: f64,
    /// Actual value acquisition time `Ti` (s, >= 0).
    pub acquisition_time: f64,
    /// `Settings.SystemDefinedExtrapolation`: count the leading-axis-dependent time.
    pub system_defined: bool,
    /// `Settings.ExtrapolatedVelocityMode`.
    pub velocity_mode: VelocityMode,
}

impl Default for ExtrapolationConfig {
    fn default() -> Self {
        Self {
            position_t1: 0.0,
            position_t2: 0.0,
            velocity_t1: 0.0,
            velocity_t2: 0.0,
            velocity_tolerance: 0.0,
            hysteresis: 0.0,
            following_time: 0.0,
            acquisition_time: 0.0,
            system_defined: true,
            velocity_mode: VelocityMode::Filtered,
        }
    }
}

/// `StatusExtrapolation` plus the leading value it yields.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct Extrapolated {
    /// `FilteredPosition`.
    pub filtered_position: f64,
    /// `FilteredVelocity` (after the tolerance band).
    pub filtered_velocity: f64,
    /// `ExtrapolatedPosition` (after the hysteresis): the leading position.
    pub position: f64,
    /// `ExtrapolatedVelocity`: the leading velocity.
    pub velocity: f64,
    /// Leading acceleration (derivative of the leading velocity).
    pub acceleration: f64,
}

/// A first-order lag, discretized by backward Euler (`k = dt / (T + dt)`), so that its lag behind
/// a ramp is exactly `T`: the extrapolation compensates it exactly.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
struct Pt1 {
    k: f64,
    y: f64,
}

impl Pt1 {
    fn new(t: f64, dt: f64, y: f64) -> Self {
        let k = if t > 0.0 { dt / (t + dt) } else { 1.0 };
        Self { k, y }
    }

    #[inline]
    fn step(&mut self, u: f64) -> f64 {
        self.y += (u - self.y) * self.k;
        self.y
    }
}

/// The extrapolation pipeline of one leader.
#[derive(Clone, Debug, PartialEq)]
pub struct Extrapolator {
    cfg: ExtrapolationConfig,
    dt: f64,
    p1: Pt1,
    p2: Pt1,
    v1: Pt1,
    v2: Pt1,
    v_band: f64,
    out: f64,
    dir: f64,
    v_out: f64,
    primed: bool,
    last: Extrapolated,
}

impl Extrapolator {
    /// A pipeline for a leader with cycle `dt` (s), primed by the first sample.
    pub fn new(cfg: ExtrapolationConfig, dt: f64) -> Self {
        Self {
            p1: Pt1::new(cfg.position_t1, dt, 0.0),
            p2: Pt1::new(cfg.position_t2, dt, 0.0),
            v1: Pt1::new(cfg.velocity_t1, dt, 0.0),
            v2: Pt1::new(cfg.velocity_t2, dt, 0.0),
            v_band: 0.0,
            out: 0.0,
            dir: 0.0,
            v_out: 0.0,
            primed: false,
            last: Extrapolated::default(),
            cfg,
            dt,
        }
    }

    /// The configuration.
    pub fn config(&self) -> &ExtrapolationConfig {
        &self.cfg
    }

    /// The effective extrapolation time (s).
    pub fn extrapolation_time(&self) -> f64 {
        let leading = if self.cfg.system_defined {
            self.cfg.acquisition_time + self.dt + self.cfg.position_t1 + self.cfg.position_t2
        } else {
            0.0
        };
        leading + self.cfg.following_time
    }

    /// Starts again from a state at rest at `p` moving with `v` (e.g. after homing, which is a
    /// jump of the actual value).
    pub fn reset(&mut self, p: f64, v: f64) {
        for f in [&mut self.p1, &mut self.p2] {
            f.y = p;
        }
        for f in [&mut self.v1, &mut self.v2] {
            f.y = v;
        }
        self.v_band = v;
        self.out = p + v * self.extrapolation_time();
        self.dir = 0.0;
        self.v_out = v;
        self.primed = true;
    }

    /// The last result.
    pub fn last(&self) -> Extrapolated {
        self.last
    }

    /// One cycle with the actual position and velocity.
    pub fn step(&mut self, p_act: f64, v_act: f64) -> Extrapolated {
        if !self.primed {
            self.reset(p_act, v_act);
        }
        let pf = self.p2.step(self.p1.step(p_act));
        let vf = self.v2.step(self.v1.step(v_act));
        let half = 0.5 * self.cfg.velocity_tolerance;
        if vf > self.v_band + half {
            self.v_band = vf - half;
        } else if vf < self.v_band - half {
            self.v_band = vf + half;
        }
        let pe = pf + self.v_band * self.extrapolation_time();
        let d = pe - self.out;
        let prev_out = self.out;
        if d == 0.0 || d * self.dir >= 0.0 {
            self.out = pe;
            if d != 0.0 {
                self.dir = d.signum();
            }
        } else if self.dir == 0.0 || d.abs() >= self.cfg.hysteresis {
            self.out = pe;
            self.dir = d.signum();
        }
        let v = match self.cfg.velocity_mode {
            VelocityMode::Filtered => self.v_band,
            VelocityMode::Differentiation => (self.out - prev_out) / self.dt,
        };
        let a = (v - self.v_out) / self.dt;
        self.v_out = v;
        self.last = Extrapolated {
            filtered_position: pf,
            filtered_velocity: self.v_band,
            position: self.out,
            velocity: v,
            acceleration: a,
        };
        self.last
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_acceleration_is_exact_on_a_parabola() {
        let at = |t: f64| State {
            p: 3.0 + 2.0 * t + 0.5 * -7.0 * t * t,
            v: 2.0 - 7.0 * t,
            a: -7.0,
        };
        for (t, dt) in [(0.0, 0.004), (0.3, -0.002), (1.0, 0.0)] {
            let e = constant_acceleration(at(t), dt);
            let x = at(t + dt);
            assert!((e.p - x.p).abs() < 1e-12 && (e.v - x.v).abs() < 1e-12 && e.a == x.a);
        }
    }

    #[test]
    fn filter_lag_is_compensated_at_constant_velocity() {
        let cfg = ExtrapolationConfig {
            position_t1: 0.004,
            position_t2: 0.002,
            velocity_t1: 0.01,
            following_time: 0.003,
            acquisition_time: 0.001,
            ..ExtrapolationConfig::default()
        };
        let dt = 0.001;
        let mut e = Extrapolator::new(cfg, dt);
        let v = 250.0;
        let mut out = Extrapolated::default();
        let mut p = 0.0;
        for _ in 0..5000 {
            p += v * dt;
            out = e.step(p, v);
        }
        // Extrapolated = actual + v * (Ti + cycle + following time): the filters' lag T1 + T2
        // is compensated exactly.
        let expect = p + v * (0.001 + 0.001 + 0.003);
        assert!(
            (out.position - expect).abs() < 1e-9,
            "{} vs {expect}",
            out.position
        );
        assert!((out.velocity - v).abs() < 1e-9);
        assert!(out.acceleration.abs() < 1e-6);
        assert!((e.extrapolation_time() - (0.001 + 0.001 + 0.006 + 0.003)).abs() < 1e-15);
    }

    #[test]
    fn tolerance_band_and_hysteresis_suppress_noise() {
        let cfg = ExtrapolationConfig {
            velocity_tolerance: 2.0,
            hysteresis: 0.5,
            system_defined: false,
            ..ExtrapolationConfig::default()
        };
        let mut e = Extrapolator::new(cfg, 0.001);
        e.step(10.0, 0.0);
        // Velocity noise of +-0.8 stays inside the band of width 2: the output velocity stays 0.
        for k in 0..100 {
            let noise = if k % 2 == 0 { 0.8 } else { -0.8 };
            let o = e.step(10.0 + 0.2 * noise, noise);
            assert_eq!(o.velocity, 0.0);
            // Position jitter of 0.16 after the first rise is held by the hysteresis of 0.5.
            assert!(o.position >= 10.0 && o.position <= 10.0 + 0.16 + 1e-12);
        }
        // A velocity step to 5 leaves the band: the output follows at half the band (4).
        let o = e.step(10.0, 5.0);
        assert_eq!(o.filtered_velocity, 4.0);
        // A real reversal of more than the hysteresis is passed on.
        let o = e.step(9.0, 0.0);
        assert_eq!(o.position, 9.0);
    }
}
