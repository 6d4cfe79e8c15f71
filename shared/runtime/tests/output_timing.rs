//! Output timing against physical truth: an output cam or cam track that drives an output
//! computes its switching times ahead (docs/io.md, "Outputs" → "Timing"), so the output switches
//! when the position it follows is at the cam's edge, earlier by exactly its compensation.
//!
//! - An actual-value cam track on a timestamped output: at each switching time plus its lead
//!   the axis's actual position (reconstructed from the samples the executive reports, exact
//!   for constant velocity and constant acceleration) is at the cam's edge, to 1 ns in time,
//!   wherever the actual motion was of constant velocity or constant acceleration over the
//!   prediction; the scheduled time equals the logged edge time to the ns. The same track on a
//!   plain output switches at the first boundary at or after that time, never later than one
//!   cycle after it.
//! - A setpoint cam track and an actual-value cam track on a CiA 402 drive of the process
//!   image: each channel switches when the drive's actual position (the load) crosses the cam's
//!   edge, earlier by the lead, within the bound measured here (one encoder increment).
//! - The prediction does not allocate.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::{AxisIndex, Cell};
use tandem_runtime::exec::{Executive, OutputSwitch};
use tandem_testkit::counting::{arm, disarm};

tandem_testkit::counting_allocator!();

const T: i64 = 1_000_000;

/// A virtual modulo axis (100 mm) under an actual-value cam track of three cams, once on a
/// timestamped and once on a plain output, with 2.5 ms / 1 ms leads (Λ = 5 ms).
const ACTUAL_CELL: &str = r#"
[cell]
name = "timing"

[[nodes]]
name = "n"
cycle_us = 1000

[devices.dq]
node = "n"
kind = "sim_digital_output"
channels = 1
timestamped = true

[devices.dq_plain]
node = "n"
kind = "sim_digital_output"
channels = 1

[signals.act]
device = "dq"
channel = 1

[signals.act_plain]
device = "dq_plain"
channel = 1

[axes.x]
node = "n"
virtual = true

[axes.x.modulo]
length = 100.0

# The S7 delay model, two cycles: the actual value is the setpoint of two cycles before, its
# position, velocity and acceleration consistent (the truth the test measures against).
[axes.x.drive]
model = "delay"
delay = 0.002

[axes.x.dynamics]
max_velocity = 1000.0
max_acceleration = 1000.0
max_deceleration = 1000.0
max_jerk = 10000000.0
velocity = 200.0
acceleration = 100.0
deceleration = 100.0
jerk = 10000000.0
emergency_deceleration = 1000.0

[[cam_tracks]]
name = "act"
axis = "x"
position = "actual"
track_length = 100.0
on_compensation = 0.0025
off_compensation = 0.001
cams = [{ on = 10.0, off = 20.0 }, { on = 40.0, off = 45.0 }, { on = 70.0, off = 90.0 }]
output = "act"

[[cam_tracks]]
name = "act_plain"
axis = "x"
position = "actual"
track_length = 100.0
on_compensation = 0.0025
off_compensation = 0.001
cams = [{ on = 10.0, off = 20.0 }, { on = 40.0, off = 45.0 }, { on = 70.0, off = 90.0 }]
output = "act_plain"
"#;

/// Accelerates at 100 mm/s² to 200 mm/s (2 s), cruises, accelerates to 500 mm/s (3 s).
const ACTUAL_SCRIPT: &str = r#"
[sim]
duration = 9.0

[[at]]
t = 0.0
axis = "x"
instruction = "MC_Power"

[[at]]
t = 0.0
axis = "act"
instruction = "MC_CamTrack"
enable = true

[[at]]
t = 0.0
axis = "act_plain"
instruction = "MC_CamTrack"
enable = true

[[at]]
t = 0.01
axis = "x"
instruction = "MC_MoveVelocity"
velocity = 200.0

[[at]]
t = 4.0
axis = "x"
instruction = "MC_MoveVelocity"
velocity = 500.0
"#;

/// The CiA 402 servo of `config/servo.toml` (a linear slide, 10 mm leadscrew, 3:1 gear) under
/// a setpoint cam track of 25 mm with two cams, 2 ms / 1 ms leads, on a timestamped output.
const SERVO_CELL: &str = r#"
[cell]
name = "servo-timing"

[[nodes]]
name = "drives"
cycle_us = 1000

[devices.slide_servo]
node = "drives"
kind = "sim_servo"
increments_per_revolution = 1048576
rated_torque = 1.27
max_torque = 3000
inertia = 0.0001
viscous_friction = 0.0001
coulomb_friction = 0.02
kv = 100.0
velocity_gain = 0.1
velocity_integral_time = 0.01
quick_stop_deceleration = 2000.0
quick_stop_option = 2
following_error_window = 262144

