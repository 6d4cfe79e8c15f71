//! An axis on an external CiA 402 drive (a `cia402` SubDevice of the node's EtherCAT segment):
//! the edge puts the drive's TxPDO in before each step (`Executive::set_drive_feedback`) and
//! takes the RxPDO after it (`Executive::drive_command`). Here the edge is this test, with the
//! project's simulated servo behind it exchanged the way the process image exchanges a
//! `sim_servo`; with `transport_cycles = 2` every cycle of the axis (setpoint, actual value,
//! following error, state) and the log are then exactly those of the same cell on a
//! `sim_servo`: the same drive connection code path runs for both.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::{Cell, DeviceKind};
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{Command, Direction, StartMode, StopMode};
use tandem_motion::plant::cia402::DriveCommand;
use tandem_motion::plant::servo::{ServoParams, SimServo};
use tandem_runtime::exec::Executive;
use tandem_testkit::workspace::root;

const CYCLE: i64 = 2_000_000;

fn example() -> String {
    std::fs::read_to_string(root().join("config/ethercat.toml")).unwrap()
}

/// The example with the segment's drive balanced over 2 cycles, as a simulated servo is.
fn external_cell() -> Cell {
    let src = example().replace("transport_cycles = 4", "transport_cycles = 2");
    tandem_config::parse("ethercat.toml", &src).unwrap()
}

/// The same cell with the segment replaced by a `sim_servo`, a `sim_digital_output` and a
/// `sim_digital_input`.
fn simulated_cell() -> Cell {
    let src = example();
    let start = src.find("[[ethercat]]").unwrap();
    let end = src.find("[signals.lamp]").unwrap();
    let mut s = src.clone();
    s.replace_range(
        start..end,
        "[devices.slide_servo]\nnode = \"drives\"\nkind = \"sim_servo\"\n\n\
         [devices.io]\nnode = \"drives\"\nkind = \"sim_digital_output\"\nchannels = 8\n\n\
         [devices.io_in]\nnode = \"drives\"\nkind = \"sim_digital_input\"\nchannels = 8\n\n",
    );
    tandem_config::parse("sim.toml", &s).unwrap()
}

/// One row per cycle: the axis's setpoint, actual value, following error and state.
type Row = (f64, f64, f64, String);

/// Runs `cell` for `cycles`, powering, homing and moving the axis to 100 mm; for an external
/// drive `edge` is the servo behind it. Returns the rows and the log.
fn run(cell: &Cell, mut edge: Option<SimServo>, cycles: i64) -> (Vec<Row>, String) {
    let mut exec = Executive::new(cell, Some(0)).unwrap();
    let dev = cell
        .devices
        .iter()
        .position(|d| d.name == "slide_servo")
        .unwrap();
    let mut log = Vec::new();
    let mut rows = Vec::new();
    let mut latched = DriveCommand::default();
    for k in 0..cycles {
        let t = k * CYCLE;
        if let Some(servo) = edge.as_mut() {
            // As the process image exchanges a simulated servo: run the last cycle with the
            // command latched at the previous boundary, sample, latch the last step's command.
            if k > 0 {
                servo.advance(CYCLE);
            }
            assert!(exec.set_drive_feedback(dev, &servo.feedback()));
            // The transition taken is the drive's own business.
            let _ = servo.exchange(&latched);
        }
        let mut apply = |action: Action| {
            let r = exec
                .apply_at(t, t, "slide", "test", action, &mut log)
                .unwrap();
            assert!(r.is_ok(), "{r:?}");
        };
        match k {
            0 => {
                apply(Action::Command(Command::Power {
                    enable: true,
                    start_mode: StartMode::PositionControlled,
                    stop_mode: StopMode::Emergency,
                }));
                apply(Action::Command(Command::Home {
                    mode: 0,
                    position: 0.0,
                }));
            }
            50 => apply(Action::Command(Command::MoveAbsolute {
                position: 100.0,
                dynamics: Dynamics {
                    velocity: 100.0,
                    acceleration: 1000.0,
                    deceleration: 1000.0,
                    jerk: 20000.0,
                },
                direction: Direction::Shortest,
            })),
            _ => {}
        }
        exec.want_status();
        exec.step(t, &mut log).unwrap();
        if edge.is_some() {
            latched = *exec.drive_command(dev).unwrap();
        }
        let s = exec.status()[0];
        rows.push((
            s.position,
            s.actual_position,
            s.following_error,
            format!("{:?}", s.state),
        ));
    }
    (rows, String::from_utf8(log).unwrap())
}

#[test]
fn an_external_drive_runs_the_same_drive_connection_as_a_simulated_servo() {
    let external = external_cell();
    let simulated = simulated_cell();
    let dev = external
        .devices
        .iter()
        .find(|d| d.name == "slide_servo")
        .unwrap();
    assert!(matches!(dev.kind, DeviceKind::EthercatCia402(_)));
    let servo = SimServo::new(ServoParams::example(CYCLE)).unwrap();
    let (ext_rows, ext_log) = run(&external, Some(servo), 800);
    let (sim_rows, sim_log) = run(&simulated, None, 800);
    assert_eq!(ext_log, sim_log);
    assert!(
        ext_log.contains("slide MC_Power job 1: Status TRUE"),
        "{ext_log}"
    );
    assert!(
        ext_log.contains("slide MC_MoveAbsolute job 3: Done"),
        "{ext_log}"
    );
    assert_eq!(ext_rows, sim_rows, "every cycle bit-identical");
    let last = ext_rows.last().unwrap();
    assert_eq!(last.0, 100.0);
    assert!((last.1 - 100.0).abs() < 1e-3, "{last:?}");
}

#[test]
fn an_external_drive_without_feedback_never_enables() {
    // Nothing at the edge: the statusword stays 0 (not ready to switch on); MC_Power waits and
    // the enable sequence's timeout (0.5 s) raises the drive alarm instead of enabling.
    let cell = external_cell();
    let mut exec = Executive::new(&cell, Some(0)).unwrap();
    let mut log = Vec::new();
    let r = exec
        .apply_at(
            0,
            0,
            "slide",
            "test",
            Action::Command(Command::Power {
                enable: true,
                start_mode: StartMode::PositionControlled,
                stop_mode: StopMode::Emergency,
            }),
            &mut log,
        )
        .unwrap();
    assert!(r.is_ok());
    for k in 0..400 {
        exec.step(k * CYCLE, &mut log).unwrap();
    }
    let log = String::from_utf8(log).unwrap();
    assert!(!log.contains("Status TRUE"), "{log}");
    assert!(log.contains("slide alarm"), "{log}");
    // The command the edge would send asks for shutdown (0x0006) first.
    let dev = cell
        .devices
        .iter()
        .position(|d| d.name == "slide_servo")
        .unwrap();
    assert!(exec.drive_command(dev).is_some());
}
