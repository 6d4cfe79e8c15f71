//! `integer` and `float` signals (`sim_analog_input`, `sim_analog_output`, `sim_counter`,
//! `[signals.<name>] type`): the bundled example's bindings, and every binding and key
//! `tandem check` refuses, named by file, line and key; `SetInput` with a number in a script.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::script::parse_cell;
use tandem_config::{parse, DeviceKind, Problem, SignalDirection, SignalType};

fn example() -> String {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    std::fs::read_to_string(root.join("config/inputs.toml")).unwrap()
}

/// The example with `from` replaced by `to` (which must occur).
fn with(from: &str, to: &str) -> String {
    let src = example();
    assert!(src.contains(from), "{from}");
    src.replacen(from, to, 1)
}

/// The error of a cell that must be refused: `(line, key, problem, message)`; the message
/// names the file, the line and the key.
fn refused(src: &str) -> (usize, String, Problem, String) {
    let e = parse("cell.toml", src).expect_err("must be refused");
    let text = e.to_string();
    let line = e.line.expect("a line");
    assert!(
        text.starts_with(&format!("cell.toml:{line}: {}: ", e.key)),
        "{text}"
    );
    (line, e.key.clone(), *e.problem, text)
}

/// The 1-based line of the first line of `src` containing `text`.
fn line_of(src: &str, text: &str) -> usize {
    src.lines().position(|l| l.contains(text)).unwrap() + 1
}

#[test]
fn the_example_binds_a_float_and_an_integer_input() {
    let c = parse("inputs.toml", &example()).unwrap();
    let s = |n: &str| &c.signals[c.signal(n).unwrap().0];
    assert_eq!(s("web_tension").signal_type, SignalType::Float);
    assert_eq!(s("web_tension").direction, SignalDirection::Input);
    assert_eq!(s("pieces").signal_type, SignalType::Integer);
    let dev = |n: &str| &c.devices.iter().find(|d| d.name == n).unwrap().kind;
    let DeviceKind::SimAnalogInput(p) = dev("tension_ai") else {
        panic!("an analog input");
    };
    assert_eq!((p.channels, p.range, p.bits), (2, 10.0, 16));
    assert_eq!(p.full_scale_code(), 32767);
    // Known answers of the documented quantization (±10 V, 16 bits).
    assert_eq!(p.quantize(10.0), (32767, 10.0));
    assert_eq!(p.quantize(2.5), (8192, 8192.0 * 10.0 / 32767.0));
    assert_eq!(p.quantize(-99.0), (-32767, -10.0));
    assert_eq!(p.quantize(0.5 * 10.0 / 32767.0 * 0.999), (0, 0.0));
    let DeviceKind::SimCounter(k) = dev("piece_counter") else {
        panic!("a counter");
    };
    assert_eq!((k.channels, k.bits), (1, 32));
    assert_eq!(k.wrap(1 << 31), -(1 << 31));
    assert_eq!(k.wrap((1 << 32) + 5), 5);
}

#[test]
fn a_float_type_on_a_bool_channel_is_refused() {
    let src = with(
        "[signals.probe]\ndevice = \"mark_io\"",
        "[signals.probe]\ntype = \"float\"\ndevice = \"mark_io\"",
    );
    let (line, key, p, text) = refused(&src);
    assert_eq!(key, "signals.probe.type");
    assert_eq!(line, line_of(&src, "type = \"float\""));
    assert!(matches!(p, Problem::ChannelType { .. }), "{text}");
    assert!(
        text.contains(
            "declared `float`, but device `mark_io` is a `sim_digital_input` with `bool` channels"
        ),
        "{text}"
    );
}

