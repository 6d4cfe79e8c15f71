//! `SwitchingAhead`: an output cam stepped with the motion predicted over its look-ahead
//! reports, for motion of constant velocity or constant acceleration, edges at exactly the
//! time the position crosses the cam (less its compensation), one look-ahead after the cycle
//! that computed them; consecutive predicted motions join; with no extrapolation the
//! prediction is the cycle shifted in time.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_motion::kinematics::cycle_motion::AxisMotion;
use tandem_motion::kinematics::profile::State;
use tandem_motion::objects::output_cam::{
    CamDirection, CamEdges, McOutputCam, OutputCam, OutputCamConfig, OutputCamParameters,
    OutputCamType, PositionType, SwitchingAhead,
};

use proptest::prelude::*;
use proptest::test_runner::RngSeed;

const T: i64 = 1_000_000;

/// A parabola: `p0 + v0 t + a t² / 2` at `t` (s).
fn parabola(p0: f64, v0: f64, a: f64, t: f64) -> State {
    State {
        p: p0 + v0 * t + 0.5 * a * t * t,
        v: v0 + a * t,
        a,
    }
}

/// The cycle `[t0, t0 + T]` of the parabola.
fn cycle(k: i64, (p0, v0, a): (f64, f64, f64)) -> AxisMotion {
    let (t0, t1) = (k * T, (k + 1) * T);
    AxisMotion::new(
        t0,
        t1,
        parabola(p0, v0, a, t0 as f64 * 1e-9),
        parabola(p0, v0, a, t1 as f64 * 1e-9),
    )
}

/// The exact time (ns) the parabola reaches `x` moving forward.
fn crossing((p0, v0, a): (f64, f64, f64), x: f64) -> f64 {
    let t = if a == 0.0 {
        (x - p0) / v0
    } else {
        (-v0 + (v0 * v0 + 2.0 * a * (x - p0)).sqrt()) / a
    };
    t * 1e9
}

#[test]
fn predicted_motions_join_and_match_the_parabola() {
    let law = (2.0, 30.0, 400.0);
    for ahead in [
        SwitchingAhead::new(PositionType::Actual, 5 * T, 2 * T),
        SwitchingAhead::new(PositionType::Setpoint, 5 * T, 2 * T),
    ] {
        let mut prev: Option<AxisMotion> = None;
        for k in 0..50 {
            let p = ahead.predict(&cycle(k, law));
            assert_eq!(p.t0_ns, k * T + ahead.horizon_ns);
            let dt = ahead.extrapolation_ns as f64 * 1e-9;
            let want = parabola(law.0, law.1, law.2, (k + 1) as f64 * 1e-3 + dt);
            assert!((p.end.p - want.p).abs() < 1e-12 && (p.end.v - want.v).abs() < 1e-12);
            if let Some(q) = prev {
                assert_eq!((q.t1_ns, q.end), (p.t0_ns, p.start), "the motions join");
            }
            prev = Some(p);
        }
    }
    // A setpoint cam without compensation: the cycle itself, shifted by the delay.
    let a = SwitchingAhead::new(PositionType::Setpoint, 2 * T, 2 * T);
    assert_eq!(a.extrapolation_ns, 0);
    let m = cycle(7, law);
    let p = a.predict(&m);
    assert_eq!(
        (p.t0_ns, p.t1_ns, p.start, p.end),
        (m.t0_ns + 2 * T, m.t1_ns + 2 * T, m.start, m.end)
    );
    // A setpoint delay longer than the look-ahead: the setpoint cam waits for it.
    assert_eq!(
        SwitchingAhead::new(PositionType::Setpoint, 2 * T, 3 * T),
        SwitchingAhead {
            horizon_ns: 3 * T,
            extrapolation_ns: 0
        }
    );
}

