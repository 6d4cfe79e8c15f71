//! MC_Home_BkPlcMc (the Beckhoff hydraulic library's homing) on the simulated valve and
//! cylinder of `config/hydraulic.toml`, through the executive: Direct sets the actual position
//! at once; AbsSwitch on the plant's reference cam gives the cam's leaving edge the value
//! Position within one cycle's travel at the sync velocity; RefPulse gives the zero pulse after
//! the cam exactly Position; Block runs the cylinder into its end stop and is Done after
//! fBlockDetectDelay without movement; the refusals (moving, unsupported mode, error state)
//! change nothing; a dropped Execute does not stop a homing; the cell file's keys are checked.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod hyd_rig;
use hyd_rig::Run;

use tandem_config::Cell;
use tandem_motion::catalog::alarm::status_bit;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{
    AxisState, Command, HydHomeInputs, HydHomingMode, StartMode, StopMode, VelocityDirection,
};
use tandem_motion::objects::job::Instruction;
use tandem_runtime::exec::Executive;
use tandem_testkit::workspace::root;

/// fRefVelo of config/hydraulic.toml.
const REF_VELO: f64 = 327.06;
/// Its cycle (s).
const DT: f64 = 1e-3;

/// config/hydraulic.toml with `hydraulic` added to `[axes.ram.hydraulic]` and `extra` at the
/// end.
fn cell(hydraulic: &str, extra: &str) -> Cell {
    let s = std::fs::read_to_string(root().join("config/hydraulic.toml")).unwrap();
    let s = s.replacen(
        "[axes.ram.hydraulic]\n",
        &format!("[axes.ram.hydraulic]\n{hydraulic}\n"),
        1,
    );
    tandem_config::parse("hydraulic.toml", &format!("{s}\n{extra}\n")).unwrap()
}

fn home(execute: bool, position: f64, mode: HydHomingMode) -> Command {
    Command::HydHome(HydHomeInputs {
        execute,
        position: Some(position),
        mode,
        calibration_cam: false,
    })
}

impl Run<'_> {
    /// The load's physical position (the cylinder's piston).
    fn physical(&self) -> f64 {
        self.exec.analog_drive(0).unwrap().position
    }

    /// The axis value of physical position `x` (the homing offset applied).
    fn axis_value(&self, x: f64) -> f64 {
        let s = self.status();
        x + (s.actual_position - self.physical())
    }

    /// Whether job `id` of MC_Home_BkPlcMc has logged `what`.
    fn logged(&self, id: u32, what: &str) -> bool {
        self.log()
            .contains(&format!("MC_Home_BkPlcMc job {id}: {what}"))
    }

    /// Steps until job `id` is Done; the cycles it took.
    fn until_done(&mut self, id: u32, max: usize) -> usize {
        for k in 0..max {
            if self.logged(id, "Done") {
                return k;
            }
            self.step();
        }
        panic!("homing not Done within {max} cycles\n{}", self.log());
    }
}

/// Direct: actual := Position at once, Done in the same command, homed, Standstill.
#[test]
fn direct_sets_the_position_at_once() {
    let cell = cell("", "");
    let mut r = Run::enabled(&cell);
    let x = r.physical();
    let id = r
        .try_cmd(home(true, 250.0, HydHomingMode::Direct))
        .unwrap()
        .unwrap();
    r.step();
    assert!(r.logged(id, "Done"), "{}", r.log());
    let s = r.status();
    assert!((r.axis_value(x) - 250.0).abs() < 2e-3, "{s:?}");
    assert!((s.actual_position - 250.0).abs() < 2e-3, "{s:?}");
    assert_eq!(s.state, AxisState::Standstill);
    assert!(s.has(status_bit::HOMING_DONE));
}

