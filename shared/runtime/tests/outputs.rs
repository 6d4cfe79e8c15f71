//! The output stage of the process image: output cams and cam tracks driving simulated digital
//! outputs, against the edge times the executive logs for them.
//!
//! A rotary axis runs forward and back at several speeds for 12 s; a distance cam with on and
//! off compensation, a time cam and a cam track with compensations each drive one channel.
//! - Timestamped outputs switch at exactly the logged edge time (to the ns), none late: the
//!   objects that drive an output compute their edges ahead (over their look-ahead), so every
//!   edge is at least one cycle after the step that computed it and the StartTime is never in
//!   the past when its frame carries it.
//! - Plain outputs switch at the first boundary at or after that instant: never before it,
//!   less than one cycle after it, and a channel whose edges cancel within one write does not
//!   switch (an independent model of the boundaries gives the same switches).
//! - Edges closer than one cycle on a timestamped terminal: the first exact, the next at the
//!   following boundary, none lost.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::Cell;
use tandem_runtime::exec::{Executive, OutputSwitch, LOOK_AHEAD_CYCLES};

const T: i64 = 1_000_000;

const CELL: &str = r#"
[cell]
name = "outputs"

[[nodes]]
name = "n"
cycle_us = 1000

[devices.dq_dist]
node = "n"
kind = "sim_digital_output"
channels = 1
timestamped = true

[devices.dq_time]
node = "n"
kind = "sim_digital_output"
channels = 2
timestamped = true

[devices.dq_track]
node = "n"
kind = "sim_digital_output"
channels = 4
timestamped = true

[signals.dist]
device = "dq_dist"
channel = 1

[signals.time]
device = "dq_time"
channel = 2

[signals.track]
device = "dq_track"
channel = 3

[axes.x]
node = "n"
virtual = true

[axes.x.modulo]
length = 360.0

[axes.x.dynamics]
max_velocity = 3000.0
max_acceleration = 20000.0
max_deceleration = 20000.0
max_jerk = 400000.0
velocity = 500.0
acceleration = 5000.0
deceleration = 5000.0
jerk = 100000.0
emergency_deceleration = 20000.0

[[output_cams]]
name = "dist_cam"
axis = "x"
on_compensation = 0.003
off_compensation = 0.0015
output = "dist"

[[output_cams]]
name = "time_cam"
axis = "x"
type = "time"
on_compensation = 0.001
off_compensation = 0.0005
output = "time"

[[cam_tracks]]
name = "glue"
axis = "x"
track_length = 90.0
on_compensation = 0.002
off_compensation = 0.0005
cams = [{ on = 10.0, off = 30.0 }, { on = 50.0, off = 58.0 }]
output = "track"
"#;

const SCRIPT: &str = r#"
[sim]
duration = 12.0

[[at]]
t = 0.0
axis = "x"
instruction = "MC_Power"

[[at]]
t = 0.0
axis = "dist_cam"
instruction = "MC_OutputCam"
enable = true
on_position = 30.0
off_position = 120.0
direction = 3

[[at]]
t = 0.0
axis = "time_cam"
instruction = "MC_OutputCam"
enable = true
on_position = 200.0
duration = 0.02
direction = 3

[[at]]
t = 0.0
axis = "glue"
instruction = "MC_CamTrack"
enable = true

[[at]]
t = 0.05
axis = "x"
instruction = "MC_MoveVelocity"
velocity = 720.0

[[at]]
t = 3.0
axis = "x"
instruction = "MC_MoveVelocity"
velocity = -1100.0

[[at]]
t = 6.0
axis = "x"
instruction = "MC_MoveVelocity"
velocity = 1900.0

[[at]]
t = 8.5
axis = "x"
instruction = "MC_MoveRelative"
distance = 250.0

[[at]]
t = 9.5
axis = "x"
instruction = "MC_MoveVelocity"
velocity = -450.0

[[at]]
t = 11.5
axis = "x"
instruction = "MC_Halt"
"#;

/// An output edge the executive logged: the object, its time, the level, and the step that
/// computed it.
#[derive(Clone, Debug)]
struct Logged {
    object: String,
    t_ns: i64,
    on: bool,
    step: i64,
}

