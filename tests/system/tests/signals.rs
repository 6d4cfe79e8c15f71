//! The process image observable over Zenoh (issue 11): `tandem up config/glue-dot.toml`, with
//! an input added (a timestamped sensor on the conveyor), runs its node and gateway; the Python
//! observer (tests/python/observe.py, eclipse-zenoh) subscribed to the cell sees every edge of
//! the glue valve's timestamped output at exactly the output cam track's logged edge time plus
//! the node's look-ahead (2 cycles + the 2 ms on-compensation = 4 ms, docs/io.md "Outputs"),
//! and every edge of the input at exactly the time the node logged.
//!
//! Every wait has a timeout.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::process::{Child, Stdio};
use std::time::Duration;
use tandem_testkit::process::{wait_for, Spawned};
use tandem_testkit::scratch::{fresh_dir, remove_dir};
use tandem_testkit::tandem::tandem;
use tandem_testkit::workspace::root;

/// The look-ahead of the glue-dot node (ns).
const LOOK_AHEAD: i64 = 4_000_000;

/// Edges of the node's log: `t=<s> <name> <what> ON|OFF...` as (ns, on), for lines naming
/// `name` and `what`.
fn logged(log: &str, name: &str, what: &str) -> Vec<(i64, bool)> {
    log.lines()
        .filter_map(|l| {
            let rest = l.strip_prefix("t=")?;
            let (t, rest) = rest.split_once(' ')?;
            let rest = rest
                .strip_prefix(name)?
                .strip_prefix(' ')?
                .strip_prefix(what)?;
            let on = rest.trim_start().starts_with("ON");
            let (s, frac) = t.split_once('.')?;
            let ns = s.parse::<i64>().ok()? * 1_000_000_000 + frac.parse::<i64>().ok()?;
            Some((ns, on))
        })
        .collect()
}

fn observe(cell: &str, endpoint: &str, seconds: f64) -> Child {
    std::process::Command::new("python3")
        .arg(root().join("tests/python/observe.py"))
        .args(["--cell", cell, "--seconds", &seconds.to_string()])
        .args(["--connect", endpoint])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

#[test]
fn a_zenoh_subscriber_sees_the_glue_valve_and_an_input_as_the_node_logged_them() {
    let pid = std::process::id();
    let dir = fresh_dir(&format!("tandem-signals-{pid}"));
    let name = format!("glue{pid}");
    let port = 20_000 + pid % 20_000;
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let src = std::fs::read_to_string(root().join("config/glue-dot.toml")).unwrap();
    let src = src.replace("name = \"glue-dot\"", &format!("name = \"{name}\""))
        + &format!(
            r#"
[[hosts]]
name = "local"
listen = ["{endpoint}"]

[devices.eye_io]
node = "packer"
kind = "sim_digital_input"
channels = 1
timestamped = true

[signals.blank_eye]
device = "eye_io"
channel = 1

[signals.blank_eye.sensor]
axis = "conveyor"
position = 100.0
width = 20.0
"#
        );
    let cell = dir.join("glue.toml");
    std::fs::write(&cell, src).unwrap();
    let script = root().join("config/glue-dot-script.toml");
    let rec = dir.join("rec");

    // The observer first (it keeps trying to reach the gateway), then the cell: the cycles
    // start on the next whole second plus one.
    let mut watcher = observe(&name, &endpoint, 9.0);
    let up = Spawned::start(
        tandem_testkit::tandem::up(tandem(), &cell, &rec)
            .arg("--script")
            .arg(&script),
    );
    let (status, up_log) = up.wait(Duration::from_secs(60), "tandem up");
    assert!(status.success(), "tandem up failed: {status}\n{up_log}");
    assert!(!up_log.contains("panicked"), "{up_log}");
    let st = wait_for(&mut watcher, Duration::from_secs(60), "observe.py");
    let o = watcher.wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        st.success(),
        "observe.py: {st}\n{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let summary: serde_json::Value =
        serde_json::from_str(text.trim()).unwrap_or_else(|e| panic!("{e}: {text}"));
    let seen = summary["signals"].as_array().unwrap();
    let of = |signal: &str| -> Vec<&serde_json::Value> {
        seen.iter().filter(|s| s["signal"] == signal).collect()
    };

    let log = std::fs::read_to_string(rec.join("packer.log")).unwrap();
    // The glue valve: each edge switched at exactly its logged time (the cam track computes its
    // switching times ahead, docs/io.md 'Outputs').
    let glue = logged(&log, "glue", "output");
    let valve = of("glue_valve");
    assert!(glue.len() >= 20, "{log}");
    for v in &valve {
        assert_eq!(v["direction"], "output");
        assert_eq!(v["timestamped"], true);
        assert_eq!(v["late"], false, "{v}");
        let (t, edge) = (
            v["time_ns"].as_i64().unwrap(),
            v["edge_ns"].as_i64().unwrap(),
        );
        assert_eq!(t, edge, "{v}");
        let on = v["level"].as_bool().unwrap();
        assert!(glue.contains(&(edge, on)), "{v} not in the log");
    }
    // None missing once the observer is surely connected (from 1 s of engine time on; the
    // cycles start at least a second after `tandem up`), up to the last switched before the
    // end.
    let end = 3_000_000_000 - LOOK_AHEAD;
    for (edge, on) in glue
        .iter()
        .filter(|(t, _)| (1_000_000_000..end).contains(t))
    {
        assert!(
            valve
                .iter()
                .any(|v| v["edge_ns"].as_i64() == Some(*edge) && v["level"] == *on),
            "edge at {edge} ns not seen over Zenoh ({} seen)",
            valve.len()
        );
    }
    // The input: each edge at exactly the time the node logged, sampled at the boundary
    // at or after it.
    let eye = logged(&log, "blank_eye", "input");
    assert!(eye.len() >= 6, "{log}");
    let inputs = of("blank_eye");
    for x in &inputs {
        assert_eq!(
            (x["direction"].as_str(), x["timestamped"].as_bool()),
            (Some("input"), Some(true))
        );
        let t = x["time_ns"].as_i64().unwrap();
        let on = x["level"].as_bool().unwrap();
        assert!(eye.contains(&(t, on)), "{x} not in the log");
        let sampled = x["sampled_ns"].as_i64().unwrap();
        assert_eq!(sampled, (t + 999_999) / 1_000_000 * 1_000_000, "{x}");
    }
    for (t, _) in eye.iter().filter(|(t, _)| *t >= 1_000_000_000) {
        assert!(
            inputs.iter().any(|x| x["time_ns"].as_i64() == Some(*t)),
            "input edge at {t} ns not seen over Zenoh"
        );
    }
    remove_dir(&dir);
}
