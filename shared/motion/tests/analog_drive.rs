//! The analog drive connection (`tandem_motion::plant::analog`) against known answers: the S7
//! analog output word, the position controller's steady-state lag against the manual's formula
//! (`v / Kv` without precontrol, the "[derived] 2 mm at 100 mm/s and Kv = 50", and
//! `(1 - Kpc) v / Kv` with it), the balancing filter, the enable DO / ready DI handshake with
//! its timeout and the loss of ready, and the simulated analog drive (first-order speed loop,
//! speed limit, stop ramp, ready delay, faults, the encoder's raw word wrapping). Property
//! tests with fixed seeds: the command never leaves the output's range, the handshake never
//! drops the enable DO while a setpoint is still applied.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use tandem_motion::plant::analog::{
    output_word, word_to_normalized, AnalogCommand, AnalogConnection, AnalogEnable,
    AnalogEnableStatus, AnalogParams, BalancingFilter, ControllerParams, PositionController,
    SimAnalogDrive, SimAnalogParams, MAX_COMMAND, NOMINAL_WORD, OVERRANGE_WORD, READY_STEP,
};
use tandem_motion::plant::drive::Plant;
use tandem_motion::plant::link::{DriveOutputs, DriveState};
use tandem_motion::plant::mechanics::{EncoderConfig, EncoderKind, Mechanics, Mounting, Scaling};

const MS: i64 = 1_000_000;

/// A linear axis: 10 mm leadscrew, gear 1:1, an encoder of `bits` raw bits with 2^20 counts
/// per motor revolution (about 1e-5 mm).
fn scaling(raw_bits: u8, inverse_drive: bool) -> Scaling {
    Scaling::new(
        &EncoderConfig {
            kind: EncoderKind::Incremental,
            steps_per_revolution: 1 << 20,
            fine_resolution_bits: 0,
            determinable_revolutions: 1,
            raw_bits,
            inverse: false,
            mounting: Mounting::MotorShaft,
        },
        &Mechanics {
            leadscrew_pitch: Some(10.0),
            inverse_drive,
            ..Mechanics::default()
        },
    )
    .unwrap()
}

fn controller(kv: f64, kpc_percent: f64) -> ControllerParams {
    ControllerParams {
        cycle_ns: MS,
        kv,
        kpc_percent,
        velocity_time_constant: 0.004,
        additional_position_time_constant: 0.0,
        // 3000/min on a 10 mm leadscrew.
        reference_velocity: 500.0,
    }
}

/// A connection and a simulated drive run in the process image's order: the drive runs the
/// last cycle with the command latched at the previous boundary, is sampled, latches the
/// command the previous step wrote; the connection reads the sample; the "axis" gives its
/// setpoint; the connection writes the command.
struct Loop {
    conn: AnalogConnection,
    drive: SimAnalogDrive,
    written: AnalogCommand,
    k: i64,
}

impl Loop {
    fn new(kv: f64, kpc: f64, ready: bool, drive: SimAnalogParams, inverse: bool) -> Self {
        let s = scaling(32, inverse);
        let params = AnalogParams {
            controller: controller(kv, kpc),
            enable_timeout_ns: 100 * MS,
            ready,
            scaling: s,
        };
        Self {
            conn: AnalogConnection::new(params, Plant::default(), 0.0).unwrap(),
            drive: SimAnalogDrive::new(drive, s).unwrap(),
            written: AnalogCommand::default(),
            k: 0,
        }
    }

    /// One cycle with the setpoint `(p, v)` and the enable `enable`; returns the inputs read.
    fn cycle(&mut self, p: f64, v: f64, enable: bool) -> tandem_motion::plant::link::DriveInputs {
        if self.k > 0 {
            self.drive.advance(MS);
        }
        let fb = self.drive.feedback();
        self.drive.exchange(&self.written);
        let inputs = self.conn.inputs(self.k * MS, &fb);
        self.written = self.conn.command(&DriveOutputs {
            position: p,
            velocity: v,
            enable,
            position_controlled: true,
            fault_reset: false,
            ..DriveOutputs::default()
        });
        self.k += 1;
        inputs
    }
}