/// What a run gives: the logged edges, the devices' switches and the end time.
struct Run {
    edges: Vec<Logged>,
    switches: Vec<OutputSwitch>,
    end: i64,
}

/// `t=<s>.<9 digits>` as ns, exactly.
fn ns(text: &str) -> i64 {
    let t = text.strip_prefix("t=").unwrap();
    let (sign, t) = t.strip_prefix('-').map_or((1, t), |x| (-1, x));
    let (s, f) = t.split_once('.').unwrap();
    sign * (s.parse::<i64>().unwrap() * 1_000_000_000 + f.parse::<i64>().unwrap())
}

/// Runs `cell` with `script` on one executive, stepping past the script's end by the
/// look-ahead and two cycles, draining the switches every step.
fn run(cell: &Cell, script: &str) -> Run {
    let script = tandem_config::script::parse_cell("script.toml", script, cell).unwrap();
    let mut exec = Executive::new(cell, None).unwrap();
    let look_ahead = (0..cell.devices.len())
        .filter_map(|d| exec.output_device(d).map(|s| s.look_ahead_ns))
        .max()
        .unwrap();
    let end = script.duration_ns + look_ahead + 2 * T;
    let (mut edges, mut switches, mut next) = (Vec::new(), Vec::new(), 0);
    let mut log = Vec::new();
    let mut t = 0;
    while t <= end {
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
                    step: t,
                });
            }
        }
        exec.drain_output_switches(|s| switches.push(*s));
        t += T;
    }
    for d in 0..cell.devices.len() {
        let s = exec.output_device(d).unwrap();
        assert_eq!(
            (s.dropped, s.unreported),
            (0, 0),
            "{}",
            cell.devices[d].name
        );
    }
    Run {
        edges,
        switches,
        end,
    }
}

/// The device driven by object `name`.
fn device_of(cell: &Cell, name: &str) -> usize {
    let signal = cell
        .output_cams
        .iter()
        .find(|c| c.name == name)
        .map(|c| c.output)
        .or_else(|| {
            cell.cam_tracks
                .iter()
                .find(|c| c.name == name)
                .map(|c| c.output)
        })
        .flatten()
        .unwrap();
    cell.signals[signal.0].device.0
}

/// The logged edges of each object with the device it drives, due at least two cycles before
/// `end`.
fn per_device(cell: &Cell, r: &Run) -> Vec<(usize, Vec<Logged>)> {
    ["dist_cam", "time_cam", "glue"]
        .iter()
        .map(|name| {
            let edges = r
                .edges
                .iter()
                .filter(|e| e.object == *name && e.t_ns <= r.end - 2 * T)
                .cloned()
                .collect();
            (device_of(cell, name), edges)
        })
        .collect()
}

#[test]
fn timestamped_outputs_switch_at_the_edge_times_to_the_ns() {
    let cell = tandem_config::parse("cell.toml", CELL).unwrap();
    let r = run(&cell, SCRIPT);
    // 2 cycles plus the largest compensation (3 ms), in cycles.
    let look_ahead = (LOOK_AHEAD_CYCLES + 3) * T;
    let mut total = 0;
    let mut first_boundary = 0;
    for (device, edges) in per_device(&cell, &r) {
        let switches: Vec<&OutputSwitch> =
            r.switches.iter().filter(|s| s.device == device).collect();
        assert!(edges.len() >= 40, "{} edges on {device}", edges.len());
        assert_eq!(switches.len(), edges.len(), "device {device}");
        for (s, e) in switches.iter().zip(&edges) {
            assert_eq!(s.edge_ns, e.t_ns, "{e:?} {s:?}");
            assert_eq!(s.on, e.on, "{e:?} {s:?}");
            // The switching time is the edge time the object reported, to the ns.
            assert_eq!(s.scheduled_ns, e.t_ns, "{e:?} {s:?}");
            assert_eq!(
                s.time_ns, e.t_ns,
                "switched at the edge's time: {e:?} {s:?}"
            );
            assert!(!s.late, "{s:?}");
            // Computed ahead: at or after the boundary after the step that computed it.
            assert!(e.t_ns >= e.step + T, "an edge in the past: {e:?}");
            // Written at a boundary after the step that computed the edge, never with a
            // StartTime in the past.
            assert!(s.written_ns >= e.step + T, "{e:?} {s:?}");
            assert_eq!(s.written_ns % T, 0);
            assert!(s.written_ns <= s.scheduled_ns, "{s:?}");
            first_boundary += usize::from(e.t_ns < e.step + 2 * T);
        }
        total += edges.len();
    }
    println!(
        "timestamped: {total} edges exact, {first_boundary} due before the second boundary \
         after their step"
    );
    assert!(total >= 400, "{total} edges");
    // The compensations put edges as early as they can be written (within the cycle after
    // the first boundary): the tightest case is covered.
    assert!(
        first_boundary >= 50,
        "{first_boundary} edges due within a cycle of the first boundary"
    );
    // The look-ahead every device of the node reports.
    let exec = Executive::new(&cell, None).unwrap();
    for d in 0..cell.devices.len() {
        assert_eq!(exec.output_device(d).unwrap().look_ahead_ns, look_ahead);
    }
}

