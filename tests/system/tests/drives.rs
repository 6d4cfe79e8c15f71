//! An axis on a simulated CiA 402 servo drive in the process set (issue 11): `tandem up` runs
//! `config/servo.toml`'s node on the real clock with its process image; the drive's enable
//! sequence, the move, the injected drive fault (alarm 421 with the drive's error code), the
//! reset and the move after it come out exactly as `tandem sim` computes them on virtual time:
//! the same log and every setpoint and actual value equal.
//!
//! Every wait has a timeout.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::HashMap;
use std::path::Path;
use std::time::Duration;
use tandem_testkit::process::{run, text, Spawned};
use tandem_testkit::scratch::{fresh_dir, remove_dir};
use tandem_testkit::tandem::tandem;
use tandem_testkit::workspace::root;

/// The columns of a CSV trace by name, rows by time (ns).
fn trace(p: &Path) -> (Vec<String>, HashMap<i64, Vec<String>>) {
    let s = std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let mut lines = s.lines();
    let cols = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| {
            let r: Vec<String> = l.split(',').map(str::to_string).collect();
            let t: f64 = r[0].parse().unwrap();
            ((t * 1e9).round() as i64, r)
        })
        .collect();
    (cols, rows)
}

#[test]
fn an_axis_on_a_simulated_cia402_drive_runs_in_the_process_set_as_in_the_simulator() {
    let dir = fresh_dir(&format!("tandem-drives-{}", std::process::id()));
    let src = std::fs::read_to_string(root().join("config/servo.toml")).unwrap();
    let name = format!("servo{}", std::process::id());
    let cell = dir.join("servo.toml");
    std::fs::write(
        &cell,
        src.replace("name = \"servo\"", &format!("name = \"{name}\"")),
    )
    .unwrap();
    let script = root().join("config/servo-script.toml");
    let rec = dir.join("rec");
    let up = Spawned::start(
        tandem_testkit::tandem::up(tandem(), &cell, &rec)
            .arg("--script")
            .arg(&script),
    );
    let (status, up_log) = up.wait(Duration::from_secs(60), "tandem up");
    assert!(status.success(), "tandem up failed: {status}\n{up_log}");
    assert!(!up_log.contains("panicked"), "{up_log}");

    let sim_trace = dir.join("sim.csv");
    let mut c = tandem();
    c.arg("sim")
        .arg(&cell)
        .arg("--script")
        .arg(&script)
        .arg("--trace")
        .arg(&sim_trace);
    let sim = run(c, Duration::from_secs(60));
    assert!(sim.status.success(), "{}", text(&sim));

    // The same log: the enable, the moves, the fault with its code, the reset.
    let node_log = std::fs::read_to_string(rec.join("drives.log")).unwrap();
    let sim_log = String::from_utf8_lossy(&sim.stdout);
    let events = |s: &str| -> Vec<String> {
        s.lines()
            .filter(|l| l.starts_with("t="))
            .map(str::to_string)
            .collect()
    };
    assert_eq!(events(&node_log), events(&sim_log), "{node_log}");
    assert!(
        node_log.contains("alarm 421 DriveFault (supplement 8976"),
        "the drive's 0x2310: {node_log}"
    );
    assert!(
        node_log.contains("MC_MoveAbsolute job 6: Done"),
        "{node_log}"
    );

    // Every setpoint and actual value of every cycle equal.
    let (cols, node) = trace(&rec.join("drives.csv"));
    let (sim_cols, sim) = trace(&sim_trace);
    assert_eq!(node.len(), 3001, "one row per 1 ms cycle over 3 s");
    for col in [
        "slide.position",
        "slide.velocity",
        "slide.actual_position",
        "slide.actual_velocity",
        "slide.following_error",
        "slide.state",
    ] {
        let i = cols.iter().position(|c| c == col).unwrap();
        let j = sim_cols.iter().position(|c| c == col).unwrap();
        for (t, row) in &node {
            let (a, b) = (&row[i], &sim[t][j]);
            match (a.parse::<f64>(), b.parse::<f64>()) {
                (Ok(x), Ok(y)) => {
                    assert!((x - y).abs() < 1e-9, "{col} at {t} ns: node {x}, sim {y}")
                }
                _ => assert_eq!(a, b, "{col} at {t} ns"),
            }
        }
    }
    remove_dir(&dir);
}
