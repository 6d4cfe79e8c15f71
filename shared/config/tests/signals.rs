//! `[devices.<name>]` of kind `sim_digital_output`, `[signals.<name>]` and the `output` of output
//! cams and cam tracks: the bindings of a good cell, and every binding `tandem check` refuses,
//! named by file, line and key.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::{parse, DeviceKind, DigitalOutputParams, Problem, SignalIndex, SignalType};

const CELL: &str = r#"
[cell]
name = "t"

[[nodes]]
name = "n"
cycle_us = 1000

[[nodes]]
name = "m"
cycle_us = 2000

[devices.dq]
node = "n"
kind = "sim_digital_output"
channels = 4
timestamped = true

[devices.plain]
node = "n"
kind = "sim_digital_output"
channels = 8

[devices.remote]
node = "m"
kind = "sim_digital_output"
channels = 2

[devices.servo]
node = "n"
kind = "sim_servo"

[signals.valve]
device = "dq"
channel = 1

[signals.mark]
device = "plain"
channel = 8

[signals.far]
device = "remote"
channel = 2

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

[[output_cams]]
name = "cam"
axis = "x"
output = "valve"

[[output_cams]]
name = "spare"
axis = "x"

[[cam_tracks]]
name = "track"
axis = "x"
track_length = 100.0
cams = [{ on = 10.0, off = 20.0 }]
output = "mark"
"#;

/// The cell with `from` replaced by `to` (which must occur).
fn with(from: &str, to: &str) -> String {
    assert!(CELL.contains(from), "{from}");
    CELL.replacen(from, to, 1)
}

/// The error of a cell that must be refused: `(line, key, problem)`.
fn refused(src: &str) -> (Option<usize>, String, Problem) {
    let e = parse("cell.toml", src).expect_err("must be refused");
    // The message names the file, the line and the key.
    let text = e.to_string();
    assert!(
        text.starts_with(&format!("cell.toml:{}: {}: ", e.line.unwrap_or(0), e.key)),
        "{text}"
    );
    (e.line, e.key.clone(), *e.problem)
}

/// The 1-based line of the `n`-th (0-based) line containing `text`.
fn line_of(src: &str, text: &str, n: usize) -> usize {
    src.lines()
        .enumerate()
        .filter(|(_, l)| l.contains(text))
        .nth(n)
        .unwrap()
        .0
        + 1
}

#[test]
fn signals_on_channels_driven_by_output_cams_and_cam_tracks() {
    let c = parse("cell.toml", CELL).unwrap();
    let dq = c.devices.iter().position(|d| d.name == "dq").unwrap();
    assert_eq!(
        c.devices[dq].kind,
        DeviceKind::SimDigitalOutput(DigitalOutputParams {
            channels: 4,
            timestamped: true
        })
    );
    let plain = c.devices.iter().position(|d| d.name == "plain").unwrap();
    assert_eq!(
        c.devices[plain].kind,
        DeviceKind::SimDigitalOutput(DigitalOutputParams {
            channels: 8,
            timestamped: false
        }),
        "timestamped defaults to false"
    );
    // Signals in name order, typed by their channel.
    let names: Vec<&str> = c.signals.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["far", "mark", "valve"]);
    let valve = c.signal("valve").unwrap();
    let s = &c.signals[valve.0];
    assert_eq!((s.device.0, s.channel), (dq, 1));
    assert_eq!(s.signal_type, SignalType::TimestampedBool);
    assert_eq!(c.signals[1].signal_type, SignalType::Bool);
    assert_eq!(c.output_cams[0].output, Some(valve));
    assert_eq!(c.output_cams[1].output, None);
    assert_eq!(c.cam_tracks[0].output, Some(SignalIndex(1)));
    // The bundled glue-dot example drives a timestamped and a plain output.
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let g = tandem_config::load(&root.join("config/glue-dot.toml")).unwrap();
    let track = g.cam_tracks[0].output.unwrap();
    assert_eq!(g.signals[track.0].signal_type, SignalType::TimestampedBool);
    let cam = g.output_cams[0].output.unwrap();
    assert_eq!(g.signals[cam.0].signal_type, SignalType::Bool);
}

#[test]
fn a_channel_bound_to_two_signals_is_refused_at_the_second() {
    // `valve` is dq channel 1; `zz` (after it in name order) takes the same channel.
    let src = format!("{CELL}\n[signals.zz]\ndevice = \"dq\"\nchannel = 1\n");
    let (line, key, problem) = refused(&src);
    assert_eq!(key, "signals.zz.channel");
    assert_eq!(line, Some(src.lines().count()));
    assert_eq!(
        problem,
        Problem::ChannelTaken {
            device: "dq".into(),
            channel: 1,
            signal: "valve".into()
        }
    );
}

