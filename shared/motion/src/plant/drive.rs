//! Simulated drive and plant, so that actual values and the following error are real.
//!
//! Two models, both from the references (S7-1500T Motion Control V4.0 function manual, 3.2.11
//! 'Closed-loop control' and 3.2.5.3 'Actual values'):
//! - [`DriveModel::Delay`]: the S7 simulation model of a simulated or virtual axis, where the
//!   actual value is the setpoint delayed by `T_t` (interpolated between cycle samples).
//! - [`DriveModel::PositionLoop`]: a position controller (gain `Kv`, velocity precontrol `Kpc`)
//!   over a first-order velocity loop (`T_vtc`) with one servo cycle of transport delay; the
//!   following error is formed against the balanced setpoint (the setpoint passed through the
//!   same dead time and first-order model, the "dynamic axis model" of 3.2.11 'Closed-loop
//!   control').
//!
//! The plant has a physical position (the drive's own coordinate); the axis adds its homing
//! offset. Reference cam, zero marks and hardware limit switches live in physical coordinates.
//! When the enable is removed the drive brakes on its own ramp (`stop_deceleration`).

/// Drive model parameters.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum DriveModel {
    /// Actual = setpoint delayed by `delay` seconds (>= 0).
    Delay {
        /// `T_t` (s).
        delay: f64,
    },
    /// P position loop with velocity precontrol over a PT1 velocity loop.
    PositionLoop {
        /// `PositionControl.Kv` (1/s), > 0.
        kv: f64,
        /// `PositionControl.Kpc` as a fraction (1.0 = 100 %).
        kpc: f64,
        /// `DynamicAxisModel.VelocityTimeConstant` (s), >= 0.
        t_vtc: f64,
    },
}

/// Simulated plant: sensors in physical coordinates.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct Plant {
    /// Reference cam (homing switch) active between these physical positions.
    pub reference_cam: Option<(f64, f64)>,
    /// Zero marks every `period` at `offset + k * period` (one per encoder revolution).
    pub zero_mark: Option<ZeroMark>,
    /// Negative hardware limit switch: active at or below this physical position.
    pub hw_limit_min: Option<f64>,
    /// Positive hardware limit switch: active at or above this physical position.
    pub hw_limit_max: Option<f64>,
    /// A mechanical (fixed) stop the load cannot pass below this physical position (only the
    /// simulated CiA 402 servo has one: the axis's own drive model has no torque).
    pub fixed_stop_min: Option<f64>,
    /// A mechanical stop the load cannot pass above this physical position (as
    /// `fixed_stop_min`).
    pub fixed_stop_max: Option<f64>,
}

impl Plant {
    /// Whether the reference cam is active at physical position `x`.
    pub fn on_reference_cam(&self, x: f64) -> bool {
        self.reference_cam
            .is_some_and(|(lo, hi)| x >= lo && x <= hi)
    }

    /// Whether the negative hardware limit switch is active at `x`.
    pub fn at_negative_limit(&self, x: f64) -> bool {
        self.hw_limit_min.is_some_and(|m| x <= m)
    }

    /// Whether the positive hardware limit switch is active at `x`.
    pub fn at_positive_limit(&self, x: f64) -> bool {
        self.hw_limit_max.is_some_and(|m| x >= m)
    }
}

/// Encoder zero marks.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ZeroMark {
    /// Distance between marks (> 0).
    pub period: f64,
    /// Position of one mark.
    pub offset: f64,
}

impl ZeroMark {
    /// The first mark strictly after `from` and at or before `to` in the direction of travel.
    pub fn crossed(&self, from: f64, to: f64) -> Option<f64> {
        if to > from {
            let k = ((from - self.offset) / self.period).floor() + 1.0;
            let m = self.offset + k * self.period;
            (m <= to).then_some(m)
        } else if to < from {
            let k = ((from - self.offset) / self.period).ceil() - 1.0;
            let m = self.offset + k * self.period;
            (m >= to).then_some(m)
        } else {
            None
        }
    }
}

