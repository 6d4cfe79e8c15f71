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
