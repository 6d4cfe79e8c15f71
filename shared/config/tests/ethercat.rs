//! `[[ethercat]]`: the segment a node drives, its expected SubDevices as devices of the node's
//! process image, the axis's drive on one of them, and every refusal named by key and line.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::{
    parse, DeviceKind, DriveConnection, EthercatDriveParams, EthercatIdentity, EthercatRole,
    Problem,
};

fn example() -> String {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/ethercat.toml");
    std::fs::read_to_string(root).unwrap()
}

/// The example with `from` replaced by `to` (which must occur).
fn with(from: &str, to: &str) -> String {
    let src = example();
    assert!(src.contains(from), "{from}");
    src.replacen(from, to, 1)
}

/// The error of a cell that must be refused: `(line, key, problem)`.
fn refused(src: &str) -> (Option<usize>, String, Problem) {
    let e = parse("cell.toml", src).expect_err("must be refused");
    (e.line, e.key.clone(), *e.problem)
}

/// The 1-based line of the first line of the example that contains `s`.
fn line_of(src: &str, s: &str) -> usize {
    src.lines().position(|l| l.contains(s)).unwrap() + 1
}

#[test]
fn the_example_segment_gives_the_node_its_devices_and_the_axis_its_drive() {
    let cell = parse("ethercat.toml", &example()).unwrap();
    assert_eq!(cell.ethercat.len(), 1);
    let seg = &cell.ethercat[0];
    assert_eq!(cell.nodes[seg.node].name, "drives");
    assert_eq!(seg.interface, "ecm");
    let names: Vec<&str> = seg.subdevices.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["slide_servo", "io"], "bus order kept");
    assert_eq!(
        seg.subdevices[0].identity,
        EthercatIdentity {
            vendor: 0x0054_444D,
            product: 0x402,
            revision: 0x0001_0000
        }
    );
    assert_eq!(seg.subdevices[0].role, EthercatRole::Cia402);
    assert_eq!(seg.subdevices[1].role, EthercatRole::Dio);
    assert_eq!(
        seg.subdevices[1].identity.to_string(),
        "vendor 0x00000002, product 0x07433052, revision 0x00100000"
    );
    // Devices stay in name order; each SubDevice's index points at its own device.
    let dev_names: Vec<&str> = cell.devices.iter().map(|d| d.name.as_str()).collect();
    assert_eq!(dev_names, ["io", "io_in", "slide_servo"]);
    let inputs = seg.subdevices[1].inputs.expect("the dio's inputs device");
    assert_eq!(cell.devices[inputs.0].name, "io_in");
    assert_eq!(cell.devices[inputs.0].kind, DeviceKind::EthercatDioInputs);
    assert_eq!(seg.subdevices[0].inputs, None);
    // Its channels are inputs, the terminal's are outputs.
    let lamp_back = cell.signal("lamp_back").unwrap();
    assert_eq!(cell.signals[lamp_back.0].device, inputs);
    assert_eq!(
        cell.signals[lamp_back.0].direction,
        tandem_config::SignalDirection::Input
    );
    let lamp = cell.signal("lamp").unwrap();
    assert_eq!(
        cell.signals[lamp.0].direction,
        tandem_config::SignalDirection::Output
    );
    for s in &seg.subdevices {
        assert_eq!(cell.devices[s.device.0].name, s.name);
        assert_eq!(cell.devices[s.device.0].node, seg.node);
    }
    assert_eq!(
        cell.devices[seg.subdevices[0].device.0].kind,
        DeviceKind::EthercatCia402(EthercatDriveParams {
            increments_per_revolution: 1 << 20,
            transport_cycles: 4,
        })
    );
    assert_eq!(
        cell.devices[seg.subdevices[1].device.0].kind,
        DeviceKind::EthercatDio
    );
    let DriveConnection::Cia402(c) = &cell.axes[0].drive else {
        panic!("the axis is on a CiA 402 drive");
    };
    assert_eq!(c.device, seg.subdevices[0].device);
    assert_eq!(c.torque_precontrol_inertia, None);
    // 3 motor revolutions per 10 mm: 1 mm is 3 · 2^20 / 10 increments.
    assert_eq!(c.scaling.drive_increments(10.0), 3 << 20);
}

#[test]
fn a_cell_without_ethercat_has_no_segment() {
    let src = example();
    let start = src.find("[[ethercat]]").unwrap();
    let end = src.find("[axes.slide]").unwrap();
    let mut cut = src.clone();
    cut.replace_range(
        start..end,
        "[devices.slide_servo]\nnode = \"drives\"\nkind = \"sim_servo\"\n",
    );
    let cell = parse("c.toml", &cut).unwrap();
    assert!(cell.ethercat.is_empty());
}