#[test]
fn an_actual_value_cam_reports_the_exact_crossing_less_its_compensation() {
    // Constant velocity, then constant acceleration (each from rest at its own time origin).
    for law in [(0.0, 250.0, 0.0), (0.0, 20.0, 900.0)] {
        let mut config = OutputCamConfig::new(OutputCamType::Distance);
        config.position_type = PositionType::Actual;
        config.parameters = OutputCamParameters {
            on_compensation: 0.0023,
            off_compensation: 0.0007,
            hysteresis: 0.0,
        };
        let mut cam = OutputCam::new(config).unwrap();
        let input = McOutputCam::distance(40.0, 95.0).with_direction(CamDirection::Both);
        cam.call(1, &input);
        let ahead = SwitchingAhead::new(PositionType::Actual, 5 * T, 2 * T);
        let mut edges = CamEdges::default();
        let mut seen = Vec::new();
        for k in 0..1000 {
            cam.step(&ahead.predict(&cycle(k, law)), &mut edges);
            for e in edges.as_slice() {
                // Computed at least one cycle ahead of the boundary that writes it.
                assert!(e.time_ns >= (k + 2) * T, "{e:?} at step {k}");
                seen.push(*e);
            }
        }
        // The first edge is the enable (off at the start); then on at 40, off at 95.
        let on = seen.iter().find(|e| e.on).unwrap();
        let off = seen.iter().rfind(|e| !e.on).unwrap();
        let want_on = crossing(law, 40.0) - 2.3e6;
        let want_off = crossing(law, 95.0) - 0.7e6;
        assert!(
            (on.time_ns as f64 - want_on).abs() <= 1.0,
            "{on:?} {want_on}"
        );
        assert!(
            (off.time_ns as f64 - want_off).abs() <= 1.0,
            "{off:?} {want_off}"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 200,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(0x5a_0011),
        ..ProptestConfig::default()
    })]

    /// Any constant-acceleration motion moving forward, any cam, any compensations, any
    /// look-ahead: both edges at the exact crossing less their compensation (1 ns), each
    /// reported at least one cycle after the boundary after its step.
    #[test]
    fn edges_are_the_exact_crossings_less_the_compensations(
        v0 in 5.0f64..500.0,
        a in 0.0f64..2000.0,
        on in 1.0f64..50.0,
        len in 0.5f64..50.0,
        on_comp in 0.0f64..0.006,
        off_comp in 0.0f64..0.006,
        setpoint in any::<bool>(),
    ) {
        // Before the cam for the first 30 ms (longer than any look-ahead here).
        let law = (-1.0 - v0 * 0.03 - 0.5 * a * 0.03 * 0.03, v0, a);
        let position_type = if setpoint { PositionType::Setpoint } else { PositionType::Actual };
        let mut config = OutputCamConfig::new(OutputCamType::Distance);
        config.position_type = position_type;
        config.parameters = OutputCamParameters {
            on_compensation: on_comp,
            off_compensation: off_comp,
            hysteresis: 0.0,
        };
        let mut cam = OutputCam::new(config).unwrap();
        cam.call(1, &McOutputCam::distance(on, on + len).with_direction(CamDirection::Both));
        // Λ = (2 + ceil(c / T)) · T, the setpoint 2 cycles behind the load.
        let c_ns = (on_comp.max(off_comp) * 1e9).ceil() as i64;
        let lambda = 2 * T + (c_ns + T - 1) / T * T;
        let ahead = SwitchingAhead::new(position_type, lambda, 2 * T);
        let delay = ahead.horizon_ns - ahead.extrapolation_ns;
        let mut edges = CamEdges::default();
        let mut seen = Vec::new();
        let end_ns = crossing(law, on + len) as i64 + 20 * T;
        for k in 0..end_ns / T {
            cam.step(&ahead.predict(&cycle(k, law)), &mut edges);
            for e in edges.as_slice() {
                prop_assert!(e.time_ns >= (k + 2) * T, "{:?} at step {}", e, k);
                seen.push(*e);
            }
        }
        let on_edge = seen.iter().find(|e| e.on).unwrap();
        let off_edge = seen.iter().rfind(|e| !e.on).unwrap();
        // The position the edge switches on: the setpoint reaches the load `delay` later.
        let want_on = crossing(law, on) + delay as f64 - on_comp * 1e9;
        let want_off = crossing(law, on + len) + delay as f64 - off_comp * 1e9;
        // An edge is never before its predecessor (a lead longer than the cam: a zero pulse).
        let want_off = want_off.max(on_edge.time_ns as f64);
        prop_assert!((on_edge.time_ns as f64 - want_on).abs() <= 1.0, "{:?} {}", on_edge, want_on);
        prop_assert!((off_edge.time_ns as f64 - want_off).abs() <= 1.0, "{:?} {}", off_edge, want_off);
    }
}
