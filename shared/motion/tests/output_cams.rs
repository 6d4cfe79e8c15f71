//! Output cam TO and MC_OutputCam: the known-answer cases AT-OC-* built from the examples and rules
//! of the S7-1500T Measuring input and cam functions V5.0 function manual, named after their ids,
//! and property tests of the edge times against exact crossings of the profile.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use tandem_motion::catalog::alarm::AlarmId;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::cycle_motion::AxisMotion;
use tandem_motion::kinematics::modulo::Modulo;
use tandem_motion::kinematics::profile::{plan_position, plan_velocity, Limits, Profile, State};
use tandem_motion::objects::output_cam::{
    combine, max_hysteresis, CamDirection, CamEdges, Edge, LogicOperation, McOutputCam, OutputCam,
    OutputCamConfig, OutputCamMode, OutputCamParameters, OutputCamType, PositionType,
};
use tandem_testkit::strategies::limits;

const MS: i64 = 1_000_000;

/// A trajectory made of profiles that each start at a cycle boundary.
struct Sim {
    segs: Vec<(i64, Profile)>,
    modulo: Option<Modulo>,
    jumps: Vec<(i64, f64)>,
}

impl Sim {
    fn at_rest(p: f64) -> Self {
        Self {
            segs: vec![(0, Profile::hold(State::rest(p)))],
            modulo: None,
            jumps: Vec::new(),
        }
    }

    /// Constant velocity `v` (units/s) from `p` at t = 0.
    fn constant(p: f64, v: f64) -> Self {
        Self {
            segs: vec![(0, Profile::hold(State { p, v, a: 0.0 }))],
            modulo: None,
            jumps: Vec::new(),
        }
    }

    fn modulo(mut self, length: f64) -> Self {
        self.modulo = Some(Modulo { start: 0.0, length });
        self
    }

    fn seg(&self, t_ns: i64) -> &(i64, Profile) {
        self.segs.iter().rev().find(|s| s.0 <= t_ns).unwrap()
    }

    fn state(&self, t_ns: i64) -> State {
        let (t0, p) = self.seg(t_ns);
        p.at((t_ns - t0) as f64 * 1e-9)
    }

    fn p(&self, t_s: f64) -> f64 {
        let t_ns = (t_s * 1e9).floor() as i64;
        let (t0, p) = self.seg(t_ns);
        p.at(t_s - *t0 as f64 * 1e-9).p
    }

    /// From `at_ns` on, constant velocity `v` (units/s).
    fn velocity(mut self, at_ns: i64, v: f64) -> Self {
        let s = self.state(at_ns);
        self.segs
            .push((at_ns, Profile::hold(State { p: s.p, v, a: 0.0 })));
        self
    }

    /// From `at_ns` on, a jerk-limited move to `target`.
    fn move_to(mut self, at_ns: i64, target: f64, lim: &Limits) -> Self {
        let s = self.state(at_ns);
        self.segs
            .push((at_ns, plan_position(s, target, lim).unwrap()));
        self
    }

    /// From `at_ns` on, a jerk-limited change to velocity `v`.
    fn ramp_velocity(mut self, at_ns: i64, v: f64, lim: &Limits) -> Self {
        let s = self.state(at_ns);
        self.segs.push((at_ns, plan_velocity(s, v, lim).unwrap()));
        self
    }

    /// At `at_ns` the position jumps to `p` (homing), at rest.
    fn jump(mut self, at_ns: i64, p: f64) -> Self {
        let old = self.state(at_ns).p;
        self.segs.push((at_ns, Profile::hold(State::rest(p))));
        self.jumps.push((at_ns, p - old));
        self
    }

    fn motion(&self, k: i64) -> AxisMotion {
        let (t0, t1) = (k * MS, (k + 1) * MS);
        let (ts, p) = self.seg(t0);
        let mut m = AxisMotion::from_profile(p, *ts, t0, t1).with_modulo(self.modulo);
        if let Some(&(_, d)) = self.jumps.iter().find(|j| j.0 == t0) {
            m = m.with_jump(d);
        }
        m
    }
}

fn lim() -> Limits {
    Limits {
        vel: 200.0,
        acc: 2000.0,
        dec: 2000.0,
        jerk: 100_000.0,
    }
}

fn cam(cam_type: OutputCamType) -> OutputCam {
    OutputCam::new(OutputCamConfig::new(cam_type)).unwrap()
}