/// AbsSwitch with the library's default directions (both negative) on the plant's cam at
/// [60, 80] mm: the ram searches down at 0.1 · fRefVelo, stops on the cam, goes on at the sync
/// velocity 0.05 · fRefVelo (16.35 mm/s) until it leaves the cam at 60, stops. The cam's
/// leaving edge then has the value Position (10 mm) within one cycle's travel at the sync
/// velocity (16.35 µm; the sample after the edge is the mark) and the encoder's count (1 µm);
/// the axis is Homing while it runs and Standstill, homed, after.
#[test]
fn abs_switch_gives_the_cams_leaving_edge_the_position() {
    let cell = cell(
        "fEnc_RefSyncVelo = 0.05",
        "[axes.ram.plant]\nreference_cam = [60.0, 80.0]\n",
    );
    let mut r = Run::enabled(&cell);
    let id = r
        .try_cmd(home(true, 10.0, HydHomingMode::AbsSwitch))
        .unwrap()
        .unwrap();
    r.step();
    assert_eq!(r.state(), AxisState::Homing);
    let cycles = r.until_done(id, 20_000);
    assert!(cycles > 1000, "{cycles}");
    r.step();
    let edge = r.axis_value(60.0);
    let bound = 0.05 * REF_VELO * DT + 1e-3;
    assert!(
        (edge - 10.0).abs() <= bound,
        "edge at {edge}, bound {bound}"
    );
    assert_eq!(r.state(), AxisState::Standstill);
    // The ram stands below the cam, where the stop from the sync velocity ended.
    let s = r.status();
    assert!(s.actual_position < 10.0 && s.actual_position > 8.0, "{s:?}");
    // And it holds there in closed loop: a move lands.
    r.move_to(30.0, 50.0);
    r.until(10_000, "landed", |r| r.status().motion_job.is_none());
    assert!((r.status().actual_position - 30.0).abs() < 0.2);
}

/// AbsSwitch on the reference cam as an input signal (`[axes.ram.inputs] reference_cam`, a
/// simulated sensor on the ram at [60, 80] mm, a digital input sampled at the cycle boundary):
/// the edge gets the value Position within two cycles' travel at the sync velocity (the
/// input's sample adds up to one cycle) and the encoder's count.
#[test]
fn abs_switch_on_the_cams_input_signal() {
    let cell = cell(
        "fEnc_RefSyncVelo = 0.05",
        "[devices.valve_io]\nnode = \"press\"\nkind = \"sim_digital_input\"\nchannels = 8\n\n\
         [signals.ram_cam]\ndevice = \"valve_io\"\nchannel = 1\n\n\
         [signals.ram_cam.sensor]\naxis = \"ram\"\nposition = 60.0\nwidth = 20.0\n\n\
         [axes.ram.inputs]\nreference_cam = \"ram_cam\"\n",
    );
    let mut r = Run::enabled(&cell);
    let id = r
        .try_cmd(home(true, 10.0, HydHomingMode::AbsSwitch))
        .unwrap()
        .unwrap();
    r.until_done(id, 20_000);
    r.step();
    let edge = r.axis_value(60.0);
    let bound = 2.0 * 0.05 * REF_VELO * DT + 1e-3;
    assert!(
        (edge - 10.0).abs() <= bound,
        "edge at {edge}, bound {bound}"
    );
}

/// RefPulse: as AbsSwitch, then on at the sync velocity to the encoder's next zero pulse
/// (every 10 mm at ..., 55, 45, ...): the pulse at 55 gets the value Position exactly (the
/// latch is exact; the encoder's count of 1 µm remains).
#[test]
fn ref_pulse_gives_the_zero_pulse_after_the_cam_the_position() {
    let cell = cell(
        "nEnc_HomingType = \"iTcMc_HomingOnSync\"",
        "[axes.ram.plant]\nreference_cam = [60.0, 80.0]\nzero_mark_period = 10.0\nzero_mark_offset = 5.0\n",
    );
    let mut r = Run::enabled(&cell);
    let id = r
        .try_cmd(home(true, 0.0, HydHomingMode::Default))
        .unwrap()
        .unwrap();
    r.until_done(id, 20_000);
    r.step();
    let pulse = r.axis_value(55.0);
    assert!(pulse.abs() <= 1e-3, "pulse at {pulse}");
}

/// Block (the library's default method, downwards): the cylinder runs into its end stop at
/// 0 mm and stands; the job is Done fBlockDetectDelay (2 s, 2000 cycles) later, not before,
/// the output 0; the actual position is Position there.
#[test]
fn block_homes_at_the_end_stop_after_the_detect_delay() {
    let cell = cell("", "");
    let mut r = Run::enabled(&cell);
    let id = r
        .try_cmd(home(true, -5.0, HydHomingMode::Default))
        .unwrap()
        .unwrap();
    r.until(20_000, "at the end stop", |r| r.physical() <= 1e-9);
    let stalled_at = r.k;
    let cycles = r.until_done(id, 10_000);
    // Done in the cycle that counted the 2000th cycle without movement (the velocity seen
    // below 1 % of fRefVelo from a few cycles before the piston touched).
    assert!(
        (1950..=2000).contains(&cycles),
        "{cycles} cycles after the stall (from {stalled_at})"
    );
    r.step();
    let s = r.status();
    assert!((s.actual_position + 5.0).abs() < 2e-3, "{s:?}");
    assert_eq!(s.state, AxisState::Standstill);
}

