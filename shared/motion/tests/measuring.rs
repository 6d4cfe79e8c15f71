//! Measuring input TO: the known-answer cases AT-MI-* built from the examples and rules of the
//! S7-1500T Measuring input and cam functions V5.0 function manual, named after their ids,
//! and property tests of the measured positions and the cyclic counters.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use tandem_motion::catalog::alarm::AlarmId;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::cycle_motion::AxisMotion;
use tandem_motion::kinematics::modulo::Modulo;
use tandem_motion::kinematics::profile::{plan_position, Limits, Profile, State};
use tandem_motion::objects::measuring::{
    CyclicMode, MeasuringContext, MeasuringInput, MeasuringInputConfig, MeasuringRoute,
    MeasuringState, MeasuringTiming, MeasuringWindow, OneTimeMode,
};
use tandem_motion::plant::sensor::{InputEdge, InputEdges, SensorDirection, SimulatedSensor};
use tandem_testkit::strategies::limits;

const MS: i64 = 1_000_000;

/// An axis moving at constant velocity `v` (units/s) from `p0` at t = 0.
fn linear(k: i64, p0: f64, v: f64) -> AxisMotion {
    let s = |t_ns: i64| State {
        p: p0 + v * t_ns as f64 * 1e-9,
        v,
        a: 0.0,
    };
    AxisMotion::new(k * MS, (k + 1) * MS, s(k * MS), s((k + 1) * MS))
}

fn cfg() -> MeasuringInputConfig {
    MeasuringInputConfig {
        apply_activation_time: false,
        ..MeasuringInputConfig::timer_di(MS)
    }
}

fn rise(t: i64) -> InputEdge {
    InputEdge {
        time_ns: t,
        rising: true,
        latched: None,
    }
}

fn fall(t: i64) -> InputEdge {
    InputEdge {
        time_ns: t,
        rising: false,
        latched: None,
    }
}

/// Axis at 10 units/ms: position x is reached at x/10 ms = x * 100_000 ns.
fn at_pos(x: f64) -> i64 {
    (x * 100_000.0).round() as i64
}