#[test]
fn output_word_is_the_s7_analog_value_representation() {
    assert_eq!(NOMINAL_WORD, 27648);
    assert_eq!(output_word(1.0), 27648);
    assert_eq!(output_word(-1.0), -27648);
    assert_eq!(output_word(0.5), 13824);
    assert_eq!(output_word(0.0), 0);
    // The overrange ends at 32511 (11.759 V): about 117.6 %.
    assert_eq!(output_word(MAX_COMMAND), OVERRANGE_WORD);
    assert_eq!(output_word(2.0), 32511);
    assert_eq!(output_word(-1e300), -32511);
    assert_eq!(output_word(f64::NAN), 0);
    assert_eq!(output_word(f64::INFINITY), 32511);
    assert!((MAX_COMMAND - 1.175_889_756_944_444_4).abs() < 1e-15);
    assert_eq!(word_to_normalized(13824), 0.5);
}

/// Runs the controller on an ideal plant (the actual moves by the command of two cycles before)
/// at constant velocity `v` and returns the control difference after `n` cycles.
fn lag_on_ideal_plant(kv: f64, kpc: f64, v: f64) -> f64 {
    let p = controller(kv, kpc);
    let mut c = PositionController::new(p, 0.0).unwrap();
    let dt = 1e-3;
    let mut actual = 0.0;
    let mut commands = [0.0_f64; 2];
    let mut e = 0.0;
    for k in 0..20_000 {
        let x = v * k as f64 * dt;
        // The command of two cycles ago has acted for the last cycle.
        actual += commands[k % 2] * p.reference_velocity * dt;
        let out = c.step(x, v, actual, true);
        commands[k % 2] = out.normalized;
        e = out.control_difference;
    }
    e
}

#[test]
fn steady_state_lag_is_v_over_kv_without_precontrol() {
    // The manual's derived figure: 100 mm/s at Kv = 50 1/s lags 2 mm.
    let e = lag_on_ideal_plant(50.0, 0.0, 100.0);
    assert!((e - 2.0).abs() < 1e-9, "{e}");
    // v / Kv for other values, and (1 - Kpc) v / Kv with partial precontrol.
    let e = lag_on_ideal_plant(20.0, 0.0, 100.0);
    assert!((e - 5.0).abs() < 1e-9, "{e}");
    let e = lag_on_ideal_plant(50.0, 50.0, 100.0);
    assert!((e - 1.0).abs() < 1e-9, "{e}");
    // Full precontrol: no lag.
    let e = lag_on_ideal_plant(50.0, 100.0, 100.0);
    assert!(e.abs() < 1e-9, "{e}");
}

#[test]
fn steady_state_lag_on_the_simulated_drive() {
    // Through the encoder (1e-5 mm), the output word (1/27648 of 500 mm/s) and a 4 ms speed
    // loop: the mean control difference over the last 0.5 s of 3 s at 100 mm/s.
    for (kpc, expected) in [(0.0, 2.0), (50.0, 1.0), (100.0, 0.0)] {
        let mut l = Loop::new(50.0, kpc, false, SimAnalogParams::example(), false);
        let (mut sum, mut n) = (0.0, 0);
        for k in 0..3000 {
            let t = k as f64 * 1e-3;
            let inp = l.cycle(100.0 * t, 100.0, true);
            if k >= 2500 {
                sum += inp.actual.balanced - inp.actual.p;
                n += 1;
            }
        }
        let mean = sum / f64::from(n);
        assert!(
            (mean - expected).abs() < 1e-3,
            "Kpc {kpc} %: mean lag {mean}, expected {expected}"
        );
        // The velocity from the encoder matches.
        assert!((l.drive.velocity() - 100.0).abs() < 0.05);
    }
}

#[test]
fn balancing_filter_delays_a_ramp_by_the_transport_and_time_constants() {
    // A ramp of 100 units/s: after the transients the filter lags by the one cycle still in
    // the delay line after `push` (the next cycle's reference) plus T_vtc + T_addPtc; each
    // discrete first-order lag delays a ramp by dt / (1 - exp(-dt / tau)) - dt.
    let dt = 1e-3;
    let (tv, ta) = (0.004, 0.002);
    let mut f = BalancingFilter::new(dt, tv, ta, 0.0);
    let mut x = 0.0;
    for k in 0..5000 {
        x = 100.0 * k as f64 * dt;
        f.push(x);
    }
    let lag = |tau: f64| dt / (1.0 - (-dt / tau).exp()) - dt;
    let expected = x - 100.0 * (dt + lag(tv) + lag(ta));
    assert!((f.balanced() - expected).abs() < 1e-9, "{}", f.balanced());
    // About T_vtc + T_addPtc + one cycle (6.5 % off at tau = 2 dt).
    assert!((x - f.balanced() - 100.0 * (dt + tv + ta)).abs() < 0.1);
    f.reset(3.0);
    assert_eq!(f.balanced(), 3.0);
    f.push(3.0);
    assert_eq!(f.balanced(), 3.0);
}