#[test]
fn an_unknown_node_is_refused() {
    let src = with(
        "node = \"drives\"                   # the node that owns",
        "node = \"nope\" #",
    );
    let (line, key, p) = refused(&src);
    assert_eq!(key, "ethercat[0].node");
    assert_eq!(line, Some(line_of(&src, "node = \"nope\"")));
    assert_eq!(p, Problem::UnknownNode("nope".into()));
}

#[test]
fn a_second_segment_on_one_node_is_refused() {
    let src = with(
        "[axes.slide]\nnode",
        "[[ethercat]]\nnode = \"drives\"\ninterface = \"eth9\"\n[[ethercat.subdevices]]\nname = \"x\"\nidentity = { vendor = 1, product = 2, revision = 3 }\nrole = \"dio\"\n[axes.slide]\nnode",
    );
    let (line, key, p) = refused(&src);
    assert_eq!(key, "ethercat[1].node");
    assert_eq!(line, Some(line_of(&src, "interface = \"eth9\"") - 1));
    assert!(
        matches!(p, Problem::Invalid(m) if m.contains("one EtherCAT segment")),
        "{p:?}"
    );
}

#[test]
fn an_interface_linux_cannot_have_is_refused() {
    for bad in ["", "a/b", "en p2", "a_name_of_16_chr", "eth0:1"] {
        let src = with("interface = \"ecm\"", &format!("interface = \"{bad}\""));
        let (line, key, p) = refused(&src);
        assert_eq!(key, "ethercat[0].interface", "{bad}");
        assert_eq!(line, Some(line_of(&src, "interface = ")), "{bad}");
        assert!(
            matches!(p, Problem::Invalid(m) if m.contains("network interface")),
            "{p:?}"
        );
    }
    // 15 characters are fine.
    parse(
        "c.toml",
        &with("interface = \"ecm\"", "interface = \"a_name_of_15_ch\""),
    )
    .unwrap();
}

#[test]
fn a_segment_without_subdevices_is_refused() {
    let src = example();
    let start = src.find("# The expected SubDevices").unwrap();
    let end = src.find("[axes.slide]\nnode").unwrap();
    let mut cut = src.clone();
    cut.replace_range(start..end, "");
    let (_, key, p) = refused(&cut);
    assert_eq!(key, "ethercat[0].subdevices");
    assert!(
        matches!(p, Problem::Invalid(m) if m.contains("1 to 64")),
        "{p:?}"
    );
}

#[test]
fn a_subdevice_name_taken_or_not_plain_is_refused() {
    // Taken by a device of [devices].
    let src = with(
        "[axes.slide]\nnode",
        "[devices.io]\nnode = \"drives\"\nkind = \"sim_servo\"\n[axes.slide]\nnode",
    );
    let (line, key, p) = refused(&src);
    assert_eq!(key, "ethercat[0].subdevices[1].name");
    assert_eq!(line, Some(line_of(&src, "name = \"io\"")));
    assert_eq!(p, Problem::NameTaken("io".into()));
    // Taken by the SubDevice before it.
    let src = with("name = \"io\"", "name = \"slide_servo\"");
    let (_, key, p) = refused(&src);
    assert_eq!(key, "ethercat[0].subdevices[1].name");
    assert_eq!(p, Problem::NameTaken("slide_servo".into()));
    // Not a plain name.
    let src = with("name = \"io\"", "name = \"i o\"");
    let (_, key, p) = refused(&src);
    assert_eq!(key, "ethercat[0].subdevices[1].name");
    assert!(
        matches!(p, Problem::BadName { what: "device", .. }),
        "{p:?}"
    );
}

#[test]
fn an_unknown_role_is_refused_with_the_roles() {
    let src = with("role = \"dio\"", "role = \"analog\"");
    let (line, key, p) = refused(&src);
    assert_eq!(key, "ethercat[0].subdevices[1].role");
    assert_eq!(line, Some(line_of(&src, "role = \"analog\"")));
    assert_eq!(
        p,
        Problem::NotOneOf {
            value: "analog".into(),
            options: vec!["cia402", "dio", "aio", "enc"]
        }
    );
}

#[test]
fn increments_per_revolution_only_on_a_drive_and_not_zero() {
    let src = with(
        "role = \"dio\"",
        "role = \"dio\"\nincrements_per_revolution = 4096",
    );
    let (_, key, p) = refused(&src);
    assert_eq!(key, "ethercat[0].subdevices[1].increments_per_revolution");
    assert!(
        matches!(p, Problem::Invalid(m) if m.contains("cia402")),
        "{p:?}"
    );
    let src = with(
        "increments_per_revolution = 1048576",
        "increments_per_revolution = 0",
    );
    let (line, key, p) = refused(&src);
    assert_eq!(key, "ethercat[0].subdevices[0].increments_per_revolution");
    assert_eq!(line, Some(line_of(&src, "increments_per_revolution = 0")));
    assert_eq!(p, Problem::Invalid("must be at least 1"));
}