/// Steps cycles `k0..k1`, calling the FB with `input` first each cycle; returns the edges.
fn run(c: &mut OutputCam, sim: &Sim, input: &McOutputCam, k0: i64, k1: i64) -> Vec<Edge> {
    let mut all = Vec::new();
    let mut edges = CamEdges::default();
    for k in k0..k1 {
        let fb = c.call(1, input);
        assert!(
            !fb.error || fb.error_id == ErrorId::TechnologyAlarm,
            "{fb:?}"
        );
        c.step(&sim.motion(k), &mut edges);
        all.extend_from_slice(edges.as_slice());
    }
    all
}

fn on(t: i64) -> Edge {
    Edge {
        time_ns: t,
        on: true,
        cam: 0,
    }
}

fn off(t: i64) -> Edge {
    Edge {
        time_ns: t,
        on: false,
        cam: 0,
    }
}

#[test]
fn at_oc_1_modulo_mapping_turns_80_220_into_30_20() {
    // Modulo 0..50, distance cam 80/220 -> 30/20: positive sweep 0 -> 150 at 10 units/ms.
    let sim = Sim::constant(0.0, 10_000.0).modulo(50.0);
    let mut c = cam(OutputCamType::Distance);
    let edges = run(&mut c, &sim, &McOutputCam::distance(80.0, 220.0), 0, 15);
    // ON at [0, 20], [30, 70], [80, 120], [130, 150]; OFF in (20, 30), (70, 80), (120, 130).
    assert_eq!(
        edges,
        vec![
            on(0),
            off(2 * MS),
            on(3 * MS),
            off(7 * MS),
            on(8 * MS),
            off(12 * MS),
            on(13 * MS)
        ]
    );
    assert!(c.status().cam_output);
}

#[test]
fn at_oc_2_time_cams_on_a_modulo_axis_switch_at_20_30_30() {
    // Modulo 0..50, sweep from 1 at 1 unit/ms: 20 is reached at 19 ms, 30 at 29 ms.
    let sim = Sim::constant(1.0, 1000.0).modulo(50.0);
    for (start, t_on) in [(20.0, 19 * MS), (30.0, 29 * MS), (80.0, 29 * MS)] {
        let mut c = cam(OutputCamType::Time);
        let edges = run(&mut c, &sim, &McOutputCam::time(start, 1e-3), 0, 35);
        assert_eq!(edges.len(), 2, "start {start}");
        assert_eq!(edges[0], on(t_on), "start {start}");
        assert_eq!(edges[1], off(t_on + MS), "start {start}");
    }
}

#[test]
fn at_oc_3_linear_start_after_end_is_on_towards_both_range_ends() {
    // Limits +-1000, On = 500, Off = -500: ON in [500, 1000] and [-1000, -500].
    let sim = Sim::constant(-1000.0, 100_000.0); // 100 units/ms
    let mut c = cam(OutputCamType::Distance);
    let input = McOutputCam::distance(500.0, -500.0).with_direction(CamDirection::Both);
    let edges = run(&mut c, &sim, &input, 0, 20);
    assert_eq!(edges, vec![on(0), off(5 * MS), on(15 * MS)]);
}

