//! The displacement-based set value generator of a hydraulic axis, `iTcMc_ProfileCtrlBased`
//! (Beckhoff TwinCAT PLC Hydraulic Positioning library, 'Profile types': the standard profile;
//! its states `E_TcHydAxState`, 4.3.3).
//!
//! The profile of the control value (the set velocity), in the library's words and numbers:
//! 1. a **time-controlled start ramp** to the travel velocity, with the smallest of `fMaxAcc`,
//!    `fAcc` and the command's acceleration (`iTcHydStateTcAccP/M`);
//! 2. **travel** at the smallest of `fRefVelo`, `fMaxVelo` and the command's velocity
//!    (`iTcHydStateConstVeloP/M`), "until a point is reached that was recalculated at the
//!    start";
//! 3. a **displacement-controlled braking ramp** ("square root generator"), with the smallest of
//!    `fMaxDec`, `fDec` and the command's deceleration, from the travel velocity down to the
//!    creep velocity, "reached at a specified distance from the target" (`fCreepDistance`;
//!    `iTcHydStatePcDecP/M`);
//! 4. **creep** at `fCreepSpeed` (`iTcHydStateCreepVeloP/M`) until the remaining distance is
//!    below the braking distance `fBrakeDistance + fBrakeDeadTime·|v_act|`;
//! 5. **idle** (`iTcHydStateIdle`): the set velocity 0 and the set position the target, for the
//!    position controller at standstill; or, with `fTargetClamping`, that output (V) with the
//!    sign of the approach and no position control (a pressing axis); with `fReposDistance`, an
//!    automatic start of a positioning to the same target once the actual position is further
//!    from it than that.
//!
//! The arithmetic is inferred from that description and stated: the brake point is the remaining
//! distance `fCreepDistance + (v_travel² - v_creep²) / (2·dec)` (where a ramp at `dec` from the
//! travel velocity reaches creep velocity at the creep distance), computed at the start; in the
//! braking ramp the set velocity is `sqrt(v_creep² + 2·dec·(d - fCreepDistance))` of the remaining
//! distance `d` measured from the **actual** position (displacement-controlled), never above the
//! travel velocity; a short move that reaches its brake point while still accelerating goes on
//! accelerating until it meets that curve; the creep velocity too is reached with the
//! acceleration, not in one step (inferred: the library says nothing of moves shorter than their
//! ramps). The braking distance is measured from the actual position too. A restart with a
//! lower velocity ramps down to it with the deceleration.
//! With `bAsymmetricalTargeting` the `…M` creep speed, creep distance, brake distance and dead time
//! serve the negative direction.
//!
//! A stop (`MC_Stop_BkPlcMc`, a lost feed enable) ramps the set velocity down in time,
//! `fStopRamp` seconds from `fRefVelo` to 0 (the ramp is referred to the reference velocity, not
//! to the current one: a slower axis stops sooner), `iTcHydStateTcDecP/M`; an emergency stop
//! with `fEmergencyRamp` (`iTcHydStateEmergencyBreak`).
//!
//! Pure: no IO, no clock (the cycle time is an input), no allocation.

use super::profile_core::{check_move, GeneratorCore, ProfileGenerator};
pub use super::profile_core::{Approach, GeneratorError, GeneratorParams, HydState, Setpoint};

/// A move the generator runs (the command's values, already limited by the parameters).
#[derive(Copy, Clone, Debug, PartialEq)]
struct Move {
    velocity: f64,
    acc: f64,
    dec: f64,
    /// Remaining distance at which the braking ramp begins.
    brake_point: f64,
}

/// The displacement-based generator `iTcMc_ProfileCtrlBased` (see the module documentation).
#[doc(alias = "iTcMc_ProfileCtrlBased")]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CtrlBasedGenerator {
    c: GeneratorCore,
    mv: Move,
    /// The limit of the set velocity's magnitude during a move (mm/s; +∞: none; negative:
    /// backing off), MC_AxCtrlSlowDownOnPressureEx_BkPlcMc's permissible velocity.
    velocity_limit: f64,
    /// The last cycle's set velocity was cut to `velocity_limit`.
    limited: bool,
}