#[test]
fn transport_cycles_from_2_to_8_on_a_drive_only() {
    for (v, ok) in [(1, false), (2, true), (8, true), (9, false)] {
        let src = with("transport_cycles = 4", &format!("transport_cycles = {v}"));
        match parse("c.toml", &src) {
            Ok(cell) => {
                assert!(ok, "{v} accepted");
                let d = cell.ethercat[0].subdevices[0].device.0;
                assert!(matches!(
                    cell.devices[d].kind,
                    DeviceKind::EthercatCia402(EthercatDriveParams { transport_cycles, .. })
                        if transport_cycles == v
                ));
            }
            Err(e) => {
                assert!(!ok, "{v} refused: {e}");
                assert_eq!(e.key, "ethercat[0].subdevices[0].transport_cycles");
                assert_eq!(*e.problem, Problem::Invalid("must be from 2 to 8 cycles"));
            }
        }
    }
    let src = with("role = \"dio\"", "role = \"dio\"\ntransport_cycles = 3");
    let (_, key, _) = refused(&src);
    assert_eq!(key, "ethercat[0].subdevices[1].transport_cycles");
}

#[test]
fn a_dio_inputs_device_is_refused_on_a_drive_taken_or_not_plain() {
    let src = with(
        "role = \"cia402\"",
        "role = \"cia402\"\ninputs = \"servo_in\"",
    );
    let (line, key, p) = refused(&src);
    assert_eq!(key, "ethercat[0].subdevices[0].inputs");
    assert_eq!(line, Some(line_of(&src, "inputs = \"servo_in\"")));
    assert_eq!(
        p,
        Problem::Invalid("only for `role = \"dio\"` or `role = \"aio\"`")
    );
    for (name, want) in [
        ("slide_servo", Problem::NameTaken("slide_servo".into())),
        ("io", Problem::NameTaken("io".into())),
        (
            "in put",
            Problem::BadName {
                what: "device",
                name: "in put".into(),
            },
        ),
    ] {
        let src = with("inputs = \"io_in\"", &format!("inputs = \"{name}\""));
        let (_, key, p) = refused(&src);
        assert_eq!(key, "ethercat[0].subdevices[1].inputs", "{name}");
        assert_eq!(p, want);
    }
}

#[test]
fn an_identity_without_revision_or_an_unknown_key_is_refused_by_the_schema() {
    let src = with(", revision = 0x00100000 }", " }");
    let e = parse("c.toml", &src).expect_err("refused");
    assert!(e.to_string().contains("revision"), "{e}");
    let src = with("role = \"dio\"", "role = \"dio\"\nchannels = 8");
    let e = parse("c.toml", &src).expect_err("refused");
    assert!(e.to_string().contains("channels"), "{e}");
}

#[test]
fn torque_precontrol_is_refused_on_an_ethercat_drive() {
    let src = with(
        "enable_timeout = 0.5",
        "enable_timeout = 0.5\ntorque_precontrol = true",
    );
    let (line, key, p) = refused(&src);
    assert_eq!(key, "axes.slide.drive.torque_precontrol");
    assert_eq!(line, Some(line_of(&src, "torque_precontrol = true")));
    assert!(
        matches!(p, Problem::Invalid(m) if m.contains("0x60B2")),
        "{p:?}"
    );
}

#[test]
fn an_axis_cannot_take_the_digital_terminal_as_its_drive() {
    let src = with(
        "device = \"slide_servo\"            # the SubDevice",
        "device = \"io\" #",
    );
    let (_, key, p) = refused(&src);
    assert_eq!(key, "axes.slide.drive.device");
    assert!(
        matches!(&p, Problem::DeviceKind { device, kind: "ethercat_dio", .. } if device == "io"),
        "{p:?}"
    );
}

/// The example with an analog terminal after the digital one, its output 1 and input 1 bound
/// to `float` signals, and `extra` appended to its SubDevice table.
fn with_aio(extra: &str) -> String {
    with(
        "# An output signal on the terminal's channel 1",
        &format!(
            "[[ethercat.subdevices]]\nname = \"ai_ao\"\n\
             identity = {{ vendor = 0x00000002, product = 0x11163052, revision = 0x00100000 }}\n\
             role = \"aio\"\ninputs = \"ai_ao_in\"\n{extra}\n\
             [signals.valve_cmd]\ndevice = \"ai_ao\"\nchannel = 1\ntype = \"float\"\n\n\
             [signals.valve_back]\ndevice = \"ai_ao_in\"\nchannel = 1\n\n\
             # An output signal on the terminal's channel 1"
        ),
    )
}