#[test]
fn controller_saturates_at_the_overrange_and_without_position_control_passes_the_velocity() {
    let mut c = PositionController::new(controller(100.0, 100.0), 0.0).unwrap();
    // 10 mm behind the balanced setpoint (at rest at 0) at Kv 100: 1000 mm/s asked, twice
    // the reference velocity: clamped to the overrange.
    let out = c.step(10.0, 0.0, -10.0, true);
    assert_eq!(out.normalized, MAX_COMMAND);
    assert_eq!(out.control_difference, 10.0);
    assert!(out.saturated);
    // The setpoint 10 reaches the balanced setpoint only after the delay line.
    let out = c.step(10.0, 0.0, -10.0, true);
    assert_eq!(
        (out.normalized, out.control_difference),
        (MAX_COMMAND, 10.0)
    );
    let out = c.step(10.0, 250.0, 1e6, false);
    assert_eq!((out.normalized, out.control_difference), (0.5, 0.0));
    assert!(!out.saturated);
    let bad = PositionController::new(
        ControllerParams {
            kpc_percent: 150.1,
            ..controller(1.0, 0.0)
        },
        0.0,
    )
    .unwrap_err();
    assert_eq!(bad.field, "kpc_percent");
    let bad = PositionController::new(
        ControllerParams {
            reference_velocity: 0.0,
            ..controller(1.0, 0.0)
        },
        0.0,
    )
    .unwrap_err();
    assert_eq!(
        bad.to_string(),
        "analog drive: reference_velocity must be positive"
    );
}

#[test]
fn enable_with_ready_waits_for_the_ready_input() {
    let mut e = AnalogEnable::new(50 * MS, true).unwrap();
    // Disabled: DO off.
    let o = e.step(0, false, false, true);
    assert!(!o.enable_do);
    assert_eq!(e.drive_state(), DriveState::Disabled);
    // Request: DO on, waiting for ready (step 4), even if ready shows already.
    let o = e.step(MS, true, true, true);
    assert!(o.enable_do);
    assert_eq!(
        o.status,
        AnalogEnableStatus::WaitingForReady { since_ns: MS }
    );
    assert_eq!(e.drive_state(), DriveState::Enabling { step: READY_STEP });
    // Ready in the next sample: enabled.
    let o = e.step(2 * MS, true, true, true);
    assert_eq!(o.status, AnalogEnableStatus::Enabled);
    assert_eq!(e.drive_state(), DriveState::Operational);
    assert!(o.enable_do);
}

#[test]
fn enable_without_ready_is_at_once() {
    let mut e = AnalogEnable::new(50 * MS, false).unwrap();
    let o = e.step(0, true, false, true);
    assert_eq!(o.status, AnalogEnableStatus::Enabled);
    assert!(o.enable_do);
    // No ready DI: a missing ready is never a loss.
    let o = e.step(MS, true, false, false);
    assert_eq!(o.status, AnalogEnableStatus::Enabled);
}

#[test]
fn ready_that_does_not_come_times_out_naming_the_step() {
    let mut e = AnalogEnable::new(5 * MS, true).unwrap();
    e.step(10 * MS, true, false, true);
    for k in 11..15 {
        let o = e.step(k * MS, true, false, true);
        assert!(o.enable_do, "still waiting at {k} ms");
    }
    // 5 ms after the DO was set.
    let o = e.step(15 * MS, true, false, true);
    assert_eq!(o.status, AnalogEnableStatus::TimedOut);
    assert!(!o.enable_do);
    assert_eq!(
        e.drive_state(),
        DriveState::EnableTimedOut { step: READY_STEP }
    );
    // Latched while the request stays, even if ready comes now.
    let o = e.step(16 * MS, true, true, true);
    assert_eq!(o.status, AnalogEnableStatus::TimedOut);
    // Request removed: disabled; a new request starts over.
    assert_eq!(
        e.step(17 * MS, false, true, true).status,
        AnalogEnableStatus::Disabled
    );
    assert_eq!(
        e.step(18 * MS, true, true, true).status,
        AnalogEnableStatus::WaitingForReady { since_ns: 18 * MS }
    );
}

