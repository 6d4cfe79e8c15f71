//! Cam track TO and MC_CamTrack: the known-answer cases AT-CT-* built from the examples and rules
//! of the S7-1500T Measuring input and cam functions V5.0 function manual, named after their ids,
//! and a property test of the track output against exact crossings.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use tandem_motion::catalog::alarm::AlarmId;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::cycle_motion::AxisMotion;
use tandem_motion::kinematics::modulo::Modulo;
use tandem_motion::kinematics::profile::{plan_position, Limits, Profile, State};
use tandem_motion::objects::cam_track::{
    match_on_enable, next_reference_position, CamTrack, CamTrackConfig, CamTrackData, CamTrackMode,
    CamTrackState, CamTrackType, McCamTrack, TrackCam, TrackOutputInterface,
};
use tandem_motion::objects::output_cam::{CamEdges, Edge};
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

    /// Constant velocity `v` (units/ms) from `p` at t = 0.
    fn constant(p: f64, v_per_ms: f64) -> Self {
        Self {
            segs: vec![(
                0,
                Profile::hold(State {
                    p,
                    v: v_per_ms * 1000.0,
                    a: 0.0,
                }),
            )],
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

    fn velocity(mut self, at_ns: i64, v_per_ms: f64) -> Self {
        let s = self.state(at_ns);
        self.segs.push((
            at_ns,
            Profile::hold(State {
                p: s.p,
                v: v_per_ms * 1000.0,
                a: 0.0,
            }),
        ));
        self
    }

    fn move_to(mut self, at_ns: i64, target: f64, lim: &Limits) -> Self {
        let s = self.state(at_ns);
        self.segs
            .push((at_ns, plan_position(s, target, lim).unwrap()));
        self
    }

    /// At `at_ns` the position jumps to `p` (continuous), at rest.
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

fn track(kind: CamTrackType, data: CamTrackData) -> CamTrack {
    CamTrack::new(CamTrackConfig::new(kind), data).unwrap()
}

/// Steps cycles `k0..k1`, calling the FB with `input` first each cycle; returns the edges.
fn run(t: &mut CamTrack, sim: &Sim, input: &McCamTrack, k0: i64, k1: i64) -> Vec<Edge> {
    let mut all = Vec::new();
    let mut edges = CamEdges::default();
    for k in k0..k1 {
        t.call(1, input);
        t.step(&sim.motion(k), &mut edges);
        all.extend_from_slice(edges.as_slice());
    }
    all
}

/// Steps without FB calls.
fn steps(t: &mut CamTrack, sim: &Sim, k0: i64, k1: i64) -> Vec<Edge> {
    let mut all = Vec::new();
    let mut edges = CamEdges::default();
    for k in k0..k1 {
        t.step(&sim.motion(k), &mut edges);
        all.extend_from_slice(edges.as_slice());
    }
    all
}

/// (time ns, on) of the edges.
fn tv(edges: &[Edge]) -> Vec<(i64, bool)> {
    edges.iter().map(|e| (e.time_ns, e.on)).collect()
}

/// On/off pairs as positions, for an axis at constant velocity `v` units/ms from `p0`.
fn positions(edges: &[Edge], p0: f64, v: f64) -> Vec<(f64, bool)> {
    edges
        .iter()
        .map(|e| (p0 + v * e.time_ns as f64 / MS as f64, e.on))
        .collect()
}

fn assert_positions(got: &[(f64, bool)], want: &[(f64, bool)]) {
    assert_eq!(got.len(), want.len(), "{got:?} vs {want:?}");
    for (g, w) in got.iter().zip(want) {
        assert!(
            (g.0 - w.0).abs() < 1e-9 && g.1 == w.1,
            "{got:?} vs {want:?}"
        );
    }
}

const MODE1: McCamTrack = McCamTrack::enabled(CamTrackMode::EndOfCycle);
const MODE0: McCamTrack = McCamTrack::enabled(CamTrackMode::Immediate);

#[test]
fn at_ct_1_reference_position_places_the_track() {
    // Axis -1000..1000, length 2000, cam 800..900, Ref -1000 -> ON at -200..-100.
    let data = CamTrackData::new(-1000.0, 2000.0).with_cam(0, TrackCam::distance(800.0, 900.0));
    let mut t = track(CamTrackType::Distance, data);
    let sim = Sim::constant(-1000.0, 100.0);
    let e = run(&mut t, &sim, &MODE1, 0, 20);
    assert_positions(
        &positions(&e, -1000.0, 100.0),
        &[(-200.0, true), (-100.0, false)],
    );
}

fn ct2_data() -> CamTrackData {
    CamTrackData::new(20.0, 100.0)
        .with_cam(0, TrackCam::distance(10.0, 20.0))
        .with_cam(
            1,
            TrackCam {
                existent: false,
                ..TrackCam::distance(30.0, 50.0)
            },
        )
        .with_cam(2, TrackCam::distance(60.0, 90.0))
}

#[test]
fn at_ct_2_function_chart_example() {
    let want = [
        (-70.0, true),
        (-60.0, false),
        (-20.0, true),
        (10.0, false),
        (30.0, true),
        (40.0, false),
        (80.0, true),
        (110.0, false),
        (130.0, true),
        (140.0, false),
        (180.0, true),
        (210.0, false),
    ];
    // Positive sweep -80 -> 220.
    let mut t = track(CamTrackType::Distance, ct2_data());
    let sim = Sim::constant(-80.0, 10.0);
    let e = run(&mut t, &sim, &MODE1, 0, 30);
    assert_positions(&positions(&e, -80.0, 10.0), &want);
    // Negative sweep 220 -> -80: the same positions, in reverse order.
    let mut t = track(CamTrackType::Distance, ct2_data());
    let sim = Sim::constant(220.0, -10.0);
    let e = run(&mut t, &sim, &MODE1, 0, 30);
    let rev: Vec<(f64, bool)> = want.iter().rev().map(|&(x, on)| (x, !on)).collect();
    assert_positions(&positions(&e, 220.0, -10.0), &rev);
    // Cam 2's span (50..70 on the axis) is never on.
    assert!(e.iter().all(|e| e.cam != 1));

    // Axis 135 -> Match 120, TrackPos 15, SingleCamState 16#1; axis 95 -> 20, 75, 16#4.
    for (x, m, tp, bits) in [(135.0, 120.0, 15.0, 0x1), (95.0, 20.0, 75.0, 0x4)] {
        let mut t = track(CamTrackType::Distance, ct2_data());
        run(&mut t, &Sim::at_rest(x), &MODE1, 0, 1);
        let s = t.status();
        assert_eq!(
            (s.match_position, s.track_position, s.single_cam_state),
            (m, tp, bits)
        );
        assert!(s.track_output);
        assert_eq!(s.state, CamTrackState::Active);
    }
}

#[test]
fn at_ct_3_modulo_track_lengths() {
    // Modulo 360, length 120: three track cycles per revolution, aligned.
    let mut t = track(CamTrackType::Distance, CamTrackData::new(0.0, 120.0));
    let sim = Sim::constant(0.0, 10.0).modulo(360.0);
    let mut starts = Vec::new();
    let mut edges = CamEdges::default();
    let mut last = f64::NAN;
    for k in 0..73 {
        t.call(1, &MODE1);
        t.step(&sim.motion(k), &mut edges);
        let m = t.status().match_position;
        if m != last {
            starts.push(m);
            last = m;
        }
    }
    assert_eq!(starts, vec![0.0, 120.0, 240.0, 0.0, 120.0, 240.0, 0.0]);

    // Length 160: starts at 0, 160, 320, then 120 and 280 in the second revolution; aligned
    // again after 4 revolutions (1440 = 9 x 160).
    let mut t = track(CamTrackType::Distance, CamTrackData::new(0.0, 160.0));
    let mut starts = Vec::new();
    let mut last = f64::NAN;
    for k in 0..150 {
        t.call(1, &MODE1);
        t.step(&sim.motion(k), &mut edges);
        let m = t.status().match_position;
        if m != last {
            starts.push(m);
            last = m;
        }
    }
    assert_eq!(
        starts,
        vec![0.0, 160.0, 320.0, 120.0, 280.0, 80.0, 240.0, 40.0, 200.0, 0.0]
    );
}

#[test]
fn at_ct_4_match_position_on_enable() {
    let m360 = Some(Modulo {
        start: 0.0,
        length: 360.0,
    });
    assert_eq!(match_on_enable(350.0, 0.0, 160.0, m360), (320.0, 30.0));
    assert_eq!(match_on_enable(100.0, 0.0, 160.0, m360), (0.0, 100.0));
    assert_eq!(match_on_enable(-50.0, 20.0, 100.0, None), (-80.0, 30.0));
    // In the object, enabled at 350 (+ two revolutions, continuous 1070).
    let mut t = track(CamTrackType::Distance, CamTrackData::new(0.0, 160.0));
    run(&mut t, &Sim::at_rest(1070.0).modulo(360.0), &MODE1, 0, 1);
    assert_eq!(t.status().match_position, 320.0);
    assert!((t.status().track_position - 30.0).abs() < 1e-9);
}

#[test]
fn at_ct_5_modulo_homing_counts_as_motion_by_the_half_rule() {
    let data = CamTrackData::new(0.0, 160.0);
    // 350 -> 10: diff 20 -> positive: Match stays 320, TrackPos 50; then 10 -> 350: diff 340
    // -> negative: back to Match 320, TrackPos 30.
    let sim = Sim::at_rest(350.0)
        .modulo(360.0)
        .jump(2 * MS, 10.0)
        .jump(4 * MS, 350.0);
    let mut t = track(CamTrackType::Distance, data);
    run(&mut t, &sim, &MODE1, 0, 3);
    assert_eq!(t.status().match_position, 320.0);
    assert!((t.status().track_position - 50.0).abs() < 1e-9);
    run(&mut t, &sim, &MODE1, 3, 6);
    assert_eq!(t.status().match_position, 320.0);
    assert!((t.status().track_position - 30.0).abs() < 1e-9);
    // The same jumps in other continuous representations give the same result.
    let sim = Sim::at_rest(350.0)
        .modulo(360.0)
        .jump(2 * MS, 10.0 - 720.0)
        .jump(4 * MS, 350.0 + 1080.0);
    let mut t = track(CamTrackType::Distance, data);
    run(&mut t, &sim, &MODE1, 0, 3);
    assert_eq!(t.status().match_position, 320.0);
    run(&mut t, &sim, &MODE1, 3, 6);
    assert_eq!(t.status().match_position, 320.0);
    assert!((t.status().track_position - 30.0).abs() < 1e-9);
    // 0 -> 180: diff 180 -> positive (<= half): Match 160, TrackPos 20.
    let sim = Sim::at_rest(0.0).modulo(360.0).jump(2 * MS, 180.0);
    let mut t = track(CamTrackType::Distance, data);
    run(&mut t, &sim, &MODE1, 0, 4);
    assert_eq!(t.status().match_position, 160.0);
    assert!((t.status().track_position - 20.0).abs() < 1e-9);
    // 0 -> 181: diff 181 -> negative (-179): Match -320 = 40, TrackPos 141.
    let sim = Sim::at_rest(0.0).modulo(360.0).jump(2 * MS, 181.0);
    let mut t = track(CamTrackType::Distance, data);
    run(&mut t, &sim, &MODE1, 0, 4);
    assert_eq!(t.status().match_position, 40.0);
    assert!((t.status().track_position - 141.0).abs() < 1e-9);
    // Linear axis: re-referenced to ReferencePosition.
    let sim = Sim::at_rest(0.0).jump(2 * MS, 1234.0);
    let mut t = track(CamTrackType::Distance, data);
    run(&mut t, &sim, &MODE1, 0, 4);
    assert_eq!(t.status().match_position, 1120.0);
}

#[test]
fn at_ct_6_cam_outside_the_track_is_ignored_until_the_track_grows() {
    let data = CamTrackData::new(0.0, 100.0).with_cam(0, TrackCam::distance(120.0, 130.0));
    assert!(!data.takes_part(0));
    let mut t = track(CamTrackType::Distance, data);
    let sim = Sim::constant(0.0, 10.0);
    assert!(run(&mut t, &sim, &MODE0, 0, 10).is_empty());
    t.set_data(CamTrackData {
        track_length: 200.0,
        ..data
    });
    assert!(t.status().cam_data_changed);
    let e = run(&mut t, &sim, &MODE0, 10, 20);
    assert!(!t.status().cam_data_changed);
    assert_positions(&positions(&e, 0.0, 10.0), &[(120.0, true), (130.0, false)]);
}

#[test]
fn at_ct_7_track_end_clips_distance_cams_time_cams_run_on() {
    let data = CamTrackData::new(0.0, 100.0).with_cam(0, TrackCam::distance(80.0, 150.0));
    let mut t = track(CamTrackType::Distance, data);
    let sim = Sim::constant(0.0, 1.0);
    let e = run(&mut t, &sim, &MODE1, 0, 200);
    assert_positions(
        &positions(&e, 0.0, 1.0),
        &[(80.0, true), (100.0, false), (180.0, true), (200.0, false)],
    );
    let data = CamTrackData::new(0.0, 100.0).with_cam(0, TrackCam::time(95.0, 20e-3));
    let mut t = track(CamTrackType::Time, data);
    let e = run(&mut t, &sim, &MODE1, 0, 150);
    assert_eq!(tv(&e), vec![(95 * MS, true), (115 * MS, false)]);
}

#[test]
fn at_ct_8_start_equal_end_never_switches() {
    let data = CamTrackData::new(0.0, 100.0).with_cam(0, TrackCam::distance(40.0, 40.0));
    let mut t = track(CamTrackType::Distance, data);
    assert!(run(&mut t, &Sim::constant(0.0, 10.0), &MODE1, 0, 30).is_empty());
    let mut t = track(CamTrackType::Distance, data);
    run(&mut t, &Sim::at_rest(40.0), &MODE1, 0, 2);
    assert!(!t.status().track_output);
}

#[test]
fn at_ct_9_mode0_change_aborts_time_cams_and_keeps_covered_distance_cams() {
    // Distance: at rest at 30 inside 10..50.
    let data = CamTrackData::new(0.0, 100.0).with_cam(0, TrackCam::distance(10.0, 50.0));
    let mut t = track(CamTrackType::Distance, data);
    let sim = Sim::at_rest(30.0);
    assert_eq!(tv(&run(&mut t, &sim, &MODE0, 0, 2)), vec![(0, true)]);
    // Still covered (20..60): stays ON without an edge.
    t.set_data(data.with_cam(0, TrackCam::distance(20.0, 60.0)));
    assert!(run(&mut t, &sim, &MODE0, 2, 4).is_empty());
    // No longer covered (40..60): OFF at the next cycle start.
    t.set_data(data.with_cam(0, TrackCam::distance(40.0, 60.0)));
    assert_eq!(tv(&run(&mut t, &sim, &MODE0, 4, 6)), vec![(4 * MS, false)]);

    // Time: a running 100 ms cam ends when new data is applied with Mode 0.
    let data = CamTrackData::new(0.0, 100.0)
        .with_cam(0, TrackCam::time(10.0, 100e-3))
        .with_cam(1, TrackCam::time(90.0, 1e-3));
    let mut t = track(CamTrackType::Time, data);
    let sim = Sim::constant(0.0, 1.0);
    assert_eq!(tv(&run(&mut t, &sim, &MODE0, 0, 20)), vec![(10 * MS, true)]);
    t.set_data(data.with_cam(1, TrackCam::time(80.0, 1e-3)));
    assert_eq!(
        tv(&run(&mut t, &sim, &MODE0, 20, 22)),
        vec![(20 * MS, false)]
    );
}

#[test]
fn at_ct_10_mode1_change_and_disable_wait_for_the_track_end() {
    let data = CamTrackData::new(0.0, 100.0).with_cam(0, TrackCam::distance(10.0, 20.0));
    let new = data.with_cam(0, TrackCam::distance(30.0, 40.0));
    let sim = Sim::constant(5.0, 10.0); // 100 at 9.5 ms, 130 at 12.5 ms
                                        // Mode 1: the change at 25 (2 ms) waits for the track end
                                        // (100).
    let mut t = track(CamTrackType::Distance, data);
    let e = run(&mut t, &sim, &MODE1, 0, 2);
    assert_positions(&positions(&e, 5.0, 10.0), &[(10.0, true), (20.0, false)]);
    t.set_data(new);
    let e = run(&mut t, &sim, &MODE1, 2, 5);
    assert!(e.is_empty());
    assert_eq!(t.status().state, CamTrackState::ActiveWaitingForNextCycle);
    assert!(t.status().cam_data_changed);
    let e = run(&mut t, &sim, &MODE1, 5, 16);
    assert_eq!(t.status().state, CamTrackState::Active);
    assert!(!t.status().cam_data_changed);
    assert_positions(&positions(&e, 5.0, 10.0), &[(130.0, true), (140.0, false)]);
    // Mode 0: at once, 30..40 in the current cycle.
    let mut t = track(CamTrackType::Distance, data);
    run(&mut t, &sim, &MODE0, 0, 2);
    t.set_data(new);
    let e = run(&mut t, &sim, &MODE0, 2, 5);
    assert_positions(&positions(&e, 5.0, 10.0), &[(30.0, true), (40.0, false)]);

    // Mode 1 disable at 50: the track runs to its end (100), a cam at 90..100 still switches,
    // the next cycle's cam at 0..10 does not.
    let data = CamTrackData::new(0.0, 100.0)
        .with_cam(0, TrackCam::distance(0.0, 10.0))
        .with_cam(1, TrackCam::distance(90.0, 100.0));
    let mut t = track(CamTrackType::Distance, data);
    let sim = Sim::constant(45.0, 1.0);
    run(&mut t, &sim, &MODE1, 0, 5);
    let fb = t.call(1, &McCamTrack::disabled(CamTrackMode::EndOfCycle));
    assert!(fb.busy);
    assert_eq!(t.status().state, CamTrackState::ActiveWaitingForNextCycle);
    let e = steps(&mut t, &sim, 5, 80);
    assert_eq!(tv(&e), vec![(45 * MS, true), (55 * MS, false)]);
    assert!(
        !t.call(1, &McCamTrack::disabled(CamTrackMode::EndOfCycle))
            .busy
    );
    assert_eq!(t.status().state, CamTrackState::Inactive);
    // Mode 0 disable inside a cam: OFF at once.
    let mut t = track(CamTrackType::Distance, data);
    run(&mut t, &sim, &MODE1, 0, 50);
    assert!(t.status().track_output);
    let fb = t.call(1, &McCamTrack::disabled(CamTrackMode::Immediate));
    assert!(!fb.busy);
    assert_eq!(tv(&steps(&mut t, &sim, 50, 52)), vec![(50 * MS, false)]);
}

#[test]
fn at_ct_11_mode2_forces_the_output_on() {
    let data = CamTrackData::new(0.0, 100.0).with_cam(0, TrackCam::distance(10.0, 20.0));
    let mut t = track(CamTrackType::Distance, data);
    let sim = Sim::constant(0.0, 10.0);
    let e = run(
        &mut t,
        &sim,
        &McCamTrack::enabled(CamTrackMode::ForcedOn),
        0,
        5,
    );
    assert_eq!(tv(&e), vec![(0, true)]);
    assert_eq!(t.status().single_cam_state, 0); // at 50: cam 1 off, the output forced on
    let e = run(
        &mut t,
        &sim,
        &McCamTrack::disabled(CamTrackMode::ForcedOn),
        5,
        7,
    );
    assert_eq!(tv(&e), vec![(5 * MS, false)]);
    assert!(!t.status().track_output);
}

#[test]
fn at_ct_12_edges_per_cycle_cap() {
    // Cams 10..12 and 14..16 at 10 units/ms: four edges in the cycle (1, 2] ms.
    let data = CamTrackData::new(0.0, 100.0)
        .with_cam(0, TrackCam::distance(10.0, 12.0))
        .with_cam(1, TrackCam::distance(14.0, 16.0));
    let sim = Sim::constant(-0.5, 10.0);
    let mut got = Vec::new();
    for interface in [
        TrackOutputInterface::Software,
        TrackOutputInterface::TimerDq,
        TrackOutputInterface::DqModule,
    ] {
        let cfg = CamTrackConfig {
            interface,
            ..CamTrackConfig::new(CamTrackType::Distance)
        };
        let mut t = CamTrack::new(cfg, data).unwrap();
        let e = run(&mut t, &sim, &MODE1, 0, 3);
        got.push((tv(&e), t.status().edges_suppressed));
    }
    let t = |x: f64| ((x + 0.5) * 100_000.0).round() as i64;
    assert_eq!(
        got[0],
        (
            vec![
                (t(10.0), true),
                (t(12.0), false),
                (t(14.0), true),
                (t(16.0), false)
            ],
            0
        )
    );
    // Timer DQ: one rising and one falling edge, the last of each.
    assert_eq!(got[1], (vec![(t(14.0), true), (t(16.0), false)], 2));
    // DQ module: one edge; the cycle ends OFF as it started, so nothing is output.
    assert_eq!(got[2], (vec![], 4));
    // DQ module with two on edges in one cycle and the output ending ON: the last wins.
    let data = data.with_cam(2, TrackCam::distance(18.0, 30.0));
    let cfg = CamTrackConfig {
        interface: TrackOutputInterface::DqModule,
        ..CamTrackConfig::new(CamTrackType::Distance)
    };
    let mut tr = CamTrack::new(cfg, data).unwrap();
    let e = run(&mut tr, &sim, &MODE1, 0, 3);
    assert_eq!(tv(&e), vec![(t(18.0), true)]);
}

#[test]
fn at_ct_13_mode1_lead_time_needs_room_after_the_switchover() {
    // v = 1 unit/ms, OnComp 5 ms. New data applied at the track end (100 at 100 ms).
    let mut data = CamTrackData::new(0.0, 100.0).with_cam(0, TrackCam::distance(50.0, 60.0));
    data.parameters.on_compensation = 5e-3;
    let sim = Sim::constant(0.0, 1.0);
    for (start, edge) in [(3.0, 100 * MS), (8.0, 103 * MS)] {
        let mut t = track(CamTrackType::Distance, data);
        run(&mut t, &sim, &MODE1, 0, 70);
        t.set_data(data.with_cam(0, TrackCam::distance(start, 20.0)));
        let e = run(&mut t, &sim, &MODE1, 70, 115);
        // A cam that starts within v * OnComp after the switch-over switches at the
        // switch-over (late); one beyond it switches exactly OnComp early.
        assert_eq!(
            e[0],
            Edge {
                time_ns: edge,
                on: true,
                cam: 0
            },
            "start {start}"
        );
    }
}

#[test]
fn at_ct_14_reference_for_a_seamless_change() {
    let m = Some(Modulo {
        start: 0.0,
        length: 360.0,
    });
    assert_eq!(next_reference_position(320.0, 160.0, true, m), 120.0);
    assert_eq!(next_reference_position(320.0, 160.0, false, m), 160.0);
    let mut t = track(CamTrackType::Distance, CamTrackData::new(0.0, 160.0));
    run(&mut t, &Sim::at_rest(350.0).modulo(360.0), &MODE1, 0, 1);
    assert_eq!(t.next_reference_position(true), 120.0);
    // Applying it with Mode 1 at the end of the cycle continues the track seamlessly.
    let sim = Sim::constant(350.0, 1.0).modulo(360.0);
    let mut t = track(CamTrackType::Distance, CamTrackData::new(0.0, 160.0));
    run(&mut t, &sim, &MODE1, 0, 2);
    let r = t.next_reference_position(true);
    t.set_data(CamTrackData::new(r, 160.0));
    run(&mut t, &sim, &MODE1, 2, 200);
    // At 550 (continuous) = 190: Match 480 = 120, TrackPos 70.
    assert_eq!(t.status().match_position, 120.0);
    assert!((t.status().track_position - 70.0).abs() < 1e-9);
}

#[test]
fn at_ct_15_masking() {
    let data = CamTrackData::new(0.0, 100.0)
        .with_cam(0, TrackCam::distance(10.0, 20.0))
        .with_cam(1, TrackCam::distance(30.0, 40.0))
        .with_cam(2, TrackCam::distance(50.0, 60.0));
    assert_eq!(data.masking, 0xFFFF_FFFF);
    let masked = CamTrackData {
        masking: !(1 << 2),
        ..data
    };
    let sim = Sim::constant(0.0, 10.0);
    let mut t = track(CamTrackType::Distance, masked);
    let e = run(&mut t, &sim, &MODE1, 0, 9);
    assert_eq!(
        e.iter().map(|e| e.cam).collect::<Vec<_>>(),
        vec![0, 0, 1, 1]
    );
}

#[test]
fn at_ct_16_order_follows_the_direction() {
    let data = CamTrackData::new(0.0, 100.0)
        .with_cam(0, TrackCam::time(10.0, 0.5e-3))
        .with_cam(1, TrackCam::time(20.0, 0.5e-3))
        .with_cam(2, TrackCam::time(30.0, 0.5e-3));
    let sim = Sim::constant(5.0, 10.0).velocity(4 * MS, -10.0);
    let mut t = track(CamTrackType::Time, data);
    let e = run(&mut t, &sim, &MODE1, 0, 8);
    let ons: Vec<u8> = e.iter().filter(|e| e.on).map(|e| e.cam).collect();
    assert_eq!(ons, vec![0, 1, 2, 2, 1, 0]);
}

#[test]
fn faulty_data_raises_703_and_reset_resumes() {
    let good = CamTrackData::new(0.0, 100.0).with_cam(0, TrackCam::distance(10.0, 50.0));
    let mut t = track(CamTrackType::Distance, good);
    let sim = Sim::at_rest(30.0);
    assert_eq!(tv(&run(&mut t, &sim, &MODE0, 0, 2)), vec![(0, true)]);
    t.set_data(good.with_cam(4, TrackCam::distance(30.0, 20.0)));
    let fb = t.call(1, &MODE0);
    assert!(fb.error);
    assert_eq!(fb.error_id, ErrorId::TechnologyAlarm);
    assert_eq!(tv(&steps(&mut t, &sim, 2, 3)), vec![(2 * MS, false)]);
    let alarm = t.status().alarm.unwrap();
    assert_eq!(
        (alarm.id, alarm.supplement),
        (AlarmId::CamTrackDataFaulty, 5)
    );
    assert_eq!(t.status().state, CamTrackState::Inactive);
    t.set_data(good);
    t.reset();
    assert_eq!(tv(&run(&mut t, &sim, &MODE0, 3, 5)), vec![(3 * MS, true)]);
    // Time cam shorter than OffComp - OnComp.
    let mut bad = CamTrackData::new(0.0, 100.0).with_cam(0, TrackCam::time(10.0, 1e-3));
    bad.parameters.off_compensation = 2e-3;
    assert!(CamTrack::new(CamTrackConfig::new(CamTrackType::Time), bad).is_err());
}

#[test]
fn one_instance_and_enabling_while_moving() {
    let data = CamTrackData::new(0.0, 100.0).with_cam(0, TrackCam::distance(10.0, 50.0));
    let mut t = track(CamTrackType::Distance, data);
    assert!(t.call(1, &MODE1).busy);
    let fb = t.call(2, &MODE1);
    assert!(fb.error && !fb.busy);
    assert_eq!(fb.error_id, ErrorId::OnlyOneInstance);
    assert_eq!(CamTrackMode::from_code(3), Err(ErrorId::IllegalMode));
    // Enabled at 3 ms while moving through 10..50 (at 30): ON at once, OFF at 50.
    let mut t = track(CamTrackType::Distance, data);
    let sim = Sim::constant(0.0, 10.0);
    let e = run(&mut t, &sim, &MODE1, 3, 8);
    assert_eq!(tv(&e), vec![(3 * MS, true), (5 * MS, false)]);
}

#[test]
fn hysteresis_and_invert() {
    // Inverted output, jitter around the cam start 10 with H = 0.1: no toggling.
    let mut data = CamTrackData::new(0.0, 100.0).with_cam(0, TrackCam::distance(10.0, 50.0));
    data.parameters.hysteresis = 0.1;
    let mut sim = Sim::constant(9.0, 1.0);
    for k in 1..30 {
        sim = sim.velocity(k * MS, if k % 2 == 0 { 0.03 } else { -0.03 });
    }
    let mut t = track(CamTrackType::Distance, data);
    let inv = McCamTrack {
        invert_output: true,
        ..MODE1
    };
    let e = run(&mut t, &sim, &inv, 0, 30);
    // 9 -> 10 at 1 ms: the output (inverted) goes off there and stays off.
    assert_eq!(tv(&e), vec![(0, true), (MS, false)]);
    assert!(t.status().output_inverted);
    data.parameters.hysteresis = 0.0;
    let mut t = track(CamTrackType::Distance, data);
    assert!(run(&mut t, &sim, &inv, 0, 30).len() > 10);
}

// ---------------------------------------------------------------------------------------------
// Property test
// ---------------------------------------------------------------------------------------------

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 32,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(0xc7_0003),
        ..ProptestConfig::default()
    })]

    /// Random distance cams on a track, jerk-limited motion there and back: the track output
    /// switches exactly (within 1 ns) where the OR of the cams changes, computed independently
    /// from `Profile::at` by bisection.
    #[test]
    fn track_output_edges_are_exact(
        lim in limits(),
        d1 in 50.0f64..300.0,
        back in 0.3f64..1.5,
        len in 15.0f64..60.0,
        reference in -50.0f64..50.0,
        cams in prop::collection::vec((0.0f64..1.0, 0.02f64..0.4), 1..6),
    ) {
        let first = plan_position(State::rest(0.0), d1, &lim).unwrap();
        let kb = (first.duration() * 1e3) as i64 + 3;
        let sim = Sim::at_rest(0.0).move_to(0, d1, &lim).move_to(kb * MS, d1 - back * d1, &lim);
        let second = plan_position(State::rest(d1), d1 - back * d1, &lim).unwrap();
        let cycles = kb + (second.duration() * 1e3) as i64 + 3;
        let mut data = CamTrackData::new(reference, len);
        let mut ranges = Vec::new();
        for (i, &(a, w)) in cams.iter().enumerate() {
            let on = a * len;
            let off = on + w * len;
            data = data.with_cam(i, TrackCam::distance(on, off));
            ranges.push((on, off.min(len)));
        }
        let inside = |x: f64| {
            let tp = (x - reference).rem_euclid(len);
            ranges.iter().any(|&(a, b)| tp >= a && tp <= b)
        };
        // Levels: every cam boundary in the travelled range; none at a rest position.
        let (min, max) = ((d1 - back * d1).min(0.0), d1);
        let mut levels = Vec::new();
        for &(a, b) in &ranges {
            for base in [a, b] {
                let mut k = ((min - reference - base) / len).floor() as i64 - 1;
                loop {
                    let l = reference + base + k as f64 * len;
                    if l > max + len { break; }
                    prop_assume!([0.0, d1, d1 - back * d1].iter().all(|r| (l - r).abs() > 1e-3));
                    levels.push(l);
                    k += 1;
                }
            }
        }
        let mut times = Vec::new();
        let t_end = cycles as f64 * 1e-3;
        for &l in &levels {
            let dt = 20e-6;
            let n = (t_end / dt) as i64;
            let (mut ta, mut fa) = (0.0, sim.p(0.0) - l);
            for i in 1..=n {
                let tb = i as f64 * dt;
                let fb = sim.p(tb) - l;
                if (fa < 0.0) != (fb < 0.0) {
                    let (mut lo, mut hi) = (ta, tb);
                    for _ in 0..200 {
                        let mid = 0.5 * (lo + hi);
                        if mid <= lo || mid >= hi { break; }
                        if ((sim.p(mid) - l) < 0.0) == (fa < 0.0) { lo = mid } else { hi = mid }
                    }
                    times.push(0.5 * (lo + hi));
                }
                ta = tb;
                fa = fb;
            }
        }
        times.sort_by(f64::total_cmp);
        times.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
        let mut expected = Vec::new();
        let mut state = inside(sim.p(0.0));
        if state { expected.push((0.0, true)); }
        for t in times {
            let after = inside(sim.p(t + 1e-7));
            if after != state {
                state = after;
                expected.push((t * 1e9, after));
            }
        }
        let mut tr = track(CamTrackType::Distance, data);
        let edges = run(&mut tr, &sim, &MODE1, 0, cycles);
        prop_assert_eq!(edges.len(), expected.len(), "{:?} vs {:?}", tv(&edges), expected);
        for (e, (t, on)) in edges.iter().zip(&expected) {
            prop_assert_eq!(e.on, *on);
            prop_assert!((e.time_ns as f64 - t).abs() <= 1.0, "edge {:?} vs exact {} ns", e, t);
        }
    }
}
