//! The torque feedforward keys of a CiA 402 drive connection (`[axes.<name>.drive]
//! torque_precontrol`, `inertia`): their defaults, their values, and the refusals naming the key.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::{parse, DriveConnection};

const CELL: &str = r#"
[cell]
name = "t"

[[nodes]]
name = "n"
cycle_us = 1000

[devices.servo1]
node = "n"
kind = "sim_servo"
inertia = 0.0003

[axes.x]
node = "n"

[axes.x.drive]
type = "cia402"
device = "servo1"

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

fn precontrol(src: &str) -> Option<f64> {
    let c = parse("cell.toml", src).unwrap();
    let DriveConnection::Cia402(d) = &c.axes[0].drive else {
        panic!("{:?}", c.axes[0].drive);
    };
    d.torque_precontrol_inertia
}

#[test]
fn torque_precontrol_is_off_by_default_and_takes_the_servos_inertia() {
    assert_eq!(precontrol(CELL), None);
    let on = CELL.replace(
        "device = \"servo1\"",
        "device = \"servo1\"\ntorque_precontrol = true",
    );
    assert_eq!(precontrol(&on), Some(0.0003), "the device's inertia");
    let given = on.replace(
        "torque_precontrol = true",
        "torque_precontrol = true\ninertia = 0.002",
    );
    assert_eq!(precontrol(&given), Some(0.002));
}

#[test]
fn bad_or_misplaced_keys_are_refused_naming_the_key() {
    let bad = CELL.replace("device = \"servo1\"", "device = \"servo1\"\ninertia = -1.0");
    let e = parse("cell.toml", &bad).expect_err("a negative inertia");
    assert_eq!(e.key, "axes.x.drive.inertia", "{e}");
    let line = bad
        .lines()
        .position(|l| l.starts_with("inertia = -1"))
        .unwrap()
        + 1;
    assert_eq!(e.line, Some(line), "{e}");
    // On the simulated drive the keys of a drive of the process image are refused.
    let sim = CELL.replace(
        "type = \"cia402\"\ndevice = \"servo1\"",
        "torque_precontrol = true",
    );
    let e = parse("cell.toml", &sim).expect_err("not on a simulated drive");
    assert_eq!(e.key, "axes.x.drive.torque_precontrol", "{e}");
}
