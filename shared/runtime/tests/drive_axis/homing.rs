//! Homing through the drive's touch probe: active (MC_Home 3, 5) and passive (2, 8, 10) homing
//! on a CiA 402 drive latch the zero mark (touch probe source: the zero pulse) or the reference
//! cam's edge (the home switch on the probe input) in the drive, as S7-1500T has a PROFIdrive
//! drive latch its reference mark. The axis homes at the latched position; the same cell on the
//! simulated drive (`type = "simulation"`, the same plant) homes at the same position.
//!
//! Geometry: 3 motor turns per 10 mm, 2^20 increments per turn; the zero pulse half a turn in
//! (`zero_pulse_offset = 2^19`), so the zero marks lie at (k + 1/2)·10/3 mm; the reference cam
//! from 40 to 50 mm (12·2^20 and 15·2^20 increments). Leaving the cam upwards, the next zero
//! mark is 155/3 mm = 15.5·2^20 increments.

use super::{cell, Run};
use tandem_config::AxisIndex;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::axis::{Command, StartMode};
use tandem_motion::plant::cia402::DriveFeedback;

const TURN: i32 = 1 << 20;

/// The homing part of the cell; `mark` the active and passive mark.
fn homing_keys(mark: &str) -> String {
    format!(
        r#"
[axes.slide.plant]
reference_cam = [40.0, 50.0]
zero_mark_period = {period:?}
zero_mark_offset = {offset:?}

[axes.slide.homing]
active_mark = "{mark}"
passive_mark = "{mark}"
approach_velocity = 50.0
referencing_velocity = 10.0
home_position = 7.5
home_position_offset = 2.0
"#,
        period = 10.0f64 / 3.0,
        offset = 5.0f64 / 3.0,
    )
}

/// `config/servo.toml` with the homing keys; on the simulated drive if `simulation`.
fn homing_cell(mark: &str, simulation: bool, extra: &str) -> tandem_config::Cell {
    let keys = homing_keys(mark);
    cell(move |s| {
        let s = s.replace("zero_pulse_offset = 0 ", "zero_pulse_offset = 524288 ");
        let s = if simulation {
            s.lines()
                .filter(|l| {
                    !(l.starts_with("device = ")
                        || l.starts_with("enable_timeout")
                        || l.starts_with("[axes.slide.mechanics]")
                        || l.starts_with("load_gear")
                        || l.starts_with("leadscrew_pitch")
                        || l.starts_with("inverse_drive")
                        || l.starts_with("efficiency"))
                })
                .map(|l| l.replace("type = \"cia402\"", "type = \"simulation\""))
                .collect::<Vec<_>>()
                .join("\n")
        } else {
            s
        };
        format!("{s}\n{keys}\n{extra}")
    })
}

/// Homes the axis with `mode` (a passive mode is carried over the marks by a move of 100 mm):
/// the axis's homing offset afterwards and the drive's last feedback.
fn home(mark: &str, mode: u8, simulation: bool, extra: &str) -> (f64, Option<DriveFeedback>) {
    let cell = homing_cell(mark, simulation, extra);
    let mut r = Run::new(&cell);
    r.power(StartMode::PositionControlled);
    r.cmd(Command::Home {
        mode,
        position: 6.0,
    });
    if matches!(mode, 2 | 8 | 10) {
        r.cmd(Command::MoveRelative {
            distance: 100.0,
            dynamics: Dynamics {
                velocity: 20.0,
                acceleration: 1000.0,
                deceleration: 1000.0,
                jerk: 0.0,
            },
        });
    }
    let what = format!("homed: mode {mode}, {mark}, simulation {simulation}");
    r.until(8000, &what, |r| r.log().contains("MC_Home job 2: Done"));
    assert!(!r.log().contains("alarm"), "{}", r.log());
    let offset = r.exec.axis(AxisIndex(0)).unwrap().position_offset();
    (offset, r.fb())
}

/// Homes on both cells; checks the offsets agree (1e-9) and equal `expected`; returns the CiA
/// 402 drive's feedback.
fn same_as_simulation(mark: &str, mode: u8, expected: f64, extra: &str) -> DriveFeedback {
    let (drive, fb) = home(mark, mode, false, extra);
    let (sim, _) = home(mark, mode, true, extra);
    assert!(
        (drive - sim).abs() < 1e-9,
        "mode {mode}, {mark}: offset {drive} on the drive, {sim} in simulation"
    );
    assert!(
        (drive - expected).abs() < 1e-9,
        "mode {mode}, {mark}: offset {drive}, expected {expected}"
    );
    fb.unwrap()
}

#[test]
fn active_homing_on_the_zero_mark_after_the_cam() {
    // Mode 3: the mark is Position - home_position_offset = 4 mm; mode 5: home_position 7.5
    // - 2.
    for (mode, home) in [(3u8, 4.0), (5, 5.5)] {
        let fb = same_as_simulation("cam_and_zero_mark", mode, home - 155.0 / 3.0, "");
        assert_eq!(fb.touch_probe_1_positive, 31 * TURN / 2, "mode {mode}");
    }
}

#[test]
fn active_homing_on_the_cam_edge() {
    let fb = same_as_simulation("digital_input", 3, 4.0 - 50.0, "");
    assert_eq!(fb.touch_probe_1_negative, 15 * TURN);
}

#[test]
fn active_homing_on_the_zero_mark_alone() {
    // The first zero mark in the homing direction from 0: 5/3 mm, half a turn.
    let fb = same_as_simulation("zero_mark", 3, 4.0 - 5.0 / 3.0, "");
    assert_eq!(fb.touch_probe_1_positive, TURN / 2);
}

#[test]
fn passive_homing_on_the_zero_mark_after_the_cam() {
    // Passive homing applies no home position offset: the mark is Position (2, 8) or
    // home_position (10).
    for (mode, home) in [(2u8, 6.0), (8, 6.0), (10, 7.5)] {
        let fb = same_as_simulation("cam_and_zero_mark", mode, home - 155.0 / 3.0, "");
        assert_eq!(fb.touch_probe_1_positive, 31 * TURN / 2, "mode {mode}");
    }
    let fb = same_as_simulation("digital_input", 2, 6.0 - 50.0, "");
    assert_eq!(fb.touch_probe_1_negative, 15 * TURN);
}

#[test]
fn homing_uses_touch_probe_2_when_a_measuring_input_has_probe_1() {
    let probe = r#"
[[measuring_inputs]]
name = "probe"
axis = "slide"
route = "profidrive"
"#;
    let fb = same_as_simulation("cam_and_zero_mark", 3, 4.0 - 155.0 / 3.0, probe);
    assert_eq!(fb.touch_probe_2_positive, 31 * TURN / 2);
    assert_eq!(fb.touch_probe_1_positive, 0, "probe 1 untouched");
    let fb = same_as_simulation("digital_input", 2, 6.0 - 50.0, probe);
    assert_eq!(fb.touch_probe_2_negative, 15 * TURN);
}