[devices.dq]
node = "drives"
kind = "sim_digital_output"
channels = 1
timestamped = true

[signals.valve]
device = "dq"
channel = 1

[devices.dq_act]
node = "drives"
kind = "sim_digital_output"
channels = 1
timestamped = true

[signals.valve_act]
device = "dq_act"
channel = 1

[axes.slide]
node = "drives"
kind = "positioning"
motion_type = "linear"
encoder = "incremental"

[axes.slide.drive]
type = "cia402"
device = "slide_servo"
enable_timeout = 0.5

[axes.slide.mechanics]
load_gear = [3, 1]
leadscrew_pitch = 10.0

[axes.slide.dynamics]
max_velocity = 300.0
max_acceleration = 3000.0
max_deceleration = 3000.0
max_jerk = 60000.0
velocity = 200.0
acceleration = 2000.0
deceleration = 2000.0
jerk = 40000.0
emergency_deceleration = 3000.0

[[cam_tracks]]
name = "glue"
axis = "slide"
track_length = 25.0
on_compensation = 0.002
off_compensation = 0.001
cams = [{ on = 5.0, off = 12.0 }, { on = 17.0, off = 19.5 }]
output = "valve"

[[cam_tracks]]
name = "glue_act"
axis = "slide"
position = "actual"
track_length = 25.0
on_compensation = 0.002
off_compensation = 0.001
cams = [{ on = 5.0, off = 12.0 }, { on = 17.0, off = 19.5 }]
output = "valve_act"
"#;

const SERVO_SCRIPT: &str = r#"
[sim]
duration = 3.0

[[at]]
t = 0.0
axis = "slide"
instruction = "MC_Power"

[[at]]
t = 0.0
axis = "slide"
instruction = "MC_Home"
mode = 0
position = 0.0

[[at]]
t = 0.0
axis = "glue"
instruction = "MC_CamTrack"
enable = true

[[at]]
t = 0.0
axis = "glue_act"
instruction = "MC_CamTrack"
enable = true

[[at]]
t = 0.05
axis = "slide"
instruction = "MC_MoveAbsolute"
position = 480.0
"#;

/// One step's sample of the axis: time, actual position and velocity, setpoint acceleration.
#[derive(Copy, Clone, Debug)]
struct Sample {
    t: i64,
    p: f64,
    v: f64,
    a_set: f64,
}

/// An output edge the executive logged: the object, its time and level.
#[derive(Clone, Debug, PartialEq)]
struct Logged {
    object: String,
    t_ns: i64,
    on: bool,
}

struct Run {
    samples: Vec<Sample>,
    edges: Vec<Logged>,
    switches: Vec<OutputSwitch>,
}

/// `t=<s>.<9 digits>` as ns, exactly.
fn ns(text: &str) -> i64 {
    let t = text.strip_prefix("t=").unwrap();
    let (s, f) = t.split_once('.').unwrap();
    s.parse::<i64>().unwrap() * 1_000_000_000 + f.parse::<i64>().unwrap()
}

/// Runs `cell` with `script` to its end on one executive, sampling axis 0 every step.
fn run(cell: &Cell, script: &str) -> Run {
    let script = tandem_config::script::parse_cell("script.toml", script, cell).unwrap();
    let mut exec = Executive::new(cell, None).unwrap();
    let (mut samples, mut edges, mut switches, mut next) = (vec![], vec![], vec![], 0);
    let mut log = Vec::new();
    let mut t = 0;
    while t <= script.duration_ns {
        while let Some(e) = script.entries.get(next).filter(|e| e.t_ns <= t) {
            next += 1;
            let r = exec.apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, &mut log);
            assert!(r.unwrap().is_ok(), "{}", String::from_utf8_lossy(&log));
        }
        log.clear();
        exec.step(t, &mut log).unwrap();
        for line in String::from_utf8(log.clone()).unwrap().lines() {
            let w: Vec<&str> = line.split_whitespace().collect();
            if w.get(2) == Some(&"output") {
                edges.push(Logged {
                    object: w[1].to_string(),
                    t_ns: ns(w[0]),
                    on: w[3] == "ON",
                });
            }
        }
        let s = *exec.axis_status(AxisIndex(0)).unwrap();
        samples.push(Sample {
            t,
            p: s.actual_position_unwrapped,
            v: s.actual_velocity,
            a_set: s.acceleration,
        });
        exec.drain_output_switches(|s| switches.push(*s));
        t += T;
    }
    Run {
        samples,
        edges,
        switches,
    }
}

/// The actual position and velocity at `t` from the samples around it, with the acceleration
/// of the velocity's slope over that cycle: exact for constant velocity and constant
/// acceleration. `None` outside the samples.
fn actual_at(samples: &[Sample], t: i64) -> Option<(f64, f64)> {
    let k = samples.partition_point(|s| s.t <= t).checked_sub(1)?;
    let (a, b) = (samples.get(k)?, samples.get(k + 1)?);
    let acc = (b.v - a.v) / ((b.t - a.t) as f64 * 1e-9);
    let dt = (t - a.t) as f64 * 1e-9;
    Some((a.p + dt * (a.v + 0.5 * dt * acc), a.v + dt * acc))
}

