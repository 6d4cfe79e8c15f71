//! The rejoin after an extrapolation as the nodes run it (docs/processes.md, "Rejoin after
//! extrapolation"): the executives of `config/line.toml` with a tolerance of 100 ms, the
//! leader's samples held back for 190 ms from 2.5 s (the line's velocity change to 1500 mm/s,
//! its jerk phase) and then delivered at once. The followers, reading the line at t - D
//! (D = 100 ms), extrapolate for 90 ms; when the samples come they rejoin them without a step
//! and, once the correction is over, move exactly as in a run without the stall.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::Coupling;
use tandem_motion::objects::axis::AxisStatus;
use tandem_runtime::exec::Executive;

const MS: i64 = 1_000_000;

/// The first cycle whose sample is held back, and the cycle at which the held ones arrive.
const STALL: (i64, i64) = (2500, 2690);

/// Runs the line for 3.2 s, with the stall or without; returns per cycle the followers' status
/// (nodes `followers` and `cutter`), and the followers' log.
fn run(stall: bool) -> (Vec<Vec<AxisStatus>>, String) {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let src = std::fs::read_to_string(root.join("config/line.toml"))
        .unwrap()
        .replace("tolerance_us = 10000 ", "tolerance_us = 100000 ");
    assert!(src.contains("delay_us = 100000 ") && src.contains("tolerance_us = 100000 "));
    let cell = tandem_config::parse("line.toml", &src).unwrap();
    let script_src = std::fs::read_to_string(root.join("config/line-script.toml")).unwrap();
    let script = tandem_config::script::parse_cell("line-script.toml", &script_src, &cell).unwrap();
    let node = |n: &str| cell.node(n).unwrap();
    let mut nodes: Vec<Executive> = ["leaders", "followers", "cutter"]
        .iter()
        .map(|n| Executive::new(&cell, Some(node(n))).unwrap())
        .collect();
    let line = cell.leader_named("line").unwrap();
    let (mut log, mut quiet) = (Vec::new(), std::io::sink());
    let mut held = Vec::new();
    let mut next = 0;
    let mut out = Vec::new();
    for k in 0..3200 {
        let t = k * MS;
        while let Some(e) = script.entries.get(next).filter(|e| e.t_ns <= t) {
            next += 1;
            for x in nodes.iter_mut() {
                // Each node refuses the axes it does not own; the outcomes are checked by the
                // golden and sim tests.
                let _ = x.apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, &mut quiet);
            }
        }
        nodes[0].step(t, &mut quiet).unwrap();
        held.push(nodes[0].sample(line, Coupling::Setpoint, t, k as u64));
        if !stall || !(STALL.0..STALL.1).contains(&k) {
            for s in held.drain(..) {
                for x in nodes[1..].iter_mut() {
                    x.feed(line, Coupling::Setpoint, s).unwrap();
                }
            }
        }
        let mut row = Vec::new();
        for (i, x) in nodes.iter_mut().enumerate().skip(1) {
            if i == 1 {
                x.step(t, &mut log).unwrap();
            } else {
                x.step(t, &mut quiet).unwrap();
            }
            row.extend_from_slice(x.status());
        }
        for x in nodes.iter_mut() {
            x.drain_job_notes(|_| {});
            x.drain_io_notes(|_| {});
        }
        out.push(row);
    }
    assert_eq!(
        nodes[1].extrapolated,
        if stall { 2 * 90 } else { 0 },
        "two followers, 90 ms each"
    );
    (out, String::from_utf8(log).unwrap())
}

/// The setpoint of an axis: position, velocity, acceleration.
fn setpoint(s: &AxisStatus) -> (f64, f64, f64) {
    (s.position, s.velocity, s.acceleration)
}

#[test]
fn followers_rejoin_the_samples_after_a_stall_without_a_step() {
    let (calm, calm_log) = run(false);
    let (stalled, log) = run(true);
    assert!(!calm_log.contains("rejoined"), "{calm_log}");
    assert!(
        log.contains("leading value of line rejoined after 91 ms of extrapolation"),
        "{log}"
    );
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cell = tandem_config::load(&root.join("config/line.toml")).unwrap();
    let feed = cell.axes.iter().position(|a| a.name == "feed").unwrap();
    let unwind = cell.axes.iter().position(|a| a.name == "unwind").unwrap();
    let n = cell.axes.len();
    for (a, name) in [(feed, "feed"), (unwind, "unwind")] {
        let p = |run: &Vec<Vec<AxisStatus>>, k: usize| run[k][a].position_unwrapped;
        // The second difference of the setpoint (acceleration × cycle²): in the calm run the
        // line's 4,000 mm/s² at most (0.004 mm); with the rejoin at most about three times it;
        // a step of the leading value would make it the step itself (millimetres).
        let worst = |run: &Vec<Vec<AxisStatus>>| {
            (1..run.len() - 1)
                .map(|k| (p(run, k + 1) - 2.0 * p(run, k) + p(run, k - 1)).abs())
                .fold(0.0, f64::max)
        };
        let (calm_worst, stalled_worst) = (worst(&calm), worst(&stalled));
        assert!(calm_worst <= 0.004 + 1e-9, "{name}: {calm_worst}");
        assert!(
            stalled_worst < 0.012,
            "{name}: largest Δ²p {stalled_worst} mm"
        );
        // The extrapolation drifted: at the rejoin the follower is off the calm run by what
        // would have been the step.
        let k = STALL.1 as usize;
        let off = (p(&stalled, k) - p(&calm, k)).abs();
        assert!(off > 0.1, "{name}: off by {off} mm at the rejoin");
        // After the correction (twice the 91 ms since the last sample before the stall, 182 ms)
        // every follower's setpoint is exactly what it is without the stall (its simulated
        // drive's actual value still remembers the disturbance, decaying).
        for k in (STALL.1 as usize + 182)..calm.len() {
            assert_eq!(
                setpoint(&calm[k][a]),
                setpoint(&stalled[k][a]),
                "{name} at {k} ms"
            );
        }
    }
    // The cutter's knife (node `cutter`, the second half of each row) too.
    let knife = cell.axes.iter().position(|a| a.name == "knife").unwrap();
    for k in (STALL.1 as usize + 182)..calm.len() {
        let (c, s) = (&calm[k][n + knife], &stalled[k][n + knife]);
        assert_eq!(setpoint(c), setpoint(s), "knife at {k} ms");
    }
}