#[test]
fn loss_of_ready_removes_the_enable_at_once() {
    let mut e = AnalogEnable::new(5 * MS, true).unwrap();
    e.step(0, true, false, true);
    e.step(MS, true, true, true);
    // Ready drops while enabled, with a setpoint still applied: the DO goes at once.
    let o = e.step(2 * MS, true, false, false);
    assert_eq!(o.status, AnalogEnableStatus::ReadyLost);
    assert!(!o.enable_do);
    // The axis sees a drive that shut down (alarm 421 supplement 3 while enabled).
    assert_eq!(e.drive_state(), DriveState::Disabled);
    // Latched until the request is removed, even when ready returns.
    assert_eq!(
        e.step(3 * MS, true, true, true).status,
        AnalogEnableStatus::ReadyLost
    );
    assert_eq!(
        e.step(4 * MS, false, true, true).status,
        AnalogEnableStatus::Disabled
    );
}

#[test]
fn disable_keeps_the_enable_until_the_setpoint_is_zero() {
    let mut e = AnalogEnable::new(5 * MS, false).unwrap();
    e.step(0, true, false, false);
    // Request removed while the setpoint written is not 0: the DO stays.
    let o = e.step(MS, false, false, false);
    assert_eq!(o.status, AnalogEnableStatus::Disabling);
    assert!(o.enable_do);
    let o = e.step(2 * MS, false, false, false);
    assert!(o.enable_do);
    // The setpoint reached 0: the DO drops.
    let o = e.step(3 * MS, false, false, true);
    assert_eq!(o.status, AnalogEnableStatus::Disabled);
    assert!(!o.enable_do);
    assert!(AnalogEnable::new(0, true).is_err());
}

#[test]
fn connection_disables_with_a_zero_word_before_the_enable_drops() {
    let mut l = Loop::new(10.0, 100.0, true, SimAnalogParams::example(), false);
    // Enable: DO at the first command, ready 10 ms after the drive saw it.
    let mut enabled_at = None;
    for k in 0..30 {
        let inp = l.cycle(0.0, 0.0, true);
        if inp.state == DriveState::Operational && enabled_at.is_none() {
            enabled_at = Some(k);
        }
    }
    // Inputs of cycle 0 decide with no request yet; the DO goes with command 1, the drive
    // latches it at boundary 2 and is ready 10 ms later (boundary 12), read by cycle 12.
    assert_eq!(enabled_at, Some(12));
    // Move, then remove the enable mid-move.
    for k in 0..100 {
        let t = k as f64 * 1e-3;
        l.cycle(50.0 * t, 50.0, true);
    }
    assert!(l.written.words.word > 0);
    l.cycle(5.0, 50.0, false);
    // The command of the cycle the enable is removed is 0; the DO is still on.
    assert_eq!(l.written, AnalogCommand::new(true, 0));
    l.cycle(5.0, 0.0, false);
    assert_eq!(l.written, AnalogCommand::new(false, 0));
}

#[test]
fn connection_reports_a_lost_ready_and_a_fault_is_reset_by_removing_the_enable() {
    let mut l = Loop::new(10.0, 100.0, true, SimAnalogParams::example(), false);
    for _ in 0..20 {
        l.cycle(0.0, 0.0, true);
    }
    assert_eq!(l.conn.status().enable, AnalogEnableStatus::Enabled);
    l.drive.amplifier_mut().inject_fault();
    // The drive's ready output is off at the next boundary; the connection reads it there.
    let inp = l.cycle(0.0, 0.0, true);
    assert_eq!(inp.state, DriveState::Disabled);
    assert_eq!(l.conn.status().enable, AnalogEnableStatus::ReadyLost);
    assert!(!l.written.enable);
    // The axis removes its enable; the fault stays while its cause does.
    for _ in 0..5 {
        l.cycle(0.0, 0.0, false);
    }
    assert!(l.drive.amplifier().in_fault());
    l.drive.amplifier_mut().clear_fault_cause();
    l.cycle(0.0, 0.0, false);
    l.cycle(0.0, 0.0, false);
    assert!(!l.drive.amplifier().in_fault());
    // Enabled again.
    for _ in 0..20 {
        l.cycle(0.0, 0.0, true);
    }
    assert_eq!(l.conn.status().enable, AnalogEnableStatus::Enabled);
}