#[test]
fn an_aio_terminal_gives_two_float_outputs_and_an_inputs_device_of_two_float_inputs() {
    let cell = parse("c.toml", &with_aio("")).unwrap();
    let seg = &cell.ethercat[0];
    assert_eq!(seg.subdevices[2].role, EthercatRole::Aio);
    assert_eq!(
        seg.subdevices[2].identity,
        EthercatIdentity {
            vendor: 2,
            product: 0x1116_3052,
            revision: 0x0010_0000
        }
    );
    let out = seg.subdevices[2].device.0;
    assert_eq!(cell.devices[out].kind, DeviceKind::EthercatAio);
    let inputs = seg.subdevices[2].inputs.unwrap().0;
    assert_eq!(cell.devices[inputs].kind, DeviceKind::EthercatAioInputs);
    assert_eq!(cell.devices[inputs].name, "ai_ao_in");
    let cmd = cell.signal("valve_cmd").unwrap();
    let back = cell.signal("valve_back").unwrap();
    assert_eq!(
        cell.signals[cmd.0].signal_type,
        tandem_config::SignalType::Float
    );
    assert_eq!(
        cell.signals[back.0].signal_type,
        tandem_config::SignalType::Float
    );
    assert_eq!(
        cell.signals[cmd.0].direction,
        tandem_config::SignalDirection::Output
    );
    assert_eq!(
        cell.signals[back.0].direction,
        tandem_config::SignalDirection::Input
    );
}

#[test]
fn an_aio_terminal_refuses_drive_keys_a_third_channel_and_a_bool_signal() {
    let (_, key, p) = refused(&with_aio("transport_cycles = 4"));
    assert_eq!(key, "ethercat[0].subdevices[2].transport_cycles");
    assert_eq!(p, Problem::Invalid("only for `role = \"cia402\"`"));
    let (_, key, _) = refused(&with_aio("increments_per_revolution = 4096"));
    assert_eq!(key, "ethercat[0].subdevices[2].increments_per_revolution");
    let src = with_aio("").replacen(
        "device = \"ai_ao_in\"\nchannel = 1",
        "device = \"ai_ao_in\"\nchannel = 3",
        1,
    );
    let (line, key, _) = refused(&src);
    assert_eq!(key, "signals.valve_back.channel");
    assert_eq!(line, Some(line_of(&src, "channel = 3")));
    let src = with_aio("").replacen("type = \"float\"", "type = \"bool\"", 1);
    let (_, key, p) = refused(&src);
    assert_eq!(key, "signals.valve_cmd.type");
    assert!(
        format!("{p}").contains("`ethercat_aio` with `float` channels"),
        "{p}"
    );
}

#[test]
fn an_enc_terminal_is_one_integer_input_and_takes_no_inputs_device() {
    let enc = "[[ethercat.subdevices]]\nname = \"wheel\"\n\
               identity = { vendor = 0x00000002, product = 0x13ED3052, revision = 0x00100000 }\n\
               role = \"enc\"\n\n[signals.wheel_count]\ndevice = \"wheel\"\nchannel = 1\n\n\
               # An output signal on the terminal's channel 1";
    let src = with("# An output signal on the terminal's channel 1", enc);
    let cell = parse("c.toml", &src).unwrap();
    let seg = &cell.ethercat[0];
    assert_eq!(seg.subdevices[2].role, EthercatRole::Enc);
    assert_eq!(
        cell.devices[seg.subdevices[2].device.0].kind,
        DeviceKind::EthercatEnc
    );
    let k = cell.signal("wheel_count").unwrap();
    assert_eq!(
        cell.signals[k.0].signal_type,
        tandem_config::SignalType::Integer
    );
    assert_eq!(
        cell.signals[k.0].direction,
        tandem_config::SignalDirection::Input
    );
    let bad = src.replacen(
        "\nrole = \"enc\"",
        "\nrole = \"enc\"\ninputs = \"wheel_in\"",
        1,
    );
    let (_, key, p) = refused(&bad);
    assert_eq!(key, "ethercat[0].subdevices[2].inputs");
    assert_eq!(
        p,
        Problem::Invalid("only for `role = \"dio\"` or `role = \"aio\"`")
    );
    let bad = src.replacen(
        "device = \"wheel\"\nchannel = 1",
        "device = \"wheel\"\nchannel = 2",
        1,
    );
    let (_, key, _) = refused(&bad);
    assert_eq!(key, "signals.wheel_count.channel");
    let bad = src.replacen(
        "\nrole = \"enc\"",
        "\nrole = \"enc\"\ntransport_cycles = 4",
        1,
    );
    let (_, key, _) = refused(&bad);
    assert_eq!(key, "ethercat[0].subdevices[2].transport_cycles");
}