#[test]
fn at_oc_4_direction_1_distance_cam() {
    let input = McOutputCam::distance(100.0, 200.0);
    // Positive move 0 -> 300: ON at 100, OFF at 200.
    let sim = Sim::at_rest(0.0).move_to(0, 300.0, &lim());
    let mut c = cam(OutputCamType::Distance);
    let edges = run(&mut c, &sim, &input, 0, 3000);
    assert_eq!(edges.len(), 2);
    assert!(edges[0].on && !edges[1].on);
    assert!((sim.p(edges[0].time_ns as f64 * 1e-9) - 100.0).abs() < 1e-6);
    assert!((sim.p(edges[1].time_ns as f64 * 1e-9) - 200.0).abs() < 1e-6);

    // Move to 150, then reverse (without stopping): OFF at the reversal.
    let sim = Sim::constant(0.0, 100.0).ramp_velocity(1400 * MS, -100.0, &lim());
    let mut c = cam(OutputCamType::Distance);
    let edges = run(&mut c, &sim, &input, 0, 2000);
    assert_eq!(edges.len(), 2, "{edges:?}");
    assert!(edges[0].on && (edges[0].time_ns - 1000 * MS).abs() <= 1);
    // The reversal: v = 0 half way through the symmetric velocity change.
    let (t_rev, p_rev) = zero_velocity(&sim, 1400 * MS, 1600 * MS);
    assert!(!edges[1].on && (edges[1].time_ns as f64 - t_rev * 1e9).abs() <= 1.0);
    assert!(p_rev > 140.0 && p_rev < 150.0);

    // Move to 150 and stop: stays ON; then move back: OFF at the start of the reverse motion.
    let sim = Sim::at_rest(0.0)
        .move_to(0, 150.0, &lim())
        .move_to(2000 * MS, 50.0, &lim());
    let mut c = cam(OutputCamType::Distance);
    let edges = run(&mut c, &sim, &input, 0, 2010);
    assert_eq!(edges.len(), 2);
    assert!(edges[0].on && !edges[1].on);
    assert_eq!(edges[1].time_ns, 2000 * MS);

    // Negative move 300 -> 0: stays OFF.
    let sim = Sim::at_rest(300.0).move_to(0, 0.0, &lim());
    let mut c = cam(OutputCamType::Distance);
    assert!(run(&mut c, &sim, &input, 0, 3000).is_empty());

    // Jump to 150 at standstill: OFF; with Direction 3: ON.
    let sim = Sim::at_rest(0.0).jump(10 * MS, 150.0);
    let mut c = cam(OutputCamType::Distance);
    assert!(run(&mut c, &sim, &input, 0, 20).is_empty());
    let mut c = cam(OutputCamType::Distance);
    let both = input.with_direction(CamDirection::Both);
    assert_eq!(run(&mut c, &sim, &both, 0, 20), vec![on(10 * MS)]);
    // Direction 1, jump into the range, then the axis starts moving positive: ON at the start.
    let sim = Sim::at_rest(0.0)
        .jump(10 * MS, 150.0)
        .move_to(20 * MS, 180.0, &lim());
    let mut c = cam(OutputCamType::Distance);
    assert_eq!(run(&mut c, &sim, &input, 0, 30), vec![on(20 * MS)]);
}

/// Time (s) and position where the velocity crosses zero in `[a, b]` (ns).
fn zero_velocity(sim: &Sim, a: i64, b: i64) -> (f64, f64) {
    let v = |t: f64| {
        let t_ns = (t * 1e9).floor() as i64;
        let (t0, p) = sim.seg(t_ns);
        p.at(t - *t0 as f64 * 1e-9).v
    };
    let (mut lo, mut hi) = (a as f64 * 1e-9, b as f64 * 1e-9);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if v(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo, sim.p(lo))
}

#[test]
fn at_oc_5_time_cam_direction_1() {
    let input = McOutputCam::time(100.0, 10e-3);
    // Positive crossing at 5 ms (90 + 2 units/ms); back over 100 negatively at 7 ms and
    // positively again at 9 ms, inside the 10 ms: no retrigger, OFF at 15 ms.
    let sim = Sim::constant(90.0, 2000.0)
        .velocity(6 * MS, -2000.0)
        .velocity(8 * MS, 2000.0);
    let mut c = cam(OutputCamType::Time);
    let edges = run(&mut c, &sim, &input, 0, 30);
    assert_eq!(edges, vec![on(5 * MS), off(15 * MS)]);

    // Negative crossing: nothing.
    let sim = Sim::constant(110.0, -2000.0);
    let mut c = cam(OutputCamType::Time);
    assert!(run(&mut c, &sim, &input, 0, 30).is_empty());

    // Homing jump 90 -> 110 (then moving on): nothing.
    let sim = Sim::at_rest(90.0)
        .jump(5 * MS, 110.0)
        .velocity(6 * MS, 2000.0);
    let mut c = cam(OutputCamType::Time);
    assert!(run(&mut c, &sim, &input, 0, 30).is_empty());

    // A running time cam survives a homing jump and a reversal.
    let sim = Sim::constant(90.0, 2000.0)
        .jump(7 * MS, 0.0)
        .velocity(8 * MS, -2000.0);
    let mut c = cam(OutputCamType::Time);
    assert_eq!(
        run(&mut c, &sim, &input, 0, 30),
        vec![on(5 * MS), off(15 * MS)]
    );
}

