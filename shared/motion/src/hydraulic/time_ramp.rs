//! The time-ramp generator of a hydraulic axis without an encoder, `iTcMc_ProfileTimeRamp`, on
//! four digital position cams (`iTcMc_EncoderDigCam`: `bDigCamPP`, `bDigCamP`, `bDigCamM`,
//! `bDigCamMM`) (Beckhoff TwinCAT PLC Hydraulic Positioning library, 'Profile types').
//!
//! In the library's words: "a time-controlled ramp function is used to accelerate to the
//! required travel velocity. This control value is maintained until the direction-specific
//! target window cam is detected. From here, a time-controlled ramp is applied to decelerate from
//! the set motion value to the set creep value. This control value is maintained until the
//! direction-specific target cam is detected. The axis is then switched to its idle behavior."
//! The start ramp is `fStartRamp` (seconds from 0 to `fRefVelo`), the braking ramp `fStopRamp`
//! (seconds from `fRefVelo` to 0), the travel velocity the smallest of `fRefVelo`, `fMaxVelo` and
//! the command's, the creep velocity `fCreepSpeed`. A restart in the same direction ramps to the
//! new velocity (up with the start ramp, down with the stop ramp); a restart in the opposite
//! direction ramps down with the stop ramp, then starts the other way (the library supports
//! both; its figures of them are not in the copy used: the ramps are inferred from the phases').
//! The brake cam seen while still accelerating starts the braking ramp at once (below creep
//! velocity: up to it with the start ramp); the target cam seen ends the motion at once, from any
//! velocity (output off).
//!
//! Pure: no IO, no clock (the cycle time is an input), no allocation.

use crate::hydraulic::generator::{GeneratorError, HydState};

/// The four position cams of `iTcMc_EncoderDigCam`.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct DigCams {
    /// `bDigCamPP`: the positive target cam.
    pub target_p: bool,
    /// `bDigCamP`: the positive brake (target window) cam.
    pub brake_p: bool,
    /// `bDigCamM`: the negative brake cam.
    pub brake_m: bool,
    /// `bDigCamMM`: the negative target cam.
    pub target_m: bool,
}

/// The parameters of the time-ramp generator (members of `ST_TcHydAxParam`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TimeRampParams {
    /// `fRefVelo` (mm/s, > 0).
    pub ref_velo: f64,
    /// `fMaxVelo` (mm/s, > 0).
    pub max_velo: f64,
    /// `fStartRamp` (s, > 0): from 0 to `fRefVelo`.
    pub start_ramp: f64,
    /// `fStopRamp` (s, > 0): from `fRefVelo` to 0.
    pub stop_ramp: f64,
    /// `fCreepSpeedP` (mm/s, > 0).
    pub creep_speed_p: f64,
    /// `fCreepSpeedM` (mm/s, > 0).
    pub creep_speed_m: f64,
}

impl Default for TimeRampParams {
    /// The library's defaults: 500 mm/s, 1.0 s ramps, creep 80 mm/s.
    fn default() -> Self {
        Self {
            ref_velo: 500.0,
            max_velo: 500.0,
            start_ramp: 1.0,
            stop_ramp: 1.0,
            creep_speed_p: 80.0,
            creep_speed_m: 80.0,
        }
    }
}

/// The generator `iTcMc_ProfileTimeRamp` (see the module documentation).
#[doc(alias = "iTcMc_ProfileTimeRamp")]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TimeRampGenerator {
    p: TimeRampParams,
    state: HydState,
    positive: bool,
    /// Set velocity (mm/s, signed).
    velocity: f64,
    /// The travel velocity of the running move (mm/s, > 0).
    travel: f64,
    /// A move in the other direction waits for the stop ramp.
    reverse_pending: bool,
}