/// Runs cycles `0..n` of the 10 units/ms axis, handing each edge to the cycle containing it.
fn run(mi: &mut MeasuringInput, n: i64, edges: &[InputEdge]) {
    for k in 0..n {
        let m = linear(k, 0.0, 10_000.0);
        let mine: Vec<InputEdge> = edges
            .iter()
            .copied()
            .filter(|e| e.time_ns > k * MS && e.time_ns <= (k + 1) * MS)
            .collect();
        mi.step(&m, &mine);
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

#[test]
fn at_mi_1_mode0_one_rising_edge_at_50() {
    let mut mi = MeasuringInput::new(cfg()).unwrap();
    let job = mi
        .measuring_input(OneTimeMode::Rising, None, MeasuringContext::OK)
        .unwrap();
    assert_eq!(mi.status().state, MeasuringState::WaitingForTrigger);
    assert!(mi.job_status(job).unwrap().busy);
    run(&mut mi, 10, &[rise(at_pos(50.0))]);
    let s = mi.job_status(job).unwrap();
    assert!(s.done && !s.busy && !s.error);
    assert!(close(s.measured_value1, 50.0), "{}", s.measured_value1);
    assert_eq!(s.measured_value2, 0.0);
    assert_eq!(s.edge_time1_ns, 5 * MS);
    assert_eq!(mi.status().state, MeasuringState::TriggerOccurred);
    assert!(close(mi.status().measured_value1, 50.0));
}

#[test]
fn at_mi_2_modes_on_r10_f20_r30() {
    let edges = [rise(at_pos(10.0)), fall(at_pos(20.0)), rise(at_pos(30.0))];
    let cases: [(OneTimeMode, f64, f64); 5] = [
        (OneTimeMode::Rising, 10.0, 0.0),
        (OneTimeMode::Falling, 20.0, 0.0),
        (OneTimeMode::TwoEdges, 10.0, 20.0),
        (OneTimeMode::RisingThenFalling, 10.0, 20.0),
        (OneTimeMode::FallingThenRising, 20.0, 30.0),
    ];
    for (mode, mv1, mv2) in cases {
        let mut mi = MeasuringInput::new(cfg()).unwrap();
        let job = mi
            .measuring_input(mode, None, MeasuringContext::OK)
            .unwrap();
        run(&mut mi, 5, &edges);
        let s = mi.job_status(job).unwrap();
        assert!(s.done, "{mode:?}");
        assert!(
            close(s.measured_value1, mv1),
            "{mode:?}: {}",
            s.measured_value1
        );
        assert!(
            close(s.measured_value2, mv2),
            "{mode:?}: {}",
            s.measured_value2
        );
    }
}

#[test]
fn at_mi_2_edges_in_one_cycle_are_taken_in_time_order() {
    // All three edges in one cycle, handed over out of order.
    let mut mi = MeasuringInput::new(cfg()).unwrap();
    let job = mi
        .measuring_input(OneTimeMode::FallingThenRising, None, MeasuringContext::OK)
        .unwrap();
    let m = linear(0, 0.0, 10_000.0);
    mi.step(&m, &[rise(300_000), rise(100_000), fall(200_000)]);
    let s = mi.job_status(job).unwrap();
    assert!(s.done);
    assert!(close(s.measured_value1, 2.0) && close(s.measured_value2, 3.0));
}

#[test]
fn at_mi_3_new_job_resets_fb_outputs_but_not_the_data_block() {
    let mut mi = MeasuringInput::new(cfg()).unwrap();
    let j1 = mi
        .measuring_input(OneTimeMode::Rising, None, MeasuringContext::OK)
        .unwrap();
    run(&mut mi, 3, &[rise(at_pos(12.0))]);
    assert!(close(mi.job_status(j1).unwrap().measured_value1, 12.0));
    let j2 = mi
        .measuring_input(OneTimeMode::Rising, None, MeasuringContext::OK)
        .unwrap();
    let s2 = mi.job_status(j2).unwrap();
    assert_eq!(s2.measured_value1, 0.0);
    assert!(s2.busy && !s2.done);
    assert!(close(mi.status().measured_value1, 12.0));
    // The finished first job keeps its outputs (it was not running, so not aborted).
    let s1 = mi.job_status(j1).unwrap();
    assert!(s1.done && !s1.command_aborted);
}

/// Steps one cycle of a stationary axis at 7.0 with the given edges.
fn still_cycle(mi: &mut MeasuringInput, k: i64, edges: &[InputEdge]) {
    let s = State::rest(7.0);
    mi.step(&AxisMotion::new(k * MS, (k + 1) * MS, s, s), edges);
}

/// `n` edges of polarity `rising` spread over cycle `k`.
fn burst(k: i64, n: i64, rising: bool) -> Vec<InputEdge> {
    (0..n)
        .map(|i| InputEdge {
            time_ns: k * MS + 1 + i * (MS / 20),
            rising,
            latched: None,
        })
        .collect()
}

#[test]
fn at_mi_4_cyclic_mode0_counters_and_lost_edges() {
    let mut mi = MeasuringInput::new(cfg()).unwrap();
    let job = mi
        .measuring_input_cyclic(CyclicMode::Rising, None, MeasuringContext::OK)
        .unwrap();
    // 5 rising edges: both values, LEC1 = LEC2 = 3.
    still_cycle(&mut mi, 0, &burst(0, 5, true));
    let s = *mi.job_status(job).unwrap();
    assert_eq!((s.counter1, s.counter2), (1, 1));
    assert_eq!((s.lost_edge_counter1, s.lost_edge_counter2), (3, 3));
    // 1 rising edge: MV1 only, C1 + 1, LEC1 = 0, LEC2 unchanged (stale 3).
    still_cycle(&mut mi, 1, &burst(1, 1, true));
    let s = *mi.job_status(job).unwrap();
    assert_eq!((s.counter1, s.counter2), (2, 1));
    assert_eq!((s.lost_edge_counter1, s.lost_edge_counter2), (0, 3));
    // 2 rising edges: both, LEC1 = LEC2 = 0.
    still_cycle(&mut mi, 2, &burst(2, 2, true));
    let s = *mi.job_status(job).unwrap();
    assert_eq!((s.counter1, s.counter2), (3, 2));
    assert_eq!((s.lost_edge_counter1, s.lost_edge_counter2), (0, 0));
    // 12 rising edges: LEC saturates at 7.
    still_cycle(&mut mi, 3, &burst(3, 12, true));
    let s = *mi.job_status(job).unwrap();
    assert_eq!((s.lost_edge_counter1, s.lost_edge_counter2), (7, 7));
    assert_eq!((s.counter1, s.counter2), (4, 3));
    // Falling edges are ignored: nothing changes.
    still_cycle(&mut mi, 4, &burst(4, 4, false));
    let s2 = *mi.job_status(job).unwrap();
    assert_eq!(s, s2);
    assert!(s2.busy && !s2.done);
    assert_eq!(mi.status().state, MeasuringState::WaitingForTrigger);
    assert_eq!(mi.status().lost_edge_counter1, 7);
}

#[test]
fn at_mi_5_cyclic_mode2_first_rising_and_first_falling() {
    let mut mi = MeasuringInput::new(cfg()).unwrap();
    let job = mi
        .measuring_input_cyclic(CyclicMode::Both, None, MeasuringContext::OK)
        .unwrap();
    // Cycle with R, F, R on a moving axis: MV1 = first R, MV2 = F, LEC = 1.
    let m = linear(0, 0.0, 10_000.0);
    mi.step(&m, &[rise(100_000), fall(200_000), rise(300_000)]);
    let s = *mi.job_status(job).unwrap();
    assert!(close(s.measured_value1, 1.0) && close(s.measured_value2, 2.0));
    assert_eq!((s.counter1, s.counter2), (1, 1));
    assert_eq!((s.lost_edge_counter1, s.lost_edge_counter2), (1, 1));
    // Order within the cycle does not matter: F before R.
    let m = linear(1, 0.0, 10_000.0);
    mi.step(&m, &[fall(MS + 100_000), rise(MS + 400_000)]);
    let s = *mi.job_status(job).unwrap();
    assert!(close(s.measured_value1, 14.0) && close(s.measured_value2, 11.0));
    assert_eq!((s.lost_edge_counter1, s.lost_edge_counter2), (0, 0));
    // Only F: MV2 set, C2 + 1, C1 unchanged (the counters diverge), LEC2 = 0, LEC1 stale.
    let m = linear(2, 0.0, 10_000.0);
    mi.step(
        &m,
        &[
            rise(2 * MS + 100_000),
            rise(2 * MS + 200_000),
            fall(2 * MS + 300_000),
        ],
    );
    let s = *mi.job_status(job).unwrap();
    assert_eq!((s.lost_edge_counter1, s.lost_edge_counter2), (1, 1));
    let m = linear(3, 0.0, 10_000.0);
    mi.step(&m, &[fall(3 * MS + 500_000)]);
    let s = *mi.job_status(job).unwrap();
    assert!(close(s.measured_value2, 35.0));
    assert_eq!((s.counter1, s.counter2), (3, 4));
    assert_eq!((s.lost_edge_counter1, s.lost_edge_counter2), (1, 0));
}

#[test]
fn at_mi_6_execute_zeroes_fb_counters_restart_zeroes_the_data_block() {
    let mut mi = MeasuringInput::new(cfg()).unwrap();
    let j1 = mi
        .measuring_input_cyclic(CyclicMode::Rising, None, MeasuringContext::OK)
        .unwrap();
    still_cycle(&mut mi, 0, &burst(0, 2, true));
    still_cycle(&mut mi, 1, &burst(1, 1, true));
    assert_eq!(mi.job_status(j1).unwrap().counter1, 2);
    let j2 = mi
        .measuring_input_cyclic(CyclicMode::Rising, None, MeasuringContext::OK)
        .unwrap();
    assert_eq!(mi.job_status(j2).unwrap().counter1, 0);
    assert!(mi.job_status(j1).unwrap().command_aborted);
    still_cycle(&mut mi, 2, &burst(2, 1, true));
    assert_eq!(mi.job_status(j2).unwrap().counter1, 1);
    // The data block kept counting across the jobs.
    assert_eq!(mi.status().counter1, 3);
    assert_eq!(mi.status().counter2, 1);
    mi.reset(false);
    assert_eq!(mi.status().counter1, 3);
    mi.reset(true);
    assert_eq!(mi.status().counter1, 0);
    assert_eq!(mi.status().counter2, 0);
    assert_eq!(mi.status().measured_value1, 0.0);
    assert_eq!(mi.status().state, MeasuringState::Inactive);
    assert!(mi.job_status(j2).unwrap().command_aborted);
}

#[test]
fn at_mi_7_windows_linear_swapped_modulo_wrapped() {
    let w = MeasuringWindow {
        start: 300.0,
        end: 100.0,
    };
    for (x, inside) in [
        (99.0, false),
        (100.0, true),
        (200.0, true),
        (300.0, true),
        (301.0, false),
    ] {
        assert_eq!(w.contains(x, None), inside, "linear {x}");
    }
    let m = Some(Modulo {
        start: 0.0,
        length: 360.0,
    });
    let w = MeasuringWindow {
        start: 300.0,
        end: 60.0,
    };
    for (x, inside) in [
        (299.0, false),
        (300.0, true),
        (359.9, true),
        (0.0, true),
        (60.0, true),
        (61.0, false),
        (180.0, false),
        (720.0 + 10.0, true),
    ] {
        assert_eq!(w.contains(x, m), inside, "modulo {x}");
    }
    // Start = 370 is mapped to 10.
    let w = MeasuringWindow {
        start: 370.0,
        end: 20.0,
    };
    assert!(
        w.contains(10.0, m) && w.contains(15.0, m) && !w.contains(9.0, m) && !w.contains(300.0, m)
    );

    // In the object: only edges inside the window count.
    let mut mi = MeasuringInput::new(cfg()).unwrap();
    let job = mi
        .measuring_input(
            OneTimeMode::Rising,
            Some(MeasuringWindow {
                start: 30.0,
                end: 20.0,
            }),
            MeasuringContext::OK,
        )
        .unwrap();
    run(&mut mi, 5, &[rise(at_pos(10.0)), rise(at_pos(25.0))]);
    let s = mi.job_status(job).unwrap();
    assert!(s.done && close(s.measured_value1, 25.0));
}

#[test]
fn at_mi_8_no_edge_in_window_one_time_alarm_cyclic_stays_busy() {
    let w = Some(MeasuringWindow {
        start: 20.0,
        end: 30.0,
    });
    let mut mi = MeasuringInput::new(cfg()).unwrap();
    let job = mi
        .measuring_input(OneTimeMode::Rising, w, MeasuringContext::OK)
        .unwrap();
    // An edge before the window (at 10) and one after (at 40): neither counts.
    run(&mut mi, 2, &[rise(at_pos(10.0))]);
    assert!(mi.job_status(job).unwrap().busy, "still before the window");
    run_from(&mut mi, 2, 5, &[rise(at_pos(40.0))]);
    let s = mi.job_status(job).unwrap();
    assert!(s.error && !s.busy && !s.done);
    assert_eq!(s.error_id, ErrorId::TechnologyAlarm);
    assert_eq!(mi.status().state, MeasuringState::MeasuringError);
    assert_eq!(
        mi.status().alarm.map(|a| a.id),
        Some(AlarmId::MeasuringRangeNotRecognized)
    );
    mi.reset(false);
    assert_eq!(mi.status().alarm, None);
    assert_eq!(mi.status().state, MeasuringState::Inactive);

    let mut mi = MeasuringInput::new(cfg()).unwrap();
    let job = mi
        .measuring_input_cyclic(CyclicMode::Rising, w, MeasuringContext::OK)
        .unwrap();
    run(&mut mi, 6, &[rise(at_pos(10.0)), rise(at_pos(40.0))]);
    let s = mi.job_status(job).unwrap();
    assert!(s.busy && !s.error);
    assert_eq!(s.counter1, 0);
    assert_eq!(mi.status().alarm, None);
}

fn run_from(mi: &mut MeasuringInput, k0: i64, k1: i64, edges: &[InputEdge]) {
    for k in k0..k1 {
        let m = linear(k, 0.0, 10_000.0);
        let mine: Vec<InputEdge> = edges
            .iter()
            .copied()
            .filter(|e| e.time_ns > k * MS && e.time_ns <= (k + 1) * MS)
            .collect();
        mi.step(&m, &mine);
    }
}

#[test]
fn at_mi_t1_timer_di_1ms() {
    let t = MeasuringTiming::new(MeasuringRoute::TimerDi, MS, MS);
    assert_eq!(t.effective_after_ns(false), 2 * MS);
    assert_eq!(t.result_latency_ns(false, false), 3 * MS);
    assert_eq!(t.result_latency_ns(true, false), 2 * MS);
    // In the object: an edge 1.5 ms after the job start is not seen, one at 2 ms is.
    let mut mi = MeasuringInput::new(MeasuringInputConfig::timer_di(MS)).unwrap();
    let job = mi
        .measuring_input(OneTimeMode::Rising, None, MeasuringContext::OK)
        .unwrap();
    run(&mut mi, 4, &[rise(1_500_000), rise(2 * MS)]);
    let s = mi.job_status(job).unwrap();
    assert!(s.done && close(s.measured_value1, 20.0));
}

#[test]
fn at_mi_t2_profidrive_2ms() {
    let t = MeasuringTiming::new(MeasuringRoute::Profidrive, 2 * MS, 2 * MS);
    assert_eq!(t.range_activation_ns(), 6 * MS);
    assert_eq!(t.effective_after_ns(false), 10 * MS);
    assert_eq!(t.effective_after_ns(true), 12 * MS);
    assert_eq!(t.result_latency_ns(false, false), 14 * MS);
    assert_eq!(t.result_latency_ns(false, true), 26 * MS);
    assert_eq!(t.window_activation_ns(3 * MS, false), 13 * MS);
    assert_eq!(t.window_activation_ns(3 * MS, true), 15 * MS);
}

#[test]
fn at_mi_t3_profidrive_2ms_send_4ms() {
    let t = MeasuringTiming::new(MeasuringRoute::Profidrive, 2 * MS, 4 * MS);
    assert_eq!(t.range_activation_ns(), 4 * MS);
    assert_eq!(t.effective_after_ns(false), 8 * MS);
    assert_eq!(t.effective_after_ns(true), 10 * MS);
}

#[test]
fn at_mi_9_new_job_and_homing_abort_the_running_one() {
    let mut mi = MeasuringInput::new(cfg()).unwrap();
    let cyc = mi
        .measuring_input_cyclic(CyclicMode::Rising, None, MeasuringContext::OK)
        .unwrap();
    still_cycle(&mut mi, 0, &[]);
    let one = mi
        .measuring_input(OneTimeMode::Rising, None, MeasuringContext::OK)
        .unwrap();
    let c = mi.job_status(cyc).unwrap();
    assert!(c.command_aborted && !c.busy);
    assert_eq!(mi.active_job(), Some(one));
    // MC_Home mode 0 (direct) has no effect; mode 3 (active homing) aborts.
    assert!(!mi.axis_homing(0));
    assert!(mi.job_status(one).unwrap().busy);
    assert!(mi.axis_homing(3));
    let o = mi.job_status(one).unwrap();
    assert!(o.command_aborted && !o.busy);
    assert_eq!(mi.active_job(), None);
    assert_eq!(mi.status().state, MeasuringState::Inactive);
    // MC_AbortMeasuringInput.
    let j = mi
        .measuring_input(OneTimeMode::Rising, None, MeasuringContext::OK)
        .unwrap();
    assert_eq!(mi.abort_measuring_input(), Ok(true));
    assert!(mi.job_status(j).unwrap().command_aborted);
    assert_eq!(mi.abort_measuring_input(), Ok(false));
}

#[test]
fn at_mi_10_invalid_encoder_and_cyclic_on_the_wrong_route() {
    let mut mi = MeasuringInput::new(cfg()).unwrap();
    let bad = MeasuringContext {
        encoder_valid: false,
        homing_active: false,
    };
    assert_eq!(
        mi.measuring_input(OneTimeMode::Rising, None, bad),
        Err(ErrorId::ActualValuesInvalid)
    );
    assert_eq!(
        mi.measuring_input_cyclic(CyclicMode::Rising, None, bad),
        Err(ErrorId::ActualValuesInvalid)
    );
    for route in [MeasuringRoute::CentralProbe, MeasuringRoute::Profidrive] {
        let mut mi = MeasuringInput::new(MeasuringInputConfig { route, ..cfg() }).unwrap();
        assert_eq!(
            mi.measuring_input_cyclic(CyclicMode::Rising, None, MeasuringContext::OK),
            Err(ErrorId::IllegalObject)
        );
        assert!(mi
            .measuring_input(OneTimeMode::Rising, None, MeasuringContext::OK)
            .is_ok());
    }
    // PROFIdrive measuring while homing runs.
    let mut mi = MeasuringInput::new(MeasuringInputConfig {
        route: MeasuringRoute::Profidrive,
        ..cfg()
    })
    .unwrap();
    let homing = MeasuringContext {
        encoder_valid: true,
        homing_active: true,
    };
    assert_eq!(
        mi.measuring_input(OneTimeMode::Rising, None, homing),
        Err(ErrorId::MeasuringRejectedHomingActive)
    );
    // Modes and windows.
    assert_eq!(OneTimeMode::from_code(5), Err(ErrorId::IllegalMode));
    assert_eq!(CyclicMode::from_code(3), Err(ErrorId::IllegalMode));
    assert_eq!(
        mi.measuring_input(
            OneTimeMode::Rising,
            Some(MeasuringWindow {
                start: f64::NAN,
                end: 1.0
            }),
            MeasuringContext::OK
        ),
        Err(ErrorId::IllegalMeasuringStart)
    );
    assert_eq!(
        mi.measuring_input(
            OneTimeMode::Rising,
            Some(MeasuringWindow {
                start: 1.0,
                end: 1.0
            }),
            MeasuringContext::OK
        ),
        Err(ErrorId::IllegalMeasuringEnd)
    );
}

#[test]
fn at_mi_11_interpolation_with_correction_time() {
    // Samples (0 ms, 0.0) and (1 ms, 10.0); edge at 0.55 ms; CorrectionTime 0.05 ms -> 5.0.
    let mut mi = MeasuringInput::new(MeasuringInputConfig {
        correction_time: 0.05e-3,
        ..cfg()
    })
    .unwrap();
    let job = mi
        .measuring_input(OneTimeMode::Rising, None, MeasuringContext::OK)
        .unwrap();
    let m = AxisMotion::new(
        0,
        MS,
        State {
            p: 0.0,
            v: 10_000.0,
            a: 0.0,
        },
        State {
            p: 10.0,
            v: 10_000.0,
            a: 0.0,
        },
    );
    mi.step(&m, &[rise(550_000)]);
    let s = mi.job_status(job).unwrap();
    assert!(s.done);
    assert!(close(s.measured_value1, 5.0), "{}", s.measured_value1);
}

#[test]
fn late_edges_use_the_history_and_future_edges_are_carried() {
    // Correction time 2.5 ms: the position comes from two cycles back.
    let mut mi = MeasuringInput::new(MeasuringInputConfig {
        correction_time: 2.5e-3,
        ..cfg()
    })
    .unwrap();
    let job = mi
        .measuring_input_cyclic(CyclicMode::Rising, None, MeasuringContext::OK)
        .unwrap();
    run(&mut mi, 3, &[]);
    // An edge at 3.7 ms handed over in cycle 3 ([3, 4] ms) -> position at 1.2 ms = 12.
    mi.step(&linear(3, 0.0, 10_000.0), &[rise(3_700_000)]);
    assert!(close(mi.job_status(job).unwrap().measured_value1, 12.0));
    // An edge later than the cycle end is evaluated in the next cycle.
    mi.step(&linear(4, 0.0, 10_000.0), &[rise(5_600_000)]);
    assert_eq!(mi.job_status(job).unwrap().counter1, 1);
    mi.step(&linear(5, 0.0, 10_000.0), &[]);
    let s = mi.job_status(job).unwrap();
    assert_eq!(s.counter1, 2);
    assert!(close(s.measured_value1, 31.0));
    // An edge older than the kept history is not evaluated: alarm 758 (no reaction).
    mi.step(&linear(6, 0.0, 10_000.0), &[rise(MS / 2)]);
    assert_eq!(mi.job_status(job).unwrap().counter1, 2);
    assert_eq!(mi.status().edges_not_evaluated, 1);
    assert_eq!(
        mi.status().alarm.map(|a| a.id),
        Some(AlarmId::MeasuringEdgeNotEvaluated)
    );
}

#[test]
fn modulo_values_are_reduced() {
    let m = Modulo {
        start: 0.0,
        length: 360.0,
    };
    let mut mi = MeasuringInput::new(cfg()).unwrap();
    let job = mi
        .measuring_input(OneTimeMode::Rising, None, MeasuringContext::OK)
        .unwrap();
    // 100 units/ms from 700: at 0.3 ms the axis is at 730 = 10 (mod 360).
    let s = |t: f64| State {
        p: 700.0 + 100_000.0 * t,
        v: 100_000.0,
        a: 0.0,
    };
    let motion = AxisMotion::new(0, MS, s(0.0), s(1e-3)).with_modulo(Some(m));
    mi.step(&motion, &[rise(300_000)]);
    assert!(close(mi.job_status(job).unwrap().measured_value1, 10.0));
}

#[test]
fn simulated_sensor_edges_with_dead_time_and_modulo_marks() {
    // Mark at 10..12 on a 0..360 modulo axis moving at 100 units/ms: rising at 10, falling at
    // 12, again at 370 and 372; dead time 0.25 ms.
    let m = Modulo {
        start: 0.0,
        length: 360.0,
    };
    let mut sensor = SimulatedSensor::new(10.0, 2.0, 0.25e-3, 0, 1, SensorDirection::Both);
    let mut all = Vec::new();
    for k in 0..5 {
        let s = |t_ns: i64| State {
            p: 100_000.0 * t_ns as f64 * 1e-9,
            v: 100_000.0,
            a: 0.0,
        };
        let motion =
            AxisMotion::new(k * MS, (k + 1) * MS, s(k * MS), s((k + 1) * MS)).with_modulo(Some(m));
        let mut out = InputEdges::default();
        sensor.step(&motion, &mut out);
        for e in out.as_slice() {
            assert!(e.time_ns <= (k + 1) * MS);
            all.push(*e);
        }
    }
    assert_eq!(
        all,
        vec![
            rise(100_000 + 250_000),
            fall(120_000 + 250_000),
            rise(3_700_000 + 250_000),
            fall(3_720_000 + 250_000),
        ]
    );
}

// ---------------------------------------------------------------------------------------------
// Property tests
// ---------------------------------------------------------------------------------------------

/// A jerk-limited move from rest at `p0` to `p1`, then back to `p2`, sampled at 1 ms.
struct Moves {
    a: Profile,
    b: Profile,
    /// Start of the second move (ns).
    tb: i64,
}

impl Moves {
    fn new(p0: f64, p1: f64, p2: f64, lim: &Limits) -> Self {
        let a = plan_position(State::rest(p0), p1, lim).unwrap();
        let tb = ((a.duration() * 1e9) as i64 / MS + 3) * MS;
        let b = plan_position(State::rest(p1), p2, lim).unwrap();
        Self { a, b, tb }
    }

    fn cycles(&self) -> i64 {
        self.tb / MS + (self.b.duration() * 1e3) as i64 + 3
    }

    fn motion(&self, k: i64) -> AxisMotion {
        let (t0, t1) = (k * MS, (k + 1) * MS);
        if t0 < self.tb {
            AxisMotion::from_profile(&self.a, 0, t0, t1)
        } else {
            AxisMotion::from_profile(&self.b, self.tb, t0, t1)
        }
    }

    fn p(&self, t_s: f64) -> f64 {
        let tb = self.tb as f64 * 1e-9;
        if t_s < tb {
            self.a.at(t_s).p
        } else {
            self.b.at(t_s - tb).p
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 64,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(0x3e45_0003),
        ..ProptestConfig::default()
    })]

    /// Simulated edges (mark sensor with dead time and jitter) measured cyclically on random
    /// jerk-limited motion: every measured position equals the true position at the edge time
    /// minus the correction time within 1e-9, and an edge is counted once.
    #[test]
    fn measured_positions_are_exact(
        lim in limits(),
        d1 in 20.0f64..200.0,
        d2 in -150.0f64..-20.0,
        mark in 0.1f64..0.9,
        width in 0.5f64..3.0,
        dead in 0.0f64..2.5e-3,
        jitter in 0i64..50_000,
        seed in any::<u64>(),
    ) {
        let moves = Moves::new(0.0, d1, d1 + d2, &lim);
        // The mark lies inside both moves' ranges, so it is passed there and back.
        let (lo, hi) = ((d1 + d2).max(0.0), d1);
        let pos = lo + 0.5 + mark * (hi - lo - width - 1.0);
        let mut sensor = SimulatedSensor::new(pos, width, dead, jitter, seed, SensorDirection::Both);
        let mut mi = MeasuringInput::new(MeasuringInputConfig { correction_time: dead, ..cfg() }).unwrap();
        let job = mi.measuring_input_cyclic(CyclicMode::Both, None, MeasuringContext::OK).unwrap();
        let mut buf = InputEdges::default();
        let (mut n1, mut n2) = (0u32, 0u32);
        for k in 0..moves.cycles() + 4 {
            let m = moves.motion(k);
            buf.clear();
            sensor.step(&m, &mut buf);
            let before = *mi.job_status(job).unwrap();
            mi.step(&m, buf.as_slice());
            let s = *mi.job_status(job).unwrap();
            let rises: Vec<_> = buf.as_slice().iter().filter(|e| e.rising).collect();
            let falls: Vec<_> = buf.as_slice().iter().filter(|e| !e.rising).collect();
            if let Some(e) = rises.first() {
                n1 += 1;
                prop_assert_eq!(s.edge_time1_ns, e.time_ns);
                let truth = moves.p(e.time_ns as f64 * 1e-9 - dead);
                prop_assert!((s.measured_value1 - truth).abs() <= 1e-9, "MV1 {} vs {}", s.measured_value1, truth);
            } else {
                prop_assert_eq!(s.counter1, before.counter1);
            }
            if let Some(e) = falls.first() {
                n2 += 1;
                prop_assert_eq!(s.edge_time2_ns, e.time_ns);
                let truth = moves.p(e.time_ns as f64 * 1e-9 - dead);
                prop_assert!((s.measured_value2 - truth).abs() <= 1e-9, "MV2 {} vs {}", s.measured_value2, truth);
            }
            prop_assert_eq!(s.counter1, n1);
            prop_assert_eq!(s.counter2, n2);
        }
        // The sensor saw the mark on the way there and back (or at least once).
        prop_assert!(n1 >= 1 && n2 >= 1);
    }

    /// Random edges, several per cycle: in every cycle the first two matching edges (mode 0/1)
    /// or the first rising and first falling (mode 2) are captured exactly once, and the
    /// lost-edge counters count the rest exactly (saturating at 7).
    #[test]
    fn cyclic_capture_and_lost_edges_are_exact(
        mode in 0i32..3,
        cycles in prop::collection::vec(prop::collection::vec((1i64..MS, any::<bool>()), 0..12), 1..30),
    ) {
        let mode = CyclicMode::from_code(mode).unwrap();
        let mut mi = MeasuringInput::new(cfg()).unwrap();
        let job = mi.measuring_input_cyclic(mode, None, MeasuringContext::OK).unwrap();
        let (mut c1, mut c2, mut l1, mut l2) = (0u32, 0u32, 0u8, 0u8);
        for (k, edges) in cycles.iter().enumerate() {
            let k = k as i64;
            let list: Vec<InputEdge> = edges.iter().map(|&(t, r)| InputEdge { time_ns: k * MS + t, rising: r, latched: None }).collect();
            mi.step(&linear(k, 0.0, 10_000.0), &list);
            let mut sorted = list.clone();
            sorted.sort_by_key(|e| e.time_ns);
            let matching: Vec<_> = sorted.iter().filter(|e| match mode {
                CyclicMode::Rising => e.rising,
                CyclicMode::Falling => !e.rising,
                CyclicMode::Both => true,
            }).collect();
            let (first, second) = match mode {
                CyclicMode::Both => (matching.iter().find(|e| e.rising).copied(), matching.iter().find(|e| !e.rising).copied()),
                _ => (matching.first().copied(), matching.get(1).copied()),
            };
            let captured = u32::from(first.is_some()) + u32::from(second.is_some());
            let lost = (matching.len() as u32 - captured).min(7) as u8;
            let s = *mi.job_status(job).unwrap();
            if let Some(e) = first {
                c1 += 1;
                l1 = lost;
                prop_assert_eq!(s.edge_time1_ns, e.time_ns);
                prop_assert!(close(s.measured_value1, e.time_ns as f64 * 1e-5));
            }
            if let Some(e) = second {
                c2 += 1;
                l2 = lost;
                prop_assert_eq!(s.edge_time2_ns, e.time_ns);
                prop_assert!(close(s.measured_value2, e.time_ns as f64 * 1e-5));
            }
            prop_assert_eq!((s.counter1, s.counter2), (c1, c2));
            prop_assert_eq!((s.lost_edge_counter1, s.lost_edge_counter2), (l1, l2));
            prop_assert_eq!((mi.status().counter1, mi.status().counter2), (c1, c2));
        }
    }
}