#[test]
fn at_oc_6_time_cam_compensations() {
    // D = 10 ms, OnComp 2 ms, OffComp 1 ms, start reached at t = 100 ms -> ON at 98, OFF at 109.
    let mut cfg = OutputCamConfig::new(OutputCamType::Time);
    cfg.parameters = OutputCamParameters {
        on_compensation: 2e-3,
        off_compensation: 1e-3,
        hysteresis: 0.0,
    };
    let mut c = OutputCam::new(cfg).unwrap();
    let sim = Sim::constant(0.0, 1000.0); // 1 unit/ms: 100 at 100 ms
    let edges = run(&mut c, &sim, &McOutputCam::time(100.0, 10e-3), 0, 130);
    assert_eq!(edges, vec![on(98 * MS), off(109 * MS)]);

    // D = 1 ms, OnComp 2, OffComp 5 violates D > Off - On: alarm 704, output off, FB error.
    cfg.parameters.off_compensation = 5e-3;
    let mut c = OutputCam::new(cfg).unwrap();
    let edges = run(&mut c, &sim, &McOutputCam::time(100.0, 1e-3), 0, 130);
    assert!(edges.is_empty());
    assert_eq!(
        c.status().alarm.map(|a| a.id),
        Some(AlarmId::OutputCamDataFaulty)
    );
    let fb = c.call(1, &McOutputCam::time(100.0, 1e-3));
    assert!(fb.error && fb.busy);
    assert_eq!(fb.error_id, ErrorId::TechnologyAlarm);
}

#[test]
fn at_oc_7_distance_cam_lead_times() {
    // 100..200 at 0.1 units/ms: OnComp 5 ms -> ON where the axis is at 99.5; OffComp 10 ms ->
    // OFF where it is at 199.0.
    let mut cfg = OutputCamConfig::new(OutputCamType::Distance);
    cfg.parameters = OutputCamParameters {
        on_compensation: 5e-3,
        off_compensation: 10e-3,
        hysteresis: 0.0,
    };
    let mut c = OutputCam::new(cfg).unwrap();
    let sim = Sim::constant(0.0, 100.0);
    let edges = run(&mut c, &sim, &McOutputCam::distance(100.0, 200.0), 0, 2100);
    assert_eq!(edges, vec![on(995 * MS), off(1990 * MS)]);
    assert!((sim.p(edges[0].time_ns as f64 * 1e-9) - 99.5).abs() < 1e-9);
    assert!((sim.p(edges[1].time_ns as f64 * 1e-9) - 199.0).abs() < 1e-9);
}

#[test]
fn at_oc_8_maximum_hysteresis() {
    assert_eq!(max_hysteresis(Some(360.0), None), Some(90.0));
    assert_eq!(max_hysteresis(None, Some((-1000.0, 1000.0))), Some(500.0));
    assert_eq!(max_hysteresis(None, None), None);
    let mut cfg = OutputCamConfig::new(OutputCamType::Distance);
    cfg.parameters.hysteresis = 200.0;
    let mut c = OutputCam::new(cfg).unwrap();
    let sim = Sim::at_rest(0.0).modulo(360.0);
    run(&mut c, &sim, &McOutputCam::distance(10.0, 20.0), 0, 2);
    assert_eq!(c.status().hysteresis, 90.0);
    assert!(c.status().hysteresis_limited);
}

#[test]
fn at_oc_9_mode_3_always_on_and_mode_2_inverted() {
    // Mode 3: ON while enabled wherever the axis is.
    let sim = Sim::constant(0.0, 100_000.0);
    let mut c = cam(OutputCamType::Distance);
    let input = McOutputCam::distance(100.0, 200.0).with_mode(OutputCamMode::AlwaysOn);
    assert_eq!(run(&mut c, &sim, &input, 0, 5), vec![on(0)]);
    assert!(c.status().cam_output);
    let disabled = McOutputCam {
        enable: false,
        ..input
    };
    let fb = c.call(1, &disabled);
    assert!(!fb.busy);
    let mut e = CamEdges::default();
    c.step(&sim.motion(5), &mut e);
    assert_eq!(e.as_slice(), &[off(5 * MS)]);

    // Mode 2: inverted (ON outside 100..200), StatusWord.X4.
    let mut c = cam(OutputCamType::Distance);
    let input = McOutputCam::distance(100.0, 200.0).with_mode(OutputCamMode::Inverted);
    let edges = run(&mut c, &sim, &input, 0, 5);
    assert_eq!(edges, vec![on(0), off(MS), on(2 * MS)]);
    assert!(c.status().output_inverted);
}

