//! [`Executive::want_status`] changes when a status is copied, never what it is.
//!
//! Every bundled example runs twice side by side: the reference reads every status after every
//! step (as `tandem sim` does, which the golden traces check); the other asks the step to copy
//! the statuses on some cycles and reads them on others (a node's telemetry asks and reads on
//! the same cycles; here they also differ, so that commands, job events and alarms land
//! between a copy and the next read). Whenever the second reads, every axis' status must be
//! the reference's bit for bit, and both logs must be byte-identical.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};
use tandem_runtime::exec::Executive;

const EXAMPLES: &[&str] = &[
    "example",
    "line",
    "cross-cutter",
    "flying-saw",
    "glue-dot",
    "print-mark-registration",
    "press",
    "servo",
];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Bits of a status: its `Debug` form, which writes every float's shortest round-trip digits
/// (so `-0.0` and `0.0` differ, as any two different bit patterns but NaNs do).
fn bits(status: &[tandem_motion::objects::axis::AxisStatus]) -> Vec<String> {
    status.iter().map(|s| format!("{s:?}")).collect()
}

/// Runs `example` with the reference and with `want`/`read` choosing, per cycle, whether the
/// second executive asks for the copy and whether it reads; returns the cycles compared.
fn compare(example: &str, want: impl Fn(i64) -> bool, read: impl Fn(i64) -> bool) -> usize {
    let config = root().join("config");
    let cell_path = if example == "example" {
        config.join("example-cell.toml")
    } else {
        config.join(format!("{example}.toml"))
    };
    let script_path = config.join(format!("{example}-script.toml"));
    let cell = tandem_config::load(&cell_path).unwrap();
    let src = std::fs::read_to_string(&script_path).unwrap();
    let script = tandem_config::script::parse_cell(example, &src, &cell).unwrap();
    let mut reference = Executive::new(&cell, None).unwrap();
    let mut copied = Executive::new(&cell, None).unwrap();
    let (mut log_ref, mut log_copied) = (Vec::new(), Vec::new());
    let tick = reference.tick_ns();
    let (mut next, mut compared) = (0, 0);
    let mut k: i64 = 0;
    while k * tick <= script.duration_ns {
        let t = k * tick;
        while let Some(e) = script.entries.get(next).filter(|e| e.t_ns <= t) {
            next += 1;
            let a = reference
                .apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, &mut log_ref)
                .unwrap();
            let b = copied
                .apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, &mut log_copied)
                .unwrap();
            assert_eq!(a, b, "{example}: t={t} {} {:?}", e.axis, e.instruction);
        }
        if want(k) {
            copied.want_status();
        }
        reference.step(t, &mut log_ref).unwrap();
        copied.step(t, &mut log_copied).unwrap();
        for x in [&mut reference, &mut copied] {
            x.drain_job_notes(|_| {});
            x.drain_io_notes(|_| {});
        }
        let expected = bits(reference.status());
        if read(k) {
            assert_eq!(bits(copied.status()), expected, "{example}: cycle {k}");
            compared += 1;
        }
        k += 1;
    }
    assert_eq!(log_ref, log_copied, "{example}: the logs differ");
    compared
}

#[test]
fn a_status_copied_in_the_step_is_the_status_read_after_it() {
    for example in EXAMPLES {
        // As a node's telemetry: asked for and read on every 10th cycle.
        let n = compare(example, |k| k % 10 == 0, |k| k % 10 == 0);
        assert!(n > 10, "{example}: only {n} cycles compared");
        // Asked for on every 3rd cycle, read on every 7th: some reads find the copy of a
        // step without a read since, some a copy followed by commands, some no copy at all.
        let n = compare(example, |k| k % 3 == 0, |k| k % 7 == 0);
        assert!(n > 10, "{example}: only {n} cycles compared");
        // Asked for every cycle, read every cycle.
        compare(example, |_| true, |_| true);
    }
}

const DYNAMICS: &str = "max_velocity = 1000.0\nmax_acceleration = 10000.0\nmax_deceleration = 10000.0\nmax_jerk = 100000.0\nvelocity = 200.0\nacceleration = 2000.0\ndeceleration = 2000.0\njerk = 20000.0\nemergency_deceleration = 20000.0\n";

/// Two nodes at 1 ms and 2 ms: the slow node's axes do not step on odd milliseconds, when
/// commands still reach them; a copy asked for then must not hide what the command did.
#[test]
fn axes_not_stepped_keep_showing_their_commands() {
    let dir = std::env::temp_dir().join(format!("tandem-status-copy-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cell_path = dir.join("cell.toml");
    let script_path = dir.join("script.toml");
    std::fs::write(
        &cell_path,
        format!(
            "[cell]\nname = \"rates\"\nbase_tick_us = 1000\n\n\
         [[nodes]]\nname = \"fast\"\ncycle_us = 1000\n\n\
         [[nodes]]\nname = \"slow\"\ncycle_us = 2000\n\n\
         [axes.a]\nnode = \"fast\"\nvirtual = true\n\n[axes.a.dynamics]\n{DYNAMICS}\n\
         [axes.b]\nnode = \"slow\"\nvirtual = true\n\n[axes.b.dynamics]\n{DYNAMICS}",
        ),
    )
    .unwrap();
    let mut script = String::from("[sim]\nduration = 0.6\n\n");
    for axis in ["a", "b"] {
        script.push_str(&format!(
            "[[at]]\nt = 0.0\naxis = \"{axis}\"\ninstruction = \"MC_Power\"\n\n\
             [[at]]\nt = 0.0\naxis = \"{axis}\"\ninstruction = \"MC_Home\"\nmode = 0\nposition = 0.0\n\n"
        ));
        // On odd milliseconds: the slow node's axis does not step then.
        for (k, ms) in [11, 101, 203, 355].iter().enumerate() {
            script.push_str(&format!(
                "[[at]]\nt = {:.3}\naxis = \"{axis}\"\ninstruction = \"MC_MoveAbsolute\"\n\
                 position = {}.0\nvelocity = 200.0\n\n",
                *ms as f64 / 1000.0,
                (k as i64 % 2 * 2 - 1) * 30
            ));
        }
    }
    std::fs::write(&script_path, script).unwrap();
    let cell = tandem_config::load(&cell_path).unwrap();
    let src = std::fs::read_to_string(&script_path).unwrap();
    let script = tandem_config::script::parse_cell("rates", &src, &cell).unwrap();
    let mut reference = Executive::new(&cell, None).unwrap();
    let mut copied = Executive::new(&cell, None).unwrap();
    let mut log = std::io::sink();
    let tick = reference.tick_ns();
    let mut next = 0;
    let mut k: i64 = 0;
    while k * tick <= script.duration_ns {
        let t = k * tick;
        while let Some(e) = script.entries.get(next).filter(|e| e.t_ns <= t) {
            next += 1;
            for x in [&mut reference, &mut copied] {
                x.apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, &mut log)
                    .unwrap()
                    .unwrap();
            }
        }
        // Asked for every cycle; read after each step.
        copied.want_status();
        reference.step(t, &mut log).unwrap();
        copied.step(t, &mut log).unwrap();
        assert_eq!(bits(copied.status()), bits(reference.status()), "cycle {k}");
        k += 1;
    }
    std::fs::remove_dir_all(&dir).ok();
}