impl CtrlBasedGenerator {
    /// The generator with parameters `p`, idle at position `x`.
    pub fn new(p: GeneratorParams, x: f64) -> Result<Self, GeneratorError> {
        let positive = [
            ("fRefVelo", p.ref_velo),
            ("fMaxVelo", p.max_velo),
            ("fAcc", p.acc),
            ("fMaxAcc", p.max_acc),
            ("fDec", p.dec),
            ("fMaxDec", p.max_dec),
            ("fStopRamp", p.stop_ramp),
            ("fEmergencyRamp", p.emergency_ramp),
            ("fCreepSpeedP", p.approach_p.creep_speed),
            ("fCreepSpeedM", p.approach_m.creep_speed),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(GeneratorError::Invalid { name, value });
            }
        }
        let at_least_0 = [
            ("fCreepDistanceP", p.approach_p.creep_distance),
            ("fCreepDistanceM", p.approach_m.creep_distance),
            ("fBrakeDistanceP", p.approach_p.brake_distance),
            ("fBrakeDistanceM", p.approach_m.brake_distance),
            ("fBrakeDeadTimeP", p.approach_p.brake_dead_time),
            ("fBrakeDeadTimeM", p.approach_m.brake_dead_time),
            ("fReposDistance", p.repos_distance),
        ];
        for (name, value) in at_least_0 {
            if !(value.is_finite() && value >= 0.0) {
                return Err(GeneratorError::Invalid { name, value });
            }
        }
        if !(p.target_clamping.is_finite() && (0.0..=10.0).contains(&p.target_clamping)) {
            return Err(GeneratorError::Invalid {
                name: "fTargetClamping",
                value: p.target_clamping,
            });
        }
        if !x.is_finite() {
            return Err(GeneratorError::Invalid {
                name: "Position",
                value: x,
            });
        }
        Ok(Self {
            c: GeneratorCore::idle_at(p, x),
            mv: Move {
                velocity: 0.0,
                acc: p.acc.min(p.max_acc),
                dec: p.dec.min(p.max_dec),
                brake_point: 0.0,
            },
            velocity_limit: f64::INFINITY,
            limited: false,
        })
    }

    /// The approach of direction `positive`.
    fn approach(&self, positive: bool) -> &Approach {
        if positive || !self.c.p.asymmetrical {
            &self.c.p.approach_p
        } else {
            &self.c.p.approach_m
        }
    }

    /// Starts a move to `target` (`MC_MoveAbsolute_BkPlcMc`) from the actual position
    /// `actual`: the smallest of the parameters' and the command's velocity, acceleration and
    /// deceleration (a value of 0 for the command's acceleration or deceleration takes the
    /// parameters'). A move while moving in the other direction first stops with the stop ramp,
    /// then starts (inferred).
    pub fn move_absolute(
        &mut self,
        target: f64,
        velocity: f64,
        acceleration: f64,
        deceleration: f64,
        actual: f64,
    ) -> Result<(), GeneratorError> {
        check_move(
            target,
            velocity,
            &[
                ("Acceleration", acceleration),
                ("Deceleration", deceleration),
            ],
        )?;
        let p = &self.c.p;
        let limit = |param: f64, max: f64, cmd: f64| {
            let l = param.min(max);
            if cmd > 0.0 {
                l.min(cmd)
            } else {
                l
            }
        };
        let positive = target >= actual;
        if !self.feed_enabled(positive) && (target - actual).abs() > 0.0 {
            return Err(GeneratorError::FeedEnable { positive });
        }
        let approach = *self.approach(positive);
        let v = velocity
            .min(p.ref_velo)
            .min(p.max_velo)
            .max(approach.creep_speed);
        let acc = limit(p.acc, p.max_acc, acceleration);
        let dec = limit(p.dec, p.max_dec, deceleration);
        let vc = approach.creep_speed;
        self.c.target = target;
        self.mv = Move {
            velocity: v,
            acc,
            dec,
            brake_point: approach.creep_distance + (v * v - vc * vc).max(0.0) / (2.0 * dec),
        };
        let moving_other_way = self.c.velocity != 0.0 && (self.c.velocity > 0.0) != positive;
        self.c.reverse_pending = moving_other_way;
        if moving_other_way {
            self.begin_stop(HydState::TcDec, self.c.stop_ramp_dec());
        } else {
            self.c.positive = positive;
            self.c.state = HydState::TcAcc;
        }
        if self.c.velocity == 0.0 {
            self.c.position = actual;
        }
        Ok(())
    }

    /// The state machine of one cycle.
    fn cycle(&mut self, dt: f64, actual: f64, actual_velocity: f64) {
        self.limited = false;
        let sign = self.c.sign();
        let approach = *self.approach(self.c.positive);
        let speed = self.c.velocity.abs();
        let m = self.mv;
        let moving = matches!(
            self.c.state,
            HydState::TcAcc | HydState::ConstVelo | HydState::PcDec | HydState::CreepVelo
        );
        if moving && !self.feed_enabled(self.c.positive) {
            self.c.state = HydState::FeedStop;
        }
        if self.c.state == HydState::FeedStop {
            if self.feed_enabled(self.c.positive) {
                // The enable is back: the move goes on from the start ramp (from the velocity
                // the intermediate stop had come down to; inferred).
                self.c.state = HydState::TcAcc;
            } else {
                let s = (speed - self.c.stop_ramp_dec() * dt).max(0.0);
                self.set(s * sign, dt);
                return;
            }
        }
        match self.c.state {
            HydState::Idle => {
                self.c.velocity = 0.0;
                self.c.position = self.c.target;
                let off = (actual - self.c.target).abs();
                if self.c.p.repos_distance > 0.0 && off > self.c.p.repos_distance {
                    // The automatic start: a positioning to the same target with the last
                    // move's dynamics, from the actual position.
                    self.c.positive = self.c.target >= actual;
                    self.c.position = actual;
                    self.c.state = HydState::TcAcc;
                    self.c.repositioned += 1;
                }
                return;
            }
            HydState::TcDec | HydState::EmergencyBreak => {
                let dec = if self.c.state == HydState::TcDec {
                    self.c.stop_dec
                } else {
                    self.c.emergency_dec()
                };
                let s = (speed - dec * dt).max(0.0);
                self.set(s * sign, dt);
                if s == 0.0 {
                    self.finish_stop();
                }
                return;
            }
            _ => {}
        }
        let remaining = (self.c.target - actual) * sign;
        if remaining <= approach.brake_distance + approach.brake_dead_time * actual_velocity.abs() {
            self.c.state = HydState::Idle;
            self.c.velocity = 0.0;
            self.c.position = self.c.target;
            return;
        }
        let vc = approach.creep_speed;
        let up = speed + m.acc * dt;
        let s = if self.c.state == HydState::CreepVelo || remaining <= approach.creep_distance {
            self.c.state = HydState::CreepVelo;
            up.min(vc)
        } else if self.c.state == HydState::PcDec || remaining <= m.brake_point {
            self.c.state = HydState::PcDec;
            let root = (vc * vc + 2.0 * m.dec * (remaining - approach.creep_distance)).sqrt();
            root.min(up)
        } else if speed > m.velocity {
            // A restart with a lower velocity: down to it with the deceleration.
            self.c.state = HydState::TcAcc;
            (speed - m.dec * dt).max(m.velocity)
        } else {
            let s = up.min(m.velocity);
            self.c.state = if s >= m.velocity {
                HydState::ConstVelo
            } else {
                HydState::TcAcc
            };
            s
        };
        self.limited = s > self.velocity_limit;
        self.set(s.min(self.velocity_limit) * sign, dt);
    }

    /// Limits the magnitude of the set velocity of the moves from the next cycle on to
    /// `limit` (mm/s; `f64::INFINITY`: no limit; a negative limit backs off against the move's
    /// direction). Stops and the idle state are not limited. A non-finite limit other than
    /// +∞ is ignored.
    pub fn limit_velocity(&mut self, limit: f64) {
        if limit.is_finite() || limit == f64::INFINITY {
            self.velocity_limit = limit;
        }
    }

    /// Whether the last cycle's set velocity of a move was cut by [`Self::limit_velocity`].
    pub fn limited(&self) -> bool {
        self.limited
    }

    /// Sets the set velocity and integrates the set position.
    fn set(&mut self, v: f64, dt: f64) {
        self.c.position += 0.5 * (self.c.velocity + v) * dt;
        self.c.velocity = v;
    }

    /// A stop ramp has reached 0: the move in the other direction that waited for it starts,
    /// or the axis is idle at its set position.
    fn finish_stop(&mut self) {
        if self.c.reverse_pending && self.c.state == HydState::TcDec {
            self.c.reverse_pending = false;
            self.c.positive = !self.c.positive;
            self.c.state = HydState::TcAcc;
        } else {
            self.c.reverse_pending = false;
            self.c.state = HydState::Idle;
            self.c.target = self.c.position;
        }
    }
}