#[test]
fn at_oc_10_second_instance_and_zero_duration_are_errors() {
    let mut c = cam(OutputCamType::Distance);
    let input = McOutputCam::distance(100.0, 200.0);
    assert!(c.call(1, &input).busy);
    let fb = c.call(2, &input);
    assert!(fb.error && !fb.busy);
    assert_eq!(fb.error_id, ErrorId::OnlyOneInstance);
    // The first instance keeps the cam; after it releases it the second may take it.
    assert!(c.call(1, &input).busy);
    c.call(
        1,
        &McOutputCam {
            enable: false,
            ..input
        },
    );
    assert!(c.call(2, &input).busy);

    let mut c = cam(OutputCamType::Time);
    let fb = c.call(1, &McOutputCam::time(100.0, 0.0));
    assert!(fb.error && !fb.busy);
    assert_eq!(fb.error_id, ErrorId::IllegalDuration);
    let fb = c.call(1, &McOutputCam::time(f64::NAN, 1.0));
    assert_eq!(fb.error_id, ErrorId::IllegalOnPosition);
    let mut c = cam(OutputCamType::Distance);
    let fb = c.call(1, &McOutputCam::distance(0.0, 2e12));
    assert_eq!(fb.error_id, ErrorId::IllegalOffPosition);
    assert_eq!(OutputCamMode::from_code(4), Err(ErrorId::IllegalMode));
    assert_eq!(CamDirection::from_code(0), Err(ErrorId::IllegalDirection));
}

#[test]
fn at_oc_11_setpoint_cam_at_zero_and_no_output_without_position_control() {
    // On = 0: switches where the setpoint crosses 0 (from -5 at 2 units/ms: at 2.5 ms).
    let sim = Sim::constant(-5.0, 2000.0);
    let mut c = cam(OutputCamType::Distance);
    let input = McOutputCam::distance(0.0, 100.0);
    assert_eq!(run(&mut c, &sim, &input, 0, 5), vec![on(2_500_000)]);
    // Not position-controlled (setpoint not valid): off, no alarm; on again when valid.
    let mut e = CamEdges::default();
    c.call(1, &input);
    c.step(&sim.motion(5).with_valid(false), &mut e);
    assert_eq!(e.as_slice(), &[off(5 * MS)]);
    assert_eq!(c.status().alarm, None);
    c.step(&sim.motion(6), &mut e);
    assert_eq!(e.as_slice(), &[on(6 * MS)]);
}

#[test]
fn at_oc_12_time_cam_needs_two_cycles_after_the_enable() {
    // The start (10) is crossed at 2.5 ms (4 units/ms).
    let sim = Sim::constant(0.0, 4000.0);
    let input = McOutputCam::time(10.0, 1e-3);
    // Enabled at cycle 1 (1 ms): the crossing is in the second cycle -> no switching.
    let mut c = cam(OutputCamType::Time);
    assert!(run(&mut c, &sim, &input, 1, 6).is_empty());
    // Enabled at cycle 0: the crossing is in the third cycle -> switches.
    let mut c = cam(OutputCamType::Time);
    assert_eq!(
        run(&mut c, &sim, &input, 0, 6),
        vec![on(2_500_000), off(3_500_000)]
    );
    // The distance cam switches in either case.
    let mut c = cam(OutputCamType::Distance);
    assert_eq!(
        run(&mut c, &sim, &McOutputCam::distance(10.0, 12.0), 2, 6),
        vec![on(2_500_000), off(3_000_000)]
    );
}

#[test]
fn at_oc_13_or_and_after_inversion() {
    // Cam A 100..200 standard, cam B 150..250 inverted, axis 0 -> 300 at 100 units/ms.
    let sim = Sim::constant(0.0, 100_000.0);
    let mut a = cam(OutputCamType::Distance);
    let mut b = cam(OutputCamType::Distance);
    let ia = McOutputCam::distance(100.0, 200.0);
    let ib = McOutputCam::distance(150.0, 250.0).with_mode(OutputCamMode::Inverted);
    let (mut ea, mut eb) = (CamEdges::default(), CamEdges::default());
    let mut or = Vec::new();
    let mut and = Vec::new();
    for k in 0..3 {
        let (sa, sb) = (a.status().cam_output, b.status().cam_output);
        a.call(1, &ia);
        b.call(1, &ib);
        a.step(&sim.motion(k), &mut ea);
        b.step(&sim.motion(k), &mut eb);
        let mut out = CamEdges::default();
        combine(LogicOperation::Or, &[(sa, &ea), (sb, &eb)], &mut out);
        or.extend_from_slice(out.as_slice());
        let mut out = CamEdges::default();
        combine(LogicOperation::And, &[(sa, &ea), (sb, &eb)], &mut out);
        and.extend_from_slice(out.as_slice());
    }
    // A: on [1, 2] ms; B inverted: on [0, 1.5) and (2.5, ..] ms.
    // OR: on from 0 until 2 ms, on again at 2.5 ms. AND: on [1, 1.5] ms.
    let t = |e: &Edge| (e.time_ns, e.on);
    assert_eq!(
        or.iter().map(t).collect::<Vec<_>>(),
        vec![(0, true), (2 * MS, false), (2_500_000, true)]
    );
    assert_eq!(
        and.iter().map(t).collect::<Vec<_>>(),
        vec![(MS, true), (1_500_000, false)]
    );
}