/// fBlockDetectDelay from the cell file: 0.5 s.
#[test]
fn block_takes_fblockdetectdelay_from_the_cell() {
    let cell = cell("fBlockDetectDelay = 0.5", "");
    let mut r = Run::enabled(&cell);
    let id = r
        .try_cmd(home(true, 0.0, HydHomingMode::Block))
        .unwrap()
        .unwrap();
    r.until(20_000, "at the end stop", |r| r.physical() <= 1e-9);
    let cycles = r.until_done(id, 10_000);
    assert!((450..=500).contains(&cycles), "{cycles}");
}

/// Execute dropped while the homing runs: it goes on and is Done (the Block homing of the
/// test above); a CalibrationCam given while it runs stops the search (AbsSwitch without a
/// cam on the plant).
#[test]
fn execute_dropped_does_not_stop_a_homing_and_the_calibration_cam_counts() {
    let cell = cell("fBlockDetectDelay = 0.5", "");
    let mut r = Run::enabled(&cell);
    let id = r
        .try_cmd(home(true, 0.0, HydHomingMode::Block))
        .unwrap()
        .unwrap();
    for _ in 0..200 {
        r.step();
    }
    assert_eq!(
        r.try_cmd(home(false, 0.0, HydHomingMode::Block)),
        Ok(Some(id))
    );
    assert_eq!(r.state(), AxisState::Homing);
    r.until_done(id, 20_000);

    // AbsSwitch on the application's cam.
    let mut r = Run::enabled(&cell);
    let id = r
        .try_cmd(home(true, 0.0, HydHomingMode::AbsSwitch))
        .unwrap()
        .unwrap();
    for _ in 0..300 {
        r.step();
    }
    let cam = |on| {
        Command::HydHome(HydHomeInputs {
            execute: true,
            position: Some(0.0),
            mode: HydHomingMode::AbsSwitch,
            calibration_cam: on,
        })
    };
    assert_eq!(r.try_cmd(cam(true)), Ok(Some(id)));
    for _ in 0..300 {
        r.step();
    }
    let x = r.physical();
    assert_eq!(r.try_cmd(cam(false)), Ok(Some(id)));
    r.until_done(id, 5000);
    r.step();
    // Left where the application's cam fell, within the stop from the sync velocity.
    assert!(r.axis_value(x).abs() < 0.1, "{}", r.axis_value(x));
}

/// A positioning while the homing runs aborts it (CommandAborted); the axis stays not homed,
/// the loop closes again and the positioning lands.
#[test]
fn a_positioning_aborts_a_homing() {
    let cell = cell("", "");
    let mut r = Run::enabled(&cell);
    let id = r
        .try_cmd(home(true, 0.0, HydHomingMode::Block))
        .unwrap()
        .unwrap();
    for _ in 0..500 {
        r.step();
    }
    let x = r.status().actual_position;
    r.cmd(Command::MoveRelative {
        distance: 20.0,
        dynamics: Dynamics {
            velocity: 50.0,
            acceleration: -1.0,
            deceleration: -1.0,
            jerk: -1.0,
        },
    });
    r.step();
    assert!(r.logged(id, "CommandAborted"), "{}", r.log());
    r.until(10_000, "landed", |r| r.status().motion_job.is_none());
    let s = r.status();
    assert!(!s.has(status_bit::HOMING_DONE));
    assert!(
        (s.actual_position - (x + 20.0)).abs() < 1.0,
        "{s:?} from {x}"
    );
    assert_eq!(s.state, AxisState::Standstill);
}

