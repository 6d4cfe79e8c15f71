//! `[devices.<name>]` and the drive connection of an axis: a CiA 402 drive of the node's process
//! image with its encoder and mechanics, and every binding `tandem check` refuses, named by
//! file, line and key.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::{parse, DeviceKind, DriveConnection, Problem};

const CELL: &str = r#"
[cell]
name = "t"

[[nodes]]
name = "n"
cycle_us = 1000

[[nodes]]
name = "m"
cycle_us = 1000

[devices.servo1]
node = "n"
kind = "sim_servo"
increments_per_revolution = 1048576

[devices.servo2]
node = "m"
kind = "sim_servo"

[axes.x]
node = "n"

[axes.x.drive]
type = "cia402"
device = "servo1"

[axes.x.mechanics]
load_gear = [3, 1]

[axes.x.dynamics]
max_velocity = 100.0
max_acceleration = 1000.0
max_deceleration = 1000.0
max_jerk = 10000.0
velocity = 50.0
acceleration = 500.0
deceleration = 500.0
jerk = 5000.0
emergency_deceleration = 2000.0
"#;

/// The cell with `from` replaced by `to` (which must occur).
fn with(from: &str, to: &str) -> String {
    assert!(CELL.contains(from), "{from}");
    CELL.replacen(from, to, 1)
}

/// The error of a cell that must be refused: `(line, key, problem)`.
fn refused(src: &str) -> (Option<usize>, String, Problem) {
    let e = parse("cell.toml", src).expect_err("must be refused");
    (e.line, e.key.clone(), *e.problem)
}

fn line_of(src: &str, text: &str) -> usize {
    src.lines().position(|l| l.contains(text)).unwrap() + 1
}

#[test]
fn an_axis_on_a_simulated_cia402_drive_with_its_mechanics() {
    let c = parse("cell.toml", CELL).unwrap();
    assert_eq!(c.devices.len(), 2);
    assert_eq!(c.devices[0].name, "servo1");
    let DeviceKind::SimServo(p) = &c.devices[0].kind else {
        panic!("{:?}", c.devices[0].kind);
    };
    assert_eq!(p.increments_per_revolution, 1 << 20);
    assert_eq!(p.cycle_ns, 1_000_000, "the node's cycle");
    let DriveConnection::Cia402(d) = &c.axes[0].drive else {
        panic!("{:?}", c.axes[0].drive);
    };
    assert_eq!(d.device.0, 0);
    assert_eq!(d.enable_timeout_ns, 1_000_000_000, "default 1 s");
    // Motor encoder of 2^20 increments, gear 3:1, rotary: one load revolution (360 units) is
    // three motor revolutions.
    assert_eq!(d.scaling.position(3 << 20), 360.0);
    assert_eq!(d.scaling.drive_increments(120.0), 1 << 20);
}

#[test]
fn an_axis_without_a_drive_table_keeps_the_simulated_drive() {
    let src = with(
        "type = \"cia402\"\ndevice = \"servo1\"",
        "model = \"delay\"",
    )
    .replace("[axes.x.mechanics]\nload_gear = [3, 1]\n", "");
    let c = parse("cell.toml", &src).unwrap();
    assert_eq!(c.axes[0].drive, DriveConnection::Simulation);
}

#[test]
fn bad_bindings_are_refused_naming_file_line_and_key() {
    // A device of another node.
    let src = with("device = \"servo1\"", "device = \"servo2\"");
    let (line, key, p) = refused(&src);
    assert_eq!(key, "axes.x.drive.device");
    assert_eq!(line, Some(line_of(&src, "device = \"servo2\"")));
    assert!(matches!(p, Problem::DeviceNode { .. }), "{p:?}");
    // An unknown device, listing the known ones.
    let src = with("device = \"servo1\"", "device = \"servo9\"");
    let (_, key, p) = refused(&src);
    assert_eq!(key, "axes.x.drive.device");
    assert!(p.to_string().contains("servo1, servo2"), "{p}");
    // A drive bound to two axes.
    let second = CELL.replace("[axes.x", "[axes.y");
    let body = second.split("[axes.y]").nth(1).unwrap();
    let src = format!("{CELL}\n[axes.y]{body}");
    let (_, key, p) = refused(&src);
    assert_eq!(key, "axes.y.drive.device");
    assert_eq!(
        p,
        Problem::DeviceTaken {
            device: "servo1".into(),
            axis: "x".into()
        }
    );
    // No device.
    let src = with("device = \"servo1\"", "");
    let (_, key, p) = refused(&src);
    assert_eq!(key, "axes.x.drive");
    assert_eq!(p, Problem::Missing("device"));
    // A virtual axis has no drive.
    let src = with(
        "node = \"n\"\n\n[axes.x.drive]",
        "node = \"n\"\nvirtual = true\n\n[axes.x.drive]",
    );
    let (_, key, p) = refused(&src);
    assert_eq!(key, "axes.x.virtual");
    assert_eq!(p, Problem::VirtualWithDrive);
    // Mechanics on the simulated drive.
    let src = with("type = \"cia402\"\ndevice = \"servo1\"", "");
    let (line, key, p) = refused(&src);
    assert_eq!(key, "axes.x.mechanics");
    assert_eq!(line, Some(line_of(&src, "[axes.x.mechanics]")));
    assert_eq!(p, Problem::OnlyWithDrive);
    // An unknown drive type.
    let src = with("type = \"cia402\"", "type = \"profidrive\"");
    let (_, key, p) = refused(&src);
    assert_eq!(key, "axes.x.drive.type");
    assert!(p.to_string().contains("simulation, cia402"), "{p}");
}

