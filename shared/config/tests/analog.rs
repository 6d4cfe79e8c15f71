//! `[axes.<name>.drive] type = "analog"` and `[devices.<name>] kind = "sim_analog_drive"`: an
//! axis on a simulated analog drive with its encoder, the controller's keys, and every binding
//! and value `tandem check` refuses, named by file, line and key.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::{parse, DeviceKind, DriveConnection, Problem};
use tandem_motion::plant::analog::SimAnalogParams;
use tandem_motion::plant::mechanics::Mounting;

const CELL: &str = r#"
[cell]
name = "t"

[[nodes]]
name = "n"
cycle_us = 2000

[devices.amp]
node = "n"
kind = "sim_analog_drive"
reference_speed = 3000.0
time_constant = 0.005

[devices.servo]
node = "n"
kind = "sim_servo"

[axes.x]
node = "n"

[axes.x.drive]
type = "analog"
device = "amp"
reference_velocity = 500.0
kv = 40.0
kpc = 80.0
t_vtc = 0.005
ready = false
enable_timeout = 0.2

[axes.x.encoder]
steps_per_revolution = 4096
fine_resolution_bits = 8
raw_bits = 32
mounting = "load_side"

[axes.x.mechanics]
leadscrew_pitch = 10.0

[axes.x.dynamics]
max_velocity = 400.0
max_acceleration = 4000.0
max_deceleration = 4000.0
max_jerk = 40000.0
velocity = 200.0
acceleration = 2000.0
deceleration = 2000.0
jerk = 20000.0
emergency_deceleration = 5000.0
"#;

/// The cell with `from` replaced by `to` (which must occur).
fn with(from: &str, to: &str) -> String {
    assert!(CELL.contains(from), "{from}");
    CELL.replacen(from, to, 1)
}

/// The error of a cell that must be refused: `(line, key, problem)`.
fn refused(src: &str) -> (Option<usize>, String, Problem) {
    let e = parse("cell.toml", src).expect_err("must be refused");
    assert_eq!(e.file, "cell.toml");
    (e.line, e.key.clone(), *e.problem)
}

fn line_of(src: &str, text: &str) -> usize {
    src.lines().position(|l| l.contains(text)).unwrap() + 1
}

#[test]
fn an_axis_on_a_simulated_analog_drive_with_its_encoder() {
    let c = parse("cell.toml", CELL).unwrap();
    let DeviceKind::SimAnalogDrive(p) = &c.devices[0].kind else {
        panic!("{:?}", c.devices[0].kind);
    };
    assert_eq!(
        *p,
        SimAnalogParams {
            reference_speed: 3000.0,
            time_constant: 0.005,
            ..SimAnalogParams::example()
        }
    );
    let DriveConnection::Analog(d) = &c.axes[0].drive else {
        panic!("{:?}", c.axes[0].drive);
    };
    assert_eq!(d.device.0, 0);
    let ctl = d.params.controller;
    assert_eq!(ctl.cycle_ns, 2_000_000, "the node's cycle");
    assert_eq!(
        (ctl.kv, ctl.kpc_percent, ctl.velocity_time_constant),
        (40.0, 80.0, 0.005)
    );
    assert_eq!(ctl.additional_position_time_constant, 0.0);
    assert_eq!(ctl.reference_velocity, 500.0);
    assert!(!d.params.ready);
    assert_eq!(d.params.enable_timeout_ns, 200_000_000);
    let s = d.params.scaling;
    assert_eq!(s.encoder().mounting, Mounting::LoadSide);
    // 4096 * 2^8 counts per load revolution of 10 mm.
    assert_eq!(s.position(4096 * 256), 10.0);
    assert_eq!(s.mechanics().drive_increments_per_revolution, None);
    // Defaults: ready wired, T_addPtc 0, a 1 s timeout.
    let src = with("ready = false\nenable_timeout = 0.2\n", "");
    let c = parse("cell.toml", &src).unwrap();
    let DriveConnection::Analog(d) = &c.axes[0].drive else {
        panic!();
    };
    assert!(d.params.ready);
    assert_eq!(d.params.enable_timeout_ns, 1_000_000_000);
}

