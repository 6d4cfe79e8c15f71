//! The simulated CiA 402 servo drive against physics and the IEC 61800-7-201 (CiA 402) drive
//! profile: enabled through the controller's own [`EnableSequence`], stepped cycle by cycle
//! (exchange, advance, feedback) as an axis drives a real drive.
//!
//! Known answers come from closed forms: constant deceleration (quick stop), the energy of a
//! coasting motor against coulomb friction, the torque limit times the inertia, the position at
//! a known instant of a constant-velocity motion (touch probe), and the 32-bit counter wrap.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use core::f64::consts::TAU;

use tandem_motion::plant::cia402::{
    digital_inputs, statusword, touch_probe, Cia402State, DriveCommand, DriveFeedback,
    EnableSequence, EnableStatus, ModeOfOperation, PowerRequest, QuickStopOption,
};
use tandem_motion::plant::servo::{ServoParams, SimServo, SimServoError, FOLLOWING_ERROR_CODE};
use tandem_testkit::counting::measure;

tandem_testkit::counting_allocator!();

const CYCLE: i64 = 1_000_000;
const CSP: i8 = ModeOfOperation::CyclicSynchronousPosition.value();
const CSV: i8 = ModeOfOperation::CyclicSynchronousVelocity.value();
const CST: i8 = ModeOfOperation::CyclicSynchronousTorque.value();

/// One cycle: RxPDO in at the boundary, the cycle's motion, TxPDO out at the next boundary.
fn cycle(servo: &mut SimServo, cmd: &DriveCommand) -> DriveFeedback {
    servo.exchange(cmd);
    servo.advance(CYCLE);
    servo.feedback()
}

/// Frictionless parameters (closed forms are then exact).
fn frictionless() -> ServoParams {
    ServoParams {
        viscous_friction: 0.0,
        coulomb_friction: 0.0,
        ..ServoParams::example(CYCLE)
    }
}

/// Powers the drive up and enables it in `mode` through the enable handshake, sending the
/// actual position as target (common practice before enabling CSP). Returns the last feedback.
fn enable(servo: &mut SimServo, mode: i8) -> DriveFeedback {
    let mut seq = EnableSequence::new(50 * CYCLE).unwrap();
    let request = PowerRequest {
        enable: true,
        ..PowerRequest::default()
    };
    let mut fb = servo.feedback();
    for k in 0..10 {
        let out = seq.step(k * CYCLE, request, fb.statusword);
        if out.status == EnableStatus::Enabled {
            return fb;
        }
        let cmd = DriveCommand {
            controlword: out.controlword,
            mode,
            target_position: fb.position_actual,
            ..DriveCommand::default()
        };
        fb = cycle(servo, &cmd);
    }
    panic!("not enabled: {:?}", servo.state());
}

fn csv(velocity: i32) -> DriveCommand {
    DriveCommand {
        controlword: 0x000F,
        mode: CSV,
        target_velocity: velocity,
        ..DriveCommand::default()
    }
}

/// Runs the drive in CSV to `velocity` (increments/s) and lets the loop settle.
fn spin_up(servo: &mut SimServo, velocity: i32) {
    enable(servo, CSV);
    for _ in 0..400 {
        cycle(servo, &csv(velocity));
    }
    let v = servo.velocity();
    assert!(
        (v - f64::from(velocity)).abs() < 1e-3 * f64::from(velocity).abs(),
        "{v}"
    );
}

fn state_of(fb: &DriveFeedback) -> Option<Cia402State> {
    Cia402State::from_statusword(fb.statusword)
}

#[test]
fn power_up_and_enable_in_three_exchanges_after_the_self_test() {
    let mut servo = SimServo::new(ServoParams::example(CYCLE)).unwrap();
    assert_eq!(servo.state(), Cia402State::NotReadyToSwitchOn);
    assert_eq!(
        cycle(&mut servo, &DriveCommand::default()).statusword,
        0x0200
    );
    assert_eq!(
        cycle(&mut servo, &DriveCommand::default()).statusword,
        0x0240
    );
    let fb = enable(&mut servo, CSP);
    assert_eq!(
        fb.statusword, 0x1237,
        "operation enabled, remote, follows the command value"
    );
    assert_eq!(fb.mode_display, CSP);
    // The plant's switches show in 0x60FD.
    servo.set_digital_inputs(digital_inputs::POSITIVE_LIMIT | digital_inputs::HOME_SWITCH);
    assert_eq!(servo.feedback().digital_inputs, 0b110);
    // An unsupported mode is not taken over.
    let fb = cycle(
        &mut servo,
        &DriveCommand {
            controlword: 0x000F,
            mode: 1,
            target_position: fb.position_actual,
            ..DriveCommand::default()
        },
    );
    assert_eq!(fb.mode_display, CSP);
}

/// The CSP set-point of cycle `k` of a move from 0: constant acceleration `a` (increments/s²)
/// up to `v` (increments/s), then constant velocity. Returns the target at the end of the cycle
/// and the mean velocity over it (the velocity feedforward).
fn ramp(k: i64, a: f64, v: f64) -> (f64, f64) {
    let t_acc = v / a;
    let p = |t: f64| {
        if t <= t_acc {
            0.5 * a * t * t
        } else {
            0.5 * a * t_acc * t_acc + v * (t - t_acc)
        }
    };
    let t0 = k as f64 * 1e-3;
    let t1 = t0 + 1e-3;
    (p(t1), (p(t1) - p(t0)) / 1e-3)
}

