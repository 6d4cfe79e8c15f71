//! Quick stop: MC_Power StopMode 1 ("immediate stop: setpoint 0 and enable removed; the drive's
//! own ramp brakes the axis") and the alarm reaction "remove enable" are the drive's quick stop
//! (controlword 0x0002, transition 11), braking at its quick stop deceleration 0x6085 with the
//! option 0x605A; StopMode 0 brakes on the axis's setpoints and then removes the enable without
//! a quick stop. The drive's internal limit (0x6041 bit 11) is StatusWord X27.

use super::{cell, Run};
use tandem_config::DriveConnection;
use tandem_motion::catalog::alarm::{status_bit, supplement, AlarmId};
use tandem_motion::objects::axis::{AxisState, Command, StartMode, StopMode};
use tandem_motion::plant::cia402::{statusword, Cia402State, QuickStopOption};
use tandem_motion::plant::drive::Plant;
use tandem_motion::plant::link::{DriveOutputs, DriveState};
use tandem_motion::plant::servo::{ServoParams, SimServo};
use tandem_runtime::drives::Cia402Link;

/// The servo's quick stop deceleration 2000 rad/s² over a 1 ms cycle, in increments/s of
/// 0x606C (2^20 increments per revolution).
fn ramp_per_cycle() -> f64 {
    2000.0 * 1e-3 * f64::from(1u32 << 20) / core::f64::consts::TAU
}

fn state(sw: u16) -> Cia402State {
    Cia402State::from_statusword(sw).unwrap()
}

/// Runs until the drive is in switch on disabled, from a move at 200 mm/s stopped by `stop`;
/// returns the (state, velocity actual) samples from the stop on.
fn stop_from_200(r: &mut Run, stop: impl Fn(&mut Run)) -> Vec<(Cia402State, i32)> {
    r.power(StartMode::PositionControlled);
    r.cmd(Command::Home {
        mode: 0,
        position: 0.0,
    });
    r.move_to(450.0, 200.0, 2000.0);
    r.until(400, "constant velocity", |r| {
        r.status().velocity == 200.0 && r.k > 300
    });
    stop(r);
    let mut samples = Vec::new();
    for _ in 0..1000 {
        r.step();
        let fb = r.fb().unwrap();
        samples.push((state(fb.statusword), fb.velocity_actual));
        if samples.last().unwrap().0 == Cia402State::SwitchOnDisabled {
            return samples;
        }
    }
    panic!("the drive did not reach switch on disabled\n{}", r.log());
}

/// Every full cycle of braking in quick stop active takes the velocity down by the ramp.
fn assert_quick_stop_ramp(samples: &[(Cia402State, i32)]) -> usize {
    let start = samples
        .iter()
        .position(|s| s.0 == Cia402State::QuickStopActive)
        .expect("quick stop active");
    let before = samples[start - 1];
    assert_eq!(before.0, Cia402State::OperationEnabled, "transition 11");
    let mut cycles = 0;
    for w in samples[start - 1..].windows(2) {
        let (v0, v1) = (f64::from(w[0].1), f64::from(w[1].1));
        if w[1].0 != Cia402State::QuickStopActive || v1 == 0.0 {
            break;
        }
        // 0x606C is rounded to whole increments/s; the servo's braking torque compensates the
        // friction as sampled at the start of each 50 µs sub-step, so the viscous part is off
        // by at most b·Δω/J = 0.1 rad/s² of 2000 (5e-5).
        assert!(
            (v0 - v1 - ramp_per_cycle()).abs() <= 1.0 + 5e-5 * ramp_per_cycle(),
            "{v0} -> {v1}: not the 0x6085 ramp of {}",
            ramp_per_cycle()
        );
        cycles += 1;
    }
    cycles
}

