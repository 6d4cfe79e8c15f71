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
    "analog",
    "inputs",
    "hydraulic",
    "hydraulic-press",
    "hydraulic-flying-gear",
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
