//! The simulator's output for every bundled example, against committed golden files.
//!
//! For each `config/<example>.toml` with its `config/<example>-script.toml`, `tandem sim`'s
//! work (load, parse, [`tandem_runtime::sim::run`]) must produce:
//! - a log byte-identical to `tests/golden/<example>.log`;
//! - a trace whose SHA-256, length and row count are those of `tests/golden/<example>.trace.sha256`
//!   (the format of `sha256sum`, then `bytes rows`; the traces themselves are tens of MB).
//!
//! A refactoring must leave every file unchanged. When a change of behaviour is intended,
//! regenerate with `TANDEM_UPDATE_GOLDEN=1 cargo test --release -p tandem-runtime --test
//! golden_traces` and say why in the commit; `tandem sim config/<example>.toml --script
//! config/<example>-script.toml --trace t.csv && sha256sum t.csv` shows the same digest (the
//! `example` cell is `config/example-cell.toml`).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

const EXAMPLES: &[&str] = &[
    "example",
    "line",
    "cross-cutter",
    "flying-saw",
    "glue-dot",
    "print-mark-registration",
    "press",
    "servo",
    "fixed-stop",
    "analog",
    "inputs",
    "hydraulic",
    "hydraulic-press",
    "hydraulic-flying-gear",
    "hydraulic-gantry",
    "hydraulic-cam-switch",
];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The cell file of an example (`example` is `example-cell.toml`) and its script.
fn files(example: &str) -> (PathBuf, PathBuf) {
    let config = root().join("config");
    let cell = if example == "example" {
        config.join("example-cell.toml")
    } else {
        config.join(format!("{example}.toml"))
    };
    (cell, config.join(format!("{example}-script.toml")))
}

/// Runs the simulator on an example: (trace, log).
fn simulate(example: &str) -> (Vec<u8>, Vec<u8>) {
    let (cell_path, script_path) = files(example);
    let cell = match tandem_config::load(&cell_path) {
        Ok(c) => c,
        Err(e) => panic!("{example}: the bundled cell does not load: {e}"),
    };
    let src = match std::fs::read_to_string(&script_path) {
        Ok(s) => s,
        Err(e) => panic!("{}: {e}", script_path.display()),
    };
    // The name the CLI gives the script in its messages: the path as given, relative.
    let name = format!(
        "config/{}",
        script_path
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
    );
    let script = match tandem_config::script::parse_cell(&name, &src, &cell) {
        Ok(s) => s,
        Err(e) => panic!("{example}: the bundled script does not parse: {e}"),
    };
    let mut trace = Vec::new();
    let mut log = Vec::new();
    if let Err(e) = tandem_runtime::sim::run(&cell, &script, &mut trace, &mut log) {
        panic!("{example}: the simulator failed: {e}");
    }
    (trace, log)
}

/// `sha256sum`'s line for the trace, then its length in bytes and its rows (header excluded).
fn digest_line(example: &str, trace: &[u8]) -> String {
    let hex: String = Sha256::digest(trace)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    let rows = trace
        .iter()
        .filter(|b| **b == b'\n')
        .count()
        .saturating_sub(1);
    format!("{hex}  {example}.csv\n{} {rows}\n", trace.len())
}

