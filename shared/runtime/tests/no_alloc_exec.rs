//! The node's cyclic path does not allocate: the three executives of `config/line.toml` (a
//! leader, geared followers reading it at t - D from their buffers, a cam follower with an
//! output cam and a measuring input) step 6,000 cycles, exchanging leading values as the nodes
//! do, with 0 allocations once the commands are applied, through a stall of the leader's samples
//! longer than D (extrapolation, then the rejoin when they come) and an outage (alarm 601).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::Coupling;
use tandem_runtime::exec::Executive;
use tandem_testkit::counting::{arm, disarm};

tandem_testkit::counting_allocator!();

#[test]
fn three_executives_step_without_allocating() {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cell = tandem_config::load(&root.join("config/line.toml")).unwrap();
    let src = std::fs::read_to_string(root.join("config/line-script.toml")).unwrap();
    let script = tandem_config::script::parse_cell("line-script.toml", &src, &cell).unwrap();
    let node = |n: &str| cell.node(n).unwrap();
    let mut nodes: Vec<Executive> = ["leaders", "followers", "cutter"]
        .iter()
        .map(|n| Executive::new(&cell, Some(node(n))).unwrap())
        .collect();
    let line = cell.leader_named("line").unwrap();
    let mut log = std::io::sink();
    let mut next = 0;
    let mut allocations = 0;
    let mut stepped = 0;
    // The samples held back by a stall, delivered at once when it ends.
    let mut held = Vec::with_capacity(200);
    let (stall_from, stall_to) = (2520, 2625);
    for k in 0..6000i64 {
        let t = k * 1_000_000;
        // Commands (which may allocate: a job takes its cam) between the counted steps.
        while let Some(e) = script.entries.get(next).filter(|e| e.t_ns <= t) {
            next += 1;
            for x in nodes.iter_mut() {
                // Only allocations are counted here; outcomes are checked by the golden and sim tests.
                let _ = x.apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, &mut log);
            }
        }
        arm();
        // From 5 s the leader's samples stop coming (its node died): the followers bridge
        // the tolerance, log the outage, raise 601 and brake, still without allocating.
        let alive = k < 5000;
        if alive {
            nodes[0].step(t, &mut log).unwrap();
        }
        let s = nodes[0].sample(line, Coupling::Setpoint, t, k as u64);
        // From 2.52 s the samples are held back for 105 ms (longer than D = 100 ms), while the
        // line accelerates: the followers extrapolate for 5 cycles, then rejoin.
        if (stall_from..stall_to).contains(&k) {
            held.push(s);
        }
        for x in nodes[1..].iter_mut() {
            if k == stall_to {
                for h in &held {
                    x.feed(line, Coupling::Setpoint, *h).unwrap();
                }
            }
            if alive && !(stall_from..stall_to).contains(&k) {
                x.feed(line, Coupling::Setpoint, s).unwrap();
            }
            x.step(t, &mut log).unwrap();
        }
        for x in nodes.iter_mut() {
            x.drain_job_notes(|_| {});
            x.drain_io_notes(|_| {});
        }
        allocations += disarm().0;
        stepped += 1;
    }
    assert_eq!(stepped, 6000);
    assert_eq!(allocations, 0, "allocations on the cyclic path");
    // It did work: the followers were coupled, bridged the stall for 5 cycles and the outage
    // for the tolerance (one extrapolated cycle per leader cycle of it: 10 of 1 ms in
    // config/line.toml), then stopped with 601.
    let knife = cell.axes.iter().position(|a| a.name == "knife").unwrap();
    let feed = cell.axes.iter().position(|a| a.name == "feed").unwrap();
    for (n, a) in [(1, feed), (2, knife)] {
        let st = nodes[n].status()[a];
        assert_eq!(st.state.name(), "ErrorStop", "{}", cell.axes[a].name);
        assert_eq!(st.error_detail.number, 601);
        assert_eq!(st.velocity, 0.0);
    }
    let line = cell.leader_named("line").unwrap();
    let bridged = (cell.leading(line).tolerance_ns / cell.leader_cycle_ns(line)) as u64;
    assert_eq!(bridged, 10);
    assert_eq!(
        nodes[1].extrapolated,
        2 * (5 + bridged),
        "two followers, one extrapolated cycle per cycle of the stall beyond D and of the tolerance"
    );
    assert_eq!(nodes[2].extrapolated, 5 + bridged);
}