/// Runs the ramp of [`ramp`] (1e8 increments/s² to 1e7 increments/s) in CSP for `cycles`
/// from `start`, with velocity feedforward and, if `torque_feedforward`, the acceleration
/// torque as torque offset. Returns the largest |following error| while accelerating (and 200
/// ms after) and after that.
fn run_csp(servo: &mut SimServo, start: i32, cycles: i64, torque_feedforward: bool) -> (i32, i32) {
    let params = *servo.params();
    let k_rad = params.increments_per_revolution as f64 / TAU;
    let (a, v) = (1e8, 1e7);
    let mut worst_accel = 0i32;
    let mut worst_settled = 0i32;
    for k in 0..cycles {
        let (p, ff) = ramp(k, a, v);
        // The acceleration ends with cycle 99 (at v / a = 100 ms).
        let accelerating = k < 100;
        let torque = if torque_feedforward && accelerating {
            params.inertia * a / k_rad / params.rated_torque * 1e3
        } else {
            0.0
        };
        let cmd = DriveCommand {
            controlword: 0x000F,
            mode: CSP,
            target_position: start.wrapping_add(p.round() as i32),
            velocity_offset: ff.round() as i32,
            torque_offset: torque.round() as i16,
            ..DriveCommand::default()
        };
        let fb = cycle(servo, &cmd);
        assert_eq!(
            state_of(&fb),
            Some(Cia402State::OperationEnabled),
            "cycle {k}"
        );
        // The drive's following error is the target minus position actual.
        assert_eq!(
            fb.following_error,
            cmd.target_position.wrapping_sub(fb.position_actual)
        );
        if k < 300 {
            worst_accel = worst_accel.max(fb.following_error.abs());
        } else {
            worst_settled = worst_settled.max(fb.following_error.abs());
        }
    }
    (worst_accel, worst_settled)
}

#[test]
fn csp_at_constant_velocity_with_feedforward_settles_within_one_increment() {
    let params = ServoParams::example(CYCLE);
    let mut servo = SimServo::new(params).unwrap();
    let start = enable(&mut servo, CSP).position_actual;
    let (worst_accel, worst_settled) = run_csp(&mut servo, start, 700, false);
    // While accelerating without torque feedforward the velocity loop needs a velocity error
    // J·a/Kp to make the acceleration torque, which the position loop makes from a lag of
    // J·a/(Kp·Kv): 1e-4 · 1e8 / (0.1 · 100) = 1000 increments at most.
    let k_rad = params.increments_per_revolution as f64 / TAU;
    let lag = params.inertia * 1e8 / k_rad / (params.velocity_loop_gain * params.kv) * k_rad;
    println!("CSP following error: accelerating {worst_accel} increments (bound {lag:.0}), settled {worst_settled}");
    assert!(f64::from(worst_accel) <= lag, "{worst_accel}");
    // At constant velocity the PI velocity loop has taken up the friction and the velocity
    // feedforward the motion: the position at each sample instant is the set-point; what is
    // left is the counter's quantization.
    assert!(worst_settled <= 1, "{worst_settled}");
    assert!((servo.velocity() - 1e7).abs() < 1.0, "{}", servo.velocity());
    // With the acceleration torque fed forward (0x60B2) the lag while accelerating shrinks.
    let mut servo = SimServo::new(params).unwrap();
    let start = enable(&mut servo, CSP).position_actual;
    let (worst_accel_ff, worst_settled_ff) = run_csp(&mut servo, start, 700, true);
    println!("with torque feedforward: accelerating {worst_accel_ff} increments, settled {worst_settled_ff}");
    assert!(worst_accel_ff * 4 < worst_accel, "{worst_accel_ff}");
    assert!(worst_settled_ff <= 1);
}

#[test]
fn csp_without_feedforward_lags_by_v_over_kv() {
    // S7-1500T Motion Control V4.0 function manual, 2.5 "Closed loop": without precontrol the
    // steady-state lag is about v / Kv.
    let mut servo = SimServo::new(ServoParams::example(CYCLE)).unwrap();
    let start = enable(&mut servo, CSP).position_actual;
    let (a, v) = (1e8, 1e6);
    let mut fb = DriveFeedback::default();
    for k in 0..1500 {
        let (p, _) = ramp(k, a, v);
        let cmd = DriveCommand {
            controlword: 0x000F,
            mode: CSP,
            target_position: start.wrapping_add(p.round() as i32),
            ..DriveCommand::default()
        };
        fb = cycle(&mut servo, &cmd);
    }
    let lag = v / ServoParams::example(CYCLE).kv;
    assert!(
        (f64::from(fb.following_error) - lag).abs() <= 2.0,
        "{} vs {lag}",
        fb.following_error
    );
}

