//! Input signals (`sim_digital_input`, `[signals.<name>.sensor]`), the `input` of measuring
//! inputs and `[axes.<name>.inputs]`: the bindings of the bundled example, and every binding
//! `tandem check` refuses, named by file, line and key.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::{parse, Problem, SignalDirection, SignalIndex, SignalType};

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

/// The error of a cell that must be refused: `(line, key, message)`; the message names the
/// file, the line and the key.
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
fn the_example_binds_its_inputs() {
    let c = parse("inputs.toml", &example()).unwrap();
    let s = |n: &str| &c.signals[c.signal(n).unwrap().0];
    assert_eq!(s("print_mark").signal_type, SignalType::TimestampedBool);
    assert_eq!(s("end_of_travel").signal_type, SignalType::Bool);
    assert_eq!(s("probe").direction, SignalDirection::Input);
    assert_eq!(s("print_mark").sensor.unwrap().position, 150.0);
    let mi = |n: &str| c.inputs.measuring_inputs[c.measuring_input(n).unwrap()];
    assert_eq!(mi("mark_reader"), c.signal("print_mark"));
    assert_eq!(mi("probe_reader"), c.signal("probe"));
    assert_eq!(c.inputs.axes[0].limit_positive, c.signal("end_of_travel"));
    assert_eq!(c.inputs.axes[0].reference_cam, None::<SignalIndex>);
    // A bound limit switch turns the hardware limit monitoring on.
    assert!(c.axes[0].config.hw_limits_active);
}

#[test]
fn a_measuring_input_on_a_plain_input_is_refused() {
    let src = with(
        "name = \"probe_reader\"\naxis = \"web\"\ninput = \"probe\"",
        "name = \"probe_reader\"\naxis = \"web\"\ninput = \"end_of_travel\"",
    );
    let src = src.replace("limit_positive = \"end_of_travel\"", "");
    let (line, key, p, text) = refused(&src);
    assert_eq!(key, "measuring_inputs[1].input");
    assert_eq!(line, line_of(&src, "input = \"end_of_travel\""));
    assert!(matches!(p, Problem::SignalType { .. }), "{text}");
    assert!(
        text.contains("signal `end_of_travel` is a plain `bool`"),
        "{text}"
    );
}

#[test]
fn unknown_and_output_signals_are_refused_as_inputs() {
    let src = with("input = \"probe\"", "input = \"nope\"");
    let (line, key, p, _) = refused(&src);
    assert_eq!(
        (line, key.as_str()),
        (line_of(&src, "\"nope\""), "measuring_inputs[1].input")
    );
    assert!(matches!(p, Problem::Unknown { what: "signal", .. }));
    // An output signal as an input, and an input as an output.
    let out = r#"
[devices.dq]
node = "line"
kind = "sim_digital_output"
channels = 1

[signals.lamp]
device = "dq"
channel = 1
"#;
    let src = with(
        "limit_positive = \"end_of_travel\"",
        "limit_positive = \"lamp\"",
    ) + out;
    let (line, key, p, text) = refused(&src);
    assert_eq!(key, "axes.web.inputs.limit_positive");
    assert_eq!(line, line_of(&src, "limit_positive = \"lamp\""));
    assert!(
        matches!(
            p,
            Problem::SignalDirection {
                is: "an output",
                ..
            }
        ),
        "{text}"
    );
    let src =
        example() + out + "\n[[output_cams]]\nname = \"oc\"\naxis = \"web\"\noutput = \"probe\"\n";
    let (line, key, p, text) = refused(&src);
    assert_eq!(key, "output_cams[0].output");
    assert_eq!(line, line_of(&src, "output = \"probe\""));
    assert!(
        matches!(p, Problem::SignalDirection { is: "an input", .. }),
        "{text}"
    );
}

#[test]
fn an_input_bound_twice_is_refused() {
    let src = with("input = \"probe\"", "input = \"print_mark\"");
    let (line, key, p, text) = refused(&src);
    assert_eq!(key, "measuring_inputs[1].input");
    let lines: Vec<&str> = src.lines().collect();
    let last = lines
        .iter()
        .rposition(|l| l.contains("input = \"print_mark\""))
        .unwrap()
        + 1;
    assert_eq!(line, last);
    assert!(
        text.ends_with("input signal `print_mark` is already bound to `measuring_inputs[0].input`"),
        "{text} {p:?}"
    );
    let src = with(
        "# limit_negative = \"<signal>\"",
        "limit_negative = \"end_of_travel\"",
    );
    let (line, key, _, text) = refused(&src);
    assert_eq!(key, "axes.web.inputs.limit_negative");
    assert_eq!(line, line_of(&src, "limit_negative = \"end_of_travel\""));
    assert!(
        text.contains("already bound to `axes.web.inputs.limit_positive`"),
        "{text}"
    );
}

#[test]
fn conflicting_keys_are_refused() {
    // The switch both as a signal and as a simulated position.
    let src = with(
        "[axes.web.inputs]",
        "[axes.web.hw_limits]\nmax = 950.0\n\n[axes.web.inputs]",
    );
    let (line, key, p, _) = refused(&src);
    assert_eq!(
        (line, key.as_str()),
        (line_of(&src, "max = 950.0"), "axes.web.hw_limits.max")
    );
    assert!(matches!(p, Problem::Conflict { .. }));
    // A measuring input with its own sensor and an input signal.
    let src = with(
        "input = \"probe\"",
        "input = \"probe\"\n\n[measuring_inputs.sensor]\nposition = 1.0\nwidth = 1.0",
    );
    let (_, key, p, _) = refused(&src);
    assert_eq!(key, "measuring_inputs[1].sensor");
    assert!(matches!(p, Problem::Conflict { .. }));
    // An input signal on a route other than timer_di.
    let src = with(
        "input = \"probe\"",
        "input = \"probe\"\nroute = \"central_probe\"",
    );
    let (_, key, _, text) = refused(&src);
    assert_eq!(key, "measuring_inputs[1].input");
    assert!(text.contains("route `timer_di`"), "{text}");
}

#[test]
fn sensors_on_outputs_or_without_an_axis_are_refused() {
    let src = with(
        "[signals.print_mark.sensor]\naxis = \"web\"                  # the axis that carries the mark\n",
        "[signals.print_mark.sensor]\n",
    );
    let (line, key, p, _) = refused(&src);
    assert_eq!(
        (line, key.as_str()),
        (
            line_of(&src, "[signals.print_mark.sensor]"),
            "signals.print_mark.sensor"
        )
    );
    assert!(matches!(p, Problem::Missing(_)));
    let src = with(
        "axis = \"web\"                  # the axis that carries",
        "axis = \"nope\" #",
    );
    let (line, key, _, _) = refused(&src);
    assert_eq!(
        (line, key.as_str()),
        (
            line_of(&src, "axis = \"nope\""),
            "signals.print_mark.sensor.axis"
        )
    );
    let src = with("width = 5.0 ", "width = -5.0 ");
    let (_, key, _, _) = refused(&src);
    assert_eq!(key, "signals.print_mark.sensor.width");
    let src = with(
        "kind = \"sim_digital_input\"    #",
        "kind = \"sim_digital_output\"    #",
    );
    let (_, key, p, _) = refused(&src);
    assert_eq!(key, "signals.print_mark.sensor");
    assert!(matches!(
        p,
        Problem::SignalDirection {
            is: "an output",
            ..
        }
    ));
}
