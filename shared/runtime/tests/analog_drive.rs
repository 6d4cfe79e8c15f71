//! An axis on a simulated analog drive through the process image, end to end in the executive
//! (`config/analog.toml`): MC_Power sets the enable output and waits for the ready input; a
//! jerk-limited move is followed with the following error inside its monitoring limits while
//! tandem closes the position loop; without precontrol the lag is the manual's `v / Kv`; a
//! drive that drops its ready mid-move raises alarm 421 (remove enable) in the cycle the
//! sample shows it; a ready that does not come names the step (supplement 0x14); on disable
//! the enable output drops only after a zero setpoint was written; MC_Reset re-enables.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::{AxisIndex, Cell};
use tandem_motion::catalog::alarm::{supplement, AlarmId};
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{AxisState, Command, StartMode, StopMode};
use tandem_motion::plant::analog::{AnalogEnableStatus, READY_STEP};
use tandem_runtime::drives::analog::AnalogDriveStatus;
use tandem_runtime::exec::Executive;
use tandem_testkit::workspace::root;

const MS: i64 = 1_000_000;

fn cell(edit: impl Fn(String) -> String) -> Cell {
    let src = std::fs::read_to_string(root().join("config/analog.toml")).unwrap();
    tandem_config::parse("analog.toml", &edit(src)).unwrap()
}

/// The cell with `from` replaced by `to` (which must occur).
fn edit(from: &'static str, to: &'static str) -> impl Fn(String) -> String {
    move |s: String| {
        assert!(s.contains(from), "{from}");
        s.replacen(from, to, 1)
    }
}

struct Run<'c> {
    exec: Executive<'c>,
    k: i64,
    log: Vec<u8>,
}

impl<'c> Run<'c> {
    fn new(cell: &'c Cell) -> Self {
        Self {
            exec: Executive::new(cell, None).unwrap(),
            k: 0,
            log: Vec::new(),
        }
    }

    fn t(&self) -> i64 {
        self.k * MS
    }

    fn apply(&mut self, target: &str, action: Action) {
        let t = self.t();
        let r = self
            .exec
            .apply_at(t, t, target, "test", action, &mut self.log)
            .unwrap();
        assert!(r.is_ok(), "{target}: {r:?}\n{}", self.log());
    }

    fn cmd(&mut self, c: Command) {
        self.apply("slide", Action::Command(c));
    }

    fn step(&mut self) {
        let t = self.t();
        self.exec.step(t, &mut self.log).unwrap();
        self.k += 1;
    }

    fn log(&self) -> String {
        String::from_utf8_lossy(&self.log).into_owned()
    }

    fn state(&mut self) -> AxisState {
        self.exec.status()[0].state
    }

    fn alarm(&self, id: AlarmId) -> Option<u16> {
        let axis = self.exec.axis(AxisIndex(0)).unwrap();
        axis.alarms().find(|a| a.id == id).map(|a| a.supplement)
    }

    fn drive(&self) -> AnalogDriveStatus {
        self.exec.analog_drive(0).unwrap()
    }

    fn until(&mut self, max: usize, what: &str, f: impl Fn(&mut Self) -> bool) {
        for _ in 0..max {
            if f(self) {
                return;
            }
            self.step();
        }
        panic!("{what}: not within {max} cycles\n{}", self.log());
    }

    fn power(&mut self, enable: bool) {
        self.cmd(Command::Power {
            enable,
            start_mode: StartMode::PositionControlled,
            stop_mode: StopMode::Emergency,
        });
    }

    fn enabled(&mut self) {
        self.power(true);
        self.cmd(Command::Home {
            mode: 0,
            position: 0.0,
        });
        self.until(50, "enabled", |r| r.state() == AxisState::Standstill);
    }

    fn move_to(&mut self, position: f64) {
        self.cmd(Command::MoveAbsolute {
            position,
            dynamics: Dynamics {
                velocity: 200.0,
                acceleration: 2000.0,
                deceleration: 2000.0,
                jerk: 40000.0,
            },
            direction: tandem_motion::objects::axis::Direction::Shortest,
        });
    }
}