#[test]
fn inverse_drive_inverts_the_command_and_the_load_still_follows() {
    let mut l = Loop::new(50.0, 100.0, false, SimAnalogParams::example(), true);
    let mut last = None;
    for k in 0..2000 {
        let t = k as f64 * 1e-3;
        last = Some(l.cycle(100.0 * t, 100.0, true));
    }
    assert!(l.written.words.word < 0, "{:?}", l.written);
    assert!((l.drive.velocity() - 100.0).abs() < 0.05);
    let a = last.unwrap().actual;
    assert!((a.balanced - a.p).abs() < 1e-3, "{a:?}");
    assert!((a.p - 199.3).abs() < 0.05, "{a:?}");
}

#[test]
fn simulated_drive_speed_loop_is_a_first_order_lag_with_a_limit() {
    let s = scaling(32, false);
    let params = SimAnalogParams {
        ready_delay: 0.0,
        ..SimAnalogParams::example()
    };
    let mut d = SimAnalogDrive::new(params, s).unwrap();
    d.exchange(&AnalogCommand::new(true, 13824));
    // 50 % of 3000/min, after one time constant 63.2 % of it.
    d.advance(4 * MS);
    let expected = 1500.0 * (1.0 - (-1.0_f64).exp());
    assert!((d.speed() - expected).abs() < 1e-9, "{}", d.speed());
    // Position: integral of the lag, 1500/60 (t - tau (1 - e^-t/tau)) revolutions x 10 mm.
    let revs = 25.0 * (0.004 - 0.004 * (1.0 - (-1.0_f64).exp()));
    assert!((d.position() - 10.0 * revs).abs() < 1e-12);
    assert!(d.feedback().ready);
    // The overrange asks 117.6 % = 3527/min; the limit is 3300/min.
    d.exchange(&AnalogCommand::new(true, OVERRANGE_WORD));
    d.advance(1000 * MS);
    assert!((d.speed() - 3300.0).abs() < 1e-6, "{}", d.speed());
    // Without enable: the stop ramp, 3000/min in 0.1 s: 3300/min takes 0.11 s.
    d.exchange(&AnalogCommand::default());
    d.advance(50 * MS);
    assert!((d.speed() - 1800.0).abs() < 1e-9, "{}", d.speed());
    let before = d.position();
    d.advance(100 * MS);
    assert_eq!(d.speed(), 0.0);
    // 1800/min = 30/s braking at 500/s²: 0.9 revolutions, 9 mm.
    assert!((d.position() - before - 9.0).abs() < 1e-9);
    assert!(!d.feedback().ready);
}

#[test]
fn simulated_drive_ready_delay_offset_and_fault_latch() {
    let s = scaling(32, false);
    let params = SimAnalogParams {
        offset: 0.1,
        ..SimAnalogParams::example()
    };
    let mut d = SimAnalogDrive::new(params, s).unwrap();
    d.exchange(&AnalogCommand::new(true, 0));
    d.advance(9 * MS);
    assert!(!d.feedback().ready, "ready 10 ms after the enable");
    d.advance(MS);
    assert!(d.feedback().ready);
    // 0.1 V offset: 1 % of 3000/min with a 0 command.
    d.advance(1000 * MS);
    assert!((d.speed() - 30.0).abs() < 1e-9);
    d.amplifier_mut().inject_fault();
    assert!(!d.feedback().ready);
    // Enable off with the cause present: still in fault.
    d.exchange(&AnalogCommand::default());
    assert!(d.amplifier().in_fault());
    d.amplifier_mut().clear_fault_cause();
    d.exchange(&AnalogCommand::default());
    assert!(!d.amplifier().in_fault());
    let bad = SimAnalogDrive::new(
        SimAnalogParams {
            offset: 10.5,
            ..SimAnalogParams::example()
        },
        s,
    )
    .unwrap_err();
    assert_eq!(bad.to_string(), "analog drive: offset is out of range");
    let bad = SimAnalogDrive::new(
        SimAnalogParams {
            ramp_down_time: 0.0,
            ..SimAnalogParams::example()
        },
        s,
    )
    .unwrap_err();
    assert_eq!(bad.field, "ramp_down_time");
}