impl ProfileGenerator for CtrlBasedGenerator {
    fn core(&self) -> &GeneratorCore {
        &self.c
    }

    fn core_mut(&mut self) -> &mut GeneratorCore {
        &mut self.c
    }

    fn advance(&mut self, dt: f64, actual: f64, actual_velocity: f64) {
        self.cycle(dt, actual, actual_velocity);
    }

    /// The stop ramps of this generator are linear in time; an emergency stop ramps with
    /// `fEmergencyRamp` whatever `dec` says, and keeps the regular stop's deceleration.
    fn begin_stop(&mut self, state: HydState, dec: f64) {
        if state == HydState::TcDec {
            self.c.stop_dec = dec;
        }
        self.c.state = state;
    }

    fn brake_point(&self) -> f64 {
        self.mv.brake_point
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;
    use crate::catalog::hyd_error::HydErrorCode;

    const DT: f64 = 1e-3;

    fn params() -> GeneratorParams {
        let approach = Approach {
            creep_speed: 10.0,
            creep_distance: 1.0,
            brake_distance: 0.1,
            brake_dead_time: 0.0,
        };
        GeneratorParams {
            acc: 500.0,
            max_acc: 500.0,
            dec: 500.0,
            max_dec: 500.0,
            approach_p: approach,
            approach_m: approach,
            ..GeneratorParams::default()
        }
    }

    /// Runs `g` on an ideal axis (the actual position is the set position of the cycle
    /// before) until idle or `cycles`; returns the setpoints.
    fn run(g: &mut CtrlBasedGenerator, cycles: usize) -> Vec<Setpoint> {
        let mut out = Vec::new();
        let (mut x, mut v) = (g.c.position, g.c.velocity);
        for _ in 0..cycles {
            let s = g.step(DT, x, v);
            out.push(s);
            (x, v) = (s.position, s.velocity);
            if s.state == HydState::Idle {
                break;
            }
        }
        out
    }

    /// The set velocity of two cycles changes within 500 mm/s²: exactly in the time ramps; in
    /// the square-root ramp, sampled once a cycle from the actual position that lags a cycle,
    /// up to `dec·(1 + 2·dec·dt/v)` (1 % at 100 mm/s, 10 % at 10 mm/s); the step to 0 at the
    /// braking distance aside.
    fn within_dynamics(w: &[Setpoint]) -> bool {
        let dv = (w[1].velocity - w[0].velocity).abs() / DT;
        let slack = 2.0 * 500.0 * DT / w[1].velocity.abs().max(1.0);
        dv <= 500.0 * (1.0 + slack) + 1e-9 || w[1].state == HydState::Idle
    }

    #[test]
    fn a_move_runs_the_standard_profile_with_its_numbers() {
        let mut g = CtrlBasedGenerator::new(params(), 0.0).unwrap();
        g.move_absolute(100.0, 100.0, 0.0, 0.0, 0.0).unwrap();
        // Brake point: creep distance + (100² - 10²) / (2 · 500) = 1 + 9.9.
        assert!((g.brake_point() - 10.9).abs() < 1e-12);
        let out = run(&mut g, 10_000);
        // The states in the library's order, each once.
        let mut states: Vec<HydState> = out.iter().map(|s| s.state).collect();
        states.dedup();
        assert_eq!(
            states,
            [
                HydState::TcAcc,
                HydState::ConstVelo,
                HydState::PcDec,
                HydState::CreepVelo,
                HydState::Idle
            ]
        );
        // The start ramp: 100 mm/s at 500 mm/s² in 0.2 s (200 cycles).
        let acc = out.iter().filter(|s| s.state == HydState::TcAcc).count();
        assert_eq!(acc + 1, 200, "cycles of the start ramp");
        // Never above the travel velocity, never faster changes than acc and dec allow.
        for w in out.windows(2) {
            assert!(w[1].velocity <= 100.0 + 1e-12);
            assert!(within_dynamics(w), "{w:?}");
        }
        // The braking ramp follows the square root of the remaining distance: v² - vc² = 2 ·
        // dec · (d - creep distance), d measured at the cycle's start.
        let mut x = 0.0_f64;
        for s in &out {
            if s.state == HydState::PcDec {
                let d: f64 = 100.0 - x;
                let want = (100.0 + 1000.0 * (d - 1.0)).sqrt().min(100.0);
                assert!((s.velocity - want).abs() < 1e-9, "{} vs {want}", s.velocity);
            }
            x = s.position;
        }
        // Creep at 10 mm/s, then idle with the set position at the target, the (ideal) actual
        // position within the braking distance before it.
        let creep: Vec<_> = out
            .iter()
            .filter(|s| s.state == HydState::CreepVelo)
            .collect();
        assert!(creep.iter().all(|s| (s.velocity - 10.0).abs() < 1e-9));
        let last = out.last().unwrap();
        assert_eq!(
            (last.state, last.velocity, last.position),
            (HydState::Idle, 0.0, 100.0)
        );
        let before = out[out.len() - 2].position;
        assert!(
            (99.9..100.0).contains(&before),
            "stopped creeping at {before}"
        );
    }

    #[test]
    fn the_negative_direction_takes_its_own_approach_when_asymmetrical() {
        let mut p = params();
        p.asymmetrical = true;
        p.approach_m.creep_speed = 5.0;
        p.approach_m.creep_distance = 2.0;
        let mut g = CtrlBasedGenerator::new(p, 50.0).unwrap();
        g.move_absolute(0.0, 100.0, 0.0, 0.0, 50.0).unwrap();
        assert!((g.brake_point() - (2.0 + (100.0 * 100.0 - 25.0) / 1000.0)).abs() < 1e-12);
        let out = run(&mut g, 10_000);
        assert!(out.iter().all(|s| s.velocity <= 0.0 && !s.positive));
        let creep: Vec<_> = out
            .iter()
            .filter(|s| s.state == HydState::CreepVelo)
            .collect();
        assert!(!creep.is_empty() && creep.iter().all(|s| (s.velocity + 5.0).abs() < 1e-9));
        assert_eq!(out.last().unwrap().position, 0.0);
        assert_eq!(HydState::CreepVelo.name(false), "iTcHydStateCreepVeloM");
    }

    #[test]
    fn a_stop_ramps_down_in_the_stop_ramp_referred_to_the_reference_velocity() {
        let mut g = CtrlBasedGenerator::new(params(), 0.0).unwrap();
        g.move_absolute(1000.0, 100.0, 0.0, 0.0, 0.0).unwrap();
        let out = run(&mut g, 300);
        assert_eq!(out.last().unwrap().state, HydState::ConstVelo);
        g.stop();
        // fStopRamp 1 s from fRefVelo 500: 500 mm/s², so 100 mm/s stop in 0.2 s.
        let out = run(&mut g, 1000);
        let ramp = out.iter().filter(|s| s.state == HydState::TcDec).count();
        assert_eq!(ramp + 1, 200);
        let last = out.last().unwrap();
        assert_eq!((last.state, last.velocity), (HydState::Idle, 0.0));
        assert_eq!(g.target(), last.position);
    }

    #[test]
    fn a_stop_with_a_deceleration_ramps_down_with_it() {
        let mut g = CtrlBasedGenerator::new(params(), 0.0).unwrap();
        g.move_absolute(1000.0, 100.0, 0.0, 0.0, 0.0).unwrap();
        run(&mut g, 300);
        // 1000 mm/s²: 100 mm/s in 0.1 s; a deceleration of 0 takes the stop ramp's 500.
        g.stop_with(1000.0);
        let out = run(&mut g, 1000);
        let ramp = out.iter().filter(|s| s.state == HydState::TcDec).count();
        assert_eq!(ramp + 1, 100);
        g.move_absolute(2000.0, 100.0, 0.0, 0.0, g.c.position)
            .unwrap();
        run(&mut g, 300);
        g.stop_with(0.0);
        let out = run(&mut g, 1000);
        let ramp = out.iter().filter(|s| s.state == HydState::TcDec).count();
        assert_eq!(ramp + 1, 200);
    }

    #[test]
    fn a_taken_over_setpoint_starts_the_next_move_without_a_step() {
        let mut g = CtrlBasedGenerator::new(params(), 0.0).unwrap();
        // Another generator left the axis at 40 mm moving at -30 mm/s.
        g.take_over(40.0, -30.0);
        assert_eq!(g.state(), HydState::TcDec);
        g.move_absolute(100.0, 100.0, 0.0, 0.0, 40.0).unwrap();
        let out = run(&mut g, 20_000);
        // From -30 mm/s with the stop ramp's 500 mm/s², then within the dynamics.
        assert!(
            (out[0].velocity + 30.0 - 500.0 * DT).abs() < 1e-9,
            "{:?}",
            out[0]
        );
        for w in out.windows(2) {
            assert!(within_dynamics(w), "{w:?}");
        }
        // It stopped with the stop ramp, then reversed and landed.
        assert_eq!(out.last().unwrap().position, 100.0);
        // A standing setpoint: idle there.
        g.take_over(7.0, 0.0);
        assert_eq!((g.state(), g.target()), (HydState::Idle, 7.0));
        g.take_over(f64::NAN, 0.0);
        assert_eq!(g.target(), 7.0);
    }

    #[test]
    fn a_missing_feed_enable_pauses_the_move_which_goes_on_when_it_returns() {
        let mut g = CtrlBasedGenerator::new(params(), 0.0).unwrap();
        g.move_absolute(1000.0, 100.0, 0.0, 0.0, 0.0).unwrap();
        run(&mut g, 300);
        assert_eq!(g.state(), HydState::ConstVelo);
        // The negative enable does not matter for a positive move.
        g.set_feed_enables(true, false);
        run(&mut g, 10);
        assert_eq!(g.state(), HydState::ConstVelo);
        // Without the positive one: the stop ramp (500 mm/s², 100 mm/s in 0.2 s), then waiting.
        g.set_feed_enables(false, false);
        let out = run(&mut g, 600);
        assert!(out.iter().all(|s| s.state == HydState::FeedStop));
        assert_eq!(out[0].state.name(out[0].positive), "iTcHydStateFeedStopPos");
        let stopped = out.iter().position(|s| s.velocity == 0.0).unwrap();
        assert_eq!(stopped + 1, 200);
        let held = out.last().unwrap().position;
        assert!(out[stopped..].iter().all(|s| s.position == held));
        for w in out.windows(2) {
            assert!(within_dynamics(w), "{w:?}");
        }
        // The enable returns: the move goes on and ends at its target.
        g.set_feed_enables(true, false);
        let out = run(&mut g, 20_000);
        assert_eq!(out[0].state, HydState::TcAcc);
        let last = out.last().unwrap();
        assert_eq!((last.state, last.position), (HydState::Idle, 1000.0));
        // A move in the direction without enable is refused and changes nothing.
        let e = g.move_absolute(0.0, 50.0, 0.0, 0.0, 1000.0).unwrap_err();
        assert_eq!(e, GeneratorError::FeedEnable { positive: false });
        assert_eq!(e.code(), HydErrorCode::NEG_FD_ENA);
        assert_eq!((g.state(), g.target()), (HydState::Idle, 1000.0));
        g.set_feed_enables(false, true);
        let e = g.move_absolute(2000.0, 50.0, 0.0, 0.0, 1000.0).unwrap_err();
        assert_eq!(e.code().0, 0x4358);
    }

    #[test]
    fn a_move_the_other_way_stops_first_then_reverses() {
        let mut g = CtrlBasedGenerator::new(params(), 0.0).unwrap();
        g.move_absolute(1000.0, 100.0, 0.0, 0.0, 0.0).unwrap();
        let out = run(&mut g, 300);
        let x = out.last().unwrap().position;
        g.move_absolute(0.0, 50.0, 0.0, 0.0, x).unwrap();
        let out = run(&mut g, 20_000);
        let mut states: Vec<(HydState, bool)> = out.iter().map(|s| (s.state, s.positive)).collect();
        states.dedup();
        assert_eq!(states[0], (HydState::TcDec, true));
        assert_eq!(states[1], (HydState::TcAcc, false));
        assert_eq!(out.last().unwrap().position, 0.0);
        // No step in the set velocity through the reversal.
        for w in out.windows(2) {
            assert!(within_dynamics(w), "{w:?}");
        }
    }

    #[test]
    fn the_braking_distance_grows_with_the_dead_time_and_the_actual_velocity() {
        let mut p = params();
        p.approach_p.brake_dead_time = 0.05;
        let mut g = CtrlBasedGenerator::new(p, 0.0).unwrap();
        g.move_absolute(100.0, 100.0, 0.0, 0.0, 0.0).unwrap();
        let out = run(&mut g, 10_000);
        // Creeping at 10 mm/s: idle from 0.1 + 0.05 · 10 = 0.6 mm before the target.
        let before = out[out.len() - 2].position;
        assert!(
            (99.4..99.41).contains(&before),
            "stopped creeping at {before}"
        );
    }

    #[test]
    fn target_clamping_presses_with_the_sign_of_the_approach_without_position_control() {
        let mut p = params();
        p.target_clamping = 2.5;
        let mut g = CtrlBasedGenerator::new(p, 50.0).unwrap();
        g.move_absolute(0.0, 50.0, 0.0, 0.0, 50.0).unwrap();
        let out = run(&mut g, 10_000);
        let moving = &out[..out.len() - 1];
        assert!(moving
            .iter()
            .all(|s| s.clamping_output == 0.0 && !s.position_control));
        let last = out.last().unwrap();
        assert_eq!(last.state, HydState::Idle);
        assert_eq!((last.clamping_output, last.position_control), (-2.5, false));
        // Without it: position control at the target.
        let mut g = CtrlBasedGenerator::new(params(), 50.0).unwrap();
        g.move_absolute(0.0, 50.0, 0.0, 0.0, 50.0).unwrap();
        let last = *run(&mut g, 10_000).last().unwrap();
        assert_eq!((last.clamping_output, last.position_control), (0.0, true));
    }

    #[test]
    fn an_idle_axis_pushed_beyond_the_repositioning_distance_positions_again() {
        let mut p = params();
        p.repos_distance = 0.5;
        let mut g = CtrlBasedGenerator::new(p, 0.0).unwrap();
        g.move_absolute(10.0, 50.0, 0.0, 0.0, 0.0).unwrap();
        run(&mut g, 10_000);
        assert_eq!(g.state(), HydState::Idle);
        // Pushed 0.4 mm: stays idle.
        let s = g.step(DT, 9.6, 0.0);
        assert_eq!((s.state, g.repositioned()), (HydState::Idle, 0));
        // Pushed 0.6 mm: starts again towards the same target, and gets there.
        g.step(DT, 9.4, 0.0);
        assert_eq!(
            (g.state(), g.repositioned(), g.target()),
            (HydState::TcAcc, 1, 10.0)
        );
        let out = run(&mut g, 10_000);
        assert!(out.iter().all(|s| s.velocity >= 0.0));
        assert_eq!(out.last().unwrap().position, 10.0);
    }

    #[test]
    fn bad_parameters_and_commands_are_refused_and_change_nothing() {
        let mut p = params();
        p.max_dec = 0.0;
        assert_eq!(
            CtrlBasedGenerator::new(p, 0.0).unwrap_err(),
            GeneratorError::Invalid {
                name: "fMaxDec",
                value: 0.0
            }
        );
        assert_eq!(
            CtrlBasedGenerator::new(p, 0.0).unwrap_err().code().name(),
            "dwTcHydErrCdDec"
        );
        let mut p = params();
        p.approach_m.brake_distance = -1.0;
        assert!(CtrlBasedGenerator::new(p, 0.0).is_err());
        let mut g = CtrlBasedGenerator::new(params(), 0.0).unwrap();
        let before = g;
        assert!(g.move_absolute(f64::NAN, 100.0, 0.0, 0.0, 0.0).is_err());
        let e = g.move_absolute(10.0, 0.0, 0.0, 0.0, 0.0).unwrap_err();
        assert_eq!(e.code().to_string(), "16#4359 dwTcHydErrCdSetVelo");
        assert!(g.move_absolute(10.0, 10.0, -1.0, 0.0, 0.0).is_err());
        assert_eq!(g, before);
        // A cycle with a NaN actual changes nothing either.
        g.move_absolute(10.0, 10.0, 0.0, 0.0, 0.0).unwrap();
        let moving = g;
        g.step(DT, f64::NAN, 0.0);
        assert_eq!(g, moving);
    }
}
