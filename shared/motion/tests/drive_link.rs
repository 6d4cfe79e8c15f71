//! The axis side of a drive behind the process image (`DriveLink::Connected`): MC_Power waits
//! for the drive to be operational, a drive fault raises technology alarm 421 with the drive's
//! error code and removes the enable, MC_Reset sends the fault reset for one cycle and the
//! enable comes back while MC_Power.Enable is held (S7-1500T Motion Control V4.0 function
//! manual, 'MC_Power', technology alarm 421 "Faulty drive" and its causes).
//!
//! The drive here is scripted by the test, one state per cycle, so that each rule is checked
//! on its own.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_motion::catalog::alarm::{supplement, AlarmId};
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::objects::axis::{
    Axis, AxisConfig, AxisState, Command, StartMode, StopMode, VelocityDirection,
};
use tandem_motion::objects::job::{Instruction, JobEvent, JobEventKind};
use tandem_motion::plant::drive::{Actual, ZeroMark};
use tandem_motion::plant::link::{DriveInputs, DriveOutputs, DriveState};
use tandem_testkit::rig::dynamics;

const MS: i64 = 1_000_000;

/// An axis on a connected drive; the test plays the drive.
struct Bench {
    axis: Axis,
    k: i64,
    events: Vec<JobEvent>,
    /// What the drive reports next cycle.
    inputs: DriveInputs,
    /// The outputs of every cycle so far.
    outputs: Vec<DriveOutputs>,
}

impl Bench {
    fn new() -> Self {
        let mut axis = Axis::new(AxisConfig::example(0.001)).unwrap();
        axis.connect_drive();
        let inputs = DriveInputs {
            actual: Actual {
                p: 12.5,
                v: 0.0,
                balanced: 12.5,
            },
            ..DriveInputs::default()
        };
        Self {
            axis,
            k: 0,
            events: Vec::new(),
            inputs,
            outputs: Vec::new(),
        }
    }

    fn step(&mut self, n: usize) {
        for _ in 0..n {
            self.axis.set_drive_inputs(&self.inputs);
            self.axis.step(self.k * MS);
            self.k += 1;
            self.outputs.push(self.axis.drive_outputs());
            self.drain();
        }
    }

    fn drain(&mut self) {
        while let Some(e) = self.axis.pop_event() {
            self.events.push(e);
        }
    }

    fn cmd(&mut self, c: Command) -> Result<u32, ErrorId> {
        let r = self.axis.command(&c);
        self.drain();
        r
    }

    fn power(&mut self, enable: bool) -> u32 {
        self.cmd(Command::Power {
            enable,
            start_mode: StartMode::PositionControlled,
            stop_mode: StopMode::Emergency,
        })
        .unwrap()
    }

    fn status_true(&self, job: u32) -> bool {
        self.events.iter().any(|e| {
            e.job == job
                && e.instruction == Instruction::Power
                && e.kind == JobEventKind::Status(true)
        })
    }

    fn last(&self) -> DriveOutputs {
        *self.outputs.last().unwrap()
    }

    fn alarm_421(&self) -> Option<u16> {
        self.axis
            .alarms()
            .find(|a| a.id == AlarmId::DriveFault)
            .map(|a| a.supplement)
    }
}

/// Powers the bench's axis and lets the drive become operational after 3 cycles.
fn enabled() -> (Bench, u32) {
    let mut b = Bench::new();
    b.step(1);
    let p = b.power(true);
    b.inputs.state = DriveState::Enabling { step: 1 };
    b.step(3);
    b.inputs.state = DriveState::Operational;
    b.step(1);
    assert!(b.status_true(p), "{:?}", b.events);
    (b, p)
}