#[test]
fn csv_step_accelerates_at_the_torque_limit() {
    let params = ServoParams::example(CYCLE);
    let mut servo = SimServo::new(params).unwrap();
    enable(&mut servo, CSV);
    // 5e7 increments/s ≈ 300 rad/s, max torque 0x6072 = 100 % of the rated torque.
    let target = 50_000_000;
    let cmd = DriveCommand {
        max_torque: 1000,
        ..csv(target)
    };
    let k = params.increments_per_revolution as f64 / TAU;
    let limit = params.rated_torque;
    let mut saturated_cycles = 0;
    let mut previous_v = servo.velocity();
    let mut peak = 0.0f64;
    for _ in 0..200 {
        let fb = cycle(&mut servo, &cmd);
        let v = servo.velocity();
        peak = peak.max(v);
        if fb.statusword & statusword::INTERNAL_LIMIT_ACTIVE != 0 {
            saturated_cycles += 1;
            assert_eq!(
                fb.torque_actual, 1000,
                "torque at the limit while accelerating"
            );
            // The acceleration is the limit less the friction over the inertia.
            let w = v / k;
            let expected =
                (limit - params.coulomb_friction - params.viscous_friction * w) / params.inertia;
            let got = (v - previous_v) / k / 1e-3;
            assert!(
                (got - expected).abs() < 0.01 * expected,
                "{got} vs {expected}"
            );
        }
        previous_v = v;
    }
    // 300 rad/s at about 12,500 rad/s²: some 24 cycles at the limit.
    let t_acc = f64::from(target) / k / ((limit - params.coulomb_friction) / params.inertia);
    println!(
        "CSV step: {saturated_cycles} cycles at the torque limit (t_acc {t_acc:.4} s), peak {peak}"
    );
    assert!(
        (saturated_cycles as f64 - t_acc * 1e3).abs() <= 2.0,
        "{saturated_cycles}"
    );
    assert!(peak < 1.02 * f64::from(target), "overshoot {peak}");
    assert!((servo.velocity() - f64::from(target)).abs() < 1e-3 * f64::from(target));
    // Without max torque from the controller the drive's own limit (300 %) applies.
    let mut servo = SimServo::new(params).unwrap();
    enable(&mut servo, CSV);
    let fb = cycle(&mut servo, &csv(target));
    assert_eq!(fb.torque_actual, 3000);
}

#[test]
fn cst_applies_the_torque_within_the_limit() {
    let params = frictionless();
    let mut servo = SimServo::new(params).unwrap();
    enable(&mut servo, CST);
    let cmd = DriveCommand {
        controlword: 0x000F,
        mode: CST,
        target_torque: 400,
        torque_offset: 100,
        ..DriveCommand::default()
    };
    let fb = cycle(&mut servo, &cmd);
    assert_eq!(fb.torque_actual, 500);
    let k = params.increments_per_revolution as f64 / TAU;
    let expected = 0.5 * params.rated_torque / params.inertia * 1e-3 * k;
    assert!((servo.velocity() - expected).abs() < 1e-6 * expected);
    let fb = cycle(
        &mut servo,
        &DriveCommand {
            target_torque: 5000,
            ..cmd
        },
    );
    assert_eq!(fb.torque_actual, 3000);
    assert_ne!(fb.statusword & statusword::INTERNAL_LIMIT_ACTIVE, 0);
}

#[test]
fn an_injected_fault_goes_through_fault_reaction_to_fault() {
    // At standstill: fault reaction active within one cycle, fault the cycle after.
    let mut servo = SimServo::new(ServoParams::example(CYCLE)).unwrap();
    let fb = enable(&mut servo, CSV);
    let hold = DriveCommand {
        controlword: 0x000F,
        mode: CSV,
        target_position: fb.position_actual,
        ..DriveCommand::default()
    };
    servo.inject_fault(0x2310).unwrap();
    let fb = cycle(&mut servo, &hold);
    assert_eq!(state_of(&fb), Some(Cia402State::FaultReactionActive));
    assert_eq!(fb.statusword & 0x6F, 0x0F);
    assert_ne!(fb.statusword & statusword::FAULT, 0);
    assert_eq!(fb.error_code, 0x2310);
    let fb = cycle(&mut servo, &hold);
    assert_eq!(state_of(&fb), Some(Cia402State::Fault));
    assert_eq!(fb.statusword, 0x0208);
    assert_eq!(fb.error_code, 0x2310);
    // The cause is still there: the fault reset edge is refused.
    cycle(
        &mut servo,
        &DriveCommand {
            controlword: 0x0080,
            ..hold
        },
    );
    let fb = cycle(
        &mut servo,
        &DriveCommand {
            controlword: 0x0000,
            ..hold
        },
    );
    assert_eq!(state_of(&fb), Some(Cia402State::Fault));
    servo.clear_fault_cause();
    let fb = cycle(
        &mut servo,
        &DriveCommand {
            controlword: 0x0080,
            ..hold
        },
    );
    assert_eq!(state_of(&fb), Some(Cia402State::SwitchOnDisabled));
    assert_eq!(fb.error_code, 0);
    assert_eq!(servo.inject_fault(0), Err(SimServoError::NoErrorCode));
}