/// The process image's drive stages (`config/servo.toml`: an axis on a simulated CiA 402
/// servo): the exchange at the boundary, the link's inputs and command, through the enable
/// sequence, a move, a drive fault and its reset, with 0 allocations.
#[test]
fn the_drive_stages_step_without_allocating() {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cell = tandem_config::load(&root.join("config/servo.toml")).unwrap();
    let src = std::fs::read_to_string(root.join("config/servo-script.toml")).unwrap();
    let script = tandem_config::script::parse_cell("servo-script.toml", &src, &cell).unwrap();
    let mut exec = Executive::new(&cell, None).unwrap();
    let mut log = std::io::sink();
    let (mut next, mut allocations) = (0, 0);
    let end = script.duration_ns / 1_000_000;
    for k in 0..=end {
        let t = k * 1_000_000;
        while let Some(e) = script.entries.get(next).filter(|e| e.t_ns <= t) {
            next += 1;
            // Only allocations are counted here; outcomes are checked by the golden test.
            let _ = exec.apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, &mut log);
        }
        arm();
        exec.step(t, &mut log).unwrap();
        exec.drain_job_notes(|_| {});
        exec.drain_io_notes(|_| {});
        allocations += disarm().0;
    }
    assert_eq!(allocations, 0, "allocations on the cyclic path");
    // It did work: the move after the fault's reset ended where it was sent.
    let st = exec.status()[0];
    assert_eq!((st.state.name(), st.position), ("Standstill", 100.0));
    assert!(exec.commands >= 8 && exec.rejected == 0);
}

/// The output stage (`config/glue-dot.toml`: a cam track on a timestamped output, an output
/// cam on a plain one): edges queued by their due time, tasks written and executed, channels
/// switched and recorded, with 0 allocations.
#[test]
fn the_output_stage_steps_without_allocating() {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cell = tandem_config::load(&root.join("config/glue-dot.toml")).unwrap();
    let src = std::fs::read_to_string(root.join("config/glue-dot-script.toml")).unwrap();
    let script = tandem_config::script::parse_cell("glue-dot-script.toml", &src, &cell).unwrap();
    let mut exec = Executive::new(&cell, None).unwrap();
    let mut log = std::io::sink();
    let (mut next, mut allocations) = (0, 0);
    let mut switches = [0usize; 2];
    let end = script.duration_ns / 1_000_000;
    for k in 0..=end {
        let t = k * 1_000_000;
        while let Some(e) = script.entries.get(next).filter(|e| e.t_ns <= t) {
            next += 1;
            // Only allocations are counted here; outcomes are checked by tests/outputs.rs.
            let _ = exec.apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, &mut log);
        }
        arm();
        exec.step(t, &mut log).unwrap();
        exec.drain_job_notes(|_| {});
        exec.drain_io_notes(|_| {});
        exec.drain_output_switches(|s| {
            if let Some(n) = switches.get_mut(usize::from(s.late)) {
                *n += 1;
            }
        });
        allocations += disarm().0;
    }
    assert_eq!(allocations, 0, "allocations on the cyclic path");
    // It did work: the gun valve and the zero mark switched, none late.
    let gun = cell
        .devices
        .iter()
        .position(|d| d.name == "gun_io")
        .unwrap();
    let counter = cell
        .devices
        .iter()
        .position(|d| d.name == "counter_io")
        .unwrap();
    let (g, c) = (
        *exec.output_device(gun).unwrap(),
        *exec.output_device(counter).unwrap(),
    );
    assert!(g.switches >= 30 && c.switches >= 4, "{g:?} {c:?}");
    assert_eq!(switches, [(g.switches + c.switches) as usize, 0]);
    assert_eq!(
        g.look_ahead_ns, 4_000_000,
        "2 cycles + the 2 ms on-compensation"
    );
}

/// Runs bundled example `name` (`config/<name>.toml` with its script) through the executive,
/// counting the allocations of every step and drain: the executive after the run and the count.
fn run_counting<'c>(cell: &'c tandem_config::Cell, name: &str) -> (Executive<'c>, u64) {
    run_counting_with(cell, name, "")
}