#[test]
fn stop_mode_1_is_the_drives_quick_stop_on_its_own_ramp() {
    let cell = cell(|s| s);
    let mut r = Run::new(&cell);
    let samples = stop_from_200(&mut r, |r| {
        r.cmd(Command::Power {
            enable: false,
            start_mode: StartMode::PositionControlled,
            stop_mode: StopMode::Immediate,
        });
        // The enable is removed at once: Status FALSE in the next step, no braking by the axis.
        r.step();
        assert_eq!(r.state(), AxisState::Disabled);
        assert!(
            r.log().contains("MC_Power job 1: Status FALSE"),
            "{}",
            r.log()
        );
    });
    // 200 mm/s = 377 rad/s at the motor: 188.5 ms at 2000 rad/s², 188 full cycles.
    let cycles = assert_quick_stop_ramp(&samples);
    assert_eq!(cycles, 188, "{samples:?}");
    // Option 2: at standstill the drive leaves quick stop active on its own (transition 12).
    let states: Vec<Cia402State> = samples.iter().map(|s| s.0).fold(Vec::new(), |mut v, s| {
        if v.last() != Some(&s) {
            v.push(s);
        }
        v
    });
    assert_eq!(
        states,
        [
            Cia402State::OperationEnabled,
            Cia402State::QuickStopActive,
            Cia402State::SwitchOnDisabled
        ]
    );
    assert_eq!(samples.last().unwrap().1, 0);
    assert!(!r.log().contains("alarm"), "{}", r.log());
}

#[test]
fn stop_mode_0_brakes_on_the_setpoints_and_never_quick_stops() {
    let cell = cell(|s| s);
    let mut r = Run::new(&cell);
    let samples = stop_from_200(&mut r, |r| {
        r.cmd(Command::Power {
            enable: false,
            start_mode: StartMode::PositionControlled,
            stop_mode: StopMode::Emergency,
        });
    });
    assert!(
        samples.iter().all(|s| s.0 != Cia402State::QuickStopActive),
        "{samples:?}"
    );
    // Braked by the axis at the emergency deceleration 3000 mm/s² (66.7 ms from 200 mm/s),
    // then disable voltage at standstill (transition 9).
    let n = samples.len();
    assert!((66..=75).contains(&n), "{n} cycles");
    assert_eq!(samples[n - 2].0, Cia402State::OperationEnabled);
    // The setpoint has stopped; the load is two cycles of transport behind it (less than
    // 0.2 % of the 62,914,560 increments/s of 200 mm/s).
    assert!(samples[n - 2].1.abs() < 125_829, "{:?}", samples[n - 2]);
}

#[test]
fn the_alarm_reaction_remove_enable_quick_stops_the_drive() {
    // A positive limit switch at 300 mm, hit at 200 mm/s: alarm 531, remove enable.
    let cell = cell(|s| s.replace("max = 520.0", "max = 300.0"));
    let mut r = Run::new(&cell);
    let samples = stop_from_200(&mut r, |r| {
        r.until(2000, "alarm 531", |r| r.alarm(AlarmId::HwLimit).is_some());
        assert_eq!(
            r.alarm(AlarmId::HwLimit),
            Some(supplement::HW_LIMIT_POSITIVE)
        );
        assert_eq!(r.state(), AxisState::ErrorStop);
    });
    assert_eq!(assert_quick_stop_ramp(&samples), 188, "{samples:?}");
}

#[test]
fn option_6_stays_in_quick_stop_until_the_enable_goes_at_standstill() {
    // 0x605A = 6: stop on the quick stop ramp and stay in quick stop active; the link sends
    // disable voltage once the drive reports standstill (bit 10), transition 12.
    let cell = cell(|s| s.replace("quick_stop_option = 2", "quick_stop_option = 6"));
    let mut r = Run::new(&cell);
    let samples = stop_from_200(&mut r, |r| {
        r.cmd(Command::Power {
            enable: false,
            start_mode: StartMode::PositionControlled,
            stop_mode: StopMode::Immediate,
        });
    });
    assert_eq!(assert_quick_stop_ramp(&samples), 188);
    let n = samples.len();
    assert_eq!(samples[n - 2], (Cia402State::QuickStopActive, 0));
}