#[test]
fn a_fault_while_moving_brakes_on_the_quick_stop_deceleration_then_faults() {
    let params = frictionless();
    let mut servo = SimServo::new(params).unwrap();
    let target = 20_000_000;
    spin_up(&mut servo, target);
    let w0 = servo.velocity() / (params.increments_per_revolution as f64 / TAU);
    servo.inject_fault(0x4310).unwrap();
    let fb = cycle(&mut servo, &csv(target));
    assert_eq!(state_of(&fb), Some(Cia402State::FaultReactionActive));
    assert_eq!(fb.error_code, 0x4310);
    assert!(fb.torque_actual < 0, "braking: {}", fb.torque_actual);
    let t_stop = w0 / params.quick_stop_deceleration;
    let braking_cycles = (t_stop * 1e3).ceil() as usize;
    let mut states = vec![state_of(&fb)];
    for _ in 0..braking_cycles + 2 {
        states.push(state_of(&cycle(&mut servo, &csv(target))));
    }
    // Fault reaction until the cycle in which the motor stops, fault at the next exchange.
    let fra = states
        .iter()
        .filter(|&&s| s == Some(Cia402State::FaultReactionActive))
        .count();
    assert_eq!(fra, braking_cycles, "t_stop {t_stop}");
    assert_eq!(states.last(), Some(&Some(Cia402State::Fault)));
    assert_eq!(servo.velocity(), 0.0);
}

#[test]
fn the_drive_raises_its_own_following_error_fault_in_csp() {
    let params = ServoParams {
        following_error_window: 5_000,
        ..ServoParams::example(CYCLE)
    };
    let mut servo = SimServo::new(params).unwrap();
    let start = enable(&mut servo, CSP).position_actual;
    // A set-point that jumps by 20,000 increments: beyond the window at once.
    let cmd = DriveCommand {
        controlword: 0x000F,
        mode: CSP,
        target_position: start.wrapping_add(20_000),
        ..DriveCommand::default()
    };
    let fb = cycle(&mut servo, &cmd);
    assert_eq!(state_of(&fb), Some(Cia402State::OperationEnabled));
    assert_ne!(fb.statusword & statusword::FOLLOWING_ERROR, 0);
    assert!(fb.following_error > 5_000, "{}", fb.following_error);
    let fb = cycle(&mut servo, &cmd);
    assert_eq!(state_of(&fb), Some(Cia402State::FaultReactionActive));
    assert_eq!(fb.error_code, FOLLOWING_ERROR_CODE);
    // Monitoring off (0xFFFFFFFF): no fault.
    let mut servo = SimServo::new(ServoParams {
        following_error_window: u32::MAX,
        ..params
    })
    .unwrap();
    let start = enable(&mut servo, CSP).position_actual;
    for _ in 0..5 {
        let fb = cycle(
            &mut servo,
            &DriveCommand {
                target_position: start.wrapping_add(20_000),
                ..cmd
            },
        );
        assert_eq!(state_of(&fb), Some(Cia402State::OperationEnabled));
        assert_eq!(fb.statusword & statusword::FOLLOWING_ERROR, 0);
    }
}

/// Quick stop from `velocity` with `option`; returns the states seen after the quick stop
/// command, the initial velocity (increments/s) and the distance to standstill (increments).
fn quick_stop(
    params: ServoParams,
    velocity: i32,
    cycles: usize,
) -> (SimServo, Vec<Cia402State>, f64, f64) {
    let mut servo = SimServo::new(params).unwrap();
    spin_up(&mut servo, velocity);
    let v0 = servo.velocity();
    let p0 = servo.position();
    let mut states = Vec::new();
    let mut stopped_at = None;
    for _ in 0..cycles {
        cycle(
            &mut servo,
            &DriveCommand {
                controlword: 0x0002,
                ..csv(velocity)
            },
        );
        states.push(servo.state());
        if servo.velocity() == 0.0 && stopped_at.is_none() {
            stopped_at = Some(servo.position());
        }
    }
    (servo, states, v0, stopped_at.unwrap_or(f64::NAN) - p0)
}