#[test]
fn mc_power_waits_for_the_drive_to_be_operational() {
    let mut b = Bench::new();
    b.step(2);
    assert!(!b.last().enable, "no enable before MC_Power");
    let p = b.power(true);
    // The enable is requested at once, the axis is not enabled until the drive says so.
    for step in 1..=3 {
        b.inputs.state = DriveState::Enabling { step };
        b.step(5);
        assert!(b.last().enable);
        assert!(
            !b.status_true(p),
            "Status TRUE before the drive is operational"
        );
        assert_eq!(b.axis.status().state, AxisState::Disabled);
        // While not enabled, the setpoint follows the actual value (no jump at the enable).
        assert_eq!(b.last().position, 12.5);
    }
    // A motion job is refused while the drive is not operational.
    let mv = b.cmd(Command::MoveVelocity {
        dynamics: dynamics(10.0, 100.0, 100.0, 0.0),
        direction: VelocityDirection::BySign,
        current: false,
        position_controlled: true,
    });
    assert_eq!(mv, Err(ErrorId::NotEnabled));
    b.inputs.state = DriveState::Operational;
    b.step(1);
    assert!(b.status_true(p));
    assert_eq!(b.axis.status().state, AxisState::Standstill);
    let out = b.last();
    assert!(out.enable && out.position_controlled);
    assert_eq!(
        out.position, 12.5,
        "the first setpoint is the actual position"
    );
    assert_eq!(b.alarm_421(), None);
}

#[test]
fn a_drive_fault_raises_421_with_the_drive_error_code_and_removes_the_enable() {
    let (mut b, p) = enabled();
    b.inputs.state = DriveState::Fault { code: 0x2310 };
    b.step(1);
    assert_eq!(
        b.alarm_421(),
        Some(0x2310),
        "the drive's 0x603F in the supplement"
    );
    assert_eq!(b.axis.status().state, AxisState::ErrorStop);
    assert!(!b.last().enable, "remove enable in the same cycle");
    assert!(b
        .events
        .iter()
        .any(|e| e.job == p && e.kind == JobEventKind::Status(false)));
    // A fault without a code of its own: "alarm message from drive".
    let (mut b, _) = enabled();
    b.inputs.state = DriveState::Fault { code: 0 };
    b.step(1);
    assert_eq!(b.alarm_421(), Some(supplement::DRIVE_ALARM));
}

#[test]
fn mc_reset_sends_one_fault_reset_and_the_enable_comes_back() {
    let (mut b, p) = enabled();
    b.inputs.state = DriveState::Fault { code: 0x4310 };
    b.step(3);
    assert_eq!(b.alarm_421(), Some(0x4310));
    assert!(b.outputs.iter().all(|o| !o.fault_reset));
    b.cmd(Command::Reset { restart: false }).unwrap();
    assert_eq!(b.alarm_421(), None, "acknowledged");
    let before = b.outputs.len();
    // The drive still reports its fault for a few cycles while it processes the reset: that
    // is not a new alarm.
    b.step(3);
    let resets: Vec<bool> = b.outputs[before..].iter().map(|o| o.fault_reset).collect();
    assert_eq!(resets, [true, false, false], "one cycle of fault reset");
    assert_eq!(b.alarm_421(), None);
    assert!(
        b.last().enable,
        "MC_Power.Enable is still held: the enable is requested again"
    );
    b.inputs.state = DriveState::Enabling { step: 3 };
    b.step(2);
    b.inputs.state = DriveState::Operational;
    b.step(1);
    let status: Vec<bool> = b
        .events
        .iter()
        .filter(|e| e.job == p)
        .filter_map(|e| match e.kind {
            JobEventKind::Status(s) => Some(s),
            _ => None,
        })
        .collect();
    assert_eq!(status, [true, false, true]);
    assert_eq!(b.axis.status().state, AxisState::Standstill);
}

#[test]
fn mc_power_on_a_faulted_drive_raises_421_at_once() {
    let mut b = Bench::new();
    b.inputs.state = DriveState::Fault { code: 0x7300 };
    b.step(1);
    assert_eq!(
        b.alarm_421(),
        None,
        "no alarm while nobody wants the enable"
    );
    b.power(true);
    b.step(1);
    assert_eq!(b.alarm_421(), Some(0x7300));
    assert!(!b.last().enable);
}