#[test]
fn a_bool_type_on_a_float_channel_and_integer_on_float_are_refused() {
    for (ty, needs) in [("bool", "sim_digital_input"), ("integer", "sim_counter")] {
        let src = with(
            "type = \"float\"                # optional",
            &format!("type = \"{ty}\"  # optional"),
        );
        let (line, key, p, text) = refused(&src);
        assert_eq!(key, "signals.web_tension.type");
        assert_eq!(line, line_of(&src, &format!("type = \"{ty}\"  #")));
        assert!(matches!(p, Problem::ChannelType { .. }), "{text}");
        assert!(
            text.contains("`sim_analog_input` with `float` channels"),
            "{text}"
        );
        assert!(text.contains(needs), "{text}");
    }
}

#[test]
fn an_unknown_type_is_refused() {
    let src = with("type = \"integer\"", "type = \"double\"");
    let (line, key, p, _) = refused(&src);
    assert_eq!(key, "signals.pieces.type");
    assert_eq!(line, line_of(&src, "type = \"double\""));
    assert!(matches!(
        p,
        Problem::Unknown {
            what: "signal type",
            ..
        }
    ));
}

#[test]
fn a_value_signal_where_a_bool_is_needed_is_refused() {
    // A measuring input fed by a float signal.
    let src = with("input = \"probe\"", "input = \"web_tension\"");
    let (line, key, p, text) = refused(&src);
    assert_eq!(key, "measuring_inputs[1].input");
    assert_eq!(line, line_of(&src, "input = \"web_tension\""));
    assert!(matches!(p, Problem::ChannelType { .. }), "{text}");
    assert!(text.contains("signal `web_tension` is `float`"), "{text}");
    // An axis's limit switch on a counter.
    let src = with(
        "limit_positive = \"end_of_travel\"",
        "limit_positive = \"pieces\"",
    );
    let (line, key, _, text) = refused(&src);
    assert_eq!(key, "axes.web.inputs.limit_positive");
    assert_eq!(line, line_of(&src, "limit_positive = \"pieces\""));
    assert!(text.contains("signal `pieces` is `integer`"), "{text}");
    // A simulated sensor on a float input.
    let src = with(
        "type = \"float\"                # optional: checked against the channel (float on a sim_analog_input)",
        "[signals.web_tension.sensor]\naxis = \"web\"\nposition = 1.0\nwidth = 1.0",
    );
    let (line, key, _, text) = refused(&src);
    assert_eq!(key, "signals.web_tension.sensor");
    assert_eq!(line, line_of(&src, "[signals.web_tension.sensor]"));
    assert!(
        text.contains("a `bool` input to carry a simulated sensor"),
        "{text}"
    );
}

#[test]
fn a_float_output_for_an_output_cam_is_refused() {
    let src = with(
        "[[measuring_inputs]]\nname = \"mark_reader\"",
        "[devices.aq]\nnode = \"line\"\nkind = \"sim_analog_output\"\nchannels = 1\n\n\
         [signals.valve_command]\ndevice = \"aq\"\nchannel = 1\n\n\
         [[output_cams]]\nname = \"cam\"\naxis = \"web\"\noutput = \"valve_command\"\n\n\
         [[measuring_inputs]]\nname = \"mark_reader\"",
    );
    let c = parse(
        "cell.toml",
        &src.replace("output = \"valve_command\"\n", ""),
    );
    let c = c.expect("the cell without the binding loads");
    let s = &c.signals[c.signal("valve_command").unwrap().0];
    assert_eq!(
        (s.signal_type, s.direction),
        (SignalType::Float, SignalDirection::Output)
    );
    let (line, key, _, text) = refused(&src);
    assert_eq!(key, "output_cams[0].output");
    assert_eq!(line, line_of(&src, "output = \"valve_command\""));
    assert!(
        text.contains("signal `valve_command` is `float`; this needs a `bool` signal"),
        "{text}"
    );
}