#[test]
fn quick_stop_brakes_on_the_quick_stop_deceleration_and_ends_per_0x605a() {
    let params = frictionless();
    let k = params.increments_per_revolution as f64 / TAU;
    let a = params.quick_stop_deceleration * k; // increments/s²
                                                // Option 2: stop on the quick stop ramp, then switch on disabled (transition 12).
    let (_, states, v0, distance) = quick_stop(params, 30_000_000, 200);
    let t_stop = v0 / a;
    let braking = (t_stop * 1e3).ceil() as usize;
    assert_eq!(
        states
            .iter()
            .filter(|&&s| s == Cia402State::QuickStopActive)
            .count(),
        braking
    );
    assert_eq!(states.get(braking), Some(&Cia402State::SwitchOnDisabled));
    assert!(
        (distance - v0 * v0 / (2.0 * a)).abs() < 1e-6 * distance,
        "{distance} {}",
        v0 * v0 / (2.0 * a)
    );
    // With friction the drive brakes with less torque: still the configured deceleration.
    let (_, _, v0f, distance_f) = quick_stop(ServoParams::example(CYCLE), 30_000_000, 200);
    assert!(
        (distance_f - v0f * v0f / (2.0 * a)).abs() < 1e-4 * distance_f,
        "{distance_f}"
    );
    // Option 6: stays in quick stop active, at standstill with target reached; enable
    // operation takes transition 16.
    let stay = ServoParams {
        quick_stop_option: QuickStopOption::QuickStopRampStay,
        ..params
    };
    let (mut servo, states, _, _) = quick_stop(stay, 30_000_000, 200);
    assert!(states.iter().all(|&s| s == Cia402State::QuickStopActive));
    let fb = servo.feedback();
    assert_eq!(
        fb.statusword, 0x0617,
        "quick stop active, remote, target reached"
    );
    assert_eq!(fb.velocity_actual, 0);
    assert_eq!(servo.exchange(&csv(0)).map(|t| t.number), Some(16));
    // Option 3: at the current (torque) limit.
    let limit = ServoParams {
        quick_stop_option: QuickStopOption::CurrentLimit,
        ..params
    };
    let (_, _, v0, distance) = quick_stop(limit, 30_000_000, 50);
    let a_limit = 3.0 * params.rated_torque / params.inertia * k;
    assert!((distance - v0 * v0 / (2.0 * a_limit)).abs() < 1e-6 * distance);
    // Option 0: the drive function is disabled; the motor coasts (no friction: no change).
    let coast = ServoParams {
        quick_stop_option: QuickStopOption::DisableDrive,
        ..params
    };
    let (servo, states, v0, _) = quick_stop(coast, 30_000_000, 3);
    assert_eq!(states.first(), Some(&Cia402State::QuickStopActive));
    assert_eq!(states.get(1), Some(&Cia402State::SwitchOnDisabled));
    assert!((servo.velocity() - v0).abs() < 1e-9 * v0);
}

#[test]
fn coulomb_friction_stops_a_coasting_motor_as_the_energy_predicts() {
    let params = ServoParams {
        viscous_friction: 0.0,
        coulomb_friction: 0.05,
        ..ServoParams::example(CYCLE)
    };
    let k = params.increments_per_revolution as f64 / TAU;
    let mut servo = SimServo::new(params).unwrap();
    spin_up(&mut servo, 16_000_000); // about 96 rad/s
    let w0 = servo.velocity() / k;
    let p0 = servo.position();
    // Disable voltage: transition 9, no torque; only the friction decelerates.
    let mut cycles = 0;
    while servo.velocity() != 0.0 {
        let fb = cycle(&mut servo, &DriveCommand::default());
        assert_eq!(fb.torque_actual, 0);
        cycles += 1;
        assert!(cycles < 10_000);
    }
    // Energy: ½ J ω0² = c θ; time: J ω0 / c.
    let theta = 0.5 * params.inertia * w0 * w0 / params.coulomb_friction;
    let t_stop = params.inertia * w0 / params.coulomb_friction;
    assert_eq!(cycles, (t_stop * 1e3).ceil() as i64, "t_stop {t_stop}");
    let travelled = (servo.position() - p0) / k;
    assert!(
        (travelled - theta).abs() < 1e-9 * theta,
        "{travelled} vs {theta}"
    );
    // And it stays: static friction holds it.
    let p = servo.position();
    cycle(&mut servo, &DriveCommand::default());
    assert_eq!(servo.position(), p);
}

/// A frictionless motor coasting at constant velocity (after a spin-up, voltage disabled).
fn coasting(params: ServoParams, velocity: i32) -> SimServo {
    let mut servo = SimServo::new(params).unwrap();
    spin_up(&mut servo, velocity);
    cycle(&mut servo, &DriveCommand::default());
    assert_eq!(servo.state(), Cia402State::SwitchOnDisabled);
    servo
}

fn probe_cmd(function: u16) -> DriveCommand {
    DriveCommand {
        touch_probe_function: function,
        ..DriveCommand::default()
    }
}

const TP1_FIRST_BOTH: u16 =
    touch_probe::ENABLE | touch_probe::SAMPLE_POSITIVE | touch_probe::SAMPLE_NEGATIVE;

#[test]
fn a_touch_probe_edge_latches_the_position_at_its_instant() {
    let mut servo = coasting(frictionless(), 12_345_678);
    for (offset, rising) in [
        (123_457, true),
        (999_999, false),
        (0, true),
        (500_000, false),
    ] {
        // Re-arm: enable bit clear for one exchange, then set.
        cycle(&mut servo, &probe_cmd(0));
        servo.exchange(&probe_cmd(TP1_FIRST_BOTH));
        let p0 = servo.position();
        let v = servo.velocity();
        servo.probe_edge(1, rising, offset).unwrap();
        servo.advance(CYCLE);
        let fb = servo.feedback();
        let exact = p0 + v * offset as f64 * 1e-9;
        // The latch is the counter value (floor) of the exact position at the instant: below
        // it by less than one increment. Rounding in the model is ~1e-9 increment here.
        let (value, stored) = if rising {
            (
                fb.touch_probe_1_positive,
                touch_probe::STATUS_POSITIVE_STORED,
            )
        } else {
            (
                fb.touch_probe_1_negative,
                touch_probe::STATUS_NEGATIVE_STORED,
            )
        };
        assert_eq!(value, exact.floor() as i64 as i32, "{exact}");
        let error = exact - f64::from(value);
        assert!((0.0..1.0).contains(&error));
        assert_eq!(fb.touch_probe_status, touch_probe::STATUS_ENABLED | stored);
    }
}