#[test]
fn a_channel_out_of_range_is_refused() {
    for (channel, text) in [
        (5, "channel = 5"),
        (0, "channel = 0"),
        (300, "channel = 300"),
    ] {
        let src = with("channel = 1", text);
        let (line, key, problem) = refused(&src);
        assert_eq!(key, "signals.valve.channel");
        assert_eq!(line, Some(line_of(&src, text, 0)));
        assert_eq!(
            problem,
            Problem::ChannelRange {
                device: "dq".into(),
                channel,
                channels: 4
            }
        );
    }
}

#[test]
fn a_signal_of_another_node_than_its_object_is_refused() {
    let src = with("output = \"valve\"", "output = \"far\"");
    let (line, key, problem) = refused(&src);
    assert_eq!(key, "output_cams[0].output");
    assert_eq!(line, Some(line_of(&src, "output = \"far\"", 0)));
    assert_eq!(
        problem,
        Problem::SignalNode {
            signal: "far".into(),
            signal_node: "m".into(),
            object_node: "n".into()
        }
    );
}

#[test]
fn a_signal_driven_by_two_objects_is_refused_at_the_second() {
    // The cam track drives `valve` too.
    let src = with("output = \"mark\"", "output = \"valve\"");
    let (line, key, problem) = refused(&src);
    assert_eq!(key, "cam_tracks[0].output");
    assert_eq!(line, Some(line_of(&src, "output = \"valve\"", 1)));
    assert_eq!(
        problem,
        Problem::SignalDriven {
            signal: "valve".into(),
            by: "cam".into()
        }
    );
    // Two output cams.
    let src = with(
        "name = \"spare\"\naxis = \"x\"\n",
        "name = \"spare\"\naxis = \"x\"\noutput = \"valve\"\n",
    );
    let (_, key, _) = refused(&src);
    assert_eq!(key, "output_cams[1].output");
}

#[test]
fn an_unknown_signal_or_device_is_refused() {
    let src = with("output = \"mark\"", "output = \"nope\"");
    let (line, key, problem) = refused(&src);
    assert_eq!(key, "cam_tracks[0].output");
    assert_eq!(line, Some(line_of(&src, "output = \"nope\"", 0)));
    assert!(
        matches!(&problem, Problem::Unknown { what: "signal", name, .. } if name == "nope"),
        "{problem:?}"
    );
    let src = with("device = \"plain\"", "device = \"nope\"");
    let (line, key, problem) = refused(&src);
    assert_eq!(key, "signals.mark.device");
    assert_eq!(line, Some(line_of(&src, "device = \"nope\"", 0)));
    assert!(
        matches!(&problem, Problem::Unknown { what: "device", name, .. } if name == "nope"),
        "{problem:?}"
    );
}

#[test]
fn a_signal_on_a_drive_and_a_drive_on_an_output_are_refused() {
    let src = with("device = \"plain\"", "device = \"servo\"");
    let (line, key, problem) = refused(&src);
    assert_eq!(key, "signals.mark.device");
    assert_eq!(line, Some(line_of(&src, "device = \"servo\"", 0)));
    assert!(
        matches!(
            &problem,
            Problem::DeviceKind {
                kind: "sim_servo",
                ..
            }
        ),
        "{problem:?}"
    );
    let src = with(
        "[axes.x]\nnode = \"n\"\n",
        "[axes.x]\nnode = \"n\"\n\n[axes.x.drive]\ntype = \"cia402\"\ndevice = \"dq\"\n",
    );
    let (_, key, problem) = refused(&src);
    assert_eq!(key, "axes.x.drive.device");
    assert!(
        matches!(
            &problem,
            Problem::DeviceKind {
                kind: "sim_digital_output",
                ..
            }
        ),
        "{problem:?}"
    );
}

#[test]
fn the_keys_of_a_digital_output_are_checked() {
    let (_, key, problem) = refused(&with("channels = 4\n", "channels = 33\n"));
    assert_eq!(key, "devices.dq.channels");
    assert_eq!(problem, Problem::Invalid("must be 1 to 32"));
    let (_, key, problem) = refused(&with("channels = 4\n", ""));
    assert_eq!(key, "devices.dq.channels");
    assert_eq!(problem, Problem::Missing("channels"));
    let (_, key, problem) = refused(&with("channels = 8\n", "channels = 8\nkv = 10.0\n"));
    assert_eq!(key, "devices.plain.kv");
    assert_eq!(problem, Problem::NotForKind("sim_digital_output"));
    let (_, key, problem) = refused(&with(
        "kind = \"sim_servo\"\n",
        "kind = \"sim_servo\"\ntimestamped = true\n",
    ));
    assert_eq!(key, "devices.servo.timestamped");
    assert_eq!(problem, Problem::NotForKind("sim_servo"));
}