/// Whether the setpoint acceleration is the same (within 1e-9) at every sample in
/// `[from, to]`: the motion there is of constant velocity or constant acceleration.
fn constant_acceleration(samples: &[Sample], from: i64, to: i64) -> Option<f64> {
    let mut it = samples.iter().filter(|s| (from..=to).contains(&s.t));
    let a = it.next()?.a_set;
    it.all(|s| (s.a_set - a).abs() <= 1e-9).then_some(a)
}

/// The time (s, signed) between `t` and the nearest instant the actual position is at one of
/// the cam edges `edges` (modulo `period`), by the velocity at `t`.
fn time_to_edge(samples: &[Sample], t: i64, edges: &[f64], period: f64) -> f64 {
    let (p, v) = actual_at(samples, t).unwrap();
    let x = p.rem_euclid(period);
    let d = edges
        .iter()
        .map(|e| {
            let d = x - e;
            d - period * (d / period).round()
        })
        .min_by(|a, b| a.abs().total_cmp(&b.abs()))
        .unwrap();
    d / v
}

/// The device of the signal named `signal`.
fn device(cell: &Cell, name: &str) -> usize {
    cell.devices.iter().position(|d| d.name == name).unwrap()
}

#[test]
fn an_actual_value_cam_switches_when_the_actual_position_is_at_the_cam_edge() {
    let cell = tandem_config::parse("cell.toml", ACTUAL_CELL).unwrap();
    let r = run(&cell, ACTUAL_SCRIPT);
    let look_ahead = 5 * T;
    let (on_lead, off_lead) = (2_500_000, 1_000_000);
    let dq = device(&cell, "dq");
    let logged: Vec<&Logged> = r.edges.iter().filter(|e| e.object == "act").collect();
    let switches: Vec<&OutputSwitch> = r.switches.iter().filter(|s| s.device == dq).collect();
    // Every edge switched, at exactly its logged time, none late.
    let end = r.samples.last().unwrap().t;
    let due: Vec<&&Logged> = logged.iter().filter(|e| e.t_ns < end).collect();
    assert_eq!(switches.len(), due.len());
    for (s, e) in switches.iter().zip(&due) {
        assert_eq!((s.time_ns, s.scheduled_ns, s.on), (e.t_ns, e.t_ns, e.on));
        assert!(!s.late, "{s:?}");
    }
    // Physical truth: at the switching time plus its lead the actual position is at the
    // cam's edge, where the motion over the prediction was of constant acceleration.
    let (mut cruise, mut accel, mut worst_ns) = (0, 0, 0.0f64);
    for s in &switches {
        let (lead, edges) = if s.on {
            (on_lead, [10.0, 40.0, 70.0])
        } else {
            (off_lead, [20.0, 45.0, 90.0])
        };
        let at = s.time_ns + lead;
        // The prediction of this edge used the samples from its step's cycle start; the
        // actual value is the setpoint of two cycles before (the delay model).
        let from = s.time_ns - look_ahead - 2 * T;
        let Some(a) = constant_acceleration(&r.samples, from - 2 * T, at + T) else {
            continue;
        };
        let err_ns = time_to_edge(&r.samples, at, &edges, 100.0) * 1e9;
        assert!(
            err_ns.abs() <= 1.0,
            "{s:?}: {err_ns} ns from the cam edge (a = {a})"
        );
        worst_ns = worst_ns.max(err_ns.abs());
        if a == 0.0 {
            cruise += 1;
        } else {
            accel += 1;
        }
    }
    println!(
        "actual cam, timestamped: {} switches; {cruise} at constant velocity and {accel} at \
         constant acceleration checked, worst {worst_ns:.3} ns from the actual crossing",
        switches.len()
    );
    assert!(cruise >= 60 && accel >= 40, "{cruise} {accel}");

    // The same track on a plain output: the same edges, each switched at the first boundary
    // at or after its time, never later than one cycle after it.
    let plain = device(&cell, "dq_plain");
    let logged_plain: Vec<(i64, bool)> = r
        .edges
        .iter()
        .filter(|e| e.object == "act_plain")
        .map(|e| (e.t_ns, e.on))
        .collect();
    let same: Vec<(i64, bool)> = logged.iter().map(|e| (e.t_ns, e.on)).collect();
    assert_eq!(logged_plain, same);
    let mut n = 0;
    for s in r.switches.iter().filter(|s| s.device == plain) {
        assert_eq!(s.time_ns % T, 0, "{s:?}");
        assert!(s.time_ns >= s.edge_ns, "before its time: {s:?}");
        assert!(s.time_ns < s.edge_ns + T, "a cycle or more late: {s:?}");
        assert_eq!(s.scheduled_ns, s.edge_ns);
        assert!(!s.late);
        n += 1;
    }
    assert!(n >= 150, "{n} plain switches");
}