#[test]
fn a_touch_probe_in_csp_latches_within_the_following_error_of_the_set_point() {
    let mut servo = SimServo::new(ServoParams::example(CYCLE)).unwrap();
    let start = enable(&mut servo, CSP).position_actual;
    let (a, v) = (1e8, 1e7);
    let mut worst = 0.0f64;
    for k in 0..600 {
        let (p, ff) = ramp(k, a, v);
        let (p_prev, _) = ramp(k - 1, a, v);
        let cmd = DriveCommand {
            controlword: 0x000F,
            mode: CSP,
            target_position: start.wrapping_add(p.round() as i32),
            velocity_offset: ff.round() as i32,
            touch_probe_function: if k % 2 == 0 { 0 } else { TP1_FIRST_BOTH },
            ..DriveCommand::default()
        };
        servo.exchange(&cmd);
        let offset = 1_000 * (k % 997);
        if k % 2 == 1 {
            servo.probe_edge(1, true, offset).unwrap();
        }
        servo.advance(CYCLE);
        let fb = servo.feedback();
        if k % 2 == 1 && k >= 300 {
            // The set-point at the instant, interpolated as the drive does.
            let s = offset as f64 / CYCLE as f64;
            let demand = if k == 0 { 0.0 } else { p_prev.round() }
                + (p.round() - if k == 0 { 0.0 } else { p_prev.round() }) * s;
            let latched = f64::from(fb.touch_probe_1_positive.wrapping_sub(start));
            worst = worst.max((latched - demand).abs());
        }
    }
    println!("CSP touch probe: latched vs interpolated set-point within {worst} increments");
    assert!(worst <= 2.0, "{worst}");
}

#[test]
fn first_event_latches_once_continuous_every_edge() {
    let mut servo = coasting(frictionless(), 10_000_000);
    // First event, positive edges only: the first of two edges in a cycle; later edges and
    // negative edges ignored until re-armed.
    let first = touch_probe::ENABLE | touch_probe::SAMPLE_POSITIVE;
    servo.exchange(&probe_cmd(first));
    let p0 = servo.position();
    servo.probe_edge(1, true, 200_000).unwrap();
    servo.probe_edge(1, false, 300_000).unwrap();
    servo.probe_edge(1, true, 100_000).unwrap(); // earlier in time, queued later
    servo.advance(CYCLE);
    let fb = servo.feedback();
    let at = |t: i64| (p0 + 1e7 * t as f64 * 1e-9).floor() as i32;
    assert_eq!(fb.touch_probe_1_positive, at(100_000));
    assert_eq!(fb.touch_probe_1_negative, 0);
    assert_eq!(fb.touch_probe_status, 0x0003);
    servo.probe_edge(1, true, 10_000).unwrap();
    let fb = cycle(&mut servo, &probe_cmd(first));
    assert_eq!(fb.touch_probe_1_positive, at(100_000), "first event: kept");
    // Re-armed: clear, then set the enable bit.
    let fb = cycle(&mut servo, &probe_cmd(0));
    assert_eq!(fb.touch_probe_status, 0);
    servo.exchange(&probe_cmd(first));
    let p1 = servo.position();
    servo.probe_edge(1, true, 10_000).unwrap();
    servo.advance(CYCLE);
    let fb = servo.feedback();
    assert_eq!(fb.touch_probe_1_positive, (p1 + 1e7 * 1e-5).floor() as i32);
    assert_eq!(fb.touch_probe_status, 0x0003);

    // Continuous, probe 2, both edges: every edge overwrites; bits 6/7 toggle per value.
    let continuous = (touch_probe::ENABLE
        | touch_probe::CONTINUOUS
        | touch_probe::SAMPLE_POSITIVE
        | touch_probe::SAMPLE_NEGATIVE)
        << touch_probe::PROBE_2_SHIFT;
    let mut toggles = 0;
    for k in 0..4 {
        servo.exchange(&probe_cmd(continuous));
        let p = servo.position();
        servo.probe_edge(2, true, 100_000).unwrap();
        servo.probe_edge(2, true, 400_000 + 1_000 * k).unwrap();
        servo.probe_edge(2, false, 700_000).unwrap();
        // Touch probe 1 is disabled now: its edges latch nothing.
        servo.probe_edge(1, true, 800_000).unwrap();
        servo.advance(CYCLE);
        let fb = servo.feedback();
        toggles += 2;
        assert_eq!(
            fb.touch_probe_2_positive,
            (p + 1e7 * (400_000 + 1_000 * k) as f64 * 1e-9).floor() as i32
        );
        assert_eq!(fb.touch_probe_2_negative, (p + 1e7 * 0.7e-3).floor() as i32);
        let status = fb.touch_probe_status >> touch_probe::PROBE_2_SHIFT;
        let positive_toggle = if toggles % 2 == 1 {
            touch_probe::STATUS_POSITIVE_TOGGLE
        } else {
            0
        };
        let negative_toggle = if (k + 1) % 2 == 1 {
            touch_probe::STATUS_NEGATIVE_TOGGLE
        } else {
            0
        };
        assert_eq!(
            status,
            0x0007 | positive_toggle | negative_toggle,
            "cycle {k}"
        );
        assert_eq!(fb.touch_probe_status & 0x00FF, 0);
    }
    assert_eq!(
        servo.probe_edge(3, true, 0),
        Err(SimServoError::NoSuchProbe { probe: 3 })
    );
    assert_eq!(
        servo.probe_edge(1, true, -1),
        Err(SimServoError::NegativeEdgeOffset { offset_ns: -1 })
    );
}

