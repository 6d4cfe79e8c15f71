//! CSV for non-position-controlled operation (sticky, as S7 keeps it after the job) and CSP
//! otherwise; torque feedforward 0x60B2 from the setpoint acceleration.

use super::{cell, Run};
use tandem_motion::catalog::alarm::status_bit;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::axis::{Command, StartMode, VelocityDirection};

const CSP: i8 = 8;
const CSV: i8 = 9;

fn move_velocity(velocity: f64, position_controlled: bool) -> Command {
    Command::MoveVelocity {
        dynamics: Dynamics {
            velocity,
            acceleration: 1000.0,
            deceleration: 1000.0,
            jerk: 0.0,
        },
        direction: VelocityDirection::BySign,
        current: false,
        position_controlled,
    }
}

/// Steps `n` cycles and returns the mode the drive displays (0x6061) and the axis's X28.
fn after(r: &mut Run, n: usize) -> (i8, bool) {
    for _ in 0..n {
        r.step();
    }
    let x28 = r.status().status_word & status_bit::NON_POSITION_CONTROLLED != 0;
    (r.fb().unwrap().mode_display, x28)
}

#[test]
fn non_position_controlled_operation_runs_the_drive_in_csv() {
    let cell = cell(|s| s);
    let mut r = Run::new(&cell);
    // MC_Power StartMode 0: not position-controlled from the enable on.
    r.power(StartMode::NonPositionControlled);
    assert_eq!(after(&mut r, 3), (CSV, true));
    r.cmd(move_velocity(50.0, false));
    assert_eq!(after(&mut r, 300), (CSV, true));
    // 50 mm/s = 15 motor turns/s = 15·2^20 increments/s, in 0x60FF and at the motor.
    let v = f64::from(r.fb().unwrap().velocity_actual);
    assert!((v - 15.0 * 1048576.0).abs() < 2000.0, "velocity actual {v}");
    // Sticky: MC_Halt keeps the mode (S7-1500T Motion Control V4.0, 'Non-position-controlled
    // operation').
    r.cmd(Command::Halt {
        deceleration: -1.0,
        jerk: -1.0,
        abort_acceleration: false,
    });
    assert_eq!(after(&mut r, 200), (CSV, true));
    // MC_MoveRelative forces position control back: CSP.
    r.cmd(Command::MoveRelative {
        distance: 5.0,
        dynamics: Dynamics {
            velocity: 50.0,
            acceleration: 1000.0,
            deceleration: 1000.0,
            jerk: 0.0,
        },
    });
    assert_eq!(after(&mut r, 3), (CSP, false));
    r.cmd(move_velocity(-20.0, true));
    assert_eq!(after(&mut r, 100), (CSP, false));
    r.cmd(move_velocity(-20.0, false));
    assert_eq!(after(&mut r, 100), (CSV, true));
    assert!(!r.log().contains("alarm"), "{}", r.log());
}

#[test]
fn start_mode_1_enables_in_csp() {
    let cell = cell(|s| s);
    let mut r = Run::new(&cell);
    r.power(StartMode::PositionControlled);
    assert_eq!(after(&mut r, 3), (CSP, false));
}

/// The largest following error of a trapezoidal move (steps of acceleration) on the cell with
/// a soft velocity loop without integral action (gain 0.02 N·m·s/rad: 200 rad/s), where the
/// torque for the inertia comes from the velocity error alone: 0.377 N·m at 2000 mm/s² need
/// 18.8 rad/s of it, 0.1 mm of following error behind Kv = 100 1/s. What is left with the
/// torque feedforward is the velocity feedforward's half cycle lead over the interpolated
/// target, a·T/(2·Kv) = 0.01 mm.
fn worst_following_error(precontrol: bool) -> f64 {
    let cell = cell(|s| {
        let s = s
            .replace("velocity_gain = 0.1 ", "velocity_gain = 0.02 ")
            .replace(
                "velocity_integral_time = 0.01 ",
                "velocity_integral_time = 0.0 ",
            );
        if precontrol {
            s.replace(
                "device = \"slide_servo\"",
                "device = \"slide_servo\"\ntorque_precontrol = true",
            )
        } else {
            s
        }
    });
    let mut r = Run::new(&cell);
    r.power(StartMode::PositionControlled);
    r.cmd(Command::Home {
        mode: 0,
        position: 0.0,
    });
    r.move_to(150.0, 200.0, 2000.0);
    let mut worst = 0.0f64;
    for _ in 0..1200 {
        r.step();
        worst = worst.max(r.status().following_error.abs());
    }
    assert!(
        r.log().contains("MC_MoveAbsolute job 3: Done"),
        "{}",
        r.log()
    );
    worst
}

#[test]
fn torque_feedforward_shrinks_the_following_error_while_accelerating() {
    let without = worst_following_error(false);
    let with = worst_following_error(true);
    eprintln!("worst following error: without {without} mm, with {with} mm");
    // Without: 0.1 mm from the inertia plus the rest (measured 0.1035 mm); with: 0.0273 mm.
    assert!((0.09..0.12).contains(&without), "{without}");
    assert!(
        with < 0.3 * without,
        "with {with} against without {without}"
    );
}
