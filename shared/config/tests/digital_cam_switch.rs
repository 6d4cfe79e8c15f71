//! `[[digital_cam_switches]]` (MC_DigitalCamSwitch_BkPlcMc): the bundled example loads as
//! written; every bad key is refused by its key path with the hydraulic library's code; the
//! script instruction takes `enable` and `enable_mask`.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;
use tandem_config::parse;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::digital_cam_switch::{CamSwitchMode, SwitchDirection};

const CELL: &str = r#"
[cell]
name = "t"

[[nodes]]
name = "n"
cycle_us = 1000

[axes.x]
node = "n"

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

[devices.dq]
node = "n"
kind = "sim_digital_output"
channels = 2

[signals.a]
device = "dq"
channel = 1

[[digital_cam_switches]]
name = "dcs"
axis = "x"
tracks = [{ on_compensation = -0.1, output = "a" }, { hysteresis = 0.5 }]
switches = [
  { track_number = 1, first_on_position = 0.0, last_on_position = 10.0 },
  { track_number = 2, first_on_position = 5.0, cam_switch_mode = 1, duration = 0.2, axis_direction = 2 },
]
"#;

#[test]
fn the_bundled_example_loads_with_the_library_example() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cell = tandem_config::load(&root.join("config/hydraulic-cam-switch.toml")).unwrap();
    let d = &cell.digital_cam_switches[0];
    assert_eq!(d.name, "cams");
    assert_eq!(d.switches.len(), 4);
    assert_eq!(d.tracks[0].on_compensation, -0.125);
    assert_eq!(d.tracks[0].off_compensation, 0.25);
    assert_eq!(d.switches[1].axis_direction, SwitchDirection::Negative);
    assert_eq!(d.switches[3].cam_switch_mode, CamSwitchMode::Time);
    assert_eq!(d.switches[3].duration, 1.35);
    assert_eq!(d.outputs, vec![cell.signal("cam1"), cell.signal("cam2")]);
    assert_eq!(cell.object_axis("cams"), Some(d.axis));
}

#[test]
fn a_cell_parses_and_each_bad_key_is_named_with_its_code() {
    let c = parse("cell.toml", CELL).unwrap();
    let d = &c.digital_cam_switches[0];
    assert_eq!(d.outputs, vec![c.signal("a"), None]);
    assert_eq!(d.switches[1].last_on_position, 5.0);
    for (from, to, key, msg) in [
        (
            "track_number = 2",
            "track_number = 3",
            "digital_cam_switches[0].switches[1].track_number",
            "16#4104",
        ),
        (
            "track_number = 1",
            "track_number = 0",
            "digital_cam_switches[0].switches[0].track_number",
            "16#4104",
        ),
        (
            "last_on_position = 10.0",
            "last_on_position = -1.0",
            "digital_cam_switches[0].switches[0].last_on_position",
            "16#0706",
        ),
        (
            ", last_on_position = 10.0",
            "",
            "digital_cam_switches[0].switches[0].last_on_position",
            "must be given",
        ),
        (
            "duration = 0.2",
            "duration = -0.2",
            "digital_cam_switches[0].switches[1].duration",
            "16#0706",
        ),
        (
            "axis_direction = 2",
            "axis_direction = 3",
            "digital_cam_switches[0].switches[1].axis_direction",
            "16#4107",
        ),
        (
            "cam_switch_mode = 1",
            "cam_switch_mode = 2",
            "digital_cam_switches[0].switches[1].cam_switch_mode",
            "16#4107",
        ),
        (
            "on_compensation = -0.1",
            "on_compensation = -200.0",
            "digital_cam_switches[0].tracks[0].on_compensation",
            "within ±100 s",
        ),
        (
            "hysteresis = 0.5",
            "hysteresis = -0.5",
            "digital_cam_switches[0].tracks[1].hysteresis",
            "16#0706",
        ),
        (
            "output = \"a\"",
            "output = \"b\"",
            "digital_cam_switches[0].tracks[0].output",
            "unknown signal `b`",
        ),
        (
            "axis = \"x\"\ntracks",
            "axis = \"y\"\ntracks",
            "digital_cam_switches[0].axis",
            "unknown axis `y`",
        ),
    ] {
        let bad = CELL.replace(from, to);
        assert_ne!(bad, CELL, "{from}");
        let e = parse("cell.toml", &bad).unwrap_err();
        assert_eq!(e.key, key, "{to}: {e}");
        assert!(e.problem.to_string().contains(msg), "{to}: {e}");
    }
}

#[test]
fn the_instruction_takes_enable_and_the_mask() {
    let c = parse("cell.toml", CELL).unwrap();
    let script = |body: &str| {
        let src = format!("[sim]\nduration = 1.0\n\n[[at]]\nt = 0.0\naxis = \"dcs\"\ninstruction = \"MC_DigitalCamSwitch_BkPlcMc\"\n{body}");
        tandem_config::script::parse_cell("s.toml", &src, &c)
    };
    let s = script("enable_mask = 0b10").unwrap();
    assert_eq!(
        s.entries[0].action,
        Action::DigitalCamSwitch {
            enable: true,
            enable_mask: 2
        }
    );
    let s = script("enable = false").unwrap();
    assert_eq!(
        s.entries[0].action,
        Action::DigitalCamSwitch {
            enable: false,
            enable_mask: u32::MAX
        }
    );
    assert!(script("enable_mask = -1").is_err());
    assert!(script("enable_mask = 4294967296").is_err());
    assert!(script("mask = 1").is_err());
}