/// The controlword sequence on the link itself, with the simulated servo in front of it.
#[test]
fn controlword_known_answers_for_enable_quick_stop_and_re_enable() {
    let cell = cell(|s| s);
    let DriveConnection::Cia402(c) = &cell.axes[0].drive else {
        panic!("servo.toml has a CiA 402 axis");
    };
    let mut link = Cia402Link::new(0, c, Plant::default(), 0.0).unwrap();
    let mut servo = SimServo::new(ServoParams {
        quick_stop_option: QuickStopOption::QuickStopRamp,
        ..ServoParams::example(1_000_000)
    })
    .unwrap();
    let mut out = DriveOutputs {
        enable: true,
        position_controlled: true,
        ..DriveOutputs::default()
    };
    let mut velocity = 0.0;
    let mut trace = Vec::new();
    for k in 0..400i64 {
        if k > 0 {
            servo.advance(1_000_000);
        }
        let fb = servo.feedback();
        let inputs = link.inputs(k * 1_000_000, &fb);
        if k == 20 {
            // The axis removes the enable to stop on the drive's ramp (StopMode 1).
            out.enable = false;
            out.quick_stop = true;
        }
        if k == 300 {
            out.enable = true;
            out.quick_stop = false;
        }
        if (5..20).contains(&k) {
            // A velocity to brake from: 1 mm/s more each cycle (CSP, feedforward).
            velocity += 1.0;
            out.position += velocity * 1e-3;
            out.velocity = velocity;
        }
        let cmd = link.command(&out);
        trace.push((cmd.controlword, inputs.state));
        servo.exchange(&cmd);
    }
    let mut words: Vec<u16> = trace.iter().map(|t| t.0).collect();
    words.dedup();
    // Nothing before the first sample; enable: shutdown, switch on, enable operation; quick
    // stop from the cycle that removed the enable; disable voltage once the drive has left
    // quick stop active (option 2); enable again from switch on disabled.
    assert_eq!(
        words,
        [0x0000, 0x0006, 0x0007, 0x000F, 0x0002, 0x0000, 0x0006, 0x0007, 0x000F]
    );
    assert_eq!(
        trace[20].0, 0x0002,
        "with the command that removed the enable"
    );
    assert!(trace[21..]
        .iter()
        .take_while(|t| t.0 == 0x0002)
        .all(|t| t.1 == DriveState::Stopping));
    assert_eq!(trace[399].1, DriveState::Operational);
    assert_eq!(servo.statusword() & statusword::STATE_MASK, 0x27);
}

#[test]
fn the_drives_internal_limit_is_statusword_x27_in_limitation() {
    // A torque limit of 400 ‰ (0.508 N·m) against 3000 mm/s²: 0.565 N·m of inertia torque at
    // the motor (3 turns per 10 mm) plus friction. The monitoring is opened so the lag is
    // allowed.
    let cell = cell(|s| {
        s.replace("max_torque = 3000", "max_torque = 400")
            .replace(
                "following_error_window = 262144",
                "following_error_window = 4294967295",
            )
            .replace("enable = true\nmin_value", "enable = false\nmin_value")
    });
    let mut r = Run::new(&cell);
    r.power(StartMode::PositionControlled);
    r.cmd(Command::Home {
        mode: 0,
        position: 0.0,
    });
    r.move_to(100.0, 200.0, 3000.0);
    let (mut limited, mut free) = (0, 0);
    for _ in 0..1200 {
        r.step();
        let fb = r.fb().unwrap();
        let drive = fb.statusword & statusword::INTERNAL_LIMIT_ACTIVE != 0;
        let axis = r.status().status_word & status_bit::IN_LIMITATION != 0;
        assert_eq!(axis, drive, "X27 mirrors 0x6041 bit 11 of the same sample");
        if drive {
            limited += 1;
            // At the limit the torque actual 0x6077 is the limit itself.
            assert_eq!(fb.torque_actual.abs(), 400, "{fb:?}");
        } else {
            free += 1;
        }
    }
    assert!(limited >= 20, "{limited} cycles at the limit");
    assert!(free > 1000, "{free} cycles free");
    // Not an alarm (S7 has none for it): the move ends Done.
    assert!(
        r.log().contains("MC_MoveAbsolute job 3: Done"),
        "{}",
        r.log()
    );
    assert_eq!(r.alarm(AlarmId::DriveFault), None);
    assert_eq!(r.status().status_word & status_bit::IN_LIMITATION, 0);
}
