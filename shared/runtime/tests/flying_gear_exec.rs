//! MC_FlyingGear_BkPlcMc (Beckhoff TwinCAT PLC Hydraulic Positioning library, 4.2.6
//! 'MC_FlyingGear_BkPlcMc') through the executive and a script: the hydraulic ram of
//! `config/hydraulic.toml` follows a virtual upper tool working in the opposite direction
//! ('Sample #2'). The command goes through the script parser (as `tandem cmd` and Zenoh); the
//! ram stands until the leader reaches the engage section, engages over twice the ram's
//! distance, is geared exactly, releases on the way back and stops at SlaveStopPosition; its set
//! position is continuous in position and velocity; the actual position follows it.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod hyd_rig;
use tandem_motion::objects::axis::sync_status;
use tandem_runtime::exec::Executive;
use tandem_testkit::workspace::root;

const LEADER: &str = r#"
[axes.upper]
node = "press"
virtual = true

[axes.upper.dynamics]
max_velocity = 500.0
max_acceleration = 5000.0
max_deceleration = 5000.0
max_jerk = 50000.0
velocity = 50.0
acceleration = 500.0
deceleration = 500.0
jerk = 5000.0
emergency_deceleration = 10000.0

[axes.ram.leaders]
upper = "setpoint"
"#;

/// Ram at 100 (its initial position), upper tool homed at 400 moving down to 150 and back at
/// 50 mm/s. MasterSyncPosition 200, SlaveSyncPosition 150: the ram works upwards over 50 mm,
/// so the engage section is 2 · 50 = 100 mm of leader, from 300 to 200; geared the ram is at
/// 150 − (x − 200); on the way back it releases from 150 (leader at 200) to 100 (leader at 300).
const SCRIPT: &str = r#"
[sim]
duration = 13.0

[[at]]
t = 0.0
axis = "ram"
instruction = "MC_Power"

[[at]]
t = 0.0
axis = "upper"
instruction = "MC_Power"

[[at]]
t = 0.01
axis = "upper"
instruction = "MC_Home"
mode = 0
position = 400.0

[[at]]
t = 0.5
axis = "ram"
instruction = "MC_FlyingGear_BkPlcMc"
master = "upper"
enable = true
ratio = 1.0
master_sync_position = 200.0
slave_sync_position = 150.0
slave_desync_position = 150.0
slave_stop_position = 100.0

[[at]]
t = 0.6
axis = "upper"
instruction = "MC_MoveAbsolute"
position = 150.0
velocity = 50.0
acceleration = 500.0
deceleration = 500.0
jerk = 5000.0

[[at]]
t = 6.5
axis = "upper"
instruction = "MC_MoveAbsolute"
position = 400.0
velocity = 50.0
acceleration = 500.0
deceleration = 500.0
jerk = 5000.0

[[at]]
t = 12.5
axis = "ram"
instruction = "MC_FlyingGear_BkPlcMc"
master = "upper"
enable = false
ratio = 1.0
master_sync_position = 200.0
slave_sync_position = 150.0
slave_desync_position = 150.0
slave_stop_position = 100.0
"#;

/// What a run saw: the sync status bits, the largest |actual − set| of the ram, the log.
struct Seen {
    flags: u8,
    worst_lag: f64,
    log: String,
    /// The ram at the end: set position, set velocity, whether a synchronous job runs.
    end: (f64, f64, bool),
}

