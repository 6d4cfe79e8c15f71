//! MC_WriteParameter / MC_ReadParameter through the executive and the simulator
//! (`config/example-parameters.script.toml` on `config/example-cell.toml`): the log names each
//! tag with the value the axis has after the instruction, refusals carry the reference's
//! ErrorIDs, a lower velocity limit slows the running move, a lower software limit stops it.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::PathBuf;

tandem_testkit::counting_allocator!();

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn the_bundled_parameter_script_runs_as_commented() {
    let cell = tandem_config::load(&root().join("config/example-cell.toml")).unwrap();
    let src =
        std::fs::read_to_string(root().join("config/example-parameters.script.toml")).unwrap();
    let script = tandem_config::script::parse_cell("parameters", &src, &cell).unwrap();
    let (mut trace, mut log) = (Vec::new(), Vec::new());
    tandem_runtime::sim::run(&cell, &script, &mut trace, &mut log).unwrap();
    let log = String::from_utf8(log).unwrap();
    for line in [
        "t=0.600000000 slide MC_WriteParameter: DynamicLimits.Velocity = 200",
        "t=0.600000000 slide MC_ReadParameter: DynamicLimits.Velocity = 200",
        "t=0.900000000 slide MC_WriteParameter: PositionControl.Kv = 80",
        "t=0.900000000 slide MC_ReadParameter: PositionControl.Kpc = 100",
        "t=1.000000000 slide MC_WriteParameter: Homing.HomePosition = 5",
        "t=1.200000000 slide MC_WriteParameter: PositionLimits_SW.MaxPosition = 380",
    ] {
        assert!(log.contains(line), "no `{line}` in\n{log}");
    }
    assert!(
        log.contains("MC_WriteParameter rejected: 16#8081 ParameterNotWritable"),
        "{log}"
    );
    assert!(
        log.contains("MC_WriteParameter rejected: 16#8003 IllegalVelocity"),
        "{log}"
    );
    assert!(
        log.contains("slide alarm 533"),
        "the lower software limit is reached:\n{log}"
    );
}

/// The node's command stage (on its cyclic thread) applies a write, formats its log line and
/// reads the value for the reply, and the steps after it run, with 0 allocations.
#[test]
fn writes_through_the_executive_and_the_steps_after_them_do_not_allocate() {
    use tandem_testkit::counting::{arm, disarm};
    let cell = tandem_config::load(&root().join("config/example-cell.toml")).unwrap();
    let src =
        std::fs::read_to_string(root().join("config/example-parameters.script.toml")).unwrap();
    let script = tandem_config::script::parse_cell("parameters", &src, &cell).unwrap();
    let mut exec = tandem_runtime::exec::Executive::new(&cell, None).unwrap();
    // A log of fixed capacity, as the node's (it cuts, never grows).
    let mut buffer = [0u8; 4096];
    let (mut next, mut allocations, mut writes) = (0, 0, 0);
    for k in 0..=3000i64 {
        let t = k * 1_000_000;
        let mut log = std::io::Cursor::new(&mut buffer[..]);
        while let Some(e) = script.entries.get(next).filter(|e| e.t_ns <= t) {
            next += 1;
            let parameter = e.instruction.ends_with("Parameter");
            if parameter {
                arm();
            }
            // Outcomes are checked by the test above; here only allocations.
            let _ = exec.apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, &mut log);
            // The node reads the value for its reply; any outcome, no allocation.
            let _ = exec.read_parameter(&e.axis, 1);
            if parameter {
                allocations += disarm().0;
                writes += 1;
            }
        }
        arm();
        exec.step(t, &mut log).unwrap();
        exec.drain_job_notes(|_| {});
        exec.drain_io_notes(|_| {});
        allocations += disarm().0;
    }
    assert_eq!(allocations, 0, "allocations while writing parameters");
    assert_eq!(writes, 10);
}