#[test]
fn an_edge_beyond_the_cycle_waits_for_the_next_one() {
    let mut servo = coasting(frictionless(), 10_000_000);
    let first = touch_probe::ENABLE | touch_probe::SAMPLE_POSITIVE;
    servo.exchange(&probe_cmd(first));
    let p0 = servo.position();
    servo.probe_edge(1, true, CYCLE + 250_000).unwrap();
    servo.advance(CYCLE);
    assert_eq!(servo.feedback().touch_probe_status, 0x0001);
    servo.exchange(&probe_cmd(first));
    servo.advance(CYCLE);
    let fb = servo.feedback();
    assert_eq!(fb.touch_probe_status, 0x0003);
    assert_eq!(
        fb.touch_probe_1_positive,
        (p0 + 1e7 * 1.25e-3).floor() as i32
    );
    // The queue is bounded.
    for _ in 0..8 {
        servo.probe_edge(1, true, 10 * CYCLE).unwrap();
    }
    assert_eq!(
        servo.probe_edge(1, true, 0),
        Err(SimServoError::ProbeEdgeQueueFull)
    );
}

#[test]
fn the_zero_pulse_latches_the_mark_position() {
    let ipr = 1u32 << 20;
    let params = ServoParams {
        zero_pulse_offset: 1_000,
        initial_position: 3.0 * f64::from(ipr) + 5_000.0,
        ..frictionless()
    };
    let mut servo = coasting(params, 30_000_000); // 28.6 revolutions per second
    let zero_first =
        touch_probe::ENABLE | touch_probe::SOURCE_ZERO_PULSE | touch_probe::SAMPLE_POSITIVE;
    servo.exchange(&probe_cmd(zero_first));
    let p0 = servo.position();
    let mut fb = servo.feedback();
    for _ in 0..100 {
        if fb.touch_probe_status & touch_probe::STATUS_POSITIVE_STORED != 0 {
            break;
        }
        servo.advance(CYCLE);
        fb = servo.feedback();
        servo.exchange(&probe_cmd(zero_first));
    }
    assert_eq!(fb.touch_probe_status, 0x0003, "no zero pulse latched");
    // The first mark after p0: 1000 + k · 2^20.
    let mark =
        1_000.0 + ((p0 - 1_000.0) / f64::from(ipr)).floor() * f64::from(ipr) + f64::from(ipr);
    assert_eq!(f64::from(fb.touch_probe_1_positive), mark);
    // Input edges do not trigger a probe whose source is the zero pulse.
    let before = fb.touch_probe_1_positive;
    let continuous = zero_first | touch_probe::CONTINUOUS;
    cycle(&mut servo, &probe_cmd(0));
    servo.exchange(&probe_cmd(continuous));
    servo.probe_edge(1, true, 0).unwrap();
    servo.advance(CYCLE / 100);
    assert_eq!(servo.feedback().touch_probe_1_positive, before);
    // Continuous: the latest mark.
    for _ in 0..100 {
        cycle(&mut servo, &probe_cmd(continuous));
    }
    let p = servo.position();
    let last = 1_000.0 + ((p - 1_000.0) / f64::from(ipr)).floor() * f64::from(ipr);
    assert_eq!(f64::from(servo.feedback().touch_probe_1_positive), last);
}

#[test]
fn position_actual_wraps_past_i32_max() {
    let params = ServoParams {
        initial_position: f64::from(i32::MAX) - 3_000_000.5,
        ..ServoParams::example(CYCLE)
    };
    let mut servo = SimServo::new(params).unwrap();
    let start = enable(&mut servo, CSP).position_actual;
    assert_eq!(start, i32::MAX - 3_000_001);
    let p_start = servo.position();
    let mut wrapped = false;
    let mut previous = start;
    for k in 0..600 {
        let (p, ff) = ramp(k, 1e8, 1e7);
        let cmd = DriveCommand {
            controlword: 0x000F,
            mode: CSP,
            target_position: start.wrapping_add(p.round() as i32),
            velocity_offset: ff.round() as i32,
            ..DriveCommand::default()
        };
        let fb = cycle(&mut servo, &cmd);
        assert_eq!(
            state_of(&fb),
            Some(Cia402State::OperationEnabled),
            "cycle {k}"
        );
        // Position actual is the continuous position as a 32-bit counter.
        let expected = (servo.position().floor() as i64) as i32;
        assert_eq!(fb.position_actual, expected);
        wrapped |= fb.position_actual < previous;
        // Moved forward by what the continuous position moved, across the wrap too.
        let moved = fb.position_actual.wrapping_sub(start);
        assert!((f64::from(moved) - (servo.position() - p_start)).abs() <= 1.0);
        // The set-points are unwrapped across the wrap: no jump in the following error.
        assert_eq!(
            fb.following_error,
            cmd.target_position.wrapping_sub(fb.position_actual)
        );
        assert!(fb.following_error.abs() <= 1000, "{}", fb.following_error);
        previous = fb.position_actual;
    }
    assert!(wrapped, "never wrapped");
    assert!(servo.position() > f64::from(i32::MAX) + 1e6);
    assert!(previous < 0);
}

