//! An axis on a simulated CiA 402 servo drive through the process image, end to end in the
//! executive (`config/servo.toml`): MC_Power runs the drive's enable sequence; a jerk-limited
//! move is followed with the following error inside its monitoring limits; an injected drive
//! fault raises technology alarm 421 with the drive's error code in the cycle the drive reports
//! it and the axis stops; MC_Reset acknowledges it on the drive; a hardware limit switch read
//! through the drive's digital inputs (0x60FD) stops the axis as the reference prescribes
//! (alarm 531, remove enable); a drive that cannot be enabled names the step that did not
//! complete.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::{AxisIndex, Cell};
use tandem_motion::catalog::alarm::{supplement, AlarmId};
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{AxisState, Command, StartMode, StopMode};
use tandem_motion::plant::cia402::statusword;
use tandem_runtime::exec::Executive;
use tandem_testkit::workspace::root;

const MS: i64 = 1_000_000;

fn cell(edit: impl Fn(String) -> String) -> Cell {
    let src = std::fs::read_to_string(root().join("config/servo.toml")).unwrap();
    tandem_config::parse("servo.toml", &edit(src)).unwrap()
}

/// The executive of the cell and its log, stepped cycle by cycle.
struct Run<'c> {
    exec: Executive<'c>,
    k: i64,
    log: Vec<u8>,
}

impl<'c> Run<'c> {
    fn new(cell: &'c Cell) -> Self {
        Self {
            exec: Executive::new(cell, None).unwrap(),
            k: 0,
            log: Vec::new(),
        }
    }

    fn t(&self) -> i64 {
        self.k * MS
    }

    fn apply(&mut self, target: &str, action: Action) {
        let t = self.t();
        let r = self
            .exec
            .apply_at(t, t, target, "test", action, &mut self.log)
            .unwrap();
        assert!(r.is_ok(), "{target}: {r:?}\n{}", self.log());
    }

    fn cmd(&mut self, c: Command) {
        self.apply("slide", Action::Command(c));
    }

    fn step(&mut self) {
        let t = self.t();
        self.exec.step(t, &mut self.log).unwrap();
        self.k += 1;
    }

    fn log(&self) -> String {
        String::from_utf8_lossy(&self.log).into_owned()
    }

    fn state(&mut self) -> AxisState {
        self.exec.status()[0].state
    }

    fn alarm(&self, id: AlarmId) -> Option<u16> {
        let axis = self.exec.axis(AxisIndex(0)).unwrap();
        axis.alarms().find(|a| a.id == id).map(|a| a.supplement)
    }

    fn statusword(&self) -> u16 {
        self.exec.drive_feedback(0).unwrap().statusword
    }

    /// Steps until `f` holds, at most `max` cycles.
    fn until(&mut self, max: usize, what: &str, f: impl Fn(&mut Self) -> bool) {
        for _ in 0..max {
            if f(self) {
                return;
            }
            self.step();
        }
        panic!("{what}: not within {max} cycles\n{}", self.log());
    }

    /// Powers and homes the axis (direct homing at 0), steps until it is enabled.
    fn enabled(&mut self) {
        self.cmd(Command::Power {
            enable: true,
            start_mode: StartMode::PositionControlled,
            stop_mode: StopMode::Emergency,
        });
        self.cmd(Command::Home {
            mode: 0,
            position: 0.0,
        });
        self.until(50, "enabled", |r| r.state() == AxisState::Standstill);
    }

    fn move_to(&mut self, position: f64) {
        self.cmd(Command::MoveAbsolute {
            position,
            dynamics: Dynamics {
                velocity: 200.0,
                acceleration: 2000.0,
                deceleration: 2000.0,
                jerk: 40000.0,
            },
            direction: tandem_motion::objects::axis::Direction::Shortest,
        });
    }
}