#[test]
fn analog_connection_keys_are_checked_naming_the_key() {
    // The reference velocity is required.
    let src = with("reference_velocity = 500.0\n", "");
    let (line, key, p) = refused(&src);
    assert_eq!(key, "axes.x.drive");
    assert_eq!(line, Some(line_of(&src, "[axes.x.drive]")));
    assert_eq!(p, Problem::Missing("reference_velocity"));
    let src = with("reference_velocity = 500.0", "reference_velocity = -1.0");
    let (line, key, p) = refused(&src);
    assert_eq!(key, "axes.x.drive.reference_velocity");
    assert_eq!(line, Some(line_of(&src, "reference_velocity = -1.0")));
    assert_eq!(p, Problem::Invalid("must be positive"));
    // Kpc is 0..150 % (S7 PositionControl.Kpc), Kv not negative.
    let src = with("kpc = 80.0", "kpc = 151.0");
    let (line, key, p) = refused(&src);
    assert_eq!(key, "axes.x.drive.kpc");
    assert_eq!(line, Some(line_of(&src, "kpc = 151.0")));
    // The axis's own check of the key (shared with the simulated drive model) comes first.
    assert!(p.to_string().contains("150"), "{p}");
    let src = with("kv = 40.0", "kv = -4.0");
    assert_eq!(refused(&src).1, "axes.x.drive.kv");
    let src = with("t_vtc = 0.005", "t_vtc = 0.005\nt_addptc = -0.001");
    let (_, key, p) = refused(&src);
    assert_eq!(key, "axes.x.drive.t_addptc");
    assert_eq!(p, Problem::Invalid("must be zero or positive"));
    // The encoder: a table with its steps (the drive has none of its own), incremental.
    let src = with("steps_per_revolution = 4096\n", "");
    let (_, key, p) = refused(&src);
    assert_eq!(key, "axes.x.encoder");
    assert_eq!(p, Problem::Missing("steps_per_revolution"));
    let src = with(
        "[axes.x.encoder]\nsteps_per_revolution = 4096\nfine_resolution_bits = 8\nraw_bits = 32\nmounting = \"load_side\"\n",
        "",
    );
    assert_eq!(refused(&src).1, "axes.x.encoder");
    let src = with(
        "[axes.x.encoder]\n",
        "[axes.x.encoder]\ntype = \"absolute\"\n",
    );
    let (line, key, _) = refused(&src);
    assert_eq!(key, "axes.x.encoder.type");
    assert_eq!(line, Some(line_of(&src, "type = \"absolute\"")));
    // Mechanics that cannot convert.
    let src = with("leadscrew_pitch = 10.0", "leadscrew_pitch = 0.0");
    let (_, key, p) = refused(&src);
    assert_eq!(key, "axes.x.mechanics.leadscrew_pitch");
    assert!(matches!(p, Problem::Mechanics(_)), "{p:?}");
    // The timeout as for a CiA 402 drive.
    let src = with("enable_timeout = 0.2", "enable_timeout = 0.0");
    assert_eq!(refused(&src).1, "axes.x.drive.enable_timeout");
}

