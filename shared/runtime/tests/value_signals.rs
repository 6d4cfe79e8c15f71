//! `integer` and `float` input signals of the process image (`config/inputs.toml`: a ±10 V
//! 16-bit `sim_analog_input`, a 32-bit `sim_counter`), end to end in the executive: a value
//! set between two boundaries is read at the next boundary and not before, quantized exactly
//! as docs/io.md says (code = round(v · 32767 / 10) clamped to ±32767, value = code · 10 /
//! 32767), clipped at full scale, and a counter register wraps modulo 2^bits.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use tandem_config::{Cell, SignalIndex};
use tandem_motion::objects::action::Action;
use tandem_runtime::exec::{Executive, InputSignalValue, SignalValue};
use tandem_testkit::workspace::root;

const MS: i64 = 1_000_000;

fn cell(edit: impl Fn(String) -> String) -> Cell {
    let src = std::fs::read_to_string(root().join("config/inputs.toml")).unwrap();
    tandem_config::parse("inputs.toml", &edit(src)).unwrap()
}

/// The executive stepped cycle by cycle (1 ms), with the value changes it reported.
struct Run<'c> {
    exec: Executive<'c>,
    k: i64,
    log: Vec<u8>,
    values: Vec<InputSignalValue>,
}

impl<'c> Run<'c> {
    fn new(cell: &'c Cell) -> Self {
        Self {
            exec: Executive::new(cell, None).unwrap(),
            k: 0,
            log: Vec::new(),
            values: Vec::new(),
        }
    }

    /// Sets `signal` to `value` at `at` (between the last step and the next).
    fn set_at(&mut self, at: i64, signal: &str, value: f64) {
        let t = self.k * MS;
        let action = Action::SetInputValue { value };
        let r = (self.exec)
            .apply_at(t, at, signal, "SetInput", action, &mut self.log)
            .unwrap();
        assert!(r.is_ok(), "{signal}: {r:?}");
    }

    fn step(&mut self) {
        self.exec.step(self.k * MS, &mut self.log).unwrap();
        let values = &mut self.values;
        self.exec.drain_input_values(|e| values.push(*e));
        self.exec.drain_input_edges(|_| {});
        self.exec.drain_io_notes(|_| {});
        self.exec.drain_job_notes(|_| {});
        self.k += 1;
    }

    fn value(&self, s: SignalIndex) -> SignalValue {
        self.exec.signal_value(s).unwrap()
    }
}

/// The documented reading of `v` on a ±10 V 16-bit channel: (code, V).
fn documented(v: f64) -> (i64, f64) {
    let code = (v * 32767.0 / 10.0).round().clamp(-32767.0, 32767.0);
    (code as i64, code * 10.0 / 32767.0)
}

#[test]
fn a_float_input_is_read_at_the_next_boundary_quantized() {
    let c = cell(|s| s);
    let tension = c.signal("web_tension").unwrap();
    let mut r = Run::new(&c);
    for _ in 0..10 {
        r.step();
    }
    // Set at 9.4 ms, between the boundaries 9 ms (stepped) and 10 ms.
    r.set_at(9 * MS + 400_000, "web_tension", 1.0);
    assert_eq!(r.value(tension), SignalValue::Float(0.0));
    assert!(r.values.is_empty());
    r.step(); // the boundary 10 ms samples it
              // 1 V: code round(3276.7) = 3277, 3277 · 10 / 32767 V: not 1.0, the terminal's value.
    let want = 3277.0 * 10.0 / 32767.0;
    assert_eq!(r.value(tension), SignalValue::Float(want));
    assert_ne!(want, 1.0);
    assert_eq!(
        r.values,
        vec![InputSignalValue {
            signal: tension.0,
            device: c
                .devices
                .iter()
                .position(|d| d.name == "tension_ai")
                .unwrap(),
            channel: 1,
            value: SignalValue::Float(want),
            raw: 3277,
            sampled_ns: 10 * MS,
        }]
    );
    let log = String::from_utf8_lossy(&r.log).into_owned();
    assert!(
        log.contains(&format!("t=0.010000000 web_tension input = {want} [3277]")),
        "{log}"
    );
    // Unchanged reading: no new change.
    r.set_at(10 * MS + 1, "web_tension", 1.00001);
    r.step();
    assert_eq!(r.values.len(), 1);
}

#[test]
fn only_the_last_value_before_a_boundary_is_read_and_beyond_range_is_full_scale() {
    let c = cell(|s| s);
    let tension = c.signal("web_tension").unwrap();
    let dev = c
        .devices
        .iter()
        .position(|d| d.name == "tension_ai")
        .unwrap();
    let mut r = Run::new(&c);
    r.step();
    r.set_at(MS - 200, "web_tension", 5.0);
    r.set_at(MS - 100, "web_tension", -12.5);
    r.step();
    assert_eq!(r.value(tension), SignalValue::Float(-10.0));
    let status = r.exec.value_device(dev).unwrap();
    assert_eq!((status.unseen, status.clipped, status.changes), (1, 1, 1));
    assert_eq!(r.values.last().unwrap().raw, -32767);
}