#[test]
fn at_oc_14_hysteresis_suppresses_jitter_and_delays_a_time_cam_to_the_band_exit() {
    // Axis stands at 150 (after positive motion) with +-0.01 jitter, Direction 1 cam 100..200.
    let jitter = |h: f64| {
        let mut sim = Sim::constant(140.0, 10_000.0).velocity(MS, 0.0);
        for k in 2..40 {
            let v = if k % 2 == 0 { 20.0 } else { -20.0 }; // +-0.02 per cycle around 150
            sim = sim.velocity(k * MS, v);
        }
        let mut cfg = OutputCamConfig::new(OutputCamType::Distance);
        cfg.parameters.hysteresis = h;
        let mut c = OutputCam::new(cfg).unwrap();
        run(&mut c, &sim, &McOutputCam::distance(100.0, 200.0), 0, 40)
    };
    let without = jitter(0.0);
    assert!(
        without.len() > 10,
        "toggles without hysteresis: {}",
        without.len()
    );
    assert_eq!(jitter(0.1), vec![on(0)]);

    // Direction 2 time cam at 99.95, H = 0.1: the axis moves up to 100 and reverses; the band
    // [99.9, 100] holds the start, so the cam fires where the axis leaves it (99.9).
    let sim = Sim::constant(99.0, 1000.0).velocity(MS, -100.0); // 1 unit/ms up, then 0.1 down
    let mut cfg = OutputCamConfig::new(OutputCamType::Time);
    cfg.parameters.hysteresis = 0.1;
    cfg.arming_cycles = 0;
    let mut c = OutputCam::new(cfg).unwrap();
    let input = McOutputCam::time(99.95, 5e-3).with_direction(CamDirection::Negative);
    let edges = run(&mut c, &sim, &input, 0, 10);
    // 100 at 1 ms; 99.9 one ms later.
    assert_eq!(edges, vec![on(2 * MS), off(7 * MS)]);
    // Without hysteresis it fires at 99.95.
    let mut cfg = OutputCamConfig::new(OutputCamType::Time);
    cfg.arming_cycles = 0;
    let mut c = OutputCam::new(cfg).unwrap();
    assert_eq!(
        run(&mut c, &sim, &input, 0, 10),
        vec![on(1_500_000), off(6_500_000)]
    );
}

#[test]
fn at_oc_15_resumes_after_reset_without_toggling_enable() {
    let mut cfg = OutputCamConfig::new(OutputCamType::Distance);
    cfg.position_type = PositionType::Actual;
    let mut c = OutputCam::new(cfg).unwrap();
    let sim = Sim::at_rest(150.0);
    let input = McOutputCam::distance(100.0, 200.0).with_direction(CamDirection::Both);
    assert_eq!(run(&mut c, &sim, &input, 0, 2), vec![on(0)]);
    // The actual value becomes invalid: alarm 702, output off.
    let mut e = CamEdges::default();
    c.call(1, &input);
    c.step(&sim.motion(2).with_valid(false), &mut e);
    assert_eq!(e.as_slice(), &[off(2 * MS)]);
    assert_eq!(
        c.status().alarm.map(|a| a.id),
        Some(AlarmId::PositionValueInvalid)
    );
    // Valid again, alarm still pending: off.
    assert!(run(&mut c, &sim, &input, 3, 5).is_empty());
    // MC_Reset: resumes by itself.
    c.reset();
    assert_eq!(run(&mut c, &sim, &input, 5, 7), vec![on(5 * MS)]);
    assert!(!c.call(1, &input).error);
}

#[test]
fn inputs_are_live_while_enabled() {
    let sim = Sim::at_rest(150.0);
    let mut c = cam(OutputCamType::Distance);
    let input = McOutputCam::distance(100.0, 200.0).with_direction(CamDirection::Both);
    assert_eq!(run(&mut c, &sim, &input, 0, 2), vec![on(0)]);
    let moved = McOutputCam::distance(160.0, 200.0).with_direction(CamDirection::Both);
    assert_eq!(run(&mut c, &sim, &moved, 2, 4), vec![off(2 * MS)]);
}