#[test]
fn encoder_raw_word_wraps_and_the_connection_counts_on() {
    // A 16-bit counter wraps every 65536 counts (0.625 mm); 300 mm is 480 wraps.
    let s = scaling(16, false);
    let params = AnalogParams {
        controller: controller(50.0, 100.0),
        enable_timeout_ns: 100 * MS,
        ready: false,
        scaling: s,
    };
    let mut conn = AnalogConnection::new(params, Plant::default(), 0.0).unwrap();
    let mut d = SimAnalogDrive::new(SimAnalogParams::example(), s).unwrap();
    let mut written = AnalogCommand::default();
    for k in 0..4000i64 {
        if k > 0 {
            d.advance(MS);
        }
        let fb = d.feedback();
        d.exchange(&written);
        let inp = conn.inputs(k * MS, &fb);
        // The actual equals the drive's load position to the count.
        assert!((inp.actual.p - d.position()).abs() < 1e-5, "k {k}");
        let t = k as f64 * 1e-3;
        let x = if t < 2.0 { 150.0 * t } else { 300.0 };
        let v = if t < 2.0 { 150.0 } else { 0.0 };
        written = conn.command(&DriveOutputs {
            position: x,
            velocity: v,
            enable: true,
            position_controlled: true,
            fault_reset: false,
            ..DriveOutputs::default()
        });
    }
    assert!((d.position() - 300.0).abs() < 1e-3, "{}", d.position());
    assert!(conn.count().unwrap() > 1 << 16);
}

fn config(seed: u64) -> ProptestConfig {
    ProptestConfig {
        cases: 512,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(seed),
        ..ProptestConfig::default()
    }
}

fn any_number() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1e4..1e4_f64,
        proptest::num::f64::ANY,
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
    ]
}

proptest! {
    #![proptest_config(config(0xA7A1_0601))]

    /// Whatever the setpoints and actual values, the command is within the output's range and
    /// its word within ±32511.
    #[test]
    fn command_is_always_within_the_normalized_range(
        kv in 0.0..2000.0_f64,
        kpc in 0.0..150.0_f64,
        steps in proptest::collection::vec((any_number(), any_number(), any_number(), any::<bool>()), 1..40),
    ) {
        let mut c = PositionController::new(controller(kv, kpc), 0.0).unwrap();
        for (p, v, a, pc) in steps {
            let out = c.step(p, v, a, pc);
            prop_assert!(out.normalized.abs() <= MAX_COMMAND, "{out:?}");
            let w = output_word(out.normalized);
            prop_assert!((-32511..=32511).contains(&w));
        }
    }

    /// The word of any number is within ±32511 and round-trips a word exactly.
    #[test]
    fn output_word_is_within_its_range(x in any_number(), w in -32511i16..=32511) {
        let word = output_word(x);
        prop_assert!((-32511..=32511).contains(&word));
        prop_assert_eq!(output_word(word_to_normalized(w)), w);
    }

    /// The enable DO never drops while a non-zero setpoint is applied, except on a lost ready
    /// or a timeout; it is never set in those states; the drive is never enabled without a
    /// ready sample (when one is configured).
    #[test]
    fn enable_do_drops_only_at_zero_setpoint_or_on_loss(
        ready_configured in any::<bool>(),
        steps in proptest::collection::vec((any::<bool>(), any::<bool>(), any::<bool>()), 1..200),
    ) {
        let mut e = AnalogEnable::new(20 * MS, ready_configured).unwrap();
        let mut was_on = false;
        for (k, (request, ready, zero)) in steps.into_iter().enumerate() {
            let before = e.status();
            let o = e.step(k as i64 * MS, request, ready, zero);
            let lost = matches!(o.status, AnalogEnableStatus::ReadyLost | AnalogEnableStatus::TimedOut);
            if lost {
                prop_assert!(!o.enable_do);
            }
            if was_on && !o.enable_do && !lost {
                // Dropped: the setpoint was 0, or nothing was commanded yet.
                let waiting = matches!(before, AnalogEnableStatus::WaitingForReady { .. });
                prop_assert!(zero || waiting, "{before:?} -> {o:?}");
            }
            if o.status == AnalogEnableStatus::Enabled && ready_configured {
                prop_assert!(ready);
                prop_assert!(before != AnalogEnableStatus::Disabled);
            }
            was_on = o.enable_do;
        }
    }
}