#[test]
fn every_reading_is_the_documented_quantization() {
    // A fixed seed: reproducible.
    let config = Config {
        cases: 200,
        failure_persistence: None,
        ..Config::default()
    };
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[11; 32]);
    let mut runner = TestRunner::new_with_rng(config, rng);
    let c = cell(|s| s);
    let tension = c.signal("web_tension").unwrap();
    runner
        .run(&(-11.0f64..11.0, 1i64..MS), |(v, off)| {
            let mut r = Run::new(&c);
            r.step();
            r.set_at(off, "web_tension", v);
            r.step();
            let (code, want) = documented(v);
            prop_assert_eq!(r.value(tension), SignalValue::Float(want));
            if code != 0 {
                prop_assert_eq!(r.values.last().map(|e| e.raw), Some(code));
            }
            // Within half a step of the value inside the range.
            if v.abs() <= 10.0 {
                prop_assert!((want - v).abs() <= 0.5 * 10.0 / 32767.0 + 1e-15);
            }
            Ok(())
        })
        .unwrap();
}

#[test]
fn a_counter_register_wraps_at_its_width() {
    for (bits, set, want) in [
        (32, 2_147_483_648.0, -2_147_483_648i64),
        (32, -7.0, -7),
        (16, 40_000.0, 40_000 - 65_536),
        (16, 65_537.0, 1),
    ] {
        let c = cell(|s| {
            s.replace(
                "bits = 32                     # the register's width: 16 or 32 (default 32)",
                &format!("bits = {bits}"),
            )
        });
        let pieces = c.signal("pieces").unwrap();
        let mut r = Run::new(&c);
        r.step();
        r.set_at(MS - 1, "pieces", set);
        assert_eq!(r.value(pieces), SignalValue::Integer(0));
        r.step();
        assert_eq!(r.value(pieces), SignalValue::Integer(want), "{bits} {set}");
        assert_eq!(r.values.last().unwrap().sampled_ns, MS);
    }
}

#[test]
fn a_value_for_a_bool_input_or_an_unknown_signal_is_refused() {
    let c = cell(|s| s);
    let mut r = Run::new(&c);
    let mut log = Vec::new();
    for target in ["probe", "nope"] {
        let a = Action::SetInputValue { value: 1.0 };
        let got = r.exec.apply(0, target, "SetInput", a, &mut log).unwrap();
        assert!(got.is_err(), "{target}: {got:?}");
    }
    r.step();
    assert!(r.values.is_empty());
}

/// `config/inputs.toml` with a ±10 V 16-bit `sim_analog_output` `valve_ao` and its channel 1
/// as the float output `valve_cmd`.
fn with_analog_output(s: String) -> String {
    s.replacen(
        "[devices.piece_counter]",
        "[devices.valve_ao]\nnode = \"line\"\nkind = \"sim_analog_output\"\nchannels = 2\n\n\
         [signals.valve_cmd]\ndevice = \"valve_ao\"\nchannel = 1\n\n[devices.piece_counter]",
        1,
    )
}

#[test]
fn set_output_drives_a_float_output_quantized_at_once_and_logs_it() {
    let c = cell(with_analog_output);
    let cmd = c.signal("valve_cmd").unwrap();
    let ao = c.devices.iter().position(|d| d.name == "valve_ao").unwrap();
    let mut r = Run::new(&c);
    for _ in 0..3 {
        r.step();
    }
    assert_eq!(
        r.value(cmd),
        SignalValue::Float(0.0),
        "0 V before any SetOutput"
    );
    let t = r.k * MS;
    let action = Action::SetOutputValue { value: 2.5 };
    let applied = (r.exec)
        .apply_at(t, t, "valve_cmd", "SetOutput", action, &mut r.log)
        .unwrap();
    assert!(applied.is_ok(), "{applied:?}");
    // At once, before the step: the writer of an EtherCAT `aio` takes it at the next boundary.
    assert_eq!(r.value(cmd), SignalValue::Float(8192.0 * 10.0 / 32767.0));
    assert_eq!(r.exec.value_device(ao).unwrap().changes, 1);
    r.step();
    let log = String::from_utf8_lossy(&r.log);
    assert!(
        log.contains("t=0.003000000 valve_cmd output = 2.50007629627369 [8192]"),
        "{log}"
    );
    assert_eq!(r.values.len(), 1);
    assert_eq!((r.values[0].raw, r.values[0].sampled_ns), (8192, 3 * MS));
    // An input is not an output, and an output not an input.
    for (signal, action) in [
        ("web_tension", Action::SetOutputValue { value: 1.0 }),
        ("valve_cmd", Action::SetInputValue { value: 1.0 }),
    ] {
        let t = r.k * MS;
        let refused = (r.exec)
            .apply_at(t, t, signal, "SetOutput", action, &mut r.log)
            .unwrap();
        assert!(refused.is_err(), "{signal}");
    }
}

#[test]
fn an_analog_channel_set_from_outside_is_sampled_at_its_boundary_as_a_script_value() {
    let c = cell(|s| s);
    let tension = c.signal("web_tension").unwrap();
    let ai = c
        .devices
        .iter()
        .position(|d| d.name == "tension_ai")
        .unwrap();
    let mut r = Run::new(&c);
    r.step();
    // The node's EtherCAT segment hands the word 8192 in as volts before the step at 1 ms.
    assert!(r.exec.set_input_value(ai, 1, MS, 8192.0 * 10.0 / 32767.0));
    assert!(
        !r.exec.set_input_value(ai + 1000, 1, MS, 1.0),
        "no such terminal"
    );
    r.step();
    assert_eq!(
        r.value(tension),
        SignalValue::Float(8192.0 * 10.0 / 32767.0)
    );
    assert_eq!(r.values.last().map(|e| e.raw), Some(8192));
    let log = String::from_utf8_lossy(&r.log);
    assert!(
        log.contains("t=0.001000000 web_tension input = 2.50007629627369 [8192]"),
        "{log}"
    );
}