#[test]
fn the_cyclic_path_does_not_allocate() {
    // 10,000 cycles of an axis driving the servo: the enable handshake, CSP at 1e6
    // increments/s, touch probes re-armed and triggered, a fault injected and reset
    // (MC_Reset), digital inputs changing. Only the test's own bookkeeping is outside.
    let mut servo = SimServo::new(ServoParams::example(CYCLE)).unwrap();
    let mut seq = EnableSequence::new(50 * CYCLE).unwrap();
    let mut fb = servo.feedback();
    let mut target = 0i32;
    let mut enabled_cycles = 0u32;
    let mut faults = 0u32;
    let mut latches = 0u32;
    let counts = measure(|| {
        for k in 0..10_000i64 {
            let request = PowerRequest {
                enable: true,
                quick_stop: false,
                fault_reset: k % 2000 >= 1300 && k % 2000 < 1310,
            };
            let out = seq.step(k * CYCLE, request, fb.statusword);
            if out.status == EnableStatus::Enabled {
                enabled_cycles += 1;
                target = target.wrapping_add(1_000);
            } else {
                target = fb.position_actual;
            }
            if out.status == EnableStatus::Fault {
                faults += 1;
            }
            if k % 2000 == 1000 {
                servo.inject_fault(0x2310).unwrap();
            }
            if k % 2000 == 1200 {
                servo.clear_fault_cause();
            }
            let cmd = DriveCommand {
                controlword: out.controlword,
                mode: CSP,
                target_position: target,
                velocity_offset: 1_000_000,
                touch_probe_function: if k % 3 == 0 { 0 } else { 0x3333 },
                ..DriveCommand::default()
            };
            servo.set_digital_inputs((k % 8) as u32);
            servo.exchange(&cmd);
            servo.probe_edge(1, k % 2 == 0, 1_000 * (k % 1000)).unwrap();
            servo.advance(CYCLE);
            fb = servo.feedback();
            if fb.touch_probe_status & 0x0202 != 0 {
                latches += 1;
            }
        }
    });
    assert_eq!(counts.allocations, 0, "{counts:?}");
    // The loop did what it says (each fault costs some 300 cycles until reset and re-enabled).
    assert!(enabled_cycles > 8_000, "{enabled_cycles}");
    assert!(faults >= 5, "{faults}");
    assert!(latches > 1_000, "{latches}");
    assert_eq!(fb.digital_inputs, 7);
}

/// A mechanical stop: CSV at 2^20 increments/s into a stop 100,000 increments ahead, the motor
/// stops dead on it and pushes with the 0x6072 limit (500 ‰); removed, it moves on.
#[test]
fn a_fixed_stop_holds_the_motor_at_the_limit_until_it_gives_way() {
    let mut servo = SimServo::new(frictionless()).unwrap();
    let stop = servo.position() + 100_000.0;
    servo.set_fixed_stops(None, Some(stop));
    enable(&mut servo, CSV);
    let cmd = DriveCommand {
        max_torque: 500,
        ..csv(1 << 20)
    };
    let mut fb = cycle(&mut servo, &cmd);
    for _ in 0..500 {
        fb = cycle(&mut servo, &cmd);
    }
    assert_eq!(servo.position(), stop);
    assert_eq!(servo.velocity(), 0.0);
    assert_eq!(fb.torque_actual, 500, "{fb:?}");
    assert_ne!(fb.statusword & statusword::INTERNAL_LIMIT_ACTIVE, 0);
    servo.set_fixed_stops(None, None);
    cycle(&mut servo, &cmd);
    assert!(servo.position() > stop);
}

/// The one-sided limits 0x60E0 / 0x60E1 narrow the loop's torque in their direction only:
/// against a stop above, 300 ‰ up; against a stop below, 200 ‰ down.
#[test]
fn the_positive_and_negative_torque_limits_apply_one_side_each() {
    for (velocity, expected) in [(1 << 20, 300), (-(1 << 20), -200)] {
        let mut servo = SimServo::new(frictionless()).unwrap();
        let p = servo.position();
        servo.set_fixed_stops(Some(p - 1000.0), Some(p + 1000.0));
        enable(&mut servo, CSV);
        let cmd = DriveCommand {
            positive_torque_limit: 300,
            negative_torque_limit: 200,
            ..csv(velocity)
        };
        let mut fb = cycle(&mut servo, &cmd);
        for _ in 0..200 {
            fb = cycle(&mut servo, &cmd);
        }
        assert_eq!(fb.torque_actual, expected, "{fb:?}");
    }
}