/// For the servo run: the number of switches of `object` on `dq` checked at 200 mm/s and the
/// worst time (µs) between a switching time plus its lead and the load at the cam's edge.
fn servo_against_the_load(cell: &Cell, r: &Run, object: &str, dq: &str) -> (usize, f64) {
    let dq = device(cell, dq);
    let switches: Vec<&OutputSwitch> = r.switches.iter().filter(|s| s.device == dq).collect();
    let logged: Vec<(i64, bool)> = r
        .edges
        .iter()
        .filter(|e| e.object == object)
        .map(|e| (e.t_ns, e.on))
        .collect();
    assert_eq!(
        switches
            .iter()
            .map(|s| (s.time_ns, s.on))
            .collect::<Vec<_>>(),
        logged[..switches.len()]
    );
    // At the switching time plus its lead, the drive's actual position (the load) is at the
    // cam's edge; measured at constant velocity (200 mm/s) after the drive settled.
    let (mut n, mut worst_us) = (0, 0.0f64);
    for s in &switches {
        let (lead, edges) = if s.on {
            (2_000_000, [5.0, 17.0])
        } else {
            (1_000_000, [12.0, 19.5])
        };
        let at = s.time_ns + lead;
        if constant_acceleration(&r.samples, at - 100 * T, at + T) != Some(0.0) {
            continue;
        }
        let (_, v) = actual_at(&r.samples, at).unwrap();
        if (v - 200.0).abs() > 1.0 {
            continue;
        }
        let err_us = time_to_edge(&r.samples, at, &edges, 25.0) * 1e6;
        worst_us = worst_us.max(err_us.abs());
        n += 1;
    }
    (n, worst_us)
}

#[test]
fn a_setpoint_cam_on_a_cia402_drive_switches_when_the_load_passes_the_cam_edge() {
    let cell = tandem_config::parse("cell.toml", SERVO_CELL).unwrap();
    let r = run(&cell, SERVO_SCRIPT);
    let (n, worst_us) = servo_against_the_load(&cell, &r, "glue", "dq");
    println!(
        "setpoint cam on a CiA 402 drive: {n} switches at 200 mm/s, worst {worst_us:.3} µs \
         from the load's crossing"
    );
    assert!(n >= 20, "{n} switches checked");
    // Measured 0.016 µs: one encoder increment (10 mm / (3 · 2^20)) at 200 mm/s.
    assert!(worst_us <= 0.05, "{worst_us} µs");
}

/// The prediction and the output stage step without allocating: the actual-value cell for
/// 3 s, every object predicting over its look-ahead.
#[test]
fn switching_ahead_steps_without_allocating() {
    let cell = tandem_config::parse("cell.toml", ACTUAL_CELL).unwrap();
    let script = tandem_config::script::parse_cell("script.toml", ACTUAL_SCRIPT, &cell).unwrap();
    let mut exec = Executive::new(&cell, None).unwrap();
    let mut log = std::io::sink();
    let (mut next, mut allocations, mut switches) = (0, 0, 0);
    for k in 0..3000i64 {
        let t = k * T;
        while let Some(e) = script.entries.get(next).filter(|e| e.t_ns <= t) {
            next += 1;
            // Only allocations are counted here; the outcomes are checked above.
            let _ = exec.apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, &mut log);
        }
        arm();
        exec.step(t, &mut log).unwrap();
        exec.drain_output_switches(|_| switches += 1);
        exec.drain_io_notes(|_| {});
        exec.drain_job_notes(|_| {});
        allocations += disarm().0;
    }
    assert!(switches >= 40, "{switches} switches");
    assert_eq!(allocations, 0);
}

/// The same track on the drive's actual value: the actual position (the load) predicted from
/// the drive's actual position, velocity and acceleration.
#[test]
fn an_actual_value_cam_on_a_cia402_drive_switches_when_the_load_passes_the_cam_edge() {
    let cell = tandem_config::parse("cell.toml", SERVO_CELL).unwrap();
    let r = run(&cell, SERVO_SCRIPT);
    let (n, worst_us) = servo_against_the_load(&cell, &r, "glue_act", "dq_act");
    println!(
        "actual-value cam on a CiA 402 drive: {n} switches at 200 mm/s, worst {worst_us:.3} µs \
         from the load's crossing"
    );
    assert!(n >= 20, "{n} switches checked");
    // Measured 0.006 µs: within one encoder increment at 200 mm/s.
    assert!(worst_us <= 0.05, "{worst_us} µs");
}