#[test]
fn the_keys_of_analog_and_counter_terminals_are_checked() {
    // Each `to` marks the refused line with `# here`.
    let cases = [
        (
            "bits = 16 ",
            "bits = 25 # here",
            "devices.tension_ai.bits",
            "2 to 24",
        ),
        (
            "range = 10.0 ",
            "range = 0.0 # here",
            "devices.tension_ai.range",
            "positive",
        ),
        (
            "bits = 32 ",
            "bits = 24 # here",
            "devices.piece_counter.bits",
            "16 or 32",
        ),
        (
            "kind = \"sim_counter\"",
            "kind = \"sim_counter\"\nrange = 5.0 # here",
            "devices.piece_counter.range",
            "not a key of a `sim_counter` device",
        ),
        (
            "kind = \"sim_analog_input\" ",
            "kind = \"sim_analog_input\"\ntimestamped = true # here\n",
            "devices.tension_ai.timestamped",
            "not a key of a `sim_analog_input` device",
        ),
        (
            "kind = \"sim_digital_input\"    # a simulated",
            "bits = 16 # here\nkind = \"sim_digital_input\"    # a simulated",
            "devices.mark_io.bits",
            "not a key of a `sim_digital_input` device",
        ),
    ];
    for (from, to, want_key, want_text) in cases {
        let src = with(from, to);
        let (line, key, _, text) = refused(&src);
        assert_eq!(key, want_key, "{text}");
        assert_eq!(line, line_of(&src, "# here"), "{text}");
        assert!(text.contains(want_text), "{text}");
    }
}

#[test]
fn set_input_takes_a_number_on_a_value_signal_only() {
    let c = parse("inputs.toml", &example()).unwrap();
    let script = |body: &str| {
        let src = format!(
            "[sim]\nduration = 1.0\n\n[[at]]\nt = 0.1\ninstruction = \"SetInput\"\n{body}\n"
        );
        parse_cell("s.toml", &src, &c)
    };
    let ok = script("axis = \"web_tension\"\nvalue = 2.5").unwrap();
    assert_eq!(
        ok.entries[0].action,
        tandem_motion::objects::action::Action::SetInputValue { value: 2.5 }
    );
    let ok = script("axis = \"pieces\"\nvalue = -3").unwrap();
    assert_eq!(
        ok.entries[0].action,
        tandem_motion::objects::action::Action::SetInputValue { value: -3.0 }
    );
    for (body, want) in [
        ("axis = \"pieces\"\nvalue = 1.5", "an integer"),
        ("axis = \"web_tension\"\nvalue = true", "a number"),
        ("axis = \"web_tension\"\nvalue = 1.0\npulse = 0.1", "pulse"),
        ("axis = \"probe\"\nvalue = 1.0", "true or false"),
    ] {
        let e = script(body).expect_err(body).to_string();
        assert!(e.contains(want), "{body}: {e}");
    }
}

#[test]
fn set_output_takes_a_number_on_a_float_output_only() {
    let src = with(
        "[[measuring_inputs]]\nname = \"mark_reader\"",
        "[devices.aq]\nnode = \"line\"\nkind = \"sim_analog_output\"\nchannels = 1\n\n\
         [signals.valve_command]\ndevice = \"aq\"\nchannel = 1\n\n\
         [[measuring_inputs]]\nname = \"mark_reader\"",
    );
    let c = parse("inputs.toml", &src).unwrap();
    let script = |body: &str| {
        let src = format!(
            "[sim]\nduration = 1.0\n\n[[at]]\nt = 0.1\ninstruction = \"SetOutput\"\n{body}\n"
        );
        parse_cell("s.toml", &src, &c)
    };
    let ok = script("axis = \"valve_command\"\nvalue = 2.5").unwrap();
    assert_eq!(
        ok.entries[0].action,
        tandem_motion::objects::action::Action::SetOutputValue { value: 2.5 }
    );
    for (body, want) in [
        ("axis = \"valve_command\"", "value"),
        ("axis = \"valve_command\"\nvalue = true", "a number"),
        (
            "axis = \"valve_command\"\nvalue = 1.0\npulse = 0.1",
            "pulse",
        ),
        ("axis = \"web_tension\"\nvalue = 1.0", "float output signal"),
        ("axis = \"probe\"\nvalue = 1.0", "float output signal"),
    ] {
        let e = script(body).expect_err(body).to_string();
        assert!(e.contains(want), "{body}: {e}");
    }
}