/// Actual values of the drive at the start of a cycle.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct Actual {
    /// Physical position.
    pub p: f64,
    /// Velocity.
    pub v: f64,
    /// Balanced setpoint (physical), the reference of the following error.
    pub balanced: f64,
}

/// Setpoints of the history kept in the drive itself: the position-loop model and a delay
/// model without delay need two; other delays keep theirs on the heap. (Inline, the history
/// of most axes shares the cache lines of the drive's state instead of needing a line of its
/// own every cycle, and the ring of two is indexed `head ^ back`, without a division.)
const INLINE_HISTORY: usize = 2;

/// The simulated drive of one axis.
#[derive(Clone, Debug)]
pub struct SimDrive {
    model: DriveModel,
    cycle: f64,
    stop_deceleration: f64,
    /// Setpoint history (p, v) for the delay model and the balancing dead time, a ring of `n`
    /// entries with the newest at `head`: in `inline` for up to [`INLINE_HISTORY`] entries,
    /// else in `heap`.
    inline: [(f64, f64); INLINE_HISTORY],
    heap: Vec<(f64, f64)>,
    n: usize,
    head: usize,
    p: f64,
    v: f64,
    /// Velocity command applied during the current cycle (one cycle of transport delay).
    v_cmd: f64,
    balanced: f64,
    prev_p: f64,
    /// `exp(-dt / T_vtc)` of the position-loop model.
    decay: f64,
}

impl SimDrive {
    /// `Kv` and `Kpc` (fraction) of the position-loop model, from the next step; the velocity
    /// loop (`T_vtc`) and the state are kept, so the position does not jump.
    pub fn set_gains(&mut self, kv: f64, kpc: f64) {
        if let DriveModel::PositionLoop { t_vtc, .. } = self.model {
            self.model = DriveModel::PositionLoop { kv, kpc, t_vtc };
        }
    }

    /// A drive at rest at physical position `p0`. `cycle` is the servo cycle (s, > 0).
    pub fn new(model: DriveModel, cycle: f64, stop_deceleration: f64, p0: f64) -> Self {
        let n = match model {
            DriveModel::Delay { delay } => (delay / cycle).ceil() as usize + 2,
            DriveModel::PositionLoop { .. } => 2,
        }
        .max(2);
        Self {
            model,
            cycle,
            stop_deceleration,
            inline: [(p0, 0.0); INLINE_HISTORY],
            heap: if n > INLINE_HISTORY {
                vec![(p0, 0.0); n]
            } else {
                Vec::new()
            },
            n,
            head: 0,
            p: p0,
            v: 0.0,
            v_cmd: 0.0,
            balanced: p0,
            prev_p: p0,
            decay: match model {
                DriveModel::PositionLoop { t_vtc, .. } if t_vtc > 0.0 => (-cycle / t_vtc).exp(),
                _ => 0.0,
            },
        }
    }

    /// The setpoint history to write, `n` entries.
    fn history_mut(&mut self) -> &mut [(f64, f64)] {
        if self.n > INLINE_HISTORY {
            &mut self.heap
        } else {
            &mut self.inline
        }
    }

    /// Actual values now.
    pub fn actual(&self) -> Actual {
        Actual {
            p: self.p,
            v: self.v,
            balanced: self.balanced,
        }
    }

    /// Physical position one cycle ago (for crossing detection).
    pub fn previous_position(&self) -> f64 {
        self.prev_p
    }

    /// The setpoint `back` cycles before the newest (the ring index without a division).
    fn hist_at(&self, back: usize) -> (f64, f64) {
        if self.n <= INLINE_HISTORY {
            // Two entries: the other one is the older.
            return self.inline[(self.head ^ back) & 1];
        }
        let n = self.n;
        let back = if back < n { back } else { back % n };
        let i = if self.head >= back {
            self.head - back
        } else {
            self.head + n - back
        };
        self.heap.get(i).copied().unwrap_or_default()
    }