#[test]
fn units_that_cannot_be_converted_are_refused_with_the_rule() {
    // A zero gear.
    let src = with("load_gear = [3, 1]", "load_gear = [0, 1]");
    let (line, key, p) = refused(&src);
    assert_eq!(key, "axes.x.mechanics.load_gear");
    assert_eq!(line, Some(line_of(&src, "load_gear = [0, 1]")));
    assert!(matches!(p, Problem::Mechanics(_)), "{p:?}");
    assert!(p.to_string().contains("LoadGear.Numerator"), "{p}");
    // An external measuring system without its distance per revolution.
    let src = with(
        "[axes.x.mechanics]",
        "[axes.x.encoder]\ntype = \"absolute\"\nsteps_per_revolution = 4096\ndeterminable_revolutions = 4096\nraw_bits = 24\nmounting = \"external\"\n\n[axes.x.mechanics]",
    );
    let (_, key, p) = refused(&src);
    assert_eq!(key, "axes.x.encoder.distance_per_revolution");
    assert!(p.to_string().contains("DistancePerRevolution"), "{p}");
    // An absolute encoder whose range does not fit its raw word.
    let src = with(
        "[axes.x.mechanics]",
        "[axes.x.encoder]\ntype = \"absolute\"\nsteps_per_revolution = 4096\ndeterminable_revolutions = 8192\nraw_bits = 24\n\n[axes.x.mechanics]",
    );
    let (_, key, p) = refused(&src);
    assert_eq!(key, "axes.x.encoder.determinable_revolutions");
    assert!(p.to_string().contains("24-bit raw word"), "{p}");
    // A mounting that does not exist.
    let src = with(
        "[axes.x.mechanics]",
        "[axes.x.encoder]\nmounting = \"belt\"\n\n[axes.x.mechanics]",
    );
    let (_, key, p) = refused(&src);
    assert_eq!(key, "axes.x.encoder.mounting");
    assert!(
        p.to_string().contains("motor_shaft, load_side, external"),
        "{p}"
    );
}

#[test]
fn servo_parameters_the_model_refuses_name_their_key() {
    let src = with("increments_per_revolution = 1048576", "inertia = -1.0");
    let (line, key, p) = refused(&src);
    assert_eq!(key, "devices.servo1.inertia");
    assert_eq!(line, Some(line_of(&src, "inertia = -1.0")));
    assert!(matches!(p, Problem::Servo(_)), "{p:?}");
    let src = with(
        "increments_per_revolution = 1048576",
        "quick_stop_option = 9",
    );
    let (_, key, _) = refused(&src);
    assert_eq!(key, "devices.servo1.quick_stop_option");
    let src = with("kind = \"sim_servo\"", "kind = \"sim_stepper\"");
    let (_, key, p) = refused(&src);
    assert_eq!(key, "devices.servo1.kind");
    assert!(p.to_string().contains("sim_servo"), "{p}");
}

#[test]
fn a_sensor_in_front_of_a_drive_touch_probe_is_on_the_inputs_own_axis() {
    let base = CELL.replace("[axes.x]", "[axes.v]\nnode = \"n\"\nvirtual = true\n\n[axes.v.dynamics]\nmax_velocity = 100.0\nmax_acceleration = 1000.0\nmax_deceleration = 1000.0\nmax_jerk = 10000.0\nvelocity = 50.0\nacceleration = 500.0\ndeceleration = 500.0\njerk = 5000.0\nemergency_deceleration = 2000.0\n\n[axes.x]");
    let probe = |sensor_axis: &str| {
        format!(
            "{base}\n[[measuring_inputs]]\nname = \"p\"\naxis = \"x\"\nroute = \"profidrive\"\n\n[measuring_inputs.sensor]\naxis = \"{sensor_axis}\"\nposition = 1.0\nwidth = 1.0\n"
        )
    };
    assert!(parse("cell.toml", &probe("x")).is_ok());
    let (_, key, p) = refused(&probe("v"));
    assert_eq!(key, "measuring_inputs[0].sensor.axis");
    assert!(p.to_string().contains("touch probe"), "{p}");
}