/// The independent model of a plain output: each edge written at the first boundary at or
/// after its time; per boundary, a channel switches to the level of its last edge if that
/// differs from its level before. (time, on, edge time) per switch.
fn plain_model(edges: &[Logged]) -> Vec<(i64, bool, i64)> {
    let mut out = Vec::new();
    let mut level = false;
    let mut k = 0;
    while k < edges.len() {
        let b = (edges[k].t_ns + T - 1).div_euclid(T) * T;
        let mut last = &edges[k];
        while k < edges.len() && edges[k].t_ns <= b {
            last = &edges[k];
            k += 1;
        }
        if last.on != level {
            level = last.on;
            out.push((b, last.on, last.t_ns));
        }
    }
    out
}

#[test]
fn plain_outputs_switch_within_one_cycle_after_the_edge_and_never_before() {
    let src = CELL.replace("timestamped = true", "timestamped = false");
    let cell = tandem_config::parse("cell.toml", &src).unwrap();
    let r = run(&cell, SCRIPT);
    let mut total = 0;
    for (device, edges) in per_device(&cell, &r) {
        let switches: Vec<&OutputSwitch> =
            r.switches.iter().filter(|s| s.device == device).collect();
        for s in &switches {
            assert_eq!(s.time_ns % T, 0, "at a boundary: {s:?}");
            assert!(s.time_ns >= s.scheduled_ns, "never before its time: {s:?}");
            assert!(s.time_ns < s.scheduled_ns + T, "within one cycle: {s:?}");
            assert_eq!(s.scheduled_ns, s.edge_ns, "due at the edge's time: {s:?}");
            assert_eq!(s.written_ns, s.time_ns);
            assert!(!s.late);
        }
        let steps: Vec<i64> = edges.iter().map(|e| e.step).collect();
        for (s, step) in switches.iter().zip(steps) {
            assert!(
                s.written_ns >= step + T,
                "written after the step that computed it"
            );
        }
        let got: Vec<(i64, bool, i64)> = switches
            .iter()
            .map(|s| (s.time_ns, s.on, s.edge_ns))
            .collect();
        assert_eq!(got, plain_model(&edges), "device {device}");
        assert!(got.len() >= 40);
        total += got.len();
    }
    println!("plain: {total} switches, each within [0, 1 cycle) after its instant");
    assert!(total >= 400, "{total} switches");
}

/// A cam track of cams narrower than a cycle at speed (0.5° at 1900°/s: 0.26 ms), with equal
/// on and off compensations (the pulses keep their width).
fn narrow() -> String {
    CELL.replace("on_compensation = 0.002\n", "on_compensation = 0.0005\n")
        .replace(
        "cams = [{ on = 10.0, off = 30.0 }, { on = 50.0, off = 58.0 }]",
        "cams = [{ on = 10.0, off = 30.0 }, { on = 50.0, off = 50.5 }, { on = 70.0, off = 70.4 }]",
        )
}

