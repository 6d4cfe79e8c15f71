//! MC_AxCtrlPressureFF_BkPlcMc (Beckhoff TwinCAT PLC Hydraulic Positioning library, 4.4.1.3) on
//! the bundled press (`config/hydraulic-press.toml`: the workpiece stops the ram at 500 mm).
//! The ram creeps into contact; the PID controller takes the control value and holds 20 kN
//! within 2 % (as MC_AxCtrlPressure_BkPlcMc does on the same press); its outputs add up to the
//! response; `Reset` ends it with the ram standing in position control; the two pressure
//! instructions exclude each other; bad parameters are refused and change nothing.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod hyd_rig;
use hyd_rig::Run;

use tandem_config::Cell;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::hydraulic::pressure::PressureReading;
use tandem_motion::hydraulic::pressure_ff::{PctrlParams, PidInputs};
use tandem_motion::objects::axis::{AxisState, Command};
use tandem_testkit::workspace::root;

fn press() -> Cell {
    tandem_config::load(&root().join("config/hydraulic-press.toml")).unwrap()
}

/// The press' force controller gains of its script (output per N), with a D part.
fn params() -> PctrlParams {
    PctrlParams {
        kp: 0.00002,
        tn: 0.05,
        tv: 0.002,
        preset: 0.0,
        windup_limit: 0.2,
        nf: 5,
        align_areas: false,
        reading: PressureReading::Force,
    }
}

fn pid(setpoint: f64, reset: bool, params: PctrlParams) -> Command {
    Command::PressureControlFf {
        enable: true,
        reset,
        inputs: PidInputs {
            setpoint,
            ..PidInputs::DEFAULT
        },
        params,
    }
}

/// The ram powered at 300 mm and pressed against the workpiece at 500 mm (creeping into it).
fn in_contact(cell: &Cell) -> Run<'_> {
    let mut r = Run::enabled_at(cell, 300.0);
    r.move_to(505.0, 150.0);
    r.until(3000, "contact", |r| {
        r.hyd().actual.is_some_and(|a| a.force > 1000.0)
    });
    r
}

#[test]
fn the_pid_controller_holds_the_set_force_and_reset_gives_the_ram_back() {
    let cell = press();
    let mut r = in_contact(&cell);
    r.cmd(pid(20_000.0, false, params()));
    assert_eq!(r.state(), AxisState::ContinuousMotion);
    let mut worst = 0.0_f64;
    for k in 0..1500 {
        r.step();
        let h = r.hyd();
        let out = h.pressure_ff.expect("MC_AxCtrlPressureFF_BkPlcMc runs");
        let sum = out.proportional + out.integrator + out.differential;
        assert!((out.response - sum).abs() < 1e-15, "{out:?}");
        let force = h.actual.unwrap().force;
        assert!((out.deviation - (20_000.0 - force)).abs() < 1e-9, "{out:?}");
        if k >= 500 {
            worst = worst.max((force - 20_000.0).abs() / 20_000.0);
        }
    }
    eprintln!("20 kN held within {:.3} %", worst * 100.0);
    assert!(worst <= 0.02, "20 kN held within {worst}\n{}", r.log());
    // Reset: the controller ends, its job Done, the ram in position control where it stands.
    let job = r.try_cmd(pid(20_000.0, true, params())).unwrap();
    assert!(r.hyd().pressure_control.is_none());
    r.step();
    assert_eq!(r.state(), AxisState::Standstill, "{}", r.log());
    assert!(
        r.log().contains(&format!(
            "MC_AxCtrlPressureFF_BkPlcMc job {}: Done",
            job.unwrap()
        )),
        "{}",
        r.log()
    );
}

#[test]
fn feed_velocity_is_added_to_the_response() {
    let cell = press();
    let mut r = in_contact(&cell);
    let with_feed = |feed_velocity| Command::PressureControlFf {
        enable: true,
        reset: false,
        inputs: PidInputs {
            setpoint: 20_000.0,
            feed_velocity,
            ..PidInputs::DEFAULT
        },
        params: params(),
    };
    r.cmd(with_feed(0.0));
    r.step();
    r.cmd(with_feed(0.05));
    r.step();
    let out = r.hyd().pressure_ff.unwrap();
    let parts = out.proportional + out.integrator + out.differential;
    assert!((out.response - (parts + 0.05)).abs() < 1e-15, "{out:?}");
    let (_, control) = r.hyd().pressure_control.unwrap();
    assert_eq!(control.set_speed, out.response);
}

#[test]
fn the_two_pressure_instructions_exclude_each_other() {
    let cell = press();
    let mut r = in_contact(&cell);
    r.cmd(pid(20_000.0, false, params()));
    r.step();
    let pi = |enable| Command::PressureControl {
        enable,
        set_value: 20_000.0,
        kp: 0.00002,
        tn: 0.05,
        preset: 0.0,
        windup_limit: 0.2,
        force: true,
    };
    assert_eq!(
        r.try_cmd(pi(true)),
        Err(ErrorId::IllegalControllerParameter)
    );
    // Disabling the one that does not run changes nothing.
    assert!(r.try_cmd(pi(false)).is_ok());
    assert!(r.hyd().pressure_ff.is_some());
}

#[test]
fn bad_parameters_are_refused_and_change_nothing() {
    let cell = press();
    // Without pressure inputs (config/hydraulic.toml) the instruction is refused.
    let plain = tandem_config::load(&root().join("config/hydraulic.toml")).unwrap();
    let mut r = Run::enabled(&plain);
    assert_eq!(
        r.try_cmd(pid(1000.0, false, params())),
        Err(ErrorId::IllegalControllerParameter)
    );
    let mut r = in_contact(&cell);
    let before = r.status();
    for bad in [
        PctrlParams {
            kp: -1.0,
            ..params()
        },
        PctrlParams {
            tv: f64::NAN,
            ..params()
        },
        PctrlParams {
            windup_limit: 0.0,
            ..params()
        },
        PctrlParams {
            nf: 101,
            ..params()
        },
        PctrlParams {
            align_areas: true,
            ..params()
        },
    ] {
        assert_eq!(
            r.try_cmd(pid(20_000.0, false, bad)),
            Err(ErrorId::IllegalControllerParameter),
            "{bad:?}"
        );
        assert!(r.hyd().pressure_control.is_none());
    }
    assert_eq!(
        r.try_cmd(pid(f64::INFINITY, false, params())),
        Err(ErrorId::IllegalControllerParameter)
    );
    assert_eq!(r.status().state, before.state);
    // A running controller keeps its parameters when a bad change is refused.
    r.cmd(pid(20_000.0, false, params()));
    r.step();
    let bad = PctrlParams {
        kp: -1.0,
        ..params()
    };
    assert_eq!(
        r.try_cmd(pid(20_000.0, false, bad)),
        Err(ErrorId::IllegalControllerParameter)
    );
    r.step();
    assert!(r.hyd().pressure_ff.is_some());
}