#[test]
fn mc_power_runs_the_enable_sequence_and_a_move_follows_within_the_monitoring() {
    let cell = cell(|s| s);
    let mut r = Run::new(&cell);
    r.step();
    r.cmd(Command::Power {
        enable: true,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Emergency,
    });
    // The drive goes through shutdown, switch on, enable operation: several exchanges, each
    // answered at the next boundary; Status TRUE only once it reports operation enabled.
    let mut cycles = 0;
    while r.state() != AxisState::Standstill {
        assert_eq!(r.state(), AxisState::Disabled);
        r.step();
        cycles += 1;
        assert!(cycles < 50, "{}", r.log());
    }
    assert!(cycles >= 3, "three steps of the handshake, {cycles} cycles");
    assert_eq!(r.statusword() & 0x6F, 0x27, "operation enabled");
    r.cmd(Command::Home {
        mode: 0,
        position: 0.0,
    });
    r.move_to(150.0);
    let fe_limit = cell.axes[0].config.following_error.min_value;
    let mut worst = 0.0f64;
    for _ in 0..1500 {
        r.step();
        worst = worst.max(r.exec.status()[0].following_error.abs());
    }
    let s = r.exec.status()[0];
    assert!(
        r.log().contains("MC_MoveAbsolute job 3: Done"),
        "{}",
        r.log()
    );
    assert_eq!(s.position, 150.0);
    assert!((s.actual_position - 150.0).abs() < cell.axes[0].config.positioning.window);
    assert!(
        worst < 0.05 * fe_limit,
        "following error {worst} against the permitted {fe_limit}"
    );
    assert!(!r.log().contains("alarm"), "{}", r.log());
}

#[test]
fn a_drive_fault_mid_move_raises_421_with_its_code_in_the_cycle_the_drive_reports_it() {
    let cell = cell(|s| s);
    let mut r = Run::new(&cell);
    r.enabled();
    r.move_to(150.0);
    for _ in 0..300 {
        r.step();
    }
    assert_eq!(r.state(), AxisState::DiscreteMotion);
    r.apply("slide_servo", Action::DriveFault { code: 0x2310 });
    // Until the drive reports the fault the axis moves on; in the step whose sample has the
    // fault bit the axis raises 421 with the drive's error code and removes its enable.
    let mut cycles = 0;
    loop {
        r.step();
        cycles += 1;
        if r.statusword() & statusword::FAULT != 0 {
            break;
        }
        assert_eq!(r.alarm(AlarmId::DriveFault), None);
        assert!(cycles < 5, "{}", r.log());
    }
    assert_eq!(r.alarm(AlarmId::DriveFault), Some(0x2310));
    assert_eq!(r.state(), AxisState::ErrorStop);
    assert!(!r.exec.axis(AxisIndex(0)).unwrap().drive_outputs().enable);
    assert!(
        r.log().contains("MC_MoveAbsolute job 3: Error 16#8001"),
        "{}",
        r.log()
    );
    // The drive brakes on its own fault reaction ramp to standstill.
    r.until(2000, "standstill", |r| {
        r.exec.status()[0].actual_velocity == 0.0
    });
    // MC_Reset while the cause is present: the drive refuses the fault reset, the enable is not
    // possible, alarm 421 names the step "fault reset" when its timeout runs out.
    r.cmd(Command::Reset { restart: false });
    assert_eq!(r.alarm(AlarmId::DriveFault), None);
    let timeout = 500;
    for _ in 0..timeout - 5 {
        r.step();
        assert_eq!(r.alarm(AlarmId::DriveFault), None, "{}", r.log());
    }
    r.until(20, "enable not possible", |r| {
        r.alarm(AlarmId::DriveFault) == Some(supplement::DRIVE_ENABLE_NOT_POSSIBLE)
    });
    // The cause removed, MC_Reset: the drive resets, the axis is enabled again (MC_Power
    // still holds its Enable) and moves.
    r.apply("slide_servo", Action::DriveFault { code: 0 });
    r.cmd(Command::Reset { restart: false });
    r.until(50, "re-enabled", |r| r.state() == AxisState::Standstill);
    assert_eq!(r.exec.drive_feedback(0).unwrap().error_code, 0);
    r.move_to(10.0);
    r.until(2000, "the move after the reset", |r| {
        r.log().contains("MC_MoveAbsolute job 6: Done")
    });
    let power: Vec<&str> = r
        .log()
        .lines()
        .filter(|l| l.contains("MC_Power job 1: Status"))
        .map(|l| if l.ends_with("TRUE") { "T" } else { "F" })
        .collect();
    assert_eq!(power, ["T", "F", "T"]);
}

