//! Property tests of the 1-DoF trajectory generator: limits, continuity across re-plans, exact
//! end state; and a cross-check of durations against `rsruckig` (a port of ruckig).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use tandem_motion::kinematics::profile::{plan_position, plan_velocity, Limits, Profile, State};

/// Samples a profile densely (and at every segment boundary) and checks the limits and the
/// continuity of p, v and a between samples.
fn check_profile(p: &Profile, start: State, lim: &Limits, end_pos: Option<f64>) {
    let trap = lim.jerk == 0.0;
    let tol = 1e-9;
    let mut prev = p.at(0.0);
    assert!(
        (prev.p - start.p).abs() <= tol * (1.0 + start.p.abs()),
        "start p"
    );
    assert!((prev.v - start.v).abs() <= tol * (1.0 + lim.vel), "start v");
    if !trap {
        assert!(
            (prev.a - start.a).abs() <= tol * (1.0 + lim.acc.max(lim.dec)),
            "start a"
        );
    }
    let n = 2000;
    let d = p.duration();
    let amax = lim.acc.max(lim.dec);
    for i in 1..=n {
        let t = d * i as f64 / n as f64;
        let s = p.at(t);
        assert!(
            s.v.abs() <= lim.vel.max(start.v.abs()) * (1.0 + tol) + tol,
            "v {} at {t}",
            s.v
        );
        assert!(
            s.a.abs() <= amax.max(start.a.abs()) * (1.0 + tol) + tol,
            "a {} at {t}",
            s.a
        );
        // Siemens semantics: `acc` while |v| grows, `dec` while it shrinks (the generated start
        // states are within both).
        if !trap {
            let bound = if s.v * s.a > 0.0 {
                lim.acc
            } else if s.v * s.a < 0.0 {
                lim.dec
            } else {
                amax
            };
            assert!(
                s.a.abs() <= bound * (1.0 + 1e-9) + 1e-9,
                "a {} at v {} exceeds its bound {bound} at {t} ({lim:?})",
                s.a,
                s.v
            );
        }
        let dt = d / n as f64;
        // Continuity: the position can move at most by |v|max*dt, velocity by |a|max*dt.
        assert!((s.p - prev.p).abs() <= lim.vel.max(start.v.abs()) * dt * (1.0 + 1e-6) + 1e-9);
        assert!((s.v - prev.v).abs() <= amax.max(start.a.abs()) * dt * (1.0 + 1e-6) + 1e-9);
        if !trap {
            assert!((s.a - prev.a).abs() <= lim.jerk * dt * (1.0 + 1e-6) + 1e-9);
        }
        prev = s;
    }
    for seg in p.segments() {
        if !trap {
            assert!(seg.jerk.abs() <= lim.jerk * (1.0 + tol));
        }
    }
    if let Some(target) = end_pos {
        let e = p.at(d);
        let travel = (target - start.p).abs().max(1e-6);
        let just_before = p.at(d * (1.0 - 1e-15));
        assert!(
            (e.p - target).abs() <= 1e-9 * travel,
            "end p {} vs {target}",
            e.p
        );
        assert!(
            (just_before.p - target).abs() <= 1e-9 * travel + 1e-9,
            "landing p"
        );
        assert!(
            just_before.v.abs() <= 1e-6 * lim.vel,
            "landing v {}",
            just_before.v
        );
    }
}

fn limits() -> impl Strategy<Value = Limits> {
    (
        0.5f64..3.3,
        1.0f64..4.3,
        0.0f64..0.7,
        0.0f64..2.3,
        prop::bool::weighted(0.15),
    )
        .prop_map(|(lv, la, ld, lj, trap)| {
            let acc = 10f64.powf(la);
            Limits {
                vel: 10f64.powf(lv),
                acc,
                dec: acc * 10f64.powf(ld - 0.35),
                jerk: if trap { 0.0 } else { acc * 10f64.powf(lj) },
            }
        })
}

fn start_within(lim: Limits) -> impl Strategy<Value = (Limits, State)> {
    (0.0f64..1.0, 0.0f64..1.0, -1000.0f64..1000.0).prop_map(move |(fv, fa, p)| {
        if lim.jerk == 0.0 {
            return (
                lim,
                State {
                    p,
                    v: (2.0 * fv - 1.0) * lim.vel,
                    a: 0.0,
                },
            );
        }
        let mut a = (2.0 * fa - 1.0) * lim.acc.min(lim.dec);
        let mut shift = a * a.abs() / (2.0 * lim.jerk);
        if shift.abs() > lim.vel {
            a = a.signum() * (2.0 * lim.jerk * lim.vel).sqrt();
            shift = a * a.abs() / (2.0 * lim.jerk);
        }
        let lo = (-lim.vel).max(-lim.vel - shift);
        let hi = lim.vel.min(lim.vel - shift);
        (
            lim,
            State {
                p,
                v: lo + fv * (hi - lo),
                a,
            },
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, failure_persistence: None, rng_seed: proptest::test_runner::RngSeed::Fixed(0x7a4d_e001), ..ProptestConfig::default() })]

    #[test]
    fn position_profiles_respect_limits_and_land(
        (lim, start) in limits().prop_flat_map(start_within),
        dist in -3.0f64..3.7, sign in prop::bool::ANY,
    ) {
        let target = start.p + if sign { 1.0 } else { -1.0 } * 10f64.powf(dist);
        let p = plan_position(start, target, &lim).unwrap();
        check_profile(&p, start, &lim, Some(target));
    }

    #[test]
    fn velocity_profiles_respect_limits(
        (lim, start) in limits().prop_flat_map(start_within),
        fv in -1.0f64..1.0,
    ) {
        let vt = fv * lim.vel;
        let p = plan_velocity(start, vt, &lim).unwrap();
        check_profile(&p, start, &lim, None);
        prop_assert!((p.at(p.duration()).v - vt).abs() <= 1e-9 * lim.vel);
    }

    /// Re-plans at random times to random targets: the state never jumps at a re-plan.
    #[test]
    fn replans_are_continuous(
        lim in limits(),
        targets in prop::collection::vec((-2000.0f64..2000.0, 0.0f64..1.0), 1..6),
    ) {
        let mut state = State::rest(0.0);
        let mut p = plan_position(state, targets[0].0, &lim).unwrap();
        for &(target, frac) in &targets[1..] {
            let t = p.duration() * frac;
            state = p.at(t);
            let before = state;
            p = plan_position(state, target, &lim).unwrap();
            let after = p.at(0.0);
            prop_assert!((after.p - before.p).abs() <= 1e-9 * (1.0 + before.p.abs()));
            prop_assert!((after.v - before.v).abs() <= 1e-9 * (1.0 + lim.vel));
            if lim.jerk > 0.0 {
                prop_assert!((after.a - before.a).abs() <= 1e-9 * (1.0 + lim.acc));
            }
            check_profile(&p, state, &lim, Some(target));
        }
    }
}