#[test]
fn pathological_motion_stays_bounded() {
    // 1000 units in one cycle on a modulo length of 1e-3: a million periods, cut at the limit.
    let m = Modulo {
        start: 0.0,
        length: 1e-3,
    };
    let a = State {
        p: 0.0,
        v: 1e6,
        a: 0.0,
    };
    let b = State {
        p: 1000.0,
        v: 1e6,
        a: 0.0,
    };
    let mut c = cam(OutputCamType::Distance);
    let mut e = CamEdges::default();
    c.call(1, &McOutputCam::distance(0.0002, 0.0007));
    c.step(&AxisMotion::new(0, MS, a, b).with_modulo(Some(m)), &mut e);
    assert_eq!(e.len(), 16);
    assert!(e.dropped() > 1000);
    // A cycle whose end lies before its start, and non-finite states: no panic, no edge.
    c.step(&AxisMotion::new(MS, 0, a, b), &mut e);
    let nan = State {
        p: f64::NAN,
        v: 0.0,
        a: 0.0,
    };
    c.step(&AxisMotion::new(2 * MS, 3 * MS, nan, nan), &mut e);
    assert!(e.len() <= 1);
}

// ---------------------------------------------------------------------------------------------
// Property tests: edge times against exact crossings
// ---------------------------------------------------------------------------------------------

/// Crossing times (s) of level `c` by the trajectory in `[0, t_end]`, found on a 20 us grid
/// and refined by bisection on `Profile::at`.
fn crossings(sim: &Sim, c: f64, t_end: f64, out: &mut Vec<f64>) {
    let dt = 20e-6;
    let n = (t_end / dt) as i64;
    let mut ta = 0.0;
    let mut fa = sim.p(0.0) - c;
    for i in 1..=n {
        let tb = i as f64 * dt;
        let fb = sim.p(tb) - c;
        if (fa < 0.0) != (fb < 0.0) {
            let (mut lo, mut hi, flo) = (ta, tb, fa);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if ((sim.p(mid) - c) < 0.0) == (flo < 0.0) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            out.push(0.5 * (lo + hi));
        }
        ta = tb;
        fa = fb;
    }
}

/// Two jerk-limited moves (there and back), sampled at 1 ms, and the distance cam
/// `[lo, hi]` (Direction 3, or modulo with wrap): the cam's edges equal the exact crossings
/// (minus the compensation, never going back in time) within 1 ns.
fn check_edges(
    sim: &Sim,
    cycles: i64,
    on_pos: f64,
    off_pos: f64,
    levels: &[f64],
    on_comp: f64,
    off_comp: f64,
) -> Result<(), TestCaseError> {
    let mut cfg = OutputCamConfig::new(OutputCamType::Distance);
    cfg.parameters.on_compensation = on_comp;
    cfg.parameters.off_compensation = off_comp;
    let mut c = OutputCam::new(cfg).unwrap();
    let input = McOutputCam::distance(on_pos, off_pos).with_direction(CamDirection::Both);
    let edges = run(&mut c, sim, &input, 0, cycles);
    let t_end = cycles as f64 * 1e-3;
    let mut times = Vec::new();
    for &l in levels {
        crossings(sim, l, t_end, &mut times);
    }
    times.sort_by(f64::total_cmp);
    // Initial state at t = 0 (at rest inside: ON with Direction 3).
    let set_contains = |x: f64| match sim.modulo {
        Some(m) => {
            let (a, b) = (m.wrap(on_pos), m.wrap(off_pos));
            let w = m.wrap(x);
            if a <= b {
                w >= a && w <= b
            } else {
                w >= a || w <= b
            }
        }
        None => x >= on_pos && x <= off_pos,
    };
    let mut state = set_contains(sim.p(0.0));
    let mut expected: Vec<(f64, bool)> = Vec::new();
    if state {
        expected.push((0.0, true));
    }
    let mut last = f64::NEG_INFINITY;
    for t in times {
        state = !state;
        let comp = if state { on_comp } else { off_comp };
        let te = ((t - comp) * 1e9).max(last);
        last = te;
        expected.push((te, state));
    }
    prop_assert!(expected.len() >= 2);
    prop_assert_eq!(
        edges.len(),
        expected.len(),
        "edges {:?} expected {:?}",
        edges,
        expected
    );
    for (e, (t, s)) in edges.iter().zip(&expected) {
        prop_assert_eq!(e.on, *s);
        prop_assert!(
            (e.time_ns as f64 - t).abs() <= 1.0,
            "edge {:?} vs exact {} ns",
            e,
            t
        );
    }
    Ok(())
}