#[test]
fn a_hardware_limit_switch_read_through_the_drive_stops_the_axis() {
    // The positive switch at 60 mm; a move to 100 mm runs into it.
    let cell = cell(|s| s.replace("max = 520.0", "max = 60.0"));
    let mut r = Run::new(&cell);
    r.enabled();
    r.move_to(100.0);
    r.until(2000, "alarm 531", |r| r.alarm(AlarmId::HwLimit).is_some());
    assert_eq!(
        r.alarm(AlarmId::HwLimit),
        Some(supplement::HW_LIMIT_POSITIVE)
    );
    let di = r.exec.drive_feedback(0).unwrap().digital_inputs;
    assert_ne!(di & 0x2, 0, "0x60FD bit 1, positive limit switch");
    // Detected within the cycle it is reached: the encoder reads the floor of the position,
    // up to one increment (10 mm / 3 / 2^20) below the switch.
    let at = r.exec.status()[0].actual_position;
    let increment = 10.0 / 3.0 / f64::from(1u32 << 20);
    assert!(at >= 60.0 - increment && at < 60.5, "detected at {at}");
    // Remove enable: the drive is disabled and brakes on its own.
    assert_eq!(r.state(), AxisState::ErrorStop);
    assert!(!r.exec.axis(AxisIndex(0)).unwrap().drive_outputs().enable);
    r.until(2000, "standstill", |r| {
        r.exec.status()[0].actual_velocity == 0.0
    });
}

/// A measuring input on the drive's touch probe (route PROFIdrive, "the drive latches the
/// position"): the mark sensor sits in front of the drive's probe input; MC_MeasuringInput
/// arms touch probe 1 (0x60B8), the drive latches the exact crossing (0x60BA/0x60BB), and the
/// measured values are those positions in the axis's coordinate.
#[test]
fn a_touch_probe_latch_gives_the_measuring_input_the_exact_position() {
    // The mark from 50 to 55 mm: 15·2^20 and 16.5·2^20 increments exactly (3 motor turns per
    // 10 mm), so the latched counter values are the mark's edges without rounding.
    let cell = cell(|s| {
        s + r#"
[[measuring_inputs]]
name = "probe"
axis = "slide"
route = "profidrive"

[measuring_inputs.sensor]
position = 50.0
width = 5.0
"#
    });
    let mut r = Run::new(&cell);
    r.enabled();
    // Home to 100 at the start: the measured values are axis positions (physical + 100).
    r.cmd(Command::Home {
        mode: 0,
        position: 100.0,
    });
    // A PROFIdrive measuring job is refused in the cycle of a homing job (16#80A3).
    r.step();
    r.apply(
        "probe",
        Action::MeasuringInput {
            cyclic: false,
            mode: 3,
            window: None,
        },
    );
    r.move_to(200.0);
    r.until(2000, "both edges measured", |r| {
        r.log().contains("MC_MeasuringInput job") && r.log().contains(": Done")
    });
    let values: Vec<f64> = r
        .log()
        .lines()
        .filter(|l| l.contains("probe MeasuredValue"))
        .map(|l| {
            l.split(" = ")
                .nth(1)
                .unwrap()
                .split(' ')
                .next()
                .unwrap()
                .parse()
                .unwrap()
        })
        .collect();
    assert_eq!(values.len(), 2, "{}", r.log());
    assert!(
        (values[0] - 150.0).abs() < 1e-9,
        "rising edge at {}",
        values[0]
    );
    assert!(
        (values[1] - 155.0).abs() < 1e-9,
        "falling edge at {}",
        values[1]
    );
    // The drive's own registers hold the same edges in increments.
    let fb = r.exec.drive_feedback(0).unwrap();
    assert_eq!(fb.touch_probe_1_positive, 15 << 20);
    assert_eq!(fb.touch_probe_1_negative, 33 << 19);
}