/// Runs `script` on `cell` checking the ram (axis 0) under its leader (axis 1) every cycle: it
/// stands at `y0` while the leader is outside the engage section (above `engage_start`, or
/// at or above it on the way back), is geared `y = ssp + s·(x − msp)` while InSync, and its set
/// position is continuous: velocity steps within `dv_max`, position steps the mean velocity.
fn run(
    cell: &tandem_config::Cell,
    script: &str,
    law: (f64, f64, f64, f64, f64),
    dv_max: f64,
) -> Seen {
    let (y0, engage_start, msp, ssp, s) = law;
    let script = tandem_config::script::parse_cell("flying.toml", script, cell).unwrap();
    let mut exec = Executive::new(cell, None).unwrap();
    let mut log = Vec::new();
    let (mut flags, mut worst_lag) = (0u8, 0.0_f64);
    let mut prev: Option<(f64, f64)> = None;
    hyd_rig::replay(&mut exec, &script, &mut log, |k, exec| {
        let [ram, leader] = [exec.status()[0], exec.status()[1]];
        let (y, v, x) = (
            ram.position_unwrapped,
            ram.velocity,
            leader.position_unwrapped,
        );
        if ram.sync_job.is_some() && k > 500 {
            if leader.velocity < 0.0 && x > engage_start
                || leader.velocity > 0.0 && x >= engage_start
            {
                assert_eq!(y, y0, "at leader {x}");
            }
            if ram.sync_status_word & sync_status::FLYING_IN_SYNC != 0 {
                assert!((y - (ssp + s * (x - msp))).abs() <= 1e-9, "{y} at {x}");
            }
        }
        if let Some((y1, v1)) = prev {
            assert!((v - v1).abs() <= dv_max, "velocity step {v1} -> {v} at {x}");
            assert!(
                ((y - y1) - 0.5 * (v + v1) * 1e-3).abs() <= 0.5 * dv_max * 1e-3,
                "at {x}"
            );
        }
        prev = Some((y, v));
        flags |= ram.sync_status_word;
        worst_lag = worst_lag.max((ram.actual_position - y).abs());
    });
    let ram = exec.status()[0];
    Seen {
        flags,
        worst_lag,
        log: String::from_utf8(log).unwrap(),
        end: (ram.position_unwrapped, ram.velocity, ram.sync_job.is_some()),
    }
}

const ALL: u8 =
    sync_status::FLYING_START_SYNC | sync_status::FLYING_IN_SYNC | sync_status::FLYING_ACTIVE;

/// Opposite directions ('Sample #2'), the command inline.
#[test]
fn the_ram_engages_gears_and_releases_on_the_upper_tool() {
    let src = std::fs::read_to_string(root().join("config/hydraulic.toml")).unwrap() + LEADER;
    let cell = tandem_config::parse("hydraulic.toml", &src).unwrap();
    // 50 mm/s, 500 mm/s² leader; ramps of 100 mm: |Δv| ≤ (500 + 50²/100)·1 ms.
    let seen = run(
        &cell,
        SCRIPT,
        (100.0, 300.0, 200.0, 150.0, -1.0),
        0.525 + 1e-9,
    );
    assert_eq!(seen.flags & ALL, ALL, "{}", seen.log);
    assert_eq!(seen.end, (100.0, 0.0, false), "{}", seen.log);
    let exec_log = &seen.log;
    assert!(exec_log.contains("MC_FlyingGear_BkPlcMc job"), "{exec_log}");
    eprintln!(
        "largest |actual - set| of the ram: {:.3} mm",
        seen.worst_lag
    );
    assert!(seen.worst_lag < 2.0, "{}\n{exec_log}", seen.worst_lag);
}

/// The bundled example (`config/hydraulic-flying-gear.toml` with its script): the cushion under
/// the slide, same directions ('Sample #1' shifted by −250 mm).
#[test]
fn the_bundled_example_pre_accelerates_the_cushion_onto_the_slide() {
    let cell = tandem_config::load(&root().join("config/hydraulic-flying-gear.toml")).unwrap();
    let script =
        std::fs::read_to_string(root().join("config/hydraulic-flying-gear-script.toml")).unwrap();
    // 100 mm/s, 1000 mm/s² slide; ramps of 100 mm: |Δv| ≤ (1000 + 100²/100)·1 ms.
    let seen = run(
        &cell,
        &script,
        (250.0, 310.0, 210.0, 200.0, 1.0),
        1.1 + 1e-9,
    );
    assert_eq!(seen.flags & ALL, ALL, "{}", seen.log);
    assert_eq!(seen.end, (250.0, 0.0, false), "{}", seen.log);
    for event in ["StartSync", "InSync", "Done"] {
        assert!(
            seen.log
                .lines()
                .any(|l| l.contains("MC_FlyingGear_BkPlcMc") && l.contains(event)),
            "{event}\n{}",
            seen.log
        );
    }
    eprintln!(
        "largest |actual - set| of the cushion: {:.3} mm",
        seen.worst_lag
    );
    assert!(seen.worst_lag < 2.0, "{}\n{}", seen.worst_lag, seen.log);
}