/// [`run_counting`] with `extra` appended to the bundled script (more `[[at]]` entries).
fn run_counting_with<'c>(
    cell: &'c tandem_config::Cell,
    name: &str,
    extra: &str,
) -> (Executive<'c>, u64) {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let file = format!("{name}-script.toml");
    let src = std::fs::read_to_string(root.join("config").join(&file)).unwrap() + extra;
    let script = tandem_config::script::parse_cell(&file, &src, cell).unwrap();
    let mut exec = Executive::new(cell, None).unwrap();
    let mut log = std::io::sink();
    let (mut next, mut allocations) = (0, 0);
    let end = script.duration_ns / 1_000_000;
    for k in 0..=end {
        let t = k * 1_000_000;
        while let Some(e) = script.entries.get(next).filter(|e| e.t_ns <= t) {
            next += 1;
            // Only allocations are counted here; outcomes are checked by the golden test.
            let _ = exec.apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, &mut log);
        }
        arm();
        exec.step(t, &mut log).unwrap();
        exec.drain_job_notes(|_| {});
        exec.drain_io_notes(|_| {});
        allocations += disarm().0;
    }
    (exec, allocations)
}

/// The cell of bundled example `name`.
fn example_cell(name: &str) -> tandem_config::Cell {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    tandem_config::load(&root.join(format!("config/{name}.toml"))).unwrap()
}

/// The analog drive stages (`config/analog.toml`: an axis on a simulated analog drive with a
/// 16-bit counter): the exchange at the boundary, the encoder, the enable / ready handshake,
/// tandem's position controller and the output word, through a move, a lost ready, the reset
/// and a move, with 0 allocations.
#[test]
fn the_analog_drive_stages_step_without_allocating() {
    let cell = example_cell("analog");
    let (mut exec, allocations) = run_counting(&cell, "analog");
    assert_eq!(allocations, 0, "allocations on the cyclic path");
    // It did work: the move after the reset ended where it was sent, on the drive too.
    let st = exec.status()[0];
    assert_eq!((st.state.name(), st.position), ("Standstill", 100.0));
    assert!((exec.analog_drive(0).unwrap().position - 100.0).abs() < 0.01);
    assert!(exec.commands >= 8 && exec.rejected == 0);
}

/// A hydraulic axis (`config/hydraulic.toml`): the displacement-based generator, the target
/// window, the position controller and Finish, and the simulated valve and cylinder, through
/// two positionings, with 0 allocations.
#[test]
fn the_hydraulic_stages_step_without_allocating() {
    let cell = example_cell("hydraulic");
    let (mut exec, allocations) = run_counting(&cell, "hydraulic");
    assert_eq!(allocations, 0, "allocations on the cyclic path");
    // It did work: the second positioning ended at its target, the cylinder within 0.2 mm.
    let st = exec.status()[0];
    assert_eq!((st.state.name(), st.position), ("Standstill", 120.0));
    assert!((exec.analog_drive(0).unwrap().position - 120.0).abs() < 0.2);
    assert!(exec.commands == 4 && exec.rejected == 0);
}

/// A hydraulic press (`config/hydraulic-press.toml`): the pressure inputs, the force controller
/// (MC_AxCtrlPressure_BkPlcMc) through contact, pressing, decompression and release, and the
/// return, with 0 allocations.
#[test]
fn the_force_control_stages_step_without_allocating() {
    let cell = example_cell("hydraulic-press");
    let (mut exec, allocations) = run_counting(&cell, "hydraulic-press");
    assert_eq!(allocations, 0, "allocations on the cyclic path");
    let st = exec.status()[0];
    assert_eq!((st.state.name(), st.position), ("Standstill", 300.0));
    assert!(exec.commands == 7 && exec.rejected == 0);
}

/// MC_TorqueLimiting's fixed stop detection (`config/fixed-stop.toml`): a torque-limited move
/// into the simulated servo's mechanical stop, the detection, clamping at the limit, a new
/// limit while clamped, the stop giving way (alarm 542) and the reset, with 0 allocations.
#[test]
fn the_torque_limited_move_into_the_fixed_stop_steps_without_allocating() {
    let cell = example_cell("fixed-stop");
    let (mut exec, allocations) = run_counting(&cell, "fixed-stop");
    assert_eq!(allocations, 0, "allocations on the cyclic path");
    // It did work: clamped at the stop, then the clamping alarm, acknowledged.
    let st = exec.status()[0];
    assert!((st.actual_position - 50.0).abs() < 1.0, "{st:?}");
    assert!(exec.commands == 7 && exec.rejected == 0);
}