#[test]
fn analog_bindings_are_refused_naming_file_line_and_key() {
    // A servo for an analog connection, and an analog drive for a CiA 402 one.
    let src = with("device = \"amp\"", "device = \"servo\"");
    let (line, key, p) = refused(&src);
    assert_eq!(key, "axes.x.drive.device");
    assert_eq!(line, Some(line_of(&src, "device = \"servo\"")));
    assert_eq!(
        p,
        Problem::DeviceKind {
            device: "servo".into(),
            kind: "sim_servo",
            needs: "an analog drive (`sim_analog_drive`)"
        }
    );
    let src = with(
        "type = \"analog\"\ndevice = \"amp\"\nreference_velocity = 500.0",
        "type = \"cia402\"\ndevice = \"amp\"",
    )
    .replace("ready = false\n", "");
    let (_, key, p) = refused(&src);
    assert_eq!(key, "axes.x.drive.device");
    assert!(p.to_string().contains("sim_analog_drive"), "{p}");
    // An analog key on a CiA 402 connection.
    let src = with(
        "type = \"analog\"\ndevice = \"amp\"",
        "type = \"cia402\"\ndevice = \"servo\"",
    );
    let (line, key, _) = refused(&src);
    assert_eq!(key, "axes.x.drive.reference_velocity");
    assert_eq!(line, Some(line_of(&src, "reference_velocity = 500.0")));
    // An analog key on the simulated drive.
    let src = with(
        "type = \"analog\"\ndevice = \"amp\"\nreference_velocity = 500.0\n",
        "",
    );
    let src = src.replace("[axes.x.encoder]\nsteps_per_revolution = 4096\nfine_resolution_bits = 8\nraw_bits = 32\nmounting = \"load_side\"\n", "");
    let src = src.replace("[axes.x.mechanics]\nleadscrew_pitch = 10.0\n", "");
    let src = src.replace("enable_timeout = 0.2\n", "");
    let (line, key, p) = refused(&src);
    assert_eq!(key, "axes.x.drive.ready");
    assert_eq!(line, Some(line_of(&src, "ready = false")));
    assert_eq!(p, Problem::OnlyWithDrive);
    // One drive, two axes.
    let second = CELL.replace("[axes.x", "[axes.y");
    let body = second.split("[axes.y]").nth(1).unwrap();
    let src = format!("{CELL}\n[axes.y]{body}");
    let (_, key, p) = refused(&src);
    assert_eq!(key, "axes.y.drive.device");
    assert_eq!(
        p,
        Problem::DeviceTaken {
            device: "amp".into(),
            axis: "x".into()
        }
    );
    // The unknown type lists analog.
    let src = with("type = \"analog\"", "type = \"pwm\"");
    let (_, _, p) = refused(&src);
    assert!(p.to_string().contains("simulation, cia402, analog"), "{p}");
}

#[test]
fn analog_device_parameters_are_checked_naming_the_key() {
    let src = with("time_constant = 0.005", "time_constant = -0.005");
    let (line, key, p) = refused(&src);
    assert_eq!(key, "devices.amp.time_constant");
    assert_eq!(line, Some(line_of(&src, "time_constant = -0.005")));
    assert_eq!(p, Problem::Invalid("must be zero or positive"));
    let src = with(
        "reference_speed = 3000.0",
        "reference_speed = 3000.0\noffset = 12.0",
    );
    let (_, key, p) = refused(&src);
    assert_eq!(key, "devices.amp.offset");
    assert_eq!(p, Problem::Invalid("is out of range"));
    let src = with("reference_speed = 3000.0", "reference_speed = 0.0");
    assert_eq!(refused(&src).1, "devices.amp.reference_speed");
    // A servo's key on an analog drive, an analog drive's key on a servo.
    let src = with("time_constant = 0.005", "inertia = 0.001");
    let (line, key, p) = refused(&src);
    assert_eq!(key, "devices.amp.inertia");
    assert_eq!(line, Some(line_of(&src, "inertia = 0.001")));
    assert_eq!(p, Problem::NotForKind("sim_analog_drive"));
    let src = with(
        "kind = \"sim_servo\"",
        "kind = \"sim_servo\"\nramp_down_time = 0.2",
    );
    let (_, key, p) = refused(&src);
    assert_eq!(key, "devices.servo.ramp_down_time");
    assert_eq!(p, Problem::NotForKind("sim_servo"));
}
