//! Durations of our profiles against `rsruckig` (a Rust port of ruckig) on random symmetric
//! cases that start within the limits. The Python ruckig fixtures (`ruckig_oracle.rs`) are the
//! primary oracle; this one runs many more cases cheaply.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use rsruckig::prelude::*;
use tandem_motion::kinematics::profile::{plan_position, plan_velocity, Limits, State};

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + self.next() * (hi.ln() - lo.ln())).exp()
    }
}

fn ruckig_duration(start: State, target: f64, velocity_mode: bool, lim: &Limits) -> Option<f64> {
    let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 0.001);
    let mut input = InputParameter::new(None);
    if velocity_mode {
        input.control_interface = ControlInterface::Velocity;
        input.target_velocity = daov_stack![target];
    } else {
        input.target_position = daov_stack![target];
        input.target_velocity = daov_stack![0.0];
    }
    input.current_position = daov_stack![start.p];
    input.current_velocity = daov_stack![start.v];
    input.current_acceleration = daov_stack![start.a];
    input.target_acceleration = daov_stack![0.0];
    input.max_velocity = daov_stack![lim.vel];
    input.max_acceleration = daov_stack![lim.acc];
    input.max_jerk = daov_stack![lim.jerk];
    let mut traj = Trajectory::new(None);
    otg.calculate(&input, &mut traj).ok()?;
    Some(traj.get_duration())
}

/// A start state (v, a) within the limits whose released velocity is within them too.
fn feasible_start(fv: f64, fa: f64, lim: &Limits) -> (f64, f64) {
    let mut a = (2.0 * fa - 1.0) * lim.acc.min(lim.dec);
    let mut shift = a * a.abs() / (2.0 * lim.jerk);
    if shift.abs() > 0.999 * lim.vel {
        a = a.signum() * (2.0 * lim.jerk * 0.999 * lim.vel).sqrt();
        shift = a * a.abs() / (2.0 * lim.jerk);
    }
    let lo = (-lim.vel).max(-lim.vel - shift) * 0.999;
    let hi = lim.vel.min(lim.vel - shift) * 0.999;
    (lo + fv * (hi - lo), a)
}

#[test]
fn durations_match_rsruckig_symmetric() {
    let mut rng = Rng(0x5eed_1234_9876_5432);
    let mut worst = (0.0f64, String::new());
    let mut compared = 0;
    for case in 0..20_000 {
        let vel = rng.log_uniform(1.0, 2000.0);
        let acc = rng.log_uniform(10.0, 20000.0);
        let jerk = acc * rng.log_uniform(1.0, 200.0);
        let lim = Limits {
            vel,
            acc,
            dec: acc,
            jerk,
        };
        let kind = case % 3;
        let (v, a) = if kind == 0 {
            (0.0, 0.0)
        } else {
            feasible_start(rng.next(), rng.next(), &lim)
        };
        let start = State { p: 0.0, v, a };
        let velocity_mode = case % 4 == 3;
        let target = if velocity_mode {
            (2.0 * rng.next() - 1.0) * vel
        } else {
            let d = rng.log_uniform(0.01, 5000.0);
            if rng.next() < 0.5 {
                -d
            } else {
                d
            }
        };
        let Some(expected) = ruckig_duration(start, target, velocity_mode, &lim) else {
            continue;
        };
        let ours = if velocity_mode {
            plan_velocity(start, target, &lim)
        } else {
            plan_position(start, target, &lim)
        }
        .unwrap()
        .duration();
        compared += 1;
        let err = (ours - expected).abs();
        let allowed = (1e-6f64).max(1e-4 * expected);
        if err / allowed > worst.0 {
            worst = (
                err / allowed,
                format!("case {case}: {start:?} -> {target} {lim:?} ours {ours} ruckig {expected}"),
            );
        }
    }
    assert!(compared > 19_000, "only {compared} cases compared");
    assert!(
        worst.0 <= 1.0,
        "worst case {:.3}x allowed: {}",
        worst.0,
        worst.1
    );
}

/// Asymmetric limits with reversals: ruckig with both bounds equal to the larger one can only be
/// faster than any profile under our (acc while speeding up, dec while braking) limits, and
/// ruckig with both equal to the smaller one can only be slower. Ours lies in between, and is
/// strictly faster than the smaller-bound one whenever a reversal can use the larger bound.
#[test]
fn asymmetric_durations_lie_between_the_symmetric_bounds() {
    let mut rng = Rng(0xa5a5_1234_0f0f_7777);
    let mut compared = 0;
    let mut improved = 0;
    for case in 0..20_000 {
        let vel = rng.log_uniform(1.0, 2000.0);
        let acc = rng.log_uniform(10.0, 20000.0);
        let dec = acc * rng.log_uniform(0.25, 4.0);
        let jerk = acc.max(dec) * rng.log_uniform(1.0, 200.0);
        let lo = Limits {
            vel,
            acc: acc.min(dec),
            dec: acc.min(dec),
            jerk,
        };
        let hi = Limits {
            vel,
            acc: acc.max(dec),
            dec: acc.max(dec),
            jerk,
        };
        let lim = Limits {
            vel,
            acc,
            dec,
            jerk,
        };
        let (v, a) = feasible_start(rng.next(), rng.next(), &lo);
        let start = State { p: 0.0, v, a };
        let velocity_mode = case % 3 == 2;
        let target = if velocity_mode {
            (2.0 * rng.next() - 1.0) * vel
        } else {
            let d = rng.log_uniform(0.01, 5000.0);
            if rng.next() < 0.5 {
                -d
            } else {
                d
            }
        };
        let (Some(t_hi), Some(t_lo)) = (
            ruckig_duration(start, target, velocity_mode, &hi),
            ruckig_duration(start, target, velocity_mode, &lo),
        ) else {
            continue;
        };
        let ours = if velocity_mode {
            plan_velocity(start, target, &lim)
        } else {
            plan_position(start, target, &lim)
        }
        .unwrap()
        .duration();
        let tol = (1e-6f64).max(1e-4 * t_lo);
        assert!(
            ours >= t_hi - tol && ours <= t_lo + tol,
            "case {case}: {start:?} -> {target} {lim:?}: ours {ours} not in [{t_hi}, {t_lo}]"
        );
        compared += 1;
        if ours < t_lo - tol {
            improved += 1;
        }
    }
    assert!(compared > 19_000, "only {compared} cases compared");
    assert!(
        improved > 1000,
        "only {improved} cases used the larger bound"
    );
}