    /// Makes `sp` the newest setpoint of the history.
    fn push(&mut self, sp: (f64, f64)) {
        if self.n <= INLINE_HISTORY {
            self.head ^= 1;
            self.inline[self.head & 1] = sp;
            return;
        }
        self.head = if self.head + 1 >= self.n {
            0
        } else {
            self.head + 1
        };
        if let Some(h) = self.heap.get_mut(self.head) {
            *h = sp;
        }
    }

    /// Applies the setpoint `(p, v)` (physical) for one cycle and integrates the plant to the
    /// start of the next cycle. With `enabled == false` the drive brakes on its own ramp and
    /// the setpoint is ignored. Without position control (`position_controlled == false`) only
    /// the velocity setpoint acts (no position loop).
    pub fn step(&mut self, sp_p: f64, sp_v: f64, enabled: bool, position_controlled: bool) {
        let dt = self.cycle;
        self.prev_p = self.p;
        self.push((sp_p, sp_v));
        if !enabled {
            let dv = self.stop_deceleration * dt;
            let v1 = if self.v.abs() <= dv {
                0.0
            } else {
                self.v - dv.copysign(self.v)
            };
            self.p += 0.5 * (self.v + v1) * dt;
            self.v = v1;
            self.v_cmd = v1;
            self.balanced = self.p;
            let p = self.p;
            self.history_mut().fill((p, 0.0));
            return;
        }
        match self.model {
            DriveModel::Delay { delay } => {
                // The plant now represents the start of the next cycle, t_k + dt; the newest
                // sample is the setpoint of t_k. Actual = setpoint at t_k + dt - delay.
                let lag = delay - dt;
                if lag <= 0.0 {
                    let (p0, v0) = self.hist_at(0);
                    self.p = p0 + v0 * (-lag);
                    self.v = v0;
                } else {
                    let back = lag / dt;
                    let k = back.floor() as usize;
                    let frac = back - k as f64;
                    let (p0, v0) = self.hist_at(k);
                    let (p1, v1) = self.hist_at(k + 1);
                    self.p = p0 + (p1 - p0) * frac;
                    self.v = v0 + (v1 - v0) * frac;
                }
                self.balanced = self.p;
            }
            DriveModel::PositionLoop { kv, kpc, t_vtc } => {
                // Balanced setpoint: dead time of one cycle, then the velocity-loop model.
                let (bp_in, _) = self.hist_at(1);
                let e = self.decay;
                // Velocity command computed from this cycle's values, effective after the
                // transport delay (it was computed last cycle: v_cmd).
                let v_cmd = self.v_cmd;
                let v0 = self.v;
                let v1 = v_cmd + (v0 - v_cmd) * e;
                self.p += v_cmd * dt + (v0 - v_cmd) * t_vtc * (1.0 - e);
                self.v = v1;
                self.balanced = bp_in + (self.balanced - bp_in) * e;
                self.v_cmd = if position_controlled {
                    kpc * sp_v + kv * (self.balanced - self.p)
                } else {
                    sp_v
                };
            }
        }
    }