impl TimeRampGenerator {
    /// The generator with parameters `p`, idle.
    pub fn new(p: TimeRampParams) -> Result<Self, GeneratorError> {
        for (name, value) in [
            ("fRefVelo", p.ref_velo),
            ("fMaxVelo", p.max_velo),
            ("fStartRamp", p.start_ramp),
            ("fStopRamp", p.stop_ramp),
            ("fCreepSpeedP", p.creep_speed_p),
            ("fCreepSpeedM", p.creep_speed_m),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(GeneratorError::Invalid { name, value });
            }
        }
        Ok(Self {
            p,
            state: HydState::Idle,
            positive: true,
            velocity: 0.0,
            travel: 0.0,
            reverse_pending: false,
        })
    }

    /// The state.
    pub fn state(&self) -> HydState {
        self.state
    }

    /// The set velocity (mm/s, signed).
    pub fn velocity(&self) -> f64 {
        self.velocity
    }

    /// Starts a move in direction `positive` at `velocity` (mm/s, > 0), until that direction's
    /// target cam.
    pub fn start(&mut self, positive: bool, velocity: f64) -> Result<(), GeneratorError> {
        if !(velocity.is_finite() && velocity > 0.0) {
            return Err(GeneratorError::Invalid {
                name: "Velocity",
                value: velocity,
            });
        }
        self.travel = velocity.min(self.p.ref_velo).min(self.p.max_velo);
        let moving_other_way = self.velocity != 0.0 && (self.velocity > 0.0) != positive;
        self.reverse_pending = moving_other_way;
        if moving_other_way {
            self.state = HydState::TcDec;
        } else {
            self.positive = positive;
            self.state = HydState::TcAcc;
        }
        Ok(())
    }

    /// A stop (`MC_Stop_BkPlcMc`): down with the stop ramp.
    pub fn stop(&mut self) {
        if self.state != HydState::Idle {
            self.state = HydState::TcDec;
            self.reverse_pending = false;
            self.travel = 0.0;
        }
    }

    /// One cycle of `dt` seconds with the cams as read at its start; returns the set velocity.
    pub fn step(&mut self, dt: f64, cams: DigCams) -> f64 {
        if !(dt.is_finite() && dt > 0.0) {
            return self.velocity;
        }
        let sign = if self.positive { 1.0 } else { -1.0 };
        let (target, brake, creep) = if self.positive {
            (cams.target_p, cams.brake_p, self.p.creep_speed_p)
        } else {
            (cams.target_m, cams.brake_m, self.p.creep_speed_m)
        };
        let speed = self.velocity.abs();
        let up = self.p.ref_velo / self.p.start_ramp * dt;
        let down = self.p.ref_velo / self.p.stop_ramp * dt;
        let moving = !matches!(self.state, HydState::Idle | HydState::TcDec);
        if target && (moving || self.state == HydState::TcDec && !self.reverse_pending) {
            self.state = HydState::Idle;
            self.velocity = 0.0;
            return 0.0;
        }
        let s = match self.state {
            HydState::Idle => 0.0,
            HydState::TcDec => {
                let floor = if self.reverse_pending || self.travel == 0.0 {
                    0.0
                } else {
                    creep
                };
                // Below creep speed (braked while still slow): up to it with the start ramp.
                let s = if speed < floor {
                    (speed + up).min(floor)
                } else {
                    (speed - down).max(floor)
                };
                if s == 0.0 {
                    self.finish_stop();
                } else if s == floor {
                    self.state = HydState::CreepVelo;
                }
                s
            }
            HydState::CreepVelo => creep,
            _ if brake => {
                self.state = HydState::TcDec;
                if speed < creep {
                    (speed + up).min(creep)
                } else {
                    (speed - down).max(creep)
                }
            }
            _ if speed > self.travel => {
                self.state = HydState::TcAcc;
                (speed - down).max(self.travel)
            }
            _ => {
                let s = (speed + up).min(self.travel);
                self.state = if s >= self.travel {
                    HydState::ConstVelo
                } else {
                    HydState::TcAcc
                };
                s
            }
        };
        self.velocity = s * sign;
        self.velocity
    }

    /// The stop ramp reached 0: the move the other way starts, or the axis is idle.
    fn finish_stop(&mut self) {
        if self.reverse_pending {
            self.reverse_pending = false;
            self.positive = !self.positive;
            self.state = HydState::TcAcc;
        } else {
            self.state = HydState::Idle;
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    const DT: f64 = 1e-3;

    fn params() -> TimeRampParams {
        TimeRampParams {
            creep_speed_p: 10.0,
            creep_speed_m: 20.0,
            ..TimeRampParams::default()
        }
    }

    /// Runs `g` on an axis at `x` with cams at the given positions (brake, target) in each
    /// direction, until idle or `cycles`; returns the set velocities and states.
    fn run(
        g: &mut TimeRampGenerator,
        x: &mut f64,
        cams_at: (f64, f64, f64, f64),
        cycles: usize,
    ) -> Vec<(f64, HydState)> {
        let (brake_p, target_p, brake_m, target_m) = cams_at;
        let mut out = Vec::new();
        for _ in 0..cycles {
            let cams = DigCams {
                target_p: *x >= target_p,
                brake_p: *x >= brake_p,
                brake_m: *x <= brake_m,
                target_m: *x <= target_m,
            };
            let v = g.step(DT, cams);
            *x += v * DT;
            out.push((v, g.state()));
            if g.state() == HydState::Idle {
                break;
            }
        }
        out
    }

    #[test]
    fn a_move_ramps_up_travels_brakes_at_the_brake_cam_and_creeps_to_the_target_cam() {
        let mut g = TimeRampGenerator::new(params()).unwrap();
        g.start(true, 100.0).unwrap();
        let mut x = 0.0;
        let out = run(&mut g, &mut x, (100.0, 110.0, -100.0, -110.0), 100_000);
        let mut states: Vec<HydState> = out.iter().map(|o| o.1).collect();
        states.dedup();
        assert_eq!(
            states,
            [
                HydState::TcAcc,
                HydState::ConstVelo,
                HydState::TcDec,
                HydState::CreepVelo,
                HydState::Idle
            ]
        );
        // fStartRamp 1 s per 500 mm/s: 100 mm/s in 0.2 s.
        let acc = out.iter().filter(|o| o.1 == HydState::TcAcc).count();
        assert_eq!(acc + 1, 200);
        // fStopRamp 1 s per 500 mm/s: 100 to 10 mm/s in 0.18 s.
        let dec = out.iter().filter(|o| o.1 == HydState::TcDec).count();
        assert_eq!(dec + 1, 180);
        assert!(out
            .iter()
            .filter(|o| o.1 == HydState::CreepVelo)
            .all(|o| (o.0 - 10.0).abs() < 1e-9));
        assert_eq!(out.last().unwrap().0, 0.0);
        assert!(
            (110.0..110.0 + 10.0 * DT + 1e-9).contains(&x),
            "stopped at {x}"
        );
    }

    #[test]
    fn restarts_ramp_to_the_new_velocity_or_reverse_through_a_stop() {
        let mut g = TimeRampGenerator::new(params()).unwrap();
        g.start(true, 100.0).unwrap();
        let mut x = 0.0;
        run(&mut g, &mut x, (1e9, 1e9, -1e9, -1e9), 300);
        assert_eq!((g.state(), g.velocity()), (HydState::ConstVelo, 100.0));
        // Faster in the same direction: up with the start ramp (0.1 s to 150 mm/s).
        g.start(true, 150.0).unwrap();
        let out = run(&mut g, &mut x, (1e9, 1e9, -1e9, -1e9), 200);
        assert_eq!(
            out.iter().filter(|o| o.1 == HydState::TcAcc).count() + 1,
            100
        );
        assert_eq!(g.velocity(), 150.0);
        // The other way: down with the stop ramp to 0, then up negative; no jump on the way.
        g.start(false, 50.0).unwrap();
        let out = run(&mut g, &mut x, (1e9, 1e9, -1e9, -1e9), 600);
        let mut last = 150.0;
        for (v, _) in &out {
            assert!((v - last).abs() <= 500.0 * DT + 1e-9, "{last} -> {v}");
            last = *v;
        }
        assert_eq!((g.state(), g.velocity()), (HydState::ConstVelo, -50.0));
        // The negative creep speed is its own.
        let cams = (1e9, 1e9, x - 1.0, x - 2.0);
        let out = run(&mut g, &mut x, cams, 100_000);
        assert!(out
            .iter()
            .filter(|o| o.1 == HydState::CreepVelo)
            .all(|o| (o.0 + 20.0).abs() < 1e-9));
        assert_eq!(g.state(), HydState::Idle);
    }

    #[test]
    fn started_on_the_brake_cam_it_ramps_up_to_creep_speed_only() {
        let mut g = TimeRampGenerator::new(params()).unwrap();
        g.start(true, 100.0).unwrap();
        let mut x = 0.0;
        let out = run(&mut g, &mut x, (-1.0, 1.0, -1e9, -1e9), 100_000);
        // Up to 10 mm/s with the start ramp (20 cycles), never above; then creep to the cam.
        assert!(out.iter().all(|o| o.0 <= 10.0 + 1e-12));
        assert!((out[19].0 - 10.0).abs() < 1e-9, "{:?}", &out[..21]);
        assert_eq!(out.last().unwrap().1, HydState::Idle);
    }

    #[test]
    fn a_stop_ramps_to_zero_and_bad_inputs_are_refused() {
        let mut g = TimeRampGenerator::new(params()).unwrap();
        g.start(false, 100.0).unwrap();
        let mut x = 0.0;
        run(&mut g, &mut x, (1e9, 1e9, -1e9, -1e9), 300);
        g.stop();
        let out = run(&mut g, &mut x, (1e9, 1e9, -1e9, -1e9), 1000);
        assert_eq!(
            out.iter().filter(|o| o.1 == HydState::TcDec).count() + 1,
            200
        );
        assert_eq!(g.state(), HydState::Idle);
        let before = g;
        assert!(g.start(true, 0.0).is_err());
        assert_eq!(g, before);
        assert_eq!(
            TimeRampGenerator::new(TimeRampParams {
                stop_ramp: 0.0,
                ..params()
            })
            .unwrap_err()
            .code()
            .name(),
            "dwTcHydAdsErrIllegalValue"
        );
    }
}