#[test]
fn edges_closer_than_a_cycle_switch_at_the_next_boundary_on_a_timestamped_output() {
    let cell = tandem_config::parse("cell.toml", &narrow()).unwrap();
    let r = run(&cell, SCRIPT);
    let track = device_of(&cell, "glue");
    let (_, edges) = per_device(&cell, &r)
        .into_iter()
        .find(|(d, _)| *d == track)
        .unwrap();
    let switches: Vec<&OutputSwitch> = r.switches.iter().filter(|s| s.device == track).collect();
    // None lost: one switch per edge, in order.
    assert_eq!(switches.len(), edges.len());
    // The terminal's model, independently: one task per frame; a task is written at the
    // first boundary after the step that computed it at which the terminal holds none, and
    // switches at its instant if that is not before the boundary, else at once.
    let mut free = i64::MIN;
    let mut late = 0;
    for (s, e) in switches.iter().zip(&edges) {
        assert_eq!((s.edge_ns, s.on), (e.t_ns, e.on));
        let at = e.t_ns;
        let w = free.max(e.step + T);
        let (time, next_free) = if at > w {
            (at, (at + T - 1).div_euclid(T) * T)
        } else {
            (w, w + T)
        };
        free = next_free;
        assert_eq!(s.time_ns, time, "{e:?} {s:?}");
        assert_eq!(s.late, time > at);
        if s.late {
            // A second event within one cycle: at the next boundary, less than a cycle late.
            late += 1;
            assert!(s.time_ns < s.scheduled_ns + T);
        }
    }
    // Each narrow pulse whose edges fall between the same two boundaries has its second
    // edge late, and only those.
    let narrow_pairs = edges
        .windows(2)
        .filter(|w| w[1].t_ns - w[0].t_ns < T)
        .count();
    println!(
        "narrow, timestamped: {} edges, {late} at the next boundary, {narrow_pairs} close pairs",
        edges.len()
    );
    assert!(late >= 20, "{late} late switches");
    assert!(
        late <= narrow_pairs,
        "{late} late, {narrow_pairs} close pairs"
    );
}

#[test]
fn pulses_narrower_than_a_cycle_vanish_on_a_plain_output() {
    let src = narrow().replace("timestamped = true", "timestamped = false");
    let cell = tandem_config::parse("cell.toml", &src).unwrap();
    let r = run(&cell, SCRIPT);
    let track = device_of(&cell, "glue");
    let (_, edges) = per_device(&cell, &r)
        .into_iter()
        .find(|(d, _)| *d == track)
        .unwrap();
    let got: Vec<(i64, bool, i64)> = r
        .switches
        .iter()
        .filter(|s| s.device == track)
        .map(|s| (s.time_ns, s.on, s.edge_ns))
        .collect();
    let want = plain_model(&edges);
    assert_eq!(got, want);
    println!(
        "narrow, plain: {} edges, {} switches",
        edges.len(),
        got.len()
    );
    // The last one written wins: some pulses vanished.
    assert!(
        edges.len() >= got.len() + 20,
        "{} edges, {} switches",
        edges.len(),
        got.len()
    );
}

#[test]
fn a_node_runs_the_output_devices_of_its_own_process_image() {
    let src = CELL.replacen(
        "[devices.dq_dist]",
        "[[nodes]]\nname = \"m\"\ncycle_us = 2000\n\n[devices.far]\nnode = \"m\"\nkind = \"sim_digital_output\"\nchannels = 1\n\n[devices.dq_dist]",
        1,
    );
    let cell = tandem_config::parse("cell.toml", &src).unwrap();
    let far = cell.devices.iter().position(|d| d.name == "far").unwrap();
    let dist = device_of(&cell, "dist_cam");
    let n = Executive::new(&cell, cell.node("n")).unwrap();
    assert!(n.output_device(dist).is_some() && n.output_device(far).is_none());
    let m = Executive::new(&cell, cell.node("m")).unwrap();
    assert!(m.output_device(dist).is_none());
    // Node m has no object driving an output: 2 cycles of its own.
    assert_eq!(m.output_device(far).unwrap().look_ahead_ns, 2 * 2 * T);
    let all = Executive::new(&cell, None).unwrap();
    assert!(all.output_device(dist).is_some() && all.output_device(far).is_some());
}