/// The refusals, each changing nothing: a moving axis (the library's NotStartable 16#4B01;
/// 16#8003), an unsupported mode (NotSupport 16#4107; 16#800A), an axis in an error state
/// (NotReady 16#4B09; 16#80F3), a velocity below 1 % of fRefVelo (SetVelo 16#4359; 16#8003),
/// an electric axis (16#8002 as the library's other instructions).
#[test]
fn refusals_change_nothing() {
    let cell = cell("", "");
    let mut r = Run::enabled(&cell);
    for mode in [
        HydHomingMode::LimitSwitch,
        HydHomingMode::Absolute,
        HydHomingMode::FlyingSwitch,
        HydHomingMode::FlyingRefPulse,
    ] {
        let before = r.status();
        assert_eq!(
            r.try_cmd(home(true, 0.0, mode)),
            Err(ErrorId::IllegalMode),
            "{mode:?}"
        );
        r.step();
        let s = r.status();
        assert_eq!(s.state, AxisState::Standstill);
        assert!((s.actual_position - before.actual_position).abs() < 1e-3);
    }
    // Moving.
    r.move_to(300.0, 100.0);
    r.step();
    let job = r.status().motion_job;
    assert_eq!(
        r.try_cmd(home(true, 0.0, HydHomingMode::Direct)),
        Err(ErrorId::IllegalVelocity)
    );
    assert_eq!(r.status().motion_job, job);
    assert_eq!(job.map(|j| j.1), Some(Instruction::MoveAbsolute));
    r.until(10_000, "landed", |r| r.status().motion_job.is_none());
    assert!((r.status().actual_position - 300.0).abs() < 0.2);

    // A velocity below 1 %.
    let slow = self::cell("fEnc_RefIndexVelo = 0.005", "");
    let mut r = Run::enabled(&slow);
    assert_eq!(
        r.try_cmd(home(true, 0.0, HydHomingMode::Block)),
        Err(ErrorId::IllegalVelocity)
    );
    r.step();
    assert_eq!(r.state(), AxisState::Standstill);

    // In an error state: the software limit reached by a velocity motion (alarm 533,
    // ErrorStop with the enable kept).
    let limited = self::cell("", "[axes.ram.sw_limits]\nmin = 50.0\nmax = 180.0\n");
    let mut r = Run::enabled(&limited);
    r.cmd(Command::MoveVelocity {
        dynamics: Dynamics {
            velocity: 100.0,
            acceleration: -1.0,
            deceleration: -1.0,
            jerk: -1.0,
        },
        direction: VelocityDirection::Positive,
        current: false,
        position_controlled: true,
    });
    r.until(5000, "error stop", |r| r.state() == AxisState::ErrorStop);
    let before = r.status().actual_position;
    assert_eq!(
        r.try_cmd(home(true, 0.0, HydHomingMode::Direct)),
        Err(ErrorId::JobRejectedInErrorStop)
    );
    assert!((r.status().actual_position - before).abs() < 1.0);
    assert!(r.status().actual_position > 100.0);
    // Not enabled.
    let mut r = Run::enabled(&cell);
    r.cmd(Command::Power {
        enable: false,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Emergency,
    });
    r.until(1000, "disabled", |r| r.state() == AxisState::Disabled);
    assert_eq!(
        r.try_cmd(home(true, 0.0, HydHomingMode::Direct)),
        Err(ErrorId::NotEnabled)
    );

    // An electric axis (config/analog.toml's slide).
    let s = std::fs::read_to_string(root().join("config/analog.toml")).unwrap();
    let electric = tandem_config::parse("analog.toml", &s).unwrap();
    let mut exec = Executive::new(&electric, None).unwrap();
    let mut log = Vec::new();
    exec.step(0, &mut log).unwrap();
    let out = exec
        .apply_at(
            0,
            0,
            "slide",
            "test",
            Action::Command(home(true, 0.0, HydHomingMode::Direct)),
            &mut log,
        )
        .unwrap();
    assert_eq!(out, Err(ErrorId::IllegalObject));
}

/// The cell file's keys: each out of its range is refused naming it; a bad nEnc_HomingType
/// names the allowed values.
#[test]
fn the_cell_files_homing_keys_are_checked() {
    let s = std::fs::read_to_string(root().join("config/hydraulic.toml")).unwrap();
    for (line, key) in [
        ("fEnc_RefIndexVelo = 1.5", "fEnc_RefIndexVelo"),
        ("fEnc_RefSyncVelo = -0.1", "fEnc_RefSyncVelo"),
        ("fBlockDetectDelay = -1.0", "fBlockDetectDelay"),
        ("nEnc_HomingType = \"OnBlock\"", "nEnc_HomingType"),
    ] {
        let src = s.replacen(
            "[axes.ram.hydraulic]\n",
            &format!("[axes.ram.hydraulic]\n{line}\n"),
            1,
        );
        let e = tandem_config::parse("hydraulic.toml", &src).unwrap_err();
        assert!(e.key.ends_with(key), "{line}: {e}");
        assert!(e.to_string().contains(key), "{e}");
    }
    let src = s.replacen(
        "[axes.ram.hydraulic]\n",
        "[axes.ram.hydraulic]\nnEnc_HomingType = \"iTcMc_HomingOnExec\"\nbEnc_RefIndexPositive = true\nfEnc_DefaultHomePosition = 12.0\n",
        1,
    );
    let cell = tandem_config::parse("hydraulic.toml", &src).unwrap();
    // The default mode is Direct now, the position fEnc_DefaultHomePosition.
    let mut r = Run::enabled(&cell);
    let id = r
        .try_cmd(Command::HydHome(HydHomeInputs {
            execute: true,
            position: None,
            mode: HydHomingMode::Default,
            calibration_cam: false,
        }))
        .unwrap()
        .unwrap();
    r.step();
    assert!(r.logged(id, "Done"));
    assert!((r.status().actual_position - 12.0).abs() < 2e-3);
}