#[test]
fn mc_power_waits_for_ready_and_a_move_follows_within_the_monitoring() {
    let cell = cell(|s| s);
    let mut r = Run::new(&cell);
    r.step();
    r.power(true);
    // Power at 1 ms: the step at 1 ms requests the enable, the inputs of 2 ms set the enable
    // output, the drive latches it at 3 ms and is ready 10 ms later: Status TRUE in the step
    // at 13 ms, not before.
    let mut cycles = 0;
    while r.state() != AxisState::Standstill {
        assert_eq!(r.state(), AxisState::Disabled);
        if cycles >= 2 {
            assert!(r.drive().link.enable_do, "enable DO set while waiting");
        }
        r.step();
        cycles += 1;
        assert!(cycles < 50, "{}", r.log());
    }
    assert_eq!(cycles, 13, "request, DO, latch, 10 ms ready delay");
    assert!(r.drive().feedback.ready);
    r.cmd(Command::Home {
        mode: 0,
        position: 0.0,
    });
    r.move_to(150.0);
    let fe = cell.axes[0].config.following_error;
    let mut worst = 0.0f64;
    let mut worst_word = 0i16;
    for _ in 0..1500 {
        r.step();
        worst = worst.max(r.exec.status()[0].following_error.abs());
        worst_word = worst_word.max(r.drive().link.word.abs());
    }
    let s = r.exec.status()[0];
    assert!(
        r.log().contains("MC_MoveAbsolute job 3: Done"),
        "{}",
        r.log()
    );
    assert_eq!(s.position, 150.0);
    assert!((s.actual_position - 150.0).abs() < cell.axes[0].config.positioning.window);
    assert!((r.drive().position - 150.0).abs() < 0.01);
    assert!(
        worst < 0.05 * fe.min_value,
        "following error {worst} against the permitted {}",
        fe.min_value
    );
    // 200 mm/s of 500 mm/s reference: 40 % of 27648, plus what the acceleration needs.
    assert!((11059..=13000).contains(&worst_word), "{worst_word}");
    assert!(!r.log().contains("alarm"), "{}", r.log());
}

#[test]
fn without_precontrol_the_lag_is_v_over_kv() {
    // Kpc 0, Kv 50: 200 mm/s lags 4 mm (the manual: about v / Kv); the monitoring is widened
    // so that it does not trip.
    let cell = cell(|s| {
        let s = edit("kpc = 100.0", "kpc = 0.0")(s);
        let s = edit("min_value = 0.5", "min_value = 8.0")(s);
        edit("max_value = 2.0", "max_value = 10.0")(s)
    });
    let mut r = Run::new(&cell);
    r.enabled();
    r.move_to(150.0);
    let mut lags = Vec::new();
    for _ in 0..700 {
        r.step();
        let s = r.exec.status()[0];
        if s.velocity == 200.0 {
            lags.push(s.following_error);
        }
    }
    // The last 100 cycles at constant velocity, after the loop settled.
    let tail = &lags[lags.len() - 100..];
    let mean = tail.iter().sum::<f64>() / tail.len() as f64;
    assert!((mean - 4.0).abs() < 2e-3, "mean lag {mean}");
    assert!(!r.log().contains("alarm"), "{}", r.log());
}

#[test]
fn loss_of_ready_mid_move_raises_421_in_the_cycle_the_sample_shows_it() {
    let cell = cell(|s| s);
    let mut r = Run::new(&cell);
    r.enabled();
    r.move_to(150.0);
    for _ in 0..300 {
        r.step();
    }
    assert_eq!(r.state(), AxisState::DiscreteMotion);
    r.apply("slide_amp", Action::DriveFault { code: 1 });
    assert_eq!(r.alarm(AlarmId::DriveFault), None);
    // The next boundary samples the drive without ready: that step raises 421 "remove
    // enable" with supplement 3 (the drive shut down; an analog drive has no error code).
    r.step();
    assert!(!r.drive().feedback.ready);
    assert_eq!(
        r.alarm(AlarmId::DriveFault),
        Some(supplement::DRIVE_SHUT_DOWN)
    );
    assert_eq!(r.state(), AxisState::ErrorStop);
    assert_eq!(r.drive().link.enable, AnalogEnableStatus::ReadyLost);
    // The enable DO is removed at once and the setpoint is 0.
    assert!(!r.drive().link.enable_do);
    assert_eq!(r.drive().link.word, 0);
    assert!(
        r.log().contains("MC_MoveAbsolute job 3: Error 16#8001"),
        "{}",
        r.log()
    );
    // The drive brakes on its own ramp.
    r.until(300, "standstill", |r| r.drive().velocity == 0.0);
    // Acknowledged with the cause still present: the re-enable waits for ready and times out
    // after 0.5 s, naming the ready step.
    r.cmd(Command::Reset { restart: false });
    r.until(700, "timeout", |r| {
        r.alarm(AlarmId::DriveFault)
            == Some(supplement::DRIVE_ENABLE_NOT_POSSIBLE + u16::from(READY_STEP))
    });
    // Cause removed, acknowledged: enabled again, and a move completes.
    r.apply("slide_amp", Action::DriveFault { code: 0 });
    r.step();
    r.cmd(Command::Reset { restart: false });
    r.until(50, "re-enabled", |r| r.state() == AxisState::Standstill);
    r.move_to(50.0);
    // Done: MC_Home, the two MC_Reset, and this move.
    r.until(2000, "done", |r| r.log().matches(": Done").count() >= 4);
    assert!((r.exec.status()[0].actual_position - 50.0).abs() < 0.01);
}