/// A move from rest at 0 to `d1`, a pause, and a move to `d1 + d2`.
fn there_and_back(d1: f64, d2: f64, lim: &Limits) -> (Sim, i64) {
    let first = plan_position(State::rest(0.0), d1, lim).unwrap();
    let kb = (first.duration() * 1e3) as i64 + 3;
    let sim = Sim::at_rest(0.0)
        .move_to(0, d1, lim)
        .move_to(kb * MS, d1 + d2, lim);
    let second = plan_position(State::rest(d1), d1 + d2, lim).unwrap();
    (sim, kb + (second.duration() * 1e3) as i64 + 3)
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 48,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(0x0c_0003),
        ..ProptestConfig::default()
    })]

    #[test]
    fn distance_cam_edges_are_exact_crossings(
        lim in limits(),
        d1 in 20.0f64..200.0,
        back in 0.2f64..1.5,
        a in 0.1f64..0.9,
        b in 0.1f64..0.9,
        on_comp in 0.0f64..2e-3,
        off_frac in 0.0f64..1.0,
    ) {
        let d2 = -back * d1;
        let (sim, cycles) = there_and_back(d1, d2, &lim);
        // Levels inside the range both moves cover, away from the rest positions.
        let lo_r = (d1 + d2).max(0.0);
        let span = d1 - lo_r;
        let (x, y) = (lo_r + a * span, lo_r + b * span);
        prop_assume!((x - y).abs() > 0.01 * span);
        let (on_pos, off_pos) = (x.min(y), x.max(y));
        check_edges(&sim, cycles, on_pos, off_pos, &[on_pos, off_pos], on_comp, on_comp * off_frac)?;
    }

    /// The boundaries are placed where the profile switches its jerk (within +-0.5 ms), so the
    /// crossings fall into cycles whose motion is not one polynomial.
    #[test]
    fn edges_at_jerk_switches_are_exact(
        lim in limits(),
        d1 in 20.0f64..200.0,
        i in 0usize..16,
        j in 0usize..16,
        di in -0.5e-3f64..0.5e-3,
        dj in -0.5e-3f64..0.5e-3,
        on_comp in 0.0f64..1e-3,
    ) {
        let (sim, cycles) = there_and_back(d1, -1.2 * d1, &lim);
        let first = plan_position(State::rest(0.0), d1, &lim).unwrap();
        let segs = first.segments();
        let at = |k: usize, d: f64| first.at(segs[k % segs.len()].t0 + d).p;
        let (x, y) = (at(i, di), at(j, dj));
        let margin = 0.02 * d1;
        prop_assume!(x > margin && x < d1 - margin && y > margin && y < d1 - margin);
        prop_assume!((x - y).abs() > 0.01 * d1);
        let (on_pos, off_pos) = (x.min(y), x.max(y));
        check_edges(&sim, cycles, on_pos, off_pos, &[on_pos, off_pos], on_comp, 0.5 * on_comp)?;
    }

    #[test]
    fn modulo_distance_cam_edges_are_exact_crossings(
        lim in limits(),
        d1 in 100.0f64..300.0,
        back in 0.2f64..1.5,
        length in 17.0f64..60.0,
        a in 0.0f64..1.0,
        b in 0.0f64..1.0,
    ) {
        let d2 = -back * d1;
        let (mut sim, cycles) = there_and_back(d1, d2, &lim);
        sim.modulo = Some(Modulo { start: 0.0, length });
        let (on_pos, off_pos) = (a * length, b * length);
        prop_assume!((on_pos - off_pos).abs() > 0.5);
        // Every representation of the boundaries inside the travelled range.
        let (min, max) = ((d1 + d2).min(0.0), d1);
        let mut levels = Vec::new();
        for base in [on_pos, off_pos] {
            let mut k = ((min - base) / length).floor() as i64;
            while base + k as f64 * length <= max + length {
                let l = base + k as f64 * length;
                // Not at a rest position (the axis would sit on the boundary).
                prop_assume!([0.0, d1, d1 + d2].iter().all(|r| (l - r).abs() > 1e-3));
                levels.push(l);
                k += 1;
            }
        }
        check_edges(&sim, cycles, on_pos, off_pos, &levels, 0.0, 0.0)?;
    }
}
