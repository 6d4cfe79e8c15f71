//! The `tandem` CLI end to end: the README's main command on the bundled example, determinism,
//! and errors that name file, line and key.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn run(args: &[&str]) -> (u8, String, String) {
    let mut out = Vec::new();
    let mut err = Vec::new();
    let mut argv = vec!["tandem".into()];
    argv.extend(args.iter().map(|s| std::ffi::OsString::from(*s)));
    let code = tandem_cli::run(argv, &mut out, &mut err);
    let code = if code == std::process::ExitCode::SUCCESS {
        0
    } else {
        1
    };
    (
        code,
        String::from_utf8(out).unwrap(),
        String::from_utf8(err).unwrap(),
    )
}

#[test]
fn example_runs_and_is_byte_identical_twice() {
    let dir = std::env::temp_dir().join(format!("tandem-sim-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cell = root().join("config/example-cell.toml");
    let script = root().join("config/example-script.toml");
    let mut traces = Vec::new();
    let mut logs = Vec::new();
    for i in 0..2 {
        let trace = dir.join(format!("trace{i}.csv"));
        let (code, out, err) = run(&[
            "sim",
            cell.to_str().unwrap(),
            "--script",
            script.to_str().unwrap(),
            "--trace",
            trace.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        traces.push(std::fs::read(&trace).unwrap());
        logs.push(out);
    }
    assert_eq!(
        traces[0], traces[1],
        "two runs must give byte-identical traces"
    );
    assert_eq!(logs[0], logs[1]);
    let text = String::from_utf8(traces[0].clone()).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    assert!(header.starts_with("time_s,conveyor.state,conveyor.position"));
    assert_eq!(header.split(',').count(), 1 + 3 * 13);
    // 6 s at 1 ms: 6001 rows, every row complete.
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 6001);
    assert!(rows.iter().all(|r| r.split(',').count() == 1 + 3 * 13));
    // The story of the script, as logged.
    let log = &logs[0];
    assert!(log.contains("slide MC_MoveAbsolute rejected: 16#80F2 NotHomed"));
    assert!(log.contains("slide MC_Home job 2: Done"));
    assert!(log.contains("slide MC_MoveAbsolute job 3: Done"));
    assert!(log.contains("conveyor MC_Stop job 3: Done"));
    // The slide ends at 300 + 5 (superimposed), the table halted somewhere in its move.
    let last: Vec<&str> = rows[rows.len() - 1].split(',').collect();
    let slide_pos: f64 = last[1 + 13 + 1].parse().unwrap();
    assert!((slide_pos - 305.0).abs() < 1e-9, "{slide_pos}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn check_reports_file_line_and_key() {
    let dir = std::env::temp_dir().join(format!("tandem-check-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let src = std::fs::read_to_string(root().join("config/example-cell.toml")).unwrap();
    let bad = src.replacen("max_velocity = 500.0", "max_velocity = -5.0", 1);
    let path = dir.join("bad.toml");
    std::fs::write(&path, bad).unwrap();
    let (code, _, err) = run(&["check", path.to_str().unwrap()]);
    assert_ne!(code, 0);
    let line = src
        .lines()
        .position(|l| l.starts_with("max_velocity = 500.0"))
        .unwrap()
        + 1;
    assert!(
        err.contains(&format!(
            "bad.toml:{line}: axes.slide.dynamics.max_velocity: must be a positive number"
        )),
        "{err}"
    );
    let (code, out, _) = run(&[
        "check",
        root().join("config/example-cell.toml").to_str().unwrap(),
    ]);
    assert_eq!(code, 0);
    assert!(out.contains("is valid"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn flying_saw_is_synchronous_at_every_cut() {
    let dir = std::env::temp_dir().join(format!("tandem-saw-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let trace = dir.join("saw.csv");
    let (code, log, err) = run(&[
        "sim",
        root().join("config/flying-saw.toml").to_str().unwrap(),
        "--script",
        root()
            .join("config/flying-saw-script.toml")
            .to_str()
            .unwrap(),
        "--trace",
        trace.to_str().unwrap(),
        "--strict",
    ]);
    assert_eq!(code, 0, "{err}\n{log}");
    assert_eq!(log.matches(": InSync").count(), 3, "{log}");
    let text = std::fs::read_to_string(&trace).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (t, x, y, job) = (
        col("time_s"),
        col("material.position"),
        col("saw.position"),
        col("saw.job"),
    );
    let mut synchronous_rows = 0;
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let xv: f64 = f[x].parse().unwrap();
        let yv: f64 = f[y].parse().unwrap();
        let tv: f64 = f[t].parse().unwrap();
        // While MC_GearInPos runs past its sync position the saw is 100 + (x - cut) exactly.
        for cut in [1000.0, 2000.0, 3000.0] {
            if f[job] == "MC_GearInPos" && xv >= cut && xv < cut + 150.0 {
                assert!(
                    (yv - (100.0 + xv - cut)).abs() < 1e-9,
                    "t {tv}: saw {yv}, material {xv}"
                );
                synchronous_rows += 1;
            }
        }
    }
    assert!(synchronous_rows >= 3 * 300, "{synchronous_rows}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_follower_gears_to_an_external_encoder() {
    let dir = std::env::temp_dir().join(format!("tandem-enc-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cell = dir.join("cell.toml");
    std::fs::write(
        &cell,
        r#"
[cell]
name = "encoder-test"

[[nodes]]
name = "n"
cycle_us = 1000

[encoders.wheel]
node = "n"
source = "profile"
profile = [[0.0, 0.0], [0.5, 200.0], [3.0, 200.0], [3.5, 50.0]]

[encoders.wheel.extrapolation]
velocity_t1 = 0.002
following_time = 0.002

[axes.knife]
node = "n"
kind = "synchronous"
virtual = true

[axes.knife.leaders]
wheel = "actual"

[axes.knife.dynamics]
max_velocity = 2000.0
max_acceleration = 20000.0
max_deceleration = 20000.0
max_jerk = 400000.0
velocity = 500.0
acceleration = 5000.0
deceleration = 5000.0
jerk = 100000.0
emergency_deceleration = 40000.0
"#,
    )
    .unwrap();
    let script = dir.join("script.toml");
    std::fs::write(
        &script,
        r#"
[sim]
duration = 4.0

[[at]]
t = 0.0
axis = "wheel"
instruction = "MC_Power"

[[at]]
t = 0.0
axis = "knife"
instruction = "MC_Power"

[[at]]
t = 0.6
axis = "knife"
instruction = "MC_GearIn"
master = "wheel"
ratio_numerator = 1
ratio_denominator = 2
"#,
    )
    .unwrap();
    let trace = dir.join("trace.csv");
    let (code, log, err) = run(&[
        "sim",
        cell.to_str().unwrap(),
        "--script",
        script.to_str().unwrap(),
        "--trace",
        trace.to_str().unwrap(),
        "--strict",
    ]);
    assert_eq!(code, 0, "{err}\n{log}");
    assert!(log.contains("knife MC_GearIn job 2: InGear"), "{log}");
    let text = std::fs::read_to_string(&trace).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (x, y, job) = (
        col("wheel.extrapolated_position"),
        col("knife.position"),
        col("knife.job"),
    );
    let mut offset = None;
    let mut rows = 0;
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let (xv, yv): (f64, f64) = (f[x].parse().unwrap(), f[y].parse().unwrap());
        // From the first synchronous row on: knife = offset + x / 2 exactly.
        if f[job] == "MC_GearIn" && log.contains("InGear") {
            rows += 1;
            if rows > 200 {
                let o = *offset.get_or_insert(yv - 0.5 * xv);
                assert!(
                    (yv - (o + 0.5 * xv)).abs() < 1e-9,
                    "{yv} vs {}",
                    o + 0.5 * xv
                );
            }
        }
    }
    assert!(rows > 2000);
    std::fs::remove_dir_all(&dir).ok();
}

/// The cross cutter's cam, written out independently: 45 u on 0..50, the 7th-degree transition
/// on 50..450, 315 + 45 u on 450..500.
fn cut_cam(x: f64) -> f64 {
    if x <= 50.0 {
        0.9 * x
    } else if x <= 450.0 {
        let u = (x - 50.0) / 400.0;
        let s = u.powi(4) * (35.0 - 84.0 * u + 70.0 * u * u - 20.0 * u.powi(3));
        45.0 + 360.0 * u - 90.0 * s
    } else {
        315.0 + 0.9 * (x - 450.0)
    }
}

#[test]
fn cross_cutter_follows_its_cam_exactly_through_a_speed_change() {
    let dir = std::env::temp_dir().join(format!("tandem-cut-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let trace = dir.join("cut.csv");
    let (code, log, err) = run(&[
        "sim",
        root().join("config/cross-cutter.toml").to_str().unwrap(),
        "--script",
        root()
            .join("config/cross-cutter-script.toml")
            .to_str()
            .unwrap(),
        "--trace",
        trace.to_str().unwrap(),
        "--strict",
    ]);
    assert_eq!(code, 0, "{err}\n{log}");
    assert!(log.contains("knife MC_CamIn job 2: InSync"));
    let text = std::fs::read_to_string(&trace).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (x, y, v) = (
        col("web.position"),
        col("knife.position"),
        col("knife.velocity"),
    );
    let mut rows = 0;
    let mut ends = 0;
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let xv: f64 = f[x].parse().unwrap();
        let yv: f64 = f[y].parse().unwrap();
        if xv >= 600.0 {
            // Knife angle (modulo 360) = cam of the web position since the first cut.
            let expect = cut_cam((xv - 600.0).rem_euclid(500.0));
            let d = (yv - expect).rem_euclid(360.0);
            assert!(d.min(360.0 - d) < 1e-9, "web {xv}: knife {yv} vs {expect}");
            rows += 1;
        }
        let vv: f64 = f[v].parse().unwrap();
        assert!(vv >= -1e-9, "the drum never turns back");
    }
    ends += log.matches("EndOfProfile").count();
    assert!(rows > 4000, "{rows}");
    assert!(ends >= 9, "{ends}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_cam_is_interpolated_again_at_run_time_only_when_no_job_uses_it() {
    let dir = std::env::temp_dir().join(format!("tandem-icam-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let src = std::fs::read_to_string(root().join("config/cross-cutter.toml")).unwrap();
    // A second cam: 600 mm sheets (a line, for the test).
    let cell = dir.join("cell.toml");
    std::fs::write(
        &cell,
        format!("{src}\n[cams.spare]\ninterpolation = \"linear\"\npoints = [[0.0, 0.0], [600.0, 360.0]]\n"),
    )
    .unwrap();
    let script = dir.join("script.toml");
    let base = std::fs::read_to_string(root().join("config/cross-cutter-script.toml")).unwrap();
    std::fs::write(
        &script,
        format!(
            "{base}\n[[at]]\nt = 2.0\naxis = \"cut\"\ninstruction = \"MC_InterpolateCam\"\n\n[[at]]\nt = 2.0\naxis = \"spare\"\ninstruction = \"MC_InterpolateCam\"\nfrom = \"cut\"\n"
        ),
    )
    .unwrap();
    let trace = dir.join("t.csv");
    let (code, log, err) = run(&[
        "sim",
        cell.to_str().unwrap(),
        "--script",
        script.to_str().unwrap(),
        "--trace",
        trace.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    // The running job holds `cut`: refused. `spare` is free: replaced by cut's definition.
    assert!(
        log.contains("cut MC_InterpolateCam rejected: 16#80AB"),
        "{log}"
    );
    assert!(log.contains("spare MC_InterpolateCam: Done"), "{log}");
    std::fs::remove_dir_all(&dir).ok();
}

// ---------------------------------------------------------------------------------------------
// Output cams, cam tracks and measuring inputs
// ---------------------------------------------------------------------------------------------

/// A one-axis cell (node 1 ms, virtual axis `x`) plus `extra` (modulo table, objects).
fn one_axis_cell(extra: &str) -> String {
    format!(
        r#"[cell]
name = "objects"

[[nodes]]
name = "n"
cycle_us = 1000

[axes.x]
node = "n"
virtual = true

[axes.x.dynamics]
max_velocity = 1000.0
max_acceleration = 4000.0
max_deceleration = 4000.0
max_jerk = 40000.0
velocity = 100.0
acceleration = 1000.0
deceleration = 1000.0
jerk = 10000.0
emergency_deceleration = 8000.0
{extra}"#
    )
}

/// Runs a cell and a script given as text; returns the log and the trace.
fn sim_text(tag: &str, cell: &str, script: &str) -> (String, String) {
    let dir = std::env::temp_dir().join(format!("tandem-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (c, s, t) = (
        dir.join("cell.toml"),
        dir.join("script.toml"),
        dir.join("t.csv"),
    );
    std::fs::write(&c, cell).unwrap();
    std::fs::write(&s, script).unwrap();
    let (code, log, err) = run(&[
        "sim",
        c.to_str().unwrap(),
        "--script",
        s.to_str().unwrap(),
        "--trace",
        t.to_str().unwrap(),
        "--strict",
    ]);
    assert_eq!(code, 0, "{err}\n{log}");
    let trace = std::fs::read_to_string(&t).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    (log, trace)
}

/// The trace as a header and rows of fields.
fn table(trace: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut lines = trace.lines();
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (header, rows)
}

fn ns(s: &str) -> i64 {
    let (a, b) = s.split_once('.').unwrap();
    a.parse::<i64>().unwrap() * 1_000_000_000 + b.parse::<i64>().unwrap()
}

/// Times (ns) and values of the log lines `t=<time> <what>`.
fn log_times(log: &str, what: &str) -> Vec<i64> {
    log.lines()
        .filter(|l| l.ends_with(what) || l.contains(&format!(" {what} ")))
        .filter_map(|l| l.strip_prefix("t=")?.split_once(' ').map(|(t, _)| ns(t)))
        .collect()
}

#[test]
fn distance_cams_switch_at_the_exact_crossing_ns() {
    let cell = one_axis_cell(
        r#"
[[output_cams]]
name = "cam"
axis = "x"

[[output_cams]]
name = "early"
axis = "x"
on_compensation = 0.0005
off_compensation = 0.00025
"#,
    );
    let script = r#"
[sim]
duration = 4.0

[[at]]
t = 0.0
axis = "x"
instruction = "MC_Power"

[[at]]
t = 0.0
axis = "cam"
instruction = "MC_OutputCam"
on_position = 150.3
off_position = 250.7
direction = 1

[[at]]
t = 0.0
axis = "early"
instruction = "MC_OutputCam"
on_position = 150.3
off_position = 250.7

[[at]]
t = 0.1
axis = "x"
instruction = "MC_MoveVelocity"
velocity = 100.0
"#;
    let (log, trace) = sim_text("ocam", &cell, script);
    let (h, rows) = table(&trace);
    let col = |n: &str| h.iter().position(|x| x == n).unwrap();
    let (t, p, v, a) = (
        col("time_s"),
        col("x.position"),
        col("x.velocity"),
        col("x.acceleration"),
    );
    // A row at constant velocity before the cam: p(t) = p_a + 100 (t - t_a) from there on.
    let r = rows
        .iter()
        .find(|r| r[v] == "100" && r[a] == "0")
        .expect("constant velocity");
    let (t_a, p_a) = (ns(&r[t]), r[p].parse::<f64>().unwrap());
    assert!(p_a < 150.0, "{p_a}");
    let at = |x: f64| t_a + ((x - p_a) / 100.0 * 1e9).round() as i64;
    let on = log_times(&log, "cam output ON");
    let off = log_times(&log, "cam output OFF");
    assert_eq!(on, vec![at(150.3)], "{log}");
    assert_eq!(off, vec![at(250.7)], "{log}");
    // Compensations lead the edges by exactly their times.
    assert_eq!(
        log_times(&log, "early output ON"),
        vec![at(150.3) - 500_000]
    );
    assert_eq!(
        log_times(&log, "early output OFF"),
        vec![at(250.7) - 250_000]
    );
    // The trace shows the output and the last edge time.
    let (out, last) = (col("cam.output"), col("cam.last_edge_s"));
    let end = rows.last().unwrap();
    assert_eq!(end[out], "0");
    assert_eq!(ns(&end[last]), at(250.7));
    let during = rows
        .iter()
        .find(|r| ns(&r[t]) > at(150.3) && ns(&r[t]) < at(250.7))
        .unwrap();
    assert_eq!(during[out], "1");
    assert_eq!(ns(&during[last]), at(150.3));
}

#[test]
fn cyclic_measuring_on_a_modulo_axis_reports_the_mark_within_1e_9() {
    // 1 unit/s: the ns quantization of edge times is worth at most 5e-10.
    let cell = one_axis_cell(
        r#"
[axes.x.modulo]
length = 2.0

[[measuring_inputs]]
name = "mark"
axis = "x"
correction_time = 0.0003

[measuring_inputs.sensor]
position = 0.7
width = 0.1
dead_time = 0.0003
seed = 3

[[measuring_inputs]]
name = "probe"
axis = "x"
"#,
    );
    let script = r#"
[sim]
duration = 11.0

[[at]]
t = 0.0
axis = "x"
instruction = "MC_Power"

[[at]]
t = 0.0
axis = "mark"
instruction = "MC_MeasuringInputCyclic"
mode = 2

[[at]]
t = 0.0
axis = "probe"
instruction = "MC_MeasuringInput"
mode = 1

[[at]]
t = 0.1
axis = "x"
instruction = "MC_MoveVelocity"
velocity = 1.0

[[at]]
t = 5.2345
axis = "probe"
instruction = "InputEdge"
rising = false
"#;
    let (log, trace) = sim_text("meas", &cell, script);
    let values = |what: &str| -> Vec<f64> {
        log.lines()
            .filter(|l| l.contains(what))
            .map(|l| {
                let v = l.split(" = ").nth(1).unwrap();
                v.split(' ').next().unwrap().parse().unwrap()
            })
            .collect()
    };
    let mv1 = values("mark MeasuredValue1");
    let mv2 = values("mark MeasuredValue2");
    // Marks at 0.7 every 2 s from about 0.8 s: 6 in 11 s.
    assert_eq!(mv1.len(), 6, "{log}");
    assert_eq!(mv2.len(), 6, "{log}");
    for x in &mv1 {
        assert!((x - 0.7).abs() < 1e-9, "{x}");
    }
    for x in &mv2 {
        assert!((x - 0.8).abs() < 1e-9, "{x}");
    }
    let (h, rows) = table(&trace);
    let col = |n: &str| h.iter().position(|x| x == n).unwrap();
    let end = rows.last().unwrap();
    assert_eq!(end[col("mark.counter1")], "6");
    assert_eq!(end[col("mark.counter2")], "6");
    assert_eq!(end[col("mark.lost_edge_counter1")], "0");
    assert_eq!(end[col("mark.state")], "WAITING_FOR_TRIGGER");
    // The scripted edge: the actual position at 5.2345 s exactly (constant velocity there).
    let probe = values("probe MeasuredValue1");
    assert_eq!(probe.len(), 1, "{log}");
    assert!(log.contains("t=5.234500000 probe MeasuredValue1"), "{log}");
    assert!(log.contains("probe MC_MeasuringInput job 1: Done"), "{log}");
    let (t, ap) = (col("time_s"), col("x.actual_position"));
    let r0 = rows.iter().position(|r| r[t] == "5.234000000").unwrap();
    let (p0, p1): (f64, f64) = (
        rows[r0][ap].parse().unwrap(),
        rows[r0 + 1][ap].parse().unwrap(),
    );
    assert!(
        (probe[0] - (p0 + p1) / 2.0).abs() < 1e-9,
        "{probe:?} {p0} {p1}"
    );
    assert_eq!(end[col("probe.state")], "TRIGGER_OCCURRED");
}

#[test]
fn object_scripts_name_unknown_objects_and_parameters() {
    let dir = std::env::temp_dir().join(format!("tandem-objscript-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cell = dir.join("cell.toml");
    std::fs::write(
        &cell,
        one_axis_cell("\n[[output_cams]]\nname = \"cam\"\naxis = \"x\"\n"),
    )
    .unwrap();
    let script = dir.join("s.toml");
    let trace = dir.join("t.csv");
    for (body, want) in [
        (
            "axis = \"nope\"\ninstruction = \"MC_OutputCam\"",
            "MC_OutputCam: unknown output cam `nope`; the cell has: cam",
        ),
        (
            "axis = \"cam\"\ninstruction = \"MC_OutputCam\"\non = 1.0",
            "MC_OutputCam: unknown parameter `on`",
        ),
        (
            "axis = \"cam\"\ninstruction = \"MC_CamTrack\"",
            "MC_CamTrack: unknown cam track `cam`",
        ),
    ] {
        std::fs::write(
            &script,
            format!("[sim]\nduration = 0.1\n\n[[at]]\nt = 0.0\n{body}\n"),
        )
        .unwrap();
        let (code, _, err) = run(&[
            "sim",
            cell.to_str().unwrap(),
            "--script",
            script.to_str().unwrap(),
            "--trace",
            trace.to_str().unwrap(),
        ]);
        assert_ne!(code, 0);
        assert!(err.contains("s.toml:4: at[0]: "), "{err}");
        assert!(err.contains(want), "{err}");
    }
    // A bad code is an ErrorID at run time, like an FB's.
    std::fs::write(
        &script,
        "[sim]\nduration = 0.1\n\n[[at]]\nt = 0.0\naxis = \"cam\"\ninstruction = \"MC_OutputCam\"\ndirection = 4\n",
    )
    .unwrap();
    let (code, log, err) = run(&[
        "sim",
        cell.to_str().unwrap(),
        "--script",
        script.to_str().unwrap(),
        "--trace",
        trace.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(log.contains("cam MC_OutputCam rejected: 16#8007"), "{log}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn print_mark_registration_converges_to_the_register_target() {
    let dir = std::env::temp_dir().join(format!("tandem-mark-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let trace = dir.join("marks.csv");
    let (code, log, err) = run(&[
        "sim",
        root()
            .join("config/print-mark-registration.toml")
            .to_str()
            .unwrap(),
        "--script",
        root()
            .join("config/print-mark-registration-script.toml")
            .to_str()
            .unwrap(),
        "--trace",
        trace.to_str().unwrap(),
        "--strict",
    ]);
    assert_eq!(code, 0, "{err}\n{log}");
    let values: Vec<f64> = log
        .lines()
        .filter(|l| l.contains("mark MeasuredValue1 = "))
        .map(|l| {
            l.split(" = ")
                .nth(1)
                .unwrap()
                .split(' ')
                .next()
                .unwrap()
                .parse()
                .unwrap()
        })
        .collect();
    // 1000 mm/s, a 400 mm repeat, 4.85 s of measuring: 11 marks.
    assert_eq!(values.len(), 11, "{log}");
    // The first mark: the cylinder is 8 mm out of register (the sensor's dead time is
    // corrected; its jitter, ±1 µs at 1000 mm/s, remains).
    assert!((values[0] - 131.4).abs() <= 1.0e-3, "{}", values[0]);
    // Each mark corrects 80 % of the error: 8 * 0.2^k, plus the jitter it passes on.
    for (k, x) in values.iter().enumerate() {
        let bound = 8.0 * 0.2f64.powi(k as i32) + 2.5e-3;
        assert!((x - 123.4).abs() <= bound, "mark {k}: {x}");
    }
    for x in &values[6..] {
        assert!((x - 123.4).abs() <= 2.5e-3, "{x}");
    }
    assert_eq!(
        log.matches("mark registration: print MC_MoveSuperimposed")
            .count(),
        11
    );
    // Marks come one repeat (0.4 s) apart at line speed.
    let times = log_times(&log, "mark MeasuredValue1");
    for w in times.windows(2).skip(1) {
        assert!(((w[1] - w[0]) - 400_000_000).abs() <= 2_000, "{times:?}");
    }
    assert!(log.contains("mark MC_MeasuringInputCyclic job 1: CommandAborted"));
    let text = std::fs::read_to_string(&trace).unwrap();
    let (h, rows) = table(&text);
    let c = h.iter().position(|x| x == "mark.counter1").unwrap();
    assert_eq!(rows.last().unwrap()[c], "11");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn glue_dots_three_per_blank_with_the_valve_lead() {
    let dir = std::env::temp_dir().join(format!("tandem-glue-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let trace = dir.join("glue.csv");
    let (code, log, err) = run(&[
        "sim",
        root().join("config/glue-dot.toml").to_str().unwrap(),
        "--script",
        root().join("config/glue-dot-script.toml").to_str().unwrap(),
        "--trace",
        trace.to_str().unwrap(),
        "--strict",
    ]);
    assert_eq!(code, 0, "{err}\n{log}");
    let text = std::fs::read_to_string(&trace).unwrap();
    let (h, rows) = table(&text);
    let col = |n: &str| h.iter().position(|x| x == n).unwrap();
    let (t, p, v) = (
        col("time_s"),
        col("conveyor.position"),
        col("conveyor.velocity"),
    );
    // At line speed (500 mm/s) p(t) is known exactly. The track drives the valve, so its edge
    // times are switching times, computed ahead for the load: the setpoint reaches the load
    // D = 2 cycles (2 ms) later (docs/io.md, "Outputs"). Every on edge leads the dot's start
    // on the load by 2 ms, every off edge its end by 1 ms: the setpoint at edge + lead - D is
    // at the dot's start or end.
    let r = rows.iter().find(|r| r[v] == "500").unwrap();
    let (t_a, p_a) = (ns(&r[t]), r[p].parse::<f64>().unwrap());
    let pos = |t_ns: i64| (p_a + (t_ns - t_a) as f64 * 1e-9 * 500.0).rem_euclid(600.0) % 200.0;
    // The setpoint's transport delay to the load: 2 cycles of 1 ms (SETPOINT_DELAY_CYCLES in
    // shared/runtime/src/outputs.rs).
    const D_NS: i64 = 2_000_000;
    let on = log_times(&log, "output ON (cam");
    let off = log_times(&log, "output OFF (cam");
    let on: Vec<i64> = on.into_iter().filter(|x| *x > t_a).collect();
    let off: Vec<i64> = off.into_iter().filter(|x| *x > t_a).collect();
    for x in &on {
        let q = pos(x + 2_000_000 - D_NS);
        assert!(
            [20.0, 90.0, 160.0].iter().any(|c| (q - c).abs() < 1e-6),
            "on at {x}: {q}"
        );
    }
    for x in &off {
        let q = pos(x + 1_000_000 - D_NS);
        assert!(
            [30.0, 100.0, 175.0].iter().any(|c| (q - c).abs() < 1e-6),
            "off at {x}: {q}"
        );
    }
    // Three dots per blank: nine per revolution (1.2 s at 500 mm/s).
    let in_rev = on
        .iter()
        .filter(|x| **x > t_a && **x <= t_a + 1_200_000_000)
        .count();
    assert_eq!(in_rev, 9, "{log}");
    // Disabled (Mode 0) at 2.8 s: no edge after it.
    assert!(on.iter().chain(&off).all(|x| *x < 2_800_000_000), "{log}");
    // The zero mark: once per revolution on the wrapping cam 590..10.
    let zero = log_times(&log, "zero output ON");
    assert!(zero.len() >= 2, "{log}");
    for w in zero.windows(2).skip(1) {
        assert_eq!(w[1] - w[0], 1_200_000_000);
    }
    let s = col("glue.single_cam_state");
    assert!(rows.iter().any(|r| r[s] == "4"));
    std::fs::remove_dir_all(&dir).ok();
}

/// A one-time measurement with the window 10..20 on an axis that moves through it at 100/s
/// without an edge.
const PROBE_LEAVES_ITS_WINDOW: &str = r#"
[sim]
duration = 1.0

[[at]]
t = 0.0
axis = "x"
instruction = "MC_Power"

[[at]]
t = 0.0
axis = "probe"
instruction = "MC_MeasuringInput"
measuring_range = true
start_position = 10.0
end_position = 20.0

[[at]]
t = 0.0
axis = "x"
instruction = "MC_MoveVelocity"
velocity = 100.0
"#;

#[test]
fn a_one_time_measurement_that_leaves_its_window_logs_alarm_752() {
    let cell = one_axis_cell("\n[[measuring_inputs]]\nname = \"probe\"\naxis = \"x\"\n");
    let (log, trace) = sim_text("win", &cell, PROBE_LEAVES_ITS_WINDOW);
    assert!(
        log.contains("probe alarm 752 MeasuringRangeNotRecognized"),
        "{log}"
    );
    assert!(
        log.contains("probe MC_MeasuringInput job 1: Error 16#8001"),
        "{log}"
    );
    let (h, rows) = table(&trace);
    let s = h.iter().position(|x| x == "probe.state").unwrap();
    assert_eq!(rows.last().unwrap()[s], "MEASURING_ERROR");
}

/// MC_Reset addressed to a measuring input acknowledges its alarm; a new measurement then runs.
#[test]
fn mc_reset_on_a_measuring_input_acknowledges_its_alarm() {
    let cell = one_axis_cell("\n[[measuring_inputs]]\nname = \"probe\"\naxis = \"x\"\n");
    let script = format!(
        "{PROBE_LEAVES_ITS_WINDOW}{}",
        r#"
[[at]]
t = 0.6
axis = "probe"
instruction = "MC_Reset"

[[at]]
t = 0.7
axis = "probe"
instruction = "MC_MeasuringInput"

[[at]]
t = 0.8
axis = "probe"
instruction = "InputEdge"
"#
    );
    let (log, trace) = sim_text("reset", &cell, &script);
    assert!(log.contains("probe alarm 752"), "{log}");
    assert!(log.contains("t=0.600000000 probe MC_Reset: Done"), "{log}");
    assert!(!log.contains("rejected"), "{log}");
    let (h, rows) = table(&trace);
    let s = h.iter().position(|x| x == "probe.state").unwrap();
    let at = |t: &str| rows.iter().find(|r| r[0] == t).unwrap()[s].clone();
    assert_eq!(at("0.599000000"), "MEASURING_ERROR");
    assert_eq!(at("0.650000000"), "INACTIVE");
    assert_eq!(at("0.750000000"), "WAITING_FOR_TRIGGER");
    assert_eq!(rows.last().unwrap()[s], "TRIGGER_OCCURRED");
}

#[test]
fn the_object_examples_pass_check() {
    for f in ["glue-dot.toml", "print-mark-registration.toml"] {
        let (code, out, err) = run(&["check", root().join("config").join(f).to_str().unwrap()]);
        assert_eq!(code, 0, "{err}");
        assert!(out.contains("is valid"), "{out}");
    }
    let (_, out, _) = run(&[
        "check",
        root().join("config/glue-dot.toml").to_str().unwrap(),
    ]);
    assert!(
        out.contains("1 output cam(s), 1 cam track(s), 0 measuring input(s)"),
        "{out}"
    );
}