#[test]
fn every_bundled_example_matches_its_golden_trace_and_log() {
    let golden = root().join("tests/golden");
    let update = std::env::var_os("TANDEM_UPDATE_GOLDEN").is_some();
    let mut mismatches = Vec::new();
    for example in EXAMPLES {
        let (trace, log) = simulate(example);
        let digest = digest_line(example, &trace);
        let log_path = golden.join(format!("{example}.log"));
        let digest_path = golden.join(format!("{example}.trace.sha256"));
        if update {
            std::fs::create_dir_all(&golden).ok();
            std::fs::write(&log_path, &log).ok();
            std::fs::write(&digest_path, &digest).ok();
            continue;
        }
        let want_log = std::fs::read(&log_path).unwrap_or_default();
        let want_digest = std::fs::read_to_string(&digest_path).unwrap_or_default();
        if log != want_log || digest != want_digest {
            // Keep what this run produced beside the build, for a diff.
            let out = std::env::temp_dir().join(format!("tandem-golden-{example}"));
            std::fs::create_dir_all(&out).ok();
            std::fs::write(out.join("trace.csv"), &trace).ok();
            std::fs::write(out.join("log.txt"), &log).ok();
            mismatches.push(format!(
                "{example}: log {} / trace {} (this run's output in {})",
                if log == want_log { "same" } else { "DIFFERS" },
                if digest == want_digest {
                    "same"
                } else {
                    "DIFFERS"
                },
                out.display()
            ));
        }
    }
    assert!(
        mismatches.is_empty(),
        "the simulator's output changed:\n{}",
        mismatches.join("\n")
    );
}

#[test]
fn the_golden_files_name_every_bundled_example() {
    // A new example with a script must be added to EXAMPLES (and get golden files).
    let mut scripts: Vec<String> = std::fs::read_dir(root().join("config"))
        .map(|d| {
            d.filter_map(|e| e.ok())
                .filter_map(|e| e.file_name().to_str().map(str::to_owned))
                .filter_map(|n| n.strip_suffix("-script.toml").map(str::to_owned))
                .collect()
        })
        .unwrap_or_default();
    scripts.sort();
    let mut known: Vec<String> = EXAMPLES.iter().map(|s| s.to_string()).collect();
    known.sort();
    assert_eq!(scripts, known);
}

/// The columns `names` of every row of a trace.
fn columns(trace: &[u8], names: &[&str]) -> Vec<Vec<f64>> {
    let text = std::str::from_utf8(trace).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at: Vec<usize> = names
        .iter()
        .map(|n| header.iter().position(|h| h == n).unwrap())
        .collect();
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            at.iter().map(|&i| f[i].parse().unwrap()).collect()
        })
        .collect()
}

/// `config/hydraulic-gantry.toml`: the two cylinders on two nodes, geared to the bridge's
/// setpoint of t - D, move together through the lift and the lowering although the right one
/// carries 1.5 kN more and has a larger valve offset: their actual positions never differ by
/// more than 0.2 mm (0.134 measured), each within 0.2 mm of its set position, which is the
/// bridge's of 100 ms before; both end at 150 mm.
#[test]
fn the_gantry_cylinders_on_two_nodes_move_together() {
    let (trace, _) = simulate("hydraulic-gantry");
    let rows = columns(
        &trace,
        &[
            "time_s",
            "bridge.position",
            "left_ram.position",
            "left_ram.actual_position",
            "right_ram.position",
            "right_ram.actual_position",
        ],
    );
    assert_eq!(rows.len(), 9001);
    let (mut skew, mut lag) = (0.0_f64, 0.0_f64);
    // MC_GearIn couples relatively: each end keeps the offset it had to the bridge at coupling
    // (the right one had sagged 0.061 mm under its load before its valve was enabled).
    let mut offsets = None;
    for (k, r) in rows.iter().enumerate() {
        skew = skew.max((r[3] - r[5]).abs());
        lag = lag.max((r[2] - r[3]).abs()).max((r[4] - r[5]).abs());
        // The set positions are the bridge's of 100 cycles before plus that offset (1e-9).
        let Some(before) = k.checked_sub(100).and_then(|b| rows.get(b)) else {
            continue;
        };
        if r[0] < 0.25 {
            continue;
        }
        let (dl, dr) = *offsets.get_or_insert((r[2] - before[1], r[4] - before[1]));
        assert!(
            (r[2] - before[1] - dl).abs() < 1e-9 && (r[4] - before[1] - dr).abs() < 1e-9,
            "t = {}: {r:?} against the bridge's {}",
            r[0],
            before[1]
        );
    }
    let (dl, dr) = offsets.unwrap();
    assert!(dl.abs() < 0.1 && dr.abs() < 0.1, "offsets {dl} {dr}");
    assert!(skew < 0.2, "the ends differ by up to {skew} mm");
    assert!(
        lag < 0.2,
        "a cylinder lags its set position by up to {lag} mm"
    );
    let last = rows.last().unwrap();
    assert!(
        (last[3] - 150.0).abs() < 0.1 && (last[5] - 150.0).abs() < 0.1,
        "{last:?}"
    );
    assert!(
        rows.iter().any(|r| r[1] >= 400.0),
        "the bridge reached 400 mm"
    );
}