    /// Resets the plant to rest at `p` (for tests and restarts).
    pub fn reset(&mut self, p: f64) {
        self.history_mut().fill((p, 0.0));
        self.p = p;
        self.prev_p = p;
        self.v = 0.0;
        self.v_cmd = 0.0;
        self.balanced = p;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_marks_crossing() {
        let z = ZeroMark {
            period: 10.0,
            offset: 3.0,
        };
        assert_eq!(z.crossed(0.0, 5.0), Some(3.0));
        assert_eq!(z.crossed(3.0, 12.9), None);
        assert_eq!(z.crossed(3.0, 13.0), Some(13.0));
        assert_eq!(z.crossed(14.0, 2.0), Some(13.0));
        assert_eq!(z.crossed(13.0, 3.5), None);
    }

    #[test]
    fn delay_model_lags_by_delay() {
        let dt = 0.001;
        let mut d = SimDrive::new(DriveModel::Delay { delay: 0.0035 }, dt, 10.0, 0.0);
        // Ramp setpoint p = 100 t.
        for k in 0..100 {
            let t = k as f64 * dt;
            d.step(100.0 * t, 100.0, true, true);
        }
        // After the step of cycle 99 the plant is at t = 0.1; the setpoint then was 10.0.
        let a = d.actual();
        assert!((a.p - 100.0 * (0.1 - 0.0035)).abs() < 1e-9, "{}", a.p);
        assert!((a.v - 100.0).abs() < 1e-9);
    }

    #[test]
    fn position_loop_tracks_with_small_following_error() {
        let dt = 0.001;
        let mut d = SimDrive::new(
            DriveModel::PositionLoop {
                kv: 100.0,
                kpc: 1.0,
                t_vtc: 0.002,
            },
            dt,
            1000.0,
            0.0,
        );
        for k in 0..2000 {
            let t = k as f64 * dt;
            d.step(50.0 * t, 50.0, true, true);
        }
        let a = d.actual();
        // Constant velocity with full precontrol: the actual follows the balanced setpoint.
        assert!((a.balanced - a.p).abs() < 1e-6, "fe {}", a.balanced - a.p);
        assert!((a.v - 50.0).abs() < 1e-6);
    }

    /// The inline ring of two (position loop): the balanced setpoint passes the setpoint of
    /// the cycle before through the velocity-loop model, bit for bit as the formula with the
    /// previous setpoint kept by hand, also across a disable (which refills the history).
    #[test]
    fn position_loop_reads_the_previous_setpoint() {
        let dt = 0.001;
        let (kv, kpc, t_vtc) = (80.0, 0.9, 0.003);
        let mut d = SimDrive::new(DriveModel::PositionLoop { kv, kpc, t_vtc }, dt, 500.0, 1.0);
        let e = (-dt / t_vtc).exp();
        let (mut p, mut v, mut v_cmd, mut balanced, mut prev_sp) = (1.0, 0.0, 0.0, 1.0, 1.0);
        for k in 0..400 {
            let sp = (1.0 + (k as f64 * 0.01).sin(), (k as f64 * 0.02).cos());
            let enabled = !(200..210).contains(&k);
            d.step(sp.0, sp.1, enabled, true);
            if enabled {
                let v1 = v_cmd + (v - v_cmd) * e;
                p += v_cmd * dt + (v - v_cmd) * t_vtc * (1.0 - e);
                v = v1;
                balanced = prev_sp + (balanced - prev_sp) * e;
                v_cmd = kpc * sp.1 + kv * (balanced - p);
                prev_sp = sp.0;
            } else {
                let dv = 500.0 * dt;
                let v1 = if v.abs() <= dv {
                    0.0
                } else {
                    v - dv.copysign(v)
                };
                p += 0.5 * (v + v1) * dt;
                v = v1;
                v_cmd = v1;
                balanced = p;
                prev_sp = p;
            }
            let a = d.actual();
            assert_eq!(
                (a.p.to_bits(), a.v.to_bits(), a.balanced.to_bits()),
                (p.to_bits(), v.to_bits(), balanced.to_bits()),
                "cycle {k}"
            );
        }
    }

    /// The delay model without delay keeps its ring inline: the actual value is the newest
    /// setpoint carried one cycle on.
    #[test]
    fn delay_model_without_delay_extrapolates_one_cycle() {
        let dt = 0.001;
        let mut d = SimDrive::new(DriveModel::Delay { delay: 0.0 }, dt, 10.0, 0.0);
        for k in 0..50 {
            let (sp_p, sp_v) = (k as f64 * 0.3, 300.0 - k as f64);
            d.step(sp_p, sp_v, true, true);
            let a = d.actual();
            assert_eq!(a.p.to_bits(), (sp_p + sp_v * dt).to_bits(), "cycle {k}");
            assert_eq!(a.v.to_bits(), sp_v.to_bits());
        }
    }
}