#[test]
fn an_enable_that_does_not_complete_names_its_step() {
    let mut b = Bench::new();
    b.step(1);
    let p = b.power(true);
    b.inputs.state = DriveState::Enabling { step: 2 };
    b.step(10);
    b.inputs.state = DriveState::EnableTimedOut { step: 2 };
    b.step(1);
    assert_eq!(
        b.alarm_421(),
        Some(supplement::DRIVE_ENABLE_NOT_POSSIBLE + 2),
        "421 'drive enable not possible', step 2 (switch on)"
    );
    assert!(!b.status_true(p));
    assert!(!b.last().enable, "the request is withdrawn");
}

#[test]
fn a_drive_that_leaves_operation_on_its_own_raises_421_shut_down() {
    let (mut b, _) = enabled();
    let mv = b
        .cmd(Command::MoveVelocity {
            dynamics: dynamics(10.0, 100.0, 100.0, 0.0),
            direction: VelocityDirection::BySign,
            current: false,
            position_controlled: true,
        })
        .unwrap();
    b.step(5);
    b.inputs.state = DriveState::Disabled;
    b.step(1);
    assert_eq!(b.alarm_421(), Some(supplement::DRIVE_SHUT_DOWN));
    assert!(b
        .events
        .iter()
        .any(|e| e.job == mv && e.kind == JobEventKind::Error(ErrorId::TechnologyAlarm)));
    assert!(!b.last().enable);
}

#[test]
fn mc_power_off_while_waiting_withdraws_the_request() {
    let mut b = Bench::new();
    b.step(1);
    b.power(true);
    b.inputs.state = DriveState::Enabling { step: 1 };
    b.step(2);
    assert!(b.last().enable);
    b.power(false);
    b.step(1);
    assert!(!b.last().enable);
    // The drive becoming operational late does not enable the axis.
    b.inputs.state = DriveState::Operational;
    b.step(1);
    assert_eq!(b.axis.status().state, AxisState::Disabled);
}

#[test]
fn in_simulation_the_outputs_are_those_applied_to_the_simulated_drive() {
    let mut axis = Axis::new(AxisConfig::example(0.001)).unwrap();
    axis.step(0);
    axis.command(&Command::Power {
        enable: true,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Emergency,
    })
    .unwrap();
    // Enabled at once: no drive handshake in simulation.
    assert_eq!(axis.status().state, AxisState::Standstill);
    axis.step(MS);
    let o = axis.drive_outputs();
    assert!(o.enable && o.position_controlled && !o.fault_reset);
    assert_eq!(o.position, axis.status().position);
}

#[test]
fn homing_that_needs_a_mark_is_accepted_on_a_connected_drive() {
    // A plant with a reference cam and zero marks: in simulation active and passive homing
    // are accepted; on a drive of the process image too (its touch probe latches the marks:
    // shared/runtime/tests/drive_homing.rs), and direct homing works.
    let mut cfg = AxisConfig::example(0.001);
    cfg.plant.reference_cam = Some((10.0, 20.0));
    cfg.plant.zero_mark = Some(ZeroMark {
        period: 5.0,
        offset: 1.0,
    });
    let home = |mode| Command::Home {
        mode,
        position: 0.0,
    };
    let mut sim = Axis::new(cfg.clone()).unwrap();
    sim.step(0);
    sim.command(&Command::Power {
        enable: true,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Emergency,
    })
    .unwrap();
    sim.step(MS);
    for mode in [2u8, 3] {
        assert!(sim.command(&home(mode)).is_ok(), "simulation, mode {mode}");
    }
    let mut b = Bench::new();
    b.axis = Axis::new(cfg).unwrap();
    b.axis.connect_drive();
    b.step(1);
    let p = b.power(true);
    b.inputs.state = DriveState::Operational;
    b.step(1);
    assert!(b.status_true(p));
    for mode in [2u8, 3, 5, 8, 10] {
        assert!(b.cmd(home(mode)).is_ok(), "mode {mode}");
    }
    assert!(b.cmd(home(0)).is_ok());
}