/// The text of column `name` of every row of a trace.
fn text_column(trace: &[u8], name: &str) -> Vec<String> {
    let text = std::str::from_utf8(trace).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at = header.iter().position(|h| *h == name).unwrap();
    lines
        .map(|l| l.split(',').nth(at).unwrap().to_owned())
        .collect()
}

/// `config/hydraulic.toml`'s trace carries the library's scope signals (its FAQ #15): the
/// generator's states in the order of the two positionings, `fTargetPos`, and
/// `fLagCtrlOutput` = fLagAmp · (fSetPos − fActPos) = 50 · lag (mm/s) while the controller
/// acts (Idle, no I part), 0 during a move in the displacement mode.
#[test]
fn the_hydraulic_trace_shows_the_generator_state_and_the_controller_output() {
    let (trace, _) = simulate("hydraulic");
    let states = text_column(&trace, "ram.hyd_state");
    let mut seen: Vec<&str> = Vec::new();
    for s in &states {
        if seen.last() != Some(&s.as_str()) {
            seen.push(s);
        }
    }
    let p = |d: &str| format!("iTcHydState{d}");
    let expected: Vec<String> = [
        "Idle",
        "TcAccP",
        "ConstVeloP",
        "PcDecP",
        "CreepVeloP",
        "Idle",
        "TcAccM",
        "ConstVeloM",
        "PcDecM",
        "CreepVeloM",
        "Idle",
    ]
    .iter()
    .map(|d| p(d))
    .collect();
    assert_eq!(seen, expected);
    let rows = columns(
        &trace,
        &[
            "ram.position",
            "ram.actual_position",
            "ram.target_position",
            "ram.lag_ctrl_output",
        ],
    );
    let mut acting = 0;
    for (k, (r, s)) in rows.iter().zip(&states).enumerate().skip(1) {
        let (set, actual, lag_out) = (r[0], r[1], r[3]);
        if s == "iTcHydStateIdle" {
            let expected = 50.0 * (set - actual);
            assert!(
                (lag_out - expected).abs() <= 1e-9,
                "row {k}: {lag_out} {expected}"
            );
            acting += 1;
        } else {
            assert_eq!(lag_out, 0.0, "row {k}: {s}");
        }
    }
    assert!(acting > 1000, "{acting}");
    // The target of the second positioning from its start on.
    let target = rows.iter().zip(&states).find(|(_, s)| s.ends_with('M'));
    assert_eq!(target.map(|(r, _)| r[2]), Some(120.0));
}

/// `config/hydraulic-press.toml`'s trace: the force column is the force on the ram from the
/// two pressure columns and the areas of `[axes.ram.hydraulic]` (1 bar = 0.1 N/mm²).
#[test]
fn the_press_trace_shows_the_pressures_and_the_force_from_them() {
    let (trace, _) = simulate("hydraulic-press");
    let rows = columns(&trace, &["ram.pressure_a", "ram.pressure_b", "ram.force"]);
    let mut worst = 0.0_f64;
    for r in &rows {
        let f = 0.1 * (r[0] * 3117.2 - r[1] * 1526.8);
        assert!((f - r[2]).abs() <= 1e-6 * f.abs().max(1.0), "{r:?}");
        worst = worst.max(r[2]);
    }
    // The force controller holds 20 kN.
    assert!(worst > 19_000.0, "{worst}");
}