/// MC_DigitalCamSwitch_BkPlcMc (`config/hydraulic-cam-switch.toml`): the library's worked
/// example on the ram, its two tracks on digital outputs through both moves and the mask
/// change, with 0 allocations.
#[test]
fn the_digital_cam_switch_steps_without_allocating() {
    let cell = example_cell("hydraulic-cam-switch");
    let (mut exec, allocations) = run_counting(&cell, "hydraulic-cam-switch");
    assert_eq!(allocations, 0, "allocations on the cyclic path");
    assert_eq!(exec.status()[0].state.name(), "Standstill");
    assert!(exec.commands == 7 && exec.rejected == 0);
}

/// The bundled hydraulic axis on the jerk-based generator with the extended position
/// controller (its D part and condition feedback, nalgebra's fixed-size matrices), through the
/// two positionings, with 0 allocations.
#[test]
fn the_jerk_generator_and_the_extended_controller_step_without_allocating() {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let src = std::fs::read_to_string(root.join("config/hydraulic.toml")).unwrap();
    let src = src.replacen(
        "fLagAmp = 50.0",
        "fLagAmp = 50.0\nposition_controller = \"extended\"\nfLagAmpTd = 0.5\n\
         fLagAmpTdd = 0.005\nfLagAmpCfb_kV = 0.3\nfLagAmpCfb_tV = 0.005\n\
         fLagAmpCfb_kA = 0.001\nfLagAmpCfb_tA = 0.005\nnProfileType = \"iTcMc_ProfileJerkBased\"",
        1,
    );
    let cell = tandem_config::parse("hydraulic.toml", &src).unwrap();
    let (mut exec, allocations) = run_counting(&cell, "hydraulic");
    assert_eq!(allocations, 0, "allocations on the cyclic path");
    let st = exec.status()[0];
    assert_eq!((st.state.name(), st.position), ("Standstill", 120.0));
    assert!(exec.commands == 4 && exec.rejected == 0);
}

/// MC_AxCtrlSlowDownOnPressureEx_BkPlcMc on the press (`config/hydraulic-press.toml`, the
/// limiter enabled before the approach), through contact, pressing and return, with 0
/// allocations.
#[test]
fn the_slow_down_on_pressure_steps_without_allocating() {
    let cell = example_cell("hydraulic-press");
    let extra = "\n[[at]]\nt = 0.05\naxis = \"ram\"\n\
                 instruction = \"MC_AxCtrlSlowDownOnPressureEx_BkPlcMc\"\n\
                 set_point = 30000.0\nkp = 0.01\n";
    let (exec, allocations) = run_counting_with(&cell, "hydraulic-press", extra);
    assert_eq!(allocations, 0, "allocations on the cyclic path");
    assert!(exec
        .axis(tandem_config::AxisIndex(0))
        .unwrap()
        .hydraulic_status()
        .unwrap()
        .slow_down
        .is_some());
    assert!(exec.commands == 8 && exec.rejected == 0);
}

/// MC_AxCtrlPressureFF_BkPlcMc on the press (`config/hydraulic-press.toml`): after the script's
/// release of MC_AxCtrlPressure_BkPlcMc, the PID controller with its D filter presses for 30 ms,
/// is reset, and the ram returns, with 0 allocations.
#[test]
fn the_pressure_ff_controller_steps_without_allocating() {
    let cell = example_cell("hydraulic-press");
    let extra = "\n[[at]]\nt = 4.55\naxis = \"ram\"\n\
                 instruction = \"MC_AxCtrlPressureFF_BkPlcMc\"\nreset = false\n\
                 setpoint = 2000.0\nkp = 0.00002\ntn = 0.05\ntv = 0.002\nnf = 5\n\
                 windup_limit = 0.2\n\
                 \n[[at]]\nt = 4.58\naxis = \"ram\"\n\
                 instruction = \"MC_AxCtrlPressureFF_BkPlcMc\"\n";
    let (mut exec, allocations) = run_counting_with(&cell, "hydraulic-press", extra);
    assert_eq!(allocations, 0, "allocations on the cyclic path");
    let st = exec.status()[0];
    assert_eq!((st.state.name(), st.position), ("Standstill", 300.0));
    assert!(exec.commands == 9 && exec.rejected == 0);
}

/// MC_FlyingGear_BkPlcMc (`config/hydraulic-flying-gear.toml`): the cushion's flying gear on
/// the slide through waiting, engaging, in sync, releasing and stopped, with 0 allocations.
#[test]
fn the_flying_gear_steps_without_allocating() {
    let cell = example_cell("hydraulic-flying-gear");
    let (mut exec, allocations) = run_counting(&cell, "hydraulic-flying-gear");
    assert_eq!(allocations, 0, "allocations on the cyclic path");
    let st = exec.status()[0];
    assert_eq!((st.position, st.sync_job), (250.0, None));
    assert!(exec.commands == 7 && exec.rejected == 0);
}