#[test]
fn a_ready_that_does_not_come_names_the_step() {
    let cell = cell(edit("ready_delay = 0.01", "ready_delay = 2.0"));
    let mut r = Run::new(&cell);
    r.power(true);
    r.until(600, "timeout", |r| r.alarm(AlarmId::DriveFault).is_some());
    assert_eq!(r.alarm(AlarmId::DriveFault), Some(0x10 + 4));
    // Raised in the step at 501 ms: 0.5 s after the enable output was set (at 1 ms).
    assert_eq!(r.t(), 502 * MS, "{}", r.log());
    assert_eq!(r.drive().link.enable, AnalogEnableStatus::TimedOut);
    assert!(!r.drive().link.enable_do);
    assert_eq!(r.state(), AxisState::ErrorStop);
    // Without a ready input the same drive enables with the enable output.
    let cell = cell_without_ready();
    let mut r = Run::new(&cell);
    r.power(true);
    r.until(5, "enabled", |r| r.state() == AxisState::Standstill);
}

fn cell_without_ready() -> Cell {
    cell(|s| {
        let s = edit("ready_delay = 0.01", "ready_delay = 2.0")(s);
        edit("ready = true", "ready = false")(s)
    })
}

#[test]
fn disable_drops_the_enable_output_only_after_a_zero_setpoint() {
    let cell = cell(|s| s);
    let mut r = Run::new(&cell);
    r.enabled();
    r.move_to(100.0);
    for _ in 0..200 {
        r.step();
    }
    // The drive reads a nonzero command.
    assert!(r.drive().latched.words.word > 0);
    // MC_Power Enable FALSE with an emergency stop: the axis brakes on its setpoints, then
    // removes the enable. Record what the drive latched at each boundary.
    r.power(false);
    let mut seen = Vec::new();
    for _ in 0..400 {
        r.step();
        seen.push(r.drive().latched);
    }
    let off = seen.iter().position(|c| !c.enable).unwrap();
    assert!(off > 0);
    // The boundary before the enable dropped, the drive already had a 0 setpoint.
    assert_eq!(seen[off - 1].words.word, 0, "{:?}", &seen[..=off]);
    assert!(seen[off - 1].enable);
    assert!(seen[off..].iter().all(|c| !c.enable && c.words.word == 0));
    assert_eq!(r.state(), AxisState::Disabled);
    assert!(!r.log().contains("alarm"), "{}", r.log());
}

/// `config/analog.toml` with a reference cam from 40 to 50 mm and zero marks every 10 mm at
/// 5 mm + k·10 mm (one per leadscrew turn), homing on `mark`.
fn homing_cell(mark: &str) -> Cell {
    let keys = format!(
        r#"
[axes.slide.plant]
reference_cam = [40.0, 50.0]
zero_mark_period = 10.0
zero_mark_offset = 5.0

[axes.slide.homing]
active_mark = "{mark}"
passive_mark = "{mark}"
approach_velocity = 50.0
referencing_velocity = 10.0
home_position = 7.5
home_position_offset = 2.0
"#
    );
    cell(move |s| format!("{s}\n{keys}"))
}

/// Homes the analog axis with `mode` (a passive mode carried over the marks by a move of
/// 100 mm): the axis's homing offset (its position minus the physical one).
fn home_analog(mark: &str, mode: u8) -> f64 {
    let cell = homing_cell(mark);
    let mut r = Run::new(&cell);
    r.power(true);
    r.until(50, "enabled", |r| r.state() == AxisState::Standstill);
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
    let what = format!("homed: mode {mode}, {mark}");
    r.until(8000, &what, |r| r.log().contains("MC_Home job 2: Done"));
    assert!(!r.log().contains("alarm"), "{}", r.log());
    r.exec.axis(AxisIndex(0)).unwrap().position_offset()
}

/// MC_Home 2, 3 and 5 on an analog drive: the encoder's zero mark and the reference cam's edge
/// are latched where the plant has them (the simulated measuring input of the encoder), so the
/// homing offset is exact: the homed mark position minus the mark.
#[test]
fn homing_on_an_analog_drive_latches_the_cam_edge_and_the_zero_mark() {
    // Active, mode 3: the mark becomes Position - home_position_offset = 4 mm; mode 5:
    // home_position - home_position_offset = 5.5 mm. The cam is left upwards at 50 mm; the
    // next zero mark is at 55 mm.
    let cases = [
        ("digital_input", 3u8, 4.0 - 50.0),
        ("cam_and_zero_mark", 3, 4.0 - 55.0),
        ("cam_and_zero_mark", 5, 5.5 - 55.0),
        // Passive, mode 2: no home position offset; the mark becomes Position = 6 mm.
        ("cam_and_zero_mark", 2, 6.0 - 55.0),
    ];
    for (mark, mode, expected) in cases {
        let offset = home_analog(mark, mode);
        assert!(
            (offset - expected).abs() < 1e-9,
            "mode {mode}, {mark}: offset {offset}, expected {expected}"
        );
    }
}