/// The input stage (`config/inputs.toml`): a timestamped input driven by a sensor on the web
/// feeding a cyclic measuring input, a probe pulsed by the script, and a plain input as the
/// web's limit switch (alarm 531): sampled, sensed, measured and drained with 0 allocations.
#[test]
fn the_input_stage_steps_without_allocating() {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cell = tandem_config::load(&root.join("config/inputs.toml")).unwrap();
    let src = std::fs::read_to_string(root.join("config/inputs-script.toml")).unwrap();
    let script = tandem_config::script::parse_cell("inputs-script.toml", &src, &cell).unwrap();
    let mut exec = Executive::new(&cell, None).unwrap();
    let mut log = std::io::sink();
    let (mut next, mut allocations, mut edges, mut measured) = (0, 0, 0, 0);
    let end = script.duration_ns / 1_000_000;
    for k in 0..=end {
        let t = k * 1_000_000;
        arm();
        while let Some(e) = script.entries.get(next).filter(|e| e.t_ns <= t) {
            next += 1;
            // Only allocations are counted here; outcomes are checked by tests/inputs.rs.
            let _ = exec.apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, &mut log);
        }
        exec.step(t, &mut log).unwrap();
        exec.drain_job_notes(|_| {});
        exec.drain_io_notes(|n| measured += usize::from(n.measured));
        exec.drain_input_edges(|_| edges += 1);
        allocations += disarm().0;
    }
    assert_eq!(allocations, 0, "allocations on the cyclic path");
    // It did work: the mark's two edges, the probe's two, the switch's one; two measurements;
    // the web stopped on its limit switch.
    assert_eq!((edges, measured), (5, 2));
    assert_eq!(exec.status()[0].error_detail.number, 531);
}

/// The value stage as a node's EtherCAT segment drives it (`config/inputs.toml` with a
/// `sim_analog_output` added): every cycle an analog input set from outside
/// (`Executive::set_input_value`, an `aio`'s input word) and a float output set by
/// `SetOutput`, both changing, sampled, logged and drained, with 0 allocations.
#[test]
fn the_value_stage_set_from_outside_and_by_set_output_does_not_allocate() {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let src = std::fs::read_to_string(root.join("config/inputs.toml"))
        .unwrap()
        .replacen(
            "[devices.piece_counter]",
            "[devices.valve_ao]\nnode = \"line\"\nkind = \"sim_analog_output\"\nchannels = 2\n\n\
             [signals.valve_cmd]\ndevice = \"valve_ao\"\nchannel = 1\n\n[devices.piece_counter]",
            1,
        );
    let cell = tandem_config::parse("inputs.toml", &src).unwrap();
    let ai = cell
        .devices
        .iter()
        .position(|d| d.name == "tension_ai")
        .unwrap();
    let ao = cell
        .devices
        .iter()
        .position(|d| d.name == "valve_ao")
        .unwrap();
    let mut exec = Executive::new(&cell, None).unwrap();
    let mut log = Vec::with_capacity(1 << 20);
    let (mut allocations, mut values) = (0, 0u64);
    for k in 0..2000i64 {
        let t = k * 1_000_000;
        let v = (k % 200) as f64 * 0.05 - 5.0;
        arm();
        assert!(exec.set_input_value(ai, 1, t, v));
        let action = tandem_motion::objects::action::Action::SetOutputValue { value: -v };
        let applied = exec.apply_at(t, t, "valve_cmd", "SetOutput", action, &mut log);
        exec.step(t, &mut log).unwrap();
        exec.drain_input_values(|_| values += 1);
        exec.drain_job_notes(|_| {});
        exec.drain_io_notes(|_| {});
        exec.drain_input_edges(|_| {});
        allocations += disarm().0;
        assert!(matches!(applied, Ok(Ok(_))), "{applied:?}");
    }
    assert_eq!(allocations, 0, "allocations on the cyclic path");
    // It did work: both channels changed every cycle (from 0 V to -5 V at the first).
    assert_eq!(values, 2 * 2000, "input and output changes");
    assert_eq!(exec.value_device(ao).unwrap().changes, 2000);
}
